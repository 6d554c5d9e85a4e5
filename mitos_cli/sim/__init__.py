"""``mitos simulate``: a kinematic corridor simulator that drives the compiled rule base.

API (everything in inches, seconds, degrees)::

    from mitos_cli.sim import load_world, simulate, run_many, FuzzyPlanner

    world = load_world("worlds/figure4.yaml")      # WorldError with file:line:col when bad
    result = simulate(world)                       # packaged rule base, behavior world.behavior
    result = simulate(world, FuzzyPlanner("my.rules", "drive"), seed=3)
    result.outcome          # "success" | "collision" | "timeout" | "stuck"
                            # (a robot's own, in result.robot_outcomes: also "stopped")
    result.summary()        # the --json dict: world, seed, outcome, reached_goal, collisions,
                            # time_s, path_length_in, min_clearance_in, replans, backouts,
                            # mean_speed_in_s, steering_total_variation_deg, ticks (over all
                            # robots), near_miss, and with several robots `robots`: each
                            # one's (result.robot_metrics)
    result.t, result.pose[T, n, 3], result.speed[T, n], result.steering[T, n],
    result.command[T, n, 2], result.ranges[T, n, B], result.clearance[T, n],
    result.perceived["road"][T, n], result.true["road"][T, n], result.obstacles[T, O, 2]

    sim = Simulation(world, planner=None, seed=3)   # the same run, one tick at a time
    while not sim.done:
        tick = sim.step()          # a Tick: pose, speed, steering, command, ranges, inputs,
                                   # clearance, obstacles, active, progress (rows are robots)
    sim.pose, sim.speed, sim.clearance, sim.time, sim.outcome   # the state now ("driving")
    sim.result()                   # the SimResult simulate() returns

    results = run_lockstep(world, None, seeds=range(64), randomise=True)  # runs stepped
                            # together: one rule evaluation per tick for all, each run's bits
                            # those it has alone (Lockstep: the same, a tick at a time)
    runs = run_many([world], runs=20, seed=1, planner=None, workers=2)   # randomised runs
    runs.to_json()          # per world: outcome rates, each metric's mean and std (replans
                            # and backouts too), every run's summary under runs_detail
    runs.worlds[0].rate("success"), runs.worlds[0].robots   # (several robots: each one's)

Modules: ``world`` (model), ``worldfile`` (YAML loader), ``pgm`` + ``gridmap`` (ROS map_server
maps), ``staticmap`` (walls from corridors or grids), ``geometry``, ``kinematics`` (tricycle),
``sensors`` (ray casting), ``obstacles`` (motion, randomisation), ``route`` (A*),
``perception`` (readings -> rule inputs), ``planner`` (the planner protocol, FuzzyPlanner),
``loop`` (the steppable ``Simulation`` and ``simulate``, a loop over its ticks), ``lockstep``
(runs stepped together), ``runs`` (many runs, process pool, each worker's runs in lockstep),
``export`` (CSV, traces), ``live`` (terminal view). Drawing lives in ``mitos_cli.draw.world``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:                  # what __getattr__ gives, for the type checker
    from .lockstep import Lockstep as Lockstep
    from .lockstep import run_lockstep as run_lockstep
    from .loop import SimResult as SimResult
    from .loop import Simulation as Simulation
    from .loop import Tick as Tick
    from .loop import simulate as simulate
    from .planner import FuzzyPlanner as FuzzyPlanner
    from .planner import Percepts as Percepts
    from .planner import Planner as Planner
    from .runs import run_many as run_many
    from .worldfile import load_world as load_world

__all__ = ["load_world", "simulate", "Simulation", "Tick", "run_many", "FuzzyPlanner", "Planner", "Percepts",
           "SimResult", "Lockstep", "run_lockstep"]


def __getattr__(name: str) -> object:
    if name == "load_world":
        from .worldfile import load_world

        return load_world
    if name in ("simulate", "Simulation", "Tick", "SimResult"):
        from . import loop

        return getattr(loop, name)
    if name in ("Lockstep", "run_lockstep"):
        from . import lockstep

        return getattr(lockstep, name)
    if name == "run_many":
        from .runs import run_many

        return run_many
    if name in ("FuzzyPlanner", "Planner", "Percepts"):
        from . import planner

        return getattr(planner, name)
    raise AttributeError(name)
