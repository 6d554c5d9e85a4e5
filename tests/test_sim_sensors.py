"""Ray casting against known geometry, walls from corridors and grids, seeded noise."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from mitos_cli.sim import geometry, sensors
from mitos_cli.sim.staticmap import corridor_rects, corridor_walls, grid_walls
from mitos_cli.sim.world import Corridor, Grid, Sensors


def walls_of(*corridors):
    return corridor_walls(corridor_rects(tuple(corridors)))


def test_rays_in_a_straight_corridor():
    walls = walls_of(Corridor(((0, 0), (400, 0)), 70))
    dirs = sensors.beam_directions(0.0, np.deg2rad([0, 90, 180, 270, 45]))
    r = geometry.ray_segments(np.array([100.0, 0.0]), dirs, walls, 1000.0)
    assert r[:4] == pytest.approx([335, 35, 135, 35])       # end walls 35 beyond the points
    assert r[4] == pytest.approx(35 * math.sqrt(2))
    assert geometry.ray_segments(np.zeros(2), dirs, walls, 20.0).max() == 20.0   # range cap


def test_an_l_corner_is_open_inside_and_closed_outside():
    walls = walls_of(Corridor(((0, 0), (200, 0), (200, 200)), 60))
    up = geometry.ray_segments(np.array([200.0, 0.0]), np.array([[0.0, 1.0]]), walls, 1e3)
    right = geometry.ray_segments(np.array([200.0, 0.0]), np.array([[1.0, 0.0]]), walls, 1e3)
    assert up[0] == pytest.approx(230) and right[0] == pytest.approx(30)
    assert not any(np.allclose(w, [170, 30, 200, 30]) for w in walls)   # no wall across


def test_a_crossroads_has_openings_both_ways():
    walls = walls_of(Corridor(((0, 0), (400, 0)), 60), Corridor(((200, -200), (200, 200)), 60))
    dirs = sensors.beam_directions(0.0, np.deg2rad([0, 90, 180, 270]))
    r = geometry.ray_segments(np.array([200.0, 0.0]), dirs, walls, 1e3)
    assert r == pytest.approx([230, 230, 230, 230])


def test_rays_hit_circles_and_rectangles():
    dirs = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
    r = geometry.ray_circles(np.zeros(2), dirs, np.array([[50.0, 0.0]]), np.array([10.0]), 99.)
    assert r == pytest.approx([40, 99, 99])
    sides = geometry.polygon_segments(geometry.rect_corners(0.0, 30.0, 0.0, 20.0, 10.0))
    r = geometry.ray_segments(np.zeros(2), dirs, sides, 99.0)
    assert r == pytest.approx([99, 25, 99])


def test_sensing_returns_map_and_true_ranges():
    walls = walls_of(Corridor(((0, 0), (400, 0)), 70))
    dirs = sensors.beam_directions(0.0, Sensors(count=4).angles)
    expected, true = sensors.cast(np.array([100.0, 0.0]), dirs, walls, np.zeros((0, 4)),
                                  np.array([[150.0, 0.0]]), np.array([5.0]), 150.0)
    assert expected == pytest.approx([150, 35, 135, 35]) and true == pytest.approx([45, 35, 135, 35])


def test_noise_is_seeded_and_keeps_no_echo_at_range():
    r = np.array([10.0, 50.0, 150.0])
    a = sensors.add_noise(r, 1.0, 150.0, np.random.default_rng(7))
    b = sensors.add_noise(r, 1.0, 150.0, np.random.default_rng(7))
    assert np.array_equal(a, b) and a[2] == 150.0 and not np.array_equal(a[:2], r[:2])


def test_grid_walls_are_cell_edges_merged_into_runs():
    occ = np.ones((5, 6), dtype=bool)
    occ[1:4, 1:5] = False                      # a free 4 x 3 room inside
    walls = grid_walls(Grid(occ, 10.0, (0.0, 0.0)))
    assert len(walls) == 4                     # one merged run per side
    r = geometry.ray_segments(np.array([25.0, 25.0]), np.array([[1.0, 0.0], [0.0, 1.0]]),
                              walls, 1e3)
    assert r == pytest.approx([25, 15])


def test_ring_and_fan_layouts():
    ring = Sensors(layout="ring", count=4).angles
    assert np.rad2deg(ring) == pytest.approx([0, 90, 180, 270])
    fan = Sensors(layout="fan", count=3, fov=180).angles
    assert np.rad2deg(fan) == pytest.approx([90, 0, -90])
    # a fan of 360 deg had its first and last beams on one line (+180 and -180)
    whole = Sensors(layout="fan", count=4, fov=360).angles
    assert np.rad2deg(whole) == pytest.approx([180, 90, 0, -90])


def test_box_to_segment_distance_matches_the_polygon_distance():
    rng = np.random.default_rng(3)
    segs = rng.uniform(-40, 40, (400, 4))
    box = geometry.polygon_segments(geometry.rect_corners(0.0, 0.0, 0.0, 24.0, 18.0))
    slow = geometry.segment_distance(box, segs).min(axis=0)
    inside = (np.abs(segs[:, 0]) < 12) & (np.abs(segs[:, 1]) < 9)
    slow = np.where(inside, 0.0, slow)                   # a segment starting inside touches
    fast = geometry.box_segment_distance(12.0, 9.0, segs)
    assert fast == pytest.approx(slow, abs=1e-9)


def _depth_by_directions(hl, hw, poly, n=36000):
    """Penetration depth by brute force: the least, over many directions u, of how far the
    polygon must move along u to clear the box (its support gap)."""
    u = np.stack([np.cos(t := np.linspace(0, 2 * np.pi, n, endpoint=False)), np.sin(t)], 1)
    box = hl * np.abs(u[:, 0]) + hw * np.abs(u[:, 1])               # the box's support
    return max(0.0, float((box - (poly @ u.T).min(axis=0)).min()))


def test_penetration_depth_is_the_shortest_separating_move():
    """Robots, rectangles and walls overlapping a footprint: minus the shortest move that
    separates them, as for circles (robot-robot contact read 0.00)."""
    rng = np.random.default_rng(5)
    hl, hw = 12.0, 9.0
    boxes = geometry.rect_corners(rng.uniform(-20, 20, 60), rng.uniform(-15, 15, 60),
                                  rng.uniform(-np.pi, np.pi, 60), rng.uniform(4, 30, 60),
                                  rng.uniform(4, 20, 60))
    segs = rng.uniform(-30, 30, (60, 2, 2))
    for polys in (boxes, segs):
        fast = geometry.box_polygon_depth(hl, hw, polys)
        slow = np.array([_depth_by_directions(hl, hw, q) for q in polys])
        assert fast == pytest.approx(slow, abs=1e-2) and (fast <= slow + 1e-9).all()
        assert (fast > 0).sum() > 20                        # most of them overlap
    # head-on: a footprint 2 in into this one; one held whole; one 3 in away; one touching
    cases = geometry.rect_corners(np.array([22.0, 1.0, 27.0, 24.0]), 0.0, np.pi,
                                  np.array([24.0, 6.0, 24.0, 24.0]), 18.0)
    assert geometry.box_polygon_distance(hl, hw, cases) == pytest.approx([-2.0, -14.0, 3.0,
                                                                          0.0])
    assert geometry.box_polygon_depth(hl, hw, np.zeros((0, 4, 2))).shape == (0,)


def test_corridors_are_carved_into_a_grid():
    from mitos_cli.sim.staticmap import carve

    occ = np.ones((10, 20), dtype=bool)                   # solid 200 x 100 in
    g = carve(Grid(occ, 10.0, (0.0, 0.0)), corridor_rects((Corridor(((20, 50), (180, 50)), 28),)))
    free_rows = np.flatnonzero(~g.occupied.all(axis=1))
    assert free_rows.tolist() == [4, 5]                   # y from 36 to 64: centres 45 and 55
    assert np.flatnonzero(~g.occupied[4]).tolist() == list(range(1, 19))   # x from 6 to 194


def test_one_origin_and_the_same_origin_per_beam_hit_alike_bit_for_bit():
    rng = np.random.default_rng(3)
    for _ in range(50):
        o = rng.uniform(-100, 100, 2)
        a = rng.uniform(0, 2 * math.pi, 24)
        dirs = np.stack([np.cos(a), np.sin(a)], axis=1)
        seg = rng.uniform(-150, 150, (20, 4))
        seg[:5, 2] = seg[:5, 0]                           # some vertical sides
        one = geometry.ray_hits(o, dirs, seg)
        per_beam = geometry.ray_hits(np.tile(o, (24, 1)), dirs, seg)
        assert one.shape == (24, 20) and one.tobytes() == per_beam.tobytes()
        assert np.isfinite(one).any()


def test_a_rings_beams_go_round_to_the_left_as_the_csv_columns_say():
    """worlds/README said `range_<b>` runs "from 0 = leftmost, clockwise": true of a fan, but
    a ring's beam 0 looks straight ahead and the next ones round to the left. A robot 10 in
    right of a 70 in corridor's centre, heading +x: beam 9 reads the left wall, 27 the right."""
    from pathlib import Path

    walls = walls_of(Corridor(((0, 0), (400, 0)), 70))
    ring, fan = Sensors("ring", 36), Sensors("fan", 3, fov=180)
    ranges = sensors.ray_segments(np.array([100.0, -10.0]),
                                  sensors.beam_directions(0.0, ring.angles), walls, 150.0)
    assert ranges[9] == pytest.approx(45) and ranges[27] == pytest.approx(25)
    assert ranges[0] == 150 and ranges[18] == pytest.approx(135)
    assert np.rad2deg(fan.angles).tolist() == [90, 0, -90]        # left, ahead, right
    readme = (Path(__file__).parent.parent / "worlds" / "README.md").read_text(encoding="utf-8")
    assert "9\nleft, 18 behind, 27 right" in readme or "9 left, 18 behind, 27 right" in readme


def test_a_beam_measures_along_its_axis_not_its_cone():
    """worlds/README.md: a reading is the first thing on the beam's axis, not the nearest in
    its cone; a pole between two beams' axes (10 deg apart) is seen by neither."""
    dirs = sensors.beam_directions(0.0, np.deg2rad([0.0, 10.0]))
    pole = np.array([[50 * math.cos(math.radians(5)), 50 * math.sin(math.radians(5))]])
    _, seen = sensors.cast(np.zeros(2), dirs, np.zeros((0, 4)), np.zeros((0, 4)), pole,
                           np.array([1.0]), 150.0)
    assert seen.tolist() == [150.0, 150.0]
    readme = (Path(__file__).resolve().parents[1] / "worlds" / "README.md").read_text()
    assert "Each beam measures along its axis" in readme
