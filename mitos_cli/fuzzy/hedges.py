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


# Hedges of fuzzylite (FLL and its FCL dialect). fuzzylite's `extremely` is Zadeh's contrast
# intensification, not MITOS's x^3, so it is called `intensely` here (the readers and writers
# translate the name).
def _seldom(x):
    with np.errstate(invalid="ignore"):
        return np.where(x <= 0.5, np.sqrt(0.5 * x), 1.0 - np.sqrt(0.5 * (1.0 - x)))


def _seldom_derivative(x):
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(x <= 0.5, 0.25 / np.sqrt(np.maximum(0.5 * x, 1e-300)),
                     0.25 / np.sqrt(np.maximum(0.5 * (1.0 - x), 1e-300)))
    return d


register(Hedge("seldom", _seldom, _seldom_derivative,
               "sqrt(x/2) if x <= 0.5, else 1 - sqrt((1 - x)/2)"))
register(Hedge("intensely", lambda x: np.where(x <= 0.5, 2.0 * x * x, 1.0 - 2.0 * (1.0 - x) ** 2),
               lambda x: np.where(x <= 0.5, 4.0 * x, 4.0 * (1.0 - x)),
               "2x^2 if x <= 0.5, else 1 - 2(1 - x)^2 (fuzzylite's `extremely`)"))
register(Hedge("any", lambda x: np.where(np.isnan(x), np.nan, 1.0), lambda x: np.zeros_like(x),
               "1 (the term does not matter)"))


def apply(names: tuple[str, ...], x: np.ndarray) -> np.ndarray:
    """Apply hedges written left to right (``very somewhat X`` = very(somewhat(X)))."""
    for name in reversed(names):
        x = HEDGES[name].fn(x)
    return x
