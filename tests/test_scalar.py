"""The scalar form of the network (mitos_cli.engine.scalar): one sample gives the same bits as its row
in a NumPy batch, for random rule bases over every norm, hedge and consequent kind it covers;
what it does not cover falls back to the NumPy path, which explains bad input as before."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from strategies import expressions

from mitos_cli import load_rulebase
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate, evaluate_one
from mitos_cli.engine.scalar import HEDGES, NORMS
from mitos_cli.errors import InputError, NoRuleFiredError
from mitos_cli.fuzzy.norms import SNORMS, TNORMS
from mitos_cli.lang.model import Behavior, Consequent, Prop, Rule, RuleBase, Setting, Use
from mitos_cli.lang.terms import Term, TermSet, Variable

HEDGE_NAMES = tuple(sorted(HEDGES))
LINEAR_SHAPES = {"triangle": 3, "trapezoid": 4, "left_shoulder": 2, "right_shoulder": 2,
                 "triangle_pw": 2, "triangle_plr": 3}


def bits(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


@st.composite
def terms(draw, prefix: str) -> tuple[Term, ...]:
    out = []
    for i in range(draw(st.integers(1, 4))):
        shape = draw(st.sampled_from(sorted(LINEAR_SHAPES)))
        xs = sorted(draw(st.lists(st.floats(0.0, 10.0).map(lambda v: round(v, 2)),
                                  min_size=4, max_size=4)))
        params = {"triangle_pw": (xs[1], xs[2] - xs[0] + 0.5),
                  "triangle_plr": (xs[1], xs[1] - xs[0] + 0.1, xs[3] - xs[1] + 0.1),
                  }.get(shape, tuple(xs[:LINEAR_SHAPES[shape]]))
        out.append(Term(f"{prefix}{i}", shape, tuple(float(p) for p in params)))
    return tuple(out)


@st.composite
def rulebases(draw) -> RuleBase:
    a = Variable("a", "input", (0.0, 10.0), draw(terms("A")))
    b = Variable("b", "input", (-5.0, 5.0), draw(terms("B")))
    linear = draw(st.booleans())
    outs = []
    for name in ("y", "z"):
        if linear and name == "y":
            coefficients = draw(st.lists(st.floats(-3, 3).map(lambda v: round(v, 2)),
                                         min_size=3, max_size=3))
            ts = (Term("L0", "linear", tuple(coefficients)), Term("C0", "singleton", (4.0,)))
        else:
            values = draw(st.lists(st.floats(-10, 10).map(lambda v: round(v, 2)),
                                   min_size=1, max_size=3))
            ts = tuple(Term(f"{name.upper()}{i}", "singleton", (v,))
                       for i, v in enumerate(values))
        outs.append(Variable(name, "output", (-50.0, 50.0), ts))
    y, z = outs

    def rule_list(prefix: str) -> tuple[Rule, ...]:
        rules = []
        for i in range(draw(st.integers(1, 5))):
            cons = [Consequent("y", draw(st.sampled_from(y.term_names)))]
            if draw(st.booleans()):
                cons.append(Consequent("z", draw(st.sampled_from(z.term_names))))
            antecedent = draw(expressions((a, b), HEDGE_NAMES, 2))
            rules.append(Rule(f"{prefix}{i}", antecedent, tuple(cons),
                              draw(st.sampled_from([1.0, 0.5, 0.3]))))
        return tuple(rules)

    inner = Behavior("inner", rule_list("i"))
    uses = ()
    if draw(st.booleans()):                     # a `use ... when ... with ...` context
        condition = draw(expressions((a, b), HEDGE_NAMES, 2, 1))
        uses = (Use("inner", condition, draw(st.sampled_from([1.0, 0.7]))),)
    main = Behavior("main", rule_list("r"), uses=uses)
    ops = (Setting("and", draw(st.sampled_from(sorted(TNORMS)))),
           Setting("or", draw(st.sampled_from(sorted(SNORMS)))),
           Setting("inference", draw(st.sampled_from(["weighted_average", "weighted_sum"]))))
    return RuleBase(None, (TermSet((a, b, y, z)),), (main, inner), ops)


@settings(max_examples=60, deadline=None)
@given(rb=rulebases(), X=st.lists(st.tuples(st.floats(-2, 12), st.floats(-7, 7)),
                                   min_size=1, max_size=8))
def test_scalar_form_gives_the_bits_of_the_batch_row(rb: RuleBase, X) -> None:
    compiled = compile_rulebase(rb, "main")
    assert compiled.scalar is not None, "every operation here has a scalar form"
    X = np.array(X, dtype=float)[:, [("a", "b").index(name) for name in compiled.inputs]]
    batch = evaluate(compiled, X, detail=False, strict=False)
    for i, row in enumerate(X.tolist()):
        expected = batch.outputs[i]
        got = compiled.scalar(*row)
        assert np.array_equal(bits(got), bits(expected)), (row, got, expected)
        if not np.isnan(expected).any():
            assert np.array_equal(bits(evaluate_one(compiled, row)), bits(expected))
            single = evaluate(compiled, X[i:i + 1], detail=False)
            assert np.array_equal(bits(single.outputs[0]), bits(expected))
            assert np.array_equal(bits(single.inputs[0]), bits(batch.inputs[i]))
            assert np.array_equal(single.clamped, batch.clamped if len(X) == 1 else
                                  (X[i] != batch.inputs[i]).astype(int))


def test_every_norm_has_a_scalar_form() -> None:
    assert set(NORMS) == set(TNORMS) | set(SNORMS)


def test_packaged_rule_base_single_evaluation_matches_the_paper() -> None:
    rb = load_rulebase()
    assert rb.compiled.scalar is not None
    out = rb.evaluate(road=78, size=45, position=4)
    assert out == {"steering": 15110 / 231, "speed": 32.42424242424243}
    batch = rb.run(np.array([[78.0, 45.0, 4.0]]), detail=False).outputs[0]
    assert np.array_equal(bits([out["steering"], out["speed"]]), bits(batch))


def _gaussian_rulebase(default: float | None) -> RuleBase:
    a = Variable("a", "input", (0.0, 10.0), (Term("G", "gaussian", (5.0, 1.0)),
                                               Term("T", "triangle", (0.0, 2.0, 4.0))))
    y = Variable("y", "output", (0.0, 10.0), (Term("Y", "singleton", (7.0,)),), default=default)
    rules = (Rule("r1", Prop("a", "G"), (Consequent("y", "Y"),)),)
    return RuleBase(None, (TermSet((a, y)),), (Behavior("main", rules),), ())


def test_shapes_without_exact_scalar_form_use_numpy() -> None:
    """exp() may differ in the last bit between NumPy and the C library: no scalar form."""
    c = compile_rulebase(_gaussian_rulebase(None))
    assert c.scalar is None
    assert evaluate_one(c, [5.0]) == (7.0,)
    mamdani = RuleBase(None, c.rulebase.termsets, c.rulebase.behaviors,
                       (Setting("inference", "mamdani"),))
    assert compile_rulebase(mamdani).scalar is None


def test_one_sample_errors_are_the_batch_errors() -> None:
    rb = load_rulebase()
    with pytest.raises(InputError, match="not a number"):
        rb.evaluate(road=float("nan"), size=45.0, position=4.0)
    with pytest.raises(InputError, match="did you mean"):
        rb.evaluate(road=78.0, sise=45.0, position=4.0)
    a = Variable("a", "input", (0.0, 10.0), (Term("T", "triangle", (0.0, 2.0, 4.0)),))
    y = Variable("y", "output", (0.0, 10.0), (Term("Y", "singleton", (7.0,)),))
    rule = Rule("r1", Prop("a", "T"), (Consequent("y", "Y"),))
    c = compile_rulebase(RuleBase(None, (TermSet((a, y)),), (Behavior("main", (rule,)),), ()))
    assert c.scalar is not None
    assert evaluate_one(c, [1.0]) == (7.0,)
    for outside in (9.0, -3.0):                 # -3 is clamped to 0, where T is 0 too
        with pytest.raises(NoRuleFiredError, match="no rule sets `y`"):
            evaluate_one(c, [outside])
        assert np.isnan(evaluate_one(c, [outside], strict=False)[0])


def test_a_compiled_rule_base_with_its_scalar_form_pickles() -> None:
    """Worker processes receive compiled rule bases: the generated function is left out and
    written again where it is used."""
    import pickle

    c = load_rulebase().compiled
    assert c.scalar is not None
    copy = pickle.loads(pickle.dumps(c))
    assert evaluate_one(copy, [78.0, 45.0, 4.0]) == evaluate_one(c, [78.0, 45.0, 4.0])
