"""One sample without NumPy: the compiled network as straight-line Python, for latency.

A NumPy call costs about a microsecond however small its array, and one evaluation of the
network is some forty of them. A robot's control loop (and the simulator, and ``teach``)
evaluates one sample at a time, so for that case :func:`scalar_function` writes the network
out as a Python function of floats: every neuron one line, in the order the engine computes
them, with exactly the engine's operations in exactly its order. IEEE 754 makes ``+ - * /``,
``sqrt``, ``min`` and ``max`` of doubles give the same bits in Python as in NumPy, so the
function returns the same bits as the sample's row in a batch (property-tested).

Operations outside that set (the non-linear membership shapes, which call ``exp`` and ``pow``,
whose NumPy implementations may differ from the C library's in the last bit), Mamdani
inference, hedged consequents and an ``accumulation`` S-norm have no scalar form:
:func:`scalar_function` returns ``None`` and the engine keeps its NumPy path for them.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from ..fuzzy.hedges import HEDGES as HEDGE_REGISTRY
from ..fuzzy.norms import SNORMS, TNORMS

if TYPE_CHECKING:
    from ..lang.operators import Operators
    from .compile import CompiledRuleBase, Grid, NodeGroup

#: Above this many neurons, writing and compiling the function costs more than it saves.
MAX_COLUMNS = 4000

ScalarFn = Callable[..., "tuple[float, ...] | None"]

# The scalar forms are the registries' (fuzzy/norms.py, fuzzy/hedges.py): each norm as Python
# statements on floats ``a`` and ``b`` leaving ``r``, each hedge on ``x`` leaving ``x``, mirroring
# the NumPy formulas operation by operation.
NORMS: dict[str, str] = {n.name: n.scalar for n in (*TNORMS.values(), *SNORMS.values())}
HEDGES: dict[str, str] = {h.name: h.scalar for h in HEDGE_REGISTRY.values() if h.scalar}


class _Unsupported(Exception):
    """The network uses an operation without an exact scalar form."""


def scalar_function(c: CompiledRuleBase) -> ScalarFn | None:
    """``f(x_1, ..., x_k)`` -> the outputs (NaN where no rule fired), or ``None`` for a NaN
    input; ``None`` instead of a function when the network has no exact scalar form."""
    try:
        source = _source(c)
    except _Unsupported:
        return None
    namespace: dict = {"sqrt": math.sqrt, "nan": math.nan, "inf": math.inf}
    exec(compile(source, f"<mitos scalar network {c.behavior}>", "exec"), namespace)
    fn = namespace["network"]
    fn.source = source
    return fn


def _source(c: CompiledRuleBase) -> str:
    ops = c.operators
    if (c.shape_groups or ops.inference in ("mamdani", "tsukamoto") or c.n_columns > MAX_COLUMNS
            or c.hedged_outputs or ops.accumulated or ops.and_ not in NORMS
            or ops.or_ not in NORMS):
        raise _Unsupported
    plan = c.plan
    k = len(c.inputs)
    args = [f"x{i}" for i in range(k)]
    lines = [f"def network({', '.join(args)}):"]
    emit = lines.append
    # inputs: NaN refused (the caller's NumPy path explains it), then clamped like np.maximum
    # followed by np.minimum
    emit(f"    if {' or '.join(f'{x} != {x}' for x in args)}:")
    emit("        return None")
    for i, x in enumerate(args):
        if ops.inputs == "as_given":      # not clamped: infinite ones go to the NumPy path
            emit(f"    if {x} - {x} != 0.0:")
            emit("        return None")
            emit(f"    {x} = {x} + 0.0")
            continue
        lo, hi = float(plan.lo[i]), float(plan.hi[i])
        emit(f"    {x} = {lo!r} if {x} < {lo!r} else {x}")
        emit(f"    {x} = ({hi!r} if {x} > {hi!r} else {x}) + 0.0")   # -0.0 -> 0.0, as the engine
    emit("    v0 = 0.0")
    emit("    v1 = 1.0")
    b, s1, cc, s2 = (col[:, 0].tolist() for col in plan.kernel)
    for j, row in enumerate(plan.linear_rows.tolist()):
        x = args[int(plan.term_var[j])]
        emit(f"    r = ({x} - {b[j]!r}) * {s1[j]!r}")
        emit(f"    f = ({cc[j]!r} - {x}) * {s2[j]!r}")
        emit("    r = r if r <= f else f")
        if plan.plateaus:
            emit("    r = r if r <= 0.0 else 0.0")
        emit("    r = r + 1.0")
        emit(f"    v{2 + row} = r if r >= 0.0 else 0.0")
    for i, level in enumerate(c.levels):
        for j, group in enumerate(level):
            grid = plan.grids.get((i, j))
            if grid is not None:
                _grid(grid, emit)
            else:
                _group(group, ops, emit)
    _outputs(c, emit)
    return "\n".join(lines) + "\n"


def _statements(text: str, emit: Callable[[str], None], **names: str) -> None:
    """Emit a statement template with its operands bound: ``a``/``b``/``x`` become columns."""
    prefix = "".join(f"{k} = {v}\n" for k, v in names.items())
    for line in (prefix + text).splitlines():
        emit("    " + line)


def _grid(grid: Grid, emit: Callable[[str], None]) -> None:
    """Every combination of the axes' memberships, folded with ``min`` outermost first (the
    engine's broadcast order), in the group's mixed-radix column order."""
    col = grid.out.start
    for combo in itertools.product(*(a.tolist() for a in grid.axes)):
        acc = f"v{combo[0]}"
        for nxt in combo[1:]:
            emit(f"    a = {acc}")
            emit(f"    b = v{nxt}")
            emit("    r = a if a <= b else b")
            acc = "r"
        emit(f"    v{col} = {acc}")
        col += 1


def _group(group: NodeGroup, ops: Operators, emit: Callable[[str], None]) -> None:
    op = group.op
    children = group.children.tolist()
    for out, ch in zip(group.out.tolist(), children):
        if op == "not":
            emit(f"    v{out} = 1.0 - v{ch[0]}")
        elif op.startswith("hedge:"):
            emit(f"    x = v{ch[0]}")
            for name in reversed(op[6:].split()):
                if name not in HEDGES:
                    raise _Unsupported
                _statements(HEDGES[name], emit)
            emit(f"    v{out} = x")
        else:                                   # a left fold over the padded children
            template = NORMS[ops.and_ if op == "and" else ops.or_]
            acc = f"v{ch[0]}"
            for nxt in ch[1:]:
                _statements(template, emit, a=acc, b=f"v{nxt}")
                acc = "r"
            emit(f"    v{out} = {acc}")


def _outputs(c: CompiledRuleBase, emit: Callable[[str], None]) -> None:
    """DOFs (contexts, then weights, as :func:`mitos_cli.engine.evaluation.rule_dof`) and the weighted
    sums by the engine's pairwise tree (:func:`mitos_cli.engine.evaluation.tree_sum`)."""
    plan = c.plan
    R = c.n_rules
    for r in range(R):
        emit(f"    d{r} = v{int(c.rule_col[r])}")
    for ctx in plan.contexts:
        for r in range(R):
            emit(f"    d{r} = d{r} * v{int(ctx[r])}")
    if plan.weight is not None:
        for r in range(R):
            emit(f"    d{r} = d{r} * {float(plan.weight[r, 0])!r}")
    m = len(c.outputs)
    K = plan.sums[:, :, 0].T                  # [k, R]
    linear = c.cons_linear
    used = [] if linear is None else [i for i in range(linear.shape[2] - 1)
                                      if linear[:, :, i].any()]
    sums = []
    for row in range(K.shape[0]):
        terms = []
        for r in range(R):
            if linear is not None and row < m:
                y = f"{float(linear[r, row, -1])!r}"
                for i in used:
                    y = f"({y} + {float(linear[r, row, i])!r} * x{i})"
                terms.append(f"(d{r} * {y})")
            else:
                terms.append(f"(d{r} * {float(K[row, r])!r})")
        size = len(terms)
        while size > 1:
            half = (size + 1) // 2
            for i in range(size - half):
                terms[i] = f"({terms[i]} + {terms[i + half]})"
            size = half
        emit(f"    s{row} = {terms[0] if terms else '0.0'}")
        sums.append(f"s{row}")
    if c.operators.inference == "weighted_sum":          # + 0.0: no -0.0, as infer() gives
        # NaN where an output with a default has no rule firing (the default then applies)
        results = [f"({sums[j]} + 0.0 if {sums[int(c.den_row[j])]} > 0.0 else nan)"
                   if j in c.summed_defaults else f"({sums[j]} + 0.0)" for j in range(m)]
    else:
        results = [f"({sums[j]} / {sums[int(c.den_row[j])]} + 0.0 if {sums[int(c.den_row[j])]} "
                   f"> 0.0 else nan)" for j in range(m)]
    emit(f"    return ({', '.join(results)},)")


__all__ = ["scalar_function", "MAX_COLUMNS"]
