"""Round trips: read X, write it as each format, read that back: the same outputs.

The corpus is every engine the readers accept: pyfuzzylite's 50 readable examples (when
installed), the sample files under ``tests/data/interop`` and MITOS's own rule base. Inputs are
seeded uniform samples over each universe. A format that cannot say something refuses with a
FormatError naming it; where it can say it only approximately (MATLAB's fixed output sampling,
MATLAB's mid-range output when no rule fires), the writer's notes say so and the test checks
the documented bound instead of equality.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mitos_cli.api import read_rulebase
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.errors import FormatError
from mitos_cli.interop import conversion_notes, write_foreign
from mitos_cli.interop.rules_writer import write_rules

ROOT = Path(__file__).parents[1]
DATA = ROOT / "tests" / "data" / "interop"


def corpus() -> list[Path]:
    from test_conformance import EXAMPLES, REFUSED

    files = sorted(DATA.glob("*.f*")) + [ROOT / "rulebases" / "mitos.rules"]
    if EXAMPLES is not None:
        files += [p for p in sorted(EXAMPLES.rglob("*.fll"))
                  if p.relative_to(EXAMPLES).as_posix() not in REFUSED]
    return files


CASES = [(path, fmt) for path in corpus() for fmt in ("fll", "fcl", "fis", "rules")]


def outputs(rb, X: np.ndarray, names: tuple[str, ...]):
    compiled = compile_rulebase(rb)
    cols = [names.index(name) for name in compiled.inputs]
    result = evaluate(compiled, X[:, cols], strict=False, detail=False)
    return compiled, result.outputs


def write_and_read(rb, fmt: str, tmp_path: Path):
    if fmt == "rules":
        rules, terms = write_rules(rb, "back.terms.yaml")
        (tmp_path / "back.terms.yaml").write_text(terms)
        path = tmp_path / "back.rules"
        path.write_text(rules)
    else:
        path = tmp_path / f"back.{fmt}"
        path.write_text(write_foreign(rb, fmt))
    return read_rulebase(path)


@pytest.mark.parametrize("path, fmt", CASES,
                         ids=[f"{p.parent.name}/{p.name}->{f}" for p, f in CASES])
def test_round_trip(path: Path, fmt: str, tmp_path: Path) -> None:
    rb = read_rulebase(path)
    original = compile_rulebase(rb)
    names = original.inputs
    rng = np.random.default_rng(np.random.SeedSequence(20261122).spawn(1)[0])
    lo, hi = original.universe[:, 0], original.universe[:, 1]
    X = rng.uniform(lo, hi, size=(200, len(names)))
    _, before = outputs(rb, X, names)
    try:
        back = write_and_read(rb, fmt, tmp_path)
    except FormatError as exc:           # the format cannot say something: named in words
        assert exc.message and ("has no" in exc.message or "cannot" in exc.message
                                or "no terms" in exc.message), exc.message
        return
    compiled, after = outputs(back, X, names)
    assert compiled.outputs == original.outputs
    notes = [] if fmt == "rules" else conversion_notes(rb, fmt)
    fired = ~np.isnan(before)
    if any("sampl" in n for n in notes):
        # MATLAB's 101 end-inclusive samples vs fuzzylite's midpoints: the centroid moves by
        # at most a few sample spacings (bound: 2% of the output range)
        span = np.array([compiled.variables[o].universe[1] - compiled.variables[o].universe[0]
                         for o in compiled.outputs])
        assert (np.abs(after - before)[fired] <= np.broadcast_to(0.02 * span, before.shape)[
            fired]).all()
        return
    np.testing.assert_allclose(after[fired], before[fired], rtol=0, atol=1e-9)
    if not any("no rule fires" in n for n in notes):
        assert (np.isnan(after) == np.isnan(before)).all()


def test_mitos_rules_through_fis_back_to_rules(tmp_path: Path) -> None:
    """.rules -> .fis -> .rules: the shoulders went out as `trapmf [-inf -inf c d]` and came
    back as a term set MITOS refused (`point must be a finite number, not -inf`)."""
    rb = read_rulebase(ROOT / "rulebases" / "mitos.rules")
    fis = write_foreign(rb, "fis")
    assert "inf" not in fis and "'NARROW':'trapmf',[-2 -1 40 70]" in fis   # feet outside
    (tmp_path / "m.fis").write_text(fis)
    via_fis = read_rulebase(tmp_path / "m.fis")
    back = write_and_read(via_fis, "rules", tmp_path)
    original = compile_rulebase(rb)
    names = original.inputs
    lo, hi = original.universe[:, 0], original.universe[:, 1]
    rng = np.random.default_rng(np.random.SeedSequence(4).spawn(1)[0])
    X = np.vstack([rng.uniform(lo, hi, size=(500, len(names))), lo, hi,
                   rng.uniform(lo - (hi - lo), hi + (hi - lo), size=(100, len(names)))])
    _, before = outputs(rb, X, names)
    _, after = outputs(back, X, names)
    fired = ~np.isnan(before)            # where no rule fires, .fis has MATLAB's mid-range
    np.testing.assert_array_equal(after[fired], before[fired])


CRISP_TERMS = """variables:
  temp: {role: input, universe: [0, 40], terms: {COLD: {shape: left_shoulder, points: [10, 20]},
         HOT: {shape: right_shoulder, points: [10, 20]}}}
  fan: {role: output, universe: [0, 3000], default: 0, terms: {HIGH: 3000}}
"""


@pytest.mark.parametrize("fmt", ["fcl", "fis", "fll", "rules"])
def test_a_crisp_consequent_converts_with_the_same_outputs(fmt: str, tmp_path: Path) -> None:
    """`then fan is 500` (language.md's `steering is 80`): every format refused it with
    "unknown term `crisp_500` of `fan`" and no position, looking up the term the writer made
    for it in the rule base rather than in the rules it writes."""
    (tmp_path / "t.terms.yaml").write_text(CRISP_TERMS)
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\n'
                                      "r1: if temp is COLD then fan is 500\n"
                                      "r2: if temp is HOT then fan is HIGH\n")
    rb = read_rulebase(tmp_path / "t.rules")
    back = write_and_read(rb, fmt, tmp_path)
    X = np.linspace(0.0, 40.0, 81)[:, None]
    np.testing.assert_allclose(outputs(back, X, ("temp",))[1], outputs(rb, X, ("temp",))[1],
                               rtol=0, atol=1e-9)


def _trapmfs(fis: str) -> list[list[float]]:
    import re

    return [[float(x) for x in m.split()] for m in re.findall(r"'trapmf',\[([^]]*)\]", fis)]


def _octave_takes_trapmf(p: list[float]) -> bool:
    """Octave's toolkit (0.4.6, `are_mf_params.m`) reads a trapmf with a < b <= c < d only."""
    return p[0] < p[1] <= p[2] < p[3]


def test_written_shoulders_have_feet_apart_as_octave_reads_them() -> None:
    """The packaged rule base's shoulders went into .fis as `trapmf [-1 -1 40 70]`, which
    Octave's `readfis` takes and its `evalfis` stops on ("trapmf's second argument must be a
    parameter vector": it wants a < b <= c < d). With `[-2 -1 40 70]` Octave gives the paper's
    65.411255411 / 32.424242424 at road=78, size=45, position=4, as MITOS does."""
    fis = write_foreign(read_rulebase(ROOT / "rulebases" / "mitos.rules"), "fis")
    shapes = _trapmfs(fis)
    assert len(shapes) == 6 and all(_octave_takes_trapmf(p) for p in shapes), shapes


RAMPS_FLL = """\
Engine: ramps
InputVariable: obstacle
  range: 0 1
  term: left Ramp 1 0
  term: right Ramp 0.2 1
OutputVariable: steer
  range: 0 1
  aggregation: Maximum
  defuzzifier: Centroid 100
  default: nan
  term: left Ramp 1 0
  term: right Ramp 0 0.8
RuleBlock: b
  conjunction: none
  disjunction: none
  implication: Minimum
  rule: if obstacle is left then steer is right
  rule: if obstacle is right then steer is left
"""


def test_ramps_are_written_to_fis_as_trapezoids_that_every_reader_takes(tmp_path: Path):
    """fuzzylite's `Ramp` went into .fis as `linsmf` / `linzmf`, MF types MATLAB has only
    since R2022a and which fuzzylite 6 ("constructor of Term <linzmf> not registered") and
    Octave's toolkit do not read: `mitos convert ObstacleAvoidance.fll --to fis` wrote a file
    that fuzzylite, which shipped the engine, could not load. They are written as `trapmf`
    with the flat end's feet 1 and 2 outside the range, as shoulders are: the same numbers."""
    (tmp_path / "r.fll").write_text(RAMPS_FLL)
    rb = read_rulebase(tmp_path / "r.fll")
    text = write_foreign(rb, "fis")
    assert "linsmf" not in text and "linzmf" not in text
    assert "MF1='left':'trapmf',[-2 -1 0 1]" in text
    assert "MF2='right':'trapmf',[0.2 1 2 3]" in text
    assert "MF2='right':'trapmf',[0 0.8 2 3]" in text
    assert all(_octave_takes_trapmf(p) for p in _trapmfs(text))
    back = write_and_read(rb, "fis", tmp_path)
    X = np.linspace(0.0, 1.0, 1001)[:, None]
    for name in ("obstacle", "steer"):
        for term in rb.variables[name].terms:
            np.testing.assert_array_equal(
                back.variables[name].term(term.name).membership(X[:, 0]),
                term.membership(X[:, 0]))


def test_fis_reader_takes_infinite_feet_as_shoulders(tmp_path: Path) -> None:
    """A .fis written with `trapmf [-inf -inf c d]` (MITOS before it wrote finite feet) reads
    as the shoulder, as FLL's `Trapezoid -inf -inf c d` does, so it converts to a term set."""
    text = write_foreign(read_rulebase(ROOT / "rulebases" / "mitos.rules"), "fis")
    text = text.replace("[-2 -1 40 70]", "[-inf -inf 40 70]").replace(
        "[70 100 161 162]", "[70 100 inf inf]")
    (tmp_path / "old.fis").write_text(text)
    road = read_rulebase(tmp_path / "old.fis").variables["road"]
    assert road.term("NARROW").shape == "left_shoulder" and \
        road.term("NARROW").params == (40.0, 70.0)
    assert road.term("WIDE").shape == "right_shoulder"
    back = write_and_read(read_rulebase(tmp_path / "old.fis"), "rules", tmp_path)
    assert back.variables["road"].term("NARROW").shape == "left_shoulder"


def test_rules_writer_keeps_operators_and_defaults(tmp_path: Path) -> None:
    rb = read_rulebase(DATA / "tipper_jfuzzylogic.fcl")
    rules, terms = write_rules(rb, "tipper.terms.yaml")
    assert 'terms "tipper.terms.yaml"' in rules
    assert "operators: inference = mamdani, resolution = 1000" in rules
    assert "r4: if not (service is poor or food is rancid) and service is not excellent " \
           "then tip is average" in rules
    assert "default: 0" in terms and "rancid: {shape: trapezoid, points: [-inf" not in terms


def test_fll_writer_text_reads_in_pyfuzzylite(tmp_path: Path) -> None:
    """What the FLL writer writes is FLL to fuzzylite too, and computes the same outputs."""
    fl = pytest.importorskip("fuzzylite", reason="pyfuzzylite is not installed")
    rb = read_rulebase(DATA / "dimmer_fuzzylite.fcl")
    engine = fl.FllImporter().from_string(write_foreign(rb, "fll"))
    X = np.linspace(0.0, 1.0, 201)
    engine.input_variables[0].value = X
    engine.process()
    theirs = np.asarray(engine.output_variables[0].value, dtype=float)
    _, ours = outputs(rb, X[:, None], ("Ambient",))
    np.testing.assert_allclose(ours[:, 0], theirs, rtol=0, atol=1e-9, equal_nan=True)


@pytest.mark.parametrize("dialect", ["fuzzylite", "iec"])
def test_fcl_keeps_the_rule_labels_it_can_number(dialect: str, tmp_path: Path) -> None:
    """The packaged rule base counts its rules from r0; FCL wrote them `RULE 1`, `RULE 2`, ...,
    so read back its r4 was r5 and `mitos eval` of the FCL named other rules than the rule
    file's for the same DOFs. A label `rN` is written `RULE N` and reads back as itself; labels
    of another form (or repeated numbers) are numbered by position, as before."""
    from mitos_cli.interop.fcl import write_fcl

    rb = read_rulebase(ROOT / "rulebases" / "mitos.rules")
    (tmp_path / "m.fcl").write_text(write_fcl(rb, "avoid_obstacle", dialect))
    back = read_rulebase(tmp_path / "m.fcl")
    labels = [r.label for r in rb.behavior("avoid_obstacle").rules]
    assert labels[:2] == ["r0", "r1"]
    assert [r.label for r in back.behavior(back.default_behavior).rules] == labels
    text = write_fcl(rb, "cruise", dialect)                      # c1, c2, ...: by position
    assert "RULE 1 : " in text and "RULE c1" not in text
