"""What running jFuzzyLogic itself (built from source) on its own ``.fcl`` files showed, and
the benchmark's reading of what jFuzzyLogic prints (``bench_conformance.py --jfuzzylogic
JAR``). No Java runs here: jFuzzyLogic's outputs are recorded strings."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.errors import FormatError
from mitos_cli.interop.fcl import parse_fcl

ROOT = Path(__file__).resolve().parents[1]

#: jFuzzyLogic's ``junit1.fcl``, shortened: singleton output terms and no METHOD (COG)
SINGLETONS_UNDER_COG = """FUNCTION_BLOCK junit1
VAR_INPUT
    temp : REAL;
END_VAR
VAR_OUTPUT
    valve : REAL;
END_VAR
FUZZIFY temp
    TERM cold := (0, 1) (30, 0);
    TERM hot := (0, 0) (30, 1);
END_FUZZIFY
DEFUZZIFY valve
    TERM closed := 0;
    TERM inlet := 1;
END_DEFUZZIFY
RULEBLOCK No1
    AND : MIN;
    ACCU : MAX;
    RULE 1 : IF temp IS cold THEN valve IS closed;
    RULE 2 : IF temp IS hot THEN valve IS inlet;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("method, warned", [("", True), ("    METHOD : COG;\n", True),
                                            ("    METHOD : COGS;\n", False)])
def test_singletons_under_cog_are_said_to_be_what_jfuzzylogic_cannot_evaluate(method, warned):
    """jFuzzyLogic throws on every evaluation of a singleton concluded under COG, its default
    ("MembershipFunction and Defuzzifier are neither both discrete nor both continuous", on
    all 21 points the oracle tried on junit1.fcl): MITOS's number there was silent."""
    text = SINGLETONS_UNDER_COG.replace("END_DEFUZZIFY", method + "END_DEFUZZIFY")
    rb = parse_fcl(text, "j.fcl")
    notes = [n for n in rb.notes if "singleton" in n]
    assert bool(notes) == warned, rb.notes
    if warned:
        written = "`METHOD : COG`" if method else "no METHOD (COG)"
        where = "j.fcl:15:14" if method else "j.fcl:12:11"
        assert notes == [f"{where}: `valve IS closed` concludes a singleton under {written}: "
                         "jFuzzyLogic throws on every evaluation (a discrete term under a "
                         "continuous defuzzifier); MITOS averages the singletons, each snapped "
                         "to its nearest sample, weighted by their aggregated degrees"]
    # by hand, temp = 10: cold 2/3, hot 1/3; under COG the singletons 0 and 1 snap to the
    # midpoints 0.0005 and 0.9995 of 1000 cells, under COGS they stay where they are
    got = evaluate(compile_rulebase(rb), np.array([[10.0]])).outputs[0, 0]
    assert got == pytest.approx(2 / 3 * 0.0005 + 1 / 3 * 0.9995 if warned else 1 / 3)


#: jFuzzyLogic's testDeMorgan files (every connective pair under NOT), with terms that span
#: their ranges, so that MITOS loads them (the originals' single-point terms give no range)
DE_MORGAN = """FUNCTION_BLOCK dm
VAR_INPUT
    x1 : REAL; RANGE := (0 .. 1);
    x2 : REAL; RANGE := (0 .. 1);
END_VAR
VAR_OUTPUT
    y : REAL;
END_VAR
FUZZIFY x1
    TERM value := (0, 0) (0.3, 1) (1, 0);
END_FUZZIFY
FUZZIFY x2
    TERM value2 := (0, 0.2) (0.6, 1) (1, 0.4);
END_FUZZIFY
DEFUZZIFY y
    TERM a := TRIAN 0 0.1 0.3;
    TERM b := TRIAN 0.2 0.4 0.6;
    TERM c := TRIAN 0.4 0.6 0.8;
    TERM d := TRIAN 0.7 0.9 1;
    METHOD : COG;
    DEFAULT := 0;
    RANGE := (0 .. 1);
END_DEFUZZIFY
RULEBLOCK No1
    CONNECTIVE;
    ACT : MIN;
    ACCU : MAX;
    RULE 1 : IF NOT(x1 IS value OR x2 IS value2) THEN y IS a;
    RULE 2 : IF NOT(x1 IS value) AND NOT(x2 IS value2) THEN y IS b;
    RULE 3 : IF NOT(x1 IS value AND x2 IS value2) THEN y IS c;
    RULE 4 : IF x1 IS NOT value OR x2 IS value2 THEN y IS d;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("connective", ["AND : HAMACHER", "OR : EINSTEIN"])
def test_hamacher_goes_with_the_einstein_sum_as_in_jfuzzylogic(connective):
    """jFuzzyLogic sets both connectives from either line (RuleBlock.fclTree): HAMACHER with
    the Einstein sum. MITOS took the De Morgan dual, the Hamacher sum (or, from `OR :
    EINSTEIN`, the Einstein product), and its outputs differed by up to 0.044."""
    from mitos_cli.interop.common import fidelity_settings

    rb = parse_fcl(DE_MORGAN.replace("CONNECTIVE", connective), "dm.fcl")
    c = compile_rulebase(rb, None, fidelity_settings(rb, "jfuzzylogic"))
    assert (c.operators.and_, c.operators.or_) == ("hamacher", "einstein_sum")
    got = evaluate(c, np.array([[0.2, 0.5], [0.9, 0.1], [0.5, 0.95]])).outputs[:, 0]
    # recorded from jFuzzyLogic (built from source), the same for both lines
    np.testing.assert_allclose(got, [0.6998437099120048, 0.5260472489886552,
                                     0.6265296810386404], rtol=0, atol=1e-9)


@pytest.mark.parametrize("lines, ours, theirs", [
    ("AND : PROD;\n    OR : MAX", ("product", "max"), ("min", "max")),
    ("AND : MIN;\n    OR : ASUM", ("min", "probabilistic_sum"), ("product", "probabilistic_sum")),
    ("OR : MAX;\n    AND : HAMACHER", ("hamacher", "max"), ("hamacher", "einstein_sum")),
    ("AND : PROD;\n    OR : ASUM", ("product", "probabilistic_sum"), None),       # a pair
    ("AND : HAMACHER;\n    OR : EINSTEIN", ("hamacher", "einstein_sum"), None),   # its pair
    ("AND : AlgebraicProduct;\n    OR : Maximum", ("product", "max"), None),      # fuzzylite's
])
def test_and_and_or_both_given_not_as_a_pair_say_what_jfuzzylogic_takes(lines, ours, theirs):
    """jFuzzyLogic sets both connectives from each AND or OR line, so the last one decides both
    (`AND : MIN; OR : ASUM;` is the product with the probabilistic sum there: the oracle's
    outputs differed by up to 1.4 on jFuzzyLogic's grammar cases); MITOS, as fuzzylite, uses
    each, and now says so."""
    rb = parse_fcl(DE_MORGAN.replace("CONNECTIVE", lines), "dm.fcl")
    c = compile_rulebase(rb)
    assert (c.operators.and_, c.operators.or_) == ours
    notes = [n for n in rb.notes if "not as a pair" in n]
    if theirs is None:
        assert notes == []
        return
    last = lines.split("\n")[-1].strip()
    assert notes == [f"dm.fcl:26:5: both AND (`{ours[0]}`) and OR (`{ours[1]}`) are given, not as "
                     f"a pair: MITOS uses each, as fuzzylite does; jFuzzyLogic sets both from "
                     f"each line, so its last, `{last}`, gives AND `{theirs[0]}` and OR "
                     f"`{theirs[1]}`: give one of them, or their pair"]


@pytest.mark.parametrize("accu, aggregation", [("", "sum"), ("ACCU : SUM;", "sum"),
                                               ("ACCU : MAX;", "max"), ("ACCU : BSUM;", "bounded_sum")])
def test_a_mamdani_output_without_accu_sums_as_jfuzzylogic_does(accu, aggregation):
    """Without ACCU jFuzzyLogic sums the rules' sets (`ACCU : SUM`, its default,
    `RuleBlock.fclTree`); MITOS took their maximum with a note (the oracle's outputs differed by
    0.142 on two overlapping output terms) and now reads `aggregation = sum`, with no note."""
    text = DE_MORGAN.replace("CONNECTIVE", "AND : MIN").replace("ACCU : MAX;", accu)
    rb = parse_fcl(text, "dm.fcl")
    assert not [n for n in rb.notes if "ACCU" in n]
    assert compile_rulebase(rb).operators.aggregation == aggregation
    weighted = SINGLETONS_UNDER_COG.replace("    ACCU : MAX;\n", "").replace(
        "END_DEFUZZIFY", "    METHOD : COGS;\nEND_DEFUZZIFY")
    ops = compile_rulebase(parse_fcl(weighted, "w.fcl")).operators
    assert (ops.inference, ops.accumulation) == ("weighted_average", "sum")


# ---------------------------------------------------------------------------------------------
# The benchmark's reading of jFuzzyLogic's output


@pytest.fixture()
def oracle(monkeypatch):
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    sys.modules.pop("jfl_oracle", None)
    import jfl_oracle

    return jfl_oracle


#: JflGrid on tipper.fcl (service, food) = (3, 7), (9, 3), and a point that threw; recorded
GRID = """in tipper.food tipper.service
universe tipper.food=0.0:9.0 tipper.service=0.0:9.0
out tipper.tip=11.701603788948043
out tipper.tip=0.0
error java.lang.RuntimeException: MembershipFunction and Defuzzifier are neither both
"""

#: ``java -jar jFuzzyLogic.jar -e tipper.fcl 7 3`` (food, service), recorded from the oracle
EVAL = """FUNCITON_BLOCK tipper
\tVAR_INPUT \t      food = 7.000000
\tVAR_INPUT \t   service = 3.000000
\tVAR_OUTPUT\t       tip = 11.701604
\tRULE_BLOCK No1
\t\tSupport  \tRule name \tRule
\t\t0.250000\t1         \tIF (service IS poor) OR (food IS rancid) THEN tip IS cheap;
"""


def test_the_driver_s_lines_are_read(oracle):
    grid = oracle.parse_grid(GRID)
    assert grid.inputs == ["tipper.food", "tipper.service"]
    assert grid.universe == {"tipper.food": (0.0, 9.0), "tipper.service": (0.0, 9.0)}
    assert grid.rows[:2] == [{"tipper.tip": 11.701603788948043}, {"tipper.tip": 0.0}]
    assert grid.rows[2].startswith("java.lang.RuntimeException: MembershipFunction")
    assert grid.load_error is None
    assert oracle.parse_grid("load-error java.lang.NullPointerException\n").load_error == \
        "java.lang.NullPointerException"


def test_the_jar_s_own_evaluation_is_read(oracle):
    assert oracle.parse_eval(EVAL) == {"tipper.tip": 11.701604}
    asked = ("Missing argument 'tipper.food' (input variable 'food' in FunctionBlock 'tipper').\n"
             "Missing argument 'tipper.service' (input variable 'service' in FunctionBlock "
             "'tipper').\n")
    assert oracle.parse_missing(asked) == ["tipper.food", "tipper.service"]
    assert oracle.syntax_errors("line 27:4 missing SEMICOLON at 'TERM'\nGpr.debug(1): x\n"
                                "line 34:1 missing ID at 'ACT'\n") == 2


def test_the_grid_holds_both_ends_and_stays_in_its_budget(oracle):
    points = oracle.grid_points([(0.0, 9.0), (-1.0, 1.0)])
    assert len(points) == 17 * 17 and [0.0, -1.0] in points and [9.0, 1.0] in points
    assert len(oracle.grid_points([(0.0, 1.0)] * 6)) <= oracle.POINTS
    assert oracle.grid_points([]) == [[]]


def test_a_difference_counts_nan_against_a_number_as_infinite(oracle):
    nan = float("nan")
    assert oracle.difference(np.array([1.0, nan]), np.array([1.5, nan])) == 0.5
    assert oracle.difference(np.array([1.0]), np.array([nan])) == float("inf")


def test_a_difference_names_its_cause(oracle):
    assert oracle.cause_of("a.fcl", 1e-12, 1e-12, ()) == ""
    assert oracle.cause_of("a.fcl", 0.01, 1e-13, ()).startswith("sampling (1000 midpoints")
    assert oracle.cause_of("a.fcl", 0.5, 0.5, ("a.fcl:3:1: `y IS hi` is concluded by `r1` and "
                                               "`r2` under the accumulation `max` (`ACCU`)",)
                           ).startswith("MITOS warned: `y IS hi` is concluded")
    assert "walks in from both ends" in oracle.cause_of("x/09_METHOD_COA.fcl", 1.0, 1.0, ())
    assert "--fidelity jfuzzylogic computes it" in oracle.cause_of("x/09_METHOD_COA.fcl", 1.0,
                                                                   1e-13, ())
    assert oracle.cause_of("a.fcl", 0.5, 0.5, ()) == "not explained"


def test_the_grammar_cases_are_written_as_jfuzzylogic_s_grammar_reads_them(oracle, tmp_path):
    files = sorted(oracle.grammar_cases(tmp_path).glob("*.fcl"))
    base = files[0].read_text()
    assert files[0].name == "00_base.fcl" and len(files) > 30
    assert "a : REAL; RANGE := (0 .. 10);" in base and "FUZZIFY a\n    TERM" in base
    names = {f.name for f in files}
    assert all(name in names for name in oracle.KNOWN if name[:2].isdigit())   # causes found


def test_jfuzzylogic_s_samples_are_reached_as_it_reaches_them():
    """jFuzzyLogic adds the step to the point before (``x += step``), so its samples drift from
    ``min + i step``; under ``--fidelity jfuzzylogic`` MITOS samples the same points, bit for
    bit, and a zero-width term at 0 (jFuzzyLogic's ``junit_shashankrao``) is missed as it is
    missed there (its output differed by 0.054 before)."""
    from mitos_cli.engine.mamdani import grid

    lo, hi, n = -1.0, 1.0, 1000
    x, java = lo, []
    for _ in range(n):
        java.append(x)
        x += (hi - lo) / n
    ours = grid(lo, hi, n, "left")
    assert ours.tobytes() == np.array(java).tobytes()
    assert 0.0 not in ours and ours[500] == pytest.approx(0.0, abs=1e-15)


def test_coa_under_fidelity_is_jfuzzylogics_walk_from_both_ends(tmp_path):
    """`METHOD : COA` on the grammar cases' base file (its inputs' RANGE in their declarations,
    as jFuzzyLogic's grammar reads them): at a = 2.5, b = 5 jFuzzyLogic 3.3 (built from
    source, docs/benchmarks.md) gave 3.99, where MITOS's bisector gives 4.995; `--fidelity
    jfuzzylogic` now computes jFuzzyLogic's COA; the default (fuzzylite's bisector) stays."""
    from test_interop_fcl_grammar import BASE
    from typer.testing import CliRunner

    from mitos_cli.cli.app import app

    path = tmp_path / "coa.fcl"
    path.write_text(BASE.replace("METHOD : COG;", "METHOD : COA;"))
    run = CliRunner().invoke
    got = run(app, ["eval", str(path), "a=2.5", "b=5", "--fidelity", "jfuzzylogic", "--json"])
    assert got.exit_code == 0, got.output
    assert json.loads(got.stdout)["outputs"]["y"] == 3.99
    plain = run(app, ["eval", str(path), "a=2.5", "b=5", "--json"])
    assert json.loads(plain.stdout)["outputs"]["y"] == pytest.approx(4.995, abs=1e-9)


@pytest.mark.parametrize("fmt, words", [
    ("fcl", "FCL's `COA` is written, which jFuzzyLogic computes as this rule base does"),
    ("fll", "FLL has no jFuzzyLogic `bisector`"),
    ("fis", "a .fis file has no jFuzzyLogic `bisector`"),
    ("rules", None)])
def test_writing_jfuzzylogics_coa_says_what_the_target_reads(fmt, words):
    """A behavior with `defuzzify = jfuzzylogic_bisector` written: FCL's COA is jFuzzyLogic's,
    but is read back as fuzzylite's bisector; FLL and .fis have only their own."""
    import dataclasses

    from test_interop_fcl_grammar import BASE

    from mitos_cli.interop import conversion_notes
    from mitos_cli.lang.model import Setting

    rb = parse_fcl(BASE.replace("METHOD : COG;", "METHOD : COA;"), "probe.fcl")
    coa = (Setting("defuzzify", "jfuzzylogic_bisector"),)
    rb = dataclasses.replace(rb, behaviors=tuple(dataclasses.replace(b, operators=b.operators + coa)
                                                 for b in rb.behaviors))
    notes = [n for n in conversion_notes(rb, fmt) if "jFuzzyLogic" in n]
    assert bool(notes) == (words is not None) and (words is None or words in notes[0]), notes


def _jfuzzylogic_nsum(a: float, b: float) -> float:
    """jFuzzyLogic 3.3's ``RuleAccumulationMethodNormedSum.aggregate``, transcribed."""
    return (a + b) / max(1.0, a + b)


@given(st.floats(0, 1), st.floats(0, 1), st.floats(0, 1))
@settings(max_examples=200, deadline=None)
def test_nsum_is_the_bounded_sum_bit_for_bit(a, b, c):
    """jFuzzyLogic folds its rules' sets into each sample from 0 with ``(v + x) / max(1, v +
    x)``: ``v + x`` up to 1, and ``s / s``, exactly 1, above; the bounded sum does the same."""
    from mitos_cli.fuzzy.norms import SNORMS

    bsum = SNORMS["bounded_sum"].fn
    folded = _jfuzzylogic_nsum(_jfuzzylogic_nsum(_jfuzzylogic_nsum(0.0, a), b), c)
    ours = float(bsum(bsum(np.float64(a), np.float64(b)), np.float64(c)))
    assert folded == ours


@pytest.mark.parametrize("method", ["COG", "COGS"])
def test_accu_nsum_is_read_as_the_bounded_sum_with_a_note(method):
    """`ACCU : NSUM` was refused ("not an S-norm MITOS computes"); jFuzzyLogic's is the bounded
    sum exactly. Under COGS it joins the rules of one singleton, as BSUM does there."""
    from test_interop_fcl_grammar import BASE

    text = BASE.replace("ACCU : MAX;", "ACCU : NSUM;")
    if method == "COGS":
        text = text.replace("METHOD : COG;", "METHOD : COGS;").replace(
            "TERM lo := (0, 0) (2, 1) (4, 0);", "TERM lo := 2;").replace(
            "TERM hi := (6, 0) (8, 1) (10, 0);", "TERM hi := 8;")
    rb = parse_fcl(text, "n.fcl")
    c = compile_rulebase(rb)
    got = (c.operators.accumulation if method == "COGS" else c.operators.aggregation)
    assert got == "bounded_sum"
    line = text.splitlines().index("    ACCU : NSUM;") + 1
    assert [n for n in rb.notes if "NSUM" in n] == [
        f"n.fcl:{line}:12: `ACCU : NSUM` is read as jFuzzyLogic's normalized sum, (a + b) / "
        "max(1, a + b), which is the bounded sum min(1, a + b) exactly (`bounded_sum`); "
        "fuzzylite 6 reads it as its `NormalizedSum`, a + b / max(1, max(a, b)), the plain sum "
        "while both are at most 1"]
    bsum = compile_rulebase(parse_fcl(text.replace("NSUM", "BSUM"), "n.fcl"))
    X = np.array([[a, b] for a in np.linspace(0, 10, 11) for b in np.linspace(0, 10, 11)])
    assert np.array_equal(evaluate(c, X, detail=False).outputs,
                          evaluate(bsum, X, detail=False).outputs)


def test_de_morgan_files_are_refused_with_what_jfuzzylogic_makes_of_them():
    """jFuzzyLogic's `testDeMorgan_1` to `_6` give every variable one-point terms and no RANGE:
    its `Variable.estimateUniverse` takes [0, 0] (the terms' extent), and the oracle measured 0
    at every point (the files test its rule degrees, not outputs). MITOS keeps refusing: no
    sampled output, default or not, can be anything but that point; the message says so where
    it said only that the terms "do not span" a universe."""
    text = DE_MORGAN.replace("CONNECTIVE", "AND : MIN").replace(" RANGE := (0 .. 1);", "")
    text = text.replace("TERM value := (0, 0) (0.3, 1) (1, 0);", "TERM value := (0, 1) (0, 1);")
    with pytest.raises(FormatError) as info:
        parse_fcl(text, "dm.fcl")
    assert info.value.message.startswith(
        "variable `x1` has no RANGE and its terms lie at the one point 0: jFuzzyLogic takes "
        "[0, 0] for its universe")
    assert info.value.span.line == text.splitlines().index("FUZZIFY x1") + 1


def test_an_input_outside_its_range_is_evaluated_as_given_under_fidelity(tmp_path):
    """jFuzzyLogic's `Variable.setValue` warns ("Value out of range?") and keeps the value, so
    its terms are evaluated outside the RANGE: `TRIAN 0 10 10` (`MembershipFunctionTriangular`)
    is 0 at a = 12, where MITOS's clamp to 10 gives 1. `--fidelity jfuzzylogic` now sets
    `inputs = as_given`; without it the input is clamped, as before. By hand at a = 12,
    b = 5: `a IS low` 0 (the point list is flat past (5, 0)), `a IS high` 0, `b IS high`
    (4, 0) (10, 1) 1/6; so rule 2 (`a IS high OR b IS high`) has DOF 1/6 (clamped: 1)."""
    from test_interop_fcl_grammar import BASE
    from typer.testing import CliRunner

    from mitos_cli.cli.app import app

    path = tmp_path / "base.fcl"
    path.write_text(BASE)
    got = CliRunner().invoke(app, ["eval", str(path), "a=12", "b=5", "--fidelity", "jfuzzylogic",
                                   "--json"])
    assert got.exit_code == 0, got.output
    data = json.loads(got.stdout)
    assert data["inputs"]["a"]["memberships"] == {"low": 0.0, "high": 0.0}
    assert [r["dof"] for r in data["rules"]] == [pytest.approx(1 / 6, abs=1e-15)]
    assert ("`a` lies outside its universe [0, 10] (12): its terms are evaluated there, not "
            "clamped (`inputs = as_given`, fuzzylite's and jFuzzyLogic's reading)") in got.stderr
    plain = CliRunner().invoke(app, ["eval", str(path), "a=12", "b=5", "--json"])
    assert [r["dof"] for r in json.loads(plain.stdout)["rules"]] == [1.0]
    assert "`a` outside its universe [0, 10] was clamped" in plain.stderr
    inf = CliRunner().invoke(app, ["eval", str(path), "a=inf", "b=5", "--fidelity",
                                   "jfuzzylogic"])
    assert inf.exit_code == 1            # (the app's main prints it; here it is the exception)
    assert inf.exception.message.startswith("input `a` is inf: with `inputs = as_given`")


def test_as_given_batch_rows_equal_single_evaluations_bit_for_bit():
    """Outside the ranges too, and through the scalar form (weighted average) and the NumPy
    path alike; a linear FUNCTION (jFuzzyLogic's COGF) at the input as given."""
    from mitos_cli.api import LoadedRuleBase
    from mitos_cli.engine.evaluation import evaluate_one
    from mitos_cli.interop.common import fidelity_settings

    sugeno = """FUNCTION_BLOCK f
VAR_INPUT
    a : REAL; RANGE := (0 .. 10);
END_VAR
VAR_OUTPUT
    y : REAL; RANGE := (0 .. 40);
END_VAR
FUZZIFY a
    TERM low := (0, 1) (10, 0);
    TERM high := TRIAN 0 10 10;
END_FUZZIFY
DEFUZZIFY y
    TERM lin := FUNCTION 2 * a + 1;
    TERM flat := 3;
    METHOD : COGF;
    DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK r
    RULE 1 : IF a IS low THEN y IS flat;
    RULE 2 : IF a IS high THEN y IS lin;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""
    rb = parse_fcl(sugeno, "f.fcl")
    c = LoadedRuleBase(rb, None, fidelity_settings(rb, "jfuzzylogic")).compiled
    assert c.operators.inputs == "as_given"
    X = np.array([[-3.0], [0.0], [2.5], [10.0], [11.0], [-0.0], [1e6]])
    batch = evaluate(c, X, detail=False).outputs[:, 0]
    alone = [evaluate_one(c, [float(x)])[0] for x in X[:, 0]]
    assert batch.tobytes() == np.array(alone).tobytes()
    # by hand, jFuzzyLogic's way: a = -3: low 1 (flat past (0, 1)), high 0: 3;
    # a = 2.5: low 0.75 at 3, high 0.25 at 2 * 2.5 + 1 = 6: (0.75 * 3 + 0.25 * 6) / 1
    assert batch[0] == 3.0 and batch[2] == pytest.approx(3.75, abs=1e-12)
    # a = 11: both terms 0 (the triangle ends at 10, the point list is flat at 0): the default
    assert batch[4] == 0.0


@pytest.mark.parametrize("fmt", ["fcl", "fll", "fis", "rules"])
def test_writing_inputs_as_given_says_it_is_left_out_where_the_format_has_no_word(fmt):
    """FCL and `.fis` cannot say it (a note); FLL says `lock-range: false` on every input, the
    rule language `inputs = as_given`."""
    import dataclasses

    from test_interop_fcl_grammar import BASE

    from mitos_cli.interop import conversion_notes
    from mitos_cli.interop.rules_writer import write_rules
    from mitos_cli.lang.model import Setting

    rb = parse_fcl(BASE, "probe.fcl")
    given = (Setting("inputs", "as_given"),)
    rb = dataclasses.replace(rb, behaviors=tuple(dataclasses.replace(b, operators=b.operators + given)
                                                 for b in rb.behaviors))
    notes = [n for n in conversion_notes(rb, fmt) if "as_given" in n]
    assert bool(notes) == (fmt in ("fcl", "fis")), notes
    if fmt == "fll":
        from mitos_cli.interop.fll import parse_fll, write_fll

        text = write_fll(rb)
        assert text.count("lock-range: false") == 3 and "lock-range: true" not in text
        assert parse_fll(text, "back.fll").operators[-1] == Setting("inputs", "as_given")
    if fmt == "rules":
        assert "inputs = as_given" in write_rules(rb, "probe.terms.yaml")[0]


def test_inputs_in_a_rule_file_and_an_unknown_value(tmp_path):
    from mitos_cli.api import load_rulebase
    from mitos_cli.errors import MitosError

    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  a: {role: input, universe: [0, 10], terms: {hi: {shape: triangle, "
        "points: [0, 10, 10]}}}\n  y: {role: output, universe: [0, 1], default: 0, "
        "terms: {z: 1}}\n")
    path = tmp_path / "t.rules"
    path.write_text('terms "t.terms.yaml"\noperators: inputs = as_given\nr1: if a is hi then y is z\n')
    rb = load_rulebase(path)
    assert rb.compiled.operators.inputs == "as_given"
    got = rb.run(np.array([[12.0], [10.0], [9.0]]), detail=False).outputs[:, 0]
    assert got.tolist() == [0.0, 1.0, 1.0]      # 12: the triangle is 0 there (clamped: 1)
    path.write_text('terms "t.terms.yaml"\noperators: inputs = as_giv\nr1: if a is hi then y is z\n')
    with pytest.raises(MitosError) as info:
        _ = load_rulebase(path).compiled
    assert info.value.message == "unknown inputs `as_giv`"
    assert info.value.hint == "did you mean `as_given`?"
    assert info.value.span is not None and info.value.span.line == 2


@given(st.lists(st.tuples(st.floats(-1e6, 1e6), st.floats(-30, 40)), min_size=1, max_size=20))
@settings(max_examples=60, deadline=None)
def test_as_given_rows_are_the_same_bits_alone_or_batched(rows):
    """The paper's determinism under `inputs = as_given`: a row gives the same bits alone
    (the scalar form where there is one) as in any batch, inside or outside the ranges."""
    from test_interop_fcl_grammar import BASE

    from mitos_cli.api import LoadedRuleBase
    from mitos_cli.engine.evaluation import evaluate_one
    from mitos_cli.interop.common import fidelity_settings

    for text in (BASE, BASE.replace("METHOD : COG;", "METHOD : COGS;").replace(
            "TERM lo := (0, 0) (2, 1) (4, 0);", "TERM lo := 2;").replace(
            "TERM hi := (6, 0) (8, 1) (10, 0);", "TERM hi := 8;")):
        rb = parse_fcl(text, "p.fcl")
        c = LoadedRuleBase(rb, None, fidelity_settings(rb, "jfuzzylogic")).compiled
        X = np.array(rows)
        batch = evaluate(c, X, detail=False, strict=False).outputs
        alone = np.array([evaluate_one(c, list(r), strict=False) for r in rows])
        assert batch.tobytes() == alone.tobytes()
