"""From range readings to the rule base's inputs (the paper's x1, x2, x3 and what the other
behaviors need).

Frame: at the robot's projection onto its route, ``a`` runs along the route and ``b`` across it,
positive to the RIGHT. The robot knows its pose (odometry) and the map it planned its route on
(:mod:`.knowledge`), so a beam whose reading is clearly shorter than that map predicts has hit
an obstacle: an unknown box, an unknown wall, a corridor blocked by furniture. Every other beam
has hit something drawn on its map (a wall, a door jamb, a pillar, a known obstacle), which the
route already keeps its clearance from: it counts as a wall (``road``, ``gap_left``,
``gap_right``), unless it stands within half the robot's width plus its safety margin of the
route ahead (where the route runs through what a robot with no map has only now mapped;
where it squeezes by under ``route: {min_clearance}``, nearer than the squeeze keeps): there
it is in the robot's way and obstructs like an obstacle.

Inputs (all floats, units in the names of ``mitos.terms.yaml`` / ``drive.terms.yaml``):

``road`` (x1, in)
    corridor width at the robot: the distance from its centre to the nearest wall hit on the
    left of the route plus that to the nearest on the right, among beams that land within
    ``window`` of the robot along the route (``range`` for a side with no wall in sight, e.g.
    at an intersection). Distances, not offsets across the route: a route leg that runs
    across a corridor (to a goal off its middle) does not widen it.
``size`` (x2, in)
    width across the route of the nearest *obstructing* object ahead: the obstacle hits within
    ``cluster`` of the nearest one, each widened by half the beam spacing at its range (an
    ultrasonic beam cannot tell where in its cone the echo came from). 0 when nothing obstructs.
``position`` (x3, in)
    lateral offset of that object's middle from the road centre, positive to the right,
    measured across the route where the object stands (around a corner: across the next leg).
    0 when nothing obstructs.
``obstacle`` (in)
    distance along the route from the robot's front to that object; ``NO_OBSTACLE`` (200, the
    far end of its universe) when nothing obstructs, so that ``obstacle is NEAR`` is 0 and the
    blending switches avoid_obstacle off. An object *obstructs* when it is ahead, within
    ``sight``, and its lateral extent overlaps the band the robot sweeps if it drives on
    parallel to the route (its width plus ``band_margin`` on each side).
``heading`` (deg)
    bearing of the route point ``lookahead`` ahead, relative to the robot's heading, positive
    to the right (steer right to reduce it).
``lane`` (in)
    lateral offset of the robot from its keep-right lane, a line ``min(road / 4, road / 2 -
    width / 2 - lane_margin)`` right of the road centre; positive = right of the lane.
``goal`` (in)
    length of route left to the goal (at least the straight distance to it).
``front`` (in)
    how far the robot can drive straight on before something its map does not show: from its
    front to the first obstacle hit in the band its body sweeps along its heading,
    ``way_margin`` added on each side; ``sight`` when none is there (see :func:`free_ways`).
    Walls do not count: the route already keeps to the corridors.
``opening`` (deg)
    bearing of the way the robot should take, relative to its heading, positive to the right:
    the way (every ``way_step`` within ``way_fov``, and the route's own bearing) that offers
    the most progress toward the route: how far its body's band is clear of walls and
    obstacles along it (up to ``way_reach``, scored in a band just clear of the body and in
    one ``way_room`` roomier) times the cosine of its angle to the route's bearing
    (``heading``; behind the robot, the side it lies on), plus ``way_room_weight`` times that
    clear length (so that when every way is shut the roomiest wins), less ``way_turn_cost`` for
    every degree it turns from the robot's heading (so it does not flip between two gaps).
    Where the route's own bearing is clear, ``opening`` is ``heading`` (to within a degree or
    two: a way nearer the heading may win by its lower turn cost); in clutter it points at
    the gap to take.
``clutter`` (objects)
    how many separate objects its map does not show the robot sees ahead within ``sight``:
    runs of neighbouring beams hitting obstacles, split where two hits lie more than
    ``clutter_gap`` apart (see :func:`clutter`). With one object at a time the paper's
    repertoire avoids "the obstacle"; among several the ``drive`` behavior takes the opening.
``nearest`` (in)
    the gap between the robot's footprint and the nearest echo ahead of its centre and
    within ``nearest_band`` of the band its body sweeps, whatever it hit (a wall, a door
    jamb, a pole, a box: drawn on its map or not), capped at ``nearest_cap``: what its front
    corners will meet next (see :func:`nearest`). ``front`` sees only what the map does not
    show and only straight on; a jamb beside a door or a pole by the corner of the body is in
    ``nearest``, so the ``drive`` behavior slows for it.
``gap_left``, ``gap_right`` (in)
    gap between the robot's side and the nearest thing hit on that side of the route: its
    distance from the body's long axis (across the body beside it, from its front or rear
    end past it) less half the body's width; walls among beams landing from ``wall_behind``
    behind to ``wall_ahead`` ahead of the robot's centre along the route, objects only while
    beside its body; all at least half its width across the route (``range`` when none; at
    least 0: a point by the nose of a robot turned across its route): what
    keeps the robot off the walls while it avoids an obstacle, and off an obstacle it is
    passing once that is no longer ahead.

:func:`truth` computes the same quantities from the true geometry (noise-free walls, exact
obstacle outlines) for the trace.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from .geometry import CACHED, clip_arrays
from .route import Route, distances, points_along, projected, projections
from .world import Robot

NO_OBSTACLE = 200.0     # in: the `obstacle` distance when nothing obstructs
INPUTS = ("road", "size", "position", "obstacle", "heading", "lane", "goal", "gap_left",
          "gap_right", "front", "opening", "clutter", "nearest")


@dataclass(frozen=True)
class Settings:
    lookahead: float = 40.0        # in: pure-pursuit point on the route, where the way is clear
    lookahead_min: float = 8.0     # in: the shortest lookahead of `heading` (a tight gap)
    lookahead_step: float = 4.0    # in: the lookaheads tried, from the shortest up
    lookahead_room: float = 1.5    # in: the chord to the route point keeps the route's least
                                   # clearance plus this from what the robot knows
    window: float = 24.0           # in: along-route half window for the road width
    sight: float = 150.0           # in: how far ahead objects count
    band_margin: float = 8.0       # in: added to each side of the swept band
    cluster: float = 30.0          # in: hits this close to the nearest belong to its object
    lane_margin: float = 6.0       # in: keep-right lane keeps this off the right wall
    road_cap: float = 100.0        # in: road width used for the lane at wide openings
    wall_behind: float = 12.0      # in
    wall_ahead: float = 36.0       # in
    way_margin: float = 1.5        # in: a way is free when this clears each side of the body
    way_room_weight: float = 0.1   # room counts this much beside progress (when all is shut)
    way_room: float = 4.0          # in: the roomier band a way is also scored in
    way_reach: float = 140.0       # in: a way clear this far (from the front) scores in full
    way_step: float = 5.0          # deg: the ways tried, every step within +-way_fov / 2
    way_fov: float = 180.0         # deg
    clutter_gap: float = 24.0      # in: neighbouring hits farther apart: two objects
    way_turn_cost: float = 0.05    # in of progress given up per deg turned from the heading
    nearest_cap: float = 60.0      # in: `nearest` when nothing is that close
    nearest_band: float = 10.0     # in: beside the body's band, echoes farther out do not count


@dataclass(frozen=True)
class Frame:
    """The robot on its route: arc length, lateral offset (right +), tangent, normal."""

    s: float
    e: float
    t: np.ndarray                  # unit tangent
    n: np.ndarray                  # unit normal to the right


def frame(route: Route, p: np.ndarray, s_hint: float) -> Frame:
    s, e, t = route.project(p, s_hint)
    return Frame(s, e, t, np.array([t[1], -t[0]]))


def frames(routes: list[Route], p: np.ndarray, hints: np.ndarray) -> list[Frame]:
    """:func:`frame` of every robot at once (``p [R, 2]``; runs in lockstep together), each
    the bits of its own (:func:`.route.projected`; the normals turned all at once)."""
    if len(routes) == 1:
        return [frame(routes[0], p[0], float(hints[0]))]
    s, e, t = projected(routes, p, hints)
    n = np.empty_like(t)
    n[:, 0], n[:, 1] = t[:, 1], -t[:, 0]
    return list(map(Frame, s, e, t, n))


def _or(least: np.ndarray, none: float, less: float | np.ndarray = 0.0) -> np.ndarray:
    """``least - less``, ``none`` where ``least`` is ``inf`` (no point: the points' values
    are finite)."""
    return np.where(least < np.inf, least - less, none)


def _obstruction(route: Route, a: np.ndarray, b: np.ndarray, points: np.ndarray, valid: np.ndarray,
                 widen: np.ndarray, robot: Robot, f: Frame,
                 cfg: Settings, rel_heading: tuple[np.ndarray, np.ndarray]) -> tuple[float, float, float]:
    """(size, position, distance) of the nearest obstructing object among ``points``
    (:func:`_obstruction_rows` of one row, kept clear of nothing)."""
    ah, bh = rel_heading
    size, position, distance = _obstruction_rows(
        [route], [f], a[None], b[None], points[None], valid[None], widen[None], cfg,
        ah[None], bh[None], np.zeros(1), np.zeros((1, len(a)), dtype=bool),
        np.full((1, len(a)), np.inf), _bodies((robot,), cfg))
    return float(size[0]), float(position[0]), float(distance[0])


def _obstruction_rows(routes: list[Route], frames: list[Frame], a: np.ndarray, b: np.ndarray,
                      points: np.ndarray, valid: np.ndarray, widen: np.ndarray,
                      cfg: Settings, ah: np.ndarray, bh: np.ndarray, least: np.ndarray, kept: np.ndarray,
                      gone: np.ndarray, body: dict[str, np.ndarray]
                                            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each row's ``(size, position, distance)`` of the nearest obstructing object among its
    ``points [R, K, 2]`` (``a``, ``b``: along and across its route; ``ah``, ``bh``: along and
    across its heading; ``least [R]``, ``kept [R, K]``: :attr:`Sights.least` and
    :attr:`Sights.kept`; ``gone [R, K]``: how far the points kept ahead lie from the route
    (:func:`_route_distances`); ``body``: the robots' :func:`_bodies`). A point obstructs when
    it lies in the band swept along the route or in the band swept along the robot's heading
    (so turning back toward an object it has not yet passed brings it back)."""
    size, position = np.zeros(len(routes)), np.zeros(len(routes))
    distance = np.full(len(routes), NO_OBSTACLE)
    ahead = valid & (a > 0) & (a < cfg.sight)
    if not np.count_nonzero(ahead):
        return size, position, distance
    blocking = ahead & (_in_band(b, widen, body["band"])
                        | ((ah > 0) & _in_band(bh, widen, body["band"])))
    if not np.count_nonzero(blocking):
        return size, position, distance
    # what the route was planned round obstructs only within its word
    rounds = blocking & kept
    some = np.logical_or.reduce(rounds, axis=1).nonzero()[0]
    if len(some):
        blocking[some] = np.where(rounds[some], gone[some] - widen[some] < least[some, None],
                                  blocking[some])
    rows = np.flatnonzero(np.logical_or.reduce(blocking, axis=1))
    if len(rows):
        distance[rows], size[rows], position[rows] = _objects(
            [routes[j] for j in rows.tolist()], [frames[j] for j in rows.tolist()], a[rows],
            points[rows], ahead[rows], blocking[rows], widen[rows], body["length"][rows, 0],
            cfg)
    return size, position, distance


def _in_band(b: np.ndarray, widen: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Whether points ``b`` across a line, each widened by ``widen`` on both sides, reach into
    the band ``half`` either side of it: ``b + widen > -half and b - widen < half``, which is
    ``|b| - widen < half`` bit for bit (``-(b + widen)`` is ``-b - widen`` exactly, and of
    ``b - widen`` and ``-b - widen`` the one from ``|b|`` is never the smaller)."""
    return np.abs(b) - widen < half


def _objects(routes: list[Route], frames: list[Frame], a: np.ndarray, points: np.ndarray,
             ahead: np.ndarray, blocking: np.ndarray, widen: np.ndarray,
             length: np.ndarray, cfg: Settings) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each row's distance, size and position of the object its nearest blocking point
    belongs to (the points ahead within ``cluster`` of it; ``length``: half the robots'
    lengths), all rows at once: the nearest points, the objects, their middles and their
    distances elementwise (exact minima; a middle is the sum of its points, added one after
    the other as ``np.mean`` of the row's alone adds them, divided by their count), where
    each object stands on its route in one :func:`.route.projections`, and how wide it is
    there in one stacked product of each row's points by its road's normal (each row's
    matrix-vector product, bit for bit). An object of one point is its own middle, so its
    offset is a zero whatever the product; it is still worked out as the one-point dot
    product it was (as :func:`_own_frames` does), so that even the sign of that zero is
    kept."""
    rows = np.arange(len(points))
    i = np.where(blocking, a, np.inf).argmin(axis=1)
    gap = points - points[rows, i][:, None]
    near = ahead & (np.hypot(gap[..., 0], gap[..., 1]) <= cfg.cluster)
    distance = np.minimum.reduce(a, axis=1, initial=np.inf, where=near) - length
    distance = np.where(distance > 0.0, distance, 0.0)              # max(0.0, distance)
    count = np.count_nonzero(near, axis=1)                             # [R], each at least 1
    centres = np.add.reduce(points, axis=1, where=near[..., None]) / count[:, None]
    hints = [f.s for f in frames]
    reach = cfg.sight + cfg.cluster
    # size and position across the road where the object stands (around a corner that is
    # the next leg of the route, not the robot's)
    where = ([routes[0].project(centres[0], hints[0], back=0.0, ahead=reach)]
             if len(routes) == 1 else projections(routes, centres, hints, 0.0, reach))
    t = np.array([t_o for _, _, t_o in where]).reshape(-1, 2)
    e_o = np.array([e for _, e, _ in where], dtype=float)[:, None]
    normal = np.empty((len(t), 2, 1))
    normal[:, 0, 0], normal[:, 1, 0] = t[:, 1], -t[:, 0]
    rel = points - centres[:, None]                                     # [R, K, 2]
    across = np.matmul(rel, normal)[..., 0]                             # rel @ normal, [R, K]
    lone = (count == 1).nonzero()[0]
    if len(lone):
        k = i[lone]                                 # (the nearest point is its object's)
        across[lone, k] = np.matmul(rel[lone, k][:, None], normal[lone])[:, 0, 0]
    across += e_o
    lo = np.minimum.reduce(across - widen, axis=1, initial=np.inf, where=near)
    hi = np.maximum.reduce(across + widen, axis=1, initial=-np.inf, where=near)
    return distance, hi - lo, (lo + hi) / 2


def _own_frame(rel: np.ndarray, heading: float) -> tuple[np.ndarray, np.ndarray]:
    """Points relative to the robot in its own frame: along the heading, and across it
    (positive to the right)."""
    c, s = math.cos(heading), math.sin(heading)
    return rel @ np.array([c, s]), rel @ np.array([s, -c])


def free_ways(ah: np.ndarray, bh: np.ndarray, widen: np.ndarray, unknown: np.ndarray,
              robot: Robot, cfg: Settings, route_bearing: float) -> tuple[float, float]:
    """``(front, opening)`` from points ``(ah, bh)`` in the robot's own frame (along and
    across its heading, right +) widened by ``widen`` (see the module docstring;
    :func:`free_ways_rows` of one row)."""
    front, opening = free_ways_rows(ah[None], bh[None], widen[None], unknown[None], [robot],
                                    cfg, np.array([route_bearing], dtype=float))
    return float(front[0]), float(opening[0])


def free_ways_rows(ah: np.ndarray, bh: np.ndarray, widen: np.ndarray, unknown: np.ndarray,
                   robots: list[Robot], cfg: Settings,
                   route_bearing: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each row's ``(front, opening)`` from its points ``[R, K]``. Every way tried is a
    direction from the robot's centre; its free length is the distance along it to the
    nearest point inside the body's band, less half the body's length. All at once:
    ``[rows, ways, points]``, one band after the other. A point at the robot's centre (``ah = bh = 0``, the
    padding of a row with fewer points) is ahead on no way."""
    return _free_ways(ah, bh, widen, unknown, _bodies(tuple(robots), cfg), cfg, route_bearing)


def _free_ways(ah: np.ndarray, bh: np.ndarray, widen: np.ndarray, unknown: np.ndarray,
               body: dict[str, np.ndarray], cfg: Settings,
               route_bearing: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`free_ways_rows` of robots whose :func:`_bodies` are ``body``, a block of rows
    at a time (:data:`CACHED`: a lockstep batch of hundreds of robots spills its
    ``[rows, ways, points]`` arrays out of a core's cache, which costs more than the calls
    the blocks repeat; each row's arithmetic is its own). Rows of finite points with more
    than ``CACHED / 8`` pairs of a way and a point go :func:`_free_ways_near`'s way when
    every way tried lies within 90 deg of the heading (as by default): its arrays are some
    four times smaller (blocks of four times the rows measured fastest), but it makes three
    times the calls, so fewer pairs (a robot alone with up to 210 beams at the default ways)
    go every point on every way, measured faster."""
    pairs = len(body["ways"]) * max(ah.shape[1], 1)
    near = (len(ah) * pairs > CACHED // 8 and ah.shape[1] > 0 and _near_ways(cfg)
            and bool(np.isfinite(ah + bh + widen).all()))
    block = _free_ways_near if near else _free_ways_block
    rows = max(1, (4 if near else 1) * CACHED // pairs)
    if len(ah) <= rows:
        return block(ah, bh, widen, unknown, body, cfg, route_bearing)
    parts = [block(ah[i:i + rows], bh[i:i + rows], widen[i:i + rows], unknown[i:i + rows],
                   {k: v if k == "ways" else v[i:i + rows] for k, v in body.items()},
                   cfg, route_bearing[i:i + rows])
             for i in range(0, len(ah), rows)]
    return np.concatenate([f for f, _ in parts]), np.concatenate([o for _, o in parts])


def _free_ways_block(ah: np.ndarray, bh: np.ndarray, widen: np.ndarray, unknown: np.ndarray,
                     body: dict[str, np.ndarray], cfg: Settings,
                     route_bearing: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_free_ways` of one block of rows, every point on every way."""
    ways = _ways_of(body, cfg, route_bearing)
    front, free = _free_along(ah, bh, widen, unknown, ways, body)
    return _opened(front, free, ways, body, cfg, route_bearing)


def _ways_of(body: dict[str, np.ndarray], cfg: Settings,
             route_bearing: np.ndarray) -> np.ndarray:
    """``[R, W]``: the ways each row tries (deg, :func:`_ways`), its route's bearing second."""
    ways = np.empty((len(route_bearing), len(body["ways"])))
    ways[:] = body["ways"]
    ways[:, 1] = clip_arrays(route_bearing, -cfg.way_fov / 2, cfg.way_fov / 2)
    return ways


def _free_along(ah: np.ndarray, bh: np.ndarray, widen: np.ndarray, unknown: np.ndarray,
                ways: np.ndarray, body: dict[str, np.ndarray]
                ) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray]]:
    """Along the first of ``ways [R, W]`` (straight on), the nearest of the ``unknown``
    points ``[R, K]`` ahead in the body's band; along each, the nearest of every point ahead
    in the body's band and in the roomier one, ``[R, W]`` each (``inf``: none)."""
    phi = np.deg2rad(ways)[..., None]
    cos, sin = np.cos(phi), np.sin(phi)
    ah, bh, widen = ah[:, None], bh[:, None], widen[:, None]
    along = ah * cos                                                       # [R, W, K]
    along += bh * sin
    across = bh * cos                   # -ah * sin + bh * cos, the same bits
    across -= ah * sin
    np.abs(across, out=across)
    across -= widen
    ahead = along > 0
    narrow = across < body["way"][..., None]       # the band just clear of the body
    narrow &= ahead
    roomy = across < body["roomy"][..., None]      # and the roomier one
    roomy &= ahead
    front = np.minimum.reduce(along[:, 0], axis=1, initial=np.inf, where=narrow[:, 0] & unknown)
    return front, (np.minimum.reduce(along, axis=2, initial=np.inf, where=narrow),
                   np.minimum.reduce(along, axis=2, initial=np.inf, where=roomy))


def _opened(front: np.ndarray, free: Iterable[np.ndarray], ways: np.ndarray,
            body: dict[str, np.ndarray], cfg: Settings,
            route_bearing: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(front, opening)`` from the nearest points ahead on each way in each band
    (:func:`_free_along`; written over): the progress each way offers toward the route's
    bearing (behind the robot: toward the side it lies on), in a band just clear of the body
    and in a roomy one, less a little for every degree turned; the way that offers the most."""
    length = body["length"]
    front = clip_arrays(front - length[:, 0], 0.0, cfg.sight)
    toward = clip_arrays(route_bearing, -90.0, 90.0)
    score = -cfg.way_turn_cost * np.abs(ways)
    weight = np.cos(np.deg2rad(ways - toward[:, None])) + cfg.way_room_weight
    for band in free:
        band -= length
        score += 0.5 * clip_arrays(band, 0.0, cfg.way_reach) * weight
    return front, ways[np.arange(len(ways)), score.argmax(axis=1)]


#: How far (deg) past the ways a point's band can reach (:func:`_free_ways_near`) a way is
#: still tried: far above the rounding of the angles, so a way left out is plainly clear.
_WAY_SLACK = 1e-2


def _free_ways_near(ah: np.ndarray, bh: np.ndarray, widen: np.ndarray, unknown: np.ndarray,
                    body: dict[str, np.ndarray], cfg: Settings,
                    route_bearing: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_free_ways_block` trying each point (finite) only on the ways its bands may
    reach: straight on and the route's bearing every point, each of the ``way_step`` grid
    only the points within ``asin(reach / distance)`` (``reach``: the roomier band and the
    point's widening) of its bearing and :data:`_WAY_SLACK`: some one in nine. A point left
    out is farther than ``reach`` from that way, or behind the robot on it, by far more than
    rounding, so every band holds the points it held and each minimum is the same (the
    products each a pair's own, elementwise)."""
    ways = _ways_of(body, cfg, route_bearing)
    front, two = _free_along(ah, bh, widen, unknown, ways[:, :2], body)
    free = np.empty((2, *ways.shape))
    free[..., :2] = two
    free[..., 2:] = _grid_free(ah, bh, widen, body, cfg)
    return _opened(front, free, ways, body, cfg, route_bearing)


def _grid_free(ah: np.ndarray, bh: np.ndarray, widen: np.ndarray, body: dict[str, np.ndarray],
               cfg: Settings) -> np.ndarray:
    """``[2, R, G]``: :func:`_free_along` of the ``way_step`` grid of ways (``G`` of them), each
    point on the ways its bands may reach (:func:`_free_ways_near`): the pairs listed point by
    point, their distances along and across worked out as :func:`_free_along` does, and
    the least of those in a band kept for each row and way (``np.minimum.at``, exact: a
    table of each row's points by way, filled and then reduced, measured slower)."""
    grid = body["ways"][2:]
    cos, sin = _grid_trig(cfg)
    rows, g = len(ah), len(grid)
    far = np.hypot(ah, bh)
    reach = np.maximum(body["way"], body["roomy"]) + widen
    bearing = np.degrees(np.arctan2(bh, ah)) - grid[0]
    with np.errstate(divide="ignore", invalid="ignore"):        # (at the centre: not tried)
        half = np.degrees(np.arcsin(clip_arrays(reach / far, 0.0, 1.0)))
        lo = np.floor((bearing - half - _WAY_SLACK) / cfg.way_step)
        hi = np.floor((bearing + half + _WAY_SLACK) / cfg.way_step) + 1.0
        first = clip_arrays(lo, 0, g).astype(np.intp)
        count = clip_arrays(hi, 0, g).astype(np.intp) - first
    count[far == 0.0] = 0                          # at the robot's centre: ahead on no way
    table = np.full((2, rows * g), np.inf)
    each = np.add.reduce(count, axis=1)            # the pairs of each row, one row after another
    count = count.ravel()
    pairs = int(each.sum())
    if pairs:
        j = np.arange(pairs) - np.repeat(np.cumsum(count) - count - first.ravel(), count)
        at = j + np.repeat(np.arange(0, rows * g, g), each)
        a, b = np.repeat(ah.ravel(), count), np.repeat(bh.ravel(), count)
        c, s = cos[j], sin[j]
        along = a * c
        along += b * s
        across = b * c
        across -= a * s
        np.abs(across, out=across)
        across -= np.repeat(widen.ravel(), count)
        ahead = along > 0
        for out, band in zip(table, (body["way"], body["roomy"])):
            inside = across < np.repeat(band[:, 0], each)
            inside &= ahead
            np.minimum.at(out, at[inside], along[inside])
    return table.reshape(2, rows, g)


@functools.lru_cache(maxsize=8)
def _near_ways(cfg: Settings) -> bool:
    """Whether :func:`_free_ways_near` serves: an even grid of ways within 90 deg of the
    heading (the ways near a point's bearing are then found without going round behind)."""
    grid = _ways(cfg)[2:]
    return bool(cfg.way_step > 0 and len(grid) and np.abs(grid).max() <= 90.0)


@functools.lru_cache(maxsize=8)
def _grid_trig(cfg: Settings) -> tuple[np.ndarray, np.ndarray]:
    """The cosines and sines of the ``way_step`` grid of ways (:func:`_ways`)."""
    phi = np.deg2rad(_ways(cfg)[2:])
    cos, sin = np.cos(phi), np.sin(phi)
    cos.flags.writeable = sin.flags.writeable = False
    return cos, sin


@functools.lru_cache(maxsize=8)
def _ways(cfg: Settings) -> np.ndarray:
    """The ways :func:`free_ways` tries: straight on, the route's bearing (a place for it),
    then every ``way_step`` within ``way_fov``."""
    n = int(round(cfg.way_fov / 2 / cfg.way_step))
    out = np.concatenate([[0.0, 0.0], np.arange(-n, n + 1) * cfg.way_step])
    out.flags.writeable = False
    return out


def nearest(ah: np.ndarray, bh: np.ndarray, robot: Robot, cfg: Settings) -> float:
    """The gap from the footprint (a ``length`` x ``width`` rectangle on the pose) to the
    nearest of the points ``(ah, bh)`` (the robot's own frame) ahead of its centre and within
    ``nearest_band`` of the band its body sweeps straight on (the walls of a corridor it
    drives down do not count; a jamb it is about to pass, or a pole by its corner, do)."""
    return float(nearest_rows(ah[None], bh[None], [robot], cfg)[0])


def nearest_rows(ah: np.ndarray, bh: np.ndarray, robots: list[Robot],
                 cfg: Settings) -> np.ndarray:
    """:func:`nearest` of every row of points ``[R, K]`` (a point at the robot's centre, the
    padding, is not ahead)."""
    return _nearest(ah, bh, _bodies(tuple(robots), cfg), cfg)


def _nearest(ah: np.ndarray, bh: np.ndarray, body: dict[str, np.ndarray],
             cfg: Settings) -> np.ndarray:
    """:func:`nearest_rows` of robots whose :func:`_bodies` are ``body``."""
    half, band, length = body["half"], body["near"], body["length"]
    across = np.abs(bh)
    ahead = (ah > 0) & (across < band)
    dx = np.maximum(ah - length, 0.0)
    dy = np.maximum(across - half, 0.0)
    gap = np.minimum.reduce(np.hypot(dx, dy), axis=1, initial=np.inf, where=ahead)
    return np.where(cfg.nearest_cap < gap, cfg.nearest_cap, gap)      # min(gap, cap): the
                                                                       # cap with none ahead


def clutter(hits: np.ndarray, unknown: np.ndarray, ah: np.ndarray, cfg: Settings,
            circular: bool = False) -> float:
    """How many separate objects the map does not show are in view ahead: runs of
    neighbouring points (in beam order; ``circular`` for a ring, whose last beam neighbours
    its first) that hit obstacles ahead within ``sight``, a run split where two neighbours
    lie more than ``clutter_gap`` apart."""
    return float(clutter_rows(hits[None], unknown[None], ah[None], cfg,
                              np.array([circular]))[0])


def clutter_rows(hits: np.ndarray, unknown: np.ndarray, ah: np.ndarray, cfg: Settings,
                 circular: np.ndarray) -> np.ndarray:
    """:func:`clutter` of every row of points ``[R, K, 2]`` (``circular [R]``)."""
    seen = unknown & (ah > 0) & (ah <= cfg.sight)
    if not np.count_nonzero(seen):
        return np.zeros(len(seen))
    before = _previous(hits.shape[1])              # np.roll(..., 1), cheaper
    gap = hits - hits[:, before]
    close = np.hypot(gap[..., 0], gap[..., 1]) <= cfg.clutter_gap
    joined = seen & seen[:, before] & close        # point i continues the run of point i - 1
    joined[:, 0] &= circular
    count = np.count_nonzero(seen & ~joined, axis=1)
    return np.where(np.logical_or.reduce(seen, axis=1), np.maximum(count, 1), 0).astype(float)


@functools.lru_cache(maxsize=8)
def _previous(k: int) -> np.ndarray:
    """Index of the point before each of ``k`` (the last before the first)."""
    out = (np.arange(k) - 1) % k
    out.flags.writeable = False
    return out


def _sides(a: np.ndarray, b: np.ndarray, ah: np.ndarray, bh: np.ndarray, valid: np.ndarray,
           walls: np.ndarray, body: dict[str, np.ndarray], cfg: Settings, far: float,
           objects: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``road``, ``gap_left`` and ``gap_right`` of every row of points ``[R, K]``, given in the
    route's frame (``a``, ``b``) and in the robot's own (``ah``, ``bh``; ``body``: the
    robots' :func:`_bodies`); ``walls``: the points the road is measured to, ``objects``:
    those that count for the side gaps only while beside the body.

    The route's frame says which side a point is on and whether it is near enough (as
    before); how far it is does not lean with the route, which on a short leg across a
    corridor (to a goal off its middle, or a replanned one) lies 45 deg off the walls: the
    road is the distance from the robot's centre to the nearest wall point on its left plus
    that on its right (the nearest point of a straight wall is its foot, whatever the
    direction), and a side gap the distance from the body's long axis (a segment half its
    length each way from the centre) less half its width, at least 0 (a point by the nose of
    a robot turned across its route): across the body beside it, from its front or rear end
    past it. A robot parallel to walls parallel to its route gets the distances across the
    route, as before."""
    over = np.abs(ah) - body["length"]
    side = np.abs(bh)
    axis = np.where(over > 0, np.hypot(over, side), side)      # from the body's long axis
    centre = np.hypot(ah, bh)
    ahead = cfg.wall_ahead if objects is None else np.where(objects, body["length"],
                                                            cfg.wall_ahead)
    near = valid & (a >= -cfg.wall_behind) & (a <= ahead) & (np.abs(b) >= body["half"])
    sides = np.array([b < 0, b > 0])                                   # [2, R, K]: left, right
    # both sides at once, each row's least (exact) of its points on that side
    road = np.minimum.reduce(np.broadcast_to(centre, sides.shape), axis=-1, initial=np.inf,
                             where=sides & (walls & (np.abs(a) <= cfg.window)))
    gaps = np.minimum.reduce(np.broadcast_to(axis, sides.shape), axis=-1, initial=np.inf,
                             where=sides & near)
    road = _or(road, far)
    gaps = np.maximum(_or(gaps, far, body["half"][:, 0]), 0.0)
    return road[0] + road[1], gaps[0], gaps[1]


def _common(route: Route, p: np.ndarray, heading: float, f: Frame, road: float, robot: Robot,
            cfg: Settings, target: np.ndarray, room: float) -> tuple[float, float, float]:
    d = target - p
    return _common_of(float(d[0]), float(d[1]), heading, route.length - f.s, f.e,
                      float(np.hypot(*(route.goal - p))), road, robot, cfg, room)


def _common_of(dx: float, dy: float, heading: float, left: float, e: float, home: float,
               road: float, robot: Robot, cfg: Settings,
               room: float) -> tuple[float, float, float]:
    """:func:`_common` from the target's offset ``(dx, dy)``, the route ``left`` ahead, the
    offset ``e`` off it and the straight distance ``home`` to the goal (Python floats: the
    rows' differences and distances are worked out together, then these row by row)."""
    bearing = math.degrees(math.atan2(dy, dx) - heading)
    bearing = (bearing + 180.0) % 360.0 - 180.0
    road_l = min(road, cfg.road_cap)
    offset = max(0.0, min(road_l / 4, road_l / 2 - robot.width / 2 - cfg.lane_margin, room))
    return -bearing, e - offset, max(left, home)


def clear_lookahead(route: Route, f: Frame, p: np.ndarray, cells: np.ndarray, radius: float,
                    need: float, cfg: Settings) -> float:
    """How far ahead the point ``heading`` aims at lies: the farthest of the lookaheads from
    ``lookahead_min`` to ``lookahead`` (every ``lookahead_step``) such that the straight line
    from the robot to that route point, and to every nearer one, keeps ``need`` inches from
    the occupied ``cells [P, 2]`` (discs of ``radius``): what the robot knows is there. A
    pure-pursuit point farther ahead than the way is straight cuts the corner the route
    bends round (into a door jamb, a pole the route squeezes past); where the way is clear it
    lies at ``lookahead`` and the robot drives smoothly."""
    return pursuit_point(route, f, p, cells, radius, need, cfg)[0]


@dataclass(frozen=True)
class Aim:
    """What a robot's pursuit point is found from (:func:`pursuit_points`): its route, where
    it is on it, its place ``p``, and the occupied cells ``[P, 2]`` (discs of ``radius``) the
    way to the point keeps ``need`` inches from."""

    route: Route
    f: Frame
    p: np.ndarray
    cells: np.ndarray
    radius: float
    need: float


def pursuit_point(route: Route, f: Frame, p: np.ndarray, cells: np.ndarray, radius: float,
                  need: float, cfg: Settings) -> tuple[float, np.ndarray]:
    """:func:`clear_lookahead` and the route point that far ahead (:func:`target_point`)."""
    ahead, target = pursuit_points([Aim(route, f, p, cells, radius, need)], cfg)
    return float(ahead[0]), target[0]


#: Where a row with fewer cells than the others has its padding: far from every route, so
#: never the nearest (a row with no cells at all is not measured).
_FAR = 1e12


def pursuit_points(aims: list[Aim], cfg: Settings, *,
                   padded: tuple[np.ndarray, np.ndarray] | None = None
                   ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`pursuit_point` of every robot at once (runs in lockstep, each robot with its
    own route and cells): the lookaheads ``[R]`` and the points ``[R, 2]``. Only the cells
    near a robot's chords are measured (:func:`_near_chords`: mostly none, and then every
    chord is clear); they are padded far away and every product is written out
    elementwise, so a robot gets the bits it gets alone, in any batch. ``padded``: the
    aims' :func:`padded_cells`, where the caller has them (runs in lockstep ask this and
    :func:`route_gaps` of the same aims)."""
    ahead = _lookaheads(cfg)
    if len(aims) == 1:
        one, target = _pursuit_one(aims[0], ahead, cfg)
        return np.array([one]), target[None]
    out_ahead = np.full(len(aims), float(ahead[-1]))
    targets = np.empty((len(aims), 2))
    sizes, cells = padded_cells(aims) if padded is None else padded
    for i in np.flatnonzero(sizes == 0).tolist():
        targets[i] = target_point(aims[i].route, aims[i].f, cfg, float(ahead[-1]))
    have_i = np.flatnonzero(sizes)
    if not len(have_i):
        return out_ahead, targets
    have = aims if len(have_i) == len(aims) else [aims[i] for i in have_i.tolist()]
    q = _targets(have, ahead)                                                 # [H, J, 2]
    targets[have_i] = q[:, -1]                                  # where every chord is clear
    p = np.array([a.p for a in have])                                         # [H, 2]
    near = _near_chords(cells, p, q, np.array([a.need + a.radius for a in have]))
    some = np.logical_or.reduce(near, axis=1).nonzero()[0]
    if not len(some):
        return out_ahead, targets
    # the rows with cells near their chords, those cells first in their order (picked out
    # by the mask, set in by another; no sort), the others padded far away
    near, q, p = near[some], q[some], p[some, None]                           # p [S, 1, 2]
    count = np.add.reduce(near, axis=1)
    rel = np.full((len(some), int(count.max()), 2), _FAR)
    rel[np.arange(rel.shape[1]) < count[:, None]] = cells[some][near]
    rel -= p                                                                  # [S, P, 2]
    e = q - p
    ee = np.maximum(e[..., 0] * e[..., 0] + e[..., 1] * e[..., 1], 1e-12)     # [S, J]
    rx, ry = rel[..., 0, None], rel[..., 1, None]                             # [S, P, 1]
    ex, ey = e[:, None, :, 0], e[:, None, :, 1]                               # [S, 1, J]
    t = clip_arrays((rx * ex + ry * ey) / ee[:, None], 0.0, 1.0)              # [S, P, J]
    clear = _clear_of(rx - t * ex, ry - t * ey,
                      np.array([have[j].radius for j in some])[:, None],
                      np.array([have[j].need for j in some])[:, None])       # [S, J]
    k = np.where(clear.all(axis=1), len(ahead) - 1, np.maximum(clear.argmin(axis=1) - 1, 0))
    rows = have_i[some]
    out_ahead[rows] = ahead[k]
    targets[rows] = q[np.arange(len(some)), k]
    return out_ahead, targets


def _pursuit_one(a: Aim, ahead: np.ndarray, cfg: Settings) -> tuple[float, np.ndarray]:
    """:func:`pursuit_points` of one robot, with no batch to set up (the same arithmetic)."""
    if not len(a.cells):
        return float(ahead[-1]), target_point(a.route, a.f, cfg, float(ahead[-1]))
    q = target_points(a.route, a.f, ahead)                                    # [J, 2]
    near = _near_chords(a.cells[None], a.p[None], q[None], np.array([a.need + a.radius]))[0]
    if not np.count_nonzero(near):
        return float(ahead[-1]), q[-1]
    e = q - a.p
    ee = np.maximum(e[:, 0] * e[:, 0] + e[:, 1] * e[:, 1], 1e-12)
    rel = a.cells[near] - a.p                                                 # [P, 2]
    rx, ry = rel[:, 0, None], rel[:, 1, None]
    t = clip_arrays((rx * e[:, 0] + ry * e[:, 1]) / ee, 0.0, 1.0)             # [P, J]
    clear = _clear_of((rx - t * e[:, 0])[None], (ry - t * e[:, 1])[None],
                      np.full((1, 1), a.radius), np.full((1, 1), a.need))[0]
    if np.count_nonzero(clear) == clear.size:
        return float(ahead[-1]), q[-1]
    k = max(int(clear.argmin()) - 1, 0)
    return float(ahead[k]), q[k]


def _near_chords(cells: np.ndarray, p: np.ndarray, q: np.ndarray,
                 reach: np.ndarray) -> np.ndarray:
    """``[H, P]``: which ``cells [H, P, 2]`` are not plainly clear of every chord from
    ``p [H, 2]`` to the points ``q [H, J, 2]``: those in the box round the chords grown by
    ``reach [H]`` (the need plus the discs' radius) and a margin far above rounding. A cell
    outside it is farther than ``reach`` from every chord, so it never decides whether a
    chord is clear, and leaving it out gives every chord the same answer (a NaN is kept)."""
    ends = np.concatenate([q, p[:, None]], axis=1)                            # [H, J + 1, 2]
    grow = (reach + 1e-6 * (1.0 + np.abs(reach)
                            + np.maximum.reduce(np.abs(ends), axis=(1, 2))))[:, None]
    lo = np.minimum.reduce(ends, axis=1) - grow                               # [H, 2]
    hi = np.maximum.reduce(ends, axis=1) + grow
    x, y = cells[..., 0], cells[..., 1]           # (a coordinate at a time: long inner loops)
    out = x < lo[:, :1]
    out |= x > hi[:, :1]
    out |= y < lo[:, 1:]
    out |= y > hi[:, 1:]
    return ~out


#: How far (relative) a chord's clearance from the squares of the gaps may lie off the one
#: from ``np.hypot`` (a few rounding errors, ~1e-15) before :func:`_clear_of` asks hypot.
_ROUNDING = 1e-9


def _clear_of(dx: np.ndarray, dy: np.ndarray, radius: np.ndarray,
              need: np.ndarray) -> np.ndarray:
    """``np.hypot(dx, dy).min(axis=1) - radius >= need`` (gaps ``[H, P, J]``, ``radius`` and
    ``need`` ``[H, 1]``): whether each chord ``[H, J]`` keeps ``need`` from every disc. The
    least gap is found from the squares (``np.hypot`` costs some 30 times a product); only a
    chord whose answer lies within rounding of the line (or is NaN) is measured with hypot,
    so each answer is the plain formula's."""
    with np.errstate(over="ignore"):            # a square past 1e308 is asked of hypot
        squares = dx * dx
        squares += dy * dy
    least = np.sqrt(np.minimum.reduce(squares, axis=1))                      # [H, J]
    over = least - radius - need
    band = _ROUNDING * (least + np.abs(radius) + np.abs(need)) + 1e-100     # tiny: underflow
    clear = over > band
    unsure = ~(clear | (over < -band))
    if np.count_nonzero(unsure):
        h, j = unsure.nonzero()
        clear[h, j] = np.hypot(dx[h, :, j], dy[h, :, j]).min(axis=1) - radius[h, 0] >= need[h, 0]
    return clear


def route_room(f: Frame, p: np.ndarray, cells: np.ndarray, radius: float,
               least: float) -> float:
    """How far the robot may stray from its route where it stands before its body comes
    within its least clearance of what it knows: the distance from the route point beside
    it to the nearest occupied cell (``cells [P, 2]``, discs of ``radius``) less ``least``
    (at least 0; ``inf`` with nothing known near)."""
    return max(0.0, _route_gap(f, p, cells) - radius - least)


def _route_gap(f: Frame, p: np.ndarray, cells: np.ndarray) -> float:
    """The distance from the route point beside the robot to the nearest of ``cells``
    (``inf`` with none): :func:`route_room` before its radius and least clearance."""
    if not len(cells):
        return math.inf
    c = p - f.e * f.n
    return float(np.hypot(*(cells - c).T).min())


def route_gaps(aims: list[Aim], *,
               padded: tuple[np.ndarray, np.ndarray] | None = None) -> list[float]:
    """:func:`_route_gap` of every robot's :class:`Aim` at once (runs in lockstep together):
    the cells padded far away, the distances elementwise and their minima exact, so each
    robot gets the bits it gets alone. ``padded``: as :func:`pursuit_points` takes it."""
    if len(aims) == 1:
        return [_route_gap(aims[0].f, aims[0].p, aims[0].cells)]
    out = np.full(len(aims), math.inf)
    sizes, cells = padded_cells(aims) if padded is None else padded
    have_i = np.flatnonzero(sizes)
    if not len(have_i):
        return out.tolist()
    have = aims if len(have_i) == len(aims) else [aims[i] for i in have_i.tolist()]
    c = (np.array([a.p for a in have])
         - np.array([a.f.e for a in have])[:, None] * np.array([a.f.n for a in have]))
    out[have_i] = np.minimum.reduce(np.hypot(cells[..., 0] - c[:, :1], cells[..., 1] - c[:, 1:]),
                                    axis=1)                    # (a coordinate at a time)
    return out.tolist()


def padded_cells(aims: list[Aim]) -> tuple[np.ndarray, np.ndarray]:
    """How many cells each of ``aims`` has ``[R]``, and the cells of those with some
    ``[H, P, 2]``: each row's own, then padding :data:`_FAR` away (row by row: a slice
    costs less than a mask of them all)."""
    cells = [a.cells for a in aims]
    sizes = list(map(len, cells))
    have = [i for i, n in enumerate(sizes) if n]
    out = np.full((len(have), max(sizes, default=0), 2), _FAR)
    for row, i in zip(out, have):
        row[:sizes[i]] = cells[i]
    return np.array(sizes, dtype=np.intp), out


@functools.lru_cache(maxsize=8)
def _lookaheads(cfg: Settings) -> np.ndarray:
    """The lookaheads :func:`clear_lookahead` tries, shortest first."""
    out = np.arange(cfg.lookahead_min, cfg.lookahead + 1e-9, cfg.lookahead_step)
    out.flags.writeable = False
    return out


def target_points(route: Route, f: Frame, ahead: np.ndarray) -> np.ndarray:
    """:func:`target_point` for every lookahead of ``ahead [J]`` at once, ``[J, 2]``."""
    s = f.s + ahead
    out = route.points_at(s)
    out[s >= route.length] = route.goal
    return out


def _targets(aims: list[Aim], ahead: np.ndarray) -> np.ndarray:
    """:func:`target_points` of every robot at once, ``[H, J, 2]`` (:func:`.route.points_along`:
    each the bits of its own)."""
    s = np.array([a.f.s for a in aims])[:, None] + ahead
    out = points_along([a.route for a in aims], s)
    past = s >= np.array([a.route.length for a in aims])[:, None]
    rows = np.flatnonzero(np.logical_or.reduce(past, axis=1))
    for i in rows:
        out[i, past[i]] = aims[i].route.goal
    return out


def target_point(route: Route, f: Frame, cfg: Settings,
                 lookahead: float | None = None) -> np.ndarray:
    """The pursuit point: on the route a lookahead ahead; the goal itself over the last
    lookahead of the route."""
    ahead = cfg.lookahead if lookahead is None else lookahead
    if f.s + ahead >= route.length:
        return route.goal
    return route.point_at(f.s + ahead)


def perceive(route: Route, f: Frame, pose: tuple[float, float, float], robot: Robot,
             dirs: np.ndarray, measured: np.ndarray, expected: np.ndarray, max_range: float,
             spacing: float, threshold: float, cfg: Settings = Settings(),
             lookahead: float | None = None, room: float = math.inf,
             kept: tuple[float, np.ndarray] | None = None,
             target: np.ndarray | None = None, squeeze: float = math.inf) -> dict[str, float]:
    """The inputs from one robot's readings (see the module docstring); ``lookahead``: of
    ``heading`` (:func:`clear_lookahead`; default ``cfg.lookahead``); ``room``: how far the
    keep-right lane may lie off the route (:func:`route_room`); ``kept``: where the route is
    replanned round what the robot senses, the least clearance it keeps and which readings
    hit what it was planned round (``[B]``): those obstruct only within that clearance of
    the route, not anywhere in the band ahead; ``target``: the route point ``lookahead``
    ahead (:func:`target_point`), when the caller has it; ``squeeze``: where the world lets
    the route pass closer to what is drawn than half the robot's width and its margin
    (``route: {min_clearance}``), the least clearance the route keeps: what is drawn obstructs
    only nearer the route than that, by the news ``threshold`` (and at least half as near:
    a squeeze of a few inches still has a middle), so the walls of the squeeze the route chose
    are not an obstacle in its middle. (:func:`perceive_rows` of one.)"""
    ahead = cfg.lookahead if lookahead is None else lookahead
    if target is None:
        target = target_point(route, f, cfg, ahead)
    sight = Sight(route, f, (float(pose[0]), float(pose[1]), float(pose[2])), robot, dirs,
                  measured, expected, spacing, threshold, ahead, room, kept, target, squeeze)
    out = perceive_rows([sight], max_range, cfg)
    return {key: float(value[0]) for key, value in out.items()}


@dataclass
class Sight:
    """What one robot perceives from at one tick (:func:`perceive_rows`)."""

    route: Route
    f: Frame
    pose: tuple[float, float, float]   # x, y (in), heading (rad)
    robot: Robot
    dirs: np.ndarray               # [B, 2] its beams
    measured: np.ndarray           # [B] its readings
    expected: np.ndarray           # [B] what its map predicts
    spacing: float                 # its beams' spacing (an echo is widened by half of it)
    threshold: float               # in: a reading this much shorter than expected is news
    lookahead: float               # of ``heading`` (:func:`clear_lookahead`)
    room: float                    # how far the lane may lie off the route (:func:`route_room`)
    kept: tuple[float, np.ndarray] | None   # see :func:`perceive`
    target: np.ndarray             # [2] the route point ``lookahead`` ahead
    squeeze: float = math.inf      # see :func:`perceive`


@dataclass
class Sights:
    """What robots perceive from at one tick, a row each (:func:`perceive_all`): the arrays
    of their :class:`Sight` one above the other (:meth:`of`), or made so at once (runs in
    lockstep make theirs from the arrays that hold all their robots' rows)."""

    routes: list[Route]
    frames: list[Frame]
    robots: list[Robot]
    pose: np.ndarray               # [R, 3] x, y (in), heading (rad)
    dirs: np.ndarray               # [R, B, 2] their beams
    measured: np.ndarray           # [R, B] their readings
    expected: np.ndarray           # [R, B] what their maps predict
    spacing: np.ndarray            # [R] their beams' spacing
    threshold: np.ndarray          # [R] in: news thresholds
    room: np.ndarray               # [R] how far each lane may lie off its route
    least: np.ndarray              # [R] the least clearance each route is replanned with
    kept: np.ndarray               # [R, B] readings that hit what its route was planned round
    # (a Sight's ``kept``; all False where its route is not replanned round what it senses)
    target: np.ndarray             # [R, 2] the route points ``lookahead`` ahead
    squeeze: np.ndarray            # [R] see :func:`perceive`

    @classmethod
    def of(cls, rows: list[Sight]) -> Sights:
        """The rows of ``rows``, one above the other."""
        kept = [r.kept for r in rows]
        beams = len(rows[0].measured)
        return cls([r.route for r in rows], [r.f for r in rows], [r.robot for r in rows],
                   np.array([r.pose for r in rows]), _stack([r.dirs for r in rows]),
                   _stack([r.measured for r in rows]), _stack([r.expected for r in rows]),
                   np.array([r.spacing for r in rows]), np.array([r.threshold for r in rows]),
                   np.array([r.room for r in rows]),
                   np.array([0.0 if k is None else k[0] for k in kept]),
                   np.array([np.zeros(beams, dtype=bool) if k is None else k[1] for k in kept]
                            ).reshape(len(rows), beams),
                   np.array([r.target for r in rows]), np.array([r.squeeze for r in rows]))


def perceive_rows(rows: list[Sight], max_range: float,
                  cfg: Settings = Settings()) -> dict[str, np.ndarray]:
    """The inputs of every row (``[R]`` each, :data:`INPUTS`), each row's the bits of
    :func:`perceive` for that robot alone (:func:`perceive_all` of their :class:`Sights`)."""
    return perceive_all(Sights.of(rows), max_range, cfg)


def perceive_all(rows: Sights, max_range: float,
                 cfg: Settings = Settings()) -> dict[str, np.ndarray]:
    """The inputs of every row of ``rows`` (``[R]`` each, :data:`INPUTS`), each row's the
    bits of :func:`perceive` for that robot alone: the beams' arithmetic over ``[R, B]``
    arrays, elementwise, with exact minima; what depends on a row's route or its map row
    by row."""
    robots = rows.robots
    body = _bodies(tuple(robots), cfg)
    p = rows.pose[:, :2]                                                # [R, 2]
    dirs, measured = rows.dirs, rows.measured
    hits = p[:, None] + measured[..., None] * dirs                      # [R, B, 2]
    rel = hits - p[:, None]
    a = np.matmul(rel, _stack([f.t for f in rows.frames])[..., None])[..., 0]   # rel @ f.t
    b = np.matmul(rel, _stack([f.n for f in rows.frames])[..., None])[..., 0]
    valid = measured < max_range * 0.999
    obstacle_hit = valid & (measured < rows.expected - rows.threshold[:, None])
    known = valid ^ obstacle_hit        # valid & ~obstacle_hit (which lies within valid)
    headings = rows.pose[:, 2].tolist()
    all_ah, all_bh, valid_ah, valid_bh = _own_frames(headings, rel, valid)
    road, wl, wr = _sides(a, b, valid_ah, valid_bh, valid, known, body, cfg, max_range,
                          obstacle_hit)
    widen = measured * rows.spacing[:, None] / 2
    ahead = a > 0
    drawn = known & ahead
    gone = _route_distances(rows, drawn | (obstacle_hit & rows.kept & ahead), hits, cfg)
    obstructing = obstacle_hit | _in_way(rows, drawn, gone, body)
    if np.count_nonzero(obstructing):
        ah, bh = all_ah, all_bh
    else:                       # what does not obstruct is not asked where it lies
        ah, bh = valid_ah, valid_bh
    size, position, distance = _obstruction_rows(
        rows.routes, rows.frames, a, b, hits, obstructing, widen, cfg, ah, bh,
        rows.least, rows.kept, gone, body)
    heading, lane, goal, pursued = _steering(rows, p, road, body, cfg)
    front, opening = _free_ways(valid_ah, valid_bh, widen, obstacle_hit, body, cfg, heading)
    ring = _rings(dirs)
    return {"road": road, "size": size, "position": position, "obstacle": distance,
            "heading": pursued, "lane": lane, "goal": goal, "gap_left": wl, "gap_right": wr,
            "front": front, "opening": opening,
            "clutter": clutter_rows(hits, obstacle_hit, ah, cfg, ring),
            "nearest": _nearest(valid_ah, valid_bh, body, cfg)}


def _steering(rows: Sights, p: np.ndarray, road: np.ndarray, body: dict[str, np.ndarray],
              cfg: Settings) -> tuple[np.ndarray, ...]:
    """Each row's route bearing, ``lane``, ``goal`` and ``heading`` (its :func:`_common`
    and :func:`pursuit`): the differences and distances of all rows at once, then those of
    a robot alone in Python floats (:func:`_common_of`, :func:`_pursuit_of`: arrays of one
    cost more), of a batch as arrays (:func:`_common_rows`, :func:`_pursuit_rows`)."""
    d = rows.target - p                                                 # to the targets
    home = np.array([r.goal for r in rows.routes]) - p                  # to the goals
    home = np.hypot(home[:, 0], home[:, 1])
    far = np.hypot(d[:, 0], d[:, 1])
    if len(p) == 1:
        r, f = rows.routes[0], rows.frames[0]
        one = _common_of(float(d[0, 0]), float(d[0, 1]), float(rows.pose[0, 2]), r.length - f.s,
                         f.e, float(home[0]), float(road[0]), rows.robots[0], cfg,
                         float(rows.room[0]))
        out = np.array([*one, _pursuit_of(one[0], float(far[0]), cfg)])[:, None]
        return out[0], out[1], out[2], out[3]
    left = np.array([r.length for r in rows.routes]) - np.array([f.s for f in rows.frames])
    bearing, lane, goal = _common_rows(d[:, 0], d[:, 1], rows.pose[:, 2], left,
                                       np.array([f.e for f in rows.frames]), home, road,
                                       body["half"][:, 0], cfg, rows.room)
    return bearing, lane, goal, _pursuit_rows(bearing, far, cfg)


def _common_rows(dx: np.ndarray, dy: np.ndarray, heading: np.ndarray, left: np.ndarray,
                 e: np.ndarray, home: np.ndarray, road: np.ndarray, half: np.ndarray,
                 cfg: Settings, room: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_common_of` of every row (``[R]`` each; ``half``: half the robots' widths), each
    row's bits: the angle from :func:`math.atan2` row by row, the rest elementwise (NumPy's
    degrees and remainder are Python's; each ``min`` and ``max`` as Python picks)."""
    angle = np.fromiter(map(math.atan2, dy.tolist(), dx.tolist()), float, len(dx))
    with np.errstate(invalid="ignore"):                         # (NaN stays NaN, as in Python)
        bearing = np.remainder(np.degrees(angle - heading) + 180.0, 360.0) - 180.0
    road_l = _least(road, cfg.road_cap)
    offset = _least(_least(road_l / 4, road_l / 2 - half - cfg.lane_margin), room)
    offset = np.where(offset > 0.0, offset, 0.0)                        # max(0.0, offset)
    return -bearing, e - offset, np.where(home > left, home, left)      # max(left, home)


def _least(a: np.ndarray, b: float | np.ndarray) -> np.ndarray:
    """Python's ``min(a, b)`` elementwise: ``b`` only where it is less than ``a``."""
    return np.where(b < a, b, a)


def _pursuit_rows(bearing: np.ndarray, distance: np.ndarray, cfg: Settings) -> np.ndarray:
    """:func:`_pursuit_of` of every row (``[R]`` each), each row's bits: the sines from
    :mod:`math` row by row, the rest elementwise (NumPy's radians and degrees are Python's)."""
    out = bearing.copy()
    turn = np.flatnonzero(~(np.abs(bearing) >= 90.0))
    if len(turn):
        b, far = bearing[turn], distance[turn]
        sine = np.fromiter(map(math.sin, np.radians(np.abs(b)).tolist()), float, len(turn))
        sine = cfg.lookahead / np.where(far < 1e-9, 1e-9, far) * sine  # max(distance, 1e-9)
        sine = np.where(sine < 1.0, sine, 1.0)                          # min(1.0, sine)
        out[turn] = np.copysign(np.degrees(np.fromiter(map(math.asin, sine.tolist()), float,
                                                       len(turn))), b)
    return out


def _rings(dirs: np.ndarray) -> np.ndarray:
    """``[R]``: whether each row's beams ``dirs [R, B, 2]`` go all round (its last beam
    neighbours its first as its second does): ``dirs[0] @ dirs[-1] >= dirs[0] @ dirs[1]``,
    within rounding, row by row (a stacked product of one row by one column is each row's
    dot product)."""
    if dirs.shape[1] <= 2:
        return np.zeros(len(dirs), dtype=bool)
    first = dirs[:, :1]                                                 # [R, 1, 2]
    last = np.matmul(first, dirs[:, -1, :, None])[:, 0, 0]
    second = np.matmul(first, dirs[:, 1, :, None])[:, 0, 0]
    return last >= second - 1e-9


def _route_distances(rows: Sights, asked: np.ndarray, hits: np.ndarray,
                     cfg: Settings) -> np.ndarray:
    """``[R, K]``: how far the points ``hits [R, K, 2]`` each row asks about (``asked``) lie
    from its route within ``sight`` (``inf`` elsewhere): what :func:`_in_way` and
    :func:`_obstruction_rows` measure, in one :func:`.route.distances` of the columns some
    row asks about, of the rows that ask (a point's distance from a route is its own
    arithmetic, whatever else is measured)."""
    out = np.full(asked.shape, np.inf)
    cols = np.logical_or.reduce(asked, axis=0).nonzero()[0]
    if not len(cols):
        return out
    n = len(rows.routes)
    some = (np.logical_or.reduce(asked, axis=1).nonzero()[0] if n > 1
            else np.zeros(1, dtype=np.intp))
    asking = some.tolist()
    at = np.s_[:, cols] if len(asking) == n else np.ix_(some, cols)
    out[at] = distances([rows.routes[i] for i in asking], [rows.frames[i].s for i in asking],
                        cfg.sight, hits[at])
    return out


def _in_way(rows: Sights, ahead: np.ndarray, gone: np.ndarray,
            body: dict[str, np.ndarray]) -> np.ndarray:
    """Which of the points ahead of their robots (``ahead``) and drawn on its map stand
    where its route would hit them: within half its width plus its safety margin of the
    route within ``sight`` (``gone``: :func:`_route_distances`; in a squeeze, nearer than
    the route keeps: see :func:`perceive`)."""
    # (only compared with: the sign of a zero, where a min or max of Python and of NumPy
    # may differ, does not matter)
    squeeze, threshold = rows.squeeze, rows.threshold
    return ahead & (gone <= np.minimum(body["in_way"][:, 0],
                                       np.maximum(squeeze - threshold, squeeze / 2))[:, None])


def _bodies(robots: tuple[Robot, ...], cfg: Settings) -> dict[str, np.ndarray]:
    """The robots' measures perception works with, ``[R, 1]`` each (read-only): half the
    width (``half``), half the length (``length``), the half width of the band an object
    obstructs in (``band``), of a way (``way``), of the roomier band a way is also scored
    in (``roomy``), of the band ``nearest`` looks in (``near``) and within which what is
    drawn stands in its way (``in_way``, :func:`perceive`), each the one robot's
    arithmetic; and the ways :func:`free_ways` tries (``ways``, :func:`_ways`). Looked up by
    the robots' and settings' identities first (hashing a :class:`Settings` costs more than
    the look-up saves, every tick), then by value."""
    key = (*map(id, robots), id(cfg))
    hit = _BODIES.get(key)
    if hit is None:
        if len(_BODIES) >= 64:
            _BODIES.clear()
        hit = _BODIES[key] = (robots, cfg, _measures(robots, cfg))   # holds them: ids stay
    return hit[2]


#: :func:`_bodies` by the identities of the robots and settings (which it keeps alive).
_BODIES: dict[tuple[int, ...], tuple[tuple[Robot, ...], Settings, dict[str, np.ndarray]]] = {}


@functools.lru_cache(maxsize=64)
def _measures(robots: tuple[Robot, ...], cfg: Settings) -> dict[str, np.ndarray]:
    """:func:`_bodies` by value."""
    def column(values: Iterable[float]) -> np.ndarray:
        return np.array(list(values), dtype=float)[:, None]

    out = {"half": column(r.width / 2 for r in robots),
           "length": column(r.length / 2 for r in robots),
           "band": column(r.width / 2 + cfg.band_margin for r in robots),
           "way": column(r.width / 2 + cfg.way_margin for r in robots),
           "roomy": column(r.width / 2 + cfg.way_margin + cfg.way_room for r in robots),
           "near": column(r.width / 2 + cfg.nearest_band for r in robots),
           "in_way": column(r.width / 2 + r.safety_margin for r in robots),
           "ways": _ways(cfg)}
    for a in out.values():
        a.flags.writeable = False
    return out


def _stack(arrays: list[np.ndarray]) -> np.ndarray:
    """The arrays (of one shape) one above the other (a view of the one, when there is one;
    ``np.array`` copies many for less than ``np.stack``)."""
    return arrays[0][None] if len(arrays) == 1 else np.array(arrays)


def _own_frames(headings: list[float], rel: np.ndarray,
                valid: np.ndarray) -> tuple[np.ndarray, ...]:
    """The points ``rel [R, B, 2]`` in each robot's own frame, along and across its heading:
    all of them (the products of :func:`_own_frame`, row by row), then the valid ones as a
    robot alone computes them from those points only, the others 0 (the robot's centre).
    A row's product is NumPy's matrix-vector product, whose every element is its own
    whatever the other rows, but a row of one point is a dot product, whose bits may differ:
    those few are worked out again as one (``tests/test_sim_perception.py``)."""
    n = len(headings)
    cs = np.empty((n, 4))                       # cos, sin, sin, -cos of each heading (math's)
    cs[:, 0] = cos = np.fromiter(map(math.cos, headings), float, n)
    cs[:, 1] = cs[:, 2] = np.fromiter(map(math.sin, headings), float, n)
    cs[:, 3] = -cos
    along = np.matmul(rel, cs[:, :2, None])[..., 0]                     # rel @ [c, s]
    across = np.matmul(rel, cs[:, 2:, None])[..., 0]                    # rel @ [s, -c]
    valid_along, valid_across = np.where(valid, along, 0.0), np.where(valid, across, 0.0)
    lone = (np.count_nonzero(valid, axis=1) == 1).nonzero()[0]
    if len(lone):
        j = valid[lone].argmax(axis=1)
        point = rel[lone, j][:, None]                                   # [L, 1, 2]
        valid_along[lone, j] = np.matmul(point, cs[lone, :2, None])[:, 0, 0]
        valid_across[lone, j] = np.matmul(point, cs[lone, 2:, None])[:, 0, 0]
    return along, across, valid_along, valid_across


def pursuit(route: Route, f: Frame, p: np.ndarray, bearing: float, cfg: Settings,
            lookahead: float | None, target: np.ndarray | None = None) -> float:
    """``heading``: the bearing of the route point ``lookahead`` ahead, as the bearing of a
    point at the usual ``cfg.lookahead`` that asks for the same turn. Pure pursuit turns on an
    arc of curvature ``2 sin(bearing) / distance``: a point a quarter as far off asks for the
    turn of one at the usual distance with four times the sine. Where the way is clear (the
    point at the usual lookahead) it is the bearing itself; in a tight gap, where the point
    lies nearer, the rules steer as hard as the nearer point needs. A point behind the robot
    (90 deg or more) keeps its bearing."""
    if abs(bearing) >= 90.0:
        return bearing
    if target is None:
        target = target_point(route, f, cfg, cfg.lookahead if lookahead is None else lookahead)
    return _pursuit_of(bearing, float(np.hypot(*(target - p))), cfg)


def _pursuit_of(bearing: float, distance: float, cfg: Settings) -> float:
    """:func:`pursuit` of a target point ``distance`` away (Python floats)."""
    if abs(bearing) >= 90.0:
        return bearing
    sine = min(1.0, cfg.lookahead / max(distance, 1e-9) * math.sin(math.radians(abs(bearing))))
    return math.copysign(math.degrees(math.asin(sine)), bearing)


def truth(route: Route, f: Frame, pose: tuple[float, float, float], robot: Robot,
          sides: tuple[float, float, float], outline: np.ndarray,
          cfg: Settings = Settings(), wall_points: np.ndarray | None = None,
          lookahead: float | None = None, room: float = math.inf) -> dict[str, float]:
    """The same inputs from the true geometry: ``sides`` the noise-free road and side gaps
    (:func:`true_sides`), ``outline`` points on every obstacle and other robot,
    ``wall_points`` where the beams meet the walls (noise-free) for ``front`` and
    ``opening``."""
    p = np.array(pose[:2])
    road, gaps = sides[0], sides[1:]
    rel = outline - p
    a = rel @ f.t if len(outline) else np.zeros(0)
    b = rel @ f.n if len(outline) else np.zeros(0)
    valid = np.ones(len(outline), dtype=bool)
    size, position, distance = _obstruction(route, a, b, outline, valid, np.zeros(len(outline)),
                                            robot, f, cfg, _own_frame(rel, pose[2]))
    target = target_point(route, f, cfg, cfg.lookahead if lookahead is None else lookahead)
    heading, lane, goal = _common(route, p, pose[2], f, road, robot, cfg, target, room)
    scan = outline if wall_points is None else np.concatenate([wall_points, outline])
    ah, bh = _own_frame(scan - p, pose[2]) if len(scan) else (np.zeros(0), np.zeros(0))
    unknown = np.arange(len(scan)) >= len(scan) - len(outline)
    front, opening = free_ways(ah, bh, np.zeros(len(scan)), unknown, robot, cfg, heading)
    objects = clutter(scan, unknown, ah, cfg)
    return {"road": road, "size": size, "position": position, "obstacle": distance,
            "heading": pursuit(route, f, p, heading, cfg, lookahead, target), "lane": lane,
            "goal": goal, "gap_left": gaps[0], "gap_right": gaps[1], "front": front,
            "opening": opening, "clutter": objects,
            "nearest": nearest(ah, bh, robot, cfg)}


def true_sides(f: Frame, pose: tuple[float, float, float], dirs: np.ndarray, expected: np.ndarray,
               outline: np.ndarray, robot: Robot, max_range: float,
               cfg: Settings = Settings()) -> tuple[float, float, float]:
    """Noise-free ``road``, ``gap_left`` and ``gap_right`` (for :func:`truth`), as
    :func:`perceive` measures them: walls from the map-predicted ranges, objects from their
    exact outlines."""
    rel = np.concatenate([expected[:, None] * dirs, outline - np.array(pose[:2])])
    walls = np.concatenate([expected < max_range * 0.999, np.zeros(len(outline), dtype=bool)])
    objects = np.concatenate([np.zeros(len(expected), dtype=bool),
                              np.ones(len(outline), dtype=bool)])
    ah, bh = _own_frame(rel, pose[2])
    road, left, right = _sides((rel @ f.t)[None], (rel @ f.n)[None], ah[None], bh[None],
                               (walls | objects)[None], walls[None],
                               _bodies((robot,), cfg), cfg, max_range, objects[None])
    return float(road[0]), float(left[0]), float(right[0])
