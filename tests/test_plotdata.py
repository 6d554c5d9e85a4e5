"""What the pictures show (mitos_cli.draw.data), checked against the engine, without matplotlib:
term curves are the memberships, a surface grid is the engine's outputs at the same points,
the rule viewer's rows are the rules and DOFs that `mitos eval` reports."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mitos_cli.api import load_rulebase
from mitos_cli.cli.app import main
from mitos_cli.draw import data as plotdata
from mitos_cli.engine import mamdani
from mitos_cli.engine.evaluation import as_batch, evaluate
from mitos_cli.errors import InputError
from mitos_cli.fuzzy import norms

SAMPLE = {"road": 78.0, "size": 45.0, "position": 4.0}

GAP_TERMS = """\
variables:
  x:
    role: input
    universe: [0, 10]
    terms:
      LOW: {shape: left_shoulder, points: [2, 4]}
      HIGH: {shape: right_shoulder, points: [6, 8]}
  y:
    role: input
    universe: [0, 1]
    terms:
      ANY: {shape: trapezoid, points: [0, 0, 1, 1]}
  out:
    role: output
    universe: [0, 100]
    terms: {SMALL: 10, BIG: 90}
"""
GAP_RULES = """\
terms "gap.terms.yaml"
if x is LOW and y is ANY then out is SMALL
if x is HIGH and y is ANY then out is BIG
"""

MAMDANI_TERMS = """\
variables:
  road:
    role: input
    universe: [0, 160]
    terms:
      NARROW: {shape: left_shoulder, points: [40, 70]}
      MEDIUM: {shape: triangle, peak: 70, width: 30}
      WIDE: {shape: right_shoulder, points: [70, 100]}
  size:
    role: input
    universe: [0, 100]
    terms:
      SMALL: {shape: left_shoulder, points: [10, 40]}
      LARGE: {shape: right_shoulder, points: [10, 70]}
  speed:
    role: output
    universe: [0, 60]
    terms:
      SLOW: {shape: triangle, points: [0, 10, 30]}
      MODERATE: {shape: trapezoid, points: [15, 25, 35, 45]}
      FAST: {shape: right_shoulder, points: [35, 55]}
"""
MAMDANI_RULES = """\
terms "m.terms.yaml"
operators: inference = mamdani, implication = {implication}, aggregation = {aggregation}
if road is NARROW then speed is SLOW
if road is MEDIUM and size is SMALL then speed is MODERATE
if road is MEDIUM and size is LARGE then speed is SLOW with 0.8
if road is WIDE and not size is LARGE then speed is FAST
if road is WIDE and size is very LARGE then speed is somewhat MODERATE
"""


@pytest.fixture(scope="module")
def mitos():
    return load_rulebase()


@pytest.fixture
def gap(tmp_path):
    (tmp_path / "gap.terms.yaml").write_text(GAP_TERMS)
    path = tmp_path / "gap.rules"
    path.write_text(GAP_RULES)
    return path


def write_mamdani(tmp_path, implication="min", aggregation="max"):
    (tmp_path / "m.terms.yaml").write_text(MAMDANI_TERMS)
    path = tmp_path / "m.rules"
    path.write_text(MAMDANI_RULES.format(implication=implication, aggregation=aggregation))
    return path


# ---------------------------------------------------------------- term curves


def test_curves_are_the_terms_memberships_with_exact_corners(mitos):
    for var in mitos.rulebase.variables.values():
        plot = plotdata.variable_plot(var)
        assert [c.name for c in plot.curves] == list(var.term_names)
        for curve, term in zip(plot.curves, var.terms):
            if term.shape == "singleton":
                assert curve.kind == "singleton"
                assert curve.x.tolist() == [term.center] and curve.y.tolist() == [1.0]
                continue
            assert curve.kind == "curve"
            np.testing.assert_array_equal(curve.y, term.membership(curve.x))
            assert curve.x[0] == var.universe[0] and curve.x[-1] == var.universe[1]
            for corner in term.corners:                 # kinks are drawn exactly
                if np.isfinite(corner):
                    assert corner in curve.x


def test_marked_values_have_the_engines_memberships(mitos):
    plots = plotdata.sheet(mitos.rulebase, values=SAMPLE)
    result = evaluate(mitos.compiled, as_batch(mitos.compiled, SAMPLE))
    engine = {key: float(mu) for key, mu in zip(mitos.compiled.term_names,
                                                  result.memberships[0])}
    for plot in plots:
        if plot.name not in SAMPLE:
            assert plot.value is None and plot.memberships == ()
            continue
        assert plot.value == SAMPLE[plot.name]
        for term, mu in plot.memberships:
            assert mu == pytest.approx(engine[(plot.name, term)], abs=1e-12)
    road = dict(plots[0].memberships)
    assert round(road["MEDIUM"], 2) == 0.73 and round(road["WIDE"], 2) == 0.27


def test_sheet_puts_inputs_first_and_picks_variables(mitos):
    plots = plotdata.sheet(mitos.rulebase)
    names = [p.name for p in plots]
    assert names[:3] == ["road", "size", "position"]
    assert {"steering", "speed"} <= set(names)
    roles = [p.role for p in plots]
    assert roles == sorted(roles, key=lambda r: r != "input")     # inputs first
    picked = plotdata.sheet(mitos.rulebase, ["speed", "road"])
    assert [p.name for p in picked] == ["speed", "road"]
    used = plotdata.sheet(mitos.rulebase, behavior="avoid_obstacle")
    assert [p.name for p in used] == ["road", "size", "position", "steering", "speed"]


def test_sheet_unknown_variable_says_did_you_mean(mitos):
    with pytest.raises(InputError) as exc:
        plotdata.sheet(mitos.rulebase, ["raod"])
    assert "unknown variable `raod`" in exc.value.message
    assert "did you mean `road`?" in exc.value.hint
    with pytest.raises(InputError, match="unknown variable `sise`"):
        plotdata.sheet(mitos.rulebase, values={"sise": 3.0})


def test_value_outside_universe_is_clamped_and_flagged(mitos):
    plot = plotdata.variable_plot(mitos.rulebase.variables["road"], 500)
    assert plot.value == 160 and plot.clamped
    assert dict(plot.memberships)["WIDE"] == 1.0


def test_linear_formula():
    from mitos_cli.lang.terms import Term

    term = Term("T", "linear", (0.5, -1.0, 0.0, 90.0))
    assert plotdata.linear_formula(term, ("road", "size", "position")) == \
        "y = 0.5 road - size + 90"
    assert plotdata.linear_formula(Term("Z", "linear", (0.0, 0.0)), ("a",)) == "y = 0"


# ---------------------------------------------------------------- surfaces


def test_surface_grid_equals_engine_outputs_point_by_point(mitos):
    s = plotdata.surface(mitos.compiled, "steering", "road", "position", {"size": 45},
                         resolution=9)
    assert s.z.shape == (9, 9)
    assert s.x.values[0] == 0 and s.x.values[-1] == 160
    assert s.y.values[0] == -60 and s.y.values[-1] == 60
    for j, pos in enumerate(s.y.values):
        for i, road in enumerate(s.x.values):
            one = mitos.evaluate(road=road, size=45, position=pos)["steering"]
            assert s.z[j, i] == one                    # bit for bit: a batch row = one eval
    assert s.fixed == (plotdata.Fixed("size", 45.0, "in", False),)
    assert s.notes() == []


def test_surface_curve_and_zoom(mitos):
    s = plotdata.surface(mitos.compiled, "speed", "road", None,
                         {"size": 45, "position": 4}, resolution=5, x_range=(40, 100))
    assert s.y is None and s.z.shape == (5,)
    np.testing.assert_array_equal(s.x.values, [40, 55, 70, 85, 100])
    expected = mitos.evaluate(road=s.x.values, size=45, position=4)["speed"]
    np.testing.assert_array_equal(s.z, expected)


def test_surface_holds_missing_inputs_at_the_midpoint_and_says_so(mitos):
    s = plotdata.surface(mitos.compiled, "steering", "road", "position", resolution=3)
    assert s.fixed == (plotdata.Fixed("size", 50.0, "in", True),)
    assert "(midpoint)" in s.fixed_text
    assert any("held at 50, the midpoint" in n and "--fix size=VALUE" in n for n in s.notes())
    np.testing.assert_array_equal(
        s.z[1], mitos.evaluate(road=s.x.values, size=50.0, position=0.0)["steering"])


def test_surface_masks_where_no_rule_fires_and_no_default(gap):
    rb = load_rulebase(gap)
    s = plotdata.surface(rb.compiled, "out", "x", "y", resolution=11)   # x = 0, 1, ..., 10
    holes = s.no_rule.all(axis=0)
    assert holes.tolist() == [x in (4, 5, 6) for x in range(11)]       # neither LOW nor HIGH
    assert not s.no_rule[:, ~holes].any()
    assert any("no rule sets `out` at 33 of 121 grid points" in n for n in s.notes())


@pytest.mark.parametrize("kwargs, message", [
    (dict(output="steer", x="road"), "unknown output `steer`"),
    (dict(output="steering", x="raod"), "unknown input (--x) `raod`"),
    (dict(output="steering", x="road", y="road"), "`road` is on both axes"),
    (dict(output="steering", x="road", fixed={"road": 3}), "on an axis and cannot also be fixed"),
    (dict(output="steering", x="road", fixed={"size": 400}), "outside its universe"),
    (dict(output="steering", x="road", x_range=(50, 300)), "is not inside its universe"),
    (dict(output="steering", x="road", resolution=1), "resolution is a whole number, 2 or more"),
])
def test_surface_errors(mitos, kwargs, message):
    with pytest.raises(InputError) as exc:
        plotdata.surface(mitos.compiled, **kwargs)
    assert message in exc.value.message


# ---------------------------------------------------------------- rule viewer


def eval_json(args, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["eval", *args, "--json"])
    assert exc.value.code in (0, None)
    return json.loads(capsys.readouterr().out)


def test_rule_view_rows_are_the_fired_rules_and_dofs_of_eval(mitos, capsys):
    view = plotdata.rule_view(mitos.compiled, SAMPLE)
    trace = eval_json([f"{k}={v:g}" for k, v in SAMPLE.items()], capsys)
    assert [r.label for r in view.rows] == [r["label"] for r in trace["rules"]] == \
        ["r4", "r5", "r7", "r8", "r22", "r23", "r25", "r26"]
    assert [r.dof for r in view.rows] == [r["dof"] for r in trace["rules"]]
    assert [r.text for r in view.rows] == [r["text"] for r in trace["rules"]]
    assert {o.name: o.value for o in view.outputs} == trace["outputs"]
    for i in view.inputs:
        assert dict(i.memberships) == trace["inputs"][i.name]["memberships"]


def test_rule_view_props_consequents_and_weighted_average(mitos):
    view = plotdata.rule_view(mitos.compiled, SAMPLE)
    r25 = next(r for r in view.rows if r.label == "r25")
    assert [(p.var, p.term) for p in r25.props] == \
        [("road", "MEDIUM"), ("size", "MED_SZ"), ("position", "RIGHT")]
    assert r25.dof == min(p.value for p in r25.props)          # eq. 17
    assert [(c.output, c.term, c.value) for c in r25.consequents] == \
        [("steering", "LM", 50.0), ("speed", "MODERATE", 30.0)]
    for out in view.outputs:                                     # eqs. 18-19 from the stems
        values = np.array([v for v, _ in out.stems])
        weights = np.array([w for _, w in out.stems])
        assert (values * weights).sum() / weights.sum() == pytest.approx(out.value, rel=1e-12)
        assert not out.defaulted
    steering = view.outputs[0]
    assert [v for v, _ in steering.stems] == [50.0, 70.0, 90.0]


def test_rule_view_hedges_and_negation_are_what_enters_the_rule(tmp_path):
    rb = load_rulebase(write_mamdani(tmp_path))
    view = plotdata.rule_view(rb.compiled, {"road": 80, "size": 30})
    rows = {r.label: r for r in view.rows}
    neg = rows["#4"].props[1]
    assert neg.text == "size is not LARGE" and neg.negated
    assert neg.value == pytest.approx(1 - neg.mu)
    np.testing.assert_allclose(neg.y, 1 - rb.rulebase.variables["size"].term("LARGE")
                               .membership(neg.x))
    very = rows["#5"].props[1]
    assert very.hedges == ("very",) and very.value == pytest.approx(very.mu ** 2)
    assert rows["#3"].dof == pytest.approx(0.8 * min(p.value for p in rows["#3"].props))
    assert rows["#3"].antecedent == min(p.value for p in rows["#3"].props)
    assert rows["#3"].factor == pytest.approx(0.8)                # `with 0.8`
    assert rows["#3"].dof_text == f"DOF {rows['#3'].dof:.2f} = 0.33 × 0.80"
    assert rows["#2"].factor == 1.0 and rows["#2"].dof_text == f"DOF {rows['#2'].dof:.2f}"


def test_rule_view_shows_use_contexts(mitos):
    """In a blended behavior (`use X when C`), a row's DOF is its antecedent times the
    context's degree: the viewer says so."""
    if "drive" not in mitos.behaviors:
        pytest.skip("the packaged rule base has no `drive` behavior")
    drive = mitos.behavior("drive")
    values = {name: float(np.mean(drive.compiled.universe[k]))
              for k, name in enumerate(drive.inputs)}
    values.update(road=78, size=45, position=4, obstacle=60)     # obstacle NEAR 0.83, FAR 0.17
    view = plotdata.rule_view(drive.compiled, values)
    result = evaluate(drive.compiled, as_batch(drive.compiled, values))
    fired = np.flatnonzero(result.dof[0] > 0)
    assert [r.index for r in view.rows] == fired.tolist()
    for row in view.rows:
        assert row.antecedent * row.factor == pytest.approx(row.dof, rel=1e-12)
    assert any(row.factor < 1 and " × " in row.dof_text for row in view.rows)


@pytest.mark.parametrize("implication, aggregation",
                         [("min", "max"), ("product", "probabilistic_sum")])
def test_rule_view_mamdani_sets_and_crisp_result(tmp_path, implication, aggregation):
    rb = load_rulebase(write_mamdani(tmp_path, implication, aggregation))
    view = plotdata.rule_view(rb.compiled, {"road": 80, "size": 30})
    (out,) = view.outputs
    (table,) = rb.compiled.mamdani
    np.testing.assert_array_equal(out.grid, table.grid)
    imp = mamdani.IMPLICATIONS[implication]
    snorm = norms.lookup("snorm", aggregation)
    expected = np.zeros_like(table.grid)
    for row in view.rows:                                 # each rule's implied set, by hand
        (c,) = row.consequents
        np.testing.assert_allclose(c.implied, imp(row.dof, c.full))
        expected = snorm.fn(expected, c.implied)
    np.testing.assert_allclose(out.aggregate, expected, atol=1e-12)
    crisp = mamdani.defuzzify(out.aggregate[None], out.grid, "centroid")[0]
    assert out.value == pytest.approx(crisp, rel=1e-12)
    assert out.value == rb.evaluate(road=80, size=30)["speed"]
    assert out.stems == ()


def test_rule_view_nothing_fired(gap):
    rb = load_rulebase(gap)
    view = plotdata.rule_view(rb.compiled, {"x": 5, "y": 0.5})
    assert view.rows == ()
    assert np.isnan(view.outputs[0].value) and view.outputs[0].defaulted


def test_rule_view_missing_input_is_refused(mitos):
    with pytest.raises(InputError, match="missing input `position`"):
        plotdata.rule_view(mitos.compiled, {"road": 78, "size": 45})


def test_the_data_of_the_pictures_take_what_load_rulebase_returns():
    """``load_rulebase()`` is the documented way in, and its LoadedRuleBase met
    AttributeErrors in sheet ('termsets'), surface ('universe') and rule_view
    ('grid_batch'): each now takes it as its compiled behavior, and refuses anything else
    in words."""
    from mitos_cli.draw.data import rule_view, sheet, surface

    loaded = load_rulebase(None, "avoid_obstacle")
    values = {"road": 78.0, "size": 45.0, "position": 4.0}
    assert surface(loaded, "steering", "road").z.tolist() == \
        surface(loaded.compiled, "steering", "road").z.tolist()
    view, direct = rule_view(loaded, values), rule_view(loaded.compiled, values)
    assert [(r.label, r.dof) for r in view.rows] == [(r.label, r.dof) for r in direct.rows]
    assert [o.value for o in view.outputs] == [o.value for o in direct.outputs]
    names = [v.name for v in sheet(loaded)]
    assert names == [v.name for v in sheet(loaded.rulebase, behavior="avoid_obstacle")]
    assert names == ["road", "size", "position", "steering", "speed"]
    assert len(sheet(loaded, behavior="drive")) > len(names)
    for call, who in ((lambda: surface("my.rules", "steering", "road"), "surface"),
                      (lambda: rule_view(None, values), "rule_view")):
        with pytest.raises(InputError, match=f"{who} draws a compiled rule base, not "):
            call()


TSUKAMOTO_TERMS = """\
variables:
  x:
    role: input
    universe: [0, 10]
    terms:
      LO: {shape: left_shoulder, points: [2, 8]}
      HI: {shape: right_shoulder, points: [2, 8]}
  y:
    role: output
    universe: [0, 100]
    terms:
      UP: {shape: ramp, start: 0, end: 100}
      DOWN: {shape: ramp, start: 100, end: 0}
"""


def test_rule_view_tsukamoto_stems_stand_where_the_engine_inverts_the_terms(tmp_path):
    """Under Tsukamoto inference the viewer drew each consequent at its term's centre (UP at
    100, DOWN at 0) with the rule's DOF, so the stems' weighted mean was not the
    result the viewer printed over them: each term stands where it is inverted at its
    summed (and hedged) degree, z = mu^-1(w), as the engine averages it."""
    (tmp_path / "t.terms.yaml").write_text(TSUKAMOTO_TERMS, encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\noperators: inference = tsukamoto\n'
        "r1: if x is LO then y is UP\nr2: if x is HI then y is somewhat DOWN\n",
        encoding="utf-8")
    view = plotdata.rule_view(load_rulebase(tmp_path / "t.rules").compiled, {"x": 4.4})
    lo, hi = 0.6, 0.4                                    # LO and HI at x = 4.4
    w_up, w_down = lo, hi ** 0.5                         # r1; somewhat(r2)
    out = view.outputs[0]
    np.testing.assert_allclose(np.array(out.stems),
                               [[100 - 100 * w_down, w_down], [100 * w_up, w_up]], rtol=1e-12)
    values = np.array([v for v, _ in out.stems])
    weights = np.array([w for _, w in out.stems])
    assert (values * weights).sum() / weights.sum() == pytest.approx(out.value, rel=1e-12)
    assert [(r.label, c.term, c.value) for r in view.rows for c in r.consequents] == \
        [("r1", "UP", pytest.approx(100 * w_up)),
         ("r2", "DOWN", pytest.approx(100 - 100 * w_down))]


@pytest.mark.parametrize("accumulation", ["max", "probabilistic_sum"])
def test_rule_view_stems_join_one_values_rules_by_the_accumulation(tmp_path, accumulation):
    """With `accumulation = max` the engine weighs a value by the S-norm of its rules' DOFs
    (jFuzzyLogic's ACCU); the viewer summed them (value 10 at 1.47 where the engine weighs
    0.8), so its stems did not average to the result drawn over them."""
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  x:\n    role: input\n    universe: [0, 10]\n    terms:\n"
        "      LO: {shape: left_shoulder, points: [2, 8]}\n"
        "      MID: {shape: triangle, peak: 5, width: 5}\n"
        "      HI: {shape: right_shoulder, points: [2, 8]}\n"
        "  y: {role: output, universe: [0, 100], terms: {A: 10, B: 90}}\n", encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        f'terms "t.terms.yaml"\noperators: accumulation = {accumulation}\n'
        "r1: if x is LO then y is A\nr2: if x is MID then y is A\nr3: if x is HI then y is B\n",
        encoding="utf-8")
    view = plotdata.rule_view(load_rulebase(tmp_path / "t.rules").compiled, {"x": 4})
    lo, mid, hi = 2 / 3, 0.8, 1 / 3
    joined = max(lo, mid) if accumulation == "max" else lo + mid - lo * mid
    out = view.outputs[0]
    np.testing.assert_allclose(np.array(out.stems), [[10, joined], [90, hi]], rtol=1e-12)
    assert (10 * joined + 90 * hi) / (joined + hi) == pytest.approx(out.value, rel=1e-12)


def test_surface_says_where_the_output_is_infinite(tmp_path):
    """A Tsukamoto sigmoid inverted where its rule fires fully makes the output infinite (as
    in fuzzylite): matplotlib leaves those points out of the curve or surface, and the picture
    had a gap with no word of why (the terminal table says `inf`)."""
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  x:\n    role: input\n    universe: [0, 10]\n    terms:\n"
        "      LO: {shape: left_shoulder, points: [2, 8]}\n"
        "      HI: {shape: right_shoulder, points: [2, 8]}\n"
        "  y:\n    role: output\n    universe: [0, 100]\n    terms:\n"
        "      S: {shape: sigmoid, inflection: 50, slope: 0.1}\n"
        "      DOWN: {shape: ramp, start: 100, end: 0}\n", encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\noperators: inference = tsukamoto\n'
        "r1: if x is LO then y is S\nr2: if x is HI then y is DOWN\n", encoding="utf-8")
    rb = load_rulebase(tmp_path / "t.rules")
    s = plotdata.surface(rb.compiled, "y", "x", resolution=11)
    assert np.isinf(s.z).sum() == 3                       # x = 0, 1, 2: LO fires fully
    assert "`y` is infinite at 3 of 11 grid points (a picture leaves them out)" in " ".join(s.notes())
