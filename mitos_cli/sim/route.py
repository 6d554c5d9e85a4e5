"""The route: an A* search over the corridor network or the occupancy grid, and the route's
geometry (arc length, projection of the robot onto it, the point a lookahead ahead).

The fuzzy rules do the driving; the route only says where the road goes (the paper's suggested
marriage of the fuzzy planner with roadmaps and cell decomposition).
"""

from __future__ import annotations

import bisect
import functools
import heapq
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import WorldError
from ..words import tenths
from .distance import _capped_squares, from_squares, squared_distances
from .geometry import CACHED, box_segment_distance, clip_arrays, point_segment_distance
from .staticmap import StaticMap
from .world import Corridor, Goal, Grid, Pose, Robot

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable

    from numpy.typing import ArrayLike

    #: the nodes of a grid: each block's row, column and clearance
    Nodes = tuple[np.ndarray, np.ndarray, np.ndarray]
    #: what grid_route works out before it searches: the field, the nodes, every step's
    #: clearance and the samples per step
    Planned = tuple["Clearance", Nodes, np.ndarray, int]


@dataclass(frozen=True)
class Route:
    points: np.ndarray             # [M, 2] polyline from the start to the goal (in)
    cum: np.ndarray                # [M] arc length at each point
    goal: np.ndarray               # [2] the goal (near the last point, maybe off the line)

    # by identity, in C (a Python ``__hash__`` was three calls a robot-tick in lockstep:
    # :func:`_laid`'s cache hashes the batch's routes)
    __hash__ = object.__hash__

    @classmethod
    def of(cls, points: ArrayLike, goal: tuple[float, float] | None = None) -> Route:
        pts = np.asarray(points, float)
        keep = np.concatenate([[True], np.hypot(*np.diff(pts, axis=0).T) > 1e-9])
        pts = pts[keep]
        if len(pts) == 1:
            pts = np.vstack([pts, pts])
        cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
        end = pts[-1].copy() if goal is None else np.array(goal, float)
        # read-only, as the dataclass is frozen: writing into `sim.routes[0].points` (to draw
        # it turned, say) moved the route the robot was following, mid-run
        for a in (pts, cum, end):
            a.flags.writeable = False
        return cls(pts, cum, end)

    @functools.cached_property
    def length(self) -> float:
        return float(self.cum[-1])

    def point_at(self, s: float) -> np.ndarray:
        s = min(max(s, 0.0), self.length)
        i = min(int(np.searchsorted(self.cum, s, side="right")) - 1, len(self.points) - 2)
        seg = self.points[i + 1] - self.points[i]
        span = self.cum[i + 1] - self.cum[i]
        return self.points[i] + (s - self.cum[i]) / span * seg if span > 0 else self.points[i]

    def points_at(self, s: np.ndarray) -> np.ndarray:
        """:meth:`point_at` of every arc length of ``s [K]`` at once, ``[K, 2]``: the same
        clamp, segment and arithmetic, element by element, so the same bits. Arc lengths
        all within the route, none of zero span (the lookahead's, mostly) need no clamp and
        no mask; those on one segment need no search either."""
        s = np.asarray(s, float)
        if s.ndim != 1 or not len(s) or not self._spans_positive:
            return self._points_at_masked(s)
        cum = self._lists[0]
        lo, hi = float(np.minimum.reduce(s)), float(np.maximum.reduce(s))
        if not (lo >= 0.0 and hi <= cum[-1]):         # NaN, or a clamp to do
            return self._points_at_masked(s)
        a, e, _, _, span = self._segments
        last = len(cum) - 2
        first = min(bisect.bisect_right(cum, lo) - 1, last)
        j: int | np.ndarray = first
        if first != min(bisect.bisect_right(cum, hi) - 1, last):      # more than one segment
            j = np.minimum(np.searchsorted(self.cum, s, side="right") - 1, last)
        return a[j] + ((s - self.cum[j]) / span[j])[:, None] * e[j]

    def _points_at_masked(self, s: np.ndarray) -> np.ndarray:
        """:meth:`points_at` clamping ``s`` to the route and keeping a point of a segment of
        zero span where it starts, as :meth:`point_at` does."""
        length = self.length
        s = np.where(s < 0.0, 0.0, s)                  # max(s, 0.0), then min(s, length),
        s = np.where(length < s, length, s)            # as Python's max and min pick
        i = np.minimum(np.searchsorted(self.cum, s, side="right") - 1, len(self.points) - 2)
        a, e, _, _, span = self._segments
        start = a[i]
        ok = span[i] > 0
        frac = (s[ok] - self.cum[i[ok]]) / span[i[ok]]
        out = start.copy()
        out[ok] = start[ok] + frac[:, None] * e[i[ok]]
        return out

    @functools.cached_property
    def _segments(self) -> tuple[np.ndarray, ...]:
        """Each segment's start ``a``, vector ``e``, squared length (at least 1e-12), length
        and span of arc length: the route does not change, so :meth:`project` and
        :meth:`points_at` do not recompute them."""
        a = self.points[:-1]
        e = self.points[1:] - a
        ee = np.maximum((e * e).sum(axis=1), 1e-12)
        return a, e, ee, np.sqrt(ee), self.cum[1:] - self.cum[:-1]

    @functools.cached_property
    def _rows(self) -> np.ndarray:
        """``[M, 8]``: each point's arc length and place (x, y), and the segment from it (its
        vector x and y, span of arc length, squared length and length; at the last point the
        last segment's again): the rows :func:`projections`, :func:`distances` and
        :func:`points_along` gather from, the values of :attr:`_segments`."""
        a, e, ee, root, span = self._segments
        out = np.empty((len(self.cum), 8))
        out[:, 0], out[:, 1:3] = self.cum, self.points
        out[:-1, 3:5], out[:-1, 5], out[:-1, 6], out[:-1, 7] = e, span, ee, root
        out[-1, 3:] = out[-2, 3:]
        out.flags.writeable = False
        return out

    @functools.cached_property
    def _spans_positive(self) -> bool:
        """Every segment spans some arc length (:meth:`of` drops repeated points)."""
        return bool((self._segments[4] > 0).all())

    @functools.cached_property
    def _lists(self) -> tuple[list[float], ...]:
        """The arc lengths and each segment's start, vector, squared length and length as
        Python floats (the same values), for the scalar arithmetic of a window of one
        segment and the bisections of :meth:`_window`."""
        a, e, ee, root, _ = self._segments
        return (self.cum.tolist(), a[:, 0].tolist(), a[:, 1].tolist(), e[:, 0].tolist(),
                e[:, 1].tolist(), ee.tolist(), root.tolist())

    def project(self, p: np.ndarray, s_hint: float, back: float = 24.0,
                ahead: float = 120.0) -> tuple[float, float, np.ndarray]:
        """Arc length ``s``, signed lateral offset (positive RIGHT of the route) and unit
        tangent at the route point nearest to ``p`` within ``[s_hint - back, s_hint + ahead]``.

        Only the segments in that window are measured (elementwise, so each gets the bits it
        would get among all); with none in it, the first segment answers."""
        first, stop = self._window(s_hint - back, s_hint + ahead)
        if first >= stop:
            first, stop = 0, 1
        got = self._project_floats(first, stop, float(p[0]), float(p[1]))
        if got is not None:
            return got
        a, e, ee, root, _ = self._segments
        if stop - first < len(a):
            a, e, ee, root = a[first:stop], e[first:stop], ee[first:stop], root[first:stop]
        t = clip_arrays(np.add.reduce((p - a) * e, axis=1) / ee, 0.0, 1.0)
        closest = a + t[:, None] * e
        gap = p - closest
        i = int(np.hypot(gap[:, 0], gap[:, 1]).argmin())
        s = self.cum[first + i] + t[i] * root[i]
        tangent = e[i] / math.sqrt(ee[i])
        lateral = float(gap[i, 0] * tangent[1] - gap[i, 1] * tangent[0])   # right of it
        return float(s), lateral, tangent

    def _project_floats(self, first: int, stop: int, px: float,
                        py: float) -> tuple[float, float, np.ndarray] | None:
        """:meth:`project` onto segments ``first:stop`` in Python floats (a handful of
        segments: cheaper than a dozen tiny arrays), or ``None`` where the nearest segment
        is not plainly nearest. Each segment's ``t`` and gap are the arrays' operations in
        the same order (the clip as :data:`.geometry.clip_arrays` does it: ``-0.0`` and NaN
        kept), so the same bits. The arrays pick the segment by ``np.hypot`` of the gaps,
        which Python does not have bit for bit; squared gaps pick the same one when the
        nearest is nearer than the others by far more than either's rounding (relative
        1e-9; no gap between 0 and 1e-140, where squares lose digits)."""
        cum, ax, ay, ex, ey, ee, root = self._lists
        gaps = []
        for j in range(first, stop):
            t = ((px - ax[j]) * ex[j] + (py - ay[j]) * ey[j]) / ee[j]
            t = 0.0 if t < 0.0 else 1.0 if t > 1.0 else t
            gx, gy = px - (ax[j] + t * ex[j]), py - (ay[j] + t * ey[j])
            gaps.append((gx * gx + gy * gy, j, t, gx, gy))
        q, j, t, gx, gy = min(gaps)
        if not (q == 0.0 and gx == 0.0 and gy == 0.0 or 1e-280 <= q < math.inf):
            return None                   # NaN, inf or a square in the subnormal range
        bound = q * (1.0 + 1e-9)
        for other in gaps:
            if other[1] != j and not bound < other[0]:    # NaN too
                return None
        tx, ty = ex[j] / root[j], ey[j] / root[j]          # root: math.sqrt(ee), the same
        return cum[j] + t * root[j], gx * ty - gy * tx, np.array([tx, ty])

    def _window(self, lo: float, hi: float) -> tuple[int, int]:
        """The segments ``first:stop`` that reach arc length ``lo`` and start by ``hi`` (those
        with ``cum[j + 1] >= lo`` and ``cum[j] <= hi``: arc length never decreases along the
        route, so they are one run of segments). Bisections of a list, as
        ``np.searchsorted(cum[1:], lo, side="left")`` and ``np.searchsorted(cum[:-1], hi,
        side="right")`` answer (which sort a NaN last)."""
        cum = self._lists[0]
        first = len(cum) - 1 if lo != lo else bisect.bisect_left(cum, lo, 1) - 1
        return first, bisect.bisect_right(cum, hi, 0, len(cum) - 1)

    def near(self, points: np.ndarray, s: float, reach: float, ahead: float) -> np.ndarray:
        """Which ``points [P, 2]`` lie within ``reach`` of the route between arc lengths ``s``
        and ``s + ahead``."""
        return self.distance(points, s, ahead) <= reach

    def distance(self, points: np.ndarray, s: float, ahead: float) -> np.ndarray:
        """The distance ``[P]`` of each point from the route between arc lengths ``s`` and
        ``s + ahead`` (``inf`` with no route there). A coordinate at a time, ``[P, M]``: a
        sum over x and y is one addition, written out (the sums over an axis of two took
        twice as long, 19 against 10 us for 24 points and 5 segments)."""
        first, stop = self._window(s, s + ahead)
        if first >= stop or not len(points):
            return np.full(len(points), np.inf)
        a, e, ee, _, _ = self._segments
        ex, ey, ee = e[first:stop, 0], e[first:stop, 1], ee[first:stop]
        rx = points[:, 0, None] - a[first:stop, 0]                      # [P, M]
        ry = points[:, 1, None] - a[first:stop, 1]
        t = clip_arrays((rx * ex + ry * ey) / ee, 0.0, 1.0)
        dx, dy = rx - t * ex, ry - t * ey
        return np.sqrt(np.minimum.reduce(dx * dx + dy * dy, axis=1))


def _laid(routes: Sequence[Route]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The rows' routes' :attr:`Route._rows` laid end to end, ``[N, 8]`` (a route shared by
    rows laid once a row: a few hundred rows), where each row's starts and how many points
    it has, ``[R]`` each, and each row's arc lengths (:func:`_arc_lengths`). Kept
    (read-only) for the next rows of the same routes: runs in lockstep ask with their
    robots' routes several times a tick, and a route changes only when it is planned
    again."""
    return _laid_once(tuple(routes))


@functools.lru_cache(maxsize=8)
def _laid_once(routes: tuple[Route, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                   np.ndarray]:
    """:func:`_laid` of ``routes`` (a route hashes by itself: the same routes, in order)."""
    rows = [r._rows for r in routes]
    size = np.fromiter(map(len, rows), np.int64, len(rows))
    table, base = np.concatenate(rows), np.cumsum(size) - size
    out = table, base, size, _arc_lengths(table, base, size)
    for a in out:
        a.flags.writeable = False
    return out


def _arc_lengths(table: np.ndarray, base: np.ndarray, size: np.ndarray) -> np.ndarray:
    """``[R, M]``: each row's arc lengths, padded with copies of its last."""
    return table[base[:, None] + np.minimum(np.arange(int(size.max())), size[:, None] - 1), 0]


def _windows(cum: np.ndarray, size: np.ndarray, lo: np.ndarray,
             hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:meth:`Route._window` of every row at once (arc lengths ``cum [R, M]`` from
    :func:`_arc_lengths`, ``lo`` and ``hi [R]``): what its bisections find, counted (arc
    length never decreases; the padding counts no more than the last it copies), a NaN
    sorted last as they sort it."""
    last = size - 1
    first = np.minimum(np.add.reduce(cum[:, 1:] < lo[:, None], axis=1), last)
    stop = np.minimum(np.add.reduce(cum[:, :-1] <= hi[:, None], axis=1), last)
    return np.where(lo != lo, last, first), np.where(hi != hi, last, stop)


def points_along(routes: Sequence[Route], s: np.ndarray) -> np.ndarray:
    """:meth:`Route.points_at` of every row at once: row ``i``'s arc lengths ``s[i]`` on
    ``routes[i]``, ``[R, J, 2]``. Each is clamped to its route, its segment found by counting
    the arc lengths up to it (what ``np.searchsorted`` answers) and its point worked out as
    :meth:`Route.points_at` does, elementwise from the routes' :func:`_laid` rows, so the
    same bits. A row with a NaN (which no count places) is left to its route."""
    asked = np.asarray(s, float)
    table, base, size, cum = _laid(routes)
    last = (size - 1)[:, None]                                               # [R, 1]
    length = table[base[:, None] + last, 0]
    s = np.where(asked < 0.0, 0.0, asked)          # max(s, 0.0), then min(s, length),
    s = np.where(length < s, length, s)            # as Python's max and min pick
    count = np.add.reduce(cum[:, None, :] <= s[..., None], axis=2)
    got = table.take(base[:, None] + np.minimum(count - 1, last - 1), axis=0)     # [R, J, 8]
    ok = got[..., 5] > 0
    out = got[..., 1:3].copy()
    at = got[ok]
    out[ok] = at[:, 1:3] + ((s[ok] - at[:, 0]) / at[:, 5])[:, None] * at[:, 3:5]
    for row in np.flatnonzero(np.logical_or.reduce(s != s, axis=1)).tolist():
        out[row] = routes[row].points_at(asked[row])
    return out


def projections(routes: Sequence[Route], points: np.ndarray, hints: Sequence[float],
                back: float = 24.0, ahead: float = 120.0) -> list[tuple[float, float, np.ndarray]]:
    """:meth:`Route.project` of every row at once (``points [R, 2]``, each on its route near
    its hint): :func:`projected`'s arc lengths, offsets and tangents, a row each."""
    return list(zip(*projected(routes, points, hints, back, ahead)))


def projected(routes: Sequence[Route], points: np.ndarray, hints: Sequence[float] | np.ndarray,
              back: float = 24.0, ahead: float = 120.0
              ) -> tuple[list[float], list[float], np.ndarray]:
    """:func:`projections` as the rows' arc lengths, lateral offsets and unit tangents
    ``[R, 2]``: each row's segments in its window (:func:`_windows`), padded with copies of
    its last one (the nearest is the first of equals, so never a copy), gathered from the
    routes' :func:`_laid` rows, so a row gets the bits it gets alone; the nearest points are
    read out for all rows together. A coordinate at a time (a sum over x and y is one
    addition), as :meth:`Route.project`'s arrays add them up."""
    table, base, size, cum = _laid(routes)
    hint = np.array(hints, float)
    lo, hi = _windows(cum, size, hint - back, hint + ahead)
    empty = lo >= hi                                            # none in it: the first one
    lo, hi = np.where(empty, 0, lo), np.where(empty, 1, hi)
    width = int((hi - lo).max())
    rows = table.take(base[:, None] + np.minimum(lo[:, None] + np.arange(width), hi[:, None] - 1),
                      axis=0)
    ax, ay, ex, ey = rows[..., 1], rows[..., 2], rows[..., 3], rows[..., 4]    # [R, M] each
    ee, root = rows[..., 6], rows[..., 7]
    px, py = points[:, 0, None], points[:, 1, None]                           # [R, 1]
    t = clip_arrays(((px - ax) * ex + (py - ay) * ey) / ee, 0.0, 1.0)         # [R, M]
    cx, cy = ax + t * ex, ay + t * ey
    r = np.arange(len(routes))
    i = np.hypot(px - cx, py - cy).argmin(axis=1)
    s = (table[base + lo + i, 0] + t[r, i] * root[r, i]).tolist()
    tangent = rows[r, i, 3:5] / np.sqrt(ee[r, i])[:, None]
    gx, gy = points[:, 0] - cx[r, i], points[:, 1] - cy[r, i]
    lateral = (gx * tangent[:, 1] - gy * tangent[:, 0]).tolist()
    return s, lateral, tangent


def distances(routes: Sequence[Route], s: Sequence[float], ahead: float,
              points: np.ndarray) -> np.ndarray:
    """:meth:`Route.distance` of every row at once: row ``i``'s points ``[R, K, 2]`` from
    ``routes[i]`` between arc lengths ``s[i]`` and ``s[i] + ahead``, ``[R, K]``. Each row's
    segments (:func:`_windows`) are padded with copies of its last one (which the minimum
    cannot tell from it), so a point gets the bits it gets from its route alone; the sums
    over x and y are written out (a sum of two is one addition), the points innermost (a
    row has a few segments in its window, and some twenty points) and the rows are worked
    a block at a time (:data:`.geometry.CACHED`)."""
    if len(routes) == 1:
        return routes[0].distance(points[0], s[0], ahead)[None]
    table, base, size, cum = _laid(routes)
    start = np.array(s, float)
    first, stop = _windows(cum, size, start, start + ahead)
    width = max(int((stop - first).max()), 0)
    out = np.full(points.shape[:2], np.inf)
    rows = np.flatnonzero(first < stop)
    if not len(rows) or not points.shape[1]:
        return out
    at = base[rows, None] + np.minimum(first[rows, None] + np.arange(width), stop[rows, None] - 1)
    a = table.take(at, axis=0)[..., 1:3]                        # [H, M, 2]: each segment's
    e = table.take(at + 1, axis=0)[..., 1:3] - a                # ends, as the route has them
    ee = np.maximum(e[..., 0] * e[..., 0] + e[..., 1] * e[..., 1], 1e-12)
    block = max(1, CACHED // (points.shape[1] * width))
    for lo in range(0, len(rows), block):
        hi = min(lo + block, len(rows))
        at = rows[lo:hi]
        px, py = points[at, None, :, 0], points[at, None, :, 1]             # [h, 1, K]
        ax, ay = a[lo:hi, :, 0, None], a[lo:hi, :, 1, None]                # [h, M, 1]
        ex, ey = e[lo:hi, :, 0, None], e[lo:hi, :, 1, None]
        rx, ry = px - ax, py - ay                          # [h, M, K]: the points innermost
        t = clip_arrays((rx * ex + ry * ey) / ee[lo:hi, :, None], 0.0, 1.0)
        dx, dy = rx - t * ex, ry - t * ey
        out[at] = np.sqrt(np.minimum.reduce(dx * dx + dy * dy, axis=1))
    return out


def _path(came: dict[int, int] | list[int], node: int) -> list[int]:
    """The nodes from the start to ``node``, following ``came`` (the start's entry is -1)."""
    path = [node]
    while came[path[-1]] != -1:
        path.append(came[path[-1]])
    return path[::-1]


def _astar(neighbours: Callable[[int], Iterable[tuple[int, float]]], start: int, goal: int,
           pos: Callable[[int], np.ndarray]) -> list[int] | None:
    frontier = [(0.0, 0, start)]
    came = {start: -1}
    cost = {start: 0.0}
    tie = 0
    while frontier:
        _, _, node = heapq.heappop(frontier)
        if node == goal:
            return _path(came, node)
        for nxt, step in neighbours(node):
            c = cost[node] + step
            if c < cost.get(nxt, math.inf):
                cost[nxt] = c
                came[nxt] = node
                tie += 1
                heapq.heappush(frontier, (c + math.dist(pos(nxt), pos(goal)), tie, nxt))
    return None


def corridor_route(corridors: tuple[Corridor, ...], start: Pose, goal: Goal,
                   walls: np.ndarray | None = None, least: float = 0.0,
                   half_width: float = 0.0) -> Route:
    """The shortest way along the corridors' centre lines, joined where they cross, keeping
    ``least`` inches from the ``walls [W, 4]`` (when given): a stretch narrower than that is
    left out, and with no way round it the goal is refused, naming the narrowest place of the
    widest way (:class:`NarrowPassage`; ``half_width``: the robot's, for what it suggests)."""
    segs = [(np.asarray(a, float), np.asarray(b, float), c.width)
            for c in corridors for a, b in zip(c.points[:-1], c.points[1:])]
    splits = _crossings(segs)
    ends = []
    for xy in ((start.x, start.y), (goal.x, goal.y)):
        best = _nearest_on(segs, np.asarray(xy, float))
        if best is None:
            raise WorldError("the map has no corridors to route along",
                             hint="add `corridors: [{points: [[0, 0], [600, 0]], width: 70}]`")
        splits[best[1]].add(best[2])
        ends.append(best)
    adj, coords, (s_id, g_id) = _centre_graph(segs, splits, ends)
    room = _edge_room(adj, coords, walls)
    path = _astar(lambda n: [(v, step) for v, step in adj.get(n, []) if room[n, v] >= least],
                  s_id, g_id, lambda n: coords[n])
    if path is None:
        if _astar(lambda n: adj.get(n, []), s_id, g_id, lambda n: coords[n]) is None:
            raise WorldError("the corridors do not connect the start to the goal",
                             hint="join the corridors: a route follows their centre lines")
        assert walls is not None            # without walls every edge has room
        raise _narrow_corridor(adj, coords, room, s_id, g_id, walls, least, half_width)
    # the route runs from the start's to the goal's projection onto the centre lines; the
    # goal itself is kept apart (perception steers for it over the last lookahead)
    return Route.of([coords[n] for n in path], goal=(goal.x, goal.y))


#: A centre line's segment: its ends and its corridor's width (in).
_Segment = tuple[np.ndarray, np.ndarray, float]


def _crossings(segs: list[_Segment]) -> list[set[float]]:
    """Where each segment meets another, as fractions along it (with its ends, 0 and 1): the
    centre lines' graph joins corridors at these points, so a route can turn there."""
    splits = [{0.0, 1.0} for _ in segs]
    for i, (a, b, _) in enumerate(segs):
        for j in range(i + 1, len(segs)):
            c, d, _ = segs[j]
            e, f = b - a, d - c
            den = e[0] * f[1] - e[1] * f[0]
            if abs(den) < 1e-12:
                continue
            w = c - a
            t = (w[0] * f[1] - w[1] * f[0]) / den
            u = (w[0] * e[1] - w[1] * e[0]) / den
            if -1e-9 <= t <= 1 + 1e-9 and -1e-9 <= u <= 1 + 1e-9:
                splits[i].add(min(max(t, 0.0), 1.0))
                splits[j].add(min(max(u, 0.0), 1.0))
    return splits


def _nearest_on(segs: list[_Segment], p: np.ndarray) -> tuple[float, int, float] | None:
    """The point of the centre lines nearest ``p`` (a start or a goal), as its distance, its
    segment and the fraction along it: the route starts or ends there (``None``: no
    segments)."""
    best: tuple[float, int, float] | None = None
    for i, (a, b, _) in enumerate(segs):
        e = b - a
        t = float(np.clip(np.dot(p - a, e) / max(np.dot(e, e), 1e-12), 0, 1))
        dist = float(np.hypot(*(a + t * e - p)))
        if best is None or dist < best[0]:
            best = (dist, i, t)
    return best


def _centre_graph(segs: list[_Segment], splits: list[set[float]],
                  ends: list[tuple[float, int, float]]
                  ) -> tuple[dict[int, list[tuple[int, float]]], list[np.ndarray], list[int]]:
    """The centre lines as a graph for :func:`_astar`: each segment cut at its ``splits``,
    a point shared by segments one node (its coordinates rounded to 1e-6 in), each edge both
    ways with its length; and the nodes of ``ends`` (:func:`_nearest_on`'s)."""
    keys: dict[tuple, int] = {}
    coords: list[np.ndarray] = []

    def node(p: np.ndarray) -> int:
        key = (round(float(p[0]), 6), round(float(p[1]), 6))
        if key not in keys:
            keys[key] = len(coords)
            coords.append(p)
        return keys[key]

    adj: dict[int, list[tuple[int, float]]] = {}
    for (a, b, _), ts in zip(segs, splits):
        ids = [node(a + t * (b - a)) for t in sorted(ts)]
        for u, v in zip(ids[:-1], ids[1:]):
            step = float(math.dist(coords[u], coords[v]))
            adj.setdefault(u, []).append((v, step))
            adj.setdefault(v, []).append((u, step))
    return adj, coords, [node(segs[i][0] + t * (segs[i][1] - segs[i][0])) for _, i, t in ends]


def _edge_room(adj: dict[int, list[tuple[int, float]]], coords: list[np.ndarray],
               walls: np.ndarray | None) -> dict[tuple[int, int], float]:
    """The least distance from each edge ``(u, v)`` of the centre-line graph to the walls
    (``inf`` without walls). An edge runs inside the corridors and crosses no wall, so the
    distance between the two segments is that of the nearer end of one to the other."""
    edges = sorted({(u, v) for u, out in adj.items() for v, _ in out})
    if walls is None or not len(walls) or not edges:
        return {e: math.inf for e in edges}
    a = np.array([coords[u] for u, _ in edges])
    b = np.array([coords[v] for _, v in edges])
    segs = np.concatenate([a, b], axis=1)                                    # [E, 4]
    block = max(16, ROOM_PAIRS // len(walls))
    order = _nearby_first(segs, block)
    least = np.empty(len(segs))
    for i in range(0, len(segs), block):
        least[order[i:i + block]] = _room_of(segs[order[i:i + block]], walls)
    return {e: float(d) for e, d in zip(edges, least)}


def _nearby_first(segs: np.ndarray, block: int) -> np.ndarray:
    """The edges in an order that keeps neighbours together (by square cells of about
    ``block / 4`` edges, column by column): a block of far-flung edges is near most walls."""
    mid = 0.5 * (segs[:, :2] + segs[:, 2:])
    extent = float(np.max(np.ptp(mid, axis=0)))
    cells = max(1.0, np.sqrt(len(segs) / max(1.0, block / 4)))
    size = extent / cells if extent > 0 else 1.0
    key = np.floor((mid - mid.min(axis=0)) / size)
    return np.lexsort((mid[:, 1], key[:, 1], key[:, 0]))


#: edge-wall pairs looked at at once (some 40 bytes a pair in a block's arrays: 10 MB)
ROOM_PAIRS = 250_000
#: walls first measured exactly per edge, the nearest by their bounding boxes
ROOM_NEAREST = 4


def _segment_distances(segs: np.ndarray, walls: np.ndarray) -> np.ndarray:
    """``[E, W]`` distances between segments that cross no wall and walls: that of the
    nearer end of one to the other."""
    ends = np.concatenate([segs[:, :2], segs[:, 2:]])                       # [2E, 2]
    to_walls = point_segment_distance(ends, walls).reshape(2, len(segs), -1).min(axis=0)
    corners = np.concatenate([walls[:, :2], walls[:, 2:]])                  # [2W, 2]
    to_edges = point_segment_distance(corners, segs).reshape(2, len(walls), -1).min(axis=0)
    return np.minimum(to_walls, to_edges.T)


def _room_of(segs: np.ndarray, walls: np.ndarray) -> np.ndarray:
    """The least distance ``[E]`` from each of ``segs`` to the walls, measured exactly only
    for the walls whose bounding box is no farther than a wall already measured: each edge
    against every wall held edges x walls x 8 floats (8 GB for a corridor of 300 points
    that crosses itself everywhere). Each distance is computed as before, pair by pair, so
    the least is the same to the bit."""
    lo, hi = np.minimum(segs[:, :2], segs[:, 2:]), np.maximum(segs[:, :2], segs[:, 2:])
    wlo, whi = np.minimum(walls[:, :2], walls[:, 2:]), np.maximum(walls[:, :2], walls[:, 2:])
    gap = np.maximum(np.maximum(wlo[None] - hi[:, None], lo[:, None] - whi[None]), 0.0)
    bound = np.hypot(gap[..., 0], gap[..., 1])          # [E, W]: at most the distance
    k = min(ROOM_NEAREST, walls.shape[0])
    near = np.unique(np.argpartition(bound, k - 1, axis=1)[:, :k])
    reach = _segment_distances(segs, walls[near]).min(axis=1)      # [E]: some wall's distance
    # (with room for the rounding of either: a wall left out must be farther for sure)
    ask = np.flatnonzero((bound <= reach[:, None] * (1 + 1e-9) + 1e-9).any(axis=0))
    return _segment_distances(segs, walls[ask]).min(axis=1)


def _narrow_corridor(adj: dict[int, list[tuple[int, float]]], coords: list[np.ndarray],
                     room: dict[tuple[int, int], float], s_id: int, g_id: int, walls: np.ndarray,
                     least: float, half_width: float) -> NarrowPassage:
    """The refusal of a corridor route: the widest way's narrowest edge (a bottleneck Dijkstra
    over the centre-line graph) and the point of it nearest a wall."""
    best = {s_id: math.inf}
    came = {s_id: -1}
    frontier = [(-math.inf, 0, s_id)]
    tie = 0
    while frontier:
        width, _, u = heapq.heappop(frontier)
        if u == g_id:
            break
        for v, _ in adj.get(u, []):
            w = min(-width, room[u, v])
            if w > best.get(v, -math.inf):
                best[v], came[v] = w, u
                tie += 1
                heapq.heappush(frontier, (-w, tie, v))
    path = _path(came, g_id)
    u, v = min(zip(path[:-1], path[1:]), key=lambda e: room[e])
    steps = np.linspace(0.0, 1.0, max(2, int(math.dist(coords[u], coords[v])) + 1))
    points = coords[u] + steps[:, None] * (coords[v] - coords[u])
    gap = point_segment_distance(points, walls).min(axis=1)
    x, y = points[int(gap.argmin())]
    g = float(gap.min())
    return narrow_passage(float(x), float(y), g, least, "corridor", tenths(2 * g), half_width)


def narrow_passage(x: float, y: float, gap: float, need: float, kind: str, wide: str,
                   half_width: float = 0.0) -> NarrowPassage:
    """The refusal naming the narrowest place (x, y) of the widest way, where the robot's
    centre keeps ``gap`` of the ``need`` inches; the hint offers the squeeze only where the
    body fits (wider than ``2 * half_width``), and says what its body would keep: the centre's
    clearance less ``half_width``, not the centre's own."""
    squeeze = math.floor(gap * 10) / 10
    body = gap - half_width
    brake = (", closer than the brake can promise: `mitos docs worlds`" if body < BRAKE_PROMISE
             else "")
    return NarrowPassage(
        f"the only way to the goal passes ({x:.0f}, {y:.0f}), where the robot's centre keeps "
        f"{gap:.1f} in from the walls (a {kind} {wide} in wide); it needs {need:.1f} in",
        hint=(f"widen the {kind}, or allow the squeeze with `route: {{min_clearance: "
              f"{squeeze:g}}}` (its body then keeps as little as {body:.1f} in from the walls"
              f"{brake})"
              if squeeze > half_width else
              f"the robot is {2 * half_width:g} in wide: widen the {kind} to at least "
              f"{2 * need:g} in"))


#: in: a body nearer a wall than this, the brake cannot promise to keep off it (worlds/README.md,
#: "a body passing within about 2 in of a wall ... can touch it")
BRAKE_PROMISE = 2.0


@dataclass(frozen=True)
class Clearance:
    """Clearance of points from the occupied cells of a grid: the exact Euclidean distance
    transform of the cell centres (:mod:`.distance`), read as the distance to the nearest
    occupied cell treated as a disc of half a cell, never more than the truth at the point.
    Kept as the squared distances in cells (:func:`.distance.squared_distances`: 2 bytes a
    cell where 8 held the distances; a robot on a large map keeps one for its own map) and
    read as distances where they are looked up (:func:`.distance.from_squares`: the same bits)."""

    squares: np.ndarray            # [rows, cols] squared cells, centre to nearest occupied
    resolution: float
    origin: tuple[float, float]

    def __hash__(self) -> int:
        return id(self)

    @classmethod
    def of(cls, occupied: np.ndarray, resolution: float, origin: tuple[float, float],
           cap: float | None = None) -> Clearance:
        """The field of a grid, exact up to ``cap`` inches (see
        :func:`.distance.distance_transform`)."""
        return cls(squared_distances(occupied, resolution, cap), resolution, origin)

    @property
    def dist(self) -> np.ndarray:
        """``[rows, cols]`` in, each cell centre to the nearest occupied centre (worked out
        afresh: for a window or a block, not a hot path's whole grid)."""
        return from_squares(self.squares, self.resolution)

    def dist_at(self, squares: np.ndarray) -> np.ndarray:
        """The distances (in) of ``squares`` looked up in :attr:`squares`."""
        return from_squares(squares, self.resolution)

    def at(self, points: np.ndarray) -> np.ndarray:
        """A lower bound on the clearance (in) at each point ``[P, 2]`` (0 outside the grid):
        the cell's distance less the point's offset from the cell centre and half a cell."""
        pts, row, col, inside = self._cell_of(points)
        res, (ox, oy) = self.resolution, self.origin
        if np.count_nonzero(inside) == len(pts):      # all inside (a route's): no masks
            off = np.hypot(pts[:, 0] - (ox + (col + 0.5) * res),
                           pts[:, 1] - (oy + (row + 0.5) * res))
            return np.maximum(self.dist_at(self.squares[row, col]) - off - res / 2, 0.0)
        out = np.zeros(len(pts))
        r, c = row[inside], col[inside]
        centre = np.stack([ox + (c + 0.5) * res, oy + (r + 0.5) * res], axis=1)
        off = np.hypot(*(pts[inside] - centre).T)
        out[inside] = np.maximum(self.dist_at(self.squares[r, c]) - off - res / 2, 0.0)
        return out

    def cells(self, points: np.ndarray) -> np.ndarray:
        """The clearance (in) of the centre of the cell holding each point ``[P, 2]`` (what
        a route node there keeps; 0 outside the grid)."""
        pts, row, col, inside = self._cell_of(points)
        out = np.zeros(len(pts))
        out[inside] = np.maximum(self.dist_at(self.squares[row[inside], col[inside]])
                                 - self.resolution / 2, 0.0)
        return out

    def _cell_of(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                   np.ndarray]:
        """Points ``[P, 2]`` as floats, their cells' rows and columns, and which are inside."""
        pts = np.atleast_2d(np.asarray(points, float))
        res, (ox, oy) = self.resolution, self.origin
        col = np.floor((pts[:, 0] - ox) / res).astype(np.int64)
        row = np.floor((pts[:, 1] - oy) / res).astype(np.int64)
        rows, cols = self.squares.shape
        inside = (row >= 0) & (row < rows) & (col >= 0) & (col < cols)
        return pts, row, col, inside

    def along(self, a: np.ndarray, b: np.ndarray) -> float:
        """The smallest clearance on the segment a-b, sampled every half cell."""
        n = max(2, int(math.ceil(math.dist(a, b) / (self.resolution / 2))) + 1)
        t = _samples_of(n)[:, None]
        return float(self.at(a + t * (b - a)).min())

    def along_path(self, points: np.ndarray) -> np.ndarray:
        """:meth:`along` of every segment of the polyline ``points [M, 2]`` at once, ``[M - 1]``
        (each segment's samples and their minimum as :meth:`along` takes them)."""
        if len(points) < 2:
            return np.zeros(0)
        a, step = points[:-1], points[1:] - points[:-1]
        xy = points.tolist()                # math.dist reads Python floats the faster
        counts = [max(2, int(math.ceil(math.dist(p, q) / (self.resolution / 2))) + 1)
                  for p, q in zip(xy[:-1], xy[1:])]
        t = np.concatenate([_samples_of(n) for n in counts])[:, None]
        which = np.repeat(np.arange(len(a)), counts)
        room = self.at(a[which] + t * step[which])
        return np.minimum.reduceat(room, np.cumsum([0] + counts[:-1]))


def set_cells(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``mask.nonzero()`` of a 2-D ``mask`` (the rows and columns of its set cells, row-major):
    its flat nonzero split into rows and columns, the same cells in the same order in half
    the time of NumPy's 2-D nonzero (13 against 6 us for a window of 42 x 80 cells)."""
    cols = mask.shape[1]
    flat = np.flatnonzero(mask)
    r = flat // cols
    return r, flat - r * cols


@functools.lru_cache(maxsize=256)
def _samples_of(n: int) -> np.ndarray:
    """``np.linspace(0, 1, n)``, kept (read-only)."""
    out = np.linspace(0.0, 1.0, n)
    out.flags.writeable = False
    return out


@dataclass(frozen=True)
class Squares:
    """The occupied cells of a grid, each the square it is: how near a straight piece comes
    to them, measured exactly (:func:`.geometry.box_segment_distance`). What a route
    promises about its clearance is kept by this measure, not by :class:`Clearance`'s
    estimate."""

    occupied: np.ndarray           # [rows, cols]
    resolution: float
    origin: tuple[float, float]

    def __hash__(self) -> int:
        return id(self)

    def room(self, a: np.ndarray, b: np.ndarray, reach: float) -> float:
        """The distance (in) from the segment ``a``-``b`` to the nearest occupied cell, or
        ``reach`` where none lies nearer (cells outside the grid are free). A long segment is
        measured in pieces of about ``4 * reach``, each against the cells round it alone."""
        res, (ox, oy) = self.resolution, self.origin
        rows, cols = self.occupied.shape
        n = max(1, int(math.ceil(math.dist(a, b) / max(4 * reach, 4 * res))))
        ends = (a + _samples_of(n + 1)[:, None] * (b - a)).tolist()     # floats: the same
        rel = []
        for (px, py), (qx, qy) in zip(ends[:-1], ends[1:]):
            c0 = max(int((min(px, qx) - reach - ox) // res), 0)
            c1 = min(int((max(px, qx) + reach - ox) // res) + 1, cols)
            r0 = max(int((min(py, qy) - reach - oy) // res), 0)
            r1 = min(int((max(py, qy) + reach - oy) // res) + 1, rows)
            if c0 >= c1 or r0 >= r1:
                continue
            r, c = set_cells(self.occupied[r0:r1, c0:c1])
            if len(r):
                cx, cy = ox + (c + c0 + 0.5) * res, oy + (r + r0 + 0.5) * res
                rel.append(np.stack([px - cx, py - cy, qx - cx, qy - cy], axis=1))
        seg = np.concatenate(rel) if rel else np.zeros((0, 4))
        if not len(seg):
            return reach
        return min(float(box_segment_distance(res / 2, res / 2, seg).min()), reach)


def _simplify(points: np.ndarray, tol: float, clearance: Clearance | None = None,
              asked: float = 0.0, squares: Squares | None = None,
              floor: float = 0.0) -> np.ndarray:
    """Douglas-Peucker that keeps its word: a shortcut replaces a stretch of the path only if
    it stays as far from the walls as the stretch did, or at least ``asked`` inches, as the
    ``clearance`` field estimates them every half cell; and, with ``squares``, only if it
    keeps at least ``floor`` or what the stretch keeps, whichever is less, measured exactly
    from the occupied cells (:meth:`Squares.room`). The estimate alone let a shortcut cut
    inside the floor where it underestimated the stretch too. A shortcut the estimate
    accepts and that keeps the floor exactly is taken as before."""
    keep = np.zeros(len(points), dtype=bool)
    keep[[0, -1]] = True
    own = clearance.along_path(points) if clearance is not None else None
    steps: dict[int, float] = {}            # the path's own steps, measured as they are needed

    def stretch(i: int, j: int) -> float:
        """The least exact room of the path's steps from point ``i`` to point ``j``."""
        assert squares is not None
        for m in range(i, j):
            if m not in steps:
                steps[m] = squares.room(points[m], points[m + 1], floor)
        return min(steps[m] for m in range(i, j))

    stack = [(0, len(points) - 1)]
    while stack:
        i, j = stack.pop()
        if j <= i + 1:
            continue
        a, b = points[i], points[j]
        e = b - a
        n = math.hypot(*e) or 1.0
        mid = points[i + 1:j]
        d = np.abs(e[0] * (mid[:, 1] - a[1]) - e[1] * (mid[:, 0] - a[0])) / n
        k = int(np.argmax(d))
        split = d[k] > tol
        if not split and own is not None:
            assert clearance is not None        # `own` is measured only with a clearance
            need = min(asked, float(own[i:j].min()))
            split = clearance.along(a, b) < need
        if not split and squares is not None:
            room = squares.room(a, b, floor)
            split = room < floor - 1e-9 and room < stretch(i, j) - 1e-9
        if split and d[k] <= 1e-9:              # on the line: split the stretch in two
            k = (j - i) // 2 - 1
        if split:
            keep[i + 1 + k] = True
            stack += [(i, i + 1 + k), (i + 1 + k, j)]
    return points[keep]


class NarrowPassage(WorldError):
    """The only way to the goal is narrower than the robot needs (names the narrowest place).
    ``end``: the line of the world file it belongs at, the start's or (mostly) the goal's."""

    def __init__(self, message: str, *, end: str = "goal", **kw: Any) -> None:   # WorldError's
        super().__init__(message, **kw)
        self.end = end
        self.gap: float | None = None      # the centre's clearance at the narrowest place


def _widest_way(free_c: np.ndarray, s: tuple[int, int], t: tuple[int, int],
                edge: np.ndarray | None = None) -> tuple[tuple[int, int], float] | None:
    """The path from ``s`` to ``t`` whose narrowest place is widest (a bottleneck Dijkstra over
    the clearance ``free_c[R, C]`` of the nodes and ``edge[8, R, C]`` of the steps between
    them): the node at that narrowest place and its clearance, or None. Each step's room is
    worked out for every node at once and read from a flat view, as :func:`_grid_astar` reads
    its costs (the search visits every node it reaches before it says there is no way: on a
    4,000 x 4,000 map it took 11 s of NumPy scalar look-ups)."""
    R, C = free_c.shape
    steps = [(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]
    rooms = _step_rooms(free_c, steps, edge)
    offsets = [dr * C + dc for dr, dc in steps]
    k, goal = len(steps), t[0] * C + t[1]
    best = [-1.0] * (R * C + C + 1)     # a step off the grid reads the padding at the end
    start = s[0] * C + s[1]
    best[start] = float(free_c[s])
    heap = [(-best[start], start)]
    where = list(range(R * C))          # the narrowest place on the way to each node
    pop, push = heapq.heappop, heapq.heappush
    while heap:
        neg, node = pop(heap)
        width_here = -neg
        if width_here < best[node]:
            continue
        if node == goal:
            return divmod(where[node], C), width_here
        for off, here in zip(offsets, rooms[node * k:node * k + k]):
            width = width_here if not here < width_here else here     # min(width_here, here)
            nxt = node + off
            if width > best[nxt]:                        # (off the grid: here is -inf)
                best[nxt] = width
                where[nxt] = where[node] if here >= width_here else nxt
                push(heap, (-width, nxt))
    return None


def _step_rooms(free_c: np.ndarray, steps: list[tuple[int, int]],
                edge: np.ndarray | None) -> memoryview:
    """Flat, node by node (a view that gives Python floats, without a list of them; step
    ``m`` from node ``n`` at ``n * 8 + m``): the room of each step,
    ``min(free_c`` of the node it reaches``, edge[m]`` of the node it leaves``)`` as Python's
    ``min`` takes it (the first unless the second is smaller), ``-inf`` off the grid."""
    R, C = free_c.shape
    rooms = np.full((R, C, len(steps)), -np.inf)
    for m, (dr, dc) in enumerate(steps):
        src = (slice(max(0, -dr), R - max(0, dr)), slice(max(0, -dc), C - max(0, dc)))
        dst = (slice(max(0, dr), R + min(0, dr)), slice(max(0, dc), C + min(0, dc)))
        far = free_c[dst]
        if edge is not None:
            own = edge[m][src]
            far = np.where(own < far, own, far)
        rooms[src + (m,)] = far
    return rooms.reshape(-1).data


ROOM = 4.0              # in a route asks for beyond the least it accepts, where it can


def clearances(robot: Robot, min_clearance: float | None = None) -> tuple[float, float]:
    """What "the robot fits" means, for the route planner and the worlds that promise a way:
    the clearance (in) a route asks for (half the width, the safety margin and ``ROOM``) and
    the least it accepts where nothing wider leads to the goal (half the width and the
    margin, or a world's ``route: {min_clearance}``)."""
    least = robot.width / 2 + robot.safety_margin
    if min_clearance is not None:
        least = min_clearance
    return max(robot.width / 2 + robot.safety_margin + ROOM, least), least


def _nodes(dist: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One node per block of ``k`` x ``k`` cells, at the block's clearest cell (the one
    nearest the block's middle among equals): its row, column ``[R, C]`` and distance. A node
    fixed at the block's middle would miss a passage's centre line by up to half a block and
    refuse a passage the robot fits with a few inches to spare."""
    rows, cols = dist.shape
    R, C = -(-rows // k), -(-cols // k)
    padded = np.full((R * k, C * k), -np.inf)
    padded[:rows, :cols] = dist
    off = np.arange(k) - (k - 1) / 2
    tie = 1e-6 * np.hypot(off[:, None], off[None, :])          # prefer the middle
    blocks = padded.reshape(R, k, C, k).transpose(0, 2, 1, 3) - tie
    best = blocks.reshape(R, C, k * k).argmax(axis=2)
    br, bc = np.divmod(best, k)
    fr = np.arange(R)[:, None] * k + br
    fc = np.arange(C)[None, :] * k + bc
    return fr, fc, padded[fr, fc]


NARROW_COST = 20.0      # extra cost per step (in steps) of a node closer than the asked clearance
NODE = 6.0              # in: a route node's block, about (whole cells)


def grid_route(static: StaticMap, start: Pose, goal: Goal, clearance: float,
               cell: float = NODE, minimum: float | None = None,
               occupied: np.ndarray | None = None, explain: bool = True,
               leave: float = 0.0, behind: float = 0.0, keep: bool = True,
               last: Prepared | None = None, half_width: float = 0.0,
               given: bool = False, between: bool = False) -> Route:
    """A* on nodes about ``cell`` inches apart, each kept at least ``clearance`` inches (the
    exact Euclidean distance) from the occupied cells, preferring the middle of the corridors.
    Nodes closer than that but not closer than ``minimum`` (the robot's half width plus its
    margin, unless the world allows a tighter squeeze) cost ``NARROW_COST`` times more, so the
    route squeezes only where nothing wider leads on; with no way even at ``minimum`` it
    refuses, naming the narrowest place of the widest way. ``occupied`` replaces the map's
    own cells (what the robot knows, when that is not the map). ``explain=False`` skips the search for
    the narrowest place (replanning only needs to know that there is no way). ``leave``:
    within this many inches of the start, any node off the occupied cells is open (a robot
    that replans beside what it is passing must be able to move off). ``keep``: keep what
    the search works out from the grid's own cells for the next search on the same grid
    (:func:`_prepared`; not for a grid made for one search); ``last``: where one robot's
    searches on its own map keep what they work out, for its next. ``half_width``: the
    robot's, for what a refusal suggests (a squeeze only where its body fits); ``given``: the
    grid is the map the robot is given (``map: {given}``), not the map itself, which a
    refusal says (a start in a wall of it passed the checks of the map itself); ``between``:
    before it refuses a way that falls short of ``minimum`` by less than a node can stand off
    a passage's middle, look again with nodes between the cells too (:func:`_between_cells`):
    a route found without it is never changed."""
    g = static.grid
    assert g is not None        # callers plan on a grid (plan_route checks; the rest build one)
    occ = g.occupied if occupied is None else occupied
    reach = clearance + 36.0           # in: beyond this from the walls, the middle is as good
    k = max(1, int(round(cell / g.resolution)))
    rows, cols = occ.shape
    R, C = -(-rows // k), -(-cols // k)
    field, (fr, fc, node_c), kept = _prepared(g, occ, reach + 2 * g.resolution, k, keep,
                                               last)
    edge = step_rooms(field, kept)                             # clearance of each step (in)
    node_c = node_c - g.resolution / 2                         # clearance at each node (in)
    size = k * g.resolution

    def cell_of(x: float, y: float) -> tuple[int, int]:
        return (int((y - g.origin[1]) // size), int((x - g.origin[0]) // size))

    def centre(rc: tuple[int, int]) -> tuple[float, float]:
        return (g.origin[0] + (fc[rc] + 0.5) * g.resolution,
                g.origin[1] + (fr[rc] + 0.5) * g.resolution)

    s, t = cell_of(start.x, start.y), cell_of(goal.x, goal.y)
    for rc, what, (x, y) in ((s, "start", (start.x, start.y)), (t, "goal", (goal.x, goal.y))):
        if not (0 <= rc[0] < R and 0 <= rc[1] < C):
            raise _outside(g, occ.shape, what, x, y)
    moves = MOVES
    floor = clearance if minimum is None else min(minimum, clearance)
    penalty = _penalty(g, node_c, fr, fc, clearance, reach, start, behind)
    blocked = _blocked(node_c, floor, s, t, leave, size)

    # an edge between two nodes keeps the floor too (nodes sit at their block's clearest
    # cell, so two clear nodes may face each other across a thin wall); edges that leave the
    # start, reach the goal or move off within `leave` are exempt, as those nodes are
    loose = ~blocked & (node_c < floor)
    loose[s] = loose[t] = True
    ok = (edge >= floor) & ~blocked[None]
    narrow = (edge < clearance) & (node_c >= clearance)[None]

    costs = _steps(moves, blocked, ok, loose, penalty, narrow)
    path = _grid_astar(costs, [dr * C + dc for dr, dc, _ in moves], R, C, s[0] * C + s[1],
                       t[0] * C + t[1])
    if path is None:
        if not explain:
            raise NarrowPassage("no way to the goal on what the robot knows")
        squares = Squares(occ, g.resolution, g.origin)
        ends = ((what, p, _end_room(field, occ, p), _end_gap(squares, p, floor)) for what, p in
                (("start", (start.x, start.y)), ("goal", (goal.x, goal.y))))
        refusal = _refusal(node_c, s, t, centre, floor, edge, half_width, tuple(ends),
                           _map_words(g, given), size, source=g.source if given else "")
        gap = getattr(refusal, "gap", None)
        if between and gap is not None and floor - gap < g.resolution * math.sqrt(0.5):
            found = _between_cells(g, occ, start, goal, clearance, floor, cell)
            if found is not None:
                return found
        raise refusal
    pts = _route_points(g, path, C, fr, fc, start, goal)
    pts = _simplify(pts, size * 0.75, field, clearance,
                    Squares(occ, g.resolution, g.origin), floor)
    return Route.of(pts, goal=(goal.x, goal.y))


def _outside(g: Grid, shape: tuple[int, ...], what: str, x: float, y: float) -> NarrowPassage:
    """The refusal of a start or goal off the grid (of ``shape`` cells) the robot plans on."""
    rows, cols = shape
    name = f" `{Path(g.source).name}`" if g.source else ""
    return NarrowPassage(
        f"the {what} ({x:g}, {y:g}) lies outside the map{name} the robot plans on "
        f"(x {g.origin[0]:g} to {g.origin[0] + cols * g.resolution:g}, y "
        f"{g.origin[1]:g} to {g.origin[1] + rows * g.resolution:g} in)",
        hint="a `given` map must cover the start and the goal" if g.source else None,
        end=what)


def _penalty(g: Grid, node_c: np.ndarray, fr: np.ndarray, fc: np.ndarray, clearance: float,
             reach: float, start: Pose, behind: float) -> np.ndarray:
    """Each node's extra cost per step: up to 4 off the middle (within ``reach`` of the
    walls), :data:`NARROW_COST` closer than ``clearance`` (so the route squeezes through only
    where nothing wider leads on), and :data:`NARROW_COST` within ``behind`` inches behind the
    start (a tricycle cannot turn on the spot: the way back costs a squeeze)."""
    penalty = (np.clip(reach - node_c, 0.0, reach) / reach * 4.0
               + np.where(node_c < clearance, NARROW_COST, 0.0))
    if behind > 0:
        x = g.origin[0] + (fc + 0.5) * g.resolution
        y = g.origin[1] + (fr + 0.5) * g.resolution
        h = math.radians(start.heading)
        rx, ry = x - start.x, y - start.y
        back = (rx * math.cos(h) + ry * math.sin(h) < 0) & (np.hypot(rx, ry) <= behind)
        penalty = penalty + np.where(back, NARROW_COST, 0.0)
    return penalty


def _blocked(node_c: np.ndarray, floor: float, s: tuple[int, int], t: tuple[int, int],
             leave: float, size: float) -> np.ndarray:
    """The nodes closer than ``floor`` to what is occupied, except the start and the goal
    (the robot stands there: let the search leave it) and, within ``leave`` inches of the
    start, any node off the occupied cells."""
    blocked = node_c < floor
    blocked[s] = blocked[t] = False
    if leave > 0:
        R, C = node_c.shape
        n = int(math.ceil(leave / size))
        r0, c0 = max(s[0] - n, 0), max(s[1] - n, 0)
        rr, cc = np.mgrid[r0:min(s[0] + n + 1, R), c0:min(s[1] + n + 1, C)]
        near = (np.hypot(rr - s[0], cc - s[1]) * size <= leave) & (node_c[rr, cc] > 0)
        blocked[rr[near], cc[near]] = False
    return blocked


def _route_points(g: Grid, path: list[int], C: int, fr: np.ndarray, fc: np.ndarray,
                  start: Pose, goal: Goal) -> np.ndarray:
    """The start, the centre of every node of ``path`` between, and the goal."""
    r, c = np.divmod(np.array(path[1:-1], dtype=np.int64), C)
    pts = np.empty((len(r) + 2, 2))
    pts[1:-1, 0] = g.origin[0] + (fc[r, c] + 0.5) * g.resolution
    pts[1:-1, 1] = g.origin[1] + (fr[r, c] + 0.5) * g.resolution
    pts[0], pts[-1] = (start.x, start.y), (goal.x, goal.y)
    return pts


def _steps(moves: Sequence[tuple[int, int, float]], blocked: np.ndarray, ok: np.ndarray,
           loose: np.ndarray, penalty: np.ndarray, narrow: np.ndarray) -> memoryview:
    """Every step of the node grid ``[R, C]`` at once, flat and node by node (move ``m``
    from node ``n`` at ``n * len(moves) + m``): its cost, ``step * (1 + penalty +
    NARROW_COST where the edge is narrow)`` in that order, as A* added it up, or ``inf``
    where it may not be taken (off the grid, onto a blocked node, or along an edge short
    of the floor between two nodes neither of them loose): A* adds that up and finds it no
    cheaper than any node's cost, as if it had skipped the step."""
    R, C = blocked.shape
    costs = np.full((R, C, len(moves)), np.inf)
    for m, (dr, dc, step) in enumerate(moves):
        src = (slice(max(0, -dr), R - max(0, dr)), slice(max(0, -dc), C - max(0, dc)))
        dst = (slice(max(0, dr), R + min(0, dr)), slice(max(0, dc), C + min(0, dc)))
        allowed = ~blocked[dst] & (ok[m][src] | loose[src] | loose[dst])
        cost = step * (1.0 + penalty[dst] + np.where(narrow[m][src], NARROW_COST, 0.0))
        costs[src + (m,)] = np.where(allowed, cost, np.inf)
    return costs.reshape(-1).data


@functools.lru_cache(maxsize=4)
def _distances(R: int, C: int) -> np.ndarray:
    """``[R, C]``: ``math.dist`` from node ``(0, 0)`` to every node, each worked out by
    ``math.dist`` itself, so that A*'s heuristic is read, not worked out, with its bits. It
    depends on the absolute differences alone, so this quarter gives every node's distance
    to any goal (:func:`_heuristic`). Kept (read-only)."""
    out = np.array([[math.dist((r, c), (0, 0)) for c in range(C)] for r in range(R)])
    out.flags.writeable = False
    return out


def _heuristic(R: int, C: int, goal: int) -> list[float]:
    """``math.dist`` from every node of the grid ``[R, C]`` to node ``goal``, flat."""
    gr, gc = divmod(goal, C)
    rows, cols = np.abs(np.arange(R) - gr), np.abs(np.arange(C) - gc)
    return _distances(R, C)[rows[:, None], cols[None, :]].ravel().tolist()


def _grid_astar(costs: memoryview, offsets: list[int], R: int, C: int, start: int,
                goal: int) -> list[int] | None:
    """:func:`_astar` over the node grid ``[R, C]`` with the steps of :func:`_steps` (the
    same pushes in the same order, so the same path), without a Python call per neighbour:
    the heuristic to the goal is read from :func:`_heuristic`, and a node popped again at
    the cost it was expanded at is not expanded again (it would push nothing: no step from
    it is cheaper than it was)."""
    size, k = R * C, len(offsets)
    h = _heuristic(R, C, goal)
    frontier = [(0.0, 0, start)]
    came = [-1] * size                   # lists by node: cheaper to read than dicts
    cost = [math.inf] * (size + C + 1)   # a step off the grid (costing inf) reads the padding
                                         # at the end, a negative index too
    done = [math.nan] * size             # the cost a node was expanded at
    cost[start] = 0.0
    tie = 0
    # the loop's names bound locally: the loop runs thousands of times a search
    pop, push = heapq.heappop, heapq.heappush
    while frontier:
        node = pop(frontier)[2]
        if node == goal:
            return _path(came, node)
        here = cost[node]
        if done[node] == here:
            continue
        done[node] = here
        for off, step in zip(offsets, costs[node * k:node * k + k]):
            c = here + step
            if c < cost[node + off]:
                nxt = node + off
                cost[nxt] = c
                came[nxt] = node
                tie += 1
                push(frontier, (c + h[nxt], tie, nxt))
    return None


def _samples(field: Clearance, xy: np.ndarray) -> np.ndarray:
    """Where along a step its clearance is sampled: every half cell or closer over the
    distance from node (0, 0) to node (1, 1)."""
    R, C = xy.shape[:2]
    step = math.dist(xy[0, 0], xy[min(1, R - 1), min(1, C - 1)]) if R * C > 1 else 1.0
    return np.linspace(0.0, 1.0, max(3, int(math.ceil(2 * step / field.resolution)) + 1))


def _edges_from(out: np.ndarray, field: Clearance, xy: np.ndarray, t: np.ndarray,
                moves: tuple[tuple[int, int, float], ...], rows: tuple[int, int],
                cols: tuple[int, int]) -> None:
    """Fill ``out [len(moves), R, C]`` with the smallest clearance on each step from the
    nodes in ``rows`` x ``cols`` (half-open ranges of node rows and columns) to its neighbour
    in each move, sampled at ``t`` along it and measured as the nodes are
    (:meth:`Clearance.cells`); each step's clearance is its own samples' alone, so any part
    gives the bits of the whole, as the least square of its samples (:func:`_least`). Steps off
    the grid are left as they are (:func:`_no_steps`).

    A sample's clearance, ``max(dist - res / 2, 0)``, never falls as ``dist`` grows (nor
    does a rounded subtraction), so the smallest is that of the smallest ``dist``: one
    subtraction a step, and none until a search reads it (:func:`step_rooms`). Every move's
    samples are worked out at once, the samples outermost (long inner loops), a step off the
    grid as a step to the node itself (and left out). A sample off the field counts a square
    of 0, as :meth:`Clearance.cells` reads its clearance 0."""
    R, C = xy.shape[:2]
    r0, r1 = max(rows[0], 0), min(rows[1], R)
    c0, c1 = max(cols[0], 0), min(cols[1], C)
    if r0 >= r1 or c0 >= c1:
        return
    band = max(1, _EDGE_SAMPLES // (len(moves) * len(t) * (c1 - c0)))
    if r1 - r0 > band:            # a whole grid in bands of rows: its arrays stay tens of MB
        for a in range(r0, r1, band):
            _edges_from(out, field, xy, t, moves, (a, min(a + band, r1)), (c0, c1))
        return
    r, c = np.arange(r0, r1)[:, None], np.arange(c0, c1)[None, :]
    dr, dc = (np.array([move[j] for move in moves], dtype=np.intp)[:, None, None]
              for j in (0, 1))
    on = (r + dr >= 0) & (r + dr < R) & (c + dc >= 0) & (c + dc < C)     # [M, r, c]
    src = (r * C + c).reshape(-1)                            # the nodes the steps leave, flat
    dst = np.where(on.reshape(len(moves), -1), src + (dr * C + dc).reshape(-1, 1), src)
    least = _least(field, xy, t, src, dst)                                 # [M, P]
    out[:, r0:r1, c0:c1][on] = least.reshape(on.shape)[on]


def _least(field: Clearance, xy: np.ndarray, t: np.ndarray, src: np.ndarray,
           dst: np.ndarray) -> np.ndarray:
    """The smallest clearance on each step from node ``src`` to node ``dst`` (flat indices
    of the nodes ``xy [R, C, 2]``; ``src`` broadcast against ``dst``), sampled at ``t`` (see
    :func:`_edges_from`), ``dst``'s shape: as the least square of its samples (0 for one off
    the field, whose clearance :meth:`Clearance.cells` reads 0), which :func:`step_rooms`
    reads as inches."""
    res, (ox, oy) = field.resolution, field.origin
    rows_n, cols_n = field.squares.shape
    xs, ys = xy[..., 0].reshape(-1), xy[..., 1].reshape(-1)
    ax, ay, tt = xs[src], ys[src], t.reshape((-1,) + (1,) * dst.ndim)
    x = ax + tt * (xs[dst] - ax)                                         # [T, *dst.shape]
    y = ay + tt * (ys[dst] - ay)
    col = np.floor((x - ox) / res).astype(np.int64)
    row = np.floor((y - oy) / res).astype(np.int64)
    if col.min() >= 0 and col.max() < cols_n and row.min() >= 0 and row.max() < rows_n:
        row *= cols_n
        row += col
        return np.minimum.reduce(field.squares.reshape(-1)[row], axis=0)
    inside = (row >= 0) & (row < rows_n) & (col >= 0) & (col < cols_n)
    squares = np.zeros(row.shape, dtype=field.squares.dtype)
    squares[inside] = field.squares[row[inside], col[inside]]
    return np.minimum.reduce(squares, axis=0)


def _off_grid(kind: np.dtype) -> int | float:
    """What a kept step off the grid holds: a square no step has (the largest integer of a
    capped field's squares, which stay below ``(cap + 1)**2``; ``-inf`` for float ones)."""
    return int(np.iinfo(kind).max) if kind.kind in "iu" else -math.inf


def _no_steps(field: Clearance, xy: np.ndarray) -> np.ndarray:
    """``[len(MOVES), R, C]`` of steps not yet measured: every one off the grid."""
    kind = field.squares.dtype
    return np.full((len(MOVES), *xy.shape[:2]), _off_grid(kind), dtype=kind)


def step_rooms(field: Clearance, kept: np.ndarray) -> np.ndarray:
    """The clearance (in) of each step whose least square ``kept`` holds (:func:`_least`):
    ``max(distance - res / 2, 0)``, as :meth:`Clearance.cells` reads a sample (it never
    falls as the square grows, so the step's least), ``-inf`` off the grid. Kept as squares,
    the steps take a quarter of the memory; read as inches where a search needs them."""
    off = kept == _off_grid(kept.dtype)
    room = np.maximum(field.dist_at(np.where(off, 0, kept)) - field.resolution / 2, 0.0)
    room[off] = -np.inf
    return room


def _edges_near(out: np.ndarray, field: Clearance, xy: np.ndarray, t: np.ndarray,
                moves: tuple[tuple[int, int, float], ...], dirty: np.ndarray) -> None:
    """:func:`_edges_from` of the steps that may sample a cell of a ``dirty`` block (``[R,
    C]``, a node's): a step's samples lie between its two nodes' cell centres, so in its own
    block, the block it steps into or (a diagonal step) the two beside both. The rest keep
    their bits; the steps are worked out a slice at a time (arrays of tens of MB at most).
    The steps of every move are picked at once (``dirty`` shifted by each move: views of it
    padded, in the moves' order and row-major within each, as they are taken move by move):
    a pass a move cost more in calls than in work."""
    R, C = dirty.shape
    pad = np.zeros((R + 2, C + 2), dtype=bool)
    pad[1:-1, 1:-1] = dirty
    shifted = np.lib.stride_tricks.sliding_window_view(pad, (R, C))  # [3, 3]: pad[i:, j:]
    dr, dc = _shifts(moves)
    near = shifted[1 + dr, 1] | shifted[1, 1 + dc]                    # [M, R, C]
    near |= shifted[1 + dr, 1 + dc]
    near |= dirty
    flat = np.flatnonzero(near)
    move = flat // (R * C)
    src = flat - move * (R * C)                                       # the node, row-major
    r = src // C
    c = src - r * C
    to_r, to_c = r + dr[move], c + dc[move]
    on = (to_r >= 0) & (to_r < R) & (to_c >= 0) & (to_c < C)          # no step off the grid
    move, r, c, src = move[on], r[on], c[on], src[on]
    dst = to_r[on] * C + to_c[on]
    step = max(1, _EDGE_SAMPLES // len(t))
    for a in range(0, len(src), step):
        s = slice(a, a + step)
        out[move[s], r[s], c[s]] = _least(field, xy, t, src[s], dst[s])


@functools.lru_cache(maxsize=4)
def _shifts(moves: tuple[tuple[int, int, float], ...]) -> tuple[np.ndarray, np.ndarray]:
    """Each move's rows and columns, ``[M]`` each; kept (read-only)."""
    dr = np.array([m[0] for m in moves], dtype=np.intp)
    dc = np.array([m[1] for m in moves], dtype=np.intp)
    for a in (dr, dc):
        a.flags.writeable = False
    return dr, dc


#: samples :func:`_edges_from` works out in one pass (about 40 bytes each at its peak)
_EDGE_SAMPLES = 8 * CACHED

MOVES = tuple((dr, dc, math.hypot(dr, dc)) for dr in (-1, 0, 1) for dc in (-1, 0, 1)
              if dr or dc)


@functools.lru_cache(maxsize=4)
def _planned_on(grid: Grid, cap: float, k: int) -> Planned:
    """What :func:`grid_route` works out from a grid's own cells before it searches: the
    clearance field (exact up to ``cap``), the nodes (blocks of ``k`` cells), every step's
    clearance and where along a step it is sampled. Kept (read-only): every run of a world
    plans on the same grid, and a robot's map differs from it only round what it has marked
    (:func:`_prepared`)."""
    field = Clearance.of(grid.occupied, grid.resolution, grid.origin, cap=cap)
    nodes = _nodes(field.dist, k)
    xy = _node_xy(grid, nodes)
    t = _samples(field, xy)
    edge = _no_steps(field, xy)
    _edges_from(edge, field, xy, t, MOVES, (0, xy.shape[0]), (0, xy.shape[1]))
    for a in (field.squares, *nodes, edge):
        a.flags.writeable = False
    return field, nodes, edge, len(t)


def _node_xy(grid: Grid, nodes: Nodes) -> np.ndarray:
    """``[R, C, 2]`` the nodes' cell centres (as :func:`grid_route`'s ``centre``)."""
    fr, fc, _ = nodes
    return np.stack([grid.origin[0] + (fc + 0.5) * grid.resolution,
                     grid.origin[1] + (fr + 0.5) * grid.resolution], axis=-1)


@dataclass
class Prepared:
    """What :func:`_prepared` last worked out for one robot's map (its cells then, the field,
    the nodes, every step's clearance and how many samples a step took), so that its next
    search starts from there: between two replans a robot marks and clears a few cells round
    where it drives, while the difference from the grid's own cells grows with every cell
    it has marked since the start."""

    key: tuple = ()                # (grid, cap, k) it was worked out for (the grid itself)
    occ: np.ndarray | None = None  # a copy of the cells
    field: Clearance | None = None
    nodes: tuple = ()
    edge: np.ndarray | None = None  # each step's least square (read by step_rooms)
    samples: int = 0


def _prepared(grid: Grid, occ: np.ndarray, cap: float, k: int, keep: bool = True,
              last: Prepared | None = None) -> tuple[Clearance, Nodes, np.ndarray]:
    """The clearance field, the nodes and every step's clearance (:func:`_planned_on`) for
    the cells ``occ`` (the grid's own, or a robot's map of it): from the grid's own, or from
    what was worked out for the same robot's map ``last`` time (kept there again), worked
    out again only where the cells that differ can reach. The capped field at a cell depends
    on the cells within ``n`` cells of it each way (:func:`.distance._capped_squares`), a node on its
    block's field, a step's clearance on its two nodes and the cells between them (which lie
    in the two nodes' blocks and, a diagonal step's, the two beside both): the rest keeps its
    bits."""
    out: tuple | None           # what _prepared_from gives, else the Planned worked out here
    if last is not None and keep and occ is not grid.occupied:
        out = _prepared_from(grid, occ, cap, k, last)
        if out is not None:
            return out
    res = grid.resolution
    n = int(math.ceil(cap / res))
    rows, cols = occ.shape
    if not keep or occ is not grid.occupied and (not occ.any() or not grid.occupied.any()
                                                 or n >= max(rows, cols)):
        field = Clearance.of(occ, res, grid.origin, cap=cap)      # no shortcut applies
        nodes = _nodes(field.dist, k)
        xy = _node_xy(grid, nodes)
        edge = _no_steps(field, xy)
        t = _samples(field, xy)
        _edges_from(edge, field, xy, t, MOVES, (0, xy.shape[0]), (0, xy.shape[1]))
        out = field, nodes, edge, len(t)
    else:
        out = _patched(grid, occ, grid.occupied, cap, k, *_planned_on(grid, cap, k))
    if last is not None and keep:
        _keep(last, grid, occ, cap, k, out)
    return out[:3]


def _prepared_from(grid: Grid, occ: np.ndarray, cap: float, k: int, last: Prepared
                   ) -> tuple[Clearance, Nodes, np.ndarray] | None:
    """:func:`_prepared` from what ``last`` holds (``None`` when it holds nothing for this
    grid, cap and block size, or when either's field is not the capped one: nothing
    occupied, or a cap beyond the grid)."""
    if last.occ is None or last.key[0] is not grid or last.key[1:] != (cap, k) \
            or int(math.ceil(cap / grid.resolution)) >= max(occ.shape) \
            or not occ.any() or not last.occ.any():
        return None
    assert last.field is not None and last.edge is not None
    out = _patched(grid, occ, last.occ, cap, k, last.field, last.nodes, last.edge,
                   last.samples)
    _keep(last, grid, occ, cap, k, out)
    return out[:3]


def _keep(last: Prepared, grid: Grid, occ: np.ndarray, cap: float, k: int, out: Planned) -> None:
    last.key, last.occ = (grid, cap, k), occ.copy()
    last.field, last.nodes, last.edge, last.samples = out


def _patched(grid: Grid, occ: np.ndarray, base_occ: np.ndarray, cap: float, k: int,
             base_field: Clearance, base_nodes: Nodes, base_edge: np.ndarray, samples: int) -> Planned:
    """The field, nodes, steps' clearance and samples per step for ``occ``, from those worked
    out for ``base_occ``: the field again where the cells that differ can reach, and the
    nodes and steps only round the cells whose distance changed (a node depends on its
    block's distances alone, a step on its two nodes and the cells between them)."""
    res = grid.resolution
    n = int(math.ceil(cap / res))
    rows, cols = occ.shape
    diff = occ != base_occ
    changed_rows = np.flatnonzero(diff.any(axis=1))
    if not len(changed_rows):
        return base_field, base_nodes, base_edge, samples
    changed_cols = np.flatnonzero(diff.any(axis=0))
    # the field where it can differ (n cells round the changed ones), from n more round that
    d0, d1 = max(int(changed_rows[0]) - n, 0), min(int(changed_rows[-1]) + 1 + n, rows)
    e0, e1 = max(int(changed_cols[0]) - n, 0), min(int(changed_cols[-1]) + 1 + n, cols)
    f0, f1 = max(d0 - n, 0), min(d1 + n, rows)
    g0, g1 = max(e0 - n, 0), min(e1 + n, cols)
    part = _capped_squares(occ[f0:f1, g0:g1], n, (d0 - f0, d1 - f0, e0 - g0, e1 - g0))
    moved = part != base_field.squares[d0:d1, e0:e1]
    moved_rows = np.flatnonzero(np.logical_or.reduce(moved, axis=1))
    if not len(moved_rows):                     # no cell's distance changed: nor anything else
        return base_field, base_nodes, base_edge, samples
    moved_cols = np.flatnonzero(np.logical_or.reduce(moved, axis=0))
    squares = base_field.squares.copy()
    squares[d0:d1, e0:e1] = part
    field = Clearance(squares, res, grid.origin)
    # the nodes of the blocks that hold a cell whose distance changed
    b0, b1 = (d0 + int(moved_rows[0])) // k, -(-(d0 + int(moved_rows[-1]) + 1) // k)
    c0, c1 = (e0 + int(moved_cols[0])) // k, -(-(e0 + int(moved_cols[-1]) + 1) // k)
    fr, fc, node_d = (a.copy() for a in base_nodes)
    sub = _nodes(field.dist_at(squares[b0 * k:b1 * k, c0 * k:c1 * k]), k)
    fr[b0:b1, c0:c1] = sub[0] + b0 * k
    fc[b0:b1, c0:c1] = sub[1] + c0 * k
    node_d[b0:b1, c0:c1] = sub[2]
    nodes = (fr, fc, node_d)
    xy = _node_xy(grid, nodes)
    R, C = fr.shape
    t = _samples(field, xy)
    edge = base_edge.copy()
    if len(t) != samples:                # node (0, 0) or (1, 1) moved: every step again
        _edges_from(edge, field, xy, t, MOVES, (0, R), (0, C))
    else:                                # the steps that may sample a changed distance
        dirty = np.zeros((R, C), dtype=bool)
        mr, mc = set_cells(moved)
        dirty[(d0 + mr) // k, (e0 + mc) // k] = True
        _edges_near(edge, field, xy, t, MOVES, dirty)
    return field, nodes, edge, len(t)


def _refusal(node_c: np.ndarray, s: tuple[int, int], t: tuple[int, int],
             centre: Callable[[tuple[int, int]], tuple[float, float]], floor: float,
             edge: np.ndarray | None = None, half_width: float = 0.0,
             ends: tuple[tuple[str, tuple[float, float], float, float], ...] = (),
             mapped: str = "the map", step: float = 0.0, source: str = "") -> WorldError:
    """Why no way keeps ``floor``: a start or goal (``ends``: each with its cell's clearance,
    -1 inside a wall, and its own distance to the nearest wall) in a wall of the map the
    robot plans on (``mapped``, in words; read from the map file ``source``, where one says
    whether the wall is an unknown cell) or too near one to leave it (the widest way's
    narrowest place lies within ``floor`` and a node ``step`` of it), no way at all, or the
    narrowest place of the widest way."""
    from .gridmap import unknown_at, unknown_words

    for what, (x, y), room, _ in ends:
        if room < 0 and unknown_at(source, x, y):
            return _end_refused(what, x, y, unknown_words(mapped), mapped, grey=True)
        if room < 0:
            return _end_refused(what, x, y, f"lies inside a wall of {mapped}", mapped)
    free_c = np.maximum(node_c, 0.0)
    free_c[s] = free_c[t] = np.inf
    if edge is not None:        # the steps out of the start and into the goal are exempt
        edge = np.maximum(edge, 0.0)
        edge[:, s[0], s[1]] = np.inf
        R, C = free_c.shape
        for m, (dr, dc) in enumerate((dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1)
                                     if dr or dc):
            r, c = t[0] - dr, t[1] - dc
            if 0 <= r < R and 0 <= c < C:
                edge[m, r, c] = np.inf
    widest = _widest_way(free_c, s, t, edge)
    if widest is None or widest[1] <= 0:
        if mapped == "the map":
            return NarrowPassage("no way through the map from the start to the goal",
                                 hint="check the start and goal, or use `unknown: free`")
        return NarrowPassage(f"no way from the start to the goal through {mapped}: it "
                             "plans its route on that map, not on the map itself",
                             hint="open a way on the map it is given, give it another "
                                  "(`given: PATH.yaml`), or none (`given: none`: it finds "
                                  "its way as it goes)")
    (r, c), gap = widest
    x, y = centre((r, c))
    for what, end, room, gap_there in ends:
        if room < floor and math.dist((x, y), end) <= floor + step:
            # the point's own distance; its cell's where that keeps the floor (the cell's
            # clearance, measured from its centre, undercuts the point's there)
            near = gap_there if gap_there < floor else room
            return _end_refused(what, *end, f"lies {near:.1f} in from a wall of {mapped}, "
                                f"and its route needs {floor:.1f} in to leave it", mapped)
    out = narrow_passage(x, y, gap, floor, "passage", f"about {tenths(2 * gap)}", half_width)
    out.gap = gap
    return out


def _between_cells(g: Grid, occ: np.ndarray, start: Pose, goal: Goal, clearance: float,
                   floor: float, cell: float) -> Route | None:
    """The route :func:`grid_route` finds with nodes at the cells' corners too, or ``None``.

    A node stands at a cell's centre, half a cell off the middle of a passage an even number
    of cells wide: a 12-cell door of 23.6 in, whose middle keeps 11.8 in, was refused as
    keeping 10.8 of the 11 asked. The centres and corners are the cells of a grid of half
    the size, occupied where an occupied cell's centre is: its exact distance transform is the
    distance to the nearest occupied centre at every centre and corner, and each of its
    clearances reads a quarter of a cell more than the grid's own (it takes off half its own
    cell, not half the grid's), so ``clearance`` and ``floor`` are asked for a quarter of a
    cell more. The route is kept only if it keeps ``floor`` exactly (:func:`_keeps`): each of
    its segments' distance from every occupied cell, the square it is, the first and last
    segments (leaving the start, reaching the goal) as much as the start and goal keep."""
    rows, cols = occ.shape
    fine = np.zeros((2 * rows + 1, 2 * cols + 1), dtype=bool)
    fine[1::2, 1::2] = occ
    half = g.resolution / 2
    grid = Grid(fine, half, (g.origin[0] - half / 2, g.origin[1] - half / 2), g.source)
    static = StaticMap(np.zeros((0, 4)), np.zeros((0, 4, 2)), grid,
                       (grid.origin[0], grid.origin[1], grid.origin[0] + fine.shape[1] * half,
                        grid.origin[1] + fine.shape[0] * half))
    quarter = g.resolution / 4
    try:
        route = grid_route(static, start, goal, clearance + quarter, cell, floor + quarter,
                           explain=False, keep=False)
    except NarrowPassage:
        return None
    return route if _keeps(route, g, occ, floor) else None


def _keeps(route: Route, g: Grid, occ: np.ndarray, floor: float) -> bool:
    """Whether ``route`` keeps ``floor`` from the occupied cells of ``g`` (``occ``), each the
    square it is, measured exactly (:meth:`Squares.room`): its first and last pieces as much
    as the start and the goal keep if that is less."""
    squares = Squares(occ, g.resolution, g.origin)
    pts = route.points
    need = np.full(len(pts) - 1, floor)
    need[0] = min(need[0], squares.room(pts[0], pts[0], floor))
    need[-1] = min(need[-1], squares.room(pts[-1], pts[-1], floor))
    return all(squares.room(a, b, floor) >= n - 1e-9 for a, b, n in zip(pts[:-1], pts[1:], need))


def _end_room(field: Clearance, occ: np.ndarray, p: tuple[float, float]) -> float:
    """The clearance (in) of the cell holding point ``p`` (what a node there keeps), -1
    where that cell is occupied."""
    _, row, col, inside = field._cell_of(np.array([p]))
    if inside[0] and occ[row[0], col[0]]:
        return -1.0
    return float(field.cells(np.array([p]))[0])


def _end_gap(squares: Squares, p: tuple[float, float], reach: float) -> float:
    """The exact distance (in) from the point ``p`` to the nearest occupied cell (each the
    square it is), at most ``reach``: what a refusal says it "lies ... in from a wall". The
    clearance of its cell (:func:`_end_room`, what the route's node there keeps) was said,
    measured from the cell's centre: "4.9 in" of a goal 3.98 in from the wall."""
    a = np.array(p, dtype=float)
    return squares.room(a, a, reach)


def _map_words(g: Grid, given: bool) -> str:
    """The map a route is planned on, in words: the one the robot is given, by name."""
    if not given:
        return "the map"
    return f"the map `{Path(g.source).name}` the robot is given" if g.source else \
        "the map the robot is given"


def _end_refused(what: str, x: float, y: float, why: str, mapped: str,
                 grey: bool = False) -> NarrowPassage:
    """The refusal of a start or goal its route cannot leave or reach, at its own line (in
    an unknown cell, ``grey``: with how to read those free)."""
    name = {"start": "start (q_init)", "goal": "goal (q_goal)"}[what]
    hint = (f"move the {what}, or give the robot a map that shows it clear: it plans on the "
            "map it is given, not on the map itself" if mapped != "the map" else
            f"move the {what} further from the walls")
    if grey:
        hint += "; or write `unknown: free` under `map:` to read unknown cells as free"
    return NarrowPassage(f"the {name} at ({x:g}, {y:g}) {why}", hint=hint, end=what)


def plan_route(static: StaticMap, corridors: tuple[Corridor, ...], start: Pose, goal: Goal,
               clearance: float, minimum: float | None = None,
               occupied: np.ndarray | None = None, half_width: float = 0.0,
               between: bool = False) -> Route:
    """The route over the corridors' centre lines or, with a grid, A* on the grid (on
    ``occupied`` when given: the cells the robot knows; ``between``: see
    :func:`grid_route`)."""
    if static.grid is None:
        return corridor_route(corridors, start, goal, static.walls,
                              clearance if minimum is None else minimum, half_width)
    return grid_route(static, start, goal, clearance, minimum=minimum, occupied=occupied,
                      half_width=half_width, between=between)
