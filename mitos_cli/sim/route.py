"""The route: an A* search over the corridor network or the occupancy grid, and the route's
geometry (arc length, projection of the robot onto it, the point a lookahead ahead).

The fuzzy rules do the driving; the route only says where the road goes (the paper's suggested
marriage of the fuzzy planner with roadmaps and cell decomposition).
"""

from __future__ import annotations

import functools
import heapq
import math
from dataclasses import dataclass

import numpy as np

from ..errors import WorldError
from .staticmap import StaticMap
from .world import Corridor, Goal, Pose


@dataclass(frozen=True)
class Route:
    points: np.ndarray             # [M, 2] polyline from the start to the goal (in)
    cum: np.ndarray                # [M] arc length at each point
    goal: np.ndarray               # [2] the goal (near the last point, maybe off the line)

    def __hash__(self) -> int:
        return id(self)

    @classmethod
    def of(cls, points, goal=None) -> "Route":
        pts = np.asarray(points, float)
        keep = np.concatenate([[True], np.hypot(*np.diff(pts, axis=0).T) > 1e-9])
        pts = pts[keep]
        if len(pts) == 1:
            pts = np.vstack([pts, pts])
        cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))])
        return cls(pts, cum, pts[-1].copy() if goal is None else np.asarray(goal, float))

    @property
    def length(self) -> float:
        return float(self.cum[-1])

    def point_at(self, s: float) -> np.ndarray:
        s = min(max(s, 0.0), self.length)
        i = min(int(np.searchsorted(self.cum, s, side="right")) - 1, len(self.points) - 2)
        seg = self.points[i + 1] - self.points[i]
        span = self.cum[i + 1] - self.cum[i]
        return self.points[i] + (s - self.cum[i]) / span * seg if span > 0 else self.points[i]

    @functools.cached_property
    def _segments(self) -> tuple[np.ndarray, ...]:
        """Each segment's start ``a``, vector ``e``, squared length (at least 1e-12) and
        length: the route does not change, so :meth:`project` does not recompute them."""
        a = self.points[:-1]
        e = self.points[1:] - a
        ee = np.maximum((e * e).sum(axis=1), 1e-12)
        return a, e, ee, np.sqrt(ee)

    def project(self, p: np.ndarray, s_hint: float, back: float = 24.0,
                ahead: float = 120.0) -> tuple[float, float, np.ndarray]:
        """Arc length ``s``, signed lateral offset (positive RIGHT of the route) and unit
        tangent at the route point nearest to ``p`` within ``[s_hint - back, s_hint + ahead]``.

        Only the segments in that window are measured (elementwise, so each gets the bits it
        would get among all); with none in it, the first segment answers."""
        a, e, ee, root = self._segments
        window = np.flatnonzero((self.cum[1:] >= s_hint - back) &
                                (self.cum[:-1] <= s_hint + ahead))
        if len(window) == 0:
            window = np.zeros(1, dtype=np.intp)
        elif len(window) < len(a):
            a, e, ee, root = a[window], e[window], ee[window], root[window]
        t = np.clip(((p - a) * e).sum(axis=1) / ee, 0.0, 1.0)
        closest = a + t[:, None] * e
        d = np.hypot(*(p - closest).T)
        i = int(np.argmin(d))
        s = self.cum[window[i]] + t[i] * root[i]
        tangent = e[i] / math.sqrt(ee[i])
        rel = p - closest[i]
        lateral = float(rel[0] * tangent[1] - rel[1] * tangent[0])   # right of the tangent
        return float(s), lateral, tangent


def _astar(neighbours, start: int, goal: int, pos) -> list[int] | None:
    frontier = [(0.0, 0, start)]
    came = {start: -1}
    cost = {start: 0.0}
    tie = 0
    while frontier:
        _, _, node = heapq.heappop(frontier)
        if node == goal:
            path = [node]
            while came[path[-1]] != -1:
                path.append(came[path[-1]])
            return path[::-1]
        for nxt, step in neighbours(node):
            c = cost[node] + step
            if c < cost.get(nxt, math.inf):
                cost[nxt] = c
                came[nxt] = node
                tie += 1
                heapq.heappush(frontier, (c + math.dist(pos(nxt), pos(goal)), tie, nxt))
    return None


def corridor_route(corridors: tuple[Corridor, ...], start: Pose, goal: Goal) -> Route:
    """The shortest way along the corridors' centre lines, joined where they cross."""
    segs = [(np.asarray(a, float), np.asarray(b, float), c.width)
            for c in corridors for a, b in zip(c.points[:-1], c.points[1:])]
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
    ends = []
    for p in ((start.x, start.y), (goal.x, goal.y)):
        p = np.asarray(p, float)
        best = None
        for i, (a, b, _) in enumerate(segs):
            e = b - a
            t = float(np.clip(np.dot(p - a, e) / max(np.dot(e, e), 1e-12), 0, 1))
            dist = float(np.hypot(*(a + t * e - p)))
            if best is None or dist < best[0]:
                best = (dist, i, t)
        splits[best[1]].add(best[2])
        ends.append(best)
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
    s_id, g_id = (node(segs[i][0] + t * (segs[i][1] - segs[i][0])) for _, i, t in ends)
    path = _astar(lambda n: adj.get(n, []), s_id, g_id, lambda n: coords[n])
    if path is None:
        raise WorldError("the corridors do not connect the start to the goal",
                         hint="join the corridors: a route follows their centre lines")
    # the route runs from the start's to the goal's projection onto the centre lines; the
    # goal itself is kept apart (perception steers for it over the last lookahead)
    return Route.of([coords[n] for n in path], goal=(goal.x, goal.y))


def _simplify(points: np.ndarray, tol: float) -> np.ndarray:
    """Douglas-Peucker."""
    keep = np.zeros(len(points), dtype=bool)
    keep[[0, -1]] = True
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
        if d[k] > tol:
            keep[i + 1 + k] = True
            stack += [(i, i + 1 + k), (i + 1 + k, j)]
    return points[keep]


def grid_route(static: StaticMap, start: Pose, goal: Goal, clearance: float,
               cell: float = 6.0) -> Route:
    """A* on a coarse copy of the grid (cells of about ``cell`` inches), blocked where closer
    than ``clearance`` to a wall, and preferring cells far from walls (so the route keeps to
    the middle of the corridors)."""
    g = static.grid
    k = max(1, int(round(cell / g.resolution)))
    rows, cols = g.occupied.shape
    R, C = -(-rows // k), -(-cols // k)
    padded = np.ones((R * k, C * k), dtype=bool)
    padded[:rows, :cols] = g.occupied
    coarse = padded.reshape(R, k, C, k).any(axis=(1, 3))
    size = k * g.resolution
    # brushfire: distance to the nearest blocked coarse cell, in cells, up to `reach`
    reach = int(math.ceil((clearance + 36.0) / size))
    dist = np.full((R, C), reach, dtype=float)
    front = coarse.copy()
    dist[front] = 0
    for step in range(1, reach):
        grown = front.copy()
        grown[1:] |= front[:-1]
        grown[:-1] |= front[1:]
        grown[:, 1:] |= front[:, :-1]
        grown[:, :-1] |= front[:, 1:]
        new = grown & ~front
        dist[new] = step
        front = grown
    blocked = dist * size < clearance
    penalty = (reach - dist) / reach * 4.0

    def cell_of(x: float, y: float) -> tuple[int, int]:
        return (int((y - g.origin[1]) // size), int((x - g.origin[0]) // size))

    def centre(rc: tuple[int, int]) -> tuple[float, float]:
        return (g.origin[0] + (rc[1] + 0.5) * size, g.origin[1] + (rc[0] + 0.5) * size)

    s, t = cell_of(start.x, start.y), cell_of(goal.x, goal.y)
    for rc, what in ((s, "start"), (t, "goal")):
        if not (0 <= rc[0] < R and 0 <= rc[1] < C):
            raise WorldError(f"the {what} lies outside the map")
    free_s, free_t = blocked[s], blocked[t]
    blocked[s] = blocked[t] = False       # the robot stands there: let the search leave it
    moves = [(dr, dc, math.hypot(dr, dc)) for dr in (-1, 0, 1) for dc in (-1, 0, 1)
             if dr or dc]

    def neighbours(n: int):
        r, c = divmod(n, C)
        for dr, dc, step in moves:
            rr, cc = r + dr, c + dc
            if 0 <= rr < R and 0 <= cc < C and not blocked[rr, cc]:
                yield rr * C + cc, step * (1.0 + penalty[rr, cc])

    path = _astar(neighbours, s[0] * C + s[1], t[0] * C + t[1],
                  lambda n: (n // C, n % C))
    del free_s, free_t
    if path is None:
        raise WorldError("no way through the map from the start to the goal for a robot this "
                         "wide", hint="check the start and goal, or use `unknown: free`")
    pts = np.array([centre(divmod(n, C)) for n in path])
    pts = _simplify(pts, size * 0.75)
    return Route.of(np.vstack([[start.x, start.y], pts[1:-1], [goal.x, goal.y]]),
                    goal=(goal.x, goal.y))


def plan_route(static: StaticMap, corridors: tuple[Corridor, ...], start: Pose, goal: Goal,
               clearance: float) -> Route:
    if static.grid is None:
        return corridor_route(corridors, start, goal)
    return grid_route(static, start, goal, clearance)
