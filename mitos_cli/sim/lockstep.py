"""Runs in lockstep: independent runs of one world stepped together, tick by tick.

Each tick the robots of every run still going are sensed in one pass (:func:`.rows.sense`:
beams, noise from each robot's own stream, clearance), the marks they see through cleared
from their maps in one pass (:func:`.knowledge.clear_all`), the cells their echoes came from
found in one pass (:func:`.knowledge.beyond_cells`), their maps marked from them in one pass
(:func:`.knowledge.mark_all`), what they see that their maps do not show cut into objects and
tested against the beams they kept in one pass (:func:`.movers.sightings`), the cells near
them on their maps found in one pass (:func:`.knowledge.near_all`), their readings looked up
where their routes were planned in one pass (:func:`.knowledge.accounted_all`), their pursuit
points found in one pass (:func:`.perception.pursuit_points`) and their rule inputs perceived
in one pass (:func:`.perception.perceive_rows`); what else a robot's own map and route need
(following its tracks, replanning) and its check are done run by run, with the code of a
run alone (:class:`~mitos_cli.sim.loop.Simulation`). Then the fuzzy planner's rule network is
evaluated once for the active robots of every run (one engine batch: the engine gives each
row the bits it gives alone), each run's brake checks its commands, and the robots of every run
move in one batch of kinematics (elementwise per robot). Runs that end drop out. Every batched
stage is elementwise per robot or an exact minimum, so each run's ticks, trajectory and summary
are bit for bit those of the same run alone, whatever the batch
(``tests/test_sim_lockstep.py``, ``tests/test_sim_same_bits.py``)."""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import fields

import numpy as np

from . import kinematics, knowledge, movers, perception, rows, safety
from .loop import Scene, SimResult, Simulation, shared_scene
from .planner import FuzzyPlanner, Planner
from .world import World

#: The row of each input in a tick's block of inputs (:data:`.perception.INPUTS` order).
_ROW = {key: j for j, key in enumerate(perception.INPUTS)}

#: Runs stepped together by default: enough to make the batched calls worth their set-up,
#: few enough that the runs' recorded ticks stay small.
BATCH = 64


class Lockstep:
    """Runs of ``world`` from ``seeds`` stepped together (``randomise``: each run draws its
    obstacle places and sensor noise from its seed, as ``simulate(..., randomise=True)``)."""

    def __init__(self, world: World, planner: Planner | None = None,
                 seeds: Sequence[int] = (), *, randomise: bool = False,
                 scene: Scene | None = None) -> None:
        if planner is None:
            planner = FuzzyPlanner(None, world.behavior)
        self.planner = planner
        if scene is None and seeds:      # the runs' map and routes, prepared once if they can
            scene = shared_scene(world, randomise)
        self.runs = [Simulation(world, planner, seed, randomise=randomise, scene=scene)
                     for seed in seeds]
        self._limits: list = []                  # the runs that last moved and their limits

    @property
    def done(self) -> bool:
        return all(run.done for run in self.runs)

    def step(self) -> None:
        """One tick of every run still going."""
        live = [run for run in self.runs if not run.done]
        commands = self._commands(live, _observe_together(live))
        ticks = [run.commanded(command) for run, command in zip(live, commands)]
        _guard_together(live, ticks)
        moving = [run for run, s in zip(live, ticks) if run.verdict(s)[1]]
        if moving:
            _move_together(moving, self._limits)

    def results(self) -> list[SimResult]:
        """Step until every run has ended; each run's :class:`SimResult`, in seed order."""
        while not self.done:
            self.step()
        return [run.result() for run in self.runs]

    def _commands(self, live: list[Simulation], seen: list) -> list[np.ndarray | None]:
        """Each run's commands ``[n, 2]`` from one evaluation of the rule network for the
        active robots of all of them (``None``: the run plans itself, as planners other than
        the fuzzy one do, whose rows need not be independent of the batch)."""
        planner = self.planner
        if not isinstance(planner, FuzzyPlanner) or not live:
            return [None] * len(live)
        active = np.concatenate([run.active for run in live])    # [all robots of all runs]
        compiled = planner.compiled
        X = np.empty((np.count_nonzero(active), len(compiled.inputs)))
        if len(X) == 0:
            return [None] * len(live)
        blocks = np.concatenate([s.block for s in seen], axis=1)        # [inputs, robots]
        for j, key in enumerate(compiled.inputs):
            X[:, j] = blocks[_ROW[key], active]
        from ..engine.evaluation import evaluate

        out = evaluate(compiled, X, detail=False).outputs
        commands = np.zeros((len(active), 2))
        for j, key in enumerate(("steering", "speed")):
            commands[active, j] = out[:, compiled.outputs.index(key)]
        stops = np.cumsum([run.n for run in live]).tolist()
        return [commands[stop - run.n:stop] for run, stop in zip(live, stops)]


def _observe_together(runs: list[Simulation]) -> list:
    """:meth:`Simulation.observe` of every run: their robots' beams and clearance sensed in
    one :func:`.rows.sense`, their maps cleared in one :func:`.knowledge.clear_all` and
    marked in one :func:`.knowledge.mark_all`, what they see seen in one
    :func:`.movers.sightings`, what their maps hold near them found in one
    :func:`.knowledge.near_all` and their readings looked up in one
    :func:`.knowledge.accounted_all`, their pursuit points found in one
    :func:`.perception.pursuit_points` and their inputs perceived in one
    :func:`.perception.perceive_rows` (each row the bits of its robot alone); what else each
    robot's map and route need, run by run."""
    fresh = [run for run in runs if not run.observed]
    if len(fresh) > 1:
        parts: list[rows.SenseRow] = []
        spans = []
        for run in fresh:
            mine = run.sense_rows()
            spans.append((len(parts), len(parts) + len(mine)))
            parts += mine
        world = fresh[0].world
        got = rows.sense(parts, fresh[0].angles, world.sensors.range)
        sensed = [run.sensed(got.part(start, stop)) for run, (start, stop) in zip(fresh, spans)]
        clearing = [run.clearing(s) for run, s in zip(fresh, sensed)]
        origins, dirs, measured = (np.concatenate([c[j] for c in clearing]) for j in (1, 2, 3))
        maps = [m for c in clearing for m in c[0]]
        knowledge.clear_all(maps, origins, dirs, measured, world.sensors.range)
        beyond = knowledge.beyond_cells(maps, origins, dirs, measured)
        learned = None
        if beyond is not None:
            for run, s, (start, stop) in zip(fresh, sensed, spans):
                run.beyond(s, beyond[start:stop])
            marked = knowledge.mark_all(maps, beyond, np.concatenate(
                [run.seeing(s) for run, s in zip(fresh, sensed)]))
            learned = [marked[start:stop] for start, stop in spans]
        framing = [run.framing(s) for run, s in zip(fresh, sensed)]
        frames = perception.frames([r for f in framing for r in f[0]],
                                   np.concatenate([f[1] for f in framing]),
                                   np.concatenate([f[2] for f in framing]))
        sighted = _sightings_together(fresh, sensed, learned)
        near = _near_together([run.aim_squares(s) for run, s in zip(fresh, sensed)])
        aims = [aim for run, s, (start, stop), seen, cells in zip(fresh, sensed, spans, sighted,
                                                                  near)
                for aim in run.aims(s, frames[start:stop], seen, cells)]
        ahead, targets = perception.pursuit_points(aims, fresh[0].settings)
        gaps = perception.route_gaps(aims)
        # (after the aims: a route planned again is planned round the cells marked by then)
        accounted = (knowledge.accounted_all(maps, beyond)
                     if beyond is not None and world.replan == "clearance" else None)
        ticks, sights = [], []
        for run, s, (start, stop) in zip(fresh, sensed, spans):
            mine_ = run.aimed(s, aims[start:stop], ahead[start:stop], targets[start:stop],
                              gaps[start:stop], None if accounted is None
                              else accounted[start:stop])
            ticks.append((run, s, mine_, start, stop))
            sights += mine_
        inputs = perception.perceive_rows(sights, world.sensors.range, fresh[0].settings)
        block = np.stack([inputs[key] for key in perception.INPUTS])     # [inputs, robots]
        for run, s, mine_, start, stop in ticks:
            run.perceived(s, mine_, block[:, start:stop])
            run.conclude(s)
    return [run.observe() for run in runs]


def _sightings_together(runs: list[Simulation], sensed: list,
                        learned: list | None = None) -> list[list[movers.Seen]]:
    """What each run is :meth:`~.loop.Simulation.watching` (its maps marked, or ``learned``
    whether they were, run by run), seen in one :func:`.movers.sightings` for the robots of
    all runs (they tick together: one time)."""
    watched = [run.watching(s, None if learned is None else learned[j])
               for j, (run, s) in enumerate(zip(runs, sensed))]
    looking = [w for w in watched if w[0]]                  # runs whose robots follow something
    got = movers.sightings([sp for w in looking for sp in w[0]], sensed[0].t,
                           *(np.concatenate([w[j] for w in looking]) for j in (1, 2, 3, 4))
                           ) if looking else []
    ends = [0, *itertools.accumulate(len(w[0]) for w in watched)]
    return [got[a:b] for a, b in zip(ends[:-1], ends[1:])]


def _near_together(asks: list[tuple]) -> list[list[np.ndarray]]:
    """What the maps answer each run's squares ``(maps, points, reaches, given)`` (the runs of
    a world ask alike), asked in one :func:`.knowledge.near_all`, run by run."""
    maps = [m for ask in asks for m in ask[0]]
    if not maps:
        return [[] for _ in asks]
    got = knowledge.near_all(maps, np.concatenate([ask[1] for ask in asks]),
                             np.concatenate([ask[2] for ask in asks]), asks[0][3])
    ends = [0, *itertools.accumulate(len(ask[0]) for ask in asks)]
    return [got[a:b] for a, b in zip(ends[:-1], ends[1:])]


def _guard_together(runs: list[Simulation], ticks: list) -> None:
    """Every run's guard on its tick's commands, what every robot's map holds near it found
    in one :func:`.knowledge.near_all` and the first sweep of every robot of every run
    measured in one :func:`.safety.free_travels`."""
    near = _near_together([(*run.brake_squares(s), False) for run, s in zip(runs, ticks)])
    sweeps = [run.braking(s, cells) for run, s, cells in zip(runs, ticks, near)]
    every = [sweep for mine in sweeps for sweep in mine]
    if not every:
        return
    cfg = runs[0].brake_settings
    free = safety.free_travels(every, cfg.step)
    start = 0
    for run, s, mine in zip(runs, ticks, sweeps):
        run.braked(s, mine, free[start:start + len(mine)])
        start += len(mine)


def _limits(runs: list[Simulation], kept: list) -> kinematics.Limits:
    """The limits of the robots of ``runs``, one after the other; ``kept`` holds the last
    (the same runs moving together keep the same limits, whose ramps the kinematics then
    derives once)."""
    if not kept or len(kept[0]) != len(runs) or any(a is not b for a, b in zip(kept[0], runs)):
        kept[:] = [list(runs), kinematics.Limits(*(
            np.concatenate([getattr(run.limits, f.name) for run in runs])
            for f in fields(kinematics.Limits)))]
    return kept[1]


def _move_together(runs: list[Simulation], kept: list) -> None:
    """:meth:`Simulation.act` for every robot of ``runs`` in one call of the kinematics
    (``kept``: the last limits, :func:`_limits`)."""
    parts = [run.motion() for run in runs]
    x, y, h, v, steer, c_steer, c_speed = (np.concatenate([p[j] for p in parts])
                                           for j in range(7))
    limits = _limits(runs, kept)
    world = runs[0].world
    after = kinematics.step(x, y, h, v, steer, c_steer, c_speed, limits, world.dt,
                            world.substeps)
    start = 0
    for run in runs:
        stop = start + run.n
        run.move_to(*(a[start:stop] for a in after))
        run.moved()
        start = stop


def run_lockstep(world: World, planner: Planner | None, seeds: Sequence[int], *,
                 randomise: bool = False, scene: Scene | None = None,
                 batch: int = BATCH) -> list[SimResult]:
    """The runs of ``world`` from ``seeds``, ``batch`` at a time in lockstep: the same results,
    bit for bit, as ``[simulate(world, planner, s, randomise=randomise, scene=scene) for s in
    seeds]``."""
    out: list[SimResult] = []
    for i in range(0, len(seeds), max(1, batch)):
        out += Lockstep(world, planner, seeds[i:i + batch], randomise=randomise,
                        scene=scene).results()
    return out
