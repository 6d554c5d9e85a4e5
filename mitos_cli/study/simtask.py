"""One task of a study through the simulator: (world, planner, operators, run, seed) -> result.

This is the only module of the study that knows the simulator. A worker process keeps the
worlds it has read and the rule bases it has compiled (per operator choice) in small caches, so
a chunk of tasks pays for parsing and compiling once.
"""

from __future__ import annotations

import functools
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
    from ..model import Setting

    return LoadedRuleBase(_rulebase(path), behavior,
                          tuple(Setting(k, v) for k, v in overrides))


def check_choice(choice: Choice, rulebase: str | None, behavior: str | None) -> None:
    """Raise the user's error now (bad rule base, operator, behavior) rather than in a worker."""
    if choice.planner == "fuzzy":
        loaded_rulebase(rulebase, behavior, choice.overrides())


def make_planner(context: StudyContext, choice: Choice, world):
    """The planner of ``choice`` for ``world``."""
    raise NotImplementedError("waiting for the simulator's Planner protocol")


def run_task(context: StudyContext, task: Task) -> dict:
    """Simulate one task; return the fields of :data:`RESULT_FIELDS`."""
    raise NotImplementedError("waiting for the simulator's simulate()")
