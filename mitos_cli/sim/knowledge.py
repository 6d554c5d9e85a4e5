"""What the robot knows of its world, as opposed to what is there.

The world file says what the robot is *given* (``map.given``): the map itself (the default),
another map (MRPB's partially unknown scenarios: the same building without its furniture), or
nothing (``given: none``), plus the obstacles marked ``known: true``. The simulator keeps the
truth (:class:`~.staticmap.StaticMap`: sensors, collisions and clearance use it) and, per
robot, a :class:`RobotMap`: the cells it plans on, which its own readings fill in as it drives.

What the robot's map predicts decides what its readings mean (:mod:`.perception`): a beam
clearly shorter than the map predicts has hit something the map does not show. With a map, the
prediction is the given map's walls and the known obstacles' outlines; with no map, it is what
the robot has mapped itself so far (a grid ray-marched per beam).

Replanning (:func:`replan`), at most once every ``REPLAN_EVERY`` seconds, as the world's
``route: {replan}`` says:

- ``clearance`` (the default): whenever the robot has mapped something new within the least
  clearance its route accepts (half its width plus its margin) of the route ahead, up to
  ``sight``, it plans again from where it stands on everything it knows, as a global planner
  on a costmap does. The route keeps its word about what the robot has seen: it never leads
  the body through something the robot knows is there;
- ``blocked``: only when no way past is left within ``TUBE`` inches of the route ahead at
  that least clearance (a shut door, a corridor full of boxes); a box in the lane leaves a way
  past, and the rules alone drive round it;
- ``never``: the route stays as it was planned at the start (the paper's robot, which had no
  map to learn into).
"""

from __future__ import annotations

import bisect
import functools
import itertools
import math
import operator
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from . import movers
from . import obstacles as obs_mod
from .geometry import CACHED, ray_circles, ray_segments
from .route import NODE, Clearance, NarrowPassage, Prepared, Route, grid_route, set_cells
from .staticmap import StaticMap, carve, cells_inside, corridor_rects, grid_walls, walled
from .world import Goal, Grid, Pose, World

RASTER = 2.0            # in: cells of the robot's map when the world gives no grid
REPLAN_EVERY = 0.5      # s: the least time between two replanning checks
TUBE = 48.0             # in: how far from its route the robot looks for a way past


@dataclass(frozen=True)
class Given:
    """What a world gives its robots: walls and shapes that predict the ranges, and the cells
    the route is planned on (``None``: the corridors' centre lines, the truth itself)."""

    knows: str                     # map | given | none
    walls: np.ndarray              # [N, 4] walls of the given map (the truth's with `map`)
    sides: np.ndarray              # [S, 4] sides of known rectangles
    centres: np.ndarray            # [C, 2] known circles
    radii: np.ndarray              # [C]
    grid: Grid | None              # the cells to plan on, known obstacles drawn in

    def __hash__(self) -> int:
        return id(self)

    @property
    def plain(self) -> bool:
        """The robot is given exactly the true map (today's worlds): nothing to add."""
        return self.knows == "map" and not len(self.sides) and not len(self.centres)


def _raster(static: StaticMap, world: World, res: float, free: bool) -> Grid:
    """A grid over the truth's bounds: free everywhere, or the corridors carved out."""
    x0, y0, x1, y1 = static.bounds
    cols, rows = int(math.ceil((x1 - x0) / res)) + 2, int(math.ceil((y1 - y0) / res)) + 2
    origin = (x0 - res, y0 - res)
    grid = Grid(np.full((rows, cols), not free), res, origin, "")
    if not free and world.corridors:
        grid = carve(grid, corridor_rects(world.corridors))
    return grid


def _stamp(grid: Grid, world: World) -> Grid:
    """The grid with every known obstacle's cells occupied."""
    known = world.known_obstacles
    if not known:
        return grid
    where = obs_mod.positions(known, 0.0)
    centres, radii, _, _, _, corners = obs_mod.shapes_at(known, where)
    rows, cols = grid.occupied.shape
    ys, xs = np.mgrid[0:rows, 0:cols]
    pts = np.stack([grid.origin[0] + (xs.ravel() + 0.5) * grid.resolution,
                    grid.origin[1] + (ys.ravel() + 0.5) * grid.resolution], axis=1)
    half = grid.resolution / 2
    hit = np.zeros(len(pts), dtype=bool)
    for c, r in zip(centres, radii):
        hit |= np.hypot(*(pts - c).T) <= r + half
    if len(corners):
        grown = corners + np.sign(corners - corners.mean(axis=1, keepdims=True)) * half
        hit |= cells_inside(grid, grown).ravel()
    return Grid(grid.occupied | hit.reshape(rows, cols), grid.resolution, grid.origin,
                grid.source)


def _walled(grid: Grid) -> Grid:
    """:func:`.staticmap.walled` by a whole route node's block of cells, so the nodes of the
    map's own cells fall where they fell on the map."""
    return walled(grid, max(1, int(round(NODE / grid.resolution))))


def given(world: World, static: StaticMap) -> Given:
    """What ``world`` gives its robots (the truth is ``static``)."""
    known = world.known_obstacles
    where = obs_mod.positions(known, 0.0)
    centres, radii, _, sides, _, _ = obs_mod.shapes_at(known, where)
    if world.knows == "map":
        walls = static.walls
        grid = None if static.grid is None else _walled(static.grid)
        if known and grid is None:
            grid = _raster(static, world, RASTER, free=False)
    elif world.knows == "given" and world.given is not None:
        grid = world.given
        if world.corridors:
            grid = carve(grid, corridor_rects(world.corridors))
        walls = grid_walls(grid)
        grid = _walled(grid)
    else:
        res = static.grid.resolution if static.grid is not None else RASTER
        grid = _raster(static, world, res, free=True)
        walls = np.zeros((0, 4))
    if grid is not None:
        grid = _stamp(grid, world)
    return Given(world.knows, walls, sides, centres, radii, grid)


def plan_grid(g: Given, static: StaticMap, world: World) -> Grid:
    """The cells a robot plans on once it must replan (the corridors rasterised if need be)."""
    return g.grid if g.grid is not None else _raster(static, world, RASTER, free=False)


@functools.lru_cache(maxsize=8)
def faces_of(given: Given, grid: Grid, rastered: bool) -> np.ndarray:
    """:func:`wall_faces` of the walls ``given`` on ``grid``, where the grid is a raster of
    walls the robot is given exactly (``rastered``: a map of corridors, ``knows: map``); none
    where the grid's cells are the map itself. Shared by the runs of a world."""
    if not rastered or given.knows != "map" or not len(given.walls):
        return _NO_FACES
    return wall_faces(given.walls, grid)


_NO_FACES = np.zeros((0, 2))
_NO_FACES.flags.writeable = False


def _with_faces(cells: np.ndarray, faces: np.ndarray, y: float, reach: float) -> np.ndarray:
    """``cells``, then those of ``faces`` (the run of a square's x) within ``reach`` of
    ``y``."""
    if not len(faces):
        return cells
    keep = np.abs(faces[:, 1] - y) <= reach
    return np.concatenate([cells, faces[keep]]) if np.count_nonzero(keep) else cells


def wall_faces(walls: np.ndarray, grid: Grid) -> np.ndarray:
    """``[F, 2]``: the centres of squares of the size of ``grid``'s cells laid along each of
    ``walls [N, 4]`` (x0, y0, x1, y1) on its solid side, flush with it (a square whose sides
    run along the wall's touches it with a whole side, a slanted one with a corner), where the
    wall runs through a free cell of the grid; a cell apart (half a cell along a slanted
    wall), in the order of their x: what the brake counts besides the grid's cells
    (:meth:`RobotMap.brake_cells`).

    A grid drawn from walls frees every cell whose centre lies on the free side, so a wall
    may run up to half a cell inside a free cell: the brake, which keeps its margin along the
    arc, not across it, then let a robot backing out at 17-19 deg toward BARN's corridor wall
    (which lies 0.84 in inside the map's free row) touch it. Where the wall runs through an
    occupied cell, or along a cell's edge, that cell covers it and no square is laid. The
    solid side of a wall is the one whose cell a cell and a half from its middle is occupied
    while the other's is free (outside the grid counts as occupied); a wall with both or
    neither (a pole stamped against it) gets no squares."""
    if not len(walls):
        return _NO_FACES
    r = grid.resolution / 2
    a, b = walls[:, :2], walls[:, 2:]
    length = np.hypot(*(b - a).T)
    keep = length > 0
    a, b, length = a[keep], b[keep], length[keep]
    along = (b - a) / length[:, None]
    normal = np.stack([-along[:, 1], along[:, 0]], axis=1)
    middle = (a + b) / 2

    def blocked(points: np.ndarray) -> np.ndarray:
        cells = np.floor((points - np.array(grid.origin)) / grid.resolution).astype(np.int64)
        rows, cols = grid.occupied.shape
        inside = (cells[:, 0] >= 0) & (cells[:, 0] < cols) & (cells[:, 1] >= 0) \
            & (cells[:, 1] < rows)
        out = np.ones(len(points), dtype=bool)
        out[inside] = grid.occupied[cells[inside, 1], cells[inside, 0]]
        return out

    left = blocked(middle + normal * (3 * r))
    right = blocked(middle - normal * (3 * r))
    side = np.where(left & ~right, 1.0, np.where(right & ~left, -1.0, 0.0))
    keep = side != 0
    a, along, normal, length = a[keep], along[keep], normal[keep] * side[keep, None], length[keep]
    if not len(a):
        return _NO_FACES
    # a square's centre this far beyond the wall touches it and no more
    off = r * (np.abs(normal[:, 0]) + np.abs(normal[:, 1]))
    # along each wall from half a cell in from one end to half a cell in from the other, a
    # cell apart along a wall that runs with the grid (they tile it), half a cell along a
    # slanted one (whose squares touch it at a corner each)
    step = np.where(np.minimum(np.abs(normal[:, 0]), np.abs(normal[:, 1])) < 1e-9, 2 * r, r)
    count = np.maximum(np.ceil((length - 2 * r) / step - 1e-9).astype(np.int64), 0) + 1
    wall = np.repeat(np.arange(len(a)), count)
    k = np.arange(len(wall)) - np.repeat(np.cumsum(count) - count, count)
    span = np.maximum(length - 2 * r, 0.0)[wall]
    s = np.where(count[wall] > 1, r + span * k / np.maximum(count[wall] - 1, 1),
                 length[wall] / 2)
    on = a[wall] + along[wall] * s[:, None]                # on the wall
    # needed only where the wall runs through a free cell (a hair beyond it, there or half a
    # cell along): where it runs through an occupied one, or along a cell's edge, that cell
    # covers it already
    beyond = on + normal[wall] * 1e-6
    free = ~blocked(beyond)
    for sign in (1.0, -1.0):
        free |= ~blocked(beyond + along[wall] * (sign * r))
    out = (on + normal[wall] * off[wall, None])[free]
    out = out[np.lexsort((out[:, 1], out[:, 0]))]         # by x: a square's are one run
    out.flags.writeable = False
    return out


def _dilated(cells: np.ndarray, reach: int) -> np.ndarray:
    """``[rows + 2 reach, cols + 2 reach]``: whether a cell (row ``i - reach``, column
    ``j - reach``, inside the grid or up to ``reach`` outside it) lies within ``reach`` cells
    (the square) of an occupied one of ``cells``: ORs of shifted copies, along the rows and
    then along the columns."""
    rows, cols = cells.shape
    padded = np.zeros((rows + 4 * reach, cols + 4 * reach), dtype=bool)
    padded[2 * reach:2 * reach + rows, 2 * reach:2 * reach + cols] = cells
    across = np.zeros((rows + 4 * reach, cols + 2 * reach), dtype=bool)
    for b in range(2 * reach + 1):
        across |= padded[:, b:b + cols + 2 * reach]
    out = np.zeros((rows + 2 * reach, cols + 2 * reach), dtype=bool)
    for a in range(2 * reach + 1):
        out |= across[a:a + rows + 2 * reach]
    return out


@functools.lru_cache(maxsize=8)
def _centre_lines(grid: Grid) -> tuple[np.ndarray, np.ndarray]:
    """The x of every column's cell centres and the y of every row's (``ox + (j + 0.5) *
    res``, the arithmetic :meth:`RobotMap.near` did cell by cell, so the same bits)."""
    rows, cols = grid.occupied.shape
    res, (ox, oy) = grid.resolution, grid.origin
    xs = ox + (np.arange(cols) + 0.5) * res
    ys = oy + (np.arange(rows) + 0.5) * res
    xs.flags.writeable = ys.flags.writeable = False
    return xs, ys


def _inside(cells: np.ndarray, shape: tuple[int, int]) -> np.ndarray | None:
    """:func:`_within`, or ``None`` when every cell lies inside."""
    ok = _within(cells, shape)
    return None if np.count_nonzero(ok) == ok.size else ok


def _within(cells: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Which cells (columns and rows ``[..., 2]``, int64, C-contiguous) lie inside a grid of
    ``shape`` (rows, columns). Seen unsigned, a negative index is a huge one, so one
    comparison a coordinate tests both ends (a coordinate at a time: cheaper than reducing
    pairs)."""
    seen = cells.view(np.uint64)
    return (seen[..., 0] < shape[1]) & (seen[..., 1] < shape[0])


@functools.lru_cache(maxsize=4)
def _given_dilated(grid: Grid, reach: int) -> np.ndarray:
    """:func:`_dilated` of a given grid's cells, shared by every robot and run that plans on
    it (a grid is never changed)."""
    return _dilated(grid.occupied, reach)


@dataclass
class RobotMap:
    """One robot's map as it drives: the cells it plans on, with what it has sensed marked."""

    grid: Grid
    occupied: np.ndarray           # bool [rows, cols], the grid's cells plus the marks
    fresh: list = field(default_factory=list)      # marks since the last check, [k, 2] each
    checked_at: float = -math.inf  # s
    replans: int = 0
    refuge: Goal | None = None     # where it waits for a mover to pass, while it waits
    planned: np.ndarray | None = None   # the cells the route was last planned on (None: given)
    marks: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    # the cells it marked (none given), as row * cols + col, ascending (row-major order)
    _around: tuple | None = field(default=None, repr=False)   # (planned, reach, its dilation)
    prepared: Prepared = field(default_factory=Prepared, repr=False)   # for its next replan

    def at_refuge(self, p: np.ndarray) -> bool:
        """Whether a robot at ``p [2]`` stands at its refuge: it holds one and is within its
        tolerance of it (as a goal is reached), not on its way there."""
        r = self.refuge
        return r is not None and math.hypot(float(p[0]) - r.x, float(p[1]) - r.y) <= r.tolerance
    _changes: int = field(default=0, repr=False)     # marks made and cleared so far
    _last_near: tuple | None = field(default=None, repr=False)     # see near()
    _decoded: tuple | None = field(default=None, repr=False)   # see _marks_decoded()
    _origin: np.ndarray = field(init=False, repr=False)        # the grid's origin, [2]
    _size: np.ndarray = field(init=False, repr=False)          # its columns and rows, [2]
    faces: np.ndarray = field(default_factory=lambda: _NO_FACES, repr=False)
    # [F, 2] squares flush with the walls it is given, for the brake (wall_faces), by x
    _faces_x: np.ndarray = field(init=False, repr=False)      # their x, [F] (contiguous)

    def __post_init__(self) -> None:
        self._origin = np.array(self.grid.origin, float)
        self._size = np.array(self.occupied.shape[::-1], np.int64)
        self._faces_x = np.ascontiguousarray(self.faces[:, 0])

    @classmethod
    def of(cls, grid: Grid, faces: np.ndarray | None = None) -> RobotMap:
        return cls(grid, grid.occupied.copy(), faces=_NO_FACES if faces is None else faces)

    def brake_cells(self, p: np.ndarray, reach: float) -> np.ndarray:
        """What the brake counts round ``p`` (the square of half side ``reach``): the
        occupied cells (:meth:`near`), then the :attr:`faces` whose centres lie in the
        square."""
        cells = self.near(p, reach)
        faces = self.faces
        if not len(faces):
            return cells
        x, y = float(p[0]), float(p[1])
        lo = int(self._faces_x.searchsorted(x - reach, side="left"))
        hi = int(self._faces_x.searchsorted(x + reach, side="right"))
        return _with_faces(cells, faces[lo:hi], y, reach)

    def accounted(self, points: np.ndarray, reach: int = 2) -> np.ndarray:
        """Which points ``[P, 2]`` lie within ``reach`` cells of a cell the robot's route was
        planned round (its map when it last planned: the given cells, and what it had marked
        by then): an echo from the same object a little further along its side, as the robot
        sees it from another angle, is the object the route went round, not a new one."""
        return self.accounted_cells(self.cell_indices(points), reach)

    def accounted_cells(self, cells: np.ndarray, reach: int = 2) -> np.ndarray:
        """:meth:`accounted` of the points in ``cells [P, 2]`` (:meth:`cell_indices`)."""
        near = self._dilation(reach)
        cells = cells + reach
        inside = _inside(cells, near.shape)
        if inside is None:
            return near[cells[:, 1], cells[:, 0]]
        out = np.zeros(len(cells), dtype=bool)
        out[inside] = near[cells[inside, 1], cells[inside, 0]]
        return out

    def _dilation(self, reach: int) -> np.ndarray:
        """:func:`_dilated` of the cells its route was planned round (:meth:`accounted`)."""
        if self.planned is None:
            return _given_dilated(self.grid, reach)
        # the cells it planned on do not change until it plans again
        if self._around is None or self._around[0] is not self.planned \
                or self._around[1] != reach:
            self._around = (self.planned, reach, _dilated(self.planned, reach))
        return self._around[2]

    def cells(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The row, column and whether inside the grid of the cell of each of ``points
        [P, 2]``."""
        cells = self.cell_indices(points)
        inside = _inside(cells, self.occupied.shape)
        return cells[:, 1], cells[:, 0], np.ones(len(cells), bool) if inside is None else inside

    def cell_indices(self, points: np.ndarray) -> np.ndarray:
        """``[P, 2]``: the column and row of the cell of each of ``points [P, 2]``, inside
        the grid or not (both coordinates in one pass: the arithmetic per element is the
        same)."""
        g = self.grid
        return np.floor((points - self._origin) / g.resolution).astype(np.int64)

    def _square(self, p: np.ndarray, reach: float) -> tuple[int, int, int, int]:
        """Rows ``r0:r1`` and columns ``c0:c1`` of the cells in the square of half side
        ``reach`` around ``p``, clipped to the grid."""
        g = self.grid
        res, (ox, oy) = g.resolution, g.origin
        rows, cols = self.occupied.shape
        x, y = float(p[0]), float(p[1])   # NumPy's // on floats is Python's: the same bits
        c0 = min(max(int((x - reach - ox) // res), 0), cols)
        r0 = min(max(int((y - reach - oy) // res), 0), rows)
        c1 = min(max(int((x + reach - ox) // res) + 1, 0), cols)
        r1 = min(max(int((y + reach - oy) // res) + 1, 0), rows)
        return r0, r1, c0, c1

    def near(self, p: np.ndarray, reach: float, given: bool = False) -> np.ndarray:
        """The centres ``[P, 2]`` of the occupied cells in the square of half side ``reach``
        around ``p`` (``given``: of the cells it was given, without its marks). A square
        inside the last one asked for, with no mark made or cleared since (the perception's
        and then the brake's, each tick), is read from that one's cells: the same cells in
        the same order."""
        r0, r1, c0, c1 = self._square(p, reach)
        last = self._last_near
        if last is not None and last[0] == (self._changes, given) and last[1] <= r0 \
                and r1 <= last[2] and last[3] <= c0 and c1 <= last[4]:
            r, c, centres = last[5:]
            if (r0, r1, c0, c1) == last[1:5]:           # the same square: all of them
                return centres
            return centres[(r >= r0) & (r < r1) & (c >= c0) & (c < c1)]
        cells = self.grid.occupied if given else self.occupied
        r, c = set_cells(cells[r0:r1, c0:c1])
        r += r0
        c += c0
        xs, ys = _centre_lines(self.grid)
        centres = np.empty((len(r), 2))
        centres[:, 0], centres[:, 1] = xs[c], ys[r]
        centres.flags.writeable = False                  # kept for the next question
        self._last_near = ((self._changes, given), r0, r1, c0, c1, r, c, centres)
        return centres

    def clear(self, origin: np.ndarray, dirs: np.ndarray, measured: np.ndarray,
              max_range: float) -> None:
        """Free the cells the robot marked that a beam now passes through short of its echo
        (something that moved on, or a mark a noisy reading put in the way): a beam is a ray
        (:mod:`.sensors`), so a cell is seen through when the ray crosses it, within half a
        cell of its centre, a cell or more before the reading. Cells the robot was given stay
        as given. (:func:`clear_all` of one map.)"""
        clear_all([self], origin[None], dirs[None], measured[None], max_range)

    def _in_sight(self, origin: np.ndarray, max_range: float
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """The marks within ``max_range`` (a square) of ``origin``: their place in
        :attr:`marks`, rows, columns and centres relative to ``origin``; ``None`` with none."""
        if not len(self.marks):
            return None
        r0, r1, c0, c1 = self._square(origin, max_range)
        # the marks in that window, in the row-major order np.nonzero would give them: those
        # in its rows are one run of the ascending marks, then its columns are picked
        r, c, centres, flat = self._marks_decoded()
        cols = self.occupied.shape[1]
        lo, hi = bisect.bisect_left(flat, r0 * cols), bisect.bisect_left(flat, r1 * cols)
        if lo == hi:
            return None
        run = c[lo:hi]
        where = ((run >= c0) & (run < c1)).nonzero()[0]
        if not len(where):
            return None
        where += lo
        return where, r[where], c[where], centres[where] - origin

    def _marks_decoded(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[int]]:
        """The rows, columns and centres ``[M, 2]`` of :attr:`marks` and the marks as a
        list, worked out again only once the marks changed (a new array each time)."""
        if self._decoded is None or self._decoded[0] is not self.marks:
            r, c = _divmod(self.marks, self.occupied.shape[1])
            xs, ys = _centre_lines(self.grid)
            centres = np.empty((len(r), 2))
            centres[:, 0], centres[:, 1] = xs[c], ys[r]
            self._decoded = (self.marks, r, c, centres, self.marks.tolist())
        return self._decoded[1:]

    def _free(self, where: np.ndarray, r: np.ndarray, c: np.ndarray) -> None:
        """Unmark the marks at places ``where`` of :attr:`marks` (cells ``r``, ``c``)."""
        self._changes += 1
        self.occupied.put(self.marks[where], False)      # (a mark is its cell's flat index)
        keep = np.ones(len(self.marks), dtype=bool)      # (np.delete's Python costs more)
        keep[where] = False
        self.marks = self.marks[keep]

    def mark(self, hits: np.ndarray, dirs: np.ndarray) -> None:
        """Mark the cells just beyond each hit point (the echo came from there)."""
        if len(hits):
            self.mark_cells(self.cell_indices(hits + dirs * (self.grid.resolution / 2)))

    def mark_cells(self, cells: np.ndarray) -> bool:
        """Mark ``cells [P, 2]`` (:meth:`cell_indices`; those outside the grid are left):
        whether any was not marked yet."""
        inside = _inside(cells, self.occupied.shape)
        return self._mark(cells if inside is None else cells[inside])

    def _mark(self, cells: np.ndarray) -> bool:
        """:meth:`mark_cells` of ``cells [P, 2]`` inside the grid."""
        row, col = cells[:, 1], cells[:, 0]
        known = self.occupied[row, col]
        if np.count_nonzero(known) < len(known):      # (a count is cheaper than .all())
            new = ~known
            row, col = row[new], col[new]
            self._changes += 1
            self.occupied[row, col] = True
            # (np.union1d's Python costs more than the work: the new cells were unmarked)
            marks = np.concatenate([self.marks,
                                    sorted(set((row * self.occupied.shape[1] + col).tolist()))])
            marks.sort()
            self.marks = marks
            xs, ys = _centre_lines(self.grid)
            centres = np.empty((len(row), 2))
            centres[:, 0], centres[:, 1] = xs[col], ys[row]
            self.fresh.append(centres)
            return True
        return False

    def any_near(self, points: np.ndarray, reach: float) -> np.ndarray:
        """``[P]``: whether any occupied cell meets the square of half side ``reach`` round
        each of ``points [P, 2]`` (a cell more on every side: never ``False`` where one does).
        Counted on a running sum over the squares' common window, four reads a square; a
        window with nothing occupied (a route down the middle of a corridor) is all ``False``."""
        res, size = self.grid.resolution, self._size
        lo = np.minimum(np.maximum(np.floor((points - reach - self._origin) / res)
                                   .astype(np.int64) - 1, 0), size)       # [P, 2]: col, row
        hi = np.minimum(np.maximum(np.floor((points + reach - self._origin) / res)
                                   .astype(np.int64) + 2, 0), size)
        (e, a), (f, b) = lo.min(axis=0).tolist(), hi.max(axis=0).tolist()
        window = self.occupied[a:b, e:f]
        if not window.any():
            return np.zeros(len(points), dtype=bool)
        sums = np.zeros((b - a + 1, f - e + 1), dtype=np.int64)
        np.cumsum(np.cumsum(window, axis=0), axis=1, out=sums[1:, 1:])
        c0, r0, c1, r1 = lo[:, 0] - e, lo[:, 1] - a, hi[:, 0] - e, hi[:, 1] - a
        return (sums[r1, c1] - sums[r0, c1] - sums[r1, c0] + sums[r0, c0]) > 0

    def ranges(self, origin: np.ndarray, dirs: np.ndarray, max_range: float) -> np.ndarray:
        """Ranges ``[B]`` this map predicts: each beam marched in half cells to the first
        occupied cell (``max_range`` when none)."""
        step = self.grid.resolution / 2
        s = np.arange(step, max_range + step, step)
        pts = origin + s[:, None, None] * dirs[None]              # [S, B, 2]
        row, col, inside = self.cells(pts.reshape(-1, 2))
        hit = np.zeros(len(row), dtype=bool)
        hit[inside] = self.occupied[row[inside], col[inside]]
        occ = hit.reshape(len(s), len(dirs))
        first = np.where(occ.any(axis=0), occ.argmax(axis=0), -1)
        return np.where(first >= 0, np.minimum(s[np.maximum(first, 0)] - step / 2, max_range),
                        max_range)


def near_all(maps: list[RobotMap], points: np.ndarray, reaches: np.ndarray,
             given: bool = False) -> list[np.ndarray]:
    """``[m.near(p, reach, given) for m, p, reach in zip(maps, points [R, 2], reaches [R])]``
    in one pass (runs in lockstep ask together): every square's cells in one block of
    windows of the largest square's size (:func:`_windows`, maps on one grid: the runs of a
    world), the rest left unoccupied, and one ``nonzero``: the same cells, in the same order,
    with the same centres. Maps that do not share their cells' shape, size and origin answer
    one by one."""
    grid = _alike(maps) if len(maps) > 1 else None
    if grid is None:
        return [m.near(p, reach, given) for m, p, reach in zip(maps, points, reaches)]
    r0, r1, c0, c1 = _squares(grid, points, reaches)
    high, wide = int((r1 - r0).max()), int((c1 - c0).max())
    if high <= 0 or wide <= 0:
        return [np.zeros((0, 2)) for _ in maps]
    if len(maps) >= ONE_GATHER and all(m.grid is grid for m in maps):
        block = _windows(maps, grid, (r0, r1, c0, c1), (high, wide), given)
    else:
        block = np.zeros((len(maps), high, wide), dtype=bool)
        for j, (m, a, b, e, f) in enumerate(zip(maps, r0.tolist(), r1.tolist(), c0.tolist(),
                                                 c1.tolist())):
            block[j, :b - a, :f - e] = (m.grid.occupied if given else m.occupied)[a:b, e:f]
    k, at = _divmod(np.flatnonzero(block), high * wide)
    r, c = _divmod(at, wide)
    r += r0[k]
    c += c0[k]
    xs, ys = _centre_lines(grid)
    centres = np.empty((len(r), 2))
    centres[:, 0], centres[:, 1] = xs[c], ys[r]
    centres.flags.writeable = False                  # (as near's)
    ends = np.cumsum(np.bincount(k, minlength=len(maps))).tolist()
    return [centres[a:b] for a, b in zip([0, *ends[:-1]], ends)]


def brake_cells_all(maps: list[RobotMap], points: np.ndarray,
                    reaches: np.ndarray) -> list[np.ndarray]:
    """``[m.brake_cells(p, reach) for ...]`` of ``maps`` round ``points [R, 2]`` with
    ``reaches [R]``: :func:`near_all`, then each map's faces in its square (the same cells
    in the same order, the same comparisons: the same bits as one by one)."""
    cells = near_all(maps, points, reaches)
    faces = maps[0].faces if maps else _NO_FACES
    if not len(faces) and all(not len(m.faces) for m in maps):
        return cells
    if not all(m.faces is faces for m in maps):
        return [c if not len(m.faces) else m.brake_cells(p, reach)
                for c, m, p, reach in zip(cells, maps, points, reaches)]
    x, half = points[:, 0], np.asarray(reaches, float)
    along = maps[0]._faces_x
    lo = along.searchsorted(x - half, side="left").tolist()
    hi = along.searchsorted(x + half, side="right").tolist()
    return [_with_faces(c, faces[a:b], y, reach)
            for c, a, b, y, reach in zip(cells, lo, hi, points[:, 1].tolist(), half.tolist())]


#: The fewest maps whose windows :func:`near_all` gathers in one copy (:func:`_windows`); fewer
#: are copied map by map. Measured on randomised slalom runs' calls, a call in one copy against
#: map by map: 45 against 35 us for 4 maps, 56 against 49 for 8, 75 against 76 for 16, 189
#: against 238 for 64.
ONE_GATHER = 16


def _windows(maps: list[RobotMap], grid: Grid, square: tuple[np.ndarray, ...],
             shape: tuple[int, int], given: bool) -> np.ndarray:
    """``[R, high, wide]``: each map's cells in its square (rows ``r0:r1``, columns
    ``c0:c1``), from the top left corner, the rest unoccupied; every map on ``grid``. A map's
    cells are the grid's plus its marks (none of them a grid's cell), so the grid's windows
    are gathered for all maps in one copy (of views of the grid's cells; a square whose
    window would reach past the grid's far edges is copied on its own) and the marks in the
    squares set in one more; a copy a map cost more than the two."""
    r0, r1, c0, c1 = square
    high, wide = shape
    rows, cols = grid.occupied.shape
    windows = _window_view(grid, high, wide)      # (squares are clipped to the grid: it fits)
    fits = (r0 + high <= rows) & (c0 + wide <= cols)
    if np.count_nonzero(fits) == len(fits):
        block = windows[r0, c0]
    else:
        block = np.zeros((len(maps), high, wide), dtype=bool)
        block[fits] = windows[r0[fits], c0[fits]]
        for j in np.flatnonzero(~fits).tolist():
            block[j, :r1[j] - r0[j], :c1[j] - c0[j]] = grid.occupied[r0[j]:r1[j], c0[j]:c1[j]]
    if np.count_nonzero(r1 - r0 - high):                 # rows below a short square's
        block &= (np.arange(high) < (r1 - r0)[:, None])[:, :, None]
    if np.count_nonzero(c1 - c0 - wide):                 # columns right of a narrow one's
        block &= (np.arange(wide) < (c1 - c0)[:, None])[:, None, :]
    counts = [len(m.marks) for m in maps]
    if given or not sum(counts):
        return block
    k = np.repeat(np.arange(len(maps)), counts)
    r, c = _divmod(np.concatenate([m.marks for m in maps]), cols)
    inside = ((r >= r0[k]) & (r < r1[k]) & (c >= c0[k]) & (c < c1[k])).nonzero()[0]
    k = k[inside]
    block[k, r[inside] - r0[k], c[inside] - c0[k]] = True
    return block


@functools.lru_cache(maxsize=8)
def _window_view(grid: Grid, high: int, wide: int) -> np.ndarray:
    """``[rows - high + 1, cols - wide + 1, high, wide]``: the window of that shape from every
    cell of the grid it fits from (views of the grid's cells, no copy), kept (read-only)."""
    return np.lib.stride_tricks.sliding_window_view(grid.occupied, (high, wide))


def _divmod(a: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``np.divmod(a, n)`` of integers ``a`` by a positive ``n``, as a floor division and
    what it leaves (``a - q * n``: the same numbers): NumPy's own integer divmod took
    twice as long as the two (a cell index split into row and column, a few thousand a
    tick)."""
    q = a // n
    return q, a - q * n


#: A map's grid (:func:`_alike` asks whether a batch's maps are all on one).
_GRID = operator.attrgetter("grid")


def _alike(maps: list[RobotMap]) -> Grid | None:
    """The first map's grid when every map's cells have its shape, size and origin (the runs
    of a world do), else ``None``."""
    grid = maps[0].grid
    if all(map(operator.is_, map(_GRID, maps), itertools.repeat(grid))):   # (most calls)
        return grid
    shape = grid.occupied.shape
    if any(m.grid is not grid and (m.grid.occupied.shape != shape
                                   or m.grid.resolution != grid.resolution
                                   or m.grid.origin != grid.origin) for m in maps):
        return None
    return grid


def _squares(grid: Grid, points: np.ndarray, reaches: np.ndarray) -> tuple[np.ndarray, ...]:
    """:meth:`RobotMap._square` of every point ``[R, 2]`` with its reach ``[R]`` at once:
    rows ``r0:r1`` and columns ``c0:c1``, ``[R]`` each (NumPy's ``//`` on floats is Python's:
    the same cells)."""
    res, (ox, oy) = grid.resolution, grid.origin
    rows, cols = grid.occupied.shape
    reach = reaches[:, None]
    corners = np.concatenate([points - reach, points + reach], axis=1)   # x0 y0 x1 y1 [R, 4]
    cells = ((corners - _four(ox, oy)) // res).astype(np.int64)
    cells[:, 2:] += 1
    np.minimum(np.maximum(cells, 0, out=cells), _four(cols, rows), out=cells)
    c0, r0, c1, r1 = cells.T
    return r0, r1, c0, c1


@functools.lru_cache(maxsize=16, typed=True)       # (2 and 2.0 are two arrays)
def _four(x: float, y: float) -> np.ndarray:
    """``[x, y, x, y]``, read-only (:func:`_squares` asks twice a tick)."""
    out = np.array([x, y, x, y])
    out.flags.writeable = False
    return out


def clear_all(maps: list[RobotMap], origins: np.ndarray, dirs: np.ndarray,
              measured: np.ndarray, max_range: float) -> None:
    """:meth:`RobotMap.clear` of every map at once (robots at ``origins [R, 2]``, their beams
    ``dirs [R, B, 2]`` and readings ``measured [R, B]``; runs in lockstep clear together):
    the marks in sight of every map one after the other, each with its robot's beams, and
    the products written out elementwise, so a map is cleared as it would be alone."""
    if len(maps) == 1:                  # one map: no beams to gather (the same arithmetic)
        m, got = maps[0], maps[0]._in_sight(origins[0], max_range)
        if got is None:
            return
        where, r, c, rel = got
        res = m.grid.resolution
        rx, ry = rel[:, 0, None], rel[:, 1, None]                  # [P, 1]
        dx, dy = dirs[0, :, 0], dirs[0, :, 1]                      # [B]
        along = rx * dx + ry * dy
        through = np.logical_or.reduce((along > 0) & (along < np.minimum(measured[0], max_range)
                                                      - res)
                                       & (np.abs(rx * dy - ry * dx) < res / 2), axis=1)
        if np.count_nonzero(through):
            m._free(where[through], r[through], c[through])
        return
    k, where, r, c, rel = _in_sight_all(maps, origins, max_range)
    if not len(k):
        return
    cell = np.array([m.grid.resolution for m in maps])
    beams = (np.ascontiguousarray(dirs[..., 0]), np.ascontiguousarray(dirs[..., 1]),
             np.minimum(measured, max_range) - cell[:, None], cell / 2)
    block = max(1, CACHED // dirs.shape[1])             # marks whose arrays stay in cache
    through = np.concatenate([_seen_through(rel[lo:lo + block], k[lo:lo + block], *beams)
                              for lo in range(0, len(k), block)])
    hit = np.flatnonzero(through)
    if not len(hit):
        return
    which, first = np.unique(k[hit], return_index=True)     # each map's marks seen through
    for j, a, e in zip(which.tolist(), first.tolist(), [*first[1:].tolist(), len(hit)]):
        mine = hit[a:e]
        maps[j]._free(where[mine], r[mine], c[mine])


def _in_sight_all(maps: list[RobotMap], origins: np.ndarray, max_range: float) -> tuple:
    """:meth:`RobotMap._in_sight` of every map (robots at ``origins [R, 2]``), one map's
    after the other: the maps ``k``, and the marks' places, rows, columns and centres
    relative to their robots; every map's marks decoded and tested against its square in one
    pass (maps alike: the runs of a world). The same marks in the same order, the same
    centres."""
    grid = _alike(maps) if len(maps) > 1 else None
    if grid is None:
        got = [(j, g) for j, (m, o) in enumerate(zip(maps, origins))
               if (g := m._in_sight(o, max_range)) is not None]
        if not got:
            return _none_in_sight()
        k = np.repeat([j for j, _ in got], [len(g[0]) for _, g in got])
        return (k, *(np.concatenate(part) for part in zip(*(g for _, g in got))))
    counts = [len(m.marks) for m in maps]
    ends = list(itertools.accumulate(counts))
    if not ends[-1]:
        return _none_in_sight()
    k = np.repeat(np.arange(len(maps)), counts)
    r, c = _divmod(np.concatenate([m.marks for m in maps]), grid.occupied.shape[1])
    r0, r1, c0, c1 = _squares(grid, origins, np.full(len(maps), max_range))
    sel = ((r >= r0[k]) & (r < r1[k]) & (c >= c0[k]) & (c < c1[k])).nonzero()[0]
    k, r, c = k[sel], r[sel], c[sel]
    where = sel - np.array([0, *ends[:-1]])[k]                 # places in each map's marks
    xs, ys = _centre_lines(grid)
    rel = np.empty((len(sel), 2))
    rel[:, 0], rel[:, 1] = xs[c], ys[r]
    rel -= origins.take(k, axis=0)                     # (take: a tenth of origins[k]'s time)
    return k, where, r, c, rel


def _none_in_sight() -> tuple:
    """:func:`_in_sight_all` with no mark in sight."""
    return (np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.int64),
            np.zeros(0, dtype=np.int64), np.zeros((0, 2)))


#: how far (times the largest coordinate and direction) :func:`_seen_through` lets single
#: precision put ``|rx * dy - ry * dx|`` below its double: the coordinates and directions
#: rounded, their products and their difference, at most ``4 * 2**-24 * (|rx| + |ry|) *
#: max(|dx|, |dy|)``, under ``5e-7`` times the largest of each; eight times that
SLACK = 4e-6


def _seen_through(rel: np.ndarray, k: np.ndarray, dx: np.ndarray, dy: np.ndarray,
                  reach: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Which marks (centres ``rel [K, 2]`` relative to robots ``k``) a beam of their robot
    (``dx``, ``dy [R, B]``) passes through, short of its echo (``reach [R, B]``: the reading
    less a cell) and within half a cell (``half [R]``) of the mark's centre: ``|rx * dy - ry
    * dx| < half`` and ``0 < rx * dx + ry * dy < reach``, elementwise. Every mark and beam is
    tried in single precision first, with a margin that covers its rounding (a few units
    in the 24th bit of the coordinates: :data:`SLACK`); the few that pass are tested again
    in double, as before, so the same marks and beams pass (all of it in double where the
    coordinates or directions are too large for single precision, or the coordinates so
    small that its rounding is no longer relative: never, on a map in inches)."""
    coords, ex, ey = (float(np.fmax.reduce(np.abs(a), axis=None, initial=0.0))  # (NaN left
                      for a in (rel, dx, dy))                                   # out)
    scale = coords * max(ex, ey, 1.0)
    if 1e-30 < scale < 1e30 and max(ex, ey) < 1e30:
        kind = np.float32
        bound = np.nextafter((half + SLACK * scale).astype(kind), kind(np.inf))  # rounded up
    else:
        kind, bound = np.float64, np.full(len(half), np.inf)
    rx, ry = (rel[:, j, None].astype(kind) for j in (0, 1))                # [K, 1]
    # (rows gathered with take: a third of the time of dy[k], the same rows)
    across = rx * dy.astype(kind).take(k, axis=0)
    across -= ry * dx.astype(kind).take(k, axis=0)
    np.abs(across, out=across)
    i, b = _divmod(np.flatnonzero(across < bound.take(k)[:, None]), dx.shape[1])
    j = k.take(i)
    beam = j * dx.shape[1] + b                  # the beams' places in [R, B], looked up flat
    x, y = rel[i, 0], rel[i, 1]
    ex, ey = dx.take(beam), dy.take(beam)
    near = np.abs(x * ey - y * ex) < half.take(j)
    i, x, y, ex, ey, beam = i[near], x[near], y[near], ex[near], ey[near], beam[near]
    along = x * ex + y * ey
    out = np.zeros(len(rel), dtype=bool)
    out[i[(along > 0) & (along < reach.take(beam))]] = True
    return out


def beyond_cells(maps: list[RobotMap], origins: np.ndarray, dirs: np.ndarray,
                 measured: np.ndarray) -> np.ndarray | None:
    """The cells ``[R, B, 2]`` (:meth:`RobotMap.cell_indices`) just beyond every robot's
    readings, where their echoes came from (robots at ``origins [R, 2]``, their beams ``dirs
    [R, B, 2]`` and readings ``measured [R, B]``; runs in lockstep together), each the bits
    of its own; ``None`` unless the maps share their cells' size and origin (the runs of a
    world do)."""
    grid = maps[0].grid
    if any(m.grid is not grid and (m.grid.resolution != grid.resolution
                                   or m.grid.origin != grid.origin) for m in maps):
        return None
    return maps[0].cell_indices(origins[:, None] + measured[..., None] * dirs
                                + dirs * (grid.resolution / 2))


def mark_all(maps: list[RobotMap], cells: np.ndarray, seen: np.ndarray) -> list[bool]:
    """``[m.mark_cells(c[w]) for m, c, w in zip(maps, cells [R, B, 2], seen [R, B])]``, the
    cells inside the grid found in one pass and the new ones marked in another
    (:func:`_add_marks`; maps alike: the runs of a world)."""
    grid = _alike(maps) if len(maps) > 1 else None
    if grid is None:
        return [m.mark_cells(c[w]) for m, c, w in zip(maps, cells, seen)]
    at = np.flatnonzero(seen & _within(cells, grid.occupied.shape))   # map by map, each in
    k = at // cells.shape[1]                                           # its beams' order
    got = cells.reshape(-1, 2).take(at, axis=0)    # (a flat take: a fraction of cells[k, b])
    row, col = got[:, 1], got[:, 0]
    if all(m.grid is grid for m in maps):
        known = _known(maps, grid, k, row, col)
    else:
        ends = np.cumsum(np.bincount(k, minlength=len(maps))).tolist()
        known = np.empty(len(k), dtype=bool)
        for m, a, e in zip(maps, [0, *ends[:-1]], ends):
            if e > a:
                known[a:e] = m.occupied[row[a:e], col[a:e]]
    new = np.flatnonzero(~known)
    if not len(new):
        return [False] * len(maps)
    _add_marks(maps, grid, k[new], row[new], col[new])
    return np.bincount(k[new], minlength=len(maps)).astype(bool).tolist()


def _known(maps: list[RobotMap], grid: Grid, k: np.ndarray, row: np.ndarray,
           col: np.ndarray) -> np.ndarray:
    """Which cells (rows ``row``, columns ``col`` of maps ``k``, ascending) the maps hold
    occupied, every map on ``grid``: a map's cells are the grid's plus its marks (none of
    them a grid's cell), so the grid's looked up for all at once and the marks of all as one
    ascending array of cells keyed by map, with one ``searchsorted``."""
    known = grid.occupied[row, col]
    marks = [m.marks for m in maps]
    counts = [len(m) for m in marks]
    if not any(counts) or not len(k):
        return known
    rows, cols = grid.occupied.shape
    size = rows * cols
    keys = np.concatenate(marks) + np.repeat(np.arange(len(maps)) * size, counts)
    asked = k * size + row * cols + col
    at = np.searchsorted(keys, asked)
    at[at == len(keys)] = 0
    known |= keys[at] == asked
    return known


def _add_marks(maps: list[RobotMap], grid: Grid, k: np.ndarray, row: np.ndarray,
               col: np.ndarray) -> None:
    """:meth:`RobotMap._mark` of the cells not yet marked (rows ``row``, columns ``col`` of
    maps ``k``, ascending; maps alike): their marks merged as one sorted array of cells keyed
    by map (a map's new cells are not among its marks), the centres as one array, then each
    map's part of both. The same marks, and the same centres in the same order."""
    rows, cols = grid.occupied.shape
    size = rows * cols
    which = np.unique(k)
    js = which.tolist()
    old = [maps[j].marks for j in js]
    flat = row * cols + col
    keys = np.concatenate([np.concatenate(old) + np.repeat(which * size, [len(o) for o in old]),
                           np.unique(k * size + flat)])
    keys.sort()
    bounds = np.searchsorted(keys, np.concatenate([which, which + 1]) * size).tolist()
    marks = keys - keys // size * size                 # every map's marks, each map's part
    xs, ys = _centre_lines(grid)
    centres = np.empty((len(k), 2))
    centres[:, 0], centres[:, 1] = xs[col], ys[row]
    ends = np.searchsorted(k, which, side="right").tolist()
    # a map's part of each array is a slice (its marks a copy of theirs: a slice would keep
    # the whole batch's marks of that tick alive as long as the map keeps them); its cells
    # are set by flat index (a quarter of the time of rows and columns)
    for j, a, e, lo, hi in zip(js, [0, *ends[:-1]], ends, bounds[:len(js)], bounds[len(js):]):
        m = maps[j]
        m._changes += 1
        m.occupied.put(flat[a:e], True)
        m.marks = marks[lo:hi].copy()
        m.fresh.append(centres[a:e])


def accounted_all(maps: list[RobotMap], cells: np.ndarray, reach: int = 2,
                  kept: Dilations | None = None) -> np.ndarray:
    """``[m.accounted_cells(c, reach) for m, c in zip(maps, cells [R, B, 2])]`` as ``[R, B]``:
    the cells inside tested and their places in a dilation worked out in one pass, then one
    ``take`` a map (maps alike: the runs of a world), or one for all from ``kept`` (a
    lockstep batch's :class:`Dilations`)."""
    grid = _alike(maps) if len(maps) > 1 else None
    if grid is None:
        return np.array([m.accounted_cells(c, reach) for m, c in zip(maps, cells)], dtype=bool
                        ).reshape(cells.shape[:2])
    rows, cols = grid.occupied.shape
    cells = cells + reach
    inside = _within(cells, (rows + 2 * reach, cols + 2 * reach))
    flat = cells[..., 1] * (cols + 2 * reach) + cells[..., 0]      # [R, B], row-major
    everywhere = np.count_nonzero(inside) == inside.size
    if not everywhere:
        flat[~inside] = 0                   # looked up at a cell of the dilation, then left
    stacked = None if kept is None else kept.of_maps(maps, reach)
    if kept is not None and stacked is not None:
        flat += kept.starts
        out = stacked.take(flat)
    else:
        out = np.empty(inside.shape, dtype=bool)
        for j, m in enumerate(maps):
            m._dilation(reach).take(flat[j], out=out[j])
    return out if everywhere else out & inside


class Dilations:
    """The maps' dilations (:meth:`RobotMap._dilation`) of a lockstep batch, one after the
    other in one flat array, so :func:`accounted_all` looks every robot's cells up in one
    ``take``: a map's part is copied again only when its dilation is a new array (it
    plans again), and none is kept past :data:`STACKED_BYTES` (large maps look up map by
    map)."""

    #: The most a batch's dilations are stacked to (bytes): office's 64 maps would be 23 MB.
    STACKED_BYTES = 4 << 20

    def __init__(self) -> None:
        self._parts: list[np.ndarray] = []
        self._flat = np.zeros(0, dtype=bool)
        self._starts = np.zeros((0, 1), dtype=np.int64)
        self._asked: tuple | None = None     # (reach, maps, their planned cells) of the last

    def of_maps(self, maps: list[RobotMap], reach: int) -> np.ndarray | None:
        """:meth:`of` the dilations of ``maps`` at ``reach`` (:meth:`RobotMap._dilation`),
        or the flat array it gave last, without asking each map again, when the maps and the
        cells each planned on are the very arrays they were then (a map that plans again
        keeps a new array; the given grid's dilation does not change): asking every map each
        tick took a third of :func:`accounted_all`'s time."""
        planned = [m.planned for m in maps]
        last = self._asked
        if last is not None and reach == last[0] and len(maps) == len(last[1]) \
                and all(map(operator.is_, maps, last[1])) \
                and all(map(operator.is_, planned, last[2])):
            return self._flat
        self._asked = None
        flat = self.of([m._dilation(reach) for m in maps])
        if flat is not None:
            self._asked = (reach, list(maps), planned)
        return flat

    def of(self, parts: list[np.ndarray]) -> np.ndarray | None:
        """The flat array of ``parts`` (dilations of one shape), or ``None`` past the cap."""
        size = parts[0].size
        if size * len(parts) > self.STACKED_BYTES:
            return None
        if len(parts) != len(self._parts) or self._flat.size != size * len(parts):
            self._flat = np.concatenate([p.reshape(-1) for p in parts])
            self._starts = (np.arange(len(parts), dtype=np.int64) * size)[:, None]
        else:
            for j, (new, old) in enumerate(zip(parts, self._parts)):
                if new is not old:
                    self._flat[j * size:(j + 1) * size] = new.reshape(-1)
        self._parts = parts
        return self._flat

    @property
    def starts(self) -> np.ndarray:
        """``[maps, 1]``: where each map's part begins in the flat array :meth:`of` gave."""
        return self._starts


def expected_ranges(g: Given, rmap: RobotMap | None, origin: np.ndarray, dirs: np.ndarray,
                    walls_near: np.ndarray, max_range: float) -> np.ndarray:
    """What the robot's map predicts along each beam: the given walls near it (the caller's
    set) and the known obstacles, or with no map what it has mapped itself."""
    if g.knows == "none" and rmap is not None:
        out = rmap.ranges(origin, dirs, max_range)
    else:
        out = ray_segments(origin, dirs, walls_near, max_range)
    if len(g.sides):
        lo = np.minimum(g.sides[:, :2], g.sides[:, 2:])
        hi = np.maximum(g.sides[:, :2], g.sides[:, 2:])
        near = ((lo <= origin + max_range) & (hi >= origin - max_range)).all(axis=1)
        if np.count_nonzero(near):
            out = np.minimum(out, ray_segments(origin, dirs, g.sides[near], max_range))
    if len(g.centres):
        near = np.hypot(*(g.centres - origin).T) <= max_range + g.radii
        if np.count_nonzero(near):
            out = np.minimum(out, ray_circles(origin, dirs, g.centres[near], g.radii[near],
                                              max_range))
    return out


def _as_map(grid: Grid) -> StaticMap:
    """A grid as a map to plan on (the planner needs only its cells)."""
    rows, cols = grid.occupied.shape
    x0, y0 = grid.origin
    return StaticMap(np.zeros((0, 4)), np.zeros((0, 4, 2)), grid,
                     (x0, y0, x0 + cols * grid.resolution, y0 + rows * grid.resolution))


def _window(grid: Grid, occupied: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> Grid:
    """The part of a grid (with cells ``occupied``) between two corners."""
    res, (ox, oy) = grid.resolution, grid.origin
    rows, cols = occupied.shape
    c0 = max(0, int((lo[0] - ox) // res))
    r0 = max(0, int((lo[1] - oy) // res))
    c1 = min(cols, int((hi[0] - ox) // res) + 1)
    r1 = min(rows, int((hi[1] - oy) // res) + 1)
    return Grid(occupied[r0:r1, c0:c1], res, (ox + c0 * res, oy + r0 * res), grid.source)


def way_past(rmap: RobotMap, route: Route, s: float, p: np.ndarray, ahead: float,
             clearance: float, minimum: float) -> bool:
    """Whether the robot at ``p`` can still get, within ``TUBE`` of its route, to a route point
    at least ``ahead`` inches on that is clear of what it knows (``minimum`` from it)."""
    end = min(s + ahead, route.length)
    last = min(end + 2 * TUBE, route.length)
    along = np.arange(s, last + 3.0, 3.0).clip(max=last)
    sample = np.array([route.point_at(u) for u in along])
    lo = np.minimum(sample.min(axis=0), p) - TUBE
    hi = np.maximum(sample.max(axis=0), p) + TUBE
    g = _window(rmap.grid, rmap.occupied, lo, hi)
    room = Clearance.of(g.occupied, g.resolution, g.origin, cap=minimum + 2 * g.resolution)
    beyond = (along >= end) & (room.at(sample) >= minimum)
    if not np.count_nonzero(beyond):
        return False
    target = sample[int(np.argmax(beyond))]
    try:
        grid_route(_as_map(g), Pose(float(p[0]), float(p[1])), Goal(float(target[0]),
                   float(target[1])), clearance, minimum=minimum, explain=False,
                   leave=clearance + 6.0, keep=False)
    except NarrowPassage:
        return False
    return True


def replan(rmap: RobotMap, route: Route, s: float, p: np.ndarray, goal: Goal, t: float,
           clearance: float, minimum: float, sight: float, when: str = "clearance", *,
           heading: float = 0.0, behind: float = 0.0,
           moving: movers.Sweep | None = None) -> Route | None:
    """A new route from ``p`` when what the robot has newly sensed invalidates the route ahead
    (``when``: see the module docstring), else ``None``. ``moving``: where what moves toward it
    will pass (:class:`.movers.Sweep`): the route keeps clear of that too (but for a way out
    round the robot), and where that leaves no way to the goal it leads to a refuge out of
    their way (:func:`refuge`) until one opens."""
    if not _due(rmap, route, s, p, t, clearance, minimum, sight, when, moving):
        return None
    start = Pose(float(p[0]), float(p[1]), heading)
    plan = functools.partial(_plan, rmap, start, clearance, minimum, behind)
    if moving is None:
        new = plan(goal, rmap.occupied)
        if new is None:            # no way left on what it knows: drive on, the rules decide
            return None            # (at a refuge: wait there, and try again at the next check)
        rmap.refuge = None
    else:
        new = _past_movers(rmap, moving, plan, p, goal, start, clearance, minimum, sight, behind)
        if new is None:
            return None
    rmap.replans += 1
    rmap.planned = rmap.occupied.copy()
    return new


def checks_due(maps: list[RobotMap], t: float, when: str = "clearance") -> list[int]:
    """Which of ``maps`` (one robot's each) are due a replanning check at ``t``: none when
    the routes are never replanned, else those last checked ``REPLAN_EVERY`` s ago or more
    (as :func:`replan` takes it; Python floats: cheaper than an array of a few hundred).
    Only these robots' :func:`replan` can plan again."""
    if when == "never":
        return []
    return [i for i, m in enumerate(maps) if not t - m.checked_at < REPLAN_EVERY]


def _due(rmap: RobotMap, route: Route, s: float, p: np.ndarray, t: float, clearance: float,
         minimum: float, sight: float, when: str, moving: movers.Sweep | None) -> bool:
    """Whether the route is planned again at ``t``: a check is due (every ``REPLAN_EVERY``
    s), and what was marked since the last one comes near the route ahead (``when``), or
    a mover will pass across it, or the robot waits at a refuge. A check takes the marks."""
    if when == "never" or t - rmap.checked_at < REPLAN_EVERY:
        return False
    if not rmap.fresh and moving is None and rmap.refuge is None:
        return False
    fresh = np.concatenate(rmap.fresh) if rmap.fresh else np.zeros((0, 2))
    rmap.fresh.clear()
    rmap.checked_at = t
    reach = minimum + rmap.grid.resolution / 2          # a mark is a cell, not its centre
    if rmap.refuge is not None or moving is not None and bool(
            route.near(_cell_centres(rmap.grid, moving.cells), s, reach, sight).any()):
        return True
    if when == "clearance":
        return bool(route.near(fresh, s, reach, sight).any())
    return (bool(route.near(fresh, s, clearance, sight).any())
            and not way_past(rmap, route, s, p, sight, clearance, minimum))


def _plan(rmap: RobotMap, start: Pose, clearance: float, minimum: float, behind: float,
          where: Goal, occupied: np.ndarray) -> Route | None:
    """A route on ``occupied`` (cells like ``rmap``'s) from ``start`` to ``where``, or
    ``None`` where none keeps ``minimum``."""
    try:
        return grid_route(_as_map(rmap.grid), start, where, clearance, minimum=minimum,
                          occupied=occupied, explain=False, leave=clearance + 6.0,
                          behind=behind, last=rmap.prepared)
    except NarrowPassage:
        return None


Planner = Callable[[Goal, np.ndarray], Route | None]   # _plan from the robot, to a place


def _past_movers(rmap: RobotMap, moving: movers.Sweep, plan: Planner, p: np.ndarray,
                 goal: Goal, start: Pose, clearance: float, minimum: float, sight: float,
                 behind: float) -> Route | None:
    """A route to the goal clear of where the movers will pass (but round the robot), right
    of those down its lane where there is room (without it, where one comes on the robot's
    left: :attr:`.movers.Sweep.left`; and never squeezing right of one that comes on its
    right, :attr:`.movers.Sweep.right`); where there is none, a route to a refuge,
    and the robot at a refuge waits there till nothing comes toward it; ``None`` when
    neither is left. ``plan(where, occupied)``: :func:`_plan` from the robot.

    A mover down the robot's lane on its right (half a body width or more off its line) is
    not passed on the right without the room keeping right asks: that way crosses in front
    of it, between it and what stands beyond, and the sonar's echoes of a cart lie at its
    nearest corner, not its middle, so a route squeezed past them at the least clearance
    runs into its true side (seed 0's ``moving+clutter6`` of ``benchmarks/bench_nav.py``:
    squeezed 10 in below the echoes of a cart whose side lay 9 in below them). As with one
    on its left, it goes left of it, or to a refuge.

    While the robot is bound for a refuge and the movers it yields to sweep nothing (their
    heading not known yet, and the robot turned out of its lane for the refuge:
    :func:`.movers.sweep`), it keeps the refuge it holds while it can reach it, though what
    stands there, better seen, leaves it less room than asked: the place was chosen clear of
    where they were drawn to pass, nothing known since says where else is out of their way,
    and with nothing to keep clear of, the nearest place out of it is where the robot
    stands, in the lane it is leaving (the same run: its refuge moved to its own place at
    17.4 s, 61 in from the cart)."""
    hole = max(clearance + 6.0, moving.wide + 6.0)
    occupied = rmap.occupied | _holed(rmap.grid, moving.cells, p, hole)
    new = None
    if rmap.refuge is None and moving.keep_right is not None:
        new = plan(goal, occupied | _holed(rmap.grid, moving.keep_right, p, hole))
        if new is None and moving.left is not None:     # right of it, squeezing past
            new = plan(goal, occupied | _holed(rmap.grid, moving.left, p, hole))
    if rmap.refuge is None and new is None:       # either side, but squeezing across one
        new = plan(goal, occupied if moving.right is None      # coming on its right
                   else occupied | _holed(rmap.grid, moving.right, p, hole))
    if new is not None:
        rmap.refuge = None
        return new
    if rmap.refuge is not None and not moving.wide:            # nothing drawn: keep it
        new = plan(rmap.refuge, occupied)
        if new is not None:
            return new
    new = refuge(rmap, rmap.occupied | moving.cells, occupied, start, clearance, minimum,
                 sight, behind)
    if new is not None:
        rmap.refuge = Goal(float(new.goal[0]), float(new.goal[1]))
    return new


def _cell_centres(grid: Grid, cells: np.ndarray) -> np.ndarray:
    """The centres ``[P, 2]`` of the set cells of ``cells`` (a boolean grid like ``grid``'s)."""
    r, c = set_cells(cells)
    return np.stack([grid.origin[0] + (c + 0.5) * grid.resolution,
                     grid.origin[1] + (r + 0.5) * grid.resolution], axis=1)


def _holed(grid: Grid, cells: np.ndarray, p: np.ndarray, radius: float) -> np.ndarray:
    """``cells`` without those within ``radius`` of ``p``: a robot standing in a mover's way
    must be able to plan its way out of it."""
    near = movers.capsule_cells(cells.shape, grid.resolution, grid.origin, p, p, radius)
    return cells & ~near


REFUGE_TRIES = 8      # the nearest places out of the movers' way a refuge is sought at
REFUGE_APART = 12.0   # in: the least distance between two places tried
BEHIND_COST = 2.0     # an inch behind the robot counts as this many more on the way to a refuge


def refuge(rmap: RobotMap, avoid: np.ndarray, occupied: np.ndarray, start: Pose,
           clearance: float, minimum: float, sight: float, behind: float) -> Route | None:
    """A route to the nearest place within ``sight`` that keeps ``clearance`` from the cells
    ``avoid`` (what the robot knows and where movers will pass), planned on ``occupied``
    (the same, less the movers' way round the robot); ``None`` when none is reached. The
    place it held last (``rmap.refuge``) comes first while it is still out of their way: a
    robot that changes its mind on the way to a refuge ends up in nobody's refuge."""
    g = rmap.grid
    p = np.array([start.x, start.y])
    win = _window(g, avoid, p - sight, p + sight)
    room = Clearance.of(win.occupied, win.resolution, win.origin,
                        cap=clearance + 2 * win.resolution)
    centres = _cell_centres(win, room.dist - win.resolution / 2 >= clearance)
    # nearest first, a place behind the robot counted BEHIND_COST times farther: a robot
    # that steers its front wheel reaches what lies ahead and beside it sooner
    rel = centres - p
    h = math.radians(start.heading)
    back = np.maximum(-(rel[:, 0] * math.cos(h) + rel[:, 1] * math.sin(h)), 0.0)
    places = list(centres[np.argsort(np.hypot(*rel.T) + BEHIND_COST * back, kind="stable")])
    if rmap.refuge is not None:
        held = np.array([rmap.refuge.x, rmap.refuge.y])
        if room.at(held[None])[0] >= clearance:
            places.insert(0, held)
    tried: list[np.ndarray] = []
    for c in places:
        if len(tried) >= REFUGE_TRIES:
            break
        if any(math.dist(c, q) < REFUGE_APART for q in tried):
            continue
        tried.append(c)
        try:
            return grid_route(_as_map(g), start, Goal(float(c[0]), float(c[1])), clearance,
                              minimum=minimum, occupied=occupied, explain=False,
                              leave=clearance + 6.0, behind=behind, last=rmap.prepared)
        except NarrowPassage:
            continue
    return None
