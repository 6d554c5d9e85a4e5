"""The dynamic-window baseline (Fox, Burgard and Thrun 1997), as ROS's ``dwa_local_planner``.

The local planner BARN and MRPB publish as their reference, written for the paper's tricycle.
It sees what the fuzzy planner sees (the same ring of range readings, the same route point
ahead) and its commands go through the same steering-rate and acceleration limits. Per tick,
for every robot at once:

1. **The dynamic window.** The commands reachable within ``window_s`` (DWA's control period)
   from the current speed ``v`` and wheel angle ``s``: speeds in ``[v - a T, v + a T]`` within
   ``[0, max_speed]``, wheel angles in ``[s - rate T, s + rate T]`` within the steering range,
   sampled on a ``speed_samples`` x ``steering_samples`` grid (``window_s: None`` makes ``T``
   the world's tick).
2. **Rollouts.** Each sample is commanded for ``horizon_s`` and driven forward with the
   tricycle's limits and exact arcs (:mod:`.kinematics`: the rear axle moves at
   ``v cos(delta)``, the robot turns at ``v sin(delta) / wheelbase``), ``rollout_steps`` poses
   per trajectory, all samples in one array ``[n, samples, steps]``.
3. **Obstacles from the readings.** Every echo shorter than the sensor range is a point in the
   robot's frame, spread over the beam's share of the ring (``echo_points`` points per beam)
   so that a wall seen by a sparse ring reads as a wall, not as a dotted line. The clearance of
   a pose is the distance from its footprint rectangle to the nearest such point; the map and
   the true obstacles are never looked at.
4. **Admissible.** A trajectory that brings the footprint closer than ``collision_in`` (or,
   when the robot is already closer, any closer than it is) is discarded, and so is one whose
   speed cannot be braked to a stop (at the acceleration limit) before the first pose that
   would be that close (Fox et al.'s admissible velocities).
5. **Score.** ``heading_weight * heading + target_weight * progress + path_weight * path +
   clearance_weight * clearance + speed_weight * speed``: *heading* = how well the final
   heading points at the route point ahead (1 aligned, 0 opposite), *progress* = how much
   closer the final pose is to that point (pushed out along its bearing to the horizon's
   reach unless it is the goal), *path* = how near the final pose ends to the route (the
   negated distance to the nearest of the route's points ahead: ROS's ``path_distance_bias``,
   which keeps a fast robot from overshooting a sharp bend of the route, weighted against
   progress as ROS's defaults weigh it against ``goal_distance_bias``, 32 to 24), *speed* =
   the sample's speed, these four scaled to [0, 1] over the admissible samples as Fox et al.
   normalise; *clearance* = the smallest clearance along the trajectory over
   ``clearance_cap_in`` (saturated at 1), absolute, so that a little more room where all is
   tight does not weigh as much as a wall ahead. The best sample is commanded.
6. **No admissible trajectory:** brake as hard as allowed and turn the wheel toward the
   clearest trajectory (ROS would start a recovery behavior; there is none here, so a robot
   boxed in ends ``stuck``).

Everything is NumPy over robots x samples x poses x echo points: no Python loop over samples.
The planner keeps no state (the percepts carry the wheel angle and speed), so runs replay
bit for bit.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .planner import Percepts
    from .world import Robot, World


@dataclass(frozen=True)
class DWAParams:
    """The baseline's parameters (inches, seconds, degrees).

    Defaults follow ROS's ``dwa_local_planner`` where it has a counterpart (``sim_time``
    1.7 s; ``vx_samples`` 3 and ``vth_samples`` 20 -> 5 speeds x 15 wheel angles). The window
    spans ``window_s`` = 0.25 s, not one 0.05 s tick: in one tick the tricycle's wheel turns
    at most 9 deg, every sample is then a near-straight arc, and on the shipped worlds (2
    runs each of seven) the planner wedged itself beside the corridor's box or clipped a
    corner (3 of 14 runs ended in a collision, 5 stuck; with 0.25 s, 1 collision and 2
    stuck). ``collision_in`` and ``clearance_weight`` were set in the same comparison. Nothing
    was set on the BARN fields or MRPB's maps; the shipped worlds of that comparison are also
    the bases of the benchmark's clutter suite (there without their clutter).
    """

    horizon_s: float = 1.7          # s, how long each sampled command is held (sim_time)
    rollout_steps: int = 10         # poses per trajectory (sim_granularity = horizon / steps)
    speed_samples: int = 5          # speeds across the window (vx_samples)
    steering_samples: int = 15      # wheel angles across the window (vth_samples)
    heading_weight: float = 0.8     # aim of the final heading at the route point ahead
    target_weight: float = 1.0      # progress toward the route point ahead (goal_distance_bias)
    path_weight: float = 32.0 / 24.0  # nearness of the final pose to the route (path_distance_bias)
    clearance_weight: float = 1.0   # smallest clearance along the trajectory (occdist_scale)
    speed_weight: float = 0.4       # prefer going fast
    clearance_cap_in: float = 24.0  # in: more clearance than this scores no better
    collision_in: float = 3.0       # in: closer than this to an echo counts as a collision
    echo_points: int = 3            # points per echo, spread over the beam's share of the ring
    window_s: float | None = 0.25   # s the window spans (None: one control period, the tick)
    # the local costmap (MRPB's move_base: a rolling window of 5.5 m at 0.05 m, an obstacle
    # layer that marks echoes within obstacle_range 3 m and clears along each beam)
    memory: bool = True             # remember echoes (False: the current scan only)
    memory_cell_in: float = 0.05 / 0.0254   # one remembered point per cell (resolution)
    memory_window_in: float = 2.75 / 0.0254  # kept within half the rolling window (5.5 m)
    mark_range_in: float = 3.0 / 0.0254     # echoes nearer than this are marked
    # recovery (move_base's clear-costmap recovery): after this long with no admissible
    # trajectory, the memory is cleared to the current scan (an aggressive reset)
    recovery_s: float = 2.0


def _window(current: np.ndarray, step: np.ndarray, lo: np.ndarray, hi: np.ndarray,
            count: int) -> np.ndarray:
    """``count`` evenly spaced values ``[n, count]`` of ``[current - step, current + step]``
    within ``[lo, hi]`` (a window pushed outside the range collapses onto its edge)."""
    a = np.clip(current - step, lo, hi)
    b = np.clip(current + step, lo, hi)
    u = np.linspace(0.0, 1.0, count) if count > 1 else np.full(1, 0.5)
    return a[:, None] + (b - a)[:, None] * u[None, :]


def rollouts(speed: np.ndarray, steering: np.ndarray, cmd_speed: np.ndarray,
             cmd_steering: np.ndarray, robot: Robot, horizon_s: float, steps: int) -> np.ndarray:
    """Poses ``[n, S, steps, 3]`` (x, y, heading in the robot's frame at the start: x ahead,
    y left, rad) of the footprint centre at times ``horizon_s * k / steps``, ``k = 1..steps``,
    when the commands ``cmd_speed``/``cmd_steering [n, S]`` (in/s, deg) are held from the
    current ``speed``/``steering [n]``: in each step the speed and the wheel move toward the
    commands within the acceleration and steering-rate limits and the robot drives an exact
    arc (:func:`.kinematics.advance`), as base_local_planner's ``generateTrajectory`` ramps
    toward its sample. A loop over the ``steps`` poses, each step all samples at once."""
    dt = horizon_s / steps
    v = np.broadcast_to(speed[:, None], cmd_speed.shape).astype(float)
    s = np.broadcast_to(steering[:, None], cmd_steering.shape).astype(float)
    dv, ds = robot.acceleration * dt, robot.max_steering_rate * dt
    half = robot.wheelbase / 2.0
    rx, ry, h = np.full(v.shape, -half), np.zeros(v.shape), np.zeros(v.shape)
    out = np.empty(v.shape + (steps, 3))
    for k in range(steps):
        v = v + np.clip(cmd_speed - v, -dv, dv)
        s = s + np.clip(cmd_steering - s, -ds, ds)
        delta = np.deg2rad(s - robot.steering_straight)
        dh = -v * np.sin(delta) / robot.wheelbase * dt
        half_dh = dh / 2.0
        zero = half_dh == 0.0
        chord = v * np.cos(delta) * dt * np.where(zero, 1.0, np.sin(half_dh)
                                                  / np.where(zero, 1.0, half_dh))
        rx = rx + chord * np.cos(h + half_dh)
        ry = ry + chord * np.sin(h + half_dh)
        h = h + dh
        out[..., k, 0] = rx + half * np.cos(h)
        out[..., k, 1] = ry + half * np.sin(h)
        out[..., k, 2] = h
    return out


def echo_points(ranges: np.ndarray, angles: np.ndarray, max_range: float,
                per_beam: int) -> tuple[np.ndarray, np.ndarray]:
    """Points ``[n, P, 2]`` in the robot frame where the readings saw something, and a mask
    ``[n, P]`` of the real ones: each echo spread over ``per_beam`` directions across its
    share of the ring (the beam spacing), all at the range it read."""
    b = len(angles)
    spacing = 2 * np.pi / b if b > 1 else 0.0
    if b > 1:
        spacing = float(np.min(np.abs(np.diff(np.unwrap(angles))))) or spacing
    offsets = (np.arange(per_beam) - (per_beam - 1) / 2) * (spacing / max(per_beam, 1))
    a = (angles[:, None] + offsets[None, :]).reshape(-1)                # [P]
    r = np.repeat(ranges, per_beam, axis=1)                             # [n, P]
    seen = r < max_range
    return np.stack([r * np.cos(a), r * np.sin(a)], axis=-1), seen


class Workspace:
    """Arrays one call hands to the next. The clearances of 75 rollouts of 10 poses to some
    330 echo points are 2 MB an array, and glibc gives freed blocks that large back to the
    system at once: fresh arrays every tick cost their page faults, half of a DWA run's
    time in the kernel (slalom 4.2 s, 2.0 of them system time; 1.9 s reusing them)."""

    def __init__(self) -> None:
        self._flat = np.empty(0)

    def arrays(self, shape: tuple[int, ...], count: int) -> list[np.ndarray]:
        """``count`` arrays of ``shape``, their contents undefined."""
        size = int(np.prod(shape))
        if self._flat.size < count * size:
            self._flat = np.empty(count * size)
        return [self._flat[k * size:(k + 1) * size].reshape(shape) for k in range(count)]


_SCRATCH = threading.local()


def scratch() -> Workspace:
    """This thread's :class:`Workspace`: one for all the planners it steps (runs in lockstep
    plan one after another; a workspace each held 10-20 MB per run of a batch of 128), and
    none shared between threads, which may plan at once."""
    work = getattr(_SCRATCH, "work", None)
    if work is None:
        work = _SCRATCH.work = Workspace()
    return work


def footprint_clearance(poses: np.ndarray, points: np.ndarray, seen: np.ndarray,
                        length: float, width: float,
                        work: Workspace | None = None) -> np.ndarray:
    """Distance ``[n, S, T]`` from a ``length`` x ``width`` footprint at each pose to the
    nearest seen point (0 when a point is inside it; ``inf`` when nothing was seen); the
    ``[n, S, T, P]`` arrays are ``work``'s (a new one's: ``None``), the same arithmetic in
    the same order as ``max(|c dx + s dy| - length / 2, 0)`` and its twin written out."""
    keep = seen.any(axis=0)                     # points no robot saw are left out at once
    if not keep.any():
        return np.full(poses.shape[:-1], np.inf)
    far = np.where(seen[:, keep, None], points[:, keep], 1e6)          # [n, P, 2]
    dx, dy, lx, ly = (work or Workspace()).arrays(poses.shape[:-1] + far.shape[1:2], 4)
    np.subtract(far[:, None, None, :, 0], poses[..., 0, None], out=dx)    # [n, S, T, P]
    np.subtract(far[:, None, None, :, 1], poses[..., 1, None], out=dy)
    c, s = np.cos(poses[..., 2, None]), np.sin(poses[..., 2, None])
    _side(np.add(np.multiply(c, dx, out=lx), np.multiply(s, dy, out=ly), out=lx), length)
    _side(np.subtract(np.multiply(c, dy, out=ly), np.multiply(s, dx, out=dx), out=ly), width)
    np.add(np.multiply(lx, lx, out=lx), np.multiply(ly, ly, out=ly), out=lx)
    d = np.sqrt(lx.min(axis=-1))
    return np.where(d > 1e5, np.inf, d)


def _side(x: np.ndarray, size: float) -> None:
    """``x`` becomes ``max(|x| - size / 2, 0)``, in place: how far outside the footprint."""
    np.maximum(np.subtract(np.abs(x, out=x), size / 2, out=x), 0.0, out=x)


def _scaled(x: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """``x [n, S]`` scaled to [0, 1] over the admissible samples of each row (0 where all
    admissible samples score the same)."""
    lo = np.min(np.where(ok, x, np.inf), axis=1, keepdims=True)
    hi = np.max(np.where(ok, x, -np.inf), axis=1, keepdims=True)
    span = hi - lo
    good = np.isfinite(span) & (span > 1e-12)
    return np.where(good, (x - np.where(good, lo, 0.0)) / np.where(good, span, 1.0), 0.0)


def dwa_command(params: DWAParams, target: np.ndarray, speed: np.ndarray,
                steering: np.ndarray, ranges: np.ndarray, angles: np.ndarray,
                max_range: float, robot: Robot, dt: float,
                memory: list[np.ndarray] | None = None,
                path: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Commanded (wheel angle [n] deg, speed [n] in/s) for ``n`` robots at once.

    ``target [n, 2]`` the route point ahead in the robot frame (in, x ahead, y left);
    ``speed``/``steering [n]`` the current ones; ``ranges [n, B]`` the readings at beam
    ``angles [B]`` (rad, CCW); ``robot`` the footprint and limits; ``dt`` the control period;
    ``memory``: each robot's remembered points in its frame (:class:`Costmap`), which then
    stand for the echoes nearer than ``mark_range_in``; ``path [n, K, 2]``: the route's points
    ahead in each robot's frame (scored by how near each rollout ends to them), or None.
    """
    out_s, out_v, _ = _command(params, target, speed, steering, ranges, angles, max_range,
                               robot, dt, memory, path)
    return out_s, out_v


def _obstacles(params: DWAParams, ranges: np.ndarray, angles: np.ndarray, max_range: float,
               memory: list[np.ndarray] | None) -> tuple[np.ndarray, np.ndarray]:
    """Obstacle points ``[n, P, 2]`` in each robot's frame and which are real ``[n, P]``: the
    current echoes, or the remembered points and the echoes beyond the marking range."""
    points, seen = echo_points(ranges, angles, max_range, params.echo_points)
    if memory is None:
        return points, seen
    seen = seen & (np.repeat(ranges, params.echo_points, axis=1) >= params.mark_range_in)
    m = max((len(x) for x in memory), default=0)
    extra = np.zeros((len(memory), m, 2))
    real = np.zeros((len(memory), m), dtype=bool)
    for i, x in enumerate(memory):
        extra[i, :len(x)] = x
        real[i, :len(x)] = True
    return np.concatenate([points, extra], axis=1), np.concatenate([seen, real], axis=1)


def _command(params: DWAParams, target: np.ndarray, speed: np.ndarray, steering: np.ndarray,
             ranges: np.ndarray, angles: np.ndarray, max_range: float, robot: Robot, dt: float,
             memory: list[np.ndarray] | None,
             path: np.ndarray | None = None, work: Workspace | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`dwa_command`, and which robots had no admissible trajectory (``path [n, K, 2]``:
    the route's points ahead in each robot's frame, or None; ``work``: arrays kept from the
    call before)."""
    p = params
    n = len(speed)
    full = np.ones(n)
    span = dt if p.window_s is None else p.window_s
    vs = _window(speed, full * robot.acceleration * span, 0 * full, full * robot.max_speed,
                 p.speed_samples)                                       # [n, V]
    ss = _window(steering, full * robot.max_steering_rate * span, full * robot.steering_min,
                 full * robot.steering_max, p.steering_samples)         # [n, W]
    V, W = vs.shape[1], ss.shape[1]
    v = np.repeat(vs, W, axis=1)                                        # [n, S] speed-major
    s = np.tile(ss, (1, V))
    poses = rollouts(speed, steering, v, s, robot, p.horizon_s, p.rollout_steps)
    points, seen = _obstacles(p, ranges, angles, max_range, memory)
    # an echo farther than any rollout's end plus the body and the clearance cap cannot
    # change a score: leave it out (most of a corridor's far walls)
    reach = vs[:, -1] * p.horizon_s + np.hypot(robot.length, robot.width) / 2 \
        + p.clearance_cap_in
    seen &= np.hypot(points[..., 0], points[..., 1]) <= reach[:, None]
    clear = footprint_clearance(poses, points, seen, robot.length, robot.width, work)
    now = footprint_clearance(np.zeros((n, 1, 1, 3)), points, seen, robot.length,
                              robot.width)[:, 0, 0]                     # [n]
    limit = np.minimum(p.collision_in, np.maximum(now - 0.5, 0.0))[:, None, None]
    close = clear <= limit                                              # [n, S, T]
    hits = close.any(axis=2)
    # arc length travelled until the first pose that is too close (the whole horizon if none)
    steps = np.arange(1, p.rollout_steps + 1) / p.rollout_steps
    first = np.where(hits, np.argmax(close, axis=2), p.rollout_steps - 1)
    run = v * p.horizon_s * steps[np.maximum(first - 1, 0)] * (first > 0)
    brake = v * v / (2.0 * robot.acceleration)
    ok = ~hits | (brake < run)
    ok &= ~hits | (v <= vs[:, :1])         # a trajectory that hits is kept only at the slowest

    end = poses[:, :, -1, :]                                            # [n, S, 3]
    to_t = target[:, None, :] - end[..., :2]
    bearing = np.arctan2(to_t[..., 1], to_t[..., 0]) - end[..., 2]
    heading = (1.0 + np.cos(bearing)) / 2.0
    progress = np.hypot(target[:, 0], target[:, 1])[:, None] - np.hypot(to_t[..., 0],
                                                                          to_t[..., 1])
    room = np.minimum(clear.min(axis=2), p.clearance_cap_in) / p.clearance_cap_in
    score = (p.heading_weight * _scaled(heading, ok) + p.target_weight * _scaled(progress, ok)
             + p.clearance_weight * room + p.speed_weight * _scaled(v, ok))
    if path is not None:                   # how near each final pose ends to the route
        gap = poses[:, :, -1, None, :2] - path[:, None]                # [n, S, K, 2]
        off = np.sqrt((gap * gap).sum(axis=-1)).min(axis=-1)           # [n, S]
        score = score + p.path_weight * _scaled(-off, ok)
    score = np.where(ok, score, -np.inf)
    best = np.argmax(score, axis=1)
    rows = np.arange(n)
    stuck = ~ok.any(axis=1)
    out_s = np.where(stuck, s[rows, np.argmax(np.where(np.isfinite(room), room, 1e9), axis=1)],
                     s[rows, best])
    out_v = np.where(stuck, 0.0, v[rows, best])
    return out_s, out_v, stuck


@dataclass
class Costmap:
    """What one robot's DWA remembers: echo points in the world frame, one per cell, marked
    when seen and cleared when a later beam passes through them (ROS's obstacle layer)."""

    points: np.ndarray                 # [M, 2] world frame (in)
    blocked_s: float = 0.0             # how long no trajectory has been admissible

    @classmethod
    def empty(cls) -> Costmap:
        return cls(np.zeros((0, 2)))

    def update(self, params: DWAParams, pose: np.ndarray, ranges: np.ndarray,
               angles: np.ndarray, max_range: float) -> None:
        """Clear what the beams now see through, mark what they hit, keep the window."""
        x, y, h = pose
        c, s = np.cos(h), np.sin(h)
        pts = self.points
        if len(pts):
            rel = pts - (x, y)
            dist = np.hypot(rel[:, 0], rel[:, 1])
            bearing = np.arctan2(rel[:, 1], rel[:, 0]) - h
            diff = np.angle(np.exp(1j * (bearing[:, None] - angles[None, :])))
            beam = np.argmin(np.abs(diff), axis=1)
            spacing = 2 * np.pi / len(angles) if len(angles) > 1 else np.pi
            if len(angles) > 1:
                spacing = float(np.min(np.abs(np.diff(np.unwrap(angles))))) or spacing
            covered = np.abs(diff[np.arange(len(pts)), beam]) <= spacing / 2
            through = covered & (ranges[beam] > dist + params.memory_cell_in)
            near = np.maximum(np.abs(rel[:, 0]), np.abs(rel[:, 1])) <= params.memory_window_in
            pts = pts[~through & near]
        local, seen = echo_points(ranges[None], angles, max_range, params.echo_points)
        local = local[0][seen[0] & (np.repeat(ranges, params.echo_points)
                                    < params.mark_range_in)]
        new = np.stack([x + c * local[:, 0] - s * local[:, 1],
                        y + s * local[:, 0] + c * local[:, 1]], axis=1)
        both = np.concatenate([new, pts])             # newest first: it wins its cell
        cells = np.floor(both / params.memory_cell_in).astype(np.int64)
        _, first = np.unique(cells, axis=0, return_index=True)
        self.points = both[np.sort(first)]

    def local(self, pose: np.ndarray) -> np.ndarray:
        """The remembered points ``[M, 2]`` in the robot's frame (x ahead, y left)."""
        x, y, h = pose
        c, s = np.cos(h), np.sin(h)
        rel = self.points - (x, y)
        return np.stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1]], axis=1)


class DWAPlanner:
    """The dynamic window as a :class:`~mitos_cli.sim.planner.Planner` (picklable).

    ``robot`` gives the footprint and the limits, ``dt`` the control period (the world's tick);
    in a world of several robots every robot is taken to be this one, as the potential field
    does. Its memory (:class:`Costmap`, one per robot) lives for one run: the simulator asks
    for a :meth:`fresh` planner at the start of every run, so runs replay bit for bit.
    """

    name = "dwa"

    def __init__(self, robot: Robot, sensor_range: float, dt: float,
                 params: DWAParams | None = None) -> None:
        self.robot = robot
        self.sensor_range = float(sensor_range)
        self.dt = float(dt)
        self.params = params or DWAParams()
        self._maps: dict[int, Costmap] = {}

    @classmethod
    def for_world(cls, world: World, params: DWAParams | None = None) -> DWAPlanner:
        return cls(world.agents[0].robot, world.sensors.range, world.dt, params)

    @property
    def path_reach(self) -> float:
        """How far along its route ahead the planner is given points (``Percepts.path``):
        as far as its fastest rollout drives."""
        return self.robot.max_speed * self.params.horizon_s

    def fresh(self) -> DWAPlanner:
        """The same planner with nothing remembered (a run's start)."""
        return DWAPlanner(self.robot, self.sensor_range, self.dt, self.params)

    def _memory(self, p: Percepts) -> list[np.ndarray] | None:
        """Each robot's costmap brought up to date with its readings, in its frame."""
        if not self.params.memory:
            return None
        robots = range(len(p.pose)) if p.robots is None else p.robots.tolist()
        angles = np.asarray(p.beam_angles, float)
        out = []
        for row, i in enumerate(robots):
            cm = self._maps.setdefault(int(i), Costmap.empty())
            cm.update(self.params, p.pose[row], np.asarray(p.ranges[row], float), angles,
                      self.sensor_range)
            out.append(cm.local(p.pose[row]))
        return out

    def _recover(self, p: Percepts, stuck: np.ndarray) -> None:
        """move_base's clear-costmap recovery: blocked for ``recovery_s``, a robot forgets
        all but what its current scan shows."""
        if not self.params.memory:
            return
        robots = range(len(p.pose)) if p.robots is None else p.robots.tolist()
        for row, i in enumerate(robots):
            cm = self._maps[int(i)]
            cm.blocked_s = cm.blocked_s + self.dt if stuck[row] else 0.0
            if cm.blocked_s >= self.params.recovery_s:
                cm.points, cm.blocked_s = np.zeros((0, 2)), 0.0

    def plan(self, p: Percepts) -> tuple[np.ndarray, np.ndarray]:
        n = len(p.pose)
        h = p.pose[:, 2]
        dx, dy = p.target[:, 0] - p.pose[:, 0], p.target[:, 1] - p.pose[:, 1]
        c, s = np.cos(h), np.sin(h)
        target = np.stack([c * dx + s * dy, -s * dx + c * dy], axis=1)
        # the route point ahead, pushed out along its bearing to the horizon's reach unless
        # it is the goal: progress toward a point nearer than a fast rollout ends would
        # reward slowing down (ROS scores against the end of the local plan for this reason)
        dist = np.hypot(target[:, 0], target[:, 1])
        reach = self.robot.max_speed * self.params.horizon_s
        at_goal = np.hypot(p.target[:, 0] - p.goal[:, 0], p.target[:, 1] - p.goal[:, 1]) < 1e-6
        scale = np.where(at_goal | (dist < 1e-9), 1.0, np.maximum(dist, reach)
                         / np.maximum(dist, 1e-9))
        target = target * scale[:, None]
        steering = (np.full(n, self.robot.steering_straight) if p.steering is None
                    else np.asarray(p.steering, float))
        path = getattr(p, "path", None)
        if path is not None:                  # the route ahead, in each robot's frame
            rel = np.asarray(path, float) - p.pose[:, None, :2]
            path = np.stack([c[:, None] * rel[..., 0] + s[:, None] * rel[..., 1],
                             -s[:, None] * rel[..., 0] + c[:, None] * rel[..., 1]], axis=-1)
        out_s, out_v, stuck = _command(
            self.params, target, np.asarray(p.speed, float), steering,
            np.asarray(p.ranges, float), np.asarray(p.beam_angles, float), self.sensor_range,
            self.robot, self.dt, self._memory(p), path, scratch())
        self._recover(p, stuck)
        return out_s, out_v
