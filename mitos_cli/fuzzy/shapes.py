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

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..numbers import exact

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    #: A shape parameter: one value, or an array of them broadcast against ``x`` (one per term).
    Param = float | np.ndarray

INF = float("inf")


def trapezoid(x: ArrayLike, a: Param, b: Param, c: Param, d: Param) -> np.ndarray:
    """Trapezoid with feet ``a``, ``d`` and core ``[b, c]``; ``a = b = -inf`` or ``c = d = inf``
    make shoulders, ``a == b`` or ``c == d`` vertical edges."""
    x = np.asarray(x, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore", under="ignore"):
        rise = np.where(x >= b, 1.0, np.where(x <= a, 0.0, (x - a) / np.subtract(b, a)))
        fall = np.where(x <= c, 1.0, np.where(x >= d, 0.0, (d - x) / np.subtract(d, c)))
    return np.minimum(rise, fall)


def triangle(x: ArrayLike, a: Param, b: Param, c: Param) -> np.ndarray:
    """Triangle with feet ``a``, ``c`` and peak ``b``."""
    return trapezoid(x, a, b, b, c)


def triangle_pw(x: ArrayLike, peak: Param, width: Param) -> np.ndarray:
    """The paper's eq. 15: ``1 - |peak - x| / width``, clipped at 0."""
    return trapezoid(x, np.subtract(peak, width), peak, peak, np.add(peak, width))


def triangle_plr(x: ArrayLike, peak: Param, left_width: Param, right_width: Param) -> np.ndarray:
    """Eq. 15 with separate widths to the left and right of the peak."""
    return trapezoid(x, np.subtract(peak, left_width), peak, peak, np.add(peak, right_width))


def left_shoulder(x: ArrayLike, a: Param, b: Param) -> np.ndarray:
    """1 up to ``a``, falling to 0 at ``b``."""
    return trapezoid(x, -INF, -INF, a, b)


def right_shoulder(x: ArrayLike, a: Param, b: Param) -> np.ndarray:
    """0 up to ``a``, rising to 1 at ``b`` and beyond."""
    return trapezoid(x, a, b, INF, INF)


def singleton(x: ArrayLike, value: Param) -> np.ndarray:
    """1 at exactly ``value``, 0 elsewhere (a crisp output value)."""
    x = np.asarray(x, dtype=float)
    out = np.where(x == value, 1.0, 0.0)
    return np.where(np.isnan(x), np.nan, out)


def linear(x: ArrayLike, *params: float) -> np.ndarray:
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
                return f"points must be in order, but {n1} = {exact(v1)} > {n2} = {exact(v2)}"
        return None
    return check


def _positive(names: tuple[str, ...], *indices: int) -> Callable[[tuple[float, ...]], str | None]:
    def check(p: tuple[float, ...]) -> str | None:
        for i in indices:
            if not p[i] > 0:
                return f"{names[i]} must be > 0, not {exact(p[i])}"
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
    variadic: bool = False        # any number of params (``discrete``: x1, y1, ..., xn, yn)

    def membership(self, x: ArrayLike, params: Sequence[Param]) -> np.ndarray:
        return self.fn(x, *params)


SHAPES: dict[str, Shape] = {}


def register(shape: Shape) -> Shape:
    """Add a shape to the registry (the interop readers add the shapes of other formats)."""
    SHAPES[shape.name] = shape
    return shape


register(Shape("triangle", ("a", "b", "c"), triangle, _ordered(("a", "b", "c")),
               lambda p: (p[0], p[1], p[1], p[2]), lambda p: p[1],
               "triangle by its corners: 0 at a, 1 at b, 0 at c"))
register(Shape("triangle_pw", ("peak", "width"), triangle_pw, _positive(("peak", "width"), 1),
               lambda p: (p[0] - p[1], p[0], p[0], p[0] + p[1]), lambda p: p[0],
               "the paper's eq. 15: 1 - |peak - x| / width"))
register(Shape("triangle_plr", ("peak", "left_width", "right_width"), triangle_plr,
               _positive(("peak", "left_width", "right_width"), 1, 2),
               lambda p: (p[0] - p[1], p[0], p[0], p[0] + p[2]), lambda p: p[0],
               "eq. 15 with separate left and right widths"))
register(Shape("trapezoid", ("a", "b", "c", "d"), trapezoid, _ordered(("a", "b", "c", "d")),
               lambda p: (p[0], p[1], p[2], p[3]), lambda p: (p[1] + p[2]) / 2,
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


#: The slope of a vertical edge in the compiled kernel, and the cap of every slope: an edge
#: narrower than ``1 / STEEP`` is a vertical one.
STEEP = 1e300


def kernel_params(corners: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    """Corner points as ``(b, s1, c, s2)`` for the compiled kernel

    ``mu = clip(1 + min((x - b) * s1, (c - x) * s2), 0, 1)``, which is finite for every finite
    ``x`` (inputs are clamped to the universe before they reach it). A missing edge (shoulder)
    gets slope 0, a vertical edge a huge slope (so does an edge too narrow for its slope to be
    a float, 1e-320 wide: an infinite slope times 0 at the corner would be NaN).
    """
    a, b, c, d = corners
    if b == -INF:           # left shoulder: no rising edge
        b, s1 = c, 0.0
    else:
        s1 = _slope(b - a)
    if c == INF:            # right shoulder: no falling edge
        c, s2 = b, 0.0
    else:
        s2 = _slope(d - c)
    return b, s1, c, s2


def _slope(width: float) -> float:
    """The slope of an edge ``width`` wide: ``1 / width``, raised by the ulps it takes for the
    edge's foot to give exactly 0 (``1 + (-width) * slope``: for about 15% of widths the
    rounded ``1 / width`` left 1.1e-16 there, and a rule fired where the term was 0, with no
    word); :data:`STEEP` where the edge is vertical or too narrow for its slope."""
    if width == 0:
        return STEEP
    slope = min(1.0 / width, STEEP)
    while slope < STEEP and 1.0 + -width * slope > 0.0:
        slope = math.nextafter(slope, math.inf)
    return slope


# --- Shapes of the foreign formats (FCL, MATLAB .fis, fuzzylite FLL) ---------------------------
#
# Formulas follow fuzzylite 8 (which follows MATLAB where both define a shape), so that files
# read from those formats give the same memberships. Parameter names are MITOS's; the readers in
# ``mitos_cli.interop`` map each format's order onto them. A NaN input gives NaN; +/-inf give the
# shape's limits (1 beyond a shoulder, ramp or sigmoid plateau, 0 elsewhere).


def _nan_of(x: np.ndarray) -> np.ndarray:
    """1 where ``x`` is a number, NaN where it is NaN (multiplied into a membership)."""
    return np.where(np.isnan(x), np.nan, 1.0)


def rectangle(x: ArrayLike, start: Param, end: Param) -> np.ndarray:
    """1 on ``[start, end]``, 0 elsewhere."""
    return trapezoid(x, start, start, end, end)


def ramp(x: ArrayLike, start: Param, end: Param) -> np.ndarray:
    """0 at ``start``, rising (or falling, when ``end < start``) linearly to 1 at ``end``, and
    1 beyond ``end``."""
    x = np.asarray(x, dtype=float)
    up = np.asarray(start) < np.asarray(end)
    return np.where(up, trapezoid(x, start, end, INF, INF), trapezoid(x, -INF, -INF, end, start))


def gaussian(x: ArrayLike, mean: Param, sigma: Param) -> np.ndarray:
    """``exp(-(x - mean)^2 / (2 sigma^2))``, as ``((x - mean) / sigma)^2 / 2``: a sigma so
    small that its square is 0 (2e-321) still gives 1 at the mean, not 0 / 0."""
    x = np.asarray(x, dtype=float)
    with np.errstate(over="ignore"):
        return np.exp(-0.5 * np.square((x - mean) / np.asarray(sigma)))


def gaussian2(x: ArrayLike, mean1: Param, sigma1: Param, mean2: Param, sigma2: Param) -> np.ndarray:
    """Two-sided Gaussian (MATLAB ``gauss2mf``, fuzzylite ``GaussianProduct``): the left
    Gaussian below ``mean1``, the right one above ``mean2``, 1 between (when ``mean1 <= mean2``)."""
    x = np.asarray(x, dtype=float)
    a = np.where(x < mean1, gaussian(x, mean1, sigma1), 1.0)
    b = np.where(x > mean2, gaussian(x, mean2, sigma2), 1.0)
    return _nan_of(x) * a * b


def bell(x: ArrayLike, center: Param, width: Param, slope: Param) -> np.ndarray:
    """Generalized bell ``1 / (1 + |(x - center) / width|^(2 slope))`` (MATLAB ``gbellmf``)."""
    x = np.asarray(x, dtype=float)
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        out = 1.0 / (1.0 + np.power(np.abs((x - center) / width), 2.0 * slope))
    return np.where(np.isinf(x), 0.0, out)


def sigmoid(x: ArrayLike, inflection: Param, slope: Param) -> np.ndarray:
    """``1 / (1 + exp(-slope (x - inflection)))``: rising for slope > 0, falling for < 0."""
    x = np.asarray(x, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        out = 1.0 / (1.0 + np.exp(-np.multiply(slope, x - inflection)))
    return out


def sigmoid_difference(x: ArrayLike, left: Param, rising: Param, falling: Param, right: Param) -> np.ndarray:
    """``|sigmoid(left, rising) - sigmoid(right, falling)|`` (fuzzylite ``SigmoidDifference``;
    MATLAB's ``dsigmf`` is the signed difference, the same wherever it is a membership)."""
    return np.abs(sigmoid(x, left, rising) - sigmoid(x, right, falling))


def clipped_sigmoid_difference(x: ArrayLike, left: Param, rising: Param, falling: Param,
                               right: Param) -> np.ndarray:
    """``max(sigmoid(left, rising) - sigmoid(right, falling), 0)``: jFuzzyLogic's ``DSIGM``
    (and Octave's ``dsigmf``); it differs from :func:`sigmoid_difference` where the second
    sigmoid is the larger."""
    return np.maximum(sigmoid(x, left, rising) - sigmoid(x, right, falling), 0.0)


def sigmoid_product(x: ArrayLike, left: Param, rising: Param, falling: Param, right: Param) -> np.ndarray:
    """``sigmoid(left, rising) * sigmoid(right, falling)`` (MATLAB ``psigmf``)."""
    return sigmoid(x, left, rising) * sigmoid(x, right, falling)


def s_shape(x: ArrayLike, start: Param, end: Param) -> np.ndarray:
    """Smooth step from 0 at ``start`` to 1 at ``end`` (two parabolas; MATLAB ``smf``)."""
    x = np.asarray(x, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        out = np.where(x <= start, 0.0, np.where(
            x <= 0.5 * (np.add(start, end)), 2.0 * np.square((x - start) / np.subtract(end, start)),
            np.where(x < end, 1.0 - 2.0 * np.square((x - end) / np.subtract(end, start)), 1.0)))
    return _nan_of(x) * out


def z_shape(x: ArrayLike, start: Param, end: Param) -> np.ndarray:
    """Smooth step from 1 at ``start`` to 0 at ``end`` (MATLAB ``zmf``)."""
    x = np.asarray(x, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        out = np.where(x <= start, 1.0, np.where(
            x < 0.5 * (np.add(start, end)), 1.0 - 2.0 * np.square((x - start) / np.subtract(end, start)),
            np.where(x < end, 2.0 * np.square((x - end) / np.subtract(end, start)), 0.0)))
    return _nan_of(x) * out


def pi_shape(x: ArrayLike, a: Param, b: Param, c: Param, d: Param) -> np.ndarray:
    """``s_shape(a, b) * z_shape(c, d)`` (MATLAB ``pimf``)."""
    return s_shape(x, a, b) * z_shape(x, c, d)


def cosine(x: ArrayLike, center: Param, width: Param) -> np.ndarray:
    """Raised cosine ``(1 + cos(2 pi (x - center) / width)) / 2`` on ``center +- width/2``."""
    x = np.asarray(x, dtype=float)
    with np.errstate(invalid="ignore", over="ignore"):      # outside: the 0 of np.where
        inside = np.isfinite(x) & (x >= center - 0.5 * np.asarray(width)) \
            & (x <= center + 0.5 * np.asarray(width))
        # (x - center) / width first: 2 / width overflows for a width of 3e-318 (inf * 0)
        out = np.where(inside, 0.5 * (1.0 + np.cos(2.0 * np.pi * ((x - center)
                                                                 / np.asarray(width)))), 0.0)
    return _nan_of(x) * out


def spike(x: ArrayLike, center: Param, width: Param) -> np.ndarray:
    """``exp(-|10 (x - center) / width|)``: a sharp peak at ``center``."""
    x = np.asarray(x, dtype=float)
    return np.exp(-np.abs(10.0 / np.asarray(width) * (x - center)))


def concave(x: ArrayLike, inflection: Param, end: Param) -> np.ndarray:
    """Concave curve reaching 1 at ``end`` and 0.5 at ``inflection`` (increasing when
    ``inflection <= end``, decreasing otherwise); 1 beyond ``end``."""
    x = np.asarray(x, dtype=float)
    i, e = np.asarray(inflection, dtype=float), np.asarray(end, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where((i <= e) & (x < e), (e - i) / (2.0 * e - i - x),
                       np.where((i >= e) & (x > e), (i - e) / (i - 2.0 * e + x), 1.0))
    out = np.where(np.isinf(x) & (((i <= e) & (x < e)) | ((i >= e) & (x > e))), 0.0, out)
    return _nan_of(x) * out


def semi_ellipse(x: ArrayLike, start: Param, end: Param) -> np.ndarray:
    """Upper half of an ellipse over ``[start, end]``, 1 at its middle."""
    x = np.asarray(x, dtype=float)
    s, e = np.minimum(start, end), np.maximum(start, end)
    r = (e - s) / 2.0
    with np.errstate(invalid="ignore", over="ignore"):
        out = np.where((x >= s) & (x <= e), np.sqrt(np.maximum(r * r - np.square(x - (s + r)), 0.0))
                       / r, 0.0)
    return _nan_of(x) * out


def arc(x: ArrayLike, start: Param, end: Param) -> np.ndarray:
    """Quarter circle from 0 at ``start`` to 1 at ``end`` (fuzzylite ``Arc``), 1 beyond."""
    x = np.asarray(x, dtype=float)
    s, e = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    r = e - s
    with np.errstate(invalid="ignore", over="ignore"):
        rising = (s < e) & (s <= x) & (x <= e)
        falling = (s > e) & (e <= x) & (x <= s)
        curve = np.sqrt(np.maximum(r * r - np.square(x - e), 0.0)) / np.abs(r)
        out = np.where(rising | falling, curve, np.where(((s < e) & (x > e)) | ((s > e) & (x < e)),
                                                         1.0, 0.0))
    return _nan_of(x) * out


def binary(x: ArrayLike, start: Param, direction: Param) -> np.ndarray:
    """1 from ``start`` on towards ``direction`` (``+inf``: x >= start; ``-inf``: x <= start)."""
    x = np.asarray(x, dtype=float)
    s, d = np.asarray(start, dtype=float), np.asarray(direction, dtype=float)
    out = np.where(((d > s) & (x >= s)) | ((d < s) & (x <= s)), 1.0, 0.0)
    return _nan_of(x) * out


def discrete(x: ArrayLike, *points: Param) -> np.ndarray:
    """Piecewise-linear through ``(x1, y1), ..., (xn, yn)`` (x ascending), constant beyond the
    ends (``numpy.interp``). Vectorized over parameter rows: the loop runs over the n points."""
    x = np.asarray(x, dtype=float)
    xs, ys = points[0::2], points[1::2]
    out = np.broadcast_to(np.asarray(ys[0], dtype=float), np.broadcast_shapes(
        x.shape, np.shape(ys[0]))).copy()
    with np.errstate(invalid="ignore", divide="ignore"):
        for (x0, y0), (x1, y1) in zip(zip(xs, ys), zip(xs[1:], ys[1:])):
            dx = np.subtract(x1, x0)
            seg = np.where(dx > 0, y0 + (x - x0) * (np.subtract(y1, y0) / np.where(dx > 0, dx, 1.0)),
                           y1)
            out = np.where(x > x0, np.where(x >= x1, y1, seg), out)
    return _nan_of(x) * out


def _check_discrete(p: tuple[float, ...]) -> str | None:
    if len(p) < 2 or len(p) % 2:
        return f"needs pairs x1, y1, ..., xn, yn (an even number of values), not {len(p)}"
    xs, ys = p[0::2], p[1::2]
    if any(a > b for a, b in zip(xs, xs[1:])):
        return "the x values must ascend"
    if any(not 0.0 <= y <= 1.0 for y in ys):
        return "memberships (y values) must lie in [0, 1]"
    return None


def _distinct(first: str, second: str) -> Callable[[tuple[float, ...]], str | None]:
    """The two parameters must differ; named as the shape names them (`concave` has
    `inflection` and `end`, no `start`)."""
    def check(p: tuple[float, ...]) -> str | None:
        return None if p[0] != p[1] else f"{first} and {second} must differ, not both {p[0]:g}"
    return check


def _nonzero(i: int, what: str) -> Callable[[tuple[float, ...]], str | None]:
    def check(p: tuple[float, ...]) -> str | None:
        return None if p[i] != 0 and np.isfinite(p[i]) else f"{what} must be finite and non-zero"
    return check


def _sigmoid_center(p: tuple[float, ...]) -> float:
    return p[0]


def _discrete_center(p: tuple[float, ...]) -> float:
    xs, ys = np.asarray(p[0::2]), np.asarray(p[1::2])
    return float(xs[int(np.argmax(ys))])


for _shape in (
    Shape("rectangle", ("start", "end"), rectangle, _ordered(("start", "end")),
          lambda p: (p[0], p[0], p[1], p[1]), lambda p: (p[0] + p[1]) / 2,
          "1 from start to end, 0 elsewhere"),
    Shape("ramp", ("start", "end"), ramp, _distinct("start", "end"),
          lambda p: (p[0], p[1], INF, INF) if p[0] < p[1] else (-INF, -INF, p[1], p[0]),
          lambda p: p[1], "0 at start, linear to 1 at end and beyond (falls when end < start)"),
    Shape("gaussian", ("mean", "sigma"), gaussian, _nonzero(1, "sigma"), None, lambda p: p[0],
          "exp(-(x - mean)^2 / (2 sigma^2))"),
    Shape("gaussian2", ("mean1", "sigma1", "mean2", "sigma2"), gaussian2,
          lambda p: _nonzero(1, "sigma1")(p) or _nonzero(3, "sigma2")(p), None,
          lambda p: (p[0] + p[2]) / 2,
          "two-sided Gaussian: left one below mean1, right one above mean2, 1 between"),
    Shape("bell", ("center", "width", "slope"), bell, _nonzero(1, "width"), None,
          lambda p: p[0], "generalized bell 1 / (1 + |(x - center) / width|^(2 slope))"),
    Shape("sigmoid", ("inflection", "slope"), sigmoid, _nonzero(1, "slope"), None, _sigmoid_center,
          "1 / (1 + exp(-slope (x - inflection)))"),
    Shape("sigmoid_difference", ("left", "rising", "falling", "right"), sigmoid_difference,
          lambda p: None, None, lambda p: (p[0] + p[3]) / 2,
          "|sigmoid(left, rising) - sigmoid(right, falling)|"),
    Shape("clipped_sigmoid_difference", ("left", "rising", "falling", "right"),
          clipped_sigmoid_difference, lambda p: None, None, lambda p: (p[0] + p[3]) / 2,
          "max(sigmoid(left, rising) - sigmoid(right, falling), 0) (jFuzzyLogic's DSIGM)"),
    Shape("sigmoid_product", ("left", "rising", "falling", "right"), sigmoid_product,
          lambda p: None, None, lambda p: (p[0] + p[3]) / 2,
          "sigmoid(left, rising) * sigmoid(right, falling)"),
    Shape("s_shape", ("start", "end"), s_shape, _ordered(("start", "end")), None,
          lambda p: p[1], "smooth step from 0 at start to 1 at end"),
    Shape("z_shape", ("start", "end"), z_shape, _ordered(("start", "end")), None,
          lambda p: p[0], "smooth step from 1 at start to 0 at end"),
    Shape("pi_shape", ("a", "b", "c", "d"), pi_shape, _ordered(("a", "b", "c", "d")), None,
          lambda p: (p[1] + p[2]) / 2, "s_shape(a, b) * z_shape(c, d)"),
    Shape("cosine", ("center", "width"), cosine, _nonzero(1, "width"), None, lambda p: p[0],
          "raised cosine of the given width around center"),
    Shape("spike", ("center", "width"), spike, _nonzero(1, "width"), None, lambda p: p[0],
          "exp(-|10 (x - center) / width|)"),
    Shape("concave", ("inflection", "end"), concave, _distinct("inflection", "end"), None, lambda p: p[1],
          "concave curve: 0.5 at inflection, 1 at end and beyond"),
    Shape("semi_ellipse", ("start", "end"), semi_ellipse, _distinct("start", "end"), None,
          lambda p: (p[0] + p[1]) / 2, "upper half ellipse over [start, end]"),
    Shape("arc", ("start", "end"), arc, _distinct("start", "end"), None, lambda p: p[1],
          "quarter circle from 0 at start to 1 at end, 1 beyond"),
    Shape("binary", ("start", "direction"), binary, _distinct("start", "direction"), None, lambda p: p[0],
          "1 from start towards direction (+inf or -inf), 0 elsewhere"),
    Shape("discrete", ("x1", "y1", "xn", "yn"), discrete, _check_discrete, None,
          _discrete_center, "piecewise linear through the points (x1, y1) ... (xn, yn)",
          variadic=True),
):
    register(_shape)


def _formula_fn(x: ArrayLike, *params: float) -> np.ndarray:
    raise TypeError("a formula term is evaluated by its Formula (Term.membership), not by params")


#: ``formula``: a membership function of ``x`` written as a formula (fuzzylite's ``Function``,
#: :mod:`mitos_cli.fuzzy.formula`); the formula lives on the term, the params are empty.
register(Shape("formula", (), _formula_fn, lambda p: None, None, lambda p: float("nan"),
               "a membership function given by a formula of x (fuzzylite's Function)"))



# ---------------------------------------------------------------------------------------------
# Tsukamoto inference: a monotonic output term's value at an activation degree w, z = mu^-1(w)
# (fuzzylite's ``Term.tsukamoto``, heights 1). Where mu never reaches w (a sigmoid at w = 1, a
# concave term at w = 0) the inverse is infinite, as in fuzzylite.


def _ramp_inverse(w: np.ndarray, start: float, end: float) -> np.ndarray:
    return start + (end - start) * w


def _sigmoid_inverse(w: np.ndarray, inflection: float, slope: float) -> np.ndarray:
    with np.errstate(divide="ignore"):
        return inflection + np.log(1.0 / w - 1.0) / -slope


def _s_shape_inverse(w: np.ndarray, start: float, end: float) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        return np.where(w <= 0.5, start + (end - start) * np.sqrt(w / 2.0),
                        end - (end - start) * np.sqrt((1.0 - w) / 2.0))


def _z_shape_inverse(w: np.ndarray, start: float, end: float) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        return np.where(w <= 0.5, end - (end - start) * np.sqrt(w / 2.0),
                        start + (end - start) * np.sqrt((1.0 - w) / 2.0))


def _concave_inverse(w: np.ndarray, inflection: float, end: float) -> np.ndarray:
    with np.errstate(divide="ignore"):
        return (inflection - end) / w + 2.0 * end - inflection


def _arc_inverse(w: np.ndarray, start: float, end: float) -> np.ndarray:
    r = end - start
    sign = -1.0 if start < end else 1.0
    return end + sign * np.sqrt(np.maximum(r * r - np.square(w * r), 0.0))


#: Shapes Tsukamoto inference can invert, and their inverses ``fn(w, *params)``.
TSUKAMOTO: dict[str, Callable[..., np.ndarray]] = {
    "ramp": _ramp_inverse, "sigmoid": _sigmoid_inverse, "s_shape": _s_shape_inverse,
    "z_shape": _z_shape_inverse, "concave": _concave_inverse, "arc": _arc_inverse,
}
