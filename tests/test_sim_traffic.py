"""Robots of one world give way where their routes cross (:mod:`mitos_cli.sim.traffic`):
the rule of the road on straight routes, and four robots at a crossroads in the simulator."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.errors import WorldError
from mitos_cli.resources import packaged_path
from mitos_cli.sim import traffic
from mitos_cli.sim.knowledge import RobotMap
from mitos_cli.sim.lockstep import run_lockstep
from mitos_cli.sim.loop import STUCK_TIME, Simulation, prepare, simulate
from mitos_cli.sim.planner import FuzzyPlanner
from mitos_cli.sim.route import Route
from mitos_cli.sim.world import Grid, Robot
from mitos_cli.sim.worldfile import load_world

DATA = Path(__file__).parent / "data"
ROBOT = Robot()
DT = 0.05


def driving(x: float, y: float, heading_deg: float, speed: float = 30.0,
            length: float = 600.0) -> traffic.Mate:
    """A robot at (x, y) on a straight route of ``length`` in along ``heading_deg``."""
    h = math.radians(heading_deg)
    start = (x - 50 * math.cos(h), y - 50 * math.sin(h))
    end = (x + length * math.cos(h), y + length * math.sin(h))
    return traffic.Mate(Route.of([start, end]), 50.0, x, y, speed, ROBOT)


def limits(*mates: traffic.Mate | None) -> np.ndarray:
    return traffic.Traffic().limits(list(mates), DT)


def test_of_two_robots_coming_to_a_crossing_the_one_with_the_other_on_its_right_gives_way():
    east = driving(-150, 0, 0)         # eastbound, 150 in before the crossing
    north = driving(0, -150, 90)       # northbound: it comes from the eastbound's right
    lim = limits(east, north)
    assert math.isinf(lim[1])
    room = traffic.room(east, north)   # straight to north's route (its places 4 in apart)
    assert room == pytest.approx(150 - traffic.zone(east, north) - traffic.SLACK, abs=0.1)
    assert lim[0] == math.sqrt((40 * DT) ** 2 + 2 * 40 * room) - 40 * DT   # stops there
    lim = limits(north, east)          # the same in the other order
    assert math.isinf(lim[0]) and math.isfinite(lim[1])


def test_head_on_and_one_behind_the_other_are_no_crossing():
    assert traffic.crossing(driving(-150, 0, 0), driving(150, 10, 180)) is None
    assert traffic.crossing(driving(-150, 0, 0), driving(-60, 0, 0)) is None
    assert np.isinf(limits(driving(-150, 0, 0), driving(150, 10, 180))).all()


def test_robots_far_apart_or_no_longer_driving_give_way_to_none():
    assert np.isinf(limits(driving(-150, 0, 0), driving(0, -900, 90))).all()
    assert np.isinf(limits(driving(-150, 0, 0), None)).all()


def test_a_robot_that_can_no_longer_stop_short_of_the_crossing_goes_first():
    # the eastbound robot has the northbound one on its right, but drives at 60 in/s 35 in
    # before the crossing's edge: it cannot stop there (60^2 / 80 = 45 in, and a tick's 3)
    fast = driving(-90, 0, 0, speed=60.0)
    north = driving(0, -200, 90)
    c = traffic.crossing(fast, north)
    assert c is not None and c.right and traffic.committed(fast, c.enter[0], DT)
    lim = limits(fast, north)
    assert math.isinf(lim[0]) and math.isfinite(lim[1])


def test_who_goes_first_is_kept_until_the_crossing_is_behind_them():
    ways = traffic.Traffic()
    east, north = driving(-150, 0, 0), driving(0, -150, 90)
    assert math.isfinite(ways.limits([east, north], DT)[0]) and ways.order == {(0, 1): 1}
    # the one giving way has nearly stopped and the other, slowed, is farther off: decided
    # afresh, the eastbound robot would clear it first now; it waits on
    east, north = driving(-80, 0, 0, speed=2.0), driving(0, -200, 90, speed=10.0)
    assert math.isfinite(ways.limits([east, north], DT)[0]) and ways.order == {(0, 1): 1}
    # the northbound robot is through, its rear past the crossing: the eastbound goes
    east, north = driving(-80, 0, 0, speed=0.0), driving(0, 100, 90)
    assert np.isinf(ways.limits([east, north], DT)).all() and ways.order == {}


def test_four_robots_each_with_another_on_its_right_the_first_of_the_ring_goes():
    ring = [driving(-150, -15, 0), driving(150, 15, 180), driving(-15, 150, 270),
            driving(15, -150, 90)]
    lim = limits(*ring)
    assert math.isinf(lim[0])                         # the first in the world's order goes
    assert np.isfinite(lim[1:]).all()                 # the others wait (on it, or in turn)


def test_rings_that_overlap_are_broken_so_that_each_pair_keeps_one_robot_waiting():
    """Six robots at a crossroads (a helper's ``six.yaml``, seed 1005, at 17.25 s): rings
    {1, 2, 5}, {2, 3, 5} and {3, 4, 5}. Dropping the waits of each ring's lowest robot freed
    both robots of the pair (1, 2), which then collided."""
    edges = {(1, 2), (2, 5), (5, 1), (2, 3), (3, 5), (3, 4), (4, 5), (0, 1)}
    gives: list[dict[int, float]] = [{} for _ in range(6)]
    for i, j in edges:
        gives[i][j] = 1.0
    traffic._unring(gives, lambda i, j: 2.0)
    assert traffic._ring(gives) is None
    after = {(i, j) for i in range(6) for j in gives[i]}
    assert {frozenset(e) for e in after} == {frozenset(e) for e in edges}   # one each way
    assert len(after) == len(edges)
    assert gives[2][1] == 2.0 and 2 not in gives[1]     # the lowest goes, the other waits


def test_a_robot_already_in_the_crossing_giving_way_stops_where_it_is():
    # the two routes moved (a replanning) and the robot giving way finds itself inside
    ways = traffic.Traffic()
    ways.order[0, 1] = 1
    east, north = driving(-40, 0, 0, speed=20.0), driving(0, -150, 90)
    c = traffic.crossing(east, north, known=True)
    assert c is not None and traffic.room(east, north) == 0.0
    assert ways.limits([east, north], DT)[0] == 0.0


@settings(max_examples=200, deadline=None)
@given(angle=st.floats(35, 145), da=st.floats(60, 220), db=st.floats(60, 220),
       va=st.floats(0, 60), vb=st.floats(0, 60))
def test_at_a_crossing_of_two_never_both_give_way_and_the_one_that_does_stops_outside(
        angle, da, db, va, vb):
    """Two straight routes crossing at the origin at ``angle``, the robots ``da`` and ``db``
    in before it: at most one gives way, and its limit lets it stop before it comes within
    the zone of the other's route (the room is measured straight to that route, never more
    than along its own)."""
    a = driving(-da, 0, 0, speed=va)
    h = math.radians(angle)
    b = driving(-db * math.cos(h), -db * math.sin(h), angle, speed=vb)
    lim = limits(a, b)
    assert np.isinf(lim).sum() >= 1
    for i, (me, other) in enumerate(((a, b), (b, a))):
        if not math.isinf(lim[i]):
            room = traffic.room(me, other)
            assert lim[i] == traffic.brake(room, me.acceleration, 0.0, DT)
            gap = float(np.min(np.hypot(*(other.path - me.at).T)))
            assert room <= max(gap - traffic.zone(me, other), 0.0)


def _without_giving_way(world):
    return dataclasses.replace(world, agents=tuple(
        dataclasses.replace(a, robot=dataclasses.replace(a.robot, give_way=False))
        for a in world.agents))


def test_four_robots_at_a_crossroads_give_way_where_without_it_two_collide():
    world = load_world(DATA / "crossroads4.yaml")
    on = simulate(world, seed=1001, randomise=True)
    off = simulate(_without_giving_way(world), seed=1001, randomise=True)
    assert off.outcome == "collision" and off.robot_outcomes.count("collision") == 2
    assert on.robot_outcomes == ("success",) * 4
    assert on.metrics["min_clearance_in"] > 0


def test_a_crossroads_run_gives_way_alike_alone_and_in_a_batch():
    """Who goes first is each run's own state, kept from tick to tick: a run in a lockstep
    batch gives way as it does alone (cut to 14 s: the robots are at the crossing)."""
    from test_sim_lockstep import assert_same_run

    world = load_world(DATA / "crossroads4.yaml").with_changes(time_limit=14.0)
    planner, scene = FuzzyPlanner(None, world.behavior), prepare(world)
    seeds = [1001, 1003, 1011]
    together = run_lockstep(world, planner, seeds, randomise=True, scene=scene)
    for seed, res in zip(seeds, together):
        alone = simulate(world, planner, seed, randomise=True, scene=scene)
        assert_same_run(alone, res)
        assert (res.speed[res.t > 10] < 1).any()          # somebody waited


def _slow_from_the_right(tmp_path: Path, x: float) -> Path:
    """crossroads4's map with two robots: one eastbound from (``x``, -15), and a slow one
    (8 in/s) northbound 90 in below the crossing, coming from its right."""
    text = (DATA / "crossroads4.yaml").read_text()
    head = text[:text.index("robots:")].replace("q_init: {x: 30, y: -15, heading: 0}",
                                                f"q_init: {{x: {x:g}, y: -15, heading: 0}}")
    path = tmp_path / f"slow{x:g}.yaml"
    path.write_text(head + """robots:
  - name: slow
    robot: {model: tricycle, wheelbase: 16, footprint: {length: 24, width: 18}, max_speed: 8}
    q_init: {x: 415, y: -90, heading: 90}
    q_goal: {x: 415, y: 370, tolerance: 12}

map:
  corridors:
    - points: [[0, 0], [800, 0]]
      width: 90
    - points: [[400, -400], [400, 400]]
      width: 90
""")
    return path


def test_a_robot_giving_way_longer_than_the_stuck_time_is_waiting_not_stuck(tmp_path):
    """A slow robot (8 in/s) crossing from the right, near the crossing, keeps the other
    waiting well over ``STUCK_TIME``; it then goes on and both arrive."""
    res = simulate(load_world(_slow_from_the_right(tmp_path, 250)))
    assert res.robot_outcomes == ("success", "success")
    still = (res.speed[:, 0] < 0.5) & res.active[:, 0]
    longest = max((len(run) for run in np.split(still, np.flatnonzero(~still)) if len(run)),
                  default=0) * res.world.dt
    assert longest > STUCK_TIME


def test_give_way_is_a_robot_setting_of_the_world_file(tmp_path):
    text = (DATA / "crossroads4.yaml").read_text()
    off = tmp_path / "off.yaml"
    off.write_text(text.replace("  acceleration: 40\n", "  acceleration: 40\n  give_way: false\n"))
    assert not load_world(off).robot.give_way and load_world(DATA / "crossroads4.yaml").robot.give_way
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace("  acceleration: 40\n", "  acceleration: 40\n  give_way: often\n"))
    with pytest.raises(WorldError, match="give_way"):
        load_world(bad)


def test_a_robot_told_to_stop_where_it_gives_way_is_waiting_not_stuck(tmp_path):
    """A robot giving way (its limit 0, 12 in before the crossing) told to stop by its
    planner, as DWA does for the robot it gives way to, waits as one the limit stops: the
    slow robot from its right takes longer than ``STUCK_TIME`` to clear the crossing, and the
    run goes on (the waiting was not counted where the command was no faster than the limit,
    and the robot read ``stuck`` after 6 s)."""
    sim = Simulation(load_world(_slow_from_the_right(tmp_path, 350)), seed=1)
    told = np.array([[90.0, 0.0], [90.0, 8.0]])         # the first stops, the slow drives on
    while not sim._ways.order:                          # (the slow one's route 3 s ahead
        sim.step(told)                                  # reaches the crossing at 2 s)
    assert sim._ways.order == {(0, 1): 1} and sim.time < 3.0
    for _ in range(int(round((STUCK_TIME + 3.0) / sim.dt))):
        assert not sim.done, sim.result().robot_outcomes
        sim.step(told)
        assert sim._ways.order == {(0, 1): 1}           # the first gives way throughout
    assert not sim.done


def test_the_echoes_of_each_robot_are_told_apart_from_walls_and_from_each_other():
    """A reading is robot ``j``'s echo when it ends on ``j``'s body, noise within
    :data:`ECHO_PAD` included: not one ending on a wall behind it, nor a robot's own."""
    pose = np.array([[0.0, 0.0, 0.0], [100.0, 0.0, math.pi / 2], [100.0, 60.0, 0.0]])
    dirs = np.array([[[1.0, 0.0], [0.0, 1.0], [100 / math.hypot(100, 60), 60 / math.hypot(100, 60)]]] * 3)
    # robot 0's beams: along +x onto robot 1's side (its body spans x 91..109), up to a
    # wall, and onto robot 2, standing 60 in above robot 1 (its body spans x 88..112)
    ranges = np.array([[91.0 + 4.0, 150.0, math.hypot(100, 60) - 12.0]] * 3)
    of = traffic.echoes(pose, [ROBOT] * 3, ranges, dirs)
    assert of.shape == (3, 3, 3)
    assert of[0, 1].tolist() == [True, False, False]
    assert of[0, 2].tolist() == [False, False, True]
    assert not of[[0, 1, 2], [0, 1, 2]].any()
    ranges[0, 0] = 91.0 - traffic.ECHO_PAD - 0.5           # short of the body: something else
    assert not traffic.echoes(pose, [ROBOT] * 3, ranges, dirs)[0, 1, 0]


def test_mates_are_the_other_robots_that_share_and_still_drive():
    share, active = [True, True, False, True], np.array([True, True, True, False])
    assert traffic.mates(share, active).tolist() == [
        [False, True, False, False], [True, False, False, False],
        [False, False, False, False], [False, False, False, False]]


def test_a_robot_leaves_off_its_map_the_mates_that_move_and_the_one_it_waits_on():
    """Robot 0 waits on robot 2, which stands in the crossing; robot 1 drives by; robot 3
    stands still; robot 4 shares nothing. Robot 0 marks 3 and 4 (standing things, a robot
    outside the fleet), never 1 nor 2; the others mark 2 and 3 where they stand."""
    share = [True, True, True, True, False]
    active = np.ones(5, dtype=bool)
    speed = np.array([0.0, 30.0, 0.0, traffic.MOVING / 2, 30.0])
    off = traffic.unmarked(share, active, speed, [(0, 2)])
    assert off.tolist() == [[False, True, True, False, False],
                            [False, False, False, False, False],
                            [False, True, False, False, False],
                            [False, True, False, False, False],
                            [False, False, False, False, False]]


@settings(max_examples=60, deadline=None)
@given(heading=st.floats(-math.pi, math.pi), ahead=st.floats(-80, 80),
       half=st.sampled_from([1.0, 2.5, 5.0]))
def test_a_mates_outline_covers_the_cells_round_its_stretched_footprint_without_gaps(
        heading, ahead, half):
    """The squares laid round a mate's footprint (stretched by the room it takes to stop)
    cover the band a cell wide just outside it, as marks of its echoes would, and leave no
    gap a brake's sweep could pass through."""
    pose = np.array([[10.0, -20.0, heading]])
    out = traffic.outlines(pose, [ROBOT], np.array([True]), half, np.array([ahead]))[0]
    c, s = math.cos(heading), math.sin(heading)
    rel = out - pose[0, :2]
    u, v = rel @ np.array([c, s]), rel @ np.array([-s, c])
    a, b = ROBOT.length / 2 + half, ROBOT.width / 2 + half          # the squares' centres
    lo, hi = -a + min(ahead, 0.0), a + max(ahead, 0.0)
    assert (u >= lo - 1e-9).all() and (u <= hi + 1e-9).all()
    assert (np.abs(v) <= b + 1e-9).all()
    assert math.isclose(u.min(), lo, abs_tol=1e-9) and math.isclose(u.max(), hi, abs_tol=1e-9)
    assert math.isclose(np.abs(v).max(), b, abs_tol=1e-9)
    # along each long side the squares touch or overlap: no gap
    side = np.sort(u[np.isclose(v, b)])
    assert (np.diff(side) <= 2 * half + 1e-9).all()
    assert traffic.outlines(pose, [ROBOT], np.array([False]), half, np.array([ahead]))[0].shape == (0, 2)


def test_a_mate_is_stretched_by_the_room_it_takes_to_stop_a_tick_late():
    """At 40 in/s with an acceleration of 40 in/s^2 a robot drives 20 in braking, and 2 in
    in the tick before: 22 in ahead; backing out at 10 in/s, 1.75 in behind."""
    robot = dataclasses.replace(ROBOT, acceleration=40.0)
    ahead = traffic.stopping(np.array([40.0, -10.0, 0.0]), [robot] * 3, DT)
    assert np.allclose(ahead, [22.0, -1.75, 0.0])


def test_a_robot_that_waited_at_a_crossing_goes_on_without_planning_round_the_other():
    """``cross135_left`` seed 1002: ``b`` gives way at the corner of the crossing. When it
    marked the other robot's echoes on its map, the crossing held a trail of walls when it
    could go: its new route swung it into the corner, and it backed out ten times and ran
    out of time. Not marking the robot it waits on, it waits and goes straight on."""
    res = simulate(load_world(DATA / "traffic" / "cross135_left.yaml"), seed=1002,
                   randomise=True)
    assert res.robot_outcomes == ("success", "success")
    assert res.backed_out == () and res.replanned == ()
    assert (res.speed[:, 1] < 1).any()                          # b waited


def test_dwa_gets_going_again_after_giving_way_at_a_t_junction():
    """``tee_left_turn`` seed 1000 with DWA: the robot turning left across the other's lane
    waits for it; with the other's echoes marked on its map it then ended ``stuck`` (14 of
    20 runs)."""
    from mitos_cli.sim.planner import make_planner

    world = load_world(DATA / "traffic" / "tee_left_turn.yaml")
    res = simulate(world, make_planner("dwa", world), seed=1000, randomise=True)
    assert res.robot_outcomes == ("success", "success")


def test_six_robots_that_drive_by_each_other_leave_no_trails_and_all_arrive():
    """``crossroads6`` seeds 1000 and 1001: robots overtaking a mate that gave way swerved
    into the oncoming lane round the trails their maps held of mates driving by, and two
    met head-on in the crossing (collisions at 15.7 and 20.7 s). Leaving moving mates off
    the maps, and braking for their bodies stretched by their stopping room, all six
    arrive, alike alone and in a batch."""
    from test_sim_lockstep import assert_same_run

    world = load_world(DATA / "traffic" / "crossroads6.yaml")
    planner, scene = FuzzyPlanner(None, world.behavior), prepare(world)
    together = run_lockstep(world, planner, [1000, 1001], randomise=True, scene=scene)
    assert [res.robot_outcomes for res in together] == [("success",) * 6] * 2
    assert_same_run(simulate(world, planner, 1000, randomise=True, scene=scene), together[0])


def test_a_robot_passing_a_mate_that_turns_as_it_stops_keeps_off_it():
    """``multirobot`` seed 16: `robot` passed `oncoming` at a hair as `oncoming` turned and
    stopped, and touched it (17.15 s) when its brake counted the mate's body flush inside
    the footprint; counting the cells just outside it, as marks of its echoes would be, both
    arrive."""
    res = simulate(load_world(packaged_path("worlds", "multirobot.yaml")), seed=16,
                   randomise=True)
    assert res.robot_outcomes == ("success", "success")


def corridor_map(box: tuple[float, float, float, float] | None = None) -> RobotMap:
    """A robot's map of a corridor 90 in wide along x from 0 to 800 (cells of 2 in), with
    the cells of ``box`` (x0, x1, y0, y1) marked as a robot marks what it sensed."""
    res, origin = 2.0, (-10.0, -60.0)
    xs = origin[0] + (np.arange(420) + 0.5) * res
    ys = origin[1] + (np.arange(60) + 0.5) * res
    x, y = np.meshgrid(xs, ys)
    rmap = RobotMap.of(Grid(np.abs(y) > 45, res, origin))
    if box is not None:
        x0, x1, y0, y1 = box
        inside = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
        rmap.mark_cells(np.stack([inside.nonzero()[1], inside.nonzero()[0]], axis=1))
    return rmap


def on_map(x: float, y: float, heading_deg: float, rmap: RobotMap,
           speed: float = 30.0) -> traffic.Mate:
    """:func:`driving`, with the robot's map."""
    m = driving(x, y, heading_deg, speed)
    return traffic.Mate(m.route, m.progress, x, y, speed, ROBOT, rmap)


#: boxes on the south side of the corridor leave 40 in of it (two side by side need 44)
BOXES = (360.0, 440.0, -45.0, 5.0)


def test_the_room_across_a_path_is_measured_on_the_robots_map():
    path = np.stack([np.arange(0.0, 800.0, 4.0), np.full(200, 25.0)], axis=1)
    width, middle = traffic.across(corridor_map(BOXES), path, np.array([50, 100]), 44.0)
    # at x = 200 the corridor (wall to wall 20 + 44: room for two, not measured), at x = 400
    # the room between the boxes and the wall, in whole cells as the map marches its beams
    assert math.isinf(width[0]) and middle[0].tolist() == [200.0, 25.0]
    assert width[1] == pytest.approx(40, abs=2.0)
    assert middle[1, 1] == pytest.approx(25.0, abs=1.0)


def _marched(rmap: RobotMap, path: np.ndarray, places: np.ndarray,
             cap: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`.traffic.across` as it was first written: every place's four beams marched."""
    along = np.gradient(path, axis=0)[places]
    length = np.hypot(along[:, 0], along[:, 1])
    ok = length > 1e-9
    unit = np.zeros_like(along)
    unit[ok] = along[ok] / length[ok, None]
    left = np.stack([-unit[:, 1], unit[:, 0]], axis=1)
    at = path[places]
    origins = np.concatenate([at - unit * (traffic.STEP / 4), at + unit * (traffic.STEP / 4)] * 2)
    n = len(places)
    sides = rmap.ranges(origins, np.concatenate([left, left, -left, -left]), cap)
    to_left, to_right = np.minimum(sides[:n], sides[n:2 * n]), np.minimum(sides[2 * n:3 * n],
                                                                           sides[3 * n:])
    width = to_left + to_right
    width[~ok] = np.inf
    return width, at + left * ((to_left - to_right) / 2)[:, None]


@settings(max_examples=100, deadline=None)
@given(st.integers(2, 60), st.data())
def test_a_paths_direction_at_some_places_is_numpys_gradient_there(n, data):
    """:func:`.traffic._along` works the gradient out only where it is needed, to the bit."""
    coords = st.floats(-1e4, 1e4, allow_nan=False)
    path = np.array(data.draw(st.lists(st.tuples(coords, coords), min_size=n, max_size=n)))
    places = np.array(sorted(data.draw(st.sets(st.integers(0, n - 1), min_size=1))))
    assert traffic._along(path, places).tolist() == np.gradient(path, axis=0)[places].tolist()


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 780), st.floats(-60, 40), st.floats(1, 40),
                          st.floats(1, 40)), max_size=4),
       st.floats(-40, 40), st.floats(-0.6, 0.6), st.floats(10, 80))
def test_the_room_measured_where_something_is_near_is_the_room_every_beam_gives(boxes, y, slope,
                                                                                cap):
    """Places with nothing occupied near are not marched: every place's room under ``cap``
    is the same to the bit as with every place's beams marched, and none is missed."""
    rmap = corridor_map()
    gx, gy = np.meshgrid(-10.0 + (np.arange(420) + 0.5) * 2.0, -60.0 + (np.arange(60) + 0.5) * 2.0)
    for x0, y0, w, h in boxes:
        inside = (gx >= x0) & (gx <= x0 + w) & (gy >= y0) & (gy <= y0 + h)
        rmap.mark_cells(np.stack([inside.nonzero()[1], inside.nonzero()[0]], axis=1))
    xs = np.arange(0.0, 800.0, 4.0)
    path = np.stack([xs, y + slope * (xs - 400.0)], axis=1)
    places = np.arange(0, 200, 3)
    width, middle = traffic.across(rmap, path, places, cap)
    full, centre = _marched(rmap, path, places, cap)
    under = full < cap
    assert (width < cap).tolist() == under.tolist()
    assert width[under].tolist() == full[under].tolist()
    assert middle[under].tolist() == centre[under].tolist()


def test_head_on_where_boxes_leave_room_for_one_the_robot_with_them_on_its_side_waits():
    """The rule of the road: give way where the obstruction is on your side. The boxes are
    on the eastbound's side, its route (not yet planned round them) running into them."""
    rmap = corridor_map(BOXES)
    east, west = on_map(200, -15, 0, rmap), on_map(600, 15, 180, rmap)
    c = traffic.crossing(east, west)
    assert c is not None and c.narrow and c.right          # the room is on west's side
    assert waits(east, west) == [(0, 1)]
    assert waits(west, east) == [(1, 0)]                   # in the other order, the same
    # boxes on the north side: the westbound waits
    north = corridor_map((360.0, 440.0, -5.0, 45.0))
    assert waits(on_map(200, -15, 0, north), on_map(600, 15, 180, north)) == [(1, 0)]
    # its route running on in its lane (into the boxes, unseen), it stops short of the
    # place: its front 12 in before where its route comes within the zone of the room west
    # takes (x = 316), as never into the other's way (below)
    room = traffic.room_before(east, east.point(c.enter[0]))
    assert room == 316 - 200 - 12 - traffic.SLACK
    lim = limits(east, west)
    assert math.isinf(lim[1]) and lim[0] == math.sqrt((40 * DT) ** 2 + 2 * 40 * room) - 40 * DT


def waits(*mates: traffic.Mate) -> list[tuple[int, int]]:
    ways = traffic.Traffic()
    ways.limits(list(mates), DT)
    return ways.waits


def test_head_on_in_a_corridor_with_room_for_two_is_no_crossing():
    wide = corridor_map((360.0, 440.0, -45.0, -30.0))       # 75 in left
    assert traffic.crossing(on_map(200, -15, 0, wide), on_map(600, 15, 180, wide)) is None
    assert traffic.crossing(on_map(200, -15, 0, corridor_map()),
                            on_map(600, 15, 180, corridor_map())) is None


def test_a_robot_standing_in_the_way_is_no_narrow_place_of_its_own():
    """The other robot, standing mid-corridor and so marked on this one's map (a mate that
    stands is), leaves 36 in on either side: room for this one to pass it, not a place for
    the two to take in turn (``crossroads4_one_out`` seed 1014: the robot marked was told
    to go, into the side of a robot that gives way to nobody)."""
    seen = corridor_map((288.0, 312.0, -9.0, 9.0))          # its body as marked, at (300, 0)
    standing = on_map(300, 0, 0, corridor_map(), speed=0.0)
    coming = on_map(500, 15, 180, seen)
    assert traffic.narrow(standing, coming) is None
    elsewhere = on_map(500, 15, 180, corridor_map((288.0, 312.0, -9.0, 9.0)))
    assert traffic.narrow(on_map(150, 0, 0, corridor_map(), speed=0.0), elsewhere) is not None


def test_a_robot_giving_way_at_a_narrow_place_waits_in_its_lane_short_of_the_others_way():
    rmap = corridor_map(BOXES)
    bend = Route.of([(150, -15), (330, -15), (360, 25), (440, 25), (470, -15), (800, -15)])
    east = traffic.Mate(bend, 50.0, 200, -15, 30.0, ROBOT, rmap)
    west = on_map(560, 25, 180, rmap)
    # east's route comes within a lane (22 in) of west's, at y = 25, on its way up to the
    # room by the boxes, 152.5 in on (its places 4 in apart: the first within, 156 in): its
    # front stops SLACK short of there
    assert traffic.room_beside(east, west) == 156 - 2 * 12 - traffic.SLACK
    # and never into the place: its route comes within the zone of west's narrow places
    # 124 in on (x = 324), where the two met it; of the two rooms, the less
    c = traffic.crossing(east, west)
    assert c is not None and c.narrow and c.enter[0] == 124
    room = traffic.room_before(east, east.point(c.enter[0]))
    assert room == 124 - 12 - traffic.SLACK
    assert waits(east, west) == [(0, 1)]
    assert limits(east, west)[0] == math.sqrt((40 * DT) ** 2 + 2 * 40 * room) - 40 * DT
    west_gone = on_map(100, 25, 180, rmap)                 # west passed it: its way is clear
    assert traffic.room_beside(east, west_gone) == math.inf


def test_two_robots_head_on_where_boxes_leave_room_for_one_pass_in_turn():
    """``narrow_pass`` seeds 1001 and 1007: both robots made for the room by the boxes,
    braked face to face and backed away in turn (one stuck after 54.50 s, both timed out).
    Now the robot with the boxes on its side waits in its lane and both arrive, alike alone
    and in a batch."""
    from test_sim_lockstep import assert_same_run

    world = load_world(DATA / "traffic" / "narrow_pass.yaml")
    planner, scene = FuzzyPlanner(None, world.behavior), prepare(world)
    together = run_lockstep(world, planner, [1001, 1007], randomise=True, scene=scene)
    assert [res.robot_outcomes for res in together] == [("success", "success")] * 2
    assert_same_run(simulate(world, planner, 1007, randomise=True, scene=scene), together[1])
