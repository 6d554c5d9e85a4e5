"""Simulator speed: simulated ticks per second for one robot, where the time goes, and the wall
time of ``--runs 100`` on one and two worker processes.

    python benchmarks/bench_sim.py                # sections 1-4, a few minutes on 2 cores
    python benchmarks/bench_sim.py --only 5       # 1,000 randomised slalom runs, two ways
    python benchmarks/bench_sim.py --only 4,5 --runs 200

1. **one robot, 60 simulated seconds at dt = 0.05** (1200 ticks): the packaged corridor world
   stretched to 2500 in so that the run never ends early; sensing (36 beams), perception, the
   fuzzy planner (behavior ``drive``, 44 rules), kinematics (4 substeps). Best and median of 5.
   Peers in the same run: the same loop with a constant planner (no rule evaluation) in the
   same corridor without its obstacle (the constant planner would hit it), and the planner's
   share of the tick measured by timing ``plan`` inside the loop. Times are wall times; the
   CPU time of the process is printed too (it is what a loaded machine distorts least).
2. **one run of ``slalom.yaml`` and of ``office.yaml``** (their own seeds, to the goal): ticks per
   second of CPU time (best of 5) against the aim of 5,000, and where a tick's time goes:
   each stage of :class:`~mitos_cli.sim.loop.Simulation` (sense, perceive, check, plan, act,
   recording and the stuck check) timed inside the loop.
3. **--runs 100** of ``slalom.yaml`` (randomised obstacles and noise) through ``run_many`` with
   1 and 2 workers; the two must give identical results.
4. **time per robot-tick in lockstep** (:mod:`mitos_cli.sim.lockstep`) at batch sizes 1, 16,
   256 and 1,024: that many randomised runs of ``slalom.yaml`` cut to 2 simulated seconds (40
   ticks each), stepped together, CPU time per robot-tick; the peer in the same run is the same
   16 runs each simulated alone (``simulate``), and every batch's results must equal theirs.
5. **1,000 randomised runs of ``slalom.yaml`` on 2 workers** (``--runs`` to change the number):
   ``run_many`` (each worker steps its runs in lockstep) against the runs simulated one by one
   on the same 2 processes; the outcome table and every run's summary must be equal.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import statistics
import time

import numpy as np

from mitos_cli.resources import packaged_path
from mitos_cli.sim.lockstep import run_lockstep
from mitos_cli.sim.loop import Simulation, prepare, simulate
from mitos_cli.sim.planner import FuzzyPlanner
from mitos_cli.sim.runs import run_many
from mitos_cli.sim.world import Corridor, Goal
from mitos_cli.sim.worldfile import load_world


class Timed:
    """A planner wrapper that adds up the time spent in ``plan``."""

    def __init__(self, inner) -> None:
        self.inner, self.name, self.seconds = inner, inner.name, 0.0

    def plan(self, percepts):
        t = time.perf_counter()
        out = self.inner.plan(percepts)
        self.seconds += time.perf_counter() - t
        return out


STAGES = ("sense", "perceive", "check", "plan", "act", "_record", "_check_stuck")


class StageTimed(Simulation):
    """A :class:`Simulation` that adds up the wall time of each stage."""

    seconds: dict[str, float]


def _timed_stage(name: str):
    inner = getattr(Simulation, name)

    def stage(self, *args):
        t = time.perf_counter()
        out = inner(self, *args)
        self.seconds[name] = self.seconds.get(name, 0.0) + time.perf_counter() - t
        return out
    return stage


for _name in STAGES:
    setattr(StageTimed, _name, _timed_stage(_name))


def one_run(world, planner, repeats: int = 5) -> None:
    """Ticks per second of one run (CPU time, best of ``repeats``) and the stages' shares."""
    scene = prepare(world)
    simulate(world, planner, scene=scene)                 # warm-up
    best_cpu, ticks = min(_cpu_of(world, planner, scene) for _ in range(repeats))
    sim = StageTimed(world, planner, scene=scene)
    sim.seconds = {}
    t = time.perf_counter()
    while not sim.done:
        sim.step()
    total = time.perf_counter() - t
    shares = ", ".join(f"{name.strip('_')} {1e6 * sim.seconds[name] / sim.ticks:.0f} us "
                       f"({100 * sim.seconds[name] / total:.0f}%)" for name in STAGES)
    print(f"   {world.name}: {ticks} ticks, {ticks / best_cpu:,.0f} ticks/s "
          f"({1e6 * best_cpu / ticks:.0f} us/tick, CPU, best of {repeats}; aim 5,000: "
          f"{ticks / best_cpu / 5000:.2f}x)")
    print(f"     per tick: {shares}; loop total {1e6 * total / sim.ticks:.0f} us (wall)")


def _cpu_of(world, planner, scene) -> tuple[float, int]:
    c = time.process_time()
    res = simulate(world, planner, scene=scene)
    return time.process_time() - c, res.ticks


class Constant:
    name = "constant"

    def plan(self, percepts):
        n = len(percepts.pose)
        return np.full(n, 90.0), np.full(n, 35.0)


def long_corridor():
    w = load_world(packaged_path("worlds", "corridor.yaml"))
    agent = dataclasses.replace(w.agents[0], goal=Goal(2470.0, -10.0, 12.0))
    return dataclasses.replace(w, time_limit=60.0, agents=(agent,),
                               corridors=(Corridor(((0.0, 0.0), (2500.0, 0.0)), 70.0),))


def time_runs(world, planner, repeats: int = 5) -> tuple[list[float], object]:
    scene = prepare(world)
    simulate(world, planner, scene=scene)                 # warm-up
    times, cpu, res = [], [], None
    for _ in range(repeats):
        t, c = time.perf_counter(), time.process_time()
        res = simulate(world, planner, scene=scene)
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    time_runs.cpu = min(cpu)
    return times, res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", default="1,2,3,4", help="sections to run (default 1,2,3,4)")
    ap.add_argument("--runs", type=int, default=1000, help="runs of section 5 (1000)")
    args = ap.parse_args()
    sections = {int(x) for x in args.only.split(",")}
    print(f"{platform.python_version()}, numpy {np.__version__}, {os.cpu_count()} CPUs, "
          f"load average {_load():.2f} at start")
    fuzzy = FuzzyPlanner(None, "drive")
    if 1 in sections:
        single_robot(fuzzy)
    if 2 in sections:
        print("\n2. one run, where the time goes")
        for name in ("slalom.yaml", "office.yaml"):
            one_run(load_world(packaged_path("worlds", name)), fuzzy)
    if 3 in sections:
        hundred_runs(fuzzy)
    if 4 in sections:
        batch_sizes(fuzzy)
    if 5 in sections:
        thousand_runs(fuzzy, args.runs)
    print(f"load average {_load():.2f} at the end")


def _load() -> float:
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")


def single_robot(fuzzy) -> None:
    world = long_corridor()
    times, res = time_runs(world, fuzzy)
    assert res.ticks == 1200, res.ticks
    best, med = min(times), statistics.median(times)
    print(f"\n1. one robot, {res.ticks} ticks (60 s at dt 0.05), outcome {res.outcome}")
    print(f"   fuzzy drive: best {best:.3f} s, median {med:.3f} s -> "
          f"{res.ticks / best:,.0f} ticks/s ({1e6 * best / res.ticks:.0f} us/tick); "
          f"CPU {time_runs.cpu:.3f} s")
    empty = dataclasses.replace(world, obstacles=())
    ftimes, fres = time_runs(empty, fuzzy)
    fcpu = time_runs.cpu
    ctimes, cres = time_runs(empty, Constant())
    ccpu = time_runs.cpu
    assert fres.ticks == cres.ticks == 1200
    fbest, cbest = min(ftimes), min(ctimes)
    print(f"   without the obstacle: fuzzy drive best {fbest:.3f} s (CPU {fcpu:.3f} s), "
          f"constant planner (no rules) best {cbest:.3f} s (CPU {ccpu:.3f} s, "
          f"{1e6 * ccpu / cres.ticks:.0f} us/tick)")
    timed = Timed(fuzzy)
    scene = prepare(world)
    t = time.perf_counter()
    simulate(world, timed, scene=scene)
    total = time.perf_counter() - t
    print(f"   rule evaluation (plan): {1e6 * timed.seconds / res.ticks:.0f} us/tick, "
          f"{100 * timed.seconds / total:.0f}% of the tick")
    print(f"   ratio fuzzy / constant loop (no obstacle, CPU): {fcpu / ccpu:.2f}x")


def hundred_runs(fuzzy) -> None:
    slalom = load_world(packaged_path("worlds", "slalom.yaml"))
    print("\n3. --runs 100 of slalom.yaml")
    walls = {}
    results = {}
    for workers in (1, 2):
        t, c0 = time.perf_counter(), os.times()
        runs = run_many([slalom], runs=100, seed=1, planner=fuzzy, workers=workers)
        walls[workers] = time.perf_counter() - t
        c1 = os.times()
        cpu = (c1.user - c0.user) + (c1.children_user - c0.children_user)
        results[workers] = runs.to_json()
        w = runs.worlds[0]
        ticks = sum(s["ticks"] for s in w.summaries)
        print(f"   {workers} worker(s): {walls[workers]:.1f} s wall, {cpu:.1f} s CPU (user, with "
              f"workers), {ticks} ticks, success {100 * w.rate('success'):.0f}%")
    assert results[1] == results[2], "results depend on the number of workers"
    print(f"   identical results with 1 and 2 workers; wall-time speed-up {walls[1] / walls[2]:.2f}x")


def batch_sizes(fuzzy) -> None:
    """Section 4: CPU time per robot-tick of runs stepped together, by batch size."""
    world = dataclasses.replace(load_world(packaged_path("worlds", "slalom.yaml")),
                                time_limit=2.0)
    scene = prepare(world)
    print("\n4. lockstep: slalom.yaml randomised, 2 simulated s a run, CPU time per robot-tick")
    seeds = list(range(16))
    c = time.process_time()
    alone = [simulate(world, fuzzy, s, randomise=True, scene=scene) for s in seeds]
    base = (time.process_time() - c) / sum(r.ticks * len(r.robot_outcomes) for r in alone)
    print(f"   16 runs, each alone (simulate): {1e6 * base:.0f} us per robot-tick")
    for size in (1, 16, 256, 1024):
        runs = list(range(max(size, 16)))
        c = time.process_time()
        res = run_lockstep(world, fuzzy, runs, randomise=True, scene=scene, batch=size)
        per = (time.process_time() - c) / sum(r.ticks * len(r.robot_outcomes) for r in res)
        for a, b in zip(alone, res):
            assert a.summary() == b.summary() and a.pose.tobytes() == b.pose.tobytes()
        print(f"   batch {size:5d} ({len(runs)} runs): {1e6 * per:.0f} us per robot-tick, "
              f"{base / per:.2f}x the runs alone")


def _alone(task) -> list[dict]:
    world, planner, seeds = task
    scene = prepare(world)
    return [simulate(world, planner, s, randomise=True, scene=scene).summary() for s in seeds]


def thousand_runs(fuzzy, n: int) -> None:
    """Section 5: ``n`` randomised slalom runs on 2 workers, in lockstep and one by one."""
    from concurrent.futures import ProcessPoolExecutor

    slalom = load_world(packaged_path("worlds", "slalom.yaml"))
    print(f"\n5. {n:,} randomised runs of slalom.yaml on 2 workers")
    t, c0 = time.perf_counter(), os.times()
    runs = run_many([slalom], runs=n, seed=1, planner=fuzzy, workers=2)
    wall, c1 = time.perf_counter() - t, os.times()
    together = list(runs.worlds[0].summaries)
    print(f"   run_many (lockstep in each worker): {wall:.1f} s wall, "
          f"{c1.children_user - c0.children_user + c1.user - c0.user:.1f} s CPU, "
          f"{sum(s['ticks'] for s in together):,} ticks; {_outcomes(together)}")
    seeds = [1 + j for j in range(n)]
    half = (n + 1) // 2
    t, c0 = time.perf_counter(), os.times()
    with ProcessPoolExecutor(2) as pool:
        parts = list(pool.map(_alone, [(slalom, fuzzy, seeds[:half]), (slalom, fuzzy, seeds[half:])]))
    wall_alone, c1 = time.perf_counter() - t, os.times()
    alone = parts[0] + parts[1]
    print(f"   one by one (simulate per run): {wall_alone:.1f} s wall, "
          f"{c1.children_user - c0.children_user + c1.user - c0.user:.1f} s CPU; "
          f"{_outcomes(alone)}")
    assert alone == together, "lockstep runs differ from the runs alone"
    print(f"   every summary equal; lockstep / one by one, wall: {wall_alone / wall:.2f}x faster; "
          f"1,000 runs at this pace: {wall * 1000 / n:.0f} s wall (aim 20 s: "
          f"{wall * 1000 / n / 20:.1f}x over)")


def _outcomes(summaries: list[dict]) -> str:
    counts = {o: sum(s["outcome"] == o for s in summaries) for o in
              ("success", "collision", "timeout", "stuck")}
    return ", ".join(f"{o} {k}" for o, k in counts.items())


if __name__ == "__main__":
    main()
