"""One registry per operator: every norm and hedge carries all its forms, and the grammar's
hedge words are the hedge registry's."""

from __future__ import annotations

import math
import re

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from mitos_cli.fuzzy.hedges import HEDGES
from mitos_cli.fuzzy.norms import SNORMS, TNORMS
from mitos_cli.resources import grammar_text

NORMS = [*TNORMS.values(), *SNORMS.values()]
unit = st.floats(0.0, 1.0, allow_nan=False)


def test_the_grammar_hedge_words_are_the_registry():
    line = next(ln for ln in grammar_text().splitlines() if ln.startswith("HEDGE"))
    # the words are a regular expression's alternation (whole words: `veryhigh` is a name)
    words = re.search(r"/\(([a-z_|]+)\)", line)
    assert words is not None, line
    assert set(words.group(1).split("|")) == set(HEDGES)


def test_every_norm_has_every_form():
    for n in NORMS:
        assert n.scalar and n.c and n.numpy, n.name
        assert n.fll, n.name                      # fuzzylite names every norm MITOS has
        assert n.gradient in (None, "select", "product", "dual_product")


def _scalar(statements: str, **env: float) -> dict:
    scope = {"sqrt": math.sqrt, **env}
    exec(statements, scope)
    return scope


@given(unit, unit)
def test_scalar_forms_give_the_numpy_bits(a, b):
    for n in NORMS:
        want = float(n(np.array([a]), np.array([b]))[0])
        assert _scalar(n.scalar, a=a, b=b)["r"] == want, n.name


@given(unit)
def test_hedge_scalar_forms_give_the_numpy_bits(x):
    for h in HEDGES.values():
        if h.scalar:
            assert _scalar(h.scalar, x=x)["x"] == float(h.fn(np.array([x]))[0]), h.name


@given(unit, unit)
def test_numpy_export_forms_compute_the_norm(a, b):
    def _div(num, den, fill):
        return np.divide(num, den, out=np.full(np.shape(num), fill), where=den != 0.0)

    for n in NORMS:
        got = eval(n.numpy, {"np": np, "_div": _div, "a": np.array([a]), "b": np.array([b])})
        assert abs(float(np.asarray(got).ravel()[0]) - float(n(np.array([a]), np.array([b]))[0])) < 1e-12
