"""The compiled rule base described as the network of fuzzy neurons of Sec. 3 (``mitos eval
--network``): its layers, their sizes, fan-in and operators."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..fuzzy import hedges as hedge_mod
from ..words import plural
from .compile import CompiledRuleBase

if TYPE_CHECKING:
    from ..lang.terms import Term

INFERENCE_TEXT = {
    "weighted_average": "weighted average of the rules' consequents, sum(dof y) / sum(dof) "
                        "(eqs. 18-19)",
    "weighted_sum": "weighted sum of the rules' consequents, sum(dof y)",
    "tsukamoto": "Tsukamoto: each term inverted at its summed degree w, sum(w z) / sum(w)",
}


def _fmt(x: float) -> str:
    return f"{x:g}"


def _term_text(term: Term) -> str:
    if term.shape == "singleton":
        return f"{term.name} = {_fmt(term.params[0])}"
    if term.shape == "linear":
        return f"{term.name} = linear"
    return f"{term.name} {term.shape_name}({term.params_text(_fmt)})"


def _fan_in(children: np.ndarray) -> str:
    counts = (children >= 2).sum(axis=1)          # columns 0 and 1 only pad
    lo, hi = int(counts.min()), int(counts.max())
    return plural(lo, "input") if lo == hi else f"{lo}-{hi} inputs"


def _group_text(op: str, compiled: CompiledRuleBase) -> str:
    ops = compiled.operators
    if op == "and":
        return f"AND neurons, T-norm {ops.and_} ({ops.tnorm.formula})"
    if op == "or":
        return f"OR neurons, S-norm {ops.or_} ({ops.snorm.formula})"
    if op == "not":
        return "NOT neurons, inhibitory input 1 - x (eqs. 8-9)"
    if op.startswith("hedge:"):
        names = op[6:].split()
        formulas = ", ".join(f"{h} {hedge_mod.HEDGES[h].formula}" for h in names)
        return f"hedge neurons, activation {' '.join(names)} ({formulas}; eqs. 10-11)"
    return f"{op} neurons"


def describe_network(compiled: CompiledRuleBase) -> str:
    """The layers of ``compiled`` as text, input side first."""
    c = compiled
    ops = c.operators
    lines = [f"behavior {c.behavior}: {plural(len(c.inputs), 'input')}, "
             f"{plural(c.n_rules, 'rule')}, "
             f"{plural(len(c.outputs), 'output')}, {plural(c.n_columns - 2, 'neuron')}",
             f"operators: {c.describe_operators()}", ""]
    table: list[tuple[str, str, str]] = []

    def row(name: str, size: object, what: str) -> None:
        table.append((name, str(size), what))

    row("layer 0", len(c.inputs), "inputs: " + ", ".join(
        f"{k} [{_fmt(lo)}, {_fmt(hi)}]" for k, (lo, hi) in zip(c.inputs, c.universe)))
    row("layer 1", c.n_terms, "membership neurons, one per input term (eq. 15 and other "
        "shapes)")
    for k in c.inputs:
        var = c.variables[k]
        row("", "", f"  {k}: " + ", ".join(_term_text(t) for t in var.terms))
    for depth, level in enumerate(c.levels, start=2):
        for group in level:
            row(f"layer {depth}", len(group.out),
                f"{_group_text(group.op, c)}, {_fan_in(group.children)}")
    extra = []
    weighted = int((c.weight != 1.0).sum())
    if weighted:
        extra.append(f"{weighted} weighted (`with w` multiplies the DOF)")
    contexts = int((c.context != 1).any(axis=1).sum()) if c.context.size else 0
    if contexts:
        extra.append(f"{contexts} under `use ... when` (DOF times the condition)")
    row("rules", c.n_rules, "DOF of each rule = the neuron of its antecedent"
        + (": " + "; ".join(extra) if extra else ""))
    if ops.inference == "mamdani":
        row(f"layer {len(c.levels) + 2}", len(c.outputs),
            f"output neurons, Mamdani: implication {ops.implication}, aggregation {ops.aggregation}, "
            f"defuzzify {ops.defuzzify}"
            + ("" if len(c.own_resolutions) == len(c.outputs) else
               f" on {plural(ops.resolution, 'sample')}"
               + (" (or its own)" if c.own_resolutions else "")))
        for table_j in c.mamdani:
            own = (f", on its own {plural(len(table_j.grid), 'sample')}"
                   if table_j.name in c.own_resolutions else "")
            row("", "", f"  {table_j.name}: {plural(len(table_j.rules), 'rule')} -> "
                f"{plural(len(table_j.labels), 'consequent set')} ({', '.join(table_j.labels)})"
                + own)
    else:
        kind = "Takagi-Sugeno, " if c.cons_linear is not None else ""
        joined = (f"; the rules of one value first joined by {ops.accumulation} "
                  f"(accumulation)" if ops.accumulated else "")
        row(f"layer {len(c.levels) + 2}", len(c.outputs),
            "output neurons, " + kind + INFERENCE_TEXT[ops.inference] + joined)
        for j, name in enumerate(c.outputs):
            n = int(c.cons_mask[:, j].sum())
            linear = 0 if c.cons_linear is None else int(
                (c.cons_linear[:, j, :-1] != 0).any(axis=1).sum())
            what = f"  {name}: {plural(n, 'rule')}"
            if c.accumulated is not None:
                what += f" of {plural(len(c.accumulated[j].first), 'value')}"
            if linear:
                what += f", {linear} with linear consequents y = a . x + c"
            default = c.default[j]
            what += "" if np.isnan(default) else f", default {_fmt(default)}"
            row("", "", what)
    w0 = max(len(a) for a, _, _ in table)
    w1 = max(len(b) for _, b, _ in table)
    for a, b, what in table:
        lines.append(f"  {a.ljust(w0)}  {b.rjust(w1)}  {what}".rstrip())
    return "\n".join(lines)
