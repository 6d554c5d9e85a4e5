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
