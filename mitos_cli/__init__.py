"""MITOS: instructible neurofuzzy motion planners (rule language, engine, simulator, teaching)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import _moved
from ._version import __version__

if TYPE_CHECKING:                  # what __getattr__ gives, for the type checker
    from .api import load_rulebase as load_rulebase

__all__ = ["__version__", "load_rulebase"]

_moved.install()   # 0.1's module paths, for one release (mitos_cli/_moved.py)


def __getattr__(name: str) -> object:
    # Lazy, so that `import mitos_cli` (and the CLI's start-up) stays light.
    if name == "load_rulebase":
        from .api import load_rulebase

        return load_rulebase
    raise AttributeError(name)


def __dir__() -> list[str]:
    # `dir(mitos_cli)` (and a notebook's tab completion) listed no `load_rulebase`, which
    # __getattr__ gives: the lazy names are listed with the module's own.
    return sorted(set(globals()) | set(__all__))
