"""What running jFuzzyLogic itself (built from source) on its own ``.fcl`` files showed. No
Java runs here: jFuzzyLogic's outputs are recorded."""

from __future__ import annotations

import numpy as np
import pytest

from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.interop.fcl import parse_fcl

#: jFuzzyLogic's ``junit1.fcl``, shortened: singleton output terms and no METHOD (COG)
SINGLETONS_UNDER_COG = """FUNCTION_BLOCK junit1
VAR_INPUT
    temp : REAL;
END_VAR
VAR_OUTPUT
    valve : REAL;
END_VAR
FUZZIFY temp
    TERM cold := (0, 1) (30, 0);
    TERM hot := (0, 0) (30, 1);
END_FUZZIFY
DEFUZZIFY valve
    TERM closed := 0;
    TERM inlet := 1;
END_DEFUZZIFY
RULEBLOCK No1
    AND : MIN;
    ACCU : MAX;
    RULE 1 : IF temp IS cold THEN valve IS closed;
    RULE 2 : IF temp IS hot THEN valve IS inlet;
END_RULEBLOCK
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("method, warned", [("", True), ("    METHOD : COG;\n", True),
                                            ("    METHOD : COGS;\n", False)])
def test_singletons_under_cog_are_said_to_be_what_jfuzzylogic_cannot_evaluate(method, warned):
    """jFuzzyLogic throws on every evaluation of a singleton concluded under COG, its default
    ("MembershipFunction and Defuzzifier are neither both discrete nor both continuous", on
    all 21 points the oracle tried on junit1.fcl): MITOS's number there was silent."""
    text = SINGLETONS_UNDER_COG.replace("END_DEFUZZIFY", method + "END_DEFUZZIFY")
    rb = parse_fcl(text, "j.fcl")
    notes = [n for n in rb.notes if "singleton" in n]
    assert bool(notes) == warned, rb.notes
    if warned:
        written = "`METHOD : COG`" if method else "no METHOD (COG)"
        where = "j.fcl:15:14" if method else "j.fcl:12:11"
        assert notes == [f"{where}: `valve IS closed` concludes a singleton under {written}: "
                         "jFuzzyLogic throws on every evaluation (a discrete term under a "
                         "continuous defuzzifier); MITOS averages the singletons, each snapped "
                         "to its nearest sample, weighted by their aggregated degrees"]
    # by hand, temp = 10: cold 2/3, hot 1/3; under COG the singletons 0 and 1 snap to the
    # midpoints 0.0005 and 0.9995 of 1000 cells, under COGS they stay where they are
    got = evaluate(compile_rulebase(rb), np.array([[10.0]])).outputs[0, 0]
    assert got == pytest.approx(2 / 3 * 0.0005 + 1 / 3 * 0.9995 if warned else 1 / 3)
