"""``accumulation = S``: weighted inference joining the rules that conclude one value with an
S-norm before the average (jFuzzyLogic's ``ACCU`` under ``METHOD : COGS`` / ``COGF``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.engine.check import check_rulebase
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate, evaluate_one
from mitos_cli.errors import LessonError, MitosError
from mitos_cli.fuzzy.norms import SNORMS
from mitos_cli.interop import write_foreign
from mitos_cli.interop.fcl import parse_fcl
from mitos_cli.lang.model import Behavior, Consequent, Prop, Rule, RuleBase, Setting
from mitos_cli.lang.parse import parse_rules
from mitos_cli.lang.resolve import build_rulebase
from mitos_cli.lang.termfile import parse_termset
from mitos_cli.lang.terms import Term, TermSet, Variable
from mitos_cli.teach.adapt import parameterise

TERMS = """\
variables:
  x:
    role: input
    universe: [0, 10]
    terms:
      LO: {shape: left_shoulder, points: [2, 8]}
      MID: {shape: triangle, points: [0, 5, 10]}
      HI: {shape: right_shoulder, points: [2, 8]}
  y:
    role: output
    universe: [0, 100]
    default: 50
    terms: {A: 10, B: 90, C: 90, L: {shape: linear, coefficients: {x: 2}, constant: 3}}
"""

RULES = """\
terms "a.terms.yaml"
operators: {operators}
r1: if x is LO then y is A
r2: if x is MID then y is A
r3: if x is HI then y is B
r4: if x is MID then y is C with 0.5
"""


def compiled(operators: str, rules: str = RULES):
    termset = parse_termset(TERMS, "a.terms.yaml")
    rb = build_rulebase(parse_rules(rules.format(operators=operators), "a.rules"), (termset,))
    return compile_rulebase(rb)


def memberships(x: float) -> tuple[float, float, float]:
    lo = min(max((8 - x) / 6, 0.0), 1.0)
    hi = min(max((x - 2) / 6, 0.0), 1.0)
    mid = max(0.0, 1 - abs(x - 5) / 5)
    return lo, mid, hi


@pytest.mark.parametrize("x", [0.0, 3.0, 4.0, 5.0, 6.5, 10.0])
def test_max_joins_the_rules_of_one_value_before_the_average(x: float):
    """By hand, as jFuzzyLogic computes COGS under ACCU MAX: 10 gets max(r1, r2), 90 (both
    B and C: it keys singletons by value) gets max(r3, 0.5 r4)."""
    lo, mid, hi = memberships(x)
    w10, w90 = max(lo, mid), max(hi, 0.5 * mid)
    want = (10 * w10 + 90 * w90) / (w10 + w90)
    got = evaluate(compiled("accumulation = max"), np.array([[x]]), detail=False).outputs[0, 0]
    assert got == pytest.approx(want, rel=1e-15)
    summed = evaluate(compiled("inference = weighted_average"), np.array([[x]]),
                      detail=False).outputs[0, 0]
    assert summed == pytest.approx((10 * (lo + mid) + 90 * (hi + 0.5 * mid))
                                   / (lo + mid + hi + 0.5 * mid), rel=1e-15)


def test_probabilistic_sum_and_weighted_sum():
    lo, mid, hi = memberships(4.0)
    w10, w90 = lo + mid - lo * mid, hi + 0.5 * mid - hi * 0.5 * mid
    got = evaluate(compiled("accumulation = probabilistic_sum, inference = weighted_sum"),
                   np.array([[4.0]]), detail=False).outputs[0, 0]
    assert got == pytest.approx(10 * w10 + 90 * w90, rel=1e-15)


def test_linear_consequents_group_by_their_function():
    """Two rules concluding one linear function are joined; its value is taken once."""
    rules = RULES.replace("then y is A\nr2: if x is MID then y is A",
                          "then y is L\nr2: if x is MID then y is L")
    x = 3.0
    lo, mid, hi = memberships(x)
    w_l, w90 = max(lo, mid), max(hi, 0.5 * mid)
    want = ((2 * x + 3) * w_l + 90 * w90) / (w_l + w90)
    got = evaluate(compiled("accumulation = max", rules), np.array([[x]]), detail=False)
    assert got.outputs[0, 0] == pytest.approx(want, rel=1e-15)


def test_a_linear_function_meeting_a_crisp_value_is_joined_there():
    """jFuzzyLogic keys its table by the value at the input: where `L = 2 x + 3` is 10 (x =
    3.5) its rules join `A`'s (10); a hair away they do not."""
    rules = RULES.replace("r2: if x is MID then y is A", "r2: if x is MID then y is L").replace(
        "r4: if x is MID then y is C with 0.5\n", "")
    c = compiled("accumulation = max", rules)
    for x, joined in [(3.5, True), (3.5 + 1e-9, False)]:
        lo, mid, hi = memberships(x)
        if joined:
            want = (10 * max(lo, mid) + 90 * hi) / (max(lo, mid) + hi)
        else:
            want = (10 * lo + (2 * x + 3) * mid + 90 * hi) / (lo + mid + hi)
        got = evaluate(c, np.array([[x]]), detail=False).outputs[0, 0]
        assert got == pytest.approx(want, rel=1e-14), x
    assert evaluate(c, np.array([[3.5]]), detail=False).outputs[0, 0] == pytest.approx(30.0)


def test_nothing_firing_takes_the_default_and_describe_names_it():
    c = compiled("accumulation = max")
    assert "accumulation = max" in c.operators.describe()
    assert c.scalar is None                       # the NumPy path answers one sample too
    rules = RULES.replace("x is LO", "x is LO and x is HI").replace("x is MID", "x is MID and "
                                                                     "x is HI")
    c = compiled("accumulation = max", rules.replace("r3: if x is HI", "r3: if x is HI and "
                                                                       "x is LO"))
    assert evaluate(c, np.array([[0.0]]), detail=False).outputs[0, 0] == 50.0


def test_an_unknown_accumulation_is_refused_with_the_choices():
    with pytest.raises(MitosError) as info:
        compiled("accumulation = maximum_sum")
    assert info.value.message == "unknown accumulation `maximum_sum`"
    # `sum` first, with what it means here, then each S-norm once (no aliases, no cut)
    assert info.value.expected == ("`sum` (each rule counted in the average, the default) or an "
                                   "S-norm: max, probabilistic_sum, bounded_sum, drastic_sum, "
                                   "einstein_sum, hamacher_sum, nilpotent_maximum")
    assert info.value.hint == "did you mean `maximum`?"


@pytest.mark.parametrize("key, value, hint", [
    ("accumulation", "SUM", "did you mean `sum`?"),
    ("aggregation", "summ", "did you mean `sum`?"),
    ("aggregation", "unbounded", "did you mean `unbounded_sum`?"),
    ("aggregation", "probor_sum", "did you mean `probor`?"),
    ("aggregation", "nsum", "jFuzzyLogic's `NSUM` is `bounded_sum` (the two are equal)"),
    ("accumulation", "NSUM", "jFuzzyLogic's `NSUM` is `bounded_sum` (the two are equal)")])
def test_an_unknown_aggregation_or_accumulation_hints_sum_and_foreign_names(key, value, hint):
    """The list used to be every S-norm name and alias, cut at 12 before `sum`."""
    with pytest.raises(MitosError) as info:
        compiled(f"inference = mamdani, {key} = {value}" if key == "aggregation"
                 else f"{key} = {value}")
    assert info.value.message == f"unknown {key} `{value}`"
    assert info.value.expected.startswith("`sum` (")
    assert info.value.hint == hint


def test_check_calls_it_idle_outside_weighted_inference_and_words_duplicates():
    rules = RULES + "r5: if x is HI then y is B\n"
    termset = parse_termset(TERMS.replace("A: 10, B: 90, C: 90, L: {shape: linear, "
                                          "coefficients: {x: 2}, constant: 3}",
                                          "A: 10, B: 90, C: 90"), "a.terms.yaml")
    rb = build_rulebase(parse_rules(rules.format(operators="accumulation = max"), "a.rules"),
                        (termset,))
    found = check_rulebase(rb).findings
    dup = [f for f in found if f.code == "duplicate"]
    assert dup and "it changes nothing (max accumulation keeps the stronger" in dup[0].message
    rb = build_rulebase(parse_rules(rules.format(
        operators="accumulation = max, inference = mamdani"), "a.rules"), (termset,))
    idle = [f for f in check_rulebase(rb).findings if f.code == "idle-setting"]
    assert [f.message for f in idle] == ["`accumulation = max` has no effect: behavior `main` "
                                         "uses mamdani inference"]


def test_adaptation_refuses_it():
    with pytest.raises(LessonError, match="adaptation does not cover `accumulation = max`"):
        parameterise(compiled("accumulation = max"))


def _rulebase(operators: str, rules: str = RULES) -> RuleBase:
    termset = parse_termset(TERMS, "a.terms.yaml")
    return build_rulebase(parse_rules(rules.format(operators=operators), "a.rules"), (termset,))


def test_fcl_writes_it_as_accu_and_reads_back_the_same_bits():
    rb = _rulebase("accumulation = probabilistic_sum")
    text = write_foreign(rb, "fcl", dialect="iec")
    assert "METHOD : COGS;" in text and text.count("ACCU : ASUM;") == 1
    back = parse_fcl(text, "back.fcl")
    X = np.linspace(-1, 11, 97)[:, None]
    before = evaluate(compile_rulebase(rb), X, detail=False).outputs
    after = evaluate(compile_rulebase(back), X, detail=False).outputs
    assert np.array_equal(bits(after), bits(before))


def test_fuzzylites_fcl_refuses_it_where_it_joins_rules_as_its_engine_would_not():
    """fuzzylite 6 counts every rule under COGS whatever the DEFUZZIFY's ACCU says, so that
    dialect cannot carry an accumulation that joins two rules; where every value is concluded
    once it changes nothing and is written."""
    with pytest.raises(MitosError) as info:
        write_foreign(_rulebase("accumulation = max"), "fcl", dialect="fuzzylite")
    assert info.value.message == ("fuzzylite's FCL has no accumulation of the rules that "
                                  "conclude one value: `r1` and `r2` both set `y` to 10, which "
                                  "`accumulation = max` joins")
    assert "--dialect iec" in info.value.hint
    once = RULES.replace("r2: if x is MID then y is A\n", "").replace("then y is C with 0.5",
                                                                      "then y is 33")
    terms = TERMS.replace(", L: {shape: linear, coefficients: {x: 2}, constant: 3}", "")
    rb = build_rulebase(parse_rules(once.format(operators="accumulation = max"), "a.rules"),
                        (parse_termset(terms, "a.terms.yaml"),))
    back = parse_fcl(write_foreign(rb, "fcl", dialect="fuzzylite"), "back.fcl")
    X = np.linspace(-1, 11, 97)[:, None]
    assert np.array_equal(bits(evaluate(compile_rulebase(back), X, detail=False).outputs),
                          bits(evaluate(compile_rulebase(rb), X, detail=False).outputs))


#: fuzzylite's FCL (ACCU in DEFUZZIFY) with two rules concluding `a` under COGS + ACCU MAX.
FUZZYLITE_COGS = """\
//Code automatically generated with fuzzylite 6.0.

FUNCTION_BLOCK accu

VAR_INPUT
  x: REAL;
END_VAR

VAR_OUTPUT
  y: REAL;
END_VAR

FUZZIFY x
  RANGE := (0.000 .. 1.000);
  TERM low := Triangle 0.000 0.250 0.500;
  TERM mid := Triangle 0.250 0.500 0.750;
  TERM high := Triangle 0.250 0.750 1.000;
END_FUZZIFY

DEFUZZIFY y
  RANGE := (0.000 .. 1.000);
  TERM a := 0.200;
  TERM b := 0.800;
  METHOD : COGS;
  ACCU : MAX;
  DEFAULT := nan;
END_DEFUZZIFY

RULEBLOCK
  AND : MIN;
  OR : MAX;
  ACT : MIN;
  RULE 1 : if x is low then y is a
  RULE 2 : if x is mid then y is a
  RULE 3 : if x is high then y is b
END_RULEBLOCK

END_FUNCTION_BLOCK
"""


def test_fuzzylites_accu_in_defuzzify_under_cogs_counts_every_rule_as_fuzzylite_6():
    """The `fuzzylite` 6 binary (Debian's 6.0+dfsg-6, `-of fld -values 9 -decimals 12`) gives
    0.32, 0.4 and 0.56 at x = 0.375, 0.5, 0.625: every rule counted, the ACCU unused (joined
    by MAX, 0.375 would give 0.4). The same ACCU in the RULEBLOCK is jFuzzyLogic's dialect
    (fuzzylite 6 fails to read it there) and joins them."""
    X = np.array([[0.375], [0.5], [0.625]])
    rb = parse_fcl(FUZZYLITE_COGS, "accu.fcl")
    assert [n for n in rb.notes if "fuzzylite's dialect" in n] == [
        "accu.fcl:25:10: `ACCU : MAX` in DEFUZZIFY under a weighted `METHOD` is fuzzylite's "
        "dialect, whose engine (fuzzylite 6) counts every rule there: read so, `r1` and `r2` "
        "both adding `y is a`; jFuzzyLogic would join them with MAX (write the ACCU in the "
        "RULEBLOCK for that)"]
    c = compile_rulebase(rb)
    assert not c.operators.accumulated
    got = evaluate(c, X, detail=False).outputs[:, 0]
    np.testing.assert_allclose(got, [0.32, 0.4, 0.56], rtol=0, atol=1e-12)
    iec = FUZZYLITE_COGS.replace("  ACCU : MAX;\n", "").replace("  ACT : MIN;\n",
                                                                "  ACT : MIN;\n  ACCU : MAX;\n")
    joined = compile_rulebase(parse_fcl(iec, "accu.fcl"))
    assert joined.operators.accumulation == "max"
    np.testing.assert_allclose(evaluate(joined, X, detail=False).outputs[:, 0],
                               [0.4, 0.4, 0.56], rtol=0, atol=1e-12)
    single = FUZZYLITE_COGS.replace("  RULE 2 : if x is mid then y is a\n", "")
    assert not [n for n in parse_fcl(single, "accu.fcl").notes if "dialect" in n]


@pytest.mark.parametrize("fmt, name", [("fll", "FLL"), ("fis", "MATLAB's .fis")])
def test_fll_and_fis_refuse_it_where_it_joins_rules_and_write_it_where_it_cannot(fmt, name):
    rb = _rulebase("accumulation = max", RULES.replace("then y is A\nr2: if x is MID then y "
                                                       "is A", "then y is A\nr2: if x is MID "
                                                       "then y is 33"))
    with pytest.raises(MitosError) as info:
        write_foreign(rb, fmt)
    assert info.value.message == (f"{name} has no accumulation of the rules that conclude one "
                                  f"value: `r3` and `r4` both set `y` to 90, which "
                                  f"`accumulation = max` joins")
    assert (info.value.span.line, info.value.span.column) == (2, 12)
    once = build_rulebase(parse_rules(RULES.replace("r2: if x is MID then y is A\n", "").replace(
        "then y is C with 0.5", "then y is 33").format(operators="accumulation = max"),
        "a.rules"), (parse_termset(TERMS.replace(", L: {shape: linear, coefficients: {x: 2}, "
                                                 "constant: 3}", ""), "a.terms.yaml"),))
    assert write_foreign(once, fmt)                 # each value once: the S-norm changes nothing
    meets = build_rulebase(parse_rules(RULES.replace("r2: if x is MID then y is A\n", "").replace(
        "then y is C with 0.5", "then y is L").format(operators="accumulation = max"), "a.rules"),
        (parse_termset(TERMS, "a.terms.yaml"),))
    with pytest.raises(MitosError) as info:         # L = 2 x + 3 is 10 (A) at x = 3.5
        write_foreign(meets, fmt)
    assert info.value.message == (f"{name} has no accumulation of the rules that conclude one "
                                  f"value: `y`'s linear function (`r4`) meets its other values "
                                  f"at some inputs, where `accumulation = max` joins their rules")


# ---------------------------------------------------------------------------------------------
# Random rule bases: the bits of a row do not depend on the batch, and the value is the fold
# by hand.

X_TERMS = (Term("P", "triangle", (0.0, 2.0, 6.0)), Term("Q", "trapezoid", (1.0, 4.0, 5.0, 9.0)),
           Term("R", "right_shoulder", (3.0, 8.0)))
Y_VALUES = {"V0": 0.0, "V1": 40.0, "V2": 40.0, "V3": 100.0}


@st.composite
def accumulated(draw):
    x = Variable("x", "input", (0.0, 10.0), X_TERMS)
    terms = tuple(Term(n, "singleton", (v,)) for n, v in Y_VALUES.items())
    if draw(st.booleans()):       # G is 40 (V1's value) at x = 10, the universe's end
        terms += (Term("F", "linear", (draw(st.sampled_from([-3.0, 0.5, 7.0])), 1.0)),
                  Term("G", "linear", (4.0, 0.0)))
    y = Variable("y", "output", (-100.0, 200.0), terms)
    rules = []
    for i in range(draw(st.integers(1, 8))):
        antecedent = Prop("x", draw(st.sampled_from(["P", "Q", "R"])),
                          negated=draw(st.booleans()))
        hedges = draw(st.sampled_from([(), (), ("very",)]))
        rules.append(Rule(f"r{i}", antecedent,
                          (Consequent("y", draw(st.sampled_from([t.name for t in terms])),
                                      hedges=hedges),),
                          draw(st.sampled_from([1.0, 0.5, 0.25]))))
    ops = (Setting("accumulation", draw(st.sampled_from(sorted(SNORMS)))),
           Setting("inference", draw(st.sampled_from(["weighted_average", "weighted_sum"]))))
    return RuleBase(None, (TermSet((x, y)),), (Behavior("main", tuple(rules)),), ops)


def by_hand(rb: RuleBase, x: float) -> float:
    """jFuzzyLogic's algorithm, one rule at a time: each rule's weight added into a table
    keyed by the value it concludes (at this input) with the S-norm, then the weighted
    average (or sum)."""
    c = compile_rulebase(rb)
    norm = SNORMS[c.operators.accumulation]
    dof = evaluate(c, np.array([[x]]), strict=False).dof[0]
    table: dict[tuple, list[float]] = {}
    y = rb.variables["y"]
    for r, rule in enumerate(rb.behaviors[0].rules):
        cons = rule.consequents[0]
        term = y.term(cons.term)
        w = dof[r] ** 2 if cons.hedges else dof[r]
        value = term.params[1] + term.params[0] * x if term.shape == "linear" else term.params[0]
        acc = table.setdefault((value, math.copysign(1.0, value)), [0.0, value])
        acc[0] = float(norm(acc[0], w))
    num = sum(w * v for w, v in table.values())
    den = sum(w for w, _ in table.values())
    if c.operators.inference == "weighted_sum":
        return num                                   # 0, the sum of nothing, without a default
    return num / den if den > 0 else np.nan


def bits(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


@settings(max_examples=80, deadline=None)
@given(rb=accumulated(), X=st.lists(st.floats(-1, 11), min_size=1, max_size=10))
def test_one_sample_gives_the_bits_of_its_row_and_the_fold_by_hand(rb: RuleBase, X):
    c = compile_rulebase(rb)
    A = np.array(X, dtype=float)[:, None]
    batch = evaluate(c, A, strict=False, detail=False).outputs[:, 0]
    for i, x in enumerate(X):
        single = evaluate(c, A[i:i + 1], strict=False, detail=False).outputs[0, 0]
        assert bits(single) == bits(batch[i])
        if not np.isnan(single):
            assert bits(evaluate_one(c, [x])[0]) == bits(batch[i])
        want = by_hand(rb, min(max(x, 0.0), 10.0))
        if np.isnan(want):
            assert np.isnan(single)
        else:
            assert single == pytest.approx(want, rel=1e-12, abs=1e-12)
