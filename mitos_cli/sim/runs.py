"""Many runs: randomised repetitions of worlds on a process pool, and their statistics.

Run ``j`` of a world uses seed ``seed + j`` and draws its obstacle places and sensor noise from
the world's ``randomise`` ranges, so any run can be replayed alone (``mitos simulate WORLD
--seed S+j --randomise``). Each run is a pure function of (world, planner, seed): the results do
not depend on the number of workers or on which worker ran what.
"""

from __future__ import annotations

import os
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from .. import machine
from ..errors import InputError, MitosError, unknown
from ..numbers import whole_number
from ..words import plural
from .lockstep import Clock, batch_for, finished, map_bytes
from .loop import OUTCOMES, ROBOT_OUTCOMES, check_seed, shared_scene
from .world import World

if TYPE_CHECKING:
    from multiprocessing.pool import AsyncResult
    from multiprocessing.process import BaseProcess
    from multiprocessing.queues import Queue

    from .loop import SimResult
    from .planner import Planner

#: each run's figures whose mean and std ``--runs`` reports (``replans`` and ``backouts``
#: are counts: routes planned again, and times a robot backed out)
METRICS = ("time_s", "path_length_in", "min_clearance_in", "mean_speed_in_s",
           "steering_total_variation_deg", "replans", "backouts")


#: Simulated seconds between the clocks a chunk of runs sends while none of them ends.
CLOCK_EVERY = 1.0

Part = tuple[int, int, dict] | tuple[int, Clock]


def _chunk_runs(task: tuple) -> Iterator[Part]:
    """One chunk's runs of a world, stepped in lockstep (:mod:`.lockstep`: each run's bits
    are those it has alone): ``(chunk, place in the chunk, summary)`` as each run ends, and
    ``(chunk, Clock)`` every :data:`CLOCK_EVERY` simulated seconds between."""
    index, world, planner, seeds, randomise, measure, scene = task
    scene = scene if scene is not None else shared_scene(world, randomise)
    for item in finished(world, planner, seeds, randomise=randomise, scene=scene,
                         every=CLOCK_EVERY):
        if isinstance(item, Clock):
            yield index, item
        else:
            j, res = item
            yield index, j, {**res.summary(), **(measure(res) if measure is not None else {})}


def ignore_interrupts() -> None:
    """A pool worker's initializer: Ctrl-C reaches the whole process group, and only the
    parent should answer it (the workers are terminated; no ``Process ForkPoolWorker-1:``).
    A SIGTERM or a SIGHUP ends the worker as the signal does, whatever the parent answers
    it with (``mitos compare`` and ``simulate`` stop as on Ctrl-C: a worker forked with that
    handler raised where ``Pool.terminate`` ends it, and a closed terminal's SIGHUP reaches
    the whole process group; ignored, as ``nohup`` does, it stays so). ``Pool.terminate``
    ends its workers with a SIGTERM: it is never ignored."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    hangup = getattr(signal, "SIGHUP", None)         # (not on Windows)
    if hangup is not None and signal.getsignal(hangup) is not signal.SIG_IGN:
        signal.signal(hangup, signal.SIG_DFL)


def end_with_parent() -> None:
    """A pool worker's initializer: end at once when the process that started the pool is
    gone. Nothing terminates the pool of a process killed (``kill -9``, the out-of-memory
    killer): its workers ran their chunks to the end, seconds, printing the tracebacks of
    the pipes they found broken, and held what they had inherited, the lock of a study's
    directory among them (a `--resume` at once was refused: "in use by another study").

    A thread waits on the parent's sentinel (a pipe that the parent's end closes) and ends
    the process: within milliseconds of the parent. Not Linux's ``PR_SET_PDEATHSIG``: it
    fires when the *thread* that forked the worker ends, and the pool forks the workers that
    replace lost ones from its own handler thread, which ends at ``terminate()``; a worker so
    killed while it held the pool's task-queue lock hung ``terminate()`` for ever (a CI run,
    ``test_a_streaming_pool_gives_every_part_as_made_and_raises_a_worker_s_error``).
    """
    import multiprocessing
    import threading

    parent = multiprocessing.parent_process()
    if parent is None:                  # (not a worker of multiprocessing's)
        return
    if not parent.is_alive():           # gone before the thread could wait
        os._exit(1)
    threading.Thread(target=_end_when_gone, args=(parent,), name="mitos-parent-watch",
                     daemon=True).start()


def _end_when_gone(parent: BaseProcess) -> None:
    parent.join()                       # (returns when the parent's end of the pipe closes)
    os._exit(1)


def trail(res: SimResult) -> dict:
    """A ``measure`` for :func:`run_many` (``--runs N --plot``): where each robot drove (its
    ``[x, y]`` while driving and where it stopped: the colliding or arriving tick), each robot's
    outcome, and where the obstacles started in this run, under the key ``trail`` (not part of
    the JSON)."""
    active = cast("np.ndarray", res.active)     # (Optional on SimResult; simulate records it)
    drove = active.copy()
    drove[1:] |= active[:-1]                    # the tick it arrived at (no longer active)
    paths = [res.pose[drove[:, i], i, :2].tolist() for i in range(len(res.robot_outcomes))]
    return {"trail": {"paths": paths, "robot_outcomes": list(res.robot_outcomes),
                      "t_end": float(res.t[-1]) if len(res.t) else 0.0,
                      "obstacles": res.obstacles[0].tolist() if len(res.obstacles) else []}}


@dataclass(frozen=True)
class WorldRuns:
    """One world's runs (or, from :attr:`robots`, one robot's: ``world`` is then its name)."""

    world: str
    summaries: tuple[dict, ...]
    outcomes: tuple[str, ...] = OUTCOMES       # whose rates figures() gives (a robot: + stopped)

    def __repr__(self) -> str:      # the generated one printed every run's summary
        n = len(self.summaries)
        rates = ", ".join(f"{o} {self.count(o) / n:.0%}" for o in self.outcomes) if n else ""
        return f"<WorldRuns {self.world!r}: {plural(n, 'run')}{': ' + rates if rates else ''}>"

    def count(self, outcome: str) -> int:
        """Runs that ended in ``outcome``; a name not among :attr:`outcomes` is an
        :class:`InputError` with a "did you mean" (``rate("sucess")`` was a silent 0.0)."""
        if not isinstance(outcome, str) or outcome not in self.outcomes:
            raise unknown("outcome", f"{outcome!s:.40}", self.outcomes, cls=InputError)
        return sum(s["outcome"] == outcome for s in self.summaries)

    def rate(self, outcome: str) -> float:
        """The share of the runs that ended in ``outcome``; of no runs there is none, an
        :class:`InputError` (it was a ``ZeroDivisionError``)."""
        n = self.count(outcome)
        self._some(f"rate of `{outcome}`")
        return n / len(self.summaries)

    def _some(self, what: str) -> None:
        if not self.summaries:
            raise InputError(f"{self.world!r} holds no runs: its {what} is undefined")

    def stat(self, key: str) -> tuple[float, float | None]:
        """The mean and sample standard deviation of figure ``key`` over the runs (``None``
        for one run, whose sample standard deviation is undefined: it was 0.0, which reads as
        runs that agree, as :meth:`figures` and ``--json`` say it); a name that is no figure
        of theirs is an :class:`InputError` with a "did you mean" (it was a ``KeyError``)."""
        figures = ([k for k, v in self.summaries[0].items()
                    if isinstance(v, (int, float, np.number)) and not isinstance(v, bool)]
                   if self.summaries else list(METRICS))
        if not isinstance(key, str) or key not in figures:
            raise unknown("figure", f"{key!s:.40}", figures, cls=InputError)
        self._some(f"mean `{key}`")
        x = np.array([s[key] for s in self.summaries], dtype=float)
        return float(x.mean()), float(x.std(ddof=1)) if len(x) > 1 else None

    @property
    def robots(self) -> tuple[WorldRuns, ...]:
        """Each robot's runs (its outcome and figures per run) in a world of several robots;
        ``()`` for one robot, whose runs are the world's."""
        if not self.summaries or "robots" not in self.summaries[0]:
            return ()
        names = [r["name"] for r in self.summaries[0]["robots"]]
        return tuple(WorldRuns(name, tuple(s["robots"][i] for s in self.summaries),
                               ROBOT_OUTCOMES) for i, name in enumerate(names))

    def figures(self) -> dict:
        """Each outcome's rate and each metric's mean and std over the runs (the std of one
        run is undefined: ``None``, null in JSON, as `compare --json` says it); of no runs,
        an :class:`InputError`."""
        row: dict[str, float | dict[str, float | None]] = {f"{o}_rate": self.rate(o)
                                                                for o in self.outcomes}
        for key in METRICS:
            mean, std = self.stat(key)
            row[key] = {"mean": mean, "std": std}
        return row


@dataclass(frozen=True)
class Runs:
    worlds: tuple[WorldRuns, ...]

    def __repr__(self) -> str:      # the generated one printed every run's summary
        shown = ", ".join(f"{w.world!r} x {len(w.summaries)}" for w in self.worlds[:6])
        more = f", ... ({len(self.worlds) - 6} more)" if len(self.worlds) > 6 else ""
        return f"<Runs of {plural(len(self.worlds), 'world')}: {shown}{more}>"

    def to_json(self) -> list[dict]:
        out = []
        for w in self.worlds:
            row = {"world": w.world, "runs": len(w.summaries), **w.figures()}
            if w.robots:
                row["robots"] = [{"name": r.world, **r.figures()} for r in w.robots]
            row["runs_detail"] = list(w.summaries)
            out.append(row)
        return out


#: What a worker process of ``simulate --runs`` holds besides its batch's maps (measured,
#: ``/usr/bin/time``'s peak: one run in a process 60 MB; a batch of 128 ``slalom`` runs 294 MB,
#: of which 28 MB maps, so about 1.6 MB of records a run; ``office``'s 701 MB, 483 MB maps).
WORKER_BYTES = 64 << 20
RUN_BYTES = 2 << 20


def default_workers(worlds: Sequence[World] = ()) -> int:
    """``-j``'s default: the CPUs this process may run on, fewer where the memory available
    would not hold that many workers, each with a lockstep batch of the largest of
    ``worlds`` (its maps, :func:`.lockstep.batch_for`, and its runs' records)."""
    cpus = machine.allowed_cpus()
    free = machine.available_memory()
    if free is None:
        return cpus
    batches = [batch_for(w) for w in worlds]
    per_worker = WORKER_BYTES + max((b * (map_bytes(w) + RUN_BYTES)
                                     for w, b in zip(worlds, batches)), default=RUN_BYTES)
    return max(1, min(cpus, free // per_worker))


class RunsInterrupted(KeyboardInterrupt):
    """Ctrl-C during :func:`run_many`: ``runs`` holds the runs that had finished (each world's
    in seed order; a world with none is left out), ``total`` how many were asked for, and
    ``interrupt`` the KeyboardInterrupt that stopped them (a caller's own kind, such as the
    command line's for a SIGTERM, whose exit code differs from Ctrl-C's)."""

    def __init__(self, runs: Runs, total: int,
                 interrupt: KeyboardInterrupt | None = None) -> None:
        super().__init__()
        self.runs, self.total = runs, total
        self.interrupt = interrupt if interrupt is not None else KeyboardInterrupt()

    @property
    def finished(self) -> int:
        return sum(len(w.summaries) for w in self.runs.worlds)


def run_many(worlds: list[World], runs: int = 0, seed: int | None = None, planner: Planner | None = None,
             workers: int | None = None, measure: Callable[[SimResult], dict] | None = None,
             on_progress: Callable[[int, int], None] | None = None,
             on_clock: Callable[[float], None] | None = None) -> Runs:
    """Run each world once (``runs=0``: its own seed, as written) or ``runs`` randomised times
    (seeds ``seed + j``, default base: the world's seed), on ``workers`` processes.
    ``measure(result) -> dict`` (a picklable function), when given, adds figures of its own to
    each run's summary in the worker (a benchmark's scores from the ticks).
    ``on_progress(done, total)`` is called as runs finish (a progress bar), and
    ``on_clock(seconds)`` between, with the simulated time the earliest batch going has
    reached (runs in lockstep end together, late in their batch). Ctrl-C terminates
    the workers and raises :class:`RunsInterrupted` with the runs that had finished."""
    worlds = _check_worlds(worlds)
    runs = whole("runs", runs, 0)
    if seed is not None:
        seed = check_seed(seed)
    if planner is None:
        from .planner import FuzzyPlanner

        planner = FuzzyPlanner(None, worlds[0].behavior if worlds else "drive")
    workers = default_workers(worlds) if workers is None else whole("workers", workers, 1)
    tasks = []
    for place, w in enumerate(worlds):
        base = w.seed if seed is None else seed
        seeds = [base] if runs <= 0 else [base + j for j in range(runs)]
        # each worker's share in lockstep batches of up to 128 runs, fewer on a large map
        # (batch_for; a batch of 5 runs costs about twice what a batch of 40 does a
        # robot-tick); a world cut into several chunks has its map and routes prepared once,
        # here, and sent along (a grid map's route search costs about as much as a run),
        # unless its draws move what the robots are given (shared_scene)
        size = even_chunks(len(seeds), workers, batch_for(w))
        scene = shared_scene(w, runs > 0) if len(seeds) > size else None
        for i in range(0, len(seeds), size):
            tasks.append((place, tuple(seeds[i:i + size]), scene))
    jobs = [(k, worlds[place], planner, chunk, runs > 0, measure, scene)
            for k, (place, chunk, scene) in enumerate(tasks)]
    total = sum(len(chunk) for _, chunk, _ in tasks)
    results: list[list[dict | None]] = [[None] * len(chunk) for _, chunk, _ in tasks]
    done = 0
    if on_progress is not None:     # the total from the start: runs in lockstep end together,
        on_progress(0, total)       # late in their batch, and the bar read "0/?" till then
    try:
        clocks: dict[int, float] = {}          # each chunk going: where its batch is
        for part in _execute(jobs, workers):
            if len(part) == 2:                  # (chunk, Clock)
                clocks[part[0]] = part[1].seconds
                if on_clock is not None:
                    on_clock(min(clocks.values()))
                continue
            k, j, summary = part
            results[k][j] = summary
            done += 1
            if all(r is not None for r in results[k]):
                clocks.pop(k, None)
            if on_progress is not None:
                on_progress(done, total)
    except KeyboardInterrupt as stop:
        raise RunsInterrupted(_group(worlds, tasks, results), total, stop) from None
    return _group(worlds, tasks, results)


def _check_worlds(worlds: object) -> list[World]:
    """``worlds`` as a list of loaded worlds, else an :class:`InputError` saying what is
    taken (one World, or a path, failed deep inside with a bare TypeError or AttributeError)."""
    if isinstance(worlds, World):
        raise InputError("run_many takes a list of worlds, not one World",
                         hint="run_many([world], ...)")
    if isinstance(worlds, (str, os.PathLike)):
        raise InputError(f"run_many takes a list of loaded worlds, not the path `{worlds}`",
                         hint=f"run_many([load_world({str(worlds)!r})], ...)")
    try:
        out = list(worlds)  # type: ignore[call-overload]  # anything iterable is tried
    except TypeError:
        out = [worlds]
    for w in out:
        if not isinstance(w, World):
            hint = (f"load_world({str(w)!r}) reads it" if isinstance(w, (str, os.PathLike))
                    else "load_world('worlds/corridor.yaml') reads a world file")
            raise InputError(f"run_many runs loaded worlds, not {type(w).__name__} "
                             f"`{w!r:.60}`", hint=hint)
    return out


def whole(what: str, value: object, least: int) -> int:
    """``value`` as an int of at least ``least``, else an :class:`InputError` (``runs=2.5``
    and ``workers=0`` met a TypeError, a ZeroDivisionError inside; ``True`` is not 1)."""
    n = whole_number(value)
    if n is None or n < least:
        raise InputError(f"`{what}` is a whole number, {least} or more, not `{value!r:.40}`")
    return n


def _execute(jobs: list[tuple], workers: int) -> Iterator[Part]:
    """``(chunk, place, summary)`` of each run as it ends, and each chunk's clocks
    (:func:`_chunk_runs`): in this process, or on a pool
    that is terminated at once on Ctrl-C or an error."""
    if workers <= 1 or len(jobs) <= 1:
        for job in jobs:
            yield from _chunk_runs(job)
        return
    yield from pool_streaming(_chunk_runs, jobs, min(workers, len(jobs)))


def even_chunks(n: int, workers: int, most: int) -> int:
    """How many of ``n`` items a chunk takes: at most ``most``, and as many chunks as a
    multiple of ``workers`` so that each worker gets about as much (200 runs on 2 workers in
    batches of at most 64: four chunks of 50, not 64, 64, 64 and 8)."""
    count = -(-n // max(1, most))
    count = -(-count // workers) * workers
    return max(1, -(-n // count))


#: where a pool worker of :func:`pool_streaming` puts what its generators yield
_outbox: Any = None


def _streaming_worker(outbox: Queue) -> None:
    global _outbox
    ignore_interrupts()
    end_with_parent()
    _outbox = outbox


def _stream(fn: Callable[[Any], Iterator[Any]], job: tuple[int, Any]) -> None:
    """Put what ``fn(item)`` yields, each part pickled here (an error raised in this thread
    reaches :func:`pool_streaming`, not the queue's feeder thread), and then an end."""
    import pickle

    k, item = job
    for part in fn(item):
        _outbox.put(("part", k, pickle.dumps(part)))
    _outbox.put(("end", k, None))


class WorkerLost(MitosError):
    """A pool worker ended before the pool did: killed (out of memory, a signal). Said as an
    error, not a traceback; without it the pool would wait for its items for ever."""


def pool_streaming(fn: Callable[[Any], Iterator[Any]], items: list,
                   workers: int) -> Iterator[Any]:
    """What the generator ``fn(item)`` yields, for each item, on a pool of ``workers``
    processes, as each part is made. A worker's error is raised here, and so is
    :class:`WorkerLost` when a worker dies; on Ctrl-C or an error the workers are terminated
    at once, not left to finish, and they end at once when this process is killed
    (:func:`end_with_parent`)."""
    import functools
    import multiprocessing
    import pickle
    import queue

    context = multiprocessing.get_context()
    outbox = context.Queue()
    others = {p.pid for p in multiprocessing.active_children()}
    pool = context.Pool(workers, initializer=_streaming_worker, initargs=(outbox,))
    started = {p.pid for p in multiprocessing.active_children()} - others
    finished = False
    try:
        pending = pool.map_async(functools.partial(_stream, fn), list(enumerate(items)),
                                 chunksize=1)
        ended = 0
        while ended < len(items):
            try:
                what, _, part = outbox.get(timeout=0.1)
            except queue.Empty:
                _check(pending, started)
                continue
            if what == "part":
                yield pickle.loads(part)
            else:
                ended += 1
        pending.get()
        finished = True
    finally:
        if finished:
            pool.close()
        else:
            pool.terminate()
        pool.join()


def _check(pending: AsyncResult, workers: set[int | None]) -> None:
    """Raise a worker's error, or :class:`WorkerLost` when one of the pool's ``workers`` is
    gone (a pool's workers end only when the pool does)."""
    import multiprocessing

    if pending.ready() and not pending.successful():
        pending.get()
    if not workers <= {p.pid for p in multiprocessing.active_children()}:
        raise WorkerLost("a worker process ended with runs unfinished: killed (out of "
                         "memory, or a signal?)",
                         hint="run again with fewer workers (-j), or fewer runs at once")


def _group(worlds: list[World], tasks: list[tuple], results: list[list[dict | None]]) -> Runs:
    """Each world's finished runs in seed order (worlds with none left out when interrupted),
    one row per place in ``worlds``: the same World given twice is two rows of their own
    runs, as two copies of it are (keyed on the object, each row held the runs of both)."""
    grouped: list[list[dict]] = [[] for _ in worlds]
    for (place, _, _), res in zip(tasks, results):
        grouped[place].extend(summary for summary in res if summary is not None)
    return Runs(tuple(WorldRuns(label, tuple(runs))
                      for runs, label in zip(grouped, _labels(worlds)) if runs))


def _labels(worlds: list[World]) -> list[str]:
    """Each world's name, with its file's where two worlds share a name (two copies of one
    world gave two rows nobody could tell apart)."""
    names = Counter(w.name for w in worlds)
    return [w.name if names[w.name] == 1 or not w.path else f"{w.name} ({w.path})"
            for w in worlds]
