"""``mitos simulate WORLD --runs N --plot runs.png``: every run's path in one picture. The
overlay's data (paths per outcome, counts, collisions) is tested without pixels; the command
writes the file and prints its table and JSON as without --plot."""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_sim_multirobot import REAR_END
from typer.testing import CliRunner

from mitos_cli.cli.app import app
from mitos_cli.draw.data.overlay import runs_overlay
from mitos_cli.sim.runs import run_many, trail
from mitos_cli.sim.worldfile import load_world

RUNNER = CliRunner()


def _summary(seed, outcome, paths, own, t_end=3.0):
    return {"seed": seed, "outcome": outcome,
            "trail": {"paths": paths, "robot_outcomes": own, "t_end": t_end,
                      "obstacles": [[5.0, 6.0]]}}


def test_paths_are_grouped_by_the_runs_outcome_with_counts_and_collisions():
    runs = [_summary(1, "success", [[[0, 0], [1, 0]]], ["success"]),
            _summary(2, "collision", [[[0, 0], [2, 1], [3, 1]]], ["collision"], t_end=4.25),
            _summary(3, "success", [[[0, 0], [1, 1]]], ["success"]),
            _summary(4, "timeout", [[[0, 0]]], ["timeout"])]
    ov = runs_overlay("w", runs, ["robot"])
    assert ov.seeds == (1, 2, 3, 4)
    assert list(ov.counts.items()) == [("success", 2), ("collision", 1), ("timeout", 1)]
    assert list(ov.paths) == ["success", "collision", "timeout"]     # the legend's order
    assert [p.tolist() for p in ov.paths["success"]] == [[[0, 0], [1, 0]], [[0, 0], [1, 1]]]
    (c,) = ov.collisions
    assert (c.x, c.y, c.t, c.robot, c.seed) == (3.0, 1.0, 4.25, "robot", 2)
    assert ov.label("success") == "success (2 of 4)"
    assert [o.tolist() for o in ov.obstacles] == [[[5.0, 6.0]]] * 4


def test_collisions_at_one_place_share_one_label():
    runs = [_summary(s, "collision", [[[0, 0], [100 + s, 0]]], ["collision"], t_end=t)
            for s, t in ((1, 5.0), (2, 4.0), (3, 6.0))]
    runs.append(_summary(4, "collision", [[[0, 0], [300, 0]]], ["collision"], t_end=9.0))
    places = runs_overlay("w", runs, ["robot"]).collision_places()
    assert places == [(101.0, 0.0, 3, 4.0, 6.0), (300.0, 0.0, 1, 9.0, 9.0)]


@pytest.fixture()
def rear_end(tmp_path):
    p = tmp_path / "rearend.yaml"
    p.write_text(REAR_END, encoding="utf-8")
    return p


def test_every_robots_path_of_every_run_from_the_runs(rear_end):
    """Two runs of two robots: four paths under the run's outcome (collision), one collision a
    run (the rammed `second`, where and when its run ended)."""
    (w,) = run_many([load_world(rear_end)], 2, 1, workers=1, measure=trail).worlds
    ov = runs_overlay(w.world, w.summaries, ["robot", "second"])
    assert ov.counts == {"collision": 2} and len(ov.paths["collision"]) == 4
    assert [(c.robot, c.seed) for c in ov.collisions] == [("second", 1), ("second", 2)]
    for c, s in zip(ov.collisions, w.summaries):
        assert c.t == pytest.approx(s["time_s"])             # the colliding tick's time
        assert np.allclose([c.x, c.y], s["trail"]["paths"][1][-1])
    first = np.asarray(w.summaries[0]["trail"]["paths"][0])
    assert np.hypot(*(first[-1] - [560, -15])) <= 12          # `robot` stopped at its goal


def test_the_command_writes_the_picture_and_the_usual_output(rear_end, tmp_path):
    pytest.importorskip("matplotlib")
    png = tmp_path / "runs.png"
    res = RUNNER.invoke(app, ["simulate", str(rear_end), "--runs", "2", "--workers", "1",
                              "--plot", str(png), "--json"])
    assert res.exit_code == 0, res.output
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"wrote picture of 2 runs to {png}" in res.stderr
    (row,) = json.loads(res.stdout)
    assert row["runs"] == 2 and all("trail" not in s for s in row["runs_detail"])
    plain = RUNNER.invoke(app, ["simulate", str(rear_end), "--runs", "2", "--workers", "1",
                                "--json"])
    assert json.loads(plain.stdout) == [row]                  # --plot changes no figure


def test_plot_of_several_worlds_is_refused(rear_end, tmp_path):
    other = tmp_path / "other.yaml"              # (one world twice is refused before that)
    other.write_text(REAR_END, encoding="utf-8")
    res = RUNNER.invoke(app, ["simulate", str(rear_end), str(other), "--runs", "2",
                              "--plot", str(tmp_path / "runs.png")])
    assert res.exit_code == 2
    assert "--plot draws one world" in res.output
    assert not (tmp_path / "runs.png").exists()


LONG = """\
name: long
dt: 0.05
time_limit: 10
robot: {model: tricycle, wheelbase: 16, footprint: {length: 24, width: 18}}
q_init: {x: 30, y: 0}
q_goal: {x: 1970, y: 0}
map:
  corridors:
    - points: [[0, 0], [2000, 0]]
      width: 80
"""


def test_collision_labels_that_would_overlap_in_the_picture_share_one():
    """Collisions 25 in apart, more than the 20 in that share a label, on a map 2,000 in long
    (25 in is 0.1 in of the picture): each had its own label, drawn over one another
    (`10.910.5 s`)."""
    pytest.importorskip("matplotlib")
    from mitos_cli.draw.runs import draw_runs
    from mitos_cli.sim.loop import prepare
    from mitos_cli.sim.worldfile import parse_world

    world = parse_world(LONG, "long.yaml")
    runs = [_summary(s, "collision", [[[0, 0], [900 + 25 * s, 0]]], ["collision"],
                     t_end=10.0 + s / 10) for s in range(4)]
    runs.append(_summary(9, "collision", [[[0, 0], [1500, 0]]], ["collision"], t_end=20.0))
    overlay = runs_overlay("long", runs, ["robot"])
    assert len(overlay.collision_places()) == 5          # 25 in apart: not within 20 in
    fig = draw_runs(overlay, world, prepare(world))
    fig.canvas.draw()                     # as drawn: the map's equal aspect applied
    labels = [t for t in fig.axes[0].texts if t.get_text().endswith(" s")]
    assert sorted(t.get_text() for t in labels) == ["20.0 s", "4×, 10.0-10.3 s"]
    boxes = [t.get_window_extent() for t in labels]
    assert not boxes[0].overlaps(boxes[1])
