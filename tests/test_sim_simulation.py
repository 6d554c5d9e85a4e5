"""The steppable simulation: simulate() is a loop over Simulation.step(), so stepping by hand
gives the same run bit for bit; reset(seed) starts it again; a user's planner drives it."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

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


def test_the_result_holds_every_recorded_tick_as_it_was_recorded():
    """result() stacks the record (one concatenation a field): each tick's arrays, bit for bit,
    and each tick's inputs the rows of its block, in order, as contiguous [T, n] arrays."""
    from mitos_cli.sim.perception import INPUTS

    sim = Simulation(short("moving.yaml", 2.0), seed=3, randomise=True)
    while not sim.done:
        sim.step()
    res = sim.result()
    for k, tick in enumerate(sim.record):
        for key in ("pose", "speed", "steering", "command", "ranges", "clearance", "active",
                    "progress"):
            assert np.array_equal(getattr(res, key)[k], getattr(tick, key)), key
        assert np.array_equal(res.obstacles[k], tick.obstacles.reshape(-1, 2))
        assert list(tick.inputs) == list(INPUTS)
        for j, key in enumerate(INPUTS):
            assert np.shares_memory(tick.inputs[key], tick.block)
            assert np.array_equal(tick.inputs[key], tick.block[j])
            assert np.array_equal(res.perceived[key][k], tick.inputs[key]), key
    assert all(v.shape == (res.ticks, 1) and v.flags.c_contiguous
               for v in res.perceived.values())
    assert res.active.dtype == bool and res.pose.shape == (res.ticks, 1, 3)


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
    assert tick.t == 0.0 and sim.time == world.dt and sim.outcome == "driving"
    assert np.array_equal(tick.command[0], [90.0, 10.0])
    assert sim.speed[0] > 0.0 and sim.clearance[0] > 0.0
    while not sim.done:
        sim.step()
    res = sim.result()
    assert res.planner == "creep" and res.ticks == 20 and res.outcome == "timeout"
    with pytest.raises(RuntimeError, match="ended"):
        sim.step()


def test_the_state_between_ticks_is_a_copy_of_the_record():
    """sim.clearance was the recorded tick's own array: writing into it (a reward shaped in
    place) changed the run's min_clearance_in, 8.2 in to 14.1 in, and the contact check."""
    world = short("corridor.yaml", 3.0)
    sim = Simulation(world, seed=1)
    while not sim.done:
        sim.step()
        for state in (sim.clearance, sim.pose, sim.speed, sim.steering, sim.progress):
            state[...] = 1000.0
    same_run(sim.result(), simulate(world, seed=1))


def test_what_observe_and_step_hand_out_is_read_only():
    """A tick's arrays and an observation's are the record: writing into them (tick.pose, the
    ranges scaled in place) changed result(), and an observation's inputs what the planner
    then decided (another run)."""
    world = short("moving.yaml", 2.0)
    sim = Simulation(world, seed=3, randomise=True)
    while not sim.done:
        seen = sim.observe()
        for array in (seen.pose, seen.ranges, seen.clearance, seen.inputs["road"], seen.where):
            with pytest.raises(ValueError, match="read-only"):
                array[...] = 0.0
        tick = sim.step()
        for array in (tick.pose, tick.speed, tick.steering, tick.command, tick.ranges,
                      tick.clearance, tick.obstacles, tick.active, tick.progress, tick.block):
            with pytest.raises(ValueError, match="read-only"):
                array[...] = 0
    res = sim.result()
    same_run(res, simulate(world, seed=3, randomise=True))
    res.pose[...] = 0.0                                  # the result's arrays are the caller's
    assert not np.array_equal(sim.result().pose, res.pose)


def test_a_route_given_out_cannot_be_changed_under_the_run():
    """sim.routes[0].points was the array the robot followed: writing into it (to draw the
    route turned, say) moved the route mid-run, and the corridor's run timed out."""
    world = short("corridor.yaml", 3.0)
    sim = Simulation(world, seed=1)
    route = sim.routes[0]
    for array in (route.points, route.cum, route.goal):
        with pytest.raises(ValueError, match="read-only"):
            array[...] = 0.0
    turned = route.points.copy()
    turned[:, 1] += 30.0                                 # a copy is the caller's to change
    while not sim.done:
        sim.step()
    same_run(sim.result(), simulate(world, seed=1))


@pytest.mark.parametrize("k, i, says", [
    (60, 0, "k is a tick of the run, 0 to 59, not `60`"),
    (-1, 0, "k is a tick of the run, 0 to 59, not `-1`"),
    (2.0, 0, "k is a tick of the run, 0 to 59, not `2.0`"),
    (10, 1, "i is the index of one of the run's 1 robot, 0 to 0, not `1`"),
    (10, -1, "i is the index of one of the run's 1 robot, 0 to 0, not `-1`"),
    (10, True, "i is the index of one of the run's 1 robot, 0 to 0, not `True`")])
def test_route_at_a_tick_or_robot_the_run_does_not_have_is_refused(k, i, says):
    """`route_at(100000, 0)` gave the last route of a 60-tick run without a word (and -5 the
    first), and `route_at(10, 1)` of one robot met `IndexError: tuple index out of range`."""
    from mitos_cli.errors import InputError

    res = simulate(short("corridor.yaml", 3.0), seed=1)
    assert res.ticks == 60 and res.route_at(59, 0) is res.route_at(np.int64(0), 0)
    with pytest.raises(InputError) as info:
        res.route_at(k, i)
    assert str(info.value) == f"input error: {says}"


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


@pytest.mark.parametrize("given, held", [
    ([[200.0, 20.0]], [150.0, 20.0]),       # past the lock to the right
    ([[-50.0, 500.0]], [30.0, 60.0]),       # past the lock to the left, past the top speed
    ([[90.0, -100.0]], [90.0, -15.0]),      # faster backward than the robot drives
    ([[150.0, 60.0]], [150.0, 60.0]),       # the limits themselves
])
def test_a_command_past_the_robots_limits_is_recorded_as_its_drive_takes_it(given, held):
    """`Simulation.step([[200, 20]])` recorded a steering command of 200 while the wheel was
    held to its lock at 150: the record, the CSV's `cmd_` columns and a `Tick` say what the
    robot was told once held to its steering lock and top speeds (as the brake's and giving
    way's caps are recorded), and the run is the one of the held command, bit for bit."""
    from mitos_cli.sim.export import csv_text

    world = short("figure4.yaml", 1.0)
    sim, same = Simulation(world), Simulation(world)
    while not sim.done:
        tick = sim.step(given)
        same.step([held])
        assert tick.command.tolist() == [held]
    same_run(sim.result(), same.result())
    assert sim.result().command.reshape(-1, 2).tolist() == [held] * sim.ticks
    rows = csv_text(sim.result(), sim.planner).splitlines()
    head = rows[0].split(",")
    first = rows[1].split(",")
    assert [float(first[head.index(c)]) for c in ("cmd_steering", "cmd_speed")] == held


class _Wild:
    """A user's planner past every limit: steering 200 or -40 deg, speed 500 or -90 in/s."""

    name = "wild"

    def plan(self, p):
        k = np.round(p.pose[:, 0]).astype(int)
        return (np.where(k % 3 == 0, 200.0, np.where(k % 3 == 1, -40.0, 95.0)),
                np.where(k % 4 == 0, 500.0, np.where(k % 4 == 1, -90.0, 25.0)))


class _Held(_Wild):
    """:class:`_Wild`'s commands held to the packaged robots' limits."""

    def plan(self, p):
        steer, speed = super().plan(p)
        return np.clip(steer, 30.0, 150.0), np.clip(speed, -15.0, 60.0)


def test_a_planners_commands_past_the_limits_are_recorded_held_alone_and_in_lockstep():
    """A planner of one's own past the robots' limits, in a world of several robots, alone
    and in lockstep (one batch): every recorded command lies within the limits, the brake
    and giving way capped what was held, and the robots do what they do given the held
    commands (the one record of the two planners, bit for bit)."""
    from mitos_cli.sim.lockstep import run_lockstep

    world = short("multirobot.yaml", 8.0)
    alone = simulate(world, _Wild(), 1, randomise=True)
    command = alone.command.reshape(-1, 2)
    assert (command[:, 0] >= 30.0).all() and (command[:, 0] <= 150.0).all()
    assert (command[:, 1] >= -15.0).all() and (command[:, 1] <= 60.0).all()
    assert (command[:, 0] == 150.0).any() and (command[:, 1] == 60.0).any()
    same_run(alone, simulate(world, _Held(), 1, randomise=True))
    wild, held = (run_lockstep(world, planner, [1, 2], randomise=True)
                  for planner in (_Wild(), _Held()))
    same_run(wild[0], alone)
    for a, b in zip(wild, held):
        same_run(a, b)


@pytest.mark.parametrize("bad", [[[np.nan, 20.0]], [[90.0, np.inf]], [[-np.inf, 20.0]]])
def test_a_command_that_is_not_finite_is_refused_and_not_recorded(bad):
    from mitos_cli.errors import CommandError

    sim = Simulation(short("corridor.yaml", 1.0))
    sim.step([[90.0, 20.0]])
    with pytest.raises(CommandError, match="the command must be finite numbers"):
        sim.step(bad)
    assert sim.ticks == 1 and len(sim.result().t) == 1


class _Gives:
    """A user's planner that commands what it is given, whatever the robots."""

    name = "gives"

    def __init__(self, steer, speed) -> None:
        self.steer, self.speed = steer, speed

    def plan(self, p):
        return self.steer, self.speed


class _Returns:
    """A user's planner that returns what it is given, whatever it is."""

    name = "returns"

    def __init__(self, given) -> None:
        self.given = given

    def plan(self, p):
        return self.given


@pytest.mark.parametrize("planner, says", [
    # Python's "not enough values to unpack" and "cannot unpack non-iterable NoneType object"
    (_Returns(np.array([[90.0, 20.0]])),
     "planner `returns` must return (steering[n], speed[n]), not ndarray of shape (1, 2)"),
    (_Returns(None), "planner `returns` must return (steering[n], speed[n]), not None"),
    (_Returns([90.0, 20.0, 1.0]),
     "planner `returns` must return (steering[n], speed[n]), not list of 3 items"),
    (_Gives(np.array([True]), 10.0), "planner `gives` must return numbers, not bools"),  # 1 deg
    (_Gives(np.full(3, 90.0), np.full(3, 10.0)),
     "planner `gives` gave (3,) steering and (3,) speed values for 1 active robot"),
    (_Gives(np.nan, 10.0), "the command of planner `gives` at 0 s must be finite numbers"),
    (_Gives(90.0, np.inf), "must be finite numbers (steering deg, speed in/s), not [[90.0, inf]]"),
])
def test_a_planners_wrong_command_is_named_where_it_is_given(planner, says):
    # a NaN became the robot's pose and failed a tick later, deep in the loop
    from mitos_cli.errors import CommandError

    with pytest.raises(CommandError) as exc:
        Simulation(short("corridor.yaml", 1.0), planner).step()
    assert says in str(exc.value) and isinstance(exc.value, ValueError)


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


@pytest.mark.parametrize("seed", [-1, 3.7, "3", np.array([3]), True, np.True_, -10**5000, None],
                         ids=["-1", "3.7", "text", "array", "True", "np.True_", "huge", "None"])
def test_a_seed_that_is_not_a_whole_number_of_0_or_more_is_refused(seed):
    """-1 was a bare ValueError from NumPy's SeedSequence; 3.7 and "3" ran as seed 3, and
    True as seed 1 (Gymnasium's reset and the engine's inputs refuse a bool); a negative
    seed of over 4,300 digits met Python's limit on printing it."""
    from mitos_cli.errors import InputError

    world = short("corridor.yaml", 0.2)
    if seed is None:                                    # the world's own: no complaint
        assert Simulation(world, seed=seed).seed == world.seed
        return
    with pytest.raises(InputError, match="a seed is a whole number, 0 or more"):
        Simulation(world, seed=seed)
    with pytest.raises(InputError, match="a seed is a whole number"):
        simulate(world, seed=seed)
    with pytest.raises(InputError, match="a seed is a whole number"):
        Simulation(world).reset(seed)


@pytest.mark.parametrize("randomise", ["no", 0, None, np.array([False])])
def test_randomise_that_is_not_a_bool_is_refused(randomise):
    """simulate(world, randomise="no") ran randomised: any true value was taken."""
    from mitos_cli.errors import InputError

    world = short("corridor.yaml", 0.2)
    with pytest.raises(InputError, match="randomise is True or False"):
        simulate(world, seed=1, randomise=randomise)
    with pytest.raises(InputError, match="randomise is True or False"):
        Simulation(world, randomise=randomise)
    same_run(simulate(world, seed=1, randomise=np.False_), simulate(world, seed=1))


def test_numpy_and_huge_seeds_are_the_runs_of_their_value():
    world = short("moving.yaml", 0.5)
    same_run(simulate(world, seed=np.int64(5), randomise=True),
             simulate(world, seed=5, randomise=True))
    assert Simulation(world, seed=np.uint64(2**63)).seed == 2**63


def test_a_path_for_a_world_or_a_name_for_a_planner_says_what_is_taken():
    """simulate("worlds/corridor.yaml") failed with `'str' object has no attribute
    'behavior'`; simulate(world, "dwa") with an AttributeError at the first tick."""
    from mitos_cli.errors import InputError, WorldError

    with pytest.raises(WorldError, match="a simulation runs a loaded World, not str") as exc:
        simulate("worlds/corridor.yaml")
    assert exc.value.hint == "load_world('worlds/corridor.yaml') reads it"
    with pytest.raises(InputError, match=r"a planner is an object with a `plan\(percepts\)`") as exc:
        simulate(short("corridor.yaml", 0.2), "dwa")
    assert "make_planner('dwa', world)" in exc.value.hint


def _robot(world, **changes):
    agent = world.agents[0]
    return (dataclasses.replace(agent, robot=dataclasses.replace(agent.robot, **changes)),)


@pytest.mark.parametrize("change, says", [
    (lambda w: {"time_limit": float("nan")}, "`time_limit` must be a finite number, not nan"),
    (lambda w: {"time_limit": float("inf")}, "`time_limit` must be a finite number, not inf"),
    (lambda w: {"time_limit": 0.0}, "`time_limit` must be positive, not 0.0"),
    (lambda w: {"time_limit": 0.01}, "`time_limit` must be at least dt (0.05 s)"),
    (lambda w: {"dt": -0.05}, "`dt` must be positive, not -0.05"),
    (lambda w: {"dt": 1e-9}, "`time_limit` must be at most 100,000 ticks"),
    (lambda w: {"substeps": 0}, "`substeps` must be at least 1, not 0"),
    (lambda w: {"substeps": 2.0}, "`substeps` must be a whole number (an int), not 2.0"),
    (lambda w: {"seed": True}, "`seed` must be a whole number of 0 or more, not True"),
    (lambda w: {"agents": _robot(w, max_speed=float("nan"))},
     "`agents[0].robot.max_speed` must be a finite number"),
    (lambda w: {"agents": _robot(w, wheelbase=30.0)}, "`agents[0].robot.wheelbase` must be at most"),
    (lambda w: {"agents": _robot(w, max_speed=100000.0)},
     "`agents[0].robot.max_speed` must be at most 327.6 in/s at dt 0.05 s"),
    (lambda w: {"dt": 1.0}, "`agents[0].robot.max_speed` must be at most 16.38 in/s at dt 1 s"),
    (lambda w: {"agents": _robot(w, steering_min=150.0, steering_max=30.0)},
     "`agents[0].robot.steering_min` must be below steering_max (30), not 150.0"),
    (lambda w: {"sensors": dataclasses.replace(w.sensors, range=0.0)},
     "`sensors.range` must be positive"),
    (lambda w: {"sensors": dataclasses.replace(w.sensors, count=0)},
     "`sensors.count` must be at least 1"),
    (lambda w: {"obstacles": (dataclasses.replace(w.obstacles[0], radius=-8.0),) + w.obstacles[1:]},
     "`obstacles[0].radius` must be positive"),
    (lambda w: {"corridors": (dataclasses.replace(w.corridors[0], width=float("inf")),)},
     "`corridors[0].width` must be a finite number"),
    (lambda w: {"corridors": (dataclasses.replace(w.corridors[0], points=((0.0, 0.0),)),)},
     "`corridors[0].points` must be a list of at least 2 points (x, y), not ((0.0, 0.0),)"),
])
def test_a_world_changed_in_python_is_checked_as_its_file_would_be(change, says):
    """time_limit=0 said "no tick recorded yet" (the Gymnasium environment "the run has
    ended"), NaN was a bare ValueError in the loop, inf an OverflowError; a world file with
    these values is refused at its line."""
    import gymnasium

    import mitos_cli.gym  # noqa: F401
    from mitos_cli.errors import WorldError

    world = load_world(packaged_path("worlds", "moving.yaml"))
    bad = dataclasses.replace(world, **change(world))
    with pytest.raises(WorldError, match=re.escape(says)):
        simulate(bad, seed=1)
    with pytest.raises(WorldError, match=re.escape(says)):
        gymnasium.make("mitos/World-v0", world=bad)
    assert Simulation(dataclasses.replace(world, seed=np.int64(3))).seed == 3   # an integer


def test_a_misspelt_robot_model_in_python_is_refused_with_the_readers_hint():
    """`model="tricycl"` ran as a tricycle, where the reader says "did you mean `tricycle`?"."""
    from mitos_cli.errors import WorldError

    world = short("corridor.yaml", 0.2)
    with pytest.raises(WorldError, match=re.escape("`agents[0].robot.model` must be one of "
                                                   "tricycle, not 'tricycl'")) as exc:
        Simulation(dataclasses.replace(world, agents=_robot(world, model="tricycl")))
    assert exc.value.hint == "did you mean `tricycle`?"


def test_a_world_built_in_python_with_a_turn_too_tight_is_refused_before_the_run():
    """`Robot(wheelbase=1e-10)` made the brake's sweep ask for 8 TiB at the first tick."""
    import gymnasium

    import mitos_cli.gym  # noqa: F401
    from mitos_cli.errors import WorldError

    world = short("corridor.yaml", 0.2)
    agent = dataclasses.replace(world.agents[0],
                                robot=dataclasses.replace(world.robot, wheelbase=1e-10))
    tiny = dataclasses.replace(world, agents=(agent, *world.agents[1:]))
    with pytest.raises(WorldError, match=r"its tightest turn has a radius of 5\.77e-11 in"):
        Simulation(tiny)
    with pytest.raises(WorldError, match=r"its tightest turn has a radius of 5\.77e-11 in"):
        gymnasium.make("mitos/World-v0", world=tiny)


@pytest.mark.parametrize("kwargs, says", [
    ({"worlds": "one"}, "takes a list of loaded worlds, not the path `one`"),
    ({"worlds": ["corridor"]}, "runs loaded worlds, not str"),
    ({"runs": 2.5}, "`runs` is a whole number, 0 or more, not `2.5`"),
    ({"runs": True}, "`runs` is a whole number, 0 or more, not `True`"),    # was 1 run
    ({"workers": 0}, "`workers` is a whole number, 1 or more, not `0`"),
    ({"seed": -1}, "a seed is a whole number"),
    ({"seed": True}, "a seed is a whole number, 0 or more, not `True`"),
])
def test_run_many_says_what_is_wrong_with_its_arguments(kwargs, says):
    """A World not in a list, runs=2.5, workers=0 or seed=-1 met a TypeError, a
    ZeroDivisionError or NumPy's ValueError inside."""
    from mitos_cli.errors import InputError
    from mitos_cli.sim import run_many

    world = short("corridor.yaml", 0.2)
    args = {"worlds": [world], "runs": 1, "workers": 1, **kwargs}
    with pytest.raises(InputError, match=re.escape(says)):
        run_many(**args)
    with pytest.raises(InputError, match=r"run_many\(\[world\], \.\.\.\)"):
        run_many(world)          # type: ignore[arg-type]


def test_a_misspelt_outcome_or_figure_of_the_runs_is_named():
    """rate("sucess") was 0.0, a rate of a run that may all have succeeded; stat("time") a
    KeyError."""
    from mitos_cli.errors import InputError
    from mitos_cli.sim import run_many

    runs = run_many([short("corridor.yaml", 0.2)], runs=2, seed=1, workers=1).worlds[0]
    assert runs.rate("timeout") == 1.0 and runs.count("success") == 0
    for call, says in ((lambda: runs.rate("sucess"), "did you mean `success`?"),
                       (lambda: runs.count(None), "unknown outcome `None`"),
                       (lambda: runs.stat("time"), "did you mean `time_s`?"),
                       (lambda: runs.stat("world"), "unknown figure `world`")):
        with pytest.raises(InputError, match=re.escape(says)):
            call()
    assert runs.stat("time_s") == (0.2, 0.0)       # two runs that agree: a spread of 0


def test_the_spread_of_one_run_is_none_not_zero():
    """stat() gave one run a standard deviation of 0.0, which reads as runs that agree (a
    sample standard deviation of one value is undefined); figures(), `--json` and the table
    said nothing (None, null, no ±) already."""
    from mitos_cli.sim import run_many

    one = run_many([short("corridor.yaml", 0.2)], runs=1, seed=1, workers=1).worlds[0]
    assert one.stat("time_s") == (0.2, None)
    assert one.figures()["time_s"] == {"mean": 0.2, "std": None}


@pytest.mark.parametrize("command", ["fast", [["90", 20.0]], [("5_0", 10.0)],
                                     np.array([["90", "20"]])])
def test_a_command_holding_text_is_refused(command):
    """``step([["90", 20]])`` steered at 90 deg and ``[("5_0", 10)]`` at 50: NumPy reads
    text as ``float()`` does. Text is refused, as bools are, and the run is left as it was."""
    from mitos_cli.errors import CommandError

    sim = Simulation(short("corridor.yaml", 1.0))
    with pytest.raises(CommandError, match="the command must be numbers, not text"):
        sim.step(command)
    assert sim.ticks == 0


@pytest.mark.parametrize("command, says", [
    (5.0, "not `5.0`"),                 # (None is no command: the planner drives)
    (np.zeros((2, 2)), "not of shape (2, 2)"),
])
def test_a_command_that_is_not_numbers_is_a_command_error(command, says):
    """step(5.0) met NumPy's "cannot reshape"; the shape and NaN messages were ValueErrors
    outside the project's errors (they are still ValueErrors)."""
    from mitos_cli.errors import CommandError

    sim = Simulation(short("corridor.yaml", 1.0))
    with pytest.raises(CommandError, match=r"a command is \[1, 2\]") as exc:
        sim.step(command)
    assert says in exc.value.message and isinstance(exc.value, ValueError)
    with pytest.raises(CommandError, match="must be finite numbers"):
        sim.step(np.array([[90.0, np.inf]]))
    with pytest.raises(CommandError, match="must be numbers, not bools"):    # read as 1.0
        sim.step([[True, 30.0]])
    assert sim.ticks == 0


def test_a_command_past_a_floats_range_is_a_command_error():
    """10**400 in a command given from outside, or returned by a planner, met NumPy's bare
    OverflowError ("int too large to convert to float")."""
    from mitos_cli.errors import CommandError

    class Huge:
        name = "huge"

        def plan(self, p):
            return [10**400], [10.0]

    sim = Simulation(short("corridor.yaml", 1.0))
    for command in ([[10**400, 20.0]], [90.0, -10**5000]):
        with pytest.raises(CommandError, match="the command must be finite numbers .* too large"):
            sim.step(command)
    assert sim.ticks == 0
    with pytest.raises(CommandError, match="planner `huge` must be finite numbers .* too large"):
        simulate(short("corridor.yaml", 1.0), Huge())


@pytest.mark.parametrize("reach", [np.nan, np.inf, 1e308, -5.0, "far", True, 10**400],
                         ids=["nan", "inf", "1e308", "-5", "text", "True", "10**400"])
def test_a_path_reach_that_is_no_distance_is_named_with_the_planner(reach):
    """NaN, infinity, 1e308, text or 10**400 met NumPy's arange ("cannot compute length",
    "Maximum allowed size exceeded") or float()'s errors at the first tick; -5 gave an empty
    path and True one of 1 in, without a word."""
    from mitos_cli.errors import InputError

    class Ahead:
        name = "ahead"
        path_reach = reach

        def plan(self, p):
            return np.full(len(p.pose), 90.0), np.full(len(p.pose), 10.0)

    with pytest.raises(InputError, match="planner `ahead` asks for a `path_reach` of `"):
        simulate(short("corridor.yaml", 0.2), Ahead())
    Ahead.path_reach = 40
    assert simulate(short("corridor.yaml", 0.2), Ahead()).ticks == 4


@pytest.mark.parametrize("written", [720.0, -1080.0, 360.0])
def test_a_start_heading_past_a_half_turn_is_recorded_within_it(written):
    """A start written as 720 deg was recorded as 720 at tick 0 (`--out`'s pose_heading_deg,
    `--trace`, the Gymnasium pose) and as 0 from tick 1 on. It is the run of heading 0."""
    world = short("corridor.yaml", 1.0)
    agent = world.agents[0]
    turned = world.with_changes(agents=(dataclasses.replace(
        agent, start=dataclasses.replace(agent.start, heading=written)),))
    sim = Simulation(turned, seed=1)
    assert sim.pose[0, 2] == 0.0 and str(sim.pose[0, 2]) == "0.0"
    same_run(simulate(turned, seed=1), simulate(world, seed=1))


def test_a_run_is_timed_by_the_ticks_it_moved():
    """A run that ends on what a tick observed (a contact, every robot at its goal) is timed
    to that tick: figure4's contact, recorded at 14.65 s, read "after 14.70 s" (the ticks
    recorded times dt). A timeout moved every tick it recorded."""
    crash = simulate(load_world(packaged_path("worlds", "figure4.yaml")))
    assert crash.outcome == "collision" and crash.clearance[-1, 0] <= 0
    assert crash.summary()["time_s"] == round(float(crash.t[-1]), 6) == 14.65
    home = simulate(load_world(packaged_path("worlds", "corridor.yaml")))
    assert home.outcome == "success"
    assert home.summary()["time_s"] == round(float(home.t[-1]), 6) == 17.9
    assert home.summary()["mean_speed_in_s"] == pytest.approx(
        home.summary()["path_length_in"] / 17.9)
    out = simulate(short("corridor.yaml", 1.0))
    assert out.outcome == "timeout" and out.summary()["time_s"] == 1.0 == out.ticks * 0.05


class _Spin:
    """Full lock to the left at full speed: the body's outer front corner sweeps wide."""

    name = "spin"

    def plan(self, p):
        n = len(p.pose)
        return np.full(n, 30.0), np.full(n, 320.0)


def _spinning_world(poles=()):
    from mitos_cli.sim.world import Obstacle

    w = load_world(packaged_path("worlds", "corridor.yaml"))
    robot = dataclasses.replace(w.robot, max_speed=320.0, acceleration=1e5,
                                max_steering_rate=1e5, brake=False)
    agent = dataclasses.replace(w.agents[0], robot=robot,
                                start=dataclasses.replace(w.agents[0].start, x=200.0, y=-60.0,
                                                          heading=0.0))
    return w.with_changes(corridors=(dataclasses.replace(w.corridors[0], width=300.0),),
                          agents=(agent,), obstacles=tuple(
                              Obstacle(name=f"pole{j}", shape="circle", x=x, y=y, radius=0.5)
                              for j, (x, y) in enumerate(poles)),
                          randomise=dataclasses.replace(w.randomise, obstacles=()))


def _swept_unseen(sim, tick: int) -> tuple[float, float]:
    """A point 0.6 in deep in the body part of the way through the move after ``tick``,
    more than 0.6 in outside it at both ends (contact is checked at ticks)."""
    from mitos_cli.sim import kinematics
    from mitos_cli.sim.geometry import rect_corners

    robot = sim.robots[0]
    motion = sim._came.of_run()

    def body(f):
        x, y, h = kinematics.along(*motion, sim.limits, sim.dt, sim.world.substeps, f)
        return x[0], y[0], h[0]

    def inside(pose, q, by):      # q at least `by` inside the footprint at `pose`
        d = np.array(q) - pose[:2]
        h = pose[2]
        along, across = d @ (np.cos(h), np.sin(h)), d @ (-np.sin(h), np.cos(h))
        return abs(along) <= robot.length / 2 - by and abs(across) <= robot.width / 2 - by

    assert tick == sim.ticks - 1
    start, end = body(0.0), body(1.0)
    for f in np.linspace(0.02, 0.98, 49):
        x, y, h = mid = body(f)
        for corner in rect_corners(*(np.array([v]) for v in (x, y, h, robot.length,
                                                            robot.width)))[0]:
            q = corner + (np.array([x, y]) - corner) / np.hypot(x - corner[0], y - corner[1])
            if inside(mid, q, 0.6) and not inside(start, q, -0.6) and not inside(end, q, -0.6):
                return float(q[0]), float(q[1])
    raise AssertionError("no point swept unseen")


def test_a_contact_between_two_ticks_is_a_collision():
    """Contact is checked at ticks; at 320 in/s on full lock the outer front corner swept a
    1 in pole between two of them with no collision (clearance 0.7 in before, 7.3 after).
    The move between is now looked at where the two clearances leave room for a contact:
    the run collides at the later tick, with the clearance found there, and moves as before
    up to it."""
    sim = Simulation(_spinning_world(), planner=_Spin(), seed=1)
    sim.step()
    sim.step()
    pole = _swept_unseen(sim, 1)
    free = Simulation(_spinning_world(), planner=_Spin(), seed=1)
    for _ in range(3):
        free.step()
    hit = Simulation(_spinning_world([pole]), planner=_Spin(), seed=1)
    while not hit.done:
        hit.step()
    res = hit.result()
    assert res.summary()["outcome"] == "collision" and res.ticks == 3
    assert res.clearance[2, 0] <= 0.0 < res.clearance[1, 0]
    assert np.array_equal(res.pose, free.result().pose)


def test_a_contact_between_ticks_is_found_alike_in_lockstep():
    """Runs in lockstep look between ticks as a run alone does, bit for bit."""
    from mitos_cli.sim.lockstep import run_lockstep

    sim = Simulation(_spinning_world(), planner=_Spin(), seed=1)
    sim.step()
    sim.step()
    world = _spinning_world([_swept_unseen(sim, 1)])
    alone = [simulate(world, _Spin(), seed) for seed in (1, 2, 3)]
    together = run_lockstep(world, _Spin(), [1, 2, 3], batch=3)
    assert [r.summary() for r in together] == [r.summary() for r in alone]
    assert all(np.array_equal(a.clearance, b.clearance) for a, b in zip(alone, together))
    assert {r.summary()["outcome"] for r in alone} == {"collision"}


@pytest.mark.parametrize("name", ["corridor", "office", "moving", "multirobot", "detour"])
def test_the_clearance_between_ticks_is_the_tick_s_at_the_tick(name):
    """What the check between ticks measures part of the way through a move
    (:meth:`Simulation._clearance_at`) is, at the move's end, the clearance the next tick
    senses there: the same walls (corridors, map cells), obstacles where they then are, and
    the other robots."""
    world = load_world(packaged_path("worlds", f"{name}.yaml"))
    sim = Simulation(world, seed=world.seed)
    for k in range(120):
        sim.step()
        if sim.done:
            break
        if k % 10 == 9:
            ahead = [sim._clearance_at(i, 1.0) for i in range(sim.n)]
            tick = sim.step()
            assert np.allclose(ahead, tick.clearance, rtol=0, atol=1e-9), (k, ahead)


class _Drive:
    name = "drive"

    def __init__(self, steering: float, speed: float) -> None:
        self.steering, self.speed = steering, speed

    def plan(self, p):
        n = len(p.pose)
        return np.full(n, self.steering), np.full(n, self.speed)


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(steering=st.one_of(st.floats(30, 60), st.floats(120, 150)), speed=st.floats(150, 320),
       f=st.floats(0.2, 0.8), corner=st.integers(0, 3), inset=st.floats(0.0, 1.5))
def test_no_contact_between_ticks_is_missed(steering, speed, f, corner, inset):
    """Against the clearance sampled at 201 places along the move: wherever the body went
    more than :data:`GRAZE` into a pole between two ticks, the check finds a contact. The
    pole is put where a corner of the body passes part of the way through a fast turn (a
    quarter of them clear of the body at both ticks: the others are not this test's)."""
    from mitos_cli.sim import kinematics
    from mitos_cli.sim.geometry import rect_corners
    from mitos_cli.sim.loop import GRAZE

    free = Simulation(_spinning_world(), planner=_Drive(steering, speed), seed=1)
    free.step()
    free.step()
    r = free.robots[0]
    x, y, h = kinematics.along(*free._came.of_run(), free.limits, free.dt,
                               free.world.substeps, f)
    q = rect_corners(x, y, h, np.array([r.length]), np.array([r.width]))[0][corner]
    pole = q + (np.array([x[0], y[0]]) - q) * inset / np.hypot(x[0] - q[0], y[0] - q[1])
    sim = Simulation(_spinning_world([tuple(pole)]), planner=_Drive(steering, speed), seed=1)
    sim.step()
    assume(not sim.done)
    tick = sim.step()
    assume(not sim.done)
    before, now = float(tick.clearance[0]), sim._clearance_at(0, 1.0)   # tick 1, and 2 ahead
    assume(before > 0 and now > 0)
    least = min(sim._clearance_at(0, g) for g in np.linspace(0.0, 1.0, 201))
    travel = float(sim._travel(sim._came.of_run()[3])[0])
    found = sim._touched_between(0, before, now, travel)
    if least < -2 * GRAZE:
        assert found is not None and found <= 0.0
    if found is not None:
        assert found <= 0.0


def test_a_misnamed_jitter_among_many_obstacles_names_a_few_and_the_nearest():
    """A world of 300 poles listed all 300 names after "must be one of" (6,000 characters)."""
    from mitos_cli.errors import WorldError
    from mitos_cli.sim.world import Jitter, Obstacle, Randomise

    world = short("corridor.yaml", 0.2)
    poles = tuple(Obstacle(f"pole_{i}", "circle", 100.0 + 3 * i, 30.0, radius=1.0)
                  for i in range(300))
    many = dataclasses.replace(world, obstacles=poles, randomise=Randomise((Jitter("pol_299"),)))
    with pytest.raises(WorldError) as exc:
        Simulation(many)
    assert "must be one of 300 names: pole_0, pole_1, pole_2, pole_3, pole_4, pole_5, " \
           "pole_6, pole_7, ..., not 'pol_299'" in exc.value.message
    assert exc.value.hint == "did you mean `pole_299`?"


def test_reset_takes_randomise_and_runs_as_a_run_made_so():
    """reset(seed) kept the constructor's randomise: a randomised episode of a Simulation made
    as written meant writing its attribute. reset(seed, randomise=True) runs what
    simulate(world, seed=seed, randomise=True) runs, also for a run of a Lockstep, whose
    scene, shared by runs as written, is not the randomised run's (detour.yaml moves an
    obstacle its robot is told of)."""
    from mitos_cli.errors import InputError
    from mitos_cli.resources import packaged_path
    from mitos_cli.sim import Lockstep, load_world, simulate

    world = load_world(str(packaged_path("worlds", "detour.yaml")))
    drawn = simulate(world, seed=7, randomise=True)
    sim = Simulation(world, seed=1)
    sim.step()
    for run in (sim, Lockstep(world, None, seeds=[1, 2]).runs[0]):
        run.reset(seed=7, randomise=True)
        while not run.done:
            run.step()
        assert np.array_equal(run.result().pose, drawn.pose) and run.randomise is True
    sim.reset(seed=3)                                  # as before: still randomised
    assert sim.randomise is True
    sim.reset(seed=3, randomise=False)
    while not sim.done:
        sim.step()
    assert np.array_equal(sim.result().pose, simulate(world, seed=3).pose)
    with pytest.raises(InputError, match="randomise is True or False, not `'no'`"):
        sim.reset(seed=1, randomise="no")


def test_a_run_still_going_is_driving_and_its_result_so_far_a_timeout():
    """sim.outcome read `timeout` from the first tick of a run with a minute to go (and
    robot_outcomes too), where the Gymnasium environment's info says `driving`; result() of
    a run cut short is still a `timeout`, and the verdicts at the end are unchanged."""
    from mitos_cli.resources import packaged_path
    from mitos_cli.sim import load_world

    sim = Simulation(load_world(str(packaged_path("worlds", "multirobot.yaml"))))
    sim.step()
    assert sim.outcome == "driving" and sim.robot_outcomes == ("driving", "driving")
    assert sim.result().outcome == "timeout" and sim.result().robot_outcomes == ("timeout",) * 2
    while not sim.done:
        sim.step()
    assert sim.outcome == sim.result().outcome == "success"
    assert sim.robot_outcomes == sim.result().robot_outcomes == ("success", "success")
