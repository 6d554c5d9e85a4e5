"""Many runs: randomised repetitions of worlds on a process pool, and their statistics.

Run ``j`` of a world uses seed ``seed + j`` and draws its obstacle places and sensor noise from
the world's ``randomise`` ranges, so any run can be replayed alone (``mitos simulate WORLD
--seed S+j --randomise``). Each run is a pure function of (world, planner, seed): the results do
not depend on the number of workers or on which worker ran what.
"""

from __future__ import annotations

import math
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

from .lockstep import run_lockstep
from .loop import OUTCOMES, ROBOT_OUTCOMES, prepare
from .world import World

METRICS = ("time_s", "path_length_in", "min_clearance_in", "mean_speed_in_s",
           "steering_total_variation_deg")


def _chunk(task: tuple) -> list[dict]:
    """One worker's runs of a world, stepped in lockstep (:mod:`.lockstep`: each run's bits
    are those it has alone)."""
    world, planner, seeds, randomise, measure = task
    scene = prepare(world)
    return [{**res.summary(), **(measure(res) if measure is not None else {})}
            for res in run_lockstep(world, planner, seeds, randomise=randomise, scene=scene)]


def trail(res) -> dict:
    """A ``measure`` for :func:`run_many` (``--runs N --plot``): where each robot drove (its
    ``[x, y]`` while driving and where it stopped: the colliding or arriving tick), each robot's
    outcome, and where the obstacles started in this run, under the key ``trail`` (not part of
    the JSON)."""
    drove = res.active.copy()
    drove[1:] |= res.active[:-1]                # the tick it arrived at (no longer active)
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

    def rate(self, outcome: str) -> float:
        return sum(s["outcome"] == outcome for s in self.summaries) / len(self.summaries)

    def stat(self, key: str) -> tuple[float, float]:
        x = np.array([s[key] for s in self.summaries], dtype=float)
        return float(x.mean()), float(x.std(ddof=1)) if len(x) > 1 else 0.0

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
        """Each outcome's rate and each metric's mean and std over the runs."""
        row: dict[str, float | dict[str, float]] = {f"{o}_rate": self.rate(o)
                                                         for o in self.outcomes}
        for key in METRICS:
            mean, std = self.stat(key)
            row[key] = {"mean": mean, "std": std}
        return row


@dataclass(frozen=True)
class Runs:
    worlds: tuple[WorldRuns, ...]

    def to_json(self) -> list[dict]:
        out = []
        for w in self.worlds:
            row = {"world": w.world, "runs": len(w.summaries), **w.figures()}
            if w.robots:
                row["robots"] = [{"name": r.world, **r.figures()} for r in w.robots]
            row["runs_detail"] = list(w.summaries)
            out.append(row)
        return out


def default_workers() -> int:
    import os

    return max(1, min(2, os.cpu_count() or 1))


def run_many(worlds: list[World], runs: int = 0, seed: int | None = None, planner=None,
             workers: int | None = None, measure=None) -> Runs:
    """Run each world once (``runs=0``: its own seed, as written) or ``runs`` randomised times
    (seeds ``seed + j``, default base: the world's seed), on ``workers`` processes.
    ``measure(result) -> dict`` (a picklable function), when given, adds figures of its own to
    each run's summary in the worker (a benchmark's scores from the ticks)."""
    if planner is None:
        from .planner import FuzzyPlanner

        planner = FuzzyPlanner(None, worlds[0].behavior if worlds else "drive")
    workers = default_workers() if workers is None else workers
    tasks = []
    for w in worlds:
        base = w.seed if seed is None else seed
        seeds = [base] if runs <= 0 else [base + j for j in range(runs)]
        size = max(1, math.ceil(len(seeds) / (2 * workers)))
        for i in range(0, len(seeds), size):
            tasks.append((w, tuple(seeds[i:i + size]), i))
    jobs = [(w, planner, chunk, runs > 0, measure) for w, chunk, _ in tasks]
    if workers > 1 and len(jobs) > 1:
        with ProcessPoolExecutor(workers) as pool:
            results = list(pool.map(_chunk, jobs))
    else:
        results = [_chunk(j) for j in jobs]
    grouped: dict[int, list[dict]] = {}
    for (w, _, _), res in zip(tasks, results):
        grouped.setdefault(id(w), []).extend(res)
    return Runs(tuple(WorldRuns(w.name, tuple(grouped[id(w)])) for w in worlds))
