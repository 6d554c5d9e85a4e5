"""Many runs of one world in one picture (``mitos simulate WORLD --runs N --plot``): every run's
paths grouped by the run's outcome, the count of each outcome, and each collision's place and
time. Built from the run summaries that :func:`mitos_cli.sim.runs.trail` filled in."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...sim.loop import OUTCOMES

if TYPE_CHECKING:
    from collections.abc import Sequence


@dataclass(frozen=True)
class Collision:
    """A robot that collided: where its footprint's centre was (in) and when (s)."""

    x: float
    y: float
    t: float
    robot: str
    seed: int


@dataclass(frozen=True)
class RunsOverlay:
    world: str
    seeds: tuple[int, ...]
    #: outcome -> the paths (``[k, 2]`` arrays, every robot's of every run with that outcome)
    paths: dict[str, tuple[np.ndarray, ...]]
    #: outcome -> number of runs (the run's outcome, as in the table); only outcomes that occur
    counts: dict[str, int]
    collisions: tuple[Collision, ...]
    #: each run's obstacle centres at t = 0 (``[O, 2]``): randomised runs move them
    obstacles: tuple[np.ndarray, ...]

    def collision_places(self, near: float = 20.0) -> list[tuple[float, float, int, float, float]]:
        """Collisions within ``near`` in of a place's first one, together: ``(x, y, count,
        first time, last time)`` per place (one label each, not twelve on top of each other)."""
        places: list[list] = []
        for c in self.collisions:
            for p in places:
                if np.hypot(c.x - p[0], c.y - p[1]) <= near:
                    p[2] += 1
                    p[3], p[4] = min(p[3], c.t), max(p[4], c.t)
                    break
            else:
                places.append([c.x, c.y, 1, c.t, c.t])
        return [tuple(p) for p in places]

    def label(self, outcome: str) -> str:
        """The legend's entry: ``collision (3 of 20)``."""
        return f"{outcome} ({self.counts[outcome]} of {len(self.seeds)})"


def runs_overlay(world: str, summaries: Sequence[dict], robot_names: list[str]) -> RunsOverlay:
    """The overlay of ``summaries`` (each with ``seed``, ``outcome`` and ``trail``)."""
    paths: dict[str, list[np.ndarray]] = {}
    counts: dict[str, int] = {}
    collisions, obstacles = [], []
    for s in summaries:
        tr, outcome = s["trail"], s["outcome"]
        counts[outcome] = counts.get(outcome, 0) + 1
        for name, path, own in zip(robot_names, tr["paths"], tr["robot_outcomes"]):
            xy = np.asarray(path, float).reshape(-1, 2)
            paths.setdefault(outcome, []).append(xy)
            if own == "collision" and len(xy):
                collisions.append(Collision(float(xy[-1, 0]), float(xy[-1, 1]),
                                            float(tr["t_end"]), name, int(s["seed"])))
        obstacles.append(np.asarray(tr["obstacles"], float).reshape(-1, 2))
    order = [o for o in OUTCOMES if o in counts] + sorted(set(counts) - set(OUTCOMES))
    return RunsOverlay(world, tuple(int(s["seed"]) for s in summaries),
                       {o: tuple(paths.get(o, ())) for o in order},
                       {o: counts[o] for o in order}, tuple(collisions), tuple(obstacles))
