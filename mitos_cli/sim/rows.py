"""Sensing many robots at once: one row per robot, of one run or of many runs stepped together
(:mod:`.lockstep`).

Each row's beams, readings and clearance are the arithmetic of one robot alone, element by
element over ``[rows, ...]`` arrays: every operation here is elementwise or an exact minimum,
so a row gets the bits it gets alone, whatever the other rows. Rows have different numbers of
nearby walls; they are padded with zero-length segments (a ray never hits one) and the padding
is masked out of every minimum. Rows sensed together have as many obstacles each (the robots
of runs of one world). Calls that may round by their operands' shape (the penetration depth's
``einsum``) are made row by row, on exactly the operands a robot alone passes.
"""

from __future__ import annotations

import functools
import math
import operator
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Generic, TypeVar, overload

import numpy as np

from .geometry import (
    EPS,
    box_polygon_depth,
    box_segment_distance,
    clip_arrays,
    cross,
    polygon_overlaps,
    polygon_segments,
)
from .sensors import Noise
from .world import Robot

T = TypeVar("T")


@dataclass
class SenseRow:
    """What one robot senses with at one tick: where it is, what is near it, its noise."""

    x: float
    y: float
    heading: float                 # rad
    robot: Robot
    walls: np.ndarray              # [W, 4] the walls near it
    segments: np.ndarray           # [W + S, 4] those walls, then obstacle and robots' sides
    boxes: np.ndarray              # [P, 4, 2] rectangles and other robots' footprints
    discs: tuple[np.ndarray, np.ndarray]   # [P, 2], [P]: discs holding them (:func:`discs`)
    centres: np.ndarray            # [C, 2] circles
    radii: np.ndarray              # [C]
    noise: float                   # in, standard deviation of its readings' noise
    rng: Noise | np.random.Generator   # its own stream of noise (standard_normal(n))


@dataclass
class Sensed:
    """Every row's beams: directions ``[R, B, 2]``, what the walls alone give ``[R, B]`` (what
    the map predicts), the noisy readings ``[R, B]`` and the footprint's clearance ``[R]``."""

    dirs: np.ndarray
    static: np.ndarray
    ranges: np.ndarray
    clearance: np.ndarray


def discs(polygons: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Discs holding convex polygons ``[P, k, 2]``: their corners' mean and the farthest
    corner's distance from it, plus 1e-6 in for rounding (``[P, 2]``, ``[P]``)."""
    middle = polygons.mean(axis=1)
    off = polygons - middle[:, None]
    return middle, np.hypot(off[..., 0], off[..., 1]).max(axis=1, initial=0.0) + 1e-6


#: Rows' arrays stacked at a :func:`sense`, by name: the arrays of each row and their stack.
Kept = dict[str, tuple[list[np.ndarray], np.ndarray]]


def sense(rows: list[SenseRow], angles: np.ndarray, max_range: float,
          kept: Kept | None = None) -> Sensed:
    """The beams of every row (:func:`.sensors.cast`, :func:`.sensors.add_noise`) and the
    clearance of its footprint, row by row the bits of one robot alone. ``kept``: what the
    last :func:`sense` of these rows stacked (runs in lockstep keep it from tick to tick),
    taken again where every row's array is the very one it was, and updated."""
    if len(rows) > 1 and len({(r.boxes.shape, len(r.centres)) for r in rows}) > 1:
        raise ValueError("rows sensed together have as many obstacles each")
    heading = np.array([r.heading for r in rows])
    origin = np.array([[r.x for r in rows], [r.y for r in rows]]).T     # (no tuple a row)
    a = heading[:, None] + angles
    dirs = np.empty((*a.shape, 2))                                      # [R, B, 2]
    dirs[..., 0] = np.cos(a)
    dirs[..., 1] = np.sin(a)
    stacks = _Stacks(rows, kept)
    static, hit = _cast(stacks, origin, dirs, max_range)
    ranges = _noisy(rows, hit, max_range)
    return Sensed(dirs, static, ranges, _clearance(stacks, origin, heading))


def clearance(rows: list[SenseRow]) -> np.ndarray:
    """The clearance of each row's footprint ``[R]``, as :func:`sense` gives it, without the
    beams (the contact check between ticks looks at poses no beam is cast from)."""
    return _clearance(_Stacks(rows), np.array([(r.x, r.y) for r in rows]),
                      np.array([r.heading for r in rows]))


def _stacked(arrays: list[np.ndarray], width: int | None = None) -> np.ndarray:
    """``[R, width, ...]``: the arrays one above the other, each padded with zeros to
    ``width`` rows (default: the longest's; a view of the one array, when there is one that
    needs no padding): one concatenation, then the rows laid out in a block where they are
    not all ``width`` long."""
    if len(arrays) == 1 and (width is None or len(arrays[0]) == width):
        return arrays[0][None]                          # (a run of one robot: each tick)
    lengths = np.fromiter(map(len, arrays), np.intp, len(arrays))
    longest = int(lengths.max())
    width = longest if width is None else width
    if longest > width:
        raise ValueError(f"an array of {longest} rows does not fit in {width}")
    flat = np.concatenate(arrays, dtype=float)
    if len(flat) == len(arrays) * width:                # (all are width long)
        return flat.reshape(len(arrays), width, *flat.shape[1:])
    out = np.zeros((len(arrays), width, *flat.shape[1:]))
    out[np.arange(width) < lengths[:, None]] = flat
    return out


class once(Generic[T]):
    """A property worked out on first use and kept in the instance: a
    ``functools.cached_property`` without the lock Python 3.11's takes at every first use
    (2-3 us; a run alone stacks six arrays a tick, and reads its tick's inputs by name)."""

    def __init__(self, fn: Callable[[Any], T]) -> None:
        self.fn, self.name, self.__doc__ = fn, fn.__name__, fn.__doc__

    @overload
    def __get__(self, obj: None, owner: type | None = None) -> once[T]: ...

    @overload
    def __get__(self, obj: object, owner: type | None = None) -> T: ...

    def __get__(self, obj: Any, owner: type | None = None) -> T | once[T]:
        if obj is None:                 # asked of the class (help(), a documentation tool)
            return self
        value = obj.__dict__[self.name] = self.fn(obj)
        return value


class _Stacks:
    """The rows' arrays one above the other (:func:`_stacked`), each stacked once a
    :func:`sense`, when a stage first asks for it; from ``kept`` (:data:`Kept`, updated)
    where the rows' arrays are the very ones stacked last (a run's obstacles stand still,
    and its walls are gathered again only once it moved on: most ticks, all of them)."""

    def __init__(self, rows: list[SenseRow], kept: Kept | None = None) -> None:
        self.rows = rows
        self.kept: Kept = {} if kept is None else kept

    def _stack(self, name: str, arrays: list[np.ndarray], width: int | None = None) -> np.ndarray:
        """``_stacked(arrays, width)``, or the stack kept of the same arrays (their widths
        are the same too)."""
        old = self.kept.get(name)
        if old is not None and len(old[0]) == len(arrays) and all(map(operator.is_, old[0],
                                                                        arrays)):
            return old[1]
        out = _stacked(arrays, width)
        self.kept[name] = (arrays, out)
        return out

    @once
    def wall_counts(self) -> list[int]:
        return [len(r.walls) for r in self.rows]

    @once
    def walls(self) -> np.ndarray:                      # [R, W, 4], W the most of a row
        return self._stack("walls", [r.walls for r in self.rows], max(self.wall_counts))

    @once
    def segments(self) -> np.ndarray:                   # [R, N, 4], N the most of a row
        arrays = [r.segments for r in self.rows]
        return self._stack("segments", arrays, max(map(len, arrays)))

    @once
    def centres(self) -> np.ndarray:                    # [R, C, 2]
        return self._stack("centres", [r.centres for r in self.rows])

    @once
    def radii(self) -> np.ndarray:                      # [R, C]
        return self._stack("radii", [r.radii for r in self.rows])

    @once
    def middles(self) -> np.ndarray:                    # [R, P, 2], the discs' (:func:`discs`)
        return self._stack("middles", [r.discs[0] for r in self.rows])

    @once
    def reaches(self) -> np.ndarray:                    # [R, P], their radii
        return self._stack("reaches", [r.discs[1] for r in self.rows])


CULL_FROM = 16                 # boxes from which beams test only the boxes their discs allow


def _cast(stacks: _Stacks, origin: np.ndarray, dirs: np.ndarray,
          max_range: float) -> tuple[np.ndarray, np.ndarray]:
    """Noise-free ranges ``[R, B]``: to the walls alone, and to everything (walls, sides and
    circles): :func:`.geometry.ray_hits` and :func:`.geometry.ray_circles`, per element.

    Among many boxes each beam tests the sides only of the boxes whose discs it passes
    through (:func:`_box_hits`): a side it cannot reach is never its nearest, and the sides
    it tests get the same formula, element by element, so every range keeps its bits."""
    rows = stacks.rows
    walls = stacks.wall_counts
    total = [len(r.segments) for r in rows]
    boxes = len(rows[0].boxes)
    if boxes >= CULL_FROM and all(t - w == 4 * boxes for w, t in zip(walls, total)):
        static = _ray_hits(stacks.walls, origin, dirs)
        hit = np.minimum(np.minimum(static, _box_hits(stacks, origin, dirs, max_range)),
                         max_range)
        static = np.minimum(static, max_range)
    else:
        t = _ray_hits(stacks.segments, origin, dirs, keep=True)        # [R, N, B]
        hit = np.minimum(t.min(axis=1, initial=np.inf), max_range)
        if walls == total:                              # no sides: the walls are all there is
            static = hit
        elif min(walls) == max(walls):                  # the walls come first in every row
            static = np.minimum(t[:, :walls[0]].min(axis=1, initial=np.inf), max_range)
        else:
            is_wall = np.arange(t.shape[1]) < np.array(walls)[:, None]
            static = np.minimum(np.minimum.reduce(t, axis=1, initial=np.inf,
                                                  where=is_wall[..., None]), max_range)
    if not len(rows[0].centres):
        return static, hit
    return static, np.minimum(hit, _circles(stacks, origin, dirs, max_range))


def _ray_hits(seg: np.ndarray, origin: np.ndarray, dirs: np.ndarray, keep: bool = False) -> np.ndarray:
    """How far along each beam ``dirs [R, B, 2]`` from ``origin [R, 2]`` it meets each
    segment ``seg [R, N, 4]`` (``inf`` where it does not): ``[R, N, B]`` when ``keep``, else
    the nearest ``[R, B]``. The beams run along the last axis: the minimum over the few
    segments is then one elementwise pass per segment, not a reduction of a few elements
    per beam (at 55 rows of 36 beams and 6 segments: 10 us, against 66)."""
    run = seg[..., 2:] - seg[..., :2]                                   # [R, N, 2]
    start = seg[..., :2] - origin[:, None]
    t = _along(dirs[:, None, :, 0], dirs[:, None, :, 1],                # [R, 1, B]
               run[..., 0, None], run[..., 1, None],                    # [R, N, 1]
               start[..., 0, None], start[..., 1, None])
    return t if keep else t.min(axis=1, initial=np.inf)


def _along(dx: np.ndarray, dy: np.ndarray, ex: np.ndarray, ey: np.ndarray, px: np.ndarray,
           py: np.ndarray) -> np.ndarray:
    """:func:`.geometry.ray_hits`' formula, elementwise: how far along the beam ``(dx, dy)``
    it meets the segment from ``(px, py)`` (relative to the beam's origin) running
    ``(ex, ey)``, or ``inf``."""
    denom = cross(dx, dy, ex, ey)
    ok = np.abs(denom) > EPS
    safe = np.where(ok, denom, 1.0)
    t = cross(px, py, ex, ey) / safe
    s = cross(px, py, dx, dy) / safe
    ok &= t >= 0.0
    ok &= s == clip_arrays(s, 0.0, 1.0)                 # 0 <= s <= 1 (false for NaN, too)
    return np.where(ok, t, np.inf)


def _box_hits(stacks: _Stacks, origin: np.ndarray, dirs: np.ndarray,
              max_range: float) -> np.ndarray:
    """The nearest box side along every beam ``[R, B]`` (``inf`` for none), testing a beam
    only against the boxes whose enclosing discs (:func:`discs`) it passes through within
    ``max_range``, with 1e-6 in of slack on top of theirs."""
    rows = stacks.rows
    middle = stacks.middles - origin[:, None]                           # [R, P, 2]
    radius = stacks.reaches[:, None] + 1e-6                             # [R, 1, P]
    dx, dy = dirs[..., 0, None], dirs[..., 1, None]                     # [R, B, 1]
    mx, my = middle[:, None, :, 0], middle[:, None, :, 1]               # [R, 1, P]
    along = dx * mx + dy * my                                           # [R, B, P]
    maybe = np.abs(dx * my - dy * mx) <= radius
    maybe &= along >= -radius
    maybe &= along - radius <= max_range
    r, b, p = np.nonzero(maybe)
    out = np.full(dirs.shape[:2], np.inf)
    if not len(r):
        return out
    sides = _stacked([row.segments[len(row.walls):] for row in rows])    # [R, 4P, 4]
    seg = sides.reshape(len(rows), -1, 4, 4)[r, p]                      # [K, 4, 4]
    run = seg[..., 2:] - seg[..., :2]                                   # [K, 4, 2]
    start = seg[..., :2] - origin[r, None]
    d = dirs[r, b]                                                      # [K, 2]
    t = _along(d[:, 0, None], d[:, 1, None], run[..., 0], run[..., 1],
               start[..., 0], start[..., 1]).min(axis=1)                # [K]
    np.minimum.at(out, (r, b), t)
    return out


def _circles(stacks: _Stacks, origin: np.ndarray, dirs: np.ndarray,
             max_range: float) -> np.ndarray:
    """:func:`.geometry.ray_circles` of every row, ``[R, B]``."""
    off = origin[:, None] - stacks.centres                              # [R, C, 2]
    radii = stacks.radii                                                # [R, C]
    mx, my = off[..., 0, None], off[..., 1, None]                       # [R, C, 1]
    # the beams along the last axis (as :func:`_ray_hits`)
    b = mx * dirs[:, None, :, 0] + my * dirs[:, None, :, 1] + 0.0        # [R, C, B]
    c = mx * mx + my * my - radii[..., None] ** 2                       # [R, C, 1]
    disc = b * b - c
    root = np.sqrt(np.maximum(disc, 0.0))
    t = np.where(c <= 0.0, 0.0, -b - root)
    hit = (disc >= 0.0) & (t >= 0.0)
    return np.minimum(np.minimum.reduce(t, axis=1, initial=np.inf, where=hit), max_range)


def _noisy(rows: list[SenseRow], ranges: np.ndarray, max_range: float) -> np.ndarray:
    """:func:`.sensors.add_noise` of every row, each from its own stream (rows without noise
    keep their ranges as they are): each row's ``rng.normal(0.0, noise, B)``, ``0.0 + noise
    * z`` of its next ``B`` standard normal draws, the products made for all rows at once."""
    noisy = [r.noise > 0 for r in rows]
    if not any(noisy):
        return ranges
    width = ranges.shape[1]
    z = _stacked([np.asarray(r.rng.standard_normal(width)) if n else np.zeros(width)
                  for r, n in zip(rows, noisy)])
    sigma = rows[0].noise if len(rows) == 1 else np.array([r.noise for r in rows])[:, None]
    draws = 0.0 + sigma * z
    out = np.where(ranges >= max_range, max_range, clip_arrays(ranges + draws, 0.0, max_range))
    return out if all(noisy) else np.where(np.array(noisy)[:, None], out, ranges)


def _clearance(stacks: _Stacks, origin: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """The clearance of every row ``[R]`` (rows of one footprint together): the signed
    distance from its footprint to walls, polygons and circles, computed in the footprint's
    own frame (the gap when apart, 0 touching, minus the penetration depth when
    overlapping)."""
    rows = stacks.rows
    if len({(r.robot.length, r.robot.width) for r in rows}) == 1:     # (most batches)
        return _group_clearance(stacks, origin, heading, rows[0].robot.length / 2,
                                rows[0].robot.width / 2)
    groups: dict[tuple[float, float], list[int]] = {}
    for i, r in enumerate(rows):
        groups.setdefault((r.robot.length / 2, r.robot.width / 2), []).append(i)
    out = np.empty(len(rows))
    for (hl, hw), idx in groups.items():
        out[idx] = _group_clearance(_Stacks([rows[i] for i in idx]), origin[idx], heading[idx],
                                    hl, hw)
    return out


class _Frames:
    """Rows' footprint frames: points of rows ``idx`` as seen from their footprints."""

    def __init__(self, origin: np.ndarray, heading: np.ndarray) -> None:
        self.origin = origin
        h = heading.tolist()
        c, s = list(map(math.cos, h)), list(map(math.sin, h))          # as one robot's
        # [R, 1, 2, 2]: row j of a point's turn is (x * c + y * s, x * -s + y * c)
        self.turn = np.array([c, s, [-x for x in s], c]).T.reshape(len(h), 1, 2, 2)

    def local(self, points: np.ndarray, idx: slice | np.ndarray = slice(None)) -> np.ndarray:
        """``[r, K, 2]`` world points of rows ``idx`` in their footprints' frames."""
        rel = (points - self.origin[idx, None])[..., None, :] * self.turn[idx]    # [r, K, 2, 2]
        return rel[..., 0] + rel[..., 1]


def _group_clearance(stacks: _Stacks, origin: np.ndarray, heading: np.ndarray,
                     hl: float, hw: float) -> np.ndarray:
    """The clearance of rows with the same footprint ``[-hl, hl] x [-hw, hw]``. A thing whose
    enclosing disc lies farther from the footprint's than the walls cannot be the nearest
    (1e-6 in of slack for rounding); rows with none nearer skip that kind of thing, but only
    while no wall touches the footprint (whatever may overlap it is measured together, as
    one robot alone does)."""
    rows = stacks.rows
    frames = _Frames(origin, heading)
    best = _walls(stacks, frames, hl, hw)
    reach = np.where(best > 0.0, best + math.hypot(hl, hw) + 1e-6, np.inf)[:, None]
    if len(rows[0].boxes):
        near = _near(origin, stacks.middles, stacks.reaches, reach)
        if len(near):
            shape = rows[0].boxes.shape
            world = _stacked([rows[i].boxes for i in near]).reshape(len(near), -1, 2)
            boxes = frames.local(world, near).reshape(len(near), *shape)
            best[near] = np.minimum(best[near], _polygons(hl, hw, boxes).min(axis=1))
    if len(rows[0].centres):
        centres, radii = stacks.centres, stacks.radii
        near = _near(origin, centres, radii, reach)
        if len(near):
            # (|x| - hl, |y| - hw) of each centre in its row's footprint's frame
            q = np.abs(frames.local(centres[near], near)) - _half_sizes(hl, hw)
            lx, ly = q[..., 0], q[..., 1]
            outside = np.hypot(np.maximum(lx, 0), np.maximum(ly, 0))
            inside = np.minimum(np.maximum(lx, ly), 0)
            best[near] = np.minimum(best[near], (outside + inside - radii[near]).min(axis=1))
    return best


def _near(origin: np.ndarray, middle: np.ndarray, radius: np.ndarray,
          reach: np.ndarray) -> np.ndarray:
    """The rows with a disc (``middle [R, D, 2]``, ``radius [R, D]``) within ``reach [R, 1]``
    of their origin."""
    away = middle - origin[:, None]
    return np.logical_or.reduce(np.hypot(away[..., 0], away[..., 1]) - radius <= reach,
                                axis=1).nonzero()[0]


@functools.lru_cache(maxsize=16)
def _half_sizes(hl: float, hw: float) -> np.ndarray:
    out = np.array([hl, hw])
    out.flags.writeable = False
    return out


def _walls(stacks: _Stacks, frames: _Frames, hl: float, hw: float) -> np.ndarray:
    """``[R]``: the signed distance from each row's footprint to its nearest wall (``inf``
    with none); the depth of walls that cross it row by row."""
    rows, counts = stacks.rows, stacks.wall_counts
    width = max(counts)
    if not width:
        return np.full(len(rows), np.inf)
    walls = stacks.walls
    ends = frames.local(walls.reshape(len(rows), -1, 2)).reshape(len(rows), -1, 2, 2)
    w = box_segment_distance(hl, hw, ends.reshape(-1, 4)).reshape(len(rows), -1)
    real = None if min(counts) == width else np.arange(width) < np.array(counts)[:, None]
    crossing = w <= 0.0 if real is None else real & (w <= 0.0)
    if np.count_nonzero(crossing):
        for i in np.logical_or.reduce(crossing, axis=1).nonzero()[0]:
            mine = crossing[i, :counts[i]]
            w[i, :counts[i]][mine] = -box_polygon_depth(hl, hw, ends[i, :counts[i]][mine])
    return (w if real is None else np.where(real, w, np.inf)).min(axis=1, initial=np.inf)


def _polygons(hl: float, hw: float, boxes: np.ndarray) -> np.ndarray:
    """:func:`.geometry.box_polygon_distance` of every row's polygons ``[R, P, k, 2]`` (in
    the footprint's frame), ``[R, P]``; the depth of those that may overlap row by row."""
    R, P = boxes.shape[:2]
    flat = boxes.reshape(R * P, *boxes.shape[2:])
    gap = box_segment_distance(hl, hw, polygon_segments(flat)).reshape(R * P, -1).min(axis=1)
    over = polygon_overlaps(hl, hw, flat, gap).reshape(R, P)
    gap = gap.reshape(R, P)
    for i in np.flatnonzero(np.logical_or.reduce(over, axis=1)):
        depth = box_polygon_depth(hl, hw, boxes[i][over[i]])
        gap[i, over[i]] = np.where(depth > 0.0, -depth, gap[i, over[i]])
    return gap
