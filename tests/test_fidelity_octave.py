"""``--fidelity octave``: Octave's fuzzy-logic-toolkit (0.4.6, Debian's
``octave-fuzzy-logic-toolkit``) where it computes a ``.fis`` otherwise than MATLAB: its centroid
is the trapezoid rule (``trapz (x, x.*y) / trapz (x, y)`` in ``defuzz.m``, the two end points
weighing half: ``sampling = trapezoid``), and it joins a Sugeno output's rules of one value
with the file's ``AggMethod`` before the weighted average (``aggregate_fis_output``:
``accumulation = AggMethod``). The numbers are Octave's ``evalfis`` on the two files below
(ours), printed with ``dlmwrite (..., 'precision', '%.17g')``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mitos_cli.api import LoadedRuleBase
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.engine.mamdani import defuzzify, trapezoid_weights
from mitos_cli.errors import MitosError
from mitos_cli.interop.common import fidelity_rulebase, fidelity_settings
from mitos_cli.interop.export import to_python
from mitos_cli.interop.fis import parse_fis
from mitos_cli.lang.model import Setting

MAMDANI = """\
[System]
Name='pump'
Type='mamdani'
Version=2.0
NumInputs=2
NumOutputs=1
NumRules=3
AndMethod='min'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='centroid'

[Input1]
Name='level'
Range=[0 10]
NumMFs=2
MF1='low':'trimf',[-5 0 6]
MF2='high':'trimf',[4 10 15]

[Input2]
Name='inflow'
Range=[0 4]
NumMFs=2
MF1='slow':'trapmf',[-1 0 1 3]
MF2='fast':'trapmf',[1 3 4 5]

[Output1]
Name='pump'
Range=[0 100]
NumMFs=3
MF1='off':'trimf',[-40 0 40]
MF2='half':'trimf',[20 50 80]
MF3='full':'trimf',[60 100 140]

[Rules]
1 1, 1 (1) : 1
2 0, 3 (1) : 1
1 2, 2 (0.8) : 1
"""

SUGENO = """\
[System]
Name='heat'
Type='sugeno'
Version=2.0
NumInputs=1
NumOutputs=1
NumRules=3
AndMethod='min'
OrMethod='max'
ImpMethod='prod'
AggMethod='max'
DefuzzMethod='wtaver'

[Input1]
Name='temp'
Range=[0 40]
NumMFs=3
MF1='cold':'trimf',[-20 0 20]
MF2='mild':'trimf',[5 20 35]
MF3='hot':'trimf',[10 40 70]

[Output1]
Name='heat'
Range=[0 10]
NumMFs=2
MF1='on':'constant',[8]
MF2='off':'linear',[0.1 1]

[Rules]
1, 1 (1) : 1
2, 1 (1) : 1
3, 2 (1) : 1
"""

X_M = np.array([[1.0, 0.5], [5.0, 2.0], [7.0, 3.5], [9.0, 1.2]])
OCTAVE_M = [13.644663523360485, 50.000000000000057, 84.450000000000003, 86.355336476639536]
X_S = np.array([[5.0], [12.0], [18.0], [30.0]])
OCTAVE_S = [8.0, 7.2749999999999995, 6.776470588235294, 5.333333333333333]


def _octave(text: str, name: str, tmp_path) -> np.ndarray:
    path = tmp_path / name                   # Octave's AggMethod is read from the file
    path.write_text(text)
    from mitos_cli.api import read_rulebase

    rb = read_rulebase(path)
    c = LoadedRuleBase(fidelity_rulebase(rb, "octave"), None,
                       fidelity_settings(rb, "octave")).compiled
    X = X_M if c.operators.inference == "mamdani" else X_S
    return evaluate(c, X, strict=False, detail=False).outputs[:, 0]


def test_the_trapezoid_centroid_is_octaves(tmp_path):
    got = _octave(MAMDANI, "pump.fis", tmp_path)
    np.testing.assert_allclose(got, OCTAVE_M, rtol=0, atol=1e-12)
    matlab = evaluate(compile_rulebase(parse_fis(MAMDANI, "pump.fis")), X_M, detail=False)
    assert abs(matlab.outputs[0, 0] - OCTAVE_M[0]) > 0.2      # 13.358: MATLAB's sum


def test_a_sugeno_output_joins_the_rules_of_one_value_by_aggmethod(tmp_path):
    got = _octave(SUGENO, "heat.fis", tmp_path)
    np.testing.assert_allclose(got, OCTAVE_S, rtol=0, atol=1e-12)
    rb = parse_fis(SUGENO, "gone.fis")          # read from text, no file behind: the reader
    accumulation = (Setting("accumulation", "max"),)         # kept the AggMethod it read
    assert fidelity_settings(rb, "octave") == accumulation
    assert fidelity_settings(parse_fis(SUGENO, None), "octave") == accumulation
    matlab = evaluate(compile_rulebase(rb), X_S, detail=False).outputs[:, 0]
    assert matlab[1] == pytest.approx(7.585714285714285, abs=1e-12)   # every rule counted
    summed = SUGENO.replace("AggMethod='max'", "AggMethod='sum'")
    path = tmp_path / "summed.fis"
    path.write_text(summed)
    from mitos_cli.api import read_rulebase

    assert fidelity_settings(read_rulebase(path), "octave") == ()
    odd = parse_fis(SUGENO.replace("AggMethod='max'", "AggMethod='maxx'"), "odd.fis")
    with pytest.raises(MitosError) as info:      # MATLAB reads it (a Sugeno file's is unused)
        fidelity_settings(odd, "octave")         # Octave's toolkit would use it
    assert info.value.span is not None and info.value.span.line == SUGENO[
        :SUGENO.index("AggMethod")].count("\n") + 1
    assert "did you mean `max`" in str(info.value.hint)


def test_trapezoid_weights_are_the_trapezoid_rule_by_hand():
    x = np.linspace(0.0, 10.0, 11)
    Y = np.array([[1.0, 0.5, 0, 0, 0, 0, 0, 0, 0, 0.25, 0.75]])
    def trapz(f):                      # Octave's trapz (x, f), written out (NumPy 1 and 2)
        return float(np.sum((f[1:] + f[:-1]) / 2 * np.diff(x)))

    want = trapz(x * Y[0]) / trapz(Y[0])
    got = defuzzify(Y, x, "centroid", weights=trapezoid_weights(11))
    assert got[0] == pytest.approx(want, rel=1e-15)
    assert list(trapezoid_weights(4)) == [0.5, 1.0, 1.0, 0.5]


def test_a_batch_row_is_the_row_alone_and_export_refuses_it():
    rb = parse_fis(MAMDANI, "pump.fis")
    c = LoadedRuleBase(rb, None, fidelity_settings(rb, "octave")).compiled
    X = np.random.default_rng(4).uniform([0, 0], [10, 4], size=(129, 2))
    batch = evaluate(c, X, strict=False, detail=False).outputs
    for i in (0, 64, 128):
        one = evaluate(c, X[i:i + 1], strict=False, detail=False).outputs
        assert one[0, 0].tobytes() == batch[i, 0].tobytes()
    with pytest.raises(MitosError) as info:
        to_python(c, "pump.fis")
    assert info.value.message == ("`mitos export` has no code for `sampling = trapezoid` "
                                  "(Octave's centroid, the ends weighing half)")


def test_eval_says_what_octave_does_otherwise(tmp_path, capsys):
    from mitos_cli.cli.app import main

    path = tmp_path / "pump.fis"
    path.write_text(MAMDANI.replace("DefuzzMethod='centroid'", "DefuzzMethod='bisector'"))
    with pytest.raises(SystemExit) as info:
        main(["eval", str(path), "level=1", "inflow=0.5", "--fidelity", "octave"])
    assert not info.value.code
    assert "Octave's bisector gives the index of its sample, not the sample" in \
        capsys.readouterr().err
    summed = tmp_path / "summed.fis"
    summed.write_text(SUGENO.replace("AggMethod='max'", "AggMethod='sum'"))
    with pytest.raises(SystemExit) as info:
        main(["eval", str(summed), "temp=12", "--fidelity", "octave"])
    assert not info.value.code
    assert "--fidelity octave changes nothing here" in capsys.readouterr().err


LAMP = Path(__file__).parent / "golden" / "eval_fidelity_octave_no_rule" / "lamp.fis"


def _eval(capsys, *args: str) -> tuple[int, str, str]:
    from mitos_cli.cli.app import main

    with pytest.raises(SystemExit) as info:
        main(["eval", *args])
    out, err = capsys.readouterr()
    return int(info.value.code or 0), out, err


def test_where_no_rule_fires_octave_gives_nan_and_the_batch_says_so(tmp_path, capsys):
    """Octave's ``evalfis`` on ``lamp.fis`` (0.4.6, ``printf ('%.17g')``): NaN at daylight 0,
    5 and 10, where no rule fires, 76.386346586646653 at 3; MATLAB gives the middle of the
    range (50), which ``--fidelity matlab`` keeps."""
    batch = tmp_path / "in.csv"
    batch.write_text("daylight\n0\n3\n10\n")
    code, out, err = _eval(capsys, str(LAMP), "--batch", str(batch), "--fidelity", "octave")
    assert code == 0
    assert out.splitlines()[1:] == ["0,nan", "3,76.38634658664667", "10,nan"]
    assert err == ("warning: no rule sets `power` in 2 rows of 3: Octave gives NaN there, and "
                   "nan is written\n")
    code, out, err = _eval(capsys, str(LAMP), "--batch", str(batch), "--fidelity", "matlab")
    assert out.splitlines()[1:] == ["0,50.0", "3,76.38634658664667", "10,50.0"]
    assert "the file's default (50) is written there" in err
    # an --on-no-rule given still chooses
    code, out, err = _eval(capsys, str(LAMP), "--batch", str(batch), "--fidelity", "octave",
                           "--on-no-rule", "skip")
    assert out.splitlines() == ["daylight,power,no_rule", "3,76.38634658664667,"]
    code, out, err = _eval(capsys, str(LAMP), "--batch", str(batch), "--fidelity", "octave",
                           "--on-no-rule", "error")
    assert code == 1 and "no rule sets `power` for daylight=0 (row 1; 2 of 3 rows)" in err


def test_a_sugeno_output_no_rule_sets_is_where_octave_stops(tmp_path, capsys):
    """Octave's ``evalfis`` stops with an error on a Sugeno system where no rule fires
    (``defuzzify_output_sugeno``: "next_agg_output(1,_): out of bound 0"); the fidelity gives NaN and
    says so. A fuzzylite ``Default=`` line, which Octave does not read, stays the file's."""
    sugeno = (LAMP.read_text().replace("'mamdani'", "'sugeno'")
              .replace("DefuzzMethod='centroid'", "DefuzzMethod='wtaver'")
              .replace("'trimf',[50 80 100]", "'constant',[80]")
              .replace("'trimf',[0 20 50]", "'constant',[20]"))
    path = tmp_path / "lamp_sugeno.fis"
    path.write_text(sugeno)
    code, out, err = _eval(capsys, str(path), "daylight=0", "--fidelity", "octave")
    assert code == 0
    assert out.splitlines()[-1] == ("  power = nan   (no rule sets it here; Octave's evalfis "
                                    "stops with an error)")
    written = tmp_path / "written.fis"
    written.write_text(sugeno.replace("Range=[0 100]\n", "Range=[0 100]\nDefault=30\n"))
    code, out, err = _eval(capsys, str(written), "daylight=0", "--fidelity", "octave")
    assert out.splitlines()[-1] == "  power = 30.0   (its default: no rule sets it here)"
