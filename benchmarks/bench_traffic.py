"""Robots giving way where their routes cross: randomised runs of crossroads worlds with
every robot giving way (the default) against the same runs with none (``give_way: false``).

    python benchmarks/bench_traffic.py                    # 100 runs of each world, 2 workers
    python benchmarks/bench_traffic.py --runs 40 --seed 1000 --jobs 1

The worlds (``tests/data``): ``crossroads4.yaml``, four robots coming to a crossroads together,
one from each side (each has another on its right: a ring); ``crossroads_carts.yaml``, three
robots from three sides while two carts cross. And ``worlds/multirobot.yaml``, two robots
head-on, where giving way should change little. For each world and each way: successes,
collisions of a robot with a robot and with anything else (a robot's collision is with a
robot when another robot's centre is nearer it than any cart's, within 32 in), stuck and
timeouts, and the mean time of the successes. The peer in the same run is the world without
giving way; the runs are the same seeds, so each row differs only by giving way.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import sys
import time

import numpy as np
from options import ROOT, guarded, positive_int

from mitos_cli.sim.loop import SimResult
from mitos_cli.sim.runs import run_many
from mitos_cli.sim.world import World
from mitos_cli.sim.worldfile import load_world

WORLDS = (ROOT / "tests" / "data" / "crossroads4.yaml",
          ROOT / "tests" / "data" / "crossroads_carts.yaml",
          ROOT / "worlds" / "multirobot.yaml")
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


@guarded
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=positive_int, default=100, help="randomised runs per world")
    ap.add_argument("--seed", type=int, default=1000, help="the first run's seed")
    ap.add_argument("--jobs", type=positive_int, default=2, help="worker processes")
    args = ap.parse_args(argv)
    print("| world, giving way | runs | success | robot-robot collisions | other collisions "
          "| stuck | timeout | mean time of successes (s) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for path in WORLDS:
        world = load_world(path)
        started = time.perf_counter()
        for way, w in (("yes", world), ("no", without_giving_way(world))):
            runs = run_many([w], runs=args.runs, seed=args.seed, workers=args.jobs,
                            measure=contacts)
            print(row(f"`{world.name}`, {way}", runs.worlds[0].summaries), flush=True)
        print(f"({world.name}: {time.perf_counter() - started:.0f} s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
