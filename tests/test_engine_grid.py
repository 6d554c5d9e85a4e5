"""The grid fast path of the AND layer gives the same bits as gathering each rule's inputs."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.engine import compile as compile_mod
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.lang.parse import parse_rules
from mitos_cli.lang.resolve import build_rulebase
from mitos_cli.lang.termfile import parse_termset

TERMS = """
variables:
  a: {role: input, universe: [0, 10], terms: {L: {shape: left_shoulder, points: [2, 5]},
      M: {shape: triangle, points: [2, 5, 8]}, H: {shape: right_shoulder, points: [5, 8]}}}
  b: {role: input, universe: [0, 10], terms: {L: {shape: left_shoulder, points: [3, 6]},
      H: {shape: right_shoulder, points: [3, 6]}}}
  c: {role: input, universe: [-5, 5], terms: {N: {shape: left_shoulder, points: [-2, 0]},
      Z: {shape: triangle, peak: 0, width: 2}, P: {shape: right_shoulder, points: [0, 2]}}}
  y: {role: output, universe: [0, 100], default: 50, terms: {LO: 10, MID: 50, HI: 90}}
"""
VARS = {"a": ["L", "M", "H"], "b": ["L", "H"], "c": ["N", "Z", "P"]}


def rulebase(order: tuple[str, ...], term_orders: dict[str, list[str]], written: tuple[str, ...]):
    lines = ['terms "t.yaml"']
    outs = ["LO", "MID", "HI"]
    for i, combo in enumerate(itertools.product(*(term_orders[v] for v in order))):
        props = dict(zip(order, combo))
        cond = " and ".join(f"{v} is {props[v]}" for v in written)
        lines.append(f"r{i}: if {cond} then y is {outs[i % 3]}")
    parsed = parse_rules("\n".join(lines) + "\n", "t.rules")
    return build_rulebase(parsed, (parse_termset(TERMS, "t.yaml"),))


@settings(max_examples=25, deadline=None)
@given(order=st.permutations(list(VARS)), written=st.permutations(list(VARS)),
       data=st.data())
def test_grid_equals_gather(order, written, data):
    term_orders = {v: data.draw(st.permutations(VARS[v])) for v in VARS}
    rb = rulebase(tuple(order), term_orders, tuple(written))
    fast = compile_rulebase(rb)
    assert fast.plan.grids, "a full grid in mixed-radix order is detected"
    X = np.random.default_rng(7).uniform([0, 0, -5], [10, 10, 5], size=(500, 3))
    X = X[:, [fast.inputs.index(v) for v in fast.inputs]]
    slow = compile_rulebase(rb)
    object.__setattr__(slow, "plan", compile_mod._plan(slow))
    slow.plan.grids.clear()
    a, b = evaluate(fast, X), evaluate(slow, X)
    assert np.array_equal(a.dof, b.dof) and np.array_equal(a.outputs, b.outputs)


def test_partial_grid_falls_back():
    rb = rulebase(("a", "c"), {"a": VARS["a"], "c": VARS["c"]}, ("a", "c"))
    from dataclasses import replace

    b0 = rb.behaviors[0]
    rb = replace(rb, behaviors=(replace(b0, rules=b0.rules[:-1]),))
    assert not compile_rulebase(rb).plan.grids


@pytest.mark.parametrize("op", ["product", "lukasiewicz"])
def test_grid_only_for_min(op):
    from mitos_cli.lang.model import Setting

    rb = rulebase(("a", "c"), {"a": VARS["a"], "c": VARS["c"]}, ("a", "c"))
    assert not compile_rulebase(rb, overrides=(Setting("and", op),)).plan.grids
