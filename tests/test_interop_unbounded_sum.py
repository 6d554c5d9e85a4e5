"""The unbounded sum as a Mamdani aggregation (`aggregation = sum`): MATLAB's
``AggMethod='sum'``, jFuzzyLogic's ``ACCU : SUM`` (and its default without ACCU), fuzzylite's
``UnboundedSum``; read, written, computed and refused as an OR.

The recorded numbers come from the engines themselves, run by hand on the files below (no
engine runs here): jFuzzyLogic built from source (``OracleGrid``, full precision), Octave's
fuzzy-logic-toolkit (``evalfis``, ``format long``) and the fuzzylite 6 binary (``-of fld
-decimals 12``), at (a, b) = (2, 3), (6, 7), (8.5, 1). Four rules, three overlapping output
triangles, two rules concluding ``m``: the summed set exceeds the max one where they overlap.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.api import LoadedRuleBase, load_rulebase
from mitos_cli.engine import mamdani
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate, tree_sum
from mitos_cli.errors import FormatError, MitosError
from mitos_cli.fuzzy import norms
from mitos_cli.interop import common
from mitos_cli.interop.fcl import parse_fcl, write_fcl
from mitos_cli.interop.fis import parse_fis, write_fis
from mitos_cli.interop.fll import parse_fll, write_fll

X = np.array([[2.0, 3.0], [6.0, 7.0], [8.5, 1.0]])

FCL = """FUNCTION_BLOCK summed
VAR_INPUT
    a : REAL; RANGE := (0 .. 10);
    b : REAL; RANGE := (0 .. 10);
END_VAR
VAR_OUTPUT
    y : REAL;
END_VAR
FUZZIFY a
    TERM lo := (0, 1) (10, 0);
    TERM hi := (0, 0) (10, 1);
END_FUZZIFY
FUZZIFY b
    TERM lo := (0, 1) (10, 0);
    TERM hi := (0, 0) (10, 1);
END_FUZZIFY
DEFUZZIFY y
    TERM s := TRIAN 0 3 6;
    TERM m := TRIAN 2 5 8;
    TERM l := TRIAN 4 7 10;
    METHOD : COG;
    DEFAULT := 0;
    RANGE := (0 .. 10);
END_DEFUZZIFY
RULEBLOCK No1
    AND : MIN;
    ACT : MIN;
    ACCU : SUM;
    RULE 1 : IF a IS lo THEN y IS s;
    RULE 2 : IF a IS hi AND b IS lo THEN y IS m;
    RULE 3 : IF b IS hi THEN y IS l;
    RULE 4 : IF a IS lo AND b IS hi THEN y IS m;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""
#: jFuzzyLogic (OracleGrid) on FCL, and on FCL without its ACCU line (the same: its default)
JFL_SUM = [4.615384615384671, 5.200000000000005, 4.892966360856254]
#: ... and with ``ACCU : MAX`` (so the sum is what moved them)
JFL_MAX = [4.3382352941176014, 5.374133949191706, 4.894391842680212]

FIS = """[System]
Name='summed'
Type='mamdani'
Version=2.0
NumInputs=2
NumOutputs=1
NumRules=4
AndMethod='min'
OrMethod='max'
ImpMethod='IMP'
AggMethod='sum'
DefuzzMethod='centroid'

[Input1]
Name='a'
Range=[0 10]
NumMFs=2
MF1='lo':'trimf',[-10 0 10]
MF2='hi':'trimf',[0 10 20]

[Input2]
Name='b'
Range=[0 10]
NumMFs=2
MF1='lo':'trimf',[-10 0 10]
MF2='hi':'trimf',[0 10 20]

[Output1]
Name='y'
Range=[0 10]
NumMFs=3
MF1='s':'trimf',[0 3 6]
MF2='m':'trimf',[2 5 8]
MF3='l':'trimf',[4 7 10]

[Rules]
1 0, 1 (1) : 1
2 1, 2 (1) : 1
0 2, 3 (1) : 1
1 2, 2 (1) : 1
"""
#: Octave's fuzzy-logic-toolkit evalfis, ImpMethod 'min' and 'prod'
OCTAVE = {"min": [4.615384615384612, 5.199999999999999, 4.893269884432362],
          "prod": [4.375000000000002, 5.333333333333337, 4.916666666666665]}

FLL = """Engine: summed
InputVariable: a
  range: 0 10
  term: lo Trapezoid -inf -inf 0 10
  term: hi Trapezoid 0 10 inf inf
InputVariable: b
  range: 0 10
  term: lo Trapezoid -inf -inf 0 10
  term: hi Trapezoid 0 10 inf inf
OutputVariable: y
  range: 0 10
  aggregation: UnboundedSum
  defuzzifier: Centroid
  default: 0
  term: s Triangle 0 3 6
  term: m Triangle 2 5 8
  term: l Triangle 4 7 10
RuleBlock: main
  conjunction: Minimum
  disjunction: Maximum
  implication: Minimum
  activation: General
  rule: if a is lo then y is s
  rule: if a is hi and b is lo then y is m
  rule: if b is hi then y is l
  rule: if a is lo and b is hi then y is m
"""
#: the fuzzylite 6 binary (its Centroid: 100 midpoints when the file writes no resolution)
FUZZYLITE6 = [4.615384615385, 5.200000000000, 4.892663043478]


def outputs(tmp_path: Path, name: str, text: str, engine: str | None = None) -> np.ndarray:
    path = tmp_path / name
    path.write_text(text)
    rb = load_rulebase(path)
    if engine is not None:
        rb = LoadedRuleBase(rb.rulebase, None, common.fidelity_settings(rb.rulebase, engine))
    return rb.run(X, detail=False).outputs[:, 0]


@pytest.mark.parametrize("accu", ["ACCU : SUM;", "ACCU : UNSUM;", ""])
def test_fcl_sum_agrees_with_jfuzzylogic(tmp_path, accu):
    """ACCU : SUM, and no ACCU at all (jFuzzyLogic's default), are the unbounded sum."""
    y = outputs(tmp_path, "s.fcl", FCL.replace("ACCU : SUM;", accu), "jfuzzylogic")
    assert y == pytest.approx(JFL_SUM, abs=1e-12)
    y = outputs(tmp_path, "m.fcl", FCL.replace("ACCU : SUM;", "ACCU : MAX;"), "jfuzzylogic")
    assert y == pytest.approx(JFL_MAX, abs=1e-12)


@pytest.mark.parametrize("imp", ["min", "prod"])
def test_fis_sum_agrees_with_octave(tmp_path, imp):
    assert outputs(tmp_path, "s.fis", FIS.replace("IMP", imp)) == pytest.approx(OCTAVE[imp],
                                                                                 abs=1e-12)


def test_fll_unbounded_sum_agrees_with_fuzzylite(tmp_path):
    assert outputs(tmp_path, "s.fll", FLL, "fuzzylite6") == pytest.approx(FUZZYLITE6, abs=1e-12)


def test_every_reader_reads_the_sum_and_every_writer_writes_it():
    rbs = [parse_fcl(FCL, "s.fcl"), parse_fis(FIS.replace("IMP", "min"), "s.fis"),
           parse_fll(FLL, "s.fll")]
    for rb in rbs:
        assert compile_rulebase(rb).operators.aggregation == "sum"
        assert "AggMethod='sum'" in write_fis(rb)
        assert "ACCU : SUM;" in write_fcl(rb, dialect="iec")             # jFuzzyLogic's name
        # fuzzylite 6's FCL reader knows it by class name only (`ACCU : SUM` fails its import)
        assert "ACCU : UnboundedSum;" in write_fcl(rb)
        assert "aggregation: UnboundedSum" in write_fll(rb)
        for parse, write, name in ((parse_fis, write_fis, "b.fis"), (parse_fcl, write_fcl, "b.fcl"),
                                   (parse_fcl, partial(write_fcl, dialect="iec"), "b.fcl"),
                                   (parse_fll, write_fll, "b.fll")):
            back = compile_rulebase(parse(write(rb), name))
            assert back.operators.aggregation == "sum"


def test_the_summed_set_is_the_sum_of_the_implied_sets():
    """Above 1 where two sets overlap; every defuzzifier reads it."""
    c = compile_rulebase(parse_fcl(FCL, "s.fcl"))
    table = c.mamdani[0]
    dof = evaluate(c, X).dof.T[table.rules]
    Y = mamdani.aggregate(dof, table.sets[table.set_of], "min", norms.aggregation("sum"))
    stack = np.minimum(dof[:, :, None], table.sets[table.set_of][:, None, :])
    assert pytest.approx(stack.sum(axis=0), abs=1e-15) == Y
    assert (stack.max(axis=0) + 1e-9 < Y).any()           # where two implied sets overlap
    for method in ("centroid", "bisector", "mom", "som", "lom", "matlab_bisector",
                   "matlab_som", "matlab_lom"):
        assert np.isfinite(mamdani.defuzzify(Y, table.grid, method)).all()


@given(st.lists(st.floats(0, 1), min_size=1, max_size=9), st.integers(1, 7))
@settings(max_examples=60, deadline=None)
def test_the_sum_is_the_engines_fixed_pairwise_order(dofs, batch):
    """The aggregation adds in ``tree_sum``'s order, fixed by the number of rules alone: a
    sample gives the same bits alone or in any batch."""
    sets = np.linspace(0.1, 0.9, len(dofs) * 5).reshape(len(dofs), 5)
    dof = np.tile(np.array(dofs)[:, None], (1, batch))
    Y = mamdani.aggregate(dof, sets, "product", norms.aggregation("sum"))
    want = tree_sum((dof[:, :, None] * sets[:, None, :]).copy())
    assert np.array_equal(Y, want)
    alone = mamdani.aggregate(dof[:, :1], sets, "product", norms.aggregation("sum"))
    assert np.array_equal(alone[0], Y[-1])


@pytest.mark.parametrize("value", ["sum", "unbounded_sum"])
def test_or_sum_is_refused_as_an_aggregation_only(tmp_path, value):
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  a: {role: input, universe: [0, 1], terms: {lo: {shape: left_shoulder, "
        "points: [0, 1]}}}\n  y: {role: output, universe: [0, 1], terms: {z: 0.5}}\n")
    path = tmp_path / "t.rules"
    path.write_text(f'terms "t.terms.yaml"\noperators: or = {value}\nr1: if a is lo then y is z\n')
    with pytest.raises(MitosError) as info:
        _ = load_rulebase(path).compiled
    assert "a Mamdani aggregation only" in info.value.message
    assert "bounded_sum" in (info.value.hint or "")
    path.write_text(f'terms "t.terms.yaml"\noperators: inference = mamdani, aggregation = {value}\n'
                    "r1: if a is lo then y is z\n")
    assert load_rulebase(path).compiled.operators.aggregation == "sum"


@pytest.mark.parametrize("text, name, words", [
    (FIS.replace("IMP", "min").replace("OrMethod='max'", "OrMethod='sum'"), "s.fis",
     "a Mamdani aggregation only"),
    (FLL.replace("disjunction: Maximum", "disjunction: UnboundedSum"), "s.fll",
     "a Mamdani aggregation only"),
])
def test_a_format_s_sum_as_or_is_refused(text, name, words):
    parse = {"s.fis": parse_fis, "s.fll": parse_fll}[name]
    with pytest.raises(FormatError) as info:
        parse(text, name)
    assert words in info.value.message


def test_a_takagi_sugeno_output_with_unbounded_sum_reads_as_none():
    """fuzzylite 8 joins the weights of the rules concluding one term with the output's
    aggregation: the unbounded sum adds them, as MITOS counts every rule (`aggregation: none`)."""
    text = """Engine: ts
InputVariable: a
  range: 0 10
  term: low Triangle 0 2 5
  term: high Triangle 5 8 10
InputVariable: b
  range: 0 1
  term: small Ramp 1 0
  term: big Ramp 0 1
OutputVariable: y
  range: 0 1
  aggregation: none
  defuzzifier: WeightedAverage TakagiSugeno
  term: off Constant 0.2
  term: on Linear 0.01 0.5 0.1
RuleBlock: main
  conjunction: Minimum
  disjunction: Maximum
  implication: none
  rule: if a is low and b is small then y is off
  rule: if a is high or b is big then y is off with 0.5
  rule: if b is big then y is on
"""
    none = compile_rulebase(parse_fll(text, "s.fll"))
    summed = compile_rulebase(parse_fll(text.replace("aggregation: none",
                                                     "aggregation: UnboundedSum"), "s.fll"))
    assert summed.operators == none.operators
    grid = np.array([[1.0, 0.2], [6.0, 0.7], [3.0, 0.9]])
    assert np.array_equal(evaluate(summed, grid).outputs, evaluate(none, grid).outputs)


def test_the_rule_view_shows_a_summed_set_above_1():
    """The aggregate's axis stopped at 1.12: a summed set above 1 was cut off."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mitos_cli.draw.data.ruleviews import OutputView
    from mitos_cli.draw.rules import draw_aggregate

    grid = np.linspace(0, 10, 101)
    fig, ax = plt.subplots()
    try:
        draw_aggregate(ax, OutputView("y", "", (0.0, 10.0), "mamdani", 5.0, False, grid=grid,
                                      aggregate=1.6 * np.exp(-(grid - 5) ** 2)))
        assert ax.get_ylim()[1] > 1.6
    finally:
        plt.close(fig)


def test_check_samples_a_summed_behavior():
    """`mitos check`'s grid evaluates the summed Mamdani behavior like any other."""
    from mitos_cli.engine.check import check_rulebase

    report = check_rulebase(parse_fcl(FCL, "s.fcl"))
    assert [f for f in report.findings if f.severity == "error"] == []


def test_a_study_s_or_of_sum_is_refused_as_an_aggregation_only():
    from mitos_cli.study.spec import canonical_snorm

    with pytest.raises(MitosError) as info:
        canonical_snorm("sum", "min")
    assert "a Mamdani aggregation only" in info.value.message
    assert "bounded_sum" in (info.value.hint or "")
