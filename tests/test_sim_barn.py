"""BARN-style worlds: deterministic, a way through for the robot, start and goal free."""

from __future__ import annotations

import numpy as np
import pytest

from mitos_cli.sim import barn
from mitos_cli.sim.loop import prepare
from mitos_cli.sim.route import Clearance, clearances
from mitos_cli.sim.staticmap import build_static
from mitos_cli.sim.worldfile import load_world


def test_same_seed_same_world_other_seed_other_field():
    a, b = barn.barn_world(7, 0.25, 3), barn.barn_world(7, 0.25, 3)
    assert a == b or a.obstacles == b.obstacles
    assert np.array_equal(barn.field(7, 0.25, 3).filled, barn.field(7, 0.25, 3).filled)
    assert not np.array_equal(barn.field(7, 0.25, 3).filled, barn.field(8, 0.25, 3).filled)


def test_barn_worlds_draw_difficulties_from_the_seed():
    worlds = barn.barn_worlds(3, seed=100)
    assert [w.seed for w in worlds] == [100, 101, 102]
    assert [w.name for w in worlds] == [w.name for w in barn.barn_worlds(3, seed=100)]
    fills = {barn.difficulty(s) for s in range(40)}
    assert {f for f, _ in fills} == set(barn.FILLS)
    assert {s for _, s in fills} == set(barn.SMOOTHINGS)


def test_protocol_goal_ten_metres_ahead_within_one_metre_in_100_s():
    w = barn.barn_world(1)
    a = w.agents[0]
    assert (a.start.x, a.start.y) == (0.0, 0.0)
    assert a.goal.x == pytest.approx(393.7, abs=0.01) and a.goal.tolerance == pytest.approx(39.37, abs=0.01)
    assert w.time_limit == 100.0
    assert (w.robot.length, w.robot.width) == (20.0, 17.0)


def test_the_smoothing_follows_the_thresholds():
    f = np.zeros((5, 5), dtype=bool)
    f[2, 2] = True                                     # alone: cleared
    assert not barn.smooth(f, 1).any()
    g = np.zeros((5, 5), dtype=bool)
    g[1:4, 1:4] = True
    g[2, 2] = False                                    # 8 filled neighbours: filled
    assert barn.smooth(g, 1)[2, 2]


@pytest.mark.parametrize("seed", [0, 3, 12])
def test_a_way_through_exists_and_is_really_clear(seed):
    f = barn.field(seed, *barn.difficulty(seed))
    clearance = clearances(barn.JACKAL)[1]
    assert barn.way_through(f.filled, clearance)
    # the raster test against an exact distance: every free raster point is clear
    free = ~barn.blocked_raster(f.filled, clearance)
    step = barn.CELL / barn.RASTER
    r, c = np.nonzero(free)
    x = barn.FIELD_AHEAD + (c + 0.5) * step
    y = -barn.FIELD / 2 + (r + 0.5) * step
    boxes = barn.cell_boxes(f.filled)
    dx = np.maximum(np.maximum(boxes[:, 0] - x[:, None], x[:, None] - boxes[:, 2]), 0)
    dy = np.maximum(np.maximum(boxes[:, 1] - y[:, None], y[:, None] - boxes[:, 3]), 0)
    assert np.hypot(dx, dy).min() >= clearance - step / 2


def test_a_wall_across_the_field_has_no_way_through():
    f = np.zeros((barn.CELLS, barn.CELLS), dtype=bool)
    f[:, 10] = True
    assert not barn.way_through(f, 9.5)
    f[12:16, 10] = False                               # a 23.6 in door: 17 in robot passes
    assert barn.way_through(f, 9.5)


@pytest.mark.parametrize("known", [False, True])
def test_start_and_goal_are_free_and_the_file_round_trips(tmp_path, known):
    w = barn.barn_world(3, 0.3, 2, known=known)
    static = build_static(w)
    a = w.agents[0]
    assert static.free(np.array([[a.start.x, a.start.y], [a.goal.x, a.goal.y]])).all()
    out = tmp_path / "barn.yaml"
    barn.write_world(w, out)
    back = load_world(out)
    assert back.name == w.name and back.agents == w.agents and back.sensors == w.sensors
    if known:
        assert back.grid is not None and np.array_equal(back.grid.occupied, w.grid.occupied)
        assert back.grid.origin == pytest.approx(w.grid.origin)
        assert not back.obstacles
    else:
        assert back.obstacles == w.obstacles and back.corridors == w.corridors


def test_known_poles_lie_where_the_unknown_rectangles_are():
    f = barn.field(5, 0.25, 3)
    g = barn.grid(f.filled)
    for o in barn.obstacles(f.filled)[:10]:
        for x in np.linspace(o.x - o.length / 2 + 1, o.x + o.length / 2 - 1, 3):
            col = int((x - g.origin[0]) // g.resolution)
            row = int((o.y - g.origin[1]) // g.resolution)
            assert g.occupied[row, col]


def test_the_module_writes_a_world(tmp_path, capsys):
    out = tmp_path / "w.yaml"
    assert barn.main(["--seed", "4", "--out", str(out)]) == 0
    assert load_world(out).seed == 4


@pytest.mark.parametrize("seed", [0, 1, 3, 7, 8, 58])
def test_every_generated_field_has_the_route_its_generator_promises(seed):
    """One definition of "the robot fits": the known twin of every field has a route (seed 58
    is a hardest fill; seeds 0, 1, 3, 7 and 8 had none when the two definitions differed)."""
    w = barn.barn_world(seed, *barn.difficulty(seed), known=True)
    route = prepare(w).routes[0]
    least = clearances(barn.JACKAL)[1]
    field = Clearance.of(w.grid.occupied, w.grid.resolution, w.grid.origin)
    pts = np.concatenate([route.points[i] + np.linspace(0, 1, 50)[:, None]
                          * (route.points[i + 1] - route.points[i])
                          for i in range(len(route.points) - 1)])
    assert field.at(pts).min() >= least - 1.0     # within the lower bound's half cell


@pytest.mark.parametrize("args, says", [
    (["--seed", "-7"], "argument --seed: the seed is a whole number of 0 or more, not -7"),
    (["--seed", "x"], "argument --seed: a whole number is expected, not `x`"),
    (["--fill", "25"], "not 25 (a percentage? --fill 0.25 is 25%)"),
    (["--fill", "nan"], "in [0, 1), not nan"),
    (["--smoothing", "-1"], "from 0 to 100, not -1"),
    (["--smoothing", "1000000000"], "from 0 to 100, not 1000000000"),
])
def test_a_bad_option_value_is_a_usage_error(tmp_path, capsys, args, says):
    out = tmp_path / "w.yaml"
    with pytest.raises(SystemExit) as exc:
        barn.main(args + ["--out", str(out)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "error: argument " in err and says in err
    assert not out.exists()


@pytest.mark.parametrize("args, says", [
    (["--sed", "7"], "error: unknown option --sed; did you mean `--seed`?"),
    (["--sed=7"], "error: unknown option --sed; did you mean `--seed`?"),
    (["--see", "7"], "error: unknown option --see; did you mean `--seed`?"),   # no abbreviation
    (["--xyz"], "error: unknown option --xyz\n"),
])
def test_a_misspelt_option_is_named_with_a_did_you_mean(tmp_path, capsys, args, says):
    """`--sed 7` said "unrecognized arguments: --sed 7" (or, without --out, only that --out
    is required); `--see 7` was taken for `--seed` by argparse's abbreviations, which
    `mitos` (Click) does not take."""
    for tail in (["--out", str(tmp_path / "w.yaml")], []):
        with pytest.raises(SystemExit) as exc:
            barn.main(args + tail)
        assert exc.value.code == 2
        assert says in capsys.readouterr().err
    assert not (tmp_path / "w.yaml").exists()


def test_the_out_file_must_be_yaml(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        barn.main(["--out", str(tmp_path / "w.txt")])
    assert exc.value.code == 2
    assert "has extension .txt; the world is written to a .yaml file" in capsys.readouterr().err


@pytest.mark.parametrize("where, says", [
    ("missing/w.yaml", "No such file or directory\nhint: check that the directory exists"),
    (".", "it is a directory\nhint: give a file name inside it"),
    ("a" * 300 + ".yaml", "File name too long\nhint: each part of a path may have at most 255"),
])
def test_a_path_that_cannot_be_written_is_refused_before_the_field_is_drawn(
        tmp_path, capsys, monkeypatch, where, says):
    monkeypatch.setattr(barn, "barn_world", lambda *a, **k: pytest.fail("drew a field"))
    assert barn.main(["--out", str(tmp_path / where)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("error: cannot write") and says in err and "Traceback" not in err


def test_a_field_that_cannot_be_drawn_is_an_error_not_a_traceback(tmp_path, capsys):
    assert barn.main(["--fill", "0.95", "--smoothing", "0", "--out",
                      str(tmp_path / "w.yaml")]) == 1
    assert "error: no field with a way through" in capsys.readouterr().err


def test_the_help_says_what_each_option_takes(capsys):
    with pytest.raises(SystemExit):
        barn.main(["-h"])
    text = " ".join(capsys.readouterr().out.split())
    assert "fraction of cells filled before smoothing, in [0, 1), e.g. 0.25" in text
    assert "fill percentage" not in text
    assert "whole number >= 0 that draws the field" in text
    assert "cellular-automaton smoothing iterations, 0-100" in text


def test_a_known_world_replaces_its_own_map_but_no_other_file(tmp_path, capsys):
    out = tmp_path / "k.yaml"
    assert barn.main(["--seed", "3", "--known", "--out", str(out)]) == 0
    assert barn.main(["--seed", "3", "--known", "--out", str(out)]) == 0    # its own map
    out.unlink()                     # k.pgm is now no world file's map: the user's
    before = (tmp_path / "k.pgm").read_bytes()
    capsys.readouterr()
    assert barn.main(["--seed", "4", "--known", "--out", str(out)]) == 1
    assert "error: `" in capsys.readouterr().err
    assert (tmp_path / "k.pgm").read_bytes() == before and not out.exists()
