"""How the packaged ``drive`` behavior fares in clutter it does not know: success, collision,
timeout and stuck rates over seeded BARN-style worlds (mitos_cli.sim.barn) and over the shipped
worlds, with the obstacles unknown (only the range readings show them) or known (in the map).

    python benchmarks/bench_drive.py --barn 100 --seed 1000      # the reported range
    python benchmarks/bench_drive.py --barn 50 --seed 0 --known  # poles drawn in the map
    python benchmarks/bench_drive.py --shipped --runs 20          # worlds/*.yaml
    python benchmarks/bench_drive.py --barn 20 --rules my.rules   # another rule base

Seeds 0-39 were used while the clutter rules were written; report on 1000 and up. Seeds 1000
and 2000 have since been run after each change to the planner, so neither is wholly unseen:
docs/navigation.md says what was measured on which.
"""

from __future__ import annotations

import argparse
import collections
import platform
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # this source tree first

from options import count, guarded, positive_int  # noqa: E402

from mitos_cli.resources import packaged_path  # noqa: E402
from mitos_cli.sim import barn  # noqa: E402
from mitos_cli.sim.planner import FuzzyPlanner  # noqa: E402
from mitos_cli.sim.runs import run_many  # noqa: E402
from mitos_cli.sim.worldfile import load_world  # noqa: E402

OUTCOMES = ("success", "collision", "timeout", "stuck")


def rates(summaries: list[dict]) -> str:
    n = len(summaries)
    count = collections.Counter(s["outcome"] for s in summaries)
    ok = [s["time_s"] for s in summaries if s["outcome"] == "success"]
    mean_t = f"{sum(ok) / len(ok):5.1f} s" if ok else "  -   (no run reached it)"
    return (f"{n:4d} runs  " + "  ".join(f"{o} {count[o] / n:5.3f}" for o in OUTCOMES)
            + f"  mean time to goal {mean_t}")


@guarded
def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--barn", type=count, default=0, help="BARN-style worlds to run")
    ap.add_argument("--seed", type=int, help="first BARN seed (1000)")
    ap.add_argument("--known", action="store_true", help="poles drawn in the robot's map")
    ap.add_argument("--shipped", action="store_true", help="the shipped worlds")
    ap.add_argument("--runs", type=positive_int, help="randomised runs per shipped world (20)")
    ap.add_argument("--rules", help="rule file (default: the packaged rule base)")
    ap.add_argument("--workers", type=positive_int)
    ap.add_argument("--show", action="store_true", help="print each failed run")
    args = ap.parse_args(argv)
    if not args.barn and not args.shipped:
        ap.error("nothing to run: give --barn N (BARN-style worlds) or --shipped")
    for given, option, needs in ((args.seed is not None, "--seed", args.barn),
                                 (args.known, "--known", args.barn),
                                 (args.show, "--show", args.barn),
                                 (args.runs is not None, "--runs", args.shipped)):
        if given and not needs:     # (each was dropped without a word)
            ap.error(f"{option} is for {'--barn N' if option != '--runs' else '--shipped'}")
    args.seed = 1000 if args.seed is None else args.seed
    args.runs = args.runs or 20
    planner = FuzzyPlanner(args.rules, "drive")
    print(f"# {platform.processor() or platform.machine()}, Python {platform.python_version()}")
    if args.barn:
        t0 = time.perf_counter()
        worlds = barn.barn_worlds(args.barn, args.seed, known=args.known)
        t1 = time.perf_counter()
        res = run_many(worlds, planner=planner, workers=args.workers)
        t2 = time.perf_counter()
        runs = [w.summaries[0] for w in res.worlds]
        kind = "known" if args.known else "unknown"
        print(f"BARN-style, poles {kind}, seeds {args.seed}-{args.seed + args.barn - 1}: "
              f"{rates(runs)}")
        print(f"  (generated in {t1 - t0:.1f} s, run in {t2 - t1:.1f} s, "
              f"{sum(s['ticks'] for s in runs) / (t2 - t1):.0f} ticks/s over all workers)")
        if args.show:
            for s in runs:
                if s["outcome"] != "success":
                    print(f"  {s['world']}: {s['outcome']} at {s['time_s']:.2f} s, "
                          f"{s['path_length_in']:.0f} in driven")
    if args.shipped:
        names = ["corridor", "slalom", "moving", "intersection", "multirobot", "office",
                 "figure4"]
        worlds = [load_world(packaged_path("worlds", f"{n}.yaml")) for n in names]
        own = run_many(worlds, planner=planner, workers=args.workers)
        many = run_many(worlds, runs=args.runs, planner=planner, workers=args.workers)
        for w, r in zip(own.worlds, many.worlds):
            print(f"{w.world:14s} own seed: {w.summaries[0]['outcome']:9s} "
                  f"--runs {args.runs}: {rates(list(r.summaries))}")


if __name__ == "__main__":
    sys.exit(main())
