"""When a run ends ``stuck``: a robot that drove too little (``STUCK_DISTANCE`` in
``STUCK_TIME``), or came no nearer its goal than ``PROGRESS_DISTANCE`` beyond its best in
``PROGRESS_TIME`` (:meth:`Simulation._check_stuck`); in a lockstep batch:
tests/test_sim_lockstep.py."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from mitos_cli.resources import packaged_path
from mitos_cli.sim import Simulation, load_world
from mitos_cli.sim.loop import PROGRESS_DISTANCE, PROGRESS_TIME, STUCK_DISTANCE, STUCK_TIME, simulate


def corridor(**changes):
    return dataclasses.replace(load_world(packaged_path("worlds", "corridor.yaml")), **changes)


def first_stuck(sim: Simulation, xs: np.ndarray, y: float) -> int | None:
    """Move robot 0 of ``sim`` to each of ``xs`` in turn; the move after which the run is
    found stuck (1-based), else None."""
    one = np.zeros(1)
    for m, x in enumerate(xs.tolist(), 1):
        sim.move_to(np.array([x]), np.array([y]), one, one, one + 90.0)
        if sim._check_stuck():
            assert sim._outcomes[0] == "stuck"
            return m
    return None


def expected_stuck(xs: np.ndarray, y: float, start: tuple[float, float],
                   goal: tuple[float, float], dt: float) -> int | None:
    """The rule in words, on the whole path at once: the first move ``m`` after which the
    robot drove less than ``STUCK_DISTANCE`` in the last ``STUCK_TIME``, or its least
    distance to the goal is less than ``PROGRESS_DISTANCE`` below what it was
    ``PROGRESS_TIME`` before (its start counts)."""
    px = np.concatenate([[start[0]], xs])
    py = np.concatenate([[start[1]], np.full(len(xs), y)])
    odometer = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(px), np.diff(py)))])
    best = np.minimum.accumulate(np.hypot(px - goal[0], py - goal[1]))
    w, p = round(STUCK_TIME / dt), round(PROGRESS_TIME / dt)
    for m in range(1, len(xs) + 1):
        if m >= w + 1 and odometer[m] - odometer[m - w] < STUCK_DISTANCE:
            return m
        if m >= p and best[m - p] - best[m] < PROGRESS_DISTANCE:
            return m
    return None


def test_a_robot_that_drives_back_and_forth_in_a_pocket_is_stuck_after_progress_time():
    """10 in toward its goal and back every 2 s: it drives 60 in every 6 s, so the distance
    test never ends the run (it ran to the time limit); it is stuck once ``PROGRESS_TIME`` has
    passed since it was last nearer its goal."""
    world = corridor()
    sim = Simulation(world, seed=1)
    start, goal = world.agents[0].start, world.agents[0].goal
    dt = world.dt
    k = np.arange(1, int(round(3 * PROGRESS_TIME / dt)))
    xs = start.x + 10.0 * np.abs(np.sin(np.pi * k * dt / 2.0))
    m = first_stuck(sim, xs, start.y)
    assert m is not None and m == expected_stuck(xs, start.y, (start.x, start.y),
                                                 (goal.x, goal.y), dt)
    # within PROGRESS_DISTANCE of nearest its goal before 1 s (10 in out): stuck
    # PROGRESS_TIME after that
    assert PROGRESS_TIME < m * dt <= PROGRESS_TIME + 1.0
    driven = np.abs(np.diff(np.concatenate([[start.x], xs[:m]])))
    window = int(round(STUCK_TIME / dt))
    assert np.convolve(driven, np.ones(window), "valid").min() > 10 * STUCK_DISTANCE


@pytest.mark.parametrize("speed", [0.6, 2.0])
def test_a_robot_that_goes_slowly_but_steadily_toward_its_goal_is_not_stuck(speed):
    """0.6 in/s (3.6 in in 6 s, just past the distance test) and 2 in/s, toward the goal for
    three times ``PROGRESS_TIME``: never stuck."""
    world = corridor()
    sim = Simulation(world, seed=1)
    start = world.agents[0].start
    k = np.arange(1, int(round(3 * PROGRESS_TIME / world.dt)))
    assert first_stuck(sim, start.x + speed * k * world.dt, start.y) is None


def test_a_robot_that_creeps_toward_its_goal_while_it_swings_is_stuck_only_below_the_pace():
    """Swinging 10 in back and forth every 2 s while its middle creeps toward the goal: at
    twice ``PROGRESS_DISTANCE`` per ``PROGRESS_TIME`` it is never stuck; at half that it is,
    where the rule in words says."""
    world = corridor()
    start, goal = world.agents[0].start, world.agents[0].goal
    dt = world.dt
    k = np.arange(1, int(round(3 * PROGRESS_TIME / dt)))
    swing = 10.0 * np.abs(np.sin(np.pi * k * dt / 2.0))
    ends = []
    for pace in (2.0, 0.5):
        xs = start.x + swing + pace * PROGRESS_DISTANCE / PROGRESS_TIME * k * dt
        ends.append((first_stuck(Simulation(world, seed=1), xs, start.y),
                     expected_stuck(xs, start.y, (start.x, start.y), (goal.x, goal.y), dt)))
    assert ends[0] == (None, None)
    assert ends[1][0] is not None and ends[1][0] == ends[1][1]


def test_a_robot_that_drives_away_from_its_goal_along_its_route_is_not_stuck():
    """Along a route that bends away from the goal the straight-line distance grows; the
    route left shrinks (2 in/s), and the robot is not stuck. The same moves with the route
    left standing still are stuck once ``PROGRESS_TIME`` has passed."""
    world = corridor()
    start = world.agents[0].start
    dt = world.dt
    one = np.zeros(1)
    ends = []
    for along in (2.0, 0.0):
        sim = Simulation(world, seed=1)
        end = None
        for m in range(1, int(round(3 * PROGRESS_TIME / dt))):
            sim._s_hint = np.array([along * m * dt])    # (as perception sets it each tick)
            sim.move_to(np.array([start.x - 2.0 * m * dt]), np.array([start.y]), one, one,
                        one + 90.0)
            if sim._check_stuck():
                end = m
                break
        ends.append(end)
    assert ends == [None, int(round(PROGRESS_TIME / dt))]


class BackAndForth:
    """Forward at 15 in/s to 8 in past where it started, back at 15 in/s to where it
    started, and again: stateless (the direction is read from the speed)."""

    name = "back_and_forth"

    def __init__(self, x0: float) -> None:
        self.x0 = x0

    def plan(self, p):
        x, v = p.pose[:, 0], p.speed
        speed = np.where(x > self.x0 + 8.0, -15.0,
                         np.where(x < self.x0, 15.0, np.where(v >= 0.0, 15.0, -15.0)))
        return np.full(len(x), 90.0), speed


def test_a_run_that_drives_back_and_forth_ends_stuck_not_at_its_time_limit():
    world = corridor(time_limit=PROGRESS_TIME + 10.0)
    res = simulate(world, BackAndForth(world.agents[0].start.x), 1)
    assert res.outcome == "stuck"
    assert PROGRESS_TIME <= res.metrics["time_s"] < PROGRESS_TIME + 3.0
    assert res.metrics["path_length_in"] > 4 * PROGRESS_TIME    # it drove all along
