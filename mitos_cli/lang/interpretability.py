"""What keeps a variable's terms meaning what their names say: order, coverage,
distinguishability and a centre term held at its point.

Interpretable neuro-fuzzy learning (Nauck and Kruse's NEFCON / NEFCLASS, Espinosa and
Vandewalle, the survey of Gacto et al., 2011) keeps these properties while it adapts; this
module measures them, for ``mitos check`` (:func:`findings`) and for the constraints of
:mod:`mitos_cli.teach.adapt` (the array functions, which take the terms' corners as numbers).

=================  =========================================================================
property           held when
=================  =========================================================================
order              the terms' peaks or cores (a crisp term's value) follow the order in which
                   the terms are written, increasing or decreasing, none equal
coverage           at every point of the universe the largest membership is at least
                   :data:`COVERAGE`
distinguishable    two fuzzy sets of one variable have a Jaccard similarity
                   ``|A and B| / |A or B|`` (min / max, integrated over the universe) of at most
                   :data:`SIMILARITY`; two neighbouring crisp values lie at least
                   :data:`DISTINCT` times the spacing of as many values spread evenly
                   from the smallest to the largest (steering 30 ... 150, 7 terms: 10 deg)
centre             when the terms are written mirror-symmetric about a point (an odd number
                   of terms; the first and last, second and second-last, ... are mirror
                   images, corner for corner), the middle term stays centred on that point
                   (``heading.AHEAD`` at 0, ``steering.ST`` at 90), unless it is written
                   with ``held: false``; a term written with ``held: POINT`` stays centred
                   on that point (what ``mitos teach`` saves once its neighbours have moved
                   out of symmetry, so that the hold outlives the symmetry it came from);
                   not measured on terms out of order (their neighbours in writing are not
                   their neighbours) nor on three terms whose outer two are crisp values
                   (any two values mirror each other)
=================  =========================================================================

Piecewise-linear terms (triangles, trapezoids, shoulders) are measured exactly, on the points
where their memberships bend (:func:`breakpoints`). A variable with any other shape of the
registry (gaussian, bell, sigmoid, ``discrete``, ...) is measured on samples
(:func:`sample_points`): :data:`RESOLUTION` evenly spaced points of the universe, plus the
breakpoints of its piecewise-linear terms (so those stay exact) and every term's centre; the
coverage is the least on those points and the similarity the trapezoid rule over them (on the
universe of 1,000 intervals, a membership of slope at most ``s`` per universe-width can dip
below its sampled value by at most ``s / 2,000`` between two samples). Such terms are ordered by
the registry's centre (a gaussian's mean, a sigmoid's inflection); a term held at a point of
symmetry is looked for among piecewise-linear terms only. Everything here is pure and
vectorized over points (and over terms, for piecewise-linear ones).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from .envelope import regular as upper_envelope_regular
from .envelope import upper_envelope
from .terms import Term, Variable

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Sequence

    #: memberships of distinct terms k[p] at the points x[at[p]]: rows(k, at)
    Rows = Callable[[np.ndarray, np.ndarray], np.ndarray]

#: Least largest-membership anywhere on an input's universe (a Ruspini partition has 0.5).
COVERAGE = 0.5
#: Largest Jaccard similarity two fuzzy sets of one variable may have.
SIMILARITY = 0.5
#: Least distance between two neighbouring crisp terms of one variable, as a fraction of the
#: spacing of as many values spread evenly from the smallest to the largest (steering: 10).
DISTINCT = 0.5
#: Relative tolerance (of the universe width) for "at its point" and "in order".
TOLERANCE = 1e-6
#: Evenly spaced points of the universe on which terms that are not piecewise linear are
#: measured (plus the corners and centres of the variable's terms): 1,000 intervals.
RESOLUTION = 1001
#: Points per universe when looking for gaps between the terms of one input (plus the
#: corners inside it).
GAP_RESOLUTION = 2001
#: What to do about a term gap (``mitos check``'s ``term-gap``, teach's interpretability line).
GAP_HINT = "widen a neighbouring term (or add one) so that the terms cover the universe"


@dataclass(frozen=True)
class Issue:
    """One interpretability problem of one variable."""

    code: str          # "term-order", "coverage", "indistinct", "off-centre"
    variable: str
    terms: tuple[str, ...]
    message: str
    hint: str


# ---- measures on corner arrays (what adaptation calls on every trial step) ---------------------

def memberships(corners: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``mu[t, n]`` of piecewise-linear terms given by their corners ``[t, 4]`` (``a <= b <= c
    <= d``, infinite for a shoulder's open side) at the points ``x[n]``."""
    corners = corners + 0.0      # -0.0 is 0.0: an edge [0, -0] divided by -0.0 (1 left of it)
    a, b, c, d = (corners[:, i:i + 1] for i in range(4))
    # (an edge narrower than a normal float overflows to +-inf: clipped, a vertical edge)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        mu = np.fmin((x - a) / (b - a), (d - x) / (d - c))    # fmin: a NaN edge gives way
    mu = np.clip(mu, 0.0, 1.0)
    # NaN where both edges are NaN: an infinite corner (inf / inf) or x on a vertical edge
    # (0 / 0), where the term is 1
    mu[np.isnan(mu)] = 1.0
    return mu


def breakpoints(corners: np.ndarray, universe: tuple[float, float]) -> np.ndarray:
    """Every point of the universe where the min or max of two of these piecewise-linear
    terms can bend: its ends, the corners and where two sloped edges cross (sorted). Two
    edges cross only where both are, so only edges whose stretches overlap are crossed
    (found in order of where they begin): the lines of every two edges, crossed, gave up to
    (2 t)^2 points, each a column of the memberships (2,000 triangles took 23 GB)."""
    lo, hi = universe
    a, b, c, d = corners.T
    rise = np.isfinite(a) & np.isfinite(b) & (b > a)
    fall = np.isfinite(c) & np.isfinite(d) & (d > c)
    # each sloped edge as mu = slope * x + offset (an edge narrower than a normal float is a
    # vertical one: its slope overflows, and the crossings it gives are not finite)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        slope = np.concatenate([1.0 / (b[rise] - a[rise]), -1.0 / (d[fall] - c[fall])])
        offset = np.concatenate([-a[rise] / (b[rise] - a[rise]), d[fall] / (d[fall] - c[fall])])
        # each edge once: a term repeated gives the same edge again, which crosses its twin
        # nowhere (17,500 copies of one triangle were 600 million pairs: 24 GB, then killed)
        edges = np.unique(np.stack([np.concatenate([a[rise], c[fall]]),
                                    np.concatenate([b[rise], d[fall]]), slope, offset], axis=1),
                          axis=0)
        slope, offset = edges[:, 2], edges[:, 3]
        i, j = _overlapping(edges[:, 0], edges[:, 1])
        cross = (offset[j] - offset[i]) / (slope[i] - slope[j])
    x = np.concatenate([[lo, hi], corners[np.isfinite(corners)], cross])
    return np.unique(x[np.isfinite(x) & (x >= lo) & (x <= hi)])


def _overlapping(left: np.ndarray, right: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every pair ``(i, j)``, ``i != j``, of the stretches ``[left, right]`` that overlap
    (touching counts), each once."""
    order = np.argsort(left, kind="stable")
    # the stretches beginning after i's and by its right end: i + 1 ... last[i] - 1 in order
    last = np.searchsorted(left[order], right[order], side="right")
    count = np.maximum(last - np.arange(len(order)) - 1, 0)
    i = np.repeat(np.arange(len(order)), count)
    j = i + 1 + np.arange(len(i)) - np.repeat(np.cumsum(count) - count, count)
    return order[i], order[j]


def coverage(corners: np.ndarray, universe: tuple[float, float],
             besides_gaps: bool = False) -> tuple[float, float]:
    """The least largest-membership on the universe and where it is, exactly: the upper
    envelope of piecewise-linear functions is smallest at one of its :func:`breakpoints`.
    ``besides_gaps``: the least above 0 (where no term is above 0 is a gap, reported apart)."""
    x = breakpoints(corners, universe)
    return least_top(envelope(corners, x), x, universe, besides_gaps)


def coverage_on(mu: np.ndarray, x: np.ndarray, universe: tuple[float, float],
                besides_gaps: bool = False) -> tuple[float, float]:
    """:func:`coverage` from the memberships ``mu[t, n]`` at the points ``x[n]``."""
    return least_top(mu.max(axis=0), x, universe, besides_gaps)


def envelope(corners: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The largest membership of these piecewise-linear terms at each point of ``x``: each
    term measured only at the points from its left corner to its right one, where it can be
    above 0, a block of :data:`PAIR_BLOCK` memberships at a time. (Every term at every point
    is terms times points, quadratic in the terms, which have about four breakpoints each:
    20,000 triangles took most of a minute.)"""
    order = None if len(x) < 2 or np.all(x[1:] >= x[:-1]) else np.argsort(x, kind="stable")
    xs = x if order is None else x[order]
    if len(corners) * len(x) >= SWEEP_FROM and len(x) and np.isfinite(xs[[0, -1]]).all() \
            and xs[-1] > xs[0] and np.all(corners[:, 1:] >= corners[:, :-1]):
        return _swept(corners, x, order, xs)
    return _over_supports(corners, order, xs)


def _over_supports(corners: np.ndarray, order: np.ndarray | None, xs: np.ndarray
                   ) -> np.ndarray:
    """:func:`envelope`, each term measured at every point of its support (``xs``: the points
    in order, ``order`` where each comes from, ``None`` if they were in order)."""
    start = np.searchsorted(xs, corners[:, 0], side="left")
    count = np.maximum(np.searchsorted(xs, corners[:, 3], side="right") - start, 0)
    top = np.zeros(len(xs))
    ends = np.cumsum(count)
    first = 0
    while first < len(corners):
        last = max(first + 1, int(np.searchsorted(ends, ends[first] - count[first] + PAIR_BLOCK,
                                                  side="right")))
        term, at = _supports(start[first:last], count[first:last])
        mu = memberships_at(corners[first + term], xs[at])
        np.maximum.at(top, at if order is None else order[at], mu)
        first = last
    return top


def _swept(corners: np.ndarray, x: np.ndarray, order: np.ndarray | None, xs: np.ndarray
           ) -> np.ndarray:
    """:func:`envelope` of terms whose corners are in order, at finite points ``x`` (``xs`` in
    order, ``order`` as for :func:`_over_supports`), from the upper envelope of the terms'
    edges and cores (:func:`~mitos_cli.lang.envelope.upper_envelope`; terms that are not three
    such segments in floating point measured over their support). The same bits: each
    point's largest membership is one term's, measured with the same operations; and a
    largest membership of 0 is -0.0 only at the point -0.0, on an edge rising from 0 (``-0.0
    - 0.0``), where it is the sign of the last term measured there, as in
    :func:`_over_supports` (elsewhere every term measured at a point gives +0.0 or more)."""
    distinct = np.unique(corners + 0.0, axis=0)          # a repeated term measured once
    fast = upper_envelope_regular(distinct)
    top = upper_envelope(distinct[fast], xs, memberships_at)
    if not fast.all():
        np.maximum(top, _over_supports(distinct[~fast], None, xs), out=top)
    if order is not None:
        top[order] = top.copy()
    signed = np.flatnonzero((x == 0) & np.signbit(x) & (top == 0))
    if len(signed):
        top[signed] = _over_supports(corners, None, x[signed])
    return top


def _supports(start: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each term ``t`` paired with the points ``start[t]`` ... ``start[t] + count[t] - 1``,
    flat: which term and which point."""
    term = np.repeat(np.arange(len(count)), count)
    at = start[term] + np.arange(len(term)) - np.repeat(np.cumsum(count) - count, count)
    return term, at


def memberships_at(corners: np.ndarray, x: np.ndarray) -> np.ndarray:
    """:func:`memberships` of term ``p`` (``corners[p]``) at point ``x[p]`` for each ``p``,
    with the same operations, so the same bits."""
    a, b, c, d = (corners + 0.0).T
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        mu = np.fmin((x - a) / (b - a), (d - x) / (d - c))
    mu = np.clip(mu, 0.0, 1.0)
    mu[np.isnan(mu)] = 1.0
    return mu


def least_top(top: np.ndarray, x: np.ndarray, universe: tuple[float, float],
              besides_gaps: bool = False) -> tuple[float, float]:
    """:func:`coverage` from the largest membership ``top[n]`` at the points ``x[n]``."""
    if besides_gaps:
        x, top = x[top > 0], top[top > 0]
        if not len(top):
            return 1.0, float(universe[0])
    k = int(np.argmin(top))
    return float(top[k]), float(x[k])


def coverage_spans(corners: np.ndarray, universe: tuple[float, float], *,
                   bends: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The universe cut into stretches the terms cover to :data:`COVERAGE` and stretches
    they cover less, as ``(ends[s + 1], least[s])``: stretch ``s`` is ``[ends[s], ends[s +
    1]]`` and ``least[s]`` the least largest-membership on it (exactly, as
    :func:`span_coverage`), at most :data:`COVERAGE`.

    What adaptation keeps per stretch: one least coverage for the whole universe is vacuous
    as soon as the written terms leave a gap anywhere (a converted tipper's ``food`` is 0 on
    [3, 7]), and then a term could leave the end of the universe uncovered. The envelope
    crosses the level only where an edge does, or jumps at a vertical edge (a breakpoint), so
    between those points each piece lies wholly on one side of it. ``bends``: the
    :func:`breakpoints`, if already known (at 2,000 terms that all overlap, 4.8 million
    points and 0.3 s)."""
    lo, hi = universe
    bends = breakpoints(corners, universe) if bends is None else bends
    a, b, c, d = corners.T
    with np.errstate(invalid="ignore", over="ignore"):
        half = np.concatenate([a + COVERAGE * (b - a), d - COVERAGE * (d - c)])
    x = np.union1d(bends, half[np.isfinite(half) & (half > lo) & (half < hi)])
    if len(x) < 2:
        return np.array([lo, hi], dtype=float), np.array([span_coverage(
            corners, universe, np.array([lo, hi], dtype=float), bends=bends)[0]])
    mid = 0.5 * (x[:-1] + x[1:])
    covered = envelope(corners, mid) >= COVERAGE - 1e-12
    cut = np.flatnonzero(covered[1:] != covered[:-1]) + 1
    ends = np.concatenate([[x[0]], x[cut], [x[-1]]]).astype(float)
    least = span_coverage(corners, universe, ends, bends=bends)
    return ends, np.minimum(least, COVERAGE)


def uncovered(corners: np.ndarray, universe: tuple[float, float], *,
              bends: np.ndarray | None = None) -> list[tuple[float, float]]:
    """The stretches ``(left, right)`` of the universe where the largest membership of these
    piecewise-linear terms is below :data:`COVERAGE`, exactly (:func:`coverage_spans`;
    ``bends`` as there)."""
    ends, least = coverage_spans(corners, universe, bends=bends)
    return [(float(a), float(b)) for a, b, m in zip(ends[:-1], ends[1:], least)
            if m < COVERAGE - 1e-9 and b > a]


def uncovered_on(top: np.ndarray, x: np.ndarray) -> list[tuple[float, float]]:
    """:func:`uncovered` on samples: each run of the points ``x`` where the largest
    membership ``top`` is below :data:`COVERAGE`, its ends where ``top`` crosses the level
    between a sample and its neighbour (linearly; an end of the universe is an end)."""
    below = top < COVERAGE - 1e-9
    padded = np.concatenate([[False], below, [False]])
    edges = np.flatnonzero(padded[1:] != padded[:-1])
    out = []
    for a, b in zip(edges[::2], edges[1::2]):          # samples a .. b - 1 are below
        left = x[a] if a == 0 else _crossing(x[a - 1], x[a], top[a - 1], top[a])
        right = x[b - 1] if b == len(x) else _crossing(x[b], x[b - 1], top[b], top[b - 1])
        out.append((float(left), float(right)))
    return out


def _crossing(x_in: float, x_out: float, m_in: float, m_out: float) -> float:
    """Where the line from ``(x_in, m_in)`` (covered) to ``(x_out, m_out)`` (below) reaches
    :data:`COVERAGE`."""
    return x_in + (m_in - COVERAGE) / (m_in - m_out) * (x_out - x_in)


def span_coverage(corners: np.ndarray, universe: tuple[float, float],
                  ends: np.ndarray, *, bends: np.ndarray | None = None) -> np.ndarray:
    """The least largest-membership on each stretch ``[ends[s], ends[s + 1]]``, exactly: at
    the :func:`breakpoints` inside it and its ends, and at both ends of each piece between
    them as the piece's line reaches them (a term is 1 on its vertical edge, and 0 just
    beside it: ``[0, 0, 3, 3]`` and ``[7, 7, 10, 10]`` leave (3, 7) uncovered although both
    are 1 at 3 and at 7). ``bends``: the :func:`breakpoints`, if already known."""
    x = np.union1d(breakpoints(corners, universe) if bends is None else bends, ends)
    top = envelope(corners, x)
    width = np.diff(x)
    m1 = envelope(corners, x[:-1] + width / 3)
    m2 = envelope(corners, x[:-1] + 2 * width / 3)
    del width
    # the line's ends, clip(min(2 m1 - m2, 2 m2 - m1)), in place (each array is millions of
    # points where many terms overlap)
    piece = 2 * m1
    piece -= m2
    m2 *= 2
    m2 -= m1
    del m1
    np.minimum(piece, m2, out=piece)
    del m2
    np.clip(piece, 0.0, 1.0, out=piece)
    first = np.searchsorted(x, ends[:-1])
    last = np.searchsorted(x, ends[1:])
    return np.array([min(top[i:j + 1].min(), piece[i:j].min(initial=1.0))
                     for i, j in zip(first, last)])


def similarity(corners: np.ndarray, universe: tuple[float, float]) -> np.ndarray:
    """Jaccard similarity ``[t, t]`` of every pair of terms (1 on the diagonal), exactly: the
    trapezoid rule on the :func:`breakpoints`, between which min and max are linear."""
    x = breakpoints(corners, universe)
    return similarity_on(memberships(corners, x), x)


def similarity_on(mu: np.ndarray, x: np.ndarray) -> np.ndarray:
    """:func:`similarity` from the memberships ``mu[t, n]`` at the points ``x[n]`` (the
    trapezoid rule over them). Terms with the same memberships are measured once (a term
    line repeated 750 times), a row of terms at a time and only for the pairs that are both
    above 0 somewhere (any other pair's minimum is 0 everywhere: similarity 0). Each pair's
    sum is the same reduction over the same points as over the whole ``[t, t, n]`` at once,
    so the same bits; that cube was 4.4 GB for 200 triangles, and a MemoryError for 750
    sampled terms."""
    distinct, which = np.unique(mu, axis=0, return_inverse=True)
    if len(distinct) < len(mu):
        which = which.reshape(-1)
        return similarity_on(distinct, x)[np.ix_(which, which)]
    t = mu.shape[0]
    dx = np.diff(x)
    out = np.zeros((t, t))

    def area(m: np.ndarray) -> np.ndarray:
        return ((m[..., 1:] + m[..., :-1]) * 0.5 * dx).sum(axis=-1)

    above = (mu > 0).astype(np.float32)
    meets = (above @ above.T) > 0              # counts of common points, exact enough for > 0
    for i in range(t):
        j = np.flatnonzero(meets[i])
        if len(j):
            inter = area(np.minimum(mu[i], mu[j]))
            union = area(np.maximum(mu[i], mu[j]))
            out[i, j] = np.divide(inter, union, out=np.zeros_like(inter), where=union > 0)
    return out


#: Least terms times points from which :func:`envelope` sweeps the terms' upper envelope
#: (:func:`~mitos_cli.lang.envelope.upper_envelope`) rather than measure every term at every
#: point of its support.
SWEEP_FROM = 1 << 14

#: Most memberships :func:`most_similar_on` and :func:`envelope` form in one array (terms or
#: pairs times points): 8 MB, a few such arrays at once, whatever the number of terms.
PAIR_BLOCK = 1 << 20


def most_similar_on(mu: np.ndarray, x: np.ndarray) -> tuple[float, int, int]:
    """The largest similarity of two different terms of ``mu[t, n]`` and which two: the pair
    :func:`similarity_on`'s matrix gives first in reading order, with the same bits, but in
    memory proportional to ``mu`` (``mitos check`` on 20,000 terms formed that ``[t, t]``
    matrix and two copies, 6.6 GB). Repeated terms are measured once; a term is measured
    only against the terms whose support (first to last point above 0) overlaps its own,
    found in order of where the supports begin, in blocks of :data:`PAIR_BLOCK`; any other
    pair has similarity 0. Every term's row of the matrix holds the same values as any row
    of a term equal to it, so its largest is known per distinct term."""
    distinct, which, counts = _distinct_rows(mu)
    above = distinct > 0
    some = above.any(axis=1)
    start = np.where(some, above.argmax(axis=1), 0)
    end = np.where(some, distinct.shape[1] - 1 - above[:, ::-1].argmax(axis=1), -1)
    return _most_similar(lambda k, at: distinct[k[:, None], at], x, which, counts, start, end)


def most_similar(corners: np.ndarray, universe: tuple[float, float]) -> tuple[float, int, int]:
    """The largest similarity of two different piecewise-linear terms and which two, as
    :func:`most_similar_on` on their memberships at the :func:`breakpoints`, without forming
    those memberships: a term's row only when measured (t terms have about 4 t breakpoints,
    so all the rows at once are quadratic in the terms: 20,000 triangles, 10 GB)."""
    return _linear_most(corners, breakpoints(corners, universe))


def most_similar_by_pairs(corners: np.ndarray, universe: tuple[float, float]
                          ) -> tuple[float, int, int] | None:
    """:func:`most_similar`, each overlapping pair summed on its own points: the universe's
    ends, the pair's corners and the crossings of its edges, where the min and the max of
    two piecewise-linear terms can bend, so the trapezoid rule is as exact there as on every
    breakpoint of the variable (about 14 points a pair, where those are quadratic in the
    terms: 300 triangles that all overlap took 56 s in `mitos check`). Repeated terms are
    measured once. ``None`` where a term has a vertical edge (a crisp step: its trapezoids
    depend on the points beside it) or there are fewer than two terms."""
    lo, hi = universe
    distinct, which, counts = _distinct_rows(corners + 0.0)
    a, b, c, d = distinct.T
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        lines = (1.0 / (b - a), -a / (b - a), -1.0 / (d - c), d / (d - c))
    rise, fall = np.isfinite(a) & np.isfinite(b), np.isfinite(c) & np.isfinite(d)
    if len(corners) < 2 or not (np.isfinite(lines[0][rise]).all()
                                and np.isfinite(lines[2][fall]).all()
                                and (b[rise] > a[rise]).all() and (d[fall] > c[fall]).all()):
        return None
    i, j = _overlapping(a, d)
    twice = np.flatnonzero(counts > 1)                  # a repeated term against its copy
    i, j = np.concatenate([np.minimum(i, j), twice]), np.concatenate([np.maximum(i, j), twice])
    # |A and B| <= the smaller area and |A or B| >= the larger: pairs measured from the
    # likeliest down, until no pair left can reach the largest found (each pair's sum is
    # its own row, so the same bits however many are measured)
    area = _areas(distinct, lo, hi)
    bound, likeliest = _likeliest(area[i], area[j])
    s = np.full(len(i), -1.0)                           # not measured: below the largest
    step = max(1, PAIR_BLOCK // 16)
    most = 0.0
    for k in range(0, len(i), step):                    # blocks of pairs, a row of points each
        p = likeliest[k:k + step]
        if bound[p[0]] < most - NEAR_MOST:
            break
        s[p] = _pairs_on_own_points(distinct, i[p], j[p], lines, lo, hi)
        most = max(most, float(s[p].max()))
    top = float(s.max()) if len(s) else 0.0
    if top <= 0:
        return 0.0, 0, 1
    # the whole matrix's first in reading order: the smallest row, then the smallest column
    occurs = [np.flatnonzero(which == k)[:2] for k in range(len(distinct))]
    best: tuple[int, int] | None = None
    for k, v in zip(i[s == top], j[s == top]):
        p, q = (occurs[k][0], occurs[k][1]) if k == v else sorted((occurs[k][0], occurs[v][0]))
        best = (int(p), int(q)) if best is None else min(best, (int(p), int(q)))
    assert best is not None
    return top, best[0], best[1]


#: How far below the largest similarity measured a pair's own points (to rounding) a pair
#: is measured again over every breakpoint, in :func:`most_similar_beside_steps`.
NEAR_MOST = 1e-9


def most_similar_beside_steps(corners: np.ndarray, universe: tuple[float, float],
                              x: np.ndarray, above: float) -> tuple[float, int, int] | None:
    """:func:`most_similar` of terms some of which have an upright edge (a crisp step),
    whose trapezoids over the breakpoints ``x`` depend on the breakpoint beside the step
    (the trapezoid from it to the step is half the area between them, where the term is 0):
    with the same bits where the largest similarity is above ``above``, and its value only
    (to rounding, with the pair ``0, 1``) where it is not; ``None`` where an edge is too
    narrow for its slope to be a normal number, or there are fewer than two terms.

    Each overlapping pair is measured first on its own points, as in
    :func:`most_similar_by_pairs`, with the breakpoint before each rising step and after
    each falling one: on those the trapezoid rule is the one over every breakpoint, to
    rounding. Only the pairs within :data:`NEAR_MOST` of the largest are then summed over
    every breakpoint, each as :func:`_linear_most` sums it (in its batch and block, so with
    the same bits), and the first row and column holding the largest picked as it picks
    them. Over every breakpoint, every pair: 300 triangles that all overlap and one crisp
    step took 200 s in `mitos check`."""
    lo, hi = universe
    if len(corners) < 2:
        return None
    distinct, which, counts = _distinct_rows(corners)
    edges = _step_edges(distinct + 0.0, x, lo)
    if edges is None:
        return None
    i, j = _overlapping(distinct[:, 0], distinct[:, 3])
    twice = np.flatnonzero(counts > 1)                  # a repeated term against its copy
    i, j = np.concatenate([np.minimum(i, j), twice]), np.concatenate([np.maximum(i, j), twice])
    # the terms as _linear_most has them: where each is above 0 on x
    start = np.searchsorted(x, distinct[:, 0], side="left")
    end = np.searchsorted(x, distinct[:, 3], side="right") - 1
    some = start <= end
    both = some[i] & some[j]
    di, dj = i[both], j[both]
    s = _screened(distinct + 0.0, di, dj, edges, lo, hi)
    most = float(s.max()) if len(s) else 0.0
    if most < above:
        return most, 0, 1
    near = s >= most - NEAR_MOST
    spans = _Spans(start, end, some)
    pk, pv, best = _first_pass(distinct, x, counts, spans, di[near], dj[near])
    r = int(np.argmax(best[which]))                 # the first row holding the largest
    k = which[r]
    # the second pass: k against every term near it, only the pairs near the largest
    around = np.flatnonzero(some & (start <= end[k]) & (end >= start[k]))
    close = set(pv[pk == k].tolist()) | set(pk[pv == k].tolist())
    only = np.isin(around, list(close))
    row = np.zeros(len(counts))
    row[around] = _pair_similarity(_rows_of(distinct, x), x, np.full(len(around), k), around,
                                   start, end, only)
    full = row[which]
    full[r] = -1.0
    col = int(np.argmax(full))
    return float(full[col]), r, col


class _Edges(NamedTuple):
    """The lines of distinct terms' edges and, for a crisp step, the breakpoint beside it."""

    lines: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
    extra: np.ndarray       # [terms, 2]: the breakpoint before a rising step, after a falling
    beside: np.ndarray      # [terms, 2, 2]: the stretch between each step and that breakpoint


def _step_edges(distinct: np.ndarray, x: np.ndarray, lo: float) -> _Edges | None:
    """Each term's edge lines, and where it has an upright edge the breakpoint of ``x``
    beside it (``lo`` where there is none); ``None`` where a slanted edge is too narrow for
    its slope to be a normal number, or runs backwards."""
    a, b, c, d = distinct.T
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        lines = (1.0 / (b - a), -a / (b - a), -1.0 / (d - c), d / (d - c))
    rise, fall = np.isfinite(a) & np.isfinite(b), np.isfinite(c) & np.isfinite(d)
    up, down = rise & (a == b), fall & (c == d)                     # upright edges
    if not (np.isfinite(lines[0][rise & ~up]).all() and np.isfinite(lines[2][fall & ~down]).all()
            and (b[rise] >= a[rise]).all() and (d[fall] >= c[fall]).all()):
        return None
    before = np.searchsorted(x, a, side="left") - 1
    after = np.searchsorted(x, d, side="right")
    extra = np.stack([np.where(up & (before >= 0), x[np.clip(before, 0, len(x) - 1)], lo),
                      np.where(down & (after < len(x)), x[np.clip(after, 0, len(x) - 1)], lo)],
                     axis=1)
    # no breakpoint lies between a step and the one beside it, so no point of a pair may
    # (the lines of two edges cross there, where the edges are not: that cut the half area)
    beside = np.stack([np.stack([np.where(up, extra[:, 0], lo), np.where(up, a, lo)], axis=1),
                       np.stack([np.where(down, d, lo), np.where(down, extra[:, 1], lo)],
                                axis=1)], axis=1)
    return _Edges(lines, extra, beside)


def _screened(distinct: np.ndarray, di: np.ndarray, dj: np.ndarray, edges: _Edges,
              lo: float, hi: float) -> np.ndarray:
    """The similarity of each pair ``di, dj`` on its own points, likeliest pairs first, as
    in :func:`most_similar_by_pairs` (the area beside a step too); -1 for the pairs whose
    bound shows they are below the largest, which are not measured."""
    area = _areas(distinct, lo, hi, edges.extra)
    bound, likeliest = _likeliest(area[di], area[dj])
    s = np.full(len(di), -1.0)
    step = max(1, PAIR_BLOCK // 20)
    found = 0.0
    for k in range(0, len(di), step):
        p = likeliest[k:k + step]
        if bound[p[0]] < found - NEAR_MOST:
            break
        s[p] = _pairs_on_own_points(distinct, di[p], dj[p], edges.lines, lo, hi, edges.extra,
                                    edges.beside)
        found = max(found, float(s[p].max()))
    return s


class _Spans(NamedTuple):
    """Where each distinct term is above 0 on the breakpoints, as :func:`_linear_most` has it."""

    start: np.ndarray
    end: np.ndarray
    some: np.ndarray        # above 0 somewhere


def _rows_of(distinct: np.ndarray, x: np.ndarray) -> Rows:
    def rows(k: np.ndarray, at: np.ndarray) -> np.ndarray:
        return memberships(distinct[k], x[at])
    return rows


def _first_pass(distinct: np.ndarray, x: np.ndarray, counts: np.ndarray, spans: _Spans,
                ni: np.ndarray, nj: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The first pass of :func:`_most_similar` (each term's pairs with the later ones, in
    its batches), summing only the pairs ``ni, nj``: each pair as the batch has it, and each
    term's largest similarity among them."""
    start, end, some = spans
    order = np.flatnonzero(some)[np.argsort(start[some], kind="stable")]
    place = np.full(len(distinct), -1)
    place[order] = np.arange(len(order))
    upto = np.searchsorted(start[order], end[order], side="right")
    fro = np.arange(len(order)) + (counts[order] < 2)
    sizes = np.maximum(upto - fro, 0)
    batch = np.empty(len(order), dtype=np.intp)
    n, total = 0, 0
    for q in range(len(order)):                     # as _most_similar closes its batches
        batch[q] = n
        total += int(sizes[q])
        if total * len(x) >= PAIR_BLOCK:
            n, total = n + 1, 0
    pk = np.where(place[ni] <= place[nj], ni, nj)         # the pair as the batch has it
    pv = np.where(place[ni] <= place[nj], nj, ni)
    wanted = set(zip(pk.tolist(), pv.tolist()))
    rows = _rows_of(distinct, x)
    best = np.zeros(len(distinct))
    for bn in np.unique(batch[place[pk]]):
        ps = np.flatnonzero(batch == bn)
        ks = np.repeat(order[ps], sizes[ps])
        vs = np.concatenate([order[fro[p]:upto[p]] for p in ps])
        only = np.array([(k, v) in wanted for k, v in zip(ks.tolist(), vs.tolist())],
                        dtype=bool)
        sim = _pair_similarity(rows, x, ks, vs, start, end, only)
        np.maximum.at(best, ks[only], sim[only])
        np.maximum.at(best, vs[only], sim[only])
    return pk, pv, best


def _likeliest(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each pair's bound on its similarity from its terms' areas ``a`` and ``b`` (|A and B|
    is at most the smaller, |A or B| at least the larger; 1 where that is no number) and the
    pairs from the likeliest down (a stable order: ties as the pairs come)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        bound = np.minimum(a, b) / np.maximum(a, b)
    bound = np.where(np.isfinite(bound), bound, 1.0)
    return bound, np.argsort(-bound, kind="stable")


def _areas(corners: np.ndarray, lo: float, hi: float, extra: np.ndarray | None = None
           ) -> np.ndarray:
    """Each piecewise-linear term's area on ``[lo, hi]``: the trapezoid rule on the ends and
    its corners, between which it is linear (and on the points ``extra[t]``, if given: the
    breakpoints beside an upright edge, as :func:`most_similar_beside_steps` measures it)."""
    pts = np.concatenate([np.full((len(corners), 1), lo), np.full((len(corners), 1), hi),
                          corners] + ([] if extra is None else [extra]), axis=1)
    pts = np.sort(np.where(np.isfinite(pts) & (pts >= lo) & (pts <= hi), pts, lo), axis=1)
    m = memberships_at(np.repeat(corners, pts.shape[1], axis=0), pts.reshape(-1)
                       ).reshape(pts.shape)
    return ((m[:, 1:] + m[:, :-1]) * 0.5 * np.diff(pts, axis=1)).sum(axis=1)


def _pairs_on_own_points(corners: np.ndarray, i: np.ndarray, j: np.ndarray,
                         lines: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
                         lo: float, hi: float,
                         extra: np.ndarray | None = None, beside: np.ndarray | None = None
                         ) -> np.ndarray:
    """The Jaccard similarity of terms ``i[p]`` and ``j[p]`` on the points of each pair (and
    on the points ``extra[t]`` of each of its terms ``t``, if given; none strictly inside the
    stretches ``beside[t, s]``, ``(left, right)``, if given)."""
    rs, ro, fs, fo = lines
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        cross = np.stack([(ro[j] - ro[i]) / (rs[i] - rs[j]), (fo[j] - ro[i]) / (rs[i] - fs[j]),
                          (ro[j] - fo[i]) / (fs[i] - rs[j]), (fo[j] - fo[i]) / (fs[i] - fs[j])],
                         axis=1)
    pts = np.concatenate([np.full((len(i), 1), lo), np.full((len(i), 1), hi), corners[i],
                          corners[j], cross] + ([] if extra is None else [extra[i], extra[j]]),
                         axis=1)
    pts = np.where(np.isfinite(pts) & (pts >= lo) & (pts <= hi), pts, lo)
    if beside is not None:
        for t in (i, j):
            for s in range(beside.shape[1]):
                pts = np.where((pts > beside[t, s, 0, None]) & (pts < beside[t, s, 1, None]),
                               lo, pts)
    pts = np.sort(pts, axis=1)
    m = np.stack([memberships_at(corners[np.repeat(k, pts.shape[1])], pts.reshape(-1))
                  .reshape(pts.shape) for k in (i, j)])
    dx = np.diff(pts, axis=1)
    lo_m, hi_m = np.minimum(m[0], m[1]), np.maximum(m[0], m[1])
    inter = ((lo_m[:, 1:] + lo_m[:, :-1]) * 0.5 * dx).sum(axis=1)
    union = ((hi_m[:, 1:] + hi_m[:, :-1]) * 0.5 * dx).sum(axis=1)
    meets = ((m[0] > 0) & (m[1] > 0)).any(axis=1)
    return np.divide(inter, union, out=np.zeros_like(inter), where=meets & (union > 0))


def _linear_most(corners: np.ndarray, x: np.ndarray) -> tuple[float, int, int]:
    """:func:`most_similar` at the points ``x``."""
    distinct, which, counts = _distinct_rows(corners)
    # the points from the term's left corner to its right one: all where it is above 0
    start = np.searchsorted(x, distinct[:, 0], side="left")
    end = np.searchsorted(x, distinct[:, 3], side="right") - 1
    return _most_similar(lambda k, at: memberships(distinct[k], x[at]), x, which, counts, start,
                         end)


def _most_similar(rows: Rows, x: np.ndarray, which: np.ndarray, counts: np.ndarray, start: np.ndarray,
                  end: np.ndarray) -> tuple[float, int, int]:
    """:func:`most_similar_on` of the terms ``which`` (indices of distinct terms, each
    occurring ``counts`` times), whose memberships ``rows(k, at)`` gives for distinct terms
    ``k[p]`` at the points ``x[at[p]]``, and are 0 outside the points ``start`` ... ``end``
    (an empty stretch: ``end < start``)."""
    some = start <= end
    best = np.zeros(len(counts))            # each row's largest: 0 for a term beside any other
    order = np.flatnonzero(some)[np.argsort(start[some], kind="stable")]
    starts = start[order]
    ks: list[np.ndarray] = []
    vs: list[np.ndarray] = []
    for p, k in enumerate(order):           # k with itself (when repeated) and the later ones
        v = order[p + int(counts[k] < 2):int(np.searchsorted(starts, end[k], side="right"))]
        ks.append(np.full(len(v), k))
        vs.append(v)
        if sum(map(len, vs)) * len(x) >= PAIR_BLOCK or p == len(order) - 1:
            k_, v_ = np.concatenate(ks), np.concatenate(vs)
            s = _pair_similarity(rows, x, k_, v_, start, end)
            np.maximum.at(best, k_, s)
            np.maximum.at(best, v_, s)
            ks, vs = [], []
    r = int(np.argmax(best[which]))         # the first row holding the largest
    k = which[r]
    near = np.flatnonzero(some & (start <= end[k]) & (end >= start[k]))
    row = np.zeros(len(counts))
    row[near] = _pair_similarity(rows, x, np.full(len(near), k), near, start, end)
    full = row[which]
    full[r] = -1.0
    j = int(np.argmax(full))
    return float(full[j]), r, j


def _distinct_rows(mu: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The different rows of ``mu``, which of them each row is and how often each occurs
    (``np.unique(mu, axis=0)`` sorts the rows as records of a field per point: 6 s for
    20,000 rows)."""
    seen: dict[bytes, int] = {}
    which = np.array([seen.setdefault((row + 0.0).tobytes(), len(seen)) for row in mu],
                     dtype=np.intp)                 # + 0.0: -0.0 is 0.0, as np.unique has it
    first = np.zeros(len(seen), dtype=np.intp)
    first[which[::-1]] = np.arange(len(mu))[::-1]
    return mu[first], which, np.bincount(which, minlength=len(seen))


def _pair_similarity(rows: Rows, x: np.ndarray, k: np.ndarray, v: np.ndarray, start: np.ndarray,
                     end: np.ndarray, only: np.ndarray | None = None) -> np.ndarray:
    """The similarity of the terms ``k[p]`` and ``v[p]`` for each pair ``p`` as
    :func:`similarity_on` forms it (0 for two terms never both above 0), each on its own
    stretch of the points: from the point before the first of the two to rise above 0
    (``start``) to the one after the last to fall back (``end``); outside it both are 0, and
    so is every trapezoid. Over every point, 20,000 narrow triangles took 70 s in `mitos
    check`. The sums are of the same trapezoids in another grouping, so a similarity may
    differ in its last bit from :func:`similarity_on`'s. Pairs of stretches of like length
    go together, in blocks of :data:`PAIR_BLOCK` memberships. ``only``: the pairs measured
    (the others 0), each in the block it would be in with all of them, so with the same
    bits."""
    last = len(x) - 1
    lo = np.maximum(np.minimum(start[k], start[v]) - 1, 0)
    hi = np.minimum(np.maximum(end[k], end[v]) + 1, last)
    out = np.zeros(len(k))
    order = np.argsort(hi - lo, kind="stable")
    widths = (hi - lo + 1)[order]                   # ascending
    i = 0
    while i < len(order):
        j = _block_end(widths, i)
        width = int(widths[j - 1])                  # the longest of the block
        p = order[i:j]
        i = j
        if only is not None:
            p = p[only[p]]
            if not len(p):
                continue
        at = np.minimum(lo[p, None] + np.arange(width), hi[p, None])    # past hi: dx 0
        a, b = rows(k[p], at), rows(v[p], at)
        dx = np.diff(x[at], axis=1)
        inter = ((np.minimum(a[:, 1:], b[:, 1:]) + np.minimum(a[:, :-1], b[:, :-1]))
                 * 0.5 * dx).sum(axis=1)
        union = ((np.maximum(a[:, 1:], b[:, 1:]) + np.maximum(a[:, :-1], b[:, :-1]))
                 * 0.5 * dx).sum(axis=1)
        meets = ((a > 0) & (b > 0)).any(axis=1)
        out[p] = np.divide(inter, union, out=np.zeros_like(inter), where=meets & (union > 0))
    return out


def _block_end(widths: np.ndarray, i: int) -> int:
    """The end of the block of pairs from ``i`` on (their ``widths`` ascending): as many as
    :data:`PAIR_BLOCK` memberships of the block's longest hold, at least one."""
    lo, hi = i + 1, len(widths)                    # (j - i) * widths[j - 1] grows with j
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if (mid - i) * int(widths[mid - 1]) <= PAIR_BLOCK:
            lo = mid
        else:
            hi = mid - 1
    return lo


def least_distance(values: np.ndarray) -> float:
    """How far apart neighbouring crisp ``values`` must stay: :data:`DISTINCT` times the
    spacing of as many values spread evenly between the smallest and the largest."""
    if len(values) < 2:
        return 0.0
    return float(DISTINCT * (np.max(values) - np.min(values)) / (len(values) - 1))


def measures(corners: np.ndarray, universe: tuple[float, float]) -> tuple[float, float]:
    """Coverage and the largest similarity of two different terms, on one evaluation of the
    memberships at the breakpoints (what adaptation checks on every trial step)."""
    x = breakpoints(corners, universe)
    mu = memberships(corners, x)
    cover = float(mu.max(axis=0).min())
    if len(corners) < 2:
        return cover, 0.0
    dx = np.diff(x)
    both = np.minimum(mu[:, None, :], mu[None, :, :])
    either = np.maximum(mu[:, None, :], mu[None, :, :])
    inter = ((both[..., 1:] + both[..., :-1]) * dx).sum(axis=-1)
    union = ((either[..., 1:] + either[..., :-1]) * dx).sum(axis=-1)
    sim = np.divide(inter, union, out=np.zeros_like(inter), where=union > 0)
    np.fill_diagonal(sim, -1.0)
    return cover, float(sim.max())


# ---- terms of any shape, on samples -------------------------------------------------------------

def sample_points(terms: Sequence[Term], universe: tuple[float, float]) -> np.ndarray:
    """Where terms of any shape are measured: :data:`RESOLUTION` evenly spaced points of the
    universe, the :func:`breakpoints` of the piecewise-linear ones among ``terms`` (so they stay
    exact) and every term's centre (sorted)."""
    lo, hi = universe
    linear = [t.corners for t in terms if t.corners is not None]
    bends = breakpoints(np.array(linear, dtype=float), universe) if linear else np.zeros(0)
    centres = np.array([t.center for t in terms], dtype=float)
    x = np.concatenate([np.linspace(lo, hi, RESOLUTION), bends, centres])
    return np.unique(x[np.isfinite(x) & (x >= lo) & (x <= hi)])


def sampled(terms: Sequence[Term], x: np.ndarray) -> np.ndarray:
    """``mu[t, n]`` of ``terms`` (any shape of the registry) at the points ``x[n]``, in
    [0, 1] (a NaN membership counts as 0)."""
    mu = np.empty((len(terms), len(x)))                   # filled a term at a time
    with np.errstate(all="ignore"):
        for row, t in zip(mu, terms):
            m = np.asarray(t.membership(x), dtype=float) * np.ones_like(x)
            row[:] = np.clip(np.nan_to_num(m, nan=0.0), 0.0, 1.0)
    return mu


# ---- what a variable's terms are --------------------------------------------------------------

def learnable(term: Term) -> bool:
    """Piecewise linear or crisp: the terms these measures (and adaptation) understand."""
    return term.shape == "singleton" or term.corners is not None


def core(term: Term) -> tuple[float, float]:
    """Where the term is 1: ``[b, c]`` of a piecewise-linear term, a crisp term's value."""
    _, b, c, _ = _corners(term)
    return (b, c)


def centre(term: Term) -> float:
    """The point a term stands for: its core's middle, or a shoulder's inner core end (any
    other shape: the registry's centre, a gaussian's mean, a sigmoid's inflection)."""
    if not learnable(term):
        return term.center
    lo, hi = core(term)
    if np.isinf(lo):
        return hi
    if np.isinf(hi):
        return lo
    return 0.5 * (lo + hi)


def _corners(term: Term) -> tuple[float, float, float, float]:
    """``(a, b, c, d)`` of a learnable term (a crisp term's value four times)."""
    if term.shape == "singleton":
        v = term.params[0]
        return (v, v, v, v)
    corners = term.corners
    assert corners is not None, "only learnable terms are measured"
    return corners


def mirror_point(var: Variable) -> float | None:
    """The point the terms are written mirror-symmetric about (an odd number of terms; the
    i-th and the i-th from last are mirror images, corner for corner), else ``None``."""
    terms = var.terms
    n = len(terms)
    if n < 3 or n % 2 == 0 or not all(learnable(t) for t in terms):
        return None
    tol = TOLERANCE * (var.universe[1] - var.universe[0])
    point = None
    for i in range(n // 2):
        left, right = _corners(terms[i]), _corners(terms[n - 1 - i])
        sums = [u + v for u, v in zip(left, reversed(right))]
        finite = [s for s in sums if np.isfinite(s)]
        if not finite or any(np.isfinite(u) != np.isfinite(v)
                             for u, v in zip(left, reversed(right))):
            return None
        p = 0.5 * finite[0]
        if any(abs(s - 2 * p) > tol for s in finite) or \
                (point is not None and abs(p - point) > tol):
            return None
        point = p
    return point


def held_term(var: Variable) -> tuple[Term, float] | None:
    """The middle term of a mirror-symmetric variable and its point, when it is written
    symmetric about that point: what adaptation holds there unless released. A term written
    with the point it is held at (``held: 90``, what ``mitos teach`` saves once adaptation has
    moved its neighbours out of symmetry) is held there."""
    written = next(((t, t.held_at) for t in var.terms if t.held_at is not None), None)
    if written is not None:
        return written
    point = mirror_point(var)
    if point is None:
        return None
    middle = var.terms[len(var.terms) // 2]
    tol = TOLERANCE * (var.universe[1] - var.universe[0])
    if middle.shape == "singleton":
        return (middle, point) if abs(middle.params[0] - point) <= tol else None
    a, b, c, d = _corners(middle)
    if abs(b + c - 2 * point) <= tol and abs(a + d - 2 * point) <= tol:
        return middle, point
    return None


# ---- findings ----------------------------------------------------------------------------------

def _num(x: float) -> str:
    return f"{x:.4g}"


def variable_issues(var: Variable) -> list[Issue]:
    """Every interpretability problem of ``var``'s terms (nothing for a variable with fewer
    than two terms, or with Takagi-Sugeno linear consequents)."""
    terms = list(var.terms)
    if len(terms) < 2 or any(t.shape == "linear" for t in terms):
        return []
    out = _order(var)
    crisp = [t for t in terms if t.shape == "singleton"]
    sets = [t for t in terms if t.shape != "singleton"]
    width = var.universe[1] - var.universe[0]
    if len(sets) >= 2 or (sets and var.role == "input"):
        if all(learnable(t) for t in sets):                     # exact
            corners = np.array([t.corners for t in sets], dtype=float)
            x = breakpoints(corners, var.universe)
            # never every term's memberships at once; only an input's coverage is measured
            top = envelope(corners, x) if var.role == "input" else x[:0]
        else:                                                   # any shape: on samples
            corners = None
            x = sample_points(sets, var.universe)
            mu = sampled(sets, x)
            top = mu.max(axis=0)
        if var.role == "input":
            low, where = least_top(top, x, var.universe, besides_gaps=True)   # see term-gap
            if low < COVERAGE - 1e-9 or _dips_beside_gaps(sets, corners, x):
                spans = (uncovered_on(top, x) if corners is None
                         else uncovered(corners, var.universe, bends=x))
                out.append(Issue("coverage", var.name, (), _coverage_message(
                    var, low, where, spans, gaps=bool(np.any(top <= 0.0))),
                    "widen the neighbouring terms so that they overlap there"))
        if len(sets) >= 2:
            found = None if corners is None else (
                most_similar_by_pairs(corners, var.universe)
                or most_similar_beside_steps(corners, var.universe, x, SIMILARITY - 1e-6))
            s, i, j = found or (most_similar_on(mu, x) if corners is None
                                else _linear_most(corners, x))
            if s > SIMILARITY + 1e-9:
                out.append(Issue("indistinct", var.name, (sets[i].name, sets[j].name), (
                    f"`{var.name}.{sets[i].name}` and `{sets[j].name}` are hard to tell apart "
                    f"(similarity {s:.2f} > {SIMILARITY:g})"),
                    "move their peaks apart or narrow them (or merge them into one term)"))
    values = sorted((t.params[0], t.name) for t in crisp)
    least = least_distance(np.array([v for v, _ in values]))
    for (v1, n1), (v2, n2) in zip(values, values[1:]):
        if v2 - v1 < least - TOLERANCE * width:
            out.append(Issue("indistinct", var.name, (n1, n2), (
                f"`{var.name}.{n1}` ({_num(v1)}) and `{n2}` ({_num(v2)}) are hard to tell apart "
                f"(closer than {_num(least)}, half the spacing of evenly spread values)"),
                "move them apart, or merge them into one term"))
    out += _off_centre(var)
    return out


def _dips_beside_gaps(sets: list[Term], corners: np.ndarray | None, x: np.ndarray) -> bool:
    """Whether the largest membership lies strictly between 0 and :data:`COVERAGE`
    anywhere: at a point of ``x`` or a third or two thirds of the way to the next. Next to a
    term gap it falls to 0 between two breakpoints where it is 1 (a shoulder's edge ending
    at the gap), which the breakpoints alone never show; the envelope is linear between
    them, so a dip shows at one of those thirds."""
    width = np.diff(x)
    for at in (x, x[:-1] + width / 3, x[:-1] + 2 * width / 3):      # a third of the memory
        top = envelope(corners, at) if corners is not None else sampled(sets, at).max(axis=0)
        if np.any((top > 0.0) & (top < COVERAGE - 1e-9)):
            return True
    return False


#: Stretches named in one coverage finding; more are counted.
SHOWN_STRETCHES = 4


def _coverage_message(var: Variable, low: float, where: float,
                      spans: list[tuple[float, float]], gaps: bool) -> str:
    """```x` is covered only to 0.2 at x = 50, less than 0.5 for x in [35, 65] (...)``: the
    least and where, then the stretches below :data:`COVERAGE` (those around a gap too, the
    gap itself being the ``term-gap`` finding), their ends rounded to the decimal place of a
    thousandth of the universe, the resolution the sampled measures have."""
    step = (var.universe[1] - var.universe[0]) / (RESOLUTION - 1)
    if low < COVERAGE - 1e-9:
        text = f"`{var.name}` is covered only to {_num(low)} at {var.name} = {_num(where)}"
        if gaps:
            text += " outside its term gaps"
    else:                       # below only where a term falls to a gap
        text = f"`{var.name}` is covered to {COVERAGE:g} except next to its term gaps"
    if spans:
        shown = [f"[{_rounded(a, step)}, {_rounded(b, step)}]"
                 for a, b in spans[:SHOWN_STRETCHES]]
        listed = shown[0] if len(shown) == 1 else ", ".join(shown[:-1]) + " and " + shown[-1]
        more = len(spans) - len(shown)
        text += (f", less than {COVERAGE:g} for {var.name} in {listed}"
                 + (f" and {more} more stretch{'es' if more > 1 else ''}" if more else ""))
    return text + (f" (every point of the universe should belong to some term at least "
                   f"{COVERAGE:g})")


def _rounded(x: float, step: float) -> str:
    """``x`` to the power of ten at most ``step`` (35.00000001 -> 35, 33.3333 -> 33.3)."""
    if not step > 0 or not np.isfinite(x):
        return _num(x)
    decimals = -int(np.floor(np.log10(step)))
    value = round(float(x), decimals) + 0.0                 # + 0.0: -0.0 reads as 0
    return f"{value:.{max(decimals, 0)}f}".rstrip("0").rstrip(".") if decimals > 0 else \
        f"{value:.0f}"


def _order(var: Variable) -> list[Issue]:
    terms = [t for t in var.terms if np.isfinite(centre(t))]      # a formula has no centre
    centres = [centre(t) for t in terms]
    steps = np.diff(centres)
    tol = TOLERANCE * (var.universe[1] - var.universe[0])
    if np.all(steps > tol) or np.all(steps < -tol):
        return []
    up = int(np.sum(steps > 0)) >= int(np.sum(steps < 0))
    k = next(i for i, s in enumerate(steps) if (s <= tol if up else s >= -tol))
    t1, t2 = terms[k], terms[k + 1]
    return [Issue("term-order", var.name, (t1.name, t2.name), (
        f"`{var.name}.{t2.name}` ({_num(centres[k + 1])}) is written after `{t1.name}` "
        f"({_num(centres[k])}) but does not lie {'above' if up else 'below'} it: the terms "
        f"are out of order"), "keep the terms in the order of their peaks, as they are "
                             "written")]


def _off_centre(var: Variable) -> list[Issue]:
    """The middle term of terms that mirror each other about a point, but not on it; a term
    written with the point it is held at (``held: 90``), but not on it."""
    tol = 1e-3 * (var.universe[1] - var.universe[0])
    written = next(((t, t.held_at) for t in var.terms if t.held_at is not None), None)
    if written is not None:
        term, at = written
        if not term.held or abs(centre(term) - at) <= tol:
            return []
        return [Issue("off-centre", var.name, (term.name,), (
            f"`{var.name}.{term.name}` is centred on {_num(centre(term))}, off the point "
            f"{_num(at)} it is held at"), f"move it back to {_num(at)}")]
    n = len(var.terms)
    if n < 3 or n % 2 == 0 or not all(learnable(t) for t in var.terms) or _order(var) \
            or _trivially_mirrored(var):
        return []
    outer = Variable(var.name, var.role, var.universe,
                     var.terms[:n // 2] + (_placeholder(var),) + var.terms[n // 2 + 1:])
    point = mirror_point(outer)
    middle = var.terms[n // 2]
    if point is None or abs(centre(middle) - point) <= tol or not middle.held:
        return []                                   # `held: false`: the instructor let it move
    return [Issue("off-centre", var.name, (middle.name,), (
        f"`{var.name}.{middle.name}` is centred on {_num(centre(middle))}, off the point "
        f"{_num(point)} its neighbours mirror each other about"),
        f"move it back to {_num(point)}")]


def _trivially_mirrored(var: Variable) -> bool:
    """Three terms whose outer two are crisp values: any two values mirror each other about
    their midpoint, so that says nothing of a point the middle term was meant to sit on
    (``{OFF: 0, LOW: 1000, HIGH: 3000}`` is not LOW off 1500)."""
    return len(var.terms) == 3 and var.terms[0].shape == var.terms[2].shape == "singleton"


def _placeholder(var: Variable) -> Term:
    return Term("_", "singleton", (0.0,))


def gap_points(var: Variable) -> np.ndarray:
    """Where gaps are looked for: :data:`GAP_RESOLUTION` points of the universe and the
    terms' corners inside it (any shape: a term is asked its membership there)."""
    lo, hi = var.universe
    corners = [c for t in var.terms if t.corners for c in t.corners if lo <= c <= hi]
    return np.unique(np.concatenate([np.linspace(lo, hi, GAP_RESOLUTION), corners]))


class Gap(NamedTuple):
    """A stretch of a universe where every term is 0: ``[left, right]``, an end left out
    (``open_left``, ``open_right``) where the terms step there from 0 to above it, so the gap
    runs up to the step but not onto it (``[20, 30.01)`` beside a rectangle from 30.01)."""

    left: float
    right: float
    open_left: bool = False
    open_right: bool = False


def gaps_on(top: np.ndarray, x: np.ndarray, middle: np.ndarray | None = None) -> list[Gap]:
    """Each run of the points ``x`` (ascending) where the largest membership ``top`` is 0
    (``left == right``: the terms only touch 0 there). ``middle``, the largest membership
    at the centre of each cell between neighbouring points, runs a gap on over a cell that
    is 0 at its centre: on points that hold the terms' corners a membership is linear on
    each open cell, so such a cell is 0 all over and the gap ends at the next point, a crisp
    step, left out (read from the points alone, it stopped one point short, ``[20, 30]`` for
    ``[20, 30.01)``, and a gap between two steps with no point inside it was not seen)."""
    if middle is None or len(x) < 2:
        padded = np.concatenate([[False], top <= 0.0, [False]])
        edges = np.flatnonzero(padded[1:] != padded[:-1])
        return [Gap(float(x[a]), float(x[b - 1])) for a, b in zip(edges[::2], edges[1::2])]
    zero = np.empty(2 * len(x) - 1, dtype=bool)     # point, cell, point, ..., cell, point
    zero[0::2] = top <= 0.0
    zero[1::2] = middle <= 0.0
    padded = np.concatenate([[False], zero, [False]])
    edges = np.flatnonzero(padded[1:] != padded[:-1])
    gaps = []
    for a, b in zip(edges[::2], edges[1::2]):       # items a .. b - 1 (a cell is odd)
        first, last = int(a), int(b) - 1
        gaps.append(Gap(float(x[first // 2]), float(x[(last + 1) // 2]),
                        first % 2 == 1, last % 2 == 1))
    return gaps


def cell_middles(x: np.ndarray) -> np.ndarray:
    """The centre of each cell between neighbouring points of ``x``."""
    return 0.5 * (x[:-1] + x[1:])


def term_gaps(var: Variable) -> list[Gap]:
    """The stretches of an input's universe where every term is 0 (``mitos check``'s
    ``term-gap``); none for an output or a variable without terms."""
    if var.role != "input" or not var.terms:
        return []
    x = gap_points(var)
    mid = cell_middles(x)
    return gaps_on(np.array([t.membership(x) for t in var.terms]).max(axis=0), x,
                   np.array([t.membership(mid) for t in var.terms]).max(axis=0))


def gap_message(var: Variable, gap: Gap) -> str:
    """How a gap is said: ``input `food`: every term is 0 for food in [0, 0.53]``."""
    left, right, open_left, open_right = gap
    where = f"at {var.name} = {left:.6g}" if left == right else \
        f"for {var.name} in {'(' if open_left else '['}{left:.6g}, {right:.6g}" \
        f"{')' if open_right else ']'}"
    return f"input `{var.name}`: every term is 0 {where}"


def rulebase_issues(variables: Iterable[Variable]) -> list[Issue]:
    """:func:`variable_issues` of each variable in turn."""
    return [i for v in variables for i in variable_issues(v)]


__all__ = ["COVERAGE", "DISTINCT", "GAP_HINT", "GAP_RESOLUTION", "PAIR_BLOCK", "RESOLUTION",
           "SIMILARITY", "Gap", "Issue", "cell_middles", "centre", "core", "coverage",
           "coverage_on", "coverage_spans",
           "envelope", "gap_message", "gap_points", "gaps_on", "held_term", "least_top",
           "memberships", "mirror_point", "most_similar", "most_similar_on", "rulebase_issues",
           "sample_points", "sampled", "similarity", "similarity_on", "span_coverage",
           "term_gaps", "uncovered", "uncovered_on", "variable_issues"]
