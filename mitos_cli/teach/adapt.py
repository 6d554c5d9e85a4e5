"""Learning by doing: neural adaptation of a behavior (the paper's eqs. 13-14).

The instructor's examples ``(x_k, t_k)`` define ``Q = sum_k sum_j (y_j(x_k) - t_kj)^2`` over
the outputs each example names. :func:`adapt` lowers ``Q`` by gradient steps on the
membership functions' break points (peaks, widths, corner points) of the behavior's input
terms and on the crisp values of its output terms, with exact gradients through the compiled
network:

* output layer (weighted average, eqs. 18-19): ``dy/dy_r = dof_r / S`` and
  ``dy/d dof_r = (y_r - y) / S`` with ``S = sum_r dof_r``;
* ``dof_r = antecedent_r * contexts_r * weight_r`` (product rule);
* AND / OR neurons: min and max pass the gradient to the child that wins (the lowest
  child index at ties, so the result is deterministic); product and probabilistic sum get
  their exact partial derivatives; other norms are refused;
* hedges (:mod:`mitos_cli.fuzzy.hedges` derivatives) and ``not`` (``-1``);
* memberships: the derivative of each piecewise-linear edge w.r.t. its corner points; a
  saturated membership (0 or 1) has derivative 0. Where an example lies exactly on a corner
  (a whole-numbered input on a knot), ``Q`` has a kink in that knot: each knot then gets the
  one-sided slope of the side on which ``Q`` falls (:func:`_corner_grad`), not a 0 that
  would hide that side from the descent.

**Mamdani behaviors** also learn the corner points of their output sets (tied, ordered and
bounded like input knots), and their gradient is central differences over the parameters, one
batch evaluation per moved parameter (:func:`difference_gradient`, steps in
:func:`difference_steps`): any implication, aggregation and defuzzifier works.

**Parameterisation.** The corner points of a variable's terms are *knots*: points with the
same value (a shoulder's end that is the next triangle's peak) are one knot, so shared break
points stay tied and a partition stays a partition. The knots keep their order (a minimum gap
of :data:`MIN_GAP` of the universe apart) and stay in the universe, so peaks stay ordered and
widths positive; a symmetric triangle (``peak`` / ``width``) stays symmetric (a linear
constraint; the gradient is projected onto the constraints' null space). Output values are
knots too (ordered, in the universe). Frozen terms (``frozen: true``), the consequents of
frozen rules (``frozen r4``) and shapes that are not piecewise linear keep their values.

**The step** (eq. 14, ``w <- w - eta dQ/dw`` with ``eta`` in (0, 1)): parameters are measured
in fractions of their universe, the projected gradient is normalised so that the parameter
that moves most moves ``eta`` x :data:`STEP` of its universe, and the step is halved until
``Q`` decreases and every constraint holds; so ``Q`` never increases. When that step had to be
halved, the same step along a second direction is tried too and the lower ``Q`` kept: the
projected gradient with each knot's component scaled by the knot's own share of the step
(:func:`_knot_steps`: halved each time the knot's slope turns, as Rprop's step sizes). A knot
lying beside a kink of ``Q`` (an example's input just past it) otherwise sets the size of every
step and the others hardly move: the shipped lesson's steepest descent stopped there. Where the
step stalls all the same (refused, or gaining less than :data:`STALL` of the starting ``Q``:
kinks crowd, and no slope the gradient sees points down), a deterministic compass search
(:class:`_Compass`) polls the free directions one knot at a time and takes the first point that
keeps every constraint and lowers ``Q``; the gradient step goes on from there, and adaptation
has converged when the compass's mesh has shrunk to its floor. Learned values are rounded to a
readable grid (``decimals``) and kept only if ``Q`` is still no worse.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, cast

import numpy as np

from ..engine.compile import CompiledRuleBase
from ..engine.evaluation import evaluate, fill_defaults, infer
from ..engine.mamdani import OutputTable, spike
from ..errors import LessonError
from ..fuzzy import hedges as hedge_mod
from ..fuzzy.norms import SNORMS, TNORMS, Norm
from ..fuzzy.shapes import kernel_params
from ..lang import interpretability as meaning
from ..lang.model import Rule, RuleBase

if TYPE_CHECKING:
    from collections.abc import Iterable
    from collections.abc import Set as AbstractSet

    from ..engine.compile import NodeGroup
    from ..lang.terms import Term, Variable

#: Fraction of a universe the most-moving parameter moves in one full step (times eta).
STEP = 0.05
#: Smallest distance between two knots of one variable, as a fraction of its universe.
MIN_GAP = 0.005
#: Step halvings tried per epoch before adaptation counts as converged.
HALVINGS = 30
#: Derived parameters (a width = right - peak) are rounded to this many decimals more than
#: their knots' grid: the learned knots are on the grid already, this drops float noise.
NOISE = 6
#: Knots closer than this fraction of the universe are one (shared) break point.
TIE = 1e-9

#: Shapes whose corner points can be learned: params as functions of the corners (a, b, c, d).
FROM_CORNERS: dict[str, Callable[[float, float, float, float], tuple[float, ...]]] = {
    "triangle": lambda a, b, c, d: (a, b, d),
    "triangle_pw": lambda a, b, c, d: (b, d - b),
    "triangle_plr": lambda a, b, c, d: (b, b - a, d - b),
    "trapezoid": lambda a, b, c, d: (a, b, c, d),
    "left_shoulder": lambda a, b, c, d: (c, d),
    "right_shoulder": lambda a, b, c, d: (a, b),
}
#: The norms adaptation differentiates: those whose registry entry says how (fuzzy/norms.py).
SUPPORTED_NORMS = {"and": tuple(n.name for n in TNORMS.values() if n.gradient),
                   "or": tuple(n.name for n in SNORMS.values() if n.gradient)}


@dataclass(frozen=True)
class Knot:
    """One learnable number: a break point of input terms or an output value."""

    var: str
    kind: str                    # "input" (term corners), "output" (a term's value), "crisp"
    label: str                   # what it is, for people: "road: NARROW.b = MEDIUM.peak"


@dataclass(frozen=True, eq=False)
class Parameters:
    """The learnable numbers of a compiled behavior and how they map onto its arrays."""

    compiled: CompiledRuleBase
    knots: tuple[Knot, ...]
    values: np.ndarray           # [P] current values
    scale: np.ndarray            # [P] universe width of each knot's variable
    lo: np.ndarray               # [P] bounds
    hi: np.ndarray
    projector: np.ndarray        # [P, P] onto the free directions (scaled coordinates)
    order: tuple[np.ndarray, ...]    # knots of one variable, in increasing order
    corner_knot: np.ndarray      # [T, 4] knot of each corner of each input term (-1: none)
    cons_knot: np.ndarray        # [R, m] knot of each rule's consequent value (-1: fixed)
    decimals: np.ndarray         # [P] decimals of the readable grid
    dependents: tuple[tuple[int, np.ndarray, np.ndarray], ...]   # see _round
    frozen_reasons: tuple[str, ...] = ()
    constraints: np.ndarray | None = None    # [c, P] rows that must stay 0 (ties, frozen)
    #: least distance between neighbours of each ``order`` entry, as a fraction of the universe
    order_gap: tuple[float, ...] = ()
    #: the variables whose coverage and distinguishability are kept (nonlinear constraints)
    partitions: tuple[Partition, ...] = ()
    #: ``(variable, term, point)`` of the terms held at their point of symmetry
    held: tuple[tuple[str, str, float], ...] = ()
    #: entries of ``order`` that are crisp output values (distinct by their current spread)
    crisp_orders: tuple[int, ...] = ()
    #: (output, term) -> its knots: a singleton's value ``[i, -1, -1, -1]``, or (Mamdani) the
    #: corners ``(a, b, c, d)`` of a piecewise-linear output set
    out_terms: dict = dataclasses.field(default_factory=dict)
    sets: tuple[SetSpec, ...] | None = None   # Mamdani: how to rebuild the output tables

    @property
    def n_free(self) -> int:
        return int(round(np.trace(self.projector)))

    @cached_property
    def neighbours(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(left, right, need)``: every pair of neighbouring knots of the ``order`` entries
        and the least distance between them (:func:`_need`), as flat arrays, so that the
        order check of every trial step is three array operations."""
        if not self.order:
            empty = np.zeros(0, dtype=np.intp)
            return empty, empty, np.zeros(0)
        left = np.concatenate([ids[:-1] for ids in self.order])
        right = np.concatenate([ids[1:] for ids in self.order])
        need = np.concatenate([_need(self, ids, k) for k, ids in enumerate(self.order)])
        return left, right, need

    @cached_property
    def crisp_neighbours(self) -> tuple[np.ndarray, ...]:
        """``(left, right, first, last, per, written)`` of the crisp ``order`` entries: their
        neighbouring pairs, each pair's group's smallest and largest knot and the fraction
        :data:`~mitos_cli.lang.interpretability.DISTINCT` / (values - 1) of the spread that
        is its least distance, and the pair's distance as written (the bound where closer)."""
        groups = [self.order[k] for k in self.crisp_orders]
        if not groups:
            empty = np.zeros(0, dtype=np.intp)
            return empty, empty, empty, empty, np.zeros(0), np.zeros(0)

        def each(fn: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
            return np.concatenate([fn(ids) for ids in groups])
        return (each(lambda ids: ids[:-1]), each(lambda ids: ids[1:]),
                each(lambda ids: np.full(len(ids) - 1, ids[0])),
                each(lambda ids: np.full(len(ids) - 1, ids[-1])),
                each(lambda ids: np.full(len(ids) - 1, meaning.DISTINCT / (len(ids) - 1))),
                each(lambda ids: np.diff(self.values[ids])))


@dataclass(frozen=True, eq=False)
class Partition:
    """The fuzzy sets of one variable, whose coverage and distinguishability adaptation keeps:
    the knot of each corner (``-1``: the corner as written) and the least coverage and largest
    similarity allowed (the documented thresholds, or the written values where those are
    already worse: adaptation never has to repair what the instructor wrote).

    Coverage is kept per stretch of the universe
    (:func:`~mitos_cli.lang.interpretability.coverage_spans`): where the written terms cover
    to 0.5 they keep doing so, and a stretch they cover less keeps at least its written least.
    One bound for the whole universe was the worst written point, 0 as soon as the terms
    left a gap anywhere, and then a term's edge on the end of the universe could move inward
    and leave it uncovered (a converted tipper's ``food.rancid`` from [0, 0, 1, 3] to [0.53,
    0.53, ...]). So a written gap may shrink but not widen or move."""

    var: str
    universe: tuple[float, float]
    knot: np.ndarray             # [t, 4]
    written: np.ndarray          # [t, 4] corners as written
    #: ``(ends[s + 1], least[s])`` of the stretches whose coverage is kept (None: not
    #: measured, an output's sets)
    cover: tuple[np.ndarray, np.ndarray] | None
    most_similar: float
    #: a tied Ruspini partition: it holds at every ordered point, so it is never measured
    by_construction: bool = False
    #: the variable's terms adaptation does not move (shapes that are not piecewise linear, a
    #: converted ``discrete`` or ``gaussian`` term), measured with the others on ``x``
    fixed: tuple = ()
    x: np.ndarray | None = None

    def corners(self, values: np.ndarray) -> np.ndarray:
        return np.where(self.knot >= 0, values[np.maximum(self.knot, 0)], self.written)

    def holds(self, values: np.ndarray) -> bool:
        if self.by_construction:
            return True
        corners = self.corners(values)
        if self.fixed:
            return self._holds_on_samples(corners)
        if self.cover is not None:
            ends, least = self.cover
            if np.any(meaning.span_coverage(corners, self.universe, ends) < least - 1e-12):
                return False
        return meaning.measures(corners, self.universe)[1] <= self.most_similar + 1e-12

    def _holds_on_samples(self, corners: np.ndarray) -> bool:
        """Beside terms of other shapes the variable is measured as `mitos check` measures
        it, on samples (:func:`_sampled_partition`), and on the moving terms' bends now."""
        assert self.x is not None
        x = np.union1d(self.x, meaning.breakpoints(corners, self.universe))
        mu = np.vstack([meaning.memberships(corners, x), meaning.sampled(self.fixed, x)])
        if self.cover is not None:
            ends, least = self.cover
            stretch = np.clip(np.searchsorted(ends, x, side="right") - 1, 0, len(least) - 1)
            if np.any(mu.max(axis=0) < least[stretch] - 1e-12):
                return False
        return meaning.most_similar_on(mu, x)[0] <= self.most_similar + 1e-12


def partition(var: str, universe: tuple[float, float], knot: np.ndarray, written: np.ndarray,
              covered: bool, fixed: tuple = ()) -> Partition:
    """A :class:`Partition` with its thresholds (see there)."""
    if fixed:
        return _sampled_partition(var, universe, knot, written, covered, fixed)
    cover = meaning.coverage_spans(written, universe) if covered else None
    most = max(meaning.SIMILARITY, meaning.most_similar(written, universe)[0]) \
        if len(written) > 1 else 1.0
    return Partition(var, universe, knot, written, cover, most,
                     by_construction=ruspini(knot, written, universe))


def _sampled_partition(var: str, universe: tuple[float, float], knot: np.ndarray,
                       written: np.ndarray, covered: bool, fixed: tuple) -> Partition:
    """A variable with terms adaptation does not move (``fixed``) beside the moving ones,
    measured on :func:`~mitos_cli.lang.interpretability.sample_points`: such a variable was
    no partition at all, so its coverage and distinctness were not kept (a converted
    controller's `dist.near`, [0, 0, 1] beside a `discrete` `far`, moved off 0 and left
    [0, 0.057] to no term). Coverage is kept per run of samples covered to 0.5, or not."""
    x = np.union1d(meaning.sample_points(fixed, universe), meaning.breakpoints(written, universe))
    mu = np.vstack([meaning.memberships(written, x), meaning.sampled(fixed, x)])
    cover = None
    if covered:
        top = mu.max(axis=0)
        ok = top >= meaning.COVERAGE - 1e-12
        starts = np.concatenate([[0], np.flatnonzero(ok[1:] != ok[:-1]) + 1])
        cover = (np.append(x[starts], x[-1]),
                 np.minimum(np.minimum.reduceat(top, starts), meaning.COVERAGE))
    most = max(meaning.SIMILARITY, meaning.most_similar_on(mu, x)[0])
    return Partition(var, universe, knot, written, cover, most, fixed=fixed, x=x)


def ruspini(knot: np.ndarray, written: np.ndarray, universe: tuple[float, float]) -> bool:
    """Whether these sets stay a Ruspini partition (memberships summing to 1 everywhere)
    however their knots move in order: written as one, and every sloped edge shares both its
    knots with an edge of the other direction (a term's fall is its neighbour's rise). Such a
    partition is covered to 0.5 at worst (where two edges cross) and two sets of it are at most
    1/3 similar (over a shared edge of width L: |A and B| = L/4, |A or B| >= 3L/4), within the
    thresholds by construction: adaptation then need not measure it."""
    x = meaning.breakpoints(written, universe)
    if not np.allclose(meaning.memberships(written, x).sum(axis=0), 1.0, atol=1e-9):
        return False
    a, b, c, d = written.T
    rising = sorted((int(i), int(j)) for i, j, u, v in zip(knot[:, 0], knot[:, 1], a, b)
                    if np.isfinite(u) and v > u)
    falling = sorted((int(i), int(j)) for i, j, u, v in zip(knot[:, 2], knot[:, 3], c, d)
                     if np.isfinite(v) and v > u)
    return all(i >= 0 and j >= 0 for i, j in rising + falling) and rising == falling


@dataclass(frozen=True, eq=False)
class SetSpec:
    """One output's Mamdani table and, per row, what it samples: ``(term, hedges)``, or
    ``(None, knot)`` for a crisp consequent."""

    table: OutputTable
    rows: tuple[tuple, ...]


# ---- building the parameterisation ------------------------------------------------------------

def _owners(rb: RuleBase, name: str) -> list[tuple[str, int]]:
    """(behavior, index of the rule in it) for each rule of ``flatten(rb, name)``, in order."""
    out: list[tuple[str, int]] = []

    def walk(bname: str) -> None:
        b = rb.behavior(bname)
        out.extend((bname, i) for i in range(len(b.rules)))
        for use in b.uses:
            walk(use.behavior)

    walk(name)
    return out


def _decimals(width: float) -> int:
    """The decimals of a readable grid over a universe ``width`` wide: about 10^4 steps, so
    0 at 10^4 and below 0 past it (tens, hundreds, ... ``-145`` on a universe of 2e149)."""
    return 4 - math.floor(math.log10(width))


def _supported(compiled: CompiledRuleBase) -> None:
    """Refuse what adaptation has no gradient for."""
    if compiled.cons_linear is not None:
        raise LessonError("adaptation does not cover Takagi-Sugeno (linear) consequents",
                          hint="give the outputs crisp values (numbers) to adapt them")
    if compiled.operators.inference == "tsukamoto" or compiled.hedged_outputs:
        raise LessonError("adaptation does not cover Tsukamoto inference or hedged "
                          "weighted-average consequents (no gradient is derived for them)")
    if compiled.operators.accumulated:
        raise LessonError(f"adaptation does not cover `accumulation = "
                          f"{compiled.operators.accumulation}` (the S-norm joining the rules "
                          f"of one value has no gradient derived for it)",
                          hint="adapt a copy without the setting (the default `sum` counts "
                               "every rule), or merge the rules that conclude one value")
    if compiled.operators.inference == "mamdani":
        return                                       # differences need no derivatives
    for op, names in SUPPORTED_NORMS.items():
        norm = compiled.operators.tnorm if op == "and" else compiled.operators.snorm
        if norm.gradient is None:
            raise LessonError(f"adaptation has gradients for `{op} = "
                              f"{' / '.join(names)}`, not `{op} = {norm.name}`",
                              hint=f"adapt with one of those (`{op} = {names[0]}` is the "
                                   f"paper's)")


@dataclass
class _Builder:
    """The knots of a parameterisation while :func:`parameterise` collects them."""

    compiled: CompiledRuleBase
    constrained: bool
    frozen_terms: frozenset
    released: frozenset
    knots: list = field(default_factory=list)
    values: list = field(default_factory=list)
    scale: list = field(default_factory=list)
    lo: list = field(default_factory=list)
    hi: list = field(default_factory=list)
    frozen: list = field(default_factory=list)
    order: list = field(default_factory=list)
    order_gap: list = field(default_factory=list)
    reasons: list = field(default_factory=list)
    sym_rows: list = field(default_factory=list)        # (a, b, d): a + d - 2 b = 0
    partitions: list = field(default_factory=list)
    held: list = field(default_factory=list)
    crisp_orders: list = field(default_factory=list)    # entries of ``order``: crisp values

    def new_knot(self, knot: Knot, value: float, width: float, bounds: tuple[float, float],
                 frozen: bool) -> int:
        self.knots.append(knot)
        self.values.append(value)
        self.scale.append(width)
        self.lo.append(bounds[0])
        self.hi.append(bounds[1])
        self.frozen.append(frozen)
        return len(self.knots) - 1

    def term_frozen(self, vname: str, term: Term) -> bool:
        return term.frozen or (vname, term.name) in self.frozen_terms

    def hold(self, vname: str) -> tuple[Term, float] | None:
        """The term of ``vname`` held at its point of symmetry, if any (and not released)."""
        if not self.constrained:
            return None
        held = meaning.held_term(self.compiled.variables[vname])
        if held is None or (vname, held[0].name) in self.released or not held[0].held:
            return None
        entry = (vname, held[0].name, float(held[1]))
        if entry not in self.held:
            self.held.append(entry)
        return held

    def tie_corners(self, vname: str, kind: str, items: list) -> dict:
        """Knots for the corners of ``items`` ((key, term) of one variable): equal corners
        are one knot; returns key -> [4] knot ids (-1: no such corner)."""
        var = self.compiled.variables[vname]
        ulo, uhi = var.universe
        width = uhi - ulo
        out: dict = {}
        points: list[tuple[float, int, int]] = []        # (value, item, corner)
        for n, (key, term) in enumerate(items):
            out[key] = np.full(4, -1, dtype=np.intp)
            points.extend((v, n, ci) for ci, v in enumerate(term.corners) if math.isfinite(v))
        points.sort()
        ids: list[int] = []
        names: dict[int, list[str]] = {}
        last = None
        for v, n, ci in points:
            key, term = items[n]
            if last is None or abs(v - self.values[last]) > TIE * width:
                last = self.new_knot(Knot(vname, kind, ""), v, width,
                                     (min(ulo, v), max(uhi, v)), False)
                ids.append(last)
                names[last] = []
            out[key][ci] = last
            names[last].append(f"{term.name}.{_corner_name(term.shape, ci)}")
            if self.term_frozen(vname, term):
                self.frozen[last] = True
        for i in ids:
            self.knots[i] = Knot(vname, kind, f"{vname}: " + " = ".join(dict.fromkeys(names[i])))
        if ids:
            self.order.append(np.array(ids, dtype=np.intp))
            self.order_gap.append(MIN_GAP)
        for key, term in items:
            if term.shape == "triangle_pw":
                self.sym_rows.append((out[key][0], out[key][1], out[key][3]))
        self._hold_set(vname, items, out)
        if self.constrained:
            self._keep_places(var.universe, [(term.corners[1:3], out[key][1:3])
                                             for key, term in items])
        if self.constrained and items:
            written = np.array([term.corners for _, term in items], dtype=float)
            moving = {term.name for _, term in items}
            self.partitions.append(partition(vname, var.universe,
                                             np.array([out[k] for k, _ in items]), written,
                                             covered=kind == "input", fixed=tuple(
                                                 t for t in var.terms if t.name not in moving)))
        return out

    def _keep_places(self, universe: tuple[float, float], cores: list) -> None:
        """Each term's core (``(b, c)`` as written and their knots) kept nearer its own centre
        as written than either neighbour's: a term moves at most half the way to the next one,
        so that it never comes to mean what its neighbour meant (`LEFT` peaking at 2 deg left
        of ahead). The bounds are the midpoints between the written centres."""
        centres = [_core_centre(tuple(core), universe) for core, _ in cores]
        order = sorted(range(len(cores)), key=lambda n: centres[n])
        for j, n in enumerate(order):
            lo = universe[0] if j == 0 else 0.5 * (centres[order[j - 1]] + centres[n])
            hi = universe[1] if j == len(order) - 1 else 0.5 * (centres[n] + centres[order[j + 1]])
            for i in cores[n][1]:
                if i >= 0:
                    v = self.values[i]
                    self.lo[i] = max(self.lo[i], min(lo, v))
                    self.hi[i] = min(self.hi[i], max(hi, v))

    def _hold_set(self, vname: str, items: list, out: dict) -> None:
        """A held triangle keeps its peak (its slopes may move: they are its neighbours'
        peaks); a held trapezoid keeps its core."""
        held = self.hold(vname) if items else None
        if held is None:
            return
        key = next((k for k, t in items if t.name == held[0].name), None)
        if key is None:
            return
        ids = out[key]
        for i in ids[1:3]:
            if i >= 0:
                self.frozen[i] = True


def _core_centre(core: tuple[float, float], universe: tuple[float, float]) -> float:
    """The centre of a core ``(b, c)`` (a shoulder's: its finite end)."""
    b, c = core
    if not math.isfinite(b):
        return c if math.isfinite(c) else 0.5 * (universe[0] + universe[1])
    return b if not math.isfinite(c) else 0.5 * (b + c)


def parameterise(compiled: CompiledRuleBase, *, constrained: bool = True,
                 frozen_terms: AbstractSet[tuple[str, str]] = frozenset(),
                                  released: AbstractSet[tuple[str, str]] = frozenset()) -> Parameters:
    """The learnable numbers of ``compiled`` (its input terms and output values).

    ``constrained`` (the default) keeps the terms' meaning as well as their order
    (:mod:`mitos_cli.lang.interpretability`): the middle term of mirror-symmetric terms held at
    its point unless ``released`` names it, neighbouring crisp output values at least
    half the spacing of evenly spread values apart, inputs covered and their sets distinguishable.
    ``frozen_terms`` are ``(variable, term)`` pairs kept as they are."""
    _supported(compiled)
    b = _Builder(compiled, constrained, frozenset(frozen_terms), frozenset(released))
    corner_knot = _input_knots(b)
    cons_knot, out_terms = _output_knots(b)
    P = len(b.knots)
    frozen_a = np.array(b.frozen, dtype=bool)
    projector, dependents, rows = _constraints(P, frozen_a, b.sym_rows)
    scale_a = np.array(b.scale, dtype=float)
    decimals = np.array([_decimals(w) for w in scale_a], dtype=int)
    mamdani = compiled.operators.inference == "mamdani"
    return Parameters(compiled, tuple(b.knots), np.array(b.values, dtype=float), scale_a,
                      np.array(b.lo), np.array(b.hi), projector, tuple(b.order), corner_knot,
                      cons_knot, decimals, dependents, tuple(dict.fromkeys(b.reasons)), rows,
                      order_gap=tuple(b.order_gap), partitions=tuple(b.partitions),
                      held=tuple(b.held), crisp_orders=tuple(b.crisp_orders),
                      out_terms=out_terms,
                      sets=_set_specs(compiled, cons_knot) if mamdani else None)


def _input_knots(b: _Builder) -> np.ndarray:
    """Input terms: equal corners of one variable tied into one knot; ``[T, 4]`` knot ids."""
    compiled = b.compiled
    T = compiled.n_terms
    corner_knot = np.full((T, 4), -1, dtype=np.intp)
    for k, vname in enumerate(compiled.inputs):
        var = compiled.variables[vname]
        items = []
        for t in range(T):
            if compiled.term_var[t] != k:
                continue
            term = var.term(compiled.term_names[t][1])
            if term.shape in FROM_CORNERS:
                items.append((t, term))
                if b.term_frozen(vname, term):          # said as a frozen output term is
                    b.reasons.append(f"{vname}.{term.name} is frozen")
            else:
                b.reasons.append(f"{vname}.{term.name}: shape `{term.shape}` is not learned")
        for t, ids in b.tie_corners(vname, "input", items).items():
            corner_knot[t] = ids
    return corner_knot


def _output_knots(b: _Builder) -> tuple[np.ndarray, dict]:
    """Output values: every crisp term of every output is a knot (ordered, at least
    ``least_distance`` apart when constrained); crisp consequents one knot per rule; Mamdani output
    sets' corners tied like an input's."""
    compiled = b.compiled
    R, m = compiled.cons_value.shape
    cons_knot = np.full((R, m), -1, dtype=np.intp)
    out_terms: dict[tuple[str, str], np.ndarray] = {}
    rules = _rules_of(compiled)
    for j, oname in enumerate(compiled.outputs):
        term_knot = _crisp_terms(b, oname)
        shaped: dict[str, np.ndarray] = {}
        if compiled.operators.inference == "mamdani":
            var = compiled.variables[oname]
            shaped = b.tie_corners(oname, "shape", [(t.name, t) for t in var.terms
                                                    if t.shape in FROM_CORNERS])
            out_terms.update({(oname, tname): ids for tname, ids in shaped.items()})
        used, locked, used_sets, locked_sets = _consequent_knots(b, j, term_knot, shaped,
                                                                 rules, cons_knot)
        var = compiled.variables[oname]
        held = {h[1] for h in b.held if h[0] == oname}
        for tname, i in term_knot.items():
            b.frozen[i] = (i not in used or i in locked or b.term_frozen(oname, var.term(tname))
                           or tname in held)
            if i in locked and not b.term_frozen(oname, var.term(tname)):
                b.reasons.append(f"{oname}.{tname} is concluded by a frozen rule")
            out_terms[(oname, tname)] = np.array([i, -1, -1, -1], dtype=np.intp)
        _thaw_sets(b, oname, shaped, used_sets, locked_sets)
    return cons_knot, out_terms


def _crisp_terms(b: _Builder, oname: str) -> dict[str, int]:
    """One knot per crisp term of output ``oname`` (frozen until a rule is found using it)."""
    var = b.compiled.variables[oname]
    ulo, uhi = var.universe
    term_knot: dict[str, int] = {}
    ids = []
    for v, tname in sorted((t.params[0], t.name) for t in var.terms if t.shape == "singleton"):
        term_knot[tname] = b.new_knot(Knot(oname, "output", f"{oname}: {tname}"), v,
                                      uhi - ulo, (ulo, uhi), True)
        ids.append(term_knot[tname])
        if b.term_frozen(oname, var.term(tname)):
            b.reasons.append(f"{oname}.{tname} is frozen")
    if len(ids) > 1 and b.constrained:
        b._keep_places((ulo, uhi), [((b.values[i], b.values[i]), (i, i)) for i in ids])
    if len(ids) > 1:
        b.order.append(np.array(ids, dtype=np.intp))
        least = meaning.least_distance(np.array([b.values[i] for i in ids])) / (uhi - ulo)
        if b.constrained:
            b.crisp_orders.append(len(b.order) - 1)
        b.order_gap.append(max(least, MIN_GAP) if b.constrained else MIN_GAP)
    if ids:
        b.hold(oname)
    return term_knot


def _rules_of(compiled: CompiledRuleBase) -> list[tuple[str, int, Rule, bool]]:
    """(owner behavior, index, rule, frozen) of each compiled rule."""
    rb = compiled.rulebase
    frozen_rules = {(x.name, label) for x in rb.behaviors for label in x.frozen}
    out = []
    for owner, index in _owners(rb, compiled.behavior):
        rule = rb.behavior(owner).rules[index]
        out.append((owner, index, rule, (owner, rule.label) in frozen_rules))
    return out


def _consequent_knots(b: _Builder, j: int, term_knot: dict, shaped: dict, rules: list,
                      cons_knot: np.ndarray) -> tuple[set, set, set, set]:
    """Point each rule's consequent on output ``j`` at its knot (a crisp number gets one of
    its own); which term knots and Mamdani sets rules that may change, or may not, use."""
    compiled = b.compiled
    oname = compiled.outputs[j]
    var = compiled.variables[oname]
    width = var.universe[1] - var.universe[0]
    used: set[int] = set()
    locked: set[int] = set()
    used_sets: set[str] = set()
    locked_sets: set[str] = set()
    crisp: dict[tuple[str, int, int], int] = {}
    for r, (owner, index, rule, is_frozen) in enumerate(rules):
        if not compiled.cons_mask[r, j]:
            continue
        tname = compiled.cons_term[r][j]
        if tname is not None and tname in shaped:
            (locked_sets if is_frozen else used_sets).add(tname)
        elif tname is not None:
            if tname not in term_knot:
                b.reasons.append(f"{oname}.{tname}: shape "
                                 f"`{var.term(tname).shape}` is not learned")
                continue
            cons_knot[r, j] = term_knot[tname]
            (locked if is_frozen else used).add(term_knot[tname])
        else:
            key = (owner, index, j)
            if key not in crisp:
                crisp[key] = b.new_knot(
                    Knot(oname, "crisp", f"{oname}: {owner}/{rule.label or '#' + str(index + 1)}"),
                    float(compiled.cons_value[r, j]), width, var.universe, is_frozen)
            cons_knot[r, j] = crisp[key]
    return used, locked, used_sets, locked_sets


def _thaw_sets(b: _Builder, oname: str, shaped: dict, used_sets: set, locked_sets: set) -> None:
    """A corner of output sets moves when a rule that is not frozen concludes one of its sets
    and no frozen rule or frozen term holds it."""
    var = b.compiled.variables[oname]
    thawed: dict[int, bool] = {}
    for tname, ids in shaped.items():
        for i in ids[ids >= 0]:
            thawed[int(i)] = thawed.get(int(i), False) or tname in used_sets
    for tname, ids in shaped.items():
        for i in ids[ids >= 0]:
            if tname in locked_sets or not thawed[int(i)]:
                b.frozen[i] = True
        if b.term_frozen(oname, var.term(tname)) and tname in used_sets:
            b.reasons.append(f"{oname}.{tname} is frozen")
        elif tname in locked_sets and not b.term_frozen(oname, var.term(tname)):
            b.reasons.append(f"{oname}.{tname} is concluded by a frozen rule")


def _set_specs(compiled: CompiledRuleBase, cons_knot: np.ndarray) -> tuple[SetSpec, ...]:
    """How to rebuild each output's Mamdani table from knot values: the rows of the engine's
    own table, except that every crisp consequent (``steering is 70``) gets a row of its own
    (two rules with the same number may learn different ones). Exact: with ``max``
    aggregation ``max_r min(d_r, s) = min(max_r d_r, s)``, and other S-norms take one set per
    rule anyway."""
    specs = []
    for j, table in enumerate(compiled.mamdani):
        keys: dict[tuple, int] = {}
        set_of = []
        for r in table.rules:                      # once per parameterisation, not per step
            term = compiled.cons_term[r][j]
            key = (term, compiled.cons_hedges[r][j]) if term is not None else \
                (None, int(cons_knot[r, j]))
            set_of.append(keys.setdefault(key, len(keys)))
        set_of_a = np.array(set_of, dtype=np.intp)
        order = np.argsort(set_of_a, kind="stable").astype(np.intp)
        starts = np.searchsorted(set_of_a[order], np.arange(len(keys))).astype(np.intp)
        labels = tuple(" ".join(k[1] + (k[0],)) if k[0] is not None else f"= crisp {k[1]}"
                       for k in keys)
        specs.append(SetSpec(dataclasses.replace(table, labels=labels, set_of=set_of_a,
                                                 order=order, starts=starts),
                             tuple(keys)))
    return tuple(specs)


def _corner_name(shape: str, corner: int) -> str:
    names = {"triangle": "abbc", "triangle_pw": ("left", "peak", "peak", "right"),
             "triangle_plr": ("left", "peak", "peak", "right"), "trapezoid": "abcd",
             "left_shoulder": "--ab", "right_shoulder": "ab--"}
    return names[shape][corner]


def _null_projector(C: np.ndarray) -> np.ndarray:
    """Orthogonal projector onto the null space of the rows ``C``."""
    P = C.shape[1]
    if not len(C):
        return np.eye(P)
    _, s, vt = np.linalg.svd(C)
    rank = int((s > 1e-10).sum())
    null = vt[rank:].T                                   # [P, F] orthonormal
    projector = null @ null.T
    projector[np.abs(projector) < 1e-13] = 0.0
    return projector


def _constraints(P: int, frozen: np.ndarray, sym_rows: Iterable[tuple[int, int, int]]
                 ) -> tuple[np.ndarray, tuple, np.ndarray]:
    """Projector onto the directions that keep frozen knots fixed and symmetric triangles
    symmetric; and, for rounding, which knots follow from which (see :func:`_round`)."""
    rows = []
    for a, b, d in sym_rows:
        row = np.zeros(P)
        row[a] += 1.0
        row[d] += 1.0
        row[b] -= 2.0
        rows.append(row)
    for i in np.flatnonzero(frozen):
        row = np.zeros(P)
        row[i] = 1.0
        rows.append(row)
    C = np.array(rows).reshape(-1, P)
    projector = _null_projector(C)
    # each symmetric triangle fixes one knot from the other two: its left corner, unless that
    # one is frozen or already determined
    dependents = []
    taken = set(np.flatnonzero(frozen).tolist())
    for a, b, d in sym_rows:
        for dep, others, coef in ((a, (b, d), (2.0, -1.0)), (d, (b, a), (2.0, -1.0)),
                                  (b, (a, d), (0.5, 0.5))):
            if dep not in taken:
                taken.add(dep)
                dependents.append((dep, np.array(others, dtype=np.intp), np.array(coef)))
                break
    return projector, tuple(dependents), C


# ---- the network with other parameter values ---------------------------------------------------

def kernel_of(p: Parameters, values: np.ndarray) -> np.ndarray:
    """The compiled kernel ``[4, T]`` with the input terms' corners taken from ``values``."""
    kernel = p.compiled.kernel.copy()
    for t in np.flatnonzero((p.corner_knot >= 0).any(axis=1)).tolist():
        a, b, c, d = (float(values[i]) if i >= 0 else orig for i, orig in
                      zip(p.corner_knot[t], _orig_corners(p, t)))
        kernel[:, t] = kernel_params((a, b, c, d))
    return kernel


def _orig_corners(p: Parameters, t: int) -> tuple[float, float, float, float]:
    var, name = p.compiled.term_names[t]
    return p.compiled.variables[var].term(name).corners


def with_values(p: Parameters, values: np.ndarray) -> CompiledRuleBase:
    """The compiled behavior with ``values`` in place of its learnable numbers (no
    recompilation: only the kernel and the consequent values change)."""
    cons = p.compiled.cons_value.copy()
    mask = p.cons_knot >= 0
    cons[mask] = values[p.cons_knot[mask]]
    c = dataclasses.replace(p.compiled, kernel=kernel_of(p, values), cons_value=cons)
    if p.sets is not None:
        # the engine's cached Mamdani tables (a cached_property) of the new compiled object
        c.__dict__["mamdani"] = output_tables(p, values)
    return c


def output_tables(p: Parameters, values: np.ndarray) -> tuple[OutputTable, ...]:
    """The Mamdani output tables with the output sets' corners and values from ``values``:
    each distinct consequent set sampled once on its grid (a few per output)."""
    c = p.compiled
    ops = c.operators
    tables = []
    assert p.sets is not None                        # its one caller checks: a Mamdani behavior
    for j, spec in enumerate(p.sets):
        var = c.variables[c.outputs[j]]
        lo, hi = var.universe
        res = len(spec.table.grid)                   # the output's own resolution, or the behavior's
        rows = []
        for term, extra in spec.rows:
            if term is None:                         # a crisp consequent: extra is its knot
                rows.append(spike(lo, hi, res, float(values[extra]), ops.sampling))
                continue
            t = _output_term(p, var, term, values)
            mu = (spike(lo, hi, res, t.params[0], ops.sampling)
                  if t.shape == "singleton"
                  else np.asarray(t.membership(spec.table.grid), dtype=float))
            rows.append(hedge_mod.apply(extra, mu))
        sets = np.array(rows, dtype=float).reshape(len(rows), res)
        tables.append(dataclasses.replace(spec.table, sets=sets))
    return tuple(tables)


def _output_term(p: Parameters, var: Variable, name: str, values: np.ndarray) -> Term:
    """Output term ``name`` with its knots' values (the term itself while they are unchanged,
    so the starting point is the engine's own table, bit for bit)."""
    term = var.term(name)
    ids = p.out_terms.get((var.name, name))
    if ids is None:
        return term
    mine = ids[ids >= 0]
    if np.array_equal(values[mine], p.values[mine]):
        return term
    if term.shape == "singleton":
        return term.with_params((float(values[ids[0]]),))
    corners = [float(values[i]) if i >= 0 else o                   # (a term with knots has corners)
               for i, o in zip(ids, cast(tuple, term.corners))]
    return term.with_params(FROM_CORNERS[term.shape](*corners))


def loss(compiled: CompiledRuleBase, X: np.ndarray, targets: np.ndarray) -> float:
    """``Q = sum (y - t)^2`` over the given targets (NaN targets are not given)."""
    return _q(evaluate(compiled, X, detail=False, strict=False).outputs, targets)


def _q(y: np.ndarray, targets: np.ndarray) -> float:
    given = ~np.isnan(targets)
    diff = np.where(given, y - np.where(given, targets, 0.0), 0.0)
    diff = np.nan_to_num(diff)
    return float(np.sum(diff * diff))


# ---- Mamdani: central differences -------------------------------------------------------------

#: Central-difference step for a centroid behavior, as a fraction of each parameter's universe.
DIFF_STEP = 1e-3


def difference_steps(p: Parameters) -> np.ndarray:
    """The step ``h`` of each knot's central difference (in its own units).

    A Mamdani output is computed on a grid of ``resolution`` samples of the output universe.
    With ``centroid`` it is a continuous, piecewise-smooth function of every parameter (the
    sampled sets move continuously with their corners), so a small step (:data:`DIFF_STEP` of
    the universe) measures its slope. A singleton is a spike in the grid cell holding it, and
    ``bisector`` / ``mom`` / ``som`` / ``lom`` pick grid samples: those outputs are step
    functions whose derivative is 0 almost everywhere, so their differences are taken one grid
    cell wide (the same fraction of the universe for input knots): the slope of ``Q`` at the
    scale the outputs can resolve, which is what a descent step of a few per cent needs.
    """
    ops = p.compiled.operators
    # the coarsest output's grid (outputs may have resolutions of their own)
    points = min((len(t.grid) for t in p.compiled.mamdani), default=ops.resolution) \
        if ops.inference == "mamdani" else ops.resolution
    cells = points - 1 if ops.sampling in ("endpoints", "trapezoid") else points
    rel = np.full(len(p.values), DIFF_STEP if ops.defuzzify == "centroid" else 1.0 / cells)
    single = np.array([k.kind in ("output", "crisp") for k in p.knots], dtype=bool)
    rel[single] = 1.0 / cells
    return rel * p.scale


def _room(p: Parameters, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """How far each knot may move alone and keep its bounds and its order."""
    low, high = p.lo.copy(), p.hi.copy()
    for k, ids in enumerate(p.order):                # one per variable
        need = _need(p, ids, k)
        low[ids[1:]] = np.maximum(low[ids[1:]], values[ids[:-1]] + need)
        high[ids[:-1]] = np.minimum(high[ids[:-1]], values[ids[1:]] - need)
    return np.minimum(low, values), np.maximum(high, values)


def difference_gradient(p: Parameters, values: np.ndarray, X: np.ndarray,
                        targets: np.ndarray) -> tuple[float, np.ndarray]:
    """``Q`` and its central-difference gradient, for Mamdani behaviors.

    Each knot that may move is moved by ``+-h`` (:func:`difference_steps`; one-sided where
    a bound or a neighbour is nearer) and ``Q`` is evaluated on the whole batch: a knot of an
    input term needs the network again; a knot of an output set only the output layer on the
    DOFs already computed. Cost per epoch: ``2 x`` (free knots) batch evaluations.
    """
    c = with_values(p, values)
    res = evaluate(c, X, strict=False)
    Q = _q(res.outputs, targets)
    assert res.dof is not None                       # detail=True, the default, keeps them
    dof = res.dof.T                                  # [R, n]
    Xc = res.inputs
    h = difference_steps(p)
    low, high = _room(p, values)
    up = np.minimum(values + h, high)
    down = np.maximum(values - h, low)
    free = np.diag(p.projector) > 1e-12
    grad = np.zeros(len(values))
    for i in np.flatnonzero(free & (up > down)):     # parameters, never samples or rules
        q = []
        for v in (up[i], down[i]):
            trial = values.copy()
            trial[i] = v
            moved = with_values(p, trial)
            if p.knots[i].kind == "input":
                q.append(loss(moved, X, targets))
            else:
                y = fill_defaults(moved, infer(moved, dof).T, Xc, False)
                q.append(_q(y, targets))
        grad[i] = (q[0] - q[1]) / (up[i] - down[i])
    return Q, grad


def gradient(p: Parameters, values: np.ndarray, X: np.ndarray,
             targets: np.ndarray) -> tuple[float, np.ndarray]:
    """``Q`` and ``dQ/dvalues``: exact, by backpropagation through the network; for Mamdani
    inference by central differences (:func:`difference_gradient`). A knot with examples
    exactly on one of its corners, where ``Q`` has a kink, gets the one-sided slope of the side
    on which ``Q`` falls (:func:`_falling_side`)."""
    if p.sets is not None:
        return difference_gradient(p, values, X, targets)
    c = with_values(p, values)
    res = evaluate(c, X, keep_values=True, strict=False)
    assert res.values is not None and res.dof is not None    # keep_values, detail (default)
    V = res.values.T                                 # [cols, n]
    Q, gdof, gcons = _output_layer(c, res.dof.T, res.outputs.T, targets.T)
    G = _network_grad(c, V, gdof)
    grad = np.zeros(len(values))
    up = down = None
    rows = np.flatnonzero((p.corner_knot >= 0).any(axis=1))
    if rows.size:
        up, down = _membership_layer(p, values, c, rows, res.inputs.T, G, grad)
    ok = p.cons_knot >= 0
    np.add.at(grad, p.cons_knot[ok], gcons[ok])
    if up is not None and down is not None:
        np.add.at(up, p.cons_knot[ok], gcons[ok])
        np.add.at(down, p.cons_knot[ok], gcons[ok])
        grad = _falling_side(up, down)
    return Q, grad


def _output_layer(c: CompiledRuleBase, dof: np.ndarray, y: np.ndarray,
                  tgt: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """``Q`` of the outputs ``y[m, n]`` against the targets ``tgt[m, n]`` (NaN: not
    corrected), and its gradient by each rule's DOF ``[R, n]`` and by each rule's crisp
    consequents ``[R, m]``, through the weighted average (or sum) of the DOFs ``[R, n]``."""
    given = ~np.isnan(tgt)
    M = c.cons_mask.astype(float)                    # [R, m]
    S = M.T @ dof                                    # [m, n]
    fired = S > 0
    err = np.where(given & fired, 2.0 * (y - np.where(given, tgt, 0.0)), 0.0)
    diff = np.where(given, np.nan_to_num(y - np.where(given, tgt, 0.0)), 0.0)
    Q = float(np.sum(diff * diff))
    Yc = c.cons_value * M                            # [R, m]
    if c.operators.inference == "weighted_sum":
        gy = err
        gdof = Yc @ gy
    else:
        gy = np.divide(err, S, out=np.zeros_like(err), where=fired)     # dQ/dy / S
        gdof = Yc @ gy - M @ (gy * np.where(fired, y, 0.0))            # (y_r - y) / S
    gcons = (dof @ gy.T) * M                         # [R, m]: dof_r / S
    return Q, gdof, gcons


def _network_grad(c: CompiledRuleBase, V: np.ndarray, gdof: np.ndarray) -> np.ndarray:
    """The gradient by every value of the network ``V[cols, n]``, from the gradient by each
    rule's DOF: through the rule's weight and contexts (``dof_r = V[rule_col] * prod
    V[context] * weight``), then the AND / OR / NOT / hedge neurons, last level first."""
    G = np.zeros_like(V)
    n = V.shape[1]
    ctx = c.context
    w = c.weight[:, None]
    base = V[c.rule_col]
    ctx_vals = V[ctx.T] if ctx.shape[1] else np.ones((0, len(c.rule_col), n))
    prod_ctx = np.prod(ctx_vals, axis=0) if ctx.shape[1] else 1.0
    _scatter_add(G, c.rule_col, gdof * w * prod_ctx)
    for j in range(ctx.shape[1]):
        others = np.prod(np.delete(ctx_vals, j, axis=0), axis=0)
        _scatter_add(G, ctx[:, j], gdof * w * base * others)
    tnorm, snorm = c.operators.tnorm, c.operators.snorm
    for level in reversed(c.levels):
        for group in reversed(level):
            _backward_group(group, V, G, tnorm, snorm)
    return G


def _membership_layer(p: Parameters, values: np.ndarray, c: CompiledRuleBase, rows: np.ndarray,
                      Xt: np.ndarray, G: np.ndarray,
                      grad: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Add to ``grad`` the slopes of the corners of the terms ``rows`` (those with a free
    knot) at the clamped inputs ``Xt[k, n]``, from the gradient ``G`` by the network's values;
    where an example lies exactly on a corner, also return the one-sided gradients (moving
    each knot up, and down), else ``None, None``."""
    corners = np.array([[values[i] if i >= 0 else o for i, o in
                         zip(p.corner_knot[t], _orig_corners(p, t))] for t in rows.tolist()])
    x = Xt[c.term_var[rows]]
    dmu = _membership_grad(corners, x)                          # [4, t, n]
    gmu = G[2 + rows]                                           # [t, n]
    idx = p.corner_knot[rows]
    ok = idx >= 0
    np.add.at(grad, idx[ok], np.einsum("ctn,tn->tc", dmu, gmu)[ok])
    sides = _corner_grad(corners, x)                            # examples on a corner
    if sides is None:
        return None, None
    up, down = grad.copy(), grad.copy()
    np.add.at(up, idx[ok], np.einsum("ctn,tn->tc", sides[0], gmu)[ok])
    np.add.at(down, idx[ok], np.einsum("ctn,tn->tc", sides[1], gmu)[ok])
    return up, down


def _falling_side(up: np.ndarray, down: np.ndarray) -> np.ndarray:
    """Per knot, from its one-sided slopes of ``Q`` (moving it up, moving it down): the slope
    of a side on which ``Q`` falls (``up`` where negative, ``down`` where positive; the steeper
    where both fall), 0 where ``Q`` rises on both sides (a kink at a minimum). Where the two
    sides agree (no example on a corner) this is the slope itself."""
    out = np.where(up < 0, up, np.where(down > 0, down, 0.0))
    return np.where((up < 0) & (down > 0) & (down > -up), down, out)


def _corner_grad(corners: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """What examples lying exactly on a corner add to ``d mu / d (a, b, c, d)`` on each side:
    ``(up, down)`` ``[4, t, n]``, for moving the corner up and down, or ``None`` when no example
    lies on one. There ``mu`` has a kink in the corner's position (it is saturated on one side
    and on an edge on the other), which :func:`_membership_grad` counts as 0: an example at
    ``x = b`` of a rising edge leaves the edge's top when ``b`` moves up (``mu`` falls below 1),
    one at ``x = a`` its foot when ``a`` moves down; on a falling edge, ``x = c`` when ``c``
    moves down and ``x = d`` when ``d`` moves up. Whole-numbered inputs on a knot (``clutter``
    = 1 on ``SPARSE`` / ``DENSE``'s knot at 1) are where this happens."""
    A, B, C, D = (corners[:, i:i + 1] for i in range(4))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        has_rise = np.isfinite(A) & np.isfinite(B) & (B > A)
        has_fall = np.isfinite(C) & np.isfinite(D) & (D > C)
        at_a, at_b = has_rise & (x == A), has_rise & (x == B)
        at_c, at_d = has_fall & (x == C), has_fall & (x == D)
        if not (at_a.any() or at_b.any() or at_c.any() or at_d.any()):
            return None
        wr = np.where(has_rise, B - A, 1.0)
        wf = np.where(has_fall, D - C, 1.0)
        up, down = np.zeros((4,) + x.shape), np.zeros((4,) + x.shape)
        down[0] = np.where(at_a, -1.0 / wr, 0.0)        # (x - b) / (b - a)^2 at x = a
        up[1] = np.where(at_b, -1.0 / wr, 0.0)          # -(x - a) / (b - a)^2 at x = b
        down[2] = np.where(at_c, 1.0 / wf, 0.0)         # (d - x) / (d - c)^2 at x = c
        up[3] = np.where(at_d, 1.0 / wf, 0.0)           # (x - c) / (d - c)^2 at x = d
    return up, down


def _scatter_add(G: np.ndarray, idx: np.ndarray, vals: np.ndarray) -> None:
    """``G[idx] += vals`` with repeated indices summed (sorted, then ``add.reduceat``: faster
    than ``np.add.at`` and in a fixed order)."""
    order = np.argsort(idx, kind="stable")
    sorted_idx = idx[order]
    starts = np.flatnonzero(np.r_[True, sorted_idx[1:] != sorted_idx[:-1]])
    G[sorted_idx[starts]] += np.add.reduceat(vals[order], starts, axis=0)


def _backward_group(group: NodeGroup, V: np.ndarray, G: np.ndarray, tnorm: Norm, snorm: Norm) -> None:
    """Pass ``G[out]`` down to ``G[children]`` for one group of neurons."""
    gout = G[group.out]                                  # [g, n]
    ch = group.children                                  # [g, a]
    op = group.op
    if op == "not":
        _scatter_add(G, ch[:, 0], -gout)
        return
    if op.startswith("hedge:"):
        names = op[6:].split()
        x = V[ch[:, 0]]
        d = np.ones_like(x)
        for name in reversed(names):                     # innermost hedge first
            h = hedge_mod.HEDGES[name]
            d = d * h.derivative(x)
            x = h.fn(x)
        _scatter_add(G, ch[:, 0], gout * d)
        return
    X = V[ch]                                            # [g, a, n]
    g, a, n = X.shape
    # how this norm's derivative goes (its registry entry); a `use` context multiplies
    rule = "product" if op == "prod" else (tnorm if op == "and" else snorm).gradient
    if rule is None:                                     # check_supported refuses these first
        raise ValueError(f"no derivative for the norm of a `{op}` neuron")
    if rule == "select":
        smaller = op == "and"                            # min picks the smallest input
        best = X[:, 0].copy()
        sel = np.zeros((g, n), dtype=np.intp)
        for j in range(1, a):                            # arity (a few), never rules or samples
            wins = X[:, j] < best if smaller else X[:, j] > best    # ties: lowest index
            np.copyto(best, X[:, j], where=wins)
            sel[wins] = j
        local = (np.arange(a)[None, :, None] == sel[:, None, :]) * gout[:, None, :]
    else:
        F = X if rule == "product" else 1.0 - X          # "dual_product": of complements
        left = np.cumprod(np.concatenate([np.ones((g, 1, n)), F[:, :-1]], axis=1), axis=1)
        right = np.cumprod(np.concatenate([np.ones((g, 1, n)), F[:, :0:-1]], axis=1),
                           axis=1)[:, ::-1]
        local = left * right * gout[:, None, :]         # prod of the others (exact, no division)
    _scatter_add(G, ch.reshape(-1), local.reshape(g * a, n))


def _membership_grad(corners: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``d mu / d (a, b, c, d)`` of piecewise-linear memberships: ``[4, t, n]``.

    On the rising edge ``mu = (x - a) / (b - a)``, on the falling edge ``(d - x) / (d - c)``;
    where the two meet (a triangle's peak) the rising edge counts; saturated memberships and
    vertical edges have derivative 0.
    """
    A, B, C, D = (corners[:, i:i + 1] for i in range(4))
    out = np.zeros((4,) + x.shape)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        has_rise = np.isfinite(A) & np.isfinite(B) & (B > A)
        has_fall = np.isfinite(C) & np.isfinite(D) & (D > C)
        rise = np.where(has_rise, (x - A) / np.where(has_rise, B - A, 1.0), np.inf)
        fall = np.where(has_fall, (D - x) / np.where(has_fall, D - C, 1.0), np.inf)
        on_rise = has_rise & (rise > 0) & (rise < 1) & (rise <= fall)
        on_fall = has_fall & (fall > 0) & (fall < 1) & ~on_rise & (fall < rise)
        wr = np.where(has_rise, B - A, 1.0) ** 2
        wf = np.where(has_fall, D - C, 1.0) ** 2
        out[0] = np.where(on_rise, (x - B) / wr, 0.0)
        out[1] = np.where(on_rise, -(x - A) / wr, 0.0)
        out[2] = np.where(on_fall, (D - x) / wf, 0.0)
        out[3] = np.where(on_fall, (x - C) / wf, 0.0)
    return out


# ---- the descent ----------------------------------------------------------------------------

@dataclass(frozen=True)
class Adaptation:
    """What :func:`adapt` did: ``Q`` before, after each epoch, and the learned values."""

    parameters: Parameters
    values: np.ndarray
    history: tuple[float, ...]       # Q before the first epoch, then after each epoch
    converged: bool
    interrupted: bool = False
    rounded: bool = False            # the last entry of ``history`` is Q after rounding
    #: what stopped it when ``interrupted``: a Ctrl-C's KeyboardInterrupt, or a SIGTERM's or
    #: SIGHUP's :class:`~mitos_cli.errors.Terminated`, which the caller raises again once the
    #: epochs done are kept (a lesson stops, and the prompt ends, with the signal's code)
    stopped_by: KeyboardInterrupt | None = None

    @property
    def q_before(self) -> float:
        return self.history[0]

    @property
    def q_after(self) -> float:
        return self.history[-1]

    def changed(self) -> list[tuple[Knot, float, float]]:
        p = self.parameters
        return [(k, float(a), float(b)) for k, a, b in zip(p.knots, p.values, self.values)
                if a != b]


def _need(p: Parameters, ids: np.ndarray, k: int) -> np.ndarray:
    """Smallest allowed distances between consecutive knots of ``p.order[k]``."""
    gap = (p.order_gap[k] if p.order_gap else MIN_GAP) * p.scale[ids[0]]
    return np.minimum(gap, np.diff(p.values[ids])) * (1 - 1e-9)     # never stricter than the start


def descent_direction(p: Parameters, values: np.ndarray, grad: np.ndarray,
                      held: tuple[int, ...] = (), metric: np.ndarray | None = None) -> np.ndarray:
    """The projected steepest-descent direction (scaled coordinates) that does not push a knot
    through a bound or a neighbour it already touches (active constraints held fixed), nor
    move the knots ``held`` (whose move breaks a partition's coverage or distinctness).

    ``metric`` (positive, one per knot) measures a knot's move as cheaper the larger its entry:
    the direction is steepest in the coordinates ``y = u / sqrt(metric)``, so that it is
    ``-metric * grad`` where nothing binds and still a descent direction
    (``grad . d = -|P sqrt(metric) grad|^2``) that keeps every linear constraint."""
    g = grad * p.scale
    base = p.constraints if p.constraints is not None else np.zeros((0, len(values)))
    extra: list[np.ndarray] = [np.eye(len(values))[i] for i in held]
    root = None if metric is None else np.sqrt(metric)

    def null(rows: list[np.ndarray]) -> np.ndarray:
        C = np.vstack([base] + rows)
        return _null_projector(C if root is None else C * root)

    projector = null(extra) if held or root is not None else p.projector
    for _ in range(len(values) + 1):
        d = -(projector @ g) if root is None else -root * (projector @ (root * g))
        tol = 1e-7 * p.scale
        rows = []
        for i in np.flatnonzero(((values - p.lo <= tol) & (d < 0))
                                | ((p.hi - values <= tol) & (d > 0))):
            row = np.zeros(len(values))
            row[i] = 1.0
            rows.append(row)
        for k, ids in enumerate(p.order):
            close = np.diff(values[ids]) - _need(p, ids, k) <= tol[ids[1:]]
            closing = np.diff(d[ids]) < 0
            for k in np.flatnonzero(close & closing).tolist():
                row = np.zeros(len(values))
                row[ids[k]], row[ids[k + 1]] = -1.0, 1.0
                rows.append(row)
        if not rows:
            return d
        extra += rows
        projector = null(extra)
    return np.zeros_like(values)                         # pragma: no cover - all blocked


def feasible(p: Parameters, values: np.ndarray, partitions: bool = True) -> bool:
    """Knots inside their bounds and in their order, at least :data:`MIN_GAP` apart (crisp
    output values ``least_distance``); each partition covered and distinguishable (when it moved)."""
    if np.any(values < p.lo - 1e-12) or np.any(values > p.hi + 1e-12):
        return False
    left, right, need = p.neighbours
    if np.any(values[right] - values[left] < need):
        return False
    # crisp values: meaning.least_distance on the values as they are (in order by now)
    left, right, first, last, per, written = p.crisp_neighbours
    need = np.minimum(per * (values[last] - values[first]), written)
    if np.any(values[right] - values[left] < need * (1 - 1e-9)):
        return False
    return not partitions or partitions_hold(p, values)


def _scaled(direction: np.ndarray, rate: float) -> np.ndarray:
    """``direction`` scaled so that the knot that moves most moves ``rate`` x :data:`STEP`."""
    biggest = np.max(np.abs(direction)) if direction.size else 0.0
    return direction * (rate * STEP / biggest) if biggest > 1e-15 else np.zeros_like(direction)


def blocking(p: Parameters, values: np.ndarray, move: np.ndarray) -> tuple[int, ...]:
    """The knots whose own ``move`` (the others still) breaks the coverage or the
    distinctness of their partition; all the moving knots of a partition that only their
    moves together break. Held while the others move, as a knot touching a bound is (an
    active set): a step refused whole would stop the descent at the first knot that may not
    go where Q falls (``food.rancid``'s edge on the end of the universe)."""
    out: list[int] = []
    for part in p.partitions:
        mine = np.unique(part.knot[part.knot >= 0])
        moving = mine[move[mine] != 0]
        if not len(moving) or part.holds(values + move):
            continue
        alone = []
        for i in moving:
            trial = values.copy()
            trial[i] += move[i]
            if not part.holds(trial):
                alone.append(int(i))
        out += alone or [int(i) for i in moving]
    return tuple(out)


def partitions_hold(p: Parameters, values: np.ndarray) -> bool:
    """Coverage and distinguishability of every partition whose knots moved."""
    for part in p.partitions:
        mine = part.knot[part.knot >= 0]
        if not np.array_equal(values[mine], p.values[mine]) and not part.holds(values):
            return False
    return True


#: A knot's share of the step shrinks by this when its slope changes sign (it stepped over a
#: kink or a minimum of Q in it), and grows by :data:`GROW` (up to the whole step) when not.
SHRINK = 0.5
GROW = 1.2
#: The least share of the step a knot keeps.
FLOOR = 1e-6


def _knot_steps(factor: np.ndarray, previous: np.ndarray,
                g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each knot's share of the step (in (0, 1]) after one more slope ``g`` (scaled
    coordinates), as Rprop sets its step sizes (Riedmiller and Braun, 1993; iRprop-, Igel and
    Huesken, 2000): halved where the slope turned, grown where it kept its sign; a turned
    slope is forgotten, so that it shrinks the share once. And the slope to compare with next."""
    turned = g * previous < 0
    kept = g * previous > 0
    factor = np.where(turned, np.maximum(factor * SHRINK, FLOOR),
                      np.where(kept, np.minimum(factor * GROW, 1.0), factor))
    return factor, np.where(turned, 0.0, g)


def _line(p: Parameters, values: np.ndarray, grad: np.ndarray, Q: float, X: np.ndarray,
          targets: np.ndarray, rate: float, step: float, metric: np.ndarray | None,
          plain: np.ndarray) -> tuple[np.ndarray, float, float, bool]:
    """One epoch's trial steps along the direction of ``metric`` (``None``: the steepest,
    ``plain``): halved until ``Q`` falls and every constraint holds; a step that lowers ``Q``
    but breaks a partition holds the knots that break it and is tried again at the same size.
    ``(candidate, Q there, step, accepted)``."""
    direction = plain if metric is None else descent_direction(p, values, grad, metric=metric)
    direction = _scaled(direction, rate)
    candidate, q_new = values, Q
    if not direction.any():
        return candidate, q_new, step, False
    held: tuple[int, ...] = ()
    for _ in range(HALVINGS):
        candidate = values + step * direction * p.scale
        if feasible(p, candidate, partitions=False):       # the cheap checks first
            q_new = loss(with_values(p, candidate), X, targets)
            if q_new < Q and partitions_hold(p, candidate):
                return candidate, q_new, step, True
            if q_new < Q:               # a partition breaks: hold the knots that break it
                more = blocking(p, values, step * direction * p.scale)
                if more and not set(more) <= set(held):
                    held = tuple(sorted(set(held) | set(more)))
                    direction = _scaled(descent_direction(p, values, grad, held, metric), rate)
                    if not direction.any():
                        break
                    continue                # the others at the same step
        step *= 0.5
    return candidate, q_new, step, False


#: A step gaining less than this fraction of the starting ``Q`` is creeping along kinks: the
#: compass polls next.
STALL = 1e-6
#: Least gain (fraction of the starting ``Q``) of a point the compass takes, so that float
#: noise never makes it cycle.
GAIN = 1e-9
#: Free directions the compass tries in one epoch (two trial points each, at most), so that an
#: epoch costs at most a few evaluations of ``Q`` more than a gradient step.
POLL = 16
#: The compass stops (adaptation has converged) when its mesh falls below this fraction of
#: its first one, after a whole round of the directions at every mesh on the way down.
POLL_FLOOR = 2.0 ** -10


def _step(p: Parameters, values: np.ndarray, grad: np.ndarray, Q: float, X: np.ndarray,
          targets: np.ndarray, rate: float, step: float,
          factor: np.ndarray) -> tuple[np.ndarray | None, float]:
    """One epoch's gradient step: the steepest, and (when it had to be halved) the one with
    each knot its own share of the step; the lower ``Q`` of the two. ``(values, step)``, or
    ``None`` when neither lowers ``Q`` inside the constraints."""
    plain = descent_direction(p, values, grad)                   # scaled coordinates
    if not np.max(np.abs(plain), initial=0.0) > 1e-15:
        return None, step
    candidate, q_new, trial, accepted = _line(p, values, grad, Q, X, targets, rate, step,
                                              None, plain)
    if (not accepted or trial < step) and factor.min() < 1.0:
        # halved: a knot by a kink may set the step; each knot its own share
        other = _line(p, values, grad, Q, X, targets, rate, step, factor, plain)
        if other[3] and (not accepted or other[1] < q_new):
            candidate, q_new, trial, accepted = other
    return (candidate if accepted else None), trial


@dataclass
class _Compass:
    """A deterministic compass (pattern) search on the free directions, for where the gradient
    step stalls. Q is piecewise smooth: it has a kink wherever a knot crosses an example's
    input or a min / max changes hands, and where those kinks crowd, no slope the gradient
    sees points down although Q still falls along a free direction a little way off (the
    shipped lesson's descent crept to 334.6; polled, it reaches 298.7). Each direction
    is a knot's own move through the linear constraints (``projector``'s column: its ties and
    symmetric partners move with it); it is tried at the mesh on the side the slope says Q
    falls first, and a point is taken only if it keeps every constraint and lowers Q by at
    least ``gain``. A round of every direction with no point taken halves the mesh."""

    directions: np.ndarray                 # [D, P], the largest entry of each 1
    mesh: float                            # fraction of the universes
    first: float
    at: int = 0                            # the direction tried next
    misses: int = 0                        # directions tried in a row without a point taken

    @classmethod
    def of(cls, p: Parameters, rate: float) -> _Compass:
        rows: list[np.ndarray] = []
        for column in p.projector.T:
            biggest = np.max(np.abs(column))
            if biggest > 1e-9 and not any(np.allclose(column / biggest, s * r)
                                          for r in rows for s in (1.0, -1.0)):
                rows.append(column / biggest)
        first = rate * STEP
        return cls(np.array(rows).reshape(len(rows), len(p.values)), first, first)

    @property
    def done(self) -> bool:
        return not len(self.directions) or self.mesh < self.first * POLL_FLOOR

    def poll(self, p: Parameters, values: np.ndarray, Q: float, grad: np.ndarray,
             X: np.ndarray, targets: np.ndarray, gain: float) -> np.ndarray | None:
        """Up to :data:`POLL` directions from where the last poll left off: the first point
        that keeps every constraint and lowers ``Q`` by ``gain``, or ``None``."""
        for _ in range(POLL):
            if self.done:
                return None
            move = self.directions[self.at] * p.scale
            side = -1.0 if grad @ move > 0 else 1.0
            for sign in (side, -side):
                trial = values + sign * self.mesh * move
                if feasible(p, trial) and loss(with_values(p, trial), X, targets) < Q - gain:
                    self.misses = 0
                    return trial
            self.at = (self.at + 1) % len(self.directions)
            self.misses += 1
            if self.misses >= len(self.directions):
                self.misses, self.mesh = 0, self.mesh * 0.5
        return None


def adapt(compiled: CompiledRuleBase, X: np.ndarray, targets: np.ndarray, *, epochs: int = 50,
          rate: float = 0.5, on_epoch: Callable[[int, float], None] | None = None,
          parameters: Parameters | None = None, constrained: bool = True,
          on_values: Callable[[np.ndarray], None] | None = None) -> Adaptation:
    """Gradient descent on ``Q`` (eqs. 13-14): ``epochs`` full-batch steps of learning factor
    ``rate`` in (0, 1), each halved until ``Q`` decreases inside the constraints
    (``parameters``, else :func:`parameterise` with ``constrained``); where the step stalls,
    an epoch is a few of the compass's trials (:class:`_Compass`), which lower ``Q`` or keep
    it. ``on_epoch`` hears ``(epoch, Q)`` and ``on_values`` the values after
    each epoch."""
    if not 0.0 < rate < 1.0:
        raise LessonError(f"the learning factor must lie in (0, 1), not {rate:g}",
                          hint="the paper's eta: try `rate 0.5`")
    p = parameters or parameterise(compiled, constrained=constrained)
    values = p.values.copy()
    Q, grad = gradient(p, values, X, targets)
    history = [Q]
    step = 1.0
    factor = np.ones(len(values))        # each knot's share of the step (_knot_steps)
    previous = np.zeros(len(values))
    compass = _Compass.of(p, rate)       # polls the free directions where the step stalls
    polling = False
    converged = False
    stopped_by: KeyboardInterrupt | None = None
    try:
        for epoch in range(1, epochs + 1):
            if Q <= 0.0:
                converged = True
                break
            moved = False
            if not polling:
                factor, previous = _knot_steps(factor, previous, grad * p.scale)
                candidate, trial = _step(p, values, grad, Q, X, targets, rate, step, factor)
                moved = candidate is not None
                if candidate is not None:
                    step, values = trial, candidate
                    Q, grad = gradient(p, values, X, targets)
                # refused, or gaining too little to be worth a step: the slopes mislead here
                polling = not moved or history[-1] - Q <= STALL * history[0]
            if polling and not moved:
                found = compass.poll(p, values, Q, grad, X, targets, GAIN * history[0])
                if found is None and compass.done:
                    converged = True
                    break
                if found is not None:        # else an epoch of the compass's search, Q kept
                    values, polling, step = found, False, 1.0
                    Q, grad = gradient(p, values, X, targets)
            history.append(Q)
            if on_epoch is not None:
                on_epoch(epoch, Q)
            if on_values is not None:
                on_values(values)
            step = min(1.0, step * 2.0)
    except KeyboardInterrupt as stop:   # (a SIGTERM, a SIGHUP too: Terminated)
        stopped_by = stop             # keep what the completed epochs learned
    q_learned = history[-1]
    values, q_final = _round(p, values, X, targets, history[0], q_learned)
    rounded = q_final != q_learned
    if rounded:
        history.append(q_final)
    return Adaptation(p, values, tuple(history), converged, stopped_by is not None, rounded,
                      stopped_by)


def _round(p: Parameters, values: np.ndarray, X: np.ndarray, targets: np.ndarray,
           q_start: float, q_learned: float) -> tuple[np.ndarray, float]:
    """Learned values on a readable grid (a few decimals), constraints kept exactly and ``Q``
    no worse than where it started; when that grid breaks a constraint (two knots rounded
    closer than :data:`MIN_GAP`) a grid one or two decimals finer; failing that, the learned
    values as they are (never the starting values: that would throw the learning away)."""
    changed = values != p.values
    if not changed.any():
        return p.values.copy(), q_start
    for extra in range(3):
        decimals = p.decimals + extra
        out = np.where(changed, _on_grid(values, decimals), values) + 0.0   # (-0.0 is 0)
        for dep, others, coef in p.dependents:        # symmetric triangles stay symmetric
            out[dep] = round(float(coef @ out[others]), int(decimals[dep]))
        if feasible(p, out):
            q = loss(with_values(p, out), X, targets)
            if q <= q_start:
                return out, q
    return values.copy(), q_learned


def _on_grid(values: np.ndarray, decimals: np.ndarray) -> np.ndarray:
    """``values`` rounded to ``decimals`` (``-2``: to hundreds), each the double nearest its
    decimal: a power of ten up to 10^22 is exact, so one product or quotient of it rounds
    once; past that Python's ``round`` rounds in decimal (a universe of 1e149 learned
    ``-6.2499999999999996e+147`` for -6.25e147, NumPy scaling by an inexact 10^-145)."""
    scale = 10.0 ** np.minimum(np.abs(decimals), 22)
    out = np.where(decimals >= 0, np.round(values * scale) / scale,
                   np.round(values / scale) * scale)
    for i in np.flatnonzero(np.abs(decimals) > 22):
        out[i] = round(float(values[i]), int(decimals[i]))
    return out


# ---- writing the learned values back into the model -------------------------------------------

def learned_rulebase(p: Parameters, values: np.ndarray) -> RuleBase:
    """The rule base with the learned values: terms with new parameters (in the form and
    decimals the grid gives), rules with new crisp consequents."""
    c = p.compiled
    rb = c.rulebase
    new_terms: dict[tuple[str, str], tuple[float, ...]] = {}
    for t in np.flatnonzero((p.corner_knot >= 0).any(axis=1)):
        var, name = c.term_names[t]
        term = c.variables[var].term(name)
        mine = p.corner_knot[t][p.corner_knot[t] >= 0]
        if np.array_equal(values[mine], p.values[mine]):
            continue                        # untouched: keep its numbers as written
        corners = [float(values[i]) if i >= 0 else o
                   for i, o in zip(p.corner_knot[t], term.corners)]
        dec = int(p.decimals[p.corner_knot[t][p.corner_knot[t] >= 0][0]])
        params = tuple(round(v, dec + NOISE) for v in FROM_CORNERS[term.shape](*corners))
        if params != term.params:
            new_terms[(var, name)] = params
    for i, knot in enumerate(p.knots):
        if knot.kind == "output" and values[i] != p.values[i]:
            new_terms[(knot.var, knot.label.split(": ", 1)[1])] = (float(values[i]),)
    for (var, name), ids in p.out_terms.items():        # Mamdani output sets
        term = c.variables[var].term(name)
        mine = ids[ids >= 0]
        if term.shape == "singleton" or np.array_equal(values[mine], p.values[mine]):
            continue
        corners = [float(values[i]) if i >= 0 else o for i, o in zip(ids, term.corners)]
        dec = int(p.decimals[ids[ids >= 0][0]])
        params = tuple(round(v, dec + NOISE) for v in FROM_CORNERS[term.shape](*corners))
        if params != term.params:
            new_terms[(var, name)] = params
    termsets = tuple(dataclasses.replace(ts, variables=tuple(
        v.with_terms(tuple(t.with_params(new_terms[(v.name, t.name)])
                           if (v.name, t.name) in new_terms else t for t in v.terms))
        for v in ts.variables)) for ts in rb.termsets)
    owners = _owners(rb, c.behavior)
    crisp: dict[tuple[str, int], dict[str, float]] = {}
    for r, j in zip(*np.nonzero(p.cons_knot >= 0)):
        i = p.cons_knot[r, j]
        if p.knots[i].kind == "crisp" and values[i] != p.values[i]:
            crisp.setdefault(owners[r], {})[c.outputs[j]] = float(values[i])
    behaviors = []
    for b in rb.behaviors:
        rules = list(b.rules)
        for (owner, index), new in crisp.items():
            if owner == b.name:
                rules[index] = _with_crisp(rules[index], new)
        behaviors.append(dataclasses.replace(b, rules=tuple(rules)))
    return dataclasses.replace(rb, termsets=termsets, behaviors=tuple(behaviors))


def _with_crisp(rule: Rule, new: dict[str, float]) -> Rule:
    cons = tuple(dataclasses.replace(c, value=new[c.var]) if c.term is None and c.var in new
                 else c for c in rule.consequents)
    return dataclasses.replace(rule, consequents=cons)


__all__ = ["Adaptation", "Knot", "Parameters", "adapt", "feasible", "gradient",
           "learned_rulebase", "loss", "parameterise", "with_values"]
