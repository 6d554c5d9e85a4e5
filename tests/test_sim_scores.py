"""BARN's score and MRPB's safety on hand-computed cases, and MRPB's test files."""

from __future__ import annotations

import numpy as np
import pytest

from mitos_cli.errors import WorldError
from mitos_cli.sim import mrpb
from mitos_cli.sim.gridmap import INCH_PER_M
from mitos_cli.sim.loop import prepare
from mitos_cli.sim.route import NarrowPassage
from mitos_cli.sim.scores import BARN_SPEED_IN_S, barn_score, mrpb_safety, optimal_time
from mitos_cli.sim.world import Robot


def test_t_opt_is_the_path_over_two_metres_a_second():
    assert pytest.approx(78.74015748) == BARN_SPEED_IN_S
    assert optimal_time(10 * INCH_PER_M) == pytest.approx(5.0)


@pytest.mark.parametrize("success, t, want", [
    (True, 8.0, 0.5),          # faster than 2 t_opt: clipped up to 2 t_opt
    (True, 10.0, 0.5),         # exactly 2 t_opt
    (True, 20.0, 0.25),        # 4 t_opt
    (True, 40.0, 0.125),       # 8 t_opt
    (True, 90.0, 0.125),       # slower than 8 t_opt: clipped down to 8 t_opt
    (False, 10.0, 0.0),        # no success, no score
])
def test_barn_score(success, t, want):
    assert barn_score(success, t, 5.0) == pytest.approx(want)


def test_mrpb_safety_is_the_fraction_of_time_below_the_distance():
    assert mrpb_safety(np.array([10.0, 3.0, 5.0, 1.0]), 4.0) == 0.5
    assert mrpb_safety(np.array([4.0, 4.0]), 4.0) == 0.0          # at the distance is safe
    assert mrpb_safety(np.array([-0.5]), 4.0) == 1.0               # a contact is unsafe
    assert mrpb_safety(np.array([]), 4.0) == 0.0


def test_mrpb_tests_read_in_inches_and_degrees(tmp_path):
    path = tmp_path / "tests.txt"
    path.write_text("# comment\ntest 1: start (1.0, -2.0, 1.5708) -> goal (3.0, 0.0, 0.0)\n")
    [(number, start, goal)] = mrpb.read_tests(path)
    assert number == 1
    assert (start.x, start.y) == pytest.approx((INCH_PER_M, -2 * INCH_PER_M))
    assert start.heading == pytest.approx(90.0, abs=1e-3)
    assert (goal.x, goal.y) == pytest.approx((3 * INCH_PER_M, 0.0))


def test_a_bad_mrpb_test_line_is_positioned(tmp_path):
    path = tmp_path / "tests.txt"
    path.write_text("test 1: start (1, 2, 0) -> goal (3, 4, 0)\ntest 2: start (1, 2) -> (3, 4)\n")
    with pytest.raises(WorldError) as info:
        mrpb.read_tests(path)
    err = info.value
    assert err.span.line == 2 and "not an MRPB start/goal test" in str(err)



@pytest.mark.parametrize("pose, column, words", [
    ("(8.6.71, 2, 0)", 16, "`8.6.71` in an MRPB test is not a number"),
    ("(1e999, 2, 0)", 16, "`1e999` in an MRPB test is not a finite number"),
    ("(1, 3e5, 0)", 19, r"`3e5` in an MRPB test lies beyond ±254,000 m"),
])
def test_a_bad_number_in_an_mrpb_test_is_refused_at_its_column(tmp_path, pose, column, words):
    """`8.6.71` fits the line's pattern and was a ValueError's traceback (from
    `bench_nav.py --mrpb DIR`); `1e999` put the start at infinity."""
    path = tmp_path / "tests.txt"
    path.write_text(f"test 1: start {pose} -> goal (3, 4, 0)\n")
    with pytest.raises(WorldError, match=words) as info:
        mrpb.read_tests(path)
    assert (info.value.span.line, info.value.span.column) == (1, column)


def test_an_mrpb_tests_file_with_a_byte_order_mark_is_read(tmp_path):
    path = tmp_path / "tests.txt"
    path.write_text("\ufefftest 1: start (1, 2, 0) -> goal (3, 4, 0)\n", encoding="utf-8")
    [(number, start, _)] = mrpb.read_tests(path)
    assert number == 1 and start.x == pytest.approx(INCH_PER_M)


def test_a_scenario_becomes_one_world_per_test(tmp_path):
    folder = tmp_path / "box"
    folder.mkdir()
    pixels = np.full((40, 40), 254, np.uint8)
    pixels[0, :] = pixels[-1, :] = pixels[:, 0] = pixels[:, -1] = 0
    (folder / "map.pgm").write_bytes(b"P5\n40 40\n255\n" + pixels.tobytes())
    (folder / "map.yaml").write_text("image: map.pgm\nresolution: 0.05\norigin: [-1, -1, 0]\n"
                                     "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    (folder / "tests.txt").write_text("test 1: start (-0.5, 0, 0) -> goal (0.5, 0, 0)\n"
                                      "test 2: start (0, -0.5, 1.57) -> goal (0, 0.5, 0)\n")
    worlds = mrpb.scenario_worlds(tmp_path, "box")
    assert [w.name for w in worlds] == ["mrpb/box#1", "mrpb/box#2"]
    assert worlds[0].grid is worlds[1].grid                     # the map is read once
    assert worlds[0].time_limit == mrpb.MIN_TIME_S


def test_a_partially_unknown_scenario_is_given_its_map_and_drives_in_the_complete_one(
        tmp_path):
    for name, wall in (("office02", 20), ("office02_partially_unknown", None)):
        folder = tmp_path / name
        folder.mkdir()
        pixels = np.full((40, 40), 254, np.uint8)
        pixels[0, :] = pixels[-1, :] = pixels[:, 0] = pixels[:, -1] = 0
        if wall:
            pixels[wall, 30:] = 0                   # furniture the given map lacks
        (folder / "map.pgm").write_bytes(b"P5\n40 40\n255\n" + pixels.tobytes())
        (folder / "map.yaml").write_text("image: map.pgm\nresolution: 0.05\n"
                                         "origin: [-1, -1, 0]\nnegate: 0\n"
                                         "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
        (folder / "tests.txt").write_text("test 1: start (-0.5, 0, 0) -> goal (0.5, 0.5, 0)\n")
    [w] = mrpb.scenario_worlds(tmp_path, "office02_partially_unknown")
    assert w.knows == "given"
    assert w.grid.occupied.sum() > w.given.occupied.sum()     # the truth holds the furniture


def _scenario(root, name, pixels, test="test 1: start (-0.6, 0, 0) -> goal (0.6, 0, 0)\n"):
    folder = root / name
    folder.mkdir()
    (folder / "map.pgm").write_bytes(b"P5\n40 40\n255\n" + pixels.astype(np.uint8).tobytes())
    (folder / "map.yaml").write_text("image: map.pgm\nresolution: 0.05\norigin: [-1, -1, 0]\n"
                                     "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n")
    (folder / "tests.txt").write_text(test)


def test_the_given_maps_unknown_cells_are_planned_through_and_the_truths_are_walls(tmp_path):
    """MRPB's given maps draw the missing furniture's area unknown (205), goals inside it."""
    truth = np.full((40, 40), 254)
    truth[0, :] = truth[-1, :] = truth[:, 0] = truth[:, -1] = 0
    truth[:3, :] = truth[-3:, :] = 205                   # unknown beyond the walls: blocked
    given = truth.copy()
    given[10:30, 18:] = 205                              # where the furniture stands
    _scenario(tmp_path, "office02", truth)
    _scenario(tmp_path, "office02_partially_unknown", given)
    [w] = mrpb.scenario_worlds(tmp_path, "office02_partially_unknown")
    assert not w.given.occupied[10:30, 18:-1].any()      # unknown: free to plan through
    assert w.grid.occupied[-3:].all() and w.grid.occupied[:3].all()
    route = prepare(w).routes[0]
    assert route.length == pytest.approx(1.2 * INCH_PER_M, abs=1.0)


def test_an_mrpb_tests_time_limit_is_measured_along_its_route(tmp_path, monkeypatch):
    """A wall between start and goal with its gap at the far end: the route is three times
    the straight line, and so is the limit (``track``'s loop is five times)."""
    monkeypatch.setattr(mrpb, "MIN_TIME_S", 0.0)
    pixels = np.full((40, 40), 254)
    pixels[0, :] = pixels[-1, :] = pixels[:, 0] = pixels[:, -1] = 0
    pixels[:26, 20] = 0                                 # open only near the bottom: 0.65 m
    _scenario(tmp_path, "room02", pixels, "test 1: start (-0.5, 0.7, 0) -> goal (0.5, 0.7, 0)\n")
    [w] = mrpb.scenario_worlds(tmp_path, "room02")
    length = prepare(w).routes[0].length
    assert length > 2.5 * INCH_PER_M                   # the straight line: 1 m
    assert w.time_limit == pytest.approx(mrpb.TIME_PER_M * length / INCH_PER_M)


def test_a_refused_mrpb_test_keeps_the_straight_lines_limit(tmp_path, monkeypatch):
    monkeypatch.setattr(mrpb, "MIN_TIME_S", 0.0)
    pixels = np.full((40, 40), 254)
    pixels[0, :] = pixels[-1, :] = pixels[:, 0] = pixels[:, -1] = 0
    pixels[:, 20] = 0                                   # no way through
    _scenario(tmp_path, "room02", pixels)
    [w] = mrpb.scenario_worlds(tmp_path, "room02")
    assert w.time_limit == pytest.approx(mrpb.TIME_PER_M * 1.2)


def test_mrpb_drives_a_robot_of_mrpbs_size_through_its_22_in_gap(tmp_path):
    """track's only way is 0.56 m wide: MRPB's Pioneer passes it, the packaged tricycle not."""
    pixels = np.full((40, 40), 254)
    pixels[0, :] = pixels[-1, :] = pixels[:, 0] = pixels[:, -1] = 0
    pixels[:, 20] = 0
    pixels[15:26, 20] = 254                             # an 11-pixel gap: 0.55 m, 21.7 in
    _scenario(tmp_path, "track", pixels)
    [w] = mrpb.scenario_worlds(tmp_path, "track")
    assert w.agents[0].robot == mrpb.PIONEER
    assert prepare(w).routes[0].length > 1.2 * INCH_PER_M
    with pytest.raises(NarrowPassage, match="about 21.7 in wide"):
        prepare(mrpb.scenario_worlds(tmp_path, "track", robot=Robot())[0])
