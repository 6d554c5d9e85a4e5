"""T-norms (AND) and S-norms (OR): the aggregation operators of the fuzzy neurons (Sec. 3).

Each norm is a vectorized binary function on arrays in [0, 1] with its formula and its De Morgan
dual (eq. 12: ``S(a, b) = 1 - T(1 - a, 1 - b)``). :func:`reduce` folds a norm over an axis, so
an n-ary AND neuron is ``reduce(tnorm, inputs, axis)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

Binary = Callable[[np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class Norm:
    name: str
    kind: str            # "tnorm" or "snorm"
    fn: Binary
    formula: str
    dual: str
    aliases: tuple[str, ...] = ()

    @property
    def identity(self) -> float:
        return 1.0 if self.kind == "tnorm" else 0.0

    def __call__(self, a, b):
        return self.fn(np.asarray(a, dtype=float), np.asarray(b, dtype=float))


def _safe_div(num, den, when_zero):
    with np.errstate(invalid="ignore", divide="ignore"):
        out = num / den
    return np.where(den == 0, when_zero, out)


def _drastic_product(a, b):
    return np.where(a == 1, b, np.where(b == 1, a, 0.0))


def _drastic_sum(a, b):
    return np.where(a == 0, b, np.where(b == 0, a, 1.0))


def _einstein_product(a, b):
    return (a * b) / (2.0 - (a + b - a * b))


def _einstein_sum(a, b):
    return (a + b) / (1.0 + a * b)


def _hamacher_product(a, b):
    return _safe_div(a * b, a + b - a * b, 0.0)


def _hamacher_sum(a, b):
    return _safe_div(a + b - 2.0 * a * b, 1.0 - a * b, 1.0)


def _nilpotent_minimum(a, b):
    return np.where(a + b > 1.0, np.minimum(a, b), 0.0)


def _nilpotent_maximum(a, b):
    return np.where(a + b < 1.0, np.maximum(a, b), 1.0)


TNORMS: dict[str, Norm] = {}
SNORMS: dict[str, Norm] = {}


def register(norm: Norm) -> Norm:
    (TNORMS if norm.kind == "tnorm" else SNORMS)[norm.name] = norm
    return norm


for _norm in (
    Norm("min", "tnorm", np.minimum, "min(a, b)", "max", ("minimum",)),
    Norm("product", "tnorm", np.multiply, "a * b", "probabilistic_sum",
         ("algebraic_product", "prod")),
    Norm("lukasiewicz", "tnorm", lambda a, b: np.maximum(0.0, a + b - 1.0),
         "max(0, a + b - 1)", "bounded_sum", ("bounded_difference", "bounded_product")),
    Norm("drastic", "tnorm", _drastic_product, "b if a = 1, a if b = 1, else 0", "drastic_sum",
         ("drastic_product",)),
    Norm("einstein", "tnorm", _einstein_product, "a * b / (2 - (a + b - a * b))",
         "einstein_sum", ("einstein_product",)),
    Norm("hamacher", "tnorm", _hamacher_product, "a * b / (a + b - a * b), 0 at a = b = 0",
         "hamacher_sum", ("hamacher_product",)),
    Norm("nilpotent_minimum", "tnorm", _nilpotent_minimum, "min(a, b) if a + b > 1, else 0",
         "nilpotent_maximum", ("nilpotent_min",)),
    Norm("max", "snorm", np.maximum, "max(a, b)", "min", ("maximum",)),
    Norm("probabilistic_sum", "snorm", lambda a, b: a + b - a * b, "a + b - a * b", "product",
         ("algebraic_sum", "probor")),
    Norm("bounded_sum", "snorm", lambda a, b: np.minimum(1.0, a + b), "min(1, a + b)",
         "lukasiewicz", ("lukasiewicz_sum",)),
    Norm("drastic_sum", "snorm", _drastic_sum, "b if a = 0, a if b = 0, else 1", "drastic"),
    Norm("einstein_sum", "snorm", _einstein_sum, "(a + b) / (1 + a * b)", "einstein"),
    Norm("hamacher_sum", "snorm", _hamacher_sum,
         "(a + b - 2 a b) / (1 - a b), 1 at a = b = 1", "hamacher"),
    Norm("nilpotent_maximum", "snorm", _nilpotent_maximum, "max(a, b) if a + b < 1, else 1",
         "nilpotent_minimum", ("nilpotent_max",)),
):
    register(_norm)


def lookup(kind: str, name: str) -> Norm:
    """The T-norm (``kind="tnorm"``) or S-norm called ``name`` or one of its aliases."""
    table = TNORMS if kind == "tnorm" else SNORMS
    if name in table:
        return table[name]
    for norm in table.values():
        if name in norm.aliases:
            return norm
    raise KeyError(name)


def names(kind: str) -> list[str]:
    table = TNORMS if kind == "tnorm" else SNORMS
    return sorted(set(table) | {a for n in table.values() for a in n.aliases})


def reduce(norm: Norm, x: np.ndarray, axis: int = -1) -> np.ndarray:
    """Fold ``norm`` over ``axis`` (left to right), as an n-ary AND or OR neuron does."""
    x = np.moveaxis(np.asarray(x, dtype=float), axis, 0)
    if norm.fn is np.minimum:
        return np.minimum.reduce(x, axis=0)
    if norm.fn is np.maximum:
        return np.maximum.reduce(x, axis=0)
    if x.shape[0] == 0:
        return np.full(x.shape[1:], norm.identity)
    acc = x[0]
    for row in x[1:]:
        acc = norm.fn(acc, row)
    return acc
