"""Planners: what turns perception into steering and speed, for all robots at once.

The protocol is one method, :meth:`Planner.plan`, called once per tick with a :class:`Percepts`
holding every robot's perception as arrays (row ``i`` = robot ``i``). It returns the commanded
steering (deg, 90 = straight, below 90 = left) and speed (in/s) as arrays ``[n]``; the robot's
limits (steering range and rate, top speed, acceleration) are applied afterwards by the
kinematics, so a planner may ask for anything. A planner must be a pure function of its
percepts (keep no hidden state, or the simulation is no longer reproducible from the trace) and
picklable (``run_many`` sends it to worker processes).

:class:`FuzzyPlanner` evaluates a compiled behavior of a rule base on the fuzzy inputs, one batch
for all robots. A baseline (a potential field, say) implements the same ``plan`` using
``percepts.ranges`` / ``beam_angles`` / ``pose`` / ``target``:

>>> class Straight:                                        # doctest: +SKIP
...     name = "straight"
...     def plan(self, p: Percepts):
...         n = len(p.pose)
...         return np.full(n, 90.0), np.full(n, 30.0)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..errors import RuleBaseError


@dataclass(frozen=True)
class Percepts:
    """What every robot perceives in one tick (rows are robots)."""

    inputs: dict[str, np.ndarray]  # fuzzy inputs by name (perception.INPUTS), each [n]
    ranges: np.ndarray             # [n, B] noisy range readings (in)
    beam_angles: np.ndarray        # [B] beam directions relative to the heading (rad, CCW)
    pose: np.ndarray               # [n, 3] x, y (in), heading (rad, CCW from +x)
    speed: np.ndarray              # [n] current speed (in/s)
    target: np.ndarray             # [n, 2] route point a lookahead ahead (in)
    goal: np.ndarray               # [n, 2] goal position (in)


class Planner(Protocol):
    name: str

    def plan(self, percepts: Percepts) -> tuple[np.ndarray, np.ndarray]:
        """Commanded (steering [n] in degrees, speed [n] in in/s)."""
        ...


class FuzzyPlanner:
    """A behavior of a rule base as the planner (default: the packaged ``drive``)."""

    def __init__(self, rulebase=None, behavior: str = "drive") -> None:
        from ..api import LoadedRuleBase, load_rulebase

        if rulebase is None or isinstance(rulebase, (str, bytes)) or hasattr(rulebase, "__fspath__"):
            loaded = load_rulebase(rulebase, behavior)
        elif isinstance(rulebase, LoadedRuleBase):
            loaded = rulebase if rulebase.compiled.behavior == behavior else \
                rulebase.behavior(behavior)
        else:
            loaded = LoadedRuleBase(rulebase, behavior)
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
                expected="inputs among " + ", ".join(INPUTS))
        for out in ("steering", "speed"):
            if out not in self.compiled.outputs:
                raise RuleBaseError(f"behavior `{self.compiled.behavior}` sets no `{out}`; "
                                    f"a driving behavior must set steering and speed",
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
            out = evaluate_one(self.compiled, [float(inputs[k][0]) for k in self.compiled.inputs])
            return np.array([out[self._cols[0]]]), np.array([out[self._cols[1]]])
        out = evaluate(self.compiled, self.matrix(inputs), detail=False).outputs
        return out[:, self._cols[0]], out[:, self._cols[1]]

    def explain(self, inputs: dict[str, np.ndarray]):
        """The detailed engine result (memberships, DOFs) for inputs ``[n]`` by name: rows are
        ticks or robots. Bit for bit what :meth:`plan` computed (the engine is row-exact)."""
        from ..engine.evaluation import evaluate

        return evaluate(self.compiled, self.matrix(inputs))
