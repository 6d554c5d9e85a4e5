"""Throughput of `mitos compare`: runs per second with 1 process, 2 processes, and Dask on a
2-worker LocalCluster, for one sweep of a shipped world (default: 1,000 runs of
worlds/corridor.yaml = 4 T-norms + the potential-field baseline x 200 seeded runs).

    python benchmarks/bench_compare.py                     # the full 1,000-run sweep
    python benchmarks/bench_compare.py --runs 40           # 5 x 40 = 200 runs (a fraction)

Each mode runs the same tasks through `run_study` (results.csv written and fsync'ed per row,
as the command does) in a fresh directory; the rows of every mode are checked to be equal
bit for bit. The Dask figure is given with and without the cluster's start-up; the cluster is
the command's own (mutual TLS on 127.0.0.1, see docs/security.md).

On a machine shared with other jobs wall-clock rates mostly measure the contention, so the
script also reports CPU seconds per run (this process and its reaped children: the pool's
workers, the Dask cluster's processes), which shows the executors' own overhead.
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import sys
import tempfile
import time
from pathlib import Path

from options import guarded, positive_int

ROOT = Path(__file__).resolve().parent.parent


def cpu_seconds() -> float:
    """User + system CPU of this process and of its finished children."""
    total = 0.0
    for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN):
        r = resource.getrusage(who)
        total += r.ru_utime + r.ru_stime
    return total


@guarded
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--world", default=str(ROOT / "worlds" / "corridor.yaml"))
    ap.add_argument("--runs", type=positive_int, default=200, help="runs per choice (5 choices)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--skip-dask", action="store_true")
    args = ap.parse_args(argv)

    from mitos_cli.sim.worldfile import load_world
    from mitos_cli.study import Study, make_choices, run_study

    load_world(args.world)          # a world it cannot read is said now, in one line

    choices = make_choices(["fuzzy", "potential_field"],
                           ["min", "product", "lukasiewicz", "einstein"], [], [])
    study = Study([args.world], choices, args.runs, args.seed)
    n = len(study.tasks())
    world = os.path.relpath(args.world, ROOT) if args.world.startswith(str(ROOT)) else args.world
    print(f"sweep: {world}, {len(choices)} choices x {args.runs} runs = {n} runs, "
          f"seed {args.seed}")
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"Python {platform.python_version()}, {platform.system()}")
    print(f"load average at start: {os.getloadavg()[0]:.2f} (1 min)")

    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        def timed(name, cpu=True, **kw):
            c0, t0 = cpu_seconds(), time.perf_counter()
            out = run_study(study, Path(tmp) / name, **kw)
            dt = time.perf_counter() - t0
            assert out.executed == n, (name, out.executed)
            results[name] = (dt, out.rows)
            used = f"   {1000 * (cpu_seconds() - c0) / n:6.0f} ms CPU/run" if cpu else ""
            print(f"  {name:<28} {dt:8.2f} s   {n / dt:8.1f} runs/s{used}", flush=True)
            return dt

        base = timed("1 process", workers=1)
        two = timed("2 processes (local)", workers=2)
        if not args.skip_dask:
            from distributed import Client

            from mitos_cli.study.executors import local_cluster

            c0, t0 = cpu_seconds(), time.perf_counter()
            # the cluster `mitos compare --executor dask` starts (mutual TLS, 127.0.0.1)
            with local_cluster(2) as cluster, \
                    Client(cluster, security=cluster.security) as client:
                start = time.perf_counter() - t0
                dask = timed("dask, 2-worker LocalCluster", cpu=False, executor="dask",
                             client=client)
            used = 1000 * (cpu_seconds() - c0) / n
            print(f"  {'  + cluster start-up':<28} {start:8.2f} s   "
                  f"{n / (dask + start):8.1f} runs/s including it   {used:6.0f} ms CPU/run "
                  f"(cluster processes included)")
    rows = [r for _dt, r in results.values()]
    same = all(r == rows[0] for r in rows[1:])
    print(f"load average at end: {os.getloadavg()[0]:.2f} (1 min)")
    print(f"rows identical across modes: {same}")
    print(f"speed-up vs 1 process: 2 processes {base / two:.2f}x"
          + (f", dask {base / dask:.2f}x" if not args.skip_dask else ""))
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
