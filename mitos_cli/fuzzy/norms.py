"""T-norms (AND) and S-norms (OR): the aggregation operators of the fuzzy neurons (Sec. 3).

Each norm is a vectorized binary function on arrays in [0, 1] with its formula and its De Morgan
dual (eq. 12: ``S(a, b) = 1 - T(1 - a, 1 - b)``). :func:`reduce` folds a norm over an axis, so
an n-ary AND neuron is ``reduce(tnorm, inputs, axis)``.

A :class:`Norm` is the one registry entry for its operator: besides the NumPy function it
carries the same formula as scalar Python statements (the engine's scalar form), as a C body
and as a NumPy expression (the exports), the rule adaptation uses to differentiate it, and its
names in FLL, ``.fis`` and FCL. Every consumer reads these fields; none keeps a table of its own.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

Binary = Callable[[np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class Norm:
    name: str
    kind: str            # "tnorm" or "snorm"
    fn: Binary
    formula: str
    dual: str
    aliases: tuple[str, ...] = ()
    #: Python statements on floats ``a``, ``b`` leaving ``r``: ``fn``'s operations in ``fn``'s
    #: order, so the scalar form gives the same bits (engine/scalar.py)
    scalar: str = ""
    #: a C function body of ``double a, double b`` (``mitos export --to c``)
    c: str = ""
    #: a NumPy expression of arrays ``a``, ``b`` (``mitos export --to python``)
    numpy: str = ""
    #: the names fuzzylite's FLL, MATLAB's ``.fis`` and IEC 61131-7 FCL give it (None: none)
    fll: str | None = None
    fis: str | None = None
    fcl: str | None = None
    #: how adaptation differentiates an n-ary neuron of this norm: ``"select"`` (the gradient
    #: goes to the winning input), ``"product"`` (the product of the others), ``"dual_product"``
    #: (of the others' complements); None: not differentiated (teach/adapt.py)
    gradient: str | None = None

    @property
    def identity(self) -> float:
        return 1.0 if self.kind == "tnorm" else 0.0

    def __call__(self, a: ArrayLike, b: ArrayLike) -> np.ndarray:
        # broadcast first: the formulas work in place on temporaries shaped like their inputs
        a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
        return self.fn(a, b)


def _fresh(x: ArrayLike) -> np.ndarray:
    """``x`` (a new result) as an array that may be overwritten (NumPy returns scalars for 0-d)."""
    return x if isinstance(x, np.ndarray) else np.asarray(x)


# The formulas below are the textbook ones rearranged so that, in floating point too, every
# norm is exactly commutative (symmetric expressions) and has its identity exactly
# (``T(a, 1) == a``, ``S(a, 0) == a``): the compiled network pads n-ary neurons with the
# identity column, so a rounding there would change a rule's DOF. Tests: tests/test_norms.py.
# They work in place on their own temporaries (never on ``a`` or ``b``): the engine calls them
# on blocks of thousands of samples, where each extra temporary costs.


def _lukasiewicz(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # max(0, a + b - 1) as min - (1 - max): exact at b = 1 (``fl(fl(a + 1) - 1)`` is not a)
    lo, hi = _fresh(np.minimum(a, b)), _fresh(np.maximum(a, b))
    np.subtract(1.0, hi, out=hi)
    np.subtract(lo, hi, out=lo)
    return np.maximum(lo, 0.0, out=lo)


def _probabilistic_sum(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # a + b - a b as hi + lo (1 - hi): exact at b = 0 and b = 1, no cancellation
    hi, lo = _fresh(np.maximum(a, b)), _fresh(np.minimum(a, b))
    t = _fresh(np.subtract(1.0, hi))
    np.multiply(t, lo, out=t)
    return np.add(t, hi, out=t)


def _drastic_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # b if a = 1, a if b = 1, else 0: min(a, b) where max(a, b) = 1
    lo = _fresh(np.minimum(a, b))
    return np.multiply(lo, np.maximum(a, b) == 1.0, out=lo)


def _drastic_sum(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # b if a = 0, a if b = 0, else 1: max(a, b) where min(a, b) = 0
    hi = _fresh(np.maximum(a, b))
    np.copyto(hi, 1.0, where=np.minimum(a, b) != 0.0)
    return hi


def _einstein_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # a b / (2 - (a + b - a b)) with the denominator as 1 + (1 - a)(1 - b): exact at b = 1
    den = _fresh(np.subtract(1.0, a))
    np.multiply(den, np.subtract(1.0, b), out=den)
    np.add(1.0, den, out=den)
    num = _fresh(np.multiply(a, b))
    return np.divide(num, den, out=num)


def _einstein_sum(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    den = _fresh(np.multiply(a, b))
    np.add(1.0, den, out=den)
    num = _fresh(np.add(a, b))
    return np.divide(num, den, out=num)


def _hamacher_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # a b / (a + b - a b), 0 at a = b = 0; the denominator is the probabilistic sum (exactly 1
    # at b = 1), and where it is 0 so is the numerator
    num = _fresh(np.multiply(a, b))
    den = _probabilistic_sum(a, b)
    return np.divide(num, den, out=num, where=den > 0.0)


def _hamacher_sum(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # (a + b - 2 a b) / (1 - a b), 1 at a = b = 1, with the numerator as a (1 - b) + b (1 - a):
    # exactly a at b = 0 and exactly 1 at b = 1 (numerator and denominator round alike)
    num = _fresh(np.multiply(a, np.subtract(1.0, b)))
    np.add(num, np.multiply(b, np.subtract(1.0, a)), out=num)
    den = _fresh(np.multiply(a, b))
    np.subtract(1.0, den, out=den)
    out = np.ones(np.shape(num))
    return np.divide(num, den, out=out, where=den > 0.0)


def _nilpotent_minimum(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # a + b > 1 tested as lo > 1 - hi: for tiny a, fl(a + 1) > 1 is false and T(a, 1) would be 0
    lo, hi = _fresh(np.minimum(a, b)), _fresh(np.maximum(a, b))
    np.subtract(1.0, hi, out=hi)
    return np.multiply(lo, lo > hi, out=lo)


def _nilpotent_maximum(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # max(a, b) if a + b < 1, else 1
    hi = _fresh(np.maximum(a, b))
    np.copyto(hi, 1.0, where=np.add(a, b) >= 1.0)
    return hi


def _bounded_sum(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    s = _fresh(np.add(a, b))
    return np.minimum(s, 1.0, out=s)


TNORMS: dict[str, Norm] = {}
SNORMS: dict[str, Norm] = {}


def register(norm: Norm) -> Norm:
    (TNORMS if norm.kind == "tnorm" else SNORMS)[norm.name] = norm
    return norm


# Scalar forms share these two lines.
_LO_HI = "lo = a if a <= b else b\nhi = a if a >= b else b"

for _norm in (
    Norm("min", "tnorm", np.minimum, "min(a, b)", "max", ("minimum",),
         scalar="r = a if a <= b else b",
         c="return a < b ? a : b;",
         numpy="np.minimum(a, b)",
         fll="Minimum", fis="min", fcl="MIN", gradient="select"),
    Norm("product", "tnorm", np.multiply, "a * b", "probabilistic_sum",
         ("algebraic_product", "prod"),
         scalar="r = a * b",
         c="return a * b;",
         numpy="a * b",
         fll="AlgebraicProduct", fis="prod", fcl="PROD", gradient="product"),
    Norm("lukasiewicz", "tnorm", _lukasiewicz,
         "max(0, a + b - 1)", "bounded_sum", ("bounded_difference", "bounded_product"),
         scalar=_LO_HI + "\nr = lo - (1.0 - hi)\nr = r if r >= 0.0 else 0.0",
         c="double lo = a < b ? a : b, hi = a < b ? b : a, t = lo - (1.0 - hi);\n"
           "    return t > 0.0 ? t : 0.0;",
         numpy="np.maximum(0.0, np.minimum(a, b) - (1.0 - np.maximum(a, b)))",
         fll="BoundedDifference", fcl="BDIF"),
    Norm("drastic", "tnorm", _drastic_product, "b if a = 1, a if b = 1, else 0", "drastic_sum",
         ("drastic_product",),
         scalar=_LO_HI + "\nr = lo * (1.0 if hi == 1.0 else 0.0)",
         c="return a == 1.0 ? b : (b == 1.0 ? a : 0.0);",
         numpy="np.where(a == 1.0, b, np.where(b == 1.0, a, 0.0))",
         fll="DrasticProduct", fcl="DPROD"),
    Norm("einstein", "tnorm", _einstein_product, "a * b / (2 - (a + b - a * b))",
         "einstein_sum", ("einstein_product",),
         scalar="r = (a * b) / (1.0 + (1.0 - a) * (1.0 - b))",
         c="return (a * b) / (1.0 + (1.0 - a) * (1.0 - b));",
         numpy="(a * b) / (1.0 + (1.0 - a) * (1.0 - b))",
         fll="EinsteinProduct", fcl="EPROD"),
    Norm("hamacher", "tnorm", _hamacher_product, "a * b / (a + b - a * b), 0 at a = b = 0",
         "hamacher_sum", ("hamacher_product",),
         scalar=_LO_HI + "\nden = (1.0 - hi) * lo + hi\nr = a * b\nr = r / den if den > 0.0 else r",
         c="double hi = a < b ? b : a, lo = a < b ? a : b, d = hi + lo * (1.0 - hi);\n"
           "    return d == 0.0 ? 0.0 : (a * b) / d;",
         numpy="_div(a * b, np.maximum(a, b) + np.minimum(a, b) * (1.0 - np.maximum(a, b)), 0.0)",
         fll="HamacherProduct", fcl="HPROD"),
    Norm("nilpotent_minimum", "tnorm", _nilpotent_minimum, "min(a, b) if a + b > 1, else 0",
         "nilpotent_maximum", ("nilpotent_min",),
         scalar=_LO_HI + "\nr = lo * (1.0 if lo > 1.0 - hi else 0.0)",
         c="double lo = a < b ? a : b, hi = a < b ? b : a;\n    return lo > 1.0 - hi ? lo : 0.0;",
         numpy="np.where(np.minimum(a, b) > 1.0 - np.maximum(a, b), np.minimum(a, b), 0.0)",
         fll="NilpotentMinimum", fcl="NMIN"),
    Norm("max", "snorm", np.maximum, "max(a, b)", "min", ("maximum",),
         scalar="r = a if a >= b else b",
         c="return a < b ? b : a;",
         numpy="np.maximum(a, b)",
         fll="Maximum", fis="max", fcl="MAX", gradient="select"),
    Norm("probabilistic_sum", "snorm", _probabilistic_sum, "a + b - a * b", "product",
         ("algebraic_sum", "probor"),
         scalar=_LO_HI + "\nr = (1.0 - hi) * lo + hi",
         c="double hi = a < b ? b : a, lo = a < b ? a : b;\n    return hi + lo * (1.0 - hi);",
         numpy="np.maximum(a, b) + np.minimum(a, b) * (1.0 - np.maximum(a, b))",
         fll="AlgebraicSum", fis="probor", fcl="ASUM", gradient="dual_product"),
    Norm("bounded_sum", "snorm", _bounded_sum, "min(1, a + b)",
         "lukasiewicz", ("lukasiewicz_sum",),
         scalar="r = a + b\nr = r if r <= 1.0 else 1.0",
         c="double s = a + b;\n    return s < 1.0 ? s : 1.0;",
         numpy="np.minimum(1.0, a + b)",
         fll="BoundedSum", fcl="BSUM"),
    Norm("drastic_sum", "snorm", _drastic_sum, "b if a = 0, a if b = 0, else 1", "drastic",
         scalar=_LO_HI + "\nr = 1.0 if lo != 0.0 else hi",
         c="return a == 0.0 ? b : (b == 0.0 ? a : 1.0);",
         numpy="np.where(a == 0.0, b, np.where(b == 0.0, a, 1.0))",
         fll="DrasticSum", fcl="DSUM"),
    Norm("einstein_sum", "snorm", _einstein_sum, "(a + b) / (1 + a * b)", "einstein",
         scalar="r = (a + b) / (1.0 + a * b)",
         c="return (a + b) / (1.0 + a * b);",
         numpy="(a + b) / (1.0 + a * b)",
         fll="EinsteinSum", fcl="ESUM"),
    Norm("hamacher_sum", "snorm", _hamacher_sum,
         "(a + b - 2 a b) / (1 - a b), 1 at a = b = 1", "hamacher",
         scalar="den = 1.0 - a * b\nr = (a * (1.0 - b) + b * (1.0 - a)) / den if den > 0.0 else 1.0",
         c="double d = 1.0 - a * b;\n"
           "    return d == 0.0 ? 1.0 : (a * (1.0 - b) + b * (1.0 - a)) / d;",
         numpy="_div(a * (1.0 - b) + b * (1.0 - a), 1.0 - a * b, 1.0)",
         fll="HamacherSum", fcl="HSUM"),
    Norm("nilpotent_maximum", "snorm", _nilpotent_maximum, "max(a, b) if a + b < 1, else 1",
         "nilpotent_minimum", ("nilpotent_max",),
         scalar="r = 1.0 if a + b >= 1.0 else (a if a >= b else b)",
         c="return a + b < 1.0 ? (a < b ? b : a) : 1.0;",
         numpy="np.where(a + b < 1.0, np.maximum(a, b), 1.0)",
         fll="NilpotentMaximum", fcl="NMAX"),
):
    register(_norm)


#: The unbounded sum ``a + b``: a Mamdani aggregation only (MATLAB's ``AggMethod='sum'``,
#: jFuzzyLogic's ``ACCU : SUM``, fuzzylite's ``UnboundedSum``), not an S-norm: it leaves
#: [0, 1], so it is kept out of :data:`SNORMS` and cannot join conditions (``or``).
UNBOUNDED_SUM = Norm("sum", "snorm", np.add, "a + b (unbounded: may exceed 1)", "",
                     ("unbounded_sum",), scalar="r = a + b", c="return a + b;", numpy="a + b",
                     fll="UnboundedSum", fis="sum", fcl="SUM")


def aggregation(name: str) -> Norm:
    """The Mamdani aggregation called ``name``: an S-norm, or the unbounded sum."""
    if name == UNBOUNDED_SUM.name or name in UNBOUNDED_SUM.aliases:
        return UNBOUNDED_SUM
    return lookup("snorm", name)


def get(name: str) -> Norm:
    """The T- or S-norm of this canonical name (the two tables share no name)."""
    return TNORMS[name] if name in TNORMS else SNORMS[name]


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


def tree_reduce(norm: Norm, x: np.ndarray, axis: int = 0) -> np.ndarray:
    """Fold ``norm`` over ``axis`` by halving: ``ceil(log2 n)`` vectorized steps, no Python
    loop over the items (an S-norm over hundreds of rules in Mamdani aggregation).

    Norms are associative, so this equals the left fold up to rounding for the rational
    norms (Einstein, Hamacher) and exactly for the others; the order depends only on the
    length of ``axis``, so a sample's result does not depend on the rest of the batch.
    """
    x = np.moveaxis(np.asarray(x, dtype=float), axis, 0)
    if norm.fn is np.minimum or norm.fn is np.maximum:
        return norm.fn.reduce(x, axis=0, initial=norm.identity)
    size = x.shape[0]
    if size == 0:
        return np.full(x.shape[1:], norm.identity)
    if size == 1:
        return x[0].copy()
    half = (size + 1) // 2
    acc = x[:half].copy()                          # never write into the caller's array
    acc[:size - half] = norm.fn(acc[:size - half], x[half:size])
    size = half
    while size > 1:
        half = (size + 1) // 2
        acc[:size - half] = norm.fn(acc[:size - half], acc[half:size])
        size = half
    return acc[0]


def reduce(norm: Norm, x: np.ndarray, axis: int = -1) -> np.ndarray:
    """Fold ``norm`` over ``axis`` (left to right), as an n-ary AND or OR neuron does."""
    x = np.moveaxis(np.asarray(x, dtype=float), axis, 0)
    if norm.fn is np.minimum or norm.fn is np.maximum:
        return norm.fn.reduce(x, axis=0, initial=norm.identity)
    if x.shape[0] == 0:
        return np.full(x.shape[1:], norm.identity)
    acc = x[0]
    for row in x[1:]:
        acc = norm.fn(acc, row)
    return acc
