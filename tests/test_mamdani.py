"""Mamdani inference: implication, S-norm aggregation, the five defuzzifiers, singletons,
hedged consequents, sub-blocking and bit identity of batches."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.api import load_rulebase, read_rulebase
from mitos_cli.engine import mamdani
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.errors import MitosError, NoRuleFiredError
from mitos_cli.fuzzy import norms
from mitos_cli.fuzzy.hedges import HEDGES
from mitos_cli.lang.model import Setting

TERMS = """\
variables:
  road:
    role: input
    universe: [0, 160]
    terms:
      NARROW: {shape: left_shoulder, points: [40, 70]}
      MEDIUM: {shape: triangle, peak: 70, width: 30}
      WIDE: {shape: right_shoulder, points: [70, 100]}
  size:
    role: input
    universe: [0, 100]
    terms:
      SMALL: {shape: left_shoulder, points: [10, 40]}
      LARGE: {shape: right_shoulder, points: [10, 70]}
  speed:
    role: output
    universe: [0, 60]
    terms:
      SLOW: {shape: triangle, points: [0, 10, 30]}
      MODERATE: {shape: trapezoid, points: [15, 25, 35, 45]}
      FAST: {shape: right_shoulder, points: [35, 55]}
      CRAWL: 5
"""

RULES = """\
terms "m.terms.yaml"
operators: inference = mamdani, {operators}
if road is NARROW then speed is SLOW
if road is MEDIUM and size is SMALL then speed is MODERATE
if road is MEDIUM and size is LARGE then speed is SLOW with 0.8
if road is WIDE and not size is LARGE then speed is FAST
if road is WIDE and size is very LARGE then speed is somewhat MODERATE
"""


def write(tmp_path, operators="defuzzify = centroid", rules=RULES):
    (tmp_path / "m.terms.yaml").write_text(TERMS)
    path = tmp_path / "m.rules"
    path.write_text(rules.format(operators=operators))
    return path


def reference(road, size, implication="min", aggregation="max", defuzzify="centroid",
              resolution=101):
    """Mamdani by the book, one sample, loops over rules: the test oracle."""
    narrow = np.clip((70 - road) / 30, 0, 1)
    medium = max(0.0, 1 - abs(road - 70) / 30)
    wide = np.clip((road - 70) / 30, 0, 1)
    small = np.clip((40 - size) / 30, 0, 1)
    large = np.clip((size - 10) / 60, 0, 1)
    x = 0 + (np.arange(resolution) + 0.5) * (60 / resolution)     # the documented grid
    slow = np.clip(np.minimum(x / 10, (30 - x) / 20), 0, 1)
    moderate = np.clip(np.minimum((x - 15) / 10, (45 - x) / 10), 0, 1)
    fast = np.clip((x - 35) / 20, 0, 1)
    rules = [(narrow, slow), (min(medium, small), moderate), (0.8 * min(medium, large), slow),
             (min(wide, 1 - large), fast), (min(wide, large ** 2), np.sqrt(moderate))]
    imp = np.minimum if implication == "min" else np.multiply
    S = norms.lookup("snorm", aggregation)
    y = np.zeros(resolution)
    for d, mu in rules:
        y = S(y, imp(d, mu))
    if y.sum() == 0:
        return np.nan
    if defuzzify == "centroid":
        return (x * y).sum() / y.sum()
    if defuzzify == "bisector":
        area = np.cumsum(y)
        gap = np.abs(area / area[-1] - 0.5)
        return x[gap == gap.min()].mean()
    peak = (y > 0) & (y == y.max())
    return {"mom": x[peak].mean(), "som": x[peak].min(), "lom": x[peak].max()}[defuzzify]


SAMPLES = [(50, 30), (78, 45), (100, 65), (65, 5), (85, 20), (120, 90), (72.5, 39.9)]


@pytest.mark.parametrize("defuzzify", ["centroid", "bisector", "mom", "som", "lom"])
@pytest.mark.parametrize("implication", ["min", "product"])
def test_matches_the_book_with_max(tmp_path, implication, defuzzify):
    ops = f"implication = {implication}, defuzzify = {defuzzify}"
    rb = load_rulebase(write(tmp_path, ops))
    X = np.array(SAMPLES, dtype=float)
    got = evaluate(rb.compiled, X).outputs[:, 0]
    want = [reference(r, s, implication, "max", defuzzify) for r, s in SAMPLES]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)


@pytest.mark.parametrize("alias, name", [("prod", "product"), ("algebraic_product", "product"),
                                         ("minimum", "min"), ("bounded_product", "lukasiewicz"),
                                         ("einstein_product", "einstein")])
def test_an_implication_takes_every_name_of_its_t_norm_as_and_does(tmp_path, alias, name):
    """language.md: `implication` is "any T-norm above", aliases included (`and = prod` was
    taken and `implication = prod` refused)."""
    rb = load_rulebase(write(tmp_path, f"implication = {alias}"))
    assert rb.compiled.operators.implication == name


def test_an_unknown_implication_is_refused_with_a_suggestion(tmp_path):
    with pytest.raises(MitosError) as info:
        load_rulebase(write(tmp_path, "implication = prodd"))
    assert "unknown implication `prodd`" in info.value.message
    assert "did you mean `prod`" in (info.value.hint or "")


@pytest.mark.parametrize("aggregation", sorted(norms.SNORMS))
def test_every_snorm_aggregates(tmp_path, aggregation):
    rb = load_rulebase(write(tmp_path, f"aggregation = {aggregation}, resolution = 201"))
    X = np.array(SAMPLES, dtype=float)
    got = evaluate(rb.compiled, X).outputs[:, 0]
    want = [reference(r, s, "min", aggregation, "centroid", 201) for r, s in SAMPLES]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)


def test_grouping_rules_by_set_is_exact_for_max():
    # max_r min(d_r, mu) == min(max_r d_r, mu): the shortcut the engine takes
    rng = np.random.default_rng(np.random.SeedSequence(7))
    d = rng.random((6, 50))
    mu = rng.random(40)
    full = mamdani.aggregate(d, np.repeat(mu[None], 6, axis=0), "min", norms.SNORMS["max"])
    short = mamdani.aggregate(d.max(axis=0, keepdims=True), mu[None], "min",
                              norms.SNORMS["max"])
    assert (full == short).all()


@pytest.mark.parametrize("aggregation", ["max", "einstein_sum"])
def test_batch_row_equals_single_evaluation_bit_for_bit(tmp_path, monkeypatch, aggregation):
    rb = load_rulebase(write(tmp_path, f"aggregation = {aggregation}, resolution = 301"))
    rng = np.random.default_rng(np.random.SeedSequence(11))
    X = np.column_stack([rng.uniform(0, 160, 700), rng.uniform(0, 100, 700)])
    monkeypatch.setattr(mamdani, "MAX_BYTES", 64 * 301 * 8)      # many small sub-blocks
    batch = evaluate(rb.compiled, X).outputs
    for i in range(0, 700, 41):
        assert (evaluate(rb.compiled, X[i:i + 1]).outputs == batch[i]).all()
    monkeypatch.setattr(mamdani, "MAX_BYTES", 2 ** 30)            # one block
    assert (evaluate(rb.compiled, X).outputs == batch).all()


def test_sub_blocks_stay_under_the_memory_ceiling(tmp_path, monkeypatch):
    rb = load_rulebase(write(tmp_path, "aggregation = probabilistic_sum, resolution = 1001"))
    seen = []
    real = mamdani.aggregate

    def spy(dof, sets, implication, aggregation):
        seen.append(dof.shape[0] * dof.shape[1] * sets.shape[1] * 8)
        return real(dof, sets, implication, aggregation)

    monkeypatch.setattr(mamdani, "aggregate", spy)
    evaluate(rb.compiled, np.tile([[80.0, 30.0]], (5000, 1)), detail=False)
    assert len(seen) > 1 and max(seen) <= mamdani.MAX_BYTES


def test_tables_are_built_once_per_compiled_rule_base(tmp_path):
    c = load_rulebase(write(tmp_path)).compiled
    assert c.mamdani is c.mamdani
    (table,) = c.mamdani
    assert table.labels == ("SLOW", "MODERATE", "FAST", "somewhat MODERATE")
    assert table.sets.shape == (4, 101)
    assert table.grid[0] == pytest.approx(60 / 202) and table.grid[-1] == pytest.approx(60 - 60 / 202)
    np.testing.assert_array_equal(table.sets[3], HEDGES["somewhat"].fn(table.sets[1]))


def test_singleton_consequent_is_a_one_cell_spike(tmp_path):
    rules = 'terms "m.terms.yaml"\noperators: inference = mamdani, {operators}\n' \
            'if road is NARROW then speed is CRAWL\nif road is WIDE then speed is 42\n'
    rb = load_rulebase(write(tmp_path, "resolution = 60", rules))
    # cells of width 1: 5 lies on a cell boundary -> cell [5, 6), midpoint 5.5
    assert rb.evaluate(road=10)["speed"] == 5.5
    assert rb.evaluate(road=150)["speed"] == 42.5
    # road 60: NARROW 1/3 -> CRAWL at 5.5; WIDE 0. Road 90: WIDE 2/3 only.
    assert rb.evaluate(road=60)["speed"] == 5.5
    # two spikes: the centroid is their DOF-weighted average
    Y = np.zeros((1, 60))
    Y[0, 5], Y[0, 42] = 0.25, 0.75
    assert mamdani.defuzzify(Y, mamdani.grid(0, 60, 60), "centroid")[0] == pytest.approx(
        0.25 * 5.5 + 0.75 * 42.5)


def test_paper_rule_base_runs_mamdani_within_half_a_cell_of_weighted_average():
    # singletons only and probabilistic-sum-free max aggregation with one rule per value:
    # at road 100 (only WIDE), size 10, position -60 exactly one rule fires (r0: RS = 110)
    rb = read_rulebase()
    c = compile_rulebase(rb, overrides=(Setting("inference", "mamdani"),
                                        Setting("resolution", "121")))
    out = evaluate(c, np.array([[100.0, 10.0, -60.0]])).outputs[0]
    assert abs(out[0] - 110) <= 0.5 * 120 / 121
    assert abs(out[1] - 40) <= 0.5 * 60 / 121


def test_nothing_fired_gives_default_or_error(tmp_path):
    rules = 'terms "m.terms.yaml"\noperators: inference = mamdani, {operators}\n' \
            'if road is NARROW and size is LARGE then speed is SLOW\n'
    rb = load_rulebase(write(tmp_path, "defuzzify = mom", rules))
    with pytest.raises(NoRuleFiredError, match="no rule sets `speed`"):
        rb.evaluate(road=150, size=0)
    out = evaluate(rb.compiled, np.array([[150.0, 0.0]]), strict=False).outputs
    assert np.isnan(out).all()


def test_empty_set_defuzzifies_to_nan():
    x = mamdani.grid(0, 1, 5)
    for method in ("centroid", "bisector", "mom", "som", "lom"):
        assert np.isnan(mamdani.defuzzify(np.zeros((1, 5)), x, method)).all()


def test_defuzzifiers_on_a_known_set():
    x = mamdani.grid(0, 10, 10)                      # 0.5, 1.5, ..., 9.5
    Y = np.array([[0, 0.2, 0.6, 0.6, 0.2, 0, 0, 0, 0, 0.0]])
    assert mamdani.defuzzify(Y, x, "centroid")[0] == pytest.approx(3.0)
    assert mamdani.defuzzify(Y, x, "mom")[0] == 3.0
    assert mamdani.defuzzify(Y, x, "som")[0] == 2.5
    assert mamdani.defuzzify(Y, x, "lom")[0] == 3.5
    assert mamdani.defuzzify(Y, x, "bisector")[0] == 2.5   # cumulative area 0.8 of 1.6
    with pytest.raises(ValueError):
        mamdani.defuzzify(Y, x, "median")


def test_huge_rule_stacks_are_built_in_chunks_of_rules(tmp_path, monkeypatch):
    # one sample's [rules, resolution] stack above the ceiling: chunks of rules, same result
    rb = load_rulebase(write(tmp_path, "aggregation = einstein_sum, resolution = 1001"))
    X = np.array(SAMPLES, dtype=float)
    whole = evaluate(rb.compiled, X).outputs
    monkeypatch.setattr(mamdani, "MAX_STACK_BYTES", 2 * 1001 * 8)      # 2 rules per chunk
    chunked = evaluate(rb.compiled, X).outputs
    np.testing.assert_allclose(chunked, whole, rtol=0, atol=1e-12)
    want = [reference(r, s, "min", "einstein_sum", "centroid", 1001) for r, s in SAMPLES]
    np.testing.assert_allclose(chunked[:, 0], want, rtol=0, atol=1e-9)


MISSED = """\
variables:
  x: {role: input, universe: [0, 10], terms: {LO: {shape: left_shoulder, points: [3, 7]},
      HI: {shape: right_shoulder, points: [3, 7]}}}
  w: {role: output, universe: [0, 100], terms: {A: {shape: triangle, points: [50, 50, 50]},
      B: {shape: triangle, points: [60, 80, 100]}}}
"""


def test_fired_rules_whose_sets_the_sampling_misses_are_told_as_such(tmp_path, capsys):
    """A rule firing fully on a set narrower than the output's sampling step (a triangle of
    width 0 between the 100 midpoints) left nothing to defuzzify, and `mitos eval` said "no
    rule fired: no rule sets `w` for x=1" while r1 fired at DOF 1; `mitos check` said OK
    (0 errors) for a rule base that `mitos eval` refused at every input."""
    from mitos_cli.api import read_rulebase
    from mitos_cli.cli.app import main
    from mitos_cli.engine.check import check_rulebase
    from mitos_cli.errors import EmptyOutputError

    (tmp_path / "m.terms.yaml").write_text(MISSED, encoding="utf-8")
    path = tmp_path / "m.rules"
    path.write_text('terms "m.terms.yaml"\noperators: inference = mamdani, resolution = 100\n'
                    "r1: if x is LO then w is A\nr2: if x is HI then w is B\n", encoding="utf-8")
    with pytest.raises(EmptyOutputError) as err:          # still a NoRuleFiredError
        load_rulebase(path).evaluate(x=1)
    assert isinstance(err.value, NoRuleFiredError)
    assert "the rules that set `w` fire (r1 at DOF 1) but give it no value for x=1" in str(
        err.value) and "no rule fired" not in str(err.value)
    assert load_rulebase(path).evaluate(x=9)["w"] == pytest.approx(80, abs=0.5)
    report = check_rulebase(read_rulebase(path))
    (gap,) = [f for f in report.findings if f.code == "no-rule-fires"]
    assert gap.severity == "error" and not report.ok and "undersampled-term" in gap.message
    assert gap.share == pytest.approx(0.3)                  # x <= 3, where r2 is 0
    with pytest.raises(SystemExit) as info:
        main(["eval", str(path), "x=1"])
    assert info.value.code == 1
    assert "no output value: the rules that set `w` fire" in capsys.readouterr().err


def _jfuzzylogic_coa(values: list[float], lo: float, hi: float) -> float:
    """jFuzzyLogic 3.3's ``DefuzzifierCenterOfArea.defuzzify``, transcribed loop for loop
    (``values`` its sampled set, ``min``/``max`` the universe, ``stepSize = (max - min) /
    values.length``)."""
    sum_low = sum_high = 0.0
    low, high = 0, len(values) - 1
    while low < high:
        if sum_low <= sum_high:
            low += 1
            sum_low += values[low]
        else:
            high -= 1
            sum_high += values[high]
    if sum_low <= 0:
        return float("nan")
    return lo + (hi - lo) / len(values) * low


_SAMPLE = st.one_of(st.just(0.0), st.just(0.25), st.just(1.0), st.floats(0, 1), st.floats(0, 3))


@given(st.integers(3, 40).flatmap(lambda n: st.lists(st.lists(_SAMPLE, min_size=n, max_size=n),
                                                      min_size=1, max_size=6)),
       st.floats(-100, 100), st.floats(0.001, 100))
@settings(max_examples=300, deadline=None)
def test_jfuzzylogic_bisector_is_its_walk_from_both_ends_bit_for_bit(rows, lo, width):
    """Without a loop over samples, the same bits as jFuzzyLogic's loop on every row: gaps of
    zeros, ties (0.25, 1.0), all zeros (NaN), sums above 1 (``aggregation = sum``)."""
    Y = np.array(rows)
    got = mamdani.defuzzify(Y, mamdani.grid(lo, lo + width, Y.shape[1], "left"),
                            "jfuzzylogic_bisector", (lo, lo + width))
    want = np.array([_jfuzzylogic_coa(r, lo, lo + width) for r in rows])
    assert np.array_equal(got, want, equal_nan=True)
    alone = mamdani.defuzzify(Y[-1:], mamdani.grid(lo, lo + width, Y.shape[1], "left"),
                              "jfuzzylogic_bisector", (lo, lo + width))
    assert np.array_equal(alone, got[-1:], equal_nan=True)


def test_jfuzzylogic_bisector_stops_at_a_gap_where_fuzzylites_takes_the_middle():
    """Two equal blocks with zeros between, by hand: low takes 1 (sums 1, 0), high takes 8
    (1, 1), low 2 (2, 1), high 7 (2, 2); the sums are equal, so low walks the gap, 3 to 6,
    adding zeros, and meets high at 7: jFuzzyLogic answers 0 + 1 * 7 = 7. fuzzylite's (and
    MITOS's) bisector takes the middle of the samples whose running area is closest to half
    (2 of 4: samples 2 to 6), 4."""
    x = mamdani.grid(0, 10, 10, "left")
    Y = np.array([[0, 1, 1, 0, 0, 0, 0, 1, 1, 0.0]])
    assert mamdani.defuzzify(Y, x, "jfuzzylogic_bisector", (0.0, 10.0))[0] == 7.0
    assert _jfuzzylogic_coa(list(Y[0]), 0.0, 10.0) == 7.0
    assert mamdani.defuzzify(Y, x, "bisector")[0] == 4.0
    # only the first sample set: jFuzzyLogic never counts it, so no area: NaN (its default)
    first = np.array([[1.0, 0, 0, 0, 0]])
    assert np.isnan(mamdani.defuzzify(first, x[:5], "jfuzzylogic_bisector", (0.0, 5.0))[0])
