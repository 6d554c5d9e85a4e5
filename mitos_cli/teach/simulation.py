"""A recorded simulation run that the instructor corrects with ``at 12.5s steering=55``.

``simulate WORLD`` drives the session's *active* behavior through the world (the simulator of
:mod:`mitos_cli.sim`, imported only here and only when asked); ``at`` turns what the robot
perceived at a time (or in a time window) into examples.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import LessonError, MitosError, Span
from ..lang.model import RuleBase
from ..words import clearance, plural

if TYPE_CHECKING:
    from collections.abc import Callable

    from ..sim.loop import SimResult


def world_path(name: str, base: Path | None = None) -> Path:
    """A world by path (relative to ``base``, then the working directory) or a packaged world
    by name: the simulator's one resolver,
    :func:`mitos_cli.sim.worldfile.resolve_world_path`."""
    from ..sim.worldfile import resolve_world_path

    return resolve_world_path(name, base)


@dataclass
class Recording:
    """One run: its verdict and what the robot perceived at every tick."""

    name: str
    behavior: str
    result: SimResult
    robot: int = 0                     # the column of the robot whose run is corrected
    robot_name: str = ""
    seed: int | None = None            # as given to `simulate` (None: the world's own)
    #: the behaviors of the rule base that drove it (the world's own may not be among them)
    behaviors: tuple[str, ...] = ()

    @property
    def t(self) -> np.ndarray:
        return self.result.t

    def time(self, row: int) -> float:
        return float(self.t[row])

    @property
    def _active(self) -> np.ndarray:
        """The ticks at which the corrected robot still drove (it stops at its goal while
        the others go on)."""
        if self.result.active is None:
            return np.ones(len(self.t), dtype=bool)
        return self.result.active[:, self.robot]

    @property
    def _last(self) -> int:
        """The row of the corrected robot's last tick: the one at which it arrived or hit
        something (its run is recorded up to there; the others may drive on)."""
        rows = np.flatnonzero(self._active)
        return min(int(rows[-1]) + 1, len(self.t) - 1) if rows.size else len(self.t) - 1

    @property
    def end(self) -> float:
        """When the corrected robot's run ends (s): see :attr:`_last`."""
        return float(self.t[self._last])

    @property
    def fingerprint(self) -> str:
        """What tells this run from another (every robot's pose at every tick, hashed): the
        journal keeps it, so that a resumed session knows whether the run it drove again is
        the one the instructor saw."""
        import hashlib

        pose = np.ascontiguousarray(self.result.pose, dtype=np.float64)
        return hashlib.sha256(pose.tobytes()).hexdigest()[:16]

    @property
    def verdict(self) -> str:
        """``success after 8.7 s``: the outcome and the time of the corrected robot."""
        s = self.result.summary()
        if self.robot_name:
            s = {**s, **self.result.robot_metrics[self.robot]}
        return f"{s['outcome']} after {s['time_s']:g} s"

    def describe(self, use: Callable[[str], str] | None = None) -> str:
        """The run's verdict, and where to go on; ``use(NAME)`` says how to make a behavior
        the active one (default `` `use NAME` ``)."""
        s = self.result.summary()
        if self.robot_name:              # the corrected robot's own run, not the world's
            own = self.result.robot_metrics[self.robot]
            s = {**s, **own, "collisions": int(own["outcome"] == "collision")}
        who = f" (robot {self.robot_name})" if self.robot_name else ""
        who += f" (seed {self.seed})" if self.seed is not None else ""
        return (f"{self.name}{who} with behavior {self.behavior}: {s['outcome']} after "
                f"{s['time_s']:g} s (min clearance {clearance(s['min_clearance_in'])} in, "
                f"{plural(s['collisions'], 'collision')}); "
                f"correct it with `at TIME OUTPUT=VALUE` (0 to {self.end:g} s)" + self._whose(use))

    def _whose(self, use: Callable[[str], str] | None = None) -> str:
        """A note when the session drove the world with another behavior than the one
        ``mitos simulate`` drives it with (the file's first behavior is rarely a driver: a new
        session's `avoid_obstacle` hits Figure 4's first obstacle after 2 s)."""
        own = self.result.world.behavior
        if own == self.behavior:
            return ""
        if self.behaviors and own not in self.behaviors:   # `use` it would be a name error
            return (f"\n  ({self.name}'s world file names behavior `{own}`, which this rule "
                    "base does not have)")
        return (f"\n  (`mitos simulate` drives {self.name} with behavior {own}: "
                f"{use(own) if use is not None else f'`use {own}`'} to drive it so here)")

    def rows(self, start: float, stop: float | None,
             places: tuple[Span | None, Span | None] = (None, None)) -> np.ndarray:
        """Tick rows at ``start`` (the nearest) or from ``start`` to ``stop``. A time that
        cannot be used is refused at its place (``places``: where the two are written), not
        at the line's first column."""
        t, end, active = self.t, self.end, self._active
        whose = f"robot {self.robot_name}'s run" if self.robot_name else "the run"
        for value, place in zip((start, stop), places):
            if value is not None and not math.isfinite(value):
                raise LessonError(f"a time is a finite number of seconds ({whose} lasted 0 "
                                  f"to {end:g} s)", span=place)
            if value is not None and not -1e-9 <= value <= end + 1e-9:
                raise LessonError(f"{whose} lasted 0 to {end:g} s; {value:g} s is outside it",
                                  span=place)
        if stop is None:
            return np.array([int(np.argmin(np.abs(t[:self._last + 1] - start)))])
        if stop < start:
            raise LessonError(f"`at {start:g}s to {stop:g}s`: the window ends before it starts",
                              span=_between(*places))
        # up to the tick at which it arrived, as one time reaches it (`active` is False there:
        # a window ending at the end of the run left out its last tick, and a robot that
        # starts at its goal had "no recorded tick between 0 s and 0 s" where `at 0s` had one)
        rows = np.flatnonzero((t >= start - 1e-9) & (t <= stop + 1e-9)
                              & (active | (np.arange(len(t)) == self._last)))
        if rows.size == 0:
            before = t[:self._last + 1][t[:self._last + 1] < start]
            after = t[:self._last + 1][t[:self._last + 1] > stop]
            hint = None
            if before.size and after.size:          # a window between two ticks
                step = float(t[1] - t[0]) if len(t) > 1 else 0.0
                hint = (f"the ticks of {whose} are {step:g} s apart: the nearest are at "
                        f"{float(before[-1]):g} s and {float(after[0]):g} s (`at {start:g}s` "
                        "alone takes the nearest tick)")
            raise LessonError(f"no recorded tick between {start:g} s and {stop:g} s",
                              span=_between(*places), hint=hint)
        return rows

    def when(self, rows: np.ndarray) -> str:
        if len(rows) == 1:
            return f"at {self.time(rows[0]):g} s"
        return f"from {self.time(rows[0]):g} s to {self.time(rows[-1]):g} s"

    def inputs_at(self, row: int, names: tuple[str, ...]) -> dict:
        missing = [n for n in names if n not in self.result.perceived]
        if missing:
            raise LessonError("the simulator does not perceive " + ", ".join(
                f"`{m}`" for m in missing), hint="correct a behavior whose inputs the "
                                                 "simulator measures (e.g. drive)")
        return {n: float(self.result.perceived[n][row, self.robot]) for n in names}


def run_world(name: str, rulebase: RuleBase, behavior: str, seed: int | None = None,
              base: Path | None = None, robot: str | None = None,
              robot_span: Span | None = None) -> Recording:
    """Drive ``behavior`` of ``rulebase`` through the world ``name``; ``at`` then corrects
    ``robot`` (a name of the world's robots, written at ``robot_span``; default the first)."""
    from ..sim.loop import simulate
    from ..sim.planner import FuzzyPlanner
    from ..sim.worldfile import load_world

    path = world_path(name, base)
    world = load_world(path)
    names = [a.name for a in world.agents]
    if robot is not None and robot not in names:
        from ..errors import unknown

        raise unknown("robot", robot, names, span=robot_span, cls=LessonError,
                      owner=Path(name).stem)
    index = names.index(robot) if robot is not None else 0
    try:
        planner = FuzzyPlanner(rulebase, behavior)
    except MitosError as exc:           # its hints name `mitos simulate --behavior`
        if exc.hint:
            name = "drive" if "drive" in {b.name for b in rulebase.behaviors} else "NAME"
            exc.hint = exc.hint.replace("(--behavior)", f"(`use {name}`, then `simulate` again)")
        raise
    result = simulate(world, planner, seed=seed)
    return Recording(Path(name).stem, behavior, result, index,
                     names[index] if len(names) > 1 else "", seed,
                     tuple(b.name for b in rulebase.behaviors))


def _between(first: Span | None, last: Span | None) -> Span | None:
    """The window from the place of its first time to the end of its last (`5s to 2s`)."""
    if first is None or last is None or last.line != first.line:
        return first
    return dataclasses.replace(first, end_column=last.end_column)
