"""fuzzylite's `.fis` exports: what its own engine, fuzzylite 6, reads in them.

fuzzylite's ``FisExporter`` writes 0 for a condition on an output (a chained engine's
``if Detergent is usual then Cycle is short``, which a .fis rule cannot say), so such a rule
has no condition at all. fuzzylite 6 reads it as ``if  then Cycle is short``, which does not
load, and ``General::activate`` skips a rule that is not loaded: it never fires. Octave's
toolkit stops on it ("nonconformant arguments" in ``eval_firing_strength``). MITOS refused it
until 2026-12-06, night 9; in a file fuzzylite wrote it now leaves it out as fuzzylite 6 does.
The numbers are the ``fuzzylite`` 6 binary's (Debian 6.0+dfsg-6, ``-of fld -d IN -decimals
12``) on the file below (ours)."""

from __future__ import annotations

import numpy as np
import pytest

from mitos_cli.api import LoadedRuleBase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.errors import MitosError
from mitos_cli.interop.common import fidelity_settings
from mitos_cli.interop.fis import parse_fis

CHAIN = """\
#Code automatically generated with fuzzylite 6.0.

[System]
Name='chain'
Type='mamdani'
Version=6.0
NumInputs=1
NumOutputs=2
NumRules=4
AndMethod='min'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='centroid'

[Input1]
Name='level'
Range=[0.000 10.000]
NumMFs=2
MF1='low':'trimf',[0.000 2.000 6.000]
MF2='high':'trimf',[4.000 8.000 10.000]

[Output1]
Name='valve'
Range=[0.000 1.000]
NumMFs=2
MF1='shut':'trimf',[0.000 0.200 0.500]
MF2='open':'trimf',[0.400 0.700 1.000]

[Output2]
Name='alarm'
Range=[0.000 1.000]
NumMFs=2
MF1='quiet':'trimf',[0.000 0.250 0.500]
MF2='loud':'trimf',[0.500 0.750 1.000]

[Rules]
1.000 , 2.000 0.000 (1.000) : 1
2.000 , 1.000 0.000 (1.000) : 1
0.000 , 0.000 2.000 (1.000) : 1
2.000 , 0.000 1.000 (0.500) : 1
"""

X = np.array([[1.0], [3.0], [5.0], [7.5]])
#: the fuzzylite 6 binary: `alarm is loud` never fires (else alarm would pass 0.5 at 5 and 7.5)
FUZZYLITE6 = [[0.7, np.nan], [0.7, np.nan], [0.494343850843, 0.25], [0.233781313473, 0.25]]


def test_a_rule_without_condition_in_fuzzylites_export_never_fires_as_in_fuzzylite_6():
    rb = parse_fis(CHAIN, "chain.fis")
    assert [r.label for r in rb.behaviors[0].rules] == ["r1", "r2", "r4"]
    assert rb.notes == ("chain.fis:40:1: 1 rule with no condition (fuzzylite's exporter writes 0 "
                        "for a condition on an output, a chained engine's, which a .fis file "
                        "cannot say): left out, as fuzzylite 6 leaves them out (it does not load "
                        "them, so they never fire); the engine's FLL or FCL keeps the conditions",)
    c = LoadedRuleBase(rb, None, fidelity_settings(rb, "fuzzylite6")).compiled
    got = evaluate(c, X, strict=False, detail=False).outputs
    want = np.array(FUZZYLITE6)
    np.testing.assert_allclose(got[:, 0], want[:, 0], rtol=0, atol=1e-12)
    # where no rule fires a .fis output is MATLAB's mid-range (fuzzylite 6: NaN)
    np.testing.assert_allclose(got[:, 1], np.where(np.isnan(want[:, 1]), 0.5, want[:, 1]),
                               rtol=0, atol=1e-12)


def test_an_output_no_rule_sets_then_is_named():
    text = CHAIN.replace("2.000 , 0.000 1.000 (0.500) : 1", "0.000 , 0.000 1.000 (0.500) : 1")
    rb = parse_fis(text, "chain.fis")
    assert len(rb.notes) == 1 and rb.notes[0].startswith("chain.fis:40:1: 2 rules with no "
                                                         "condition")
    assert "; no rule sets `alarm` then, so MITOS computes no value for it (fuzzylite 6: NaN " \
           "on every row)" in rb.notes[0]
    assert LoadedRuleBase(rb).outputs == ("valve",)


def test_elsewhere_a_rule_without_condition_is_still_refused():
    """Not fuzzylite's file: MATLAB defines no such rule, and Octave stops on it."""
    with pytest.raises(MitosError) as info:
        parse_fis(CHAIN.replace("#Code automatically generated with fuzzylite 6.0.\n", ""),
                  "chain.fis")
    assert info.value.message == "the rule has no condition"
    assert (info.value.span.line, info.value.span.column) == (39, 1)


# fuzzylite's Tsukamoto systems in .fis (fuzzylite ignores `Type` and infers Tsukamoto
# inference from a weighted defuzzifier over monotonic terms; its exporter writes
# `Type='tsukamoto'`): read as the same system written in FLL, bit for bit.
TSUKAMOTO_FIS = """\
[System]
Name='tsk'
Type='{kind}'
NumInputs=1
NumOutputs=2
NumRules=3
AndMethod='min'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='wtaver'

[Input1]
Name='X'
Range=[-10 10]
NumMFs=3
MF1='small':'gbellmf',[5 3 -10]
MF2='medium':'gbellmf',[5 3 0]
MF3='large':'gbellmf',[5 3 10]

[Output1]
Name='Ramps'
Range=[0 1]
NumMFs=3
MF1='a':'rampmf',[0 0.25]
MF2='b':'rampmf',[0.6 0.4]
MF3='c':{third}

[Output2]
Name='Shapes'
Range=[0 1]
NumMFs=3
MF1='a':'smf',[0 0.25]
MF2='b':'zmf',[0.3 0.6]
MF3='c':'concavemf',[0.9 1]

[Rules]
1, 1 1 (1) : 1
2, 2 2 (1) : 1
3, 3 3 (1) : 1
"""
TSUKAMOTO_FLL = """\
Engine: tsk
InputVariable: X
  range: -10 10
  term: small Bell -10 5 3
  term: medium Bell 0 5 3
  term: large Bell 10 5 3
OutputVariable: Ramps
  range: 0 1
  defuzzifier: WeightedAverage
  default: nan
  term: a Ramp 0 0.25
  term: b Ramp 0.6 0.4
  term: c Ramp 0.7 1
OutputVariable: Shapes
  range: 0 1
  defuzzifier: WeightedAverage
  default: nan
  term: a SShape 0 0.25
  term: b ZShape 0.3 0.6
  term: c Concave 0.9 1
RuleBlock:
  conjunction: Minimum
  disjunction: Maximum
  implication: Minimum
  rule: if X is small then Ramps is a and Shapes is a
  rule: if X is medium then Ramps is b and Shapes is b
  rule: if X is large then Ramps is c and Shapes is c
"""


@pytest.mark.parametrize("kind", ["tsukamoto", "sugeno"])
def test_a_fis_of_monotonic_outputs_is_tsukamoto_as_its_fll_twin(kind):
    from mitos_cli.interop.fll import parse_fll

    fis = parse_fis(TSUKAMOTO_FIS.format(kind=kind, third="'rampmf',[0.7 1]"), "tsk.fis")
    assert dict((s.key, s.value) for s in fis.operators)["inference"] == "tsukamoto"
    said = [n for n in fis.notes if "read as fuzzylite reads it: Tsukamoto inference" in n]
    assert len(said) == (kind == "sugeno")      # `Type='tsukamoto'` says so itself
    x = np.linspace(-10, 10, 401)
    ours = LoadedRuleBase(fis).evaluate(X=x)
    twin = LoadedRuleBase(parse_fll(TSUKAMOTO_FLL, "tsk.fll")).evaluate(X=x)
    for name in ("Ramps", "Shapes"):
        assert ours[name].tobytes() == twin[name].tobytes()
    w = 1 / 65            # X = 0: `small` and `large` at 1 / (1 + (10 / 5)^6), `medium` at 1
    by_hand = (w * 0.25 * w + 0.4 + w * (0.7 + 0.3 * w)) / (1 + 2 * w)   # ramps inverted
    assert ours["Ramps"][200] == pytest.approx(by_hand, rel=1e-12)


def test_a_tsukamoto_fis_with_an_mf_it_cannot_invert_is_refused_at_the_mf():
    with pytest.raises(MitosError) as info:
        parse_fis(TSUKAMOTO_FIS.format(kind="tsukamoto", third="'constant',[0.7]"), "tsk.fis")
    assert info.value.message.startswith("output term `Ramps.c`: Tsukamoto inference inverts "
                                         "monotonic terms")
    assert info.value.span.line == 27


def test_a_sugeno_fis_mixing_monotonic_and_constant_outputs_is_refused_at_the_mf():
    ramps = ("MF1='a':'constant',[0]\nMF2='b':'constant',[0.5]\n"
             "MF3='c':'constant',[1]")
    text = TSUKAMOTO_FIS.format(kind="sugeno", third="'rampmf',[0.7 1]")
    text = text.replace("MF1='a':'rampmf',[0 0.25]\nMF2='b':'rampmf',[0.6 0.4]\n"
                        "MF3='c':'rampmf',[0.7 1]", ramps)
    with pytest.raises(MitosError) as info:
        parse_fis(text, "tsk.fis")
    assert info.value.message == ("output `Ramps`'s MF `a` is a `singleton` term, where "
                                  "`Shapes`'s are all monotonic (Tsukamoto): MITOS takes one "
                                  "inference per rule base")
    assert info.value.span.line == 25


def test_a_tsukamoto_fis_summing_its_weights_is_refused_at_the_method():
    text = TSUKAMOTO_FIS.format(kind="tsukamoto", third="'rampmf',[0.7 1]")
    with pytest.raises(MitosError) as info:
        parse_fis(text.replace("'wtaver'", "'wtsum'"), "tsk.fis")
    assert info.value.message.startswith("Tsukamoto inference with a weighted sum")
    assert info.value.span.line == 11


def test_a_tsukamoto_fis_says_its_outputs_take_only_monotonic_mfs():
    with pytest.raises(MitosError) as info:
        parse_fis(TSUKAMOTO_FIS.format(kind="tsukamoto", third="'trimf',[0.6 0.8 1]"), "tsk.fis")
    assert info.value.message == ("MF `c`: the outputs of a Tsukamoto-type .fis take only "
                                  "monotonic MFs (rampmf, sigmf, smf, zmf, concavemf: "
                                  "fuzzylite's Tsukamoto inference), not `trimf`")
    assert info.value.span.line == 27


def test_a_hybrid_fis_is_refused_with_the_way_to_its_fll():
    """fuzzylite writes an engine of Mamdani and Takagi-Sugeno outputs as `Type='hybrid'`
    (its examples' hybrid/tipper.fis): one defuzzifier for both kinds, which fuzzylite 6 reads
    back as a centroid over the constant terms too. MITOS refuses it and says where the
    engine is whole: the FLL it was written from, whose rule blocks become behaviors."""
    text = TSUKAMOTO_FIS.format(kind="hybrid", third="'rampmf',[0.7 1]")
    with pytest.raises(MitosError) as info:
        parse_fis(text, "tipper.fis")
    assert info.value.message == "FIS type `hybrid` is not supported"
    assert (info.value.span.line, info.value.span.column) == (3, 6)
    assert "the FLL it was written from" in (info.value.hint or "")
