"""Tsukamoto inference: each rule's monotonic consequent term, inverted at its degree.

fuzzylite's ``WeightedAverage Tsukamoto``: per output, the degrees of the rules concluding one
term are summed into that term's activation ``w`` (fuzzylite's aggregation ``none``), the term
is inverted there, ``z = mu^-1(w)`` (:data:`mitos_cli.fuzzy.shapes.TSUKAMOTO`), and the output
is ``sum(w z) / sum(w)`` over its terms (NaN where no rule fired). A term that did not fire
(``w = 0``) adds nothing; where a term never reaches ``w`` (a sigmoid at ``w = 1``) its inverse
is infinite and so is the output, as in fuzzylite; where rules fire fully on a term
reaching 1 at +inf and one reaching it at -inf, the output has no value (NaN, as
``inf - inf`` in fuzzylite; MITOS gives the declared default there, as where no rule fires,
and says so). A consequent's hedges hedge its rule's
degree, as in weighted-average inference. Loops run over outputs and their terms (a few),
never over rules or samples; sums are :func:`~mitos_cli.engine.evaluation.tree_sum`'s, so a
sample gives the same bits alone or in any batch.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..fuzzy import hedges as hedge_mod
from ..fuzzy.shapes import TSUKAMOTO

if TYPE_CHECKING:
    from .compile import CompiledRuleBase


@dataclass(frozen=True, eq=False)
class TermRules:
    """One output term and the rules that conclude it, grouped by their hedges."""

    shape: str
    params: tuple[float, ...]
    groups: tuple[tuple[tuple[str, ...], np.ndarray], ...]    # (hedges, rule rows)


def build_plan(compiled: CompiledRuleBase) -> tuple[tuple[TermRules, ...], ...]:
    """Per output, its concluded terms in first-concluded order (fuzzylite's grouping)."""
    plan = []
    for j, name in enumerate(compiled.outputs):
        var = compiled.variables[name]
        rows: dict[str, dict[tuple[str, ...], list[int]]] = {}
        for r in range(compiled.n_rules):
            term = compiled.cons_term[r][j]
            if term is not None:
                rows.setdefault(term, {}).setdefault(compiled.cons_hedges[r][j], []).append(r)
        plan.append(tuple(
            TermRules(var.term(t).shape, var.term(t).params,
                      tuple((h, np.array(rs, dtype=np.intp)) for h, rs in groups.items()))
            for t, groups in rows.items()))
    return tuple(plan)


def tsukamoto_outputs(compiled: CompiledRuleBase, dof: np.ndarray) -> np.ndarray:
    """DOFs ``[R, b]`` -> outputs ``[m, b]``."""
    from .evaluation import tree_sum

    b = dof.shape[1]
    out = np.full((len(compiled.outputs), b), np.nan)
    for j, terms in enumerate(compiled.tsukamoto):
        if not terms:
            continue
        W = np.empty((len(terms), b))
        WZ = np.empty((len(terms), b))
        for t, term in enumerate(terms):
            parts = [hedge_mod.weigh(h, dof[rows]) if h else dof[rows] for h, rows in term.groups]
            w = tree_sum(np.concatenate(parts))
            with np.errstate(invalid="ignore"):
                z = TSUKAMOTO[term.shape](w, *term.params)
                WZ[t] = np.where(w > 0.0, w * z, 0.0)
            W[t] = w
        den = tree_sum(W)
        with np.errstate(invalid="ignore"):     # +inf and -inf: NaN, said where it is used
            num = tree_sum(WZ)
        with np.errstate(invalid="ignore", divide="ignore"):
            np.divide(num, den, out=out[j], where=den > 0.0)
    return out
