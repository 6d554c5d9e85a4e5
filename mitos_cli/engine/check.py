"""Static analysis of a rule base (``mitos check``): what the rules leave out or say twice.

:func:`check_rulebase` returns a :class:`Report` of :class:`Finding` objects, each with a
severity, a message, the place in the rule file or term set it concerns (a :class:`Span`) and,
for findings about the input space, the regions as boxes of input ranges. Nothing here prints.

What is checked, per behavior (every behavior of the file unless one is named; then the term
sets' findings are only about the variables it reads or sets):

====================  ==========  ==========================================================
code                  severity    meaning
====================  ==========  ==========================================================
``no-rule-fires``     error       a region of the input space where no rule sets an output
                                  that declares no ``default`` (``mitos eval`` fails there)
``no-rule-fires``     warning     the same, but the output falls back to its ``default`` (or
                                  the inference is ``weighted_sum`` and it declares none:
                                  the sum is 0 there)
``low-dof``           warning     a region where some rule fires but the total DOF of the
                                  rules setting an output is below ``threshold``
``conflict``          error       rules with the same antecedent and different consequents
``duplicate``         warning     rules with the same antecedent and the same consequents
``contradiction``     warning     an antecedent that asks for ``x is A`` and ``x is not A``
``idle-setting``      warning     a Mamdani-only operator setting (``defuzzify``, ...), or an
                                  output's own ``resolution:``, where the inference is not
                                  Mamdani
``infinite-output``   warning     a sigmoid a Tsukamoto rule concludes: it reaches 1 only at
                                  infinity, so where the rule fires fully the output is +-inf
``unreachable``       warning     a rule that fires nowhere: its DOF is 0 on a grid of the
                                  inputs its conditions name, every corner point of their
                                  terms and the midpoints between them (info, hedged, when
                                  even that grid is too large to hold them)
``term-gap``          warning     a stretch of an input's universe where all its terms are 0
``term-outside``      warning     an input term that never reaches 1 inside the universe;
                                  a Mamdani output term (as a rule concludes it) that lies
                                  outside its output's range, or is 0 all over it
``unused-term``       warning     an input term (or a whole input) that no rule uses (info
                                  for a term no other covers: the term set needs it)
``unconcluded-term``  info        an output term that no rule concludes
``undersampled-term`` warning     a Mamdani output term (as a rule concludes it) whose largest
                                  membership over the output's sample points is below
                                  :data:`~mitos_cli.engine.mamdani.UNDERSAMPLED_BELOW` (0.5):
                                  narrower than the sampling step, its rules hardly change
                                  the output (above 0 somewhere in the range, else
                                  ``term-outside``)
``term-order``        warning     terms whose peaks (values) are not in the written order
``coverage``          warning     a point of an input's universe where no term reaches 0.5
``indistinct``        warning     two terms of a variable too alike to tell apart
``off-centre``        warning     the middle of mirror-symmetric terms off their point
====================  ==========  ==========================================================

The last four are the interpretability checks of :mod:`mitos_cli.lang.interpretability` (their
thresholds are documented there); ``mitos teach`` runs them after ``adapt`` and ``save``.

The input space is sampled on a grid: ``resolution`` evenly spaced points per input plus every
corner point of its terms (where memberships start or stop being 0), capped at
:data:`MAX_SAMPLES` points in all. The whole grid is one vectorized batch through
:func:`mitos_cli.engine.evaluation.evaluate`. With many inputs even the corner points are too
many; the grid then skips some, and :attr:`GridInfo.skipped` names those inputs (the
``no-rule-fires`` and ``low-dof`` findings say so too: they may miss places between samples).
A behavior that others ``use`` is judged where it is in use (:class:`InUse`): a sample of
its grid counts in ``no-rule-fires`` and ``low-dof`` only where some ``use ... when`` chain
from a behavior nothing uses brings it in and no rule outside it sets the output there. A
behavior that uses others gets its ``no-rule-fires`` exactly, with no grid (:class:`Exact`,
:mod:`.regions`); only its ``low-dof`` is sampled. Either falls back to the behavior's own
grid where :mod:`.regions` has no exact answer (other operators or terms).
Regions are reported as boxes of sampled values, e.g.
``road in [0, 40] and size in [70, 100]``; an input left out of a box may take any value.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from ..errors import Span
from ..lang import interpretability as meaning
from ..lang.model import (
    And,
    Consequent,
    Expr,
    Not,
    Prop,
    Rule,
    RuleBase,
    flatten,
    format_consequent,
    format_expr,
)
from ..lang.terms import TermSet, Variable
from . import regions
from .compile import CompiledRuleBase, compile_rulebase
from .evaluation import BLOCK_CELLS, declares_nan, rule_dofs

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator, Sequence

    from ..lang.operators import Operators
    from ..lang.terms import Term
    from .mamdani import Undersampled

SEVERITIES = ("error", "warning", "info")
#: Most grid points one behavior is sampled on (the per-input resolution shrinks to fit).
MAX_SAMPLES = 300_000
#: Regions listed per finding; the rest are counted.
MAX_BOXES = 6
#: Points per universe when looking for gaps between the terms of one input.
GAP_RESOLUTION = meaning.GAP_RESOLUTION
#: An input term whose largest membership inside the universe reaches this counts as reaching
#: 1: a sigmoid used as a shoulder comes within 1e-4 of 1 but never gets there, and its peak
#: is not "outside the universe" for that.
NEARLY_ONE = 0.99


@dataclass(frozen=True)
class Box:
    """A box of the input space: ``ranges[var] = (lo, hi)``; inputs not named are free.
    ``open`` says, range by range, which ends are left out: an end at a crisp step, where
    the region runs up to the step but not onto it (``x in [0, 2)``)."""

    ranges: tuple[tuple[str, float, float], ...]
    open: tuple[tuple[bool, bool], ...] = ()

    def describe(self) -> str:
        if not self.ranges:
            return "everywhere"
        parts = []
        ends = self.open or ((False, False),) * len(self.ranges)
        for (name, lo, hi), (open_lo, open_hi) in zip(self.ranges, ends):
            parts.append(f"{name} = {_num(lo)}" if lo == hi else
                         f"{name} in {'(' if open_lo else '['}{_num(lo)}, {_num(hi)}"
                         f"{')' if open_hi else ']'}")
        return " and ".join(parts)

    def to_json(self) -> dict:
        return {name: [lo, hi] for name, lo, hi in self.ranges}


@dataclass(frozen=True)
class Finding:
    severity: str            # "error", "warning" or "info"
    code: str
    message: str
    span: Span | None = None
    behavior: str | None = None
    hint: str | None = None
    regions: tuple[Box, ...] = ()
    more_regions: int = 0    # boxes not listed in ``regions``
    share: float | None = None   # fraction of the input space's volume (volume_share)
    uncovered: int = 0       # grid cells of a very ragged region left out of every box

    def to_json(self) -> dict:
        out: dict[str, object] = {"severity": self.severity, "code": self.code, "behavior": self.behavior,
               "message": self.message,
               "span": None if self.span is None else
               {"path": self.span.path, "line": self.span.line, "column": self.span.column}}
        if self.hint:
            out["hint"] = self.hint
        if self.regions or self.share is not None:
            out["regions"] = [b.to_json() for b in self.regions]
            out["more_regions"] = self.more_regions
            out["uncovered_samples"] = self.uncovered
            out["share"] = self.share
        return out


@dataclass(frozen=True)
class GridInfo:
    behavior: str
    points: tuple[tuple[str, int], ...]    # samples per input
    samples: int
    #: inputs whose terms' corner points the grid could not all hold (too many inputs):
    #: `no-rule-fires` and `low-dof` may miss places between its samples
    skipped: tuple[str, ...] = ()
    corner_samples: float = 0.0            # the samples every corner point would take
    #: `no-rule-fires` was decided exactly, with no grid (:mod:`.regions`): only `low-dof`
    #: is sampled
    exact: bool = False


@dataclass(frozen=True)
class Report:
    rulebase: RuleBase
    findings: tuple[Finding, ...]
    grids: tuple[GridInfo, ...]
    threshold: float
    behaviors: tuple[str, ...] = field(default=())

    def count(self, severity: str) -> int:
        return sum(f.severity == severity for f in self.findings)

    @property
    def ok(self) -> bool:
        """No error-level finding."""
        return self.count("error") == 0


def _num(x: float) -> str:
    return f"{x:.6g}"


# ---------------------------------------------------------------------------------------------
# entry point

def check_rulebase(rb: RuleBase, behavior: str | None = None, *, threshold: float = 0.1,
                   resolution: int = 41) -> Report:
    """Analyse ``behavior`` of ``rb`` (every behavior when ``None``)."""
    names = [behavior] if behavior else [b.name for b in rb.behaviors]
    findings: list[Finding] = []
    grids: list[GridInfo] = []
    seen: set[tuple] = set()               # undersampled terms already reported
    for name in names:
        rb.behavior(name)                       # unknown behavior: did-you-mean error
    compositions = _Compositions(rb)
    for name in names:
        compiled = compile_rulebase(rb, name)
        findings += _rule_pairs(rb, name, compiled.operators)
        findings += _contradictions(rb, name)
        findings += _idle_settings(rb, name, compiled)
        findings += _undersampled(rb, name, compiled, seen)
        findings += _infinite_inverses(rb, name, compiled, seen)
        grid_findings, info = _sampled(compiled, threshold, resolution,
                                       compositions.in_use(name, compiled),
                                       compositions.exact(name, compiled))
        findings += grid_findings
        grids.append(info)
    # the term sets' findings: with one behavior named, only about the variables it uses
    # (its used behaviors' included); `nearest.ROOMY` is no concern of `avoid_obstacle`
    scope = None if not behavior else set().union(*(
        set(c.inputs) | set(c.outputs) for c in (compile_rulebase(rb, n) for n in names)))
    findings += _term_gaps(rb, scope)
    findings += _unused_terms(rb, scope)
    findings += _interpretability(rb, scope)
    order = {s: i for i, s in enumerate(SEVERITIES)}
    findings.sort(key=lambda f: (order[f.severity], _span_key(f.span)))
    return Report(rb, tuple(findings), tuple(grids), threshold, tuple(names))


def check_termset(ts: TermSet) -> Report:
    """The findings a term set has on its own, before any rule reads it: input terms that
    never reach 1 or leave gaps, and the interpretability checks (order, coverage, distinct
    terms, centre terms on their points). The rules' findings need a rule file."""
    rb = RuleBase(ts.path, (ts,), ())
    findings = _term_gaps(rb) + _interpretability(rb)
    order = {s: i for i, s in enumerate(SEVERITIES)}
    findings.sort(key=lambda f: (order[f.severity], _span_key(f.span)))
    return Report(rb, tuple(findings), (), 0.0)


#: operator settings that only Mamdani inference reads
MAMDANI_ONLY = ("implication", "aggregation", "defuzzify", "resolution", "sampling")


def _idle_settings(rb: RuleBase, name: str, compiled: CompiledRuleBase) -> list[Finding]:
    """Settings that the behavior's inference method ignores (``defuzzify = lom`` without
    ``inference = mamdani`` is almost certainly a mistake)."""
    inference = compiled.operators.inference
    weighted = inference in ("weighted_average", "weighted_sum")
    out = []
    for setting in tuple(rb.operators) + tuple(rb.behavior(name).operators):
        if setting.key == "accumulation" and not weighted:
            out.append(Finding(
                "warning", "idle-setting",
                f"`{setting.key} = {setting.value}` has no effect: behavior `{name}` uses "
                f"{inference} inference", setting.span, name,
                "accumulation joins the rules of one value under weighted_average or "
                "weighted_sum inference; remove the setting"))
        if setting.key in MAMDANI_ONLY and inference != "mamdani":
            out.append(Finding(
                "warning", "idle-setting",
                f"`{setting.key} = {setting.value}` has no effect: behavior `{name}` uses "
                f"{compiled.operators.inference} inference", setting.span, name,
                "add `inference = mamdani` to the operators line, or remove the setting"))
    if inference != "mamdani":        # an output's own resolution, from its term set
        for output in compiled.outputs:
            var = compiled.variables.get(output)
            if var is not None and var.resolution is not None:
                out.append(Finding(
                    "warning", "idle-setting",
                    f"`{output}`'s own `resolution: {var.resolution}` has no effect: behavior "
                    f"`{name}` uses {inference} inference", var.span, name,
                    "add `inference = mamdani` to the operators line, or remove the "
                    "resolution"))
    return out


def _undersampled(rb: RuleBase, name: str, compiled: CompiledRuleBase, seen: set[tuple]) -> list[Finding]:
    """Output terms that the Mamdani sampling misses (:func:`.mamdani.undersampled`), once
    per term and sampling however many behaviors conclude them."""
    from .mamdani import undersampled

    out = []
    for u in undersampled(compiled):
        key = (u.output, u.label, u.points, u.step)
        if key in seen:
            continue
        seen.add(key)
        term = rb.variables[u.output].term(u.term)
        code = "term-outside" if u.outside else "undersampled-term"
        out.append(Finding("warning", code, u.describe(), term.span, name,
                           undersampled_hint(rb.path, u)))
    return out


def _infinite_inverses(rb: RuleBase, name: str, compiled: CompiledRuleBase,
                      seen: set[tuple]) -> list[Finding]:
    """Sigmoids a Tsukamoto behavior concludes, once per term: a sigmoid reaches 1 only at
    infinity, so where its rules fire fully the output is +-inf."""
    if compiled.operators.inference != "tsukamoto":
        return []
    out = []
    for j, output in enumerate(compiled.outputs):
        for r in range(compiled.n_rules):
            term = compiled.cons_term[r][j]
            if term is None or ("infinite", output, term) in seen \
                    or rb.variables[output].term(term).shape != "sigmoid":
                continue
            seen.add(("infinite", output, term))
            out.append(Finding(
                "warning", "infinite-output",
                f"`{output}.{term}` is a sigmoid, which Tsukamoto inference inverts: it reaches "
                f"1 only at infinity, so where rule `{compiled.labels[r]}` fires fully "
                f"`{output}` is +-inf (as in fuzzylite)", rb.variables[output].term(term).span,
                name, "conclude a term that reaches 1 (ramp, s_shape, z_shape, concave, arc), "
                      "or keep the rule's degree below 1"))
    return out


def undersampled_hint(path: str | None, u: Undersampled) -> str:
    """What to do about a term its output's sampling misses: a finer sampling, or (a term
    outside the range, or 0 all over it) moving it in."""
    if u.outside == "outside":
        return "move the term into the range, or widen the output's range"
    if u.outside:
        return "change the term so that it is above 0 somewhere in the output's range"
    return resolution_hint(path, u.points, u.output if u.own else None)


def resolution_hint(path: str | None, points: int, own: str | None = None) -> str:
    """How to sample an output more finely, in the words of the file's format."""
    suffix = (path or "").rsplit(".", 1)[-1].lower()
    finer = 1001 if points < 1001 else min(points * 10, 100_000)
    if suffix == "fis":
        return ("widen it; a .fis output is always sampled at MATLAB's 101 points: `mitos eval "
                "--fidelity fuzzylite` samples 1000, or convert the file (`mitos convert --to "
                "rules`) and set `resolution = 1001`")
    if suffix == "fll":
        return (f"widen it, or raise the defuzzifier's resolution (`defuzzifier: Centroid "
                f"{finer}`)")
    if suffix == "fcl":
        return (f"widen it, or raise the defuzzifier's resolution (`METHOD : COG "
                f"{finer};`, which MITOS reads; fuzzylite 6 and jFuzzyLogic read none)")
    if own is not None:          # the output's own resolution, which the operators' do not set
        return (f"widen it, or raise `{own}`'s own resolution (now {points}): `resolution: "
                f"{finer}` under `{own}` in its term set")
    return (f"widen it, or raise the resolution (now {points}): `resolution = {finer}` in "
            f"the behavior's (or the file's) `operators:` line")


def _span_key(span: Span | None) -> tuple:
    return ("", 0, 0) if span is None else (span.path or "", span.line, span.column)


def _behavior_span(rb: RuleBase, name: str) -> Span | None:
    b = rb.behavior(name)
    if b.span is not None:
        return b.span
    if b.rules and b.rules[0].span is not None:       # top-level rules: point at the first
        return b.rules[0].span
    return Span(rb.path, 1, 1) if rb.path else None


# ---------------------------------------------------------------------------------------------
# rules compared with each other (conflicts, duplicates)

def canonical(expr: Expr) -> tuple:   # nested tuples and frozensets of names and flags
    """A key equal for antecedents that differ only in the order of `and` / `or` items."""
    if isinstance(expr, Prop):
        return ("prop", expr.var, expr.term, expr.hedges, expr.negated)
    if isinstance(expr, Not):
        inner = canonical(expr.expr)
        if inner[0] == "prop":                 # not (x is A) == x is not A
            return inner[:4] + (not inner[4],)
        if inner[0] == "not":
            return inner[1]
        return ("not", inner)
    op = "and" if isinstance(expr, And) else "or"
    items: set[tuple] = set()
    for item in expr.items:
        key = canonical(item)
        items.update(key[1] if key[0] == op else (key,))
    if len(items) == 1:
        return next(iter(items))
    return (op, frozenset(items))


def _consequents(rule: Rule) -> dict[str, Consequent]:
    return {c.var: c for c in rule.consequents}


def _same(a: Consequent, b: Consequent, variables: dict[str, Variable]) -> bool:
    def value(c: Consequent) -> tuple:
        if c.term is None:
            return ("value", c.value)
        center = variables[c.var].term(c.term).center
        if c.hedges or center != center:     # hedged, or a linear (Takagi-Sugeno) term
            return ("term", c.hedges, c.term)
        return ("value", center)
    return value(a) == value(b)


def _rule_pairs(rb: RuleBase, behavior: str, operators: Operators) -> list[Finding]:
    flat = flatten(rb, behavior)
    groups: dict[object, list[int]] = {}
    for i, (_, rule, contexts) in enumerate(flat):
        if rule.weight == 0 or any(u.weight == 0 for u in contexts):
            continue                 # it never fires (`unreachable` says so): no twin of any
        key = (canonical(rule.antecedent),
               tuple(canonical(u.condition) if u.condition is not None else None
                     for u in contexts))
        groups.setdefault(key, []).append(i)
    variables = rb.variables
    out = []
    for members in groups.values():
        for pos, j in enumerate(members[1:], start=1):
            label_j, rule_j, _ = flat[j]
            for i in members[:pos]:
                label_i, rule_i, _ = flat[i]
                ci, cj = _consequents(rule_i), _consequents(rule_j)
                clash = [v for v in ci if v in cj and not _same(ci[v], cj[v], variables)]
                where = f"`{label_j}` has the same antecedent as `{label_i}`"
                if clash:
                    says = "; ".join(f"{format_consequent(ci[v])} vs "
                                     f"{format_consequent(cj[v])}" for v in clash)
                    out.append(Finding(
                        "error", "conflict", f"{where} but concludes differently: {says}",
                        rule_j.span, behavior,
                        hint="merge the two rules, or make their conditions differ"))
                elif ci.keys() == cj.keys():
                    extra = "" if rule_i.weight == rule_j.weight else \
                        f" (weights {rule_i.weight:g} and {rule_j.weight:g})"
                    out.append(Finding(
                        "warning", "duplicate",
                        f"{where} and the same consequents{extra}: {_twice(operators)}",
                        rule_j.span, behavior,
                        hint="delete one of them, or give one rule a weight (`with 0.5`)"))
                else:
                    continue
                break                         # report each rule against its first twin only
    return out


def _twice(operators: Operators) -> str:
    """What a rule written twice does to the outputs, under the behavior's inference."""
    if operators.accumulated:
        if operators.accumulation == "max":
            return "it changes nothing (max accumulation keeps the stronger of the two)"
        return f"its DOF is accumulated twice ({operators.accumulation})"
    if operators.inference != "mamdani":      # Tsukamoto's output is a weighted average too
        summed = operators.inference == "weighted_sum"
        return f"it counts twice in the weighted {'sum' if summed else 'average'}"
    if operators.aggregation == "max":
        return "it changes nothing (max aggregation keeps the stronger of the two)"
    if operators.aggregation == "sum":
        return "its set is added twice (aggregation = sum)"
    return f"its set is aggregated twice ({operators.aggregation})"


# ---------------------------------------------------------------------------------------------
# contradictory antecedents

def _literals(expr: Expr, negated: bool = False
             ) -> Iterator[tuple[str, str, tuple[str, ...], bool, Prop]]:
    """The propositions an `and` chain requires, as (var, term, hedges, negated)."""
    if isinstance(expr, Prop):
        yield (expr.var, expr.term, expr.hedges, expr.negated != negated, expr)
    elif isinstance(expr, Not) and isinstance(expr.expr, Prop):
        yield from _literals(expr.expr, not negated)
    elif isinstance(expr, And) and not negated:
        for item in expr.items:
            yield from _literals(item)


def _contradictions(rb: RuleBase, behavior: str) -> list[Finding]:
    out = []
    for label, rule, _ in flatten(rb, behavior):
        seen: dict[tuple[str, str, tuple[str, ...], bool], Prop] = {}
        for var, term, hedges, neg, prop in _literals(rule.antecedent):
            twin = seen.get((var, term, hedges, not neg))
            literal = replace(prop, negated=neg)
            twin = seen.get((var, term, hedges, not neg))
            if twin is not None:
                a, b = (twin, literal) if not twin.negated else (literal, twin)
                out.append(Finding(
                    "warning", "contradiction",
                    f"`{label}` asks for `{format_expr(a)}` and `{format_expr(b)}` at once: its "
                    f"DOF is min(mu, 1 - mu), at most 0.5, and 0 wherever `{var}` is fully "
                    f"{term} or not {term} at all", prop.span or rule.span, behavior,
                    hint="drop one of the two conditions"))
                break
            seen[(var, term, hedges, neg)] = literal
    return out


# ---------------------------------------------------------------------------------------------
# the sampled input space

def corner_points(compiled: CompiledRuleBase, i: int) -> np.ndarray:
    """Input ``i``'s universe ends and its terms' corner points inside the universe (a
    smooth term's centre; a formula has neither), sorted."""
    lo, hi = compiled.universe[i]
    pts = [lo, hi]
    for term in compiled.variables[compiled.inputs[i]].terms:    # a formula's centre is NaN
        points = term.corners if term.corners is not None else (term.center,)
        pts += [c for c in points if lo <= c <= hi]
    return np.unique(np.asarray(pts, float))


def _axis(compiled: CompiledRuleBase, i: int, n: int, between: bool) -> np.ndarray:
    """``n`` even steps of input ``i``'s universe and its corner points (``between``: and
    the midpoints of neighbouring corner points)."""
    lo, hi = compiled.universe[i]
    pts = [np.linspace(lo, hi, n), corner_points(compiled, i)]
    if between:
        pts.append(_midpoints(compiled, i))
    return np.unique(np.concatenate(pts))


def _midpoints(compiled: CompiledRuleBase, i: int) -> np.ndarray:
    corners = corner_points(compiled, i)
    return 0.5 * (corners[:-1] + corners[1:])


def _size(axes: list[np.ndarray]) -> float:
    return float(np.prod([len(a) for a in axes], dtype=float))


def fitted_axes(compiled: CompiledRuleBase, inputs: list[int], resolution: int,
                max_samples: int = MAX_SAMPLES, between: bool = False) -> list[np.ndarray]:
    """Sample points of ``inputs``: ``resolution`` even steps plus the corner points (and,
    ``between``, the midpoints between them), with ``resolution`` lowered until the grid has
    at most ``max_samples`` points, then the midpoints dropped, then (many inputs: even the
    corners are too many) the corners thinned evenly: :func:`skipped_corners` tells."""
    def axes_for(n: int, mid: bool) -> list[np.ndarray]:
        return [_axis(compiled, i, n, mid) for i in inputs]

    lo, hi = 2, max(2, resolution)
    if _size(axes_for(hi, between)) <= max_samples:
        return axes_for(hi, between)
    if between and _size(axes_for(2, True)) > max_samples:
        between = False                      # the midpoints go before the corners do
    while hi - lo > 1:                       # the largest resolution that fits
        mid = (lo + hi) // 2
        if _size(axes_for(mid, between)) <= max_samples:
            lo = mid
        else:
            hi = mid
    axes = axes_for(lo, between)
    if _size(axes) > max_samples:            # many inputs: even the corners are too many;
        per_axis = max(2, int(max_samples ** (1.0 / len(axes))))   # thin them evenly
        axes = [a if len(a) <= per_axis else
                a[np.unique(np.round(np.linspace(0, len(a) - 1, per_axis)).astype(int))]
                for a in axes]
    return axes


def grid_axes(compiled: CompiledRuleBase, resolution: int,
              max_samples: int = MAX_SAMPLES) -> list[np.ndarray]:
    """Sample points per input: ``resolution`` even steps plus the terms' corner points,
    with ``resolution`` lowered until the grid has at most ``max_samples`` points
    (:func:`fitted_axes` over every input)."""
    return fitted_axes(compiled, list(range(len(compiled.inputs))), resolution, max_samples)


def skipped_corners(compiled: CompiledRuleBase, inputs: list[int],
                    axes: list[np.ndarray]) -> tuple[str, ...]:
    """The inputs whose axis lost some of its corner points to :func:`fitted_axes`'s
    thinning: between the samples of those, a rule may fire or stop firing unseen."""
    return tuple(compiled.inputs[i] for i, a in zip(inputs, axes)
                 if not np.isin(corner_points(compiled, i), a).all())


def listed_names(names: tuple[str, ...] | list[str], most: int = 4) -> str:
    """``a, b, c and 10 more`` (backquoted)."""
    if not names:
        return "no input"
    shown = [f"`{n}`" for n in names[:most]]
    more = len(names) - len(shown)
    if more:
        return ", ".join(shown) + f" and {more} more"
    return shown[0] if len(shown) == 1 else ", ".join(shown[:-1]) + " and " + shown[-1]


#: Terms one ``unconcluded-term`` note names; more are counted.
SHOWN_TERMS = 10


def _first_names(names: list[str]) -> str:
    """``A, B, C`` or ``A, B, ... J and 19,990 more`` (the note named all 20,000 terms of a
    fuzzed FLL file on one line)."""
    more = len(names) - SHOWN_TERMS
    return ", ".join(names[:SHOWN_TERMS]) + (f" and {more:,} more" if more > 0 else "")


# ---------------------------------------------------------------------------------------------
# behaviors as they are used: compositions, judged with box algebra (regions.py)

#: Most boxes a behavior's in-use region may have (each sample of its grid is tested against
#: each: more and it is judged on its own, as before).
MAX_IN_USE_BOXES = 256


@dataclass(frozen=True)
class InUse:
    """Where a behavior that others ``use`` counts, output by output: the points of its own
    inputs where, for some values of the other inputs, some chain of ``use ... when`` from a
    behavior nothing uses (``users``) brings it in with a degree above 0 and no rule outside
    it in that composition sets the output. There a gap of its own is the composition's, and
    a low DOF of its own is at most the composition's; elsewhere it is not in use, or a
    sibling sets the output."""

    users: tuple[str, ...]
    space: regions.Space                     # the behavior's own inputs
    alone: dict[str, list[regions.Cube]]

    def mask(self, output: str, X: np.ndarray) -> np.ndarray:
        return self.space.contains(self.alone[output], X)

    @property
    def where(self) -> str:
        return f"where {listed_names(self.users)} {'uses' if len(self.users) == 1 else 'use'} it"


@dataclass(frozen=True)
class Exact:
    """Where no rule of a composition (a behavior that ``use``s others) sets each output,
    as disjoint cubes: exact, with no grid."""

    space: regions.Space
    gaps: dict[str, list[regions.Cube]]


@dataclass
class _Composed:
    compiled: CompiledRuleBase
    space: regions.Space
    chains: list[tuple]                      # each flattened rule's `use` chain
    fires: list[list[regions.Cube]]          # where each rule's DOF is above 0
    counting: np.ndarray


class _Compositions:
    """The behaviors of a rule base as the compositions a user evaluates: for each behavior
    nothing ``use``s (a top level), where each of its rules fires (exactly, on atoms:
    :mod:`.regions`). Anything :class:`.regions.NotExact` leaves the behavior judged on its
    own, on its grid, as a behavior nobody uses is."""

    def __init__(self, rb: RuleBase) -> None:
        self.rb = rb
        self.used_by: dict[str, set[str]] = {}
        for b in rb.behaviors:
            for u in b.uses:
                self.used_by.setdefault(u.behavior, set()).add(b.name)
        self.tops = [b.name for b in rb.behaviors if b.name not in self.used_by and b.uses]
        self._composed: dict[str, _Composed | None] = {}

    def _space(self, compiled: CompiledRuleBase) -> regions.Space:
        rb = self.rb
        return regions.Space([rb.variables[v] for v in compiled.inputs],
                             [corner_points(compiled, i) for i in range(len(compiled.inputs))],
                             compiled.operators.and_, compiled.operators.or_)

    def composed(self, top: str) -> _Composed | None:
        if top not in self._composed:
            try:
                compiled = compile_rulebase(self.rb, top)
                space = self._space(compiled)
                conditions: dict[int, list[regions.Cube]] = {}

                def where(expr: Expr | None) -> list[regions.Cube]:
                    if id(expr) not in conditions:
                        conditions[id(expr)] = space.fires(expr)
                    return conditions[id(expr)]

                chains, fires = [], []
                for _, rule, chain in flatten(self.rb, top):
                    chains.append(chain)
                    cubes = [] if rule.weight == 0 or any(u.weight == 0 for u in chain) \
                        else where(rule.antecedent)
                    for use in chain:
                        if cubes and use.condition is not None:
                            cubes = regions.intersect(cubes, where(use.condition))
                    fires.append(cubes)
                counting, _ = _counting(compiled)
                self._composed[top] = _Composed(compiled, space, chains, fires, counting)
            except regions.NotExact:
                self._composed[top] = None
        return self._composed[top]

    def exact(self, name: str, compiled: CompiledRuleBase) -> Exact | None:
        """A top level's gaps, per output; None for a behavior that uses none (judged on its
        grid, exactly as before) or where there is no exact answer."""
        if name not in self.tops:
            return None
        c = self.composed(name)
        if c is None:
            return None
        try:
            gaps = {}
            for j, output in enumerate(c.compiled.outputs):
                setting = [cube for r, cubes in enumerate(c.fires) if c.counting[r, j] > 0
                           for cube in cubes]
                gaps[output] = regions.subtract([c.space.full], regions.simplify(setting))
        except regions.NotExact:
            self._composed[name] = None        # too costly: the whole composition is sampled
            return None
        return Exact(c.space, gaps)

    def in_use(self, name: str, compiled: CompiledRuleBase) -> InUse | None:
        """Where a behavior that others use counts (:class:`InUse`); None for one nobody
        uses, or where there is no exact answer."""
        if name not in self.used_by:
            return None
        alone: dict[str, list[regions.Cube]] = {o: [] for o in compiled.outputs}
        users = []
        top = ""
        try:
            own = self._space(compiled)
            for top in self.tops:
                c = self.composed(top)
                if c is None:
                    return None
                inside = [next((k for k, u in enumerate(chain) if u.behavior == name), -1)
                          for chain in c.chains]
                if all(k < 0 for k in inside):
                    continue
                users.append(top)
                prefixes = {tuple(map(id, chain[:k + 1])): chain[:k + 1]
                            for chain, k in zip(c.chains, inside) if k >= 0}
                used: list[regions.Cube] = []
                for prefix in prefixes.values():
                    cubes = [] if any(u.weight == 0 for u in prefix) else [c.space.full]
                    for use in prefix:
                        if cubes and use.condition is not None:
                            cubes = regions.intersect(cubes, c.space.fires(use.condition))
                    used += cubes
                keep = [c.space.names.index(v) for v in compiled.inputs]
                for output in compiled.outputs:
                    j = c.compiled.outputs.index(output)
                    others = [cube for r, cubes in enumerate(c.fires)
                              if inside[r] < 0 and c.counting[r, j] > 0 for cube in cubes]
                    there = regions.subtract(regions.disjoint(regions.simplify(used)),
                                             regions.simplify(others))
                    alone[output] = regions.simplify(alone[output]
                                                     + regions.project(there, keep))
        except regions.NotExact:
            if top in self._composed:          # too costly: every behavior it reaches, and
                self._composed[top] = None     # it, are sampled (one budget spent, not many)
            return None
        if not users:                  # used only by behaviors that are themselves unused
            return None                # by any top level: judged on its own
        alone = {o: regions.merged(cubes) for o, cubes in alone.items()}
        if any(len(cubes) > MAX_IN_USE_BOXES for cubes in alone.values()):
            return None                # each grid sample is tested against each box
        return InUse(tuple(users), own, alone)


def _sampled(compiled: CompiledRuleBase, threshold: float, resolution: int,
             in_use: InUse | None = None,
             exact: Exact | None = None) -> tuple[list[Finding], GridInfo]:
    """The grid's findings: coverage and rules that never fire. ``in_use``: a behavior
    others use counts only where it is in use and alone (:class:`InUse`); ``exact``: a
    composition's gaps, decided with no grid (only its low DOF is sampled)."""
    every = list(range(len(compiled.inputs)))
    axes = grid_axes(compiled, resolution)
    shape = tuple(len(a) for a in axes)
    mesh = np.meshgrid(*axes, indexing="ij")
    X = np.stack([m.reshape(-1) for m in mesh], axis=1) if axes else np.zeros((1, 0))
    dof = rule_dofs(compiled, X)                       # [n, R]
    skipped = skipped_corners(compiled, every, axes)
    info = GridInfo(compiled.behavior, tuple(zip(compiled.inputs, shape)), X.shape[0],
                    skipped, _size([corner_points(compiled, i) for i in every]),
                    exact is not None)
    name = compiled.behavior
    span = _behavior_span(compiled.rulebase, name)
    out = _coverage(compiled, threshold, axes, X, dof, skipped, span, in_use, exact)

    # rules that never fire: only the behavior's own (a used behavior's rules are judged in
    # their own behavior, on its own, finer grid; here a `when` condition may silence them)
    fires = (dof > 0.0).any(axis=0) if dof.shape[0] else np.zeros(compiled.n_rules, bool)
    own = np.array([not contexts for _, _, contexts in flatten(compiled.rulebase, name)],
                   dtype=bool)
    out += _unreachable(compiled, np.flatnonzero(~fires & own), resolution)
    return out, info


def _coverage(compiled: CompiledRuleBase, threshold: float, axes: list[np.ndarray],
              X: np.ndarray, dof: np.ndarray, skipped: tuple[str, ...], span: Span | None,
              in_use: InUse | None, exact: Exact | None) -> list[Finding]:
    """The coverage findings of the grid ``X`` (``axes``; ``dof [n, R]`` its rules' DOFs),
    per output: where no rule fires (unless ``exact`` decided that with no grid) and where
    the total DOF is low. Outputs with the same gap are one finding
    (:func:`_gap_groups`)."""
    shape = tuple(len(a) for a in axes)
    thinned = (f" (on a grid that skipped corner points of {listed_names(skipped)}: there may "
               f"be more)" if skipped else "")
    out: list[Finding] = []
    counting, missed = _counting(compiled)
    total = dof @ counting                             # [n, m] total DOF per output
    if in_use is not None:                   # where it is not in use, or not alone: no say
        for j, o in enumerate(compiled.outputs):
            total[~in_use.mask(o, X), j] = np.inf
    centres = None                                     # the same at the cells' centres
    kinds: tuple[tuple[str, Callable[[np.ndarray], np.ndarray]], ...] = (
             ("no-rule-fires", lambda t: t <= 0.0),
             ("low-dof", lambda t: (t > 0.0) & (t < threshold)))
    if exact is not None:
        out += _exact_gaps(compiled, exact, span, missed)
        kinds = kinds[1:]
    for kind, mask_of in kinds:
        for mask, has_default, outs in _gap_groups(compiled, total, mask_of):
            inner = kind == "no-rule-fires" and not skipped
            cells = None
            if inner and all(len(a) > 1 for a in axes):
                if centres is None:
                    centres = _centre_totals(compiled, axes, counting, in_use)
                share = _unset_share(centres, axes, compiled.outputs.index(outs[0]))
                unset = centres[:, [compiled.outputs.index(o) for o in outs]] <= 0.0
                cells = unset.all(axis=1).reshape([len(a) - 1 for a in axes])
            else:
                share = volume_share(mask.reshape(shape), axes, inner=inner)
            boxes, uncovered = boxes_of(mask.reshape(shape), axes, compiled.inputs,
                                        cells=cells)
            severity, message, hint = _coverage_words(compiled, kind, outs, share,
                                                      has_default, threshold, thinned, in_use)
            if missed.intersection(outs):
                message += (" (counting only the rules whose sets its sampling does not miss: "
                            "undersampled-term)")
            out.append(Finding(severity, kind, message, span, compiled.behavior, hint,
                               tuple(boxes[:MAX_BOXES]), max(0, len(boxes) - MAX_BOXES), share,
                               uncovered))
    return out


def _gap_groups(compiled: CompiledRuleBase, total: np.ndarray,
                mask_of: Callable[[np.ndarray], np.ndarray]
                ) -> list[tuple[np.ndarray, bool, list[str]]]:
    """The outputs' gaps (``mask_of`` each output's column of ``total [n, m]``), outputs
    whose gaps are the same samples and alike in having a default grouped, so that one gap
    is said once: each group's mask, whether its outputs have a default, and their names."""
    reported: dict[tuple, list[str]] = {}
    masks = {}
    for j, out_name in enumerate(compiled.outputs):
        mask = mask_of(total[:, j])
        if not mask.any():
            continue
        # a declared `default: nan` is the rule base's own choice, as a number is
        has_default = not np.isnan(compiled.default[j]) or declares_nan(compiled, out_name)
        key = (mask.tobytes(), has_default)
        reported.setdefault(key, []).append(out_name)
        masks[key] = mask
    return [(masks[key], key[1], outs) for key, outs in reported.items()]


def _exact_gaps(compiled: CompiledRuleBase, exact: Exact, span: Span | None,
                missed: set[str]) -> list[Finding]:
    """A composition's ``no-rule-fires`` findings from its exact gaps (outputs with the same
    gap in one finding), in the words and boxes of the sampled ones."""
    groups: dict[tuple, list[str]] = {}
    for j, out_name in enumerate(compiled.outputs):
        gap = exact.gaps[out_name]
        if not gap:
            continue
        has_default = not np.isnan(compiled.default[j]) or declares_nan(compiled, out_name)
        groups.setdefault((tuple(sorted(gap)), has_default), []).append(out_name)
    out = []
    for (gap, has_default), outs in groups.items():
        share = exact.space.volume(gap)
        boxes = [Box(ranges, ends) for ranges, ends in exact.space.boxes(list(gap))]
        severity, message, hint = _coverage_words(compiled, "no-rule-fires", outs, share,
                                                  has_default, 0.0, "")
        if missed.intersection(outs):
            message += (" (counting only the rules whose sets its sampling does not miss: "
                        "undersampled-term)")
        out.append(Finding(severity, "no-rule-fires", message, span, compiled.behavior, hint,
                           tuple(boxes[:MAX_BOXES]), max(0, len(boxes) - MAX_BOXES), share))
    return out


def _counting(compiled: CompiledRuleBase) -> tuple[np.ndarray, set[str]]:
    """``[R, m]`` weights of the rules' DOFs in each output's coverage sum, and the outputs
    some of whose rules do not count: a Mamdani rule whose concluded set is 0 at every point
    its output is sampled at (narrower than a step, or outside the range) fires without
    giving the output anything, and where only such rules fire `mitos eval` finds no value."""
    from .mamdani import undersampled

    counting = compiled.cons_mask.astype(float)
    missed = set()
    for u in undersampled(compiled):
        if u.peak <= 0.0 or u.outside:
            counting[u.rules, compiled.outputs.index(u.output)] = 0.0
            missed.add(u.output)
    return counting, missed


def _coverage_words(compiled: CompiledRuleBase, kind: str, outs: list[str], share: float,
                    has_default: bool, threshold: float, thinned: str,
                    in_use: InUse | None = None) -> tuple[str, str, str]:
    """The severity, message and hint of a coverage finding (``no-rule-fires`` or
    ``low-dof``) of the outputs ``outs`` over ``share`` of the input space: no rule firing is
    an error only where the output has no default and is not a weighted sum (of nothing, 0;
    with a default, the default applies there, as under the other inferences). ``in_use``:
    said of a behavior others use, where it is in use and nothing else sets the outputs."""
    name = compiled.behavior
    what = " and ".join(f"`{o}`" for o in outs)
    who = f"behavior `{name}`"
    space = "the input space"
    if in_use is not None:
        who += f", {in_use.where} and no other behavior sets {what} there"
        space = "its input space"
    if kind != "no-rule-fires":
        return ("warning",
                f"{who}: the rules setting {what} fire with a total DOF below "
                f"{threshold:g} in {_pct(share)} of {space}{thinned}",
                "widen the terms or add rules, so that more than a trace of a rule fires")
    summed = compiled.operators.inference == "weighted_sum"
    where = (f"in {_pct(share)} of {space}" if share > 0 else
             f"on lines or points of {space} (none of its volume)")
    message = f"{who}: no rule sets {what} {where}{thinned}"
    if summed and not has_default:
        return ("warning", message + " (the weighted sum is 0 there)",
                "add rules that cover these inputs")
    if has_default:
        values = ", ".join(f"{o} = {compiled.default[compiled.outputs.index(o)]:g}" for o in outs)
        return ("warning", message + f" (the default applies there: {values})",
                "add rules that cover these inputs")
    return ("error", message, f"add rules that cover these inputs, or add `default: VALUE` to "
                              f"{what} in the term set to define the output when no rule fires")


#: Samples evaluated at once when a rule is looked at on a grid of its own inputs.
CHUNK = 20_000


def _unreachable(compiled: CompiledRuleBase, rules: np.ndarray,
                 resolution: int) -> list[Finding]:
    """Of ``rules`` (none fired on the behavior's grid, which may have had to skip corner
    points), those that fire nowhere. A rule's DOF reads only the inputs its conditions
    (and its `use` contexts' conditions) name, so it is looked at again on a grid of those
    alone, holding every corner point of their terms and the midpoint between each two:
    between neighbouring corner points a piecewise-linear term is linear, so wherever the
    rule fires it fires at one of those points (for T-norms without zero divisors: `min`,
    `product`, ...). Only when that grid too is too large is the finding hedged."""
    flat = flatten(compiled.rulebase, compiled.behavior)
    groups: dict[tuple[int, ...], list[int]] = {}
    for r in rules:
        _, rule, contexts = flat[r]
        used: set[tuple[str, str]] = set()
        for expr in (rule.antecedent,) + tuple(u.condition for u in contexts
                                               if u.condition is not None):
            _terms_used(expr, used)
        key = tuple(sorted({compiled.inputs.index(v) for v, _ in used}))
        groups.setdefault(key, []).append(int(r))
    out = []
    for inputs, members in groups.items():
        axes = fitted_axes(compiled, list(inputs), resolution, between=True)
        fires = _fires_on(compiled, np.array(members), list(inputs), axes)
        names = tuple(compiled.inputs[i] for i in inputs)
        skipped = skipped_corners(compiled, list(inputs), axes)
        exact = not skipped and all(np.isin(_midpoints(compiled, i), a).all()
                                    for i, a in zip(inputs, axes))
        samples = int(_size(axes))
        for r in np.array(members)[~fires]:
            rule = compiled.rules[r]
            why = " (its weight is 0)" if rule.weight == 0 else ""
            label = compiled.labels[r]
            if exact or rule.weight == 0:
                out.append(Finding(
                    "warning", "unreachable",
                    f"`{label}` never fires: its DOF is 0 at all {samples:,} sampled values of "
                    f"{listed_names(names)}, every corner point of {'their' if len(names) > 1 else 'its'} "
                    f"terms and between them"
                    f"{why}", rule.span, compiled.behavior,
                    hint="its conditions cannot hold together; check the terms it names"))
                continue
            gap = (f"corner points of {listed_names(skipped)}" if skipped else
                   "the points between corner points")
            out.append(Finding(
                "info", "unreachable",
                f"`{label}` fired at none of {samples:,} sampled inputs of {listed_names(names)}, "
                f"a grid that skipped {gap}: it may fire between them", rule.span,
                compiled.behavior, hint="check that its conditions can hold together"))
    return out


def _fires_on(compiled: CompiledRuleBase, rules: np.ndarray, inputs: list[int],
              axes: list[np.ndarray]) -> np.ndarray:
    """Which of ``rules`` have a DOF above 0 somewhere on the grid ``axes`` of ``inputs``
    (every other input at its universe's low end: those rules do not read it), a
    :data:`CHUNK` of samples at a time."""
    shape = tuple(len(a) for a in axes)
    total = int(np.prod(shape))
    fires = np.zeros(len(rules), bool)
    for start in range(0, total, CHUNK):
        at = np.unravel_index(np.arange(start, min(start + CHUNK, total)), shape)
        X = np.repeat(compiled.universe[None, :, 0], len(at[0]), axis=0)
        for d, i in enumerate(inputs):
            X[:, i] = axes[d][at[d]]
        fires |= (rule_dofs(compiled, X)[:, rules] > 0.0).any(axis=0)
        if fires.all():
            break
    return fires


def _centre_totals(compiled: CompiledRuleBase, axes: list[np.ndarray],
                   counting: np.ndarray, in_use: InUse | None = None) -> np.ndarray:
    """``[cells, m]`` total DOF per output at the centre of each cell between neighbouring
    samples (every axis has two or more); +inf where ``in_use`` says it has no say."""
    mesh = np.meshgrid(*(0.5 * (a[:-1] + a[1:]) for a in axes), indexing="ij")
    X = np.stack([m.reshape(-1) for m in mesh], axis=1) if axes else np.zeros((1, 0))
    total = rule_dofs(compiled, X) @ counting
    if in_use is not None:
        for j, o in enumerate(compiled.outputs):
            total[~in_use.mask(o, X), j] = np.inf
    return total


def _unset_share(centres: np.ndarray, axes: list[np.ndarray], j: int) -> float:
    """The share of the input space's volume where no rule sets output ``j``: the cells
    whose centre it is unset at. On a grid that holds the terms' corner points a membership
    is linear on each open cell, so a DOF of min or product that is 0 at the centre is 0 all
    over the cell, and one above 0 there is 0 at most on its boundary: exact, also where a
    term is 0 on the cell and above 0 at its ends (a vertical edge, a zero-width term),
    which a count of the cells unset at every vertex took for set."""
    m = (centres[:, j] <= 0.0).astype(float).reshape([len(a) - 1 for a in axes])
    for a in axes:                           # contract each axis with its cells' widths
        m = np.tensordot(np.diff(a) / (a[-1] - a[0]), m, axes=(0, 0))
    return float(m)


def volume_share(mask: np.ndarray, axes: list[np.ndarray], inner: bool) -> float:
    """The share of the input space's volume that the grid ``mask`` stands for (not of its
    samples: the corner points crowd some stretches). Each cell between neighbouring samples
    counts its volume times the share of its vertices in the mask, or (``inner``) only when
    all are (:func:`_unset_share`, which judges a cell at its centre, is exact where this
    is not: beside a vertical edge or a zero-width term)."""
    if any(len(a) < 2 for a in axes):
        return float(mask.mean())
    m = mask.astype(float)
    for d in range(mask.ndim):
        lo = np.take(m, np.arange(len(axes[d]) - 1), axis=d)
        hi = np.take(m, np.arange(1, len(axes[d])), axis=d)
        m = np.minimum(lo, hi) if inner else 0.5 * (lo + hi)
    for a in axes:                           # contract each axis with its cells' widths
        m = np.tensordot(np.diff(a) / (a[-1] - a[0]), m, axes=(0, 0))
    return float(m)


def _pct(share: float) -> str:
    pct = 100.0 * share
    return f"{pct:.2g}%" if pct < 10 else f"{pct:.0f}%"


def _steps(cells: np.ndarray, lo: list, hi: list) -> list[tuple[bool, bool]]:
    """For a box of samples ``lo``..``hi - 1``, which ends run on to the next sample, left
    out: where every cell just beyond the end (along the box's own cells) is unset at its
    centre. On a grid that holds the corner points a membership is linear on each open cell,
    so the region then fills the cell and stops at the next sample, a crisp step: a box read
    from the samples alone stopped one sample short (``x in [0, 1.75]`` for ``[0, 2)``)."""
    ends = []
    for d in range(cells.ndim):
        across = [slice(a, b - 1) for a, b in zip(lo, hi)]      # the box's cells elsewhere
        if any(b - a < 2 for e, (a, b) in enumerate(zip(lo, hi)) if e != d):
            ends.append((False, False))       # a box one sample thin has no cells to judge
            continue
        sides = []
        for beyond in (lo[d] - 1, hi[d] - 1):     # the cells below and above the box
            face = list(across)
            face[d] = slice(beyond, beyond + 1)
            sides.append(bool(0 <= beyond < cells.shape[d] and cells[tuple(face)].all()))
        ends.append((sides[0], sides[1]))
    return ends


def boxes_of(mask: np.ndarray, axes: list[np.ndarray], names: tuple[str, ...],
             limit: int = 200, cells: np.ndarray | None = None) -> tuple[list[Box], int]:
    """Cover the true cells of a k-dimensional grid mask with boxes, largest first.

    Each box starts at the first uncovered true cell and grows along every axis in turn (up,
    then down) while the grown box stays inside the mask; boxes may overlap. Ranges spanning a
    whole axis are left out. Returns the boxes (at most ``limit``) and the number of true cells
    they leave uncovered (0 unless the mask is too ragged for ``limit`` boxes). ``cells``: which
    cells between samples are in the region at their centre (:func:`_unset_share`'s), to run
    an end on to a crisp step beyond the last sample (:func:`_steps`).
    """
    remaining = mask.copy()
    boxes: list[tuple[int, Box]] = []
    while remaining.any() and len(boxes) < limit:
        start = np.unravel_index(int(np.argmax(remaining)), mask.shape)
        lo = list(start)
        hi = [s + 1 for s in start]
        for d in range(mask.ndim):
            for step in (1, -1):
                while True:
                    if step == 1 and hi[d] >= mask.shape[d]:
                        break
                    if step == -1 and lo[d] <= 0:
                        break
                    sl = [slice(a, b) for a, b in zip(lo, hi)]
                    sl[d] = slice(hi[d], hi[d] + 1) if step == 1 else slice(lo[d] - 1, lo[d])
                    if not mask[tuple(sl)].all():
                        break
                    if step == 1:
                        hi[d] += 1
                    else:
                        lo[d] -= 1
        region = tuple(slice(a, b) for a, b in zip(lo, hi))
        remaining[region] = False
        ends = _steps(cells, lo, hi) if cells is not None else [(False, False)] * mask.ndim
        kept = [d for d in range(mask.ndim) if not (lo[d] == 0 and hi[d] == mask.shape[d])]
        ranges = tuple((names[d], float(axes[d][lo[d] - ends[d][0]]),
                        float(axes[d][hi[d] - 1 + ends[d][1]])) for d in kept)
        size = int(np.prod([b - a for a, b in zip(lo, hi)]))
        boxes.append((size, Box(ranges, tuple(ends[d] for d in kept) if cells is not None
                                else ())))
    boxes.sort(key=lambda sb: -sb[0])
    return [b for _, b in boxes], int(remaining.sum())


# ---------------------------------------------------------------------------------------------
# term sets

def _variables(rb: RuleBase, scope: set[str] | None) -> list[Variable]:
    """The file's variables, or those in ``scope`` (the ones a named behavior uses)."""
    return [v for v in rb.variables.values() if scope is None or v.name in scope]


def _term_gaps(rb: RuleBase, scope: set[str] | None = None) -> list[Finding]:
    out = []
    for var in _variables(rb, scope):
        if var.role != "input" or not var.terms:
            continue
        lo, hi = var.universe
        x = meaning.gap_points(var)
        top, envelope = _tops(var.terms, x)
        middle = _tops(var.terms, meaning.cell_middles(x))[1] if len(x) > 1 else None
        for term, most in zip(var.terms, top):
            if most < NEARLY_ONE:
                out.append(Finding(
                    "warning", "term-outside",
                    f"input term `{var.name}.{term.name}` never reaches 1 inside the universe "
                    f"[{_num(lo)}, {_num(hi)}] (at most {most:.3g})", term.span, None,
                    hint="move the term's peak into the universe, or widen the universe"))
        for gap in meaning.gaps_on(envelope, x, middle):
            out.append(Finding("warning", "term-gap", meaning.gap_message(var, gap),
                               var.span, None, hint=meaning.GAP_HINT))
    return out


def _tops(terms: Sequence[Term], x: np.ndarray) -> tuple[list[float], np.ndarray]:
    """Each term's largest membership on the points ``x``, and the largest of any term at
    each point: a few terms' memberships at a time (all at once, 10,000 terms on their 40,000
    corners were 3.2 GB)."""
    top: list[float] = []
    envelope = np.zeros(len(x))
    step = max(1, BLOCK_CELLS // max(1, len(x)))
    for i in range(0, len(terms), step):
        mus = np.array([t.membership(x) for t in terms[i:i + step]])
        top += mus.max(axis=1).tolist()
        np.maximum(envelope, mus.max(axis=0), out=envelope)
    return top, envelope


def _interpretability(rb: RuleBase, scope: set[str] | None = None) -> list[Finding]:
    from ..lang.interpretability import variable_issues

    out = []
    for var in _variables(rb, scope):
        for issue in variable_issues(var):
            span = var.term(issue.terms[0]).span if issue.terms else var.span
            out.append(Finding("warning", issue.code, issue.message, span, None,
                               hint=issue.hint))
    return out


def _terms_used(expr: Expr, out: set[tuple[str, str]]) -> None:
    if isinstance(expr, Prop):
        out.add((expr.var, expr.term))
    elif isinstance(expr, Not):
        _terms_used(expr.expr, out)
    else:
        for item in expr.items:
            _terms_used(item, out)


def _unused_input_term(var: Variable, k: int, x: np.ndarray,
                       top: tuple[np.ndarray, np.ndarray, np.ndarray]) -> Finding:
    """An input term no rule reads: a warning, or a note where the term set needs it to
    cover its universe (no other term reaches 0.5 where it does: removed, it would leave a
    `coverage` finding, or a `term-gap`), as `nearest.ROOMY` beside `nearest.TIGHT`.
    ``top``: the largest membership of any term at each point of ``x``, whose it is, and the
    second largest (:func:`_top_two`). ``k``: the term's index in ``var.terms``."""
    term = var.terms[k]
    first, which, second = top
    alone = which[(first >= 0.5) & (second < 0.5)]     # where one term alone reaches 0.5
    needed = np.zeros(len(x), bool)
    if (alone == k).any():              # the only terms that can be needed: one membership
        mine = term.membership(x)
        best = np.where(which == k, second, first)          # the other terms' largest
        needed = (mine >= 0.5) & (best < 0.5)
    if not needed.any():
        return Finding("warning", "unused-term",
                       f"input term `{var.name}.{term.name}` is used by no rule", term.span,
                       None, hint="write a rule for it, or remove it from the term set")
    stretch = " and ".join(_stretches(var.name, x, np.minimum(mine - 0.5, 0.5 - best), needed))
    # its complement, if it has one, is the term that is largest where it is least
    other = var.terms[int(top[1][int(np.argmin(mine))])]
    hint = "keep it for the term set's coverage"
    if other is not term and np.allclose(1.0 - other.membership(x), mine, rtol=0.0, atol=1e-12):
        hint += (f"; `{var.name} is {term.name}` has the degree of `{var.name} is not "
                 f"{other.name}`, which a rule may say instead")
    return Finding("info", "unused-term",
                   f"input term `{var.name}.{term.name}` is used by no rule, but no other term "
                   f"of `{var.name}` reaches 0.5 for {stretch}: it covers the universe there",
                   term.span, None, hint=hint)


def _top_two(terms: Sequence[Term], x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """At each point of ``x``: the largest membership of ``terms``, the index of the term
    that has it, and the second largest; a few terms at a time (as :func:`_tops`)."""
    first = np.full(len(x), -np.inf)
    which = np.zeros(len(x), np.intp)
    second = np.full(len(x), -np.inf)
    step = max(1, BLOCK_CELLS // max(1, len(x)))
    for i in range(0, len(terms), step):
        mus = np.array([t.membership(x) for t in terms[i:i + step]])
        for row, mu in enumerate(mus):          # a block of a few terms
            higher = mu > first
            second = np.where(higher, first, np.maximum(second, mu))
            which = np.where(higher, i + row, which)
            first = np.where(higher, mu, first)
    return first, which, second


def _stretches(name: str, x: np.ndarray, g: np.ndarray, inside: np.ndarray) -> list[str]:
    """The runs of ``inside`` (the samples ``x`` where ``g`` is in the region) as ranges,
    each end that lies between samples placed where ``g`` crosses 0 on a line between them
    (exact for piecewise-linear terms, whose corners are among the samples) and left out."""
    out = []
    edges = np.flatnonzero(np.diff(np.concatenate([[False], inside, [False]]).astype(int)))
    for start, stop in zip(edges[0::2], edges[1::2]):
        lo, hi, open_lo, open_hi = x[start], x[stop - 1], False, False
        if start > 0 and g[start] != g[start - 1]:
            t = -g[start - 1] / (g[start] - g[start - 1])
            lo, open_lo = x[start - 1] + t * (x[start] - x[start - 1]), True
        if stop < len(x) and g[stop] != g[stop - 1]:
            t = g[stop - 1] / (g[stop - 1] - g[stop])
            hi, open_hi = x[stop - 1] + t * (x[stop] - x[stop - 1]), True
        out.append(f"{name} = {_num(lo)}" if lo == hi else
                   f"{name} in {'(' if open_lo else '['}{_num(lo)}, {_num(hi)}"
                   f"{')' if open_hi else ']'}")
    return out


def _unused_terms(rb: RuleBase, scope: set[str] | None = None) -> list[Finding]:
    used: set[tuple[str, str]] = set()
    concluded: set[tuple[str, str]] = set()
    for b in rb.behaviors:                  # a term used anywhere in the file is used
        for rule in b.rules:
            _terms_used(rule.antecedent, used)
            for c in rule.consequents:
                if c.term is not None:
                    concluded.add((c.var, c.term))
        for use in b.uses:
            if use.condition is not None:
                _terms_used(use.condition, used)
    set_by_rules = {c.var for b in rb.behaviors for r in b.rules for c in r.consequents}
    out = []
    for var in _variables(rb, scope):
        if var.role == "input":
            unused = [k for k, t in enumerate(var.terms) if (var.name, t.name) not in used]
            if len(unused) == len(var.terms):
                out.append(Finding("warning", "unused-term",
                                   f"input `{var.name}` is used by no rule", var.span, None,
                                   hint="write rules that use it, or remove it"))
                continue
            if unused:
                x = meaning.gap_points(var)
                top = _top_two(var.terms, x)
                out += [_unused_input_term(var, k, x, top) for k in unused]
        else:
            unconcluded = [t.name for t in var.terms if (var.name, t.name) not in concluded]
            if unconcluded and var.name in set_by_rules:
                out.append(Finding("info", "unconcluded-term",
                                   f"output `{var.name}`: no rule concludes "
                                   + _first_names(unconcluded), var.span, None))
            elif var.name not in set_by_rules:
                out.append(Finding("warning", "unused-term",
                                   f"output `{var.name}` is set by no rule", var.span, None,
                                   hint="write rules that set it, or remove it"))
    return out
