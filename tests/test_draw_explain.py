"""Pictures that explain themselves: time marks on moving things, a colour and legend entry per
robot, a collision's marker and time, labels that stay inside the map, singleton stems in the
Mamdani rule viewer and visible medians in the study's boxes."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("matplotlib")

from mitos_cli.draw import rules as rules_draw  # noqa: E402
from mitos_cli.draw.world import ROBOT_COLOURS, draw_run, inward, time_step  # noqa: E402
from mitos_cli.sim.loop import simulate  # noqa: E402
from mitos_cli.sim.worldfile import load_world  # noqa: E402

# two robots passing in a short corridor, a box sliding toward them: about 5 s
WORLD = """\
name: meet
seed: 2
dt: 0.05
time_limit: 5
robot:
  model: tricycle
  wheelbase: 16
  footprint: {length: 24, width: 18}
q_init: {x: 30, y: -12, heading: 0}
q_goal: {x: 330, y: -12, tolerance: 12}
robots:
  - name: other
    q_init: {x: 330, y: 12, heading: 180}
    q_goal: {x: 30, y: 12, tolerance: 12}
map:
  corridors:
    - points: [[0, 0], [360, 0]]
      width: 90
obstacles:
  - {name: slider, shape: circle, at: [200, 35], radius: 5, velocity: [-10, 0]}
"""


@pytest.fixture(scope="module")
def meeting(tmp_path_factory):
    path = tmp_path_factory.mktemp("w") / "meet.yaml"
    path.write_text(WORLD)
    return simulate(load_world(path))


def texts(fig) -> list[str]:
    return [t.get_text() for ax in fig.axes for t in ax.texts]


def test_time_steps_are_round_and_few():
    assert [time_step(t) for t in (4.0, 5.0, 27.05, 60.0, 400.0)] == [1, 1, 5, 10, 120]


def test_labels_near_an_edge_face_the_middle():
    from mitos_cli.draw.output import new_figure

    ax = new_figure((4, 3)).add_subplot(1, 1, 1)
    ax.set_xlim(0, 100)
    ax.set_ylim(0, 100)
    right = inward(ax, 95, 5)
    assert right["ha"] == "right" and right["xytext"][0] < 0 and right["va"] == "bottom"
    left = inward(ax, 5, 95)
    assert left["ha"] == "left" and left["xytext"][0] > 0 and left["va"] == "top"
    assert inward(ax, 5, 5, above=False)["va"] == "top"


def test_several_robots_get_a_colour_each_and_moving_things_time_marks(meeting):
    fig = draw_run(meeting)
    (ax,) = [a for a in fig.axes if a.get_legend() is not None]
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    for i, name in enumerate(("robot", "other")):
        assert f"{name}: {meeting.robot_outcomes[i]}" in legend
        line = next(ln for ln in ax.lines if ln.get_label().startswith(f"{name}:"))
        assert line.get_color() == ROBOT_COLOURS[i]
    assert "obstacle track" in legend and "time marks (s)" in legend
    marks = [t for t in texts(fig) if t.endswith(" s") and t[:-2].isdigit()]
    # the slider's track and both robots' paths, every second (the labels near a track's end
    # left out): at least one mark each, all whole seconds within the run
    assert len(marks) >= 3 and all(1 <= int(m[:-2]) <= meeting.t[-1] for m in marks)
    assert not any(c.get_label() == "speed (in/s)" for c in fig.axes)   # no speed colourbar


def test_a_collision_is_marked_with_its_time():
    result = simulate(load_world("worlds/figure4.yaml"))
    fig = draw_run(result)
    assert result.outcome == "collision"
    assert f"collision at {result.metrics['time_s']:.2f} s" in texts(fig)
    ax = fig.axes[0]
    (x_mark,) = [ln for ln in ax.lines if ln.get_marker() == "x"]
    assert np.allclose(x_mark.get_xydata()[0], result.pose[-1, 0, :2])


def test_singletons_are_found_and_wide_sets_are_not():
    grid = np.linspace(0, 10, 101)
    y = np.zeros_like(grid)
    y[30], y[70:72] = 0.4, (0.2, 0.9)
    assert rules_draw.spikes(grid, y) == [(3.0, 0.4), (pytest.approx(7.1), 0.9)]
    y[10:20] = 0.5
    assert rules_draw.spikes(grid, y) is None
    assert rules_draw.spikes(grid, np.zeros_like(grid)) is None


def test_mamdani_viewer_draws_singletons_as_stems_under_their_titles():
    from mitos_cli import load_rulebase
    from mitos_cli.draw.data import rule_view

    rb = load_rulebase().with_operators(inference="mamdani")
    # one rule fires (r0: RS 110, MEDIUM 40): the case whose titles overlapped the row above
    view = rule_view(rb.compiled, {"road": 150.0, "size": 5.0, "position": -50.0})
    fig = rules_draw.draw_rules(view)
    (ax,) = [a for a in fig.axes if any(c.get_gid() == "aggregate:steering"
                                        for c in a.collections)]
    stems = [c for c in ax.collections if c.get_gid() == "aggregate:steering"]
    (segment,) = [seg for c in stems for seg in c.get_segments()]
    assert segment[0][0] == pytest.approx(110, abs=1.5) and segment[1][1] == pytest.approx(1.0)
    (row,) = [c for a in fig.axes for c in a.collections if c.get_gid() == "r0:steering"
              and len(c.get_segments()[0]) == 2 and c.get_linestyle()[0][1] is None]
    assert row.get_segments()[0][0][0] == 110.0          # the singleton's own value
    fig.canvas.draw()
    title = ax.title.get_window_extent()
    above = [a for a in fig.axes if a.get_position().y0 > ax.get_position().y1]
    assert title.y1 <= min(a.get_window_extent().y0 for a in above)


def test_study_boxes_have_black_medians(tmp_path, monkeypatch):
    from mitos_cli.draw import study

    rows = [{"world": "w", "min_clearance_in": v, "c": c}
            for c in ("a", "b") for v in (1.0, 2.0, 3.0, 4.0)]
    seen = {}
    monkeypatch.setattr(study, "_save", lambda fig, plt, path: seen.setdefault("fig", fig))
    study.clearance_boxes(rows, ["w"], ["a", "b"], lambda r: r["c"], tmp_path / "c.png")
    medians = [ln for ln in seen["fig"].axes[0].lines if len(ln.get_xdata()) == 2 and
               ln.get_ydata()[0] == ln.get_ydata()[1] == 2.5]
    assert len(medians) == 2 and all(ln.get_color() == "black" for ln in medians)


def test_a_one_world_clearance_plot_keeps_its_title_and_legend_entries_whole(tmp_path,
                                                                             monkeypatch):
    """One world's panel is 4.2 in wide: the title ran off both edges ("m clearance over all
    runs ... whiskers: 1"), and the legend was wrapped inside an entry ("3: fuzzy" /
    "and=lukasiewicz")."""
    from mitos_cli.draw import study

    labels = ["fuzzy and=min", "fuzzy and=product", "fuzzy and=lukasiewicz",
              "fuzzy and=einstein", "dwa"]
    rows = [{"world": "w", "min_clearance_in": v, "c": c} for c in labels for v in (1.0, 3.0)]
    seen = []
    monkeypatch.setattr(study, "_save", lambda fig, plt, path: seen.append(fig))
    study.clearance_boxes(rows, ["w"], labels, lambda r: r["c"], tmp_path / "c.png")
    fig = seen[0]
    fig.canvas.draw()
    box = fig._suptitle.get_window_extent()
    assert box.x0 >= 0 and box.x1 <= fig.bbox.width
    legend = next(t for t in fig.texts if t is not fig._suptitle).get_text().split("\n")
    assert [entry for line in legend for entry in line.split("   ")] == [
        f"{j + 1}: {label}" for j, label in enumerate(labels)]
    assert study._packed(["1: a b", "2: c d", "3: e"], 15) == ["1: a b   2: c d", "3: e"]
    assert study._packed(["1: a b", "2: c d", "3: e"], 12) == ["1: a b", "2: c d", "3: e"]


def test_study_plots_tell_worlds_of_one_stem_apart(tmp_path, monkeypatch):
    """`a/t.yaml` and `b/t.yaml` were two groups, two panels, both named `t`, where the
    tables name them by their paths."""
    from types import SimpleNamespace

    from mitos_cli.draw import study

    worlds = ["a/t.yaml", "b/t.yaml", "c/u.yaml"]
    seen = []
    monkeypatch.setattr(study, "_save", lambda fig, plt, path: seen.append(fig))
    rows = [{"world": w, "min_clearance_in": 1.0, "c": "x"} for w in worlds]
    study.clearance_boxes(rows, worlds, ["x"], lambda r: r["c"], tmp_path / "c.png")
    rate = SimpleNamespace(k=1, n=2, lo=0.1, hi=0.9)
    summaries = [SimpleNamespace(world=w, choice=SimpleNamespace(label="x"),
                                 rates={"success": rate}) for w in worlds]
    study.success_bars(summaries, worlds, ["x"], tmp_path / "s.png")
    boxes, bars = seen
    assert [ax.get_title() for ax in boxes.axes[:3]] == ["a/t.yaml", "b/t.yaml", "u"]
    assert [t.get_text() for t in bars.axes[0].get_xticklabels()] == ["a/t.yaml", "b/t.yaml",
                                                                       "u"]


def test_no_robot_takes_a_colour_the_picture_uses_for_something_else(tmp_path):
    """A new user's third review: in a three-robot world the third robot's path was the
    purple of the "replanned route" line. No robot colour is one the plot gives the route, a
    replanned route, obstacles or the start and goal, nor near one (RGB distance > 50)."""
    from mitos_cli.draw.world import REPLANNED_COLOUR, RESERVED

    def rgb(c: str) -> tuple[int, ...]:
        return tuple(int(c[k:k + 2], 16) for k in (1, 3, 5))

    for robot in ROBOT_COLOURS:
        assert min(sum((a - b) ** 2 for a, b in zip(rgb(robot), rgb(r))) ** 0.5
                   for r in RESERVED) > 50, robot
    assert len(set(ROBOT_COLOURS)) == len(ROBOT_COLOURS)
    three = WORLD.replace("time_limit: 5", "time_limit: 1").replace(
        "map:\n", "  - name: third\n    q_init: {x: 180, y: -30, heading: 0}\n"
                  "    q_goal: {x: 330, y: -30, tolerance: 12}\nmap:\n")
    path = tmp_path / "three.yaml"
    path.write_text(three)
    fig = draw_run(simulate(load_world(path)))
    (ax,) = [a for a in fig.axes if a.get_legend() is not None]
    paths = [ln.get_color() for ln in ax.lines
             if ln.get_label().split(":")[0] in ("robot", "other", "third")]
    assert paths == list(ROBOT_COLOURS[:3]) and REPLANNED_COLOUR not in paths


def test_study_plots_draw_dollars_as_written(tmp_path):
    """A world's or choice's name with `$x^$` stopped the study's plots in matplotlib's
    mathtext (the layout measured the texts before they were made literal, and wrap=True
    measures them as mathtext whatever parse_math says)."""
    from types import SimpleNamespace

    from mitos_cli.draw import study

    rows = [{"world": "w $x^$", "min_clearance_in": 1.0, "c": "a $x^$"}]
    study.clearance_boxes(rows, ["w $x^$"], ["a $x^$"], lambda r: r["c"], tmp_path / "c.png")
    rate = SimpleNamespace(k=3, n=4, lo=0.3, hi=0.9)
    summary = SimpleNamespace(world="w $x^$", choice=SimpleNamespace(label="a $x^$"),
                              rates={"success": rate})
    study.success_bars([summary], ["w $x^$"], ["a $x^$"], tmp_path / "s.png")
    assert (tmp_path / "c.png").stat().st_size > 0 and (tmp_path / "s.png").stat().st_size > 0


@pytest.mark.parametrize("worlds", [
    ["a_rather_long_world_file_name_for_the_corridor.yaml", "ok.yaml", "b31.yaml",
     "all worlds"],
    ["corridor", "slalom", "figure4"],
    [f"w{k}_{'x' * (k % 3) * 9}.yaml" for k in range(9)]])
def test_study_success_bars_never_write_one_worlds_name_over_anothers(tmp_path, monkeypatch,
                                                                     worlds):
    """`mitos compare a_rather_long_world_file_name_for_the_corridor.yaml ok.yaml b31.yaml`
    wrote the first name across the second (`..._for_the_corrok dor`)."""
    from types import SimpleNamespace

    from mitos_cli.draw import study

    labels = ["fuzzy and=min", "fuzzy and=product", "potential_field", "dwa"]
    seen = []
    monkeypatch.setattr(study, "_save", lambda fig, plt, path: seen.append(fig))
    rate = SimpleNamespace(k=1, n=2, lo=0.1, hi=0.9)
    summaries = [SimpleNamespace(world=w, choice=SimpleNamespace(label=c),
                                 rates={"success": rate}) for w in worlds for c in labels]
    study.success_bars(summaries, worlds, labels, tmp_path / "s.png")
    fig = seen[0]
    fig.canvas.draw()
    boxes = [t.get_window_extent() for t in fig.axes[0].get_xticklabels()]
    assert len(boxes) == len(worlds)
    for a, b in zip(boxes, boxes[1:]):
        assert not a.overlaps(b), (a, b)
    assert all(b.x0 >= 0 and b.x1 <= fig.bbox.width and b.y0 >= 0 for b in boxes)
    (legend,) = fig.legends or [fig.axes[0].get_legend()]
    key = legend.get_window_extent()
    assert not any(key.overlaps(b) for b in boxes) and key.y0 >= 0


def test_study_clearance_panels_keep_a_long_worlds_name_over_its_own_panel(tmp_path,
                                                                           monkeypatch):
    """A world's name wider than its panel ran into the next panel's title."""
    from mitos_cli.draw import study

    worlds = ["the_long_corridor_with_two_boxes_and_a_cart_on_the_left_side.yaml", "ok.yaml",
              "b31.yaml"]
    rows = [{"world": w, "min_clearance_in": v, "c": "x"} for w in worlds for v in (1.0, 2.0)]
    seen = []
    monkeypatch.setattr(study, "_save", lambda fig, plt, path: seen.append(fig))
    study.clearance_boxes(rows, worlds, ["x"], lambda r: r["c"], tmp_path / "c.png")
    fig = seen[0]
    fig.canvas.draw()
    for ax in fig.axes[:3]:
        title, panel = ax.title.get_window_extent(), ax.get_window_extent()
        assert panel.x0 - 20 <= title.x0 and title.x1 <= panel.x1 + 20, ax.get_title()
    assert fig.axes[0].get_title().replace("\n", "") == worlds[0][:-5]


EIGHT = """\
name: eight
seed: 2
dt: 0.05
time_limit: 8
robot: {model: tricycle, wheelbase: 16, footprint: {length: 24, width: 18}, give_way: false}
q_init: {x: 20, y: 0, heading: 0}
q_goal: {x: 400, y: 300}
map:
  corridors:
    - points: [[0, 0], [400, 0], [400, 320]]
      width: 80
obstacles:
  - {name: box1, shape: circle, at: [200, -10], radius: 10}
  - {name: crate, shape: rectangle, at: [410, 150], length: 20, width: 20, angle: 30}
robots:
""" + "".join(f"  - name: r{k}\n    q_init: {{x: {20 + 45 * k}, y: {-20 if k % 2 else 20}, "
              f"heading: 0}}\n    q_goal: {{x: 400, y: {300 - 35 * k}}}\n" for k in range(1, 8))


def test_eight_robots_are_told_apart_and_one_collision_place_has_one_label(tmp_path):
    """Of eight robots, `robot` and `r6` were drawn in one blue and `r1` and `r7` in one
    orange, and r3 and r4, which ran into each other 23 in apart, had two labels
    `collision at 5.05 s` drawn over one another (the robots do not give way to each other
    here, as before they could: giving way, none collides)."""
    path = tmp_path / "eight.yaml"
    path.write_text(EIGHT, encoding="utf-8")
    res = simulate(load_world(path))
    assert res.robot_outcomes.count("collision") == 2
    fig = draw_run(res)
    ax = fig.axes[0]
    names = {a.name for a in res.world.agents}
    paths = [ln for ln in ax.lines if ln.get_label().split(":")[0] in names]
    assert len(paths) == 8
    assert len({(ln.get_color(), ln.get_linestyle()) for ln in paths}) == 8
    fig.canvas.draw()
    labels = [t.get_window_extent() for t in ax.texts if t.get_text().startswith("collision")]
    assert labels and not any(a.overlaps(b) for k, a in enumerate(labels)
                              for b in labels[k + 1:])
