"""``mitos docs``: the pages the help texts and hints name, from the checkout (the installed
wheel's copy: ``tests/test_wheel.py``)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from mitos_cli.cli.app import main
from mitos_cli.cli.docs_cmd import page_name
from mitos_cli.resources import doc_pages

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "mitos_cli"


def _strings(path: Path) -> list[tuple[int, str]]:
    """The string constants of a module, its docstrings left out (a reader's, not a user's)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docstrings = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) \
                and node.body and isinstance(node.body[0], ast.Expr) \
                and isinstance(node.body[0].value, ast.Constant):
            docstrings.add(id(node.body[0].value))
    return [(node.lineno, node.value) for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str)
            and id(node) not in docstrings]


def _docstrings_shown(path: Path) -> list[str]:
    """The docstrings the CLI prints as help: its commands'."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [ast.get_docstring(node) or "" for node in ast.walk(tree)
            if isinstance(node, ast.FunctionDef) and node.name.endswith(("_command", "_cmd"))]


def test_every_page_a_message_names_is_one_mitos_docs_prints():
    """Messages name `mitos docs NAME`, never a repository path (`docs/interop.md`,
    `worlds/README.md`), which a pip install does not have."""
    pages = doc_pages()
    named, stale = [], []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name == "docs_cmd.py":          # its own help explains the file names
            continue
        texts = [t for _, t in _strings(path)] + _docstrings_shown(path)
        for text in texts:
            named += re.findall(r"mitos docs (\w+)", text)
            stale += [f"{path.relative_to(ROOT)}: {m}"
                      for m in re.findall(r"(?:docs/\w+\.md|worlds/README\.md)", text)]
    assert stale == []
    assert set(named) >= {"interop", "teach", "study", "worlds"}
    assert set(named) <= set(pages)


def run(capsys, *args: str) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as info:
        main(["docs", *args])
    out, err = capsys.readouterr()
    return int(info.value.code or 0), out, err


def test_a_page_by_any_of_its_names(capsys):
    want = (ROOT / "docs" / "teach.md").read_text(encoding="utf-8")
    for given in ("teach", "TEACH", "teach.md", "docs/teach.md", "./docs/teach.md"):
        assert page_name(given) == "teach"
        code, out, err = run(capsys, given)
        assert (code, err) == (0, "") and out == want
    assert page_name("README.md") == "readme" and page_name("worlds/README.md") == "worlds"
    code, out, _ = run(capsys, "worlds", "--path")
    assert Path(out.strip()) == (ROOT / "worlds" / "README.md").resolve()


def test_the_listing_and_a_wrong_page(capsys):
    code, out, err = run(capsys)
    assert code == 0 and err == ""
    lines = out.splitlines()
    assert lines[0] == "pages (mitos docs NAME prints one; --path says where its file is):"
    assert "  interop       Interoperability: FCL, MATLAB .fis, fuzzylite FLL, and code export" \
        in lines
    assert lines[-1] == "  worlds        Worlds for mitos simulate"
    code, out, err = run(capsys, "telepathy")
    assert code == 2 and out == ""
    assert err.splitlines()[0] == "usage error: unknown page `telepathy`"
    assert "changelog" in err and "worlds" in err         # every page, not the first 12
    assert "`mitos docs` lists them" in err


def test_the_wheel_carries_every_page():
    """pyproject.toml names each page (a folder would ship what lies on the disk): a page
    added to docs/ and not there would be missing from `mitos docs` after a pip install."""
    tomllib = pytest.importorskip("tomllib")          # Python 3.11 on

    forced = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))[
        "tool"]["hatch"]["build"]["targets"]["wheel"]["force-include"]
    pages = {k: v for k, v in forced.items() if k.endswith(".md")}
    want = {f"docs/{p.name}": f"mitos_cli/_data/docs/{p.name}"
            for p in (ROOT / "docs").glob("*.md")}
    assert pages == {**want, "README.md": "mitos_cli/_data/docs/README.md"}
