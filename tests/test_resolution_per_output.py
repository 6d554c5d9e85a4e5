"""A Mamdani output's own resolution (``resolution:`` on an output variable): fuzzylite gives
each output its defuzzifier's resolution (``Centroid 200`` on one, ``Centroid 500`` on
another), which MITOS refused ("resolution 500 differs from 200") until 2026-12-06, night 9.

The reference numbers are the engines' own, on the FLL file below (ours): pyfuzzylite 8.0.6
(``FllImporter().from_file``, ``process()``), and Debian's ``fuzzylite`` 6 binary (``-of fld -d
IN -decimals 12``), which samples an output without a resolution at 100 points where fuzzylite
8 takes 1000."""

from __future__ import annotations

import numpy as np
import pytest

from mitos_cli.api import LoadedRuleBase
from mitos_cli.engine.check import check_rulebase
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.describe import describe_network
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.errors import MitosError
from mitos_cli.interop import parse_foreign, write_foreign
from mitos_cli.interop.common import fidelity_rulebase, fidelity_settings
from mitos_cli.interop.fll import parse_fll
from mitos_cli.interop.rules_writer import write_rules
from mitos_cli.lang.parse import parse_rules
from mitos_cli.lang.resolve import build_rulebase
from mitos_cli.lang.termfile import parse_termset
from mitos_cli.teach.adapt import output_tables, parameterise

OWN = """\
Engine: own
InputVariable: light
  enabled: true
  range: 0.000 1.000
  lock-range: false
  term: dark Triangle 0.000 0.300 0.600
  term: dim Triangle 0.200 0.500 0.800
  term: bright Triangle 0.400 0.700 1.000
OutputVariable: lamp
  enabled: true
  range: 0.000 1.000
  lock-range: false
  aggregation: Maximum
  defuzzifier: Centroid 200
  default: nan
  lock-previous: false
  term: low Triangle 0.000 0.200 0.450
  term: mid Triangle 0.200 0.500 0.800
  term: high Triangle 0.550 0.800 1.000
OutputVariable: shade
  enabled: true
  range: 0.000 1.000
  lock-range: false
  aggregation: Maximum
  defuzzifier: Centroid 7
  default: nan
  lock-previous: false
  term: open Cosine 0.250 0.500
  term: half Cosine 0.500 0.500
  term: closed Cosine 0.750 0.500
OutputVariable: fan
  enabled: true
  range: 0.000 1.000
  lock-range: false
  aggregation: Maximum
  defuzzifier: Centroid
  default: nan
  lock-previous: false
  term: slow Triangle 0.000 0.250 0.600
  term: fast Triangle 0.400 0.750 1.000
RuleBlock: main
  enabled: true
  conjunction: Minimum
  disjunction: Maximum
  implication: Minimum
  activation: General
  rule: if light is dark then lamp is high and shade is open
  rule: if light is dim then lamp is mid and shade is half and fan is slow
  rule: if light is bright then lamp is low and shade is closed and fan is fast
"""

X = np.array([[0.1], [0.35], [0.5], [0.62], [0.9]])
#: pyfuzzylite 8.0.6: lamp at 200 points, shade at 7, fan at 1000 (its default)
FUZZYLITE8 = [[0.7788908609139084, 0.23852823900334685, np.nan],
              [0.6348203036666129, 0.3609746558218127, 0.2888888888888888],
              [0.5000000000000001, 0.49999999999999994, 0.43067660593338614],
              [0.3780373434359054, 0.6276946177978359, 0.5123808915926468],
              [0.2211091390860914, 0.7614717609966531, 0.7077778736505747]]
#: the fuzzylite 6 binary: the same, but fan at 100 points (its default)
FUZZYLITE6 = [[0.778890860914, 0.238528239003, np.nan],
              [0.634820303667, 0.360974655822, 0.288874079716],
              [0.500000000000, 0.500000000000, 0.430703851839],
              [0.378037343436, 0.627694617798, 0.512398528185],
              [0.221109139086, 0.761471760997, 0.707786791590]]


def _outputs(rb, settings=()) -> np.ndarray:
    c = LoadedRuleBase(rb, None, settings).compiled
    return evaluate(c, X, strict=False, detail=False).outputs


def bits(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


def test_each_output_is_sampled_at_its_own_resolution_as_fuzzylite_8_and_6():
    rb = parse_fll(OWN, "own.fll")
    assert [rb.variables[n].resolution for n in ("lamp", "shade", "fan")] == [200, 7, None]
    c = compile_rulebase(rb)
    assert [len(t.grid) for t in c.mamdani] == [200, 7, 1000]
    np.testing.assert_allclose(_outputs(rb), FUZZYLITE8, rtol=0, atol=1e-15)
    six = fidelity_settings(rb, "fuzzylite6")
    assert [len(t.grid) for t in LoadedRuleBase(rb, None, six).compiled.mamdani] == [200, 7, 100]
    np.testing.assert_allclose(_outputs(rb, six), FUZZYLITE6, rtol=0, atol=1e-12)


def test_an_output_without_a_resolution_beside_one_with_is_not_sampled_at_the_others():
    """Night 8 read one written resolution as every output's: `fan` (none written) was
    sampled at `lamp`'s 200 points, 0.4306833 at light = 0.5 where fuzzylite 8 gives
    0.4306766 (1000 points) and fuzzylite 6 0.4307039 (100): no engine's number."""
    text = OWN[:OWN.index("OutputVariable: shade")] + OWN[OWN.index("OutputVariable: fan"):]
    for cut in (" and shade is open", " and shade is half", " and shade is closed"):
        text = text.replace(cut, "")
    rb = parse_fll(text, "mixed.fll")
    assert rb.variables["lamp"].resolution == 200 and rb.variables["fan"].resolution is None
    want8 = np.array(FUZZYLITE8)[:, [0, 2]]
    np.testing.assert_allclose(_outputs(rb), want8, rtol=0, atol=1e-15)
    want6 = np.array(FUZZYLITE6)[:, [0, 2]]
    np.testing.assert_allclose(_outputs(rb, fidelity_settings(rb, "fuzzylite6")), want6,
                               rtol=0, atol=1e-12)


def test_one_resolution_for_every_output_stays_the_behaviors():
    text = OWN.replace("Centroid 7", "Centroid 200").replace("  defuzzifier: Centroid\n",
                                                             "  defuzzifier: Centroid 200\n")
    rb = parse_fll(text, "one.fll")
    assert all(v.resolution is None for v in rb.variables.values())
    c = compile_rulebase(rb)
    assert c.operators.resolution == 200 and c.own_resolutions == {}
    assert "resolution = 200" in c.describe_operators()


def test_matlab_and_jfuzzylogic_sample_every_output_alike():
    rb = parse_fll(OWN, "own.fll")
    for engine, points in (("matlab", 101), ("jfuzzylogic", 1000)):
        c = LoadedRuleBase(fidelity_rulebase(rb, engine), None,
                           fidelity_settings(rb, engine)).compiled
        assert [len(t.grid) for t in c.mamdani] == [points] * 3, engine
    assert fidelity_rulebase(rb, "fuzzylite6") is rb


def test_fll_and_the_rule_language_write_it_and_read_back_the_same_bits(tmp_path):
    rb = parse_fll(OWN, "own.fll")
    fll = write_foreign(rb, "fll")
    assert [ln.strip() for ln in fll.splitlines() if "defuzzifier" in ln] == [
        "defuzzifier: Centroid 200", "defuzzifier: Centroid 7", "defuzzifier: Centroid"]
    back = parse_foreign(fll, "fll", "back.fll")
    assert np.array_equal(bits(_outputs(back)), bits(_outputs(rb)))
    rules, terms = write_rules(rb, "own.terms.yaml")
    assert "    resolution: 200\n" in terms and "    resolution: 7\n" in terms
    assert terms.count("resolution:") == 2
    (tmp_path / "own.rules").write_text(rules)
    (tmp_path / "own.terms.yaml").write_text(terms)
    from mitos_cli.api import read_rulebase

    again = read_rulebase(tmp_path / "own.rules")
    assert again.variables["shade"].resolution == 7
    assert np.array_equal(bits(_outputs(again)), bits(_outputs(rb)))


def test_fcl_and_fis_say_the_resolutions_they_drop():
    from mitos_cli.interop import conversion_notes

    rb = parse_fll(OWN.replace("Cosine", "Gaussian"), "own.fll")
    fcl = conversion_notes(rb, "fcl")
    assert any("without this rule base's 1000 and 200 and 7 points" in n for n in fcl), fcl
    fis = conversion_notes(rb, "fis")
    assert any("this rule base uses 200 and 7 and 1000 midpoints" in n for n in fis), fis


def test_a_batch_row_is_the_row_alone_bit_for_bit():
    c = compile_rulebase(parse_fll(OWN, "own.fll"))
    X2 = np.random.default_rng(3).uniform(-0.1, 1.1, size=(257, 1))
    batch = evaluate(c, X2, strict=False, detail=False).outputs
    for i in (0, 100, 256):
        one = evaluate(c, X2[i:i + 1], strict=False, detail=False).outputs
        assert np.array_equal(bits(one[0]), bits(batch[i]))


def test_the_header_and_the_network_name_them():
    c = compile_rulebase(parse_fll(OWN, "own.fll"))
    assert c.own_resolutions == {"lamp": 200, "shade": 7}
    # (its inputs say no `lock-range`: fuzzylite's default, read as `inputs = as_given`)
    assert c.describe_operators().endswith("resolution = 1000, 200 for lamp, 7 for shade, "
                                           "inputs = as_given")
    text = describe_network(c)
    assert "defuzzify centroid on 1,000 samples (or its own)" in text
    assert "shade: 3 rules -> 3 consequent sets (open, half, closed), on its own 7 samples" in text


TERMS = """\
variables:
  x:
    role: input
    universe: [0, 10]
    terms: {lo: {shape: left_shoulder, points: [2, 8]}, hi: {shape: right_shoulder, points: [2, 8]}}
  y:
    role: output
    universe: [0, 30]
    resolution: 30
    terms:
      a: {shape: triangle, points: [0, 5, 10]}
      thin: {shape: triangle, points: [14.6, 15, 15.4]}
      b: {shape: triangle, points: [20, 25, 30]}
"""
RULES = """\
terms "t.terms.yaml"
operators: inference = mamdani, resolution = 1001
if x is lo then y is a
if x is hi then y is b
if x is hi then y is thin
"""


def _rule_file(terms: str = TERMS):
    return build_rulebase(parse_rules(RULES, "t.rules"), (parse_termset(terms, "t.terms.yaml"),))


def test_a_term_sets_resolution_beats_the_operators_and_check_says_where_to_raise_it():
    rb = _rule_file()
    c = compile_rulebase(rb)
    assert len(c.mamdani[0].grid) == 30
    found = [f for f in check_rulebase(rb).findings if f.code == "undersampled-term"]
    assert found and found[0].hint == ("widen it, or raise `y`'s own resolution (now 30): "
                                       "`resolution: 1001` under `y` in its term set")


def test_teach_samples_each_output_on_its_own_grid():
    c = compile_rulebase(_rule_file())
    p = parameterise(c)
    for mine, engine in zip(output_tables(p, p.values), c.mamdani):
        assert np.array_equal(bits(mine.sets), bits(engine.sets))


@pytest.mark.parametrize("old, new, message, where", [
    ("    resolution: 30\n", "    resolution: 2\n",
     "variable `y`: resolution must be a whole number from 3 to 100000, not 2", (9, 17)),
    ("    resolution: 30\n", "    resolution: 31.5\n",
     "variable `y`: resolution must be a whole number from 3 to 100000, not 31.5", (9, 17)),
    ("    resolution: 30\n", "    resolution: many\n",
     "variable `y`: resolution must be a whole number from 3 to 100000, not 'many'", (9, 17)),
    ("    role: input\n", "    role: input\n    resolution: 30\n",
     "variable `x`: only outputs take a `resolution` (an input is not sampled)", (4, 5)),
])
def test_a_bad_resolution_is_refused_at_its_place(old, new, message, where):
    with pytest.raises(MitosError) as info:
        parse_termset(TERMS.replace(old, new, 1), "t.terms.yaml")
    assert info.value.message == message
    assert (info.value.span.line, info.value.span.column) == where


def test_fcl_cog_with_a_resolution_per_output_reads_the_same_way():
    """`METHOD : COG 200;` is MITOS's own FCL (neither fuzzylite 6 nor jFuzzyLogic reads a
    resolution there): per output, as in FLL, and an output without one keeps the 1000."""
    from mitos_cli.interop.fcl import parse_fcl

    fcl = write_foreign(parse_fll(OWN, "own.fll"), "fcl")
    fcl = fcl.replace("METHOD : COG;", "METHOD : COG 200;", 1).replace(
        "METHOD : COG;", "METHOD : COG 7;", 1)
    rb = parse_fcl(fcl, "own.fcl")
    assert [rb.variables[n].resolution for n in ("lamp", "shade", "fan")] == [200, 7, None]
    np.testing.assert_allclose(_outputs(rb), FUZZYLITE8, rtol=0, atol=1e-15)
    same = parse_fcl(fcl.replace("COG 7;", "COG 200;").replace("METHOD : COG;",
                                                               "METHOD : COG 200;"), "one.fcl")
    assert all(v.resolution is None for v in same.variables.values())
    assert compile_rulebase(same).operators.resolution == 200


def test_the_exported_python_samples_each_output_on_its_own_grid(tmp_path):
    import importlib.util

    from mitos_cli.interop.export import to_python

    c = compile_rulebase(parse_fll(OWN, "own.fll"))
    path = tmp_path / "exported.py"
    path.write_text(to_python(c, "own.fll"))
    spec = importlib.util.spec_from_file_location("exported", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    np.testing.assert_allclose(module.evaluate(X), FUZZYLITE8, rtol=0, atol=1e-12)


def test_check_calls_an_outputs_own_resolution_idle_outside_mamdani():
    rules = RULES.replace("operators: inference = mamdani, resolution = 1001\n", "").replace(
        "then y is thin", "then y is 15")
    terms = TERMS.replace("a: {shape: triangle, points: [0, 5, 10]}", "a: 5").replace(
        "thin: {shape: triangle, points: [14.6, 15, 15.4]}", "thin: 15").replace(
        "b: {shape: triangle, points: [20, 25, 30]}", "b: 25")
    rb = build_rulebase(parse_rules(rules, "t.rules"), (parse_termset(terms, "t.terms.yaml"),))
    idle = [f for f in check_rulebase(rb).findings if f.code == "idle-setting"]
    assert [f.message for f in idle] == ["`y`'s own `resolution: 30` has no effect: behavior "
                                         "`main` uses weighted_average inference"]
    assert (idle[0].span.line, idle[0].span.column) == (6, 3)
    assert not [f for f in check_rulebase(_rule_file()).findings if f.code == "idle-setting"]
