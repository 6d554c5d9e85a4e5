"""Membership-function shapes: vectorized free functions and their registry.

Each shape is a :class:`Shape` with named parameters, a vectorized membership function that
broadcasts ``x`` against its parameters, a validity check, a crisp centre (used as the rule's
consequent value by the weighted-average inference of eqs. 18-19) and, for the piecewise-linear
shapes, their corner points ``(a, b, c, d)`` so that the compiler can evaluate every linear term
of a rule base in one NumPy expression.

Defined behaviour outside the reals: a NaN input gives NaN; ``-inf`` and ``+inf`` give the
limits of the shape (1 under a shoulder, 0 elsewhere).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

INF = float("inf")


def trapezoid(x, a, b, c, d):
    """Trapezoid with feet ``a``, ``d`` and core ``[b, c]``; ``a = b = -inf`` or ``c = d = inf``
    make shoulders, ``a == b`` or ``c == d`` vertical edges."""
    x = np.asarray(x, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        rise = np.where(x >= b, 1.0, np.where(x <= a, 0.0, (x - a) / np.subtract(b, a)))
        fall = np.where(x <= c, 1.0, np.where(x >= d, 0.0, (d - x) / np.subtract(d, c)))
    return np.minimum(rise, fall)


def triangle(x, a, b, c):
    """Triangle with feet ``a``, ``c`` and peak ``b``."""
    return trapezoid(x, a, b, b, c)


def triangle_pw(x, peak, width):
    """The paper's eq. 15: ``1 - |peak - x| / width``, clipped at 0."""
    return trapezoid(x, np.subtract(peak, width), peak, peak, np.add(peak, width))


def triangle_plr(x, peak, left_width, right_width):
    """Eq. 15 with separate widths to the left and right of the peak."""
    return trapezoid(x, np.subtract(peak, left_width), peak, peak, np.add(peak, right_width))


def left_shoulder(x, a, b):
    """1 up to ``a``, falling to 0 at ``b``."""
    return trapezoid(x, -INF, -INF, a, b)


def right_shoulder(x, a, b):
    """0 up to ``a``, rising to 1 at ``b`` and beyond."""
    return trapezoid(x, a, b, INF, INF)


def singleton(x, value):
    """1 at exactly ``value``, 0 elsewhere (a crisp output value)."""
    x = np.asarray(x, dtype=float)
    out = np.where(x == value, 1.0, 0.0)
    return np.where(np.isnan(x), np.nan, out)


def linear(x, *params):
    """Takagi-Sugeno linear consequent ``y = c_1 x_1 + ... + c_k x_k + constant``.

    Not a membership function: ``x`` stacks the ``k`` inputs on its first axis (``x[i]`` is
    input ``i``, any trailing shape) and ``params`` is ``(c_1, ..., c_k, constant)``, the
    layout of :data:`LINEAR_LAYOUT`. The sum runs left to right, so it is elementwise and
    deterministic per sample.
    """
    *coefficients, constant = params
    x = np.asarray(x, dtype=float)
    y = np.full(x.shape[1:], float(constant))
    for c, xi in zip(coefficients, x):
        if c != 0.0:
            y = y + c * xi
    return y


#: Parameter layout of the ``linear`` shape (shared with the interop readers, which map
#: fuzzylite's ``Linear`` term onto it): ``params = (c_1, ..., c_k, constant)``, one
#: coefficient per **input variable of the term set that defines the term, in the order the
#: term set lists them** (for a term set read from FLL/FIS: the engine's inputs in order),
#: then the constant. The compiler maps the coefficients onto the compiled inputs by name;
#: a missing coefficient is 0. Only output variables may have linear terms, and only the
#: Takagi-Sugeno inferences (``weighted_average``, ``weighted_sum``) can use them.
LINEAR_LAYOUT = "(c_1, ..., c_k, constant) over the term set's input variables, in order"


def _ordered(names: tuple[str, ...]) -> Callable[[tuple[float, ...]], str | None]:
    def check(p: tuple[float, ...]) -> str | None:
        for (n1, v1), (n2, v2) in zip(zip(names, p), zip(names[1:], p[1:])):
            if v1 > v2:
                return f"points must be in order, but {n1} = {v1:g} > {n2} = {v2:g}"
        return None
    return check


def _positive(*indices: int) -> Callable[[tuple[float, ...]], str | None]:
    def check(p: tuple[float, ...]) -> str | None:
        for i in indices:
            if not p[i] > 0:
                return f"width must be > 0, not {p[i]:g}"
        return None
    return check


@dataclass(frozen=True)
class Shape:
    """A membership-function family."""

    name: str
    params: tuple[str, ...]
    fn: Callable[..., np.ndarray]
    check: Callable[[tuple[float, ...]], str | None]
    corners: Callable[[tuple[float, ...]], tuple[float, float, float, float]] | None
    center: Callable[[tuple[float, ...]], float]
    doc: str

    def membership(self, x, params) -> np.ndarray:
        return self.fn(x, *params)


SHAPES: dict[str, Shape] = {}


def register(shape: Shape) -> Shape:
    """Add a shape to the registry (the interop readers add the shapes of other formats)."""
    SHAPES[shape.name] = shape
    return shape


register(Shape("triangle", ("a", "b", "c"), triangle, _ordered(("a", "b", "c")),
               lambda p: (p[0], p[1], p[1], p[2]), lambda p: p[1],
               "triangle by its corners: 0 at a, 1 at b, 0 at c"))
register(Shape("triangle_pw", ("peak", "width"), triangle_pw, _positive(1),
               lambda p: (p[0] - p[1], p[0], p[0], p[0] + p[1]), lambda p: p[0],
               "the paper's eq. 15: 1 - |peak - x| / width"))
register(Shape("triangle_plr", ("peak", "left_width", "right_width"), triangle_plr,
               _positive(1, 2),
               lambda p: (p[0] - p[1], p[0], p[0], p[0] + p[2]), lambda p: p[0],
               "eq. 15 with separate left and right widths"))
register(Shape("trapezoid", ("a", "b", "c", "d"), trapezoid, _ordered(("a", "b", "c", "d")),
               lambda p: tuple(p), lambda p: (p[1] + p[2]) / 2,
               "trapezoid: 0 at a, 1 from b to c, 0 at d"))
register(Shape("left_shoulder", ("a", "b"), left_shoulder, _ordered(("a", "b")),
               lambda p: (-INF, -INF, p[0], p[1]), lambda p: p[0],
               "1 up to a, falling to 0 at b"))
register(Shape("right_shoulder", ("a", "b"), right_shoulder, _ordered(("a", "b")),
               lambda p: (p[0], p[1], INF, INF), lambda p: p[1],
               "0 up to a, rising to 1 at b and beyond"))
register(Shape("singleton", ("value",), singleton, lambda p: None, None, lambda p: p[0],
               "a crisp value: 1 at value, 0 elsewhere"))
register(Shape("linear", ("coefficients", "constant"), linear, lambda p: None, None,
               lambda p: float("nan"),
               "Takagi-Sugeno output y = sum of coefficient * input + constant "
               "(params: LINEAR_LAYOUT)"))


def kernel_params(corners: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    """Corner points as ``(b, s1, c, s2)`` for the compiled kernel

    ``mu = clip(1 + min((x - b) * s1, (c - x) * s2), 0, 1)``, which is finite for every finite
    ``x`` (inputs are clamped to the universe before they reach it). A missing edge (shoulder)
    gets slope 0, a vertical edge a huge slope.
    """
    a, b, c, d = corners
    steep = 1e300
    if b == -INF:           # left shoulder: no rising edge
        b, s1 = c, 0.0
    else:
        s1 = steep if b == a else 1.0 / (b - a)
    if c == INF:            # right shoulder: no falling edge
        c, s2 = b, 0.0
    else:
        s2 = steep if d == c else 1.0 / (d - c)
    return b, s1, c, s2
