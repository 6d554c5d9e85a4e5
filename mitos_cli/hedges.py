"""Hedges (linguistic modifiers): the activation functions of eqs. 10-11.

``very`` concentrates (x^2), ``somewhat`` / ``more_or_less`` dilate (sqrt x), ``extremely``
concentrates more (x^3). Each maps arrays in [0, 1] to [0, 1] and keeps 0 and 1 fixed. Squares
and cubes are products and the root is ``np.sqrt``, so they are exact and deterministic.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np


@dataclass(frozen=True)
class Hedge:
    name: str
    fn: Callable[[np.ndarray], np.ndarray]
    derivative: Callable[[np.ndarray], np.ndarray]
    formula: str


def _sqrt_derivative(x: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore"):
        return np.where(x > 0, 0.5 / np.sqrt(np.maximum(x, 1e-300)), 0.0)


HEDGES: dict[str, Hedge] = {}


def register(hedge: Hedge) -> Hedge:
    HEDGES[hedge.name] = hedge
    return hedge


register(Hedge("very", lambda x: x * x, lambda x: 2 * x, "x^2"))
register(Hedge("extremely", lambda x: x * x * x, lambda x: 3 * x * x, "x^3"))
register(Hedge("somewhat", np.sqrt, _sqrt_derivative, "sqrt(x)"))
register(Hedge("more_or_less", np.sqrt, _sqrt_derivative, "sqrt(x)"))


def apply(names: tuple[str, ...], x: np.ndarray) -> np.ndarray:
    """Apply hedges written left to right (``very somewhat X`` = very(somewhat(X)))."""
    for name in reversed(names):
        x = HEDGES[name].fn(x)
    return x
