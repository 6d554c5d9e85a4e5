"""Compiling a behavior of a rule base into the arrays of a layered fuzzy-neuron network.

The network has the layers the paper describes (Sec. 3):

1. **membership layer**: one neuron per input term (eq. 15 and the other shapes);
2. **literal layer**: hedges as activations (eqs. 10-11) and ``not`` as inhibitory input
   (eqs. 8-9), only where a rule uses them;
3. **AND / OR / NOT layers**: one T-norm (AND) or S-norm (OR) neuron per sub-expression and
   per rule, computed level by level;
4. **output layer**: DOFs times rule weights and ``use`` contexts, combined into the outputs.

Every value lives in one column of a matrix ``V[n, columns]``; column 0 holds 0 and column 1
holds 1 (the identities that pad n-ary neurons). The engine (:mod:`mitos_cli.engine`) walks
the levels with one NumPy call per level and operator: never a Python loop over rules or
samples.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..fuzzy.formula import Formula
from ..fuzzy.shapes import kernel_params
from ..lang import operators as ops_mod
from ..lang.model import And, Expr, Not, Prop, Rule, RuleBase, Setting, Use, flatten, format_rule
from ..lang.operators import Operators
from ..lang.terms import Term, Variable

if TYPE_CHECKING:
    from collections.abc import Mapping

    from ..lang.model import Consequent
    from .mamdani import OutputTable
    from .scalar import ScalarFn
    from .tsukamoto import TermRules

    #: a behavior's rules as :func:`~mitos_cli.lang.model.flatten` gives them
    Flat = list[tuple[str, Rule, tuple[Use, ...]]]


ZERO, ONE = 0, 1


@dataclass(frozen=True, eq=False)   # holds arrays: identity, not ==
class NodeGroup:
    """Neurons of one level that share an operator: ``V[:, out] = op(V[:, children])``."""

    op: str                       # "and", "or", "not" or "hedge:<names>"
    out: np.ndarray               # [m] output columns
    children: np.ndarray          # [m, arity] input columns, padded with the identity column


@dataclass(frozen=True, eq=False)
class ShapeGroup:
    """Input terms of a non-linear shape, evaluated together."""

    shape: str
    cols: np.ndarray              # [g] columns in V (2 + term index)
    inputs: np.ndarray            # [g] input column of each
    params: np.ndarray            # [g, p]
    formula: Formula | None = None   # the one term of a ``formula`` group


@dataclass(frozen=True, eq=False)
class CompiledRuleBase:
    """A behavior as arrays. Rows of every batch are samples; columns are variables."""

    rulebase: RuleBase
    behavior: str
    operators: Operators
    inputs: tuple[str, ...]                 # input variables, in column order
    universe: np.ndarray                    # [k, 2]
    term_var: np.ndarray                    # [T] input column of each membership neuron
    term_names: tuple[tuple[str, str], ...]  # [T] (variable, term)
    linear: np.ndarray                      # [T] bool: piecewise-linear term
    kernel: np.ndarray                      # [4, T] (b, s1, c, s2) of linear terms
    shape_groups: tuple[ShapeGroup, ...]
    levels: tuple[tuple[NodeGroup, ...], ...]
    n_columns: int
    rule_col: np.ndarray                    # [R] column holding each rule's antecedent
    weight: np.ndarray                      # [R] rule weight x constant use weights
    context: np.ndarray                     # [R, C] columns of use-conditions (1 = none)
    labels: tuple[str, ...]
    rules: tuple[Rule, ...]
    outputs: tuple[str, ...]
    cons_value: np.ndarray                  # [R, m] crisp consequent (0 where unset)
    cons_mask: np.ndarray                   # [R, m] bool: the rule sets this output
    cons_term: tuple[tuple[str | None, ...], ...]  # [R][m] output term named, if any
    cons_hedges: tuple[tuple[tuple[str, ...], ...], ...]
    default: np.ndarray                     # [m] value when no rule fires (nan = none)
    variables: dict = field(repr=False, default_factory=dict)
    #: [R, m, k + 1] Takagi-Sugeno consequents ``y = a . x + c`` (coefficients over
    #: :attr:`inputs`, then the constant), only when some rule has a ``linear`` consequent;
    #: constant consequents are rows with a = 0, unset outputs are all 0.
    cons_linear: np.ndarray | None = None

    def __repr__(self) -> str:   # the generated one prints every array (125,000 characters)
        return (f"<CompiledRuleBase {self.behavior!r}: {len(self.inputs)} inputs "
                f"({', '.join(self.inputs)}), {len(self.outputs)} outputs "
                f"({', '.join(self.outputs)}), {self.n_rules} rules, {self.n_terms} terms, "
                f"{len(self.levels)} levels, {self.n_columns} neurons; {self.describe_operators()}>")

    def describe_operators(self) -> str:
        """:meth:`Operators.describe` with the Mamdani outputs' own resolutions."""
        own = self.own_resolutions
        return self.operators.describe(own, every=len(own) == len(self.outputs))

    @property
    def own_resolutions(self) -> dict[str, int]:
        """The Mamdani outputs sampled at a resolution of their own (not the behavior's)."""
        if self.operators.inference != "mamdani":
            return {}
        own = ((n, self.variables[n].resolution) for n in self.outputs if n in self.variables)
        return {n: r for n, r in own if r is not None and r != self.operators.resolution}

    @property
    def kernel_columns(self) -> np.ndarray:
        """The kernel as ``[4, T, 1]`` columns, to broadcast against ``[T, b]`` blocks."""
        return self.kernel[:, :, None]

    @property
    def weighted(self) -> bool:
        return bool((self.weight != 1.0).any())

    @property
    def sum_weights(self) -> np.ndarray:
        """``[k, R]`` weights of the output layer's sums: one numerator per output, then one
        denominator per distinct set of rules that set an output."""
        return self._sums[0]

    @property
    def den_row(self) -> np.ndarray:
        """Row of :attr:`sum_weights` holding each output's denominator."""
        return self._sums[1]

    @functools.cached_property
    def _sums(self) -> tuple[np.ndarray, np.ndarray]:
        masks = [tuple(self.cons_mask[:, j]) for j in range(len(self.outputs))]
        distinct = list(dict.fromkeys(masks))
        K = np.vstack([self.cons_value.T] + [np.array(d, dtype=float)[None] for d in distinct])
        rows = np.array([len(self.outputs) + distinct.index(m) for m in masks], dtype=np.intp)
        # (an explicit row count: with no rules, ``reshape(-1, 0)`` cannot infer it)
        return K.reshape(len(self.outputs) + len(distinct), self.n_rules), rows

    @functools.cached_property
    def summed_defaults(self) -> tuple[int, ...]:
        """Outputs of ``weighted_sum`` inference that declare a ``default`` (a number, or
        fuzzylite's ``nan``): where none of their rules fires the default applies, as it
        does under the other inferences (and in fuzzylite and MATLAB), not the empty sum's
        0. An output without one keeps 0 there."""
        if self.operators.inference != "weighted_sum":
            return ()
        return tuple(j for j, name in enumerate(self.outputs)
                     if not np.isnan(self.default[j])
                     or ((v := self.variables.get(name)) is not None and v.default is not None))

    @functools.cached_property
    def hedged_outputs(self) -> tuple[int, ...]:
        """Outputs of weighted inference with a hedged consequent (each hedges its rule's
        weight, :func:`mitos_cli.engine.evaluation.weighted_average`); none under Mamdani,
        where a hedge reshapes the consequent set."""
        if self.operators.inference not in ("weighted_average", "weighted_sum"):
            return ()
        return tuple(j for j in range(len(self.outputs))
                     if any(row[j] for row in self.cons_hedges))

    @functools.cached_property
    def accumulated(self) -> tuple[Accumulation, ...] | None:
        """Per output, its rules grouped by the value they conclude, which the behavior's
        ``accumulation`` S-norm joins before the average; None under the default ``sum``."""
        if not self.operators.accumulated:
            return None
        return tuple(_accumulation(self, j) for j in range(len(self.outputs)))

    @property
    def joins(self) -> bool:
        """Whether an ``accumulation`` S-norm may join two rules anywhere: two of one value,
        or (at some inputs) two values of which one is linear; else it changes nothing
        (``S(0, d) = d``)."""
        return self.accumulated is not None and any(
            a.steps or (self.cons_linear is not None and len(a.first) > 1)
            for a in self.accumulated)

    @property
    def n_rules(self) -> int:
        return len(self.labels)

    @property
    def n_terms(self) -> int:
        return len(self.term_names)

    def input_variable(self, name: str) -> Variable:
        return self.variables[name]

    def output_variable(self, name: str) -> Variable:
        return self.variables[name]

    def rule_text(self, r: int) -> str:
        return format_rule(self.rules[r], label=False)

    @functools.cached_property
    def plan(self) -> Plan:
        """Everything the engine's hot path needs, precomputed once."""
        return _plan(self)

    @functools.cached_property
    def grid_batch(self) -> GridBatch | None:
        """The constants of the batch path of a behavior whose rules are one grid, or None
        (:class:`GridBatch`; made on the first batch, so one evaluation never pays for it)."""
        plan = self.plan
        return _grid_batch(self, plan.grids, plan.rules, plan.weight, plan.sum_rows)

    @functools.cached_property
    def scalar(self) -> ScalarFn | None:
        """The network as a Python function of one sample's floats (``None`` when it has no
        exact scalar form): see :mod:`mitos_cli.engine.scalar`. Written on first use."""
        from .scalar import scalar_function

        return scalar_function(self)

    def __getstate__(self) -> dict:
        """Pickled (for worker processes) without the scalar function, which is generated
        code; a process that needs it writes it again. (The Mamdani tables stay: adaptation
        puts tables there that the terms alone do not give.)"""
        return {k: v for k, v in self.__dict__.items() if k != "scalar"}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)

    @functools.cached_property
    def tsukamoto(self) -> tuple[tuple[TermRules, ...], ...]:
        """Per output, its terms and the rules concluding each, for Tsukamoto inference."""
        from .tsukamoto import build_plan

        return build_plan(self)

    @functools.cached_property
    def mamdani(self) -> tuple[OutputTable, ...]:
        """Sampled output terms for Mamdani inference (built once per compiled rule base)."""
        from .mamdani import build_tables

        return build_tables(self)


@dataclass(frozen=True, eq=False)
class Accumulation:
    """One output's rules grouped by the value they conclude (a crisp value, or one linear
    function: jFuzzyLogic keys its singletons by value), groups in the order of their first
    rule. The S-norm folds each group left to right in rule order, one step per depth: at step
    ``k`` the groups ``steps[k][0]`` take in their ``k``-th rule ``steps[k][1]``."""

    first: np.ndarray                              # [G] the first rule of each group
    steps: tuple[tuple[np.ndarray, np.ndarray], ...]   # depth 1, 2, ...: (groups, rules)


def _accumulation(c: CompiledRuleBase, j: int) -> Accumulation:
    """Output ``j``'s :class:`Accumulation`: a linear consequent's key is its coefficients
    and constant, a crisp one's its value (a linear one of zero coefficients is that value)."""
    groups: dict[tuple[float, ...], list[int]] = {}
    for r in np.flatnonzero(c.cons_mask[:, j]):
        value = float(c.cons_value[r, j])
        key: tuple[float, ...] = (value, math.copysign(1.0, value))   # 0.0 and -0.0: two
        if c.cons_linear is not None:
            row = tuple(c.cons_linear[r, j].tolist())
            key = row if any(row[:-1]) else (row[-1], math.copysign(1.0, row[-1]))
        groups.setdefault(key, []).append(int(r))
    members = list(groups.values())
    depth = max((len(g) for g in members), default=0)
    steps = tuple((np.array([g for g, m in enumerate(members) if len(m) > k], dtype=np.intp),
                   np.array([m[k] for m in members if len(m) > k], dtype=np.intp))
                  for k in range(1, depth))
    return Accumulation(np.array([m[0] for m in members], dtype=np.intp), steps)


@dataclass(frozen=True, eq=False)
class Plan:
    """Precomputed arrays and flags for :mod:`mitos_cli.engine` (derived, never edited)."""

    n_terms: int
    n_rules: int
    lo: np.ndarray                     # [k] universe minima
    hi: np.ndarray                     # [k] universe maxima
    lo_col: np.ndarray                 # [k, 1] the same as columns
    hi_col: np.ndarray
    all_linear: bool
    linear_rows: np.ndarray            # [L] terms evaluated by the linear kernel
    term_var: np.ndarray               # [L] their input column
    input_rows: tuple[tuple[int, int], ...]   # [k] each input's run of term rows
    kernel: tuple[np.ndarray, ...]     # (b, s1, c, s2), each [L, 1], contiguous
    plateaus: bool                     # some linear term is 1 between a rise and a fall
    bounds: tuple[list[float], list[float]]   # lo, hi as Python floats (for one sample)
    rules: slice | np.ndarray          # where the rules' antecedents live in V
    contexts: tuple[np.ndarray, ...]   # columns multiplying each rule's DOF (use nesting)
    weight: np.ndarray | None          # [R, 1] rule weights, None when all are 1
    sums: np.ndarray                   # [R, k, 1] output-layer weights (numerators, dens)
    den_row: np.ndarray                # [m] row of ``sums`` with each output's denominator
    sum_rows: tuple                    # per row of ``sums``: its weights [R, 1], None if all 1
    grids: dict                        # (level, group) -> Grid, for AND groups that are grids


@dataclass(frozen=True, eq=False)
class Grid:
    """An AND group whose neurons are every combination of some variables' terms, in
    mixed-radix order (the paper's 27 rules): computed by broadcasting ``min`` over one
    membership vector per variable instead of gathering each neuron's inputs."""

    axes: tuple[np.ndarray, ...]       # membership columns per variable, outermost first
    out: slice                         # the group's output columns (contiguous)
    shape: tuple[int, ...]


def _grid(group: NodeGroup, c: CompiledRuleBase) -> Grid | None:
    """The group as a :class:`Grid`, or ``None`` when it is not one."""
    T = c.n_terms
    ch = group.children
    if group.op != "and" or not ((ch >= 2) & (ch < 2 + T)).all():
        return None
    out = group.out
    if not (np.diff(out) == 1).all():
        return None
    var_of = c.term_var[ch - 2]                            # [g, arity]
    if (np.sort(var_of, axis=1) != np.sort(var_of[:1], axis=1)).any():
        return None
    if len(set(var_of[0].tolist())) != ch.shape[1]:
        return None
    per_var = {int(v): ch[np.arange(len(ch)), np.argmax(var_of == v, axis=1)]
               for v in var_of[0]}                          # var -> [g] its column per neuron
    changes = {v: int((np.diff(cols) != 0).sum()) for v, cols in per_var.items()}
    order = sorted(per_var, key=lambda v: changes[v])      # outermost changes least
    axes = [np.array(list(dict.fromkeys(per_var[v].tolist())), dtype=np.intp) for v in order]
    shape = tuple(len(a) for a in axes)
    if int(np.prod(shape)) != len(out):
        return None
    index = np.zeros(len(out), dtype=np.intp)
    for v, a in zip(order, axes):
        pos = {int(col): i for i, col in enumerate(a)}
        index = index * len(a) + np.array([pos[int(col)] for col in per_var[v]])
    if not (index == np.arange(len(out))).all():
        return None
    return Grid(tuple(axes), slice(int(out[0]), int(out[-1]) + 1), shape)


@dataclass(frozen=True, eq=False)
class GridBatch:
    """The constants of the batch path for a behavior whose rules are exactly one
    :class:`Grid` (every combination of its inputs' terms, the paper's 27 rules) with
    piecewise-linear terms, crisp consequents and weighted inference
    (:func:`mitos_cli.engine.evaluation.evaluate_columns`).

    That path computes only the grid's memberships and DOFs, with the engine's operations in
    its order, in a few NumPy calls per block over preallocated buffers: each input's terms
    are one row of ``[k, t]`` (padded to the longest input's ``t`` with a copy of its first
    term, whose row is never read), in the order the grid's axis lists them.
    """

    B: np.ndarray                      # [k, t, 1] kernel b of each input's terms
    C: np.ndarray                      # [k, t, 1] kernel c
    S: np.ndarray                      # [2, k * t, 1] the slopes s1 (rise) and s2 (fall)
    axes: tuple[tuple[int, int], ...]  # (input, terms) of each grid axis, outermost first
    shape: tuple[int, ...]             # the grid's shape (its rules in mixed-radix order)
    plateaus: bool                     # clip at 1 (some term is 1 between a rise and a fall)
    overflow: bool                     # a slope times a distance may pass 1e308
    weight: np.ndarray | None          # [R, 1] rule weights, None when all are 1
    Kw: np.ndarray                     # [R, w, 1] weights of the sums that have some (not 1)
    ones: int                          # 1: the last sum's weights are all 1 (a denominator)
    num: tuple[int, ...]               # [m] each output's numerator among the sums ...
    den: tuple[int, ...]               # [m] ... and its denominator (weighted rows, then ones)
    weighted_sum: bool                 # inference = weighted_sum: no division


def _grid_batch(c: CompiledRuleBase, grids: dict[tuple[int, int], Grid], rules: slice | np.ndarray,
                weight: np.ndarray | None,
                sum_rows: tuple[np.ndarray | None, ...]) -> GridBatch | None:
    """The :class:`GridBatch` of ``c``, or None when its rules are not exactly one grid."""
    if (c.operators.inference not in ("weighted_average", "weighted_sum")
            or c.operators.accumulated or c.cons_linear is not None or c.hedged_outputs or c.shape_groups
            or c.context.shape[1] or len(c.levels) != 1
            or len(c.levels[0]) != 1 or (0, 0) not in grids):
        return None
    grid = grids[(0, 0)]
    if not isinstance(rules, slice) or rules != grid.out or len(grid.axes) < 2:
        return None
    var_of = [int(c.term_var[int(cols[0]) - 2]) for cols in grid.axes]
    if sorted(var_of) != list(range(len(c.inputs))):
        return None                    # (every input is one axis of the grid)
    k, t = len(c.inputs), max(len(cols) for cols in grid.axes)
    rows = np.zeros((k, t), dtype=np.intp)       # term index of each [input, row]
    for v, cols in zip(var_of, grid.axes):
        rows[v] = cols[0] - 2
        rows[v, :len(cols)] = cols - 2
    kb, s1, kc, s2 = (c.kernel[i][rows][:, :, None] for i in range(4))
    lo, hi = c.universe[:, :1, None], c.universe[:, 1:, None]
    with np.errstate(over="ignore", invalid="ignore"):   # a bound past 1e308 is inf: may overflow
        reach = np.maximum(np.abs(s1), np.abs(s2)) * (np.abs(hi - kb) + np.abs(hi - kc)
                                                      + np.abs(lo - kb) + np.abs(lo - kc))
    weighted = [j for j, w in enumerate(sum_rows) if w is not None]
    ones = [j for j, w in enumerate(sum_rows) if w is None]
    weighted += ones[1:]               # another sum of all-1 weights: its products are the DOFs
    ones = ones[:1]
    position = {j: i for i, j in enumerate(weighted + ones)}
    return GridBatch(
        B=np.ascontiguousarray(kb), C=np.ascontiguousarray(kc),
        S=np.ascontiguousarray(np.stack([s1, s2]).reshape(2, k * t, 1)),
        axes=tuple((v, len(cols)) for v, cols in zip(var_of, grid.axes)), shape=grid.shape,
        plateaus=bool(((kb < kc) & (s1 > 0) & (s2 > 0)).any()),
        overflow=not bool((reach < 1e300).all()), weight=weight,
        Kw=np.ascontiguousarray(c.sum_weights[weighted].T[:, :, None]), ones=len(ones),
        num=tuple(position[j] for j in range(len(c.outputs))),
        den=tuple(position[int(j)] for j in c.den_row),
        weighted_sum=c.operators.inference == "weighted_sum")


def _plan(c: CompiledRuleBase) -> Plan:
    rows = np.flatnonzero(c.linear)
    r0 = int(c.rule_col[0]) if c.n_rules else 2
    contiguous = bool((c.rule_col == np.arange(r0, r0 + c.n_rules)).all())
    rules = slice(r0, r0 + c.n_rules) if contiguous else c.rule_col
    weight = c.weight[:, None].copy() if c.weighted else None
    sum_rows = tuple(None if (w == 1.0).all() else np.ascontiguousarray(w[:, None])
                     for w in c.sum_weights)
    grids = {} if c.operators.and_ != "min" else {
        (i, j): grid for i, level in enumerate(c.levels) for j, group in enumerate(level)
        if (grid := _grid(group, c)) is not None}
    return Plan(
        n_terms=c.n_terms, n_rules=c.n_rules,
        lo=np.ascontiguousarray(c.universe[:, 0]), hi=np.ascontiguousarray(c.universe[:, 1]),
        lo_col=np.ascontiguousarray(c.universe[:, :1]),
        hi_col=np.ascontiguousarray(c.universe[:, 1:]),
        all_linear=bool(c.linear.all()), linear_rows=rows, term_var=c.term_var[rows],
        input_rows=tuple((int(np.searchsorted(c.term_var, k)),
                          int(np.searchsorted(c.term_var, k, side="right")))
                         for k in range(len(c.inputs))),
        kernel=tuple(np.ascontiguousarray(k[rows, None]) for k in c.kernel),
        bounds=(c.universe[:, 0].tolist(), c.universe[:, 1].tolist()),
        plateaus=bool(((c.kernel[0] < c.kernel[2]) & (c.kernel[1] > 0) & (c.kernel[3] > 0)
                       )[rows].any()),
        rules=rules,
        contexts=tuple(np.ascontiguousarray(c.context[:, j]) for j in range(c.context.shape[1])),
        weight=weight, sums=np.ascontiguousarray(c.sum_weights.T[:, :, None]), den_row=c.den_row,
        sum_rows=sum_rows, grids=grids)


class _Builder:
    """Allocates columns and collects node groups per level while walking expressions."""

    def __init__(self, n_terms: int) -> None:
        self.next_col = 2 + n_terms
        self.nodes: dict[tuple, tuple[int, int]] = {}   # key -> (column, level)
        self.pending: dict[tuple[int, str], list[tuple[int, list[int]]]] = {}
        self.negated_from: dict[int, tuple[int, int]] = {}   # not-node column -> its input

    def negate(self, ref: tuple[int, int]) -> tuple[int, int]:
        """``not`` of ``ref``; ``not not x`` is ``x`` itself, because ``1 - (1 - x)`` rounds a
        tiny membership to 0 and would turn a barely firing rule into one that does not fire."""
        if ref[0] in self.negated_from:
            return self.negated_from[ref[0]]
        out = self.node(("not", ref[0]), "not", [ref])
        self.negated_from[out[0]] = ref
        return out

    def node(self, key: tuple, op: str, children: list[tuple[int, int]]) -> tuple[int, int]:
        if key in self.nodes:
            return self.nodes[key]
        level = 1 + max((lvl for _, lvl in children), default=0)
        col = self.next_col
        self.next_col += 1
        self.pending.setdefault((level, op), []).append((col, [c for c, _ in children]))
        self.nodes[key] = (col, level)
        return col, level

    def levels(self, tnorm_identity: int = ONE) -> tuple[tuple[NodeGroup, ...], ...]:
        out: dict[int, list[NodeGroup]] = {}
        for (level, op), items in sorted(self.pending.items()):
            # neurons of similar fan-in share a group (fan-in up to a power of two), so one
            # rule with 10,000 conditions does not pad every neuron of its level to 10,000
            buckets: dict[int, list[tuple[int, list[int]]]] = {}
            for item in items:
                buckets.setdefault((len(item[1]) - 1).bit_length(), []).append(item)
            for _, bucket in sorted(buckets.items()):
                out.setdefault(level, []).append(_group(op, bucket))
        return tuple(tuple(out[k]) for k in sorted(out))


def _group(op: str, items: list[tuple[int, list[int]]]) -> NodeGroup:
    arity = max(len(ch) for _, ch in items)
    pad = ZERO if op == "or" else ONE
    children = np.full((len(items), arity), pad, dtype=np.intp)
    for i, (_, ch) in enumerate(items):
        children[i, :len(ch)] = ch
    return NodeGroup(op, np.array([c for c, _ in items], dtype=np.intp), children)


def compile_rulebase(rb: RuleBase, behavior: str | None = None,
                     overrides: tuple[Setting, ...] = ()) -> CompiledRuleBase:
    """Compile ``behavior`` (default: the rule base's first) into arrays.

    ``overrides`` are operator settings applied last, over the file's and the behavior's (a
    study of T-norms compiles the same rules with ``Setting("and", "product")`` and so on).
    """
    name = behavior or rb.default_behavior
    b = rb.behavior(name)
    operators = ops_mod.of_behavior(rb, b, tuple(overrides))
    flat = flatten(rb, name)
    if not flat:
        from ..errors import RuleBaseError

        raise RuleBaseError(f"behavior `{name}` has no rules (nor uses a behavior that has)",
                            span=b.span, hint=f"write a rule in `{name}`, or `use` a behavior "
                                              "with rules")
    variables = rb.variables
    inputs, outputs, linear_inputs = _used_variables(rb, flat, operators)
    members = _membership_layer(inputs, variables)
    builder = _Builder(len(members.terms))
    ante = _antecedents(flat, builder, members.index)
    cons = _consequents(flat, variables, inputs, outputs, linear_inputs)
    default = np.array([np.nan if variables[o].default is None else variables[o].default
                        for o in outputs], dtype=float)
    universe = np.array([variables[v].universe for v in inputs], dtype=float).reshape(-1, 2)
    return CompiledRuleBase(
        rulebase=rb, behavior=name, operators=operators, inputs=inputs, universe=universe,
        term_var=members.term_var, term_names=members.names, linear=members.linear,
        kernel=members.kernel, shape_groups=members.shape_groups, levels=builder.levels(),
        n_columns=builder.next_col, rule_col=ante.rule_col, weight=ante.weight,
        context=ante.context, labels=ante.labels, rules=ante.rules, outputs=outputs,
        cons_value=cons.value, cons_mask=cons.mask, cons_term=cons.term,
        cons_hedges=cons.hedges, default=default, variables=dict(variables),
        cons_linear=cons.linear)


def _used_variables(rb: RuleBase, flat: Flat, operators: Operators
                   ) -> tuple[tuple[str, ...], tuple[str, ...], dict[str, tuple[str, ...]]]:
    """The inputs the rules read (in declaration order), the outputs they set, and for each
    output with ``linear`` (Takagi-Sugeno) terms the inputs its coefficients follow."""
    variables = rb.variables
    used_inputs: set[str] = set()
    for _, rule, contexts in flat:
        _collect_inputs(rule.antecedent, used_inputs)
        for use in contexts:
            if use.condition is not None:
                _collect_inputs(use.condition, used_inputs)
    linear_inputs: dict[str, tuple[str, ...]] = {}
    concluded: dict[tuple[str, str | None], Rule] = {}
    for _, rule, _ in flat:
        for c in rule.consequents:
            if operators.inference == "tsukamoto":
                _check_tsukamoto(c, rule, variables, concluded)
            elif operators.inference != "mamdani":
                _check_crisp_value(c, rule, variables, operators.inference)
            if c.term is not None and variables[c.var].term(c.term).shape == "linear":
                names = linear_inputs.setdefault(c.var, _termset_inputs(rb, c.var))
                coefficients = variables[c.var].term(c.term).params[:-1]
                used_inputs.update(n for n, a in zip(names, coefficients) if a != 0.0)
                if operators.inference == "mamdani":
                    from ..errors import RuleBaseError

                    raise RuleBaseError(
                        f"`{c.var} is {c.term}` is a linear (Takagi-Sugeno) consequent, which "
                        f"Mamdani inference cannot use", span=c.span or rule.span,
                        hint="use `inference = weighted_average` (or weighted_sum), or give "
                             f"`{c.var}` membership-shaped terms")
    inputs = tuple(v.name for v in variables.values() if v.name in used_inputs)
    outputs = set(c.var for _, rule, _ in flat for c in rule.consequents)
    return inputs, tuple(v.name for v in variables.values() if v.name in outputs), linear_inputs


@dataclass(frozen=True, eq=False)
class _Members:
    """The membership layer: every term of every used input, one neuron each."""

    names: tuple[tuple[str, str], ...]     # [T] (variable, term)
    terms: tuple[Term, ...]
    term_var: np.ndarray                   # [T] input column of each
    linear: np.ndarray                     # [T] piecewise-linear (the fast kernel)
    kernel: np.ndarray                     # [4, T] (b, s1, c, s2) of the linear ones
    shape_groups: tuple[ShapeGroup, ...]   # the others, grouped by shape and parameter count

    @functools.cached_property
    def index(self) -> dict[tuple[str, str], int]:
        return {key: i for i, key in enumerate(self.names)}


def _membership_layer(inputs: tuple[str, ...], variables: Mapping[str, Variable]) -> _Members:
    names = tuple((v, t.name) for v in inputs for t in variables[v].terms)
    terms = tuple(t for v in inputs for t in variables[v].terms)
    term_var = [k for k, v in enumerate(inputs) for _ in variables[v].terms]
    kernel = np.zeros((4, len(terms)))
    # variadic shapes group by param count, formula terms by formula
    groups: dict[tuple[str, int, Formula | None], list[int]] = {}
    for i, t in enumerate(terms):
        if t.corners is not None:
            kernel[:, i] = kernel_params(t.corners)
        else:
            groups.setdefault((t.shape, len(t.params), t.formula), []).append(i)
    shape_groups = tuple(
        ShapeGroup(shape, np.array([2 + i for i in idx], dtype=np.intp),
                   np.array([term_var[i] for i in idx], dtype=np.intp),
                   np.array([terms[i].params for i in idx], dtype=float).reshape(
                       len(idx), n_params), formula)
        for (shape, n_params, formula), idx in groups.items())
    return _Members(names, terms, np.array(term_var, dtype=np.intp),
                    np.array([t.corners is not None for t in terms], dtype=bool), kernel,
                    shape_groups)


@dataclass(frozen=True, eq=False)
class _Antecedents:
    rule_col: np.ndarray             # [R] column of each rule's antecedent
    weight: np.ndarray               # [R] rule weight x constant use weights
    context: np.ndarray              # [R, C] columns of use-conditions (1 = none)
    labels: tuple[str, ...]
    rules: tuple[Rule, ...]


def _walk(builder: _Builder, term_index: dict, expr: Expr) -> tuple[int, int]:
    """The (column, level) of ``expr``'s neuron, adding the neurons it needs to ``builder``
    (a sub-expression used twice is one neuron)."""
    if isinstance(expr, Prop):
        col = 2 + term_index[(expr.var, expr.term)]
        ref = (col, 0)
        if expr.hedges:
            ref = builder.node(("hedge", expr.hedges, col), "hedge:" + " ".join(expr.hedges),
                               [ref])
        return builder.negate(ref) if expr.negated else ref
    if isinstance(expr, Not):
        return builder.negate(_walk(builder, term_index, expr.expr))
    op = "and" if isinstance(expr, And) else "or"
    children = [_walk(builder, term_index, item) for item in expr.items]
    if len(children) == 1:
        return children[0]
    return builder.node((op, tuple(c for c, _ in children)), op, children)


def _antecedents(flat: Flat, builder: _Builder, term_index: dict) -> _Antecedents:
    """Every rule's antecedent and ``use`` conditions as neurons, and its weight."""
    rule_col, weight, contexts = [], [], []
    for _, rule, uses in flat:
        rule_col.append(_walk(builder, term_index, rule.antecedent)[0])
        w = rule.weight
        ctx = []
        for use in uses:
            w *= use.weight
            if use.condition is not None:
                ctx.append(_walk(builder, term_index, use.condition)[0])
        weight.append(w)
        contexts.append(ctx)
    width = max((len(c) for c in contexts), default=0)
    context = np.full((len(flat), width), ONE, dtype=np.intp)
    for r, ctx in enumerate(contexts):
        context[r, :len(ctx)] = ctx
    return _Antecedents(np.array(rule_col, dtype=np.intp), np.array(weight, dtype=float),
                        context, tuple(label for label, _, _ in flat),
                        tuple(rule for _, rule, _ in flat))


@dataclass(frozen=True, eq=False)
class _Consequents:
    value: np.ndarray                # [R, m] crisp consequent (0 where unset or linear)
    mask: np.ndarray                 # [R, m] the rule sets this output
    term: tuple[tuple[str | None, ...], ...]
    hedges: tuple[tuple[tuple[str, ...], ...], ...]
    linear: np.ndarray | None        # [R, m, k + 1] Takagi-Sugeno consequents, if any


def _consequents(flat: Flat, variables: Mapping[str, Variable], inputs: tuple[str, ...],
                 outputs: tuple[str, ...],
                 linear_inputs: dict[str, tuple[str, ...]]) -> _Consequents:
    """What each rule sets: a crisp value (a term's centre or a number), the term and hedges
    it names, and, for ``linear`` terms, the coefficients over :data:`inputs`."""
    m = len(outputs)
    value = np.zeros((len(flat), m))
    mask = np.zeros((len(flat), m), dtype=bool)
    term: list[list[str | None]] = [[None] * m for _ in flat]
    hedges: list[list[tuple[str, ...]]] = [[()] * m for _ in flat]
    for r, (_, rule, _) in enumerate(flat):
        for c in rule.consequents:
            j = outputs.index(c.var)
            mask[r, j] = True
            if c.term is not None:
                value[r, j] = variables[c.var].term(c.term).center
                term[r][j] = c.term
                hedges[r][j] = c.hedges
            else:
                value[r, j] = c.value
    linear = _linear_consequents(flat, variables, inputs, outputs, linear_inputs, value) \
        if linear_inputs else None
    return _Consequents(value, mask, tuple(tuple(row) for row in term),
                        tuple(tuple(row) for row in hedges), linear)


def _linear_consequents(flat: Flat, variables: Mapping[str, Variable], inputs: tuple[str, ...],
                        outputs: tuple[str, ...], linear_inputs: dict[str, tuple[str, ...]],
                        value: np.ndarray) -> np.ndarray:
    """``[R, m, k + 1]``: constants as rows with a = 0; zeroes ``value`` where a rule's
    consequent is linear (its centre means nothing there)."""
    out = np.zeros((len(flat), len(outputs), len(inputs) + 1))
    out[:, :, -1] = value
    input_col = {var: i for i, var in enumerate(inputs)}
    for r, (_, rule, _) in enumerate(flat):
        for c in rule.consequents:
            if c.var not in linear_inputs or c.term is None:
                continue
            term = variables[c.var].term(c.term)
            if term.shape == "linear":
                j = outputs.index(c.var)
                for var, a in zip(linear_inputs[c.var], term.params[:-1]):
                    if a != 0.0:
                        out[r, j, input_col[var]] = a
                out[r, j, -1] = term.params[-1]
                value[r, j] = 0.0
    return out


def _check_crisp_value(c: Consequent, rule: Rule, variables: Mapping[str, Variable],
                       inference: str) -> None:
    """Weighted inference needs each consequent term's crisp value (its centre); a ``formula``
    term has none (its centre was NaN, and the output then silently its default)."""
    if c.term is None or variables[c.var].term(c.term).shape != "formula":
        return
    from ..errors import RuleBaseError

    raise RuleBaseError(
        f"`{c.var} is {c.term}`: `{c.term}` is a formula term, which has no crisp value for "
        f"`{inference}` inference to average", span=c.span or rule.span,
        hint=f"give `{c.var}` a crisp term (`{c.term}: 42`) or a shape with a centre, or use "
             f"`inference = mamdani`")


def _check_tsukamoto(c: Consequent, rule: Rule, variables: Mapping[str, Variable],
                     concluded: dict[tuple[str, str | None], Rule]) -> None:
    """Tsukamoto inference inverts each consequent's term: only monotonic ones have one, and
    only at a degree in [0, 1], which a term concluded by several rules (their degrees are
    summed, fuzzylite's rule) may exceed."""
    from ..errors import RuleBaseError
    from ..fuzzy.shapes import TSUKAMOTO

    first = concluded.setdefault((c.var, c.term), rule)
    if first is not rule:
        raise RuleBaseError(
            f"`{c.var} is {c.term}` is concluded by rules `{first.label}` and `{rule.label}`: "
            f"under Tsukamoto inference their degrees add up and may pass 1, where the term "
            f"has no inverse", span=c.span or rule.span,
            hint="join the rules' conditions with `or` in one rule")

    shape = variables[c.var].term(c.term).shape if c.term is not None else None
    if shape not in TSUKAMOTO:
        what = f"a `{shape}` term" if shape else "a crisp value"
        raise RuleBaseError(
            f"`{c.var} is {c.term or c.value}`: Tsukamoto inference needs a monotonic "
            f"consequent term ({', '.join(TSUKAMOTO)}), not {what}", span=c.span or rule.span)


def _termset_inputs(rb: RuleBase, output: str) -> tuple[str, ...]:
    """The input variables, in order, of the term set defining ``output`` (the coefficient
    order of its ``linear`` terms, :data:`mitos_cli.fuzzy.shapes.LINEAR_LAYOUT`)."""
    for ts in rb.termsets:
        if any(v.name == output for v in ts.variables):
            return tuple(v.name for v in ts.variables if v.role == "input")
    return ()


def _collect_inputs(expr: Expr, out: set[str]) -> None:
    if isinstance(expr, Prop):
        out.add(expr.var)
    elif isinstance(expr, Not):
        _collect_inputs(expr.expr, out)
    else:
        for item in expr.items:
            _collect_inputs(item, out)


__all__ = ["CompiledRuleBase", "NodeGroup", "ShapeGroup", "compile_rulebase", "Use"]
