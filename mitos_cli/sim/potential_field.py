"""The classical baseline: an artificial potential field (Khatib 1986) driving the tricycle.

What robotics users would pick instead of fuzzy rules, and what the paper names as a partner
for its planner. It sees what the fuzzy planner sees (the same ring of range sensors, the same
route waypoints) and drives the same robot through the same limits (the simulator applies the
steering-rate and acceleration limits to whatever a planner commands).

In the robot's frame (x forward, y to the left), per tick:

- **attraction** to the target (the route's next waypoint, the goal at the end):
  ``F_att = k_att * t / |t|`` -- a unit pull, so the push of walls is comparable everywhere;
- **repulsion** from every beam whose echo is closer than ``influence_in`` to the body:
  with clearance ``d`` (range minus the distance from the centre to the footprint's edge in
  that direction), ``F_rep = -k_rep (1/d - 1/d0) / d^2 * u`` (``u`` the beam's direction),
  the gradient of Khatib's FIRAS potential ``k_rep/2 (1/d - 1/d0)^2``. Walls on both sides
  push from both sides, which centres the robot in a corridor;
- **steering** toward the resulting force: ``phi = atan2(F_y, F_x)``, steering
  ``90 - gain * phi`` (deg; below 90 turns left), clipped to the robot's steering range;
- **speed**: ``max_speed`` scaled down by the clearance ahead (to 0 at ``stop_in``), by how
  far the force points away from straight ahead (``cos(phi)``, at least ``turn_floor``) and by
  the distance to the goal (within ``goal_slow_in``), never below ``min_speed`` unless a stop
  is due.

Its known weakness is the classical one: where attraction and repulsion cancel (an obstacle
dead ahead and symmetric, a U-shaped trap) the force vanishes or points back and the robot
stops or oscillates -- the simulator reports that as ``stuck`` or ``timeout``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .planner import Percepts
    from .world import Robot, World


@dataclass(frozen=True)
class PotentialFieldParams:
    """The baseline's parameters (inches, seconds, degrees).

    Defaults chosen by a grid search on the shipped corridor, slalom and intersection worlds
    (k_rep 500 / 2000 / 6000, influence 40 / 70, gain 1 / 2, slow_in 40 / 70; 6 randomised
    runs each): every setting with k_rep >= 500 reached the goal in all 18 runs, and these
    were the fastest (docs/study.md).
    """

    k_att: float = 1.0               # pull toward the target (a unit vector times this)
    k_rep: float = 500.0             # in^3, strength of the repulsion (force is unitless)
    influence_in: float = 40.0       # d0: obstacles farther than this from the body are ignored
    gain: float = 1.0                # deg of steering per deg of force direction
    stop_in: float = 4.0             # clearance ahead at which the robot stops
    slow_in: float = 40.0            # clearance ahead below which it slows down
    ahead_deg: float = 35.0          # half-width of the cone that counts as "ahead"
    turn_floor: float = 0.35         # smallest speed factor for turning
    min_speed: float = 6.0           # in/s, creep speed (unless a stop is due)
    goal_slow_in: float = 40.0       # slow down within this distance of the goal


def body_extent(angles: np.ndarray, length: float, width: float) -> np.ndarray:
    """Distance from the centre of a ``length`` x ``width`` rectangle to its edge, per angle."""
    c, s = np.abs(np.cos(angles)), np.abs(np.sin(angles))
    with np.errstate(divide="ignore"):
        along = np.where(c > 1e-12, (length / 2.0) / np.maximum(c, 1e-12), np.inf)
        across = np.where(s > 1e-12, (width / 2.0) / np.maximum(s, 1e-12), np.inf)
    return np.minimum(along, across)


def field_command(params: PotentialFieldParams, target: np.ndarray, angles: np.ndarray,
                  ranges: np.ndarray, max_range: float, extent: np.ndarray,
                  goal_distance: np.ndarray, max_speed: np.ndarray,
                  steering_min: np.ndarray, steering_max: np.ndarray,
                  straight: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Steering (deg), speed (in/s) and the force direction (deg) for ``n`` robots at once.

    ``target[n, 2]`` in the robot frame (in); ``angles[b]`` beam directions (rad, CCW from
    the heading); ``ranges[n, b]`` echoes (``>= max_range``: nothing seen); ``extent[b]`` the
    body's half-size per beam; ``goal_distance[n]``; limits as arrays ``[n]``.
    """
    p = params
    ranges = np.asarray(ranges, dtype=float)
    n = ranges.shape[0]
    t = np.asarray(target, dtype=float).reshape(n, 2)
    t_norm = np.hypot(t[:, 0], t[:, 1])
    pull = p.k_att * t / np.maximum(t_norm, 1e-9)[:, None]

    d = np.maximum(ranges - extent[None, :], 0.5)            # clearance per beam, in
    seen = (ranges < max_range) & (d < p.influence_in)
    mag = np.where(seen, p.k_rep * (1.0 / d - 1.0 / p.influence_in) / (d * d), 0.0)
    push = -np.stack([mag @ np.cos(angles), mag @ np.sin(angles)], axis=1)

    force = pull + push
    phi = np.degrees(np.arctan2(force[:, 1], force[:, 0]))   # + = to the left
    steering = np.clip(straight - p.gain * phi, steering_min, steering_max)

    ahead = np.abs(np.degrees(angles)) <= p.ahead_deg
    ahead |= np.abs(np.degrees(angles) - 360.0) <= p.ahead_deg
    clear_ahead = np.min(np.where(ahead[None, :], d, np.inf), axis=1) if ahead.any() \
        else np.full(n, np.inf)
    slow = np.clip((clear_ahead - p.stop_in) / (p.slow_in - p.stop_in), 0.0, 1.0)
    turn = np.maximum(np.cos(np.radians(np.minimum(np.abs(phi), 90.0))), p.turn_floor)
    near_goal = np.clip(goal_distance / p.goal_slow_in, 0.25, 1.0)
    speed = max_speed * slow * turn * near_goal
    speed = np.where(clear_ahead <= p.stop_in, 0.0, np.maximum(speed, p.min_speed))
    return steering, np.minimum(speed, max_speed), phi


class PotentialFieldPlanner:
    """The potential field as a :class:`~mitos_cli.sim.planner.Planner` (picklable, stateless).

    ``robot`` gives the footprint (to turn ranges into clearances) and the limits; in a world
    with several robots every robot is taken to be this one (the shipped worlds use one model).
    """

    name = "potential_field"

    def __init__(self, robot: Robot, sensor_range: float,
                 params: PotentialFieldParams | None = None) -> None:
        self.robot = robot
        self.sensor_range = float(sensor_range)   # in: a reading this far saw nothing
        self.params = params or PotentialFieldParams()

    @classmethod
    def for_world(cls, world: World, params: PotentialFieldParams | None = None) -> PotentialFieldPlanner:
        return cls(world.agents[0].robot, world.sensors.range, params)

    def plan(self, p: Percepts) -> tuple[np.ndarray, np.ndarray]:
        r = self.robot
        n = len(p.pose)
        x, y, h = p.pose[:, 0], p.pose[:, 1], p.pose[:, 2]
        dx, dy = p.target[:, 0] - x, p.target[:, 1] - y
        c, s = np.cos(h), np.sin(h)
        target = np.stack([c * dx + s * dy, -s * dx + c * dy], axis=1)
        goal_distance = np.hypot(p.goal[:, 0] - x, p.goal[:, 1] - y)
        full = np.full(n, 1.0)
        steering, speed, _phi = field_command(
            self.params, target, p.beam_angles, p.ranges, self.sensor_range,
            body_extent(p.beam_angles, r.length, r.width), goal_distance,
            full * r.max_speed, full * r.steering_min, full * r.steering_max,
            full * r.steering_straight)
        return steering, speed
