"""Takagi-Sugeno inference: constant and linear consequents, weighted average and weighted sum."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.api import load_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.errors import RuleBaseError, TermSetError
from mitos_cli.fuzzy.shapes import SHAPES, linear
from mitos_cli.lang.termfile import parse_termset

TERMS = """\
variables:
  road:
    role: input
    universe: [0, 160]
    terms:
      NARROW: {shape: left_shoulder, points: [40, 70]}
      WIDE: {shape: right_shoulder, points: [40, 100]}
  size:
    role: input
    universe: [0, 100]
    terms:
      SMALL: {shape: left_shoulder, points: [10, 40]}
      LARGE: {shape: right_shoulder, points: [10, 70]}
  steering:
    role: output
    universe: [30, 150]
    terms:
      TURN: {shape: linear, coefficients: {road: 0.5, size: -1}, constant: 90}
      EASE: {shape: linear, coefficients: {size: 0.25}, constant: 60}
      LS: {shape: constant, value: 70}
      ST: 90
"""

RULES = """\
terms "s.terms.yaml"
{operators}
if road is NARROW then steering is TURN
if road is WIDE and size is LARGE then steering is LS with 0.5
if road is WIDE and size is SMALL then steering is EASE
if size is very LARGE then steering is ST with 0.25
"""


def write(tmp_path, operators: str = "", terms: str = TERMS, rules: str = RULES):
    (tmp_path / "s.terms.yaml").write_text(terms)
    path = tmp_path / "s.rules"
    path.write_text(rules.format(operators=operators))
    return path


def reference(road: float, size: float, weighted_sum: bool = False) -> float:
    """The same rule base computed by hand, one sample at a time."""
    narrow = np.clip((70 - road) / 30, 0, 1)
    wide = np.clip((road - 40) / 60, 0, 1)
    small = np.clip((40 - size) / 30, 0, 1)
    large = np.clip((size - 10) / 60, 0, 1)
    w = np.array([narrow, 0.5 * min(wide, large), min(wide, small), 0.25 * large ** 2])
    y = np.array([0.5 * road - size + 90, 70, 0.25 * size + 60, 90])
    return float((w * y).sum() if weighted_sum else (w * y).sum() / w.sum())


def test_linear_term_layout():
    ts = parse_termset(TERMS)
    steering = ts.variable("steering")
    assert steering.term("TURN").shape == "linear"
    assert steering.term("TURN").params == (0.5, -1.0, 90.0)    # road, size, constant
    assert steering.term("EASE").params == (0.0, 0.25, 60.0)    # missing coefficient is 0
    assert steering.term("LS").shape == "singleton"             # `constant` is a singleton
    assert steering.term("LS").params == (70.0,)
    assert np.isnan(steering.term("TURN").center)
    assert "linear" in SHAPES


def test_linear_function_sums_in_order():
    x = np.array([[10.0, 20.0], [1.0, 2.0]])
    assert linear(x, 0.5, -1.0, 90.0).tolist() == [94.0, 98.0]
    assert linear(x, 0.0, 0.0, 7.0).tolist() == [7.0, 7.0]


def test_compiled_coefficients(tmp_path):
    c = load_rulebase(write(tmp_path)).compiled
    assert c.inputs == ("road", "size")
    assert c.cons_linear.shape == (4, 1, 3)
    assert c.cons_linear[:, 0].tolist() == [[0.5, -1, 90], [0, 0, 70], [0, 0.25, 60], [0, 0, 90]]


def test_no_linear_array_without_linear_terms():
    assert load_rulebase().compiled.cons_linear is None


@settings(max_examples=60, deadline=None)
@given(st.floats(0, 160), st.floats(0, 100))
def test_weighted_average_matches_hand_computation(tmp_path_factory, road, size):
    rb = load_rulebase(write(tmp_path_factory.mktemp("s")))
    got = rb.evaluate(road=road, size=size)["steering"]
    assert got == pytest.approx(reference(road, size), rel=1e-12, abs=1e-12)


def test_weighted_sum(tmp_path):
    rb = load_rulebase(write(tmp_path, "operators: inference = weighted_sum"))
    for road, size in [(50, 30), (120, 80), (0, 0), (160, 100)]:
        assert rb.evaluate(road=road, size=size)["steering"] == pytest.approx(
            reference(road, size, weighted_sum=True), rel=1e-12)


def test_batch_rows_equal_single_evaluations_bit_for_bit(tmp_path):
    rb = load_rulebase(write(tmp_path))
    rng = np.random.default_rng(np.random.SeedSequence(3))
    X = np.column_stack([rng.uniform(0, 160, 3000), rng.uniform(0, 100, 3000)])
    batch = evaluate(rb.compiled, X).outputs
    for i in range(0, 3000, 97):
        assert evaluate(rb.compiled, X[i:i + 1]).outputs[0, 0] == batch[i, 0]


def test_linear_coefficient_brings_its_input_into_the_network(tmp_path):
    rules = 'terms "s.terms.yaml"\nif road is NARROW then steering is EASE\n'
    rb = load_rulebase(write(tmp_path, rules=rules))
    assert rb.inputs == ("road", "size")           # `size` only appears in the consequent
    assert rb.evaluate(road=10, size=40)["steering"] == 70.0


def test_linear_consequent_refused_by_mamdani(tmp_path):
    with pytest.raises(RuleBaseError, match="Mamdani inference cannot use") as err:
        load_rulebase(write(tmp_path, "operators: inference = mamdani"))
    assert "weighted_average" in err.value.hint


def test_unknown_coefficient_name():
    bad = TERMS.replace("{road: 0.5, size: -1}", "{raod: 0.5}")
    with pytest.raises(TermSetError, match="`raod` is not an input variable") as err:
        parse_termset(bad, "s.terms.yaml")
    assert err.value.hint == "did you mean `road`?"
    assert err.value.span.line == 18


def test_linear_needs_a_constant():
    bad = TERMS.replace(", constant: 90}", "}")
    with pytest.raises(TermSetError, match="missing `constant`"):
        parse_termset(bad)


def test_linear_unknown_key():
    bad = TERMS.replace("constant: 90}", "constant: 90, slope: 2}")
    with pytest.raises(TermSetError, match="unknown key `slope`"):
        parse_termset(bad)


def test_linear_term_on_an_input_is_refused():
    bad = TERMS.replace("NARROW: {shape: left_shoulder, points: [40, 70]}",
                        "NARROW: {shape: linear, constant: 1}")
    with pytest.raises(TermSetError, match="belongs to an output variable"):
        parse_termset(bad)


GAPPED = """\
variables:
  x:
    role: input
    universe: [0, 10]
    terms:
      LO: {shape: triangle, points: [0, 0, 4]}
      HI: {shape: triangle, points: [6, 10, 10]}
  y:
    role: input
    universe: [0, 10]
    terms:
      LO: {shape: triangle, points: [0, 0, 4]}
      HI: {shape: triangle, points: [6, 10, 10]}
  w: {role: output, universe: [-100, 100], default: 42, terms: {A: -10, B: 50}}
  u: {role: output, universe: [-100, 100], terms: {A: -10, B: 50}}
  n: {role: output, universe: [-100, 100], default: .nan, terms: {A: -10, B: 50}}
"""


@pytest.mark.parametrize("hedge", ["", "very "])
def test_a_weighted_sum_where_no_rule_fires_takes_the_declared_default(tmp_path, hedge):
    """Where none of an output's rules fired, a weighted sum gave 0, the empty sum, even for
    an output that declares a default, while `mitos eval` printed it as "its default" (42);
    fuzzylite gives the default there, MATLAB a `.fis` output's middle, which the reader makes
    its default. The default applies now on every path (one sample, a grid batch, the
    detailed one); an output without a default keeps 0; `default: .nan` gives NaN."""
    path = write(tmp_path, terms=GAPPED, rules=(
        'terms "s.terms.yaml"\noperators: inference = weighted_sum\n'
        f"r1: if x is LO and y is LO then w is {hedge}A and u is A and n is A\n"
        "r2: if x is LO and y is HI then w is B and u is B and n is B\n"
        "r3: if x is HI and y is LO then w is B and u is A and n is B\n"
        "r4: if x is HI and y is HI then w is A and u is B and n is A\n"))
    rb = load_rulebase(path)
    assert rb.evaluate(x=5, y=5) == pytest.approx({"w": 42.0, "u": 0.0, "n": float("nan")},
                                                  nan_ok=True)
    X = np.array([[5.0, 5.0], [1.0, 1.0], [5.0, 1.0], [9.0, 9.0]] * 300)
    batch = rb.evaluate(x=X[:, 0], y=X[:, 1])
    detailed = evaluate(rb.compiled, X).outputs
    for got in (np.column_stack([batch["w"], batch["u"], batch["n"]]), detailed):
        np.testing.assert_array_equal(got[:4, 0], [42.0, -5.625 if hedge else -7.5, 42.0, -7.5])
        np.testing.assert_array_equal(got[:4, 1], [0.0, -7.5, 0.0, 37.5])
        assert np.isnan(got[[0, 2], 2]).all() and not np.isnan(got[[1, 3], 2]).any()
    assert "w = 42.0   (its default: no rule sets it here)" in rb.trace(x=5, y=5).render()
