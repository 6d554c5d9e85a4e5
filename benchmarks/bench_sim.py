"""Simulator speed: simulated ticks per second for one robot, where the time goes, and the wall
time of ``--runs 100`` on one and two worker processes.

    python benchmarks/bench_sim.py                # sections 1-4, a few minutes on 2 cores
    python benchmarks/bench_sim.py --only 2,4 --against main   # this tree and main's, one process
    python benchmarks/bench_sim.py --only 5       # 1,000 randomised slalom runs, two ways
    python benchmarks/bench_sim.py --only 4,5 --runs 200
    python benchmarks/bench_sim.py --only 4 --seconds 0 --sizes 16,64 --against main  # full runs

1. **one robot, 60 simulated seconds at dt = 0.05** (1200 ticks): the packaged corridor world
   stretched to 2500 in so that the run never ends early; sensing (36 beams), perception, the
   fuzzy planner (behavior ``drive``, 55 rules), kinematics (4 substeps). Best and median of 5.
   Peers in the same run: the same loop with a constant planner (no rule evaluation) in the
   same corridor without its obstacle (the constant planner would hit it), and the planner's
   share of the tick measured by timing ``plan`` inside the loop. Times are wall times; the
   CPU time of the process is printed too (it is what a loaded machine distorts least).
2. **one run of ``slalom.yaml`` and of ``office.yaml``** (their own seeds, to the goal): ticks per
   second of CPU time (best of 5) against the aim of 5,000, and where a tick's time goes:
   each stage of :class:`~mitos_cli.sim.loop.Simulation` timed inside the loop (sense: beams,
   noise and clearance; map and route: what the robot marks and clears on its map, its
   replanning, the lookahead and its route's room; inputs: the rule inputs from the readings;
   check; plan: the rule evaluation; brake: the robot's own guard; act: the kinematics;
   record and the stuck check). With ``--against REV``: this tree and git revision ``REV``'s
   (imported as ``mitos_cli_rev``) in interleaved rounds of one process, best CPU time of
   each, and both must give the same run (summary and every pose).
3. **--runs 100** of ``slalom.yaml`` (randomised obstacles and noise) through ``run_many`` with
   1 and 2 workers; the two must give identical results.
4. **time per robot-tick in lockstep** (:mod:`mitos_cli.sim.lockstep`) at batch sizes 1, 16,
   256 and 1,024 (``--sizes``): that many randomised runs of ``slalom.yaml`` cut to 2 simulated
   seconds (40 ticks each; ``--seconds 0``: every run to its end, where its map holds more and
   its brake sweeps more cells: a robot-tick costs about 1.5x), stepped together, CPU time
   per robot-tick; the peer in the same run is the same 16 runs each simulated alone
   (``simulate``), and every batch's results must equal theirs.
   With ``--against REV``: REV's tree at the same batch sizes, rounds interleaved.
5. **1,000 randomised runs of ``slalom.yaml`` on 2 workers** (``--runs`` to change the number):
   ``run_many`` (each worker steps its runs in lockstep) against the runs simulated one by one
   on the same 2 processes; the outcome tables and every run's summary must be equal.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import importlib
import math
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from options import guarded, positive_int, revision
from revision import differs, foreign, package_of

from mitos_cli.resources import packaged_path
from mitos_cli.sim.lockstep import run_lockstep
from mitos_cli.sim.loop import Simulation, prepare, simulate
from mitos_cli.sim.planner import FuzzyPlanner
from mitos_cli.sim.runs import run_many
from mitos_cli.sim.world import Corridor, Goal, Randomise
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


STAGES = ("sense", "perceive", "sights", "check", "plan", "_guard", "act", "_record",
          "_check_stuck")
SHOWN = {"sense": "sense", "sights": "map and route", "perceive": "inputs", "check": "check",
         "plan": "plan", "_guard": "brake", "act": "act", "_record": "record",
         "_check_stuck": "stuck check"}


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
    print(f"   {world.name}: {ticks} ticks, {ticks / best_cpu:,.0f} ticks/s "
          f"({1e6 * best_cpu / ticks:.0f} us/tick, CPU, best of {repeats}; aim 5,000: "
          f"{ticks / best_cpu / 5000:.2f}x)")
    _stages(world, planner, scene)


def _stages(world, planner, scene) -> None:
    """Where a tick's time goes: each stage timed inside the loop (wall time; the map and
    route stage is inside the perception stage, shown apart)."""
    sim = StageTimed(world, planner, scene=scene)
    sim.seconds = {}
    t = time.perf_counter()
    while not sim.done:
        sim.step()
    total = time.perf_counter() - t
    spent = dict(sim.seconds)
    spent["perceive"] -= spent.get("sights", 0.0)
    shares = ", ".join(f"{SHOWN[name]} {1e6 * spent.get(name, 0.0) / sim.ticks:.0f} us "
                       f"({100 * spent.get(name, 0.0) / total:.0f}%)" for name in STAGES)
    print(f"     per tick: {shares}; loop total {1e6 * total / sim.ticks:.0f} us (wall)")


def against_runs(rev: str, theirs, planner_name: str = "drive", rounds: int = 7) -> None:
    """Section 2 against git revision ``rev``'s tree (the package ``theirs``): one run of each
    world by each tree in interleaved rounds, best CPU time of each; both give the same run."""
    setups = {}
    for name in ("slalom.yaml", "office.yaml"):
        for tree, pkg in (("this tree", "mitos_cli"), (rev, theirs.__name__)):
            wf = importlib.import_module(pkg + ".sim.worldfile")
            loop = importlib.import_module(pkg + ".sim.loop")
            world = wf.load_world(packaged_path("worlds", name))
            fuzzy = importlib.import_module(pkg + ".sim.planner").FuzzyPlanner(None, planner_name)
            scene = loop.prepare(world)
            setups[name, tree] = (loop, world, fuzzy, scene, loop.simulate(world, fuzzy,
                                                                           scene=scene))
        mine, old = setups[name, "this tree"][4], setups[name, rev][4]
        if mine.summary() != old.summary() or mine.pose.tobytes() != old.pose.tobytes():
            raise differs(f"{name}'s run", rev)         # before any round is timed
    best: dict[tuple[str, str], float] = {}
    for _ in range(rounds):
        for key, (loop, world, fuzzy, scene, _) in setups.items():
            c = time.process_time()
            loop.simulate(world, fuzzy, scene=scene)
            best[key] = min(best.get(key, math.inf), time.process_time() - c)
    for name in ("slalom.yaml", "office.yaml"):
        mine = setups[name, "this tree"][4]
        rates = {tree: mine.ticks / best[name, tree] for tree in ("this tree", rev)}
        print(f"   {name[:-5]}: {mine.ticks} ticks, this tree {rates['this tree']:,.0f} ticks/s "
              f"({1e6 / rates['this tree']:.0f} us/tick), {rev} {rates[rev]:,.0f} ticks/s "
              f"({1e6 / rates[rev]:.0f} us/tick): {rates['this tree'] / rates[rev]:.2f}x; "
              f"aim 5,000: {rates['this tree'] / 5000:.2f}x (CPU, best of {rounds} "
              f"interleaved rounds; the same run from both trees)")
        loop, world, fuzzy, scene, _ = setups[name, "this tree"]
        _stages(world, fuzzy, scene)


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


@guarded
def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", type=_sections, default="1,2,3,4",
                    help="sections to run, comma-separated, of 1-5 (default 1,2,3,4; 5 is the "
                         "1,000 runs)")
    ap.add_argument("--runs", type=positive_int, default=1000, help="runs of section 5 (1000)")
    ap.add_argument("--seconds", type=_seconds, default=2.0, help="section 4: simulated seconds a "
                    "run (2; 0: the world's own limit, every run to its end)")
    ap.add_argument("--sizes", type=_sizes, default="1,16,256,1024",
                    help="section 4: batch sizes, comma-separated")
    ap.add_argument("--against", metavar="REV", type=revision, help="sections 2 and 4: this tree and git "
                    "revision REV's, interleaved in one process")
    args = ap.parse_args(argv)
    sections = args.only
    if args.against and not sections & {2, 4}:      # it imported REV's tree and compared nothing
        ap.error(f"--against compares sections 2 and 4, and --only {_listed(sections)} has "
                 "neither")
    print(f"{platform.python_version()}, numpy {np.__version__}, {_cpus()}, "
          f"load average {_load():.2f} at start")
    fuzzy = FuzzyPlanner(None, "drive")
    with tempfile.TemporaryDirectory() as tmp, foreign(args.against):
        theirs = None
        if args.against:
            os.environ["MITOS_CACHE_DIR"] = "off"    # the cache pickles one tree's classes
            theirs = package_of(args.against, Path(tmp))
        if 1 in sections:
            single_robot(fuzzy)
        if 2 in sections:
            print("\n2. one run, where the time goes")
            if theirs is not None:
                against_runs(args.against, theirs)
            else:
                for name in ("slalom.yaml", "office.yaml"):
                    one_run(load_world(packaged_path("worlds", name)), fuzzy)
        if 3 in sections:
            hundred_runs(fuzzy)
        if 4 in sections:
            batch_sizes(fuzzy, args.against, theirs, args.seconds,
                        args.sizes)
        if 5 in sections:
            thousand_runs(fuzzy, args.runs)
    print(f"load average {_load():.2f} at the end")


def _sections(text: str) -> set[int]:
    """``--only``: section numbers of 1-5, comma-separated."""
    try:
        sections = {int(x) for x in text.split(",")}
    except ValueError:
        raise argparse.ArgumentTypeError(f"`{text}`: give section numbers, e.g. 1,2") from None
    if not sections <= {1, 2, 3, 4, 5}:
        raise argparse.ArgumentTypeError(f"`{text}`: the sections are 1 to 5")
    return sections


def _listed(sections: set[int]) -> str:
    return ",".join(map(str, sorted(sections)))


def _seconds(text: str) -> float:
    """``--seconds``: a finite number of simulated seconds, 0 or more."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"`{text}` is not a number of seconds") from None
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError(f"`{text}`: give 0 (every run to its end) or more "
                                         "simulated seconds")
    return value


def _sizes(text: str) -> list[int]:
    """``--sizes``: batch sizes of 1 or more, comma-separated."""
    try:
        sizes = [int(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"`{text}`: give batch sizes, e.g. 16,64") from None
    if min(sizes) < 1:
        raise argparse.ArgumentTypeError(f"`{text}`: each batch size must be at least 1")
    return sizes


def _cpus() -> str:
    model = platform.processor() or "unknown CPU"
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    return f"{os.cpu_count()} CPUs ({model})"


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
    empty = dataclasses.replace(world, obstacles=(), randomise=Randomise())   # nothing to jitter
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


def batch_sizes(fuzzy, rev: str | None = None, theirs=None, seconds: float = 2.0,
                sizes: list[int] | None = None) -> None:
    """Section 4: CPU time per robot-tick of runs stepped together, by batch size (with
    ``rev``: also its tree's, the two interleaved batch by batch). Runs of ``seconds``
    simulated seconds (0: to their end; the first seconds, in the open, cost the least)."""
    def cut(world):
        return dataclasses.replace(world, time_limit=seconds) if seconds else world

    world = cut(load_world(packaged_path("worlds", "slalom.yaml")))
    scene = prepare(world)
    length = f"{seconds:g} simulated s a run" if seconds else "every run to its end"
    print(f"\n4. lockstep: slalom.yaml randomised, {length}, CPU time per robot-tick")
    seeds = list(range(16))
    c = time.process_time()
    alone = [simulate(world, fuzzy, s, randomise=True, scene=scene) for s in seeds]
    base = (time.process_time() - c) / sum(r.ticks * len(r.robot_outcomes) for r in alone)
    print(f"   16 runs, each alone (simulate): {1e6 * base:.0f} us per robot-tick")
    old = None
    if theirs is not None:
        loop = importlib.import_module(theirs.__name__ + ".sim.loop")
        old_world = cut(importlib.import_module(theirs.__name__ + ".sim.worldfile")
                        .load_world(packaged_path("worlds", "slalom.yaml")))
        old = (importlib.import_module(theirs.__name__ + ".sim.lockstep").run_lockstep,
               old_world, importlib.import_module(theirs.__name__ + ".sim.planner")
               .FuzzyPlanner(None, "drive"), loop.prepare(old_world))
    for size in sizes or (1, 16, 256, 1024):
        runs = list(range(max(size, 16)))
        c = time.process_time()
        res = run_lockstep(world, fuzzy, runs, randomise=True, scene=scene, batch=size)
        per = (time.process_time() - c) / sum(r.ticks * len(r.robot_outcomes) for r in res)
        for a, b in zip(alone, res):
            assert a.summary() == b.summary() and a.pose.tobytes() == b.pose.tobytes()
        line = (f"   batch {size:5d} ({len(runs)} runs): {1e6 * per:.0f} us per robot-tick, "
                f"{base / per:.2f}x the runs alone")
        if old is not None:
            lockstep, old_world, old_fuzzy, old_scene = old
            c = time.process_time()
            theirs_res = lockstep(old_world, old_fuzzy, runs, randomise=True, scene=old_scene,
                                  batch=size)
            old_per = (time.process_time() - c) / sum(r.ticks * len(r.robot_outcomes)
                                                       for r in theirs_res)
            if [r.summary() for r in theirs_res] != [r.summary() for r in res]:
                raise differs(f"the batch of {size}'s runs", rev)
            # a ratio, not "slower": below 1 the other tree is the faster one
            line += f"; {rev}: {1e6 * old_per:.0f} us ({old_per / per:.2f}x this tree's, same runs)"
        print(line)


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
    sys.exit(main())
