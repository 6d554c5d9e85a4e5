"""Exported code and foreign readers: how fast they are, against MITOS's engine and pyfuzzylite.

Run from the repository root (about a minute):

    python benchmarks/bench_export.py

For two rule bases — MITOS's own (`avoid_obstacle`: 27 rules, min / weighted average) and
MATLAB's tipper read from `tests/data/interop/tipper.fis` (Mamdani, centroid on 101 samples) —
it times, on the same 10^5 random inputs, best of 5 after a warm-up:

- MITOS's batch engine (`evaluate(..., detail=False)`),
- the exported NumPy module (`mitos export --to python`, `evaluate(X)`),
- the exported C (`mitos export --to c`, compiled `cc -std=c99 -O2`, one call per sample in a
  loop, timed inside the C program with `clock()`),
- pyfuzzylite 8's vectorized engine on the same system written by MITOS's FLL writer (best
  of 3),

after checking that all four compute the same outputs. Then one sample at a time, as a
robot's control loop calls them (median of 2,000 calls over the first inputs): MITOS's
``load_rulebase().evaluate(**inputs)``, the exported module's ``evaluate_one(**inputs)`` (the
same bits as its ``evaluate`` row, checked on each sample) and pyfuzzylite's ``process()`` on
scalar values. It also times reading each file (the FCL, FIS and FLL readers, parse to
checked model) against pyfuzzylite's FLL importer.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).parents[1]
sys.path.insert(0, str(ROOT))

from options import guarded  # noqa: E402
from peers import require  # noqa: E402

from mitos_cli.api import load_rulebase, read_rulebase  # noqa: E402
from mitos_cli.engine.evaluation import evaluate  # noqa: E402
from mitos_cli.interop import write_foreign  # noqa: E402
from mitos_cli.interop.export import to_c, to_python  # noqa: E402

N = 100_000
REPEATS = 5
ONE = 2000          # samples timed one at a time

DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
int bench_eval(const double *in, double *out);
int main(int argc, char **argv) {
    int n = atoi(argv[1]), k = atoi(argv[2]), m = atoi(argv[3]), rep, i, j;
    double *X = malloc(sizeof(double) * n * k), *Y = malloc(sizeof(double) * n * m);
    double best = 1e30, check = 0.0;
    FILE *f = fopen(argv[4], "rb");
    if (fread(X, sizeof(double), (size_t)n * k, f) != (size_t)n * k) return 1;
    fclose(f);
    for (rep = 0; rep < 6; ++rep) {
        clock_t t0 = clock();
        for (i = 0; i < n; ++i) bench_eval(X + (size_t)i * k, Y + (size_t)i * m);
        double dt = (double)(clock() - t0) / CLOCKS_PER_SEC;
        if (rep > 0 && dt < best) best = dt;
    }
    f = fopen(argv[5], "wb");
    fwrite(Y, sizeof(double), (size_t)n * m, f);
    fclose(f);
    for (j = 0; j < n * m; ++j) check += Y[j] == Y[j] ? Y[j] : 0.0;
    printf("%.9f %.17g\n", best, check);
    return 0;
}
"""


def best_of(fn, repeats: int = REPEATS) -> float:
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def bench(label: str, path: Path, tmp: Path) -> None:
    rb = load_rulebase(path)
    c = rb.compiled
    rng = np.random.default_rng(np.random.SeedSequence(2026).spawn(1)[0])
    X = rng.uniform(c.universe[:, 0], c.universe[:, 1], size=(N, len(c.inputs)))
    want = evaluate(c, X, detail=False, strict=False).outputs
    t_engine = best_of(lambda: evaluate(c, X, detail=False, strict=False))

    module_path = tmp / f"{label}_exported.py"
    module_path.write_text(to_python(c, path.name))
    spec = importlib.util.spec_from_file_location(f"{label}_exported", module_path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert np.allclose(module.evaluate(X), want, rtol=0, atol=1e-9, equal_nan=True)
    t_python = best_of(lambda: module.evaluate(X))

    cc = shutil.which("cc") or shutil.which("gcc")
    t_c = None
    if cc:
        (tmp / "m.c").write_text(to_c(c, "bench", path.name))
        (tmp / "d.c").write_text(DRIVER)
        subprocess.run([cc, "-std=c99", "-O2", "-o", str(tmp / "b"), str(tmp / "m.c"),
                        str(tmp / "d.c"), "-lm"], check=True)
        X.tofile(tmp / "x.bin")
        out = subprocess.run([str(tmp / "b"), str(N), str(len(c.inputs)), str(len(c.outputs)),
                              str(tmp / "x.bin"), str(tmp / "y.bin")], capture_output=True,
                             text=True, check=True).stdout.split()
        t_c = float(out[0])
        got = np.fromfile(tmp / "y.bin").reshape(N, len(c.outputs))
        assert np.allclose(got, want, rtol=0, atol=1e-9, equal_nan=True)

    import fuzzylite as fl

    engine = fl.FllImporter().from_string(write_foreign(rb.rulebase, "fll"))

    def run_fl():
        for i, name in enumerate(c.inputs):
            engine.input_variable(name).value = X[:, i]
        engine.process()
        return np.column_stack([np.asarray(engine.output_variable(o).value, dtype=float)
                                for o in c.outputs])

    theirs = run_fl()
    # the same system: pyfuzzylite samples Mamdani outputs at midpoints, a .fis at
    # MATLAB's end points, so only the weighted-average rule base is compared exactly
    if c.operators.inference != "mamdani":
        assert np.allclose(theirs, want, rtol=0, atol=1e-9, equal_nan=True)
    t_fl = best_of(run_fl, 3)

    singles = bench_one(rb, module, engine, X[:ONE])
    print(f"\n{label} ({path.relative_to(ROOT)}; {c.n_rules} rules, {c.operators.describe()})")
    print(f"  {'implementation':34s} {'total s':>9s} {'us/sample':>10s} {'vs engine':>10s}")
    for name, t in (("MITOS engine (batch)", t_engine), ("exported NumPy module (batch)", t_python),
                    ("exported C (one call per sample)", t_c),
                    ("pyfuzzylite 8 (vectorized)", t_fl)):
        if t is None:
            print(f"  {name:34s} not timed: no C compiler (cc or gcc) on PATH")
        else:
            print(f"  {name:34s} {t:9.4f} {1e6 * t / N:10.3f} {ratio_text(t_engine / t):>9s}x")
    print(f"  {'one sample at a time':34s} {'':>9s} {'us/call':>10s} {'vs engine':>10s}")
    for name, t in singles.items():
        print(f"  {name:34s} {'':>9s} {1e6 * t:10.2f} "
              f"{ratio_text(singles['MITOS evaluate(**inputs)'] / t):>9s}x")


def ratio_text(ratio: float) -> str:
    """A ratio to the engine, two decimals, or two significant digits below 0.1: pyfuzzylite
    on scalars, some 500 times slower, read 0.00x."""
    return f"{ratio:.2f}" if ratio >= 0.1 else f"{ratio:.2g}"


def bench_one(rb, module, engine, X: np.ndarray) -> dict[str, float]:
    """Median seconds a call, one sample at a time: MITOS, the exported ``evaluate_one`` (its
    outputs checked against its ``evaluate`` row, bit for bit) and pyfuzzylite on scalars."""
    rows = [dict(zip(rb.inputs, map(float, x))) for x in X]
    for row, want in zip(rows, module.evaluate(X)):
        assert np.array(list(module.evaluate_one(**row).values())).tobytes() == want.tobytes()

    def fl_one(row: dict) -> None:
        for name, v in row.items():
            engine.input_variable(name).value = v
        engine.process()

    calls = {"MITOS evaluate(**inputs)": lambda row: rb.evaluate(**row),
             "exported evaluate_one(**inputs)": lambda row: module.evaluate_one(**row),
             "pyfuzzylite 8 process() on scalars": fl_one}
    out = {}
    for name, call in calls.items():
        times = []
        for row in rows:
            t0 = time.perf_counter()
            call(row)
            times.append(time.perf_counter() - t0)
        out[name] = float(np.median(times))
    return out


def bench_readers(tmp: Path) -> None:
    import fuzzylite as fl

    data = ROOT / "tests" / "data" / "interop"
    fll = tmp / "mitos.fll"
    fll.write_text(write_foreign(read_rulebase(ROOT / "rulebases" / "mitos.rules"), "fll"))
    print("\nreading a file into a checked model (best of 20, ms)")
    for path in (data / "tipper.fis", data / "tipper_jfuzzylogic.fcl", fll):
        t = best_of(lambda: read_rulebase(path), 20)
        print(f"  MITOS {path.suffix:5s} {path.name:28s} {1e3 * t:8.2f}")
    text = fll.read_text()
    t = best_of(lambda: fl.FllImporter().from_string(text), 20)
    print(f"  pyfuzzylite .fll {fll.name:22s} {1e3 * t:8.2f}")


@guarded
def main(argv: list[str] | None = None) -> None:
    argparse.ArgumentParser(description=__doc__,
                            formatter_class=argparse.RawDescriptionHelpFormatter).parse_args(argv)
    require("bench_export.py", "fuzzylite")
    print(f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f}, NumPy "
          f"{np.__version__}, n = {N}")
    with tempfile.TemporaryDirectory() as tmp:
        bench("mitos", ROOT / "rulebases" / "mitos.rules", Path(tmp))
        bench("tipper", ROOT / "tests" / "data" / "interop" / "tipper.fis", Path(tmp))
        bench_readers(Path(tmp))


if __name__ == "__main__":
    sys.exit(main())
