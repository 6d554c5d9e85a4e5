"""Checks of option values that Typer's own ``min=``/``max=`` let through."""

from __future__ import annotations

import math

import typer


def finite(value: float | None) -> float | None:
    """``nan`` passes ``min=0`` (every comparison with NaN is false): refuse it, and the
    infinities, as usage errors (exit 2) instead of letting them turn a check off or reach
    the code as a traceback. ``None`` (an option left out) passes."""
    if value is not None and not math.isfinite(value):
        raise typer.BadParameter(f"must be a finite number, not {value}")
    return value


def named(value: str | None) -> str | None:
    """A name given as an option (``-b ''``, ``--and ''``) is not empty: an empty one would
    quietly mean the default."""
    if value is not None and not value.strip():
        raise typer.BadParameter("must name something, not be empty")
    return value
