"""Compiled rule bases and their evaluation: compile, evaluate, scalar form, Mamdani, traces."""

from __future__ import annotations


def __getattr__(name: str) -> object:
    # 0.1's module mitos_cli.engine held what mitos_cli.engine.evaluation holds now.
    import importlib

    evaluation = importlib.import_module(".evaluation", __name__)
    if name.startswith("__") or not hasattr(evaluation, name):
        raise AttributeError(name)
    from .._moved import warn_moved

    warn_moved(f"mitos_cli.engine.{name}", f"mitos_cli.engine.evaluation.{name}")
    return getattr(evaluation, name)
