"""The steppable simulation: simulate() is a loop over Simulation.step(), so stepping by hand
gives the same run bit for bit; reset(seed) starts it again; a user's planner drives it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from mitos_cli.engine.evaluation import evaluate_one
from mitos_cli.resources import packaged_path
from mitos_cli.sim import Simulation, simulate
from mitos_cli.sim.planner import FuzzyPlanner
from mitos_cli.sim.worldfile import load_world


def short(name: str, seconds: float):
    return dataclasses.replace(load_world(packaged_path("worlds", name)), time_limit=seconds)


def same_run(a, b) -> None:
    assert a.ticks == b.ticks
    for key in ("t", "pose", "speed", "steering", "command", "ranges", "clearance",
                "obstacles", "active", "progress"):
        assert np.array_equal(getattr(a, key), getattr(b, key)), key
    for key in a.perceived:
        assert np.array_equal(a.perceived[key], b.perceived[key]), key
    assert a.summary() == b.summary()


def test_stepping_by_hand_is_simulate():
    world = short("moving.yaml", 3.0)                    # noise and moving obstacles
    planner = FuzzyPlanner(None, "drive")
    sim = Simulation(world, planner, seed=7, randomise=True)
    ticks = []
    while not sim.done:
        ticks.append(sim.step())
    assert [t.k for t in ticks] == list(range(len(ticks))) and sim.ticks == len(ticks) == 60
    same_run(sim.result(), simulate(world, planner, 7, randomise=True))


def test_reset_starts_the_same_run_again():
    world = short("moving.yaml", 1.0)
    sim = Simulation(world, seed=3, randomise=True)
    while not sim.done:
        sim.step()
    first = sim.result()
    sim.reset(3)
    assert sim.ticks == 0 and sim.time == 0.0 and not sim.done
    while not sim.done:
        sim.step()
    same_run(first, sim.result())
    sim.reset(4)
    while not sim.done:
        sim.step()
    assert not np.array_equal(first.ranges, sim.result().ranges)


def test_state_between_ticks_and_a_users_planner():
    world = short("corridor.yaml", 1.0)

    class Creep:
        name = "creep"

        def plan(self, p):
            return np.full(len(p.pose), 90.0), np.full(len(p.pose), 10.0)

    sim = Simulation(world, planner=Creep())
    start = world.agents[0].start
    assert np.array_equal(sim.pose[0], [start.x, start.y, start.heading])
    tick = sim.step()
    assert tick.t == 0.0 and sim.time == world.dt and sim.outcome == "timeout"
    assert np.array_equal(tick.command[0], [90.0, 10.0])
    assert sim.speed[0] > 0.0 and sim.clearance[0] > 0.0
    while not sim.done:
        sim.step()
    res = sim.result()
    assert res.planner == "creep" and res.ticks == 20 and res.outcome == "timeout"
    with pytest.raises(RuntimeError, match="ended"):
        sim.step()


def test_the_verdicts_end_the_run():
    world = load_world(packaged_path("worlds", "figure4.yaml"))     # collides at B
    sim = Simulation(world)
    while not sim.done:
        sim.step()
    assert sim.outcome == "collision" and sim.clearance[0] <= 0.0
    assert sim.result().collisions == 1


def test_the_documented_example_runs():
    import doctest

    from mitos_cli.sim import loop

    failures, tried = doctest.testmod(loop, verbose=False)
    assert tried >= 5 and failures == 0


def test_a_command_from_outside_drives_the_same_run_as_the_planner():
    """observe() then step(command): what an outside policy (the Gymnasium environment) does;
    the planner's own commands given this way reproduce simulate() bit for bit."""
    world = short("moving.yaml", 3.0)
    planner = FuzzyPlanner(None, "drive")
    sim = Simulation(world, planner, seed=5, randomise=True)
    while not sim.done:
        seen = sim.observe()
        assert sim.observe() is seen                   # once per tick
        out = evaluate_one(planner.compiled, [float(seen.inputs[k][0])
                                              for k in planner.compiled.inputs])
        cols = [planner.compiled.outputs.index(o) for o in ("steering", "speed")]
        ending = sim.ending
        sim.step(np.array([[out[cols[0]], out[cols[1]]]]))
        assert not ending or sim.done
    same_run(sim.result(), simulate(world, planner, 5, randomise=True))
    assert sim.routes == sim.result().routes
    with pytest.raises(RuntimeError, match="has ended"):
        sim.observe()


class _Gives:
    """A user's planner that commands what it is given, whatever the robots."""

    name = "gives"

    def __init__(self, steer, speed) -> None:
        self.steer, self.speed = steer, speed

    def plan(self, p):
        return self.steer, self.speed


@pytest.mark.parametrize("planner, says", [
    (_Gives(np.full(3, 90.0), np.full(3, 10.0)),
     "planner `gives` gave (3,) steering and (3,) speed values for 1 active robot"),
    (_Gives(np.nan, 10.0), "the command of planner `gives` at 0 s must be finite numbers"),
    (_Gives(90.0, np.inf), "must be finite numbers (steering deg, speed in/s), not [[90.0, inf]]"),
])
def test_a_planners_wrong_command_is_named_where_it_is_given(planner, says):
    # a NaN became the robot's pose and failed a tick later, deep in the loop
    with pytest.raises(ValueError) as exc:
        Simulation(short("corridor.yaml", 1.0), planner).step()
    assert says in str(exc.value)


def test_a_wrong_command_from_outside_and_an_early_result_say_what_is_wrong():
    sim = Simulation(short("corridor.yaml", 1.0))
    with pytest.raises(RuntimeError, match="no tick recorded yet"):
        sim.result()
    with pytest.raises(ValueError, match=r"a command is \[1, 2\] .* not of shape \(3,\)"):
        sim.step(np.zeros(3))
    with pytest.raises(ValueError, match="the command must be finite numbers"):
        sim.step(np.array([[np.nan, 20.0]]))
    sim.step(np.array([[90.0, 20.0]]))                  # the run is as if none was given
    again = Simulation(short("corridor.yaml", 1.0))
    again.step(np.array([[90.0, 20.0]]))
    same_run(sim.result(), again.result())
