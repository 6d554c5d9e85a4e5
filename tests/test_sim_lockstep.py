"""Runs in lockstep give every run the bits it has alone, whatever the batch."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from mitos_cli.resources import packaged_path
from mitos_cli.sim import rows
from mitos_cli.sim.lockstep import Lockstep, run_lockstep
from mitos_cli.sim.loop import STUCK_TIME, Batch, Simulation, prepare, simulate
from mitos_cli.sim.planner import FuzzyPlanner, make_planner
from mitos_cli.sim.worldfile import load_world

WORLDS = ("corridor", "slalom", "moving", "intersection", "multirobot", "office", "detour",
          "figure4")
TINY = Path(__file__).parent / "data" / "tiny.yaml"


def recorded(res) -> dict:
    out = {key: getattr(res, key) for key in ("t", "pose", "speed", "steering", "command",
                                               "ranges", "clearance", "obstacles", "active",
                                               "progress")}
    out.update({f"p_{k}": v for k, v in res.perceived.items()})
    return out


def assert_same_run(a, b) -> None:
    assert a.ticks == b.ticks
    for key, value in recorded(a).items():
        other = recorded(b)[key]
        assert value.shape == other.shape and value.tobytes() == other.tobytes(), key
    assert a.summary() == b.summary()
    assert [(k, i) for k, i, _ in a.replanned] == [(k, i) for k, i, _ in b.replanned]


@pytest.mark.parametrize("name", WORLDS)
def test_each_shipped_world_runs_alone_and_in_a_batch_alike(name):
    world = dataclasses.replace(load_world(packaged_path("worlds", f"{name}.yaml")),
                                time_limit=1.0)
    planner, scene = FuzzyPlanner(None, world.behavior), prepare(world)
    seeds = [world.seed, world.seed + 7]
    together = run_lockstep(world, planner, seeds, randomise=True, scene=scene)
    for seed, res in zip(seeds, together):
        assert_same_run(simulate(world, planner, seed, randomise=True, scene=scene), res)


def test_runs_that_end_at_different_ticks_drop_out_and_the_rest_go_on():
    world = load_world(TINY)
    planner, scene = FuzzyPlanner(None, world.behavior), prepare(world)
    seeds = [3, 5]
    alone = [simulate(world, planner, s, randomise=True, scene=scene) for s in seeds]
    assert len({r.ticks for r in alone}) > 1              # they do end at different ticks
    for a, b in zip(alone, run_lockstep(world, planner, seeds, randomise=True, scene=scene)):
        assert_same_run(a, b)


@pytest.mark.parametrize("name", ["potential_field", "dwa"])   # dwa: with the route ahead
def test_a_planner_other_than_the_fuzzy_one_plans_each_run_itself(name):
    world = dataclasses.replace(load_world(TINY), time_limit=1.0)
    planner = make_planner(name, world)
    lock = Lockstep(world, planner, [1, 2], randomise=True)
    for seed, res in zip([1, 2], lock.results()):
        assert_same_run(simulate(world, planner, seed, randomise=True), res)
    assert lock.done


def test_a_batch_sees_the_news_each_run_sees_alone_with_its_own_noise():
    """Each randomised run draws its own sensor noise, so its own news threshold."""
    world = load_world(packaged_path("worlds", "corridor.yaml"))
    runs = [Simulation(world, None, seed, randomise=True) for seed in range(7000, 7006)]
    assert len({run.world.sensors.noise for run in runs}) > 1
    batch = Batch(runs)
    got = rows.sense([part for run in runs for part in run.sense_rows()], runs[0].angles,
                     world.sensors.range)
    rng = np.random.default_rng(1)          # readings a little short of the walls, or at range
    ranges = np.where(rng.random(got.ranges.shape) < 0.2, world.sensors.range,
                      got.static - rng.uniform(0.0, 8.0, got.ranges.shape))
    got = rows.Sensed(got.dirs, got.static, ranges, got.clearance)
    sensed = batch.sensed(got)
    together = batch.seeing()
    alone = np.concatenate([run.seeing(s) for run, s in zip(runs, sensed)])
    assert 0 < np.count_nonzero(alone) < alone.size
    assert together.tobytes() == alone.tobytes()


def test_runs_stuck_in_a_batch_are_stuck_at_the_tick_they_are_alone():
    world = dataclasses.replace(load_world(packaged_path("worlds", "multirobot.yaml")),
                                time_limit=STUCK_TIME + 3.0)
    start = world.agents[0].start

    class Stands:                           # the first robot drives 5 in, then stands
        name = "stands"

        def plan(self, p):
            off = np.hypot(p.pose[:, 0] - start.x, p.pose[:, 1] - start.y)
            return np.full(len(p.pose), 90.0), np.where((p.robots == 0) & (off > 5.0), 0.0, 20.0)

    lock = Lockstep(world, Stands(), [1, 2, 3], randomise=True)
    for seed, res in zip([1, 2, 3], lock.results()):
        assert res.robot_outcomes[0] == "stuck"
        assert_same_run(simulate(world, Stands(), seed, randomise=True), res)
