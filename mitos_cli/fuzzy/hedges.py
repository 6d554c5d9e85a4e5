"""Hedges (linguistic modifiers): the activation functions of eqs. 10-11.

``very`` concentrates (x^2), ``somewhat`` / ``more_or_less`` dilate (sqrt x), ``extremely``
concentrates more (x^3). Each maps arrays in [0, 1] to [0, 1] and keeps 0 and 1 fixed. Squares
and cubes are products and the root is ``np.sqrt``, so they are exact and deterministic.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Hedge:
    """One hedge, everything about it: every consumer (the grammar's words, the scalar form,
    the exports, adaptation, the FLL/FCL readers and writers) reads it from here."""

    name: str
    fn: Callable[[np.ndarray], np.ndarray]
    derivative: Callable[[np.ndarray], np.ndarray]
    formula: str
    #: Python statements on a float ``x`` leaving ``x`` (engine/scalar.py); "" = none exact
    scalar: str = ""
    #: a C function body of ``double x`` and a NumPy expression of ``x`` (the exports)
    c: str = ""
    numpy: str = ""
    #: fuzzylite's name for the same function (FLL and its FCL dialect); None: it has none
    fuzzylite: str | None = None


def _sqrt_derivative(x: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore"):
        return np.where(x > 0, 0.5 / np.sqrt(np.maximum(x, 1e-300)), 0.0)


HEDGES: dict[str, Hedge] = {}


def register(hedge: Hedge) -> Hedge:
    HEDGES[hedge.name] = hedge
    return hedge


register(Hedge("very", lambda x: x * x, lambda x: 2 * x, "x^2",
               "x = x * x", "return x * x;", "x * x", "very"))
register(Hedge("extremely", lambda x: x * x * x, lambda x: 3 * x * x, "x^3",
               "x = x * x * x", "return x * x * x;", "x * x * x"))
register(Hedge("somewhat", np.sqrt, _sqrt_derivative, "sqrt(x)",
               "x = sqrt(x)", "return sqrt(x);", "np.sqrt(x)", "somewhat"))
register(Hedge("more_or_less", np.sqrt, _sqrt_derivative, "sqrt(x)",
               "x = sqrt(x)", "return sqrt(x);", "np.sqrt(x)", "somewhat"))


# Hedges of fuzzylite (FLL and its FCL dialect). fuzzylite's `extremely` is Zadeh's contrast
# intensification, not MITOS's x^3, so it is called `intensely` here (the readers and writers
# translate the name).
def _seldom(x: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        return np.where(x <= 0.5, np.sqrt(0.5 * x), 1.0 - np.sqrt(0.5 * (1.0 - x)))


def _seldom_derivative(x: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(x <= 0.5, 0.25 / np.sqrt(np.maximum(0.5 * x, 1e-300)),
                     0.25 / np.sqrt(np.maximum(0.5 * (1.0 - x), 1e-300)))
    return d


register(Hedge("seldom", _seldom, _seldom_derivative,
               "sqrt(x/2) if x <= 0.5, else 1 - sqrt((1 - x)/2)",
               "x = sqrt(0.5 * x) if x <= 0.5 else 1.0 - sqrt(0.5 * (1.0 - x))",
               "return x <= 0.5 ? sqrt(0.5 * x) : 1.0 - sqrt(0.5 * (1.0 - x));",
               "np.where(x <= 0.5, np.sqrt(0.5 * x), 1.0 - np.sqrt(0.5 * np.maximum(1.0 - x, 0)))",
               "seldom"))
register(Hedge("intensely", lambda x: np.where(x <= 0.5, 2.0 * x * x, 1.0 - 2.0 * (1.0 - x) ** 2),
               lambda x: np.where(x <= 0.5, 4.0 * x, 4.0 * (1.0 - x)),
               "2x^2 if x <= 0.5, else 1 - 2(1 - x)^2 (fuzzylite's `extremely`)",
               "y = 1.0 - x\nx = 2.0 * x * x if x <= 0.5 else 1.0 - 2.0 * (y * y)",
               "return x <= 0.5 ? 2.0 * x * x : 1.0 - 2.0 * (1.0 - x) * (1.0 - x);",
               "np.where(x <= 0.5, 2.0 * x * x, 1.0 - 2.0 * (1.0 - x) ** 2)", "extremely"))
register(Hedge("any", lambda x: np.where(np.isnan(x), np.nan, 1.0), lambda x: np.zeros_like(x),
               "1 (the term does not matter)", "",
               "(void)x;\n    return 1.0;", "np.where(np.isnan(x), np.nan, 1.0)", "any"))


def fuzzylite_names() -> dict[str, str]:
    """fuzzylite's hedge names -> MITOS's (``more_or_less`` is written as ``somewhat``)."""
    return {h.fuzzylite: h.name for h in HEDGES.values()
            if h.fuzzylite is not None and h.name != "more_or_less"}


def weigh(names: tuple[str, ...], dof: np.ndarray) -> np.ndarray:
    """A hedged consequent's weight: ``names`` applied to the rule's DOF where it fires, 0 where
    it does not (``any`` is 1 even at 0, and a rule that did not fire counted fully)."""
    return np.where(dof > 0, apply(names, dof), dof)


def apply(names: tuple[str, ...], x: np.ndarray) -> np.ndarray:
    """Apply hedges written left to right (``very somewhat X`` = very(somewhat(X)))."""
    for name in reversed(names):
        x = HEDGES[name].fn(x)
    return x
