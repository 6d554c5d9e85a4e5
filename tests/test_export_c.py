"""``mitos export``: the C99 file compiles cleanly with the system compiler and agrees with the
engine; the NumPy module agrees too.

Agreement is checked on 300 seeded random inputs per rule base to 1e-9 absolute (the generated
code evaluates the same formulas; only summation order differs, so in practice the gap is below
1e-12), with NaN ("no rule fired, no default") in the same places.
"""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from mitos_cli.api import load_rulebase
from mitos_cli.cli.app import app
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.interop.export import to_c, to_python

ROOT = Path(__file__).parents[1]
DATA = ROOT / "tests" / "data" / "interop"
CC = shutil.which("cc") or shutil.which("gcc")
TOLERANCE = 1e-9

DRIVER = r"""
#include <stdio.h>
int demo_eval(const double *in, double *out);
int main(void) {
    double in[16], out[16];
    int k, m, i, j;
    if (scanf("%d %d", &k, &m) != 2) return 1;
    for (;;) {
        int status;
        for (i = 0; i < k; ++i) if (scanf("%lf", &in[i]) != 1) return 0;
        status = demo_eval(in, out);
        printf("%d", status);
        for (j = 0; j < m; ++j) printf(" %.17g", out[j]);
        printf("\n");
    }
}
"""

TERMS = """\
variables:
  a: {role: input, universe: [0, 10], terms: {low: {shape: left_shoulder, points: [2, 6]},
      mid: {shape: gaussian, points: [5, 1.5]}, high: {shape: s_shape, points: [4, 9]}}}
  b: {role: input, universe: [-1, 1], terms: {neg: {shape: sigmoid, points: [0, -6]},
      zero: {shape: bell, points: [0, 0.4, 2]}, pos: {shape: discrete, points: [-0.2, 0, 0.5, 1]}}}
  y: {role: output, universe: [0, 100], default: 50, terms: {lo: {shape: triangle, points: [0, 20, 40]},
      mid: {shape: gaussian2, points: [45, 5, 55, 5]}, hi: {shape: trapezoid, points: [60, 80, 100, 100]},
      spot: 70}}
"""

RULES = """\
terms "t.terms.yaml"
operators: and = {and_}, or = {or_}, inference = mamdani, implication = {imp}, aggregation = {agg}, defuzzify = {defuzz}, resolution = 257
behavior main:
    use parts when a is not very high with 0.9
    r1: if a is low and not (b is neg or b is somewhat zero) then y is lo
    r2: if a is seldom mid or b is intensely pos then y is very mid with 0.7
    r3: if a is high and b is any zero then y is hi
    r4: if a is extremely low then y is spot
    r5: if b is pos and a is mid then y is 30
end
behavior parts:
    p1: if b is zero then y is mid
end
"""

OPERATOR_CASES = [
    dict(and_="min", or_="max", imp="min", agg="max", defuzz="centroid"),
    dict(and_="product", or_="probabilistic_sum", imp="product", agg="probabilistic_sum",
         defuzz="bisector"),
    dict(and_="lukasiewicz", or_="bounded_sum", imp="min", agg="bounded_sum", defuzz="mom"),
    dict(and_="einstein", or_="einstein_sum", imp="einstein", agg="einstein_sum", defuzz="som"),
    dict(and_="hamacher", or_="hamacher_sum", imp="hamacher", agg="hamacher_sum", defuzz="lom"),
    dict(and_="drastic", or_="drastic_sum", imp="min", agg="max", defuzz="centroid"),
    dict(and_="nilpotent_minimum", or_="nilpotent_maximum", imp="product",
         agg="nilpotent_maximum", defuzz="centroid"),
    # the unbounded sum: an aggregation only (MATLAB's `sum`), the set may exceed 1
    dict(and_="product", or_="max", imp="product", agg="sum", defuzz="centroid"),
    dict(and_="min", or_="probabilistic_sum", imp="min", agg="sum", defuzz="bisector"),
    dict(and_="min", or_="max", imp="min", agg="sum", defuzz="mom"),
]


def synthetic(tmp_path: Path, case: dict) -> Path:
    (tmp_path / "t.terms.yaml").write_text(TERMS)
    path = tmp_path / "t.rules"
    path.write_text(RULES.format(**case))
    return path


def sugeno(tmp_path: Path, inference: str) -> Path:
    (tmp_path / "s.terms.yaml").write_text(TERMS.replace(
        "terms: {lo: {shape: triangle, points: [0, 20, 40]},\n      mid: {shape: gaussian2, "
        "points: [45, 5, 55, 5]}, hi: {shape: trapezoid, points: [60, 80, 100, 100]},\n"
        "      spot: 70}", "terms: {lo: 10, lin: {shape: linear, coefficients: {a: 3, b: -20}, "
        "constant: 40}, hi: 90}"))
    path = tmp_path / "s.rules"
    path.write_text(f'terms "s.terms.yaml"\noperators: inference = {inference}\n'
                    "r1: if a is low then y is lo\nr2: if a is mid and b is zero then y is lin\n"
                    "r3: if a is high or b is pos then y is hi with 0.5\n")
    return path


def fixtures(tmp_path: Path) -> list[Path]:
    files = [ROOT / "rulebases" / "mitos.rules", DATA / "tipper.fis",
             DATA / "tipper_jfuzzylogic.fcl", DATA / "dimmer_fuzzylite.fcl",
             DATA / "robot_jfuzzylogic.fcl",
             sugeno(tmp_path, "weighted_average"), sugeno(tmp_path, "weighted_sum")]
    return files


def reference(path: Path) -> tuple[object, np.ndarray, np.ndarray]:
    rb = load_rulebase(path)
    c = rb.compiled
    rng = np.random.default_rng(np.random.SeedSequence(6).spawn(1)[0])
    lo, hi = c.universe[:, 0], c.universe[:, 1]
    X = rng.uniform(lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo), size=(300, len(c.inputs)))
    return c, X, rb.run(X, strict=False, detail=False).outputs


def run_c_status(c, X: np.ndarray, tmp_path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The exported C function on each row of ``X``: its return values and its outputs."""
    src, drv, exe = tmp_path / "demo.c", tmp_path / "driver.c", tmp_path / "demo"
    src.write_text(to_c(c, "demo", "test"))
    drv.write_text(DRIVER)
    # -Wmissing-prototypes: an embedded build's usual flag (the export had no prototype)
    built = subprocess.run([CC, "-std=c99", "-O0", "-Wall", "-Wextra", "-pedantic", "-Werror",
                            "-Wmissing-prototypes", "-o", str(exe), str(src), str(drv), "-lm"],
                           capture_output=True, text=True)
    assert built.returncode == 0, built.stderr
    rows = "\n".join(" ".join(repr(float(v)) for v in row) for row in X)
    done = subprocess.run([str(exe)], input=f"{X.shape[1]} {len(c.outputs)}\n{rows}\n",
                          capture_output=True, text=True, check=True)
    lines = [line.split() for line in done.stdout.splitlines()]
    return (np.array([int(line[0]) for line in lines]),
            np.array([[float(v) for v in line[1:]] for line in lines]))


def run_c(c, X: np.ndarray, tmp_path: Path) -> np.ndarray:
    return run_c_status(c, X, tmp_path)[1]


def exported_module(c, tmp_path: Path):
    """The module `mitos export --to python` writes for ``c``, imported."""
    path = tmp_path / "exported.py"
    path.write_text(to_python(c, "test"))
    spec = importlib.util.spec_from_file_location("exported", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run_python(c, X: np.ndarray, tmp_path: Path) -> np.ndarray:
    return exported_module(c, tmp_path).evaluate(X)


def agree(got: np.ndarray, want: np.ndarray) -> None:
    assert got.shape == want.shape
    assert (np.isnan(got) == np.isnan(want)).all()
    np.testing.assert_allclose(got, want, rtol=0, atol=TOLERANCE, equal_nan=True)


needs_cc = pytest.mark.skipif(CC is None, reason="no C compiler (cc or gcc) on PATH")


@needs_cc
def test_c_export_agrees_with_eval(tmp_path: Path) -> None:
    for path in fixtures(tmp_path):
        c, X, want = reference(path)
        agree(run_c(c, X, tmp_path), want)


@needs_cc
@pytest.mark.parametrize("case", OPERATOR_CASES,
                         ids=[f"{c['and_']}-{c['agg']}" for c in OPERATOR_CASES])
def test_c_export_operators_hedges_uses(case: dict, tmp_path: Path) -> None:
    c, X, want = reference(synthetic(tmp_path, case))
    agree(run_c(c, X, tmp_path), want)
    agree(run_python(c, X, tmp_path), want)


@pytest.mark.parametrize("name", ["mitos.rules", "tipper.fis"])
def test_python_export_gives_each_row_its_bits_in_any_block(name: str, tmp_path: Path) -> None:
    """The exported ``evaluate`` works in blocks of ``BLOCK`` rows: 2.5 blocks give each
    row the bits it gets alone, and a small ``BLOCK`` the bits of one large one."""
    from mitos_cli.interop.export.python import BLOCK

    path = ROOT / "rulebases" / name if name.endswith(".rules") else DATA / name
    c = load_rulebase(path).compiled
    rng = np.random.default_rng(12)
    lo, hi = c.universe[:, 0], c.universe[:, 1]
    X = rng.uniform(lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo), size=(BLOCK * 5 // 2, len(c.inputs)))
    X[::101, 0] = np.nan
    module = exported_module(c, tmp_path)
    whole = module.evaluate(X)
    rows = np.concatenate([module.evaluate(X[i:i + 1]) for i in range(0, len(X), 997)])
    assert np.array_equal(whole[::997].view(np.uint64), rows.view(np.uint64))
    module.BLOCK = 7
    assert np.array_equal(module.evaluate(X[:500]).view(np.uint64), whole[:500].view(np.uint64))


BINARY_FLL = """\
Engine: b
InputVariable: x
  range: 0 10
  term: right Binary 3 inf
  term: left Binary 7 -inf
OutputVariable: y
  range: 0 10
  aggregation: none
  defuzzifier: WeightedAverage TakagiSugeno
  default: 5
  term: lo Constant 2
  term: hi Constant 8
RuleBlock: r
  rule: if x is right then y is hi
  rule: if x is left then y is lo with 0.5
"""


@needs_cc
def test_a_binary_input_term_with_an_infinite_direction_exports(tmp_path: Path) -> None:
    """`Binary 3 inf`, fuzzylite's way to write a step (pyfuzzylite's `terms/binary.fll`), made
    `mitos export` stop with a Python traceback: an infinity has no C or Python literal."""
    path = tmp_path / "b.fll"
    path.write_text(BINARY_FLL)
    c, X, want = reference(path)
    X = np.vstack([X, [[3.0], [7.0], [2.999], [7.001]]])
    want = load_rulebase(path).run(X, strict=False, detail=False).outputs
    agree(run_c(c, X, tmp_path), want)
    agree(run_python(c, X, tmp_path), want)


#: A MATLAB file whose output spans 0, so that MATLAB's som and lom (by absolute value) are
#: neither the leftmost nor the rightmost sample of a maximum
STEER_FIS = """\
[System]
Name='steer'
Type='mamdani'
NumInputs=1
NumOutputs=1
NumRules=3
AndMethod='min'
OrMethod='max'
ImpMethod='prod'
AggMethod='max'
DefuzzMethod='{method}'

[Input1]
Name='x'
Range=[0 10]
NumMFs=3
MF1='lo':'trimf',[-10 0 6]
MF2='mid':'trapmf',[2 4 6 8]
MF3='hi':'trimf',[4 10 20]

[Output1]
Name='steer'
Range=[-10 10]
NumMFs=3
MF1='left':'trapmf',[-9 -7 -3 -1]
MF2='ahead':'trapmf',[-4 -1 1 4]
MF3='right':'trapmf',[1 3 7 9]

[Rules]
1, 1 (1) : 1
2, 2 (1) : 1
3, 3 (0.8) : 1
"""


@needs_cc
@pytest.mark.parametrize("method", ["bisector", "som", "lom", "mom", "centroid"])
def test_matlabs_defuzzifiers_export_as_eval_computes_them(method: str, tmp_path: Path) -> None:
    path = tmp_path / "steer.fis"
    path.write_text(STEER_FIS.format(method=method))
    c, X, want = reference(path)
    agree(run_c(c, X, tmp_path), want)
    agree(run_python(c, X, tmp_path), want)


@needs_cc
def test_jfuzzylogics_coa_exports_as_eval_computes_it(tmp_path: Path) -> None:
    """``--fidelity jfuzzylogic``'s COA (``jfuzzylogic_bisector``): the C function runs
    jFuzzyLogic's loop, the Python module the engine's loop-free count; both give eval's
    bits, on the grammar case where it is 1 from fuzzylite's bisector."""
    from test_interop_fcl_grammar import BASE

    from mitos_cli.api import LoadedRuleBase
    from mitos_cli.interop.common import fidelity_settings
    from mitos_cli.interop.fcl import parse_fcl

    rb = parse_fcl(BASE.replace("METHOD : COG;", "METHOD : COA;"), "probe.fcl")
    c = LoadedRuleBase(rb, None, fidelity_settings(rb, "jfuzzylogic")).compiled
    assert c.operators.defuzzify == "jfuzzylogic_bisector"
    k = np.linspace(0, 10, 17)
    X = np.array([(a, b) for a in k for b in k])
    want = evaluate(c, X, detail=False).outputs
    assert want[np.flatnonzero((X == [2.5, 5.0]).all(axis=1))[0], 0] == 3.99
    assert np.array_equal(run_c(c, X, tmp_path), want)
    assert np.array_equal(run_python(c, X, tmp_path), want)


@needs_cc
@pytest.mark.parametrize("method", ["COG", "COGS"])
def test_inputs_as_given_export_as_eval_computes_them(method: str, tmp_path: Path) -> None:
    """``inputs = as_given`` (``--fidelity jfuzzylogic``): the exports do not clamp either, on
    inputs up to half a range outside; an infinite input gives the C status -1 and NaN
    outputs, NaN from the Python module (eval refuses it)."""
    from test_interop_fcl_grammar import BASE

    from mitos_cli.api import LoadedRuleBase
    from mitos_cli.interop.common import fidelity_settings
    from mitos_cli.interop.fcl import parse_fcl

    text = BASE if method == "COG" else BASE.replace("METHOD : COG;", "METHOD : COGS;").replace(
        "TERM lo := (0, 0) (2, 1) (4, 0);", "TERM lo := 2;").replace(
        "TERM hi := (6, 0) (8, 1) (10, 0);", "TERM hi := 8;")
    rb = parse_fcl(text, "probe.fcl")
    c = LoadedRuleBase(rb, None, fidelity_settings(rb, "jfuzzylogic")).compiled
    assert c.operators.inputs == "as_given"
    X = np.array([(a, b) for a in np.linspace(-5, 15, 9) for b in np.linspace(-5, 15, 9)])
    want = evaluate(c, X, detail=False, strict=False).outputs
    clamped = evaluate(compile_rulebase(rb), X, detail=False, strict=False).outputs
    assert not np.array_equal(want, clamped, equal_nan=True)      # the clamp mattered here
    agree(run_c(c, X, tmp_path), want)
    agree(run_python(c, X, tmp_path), want)
    status, out = run_c_status(c, np.array([[np.inf, 1.0]]), tmp_path)
    assert status[0] == -1 and np.isnan(out).all()
    assert np.isnan(run_python(c, np.array([[np.inf, 1.0]]), tmp_path)).all()


@needs_cc
def test_c_export_every_fuzzylite_shape(tmp_path: Path) -> None:
    from test_conformance import EXAMPLES

    if EXAMPLES is None:
        pytest.skip("pyfuzzylite is not installed")
    c, X, want = reference(EXAMPLES / "mamdani" / "all_terms.fll")
    agree(run_c(c, X, tmp_path), want)


@needs_cc
@pytest.mark.parametrize("name", ["mitos.rules", "tipper.fis"])
def test_c_export_a_nan_input_gives_nan_and_a_status(name: str, tmp_path: Path) -> None:
    """The clamp passes NaN and the min t-norm (`a < b ? a : b`) drops it: without a check
    the C function returned a plausible number where the NumPy module returns NaN."""
    path = ROOT / "rulebases" / name if name.endswith(".rules") else DATA / name
    c = load_rulebase(path).compiled
    text = to_c(c, "demo", "test")
    assert "or DEMO_NAN_INPUT (-1) when an input is NaN" in text.split("*/")[0]  # documented
    middle = c.universe.mean(axis=1)
    X = np.tile(middle, (len(c.inputs) + 1, 1))
    for i in range(len(c.inputs)):
        X[i + 1, i] = np.nan
    status, out = run_c_status(c, X, tmp_path)
    assert status[0] >= 0 and not np.isnan(out[0]).any()
    assert (status[1:] == -1).all() and np.isnan(out[1:]).all(), (status, out)
    assert np.isnan(run_python(c, X[1:], tmp_path)).all()      # as the NumPy module


def test_python_export_agrees_with_eval(tmp_path: Path) -> None:
    for path in fixtures(tmp_path):
        c, X, want = reference(path)
        agree(run_python(c, X, tmp_path), want)


def test_exports_give_a_weighted_sums_default_where_no_rule_fires(tmp_path: Path) -> None:
    """A weighted sum where none of an output's rules fires takes the output's declared
    default, as `mitos eval` gives it (it gave 0, the empty sum); without one it stays 0."""
    (tmp_path / "g.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 10], terms: {LO: {shape: triangle, points: [0, 0, 4]},"
        " HI: {shape: triangle, points: [6, 10, 10]}}}\n"
        "  w: {role: output, universe: [-100, 100], default: 42, terms: {A: -10, B: 50}}\n"
        "  u: {role: output, universe: [-100, 100], terms: {A: -10, B: 50}}\n")
    path = tmp_path / "g.rules"
    path.write_text('terms "g.terms.yaml"\noperators: inference = weighted_sum\n'
                    "r1: if x is LO then w is A and u is A\nr2: if x is HI then w is B and u is B\n")
    c, X, want = reference(path)
    assert (want[(X[:, 0] > 4) & (X[:, 0] < 6)] == [42.0, 0.0]).all()
    agree(run_python(c, X, tmp_path), want)
    if CC is not None:
        agree(run_c(c, X, tmp_path), want)
    # and their comments say so: "(NaN when it has none)" was said of `u`'s 0
    assert "(0, the empty sum, when it has none)" in " ".join(
        line.lstrip(" *") for line in to_c(c, "demo", "test").splitlines())
    assert "default (0, the empty sum, when it has none)" in to_python(c, "test")


@pytest.mark.parametrize("operators", [
    "accumulation = max", "accumulation = probabilistic_sum, inference = weighted_sum",
    "accumulation = einstein_sum"])
def test_exports_join_the_rules_of_one_value_as_eval_does(operators: str, tmp_path: Path) -> None:
    """Under `accumulation = S` the exports weigh each value by `accumulate(...)` of the rules
    concluding it (a linear function, two terms of one crisp value and a hedged consequent),
    and join the linear function's value with another where they meet, as the engine does
    (`lin` = 40 + 3 a - 20 b is 90 at the clamped corner a = 10, b = -1)."""
    path = sugeno(tmp_path, "weighted_average")
    (tmp_path / "s.terms.yaml").write_text((tmp_path / "s.terms.yaml").read_text().replace(
        "hi: 90}", "hi: 90, top: 90}"))
    path.write_text(path.read_text().replace("inference = weighted_average", operators)
                    + "r4: if b is neg then y is lin\nr5: if a is high then y is very top\n"
                      "r6: if b is zero then y is lo with 0.7\n")
    c, X, want = reference(path)
    assert c.accumulated is not None and len(c.accumulated[0].first) == 3   # lo, lin, 90
    text = to_python(c, "test")
    assert "w2 = accumulate(dof_2, hedge_very(dof_4)) + np.zeros(X.shape[0])" in text
    assert "w2 = np.where(same, accumulate(w1, w2), w2)" in text   # lin meets 90 at a corner
    agree(run_python(c, X, tmp_path), want)
    if CC is not None:
        agree(run_c(c, X, tmp_path), want)


def test_c_file_is_self_contained(tmp_path: Path) -> None:
    text = to_c(load_rulebase(ROOT / "rulebases" / "mitos.rules").compiled, "robot")
    includes = [line for line in text.splitlines() if line.startswith("#include")]
    assert includes == ["#include <math.h>"]
    assert "malloc" not in text and "static double *" not in text
    assert "int robot_eval(const double in[ROBOT_N_INPUTS], double out[ROBOT_N_OUTPUTS])" in text
    assert "#define ROBOT_IN_ROAD 0" in text and "#define ROBOT_OUT_STEERING 0" in text


def test_export_cli(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    runner = CliRunner()
    out = tmp_path / "planner.c"
    result = runner.invoke(app, ["export", str(ROOT / "rulebases" / "mitos.rules"), "--to", "c",
                                 "-o", str(out), "--prefix", "planner"])
    assert result.exit_code == 0, result.output
    assert "int planner_eval(" in out.read_text()
    result = runner.invoke(app, ["export", str(DATA / "tipper.fis"), "--to", "python"])
    assert result.exit_code == 0 and "def evaluate(X):" in result.stdout
    result = runner.invoke(app, ["export", str(DATA / "tipper.fis"), "--to", "c",
                                 "--prefix", "1x"])
    assert result.exit_code == 2 and "not a C identifier" in result.output
    said = " ".join(result.output.replace("│", " ").split())
    assert "did you mean `_1x`?" in said
    result = runner.invoke(app, ["export", str(DATA / "tipper.fis"), "--to", "c",
                                 "--prefix", "my-planner"])            # the name it meant
    said = " ".join(result.output.replace("│", " ").split())
    assert result.exit_code == 2 and "did you mean `my_planner`?" in said


def test_a_prefix_for_python_is_a_usage_error(tmp_path: Path) -> None:
    """`--to python --prefix foo` wrote the module without a word: a Python module has no C
    names. `--prefix ''` stays "not a C identifier"."""
    from typer.testing import CliRunner

    runner = CliRunner()
    out = tmp_path / "t.py"
    result = runner.invoke(app, ["export", str(DATA / "tipper.fis"), "--to", "python",
                                 "--prefix", "foo", "-o", str(out)])
    assert result.exit_code == 2 and not out.exists()
    assert "--prefix names the C code" in " ".join(result.output.replace("│", " ").split())
    result = runner.invoke(app, ["export", str(DATA / "tipper.fis"), "--to", "c",
                                 "--prefix", ""])
    assert result.exit_code == 2 and "not a C identifier" in result.output


@needs_cc
def test_c_export_agrees_with_mitos_eval_command(tmp_path: Path) -> None:
    """The same numbers as the command a user runs: `mitos eval ... --json`."""
    import json

    from typer.testing import CliRunner

    cases = [(ROOT / "rulebases" / "mitos.rules", {"road": 78, "size": 45, "position": 4}),
             (DATA / "tipper.fis", {"service": 2, "food": 1}),
             (DATA / "robot_jfuzzylogic.fcl", {"dist": 0.4, "angle": 10})]
    for path, inputs in cases:
        result = CliRunner().invoke(app, ["eval", str(path), "--json"] +
                                    [f"{k}={v}" for k, v in inputs.items()])
        assert result.exit_code == 0, result.output
        want = json.loads(result.stdout)["outputs"]
        c = load_rulebase(path).compiled
        X = np.array([[inputs[name] for name in c.inputs]], dtype=float)
        got = run_c(c, X, tmp_path)[0]
        assert dict(zip(c.outputs, got)) == pytest.approx(want, abs=TOLERANCE)


def test_python_export_evaluate_one_names_a_missing_or_unknown_input(tmp_path: Path) -> None:
    """`evaluate_one(road=78, size=45)` raised a bare KeyError and unknown keywords were
    ignored: a TypeError as Python's own calls give, with the closest input."""
    c = load_rulebase(ROOT / "rulebases" / "mitos.rules").compiled
    module = exported_module(c, tmp_path)
    with pytest.raises(TypeError, match=r"missing 1 required keyword argument: 'position'$"):
        module.evaluate_one(road=78, size=45)
    with pytest.raises(TypeError, match=r"missing 2 required keyword arguments: 'size', 'posi"):
        module.evaluate_one(road=78)
    with pytest.raises(TypeError, match=r"unexpected keyword argument 'positon'; did you mean "
                                        r"'position'\?"):
        module.evaluate_one(road=78, size=45, positon=4)
    with pytest.raises(TypeError, match=r"argument 'zzz'; the inputs are 'road', 'size'"):
        module.evaluate_one(road=78, size=45, position=4, zzz=1)
    assert module.evaluate_one(road=78, size=45, position=4) == pytest.approx(
        load_rulebase(ROOT / "rulebases" / "mitos.rules").evaluate(road=78, size=45,
                                                                    position=4), abs=1e-12)


def test_python_export_checks_its_values_and_hints_a_swap(tmp_path: Path) -> None:
    """`evaluate_one(raod=...)` got no hint (a swap counted as two edits), a 3-D `X` met NumPy's
    "could not broadcast", bools were read as 1 and 0, and an array for one input met NumPy's
    "only 0-dimensional arrays can be converted"."""
    c = load_rulebase(ROOT / "rulebases" / "mitos.rules").compiled
    module = exported_module(c, tmp_path)
    for typo in ("raod", "Road", "szie", "postiion"):
        with pytest.raises(TypeError, match=rf"argument '{typo}'; did you mean '(road|size|posi)"):
            module.evaluate_one(**{typo: 1})
    with pytest.raises(ValueError, match=r"X must be 2-D, one row of 3 inputs per sample "
                                         r"\(X\[n, 3\]\), not of shape \(2, 3, 3\)$"):
        module.evaluate(np.zeros((2, 3, 3)))
    # as the library says it (it said the columns wanted, not the number given)
    with pytest.raises(ValueError, match=r"^expected 3 input columns \(road, size, position\), "
                                         r"not 2$"):
        module.evaluate([[78, 45]])
    for X in ([[True, 45, 4]], np.ones((2, 3), dtype=bool), np.array([[78, False, 4]], dtype=object),
              (78.0, 45.0, np.True_)):
        with pytest.raises(TypeError, match=r"X must hold numbers, not bools"):
            module.evaluate(X)
    for value in (True, np.array(True), [False]):
        with pytest.raises(TypeError, match=r"takes numbers, not bools: road="):
            module.evaluate_one(road=value, size=45, position=4)
    for value in (np.array([1.0, 2.0]), [78], np.zeros((1, 1))):
        with pytest.raises(TypeError, match=r"takes one number per input, not .* for 'road'; "
                                            r"evaluate\(X\) takes many samples"):
            module.evaluate_one(road=value, size=45, position=4)
    one = module.evaluate(np.array([[78.0, 45.0, 4.0]]))
    assert module.evaluate([78, 45, 4]).tobytes() == one.tobytes()            # a row as before
    assert module.evaluate_one(road=np.array(78.0), size=np.int64(45), position="4") == \
        dict(zip(module.OUTPUTS, one[0].tolist()))


def test_export_refuses_tsukamoto_at_the_operators_line(tmp_path: Path, capsys) -> None:
    """`format error: `mitos export` has no code for Tsukamoto inference` said neither file
    nor line; now it points at the `inference = tsukamoto` that chose it."""
    from mitos_cli.cli.app import main

    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  x: {role: input, universe: [0, 10], terms: {A: {shape: left_shoulder, "
        "points: [0, 10]}}}\n  y: {role: output, universe: [0, 100], terms: {UP: {shape: ramp, "
        "points: [20, 80]}}}\n")
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\noperators: inference = tsukamoto\n'
                                      "r1: if x is A then y is UP\n")
    for to in ("c", "python"):
        with pytest.raises(SystemExit) as info:
            main(["export", str(tmp_path / "t.rules"), "--to", to])
        err = capsys.readouterr().err
        assert info.value.code == 1
        assert "t.rules:2:12: format error: `mitos export` has no code for Tsukamoto " \
               "inference" in err
        assert "^^^^" in err


@needs_cc
def test_a_consequent_hedged_with_any_counts_only_where_its_rule_fires(tmp_path: Path) -> None:
    """`any` is 1 at a DOF of 0 too: the exported code weighed a rule that did not fire
    fully, as the engine did; both now weigh it only where it fires, and agree."""
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n"
        "  a: {role: input, universe: [0, 10], terms: {low: {shape: left_shoulder, points: [2, 6]},"
        " high: {shape: right_shoulder, points: [4, 8]}}}\n"
        "  y: {role: output, universe: [0, 100], default: 50, terms: {lo: 10, hi: 90}}\n")
    path = tmp_path / "t.rules"
    path.write_text('terms "t.terms.yaml"\nr1: if a is low then y is any lo\n'
                    "r2: if a is high then y is very hi\n")
    c, X, want = reference(path)
    assert want[X[:, 0] >= 6, 0] == pytest.approx(90.0)           # r1 does not fire there
    agree(run_c(c, X, tmp_path), want)
    agree(run_python(c, X, tmp_path), want)
