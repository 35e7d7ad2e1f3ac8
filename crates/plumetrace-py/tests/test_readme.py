"""The Python examples of the guide (docs/python.md) and of README.md run as written."""

import re

from conftest import REPO


def test_the_readmes_python_examples_run():
    section = (REPO / "docs" / "python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) >= 3
    scope: dict = {}
    for b in blocks:
        exec(compile(b, "docs/python.md", "exec"), scope)
    assert scope["r"].outcome
    # The Python planner of the guide declares on the demo.
    assert scope["d"] is not None and scope["d"]["rule"] == "custom"
    assert scope["obs"].shape == (12,)


def test_the_front_pages_python_example_runs(tmp_path, monkeypatch):
    readme = (REPO / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", readme, flags=re.S)
    assert len(blocks) == 1
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    exec(compile(blocks[0], "README.md", "exec"), scope)
    # The comment in the README is what the run prints.
    printed = re.search(r"print\(r\.verdict\)\s+# (.*)", blocks[0]).group(1)
    assert scope["r"].verdict == printed
    assert (tmp_path / "out" / "demo-py" / "replay.html").is_file()
