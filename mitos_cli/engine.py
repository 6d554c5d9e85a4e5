"""Evaluating a compiled rule base on a batch of inputs: a pure function of arrays.

``evaluate(compiled, X)`` takes ``X[n, k]`` (rows are samples, columns the compiled inputs) and
returns memberships ``[n, T]``, DOFs ``[n, R]`` and outputs ``[n, m]``. All work is row-wise,
so a single evaluation is exactly row 0 of a batch of one (bit for bit): sums run along the
contiguous last axis, which NumPy reduces the same way for one row or a million.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import hedges as hedge_mod
from . import norms
from .compile import ONE, ZERO, CompiledRuleBase
from .errors import InputError, NoRuleFiredError
from .shapes import SHAPES


@dataclass(frozen=True)
class Result:
    """What one batch evaluation computed (rows are samples)."""

    compiled: CompiledRuleBase
    inputs: np.ndarray        # [n, k] after clamping to the universes
    memberships: np.ndarray   # [n, T]
    dof: np.ndarray           # [n, R] degree of fulfilment of each rule (after weights)
    outputs: np.ndarray       # [n, m]
    clamped: np.ndarray       # [k] how many samples of each input were clamped
    values: np.ndarray | None = None  # [n, columns] every neuron's value (kept on request)

    def output(self, name: str) -> np.ndarray:
        return self.outputs[:, self.compiled.outputs.index(name)]


def as_batch(compiled: CompiledRuleBase, columns: dict[str, object]) -> np.ndarray:
    """Input arrays by variable name -> ``X[n, k]`` in the compiled column order.

    Every compiled input must be given; scalars broadcast against arrays. Names that the
    behavior does not use are refused with a "did you mean".
    """
    from .errors import unknown

    for name in columns:
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
    arrays = []
    for name in compiled.inputs:
        value = columns[name]
        try:
            arr = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"input `{name}` must be a number, not `{value}`") from None
        arrays.append(arr)
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrays))
    except ValueError:
        raise InputError("input arrays have different lengths: " + ", ".join(
            f"{n} {a.shape}" for n, a in zip(compiled.inputs, arrays))) from None
    if len(shape) > 1:
        raise InputError(f"inputs must be numbers or 1-D arrays, not of shape {shape}")
    n = shape[0] if shape else 1
    X = np.empty((n, len(arrays)))
    for j, arr in enumerate(arrays):
        X[:, j] = np.broadcast_to(arr, shape).reshape(-1) if shape else arr
    return X


def check_inputs(compiled: CompiledRuleBase, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Refuse NaN, clamp to each universe; return the clamped copy and clamp counts."""
    X = np.array(X, dtype=float, copy=True, ndmin=2)
    if X.ndim != 2 or X.shape[1] != len(compiled.inputs):
        raise InputError(f"expected inputs of shape [n, {len(compiled.inputs)}] "
                         f"({', '.join(compiled.inputs)}), not {X.shape}")
    bad = np.isnan(X)
    if bad.any():
        row, col = map(int, np.argwhere(bad)[0])
        where = f" (sample {row + 1})" if X.shape[0] > 1 else ""
        raise InputError(f"input `{compiled.inputs[col]}` is not a number (NaN){where}",
                         hint="give every input a finite number")
    lo, hi = compiled.universe[:, 0], compiled.universe[:, 1]
    clamped = ((X < lo) | (X > hi)).sum(axis=0)
    if clamped.any():
        np.clip(X, lo, hi, out=X)
    return X, clamped


def memberships(compiled: CompiledRuleBase, X: np.ndarray, out: np.ndarray) -> None:
    """Membership layer: fill ``out[:, 2:2+T]`` with every input term's membership."""
    T = compiled.n_terms
    mu = out[:, 2:2 + T]
    if compiled.linear.any():
        b, s1, c, s2 = compiled.kernel
        x = X[:, compiled.term_var]
        rise = (x - b) * s1
        fall = np.subtract(c, x, out=x)
        fall *= s2
        np.minimum(rise, fall, out=rise)
        rise += 1.0
        np.clip(rise, 0.0, 1.0, out=rise)
        mu[:] = rise
    for g in compiled.shape_groups:
        shape = SHAPES[g.shape]
        x = X[:, g.inputs]
        out[:, g.cols] = shape.fn(x, *(g.params[:, i] for i in range(g.params.shape[1])))


def _apply_group(group, V: np.ndarray, tnorm: norms.Norm, snorm: norms.Norm) -> None:
    op = group.op
    ch = group.children
    if op == "not":
        V[:, group.out] = 1.0 - V[:, ch[:, 0]]
        return
    if op.startswith("hedge:"):
        V[:, group.out] = hedge_mod.apply(tuple(op[6:].split()), V[:, ch[:, 0]])
        return
    norm = tnorm if op == "and" else snorm
    acc = V[:, ch[:, 0]]
    for j in range(1, ch.shape[1]):     # loop over arity (a few), never over rules
        if norm.fn is np.minimum or norm.fn is np.maximum:
            norm.fn(acc, V[:, ch[:, j]], out=acc)
        else:
            acc = norm.fn(acc, V[:, ch[:, j]])
    V[:, group.out] = acc


def evaluate(compiled: CompiledRuleBase, X, *, keep_values: bool = False,
             strict: bool = True) -> Result:
    """Evaluate the network on ``X[n, k]``.

    With ``strict`` (the default) an output whose rules all have DOF 0 for some sample takes
    the variable's ``default``, and without one raises :class:`NoRuleFiredError`; with
    ``strict=False`` such outputs are NaN (for callers that report them themselves).
    """
    X, clamped = check_inputs(compiled, X)
    n = X.shape[0]
    V = np.empty((n, compiled.n_columns))
    V[:, ZERO] = 0.0
    V[:, ONE] = 1.0
    memberships(compiled, X, V)
    tnorm, snorm = compiled.operators.tnorm, compiled.operators.snorm
    for level in compiled.levels:
        for group in level:
            _apply_group(group, V, tnorm, snorm)
    dof = V[:, compiled.rule_col]
    if compiled.context.shape[1]:
        for j in range(compiled.context.shape[1]):   # depth of `use` nesting
            dof *= V[:, compiled.context[:, j]]
    if (compiled.weight != 1.0).any():
        dof *= compiled.weight
    outputs = infer(compiled, dof, X, strict=strict)
    mu = V[:, 2:2 + compiled.n_terms]
    return Result(compiled, X, mu if keep_values else mu.copy(), dof, outputs, clamped,
                  V if keep_values else None)


def infer(compiled: CompiledRuleBase, dof: np.ndarray, X: np.ndarray, *,
          strict: bool = True) -> np.ndarray:
    """Output layer: combine the rules' DOFs into crisp outputs."""
    method = compiled.operators.inference
    if method == "mamdani":
        from .mamdani import mamdani_outputs

        out = mamdani_outputs(compiled, dof)
    else:
        out = np.empty((dof.shape[0], len(compiled.outputs)))
        for j in range(len(compiled.outputs)):          # loop over outputs (one or two)
            mask = compiled.cons_mask[:, j]
            weights = dof if mask.all() else dof * mask
            num = (weights * compiled.cons_value[:, j]).sum(axis=1)
            if method == "weighted_sum":
                out[:, j] = num
                continue
            den = weights.sum(axis=1)
            with np.errstate(invalid="ignore", divide="ignore"):
                out[:, j] = np.where(den > 0, num / den, np.nan)
    return fill_defaults(compiled, out, dof, X, strict)


def fill_defaults(compiled: CompiledRuleBase, out: np.ndarray, dof: np.ndarray,
                  X: np.ndarray, strict: bool) -> np.ndarray:
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
        elif strict:
            row = int(np.argmax(col))
            values = ", ".join(f"{k}={X[row, i]:g}" for i, k in enumerate(compiled.inputs))
            raise NoRuleFiredError(
                f"no rule sets `{name}` for {values}" +
                (f" ({int(col.sum())} of {len(col)} samples)" if len(col) > 1 else ""),
                hint=f"add `default: VALUE` to the `{name}` variable in the term set to define "
                     f"the output when no rule fires, or add rules that cover these inputs")
    return out
