"""One task of a study through the simulator: (world, planner, operators, run, seed) -> result.

This is the only module of the study that knows the simulator. A worker process keeps the
worlds it has read and the rule bases it has compiled (per operator choice) in small caches, so
a chunk of tasks pays for parsing and compiling once.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

from .spec import Choice, Task
from .store import RESULT_FIELDS


@dataclass(frozen=True)
class StudyContext:
    """What every task of a study shares: the fuzzy planner's rule base and behavior."""

    rulebase: str | None = None
    behavior: str | None = None


@functools.lru_cache(maxsize=32)
def _world(path: str):
    from ..sim.worldfile import load_world

    return load_world(path)


@functools.lru_cache(maxsize=8)
def _rulebase(path: str | None):
    from ..api import read_rulebase

    return read_rulebase(path)


@functools.lru_cache(maxsize=64)
def loaded_rulebase(path: str | None, behavior: str | None, overrides: tuple):
    """The rule base compiled with the choice's operators (``overrides``: (key, value) pairs)."""
    from ..api import LoadedRuleBase
    from ..lang.model import Setting

    return LoadedRuleBase(_rulebase(path), behavior,
                          tuple(Setting(k, v) for k, v in overrides))


def check_choice(choice: Choice, context: StudyContext, world_path: str) -> None:
    """Raise the user's error now (bad rule base, operator, behavior) rather than in a worker."""
    _planner(context, choice, world_path)


@functools.lru_cache(maxsize=32)
def _scene(path: str):
    """Walls and routes of a world, shared by its randomised runs (``None``: each run
    prepares its own, where a draw moves what the robots are given; :func:`shared_scene`)."""
    from ..sim.loop import shared_scene

    return shared_scene(_world(path), True)


@functools.lru_cache(maxsize=64)
def _planner(context: StudyContext, choice: Choice, path: str):
    from ..sim.planner import make_planner

    world = _world(path)
    if choice.planner != "fuzzy":
        return make_planner(choice.planner, world)
    behavior = context.behavior or world.behavior
    return make_planner("fuzzy", world,
                        loaded_rulebase(context.rulebase, behavior, choice.overrides()), behavior)


def run_task(context: StudyContext, task: Task) -> dict:
    """Simulate one task (the world randomised from the task's seed); return the fields of
    :data:`RESULT_FIELDS`."""
    from ..sim.loop import simulate

    world = _world(task.world)
    result = simulate(world, _planner(context, task.choice, task.world), task.seed,
                      randomise=True, scene=_scene(task.world))
    return _fields(result)


def run_tasks(context: StudyContext, tasks: Sequence[Task]) -> Iterator[tuple[Task, dict]]:
    """Simulate ``tasks``, those of each world and choice stepped together
    (:class:`~mitos_cli.sim.lockstep.Lockstep`: each run's bits are those :func:`run_task`
    gives it alone), giving each task and its fields as its run ends."""
    from ..sim.lockstep import Lockstep

    groups: dict[tuple[str, Choice], list[Task]] = {}
    for task in tasks:
        groups.setdefault((task.world, task.choice), []).append(task)
    for (path, choice), group in groups.items():
        runs = Lockstep(_world(path), _planner(context, choice, path),
                        [task.seed for task in group], randomise=True, scene=_scene(path))
        for j, result in runs.finished():
            yield group[j], _fields(result)


def _fields(result) -> dict:
    return {"outcome": result.outcome, **{f: result.metrics[f] for f in RESULT_FIELDS[1:]}}


@dataclass(frozen=True)
class Simulator:
    """The simulator as a study's task function (picklable): one task alone, or a chunk of
    tasks in lockstep (:attr:`each`, which the executors use where a task function has it)."""

    context: StudyContext

    def __call__(self, task: Task) -> dict:
        return run_task(self.context, task)

    def each(self, tasks: Sequence[Task]) -> Iterator[tuple[Task, dict]]:
        return run_tasks(self.context, tasks)
