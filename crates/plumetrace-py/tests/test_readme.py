"""The README's Python examples run as written."""

import re

from conftest import REPO


def test_the_readmes_python_examples_run():
    text = (REPO / "README.md").read_text()
    section = text[text.index("\n## Python\n"):]
    section = section[: section.index("\n## ", 1)]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) >= 3
    scope: dict = {}
    for b in blocks:
        exec(compile(b, "README.md", "exec"), scope)
    assert scope["r"].outcome
    assert scope["obs"].shape == (12,)
