"""Runs in lockstep: independent runs of one world stepped together, tick by tick.

Each tick the robots of every run still going are sensed in one pass (:func:`.rows.sense`:
beams, noise from each robot's own stream, clearance), the marks they see through cleared
from their maps in one pass (:func:`.knowledge.clear_all`), the cells their echoes came from
found in one pass (:func:`.knowledge.beyond_cells`), their maps marked from them in one pass
(:func:`.knowledge.mark_all`), what they see that their maps do not show cut into objects and
tested against the beams they kept in one pass (:func:`.movers.sightings`) and their tracks
followed in one pass (:func:`.movers.follow_all`), the cells near them on their maps found in
one pass (:func:`.knowledge.near_all`), their readings looked up where their routes were
planned in one pass (:func:`.knowledge.accounted_all`), their pursuit points found in one
pass (:func:`.perception.pursuit_points`) and their rule inputs perceived in one pass
(:func:`.perception.perceive_all`) and checked (contact, arrival) in one pass; the robots
due a replanning check are found in one pass (:func:`.knowledge.checks_due`) and only their
routes planned again, robot by robot, with the code of a run alone
(:meth:`~mitos_cli.sim.loop.Simulation.replanned`). Then the fuzzy planner's rule network is
evaluated once for the active robots of every run (one engine batch: the engine gives each
row the bits it gives alone), the brake of every robot of every run checks its command in
one pass (:meth:`.safety.Fleet.guard`: the first sweeps measured together, most commands
decided with arrays), every run's tick is recorded and judged in one pass, and the robots of
every run move in one batch of kinematics (elementwise per robot). The bookkeeping done once
for all runs is :class:`~mitos_cli.sim.loop.Batch`'s; each run's arrays are views of the
batch's. Runs that end drop out. Every batched stage is elementwise per robot or an exact
minimum, so each run's ticks, trajectory and summary are bit for bit those of the same run
alone, whatever the batch (``tests/test_sim_lockstep.py``,
``tests/test_sim_same_bits.py``)."""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import overload

import numpy as np

from ..errors import InputError
from ..numbers import whole_number
from . import knowledge, movers, perception, rows
from .loop import Batch, Scene, SimResult, Simulation, check_seed, check_world, row_spans, shared_scene
from .planner import FuzzyPlanner, Planner
from .world import World

#: The row of each input in a tick's block of inputs (:data:`.perception.INPUTS` order).
_ROW = {key: j for j, key in enumerate(perception.INPUTS)}

#: Runs stepped together by default: enough to make the batched calls worth their set-up,
#: few enough that the runs' recorded ticks stay small. A tick's NumPy calls cost much the
#: same for 64 robots as for 128: 256 randomised slalom runs took 0.91x the CPU a robot-tick
#: in batches of 128 that they took in batches of 64 (mean of 7 rounds alternated, 152.6
#: against 168.1 us; batches of 256, 2 rounds: 147.0 and 154.1 against 138.5 and 160.9).
BATCH = 128

#: What the runs of one batch may keep of their maps together (bytes), and what a robot
#: keeps a cell of the map it plans on (its copy of the cells and what its route searches
#: worked out on them: 10.4 bytes, measured on a 4,000 x 4,000 map; 21 before the field and
#: the steps were kept as squares). A batch of 64 runs there took 20 GB; the packaged
#: worlds' maps (600 x 600 at most) still fill a batch of 128 (271 would fit).
MAP_MEMORY = 1 << 30
CELL_BYTES = 11


@dataclass(frozen=True)
class Clock:
    """Where the runs still going of a lockstep batch are, in simulated seconds (the earliest
    of them): what :meth:`Lockstep.finished` tells a progress bar between the runs' ends."""

    seconds: float


class Lockstep:
    """Runs of ``world`` from ``seeds`` stepped together (``randomise``: each run draws its
    obstacle places and sensor noise from its seed, as ``simulate(..., randomise=True)``)."""

    def __init__(self, world: World, planner: Planner | None = None,
                 seeds: Sequence[int] = (), *, randomise: bool = False,
                 scene: Scene | None = None) -> None:
        check_world(world)              # (a path met "'str' object has no attribute ...")
        seeds = seed_list(seeds)
        if planner is None:
            planner = FuzzyPlanner(None, world.behavior)
        self.planner = planner
        if scene is None and seeds:      # the runs' map and routes, prepared once if they can
            scene = shared_scene(world, randomise)
        self.runs = [Simulation(world, planner, seed, randomise=randomise, scene=scene)
                     for seed in seeds]
        self._batch: Batch | None = None         # the runs last stepped together

    def __getstate__(self) -> dict:
        """A copy (``copy.deepcopy``, pickle) without its batch: the runs' copies hold arrays
        of their own where the batch's runs hold views of its arrays, so the copy makes a
        batch of them afresh."""
        return {**self.__dict__, "_batch": None}

    def __repr__(self) -> str:
        from ..words import plural

        if not self.runs:
            return "<Lockstep of 0 runs>"
        first = self.runs[0]
        name = getattr(self.planner, "name", type(self.planner).__name__)
        going = sum(not run.done for run in self.runs)
        return (f"<Lockstep of {plural(len(self.runs), 'run')} of {first.world.name!r}, {name}: "
                f"{going} driving, {len(self.runs) - going} ended>")

    @property
    def done(self) -> bool:
        return all(run.done for run in self.runs)

    def step(self) -> None:
        """One tick of every run still going: observed, checked, recorded and moved as one
        :class:`Batch` when they are at the same tick and none was observed from outside;
        else each observed, guarded and moved as alone (the rule network still for all at
        once)."""
        live = [run for run in self.runs if not run.done]
        if not live:
            return
        if len(live) > 1 and _in_step(live) and not any(run.observed for run in live):
            batch = self._batch_of(live)
            _observe_together(batch)
            batch.commanded(self._commands(live, batch.block, batch.active))
            batch.guard()
            moving = batch.verdict()
            if moving is batch.runs:        # every run drives on: the batch moves them all,
                batch.move()                # a tick on from the tick it just recorded
                return
        else:
            seen = [run.observe() for run in live]
            commands = self._commands(live, np.concatenate([s.block for s in seen], axis=1),
                                      np.concatenate([run.active for run in live]))
            ticks = [run.commanded(None if commands is None else commands[a:b])
                     for run, (a, b) in zip(live, row_spans(live))]
            _guard_together(live, ticks)
            moving = [run for run, s in zip(live, ticks) if run.verdict(s)[1]]
        if len(moving) > 1 and _in_step(moving):
            self._batch_of(moving).move()
        else:
            for run in moving:
                run.act(run.decided)
                run.moved()

    def _batch_of(self, runs: list[Simulation]) -> Batch:
        """The :class:`Batch` of ``runs``: the last one while it serves them."""
        kept = self._batch
        if kept is None or not kept.serves(runs):
            kept = self._batch = Batch(runs)
        return kept

    def results(self) -> list[SimResult]:
        """Step until every run has ended; each run's :class:`SimResult`, in seed order."""
        while not self.done:
            self.step()
        return [run.result() for run in self.runs]

    @overload
    def finished(self, every: None = None) -> Iterator[tuple[int, SimResult]]: ...
    @overload
    def finished(self, every: float) -> Iterator[tuple[int, SimResult] | Clock]: ...

    def finished(self, every: float | None = None) -> Iterator[tuple[int, SimResult] | Clock]:
        """Step until every run has ended, giving each run's place among the seeds and its
        :class:`SimResult` the tick it ends (a progress bar moves, a study writes it down).
        With ``every`` (simulated seconds), also a :class:`Clock` each time the runs still
        going pass a multiple of it: runs in lockstep end together, late in their batch, and a
        bar that counts only ends stood still till then."""
        given = [False] * len(self.runs)
        due = every
        while True:
            for i, run in enumerate(self.runs):
                if run.done and not given[i]:
                    given[i] = True
                    yield i, run.result()
            if all(given):
                return
            self.step()
            if every is not None and due is not None:
                now = min((run.time for run in self.runs if not run.done), default=None)
                if now is not None and now >= due:
                    yield Clock(now)
                    due = (now // every + 1) * every

    def _commands(self, live: list[Simulation], blocks: np.ndarray,
                  active: np.ndarray) -> np.ndarray | None:
        """The commands ``[robots, 2]`` of the robots of all ``live`` runs, from one
        evaluation of the rule network for the active ones (``blocks [inputs, robots]``:
        their inputs; ``None``: each run plans itself, as planners other than the fuzzy one
        do, whose rows need not be independent of the batch)."""
        planner = self.planner
        if not isinstance(planner, FuzzyPlanner):
            return None
        compiled = planner.compiled
        X = np.empty((np.count_nonzero(active), len(compiled.inputs)))
        if len(X) == 0:
            return None
        for j, key in enumerate(compiled.inputs):
            X[:, j] = blocks[_ROW[key], active]
        from ..engine.evaluation import evaluate

        out = evaluate(compiled, X, detail=False).outputs
        commands = np.zeros((len(active), 2))
        for j, key in enumerate(("steering", "speed")):
            commands[active, j] = out[:, compiled.outputs.index(key)]
        return commands


def _in_step(runs: list[Simulation]) -> bool:
    """Whether ``runs`` are at the same tick (a user may step one of them alone)."""
    return len({run.ticks for run in runs}) == 1


def _observe_together(batch: Batch) -> None:
    """:meth:`Simulation.observe` of every run of ``batch``: their robots' beams and
    clearance sensed in one :func:`.rows.sense`, their maps cleared in one
    :func:`.knowledge.clear_all` and marked in one :func:`.knowledge.mark_all`, what they
    see seen in one :func:`.movers.sightings`, what their maps hold near them found in one
    :func:`.knowledge.near_all` and their readings looked up in one
    :func:`.knowledge.accounted_all`, the robots due a replanning check found in one
    :meth:`.Batch.aims`, their pursuit points found in one
    :func:`.perception.pursuit_points`, their inputs perceived in one
    :func:`.perception.perceive_all` (each row the bits of its robot alone) and checked in
    one :meth:`.Batch.conclude`; what else each robot's map and route need, run by run."""
    fresh, maps = batch.runs, batch.maps
    world = fresh[0].world
    got = rows.sense(batch.sense_rows(), fresh[0].angles, world.sensors.range, batch.stacked)
    sensed = batch.sensed(got)
    knowledge.clear_all(maps, batch.at, got.dirs, got.ranges, world.sensors.range)
    beyond = knowledge.beyond_cells(maps, batch.at, got.dirs, got.ranges)
    learned = None                # (whether each row's map was marked)
    if beyond is not None:        # (marked and looked up here: no run asks for its own)
        learned = knowledge.mark_all(maps, beyond, batch.seeing())
    frames = perception.frames(*batch.framing())
    if learned is None:
        for run, s, seen in zip(fresh, sensed, _sightings_together(fresh, sensed)):
            run.tracked(s, seen)
    else:
        batch.tracked(_watched_together(batch, learned))
    near = knowledge.near_all(maps, batch.at, batch.reaches, world.replan != "clearance")
    aims = batch.aims(frames, near)
    padded = perception.padded_cells(aims) if len(aims) > 1 else None   # (for both)
    targets = perception.pursuit_points(aims, fresh[0].settings, padded=padded)[1]
    gaps = perception.route_gaps(aims, padded=padded)
    # (after the aims: a route planned again is planned round the cells marked by then)
    if world.replan == "clearance" and beyond is not None:
        accounted = knowledge.accounted_all(maps, beyond, kept=batch.dilations)
    else:
        accounted = np.concatenate([run.accounted(s) for run, s in zip(fresh, sensed)])
    sights = batch.aimed(aims, targets, gaps, accounted)
    batch.conclude(perception.perceive_all(sights, world.sensors.range, fresh[0].settings),
                   targets)


def _watched_together(batch: Batch, learned: list[bool]) -> list[movers.Seen]:
    """What the robots of every run of ``batch`` that follow something see
    (:meth:`.Batch.watching`: their maps marked, ``learned`` whether each row's was), seen in one
    :func:`.movers.sightings`, in row order."""
    spaces, rows, *looks = batch.watching(learned)
    return movers.sightings(spaces, batch.ticks[0].t, *looks) if len(rows) else []


def _sightings_together(runs: list[Simulation], sensed: list) -> list[list[movers.Seen]]:
    """What each run is :meth:`~.loop.Simulation.watching` (its maps marked run by run),
    seen in one :func:`.movers.sightings` for the robots of all runs (they tick together:
    one time)."""
    watched = [run.watching(s) for run, s in zip(runs, sensed)]
    looking = [w for w in watched if w[0]]                  # runs whose robots follow something
    got = movers.sightings([sp for w in looking for sp in w[0]], sensed[0].t,
                           *(np.concatenate([w[j] for w in looking]) for j in (1, 2, 3, 4))
                           ) if looking else []
    ends = [0, *itertools.accumulate(len(w[0]) for w in watched)]
    return [got[a:b] for a, b in zip(ends[:-1], ends[1:])]


def _guard_together(runs: list[Simulation], ticks: list) -> None:
    """Every run's guard on its tick's commands, run by run: runs not at one tick, or one of
    them observed from outside (a user stepping a run alone), are not a :class:`Batch`."""
    for run, s in zip(runs, ticks):
        run._guard(s)


def batch_for(world: World, most: int = BATCH) -> int:
    """How many runs of ``world`` one lockstep batch steps: ``most``, fewer where their
    robots' maps would take more than :data:`MAP_MEMORY` together (at least one)."""
    return max(1, min(most, MAP_MEMORY // max(1, map_bytes(world))))


def map_bytes(world: World) -> int:
    """About what the maps of one run of ``world`` take: each robot's copy of the map it
    plans on and what its route searches work out on it (:data:`CELL_BYTES` a cell)."""
    return _plan_cells(world) * CELL_BYTES * len(world.agents)


def _plan_cells(world: World) -> int:
    """About how many cells the map a robot plans on holds: the grid it is given or the
    world's, else the corridors' bounds rasterised (:data:`.knowledge.RASTER`)."""
    grid = world.given if world.given is not None else world.grid
    if grid is not None:
        return int(grid.occupied.size)
    points = np.array([p for c in world.corridors for p in c.points]).reshape(-1, 2)
    if not len(points):
        return 0
    pad = max(c.width for c in world.corridors) + 2 * knowledge.RASTER
    span = points.max(axis=0) - points.min(axis=0) + pad
    return int(np.prod(np.ceil(span / knowledge.RASTER)))


@overload
def finished(world: World, planner: Planner | None, seeds: Sequence[int], *,
             randomise: bool = ..., scene: Scene | None = ..., batch: int | None = ...,
             every: None = None) -> Iterator[tuple[int, SimResult]]: ...
@overload
def finished(world: World, planner: Planner | None, seeds: Sequence[int], *,
             randomise: bool = ..., scene: Scene | None = ..., batch: int | None = ...,
             every: float) -> Iterator[tuple[int, SimResult] | Clock]: ...


def finished(world: World, planner: Planner | None, seeds: Sequence[int], *,
             randomise: bool = False, scene: Scene | None = None, batch: int | None = None,
             every: float | None = None) -> Iterator[tuple[int, SimResult] | Clock]:
    """The runs of ``world`` from ``seeds``, ``batch`` at a time in lockstep (default:
    :func:`batch_for`), each run's place among the seeds and its result as it ends; with
    ``every``, also each batch's :class:`Clock` (:meth:`Lockstep.finished`)."""
    check_world(world)
    seeds = seed_list(seeds)
    if batch is not None and ((b := whole_number(batch)) is None or b < 1):
        raise InputError(f"batch is a whole number of runs, 1 or more, not `{batch!r:.40}`",
                         hint="leave it out: batch_for(world) sizes it")
    size = max(1, batch_for(world) if batch is None else batch)
    for i in range(0, len(seeds), size):
        for item in Lockstep(world, planner, seeds[i:i + size], randomise=randomise,
                             scene=scene).finished(every):
            yield item if isinstance(item, Clock) else (i + item[0], item[1])


def seed_list(seeds: object) -> list[int]:
    """``seeds`` as a list of seeds (each checked as :func:`.loop.check_seed` checks one),
    else an :class:`InputError`: one seed not in a list met "object of type 'int' has no
    len()"."""
    if isinstance(seeds, (str, bytes)) or not hasattr(seeds, "__iter__"):
        raise InputError(f"seeds is a list of seeds, not {type(seeds).__name__} "
                         f"`{seeds!r:.40}`", hint="seeds=[1], or seeds=range(64)")
    return [check_seed(seed) for seed in seeds]


def run_lockstep(world: World, planner: Planner | None, seeds: Sequence[int], *,
                 randomise: bool = False, scene: Scene | None = None,
                 batch: int | None = None) -> list[SimResult]:
    """The runs of ``world`` from ``seeds``, ``batch`` at a time in lockstep (default:
    :func:`batch_for`): the same results, bit for bit, as ``[simulate(world, planner, s,
    randomise=randomise, scene=scene) for s in seeds]``."""
    seeds = seed_list(seeds)
    out: list[SimResult | None] = [None] * len(seeds)
    for i, res in finished(world, planner, seeds, randomise=randomise, scene=scene,
                           batch=batch):
        out[i] = res
    return [res for res in out if res is not None]
