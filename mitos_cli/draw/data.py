"""What the pictures show, as plain data: term curves, control surfaces and rule-viewer rows.

Every picture of :mod:`mitos_cli.draw` (and every terminal plot of :mod:`mitos_cli.draw.terminal`)
draws one of the dataclasses built here, so what a picture says can be tested without
matplotlib and without looking at pixels:

- :func:`variable_plot` -> :class:`VariablePlot`: every term of a variable sampled over its
  universe (corner points included, so piecewise-linear curves are drawn exactly), and the
  memberships of a marked value;
- :func:`surface` -> :class:`Surface`: one output over a grid of one or two inputs with the
  others fixed, computed by the engine in one batch;
- :func:`rule_view` -> :class:`RuleView`: for one input, the fired rules with the memberships
  of their propositions, their DOFs and consequents, and each output's aggregate and result.

Nothing here imports matplotlib or prints.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..engine.compile import CompiledRuleBase
from ..errors import InputError, unknown
from ..fuzzy.hedges import apply as apply_hedges
from ..lang.model import And, Expr, Not, Or, Prop, RuleBase, format_expr
from ..lang.terms import Term, Variable

#: Samples per term curve (corner points are added to these).
CURVE_POINTS = 401


# ---------------------------------------------------------------- term curves


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
    top = x[y >= y.max()] if y.size else x
    label_x = float((top.min() + top.max()) / 2) if top.size else term.center
    return TermCurve(term.name, "curve", x, y, term.center, label_x)


def termset_inputs(rulebase: RuleBase, variable: str) -> tuple[str, ...]:
    """The input variables of the term set that defines ``variable`` (the layout of its
    ``linear`` terms' coefficients)."""
    for ts in rulebase.termsets:
        if any(v.name == variable for v in ts.variables):
            return tuple(v.name for v in ts.variables if v.role == "input")
    return ()


def variable_plot(variable: Variable, value: float | None = None, *,
                  inputs: tuple[str, ...] = (), points: int = CURVE_POINTS) -> VariablePlot:
    """Sample every term of ``variable``; mark ``value`` (clamped to the universe, as the
    engine clamps inputs). ``inputs`` names the coefficients of ``linear`` terms."""
    x = curve_grid(variable.universe, variable.terms, points)
    curves = tuple(_term_curve(t, x, inputs) for t in variable.terms)
    mus: tuple[tuple[str, float], ...] = ()
    clamped = False
    if value is not None:
        lo, hi = variable.universe
        value = float(value)
        if np.isnan(value):
            raise InputError(f"`{variable.name}` must be a number, not NaN")
        clamped = not lo <= value <= hi
        value = min(max(value, lo), hi)
        mus = tuple((t.name, float(t.membership(value))) for t in variable.terms
                    if t.shape not in ("linear", "singleton"))
    return VariablePlot(variable.name, variable.role, variable.unit, variable.description,
                        tuple(variable.universe), curves, value, mus, clamped)


def sheet(rulebase: RuleBase, names: list[str] | None = None,
          values: dict[str, float] | None = None, behavior: str | None = None,
          points: int = CURVE_POINTS) -> tuple[VariablePlot, ...]:
    """The membership sheet: every variable of the rule base (inputs first, in file order),
    only those ``behavior`` uses, or the ``names`` asked for; ``values`` marked. Unknown
    names get a "did you mean"."""
    variables = rulebase.variables
    values = dict(values or {})
    for name in list(names or []) + list(values):
        if name not in variables:
            raise unknown("variable", name, variables, cls=InputError)
    if names:
        chosen = [variables[n] for n in dict.fromkeys(names)]
    else:
        chosen = sorted(variables.values(), key=lambda v: v.role != "input")
        if behavior is not None:
            from ..engine.compile import compile_rulebase

            compiled = compile_rulebase(rulebase, behavior)
            used = set(compiled.inputs) | set(compiled.outputs)
            chosen = [v for v in chosen if v.name in used]
    return tuple(variable_plot(v, values.get(v.name), inputs=termset_inputs(rulebase, v.name),
                               points=points) for v in chosen)


# ---------------------------------------------------------------- control surfaces


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
        out = [f"`{f.name}` not fixed: held at {f.value:g}, the midpoint of its universe "
               f"(give --fix {f.name}=VALUE)" for f in self.fixed if f.defaulted]
        n = int(self.no_rule.sum())
        if n:
            out.append(f"no rule sets `{self.output}` at {n} of {self.z.size} grid points "
                       f"and it has no default: shown as a blank (masked) region")
        return out


def _input_axis(compiled: CompiledRuleBase, name: str, what: str) -> int:
    if name in compiled.inputs:
        return compiled.inputs.index(name)
    known = [v.name for v in compiled.variables.values() if v.role == "input"]
    if name in known:
        raise InputError(f"behavior `{compiled.behavior}` does not use input `{name}` ({what})",
                         expected="one of " + ", ".join(compiled.inputs))
    raise unknown(f"input ({what})", name, compiled.inputs, cls=InputError)


def surface(compiled: CompiledRuleBase, output: str, x: str, y: str | None = None,
            fixed: dict[str, float] | None = None, resolution: int = 61,
            x_range: tuple[float, float] | None = None,
            y_range: tuple[float, float] | None = None) -> Surface:
    """The control surface of ``output`` over ``x`` (and ``y``), the other inputs fixed.

    Inputs not in ``fixed`` are held at the midpoint of their universe (:class:`Fixed` says
    so). The whole grid is one batch through :func:`mitos_cli.engine.evaluation.evaluate` with
    ``strict=False``: where no rule fires and the output has no default, ``z`` is NaN.
    ``x_range`` / ``y_range`` zoom into part of a universe.
    """
    from ..engine.evaluation import evaluate

    if output not in compiled.outputs:
        raise unknown("output", output, compiled.outputs, cls=InputError)
    if resolution < 2:
        raise InputError(f"resolution must be at least 2, not {resolution}")
    ix = _input_axis(compiled, x, "--x")
    iy = _input_axis(compiled, y, "--y") if y is not None else None
    if iy == ix:
        raise InputError(f"`{x}` is on both axes", hint="choose two different inputs")
    fixed = dict(fixed or {})
    for name in fixed:
        k = _input_axis(compiled, name, "--fix")
        if k in (ix, iy):
            raise InputError(f"`{name}` is on an axis and cannot also be fixed",
                             hint=f"drop --fix {name}=...")

    def axis(k: int, limits: tuple[float, float] | None) -> Axis:
        lo, hi = compiled.universe[k]
        if limits is not None:
            a, b = limits
            if not (lo <= a < b <= hi):
                raise InputError(f"range {a:g}:{b:g} of `{compiled.inputs[k]}` is not inside "
                                 f"its universe [{lo:g}, {hi:g}]",
                                 hint="give LOW:HIGH with LOW < HIGH inside the universe")
            lo, hi = a, b
        var = compiled.variables[compiled.inputs[k]]
        return Axis(var.name, var.unit, np.linspace(lo, hi, resolution))

    ax_x = axis(ix, x_range)
    ax_y = axis(iy, y_range) if iy is not None else None
    held = []
    for k, name in enumerate(compiled.inputs):
        if k in (ix, iy):
            continue
        var = compiled.variables[name]
        if name in fixed:
            held.append(Fixed(name, float(fixed[name]), var.unit, False))
        else:
            lo, hi = compiled.universe[k]
            held.append(Fixed(name, float((lo + hi) / 2), var.unit, True))
    for f in held:
        lo, hi = compiled.universe[compiled.inputs.index(f.name)]
        if np.isnan(f.value) or not lo <= f.value <= hi:
            raise InputError(f"--fix {f.name}={f.value:g} is outside its universe "
                             f"[{lo:g}, {hi:g}]")

    if ax_y is None:
        X = np.empty((resolution, len(compiled.inputs)))
        X[:, ix] = ax_x.values
    else:
        gx, gy = np.meshgrid(ax_x.values, ax_y.values)        # [ny, nx]
        X = np.empty((gx.size, len(compiled.inputs)))
        X[:, ix] = gx.ravel()
        X[:, iy] = gy.ravel()
    for f in held:
        X[:, compiled.inputs.index(f.name)] = f.value
    result = evaluate(compiled, X, detail=False, strict=False)
    z = result.output(output)
    if ax_y is not None:
        z = z.reshape(len(ax_y.values), len(ax_x.values))
    unit = compiled.variables[output].unit
    return Surface(output, unit, ax_x, ax_y, z, tuple(held), compiled.behavior)


# ---------------------------------------------------------------- rule viewer


@dataclass(frozen=True)
class PropView:
    """One proposition ``var is [not] [hedges] TERM`` of a fired rule, at the input value."""

    var: str
    term: str
    hedges: tuple[str, ...]
    negated: bool
    x: np.ndarray             # the term's curve after hedges and negation, over the universe
    y: np.ndarray
    mu: float                 # the term's membership at the input (what eval prints)
    value: float              # after hedges and negation: what enters the rule's AND / OR

    @property
    def text(self) -> str:
        return format_expr(Prop(self.var, self.term, self.hedges, self.negated))


@dataclass(frozen=True)
class ConsequentView:
    """What a fired rule says about one output: its term (or number) and crisp value."""

    output: str
    term: str | None
    hedges: tuple[str, ...]
    value: float              # the crisp consequent (for a linear term: at this input)
    implied: np.ndarray | None = None   # Mamdani: the rule's implied set over the output grid
    full: np.ndarray | None = None      # Mamdani: the consequent set before implication


@dataclass(frozen=True)
class RuleRow:
    index: int                # position in the compiled behavior
    label: str
    text: str
    dof: float                # the engine's DOF: antecedent x rule weight x `use` contexts
    props: tuple[PropView, ...]
    consequents: tuple[ConsequentView, ...]
    antecedent: float = float("nan")   # the antecedent's value alone (eq. 17 for an AND)

    @property
    def factor(self) -> float:
        """What the rule's weight and its behavior's ``use ... when`` contexts multiply the
        antecedent by (1 for a plain rule)."""
        return self.dof / self.antecedent if self.antecedent > 0 else 1.0

    @property
    def dof_text(self) -> str:
        """``DOF 0.10``, or ``DOF 0.10 = 0.60 x 0.17`` when a weight or context scales it."""
        text = f"DOF {self.dof:.2f}"
        if abs(self.factor - 1.0) > 1e-12:
            text += f" = {self.antecedent:.2f} × {self.factor:.2f}"
        return text


@dataclass(frozen=True)
class OutputView:
    """An output's aggregate: for the weighted average, the consequent values with their
    summed DOFs (``stems``); for Mamdani, the aggregated set over ``grid``; and the result
    (NaN: no rule fired and no default)."""

    name: str
    unit: str
    universe: tuple[float, float]
    inference: str
    value: float
    defaulted: bool           # no rule set it: the value is the variable's default
    stems: tuple[tuple[float, float], ...] = ()       # (consequent value, summed DOF)
    grid: np.ndarray | None = None
    aggregate: np.ndarray | None = None

    @property
    def label(self) -> str:
        return f"{self.name} [{self.unit}]" if self.unit else self.name


@dataclass(frozen=True)
class InputValue:
    name: str
    unit: str
    value: float              # after clamping to the universe
    clamped: bool
    memberships: tuple[tuple[str, float], ...]
    universe: tuple[float, float]


@dataclass(frozen=True)
class RuleView:
    behavior: str
    operators: str
    n_rules: int
    inputs: tuple[InputValue, ...]
    rows: tuple[RuleRow, ...]          # fired rules, in rule-base order
    outputs: tuple[OutputView, ...]


def props_of(expr: Expr) -> list[tuple[Prop, bool]]:
    """The propositions of an antecedent in reading order, each with whether an enclosing
    ``not (...)`` inverts it (shown as drawn, not as evaluated: the DOF comes from the engine)."""
    out: list[tuple[Prop, bool]] = []

    def walk(e: Expr, inverted: bool) -> None:
        if isinstance(e, Prop):
            out.append((e, inverted))
        elif isinstance(e, Not):
            walk(e.expr, not inverted)
        elif isinstance(e, (And, Or)):
            for item in e.items:
                walk(item, inverted)

    walk(expr, False)
    return out


def _prop_view(prop: Prop, inverted: bool, variable: Variable, mu: float) -> PropView:
    """``inverted``: an enclosing ``not (...)`` applies, drawn as a negated proposition."""
    if inverted:
        prop = Prop(prop.var, prop.term, prop.hedges, not prop.negated)
    term = variable.term(prop.term)
    x = curve_grid(variable.universe, (term,))
    y = np.asarray(term.membership(x), dtype=float)
    hedged = float(apply_hedges(prop.hedges, np.array(mu))) if prop.hedges else mu
    if prop.hedges:
        y = apply_hedges(prop.hedges, y)
    if prop.negated:
        y = 1.0 - y
        hedged = 1.0 - hedged
    return PropView(prop.var, prop.term, prop.hedges, prop.negated, x, y, mu, hedged)


def rule_view(compiled: CompiledRuleBase, values: dict[str, float]) -> RuleView:
    """Evaluate one input and collect what the rule viewer draws.

    Memberships, DOFs and outputs are the engine's (the numbers ``mitos eval`` prints); the
    rows are the rules with DOF > 0 in rule-base order. For Mamdani inference each consequent
    carries the rule's implied output set and each output the aggregated set
    (:mod:`mitos_cli.engine.mamdani`).
    """
    from ..engine.evaluation import as_batch, evaluate

    X = as_batch(compiled, values)
    if X.shape[0] != 1:
        raise InputError("the rule viewer takes one value per input")
    res = evaluate(compiled, X, detail=True, keep_values=True, strict=False)
    antecedent = res.values[0][compiled.rule_col]
    mu = res.memberships[0]
    dof = res.dof[0]
    term_index = {key: i for i, key in enumerate(compiled.term_names)}

    inputs = []
    for k, name in enumerate(compiled.inputs):
        var = compiled.variables[name]
        lo, hi = compiled.universe[k]
        v = float(res.inputs[0, k])
        mus = tuple((t.name, float(mu[term_index[(name, t.name)]])) for t in var.terms)
        inputs.append(InputValue(name, var.unit, v, bool(res.clamped[k]) and v in (lo, hi), mus,
                                 (float(lo), float(hi))))

    crisp = compiled.cons_value
    if compiled.cons_linear is not None:
        from ..engine.evaluation import linear_consequents

        crisp = linear_consequents(compiled, np.ascontiguousarray(res.inputs.T))[:, :, 0].T
    mamdani = compiled.operators.inference == "mamdani"
    sets = _mamdani_sets(compiled, dof) if mamdani else None

    fired = np.flatnonzero(dof > 0)
    rows = []
    for r in fired:
        rule = compiled.rules[r]
        props = []
        for prop, inverted in props_of(rule.antecedent):
            props.append(_prop_view(prop, inverted, compiled.variables[prop.var],
                                    float(mu[term_index[(prop.var, prop.term)]])))
        cons = tuple(
            ConsequentView(out, compiled.cons_term[r][j], compiled.cons_hedges[r][j],
                           float(crisp[r, j]),
                           *((None, None) if sets is None else sets[j][0][int(r)]))
            for j, out in enumerate(compiled.outputs) if compiled.cons_mask[r, j])
        rows.append(RuleRow(int(r), compiled.labels[r], compiled.rule_text(r), float(dof[r]),
                            tuple(props), cons, float(antecedent[r])))

    outputs = []
    for j, name in enumerate(compiled.outputs):
        var = compiled.variables[name]
        setting = compiled.cons_mask[:, j] & (dof > 0)
        value = float(res.outputs[0, j])
        stems: tuple[tuple[float, float], ...] = ()
        grid = agg = None
        if mamdani:
            _, grid, agg = sets[j]
        else:
            summed: dict[float, float] = {}
            for r in np.flatnonzero(setting):
                summed[float(crisp[r, j])] = summed.get(float(crisp[r, j]), 0.0) + float(dof[r])
            stems = tuple(sorted(summed.items()))
        outputs.append(OutputView(name, var.unit, tuple(var.universe),
                                  compiled.operators.inference, value, not setting.any(),
                                  stems, grid, agg))
    return RuleView(compiled.behavior, compiled.operators.describe(), compiled.n_rules,
                    tuple(inputs), tuple(rows), tuple(outputs))


def _mamdani_sets(compiled: CompiledRuleBase, dof: np.ndarray):
    """Per output ``j``: ``({rule: (implied set, consequent set)}, grid, aggregate)`` for one
    sample's DOFs,
    from the sampled consequent sets the engine uses (:mod:`mitos_cli.engine.mamdani`)."""
    from ..engine import mamdani
    from ..fuzzy import norms

    ops = compiled.operators
    aggregation = norms.lookup("snorm", ops.aggregation)
    out = []
    for table in compiled.mamdani:            # one per output
        sets = table.sets[table.set_of]                           # [R_j, res]
        d = dof[table.rules]
        implied = mamdani.IMPLICATIONS[ops.implication](d[:, None], sets)
        agg = (mamdani.aggregate(d[:, None], sets, ops.implication, aggregation)[0]
               if len(table.rules) else np.zeros_like(table.grid))
        out.append(({int(r): (implied[i], sets[i]) for i, r in enumerate(table.rules)},
                    table.grid, agg))
    return out
