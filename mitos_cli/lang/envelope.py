"""The upper envelope of piecewise-linear terms: the largest membership of any term at each
of many points, with the bits of every term measured at every point, in time about
proportional to the points plus the terms times the envelope's pieces.

A term ``(a, b, c, d)`` is three closed segments of lines: its rising edge on ``[a, b]``, its
core (1) on ``[b, c]`` and its falling edge on ``[c, d]`` (0 elsewhere, and an open side has
no edge). The envelope of all those segments, and of 0, is built by merging envelopes two at
a time, level by level (divide and conquer, every merge of a level in one pass of array
operations): on each stretch between the corners of two envelopes each is one line, and the
larger is kept, the stretch cut where the two lines cross. Its few pieces (about two per
term for triangles that all overlap, where the breakpoints between which every term is
linear are quadratic in the terms) then say which terms can be the largest at a point:

- where a core holds the point, the largest membership is 1, to the bit;
- else only the terms whose edge comes within :data:`NEAR` of the envelope on the piece
  holding the point can be largest (a membership rounds by a few units in the last place,
  and the envelope's lines are those memberships' lines, crossed where they cross).

Those few terms are measured at the point with the same operations as
:func:`~mitos_cli.lang.interpretability.memberships_at` and the largest kept: the same bits as
every term at every point, whatever the rounding of the envelope itself. Terms that are not
three such segments in floating point (an edge upright or too narrow for its slope to be a
normal number, an infinite foot beside a finite peak, corners out of order or not numbers)
are measured at every point of their support, as before.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    #: three lines' slopes, points and values: line i is m[i] (x - p[i]) + q[i]
    Lines = tuple[np.ndarray, np.ndarray, np.ndarray]

#: How far below the envelope (in membership) a term's edge may lie on a piece and still be
#: measured there: far more than the rounding of a membership or of the envelope's lines
#: (a few 1e-16), far less than the gap between two terms that are not tied.
NEAR = 1e-9
#: Most (term, point) pairs measured at once: 2 MB per array.
BLOCK = 1 << 18

_FLOOR = 0          # the line of 0: line ids of the segments start at 1


def regular(corners: np.ndarray) -> np.ndarray:
    """Which terms (rows of ``corners``, ``+ 0.0``) are three closed segments of lines with
    normal slopes (see the module's docstring); the others are measured point by point."""
    a, b, c, d = corners.T
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        wide_rise, wide_fall = b - a, d - c
        rise = np.isfinite(a) & np.isfinite(b) & (wide_rise > 0) & np.isfinite(wide_rise) \
            & np.isfinite(1.0 / wide_rise)
        fall = np.isfinite(c) & np.isfinite(d) & (wide_fall > 0) & np.isfinite(wide_fall) \
            & np.isfinite(1.0 / wide_fall)
    open_rise = (a == -np.inf) & (b == -np.inf)
    open_fall = (c == np.inf) & (d == np.inf)
    return (rise | open_rise) & (fall | open_fall) & (b <= c)


def upper_envelope(corners: np.ndarray, xs: np.ndarray,
                   measure: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> np.ndarray:
    """The largest ``measure(corners[p], xs[p])`` (0 at least) of the terms ``corners[t, 4]``
    at each of the sorted, finite points ``xs``, for regular terms only (:func:`regular`):
    ``measure`` is the membership of term ``p`` at point ``p`` for each ``p``."""
    top = np.zeros(len(xs))
    if not len(corners) or not len(xs):
        return top
    lo, hi = float(xs[0]), float(xs[-1])
    a, b, c, d = corners.T
    t = np.arange(len(corners))
    # the segments: rising edges, falling edges, cores; as mu = m * (x - p) + q on [l, r]
    with np.errstate(divide="ignore"):
        rise, fall = np.isfinite(a), np.isfinite(d)
        left = np.concatenate([a[rise], c[fall], b])
        right = np.concatenate([b[rise], d[fall], c])
        m = np.concatenate([1.0 / (b[rise] - a[rise]), -1.0 / (d[fall] - c[fall]),
                            np.zeros(len(b))])
    p = np.concatenate([a[rise], d[fall], np.zeros(len(b))])
    q = np.concatenate([np.zeros(int(rise.sum()) + int(fall.sum())), np.ones(len(b))])
    term = np.concatenate([t[rise], t[fall], t])
    core = np.zeros(len(left), dtype=bool)
    core[len(left) - len(b):] = True
    inside = (right >= lo) & (left <= hi)
    left, right = np.maximum(left[inside], lo), np.minimum(right[inside], hi)
    m, p, q, term, core = m[inside], p[inside], q[inside], term[inside], core[inside]

    # where a core holds the point, the largest is 1 (every membership is clipped to 1): the
    # cores joined where they overlap, so the count of cores holding a point is 0 or 1
    ones = np.zeros(len(xs) + 1, dtype=np.int8)
    fro, to = _joined(left[core], right[core])
    np.add.at(ones, np.searchsorted(xs, fro, side="left"), 1)
    np.add.at(ones, np.searchsorted(xs, to, side="right"), -1)
    one = np.cumsum(ones[:-1], dtype=np.int8) > 0
    del ones

    wide = right > left                 # a segment of one point is its neighbours' end
    lines = (np.concatenate([[0.0], m[wide]]), np.concatenate([[0.0], p[wide]]),
             np.concatenate([[0.0], q[wide]]))
    starts, line = _envelope(left[wide], right[wide], lines, lo, hi)
    ends = np.append(starts[1:], hi)

    sloped = wide & ~core
    seg = np.flatnonzero(sloped[wide]) + 1                      # their line ids
    first = np.searchsorted(starts, left[sloped], side="right") - 1
    count = np.searchsorted(starts, right[sloped], side="left") - first
    which, s_left, s_right = term[sloped], left[sloped], right[sloped]
    done = 0
    while done < len(seg):              # blocks of (segment, piece) pairs
        stop = _block_end(count, done)
        k, s = _spread(first[done:stop], count[done:stop])
        s = s + done
        u0 = np.maximum(starts[k], s_left[s])
        u1 = np.minimum(ends[k], s_right[s])
        gap = np.minimum(_value(lines, line[k], u0) - _value(lines, seg[s], u0),
                         _value(lines, line[k], u1) - _value(lines, seg[s], u1))
        near = gap <= NEAR
        _measure_on(top, xs, one, corners, which[s[near]], u0[near], u1[near], measure)
        done = stop
    top[one] = 1.0
    return top


def _joined(left: np.ndarray, right: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The closed stretches ``[left, right]`` joined where they overlap or touch: their union
    as stretches apart from each other."""
    if not len(left):
        return left, right
    order = np.argsort(left, kind="stable")
    left, right = left[order], np.maximum.accumulate(right[order])
    new = np.append(True, left[1:] > right[:-1])       # begins after all before it end
    ends = np.append(np.flatnonzero(new)[1:] - 1, len(left) - 1)
    return left[new], right[ends]


def _measure_on(top: np.ndarray, xs: np.ndarray, one: np.ndarray, corners: np.ndarray,
                term: np.ndarray, u0: np.ndarray, u1: np.ndarray,
                measure: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> None:
    """Raise ``top`` to ``term[i]``'s membership at the points of ``xs`` in ``[u0[i],
    u1[i]]`` (those under a core are 1 anyway)."""
    start = np.searchsorted(xs, u0, side="left")
    count = np.maximum(np.searchsorted(xs, u1, side="right") - start, 0)
    # a stretch of more than BLOCK points in parts of BLOCK
    parts = -(-count // BLOCK)
    term = np.repeat(term, parts)
    part = np.arange(len(term)) - np.repeat(np.cumsum(parts) - parts, parts)
    start = np.repeat(start, parts) + part * BLOCK
    count = np.minimum(np.repeat(count, parts) - part * BLOCK, BLOCK)
    done = 0
    while done < len(term):
        stop = _block_end(count, done)
        at, i = _spread(start[done:stop], count[done:stop])
        i = i + done
        keep = ~one[at]
        i, at = i[keep], at[keep]
        np.maximum.at(top, at, measure(corners[term[i]], xs[at]))
        done = stop


def _block_end(count: np.ndarray, first: int) -> int:
    """The end of a block of rows from ``first`` whose ``count`` sum to about :data:`BLOCK`
    (at least one row)."""
    total = np.cumsum(count[first:])
    return first + max(1, int(np.searchsorted(total, BLOCK, side="right")))


def _spread(start: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each ``start[i] + j`` for ``j < count[i]``, flat, with its ``i``: which item and where."""
    count = np.maximum(count, 0)
    i = np.repeat(np.arange(len(count)), count)
    return start[i] + np.arange(len(i)) - np.repeat(np.cumsum(count) - count, count), i


def _value(lines: Lines, k: np.ndarray, x: np.ndarray) -> np.ndarray:
    m, p, q = lines
    return m[k] * (x - p[k]) + q[k]


def _envelope(left: np.ndarray, right: np.ndarray, lines: Lines, lo: float, hi: float
              ) -> tuple[np.ndarray, np.ndarray]:
    """The upper envelope of the segments ``i`` (line ``i + 1`` of ``lines`` on ``[left[i],
    right[i]]``, each wider than a point) and of 0 (line 0) on ``[lo, hi]``: the start of each
    piece (the first is ``lo``; a piece ends where the next starts, the last at ``hi``) and
    its line."""
    n = len(left)
    if n == 0:
        return np.array([lo]), np.array([_FLOOR])
    # each segment alone: 0, the segment, 0 (a piece of no width left out)
    block = np.repeat(np.arange(n), 3)
    start = np.stack([np.full(n, lo), left, right], axis=1).reshape(-1)
    line = np.stack([np.full(n, _FLOOR), np.arange(1, n + 1), np.full(n, _FLOOR)],
                    axis=1).reshape(-1)
    keep = np.ones(3 * n, dtype=bool)
    keep[0::3] = left > lo
    keep[2::3] = right < hi
    block, start, line = block[keep], start[keep], line[keep]
    blocks = n
    while blocks > 1:
        if blocks % 2:                                  # the odd one out merges with 0
            block = np.append(block, blocks)
            start = np.append(start, lo)
            line = np.append(line, _FLOOR)
            blocks += 1
        block, start, line = _merge(block, start, line, lines, hi)
        blocks //= 2
    return start, line


def _merge(block: np.ndarray, start: np.ndarray, line: np.ndarray, lines: Lines, hi: float
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Envelopes ``2 k`` and ``2 k + 1`` (pieces sorted by block, then start) merged into
    envelope ``k``, every pair at once."""
    pair, side = block // 2, block % 2
    order = np.lexsort((side, start, pair))
    index = np.arange(len(block))
    # at each start, the piece of either envelope holding it: the last of its own so far
    a = np.maximum.accumulate(np.where(side[order] == 0, index[order], -1))
    b = np.maximum.accumulate(np.where(side[order] == 1, index[order], -1))
    pair, at = pair[order], start[order]
    last = np.append((pair[1:] != pair[:-1]) | (at[1:] != at[:-1]), True)
    pair, at, la, lb = pair[last], at[last], line[a[last]], line[b[last]]
    end = np.append(np.where(pair[1:] == pair[:-1], at[1:], hi), hi)
    d0 = _value(lines, la, at) - _value(lines, lb, at)
    d1 = _value(lines, la, end) - _value(lines, lb, end)
    first = np.where((d0 > 0) | ((d0 == 0) & (d1 >= 0)), la, lb)
    cross = ((d0 > 0) & (d1 < 0)) | ((d0 < 0) & (d1 > 0))
    with np.errstate(invalid="ignore", divide="ignore"):
        x = np.clip(at + (end - at) * (d0 / (d0 - d1)), at, end)
    second = np.where(first == la, lb, la)
    # each stretch: its first line from its start, and where the lines cross, the other
    pair = np.stack([pair, pair], axis=1).reshape(-1)
    start = np.stack([at, x], axis=1).reshape(-1)
    line = np.stack([first, second], axis=1).reshape(-1)
    keep = np.stack([np.ones(len(cross), dtype=bool), cross], axis=1).reshape(-1)
    pair, start, line = pair[keep], start[keep], line[keep]
    # a piece of no width gives way to the next; a piece of the line before it joins it
    wide = np.append((pair[1:] != pair[:-1]) | (start[1:] != start[:-1]), True) & (start < hi)
    pair, start, line = pair[wide], start[wide], line[wide]
    new = np.append(True, (pair[1:] != pair[:-1]) | (line[1:] != line[:-1]))
    return pair[new], start[new], line[new]
