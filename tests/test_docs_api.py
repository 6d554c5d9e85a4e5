"""docs/api.md runs as written: every example on the page is a doctest, from the repository
root."""

from __future__ import annotations

import doctest
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_api_page_examples_run(monkeypatch):
    monkeypatch.chdir(ROOT)
    failed, tried = doctest.testfile(
        str(ROOT / "docs" / "api.md"), module_relative=False, verbose=False, report=True,
        optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert tried > 40 and failed == 0


def test_worlds_readme_python_example_says_what_it_prints(monkeypatch, capsys):
    """worlds/README.md's "Driving the simulator from Python": the block runs from the
    repository root and ends the way its comment says."""
    import re

    monkeypatch.chdir(ROOT)
    text = (ROOT / "worlds" / "README.md").read_text(encoding="utf-8")
    block = next(b for b in re.findall(r"```python\n(.*?)```", text, re.S) if "Simulation(" in b)
    said = re.search(r'print\(sim\.outcome\)\s+# "(\w+)"', block)
    assert said is not None
    exec(compile(block, "worlds/README.md", "exec"), {})
    printed = capsys.readouterr().out.split()
    assert printed[-1] == said.group(1)
