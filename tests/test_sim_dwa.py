"""The dynamic-window baseline: its rollouts, its obstacle cost, and a corridor run."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given as hgiven
from hypothesis import settings
from hypothesis import strategies as st

from mitos_cli.sim import kinematics
from mitos_cli.sim.dwa import (
    DWAParams,
    DWAPlanner,
    Workspace,
    dwa_command,
    echo_points,
    footprint_clearance,
    rollouts,
)
from mitos_cli.sim.loop import simulate
from mitos_cli.sim.world import Robot
from mitos_cli.sim.worldfile import parse_world

CORRIDOR = """\
name: dwa-corridor
seed: 3
dt: 0.05
time_limit: 20
substeps: 2
robot:
  model: tricycle
  wheelbase: 16
  footprint: {length: 24, width: 18}
sensors: {layout: ring, count: 24, cone: 15, range: 120, noise: 0.5}
q_init: {x: 30, y: -10, heading: 0}
q_goal: {x: 280, y: -10, tolerance: 12}
map:
  corridors:
    - points: [[0, 0], [310, 0]]
      width: 70
obstacles:
  - {name: box, shape: circle, at: [150, -12], radius: 9}
"""


@pytest.fixture(scope="module")
def corridor_run():
    world = parse_world(CORRIDOR, "dwa-corridor.yaml")
    return world, simulate(world, DWAPlanner.for_world(world))


def test_dwa_drives_past_the_box_to_the_goal(corridor_run):
    world, res = corridor_run
    assert res.outcome == "success", res.summary()
    assert res.metrics["min_clearance_in"] > 0
    assert res.planner == "dwa"


def test_dwa_runs_replay_bit_for_bit(corridor_run):
    world, res = corridor_run
    short = world.with_changes(time_limit=2.0)
    again = simulate(short, DWAPlanner.for_world(short))
    k = again.ticks
    assert np.array_equal(again.pose, res.pose[:k])
    assert np.array_equal(again.command, res.command[:k])


def test_a_rollout_of_a_reached_command_is_the_kinematics_arc():
    robot = Robot()
    v, s = np.array([[30.0, 45.0]]), np.array([[70.0, 120.0]])
    poses = rollouts(np.array([30.0]), np.array([70.0]), v[:, :1], s[:, :1], robot, 1.0, 10)
    lim = kinematics.Limits.of([robot])
    x, y, h = np.zeros(1), np.zeros(1), np.zeros(1)
    for k in range(10):
        x, y, h = kinematics.advance(x, y, h, np.array([30.0]), np.array([70.0]), lim, 0.1)
        assert poses[0, 0, k, 0] == pytest.approx(x[0], abs=1e-9)
        assert poses[0, 0, k, 1] == pytest.approx(y[0], abs=1e-9)
        assert poses[0, 0, k, 2] == pytest.approx(h[0], abs=1e-9)
    assert poses[0, 0, -1, 2] > 0                     # steering below 90 turns left


def test_a_rollout_ramps_within_the_limits():
    robot = Robot()        # 40 in/s^2: from rest, 0.1 s at most 4 in/s, so under 0.4 in
    poses = rollouts(np.zeros(1), np.array([90.0]), np.array([[60.0]]), np.array([[90.0]]),
                     robot, 1.0, 10)
    assert poses[0, 0, 0, 0] == pytest.approx(4.0 * 0.1)
    assert poses[0, 0, -1, 0] == pytest.approx(sum(4.0 * k * 0.1 for k in range(1, 11)))


def test_footprint_clearance_by_hand():
    pose = np.zeros((1, 1, 1, 3))                                 # at the origin, facing +x
    pts = np.array([[[20.0, 0.0], [0.0, -15.0], [16.0, 13.0], [3.0, 2.0]]])
    for i, want in enumerate([8.0, 6.0, math.hypot(4.0, 4.0), 0.0]):
        seen = np.zeros((1, 4), bool)
        seen[0, i] = True
        assert footprint_clearance(pose, pts, seen, 24.0, 18.0)[0, 0, 0] == pytest.approx(want)
    assert footprint_clearance(pose, pts, np.zeros((1, 4), bool), 24.0, 18.0)[0, 0, 0] == math.inf


def _clearance_as_written(poses, points, seen, length, width):
    """footprint_clearance as it was written before its arrays were reused (each a new one)."""
    keep = seen.any(axis=0)
    if not keep.any():
        return np.full(poses.shape[:-1], np.inf)
    far = np.where(seen[:, keep, None], points[:, keep], 1e6)
    dx = far[:, None, None, :, 0] - poses[..., 0, None]
    dy = far[:, None, None, :, 1] - poses[..., 1, None]
    c, s = np.cos(poses[..., 2, None]), np.sin(poses[..., 2, None])
    lx = np.maximum(np.abs(c * dx + s * dy) - length / 2, 0.0)
    ly = np.maximum(np.abs(c * dy - s * dx) - width / 2, 0.0)
    d = np.sqrt((lx * lx + ly * ly).min(axis=-1))
    return np.where(d > 1e5, np.inf, d)


@hgiven(st.integers(0, 2**32 - 1), st.lists(st.tuples(*[st.integers(1, 6)] * 4), min_size=1,
                                             max_size=4))
@settings(max_examples=60, deadline=None)
def test_a_workspace_reused_across_shapes_gives_the_bits_of_new_arrays(seed, shapes):
    """The clearances are computed in arrays one call hands to the next (fresh 2 MB arrays
    each tick were half a DWA run's time, in page faults): the same bits as the expression
    with new arrays, whatever shapes came before."""
    rng = np.random.default_rng(seed)
    work = Workspace()
    for n, s, t, p in shapes:
        poses = rng.normal(0.0, 30.0, (n, s, t, 3))
        points, seen = rng.normal(0.0, 50.0, (n, p, 2)), rng.random((n, p)) < 0.7
        got = footprint_clearance(poses, points, seen, 24.0, 18.0, work)
        assert got.tobytes() == _clearance_as_written(poses, points, seen, 24.0, 18.0).tobytes()


def test_planners_of_one_thread_share_its_workspace_and_threads_do_not():
    """A workspace per planner held 10-20 MB for each run of a lockstep batch (`simulate
    --runs 8 --planner dwa`: 207 MB at its peak, against 71 MB); threads may plan at once, so
    each has its own."""
    import threading

    from mitos_cli.sim.dwa import scratch

    mine = scratch()
    assert scratch() is mine
    theirs: list[Workspace] = []
    worker = threading.Thread(target=lambda: theirs.append(scratch()))
    worker.start()
    worker.join()
    assert theirs and theirs[0] is not mine


def test_echoes_spread_over_the_beams_share_and_misses_are_not_points():
    angles = np.deg2rad(np.arange(4) * 90.0)
    pts, seen = echo_points(np.array([[50.0, 150.0, 150.0, 150.0]]), angles, 150.0, 3)
    assert seen.tolist() == [[True] * 3 + [False] * 9]
    assert np.hypot(pts[0, :3, 0], pts[0, :3, 1]) == pytest.approx([50.0] * 3)
    assert np.degrees(np.arctan2(pts[0, :3, 1], pts[0, :3, 0])) == pytest.approx([-30, 0, 30])


def test_a_wall_ahead_slows_it_and_open_space_speeds_it_up():
    robot, angles = Robot(), np.deg2rad(np.arange(36) * 10.0)
    wall = np.full((1, 36), 150.0)
    wall[0, [34, 35, 0, 1, 2]] = 20.0                  # something 20 in ahead
    args = (np.array([[200.0, 0.0]]), np.array([40.0]), np.array([90.0]))
    _, slow = dwa_command(DWAParams(), *args, wall, angles, 150.0, robot, 0.05)
    _, fast = dwa_command(DWAParams(), *args, np.full((1, 36), 150.0), angles, 150.0, robot,
                          0.05)
    assert slow[0] < 40.0 < fast[0]


def test_boxed_in_it_brakes_and_the_window_bounds_the_wheel():
    robot, angles = Robot(), np.deg2rad(np.arange(36) * 10.0)
    steer, speed = dwa_command(DWAParams(), np.array([[200.0, 0.0]]), np.array([30.0]),
                               np.array([90.0]), np.full((1, 36), 14.0), angles, 150.0, robot,
                               0.05)
    assert speed[0] == 0.0
    assert abs(steer[0] - 90.0) <= robot.max_steering_rate * DWAParams().window_s + 1e-9


def test_the_costmap_remembers_behind_the_fan_and_clears_what_a_beam_sees_through():
    from mitos_cli.sim.dwa import Costmap

    p = DWAParams()
    angles = np.deg2rad(np.linspace(45, -45, 19))            # a forward fan
    cm = Costmap.empty()
    ranges = np.full(19, 150.0)
    ranges[9] = 40.0                                          # a pole dead ahead
    cm.update(p, np.array([0.0, 0.0, 0.0]), ranges, angles, 150.0)
    assert len(cm.points) and np.allclose(cm.points[:, 0], 40.0, atol=1.0)
    cm.update(p, np.array([0.0, 0.0, math.pi]), np.full(19, 150.0), angles, 150.0)
    assert len(cm.points)                                     # turned away: still there
    cm.update(p, np.array([0.0, 0.0, 0.0]), np.full(19, 150.0), angles, 150.0)
    assert not len(cm.points)                                 # seen through: cleared


def test_a_fresh_planner_remembers_nothing_and_runs_replay(corridor_run):
    world, res = corridor_run
    planner = DWAPlanner.for_world(world)
    first = simulate(world, planner)
    assert not planner._maps                                  # the run used a fresh copy
    again = simulate(world, planner)
    assert np.array_equal(first.pose, again.pose) and np.array_equal(first.pose, res.pose)


def test_the_route_ahead_slows_it_before_a_sharp_bend():
    """ROS's path_distance_bias: scored by how near each rollout ends to the route, a robot
    30 in before a sharp left bend slows and turns in; scored only by progress toward the
    route point pushed out to the horizon, it speeds up and overshoots (it circled a room
    at 60 in/s in office02 #1 once the brake no longer capped it at 48)."""
    robot, angles = Robot(), np.deg2rad(np.arange(36) * 10.0)
    free = np.full((1, 36), 150.0)
    path = np.concatenate([np.stack([np.arange(0, 31, 4.0), np.zeros(8)], 1),
                           np.stack([np.full(20, 30.0), np.arange(4, 81, 4.0)], 1)])[None]
    target = np.array([[30.0, 10.0]]) * (102 / math.hypot(30, 10))
    args = (DWAParams(), target, np.array([30.0]), np.array([90.0]), free, angles, 150.0,
            robot, 0.05)
    (blind_s,), (blind_v,) = dwa_command(*args)
    (steer,), (speed,) = dwa_command(*args, path=path)
    assert speed < 30.0 < blind_v and steer < blind_s < 90.0        # left is below 90


def test_only_a_planner_that_asks_is_given_the_route_ahead():
    from mitos_cli.sim.loop import Simulation

    world = parse_world(CORRIDOR, "dwa-corridor.yaml")
    seen = {}

    class Spy:
        name = "spy"
        path_reach = 40.0

        def plan(self, p):
            seen["path"] = p.path
            return np.full(len(p.pose), 90.0), np.zeros(len(p.pose))

    Simulation(world, Spy(), 3).step()
    assert seen["path"].shape == (1, 11, 2)                   # 0, 4, ..., 40 in ahead
    steps = np.hypot(*np.diff(seen["path"][0], axis=0).T)
    assert np.allclose(seen["path"][0, 0], [30.0, -10.0]) and (steps <= 4.0 + 1e-9).all()
    Simulation(world, None, 3).step()                          # the rules: no path made
