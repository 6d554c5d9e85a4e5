"""Every construct of jFuzzyLogic's FCL grammar (its ANTLR ``Fcl.g``) either loads or is
refused by name, at its position: one small file of our own, varied one construct at a time."""

from __future__ import annotations

import numpy as np
import pytest

from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.errors import FormatError
from mitos_cli.interop.fcl import parse_fcl

BASE = """\
(* an IEC comment *)
/* a C comment */
// a line comment
FUNCTION_BLOCK probe
VAR_INPUT
    a : REAL;
    b : REAL; RANGE := (0 .. 10);
END_VAR
VAR_OUTPUT
    y : REAL;
END_VAR
FUZZIFY a
    RANGE := (0 .. 10);
    TERM low := (0, 1) (5, 0);
    TERM high := TRIAN 0 10 10;
END_FUZZIFY
FUZZIFY b
    TERM low := TRAPE 0 0 2 6;
    TERM high := (4, 0) (10, 1);
END_FUZZIFY
DEFUZZIFY y
    TERM lo := (0, 0) (2, 1) (4, 0);
    TERM hi := (6, 0) (8, 1) (10, 0);
    METHOD : COG;
    DEFAULT := 0;
    RANGE := (0 .. 10);
END_DEFUZZIFY
RULEBLOCK r
    AND : MIN;
    OR : MAX;
    ACT : MIN;
    ACCU : MAX;
    RULE 1 : IF a IS low AND b IS low THEN y IS lo;
    RULE 2 : IF a IS high OR b IS high THEN y IS hi;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""

HIGH = "TERM high := TRIAN 0 10 10;"
LOADS = [
    (HIGH, "TERM high := GAUSS 8 2;"), (HIGH, "TERM high := GAUSS2 6 1 8 2;"),
    (HIGH, "TERM high := GBELL 2 3 8;"), (HIGH, "TERM high := SIGM 2 5;"),
    (HIGH, "TERM high := COSINE 3 7;"), (HIGH, "TERM high := DSIGM 2 4 2 8;"),
    (HIGH, "TERM high := TRIAN 0 1e1 1E+1;"),
    ("TERM lo := (0, 0) (2, 1) (4, 0);", "TERM lo := 2;"),
    *[("METHOD : COG;", f"METHOD : {m};") for m in ("COA", "LM", "RM", "MM")],
    *[("OR : MAX;", f"OR : {o};") for o in ("ASUM", "BSUM", "DMAX", "NIPMAX", "EINSTEIN")],
    *[("AND : MIN;", f"AND : {o};") for o in ("PROD", "BDIF", "DMIN", "NIPMIN", "HAMACHER")],
    ("ACT : MIN;", "ACT : PROD;"), ("ACCU : MAX;", "ACCU : BSUM;"),
    ("ACCU : MAX;", "ACCU : PROBOR;"), ("ACCU : MAX;", "ACCU : SUM;"), ("ACCU : MAX;", "ACCU : UNSUM;"),
    ("ACCU : MAX;", "ACCU : NSUM;"),
    ("IF a IS low AND", "IF NOT a IS low AND"), ("IF a IS low AND", "IF a IS NOT low AND"),
    ("IF a IS low AND b IS low THEN", "IF (a IS low AND b IS low) THEN"),
    ("IF a IS low AND b IS low THEN", "IF NOT (a IS low OR b IS high) THEN"),
    ("THEN y IS lo;", "THEN y IS lo WITH 0.5;"), ("RULE 1 :", "RULE first :"),
    ("FUNCTION_BLOCK probe", "FUNCTION_BLOCK"),
    ("    y : REAL;\n", "    y : REAL; RANGE := (0 .. 10);\n"),
]
REFUSED = [
    (HIGH, "TERM high := FUNCTION 2 * (1 + 3);", "FUNCTION terms"),
    ("TERM lo := (0, 0) (2, 1) (4, 0);", "TERM lo := SINGLETONS (1, 0.5) (2, 1);",
     "SINGLETONS terms"),
    (HIGH, "TERM high := TRIAN 0 mid 10;", "a parameter given by a variable (`mid`)"),
    (HIGH, "TERM high := (0, 0) (mid, 1);", "a parameter given by a variable (`mid`)"),
    ("DEFAULT := 0;", "DEFAULT := NC;", "`DEFAULT := NC` (no change"),
    ("METHOD : COG;", "METHOD : COGF;", "not a `triangle` term"),     # COGF is COGS
    ("METHOD : COG;", "METHOD : COGS;", "not a `triangle` term"),
    ("OR : MAX;", "OR : NSUM;", "jFuzzyLogic's normalized sum is an accumulation"),
    ("OR : MAX;", "OR : SUM;", "the unbounded sum is a Mamdani aggregation only"),
    ("IF a IS low AND b IS low THEN", "IF a AND b IS low THEN", "a condition without `IS`"),
    ("END_FUNCTION_BLOCK\n", "END_FUNCTION_BLOCK\nFUNCTION_BLOCK probe\nEND_FUNCTION_BLOCK\n",
     "two function blocks are named `probe`"),
]


def test_the_base_file_loads_and_evaluates():
    c = compile_rulebase(parse_fcl(BASE, "probe.fcl"))
    y = evaluate(c, np.array([[0.0, 0.0], [10.0, 10.0]]), detail=False).outputs[:, 0]
    assert y == pytest.approx([2.0, 8.0], abs=1e-9)       # only `lo`, only `hi` fires


@pytest.mark.parametrize("old, new", LOADS, ids=[n.strip()[:40] for _, n in LOADS])
def test_construct_loads(old: str, new: str):
    assert old in BASE
    rb = parse_fcl(BASE.replace(old, new, 1), "probe.fcl")
    compile_rulebase(rb)


@pytest.mark.parametrize("old, new, words", REFUSED, ids=[w[:40] for _, _, w in REFUSED])
def test_construct_is_refused_by_name(old: str, new: str, words: str):
    assert old in BASE
    text = BASE.replace(old, new, 1)
    with pytest.raises(FormatError) as info:
        parse_fcl(text, "probe.fcl")
    assert words in info.value.message, info.value.render()
    span = info.value.span
    assert span is not None and span.path == "probe.fcl" and span.source_line is not None
    assert span.source_line.strip() in text


def test_einstein_after_or_is_the_einstein_sum():
    rb = parse_fcl(BASE.replace("OR : MAX;", "OR : EINSTEIN;"), "probe.fcl")
    assert compile_rulebase(rb).operators.or_ == "einstein_sum"
    rb = parse_fcl(BASE.replace("AND : MIN;", "AND : HAMACHER;"), "probe.fcl")
    assert compile_rulebase(rb).operators.and_ == "hamacher"


@pytest.mark.parametrize("condition, warned", [
    ("a IS high OR b IS high AND a IS low", True),
    ("a IS low AND b IS low OR a IS high AND b IS high", True),
    ("NOT (a IS high OR b IS high AND a IS low)", True),
    ("a IS high OR (b IS high AND a IS low)", False),
    ("(a IS high OR b IS high) AND a IS low", False),
    ("a IS low AND b IS low OR a IS high", False),
    ("a IS high OR b IS high", False)])
def test_or_before_an_unparenthesized_and_says_how_it_is_grouped(condition, warned):
    """jFuzzyLogic's `condition : subcondition ((AND | OR) subcondition)*` groups AND and OR
    left to right, `(a OR b) AND c`, where MITOS (as fuzzylite) takes AND first: such a rule
    was read one way without a word, though the file may be jFuzzyLogic's."""
    old = "IF a IS high OR b IS high THEN"
    text = BASE.replace(old, f"IF {condition} THEN")
    rb = parse_fcl(text, "probe.fcl")
    notes = [n for n in rb.notes if "`OR` before an `AND`" in n]
    assert bool(notes) == warned, rb.notes
    if warned:
        line = text.splitlines().index(f"    RULE 2 : IF {condition} THEN y IS hi;") + 1
        column = len(f"    RULE 2 : IF {condition}") - len(condition) + \
            condition.index(" OR ") + 5
        assert notes[0].startswith(f"probe.fcl:{line}:{column}: ")
        assert "jFuzzyLogic reads AND and OR left to right" in notes[0]


@pytest.mark.parametrize("written, universe", [
    ("(0..10)", (0.0, 10.0)), ("(0.. 10)", (0.0, 10.0)), ("(-5..5)", (-5.0, 5.0)),
    ("(0.5..1e1)", (0.5, 10.0))])
def test_a_range_without_spaces_around_the_dots_is_read(written, universe):
    """`RANGE := (0..10);` (fuzzylite 6 and jFuzzyLogic read it) was refused with "unexpected
    `.10`": the number took `0.` and left `.10`. A number now stops before `..`."""
    text = BASE.replace("FUZZIFY a\n    RANGE := (0 .. 10);", f"FUZZIFY a\n    RANGE := {written};")
    assert parse_fcl(text, "probe.fcl").variables["a"].universe == universe


def test_the_iec_dialect_writes_what_jfuzzylogics_grammar_reads():
    """jFuzzyLogic's `Fcl.g` has an input's RANGE after its declaration (`var_def : ID COLON
    data_type SEMICOLON (range)?`), FUZZIFY blocks of terms only, `DEFAULT := REAL | NC` and
    its own names for the smooth shapes. The IEC dialect wrote RANGE in FUZZIFY, `DEFAULT :=
    nan;` and fuzzylite's `Gaussian`, none of which that grammar reads."""
    from mitos_cli.interop import write_foreign

    text = BASE.replace(HIGH, "TERM high := GAUSS 8 2;").replace(
        "TERM high := (4, 0) (10, 1);", "TERM high := GBELL 2 3 8;").replace(
        "DEFAULT := 0;", "DEFAULT := nan;")
    rb = parse_fcl(text, "probe.fcl")
    written = write_foreign(rb, "fcl", dialect="iec")
    lines = [line.strip() for line in written.splitlines()]
    fuzzify = [i for i, line in enumerate(lines) if line.startswith("FUZZIFY")]
    for i in fuzzify:
        block = lines[i + 1:lines.index("END_FUZZIFY", i)]
        assert all(line.startswith("TERM ") for line in block), block
    assert "a : REAL; RANGE := (0 .. 10);" in lines and "b : REAL; RANGE := (0 .. 10);" in lines
    assert "TERM high := GAUSS 8 2;" in lines and "TERM high := GBELL 2 3 8;" in lines
    assert not any(line.startswith("DEFAULT") for line in lines)
    back = parse_fcl(written, "back.fcl")
    X = np.random.default_rng(5).uniform(0, 10, size=(200, 2))
    before = evaluate(compile_rulebase(rb), X, strict=False, detail=False).outputs
    after = evaluate(compile_rulebase(back), X, strict=False, detail=False).outputs
    np.testing.assert_array_equal(after, before)
    fuzzylite = write_foreign(rb, "fcl")            # fuzzylite 6 reads RANGE in FUZZIFY
    assert "FUZZIFY a\n    RANGE := (0 .. 10);" in fuzzylite and "DEFAULT := nan;" in fuzzylite


SINGLETONS = BASE.replace("TERM lo := (0, 0) (2, 1) (4, 0);", "TERM lo := 2;").replace(
    "TERM hi := (6, 0) (8, 1) (10, 0);", "TERM hi := 8;").replace("METHOD : COG;", "METHOD : COGS;")


def _memberships(a: float, b: float) -> tuple[float, float, float, float]:
    """The BASE file's input terms by hand: a low, a high, b low, b high."""
    return (max(0.0, (5 - a) / 5), a / 10, min(1.0, max(0.0, (6 - b) / 4)),
            max(0.0, (b - 4) / 6))


THIRD = "    RULE 3 : IF b IS high THEN y IS hi;\nEND_RULEBLOCK"


@pytest.mark.parametrize("accu, join", [
    ("ACCU : MAX;", max),
    ("ACCU : PROBOR;", lambda p, q: p + q - p * q),
    ("", lambda p, q: p + q),                     # jFuzzyLogic's default without ACCU: SUM
    ("ACCU : SUM;", lambda p, q: p + q),          # refused as no S-norm until night 8
])
def test_cogs_under_accu_joins_the_rules_of_one_singleton_as_jfuzzylogic(accu, join):
    """jFuzzyLogic adds each rule's degree into its COGS defuzzifier's point at the singleton's
    value with the ACCU norm, then averages the points; MITOS summed every rule (fuzzylite 6)
    and only warned. COGS + ACCU now reads as `accumulation = ACCU`: the numbers by hand."""
    text = SINGLETONS.replace("ACCU : MAX;", accu).replace("END_RULEBLOCK", THIRD)
    rb = parse_fcl(text, "s.fcl")
    assert not [n for n in rb.notes if "concluded by" in n]
    c = compile_rulebase(rb)
    assert c.operators.accumulation == {"ACCU : MAX;": "max", "ACCU : PROBOR;":
                                        "probabilistic_sum", "": "sum", "ACCU : SUM;": "sum"}[accu]
    for a, b in [(3.0, 5.0), (1.0, 9.0), (8.0, 4.5), (2.5, 0.0)]:
        a_low, a_high, b_low, b_high = _memberships(a, b)
        w2, w8 = min(a_low, b_low), join(max(a_high, b_high), b_high)
        want = (2 * w2 + 8 * w8) / (w2 + w8)
        got = evaluate(c, np.array([[a, b]]), detail=False).outputs[0, 0]
        assert got == pytest.approx(want, rel=1e-14), (a, b)


FUNCTIONS = SINGLETONS.replace("TERM lo := 2;", "TERM lo := FUNCTION (a * 0.5) + 1;").replace(
    "TERM hi := 8;", "TERM hi := FUNCTION 2 * (b - 1) + a / 4;").replace(
    "METHOD : COGS;", "METHOD : COGF;").replace("    RANGE := (0 .. 10);\nEND_DEFUZZIFY",
                                                "END_DEFUZZIFY")


def test_cogf_reads_linear_functions_as_linear_consequents():
    """jFuzzyLogic's COGF: each FUNCTION term a singleton at its value, averaged as COGS (its
    ACCU joining rules of one function). A linear one is a `linear` term; by hand at 4 inputs."""
    rb = parse_fcl(FUNCTIONS.replace("END_RULEBLOCK", THIRD), "f.fcl")
    y = rb.variables["y"]
    assert [(t.shape, t.params) for t in y.terms] == [("linear", (0.5, 0.0, 1.0)),
                                                      ("linear", (0.25, 2.0, -2.0))]
    assert y.universe == (-2.0, 20.5)             # every value over the inputs' ranges
    assert any("`y` has no RANGE; its universe [-2, 20.5] holds every value" in n
               for n in rb.notes)
    c = compile_rulebase(rb)
    for a, b in [(3.0, 5.0), (1.0, 9.0), (8.0, 4.5), (2.5, 0.0)]:
        a_low, a_high, b_low, b_high = _memberships(a, b)
        w_lo, w_hi = min(a_low, b_low), max(max(a_high, b_high), b_high)
        want = (w_lo * (0.5 * a + 1) + w_hi * (2 * (b - 1) + a / 4)) / (w_lo + w_hi)
        got = evaluate(c, np.array([[a, b]]), detail=False).outputs[0, 0]
        assert got == pytest.approx(want, rel=1e-14), (a, b)


@pytest.mark.parametrize("function, at, words", [
    ("a * b", "*", "a product of two inputs is not linear in the inputs"),
    ("(a * 3.0) + 5 * SIN(a)", "SIN", "`SIN` of an input is not linear"),
    ("a ^ 2", "^", "a power of an input is not linear"),
    ("1 / (a + 1)", "/", "a division by an input is not linear"),
    ("c * 2", "c", "`c` is not an input variable"),
    ("a * 2)", ")", "unexpected `)`"),
])
def test_a_function_that_is_not_linear_is_refused_where_it_stops_being_so(function, at, words):
    text = FUNCTIONS.replace("FUNCTION (a * 0.5) + 1;", f"FUNCTION {function};")
    with pytest.raises(FormatError) as info:
        parse_fcl(text, "f.fcl")
    assert words in info.value.message, info.value.render()
    span = info.value.span
    assert span.line == 22 and span.source_line[span.column - 1:].startswith(at)
    if "linear" in words:
        assert "linear Takagi-Sugeno consequent" in info.value.message


def test_constants_of_a_function_are_folded_and_an_input_function_stays_refused():
    rb = parse_fcl(FUNCTIONS.replace("FUNCTION (a * 0.5) + 1;",
                                     "FUNCTION -a * 2 ^ 3 / 4 - abs(-1) + 10 % 4;"), "f.fcl")
    assert rb.variables["y"].term("lo").params == (-2.0, 0.0, 1.0)
    with pytest.raises(FormatError) as info:      # an input's membership by formula
        parse_fcl(FUNCTIONS.replace("TERM high := (4, 0) (10, 1);",
                                    "TERM high := FUNCTION b / 10;"), "f.fcl")
    assert "FUNCTION terms (a membership given by a formula)" in info.value.message


def test_one_rule_concluding_two_terms_of_an_output_is_two_rules():
    """jFuzzyLogic's junit3 ``THEN valve IS drainage, valve IS closed WITH 0.8``: each
    conclusion is implied at the rule's degree (its weight included) and accumulated like
    another rule's, so two rules of its condition and weight are exact; MITOS refused it."""
    third = "    RULE 3 : IF b IS high THEN y IS lo, y IS hi WITH 0.5;\nEND_RULEBLOCK"
    rb = parse_fcl(SINGLETONS.replace("END_RULEBLOCK", third), "s.fcl")
    rules = rb.behaviors[0].rules
    assert [(r.label, r.consequents[0].term, r.weight) for r in rules[2:]] == [
        ("r3", "lo", 0.5), ("r3_2", "hi", 0.5)]
    assert rules[2].antecedent == rules[3].antecedent
    assert any("rule `r3` concludes 2 terms of one output: read as the rules `r3`, `r3_2`" in n
               and n.startswith("s.fcl:35:5:") for n in rb.notes)
    c = compile_rulebase(rb)
    for a, b in [(3.0, 5.0), (1.0, 9.0), (8.0, 4.5)]:
        a_low, a_high, b_low, b_high = _memberships(a, b)
        w2, w8 = max(min(a_low, b_low), 0.5 * b_high), max(max(a_high, b_high), 0.5 * b_high)
        got = evaluate(c, np.array([[a, b]]), detail=False).outputs[0, 0]
        assert got == pytest.approx((2 * w2 + 8 * w8) / (w2 + w8), rel=1e-14)


@pytest.mark.parametrize(("expr", "column", "says"), [
    # a RecursionError (a traceback) at each: 50,000 parentheses, 100,000 signs, 5,000 exp(
    ("(" * 50_000 + "a" + ")" * 50_000, 125, "FUNCTION: nested more than 100 deep"),
    ("-" * 100_000 + "a", 125, "FUNCTION: nested more than 100 deep"),
    ("exp(" * 5_000 + "0" + ")" * 5_000, 225, "FUNCTION: nested more than 100 deep"),
    ("(" * 100 + "a" + ")" * 100, None, None),                  # at the limit: read
    # complex: float() of it was a TypeError
    ("(-8) ^ 0.5", 30, "FUNCTION: -8 ^ 0.5 is not a number"),
    # past a float's range without an exception: a coefficient of inf, or NaN
    ("1e308 * 10 * a", 24, "FUNCTION: its coefficient of a comes to inf, past a float's range"),
    ("a*1e308*10 - a*1e308*10", 24,
     "FUNCTION: its coefficient of a comes to nan, past a float's range"),
    ("1e308 + 1e308", 24, "FUNCTION: its constant comes to inf, past a float's range"),
])
def test_hostile_functions_are_refused_at_their_place(tmp_path, capsys, expr, column, says):
    from mitos_cli.cli.app import main

    path = tmp_path / "f.fcl"
    path.write_text(FUNCTIONS.replace("TERM lo := FUNCTION (a * 0.5) + 1;",
                                      f"TERM lo := FUNCTION {expr};"), encoding="utf-8")
    with pytest.raises(SystemExit) as info:
        main(["check", str(path)])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    if says is None:
        assert info.value.code == 0
    else:
        assert info.value.code == 1 and f"f.fcl:22:{column}: format error: {says}" in err


def test_a_function_of_200000_terms_is_read_in_linear_time():
    """Each token sliced the rest of the text (`text[pos:]`): a FUNCTION of 200,000 terms
    (1.2 MB) took past a minute; read as the sum it is."""
    text = FUNCTIONS.replace("TERM lo := FUNCTION (a * 0.5) + 1;",
                             "TERM lo := FUNCTION " + " + ".join(["a"] * 200_000) + ";")
    lo = parse_fcl(text, "f.fcl").variables["y"].term("lo")
    assert lo.params == (200_000.0, 0.0, 0.0)


@pytest.mark.parametrize("char, name", [("\u200b", "ZERO WIDTH SPACE"),
                                        ("\u2060", "WORD JOINER")])
def test_a_keyword_followed_by_an_invisible_character_is_told_so(char, name):
    """`ACT` and a zero-width space read as a name where `ACT` stands: "did you mean `ACT`?"
    named what the user sees as written."""
    with pytest.raises(FormatError) as got:
        parse_fcl(BASE.replace("ACT : MIN;", f"ACT{char} : MIN;", 1), "probe.fcl")
    assert got.value.hint == (f"`ACT` is followed by the invisible character "
                              f"`\\u{ord(char):04x}` ({name}): delete it")
    assert got.value.span.source_line == f"    ACT{char} : MIN;" and got.value.span.column == 5
