"""Mamdani inference: implication, aggregation by an S-norm (or the sum), defuzzification.

For each output variable the consequent sets are sampled once per compiled rule base on a grid
of ``resolution`` points (:func:`build_tables`, cached as ``CompiledRuleBase.mamdani``). For a
block of samples, each rule's DOF cuts (``min``) or scales (``product``) its consequent set, the
rules' sets are joined by the aggregation S-norm, or added (``aggregation = sum``, the unbounded
sum of MATLAB's ``AggMethod='sum'`` and jFuzzyLogic's ``ACCU : SUM``: the set may exceed 1),
and the result is defuzzified:

``centroid``   ``sum(x mu) / sum(mu)``
``bisector``   the sample where the cumulative area is closest to half the total (mean of ties)
``mom``        mean of the samples where ``mu`` is maximal (and > 0)
``som``        smallest of them
``lom``        largest of them
``matlab_*``   MATLAB's ``evalfis`` (a ``.fis`` file's): ``matlab_bisector`` the first sample
               whose running area reaches half the total; ``matlab_som`` / ``matlab_lom`` the
               maximum's sample smallest / largest in absolute value (the first of a tie)
``jfuzzylogic_bisector``  jFuzzyLogic's ``METHOD : COA`` (``DefuzzifierCenterOfArea``): two
               running sums walk in from both ends, the smaller one taking the next sample (the
               left one on a tie), the first and last samples never counted; the result is
               ``lo + step * i`` where they meet (:func:`walk_from_both_ends`)

**Grid.** The universe ``[lo, hi]`` is cut into ``resolution`` equal cells (the output's own
``resolution`` where its variable has one, as fuzzylite gives each output its defuzzifier's:
each output has a table of its own, and the batch path is the same) and sampled at their
midpoints, ``x_i = lo + (i + 1/2) (hi - lo) / resolution``: the midpoint rule of integration,
the same as fuzzylite's integral defuzzifiers with ``resolution`` divisions, so MITOS and
fuzzylite agree to rounding on the same rule base.

**Singletons** (``steering is 70``, or a term ``LS: 70``) have no area. Mamdani inference
discretises them: a singleton is a spike one cell wide at the sample nearest its value (the
midpoint of the cell holding it), with height 1 before implication. With only singletons in an
output, centroid is then the DOF-weighted average of the snapped values (for ``max``
aggregation, of the strongest rule per value): each value moves by at most half a cell,
``(hi - lo) / (2 resolution)``. (fuzzylite samples a singleton where ``x == value`` only, which
a midpoint rarely hits, and returns NaN.)

**Hedged consequents** (``then steering is very LS``) hedge the consequent set, ``very LS`` =
``mu_LS(y)^2``, as Zadeh defines it. (fuzzylite hedges the rule's activation degree instead.)

**Speed.** With ``max`` aggregation the rules that share a consequent set are first joined on
their DOFs (``max_r I(d_r, mu) = I(max_r d_r, mu)`` for a monotone implication, exactly), so
the sampled work scales with the number of distinct consequent sets, not of rules; other
S-norms and the sum reduce the ``[rules, samples, resolution]`` stack by a pairwise tree (log2
R vectorized steps, in an order fixed by R alone, as ``evaluation.tree_sum``). Samples are
processed in sub-blocks so that no intermediate array exceeds :data:`MAX_BYTES` (when one
sample's stack alone exceeds :data:`MAX_STACK_BYTES`, its rules are taken in chunks, joined by
the same S-norm). Everything is elementwise per sample or a reduction along one sample's own
row, so a single evaluation is bit for bit its row in a batch.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

import numpy as np

from ..errors import TermSetError
from ..fuzzy import hedges as hedge_mod
from ..fuzzy import norms

if TYPE_CHECKING:
    from ..lang.terms import Term
    from .compile import CompiledRuleBase

#: Ceiling on the intermediate ``[rules, samples, resolution]`` array of one sub-block. Small
#: enough to stay in cache: on the benchmark machine 1 MB ran about twice as fast as 8 MB and
#: 4x as fast as 32 MB (benchmarks/bench_norms.py, resolution 101 and 1001).
MAX_BYTES = 2 ** 20

IMPLICATIONS: dict[str, Callable[..., np.ndarray]] = {"min": np.minimum, "product": np.multiply}
IMPLICATIONS.update({name: (lambda a, b, norm=norm: norm(*np.broadcast_arrays(a, b)))
                     for name, norm in norms.TNORMS.items() if name not in IMPLICATIONS})


@dataclass(frozen=True)
class OutputTable:
    """One output's consequent sets, sampled on its grid."""

    name: str
    grid: np.ndarray          # [res] sample points (cell midpoints)
    sets: np.ndarray          # [t, res] sampled consequent sets (hedges applied)
    labels: tuple[str, ...]   # [t] "LS", "very LS", "= 70"
    rules: np.ndarray         # [R_j] rules that set this output
    set_of: np.ndarray        # [R_j] row of ``sets`` for each of those rules
    order: np.ndarray         # [R_j] those rules (positions in ``rules``) sorted by set
    starts: np.ndarray        # [t] start of each set's run in ``order`` (for reduceat)
    #: [res] each point's weight in the centroid's and bisector's sums (``sampling =
    #: trapezoid``: the two ends half); None: every point 1
    weights: np.ndarray | None = None


def grid(lo: float, hi: float, resolution: int, sampling: str = "midpoints") -> np.ndarray:
    """The midpoints of ``resolution`` equal cells of ``[lo, hi]`` (``sampling="endpoints"``:
    ``resolution`` evenly spaced points from ``lo`` to ``hi``, as MATLAB's ``evalfis``;
    ``"left"``: the cells' left ends, as jFuzzyLogic)."""
    if sampling in ("endpoints", "trapezoid"):
        return np.linspace(lo, hi, resolution)
    if sampling == "left":    # jFuzzyLogic: the cells' left ends, reached as it reaches them
        return _stepped(lo, (hi - lo) / resolution, resolution)
    return lo + (np.arange(resolution) + 0.5) * ((hi - lo) / resolution)


def _stepped(lo: float, step: float, n: int) -> np.ndarray:
    """``n`` points from ``lo`` by adding ``step`` to the one before, one at a time, as
    jFuzzyLogic's loops do (``x += step``): the rounding accumulates, so its points drift from
    ``lo + i step`` by a few units in the last place, and a term 1 only at one point (a zero-
    width triangle at 0) may be hit by one and missed by the other. ``np.add.accumulate`` adds
    in order, one element after another."""
    steps = np.full(n, step)
    steps[0] = lo
    return np.add.accumulate(steps)


def spike(lo: float, hi: float, resolution: int, value: float,
          sampling: str = "midpoints") -> np.ndarray:
    """A singleton at ``value`` as sampled set: 1 at the midpoint of the cell holding it (with
    ``endpoints`` sampling: at the nearest sample point)."""
    row = np.zeros(resolution)
    if sampling in ("endpoints", "trapezoid"):
        i = int(np.rint((value - lo) / (hi - lo) * (resolution - 1)))
    else:
        i = int(np.floor((value - lo) / ((hi - lo) / resolution)))
    row[min(max(i, 0), resolution - 1)] = 1.0
    return row


def build_tables(compiled: CompiledRuleBase) -> tuple[OutputTable, ...]:
    """Sample every consequent set the rules use, per output (done once, then cached), on the
    output's own ``resolution`` where it has one, else its behavior's."""
    sampling = compiled.operators.sampling
    tables = []
    for j, name in enumerate(compiled.outputs):
        var = compiled.variables[name]
        res = var.resolution or compiled.operators.resolution
        lo, hi = var.universe
        x = grid(lo, hi, res, sampling)
        rules = np.flatnonzero(compiled.cons_mask[:, j])
        keys: dict[tuple, int] = {}
        rows: list[np.ndarray] = []
        labels: list[str] = []
        picks: list[int] = []
        for r in rules:
            term, hedges = compiled.cons_term[r][j], compiled.cons_hedges[r][j]
            key = (term, hedges) if term is not None else ("=", float(compiled.cons_value[r, j]))
            if key not in keys:
                keys[key] = len(rows)
                if term is None:
                    rows.append(spike(lo, hi, res, cast(float, key[1]), sampling))   # ("=", value)
                    labels.append(f"= {key[1]:g}")
                else:
                    t = var.term(term)
                    mu = (spike(lo, hi, res, t.params[0], sampling) if t.shape == "singleton"
                          else np.asarray(t.membership(x), dtype=float))
                    if t.formula is not None and not np.isfinite(mu).all():
                        at = float(x[np.flatnonzero(~np.isfinite(mu))[0]])
                        raise TermSetError(f"term `{name}.{term}`: its formula "
                                           f"`{t.formula.text}` gives {mu[~np.isfinite(mu)][0]} "
                                           f"at {name} = {at:g}", span=t.span,
                                           hint="change the formula so it is defined on the "
                                                "whole universe")
                    rows.append(hedge_mod.apply(hedges, mu))
                    labels.append(" ".join(hedges + (term,)))
            picks.append(keys[key])
        set_of = np.array(picks, dtype=np.intp)
        order = np.argsort(set_of, kind="stable").astype(np.intp)
        starts = np.searchsorted(set_of[order], np.arange(len(rows))).astype(np.intp)
        sets = np.array(rows, dtype=float).reshape(len(rows), res)
        tables.append(OutputTable(name, x, sets, tuple(labels), rules, set_of, order, starts,
                                  trapezoid_weights(res) if sampling == "trapezoid" else None))
    return tuple(tables)


def trapezoid_weights(points: int) -> np.ndarray:
    """The trapezoid rule's weights on ``points`` evenly spaced points (the common step left
    out: it cancels in a centroid and in a bisector's half): 1, the two ends 1/2."""
    w = np.ones(points)
    w[[0, -1]] = 0.5
    return w


#: A consequent set whose largest membership over its output's sample points is below this
#: is *undersampled*: a term narrower than the sampling step can fall between the points
#: (``trimf [4.9 5 5.1]`` on MATLAB's 101 points of [0, 30], every 0.3, is 0 at every one),
#: and its rules then hardly change the output, or not at all, however strongly they fire.
#: Half the term's height: a triangle at least one step wide always reaches it.
UNDERSAMPLED_BELOW = 0.5


@dataclass(frozen=True)
class Undersampled:
    """A consequent set that its output's sampling misses (see :data:`UNDERSAMPLED_BELOW`)."""

    output: str
    label: str                # the set as rules conclude it: "cheap", "very cheap"
    term: str                 # the output term under the hedges
    peak: float               # its largest membership over the sample points
    points: int               # the output's sample points (``resolution``)
    step: float               # the distance between two of them
    rules: np.ndarray         # [r] the rules concluding it (columns of ``dof``)
    #: "" when it is above 0 somewhere in the output's range, only narrower than a step;
    #: "outside" when it lies outside the range, "zero" when it is 0 all over it (a
    #: formula): no resolution makes its rules count
    outside: str = ""
    universe: tuple[float, float] = (0.0, 0.0)
    own: bool = False         # sampled at the output's own resolution, not its behavior's

    def describe(self) -> str:
        """What is wrong, for ``check`` and ``eval``."""
        if self.outside:
            lo, hi = self.universe
            where = "lies outside" if self.outside == "outside" else "is 0 all over"
            return (f"term `{self.label}` of output `{self.output}` {where} its range "
                    f"[{lo:g}, {hi:g}]: its rules do not change `{self.output}`")
        where = (f"falls between the {self.points} points its output is sampled at "
                 if self.peak <= 0.0 else
                 f"reaches only {self.peak:.2g} at the {self.points} points its output is "
                 f"sampled at ")
        effect = "do not change" if self.peak <= 0.0 else "hardly change"
        return (f"term `{self.label}` of output `{self.output}` {where}(every {self.step:.3g}): "
                f"its rules {effect} `{self.output}`")


def undersampled(compiled: CompiledRuleBase) -> tuple[Undersampled, ...]:
    """The consequent sets of a Mamdani behavior that its outputs' sampling misses. A crisp
    value or a singleton is a spike of height 1 at its nearest point: never missed."""
    if compiled.operators.inference != "mamdani":
        return ()
    out = []
    for table in compiled.mamdani:
        if len(table.grid) < 2:
            continue
        step = float(table.grid[1] - table.grid[0])
        for i, label in enumerate(table.labels):
            peak = float(table.sets[i].max()) if table.sets.shape[1] else 0.0
            if label.startswith("=") or not peak < UNDERSAMPLED_BELOW:
                continue
            var = compiled.variables[table.name]
            term = var.term(label.split()[-1])
            outside = "" if _above_zero(term, label.split()[:-1], var.universe) else \
                "outside" if term.corners is not None else "zero"
            out.append(Undersampled(table.name, label, term.name, peak, len(table.grid), step,
                                    table.rules[table.set_of == i], outside,
                                    (float(var.universe[0]), float(var.universe[1])),
                                    var.resolution is not None))
    return tuple(out)


#: Points of an output's range on which a term missed by its sampling is looked at again.
DENSE = 100_001


def _above_zero(term: Term, hedges: list[str], universe: tuple[float, float]) -> bool:
    """Whether the (hedged) term is above 0 anywhere in the range: at :data:`DENSE` points
    and its corner points and centre inside it (a term as narrow as a float is still seen at
    its peak)."""
    lo, hi = universe
    extra = [c for c in (term.corners or ()) + (term.center,) if lo <= c <= hi]
    x = np.concatenate([np.linspace(lo, hi, DENSE), np.asarray(extra, dtype=float)])
    with np.errstate(all="ignore"):
        mu = hedge_mod.apply(tuple(hedges), np.asarray(term.membership(x), dtype=float))
    return bool(np.any(mu > 0.0))


def aggregate(dof: np.ndarray, sets: np.ndarray, implication: str,
              aggregation: norms.Norm) -> np.ndarray:
    """The output fuzzy set ``[b, res]`` of DOFs ``[R, b]`` and consequent sets ``[R, res]``:
    ``S_r I(dof_r, set_r)`` (no sub-blocking: callers keep ``R * b * res`` small)."""
    stack = IMPLICATIONS[implication](dof[:, :, None], sets[:, None, :])
    if aggregation.fn is np.maximum:
        return np.maximum.reduce(stack, axis=0)
    return norms.tree_reduce(aggregation, stack, axis=0)


def defuzzify(Y: np.ndarray, x: np.ndarray, method: str,
              universe: tuple[float, float] = (0.0, 1.0),
              weights: np.ndarray | None = None) -> np.ndarray:
    """Crisp values ``[b]`` of output sets ``Y[b, res]`` sampled at ``x[res]`` (NaN where the
    set is empty). ``universe`` is the output's range (only jFuzzyLogic's COA reads it);
    ``weights[res]``: each point's weight in the centroid's and the bisector's sums (the
    trapezoid rule's), else 1."""
    out = np.full(Y.shape[0], np.nan)
    if method == "jfuzzylogic_bisector":
        return walk_from_both_ends(Y, *universe)
    if weights is not None and method in ("centroid", "bisector", "matlab_bisector"):
        Y = Y * weights
    if method == "centroid":
        den = Y.sum(axis=1)
        num = (Y * x).sum(axis=1)
        np.divide(num, den, out=out, where=den > 0)
        return out
    if method in ("bisector", "matlab_bisector"):
        area = np.cumsum(Y, axis=1)
        total = area[:, -1:]
        ok = total[:, 0] > 0
        if method == "matlab_bisector":     # the first sample whose running area reaches half
            out[ok] = x[np.argmax(area >= total / 2, axis=1)][ok]
            return out
        with np.errstate(invalid="ignore", divide="ignore"):
            gap = np.abs(area / total - 0.5)
        ties = gap == gap.min(axis=1, keepdims=True)
        count = ties.sum(axis=1)
        np.divide(np.where(ties, x, 0.0).sum(axis=1), count, out=out, where=ok & (count > 0))
        return out
    top = Y.max(axis=1, keepdims=True)
    peak = (Y > 0) & (top == Y)
    ok = peak.any(axis=1)
    if method == "mom":
        np.divide(np.where(peak, x, 0.0).sum(axis=1), peak.sum(axis=1), out=out, where=ok)
    elif method == "som":
        out[ok] = x[np.argmax(peak, axis=1)][ok]
    elif method == "lom":
        out[ok] = x[len(x) - 1 - np.argmax(peak[:, ::-1], axis=1)][ok]
    elif method == "matlab_som":            # the maximum's sample nearest 0 (the first of two)
        out[ok] = x[np.argmin(np.where(peak, np.abs(x), np.inf), axis=1)][ok]
    elif method == "matlab_lom":            # the maximum's sample farthest from 0
        out[ok] = x[np.argmax(np.where(peak, np.abs(x), -1.0), axis=1)][ok]
    else:
        raise ValueError(f"unknown defuzzifier {method!r}")
    return out


def walk_from_both_ends(Y: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """jFuzzyLogic's center of area (``DefuzzifierCenterOfArea.defuzzify``) of ``Y[b, n]``,
    without its loop. There ``low`` starts at sample 0 and ``hi`` at sample n - 1, each with a
    sum of 0; while ``low < hi``, if ``sumLow <= sumHigh`` then ``low`` moves right and adds
    its sample, else ``hi`` moves left and adds its one; the answer is ``lo + step * low``
    (``step = (hi - lo) / n``), NaN when ``sumLow`` ends at 0. Samples 0 and n - 1 are only
    counted by a walk that reaches them, so a set split by a gap of zeros is cut where the
    sums first balance, which need not be its middle.

    The walk is a merge of two fixed non-decreasing sequences: the left sums
    ``a_k = Y[1] + ... + Y[k]`` and the right sums ``c_j = Y[n-2] + ... + Y[n-1-j]``, each
    added in jFuzzyLogic's order (``np.cumsum`` adds one element after another). After its
    n - 1 moves ``low`` has made as many moves as there are ``i`` in 1..n-1 with
    ``a_{i-1} <= c_{n-1-i}`` (the ``i``-th left move comes before the right move that would
    meet it exactly then, ties going left), so counting that condition gives ``low`` with the
    same sums, compared the same way: bit for bit the loop's answer (checked against a
    transcription of it in ``tests/test_mamdani.py``)."""
    b, n = Y.shape
    zero = np.zeros((b, 1))
    left = np.concatenate([zero, np.cumsum(Y[:, 1:], axis=1)], axis=1)         # a_0 .. a_{n-1}
    right = np.concatenate([zero, np.cumsum(Y[:, n - 2:0:-1], axis=1)], axis=1)  # c_0 .. c_{n-2}
    low = np.count_nonzero(left[:, :n - 1] <= right[:, ::-1], axis=1)
    out = lo + ((hi - lo) / n) * low
    return np.where(left[np.arange(b), low] > 0.0, out, np.nan)


def mamdani_outputs(compiled: CompiledRuleBase, dof: np.ndarray) -> np.ndarray:
    """Output layer of a Mamdani behavior: DOFs ``[R, b]`` -> crisp outputs ``[m, b]``."""
    ops = compiled.operators
    aggregation = norms.aggregation(ops.aggregation)
    b = dof.shape[1]
    out = np.empty((len(compiled.outputs), b))
    for j, table in enumerate(compiled.mamdani):      # loop over outputs (one or two)
        if not len(table.rules):
            out[j] = np.nan
            continue
        D = dof[table.rules]
        if aggregation.fn is np.maximum:
            # rules sharing a consequent set: max of their DOFs, then one implication per set
            D = np.maximum.reduceat(D[table.order], table.starts, axis=0)
            sets = table.sets
        else:
            sets = table.sets[table.set_of]
        per = max(1, MAX_BYTES // (8 * sets.shape[0] * sets.shape[1]))
        for start in range(0, b, per):                # sub-blocks of samples
            block = slice(start, min(start + per, b))
            Y = _aggregate_chunked(D[:, block], sets, ops.implication, aggregation)
            out[j, block] = defuzzify(Y, table.grid, ops.defuzzify,
                                      compiled.variables[table.name].universe, table.weights)
    return out


#: Above this, even one sample's ``[rules, resolution]`` stack is built in chunks of rules
#: (hundreds of rules at a resolution of tens of thousands, with a non-max aggregation).
MAX_STACK_BYTES = 32 * 2 ** 20


def _aggregate_chunked(dof: np.ndarray, sets: np.ndarray, implication: str,
                      aggregation: norms.Norm) -> np.ndarray:
    rules = max(1, MAX_STACK_BYTES // (8 * dof.shape[1] * sets.shape[1]))
    if rules >= dof.shape[0]:
        return aggregate(dof, sets, implication, aggregation)
    Y = aggregate(dof[:rules], sets[:rules], implication, aggregation)
    for r in range(rules, dof.shape[0], rules):     # chunks of rules, each one vectorized
        Y = aggregation.fn(Y, aggregate(dof[r:r + rules], sets[r:r + rules], implication,
                                        aggregation))
    return Y
