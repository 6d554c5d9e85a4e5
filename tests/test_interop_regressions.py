"""Regression tests for foreign files that loaded wrongly or not at all, each on a small file
of its own: names that begin with hedge words, MATLAB comments and padded parameters,
jFuzzyLogic's FCL constructs, each format's shape definitions, non-finite numbers, and the
batch's no-rule-fired policy."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from mitos_cli.api import load_rulebase, read_rulebase
from mitos_cli.errors import MitosError
from mitos_cli.interop.fcl import parse_fcl
from mitos_cli.interop.fis import parse_fis
from mitos_cli.interop.fll import parse_fll
from mitos_cli.lang.parse import parse_rules


def outputs(rb, **inputs):
    from mitos_cli.engine.compile import compile_rulebase
    from mitos_cli.engine.evaluation import as_batch, evaluate

    c = compile_rulebase(rb)
    return dict(zip(c.outputs, evaluate(c, as_batch(c, inputs), strict=False).outputs[0]))


# ---------------------------------------------------------------------------------------------
# Hedge words are whole words

FLL_HEDGE_PREFIX = """\
Engine: e
InputVariable: x
  range: 0 10
  term: veryhigh Triangle 0 10 10
  term: high Triangle 0 10 10
OutputVariable: y
  range: 0 10
  defuzzifier: WeightedAverage
  default: nan
  term: anyway Constant 8
  term: low Constant 2
RuleBlock: b
  conjunction: Minimum
  disjunction: Maximum
  rule: if x is veryhigh then y is anyway
  rule: if x is notable then y is low
"""


def test_rule_language_reads_a_name_beginning_with_a_hedge_as_a_name():
    rb = parse_rules("behavior b:\n if x is veryhigh then y is anyway\n"
                     " if x is notable then y is somewhat_low\n if x is very high then y is low\nend\n")
    a, b, c = rb.behaviors[0].rules
    assert (a.antecedent.term, a.antecedent.hedges) == ("veryhigh", ())
    assert a.consequents[0].term == "anyway"
    assert (b.antecedent.term, b.antecedent.negated) == ("notable", False)
    assert b.consequents[0].term == "somewhat_low"
    assert (c.antecedent.term, c.antecedent.hedges) == ("high", ("very",))


def test_fll_reads_a_name_beginning_with_a_hedge_as_a_name():
    text = FLL_HEDGE_PREFIX.replace("rule: if x is notable then y is low\n", "")
    rb = parse_fll(text)
    rule = rb.behaviors[0].rules[0]
    assert (rule.antecedent.term, rule.antecedent.hedges) == ("veryhigh", ())
    assert outputs(rb, x=5.0)["y"] == pytest.approx(8.0)


# ---------------------------------------------------------------------------------------------
# MATLAB .fis as MATLAB and fuzzylite write it

FIS = """\
% $Revision: 1.1 $
#Code automatically generated with fuzzylite
[System]
Name='small'
Type='mamdani'
NumInputs=1
NumOutputs=1
NumRules=2
AndMethod='einstein_product'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='centroid'

[Input1]
Name='x'
Range=[0 10]
NumMFs=2
MF1='low':'gbellmf',[3 2 0 0]
MF2='low':'trimf',[0 10 10]

[Output1]
Name='y'
Range=[0 10]
NumMFs=2
MF1='a':'trimf',[0 0 10]
MF2='b':'trimf',[0 10 10]

[Rules]
% the two rules
1, 1 (1) : 1
2, 2 (1) : 1
"""


def test_fis_skips_comment_lines_and_reads_padded_lists_and_octave_names():
    rb = parse_fis(FIS, "small.fis")
    x = rb.variables["x"]
    assert x.terms[0].shape == "bell" and x.terms[0].params == (0.0, 3.0, 2.0)
    assert any(s.key == "and" and s.value == "einstein" for s in rb.operators)


def test_fis_keeps_duplicate_mf_names_apart_and_says_so():
    rb = parse_fis(FIS, "small.fis")
    assert rb.variables["x"].term_names == ("low", "low_2")
    r2 = rb.behaviors[0].rules[1]
    assert (r2.antecedent.term, r2.consequents[0].term) == ("low_2", "b")
    assert len(rb.notes) == 1 and "small.fis:20:" in rb.notes[0] and "`low_2`" in rb.notes[0]


def test_fis_padded_list_with_a_nonzero_extra_number_is_refused():
    with pytest.raises(MitosError, match="gbellmf takes 3 numbers, not 4"):
        parse_fis(FIS.replace("[3 2 0 0]", "[3 2 0 1]"), "small.fis")


# ---------------------------------------------------------------------------------------------
# jFuzzyLogic's FCL

from typer.testing import CliRunner  # noqa: E402

from mitos_cli.cli.app import app  # noqa: E402

runner = CliRunner(env={"COLUMNS": "200", "NO_COLOR": "1"})

JFUZZY = """\
FUNCTION_BLOCK t
VAR_INPUT
    x : REAL RANGE := (0 .. 10);
    unused : REAL;
END_VAR
VAR_OUTPUT
    y : REAL;
END_VAR
FUZZIFY x
    TERM low := gauss 2 1;
    TERM high := gauss 8 1;
END_FUZZIFY
FUZZIFY unused
    TERM a := sigm 2 5;
END_FUZZIFY
DEFUZZIFY y
    TERM a := dsigm 4 2 1 6;
    TERM b := gbell 2 3 8;
    METHOD : COG;
    DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK r
    AND : MIN;
    ACT : MIN;
    ACCU : MAX;
    RULE 1 : IF NOT x IS low THEN y IS b;
    RULE 2 : IF x IS low THEN y IS a;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_fcl_reads_not_before_a_proposition_and_range_in_var_input():
    rb = parse_fcl(JFUZZY, "t.fcl")
    from mitos_cli.lang.model import Not, Prop

    r1 = rb.behaviors[0].rules[0]
    assert r1.antecedent == Not(Prop("x", "low"))
    assert rb.variables["x"].universe == (0.0, 10.0)


def test_fcl_derives_a_missing_range_from_unbounded_terms_as_jfuzzylogic():
    rb = parse_fcl(JFUZZY, "t.fcl")
    # sigm 2 5: 5 -+ 9/2; dsigm 4 2 1 6: [min(2 - 9/4, 6 - 9), max(2 + 9/4, 6 + 9)];
    # gbell 2 3 8: 8 -+ 2 * 999^(1/6)
    assert rb.variables["unused"].universe == (0.5, 9.5)
    lo, hi = rb.variables["y"].universe
    assert lo == pytest.approx(-3.0) and hi == pytest.approx(15.0)
    assert any("`y` has no RANGE" in n and "t.fcl:16:1" in n for n in rb.notes)


def test_fcl_dsigm_is_jfuzzylogics_clipped_difference():
    rb = parse_fcl(JFUZZY, "t.fcl")
    term = rb.variables["y"].term("a")
    x = np.array([-2.0, 2.0, 6.0, 9.0, 12.0, np.nan])
    s1 = 1 / (1 + np.exp(-4 * (x - 2)))
    s2 = 1 / (1 + np.exp(-1 * (x - 6)))
    from mitos_cli.fuzzy.shapes import SHAPES

    got = SHAPES[term.shape].membership(x, term.params)
    np.testing.assert_allclose(got[:-1], np.maximum(s1 - s2, 0)[:-1], rtol=0, atol=1e-15)
    assert got[0] == 0.0 and np.isnan(got[-1])     # |s1 - s2| would give 3.4e-4 at -2


def test_fcl_function_terms_and_blocks_of_one_name_are_refused_by_name():
    """A FUNCTION term is a linear Takagi-Sugeno consequent now: under a Mamdani METHOD it is
    refused as such (jFuzzyLogic throws there too: a discrete term, a continuous defuzzifier)."""
    text = JFUZZY.replace("TERM b := gbell 2 3 8;", "TERM b := FUNCTION (x * 2);")
    with pytest.raises(MitosError) as info:
        parse_fcl(text, "t.fcl")
    assert info.value.message == ("output term `y.b`: linear terms need a weighted-average "
                                  "(Takagi-Sugeno) defuzzifier") and info.value.span.line == 18
    with pytest.raises(MitosError) as info:
        parse_fcl(JFUZZY + JFUZZY, "t.fcl")
    assert info.value.message == "two function blocks are named `t`"
    assert info.value.span.line == 30


def test_fcl_function_blocks_are_behaviors_of_their_names():
    """jFuzzyLogic reads several FUNCTION_BLOCKs in one file, each by its name (its junit2 and
    scarled examples); MITOS refused the file. Each is now a behavior of that name, over the
    variables of all; one variable defined alike is shared, differently refused."""
    second = JFUZZY.replace("FUNCTION_BLOCK t", "FUNCTION_BLOCK u")
    rb = parse_fcl(JFUZZY + second, "t.fcl")
    assert [b.name for b in rb.behaviors] == ["t", "u"] and rb.default_behavior == "t"
    assert list(rb.variables) == [v.name for v in parse_fcl(JFUZZY, "t.fcl").termsets[0].variables]
    from mitos_cli.engine.compile import compile_rulebase
    from mitos_cli.engine.evaluation import evaluate

    X = np.array([[3.0], [8.5]])
    alone = evaluate(compile_rulebase(parse_fcl(JFUZZY, "t.fcl")), X).outputs
    assert np.array_equal(evaluate(compile_rulebase(rb, "u"), X).outputs, alone)
    other = second.replace("TERM b := gbell 2 3 8;", "TERM b := gbell 2 3 7;")
    with pytest.raises(MitosError) as info:
        parse_fcl(JFUZZY + other, "t.fcl")
    assert info.value.message == ("variable `y` is defined in two function blocks, differently "
                                  "(first at line 16)")
    assert info.value.span.line == 45


def test_batch_accepts_a_column_for_an_input_no_rule_tests(tmp_path: Path):
    path = tmp_path / "t.fcl"
    path.write_text(JFUZZY)
    csv = tmp_path / "in.csv"
    csv.write_text("x,unused\n1,2\n8,3\n")
    result = runner.invoke(app, ["eval", str(path), "--batch", str(csv)])
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()      # read, ignored by the rules, passed through
    assert lines[0] == "x,y,unused" and len(lines) == 3 and lines[1].endswith(",2")
    result = runner.invoke(app, ["eval", str(path), "x=1", "unused=2"])
    assert result.exit_code == 0, result.output


# ---------------------------------------------------------------------------------------------
# No rule fired in a batch

DIMMER = """\
Engine: dimmer
InputVariable: light
  range: 0 1
  term: DARK Triangle 0.2 0.4 0.6
  term: BRIGHT Triangle 0.4 0.6 0.8
OutputVariable: power
  range: 0 1
  defuzzifier: WeightedAverage
  default: nan
  term: HIGH Constant 0.9
  term: LOW Constant 0.1
RuleBlock: b
  conjunction: Minimum
  disjunction: Maximum
  rule: if light is DARK then power is HIGH
  rule: if light is BRIGHT then power is LOW
"""


def batch(tmp_path: Path, fll: str, *options: str):
    path = tmp_path / "dimmer.fll"
    path.write_text(fll)
    csv = tmp_path / "in.csv"
    csv.write_text("light\n0.1\n0.4\n0.5\n0.9\n")
    return runner.invoke(app, ["eval", str(path), "--batch", str(csv), *options])


def test_batch_honours_a_declared_nan_default_and_counts_the_rows(tmp_path: Path):
    result = batch(tmp_path, DIMMER)
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines() == ["light,power", "0.1,nan", "0.4,0.9", "0.5,0.5",
                                          "0.9,nan"]
    assert "no rule sets `power` in 2 rows of 4: the file's default (nan)" in result.stderr


def test_batch_without_a_declared_default_stops_unless_asked(tmp_path: Path):
    fll = DIMMER.replace("  default: nan\n", "")
    result = batch(tmp_path, fll)
    assert result.exit_code == 1 and "no rule sets `power` for light=0.1 (row 1; 2 of 4 rows)" \
        in str(result.exception) and "--on-no-rule" in result.exception.hint
    assert str(result.exception.span) == f"{tmp_path / 'in.csv'}:2:1"
    result = batch(tmp_path, fll, "--on-no-rule", "nan")
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines() == ["light,power,no_rule", "0.1,nan,power", "0.4,0.9,",
                                          "0.5,0.5,", "0.9,nan,power"]
    result = batch(tmp_path, fll, "--on-no-rule", "skip")
    assert result.stdout.splitlines() == ["light,power,no_rule", "0.4,0.9,", "0.5,0.5,"]
    assert "in 2 rows of 4: left out" in result.stderr
    result = batch(tmp_path, DIMMER.replace("default: nan", "default: 0.5"), "--on-no-rule",
                   "default")
    assert result.stdout.splitlines()[1] == "0.1,0.5,power"
    result = batch(tmp_path, DIMMER, "--on-no-rule", "error")
    assert result.exit_code == 1      # the row's place in the file, as other batch errors
    assert str(result.exception.span) == f"{tmp_path / 'in.csv'}:2:1"


def test_api_gives_nan_only_where_the_rule_base_asked_for_it():
    from mitos_cli.errors import NoRuleFiredError

    rb = load_rulebase_text(DIMMER)
    assert math.isnan(rb.evaluate(light=0.1)["power"])
    with pytest.raises(NoRuleFiredError):
        load_rulebase_text(DIMMER.replace("  default: nan\n", "")).evaluate(light=0.1)


def load_rulebase_text(fll: str):
    from mitos_cli.api import LoadedRuleBase

    return LoadedRuleBase(parse_fll(fll, "dimmer.fll"))


# ---------------------------------------------------------------------------------------------
# Numbers floating point cannot evaluate are refused where they are written

TIPPER_FIS = (Path(__file__).parent / "data" / "interop" / "tipper.fis").read_text()


@pytest.mark.parametrize("old, new, line, words", [
    ("TERM bad := (0, 1) (4, 0);", "TERM bad := (4, 1) (NaN, 0);", 10, "must be a finite"),
    ("TERM bad := (0, 1) (4, 0);", "TERM bad := (0, 1) (1e308, 0);", 10, "beyond"),
    ("RANGE := (0 .. 10);", "RANGE := (0 .. inf);", 9, "the range is inf"),
    ("DEFAULT := 5;", "DEFAULT := 50;", 15, "default 50 lies outside"),
    ("DEFAULT := 5;", "DEFAULT := inf;", 15, "default is inf"),
])
def test_fcl_non_finite_and_extreme_numbers_are_refused(old, new, line, words):
    text = """\
FUNCTION_BLOCK f
VAR_INPUT
    x : REAL;
END_VAR
VAR_OUTPUT
    y : REAL;
END_VAR
FUZZIFY x
    RANGE := (0 .. 10);
    TERM bad := (0, 1) (4, 0);
    TERM good := (2, 0) (10, 1);
END_FUZZIFY
DEFUZZIFY y
    TERM a := (0, 0) (5, 1) (10, 0);
    DEFAULT := 5;
    RANGE := (0 .. 10);
END_DEFUZZIFY
RULEBLOCK r
    RULE 1 : IF x IS bad THEN y IS a;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""
    assert old in text
    parse_fcl(text, "f.fcl")
    with pytest.raises(MitosError) as info:
        parse_fcl(text.replace(old, new), "f.fcl")
    assert words in info.value.message
    assert info.value.span is not None and info.value.span.line in (line, 8, 13)


@pytest.mark.parametrize("old, new, words", [
    ("term: veryhigh Triangle 0 10 10", "term: veryhigh Trapezoid 0 1e309 inf inf",
     "`1e309` is past a float's range"),
    ("range: 0 10\n  defuzzifier", "range: 0 inf\n  defuzzifier", "the range is inf"),
    ("default: nan", "default: 1000", "default 1000 lies outside its range [0, 10]"),
    ("term: anyway Constant 8", "term: anyway Constant nan", "must be a finite"),
])
def test_fll_non_finite_and_out_of_range_numbers_are_refused(old, new, words):
    assert old in FLL_HEDGE_PREFIX
    with pytest.raises(MitosError) as info:
        parse_fll(FLL_HEDGE_PREFIX.replace(old, new), "e.fll")
    assert words in info.value.message and info.value.span is not None


@pytest.mark.parametrize("old, new, words", [
    ("Range=[0 30]", "Range=[0 inf]", "the range is inf"),
    ("Range=[0 10]", "Range=[0 1e300]", "beyond"),
    # six digits printed 1.0000001e150 as 1e+150, "beyond ±1e+150"
    ("Range=[0 10]", "Range=[0 1.0000001e150]", "is 1.0000001e+150: numbers beyond ±1e+150"),
    ("1 1, 1 (1) : 2", "9" * 400 + " 1, 1 (1) : 2", "`9999999999...999999` (400 characters) is past"),
    ("1 1, 1 (1) : 2", "1 1, 1.5 (1) : 2", "fractional"),
    ("1 1, 1 (1) : 2", "1 1, 1 (1) : 99999999999999999999", "connection"),
    ("1 1, 1 (1) : 2", "1 1, 1 (1e999) : 2", "`1e999` is past a float's range"),
])
def test_fis_non_finite_and_extreme_numbers_are_refused(old, new, words):
    assert old in TIPPER_FIS, old
    with pytest.raises(MitosError) as info:
        parse_fis(TIPPER_FIS.replace(old, new, 1), "tipper.fis")
    assert words in info.value.message and info.value.span is not None


def test_a_bad_default_is_refused_at_its_own_line():
    """The default's line, not the variable's header (`OutputVariable: y`, `DEFUZZIFY tip`)."""
    fll = FLL_HEDGE_PREFIX.replace("default: nan", "default: 1000")
    fis = TIPPER_FIS.replace("Range=[0 30]", "Range=[0 30]\nDefault=40")
    fcl = (Path(__file__).parent / "data" / "interop" / "tipper_jfuzzylogic.fcl").read_text()
    assert "DEFAULT := 0;" in fcl
    for parse, text, line in (
            (parse_fll, fll, fll.splitlines().index("  default: 1000") + 1),
            (parse_fis, fis, fis.splitlines().index("Default=40") + 1),
            (parse_fcl, fcl.replace("DEFAULT := 0;", "DEFAULT := 1e200;"),
             next(i + 1 for i, t in enumerate(fcl.splitlines()) if "DEFAULT := 0;" in t))):
        with pytest.raises(MitosError, match="default") as info:
            parse(text, "f")
        assert info.value.span.line == line, info.value


def test_fis_section_numbers_too_long_for_int_are_refused():
    with pytest.raises(MitosError, match="unknown section"):
        parse_fis(TIPPER_FIS.replace("[Input1]", "[Input" + "9" * 5000 + "]"), "tipper.fis")


# ---------------------------------------------------------------------------------------------
# Round trips and sampling

HYPHEN_FIS = FIS.replace("Name='x'", "Name='LDL-Level'").replace("AndMethod='einstein_product'",
                                                                   "AndMethod='min'")


@pytest.mark.parametrize("fmt", ["fll", "fcl", "fis"])
def test_hyphenated_and_reserved_names_are_mapped_to_legal_ones(fmt):
    from mitos_cli.interop import conversion_notes, parse_foreign, write_foreign

    rb = parse_fis(HYPHEN_FIS.replace("MF1='low'", "MF1='very'"), "h.fis")
    back = parse_foreign(write_foreign(rb, fmt), fmt, f"h.{fmt}")
    want = "LDL-Level" if fmt == "fis" else "LDL_Level"
    assert [v.name for v in back.variables.values()][0] == want
    notes = conversion_notes(rb, fmt)
    if fmt != "fis":
        assert any("`LDL-Level` is written as `LDL_Level`" in n for n in notes)
        assert any("`LDL-Level.very` is written as `very_`" in n for n in notes)
    for x in (1.0, 4.0, 9.0):         # FLL and FCL sample 1000 midpoints, .fis 101 ends
        assert outputs(back, **{want: x})["y"] == pytest.approx(
            outputs(rb, **{"LDL-Level": x})["y"], abs=0.05)


def test_fll_shoulders_are_written_to_the_term_set_as_shoulders(tmp_path: Path):
    from mitos_cli.interop.rules_writer import write_rules

    text = FLL_HEDGE_PREFIX.replace("term: high Triangle 0 10 10",
                                    "term: high Trapezoid -inf -inf 4 7")
    rb = parse_fll(text.replace("rule: if x is notable then y is low\n", ""), "e.fll")
    assert rb.variables["x"].term("high").shape == "left_shoulder"
    rules, terms = write_rules(rb, "e.terms.yaml")
    assert "left_shoulder" in terms and "inf" not in terms
    (tmp_path / "e.rules").write_text(rules)
    (tmp_path / "e.terms.yaml").write_text(terms)
    assert read_rulebase(tmp_path / "e.rules").variables["x"].term("high").shape == \
        "left_shoulder"


def test_convert_warns_with_the_measured_difference(tmp_path: Path):
    source = Path(__file__).parent / "data" / "interop" / "tipper.fis"
    result = runner.invoke(app, ["convert", str(source), "--to", "fll", "-o",
                                 str(tmp_path / "t.fll")])
    assert result.exit_code == 0, result.output
    assert "reading the written FLL back, `tip` moves by up to 0.01" in result.stderr
    result = runner.invoke(app, ["convert", str(source), "--to", "fis", "-o",
                                 str(tmp_path / "t.fis")])
    assert "moves by" not in result.stderr          # .fis to .fis: unchanged


NEG_FIS = """\
[System]
Name='neg'
Type='mamdani'
NumInputs=1
NumOutputs=1
NumRules=2
AndMethod='min'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='{method}'

[Input1]
Name='x'
Range=[0 10]
NumMFs=2
MF1='lo':'trimf',[-10 0 10]
MF2='hi':'trimf',[0 10 20]

[Output1]
Name='steer'
Range=[-10 10]
NumMFs=2
MF1='left':'trapmf',[-9 -7 -3 -1]
MF2='right':'trapmf',[1 3 7 9]

[Rules]
1, 1 (1) : 1
2, 2 (1) : 1
"""


@pytest.mark.parametrize("method, x, want", [
    ("som", 2.1, -2.6), ("lom", 2.1, -7.4), ("som", 7.9, 2.6), ("lom", 7.9, 7.4),
    ("som", 5.0, -2.0), ("lom", 5.0, -8.0),            # ties of -2 and 2, -8 and 8: the first
    ("mom", 2.1, -5.0), ("bisector", 2.1, -4.0), ("bisector", 5.0, -1.2)])
def test_a_fis_files_defuzzifier_is_matlabs(method: str, x: float, want: float):
    """The values are MATLAB's rules applied to Octave's aggregated sets. MATLAB's evalfis takes som and lom by absolute value (its `defuzzSmallestOfMax` keeps
    the maximum's sample nearest 0) and its bisector as the first sample whose running area
    reaches half the total. MITOS took fuzzylite's: the leftmost and rightmost samples (-7.4
    for som where MATLAB gives -2.6, 24% of the range) and the sample whose running area is
    closest to half (one sample off on about half of the inputs)."""
    rb = parse_fis(NEG_FIS.format(method=method), "n.fis")
    from mitos_cli.api import LoadedRuleBase

    got = LoadedRuleBase(rb).run(np.array([[x]]), detail=False).outputs[0, 0]
    assert got == pytest.approx(want, abs=1e-9)


@pytest.mark.parametrize("engine, want", [("matlab", -2.6), ("fuzzylite6", -7.3),
                                           ("fuzzylite", -7.41)])
def test_a_fidelity_computes_som_as_its_engine_defines_it(engine: str, want: float):
    """`--fidelity fuzzylite6` on a .fis file with `som` gave MATLAB's -2.6 at fuzzylite 6's
    sampling, where the `fuzzylite` binary gives -7.3: a fidelity now takes its engine's own
    bisector, som and lom too."""
    from mitos_cli.api import LoadedRuleBase
    from mitos_cli.interop.common import fidelity_settings

    rb = parse_fis(NEG_FIS.format(method="som"), "n.fis")
    loaded = LoadedRuleBase(rb, None, fidelity_settings(rb, engine))
    assert loaded.run(np.array([[2.1]]), detail=False).outputs[0, 0] == pytest.approx(want)


STEP_FIS = NEG_FIS.replace("DefuzzMethod='{method}'", "DefuzzMethod='centroid'").replace(
    "NumMFs=2\nMF1='lo':'trimf',[-10 0 10]\nMF2='hi':'trimf',[0 10 20]", "NumMFs=2\n{mfs}")


@pytest.mark.parametrize("mf, inside, outside", [
    ("'smf',[3 3]", (3.0, 5.0), (2.999, 0.0)), ("'zmf',[3 3]", (3.0, 0.0), (3.001, 10.0)),
    ("'smf',[5 3]", (4.0, 4.5), (3.999,)), ("'zmf',[5 3]", (4.0, 3.5), (4.001,)),
    ("'pimf',[2 2 6 6]", (2.0, 6.0, 4.0), (1.999, 6.001))])
def test_matlabs_step_smf_zmf_and_pimf_are_1_at_the_step(mf: str, inside, outside, tmp_path):
    """MATLAB's `smf [a b]` with a >= b is the step x >= (a + b) / 2 (its `fisSMf`), `zmf` the
    step x <= (a + b) / 2, `pimf` their product. `smf [3 3]` was read as fuzzylite's S shape,
    0 at x = 3 where MATLAB gives 1, and `smf [5 3]` was refused."""
    from mitos_cli.interop import write_foreign

    text = STEP_FIS.format(mfs=f"MF1='lo':{mf}\nMF2='hi':'trimf',[0 10 20]")
    rb = parse_fis(text, "s.fis")
    lo = rb.variables["x"].term("lo")
    assert (lo.membership(np.array(inside)) == 1.0).all()
    assert (lo.membership(np.array(outside)) == 0.0).all()
    again = parse_fis(write_foreign(rb, "fis"), "again.fis").variables["x"].term("lo")
    x = np.linspace(0, 10, 1001)
    assert (again.membership(x) == lo.membership(x)).all()


@pytest.mark.parametrize("mf", ["'linsmf',[6 2]", "'linzmf',[6 2]"])
def test_matlabs_linsmf_and_linzmf_with_feet_reversed_are_refused(mf: str):
    """`linsmf [a b]` rises from its foot a to its shoulder b and `linzmf [a b]` falls from a to
    b; MATLAB defines them for a <= b. With a > b the reader read `linsmf [6 2]` as a ramp
    *falling* from 1 at 2 to 0 at 6 (fuzzylite's `Ramp 6 2`) and `linzmf [6 2]` as a rising
    one: the opposite of what the MF's name says, without a word."""
    text = STEP_FIS.format(mfs=f"MF1='lo':{mf}\nMF2='hi':'trimf',[0 10 20]")
    with pytest.raises(MitosError) as exc:
        parse_fis(text, "r.fis")
    assert exc.value.span is not None and exc.value.span.line == 17
    assert f"{mf.split(',')[0][1:-1]} takes [a b] with a <= b" in str(exc.value)
    assert "write the smaller end first: `linsmf [2 6]` rises" in str(exc.value)


def test_matlabs_linzmf_step_is_refused_by_name():
    """`linzmf [a a]` is 0 at a itself, where a `binary` step (zmf [a a]) is 1: refused,
    where it was refused for "start and end must differ"."""
    text = STEP_FIS.format(mfs="MF1='lo':'linzmf',[4 4]\nMF2='hi':'trimf',[0 10 20]")
    with pytest.raises(MitosError, match=r"`linzmf \[4 4\]` is MATLAB's step 1 below 4 and 0 "
                                         r"from 4 on, which no MITOS shape computes exactly"):
        parse_fis(text, "z.fis")


@pytest.mark.parametrize("mf, ones", [("'linsmf',[4 4]", (4.0, 4.001, 10.0)),
                                      ("'linsmf',[3 5]", (5.0, 7.0))])
def test_matlabs_linsmf_rises_and_its_step_is_read(mf: str, ones):
    """`linsmf [a a]` is MATLAB's step, 0 below a and 1 from a on (its documentation), as
    `smf [a a]` is: it was refused ("start and end must differ")."""
    text = STEP_FIS.format(mfs=f"MF1='lo':{mf}\nMF2='hi':'trimf',[0 10 20]")
    lo = parse_fis(text, "s.fis").variables["x"].term("lo")
    assert (lo.membership(np.array(ones)) == 1.0).all()
    assert (lo.membership(np.array([0.0, 2.0, 2.999])) == 0.0).all()


def test_converting_matlabs_som_to_fuzzylites_says_that_it_moves():
    from mitos_cli.interop import conversion_notes, write_foreign

    rb = parse_fis(NEG_FIS.format(method="som"), "n.fis")
    assert any("FLL has no MATLAB `som`" in n for n in conversion_notes(rb, "fll"))
    assert not any("MATLAB `som`" in n for n in conversion_notes(rb, "rules"))
    fll = parse_fll(write_foreign(parse_fis(NEG_FIS.format(method="lom"), "n.fis"), "fll"), "n.fll")
    assert any("a .fis file's `lom` is MATLAB's" in n for n in conversion_notes(fll, "fis"))


def test_matlabs_bisector_is_the_first_sample_reaching_half_the_area():
    from mitos_cli.engine.mamdani import defuzzify

    x = np.array([0.0, 1.0, 2.0, 3.0])
    Y = np.array([[1.0, 0.0, 0.9, 0.1]])             # running area 1, 1, 1.9, 2: half is 1
    assert defuzzify(Y, x, "matlab_bisector")[0] == 0.0       # reached at the first sample
    assert defuzzify(Y, x, "bisector")[0] == 0.5              # closest: a tie of 0 and 1
    Y = np.array([[0.0, 0.3, 0.3, 0.4]])             # 0, 0.3, 0.6, 1: half reached at x = 2
    assert defuzzify(Y, x, "matlab_bisector")[0] == 2.0
    assert defuzzify(Y, x, "matlab_som")[0] == defuzzify(Y, x, "matlab_lom")[0] == 3.0


def test_a_default_nan_against_a_number_is_told_as_such_not_as_inf(tmp_path: Path):
    """Where no rule fires a .fis file gives MATLAB's mid-range and the FLL its declared NaN:
    the round trip said "`y` moves by up to inf", an infinity nobody computed."""
    from mitos_cli.interop import round_trip_difference, write_foreign

    text = FLL_HEDGE_PREFIX.split("RuleBlock:")[0].replace("high Triangle 0", "high Triangle 5")
    text += ("RuleBlock: b\n  conjunction: Minimum\n  disjunction: Maximum\n"
             "  implication: Minimum\n  rule: if x is high then y is low\n")
    rb = parse_fll(text, "d.fll")
    notes = round_trip_difference(rb, parse_fis(write_foreign(rb, "fis"), "d.fis"), "fis")
    assert not any("inf" in n.split("(")[0] for n in notes), notes
    told = [n for n in notes if "where the rule base gives nan" in n]
    assert len(told) == 1 and "`y` is 5 where the rule base gives nan, on " in told[0]
    assert " of 2,000 seeded inputs and 3 at the universes' ends and middles (first at x=" in told[0]


def test_fidelity_chooses_the_reference_engines_sampling():
    from mitos_cli.engine.mamdani import grid

    assert grid(0.0, 10.0, 4, "left").tolist() == [0.0, 2.5, 5.0, 7.5]
    source = Path(__file__).parent / "data" / "interop" / "tipper.fis"
    got = {}
    for engine in ("matlab", "jfuzzylogic", "fuzzylite"):
        result = runner.invoke(app, ["eval", str(source), "service=2", "food=1",
                                     "--fidelity", engine, "--json"])
        assert result.exit_code == 0, result.output
        import json

        got[engine] = json.loads(result.stdout)["outputs"]
    tip = {k: v["tip"] for k, v in got.items()}
    assert tip["matlab"] == pytest.approx(7.0169, abs=5e-5)       # MATLAB's documented value
    assert tip["jfuzzylogic"] != tip["matlab"] and tip["fuzzylite"] != tip["matlab"]
    # the same as asking for jFuzzyLogic's grid (1000 left cell ends) by operator settings
    rb = load_rulebase(source)
    from mitos_cli.api import LoadedRuleBase
    from mitos_cli.lang.model import Setting

    fine = LoadedRuleBase(rb.rulebase, None, (Setting("resolution", "1000"),
                                              Setting("sampling", "left")))
    assert fine.evaluate(service=2.0, food=1.0)["tip"] == pytest.approx(tip["jfuzzylogic"],
                                                                        abs=1e-9)


def test_fis_reads_fuzzylites_output_keys():
    text = FIS.replace("AndMethod='einstein_product'", "AndMethod=''").replace(
        "[Output1]\nName='y'", "[Output1]\nName='y'\nEnabled=1\nDefault=nan\nLockPrevious=0\n"
        "LockRange=0")
    rb = parse_fis(text.replace("2, 2 (1) : 1", "2, 2 (1) : 2"), "small.fis")
    assert math.isnan(rb.variables["y"].default)             # the file asks for NaN
    with pytest.raises(MitosError, match="LockPrevious=1"):
        parse_fis(text.replace("LockPrevious=0", "LockPrevious=1"), "small.fis")


def test_fll_repeated_term_names_mean_the_last_as_in_fuzzylite():
    text = FLL_HEDGE_PREFIX.replace("term: high Triangle 0 10 10", "term: veryhigh Triangle 0 0 10")
    rb = parse_fll(text.replace("rule: if x is notable then y is low\n", ""), "e.fll")
    assert rb.variables["x"].term_names == ("veryhigh_2", "veryhigh")
    assert rb.variables["x"].term("veryhigh").params == (0.0, 0.0, 10.0)   # the last one
    assert any("e.fll:4:" in n and "`veryhigh_2`" in n for n in rb.notes)


def test_exported_python_computes_jfuzzylogics_dsigm(tmp_path: Path):
    import importlib.util

    path = tmp_path / "t.fcl"
    path.write_text(JFUZZY.replace("TERM low := gauss 2 1;", "TERM low := dsigm 4 2 1 6;"))
    out = tmp_path / "t_py.py"
    result = runner.invoke(app, ["export", str(path), "--to", "python", "-o", str(out)])
    assert result.exit_code == 0, result.output
    spec = importlib.util.spec_from_file_location("t_py", out)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rb = load_rulebase(path)
    X = np.linspace(0, 10, 41)[:, None]
    np.testing.assert_allclose(module.evaluate(X)[:, 0], rb.run(X).outputs[:, 0], atol=1e-12)


@pytest.mark.parametrize("mf, term", [
    ("'rampmf',[2 8]", "Ramp 2 8"), ("'cosinemf',[5 6]", "Cosine 5 6"),
    ("'discretemf',[0 0 5 1 10 0]", "Discrete 0 0 5 1 10 0"), ("'spikemf',[5 4]", "Spike 5 4"),
    ("'concavemf',[4 6]", "Concave 4 6"), ("'rectmf',[2 8]", "Rectangle 2 8"),
    ("'binarymf',[5 1]", "Binary 5 1"),
])
def test_fis_reads_the_mf_types_fuzzylite_writes_as_its_terms(mf, term):
    # fuzzylite's exporter writes its own terms as these types (its examples' AllTerms.fis,
    # Laundry.fis), with the parameters in the order of its .fll; they were refused
    fis = parse_fis(FIS.replace("MF1='low':'gbellmf',[3 2 0 0]", f"MF1='low':{mf}"), "s.fis")
    fll = parse_fll(FLL_HEDGE_PREFIX.replace("term: veryhigh Triangle 0 10 10",
                                             f"term: veryhigh {term}").replace(
        "  rule: if x is notable then y is low\n", ""), "e.fll")
    got, want = fis.variables["x"].terms[0], fll.variables["x"].terms[0]
    assert (got.shape, got.params) == (want.shape, want.params)


@pytest.mark.parametrize("index, hedges, negated, mu", [
    ("2.2", ("very",), False, lambda t: t ** 2), ("-2.3", ("extremely",), True,
                                                  lambda t: 1 - t ** 3),
    ("2.05", ("somewhat",), False, math.sqrt), ("2.4", ("very", "very"), False,
                                                 lambda t: t ** 4),
])
def test_fis_reads_octaves_hedges_in_an_antecedent(index, hedges, negated, mu):
    # Octave's fuzzy-logic-toolkit: the fraction is the power round(100 f) / 10, then `not`
    # (get_mf_index_and_hedge.m); its investment_portfolio.fis was refused
    text = FIS.replace("NumRules=2", "NumRules=1").replace(
        "MF1='low':'gbellmf',[3 2 0 0]", "MF1='lo':'trimf',[0 0 10]").replace(
        "AndMethod='einstein_product'", "AndMethod='min'")
    rules = text[text.index("[Rules]"):]
    rb = parse_fis(text.replace(rules, f"[Rules]\n{index}, 1 (1) : 1\n"), "s.fis")
    prop = rb.behaviors[0].rules[0].antecedent
    assert (prop.term, prop.hedges, prop.negated) == ("low", hedges, negated)
    from mitos_cli.engine.compile import compile_rulebase
    from mitos_cli.engine.evaluation import as_batch, evaluate

    c = compile_rulebase(rb)
    dof = evaluate(c, as_batch(c, {"x": 7.5}), strict=False).dof[0, 0]
    assert dof == pytest.approx(mu(0.75), abs=1e-15)


def test_fis_refuses_a_hedge_octave_does_not_name_and_a_hedged_consequent():
    text = FIS.replace("AndMethod='einstein_product'", "AndMethod='min'").replace(
        "NumRules=2", "NumRules=1")
    rules = text[text.index("[Rules]"):]
    with pytest.raises(MitosError, match=r"Octave's hedge x\^1.5 \(the fraction .15\)"):
        parse_fis(text.replace(rules, "[Rules]\n2.15, 1 (1) : 1\n"), "s.fis")
    with pytest.raises(MitosError, match="fractional .hedged. consequents"):
        parse_fis(text.replace(rules, "[Rules]\n2, 1.2 (1) : 1\n"), "s.fis")


def test_fis_notes_where_a_sugeno_aggmethod_changes_other_engines_outputs():
    # Octave's linear_tip_calculator.fis (AggMethod='max', two rules concluding one term):
    # Octave and fuzzylite take the max first, MATLAB and MITOS average every rule; it was
    # read without a word
    sugeno = FIS.replace("Type='mamdani'", "Type='sugeno'").replace(
        "DefuzzMethod='centroid'", "DefuzzMethod='wtaver'").replace(
        "AndMethod='einstein_product'", "AndMethod='min'").replace(
        "MF1='a':'trimf',[0 0 10]", "MF1='a':'constant',[2]").replace(
        "MF2='b':'trimf',[0 10 10]", "MF2='b':'constant',[8]")
    rules = sugeno[sugeno.index("[Rules]"):]
    shared = sugeno.replace(rules, "[Rules]\n1, 1 (1) : 1\n2, 1 (1) : 1\n")
    assert any("AggMethod='max' in a Sugeno system" in n and "(y.a)" in n
               for n in parse_fis(shared, "s.fis").notes)
    assert not any("AggMethod" in n for n in parse_fis(
        sugeno.replace(rules, "[Rules]\n1, 1 (1) : 1\n2, 2 (1) : 1\n"), "s.fis").notes)


def test_an_fll_name_with_a_letter_beyond_ascii_is_read_in_rules():
    """pyfuzzylite 8 reads `term: lö Triangle ...` and `if x is lö`; MITOS took the
    declaration and then refused the rule ("cannot read this rule" at the `ö`)."""
    text = FLL_HEDGE_PREFIX.replace("InputVariable: x", "InputVariable: xö").replace(
        "term: high Triangle", "term: veryö Triangle").replace(
        "rule: if x is veryhigh then y is anyway\n", "rule: if xö is veryhigh then y is anyway\n"
    ).replace("rule: if x is notable then y is low\n", "rule: if xö is veryö then y is low\n")
    rb = parse_fll(text, "u.fll")
    second = rb.behaviors[0].rules[1].antecedent
    assert (second.var, second.term, second.hedges) == ("xö", "veryö", ())
    X = np.array([[10.0]])                          # both terms 1: (8 + 2) / 2
    from mitos_cli.api import LoadedRuleBase

    assert LoadedRuleBase(rb).run(X, detail=False).outputs[0, 0] == pytest.approx(5.0)


def test_an_output_without_defuzzify_in_a_file_without_rules_gives_its_terms():
    """jFuzzyLogic's junit4 and membershipFunctionsDemo declare an output they never define
    and have no rules: their inputs' terms are what `plot terms` and `check` read; with rules,
    the missing block is refused as before."""
    from mitos_cli.errors import NoRulesError

    text = JFUZZY.split("DEFUZZIFY y")[0] + "END_FUNCTION_BLOCK\n"
    with pytest.raises(NoRulesError) as info:
        parse_fcl(text, "t.fcl")
    assert [v.name for v in info.value.termset.variables] == ["x", "unused"]
    with_rules = text.replace("END_FUNCTION_BLOCK", "RULEBLOCK r\n    RULE 1 : IF x IS low THEN "
                                                    "y IS a;\nEND_RULEBLOCK\nEND_FUNCTION_BLOCK")
    with pytest.raises(MitosError, match="variable `y` is declared but has no DEFUZZIFY block"):
        parse_fcl(with_rules, "t.fcl")


@pytest.mark.parametrize(("key", "says"), [
    ("AggMethod", "t.fis:11:11: format error: AggMethod='' but rules r1 and r2 both set `tip`: "
                  "a Mamdani system joins their sets with its aggregation"),
    ("ImpMethod", "t.fis:10:11: format error: ImpMethod='' but rule r1 concludes `tip`: a "
                  "Mamdani system cuts each rule's set with its implication"),
])
def test_an_empty_mamdani_method_that_changes_the_number_is_refused(tmp_path, capsys, key,
                                                                    says):
    """`AggMethod=''` / `ImpMethod=''` in a Mamdani .fis were read as MATLAB's defaults (max,
    min) without a word, where fuzzylite refuses to run without them. Refused where they
    change the number; one rule per output leaves the aggregation nothing to join."""
    from mitos_cli.cli.app import main

    text = TIPPER_FIS
    line = next(x for x in text.splitlines() if x.startswith(key))
    path = tmp_path / "t.fis"
    path.write_text(text.replace(line, f"{key}=''"), encoding="utf-8")
    with pytest.raises(SystemExit) as info:
        main(["eval", str(path), "service=3", "food=8"])
    err = capsys.readouterr().err
    assert info.value.code == 1 and says in err
    assert f"give {key} a method" in err
    if key == "AggMethod":                            # one rule: nothing to join, read
        one = path.read_text(encoding="utf-8").replace("NumRules=3", "NumRules=1").replace(
            "2 0, 2 (1) : 1\n", "").replace("3 2, 3 (1) : 2\n", "")
        assert [r.label for r in parse_fis(one, "one.fis").behaviors[0].rules] == ["r1"]


SPACED_FLL = """\
Engine : dimmer
InputVariable : Ambient
  range : 0 1
  term : DARK Triangle 0 0.25 0.5
  term : BRIGHT Triangle 0.5 0.75 1
OutputVariable : Power
  range : 0 1
  aggregation : Maximum
  defuzzifier : Centroid 100
  default : nan
  term : LOW Triangle 0 0.25 0.5
  term : HIGH Triangle 0.5 0.75 1
RuleBlock : b
  implication : Minimum
  rule : if Ambient is DARK then Power is HIGH
  rule : if Ambient is BRIGHT then Power is LOW
"""


def test_fll_keys_spaced_from_their_colon_read_as_fuzzylite_reads_them():
    """`range : 0 1` is read by fuzzylite 6 (the `fuzzylite` binary) and pyfuzzylite, which
    trim the key; MITOS refused it as "unknown InputVariable key `range `" with the hint "did
    you mean `range`?"."""
    spaced = parse_fll(SPACED_FLL, "s.fll")
    plain = parse_fll(SPACED_FLL.replace(" :", ":"), "p.fll")
    assert spaced.variables["Ambient"].universe == (0.0, 1.0)
    for x in (0.1, 0.3, 0.6, 0.9):
        assert outputs(spaced, Ambient=x) == outputs(plain, Ambient=x)
    assert outputs(spaced, Ambient=0.3)["Power"] == pytest.approx(0.75, abs=1e-12)


PLAIN_FLL = SPACED_FLL.replace(" :", ":")


@pytest.mark.parametrize("text", [
    PLAIN_FLL.replace("  implication: Minimum\n", ""),
    PLAIN_FLL.replace("implication: Minimum", "implication: none")])
def test_a_mamdani_rule_block_without_implication_is_refused(text: str):
    """fuzzylite (6 and 8) stops on a Mamdani rule block without an implication ("implication
    operator needed to activate"); MITOS read it as min without a word, as the .fis reader
    did `ImpMethod=''` until it refused it."""
    with pytest.raises(MitosError) as exc:
        parse_fll(text, "i.fll")
    assert "the rule block has no implication, but rule r1 concludes `Power`" in str(exc.value)
    assert exc.value.span is not None
    assert exc.value.span.source_line.strip() == "rule: if Ambient is DARK then Power is HIGH"


@pytest.mark.parametrize("text", [
    PLAIN_FLL.replace("  aggregation: Maximum\n", ""),
    PLAIN_FLL.replace("aggregation: Maximum", "aggregation: none")])
def test_a_mamdani_output_two_rules_set_without_aggregation_is_refused(text: str):
    """Two rules setting `Power` join their sets by its aggregation, which the file leaves out:
    fuzzylite stops ("expected an aggregation operator"), MITOS took max without a word. One
    rule per output needs none (its set is itself under any S-norm) and still loads."""
    with pytest.raises(MitosError) as exc:
        parse_fll(text, "a.fll")
    assert "output `Power` has no aggregation, but rules r1 and r2 both set it" in str(exc.value)
    assert exc.value.span is not None and exc.value.span.line == 6
    one = text.replace("  rule: if Ambient is BRIGHT then Power is LOW\n", "")
    assert outputs(parse_fll(one, "o.fll"), Ambient=0.3)["Power"] == pytest.approx(0.75, abs=1e-12)


def test_a_mamdani_output_without_defuzzifier_is_refused():
    """fuzzylite stops on an output its rules set without a defuzzifier ("defuzzifier needed
    to defuzzify output variable"); MITOS took the centroid without a word."""
    with pytest.raises(MitosError) as exc:
        parse_fll(PLAIN_FLL.replace("  defuzzifier: Centroid 100\n", ""), "d.fll")
    assert "output `Power` has no defuzzifier, but rule r1 sets it" in str(exc.value)
    assert exc.value.span is not None and exc.value.span.line == 6


def test_an_output_without_aggregation_does_not_borrow_another_outputs():
    """`Power` has `aggregation: Maximum`, `Fan` none and two rules: the check read the rule
    base's merged operators, where Power's Maximum stood for both."""
    text = PLAIN_FLL.replace("RuleBlock: b", "OutputVariable: Fan\n  range: 0 1\n"
                             "  defuzzifier: Centroid 100\n  term: OFF Triangle 0 0 1\n"
                             "RuleBlock: b").replace(
        "then Power is HIGH", "then Power is HIGH and Fan is OFF").replace(
        "then Power is LOW", "then Power is LOW and Fan is OFF")
    with pytest.raises(MitosError, match="output `Fan` has no aggregation, but rules r1 and r2"):
        parse_fll(text, "f.fll")


# ---------------------------------------------------------------------------------------------
# Found on public files (night 25)

def test_fis_names_written_with_blanks_around_them_are_read_without(tmp_path):
    """`Name='User '` and `MF1='Low '` (in public MATLAB files) were read with the blank:
    a batch CSV's header cells are trimmed, so `--batch` could never name that input ("no
    column for `User `"). fuzzylite trims them too; MITOS now reads `User` and `Low`."""
    text = TIPPER_FIS.replace("Name='food'", "Name='food '").replace(
        "MF1='rancid'", "MF1=' rancid  '")
    rb = parse_fis(text, "t.fis")
    assert "food" in rb.variables and [t.name for t in rb.variables["food"].terms] == [
        "rancid", "delicious"]
    path = tmp_path / "t.fis"
    path.write_text(text)
    result = runner.invoke(app, ["eval", str(path), "--batch", "-"],
                           input="service,food\n2,1\n")
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines()[0] == "service,food,tip"
    assert float(result.stdout.splitlines()[1].split(",")[2]) == pytest.approx(7.016879, abs=1e-6)


COGS_NO_RANGE = """\
FUNCTION_BLOCK score
VAR_INPUT
    x : REAL;
END_VAR
VAR_OUTPUT
    y : REAL;
END_VAR
FUZZIFY x
    TERM lo := (0, 1) (4, 0);
    TERM hi := (6, 0) (10, 1);
END_FUZZIFY
DEFUZZIFY y
    TERM low := 10;
    TERM high := 100;
    METHOD : COGS;
    DEFAULT := 0;
END_DEFUZZIFY
RULEBLOCK r
    AND : MIN;
    ACCU : MAX;
    RULE 1 : IF x IS lo THEN y IS low;
    RULE 2 : IF x IS hi THEN y IS high;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


def test_fcl_cogs_default_beyond_the_singletons_widens_the_range_it_derives():
    """An output without RANGE gets its terms' extent, [10, 100] here, as jFuzzyLogic derives
    it; `DEFAULT := 0` (returned where no rule fires) was then refused as outside "its range",
    a range the file never wrote. COGS averages the singletons and samples no range, so the
    range now holds the default, as it already did for linear (COGF) terms: 10 at x = 2, 0
    where no rule fires, 100 at x = 9, the same numbers as with `RANGE := (0 .. 100)`."""
    rb = parse_fcl(COGS_NO_RANGE, "s.fcl")
    assert rb.variables["y"].universe == (0.0, 100.0)
    assert any("`y` has no RANGE; its universe [0, 100] holds its terms' values and its "
               "DEFAULT 0" in n for n in rb.notes)
    written = parse_fcl(COGS_NO_RANGE.replace("    DEFAULT := 0;\n",
                                              "    DEFAULT := 0;\n    RANGE := (0 .. 100);\n"),
                        "r.fcl")
    for x, want in [(2.0, 10.0), (5.0, 0.0), (9.0, 100.0), (3.0, 10.0)]:
        assert outputs(rb, x=x)["y"] == want == outputs(written, x=x)["y"]


def test_fcl_sampled_output_default_beyond_its_derived_range_says_the_range_was_derived():
    """Under COG the derived range is sampled, so widening it would move the numbers from
    jFuzzyLogic's; the refusal now says that the file gives no RANGE and which one to add."""
    text = COGS_NO_RANGE.replace("TERM low := 10;", "TERM low := (10, 0) (20, 1) (30, 0);") \
        .replace("TERM high := 100;", "TERM high := (70, 0) (80, 1) (100, 0);") \
        .replace("METHOD : COGS;", "METHOD : COG;")
    with pytest.raises(MitosError) as exc:
        parse_fcl(text, "c.fcl")
    assert exc.value.message.startswith("output `y` has no RANGE, and its DEFAULT 0 lies outside "
                                        "[10, 100], the extent of its terms")
    assert exc.value.hint.startswith("add `RANGE := (0 .. 100);`")
    assert exc.value.span is not None and exc.value.span.line == 16


SUGENO_CONSTANT_FIS = """\
[System]
Name='s'
Type='sugeno'
NumInputs=1
NumOutputs=1
NumRules=2
AndMethod='prod'
OrMethod='probor'
ImpMethod='prod'
AggMethod='sum'
DefuzzMethod='wtaver'

[Input1]
Name='t'
Range=[24 34]
NumMFs=2
MF1='cool':'trimf',[14 24 34]
MF2='warm':'trimf',[24 34 44]

[Output1]
Name='fan'
Range=[0 1]
NumMFs=2
MF1='slow':'linear',[-0.01 0.5]
MF2='full':'linear',[0 100]

[Rules]
1, 1 (1) : 1
2, 2 (1) : 1
"""


def test_a_constant_linear_term_beyond_the_range_converts_to_rules(tmp_path):
    """A public Sugeno file writes `linear [0 0 100]` on `Range=[0 1]` (MATLAB's Sugeno ranges
    bound nothing). The rule-language writer wrote it as the number 100, which a term set
    refuses beyond the universe, and `convert --to rules` stopped with "a defect of `mitos
    convert`; please report it". A constant linear term beyond the universe stays linear."""
    src = tmp_path / "s.fis"
    src.write_text(SUGENO_CONSTANT_FIS)
    out = tmp_path / "s.rules"
    result = runner.invoke(app, ["convert", str(src), "--to", "rules", "-o", str(out)])
    assert result.exit_code == 0, result.output
    terms = (tmp_path / "s.terms.yaml").read_text()
    assert "full: {shape: linear, coefficients: {}, constant: 100}" in terms
    X = np.linspace(24, 34, 41)
    before = load_rulebase(src).evaluate(t=X)["fan"]
    after = load_rulebase(out).evaluate(t=X)["fan"]
    np.testing.assert_array_equal(after, before)
    assert before[-1] == 100.0 and before[0] == pytest.approx(0.26, abs=1e-12)


POINT_FIS = """\
[System]
Name='point'
Type='mamdani'
NumInputs=1
NumOutputs=1
NumRules=2
AndMethod='min'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='centroid'

[Input1]
Name='tutor'
Range=[0 1]
NumMFs=2
MF1='no':'trimf',[0 0 0]
MF2='yes':'trimf',[1 1 1]

[Output1]
Name='grade'
Range=[0 30]
NumMFs=2
MF1='low':'trimf',[0 0 7]
MF2='high':'trimf',[23 30 30]

[Rules]
1, 1 (1) : 1
2, 2 (1) : 1
"""


def test_convert_measures_at_the_universes_ends_where_a_term_is_one_point(tmp_path):
    """A public file's 0/1 inputs have `trimf [0 0 0]` and `[1 1 1]` terms, 1 at one point,
    which none of 2,000 draws meets: `convert --to fll` measured no difference and gave no
    figure, while at tutor = 0 and 1 the written FLL's output moves (101 end points against
    1000 midpoints). The ends and middles of the universes are measured too."""
    src = tmp_path / "p.fis"
    src.write_text(POINT_FIS)
    result = runner.invoke(app, ["convert", str(src), "--to", "fll", "-o", str(tmp_path / "p.fll")])
    assert result.exit_code == 0, result.output
    moved = [line for line in result.stderr.splitlines() if "`grade` moves by up to" in line]
    assert len(moved) == 1, result.stderr
    assert moved[0].endswith("on 2,000 seeded inputs and 3 at the universes' ends and middles "
                             "(largest at tutor=0)") or moved[0].endswith("(largest at tutor=1)")
    before = load_rulebase(src).evaluate(tutor=np.array([0.0, 0.5, 1.0]))["grade"]
    after = load_rulebase(tmp_path / "p.fll").evaluate(tutor=np.array([0.0, 0.5, 1.0]))["grade"]
    assert before[1] == after[1] == 15.0 and before[0] != after[0]
