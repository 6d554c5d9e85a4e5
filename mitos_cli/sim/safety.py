"""The robot's own safety, whatever its planner commands: an emergency brake, and backing out
of a pocket.

A planner (the fuzzy rules, a potential field, DWA, a user's own) commands a wheel angle and a
speed; the tricycle then sweeps its body along an arc, and a corner it turns into a pole is a
collision that no rule saw coming (the rules read ranges along bands, not arcs). Two things
every robot of this kind carries, applied to every command (``robot: {brake: false}`` takes
them away, as the paper's robot had none):

- **the brake** (:func:`brake`): the robot goes no faster than it can stop, at its
  acceleration, within the free travel of the arc its wheel is set to, keeping ``margin`` from
  everything it knows is there (its map: what it was given and what it has sensed, which its
  readings keep up to date), counting the tick it drives on before the next command; it
  looks along the arc as far as stopping from its top speed takes (:func:`reach_of`). Where
  the arc is shut the robot stops. A wheel that would turn toward what the robot could no
  longer stop short of, at the speed it has, is held where it is when its own arc leaves
  more room: the brake bounds the speed on one arc, and a hard turn at speed (a planner
  swerving just after it passed another robot) swung a robot into a wall it could then not
  stop before. A robot that still rolls against its command (a backing-out just ended) is
  measured the way it rolls, not the way it is told to go (:func:`_rolling`).
- **backing out** (:class:`Recovery`): held by the brake for ``patience`` seconds while its
  planner wants to go on, the robot backs out for ``back_time`` seconds on the opposite lock
  (which swings its nose toward the side its route lies on), else straight, else the other
  lock, else on the wheel between them nearest that lock with room behind, as far as the
  way behind is free, then hands back to its planner. A tricycle cannot turn on the spot;
  this is how it turns in a pocket (ROS's ``move_base`` recovers the same way: clear, back up, try again).

The sweep (:func:`free_travel`) moves the footprint along the exact arc about the rear axle.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .world import Robot

if TYPE_CHECKING:
    from collections.abc import Sequence

    #: a footprint's number: one float, or one per sweep (``[R, 1]``) or per place
    Num = float | np.ndarray


@dataclass(frozen=True)
class Settings:
    margin: float = 1.0            # in: the body keeps this from what the robot knows
    reach: float = 30.0            # in: the least the brake looks along its arc (a robot
                                   # looks as far as stopping from its top speed takes)
    step: float = 1.0              # in: the most a cell's depth changes between two places of
                                   # the sweep (the rear axle's travel between them, straight on)
    patience: float = 1.0          # s: held to a stop this long, the robot backs out
    back_time: float = 1.5         # s: how long one backing-out lasts
    back_room: float = 4.0         # in: it backs out only with this much free behind
    want: float = 2.0              # in/s: a planner asking for more than this wants to go on


def free_travel(cells: np.ndarray, radius: float, pose: tuple[float, float, float],
                robot: Robot, delta: float, backward: bool, reach: float,
                step: float = 1.0) -> float:
    """How far (in, along the rear axle's path) the robot can drive from ``pose`` (x, y, heading
    in rad) with its wheel held ``delta`` degrees off straight (positive right), forward or
    ``backward``, before its footprint touches one of the occupied ``cells [P, 2]`` (squares
    of half side ``radius``, :func:`_depth`); ``reach`` when it can drive that far, 0 when it
    touches one already, but for backing out: backward, a cell it touches blocks only the steps
    that take it deeper in.

    The footprint is placed every :func:`_spacing` along the arc, close enough that no cell's
    depth changes by more than ``step`` from one place to the next; where a cell might be
    touched between two places (:func:`_pairs`), :func:`_between` looks closer. So no touch
    deeper than 1/16 in (``step / 16``) passes between two places unseen: at full lock a front
    corner moves three to four times as far as the rear axle, and places a whole inch of the
    axle's path apart let it clip a wall's corner. Only the cells in the box the footprint's
    circumscribed disc sweeps (grown by a step) are tested: a cell outside it is touched
    nowhere along the arc, and each cell's test is its own."""
    if not len(cells):
        return reach
    h, k, a, b, sin_h, cos_h, half, hl, hw, disc, du = _sweep_of(pose, robot, delta, radius, step)
    u = _path(reach, du, backward)                   # [K]
    arc = Arc(h, k, a, b, sin_h, cos_h, half, abs(k) > 1e-9)
    c, s, cx, cy = arc.centres(u)                    # [K]: the footprint's centres
    px, py = cells[:, 0], cells[:, 1]
    swept = ((px >= cx.min() - disc) & (px <= cx.max() + disc)
             & (py >= cy.min() - disc) & (py <= cy.max() + disc))
    if not np.count_nonzero(swept):
        return reach
    px, py = px[swept, None], py[swept, None]
    depth = _depth_in(px - cx, py - cy, c, s, _room(c, s, hl, hw, radius))      # [P, K]
    inside = _touched(depth, backward)
    hit = np.logical_or.reduce(inside, axis=0)
    cell, j = _pairs(inside, depth, step)
    _between(hit[None], len(u), cell, j, np.zeros(len(px), dtype=np.intp), u[None], arc, px, py,
             hl, hw, radius)
    if not np.count_nonzero(hit):
        return reach
    return float(max(int(hit.argmax()) - 1, 0) * du)


def _sweep_of(pose: tuple[float, float, float], robot: Robot, delta: float, radius: float,
              step: float) -> tuple[float, ...]:
    """One sweep's numbers in Python floats, the same alone and among many: :class:`Arc`'s
    heading, curvature, the rear axle's start, the heading's sine and cosine and half the
    wheelbase; the footprint's half length and width, how far the box of the cells it may
    touch reaches past its centres, and the places' spacing (:func:`_spacing`)."""
    x, y, h = pose
    wb, hl, hw = robot.wheelbase, robot.length / 2, robot.width / 2
    k = -math.tan(math.radians(delta)) / wb          # rad per inch of the rear axle's path
    return (h, k, x - wb / 2 * math.cos(h), y - wb / 2 * math.sin(h), math.sin(h), math.cos(h),
            wb / 2, hl, hw, _disc(robot, radius, step), _spacing(robot, k, radius, step))


def _disc(robot: Robot, radius: float, step: float) -> float:
    """How far past the footprint's centres the box of the cells a sweep may touch reaches:
    its circumscribed disc, a cell's corner (of half side ``radius``) and a step."""
    return math.hypot(robot.length / 2, robot.width / 2) + radius * math.sqrt(2) + step + 1e-6


@dataclass(frozen=True)
class Arc:
    """The arc of one sweep (each field a float), or of ``R`` (each ``[R, 1]``): heading
    (rad), curvature (rad per inch of the rear axle's path), the rear axle's start, the
    heading's sine and cosine, half the wheelbase and whether it turns at all. One sweep's
    places come out bit for bit as the same sweep's among many."""

    h: Any
    k: Any
    a: Any
    b: Any
    sin_h: Any
    cos_h: Any
    half: Any
    turning: Any

    def centres(self, u: np.ndarray, rows: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(cos, sin, x, y)`` of the heading and the footprint's centre after ``u`` inches
        of the rear axle's path (``[R, K]``, or ``rows``: of those sweeps, one per row)."""
        def pick(v: Any) -> Any:          # a field: a float, or [R, 1] (np.ndim tells)
            return v if rows is None or np.ndim(v) == 0 else v[rows]

        h, k, a, b = pick(self.h), pick(self.k), pick(self.a), pick(self.b)
        sin_h, cos_h, turning = pick(self.sin_h), pick(self.cos_h), pick(self.turning)
        # (the sums worked in place where they are arrays: a batch's [R, K] are 200 KB each,
        # and each one more fresh from the system is some fifty page faults; a + b is b + a)
        hk = k * u
        hk += h
        c = np.cos(hk)
        s = np.sin(hk, out=hk)
        if np.ndim(turning) == 0:                     # one sweep: one formula
            rx = a + (s - sin_h) / k if turning else a + u * cos_h
            ry = b + (cos_h - c) / k if turning else b + u * sin_h
        elif turning.all():                           # (a wheel is seldom exactly straight)
            rx = np.subtract(s, sin_h)
            rx /= k
            rx += a
            ry = np.subtract(cos_h, c)
            ry /= k
            ry += b
        else:
            bend = np.where(turning, k, 1.0)          # a straight sweep divides by nothing
            rx = np.where(turning, a + (s - sin_h) / bend, a + u * cos_h)
            ry = np.where(turning, b + (cos_h - c) / bend, b + u * sin_h)
        half = pick(self.half)
        cx, cy = half * c, half * s
        cx += rx
        cy += ry
        return c, s, cx, cy


#: Places looked at between two of a sweep's where a cell may be touched between them.
BETWEEN = 8


def _touched(depth: np.ndarray, backward: bool | np.ndarray) -> np.ndarray:
    """``[P, K]`` whether the footprint touches each cell at each place; backing away from a
    cell it touches already (a mark a noisy echo put at its edge), only the places deeper in
    (``backward``: a bool, or one per cell)."""
    inside = depth >= 0
    if backward is False or not np.count_nonzero(backward):
        return inside
    back = np.broadcast_to(np.asarray(backward), (len(depth),))
    inside[back] = np.where(inside[back][:, :1], depth[back] > depth[back][:, :1], inside[back])
    return inside


def _pairs(inside: np.ndarray, depth: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """``(cell, j)``: where a cell may be touched between two places ``j`` and ``j + 1`` of
    ``depth [P, K]`` that touch it at neither (``inside``). The depth changes by at most
    ``step`` from one place to the next, so only where the two depths add up to ``-step`` or
    more; a cell touched at the start is left out (backing away, only deeper places count)."""
    maybe = (depth[:, :-1] + depth[:, 1:] >= -step) & ~inside[:, :-1] & ~inside[:, 1:]
    maybe &= depth[:, :1] < 0
    return np.divmod(np.flatnonzero(maybe), depth.shape[1] - 1)


def _between(hit: np.ndarray, own: int | np.ndarray, cell: np.ndarray, j: np.ndarray, owner: np.ndarray,
             u: np.ndarray, arc: Arc, px: np.ndarray, py: np.ndarray, hl: Num, hw: Num, radius: Num) -> None:
    """Mark in ``hit [R, K]`` (where each sweep touches a cell, within its ``own`` places) the
    places ``j + 1`` of the :func:`_pairs` ``(cell, j)`` where one of :data:`BETWEEN` - 1
    places between ``j`` and ``j + 1`` touches the cell. Between two of those the depth
    changes by at most ``step / BETWEEN``: what is left unseen is a graze of less than
    ``step / (2 BETWEEN)`` (1/16 in), not a corner swinging through a cell. (Counting every
    pair that might graze would stop a robot sliding past a cell of its map a few thousandths
    of an inch off, which the map's cells, larger than what they mark, make common among
    poles.) Only the pairs before a sweep's first touch are looked at: the first is all that
    counts, and most pairs come after it. ``u [R, K]`` the places of each sweep, ``owner
    [P]`` each cell's sweep."""
    rows = owner[cell]
    first = np.where(np.logical_or.reduce(hit, axis=1), hit.argmax(axis=1), own)
    keep = j + 1 < first[rows]
    if not np.count_nonzero(keep):
        return
    cell, j, rows = cell[keep], j[keep], rows[keep]
    lo, hi = u[rows, j][:, None], u[rows, j + 1][:, None]
    t = np.arange(1, BETWEEN) / BETWEEN
    uu = lo + (hi - lo) * t                                               # [C, BETWEEN - 1]
    c, s, cx, cy = arc.centres(uu, rows)
    pick = (lambda v: v[cell]) if np.ndim(hl) else (lambda v: v)
    dd = _depth(px[cell] - cx, py[cell] - cy, c, s, pick(hl), pick(hw), pick(radius))
    touch = np.logical_or.reduce(dd >= 0, axis=1)
    hit[rows[touch], j[touch] + 1] = True


#: Elements (float64, 64 KB) in one of the ``[M, K]`` arrays worked out at a time: the
#: arrays of a whole batch at once were too large for the allocator to keep, and came fresh
#: from the system at every call, a page fault every 4 KB (30% of a lockstep sweep's time).
#: At 128 KB they still did often: 64 slalom runs in lockstep took 208,000 page faults, at
#: 64 KB 57,000, and their sweeps 30 -> 26 us a robot-tick (more chunks cost 2 us a sweep
#: measured apart, where nothing faults).
CHUNK = 8192


def _chunks(rows: int, width: int) -> list[slice]:
    """Slices of ``rows`` rows of ``width`` elements each, :data:`CHUNK` elements at most."""
    per = max(CHUNK // max(width, 1), 1)
    return [slice(lo, lo + per) for lo in range(0, rows, per)]


def _spacing(robot: Robot, k: float, radius: float, step: float) -> float:
    """The rear axle's travel between two places of the footprint along an arc of curvature
    ``k`` (rad per inch) such that no cell's depth (:func:`_depth`) changes by more than
    ``step``: per inch of the axle's travel the footprint's centre moves at most
    ``1 + |k| wb / 2`` inches and turns ``|k|`` rad, and a turn moves the depth of a cell
    that can touch by at most ``|k|`` times its distance from the centre (half the
    footprint's diagonal, a cell's diagonal and the step). Straight on, ``step`` itself."""
    return step / (1.0 + abs(k) * _far(robot, radius, step))


#: in: the least radius of a robot's tightest turn (the rear axle's path at full lock). The
#: sweep's places are ``step / (1 + |k| far)`` apart (:func:`_spacing`), so their number grows
#: as one over that radius: at 0.06 in a 3 s run on a small map took 18 s, at 0.006 in it was
#: killed after a minute at 434 MB, at 1e-15 in (a lock of 90 deg) it asked for more memory
#: than a machine has. The packaged robots turn at 7.5 to 9.2 in; a robot that turns within
#: half an inch of its rear axle turns on the spot, which no tricycle does.
TIGHTEST_TURN = 0.5


def full_lock(robot: Robot) -> float:
    """How far (deg) the robot's wheel turns from straight at most, to either side."""
    return max(robot.steering_straight - robot.steering_min,
               robot.steering_max - robot.steering_straight)


def tightest_turn(robot: Robot) -> float:
    """The radius (in) of the rear axle's path at the robot's :func:`full_lock`:
    ``wheelbase / tan(lock)``; 0 where the wheel can stand across the robot (90 deg or more)."""
    lock = full_lock(robot)
    return robot.wheelbase / math.tan(math.radians(lock)) if lock < 90 else 0.0


def fastest_point(robot: Robot) -> float:
    """How far the body's fastest point moves per inch the front wheel drives, at most: 1
    straight on, more in a turn, where the footprint's front corner on the outside swings
    wider than the wheel (the packaged robots: 1.47 at full lock). It bounds how much closer
    the body can come to anything in a tick (:meth:`.loop.Simulation._between`).

    At a lock ``d`` the robot turns about a point on its rear axle's line, ``wheelbase /
    tan(d)`` out, at ``sin(d) / wheelbase`` rad per inch of the wheel; that corner lies
    ``(length + wheelbase) / 2`` ahead of the axle and ``width / 2`` beyond the robot's far
    side, so (squared, times the wheelbase squared) it moves ``wb^2 + A sin^2 d + B sin 2d``
    with ``A = ((l + wb) / 2)^2 + (w / 2)^2 - wb^2`` and ``B = wb w / 2``: a sine in ``2d``
    whose crest is taken where the lock reaches it."""
    wb, lock = robot.wheelbase, math.radians(min(full_lock(robot), 90.0))
    a, b = (robot.length + wb) / 2, robot.width / 2
    big, cross = a * a + b * b - wb * wb, wb * b
    crest = (math.atan2(big / 2, cross) + math.pi / 2) / 2
    at = min(lock, crest)
    return math.sqrt(wb * wb + big * math.sin(at) ** 2 + cross * math.sin(2 * at)) / wb


def swing_words(swing: float) -> str:
    """What :func:`fastest_point`'s ``swing`` means, for a message."""
    return (f"at full lock its outer front corner moves {swing:.3g}x as fast as its wheel"
            if swing > 1.0 else "straight on, every point as fast as its wheel")


def _far(robot: Robot, radius: float, step: float) -> float:
    """:func:`_spacing`'s reach of a turn: half the wheelbase, half the footprint's diagonal,
    a cell's diagonal and the step."""
    return (robot.wheelbase / 2 + math.hypot(robot.length / 2, robot.width / 2)
            + 2 * math.sqrt(2) * radius + step)


def _depth(dx: np.ndarray, dy: np.ndarray, c: np.ndarray, s: np.ndarray, hl: Num, hw: Num,
           r: Num) -> np.ndarray:
    """How deep a cell, the square of half side ``r`` centred ``(dx, dy)`` from the
    footprint's centre, reaches into the footprint (half length ``hl``, half width ``hw``,
    heading cosine ``c`` and sine ``s``): the least overlap along the four axes that can
    separate two rectangles, the footprint's two and the grid's. Taken as a disc of radius
    ``r``, a cell's corner stood 0.41 r out of it, and a flank sliding past a wall block at a
    slant met that corner with the brake's way free."""
    return _depth_in(dx, dy, c, s, _room(c, s, hl, hw, r))


def _room(c: np.ndarray, s: np.ndarray, hl: Num, hw: Num, r: Num) -> tuple[Any, Any, Any, Any]:
    """What of :func:`_depth` depends on the footprint's place alone, not on the cell: the
    footprint's half extents grown by the cell's, along its own axes and along the grid's
    (worked out once a place, not once a cell and place, in the order :func:`_depth` sums)."""
    ac, as_ = np.abs(c), np.abs(s)
    e = ac + as_
    e *= r                               # the cell's half extent along the footprint's axes
    along = hl + e
    e += hw                              # (in place, as Arc.centres: the same sums, in order)
    x = hl * ac
    x += r
    part = hw * as_
    x += part                            # r + hl ac + hw as
    y = hl * as_
    y += r
    y += np.multiply(hw, ac, out=part)   # r + hl as + hw ac
    return along, e, x, y


def _depth_in(dx: np.ndarray, dy: np.ndarray, c: np.ndarray, s: np.ndarray,
              room: Sequence[Any]) -> np.ndarray:      # _room's four
    """:func:`_depth` with the footprint's :func:`_room` at each place."""
    along, across, x, y = room
    along = along - np.abs(dx * c + dy * s)
    across = across - np.abs(dy * c - dx * s)
    return np.minimum(np.minimum(along, across), np.minimum(x - np.abs(dx), y - np.abs(dy)))


def free_travels(sweeps: list[tuple[Body, float, bool]], step: float = 1.0) -> np.ndarray:
    """:func:`free_travel` of many sweeps at once (``(body, wheel, backward)`` each, as far as
    its body's ``reach``), ``[R]``: what is one number per sweep is worked out as
    :func:`free_travel` does, in Python floats; the rest by :func:`_travels`, so a sweep gets
    the bits it gets alone."""
    if len(sweeps) == 1:                 # a robot alone: no batch to set up
        body, wheel, backward = sweeps[0]
        return np.array([free_travel(body.cells, body.radius, body.pose, body.robot,
                                     wheel - body.robot.steering_straight, backward, body.reach,
                                     step)])
    out = np.array([body.reach for body, _, _ in sweeps], dtype=float)
    rows = [j for j, (body, _, _) in enumerate(sweeps) if len(body.cells)]
    if not rows:
        return out
    bodies = [sweeps[j][0] for j in rows]
    numbers = np.array([
        _sweep_of(body.pose, body.robot, wheel - body.robot.steering_straight, body.radius, step)
        for body, wheel, _ in (sweeps[j] for j in rows)]).T                   # [11, R]
    out[rows] = _travels([body.cells for body in bodies], numbers,
                         np.array([body.radius for body in bodies]), out[rows],
                         np.array([sweeps[j][2] for j in rows]), step)
    return out


def _travels(cells: list[np.ndarray] | Boxed, numbers: np.ndarray | tuple[np.ndarray, ...],
             radius: np.ndarray, reach: np.ndarray,
             back: np.ndarray, step: float) -> np.ndarray:
    """The free travel ``[R]`` of ``R`` sweeps (runs in lockstep brake together), each with
    cells (``[P, 2]`` each, of half side ``radius [R]``; or what a :data:`Boxed` finds round
    each sweep's box), backward or not (``back [R]``), as
    far as ``reach [R]``; ``numbers``: each sweep's :func:`_sweep_of`, ``[R]`` each. Worked
    out elementwise over ``[R, K]`` places (each sweep's own, its last repeated to the
    longest) and ``[M, K]`` for the ``M`` cells in the sweeps' boxes that :func:`_near`
    keeps, each with its sweep's places (not padded to the sweep with the most: a quarter of
    the cells would be real), so a sweep gets the bits it gets alone."""
    h, k, a, b, sin_h, cos_h, half, hl, hw, disc, du = (v[:, None] for v in numbers)  # [R, 1]
    rad, out = radius[:, None], reach.copy()
    own = (np.ceil(reach[:, None] / du - 1e-9) + 1).astype(np.intp)    # as many places as _path's
    u = np.minimum(np.arange(int(own.max())), own - 1) * np.where(back[:, None], -du, du)
    arc = Arc(h, k, a, b, sin_h, cos_h, half, np.abs(k) > 1e-9)
    c, s, cx, cy = arc.centres(u)              # [R, K]: the footprint at each sweep's places
    px, py, owner = _in_boxes(cells, cx, cy, disc[:, 0], 2 * radius)    # [M, 1], by sweep
    if not len(owner):
        return out
    places = (c, s, cx, cy, *_room(c, s, hl, hw, rad))
    near, sure, lo, hi = _near(px, py, owner, places,
                               _bound(k, du, hl, hw, half, rad, step)[:, 0], back)
    px, py, owner, lo, hi = px[near], py[near], owner[near], lo[near], hi[near]
    if not len(owner):
        return out
    # each sweep's places up to the first where a cell is touched for sure (its own at most):
    # no later place changes where it first touches, nor a pair _between looks at
    upto = np.maximum(own[:, 0], 0)            # (a sweep of no place: a reach below 0)
    np.minimum.at(upto, owner, sure[near] + 1)
    hi = np.minimum(hi, upto[owner] - 1)       # each cell's window, up to its sweep's last
    some = hi >= lo
    if not np.count_nonzero(some):
        return out
    if not some.all():
        px, py, owner, lo, hi = px[some], py[some], owner[some], lo[some], hi[some]
    hit, cell, j = _touches(px, py, owner, places, back, step, lo, hi)
    _between(hit, own[:, 0], cell, j, owner, u, arc, px, py, hl[owner], hw[owner], rad[owner])
    first = np.maximum(hit.argmax(axis=1) - 1, 0) * du[:, 0]
    return np.where(np.logical_or.reduce(hit, axis=1), first, out)


#: The coarse pass (:func:`_near`) looks at every ``COARSE``-th place of a sweep, and its last.
COARSE = 8
#: in: far more than a depth's rounding (of the places, the footprint's centres and the depth
#: itself: below 1e-5 in for coordinates of thousands of inches and curvatures above 1e-9)
ROUNDING = 1e-3


def _in_boxes(known: list[np.ndarray] | Boxed, cx: np.ndarray, cy: np.ndarray,
              disc: np.ndarray, side: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cells (``px, py [M, 1]``) of ``known`` (each sweep's, or what the :data:`Boxed`
    finds round each sweep's box) in the box each sweep may touch (its centres ``cx, cy [R,
    K]``, grown by ``disc [R]``), and their sweep (``owner [M]``, sorted). A :data:`Boxed`
    is asked for the square round each box grown by a cell's ``side [R]``: a cell whose
    centre lies in the box has its row and column in that square's."""
    lo_x, hi_x = cx.min(axis=1) - disc, cx.max(axis=1) + disc
    lo_y, hi_y = cy.min(axis=1) - disc, cy.max(axis=1) + disc
    if callable(known):
        centre = np.empty((len(lo_x), 2))
        centre[:, 0], centre[:, 1] = (lo_x + hi_x) / 2, (lo_y + hi_y) / 2
        known = known(centre, np.maximum(hi_x - lo_x, hi_y - lo_y) / 2 + side)
    cells = np.concatenate(known)                                               # [P, 2]
    counts = [len(c) for c in known]
    px, py = cells[:, 0], cells[:, 1]
    swept = px >= np.repeat(lo_x, counts)            # (each sweep's bound, cell by cell)
    swept &= px <= np.repeat(hi_x, counts)
    swept &= py >= np.repeat(lo_y, counts)
    swept &= py <= np.repeat(hi_y, counts)
    keep = np.flatnonzero(swept)
    return px[keep, None], py[keep, None], np.repeat(np.arange(len(known)), counts)[keep]


def _near(px: np.ndarray, py: np.ndarray, owner: np.ndarray, places: tuple[np.ndarray, ...],
          bound: np.ndarray, back: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``[M]`` which cells (``px, py [M, 1]`` of sweeps ``owner [M]``) may reach a depth of
    ``-step`` at one of their sweep's ``places`` (``c, s, cx, cy`` and :func:`_room`, each
    ``[R, K]``), from their depths at the :func:`_coarse` places alone: a cell deeper than
    ``-bound [R]`` (:func:`_bound`) at none of those is below ``-step`` at every place, so it
    is never touched, not even at the start (backing away, :func:`_touched`), nor between two
    places (two depths below ``-step`` add up to less than ``-step``, :func:`_pairs`).
    Leaving it out changes no bit of the answer, and most of the cells in a sweep's box are
    out of its reach. Also ``[M]``: the first of those places where each cell is touched for
    sure (:func:`_touched`, backing out of sweeps ``back [R]``: its depth 0 or more, and not
    a cell touched at the start backed away from), past the last place where none is; and
    each cell's window, the places ``lo`` to ``hi`` (``[M]`` each) from the coarse place
    before its first deeper than ``-bound`` to the one after its last: by the same bound,
    every place outside lies between two coarse places below ``-bound``, so the cell is
    below ``-step`` there (a cell passes the footprint in a short stretch of a sweep, and
    :func:`_touches` looks at that stretch alone: a third of the places). (The places a cell
    is looked at run down a column: NumPy takes the greatest of each column at once, and of
    each short row one row at a time.)"""
    width = places[0].shape[1]
    at = _coarse(width)[:, None]                                # [C, 1]
    last = len(at) - 1

    def deep(part: slice) -> tuple[np.ndarray, ...]:
        where = at + owner[part] * width                        # [C, M]: in places, flat
        c, s, cx, cy, *room = (np.take(v, where) for v in places)
        depth = _depth_in(px[part, 0] - cx, py[part, 0] - cy, c, s, room)
        sure = depth >= 0
        sure &= (depth[:1] < 0) | ~back[owner[part]]
        within = depth >= -bound[owner[part]]
        first = np.maximum(within.argmax(axis=0) - 1, 0)
        after = np.minimum(last - within[::-1].argmax(axis=0) + 1, last)
        return (depth.max(axis=0) >= -bound[owner[part]],
                np.where(np.logical_or.reduce(sure, axis=0), at[sure.argmax(axis=0), 0], width),
                at[first, 0], at[after, 0])

    near, sure, lo, hi = zip(*(deep(part) for part in _chunks(len(owner), len(at))))
    return np.concatenate(near), np.concatenate(sure), np.concatenate(lo), np.concatenate(hi)


def _touches(px: np.ndarray, py: np.ndarray, owner: np.ndarray, places: tuple[np.ndarray, ...],
             back: np.ndarray, step: float, lo: np.ndarray, hi: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where each sweep touches a cell (``[R, K]``, :func:`_touched`; backing out, ``back
    [R]``) and the pairs of places a cell may be touched between (:func:`_pairs`), worked
    out :data:`CHUNK` elements at a time: the cells ``px, py [M, 1]`` of sweeps ``owner
    [M]`` (sorted) at their sweep's ``places`` (as :func:`_near` takes them), each cell at
    the places of its window ``lo`` to ``hi`` (``[M]`` each, not empty: :func:`_near`'s, up
    to its sweep's first sure touch) one after the other. Outside its window a cell is
    below ``-step``: neither touched nor half of a pair, and below 0 at the start."""
    width = places[0].shape[1]
    hit = np.zeros(places[0].shape, dtype=bool)
    flat_hit = hit.reshape(-1)
    pairs = []
    for part in _spans(hi - lo + 1):
        count = hi[part] - lo[part] + 1
        cell = np.repeat(np.arange(part.start, part.stop), count)             # [N]
        first = np.cumsum(count) - count               # where each cell's places begin
        j = np.arange(len(cell)) - np.repeat(first - lo[part], count)
        at = owner[cell] * width + j                                            # in places
        c, s, cx, cy, *room = (np.take(v, at) for v in places)
        depth = _depth_in(px[cell, 0] - cx, py[cell, 0] - cy, c, s, room)      # [N]
        inside = depth >= 0
        # each cell's depth at the start (below 0 where its window begins later)
        start = np.where(lo[part] == 0, depth[first], -np.inf)[cell - part.start]
        if np.count_nonzero(back[owner[part]]):        # (_touched, a cell at a time)
            away = back[owner[cell]] & (start >= 0)
            inside[away] = depth[away] > start[away]
        flat_hit[at[inside]] = True
        maybe = (depth[:-1] + depth[1:] >= -step) & ~inside[:-1] & ~inside[1:]    # (_pairs)
        maybe &= (cell[1:] == cell[:-1]) & (start[:-1] < 0)   # one cell's, not touched at first
        k = np.flatnonzero(maybe)
        pairs.append((cell[k], j[k]))
    cell, j = (np.concatenate(v) for v in zip(*pairs))
    return hit, cell, j


def _spans(count: np.ndarray) -> list[slice]:
    """The cells (``count [M]`` places each) cut into slices at each multiple of
    :data:`CHUNK` places: a slice ends with the cell whose places reach past the next
    multiple, so it holds up to about twice :data:`CHUNK` (a cell of more, alone)."""
    ends = np.cumsum(count)
    if ends[-1] <= CHUNK:
        return [slice(0, len(count))]
    cuts = np.searchsorted(ends, np.arange(CHUNK, int(ends[-1]), CHUNK), side="right").tolist()
    bounds = sorted({0, *cuts, len(count)})
    return [slice(a, b) for a, b in zip(bounds[:-1], bounds[1:])]


def _coarse(places: int) -> np.ndarray:
    """The places :func:`_near` looks at of ``places``: every ``COARSE``-th and the last."""
    return np.append(np.arange(0, places - 1, COARSE), places - 1)


def _bound(k: np.ndarray, du: np.ndarray, hl: np.ndarray, hw: np.ndarray, half: np.ndarray,
           r: np.ndarray, step: float) -> np.ndarray:
    """The depth a cell must reach at one of the places :func:`_near` looks at to reach
    ``-step`` at a place between (of sweeps of curvature ``k``, places ``du`` apart, half the
    wheelbase ``half``; cells of half side ``r``). Every place is at most ``h = COARSE du /
    2`` of the axle's path from one looked at. Per inch of that path the footprint's centre
    moves 1 along its heading and ``|k| half`` across it, and turns ``|k|`` rad; a cell at
    depth ``-D`` or more lies within ``hl + 1.42 r + D`` of the centre along the heading and
    ``hw + 1.42 r + D`` across it, so there no overlap of :func:`_depth` changes faster than
    ``L = 1 + |k| (F + D)``, ``F = half + hl + hw + 2.83 r``. A cell at ``-T`` or more at a
    place (``T = step + ROUNDING``) is thus at ``-T - L h`` or more within ``h`` of it, which
    is ``-D`` for the ``D`` below. ``ROUNDING`` more covers the rounding of the depth looked
    at as ``T`` does that of the other. Where ``|k| h`` nears 1, no bound (inf)."""
    a = np.abs(k)
    h = COARSE / 2 * du
    f = half + hl + hw + 2 * math.sqrt(2) * r
    d = (step + ROUNDING + h * (1 + a * f)) / np.maximum(1 - a * h, 0.5)
    return np.where(a * h < 0.5, d + ROUNDING, np.inf)


@functools.lru_cache(maxsize=16)
def _path(reach: float, step: float, backward: bool) -> np.ndarray:
    """``[K]`` the rear axle's signed travel at each place of the sweep, ``step`` apart, the
    last at ``reach`` or just past it (a touch short of ``reach`` is never beyond the last)."""
    out = np.arange(math.ceil(reach / step - 1e-9) + 1) * (-step if backward else step)
    out.flags.writeable = False
    return out


def brake(free: float, acceleration: float, margin: float, dt: float = 0.0) -> float:
    """The fastest (in/s) a robot may drive that can stop at ``acceleration`` within ``free``
    inches less ``margin`` when it drives on at that speed for ``dt`` before it brakes (the
    command it is given now is carried out for a tick: ``v dt + v^2 / 2a`` is the room)."""
    lag = acceleration * dt
    return math.sqrt(lag * lag + 2.0 * acceleration * max(free - margin, 0.0)) - lag


def _brakes(free: np.ndarray, acceleration: np.ndarray, margin: float,
            dt: float) -> np.ndarray:
    """:func:`brake` of many robots at once, elementwise: the same bits (a square root is
    correctly rounded in NumPy as in :mod:`math`, and ``np.maximum(a, b)`` is ``max(a, b)``,
    ties and NaN alike)."""
    lag = acceleration * dt
    return np.sqrt(lag * lag + 2.0 * acceleration * np.maximum(free - margin, 0.0)) - lag


def reach_of(robot: Robot, dt: float, cfg: Settings, sight: float) -> float:
    """How far along its arc a robot's brake looks (in): what stopping from its top speed
    takes, a tick's drive and the margin included, a step over (so that nothing in sight
    leaves its top speed free), at least ``cfg.reach`` and at most ``sight``, its sensors'
    range: a robot that needs longer to stop goes no faster than it can stop within what it
    can see (and a robot of 200 in/s braking at 1 in/s^2 does not sweep 20,000 in a tick)."""
    v, a = robot.max_speed, robot.acceleration
    stop = v * dt + v * v / (2.0 * a) + cfg.margin
    if not stop < sight:           # its sight bounds it (inf at `acceleration: 1e-320`)
        return max(cfg.reach, math.ceil(sight))
    return max(cfg.reach, min(math.ceil(stop) + cfg.step, math.ceil(sight)))


@dataclass
class Recovery:
    """One robot's backing out: how long the brake has held it, and the backing-out under way
    (seconds left and the wheel angle)."""

    held: float = 0.0              # s the brake has held it while its planner wanted to go
    left: float = 0.0              # s of backing out left
    wheel: float = 90.0            # deg: the lock it backs out on


@dataclass(frozen=True)
class Body:
    """What the guard needs of one robot at one tick: its pose (x, y in, heading rad), its
    wheel's angle now (deg), the cells it knows are occupied near it (``[P, 2]``, squares of
    half side ``radius``), the side its route lies on (``heading`` input: positive right) and how far
    along its arc its brake looks (:func:`reach_of`)."""

    robot: Robot
    pose: tuple[float, float, float]
    wheel: float
    cells: np.ndarray
    radius: float
    route_side: float
    reach: float = Settings.reach
    speed: float = 0.0                 # in/s: how fast it drives now

    def free(self, wheel: float, backward: bool, cfg: Settings) -> float:
        """Free travel with the wheel at ``wheel`` (deg, 90 straight), forward or backward."""
        return free_travel(self.cells, self.radius, self.pose, self.robot,
                           wheel - self.robot.steering_straight, backward, self.reach, cfg.step)


def guard(command: tuple[float, float], body: Body, rec: Recovery, dt: float,
          cfg: Settings = Settings(),
          known: tuple[float, bool, float] | None = None) -> tuple[tuple[float, float], bool]:
    """The command the robot carries out (steering deg, speed in/s) and whether it begins to
    back out now, from its planner's ``command``: a backing-out under way goes on while the
    way behind is free; otherwise the brake holds the speed to what the arc the wheel will be
    on allows, and a robot held ``patience`` seconds against its planner's wish backs out
    (on the lock that swings its nose toward its route, else straight, else the other lock,
    else on a wheel between them, 15 deg apart from that lock's side), if it has the room.
    ``rec`` is updated. ``known``: the first sweep already measured (wheel, backward, free
    travel: :func:`first_sweep`'s for ``command``, ``body`` and ``rec``, measured with other
    robots' by :meth:`Fleet.guard`), whose wheel is not worked out again."""
    robot = body.robot

    def free(wheel: float, backward: bool) -> float:
        if known is not None and known[:2] == (wheel, backward):
            return known[2]
        return body.free(wheel, backward, cfg)

    first = known
    if rec.left > 0:
        rec.left -= dt
        wheel = _wheel(rec.wheel, body, dt) if known is None else known[0]
        back = free(wheel, True)                 # the arc of the wheel as it will be
        if back > cfg.margin:
            return (rec.wheel, -min(robot.max_reverse,
                                    brake(back, robot.acceleration, cfg.margin, dt))), False
        if wheel != rec.wheel:                   # still turning to the lock: wait for it
            return (rec.wheel, 0.0), False
        rec.left = 0.0
        first = None                             # (the first sweep was the way behind)
    steer, want = command
    wheel = _wheel(steer, body, dt) if first is None else first[0]
    limit = brake(free(wheel, want < 0), robot.acceleration, cfg.margin, dt)
    slowest = max(abs(body.speed) - robot.acceleration * dt, 0.0)
    if slowest > 0 and (body.speed < 0) != (want < 0) and wheel != body.wheel:
        steer, limit = _rolling(steer, limit, wheel, want, slowest, body, free, cfg, dt)
    elif limit < slowest and wheel != body.wheel:
        # turning the wheel puts what it would hit nearer than it can stop: hold the wheel
        # where it is when that arc leaves more room
        hold = brake(free(body.wheel, want < 0), robot.acceleration, cfg.margin, dt)
        if hold > limit:
            steer, limit = body.wheel, hold
    speed = math.copysign(limit, want) if abs(want) > limit else want
    rec.held = rec.held + dt if abs(want) > cfg.want and limit < cfg.want else 0.0
    if rec.held < cfg.patience or robot.max_reverse <= 0:
        return (steer, speed), False
    lock, other = ((robot.steering_min, robot.steering_max) if body.route_side > 0 else
                   (robot.steering_max, robot.steering_min))
    between = _wheels_between(lock, other, robot.steering_straight)
    for wheel in (lock, robot.steering_straight, other) + between:   # rather than stay put
        if free(wheel, True) >= cfg.back_room:
            rec.left, rec.wheel, rec.held = cfg.back_time, wheel, 0.0
            return (wheel, -robot.max_reverse), True
    return (steer, speed), False


def _wheels_between(lock: float, other: float, straight: float,
                    step: float = 15.0) -> tuple[float, ...]:
    """The wheels between the locks, ``step`` apart, from ``lock``'s side to ``other``'s, but
    straight (which is tried before): a robot held where the two locks and straight have no
    room behind may still back out on a wheel between them (BARN's ``barn-1070``, seed 1000,
    kept its wheel while it rolled back, then wedged where 75 deg had 50 in behind and the
    three wheels 0-3 in). Tried only where those three have none, so no backing-out that
    started before goes another way."""
    way = math.copysign(step, other - lock)
    wheels = (lock + way * k for k in range(1, int(abs(other - lock) // step)))
    return tuple(w for w in wheels if w != straight)


def _rolling(steer: float, limit: float, wheel: float, want: float, slowest: float, body: Body,
             free: Callable[[float, bool], float], cfg: Settings,
             dt: float) -> tuple[float, float]:
    """The steer and speed limit of a robot that still rolls against its command (backing
    out just ended, the way ahead of it free again): braking, it rolls on the old way, on
    the arc its wheel turns to, before it can go the new. Where that arc leaves less room
    than the roll needs and the arc it is on leaves as much or more, the wheel stays where
    it is (and the limit is the new way's on that arc): measured along the new way alone, a
    rear swung into a pole while the robot still rolled back at 7.6 in/s. The room is
    compared, not the speeds it allows: inside the margin both allow none, and the arc with
    more room is still the one that stays clear longer. Where neither leaves any (a mark
    inside the body shuts every arc), the wheel stays too: turning it as the robot rolls
    swings the far end of the body sideways, and a BARN robot rolling back 2.2 in from 14
    in/s so turned its front corner into a pole it had sensed (``barn-4026``, seed 4000)."""
    robot, back = body.robot, body.speed < 0
    turned = free(wheel, back)
    if brake(turned, robot.acceleration, cfg.margin, dt) >= slowest:
        return steer, limit
    if free(body.wheel, back) < turned:
        return steer, limit
    return body.wheel, brake(free(body.wheel, want < 0), robot.acceleration, cfg.margin, dt)


def first_sweep(command: tuple[float, float], body: Body, rec: Recovery,
                dt: float) -> tuple[float, bool]:
    """The wheel (deg) and direction (backward?) of the first sweep :func:`guard` measures
    for ``command``: the way behind a backing-out under way, else the arc the wheel turns to."""
    if rec.left > 0:
        return _wheel(rec.wheel, body, dt), True
    return _wheel(command[0], body, dt), command[1] < 0


def _wheel(steer: float, body: Body, dt: float) -> float:
    """Where the wheel is after a tick turning toward ``steer`` at the robot's rate."""
    robot = body.robot
    turn = robot.max_steering_rate * dt
    target = min(max(steer, robot.steering_min), robot.steering_max)
    return body.wheel + min(max(target - body.wheel, -turn), turn)


def rest(n: int) -> np.ndarray:
    """``[n, 3]`` the :class:`Recovery` of ``n`` robots at rest, a row each: held, left, wheel
    (the state :meth:`Fleet.guard` keeps)."""
    calm = Recovery()
    return np.tile([calm.held, calm.left, calm.wheel], (n, 1))


#: What robots' maps hold: ``near(j, centres [R, 2], half [R])``, the centres ``[P, 2]`` of
#: the occupied cells of the maps of robots ``j`` (places in a guard's rows) in the squares
#: of half side ``half`` round ``centres``, a cell taken where its row and column lie in the
#: square's (:meth:`.knowledge.RobotMap.near`, :func:`.knowledge.near_all`).
Near = Callable[[np.ndarray, np.ndarray, np.ndarray], list[np.ndarray]]

#: What sweeps' robots know round their boxes: ``boxed(centres [R, 2], half [R])``, the cells
#: of each sweep's robot in the square of half side ``half`` round ``centres``
#: (:meth:`Fleet.free`).
Boxed = Callable[[np.ndarray, np.ndarray], list[np.ndarray]]

#: The arrays of a :class:`Fleet`, a row per robot.
_FLEET_ROWS = ("radius", "reach", "brakes", "wheelbase", "half", "hl", "hw", "straight", "lo",
               "hi", "turn", "acceleration", "reverse", "squares", "disc", "far")


class Fleet:
    """Robots a guard keeps, a row each, and what of them stays from tick to tick: each one's
    :class:`~.world.Robot`, the half side of its map's cells (``radius``) and how far its
    brake looks (``reach``, :func:`reach_of`), with what :func:`guard` and :func:`_sweep_of`
    work out of them, as arrays ``[N]``. A run holds one fleet of its robots; runs in
    lockstep join theirs into one (:meth:`joined`)."""

    def __init__(self, robots: list[Robot], radius: list[float], reach: list[float], dt: float,
                 cfg: Settings = Settings()) -> None:
        self.robots, self.dt, self.cfg = tuple(robots), dt, cfg
        self.radius, self.reach = np.array(radius, float), np.array(reach, float)

        def each(value: Callable[[Robot], float]) -> np.ndarray:
            return np.array([value(r) for r in robots], float)

        step = cfg.step
        self.brakes = np.array([r.brake for r in robots], dtype=bool)
        self.wheelbase, self.half = each(lambda r: r.wheelbase), each(lambda r: r.wheelbase / 2)
        self.hl, self.hw = each(lambda r: r.length / 2), each(lambda r: r.width / 2)
        self.straight, self.lo, self.hi = (each(lambda r: r.steering_straight),
                                           each(lambda r: r.steering_min),
                                           each(lambda r: r.steering_max))
        self.turn = each(lambda r: r.max_steering_rate * dt)        # deg a tick
        self.acceleration = each(lambda r: r.acceleration)
        self.reverse = each(lambda r: r.max_reverse)
        # in: the half side of the square round it whose cells it brakes for
        self.squares = self.reach + each(lambda r: math.hypot(r.length, r.width))
        self.disc = np.array([_disc(r, rad, step) for r, rad in zip(robots, radius)])
        self.far = np.array([_far(r, rad, step) for r, rad in zip(robots, radius)])

    def __repr__(self) -> str:
        return f"<Fleet of {len(self.robots)} robots, dt {self.dt:g} s>"

    @classmethod
    def joined(cls, fleets: list[Fleet]) -> Fleet:
        """The robots of ``fleets``, one fleet after the other (of one ``dt`` and settings):
        their rows joined, not worked out again (a batch joins its runs' fleets whenever a
        run drops out)."""
        out = cls.__new__(cls)
        out.robots = tuple(r for f in fleets for r in f.robots)
        out.dt, out.cfg = fleets[0].dt, fleets[0].cfg
        for name in _FLEET_ROWS:
            setattr(out, name, np.concatenate([getattr(f, name) for f in fleets]))
        return out

    def guard(self, rows: np.ndarray, command: np.ndarray, state: np.ndarray,
              now: tuple[np.ndarray, ...], cells: list[np.ndarray] | Near) -> list[int]:
        """:func:`guard` of the robots ``rows`` (ascending) at once, on their ``command [N,
        2]`` and their :class:`Recovery` ``state [N, 3]`` (:func:`rest`), both updated in
        place; the rows that begin to back out, in order. ``now``: every row's x, y (in),
        heading (rad), wheel (deg), speed (in/s) and route side, ``[N]`` each; ``cells``:
        what each of ``rows`` knows is occupied near it, or its map (:data:`Near`), asked
        for the square of half side :attr:`squares` round it, and for its first sweep only
        round the sweep's box (:meth:`free`). Their first sweeps (:func:`first_sweep`) are
        measured together; a robot whose command the brake alone decides (no backing out
        under way or to begin, no wheel to hold: most, most ticks) is decided here, the rest
        by :func:`guard` itself, with its first sweep known. One robot is guarded as alone:
        the arrays would cost more than they save."""
        if len(rows) <= 1:
            return [i for i in rows.tolist()
                    if self._one(i, command, state, now, self._own(cells, rows, now, [0])[0])]
        cfg, dt = self.cfg, self.dt
        x, y, h, wheel, speed, _ = (v[rows] for v in now)
        held, left, lock = state[rows].T
        steer, want = command[rows].T
        backing = left > 0
        turned = self._wheels(rows, np.where(backing, lock, steer), wheel)
        back = backing | (want < 0)
        free = self.free(rows, x, y, h, turned, back, cells)
        acceleration = self.acceleration[rows]
        limit = _brakes(free, acceleration, cfg.margin, dt)
        slowest = np.maximum(np.abs(speed) - acceleration * dt, 0.0)
        held = np.where((np.abs(want) > cfg.want) & (limit < cfg.want), held + dt, 0.0)
        rolling = (slowest > 0) & ((speed < 0) != (want < 0))       # against its command
        hard = (backing | (((limit < slowest) | rolling) & (turned != wheel))
                | ((held >= cfg.patience) & (self.reverse[rows] > 0)))
        easy = rows[~hard]
        command[easy, 1] = np.where(np.abs(want) > limit, np.copysign(limit, want), want)[~hard]
        state[easy, 0] = held[~hard]
        hard_rows = hard.nonzero()[0].tolist()
        if not hard_rows:
            return []
        own = self._own(cells, rows, now, hard_rows)
        return [int(rows[j]) for j, mine in zip(hard_rows, own)
                if self._one(int(rows[j]), command, state, now, mine,
                             (turned.item(j), bool(back[j]), free.item(j)))]

    def _own(self, cells: list[np.ndarray] | Near, rows: np.ndarray,
             now: tuple[np.ndarray, ...], picked: list[int]) -> list[np.ndarray]:
        """What the robots ``rows[picked]`` know in their squares (:attr:`squares`): theirs
        of ``cells``, or asked of their maps."""
        if not callable(cells):
            return [cells[j] for j in picked]
        which = rows[picked]
        at = np.empty((len(which), 2))
        at[:, 0], at[:, 1] = now[0][which], now[1][which]
        return cells(np.array(picked, dtype=np.intp), at, self.squares[which])

    def _one(self, i: int, command: np.ndarray, state: np.ndarray, now: tuple[np.ndarray, ...],
             cells: np.ndarray, known: tuple[float, bool, float] | None = None) -> bool:
        """:func:`guard` of the robot of row ``i`` (:meth:`guard`'s arguments, ``cells`` its
        own, ``known`` its first sweep if measured): whether it begins to back out."""
        x, y, h, wheel, speed, side = (v.item(i) for v in now)
        body = Body(self.robots[i], (x, y, h), wheel, cells, self.radius.item(i), side,
                    self.reach.item(i), speed)
        rec = Recovery(*state[i].tolist())
        command[i], backs = guard((command.item(i, 0), command.item(i, 1)), body, rec, self.dt,
                                  self.cfg, known)
        state[i] = rec.held, rec.left, rec.wheel
        return backs

    def _wheels(self, rows: np.ndarray, steer: np.ndarray, wheel: np.ndarray) -> np.ndarray:
        """:func:`_wheel` of the robots ``rows`` (wheels at ``wheel``, turning toward
        ``steer``), with Python's ``min`` and ``max`` to the bit (ties and zeros' signs)."""
        turn = self.turn[rows]
        target = _least(_most(steer, self.lo[rows]), self.hi[rows])
        return wheel + _least(_most(target - wheel, -turn), turn)

    def free(self, rows: np.ndarray, x: np.ndarray, y: np.ndarray, h: np.ndarray,
             wheel: np.ndarray, back: np.ndarray, cells: list[np.ndarray] | Near) -> np.ndarray:
        """:func:`free_travels` of the robots ``rows`` at ``x, y, h``, their wheels at
        ``wheel`` (deg), backward or not (``back``), what each knows being ``cells``, ``[R]``
        each (or asked of their maps, :data:`Near`: round each sweep's box alone, a few
        times fewer cells than the robot's square holds, where that square holds the box;
        its square where not, so the cells in the box are those of the square); each
        sweep's numbers (:func:`_sweep_of`) worked out for all at once in the same Python
        floats."""
        step, reach = self.cfg.step, self.reach[rows]
        if callable(cells):
            some = np.arange(len(rows))
            known: list[np.ndarray] | Boxed = self._boxed(cells, rows, x, y)
        else:
            some = np.fromiter(map(len, cells), np.intp, len(cells)).nonzero()[0]
            if not len(some):
                return reach
            known = [cells[j] for j in some.tolist()]
        which = rows[some]
        reach[some] = _travels(known, self._sweeps(which, x[some], y[some], h[some],
                                                   wheel[some] - self.straight[which]),
                               self.radius[which], reach[some], back[some], step)
        return reach

    def _boxed(self, near: Near, rows: np.ndarray, x: np.ndarray, y: np.ndarray) -> Boxed:
        """What the maps of the robots ``rows`` (at ``x, y``) hold round their sweeps' boxes,
        as :func:`_in_boxes` asks: the square round a box where it lies in the robot's own
        square (:attr:`squares`), else that square, so that no cell outside it is found.
        (The same sums as :func:`.knowledge.near_all`'s corners: a square inside another
        in these floats has its rows and columns among the other's.)"""
        square = self.squares[rows]

        def boxed(centre: np.ndarray, half: np.ndarray) -> list[np.ndarray]:
            bx, by = centre[:, 0], centre[:, 1]
            inside = ((bx - half >= x - square) & (bx + half <= x + square)
                      & (by - half >= y - square) & (by + half <= y + square))
            if not inside.all():
                centre = centre.copy()
                centre[~inside, 0], centre[~inside, 1] = x[~inside], y[~inside]
                half = np.where(inside, half, square)
            return near(np.arange(len(rows)), centre, half)

        return boxed

    def _sweeps(self, rows: np.ndarray, x: np.ndarray, y: np.ndarray, h: np.ndarray,
                delta: np.ndarray) -> tuple[np.ndarray, ...]:
        """:func:`_sweep_of` of the robots ``rows`` at ``x, y, h`` with their wheels
        ``delta`` off straight, ``[R]`` each: the sines, cosines and tangents by :mod:`math`,
        one robot at a time as alone, the rest elementwise in the same order."""
        n, heading = len(rows), h.tolist()
        sin_h = np.fromiter(map(math.sin, heading), float, n)
        cos_h = np.fromiter(map(math.cos, heading), float, n)
        k = -np.fromiter(map(math.tan, map(math.radians, delta.tolist())), float, n) \
            / self.wheelbase[rows]
        half = self.half[rows]
        du = self.cfg.step / (1.0 + np.abs(k) * self.far[rows])
        return (h, k, x - half * cos_h, y - half * sin_h, sin_h, cos_h, half, self.hl[rows],
                self.hw[rows], self.disc[rows], du)


def _most(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Python's ``max(a, b)`` elementwise: ``b`` only where it is greater."""
    return np.where(b > a, b, a)


def _least(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Python's ``min(a, b)`` elementwise: ``b`` only where it is less."""
    return np.where(b < a, b, a)
