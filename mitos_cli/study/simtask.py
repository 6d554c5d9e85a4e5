"""One task of a study through the simulator: (world, planner, operators, run, seed) -> result.

This is the only module of the study that knows the simulator. A worker process keeps the
worlds it has read and the rule bases it has compiled (per operator choice) in small caches, so
a chunk of tasks pays for parsing and compiling once. The caches are keyed on what the files
hold (their digests, as ``study.json`` records them), not on their paths: a file edited between
two studies of one session (a notebook, a Dask cluster) is read again.
"""

from __future__ import annotations

import functools
import hashlib
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import NameError_
from .spec import Choice, Task
from .store import RESULT_FIELDS, StudyError

if TYPE_CHECKING:
    from ..api import LoadedRuleBase
    from ..lang.model import RuleBase
    from ..sim.lockstep import Clock
    from ..sim.loop import Scene, SimResult
    from ..sim.planner import Planner
    from ..sim.world import World

#: the key of the rule base's digest among a study's (the others are its world files)
RULEBASE = "rulebase"


@dataclass(frozen=True)
class StudyContext:
    """What every task of a study shares: the fuzzy planner's rule base and behavior, and
    the digests of its files that ``study.json`` records (``(name, digest)`` pairs; without
    them, each file's digest is taken as it is now)."""

    rulebase: str | None = None
    behavior: str | None = None
    digests: tuple[tuple[str, str], ...] = ()

    def digest(self, name: str) -> str | None:
        """The recorded digest of a world file (or of :data:`RULEBASE`), if any."""
        return dict(self.digests).get(name)


def file_digest(paths: Sequence[Path]) -> str | None:
    """A digest of the files' bytes (16 hex digits); None when one cannot be read (reported
    where the file is read), or is no regular file (a FIFO a world names was waited on)."""
    h = hashlib.sha256()
    try:
        for p in paths:
            if not p.is_file():
                return None
            h.update(p.read_bytes())
    except OSError:
        return None
    return h.hexdigest()[:16]


def world_digest(path: str) -> str | None:
    """A digest of a world file and the map files it reads (:func:`.worldfile.map_files`);
    a world without any has the digest of its own bytes, as before. A packaged world's name
    (``corridor``) is its file's."""
    from ..resources import world_file
    from ..sim.worldfile import map_files

    file = world_file(path)
    return file_digest([file, *map_files(file)])


def rulebase_digest(rb: RuleBase) -> str | None:
    """A digest of the files a rule base was read from: its own and its term sets."""
    if rb.path is None:
        return None
    path = Path(rb.path)
    return file_digest([path] + [path.parent / p for p in rb.termset_paths])


def _world_key(context: StudyContext, path: str) -> str | None:
    return context.digest(path) or world_digest(path)


def _rulebase_key(context: StudyContext) -> str | None:
    if context.digest(RULEBASE) is not None:
        return context.digest(RULEBASE)
    from ..api import read_rulebase

    return rulebase_digest(read_rulebase(context.rulebase))


def _unchanged(what: str, key: str | None, now: str | None) -> None:
    """A file that no longer holds what the study recorded: its runs would be of another
    file than ``study.json`` says (keyed on the path, a later study of the session ran the
    file as it was when first read)."""
    if key is not None and now != key:
        raise StudyError(f"{what} changed while the study ran; its runs so far are of the "
                         f"file as it was", hint="put the file back and resume (--resume), or "
                         "run the study again in another directory (-o)")


@functools.lru_cache(maxsize=32)
def _world(path: str, key: str | None) -> World:
    from ..sim.worldfile import load_world

    world = load_world(path)
    _unchanged(f"the world file `{path}` (or a map it reads)", key, world_digest(path))
    return world


@functools.lru_cache(maxsize=8)
def _rulebase(path: str | None, key: str | None) -> RuleBase:
    from ..api import read_rulebase

    rb = read_rulebase(path)
    _unchanged("the rule base", key, rulebase_digest(rb))
    return rb


@functools.lru_cache(maxsize=64)
def loaded_rulebase(path: str | None, key: str | None, behavior: str | None,
                    overrides: tuple[tuple[str, str], ...]) -> LoadedRuleBase:
    """The rule base compiled with the choice's operators (``overrides``: (key, value) pairs;
    ``key``: the digest of its files)."""
    from ..api import LoadedRuleBase
    from ..lang.model import Setting

    return LoadedRuleBase(_rulebase(path, key), behavior,
                          tuple(Setting(k, v) for k, v in overrides))


def check_choice(choice: Choice, context: StudyContext, world_path: str) -> None:
    """Raise the user's error now (bad rule base, operator, behavior) rather than in a worker."""
    _planner(context, choice, world_path)


@functools.lru_cache(maxsize=32)
def _scene(path: str, key: str | None) -> Scene | None:
    """Walls and routes of a world, shared by its randomised runs (``None``: each run
    prepares its own, where a draw moves what the robots are given; :func:`shared_scene`)."""
    from ..sim.loop import shared_scene

    return shared_scene(_world(path, key), True)


def _planner(context: StudyContext, choice: Choice, path: str) -> Planner:
    rulebase = _rulebase_key(context) if choice.planner == "fuzzy" else None
    return _make_planner(context, choice, path, _world_key(context, path), rulebase)


@functools.lru_cache(maxsize=64)
def _make_planner(context: StudyContext, choice: Choice, path: str, key: str | None,
                  rulebase: str | None) -> Planner:
    from ..sim.planner import make_planner, said_at_world

    world = _world(path, key)
    if choice.planner != "fuzzy":
        return make_planner(choice.planner, world)
    behavior = context.behavior or world.behavior
    try:
        compiled = loaded_rulebase(context.rulebase, rulebase, behavior, choice.overrides())
    except NameError_ as exc:       # the world's `behavior:`, not in the rule base: said there
        if not context.behavior:
            said_at_world(exc, world, context.rulebase is not None)
        raise
    return make_planner("fuzzy", world, compiled, behavior)


def run_task(context: StudyContext, task: Task) -> dict:
    """Simulate one task (the world randomised from the task's seed); return the fields of
    :data:`RESULT_FIELDS`."""
    from ..sim.loop import simulate

    key = _world_key(context, task.world)
    result = simulate(_world(task.world, key), _planner(context, task.choice, task.world),
                      task.seed, randomise=True, scene=_scene(task.world, key))
    return _fields(result)


def run_tasks(context: StudyContext, tasks: Sequence[Task],
              every: float | None = None) -> Iterator[tuple[Task, dict] | Clock]:
    """Simulate ``tasks``, those of each world and choice stepped together
    (:class:`~mitos_cli.sim.lockstep.Lockstep`: each run's bits are those :func:`run_task`
    gives it alone), giving each task and its fields as its run ends; with ``every``, also
    where the runs going are between their ends (:meth:`.Lockstep.finished`)."""
    from ..sim.lockstep import Clock, finished

    groups: dict[tuple[str, Choice], list[Task]] = {}
    for task in tasks:
        groups.setdefault((task.world, task.choice), []).append(task)
    for (path, choice), group in groups.items():
        key = _world_key(context, path)
        runs = finished(_world(path, key), _planner(context, choice, path),
                        [task.seed for task in group], randomise=True, scene=_scene(path, key),
                        every=every)
        for item in runs:
            yield item if isinstance(item, Clock) else (group[item[0]], _fields(item[1]))


def _fields(result: SimResult) -> dict:
    """The run's figures over all robots; with several, each robot's under ``robots``: its
    own outcome and figures as ``mitos simulate`` gives them (:attr:`.SimResult.robot_metrics`;
    its collisions 1 where it collided), without ticks (the run's)."""
    out = {"outcome": result.outcome, **{f: result.metrics[f] for f in RESULT_FIELDS[1:]}}
    if len(result.robot_metrics) > 1:
        out["robots"] = [{"robot": m["name"], "outcome": m["outcome"],
                          "collisions": int(m["outcome"] == "collision"),
                          **{f: m[f] for f in RESULT_FIELDS[2:] if f != "ticks"}}
                         for m in result.robot_metrics]
    return out


@dataclass(frozen=True)
class Simulator:
    """The simulator as a study's task function (picklable): one task alone, or a chunk of
    tasks in lockstep (:attr:`each`, which the executors use where a task function has it)."""

    context: StudyContext

    def __call__(self, task: Task) -> dict:
        return run_task(self.context, task)

    def each(self, tasks: Sequence[Task]) -> Iterator[tuple[Task, dict] | Clock]:
        from ..sim.runs import CLOCK_EVERY

        return run_tasks(self.context, tasks, every=CLOCK_EVERY)

    def robots(self, path: str) -> tuple[str, ...]:
        """The names of the robots of the world ``path`` where it has several (``()``: one),
        whose runs have a row per robot in ``results.csv``."""
        agents = _world(path, _world_key(self.context, path)).agents
        return tuple(a.name for a in agents) if len(agents) > 1 else ()

    def worlds(self, tasks: Sequence[Task]) -> list[World]:
        """The worlds ``tasks`` run, as the workers read them: what a default number of
        workers is counted from (each steps a batch of a world's runs with their maps)."""
        paths = dict.fromkeys(task.world for task in tasks)
        return [_world(path, _world_key(self.context, path)) for path in paths]
