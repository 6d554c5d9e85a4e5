"""T-norm and S-norm axioms (Sec. 3) and De Morgan duality (eq. 12), as property tests.

Laws that hold exactly in floating point are tested exactly: commutativity, the identity
(``T(a, 1) == a``, ``S(a, 0) == a``: the compiled network pads neurons with the identity
column), the boundary, the range [0, 1], and associativity of min, max, drastic and nilpotent
norms. The rational norms (Lukasiewicz, product, Einstein, Hamacher) are associative and
monotone only up to rounding: within 1e-12, and for the Hamacher sum's associativity near
``a = b = 1`` within what its division by ``1 - a b`` makes of an ulp.

De Morgan duality ``S(a, b) = 1 - T(1 - a, 1 - b)`` is tested on a dyadic grid, where
``1 - a`` is exact: with general floats ``1 - (1 - a) != a`` and the discontinuous norms
(drastic, nilpotent) would jump at a rounded threshold; the continuous pairs are also tested on
arbitrary floats within 1e-12.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from mitos_cli.fuzzy import norms

TOL = 1e-12
FAST = settings(max_examples=60, deadline=None)   # 14 norms x 9 laws: keep the suite quick
ALL = [*norms.TNORMS.values(), *norms.SNORMS.values()]
IDS = [n.name for n in ALL]
EXACTLY_ASSOCIATIVE = {"min", "max", "drastic", "drastic_sum", "nilpotent_minimum",
                       "nilpotent_maximum"}
DISCONTINUOUS = {"drastic", "drastic_sum", "nilpotent_minimum", "nilpotent_maximum"}
PAIRS = [(t, norms.lookup("snorm", t.dual)) for t in norms.TNORMS.values()]

unit = st.floats(0.0, 1.0)
dyadic = st.integers(0, 2 ** 20).map(lambda k: k / 2 ** 20)
special = st.sampled_from([0.0, 1.0, 0.5, 5e-324, 1e-300, 1e-17, 1 - 2 ** -53, 0.3, 0.7])
values = st.one_of(unit, dyadic, special)


def call(norm, *args):
    return float(norm(*args))


def test_seven_of_each_and_duals_pair_up():
    assert len(norms.TNORMS) == 7 and len(norms.SNORMS) == 7
    for t in norms.TNORMS.values():
        s = norms.lookup("snorm", t.dual)
        assert s.dual == t.name, f"{t.name} <-> {s.name} is not a pair both ways"


def test_lookup_by_alias_and_unknown():
    assert norms.lookup("tnorm", "algebraic_product").name == "product"
    assert norms.lookup("snorm", "probor").name == "probabilistic_sum"
    assert norms.lookup("tnorm", "bounded_difference").name == "lukasiewicz"
    with pytest.raises(KeyError):
        norms.lookup("tnorm", "maxx")
    assert "probor" in norms.names("snorm")


@pytest.mark.parametrize("norm", ALL, ids=IDS)
@FAST
@given(a=values, b=values)
def test_commutative_and_in_range(norm, a, b):
    ab, ba = call(norm, a, b), call(norm, b, a)
    assert ab == ba
    assert 0.0 <= ab <= 1.0


@pytest.mark.parametrize("norm", ALL, ids=IDS)
@FAST
@given(a=values)
def test_identity_and_boundary_exact(norm, a):
    one, zero = (1.0, 0.0) if norm.kind == "tnorm" else (0.0, 1.0)
    assert call(norm, a, one) == a          # identity: 1 for T-norms, 0 for S-norms
    assert call(norm, one, a) == a
    assert call(norm, a, zero) == zero      # boundary: T(a, 0) = 0, S(a, 1) = 1
    assert call(norm, zero, a) == zero


@pytest.mark.parametrize("norm", ALL, ids=IDS)
@FAST
@given(a=values, b=values, c=values)
@example(a=0.9453125, b=0.99999, c=0.99999)      # the Hamacher sum's ill-conditioned corner
def test_associative(norm, a, b, c):
    left = call(norm, call(norm, a, b), c)
    right = call(norm, a, call(norm, b, c))
    if norm.name in EXACTLY_ASSOCIATIVE:
        assert left == right
    else:
        assert left == pytest.approx(right, abs=TOL + _amplified(norm, a, b, c))


def _amplified(norm, a, b, c) -> float:
    """How far rounding alone may set the two sides apart beyond ``TOL``: the Hamacher sum
    divides by ``1 - x y``, whose rounding (an ulp of 1) is amplified by ``1 / (1 - x y)``
    near ``x = y = 1`` (``a = 0.9453125, b = c = 0.99999`` differ by 1.8e-12)."""
    if norm.name != "hamacher_sum":
        return 0.0
    pairs = [(a, b), (b, c), (call(norm, a, b), c), (a, call(norm, b, c))]
    dens = [1.0 - x * y for x, y in pairs if 1.0 - x * y > 0.0]
    return 8 * np.finfo(float).eps / min(dens, default=1.0)


@pytest.mark.parametrize("norm", ALL, ids=IDS)
@FAST
@given(a=values, a2=values, b=values)
def test_monotone(norm, a, a2, b):
    lo, hi = min(a, a2), max(a, a2)
    slack = 0.0 if norm.name in DISCONTINUOUS else TOL
    assert call(norm, lo, b) <= call(norm, hi, b) + slack


@pytest.mark.parametrize("tnorm,snorm", PAIRS, ids=[f"{t.name}-{s.name}" for t, s in PAIRS])
@FAST
@given(a=dyadic, b=dyadic)
def test_de_morgan_on_exact_grid(tnorm, snorm, a, b):
    # eq. 12 both ways: S(a, b) = 1 - T(1 - a, 1 - b) and T(a, b) = 1 - S(1 - a, 1 - b)
    assert call(snorm, a, b) == pytest.approx(1.0 - call(tnorm, 1.0 - a, 1.0 - b), abs=TOL)
    assert call(tnorm, a, b) == pytest.approx(1.0 - call(snorm, 1.0 - a, 1.0 - b), abs=TOL)


@pytest.mark.parametrize("tnorm,snorm", [p for p in PAIRS if p[0].name not in DISCONTINUOUS],
                         ids=[f"{t.name}-{s.name}" for t, s in PAIRS
                              if t.name not in DISCONTINUOUS])
@FAST
@given(a=unit, b=unit)
@example(a=0.9999920678048861, b=0.9999920678048861)    # 3.1e-12 apart: the division by 1 - ab
def test_de_morgan_on_floats(tnorm, snorm, a, b):
    slack = _amplified(snorm, a, b, 0.0)   # (c = 0: S(., 0) is exact, adds no pair of its own)
    assert call(snorm, a, b) == pytest.approx(1.0 - call(tnorm, 1.0 - a, 1.0 - b),
                                              abs=TOL + slack)


@pytest.mark.parametrize("norm", ALL, ids=IDS)
def test_textbook_values(norm):
    a, b = 0.3, 0.6
    expected = {
        "min": 0.3, "product": 0.18, "lukasiewicz": 0.0, "drastic": 0.0,
        "einstein": 0.18 / (2 - (0.9 - 0.18)), "hamacher": 0.18 / (0.9 - 0.18),
        "nilpotent_minimum": 0.0,
        "max": 0.6, "probabilistic_sum": 0.72, "bounded_sum": 0.9, "drastic_sum": 1.0,
        "einstein_sum": 0.9 / 1.18, "hamacher_sum": (0.9 - 0.36) / (1 - 0.18),
        "nilpotent_maximum": 0.6,
    }[norm.name]
    assert call(norm, a, b) == pytest.approx(expected, abs=1e-15)
    assert call(norm, 0.7, 0.8) == pytest.approx({
        "lukasiewicz": 0.5, "nilpotent_minimum": 0.7, "nilpotent_maximum": 1.0,
        "bounded_sum": 1.0}.get(norm.name, call(norm, 0.7, 0.8)), abs=1e-15)


def test_undefined_corners_take_their_limits():
    assert call(norms.TNORMS["hamacher"], 0.0, 0.0) == 0.0
    assert call(norms.SNORMS["hamacher_sum"], 1.0, 1.0) == 1.0


@pytest.mark.parametrize("norm", ALL, ids=IDS)
@FAST
@given(st.lists(values, min_size=0, max_size=40))
def test_tree_reduce_equals_left_fold(norm, items):
    x = np.array(items, dtype=float).reshape(len(items), 1)
    tree = norms.tree_reduce(norm, x, axis=0)
    fold = norms.reduce(norm, x, axis=0)
    assert tree.shape == (1,)
    if norm.name in EXACTLY_ASSOCIATIVE:
        assert tree[0] == fold[0]
    else:
        assert tree[0] == pytest.approx(fold[0], abs=1e-10)
    if not items:
        assert tree[0] == norm.identity


def test_tree_reduce_leaves_its_input_alone():
    x = np.array([[0.2, 0.9], [0.5, 0.4], [0.7, 0.1]])
    before = x.copy()
    norms.tree_reduce(norms.SNORMS["probabilistic_sum"], x, axis=0)
    assert (x == before).all()


@FAST
@given(st.lists(unit, min_size=1, max_size=12), st.integers(0, 11))
def test_tree_reduce_is_per_column(items, pad):
    # a column's result does not depend on the other columns (bit identity of batches)
    norm = norms.SNORMS["einstein_sum"]
    x = np.array(items)[:, None]
    wide = np.hstack([np.full((len(items), pad), 0.25), x])
    assert norms.tree_reduce(norm, wide, 0)[-1] == norms.tree_reduce(norm, x, 0)[0]
