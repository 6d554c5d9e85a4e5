"""The static map as walls: corridors carved out of solid space and/or an occupancy grid.

:func:`build_static` turns a world's map into a :class:`StaticMap`: wall segments (what the
sensors see and the robot can hit) and a ``free(points)`` test. Corridors are rectangles, one
per polyline piece, stretched by half the width beyond each end so that corners and
intersections fall out of their overlaps; a wall is every rectangle side minus what lies inside
another rectangle. A grid's walls are the cell edges between blocked and free cells, merged
into runs. With both, the corridors are carved into the grid first, grown to hold them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import WorldError
from .geometry import clip_segment_outside, points_in_polygon, rect_corners
from .world import Corridor, Grid, World


def corridor_rects(corridors: tuple[Corridor, ...]) -> np.ndarray:
    """Rectangles ``[Q, 4, 2]``: one per polyline piece, extended by width/2 at both ends."""
    rects = []
    for c in corridors:
        pts = np.asarray(c.points, float)
        for a, b in zip(pts[:-1], pts[1:]):
            d = b - a
            length = float(np.hypot(*d))
            heading = float(np.arctan2(d[1], d[0]))
            mid = (a + b) / 2
            rects.append(rect_corners(mid[0], mid[1], heading, length + c.width, c.width))
    return np.array(rects).reshape(-1, 4, 2)


def corridor_walls(rects: np.ndarray) -> np.ndarray:
    """Every rectangle's sides less what lies inside the others. A side is clipped by the
    rectangles whose bounding box meets its own only (the others cut nothing): each side by
    every other rectangle took 22 s for a polyline of 400 points."""
    lo, hi = rects.min(axis=1), rects.max(axis=1)
    walls = []
    for i, corners in enumerate(rects):
        for k in range(4):
            side = np.concatenate([corners[k], corners[(k + 1) % 4]])
            meets = ((lo <= np.maximum(side[:2], side[2:])).all(axis=1)
                     & (hi >= np.minimum(side[:2], side[2:])).all(axis=1))
            meets[i] = False
            walls.extend(clip_segment_outside(side, rects[meets]))
    return np.array(walls).reshape(-1, 4)


def _runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Runs of True along axis 1 of ``mask[L, W]``: (line, start, end) arrays (end exclusive)."""
    L, W = mask.shape
    padded = np.zeros((L, W + 2), dtype=np.int8)
    padded[:, 1:-1] = mask
    step = np.diff(padded, axis=1)
    line_s, start = np.nonzero(step == 1)
    line_e, end = np.nonzero(step == -1)
    return line_s, start, end   # nonzero scans row-major, so starts and ends pair up


def grid_walls(grid: Grid) -> np.ndarray:
    """Cell edges between blocked and free cells (outside the grid counts as blocked)."""
    blocked = np.pad(grid.occupied, 1, constant_values=True)
    res, (ox, oy) = grid.resolution, grid.origin
    # horizontal edges: between padded rows r and r+1, at y = oy + r * res
    h = blocked[:-1, 1:-1] != blocked[1:, 1:-1]
    r, c0, c1 = _runs(h)
    horiz = np.stack([ox + c0 * res, oy + r * res, ox + c1 * res, oy + r * res], axis=1)
    # vertical edges: between padded columns c and c+1, at x = ox + c * res
    v = (blocked[1:-1, :-1] != blocked[1:-1, 1:]).T
    c, r0, r1 = _runs(v)
    vert = np.stack([ox + c * res, oy + r0 * res, ox + c * res, oy + r1 * res], axis=1)
    return np.concatenate([horiz, vert]).astype(float)


#: The most cells a grid grown to hold its corridors may have (a 16-bit 8,000 x 8,000 image,
#: the largest map read, has 6.4e7): a corridor miles off the map is a mistake, not a plan.
MAX_GROWN = 64_000_000


def walled(grid: Grid, cells: int = 1) -> Grid:
    """``grid`` with a ring ``cells`` wide of occupied cells round it (its own cells where
    they were), or ``grid`` itself where its border is occupied already: what a map does
    not cover is solid (:func:`grid_walls`, the truth, counts it so), and a robot's map read
    as free beyond its edge let the route run along the edge of a map whose border is free
    (MIT's Building 31, outside the building) and the brake drive into it."""
    occ = grid.occupied
    if occ[0].all() and occ[-1].all() and occ[:, 0].all() and occ[:, -1].all():
        return grid
    res, (ox, oy) = grid.resolution, grid.origin
    return Grid(np.pad(occ, cells, constant_values=True), res,
                (ox - cells * res, oy - cells * res), grid.source, grid.notes)


def carve(grid: Grid, rects: np.ndarray) -> Grid:
    """The grid with every cell whose centre lies in a corridor made free, grown first by
    whole cells of wall to hold every corridor (:func:`covering`)."""
    grid = covering(grid, rects)
    inside = cells_inside(grid, rects)
    return Grid(grid.occupied & ~inside, grid.resolution, grid.origin, grid.source)


#: the most cell centres tested against one polygon at once (a block of its rows)
CELL_BLOCK = 1 << 16


def cells_inside(grid: Grid, polygons: np.ndarray) -> np.ndarray:
    """Whether each cell's centre of ``grid`` lies in any convex CCW polygon ``[Q, K, 2]``:
    ``[rows, cols]``. Each polygon is tested on the cells of its bounding box only, a block of
    rows at a time: every cell against every polygon at once held cells x polygons x 64
    bytes, 6 GB for a 76 m building of 20 corridors (a traceback where memory was short)."""
    rows, cols = grid.occupied.shape
    inside = np.zeros((rows, cols), dtype=bool)
    (ox, oy), res = grid.origin, grid.resolution
    for poly in polygons:
        (x0, y0), (x1, y1) = poly.min(axis=0), poly.max(axis=0)
        c0, c1 = _cell_span(x0, x1, ox, res, cols)
        r0, r1 = _cell_span(y0, y1, oy, res, rows)
        if c0 >= c1 or r0 >= r1:
            continue
        step = min(BAND_ROWS, max(1, CELL_BLOCK // (c1 - c0)))
        for r in range(r0, r1, step):
            ys = oy + (np.arange(r, min(r + step, r1)) + 0.5) * res
            b0, b1 = _band_cells(poly, float(ys[0]), float(ys[-1]), ox, res, (c0, c1))
            if b0 >= b1:
                continue
            xs = ox + (np.arange(b0, b1) + 0.5) * res
            px, py = np.broadcast_arrays(xs[None, :], ys[:, None])
            hit = points_in_polygon(np.stack([px.ravel(), py.ravel()], axis=1), poly[None])
            inside[r:r + len(ys), b0:b1] |= hit[:, 0].reshape(len(ys), b1 - b0)
    return inside


#: rows of cells tested against a polygon at once: a band narrow enough that a corridor
#: running across the map is tested near itself only (its bounding box, for a diagonal
#: corridor, is the whole map: 300 such corridors took 14 s to carve)
BAND_ROWS = 16


def _band_cells(poly: np.ndarray, y0: float, y1: float, ox: float, res: float,
                within: tuple[int, int]) -> tuple[int, int]:
    """The columns ``[first, last)`` of ``within`` whose centres may lie in the convex
    polygon ``poly [K, 2]`` between the heights ``y0`` and ``y1`` (its corners there and
    where its sides cross them; a cell to spare at each end)."""
    xs = [x for x, y in poly.tolist() if y0 <= y <= y1]
    for (xa, ya), (xb, yb) in zip(poly.tolist(), np.roll(poly, -1, axis=0).tolist()):
        for y in (y0, y1):
            if ya != yb and min(ya, yb) <= y <= max(ya, yb):
                xs.append(xa + (y - ya) * (xb - xa) / (yb - ya))
    if not xs:
        return 0, 0
    first, last = _cell_span(min(xs), max(xs), ox, res, within[1])
    return max(first, within[0]), last


def _cell_span(lo: float, hi: float, origin: float, res: float, n: int) -> tuple[int, int]:
    """The cells ``[first, last)`` of a row or column whose centres may lie in ``[lo, hi]``,
    a cell to spare at each end (a centre on the polygon's edge counts as inside)."""
    first = max(0, math.floor((lo - origin) / res) - 1)
    return first, min(n, math.ceil((hi - origin) / res) + 1)


def covering(grid: Grid, rects: np.ndarray) -> Grid:
    """``grid`` grown by whole cells of wall (its cells where they were) until it holds every
    corridor rectangle ``rects [Q, 4, 2]``: a corridor carved into a map used to end at the
    map's edge without a word, all beyond it solid."""
    if not len(rects):
        return grid
    res, (ox, oy) = grid.resolution, grid.origin
    rows, cols = grid.occupied.shape
    lo, hi = rects.reshape(-1, 2).min(axis=0), rects.reshape(-1, 2).max(axis=0)
    left, bottom = (max(0, math.ceil((o - m) / res)) for o, m in zip((ox, oy), lo))
    right = max(0, math.ceil((hi[0] - (ox + cols * res)) / res))
    top = max(0, math.ceil((hi[1] - (oy + rows * res)) / res))
    if not (left or bottom or right or top):
        return grid
    size = (rows + bottom + top) * (cols + left + right)
    if size > MAX_GROWN:
        name = f" `{Path(grid.source).name}`" if grid.source else ""
        raise WorldError(f"the corridors reach so far past the map{name} that it would grow to "
                         f"{size:.3g} cells, more than {MAX_GROWN:.3g}",
                         hint="check the corridors' points (inches) and the map's `origin` and "
                              "`resolution` (metres)")
    occupied = np.pad(grid.occupied, ((bottom, top), (left, right)), constant_values=True)
    return Grid(occupied, res, (ox - left * res, oy - bottom * res), grid.source)


@dataclass(frozen=True)
class StaticMap:
    """Walls ``[N, 4]`` with their bounding boxes, and what is free."""

    walls: np.ndarray
    rects: np.ndarray              # corridor rectangles [Q, 4, 2] (empty with a grid)
    grid: Grid | None
    bounds: tuple[float, float, float, float]    # xmin, ymin, xmax, ymax

    def __hash__(self) -> int:
        return id(self)

    @property
    def lo(self) -> np.ndarray:
        return np.minimum(self.walls[:, 0:2], self.walls[:, 2:4])

    def free(self, points: np.ndarray) -> np.ndarray:
        """Whether each point ``[P, 2]`` lies in free space."""
        points = np.atleast_2d(np.asarray(points, float))
        if self.grid is not None:
            g = self.grid
            colf = np.floor((points[:, 0] - g.origin[0]) / g.resolution)
            rowf = np.floor((points[:, 1] - g.origin[1]) / g.resolution)
            rows, cols = g.occupied.shape
            # compared as floats: a point 1e38 away is outside, not an int64 cast gone wrong
            inside = (rowf >= 0) & (rowf < rows) & (colf >= 0) & (colf < cols)
            row = np.where(inside, rowf, 0).astype(np.int64)
            col = np.where(inside, colf, 0).astype(np.int64)
            out = np.zeros(len(points), dtype=bool)
            out[inside] = ~g.occupied[row[inside], col[inside]]
            return out
        return np.asarray(points_in_polygon(points, self.rects).any(axis=1))

    def near(self, x: float, y: float, reach: float) -> np.ndarray:
        """The walls whose bounding box comes within ``reach`` of (x, y)."""
        w = self.walls
        keep = ((np.minimum(w[:, 0], w[:, 2]) <= x + reach) &
                (np.maximum(w[:, 0], w[:, 2]) >= x - reach) &
                (np.minimum(w[:, 1], w[:, 3]) <= y + reach) &
                (np.maximum(w[:, 1], w[:, 3]) >= y - reach))
        return w[keep]


def build_static(world: World) -> StaticMap:
    rects = corridor_rects(world.corridors) if world.corridors else np.zeros((0, 4, 2))
    grid = world.grid
    if grid is not None:
        if len(rects):
            grid = carve(grid, rects)
        walls = grid_walls(grid)
        rows, cols = grid.occupied.shape
        bounds = (grid.origin[0], grid.origin[1], grid.origin[0] + cols * grid.resolution,
                  grid.origin[1] + rows * grid.resolution)
        return StaticMap(walls, np.zeros((0, 4, 2)), grid, bounds)
    walls = corridor_walls(rects)
    pts = rects.reshape(-1, 2)
    (x0, y0), (x1, y1) = pts.min(axis=0), pts.max(axis=0)
    return StaticMap(walls, rects, None, (float(x0), float(y0), float(x1), float(y1)))
