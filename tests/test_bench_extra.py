"""``pip install -e ".[bench]"`` installs everything the scripts in ``benchmarks/`` import.

Each third-party module a benchmark imports (at the top or inside a function) must come from
a distribution the ``bench`` extra names, directly or through the extras and dependencies it
pulls in, so that every figure in docs/benchmarks.md can be rerun from that one install."""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

import pytest

tomllib = pytest.importorskip("tomllib")   # Python 3.11+; the extra is the same on 3.10

ROOT = Path(__file__).resolve().parents[1]
#: import name -> the distribution that provides it, where the two differ
DISTRIBUTION = {"fuzzylite": "pyfuzzylite", "skfuzzy": "scikit-fuzzy", "yaml": "pyyaml",
                "distributed": "dask", "PIL": "pillow"}
#: what scikit-fuzzy 0.5 imports without declaring it (it declares no dependencies)
UNDECLARED = {"scikit-fuzzy": {"scipy", "networkx"}}


def imported_modules() -> dict[str, set[str]]:
    """Top-level module -> the benchmark scripts that import it."""
    found: dict[str, set[str]] = {}
    for path in sorted((ROOT / "benchmarks").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0 and \
                node.module else []
            for name in names:
                found.setdefault(name.split(".")[0], set()).add(path.name)
    return found


def third_party(module: str) -> bool:
    local = {p.stem for p in (ROOT / "benchmarks").glob("*.py")}
    return module not in sys.stdlib_module_names and module not in local \
        and module != "mitos_cli"


def project_name(requirement: str) -> tuple[str, list[str]]:
    match = re.match(r"\s*([A-Za-z0-9_.-]+)\s*(?:\[([^\]]*)\])?", requirement)
    assert match, requirement
    extras = [e.strip() for e in (match.group(2) or "").split(",") if e.strip()]
    return match.group(1).lower().replace("_", "-"), extras


def bench_distributions() -> set[str]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    extras = project["optional-dependencies"]
    names = {project_name(r)[0] for r in project["dependencies"]}
    todo, seen = ["bench"], set()
    while todo:
        extra = todo.pop()
        seen.add(extra)
        for requirement in extras[extra]:
            name, wanted = project_name(requirement)
            if name == "mitos":
                todo += [e for e in wanted if e not in seen]
            else:
                names.add(name)
    return names


def test_the_bench_extra_installs_every_import_of_the_benchmarks():
    provided = bench_distributions()
    missing = {}
    for module, scripts in imported_modules().items():
        if third_party(module) and DISTRIBUTION.get(module, module).lower() not in provided:
            missing[module] = sorted(scripts)
    assert not missing, f"add to the bench extra in pyproject.toml: {missing}"
    for dist, needs in UNDECLARED.items():
        assert dist in provided and needs <= provided, (dist, needs - provided)


def test_a_benchmark_names_a_missing_peer_and_how_to_install_it(monkeypatch, capsys):
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import peers

    peers.require("bench_x.py", "json")                      # present: nothing happens
    with pytest.raises(SystemExit) as exit_:
        peers.require("bench_x.py", "json", "skfuzzy_not_here", "fuzzylite_not_here")
    message = str(exit_.value.code)
    assert message.startswith("bench_x.py: the peers it is measured against are not installed")
    assert "skfuzzy_not_here, fuzzylite_not_here" in message and 'pip install -e ".[bench]"' in message
