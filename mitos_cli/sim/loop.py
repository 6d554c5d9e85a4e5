"""The simulation loop: sense, perceive, plan (one batch for all robots), move; then verdict and
metrics. Stepping never draws; the :class:`SimResult` holds every tick as arrays.

Per tick ``k`` (time ``k * dt``): obstacles are placed at that time; each robot casts its beams
and perceives its inputs (the true values are computed afterwards, on demand, from the recorded
poses: :func:`true_inputs`); a robot whose footprint touches anything has collided
(the run ends); a robot within its goal's tolerance is done (it stops and stays as an obstacle);
the planner evaluates all active robots in one batch; the kinematics apply the steering-rate and
acceleration limits and integrate in ``substeps`` exact arcs. The run ends in ``success`` (every
robot at its goal), ``collision``, ``stuck`` (a robot moved less than ``STUCK_DISTANCE`` in
``STUCK_TIME``) or ``timeout``.

Randomness: ``SeedSequence(seed).spawn(1 + robots)``: the first stream randomises the world
(only when asked, for ``--runs``), then one stream of sensor noise per robot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import geometry, kinematics, obstacles as obs_mod, perception, sensors
from .geometry import box_polygon_depth, box_polygon_distance, box_segment_distance, \
    polygon_segments, rect_corners
from .planner import Percepts, Planner
from .route import Route, plan_route
from .staticmap import StaticMap, build_static
from .world import World

STUCK_TIME = 6.0        # s
STUCK_DISTANCE = 3.0    # in
NEAR_SLACK = 24.0       # in: a robot's set of nearby walls is gathered again after this move
OUTCOMES = ("success", "collision", "timeout", "stuck")


@dataclass(frozen=True)
class Scene:
    """What does not change during a run: the walls and each robot's route."""

    static: StaticMap
    routes: tuple[Route, ...]

    def __hash__(self) -> int:
        return id(self)


def prepare(world: World) -> Scene:
    """Walls and routes (A* over the corridors or the grid) of a world."""
    static = build_static(world)
    routes = tuple(plan_route(static, world.corridors, a.start, a.goal,
                              clearance=a.robot.width / 2 + a.robot.safety_margin + 4.0)
                   for a in world.agents)
    return Scene(static, routes)


@dataclass
class SimResult:
    """A finished run: verdict, metrics and every tick as arrays (``T`` ticks, ``n`` robots)."""

    world: World
    seed: int
    planner: str
    outcome: str
    robot_outcomes: tuple[str, ...]
    collisions: int
    t: np.ndarray                  # [T] s
    pose: np.ndarray               # [T, n, 3] x, y (in), heading (deg)
    speed: np.ndarray              # [T, n] in/s
    steering: np.ndarray           # [T, n] deg (the wheel's actual angle)
    command: np.ndarray            # [T, n, 2] planner's steering and speed
    ranges: np.ndarray             # [T, n, B] in (noisy readings)
    perceived: dict[str, np.ndarray]   # name -> [T, n]
    clearance: np.ndarray          # [T, n] in, footprint to the nearest thing
    obstacles: np.ndarray          # [T, O, 2] obstacle positions
    routes: tuple[Route, ...] = ()
    static: StaticMap | None = None
    active: np.ndarray | None = None   # [T, n] robot still driving at that tick
    progress: np.ndarray | None = None  # [T, n] arc length along each robot's route (in)
    metrics: dict = field(default_factory=dict)    # the run's figures over all robots
    robot_metrics: tuple[dict, ...] = ()           # each robot's figures (name, outcome, ...)
    _true: dict | None = field(default=None, repr=False)

    @property
    def true(self) -> dict[str, np.ndarray]:
        """The inputs from the true geometry, name -> ``[T, n]`` (computed on first use from
        the recorded poses and obstacle places: stepping does not need them)."""
        if self._true is None:
            self._true = true_inputs(self)
        return self._true

    @property
    def ticks(self) -> int:
        return len(self.t)

    def summary(self) -> dict:
        """The ``--json`` contract: the run's figures over all robots and, when there are
        several, each robot's under ``robots``."""
        out = {"world": self.world.name, "seed": self.seed, "outcome": self.outcome,
               "reached_goal": all(o == "success" for o in self.robot_outcomes),
               **self.metrics}
        if len(self.robot_metrics) > 1:
            out["robots"] = [dict(m) for m in self.robot_metrics]
        return out


def _stop_ticks(res: SimResult) -> np.ndarray:
    """``[n]`` ticks each robot drove: to the tick it stopped at its goal, else the whole run."""
    stopped = ~res.active.reshape(res.ticks, len(res.robot_outcomes))
    return np.where(stopped.any(axis=0), stopped.argmax(axis=0) + 1, res.ticks)


def _robot_metrics(res: SimResult, dt: float) -> tuple[dict, ...]:
    """Each robot's figures up to the tick it stopped (at its goal) or the run ended: its time,
    path, mean speed over that time and steering variation; its clearance over the whole run
    (a robot at its goal is still something the others can hit)."""
    out = []
    for i, (agent, outcome, ticks) in enumerate(zip(res.world.agents, res.robot_outcomes,
                                                   _stop_ticks(res).tolist())):
        xy = res.pose[:ticks, i, :2]
        path = float(np.hypot(*np.diff(xy, axis=0).T).sum()) if len(xy) > 1 else 0.0
        time_s = float(ticks * dt)
        out.append({
            "name": agent.name, "outcome": outcome, "reached_goal": outcome == "success",
            "time_s": round(time_s, 6), "path_length_in": path,
            "min_clearance_in": float(res.clearance[:, i].min()) if res.ticks else 0.0,
            "mean_speed_in_s": path / time_s if time_s > 0 else 0.0,
            "steering_total_variation_deg":
                float(np.abs(np.diff(res.steering[:ticks, i])).sum())})
    return tuple(out)


def _metrics(res: SimResult, dt: float) -> dict:
    """The run's figures over all robots (one robot: its own): the time until the last robot
    stopped, the path and the steering variation summed over the robots, the mean speed of
    all the driving (total path over total driving time), the smallest clearance of any."""
    each = res.robot_metrics
    path = sum(m["path_length_in"] for m in each)
    driving = float(_stop_ticks(res).sum() * dt)
    return {"collisions": sum(m["outcome"] == "collision" for m in each),
            "time_s": round(float(res.ticks * dt), 6), "path_length_in": path,
            "min_clearance_in": min(m["min_clearance_in"] for m in each),
            "mean_speed_in_s": path / driving if driving > 0 else 0.0,
            "steering_total_variation_deg": sum(m["steering_total_variation_deg"]
                                                for m in each),
            "ticks": int(res.ticks)}


def _footprints(pose: np.ndarray, robots) -> np.ndarray:
    return rect_corners(pose[:, 0], pose[:, 1], pose[:, 2],
                        np.array([r.length for r in robots]), np.array([r.width for r in robots]))


def _clearance(pose: np.ndarray, robot, walls: np.ndarray, polygons: np.ndarray,
               centres: np.ndarray, radii: np.ndarray) -> float:
    """Signed distance from one robot's footprint to walls, rectangles and other robots
    (``polygons [P, 4, 2]``) and circles, computed in the footprint's own frame: the gap when
    apart, 0 touching, minus the penetration depth (the shortest move that separates them) when
    overlapping, with one definition for every kind of thing."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    hl, hw = robot.length / 2, robot.width / 2

    def local(points: np.ndarray) -> np.ndarray:        # [..., 2] world -> footprint frame
        rel = points - pose[:2]
        return np.stack([rel[..., 0] * c + rel[..., 1] * s,
                         -rel[..., 0] * s + rel[..., 1] * c], axis=-1)

    best = math.inf
    ends = local(walls.reshape(-1, 2, 2))
    boxes = local(polygons)
    d = box_segment_distance(hl, hw, np.concatenate([ends.reshape(-1, 4),
                                                     polygon_segments(boxes)]))
    if len(walls):                                      # one call for walls and box sides
        w = d[:len(ends)]
        crossing = w <= 0.0
        if crossing.any():
            w[crossing] = -box_polygon_depth(hl, hw, ends[crossing])
        best = float(w.min())
    if len(polygons):
        sides = d[len(ends):]
        best = min(best, float(box_polygon_distance(hl, hw, boxes, sides).min()))
    if len(centres):
        rel = centres - pose[:2]
        lx = np.abs(rel[:, 0] * c + rel[:, 1] * s) - hl
        ly = np.abs(-rel[:, 0] * s + rel[:, 1] * c) - hw
        outside = np.hypot(np.maximum(lx, 0), np.maximum(ly, 0))
        inside = np.minimum(np.maximum(lx, ly), 0)
        best = min(best, float((outside + inside - radii).min()))
    return best


def simulate(world: World, planner: Planner | None = None, seed: int | None = None, *,
             randomise: bool = False, scene: Scene | None = None,
             on_tick=None) -> SimResult:
    """Run ``world`` with ``planner`` (default: the packaged rule base's ``drive``) from
    ``seed`` (default: the world's). ``randomise`` draws obstacle places and sensor noise from
    the world's ranges first. ``on_tick(k, state)`` is called after each tick (``--live``)."""
    if planner is None:
        from .planner import FuzzyPlanner

        planner = FuzzyPlanner(None, world.behavior)
    seed = world.seed if seed is None else int(seed)
    streams = [np.random.default_rng(s) for s in
               np.random.SeedSequence(seed).spawn(1 + len(world.agents))]
    if randomise:
        world = obs_mod.randomised(world, streams[0])
    scene = scene or prepare(world)
    static, routes = scene.static, scene.routes
    agents = world.agents
    robots = [a.robot for a in agents]
    n = len(agents)
    lim = kinematics.Limits.of(robots)
    sen = world.sensors
    angles = sen.angles
    B = len(angles)
    spacing = (2 * math.pi / B if sen.layout == "ring"
               else math.radians(sen.fov) / max(B - 1, 1))
    spacing = min(spacing, 2 * math.tan(math.radians(sen.cone) / 2)) if sen.cone > 0 else 0.0
    threshold = max(4.0, 3.0 * sen.noise)
    reach = sen.range + max(max(r.length, r.width) for r in robots)
    cfg = perception.Settings()

    dt, sub = world.dt, world.substeps
    steps = int(math.floor(world.time_limit / dt + 1e-9))
    x = np.array([a.start.x for a in agents], float)
    y = np.array([a.start.y for a in agents], float)
    h = np.deg2rad(np.array([a.start.heading for a in agents], float))
    v = np.zeros(n)
    steer = lim.straight.copy()
    s_hint = np.zeros(n)
    active = np.ones(n, dtype=bool)
    goals = np.array([[a.goal.x, a.goal.y] for a in agents], float)
    tol = np.array([a.goal.tolerance for a in agents], float)

    near_at = [(math.inf, math.inf)] * n      # where each robot's wall set was gathered
    near_walls = [np.zeros((0, 4))] * n
    rec_pose, rec_v, rec_steer, rec_cmd, rec_rng, rec_clear, rec_obs, rec_act = ([] for _ in range(8))
    rec_p = {k: [] for k in perception.INPUTS}
    rec_s: list[np.ndarray] = []
    outcomes = ["timeout"] * n
    collided = 0
    stuck_window = max(1, int(round(STUCK_TIME / dt)))
    history: list[np.ndarray] = []

    for k in range(steps):
        t = k * dt
        where = obs_mod.positions(world.obstacles, t)
        centres, radii, _, rect_sides, _, rect_box = obs_mod.shapes_at(world.obstacles, where)
        pose = np.stack([x, y, h], axis=1)
        footprints = _footprints(pose, robots)
        robot_sides = (polygon_segments(footprints).reshape(n, 4, 4) if n > 1
                       else np.zeros((1, 4, 4)))       # other robots are obstacles to each
        ranges = np.zeros((n, B))
        percepts_p = {key: np.zeros(n) for key in perception.INPUTS}
        targets = np.zeros((n, 2))
        clear = np.zeros(n)
        for i in range(n):
            others = np.concatenate([rect_sides] + [robot_sides[j] for j in range(n) if j != i])
            if math.hypot(x[i] - near_at[i][0], y[i] - near_at[i][1]) > NEAR_SLACK:
                near_at[i] = (x[i], y[i])
                near_walls[i] = static.near(x[i], y[i], reach + NEAR_SLACK)
            walls = near_walls[i]
            dirs = sensors.beam_directions(h[i], angles)
            f = perception.frame(routes[i], pose[i, :2], s_hint[i])
            s_hint[i] = f.s
            expected, true_r = sensors.cast(pose[i, :2], dirs, walls, others, centres, radii,
                                            sen.range)
            measured = sensors.add_noise(true_r, sen.noise, sen.range, streams[1 + i])
            ranges[i] = measured
            p = perception.perceive(routes[i], f, (x[i], y[i], h[i]), robots[i], dirs, measured,
                                    expected, sen.range, spacing, threshold, cfg)
            for key in perception.INPUTS:
                percepts_p[key][i] = p[key]
            targets[i] = perception.target_point(routes[i], f, cfg)
            boxes = np.concatenate([rect_box, footprints[:i], footprints[i + 1:]])
            clear[i] = _clearance(pose[i], robots[i], walls, boxes, centres, radii)

        hit = active & (clear <= 0.0)
        arrived = active & (np.hypot(x - goals[:, 0], y - goals[:, 1]) <= tol)
        for i in np.flatnonzero(arrived):
            outcomes[i] = "success"
        active &= ~arrived
        cmd = np.zeros((n, 2))
        cmd[:, 0] = lim.straight
        if active.any():
            idx = np.flatnonzero(active)
            sub_p = Percepts({key: val[idx] for key, val in percepts_p.items()}, ranges[idx],
                             angles, pose[idx], v[idx], targets[idx], goals[idx])
            c_steer, c_speed = planner.plan(sub_p)
            cmd[idx, 0], cmd[idx, 1] = c_steer, c_speed

        rec_pose.append(np.stack([x, y, np.rad2deg(h)], axis=1))
        rec_v.append(v.copy())
        rec_steer.append(steer.copy())
        rec_cmd.append(cmd)
        rec_rng.append(ranges)
        rec_clear.append(clear)
        rec_obs.append(where)
        rec_act.append(active.copy())
        rec_s.append(s_hint.copy())
        for key in perception.INPUTS:
            rec_p[key].append(percepts_p[key])
        if on_tick is not None:
            on_tick(k, {"t": t, "pose": rec_pose[-1], "speed": v, "steering": steer,
                        "inputs": percepts_p, "clearance": clear, "obstacles": where})

        if hit.any():
            collided = int(hit.sum())
            for i in np.flatnonzero(hit):
                outcomes[i] = "collision"
            break
        if not active.any():
            break
        # move: limits and exact arcs, substep by substep; stopped robots stay put
        x, y, h, v, steer = kinematics.step(x, y, h, np.where(active, v, 0.0), steer,
                                            cmd[:, 0], cmd[:, 1], lim, dt, sub)
        history.append(np.stack([x, y], axis=1))
        if len(history) > stuck_window:
            moved = np.hypot(*(history[-1] - history[-1 - stuck_window]).T)
            stuck = active & (moved < STUCK_DISTANCE)
            if stuck.any():
                for i in np.flatnonzero(stuck):
                    outcomes[i] = "stuck"
                break

    if "collision" in outcomes:
        outcome = "collision"
    elif all(o == "success" for o in outcomes):
        outcome = "success"
    elif "stuck" in outcomes:
        outcome = "stuck"
    else:
        outcome = "timeout"
    res = SimResult(
        world=world, seed=seed, planner=getattr(planner, "name", type(planner).__name__),
        outcome=outcome, robot_outcomes=tuple(outcomes), collisions=collided,
        t=np.arange(len(rec_pose)) * dt, pose=np.array(rec_pose), speed=np.array(rec_v),
        steering=np.array(rec_steer), command=np.array(rec_cmd), ranges=np.array(rec_rng),
        perceived={key: np.array(val) for key, val in rec_p.items()},
        clearance=np.array(rec_clear), obstacles=np.array(rec_obs).reshape(len(rec_pose), -1, 2),
        routes=routes, static=static, active=np.array(rec_act), progress=np.array(rec_s))
    res.robot_metrics = _robot_metrics(res, dt)
    res.metrics = _metrics(res, dt)
    return res


def true_inputs(res: SimResult) -> dict[str, np.ndarray]:
    """The rule inputs from the true geometry at every tick (noise-free map rays across the
    route for the road, exact obstacle and robot outlines for the obstruction and the side
    gaps), name -> ``[T, n]``."""
    world, static = res.world, res.static
    agents = world.agents
    n = len(agents)
    robots = [a.robot for a in agents]
    sen = world.sensors
    angles = sen.angles
    reach = sen.range + max(max(r.length, r.width) for r in robots)
    cfg = perception.Settings()
    shape_outline, outline_owner = obs_mod.outline_points(
        world.obstacles, np.zeros((len(world.obstacles), 2)))
    out = {key: np.zeros((res.ticks, n)) for key in perception.INPUTS}
    for k in range(res.ticks):
        where = res.obstacles[k]
        outline = shape_outline + where[outline_owner] if len(where) else shape_outline
        pose = res.pose[k].copy()
        pose[:, 2] = np.deg2rad(pose[:, 2])
        corners = _footprints(pose, robots)
        for i in range(n):
            walls = static.near(pose[i, 0], pose[i, 1], reach)
            f = perception.frame(res.routes[i], pose[i, :2], res.progress[k, i])
            dirs = np.concatenate([sensors.beam_directions(pose[i, 2], angles), [-f.n, f.n]])
            expected = geometry.ray_segments(pose[i, :2], dirs, walls, sen.range)
            # across the route, to the walls within reach (an opening reads as the sensor
            # range, as the perceived width does, not as a sentinel a million inches wide)
            across = geometry.ray_segments(pose[i, :2], dirs[-2:], walls, sen.range)
            things = np.concatenate([outline] + [corners[j] for j in range(n) if j != i])
            gaps = perception.side_gaps(f, pose[i, :2], dirs[:-2], expected[:-2], things,
                                        robots[i], sen.range, cfg)
            seen = expected[:-2] < sen.range * 0.999
            wall_points = pose[i, :2] + expected[:-2, None][seen] * dirs[:-2][seen]
            tr = perception.truth(res.routes[i], f, tuple(pose[i]), robots[i],
                                  (float(across[0]), float(across[1])), things, gaps, cfg,
                                  wall_points)
            for key in perception.INPUTS:
                out[key][k, i] = tr[key]
    return out
