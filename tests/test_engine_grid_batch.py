"""The batch path of a rule base that is one grid (``evaluate_columns`` through
``_grid_columns``, what ``load_rulebase().evaluate(**arrays)`` takes for the paper's 27 rules):
the bits of the general path's rows and of each sample alone, in any batch and block, for
random grids of piecewise-linear terms (shoulders, triangles, plateaus, vertical edges), rule
weights, outputs some rules leave unset, and both weighted inferences."""

from __future__ import annotations

import contextlib
import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli import load_rulebase
from mitos_cli.engine import evaluation
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate, evaluate_columns, evaluate_one
from mitos_cli.errors import InputError
from mitos_cli.lang.model import And, Behavior, Consequent, Prop, Rule, RuleBase, Setting
from mitos_cli.lang.terms import Term, TermSet, Variable

POINTS = {"triangle": 3, "trapezoid": 4, "left_shoulder": 2, "right_shoulder": 2}
UNIVERSES = {"a": (0.0, 10.0), "b": (-5.0, 5.0), "c": (-1.0, 3.0)}


def bits(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


@st.composite
def terms(draw, name: str) -> tuple[Term, ...]:
    lo, hi = UNIVERSES[name]
    out = []
    for i in range(draw(st.integers(1, 4))):
        shape = draw(st.sampled_from(sorted(POINTS)))
        # points on a coarse grid of the universe, so vertical edges (equal points) and
        # corners at 0 (x - b = -0.0 for an input of -0.0) are common
        xs = sorted(draw(st.lists(st.integers(-2, 22).map(lambda j: lo + (hi - lo) * j / 20),
                                  min_size=POINTS[shape], max_size=POINTS[shape])))
        out.append(Term(f"{name.upper()}{i}", shape, tuple(float(x) for x in xs)))
    return tuple(out)


@st.composite
def grids(draw):
    """A rule base whose rules are every combination of its inputs' terms, in mixed-radix
    order of some variable order and term orders, written in some order."""
    names = draw(st.permutations(list(UNIVERSES)).map(lambda p: p[:draw(st.integers(2, 3))]))
    inputs = {v: Variable(v, "input", UNIVERSES[v], draw(terms(v))) for v in names}
    y = Variable("y", "output", (-50.0, 50.0),
                 tuple(Term(f"Y{i}", "singleton", (v,)) for i, v in enumerate(
                     draw(st.lists(st.integers(-40, 40).map(float), min_size=1, max_size=3)))),
                 default=draw(st.sampled_from([None, 0.0])))
    z = Variable("z", "output", (-1.0, 1.0), (Term("ZN", "singleton", (-1.0,)),
                                               Term("ZP", "singleton", (1.0,))), default=0.5)
    written = draw(st.permutations(list(names)))
    orders = {v: draw(st.permutations(list(inputs[v].term_names))) for v in names}
    rules = []
    for i, combo in enumerate(itertools.product(*(orders[v] for v in names))):
        props = dict(zip(names, combo))
        cons = [Consequent("y", draw(st.sampled_from(y.term_names)))] \
            if draw(st.integers(0, 5)) else [Consequent("y", None, float(i % 7) - 3.0)]
        if draw(st.booleans()):                    # z: set by some rules only
            cons.append(Consequent("z", draw(st.sampled_from(z.term_names))))
        rules.append(Rule(f"r{i}", And(tuple(Prop(v, props[v]) for v in written)),
                          tuple(cons), draw(st.sampled_from([1.0, 1.0, 0.5, 0.3]))))
    ops = (Setting("inference", draw(st.sampled_from(["weighted_average", "weighted_sum"]))),)
    termset = TermSet((*inputs.values(), y, z))
    return RuleBase(None, (termset,), (Behavior("main", tuple(rules)),), ops)


@st.composite
def batches(draw, k: int):
    """Inputs around the universes: inside, outside (clamped), on the corners, -0.0."""
    special = st.sampled_from([-0.0, 0.0, -5.0, -1.0, 3.0, 5.0, 10.0, 2.5, -7.0, 14.0])
    value = st.one_of(st.floats(-8, 14, allow_nan=False), special)
    return np.array(draw(st.lists(st.lists(value, min_size=k, max_size=k),
                                  min_size=1, max_size=40)), dtype=float).reshape(-1, k)


@settings(max_examples=80, deadline=None)
@given(rb=grids(), data=st.data())
def test_the_grid_path_gives_the_bits_of_the_general_path(rb, data):
    c = compile_rulebase(rb, "main")
    assert c.grid_batch is not None, "one grid of linear terms takes the grid path"
    X = data.draw(batches(len(c.inputs)))
    rows = evaluate(c, X, strict=False).outputs              # the general path (with detail)
    inside = np.clip(X, c.universe[:, 0], c.universe[:, 1])
    for block in (16, 32, 8192):                                        # several blocks, one
        for Xin in (X, inside):                                         # clamped per block or not
            expected = rows if Xin is X else evaluate(c, Xin, strict=False).outputs
            with grid_block(block):
                got = evaluate_columns(c, list(Xin.T), strict=False)
            assert np.array_equal(bits(got), bits(expected.T))
    fast = evaluate(c, X, detail=False, strict=False)                   # rows, the grid path
    assert np.array_equal(bits(fast.outputs), bits(rows))
    general = evaluate(c, X, strict=False)
    assert np.array_equal(bits(fast.inputs), bits(general.inputs))
    assert fast.clamped.tolist() == general.clamped.tolist()
    if len(X) > 1:                                       # (one sample: the scalar form's)
        assert np.array_equal(fast.no_rule, general.no_rule)
    for i in range(len(X)):                                             # each sample alone
        alone = evaluate_columns(c, X[i:i + 1].T, strict=False)
        assert np.array_equal(bits(alone[:, 0]), bits(rows[i]))
        if c.scalar is not None and not np.isnan(rows[i]).any():
            assert np.array_equal(bits(evaluate_one(c, X[i].tolist())), bits(rows[i]))


@contextlib.contextmanager
def grid_block(block: int):
    saved = evaluation.GRID_BLOCK
    evaluation.GRID_BLOCK = block
    try:
        yield
    finally:
        evaluation.GRID_BLOCK = saved


def test_the_packaged_rule_base_takes_the_grid_path_in_any_batch():
    rb = load_rulebase()
    c = rb.compiled
    assert c.grid_batch is not None
    rng = np.random.default_rng(11)
    X = rng.uniform(c.universe[:, 0] - 5, c.universe[:, 1] + 5, size=(3 * 8192 + 5, 3))
    X[:4] = [[-0.0, 0.0, -0.0], [100.0, 100.0, 7.0], [0.0, 0.0, -7.0], [50.5, -0.0, 0.0]]
    rows = evaluate(c, X).outputs
    for n in (1, 2, 3, 8191, 8192, 8193, len(X)):
        out = rb.evaluate(**{name: X[:n, j] for j, name in enumerate(c.inputs)})
        for j, name in enumerate(c.outputs):
            assert np.array_equal(bits(out[name]), bits(rows[:n, j])), (n, name)
    inside = np.clip(X, c.universe[:, 0], c.universe[:, 1])   # not clamped block by block
    rows = evaluate(c, inside).outputs
    assert np.array_equal(bits(evaluate_columns(c, inside.T)), bits(rows.T))


def test_a_nan_is_refused_with_its_sample_and_numpys_buffer_is_restored():
    rb = load_rulebase()
    before = np.getbufsize()
    road = np.full(20000, 50.0)
    road[12345] = np.nan
    with pytest.raises(InputError, match="sample 12346"):
        rb.evaluate(road=road, size=10.0, position=0.0)
    assert np.getbufsize() == before
    rb.evaluate(road=road[:100], size=10.0, position=0.0)
    assert np.getbufsize() == before


def test_columns_of_another_shape_are_refused():
    c = load_rulebase().compiled
    with pytest.raises(InputError, match="expected 3 input columns"):
        evaluate_columns(c, np.zeros((2, 5)))
    with pytest.raises(InputError, match="of one length"):
        evaluate_columns(c, [np.zeros(5), np.zeros(4), np.zeros(5)])


@pytest.mark.parametrize("inference", ["weighted_average", "weighted_sum"])
def test_plateaus_vertical_edges_and_weights_on_a_lattice(inference):
    a = Variable("a", "input", (0.0, 10.0), (Term("P", "trapezoid", (1.0, 3.0, 6.0, 8.0)),
                                            Term("V", "trapezoid", (0.0, 0.0, 4.0, 4.0)),
                                            Term("L", "left_shoulder", (2.0, 5.0))))
    b = Variable("b", "input", (-5.0, 5.0), (Term("T", "triangle", (-5.0, 0.0, 0.0)),
                                             Term("Q", "trapezoid", (-4.0, -1.0, 2.0, 5.0))))
    y = Variable("y", "output", (-9.0, 9.0), (Term("N", "singleton", (-7.0,)),
                                              Term("P", "singleton", (3.0,))), default=0.0)
    rules = tuple(Rule(f"r{i}", And((Prop("a", ta), Prop("b", tb))),
                       (Consequent("y", "N" if i % 2 else "P"),), (1.0, 0.5, 0.3)[i % 3])
                  for i, (ta, tb) in enumerate(itertools.product(a.term_names, b.term_names)))
    rb = RuleBase(None, (TermSet((a, b, y)),), (Behavior("main", rules),),
                  (Setting("inference", inference),))
    c = compile_rulebase(rb, "main")
    assert c.grid_batch is not None and c.grid_batch.plateaus
    grid = np.array(np.meshgrid(np.arange(-1.0, 11.0, 0.125), np.arange(-6.0, 6.0, 0.125)))
    X = np.vstack([grid.reshape(2, -1).T, [[-0.0, -0.0], [4.0, -0.0], [0.0, 0.0]]])
    rows = evaluate(c, X).outputs
    with grid_block(64):
        assert np.array_equal(bits(evaluate_columns(c, X.T)), bits(rows.T))
