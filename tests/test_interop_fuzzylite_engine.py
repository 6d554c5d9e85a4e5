"""fuzzylite constructs beyond one rule block of plain rules, each on a small file of its own,
checked against values worked out by hand from fuzzylite's definitions: chained outputs,
hedged Takagi-Sugeno consequents (cumulative, as fuzzylite computes them), ``Function`` terms,
Tsukamoto inference and ``lock-range`` / ``lock-previous``."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.errors import FormatError
from mitos_cli.interop.fll import parse_fll


def run(text: str, X, behavior: str | None = None) -> np.ndarray:
    c = compile_rulebase(parse_fll(text, "t.fll"), behavior)
    return evaluate(c, np.asarray(X, dtype=float), strict=False, detail=False).outputs


# ---------------------------------------------------------------------------------------------
# Chained outputs: a condition on an output is that term's aggregated activation so far

CHAINED = """\
Engine: chained
InputVariable: x
  range: 0 1
  term: low Triangle 0 0 1
  term: high Triangle 0 1 1
OutputVariable: p
  range: 0 1
  aggregation: Maximum
  defuzzifier: Centroid 200
  default: nan
  term: small Triangle 0 0 0.5
  term: big Triangle 0.5 1 1
OutputVariable: q
  range: 0 1
  aggregation: Maximum
  defuzzifier: Centroid 200
  default: nan
  term: a Triangle 0 0 1
  term: b Triangle 0 1 1
RuleBlock: b
  conjunction: Minimum
  disjunction: Maximum
  implication: Minimum
  activation: General
  rule: if x is low then p is small
  rule: if x is high then p is big
  rule: if x is very high then p is big
  rule: if p is small then q is a
  rule: if p is big then q is b
"""


def test_a_condition_on_an_output_is_its_terms_activation_so_far():
    rb = parse_fll(CHAINED, "t.fll")
    assert any("chained engine" in n for n in rb.notes)
    by_hand = CHAINED.replace("if p is small", "if x is low").replace(
        "if p is big", "if x is high or x is very high")
    X = np.linspace(0, 1, 41)[:, None]
    assert np.array_equal(run(CHAINED, X), run(by_hand, X), equal_nan=True)


def test_chained_outputs_agree_with_fuzzylite():
    fl = pytest.importorskip("fuzzylite")
    engine = fl.FllImporter().from_string(CHAINED)
    X = np.linspace(0, 1, 41)
    engine.input_variable("x").value = X
    engine.process()
    theirs = np.column_stack([engine.output_variable(n).value for n in ("p", "q")])
    assert np.allclose(run(CHAINED, X[:, None]), theirs, atol=1e-9, equal_nan=True)


def test_a_chained_term_no_earlier_rule_sets_is_refused_by_name():
    text = CHAINED.replace("  rule: if x is low then p is small\n", "") + \
        "  rule: if x is low then p is small\n"
    with pytest.raises(FormatError, match="which no rule before it sets"):
        parse_fll(text, "t.fll")


def test_a_chained_output_aggregated_unlike_the_disjunction_is_refused():
    text = CHAINED.replace("aggregation: Maximum", "aggregation: AlgebraicSum")
    with pytest.raises(FormatError, match="aggregates 2 rules with `probabilistic_sum`"):
        parse_fll(text, "t.fll")


# ---------------------------------------------------------------------------------------------
# Hedged Takagi-Sugeno consequents hedge the rule's activation, cumulatively

HEDGED = """\
Engine: hedged
InputVariable: x
  range: 0 1
  term: low Triangle 0 0 1
  term: high Triangle 0 1 1
OutputVariable: y
  range: 0 10
  aggregation: none
  defuzzifier: WeightedAverage
  default: nan
  term: lo Constant 2
  term: hi Constant 8
OutputVariable: z
  range: 0 10
  aggregation: none
  defuzzifier: WeightedAverage
  default: nan
  term: lo Constant 2
  term: hi Constant 8
RuleBlock: b
  conjunction: EinsteinProduct
  disjunction: Maximum
  rule: if x is low then y is very lo and z is lo
  rule: if x is high then y is hi and z is somewhat hi
"""


def test_a_hedged_sugeno_consequent_hedges_the_rule_weight_and_those_after_it():
    x = 0.3
    low, high = 1 - x, x
    # rule 1: y sees very(low); z, after it, very(low) too (fuzzylite reassigns the degree)
    y = (low ** 2 * 2 + high * 8) / (low ** 2 + high)
    z = (low ** 2 * 2 + np.sqrt(high) * 8) / (low ** 2 + np.sqrt(high))
    got = run(HEDGED, [[x], [0.0]])
    assert got[0] == pytest.approx([y, z], abs=1e-12)
    assert got[1] == pytest.approx([2.0, 2.0])
    rb = parse_fll(HEDGED, "t.fll")
    assert rb.behaviors[0].rules[0].consequents[1].hedges == ("very",)


def test_hedged_sugeno_consequents_agree_in_the_scalar_form_and_the_exports(tmp_path):
    import importlib.util

    from mitos_cli.interop.export import to_python

    c = compile_rulebase(parse_fll(HEDGED, "t.fll"))
    assert c.scalar is None             # no exact scalar form: the NumPy path answers
    path = tmp_path / "hedged.py"
    path.write_text(to_python(c, "test"))
    spec = importlib.util.spec_from_file_location("hedged", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    X = np.linspace(0.05, 1, 7)[:, None]
    assert np.allclose(module.evaluate(X), evaluate(c, X, detail=False).outputs, atol=1e-12)


def test_hedged_sugeno_consequents_agree_with_fuzzylite():
    fl = pytest.importorskip("fuzzylite")
    engine = fl.FllImporter().from_string(HEDGED.replace("  disjunction: Maximum\n",
                                                         "  disjunction: Maximum\n"
                                                         "  implication: none\n"
                                                         "  activation: General\n"))
    X = np.linspace(0.05, 1, 20)
    engine.input_variable("x").value = X
    engine.process()
    theirs = np.column_stack([engine.output_variable(n).value for n in ("y", "z")])
    assert np.allclose(run(HEDGED, X[:, None]), theirs, atol=1e-12)


#: A Mamdani engine with a hedged consequent: fuzzylite 6 and 8 hedge the rule's activation
#: degree (min(very(dof), mu_lo)); MITOS's rules hedge the set (min(dof, mu_lo^2)). At x = 0.5
#: pyfuzzylite 8 gives y = 5.577 (fuzzylite 6 at its 100 points 5.576), the set reading 5.373.
HEDGED_MAMDANI = """\
Engine: hm
InputVariable: x
  range: 0 1
  term: low Triangle 0 0 1
  term: high Triangle 0 1 1
OutputVariable: y
  range: 0 10
  aggregation: Maximum
  defuzzifier: Centroid 1000
  default: nan
  term: lo Triangle 0 3 6
  term: hi Triangle 4 7 10
RuleBlock: b
  conjunction: Minimum
  disjunction: Maximum
  implication: Minimum
  rule: if x is low then y is hi
  rule: if x is high then y is very lo
"""


def test_a_hedged_mamdani_consequent_is_read_as_fuzzylite_computes_it():
    """It was read as MITOS's hedged set where fuzzylite hedges the degree: another number
    (5.37 where fuzzylite gives 5.58), and not a word. With one proposition as the condition
    the hedge is moved onto it, which computes fuzzylite's degree exactly."""
    assert run(HEDGED_MAMDANI, [[0.5]])[0, 0] == pytest.approx(5.576923076923077, abs=1e-12)
    rb = parse_fll(HEDGED_MAMDANI, "t.fll")
    moved = rb.behaviors[0].rules[1]
    assert moved.antecedent.hedges == ("very",) and moved.consequents[0].hedges == ()
    line = HEDGED_MAMDANI.splitlines().index("  rule: if x is high then y is very lo") + 1
    assert any(n.startswith(f"t.fll:{line}:") and "1 rule hedges a Mamdani consequent" in n
               for n in rb.notes)


def test_the_note_on_a_hedged_mamdani_consequent_quotes_the_rule_it_moved():
    """The note gave a fixed example, `then y is very lo` as `if x is very A then y is lo`,
    beside the file's line as if it were that rule: it quotes the rule read so, in its names."""
    rb = parse_fll(HEDGED_MAMDANI.replace("very lo", "very hi"), "t.fll")
    note = next(n for n in rb.notes if "hedges a Mamdani consequent" in n)
    assert "(`then y is very hi` as `if x is very high then y is hi`)" in note


def test_a_hedged_mamdani_consequent_agrees_with_fuzzylite():
    fl = pytest.importorskip("fuzzylite")
    engine = fl.FllImporter().from_string(HEDGED_MAMDANI.replace(      # pyfuzzylite reserves x
        "InputVariable: x", "InputVariable: v").replace("if x is", "if v is").replace(
        "RuleBlock: b\n", "RuleBlock: b\n  activation: General\n"))
    X = np.linspace(0.0, 1.0, 41)
    engine.input_variable("v").value = X
    engine.process()
    ours = run(HEDGED_MAMDANI, X[:, None])[:, 0]
    assert np.allclose(ours, engine.output_variable("y").value, atol=1e-12, equal_nan=True)


@pytest.mark.parametrize("rule", [
    "if x is high then y is very lo with 0.5",        # fuzzylite hedges 0.5 * dof
    "if x is not high then y is very lo",             # very(1 - mu): no hedge of MITOS's
    "if x is high or x is low then y is very lo",     # very(max(...)): a hedge on a group
    "if x is high then y is any lo"])                 # fuzzylite skips a rule of degree 0
def test_a_hedged_mamdani_consequent_no_condition_can_carry_is_refused(rule):
    from mitos_cli.interop.fcl import parse_fcl

    text = HEDGED_MAMDANI.replace("if x is high then y is very lo", rule)
    with pytest.raises(FormatError, match="hedges a Mamdani consequent") as info:
        parse_fll(text, "t.fll")
    line = text.splitlines().index(f"  rule: {rule}") + 1
    assert str(info.value.span) == f"t.fll:{line}:{len('  rule: ' + rule.split(' then')[0]) + 7}"
    assert "move the hedge onto the condition" in info.value.hint
    fcl = ("FUNCTION_BLOCK hm\nVAR_INPUT x : REAL; END_VAR\nVAR_OUTPUT y : REAL; END_VAR\n"
           "FUZZIFY x\nRANGE := (0 .. 1);\nTERM low := Triangle 0 0 1;\n"
           "TERM high := Triangle 0 1 1;\nEND_FUZZIFY\nDEFUZZIFY y\nRANGE := (0 .. 10);\n"
           "TERM lo := Triangle 0 3 6;\nMETHOD : COG;\nACCU : MAX;\nEND_DEFUZZIFY\n"
           f"RULEBLOCK b\nAND : MIN;\nACT : MIN;\nRULE 1 : {rule}\nEND_RULEBLOCK\n"
           "END_FUNCTION_BLOCK\n")
    with pytest.raises(FormatError, match="hedges a Mamdani consequent"):
        parse_fcl(fcl, "t.fcl")


def test_a_hedged_mamdani_consequent_is_not_written_for_fuzzylite(tmp_path):
    """MITOS's `then y is very lo` under Mamdani inference (the hedged set) was written to FLL
    and FCL as it stands, which fuzzylite reads as the hedged degree: other outputs."""
    from mitos_cli.api import read_rulebase
    from mitos_cli.interop import write_foreign

    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  x: {role: input, universe: [0, 1], terms: {low: {shape: triangle, "
        "points: [0, 0, 1]}}}\n  y: {role: output, universe: [0, 10], terms: {lo: {shape: "
        "triangle, points: [0, 3, 6]}}}\n")
    path = tmp_path / "t.rules"
    path.write_text('terms "t.terms.yaml"\noperators: inference = mamdani\n'
                    "r1: if x is low then y is very lo\n")
    rb = read_rulebase(path)
    for fmt, dialect in (("fll", None), ("fcl", None), ("fcl", "iec")):
        with pytest.raises(FormatError, match="`y is very lo` hedges a Mamdani") as info:
            write_foreign(rb, fmt, dialect=dialect)
        assert str(info.value.span) == f"{path}:3:22"
    path.write_text('terms "t.terms.yaml"\nr1: if x is low then y is very lo\n')
    assert "y is very lo" in write_foreign(read_rulebase(path), "fll")   # weighted: the degree


# ---------------------------------------------------------------------------------------------
# Function terms: a membership given by a formula of x, parsed (never eval'd)

FUNCTION = """\
Engine: function
InputVariable: u
  range: 0 1
  term: bump Function 1 - 4 * (x - 0.5)^2
  term: edge Function fabs(1 - 2*x) * lt(x, 0.5) + ge(x, 0.75) * (x - 0.75) * 4
OutputVariable: y
  range: 0 1
  aggregation: Maximum
  defuzzifier: Centroid 100
  default: nan
  term: low Function lt(x, 0.5) * (1 - 2 * x)
  term: high Triangle 0.4 1 1
RuleBlock: b
  implication: Minimum
  activation: General
  rule: if u is bump then y is high
  rule: if u is edge then y is low
"""


def test_function_terms_are_their_formulas_on_inputs_and_outputs():
    from mitos_cli.fuzzy.formula import parse

    rb = parse_fll(FUNCTION, "t.fll")
    bump = rb.variables["u"].term("bump")
    assert bump.shape == "formula" and bump.formula == parse("1 - 4 * (x - 0.5)^2")
    x = np.array([0.0, 0.25, 0.5, 0.9])
    assert np.allclose(bump.membership(x), 1 - 4 * (x - 0.5) ** 2, atol=0)
    edge = rb.variables["u"].term("edge").membership(x)
    assert np.allclose(edge, np.abs(1 - 2 * x) * (x < 0.5) + (x >= 0.75) * (x - 0.75) * 4)
    fl = pytest.importorskip("fuzzylite")
    engine = fl.FllImporter().from_string(FUNCTION)
    X = np.linspace(0.01, 0.99, 30)
    engine.input_variable("u").value = X
    engine.process()
    assert np.allclose(run(FUNCTION, X[:, None])[:, 0], engine.output_variable("y").value,
                       atol=1e-12, equal_nan=True)


@pytest.mark.parametrize("formula, value", [
    ("~x^2", 0.49), ("1 - 0.5 * ~x^2", 0.755), ("~(x - 0.5)^2 + 0.5", 0.54),
    ("2^~x^2", 2 ** 0.49), ("~x ^ 2 ^ 2", 0.7 ** 4), ("!x^0", 1.0), ("-x^2 + 1", 0.51)])
def test_fuzzylites_negation_binds_tighter_than_its_power(formula, value):
    """fuzzylite 6 and 8 give `~` and `!` precedence 100 and `^` 90, so `~x^2` is x squared;
    MITOS read it as -(x^2), another membership (0.755 became 1.245 on `1 - 0.5 * ~x^2`).
    `-` (which fuzzylite does not read) stays looser than `^`, as in mathematics."""
    text = FUNCTION.replace("1 - 4 * (x - 0.5)^2", formula)
    term = parse_fll(text, "t.fll").variables["u"].term("bump")
    assert term.formula(np.array([0.7]))[0] == pytest.approx(value, abs=1e-15)


@pytest.mark.parametrize("formula, column, words", [
    ("1 - sin(x", 10, "expected `)`"),
    ("1 - sine(x)", 5, "unknown name `sine`"),
    ("x ** * 2", 6, "unexpected `*`"),
    ("inputX / 2", 1, "unknown name `inputX`"),
    ("x $ 2", 3, "cannot read `$`"),
    ("(x + 1) 2", 9, "after a complete formula"),
])
def test_a_bad_formula_is_refused_at_its_column(formula, column, words):
    text = FUNCTION.replace("1 - 4 * (x - 0.5)^2", formula)
    with pytest.raises(FormatError) as info:
        parse_fll(text, "t.fll")
    assert words in info.value.message
    start = text.splitlines()[3].index(formula) + 1
    assert info.value.span.line == 4 and info.value.span.column == start + column - 1


def test_a_long_formula_is_evaluated_and_a_deep_one_refused_at_its_column():
    """A sum of 1,000 terms or a 100-deep nesting is read and evaluated (both ended in
    RecursionError); one level more is refused at the first `(` past the limit."""
    from mitos_cli.fuzzy.formula import MAX_NESTING, parse

    x = np.linspace(0, 1, 5)
    long = parse("x/10" + " + 0*x" * 1000 + " - x^2^1" * 1000)
    assert np.array_equal(long(x), x / 10 - 1000 * x ** 2 ** 1)
    assert parse("2^-x^3")(x) == pytest.approx(2.0 ** -(x ** 3))
    deep = "(" * MAX_NESTING + "x" + ")" * MAX_NESTING
    assert np.array_equal(parse(deep)(x), x)
    for formula in ("(" + deep + ")", "-" * 1000 + "x", "abs(" * 400 + "x" + ")" * 400):
        text = FUNCTION.replace("1 - 4 * (x - 0.5)^2", formula)
        with pytest.raises(FormatError, match="nested more than 100 deep") as info:
            parse_fll(text, "t.fll")
        start = text.splitlines()[3].index(formula) + 1
        step = 4 if formula.startswith("abs") else 1
        assert info.value.span.line == 4 and info.value.span.column == start + 100 * step


def test_a_formula_read_from_a_deep_stack_is_refused_not_a_recursion_error():
    """Within the nesting limit the parser still recurses a few frames a level: called from
    deep inside a program, a worst-case formula is an error in words, never a traceback."""
    from mitos_cli.errors import TermSetError
    from mitos_cli.fuzzy.formula import MAX_NESTING, parse

    text = "".join(f"x {'+*^'[i % 3]} (" for i in range(MAX_NESTING)) + "x" + ")" * MAX_NESTING

    def deep(n):
        return parse(text) if n == 0 else deep(n - 1)

    with pytest.raises(TermSetError, match="nested too deep to read here"):
        deep(sys.getrecursionlimit() - 300)


def test_a_formula_membership_outside_0_1_is_refused_at_evaluation():
    from mitos_cli.errors import InputError

    text = FUNCTION.replace("1 - 4 * (x - 0.5)^2", "2 * x")
    with pytest.raises(InputError, match=r"gives 1\.8 at u = 0\.9") as info:
        run(text, [[0.9]])
    # said where the term is written (it had no place: `mitos eval` and `check` printed none)
    assert (info.value.span.path, info.value.span.line) == ("t.fll", 4)
    assert "term: bump Function 2 * x" in info.value.render()


@pytest.mark.parametrize("again", ["1 - 4 * (x - 0.5)^2", "x"])
def test_a_formula_term_named_twice_keeps_its_formula(again):
    """fuzzylite 8 reads the last of two terms of one name; the other is read as `bump_2`,
    which was made a new term without its formula: `check` and `eval` ended in a TypeError
    ("a formula term is evaluated by its Formula")."""
    from mitos_cli.fuzzy.formula import parse

    text = FUNCTION.replace("  term: edge", f"  term: bump Function {again}\n  term: edge")
    rb = parse_fll(text, "t.fll")
    u = rb.variables["u"]
    assert u.term("bump_2").formula == parse("1 - 4 * (x - 0.5)^2")
    assert u.term("bump").formula == parse(again)
    assert np.isfinite(run(text, [[0.2], [0.7]])).all()


def test_formula_terms_round_trip_through_fll_and_term_sets(tmp_path):
    from mitos_cli.api import read_rulebase
    from mitos_cli.interop import write_foreign
    from mitos_cli.interop.rules_writer import write_rules

    rb = parse_fll(FUNCTION, "t.fll")
    X = np.linspace(0.01, 0.99, 30)[:, None]
    want = run(FUNCTION, X)
    assert np.array_equal(run(write_foreign(rb, "fll"), X), want, equal_nan=True)
    rules, terms = write_rules(rb, "t.terms.yaml")
    (tmp_path / "t.rules").write_text(rules)
    (tmp_path / "t.terms.yaml").write_text(terms)
    back = compile_rulebase(read_rulebase(tmp_path / "t.rules"))
    assert np.array_equal(evaluate(back, X, strict=False).outputs, want, equal_nan=True)
    with pytest.raises(FormatError, match="FCL has no formula terms"):
        write_foreign(rb, "fcl")


# ---------------------------------------------------------------------------------------------
# Tsukamoto inference: each monotonic consequent term inverted at its degree

TSUKAMOTO = """\
Engine: tsukamoto
InputVariable: u
  range: 0 1
  term: low Triangle 0 0 1
  term: high Triangle 0 1 1
OutputVariable: y
  range: 0 10
  aggregation: none
  defuzzifier: WeightedAverage
  default: nan
  term: down Ramp 10 0
  term: up SShape 2 8
RuleBlock: b
  conjunction: Minimum
  disjunction: Maximum
  implication: none
  activation: General
  rule: if u is low then y is down
  rule: if u is high then y is up
"""


def test_tsukamoto_inverts_each_term_at_its_degree():
    rb = parse_fll(TSUKAMOTO, "t.fll")
    c = compile_rulebase(rb)
    assert c.operators.inference == "tsukamoto"        # inferred from the monotonic terms
    u = 0.3
    w_down, w_up = 1 - u, u
    z_down = 10 - 10 * w_down                          # Ramp 10 0 at w
    z_up = 8 - 6 * np.sqrt((1 - w_up) / 2) if w_up > 0.5 else 2 + 6 * np.sqrt(w_up / 2)
    want = (w_down * z_down + w_up * z_up) / (w_down + w_up)
    assert run(TSUKAMOTO, [[u]])[0, 0] == pytest.approx(want, abs=1e-12)
    fl = pytest.importorskip("fuzzylite")
    engine = fl.FllImporter().from_string(TSUKAMOTO)
    X = np.linspace(0.05, 0.95, 19)
    engine.input_variable("u").value = X
    engine.process()
    assert np.allclose(run(TSUKAMOTO, X[:, None])[:, 0], engine.output_variable("y").value,
                       atol=1e-12)


def test_tsukamoto_refuses_a_term_it_cannot_invert_and_formats_without_it():
    from mitos_cli.interop import write_foreign

    with pytest.raises(FormatError, match="Tsukamoto inference inverts monotonic terms"):
        parse_fll(TSUKAMOTO.replace("WeightedAverage", "WeightedAverage Tsukamoto").replace(
            "term: up SShape 2 8", "term: up Triangle 2 8 9"), "t.fll")
    rb = parse_fll(TSUKAMOTO, "t.fll")
    X = np.linspace(0, 1, 11)[:, None]
    assert np.array_equal(run(write_foreign(rb, "fll"), X), run(TSUKAMOTO, X), equal_nan=True)
    for fmt in ("fcl", "fis"):
        with pytest.raises(FormatError, match="no Tsukamoto inference"):
            write_foreign(rb, fmt)


def test_fll_writer_refuses_a_tsukamoto_term_without_inverse_at_the_term(tmp_path, capsys):
    """A triangle no rule concludes is fine to the rule language, not to FLL's `WeightedAverage
    Tsukamoto`: `convert --to fll` failed on reading its own text back, at a line of a file it
    never wrote; it is refused at the term in the term set, and nothing is written."""
    from mitos_cli.api import read_rulebase
    from mitos_cli.cli.app import main
    from mitos_cli.interop import write_foreign

    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n"
        "  x: {role: input, universe: [0, 10], terms: {A: {shape: triangle, points: [0, 0, 10]},"
        " B: {shape: triangle, points: [0, 10, 10]}}}\n"
        "  y:\n    role: output\n    universe: [0, 1]\n    default: 0\n    terms:\n"
        "      DN: {shape: ramp, points: [1, 0]}\n      UP: {shape: ramp, points: [0, 1]}\n"
        "      T: {shape: triangle, points: [0, 0.5, 1]}\n", encoding="utf-8")
    rules = tmp_path / "t.rules"
    rules.write_text('terms "t.terms.yaml"\noperators: inference = tsukamoto\n'
                     "r1: if x is A then y is DN\nr2: if x is B then y is UP\n", encoding="utf-8")
    with pytest.raises(FormatError) as info:
        write_foreign(read_rulebase(rules), "fll")
    assert "output term `y.T`" in info.value.message and "not a `triangle` term" in \
        info.value.message
    assert info.value.span.path.endswith("t.terms.yaml") and info.value.span.line == 10
    with pytest.raises(SystemExit) as done:
        main(["convert", str(rules), "--to", "fll", "-o", str(tmp_path / "t.fll")])
    err = capsys.readouterr().err
    assert done.value.code == 1 and "t.terms.yaml:10:" in err and "t.fll:" not in err
    assert not (tmp_path / "t.fll").exists()


OPPOSITE_SIGMOIDS = """\
Engine: opposite
InputVariable: x
  range: 0 10
  term: low Triangle 0 0 10
  term: also_low Triangle 0 0 5
OutputVariable: y
  range: 0 1
  aggregation: none
  defuzzifier: WeightedAverage Tsukamoto
  default: 0.5
  term: down Sigmoid 0.5 -30
  term: up Sigmoid 0.5 30
RuleBlock: b
  conjunction: Minimum
  activation: General
  rule: if x is low then y is down
  rule: if x is also_low then y is up
"""


def test_tsukamoto_inverses_at_both_infinities_give_the_default_and_say_so(tmp_path, capsys):
    """At x = 0 both rules fire fully: `down` reaches 1 at -inf and `up` at +inf, and their
    weighted average has no value. NumPy's "invalid value encountered in add" reached the
    terminal, `mitos eval` printed the declared default as the rules' value (`y = 0.5`, no
    note) and `--json` did not list it as defaulted; without a default the error blamed a
    hedged consequent's underflow."""
    import json
    import warnings

    from mitos_cli.cli.app import main
    from mitos_cli.errors import EmptyOutputError

    path = tmp_path / "t.fll"
    path.write_text(OPPOSITE_SIGMOIDS, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert run(OPPOSITE_SIGMOIDS, [[0.0]])[0, 0] == 0.5
        main_out = []
        for argv in (["eval", str(path), "x=0"], ["eval", str(path), "x=0", "--json"]):
            with pytest.raises(SystemExit) as done:
                main(argv)
            captured = capsys.readouterr()
            assert done.value.code == 0 and "RuntimeWarning" not in captured.err
            main_out.append(captured.out)
    assert "y = 0.5   (its default: the rules that fire give it no value here)" in main_out[0]
    assert json.loads(main_out[1])["defaulted"] == ["y"]
    c = compile_rulebase(parse_fll(OPPOSITE_SIGMOIDS.replace("  default: 0.5\n", ""), "t.fll"))
    with pytest.raises(EmptyOutputError, match=r"lie at \+inf and -inf .* no value"):
        evaluate(c, np.array([[0.0]]))


def test_a_batch_says_which_rows_the_rules_fire_in_but_give_no_value(tmp_path, capsys):
    """`--batch` said "no rule sets `y` in 1 row of 3" of a row where both rules fire fully
    (x = 0: inverses at +inf and -inf); x = 10 is a row no rule sets."""
    from mitos_cli.cli.app import main

    path = tmp_path / "t.fll"
    path.write_text(OPPOSITE_SIGMOIDS.replace("Triangle 0 0 10", "Triangle 0 0 9"),
                    encoding="utf-8")
    (tmp_path / "b.csv").write_text("x\n0\n1\n10\n", encoding="utf-8")
    with pytest.raises(SystemExit) as done:
        main(["eval", str(path), "--batch", str(tmp_path / "b.csv")])
    captured = capsys.readouterr()
    assert done.value.code == 0
    assert ("no rule sets `y` in 1 row of 3, and the rules that fire give it no value in 1 "
            "other: the file's default (0.5) is written there") in captured.err
    assert captured.out.splitlines()[1] == "0,0.5"
    path.write_text(OPPOSITE_SIGMOIDS.replace("  default: 0.5\n", ""), encoding="utf-8")
    with pytest.raises(SystemExit) as done:
        main(["eval", str(path), "--batch", str(tmp_path / "b.csv")])
    err = capsys.readouterr().err
    assert done.value.code == 1
    assert "b.csv:2:1: no output value: the rules that fire give `y` no value for x=0" in err


def test_tsukamoto_refuses_a_term_concluded_twice():
    from mitos_cli.errors import RuleBaseError

    text = TSUKAMOTO + "  rule: if u is very high then y is up\n"
    with pytest.raises(RuleBaseError, match="their degrees add up and may pass 1"):
        compile_rulebase(parse_fll(text, "t.fll"))


def test_fcl_cogs_over_monotonic_terms_is_tsukamoto():
    from mitos_cli.interop.fcl import parse_fcl

    text = """\
FUNCTION_BLOCK t
VAR_INPUT u : REAL; END_VAR
VAR_OUTPUT y : REAL; END_VAR
FUZZIFY u RANGE := (0 .. 1); TERM low := Triangle 0 0 1; TERM high := Triangle 0 1 1; END_FUZZIFY
DEFUZZIFY y RANGE := (0 .. 10); TERM down := Ramp 10 0; TERM up := SShape 2 8;
  METHOD : COGS; DEFAULT := nan; END_DEFUZZIFY
RULEBLOCK b AND : MIN; RULE 1 : IF u IS low THEN y IS down; RULE 2 : IF u IS high THEN y IS up;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""
    c = compile_rulebase(parse_fcl(text, "t.fcl"))
    assert c.operators.inference == "tsukamoto"
    X = np.linspace(0, 1, 11)[:, None]
    assert np.array_equal(evaluate(c, X, strict=False, detail=False).outputs,
                          run(TSUKAMOTO, X), equal_nan=True)


# ---------------------------------------------------------------------------------------------
# Input ranges: fuzzylite clamps an input only under `lock-range: true` (its default is false)

RANGES = """\
Engine: ranges
InputVariable: x
  range: 0 10
LOCK_X
  term: low Triangle 0 0 10
  term: high Triangle 0 10 10
InputVariable: z
  range: 0 10
LOCK_Z
  term: wide Triangle -10 0 20
OutputVariable: y
  range: 0 1
  aggregation: none
  defuzzifier: WeightedAverage TakagiSugeno
  default: nan
  term: a Constant 0
  term: b Constant 1
RuleBlock: r
  conjunction: Minimum
  activation: General
  rule: if x is low and z is wide then y is a
  rule: if x is high and z is wide then y is b
"""


def ranges(x: str, z: str) -> str:
    return RANGES.replace("LOCK_X", x).replace("LOCK_Z", z)


@pytest.mark.parametrize("lock", ["  lock-range: false", "  description: lock-range unwritten"])
def test_an_input_not_locked_to_its_range_is_evaluated_as_given(lock):
    """By hand: at x = 12 both triangles of x are 0 (they end at 10), so no rule fires and y is
    its default, NaN; clamped to 10, `high` is 1 and y is 1. z = 5 is inside its range."""
    rb = parse_fll(ranges(lock, lock), "t.fll")
    assert compile_rulebase(rb).operators.inputs == "as_given"
    got = run(ranges(lock, lock), [[12.0, 5.0], [5.0, 5.0], [-3.0, 5.0]])[:, 0]
    assert np.isnan(got[0]) and got[1] == 0.5 and np.isnan(got[2])
    assert not rb.notes


def test_inputs_locked_to_their_ranges_are_clamped():
    text = ranges("  lock-range: true", "  lock-range: true")
    assert compile_rulebase(parse_fll(text, "t.fll")).operators.inputs == "clamped"
    assert run(text, [[12.0, 5.0], [-3.0, 5.0]])[:, 0].tolist() == [1.0, 0.0]


def test_inputs_locked_and_not_are_all_clamped_with_a_note_naming_the_others():
    rb = parse_fll(ranges("  lock-range: true", "  lock-range: false"), "t.fll")
    assert compile_rulebase(rb).operators.inputs == "clamped"
    assert len(rb.notes) == 1 and rb.notes[0].startswith("t.fll:9:15: ")
    assert "`z` not locked to its range (`lock-range: false`" in rb.notes[0]


@pytest.mark.parametrize("lock", ["true", "false"])
def test_the_fll_writer_says_whether_inputs_are_clamped(lock):
    from mitos_cli.interop.fll import write_fll

    text = write_fll(parse_fll(ranges(f"  lock-range: {lock}", f"  lock-range: {lock}"), "t.fll"))
    inputs = text.split("OutputVariable:")[0]
    assert inputs.count(f"lock-range: {lock}") == 2 and inputs.count("lock-range:") == 2
    again = compile_rulebase(parse_fll(text, "back.fll"))
    assert again.operators.inputs == ("clamped" if lock == "true" else "as_given")


def test_fidelity_fuzzylite_evaluates_fcl_inputs_as_given_and_keeps_an_fll_files_locks():
    """fuzzylite's FCL and `.fis` importers leave `lock-range` false (FCL has no word for an
    input's); an FLL file says its own, which its reading already kept."""
    from mitos_cli.interop.common import fidelity_settings
    from mitos_cli.interop.fcl import parse_fcl
    from mitos_cli.lang.model import Setting

    fcl = parse_fcl("FUNCTION_BLOCK t\nVAR_INPUT u : REAL; END_VAR\nVAR_OUTPUT y : REAL; END_VAR\n"
                    "FUZZIFY u RANGE := (0 .. 1); TERM low := Triangle 0 0 1; END_FUZZIFY\n"
                    "DEFUZZIFY y RANGE := (0 .. 1); TERM z := 1; METHOD : COGS; DEFAULT := 0; "
                    "END_DEFUZZIFY\nRULEBLOCK b RULE 1 : IF u IS low THEN y IS z; END_RULEBLOCK\n"
                    "END_FUNCTION_BLOCK\n", "t.fcl")
    given = Setting("inputs", "as_given")
    for engine in ("fuzzylite", "fuzzylite6", "jfuzzylogic"):
        assert given in fidelity_settings(fcl, engine)
    assert given not in fidelity_settings(fcl, "matlab")
    locked = parse_fll(ranges("  lock-range: true", "  lock-range: true"), "t.fll")
    assert given not in fidelity_settings(locked, "fuzzylite")


def test_inputs_outside_their_ranges_agree_with_fuzzylite():
    fl = pytest.importorskip("fuzzylite", reason="pyfuzzylite is not installed")
    for x_lock, z_lock in (("false", "false"), ("true", "true")):
        text = ranges(f"  lock-range: {x_lock}", f"  lock-range: {z_lock}")
        engine = fl.FllImporter().from_string(text)
        X = np.array([[x, z] for x in (-3.0, 0.0, 4.0, 10.0, 12.5) for z in (-20.0, 5.0, 25.0)])
        want = []
        for x, z in X:
            engine.input_variable("x").value, engine.input_variable("z").value = x, z
            engine.process()
            want.append(float(np.asarray(engine.output_variable("y").value).ravel()[0]))
        np.testing.assert_allclose(run(text, X)[:, 0], want, rtol=0, atol=1e-15)
