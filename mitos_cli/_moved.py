"""Old module paths of the 0.1 layout, kept importable for one release with a warning.

0.2 grouped the flat package by stage (``lang``, ``fuzzy``, ``engine``, ``draw``; see
docs/architecture.md). ``import mitos_cli.compile`` still works and gives
``mitos_cli.engine.compile`` itself (the same module object), with a ``DeprecationWarning``
that names the new path. ``mitos_cli.engine`` is a package now; the names the old module
``mitos_cli.engine`` held are served from ``mitos_cli.engine.evaluation`` the same way
(``mitos_cli/engine/__init__.py``).
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
import warnings
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Sequence
    from importlib.machinery import ModuleSpec
    from types import ModuleType

#: old module -> new module (docs/changelog.md lists the same table)
MOVED = {
    "parse": "lang.parse", "model": "lang.model", "terms": "lang.terms",
    "yamlpos": "lang.yamlpos", "cache": "lang.cache", "build": "lang.resolve",
    "termset": "lang.termfile",
    "shapes": "fuzzy.shapes", "hedges": "fuzzy.hedges", "norms": "fuzzy.norms",
    "neurons": "fuzzy.neurons", "operators": "lang.operators",
    "compile": "engine.compile", "scalar": "engine.scalar", "mamdani": "engine.mamdani",
    "trace": "engine.trace", "check": "engine.check", "network": "engine.describe",
    "batch": "engine.csvio", "plotdata": "draw.data", "termplot": "draw.terminal",
}


def warn_moved(old: str, new: str, stacklevel: int = 3) -> None:
    warnings.warn(f"{old} moved to {new}; the old path goes away in the next release",
                  DeprecationWarning, stacklevel=stacklevel)


class _Loader:
    """Gives the new module for the old name (the import protocol, without importlib.abc:
    importing it took some 35 ms of every command's start)."""

    def __init__(self, new: str) -> None:
        self.new = new

    def create_module(self, spec: ModuleSpec) -> ModuleType:   # the new module itself, not a copy
        module = importlib.import_module(self.new)
        self.spec = module.__spec__
        return module

    def exec_module(self, module: ModuleType) -> None:  # the import system stamped the old name's spec on it
        module.__spec__ = self.spec
        module.__loader__ = self.spec.loader if self.spec is not None else None


class _Finder:
    def find_spec(self, fullname: str, path: Sequence[str] | None,
                  target: ModuleType | None = None) -> ModuleSpec | None:
        head, _, tail = fullname.partition(".")
        if head != "mitos_cli" or tail not in MOVED:
            return None
        new = f"mitos_cli.{MOVED[tail]}"
        warn_moved(fullname, new, stacklevel=4)
        # a duck-typed loader: importlib.abc costs start-up (docs/benchmarks.md)
        return importlib.util.spec_from_loader(fullname, _Loader(new))  # type: ignore[arg-type]


def install() -> None:
    if not any(isinstance(f, _Finder) for f in sys.meta_path):
        sys.meta_path.append(_Finder())
