"""A world file's `robots:` as a new user writes it, and breaks it: each message names the
robot, quotes what was written, and says where a key in the wrong block belongs
(worlds/README.md, "The format, annotated" and the errors after "Several robots")."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.errors import WorldError
from mitos_cli.sim.worldfile import parse_world

# the first robot, and `b` coming the other way; ITEM is the rest of `b`'s item
WORLD = """\
name: t
dt: 0.05
time_limit: 10
robot:
  model: tricycle
  wheelbase: 16
  footprint: {length: 24, width: 18}
TOP
q_init: {x: 30, y: -10}
q_goal: {x: 570, y: -10}
robots:
  - name: b
    q_init: {x: 570, y: 10, heading: 180}
    q_goal: {x: 30, y: 10}
ITEM
map:
  corridors:
    - points: [[0, 0], [600, 0]]
      width: 90
"""


def world(item: str = "", top: str = "") -> str:
    return WORLD.replace("ITEM\n", item).replace("TOP\n", top)


def error(text: str) -> str:
    with pytest.raises(WorldError) as info:
        parse_world(text, "w.yaml")
    return info.value.render()


def test_the_world_loads_and_b_takes_its_own_keys():
    w = parse_world(world("    robot: {max_speed: 40, give_way: false}\n"), "w.yaml")
    assert [a.name for a in w.agents] == ["robot", "b"]
    assert (w.agents[1].robot.max_speed, w.agents[1].robot.give_way) == (40, False)
    assert (w.agents[0].robot.max_speed, w.agents[0].robot.give_way) == (60, True)


@pytest.mark.parametrize("key", ["give_way", "brake"])
@pytest.mark.parametrize("written, said", [
    ("null", "`null`"), ("~", "`~`"), ("", "nothing (an empty value)"),
    ('""', 'the empty text `""`'), ("[true]", "a list")])
def test_a_flag_of_nothing_is_quoted_as_written_and_the_default_named(key, written, said):
    """`give_way: null` read "not `None`" (Python's word; `brake` the same, through the one
    flag reader); the hint now says what leaving it out takes."""
    text = error(world(f"    robot:\n      {key}: {written}\n"))
    assert f"world error: `{key}` in robot `b` must be true or false, not {said}\n" in text
    assert (f"hint: write `{key}: true` or `{key}: false`; left out, `{key}` is true "
            f"(the first robot's)") in text
    assert "w.yaml:15:" in text and "None" not in text
    text = error(world(top=f"  {key}: {written}\n"))           # the first robot's own
    assert f"`{key}` in robot must be true or false, not {said}\n" in text
    assert text.endswith(f"; left out, `{key}` is true")


@pytest.mark.parametrize("key, value", [("give_way", "false"), ("max_speed", "40"),
                                        ("footprint", "{length: 20, width: 14}"),
                                        ("brake", "false"), ("wheelbase", "12")])
def test_a_robot_key_beside_an_items_robot_says_it_belongs_under_it(key, value):
    """A `robot:` key written at a `robots:` item's level was "unknown key" with no word of
    the item's `robot:`."""
    text = error(world(f"    {key}: {value}\n"))
    shown = "..." if value.startswith("{") else value
    assert f"w.yaml:14:5: world error: unknown key `{key}` in robot `b`\n" in text
    assert (f"hint: `{key}` is a key of the robot itself: write it under this robot's "
            f"`robot:`, as `robot: {{{key}: {shown}}}`") in text


@pytest.mark.parametrize("key, value", [("give_way", "false"), ("max_speed", "40")])
def test_a_robot_key_at_the_top_of_the_file_says_it_belongs_under_robot(key, value):
    """At the top level `max_speed` was offered "did you mean `seed`?"."""
    text = error(world(top=f"{key}: {value}\n"))
    assert f"w.yaml:8:1: world error: unknown key `{key}` in the world file\n" in text
    assert (f"hint: `{key}` is a key of the robot itself: write it under `robot:`, as "
            f"`robot: {{{key}: {value}}}`") in text
    assert "did you mean" not in text


@pytest.mark.parametrize("key, value", [("q_init", "{x: 570, y: 10}"), ("q_goal", "{x: 1, y: 1}"),
                                        ("name", "c")])
def test_an_item_key_under_its_robot_says_it_belongs_beside_it(key, value):
    text = error(world(f"    robot:\n      {key}: {value}\n"))
    assert f"w.yaml:15:7: world error: unknown key `{key}` in robot `b`\n" in text
    assert f"hint: `{key}` is the `robots:` item's: write it beside `robot:`, not under it" \
        in text


@pytest.mark.parametrize("key", ["q_init", "name", "robots"])
def test_a_key_under_the_first_robot_says_where_it_belongs(key):
    text = error(world(top=f"  {key}: x\n"))
    assert f"unknown key `{key}` in robot\n" in text
    assert ("the first robot is named `robot`" if key == "name" else
            f"`{key}` is not the robot's: write it at the top level of the file") in text


@pytest.mark.parametrize("where", ["item", "robot"])
@pytest.mark.parametrize("key", ["sensors", "behavior", "dt"])
def test_a_world_key_under_a_robot_says_it_is_the_worlds(where, key):
    """Every robot of a world has the world's sensors, behavior and tick."""
    block = f"    {key}: x\n" if where == "item" else f"    robot:\n      {key}: x\n"
    text = error(world(block))
    assert f"unknown key `{key}` in robot `b`" in text
    assert (f"hint: `{key}` is the world's, the same for every robot: write it at the top "
            "level of the file") in text


def test_a_misspelt_key_still_gets_did_you_mean():
    assert "did you mean `give_way`?" in error(world("    robot: {givway: false}\n"))
    assert "did you mean `q_init`?" in error(world("    q_int: {x: 1, y: 1}\n"))


@pytest.mark.parametrize("key, value, said", [
    ("max_speed", "null", "`max_speed` in robot `b` must be a number, not `null`"),
    ("max_speed", "0", "`max_speed` in robot `b` must be positive, not 0"),
    ("footprint", "{length: 20}", "missing `width` in the footprint of robot `b`"),
    ("footprint", "null", "the footprint of robot `b` must be a mapping"),
    ("steering", "{min: 30, max: 150, max_rate: 0}",
     "`max_rate` in the steering of robot `b` must be positive, not 0"),
    ("model", "null", "`model` in robot `b` must be one of tricycle, not `null`")])
def test_a_robots_own_keys_name_the_robot(key, value, said):
    """In a world of eight robots "`max_speed` in robot must be ..." did not say whose."""
    assert said in error(world(f"    robot: {{{key}: {value}}}\n"))


def test_an_empty_robot_block_says_to_leave_it_out():
    """`robot:` with nothing under it read "robot must be a mapping"."""
    for written in ("null", ""):
        text = error(world(f"    robot: {written}\n"))
        assert "world error: the `robot:` of `b` is empty" in text
        assert "hint: or leave `robot:` out: `b` is then the same robot as the first" in text


def test_an_unnamed_robot_whose_place_name_is_taken_is_told_so():
    """The third robot, unnamed, is `robot3`; a second named `robot3` made the third's error
    read "two robots are named `robot3`" at an item that names none."""
    text = error(world("  - q_init: {x: 300, y: 30}\n    q_goal: {x: 100, y: 30}\n")
                 .replace("name: b", "name: robot3"))
    assert "w.yaml:14:5: world error: this robot has no `name`, so it is called `robot3`" in text
    assert "hint: give it a name of its own: `name: ...`" in text


def test_a_name_taken_by_an_unnamed_robots_place_says_so():
    """An unnamed `b` is `robot2`; a third named `robot2` read "two robots are named
    `robot2`", though the file names only one so."""
    text = error(world("  - {name: robot2, q_init: {x: 300, y: 30}, q_goal: {x: 100, y: 30}}\n")
                 .replace("  - name: b\n    q_init", "  - q_init"))
    assert ("w.yaml:13:12: world error: two robots are named `robot2` (an earlier robot has no "
            "`name` and is called `robot2` by its place): give each a name of its own") in text


def test_a_robot_named_all_robots_is_refused():
    """`all robots` heads the table's column of every robot: a robot of that name made two."""
    text = error(world().replace("name: b", "name: all robots"))
    assert "w.yaml:11:11: world error: `all robots` heads the summary's column" in text


def test_a_robot_named_robot_says_the_first_is():
    text = error(world().replace("name: b", "name: robot"))
    assert "two robots are named `robot` (the first robot, under `robot:`, is `robot`)" in text


def test_the_command_refuses_a_misplaced_give_way_with_exit_1(tmp_path, capsys):
    """The whole message as `mitos simulate` prints it: file:line:column, the line, a caret,
    what was expected and where the key belongs; exit 1, no traceback."""
    from mitos_cli.cli.app import main

    p = tmp_path / "fleet.yaml"
    p.write_text(world("    give_way: false\n"), encoding="utf-8")
    with pytest.raises(SystemExit) as info:
        main(["simulate", str(p)])
    assert info.value.code == 1
    assert capsys.readouterr().err == (
        f"{p}:14:5: world error: unknown key `give_way` in robot `b`\n"
        "        give_way: false\n"
        "        ^\n"
        "expected one of name, q_init, q_goal, robot\n"
        "hint: `give_way` is a key of the robot itself: write it under this robot's `robot:`, "
        "as `robot: {give_way: false}`\n")


def goals(first: str, b: str) -> str:
    """The world with the first robot's goal and `b`'s (`{x: ..., y: ...}`) as given."""
    return world().replace("q_goal: {x: 570, y: -10}", f"q_goal: {first}").replace(
        "q_goal: {x: 30, y: 10}", f"q_goal: {b}")


def test_two_goals_no_two_bodies_can_stand_at_are_refused():
    """`b`'s goal on the first robot's with a tolerance of 1 in (the first's 12): whichever
    arrived first parked in the other's way, and the run drove on to its time limit
    (`TIMEOUT (robot timeout, b success) after 60.00 s`). The rule said: the two bodies'
    half-widths, plus the first's tolerance less the second's."""
    text = error(goals("{x: 570, y: -10}", "{x: 570, y: -10, tolerance: 1}"))
    assert ("w.yaml:13:13: world error: the goals (q_goal) of `robot` at (570, -10) and `b` at "
            "(570, -10) are 0.0 in apart; two robots' goals must be at least 29 in apart: half "
            "of each one's narrower side (9 + 9 in) plus the first's tolerance less the "
            "second's (12 - 1 in). `robot`, arriving first, may park anywhere within 12 in of "
            "its goal, and `b` then has no room to stand within 1 in of its own\n"
            "        q_goal: {x: 570, y: -10, tolerance: 1}\n"
            "                ^\n") in text
    assert "hint: move the goals 29 in or more farther apart, or widen `b`'s tolerance to 18 in" \
        in text
    text = error(goals("{x: 300, y: -10}", "{x: 300, y: 18, tolerance: 1}"))
    assert "are 28.0 in apart; two robots' goals must be at least 29 in apart" in text
    assert "move the goals 1 in or more farther apart" in text
    assert parse_world(goals("{x: 300, y: -10}", "{x: 300, y: 19, tolerance: 1}"), "w.yaml")
    # tolerances as wide as the two half-widths: room wherever the other parks
    assert "widen `robot`'s tolerance to 18 in" in error(
        goals("{x: 300, y: -10}", "{x: 300, y: -10, tolerance: 18}"))
    assert parse_world(goals("{x: 300, y: -10, tolerance: 18}",
                             "{x: 300, y: -10, tolerance: 18}"), "w.yaml")


def test_two_robots_given_one_goal_are_refused():
    """Both robots' goals at one point with tolerances of 12 in were taken (the two centres
    could stand 24 in apart there, the bodies needing 18): the robot that came second drove
    at the first, parked where it entered its tolerance (`fleet_tiny` with one goal and a
    time limit of 90 s: 1 success in 20 runs, 11 collisions, 8 stuck)."""
    text = error(goals("{x: 300, y: -10}", "{x: 300, y: -10}"))
    assert ("w.yaml:13:13: world error: the goals (q_goal) of `robot` at (300, -10) and `b` at "
            "(300, -10) are 0.0 in apart; two robots' goals must be at least 18 in apart: half "
            "of each one's narrower side (9 + 9 in) plus the first's tolerance less the "
            "second's (12 - 12 in)") in text
    assert "hint: move the goals 18 in or more farther apart, or widen `b`'s tolerance to 18 in" \
        in text
    assert "move the goals 1 in or more" in error(goals("{x: 300, y: -10}", "{x: 300, y: 7}"))
    assert parse_world(goals("{x: 300, y: -10}", "{x: 300, y: 8}"), "w.yaml")


def test_a_goal_inside_a_robot_parked_from_its_start_is_refused():
    """A robot that starts within its goal's tolerance stands there from the first tick; a
    goal inside its body was driven at until the time limit. A goal inside the start of a
    robot that drives off is taken: it leaves."""
    parked = "  - {name: parked, q_init: {x: 300, y: 20, heading: 90}, q_goal: {x: 300, y: 25}}\n"
    text = error(world(parked).replace("q_goal: {x: 30, y: 10}", "q_goal: {x: 300, y: 25}"))
    assert ("w.yaml:13:13: world error: the goal (q_goal) of `b` at (300, 25) is taken by "
            "`parked`, which starts within its own goal's tolerance and so stands there from "
            "the first tick: within 12 in of the goal, `b`'s centre comes at most 5.1 in from "
            "`parked`'s body, and its own body needs 9 in\n") in text
    assert "hint: move the goal, or start `parked` farther from its own goal" in text
    leaves = parked.replace("q_goal: {x: 300, y: 25}", "q_goal: {x: 500, y: 20}")
    assert parse_world(world(leaves).replace("q_goal: {x: 30, y: 10}", "q_goal: {x: 300, y: 25}"),
                       "w.yaml")


def test_give_way_false_under_the_first_robot_holds_for_every_robot_that_sets_none():
    """As worlds/README.md says (a user leaving the first robot out left all of them out)."""
    w = parse_world(world("    robot: {give_way: true}\n", top="  give_way: false\n"), "w.yaml")
    assert [a.robot.give_way for a in w.agents] == [False, True]
    w = parse_world(world(top="  give_way: false\n"), "w.yaml")
    assert [a.robot.give_way for a in w.agents] == [False, False]


@pytest.mark.parametrize("part, said", [
    ("robots:\n  - {name: b, q_init: {x: 30, y: 8}, q_goal: {x: 570, y: 8}}\n",
     "w.yaml:11:23: world error: at the start (q_init) of `b`, (30, 8) heading 0 deg, the "
     "robot's body touches robot `robot`'s at its start (a touch is a contact: the run would "
     "end in a collision at its first tick)"),
    ("obstacles:\n  - {name: box, shape: circle, at: [50, -10], radius: 8}\n",
     "w.yaml:8:9: world error: at the start (q_init), (30, -10) heading 0 deg, the robot's body "
     "(24 x 18 in) touches obstacle `box` (a touch is a contact"),
    ("obstacles:\n  - {name: crate, shape: rectangle, at: [30, -28], length: 10, width: 18}\n",
     "touches obstacle `crate` (a touch is a contact")])
def test_a_start_touching_a_robot_or_an_obstacle_is_refused_as_one_reaching_in(part, said):
    """A body touching another robot's or an obstacle at its start was taken ("touching is
    not reaching in") and the run read `COLLISION ... after 0.00 s`: a touch is a contact
    (clearance 0), as a start touching a wall was refused already."""
    text = WORLD.replace("TOP\n", "").replace("ITEM\n", "")
    head, _, rest = text.partition("robots:\n")
    rest = rest.partition("map:\n")[2]
    text = error(head + part + "map:\n" + rest)
    assert said in text, text
    apart = part.replace("y: 8}", "y: 9}").replace("[50, -10]", "[51, -10]").replace(
        "[30, -28]", "[30, -29]")
    assert parse_world(head + apart + "map:\n" + rest, "w.yaml")


def test_a_short_footprint_under_the_first_robots_wheelbase_says_whose_it_is():
    """`robot: {footprint: {length: 10, width: 8}}` under the first robot's 16 in wheelbase
    was told "shorten `wheelbase`", a key the item does not have."""
    text = error(world("    robot: {footprint: {length: 10, width: 8}}\n"))
    assert ("w.yaml:14:24: world error: the wheelbase (16 in, the first robot's, which this "
            "robot takes) is longer than the robot's footprint (10 in long)") in text
    assert ("hint: give this robot its own `wheelbase` (at most 10 in) beside its `footprint`, "
            "or lengthen the footprint") in text
    assert parse_world(world("    robot: {footprint: {length: 10, width: 8}, wheelbase: 8}\n"),
                       "w.yaml").agents[1].robot.wheelbase == 8


@pytest.mark.parametrize("corridors, goal, said", [
    ("    - points: [[1000, 0], [1200, 0]]\n      width: 90\n", "{x: 1100, y: 0}",
     "w.yaml:13:13: world error: robot `b`: the corridors do not connect the start to the goal"),
    ("    - points: [[600, 0], [700, 0]]\n      width: 15\n"
     "    - points: [[700, 0], [800, 0]]\n      width: 90\n", "{x: 780, y: 0}",
     "w.yaml:13:13: world error: robot `b`: the only way to the goal passes (645, 0)")])
def test_a_fleet_robot_without_a_route_is_named(corridors, goal, said):
    """"the corridors do not connect the start to the goal" did not say whose, in a world of
    several robots (the line did, at `b`'s q_goal)."""
    from mitos_cli.sim.loop import prepare

    def refusal(text: str) -> str:
        with pytest.raises(WorldError) as info:
            prepare(parse_world(text, "w.yaml"))
        return info.value.render()

    wider = world().replace("      width: 90\n", "      width: 90\n" + corridors)
    assert said in refusal(wider.replace("q_goal: {x: 30, y: 10}", f"q_goal: {goal}"))
    head, _, rest = wider.replace("q_goal: {x: 570, y: -10}", f"q_goal: {goal}").partition(
        "robots:\n")
    alone = refusal(head + "map:" + rest.partition("map:")[2])
    assert "world error: the " in alone and "robot `" not in alone    # one robot: as it was


@pytest.mark.parametrize("where, block, said", [
    ("item", "    heading: 180\n",
     "hint: `heading` is the start's: write it in `q_init`, as `q_init: {x: ..., y: ..., "
     "heading: 180}`"),
    ("item", "    tolerance: 3\n",
     "hint: `tolerance` is the goal's: write it in `q_goal`, as `q_goal: {x: ..., y: ..., "
     "tolerance: 3}`"),
    ("robot", "    robot: {tolerance: 3}\n", "hint: `tolerance` is the goal's"),
    ("top", "heading: 90\n", "hint: `heading` is the start's: write it in `q_init`, as "
     "`q_init: {x: ..., y: ..., heading: 90}`"),
    ("item", "    x: 5\n", "hint: `x` is a coordinate of `q_init` or `q_goal`")])
def test_a_starts_or_goals_key_beside_it_says_where_it_belongs(where, block, said):
    """`heading: 180` beside a `robots:` item's `q_init` was "unknown key" with no hint."""
    text = error(world(top=block) if where == "top" else world(block))
    assert said in text, text


def test_half_a_footprint_in_an_item_offers_the_first_robots_other_side():
    """`robot: {footprint: {width: 14}}`: the steering's keys are taken one by one from the
    first robot, a footprint's are not; "add `length: ...`" did not say what it had been."""
    text = error(world("    robot: {footprint: {width: 14}}\n"))
    assert "w.yaml:14:24: world error: missing `length` in the footprint of robot `b`\n" in text
    assert "hint: add `length: 24` to keep the first robot's length" in text


FIXED = ("randomise moves obstacles and the sensor noise, not the robots: each robot starts at "
         "its `q_init`")


@pytest.mark.parametrize("randomise, said", [
    ("randomise:\n  obstacles:\n    b: {dx: [-10, 10]}\n", f"hint: `b` is a robot: {FIXED}"),
    ("randomise:\n  robots:\n    b: {dx: [-10, 10]}\n", f"hint: {FIXED}"),
    ("randomise:\n  q_init: {dx: [-10, 10]}\n", f"hint: {FIXED}")])
def test_randomising_a_robot_says_randomise_moves_obstacles(randomise, said):
    """A robot's name under `randomise: obstacles:` was "unknown key" offered the obstacles'
    names, and `randomise: robots:` no hint at all."""
    box = "obstacles:\n  - {name: box, shape: circle, at: [300, 30], radius: 5}\n"
    text = error(world() + box + randomise)
    assert said in text, text
    none = error(world() + randomise.replace("robots", "obstacles"))   # and no obstacles
    assert f"hint: {FIXED}" in none


@pytest.mark.parametrize("block, said", [
    ("top:max_sped: 40\n", "hint: did you mean `max_speed`? `max_speed` is a key of the robot "
     "itself: write it under `robot:`"),
    ("    giveway: false\n", "hint: did you mean `give_way`? `give_way` is a key of the robot "
     "itself: write it under this robot's `robot:`"),
    ("    robot: {q_gaol: {x: 1, y: 2}}\n", "hint: did you mean `q_goal`? `q_goal` is the "
     "`robots:` item's: write it beside `robot:`, not under it"),
    ("    robto: {max_speed: 3}\n", "hint: did you mean `robot`?\n"),
    ("top:robtos: []\n", "hint: did you mean `robots`?")])
def test_a_misspelt_key_of_another_block_is_offered_with_where_it_belongs(block, said):
    """`max_sped: 40` at the top of the file was offered `name` (the closest top key); the
    closest key of any block is offered, with where it goes."""
    text = error(world(top=block[4:]) if block.startswith("top:") else world(block))
    assert said in text + "\n", text


def test_a_misspelt_heading_beside_q_init_is_offered_without_a_value_it_lacks():
    text = error(world("    headng: 180\n"))
    assert ("hint: did you mean `heading`? `heading` is the start's: write it in `q_init`, as "
            "`q_init: {x: ..., y: ..., heading: ...}`") in text


def _open_fleet(starts: list[tuple[float, float, float]], size: tuple[float, float]) -> str:
    """A wide corridor, the first robot far off, and one robot of ``size`` (length, width)
    at each of ``starts`` (x, y, heading), each to a goal of its own far from every start."""
    length, width = size
    rows = "".join(f"  - {{name: r{i}, q_init: {{x: {x!r}, y: {y!r}, heading: {h!r}}}, "
                   f"q_goal: {{x: {1000 + 80 * i}, y: -60}}}}\n"
                   for i, (x, y, h) in enumerate(starts))
    end = 1100 + 80 * len(starts)
    return (f"name: t\ndt: 0.05\ntime_limit: 10\nrobot:\n  model: tricycle\n  wheelbase: 16\n"
            f"  footprint: {{length: {length!r}, width: {width!r}}}\n"
            f"q_init: {{x: 30, y: -60}}\nq_goal: {{x: {end - 40}, y: 60}}\n"
            f"robots:\n{rows}map:\n  corridors:\n    - points: [[0, 0], [{end}, 0]]\n"
            f"      width: 240\n")


@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(st.floats(200, 320), st.floats(-50, 50), st.floats(-180, 180)),
                min_size=2, max_size=6),
       st.tuples(st.floats(18, 40), st.floats(16, 18)))
def test_overlapping_starts_are_found_as_measuring_every_pair_finds_them(starts, size):
    """The starts' check measures only robots whose bodies' circles meet (a fleet of 400
    took 4.6 CPU s, every pair measured): the first pair that touches or overlaps, in the
    file's order, is the one measuring every pair finds."""
    import math

    import numpy as np

    from mitos_cli.sim.geometry import box_polygon_distance, rect_corners

    length, width = size
    found = None
    for i, (x, y, h) in enumerate(starts):
        c, s = math.cos(math.radians(h)), math.sin(math.radians(h))
        for j, (x2, y2, h2) in enumerate(starts[:i]):
            corners = rect_corners(x2, y2, math.radians(h2), length, width)
            local = (corners - np.array([x, y])) @ np.array([[c, -s], [s, c]])
            if box_polygon_distance(length / 2, width / 2, local[None])[0] <= 0.0:
                found = (i, j)
                break
        if found:
            break
    text = _open_fleet(starts, size)
    if found is None:
        parse_world(text, "w.yaml")
        return
    said = error(text)
    i, j = found
    assert f"at the start (q_init) of `r{i}`" in said and f"robot `r{j}`'s at its start" in said
