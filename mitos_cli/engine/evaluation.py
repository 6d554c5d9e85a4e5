"""Evaluating a compiled rule base on a batch of inputs: a pure function of arrays.

``evaluate(compiled, X)`` takes ``X[n, k]`` (rows are samples, columns the compiled inputs) and
returns memberships ``[n, T]``, DOFs ``[n, R]`` and outputs ``[n, m]``. Internally a block of
samples is ``V[neurons, b]``: each layer gathers whole rows (contiguous copies), and every
operation is elementwise per sample, so a single evaluation is bit for bit the same as its row
in any batch.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import EmptyOutputError, InputError, NoRuleFiredError
from ..fuzzy import hedges as hedge_mod
from ..fuzzy import norms
from ..fuzzy.shapes import SHAPES
from ..numbers import exact
from ..words import plural
from .compile import CompiledRuleBase
from .inputs import floats, named_columns
from .threads import Blocks, map_blocks, thread_count

if TYPE_CHECKING:
    from collections.abc import Sequence

    from numpy.typing import ArrayLike

    from .compile import Grid, GridBatch, NodeGroup, Plan, ShapeGroup

    #: inputs as columns: an array ``[k, n]``, ``k`` 1-D arrays of one length, or a mapping
    #: of each input's name to its column (or to one number)
    Columns = ArrayLike | Sequence[ArrayLike] | Mapping[str, ArrayLike]


@dataclass(frozen=True, eq=False)   # holds arrays: identity, not ==
class Result:
    """What one batch evaluation computed (rows are samples)."""

    compiled: CompiledRuleBase
    inputs: np.ndarray        # [n, k] after clamping to the universes
    memberships: np.ndarray | None   # [n, T] (None with detail=False)
    dof: np.ndarray | None    # [n, R] degree of fulfilment of each rule (after weights)
    outputs: np.ndarray       # [n, m]
    clamped: np.ndarray       # [k] how many samples of each input were clamped
    values: np.ndarray | None = None  # [n, columns] every neuron's value (kept on request)
    no_rule: np.ndarray | None = None  # [n, m] True where no rule set the output (before defaults)

    # memberships and dof are transposed views of [T, n] / [R, n] arrays (rows are samples).

    def __repr__(self) -> str:
        kept = [k for k in ("memberships", "dof", "values") if getattr(self, k) is not None]
        return (f"<Result of {self.compiled.behavior!r}: {plural(len(self.outputs), 'sample')} x "
                f"{plural(len(self.compiled.outputs), 'output')} ({', '.join(self.compiled.outputs)})"
                f"{'; with ' + ', '.join(kept) if kept else ''}>")

    def output(self, name: str) -> np.ndarray:
        """The column ``[n]`` of output ``name``; another name is an :class:`InputError`
        with a "did you mean" (it was ``ValueError: tuple.index(x): x not in tuple``)."""
        outputs = self.compiled.outputs
        if not isinstance(name, str) or name not in outputs:
            from ..errors import unknown

            raise unknown("output", f"{name!s:.40}", outputs, cls=InputError)
        return self.outputs[:, outputs.index(name)]


def as_batch(compiled: CompiledRuleBase, columns: Mapping[str, object]) -> np.ndarray:
    """Input arrays by variable name -> ``X[n, k]`` in the compiled column order.

    Every compiled input must be given; scalars broadcast against arrays. Names that the
    behavior does not use are refused with a "did you mean".
    """
    if len(columns) == len(compiled.inputs) and all(type(v) in (float, int)
                                                     for v in columns.values()):
        try:                                   # numbers by name: one small array, no checks
            return np.array([[float(columns[k]) for k in compiled.inputs]])  # type: ignore[arg-type]
        except (KeyError, OverflowError):
            pass                               # a misspelt name, 10**400: below
    # anything else through floats(): float() alone reads True, "5_0" and Decimal("1e400")
    _check_names(compiled, columns)
    return np.ascontiguousarray(_columns(compiled, columns).T)


def as_columns(compiled: CompiledRuleBase, columns: Mapping[str, object]) -> list[np.ndarray]:
    """Like :func:`as_batch`, but one 1-D float array per input, in the compiled order, all
    of one length (what :func:`evaluate_columns` takes): an input given as a float array is
    used as it is, a scalar is broadcast (a view), so a large batch is not copied."""
    _check_names(compiled, columns)
    return _column_list(compiled, columns)


def _check_names(compiled: CompiledRuleBase, columns: Mapping[str, object]) -> None:
    from ..errors import unknown

    for name in columns:
        if not isinstance(name, str):   # (a dict keyed 0, 1, 2 met a TypeError in did you mean)
            raise InputError(f"inputs are named by text, not `{name!r:.40}`",
                             expected="names among " + ", ".join(compiled.inputs),
                             hint="give the values in order as a list or array, or by name")
        if name not in compiled.inputs:
            known = [v.name for v in compiled.variables.values() if v.role == "input"]
            if name in known:
                raise InputError(f"behavior `{compiled.behavior}` does not use input `{name}`",
                                 expected="values for " + ", ".join(compiled.inputs))
            raise unknown("input", name, compiled.inputs, cls=InputError)
    missing = [k for k in compiled.inputs if k not in columns]
    if missing:
        raise InputError("missing input " + ", ".join(f"`{m}`" for m in missing),
                         expected="a value for each of " + ", ".join(compiled.inputs),
                         hint="give them as " + " ".join(f"{k}=VALUE" for k in missing))


def _columns(compiled: CompiledRuleBase, columns: Mapping[str, object]) -> np.ndarray:
    arrays = _column_list(compiled, columns)
    Xt = np.empty((len(arrays), arrays[0].shape[0] if arrays else 1))
    for j, arr in enumerate(arrays):
        Xt[j] = arr
    return Xt


def _column_list(compiled: CompiledRuleBase, columns: Mapping[str, object]) -> list[np.ndarray]:
    arrays = [floats(columns[name], f"input `{name}`") for name in compiled.inputs]
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrays))
    except ValueError:
        raise InputError("input arrays have different lengths: " + ", ".join(
            f"{n} {a.shape}" for n, a in zip(compiled.inputs, arrays))) from None
    if len(shape) > 1:
        raise InputError(f"inputs must be numbers or 1-D arrays, not of shape {shape}")
    n = shape[0] if shape else 1
    return [arr if arr.shape == (n,) else np.broadcast_to(arr, (n,)) for arr in arrays]


def check_inputs(compiled: CompiledRuleBase, X: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Refuse NaN, clamp to each universe: ``X[n, k]`` -> (clamped ``Xt[k, n]``, counts)."""
    return _clamp(compiled, _rows(compiled, X))


def _rows(compiled: CompiledRuleBase, X: ArrayLike | Mapping[str, ArrayLike]) -> np.ndarray:
    """``X`` as a float array ``[n, k]`` (one sample may come as a flat ``[k]``; a mapping,
    or a table that names its columns (:func:`~.inputs.named_columns`: a DataFrame, a
    structured array), gives the inputs by name, as :func:`as_batch` reads them)."""
    if type(X) is not np.ndarray or X.dtype.names:    # a mapping's keys were read as values,
        named = named_columns(X)                        # a DataFrame's columns by position
        if named is not None:
            return as_batch(compiled, named)
    k = len(compiled.inputs)
    X = floats(X, "the inputs", many=True)
    if X.ndim == 1 and X.shape[0] == k:
        X = X[None]
    if X.ndim != 2 or X.shape[1] != k:
        raise InputError(f"expected inputs of shape [n, {k}] "
                         f"({', '.join(compiled.inputs)}), not {X.shape}")
    return X


def _clamp(compiled: CompiledRuleBase, X: np.ndarray, first: int = 0,
           total: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``X[b, k]`` -> clamped ``Xt[k, b]`` (each input a contiguous row) and how many
    samples of each input were clamped. ``first`` and ``total`` place the block in its batch
    for the message about a NaN."""
    return _clamp_columns(compiled, X.T, first, total)


def _clamp_columns(compiled: CompiledRuleBase, Xt: np.ndarray, first: int = 0,
                   total: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_clamp` of a block given as columns ``Xt[k, b]`` (any strides). Under ``inputs =
    as_given`` nothing is clamped (and nothing counted), but a NaN or an infinite input is
    refused: a term or linear function has no number there."""
    plan = compiled.plan
    if compiled.operators.inputs == "as_given":
        Xc = np.array(Xt, dtype=float, order="C") + 0.0          # -0.0 -> 0.0, as the clamp
        if not np.isfinite(Xc).all():
            bad = ~np.isfinite(Xc)
            row = int(np.argmax(bad.any(axis=0)))
            col = int(np.argmax(bad[:, row]))
            where = f" (sample {first + row + 1})" if (total or Xt.shape[1]) > 1 else ""
            value = Xc[col, row]
            if value != value:
                raise InputError(f"input `{compiled.inputs[col]}` is not a number (NaN){where}",
                                 hint="give every input a finite number")
            raise InputError(f"input `{compiled.inputs[col]}` is {value}{where}: with `inputs = "
                             f"as_given` (fuzzylite's and jFuzzyLogic's reading) it is not "
                             f"clamped to its universe, and its terms have no number there",
                             hint="give every input a finite number")
        return Xc, np.zeros(len(plan.lo), dtype=np.intp)
    Xc = np.maximum(Xt, plan.lo_col, order="C")  # NaN stays NaN, and differs from itself
    np.minimum(Xc, plan.hi_col, out=Xc)
    Xc += 0.0     # -0.0 -> 0.0: which zero max(-0.0, 0.0) returns is NumPy's choice, per loop
    if not (Xc != Xt).any():                   # the common case: nothing to clamp, no NaN
        return Xc, np.zeros(len(plan.lo), dtype=np.intp)
    bad = np.isnan(Xt)
    if bad.any():          # the first sample with a NaN, whatever the width of the blocks
        row = int(np.argmax(bad.any(axis=0)))
        col = int(np.argmax(bad[:, row]))
        where = f" (sample {first + row + 1})" if (total or Xt.shape[1]) > 1 else ""
        raise InputError(f"input `{compiled.inputs[col]}` is not a number (NaN){where}",
                         hint="give every input a finite number")
    return Xc, (Xc != Xt).sum(axis=1)


#: Samples per block: one block's neuron values stay in the CPU cache. Every operation is
#: column-wise (per sample), so results do not depend on the block size.
BLOCK = 8192

#: Most neuron values of one block (16 MB): a network of more than 256 neurons takes blocks of
#: fewer samples (:func:`block_width`). Without it a variable of 10,000 terms made blocks of
#: 655 MB, and `mitos check` of one 1.3 GB.
BLOCK_CELLS = BLOCK * 256


def block_width(compiled: CompiledRuleBase) -> int:
    """Samples per block of ``compiled``'s network: :data:`BLOCK`, or as many as
    :data:`BLOCK_CELLS` neuron values hold (at least 16)."""
    return max(16, min(BLOCK, BLOCK_CELLS // max(1, compiled.n_columns)))

#: Elements between the rows of a buffer whose halves are added in place. NumPy 1.x takes its
#: scalar loop, at twice the time, when an input ends exactly where the output begins (so
#: ``np.add(W[:h], W[h:], out=W[:h])`` on a contiguous ``W``); rows a cache line apart are
#: never adjacent. (NumPy 2 has no such case.)
_GAP = 8


def memberships(compiled: CompiledRuleBase, Xt: np.ndarray, out: np.ndarray) -> None:
    """Membership layer: fill rows ``2 .. 2+T`` of ``out[columns, b]`` from ``Xt[k, b]``.

    Piecewise-linear terms share one kernel, ``clip(1 + min((x - b) s1, (c - x) s2), 0, 1)``
    (see :func:`mitos_cli.fuzzy.shapes.kernel_params`); other shapes are evaluated per shape. The
    clip at 1 is skipped when no term has a plateau between two slopes (triangles and
    shoulders never exceed 1), and the clip at 0 takes a row of zeros: NumPy's ``maximum``
    with a Python scalar is about 1.5x slower than with an array.
    """
    plan = compiled.plan
    if len(plan.linear_rows):
        b, s1, c, s2 = plan.kernel
        if plan.all_linear:            # each input's terms are a run of rows: no gather of x
            rise, fall = out[2:2 + plan.n_terms], np.empty((plan.n_terms, Xt.shape[1]))
            for v, (lo, hi) in enumerate(plan.input_rows):   # a loop over the inputs
                np.subtract(Xt[v], b[lo:hi], out=rise[lo:hi])
                np.subtract(c[lo:hi], Xt[v], out=fall[lo:hi])
        else:
            x = Xt[plan.term_var]
            rise = np.subtract(x, b)
            fall = np.subtract(c, x, out=x)
        with np.errstate(over="ignore"):   # a slope x distance past 1e308 is inf: clipped to 0 or 1
            rise *= s1
            fall *= s2
        np.minimum(rise, fall, out=rise)
        if plan.plateaus:
            np.minimum(rise, 0.0, out=rise)
        rise += 1.0
        width = rise.shape[1]
        np.maximum(rise, _ZEROS[:, :width] if width <= BLOCK else 0.0, out=rise)
        if not plan.all_linear:
            out[2 + plan.linear_rows] = rise
    for g in compiled.shape_groups:
        x = Xt[g.inputs]
        if g.formula is not None:
            out[g.cols] = _formula_memberships(compiled, g, x)
            continue
        shape = SHAPES[g.shape]
        out[g.cols] = shape.fn(x, *(g.params[:, i:i + 1] for i in range(g.params.shape[1])))


def _formula_memberships(compiled: CompiledRuleBase, g: ShapeGroup, x: np.ndarray) -> np.ndarray:
    """A formula term's memberships; a value that is no degree (NaN, or outside [0, 1]) is
    refused with the term and the input, never passed on (a hedge would turn it into NaN)."""
    assert g.formula is not None
    mu = g.formula(x)
    bad = ~((mu >= 0.0) & (mu <= 1.0))
    if bad.any():
        row, col = map(int, np.argwhere(bad)[0])
        var, term = compiled.term_names[int(g.cols[row]) - 2]
        raise InputError(f"term `{var}.{term}` (formula `{g.formula.text}`) gives {exact(mu[row, col])} "
                         f"at {var} = {exact(x[row, col])}: a membership degree lies in [0, 1]",
                         span=compiled.variables[var].term(term).span,    # (where it is written)
                         hint="change the formula so it stays within [0, 1] on the universe")
    return mu


def _apply_group(group: NodeGroup, V: np.ndarray, tnorm: norms.Norm, snorm: norms.Norm) -> None:
    """One layer's neurons of one operator: gather their inputs, aggregate, write outputs."""
    op = group.op
    ch = group.children
    if op == "not":
        V[group.out] = 1.0 - V[ch[:, 0]]
        return
    if op.startswith("hedge:"):
        V[group.out] = hedge_mod.apply(tuple(op[6:].split()), V[ch[:, 0]])
        return
    norm = tnorm if op == "and" else snorm
    lo, hi = int(group.out[0]), int(group.out[-1]) + 1
    contiguous = hi - lo == len(group.out)     # the compiler allocates a group's outputs in a row
    inputs = V[ch]                             # [g, arity, b]: whole rows, copied
    if norm.fn is np.minimum or norm.fn is np.maximum:
        acc = norm.fn.reduce(inputs, axis=1, out=V[lo:hi] if contiguous else None)
    else:
        acc = inputs[:, 0]
        for j in range(1, ch.shape[1]):        # loop over arity (a few), never over rules
            acc = norm.fn(acc, inputs[:, j])
        if contiguous:
            V[lo:hi] = acc
    if not contiguous:
        V[group.out] = acc


def network_values(compiled: CompiledRuleBase, Xt: np.ndarray) -> np.ndarray:
    """Every neuron's value ``V[columns, b]`` for inputs ``Xt[k, b]`` (one block)."""
    V = np.empty((compiled.n_columns, Xt.shape[1]))
    V[:2] = _CONSTANTS
    memberships(compiled, Xt, V)
    if compiled.levels:
        tnorm, snorm = compiled.operators.tnorm, compiled.operators.snorm
        grids = compiled.plan.grids
        for i, level in enumerate(compiled.levels):
            for j, group in enumerate(level):
                grid = grids.get((i, j))
                if grid is not None:
                    _apply_grid(grid, V)
                else:
                    _apply_group(group, V, tnorm, snorm)
    return V


def _apply_grid(grid: Grid, V: np.ndarray) -> None:
    """AND neurons over every combination of terms: ``min`` broadcast over one membership
    vector per variable (``t1 + t1 t2 + ...`` minima instead of gathers)."""
    b = V.shape[1]
    acc = V[grid.axes[0]]
    for depth, axis in enumerate(grid.axes[1:], start=1):
        last = depth == len(grid.axes) - 1
        target = V[grid.out].reshape(grid.shape + (b,)) if last else None
        acc = np.minimum(acc[..., None, :], V[axis], out=target)


_CONSTANTS = np.array([[0.0], [1.0]])   # columns ZERO and ONE
_ZEROS = np.zeros((1, BLOCK))           # the clip at 0 of the membership kernel
_ZEROS.flags.writeable = False


def rule_dof(compiled: CompiledRuleBase, V: np.ndarray) -> np.ndarray:
    """DOFs ``[R, b]``: antecedent values times ``use`` contexts and rule weights."""
    plan = compiled.plan
    dof = V[plan.rules]                         # a view when the rules own a run of columns
    if plan.contexts or plan.weight is not None:
        dof = dof.copy()
        for ctx in plan.contexts:                   # depth of `use` nesting
            dof *= V[ctx]
        if plan.weight is not None:
            dof *= plan.weight
    return dof


def tree_sum(W: np.ndarray) -> np.ndarray:
    """Sum ``W[R, ...]`` over its first axis (the rules) by halving, pairwise.

    Only elementwise additions, in an order fixed by ``R`` alone: one sample gives the same
    bits alone or in any batch, on any NumPy. The loop runs log2(R) times, each step adding
    two contiguous halves.
    """
    size = W.shape[0]
    while size > 1:
        half = (size + 1) // 2
        np.add(W[:size - half], W[half:size], out=W[:size - half])
        size = half
    return W[0]


def linear_consequents(compiled: CompiledRuleBase, Xt: np.ndarray) -> np.ndarray:
    """Takagi-Sugeno consequents ``Y[m, R, b] = a . x + c`` of every rule and output.

    A fixed left-to-right sum over the inputs (a handful), elementwise per sample: never a
    matrix product, whose summation order could depend on the batch size.
    """
    A = compiled.cons_linear                     # [R, m, k + 1]
    if A is None:
        raise ValueError(f"behavior `{compiled.behavior}` has no linear consequents")
    Y = np.empty((A.shape[1], A.shape[0], Xt.shape[1]))
    Y[:] = A[:, :, -1].T[:, :, None]
    for i in range(A.shape[2] - 1):
        a = A[:, :, i].T                         # [m, R]
        if a.any():
            Y += a[:, :, None] * Xt[i]
    return Y


def weighted_average(compiled: CompiledRuleBase, dof: np.ndarray,
                     Xt: np.ndarray | None = None) -> np.ndarray:
    """Eqs. 18-19 for every output: ``sum(dof * y) / sum(dof)`` (NaN where nothing fired).

    ``y`` is the rule's crisp consequent, or with linear consequents ``a . x + c`` for the
    block's inputs ``Xt[k, b]``; ``weighted_sum`` skips the division. Every sum is the
    pairwise :func:`tree_sum` over the rules, so its bits do not depend on the batch.
    """
    plan = compiled.plan
    m = len(compiled.outputs)
    if compiled.cons_linear is not None and Xt is None:
        raise ValueError("linear consequents need the inputs: weighted_average(compiled, dof, Xt)")
    if compiled.accumulated is not None:
        return _accumulated_average(compiled, dof, Xt)
    if compiled.cons_linear is not None and Xt is not None:
        W = np.multiply(dof[:, None], plan.sums)     # [R, k, b]: numerators, denominators
        np.multiply(dof[:, None], linear_consequents(compiled, Xt).transpose(1, 0, 2),
                    out=W[:, :m])
        sums = tree_sum(W)
    else:
        sums = _constant_sums(plan, dof)
    if compiled.hedged_outputs:
        return _hedged_average(compiled, dof, Xt, sums)
    if compiled.operators.inference == "weighted_sum":
        return _unset_sums(compiled, sums[:m].copy(), sums[plan.den_row])
    den = sums[plan.den_row]
    fired = den > 0
    if fired.all():
        return np.divide(sums[:m], den)
    return np.divide(sums[:m], den, out=np.full((m, dof.shape[1]), np.nan), where=fired)


def _hedged_average(compiled: CompiledRuleBase, dof: np.ndarray, Xt: np.ndarray | None,
                    sums: np.ndarray) -> np.ndarray:
    """Weighted inference where consequents carry hedges (``then tip is very high``): the
    hedge weights that rule's consequent by ``hedge(dof)`` (fuzzylite's reading; hedging a
    singleton's set, Zadeh's reading, would change nothing). Outputs without hedges keep
    their sums; a hedged one is summed again over its own weights (a loop over the few
    distinct hedges of an output, never over rules)."""
    m = len(compiled.outputs)
    nums, dens = sums[:m].copy(), sums[compiled.plan.den_row].copy()
    Y = linear_consequents(compiled, Xt) if compiled.cons_linear is not None and Xt is not None \
        else None
    for j in compiled.hedged_outputs:
        D = _rule_weights(compiled, dof, j)
        y = Y[j] if Y is not None else compiled.cons_value[:, j, None]
        dens[j] = tree_sum(D.copy())
        nums[j] = tree_sum(np.multiply(D, y))
    if compiled.operators.inference == "weighted_sum":
        return _unset_sums(compiled, nums, dens)
    fired = dens > 0
    return np.divide(nums, dens, out=np.full(nums.shape, np.nan), where=fired)


def _rule_weights(compiled: CompiledRuleBase, dof: np.ndarray, j: int) -> np.ndarray:
    """``[R, b]``: each rule's weight in output ``j``: its DOF where it sets ``j`` (0 where it
    does not), hedged where its consequent is (a loop over the output's few distinct hedges)."""
    D = dof * compiled.cons_mask[:, j, None]
    if j in compiled.hedged_outputs:
        column = [compiled.cons_hedges[r][j] for r in range(compiled.n_rules)]
        for hedges in dict.fromkeys(h for h in column if h):
            rows = np.array([h == hedges for h in column])
            D[rows] = hedge_mod.weigh(hedges, dof[rows])
    return D


def _accumulated_average(compiled: CompiledRuleBase, dof: np.ndarray,
                         Xt: np.ndarray | None) -> np.ndarray:
    """Weighted inference under ``accumulation = S``: the rules concluding one value of an
    output are joined by the S-norm into one weight (jFuzzyLogic's ``ACCU`` at a singleton),
    then ``sum(w_g y_g) / sum(w_g)`` over the values. The fold runs per depth of the groups
    (a loop over the most rules one value has, never over rules or samples) in rule order,
    and the sums are :func:`tree_sum` over the groups: a sample's bits do not depend on the
    batch."""
    snorm = norms.lookup("snorm", compiled.operators.accumulation)
    m, b = len(compiled.outputs), dof.shape[1]
    nums, dens = np.zeros((m, b)), np.zeros((m, b))
    Y = linear_consequents(compiled, Xt) if compiled.cons_linear is not None and Xt is not None \
        else None
    assert compiled.accumulated is not None
    for j, acc in enumerate(compiled.accumulated):
        if not len(acc.first):
            continue
        D = _rule_weights(compiled, dof, j)
        W = D[acc.first]                                   # [G, b], a copy
        for groups, rules in acc.steps:
            W[groups] = snorm(W[groups], D[rules])
        y = Y[j][acc.first] if Y is not None else compiled.cons_value[acc.first, j, None]
        if Y is not None and len(acc.first) > 1:
            W, y = _join_equal_values(W, y, snorm)
        nums[j] = tree_sum(np.multiply(W, y))
        dens[j] = tree_sum(W.copy())
    if compiled.operators.inference == "weighted_sum":
        return _unset_sums(compiled, nums, dens)
    fired = dens > 0
    return np.divide(nums, dens, out=np.full(nums.shape, np.nan), where=fired)


def _join_equal_values(W: np.ndarray, y: np.ndarray,
                       snorm: norms.Norm) -> tuple[np.ndarray, np.ndarray]:
    """Groups of different linear functions whose values are equal at a sample (``[G, b]``
    weights and values) joined there too, as jFuzzyLogic keys its table by the value (a
    ``Double``: ``0.0`` and ``-0.0`` are two keys). Each sample's values are sorted, stably,
    and a run of equal ones is folded into its last row (a loop over the few groups of an
    output, never over samples): the order depends on the sample alone."""
    order = np.argsort(y, axis=0, kind="stable")
    ys = np.take_along_axis(y, order, axis=0)
    ws = np.take_along_axis(W, order, axis=0)
    sign = np.signbit(ys)
    for k in range(1, len(ys)):
        same = (ys[k] == ys[k - 1]) & (sign[k] == sign[k - 1])
        if same.any():
            ws[k] = np.where(same, snorm(ws[k - 1], ws[k]), ws[k])
            ws[k - 1] = np.where(same, 0.0, ws[k - 1])
    return ws, ys


def _unset_sums(compiled: CompiledRuleBase, nums: np.ndarray, dens: np.ndarray) -> np.ndarray:
    """A weighted sum ``nums[m, b]`` with NaN where none of an output's rules fired (its
    denominator ``dens`` 0) and the output declares a default, which then applies there
    (:func:`fill_defaults`), as under every other inference; elsewhere the sum, 0 where
    nothing fired for an output without a default."""
    for j in compiled.summed_defaults:
        nums[j][dens[j] <= 0] = np.nan
    return nums


def _constant_sums(plan: Plan, dof: np.ndarray) -> np.ndarray:
    """``[k, b]``: each numerator and denominator row of the output layer by the pairwise
    :func:`tree_sum` over the rules (a loop over the few sums, never over rules). The first
    halving step reads the DOFs directly, products formed in place (a row of ones, a
    denominator, adds the DOFs themselves, with no copy); the later steps run on every sum at
    once. The same products and the same tree as summing ``dof[:, None] * plan.sums``."""
    R, b = dof.shape
    if R < 2:
        return np.multiply(dof, plan.sums[:, :, 0].T)
    half = (R + 1) // 2
    low = R - half                       # rules i < low pair with i + half; an odd one stays
    S = np.empty((half, len(plan.sum_rows), b + _GAP))[:, :, :b]     # rows apart: see _GAP
    tmp = None
    for j, weights in enumerate(plan.sum_rows):
        row = S[:, j]
        if weights is None:
            np.add(dof[:low], dof[half:], out=row[:low])
            if low < half:
                row[low] = dof[low]
        else:
            np.multiply(dof[:half], weights[:half], out=row)
            if tmp is None:
                tmp = np.empty((low, b))
            np.multiply(dof[half:], weights[half:], out=tmp)
            np.add(row[:low], tmp, out=row[:low])
    return tree_sum(S)


def evaluate(compiled: CompiledRuleBase, X: ArrayLike | Mapping[str, ArrayLike], *,
             detail: bool = True, keep_values: bool = False, strict: bool = True) -> Result:
    """Evaluate the network on ``X[n, k]``, in cache-sized blocks of samples (or on inputs by
    name: ``{"road": array, "size": 45, ...}``, as :func:`as_batch` reads them).

    ``detail`` keeps memberships and DOFs (``False`` returns only outputs, faster);
    ``keep_values`` also keeps every neuron's value (for training and the rule viewer). An
    output whose rules all have DOF 0 for some sample takes the variable's ``default``; when it
    has none, ``strict`` (the default) raises :class:`NoRuleFiredError` and ``strict=False``
    leaves NaN there (for callers that report such samples themselves).

    Blocks are spread over threads (:func:`~.threads.map_blocks`): the same bits. Without
    ``detail`` or ``keep_values``, a behavior whose rules are one grid takes
    :func:`_grid_columns` (the same bits, in fewer NumPy calls).
    """
    X = _rows(compiled, X)
    n, k = X.shape
    if n == 1 and not (detail or keep_values):
        one = _evaluate_one(compiled, X[0].tolist())
        if one is not None:
            one_in, one_out = one
            return Result(compiled, np.array([one_in]), None, None, np.array([one_out]),
                          (np.array(one_in) != X[0]).astype(np.intp))
    if compiled.grid_batch is not None and not (detail or keep_values):
        return _grid_result(compiled, compiled.grid_batch, X, strict)
    plan = compiled.plan
    T, R = plan.n_terms, plan.n_rules
    clamped_in = np.empty((k, n))
    mu = np.empty((T, n)) if detail else None
    dof = np.empty((R, n)) if detail else None
    values = np.empty((compiled.n_columns, n)) if keep_values else None
    out = np.empty((len(compiled.outputs), n))

    def blocks(ranges: Blocks) -> np.ndarray:     # each block one vectorized pass
        counts = np.zeros(k, dtype=np.intp)
        for start, end in ranges:
            block = slice(start, end)
            Xt, clamped = _clamp(compiled, X[block], start, n)
            counts += clamped
            V = network_values(compiled, Xt)
            d = rule_dof(compiled, V)
            out[:, block] = infer(compiled, d, Xt)
            clamped_in[:, block] = Xt
            if mu is not None and dof is not None:      # detail
                mu[:, block] = V[2:2 + T]
                dof[:, block] = d
            if values is not None:                      # keep_values
                values[:, block] = V
        return counts
    counts = sum(map_blocks(blocks, n, block_width(compiled)), np.zeros(k, dtype=np.intp))
    clamped_rows = clamped_in.T        # (not X again: `blocks` reads X, the rows of the inputs)
    no_rule = np.isnan(out.T)
    outputs = fill_defaults(compiled, out.T, clamped_rows, strict)
    return Result(compiled, clamped_rows, None if mu is None else mu.T, None if dof is None else dof.T,
                  outputs, counts, None if values is None else values.T, no_rule)


def _grid_result(compiled: CompiledRuleBase, g: GridBatch, X: np.ndarray, strict: bool) -> Result:
    """:func:`evaluate` of ``X[n, k]`` without detail for a grid behavior: the inputs clamped
    (one contiguous row each; a NaN is named by its first sample, as the blocks of
    :func:`evaluate` name it), then the outputs by :func:`_grid_columns`."""
    Xc, counts = _clamp(compiled, X)
    out = np.empty((len(compiled.outputs), X.shape[0]))
    _grid_columns(compiled, g, list(Xc), out)
    no_rule = np.isnan(out.T)
    return Result(compiled, Xc.T, None, None, fill_defaults(compiled, out.T, Xc.T, strict),
                  counts, None, no_rule)


def rule_dofs(compiled: CompiledRuleBase, X: ArrayLike) -> np.ndarray:
    """The rules' DOFs ``[n, R]`` on ``X[n, k]`` (clamped to the universes), the bits of
    :func:`evaluate`'s ``dof``, without inferring the outputs: what a coverage check needs,
    at a cost that does not grow with a Mamdani output's ``resolution``."""
    X = _rows(compiled, X)
    n = X.shape[0]
    dof = np.empty((compiled.plan.n_rules, n))
    width = block_width(compiled)
    for start in range(0, n, width):
        block = slice(start, min(start + width, n))
        Xt, _ = _clamp(compiled, X[block], start, n)
        dof[:, block] = rule_dof(compiled, network_values(compiled, Xt))
    return dof.T


def evaluate_columns(compiled: CompiledRuleBase, Xt: Columns, *, strict: bool = True) -> np.ndarray:
    """The outputs ``[m, n]`` (one contiguous row per output) for inputs given as columns
    ``Xt[k, n]`` (an array, a sequence of ``k`` 1-D arrays of one length, or a mapping of
    the inputs' names to their columns, numbers broadcast):
    :func:`evaluate` with ``detail=False``, bit for bit, without copying a large batch into
    rows or keeping its clamped inputs (``load_rulebase().evaluate(**arrays)``).

    A behavior whose rules are one grid (:class:`~mitos_cli.engine.compile.GridBatch`, the
    paper's 27 rules) takes :func:`_grid_columns`, the same operations in fewer NumPy calls.
    A large batch's blocks are spread over threads (:mod:`~mitos_cli.engine.threads`): the
    same bits, since no sample's operations depend on the others."""
    Xt, columns = _input_columns(compiled, Xt)
    if any(x.ndim != 1 or x.shape != columns[0].shape for x in columns):
        raise InputError("input columns must be 1-D arrays of one length, not of shapes "
                         + ", ".join(str(x.shape) for x in columns))
    n = columns[0].shape[0] if columns else 0
    out = np.empty((len(compiled.outputs), n))
    grid = compiled.grid_batch
    if grid is not None:
        unfired = _grid_columns(compiled, grid, columns, out)
    else:
        if not (isinstance(Xt, np.ndarray) and Xt.dtype == float and Xt.ndim == 2):
            Xt = np.array(columns).reshape(len(columns), n)

        def blocks(ranges: Blocks) -> None:
            for start, end in ranges:
                Xc, _ = _clamp_columns(compiled, Xt[:, start:end], start, n)
                out[:, start:end] = infer(compiled, rule_dof(compiled, network_values(compiled, Xc)),
                                          Xc)
        map_blocks(blocks, n, block_width(compiled))
        unfired = True
    if unfired and np.isnan(out).any():      # rare: the clamped rows, for the message
        rows = np.array(columns).T + 0.0
        if compiled.operators.inputs == "clamped":
            rows = np.minimum(np.maximum(rows, compiled.plan.lo), compiled.plan.hi) + 0.0
        fill_defaults(compiled, out.T, rows, strict)
    return out


def _input_columns(compiled: CompiledRuleBase,
                   Xt: Any) -> tuple[Columns, list[np.ndarray]]:   # any: checked here, at run time
    """``Xt`` (an array ``[k, n]`` or ``k`` columns) and its columns as float arrays, each
    through :func:`~.inputs.floats` as the rows' and the named inputs' values are (a bool,
    date, bytes or structured column was read as numbers here, a complex one with NumPy's
    warning); a float column is kept as it is, not copied. A mapping gives the columns by
    name, as :func:`as_columns` reads them."""
    if type(Xt) is not np.ndarray or Xt.dtype.names:   # (a mapping's keys were read as the
        named = named_columns(Xt)                        # columns, a DataFrame's by position)
        if named is not None:
            columns = as_columns(compiled, named)
            return columns, columns
    if isinstance(Xt, np.ndarray) or not hasattr(Xt, "__len__"):
        Xt = floats(Xt, "the input columns", many=True)
    if isinstance(Xt, np.ndarray) and Xt.ndim == 0:
        raise InputError(f"expected {len(compiled.inputs)} input columns "
                         f"({', '.join(compiled.inputs)}), not one number")
    if len(Xt) != len(compiled.inputs):
        raise InputError(f"expected {len(compiled.inputs)} input columns "
                         f"({', '.join(compiled.inputs)}), not {len(Xt)}")
    return Xt, [floats(x, f"input `{name}`") for x, name in zip(Xt, compiled.inputs)]


#: Samples per block of :func:`_grid_columns` when the batch is spread over threads. Every
#: NumPy call releases the GIL and takes it back, so threads that make many short calls wait
#: on each other: wide blocks make fewer (on 2 cores, 1,536-sample blocks in two threads ran
#: slower than in one).
GRID_BLOCK = 8192

#: Bytes of a block's buffers when one thread evaluates the batch: three quarters of a core's
#: L2 cache (2 MiB on the Xeon measured), so that a block stays there. For the paper's 27
#: rules that is 1,536 samples, which ran 1.3x the 8,192 of :data:`GRID_BLOCK` in one thread
#: (1,024 and 2,048: 1.2x; ``benchmarks/bench_core.py``).
CACHE_BYTES = 1_572_864


class _GridBlock:
    """The views of one block of :func:`_grid_columns` (``w`` samples) that its NumPy calls
    take, into the buffers of ``like`` (a block at least as wide: the batch's last, shorter
    block uses the full blocks' memory) or new ones. Made once per call for the full blocks.
    """

    def __init__(self, g: GridBatch, w: int, like: _GridBlock | None = None) -> None:
        k, t = g.B.shape[:2]
        R, nw = g.Kw.shape[:2]
        if like is None:
            # rises and falls (a row apart: see _GAP), then the memberships; every rule's
            # terms of the sums [R, sums, w], rows a cache line apart: the weighted sums'
            # products, then the sum of all-1 weights (the denominator), whose terms are the
            # DOFs themselves, so the grid writes them there (without one, a column more)
            self.buffers = (np.empty((k, w)), np.empty((2, k * t + 1, w)), np.zeros(w),
                            [np.empty(g.shape[:d + 1] + (w,)) for d in range(1, len(g.axes) - 1)],
                            np.empty((R, nw + 1, w + _GAP)))
        else:
            self.buffers = like.buffers
        X, RF, zeros, inner, P = self.buffers
        self.X = X[:, :w]                      # the block's (clamped) inputs
        self.Xb = self.X[:, None, :]
        self.RF = RF[:, :k * t, :w]
        self.rise, self.fall = (RF[i, :k * t, :w].reshape(k, t, w) for i in (0, 1))
        self.zeros = zeros[:w]                 # the clips at 0 and 1: one row, broadcast
        self.M = self.rise
        self.axes = [self.M[v, :size] for v, size in g.axes]
        nsum = nw + g.ones
        P = P[:, :, :w]
        self.D = D = P[:, nw]
        # the grid's minima, outermost axis first; the last fills the DOFs
        self.grid = []
        acc = self.axes[0]
        for depth, axis in enumerate(self.axes[1:], start=1):
            shape = g.shape[:depth + 1] + (w,)
            target = D.reshape(shape) if depth == len(self.axes) - 1 else inner[depth - 1][..., :w]
            self.grid.append((acc[..., None, :], axis, target))
            acc = target
        assert np.may_share_memory(self.grid[-1][2], D) and np.may_share_memory(self.M, RF)
        self.products = (D[:, None, :], g.Kw, P[:, :nw])
        # tree_sum() over the rules, on every sum at once: the first step pairs rule i with
        # i + half, the later ones halve what is left
        self.P = P = P[:, :nsum]
        self.tree = []
        size = R
        while size > 1:
            h = (size + 1) // 2
            self.tree.append((P[:size - h], P[h:size]))
            size = h
        sums = self.P[0]
        self.nums = [sums[j] for j in g.num]
        self.dens = [sums[j] for j in g.den]
        self.shared = len(set(g.den)) == 1 and list(g.num) == list(range(len(g.num)))
        self.all_nums = sums[:len(g.num)]


def _grid_columns(compiled: CompiledRuleBase, g: GridBatch, columns: list, out: np.ndarray) -> bool:
    """:func:`evaluate_columns` of a grid behavior: the outputs into ``out[m, n]``; True
    when some sample may have no rule fired (NaN in ``out``).

    The operations of :func:`memberships`, :func:`_apply_grid`, :func:`rule_dof` and
    :func:`weighted_average` (so the same bits), over the grid's terms only, in about twenty
    NumPy calls per block on buffers each thread makes once (:func:`~.threads.map_blocks`):
    no temporary arrays, no gathers, the sums'
    later steps on all sums at once. Inputs inside their universes (checked once over the
    batch) are not clamped block by block; that skips only the clamp's ``+ 0.0``, which
    turns an input of -0.0 into 0.0, and a membership is the same for both (either zero,
    through ``x - b`` or ``c - x`` and the slope, reaches ``1 + min(...)`` only as a zero
    that the ``+ 1`` absorbs). NumPy's ufunc buffer is set to the narrowest block's width:
    with the default (8,192 elements), a broadcast operand over a shorter row is copied through
    the buffer, at twice the time of the call (a batch under 8,192 samples, a short last block).
    """
    plan = compiled.plan
    n = out.shape[1]
    if not n:
        return False
    lo, hi = plan.bounds
    inside = all(lo[v] <= x.min() and x.max() <= hi[v]      # NaN fails both
                 for v, x in enumerate(columns))
    count = -(-n // _grid_width(g, n))
    width = -(-n // count)                     # blocks of one width, the last no wider
    last = n - (count - 1) * width

    def blocks(ranges: Blocks) -> bool:
        full = _GridBlock(g, width)            # this thread's buffers
        old = np.setbufsize(max(16, last - last % 16))
        try:
            unfired = False
            for start, end in ranges:
                b = full if end - start == width else _GridBlock(g, end - start, full)
                unfired |= _grid_block(compiled, g, b, columns, inside, out, start, end)
            return unfired
        finally:
            np.setbufsize(old)
    unfired = any(map_blocks(blocks, n, width))
    _no_negative_zero(out)
    return unfired


def _grid_width(g: GridBatch, n: int) -> int:
    """The widest block of :func:`_grid_columns` for ``n`` samples: :data:`GRID_BLOCK` when
    they are spread over threads, else as many samples as :data:`CACHE_BYTES` holds of the
    buffers of :class:`_GridBlock` (a multiple of 256, at least 512 and at most
    :data:`GRID_BLOCK`)."""
    if n > GRID_BLOCK and thread_count() > 1:
        return GRID_BLOCK
    k, t = g.B.shape[:2]
    R, nw = g.Kw.shape[:2]
    inner = sum(math.prod(g.shape[:d + 1]) for d in range(1, len(g.axes) - 1))
    per_sample = 8 * (k + 2 * (k * t + 1) + 1 + inner + R * (nw + 1))
    return min(GRID_BLOCK, max(512, CACHE_BYTES // per_sample // 256 * 256))


def _grid_block(compiled: CompiledRuleBase, g: GridBatch, b: _GridBlock, columns: list, inside: bool,
                out: np.ndarray, start: int, end: int) -> bool:
    """One block of :func:`_grid_columns`: ``out[:, start:end]``, True where a sample may have
    no rule fired."""
    # memberships: the linear kernel (memberships())
    M = b.M
    if inside:
        for v, x in enumerate(columns):
            xv = x[start:end]
            np.subtract(xv, g.B[v], out=b.rise[v])
            np.subtract(g.C[v], xv, out=b.fall[v])
    else:
        for v, x in enumerate(columns):
            b.X[v] = x[start:end]
        Xc, _ = _clamp_columns(compiled, b.X, start, out.shape[1])
        b.X[...] = Xc
        np.subtract(b.Xb, g.B, out=b.rise)
        np.subtract(g.C, b.Xb, out=b.fall)
    if g.overflow:
        with np.errstate(over="ignore"):
            b.RF *= g.S
    else:
        b.RF *= g.S
    np.minimum(M, b.fall, out=M)
    if g.plateaus:
        np.minimum(M, b.zeros, out=M)
    M += 1.0
    np.maximum(M, b.zeros, out=M)
    for acc, axis, target in b.grid:            # _apply_grid()
        np.minimum(acc, axis, out=target)
    if g.weight is not None:                    # rule_dof()
        b.D *= g.weight
    np.multiply(*b.products)                    # _constant_sums()
    for x, y in b.tree:
        np.add(x, y, out=x)
    # weighted_average()
    part = out[:, start:end]
    if g.weighted_sum:
        for j, num in enumerate(b.nums):
            part[j] = num
        unset = False
        for j in compiled.summed_defaults:        # _unset_sums()
            den = b.dens[j]
            if den.min() <= 0:
                part[j][den <= 0] = np.nan
                unset = True
        return unset
    if b.shared:
        den = b.dens[0]
        if den.min() > 0:
            np.divide(b.all_nums, den, out=part)
            return False
    unfired = False
    for j, (num, den) in enumerate(zip(b.nums, b.dens)):
        if den.min() > 0:
            np.divide(num, den, out=part[j])
        else:
            part[j] = np.nan
            np.divide(num, den, out=part[j], where=den > 0)
            unfired = True
    return unfired


_FLOAT = {float}


def evaluate_one(compiled: CompiledRuleBase, values: list[float] | Mapping[str, float],
                 strict: bool = True) -> tuple[float, ...]:
    """The outputs for one sample (inputs in :attr:`CompiledRuleBase.inputs` order): the same
    bits as its row in :func:`evaluate`, through the network's scalar form where it has one
    (:mod:`mitos_cli.engine.scalar`, a few microseconds instead of some forty NumPy calls).
    Values other than floats are read as :func:`~.inputs.floats` reads them (the scalar form
    would take ``True`` as 1). A mapping gives the values by name (``{"road": 78, ...}``),
    checked as :func:`as_batch` checks names."""
    # a mapping or a pandas Series gives the values by name (a dict was "the inputs must be
    # numbers, not `{...}`", a Series read in its own order); a list, the usual call, is not
    # asked
    named = None if type(values) is list else named_columns(values)
    row: Any = values if named is None else _named_row(compiled, named)   # checked just below
    if not _FLOAT.issuperset(map(type, row)):
        row = floats(row, "the inputs", many=True).tolist()
    return evaluate_floats(compiled, row, strict)


def _named_row(compiled: CompiledRuleBase, named: Mapping[str, object]) -> list:
    _check_names(compiled, named)
    return [named[name] for name in compiled.inputs]


def evaluate_floats(compiled: CompiledRuleBase, values: list[float],
                    strict: bool = True) -> tuple[float, ...]:
    """:func:`evaluate_one` of values already Python floats (the caller has made them so)."""
    fn = compiled.scalar                # _evaluate_one's outputs, without the clamped inputs
    if fn is not None and len(values) == len(compiled.inputs):
        outputs = fn(*values)
        # a NaN output (no rule fired: the default, or an error) makes the sum NaN; so do
        # +inf and -inf together, which the NumPy path then answers as well
        if outputs is not None and (total := sum(outputs)) == total:
            return outputs
    return tuple(evaluate(compiled, np.array([values], dtype=float), detail=False,
                          strict=strict).outputs[0].tolist())


def _evaluate_one(compiled: CompiledRuleBase,
                  values: list[float]) -> tuple[list[float], tuple[float, ...]] | None:
    """(clamped inputs, outputs) by the scalar form, or ``None`` where the NumPy path must
    answer: no scalar form, a NaN input, or an output no rule set (defaults and errors)."""
    fn = compiled.scalar
    if fn is None or len(values) != len(compiled.inputs):
        return None
    outputs = fn(*values)
    if outputs is None or (total := sum(outputs)) != total:      # NaN: as evaluate_floats
        return None
    if compiled.operators.inputs == "as_given":
        return [x + 0.0 for x in values], outputs
    lo, hi = compiled.plan.bounds
    clamped = [(a if x < a else b if x > b else x) + 0.0 for x, a, b in zip(values, lo, hi)]
    return clamped, outputs


def infer(compiled: CompiledRuleBase, dof: np.ndarray,
          Xt: np.ndarray | None = None) -> np.ndarray:
    """Output layer: DOFs ``[R, b]`` -> outputs ``[m, b]`` (NaN where no rule fired).

    ``Xt[k, b]`` (the block's clamped inputs) is needed only by linear consequents.
    """
    if compiled.operators.inference == "mamdani":
        from .mamdani import mamdani_outputs

        return mamdani_outputs(compiled, dof)
    if compiled.operators.inference == "tsukamoto":
        from .tsukamoto import tsukamoto_outputs

        return tsukamoto_outputs(compiled, dof)
    if compiled.cons_linear is not None and Xt is None:
        raise ValueError("linear consequents need the inputs: infer(compiled, dof, Xt)")
    return _no_negative_zero(weighted_average(compiled, dof, Xt))


def _no_negative_zero(out: np.ndarray) -> np.ndarray:
    """``out`` with -0.0 made 0.0 (``x + 0.0``; every other value, NaN too, keeps its bits): a
    weighted sum of rules that did not fire over negative values (``0 * -10``), or a crisp
    ``-0``, was printed ``-0.0``."""
    return np.add(out, 0.0, out=out)


def declares_nan(compiled: CompiledRuleBase, output: str) -> bool:
    """Whether ``output`` declares NaN as its value when no rule fires (fuzzylite's
    ``default: nan``, FCL's ``DEFAULT := nan``, a term set's ``default: .nan``)."""
    v = compiled.variables.get(output)
    return v is not None and v.default is not None and v.default != v.default


def fill_defaults(compiled: CompiledRuleBase, out: np.ndarray, X: np.ndarray,
                  strict: bool) -> np.ndarray:
    """Where no rule fired (NaN), use the output's default or explain how to declare one."""
    empty = np.isnan(out)
    if not empty.any():
        return out
    for j, name in enumerate(compiled.outputs):
        col = empty[:, j]
        if not col.any():
            continue
        default = compiled.default[j]
        if not np.isnan(default):
            out[col, j] = default
        elif declares_nan(compiled, name):
            continue                           # the rule base asked for NaN here
        elif strict:
            row = int(np.argmax(col))
            values = ", ".join(f"{k}={exact(X[row, i])}" for i, k in enumerate(compiled.inputs))
            many = f" ({int(col.sum())} of {len(col)} samples)" if len(col) > 1 else ""
            declare = (f"declare a default for `{name}` (`default: VALUE` on the variable in a "
                       f"YAML term set, `DEFAULT := VALUE` in FCL, `default: VALUE` in FLL) to "
                       f"define the output when no rule fires")
            fired = _fired_setting(compiled, j, X[row])
            if fired:
                why, fix = _why_empty(compiled, j)
                raise EmptyOutputError(
                    f"the rules that set `{name}` fire ({fired}) but give it no value "
                    f"for {values}{many}: {why}", hint=f"{fix}{declare}")
            raise NoRuleFiredError(f"no rule sets `{name}` for {values}{many}",
                                   hint=f"{declare}, or add rules that cover these inputs")
    return out


def _fired_setting(compiled: CompiledRuleBase, j: int, x: np.ndarray) -> str:
    """The rules setting output ``j`` that fire at the (clamped) inputs ``x``, with their
    DOFs (the first three), or "" where none does: asked only on the way to an error."""
    dof = rule_dofs(compiled, x[None])[0]
    fired = [r for r in np.flatnonzero(compiled.cons_mask[:, j]) if dof[r] > 0]
    told = ", ".join(f"{compiled.labels[r]} at DOF {dof[r]:.2g}" for r in fired[:3])
    return told + (" ..." if len(fired) > 3 else "")


def _why_empty(compiled: CompiledRuleBase, j: int) -> tuple[str, str]:
    """Why output ``j``'s fired rules left it no value, and the start of a hint."""
    if compiled.operators.inference == "mamdani":
        points = len(compiled.mamdani[j].grid)
        return (f"the sets they conclude, implied at those DOFs, are 0 at all {points} points "
                f"`{compiled.outputs[j]}` is sampled at, so there is nothing to defuzzify",
                "widen the terms they conclude or raise `resolution` (`mitos check` names the "
                "terms: undersampled-term), or ")
    if compiled.operators.inference == "tsukamoto":
        return ("the terms they conclude, inverted at those DOFs, lie at +inf and -inf (a "
                "sigmoid reaches 1 only at infinity), and their weighted average has no value",
                "conclude terms that reach 1 within the range (a ramp, an S or Z shape), or ")
    return ("their weights in it are 0 (a hedged consequent of a DOF so small that it "
            "underflows)", "")
