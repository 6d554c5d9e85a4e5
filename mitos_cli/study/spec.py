"""What a study runs: operator choices, tasks, and their seeds.

A study is every combination of worlds x choices x runs. A :class:`Choice` is one planner with
its operators (``fuzzy`` with a T-norm, S-norm and inference method; ``potential_field`` and
``dwa`` have none). A :class:`Task` is one simulation: world, choice, run index and seed.

Seeds: ``SeedSequence(seed).spawn(len(worlds))[w].spawn(runs)[r]`` gives the seed of run ``r``
in world ``w``, whatever the choice. Every choice therefore drives exactly the same randomized
worlds (obstacle placements, sensor noise): the comparison is paired.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, NameError_, unknown
from ..fuzzy import norms
from ..lang.operators import INFERENCES
from ..sim.planner import PLANNERS as _REGISTRY

PLANNERS = tuple(_REGISTRY)      # the simulator's planner registry, in its order

#: the columns that identify a task in ``results.csv``
KEY_FIELDS = ("world", "planner", "and", "or", "inference", "run")


@dataclass(frozen=True, order=True)
class Choice:
    """A planner and, for the fuzzy one, its operator overrides (``""`` = the rule base's)."""

    planner: str
    and_: str = ""
    or_: str = ""
    inference: str = ""

    @property
    def label(self) -> str:
        parts = [f"{k}={v}" for k, v in (("and", self.and_), ("or", self.or_),
                                        ("inference", self.inference)) if v]
        return " ".join([self.planner, *parts])

    def overrides(self) -> tuple[tuple[str, str], ...]:
        """The operator settings to compile the rule base with, as (key, value) pairs."""
        return tuple((k, v) for k, v in (("and", self.and_), ("or", self.or_),
                                          ("inference", self.inference)) if v)


@dataclass(frozen=True)
class Task:
    """One simulation of a study. ``index`` is its place in the study (the serial order)."""

    index: int
    world: str          # the world file as the user gave it
    choice: Choice
    run: int
    seed: int

    @property
    def key(self) -> tuple[str, ...]:
        c = self.choice
        return (self.world, c.planner, c.and_, c.or_, c.inference, str(self.run))


def split_list(text: str | None) -> list[str]:
    """``"min, product,,einstein"`` -> ``["min", "product", "einstein"]`` (order kept, no repeats)."""
    if text is None:
        return []
    out: list[str] = []
    for item in text.split(","):
        item = item.strip()
        if item and item not in out:
            out.append(item)
    return out


def canonical_tnorm(name: str) -> str:
    try:
        return norms.lookup("tnorm", name).name
    except KeyError:
        raise unknown("T-norm", name, norms.names("tnorm")) from None


def canonical_snorm(name: str, tnorm: str) -> str:
    """An S-norm name; ``dual`` is the De Morgan dual of ``tnorm`` (eq. 12)."""
    if name == "dual":
        if not tnorm:
            return ""
        return norms.lookup("tnorm", tnorm).dual
    if name in (norms.UNBOUNDED_SUM.name, *norms.UNBOUNDED_SUM.aliases):
        # a name `or` does not take, as an unknown one (`--or sum`: a usage error, exit 2)
        raise NameError_(f"S-norm `{name}`: the unbounded sum is a Mamdani aggregation only, "
                         f"not an S-norm for `or`", hint="did you mean `bounded_sum` (min(1, "
                                                         "a + b)) or `probabilistic_sum` (a + b "
                                                         "- a b)?")
    try:
        return norms.lookup("snorm", name).name
    except KeyError:
        raise unknown("S-norm", name, [*norms.names("snorm"), "dual"]) from None


def make_choices(planners: Sequence[str], ands: Sequence[str] = (), ors: Sequence[str] = (),
                 inferences: Sequence[str] = ()) -> list[Choice]:
    """Every fuzzy combination of T-norm x S-norm x inference, then the other planners.

    An empty list (the default: ``make_choices(["fuzzy"], ands=["min", "product"])``) keeps
    the rule base's setting. ``--or dual`` pairs each T-norm with its
    De Morgan dual instead of crossing them.
    """
    planners, ands = _names("planners", planners), _names("T-norms", ands)
    ors, inferences = _names("S-norms", ors), _names("inference methods", inferences)
    for p in planners:
        if p not in PLANNERS:
            raise unknown("planner", p, PLANNERS)
    for i in inferences:
        if i not in INFERENCES:
            raise unknown("inference method", i, INFERENCES)
    ands = [canonical_tnorm(a) for a in ands] or [""]
    inferences = inferences or [""]
    choices: list[Choice] = []
    for planner in planners:
        if planner != "fuzzy":
            choices.append(Choice(planner))
            continue
        for a, o, i in itertools.product(ands, ors or [""], inferences):
            c = Choice("fuzzy", a, canonical_snorm(o, a) if o else "", i)
            if c not in choices:
                choices.append(c)
    return choices


def _names(what: str, names: object) -> list[str]:
    """``names`` as a list of strings, else an :class:`InputError` (a string was read a
    letter at a time: ``make_choices("fuzzy", ...)`` said "unknown planner `f`")."""
    example = 'make_choices(["fuzzy"], ["min", "product"], [], [])'
    if isinstance(names, str):
        raise InputError(f"{what} are a list of names, not the string `{names}`",
                         hint=f"{split_list(names) or [names]!r}")
    try:
        out = list(names)  # type: ignore[call-overload]  # anything iterable is tried
    except TypeError:
        raise InputError(f"{what} are a list of names, not {type(names).__name__} "
                         f"`{names!r:.40}`", hint=example) from None
    for name in out:
        if not isinstance(name, str):
            raise InputError(f"{what} are a list of names, not of {type(name).__name__} "
                             f"`{name!r:.40}`", hint=example)
    return out


def task_seeds(seed: int, n_worlds: int, runs: int) -> list[list[int]]:
    """``seeds[w][r]``: one 63-bit seed per (world, run), shared by every choice."""
    out = []
    for world_seq in np.random.SeedSequence(seed).spawn(n_worlds):
        out.append([int(s.generate_state(1, np.uint64)[0] >> np.uint64(1))
                    for s in world_seq.spawn(runs)])
    return out


def expand(worlds: list[str], choices: list[Choice], runs: int, seed: int) -> list[Task]:
    """All tasks of a study in their serial order: run-major, then world, then choice, so a
    sweep stopped half-way holds complete, paired runs of every world and choice."""
    seeds = task_seeds(seed, len(worlds), runs)
    tasks: list[Task] = []
    for r in range(runs):
        for w, world in enumerate(worlds):
            for choice in choices:
                tasks.append(Task(len(tasks), world, choice, r, seeds[w][r]))
    return tasks
