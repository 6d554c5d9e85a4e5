"""Planners: what turns perception into steering and speed, for all robots at once.

The protocol is one method, :meth:`Planner.plan`, called once per tick with a :class:`Percepts`
holding every robot's perception as arrays (row ``i`` = robot ``i``). It returns the commanded
steering (deg, 90 = straight, below 90 = left) and speed (in/s) as arrays ``[n]``; the robot's
limits (steering range and rate, top speed, acceleration) are applied afterwards by the
kinematics, so a planner may ask for anything. A planner must be a pure function of its
percepts (keep no hidden state, or the simulation is no longer reproducible from the trace) and
picklable (``run_many`` sends it to worker processes). A planner that remembers within a run
(DWA's costmap) has a method ``fresh()`` giving a copy with nothing remembered: the simulator
calls it at the start of every run, so what it remembers is a function of the run's own
percepts and runs still replay bit for bit.

:class:`FuzzyPlanner` evaluates a compiled behavior of a rule base on the fuzzy inputs, one batch
for all robots. A baseline (a potential field, say) implements the same ``plan`` using
``percepts.ranges`` / ``beam_angles`` / ``pose`` / ``target``; a planner with a ``path_reach``
(in) is also given ``percepts.path``, its route's points that far ahead (DWA scores by them):

>>> class Straight:                                        # doctest: +SKIP
...     name = "straight"
...     def plan(self, p: Percepts):
...         n = len(p.pose)
...         return np.full(n, 90.0), np.full(n, 30.0)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from ..errors import NameError_, RuleBaseError, Span, unknown

if TYPE_CHECKING:
    from pathlib import Path

    from ..api import LoadedRuleBase
    from ..engine.evaluation import Result
    from ..lang.model import Expr, RuleBase
    from .world import World

    #: what a fuzzy planner is made from: a loaded rule base, a rule base, a file (None: the
    #: packaged one)
    RuleBaseSource = LoadedRuleBase | RuleBase | str | Path | None


@dataclass(frozen=True)
class Percepts:
    """What every robot perceives in one tick (rows are robots). The heading (``pose[:, 2]``)
    and the beams' directions are in radians, where ``Simulation.pose``, a ``Tick`` and a
    ``SimResult`` give the heading in degrees (docs/api.md)."""

    inputs: dict[str, np.ndarray]  # fuzzy inputs by name (perception.INPUTS), each [n]
    ranges: np.ndarray             # [n, B] noisy range readings (in)
    beam_angles: np.ndarray        # [B] beam directions relative to the heading (rad, CCW)
    pose: np.ndarray               # [n, 3] x, y (in), heading (rad, CCW from +x)
    speed: np.ndarray              # [n] current speed (in/s)
    target: np.ndarray             # [n, 2] route point a lookahead ahead (in)
    goal: np.ndarray               # [n, 2] goal position (in)
    steering: np.ndarray | None = None   # [n] the wheel's current angle (deg), for planners
                                         # that search the commands reachable from it (DWA)
    robots: np.ndarray | None = None     # [n] which robot of the world each row is (rows
                                         # are the robots still driving)
    path: np.ndarray | None = None       # [n, K, 2] points of each robot's route (world
                                         # frame, in), every 4 in (loop.PATH_STEP) from where
                                         # it is to the planner's ``path_reach`` ahead; None
                                         # unless the planner has a ``path_reach`` (DWA)


class Planner(Protocol):
    name: str

    def plan(self, percepts: Percepts) -> tuple[np.ndarray, np.ndarray]:
        """Commanded (steering [n] in degrees, speed [n] in in/s)."""
        ...


def first_use(rulebase: RuleBase, behavior: str, name: str) -> Span | None:
    """Where ``behavior`` (or a behavior it uses, depth first) first reads variable ``name``
    in a rule's or a `use`'s condition; else where the term set declares it; else None."""
    from ..lang.model import And, Not, Or, Prop

    def in_expr(e: Expr) -> Span | None:
        if isinstance(e, Prop):
            return e.span.naming(name) if e.var == name and e.span else None
        items = (e.expr,) if isinstance(e, Not) else e.items if isinstance(e, (And, Or)) else ()
        return next((s for s in map(in_expr, items) if s is not None), None)

    seen: set[str] = set()

    def in_behavior(b: str) -> Span | None:
        if b in seen:
            return None
        seen.add(b)
        found = next((b_ for b_ in rulebase.behaviors if b_.name == b), None)
        if found is None:
            return None
        for rule in found.rules:
            if (s := in_expr(rule.antecedent)) is not None:
                return s
        for use in found.uses:
            if use.condition is not None and (s := in_expr(use.condition)) is not None:
                return s
            if (s := in_behavior(use.behavior)) is not None:
                return s
        return None

    span = in_behavior(behavior)
    if span is None:
        variable = rulebase.variables.get(name)
        span = getattr(variable, "span", None)
    return span


def _behavior_span(rulebase: RuleBase, behavior: str) -> Span | None:
    """Where ``behavior`` is declared in its rule file (None for top-level rules or text)."""
    return next((b.span for b in rulebase.behaviors if b.name == behavior), None)


class FuzzyPlanner:
    """A behavior of a rule base as the planner (default: the packaged ``drive``)."""

    def __init__(self, rulebase: RuleBaseSource = None, behavior: str = "drive") -> None:
        from ..api import LoadedRuleBase, load_rulebase
        from ..lang.model import RuleBase

        if isinstance(rulebase, LoadedRuleBase):
            loaded = rulebase if rulebase.compiled.behavior == behavior else \
                rulebase.behavior(behavior)
        elif isinstance(rulebase, RuleBase):
            loaded = LoadedRuleBase(rulebase, behavior)
        else:           # a path, None (the packaged one); anything else load_rulebase refuses
            loaded = load_rulebase(rulebase, behavior)   # (3 met "'int' has no 'behavior'")
        self.loaded = loaded
        self.compiled = loaded.compiled
        self.name = f"fuzzy:{self.compiled.behavior}"
        from .perception import INPUTS

        missing = [k for k in self.compiled.inputs if k not in INPUTS]
        if missing:
            raise RuleBaseError(
                f"behavior `{self.compiled.behavior}` reads input "
                + ", ".join(f"`{m}`" for m in missing)
                + ", which the simulator does not perceive",
                span=first_use(loaded.rulebase, self.compiled.behavior, missing[0]),
                expected="inputs among " + ", ".join(INPUTS),
                hint="the simulator measures only these (`mitos docs worlds`, \"What the robot "
                     "perceives\"); simulate a behavior that reads them (--behavior)")
        for out in ("steering", "speed"):
            if out not in self.compiled.outputs:
                raise RuleBaseError(f"behavior `{self.compiled.behavior}` sets no `{out}`; "
                                    f"a driving behavior must set steering and speed",
                                    span=_behavior_span(loaded.rulebase, self.compiled.behavior),
                                    hint="simulate a behavior such as `drive` (--behavior)")
        self._cols = [self.compiled.outputs.index("steering"),
                      self.compiled.outputs.index("speed")]

    def matrix(self, inputs: dict[str, np.ndarray]) -> np.ndarray:
        """``X[n, k]`` in the compiled input order."""
        return np.column_stack([np.asarray(inputs[k], float) for k in self.compiled.inputs])

    def plan(self, percepts: Percepts) -> tuple[np.ndarray, np.ndarray]:
        from ..engine.evaluation import evaluate, evaluate_one

        inputs = percepts.inputs
        if len(percepts.pose) == 1:             # one robot: the scalar form, same bits
            one = evaluate_one(self.compiled, [float(inputs[k][0]) for k in self.compiled.inputs])
            return np.array([one[self._cols[0]]]), np.array([one[self._cols[1]]])
        out = evaluate(self.compiled, self.matrix(inputs), detail=False).outputs
        return out[:, self._cols[0]], out[:, self._cols[1]]

    def explain(self, inputs: dict[str, np.ndarray]) -> Result:
        """The detailed engine result (memberships, DOFs) for inputs ``[n]`` by name: rows are
        ticks or robots. Bit for bit what :meth:`plan` computed (the engine is row-exact)."""
        from ..engine.evaluation import evaluate

        return evaluate(self.compiled, self.matrix(inputs))


@dataclass(frozen=True)
class PlannerKind:
    """One entry of the planner registry: its name, what it is, and how to build it for a
    world (``build(world, rulebase, behavior)``; only the fuzzy planner reads the last two)."""

    name: str
    summary: str
    build: Callable[..., Planner]


def _fuzzy(world: World, rulebase: RuleBaseSource = None, behavior: str | None = None) -> Planner:
    return fuzzy_planner(world, rulebase, behavior or None)     # (as it was: "" is the world's)


def fuzzy_planner(world: World, rulebase: RuleBaseSource = None, behavior: str | None = None) -> FuzzyPlanner:
    """The rule base's ``behavior`` (default: the world's ``behavior:``) as a planner; the
    world's behavior missing from the rule base is said at the world's line, with how to
    choose another (`mitos simulate`, and the Gymnasium environments)."""
    try:
        return FuzzyPlanner(rulebase, world.behavior if behavior is None else behavior)
    except NameError_ as exc:       # the world file's `behavior:` names none of the rule base's
        if behavior is None:
            said_at_world(exc, world, rulebase is not None)
        raise


def said_at_world(exc: NameError_, world: World, given: bool) -> None:
    """``exc``, "unknown behavior" for the world's own ``behavior:``, said at the world's line
    with why it was looked for and how to choose another (``given``: a rule base was given,
    not the packaged one); any other error is left as it is."""
    if exc.span is not None or not exc.message.startswith("unknown behavior"):
        return
    exc.span = getattr(world, "behavior_span", None)
    # `simulate figure4 --rulebase tipper.fis`: the error stood at the world's line with
    # no word of why the world's behavior was looked for, nor how to choose another
    said = (f"the world is driven by its `behavior: {world.behavior}`, which "
            f"{'this rule base' if given else 'the rule base'} lacks: "
            f"choose one of its behaviors (--behavior NAME; behavior= from Python)")
    exc.hint = (f"{exc.hint} (--behavior NAME drives with another than the world's "
                f"`behavior: {world.behavior}`)" if exc.hint else said)


def _potential_field(world: World, rulebase: RuleBaseSource = None, behavior: str | None = None) -> Planner:
    from .potential_field import PotentialFieldPlanner

    return PotentialFieldPlanner.for_world(world)


def _dwa(world: World, rulebase: RuleBaseSource = None, behavior: str | None = None) -> Planner:
    from .dwa import DWAPlanner

    return DWAPlanner.for_world(world)


#: every planner the simulator, ``mitos simulate --planner`` and ``mitos compare`` know
PLANNERS: dict[str, PlannerKind] = {k.name: k for k in (
    PlannerKind("fuzzy", "the rule base's driving behavior (default: the packaged `drive`)",
                _fuzzy),
    PlannerKind("potential_field", "an artificial potential field (Khatib 1986)",
                _potential_field),
    PlannerKind("dwa", "a dynamic window (Fox et al. 1997; ROS's dwa_local_planner)", _dwa),
)}


def planner_kind(name: str) -> PlannerKind:
    """The registry entry called ``name`` (an unknown name: an error with "did you mean")."""
    try:
        return PLANNERS[name]
    except KeyError:
        raise unknown("planner", name, PLANNERS) from None


def make_planner(name: str, world: World, rulebase: RuleBaseSource = None,
                 behavior: str | None = None) -> Planner:
    """The planner ``name`` built for ``world`` (the fuzzy one from ``rulebase``/``behavior``)."""
    return planner_kind(name).build(world, rulebase, behavior)
