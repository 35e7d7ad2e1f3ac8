"""The guide's Python examples (docs/python.md) run as written."""

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
