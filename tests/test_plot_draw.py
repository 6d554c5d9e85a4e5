"""The matplotlib drawings (mitos_cli.draw) carry the plotted data: line y-data are the
memberships, the heat map's mesh is the surface grid, the rule viewer has one row per fired
rule. No pixels are compared."""

from __future__ import annotations

import re

import numpy as np
import pytest

pytest.importorskip("matplotlib")

from mitos_cli.api import load_rulebase  # noqa: E402
from mitos_cli.draw import data as plotdata  # noqa: E402
from mitos_cli.draw.output import DrawError, check_format  # noqa: E402
from mitos_cli.draw.rules import draw_rules  # noqa: E402
from mitos_cli.draw.surface import draw_surface  # noqa: E402
from mitos_cli.draw.terms import draw_sheet, draw_terms_before_after  # noqa: E402
from mitos_cli.errors import WriteError  # noqa: E402

SAMPLE = {"road": 78.0, "size": 45.0, "position": 4.0}


@pytest.fixture(scope="module")
def mitos():
    return load_rulebase()


def visible_axes(fig):
    return [ax for ax in fig.axes if ax.get_visible() and not hasattr(ax, "_colorbar")
            and ax.get_label() != "<colorbar>"]


def test_sheet_lines_are_the_memberships(mitos):
    plots = plotdata.sheet(mitos.rulebase, values=SAMPLE)
    fig = draw_sheet(plots)
    axes = visible_axes(fig)
    assert len(axes) == len(plots)
    for ax, plot in zip(axes, plots):
        curves = [c for c in plot.curves if c.kind == "curve"]
        lines = {line.get_label(): line for line in ax.lines}
        for curve in curves:
            line = lines[curve.name]
            np.testing.assert_array_equal(line.get_xdata(), curve.x)
            np.testing.assert_array_equal(line.get_ydata(), curve.y)
        texts = {t.get_text() for t in ax.texts}
        assert {c.name for c in plot.curves} <= texts               # every term labelled
        assert plot.axis_label == ax.get_xlabel()
        if plot.value is not None:
            marker = lines[f"{plot.name} = {plot.value:g} {plot.unit}"]
            assert list(marker.get_xdata()) == [plot.value, plot.value]
            shown = {f"{mu:.2f}" for _, mu in plot.memberships if plotdata.visible(mu)}
            assert shown <= texts                                    # memberships written
        singletons = [c for c in plot.curves if c.kind == "singleton"]
        if singletons:                                               # outputs: stems
            segments = [seg for coll in ax.collections if hasattr(coll, "get_segments")
                        for seg in coll.get_segments()]
            tops = sorted(float(seg[0][0]) for seg in segments if len(seg) == 2
                          and seg[1][1] == 1.0 and seg[0][0] == seg[1][0])
            assert tops == sorted(c.center for c in singletons)


def test_sheet_single_variable_and_file(mitos, tmp_path):
    plots = plotdata.sheet(mitos.rulebase, ["size"], {"size": 45})
    path = tmp_path / "size.svg"
    fig = draw_sheet(plots, path)
    assert len(visible_axes(fig)) == 1
    assert path.read_text().lstrip().startswith(("<?xml", "<svg"))


def test_heatmap_mesh_is_the_surface_grid(mitos):
    s = plotdata.surface(mitos.compiled, "steering", "road", "position", {"size": 45},
                         resolution=7)
    fig = draw_surface(s, style="heatmap")
    ax = fig.axes[0]
    mesh = next(c for c in ax.collections if type(c).__name__ == "QuadMesh")
    np.testing.assert_array_equal(np.asarray(mesh.get_array()).reshape(s.z.shape), s.z)
    assert ax.get_xlabel() == "road [in]" and ax.get_ylabel() == "position [in]"
    assert "size = 45 in" in ax.get_title(loc="left")


def test_surface_3d_and_curve(mitos):
    s = plotdata.surface(mitos.compiled, "speed", "road", "size", {"position": 4},
                         resolution=6)
    fig = draw_surface(s, style="surface")
    ax = fig.axes[0]
    assert ax.name == "3d" and ax.get_zlabel() == "speed [in/s]"
    c = plotdata.surface(mitos.compiled, "speed", "road", None,
                         {"position": 4, "size": 45}, resolution=6)
    fig = draw_surface(c)
    (line,) = [ln for ln in fig.axes[0].lines if ln.get_label() == "speed"]
    np.testing.assert_array_equal(line.get_ydata(), c.z)
    np.testing.assert_array_equal(line.get_xdata(), c.x.values)


def test_masked_surface_says_so(tmp_path):
    from test_plotdata import GAP_RULES, GAP_TERMS

    (tmp_path / "gap.terms.yaml").write_text(GAP_TERMS)
    (tmp_path / "gap.rules").write_text(GAP_RULES)
    rb = load_rulebase(tmp_path / "gap.rules")
    s = plotdata.surface(rb.compiled, "out", "x", "y", resolution=11)
    fig = draw_surface(s, style="heatmap")
    mesh = next(c for c in fig.axes[0].collections if type(c).__name__ == "QuadMesh")
    arr = mesh.get_array()
    assert np.ma.is_masked(arr) and arr.mask.reshape(s.z.shape).tolist() == \
        s.no_rule.tolist()
    legend = fig.axes[0].get_legend()
    assert [t.get_text() for t in legend.get_texts()] == ["no rule fires (no default)"]
    curve = plotdata.surface(rb.compiled, "out", "x", None, {"y": 0.5}, resolution=11)
    fig = draw_surface(curve)
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()][-1] == \
        "no rule fires (no default)"


def test_an_infinite_output_is_not_called_no_rule_fires(tmp_path):
    """A Tsukamoto sigmoid inverted where its rule fires fully makes the output infinite:
    the heat map hatched those cells with the legend "no rule fires (no default)", where a
    rule fires fully, and the curve left a gap with no legend at all."""
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  x:\n    role: input\n    universe: [0, 10]\n    terms:\n"
        "      LO: {shape: left_shoulder, points: [2, 8]}\n"
        "      HI: {shape: right_shoulder, points: [2, 8]}\n"
        "  y: {role: input, universe: [0, 10], terms: {ANY: {shape: rectangle, points: [0, 10]}}}\n"
        "  out:\n    role: output\n    universe: [0, 100]\n    terms:\n"
        "      S: {shape: sigmoid, inflection: 50, slope: 0.1}\n"
        "      DOWN: {shape: ramp, start: 100, end: 0}\n", encoding="utf-8")
    (tmp_path / "t.rules").write_text(
        'terms "t.terms.yaml"\noperators: inference = tsukamoto\n'
        "r1: if x is LO and y is ANY then out is S\nr2: if x is HI then out is DOWN\n",
        encoding="utf-8")
    rb = load_rulebase(tmp_path / "t.rules")
    s = plotdata.surface(rb.compiled, "out", "x", "y", resolution=11)
    assert np.isinf(s.z).any() and not np.isnan(s.z).any()
    fig = draw_surface(s, style="heatmap")
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == ["`out` infinite"]
    curve = plotdata.surface(rb.compiled, "out", "x", None, {"y": 5}, resolution=11)
    fig = draw_surface(curve)
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()][-1] == \
        "`out` infinite"
    assert len(by_gid(fig, "no-rule")) == 1


def by_gid(fig, gid):
    return [a for ax in fig.axes for a in ax.get_children() if a.get_gid() == gid]


def test_rule_viewer_has_a_row_per_fired_rule(mitos):
    from mitos_cli.draw.rules import BAND

    view = plotdata.rule_view(mitos.compiled, SAMPLE)
    fig = draw_rules(view)
    ncols = len(view.inputs) + len(view.outputs)
    assert len(fig.axes) == 2 * ncols                 # rule rows, then the aggregate row
    rows = [t.get_text() for ax in fig.axes for t in ax.texts if "DOF" in t.get_text()]
    assert rows == [f"{r.label}\nDOF {r.dof:.2f}" for r in view.rows]
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert "road = 78 in" in titles
    assert f"steering = {view.outputs[0].value:.1f} deg" in titles
    n = len(view.rows)
    for k, row in enumerate(view.rows):
        base = n - 1 - k                               # first rule on top
        for p in row.props:                            # the fill reaches the membership
            line, fill = by_gid(fig, f"{row.label}:{p.var}")
            np.testing.assert_allclose(line.get_ydata(), base + BAND * p.y)
            top = max(v[1] for path in fill.get_paths() for v in path.vertices)
            assert top == pytest.approx(base + BAND * p.value)
        for c in row.consequents:                      # a stem as high as the DOF
            (stem,) = by_gid(fig, f"{row.label}:{c.output}")
            ((x0, y0), (x1, y1)), = stem.get_segments()
            assert x0 == x1 == c.value
            assert (y0, y1) == pytest.approx((base, base + BAND * row.dof))
    for out in view.outputs:                           # aggregate stems and the result line
        stems = by_gid(fig, f"aggregate:{out.name}")
        xs = sorted(float(seg[0][0]) for st in stems for seg in st.get_segments())
        assert xs == [v for v, _ in out.stems]
        (result,) = by_gid(fig, f"result:{out.name}")
        assert list(result.get_xdata()) == [out.value, out.value]


def test_rule_viewer_mamdani_sets(tmp_path):
    from test_plotdata import write_mamdani

    rb = load_rulebase(write_mamdani(tmp_path))
    view = plotdata.rule_view(rb.compiled, {"road": 80, "size": 30})
    fig = draw_rules(view)
    (out,) = view.outputs
    fill, line = by_gid(fig, "aggregate:speed")
    np.testing.assert_array_equal(line.get_ydata(), out.aggregate)
    np.testing.assert_array_equal(line.get_xdata(), out.grid)


def test_rule_viewer_caps_rows(mitos):
    view = plotdata.rule_view(mitos.compiled, SAMPLE)
    fig = draw_rules(view, max_rows=3)
    assert "the 5 weakest not shown" in fig._suptitle.get_text()
    labels = [t.get_text().split("\n")[0] for ax in fig.axes for t in ax.texts
              if "DOF" in t.get_text()]
    assert labels == ["r4", "r22", "r25"]     # the 3 strongest (r4 before r7 at a tie)


def test_before_after(mitos, tmp_path):
    road = mitos.rulebase.variables["road"]
    medium = road.term("MEDIUM")
    after = road.with_terms(tuple(t.with_params((74.0, 34.0)) if t.name == "MEDIUM" else t
                                  for t in road.terms))
    path = tmp_path / "road.png"
    fig = draw_terms_before_after(road, after, path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    ax = fig.axes[0]
    dashed = [ln for ln in ax.lines if ln.get_linestyle() == "--"]
    solid = [ln for ln in ax.lines if ln.get_linestyle() == "-"]
    assert len(dashed) == len(solid) == 3
    before_medium = next(ln for ln in dashed if ln.get_label() == "MEDIUM")
    after_medium = next(ln for ln in solid if ln.get_label() == "MEDIUM")
    np.testing.assert_array_equal(before_medium.get_ydata(),
                                  medium.membership(before_medium.get_xdata()))
    assert max(after_medium.get_xdata()[after_medium.get_ydata() == 1.0]) == 74.0
    assert any("MEDIUM: peak 70 → 74, width 30 → 34" in t.get_text() for t in ax.texts)
    assert before_medium.get_color() == after_medium.get_color()


def test_formats():
    assert check_format("a.PNG") == "png" and check_format("b.svg") == "svg"
    with pytest.raises(DrawError) as exc:
        check_format("c.pdf")
    assert "unknown picture format `pdf`" in exc.value.message
    assert exc.value.expected == "a file name ending in .png or .svg"


def test_show_without_display_is_a_clear_error(monkeypatch, mitos):
    import matplotlib

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    if matplotlib.get_backend().lower() not in ("agg",):
        pytest.skip("an interactive backend is configured here")
    with pytest.raises(DrawError) as exc:
        draw_sheet(plotdata.sheet(mitos.rulebase, ["road"]), show=True)
    assert exc.value.message.startswith("cannot open a window")
    assert "-o FILE.png" in exc.value.hint


def test_unwritable_path_is_a_clear_error(mitos, tmp_path):
    with pytest.raises(WriteError, match="cannot write"):
        draw_sheet(plotdata.sheet(mitos.rulebase, ["road"]), tmp_path / "no" / "dir.png")


ONE_INPUT = """\
variables:
  x:
    role: input
    universe: [0, 10]
    terms:
      LOW: {shape: left_shoulder, points: [2, 8]}
  speed:
    role: output
    universe: [0, 60]
    terms:
      SLOW: {shape: triangle, points: [0, 10, 20]}
"""


def test_rule_viewer_fills_each_term_up_to_its_membership(mitos):
    """A new user's third review: the fill was the term *scaled* by the membership (the
    curve is sampled at its breakpoints only, and min() of those samples joined a shoulder's
    foot to its top); docs/plots.md says "filled up to its membership". The fill's edge now
    follows the curve up to the membership, and meets it at the input value."""
    from mitos_cli.draw.rules import clipped

    x, y = clipped(np.array([0.0, 70.0, 100.0, 160.0]), np.array([0.0, 0.0, 1.0, 1.0]), 0.27)
    np.testing.assert_allclose(x, [0, 70, 78.1, 100, 160])
    np.testing.assert_allclose(y, [0, 0, 0.27, 0.27, 0.27])
    view = plotdata.rule_view(mitos.compiled, SAMPLE)
    fig = draw_rules(view)
    row = view.rows[0]
    for p in row.props:
        _, fill = by_gid(fig, f"{row.label}:{p.var}")
        edge = max((v for path in fill.get_paths() for v in path.vertices
                    if abs(v[0] - SAMPLE[p.var]) < 1e-9), key=lambda v: v[1], default=None)
        base = len(view.rows) - 1
        if edge is not None:
            assert edge[1] == pytest.approx(base + 0.8 * p.value)


@pytest.mark.parametrize("weight", ["", " with 0.8"])
def test_rule_viewer_row_labels_fit_a_narrow_figure(tmp_path, weight):
    """"OOF 0.70" for "DOF 0.70" and "gregate" for "aggregate": with one input and one
    output the labels ran off the figure's left edge."""
    (tmp_path / "x.terms.yaml").write_text(ONE_INPUT)
    (tmp_path / "one.rules").write_text(f'terms "x.terms.yaml"\nif x is LOW then speed is '
                                        f'SLOW{weight}\n')
    rb = load_rulebase(tmp_path / "one.rules")
    fig = draw_rules(plotdata.rule_view(rb.compiled, {"x": 3.0}))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    labels = [t for ax in fig.axes for t in ax.texts
              if "DOF" in t.get_text() or t.get_text() == "aggregate"]
    assert len(labels) == 2
    for t in labels:
        assert t.get_window_extent(renderer).x0 >= 0, t.get_text()


def test_every_panel_title_of_the_packaged_sheet_stays_inside_the_figure(mitos):
    """The right column's descriptions were wrapped to the panel's whole width, but a title
    starts over the axes, after the y label: `clutter`'s ran past the figure's right edge
    ("... are in" cut at the edge)."""
    fig = draw_sheet(plotdata.sheet(mitos.rulebase))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    titles = [ax._left_title for ax in visible_axes(fig)]     # (set_title(loc="left"))
    assert len(titles) == 15 and all(t.get_text() for t in titles)     # 13 inputs, 2 outputs
    for title in titles:
        assert title.get_window_extent(renderer).x1 <= fig.bbox.x1, title.get_text()


def test_a_lone_sample_where_no_rule_fires_is_hatched(tmp_path):
    """On a coarse grid a single sample where nothing fires was drawn zero wide by
    `fill_between(where=...)`: the legend named the hatching, and there was none. Each run of
    such samples is hatched up to half a step from its neighbours."""
    from test_plotdata import GAP_RULES, GAP_TERMS

    from mitos_cli.draw.surface import _nan_spans

    (tmp_path / "gap.terms.yaml").write_text(GAP_TERMS)
    (tmp_path / "gap.rules").write_text(GAP_RULES)
    rb = load_rulebase(tmp_path / "gap.rules")
    for n in (5, 11, 61):
        curve = plotdata.surface(rb.compiled, "out", "x", None, {"y": 0.5}, resolution=n)
        x, mask = curve.x.values, curve.no_rule
        assert mask.any()
        spans = _nan_spans(x, mask)
        covered = [any(lo <= xi <= hi for lo, hi in spans) for xi in x]
        assert covered == mask.tolist() and all(hi > lo for lo, hi in spans)
        assert len(by_gid(draw_surface(curve), "no-rule")) == len(spans)


def test_the_library_drawings_say_what_is_wrong_with_their_arguments(mitos, tmp_path):
    """A path that is not one met pathlib's TypeError, an unknown style a bare ValueError, an
    empty sheet max()'s "empty sequence", and surface()'s resolution 10.5 or "10", a held
    value "abc" or None and a range not a pair TypeErrors and ValueErrors from inside."""
    from mitos_cli.draw.animation import animate_run
    from mitos_cli.draw.world import draw_run
    from mitos_cli.errors import InputError
    from mitos_cli.sim import Simulation, load_world

    sim = Simulation(load_world("corridor"), seed=1)
    sim.step()
    with pytest.raises(DrawError, match="a picture is written to a file: expected a path, not "
                                        "int `3`"):
        draw_run(sim.result(), 3)
    with pytest.raises(DrawError, match="an animation is written to a file"):
        animate_run(sim.result(), None)
    c = mitos.compiled
    surface = plotdata.surface(c, "steering", "road", "position", resolution=5)
    with pytest.raises(InputError, match="unknown style `heat`") as exc:
        draw_surface(surface, tmp_path / "s.png", style="heat")
    assert exc.value.hint == "did you mean `heatmap`?"
    with pytest.raises(InputError, match="a sheet draws at least one variable"):
        draw_sheet([])
    for kwargs, says in (({"resolution": 10.5}, "resolution is a whole number, 2 or more"),
                         ({"resolution": "10"}, "resolution is a whole number, 2 or more"),
                         ({"fixed": {"size": "abc"}}, "the value held for `size` must be a"),
                         ({"fixed": {"size": None}}, "the value held for `size` is None"),
                         ({"x_range": (1, 2, 3)}, "the range of `road` is a pair (low, high)"),
                         ({"x": 3}, "unknown input (--x) `3`")):
        with pytest.raises(InputError, match=re.escape(says)):
            plotdata.surface(c, "steering", **{"x": "road", **kwargs})
    with pytest.raises(InputError, match="must be a number, not `abc`"):
        plotdata.variable_plot(mitos.rulebase.variables["road"], "abc")
    with pytest.raises(InputError, match="names is a list of variable names, not the text"):
        plotdata.sheet(mitos.rulebase, "road")


@pytest.mark.parametrize("style", ["heatmap", "surface"])
def test_no_contour_runs_along_a_plateau_at_its_last_bit(mitos, style):
    """speed over road x size is 40 across its top, computed as 40 in some cells and
    40 + 1.4e-14 in others: a contour at 40 ran wherever the last bit changed, four stripes
    labelled 40 across a flat region."""
    from matplotlib.contour import ContourSet

    s = plotdata.surface(mitos.compiled, "speed", "road", "size", fixed={"position": 4.0})
    assert s.z.max() > 40.0 and np.isclose(s.z.max(), 40.0)          # the noise is there
    fig = draw_surface(s, style=style)
    (contours,) = [c for ax in fig.axes for c in ax.get_children() if isinstance(c, ContourSet)]
    assert len(contours.levels) > 0 and max(contours.levels) < 40.0


def test_before_and_after_are_one_variable(mitos):
    """road before and size after were drawn as one variable's terms moved, without a word;
    None met an AttributeError."""
    from mitos_cli.errors import InputError

    road, size = mitos.rulebase.variables["road"], mitos.rulebase.variables["size"]
    with pytest.raises(InputError, match="before and after are two variables, `road` and `size`"):
        draw_terms_before_after(road, size, None)
    with pytest.raises(InputError, match="a variable before and after is a Variable, not NoneType"):
        draw_terms_before_after(road, None, None)
    assert draw_terms_before_after(road, road, None) is not None


def test_the_rule_viewer_and_the_sheet_say_what_they_draw(mitos):
    """draw_rules(view, max_rows="x") and 2.5 met TypeErrors, 0 and -1 were taken; a view or a
    plot that is not one met AttributeErrors."""
    from mitos_cli.errors import InputError

    view = plotdata.rule_view(mitos.compiled, SAMPLE)
    for most in ("x", 2.5, 0, -1, True, None):
        with pytest.raises(InputError, match="max_rows is a whole number, 1 or more"):
            draw_rules(view, max_rows=most)
    with pytest.raises(InputError, match="draw_rules draws a RuleView, not NoneType"):
        draw_rules(None)
    with pytest.raises(InputError, match="a sheet draws VariablePlots, not NoneType"):
        draw_sheet([None])
    assert draw_rules(view, max_rows=2) is not None


def test_a_picture_named_with_a_trailing_separator_names_a_directory(tmp_path, monkeypatch):
    """`animate_run(result, "run.gif/")` wrote `run.gif`, where `--animate run.gif/` on the
    command line is refused: `Path('run.gif/')` is `run.gif`."""
    from mitos_cli.draw.animation import animate_run
    from mitos_cli.draw.world import draw_run
    from mitos_cli.sim import Simulation, load_world

    monkeypatch.chdir(tmp_path)
    sim = Simulation(load_world("corridor"), seed=1)
    sim.step()
    for draw, name in ((animate_run, "run.gif/"), (draw_run, "run.png/")):
        with pytest.raises(DrawError, match=f"`{name}` ends in `/`, so it names a directory"):
            draw(sim.result(), name)
    assert not list(tmp_path.iterdir())
