"""The peers a benchmark times MITOS against, checked before it starts: a missing one is named
with the command that installs it, not met as a traceback half-way through the run."""

from __future__ import annotations

import importlib.util
import sys

#: Module -> the package pip installs it from.
PACKAGES = {"fuzzylite": "pyfuzzylite", "simpful": "simpful", "skfuzzy": "scikit-fuzzy"}


def require(script: str, *modules: str) -> None:
    """Exit with status 1 and a message unless every one of ``modules`` can be imported."""
    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    if not missing:
        return
    names = ", ".join(PACKAGES.get(m, m) for m in missing)
    sys.exit(f"{script}: the peers it is measured against are not installed ({names}).\n"
             f"  pip install -e \".[bench]\"   installs every peer (with NumPy 1.x: pyfuzzylite 8 "
             f"requires NumPy below 2; a venv of its own keeps yours); see docs/benchmarks.md")
