"""Control surfaces: one output over a grid of one or two inputs with the others fixed, computed
by the engine in one batch."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...engine.compile import CompiledRuleBase
from ...errors import InputError, unknown
from ...numbers import whole_number
from .curves import compiled_of

if TYPE_CHECKING:
    from ...api import LoadedRuleBase


@dataclass(frozen=True)
class Axis:
    name: str
    unit: str
    values: np.ndarray

    @property
    def label(self) -> str:
        return f"{self.name} [{self.unit}]" if self.unit else self.name


@dataclass(frozen=True)
class Fixed:
    """An input held fixed while the surface varies the others."""

    name: str
    value: float
    unit: str
    defaulted: bool          # not given: the midpoint of its universe


@dataclass(frozen=True)
class Surface:
    """``z`` = the output over ``x`` (a curve, ``z[nx]``) or over ``x`` and ``y``
    (``z[ny, nx]``, rows follow ``y``). ``z`` is NaN where no rule sets the output and the
    output has no default; :attr:`no_rule` is that mask."""

    output: str
    unit: str
    x: Axis
    y: Axis | None
    z: np.ndarray
    fixed: tuple[Fixed, ...]
    behavior: str
    #: the output declares NaN as its default (`default: .nan`): where no rule fires it is
    #: that, not "no default"
    nan_default: bool = False

    def __repr__(self) -> str:   # the generated one printed the axes' and z's arrays
        over = self.x.name if self.y is None else f"{self.x.name} x {self.y.name}"
        fixed = ", ".join(f"{f.name}={f.value:g}" for f in self.fixed[:4]) + (
            ", ..." if len(self.fixed) > 4 else "")
        held = f", {fixed} held" if fixed else ""
        unset = int(np.isnan(self.z).sum())
        return (f"<Surface of {self.output!r} over {over} ({' x '.join(map(str, self.z.shape))}"
                f" points{held}; NaN at {unset})>")

    @property
    def no_rule(self) -> np.ndarray:
        return np.isnan(self.z)

    @property
    def label(self) -> str:
        return f"{self.output} [{self.unit}]" if self.unit else self.output

    @property
    def fixed_text(self) -> str:
        return ", ".join(f"{f.name} = {f.value:g}{' ' + f.unit if f.unit else ''}"
                         + (" (midpoint)" if f.defaulted else "") for f in self.fixed)

    def notes(self) -> list[str]:
        """What a user should be told: defaulted inputs, regions where nothing fires."""
        held = [f for f in self.fixed if f.defaulted]
        if len(held) > 2:           # `drive` over one input: 12 lines of notes, one an input
            out = [f"{len(held)} inputs not fixed, each held at the midpoint of its universe: "
                   + ", ".join(f"{f.name} = {f.value:g}" for f in held)
                   + " (give --fix NAME=VALUE)"]
        else:
            out = [f"`{f.name}` not fixed: held at {f.value:g}, the midpoint of its universe "
                   f"(give --fix {f.name}=VALUE)" for f in held]
        n = int(self.no_rule.sum())
        if n:
            out.append(f"no rule sets `{self.output}` at {n} of {self.z.size} grid points "
                       f"and {no_default_words(self.nan_default)}: shown as a blank (masked) "
                       f"region")
        infinite = int(np.isinf(self.z).sum())
        if infinite:                # (a Tsukamoto sigmoid inverted at 1: a gap, said why)
            out.append(f"`{self.output}` is infinite at {infinite} of {self.z.size} grid points "
                       f"(a picture leaves them out)")
        return out


def no_default_words(nan_default: bool) -> str:
    """Why an output is NaN where no rule fires: it has no default, or its default is NaN."""
    return "its default is nan" if nan_default else "it has no default"


def _input_axis(compiled: CompiledRuleBase, name: str, what: str) -> int:
    if not isinstance(name, str):   # (an int met difflib's "'int' object is not iterable")
        raise unknown(f"input ({what})", f"{name!r:.40}", compiled.inputs, cls=InputError)
    if name in compiled.inputs:
        return compiled.inputs.index(name)
    known = [v.name for v in compiled.variables.values() if v.role == "input"]
    if name in known:
        raise InputError(f"behavior `{compiled.behavior}` does not use input `{name}` ({what})",
                         expected="one of " + ", ".join(compiled.inputs))
    raise unknown(f"input ({what})", name, compiled.inputs, cls=InputError)


def _number(value: object, what: str) -> float:
    """``value`` as one float, else the engine's :class:`InputError` about ``what`` (text
    met ``float()``'s ValueError, ``None`` its TypeError)."""
    from ...engine.inputs import floats

    x = floats(value, what)
    if x.ndim:
        raise InputError(f"{what} is one number, not of shape {x.shape}")
    return float(x)


def _pair(limits: object, what: str) -> tuple[float, float]:
    """A zoom range ``(low, high)`` as two floats, else an :class:`InputError`."""
    if not isinstance(limits, (tuple, list)) or len(limits) != 2:
        raise InputError(f"{what} is a pair (low, high), not `{limits!r:.40}`")
    return _number(limits[0], what), _number(limits[1], what)


def _finite(what: str, values: tuple[float, ...], universe: tuple[float, float]) -> None:
    """Refuse NaN and infinity in a range or a held value as what they are (`-20:nan` was
    "not inside its universe", as if it were a number too large)."""
    for v in values:
        if not math.isfinite(v):
            kind = "not a number" if math.isnan(v) else "not a finite number"
            raise InputError(f"{what}: `{v:g}` is {kind}",
                             hint=f"give numbers inside the universe [{universe[0]:g}, "
                                  f"{universe[1]:g}]")


def surface(compiled: CompiledRuleBase | LoadedRuleBase, output: str, x: str, y: str | None = None,
            fixed: dict[str, float] | None = None, resolution: int = 61,
            x_range: tuple[float, float] | None = None,
            y_range: tuple[float, float] | None = None) -> Surface:
    """The control surface of ``output`` over ``x`` (and ``y``), the other inputs fixed.

    Inputs not in ``fixed`` are held at the midpoint of their universe (:class:`Fixed` says
    so). The whole grid is one batch through :func:`mitos_cli.engine.evaluation.evaluate` with
    ``strict=False``: where no rule fires and the output has no default, ``z`` is NaN.
    ``x_range`` / ``y_range`` zoom into part of a universe. ``compiled`` may be what
    ``load_rulebase`` returns.
    """
    from ...engine.evaluation import declares_nan, evaluate

    compiled = compiled_of(compiled, "surface")

    if not isinstance(output, str) or output not in compiled.outputs:
        raise unknown("output", f"{output!s:.40}", compiled.outputs, cls=InputError)
    if (n := whole_number(resolution)) is None or n < 2:     # (2.5 and "10" met TypeErrors)
        raise InputError(f"resolution is a whole number, 2 or more, not `{resolution!r:.40}`")
    ix = _input_axis(compiled, x, "--x")
    iy = _input_axis(compiled, y, "--y") if y is not None else None
    if iy == ix:
        raise InputError(f"`{x}` is on both axes", hint="choose two different inputs")
    fixed = dict(fixed or {})
    for name in fixed:
        if _input_axis(compiled, name, "--fix") in (ix, iy):
            raise InputError(f"`{name}` is on an axis and cannot also be fixed",
                             hint=f"drop --fix {name}=...")
    ax_x = _axis(compiled, ix, x_range, n)
    ax_y = _axis(compiled, iy, y_range, n) if iy is not None else None
    held = _held(compiled, fixed, (ix, iy))
    X = _grid(compiled, ix, ax_x, iy, ax_y, held)
    z = evaluate(compiled, X, detail=False, strict=False).output(output)
    if ax_y is not None:
        z = z.reshape(len(ax_y.values), len(ax_x.values))
    unit = compiled.variables[output].unit
    return Surface(output, unit, ax_x, ax_y, z, tuple(held), compiled.behavior,
                   declares_nan(compiled, output))


def _axis(compiled: CompiledRuleBase, k: int, limits: tuple[float, float] | None,
          resolution: int) -> Axis:
    """Input ``k``'s axis: its universe, or the part ``limits`` zooms into."""
    lo, hi = compiled.universe[k]
    if limits is not None:
        name = compiled.inputs[k]
        a, b = _pair(limits, f"the range of `{name}`")
        _finite(f"range {a:g}:{b:g} of `{name}`", (a, b), (lo, hi))
        if a > b:
            raise InputError(f"range {a:g}:{b:g} of `{name}` is reversed: LOW comes first",
                             hint=f"write {name}={b:g}:{a:g}")
        if a == b:
            raise InputError(f"range {a:g}:{b:g} of `{name}` is empty: LOW and HIGH are "
                             f"the same", hint="give LOW:HIGH with LOW < HIGH")
        if not (lo <= a < b <= hi):
            raise InputError(f"range {a:g}:{b:g} of `{name}` is not inside its universe "
                             f"[{lo:g}, {hi:g}]",
                             hint="give LOW:HIGH with LOW < HIGH inside the universe")
        lo, hi = a, b
    var = compiled.variables[compiled.inputs[k]]
    return Axis(var.name, var.unit, np.linspace(lo, hi, resolution))


def _held(compiled: CompiledRuleBase, fixed: dict[str, float],
          axes: tuple[int, int | None]) -> list[Fixed]:
    """The inputs on no axis, each at its value in ``fixed`` or its universe's midpoint."""
    held = []
    for k, name in enumerate(compiled.inputs):
        if k in axes:
            continue
        var = compiled.variables[name]
        if name in fixed:
            held.append(Fixed(name, _number(fixed[name], f"the value held for `{name}`"),
                              var.unit, False))
        else:
            lo, hi = compiled.universe[k]
            held.append(Fixed(name, float((lo + hi) / 2), var.unit, True))
    for f in held:
        lo, hi = compiled.universe[compiled.inputs.index(f.name)]
        _finite(f"--fix {f.name}={f.value:g}", (f.value,), (lo, hi))
        if not lo <= f.value <= hi:
            raise InputError(f"--fix {f.name}={f.value:g} is outside its universe "
                             f"[{lo:g}, {hi:g}]")
    return held


def _grid(compiled: CompiledRuleBase, ix: int, ax_x: Axis, iy: int | None, ax_y: Axis | None,
          held: list[Fixed]) -> np.ndarray:
    """The inputs' rows: the axes' points (``y`` major), the held inputs' values."""
    if ax_y is None or iy is None:
        X = np.empty((len(ax_x.values), len(compiled.inputs)))
        X[:, ix] = ax_x.values
    else:
        gx, gy = np.meshgrid(ax_x.values, ax_y.values)        # [ny, nx]
        X = np.empty((gx.size, len(compiled.inputs)))
        X[:, ix] = gx.ravel()
        X[:, iy] = gy.ravel()
    for f in held:
        X[:, compiled.inputs.index(f.name)] = f.value
    return X
