"""Robots of one world give way to each other where their routes cross.

Each robot senses the others as it senses a cart: echoes on its sonar. Head-on in a corridor
that is enough (each keeps right and they pass), but two robots coming to a crossing from two
sides each avoid the other as if it stood still, swerve into its way and meet in the middle
(docs/navigation.md, night 8's #12). Robots of one fleet share where they are and the route
each follows, as real fleets share their traffic (Open-RMF's schedule, a warehouse's fleet
manager), and give way by the rule of the road:

- the **crossing**: the stretch of each robot's route ahead (from its rear to
  :data:`LOOK_TIME` of its top speed on) that passes within :func:`zone` of the other's, where
  the two stretches run at :data:`CROSSING` or more to each other (head-on and one behind the
  other are the sonar's and the brake's: the robots keep right, and a robot slows for what is
  ahead of it);
- **who goes first** is decided where two robots first meet a crossing, and kept until it is
  behind them (:class:`Traffic`): a robot that can no longer stop short of the crossing, or is
  in it, is *committed* and goes first; of two committed, the one that comes first to where
  the routes meet; of none, the one coming from the other's right, unless the other clears
  the crossing :data:`CLEAR_BY` before it arrives. Four robots each with another on its right
  wait on each other in a ring; the first of them in the world's order goes, and those it
  waited on wait on it;
- **giving way** is a speed limit, :func:`.safety.brake`'s for the room left before the robot
  comes within the zone of the other's route and :data:`SLACK` more, measured straight to that
  route (never more than along its own, whatever a replanning does to either route); a robot
  already inside stops where it is. It goes on once the other's route, rear included, has
  left the crossing. A robot waiting so is not ``stuck`` (:mod:`.loop`), and it leaves
  the echoes of the robot it waits on out of its tracks;
- a **narrow place**: two robots head-on (at 135 deg or more) where both routes pass a place
  with room for one (:func:`narrow`: across either robot's route on its map, less than the
  two side by side with their margins; the place is often seen only once they have met)
  cross there in turn: the one with the obstruction on its side gives way (whoever comes
  to the place first), unless only it is committed. It waits in its lane, short of where
  its route comes within a lane of the other's (:func:`room_beside`) and never into the
  place (:func:`room_before`). Head-on where there is room for two they pass each other as
  before;
- **mates are not walls**: a robot leaves off its map the echoes (:func:`echoes`) of the
  robots of its fleet that drive by, and of the one it waits on (:func:`unmarked`); its
  brake counts their bodies instead, each stretched by the room it takes to stop
  (:func:`outlines`, :func:`stopping`), as each robot's brake stops it short of the others'
  so stretched. A mate that stands is marked where it stands, and routes go round it.

It is a limit on every planner's command, as the brake is (a user's planner, DWA, a
Gymnasium action), and it reads only what the robots share, never the world. Each run keeps
its own :class:`Traffic`, fed the run's own arrays: a run's robots give way the same in any
batch. ``robot: {give_way: false}`` leaves a robot out (it neither shares nor gives way).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np

from .knowledge import RobotMap
from .route import Route
from .safety import brake
from .world import Robot

#: in: the distance between two places of a route looked along
STEP = 4.0
#: s: how far ahead a robot looks along its route, at its top speed
LOOK_TIME = 3.0
#: the least sine of the angle between two routes' stretches near each other that is a
#: crossing (30 deg)
CROSSING = 0.5
#: in/s: a robot is reckoned to move at least this fast when its arrival is timed
SLOWEST = 10.0
#: s: a robot that clears the crossing this long before the other arrives need not give way
CLEAR_BY = 1.0
#: in: a reading that ends this near another robot's body is its echo (three standard
#: deviations of the noisiest randomised sensors of the shipped worlds, 1.5 in, and 0.5 more)
ECHO_PAD = 5.0
#: in: a robot giving way stops this much short of the crossing's edge; it is committed only
#: when it could not stop short of the edge itself (so braking to give way never commits it)
SLACK = 12.0
#: in/s: a mate this fast is driving by, and is left off the others' maps (:func:`unmarked`);
#: slower, it stands in the way and is marked where it stands (a little under the slowest
#: a tracker takes for moving, :data:`.movers.MIN_SPEED`, 6 in/s)
MOVING = 5.0
#: the least cosine of the angle between two routes' stretches near each other, negated,
#: for robots coming towards each other at a narrow place (135 deg; at a crossing the rule
#: of the road is the crossing's)
HEAD_ON = math.sqrt(0.5)
#: in: how far from its route a robot may drive: its keep-right lane (perception's ``road_cap``
#: of 100 in, a quarter of it)
LANE = 25.0


class Mate:
    """What a robot shares with the others of its run: where it is, its speed, the route it
    follows (the stretch ahead made only when a crossing is looked for) and, where it has one,
    its map (where two robots meeting head-on find room for one only, :func:`narrow`)."""

    def __init__(self, route: Route, progress: float, x: float, y: float, speed: float,
                 robot: Robot, rmap: RobotMap | None = None) -> None:
        self.route, self.progress, self.speed = route, progress, speed
        self.at = np.array([x, y])
        self.acceleration = robot.acceleration
        self.radius = math.hypot(robot.length / 2, robot.width / 2)
        self.back = robot.length / 2               # in: the path begins at its rear
        self.lane = robot.width + 2 * robot.safety_margin    # in: the width it drives in
        self.reach = max(robot.max_speed, SLOWEST) * LOOK_TIME
        self.map = rmap
        self._path: np.ndarray | None = None

    def ends(self, k: int) -> bool:
        """Whether the route ends at or before its path's place ``k`` (the robot stops there:
        its goal, or a refuge out of a cart's way, is no crossing)."""
        return self.progress - self.back + k * STEP >= self.route.length

    def point(self, ahead: float) -> np.ndarray:
        """``[2]`` the place of its route ``ahead`` in from its centre."""
        s = min(max(self.progress + ahead, 0.0), self.route.length)
        return self.route.points_at(np.array([s]))[0]

    @property
    def path(self) -> np.ndarray:
        """``[K, 2]`` its route from its rear to :attr:`reach` ahead, a place every STEP in."""
        if self._path is None:
            self._path = self.ahead(self.reach)
        return self._path

    def ahead(self, span: float) -> np.ndarray:
        """``[K, 2]`` its route from its rear to ``span`` ahead, a place every STEP in."""
        ahead = np.arange(-self.back, span + STEP / 2, STEP)
        return self.route.points_at(np.clip(self.progress + ahead, 0.0, self.route.length))


def zone(a: Mate, b: Mate) -> float:
    """How near (in) two robots' routes pass for their bodies to meet: their half diagonals,
    and a lane's width (:data:`LANE`) for how far off their routes the two drive."""
    return a.radius + b.radius + LANE


@dataclass(frozen=True)
class Crossing:
    """Where two robots' routes cross, in inches along each from the robot's centre (less
    than 0: behind it): the first and the last place within :func:`zone`, and the place
    where the two routes come nearest."""

    enter: tuple[float, float]
    leave: tuple[float, float]
    centre: tuple[float, float]
    right: bool                    # the second robot comes from the first's right
    narrow: bool = False           # head-on through a place with room for one (:func:`narrow`)


def crossing(a: Mate, b: Mate, known: bool = False, look_narrow: bool = True) -> Crossing | None:
    """Where the routes of ``a`` and ``b`` cross ahead, or ``None``: apart, or, unless the
    crossing is ``known`` already, with either robot backing out, with a route ending within
    :func:`zone` of the other (where the robot will stand: its goal, or a refuge out of a
    cart's way), or with the two routes' stretches within the zone of each other (each from
    its first place there to its last) at less than :data:`CROSSING` to each other: head-on
    or one behind the other, where the stretches run along each other, even where one route
    swerves round an object for a moment. A known crossing is kept however the routes meet
    (the routes of two robots going round each other in it may run side by side). Robots
    coming towards each other (``look_narrow``, known or not) cross where both pass a place
    with room for one (:func:`narrow`): the place is often seen only once they have met."""
    if math.dist(a.at, b.at) > a.back + a.reach + b.back + b.reach + zone(a, b):
        return None                                   # (too far apart for their paths to)
    if not known and min(a.speed, b.speed) < 0:
        return None
    d = np.hypot(a.path[:, None, 0] - b.path[None, :, 0], a.path[:, None, 1] - b.path[None, :, 1])
    near = d < zone(a, b)
    rows, cols = near.any(axis=1).nonzero()[0], near.any(axis=0).nonzero()[0]
    if not len(rows):
        return None
    ua, ub = _unit(a.path[rows[-1]] - a.path[rows[0]]), _unit(b.path[cols[-1]] - b.path[cols[0]])
    sine = _sine(ua, ub)
    if not known and (a.ends(rows[-1]) or b.ends(cols[-1])):
        return None
    if look_narrow and _cosine(ua, ub) < 0 and (tight := narrow(a, b)) is not None:
        return tight
    if not known and abs(sine) < CROSSING:
        return None
    i, j = (int(k) for k in np.unravel_index(int(np.argmin(d)), d.shape))
    return Crossing((rows[0] * STEP - a.back, cols[0] * STEP - b.back),
                    (rows[-1] * STEP - a.back, cols[-1] * STEP - b.back),
                    (i * STEP - a.back, j * STEP - b.back), sine > 0)


def narrow(a: Mate, b: Mate) -> Crossing | None:
    """Where ``a`` and ``b``, head-on (their routes' stretches near each other at
    :data:`HEAD_ON` or more), both pass a place too narrow for the two side by side
    (:func:`across` under the sum of their :attr:`Mate.lane`), as a :class:`Crossing` from
    the first such place of each one's route to the last, or ``None``; ``right`` if the room
    is on ``b``'s side. The routes are looked along until each has passed the other robot
    (the place is seen late, and each sees only its own side of it); a place is narrow on
    either robot's map, but not beside the other robot itself (standing, it is marked), and
    a place of one route is in the narrow where it lies within :func:`zone` of a narrow
    place of the other (the one seen is often not on the other's route yet: it runs on
    where it has not seen it)."""
    if a.map is None or b.map is None:
        return None
    span = math.dist(a.at, b.at) + zone(a, b)
    pa, pb = a.ahead(span), b.ahead(span)
    d = np.hypot(pa[:, None, 0] - pb[None, :, 0], pa[:, None, 1] - pb[None, :, 1])
    near = d < zone(a, b)
    rows, cols = near.any(axis=1).nonzero()[0], near.any(axis=0).nonzero()[0]
    if not len(rows) or _cosine(_unit(pa[rows[-1]] - pa[rows[0]]),
                                _unit(pb[cols[-1]] - pb[cols[0]])) > -HEAD_ON:
        return None
    need = a.lane + b.lane
    (wa, ma), (wb, mb) = across(a.map, pa, rows, need), across(b.map, pb, cols, need)
    # (not where the other itself, standing and marked, narrows the way beside it)
    na = (wa < need) & (np.hypot(*(pa[rows] - b.at).T) > b.radius + a.lane)
    nb = (wb < need) & (np.hypot(*(pb[cols] - a.at).T) > a.radius + b.lane)
    if not (na.any() or nb.any()):
        return None
    apart = d[np.ix_(rows, cols)] < zone(a, b)
    in_a, in_b = na | apart[:, nb].any(axis=1), nb | apart[na, :].any(axis=0)
    if not (in_a.any() and in_b.any()):
        return None
    ia, ib = rows[in_a], cols[in_b]
    mid_a, mid_b = (ia[0] + ia[-1]) // 2, (ib[0] + ib[-1]) // 2
    # the middle of the room, where a route runs in it (not through what it has not seen)
    room_at = np.concatenate([ma[na & (wa >= a.lane / 2)], mb[nb & (wb >= b.lane / 2)]])
    middle = room_at.mean(axis=0) if len(room_at) else (pa[mid_a] + pb[mid_b]) / 2
    return Crossing((ia[0] * STEP - a.back, ib[0] * STEP - b.back),
                    (ia[-1] * STEP - a.back, ib[-1] * STEP - b.back),
                    (mid_a * STEP - a.back, mid_b * STEP - b.back),
                    _left(a, b, middle) > 0, narrow=True)


def _left(a: Mate, b: Mate, p: np.ndarray) -> float:
    """How far (in) ``p`` lies to the left of ``a``'s way towards ``b`` (as far as it lies
    to the right of ``b``'s towards ``a``): the room of a narrow place on a robot's left is
    the oncoming lane for it, and the obstruction is on its own side (the rule of the road:
    it gives way)."""
    e = _unit(b.at - a.at)
    return 0.0 if e is None else float(e[0] * (p[1] - a.at[1]) - e[1] * (p[0] - a.at[0]))


def across(rmap: RobotMap, path: np.ndarray, places: np.ndarray,
           cap: float) -> tuple[np.ndarray, np.ndarray]:
    """The room across ``path [K, 2]`` at its ``places`` on ``rmap``, to either side at
    right angles to the path (each side at most ``cap``), where it is less than ``cap``:
    its width ``[P]`` (``inf`` where it is ``cap`` or more, and where the path has no
    direction: its route's end) and its middle ``[P, 2]``. Each side is the nearer of two
    beams a quarter of a STEP before and after the place: between them they cross every
    cell the path passes (a face seen edge on is a cell or two thick). Only places with
    something occupied within half of ``cap`` (and the beams' slack) are measured: the room
    elsewhere is ``cap`` or more."""
    at = path[places]
    width, middle = np.full(len(places), np.inf), at.copy()
    go = rmap.any_near(at, _reach(rmap, cap)).nonzero()[0]
    if not len(go):
        return width, middle
    along = _along(path, places[go])
    length = np.hypot(along[:, 0], along[:, 1])
    ok = length > 1e-9
    go, along, length = go[ok], along[ok], length[ok]
    if not len(go):
        return width, middle
    unit = along / length[:, None]
    left = np.stack([-unit[:, 1], unit[:, 0]], axis=1)
    at = at[go]
    origins = np.concatenate([at - unit * (STEP / 4), at + unit * (STEP / 4)] * 2)
    n = len(go)
    sides = rmap.ranges(origins, np.concatenate([left, left, -left, -left]), cap)
    to_left = np.minimum(sides[:n], sides[n:2 * n])
    to_right = np.minimum(sides[2 * n:3 * n], sides[3 * n:])
    room = to_left + to_right
    under = room < cap
    width[go[under]] = room[under]
    middle[go[under]] = (at + left * ((to_left - to_right) / 2)[:, None])[under]
    return width, middle


def _reach(rmap: RobotMap, cap: float) -> float:
    """How near a place something occupied must lie on ``rmap`` for the room across it to be
    less than ``cap``: half of it, and the beams' slack (a quarter STEP to a beam's origin,
    a cell to the sample in it)."""
    return cap / 2 + STEP / 4 + rmap.grid.resolution


def _along(path: np.ndarray, places: np.ndarray) -> np.ndarray:
    """``np.gradient(path, axis=0)[places]``, worked out at ``places`` alone with the same
    arithmetic (half the central difference inside, the one-sided difference at the ends)."""
    last = len(path) - 1
    d = path[np.minimum(places + 1, last)] - path[np.maximum(places - 1, 0)]
    inside = (places > 0) & (places < last)
    d[inside] /= 2.0
    return d


def _cosine(u: np.ndarray | None, v: np.ndarray | None) -> float:
    """The cosine of the angle between unit vectors ``u`` and ``v`` (0 where either is ``None``)."""
    if u is None or v is None:
        return 0.0
    return float(u[0] * v[0] + u[1] * v[1])


def _sine(u: np.ndarray | None, v: np.ndarray | None) -> float:
    """The sine of the angle from unit vector ``u`` to ``v`` (0 where either is ``None``)."""
    if u is None or v is None:
        return 0.0
    return float(u[0] * v[1] - u[1] * v[0])


def _unit(d: np.ndarray) -> np.ndarray | None:
    """``d`` made a unit vector (``None`` for a stretch of no length: a route's end)."""
    n = math.hypot(float(d[0]), float(d[1]))
    return d / n if n > 1e-9 else None


def committed(m: Mate, enter: float, dt: float) -> bool:
    """Whether the robot can no longer stop short of a crossing ``enter`` in ahead (or is in it)."""
    return enter <= 0 or brake(enter, m.acceleration, 0.0, dt) < m.speed


def _time(m: Mate, distance: float) -> float:
    return distance / max(m.speed, SLOWEST)


def first(a: Mate, b: Mate, c: Crossing, dt: float) -> bool:
    """Whether ``a`` goes first at its crossing ``c`` with ``b``, decided where the two first
    meet it: a committed robot goes first; of two, the one that comes first to where their
    routes meet (the one from the right at a tie); of none, at a :func:`narrow` place the one
    with the room on its own side (the other has the obstruction on its side: the rule of
    the road; ``a`` at a tie), elsewhere the one from the other's right, unless the other
    clears the crossing :data:`CLEAR_BY` before it arrives."""
    mine, theirs = committed(a, c.enter[0], dt), committed(b, c.enter[1], dt)
    if mine != theirs:
        return mine
    if mine:
        ta, tb = _time(a, c.centre[0]), _time(b, c.centre[1])
        return ta < tb or (ta == tb and not c.right)
    if c.narrow:               # the room on b's side: b goes (whoever comes to it first)
        return not c.right
    if c.right:                                     # b from a's right: b goes, unless a is
        return _time(a, c.leave[0]) + CLEAR_BY <= _time(b, c.enter[1])     # gone by then
    return not _time(b, c.leave[1]) + CLEAR_BY <= _time(a, c.enter[0])


def room_before(a: Mate, entry: np.ndarray) -> float:
    """How far (in) ``a``, giving way at a :func:`narrow` place, may drive at most: until its
    front is :data:`SLACK` short of ``entry [2]``, where its route came to the place when the
    two met it (measured straight)."""
    return max(math.dist(a.at, entry) - a.back - SLACK, 0.0)


def room_beside(a: Mate, b: Mate) -> float:
    """How far (in) ``a``, giving way to ``b`` at a :func:`narrow` place, may still drive:
    until its front is :data:`SLACK` short of where its route comes within a lane (half of
    each one's :attr:`Mate.lane`) of ``b``'s, looked along until ``b`` has passed it. It
    waits in its lane, out of the way ``b`` takes through the narrow and out of it; the
    narrow's ends are not its marks (each robot sees only its own side of the place)."""
    span = math.dist(a.at, b.at) + zone(a, b)
    pa, pb = a.ahead(span), b.ahead(span)
    gap = np.min(np.hypot(pa[:, None, 0] - pb[None, :, 0], pa[:, None, 1] - pb[None, :, 1]),
                 axis=1)
    ahead = np.arange(len(pa)) * STEP - a.back               # from its centre, along its route
    inside = ((gap < (a.lane + b.lane) / 2) & (ahead >= 0)).nonzero()[0]
    if not len(inside):
        return math.inf
    return max(float(ahead[inside[0]]) - 2 * a.back - SLACK, 0.0)


def room(a: Mate, b: Mate) -> float:
    """How far (in) ``a``, giving way to ``b``, may still drive: until it is :data:`SLACK`
    outside the crossing, measured straight to ``b``'s route (never more than along its own,
    which crosses ``b``'s at an angle; and a replanning that moves either route cannot let a
    robot giving way drive on into the crossing)."""
    gap = float(np.min(np.hypot(b.path[:, 0] - a.at[0], b.path[:, 1] - a.at[1])))
    return max(gap - zone(a, b) - SLACK, 0.0)


class Traffic:
    """The robots of one run giving way at crossings: who goes first at each crossing is
    decided once, where the two first meet it, and kept until it is behind them (decided
    again each tick, two robots braking for each other took turns going first)."""

    def __init__(self) -> None:
        self.order: dict[tuple[int, int], int] = {}     # (i, j), i < j -> the one first
        self.waits: list[tuple[int, int]] = []          # (robot, the robot it waits on)
        # (i, j) met head-on at a narrow place -> where each one's route comes to it
        self.narrows: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}

    def limits(self, mates: Sequence[Mate | None], dt: float) -> np.ndarray:
        """Each robot's speed limit (in/s; ``inf`` where it gives way to none) among
        ``mates`` (``None``: a robot no longer driving or not sharing). Where giving way goes
        round in a ring (four robots at a crossroads, each with another on its right), the
        first robot of the ring in the world's order goes (:func:`_unring`)."""
        n = len(mates)
        gives: list[dict[int, float]] = [{} for _ in range(n)]
        for i in range(n):
            for j in range(i + 1, n):
                a, b = mates[i], mates[j]
                c = None if a is None or b is None else \
                    crossing(a, b, (i, j) in self.order, (i, j) not in self.narrows)
                if c is None or a is None or b is None:
                    self.order.pop((i, j), None)
                    self.narrows.pop((i, j), None)
                    continue
                if (i, j) not in self.order or c.narrow:   # (a crossing found narrow: anew)
                    self.order[i, j] = i if first(a, b, c, dt) else j
                    if c.narrow:
                        self.narrows[i, j] = (a.point(c.enter[0]), b.point(c.enter[1]))
                if self.order[i, j] == i:
                    gives[j][i] = self._room(mates, j, i)
                else:
                    gives[i][j] = self._room(mates, i, j)
        _unring(gives, lambda i, j: self._room(mates, i, j))
        self.waits = [(i, j) for i, given in enumerate(gives) for j in given]
        out = np.full(n, np.inf)
        for i, given in enumerate(gives):
            m = mates[i]
            if m is not None and given:
                out[i] = brake(min(given.values()), m.acceleration, 0.0, dt)
        return out

    def _room(self, mates: Sequence[Mate | None], i: int, j: int) -> float:
        """Robot ``i``'s room giving way to ``j``: short of the narrow place where the two
        met head-on (:func:`room_beside`, and never into the place: :func:`room_before`),
        else outside the crossing (:func:`room`)."""
        a, b = cast(Mate, mates[i]), cast(Mate, mates[j])
        entries = self.narrows.get((min(i, j), max(i, j)))
        if entries is not None:
            return min(room_beside(a, b), room_before(a, entries[0 if i < j else 1]))
        return room(a, b)


def echoes(pose: np.ndarray, robots: Sequence[Robot], ranges: np.ndarray,
           dirs: np.ndarray) -> np.ndarray:
    """``[n, n, B]``: which of each robot's readings (``ranges [n, B]`` along ``dirs [n, B,
    2]`` from ``pose [n, 3]``, heading in radians) are echoes of each other robot: the
    reading ends within :data:`ECHO_PAD` of that robot's body (a robot's own row is all
    ``False``): what a robot leaves off its map of the robots :func:`unmarked` says."""
    n = len(robots)
    ends = pose[:, None, :2] + ranges[:, :, None] * dirs               # [n, B, 2]
    rel = ends[:, None] - pose[None, :, None, :2]                      # [n, n, B, 2]
    c, s = np.cos(pose[:, 2])[None, :, None], np.sin(pose[:, 2])[None, :, None]
    half_l = np.array([r.length / 2 for r in robots])[None, :, None]
    half_w = np.array([r.width / 2 for r in robots])[None, :, None]
    along = np.abs(rel[..., 0] * c + rel[..., 1] * s) - half_l
    side = np.abs(rel[..., 1] * c - rel[..., 0] * s) - half_w
    out = np.hypot(np.maximum(along, 0.0), np.maximum(side, 0.0)) <= ECHO_PAD
    out[np.arange(n), np.arange(n)] = False
    return out


def mates(share: Sequence[bool], active: np.ndarray) -> np.ndarray:
    """``[n, n]``: which robots each robot takes for mates rather than for walls: both
    share (``give_way``) and the other still drives. Where a mate is the fleet shares; a
    robot that arrived or crashed stands still and is a wall like any other."""
    both = np.asarray(share, dtype=bool) & active
    out = both[:, None] & both[None, :]
    np.fill_diagonal(out, False)
    return out


def unmarked(share: Sequence[bool], active: np.ndarray, speed: np.ndarray,
             waits: Iterable[tuple[int, int]]) -> np.ndarray:
    """``[n, n]``: whose echoes each robot leaves off its map: its :func:`mates` that move
    (:data:`MOVING` or faster), and the robot it waits on (``waits``: pairs of a robot and
    the robot it gives way to) however it moves. Marked, a mate driving by was a trail of
    walls where it had been, which the robot planned round: into a crossing's corner, or
    swerving into the oncoming lane (six robots at a crossroads). A mate that stands, waiting
    or giving way, is marked: it is in the way, and the route goes round it."""
    out = mates(share, active) & (np.abs(speed) >= MOVING)[None, :]
    for me, other in waits:
        out[me, other] = True
    return out


def outlines(pose: np.ndarray, robots: Sequence[Robot], which: np.ndarray, half: float,
             ahead: np.ndarray) -> list[np.ndarray]:
    """Each robot's outline (``[P, 2]``; empty where not ``which``): the centres of squares
    of half side ``half`` (a cell of the maps) laid round its footprint at ``pose [n, 3]``,
    a square's side apart, each covering the cell just outside the footprint as a mark covers
    the cell beyond an echo; the footprint stretched ``ahead [n]`` in along its heading
    (backward where negative). What another robot's brake counts for a mate, the room it
    takes to stop (:meth:`.knowledge.RobotMap.brake_cells` counts the map's cells so). Flush
    inside the footprint, a robot passing a mate that turned as it stopped touched it
    (`multirobot` seed 16)."""
    out = []
    for j, r in enumerate(robots):
        if not which[j]:
            out.append(np.zeros((0, 2)))
            continue
        a, b = r.length / 2 + half, r.width / 2 + half
        lo, hi = -a + min(float(ahead[j]), 0.0), a + max(float(ahead[j]), 0.0)
        u = np.linspace(lo, hi, max(2, math.ceil((hi - lo) / (2 * half)) + 1))
        v = np.linspace(-b, b, max(2, math.ceil(2 * b / (2 * half)) + 1))[1:-1]
        local = np.concatenate([np.stack([u, np.full_like(u, -b)], 1),
                                np.stack([u, np.full_like(u, b)], 1),
                                np.stack([np.full_like(v, lo), v], 1),
                                np.stack([np.full_like(v, hi), v], 1)])
        x, y, h = pose[j]
        c, s = math.cos(h), math.sin(h)
        out.append(local @ np.array([[c, s], [-s, c]]) + (x, y))
    return out


def stopping(speed: np.ndarray, robots: Sequence[Robot], dt: float) -> np.ndarray:
    """``[n]`` in: how far each robot drives (signed: backward negative) before it can
    stop, a tick late: what a mate's footprint is stretched by for the brake
    (:func:`outlines`), as each robot's brake stops it short of the others' so stretched."""
    a = np.array([r.acceleration for r in robots])
    return speed * (np.abs(speed) / (2 * a) + dt)


def _unring(gives: list[dict[int, float]], room_of: Callable[[int, int], float]) -> None:
    """Break every ring of giving way in ``gives`` (robot -> {robot it waits on: its room}):
    the lowest robot of a ring goes, and the robots of the ring it waited on wait on it
    instead (``room_of(i, j)``: ``i``'s room giving way to ``j``), so each pair that meets
    still has one robot that waits. (Only dropping its waits freed, where rings overlap, both
    robots of a pair: six robots at a crossroads met so.) Each turn makes an edge from a
    lower robot to a higher one point down, so the turns end."""
    while (ring := _ring(gives)) is not None:
        lowest = min(ring)
        for j in [j for j in gives[lowest] if j in ring]:
            del gives[lowest][j]
            gives[j][lowest] = room_of(j, lowest)


def _ring(gives: list[dict[int, float]]) -> set[int] | None:
    """The robots of a ring of giving way (each waits on the next, the last on the first),
    or ``None``: the first found depth first from the lowest robot, each robot visited once."""
    state = [0] * len(gives)                    # 0 not yet, 1 on the way being walked, 2 done
    for start in range(len(gives)):
        if state[start]:
            continue
        way, todo = [start], [iter(sorted(gives[start]))]
        state[start] = 1
        while todo:
            nxt = next(todo[-1], None)
            if nxt is None:
                state[way.pop()] = 2
                todo.pop()
            elif state[nxt] == 1:
                return set(way[way.index(nxt):])
            elif state[nxt] == 0:
                state[nxt] = 1
                way.append(nxt)
                todo.append(iter(sorted(gives[nxt])))
    return None
