"""The exported NumPy module's ``evaluate_one`` on plain floats gives ``evaluate``'s row.

``evaluate_one`` calls ``_evaluate_row``, the module's network written on Python floats (one
NumPy call costs about a microsecond, and one sample took some forty of them). Its claim is
exactness: the same bits as the sample's row of ``evaluate``, for every norm, hedge, context,
weight, linear or hedged consequent, both weighted inferences, clamped or not, and inputs
outside the universe, infinite, NaN or a signed zero.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_export_c import DATA, ROOT, exported_module

from mitos_cli.api import load_rulebase
from mitos_cli.fuzzy.norms import SNORMS, TNORMS

TERMS = """\
variables:
  a: {role: input, universe: [0, 10], terms: {low: {shape: left_shoulder, points: [2, 6]},
      mid: {shape: triangle, points: [2, 5, 8]}, high: {shape: right_shoulder, points: [4, 9]}}}
  b: {role: input, universe: [-1, 1], terms: {neg: {shape: trapezoid, points: [-1, -1, -0.5, 0]},
      zero: {shape: triangle, points: [-0.5, 0, 0.5]}, pos: {shape: ramp, points: [0, 1]}}}
  y: {role: output, universe: [0, 100], default: 50, terms: {lo: 10, hi: 90,
      lin: {shape: linear, coefficients: {a: 3, b: -20}, constant: 40}}}
  z: {role: output, universe: [-10, 10], terms: {neg: -5, pos: 5}}
"""

RULES = """\
terms "t.terms.yaml"
operators: and = {and_}, or = {or_}, inference = {inference}, inputs = {inputs}
behavior main:
    use parts when a is not very high with 0.9
    r1: if a is low and not (b is neg or b is somewhat zero) then y is lo and z is neg
    r2: if a is seldom mid or b is intensely pos then y is very lin with 0.7
    r3: if a is high and b is more_or_less zero then y is hi and z is pos
    r4: if a is extremely low then y is somewhat hi
    r5: if b is pos and a is mid then y is 30
end
behavior parts:
    p1: if b is zero then y is lin and z is pos
end
"""

CASES = [dict(and_=t, or_=s, inference=inference, inputs=inputs)
         for (t, s), inference, inputs in zip(
             itertools.zip_longest(TNORMS, SNORMS, fillvalue="min"),
             itertools.cycle(["weighted_average", "weighted_sum"]),
             itertools.cycle(["clamped", "clamped", "as_given"]))]


def exported(tmp_path: Path, case: dict) -> ModuleType:
    (tmp_path / "t.terms.yaml").write_text(TERMS)
    path = tmp_path / "t.rules"
    path.write_text(RULES.format(**case))
    return exported_module(load_rulebase(path).compiled, tmp_path)


def same_bits(module: ModuleType, rows: np.ndarray) -> None:
    """Each row through ``evaluate_one`` gives ``evaluate``'s row, bit for bit."""
    want = module.evaluate(rows)
    for row, y in zip(rows, want):
        got = module.evaluate_one(**dict(zip(module.INPUTS, row.tolist())))
        assert np.array(list(got.values())).tobytes() == y.tobytes(), (row, got, y)


value = st.one_of(st.floats(-15, 15), st.sampled_from(
    [0.0, -0.0, 10.0, -1.0, 1.0, 5.0, 2.0, 0.5, np.inf, -np.inf, np.nan, 1e300]))


@pytest.mark.parametrize("case", CASES, ids=[f"{c['and_']}-{c['or_']}-{c['inference']}-{c['inputs']}"
                                             for c in CASES])
def test_evaluate_one_gives_evaluates_row_bit_for_bit(case: dict, tmp_path: Path) -> None:
    module = exported(tmp_path, case)
    assert module._evaluate_row is not None          # the float path is the one under test

    @settings(max_examples=60, deadline=None)
    @given(st.lists(st.tuples(value, value), min_size=1, max_size=8))
    def check(rows: list[tuple[float, float]]) -> None:
        same_bits(module, np.array(rows, dtype=float))

    check()
    grid = np.linspace(-1, 11, 25)
    same_bits(module, np.array(list(itertools.product(grid, np.linspace(-1.5, 1.5, 13)))))


def test_the_paper_base_takes_the_float_path_with_evaluates_bits(tmp_path: Path) -> None:
    module = exported_module(load_rulebase(ROOT / "rulebases" / "mitos.rules").compiled, tmp_path)
    assert module._evaluate_row is not None
    rng = np.random.default_rng(3)
    same_bits(module, rng.uniform(-200, 200, size=(2000, len(module.INPUTS))))


def test_a_base_without_a_float_form_keeps_evaluate_for_one_sample(tmp_path: Path) -> None:
    """A gaussian term (``exp``), a Mamdani base: ``evaluate_one`` is ``evaluate``'s row."""
    module = exported_module(load_rulebase(DATA / "tipper.fis").compiled, tmp_path)
    assert module._evaluate_row is None
    same_bits(module, np.array([[3.0, 7.0], [-1.0, 12.0], [np.nan, 5.0]]))


def test_a_module_whose_inputs_are_not_clamped_says_so_once_and_warns_of_nothing(
        tmp_path: Path) -> None:
    """With ``inputs = as_given`` the module's docstring gave the clamped sentence's first line
    and then its own ("clamped to their ``evaluate(X)`` maps inputs ... not clamped"), and an
    input far outside its universe made ``mf_kernel``'s slope overflow with NumPy's
    ``RuntimeWarning: overflow encountered in multiply``, where the engine gives the same
    numbers without a word."""
    import warnings

    case = dict(and_="lukasiewicz", or_="bounded_sum", inference="weighted_average",
                inputs="as_given")
    module = exported(tmp_path, case)
    assert module.__doc__.count("maps inputs") == 1 and "clamped to their" not in module.__doc__
    assert "not clamped: an\ninfinite one gives NaN" in module.__doc__
    X = np.array([[1e300, 0.0], [5.0, 1e300], [-1e300, 0.5], [1e200, -1e200]])
    want = load_rulebase(tmp_path / "t.rules").run(X, strict=False, detail=False).outputs
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = module.evaluate(X)
        ones = [tuple(module.evaluate_one(a=a, b=b).values()) for a, b in X.tolist()]
    assert np.array_equal(got, want, equal_nan=True)
    assert np.array_equal(np.array(ones), want, equal_nan=True)
    (tmp_path / "c").mkdir()
    clamped = exported(tmp_path / "c", {**case, "inputs": "clamped"})
    assert "not clamped" not in clamped.__doc__
    assert clamped.__doc__.count("maps inputs ``X[n, k]`` (columns in INPUTS order, clamped to "
                                 "their\nuniverses)") == 1
