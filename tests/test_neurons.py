"""The fuzzy neuron of Sec. 3, Fig. 3(b), and the compiled rule base as that network."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.api import load_rulebase, read_rulebase
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import network_values
from mitos_cli.fuzzy import neurons, norms
from mitos_cli.lang.model import Setting

FAST = settings(max_examples=60, deadline=None)
dyadic = st.integers(0, 2 ** 20).map(lambda k: k / 2 ** 20)
PAIRS = [(t, norms.lookup("snorm", t.dual)) for t in norms.TNORMS.values()]


def test_synapses_eqs_4_to_6():
    x = np.array([0.2, 0.5, 0.9])
    w = np.array([0.5, 1.0, 0.3])
    assert neurons.synapse(x, w, "product").tolist() == [0.1, 0.5, 0.27]
    assert neurons.synapse(x, w, "max").tolist() == [0.5, 1.0, 0.9]


def test_and_and_or_neurons_with_weights():
    x = np.array([[0.2, 0.5, 0.9], [1.0, 0.7, 0.6]])
    w = np.array([1.0, 0.5, 1.0])
    and_prod = neurons.neuron(x, norm="min", weights=w)          # min(x1, 0.5 x2, x3)
    assert and_prod.tolist() == [0.2, 0.35]
    or_max = neurons.neuron(x, norm="max", weights=[0.0, 0.6, 0.0], synapse_kind="max")
    assert or_max.tolist() == [0.9, 1.0]
    assert neurons.neuron(x, norm="product").tolist() == pytest.approx([0.09, 0.42])


def test_identity_weights_change_nothing():
    x = np.random.default_rng(np.random.SeedSequence(1)).random((20, 4))
    for kind, (_, identity, _) in neurons.SYNAPSES.items():
        assert (neurons.neuron(x, norm="einstein", weights=np.full(4, identity),
                               synapse_kind=kind) == neurons.neuron(x, norm="einstein")).all()


def test_inhibitory_inputs_eqs_8_9():
    x = np.array([0.2, 0.7])
    assert neurons.neuron(x, norm="min", inhibitory=[False, True]) == pytest.approx(0.2)
    assert neurons.neuron(x, norm="min", inhibitory=[True, True]) == pytest.approx(0.3)
    # weighting happens in the synapse, inhibition after it: 1 - (0.7 * 0.5)
    assert neurons.neuron(x, norm="max", weights=[1, 0.5], inhibitory=[False, True]) == 0.65


def test_activations_eqs_10_11():
    x = np.array([0.25, 0.81])
    assert neurons.neuron(x, norm="max", activation="identity") == 0.81
    assert neurons.neuron(x, norm="max", activation="very") == pytest.approx(0.81 ** 2)
    assert neurons.neuron(x, norm="max", activation="more_or_less") == pytest.approx(0.9)
    assert neurons.neuron(x, norm="max", activation=("very", "somewhat")) == pytest.approx(0.81)


def test_a_layer_by_broadcasting():
    X = np.random.default_rng(np.random.SeedSequence(2)).random((50, 3))
    W = np.array([[1.0, 0.5, 0.2], [0.3, 1.0, 1.0]])
    layer = neurons.neuron(X[:, None, :], norm="product", weights=W)
    assert layer.shape == (50, 2)
    for u in range(2):
        assert (layer[:, u] == neurons.neuron(X, norm="product", weights=W[u])).all()


def test_unknown_names():
    with pytest.raises(KeyError):
        neurons.neuron([0.5], norm="average")
    with pytest.raises(KeyError):
        neurons.neuron([0.5], activation="slightly")
    with pytest.raises(KeyError):
        neurons.neuron([0.5], synapse_kind="sum")


@pytest.mark.parametrize("tnorm,snorm", PAIRS, ids=[f"{t.name}-{s.name}" for t, s in PAIRS])
@FAST
@given(st.lists(dyadic, min_size=1, max_size=6))
def test_figure_3b_snorm_from_tnorm_neurons(tnorm, snorm, items):
    # an OR neuron = a T-norm neuron with negated inputs followed by a negating neuron (eq. 12)
    x = np.array(items)
    built = neurons.snorm_from_tnorm(x, tnorm.name)
    direct = neurons.neuron(x, norm=snorm.name)
    # 1e-9: Hamacher's sum divides by 1 - ab, which cancels near a = b = 1 (found at
    # a ~ 0.49999, b = c ~ 0.99998: the two routes differ by 1.0e-12 there)
    assert built == pytest.approx(direct, abs=1e-9)


def test_figure_3b_batched():
    x = np.random.default_rng(np.random.SeedSequence(4)).random((1000, 3))
    for tnorm, snorm in PAIRS:
        if tnorm.name in ("drastic", "nilpotent_minimum"):
            continue             # discontinuous: exact only where 1 - x is exact (see above)
        np.testing.assert_allclose(neurons.snorm_from_tnorm(x, tnorm),
                                   neurons.neuron(x, norm=snorm), rtol=0, atol=1e-12)


@pytest.mark.parametrize("tnorm", sorted(norms.TNORMS))
def test_compiled_and_layer_is_a_layer_of_and_neurons(tnorm):
    # the paper's 27 rules: each rule's DOF is an AND neuron over its three memberships
    c = compile_rulebase(read_rulebase(), overrides=(Setting("and", tnorm),))
    rng = np.random.default_rng(np.random.SeedSequence(5))
    X = np.column_stack([rng.uniform(*u, 400) for u in c.universe])
    V = network_values(c, np.ascontiguousarray(X.T))      # inputs inside their universes
    mu = V[2:2 + c.n_terms].T                                    # [b, T] membership layer
    index = {key: i for i, key in enumerate(c.term_names)}
    cols = np.array([[index[(p.var, p.term)] for p in rule.antecedent.items]
                     for rule in c.rules])                        # [R, 3]
    layer = neurons.neuron(mu[:, cols], norm=tnorm)              # [b, R]
    assert (layer == V[c.rule_col].T).all()


def test_not_and_hedges_are_inhibitory_inputs_and_activations(tmp_path):
    paper_terms = Path(read_rulebase().termsets[0].path).read_text()
    (tmp_path / "t.terms.yaml").write_text(paper_terms)
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\noperators: and = hamacher, or = einstein_sum\n'
        "if road is very WIDE and not size is LARGE_SZ then speed is FAST\n"
        "if road is somewhat NARROW or position is not LEFT then speed is SLOW\n")
    c = load_rulebase(tmp_path / "t.rules").compiled
    rng = np.random.default_rng(np.random.SeedSequence(6))
    X = np.column_stack([rng.uniform(*u, 300) for u in c.universe])
    V = network_values(c, np.ascontiguousarray(X.T))
    mu = dict(zip(c.term_names, V[2:2 + c.n_terms]))
    very_wide = neurons.neuron(mu["road", "WIDE"][:, None], norm="hamacher", activation="very")
    r1 = neurons.neuron(np.stack([very_wide, mu["size", "LARGE_SZ"]], axis=-1),
                        norm="hamacher", inhibitory=[False, True])
    sw_narrow = neurons.neuron(mu["road", "NARROW"][:, None], norm="hamacher",
                               activation="somewhat")
    r2 = neurons.neuron(np.stack([sw_narrow, mu["position", "LEFT"]], axis=-1),
                        norm="einstein_sum", inhibitory=[False, True])
    assert (r1 == V[c.rule_col[0]]).all()
    assert (r2 == V[c.rule_col[1]]).all()
