"""Same world, rule base and seed: the same trace, bit for bit (and whatever the workers)."""

from __future__ import annotations

import dataclasses

import numpy as np

from mitos_cli.resources import packaged_path
from mitos_cli.sim.loop import shared_scene, simulate
from mitos_cli.sim.planner import FuzzyPlanner
from mitos_cli.sim.runs import run_many
from mitos_cli.sim.worldfile import load_world


def short(name: str, seconds: float):
    w = load_world(packaged_path("worlds", name))
    return dataclasses.replace(w, time_limit=seconds)


def arrays(res):
    out = {"t": res.t, "pose": res.pose, "speed": res.speed, "steering": res.steering,
           "command": res.command, "ranges": res.ranges, "clearance": res.clearance,
           "obstacles": res.obstacles}
    out.update({f"p_{k}": v for k, v in res.perceived.items()})
    out.update({f"t_{k}": v for k, v in res.true.items()})
    return out


def test_two_runs_are_bit_identical():
    world = short("moving.yaml", 6.0)                    # noise and moving obstacles
    planner = FuzzyPlanner(None, "drive")
    a = simulate(world, planner, seed=11, randomise=True)
    b = simulate(world, FuzzyPlanner(None, "drive"), seed=11, randomise=True)
    assert a.ticks == b.ticks > 100
    for key, value in arrays(a).items():
        assert np.array_equal(value, arrays(b)[key]), key
    assert a.summary() == b.summary()


def test_another_seed_gives_another_run():
    world = short("moving.yaml", 3.0)
    a = simulate(world, seed=1, randomise=True)
    b = simulate(world, seed=2, randomise=True)
    assert not np.array_equal(a.ranges, b.ranges)


def test_run_many_does_not_depend_on_the_workers():
    world = short("corridor.yaml", 2.0)
    one = run_many([world], runs=4, seed=5, workers=1)
    two = run_many([world], runs=4, seed=5, workers=2)
    assert one.to_json() == two.to_json()
    assert [s["seed"] for s in one.worlds[0].summaries] == [5, 6, 7, 8]


def test_a_run_of_many_is_the_run_alone_where_draws_move_what_the_robot_is_given():
    # detour's cabinet is known (drawn on the robot's map) and randomised: each run's robot
    # is given the map with the cabinet where its draw put it, in a chunk of runs as alone
    world = short("detour.yaml", 21.0)     # where the cabinet's place tells (19.75-20.45 s)
    assert shared_scene(world, True) is None and shared_scene(world, False) is not None
    many = run_many([world], runs=1, seed=1, workers=1)
    for j, summary in enumerate(many.worlds[0].summaries):
        alone = simulate(world, seed=1 + j, randomise=True).summary()
        assert {k: summary[k] for k in alone} == alone


def test_the_planner_is_row_exact_so_recorded_dofs_are_the_ones_used():
    world = short("corridor.yaml", 3.0)
    planner = FuzzyPlanner(None, "drive")
    res = simulate(world, planner)
    detail = planner.explain({k: v[:, 0] for k, v in res.perceived.items()})
    steering = detail.outputs[:, planner.compiled.outputs.index("steering")]
    assert np.array_equal(steering, res.command[:, 0, 0])


def test_the_documented_api_imports():
    # mitos_cli/sim/__init__.py documents `from mitos_cli.sim import simulate, load_world, ...`
    from mitos_cli.sim import FuzzyPlanner, SimResult, load_world, run_many
    from mitos_cli.sim import simulate as run

    assert callable(run) and callable(load_world) and callable(run_many)
    assert isinstance(FuzzyPlanner, type) and isinstance(SimResult, type)
