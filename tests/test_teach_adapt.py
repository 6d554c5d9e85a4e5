"""Adaptation: exact gradients (vs finite differences), Q never increases, the term set keeps
its shape (order, ties, symmetry, universe), frozen things stay."""


import numpy as np
import pytest

from mitos_cli.api import load_rulebase
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.errors import LessonError
from mitos_cli.lang.parse import parse_rules
from mitos_cli.lang.resolve import build_rulebase
from mitos_cli.lang.termfile import parse_termset
from mitos_cli.teach.adapt import adapt, feasible, gradient, learned_rulebase, loss, parameterise, with_values

TERMS = """
variables:
  x: {role: input, universe: [0, 10], terms: {
      LO: {shape: left_shoulder, points: [2, 5]},
      MID: {shape: triangle, points: [2, 5, 8]},
      HI: {shape: right_shoulder, points: [5, 8]}}}
  z: {role: input, universe: [0, 10], terms: {
      A: {shape: trapezoid, points: [0, 1, 3, 6]},
      B: {shape: triangle, left_width: 2, peak: 6, right_width: 3},
      C: {shape: triangle, peak: 8, width: 1.5, frozen: true}}}
  y: {role: output, universe: [0, 100], default: 50, terms: {S: 10, M: 50, L: 90}}
"""
RULES = """
behavior b:
  r1: if x is LO and z is A then y is S
  r2: if x is MID or z is very B then y is M
  r3: if x is HI and not z is C then y is L
  r4: if x is somewhat MID and z is B then y is 70
  frozen r1
end
"""


def small(rules=RULES, terms=TERMS):
    rb = build_rulebase(parse_rules(rules), (parse_termset(terms),), ("t.yaml",))
    return compile_rulebase(rb, "b")


def points(n, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(0, 10, (n, 2))


def finite_differences(p, X, T, h=1e-6):
    num = np.zeros(len(p.values))
    for i in range(len(p.values)):
        up, down = p.values.copy(), p.values.copy()
        up[i] += h * p.scale[i]
        down[i] -= h * p.scale[i]
        num[i] = (loss(with_values(p, up), X, T) - loss(with_values(p, down), X, T)) / (
            2 * h * p.scale[i])
    return num


def away_from_ties(compiled, X):
    """Drop samples where a min/max or a membership is at a kink (within 1e-4)."""
    V = evaluate(compiled, X, keep_values=True, strict=False).values
    keep = np.ones(len(X), dtype=bool)
    T = compiled.n_terms
    mu = V[:, 2:2 + T]
    keep &= ~np.any((np.abs(mu - 0) < 1e-4) & (mu > 0) | (np.abs(mu - 1) < 1e-4) & (mu < 1),
                    axis=1)
    for level in compiled.levels:
        for g in level:
            if g.op in ("and", "or") and g.children.shape[1] > 1:
                vals = np.sort(V[:, g.children], axis=2)
                if g.op == "and":
                    tie = (vals[:, :, 1] - vals[:, :, 0] < 1e-4) & (vals[:, :, 0] > 1e-4)
                else:
                    tie = (vals[:, :, -1] - vals[:, :, -2] < 1e-4) & (vals[:, :, -1] > 1e-4)
                keep &= ~np.any(tie, axis=1)
    return X[keep]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_gradient_matches_finite_differences_on_the_paper_rule_base(seed):
    compiled = load_rulebase().compiled
    p = parameterise(compiled)
    rng = np.random.default_rng(seed)
    X = np.column_stack([rng.uniform(0, 160, 300), rng.uniform(0, 100, 300),
                         rng.uniform(-60, 60, 300)])
    X = away_from_ties(compiled, X)
    assert len(X) > 100
    T = np.column_stack([rng.uniform(30, 150, len(X)), rng.uniform(0, 60, len(X))])
    T[::3, 1] = np.nan                               # some examples correct steering only
    _, g = gradient(p, p.values, X, T)
    num = finite_differences(p, X, T)
    assert np.any(g != 0)
    np.testing.assert_allclose(g, num, rtol=1e-5, atol=1e-4 * np.abs(num).max())


@pytest.mark.parametrize("seed", [3, 4])
def test_gradient_through_hedges_not_or_crisp_and_products(seed):
    for ops in ("", "operators: and = product, or = probabilistic_sum\n",
                "operators: inference = weighted_sum\n"):
        compiled = small(ops + RULES)
        p = parameterise(compiled)
        X = away_from_ties(compiled, points(400, seed))
        assert len(X) > 100
        T = np.random.default_rng(seed).uniform(0, 100, (len(X), 1))
        Q, g = gradient(p, p.values, X, T)
        assert pytest.approx(loss(compiled, X, T)) == Q
        num = finite_differences(p, X, T)
        np.testing.assert_allclose(g, num, rtol=1e-5, atol=1e-5 * np.abs(num).max())


def test_ties_pass_the_gradient_to_the_lowest_index_deterministically():
    compiled = small()
    p = parameterise(compiled)
    X = np.array([[5.0, 6.0], [5.0, 6.0]])           # memberships at their peaks: ties
    T = np.array([[0.0], [0.0]])
    a = gradient(p, p.values, X, T)[1]
    b = gradient(p, p.values, X, T)[1]
    assert np.array_equal(a, b) and np.all(np.isfinite(a))


def test_q_decreases_on_a_synthetic_target_and_never_increases():
    compiled = load_rulebase().compiled
    p = parameterise(compiled, constrained=False)      # the target moves road.MEDIUM, held
    truth = p.values.copy()                            # at its point when constrained
    truth[1] += 4.0          # road: the shared NARROW.b = MEDIUM.peak = WIDE.a ...
    truth[0] += 2.0          # ... and NARROW.a; MEDIUM stays symmetric through right = 104
    truth[2] += 6.0
    truth[11] -= 6.0         # steering LS
    rng = np.random.default_rng(5)
    X = np.column_stack([rng.uniform(0, 160, 500), rng.uniform(0, 100, 500),
                         rng.uniform(-60, 60, 500)])
    T = evaluate(with_values(p, truth), X).outputs
    seen = []
    result = adapt(compiled, X, T, epochs=60, rate=0.5, on_epoch=lambda e, q: seen.append(q),
                   parameters=p)
    history = np.array(result.history)
    assert np.all(np.diff(history[:-1]) <= 0)          # no epoch raises Q (a compass epoch may keep it)
    assert result.q_after <= result.q_before * 0.05
    assert feasible(result.parameters, result.values)


def test_constraints_hold_order_ties_symmetry_universe():
    compiled = load_rulebase().compiled
    rng = np.random.default_rng(6)
    X = np.column_stack([rng.uniform(0, 160, 200), rng.uniform(0, 100, 200),
                         rng.uniform(-60, 60, 200)])
    T = np.column_stack([np.full(200, 35.0), np.full(200, 5.0)])   # an extreme target
    result = adapt(compiled, X, T, epochs=80, rate=0.9)
    rb = learned_rulebase(result.parameters, result.values)
    for name in ("road", "size", "position"):
        v = rb.variables[name]
        lo_, mid, hi_ = v.terms
        assert lo_.params[1] == mid.params[0]             # shared peak stays tied
        assert hi_.params[0] == mid.params[0]
        left = mid.params[0] - mid.params[1]
        right = mid.params[0] + mid.params[1]
        assert left == pytest.approx(lo_.params[0], abs=1e-9)    # symmetric triangle tied
        assert right == pytest.approx(hi_.params[1], abs=1e-9)
        assert mid.params[1] > 0
        u0, u1 = v.universe
        assert u0 <= left < mid.params[0] < right <= u1
    values = [t.params[0] for t in rb.variables["steering"].terms]
    assert values == sorted(values) and values[0] >= 30 and values[-1] <= 150


def test_frozen_terms_and_frozen_rules_keep_their_values():
    compiled = small()
    p = parameterise(compiled)
    X = points(300, 7)
    T = np.full((300, 1), 20.0)
    released = parameterise(compiled, released={("y", "M")})   # M: held at 50 by default
    result = adapt(compiled, X, T, epochs=40, parameters=released)
    rb = learned_rulebase(result.parameters, result.values)
    assert rb.variables["z"].term("C").params == (8.0, 1.5)       # frozen: true
    assert rb.variables["y"].term("S").params == (10.0,)         # only r1 (frozen) says S
    assert rb.variables["y"].term("M").params != (50.0,)
    assert result.q_after < result.q_before
    labels = [k.label for k in p.knots]
    assert any("B.peak" in x for x in labels)


def test_not_adapted_names_frozen_input_terms_frozen_rules_terms_and_frozen_outputs():
    """`not adapted:` named `steering.LB is frozen` but not the frozen `heading.LEFT`: the
    docs say frozen terms, output terms concluded by a frozen rule and shapes not learned
    keep their values, and the line now names all of them."""
    compiled = small()                          # z.C frozen: true; r1 (frozen) concludes S
    assert parameterise(compiled).frozen_reasons == ("z.C is frozen",
                                                     "y.S is concluded by a frozen rule")
    p = parameterise(compiled, frozen_terms={("x", "MID"), ("y", "L")})
    assert p.frozen_reasons == ("x.MID is frozen", "z.C is frozen", "y.L is frozen",
                                "y.S is concluded by a frozen rule")


def test_refusals_are_clear():
    # (Mamdani behaviors are adapted too: tests/test_teach_mamdani.py)
    with pytest.raises(LessonError, match="not `and = lukasiewicz`") as exc:
        parameterise(small("operators: and = lukasiewicz\n" + RULES))
    assert exc.value.message == ("adaptation has gradients for `and = min / product`, not "
                                 "`and = lukasiewicz`")
    assert exc.value.hint == "adapt with one of those (`and = min` is the paper's)"
    compiled = small()
    with pytest.raises(LessonError, match=r"\(0, 1\)"):
        adapt(compiled, points(5), np.zeros((5, 1)), rate=1.5)


def test_vectorized_one_epoch_is_fast_enough_to_not_loop(benchmark=None):
    compiled = load_rulebase().compiled
    rng = np.random.default_rng(8)
    X = np.column_stack([rng.uniform(0, 160, 1000), rng.uniform(0, 100, 1000),
                         rng.uniform(-60, 60, 1000)])
    T = np.column_stack([rng.uniform(30, 150, 1000), rng.uniform(0, 60, 1000)])
    result = adapt(compiled, X, T, epochs=2)
    assert len(result.history) >= 2
    again = adapt(compiled, X, T, epochs=2)              # deterministic, bit for bit
    assert np.array_equal(result.values, again.values)


def test_gradient_through_use_contexts_of_the_drive_behavior():
    compiled = load_rulebase(None, "drive").compiled
    assert compiled.context.shape[1] >= 1                # blended behaviors
    p = parameterise(compiled)
    rng = np.random.default_rng(9)
    X = np.column_stack([rng.uniform(*compiled.universe[k], 300)
                         for k in range(len(compiled.inputs))])
    X = away_from_ties(compiled, X)
    T = np.column_stack([rng.uniform(30, 150, len(X)), rng.uniform(0, 60, len(X))])
    _, g = gradient(p, p.values, X, T)
    num = finite_differences(p, X, T)
    np.testing.assert_allclose(g, num, rtol=1e-5, atol=1e-4 * np.abs(num).max())


def test_examples_on_a_corner_give_the_slope_of_the_side_where_q_falls():
    """`clutter` = 1 on SPARSE / DENSE's knot at 1: the membership has a kink there, and a
    slope of 0 (the two-sided derivative does not exist) hid from the descent that moving the
    knot down lowers Q. The one-sided slope of the falling side is what `gradient` gives, and
    finite differences on that side agree; `adapt` moves the knot."""
    terms = ("variables:\n  n: {role: input, universe: [0, 20], terms: {\n"
             "      FEW: {shape: left_shoulder, points: [1, 3]},\n"
             "      MANY: {shape: right_shoulder, points: [1, 3]}}}\n"
             "  y: {role: output, universe: [0, 100], terms: {S: 10, L: 90}}\n")
    rules = "behavior b:\n  r1: if n is FEW then y is S\n  r2: if n is MANY then y is L\nend\n"
    c = small(rules, terms)
    p = parameterise(c)
    X = np.array([[1.0], [1.0], [0.0]])                 # two on the knot at 1
    T = np.array([[30.0], [30.0], [10.0]])
    knot = next(i for i, k in enumerate(p.knots) if k.label == "n: FEW.a = MANY.a")
    q, g = gradient(p, p.values, X, T)
    h = 1e-6
    down = p.values.copy()
    down[knot] -= h
    up = p.values.copy()
    up[knot] += h
    assert loss(with_values(p, up), X, T) == q          # up: nothing changes
    slope = (q - loss(with_values(p, down), X, T)) / h  # down: Q falls
    assert slope > 0 and g[knot] == pytest.approx(slope, rel=1e-4)
    result = adapt(c, X, T, epochs=20)
    assert result.values[knot] < p.values[knot] and result.q_after < 0.5 * q


@pytest.mark.parametrize("seed", range(5))
def test_a_direction_with_each_knot_its_own_step_descends_and_keeps_the_constraints(seed):
    """The metric of the per-knot steps (``adapt``'s first trial direction): still a descent
    direction, ties, symmetric triangles and frozen knots kept, and knots at a bound or
    touching a neighbour not pushed through it."""
    from mitos_cli.teach.adapt import _knot_steps, descent_direction

    compiled = load_rulebase().compiled
    p = parameterise(compiled)
    rng = np.random.default_rng(seed)
    values = p.values.copy()
    values[:] = np.clip(values, p.lo, p.hi)
    g = rng.normal(size=len(values)) / p.scale
    factor, _ = _knot_steps(np.ones(len(values)), rng.normal(size=len(values)), g * p.scale)
    assert set(np.unique(factor)) <= {0.5, 1.0}
    d = descent_direction(p, values, g, metric=factor)
    assert (g * p.scale) @ d < 0
    assert np.allclose(p.constraints @ d, 0.0, atol=1e-9)
    step = d * (0.025 / np.abs(d).max())
    assert feasible(p, values + step * p.scale)


def test_the_compass_moves_along_free_directions_and_only_where_q_falls():
    """Where the step stalls, the compass (``adapt``'s poll) tries one knot's move through the
    linear constraints at a time: every direction keeps ties, symmetric triangles, frozen and
    held knots; a point it takes keeps every constraint and lowers Q; the same inputs give the
    same point; and with nothing left to gain it returns None (converged)."""
    from mitos_cli.teach.adapt import GAIN, _Compass

    compiled = load_rulebase().compiled
    p = parameterise(compiled)
    rng = np.random.default_rng(3)
    X = np.column_stack([rng.uniform(0, 160, 60), rng.uniform(0, 100, 60), rng.uniform(-60, 60, 60)])
    T = np.column_stack([np.full(60, 70.0), np.full(60, 30.0)])
    compass = _Compass.of(p, 0.5)
    assert len(compass.directions) == p.n_free
    assert np.allclose(p.constraints @ compass.directions.T, 0.0, atol=1e-9)
    q, g = gradient(p, p.values, X, T)
    found = compass.poll(p, p.values, q, g, X, T, GAIN * q)
    again = _Compass.of(p, 0.5).poll(p, p.values, q, g, X, T, GAIN * q)
    assert found is not None and again is not None and np.array_equal(found, again)
    assert feasible(p, found) and loss(with_values(p, found), X, T) < q
    assert _Compass.of(p, 0.5).poll(p, p.values, q, g, X, T, q) is None   # nothing gains Q


@pytest.mark.parametrize("width, value, decimals, shown", [
    (2e149, -6.2499999999999996e+147, -145, -6.25e147),   # was written with its float noise
    (2e5, 123456.789, -1, 123460.0),
    (100.0, 130.8712, 2, 130.87),
    (2e-30, 1.23456789e-31, 34, 1.235e-31)])
def test_learned_values_are_rounded_to_a_readable_grid_at_any_scale(width, value, decimals, shown):
    """The grid has about 10^4 steps over a universe: at 2e149 a learned knot was kept as
    `-6.2499999999999996e+147` (the grid stopped at whole numbers, and 10^-145 is no double);
    it is now the double nearest -6.25e147, written `-6.25e+147`."""
    from mitos_cli.teach.adapt import _decimals, _on_grid

    assert _decimals(width) == decimals
    got = float(_on_grid(np.array([value]), np.array([decimals]))[0])
    assert got == shown and repr(got) == repr(shown)
