"""Plot benchmark: computing a control surface, and the wall time of the `mitos plot` commands.

Run from the repository root (one command)::

    python benchmarks/bench_plot.py            # add --quick for a fast smoke run

It measures, in one run, on the packaged MITOS rule base (behavior ``avoid_obstacle``):

a. the data of a control surface, steering over road x position at size = 45 on an N x N grid
   (N = 201: 40,401 points): ``plotdata.surface`` (one vectorized engine batch), the same
   points one ``LoadedRuleBase.evaluate`` call each (what a loop over the grid costs), and
   pyfuzzylite on the same rules, vectorized ``Engine.process()`` and one point per call (the
   loop its users write for a surface). Every peer is checked to give the same grid first;
b. whole-process wall and CPU time (medians of repeated runs) of ``mitos plot terms`` drawn
   in the terminal (no matplotlib import), of the three plot commands writing a PNG, and of
   ``mitos eval`` for reference.

Figures go to stdout as a table; temporary PNGs are written to a temporary directory.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_core import _version, best_of, fmt_time, fuzzylite_engine, machine  # noqa: E402
from options import guarded  # noqa: E402
from peers import require  # noqa: E402

from mitos_cli import load_rulebase
from mitos_cli.draw import data as plotdata  # noqa: E402


def process_times(argv: list[str], runs: int) -> tuple[float, float]:
    """Median wall time and median CPU time (user + system) of a whole process. On a shared
    machine the CPU time is the steadier of the two: waiting for a core does not count."""
    import resource
    import statistics
    import subprocess

    subprocess.run(argv, check=True, capture_output=True)      # warm the file cache
    wall, cpu = [], []
    for _ in range(runs):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run(argv, check=True, capture_output=True)
        wall.append(time.perf_counter() - t0)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return statistics.median(wall), statistics.median(cpu)


@guarded
def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="small sizes, for a smoke run")
    args = ap.parse_args(argv)
    require("bench_plot.py", "fuzzylite", "matplotlib")
    n = 51 if args.quick else 201
    loop_n = 21 if args.quick else 61          # per-point loops run on a coarser grid
    repeats = 3 if args.quick else 5
    runs = 3 if args.quick else 7

    rb = load_rulebase(behavior="avoid_obstacle")
    c = rb.compiled

    def mitos_surface(k):
        return plotdata.surface(c, "steering", "road", "position", {"size": 45}, k)

    s = mitos_surface(n)
    gx, gy = np.meshgrid(s.x.values, s.y.values)
    X = np.column_stack([gx.ravel(), np.full(gx.size, 45.0), gy.ravel()])

    fl = fuzzylite_engine(rb)
    steer = c.outputs.index("steering")

    def fl_batch():
        fl.input_values = X
        fl.process()
        return np.asarray(fl.output_values)[:, steer]

    np.testing.assert_allclose(fl_batch(), s.z.ravel(), rtol=1e-12, atol=1e-9)

    coarse = mitos_surface(loop_n)
    cx, cy = np.meshgrid(coarse.x.values, coarse.y.values)
    points = list(zip(cx.ravel().tolist(), cy.ravel().tolist()))

    def mitos_loop():
        return [rb.evaluate(road=r, size=45.0, position=p)["steering"] for r, p in points]

    single = fuzzylite_engine(rb)         # a fresh engine: scalar inputs from the start
    road_v, size_v, pos_v = (single.input_variable(nm) for nm in c.inputs)
    steer_v = single.output_variable("steering")

    def fl_loop():
        out = []
        for r, p in points:
            road_v.value, size_v.value, pos_v.value = r, 45.0, p
            single.process()
            out.append(float(np.asarray(steer_v.value).reshape(-1)[0]))
        return out

    assert mitos_loop() == coarse.z.ravel().tolist()
    np.testing.assert_allclose(fl_loop(), coarse.z.ravel(), rtol=1e-12, atol=1e-9)

    t_batch = best_of(lambda: mitos_surface(n), repeats)
    t_fl_batch = best_of(fl_batch, max(2, repeats // 2))
    t_loop = best_of(mitos_loop, max(2, repeats // 2)) / len(points)
    t_fl_loop = best_of(fl_loop, max(2, repeats // 2)) / len(points)
    pts = n * n

    print(f"# bench_plot ({machine()}; pyfuzzylite {_version('fuzzylite')})")
    print()
    print(f"## a. control surface data: steering over road x position, {n} x {n} = {pts:,} "
          f"points")
    print()
    print("| how | time for the grid | per point | vs MITOS batch |")
    print("| --- | --- | --- | --- |")
    print(f"| MITOS `plotdata.surface` (one batch) | {fmt_time(t_batch)} | "
          f"{fmt_time(t_batch / pts)} | 1x |")
    print(f"| pyfuzzylite vectorized `process()` | {fmt_time(t_fl_batch)} | "
          f"{fmt_time(t_fl_batch / pts)} | {t_fl_batch / t_batch:.0f}x slower |")
    print(f"| MITOS, one `evaluate()` per point | {fmt_time(t_loop * pts)} (extrapolated) | "
          f"{fmt_time(t_loop)} | {t_loop * pts / t_batch:.0f}x slower |")
    print(f"| pyfuzzylite, one `process()` per point | {fmt_time(t_fl_loop * pts)} "
          f"(extrapolated) | {fmt_time(t_fl_loop)} | {t_fl_loop * pts / t_batch:.0f}x slower |")
    print()
    print(f"(per-point loops timed on a {loop_n} x {loop_n} grid; every method gives the same "
          f"grid, checked before timing)")

    exe = [sys.executable, "-m", "mitos_cli"]
    with tempfile.TemporaryDirectory() as tmp:
        png = str(Path(tmp) / "p.png")
        cases = [
            ("mitos eval road=78 size=45 position=4", ["eval", "road=78", "size=45",
                                                       "position=4"]),
            ("mitos plot terms -b avoid_obstacle (terminal)",
             ["plot", "terms", "-b", "avoid_obstacle", "--no-color"]),
            ("mitos plot surface (terminal table)",
             ["plot", "surface", "steering", "--x", "road", "--y", "position", "--fix",
              "size=45"]),
            ("mitos plot terms -b avoid_obstacle -o p.png",
             ["plot", "terms", "-b", "avoid_obstacle", "road=78", "size=45", "position=4",
              "-o", png]),
            ("mitos plot surface ... -o p.png (3-D, 61 x 61)",
             ["plot", "surface", "steering", "--x", "road", "--y", "position", "--fix",
              "size=45", "-o", png]),
            ("mitos plot surface ... --style heatmap -o p.png",
             ["plot", "surface", "steering", "--x", "road", "--y", "position", "--fix",
              "size=45", "--style", "heatmap", "-o", png]),
            ("mitos plot rules road=78 size=45 position=4 -o p.png",
             ["plot", "rules", "road=78", "size=45", "position=4", "-o", png]),
        ]
        times = [(label, *process_times(exe + argv, runs)) for label, argv in cases]
    base_cpu = times[0][2]
    print()
    print(f"## b. whole process, median of {runs} runs")
    print()
    print("| command | wall time | CPU time | CPU vs `mitos eval` |")
    print("| --- | --- | --- | --- |")
    for label, wall, cpu in times:
        print(f"| `{label}` | {fmt_time(wall)} | {fmt_time(cpu)} | {cpu / base_cpu:.1f}x |")


if __name__ == "__main__":
    t0 = time.perf_counter()
    code = main()
    print(f"\n(benchmark took {time.perf_counter() - t0:.0f} s)")
    sys.exit(code)
