"""Core engine benchmark: MITOS against a hand-written NumPy kernel, pyfuzzylite and simpful.

Run from the repository root (one command)::

    python benchmarks/bench_core.py            # add --quick for a fast smoke run
    python benchmarks/bench_core.py --startup  # only (c), 21 alternating runs of each
    python benchmarks/bench_core.py --against main  # this tree against main's, one process

It measures, in one run, on the packaged MITOS rule base (behavior ``avoid_obstacle``, the
paper's 27 rules):

a. batch throughput on 10^6 random inputs (best of 10 rounds that call each in turn):
``engine.evaluate`` with ``detail=True`` (memberships
   and DOFs kept) and ``detail=False`` (outputs only), ``load_rulebase().evaluate(**columns)``
   (arrays by name), a hand-written NumPy kernel for exactly this rule base, and pyfuzzylite
   8's vectorized ``Engine.process()`` on the same rules; and the peak memory NumPy allocates
   in one call of ``evaluate(**columns)`` and of the kernel (tracemalloc);
b. single-evaluation latency: ``load_rulebase().evaluate(road=..., size=..., position=...)``
   (the network's scalar form, :mod:`mitos_cli.engine.scalar`), the engine's array entry point with
   one row (``evaluate(compiled, X[i:i+1], detail=False)``, the same scalar form plus the
   ``Result`` arrays) and with memberships and DOFs (``detail=True``: the NumPy path, what the
   trace of ``mitos eval`` uses); pyfuzzylite (set three inputs, ``process()``, read two
   outputs) and simpful (``set_variable`` x3, ``Sugeno_inference``);
c. whole-process time of ``mitos eval road=78 size=45 position=4`` against
   ``python -c "import numpy"`` (median of repeated runs).

Every peer is checked to compute the same outputs as MITOS before it is timed. Throughput is
the best of several repeats after a warm-up; latency the median over repeats of the mean time
per call. Figures go to stdout as a table; nothing is written to disk.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from options import guarded, revision
from peers import require
from revision import differs, foreign, package_of

from mitos_cli import load_rulebase
from mitos_cli.engine.evaluation import evaluate

SEED = 20240611


# ---------------------------------------------------------------------------------------------
# the hand-written NumPy kernel for exactly this rule base

class PaperKernel:
    """The 27-rule MITOS base written out by hand: three inputs with three terms each (left
    shoulder, eq. 15 triangle, right shoulder), DOF = min of three memberships for every
    combination, outputs = DOF-weighted averages of crisp consequents. Blocks of samples keep
    the working set in cache. The consequent table is read from the rule base once."""

    def __init__(self, rb, block: int = 16384) -> None:
        c = rb.compiled
        assert c.inputs == ("road", "size", "position") and c.n_rules == 27
        self.block = block
        variables = c.variables
        self.params = []                       # per input: (lo, hi, shoulder/triangle corners)
        for name in c.inputs:
            v = variables[name]
            left, mid, right = v.terms
            assert (left.shape, mid.shape, right.shape) == ("left_shoulder", "triangle_pw",
                                                          "right_shoulder")
            self.params.append((v.universe, left.params, mid.params, right.params))
        # K[o, i, j, k]: consequent value of output o for road term i, size term j, position
        # term k; row 2 holds ones (the denominator)
        K = np.zeros((3, 3, 3, 3))
        names = [[t.name for t in variables[n].terms] for n in c.inputs]
        for r, rule in enumerate(c.rules):
            terms = {p.var: p.term for p in rule.antecedent.items}
            i, j, k = (names[d].index(terms[n]) for d, n in enumerate(c.inputs))
            K[0, i, j, k], K[1, i, j, k] = c.cons_value[r]
            K[2, i, j, k] = 1.0
        self.K = K.reshape(3, 27)

    @staticmethod
    def _terms(x: np.ndarray, p) -> np.ndarray:
        (lo, hi), (la, lb), (peak, width), (ra, rb) = p
        x = np.clip(x, lo, hi)
        mu = np.empty((3,) + x.shape)
        np.clip((lb - x) / (lb - la), 0.0, 1.0, out=mu[0])
        np.clip(1.0 - np.abs(peak - x) / width, 0.0, None, out=mu[1])
        np.clip((x - ra) / (rb - ra), 0.0, 1.0, out=mu[2])
        return mu

    def __call__(self, X: np.ndarray) -> np.ndarray:
        n = X.shape[0]
        out = np.empty((n, 2))
        Xt = np.ascontiguousarray(X.T)
        for s in range(0, n, self.block):
            e = min(s + self.block, n)
            road, size, pos = (self._terms(Xt[d, s:e], self.params[d]) for d in range(3))
            rs = np.minimum(road[:, None, :], size[None, :, :])           # [3, 3, b]
            dof = np.minimum(rs[:, :, None, :], pos[None, None, :, :])     # [3, 3, 3, b]
            sums = self.K @ dof.reshape(27, e - s)                          # [3, b]
            out[s:e] = (sums[:2] / sums[2]).T
        return out


# ---------------------------------------------------------------------------------------------
# peers built from the same rule base

def fuzzylite_engine(rb):
    import fuzzylite as fl

    c = rb.compiled

    def term(t):
        if t.shape == "left_shoulder":
            return fl.Ramp(t.name, t.params[1], t.params[0])
        if t.shape == "right_shoulder":
            return fl.Ramp(t.name, t.params[0], t.params[1])
        if t.shape == "triangle_pw":
            peak, width = t.params
            return fl.Triangle(t.name, peak - width, peak, peak + width)
        raise ValueError(t.shape)

    inputs = [fl.InputVariable(name=n, minimum=c.variables[n].universe[0],
                               maximum=c.variables[n].universe[1], lock_range=True,
                               terms=[term(t) for t in c.variables[n].terms])
              for n in c.inputs]
    outputs = [fl.OutputVariable(name=n, minimum=c.variables[n].universe[0],
                                 maximum=c.variables[n].universe[1], lock_range=False,
                                 lock_previous=False, default_value=fl.nan, aggregation=None,
                                 defuzzifier=fl.WeightedAverage(type="TakagiSugeno"),
                                 terms=[fl.Constant(t.name, t.center)
                                        for t in c.variables[n].terms])
               for n in c.outputs]
    engine = fl.Engine(name="mitos", input_variables=inputs, output_variables=outputs,
                       rule_blocks=[fl.RuleBlock(
                           name="avoid_obstacle", conjunction=fl.Minimum(),
                           disjunction=fl.Maximum(), implication=None, activation=fl.General(),
                           rules=[])])
    block = engine.rule_blocks[0]
    for r in range(c.n_rules):
        block.rules.append(fl.Rule.create(c.rule_text(r), engine))
    return engine


def simpful_system(rb):
    from simpful import FuzzySet, FuzzySystem, LinguisticVariable, Trapezoidal_MF, Triangular_MF

    c = rb.compiled
    fs = FuzzySystem(show_banner=False)
    for n in c.inputs:
        v = c.variables[n]
        lo, hi = v.universe
        sets = []
        for t in v.terms:
            if t.shape == "left_shoulder":
                mf = Trapezoidal_MF(lo - 1.0, lo - 1.0, t.params[0], t.params[1])
            elif t.shape == "right_shoulder":
                mf = Trapezoidal_MF(t.params[0], t.params[1], hi + 1.0, hi + 1.0)
            else:
                peak, width = t.params
                mf = Triangular_MF(peak - width, peak, peak + width)
            sets.append(FuzzySet(function=mf, term=t.name))
        fs.add_linguistic_variable(n, LinguisticVariable(sets, universe_of_discourse=[lo, hi]))
    for n in c.outputs:
        for t in c.variables[n].terms:
            fs.set_crisp_output_value(f"{n}_{t.name}", t.center)
    rules = []
    for rule in c.rules:            # simpful: one consequent per rule
        cond = " AND ".join(f"({p.var} IS {p.term})" for p in rule.antecedent.items)
        for cons in rule.consequents:
            rules.append(f"IF {cond} THEN ({cons.var} IS {cons.var}_{cons.term})")
    fs.add_rules(rules)
    return fs


# ---------------------------------------------------------------------------------------------
# timing helpers

#: Calls of one function in a row within a round; the first is not timed. The call after
#: another function's pays for it: OpenBLAS's threads spin for a while after the kernel's
#: product, so the batch timed next had one core (86-119 ms against 64-70 ms on 2 cores).
CALLS = 3


def in_a_row(fn, calls: int = CALLS) -> tuple[float, float]:
    """The best wall and CPU seconds of the calls of ``fn`` after the first of ``calls`` in a
    row."""
    fn()
    wall = cpu = float("inf")
    for _ in range(calls - 1):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        cpu = min(cpu, time.process_time() - c0)
        wall = min(wall, time.perf_counter() - t0)
    return wall, cpu


def interleaved_best(fns: dict, repeats: int) -> dict:
    """Best time of each function over ``repeats`` rounds that call every one in turn (each
    :data:`CALLS` times in a row, :func:`in_a_row`), so a machine whose load changes during
    the run slows each of them alike (the ratios are what the benchmark reports)."""
    best = {name: float("inf") for name in fns}
    for _ in range(repeats):
        for name, fn in fns.items():
            best[name] = min(best[name], in_a_row(fn)[0])
    return best


def best_of(fn, repeats: int) -> float:
    fn()                                           # warm-up
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def per_call(fn, args, repeats: int) -> float:
    """Median over ``repeats`` of the mean seconds per call of ``fn(*a)`` over ``args``."""
    for a in args[:50]:
        fn(*a)
    means = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for a in args:
            fn(*a)
        means.append((time.perf_counter() - t0) / len(args))
    return statistics.median(means)


def peak_memory(fn) -> int:
    """Bytes NumPy allocated at the peak of one call (tracemalloc sees NumPy's buffers)."""
    import tracemalloc

    fn()
    tracemalloc.start()
    try:
        result = fn()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    del result
    return peak


def process_time(argv: list[str], runs: int) -> float:
    # As installed: Python may write and use byte code (an inherited PYTHONDONTWRITEBYTECODE
    # would make every run recompile MITOS's sources, which no installed copy does).
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    subprocess.run(argv, check=True, capture_output=True, env=env)   # byte code, file cache
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        subprocess.run(argv, check=True, capture_output=True, env=env)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def startup(runs: int) -> None:
    """(c) alone, the two commands alternating so that the machine's drift hits both alike."""
    mitos = str(Path(sys.executable).parent / "mitos")
    commands = {"mitos": [mitos, "eval", "road=78", "size=45", "position=4"],
                "numpy": [sys.executable, "-c", "import numpy"]}
    times: dict[str, list[float]] = {k: [] for k in commands}
    for _ in range(runs):
        for name, argv in commands.items():
            times[name].append(process_time(argv, 1))
    t_eval, t_numpy = (statistics.median(times[k]) for k in commands)
    print(f"# MITOS start-up ({time.strftime('%Y-%m-%d')}), {machine()}")
    print(f"command: python benchmarks/bench_core.py --startup (median of {runs} alternating runs)")
    print(f"| `mitos eval road=78 size=45 position=4` (whole process) | {fmt_time(t_eval)} | "
          f"{t_eval / t_numpy:.2f}x `python -c \"import numpy\"` |")
    print(f"| `python -c \"import numpy\"` (whole process) | {fmt_time(t_numpy)} | |")


def against(rev: str, quick: bool = False) -> None:
    """This tree's column batch (``load_rulebase().evaluate(**columns)``) against ``rev``'s and
    the kernel, interleaved in one process (best of the rounds, wall and CPU time); peak memory
    of each; one evaluation by name (median of rounds that alternate the two trees); and the
    whole-process start-up of ``mitos eval`` from each tree against ``import numpy``
    (alternating runs, ``rev``'s tree first on ``PYTHONPATH``, run outside the repository)."""
    import tempfile

    host = machine()
    n, rounds, single_n, runs = (10**5, 5, 200, 5) if quick else (10**6, 20, 2000, 21)
    with tempfile.TemporaryDirectory() as tmp, foreign(rev):
        theirs = package_of(rev, Path(tmp), ("mitos_cli", "rulebases", "grammar"))
        saved = os.environ.get("MITOS_CACHE_DIR")
        os.environ["MITOS_CACHE_DIR"] = "off"    # the cache pickles this tree's classes
        try:
            old = theirs.load_rulebase()
        finally:
            os.environ.pop("MITOS_CACHE_DIR")
            if saved is not None:
                os.environ["MITOS_CACHE_DIR"] = saved
        rb = load_rulebase()
        c = rb.compiled
        rng = np.random.default_rng(np.random.SeedSequence(SEED))
        X = rng.uniform(c.universe[:, 0], c.universe[:, 1], size=(n, len(c.inputs)))
        columns = {name: np.ascontiguousarray(X[:, j]) for j, name in enumerate(c.inputs)}
        kernel = PaperKernel(rb)
        a, b = old.evaluate(**columns), rb.evaluate(**columns)
        if not all(np.array_equal(a[o].view(np.uint64), b[o].view(np.uint64))
                   for o in c.outputs):
            raise differs("the packaged rule base's column batch", rev)
        fns = {"kernel": lambda: kernel(X), rev: lambda: old.evaluate(**columns),
               "this tree": lambda: rb.evaluate(**columns)}
        # the allocator as the default run leaves it, whose first call is the traced batch:
        # at 10^5 rows (--quick) the kernel, timed first, paged in every temporary afresh and
        # read 2.2-3.2x slower than after it (0.95-1.00x)
        evaluate(c, X, detail=True)
        wall = {k: float("inf") for k in fns}
        cpu = dict(wall)
        for _ in range(rounds):
            for name, fn in fns.items():
                w, cp = in_a_row(fn)
                cpu[name], wall[name] = min(cpu[name], cp), min(wall[name], w)
        memory = {name: peak_memory(fn) for name, fn in fns.items()}

        pts = [tuple(map(float, x)) for x in X[:single_n]]
        single: dict[str, list[float]] = {rev: [], "this tree": []}
        for _ in range(rounds):
            for name, loaded in ((rev, old), ("this tree", rb)):
                ev = loaded.evaluate
                t0 = time.perf_counter()
                for r, s_, p in pts:
                    ev(road=r, size=s_, position=p)
                single[name].append((time.perf_counter() - t0) / len(pts))

        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        code = "import sys; from mitos_cli.cli.app import main; sys.argv[0] = 'mitos'; sys.exit(main())"
        evalargs = ["eval", "road=78", "size=45", "position=4"]
        commands = {rev: ([sys.executable, "-c", code, *evalargs], dict(env, PYTHONPATH=tmp)),
                    "this tree": ([sys.executable, "-c", code, *evalargs],
                                  dict(env, PYTHONPATH=str(Path(__file__).resolve().parents[1]))),
                    "numpy": ([sys.executable, "-c", "import numpy"], env)}
        printed = {k: subprocess.run(argv, check=True, capture_output=True, env=e, cwd=tmp).stdout
                   for k, (argv, e) in commands.items()}
        assert printed[rev] == printed["this tree"]
        times: dict[str, list[float]] = {k: [] for k in commands}
        for _ in range(runs):
            for name, (argv, e) in commands.items():
                t0 = time.perf_counter()
                subprocess.run(argv, check=True, capture_output=True, env=e, cwd=tmp)
                times[name].append(time.perf_counter() - t0)

    print(f"# MITOS core benchmark against {rev} ({time.strftime('%Y-%m-%d')})")
    print(f"machine: {host}")
    print(_threads())
    print(f"command: python benchmarks/bench_core.py --against {rev}{' --quick' if quick else ''}")
    print(f"batch: {n:,} random inputs, best of {rounds} interleaved rounds of {CALLS} calls in a "
          f"row, the first untimed (wall; CPU time of the process in brackets); single: median "
          f"of {rounds} alternating rounds of {single_n} calls; "
          f"process: median of {runs} alternating runs\n")
    print(f"| measurement | {rev} | this tree |")
    print("| --- | ---: | ---: |")
    for label, key in (("batch, `load_rulebase().evaluate(**columns)` / kernel", "ratio"),
                       ("batch, eval/s", "rate"), ("peak extra memory / kernel's", "mem")):
        cells = []
        for name in (rev, "this tree"):
            if key == "ratio":
                cells.append(f"{wall['kernel'] / wall[name]:.2f}x ({cpu['kernel'] / cpu[name]:.2f}x)")
            elif key == "rate":
                cells.append(f"{fmt_rate(n / wall[name])} ({fmt_rate(n / cpu[name])})")
            else:
                cells.append(f"{memory[name] / 1e6:.1f} / {memory['kernel'] / 1e6:.1f} MB "
                             f"({memory[name] / memory['kernel']:.2f}x)")
        print(f"| {label} | {cells[0]} | {cells[1]} |")
    print(f"| hand-written kernel, eval/s | {fmt_rate(n / wall['kernel'])} "
          f"({fmt_rate(n / cpu['kernel'])}) | |")
    print(f"| one evaluation, `load_rulebase().evaluate(road=..., ...)` | "
          f"{fmt_time(statistics.median(single[rev]))} | "
          f"{fmt_time(statistics.median(single['this tree']))} |")
    med = {k: statistics.median(v) for k, v in times.items()}
    print(f"| `mitos eval road=78 size=45 position=4` / `python -c \"import numpy\"` | "
          f"{med[rev] / med['numpy']:.2f}x ({fmt_time(med[rev])}) | "
          f"{med['this tree'] / med['numpy']:.2f}x ({fmt_time(med['this tree'])}) |")
    print(f"\n{_load()} at the end")


def machine() -> str:
    model = platform.processor() or "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return (f"{os.cpu_count()} CPUs ({model}), Python {platform.python_version()}, "
            f"NumPy {np.__version__}; {_load()} at the start")


def fmt_rate(x: float) -> str:
    return f"{x:.3g}"


def fmt_time(s: float) -> str:
    if s < 1e-3:
        return f"{s * 1e6:.1f} us"
    return f"{s * 1e3:.1f} ms" if s < 1 else f"{s:.2f} s"


# ---------------------------------------------------------------------------------------------

@guarded
def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="small sizes, for a smoke run")
    ap.add_argument("--startup", action="store_true",
                    help="only the whole-process start-up of `mitos eval` against NumPy's import")
    ap.add_argument("--against", metavar="REV", type=revision,
                    help="only the column batch, one evaluation and start-up of this tree against "
                         "git revision REV's (e.g. main), in one process, rounds interleaved")
    args = ap.parse_args(argv)
    if args.startup and args.against:       # --startup ran alone and --against went unsaid
        ap.error("--startup times this tree alone; --against times its start-up against REV's "
                 "too: give one of them")
    if args.startup:
        startup(runs=21)
        return
    if args.against:
        against(args.against, quick=args.quick)
        return
    require("bench_core.py", "fuzzylite", "simpful")
    n = 10**5 if args.quick else 10**6
    repeats = 3 if args.quick else 5
    single_n = 200 if args.quick else 2000
    runs = 3 if args.quick else 11

    host = machine()
    rb = load_rulebase()
    c = rb.compiled
    rng = np.random.default_rng(np.random.SeedSequence(SEED))
    lo, hi = c.universe[:, 0], c.universe[:, 1]
    X = rng.uniform(lo, hi, size=(n, len(c.inputs)))

    # the peers compute what MITOS computes (checked before anything is timed)
    reference = evaluate(c, X[:20000], detail=False).outputs
    kernel = PaperKernel(rb)
    np.testing.assert_allclose(kernel(X[:20000]), reference, rtol=1e-12, atol=1e-9)
    fl_engine = fuzzylite_engine(rb)
    fl_engine.input_values = X[:20000]
    fl_engine.process()
    np.testing.assert_allclose(fl_engine.output_values, reference, rtol=1e-12, atol=1e-9)
    with contextlib.redirect_stdout(io.StringIO()):         # simpful's banner and notes
        sf = simpful_system(rb)
        for x in X[:200]:
            for name, value in zip(c.inputs, x):
                sf.set_variable(name, float(value))
            got = sf.Sugeno_inference(list(c.outputs))
            np.testing.assert_allclose([got[o] for o in c.outputs],
                                       evaluate(c, x[None], detail=False).outputs[0],
                                       rtol=1e-12, atol=1e-9)

    # (a) batch throughput
    columns = {name: np.ascontiguousarray(X[:, j]) for j, name in enumerate(c.inputs)}
    batch = interleaved_best({"detail": lambda: evaluate(c, X, detail=True),
                              "fast": lambda: evaluate(c, X, detail=False),
                              "kernel": lambda: kernel(X),
                              "loaded": lambda: rb.evaluate(**columns)}, 2 * repeats)
    t_detail, t_fast, t_kernel, t_loaded = (batch[k] for k in ("detail", "fast", "kernel",
                                                                "loaded"))
    mem_loaded = peak_memory(lambda: rb.evaluate(**columns))
    mem_kernel = peak_memory(lambda: kernel(X))

    def fl_batch():
        fl_engine.input_values = X
        fl_engine.process()
        return fl_engine.output_values
    t_fl = best_of(fl_batch, max(2, repeats // 2))
    rate = {k: n / t for k, t in (("detail", t_detail), ("fast", t_fast), ("kernel", t_kernel),
                                   ("loaded", t_loaded),
                                   ("fl", t_fl))}

    # (b) single-evaluation latency
    single = X[:single_n]
    lat_mitos = per_call(lambda r, s, p: rb.evaluate(road=r, size=s, position=p),
                         [tuple(map(float, x)) for x in single], repeats)
    rows1 = [(X[i:i + 1],) for i in range(single_n)]
    lat_row = per_call(lambda x: evaluate(c, x, detail=False), rows1, repeats)
    lat_row_detail = per_call(lambda x: evaluate(c, x, detail=True), rows1, repeats)
    road_v, size_v, pos_v = (fl_engine.input_variable(nm) for nm in c.inputs)
    steer_v, speed_v = (fl_engine.output_variable(nm) for nm in c.outputs)

    def fl_single(r, s, p):
        road_v.value, size_v.value, pos_v.value = r, s, p
        fl_engine.process()
        return np.asarray(steer_v.value).item(), np.asarray(speed_v.value).item()

    def sf_single(r, s, p):
        sf.set_variable("road", r)
        sf.set_variable("size", s)
        sf.set_variable("position", p)
        return sf.Sugeno_inference(["steering", "speed"])

    pts = [tuple(map(float, x)) for x in single]
    lat_fl = per_call(fl_single, pts[: max(50, single_n // 4)], repeats)
    with contextlib.redirect_stdout(io.StringIO()):
        lat_sf = per_call(sf_single, pts[: max(50, single_n // 4)], repeats)

    # (c) whole process
    mitos = str(Path(sys.executable).parent / "mitos")
    t_eval = process_time([mitos, "eval", "road=78", "size=45", "position=4"], runs)
    t_numpy = process_time([sys.executable, "-c", "import numpy"], runs)

    print(f"# MITOS core benchmark ({time.strftime('%Y-%m-%d')})")
    print(f"machine: {host}")
    print(_threads())
    print(f"command: python benchmarks/bench_core.py{' --quick' if args.quick else ''}")
    print(f"batch: {n:,} random inputs, best of {2 * repeats} interleaved rounds of {CALLS} calls "
          f"in a row, the first untimed; "
          f"single: median of {repeats} repeats of the mean over {single_n} (MITOS) / "
          f"{len(pts[:max(50, single_n // 4)])} (peers) calls; process: median of {runs} runs\n")
    print("| measurement | figure | ratio |")
    print("| --- | ---: | --- |")
    print(f"| MITOS batch, `evaluate(detail=True)` | {fmt_rate(rate['detail'])} eval/s | "
          f"{rate['detail'] / rate['kernel']:.2f}x the hand-written kernel, "
          f"{rate['detail'] / rate['fl']:.0f}x pyfuzzylite |")
    print(f"| MITOS batch, `evaluate(detail=False)` | {fmt_rate(rate['fast'])} eval/s | "
          f"{rate['fast'] / rate['kernel']:.2f}x the hand-written kernel, "
          f"{rate['fast'] / rate['fl']:.0f}x pyfuzzylite |")
    print(f"| MITOS batch, `load_rulebase().evaluate(**columns)` | {fmt_rate(rate['loaded'])} "
          f"eval/s | **{rate['loaded'] / rate['kernel']:.2f}x the hand-written kernel** "
          f"(aim >= 1.0x) |")
    print(f"| hand-written NumPy kernel (this rule base) | {fmt_rate(rate['kernel'])} eval/s | |")
    print(f"| peak extra memory, `load_rulebase().evaluate(**columns)` | {mem_loaded / 1e6:.1f} MB "
          f"| {mem_loaded / mem_kernel:.2f}x the kernel's {mem_kernel / 1e6:.1f} MB (aim <= 1.0x) |")
    print(f"| pyfuzzylite {_version('fuzzylite')} vectorized `process()` | "
          f"{fmt_rate(rate['fl'])} eval/s | |")
    print(f"| MITOS single, `load_rulebase().evaluate(...)` | {fmt_time(lat_mitos)} | "
          f"{lat_fl / lat_mitos:.0f}x faster than pyfuzzylite, "
          f"{lat_sf / lat_mitos:.0f}x faster than simpful |")
    print(f"| MITOS single, `evaluate(compiled, X[i:i+1], detail=False)` | "
          f"{fmt_time(lat_row)} | {lat_fl / lat_row:.0f}x faster than pyfuzzylite |")
    print(f"| MITOS single, `evaluate(compiled, X[i:i+1], detail=True)` (NumPy path) | "
          f"{fmt_time(lat_row_detail)} | {lat_fl / lat_row_detail:.0f}x faster than pyfuzzylite |")
    print(f"| pyfuzzylite {_version('fuzzylite')} single | {fmt_time(lat_fl)} | |")
    print(f"| simpful {_version('simpful')} single | {fmt_time(lat_sf)} | |")
    print(f"| `mitos eval road=78 size=45 position=4` (whole process) | {fmt_time(t_eval)} | "
          f"{t_eval / t_numpy:.2f}x `python -c \"import numpy\"` |")
    print(f"| `python -c \"import numpy\"` (whole process) | {fmt_time(t_numpy)} | |")
    print(f"\n{_load()} at the end")


def _threads() -> str:
    """Who may use how many threads: MITOS's batches (its blocks over threads) and the BLAS
    product of the kernel."""
    from mitos_cli.engine.threads import ENV, thread_count

    blas = os.environ.get("OPENBLAS_NUM_THREADS") or os.environ.get("OMP_NUM_THREADS")
    return (f"threads: MITOS batches {thread_count()} ({ENV}={os.environ.get(ENV, 'unset')}), "
            f"the kernel's BLAS {blas or 'its default'}")


def _load() -> str:
    try:
        return "load average {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())
    except OSError:
        return "load average unknown"


def _version(dist: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(dist if dist != "fuzzylite" else "pyfuzzylite")
    except PackageNotFoundError:
        return "?"


if __name__ == "__main__":
    sys.exit(main())
