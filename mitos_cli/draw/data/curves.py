"""Term curves: every term of a variable sampled over its universe (corner points included, so
piecewise-linear curves are drawn exactly), and the memberships of a marked value."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...errors import InputError, unknown
from ...lang.model import RuleBase
from ...lang.terms import Term, TermSet, Variable

if TYPE_CHECKING:
    from ...api import LoadedRuleBase
    from ...engine.compile import CompiledRuleBase

#: Samples per term curve (corner points are added to these).
CURVE_POINTS = 401


@dataclass(frozen=True)
class TermCurve:
    """One term of a variable, ready to draw.

    ``kind`` is ``"curve"`` (a membership function sampled at ``x``), ``"singleton"`` (a crisp
    output value: ``x = [center]``, ``y = [1]``, drawn as a stem) or ``"linear"`` (a
    Takagi-Sugeno consequent, which has no membership function: ``formula`` says what it is).
    ``label_x`` is where its name goes: the middle of its plateau inside the universe.
    """

    name: str
    kind: str
    x: np.ndarray
    y: np.ndarray
    center: float
    label_x: float
    formula: str = ""


@dataclass(frozen=True)
class VariablePlot:
    """A variable's term set, with an optional value marked and its memberships."""

    name: str
    role: str
    unit: str
    description: str
    universe: tuple[float, float]
    curves: tuple[TermCurve, ...]
    value: float | None = None
    memberships: tuple[tuple[str, float], ...] = ()   # (term, mu) at ``value``, curves only
    clamped: bool = False                             # ``value`` was outside the universe

    def __repr__(self) -> str:   # the generated one printed every curve's points (20,000
        # characters for the sheet of the packaged rule base)
        lo, hi = self.universe
        marked = "" if self.value is None else f", marked at {self.value:g}"
        names = ", ".join(c.name for c in self.curves[:6]) + (", ..." if len(self.curves) > 6
                                                               else "")
        unit = f" {self.unit}" if self.unit else ""
        return (f"<VariablePlot {self.name!r} ({self.role}) [{lo:g}, {hi:g}]{unit}: "
                f"{len(self.curves)} terms ({names}){marked}>")

    @property
    def axis_label(self) -> str:
        return f"{self.name} [{self.unit}]" if self.unit else self.name


def visible(mu: float) -> bool:
    """Whether a membership is worth writing at two decimals (0.004 would print as 0.00)."""
    return round(mu, 2) > 0


def curve_grid(universe: tuple[float, float], terms: tuple[Term, ...] = (),
               points: int = CURVE_POINTS) -> np.ndarray:
    """``points`` samples of the universe plus every finite corner inside it, and the points
    just beside each corner, so that kinks and vertical edges land exactly on the grid. When
    every term is piecewise linear, the ends and corners alone draw them exactly (and keep
    SVG files small)."""
    lo, hi = universe
    if terms and all(t.corners is not None for t in terms):
        points = 2
    extra = []
    for term in terms:
        corners = term.corners
        if corners is None:
            continue
        for c in corners:
            if np.isfinite(c) and lo <= c <= hi:
                extra += [c, np.nextafter(c, -np.inf), np.nextafter(c, np.inf)]
    x = np.concatenate([np.linspace(lo, hi, points), np.asarray(extra, dtype=float)])
    return np.unique(np.clip(x, lo, hi))


def linear_formula(term: Term, inputs: tuple[str, ...]) -> str:
    """``y = 0.5 road - size + 90`` for a ``linear`` term over ``inputs`` (its term set's)."""
    *coefficients, constant = term.params
    parts = []
    for name, a in zip(inputs, coefficients):
        if a == 0:
            continue
        sign = "-" if a < 0 else "+"
        mag = abs(a)
        parts.append(f"{sign} {'' if mag == 1 else f'{mag:g} '}{name}")
    if constant or not parts:
        parts.append(f"{'-' if constant < 0 else '+'} {abs(constant):g}")
    text = " ".join(parts)
    text = text[2:] if text.startswith("+ ") else "-" + text[2:]
    return f"y = {text}"


def _term_curve(term: Term, x: np.ndarray, inputs: tuple[str, ...]) -> TermCurve:
    if term.shape == "linear":
        empty = np.empty(0)
        return TermCurve(term.name, "linear", empty, empty, float("nan"), float("nan"),
                         linear_formula(term, inputs))
    if term.shape == "singleton":
        c = term.center
        return TermCurve(term.name, "singleton", np.array([c]), np.array([1.0]), c, c)
    y = np.asarray(term.membership(x), dtype=float)
    return TermCurve(term.name, "curve", x, y, term.center, _label_x(x, y, term.center))


def _label_x(x: np.ndarray, y: np.ndarray, center: float) -> float:
    """The middle of the curve's plateau, among its finite values: a formula term may be NaN
    somewhere (``sqrt(x - 6)``), and one NaN made the plateau empty and the label NaN."""
    finite = np.isfinite(y)
    if finite.any():
        top = x[finite & (y >= y[finite].max())]
        return float((top.min() + top.max()) / 2)
    return center if np.isfinite(center) else float((x.min() + x.max()) / 2) if x.size else 0.0


def termset_inputs(source: RuleBase | TermSet, variable: str) -> tuple[str, ...]:
    """The input variables of the term set that defines ``variable`` (the layout of its
    ``linear`` terms' coefficients)."""
    for ts in _termsets(source):
        if any(v.name == variable for v in ts.variables):
            return tuple(v.name for v in ts.variables if v.role == "input")
    return ()


def _termsets(source: RuleBase | TermSet) -> tuple[TermSet, ...]:
    return (source,) if isinstance(source, TermSet) else source.termsets


def variable_plot(variable: Variable, value: float | None = None, *,
                  inputs: tuple[str, ...] = (), points: int = CURVE_POINTS) -> VariablePlot:
    """Sample every term of ``variable``; mark ``value`` (clamped to the universe, as the
    engine clamps inputs). ``inputs`` names the coefficients of ``linear`` terms."""
    x = curve_grid(variable.universe, variable.terms, points)
    curves = tuple(_term_curve(t, x, inputs) for t in variable.terms)
    mus: tuple[tuple[str, float], ...] = ()
    clamped = False
    if value is not None:
        from ...engine.inputs import floats

        lo, hi = variable.universe
        marked = floats(value, f"the value marked on `{variable.name}`")   # ("abc": float())
        if marked.ndim:
            raise InputError(f"the value marked on `{variable.name}` is one number, not of "
                             f"shape {marked.shape}")
        value = float(marked)
        if np.isnan(value):
            raise InputError(f"`{variable.name}` must be a number, not NaN")
        clamped = not lo <= value <= hi
        value = min(max(value, lo), hi)
        mus = tuple((t.name, float(t.membership(value))) for t in variable.terms
                    if t.shape not in ("linear", "singleton"))
    return VariablePlot(variable.name, variable.role, variable.unit, variable.description,
                        (variable.universe[0], variable.universe[1]), curves, value, mus, clamped)


def compiled_of(source: object, who: str) -> CompiledRuleBase:
    """The compiled behavior of ``source``: a :class:`CompiledRuleBase` as it is, the one a
    :class:`~mitos_cli.api.LoadedRuleBase` (what ``load_rulebase`` returns) holds; anything
    else is an :class:`InputError` (a LoadedRuleBase met "has no attribute 'universe'")."""
    from ...api import LoadedRuleBase
    from ...engine.compile import CompiledRuleBase

    if isinstance(source, LoadedRuleBase):
        return source.compiled
    if isinstance(source, CompiledRuleBase):
        return source
    raise InputError(f"{who} draws a compiled rule base, not {type(source).__name__} "
                     f"`{source!r:.40}`", hint=f"{who}(load_rulebase('my.rules'), ...)")


def sheet(rulebase: RuleBase | TermSet | LoadedRuleBase, names: list[str] | None = None,
          values: dict[str, float] | None = None, behavior: str | None = None,
          points: int = CURVE_POINTS) -> tuple[VariablePlot, ...]:
    """The membership sheet: every variable of the rule base or term set (inputs first, in
    file order), only those ``behavior`` uses, or the ``names`` asked for; ``values`` marked.
    A :class:`~mitos_cli.api.LoadedRuleBase` (``load_rulebase(...)``) is its rule base with
    its compiled behavior as ``behavior`` unless another is given. Unknown names get a "did
    you mean"."""
    from ...api import LoadedRuleBase

    if isinstance(rulebase, LoadedRuleBase):    # (it met "has no attribute 'termsets'")
        behavior = rulebase.compiled.behavior if behavior is None else behavior
        rulebase = rulebase.rulebase
    variables = {v.name: v for ts in _termsets(rulebase) for v in ts.variables}
    if isinstance(names, str):      # ("road" was read letter by letter: unknown variable `r`)
        raise InputError(f"names is a list of variable names, not the text `{names:.40}`",
                         hint=f"sheet(rulebase, [{names[:40]!r}])")
    values = dict(values or {})
    for name in list(names or []) + list(values):
        if name not in variables:
            raise unknown("variable", name, variables, cls=InputError)
    if names:
        chosen = [variables[n] for n in dict.fromkeys(names)]
    else:
        chosen = sorted(variables.values(), key=lambda v: v.role != "input")
        if behavior is not None and isinstance(rulebase, TermSet):
            raise InputError(f"a term set has no behaviors: behavior `{behavior:.40}` needs "
                             "the rule file that reads it")
        if behavior is not None and isinstance(rulebase, RuleBase):
            from ...engine.compile import compile_rulebase

            compiled = compile_rulebase(rulebase, behavior)
            used = set(compiled.inputs) | set(compiled.outputs)
            chosen = [v for v in chosen if v.name in used]
    return tuple(variable_plot(v, values.get(v.name), inputs=termset_inputs(rulebase, v.name),
                               points=points) for v in chosen)


