"""Adaptation of Mamdani behaviors: central-difference gradients, Q falls on examples made by a
rule base whose output sets were moved, never rises per epoch, the term set keeps its shape,
frozen things stay, the same run gives the same bits; and a session adapts and saves one."""

import numpy as np
import pytest

from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.lang.parse import parse_rules
from mitos_cli.lang.resolve import build_rulebase
from mitos_cli.lang.termfile import parse_termset
from mitos_cli.teach.adapt import (
    adapt,
    descent_direction,
    difference_steps,
    feasible,
    gradient,
    learned_rulebase,
    loss,
    parameterise,
    with_values,
)
from mitos_cli.teach.session import Session

TERMS = """
variables:
  x: {role: input, universe: [0, 10], terms: {
      LO: {shape: left_shoulder, points: [2, 5]},
      MID: {shape: triangle, points: [2, 5, 8]},
      HI: {shape: right_shoulder, points: [5, 8]}}}
  z: {role: input, universe: [0, 10], terms: {
      A: {shape: left_shoulder, points: [3, 6]},
      B: {shape: right_shoulder, points: [3, 6]}}}
  y: {role: output, universe: [0, 100], terms: {
      S: {shape: triangle, points: [0, 20, 40]},
      M: {shape: triangle, peak: 50, width: 20},
      L: {shape: trapezoid, points: [60, 75, 85, 100]},
      TOP: 95}}
"""
RULES = """
operators: inference = mamdani, {ops}
behavior b:
  r1: if x is LO and z is A then y is S
  r2: if x is MID then y is M
  r3: if x is HI or z is B then y is L
  r4: if x is LO and z is B then y is somewhat M
  r5: if x is very HI and z is B then y is TOP
end
"""
#: The "true" rule base: the output sets' peaks moved (S 20 -> 30, M 50 -> 42, L's core
#: [75, 85] -> [68, 78]).
TRUE_TERMS = (TERMS.replace("[0, 20, 40]", "[0, 30, 40]").replace("peak: 50", "peak: 42")
              .replace("[60, 75, 85, 100]", "[60, 68, 78, 100]"))


def compiled(ops="defuzzify = centroid", terms=TERMS, rules=RULES):
    rb = build_rulebase(parse_rules(rules.format(ops=ops)), (parse_termset(terms),),
                        ("t.yaml",))
    return compile_rulebase(rb, "b")


def examples(ops, n=300, seed=0):
    X = np.random.default_rng(seed).uniform(0, 10, (n, 2))
    return X, evaluate(compiled(ops, TRUE_TERMS), X).outputs


def learned_epochs(result):
    """Q before, then after each epoch (without the final rounding)."""
    return np.array(result.history[:len(result.history) - result.rounded])


def test_output_sets_corners_are_knots_tied_ordered_and_in_the_universe():
    p = parameterise(compiled())
    labels = [k.label for k in p.knots]
    assert "y: S.b" in labels and "y: M.peak" in labels and "y: L.c" in labels
    assert "y: TOP" in labels                           # a singleton's value, as before
    assert "x: LO.b = MID.b = HI.a" in labels           # inputs: the same knots as before
    rng = np.random.default_rng(1)
    X = rng.uniform(0, 10, (200, 2))
    T = rng.uniform(0, 100, (200, 1))
    assert gradient(p, p.values, X, T)[0] == loss(compiled(), X, T)   # same table, same bits


@pytest.mark.parametrize("seed", [2, 3])
def test_difference_gradient_is_the_slope_of_q(seed):
    """Each component is the central difference of Q through the full network (the output-set
    knots take a shortcut through the output layer alone: same numbers); small steps along
    the projected gradient lower Q."""
    p = parameterise(compiled())
    X, T = examples("defuzzify = centroid", 200, seed)
    Q, g = gradient(p, p.values, X, T)
    h = difference_steps(p)
    free = np.flatnonzero(np.diag(p.projector) > 0)
    assert len(free) >= 10 and np.count_nonzero(g[free]) >= 8
    inside = (p.values - h > p.lo) & (p.values + h < p.hi)
    for i in free[inside[free]]:
        move = np.zeros_like(p.values)
        move[i] = h[i]
        q_up = loss(with_values(p, p.values + move), X, T)
        q_down = loss(with_values(p, p.values - move), X, T)
        assert g[i] == pytest.approx((q_up - q_down) / (2 * h[i]), rel=1e-9, abs=1e-9)
    d = descent_direction(p, p.values, g)               # what adapt steps along
    for size in (0.002, 0.01):                          # of the universe, for the most-moved
        step = p.values + size * d / np.abs(d).max() * p.scale
        assert feasible(p, step) and loss(with_values(p, step), X, T) < Q


# Q after / Q before measured for these examples (300, seed 0), 40 epochs, rate 0.5:
# centroid 0.009, product / probabilistic_sum 0.007, bisector 0.06, mom 0.10, lom 0.21
# (the last three pick grid samples: Q is a step function, the descent stops sooner).
@pytest.mark.parametrize("ops, factor, n", [
    ("defuzzify = centroid", 0.02, 300),
    ("implication = product, aggregation = probabilistic_sum, defuzzify = centroid", 0.05, 100),
    ("defuzzify = bisector", 0.1, 300),
    ("defuzzify = mom", 0.2, 300),
    ("implication = product, aggregation = sum, defuzzify = centroid", 0.05, 100),
])
def test_q_falls_substantially_and_never_rises(ops, factor, n):
    c = compiled(ops)
    X, T = examples(ops, n)
    seen = []
    result = adapt(c, X, T, epochs=40, rate=0.5, on_epoch=lambda e, q: seen.append(q))
    history = learned_epochs(result)
    assert np.all(np.diff(history) <= 0)                 # no epoch raises Q (a compass epoch may keep it)
    assert seen == list(history[1:len(seen) + 1])        # the progress bar saw each epoch
    assert result.q_after <= factor * result.q_before
    assert result.q_after == loss(with_values(result.parameters, result.values), X, T)
    assert feasible(result.parameters, result.values)
    y = learned_rulebase(result.parameters, result.values).variables["y"]
    S, M, L = (y.term(n).corners for n in "SML")
    for corners in (S, M, L):
        assert 0 <= corners[0] <= corners[1] <= corners[2] <= corners[3] <= 100
    assert M[1] - M[0] == pytest.approx(M[3] - M[1])    # a peak / width triangle stays one


def test_centroid_finds_the_moved_peaks():
    ops = "defuzzify = centroid"
    X, T = examples(ops)
    result = adapt(compiled(ops), X, T, epochs=40)
    y = learned_rulebase(result.parameters, result.values).variables["y"]
    assert y.term("S").corners[1] == pytest.approx(30, abs=8)     # from 20
    assert y.term("M").corners[1] == pytest.approx(42, abs=4)     # from 50
    assert y.term("L").corners[1] == pytest.approx(68, abs=8)     # from 75


def test_frozen_terms_and_rules_stay_and_determinism():
    ops = "defuzzify = centroid"
    terms = TERMS.replace("[60, 75, 85, 100]}", "[60, 75, 85, 100], frozen: true}")
    rules = RULES.replace("end", "  frozen r1\nend")
    c = compiled(ops, terms, rules)
    X, T = examples(ops, 200)
    first = adapt(c, X, T, epochs=15)
    again = adapt(compiled(ops, terms, rules), X, T, epochs=15)
    assert np.array_equal(first.values, again.values)            # bit for bit
    assert first.history == again.history
    rb = learned_rulebase(first.parameters, first.values)
    assert rb.variables["y"].term("L").params == (60.0, 75.0, 85.0, 100.0)   # frozen: true
    assert rb.variables["y"].term("S").params == (0.0, 20.0, 40.0)   # only r1 (frozen) says S
    assert rb.variables["y"].term("M").params != (50.0, 20.0)
    assert first.q_after < 0.5 * first.q_before


def test_a_session_adapts_a_mamdani_behavior_and_saves_it(tmp_path):
    (tmp_path / "m.terms.yaml").write_text(TERMS)
    (tmp_path / "m.rules").write_text('terms "m.terms.yaml"\n'
                                      + RULES.format(ops="defuzzify = centroid"))
    lines = []
    s = Session(tmp_path / "m.rules", out=lines.append)
    truth = compiled("defuzzify = centroid", TRUE_TERMS)
    for x, z in [(1, 1), (3, 2), (5, 5), (6, 2), (8, 8), (9, 3), (4, 7), (2, 9)]:
        (y,) = evaluate(truth, np.array([[x, z]], dtype=float)).outputs[0]
        s.run(f"correct x={x} z={z} -> y={y:.3f}")
    s.run("adapt epochs 20")
    text = "\n".join(map(str, lines))
    assert "Q" in text and "->" in text
    s.run(f"save {tmp_path / 'out.rules'}")
    saved = (tmp_path / "out.terms.yaml").read_text()
    assert saved != TERMS and "peak: 50," not in saved          # M's peak moved
