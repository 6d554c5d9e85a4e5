"""The rule viewer's data: for one input, the fired rules with the memberships of their
propositions, their DOFs and consequents, and each output's aggregate and result."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...engine.compile import CompiledRuleBase
from ...errors import InputError
from ...fuzzy.hedges import apply as apply_hedges
from ...fuzzy.hedges import weigh
from ...lang.model import And, Expr, Not, Or, Prop, format_expr
from ...lang.terms import Variable
from .curves import compiled_of, curve_grid

if TYPE_CHECKING:
    from ...api import LoadedRuleBase
    from ...engine.evaluation import Result


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
    nan_default: bool = False          # declares NaN as its default (`default: .nan`)

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

    def __repr__(self) -> str:   # the generated one printed every row's view (6,000 characters)
        outputs = ", ".join(f"{o.name} {o.value:.4g}{' ' + o.unit if o.unit else ''}"
                            for o in self.outputs)
        return (f"<RuleView of {self.behavior!r}: {len(self.rows)} of {self.n_rules} rules "
                f"fired; {outputs}>")


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


def rule_view(compiled: CompiledRuleBase | LoadedRuleBase, values: dict[str, float]) -> RuleView:
    """Evaluate one input and collect what the rule viewer draws.

    Memberships, DOFs and outputs are the engine's (the numbers ``mitos eval`` prints); the
    rows are the rules with DOF > 0 in rule-base order. For Mamdani inference each consequent
    carries the rule's implied output set and each output the aggregated set
    (:mod:`mitos_cli.engine.mamdani`). ``compiled`` may be what ``load_rulebase`` returns.
    """
    from ...engine.evaluation import as_batch, evaluate

    compiled = compiled_of(compiled, "rule_view")

    X = as_batch(compiled, values)
    if X.shape[0] != 1:
        raise InputError("the rule viewer takes one value per input")
    res = evaluate(compiled, X, detail=True, keep_values=True, strict=False)
    assert res.values is not None and res.memberships is not None and res.dof is not None
    mu = res.memberships[0]
    dof = res.dof[0]
    term_index = {key: i for i, key in enumerate(compiled.term_names)}

    crisp = compiled.cons_value
    if compiled.cons_linear is not None:
        from ...engine.evaluation import linear_consequents

        crisp = linear_consequents(compiled, np.ascontiguousarray(res.inputs.T))[:, :, 0].T
    mamdani = compiled.operators.inference == "mamdani"
    sets = _mamdani_sets(compiled, dof) if mamdani else None
    if compiled.operators.inference == "tsukamoto":
        crisp = _tsukamoto_points(compiled, dof, crisp)

    inputs = _input_values(compiled, res, mu, term_index)
    rows = _rule_rows(compiled, res.values[0][compiled.rule_col], dof, mu, term_index, crisp,
                      sets)
    outputs = _output_views(compiled, res, dof, crisp, sets)
    return RuleView(compiled.behavior, compiled.describe_operators(), compiled.n_rules,
                    inputs, rows, outputs)


#: Each output's Mamdani sets (:func:`_mamdani_sets`): each rule's implied set, and the
#: aggregated set on its grid.
_Sets = list[tuple[dict[int, tuple[np.ndarray, np.ndarray]], np.ndarray, np.ndarray]]


def _input_values(compiled: CompiledRuleBase, res: Result, mu: np.ndarray,
                  term_index: dict[tuple[str, str], int]) -> tuple[InputValue, ...]:
    """Each input's value (said to be clamped only when it was moved onto an end of its
    universe) and its terms' memberships (``mu``, at ``term_index``)."""
    inputs = []
    for k, name in enumerate(compiled.inputs):
        var = compiled.variables[name]
        lo, hi = compiled.universe[k]
        v = float(res.inputs[0, k])
        mus = tuple((t.name, float(mu[term_index[(name, t.name)]])) for t in var.terms)
        inputs.append(InputValue(name, var.unit, v, bool(res.clamped[k]) and v in (lo, hi), mus,
                                 (float(lo), float(hi))))
    return tuple(inputs)


def _rule_rows(compiled: CompiledRuleBase, antecedent: np.ndarray, dof: np.ndarray,
               mu: np.ndarray, term_index: dict[tuple[str, str], int], crisp: np.ndarray,
               sets: _Sets | None) -> tuple[RuleRow, ...]:
    """A row for each rule that fires (DOF > 0), in rule-base order: its propositions'
    memberships, its consequents (each with its implied set under Mamdani inference), its
    DOF and its condition's value before the weight (``antecedent``)."""
    rows = []
    for r in np.flatnonzero(dof > 0).tolist():
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
    return tuple(rows)


def _output_views(compiled: CompiledRuleBase, res: Result, dof: np.ndarray,
                  crisp: np.ndarray, sets: _Sets | None) -> tuple[OutputView, ...]:
    """Each output's value and what made it: the aggregated set under Mamdani inference,
    else a stem per value the firing rules set (:func:`_summed`); whether no rule set it."""
    from ...engine.evaluation import declares_nan

    outputs = []
    for j, name in enumerate(compiled.outputs):
        var = compiled.variables[name]
        setting = compiled.cons_mask[:, j] & (dof > 0)
        value = float(res.outputs[0, j])
        stems: tuple[tuple[float, float], ...] = ()
        grid = agg = None
        if sets is not None:
            _, grid, agg = sets[j]
        else:
            stems = _summed(compiled, j, np.flatnonzero(setting), crisp, dof)
        outputs.append(OutputView(name, var.unit, tuple(var.universe),
                                  compiled.operators.inference, value, not setting.any(),
                                  stems, grid, agg, declares_nan(compiled, name)))
    return tuple(outputs)


def _tsukamoto_points(compiled: CompiledRuleBase, dof: np.ndarray,
                      crisp: np.ndarray) -> np.ndarray:
    """``crisp`` with each rule's consequent where Tsukamoto inference puts it: its term
    inverted at the term's activation, the summed (hedged) DOFs of the rules concluding it
    (:mod:`mitos_cli.engine.tsukamoto`), not at the term's centre."""
    from ...fuzzy.shapes import TSUKAMOTO

    points = np.array(crisp, dtype=float)
    for j, name in enumerate(compiled.outputs):
        var = compiled.variables[name]
        concluding: dict[str, list[int]] = {}
        for r in range(compiled.n_rules):
            term = compiled.cons_term[r][j]
            if term is not None:
                concluding.setdefault(term, []).append(r)
        for term, rules in concluding.items():
            w = sum(float(weigh(compiled.cons_hedges[r][j], np.asarray(dof[r])))
                    if compiled.cons_hedges[r][j] else float(dof[r]) for r in rules)
            if w > 0:
                t = var.term(term)
                with np.errstate(invalid="ignore", divide="ignore"):
                    points[rules, j] = float(TSUKAMOTO[t.shape](np.asarray(w), *t.params))
    return points


def _summed(compiled: CompiledRuleBase, j: int, rules: np.ndarray, crisp: np.ndarray,
            dof: np.ndarray) -> tuple[tuple[float, float], ...]:
    """Output ``j``'s consequent values with the summed weights the engine averages them by: a
    hedged consequent's is ``hedge(dof)`` (``very`` squares it), not the rule's DOF; under
    ``accumulation = S`` (an S-norm) the rules of one value are joined by S in rule order,
    not summed (:func:`mitos_cli.engine.evaluation`'s accumulated inference)."""
    from ...fuzzy import norms

    accumulation = compiled.operators.accumulation
    join = None if accumulation == "sum" else norms.lookup("snorm", accumulation)
    summed: dict[float, float] = {}
    for r in rules.tolist():
        hedges = compiled.cons_hedges[r][j]
        w = float(weigh(hedges, np.asarray(dof[r]))) if hedges else float(dof[r])
        value = float(crisp[r, j])
        if value not in summed:
            summed[value] = w
        elif join is None:
            summed[value] += w
        else:
            summed[value] = float(join(np.asarray(summed[value]), np.asarray(w)))
    return tuple(sorted(summed.items()))


def _mamdani_sets(compiled: CompiledRuleBase, dof: np.ndarray) -> _Sets:
    """Per output ``j``: ``({rule: (implied set, consequent set)}, grid, aggregate)`` for one
    sample's DOFs,
    from the sampled consequent sets the engine uses (:mod:`mitos_cli.engine.mamdani`)."""
    from ...engine import mamdani
    from ...fuzzy import norms

    ops = compiled.operators
    aggregation = norms.aggregation(ops.aggregation)
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
