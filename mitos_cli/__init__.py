"""MITOS: instructible neurofuzzy motion planners (rule language, engine, simulator, teaching)."""

from __future__ import annotations

__version__ = "0.1.0"

__all__ = ["__version__", "load_rulebase"]


def __getattr__(name: str):
    # Lazy, so that `import mitos_cli` (and the CLI's start-up) stays light.
    if name == "load_rulebase":
        from .api import load_rulebase

        return load_rulebase
    raise AttributeError(name)
