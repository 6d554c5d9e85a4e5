"""The upper envelope of piecewise-linear terms (``mitos_cli.lang.envelope``), swept rather
than every term measured at every point of its support: the same bits, on random term sets
of every kind of edge, and the same `mitos check` report on many overlapping terms."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.engine.check import check_rulebase
from mitos_cli.lang import envelope
from mitos_cli.lang import interpretability as meaning
from mitos_cli.lang.terms import Term, Variable

UNIVERSE = (0.0, 10.0)
#: corners drawn from a few values (ties, terms touching the universe's ends, edges that
#: meet at a corner) or from anywhere
SPOTS = st.one_of(st.sampled_from([-2.0, 0.0, 1.0, 2.5, 5.0, 7.5, 10.0, 12.0]),
                  st.floats(-3.0, 13.0, allow_nan=False, width=64))


@st.composite
def terms(draw) -> tuple[float, float, float, float]:
    """One term's corners: a triangle, trapezoid, either shoulder, a crisp step (an upright
    edge), a rectangle, a spike of one point or the whole line."""
    a, b, c, d = sorted(draw(st.lists(SPOTS, min_size=4, max_size=4)))
    kind = draw(st.sampled_from(["triangle", "trapezoid", "left", "right", "step up",
                                 "step down", "rectangle", "spike", "everywhere"]))
    return {"triangle": (a, b, b, d), "trapezoid": (a, b, c, d),
            "left": (-np.inf, -np.inf, c, d), "right": (a, b, np.inf, np.inf),
            "step up": (b, b, c, d), "step down": (a, b, c, c), "rectangle": (b, b, c, c),
            "spike": (b, b, b, b), "everywhere": (-np.inf, -np.inf, np.inf, np.inf)}[kind]


@st.composite
def term_sets(draw) -> np.ndarray:
    """Up to 12 terms, some repeated."""
    rows = draw(st.lists(terms(), min_size=1, max_size=12))
    rows += [rows[i] for i in draw(st.lists(st.integers(0, len(rows) - 1), max_size=3))]
    return np.array(rows, dtype=float)


def every_corner_and_crossing(corners: np.ndarray, extra: list[float]) -> np.ndarray:
    """The universe's ends, every corner and every crossing of two edges' lines (the lines
    whole, not only where both edges are), a third and two thirds of the way between
    neighbours, and ``extra`` points (-0.0 among them): unsorted."""
    lo, hi = UNIVERSE
    a, b, c, d = corners.T
    with np.errstate(all="ignore"):
        slope = np.concatenate([1 / (b - a), -1 / (d - c)])
        offset = np.concatenate([-a / (b - a), d / (d - c)])
        cross = ((offset[None, :] - offset[:, None]) / (slope[:, None] - slope[None, :]))
    x = np.concatenate([[lo, hi], corners.ravel(), cross.ravel()])
    x = np.unique(x[np.isfinite(x)])
    width = np.diff(x)
    return np.concatenate([x[::-1], x[:-1] + width / 3, x[:-1] + 2 * width / 3, extra])


def swept(corners: np.ndarray, x: np.ndarray, monkeypatch) -> np.ndarray:
    monkeypatch.setattr(meaning, "SWEEP_FROM", 0)
    return meaning.envelope(corners, x)


def over_supports(corners: np.ndarray, x: np.ndarray, monkeypatch) -> np.ndarray:
    """What :func:`meaning.envelope` computed before the sweep: every term at every point of
    its support."""
    monkeypatch.setattr(meaning, "SWEEP_FROM", 1 << 62)
    return meaning.envelope(corners, x)


@settings(max_examples=600, deadline=None)
@given(corners=term_sets(), extra=st.lists(st.one_of(SPOTS, st.just(-0.0)), max_size=6))
def test_the_swept_envelope_has_the_bits_of_every_term_at_every_point(corners, extra):
    """At every corner and crossing of the terms, and between them: the bits of each term
    measured over its support (the sign of a 0 too), and the values of every term measured at
    every point."""
    x = every_corner_and_crossing(corners, extra)
    with pytest.MonkeyPatch.context() as mp:
        got, old = swept(corners, x, mp), over_supports(corners, x, mp)
    assert got.tobytes() == old.tobytes()
    assert np.array_equal(got, meaning.memberships(corners, x).max(axis=0))


@settings(max_examples=200, deadline=None)
@given(corners=term_sets(), block=st.integers(1, 9))
def test_the_sweep_in_small_blocks_gives_the_same_bits(corners, block):
    """Pairs of (term, point) and of (edge, piece) taken a few at a time, a stretch of many
    points cut into parts: the same bits."""
    x = every_corner_and_crossing(corners, [])
    with pytest.MonkeyPatch.context() as mp:
        old = over_supports(corners, x, mp)
        mp.setattr(envelope, "BLOCK", block)
        assert swept(corners, x, mp).tobytes() == old.tobytes()


@pytest.mark.parametrize("seed", range(20))
def test_many_random_overlapping_triangles_have_the_same_envelope(seed):
    """Up to 300 triangles that all overlap (what `mitos check` took cubic time on), with
    shoulders, trapezoids and repeated terms among them, on their breakpoints and the thirds
    between: the same bits."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(20, 300))
    peak = rng.uniform(30, 70, n)
    corners = np.stack([rng.uniform(0, 20, n), peak, peak, rng.uniform(80, 100, n)], axis=1)
    if seed % 2:
        corners = np.round(corners)                         # ties
        corners[::7, 2] += 5                                # trapezoids
    corners[0, :2] = -np.inf
    corners[1, 2:] = np.inf
    corners[2] = corners[3]
    x = meaning.breakpoints(corners, (0.0, 100.0))
    x = np.concatenate([x, x[:-1] + np.diff(x) / 3, x[:-1] + 2 * np.diff(x) / 3])
    with pytest.MonkeyPatch.context() as mp:
        assert swept(corners, x, mp).tobytes() == over_supports(corners, x, mp).tobytes()


def test_terms_the_sweep_cannot_take_are_measured_over_their_support():
    """An upright edge, an edge too narrow for its slope, an infinite foot beside a finite
    peak: measured point by point, beside the swept ones; terms out of order: all point by
    point."""
    regular = np.array([[0.0, 2.0, 2.0, 4.0], [-np.inf, -np.inf, 1.0, 3.0],
                        [0.0, 0.0, 0.0, 0.0] + np.array([2, 3, 4, 5.0])])
    odd = np.array([[3.0, 3.0, 5.0, 6.0], [0.0, 1e-310, 2.0, 2.5],
                    [-np.inf, 1.0, 2.0, 3.0], [5.0, 4.0, 6.0, 7.0]])
    assert envelope.regular(np.vstack([regular, odd])).tolist() == [True] * 3 + [False] * 4
    x = np.linspace(-1, 8, 901)
    for corners in (np.vstack([regular, odd[:3]]), np.vstack([regular, odd])):
        with pytest.MonkeyPatch.context() as mp:
            assert swept(corners, x, mp).tobytes() == over_supports(corners, x, mp).tobytes()


def test_minus_zero_keeps_the_sign_the_last_term_measured_there_gives():
    """At the point -0.0, an edge rising from 0 and one falling to 0 both give a zero, whose
    signs the NumPy version decides (2.x: -0.0 and +0.0; 1.25 gives +0.0 where 2.x gives
    -0.0); the sweep keeps the sign the old order gives, either way round."""
    x = np.array([-0.0, 0.5, 1.0])
    for rows in ([[0.0, 1.0, 1.0, 2.0], [-1.0, -0.5, -0.5, 0.0]],
                 [[-1.0, -0.5, -0.5, 0.0], [0.0, 1.0, 1.0, 2.0]]):
        corners = np.array(rows)
        with pytest.MonkeyPatch.context() as mp:
            got = swept(corners, x, mp)
            assert got.tobytes() == over_supports(corners, x, mp).tobytes()   # signs too
        assert got[0] == 0.0


def test_many_overlapping_triangles_are_checked_with_the_same_report():
    """`mitos check`'s findings on 150 random triangles of one input that all overlap, and
    of an output: the same words swept as measured at every point of each support."""
    rng = np.random.default_rng(11)
    n = 150
    tri = np.round(np.stack([rng.uniform(0, 20, n), rng.uniform(30, 70, n),
                             rng.uniform(80, 100, n)], axis=1), 3)
    found = []
    for sweep_from in (0, 1 << 62):
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(meaning, "SWEEP_FROM", sweep_from)
            found.append([meaning.variable_issues(Variable("x", role, (0.0, 100.0), tuple(
                Term(f"T{k}", "triangle", tuple(row)) for k, row in enumerate(tri))))
                for role in ("input", "output")])
    assert found[0] == found[1]
    assert [i.code for i in found[0][0]] == ["term-order", "coverage", "indistinct"]
    assert "covered only to" in found[0][0][1].message


def test_the_envelope_of_2000_overlapping_triangles_is_not_cubic():
    """2,000 random triangles that all overlap have about 4.8 million breakpoints; every
    term measured at every point of its support is 2,000 times as many memberships (`mitos
    check` took 456 s). Swept, each point is measured for the few terms near the envelope
    there: counted, not timed."""
    rng = np.random.default_rng(11)
    n = 2000
    tri = np.stack([rng.uniform(0, 20, n), rng.uniform(30, 70, n), rng.uniform(30, 70, n),
                    rng.uniform(80, 100, n)], axis=1)
    tri[:, 1:3] = np.sort(tri[:, 1:3], axis=1)
    x = np.linspace(0.0, 100.0, 20_001)
    measured = []
    real = meaning.memberships_at

    def counting(corners, at):
        measured.append(len(at))
        return real(corners, at)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(meaning, "memberships_at", counting)
        top = swept(tri, x, mp)
        assert sum(measured) < 4 * len(x)
        assert top.tobytes() == over_supports(tri, x, mp).tobytes()


def test_check_rulebase_reads_the_sweep(tmp_path):
    """The check of a file (through `check_rulebase`) finds the same with the sweep on."""
    terms = "\n".join(f"      T{k}: {{shape: triangle, points: [{k}, {k + 20}, {k + 40}]}}"
                      for k in range(0, 60, 3))
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  x:\n    role: input\n    universe: [0, 100]\n    terms:\n" + terms
        + "\n  y:\n    role: output\n    universe: [0, 1]\n    terms: {LO: 0, HI: 1}\n")
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\n\nbehavior b:\n'
                                      "    r0: if x is T0 then y is LO\nend\n")
    from mitos_cli import api

    rb = api.read_rulebase(tmp_path / "t.rules")
    reports = []
    for sweep_from in (0, 1 << 62):
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(meaning, "SWEEP_FROM", sweep_from)
            reports.append([f.to_json() for f in check_rulebase(rb).findings])
    assert reports[0] == reports[1]
    assert "coverage" in [f["code"] for f in reports[0]]


# ---- the most similar pair when a term has an upright edge ------------------------------------

@st.composite
def stepped_sets(draw) -> np.ndarray:
    """Two to ten terms, at least one with an upright edge, some repeated."""
    rows = draw(st.lists(terms(), min_size=1, max_size=9))
    a, b, c, d = sorted(draw(st.lists(SPOTS, min_size=4, max_size=4)))
    rows.append(draw(st.sampled_from([(b, b, c, d), (a, b, c, c), (b, b, c, c)])))
    rows += [rows[i] for i in draw(st.lists(st.integers(0, len(rows) - 1), max_size=2))]
    return np.array(rows, dtype=float)


@settings(max_examples=400, deadline=None)
@given(corners=stepped_sets(), block=st.sampled_from([40, 300, 5000, meaning.PAIR_BLOCK]))
def test_the_most_similar_pair_beside_a_step_is_the_one_over_every_breakpoint(corners, block):
    """Terms with a crisp step were measured a pair at a time over every breakpoint (the
    trapezoid beside a step depends on the breakpoint before it): each pair is measured on
    its own points and the breakpoints beside the steps, and only those near the largest
    over every breakpoint, in the batch and block where they were: the same pair and the
    same bits, whatever the blocks."""
    x = meaning.breakpoints(corners, UNIVERSE)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(meaning, "PAIR_BLOCK", block)
        old = meaning._linear_most(corners, x)
        new = meaning.most_similar_beside_steps(corners, UNIVERSE, x, above=-1.0)
    if new is None:                                 # an edge too narrow for its slope
        a, b, c, d = corners.T
        with np.errstate(all="ignore"):
            assert not np.isfinite(np.concatenate([1 / (b - a), 1 / (d - c)])[
                np.isfinite(np.concatenate([a, c])) & (np.concatenate([b - a, d - c]) > 0)
            ]).all() or len(corners) < 2
        return
    assert (np.float64(new[0]).tobytes(), new[1:]) == (np.float64(old[0]).tobytes(), old[1:])


def test_below_the_threshold_only_the_value_is_given():
    """Terms no pair of which is near the threshold are not summed over every breakpoint:
    the largest similarity to rounding, the pair 0, 1."""
    corners = np.array([[0.0, 0.0, 1.0, 2.0], [4.0, 5.0, 5.0, 6.0], [5.0, 6.0, 7.0, 7.0]])
    x = meaning.breakpoints(corners, UNIVERSE)
    s, i, j = meaning.most_similar_beside_steps(corners, UNIVERSE, x, above=0.5)
    assert (i, j) == (0, 1)
    assert s == pytest.approx(meaning._linear_most(corners, x)[0], abs=1e-12)


def test_many_triangles_and_a_step_are_checked_in_quadratic_time_with_the_same_report():
    """300 random triangles that all overlap and one crisp step took 200 s in `mitos check`
    (every overlapping pair summed over every breakpoint): the same findings, every pair
    summed over every breakpoint counted, not timed."""
    rng = np.random.default_rng(11)
    n = 60
    tri = np.round(np.stack([rng.uniform(0, 20, n), rng.uniform(30, 70, n),
                             rng.uniform(80, 100, n)], axis=1), 3)
    var = Variable("x", "input", (0.0, 100.0), tuple(
        Term(f"T{k}", "triangle", tuple(row)) for k, row in enumerate(tri))
        + (Term("S", "trapezoid", (50.0, 50.0, 60.0, 70.0)),))
    summed = []
    real = meaning._pair_similarity

    def counting(rows, x, k, v, start, end, only=None):
        summed.append(len(k) if only is None else int(only.sum()))
        return real(rows, x, k, v, start, end, only)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(meaning, "_pair_similarity", counting)
        new = meaning.variable_issues(var)
        few = sum(summed)
        mp.setattr(meaning, "most_similar_beside_steps", lambda *args: None)
        old = meaning.variable_issues(var)
    assert new == old
    assert "indistinct" in [i.code for i in new]
    assert few < 10 < n * (n - 1) // 2 < sum(summed) - few


def test_no_point_of_a_pair_lies_between_a_step_and_the_breakpoint_before_it():
    """A rising edge left of the universe and a falling edge on the right cross, as lines,
    at 0.107: between the step at 1.358 and the breakpoint before it (0), where no edge is.
    That point cut the trapezoid beside the step: 0.6464 for 0.6523, and the pair was missed."""
    corners = np.array([[1.3579015095288418, 1.3579015095288418, 5.174128937276878,
                         7.975326627313585],
                        [-1.0367901235837957, -0.6293931233462313, 7.836767693809696,
                         10.268965523068811],
                        [-1.0994638153938379, 1.7066463907066298, 4.239508097461754,
                         5.345204029513129],
                        [5.938989282851545, 6.749862398604467, np.inf, np.inf]])
    x = meaning.breakpoints(corners, UNIVERSE)
    old = meaning._linear_most(corners, x)
    assert old[1:] == (0, 1)
    assert meaning.most_similar_beside_steps(corners, UNIVERSE, x, above=-1.0) == old


@pytest.mark.parametrize("seed", range(8))
def test_random_stepped_sets_give_the_pair_over_every_breakpoint(seed):
    """Random trapezoids, shoulders, repeated terms and steps on either side (25 sets a
    seed, up to 11 terms): the same triple to the bit as over every breakpoint."""
    rng = np.random.default_rng(seed)
    for _ in range(25):
        t = int(rng.integers(2, 12))
        corners = np.sort(rng.uniform(-2, 12, (t, 4)), axis=1)
        if rng.random() < 0.5:
            corners = np.round(corners) + 0.0
        corners[rng.integers(t), :2] = -np.inf
        corners[rng.integers(t), 2:] = np.inf
        k = rng.integers(t)
        corners[k, 1] = corners[k, 0]
        k = rng.integers(t)
        corners[k, 2] = corners[k, 3]
        corners[rng.integers(t)] = corners[rng.integers(t)]
        x = meaning.breakpoints(corners, UNIVERSE)
        old = meaning._linear_most(corners, x)
        new = meaning.most_similar_beside_steps(corners, UNIVERSE, x, above=-1.0)
        assert new is not None
        assert (np.float64(new[0]).tobytes(), new[1:]) == (np.float64(old[0]).tobytes(),
                                                            old[1:])
