"""Regression tests for foreign files that loaded wrongly or not at all, each on a small file
of its own: names that begin with hedge words, MATLAB comments and padded parameters,
jFuzzyLogic's FCL constructs, each format's shape definitions, non-finite numbers, and the
batch's no-rule-fired policy."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from mitos_cli.api import load_rulebase, read_rulebase
from mitos_cli.errors import MitosError
from mitos_cli.interop.fcl import parse_fcl
from mitos_cli.interop.fis import parse_fis
from mitos_cli.interop.fll import parse_fll
from mitos_cli.parse import parse_rules


def outputs(rb, **inputs):
    from mitos_cli.compile import compile_rulebase
    from mitos_cli.engine import as_batch, evaluate

    c = compile_rulebase(rb)
    return dict(zip(c.outputs, evaluate(c, as_batch(c, inputs), strict=False).outputs[0]))


# ---------------------------------------------------------------------------------------------
# Hedge words are whole words

FLL_HEDGE_PREFIX = """\
Engine: e
InputVariable: x
  range: 0 10
  term: veryhigh Triangle 0 10 10
  term: high Triangle 0 10 10
OutputVariable: y
  range: 0 10
  defuzzifier: WeightedAverage
  default: nan
  term: anyway Constant 8
  term: low Constant 2
RuleBlock: b
  conjunction: Minimum
  disjunction: Maximum
  rule: if x is veryhigh then y is anyway
  rule: if x is notable then y is low
"""


def test_rule_language_reads_a_name_beginning_with_a_hedge_as_a_name():
    rb = parse_rules("behavior b:\n if x is veryhigh then y is anyway\n"
                     " if x is notable then y is somewhat_low\n if x is very high then y is low\nend\n")
    a, b, c = rb.behaviors[0].rules
    assert (a.antecedent.term, a.antecedent.hedges) == ("veryhigh", ())
    assert a.consequents[0].term == "anyway"
    assert (b.antecedent.term, b.antecedent.negated) == ("notable", False)
    assert b.consequents[0].term == "somewhat_low"
    assert (c.antecedent.term, c.antecedent.hedges) == ("high", ("very",))


def test_fll_reads_a_name_beginning_with_a_hedge_as_a_name():
    text = FLL_HEDGE_PREFIX.replace("rule: if x is notable then y is low\n", "")
    rb = parse_fll(text)
    rule = rb.behaviors[0].rules[0]
    assert (rule.antecedent.term, rule.antecedent.hedges) == ("veryhigh", ())
    assert outputs(rb, x=5.0)["y"] == pytest.approx(8.0)


# ---------------------------------------------------------------------------------------------
# MATLAB .fis as MATLAB and fuzzylite write it

FIS = """\
% $Revision: 1.1 $
#Code automatically generated with fuzzylite
[System]
Name='small'
Type='mamdani'
NumInputs=1
NumOutputs=1
NumRules=2
AndMethod='einstein_product'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='centroid'

[Input1]
Name='x'
Range=[0 10]
NumMFs=2
MF1='low':'gbellmf',[3 2 0 0]
MF2='low':'trimf',[0 10 10]

[Output1]
Name='y'
Range=[0 10]
NumMFs=2
MF1='a':'trimf',[0 0 10]
MF2='b':'trimf',[0 10 10]

[Rules]
% the two rules
1, 1 (1) : 1
2, 2 (1) : 1
"""


def test_fis_skips_comment_lines_and_reads_padded_lists_and_octave_names():
    rb = parse_fis(FIS, "small.fis")
    x = rb.variables["x"]
    assert x.terms[0].shape == "bell" and x.terms[0].params == (0.0, 3.0, 2.0)
    assert any(s.key == "and" and s.value == "einstein" for s in rb.operators)


def test_fis_keeps_duplicate_mf_names_apart_and_says_so():
    rb = parse_fis(FIS, "small.fis")
    assert rb.variables["x"].term_names == ("low", "low_2")
    r2 = rb.behaviors[0].rules[1]
    assert (r2.antecedent.term, r2.consequents[0].term) == ("low_2", "b")
    assert len(rb.notes) == 1 and "small.fis:20:" in rb.notes[0] and "`low_2`" in rb.notes[0]


def test_fis_padded_list_with_a_nonzero_extra_number_is_refused():
    with pytest.raises(MitosError, match="gbellmf takes 3 numbers, not 4"):
        parse_fis(FIS.replace("[3 2 0 0]", "[3 2 0 1]"), "small.fis")
