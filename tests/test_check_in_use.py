"""``mitos check`` judges a behavior that others ``use`` where it is in use, and a composition's
coverage exactly, with box algebra (mitos_cli.engine.regions): against a dense sample."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from strategies import expressions

from mitos_cli.api import read_rulebase
from mitos_cli.cli.app import main
from mitos_cli.engine import regions
from mitos_cli.engine.check import _Compositions, check_rulebase, corner_points
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import rule_dofs
from mitos_cli.fuzzy.hedges import HEDGES
from mitos_cli.lang.model import Behavior, Consequent, Rule, RuleBase, Setting, Use
from mitos_cli.lang.terms import Term, TermSet, Variable

TERMS = """variables:
  x:
    role: input
    universe: [0, 100]
    terms:
      LO: {shape: left_shoulder, points: [20, 40]}
      HI: {shape: right_shoulder, points: [60, 80]}
  z:
    role: input
    universe: [0, 10]
    terms:
      A: {shape: left_shoulder, points: [3, 5]}
      B: {shape: right_shoulder, points: [3, 5]}
  y:
    role: output
    universe: [0, 10]
    default: 0
    terms: {ONE: 1, TWO: 2}
"""

PART = "behavior part:\n  p1: if x is LO then y is ONE\nend\n"


def rules(tmp_path, text: str):
    (tmp_path / "t.terms.yaml").write_text(TERMS, encoding="utf-8")
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\n' + text, encoding="utf-8")
    return read_rulebase(tmp_path / "t.rules")


def coverage(report, behavior=None):
    return [f for f in report.findings if f.code in ("no-rule-fires", "low-dof")
            and (behavior is None or f.behavior == behavior)]


def test_a_gap_inside_the_use_region_is_still_reported(tmp_path):
    # `part` sets y only where x is LO, and `top` uses it wherever z is A: x > 40 is a gap
    rb = rules(tmp_path, PART + "behavior top:\n  use part when z is A\n  t1: if z is B then "
                               "y is TWO\nend\n")
    found = coverage(check_rulebase(rb), "part")
    assert [f.code for f in found] == ["no-rule-fires"]
    f = found[0]
    assert f.message == ("behavior `part`, where `top` uses it and no other behavior sets `y` "
                         "there: no rule sets `y` in 60% of its input space (the default "
                         "applies there: y = 0)")
    assert [b.describe() for b in f.regions] == ["x in [40, 100]"]
    assert f.span.line == 2 and f.severity == "warning"
    # and the composition: where z is not B (t1) and x is not LO, nothing sets y (exact:
    # 60% of x times 30% of z)
    (top,) = coverage(check_rulebase(rb), "top")
    assert top.share == pytest.approx(0.18)
    assert [b.describe() for b in top.regions] == ["x in [40, 100] and z in [0, 3]"]


def test_a_gap_outside_the_use_region_is_not(tmp_path):
    # the same `part` on its own has the gap (today's finding) ...
    alone = check_rulebase(rules(tmp_path, PART))
    assert [f.code for f in coverage(alone)] == ["no-rule-fires"]
    # ... but `top` uses it only where x is LO, where it covers, and sets y itself elsewhere
    rb = rules(tmp_path, PART + "behavior top:\n  use part when x is LO\n"
                               "  t1: if x is not LO then y is TWO\nend\n")
    report = check_rulebase(rb)
    assert coverage(report) == []
    assert report.ok


def test_a_siblings_coverage_counts(tmp_path):
    # `fill` sets y where `part` does not, both used where z is A: no gap of `part`; the
    # composition's gap is where z is not A at all, and it is said there
    rb = rules(tmp_path, PART + "behavior fill:\n  f1: if x is not LO then y is TWO\nend\n"
                               "behavior top:\n  use part when z is A\n  use fill when z is A\n"
                               "end\n")
    report = check_rulebase(rb)
    assert coverage(report, "part") == [] and coverage(report, "fill") == []
    (top,) = coverage(report, "top")
    assert [b.describe() for b in top.regions] == ["z in [5, 10]"]
    assert top.share == pytest.approx(0.5)
    assert top.message.startswith("behavior `top`: no rule sets `y` in 50% of the input space")


def test_low_dof_counts_only_where_the_behavior_is_alone(tmp_path):
    weak = "behavior part:\n  p1: if x is LO then y is ONE with 0.05\nend\n"
    rb = rules(tmp_path, weak + "behavior top:\n  use part when z is A\n"
                               "  t1: if z is A then y is TWO\n  t2: if z is B then y is ONE\nend\n")
    assert coverage(check_rulebase(rb), "part") == []        # `top`'s t1 sets y beside it
    rb = rules(tmp_path, weak + "behavior top:\n  use part when z is A\n"
                               "  t1: if x is not LO then y is TWO\n  t2: if z is B then y is ONE\nend\n")
    found = [f for f in coverage(check_rulebase(rb), "part") if f.code == "low-dof"]
    assert len(found) == 1 and "where `top` uses it" in found[0].message
    assert [b.describe() for b in found[0].regions] == ["x in [0, 20]"]


def test_a_standalone_behavior_gives_the_findings_it_gives_alone(tmp_path):
    solo = "behavior solo:\n  s1: if z is A then y is ONE with 0.05\nend\n"
    with_others = check_rulebase(rules(tmp_path, solo + PART + "behavior top:\n  use part\nend\n"))
    alone = check_rulebase(rules(tmp_path, solo))
    mine = [f for f in with_others.findings if f.behavior == "solo"]
    assert mine == [f for f in alone.findings if f.behavior == "solo"] and len(mine) == 2


def test_cli_says_in_use(tmp_path, capsys):
    rules(tmp_path, PART + "behavior top:\n  use part when z is A\n  t1: if z is B then y is TWO\n"
                           "end\n")
    with pytest.raises(SystemExit) as info:
        main(["check", str(tmp_path / "t.rules")])
    out = capsys.readouterr().out
    assert info.value.code == 0
    assert (f"{tmp_path / 't.rules'}:2:1: warning: behavior `part`, where `top` uses it and no "
            "other behavior sets `y` there: no rule sets `y` in 60% of its input space") in out
    assert "\nbehavior part:\n^\n" in out.replace("    ", "")
    assert "    x in [40, 100]\n" in out


def test_the_packaged_drive_is_covered_with_no_grid_note_on_gaps():
    report = check_rulebase(read_rulebase())
    assert coverage(report) == []
    drive = next(g for g in report.grids if g.behavior == "drive")
    assert drive.exact and drive.skipped


# ---------------------------------------------------------------------------------------------
# the box algebra against a dense sample

LINEAR = {"triangle": 3, "trapezoid": 4, "left_shoulder": 2, "right_shoulder": 2,
          "rectangle": 2}


@st.composite
def term_sets(draw, prefix: str) -> tuple[Term, ...]:
    out = []
    for i in range(draw(st.integers(1, 3))):
        shape = draw(st.sampled_from(sorted(LINEAR)))
        xs = sorted(draw(st.lists(st.integers(0, 10).map(float), min_size=4, max_size=4)))
        if shape == "rectangle" and xs[0] == xs[1]:
            xs[1] += 0.5
        out.append(Term(f"{prefix}{i}", shape, tuple(xs[:LINEAR[shape]])))
    return tuple(out)


@st.composite
def compositions(draw) -> RuleBase:
    a = Variable("a", "input", (0.0, 10.0), draw(term_sets("A")))
    b = Variable("b", "input", (0.0, 10.0), draw(term_sets("B")))
    y = Variable("y", "output", (0.0, 10.0), (Term("ONE", "singleton", (1.0,)),), default=0.0)
    hedges = tuple(sorted(HEDGES))

    def rule_list(prefix: str) -> tuple[Rule, ...]:
        return tuple(Rule(f"{prefix}{i}", draw(expressions((a, b), hedges, 1)),
                          (Consequent("y", "ONE"),), draw(st.sampled_from([1.0, 0.5])))
                     for i in range(draw(st.integers(1, 3))))

    inner = Behavior("inner", rule_list("i"))
    condition = draw(expressions((a, b), hedges, 1, 1))
    main = Behavior("main", rule_list("r"), uses=(Use("inner", condition),))
    ops = (Setting("and", draw(st.sampled_from(sorted(regions.EXACT_TNORMS)))),
           Setting("or", draw(st.sampled_from(sorted(regions.EXACT_SNORMS)))))
    return RuleBase(None, (TermSet((a, b, y)),), (main, inner), ops)


def atom_grid(compiled):
    """Every combination of the atoms' points (corners and the middles between them), each
    atom's length, and a dense uniform sample."""
    atoms = [regions.Atoms(n, corner_points(compiled, i)) for i, n in enumerate(compiled.inputs)]
    points = np.array(list(itertools.product(*(a.points for a in atoms))))
    lengths = np.prod(np.array(list(itertools.product(*(a.lengths for a in atoms)))), axis=1)
    return points, lengths


@settings(max_examples=80, deadline=None)
@given(rb=compositions(), seed=st.integers(0, 2**32 - 1))
def test_exact_gaps_agree_with_a_dense_sample(rb, seed):
    compiled = compile_rulebase(rb, "main")
    exact = _Compositions(rb).exact("main", compiled)
    assert exact is not None
    gap = exact.gaps["y"]
    points, lengths = atom_grid(compiled)
    rng = np.random.default_rng(seed)
    uniform = rng.uniform(compiled.universe[:, 0], compiled.universe[:, 1],
                          size=(2000, len(compiled.inputs)))
    for X in (points, uniform):
        unset = (rule_dofs(compiled, X) @ compiled.cons_mask[:, 0].astype(float)) <= 0.0
        assert np.array_equal(exact.space.contains(gap, X), unset)
        if X is points:                # a cube's volume is its atoms' lengths
            assert exact.space.volume(gap) == pytest.approx(float(lengths[unset].sum()))


@settings(max_examples=60, deadline=None)
@given(rb=compositions())
def test_in_use_agrees_with_a_dense_sample(rb):
    """`inner` counts at a point of its inputs where, for some value of the others, its `use`
    condition is above 0 and no rule of `main` sets y: on every atom of the whole space."""
    top = compile_rulebase(rb, "main")
    comps = _Compositions(rb)
    inner = compile_rulebase(rb, "inner")
    in_use = comps.in_use("inner", inner)
    assert in_use is not None
    points, _ = atom_grid(top)
    dof = rule_dofs(top, points)
    own = np.array([not label.startswith("inner/") for label in top.labels])
    cond = compile_rulebase(RuleBase(None, rb.termsets, (Behavior(
        "c", (Rule("c", rb.behavior("main").uses[0].condition, (Consequent("y", "ONE"),)),)),),
        rb.operators), "c")
    in_ctx = rule_dofs(cond, points[:, [top.inputs.index(v) for v in cond.inputs]])[:, 0] > 0
    alone = in_ctx & ~(dof[:, own] > 0).any(axis=1)
    cols = [top.inputs.index(v) for v in inner.inputs]
    expected = {tuple(p) for p in points[alone][:, cols]}
    got = in_use.mask("y", points[:, cols])
    assert {tuple(p) for p in points[:, cols][got]} == expected


def test_an_unused_term_the_coverage_needs_is_a_note(tmp_path):
    # no rule reads z.B, but without it no term of z reaches 0.5 above z = 4: a note, with the
    # complement it equals; x.HI is unused too, and x.LO covers nothing above 30 either
    rb = rules(tmp_path, "r1: if z is not A then y is ONE\nr2: if z is A and x is LO then y is TWO\n"
                         "r3: if x is not LO then y is ONE\n")
    found = {f.message.split("`")[1]: f for f in check_rulebase(rb).findings
             if f.code == "unused-term"}
    assert found["z.B"].severity == "info"
    assert found["z.B"].message == ("input term `z.B` is used by no rule, but no other term of "
                                    "`z` reaches 0.5 for z in (4, 10]: it covers the universe "
                                    "there")
    assert found["z.B"].hint == ("keep it for the term set's coverage; `z is B` has the degree "
                                 "of `z is not A`, which a rule may say instead")
    assert found["x.HI"].severity == "info" and "x in (70, 100]" in found["x.HI"].message
    assert "has the degree" not in found["x.HI"].hint          # HI is no complement of LO


def test_an_unused_term_the_coverage_does_not_need_is_a_warning(tmp_path):
    terms = TERMS.replace("      HI: {shape: right_shoulder, points: [60, 80]}",
                          "      HI: {shape: right_shoulder, points: [20, 40]}\n"
                          "      TOP: {shape: right_shoulder, points: [70, 90]}")
    (tmp_path / "t.terms.yaml").write_text(terms, encoding="utf-8")
    (tmp_path / "t.rules").write_text('terms "t.terms.yaml"\nr1: if x is LO then y is ONE\n'
                                      "r2: if x is HI and z is A then y is TWO\n"
                                      "r3: if z is B then y is TWO\n", encoding="utf-8")
    (top,) = [f for f in check_rulebase(read_rulebase(tmp_path / "t.rules")).findings
              if f.code == "unused-term"]
    assert top.severity == "warning" and top.message == "input term `x.TOP` is used by no rule"
    assert top.hint == "write a rule for it, or remove it from the term set"


def test_with_operators_that_have_no_exact_answer_each_behavior_is_judged_on_its_own(tmp_path):
    # Lukasiewicz's `and` is 0 where both items are above 0 (zero divisors): no boxes; `part`
    # and `top` get the sampled findings each would have alone
    text = PART + "behavior top:\n  use part when x is LO\n  t1: if x is not LO then y is TWO\nend\n"
    exact = check_rulebase(rules(tmp_path, text))
    sampled = check_rulebase(rules(tmp_path, "operators: and = lukasiewicz\n" + text))
    assert coverage(exact) == []
    assert [f.behavior for f in coverage(sampled)] == ["part"]
    assert "uses it" not in coverage(sampled)[0].message
    assert [g.exact for g in sampled.grids] == [False, False]
    assert [g.exact for g in exact.grids] == [False, True]
    with pytest.raises(regions.NotExact, match="lukasiewicz"):
        regions.Space([], [], "lukasiewicz", "max")


def test_json_says_which_gaps_were_decided_exactly(tmp_path, capsys):
    import json

    rules(tmp_path, PART + "behavior top:\n  use part when z is A\nend\n")
    with pytest.raises(SystemExit):
        main(["check", str(tmp_path / "t.rules"), "--json"])
    out = json.loads(capsys.readouterr().out)
    assert {b["name"]: b["exact_gaps"] for b in out["behaviors"]} == {"part": False, "top": True}


def test_the_chain_of_uses_runs_to_every_behavior_nothing_uses(tmp_path):
    # `part` reaches `top` through `mid` (when z is A, then when x is not HI) and is used by
    # `other` too: its gap x in [40, 100] is in use where x is not HI (x < 80) in `top`, and
    # wherever `other` uses it; the finding names both
    text = (PART + "behavior mid:\n  use part when x is not HI\nend\n"
            "behavior top:\n  use mid when z is A\n  t1: if z is B then y is TWO\nend\n"
            "behavior other:\n  use part when z is A\n  o1: if z is B then y is TWO\nend\n")
    (f,) = coverage(check_rulebase(rules(tmp_path, text)), "part")
    assert f.message.startswith("behavior `part`, where `top` and `other` use it and no other "
                                "behavior sets `y` there: no rule sets `y` in 60% of its input")
    # used only through `mid` in `top`, the part of the gap where x is HI is out of use
    text = (PART + "behavior mid:\n  use part when x is not HI\nend\n"
            "behavior top:\n  use mid when z is A\n  t1: if z is B then y is TWO\nend\n")
    report = check_rulebase(rules(tmp_path, text))
    (f,) = coverage(report, "part")
    assert [b.describe() for b in f.regions] == ["x in [40, 80)"]
    assert f.share == pytest.approx(0.4)
    assert [g.behavior for g in report.grids if g.exact] == ["top"]


def test_past_the_work_budget_the_composition_is_sampled_as_before(tmp_path, monkeypatch):
    text = PART + "behavior top:\n  use part when x is LO\n  t1: if x is not LO then y is TWO\nend\n"
    monkeypatch.setattr(regions, "MAX_WORK", 0)          # every box difference is too many
    report = check_rulebase(rules(tmp_path, text))
    assert [g.exact for g in report.grids] == [False, False]
    (f,) = coverage(report)                   # `part` on its own, as with no composition
    assert f.behavior == "part" and "uses it" not in f.message
    with pytest.raises(regions.NotExact, match="more than 0 box differences"):
        regions.subtract([(1,)], [(1,)])
