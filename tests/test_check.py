"""``mitos check``: each kind of finding on a small rule base made to have it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from mitos_cli.api import read_rulebase
from mitos_cli.cli.app import main
from mitos_cli.engine.check import boxes_of, canonical, check_rulebase, grid_axes
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.lang.parse import parse_expr

TERMS = """variables:
  road:
    role: input
    universe: [0, 160]
    terms:
      NARROW: {shape: left_shoulder, points: [40, 60]}
      MEDIUM: {shape: triangle, peak: 70, width: 20}
      WIDE:   {shape: right_shoulder, points: [80, 100]}
      HUGE:   {shape: right_shoulder, points: [140, 150]}
  size:
    role: input
    universe: [0, 100]
    terms:
      SMALL: {shape: left_shoulder, points: [10, 40]}
      LARGE: {shape: right_shoulder, points: [40, 70]}
  steering:
    role: output
    universe: [30, 150]
    terms: {LS: 70, ST: 90, RS: 110}
  speed:
    role: output
    universe: [0, 60]
    default: 0
    terms: {SLOW: 20, FAST: 50}
"""

RULES = """terms "t.terms.yaml"
r1: if road is NARROW and size is SMALL then steering is LS and speed is SLOW
r2: if size is SMALL and road is NARROW then steering is RS and speed is SLOW
r3: if road is MEDIUM then steering is ST and speed is FAST
r4: if road is MEDIUM then steering is ST and speed is FAST
r5: if road is NARROW and road is WIDE then steering is 95
r6: if road is WIDE and not road is WIDE then steering is 95
r7: if road is WIDE and size is LARGE then steering is 80
"""


@pytest.fixture()
def flawed(tmp_path) -> Path:
    (tmp_path / "t.terms.yaml").write_text(TERMS, encoding="utf-8")
    path = tmp_path / "t.rules"
    path.write_text(RULES, encoding="utf-8")
    return path


def by_code(report, code):
    return [f for f in report.findings if f.code == code]


def test_packaged_rule_base_passes():
    rb = read_rulebase()
    report = check_rulebase(rb)
    assert report.ok, [f.message for f in report.findings if f.severity == "error"]
    assert {g.behavior for g in report.grids} == {b.name for b in rb.behaviors}
    # the paper's 27 rules cover the whole input space with a total DOF of at least 1
    paper = check_rulebase(rb, "avoid_obstacle", threshold=0.999)
    assert [f for f in paper.findings if f.behavior == "avoid_obstacle"] == []
    grid = paper.grids[0]
    assert grid.samples == np.prod([n for _, n in grid.points]) > 50_000


def test_flawed_rule_base_findings(flawed):
    report = check_rulebase(read_rulebase(flawed))
    assert not report.ok
    codes = sorted((f.severity, f.code) for f in report.findings)
    assert codes == sorted([
        ("error", "no-rule-fires"), ("warning", "no-rule-fires"), ("warning", "low-dof"),
        ("error", "conflict"), ("warning", "duplicate"), ("warning", "unreachable"),
        ("warning", "contradiction"), ("warning", "unused-term"), ("warning", "term-gap"),
        ("warning", "coverage"),      # road: NARROW and MEDIUM cross at 0.25 (road = 55)
        ("warning", "coverage")])     # size: below 0.5 on [25, 55], around its gap at 40
    assert report.findings[0].severity == "error"            # errors come first


def test_coverage_gap_without_default_is_an_error(flawed):
    report = check_rulebase(read_rulebase(flawed))
    gap = [f for f in by_code(report, "no-rule-fires") if f.severity == "error"][0]
    assert "no rule sets `steering`" in gap.message
    assert "default: VALUE" in gap.hint
    regions = [b.describe() for b in gap.regions]
    # NARROW/SMALL rules need size < 40, r7 needs WIDE; r3 covers the MEDIUM road
    assert regions == ["road in [0, 50] and size in [40, 100]",
                       "road in [100, 160] and size in [0, 40]"]
    assert gap.span.line == 2 and gap.span.path == str(flawed)     # the first rule
    assert gap.share == pytest.approx(50 / 160 * 0.6 + 60 / 160 * 0.4)


STEPS = """\
variables:
  x:
    role: input
    universe: [0, 4]
    terms:
      LOW: {shape: rectangle, points: [0, 2]}
      TRI: {shape: triangle, points: [2, 3, 4]}
      MID: {shape: rectangle, points: [1, 3]}
  z:
    role: input
    universe: [0, 10]
    terms:
      LEFT: {shape: rectangle, points: [0, 5]}
      RAMP: {shape: triangle, points: [5, 7.5, 10]}
  y:
    role: output
    universe: [0, 1]
    terms:
      A: {shape: triangle, points: [0, 0.5, 1]}
"""


@pytest.mark.parametrize("condition, boxes", [
    ("x is LOW", ["x in (2, 4]"]),                      # a crisp step down at 2
    ("not x is LOW", ["x in [0, 2]"]),
    ("x is MID", ["x in [0, 1)", "x in (3, 4]"]),
    ("x is TRI", ["x in [0, 2]", "x = 4"]),             # a foot, not a step: 0 at 2 itself
    ("x is LOW and z is LEFT", ["z in (5, 10]", "x in (2, 4]"]),
    ("x is MID and z is RAMP", ["z in [0, 5]", "x in [0, 1)", "x in (3, 4]", "z = 10"]),
    ("x is LOW or z is LEFT", ["x in (2, 4] and z in (5, 10]"]),
])
def test_a_regions_end_at_a_crisp_step_is_the_step(tmp_path, condition, boxes):
    """A `no-rule-fires` box was read from the samples alone, so beside a crisp step it
    stopped one sample short: `x in [0, 1.75]` for [0, 2). An end whose next cell is unset
    all through now runs on to the step, left out (an open end)."""
    (tmp_path / "t.terms.yaml").write_text(STEPS)
    (tmp_path / "t.rules").write_text(f'terms "t.terms.yaml"\nbehavior b:\n  r1: if '
                                      f"{condition} then y is A\nend\n")
    report = check_rulebase(read_rulebase(tmp_path / "t.rules"))
    (gap,) = by_code(report, "no-rule-fires")
    assert [b.describe() for b in gap.regions] == boxes


def test_coverage_gap_with_default_is_a_warning(flawed):
    report = check_rulebase(read_rulebase(flawed))
    gap = [f for f in by_code(report, "no-rule-fires") if f.severity == "warning"][0]
    assert "no rule sets `speed`" in gap.message and "speed = 0" in gap.message
    assert [b.describe() for b in gap.regions] == ["road in [90, 160]",
                                                  "road in [0, 50] and size in [40, 100]"]



@pytest.mark.parametrize("points, where, share", [
    ("[2, 4]", "in 20% of the input space", 0.2),        # x in [4, 6]: 9 of the 41 samples
    ("[2, 5]", "on lines or points of the input space (none of its volume)", 0.0)])   # x = 5


def test_no_rule_fires_gives_the_share_of_the_input_space(tmp_path, points, where, share):
    """It gave the share of the samples (22%, 9 of 41, for a gap of 20%), which the terms'
    corner points crowd; it is the share of the volume now, exact where the grid holds them."""
    high = "[6, 8]" if points == "[2, 4]" else "[5, 8]"
    (tmp_path / "e.terms.yaml").write_text(
        "variables:\n  x: {role: input, universe: [0, 10], terms: {LO: {shape: left_shoulder, "
        f"points: {points}}}, HI: {{shape: right_shoulder, points: {high}}}}}}}\n"
        "  y: {role: output, universe: [0, 100], default: 50, terms: {A: 0, B: 100}}\n",
        encoding="utf-8")
    (tmp_path / "e.rules").write_text('terms "e.terms.yaml"\nr1: if x is LO then y is A\n'
                                      "r2: if x is HI then y is B\n", encoding="utf-8")
    (gap,) = by_code(check_rulebase(read_rulebase(tmp_path / "e.rules")), "no-rule-fires")
    assert gap.message.startswith(f"behavior `main`: no rule sets `y` {where} (the default")
    assert gap.share == pytest.approx(share, abs=1e-12)


def test_coverage_gap_with_weighted_sum_is_a_warning(tmp_path):
    (tmp_path / "t.terms.yaml").write_text(TERMS, encoding="utf-8")
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\noperators: inference = '
                                      "weighted_sum\nif road is WIDE then steering is RS\n",
                                      encoding="utf-8")
    report = check_rulebase(read_rulebase(tmp_path / "t.rules"))
    (gap,) = by_code(report, "no-rule-fires")
    assert report.ok and gap.severity == "warning" and "weighted sum is 0" in gap.message


def test_coverage_gap_with_weighted_sum_and_a_default_says_the_default_applies(tmp_path):
    """Under weighted_sum an output's declared default applies where none of its rules fires
    (`mitos eval` gives it); the finding said the sum was 0 there."""
    (tmp_path / "t.terms.yaml").write_text(TERMS, encoding="utf-8")
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\noperators: inference = '
                                      "weighted_sum\nif road is WIDE then speed is FAST\n",
                                      encoding="utf-8")
    (gap,) = by_code(check_rulebase(read_rulebase(tmp_path / "t.rules")), "no-rule-fires")
    assert gap.severity == "warning" and "(the default applies there: speed = 0)" in gap.message


def test_low_total_dof(flawed):
    low = by_code(check_rulebase(read_rulebase(flawed)), "low-dof")[0]
    # r7 alone: LARGE(42.5) = 0.083 < 0.1 on the wide road
    assert [b.describe() for b in low.regions] == ["road in [100, 160] and size = 42.5"]
    assert by_code(check_rulebase(read_rulebase(flawed), threshold=0.0), "low-dof") == []


def test_conflict_and_duplicate(flawed):
    report = check_rulebase(read_rulebase(flawed))
    conflict = by_code(report, "conflict")[0]
    assert conflict.message == ("`r2` has the same antecedent as `r1` but concludes "
                                "differently: steering is LS vs steering is RS")
    assert conflict.span.line == 3
    dup = by_code(report, "duplicate")[0]
    assert dup.message.startswith("`r4` has the same antecedent as `r3` and the same")
    assert dup.span.line == 5


def test_unreachable_and_contradiction(flawed):
    report = check_rulebase(read_rulebase(flawed))
    unreachable = by_code(report, "unreachable")
    assert [f.span.line for f in unreachable] == [6]          # NARROW and WIDE never overlap
    assert "`r5` never fires" in unreachable[0].message
    contradiction = by_code(report, "contradiction")[0]
    assert "`road is WIDE` and `road is not WIDE`" in contradiction.message
    assert (contradiction.span.line, contradiction.span.column) == (7, 29)


def test_unused_terms_and_gaps(flawed):
    report = check_rulebase(read_rulebase(flawed))
    unused = by_code(report, "unused-term")[0]
    assert unused.message == "input term `road.HUGE` is used by no rule"
    assert unused.span.path.endswith("t.terms.yaml") and unused.span.line == 9
    gap = by_code(report, "term-gap")[0]
    assert gap.message == "input `size`: every term is 0 at size = 40"
    # steering's terms LS, ST, RS are all concluded... but only LS, RS by r1/r2 and ST by r3
    assert by_code(report, "unconcluded-term") == []


def test_the_unconcluded_terms_named_are_capped(tmp_path):
    """A fuzzed FLL output of 20,000 terms, one concluded: the note named the other 19,999 on
    one line (220 KB). It names the first ten and counts the others."""
    values = ", ".join(f"V{i}: {i}" for i in range(25))
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  x: {role: input, universe: [0, 1], terms: {LO: {shape: left_shoulder, "
        "points: [0, 1]}, HI: {shape: right_shoulder, points: [0, 1]}}}\n"
        f"  y: {{role: output, universe: [0, 24], terms: {{{values}}}}}\n", encoding="utf-8")
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\nbehavior b:\n'
                                      "  if x is LO then y is V0\n  if x is HI then y is V24\n"
                                      "end\n", encoding="utf-8")
    (note,) = by_code(check_rulebase(read_rulebase(tmp_path / "t.rules")), "unconcluded-term")
    assert note.message == ("output `y`: no rule concludes V1, V2, V3, V4, V5, V6, V7, V8, V9, "
                            "V10 and 13 more")


def test_term_gap_over_a_range(tmp_path):
    terms = TERMS.replace("[10, 40]", "[10, 20]").replace("[40, 70]", "[50, 70]")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text(RULES, encoding="utf-8")
    gaps = by_code(check_rulebase(read_rulebase(tmp_path / "t.rules")), "term-gap")
    assert [g.message for g in gaps] == ["input `size`: every term is 0 for size in [20, 50]"]


@pytest.mark.parametrize(("small", "large", "says"), [
    # a gap that ends at a crisp step ran one sample short of it: [20, 30] for [20, 30.01)
    ("{shape: left_shoulder, points: [10, 20]}", "{shape: rectangle, points: [30.01, 100]}",
     "for size in [20, 30.01)"),
    ("{shape: rectangle, points: [0, 20.01]}", "{shape: right_shoulder, points: [30, 40]}",
     "for size in (20.01, 30]"),
    # two steps with no sample between them: a gap that was not reported at all
    ("{shape: rectangle, points: [0, 20.01]}", "{shape: rectangle, points: [20.02, 100]}",
     "for size in (20.01, 20.02)"),
    ("{shape: rectangle, points: [0, 20]}", "{shape: rectangle, points: [20, 100]}", None),
])
def test_a_term_gap_beside_a_crisp_step_ends_at_the_step(tmp_path, capsys, small, large, says):
    terms = TERMS.replace("{shape: left_shoulder, points: [10, 40]}", small).replace(
        "{shape: right_shoulder, points: [40, 70]}", large)
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text(RULES, encoding="utf-8")
    gaps = by_code(check_rulebase(read_rulebase(tmp_path / "t.rules")), "term-gap")
    assert [g.message for g in gaps if "size" in g.message] == (
        [f"input `size`: every term is 0 {says}"] if says else [])
    _, out, _ = run(["check", str(tmp_path / "t.rules")], capsys)
    assert (f"warning: input `size`: every term is 0 {says} [term-gap]" in out) if says else \
        "input `size`: every term is 0" not in out


def test_term_peaking_outside_the_universe(tmp_path):
    terms = TERMS.replace("HUGE:   {shape: right_shoulder, points: [140, 150]}",
                          "HUGE:   {shape: gaussian, mean: 180, sigma: 10}")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text(RULES, encoding="utf-8")
    (finding,) = by_code(check_rulebase(read_rulebase(tmp_path / "t.rules")), "term-outside")
    assert finding.message == ("input term `road.HUGE` never reaches 1 inside the universe "
                               "[0, 160] (at most 0.135)")
    assert finding.span.line == 9 and finding.severity == "warning"


@pytest.mark.parametrize("shape", ["sigmoid, inflection: 120, slope: 0.5",
                                   "sigmoid_product, left: 110, rising: 1, falling: 1, "
                                   "right: 150"])


def test_a_sigmoid_shoulder_is_not_a_term_outside_the_universe(tmp_path, shape):
    """A sigmoid comes within 1e-4 of 1 at the universe's end but never reaches it: check said
    "never reaches 1 inside the universe (at most 1)" and told the user to move its peak in."""
    terms = TERMS.replace("HUGE:   {shape: right_shoulder, points: [140, 150]}",
                          f"HUGE:   {{shape: {shape}}}")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text(RULES, encoding="utf-8")
    assert by_code(check_rulebase(read_rulebase(tmp_path / "t.rules")), "term-outside") == []


def test_one_behavior_only(tmp_path):
    (tmp_path / "t.terms.yaml").write_text(TERMS, encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\n'
        "behavior full:\n  if road is NARROW or road is MEDIUM or road is WIDE "
        "then steering is ST and speed is SLOW\nend\n"
        "behavior part:\n  if road is WIDE then steering is LS\nend\n", encoding="utf-8")
    rb = read_rulebase(tmp_path / "t.rules")
    assert check_rulebase(rb, "full").ok
    report = check_rulebase(rb)
    assert not report.ok and {f.behavior for f in by_code(report, "no-rule-fires")} == {"part"}


def test_used_rules_are_judged_in_their_own_behavior(tmp_path):
    (tmp_path / "t.terms.yaml").write_text(TERMS, encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\n'
        "behavior wide:\n  w1: if road is WIDE then steering is RS\nend\n"
        "behavior narrow:\n  n1: if road is NARROW then steering is LS\n"
        "  use wide when road is NARROW\nend\n", encoding="utf-8")
    report = check_rulebase(read_rulebase(tmp_path / "t.rules"), "narrow")
    # `wide/w1` never fires inside `narrow` (NARROW and WIDE never overlap): not a rule defect
    assert by_code(report, "unreachable") == []


def test_takagi_sugeno_duplicates_are_not_conflicts(tmp_path):
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  x:\n    role: input\n    universe: [0, 10]\n    terms:\n"
        "      LO: {shape: left_shoulder, points: [2, 8]}\n"
        "      HI: {shape: right_shoulder, points: [2, 8]}\n"
        "  y:\n    role: output\n    universe: [0, 100]\n    terms:\n"
        "      L: {shape: linear, coefficients: {x: 2}, constant: 1}\n"
        "      M: {shape: linear, coefficients: {x: 3}, constant: 1}\n"
        "      C: 5\n      D: 5\n", encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\nr1: if x is LO then y is L\nr2: if x is LO then y is L\n'
        "r3: if x is HI then y is C\nr4: if x is HI then y is D\n"
        "r5: if x is not LO then y is M\nr6: if not x is LO then y is L\n", encoding="utf-8")
    report = check_rulebase(read_rulebase(tmp_path / "t.rules"))
    assert [(f.code, f.span.line) for f in report.findings
            if f.code in ("duplicate", "conflict")] == [("conflict", 7), ("duplicate", 3),
                                                       ("duplicate", 5)]


def test_canonical_antecedents():
    same = [("road is A and size is B", "size is B and road is A"),
            ("not road is A", "road is not A"),
            ("road is A and (size is B and pos is C)", "pos is C and size is B and road is A"),
            ("road is A or road is A", "road is A")]
    for a, b in same:
        assert canonical(parse_expr(a)) == canonical(parse_expr(b)), (a, b)
    assert canonical(parse_expr("road is A and size is B")) != \
        canonical(parse_expr("road is A or size is B"))


def test_boxes_of_a_mask():
    axes = [np.arange(5.0), np.arange(4.0) * 10]
    mask = np.zeros((5, 4), bool)
    mask[0:2, :] = True              # x in [0, 1], any y
    mask[3:5, 1:3] = True            # x in [3, 4], y in [10, 20]
    boxes, left = boxes_of(mask, axes, ("x", "y"))
    assert left == 0
    assert [b.describe() for b in boxes] == ["x in [0, 1]", "x in [3, 4] and y in [10, 20]"]
    everything, _ = boxes_of(np.ones((5, 4), bool), axes, ("x", "y"))
    assert [b.describe() for b in everything] == ["everywhere"]


def test_grid_includes_corners_and_stays_capped():
    compiled = compile_rulebase(read_rulebase())
    axes = grid_axes(compiled, 41)
    road = axes[compiled.inputs.index("road")]
    assert {40.0, 70.0, 100.0} <= set(road) and road[0] == 0 and road[-1] == 160
    small = grid_axes(compiled, 10_000, max_samples=1000)
    assert 500 < np.prod([len(a) for a in small]) <= 1000
    tiny = grid_axes(compiled, 41, max_samples=30)        # fewer than the corners alone
    assert np.prod([len(a) for a in tiny]) <= 30
    assert all(a[0] == u[0] and a[-1] == u[1] for a, u in zip(tiny, compiled.universe))



def _ruspini(tmp_path, rules: str, inputs: int = 6, default: str = "    default: 50\n"):
    """``inputs`` inputs of 9 triangles each on [0, 80], peaks every 10 (a Ruspini
    partition): their corner points alone (9 ** 6) are more than the grid holds."""
    v = "".join(f"  x{i}:\n    role: input\n    universe: [0, 80]\n    terms:\n" + "".join(
        f"      T{k}: {{shape: triangle, peak: {10 * k}, width: 10}}\n" for k in range(9))
        for i in range(inputs))
    (tmp_path / "ru.terms.yaml").write_text(
        "variables:\n" + v + "  y:\n    role: output\n    universe: [0, 100]\n" + default
        + "    terms: {A: 0, B: 100}\n", encoding="utf-8")
    (tmp_path / "ru.rules").write_text('terms "ru.terms.yaml"\n' + rules, encoding="utf-8")
    return read_rulebase(tmp_path / "ru.rules")


def test_a_rule_firing_only_where_the_thinned_grid_skipped_is_not_unreachable(tmp_path):
    """Six inputs of 9 terms: the grid kept 8 points per input, not 40, and `check` said the
    rules on T4 "never fire ... conditions cannot hold together" (they fire at DOF 1). A rule
    is now judged on a grid of its own inputs, every corner point and between them; only a
    rule whose own inputs are too many for that is a note, saying what was skipped."""
    rules = "".join(f"r{i}_{k}: if x{i} is T{k} then y is {'AB'[k % 2]}\n"
                    for i in range(6) for k in range(9))
    rules += "all4: if " + " and ".join(f"x{i} is T4" for i in range(6)) + " then y is A\n"
    rules += "never: if x0 is T1 and x0 is T3 then y is B\n"
    report = check_rulebase(_ruspini(tmp_path, rules))
    (grid,) = report.grids
    assert grid.skipped == tuple(f"x{i}" for i in range(6))
    found = {f.message.split("`")[1]: f for f in by_code(report, "unreachable")}
    assert set(found) == {"all4", "never"}
    assert found["never"].severity == "warning" and found["never"].message.startswith(
        "`never` never fires: its DOF is 0 at all ")
    assert "every corner point of its terms and between them" in found["never"].message
    assert found["all4"].severity == "info"
    assert "a grid that skipped corner points of `x0`, `x1`, `x2`, `x3` and 2 more: it may " \
        "fire between them" in found["all4"].message


def test_a_thinned_grid_says_so(tmp_path, capsys):
    """`no-rule-fires` on a grid that skipped corner points may miss places, and says so;
    the summary and the JSON name the inputs."""
    rules = "".join(f"r{k}: if x0 is T{k} then y is {'AB'[k % 2]}\n" for k in range(9)
                    if k not in (4, 5))             # x0 in (30, 60) in no rule of x0 ...
    rules += "".join(f"s{i}: if x{i} is T0 then y is A\n" for i in range(1, 6))     # ... nor above 10 here
    report = check_rulebase(_ruspini(tmp_path, rules, default=""))
    (gap,) = by_code(report, "no-rule-fires")
    assert gap.message.endswith("(on a grid that skipped corner points of `x0`, `x1`, `x2`, "
                                "`x3` and 2 more: there may be more)")
    code, out, _ = run(["check", str(tmp_path / "ru.rules")], capsys)
    assert code == 1 and "\nnote: `main`'s grid skipped corner points of `x0`, `x1`, `x2`, " \
        "`x3` and 2 more (all of them would take 5.31e+05 samples" in out
    code, out, _ = run(["check", str(tmp_path / "ru.rules"), "--json"], capsys)
    assert json.loads(out)["behaviors"][0]["skipped_corners"] == [f"x{i}" for i in range(6)]
    assert not check_rulebase(read_rulebase()).grids[0].skipped      # avoid_obstacle


# ---------------------------------------------------------------------------------------------
# the command


def run(args, capsys):
    with pytest.raises(SystemExit) as info:
        main(args)
    out, err = capsys.readouterr()
    return info.value.code, out, err


def test_cli_exit_codes(flawed, capsys):
    code, out, _ = run(["check", str(flawed)], capsys)
    assert code == 1
    assert f"{flawed}:3:1: error: `r2` has the same antecedent as `r1`" in out
    assert out.rstrip().endswith("2 errors, 9 warnings, 0 notes")   # 9: road, size coverage
    code, out, _ = run(["check"], capsys)
    assert code == 0 and out.rstrip().endswith(" - OK") and "0 errors" in out


def test_cli_json_matches_the_library(flawed, capsys):
    code, out, _ = run(["check", str(flawed), "--json", "--threshold", "0.05"], capsys)
    data = json.loads(out)
    report = check_rulebase(read_rulebase(flawed), threshold=0.05)
    assert code == 1 and data["ok"] is False and data["threshold"] == 0.05
    assert data["findings"] == [f.to_json() for f in report.findings]
    assert data["summary"] == {"error": 2, "warning": 8, "info": 0}   # 8: with coverage
    gap = data["findings"][0]
    assert gap["code"] == "no-rule-fires" and gap["regions"][0] == {"road": [0.0, 50.0],
                                                                    "size": [40.0, 100.0]}


def test_cli_behavior_and_resolution(flawed, capsys):
    code, out, _ = run(["check", str(flawed), "-b", "main", "--resolution", "5"], capsys)
    assert code == 1 and "`main` on 12 road x 8 size = 96 samples" in out


def test_help_reads_as_paragraphs(capsys):
    """The command list shows one sentence; the help joins the docstring's lines (Typer's rich
    help would keep the source's line breaks: "unused" alone at the end of a line)."""
    code, out, _ = run(["--help"], capsys)
    listing = " ".join(out.replace("│", " ").split())
    assert "check Check a rule base: coverage gaps, conflicts, duplicates, dead rules, " \
           "unused terms. teach" in listing
    code, out, _ = run(["check", "--help"], capsys)
    lines = [line.strip() for line in out.splitlines()]
    assert "terms and gaps between terms. Exits 1 on an error: inputs where no rule sets an" \
        not in lines
    assert "Exits 1 on an error: inputs where no rule sets an output that has no default," \
        in " ".join(lines)


def test_settings_only_mamdani_reads_are_flagged(tmp_path):
    (tmp_path / "t.terms.yaml").write_text(TERMS, encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\noperators: defuzzify = lom, and = product\n'
        "if road is NARROW or road is MEDIUM or road is WIDE "
        "then steering is ST and speed is SLOW\n", encoding="utf-8")
    (finding,) = by_code(check_rulebase(read_rulebase(tmp_path / "t.rules")), "idle-setting")
    assert finding.severity == "warning" and finding.span.line == 2
    assert finding.message == ("`defuzzify = lom` has no effect: behavior `main` uses "
                               "weighted_average inference")


SIGMOID = """\
variables:
  x: {role: input, universe: [0, 10], terms: {A: {shape: triangle, points: [0, 0, 10]}, B: {shape: triangle, points: [0, 10, 10]}}}
  y: {role: output, universe: [0, 1], default: 0, terms: {S: {shape: sigmoid, points: [0.5, 10]}, DN: {shape: ramp, points: [1, 0]}}}
"""


def test_a_tsukamoto_sigmoid_is_warned_of_when_read_and_checked(tmp_path, capsys):
    """A sigmoid reaches 1 only at infinity: `y = inf` at x=0, which the FLL reader warned of
    and the rule language, `eval` and `check` did not."""
    (tmp_path / "ts.terms.yaml").write_text(SIGMOID, encoding="utf-8")
    path = tmp_path / "ts.rules"
    path.write_text('terms "ts.terms.yaml"\noperators: inference = tsukamoto\n'
                    "r1: if x is A then y is S\nr2: if x is B then y is DN\n", encoding="utf-8")
    rb = read_rulebase(path)
    (note,) = rb.notes
    assert note.startswith(f"{path}:3:20: `y is S` inverts a sigmoid (Tsukamoto inference)")
    (finding,) = by_code(check_rulebase(rb), "infinite-output")
    assert finding.severity == "warning" and (finding.span.line, finding.span.column) == (3, 59)
    assert "where rule `r1` fires fully `y` is +-inf" in finding.message
    code, out, err = run(["check", str(path)], capsys)
    assert code == 0 and "[infinite-output]" in out and "1 warning" in out
    assert "inverts a sigmoid" in err
    code, out, err = run(["eval", str(path), "x=0"], capsys)
    assert code == 0 and "y = inf" in out and "a sigmoid reaches 1 only at infinity" in err
    path.write_text(path.read_text().replace("tsukamoto", "mamdani"))
    assert read_rulebase(path).notes == ()


def test_the_coverage_check_reads_the_rules_dofs_only(tmp_path, monkeypatch):
    """A Mamdani output sampled on 100,000 points makes each inferred sample cost 100,000
    times a DOF; the check needs only the DOFs (it took minutes on the packaged rule base),
    and they are the bits ``evaluate`` gives."""
    from mitos_cli.engine import evaluation, mamdani
    (tmp_path / "t.terms.yaml").write_text(
        TERMS.replace("terms: {LS: 70, ST: 90, RS: 110}", "terms:\n"
                      "      LS: {shape: triangle, peak: 70, width: 20}\n"
                      "      ST: {shape: triangle, peak: 90, width: 20}\n"
                      "      RS: {shape: triangle, peak: 110, width: 20}"), encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\noperators: inference = mamdani, resolution = 100000\n'
        "if road is NARROW then steering is LS\nif road is WIDE or size is LARGE "
        "then steering is RS\n", encoding="utf-8")
    rb = read_rulebase(tmp_path / "t.rules")
    compiled = compile_rulebase(rb, "main")
    X = np.stack([m.ravel() for m in np.meshgrid(*grid_axes(compiled, 9), indexing="ij")],
                 axis=1)
    dof = evaluation.evaluate(compiled, X, detail=True, strict=False).dof
    assert np.array_equal(evaluation.rule_dofs(compiled, X), dof)

    def inferred(*args, **kwargs):
        raise AssertionError("the check inferred an output")
    monkeypatch.setattr(mamdani, "mamdani_outputs", inferred)
    monkeypatch.setattr(evaluation, "infer", inferred)
    report = check_rulebase(rb)
    assert report.grids[0].samples > 1000 and by_code(report, "no-rule-fires")


@pytest.mark.parametrize("name", ["check_termless_input.fll", "check_formula_output.fll",
                                  "check_formula_input.fll"])


def test_files_eval_reads_are_checked_too(name, capsys):
    # found in fuzzylite's examples: an input with no terms (a ValueError from the term
    # gaps), a formula term on an output (StopIteration in the term order) or on an input
    # (its NaN centre became a sample: "input `u` is not a number")
    path = Path(__file__).parent / "data" / "interop" / name
    code, out, err = run(["check", str(path)], capsys)
    assert code == 0 and out.rstrip().endswith(" - OK") and not err


TIPPER_FIS = Path(__file__).parent / "data" / "interop" / "tipper.fis"


@pytest.mark.parametrize("cheap", ["[4.9 5 5.1]", "[5 5 5]"])
def test_an_output_term_between_the_sample_points_is_reported(tmp_path, capsys, cheap):
    """On MATLAB's 101 points of [0, 30] (every 0.3) a triangle 0.2 wide is 0 everywhere."""
    fis = tmp_path / "f.fis"
    fis.write_text(TIPPER_FIS.read_text().replace("[0 5 10]", cheap), encoding="utf-8")
    (finding,) = by_code(check_rulebase(read_rulebase(fis)), "undersampled-term")
    assert finding.message == ("term `cheap` of output `tip` falls between the 101 points its "
                               "output is sampled at (every 0.3): its rules do not change `tip`")
    assert finding.severity == "warning" and finding.span.line == 33
    assert "--fidelity fuzzylite" in finding.hint
    with pytest.raises(SystemExit) as exit_:
        main(["check", str(fis)])
    assert exit_.value.code == 0                # a warning
    assert "[undersampled-term]" in capsys.readouterr().out



def test_an_output_term_outside_its_range_is_not_called_undersampled(tmp_path, capsys):
    """`trimf [40 45 50]` on [0, 30] was "undersampled", with the advice to raise the
    resolution, which no resolution answers; so was a formula that is 0 all over the range."""
    fis = tmp_path / "f.fis"
    fis.write_text(TIPPER_FIS.read_text().replace("[0 5 10]", "[40 45 50]"), encoding="utf-8")
    report = check_rulebase(read_rulebase(fis))
    assert not by_code(report, "undersampled-term")
    (finding,) = by_code(report, "term-outside")
    assert finding.message == ("term `cheap` of output `tip` lies outside its range [0, 30]: "
                               "its rules do not change `tip`")
    assert finding.span.line == 33 and "widen the output's range" in finding.hint
    with pytest.raises(SystemExit):
        main(["eval", str(fis), "service=3", "food=8"])
    err = capsys.readouterr().err
    assert "`cheap` of output `tip` lies outside its range [0, 30]" in err and \
        "resolution" not in err
    terms = TERMS.replace("terms: {SLOW: 20, FAST: 50}", "terms:\n      SLOW: {shape: formula, "
                          "formula: \"-x\"}\n      FAST: {shape: triangle, peak: 50, width: 10}")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text("operators: inference = mamdani\n" + RULES,
                                      encoding="utf-8")
    (zero,) = by_code(check_rulebase(read_rulebase(tmp_path / "t.rules")), "term-outside")
    assert zero.message == ("term `SLOW` of output `speed` is 0 all over its range [0, 60]: "
                            "its rules do not change `speed`")
    assert "above 0 somewhere" in zero.hint


def test_a_term_barely_sampled_is_reported_with_its_peak_and_a_wide_one_is_not(tmp_path):
    terms = TERMS.replace("terms: {SLOW: 20, FAST: 50}",
                          "terms:\n      SLOW: {shape: triangle, peak: 20.2, width: 0.4}\n"
                          "      FAST: {shape: triangle, peak: 50, width: 1.2}")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text("operators: inference = mamdani\n" + RULES,
                                      encoding="utf-8")
    (finding,) = by_code(check_rulebase(read_rulebase(tmp_path / "t.rules")),
                         "undersampled-term")
    # 101 midpoints of [0, 60], every 0.594: the nearest to SLOW's peak is 0.3 away, to
    # FAST's 0.2 (inside half its width)
    assert finding.message == ("term `SLOW` of output `speed` reaches only 0.26 at the 101 "
                               "points its output is sampled at (every 0.594): its rules "
                               "hardly change `speed`")
    assert "resolution = 1001" in finding.hint and "`operators:` line" in finding.hint


def test_a_crisp_output_is_never_undersampled(flawed):
    assert not by_code(check_rulebase(read_rulebase(flawed)), "undersampled-term")


def test_a_named_behavior_gets_only_the_findings_about_what_it_uses():
    """`check -b avoid_obstacle` warned about `nearest.ROOMY`, an input it never reads."""
    rb = read_rulebase(None)
    everything = check_rulebase(rb, resolution=5)
    assert any("nearest.ROOMY" in f.message for f in everything.findings)
    one = check_rulebase(rb, "avoid_obstacle", resolution=5)
    assert not any("nearest" in f.message for f in one.findings)
    assert {f.code for f in one.findings} <= {"unconcluded-term"}    # about `speed`, it sets
    take = check_rulebase(rb, "take_opening", resolution=5)           # it reads `nearest`
    assert any("nearest.ROOMY" in f.message for f in take.findings)


def test_the_findings_name_a_packaged_file_as_the_summary_does(tmp_path, monkeypatch, capsys):
    """From anywhere: `rulebases/drive.terms.yaml:103:7: warning: ...` above `checked
    rulebases/mitos.rules (packaged)`, not the file's place in site-packages."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit):
        main(["check", "-n", "5"])
    out = capsys.readouterr().out
    located = [line for line in out.splitlines() if ": warning: " in line or ": note: " in line]
    assert located and all(line.startswith("rulebases/") for line in located), located
    assert "\nchecked rulebases/mitos.rules (packaged): " in out


def _many_triangles(tmp_path: Path, n: int) -> Path:
    """A rule file whose input `x` has ``n`` narrow triangles, one of them used."""
    terms = "".join(f"      T{i}: {{shape: triangle, peak: {i + 1}, width: 1}}\n" for i in range(n))
    (tmp_path / "big.terms.yaml").write_text(
        f"variables:\n  x:\n    role: input\n    universe: [0, {n + 1}]\n    terms:\n{terms}"
        "  y:\n    role: output\n    universe: [0, 10]\n    terms:\n"
        "      A: {shape: triangle, peak: 5, width: 5}\n")
    (tmp_path / "big.rules").write_text('terms "big.terms.yaml"\nr1: if x is T0 then y is A\n')
    return tmp_path / "big.rules"


def test_a_variable_of_many_terms_is_checked_in_blocks(tmp_path):
    """`mitos check` of 10,000 triangles took 2 GB (20,000: 7 GB): its grid evaluated every
    term at 8,192 samples a block, and the term gaps took every term's memberships at every
    corner at once. Both now go a few terms' worth at a time."""
    import tracemalloc

    rb = read_rulebase(_many_triangles(tmp_path, 3000))
    tracemalloc.start()
    try:
        report = check_rulebase(rb)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 120e6                                    # was over 500 MB
    codes = {f.code for f in report.findings}
    assert {"no-rule-fires", "term-gap"} <= codes


def test_a_term_repeated_thousands_of_times_is_checked_in_little_memory(tmp_path, capsys):
    """The fuzzer's FLL file with one `term:` line repeated 17,500 times: `mitos check` crossed
    every two of the copies' edges and grew to 24 GB (the campaign's worker: a MemoryError).
    A repeated edge is crossed once now."""
    import tracemalloc

    path = tmp_path / "many.fll"
    path.write_text("Engine: e\nInputVariable: x\n  range: 0 1\n  term: A Triangle 0 0.5 1\n"
                    "OutputVariable: y\n  range: 0 1\n  defuzzifier: Centroid\n  default: 0.5\n"
                    + "  term: A Triangle 0 0.5 1\n" * 3000
                    + "RuleBlock: r\n  implication: Minimum\n  rule: if x is A then y is A\n",
                    encoding="utf-8")
    code, out, _ = run(["check", str(path)], capsys)
    assert code == 0 and "are hard to tell apart (similarity 1.00 > 0.5) [indistinct]" in out
    rb = read_rulebase(path)
    tracemalloc.start()
    try:
        check_rulebase(rb)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 50e6                                     # was 470 MB for 3,000 copies


def test_a_report_names_each_file_once(tmp_path, monkeypatch):
    """Each finding's file was looked up among the packaged rule bases again (resolving
    paths): 20,000 findings of one term set took 10 s to print."""
    from mitos_cli import resources
    from mitos_cli.cli.check_cmd import render

    asked = []
    real = resources.packaged_name
    monkeypatch.setattr(resources, "packaged_name", lambda p: asked.append(p) or real(p))
    report = check_rulebase(read_rulebase(_many_triangles(tmp_path, 300)))
    text = render(report, "big.rules")
    assert text.count("big.terms.yaml:") >= 300 and len(asked) == len(set(asked)) <= 2


def test_a_term_set_alone_is_checked_for_its_terms(tmp_path, capsys):
    """`mitos check X.terms.yaml`: the findings terms have before any rule reads them (a
    gap, terms out of order), at their lines; a world or a map named there is said to be one."""
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n"
        "  x:\n    role: input\n    universe: [0, 10]\n    terms:\n"
        "      LO: {shape: triangle, points: [0, 2, 5]}\n"
        "      MID: {shape: triangle, points: [5, 8, 10]}\n"
        "      HI: {shape: triangle, points: [2, 5, 8]}\n"
        "  g:\n    role: input\n    universe: [0, 10]\n    terms:\n"
        "      A: {shape: triangle, points: [0, 1, 2]}\n"
        "      B: {shape: triangle, points: [8, 9, 10]}\n")
    code, out, _ = run(["check", str(tmp_path / "t.terms.yaml")], capsys)
    assert code == 0
    assert f"{tmp_path / 't.terms.yaml'}:7:7: warning: `x.HI` (5) is written after `MID` (8) " \
        "but does not lie above it: the terms are out of order [term-order]" in out
    assert "[term-gap]" in out and "[unused-term]" not in out
    assert "the term set's 2 variables (no rules)" in out
    code, out, _ = run(["check", "--json", str(tmp_path / "t.terms.yaml")], capsys)
    data = json.loads(out)
    assert data["termset"].endswith("t.terms.yaml") and data["behaviors"] == []
    assert {f["code"] for f in data["findings"]} >= {"term-order", "term-gap"}
    code, _, err = run(["check", str(tmp_path / "t.terms.yaml"), "-b", "drive"], capsys)
    assert code == 2 and "has no behaviors (its terms only)" in err
    code, out, _ = run(["check", "rulebases/drive.terms.yaml"], capsys)   # packaged, anywhere
    assert code == 0 and "0 errors, 0 warnings, 0 notes - OK" in out
    world = tmp_path / "w.yaml"
    world.write_text("name: w\nq_init: [0, 0, 0]\nq_goal: [9, 0]\n")
    code, _, err = run(["check", str(world)], capsys)
    assert code == 1 and "is a world file, not a term set" in err and "mitos simulate" in err
    code, _, err = run(["check", str(tmp_path / "t.term.yaml")], capsys)
    assert code == 1 and "did you mean `" in err and "t.terms.yaml`?" in err


def test_a_rule_weighted_0_is_no_conflict(tmp_path):
    """`with 0` (or `use B with 0`) switches a rule off: it never fires, as `unreachable`
    says; `conflict` reported it as an error (exit 1) against the rule it was written
    beside."""
    (tmp_path / "t.terms.yaml").write_text(TERMS, encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\nbehavior a:\n    r1: if road is WIDE then steering is LS\n'
        "    r2: if road is WIDE then steering is RS with 0\n    use b with 0\nend\n"
        "behavior b:\n    q: if road is WIDE then steering is ST\nend\n", encoding="utf-8")
    report = check_rulebase(read_rulebase(tmp_path / "t.rules"), "a")
    assert by_code(report, "conflict") == []
    assert {f.code for f in report.findings if f.severity == "error"} == {"no-rule-fires"}
    assert [f.message.split(":")[0] for f in by_code(report, "unreachable")] == [
        "`r2` never fires"]


@pytest.mark.parametrize("operators, says", [
    ("", "it counts twice in the weighted average"),
    ("operators: inference = weighted_sum\n", "it counts twice in the weighted sum"),
    ("operators: inference = mamdani\n",
     "it changes nothing (max aggregation keeps the stronger of the two)"),
    ("operators: inference = mamdani, aggregation = bounded_sum\n",
     "its set is aggregated twice (bounded_sum)"),
    ("operators: inference = mamdani, aggregation = sum\n",
     "its set is added twice (aggregation = sum)"),
])


def test_a_duplicate_says_what_it_does_under_the_inference(tmp_path, operators, says):
    """A rule written twice "counts twice in the weighted average", said under Mamdani
    inference too, where with max aggregation the second changes nothing."""
    (tmp_path / "t.terms.yaml").write_text(TERMS, encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\n' + operators + "r1: if road is WIDE then speed is FAST\n"
        "r2: if road is WIDE then speed is FAST\n", encoding="utf-8")
    (dup,) = by_code(check_rulebase(read_rulebase(tmp_path / "t.rules")), "duplicate")
    assert dup.message.endswith(says)


@pytest.mark.parametrize("terms, share", [
    # crisp steps: no rule fires on [0, 2), (5, 7) and (9, 10], half the universe
    ("{A: {shape: rectangle, points: [2, 5]}, B: {shape: rectangle, points: [7, 9]}}", 0.5),
    # a zero-width term fires at 5 alone: none fires on (4, 5) and (5, 6)
    ("{A: {shape: triangle, points: [0, 0, 4]}, B: {shape: triangle, points: [5, 5, 5]},"
     " C: {shape: triangle, points: [6, 10, 10]}}", 0.2),
])


def test_where_no_rule_fires_is_measured_exactly_beside_vertical_edges(tmp_path, terms, share):
    """A cell between samples counted as unset only when no rule fired at any of its ends, so
    the cells beside a crisp step (a rectangle's edge) or a zero-width term, where the rules
    are 0 inside and above 0 at one end, counted as set: 40% for 50%, 15% for 20%. A cell
    is judged at its centre now, which is exact on a grid that holds the corner points."""
    (tmp_path / "t.terms.yaml").write_text(
        f"variables:\n  x: {{role: input, universe: [0, 10], terms: {terms}}}\n"
        "  w: {role: output, universe: [0, 100], terms: {P: 10, Q: 50, R: 90}}\n",
        encoding="utf-8")
    names = "ABC" if "C:" in terms else "AB"
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\n' + "".join(
        f"r{i}: if x is {t} then w is {'PQR'[i]}\n" for i, t in enumerate(names)),
        encoding="utf-8")
    (gap,) = by_code(check_rulebase(read_rulebase(tmp_path / "t.rules")), "no-rule-fires")
    assert gap.share == pytest.approx(share, abs=1e-12)


@pytest.mark.parametrize("given", ["", 3, None])
def test_read_termset_says_a_term_set_is_read_from_a_file(given):
    """From Python, `read_termset(3)` was told "a rule base is read from a file"."""
    from mitos_cli.api import read_termset
    from mitos_cli.errors import TermSetError

    with pytest.raises(TermSetError, match="a term set is read from a file: expected its path"):
        read_termset(given)
