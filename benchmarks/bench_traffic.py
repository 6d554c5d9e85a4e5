"""Robots giving way where their routes cross: randomised runs of multi-robot worlds with
every robot giving way (the default) against the same runs with none (``give_way: false``).

    python benchmarks/bench_traffic.py                    # 100 runs of each world, 2 workers
    python benchmarks/bench_traffic.py --runs 40 --seed 1000 --jobs 1
    python benchmarks/bench_traffic.py --planners fuzzy,dwa --only cross135_left,tee_left_turn

The worlds: ``tests/data/crossroads4.yaml``, four robots coming to a crossroads together, one
from each side (each has another on its right: a ring); ``tests/data/crossroads_carts.yaml``,
three robots from three sides while two carts cross; ``worlds/multirobot.yaml``, two robots
head-on, where giving way should change little; and the layouts of ``tests/data/traffic/``
(two robots crossing at 45, 90 and 135 deg from either side, a left turn across a lane at a
T-junction, a merge, six robots at a crossroads, a larger robot, a fleet with one robot left
out; each file says what it holds). For each world, planner and way: successes, collisions of
a robot with a robot and with anything else (a robot's collision is with a robot when another
robot's centre is nearer it than any cart's, within 32 in), stuck and timeouts, and the mean
time of the successes. The peer in the same run is the world without giving way; the runs are
the same seeds, so each row pair differs only by giving way.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from options import ROOT, guarded, positive_int

from mitos_cli.errors import unknown
from mitos_cli.sim.loop import SimResult
from mitos_cli.sim.planner import PLANNERS, make_planner
from mitos_cli.sim.runs import run_many
from mitos_cli.sim.world import World
from mitos_cli.sim.worldfile import load_world

WORLDS: tuple[Path, ...] = (
    ROOT / "tests" / "data" / "crossroads4.yaml",
    ROOT / "tests" / "data" / "crossroads_carts.yaml",
    ROOT / "worlds" / "multirobot.yaml",
    *sorted((ROOT / "tests" / "data" / "traffic").glob("*.yaml")))
#: in: a collided robot's nearest other robot (centre to centre) within this is what it met
TOUCH = 32.0


def contacts(res: SimResult) -> dict:
    """The run's collided robots that met another robot, and those that met something else
    (picklable: :func:`run_many` calls it in its workers)."""
    k = res.ticks - 1
    robots = others = 0
    for i, outcome in enumerate(res.robot_outcomes):
        if outcome != "collision":
            continue
        at = res.pose[k, i, :2]
        robot = min((float(np.hypot(*(at - res.pose[k, j, :2])))
                     for j in range(len(res.robot_outcomes)) if j != i), default=np.inf)
        cart = min((float(np.hypot(*(at - res.obstacles[k, j])))
                    for j in range(res.obstacles.shape[1])), default=np.inf)
        if robot < TOUCH and robot <= cart:
            robots += 1
        else:
            others += 1
    return {"robot_contacts": robots, "other_contacts": others}


def without_giving_way(world: World) -> World:
    return dataclasses.replace(world, agents=tuple(
        dataclasses.replace(a, robot=dataclasses.replace(a.robot, give_way=False))
        for a in world.agents))


def row(name: str, summaries: list[dict]) -> str:
    n = len(summaries)
    count = {o: sum(s["outcome"] == o for s in summaries)
             for o in ("success", "collision", "stuck", "timeout")}
    robots = sum(s["robot_contacts"] > 0 for s in summaries)
    others = sum(s["other_contacts"] > 0 and s["robot_contacts"] == 0 for s in summaries)
    times = [s["time_s"] for s in summaries if s["outcome"] == "success"]
    mean = f"{statistics.fmean(times):.2f}" if times else "-"
    return (f"| {name} | {n} | {count['success']} ({100 * count['success'] / n:.0f}%) | "
            f"{robots} | {others} | {count['stuck']} | {count['timeout']} | {mean} |")


def _names(text: str, what: str, known: list[str]) -> list[str]:
    names = [p.strip() for p in text.split(",") if p.strip()]
    if not names:
        raise argparse.ArgumentTypeError(f"no {what} given (comma-separated names)")
    for name in names:
        if name not in known:
            err = unknown(what, name, known)
            raise argparse.ArgumentTypeError(
                "; ".join(x for x in (err.message, err.hint, f"expected {err.expected}") if x))
    return names


@guarded
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=positive_int, default=100, help="randomised runs per world")
    ap.add_argument("--seed", type=int, default=1000, help="the first run's seed")
    ap.add_argument("--jobs", type=positive_int, default=2, help="worker processes")
    stems = [p.stem for p in WORLDS]
    ap.add_argument("--only", type=lambda t: _names(t, "world", stems), default=stems,
                    help="comma-separated world names (default: all)")
    ap.add_argument("--planners", type=lambda t: _names(t, "planner", list(PLANNERS)),
                    default=["fuzzy"], help="comma-separated (default: fuzzy)")
    args = ap.parse_args(argv)
    print("| world, planner, giving way | runs | success | robot-robot collisions | other "
          "collisions | stuck | timeout | mean time of successes (s) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for path in (p for p in WORLDS if p.stem in args.only):
        world = load_world(path)
        for name in args.planners:
            started = time.perf_counter()
            for way, w in (("yes", world), ("no", without_giving_way(world))):
                runs = run_many([w], runs=args.runs, seed=args.seed, workers=args.jobs,
                                planner=make_planner(name, w), measure=contacts)
                print(row(f"`{world.name}`, {name}, {way}", runs.worlds[0].summaries),
                      flush=True)
            print(f"({world.name}, {name}: {time.perf_counter() - started:.0f} s)",
                  file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
