"""World files: every complaint names the file, line and column (one test per error)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.errors import WorldError
from mitos_cli.sim.world import Robot
from mitos_cli.sim.worldfile import load_world, parse_world, resolve_world_path

BASE = """\
name: t
seed: 1
dt: 0.05
time_limit: 10
robot:
  model: tricycle
  wheelbase: 16
  footprint: {length: 24, width: 18}
q_init: {x: 30, y: 0, heading: 0}
q_goal: {x: 300, y: 0}
map:
  corridors:
    - points: [[0, 0], [400, 0]]
      width: 70
"""


def error(text: str, path: str = "w.yaml") -> str:
    with pytest.raises(WorldError) as info:
        parse_world(text, path)
    return info.value.render()


def test_the_base_world_loads():
    w = parse_world(BASE, "w.yaml")
    assert w.name == "t" and w.robot.wheelbase == 16 and w.robot.max_speed == 60
    assert w.agents[0].goal.tolerance == 12 and w.behavior == "drive"
    assert w.corridors[0].width == 70


def test_unknown_top_level_key_suggests_the_closest():
    msg = error(BASE + "time_limt: 5\n")
    assert "w.yaml:15:1" in msg and "unknown key `time_limt`" in msg
    assert "did you mean `time_limit`?" in msg


def test_unknown_robot_key_points_at_its_line():
    msg = error(BASE.replace("  wheelbase: 16", "  wheelbas: 16"))
    assert "w.yaml:7:3" in msg and "did you mean `wheelbase`?" in msg


def test_a_bad_coordinate_is_pointed_at_itself_not_its_list():
    msg = error(BASE.replace("[[0, 0], [400, 0]]", "[[0, 0], [400, far]]"))
    assert msg.startswith("w.yaml:13:30: world error: a point of `points` of corridor 1 must be "
                          "a number, not `far`")
    assert msg.splitlines()[2] == " " * 33 + "^"


def test_missing_field_names_what_to_add():
    msg = error(BASE.replace("q_goal: {x: 300, y: 0}\n", ""))
    assert "missing `q_goal`" in msg and "w.yaml:1:1" in msg


def test_missing_footprint():
    msg = error(BASE.replace("  footprint: {length: 24, width: 18}\n", ""))
    assert "missing `footprint` in robot" in msg and "w.yaml:6:3" in msg


def test_start_inside_a_wall():
    msg = error(BASE.replace("q_init: {x: 30, y: 0", "q_init: {x: 30, y: 50"))
    assert "w.yaml:9:9" in msg and "start (q_init) at (30, 50) lies inside a wall" in msg


def test_goal_inside_a_wall():
    msg = error(BASE.replace("q_goal: {x: 300, y: 0}", "q_goal: {x: 500, y: 0}"))
    assert "w.yaml:10:9" in msg and "goal (q_goal)" in msg and "inside a wall" in msg


def test_unknown_obstacle_shape():
    msg = error(BASE + "obstacles:\n  - {name: a, shape: circel, at: [100, 0], radius: 5}\n")
    assert "w.yaml:16:" in msg and "did you mean `circle`?" in msg


def test_velocity_and_waypoints_together():
    msg = error(BASE + "obstacles:\n  - {name: a, shape: circle, at: [100, 0], radius: 5,"
                       " velocity: [1, 0], waypoints: [[200, 0]], speed: 3}\n")
    assert "both `velocity` and `waypoints`" in msg


def test_randomise_names_an_unknown_obstacle():
    msg = error(BASE + "obstacles:\n  - {name: box, shape: circle, at: [100, 0], radius: 5}\n"
                       "randomise:\n  obstacles:\n    boxx: {dx: [-1, 1]}\n")
    assert "w.yaml:19:5" in msg and "did you mean `box`?" in msg


def test_a_number_that_is_not_one():
    msg = error(BASE.replace("dt: 0.05", "dt: fast"))
    assert "w.yaml:3:5" in msg and "must be a number" in msg


@pytest.mark.parametrize("old, new, unit", [("dt: 0.05", "dt: 50ms", "ms"),
                                             ("wheelbase: 16", "wheelbase: 16 in", "in"),
                                             ("x: 300", "x: 300in", "in")])
def test_a_number_with_a_unit_is_told_to_drop_it(old, new, unit):
    """`wheelbase: 16in` said "must be a number, not `16in`" and no more: the hint says to write
    the number alone and what a world's numbers are in (not `50`: 50ms is not 50 s)."""
    msg = error(BASE.replace(old, new))
    assert msg.splitlines()[-1] == (f"hint: write the number alone, without `{unit}`: a world's "
                                    f"numbers are in inches, seconds and degrees")
    assert "hint" not in error(BASE.replace("dt: 0.05", "dt: fast"))    # no unit: no hint


def test_steering_limits_must_bracket_straight():
    msg = error(BASE.replace("  wheelbase: 16\n", "  wheelbase: 16\n  steering: {min: 100}\n"))
    assert "min < straight < max" in msg


def test_invalid_yaml_has_a_position():
    msg = error(BASE + "obstacles: [\n")
    assert "invalid YAML" in msg and "w.yaml:" in msg


def test_unreadable_map_image(tmp_path: Path):
    (tmp_path / "map.yaml").write_text("image: missing.pgm\nresolution: 0.05\n"
                                       "origin: [0, 0, 0]\n", encoding="utf-8")
    world = tmp_path / "w.yaml"
    world.write_text(BASE.replace("  corridors:\n    - points: [[0, 0], [400, 0]]\n"
                                  "      width: 70\n", "  grid: map.yaml\n"), encoding="utf-8")
    with pytest.raises(WorldError) as info:
        load_world(world)
    msg = info.value.render()
    assert "map.yaml:1:8" in msg and re.search(r"map image `.*missing\.pgm` (\(\d+ characters\) )?not found", msg)


def test_a_map_image_that_is_not_a_pgm(tmp_path: Path):
    (tmp_path / "map.pgm").write_bytes(b"\x89PNG not a pgm")
    (tmp_path / "map.yaml").write_text("image: map.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n",
                                       encoding="utf-8")
    world = tmp_path / "w.yaml"
    world.write_text(BASE.replace("  corridors:\n    - points: [[0, 0], [400, 0]]\n"
                                  "      width: 70\n", "  grid: map.yaml\n"), encoding="utf-8")
    with pytest.raises(WorldError, match="not a PGM image"):
        load_world(world)


def test_a_rotated_map_is_turned_about_its_origin(tmp_path: Path):
    # rotated maps used to be refused; the yaw is now honoured (tests/test_sim_gridmap.py)
    from mitos_cli.sim.gridmap import load_map_yaml

    (tmp_path / "map.pgm").write_bytes(b"P5 2 2 255\n" + bytes([254, 254, 254, 254]))
    (tmp_path / "map.yaml").write_text("image: map.pgm\nresolution: 0.05\n"
                                       "origin: [0, 0, 3.14]\n", encoding="utf-8")
    grid = load_map_yaml(tmp_path / "map.yaml")
    assert grid.origin[0] < -3.9 and grid.origin[1] < -3.9     # it lies left of and below


def _free_map(tmp_path: Path, corridors: str = "") -> Path:
    """A world on a free 10 x 10 ft map (120 in a side at 1 in a cell, lower left at 0, 0)."""
    (tmp_path / "map.pgm").write_bytes(b"P5 120 120 255\n" + bytes([254]) * 120 * 120)
    (tmp_path / "map.yaml").write_text("image: map.pgm\nresolution: 0.0254\n"
                                       "origin: [0, 0, 0]\n", encoding="utf-8")
    world = tmp_path / "w.yaml"
    world.write_text(BASE.replace("q_init: {x: 30, y: 0", "q_init: {x: 30, y: 60")
                     .replace("  corridors:\n    - points: [[0, 0], [400, 0]]\n"
                              "      width: 70\n", "  grid: map.yaml\n" + corridors),
                     encoding="utf-8")
    return world


def test_a_goal_off_the_map_is_outside_the_map_not_inside_a_wall(tmp_path: Path):
    """Off a grid all is solid, but "inside a wall ... move it into a corridor" told the user
    of a wrong `origin` or a corridor carved past the map's edge what they had done."""
    with pytest.raises(WorldError) as info:
        load_world(_free_map(tmp_path))                   # the goal at (300, 0)
    msg = info.value.render()
    assert ("w.yaml:10:9: world error: the goal (q_goal) at (300, 0) lies outside the map "
            "`map.yaml` (x 0 to 120, y 0 to 120 in)") in msg
    assert "check the map's `origin` and `resolution`" in msg



def test_a_goal_in_an_unknown_cell_says_so_and_how_to_read_it_free(tmp_path: Path):
    """A goal in the grey (unknown) part of a SLAM map was "inside a wall ... move it into a
    corridor": the user looked for a wall in a room the scan had left grey."""
    path = _free_map(tmp_path)
    pixels = bytearray([254]) * 120 * 120
    for row in range(50, 70):                       # grey 205 round (100, 60): unknown
        pixels[row * 120 + 90:row * 120 + 110] = bytes([205]) * 20
    (tmp_path / "map.pgm").write_bytes(b"P5 120 120 255\n" + bytes(pixels))
    path.write_text(path.read_text().replace("q_goal: {x: 300, y: 0}", "q_goal: {x: 100, y: 60}"))
    with pytest.raises(WorldError) as info:
        load_world(path)
    msg = info.value.render()
    assert ("w.yaml:10:9: world error: the goal (q_goal) at (100, 60) lies in an unknown cell of "
            "the map `map.yaml` (grey, between its free_thresh and occupied_thresh), which counts "
            "as a wall") in msg
    assert "`unknown: free` under `map:`" in msg
    path.write_text(path.read_text().replace("  grid: map.yaml\n",
                                             "  grid: map.yaml\n  unknown: free\n"))
    assert load_world(path).grid is not None
    (tmp_path / "map.pgm").write_bytes(b"P5 120 120 255\n" + bytes(pixels).replace(b"\xcd", b"\0"))
    path.write_text(path.read_text().replace("  unknown: free\n", ""))
    with pytest.raises(WorldError, match=r"at \(100, 60\) lies inside a wall"):
        load_world(path)                            # black there: a wall, as before


def test_a_start_or_goal_in_a_wall_of_a_map_is_offered_the_nearest_point_with_room(
        tmp_path: Path):
    """On a user's own map nothing says which coordinates are free, and the world cannot be
    drawn until it loads: "lies inside a wall, move it into a corridor" left the user to guess.
    The hint names the nearest point where the robot has room turned any way, and that point
    loads."""
    path = _free_map(tmp_path)
    pixels = bytearray([254]) * 120 * 120
    for row in range(120):                          # x 0 to 80 in: a wall; free beyond
        pixels[row * 120:row * 120 + 80] = bytes([0]) * 80
    (tmp_path / "map.pgm").write_bytes(b"P5 120 120 255\n" + bytes(pixels))
    text = path.read_text().replace("q_goal: {x: 300, y: 0}", "q_goal: {x: 100, y: 30}")
    for start in ("{x: 30, y: 60", "{x: 79, y: 100", "{x: 85, y: 60"):   # in the wall, at it
        path.write_text(text.replace("q_init: {x: 30, y: 60", "q_init: " + start))
        with pytest.raises(WorldError) as info:
            load_world(path)
        found = re.search(r"the nearest point with room for the robot turned any way: "
                          r"\((-?\d+), (-?\d+)\)", info.value.hint or "")
        assert found, info.value.render()
        x, y = int(found.group(1)), int(found.group(2))
        assert 80 + 15 <= x <= 120 - 15 and 15 <= y <= 120 - 15    # half the diagonal: 15
        path.write_text(text.replace("q_init: {x: 30, y: 60", f"q_init: {{x: {x}, y: {y}"))
        assert load_world(path).agents[0].start.x == x            # the point offered loads
    # a map of corridors has no grid to look in: the hint stays as it was
    assert "move it into a corridor" in error(BASE.replace("q_init: {x: 30, y: 0",
                                                           "q_init: {x: 30, y: 100"))


def test_a_start_whose_body_reaches_into_grey_says_so(tmp_path: Path):
    """A body reaching into the grey (unknown) part of a map was said to reach "into a wall";
    black there, it still is."""
    path = _free_map(tmp_path)                      # the start at (30, 60) heading 0
    path.write_text(path.read_text().replace("q_goal: {x: 300, y: 0}", "q_goal: {x: 100, y: 100}"))
    pixels = bytearray([254]) * 120 * 120
    for row in range(50, 70):                       # grey from x = 40, under the body's nose
        pixels[row * 120 + 40:row * 120 + 60] = bytes([205]) * 20
    (tmp_path / "map.pgm").write_bytes(b"P5 120 120 255\n" + bytes(pixels))
    with pytest.raises(WorldError) as info:
        load_world(path)
    assert info.value.message.endswith("the robot's body (24 x 18 in) reaches into an unknown "
                                       "cell of the map `map.yaml` (grey, between its "
                                       "free_thresh and occupied_thresh), which counts as a wall")
    assert "`unknown: free` under `map:`" in info.value.hint
    (tmp_path / "map.pgm").write_bytes(b"P5 120 120 255\n" + bytes(pixels).replace(b"\xcd", b"\0"))
    with pytest.raises(WorldError, match=r"reaches into a wall\n"):
        load_world(path)


@pytest.mark.parametrize("grid, said", [("", "`grid` in map is empty"),
                                        ("[map.yaml]", "`grid` in map must be a map_server "
                                                       "YAML file, not a list")])
def test_an_empty_grid_is_said_so_not_a_map_file_none(tmp_path: Path, grid, said):
    """`grid:` left empty was "map file `None` not found"; `grid: [map.yaml]` was "map file
    `['map.yaml']` not found"."""
    path = _free_map(tmp_path)
    path.write_text(path.read_text().replace("grid: map.yaml", f"grid: {grid}".rstrip()))
    with pytest.raises(WorldError) as info:
        load_world(path)
    assert info.value.message == said and info.value.span.source_line.startswith("  grid:")
    assert "None" not in info.value.render() and "maps/office.yaml" in info.value.hint


def test_a_yaw_past_a_whole_turn_is_warned_of_as_likely_degrees(tmp_path: Path):
    """`origin: [0, 0, 90]` (90 degrees meant) turned the map by 90 rad, 116.6 degrees past 14
    turns, without a word: map_server's yaw is in radians, within ±pi as map_saver writes it."""
    path = _free_map(tmp_path)
    path.write_text(path.read_text().replace("q_init: {x: 30, y: 60, heading: 0}",
                                             "q_init: {x: -80, y: 27, heading: 0}")
                    .replace("q_goal: {x: 300, y: 0}", "q_goal: {x: -60, y: 27}"))
    (tmp_path / "map.yaml").write_text("image: map.pgm\nresolution: 0.0254\n"
                                       "origin: [0, 0, 90]\n", encoding="utf-8")
    [note] = load_world(path).notes
    assert note == (f"{tmp_path / 'map.yaml'}:3:16: the origin's yaw 90 is in radians and turns "
                    "the map by 116.6 degrees (a yaw past a whole turn is likely degrees: 90 "
                    "degrees is 1.5708 rad)")
    (tmp_path / "map.yaml").write_text("image: map.pgm\nresolution: 0.0254\n"
                                       "origin: [0, 0, -3.14]\n", encoding="utf-8")
    path.write_text(path.read_text().replace("{x: -80, y: 27, heading: 0}",
                                             "{x: -60, y: -60, heading: 0}")
                    .replace("{x: -60, y: 27}", "{x: -40, y: -60}"))
    assert load_world(path).notes == ()


def test_a_corridor_carved_past_the_maps_edge_grows_the_map(tmp_path: Path):
    """A corridor carved into a map ended at the map's edge without a word (all beyond it
    solid), and a goal in it was "inside a wall": the map now grows, by whole cells of wall,
    to hold its corridors, its own cells where they were."""
    from mitos_cli.sim.loop import simulate
    from mitos_cli.sim.staticmap import build_static

    corridor = "  corridors:\n    - points: [[30, 60], [400, 60]]\n      width: 40\n"
    path = _free_map(tmp_path, corridor)
    path.write_text(path.read_text().replace("q_goal: {x: 300, y: 0}", "q_goal: {x: 380, y: 60}")
                    .replace("time_limit: 10", "time_limit: 30"))
    world = load_world(path)
    static = build_static(world)
    assert static.bounds[0] == 0 and static.bounds[2] >= 420      # 120 in of map, grown
    assert static.grid is not None and static.grid.origin == (0.0, 0.0)
    assert static.free([[380, 60], [300, 60]]).all() and not static.free([[300, 100]])[0]
    assert simulate(world, seed=1).outcome == "success"
    far = "  corridors:\n    - points: [[30, 60], [9000000, 60]]\n      width: 40\n"
    with pytest.raises(WorldError, match="the corridors reach so far past the map `map.yaml` "
                                         "that it would grow to 1.08e"):
        load_world(_free_map(tmp_path, far))


def test_unknown_map_key_in_map_yaml(tmp_path: Path):
    (tmp_path / "map.yaml").write_text("image: m.pgm\nresolutoin: 0.05\n", encoding="utf-8")
    world = tmp_path / "w.yaml"
    world.write_text(BASE.replace("  corridors:\n    - points: [[0, 0], [400, 0]]\n"
                                  "      width: 70\n", "  grid: map.yaml\n"), encoding="utf-8")
    with pytest.raises(WorldError, match="did you mean `resolution`"):
        load_world(world)


def test_corridors_that_do_not_connect_start_and_goal():
    from mitos_cli.sim.loop import prepare

    text = BASE.replace("    - points: [[0, 0], [400, 0]]\n      width: 70\n",
                        "    - points: [[0, 0], [100, 0]]\n      width: 70\n"
                        "    - points: [[200, 0], [400, 0]]\n      width: 70\n")
    w = parse_world(text, "w.yaml")
    with pytest.raises(WorldError, match="do not connect"):
        prepare(w)


def test_packaged_world_names_resolve_and_unknown_ones_suggest():
    assert resolve_world_path("figure4.yaml").name == "figure4.yaml"
    assert resolve_world_path("figure4").name == "figure4.yaml"
    with pytest.raises(WorldError, match="did you mean `figure4.yaml`"):
        resolve_world_path("figure5.yaml")


def test_a_start_where_the_body_reaches_into_a_wall_is_refused_at_its_line():
    # the centre is 2 in inside the 70 in corridor; half the 18 in body is in the wall
    msg = error(BASE.replace("q_init: {x: 30, y: 0", "q_init: {x: 30, y: -33"))
    assert "w.yaml:9:9" in msg and "the robot's body (24 x 18 in) reaches into a wall" in msg
    assert parse_world(BASE.replace("q_init: {x: 30, y: 0", "q_init: {x: 30, y: -25"),
                       "w.yaml")                        # 1 in to spare
    msg = error(BASE.replace("q_init: {x: 30, y: 0, heading: 0",
                             "q_init: {x: 30, y: -25, heading: 90"))    # turned across
    assert "reaches into a wall" in msg


def _pinched(width: float, extra: str = "") -> str:
    """BASE with its middle 100 in narrowed to ``width``."""
    return BASE.replace(
        "    - points: [[0, 0], [400, 0]]\n      width: 70\n",
        "    - points: [[0, 0], [150, 0]]\n      width: 70\n"
        f"    - points: [[150, 0], [250, 0]]\n      width: {width}\n"
        "    - points: [[250, 0], [400, 0]]\n      width: 70\n") + extra


def test_a_corridor_narrower_than_the_robot_is_refused_naming_the_place():
    from mitos_cli.sim.loop import prepare
    from mitos_cli.sim.route import NarrowPassage

    with pytest.raises(NarrowPassage) as info:
        prepare(parse_world(_pinched(16), "w.yaml"))
    msg = info.value.render()
    assert "keeps 8.0 in from the walls (a corridor 16 in wide); it needs 11.0 in" in msg
    x = float(msg.split("passes (")[1].split(",")[0])
    assert 150 <= x <= 250
    assert "the robot is 18 in wide: widen the corridor to at least 22 in" in msg


def test_a_corridor_width_is_said_to_a_tenth():
    """An 18.5 in corridor was "18 in wide"."""
    from mitos_cli.sim.loop import prepare
    from mitos_cli.sim.route import NarrowPassage

    with pytest.raises(NarrowPassage) as info:
        prepare(parse_world(_pinched(18.5), "w.yaml"))
    assert "(a corridor 18.5 in wide); it needs 11.0 in" in info.value.message


def test_a_corridor_the_robot_fits_is_a_squeeze_the_world_may_allow():
    from mitos_cli.sim.loop import prepare
    from mitos_cli.sim.route import NarrowPassage

    with pytest.raises(NarrowPassage, match=r"min_clearance: 9.9\}") as exc:
        prepare(parse_world(_pinched(20), "w.yaml"))
    assert "its body then keeps as little as 1.0 in from the walls" in exc.value.hint
    scene = prepare(parse_world(_pinched(20, "route: {min_clearance: 9.9}\n"), "w.yaml"))
    assert scene.routes[0].length == pytest.approx(270.0)


def test_a_corridor_route_goes_round_a_narrow_stretch_when_a_wide_way_leads_on():
    from mitos_cli.sim.loop import prepare

    loop = ("    - points: [[120, 0], [120, 150], [280, 150], [280, 0]]\n      width: 70\n")
    text = _pinched(16).replace("      width: 16\n", "      width: 16\n" + loop)
    route = prepare(parse_world(text, "w.yaml")).routes[0]
    assert route.points[:, 1].max() == pytest.approx(150.0)     # north round the loop
    assert route.length == pytest.approx(270.0 + 2 * 150.0)


def test_a_behavior_the_rule_base_lacks_is_reported_at_the_world_files_line():
    from mitos_cli.errors import NameError_
    from mitos_cli.sim.planner import make_planner

    w = parse_world(BASE + "behavior: drvie\n", "w.yaml")
    with pytest.raises(NameError_) as info:
        make_planner("fuzzy", w)
    msg = info.value.render()
    assert "w.yaml:15:11" in msg and "did you mean `drive`?" in msg
    with pytest.raises(NameError_) as info:            # named on the command line: no line
        make_planner("fuzzy", w, behavior="drvie")
    assert info.value.span is None


def test_a_goal_no_route_reaches_is_reported_at_its_line():
    from mitos_cli.sim.loop import prepare
    from mitos_cli.sim.route import NarrowPassage

    with pytest.raises(NarrowPassage) as info:
        prepare(parse_world(_pinched(16), "w.yaml"))
    assert info.value.render().startswith("w.yaml:10:9: world error: the only way")


def test_a_seed_keeps_every_digit():
    big = 18446744073709551617
    assert parse_world(BASE.replace("seed: 1", f"seed: {big}"), "w.yaml").seed == big
    assert "seed must be at least 0" in error(BASE.replace("seed: 1", "seed: -3"))
    assert "whole number" in error(BASE.replace("seed: 1", "seed: 1.5"))


def test_a_run_of_too_many_ticks_is_refused_at_dt():
    msg = error(BASE.replace("dt: 0.05", "dt: 0.00001"))
    assert "w.yaml:3:5" in msg and "1,000,000 ticks; a run takes at most 100,000" in msg


@pytest.mark.parametrize("written, value", [("010", 10.0), ("1e1", 10.0), ("0x0A", 10.0),
                                            ("10.0", 10.0)])
def test_numbers_read_as_written(written, value):
    w = parse_world(BASE.replace("time_limit: 10", f"time_limit: {written}"), "w.yaml")
    assert w.time_limit == value


def test_a_sexagesimal_looking_value_is_not_a_number():
    assert "must be a number, not `1:00`" in error(BASE.replace("time_limit: 10",
                                                                "time_limit: 1:00"))


@pytest.mark.parametrize("obstacle, what", [
    ("{name: bin, shape: circle, at: [300, 0], radius: 9}", "goal (q_goal)"),
    ("{name: crate, shape: rectangle, at: [300, 2], length: 30, width: 20, angle: 30}",
     "goal (q_goal)"),
    ("{name: crate, shape: rectangle, at: [30, 0], length: 30, width: 20}", "start (q_init)"),
])
def test_a_start_or_goal_inside_an_obstacle_is_refused(obstacle, what):
    msg = error(BASE + f"obstacles:\n  - {obstacle}\n")
    name = obstacle.split("name: ")[1].split(",")[0]
    assert f"the {what} at" in msg and f"lies inside obstacle `{name}`" in msg
    assert ("w.yaml:10:9" if "goal" in what else "w.yaml:9:9") in msg


@pytest.mark.parametrize("obstacle, touches", [
    ("{name: bin, shape: circle, at: [50, 0], radius: 9}", True),      # 1 in into the nose
    ("{name: bin, shape: circle, at: [52, 0], radius: 9}", False),     # 1 in short of it
    ("{name: crate, shape: rectangle, at: [30, 18], length: 30, width: 20, angle: 0}", True),
    ("{name: crate, shape: rectangle, at: [30, 20], length: 30, width: 20, angle: 0}", False),
    ("{name: crate, shape: rectangle, at: [30, 20], length: 30, width: 20, angle: 10}", True),
])
def test_a_start_where_the_body_reaches_into_an_obstacle_is_refused(obstacle, touches):
    text = BASE + f"obstacles:\n  - {obstacle}\n"
    if not touches:
        assert parse_world(text, "w.yaml")
        return
    msg = error(text)
    assert "w.yaml:9:9" in msg and "the robot's body (24 x 18 in) reaches into obstacle" in msg


def test_robots_whose_bodies_overlap_at_the_start_are_refused():
    robots = ("robots:\n  - name: b\n    q_init: {{x: {x}, y: 0, heading: 180}}\n"
              "    q_goal: {{x: 300, y: 20}}\n")
    msg = error(BASE + robots.format(x=50))        # noses 4 in into each other
    assert "w.yaml:17:13" in msg and "overlaps robot `robot`'s at its start" in msg
    assert parse_world(BASE + robots.format(x=55), "w.yaml")       # 1 in apart


@pytest.mark.parametrize("jitter, what", [
    ("{dx: [-125, -115], dy: [0, 0]}", "start (q_init) at (30, 0)"),
    ("{dx: [100, 160], dy: [-1, 1]}", "goal (q_goal) at (300, 0)"),
    ("{dx: [150, 150], dy: [5, 10]}", "goal (q_goal) at (300, 0)"),     # 1 in to spare
])
def test_a_randomise_range_that_reaches_a_start_or_goal_is_refused(jitter, what):
    text = (BASE + "obstacles:\n  - {name: box, shape: circle, at: [150, 5], radius: 9}\n"
            f"randomise:\n  obstacles:\n    box: {jitter}\n")
    if "[5, 10]" in jitter:
        assert parse_world(text, "w.yaml")
        return
    msg = error(text)
    assert "w.yaml:19:10" in msg and f"randomise can move obstacle `box` over the {what}" in msg


@pytest.mark.parametrize("obstacle, jitter, refused", [
    # the body spans x 18..42, y -9..9; none of these reaches the start point (30, 0)
    ("{name: box, shape: circle, at: [150, 5], radius: 9}", "{dx: [-100, -98]}", True),
    ("{name: box, shape: circle, at: [150, 5], radius: 9}", "{dx: [-99, -97]}", False),
    ("{name: box, shape: rectangle, at: [150, 20], length: 20, width: 10}",
     "{dx: [-120, -118], dy: [-8, -8]}", True),
    ("{name: box, shape: rectangle, at: [150, 22], length: 20, width: 10, angle: 10}",
     "{dx: [-120, -118], dy: [-8, -8]}", True),
    ("{name: box, shape: rectangle, at: [150, 22], length: 20, width: 10}",
     "{dx: [-120, -118], dy: [-8, -8]}", False),                    # 1 in to spare
])
def test_a_randomise_range_that_reaches_the_body_at_the_start_is_refused(obstacle, jitter,
                                                                         refused):
    """Only the start point was tested: a draw over the robot's nose began every run of it in
    a collision at its first tick, counted against the planner (`--runs 3`: 100% collision,
    path 0), where the same obstacle written there is refused."""
    text = BASE + f"obstacles:\n  - {obstacle}\nrandomise:\n  obstacles:\n    box: {jitter}\n"
    if not refused:
        assert parse_world(text, "w.yaml")
        return
    msg = error(text)
    assert "w.yaml:19:10" in msg and "randomise can move obstacle `box` over the start " \
        "(q_init) at (30, 0): into the robot's body (24 x 18 in) there" in msg


def test_a_randomised_draw_that_shuts_the_known_way_is_said_to_be_the_draws():
    """A draw that moves an obstacle the robot is told of across its only way was refused as
    the world's own "the only way to the goal passes ...", though the world as written has
    its route: the refusal names the draw and the seed that replays it."""
    from mitos_cli.sim.loop import Simulation

    text = (BASE + "obstacles:\n  - {name: box, shape: circle, at: [150, 30], radius: 20, "
            "known: true}\nrandomise:\n  obstacles:\n    box: {dy: [-30, -30]}\n")
    world = parse_world(text, "w.yaml")
    Simulation(world, seed=5)                          # as written, it has its way
    with pytest.raises(WorldError) as info:
        Simulation(world, seed=5, randomise=True)
    msg = info.value.render()
    assert msg.startswith("w.yaml:10:9: world error: the randomised run of seed 5 drew `box` "
                          "to (150, 0), where the robot is told it stands (`known: true`), "
                          "and then the only way to the goal passes (")
    assert "`--seed 5 --randomise` replays this one" in msg


def test_a_moving_obstacle_may_start_over_the_goal_it_leaves():
    text = (BASE + "obstacles:\n  - {name: cart, shape: circle, at: [330, 0], radius: 9, "
            "velocity: [-10, 0]}\nrandomise:\n  obstacles:\n    cart: {dx: [-40, 0]}\n")
    assert parse_world(text, "w.yaml")


def test_a_moving_obstacle_may_start_over_the_goal_as_written_too():
    """A cart written over the goal it drives off was refused ("the goal ... lies inside
    obstacle `cart` (where it stands at the start)"), where a `randomise` range that moves it
    there is taken; a still one over the goal, or a cart over the start, is still refused."""
    cart = "obstacles:\n  - {name: cart, shape: circle, at: [300, 0], radius: 9, %s}\n"
    world = parse_world(BASE + cart % "velocity: [-10, 0]", "w.yaml")
    assert world.obstacles[0].motion.kind == "velocity"
    msg = error(BASE + cart % "known: false")
    assert "w.yaml:10:9" in msg and "lies inside obstacle `cart`" in msg
    moving = cart.replace("[300, 0]", "[30, 0]") % "velocity: [10, 0]"
    assert "w.yaml:9:9" in error(BASE + moving)


def test_a_goal_the_body_cannot_reach_within_its_tolerance_is_refused():
    """A goal 2 in from a wall with a tolerance of 5 in: the robot's centre keeps half its
    width (9 in) from the wall, 7 in from the goal at best, so the run was driven at until
    its time limit. It is refused where it is written, with what the body needs."""
    near = BASE.replace("q_goal: {x: 300, y: 0}", "q_goal: {x: 300, y: -33, tolerance: 5}")
    msg = error(near)
    assert msg.startswith("w.yaml:10:9: world error: the goal (q_goal) at (300, -33) cannot be "
                          "reached: within its tolerance (5 in) the robot's centre keeps at "
                          "most 7.0 in from the walls and still obstacles")
    assert "18 in wide, needs 9 in to stand there at all" in msg and "`tolerance: 1" in msg
    assert parse_world(near.replace("tolerance: 5", "tolerance: 8"), "w.yaml")
    # a round box leaves 16 in beside the wall at the goal: 8.2 in for the centre at best
    gap = BASE.replace("q_goal: {x: 300, y: 0}", "q_goal: {x: 300, y: -27, tolerance: 5}")
    box = "obstacles:\n  - {name: box, shape: circle, at: [300, 0], radius: 19%s}\n"
    assert "keeps at most 8.2 in" in error(gap + box % "")
    assert parse_world(gap + box % ", velocity: [0, 30]", "w.yaml")     # a cart drives off


@pytest.mark.parametrize("written, said", [("~", "`~`"), ("null", "`null`"),
                                           ("", "nothing (an empty value)")])
def test_an_empty_number_says_so(written, said):
    """Nothing is quoted as written: `null` read "nothing (an empty value or `~`)"."""
    msg = error(BASE.replace("time_limit: 10", f"time_limit: {written}"))
    assert "w.yaml:4:" in msg and f"must be a number, not {said}\n" in msg, msg


def test_a_name_with_a_control_character_is_refused():
    msg = error(BASE.replace("name: t", 'name: "t\\e[31m"'))
    assert "w.yaml:1:7" in msg and "control character" in msg


def test_an_empty_world_name_says_so():
    """Path("") is ".": load_world("") said "`.` is a directory", a path never given."""
    from mitos_cli.sim import load_world

    for load in (load_world, resolve_world_path):
        with pytest.raises(WorldError) as exc:
            load("")
        assert exc.value.message == "the world's name is empty"


def test_a_world_from_standard_input_is_refused_in_words(tmp_path, monkeypatch, capsys):
    """`cat w.yaml | mitos simulate -`, as `mitos eval --batch -` and `mitos teach --lesson -`
    read standard input, said "world file `-` not found" and listed the packaged worlds."""
    from mitos_cli.cli.app import main

    monkeypatch.chdir(tmp_path)
    with pytest.raises(WorldError) as exc:
        resolve_world_path("-")
    assert exc.value.message == ("a world is read from its file, not from standard input "
                                 "(`-`)")
    assert exc.value.hint == ("save it to a file and name that (a map it names is found "
                              "beside the world's file)")
    with pytest.raises(SystemExit) as info:
        main(["simulate", "-"])
    err = capsys.readouterr().err
    assert info.value.code == 1 and "not from standard input (`-`)" in err, err


def test_a_misspelt_world_path_points_at_the_file_beside_it(tmp_path, monkeypatch):
    (tmp_path / "w").mkdir()
    (tmp_path / "w" / "tiny.yaml").write_text(BASE)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(WorldError) as exc:
        resolve_world_path("w/tiyn.yaml")
    assert exc.value.hint == "did you mean `w/tiny.yaml`?"      # was a packaged world's name
    with pytest.raises(WorldError) as exc:
        resolve_world_path("w")
    assert exc.value.message == "`w` is a directory, not a world file"
    with pytest.raises(WorldError) as exc:
        resolve_world_path("slalm")                            # a name: the packaged worlds
    assert exc.value.hint == "did you mean `slalom`?"


@pytest.mark.parametrize("old, new, says", [
    ("q_goal: {x: 300, y: 0}\n", "q_goal: {x: 300, y: 0}\nbehavior:\n",
     "behavior must be the name of a behavior"),                       # was "`None`"
    ("  footprint: {length: 24, width: 18}\n", "  footprint: {length: 24, width: 18}\n"
     "  brake: maybe\n", "`brake` in robot must be true or false, not `maybe`"),
    ("  footprint: {length: 24, width: 18}\n", "  footprint: {length: 24, width: 18}\n"
     "  brake: off\n", "w.yaml:9:10: world error: `brake` in robot must be true or false, "
     "not `off`\n      brake: off\n             ^\nexpected true or false\nhint: "
     "write `brake: false`"),                           # was false (YAML 1.1), silently
    ("map:\n", "map:\n  given: whatever\n",
     "`given` in map must be `none` or a map_server YAML file, not `whatever`"),
    ("width: 70\n", "width: 70\nrandomise: {sensor_noise: 1}\n",
     "sensor_noise must be a range [low, high]"),                      # was "a point [x, y]"
])
def test_wrong_values_are_said_in_words(old, new, says):
    assert says in error(BASE.replace(old, new))


@pytest.mark.parametrize("old, new, says, hint", [
    ("map:\n", "map:\n  unknown: ocupied\n", "`unknown: ocupied` in map: unknown value",
     "did you mean `occupied`?"),                       # was "unknown unknown `ocupied`"
    ("  model: tricycle\n", "  model: tricyle\n", "unknown model `tricyle` in robot",
     "did you mean `tricycle`?"),                       # a key that names its value: as it was
])
def test_a_choice_reads_as_words(old, new, says, hint):
    text = error(BASE.replace(old, new, 1))
    assert f"error: {says}\n" in text and f"hint: {hint}" in text


def test_a_field_of_view_on_a_ring_is_refused():
    ring = BASE + "sensors: {layout: ring, fov: 90}\n"          # it was silently ignored
    assert "`fov` in sensors is for `layout: fan`" in error(ring)
    assert parse_world(BASE + "sensors: {layout: ring, fov: 360}\n", "w.yaml")
    assert parse_world(BASE + "sensors: {layout: fan, fov: 90}\n", "w.yaml")


def test_a_huge_number_is_explained_in_its_own_unit():
    msg = error(BASE.replace("time_limit: 10", "time_limit: 1e12"))
    assert "1e7 s is 116 days" in msg and "inches" not in msg       # was "254 km"
    msg = error(BASE + "sensors: {count: 1e8}\n")
    assert "`count` in sensors must be at most 720, not 1e+08" in msg
    # an obstacle's angle and the wheel's limits are degrees, its rate degrees a second
    msg = error(BASE + "obstacles: [{shape: rectangle, at: [100, 0], length: 10, width: 10, "
                       "angle: 1e300}]\n")
    assert "hint: angles are in degrees: 1e7 deg is 27,778 turns" in msg
    msg = error(BASE.replace("  wheelbase: 16\n", "  wheelbase: 16\n  steering: {max_rate: 1e300}\n"))
    assert "hint: a steering rate is in degrees a second" in msg


def test_small_wording_of_the_world_reader():
    """`waypoints: []` said "at least 1 points"; `seed: true` quoted Python's `True`; an
    empty name was taken, and every verdict began `: TIMEOUT`."""
    msg = error(BASE + "obstacles: [{shape: circle, at: [100, 0], radius: 5, waypoints: []}]\n")
    assert "must be a list of at least one point [x, y]" in msg
    assert "must be a number, not `true`" in error(BASE.replace("seed: 1", "seed: true"))
    for empty in ('""', "'  '"):
        msg = error(BASE.replace("name: t", f"name: {empty}"))
        assert "w.yaml:1:7: world error: the world's `name` is empty" in msg


def test_randomising_obstacles_in_a_world_without_any_says_so():
    msg = error(BASE + "randomise:\n  obstacles:\n    box: {dx: [-30, 30]}\n")
    assert "randomise moves obstacles, and the world has none" in msg    # "expected one of "


def test_a_time_limit_shorter_than_a_tick_is_refused():
    msg = error(BASE.replace("time_limit: 10", "time_limit: 0.01"))
    assert "w.yaml:4:13" in msg and "shorter than one tick (dt 0.05 s)" in msg


def test_a_name_that_is_not_text_is_refused():
    assert "w.yaml:1:7" in error(BASE.replace("name: t", "name: [1, 2]"))
    assert 'quote it: name: "42"' in error(BASE.replace("name: t", "name: 42"))


def test_corridors_too_large_for_the_robots_map_are_refused():
    """The robot's map of a corridor world is a raster of 2 in cells; a world of 1e6 in was
    a NumPy allocation of 233 GiB (a traceback)."""
    msg = error(BASE.replace("[[0, 0], [400, 0]]", "[[0, 0], [1000000, 0], [1000000, 1000000]]"))
    assert "w.yaml:13:5" in msg and "at most 5,000,000 fit" in msg


def test_an_angle_too_large_is_explained_in_degrees():
    assert "angles are in degrees" in error(BASE.replace("heading: 0", "heading: 1e300"))


def test_load_world_finds_a_packaged_world_from_any_directory(tmp_path, monkeypatch):
    """docs/api.md's `load_world("worlds/figure4.yaml")` worked only from the repository root
    (the command line, the Gymnasium environments and load_rulebase find packaged files from
    anywhere); a file that is there is still read first."""
    from mitos_cli.errors import NameError_
    from mitos_cli.resources import packaged_path

    monkeypatch.chdir(tmp_path)
    packaged = packaged_path("worlds", "figure4.yaml")
    assert load_world("worlds/figure4.yaml").path == str(packaged)
    assert load_world("figure4").path == str(packaged)
    (tmp_path / "figure4.yaml").write_text(BASE)
    assert load_world("figure4.yaml").name == "t"
    with pytest.raises(NameError_, match="world file `figur4` not found") as exc:
        load_world("figur4")
    assert exc.value.hint == "did you mean `figure4`?"
    # a directory that is not the packaged one is a typo, not a way to the packaged world
    for typo in ("nope/figure4.yaml", "/elsewhere/worlds/figure4.yaml", "world/figure4"):
        with pytest.raises(NameError_, match=f"world file `{typo}` not found") as exc:
            load_world(typo)
        assert exc.value.hint == (f"there is no `{typo}`; the packaged world of that name is "
                                  "`figure4`")
    assert load_world("./worlds/figure4.yaml").path == str(packaged)


@pytest.mark.parametrize("name, hint, listed", [
    # a path: not found, and no packaged name unless one is close (`nosuch.yaml` was "did
    # you mean `office.yaml`?": the `.yaml` both end in)
    ("nosuch.yaml", "`mitos list` shows the packaged worlds", False),
    ("foo/nosuch.yaml", "`mitos list` shows the packaged worlds", False),
    ("slalm.yaml", "did you mean `slalom.yaml`?", True),
    ("nosuch", None, True),                     # a name: the packaged worlds' names
    # `worlds/NAME.yaml` is found from anywhere, so its misspelling gets the packaged names
    # too (it got only "`mitos list` shows ..." where there is no `worlds/`)
    ("worlds/slalon.yaml", "did you mean `worlds/slalom.yaml`?", False),
    ("worlds/nosuch.yaml", "`mitos list` shows the packaged worlds", False),
    ("foo/slalon.yaml", "`mitos list` shows the packaged worlds", False),
])
def test_a_missing_world_file_is_not_found(tmp_path, monkeypatch, name, hint, listed):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "other.yaml").write_text(BASE)   # a file beside it, not close either
    with pytest.raises(WorldError) as exc:
        resolve_world_path(name)
    assert exc.value.message == f"world file `{name}` not found"
    assert (exc.value.hint or "").startswith(hint) if hint else exc.value.hint is None
    assert (exc.value.expected or "").startswith("one of the packaged worlds: ") == listed


def test_simulate_a_missing_world_file(tmp_path, monkeypatch, capsys):
    from mitos_cli.cli.app import main

    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as info:
        main(["simulate", "nosuch.yaml"])
    err = capsys.readouterr().err
    assert info.value.code == 1 and "world error: world file `nosuch.yaml` not found" in err
    assert "office" not in err


@pytest.mark.parametrize("given, says", [
    (3, "not int `3`"),
    (None, "not NoneType `None`"),
    ({"map": {}}, "parse_world(text, 'name.yaml')"),
])
def test_load_world_of_something_that_is_not_a_path_says_what_it_takes(given, says):
    with pytest.raises(WorldError, match="expected a path or a packaged world's name") as exc:
        load_world(given)
    assert says in exc.value.render()


def test_load_world_of_a_loaded_world_says_it_is_loaded():
    world = load_world("corridor")
    with pytest.raises(WorldError) as exc:
        load_world(world)
    assert "loaded already" in str(exc.value) and len(exc.value.message) < 200


@pytest.mark.parametrize("given", ["  given:\n", "  given:   # to do\n"])
def test_an_empty_given_is_refused_as_an_empty_unknown_is(given):
    """A new user's third review: an empty `given:` silently meant "no map at all" (as
    `given: none`), where an empty `unknown:` is refused. Now it is refused, at the value."""
    text = error(BASE.replace("map:\n", "map:\n" + given, 1))
    assert "w.yaml:" in text and "`given:` in map is empty" in text
    assert "expected a map_server YAML file or `none`" in text and "`given: none`" in text
    written = BASE.replace("map:\n", "map:\n  given: none\n", 1)
    assert parse_world(written, "w.yaml")                        # written out, it is taken
    assert parse_world(BASE.replace("map:\n", "map:\n  given: null\n", 1), "w.yaml")


def test_a_wheelbase_longer_than_the_footprint_is_refused():
    """A new user's third review: `wheelbase: 40` under a 24 in footprint was taken."""
    text = error(BASE.replace("wheelbase: 16", "wheelbase: 40"))
    assert "w.yaml:7:14: world error: the wheelbase (40 in) is longer than the robot's " \
           "footprint (24 in long)" in text and "expected a wheelbase of at most 24 in" in text
    other = BASE + ("robots:\n  - name: b\n    q_init: {x: 30, y: 20}\n    q_goal: {x: 300, y: 20}\n"
                    "    robot: {footprint: {length: 12, width: 10}}\n")
    assert "the wheelbase (16 in, the first robot's, which this robot takes) is longer" in \
        error(other)                                              # inherited, then too long
    assert parse_world(BASE.replace("wheelbase: 16", "wheelbase: 24"), "w.yaml")


def test_a_turn_tighter_than_half_an_inch_is_refused_at_the_value_that_makes_it():
    """The fuzz audit: `wheelbase: 1e-320` died in the brake's sweep (division by zero),
    `wheelbase: 1e-10` asked for 8 TiB, `wheelbase: 0.01` on a map ran for minutes; a lock of
    90 deg did the same at any wheelbase (its places are closer the tighter the turn)."""
    text = error(BASE.replace("wheelbase: 16", "wheelbase: 1e-320"))
    assert text.startswith("w.yaml:7:14: world error: the robot's tightest turn has a radius "
                           "of 5.78e-321 in (wheelbase 1e-320 in at a lock of 60 deg)")
    assert "expected a wheelbase of at least 0.866 in at this lock" in text
    assert "wheelbase 0.01 in" in error(BASE.replace("wheelbase: 16", "wheelbase: 0.01"))
    assert parse_world(BASE.replace("wheelbase: 16", "wheelbase: 1\n  max_speed: 20"), "w.yaml")
    steer = "  wheelbase: 16\n  steering: {min: 0, max: 180}\n"
    text = error(BASE.replace("  wheelbase: 16\n", steer))
    assert text.startswith("w.yaml:8:19: world error: the steering's lock is 90 deg off straight")
    text = error(BASE.replace("  wheelbase: 16\n", steer.replace("min: 0, max: 180", "min: 1, max: 150")))
    assert "w.yaml:8:19:" in text and "expected a lock of at most 88.2 deg" in text
    other = BASE + ("robots:\n  - name: b\n    q_init: {x: 30, y: 20}\n    q_goal: {x: 300, y: 20}\n"
                    "    robot: {wheelbase: 0.1}\n")
    assert "w.yaml:19:24: world error: the robot's tightest turn" in error(other)


def test_a_world_file_that_is_not_utf8_is_placed_at_its_byte(tmp_path: Path):
    """The fuzz audit: "(byte 0xff at line 15, column 3)" in prose only, where the term-set,
    rule-file and lesson readers put the place first."""
    path = tmp_path / "w.yaml"
    path.write_bytes(BASE.encode() + b"# \xff\n")
    with pytest.raises(WorldError) as info:
        load_world(path)
    assert info.value.render().startswith(f"{path}:15:3: world error: cannot read world file "
                                          f"`{path}`: it is not UTF-8 text (byte 0xff at line 15")


def test_a_misspelt_offset_under_randomise_says_dx_or_dy():
    text = error(BASE + "obstacles:\n  - {name: box, shape: circle, at: [150, 10], radius: 5}\n"
                        "randomise:\n  obstacles:\n    box: {dz: [-5, 5]}\n")
    assert "unknown key `dz` in randomise of `box`" in text
    assert "did you mean `dx` or `dy`?" in text and "w.yaml:19:11" in text


def test_a_corridor_in_metres_gets_a_hint_about_units():
    """`width: 1.8` (metres by mistake) said only that the start lies in a wall."""
    text = error(BASE.replace("width: 70", "width: 1.8"))
    assert "hint: lengths in a world are inches: a corridor `width: 1.8` is narrower than " \
           "the robot (18 in wide); if 1.8 is metres, write 71" in text
    text = error(BASE.replace("width: 70", "width: 1.8").replace("y: 0, heading", "y: 30, heading"))
    assert "lies inside a wall" in text and "lengths in a world are inches" in text


@pytest.mark.parametrize("width", ["0.3", "0.001"])
def test_the_units_hint_offers_no_metres_that_are_still_too_narrow(width):
    """`width: 0.3` said "if 0.3 is metres, write 12", a corridor still narrower than the
    18 in robot, and `width: 0.001` "write 0", which the reader refuses."""
    text = error(BASE.replace("width: 70", f"width: {width}"))
    assert (f"hint: lengths in a world are inches: a corridor `width: {width}` is narrower "
            "than the robot (18 in wide)\n") in text + "\n"
    assert "is metres" not in text


OBSTACLES = ("obstacles:\n"
             "  - {name: buried, shape: circle, at: [150, 80], radius: 5}\n"
             "  - {name: slab, shape: rectangle, at: [250, -60], length: 20, width: 10}\n"
             "  - {name: box, shape: rectangle, at: [120, 10], length: 10, width: 10}\n"
             "  - {name: edge, shape: circle, at: [200, 38], radius: 5}\n")


def test_an_obstacle_inside_a_wall_is_a_warning_not_an_error():
    """Entirely in solid space, no beam or robot reaches it: harmless but pointless, so a
    warning (at its item); one that reaches into the corridor is an ordinary obstacle."""
    w = parse_world(BASE + OBSTACLES, "w.yaml")
    assert len(w.notes) == 2, w.notes
    assert w.notes[0].startswith("w.yaml:16:5: obstacle `buried` at (150, 80) lies entirely "
                                 "inside a wall")
    assert w.notes[1].startswith("w.yaml:17:5: obstacle `slab`")
    assert parse_world(BASE, "w.yaml").notes == ()


def test_a_mover_that_goes_into_a_wall_is_a_warning_and_one_that_comes_out_is_not():
    """A mover passes through walls in the simulator (a cart whose waypoints crossed an
    office's walls drove through two, without a word); one that starts in a wall, as out of
    a doorway, and comes into the corridor is meant."""
    into = parse_world(BASE + "obstacles:\n  - {name: cart, shape: circle, at: [100, 0], "
                       "radius: 5, velocity: [0, 10]}\n", "w.yaml")
    assert into.notes == ("w.yaml:16:5: obstacle `cart` moves into a wall at (100, 36) after "
                          "3.6 s: a mover passes through walls here, where a real one would "
                          "stop (check its `waypoints` or `velocity`)",)
    out = parse_world(BASE + "obstacles:\n  - {name: door, shape: circle, at: [100, 60], "
                      "radius: 5, waypoints: [[100, 60], [100, 0]], speed: 10, mode: stop}\n",
                      "w.yaml")
    assert out.notes == ()
    along = parse_world(BASE + "obstacles:\n  - {name: cart, shape: circle, at: [100, 0], "
                        "radius: 5, waypoints: [[100, 0], [350, 0]], speed: 10, "
                        "mode: ping-pong}\n", "w.yaml")
    assert along.notes == ()


def test_a_randomise_range_that_buries_an_obstacle_is_a_warning():
    w = parse_world(BASE + OBSTACLES + "randomise:\n  obstacles:\n    box: {dy: [-100, 100]}\n",
                    "w.yaml")
    assert any(n.startswith("w.yaml:22:10: randomise can move obstacle `box` entirely into a "
                            "wall (dx 0, dy -100 in") for n in w.notes), w.notes
    calm = parse_world(BASE + OBSTACLES + "randomise:\n  obstacles:\n    box: {dy: [-10, 10]}\n",
                       "w.yaml")
    assert len(calm.notes) == 2


def test_simulate_prints_the_warnings_and_runs(tmp_path, capsys):
    from mitos_cli.cli.app import main

    path = tmp_path / "w.yaml"
    path.write_text(BASE.replace("time_limit: 10", "time_limit: 0.5") + OBSTACLES)
    with pytest.raises(SystemExit) as info:
        main(["simulate", str(path)])
    err = capsys.readouterr().err
    assert info.value.code == 0
    assert f"warning: {path}:16:5: obstacle `buried`" in err


def test_a_velocity_of_three_numbers_is_said_in_in_per_s():
    """It said "(in/s) must be a point [x, y] (inches)": two units for one value."""
    text = error(BASE + "obstacles:\n  - {name: cart, shape: circle, at: [150, 20], radius: 5, "
                        "velocity: [0, 0.5, 1]}\n")
    assert "`velocity` of obstacle `cart` must be a velocity [vx, vy] (in/s)" in text
    assert "inches" not in text


def test_a_range_that_ends_at_minus_zero_draws_as_zero_to_zero():
    from mitos_cli.sim.loop import simulate

    w = parse_world(BASE.replace("width: 70\n", "width: 70\nrandomise: {sensor_noise: [0, -0.0]}\n"),
                    "w.yaml")
    assert [str(x) for x in w.randomise.sensor_noise] == ["0.0", "0.0"]
    simulate(w, seed=3, randomise=True)          # numpy refused uniform(0.0, -0.0)


def _building(corridors: int, span: float) -> str:
    """A world of ``corridors`` corridors crossing a square building ``span`` in across."""
    pieces = "".join(f"    - points: [[0, {y}], [{span}, {y}]]\n      width: 70\n"
                     f"    - points: [[{y}, 0], [{y}, {span}]]\n      width: 70\n"
                     for y in range(0, int(span), int(span) // (corridors // 2)))
    return BASE.split("map:")[0] + "map:\n  corridors:\n" + pieces


def test_carving_a_building_of_many_corridors_holds_little_memory():
    """Every cell was tested against every corridor at once (cells x corridors x 64 bytes):
    a 76 m building of 20 corridors took 6 GB and a traceback where memory was short, 100
    known boxes in it 14 GB. Each corridor is now tested on its own cells, a block at a time."""
    import tracemalloc

    import numpy as np

    from mitos_cli.sim.staticmap import carve, corridor_rects
    from mitos_cli.sim.world import Grid

    world = parse_world(_building(10, 1000), "b.yaml")
    grid = Grid(np.ones((520, 520), dtype=bool), 2.0, (-40.0, -40.0), "")
    tracemalloc.start()
    try:
        carve(grid, corridor_rects(world.corridors))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 48 << 20, f"carving held {peak / 2**20:.0f} MB"


def test_cells_inside_is_every_cell_against_every_polygon():
    """The blockwise test of each polygon's own cells finds what testing all at once found,
    turned rectangles and centres on an edge included."""
    import numpy as np

    from mitos_cli.sim.geometry import points_in_polygon, rect_corners
    from mitos_cli.sim.staticmap import cells_inside
    from mitos_cli.sim.world import Grid

    polys = np.array([rect_corners(x, y, h, 30.0, 8.0)
                      for x, y, h in ((10, 12, 0.0), (40, 30, 0.7), (-5, 50, 1.5707963267948966),
                                      (70, 70, 2.5), (200, 200, 0.3))])
    grid = Grid(np.ones((50, 60), dtype=bool), 2.0, (-20.0, -10.0), "")
    ys, xs = np.mgrid[0:50, 0:60]
    centres = np.stack([-20.0 + (xs.ravel() + 0.5) * 2.0, -10.0 + (ys.ravel() + 0.5) * 2.0], 1)
    whole = points_in_polygon(centres, polys).any(axis=1).reshape(50, 60)
    assert whole.any()
    assert (cells_inside(grid, polys) == whole).all()


def _crossing(n: int, seed: int = 3) -> list[list[float]]:
    """A corridor of ``n`` random points in a 3,000 in square: it crosses itself all over."""
    import random

    rng = random.Random(seed)
    return [[round(rng.uniform(0, 3000)), round(rng.uniform(0, 3000))] for _ in range(n)]


def _room_every_pair(adj, coords, walls):
    """The room of each edge as it was found: every edge against every wall at once."""
    import numpy as np

    from mitos_cli.sim.geometry import point_segment_distance

    edges = sorted({(u, v) for u, out in adj.items() for v, _ in out})
    a = np.array([coords[u] for u, _ in edges])
    b = np.array([coords[v] for _, v in edges])
    to_walls = point_segment_distance(np.concatenate([a, b]), walls).reshape(
        2, len(edges), -1).min(axis=0)
    corners = np.concatenate([walls[:, :2], walls[:, 2:]])
    to_edges = point_segment_distance(corners, np.concatenate([a, b], axis=1)).reshape(
        2, len(walls), -1).min(axis=0)
    return dict(zip(edges, np.minimum(to_walls.min(axis=1), to_edges.min(axis=0)).tolist()))


def test_a_routes_room_is_measured_near_each_edge_the_same_to_the_bit(monkeypatch):
    """Each edge of the centre-line graph was measured against every wall at once: a corridor
    of 300 points crossing itself took 8 GB and 42 s to start (`mitos simulate`). Edges are
    measured in blocks of neighbours, against the walls that can be nearest only, and the
    room is the same to the bit; the block's memory stays small."""
    import tracemalloc
    from types import SimpleNamespace

    import numpy as np

    from mitos_cli.sim import route
    from mitos_cli.sim.staticmap import corridor_rects, corridor_walls

    captured = {}
    real = route._edge_room

    def keep(adj, coords, walls):
        captured.update(adj=adj, coords=coords, walls=walls)
        return real(adj, coords, walls)

    corridors = (SimpleNamespace(points=_crossing(60), width=60.0),)
    walls = corridor_walls(corridor_rects(corridors))
    monkeypatch.setattr(route, "_edge_room", keep)
    route.corridor_route(corridors, SimpleNamespace(x=0.0, y=0.0), SimpleNamespace(x=1.0, y=1.0),
                         walls)
    adj, coords = captured["adj"], captured["coords"]
    assert len(adj) > 400 and len(walls) > 800          # 1,698 edges
    expected = _room_every_pair(adj, coords, walls)
    tracemalloc.start()
    try:
        assert real(adj, coords, walls) == expected
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 64 << 20, f"measuring the room held {peak / 2**20:.0f} MB"    # (was 222)
    monkeypatch.setattr(route, "ROOM_PAIRS", 20_000, raising=False)    # many small blocks
    assert real(adj, coords, walls) == expected
    grid = np.array([[float(x), float(y), float(x + 5 * (i % 3)), float(y)]
                     for i, (x, y) in enumerate(_crossing(50, 4))])
    assert real(adj, coords, grid) == _room_every_pair(adj, coords, grid)


def test_a_diagonal_corridor_is_carved_near_itself_only(monkeypatch):
    """A corridor's cells were tested over its bounding box, the whole map for a diagonal
    one (300 crossing corridors: 14 s). A band of rows is tested between the polygon's own
    sides now, with the same cells found."""
    import random

    import numpy as np

    from mitos_cli.sim import staticmap
    from mitos_cli.sim.geometry import points_in_polygon, rect_corners
    from mitos_cli.sim.staticmap import cells_inside
    from mitos_cli.sim.world import Grid

    rng = random.Random(2)
    for _ in range(30):
        polys = np.array([rect_corners(rng.uniform(-50, 150), rng.uniform(-50, 150),
                                       rng.uniform(-4, 4), rng.uniform(0.5, 300),
                                       rng.choice([0.3, 2, 8, 30]))
                          for _ in range(rng.randint(1, 12))])
        rows, cols, res = rng.randint(5, 120), rng.randint(5, 120), rng.choice([0.7, 1.0, 2.5])
        grid = Grid(np.ones((rows, cols), dtype=bool), res,
                    (rng.uniform(-30, 0), rng.uniform(-30, 0)), "")
        ys, xs = np.mgrid[0:rows, 0:cols]
        centres = np.stack([grid.origin[0] + (xs.ravel() + 0.5) * res,
                            grid.origin[1] + (ys.ravel() + 0.5) * res], 1)
        whole = points_in_polygon(centres, polys).any(axis=1).reshape(rows, cols)
        assert (cells_inside(grid, polys) == whole).all()
    tested = []

    def counting(points, corners):
        tested.append(len(points))
        return points_in_polygon(points, corners)

    monkeypatch.setattr(staticmap, "points_in_polygon", counting)
    diagonal = np.array([rect_corners(500.0, 500.0, 0.7853981633974483, 1400.0, 20.0)])
    grid = Grid(np.ones((500, 500), dtype=bool), 2.0, (0.0, 0.0), "")
    assert cells_inside(grid, diagonal).sum() > 3000
    assert sum(tested) < 40_000          # its bounding box: 250,000 cells


def test_a_corridor_side_is_clipped_only_by_the_rectangles_near_it(monkeypatch):
    """Each rectangle's four sides were clipped by every other rectangle: a polyline of 400
    points took 22 s to load. Only the rectangles whose bounding box meets a side are asked
    now, and the walls are what asking every rectangle made."""
    import numpy as np

    from mitos_cli.sim import staticmap
    from mitos_cli.sim.geometry import clip_segment_outside

    world = parse_world(BASE.replace("[[0, 0], [400, 0]]", "[" + ", ".join(
        f"[{i * 10}, {(i % 7) * 3}]" for i in range(101)) + "]").replace("300, y: 0", "900, y: 0")
        .replace("x: 30, y: 0", "x: 30, y: 3"), "p.yaml")
    rects = staticmap.corridor_rects(world.corridors)
    asked = []

    def counting(side, others, *args):
        asked.append(len(others))
        return clip_segment_outside(side, others, *args)

    monkeypatch.setattr(staticmap, "clip_segment_outside", counting)
    walls = staticmap.corridor_walls(rects)
    assert sum(asked) < 20 * len(asked)           # (every other: 99 a side)
    every = [clip_segment_outside(np.concatenate([c[k], c[(k + 1) % 4]]),
                                  np.delete(rects, i, axis=0))
             for i, c in enumerate(rects) for k in range(4)]
    assert np.array_equal(walls, np.array([w for ws in every for w in ws]).reshape(-1, 4))


ROBOT_2 = "robots:\n  - {name: NAME, q_init: {x: 300, y: 20, heading: 180}, q_goal: {x: 30, y: 20}}\n"
BOX = "obstacles:\n  - {name: NAME, shape: circle, at: [200, 25], radius: 5}\n"


@pytest.mark.parametrize("part", [ROBOT_2, BOX])
@pytest.mark.parametrize("written, said", [
    ("", "`name` is empty"), ('""', "`name` is empty"), ("' '", "`name` is empty"),
    ("[a, b]", "`name` must be text"), ("7", 'quote it: name: "7"'),
    ('"a\\tb"', "name holds a control character")])
def test_a_robots_or_obstacles_name_is_text_and_not_blank(part, written, said):
    """A robot's or an obstacle's `name` was taken as written: `name:` named it `None`, `name:
    ""` left its table row and CSV rows blank, `name: [a, b]` printed `['a', 'b']`."""
    text = error(BASE + part.replace("NAME", written))
    whose = "robot 2's" if part is ROBOT_2 else "obstacle 1's"
    assert whose in text and said in text and "w.yaml:" in text
    assert parse_world(BASE + part.replace("NAME", '"7"'), "w.yaml")


def test_a_fraction_of_substeps_is_refused_not_cut_to_a_whole_one():
    """`substeps: 2.5` ran 2 substeps a tick without a word (a World built in Python with 2.5
    was refused, as a world file's sensor `count: 3.5` is)."""
    text = error(BASE.replace("time_limit: 10", "time_limit: 10\nsubsteps: 2.5"))
    assert "w.yaml:5:11" in text and "`substeps` in the world file must be a whole number" in text
    assert parse_world(BASE.replace("time_limit: 10", "time_limit: 10\nsubsteps: 3.0"),
                       "w.yaml").substeps == 3


@pytest.mark.parametrize("nan", [".nan", ".NaN", ".NAN"])
def test_a_nan_is_not_said_to_be_past_a_floats_range(nan):
    """`dt: .nan` was refused as "`.nan` is past a float's range", the words for `1e400`."""
    text = error(BASE.replace("dt: 0.05", f"dt: {nan}"))
    assert f"`dt` in the world file must be a finite number, not `{nan}`" in text
    assert "past a float's range" not in text
    assert "past a float's range" in error(BASE.replace("dt: 0.05", "dt: 1e400"))


def test_a_pipe_or_a_device_named_as_the_world_is_not_said_to_be_missing(tmp_path: Path):
    """`mitos simulate w.yaml` on a FIFO said "world file `w.yaml` not found" and offered a
    file beside it; `/dev/zero` was "not found" too. Both are there, and not world files."""
    import os

    os.mkfifo(tmp_path / "w.yaml")
    for name in (tmp_path / "w.yaml", Path("/dev/zero")):
        with pytest.raises(WorldError) as info:
            resolve_world_path(str(name))
        text = info.value.render()
        assert "is not a regular file" in text and "not found" not in text


@pytest.mark.parametrize("change, said", [
    (("  footprint: {length: 24, width: 18}",
      "  footprint: {length: 24, width: 18}\n  max_speed: 100000\n  acceleration: 1000000"),
     "at max_speed 100000 in/s the robot's body moves up to 7.33e+03 in a tick"),
    (("dt: 0.05", "dt: 1"),
     "at max_speed 60 in/s the robot's body moves up to 87.9 in a tick (dt 1 s; at full lock its "
     "outer front corner moves 1.47x as fast as its wheel)"),
    (("  footprint: {length: 24, width: 18}",
      "  footprint: {length: 24, width: 18}\n  max_reverse: 600"), "at max_reverse 600 in/s")])
def test_a_robot_that_drives_past_its_length_in_a_tick_is_refused(change, said):
    """Contact is checked once a tick: `max_speed: 100000` with `acceleration: 1000000` drove
    through the walls and 4,000 in outside the map with "no collision" (potential_field), and
    DWA hung. One tick's move of any point of the body is at most the robot's length."""
    text = error(BASE.replace(*change))
    assert said in text and "farther than its own length (24 in)" in text


def test_a_turn_counts_in_a_tick_s_move():
    """A tick's drive of the wheel was held to the robot's length (480 in/s at dt 0.05), but in
    a turn at full lock the outer front corner moves 1.47x as fast as the wheel: at 480 in/s it
    swept past a 1 in pole between two ticks with no collision. The bound is on that corner."""
    def world(speed):
        return BASE.replace("  footprint: {length: 24, width: 18}",
                            f"  footprint: {{length: 24, width: 18}}\n  max_speed: {speed}")

    assert parse_world(world(327), "w.yaml").robot.max_speed == 327
    text = error(world(480))
    assert "moves up to 35.2 in a tick" in text and "at most 327.6 in/s" in text


@settings(max_examples=200, deadline=None)
@given(length=st.floats(2, 100), width=st.floats(1, 100), share=st.floats(0.05, 1),
       lock=st.floats(1, 89.9))
def test_the_fastest_point_is_the_fastest_corner(length, width, share, lock):
    """:func:`fastest_point` against the four corners' speeds about the turn's centre,
    sampled over every lock up to full lock: never below them, and at most a sample's
    spacing above."""
    from mitos_cli.sim.safety import fastest_point

    wb = share * length
    robot = Robot(length=length, width=width, wheelbase=wb, steering_min=90 - lock,
                  steering_max=90 + lock)
    d = np.radians(np.linspace(1e-9, lock, 4001))[:, None]
    x = np.array([-1, -1, 1, 1]) * length / 2 + wb / 2          # from the rear axle
    y = np.array([-1, 1, -1, 1]) * width / 2
    corners = (np.hypot(x, y - wb / np.tan(d)) * np.sin(d) / wb).max()
    assert max(corners, 1.0) <= fastest_point(robot) * (1 + 1e-12)
    assert fastest_point(robot) <= max(corners, 1.0) * (1 + 1e-4)


def test_another_robot_that_drives_past_its_length_in_a_tick_is_refused():
    text = error(BASE + "robots:\n  - {name: r2, q_init: {x: 300, y: 20, heading: 180}, "
                 "q_goal: {x: 30, y: 20}, robot: {max_speed: 1000}}\n")
    assert "at max_speed 1000 in/s the robot's body moves up to 73.3 in a tick" in text


def test_a_tick_count_past_any_reading_is_written_short():
    """`dt: 1e-300` was refused with a tick count of 302 digits, most of them a float's noise."""
    text = error(BASE.replace("dt: 0.05", "dt: 1e-300"))
    assert "time_limit 10 s at dt 1e-300 s is 1e+301 ticks; a run takes at most 100,000" in text
    assert "is 200,000 ticks" in error(BASE.replace("dt: 0.05", "dt: 0.00005"))
    # dt 5e-324 made the count overflow: "is inf ticks"
    assert "is over 1e308 ticks" in error(BASE.replace("dt: 0.05", "dt: 5e-324"))


@pytest.mark.parametrize("obstacle, said", [
    ("{name: cart, shape: circle, at: [200, 20], radius: 6, velocity: [-1500, 0]}",
     "obstacle `cart` moves 75 in a tick (at 1500 in/s, dt 0.05 s), farther than its own size "
     "(12 in)"),
    ("{name: cart, shape: rectangle, at: [200, 20], length: 30, width: 4, "
     "waypoints: [[100, 0]], speed: 100}", "moves 5 in a tick (at 100 in/s, dt 0.05 s), "
     "farther than its own size (4 in)")])
def test_an_obstacle_that_moves_past_its_size_in_a_tick_is_refused(obstacle, said):
    """Contact is checked once a tick, as for the robot: a cart at 1500 in/s jumped 75 in a
    tick and could pass through the robot unseen."""
    text = error(BASE + f"obstacles:\n  - {obstacle}\n")
    assert said in text and "expected a speed of at most" in text
    ok = BASE + "obstacles:\n  - {name: cart, shape: circle, at: [200, 20], radius: 6, " \
                "velocity: [-240, 0]}\n"
    assert parse_world(ok, "w.yaml").obstacles[0].speed == 240


def test_an_obstacle_built_in_python_that_moves_past_its_size_is_refused():
    from dataclasses import replace

    from mitos_cli.sim import Simulation
    from mitos_cli.sim.world import Motion

    world = parse_world(BASE + "obstacles:\n  - {name: cart, shape: circle, at: [200, 20], "
                               "radius: 6, velocity: [-15, 0]}\n", "w.yaml")
    fast = replace(world.obstacles[0], motion=Motion("velocity", velocity=(-1500.0, 0.0)))
    with pytest.raises(WorldError, match=r"obstacles\[0\]\.motion\.velocity` must be at most "
                                         r"240 in/s at dt 0\.05 s"):
        Simulation(replace(world, obstacles=(fast,)), seed=1)


def test_a_map_named_as_a_world_is_said_to_be_one():
    """`mitos simulate worlds/maps/mrpb_office02.yaml` said "unknown key `image` in the world
    file" and listed the world's keys."""
    text = (Path(__file__).parents[1] / "worlds" / "maps" / "mrpb_office02.yaml").read_text()
    with pytest.raises(WorldError) as info:
        parse_world(text, "maps/m.yaml")
    assert info.value.message == ("`maps/m.yaml` is a map (map_server's YAML: `image`, "
                                  "`resolution`), not a world file")
    assert (info.value.span.line, info.value.span.column) == (1, 1)
    assert info.value.hint.startswith("a world drives on it by naming it, `map: {grid: m.yaml}`")
    with pytest.raises(WorldError, match="unknown key `image`"):   # a world with the key
        parse_world(BASE + "image: m.pgm\nresolution: 0.05\n", "w.yaml")


def test_a_term_set_named_as_a_world_is_said_to_be_one():
    """"unknown key `variables` in the world file" said nothing of what the file was."""
    text = (Path(__file__).parents[1] / "rulebases" / "mitos.terms.yaml").read_text()
    with pytest.raises(WorldError) as info:
        parse_world(text, "m.terms.yaml")
    assert info.value.message == "`m.terms.yaml` is a term set, not a world file"
    assert (info.value.span.line, info.value.span.column) == (1, 1)
    assert "mitos plot terms" in info.value.hint
    with pytest.raises(WorldError, match="unknown key `variables`"):   # a world with it
        parse_world(BASE + "variables: {}\n", "w.yaml")


def test_the_nearest_point_with_room_is_the_whole_maps_nearest():
    """The windowed search (a window round the point, widened until the nearest cell with
    room lies inside it) finds a cell as near as the distance transform of the whole map."""
    import math
    from types import SimpleNamespace

    from mitos_cli.sim.distance import distance_transform
    from mitos_cli.sim.worldfile import _nearest_room

    rng = np.random.default_rng(5)
    res = 0.05 / 0.0254                                  # 5 cm cells, in inches
    agent = SimpleNamespace(robot=SimpleNamespace(length=24.0, width=18.0, safety_margin=2.0))
    need = math.hypot(24, 18) / 2 + 2 + res + 1.0
    for trial in range(12):
        rows, cols = rng.integers(20, 400, size=2)
        occupied = rng.random((rows, cols)) < rng.choice([0.001, 0.01, 0.05])
        grid = SimpleNamespace(occupied=occupied, origin=(-30.0, 12.0), resolution=res)
        static = SimpleNamespace(grid=grid)
        x = -30 + rng.uniform(0, cols * res)
        y = 12 + rng.uniform(0, rows * res)
        said = _nearest_room(static, agent, x, y)
        dist = distance_transform(np.pad(occupied, 1, constant_values=True), res)[1:-1, 1:-1]
        ok_r, ok_c = np.nonzero(dist >= need)
        if not len(ok_r):
            assert said == ""
            continue
        centres = np.stack([-30 + (ok_c + 0.5) * res, 12 + (ok_r + 0.5) * res], axis=1)
        best = np.min(np.hypot(centres[:, 0] - x, centres[:, 1] - y))
        found = re.search(r"\((-?\d+), (-?\d+)\)\)$", said)
        assert found, said
        px, py = float(found.group(1)), float(found.group(2))
        col, row = int((px + 30) // res), int((py - 12) // res)
        assert dist[row, col] >= need                      # the point's cell has room
        got = math.hypot(-30 + (col + 0.5) * res - x, 12 + (row + 0.5) * res - y)
        assert got == pytest.approx(best, abs=1e-9), trial
