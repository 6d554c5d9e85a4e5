"""Batch throughput of the MITOS rule base under each T-norm, and of a Mamdani centroid version
at resolution 101 and 1001, side by side with pyfuzzylite 8 and scikit-fuzzy on the same rule
base in the same run (printed as samples per second and ratios).

    python benchmarks/bench_norms.py                  # full sizes (about a minute)
    python benchmarks/bench_norms.py --quick          # smaller batches

The rule base is the packaged one (the paper's 27 rules, 3 inputs, 2 outputs). The Sugeno
part uses its crisp consequents (DOF-weighted average, eqs. 18-19) and is compared with
fuzzylite's Takagi-Sugeno engine with the same conjunction; scikit-fuzzy has no Sugeno
inference, so it appears only in the Mamdani part. The Mamdani version gives the outputs
triangular terms (steering: peaks 30..150, half-width 20; speed: peaks 10..50, half-width 10),
min implication, max aggregation and centroid. All three libraries sample the output universe
at the same points (the midpoints of ``resolution`` cells), and the script checks that the
outputs agree before it prints a figure: with pyfuzzylite to 1e-9, with scikit-fuzzy (whose
centroid integrates the piecewise-linear interpolant) within one cell. Each time is the best of
``--repeat`` runs (scikit-fuzzy: one run).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml
from options import guarded, positive_int
from peers import require

FL_TNORM = {"min": "Minimum", "product": "AlgebraicProduct", "lukasiewicz": "BoundedDifference",
            "drastic": "DrasticProduct", "einstein": "EinsteinProduct",
            "hamacher": "HamacherProduct", "nilpotent_minimum": "NilpotentMinimum"}
STEERING = {"LB": 30, "LM": 50, "LS": 70, "ST": 90, "RS": 110, "RM": 130, "RB": 150}
SPEED = {"STOP": 0, "CREEP": 10, "SLOW": 20, "MODERATE": 30, "MEDIUM": 40, "FAST": 50,
         "TOP": 60}
HALF_WIDTH = {"steering": 20, "speed": 10}


def corners(term) -> tuple[float, float, float, float]:
    a, b, c, d = term.corners
    return a, b, c, d


def fll_term(term) -> str:
    if term.shape == "singleton":
        return f"{term.name} Constant {term.params[0]:g}"
    a, b, c, d = corners(term)
    if a == -np.inf:
        return f"{term.name} Ramp {d:g} {c:g}"
    if d == np.inf:
        return f"{term.name} Ramp {a:g} {b:g}"
    if b == c:
        return f"{term.name} Triangle {a:g} {b:g} {d:g}"
    return f"{term.name} Trapezoid {a:g} {b:g} {c:g} {d:g}"


def mamdani_files(tmp: Path, resolution: int) -> Path:
    """The packaged rules with triangular output terms and Mamdani operators."""
    from mitos_cli.api import default_rulebase_path

    src = default_rulebase_path()
    terms = yaml.safe_load((src.parent / "mitos.terms.yaml").read_text())
    for name, peaks in (("steering", STEERING), ("speed", SPEED)):
        w = HALF_WIDTH[name]
        terms["variables"][name]["terms"] = {
            t: {"shape": "triangle", "points": [p - w, p, p + w]} for t, p in peaks.items()}
    (tmp / "mitos.terms.yaml").write_text(yaml.safe_dump(terms))
    for other in src.parent.glob("*.terms.yaml"):        # the other term sets it names
        if other.name != "mitos.terms.yaml":
            (tmp / other.name).write_text(other.read_text())
    lines = src.read_text().splitlines()
    at = next(i for i, line in enumerate(lines) if line.startswith("terms "))
    lines.insert(at + 1, f"operators: inference = mamdani, resolution = {resolution}")
    text = "\n".join(lines) + "\n"
    path = tmp / f"m{resolution}.rules"
    path.write_text(text)
    return path


def fuzzylite_engine(compiled, conjunction: str, mamdani: bool):
    import fuzzylite as fl

    from mitos_cli.lang.model import format_rule

    lines = ["Engine: bench"]
    for name in compiled.inputs:
        v = compiled.variables[name]
        lines += [f"InputVariable: {name}", "  enabled: true",
                  f"  range: {v.universe[0]:g} {v.universe[1]:g}", "  lock-range: false"]
        lines += [f"  term: {fll_term(t)}" for t in v.terms]
    ops = compiled.operators
    for j, name in enumerate(compiled.outputs):
        v = compiled.variables[name]
        default = "nan" if np.isnan(compiled.default[j]) else f"{compiled.default[j]:g}"
        defuzz = (f"Centroid {ops.resolution}" if mamdani else "WeightedAverage TakagiSugeno")
        lines += [f"OutputVariable: {name}", "  enabled: true",
                  f"  range: {v.universe[0]:g} {v.universe[1]:g}", "  lock-range: false",
                  f"  aggregation: {'Maximum' if mamdani else 'none'}",
                  f"  defuzzifier: {defuzz}", f"  default: {default}", "  lock-previous: false"]
        lines += [f"  term: {fll_term(t)}" for t in v.terms]
    lines += ["RuleBlock: rules", "  enabled: true", f"  conjunction: {FL_TNORM[conjunction]}",
              "  disjunction: Maximum", f"  implication: {'Minimum' if mamdani else 'none'}",
              "  activation: General"]
    lines += [f"  rule: {format_rule(r, label=False)}" for r in compiled.rules]
    return fl.FllImporter().from_string("\n".join(lines) + "\n")


def run_fuzzylite(engine, compiled, X):
    for j, name in enumerate(compiled.inputs):
        engine.input_variable(name).value = X[:, j].copy()
    engine.process()
    return np.column_stack([engine.output_variable(o).value for o in compiled.outputs])


def skfuzzy_system(compiled):
    import skfuzzy as fuzz
    from skfuzzy import control as ctrl

    from mitos_cli.engine.mamdani import grid
    from mitos_cli.lang.model import And, Prop

    def mf(universe, term):
        a, b, c, d = corners(term)
        lo, hi = universe[0] - 1, universe[-1] + 1
        return fuzz.trapmf(universe, [lo if a == -np.inf else a, lo if b == -np.inf else b,
                                      hi if c == np.inf else c, hi if d == np.inf else d])

    ants = {}
    for name in compiled.inputs:
        v = compiled.variables[name]
        # a step of 0.5 holds every break point, so interpolation is exact
        ants[name] = ctrl.Antecedent(np.arange(v.universe[0], v.universe[1] + 0.25, 0.5), name)
        for t in v.terms:
            ants[name][t.name] = mf(ants[name].universe, t)
    cons = {}
    for name in compiled.outputs:
        v = compiled.variables[name]
        x = grid(*v.universe, compiled.operators.resolution)
        cons[name] = ctrl.Consequent(x, name, defuzzify_method="centroid")
        used = {c.term for r in compiled.rules for c in r.consequents if c.var == name}
        for t in v.terms:
            if t.name in used:          # scikit-fuzzy fails on a term no rule names
                cons[name][t.name] = mf(x, t)
    rules = []
    for rule in compiled.rules:
        items = rule.antecedent.items if isinstance(rule.antecedent, And) else (rule.antecedent,)
        assert all(isinstance(p, Prop) and not p.hedges and not p.negated for p in items)
        term = ants[items[0].var][items[0].term]
        for p in items[1:]:
            term = term & ants[p.var][p.term]
        rules.append(ctrl.Rule(term, tuple(cons[c.var][c.term] for c in rule.consequents)))
    return ctrl.ControlSystemSimulation(ctrl.ControlSystem(rules))


def run_skfuzzy(sim, compiled, X):
    import warnings

    with warnings.catch_warnings():    # "array shape differs from previous": all are replaced
        warnings.simplefilter("ignore", UserWarning)
        for j, name in enumerate(compiled.inputs):
            sim.input[name] = X[:, j].copy()
    sim.compute()
    return np.column_stack([np.atleast_1d(sim.output[o]) for o in compiled.outputs])


def best_of(fn, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


@guarded
def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="smaller batches")
    ap.add_argument("--repeat", type=positive_int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    require("bench_norms.py", "fuzzylite", "skfuzzy")

    import fuzzylite as fl

    from mitos_cli.api import load_rulebase, read_rulebase
    from mitos_cli.engine.compile import compile_rulebase
    from mitos_cli.engine.evaluation import evaluate
    from mitos_cli.lang.model import Setting

    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"Python {platform.python_version()}, NumPy {np.__version__}, "
          f"pyfuzzylite {fl.__version__}; {time.strftime('%Y-%m-%d')}; load average at start "
          f"{os.getloadavg()[0]:.2f}")
    rng = np.random.default_rng(np.random.SeedSequence(args.seed))
    rb = read_rulebase()
    base = compile_rulebase(rb, "avoid_obstacle")
    assert base.n_rules == 27

    def inputs(n):
        return np.column_stack([rng.uniform(lo, hi, n) for lo, hi in base.universe])

    n = 20_000 if args.quick else 200_000
    X = inputs(n)
    print(f"\nSugeno (weighted average, eqs. 18-19), 27 rules, {n} samples; samples/s "
          f"(best of {args.repeat}):")
    print(f"  {'T-norm':<18} {'MITOS':>12} {'pyfuzzylite':>12} {'ratio':>8}")
    for tnorm in FL_TNORM:
        c = compile_rulebase(rb, "avoid_obstacle", overrides=(Setting("and", tnorm),))
        engine = fuzzylite_engine(c, tnorm, mamdani=False)
        ours = evaluate(c, X, detail=False, strict=False).outputs
        theirs = run_fuzzylite(engine, c, X)
        assert np.allclose(ours, theirs, atol=1e-9, equal_nan=True), tnorm
        t_m = best_of(lambda: evaluate(c, X, detail=False, strict=False), args.repeat)
        t_f = best_of(lambda: run_fuzzylite(engine, c, X), args.repeat)
        print(f"  {tnorm:<18} {n / t_m:12,.0f} {n / t_f:12,.0f} {t_f / t_m:7.1f}x", flush=True)

    with tempfile.TemporaryDirectory() as tmp:
        for resolution in (101, 1001):
            c = load_rulebase(mamdani_files(Path(tmp), resolution), "avoid_obstacle").compiled
            engine = fuzzylite_engine(c, "min", mamdani=True)
            sim = skfuzzy_system(c)
            n_m = (5_000 if args.quick else 50_000) // (1 if resolution == 101 else 5)
            n_f = n_m // (1 if resolution == 101 else 2)
            n_s = 200 if args.quick else 1_000
            Xm = inputs(n_m)
            check = Xm[:200]
            ours = evaluate(c, check, strict=False).outputs
            assert np.allclose(ours, run_fuzzylite(engine, c, check), atol=1e-9), "fuzzylite"
            # scikit-fuzzy integrates the piecewise-linear interpolant of the samples (its
            # centroid is the trapezoid rule, not the midpoint rule): within one cell
            cell = np.array([np.subtract(*c.variables[o].universe[::-1]) / resolution
                             for o in c.outputs])
            assert (np.abs(ours - run_skfuzzy(sim, c, check)) <= cell).all(), "scikit-fuzzy"
            t_m = best_of(lambda: evaluate(c, Xm, detail=False, strict=False), args.repeat)
            t_f = best_of(lambda: run_fuzzylite(engine, c, Xm[:n_f]), args.repeat)
            t_s = best_of(lambda: run_skfuzzy(sim, c, Xm[:n_s]), 1)
            m, f, s = n_m / t_m, n_f / t_f, n_s / t_s
            print(f"\nMamdani (min, max, centroid) at resolution {resolution}, 27 rules; "
                  f"samples/s (MITOS {n_m}, pyfuzzylite {n_f}, scikit-fuzzy {n_s} samples):")
            print(f"  MITOS        {m:12,.0f}")
            print(f"  pyfuzzylite  {f:12,.0f}   MITOS is {m / f:6.1f}x faster")
            print(f"  scikit-fuzzy {s:12,.0f}   MITOS is {m / s:6.0f}x faster", flush=True)
    print(f"\nload average at end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    sys.exit(main())
