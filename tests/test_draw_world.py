"""``mitos simulate --plot`` without matplotlib: the install hint, not a traceback."""

from __future__ import annotations

import dataclasses
import sys

import numpy as np
import pytest

from mitos_cli.cli.app import main

WORLD = """\
name: tiny
seed: 1
dt: 0.05
time_limit: 0.5
robot:
  model: tricycle
  wheelbase: 16
  footprint: {length: 24, width: 18}
q_init: {x: 30, y: -10, heading: 0}
q_goal: {x: 500, y: -10}
map:
  corridors:
    - points: [[0, 0], [600, 0]]
      width: 70
"""


@pytest.mark.parametrize("args", [["--plot", "run.png"], ["--runs", "3", "--plot", "run.png"],
                                  ["--animate", "run.gif"]])
def test_plot_without_matplotlib_says_how_to_install(tmp_path, monkeypatch, capsys, args):
    """... before the run: `--runs 1000 --plot` ran every run, then failed on the picture
    and printed no table."""
    from mitos_cli.sim import loop, runs

    world = tmp_path / "tiny.yaml"
    world.write_text(WORLD, encoding="utf-8")
    for name in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, "matplotlib", None)      # `import matplotlib` fails
    monkeypatch.setattr(loop, "simulate", lambda *a, **k: pytest.fail("the run started"))
    monkeypatch.setattr(runs, "run_many", lambda *a, **k: pytest.fail("the runs started"))
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as info:
        main(["simulate", str(world), *args])
    err = capsys.readouterr().err
    assert info.value.code == 1, err
    assert "drawing pictures needs matplotlib, which is not installed" in err
    assert "pip install 'matplotlib>=3.6' (the `plot` extra of mitos-planner)" in err and "Traceback" not in err
    assert not (tmp_path / "run.png").exists()


def test_readme_main_job_installs_what_its_picture_needs():
    """The README's first command draws `run.png`: its install must bring matplotlib."""
    from pathlib import Path

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    command = next(line for line in readme.splitlines()
                   if line.startswith("python3 -m venv") and "mitos simulate" in line)
    assert "--plot" in command and 'pip install ".[plot]"' in command, command


def test_a_generated_field_is_not_written_over_with_its_pole_names():
    pytest.importorskip("matplotlib")
    from mitos_cli.draw.world import draw_run
    from mitos_cli.sim import barn
    from mitos_cli.sim.loop import simulate

    w = barn.barn_world(0, 0.25, 3).with_changes(time_limit=0.5)
    assert len(w.obstacles) > 12
    fig = draw_run(simulate(w, None, w.seed))
    names = {o.name for o in w.obstacles}
    assert not [t for t in fig.axes[0].texts if t.get_text() in names]


def test_in_a_crowd_only_the_obstacle_hit_is_named():
    from types import SimpleNamespace

    import numpy as np

    from mitos_cli.draw.world import _labelled
    from mitos_cli.sim import barn

    w = barn.barn_world(0, 0.25, 3)
    where = np.array([[o.x, o.y] for o in w.obstacles])[None]          # [1, O, 2]
    hit = 7
    pose = np.array([[[where[0, hit, 0], where[0, hit, 1], 0.0]]])     # where it struck
    run = SimpleNamespace(world=w, outcome="collision", obstacles=where, pose=pose,
                          robot_outcomes=("collision",))
    assert _labelled(run) == {hit}
    assert _labelled(SimpleNamespace(**{**vars(run), "outcome": "success"})) == set()


@pytest.mark.parametrize("args", [["--plot", "run.png"], ["--runs", "2", "--plot", "run.png"],
                                  ["--animate", "run.gif"]])
def test_a_dollar_in_a_worlds_name_is_drawn_as_written(tmp_path, monkeypatch, capsys, args):
    pytest.importorskip("matplotlib")
    monkeypatch.chdir(tmp_path)
    (tmp_path / "w.yaml").write_text(WORLD.replace("name: tiny", 'name: "co $x^$ rridor"'))
    with pytest.raises(SystemExit) as exc:        # mathtext would stop on `$x^$`
        main(["simulate", "w.yaml", *args])
    assert exc.value.code == 0, capsys.readouterr().err
    assert (tmp_path / args[-1]).stat().st_size > 0


def test_a_large_map_is_drawn_in_blocks_that_keep_every_occupied_cell():
    """A 4,000 x 4,000 map's cells were colour-mapped and resampled one by one (4 s and 700 MB
    of a picture a few thousand pixels wide); a map of more than DRAWN_CELLS along a side is
    drawn in blocks, grey where any of its cells is occupied, each block where its cells are."""
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from mitos_cli.draw.world import DRAWN_CELLS, draw_grid
    from mitos_cli.sim.world import Grid

    cells = np.zeros((DRAWN_CELLS + 1, 30), dtype=bool)
    cells[DRAWN_CELLS, 7] = True                      # one cell in the last, partial block
    fig, ax = plt.subplots()
    draw_grid(ax, Grid(cells, 2.0, (-5.0, 1.0)))
    image = ax.get_images()[0]
    drawn = np.asarray(image.get_array())
    assert drawn.shape == (DRAWN_CELLS // 2 + 1, 15)          # blocks of 2 x 2 cells
    assert (drawn < 1.0).sum() == 1 and drawn[-1, 3] < 1.0    # the occupied cell's block
    assert image.get_extent() == [-5.0, -5.0 + 30 * 2.0, 1.0, 1.0 + (DRAWN_CELLS + 2) * 2.0]
    plt.close(fig)


@pytest.mark.parametrize("every", [np.nan, np.inf, -1.0, "1", True, 10**400],
                         ids=["nan", "inf", "-1", "text", "True", "10**400"])
def test_footprint_every_that_is_no_time_is_refused(every):
    """NaN, infinity and 10**400 met int()'s and float()'s errors, text a TypeError, and -1
    drew a footprint every tick without a word."""
    from mitos_cli.draw.world import draw_run
    from mitos_cli.errors import InputError
    from mitos_cli.sim import load_world, simulate

    result = simulate(dataclasses.replace(load_world("corridor"), time_limit=0.5))
    with pytest.raises(InputError, match="footprint_every is a number of seconds, 0 or more"):
        draw_run(result, footprint_every=every)
    draw_run(result, footprint_every=1e308)              # one footprint: the first tick's
    draw_run(result, footprint_every=0)                  # every tick


def test_the_pictures_title_shows_a_clearance_below_the_margin_as_below_it():
    """A run that came 1.99 in from what it passed, under a safety margin of 2 in: the verdict
    printed `min clearance 1.99 in; closer than the safety margin (2 in)` while the picture's
    title (and the result's repr) said `min clearance 2.0 in`."""
    pytest.importorskip("matplotlib")
    from mitos_cli.draw.world import draw_run
    from mitos_cli.sim.loop import simulate
    from mitos_cli.sim.worldfile import parse_world

    run = simulate(parse_world(WORLD, "tiny.yaml"))
    assert run.world.agents[0].robot.safety_margin == 2
    near = dataclasses.replace(run, metrics={**run.metrics, "min_clearance_in": 1.9888})
    assert "min clearance 1.99 in)" in draw_run(near).axes[0].get_title()
    assert repr(near).endswith("min clearance 1.99 in>")
    assert "min clearance 2.0 in" in draw_run(dataclasses.replace(
        run, metrics={**run.metrics, "min_clearance_in": 2.0111})).axes[0].get_title()
