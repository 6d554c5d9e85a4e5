"""Perception: the paper's inputs from geometry (true values) and from the beams."""

from __future__ import annotations

import numpy as np
import pytest

from mitos_cli.sim import perception
from mitos_cli.sim.perception import NO_OBSTACLE
from mitos_cli.sim.route import Route
from mitos_cli.sim.world import Robot

ROUTE = Route.of([(0.0, 0.0), (600.0, 0.0)])
ROBOT = Robot(length=24, width=18)


def truth_at(x, y, outline):
    f = perception.frame(ROUTE, np.array([x, y]), x)
    return perception.truth(ROUTE, f, (x, y, 0.0), ROBOT, (70.0, 26.0 + y, 26.0 - y),
                            np.asarray(outline, float).reshape(-1, 2))


def circle(cx, cy, r, n=32):
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.stack([cx + r * np.cos(a), cy + r * np.sin(a)], axis=1)


def test_nothing_ahead_means_size_zero_and_no_obstacle():
    t = truth_at(100, 0, np.zeros((0, 2)))
    assert t["size"] == 0 and t["position"] == 0 and t["obstacle"] == NO_OBSTACLE
    assert t["road"] == 70 and t["heading"] == pytest.approx(0.0)


def test_an_obstacle_right_of_centre():
    t = truth_at(100, 0, circle(200, -10, 9))          # -y is the robot's right
    assert t["size"] == pytest.approx(18, abs=0.2)
    assert t["position"] == pytest.approx(10, abs=0.1)
    assert t["obstacle"] == pytest.approx(200 - 9 - 100 - 12, abs=0.2)


def test_an_object_outside_the_swept_band_does_not_obstruct():
    t = truth_at(100, 0, circle(200, 40, 5))
    assert t["obstacle"] == NO_OBSTACLE


def test_lane_and_heading_for_keep_right():
    t = truth_at(100, 5, np.zeros((0, 2)))             # 5 in left of the centre
    # keep-right lane: min(road / 4, road / 2 - width / 2 - 6) = 17.5 right of the centre
    assert t["lane"] == pytest.approx(-5 - 17.5)
    assert t["heading"] > 0                            # the route lies to the right


def test_beams_see_the_obstacle_that_the_map_does_not_predict():
    from mitos_cli.sim import sensors
    from mitos_cli.sim.staticmap import corridor_rects, corridor_walls
    from mitos_cli.sim.world import Corridor, Sensors

    walls = corridor_walls(corridor_rects((Corridor(((0, 0), (600, 0)), 70),)))
    sen = Sensors(count=72)
    dirs = sensors.beam_directions(0.0, sen.angles)
    p = np.array([100.0, 0.0])
    expected, true = sensors.cast(p, dirs, walls, np.zeros((0, 4)), np.array([[180.0, -10.0]]),
                                  np.array([9.0]), sen.range)
    f = perception.frame(ROUTE, p, 100.0)
    got = perception.perceive(ROUTE, f, (100.0, 0.0, 0.0), ROBOT, dirs, true, expected,
                              sen.range, 2 * np.pi / 72, 4.0)
    assert got["road"] == pytest.approx(70, abs=0.5)
    assert got["obstacle"] == pytest.approx(180 - 9 - 100 - 12, abs=2)
    assert 0 < got["position"] < 20 and 10 < got["size"] < 30       # right of centre, ~18


def corridor_reading(p, heading, route, count=36):
    """What a noise-free ring of ``count`` beams reads at ``p`` in the 70 in corridor."""
    from mitos_cli.sim import sensors
    from mitos_cli.sim.staticmap import corridor_rects, corridor_walls
    from mitos_cli.sim.world import Corridor, Sensors

    walls = corridor_walls(corridor_rects((Corridor(((0, 0), (600, 0)), 70),)))
    sen = Sensors(count=count)
    dirs = sensors.beam_directions(heading, sen.angles)
    expected, true = sensors.cast(p, dirs, walls, np.zeros((0, 4)), np.zeros((0, 2)),
                                  np.zeros(0), sen.range)
    f = perception.frame(route, p, 0.0)
    return perception.perceive(route, f, (float(p[0]), float(p[1]), heading), ROBOT, dirs, true,
                               expected, sen.range, 2 * np.pi / count, 4.0)


@pytest.mark.parametrize("heading", [0.0, -0.3])
def test_side_gaps_and_road_do_not_lean_with_a_leg_across_the_corridor(heading):
    """The last leg to a goal off the corridor's middle runs 45 deg across it: the road and
    the side gaps are the walls' distances still (across the leg, `gap_right` read 1.8 in
    where the body was 14 in off the wall, and the road 54 in; the truth read 99)."""
    p = np.array([556.0, -12.0])
    across = Route.of([(0.0, 0.0), (560.0, 0.0), (570.0, -10.0)])
    got = corridor_reading(p, heading, across)
    straight = corridor_reading(p, heading, ROUTE)
    for key in ("road", "gap_left", "gap_right"):
        assert got[key] == straight[key]
    assert got["road"] == pytest.approx(70.0, abs=0.5)
    if heading == 0.0:                 # parallel to the walls: the gaps across the body
        assert got["gap_right"] == pytest.approx(35 - 12 - 9, abs=0.3)
        assert got["gap_left"] == pytest.approx(35 + 12 - 9, abs=0.3)
    else:                              # turned toward the right wall: its front end is nearer
        front = 35 - 12 - 12 * np.sin(0.3)
        assert got["gap_right"] == pytest.approx(front - 9, abs=0.5)


def test_a_pole_beside_the_body_is_its_gap_across_it_not_from_the_centre():
    cfg = perception.Settings()
    body = perception._bodies((ROBOT,), cfg)
    ah, bh = np.array([[10.0, 20.0, -30.0]]), np.array([[-13.0, 15.0, 30.0]])
    valid = np.ones((1, 3), dtype=bool)
    road, left, right = perception._sides(ah, bh, ah, bh, valid, valid, body, cfg, 150.0)
    assert left[0] == pytest.approx(13.0 - 9.0)                    # beside: across the body
    assert right[0] == pytest.approx(np.hypot(20 - 12, 15) - 9)    # past the front: its end
    assert road[0] == pytest.approx(np.hypot(10, 13) + np.hypot(20, 15))   # from the centre


def test_nearest_is_the_gap_from_the_body_to_the_nearest_echo_near_its_band():
    cfg = perception.Settings()
    # a jamb 4 in beside the body's side and 3 in ahead of its front corner: the corner gap
    assert perception.nearest(np.array([12.0 + 3.0]), np.array([-(9.0 + 4.0)]), ROBOT,
                              cfg) == pytest.approx(5.0)
    # straight ahead: the distance from the front; behind the centre: nothing
    assert perception.nearest(np.array([40.0, -20.0]), np.array([0.0, 0.0]), ROBOT,
                              cfg) == pytest.approx(28.0)
    assert perception.nearest(np.array([-5.0]), np.array([10.0]), ROBOT, cfg) == cfg.nearest_cap
    # the walls of a corridor the robot drives down, 31 in beside it, do not count
    assert perception.nearest(np.array([20.0, 60.0]), np.array([-40.0, 40.0]), ROBOT,
                              cfg) == cfg.nearest_cap
    t = truth_at(100, 0, circle(150, -14, 4, n=360))   # a pole right of the way ahead
    assert t["nearest"] == pytest.approx(np.hypot(150 - 112, 14 - 9) - 4, abs=0.2)


def test_the_drive_behavior_slows_as_the_nearest_echo_comes_close():
    from mitos_cli.sim.planner import FuzzyPlanner

    planner = FuzzyPlanner(None, "drive")
    calm = dict(road=80, size=0, position=0, obstacle=200, heading=0, lane=0, goal=300,
                gap_left=30, gap_right=30, front=150, opening=0, clutter=0)
    in_clutter = dict(calm, clutter=5, front=100)
    for inputs in (calm, in_clutter):
        speeds = []
        for gap in (60.0, 10.0, 7.0, 4.0, 1.0):
            x = {k: np.array([v], float) for k, v in {**inputs, "nearest": gap}.items()}
            speeds.append(float(planner.plan(_percepts(x))[1][0]))
        assert speeds == sorted(speeds, reverse=True) and speeds[0] > speeds[-1] + 10
        assert speeds[-1] <= 10.0 + 1e-9                  # creeping when the body is that close


def _percepts(inputs):
    from mitos_cli.sim.planner import Percepts

    z = np.zeros((1, 2))
    return Percepts(inputs, np.zeros((1, 1)), np.zeros(1), np.zeros((1, 3)), np.zeros(1), z, z)


def test_the_lookahead_shortens_where_the_chord_to_the_route_would_cut_a_corner():
    cfg = perception.Settings()
    bend = Route.of([(0.0, 0.0), (30.0, 0.0), (30.0, -100.0)])           # a right turn ahead
    f = perception.frame(bend, np.array([0.0, 0.0]), 0.0)
    p = np.array([0.0, 0.0])
    assert perception.clear_lookahead(bend, f, p, np.zeros((0, 2)), 1.0, 12.0, cfg) == 40.0
    jamb = np.array([[24.0, -8.0]])                         # inside the bend
    ahead = perception.clear_lookahead(bend, f, p, jamb, 1.0, 6.0, cfg)
    assert cfg.lookahead_min <= ahead < cfg.lookahead
    q = perception.target_point(bend, f, cfg, ahead)        # the chord it kept stays clear
    t = np.clip(jamb[0] @ q / (q @ q), 0, 1)
    assert np.hypot(*(jamb[0] - t * q)) - 1.0 >= 6.0
    farther = perception.target_point(bend, f, cfg, ahead + cfg.lookahead_step)
    t = np.clip(jamb[0] @ farther / (farther @ farther), 0, 1)
    assert np.hypot(*(jamb[0] - t * farther)) - 1.0 < 6.0     # one step on, it cuts in


@pytest.mark.parametrize("bearing", [-80.0, -30.0, -5.0, 0.0, 12.0, 60.0])
def test_heading_is_the_bearing_at_the_usual_lookahead_and_as_sharp_as_a_nearer_point_needs(
        bearing):
    cfg = perception.Settings()
    route = Route.of([(0.0, 0.0), (600.0, 0.0)])
    f = perception.frame(route, np.array([0.0, 0.0]), 0.0)
    p = np.array([0.0, 0.0])
    assert perception.pursuit(route, f, p, bearing, cfg, cfg.lookahead) == pytest.approx(bearing)
    near = perception.pursuit(route, f, p, bearing, cfg, 10.0)   # a quarter as far: 4x the sine
    expect = np.degrees(np.arcsin(min(1.0, 4 * np.sin(np.radians(abs(bearing))))))
    assert near == pytest.approx(np.copysign(expect, bearing) if bearing else 0.0)
    assert abs(near) >= abs(bearing)
    assert perception.pursuit(route, f, p, 135.0, cfg, 10.0) == 135.0   # behind: as it is


def test_the_keep_right_lane_stays_within_the_routes_room():
    cfg = perception.Settings()
    route = Route.of([(0.0, 0.0), (600.0, 0.0)])
    p = np.array([100.0, 0.0])
    f = perception.frame(route, p, 100.0)
    assert perception.route_room(f, p, np.zeros((0, 2)), 1.0, 11.0) == np.inf
    room = perception.route_room(f, p, np.array([[100.0, -15.0]]), 1.0, 11.0)
    assert room == pytest.approx(3.0)                     # 15 less the cell and the least
    wide = perception._common(route, p, 0.0, f, 70.0, ROBOT, cfg, 40.0, np.inf)[1]
    tight = perception._common(route, p, 0.0, f, 70.0, ROBOT, cfg, 40.0, room)[1]
    assert wide == pytest.approx(-min(70 / 4, 35 - 9 - cfg.lane_margin))
    assert tight == pytest.approx(-3.0)                   # the lane only 3 in right of the route


def test_keep_clear_steers_off_one_side_but_not_between_two_jambs():
    from mitos_cli.sim.planner import FuzzyPlanner

    planner = FuzzyPlanner(None, "drive")
    door = dict(road=30, size=0, position=0, obstacle=200, heading=0, lane=0, goal=300,
                gap_left=30, gap_right=30, front=150, opening=0, clutter=0, nearest=60)

    def steering(**change):
        x = {k: np.array([v], float) for k, v in {**door, **change}.items()}
        return float(planner.plan(_percepts(x))[0][0])

    assert steering() == pytest.approx(90.0)
    assert steering(gap_left=2.0) > 100.0            # a wall close on the left: steer right
    assert steering(gap_left=2.0, gap_right=3.0) == pytest.approx(90.0)   # a door: straight on


@pytest.mark.parametrize("squeeze, off, obstructs", [
    (np.inf, 3.0, True),        # no squeeze: within half the width and the margin (11 in)
    (10.5, 3.0, True),          # a squeeze of 10.5 in: nearer than 10.5 - 4
    (10.5, 8.0, False),         # the squeeze's own walls
    (3.5, 1.0, True),           # a squeeze of 3.5 in still has a middle: half of it
    (3.5, 3.0, False),
])
def test_what_is_drawn_obstructs_in_a_squeeze_only_nearer_than_it_keeps(squeeze, off,
                                                                          obstructs):
    """One beam hits a point the map shows (a wall), 40 in ahead and ``off`` in left of the
    route: an obstacle to the rules only where it stands in the robot's way."""
    robot = Robot(length=24, width=18, safety_margin=2)
    dirs = np.array([[40.0, off]]) / np.hypot(40.0, off)
    reading = np.array([np.hypot(40.0, off)])
    f = perception.frame(ROUTE, np.array([100.0, 0.0]), 100.0)
    got = perception.perceive(ROUTE, f, (100.0, 0.0, 0.0), robot, dirs, reading, reading, 150.0,
                              0.1, 4.0, squeeze=squeeze)
    assert (got["obstacle"] < NO_OBSTACLE) == obstructs


def test_own_frames_of_all_rows_at_once_are_each_robots_own_bits():
    """Every row's points in its robot's frame, all rows in one product, are the bits of
    :func:`perception._own_frame` of that row alone: of all its points, and of its valid
    points alone (rows of none, one and several valid points, as a batch meets them)."""
    rng = np.random.default_rng(7)
    for beams in (1, 2, 5, 36):
        rel = rng.normal(size=(40, beams, 2)) * rng.choice([1e-3, 1.0, 150.0], size=(40, beams, 2))
        valid = rng.random((40, beams)) < rng.random((40, 1))
        valid[:3] = False
        valid[3:6] = np.eye(beams, dtype=bool)[rng.integers(0, beams, 3)]   # one point each
        headings = rng.uniform(-7.0, 7.0, 40).tolist()
        along, across, valid_along, valid_across = perception._own_frames(headings, rel, valid)
        for i, heading in enumerate(headings):
            want = perception._own_frame(rel[i], heading)
            assert along[i].tobytes() == want[0].tobytes()
            assert across[i].tobytes() == want[1].tobytes()
            mine = valid[i]
            alone = perception._own_frame(rel[i][mine], heading)
            assert valid_along[i, mine].tobytes() == alone[0].tobytes()
            assert valid_across[i, mine].tobytes() == alone[1].tobytes()
            assert not valid_along[i, ~mine].any() and not valid_across[i, ~mine].any()


def test_rings_of_all_rows_at_once_are_each_rows_own_test():
    """Whether each row's beams go all round, for all rows at once, is the row's own dot
    product test (rings, fans, beams off by a rounding error, noise)."""
    rng = np.random.default_rng(3)
    for beams in (1, 2, 3, 36):
        angles = np.concatenate([np.linspace(0, 2 * np.pi, beams, endpoint=False)[None]
                                 + rng.uniform(-4, 4, (30, 1)),
                                 np.linspace(-1.0, 1.0, beams)[None] + rng.uniform(-4, 4, (30, 1))])
        dirs = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
        dirs[::7] += rng.normal(scale=1e-9, size=dirs[::7].shape)
        want = [len(d) > 2 and float(d[0] @ d[-1]) >= float(d[0] @ d[1]) - 1e-9 for d in dirs]
        assert perception._rings(dirs).tolist() == want
        assert perception._rings(dirs[:1]).tolist() == want[:1]


def test_obstructions_of_all_rows_at_once_are_each_objects_own_bits():
    """Each row's obstructing object, its distance, middle and width across the road,
    measured for all rows at once (:func:`perception._objects`), are the bits of the plain
    formula of that object's points alone: the sum of its points over their count, where it
    stands on the route (:meth:`Route.project`), each point's offset ``(point - middle) @
    normal + e`` (objects of one point and of many, batches of one row and of many)."""
    rng = np.random.default_rng(11)
    cfg = perception.Settings()
    route = Route.of([(0.0, 0.0), (300.0, 40.0), (600.0, 0.0)])
    reach = cfg.sight + cfg.cluster
    for beams in (1, 2, 5, 36):
        n = 30
        p = np.stack([rng.uniform(0, 500, n), rng.uniform(-20, 20, n)], axis=1)
        points = p[:, None] + rng.normal(size=(n, beams, 2)) * rng.choice([2.0, 20.0, 60.0],
                                                                         size=(n, 1, 1))
        frames = [perception.frame(route, q, float(q[0])) for q in p]
        a = np.array([(pts - q) @ f.t for pts, q, f in zip(points, p, frames)])
        blocking = rng.random((n, beams)) < 0.5
        blocking[np.arange(n), rng.integers(0, beams, n)] = True            # one at least
        ahead = blocking | (rng.random((n, beams)) < 0.8)
        widen = rng.uniform(0.0, 5.0, (n, beams))
        length = np.full(n, 12.0)
        args = (a, points, ahead, blocking, widen, length)
        together = perception._objects([route] * n, frames, *args, cfg)
        for i in range(n):
            k = np.where(blocking[i], a[i], np.inf).argmin()
            gap = points[i] - points[i, k]
            near = ahead[i] & (np.hypot(gap[:, 0], gap[:, 1]) <= cfg.cluster)
            pts = points[i][near]
            middle = np.add.reduce(pts, axis=0) / len(pts)
            _, e, t = route.project(middle, frames[i].s, back=0.0, ahead=reach)
            across = (pts - middle) @ np.array([t[1], -t[0]]) + e
            lo = np.minimum.reduce(across - widen[i][near])
            hi = np.maximum.reduce(across + widen[i][near])
            distance = np.minimum.reduce(a[i][near]) - 12.0
            want = (distance if distance > 0.0 else 0.0, hi - lo, (lo + hi) / 2)
            alone = perception._objects([route], [frames[i]], *(x[i:i + 1] for x in args), cfg)
            for got, j in ((together, i), (alone, 0)):
                assert np.array([x[j] for x in got]).tobytes() == np.array(want).tobytes()
