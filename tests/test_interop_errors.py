"""Every refusal and error of the readers and writers, met once: message, line and column.

Each case is a small file (built from a valid one by replacing a line) and the words the error
must contain; the error must be a FormatError (or the build's own error for names) pointing at
the right line.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from mitos_cli.errors import FormatError, MitosError
from mitos_cli.interop import read_foreign, write_foreign
from mitos_cli.interop.fcl import parse_fcl
from mitos_cli.interop.fis import parse_fis
from mitos_cli.interop.fll import parse_fll

FLL = """\
Engine: test
InputVariable: a
  enabled: true
  range: 0 10
  lock-range: false
  term: low Triangle 0 2 5
  term: high Triangle 5 8 10
InputVariable: b
  range: 0 1
  term: small Ramp 1 0
  term: big Ramp 0 1
OutputVariable: y
  range: 0 1
  aggregation: Maximum
  defuzzifier: Centroid 200
  default: nan
  lock-previous: false
  term: off Triangle 0 0.25 0.5
  term: on Triangle 0.5 0.75 1
RuleBlock: main
  conjunction: Minimum
  disjunction: Maximum
  implication: Minimum
  activation: General
  rule: if a is low and b is small then y is off
  rule: if a is high or b is big then y is on with 0.5
"""

SUGENO = FLL.replace("  aggregation: Maximum\n", "  aggregation: none\n").replace(
    "defuzzifier: Centroid 200", "defuzzifier: WeightedAverage TakagiSugeno").replace(
    "term: off Triangle 0 0.25 0.5", "term: off Constant 0.2").replace(
    "term: on Triangle 0.5 0.75 1", "term: on Linear 0.01 0.5 0.1").replace(
    "implication: Minimum", "implication: none")


def fll(old: str, new: str, base: str = FLL) -> str:
    assert old in base, old
    return base.replace(old, new, 1)


def line_of(text: str, needle: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), 1) if needle in line)


FLL_CASES = [
    ("term: low Triangle 0 2 5", "term low Triangle", "expected `key: value`"),
    ("InputVariable: b", "InputVariable:", "InputVariable needs a name"),
    ("Engine: test", "description: x\nEngine: test", "`description` before any section"),
    ("  lock-range: false", "  lock-rnage: false", "unknown InputVariable key `lock-rnage`"),
    ("  enabled: true", "  enabled: false", "MITOS has no disabled"),
    ("  range: 0 10", "  range: 0", "`range` takes two numbers"),
    ("  range: 0 10", "  range: 10 0", "range [10, 0] is empty"),
    ("  range: 0 10", "  range: 0 ten", "expected a number, not `ten`"),
    ("term: low Triangle 0 2 5", "term: low", "`term` takes a name, a type"),
    ("  lock-previous: false", "  lock-previous: true", "needs state between evaluations"),
    ("  lock-range: false", "  lock-range: yes", "`lock-range` is `true` or `false`, not `yes`"),
    ("  lock-previous: false", "  lock-previous: 1", "`lock-previous` is `true` or `false`"),
    ("defuzzifier: Centroid 200", "defuzzifier:", "`defuzzifier` needs a name"),
    ("defuzzifier: Centroid 200", "defuzzifier: Centroid 2.5", "resolution must be a whole"),
    ("defuzzifier: Centroid 200", "defuzzifier: Centriod", "unknown defuzzifier `Centriod`"),
    ("aggregation: Maximum", "aggregation: NormalizedSum", "but fuzzylite 6's is a + b / max(1, max(a, b))"),
    ("conjunction: Minimum", "conjunction: Minimun", "unknown conjunction `Minimun`"),
    ("activation: General", "activation: Highest 2", "activation `Highest 2` is not supported"),
    ("  range: 0 1\n  term: small", "  term: small", "variable `b` has no `range`"),
    ("term: low Triangle 0 2 5", "term: low Linear 1 2 3", "Linear terms belong to outputs"),
    ("term: low Triangle 0 2 5", "term: low Function y*y", "unknown name `y` in the formula"),
    ("term: low Triangle 0 2 5", "term: low Triangel 0 2 5", "unknown term type `Triangel`"),
    ("term: low Triangle 0 2 5", "term: low Triangle 0 2", "Triangle takes 3 numbers, not 2"),
    ("term: low Triangle 0 2 5", "term: low Triangle 0 2 5 0.5", "a term height (0.5)"),
    ("term: low Triangle 0 2 5", "term: low Triangle 5 2 0", "points must be in order"),
    ("rule: if a is low and b", "rule: if a low and b", "cannot read this rule"),
    ("conjunction: Minimum", "conjunction: none", "uses `and` but its rule block's conjunction"),
    ("disjunction: Maximum", "disjunction: none", "uses `or` but its rule block's disjunction"),
    ("rule: if a is low and b is small", "rule: if a is low and b is tiny",
     "unknown term `tiny` of `b`"),
    ("then y is off", "then a is off", "`a` is an input variable and cannot appear in an action"),
    ("if a is low and b is small then", "if a is very not low and b is small then",
     "`not` after a hedge"),
    ("then y is off", "then y is not off", "`not` in a consequent"),
    ("if a is low and b is small then", "if a is very and b is small then", "names no term"),
    ("InputVariable: b\n  range: 0 1\n  term: small Ramp 1 0\n  term: big Ramp 0 1\n",
     "InputVariable: b\n  range: 0 1\n  term: small Ramp 1 0\n  term: big Ramp 0 1\n"
     "InputVariable: b\n  range: 0 1\n  term: x Ramp 0 1\n", "variable `b` is defined twice"),
    ("  rule: if a is low and b is small then y is off\n"
     "  rule: if a is high or b is big then y is on with 0.5\n", "", "the file has no rules"),
    ("OutputVariable: y\n  range: 0 1\n  aggregation: Maximum\n  defuzzifier: Centroid 200\n"
     "  default: nan\n  lock-previous: false\n  term: off Triangle 0 0.25 0.5\n"
     "  term: on Triangle 0.5 0.75 1\n",
     "OutputVariable: y\n  range: 0 1\n  defuzzifier: Centroid\n", "output variable `y` has no "
     "terms"),
    ("term: off Triangle 0 0.25 0.5", "term: off Linear 0 0 1", "linear terms need a weighted"),
    ("defuzzifier: Centroid 200", "defuzzifier: WeightedAverage",
     "or monotonic ones (Tsukamoto"),
    ("defuzzifier: Centroid 200", "defuzzifier: WeightedAverage Tsukamoto",
     "Tsukamoto inference inverts monotonic terms"),
    ("defuzzifier: Centroid 200", "defuzzifier: WeightedAverage Magic",
     "unknown weighted defuzzifier type `Magic`"),
    ("term: off Triangle 0 0.25 0.5", "term: off Constant 0.25",
     "fuzzylite's `Constant` is a flat membership"),    ("term: off Triangle 0 0.25 0.5", "term: off Triangle 0 0.25 5e999",    # was "... is inf"
     "`5e999` is past a float's range"),
]


@pytest.mark.parametrize("old, new, words", FLL_CASES, ids=[c[2][:40] for c in FLL_CASES])
def test_fll_errors(old: str, new: str, words: str) -> None:
    text = fll(old, new)
    with pytest.raises(MitosError) as info:
        parse_fll(text, "bad.fll")
    assert words in info.value.message, info.value.render()
    span = info.value.span
    assert span is not None and span.path == "bad.fll" and span.line >= 1


# A rule's keyword glued to the next word: the contextual lexer took it off the word's front
# (`a islow` was `a is low`); fuzzylite splits a rule at its blanks and refuses the word.
@pytest.mark.parametrize("old, new, word, expected, hint", [
    ("if a is low and", "if a islow and", "islow", "is",
     "`is` and `low` are two words: `is low`"),
    ("is small then y", "is small theny", "theny", "one of and, or, then",
     "`then` and `y` are two words: `then y`"),
    ("is on with 0.5", "is on with0.5", "with0.5", "one of and, the end of the rule, with",
     "`with` and `0.5` are two words: `with 0.5`"),
    ("rule: if a is low", "rule: ifa is low", "ifa", "if",
     "`if` and `a` are two words: `if a`"),
    ("is low and b", "is low andb", "andb", "one of and, or, then",
     "`and` and `b` are two words: `and b`"),
    ("is high or b", "is high orb", "orb", "one of and, or, then",
     "`or` and `b` are two words: `or b`"),
    ("if a is low and", "if a isvery low and", "isvery", "is",
     "`is` and `very` are two words: `is very`"),
    ("with 0.5", "with 0.5x", "0.5x", "a number", None),
])
def test_fll_a_keyword_glued_to_the_next_word_is_refused_at_the_word(
        old: str, new: str, word: str, expected: str, hint: str | None) -> None:
    text = fll(old, new)
    with pytest.raises(FormatError) as info:
        parse_fll(text, "bad.fll")
    exc = info.value
    assert (exc.message, exc.expected, exc.hint) == (f"unexpected `{word}`", expected, hint)
    line = text.splitlines()[exc.span.line - 1]
    assert line[exc.span.column - 1:].startswith(word)
    assert exc.render().splitlines()[2].strip() == "^" * len(word)


def test_fll_a_term_glued_to_a_keyword_is_named_in_the_hint() -> None:
    with pytest.raises(FormatError) as info:
        parse_fll(fll("then y is on with 0.5", "then y is onwith 0.5"), "bad.fll")
    assert info.value.render() == (
        "bad.fll:26:51: format error: cannot read this rule\n"
        "      rule: if a is high or b is big then y is onwith 0.5\n"
        "                                                      ^\n"
        "expected one of and, the end of the rule, with\n"
        "hint: `onwith` is read as one name: `on` and `with` are two words")
    with pytest.raises(FormatError) as info:       # the end of the rule said after it
        parse_fll(fll("then y is on with 0.5", "then y is on with"), "bad.fll")
    assert (info.value.span.column, info.value.expected) == (51, "a number")


def test_fll_a_term_name_glued_to_its_type_is_named_in_the_hint() -> None:
    """`term: lowTriangle 0 2 5` took `lowTriangle` for the name and `0` for the type, with no
    word on why."""
    with pytest.raises(FormatError) as info:
        parse_fll(fll("term: low Triangle 0 2 5", "term: lowTriangle 0 2 5"), "bad.fll")
    assert (info.value.message, info.value.hint) == (
        "term `lowTriangle`: unknown term type `0`",
        "`lowTriangle` is read as the term's name: `low` and `Triangle` are two words")


@pytest.mark.parametrize("old, new, hint", [
    # a section's name split in two was an unknown key of the section above, with no hint
    ("InputVariable: b", "Input Variable: b", "`Input Variable` is one word: `InputVariable`"),
    ("RuleBlock: main", "Rule Block: main", "`Rule Block` is one word: `RuleBlock`"),
    ("  lock-range: false", "  lock range: false", "`lock range` is one word: `lock-range`"),
])
def test_fll_a_key_split_in_two_is_said_as_one_word(old: str, new: str, hint: str) -> None:
    with pytest.raises(FormatError) as info:
        parse_fll(fll(old, new), "bad.fll")
    assert info.value.message.startswith("unknown ") and info.value.hint == hint


def test_fll_error_points_at_the_line() -> None:
    text = fll("term: low Triangle 0 2 5", "term: low Triangle 0 2 5 0.5")
    with pytest.raises(FormatError) as info:
        parse_fll(text, "bad.fll")
    assert info.value.span.line == line_of(text, "0 2 5 0.5")
    assert "bad.fll:6:" in info.value.render() and "^" in info.value.render()


SUGENO_CASES = [
    ("  aggregation: none", "  aggregation: Maximum\n  lock-range: true",
     "`lock-range: true` on the Takagi-Sugeno output"),
    ("  aggregation: none\n", "  aggregation: Maximum\n", "is concluded by several rules while"),
    ("term: on Linear 0.01 0.5 0.1", "term: on Linear 0.5 0.1", "Linear takes one coefficient"),
    ("defuzzifier: WeightedAverage TakagiSugeno\n  default: nan\n  lock-previous: false\n"
     "  term: off Constant 0.2", "defuzzifier: Centroid\n  default: nan\n  lock-previous: "
     "false\n  term: off Triangle 0 0.25 0.5", "linear terms need a weighted-average"),
]


@pytest.mark.parametrize("old, new, words", SUGENO_CASES, ids=[c[2][:40] for c in SUGENO_CASES])
def test_fll_sugeno_errors(old: str, new: str, words: str) -> None:
    base = SUGENO.replace("then y is on with 0.5", "then y is off") if "several" in words \
        else SUGENO
    with pytest.raises(FormatError) as info:
        parse_fll(fll(old, new, base), "bad.fll")
    assert words in info.value.message, info.value.render()


def test_fll_conflicting_outputs() -> None:
    text = FLL + SUGENO[SUGENO.index("OutputVariable"):SUGENO.index("RuleBlock")].replace(
        "OutputVariable: y", "OutputVariable: z")
    text = text.replace("RuleBlock: main", "RuleBlock: main", 1)
    with pytest.raises(FormatError) as info:
        parse_fll(text, "bad.fll")
    assert "differs from `centroid` set at bad.fll:15" in info.value.message
    text = FLL + FLL[FLL.index("OutputVariable"):FLL.index("RuleBlock")].replace(
        "OutputVariable: y", "OutputVariable: z").replace("Centroid 200", "Centroid 500")
    rb = parse_fll(text, "own.fll")     # fuzzylite's SimpleDimmerChained: refused until night 9
    assert (rb.variables["y"].resolution, rb.variables["z"].resolution) == (200, 500)


FIS = (Path(__file__).parent / "data" / "interop" / "tipper.fis").read_text()

FIS_CASES = [
    ("[System]", "System", "expected a section header"),
    ("Name='tipper'", "Name", "expected `Key=value`"),
    ("Version=2.0", "Versoin=2.0", "unknown [System] key `Versoin`"),
    ("Type='mamdani'", "Type='tsk'", "FIS type `tsk` is not supported"),
    ("Type='mamdani'", "Type=mamdani", "expected a quoted text"),
    ("DefuzzMethod='centroid'", "DefuzzMethod='wtaver'", "does not fit a mamdani system"),
    ("AndMethod='min'", "AndMethod='bounded'", "unknown AND method `bounded`"),
    ("OrMethod='max'", "OrMethod='sum'", "a Mamdani aggregation only"),
    ("[Input2]", "[Input3]", "expected [Input2], found [Input3]"),
    ("[Rules]", "[Ruels]", "unknown section [Ruels]"),
    ("NumInputs=2", "NumInputs=3", "NumInputs=3 but the file has 2"),
    ("NumRules=3", "NumRules=4", "NumRules=4 but the file has 3"),
    ("NumMFs=2", "NumMfs=2", "unknown key `NumMfs`"),
    ("Name='food'\n", "", "a variable needs `Name` and `Range`"),
    ("Range=[0 30]", "Range=[30 0]", "`Range` must be [min max]"),
    ("Range=[0 30]", "Range=0 30", "expected numbers in brackets"),
    ("NumMFs=2", "NumMFs=5", "NumMFs=5 but the variable has 2"),
    ("MF1='rancid':'trapmf',[0 0 1 3]", "MF1='rancid' 'trapmf' [0 0 1 3]",
     "expected 'name':'type',[params]"),
    ("MF1='rancid':'trapmf',[0 0 1 3]", "MF1='rancid':'trapezoid',[0 0 1 3]",
     "membership function type `trapezoid` is not supported"),
    ("MF1='rancid':'trapmf',[0 0 1 3]", "MF1='rancid':'trapmf',[0 0 1]",
     "trapmf takes 4 numbers, not 3"),
    ("MF1='rancid':'trapmf',[0 0 1 3]", "MF1='rancid':'linear',[0 0 1]",
     "`linear` belongs to Sugeno outputs"),
    ("MF1='rancid':'trapmf',[0 0 1 3]", "MF1='rancid':'trapmf',[0 0 1 x]", "expected a number"),
    ("1 1, 1 (1) : 2", "1 1 1 (1) : 2", "expected a rule"),
    ("1 1, 1 (1) : 2", "1 1 1, 1 (1) : 2", "the rule lists 3 inputs and 1 output"),
    ("1 1, 1 (1) : 2", "1 1, 1 (1) : 3", "connection 3: expected 1 (AND) or 2 (OR)"),
    ("1 1, 1 (1) : 2", "1.15 1, 1 (1) : 2", "Octave's hedge x^1.5 (the fraction .15)"),
    ("1 1, 1 (1) : 2", "4 1, 1 (1) : 2", "`service` has 3 MFs, not 4"),
    ("1 1, 1 (1) : 2", "1 1, -1 (1) : 2", "negative (complemented)"),
    ("1 1, 1 (1) : 2", "1 1, 4 (1) : 2", "`tip` has 3 MFs, not 4"),
    ("1 1, 1 (1) : 2", "0 0, 1 (1) : 2", "the rule has no condition"),
    ("1 1, 1 (1) : 2", "1 1, 0 (1) : 2", "the rule has no consequent"),    ("MF1='rancid':'trapmf',[0 0 1 3]", "MF1='rancid':'trapmf',[0 0 1 3e400]",
     "`3e400` is past a float's range"),                     # was "the ... parameter 4 is inf"
]


@pytest.mark.parametrize("old, new, words", FIS_CASES, ids=[c[2][:40] for c in FIS_CASES])
def test_fis_errors(old: str, new: str, words: str) -> None:
    assert old in FIS
    text = FIS.replace(old, new, 1)
    with pytest.raises(FormatError) as info:
        parse_fis(text, "bad.fis")
    assert words in info.value.message, info.value.render()
    assert info.value.span is not None and info.value.span.path == "bad.fis"


def test_fis_sugeno_linear_count_and_missing_system() -> None:
    sugeno = FIS.replace("Type='mamdani'", "Type='sugeno'").replace(
        "DefuzzMethod='centroid'", "DefuzzMethod='wtaver'").replace(
        "MF1='cheap':'trimf',[0 5 10]", "MF1='cheap':'linear',[1 2]")
    with pytest.raises(FormatError, match=r"linear takes 3 numbers"):
        parse_fis(sugeno, "bad.fis")
    ramp = sugeno.replace("MF1='cheap':'linear',[1 2]", "MF1='cheap':'rampmf',[0 0.25]")
    with pytest.raises(FormatError) as info:            # fuzzylite's Tsukamoto .fis
        parse_fis(ramp, "bad.fis")
    assert info.value.message == (     # `cheap` is fine alone; its neighbour is not
        "MF `average`: the outputs of a Sugeno-type .fis take `constant` or `linear` MFs, or "
        "only monotonic ones (rampmf, sigmf, smf, zmf, concavemf: fuzzylite's Tsukamoto "
        "inference), not `trimf`")
    with pytest.raises(FormatError, match=r"no \[System\] section"):
        parse_fis(FIS[FIS.index("[Input1]"):], "bad.fis")
    with pytest.raises(FormatError, match="output `tip` has no membership functions"):
        parse_fis(FIS.replace("NumMFs=3\nMF1='cheap':'trimf',[0 5 10]\nMF2='average':'trimf',"
                              "[10 15 20]\nMF3='generous':'trimf',[20 25 30]\n", ""), "bad.fis")


FCL = (Path(__file__).parent / "data" / "interop" / "tipper_jfuzzylogic.fcl").read_text()


def test_a_name_defined_twice_is_reported_at_the_second_definition() -> None:
    """As the rule language does (`behavior `a` is defined twice (first at line 2)`): the
    first definition is the correct one; the second is what to look at."""
    cases = [
        (parse_fis, FIS.replace("Name='food'", "Name='service'"), "Name='service'", 2,
         "variable `service` is defined twice (first at line 15)"),
        (parse_fll, FLL + "InputVariable: b\n  range: 0 1\n  term: x Ramp 0 1\n",
         "InputVariable: b", 2, "variable `b` is defined twice (first at line "),
        (parse_fcl, FCL.replace("TERM good := (1, 0)", "TERM poor := (1, 0)"), "TERM poor", 2,
         "variable `service`: duplicate term `poor` (first at line "),
        (parse_fcl, FCL.replace("\tfood : REAL;", "\tfood : REAL;\n\tfood : REAL;"),
         "\tfood : REAL;", 2, "variable `food` is declared twice (first at line "),
    ]
    for parse, text, needle, nth, words in cases:
        with pytest.raises(FormatError) as info:
            parse(text, "twice")
        lines = [i for i, line in enumerate(text.splitlines(), 1) if needle in line]
        first = lines[0]
        assert info.value.message.startswith(words) and f"line {first})" in info.value.message
        assert info.value.span.line == lines[nth - 1], (info.value.render(), lines)

FCL_CASES = [
    ("END_FUNCTION_BLOCK", "END_FUNCTION_BLOCK\nFUNCTION_BLOCK two\nEND_FUNCTION_BLOCK",
     "the file defines no input variable"),                   # the second block, at its line
    ("END_FUNCTION_BLOCK", "", "unexpected end of file"),
    ("METHOD : COG;", "METHOD : COG", "unexpected `DEFAULT`"),
    ("TERM poor := (0, 1) (4, 0) ;", "TERM poor := (0, 1) (4, 0) $;", "unexpected character `$`"),
    ("	food : REAL;", "	food : REAL;\n	food : REAL;", "variable `food` is declared twice"),
    ("	food : REAL;", "	food : BOOL;", "type `BOOL` is not supported"),
    ("FUZZIFY food", "FUZZIFY foood", "`foood` is not declared"),
    ("DEFUZZIFY tip", "DEFUZZIFY food", "`food` is declared as an input but has a DEFUZZIFY"),
    ("	tip : REAL;", "	tip : REAL;\n	tap : REAL;", "`tap` is declared but has no DEFUZZIFY"),
    ("TERM rancid := (0, 1) (1, 1) (3,0) ;", "TERM rancid := (0, 1) (1, 1) (3,0) ;\n"
     "	METHOD : COG;", "`METHOD` has no meaning in FUZZIFY"),
    ("DEFAULT := 0;", "DEFAULT := 0 | NC;", "`| NC` (no change"),
    ("DEFAULT := 0;", "DEFAULT := 0 | XX;", "unknown DEFAULT flag `XX`"),
    ("DEFAULT := 0;", "DEFAULT := zero;", "DEFAULT must be a number, not `zero`"),
    ("DEFAULT := 0;", "DEFAULT := 0;\n	LOCK : PREVIOUS;", "`LOCK : PREVIOUS`"),
    ("DEFAULT := 0;", "DEFAULT := 0;\n	LOCK : FOREVER;", "unknown LOCK `FOREVER`"),
    ("	TERM rancid := (0, 1) (1, 1) (3,0) ;\n	TERM delicious := (7,0) (9,1);\n", "",
     "variable `food` has no terms"),
    # a gauss term without RANGE gets jFuzzyLogic's estimate (mean -+ 4 sigma); a shape that
    # jFuzzyLogic has no estimate for is still refused
    ("TERM rancid := (0, 1) (1, 1) (3,0) ;", "TERM rancid := Spike 0 1;",
     "has no RANGE and its `rancid` term (spike)"),
    ("	TERM rancid := (0, 1) (1, 1) (3,0) ;\n	TERM delicious := (7,0) (9,1);\n",
     "	TERM rancid := 3;\n", "its terms lie at the one point 3: jFuzzyLogic takes [3, 3]"),
    ("RANGE := (0 .. 30);", "RANGE := (30 .. 0);", "RANGE [30, 0] is empty"),
    ("TERM rancid := (0, 1) (1, 1) (3,0) ;", "TERM rancid := (0, 1) (3, 1) (1,0) ;",
     "the points' x values must ascend"),
    ("TERM rancid := (0, 1) (1, 1) (3,0) ;", "TERM rancid := (0, 1);",
     "a point list needs at least two points"),
    ("TERM cheap := trian 0 5 10;", "TERM cheap := train 0 5 10;",
     "unknown membership function `train`"),
    ("TERM cheap := trian 0 5 10;", "TERM cheap := trian 0 5;", "trian takes 3 numbers, not 2"),
    ("TERM cheap := trian 0 5 10;", "TERM cheap := Triangle 0 5 10 0.5;", "a term height (0.5)"),
    ("TERM rancid := (0, 1) (1, 1) (3,0) ;", "TERM rancid := Linear 1 2 3;",
     "Linear terms belong to outputs"),
    ("ACT : MIN;", "ACTIVATION : Highest;", "activation `Highest` is not supported"),
    ("METHOD : COG;", "METHOD : COG 2.5;", "resolution must be a whole number"),
    ("METHOD : COG;", "METHOD : CENTER;", "unknown METHOD `CENTER`"),
    ("ACCU : MAX;", "ACCU : NormalizedSum;", "fuzzylite 8's normalized sum, (a + b) / max(1, "),
    ("METHOD : COG;", "METHOD : cogf;", "a weighted-average output needs constant or linear"),
    ("RULE 2 : IF service IS good", "RULE 2 : IF service IS goood", "of `service`"),
    ("TERM cheap := trian 0 5 10;", "TERM cheap := Constant 5;",
     "fuzzylite's `Constant` is a flat membership"),    ("RANGE := (0 .. 30);", "RANGE := (0 .. 3e400);", "`3e400` is past a float's range"),
]


@pytest.mark.parametrize("old, new, words", FCL_CASES, ids=[c[2][:40] for c in FCL_CASES])
def test_fcl_errors(old: str, new: str, words: str) -> None:
    assert old in FCL, old
    text = FCL.replace(old, new, 1)
    with pytest.raises(MitosError) as info:
        parse_fcl(text, "bad.fcl")
    assert words in info.value.message, info.value.render()
    span = info.value.span
    assert span is not None and span.path == "bad.fcl" and span.line >= 1


@pytest.mark.parametrize("old, new, at, hint", [
    ("TERM poor :=", "TREM poor :=", "TREM", "did you mean `TERM`?"),
    ("END_FUZZIFY", "END_FUZIFY", "END_FUZIFY", "did you mean `END_FUZZIFY`?"),
    ("END_FUZZIFY", "", "FUZZIFY", None),           # a keyword out of place: no did-you-mean
])
def test_fcl_keywords_as_fcl_writes_them(old: str, new: str, at: str, hint: str | None) -> None:
    """Expected keywords read `END_FUZZIFY`, not `end fuzzify`; a misspelt one is named."""
    with pytest.raises(FormatError) as info:
        parse_fcl(FCL.replace(old, new, 1), "bad.fcl")
    exc = info.value
    assert exc.message == f"unexpected `{at}`" and exc.hint == hint
    assert exc.expected == "one of END_FUZZIFY, METHOD/ACCU/AND/OR/ACT, RANGE, TERM"
    caret = exc.render().splitlines()[2]
    assert caret.strip() == "^" * len(at)


# A keyword glued to the next word: Lark's contextual lexer took the keyword off the front of
# the word where only a keyword could stand, and read `ISgood` as `IS good`, `WITH0.8` as `WITH
# 0.8`; jFuzzyLogic's lexer reads the word as one identifier and refuses it. It is said at the
# word, with what could stand there.
@pytest.mark.parametrize("old, new, word, expected, hint", [
    ("IF service IS good", "IF service ISgood", "ISgood", "one of AND, IS, OR, THEN",
     "`IS` and `good` are two words: `IS good`"),
    ("IS good THEN tip", "IS good THENtip", "THENtip", "one of AND, OR, THEN",
     "`THEN` and `tip` are two words: `THEN tip`"),
    ("RULE 2 : IF service", "RULE 2 : IFservice", "IFservice", "IF",
     "`IF` and `service` are two words: `IF service`"),
    ("IS poor OR food", "IS poor ORfood", "ORfood", "one of AND, OR, THEN",
     "`OR` and `food` are two words: `OR food`"),
    ("IS excellent AND food", "IS excellent ANDfood", "ANDfood", "one of AND, OR, THEN",
     "`AND` and `food` are two words: `AND food`"),
    ("IF NOT (", "IFNOT (", "IFNOT", "IF", "`IF` and `NOT` are two words: `IF NOT`"),
    ("service IS NOT excellent", "service ISNOT excellent", "ISNOT", "one of AND, IS, OR, THEN",
     "`IS` and `NOT` are two words: `IS NOT`"),
    ("WITH 0.8", "WITH0.8", "WITH0.8",
     "one of AND, END_RULEBLOCK, METHOD/ACCU/AND/OR/ACT, RULE, WITH, `,`, `;`",
     "`WITH` and `0.8` are two words: `WITH 0.8`"),
    ("RULE 2 :", "RULE2 :", "RULE2", "one of END_RULEBLOCK, METHOD/ACCU/AND/OR/ACT, RULE",
     "`RULE` and `2` are two words: `RULE 2`"),
    ("TERM poor", "TERMpoor", "TERMpoor", "one of END_FUZZIFY, METHOD/ACCU/AND/OR/ACT, RANGE, "
     "TERM", "`TERM` and `poor` are two words: `TERM poor`"),
    ("FUZZIFY food", "FUZZIFYfood", "FUZZIFYfood", "one of DEFUZZIFY, END_FUNCTION_BLOCK, "
     "FUZZIFY, RULEBLOCK, VAR_INPUT, VAR_OUTPUT", "`FUZZIFY` and `food` are two words: "
     "`FUZZIFY food`"),
    ("RULEBLOCK No1", "RULEBLOCKNo1", "RULEBLOCKNo1", "one of DEFUZZIFY, END_FUNCTION_BLOCK, "
     "FUZZIFY, RULEBLOCK, VAR_INPUT, VAR_OUTPUT", "`RULEBLOCK` and `No1` are two words: "
     "`RULEBLOCK No1`"),
    ("FUNCTION_BLOCK tipper", "FUNCTION_BLOCKtipper", "FUNCTION_BLOCKtipper",
     "FUNCTION_BLOCK", "`FUNCTION_BLOCK` and `tipper` are two words: "
     "`FUNCTION_BLOCK tipper`"),
    ("END_FUZZIFY\n\nDEFUZZIFY", "END_FUZZIFYDEFUZZIFY", "END_FUZZIFYDEFUZZIFY",
     "one of END_FUZZIFY, METHOD/ACCU/AND/OR/ACT, RANGE, TERM",
     "`END_FUZZIFY` and `DEFUZZIFY` are two words: `END_FUZZIFY DEFUZZIFY`"),
    ("END_RULEBLOCK\n\nEND_FUNCTION_BLOCK", "END_RULEBLOCKEND_FUNCTION_BLOCK",
     "END_RULEBLOCKEND_FUNCTION_BLOCK", "one of END_RULEBLOCK, METHOD/ACCU/AND/OR/ACT, RULE",
     "`END_RULEBLOCK` and `END_FUNCTION_BLOCK` are two words: "
     "`END_RULEBLOCK END_FUNCTION_BLOCK`"),
    # what follows is no word that may follow the keyword: the keyword misspelt
    ("END_RULEBLOCK", "END_RULEBLOCKx", "END_RULEBLOCKx",
     "one of END_RULEBLOCK, METHOD/ACCU/AND/OR/ACT, RULE", "did you mean `END_RULEBLOCK`?"),
    # numbers glued: `10x` was `10` and a parameter named `x`, `5.5.5` was 5.5 and 0.5
    ("trian 0 5 10", "trian 0 5 10x", "10x", "one of `;`, a name, a number, inf, nan", None),
    ("trian 0 5 10", "trian 0 5.5.5", "5.5.5", "one of `;`, a name, a number, inf, nan", None),
])
def test_fcl_a_keyword_glued_to_the_next_word_is_refused_at_the_word(
        old: str, new: str, word: str, expected: str, hint: str | None) -> None:
    assert old in FCL, old
    text = FCL.replace(old, new, 1)
    with pytest.raises(FormatError) as info:
        parse_fcl(text, "bad.fcl")
    exc = info.value
    assert (exc.message, exc.expected, exc.hint) == (f"unexpected `{word}`", expected, hint)
    line = text.splitlines()[exc.span.line - 1]
    assert line[exc.span.column - 1:].startswith(word)
    assert exc.render().splitlines()[2].strip() == "^" * len(word)


def test_fcl_a_glued_keyword_in_fuzzylites_dialect_is_said_in_full() -> None:
    text = (Path(__file__).parent / "data" / "interop" / "dimmer_fuzzylite.fcl").read_text()
    with pytest.raises(FormatError) as info:
        parse_fcl(text.replace("if Ambient is DARK", "if Ambient isDARK"), "dimmer.fcl")
    assert info.value.render() == (
        "dimmer.fcl:32:21: format error: unexpected `isDARK`\n"
        "    RULE 1 : if Ambient isDARK then Power is HIGH\n"
        "                        ^^^^^^\n"
        "expected one of AND, IS, OR, THEN\n"
        "hint: `is` and `DARK` are two words: `is DARK`")
    with pytest.raises(FormatError) as info:
        parse_fcl(text.replace("with 0.5", "with0.5"), "dimmer.fcl")
    assert info.value.message == "unexpected `with0.5`"


@pytest.mark.parametrize("old, new, at, hint", [
    # a word that ends in a keyword the parser expects next is one name (as jFuzzyLogic reads
    # it): the error comes at the word after it, and says why
    ("IS poor OR food", "IS poorOR food", "food", "`poorOR` is read as one name: `poor` and "
     "`OR` are two words"),
    ("IS rancid THEN tip IS cheap", "IS rancidTHEN tip IS cheap", "tip", "`rancidTHEN` is "
     "read as one name: `rancid` and `THEN` are two words"),
    ("\tservice : REAL;", "\tservice : REALRANGE := (0 .. 10);", ":=", "`REALRANGE` is read "
     "as one name: `REAL` and `RANGE` are two words"),
    ("END_VAR\n\nVAR_OUTPUT", "END_VARVAR_OUTPUT", "tip", "`END_VARVAR_OUTPUT` is read as "
     "one name: `END_VAR` and `VAR_OUTPUT` are two words"),
])
def test_fcl_a_name_glued_to_a_keyword_is_named_in_the_hint(old: str, new: str, at: str,
                                                            hint: str) -> None:
    assert old in FCL, old
    with pytest.raises(FormatError) as info:
        parse_fcl(FCL.replace(old, new, 1), "bad.fcl")
    assert (info.value.message, info.value.hint) == (f"unexpected `{at}`", hint)


def test_an_unknown_method_lists_each_name_once() -> None:
    """MATLAB's and jFuzzyLogic's bisectors are written as fuzzylite's: the list read
    "COG, COA, MM, LM, RM, COA, LM, RM, COA, COGS, COGSS"."""
    with pytest.raises(FormatError) as info:
        parse_fcl(FCL.replace("METHOD : COG;", "METHOD : COGx;", 1), "bad.fcl")
    assert info.value.expected == "one of COG, COA, MM, LM, RM, COGS, COGSS"
    with pytest.raises(FormatError) as info:
        parse_fis(FIS.replace("DefuzzMethod='centroid'", "DefuzzMethod='centroidx'"), "b.fis")
    assert info.value.expected == "one of centroid, bisector, mom, som, lom, wtaver, wtsum"


def test_a_hedge_or_not_glued_to_a_term_is_two_words_not_the_term() -> None:
    """`IS NOTexcellent` said "did you mean `excellent`?", which drops the NOT."""
    with pytest.raises(FormatError) as info:
        parse_fcl(FCL.replace("IS NOT excellent", "IS NOTexcellent", 1), "bad.fcl")
    assert info.value.hint == "`NOT` and `excellent` are two words: `service is NOT excellent`"
    with pytest.raises(FormatError) as info:
        parse_fll(fll("if a is low and", "if a is verylow and"), "bad.fll")
    assert info.value.hint == "`very` and `low` are two words: `a is very low`"


@pytest.mark.parametrize("old, new, at, hint", [
    # a keyword split in two: "unexpected `END`" with "did you mean `AND`?"
    ("END_RULEBLOCK", "END RULEBLOCK", "END", "`END RULEBLOCK` is one word: `END_RULEBLOCK`"),
    ("VAR_INPUT", "VAR INPUT", "VAR", "`VAR INPUT` is one word: `VAR_INPUT`"),
    ("END_FUZZIFY", "END FUZZIFY", "END", "`END FUZZIFY` is one word: `END_FUZZIFY`"),
    # `END` read as a variable's name, the error at `VAR`
    ("\tfood : REAL;\nEND_VAR", "\tfood : REAL;\nEND VAR", "VAR",
     "`END VAR` is one word: `END_VAR`"),
    # `FUNCTION` began a formula that ran to the next `;`, lines on, all of it "unexpected"
    ("FUNCTION_BLOCK tipper", "FUNCTION BLOCK tipper", "FUNCTION",
     "`FUNCTION BLOCK` is one word: `FUNCTION_BLOCK`"),
    # the `_` left out: `ENDVAR` was a variable's name, the error at the next line
    ("\tfood : REAL;\nEND_VAR", "\tfood : REAL;\nENDVAR", "VAR_OUTPUT",
     "`ENDVAR` is read as a name: did you mean `END_VAR`?"),
])
def test_fcl_a_keyword_split_in_two_is_said_as_one_word(old: str, new: str, at: str,
                                                       hint: str) -> None:
    assert old in FCL, old
    with pytest.raises(FormatError) as info:
        parse_fcl(FCL.replace(old, new, 1), "bad.fcl")
    assert (info.value.message, info.value.hint) == (f"unexpected `{at}`", hint)
    assert info.value.render().splitlines()[2].strip() == "^" * len(at)


def test_fcl_punctuation_is_quoted() -> None:
    with pytest.raises(FormatError) as info:
        parse_fcl(FCL.replace("TERM poor :=", "TERM poor =", 1), "bad.fcl")
    assert info.value.expected == "`:=`"


def test_fcl_sugeno_lock_range() -> None:
    text = (Path(__file__).parent / "data" / "interop" / "dimmer_fuzzylite.fcl").read_text()
    text = text.replace("TERM LOW := Gaussian 0.000 0.200;", "TERM LOW := 0.1;").replace(
        "TERM MEDIUM := Bell 0.500 0.250 3.000;", "TERM MEDIUM := 0.5;").replace(
        "TERM HIGH := Sigmoid 0.750 20.000;", "TERM HIGH := 0.9;").replace(
        "METHOD : COG;", "METHOD : COGS;\nLOCK : RANGE;").replace("ACCU : MAX;\n", "")
    text = text.replace("then Power is LOW with 0.5", "then Power is LOW")
    with pytest.raises(FormatError, match="`LOCK : RANGE` on the Takagi-Sugeno output"):
        parse_fcl(text, "bad.fcl")
    ok = parse_fcl(text.replace("LOCK : RANGE;\n", ""), "ok.fcl")
    assert [s.value for s in ok.operators if s.key == "inference"] == ["weighted_average"]


# ---------------------------------------------------------------------------------------------
# Writers and dispatch


def test_unknown_extension_and_missing_file(tmp_path: Path) -> None:
    with pytest.raises(FormatError, match="unknown format `.xml`"):
        read_foreign(tmp_path / "x.xml")
    # a missing file is not a format error: it is reported as for a .rules file
    from mitos_cli.errors import RuleBaseError

    with pytest.raises(RuleBaseError, match="rule file `.*` not found"):
        read_foreign(tmp_path / "x.fll")
    (tmp_path / "tipper.fll").write_text(FLL)
    with pytest.raises(RuleBaseError) as exc:
        read_foreign(tmp_path / "tiper.fll")
    assert exc.value.hint == f"did you mean `{tmp_path / 'tipper.fll'}`?"   # as it was named
    with pytest.raises(FormatError, match="unknown format `yaml`"):
        write_foreign(parse_fll(FLL), "yaml")


def test_fis_writer_refusals() -> None:
    nested = parse_fll(fll("rule: if a is low and b is small then y is off",
                           "rule: if a is low and (b is small or a is high) then y is off"))
    with pytest.raises(FormatError, match="nested expressions cannot be written to .fis"):
        write_foreign(nested, "fis")
    hedged = parse_fll(fll("if a is low and", "if a is very low and"))
    with pytest.raises(FormatError, match="hedges cannot be written to .fis"):
        write_foreign(hedged, "fis")
    twice = parse_fll(fll("if a is low and b is small", "if a is low and a is high"))
    with pytest.raises(FormatError, match="tests `a` twice"):
        write_foreign(twice, "fis")
    shapes = parse_fll(fll("term: low Triangle 0 2 5", "term: low Cosine 2 4"))
    with pytest.raises(FormatError, match="MATLAB has no `cosine` membership function"):
        write_foreign(shapes, "fis")
    norm = parse_fll(fll("conjunction: Minimum", "conjunction: EinsteinProduct"))
    with pytest.raises(FormatError, match="FIS has no AND method `einstein`"):
        write_foreign(norm, "fis")


def test_fll_writer_refuses_mamdani_singletons() -> None:
    rb = parse_fcl((Path(__file__).parent / "data" / "interop" / "tipper_jfuzzylogic.fcl")
                   .read_text().replace("TERM cheap := trian 0 5 10;", "TERM cheap := 5;"))
    with pytest.raises(FormatError, match="fuzzylite has no singleton set for a Mamdani"):
        write_foreign(rb, "fll")
    assert "TERM cheap := 5;" in write_foreign(rb, "fcl")      # IEC has them


def test_fuzzylite_writer_refusals(tmp_path: Path) -> None:
    from mitos_cli.api import read_rulebase

    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  a: {role: input, universe: [0, 10], terms: {low: {shape: triangle, "
        "points: [0, 2, 5]}, high: {shape: triangle, points: [5, 8, 10]}}}\n"
        "  y: {role: output, universe: [0, 1], terms: {lo: 0.2, hi: 0.8}}\n")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\noperators: and = product, or = max\n'
        "r1: if not (a is low and a is high) then y is lo\n"
        "r2: if a is extremely high then y is hi\n")
    rb = read_rulebase(tmp_path / "t.rules")
    with pytest.raises(FormatError, match="not De Morgan duals"):
        write_foreign(rb, "fll")
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\n'
                                      "r2: if a is extremely high then y is hi\n")
    with pytest.raises(FormatError, match="fuzzylite has no hedge like MITOS's `extremely`"):
        write_foreign(read_rulebase(tmp_path / "t.rules"), "fcl")
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\nbehavior inner:\n'
                                      "  r1: if a is low then y is lo\nend\n"
                                      "behavior outer:\n  use inner when a is high\nend\n")
    with pytest.raises(FormatError, match="a conditional include cannot be written") as info:
        write_foreign(read_rulebase(tmp_path / "t.rules"), "fll", "outer")
    # the hint said "convert the behavior it is used by alone", which is `outer`, refused here
    assert info.value.hint == ("convert `inner` alone (--behavior inner), or write the "
                               "condition into its rules; `mitos export` (C, Python) keeps "
                               "`outer` whole")


def test_rules_writer_refusals() -> None:
    from mitos_cli.interop.rules_writer import write_rules

    reserved = parse_fll(FLL.replace("InputVariable: b", "InputVariable: end").replace(
        "b is", "end is"))
    # names the rule language cannot hold are mapped to legal ones, with a note (they were
    # refused before; converting a file should not fail on a name)
    from mitos_cli.interop import conversion_notes

    rules, terms = write_rules(reserved, "x.terms.yaml")
    assert "end_ is" in rules and "  end_:" in terms
    assert any("variable `end` is written as `end_`" in n
               for n in conversion_notes(reserved, "rules"))
    dotted = parse_fll(FLL.replace("term: low", "term: lo.w").replace("a is low", "a is lo.w"))
    rules, _ = write_rules(dotted, "x.terms.yaml")
    assert "a is lo_w" in rules
    assert any("`a.lo.w` is written as `lo_w`" in n for n in conversion_notes(dotted, "rules"))
    bare = parse_fll(SUGENO.replace("  term: small Ramp 1 0\n  term: big Ramp 0 1\n", "")
                     .replace("a is low and b is small", "a is low")
                     .replace("a is high or b is big", "a is high"))
    with pytest.raises(FormatError, match="input `b` has no terms"):
        write_rules(bare, "x.terms.yaml")


def test_names_are_made_legal_in_time_linear_in_the_terms() -> None:
    """`convert --to rules` of an FLL output with 8,000 terms took 50 s: each term's name was
    checked against a fresh copy of all its variable's names (2,000 terms 8.6 s)."""
    import time
    import types

    from mitos_cli.interop.common import legal_names
    from mitos_cli.lang.terms import Term, Variable

    var = Variable("y", "output", (0.0, 1.0),
                   tuple(Term(f"L{i}", "singleton", (0.5,)) for i in range(40_000)))
    rb = types.SimpleNamespace(termsets=[types.SimpleNamespace(variables=[var])])
    start = time.process_time()
    assert legal_names(rb, "rules") == (rb, [])             # every name legal: as it was
    assert time.process_time() - start < 2                  # was about 30 s


# ---------------------------------------------------------------------------------------------
# Encodings: MATLAB and Java on Windows write Windows-1252


def test_a_windows_1252_fis_is_read_with_a_note(tmp_path: Path) -> None:
    text = Path("tests/data/interop/tipper.fis").read_text().replace(
        "Name='service'", "Name='service'\n% Temperatur (°C), naïve")
    (tmp_path / "t.fis").write_bytes(text.encode("cp1252"))
    rb = read_foreign(tmp_path / "t.fis")
    same = read_foreign(Path("tests/data/interop/tipper.fis"))
    assert write_foreign(rb, "fll") == write_foreign(same, "fll")
    assert rb.notes[0].startswith("`t.fis` is not UTF-8 (byte 0xb0 at line ")
    assert "read as Windows-1252" in rb.notes[0]


def test_a_windows_1252_name_reaches_the_rules(tmp_path: Path) -> None:
    text = Path("tests/data/interop/tipper.fis").read_text().replace("service", "qualité")
    (tmp_path / "t.fis").write_bytes(text.encode("cp1252"))
    rb = read_foreign(tmp_path / "t.fis")
    assert "read as Windows-1252" in rb.notes[0]
    from mitos_cli.interop import conversion_notes

    assert any("`qualité` is written as `qualit_`" in note
               for note in conversion_notes(rb, "rules"))


@pytest.mark.parametrize("data, message, at", [
    (b"[System]\nName='a\x00\xb0'\n", r"\(byte 0x00 at line 2, column 8\)$", (2, 8)),
    (b"[System]\nName='a\x00b'\n", r"\(byte 0x00 at line 2, column 8\)$", (2, 8)),   # UTF-8
    # UTF-16 and UTF-32, with their mark or without: at the first NUL, as every reader says it
    ("[System]\nName='a'\n".encode("utf-16-le"), "looks like UTF-16 text \\(little-endian, "
     "without a byte-order mark\\)", (1, 2)),
    (b"\xff\xfe" + "[System]\n".encode("utf-16-le"), "looks like UTF-16 text \\(little-endian, "
     "with its", (1, 4)),
    (b"\x00\x00\xfe\xff" + "[System]\n".encode("utf-32-be"), "looks like UTF-32 text "
     "\\(big-endian, with its", (1, 1)),
    # 0xe9 is é in Windows-1252: the byte it leaves undefined is the one refused
    (b"[System]\n\xe9\x81\n", "byte 0x81 at line 2, column 2 is neither UTF-8 nor", (2, 2)),
    # UTF-8 on one line, a Windows-1252 degree sign on another: as one, the other is garbled
    ("[System]\nName='qualité'\n% 20 °C\n".encode().replace("°".encode(), b"\xb0"),
     "is UTF-8 at line 2, but byte 0xb0 at line 3, column 6 is not UTF-8", (3, 6)),
    (b"\xef\xbb\xbf[System]\n% 20 \xb0C\n",
     "begins with UTF-8's byte-order mark, but byte 0xb0 at line 2, column 6", (2, 6)),
])
def test_bytes_that_are_no_text_are_refused_where_they_are(tmp_path: Path, data: bytes,
                                                           message: str, at: tuple) -> None:
    (tmp_path / "x.fis").write_bytes(data)
    with pytest.raises(FormatError, match=message) as exc:
        read_foreign(tmp_path / "x.fis")
    assert exc.value.span is not None
    assert (exc.value.span.line, exc.value.span.column) == at


def test_one_thing_expected_is_named_without_one_of() -> None:
    """A consequent in parentheses (`THEN (tip IS cheap)`, which jFuzzyLogic's grammar does not
    have; a public file writes it) said "expected one of a name"; one word expected is named
    alone, in FCL and FLL alike."""
    with pytest.raises(FormatError) as info:
        parse_fcl(FCL.replace("THEN tip IS cheap", "THEN (tip IS cheap)", 1), "bad.fcl")
    assert (info.value.message, info.value.expected) == ("unexpected `(`", "a name")
    with pytest.raises(FormatError) as info:
        parse_fll(fll("then y is on with 0.5", "then y is on with"), "bad.fll")
    assert info.value.render().splitlines()[-1] == "expected a number"
