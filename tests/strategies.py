"""Hypothesis strategies shared by the property tests: random antecedent expressions."""

from __future__ import annotations

from hypothesis import strategies as st

from mitos_cli.lang.model import And, Not, Or, Prop


@st.composite
def expressions(draw, inputs, hedges: tuple[str, ...], max_hedges: int = 1, depth: int = 2):
    """``and`` / ``or`` / ``not`` trees of depth at most ``depth`` over the terms of the input
    variables ``inputs``, each proposition with up to ``max_hedges`` of ``hedges``."""
    if depth == 0 or draw(st.booleans()):
        v = draw(st.sampled_from(inputs))
        chosen = tuple(draw(st.lists(st.sampled_from(hedges), max_size=max_hedges)))
        return Prop(v.name, draw(st.sampled_from(v.term_names)), chosen, draw(st.booleans()))
    kind = draw(st.sampled_from(["and", "or", "not"]))
    if kind == "not":
        return Not(draw(expressions(inputs, hedges, max_hedges, depth - 1)))
    items = tuple(draw(st.lists(expressions(inputs, hedges, max_hedges, depth - 1),
                                min_size=2, max_size=3)))
    return And(items) if kind == "and" else Or(items)
