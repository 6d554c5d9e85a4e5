"""The simulator's faster paths give the bits of the plain ones they replace: each test holds a
fast path against the straightforward code it stands for (written out here) or against itself
on one row, on random inputs."""

from __future__ import annotations

import dataclasses
import math

import hypothesis
import numpy as np
import pytest
from hypothesis import strategies as st

from mitos_cli.resources import packaged_path
from mitos_cli.sim import (
    distance,
    geometry,
    knowledge,
    loop,
    movers,
    perception,
    route,
    rows,
    safety,
)
from mitos_cli.sim.loop import Simulation, prepare
from mitos_cli.sim.planner import FuzzyPlanner
from mitos_cli.sim.world import Grid, Robot
from mitos_cli.sim.worldfile import load_world


def same(a, b) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and a.tobytes() == b.tobytes()


def test_the_clip_ufunc_is_np_clip_signed_zeros_and_nan_included():
    values = [math.nan, -math.inf, math.inf, 0.0, -0.0, 1.0, -1.0, 90.0, 5e-324]
    for x in values:
        for lo in values:
            for hi in values:
                assert same(geometry.clip_arrays(np.array([x]), lo, hi)[0], np.clip(x, lo, hi))


def test_ray_circles_sums_as_einsum_did():
    rng = np.random.default_rng(1)
    for _ in range(200):
        origin = rng.uniform(-300, 300, 2)
        centres = origin + rng.uniform(-160, 160, (int(rng.integers(1, 5)), 2))
        if rng.random() < 0.2:
            centres[0] = origin                          # a beam from a circle's centre
        radii = rng.uniform(0, 20, len(centres))
        a = rng.uniform(0, 2 * np.pi) + np.deg2rad(np.arange(0, 360, 10))
        if rng.random() < 0.2:
            a = np.deg2rad(np.arange(0, 360, 90))        # beams along the axes: zero products
        dirs = np.stack([np.cos(a), np.sin(a)], axis=1)
        m = np.broadcast_to(origin, (len(dirs), 2))[:, None, :] - centres[None]
        b = np.einsum("bck,bk->bc", m, dirs)
        c = np.einsum("bck,bck->bc", m, m) - radii[None] ** 2
        disc = b * b - c
        t = np.where(c <= 0.0, 0.0, -b - np.sqrt(np.maximum(disc, 0.0)))
        want = np.minimum(np.where((disc >= 0.0) & (t >= 0.0), t, np.inf).min(axis=1), 150.0)
        assert same(geometry.ray_circles(origin, dirs, centres, radii, 150.0), want)


def point_segment_distance_axis_by_axis(p, seg):
    """:func:`.geometry.point_segment_distance` as it was written: x and y apart."""
    ax, ay = seg[:, 0], seg[:, 1]
    ex, ey = seg[:, 2] - ax, seg[:, 3] - ay
    dx, dy = p[:, 0, None] - ax, p[:, 1, None] - ay
    t = np.clip((dx * ex + dy * ey) / np.maximum(ex * ex + ey * ey, geometry.EPS), 0.0, 1.0)
    return np.hypot(dx - t * ex, dy - t * ey)


def box_segment_distance_axis_by_axis(hl, hw, seg):
    """:func:`.geometry.box_segment_distance` as it was written: each end's distance on its
    own, and the segments that may cross the box found by their own nearest point to its
    centre."""
    x0, y0, x1, y1 = seg[:, 0], seg[:, 1], seg[:, 2], seg[:, 3]
    e0 = np.hypot(np.maximum(np.abs(x0) - hl, 0.0), np.maximum(np.abs(y0) - hw, 0.0))
    e1 = np.hypot(np.maximum(np.abs(x1) - hl, 0.0), np.maximum(np.abs(y1) - hw, 0.0))
    corners = np.array([[-hl, -hw], [hl, -hw], [hl, hw], [-hl, hw]])
    d = np.minimum(np.minimum(e0, e1),
                   point_segment_distance_axis_by_axis(corners, seg).min(axis=0))
    dx, dy = x1 - x0, y1 - y0
    t = np.clip(-(x0 * dx + y0 * dy) / np.maximum(dx * dx + dy * dy, geometry.EPS), 0.0, 1.0)
    maybe = np.hypot(x0 + t * dx, y0 + t * dy) <= math.hypot(hl, hw)
    out = d.copy()
    out[maybe] = geometry._box_crossing(hl, hw, seg[maybe], d[maybe])
    return out


def test_distances_to_segments_worked_on_both_axes_at_once_are_those_axis_by_axis():
    rng = np.random.default_rng(13)
    for k in range(3000):
        seg = rng.normal(0, 30, (int(rng.integers(1, 8)), 4))
        if k % 3 == 0:
            seg = np.round(seg)                          # ends on the box's sides and corners
        if k % 5 == 0:
            seg[0, 2:] = seg[0, :2]                      # a segment of no length
        if k % 7 == 0:
            seg[:, 1] = seg[:, 3] = 0.0                  # along the box's axis, through it
        if k % 11 == 0:
            seg[0] = (-0.0, 0.0, 0.0, -0.0)              # a point at the centre, signed zeros
        hl, hw = (0.0, 0.0) if k % 17 == 0 else tuple(rng.uniform(0, 20, 2))
        points = rng.normal(0, 30, (int(rng.integers(1, 6)), 2))
        assert same(geometry.point_segment_distance(points, seg),
                    point_segment_distance_axis_by_axis(points, seg))
        assert same(geometry.box_segment_distance(hl, hw, seg),
                    box_segment_distance_axis_by_axis(hl, hw, seg))


def test_points_at_is_point_at_for_every_arc_length():
    rng = np.random.default_rng(2)
    for k in range(300):
        pts = np.cumsum(rng.normal(0, 30, (int(rng.integers(2, 8)), 2)), axis=0)
        r = route.Route.of(pts)
        if k % 7 == 0:                                   # a zero-length segment kept as given
            r = route.Route(np.vstack([r.points[:1], r.points]), np.concatenate([[0.0], r.cum]),
                            r.goal)
        s = np.concatenate([rng.uniform(-20, r.length + 20, 12), [0.0, -0.0, r.length, r.cum[1]]])
        assert same(r.points_at(s), [r.point_at(float(u)) for u in s])
        j = int(rng.integers(0, len(r.cum) - 1))   # on one segment or more, ends included
        for s in (rng.uniform(r.cum[j], r.cum[j + 1], 9), r.cum[j:j + 2], [-0.0, r.cum[1]],
                  rng.uniform(0.0, r.length, 9), r.cum, rng.uniform(0, 20) + np.arange(0, 97, 12.0),
                  [r.cum[-2], r.length], [r.length], [np.nan], np.zeros(0)):
            s = np.asarray(s, float)
            assert same(r.points_at(s), np.reshape([r.point_at(float(u)) for u in s], (-1, 2)))


def test_points_along_many_routes_at_once_are_each_routes_own():
    rng = np.random.default_rng(15)
    for k in range(60):
        shared = []
        for j in range(int(rng.integers(1, 6))):
            r = route.Route.of(np.cumsum(rng.normal(0, 30, (int(rng.integers(2, 30)), 2)), axis=0))
            if (k + j) % 5 == 0:                          # a zero-length segment kept as given
                r = route.Route(np.vstack([r.points[:1], r.points]),
                                np.concatenate([[0.0], r.cum]), r.goal)
            shared.append(r)
        routes = [shared[int(i)] for i in rng.integers(0, len(shared), int(rng.integers(1, 12)))]
        s = np.array([rng.uniform(-20, r.length + 20) + np.arange(0.0, 36.0, 4.0) for r in routes])
        s[rng.random(s.shape) < 0.1] = 0.0
        for i, r in enumerate(routes):                    # ends, knots, -0.0, inf and NaN
            s[i, int(rng.integers(0, s.shape[1]))] = rng.choice(
                [-0.0, r.length, r.cum[int(rng.integers(0, len(r.cum)))], -np.inf, np.inf,
                 np.nan if rng.random() < 0.2 else 1.0])
        got = route.points_along(routes, s)
        for i, r in enumerate(routes):
            assert same(got[i], r.points_at(s[i]))


def test_a_routes_own_clearance_along_every_segment_at_once():
    rng = np.random.default_rng(3)
    occupied = rng.random((40, 50)) < 0.05
    field = route.Clearance.of(occupied, 2.0, (-10.0, -5.0), cap=30.0)
    for _ in range(50):
        pts = rng.uniform(-20, 100, (int(rng.integers(2, 9)), 2))
        want = [field.along(p, q) for p, q in zip(pts[:-1], pts[1:])]
        assert same(field.along_path(pts), want)


def accounted_cell_by_cell(rmap: knowledge.RobotMap, points: np.ndarray, reach: int = 2):
    """RobotMap.accounted as it was written: the (2 reach + 1)^2 neighbours looked up one
    offset at a time."""
    row, col, _ = rmap.cells(points)
    cells = rmap.grid.occupied if rmap.planned is None else rmap.planned
    rows_, cols_ = cells.shape
    out = np.zeros(len(points), dtype=bool)
    for dr in range(-reach, reach + 1):
        for dc in range(-reach, reach + 1):
            r, c = row + dr, col + dc
            inside = (r >= 0) & (r < rows_) & (c >= 0) & (c < cols_)
            out[inside] |= cells[r[inside], c[inside]]
    return out


def cells_column_by_column(rmap: knowledge.RobotMap, points: np.ndarray):
    """RobotMap.cells as it was written: each coordinate apart, four comparisons."""
    g = rmap.grid
    col = np.floor((points[:, 0] - g.origin[0]) / g.resolution).astype(np.int64)
    row = np.floor((points[:, 1] - g.origin[1]) / g.resolution).astype(np.int64)
    rows_, cols_ = rmap.occupied.shape
    return row, col, (row >= 0) & (row < rows_) & (col >= 0) & (col < cols_)


def test_cells_found_for_both_coordinates_at_once_are_those_of_each_apart():
    rng = np.random.default_rng(13)
    rmap = knowledge.RobotMap.of(Grid(rng.random((30, 40)) < 0.03, 2.0, (-7.0, 3.0)))
    edges = np.array([[-7.0, 3.0], [73.0, 63.0], [72.999, 62.999], [-7.0 - 1e-12, 3.0],
                      [-1e15, 1e15], [0.0, -0.0]])
    for k in range(60):
        pts = rng.uniform([-30, -30], [110, 90], (int(rng.integers(0, 40)), 2))
        if k % 3 == 0:                                     # all inside, or a few edges
            pts = rng.uniform([-7, 3], [73, 63], (20, 2)) if k % 2 else edges
        got, want = rmap.cells(pts), cells_column_by_column(rmap, pts)
        assert all(np.array_equal(a, b) for a, b in zip(got, want))


def test_accounted_looks_up_a_dilation_with_the_same_answer():
    rng = np.random.default_rng(4)
    grid = Grid(rng.random((30, 40)) < 0.03, 2.0, (-7.0, 3.0))
    rmap = knowledge.RobotMap.of(grid)
    for k in range(40):
        if k == 20:
            rmap.planned = rng.random((30, 40)) < 0.05
        pts = rng.uniform([-20, -10], [100, 80], (60, 2))
        assert same(rmap.accounted(pts), accounted_cell_by_cell(rmap, pts))


def test_many_maps_marked_and_looked_up_at_once_are_each_maps_own():
    rng = np.random.default_rng(18)
    grid = Grid(rng.random((30, 40)) < 0.03, 2.0, (-7.0, 3.0))
    together = [knowledge.RobotMap.of(grid) for _ in range(7)]
    alone = [knowledge.RobotMap.of(grid) for _ in range(7)]
    kept = knowledge.Dilations()        # a lockstep batch's, kept from look-up to look-up
    flags: list[bool] = []
    for k in range(40):
        if k in (20, 30):               # some plan again: a dilation of their own
            for m, a in zip(together[k % 3::2], alone[k % 3::2]):
                m.planned, a.planned = m.occupied.copy(), a.occupied.copy()
        if k % 5 == 4:                  # marks seen through are freed, then marked again
            origins = rng.uniform([-5.0, 5.0], [70.0, 60.0], (len(together), 2))
            turn = rng.uniform(0, 2 * np.pi, (len(together), 1)) + np.linspace(0, 6, 24)
            dirs = np.stack([np.cos(turn), np.sin(turn)], axis=2)
            measured = rng.uniform(5.0, 60.0, (len(together), 24))
            knowledge.clear_all(together, origins, dirs, measured, 60.0)
            for a, o, d, r in zip(alone, origins, dirs, measured):
                a.clear(o, d, r, 60.0)
        # cells inside the grid, beyond its edges and outside its dilation too
        cells = rng.integers([-6, -6], [46, 36], (len(together), 25, 2))
        seen = rng.random((len(together), 25)) < 0.3
        marked = knowledge.mark_all(together, cells, seen)
        assert marked == [a.mark_cells(c[w]) for a, c, w in zip(alone, cells, seen)]
        flags += marked
        got = knowledge.accounted_all(together, cells)
        assert np.array_equal(knowledge.accounted_all(together, cells, kept=kept), got)
        for m, a, c, row in zip(together, alone, cells, got):
            assert np.array_equal(m.occupied, a.occupied) and np.array_equal(m.marks, a.marks)
            assert m.marks.dtype == a.marks.dtype and m._changes == a._changes
            assert len(m.fresh) == len(a.fresh)
            assert all(same(x, y) for x, y in zip(m.fresh, a.fresh))   # centres, in order
            assert np.array_equal(row, a.accounted_cells(c))
    assert any(flags) and not all(flags)
    for few in (together[1:], together[1:], together[:0:-1]):   # a run ends; others, turned
        cells = rng.integers([-6, -6], [46, 36], (len(few), 25, 2))
        want = [m.accounted_cells(c) for m, c in zip(few, cells)]
        assert np.array_equal(knowledge.accounted_all(few, cells, kept=kept), want)
    other = knowledge.RobotMap.of(Grid(rng.random((30, 40)) < 0.03, 2.0, (-7.0, 3.0)))
    for few in ([together[1], other], [other, together[1]]):     # alike grids, turned
        cells = rng.integers([-6, -6], [46, 36], (len(few), 25, 2))
        want = [m.accounted_cells(c) for m, c in zip(few, cells)]
        assert np.array_equal(knowledge.accounted_all(few, cells, kept=kept), want)


def clear_by_scanning(occupied: np.ndarray, given: np.ndarray, grid: Grid, origin, dirs,
                      measured, max_range: float) -> None:
    """RobotMap.clear as it was written: its window scanned for marked cells."""
    res, (ox, oy) = grid.resolution, grid.origin
    rows_, cols_ = occupied.shape
    c0 = min(max(int((origin[0] - max_range - ox) // res), 0), cols_)
    r0 = min(max(int((origin[1] - max_range - oy) // res), 0), rows_)
    c1 = min(max(int((origin[0] + max_range - ox) // res) + 1, 0), cols_)
    r1 = min(max(int((origin[1] + max_range - oy) // res) + 1, 0), rows_)
    window = (slice(r0, r1), slice(c0, c1))
    r, c = np.nonzero(occupied[window] & ~given[window])
    if not len(r):
        return
    rel = np.stack([ox + (c + c0 + 0.5) * res, oy + (r + r0 + 0.5) * res], axis=1) - origin
    along = rel @ dirs.T
    across = np.abs(rel[:, :1] * dirs[:, 1] - rel[:, 1:] * dirs[:, 0])
    through = ((along > 0) & (along < np.minimum(measured, max_range) - res)
               & (across < res / 2)).any(axis=1)
    occupied[r[through] + r0, c[through] + c0] = False


def test_a_maps_marks_kept_as_a_list_clear_as_a_scan_of_its_window_did():
    rng = np.random.default_rng(5)
    grid = Grid(rng.random((60, 80)) < 0.02, 2.0, (0.0, 0.0))
    rmap = knowledge.RobotMap.of(grid)
    reference = grid.occupied.copy()
    angles = np.deg2rad(np.arange(0, 360, 10))
    for _ in range(60):
        origin = rng.uniform([10, 10], [150, 110])
        dirs = np.stack([np.cos(angles), np.sin(angles)], axis=1)
        measured = rng.uniform(0, 60, len(dirs))
        hits = origin + measured[:, None] * dirs
        seen = rng.random(len(dirs)) < 0.5
        rmap.mark(hits[seen], dirs[seen])
        row, col, inside = rmap.cells(hits[seen] + dirs[seen] * 1.0)
        reference[row[inside], col[inside]] = True
        clear_by_scanning(reference, grid.occupied, grid, origin, dirs, measured, 40.0)
        rmap.clear(origin, dirs, measured, 40.0)
        assert np.array_equal(rmap.occupied, reference)
        assert np.array_equal(np.flatnonzero(reference & ~grid.occupied), rmap.marks)


def free_travel_over_every_cell(cells, radius, pose, robot, delta, backward, reach, step=1.0):
    """safety.free_travel as it is written, but every cell tested at every place, and
    between every two places where it might be touched (backing, a cell touched at the start
    blocks only the places that take it deeper in)."""
    x, y, h = pose
    if not len(cells):
        return reach
    wb, hl, hw = robot.wheelbase, robot.length / 2, robot.width / 2
    k = -math.tan(math.radians(delta)) / wb
    far = wb / 2 + math.hypot(hl, hw) + 2 * math.sqrt(2) * radius + step
    du = step / (1.0 + abs(k) * far)
    u = np.arange(math.ceil(reach / du - 1e-9) + 1) * (-du if backward else du)

    def depth_at(u):                      # [P, ...] each cell the square it is: four axes
        hk = h + k * u
        c, s = np.cos(hk), np.sin(hk)
        if abs(k) > 1e-9:
            rx = x - wb / 2 * math.cos(h) + (s - math.sin(h)) / k
            ry = y - wb / 2 * math.sin(h) + (math.cos(h) - c) / k
        else:
            rx = x - wb / 2 * math.cos(h) + u * math.cos(h)
            ry = y - wb / 2 * math.sin(h) + u * math.sin(h)
        dx = cells[:, 0].reshape((-1,) + (1,) * u.ndim) - (rx + wb / 2 * c)
        dy = cells[:, 1].reshape((-1,) + (1,) * u.ndim) - (ry + wb / 2 * s)
        ac, as_ = np.abs(c), np.abs(s)
        e = radius * (ac + as_)
        return np.minimum(np.minimum(hl + e - np.abs(dx * c + dy * s),
                                     hw + e - np.abs(dy * c - dx * s)),
                          np.minimum(radius + hl * ac + hw * as_ - np.abs(dx),
                                     radius + hl * as_ + hw * ac - np.abs(dy)))

    depth = depth_at(u)                                               # [P, K]
    inside = depth >= 0
    if backward:
        inside = np.where(inside[:, :1], depth > depth[:, :1], inside)
    t = np.arange(1, safety.BETWEEN) / safety.BETWEEN
    between = depth_at(u[:-1, None] + (u[1:, None] - u[:-1, None]) * t)     # [P, K-1, B-1]
    touch = (between >= 0).any(axis=2)
    maybe = (depth[:, :-1] + depth[:, 1:] >= -step) & ~inside[:, :-1] & ~inside[:, 1:]
    inside[:, 1:] |= maybe & (depth[:, :1] < 0) & touch
    hit = inside.any(axis=0)
    if not hit.any():
        return reach
    return float(max(int(np.argmax(hit)) - 1, 0) * du)


def test_the_brakes_sweep_tests_only_the_cells_its_disc_sweeps_with_the_same_answer():
    rng = np.random.default_rng(6)
    robot = Robot()
    for _ in range(400):
        pose = (float(rng.uniform(-5, 5)), float(rng.uniform(-5, 5)), float(rng.uniform(-4, 4)))
        cells = rng.uniform(-70, 70, (int(rng.integers(0, 300)), 2))
        delta = float(rng.choice([0.0, rng.uniform(-60, 60)]))
        backward = bool(rng.random() < 0.3)
        assert same(safety.free_travel(cells, 1.0, pose, robot, delta, backward, 30.0),
                    free_travel_over_every_cell(cells, 1.0, pose, robot, delta, backward, 30.0))


def steps_clearance_sample_by_sample(field, xy, t) -> np.ndarray:
    """Every step's clearance as :func:`.route._edges_from` measured it, each sample's
    clearance (:meth:`.route.Clearance.cells`) and then their minimum."""
    R, C = xy.shape[:2]
    out = np.full((len(route.MOVES), R, C), -np.inf)
    for m, (dr, dc, _) in enumerate(route.MOVES):
        r0, r1, c0, c1 = max(-dr, 0), min(R - dr, R), max(-dc, 0), min(C - dc, C)
        a, b = xy[r0:r1, c0:c1], xy[r0 + dr:r1 + dr, c0 + dc:c1 + dc]
        pts = a[..., None, :] + t[:, None] * (b - a)[..., None, :]
        out[m, r0:r1, c0:c1] = field.cells(pts.reshape(-1, 2)).reshape(pts.shape[:-1]).min(
            axis=-1)
    return out


def test_steps_clearance_from_their_least_distance_is_the_least_of_their_samples():
    rng = np.random.default_rng(17)
    for k in range(40):
        grid = Grid(rng.random((int(rng.integers(5, 60)), int(rng.integers(5, 60)))) < 0.05,
                    float(rng.choice([1.0, 2.0, 0.7])), tuple(rng.uniform(-50, 50, 2)))
        field = route.Clearance.of(grid.occupied, grid.resolution, grid.origin,
                                   cap=float(rng.choice([6.0, 20.0, 1e3])))
        nodes = route._nodes(field.dist, int(rng.integers(1, 4)))
        xy = route._node_xy(grid, nodes)
        if k % 4 == 0:          # samples off the field (a field smaller than the nodes' grid)
            field = route.Clearance(field.squares[:-2, :-3], field.resolution, field.origin)
        t = route._samples(field, xy)
        got = route._no_steps(field, xy)            # kept as squares, read as inches
        route._edges_from(got, field, xy, t, route.MOVES, (0, xy.shape[0]), (0, xy.shape[1]))
        assert same(route.step_rooms(field, got), steps_clearance_sample_by_sample(field, xy, t))


def test_the_steps_clearance_of_a_block_of_nodes_is_that_block_of_the_whole():
    rng = np.random.default_rng(19)
    for k in range(40):
        grid = Grid(rng.random((int(rng.integers(5, 60)), int(rng.integers(5, 60)))) < 0.05,
                    float(rng.choice([1.0, 2.0, 0.7])), tuple(rng.uniform(-50, 50, 2)))
        field = route.Clearance.of(grid.occupied, grid.resolution, grid.origin, cap=20.0)
        xy = route._node_xy(grid, route._nodes(field.dist, int(rng.integers(1, 4))))
        if k % 4 == 0:          # samples off the field (a field smaller than the nodes' grid)
            field = route.Clearance(field.squares[:-2, :-3], field.resolution, field.origin)
        t = route._samples(field, xy)
        R, C = xy.shape[:2]
        r0, c0 = int(rng.integers(-1, R)), int(rng.integers(-1, C))
        r1, c1 = int(rng.integers(r0 + 1, R + 2)), int(rng.integers(c0 + 1, C + 2))
        kind = field.squares.dtype
        got = np.full((len(route.MOVES), R, C), 7, dtype=kind)   # what is not measured stays
        route._edges_from(got, field, xy, t, route.MOVES, (r0, r1), (c0, c1))
        want = steps_clearance_sample_by_sample(field, xy, t)
        inside = np.zeros((R, C), dtype=bool)
        inside[max(r0, 0):r1, max(c0, 0):c1] = True
        stays = ~inside[None] | np.isneginf(want)            # (steps off the grid too)
        assert (got[stays] == 7).all()
        assert same(route.step_rooms(field, got)[~stays], want[~stays])


def test_a_part_of_the_capped_distances_is_that_part_of_the_whole():
    rng = np.random.default_rng(18)
    for _ in range(100):
        cells = rng.random((int(rng.integers(1, 40)), int(rng.integers(1, 40)))) < 0.1
        cap = int(rng.integers(1, 12))
        r0, c0 = int(rng.integers(0, cells.shape[0])), int(rng.integers(0, cells.shape[1]))
        r1 = int(rng.integers(r0 + 1, cells.shape[0] + 1))
        c1 = int(rng.integers(c0 + 1, cells.shape[1] + 1))
        assert same(distance._capped(cells, cap, (r0, r1, c0, c1)),
                    distance._capped(cells, cap)[r0:r1, c0:c1])


def _capped_in_floats(blocked: np.ndarray, cap: int) -> np.ndarray:
    """The capped squared distances as they were worked out in float64 (before the integer
    ones): the reference the integer arithmetic must give bit for bit."""
    n = blocked.shape[0]
    idx = np.arange(n, dtype=float)[:, None]
    above = np.maximum.accumulate(np.where(blocked, idx, -np.inf), axis=0)
    below = np.minimum.accumulate(np.where(blocked, idx, np.inf)[::-1], axis=0)[::-1]
    g = np.minimum(np.minimum(idx - above, below - idx), cap + 1.0) ** 2
    padded = np.full((n, blocked.shape[1] + 2 * cap), (cap + 1.0) ** 2)
    padded[:, cap:cap + blocked.shape[1]] = g
    d = g.copy()
    for dc in range(1, cap + 1):
        np.minimum(d, padded[:, cap + dc:cap + dc + blocked.shape[1]] + dc * dc, out=d)
        np.minimum(d, padded[:, cap - dc:cap - dc + blocked.shape[1]] + dc * dc, out=d)
    return d


@hypothesis.settings(max_examples=60, deadline=None)
@hypothesis.given(st.integers(1, 50), st.integers(1, 50), st.floats(0.0, 0.3),
       st.sampled_from([1, 2, 7, 30, 180, 181, 400]), st.integers(0, 2**32 - 1))
def test_the_capped_distances_in_integers_are_the_float_ones(rows, cols, density, cap, seed):
    """Integers (uint16 up to a cap of 180, int64 past it) give the float64 bits."""
    cells = np.random.default_rng(seed).random((rows, cols)) < density
    got = distance._capped(cells, cap)
    assert got.dtype == np.float64 and same(got, _capped_in_floats(cells, cap))


@hypothesis.settings(max_examples=40, deadline=None)
@hypothesis.given(st.integers(1, 40), st.integers(1, 40), st.data())
def test_the_heuristic_read_from_one_quarter_is_math_dist_to_the_goal(R, C, data):
    """A*'s heuristic is read from the distances from one corner (a quarter of the table it
    was read from, a 4,000 x 4,000 map's 7 million `math.dist` calls cut to 1.8 million):
    every node's is `math.dist` to the goal itself, bit for bit."""
    from mitos_cli.sim.route import _heuristic

    goal = data.draw(st.integers(0, R * C - 1))
    want = [math.dist((r, c), divmod(goal, C)) for r in range(R) for c in range(C)]
    assert same(np.array(_heuristic(R, C, goal)), np.array(want))


@hypothesis.settings(max_examples=60, deadline=None)
@hypothesis.given(st.integers(0, 2**32 - 1), st.integers(1, 30))
def test_capped_squares_that_stop_shifting_early_are_every_shifts_minimum(seed, cap):
    """:func:`.distance._capped_squares` stops shifting once no shift can lower a square:
    the bits of the minimum over every shift up to the cap, beyond the cap too, whole or in
    part."""
    rng = np.random.default_rng(seed)
    rows, cols = (int(n) for n in rng.integers(1, 50, 2))
    blocked = rng.random((rows, cols)) < float(rng.choice([0.0, 0.01, 0.05, 0.3]))
    far = cap + 1
    g = np.minimum(distance._column_steps(blocked, far), far).astype(np.int64) ** 2
    padded = np.full((rows, cols + 2 * cap), far * far, dtype=np.int64)
    padded[:, cap:cap + cols] = g
    every = np.min([padded[:, cap + dc:cap + dc + cols] + dc * dc for dc in range(-cap, cap + 1)],
                   axis=0)
    r0, c0 = int(rng.integers(0, rows)), int(rng.integers(0, cols))
    r1, c1 = int(rng.integers(r0 + 1, rows + 1)), int(rng.integers(c0 + 1, cols + 1))
    assert np.array_equal(distance._capped_squares(blocked, cap), every)
    assert np.array_equal(distance._capped_squares(blocked, cap, (r0, r1, c0, c1)),
                          every[r0:r1, c0:c1])


@hypothesis.settings(max_examples=40, deadline=None)
@hypothesis.given(st.integers(0, 2**32 - 1), st.sampled_from([None, 3.0, 9.5, 400.0]))
def test_a_field_kept_as_squares_reads_the_distances_it_held(seed, cap):
    """The clearance field is kept as squared cells (2 bytes a cell, not 8) and read as
    distances where it is looked up: every read gives the bits the float64 field gave."""
    from mitos_cli.sim.distance import distance_transform

    rng = np.random.default_rng(seed)
    rows, cols = (int(n) for n in rng.integers(3, 40, 2))
    occ = rng.random((rows, cols)) < float(rng.uniform(0.0, 0.2))
    res, origin = float(rng.choice([0.5, 2.0, 1.9685])), (-3.0, 1.5)
    field = route.Clearance.of(occ, res, origin, cap=cap)
    dist = distance_transform(occ, res, cap)
    assert same(field.dist, dist)
    pts = rng.uniform(-6, max(rows, cols) * res + 6, (50, 2))
    col = np.floor((pts[:, 0] - origin[0]) / res).astype(np.int64)
    row = np.floor((pts[:, 1] - origin[1]) / res).astype(np.int64)
    inside = (row >= 0) & (row < rows) & (col >= 0) & (col < cols)
    want = np.zeros(len(pts))
    want[inside] = np.maximum(dist[row[inside], col[inside]] - res / 2, 0.0)
    assert same(field.cells(pts), want)
    centre = np.stack([origin[0] + (col + 0.5) * res, origin[1] + (row + 0.5) * res], axis=1)
    off = np.hypot(*(pts - centre)[inside].T)
    want[inside] = np.maximum(dist[row[inside], col[inside]] - off - res / 2, 0.0)
    assert same(field.at(pts), want)
    xy = route._node_xy(Grid(occ, res, origin), route._nodes(dist, 2))
    R, C = xy.shape[:2]
    src, dst = np.arange(R * C), np.roll(np.arange(R * C), 1)
    t = route._samples(field, xy)
    x = xy[..., 0].reshape(-1)[src] + t[:, None] * (xy[..., 0].reshape(-1)[dst]
                                                     - xy[..., 0].reshape(-1)[src])
    y = xy[..., 1].reshape(-1)[src] + t[:, None] * (xy[..., 1].reshape(-1)[dst]
                                                     - xy[..., 1].reshape(-1)[src])
    c = np.floor((x - origin[0]) / res).astype(np.int64)
    r = np.floor((y - origin[1]) / res).astype(np.int64)
    least = np.maximum(dist[r, c].min(axis=0) - res / 2, 0.0)
    assert same(route.step_rooms(field, route._least(field, xy, t, src, dst)), least)


def _widest_way_by_scalars(free_c, s, t, edge=None):
    """The widest way's search as it was written, NumPy scalar by scalar: the reference."""
    import heapq

    R, C = free_c.shape
    best = np.full(R * C, -1.0)
    start = s[0] * C + s[1]
    best[start] = free_c[s]
    heap = [(-best[start], start)]
    where = {start: start}
    steps = [(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]
    while heap:
        neg, node = heapq.heappop(heap)
        if -neg < best[node]:
            continue
        if node == t[0] * C + t[1]:
            return divmod(where[node], C), -neg
        r, c = divmod(node, C)
        for m, (dr, dc) in enumerate(steps):
            rr, cc = r + dr, c + dc
            if 0 <= rr < R and 0 <= cc < C:
                here = free_c[rr, cc] if edge is None else min(free_c[rr, cc], edge[m, r, c])
                width = min(-neg, here)
                nxt = rr * C + cc
                if width > best[nxt]:
                    best[nxt] = width
                    where[nxt] = where[node] if here >= -neg else nxt
                    heapq.heappush(heap, (-width, nxt))
    return None


@hypothesis.settings(max_examples=150, deadline=None)
@hypothesis.given(st.integers(0, 2**32 - 1))
def test_the_widest_way_read_from_flat_lists_is_the_scalar_searchs(seed):
    """The no-way search reads each step's room from a flat list (11 s of NumPy scalar
    look-ups on a 4,000 x 4,000 map): the same narrowest place and width, ties included."""
    rng = np.random.default_rng(seed)
    R, C = (int(n) for n in rng.integers(1, 20, 2))
    digits = int(rng.integers(0, 2))                   # whole numbers: many ties
    free = np.maximum(np.round(rng.uniform(-3, 10, (R, C)), digits), 0.0)
    edge = None
    if rng.random() < 0.7:
        edge = np.maximum(np.round(rng.uniform(-3, 10, (8, R, C)), digits), 0.0)
        edge[:, rng.random((R, C)) < 0.2] = -np.inf
    s = (int(rng.integers(0, R)), int(rng.integers(0, C)))
    t = (int(rng.integers(0, R)), int(rng.integers(0, C)))
    free[s] = free[t] = np.inf
    want, got = _widest_way_by_scalars(free, s, t, edge), route._widest_way(free, s, t, edge)
    assert (want is None) == (got is None)
    if want is not None:
        assert got[0] == want[0] and got[1] == want[1]


def test_the_prepared_search_patches_only_round_the_changed_cells():
    world = load_world(packaged_path("worlds", "slalom.yaml"))
    grid = prepare(world).plan_grid
    rng = np.random.default_rng(7)
    for k in range(8):
        occ = grid.occupied.copy()
        r = rng.integers(0, occ.shape[0], int(rng.integers(1, 20)))
        c = rng.integers(0, occ.shape[1], len(r))
        if k == 3:                                       # round node (0, 0) and (1, 1)
            r, c = r % 5, c % 5
        occ[r, c] = ~occ[r, c] if k % 2 else True
        patched = route._prepared(grid, occ, 50.0, 3)
        whole = route._prepared(grid, occ, 50.0, 3, keep=False)
        assert same(patched[0].dist, whole[0].dist)
        assert all(same(a, b) for a, b in zip(patched[1], whole[1]))
        assert same(patched[2], whole[2])


def test_a_robots_searches_patch_from_its_last_one_with_the_bits_of_the_whole():
    world = load_world(packaged_path("worlds", "slalom.yaml"))
    grid = prepare(world).plan_grid
    rng = np.random.default_rng(11)
    last = route.Prepared()
    occ = grid.occupied.copy()
    for k in range(10):              # marks added where the robot drives, some cleared again
        r = rng.integers(0, occ.shape[0], int(rng.integers(1, 30)))
        c = int(rng.integers(0, occ.shape[1] - 40)) + rng.integers(0, 40, len(r))
        if k == 4:                                       # round node (0, 0) and (1, 1)
            r, c = r % 5, c % 5
        occ[r, c] = ~occ[r, c] if k % 3 == 2 else True
        if k == 7:
            occ[:] = False                              # nothing known: no shortcut at all
        patched = route._prepared(grid, occ, 50.0, 3, last=last)
        whole = route._prepared(grid, occ, 50.0, 3, keep=False)
        assert same(patched[0].dist, whole[0].dist)
        assert all(same(a, b) for a, b in zip(patched[1], whole[1]))
        assert same(patched[2], whole[2])
        assert same(last.occ, occ) and last.occ is not occ


@hypothesis.settings(deadline=None, max_examples=60)
@hypothesis.given(st.integers(0, 2**32 - 1), st.integers(1, 4), st.integers(2, 9))
def test_steps_worked_out_again_only_near_the_changed_distances_are_those_of_the_whole(
        seed, k, reach):
    """Blocks of 1 to 4 cells, distances capped at 2 to 9 cells: a step that crosses the
    corner of a block beside its two nodes' blocks (a diagonal one) is worked out again too."""
    rng = np.random.default_rng(seed)
    rows, cols = (int(n) for n in rng.integers(12, 40, 2))
    grid = Grid(rng.random((rows, cols)) < 0.06, 2.0, (-3.0, 1.5))
    occ = grid.occupied.copy()
    r = rng.integers(0, rows, int(rng.integers(1, 6)))
    c = rng.integers(0, cols, len(r))
    occ[r, c] = ~occ[r, c]
    cap = 2.0 * reach - 0.5
    patched = route._prepared(grid, occ, cap, k)
    whole = route._prepared(grid, occ, cap, k, keep=False)
    assert same(patched[0].dist, whole[0].dist)
    assert all(same(a, b) for a, b in zip(patched[1], whole[1]))
    assert same(patched[2], whole[2])


@hypothesis.given(st.integers(0, 2**32 - 1))
@hypothesis.settings(max_examples=60, deadline=None)
def test_set_cells_are_numpys_nonzero(seed):
    """:func:`.route.set_cells` (a flat nonzero split into rows and columns) gives NumPy's
    2-D ``nonzero``: the same cells in the same order, of grids and of windows into them."""
    rng = np.random.default_rng(seed)
    grid = rng.random(tuple(int(n) for n in rng.integers(0, 40, 2))) < float(rng.random())
    r0, c0 = (int(rng.integers(0, n + 1)) for n in grid.shape)
    r1, c1 = int(rng.integers(r0, grid.shape[0] + 1)), int(rng.integers(c0, grid.shape[1] + 1))
    for mask in (grid, grid[r0:r1, c0:c1]):
        got, want = route.set_cells(mask), mask.nonzero()
        assert all(same(a, b) and a.dtype == b.dtype for a, b in zip(got, want))


@hypothesis.given(st.integers(0, 2**32 - 1))
@hypothesis.settings(max_examples=40, deadline=None)
def test_clearance_of_points_all_on_the_grid_is_the_masked_reads(seed):
    """:meth:`.route.Clearance.at` reads points all on the grid without masks: the bits of
    the masked reads it takes with one point off the grid."""
    rng = np.random.default_rng(seed)
    rows, cols = (int(n) for n in rng.integers(3, 30, 2))
    res = float(rng.choice([0.05, 0.5, 2.0, 3.0]))
    origin = tuple(rng.normal(0, 7, 2).tolist())
    field = route.Clearance.of(rng.random((rows, cols)) < 0.1, res, origin, cap=5 * res)
    inside = np.asarray(origin) + rng.uniform(0, 1, (50, 2)) * [cols * res, rows * res]
    inside = inside[field._cell_of(inside)[3]]           # (none on the far edge, rounded)
    off = np.vstack([inside, [[origin[0] - 1.0, origin[1] - 1.0]]])
    assert same(field.at(inside), field.at(off)[:-1])


def test_a_star_over_flat_tables_takes_the_generic_searchs_path():
    rng = np.random.default_rng(8)
    for _ in range(200):
        R, C = int(rng.integers(3, 25)), int(rng.integers(3, 25))
        blocked = rng.random((R, C)) < 0.25
        ok = rng.random((8, R, C)) < 0.8
        loose = rng.random((R, C)) < 0.1
        narrow = rng.random((8, R, C)) < 0.2
        penalty = rng.uniform(0, 5, (R, C))
        if rng.random() < 0.5:     # cheap nodes: a step onto one costs less than the heuristic
            penalty[rng.random((R, C)) < 0.5] = -0.9        # falls, so nodes are reopened
        s = (int(rng.integers(0, R)), int(rng.integers(0, C)))
        t = (int(rng.integers(0, R)), int(rng.integers(0, C)))
        blocked[s] = blocked[t] = False

        def neighbours(n: int):
            r, c = divmod(n, C)
            for m, (dr, dc, step) in enumerate(route.MOVES):
                rr, cc = r + dr, c + dc
                if 0 <= rr < R and 0 <= cc < C and not blocked[rr, cc] and (
                        ok[m, r, c] or loose[r, c] or loose[rr, cc]):
                    yield rr * C + cc, step * (1.0 + penalty[rr, cc]
                                               + (route.NARROW_COST if narrow[m, r, c] else 0.0))

        want = route._astar(neighbours, s[0] * C + s[1], t[0] * C + t[1],
                            lambda n: (n // C, n % C))
        costs = route._steps(list(route.MOVES), blocked, ok, loose, penalty, narrow)
        got = route._grid_astar(costs, [dr * C + dc for dr, dc, _ in route.MOVES], R, C,
                                s[0] * C + s[1], t[0] * C + t[1])
        assert got == want


def running(name: str, runs: int = 3, ticks: int = 120) -> list[Simulation]:
    """``runs`` randomised runs of a shipped world, stepped ``ticks`` times."""
    world = load_world(packaged_path("worlds", name))
    planner, scene = FuzzyPlanner(None, world.behavior), prepare(world)
    out = []
    for seed in range(1, runs + 1):
        sim = Simulation(world, planner, seed, randomise=True, scene=scene)
        for _ in range(ticks):
            if not sim.done:
                sim.step()
        out.append(sim)
    return [sim for sim in out if not sim.done]


@pytest.mark.parametrize("name", ["slalom.yaml", "office.yaml", "multirobot.yaml"])
def test_robots_sensed_together_get_the_bits_they_get_alone(name):
    sims = running(name)
    parts = [row for sim in sims for row in sim.sense_rows()]
    assert len(parts) > 1
    angles, max_range = sims[0].angles, sims[0].world.sensors.range
    parts[0] = dataclasses.replace(parts[0], noise=0.0)       # a row without noise among them

    def streams(k: int) -> list[rows.SenseRow]:               # each row's noise from seed k + i
        return [dataclasses.replace(row, rng=np.random.default_rng(k + i))
                for i, row in enumerate(parts)]

    together = rows.sense(streams(100), angles, max_range)
    for i, row in enumerate(streams(100)):
        alone = rows.sense([row], angles, max_range)
        for key in ("dirs", "static", "ranges", "clearance"):
            assert same(getattr(alone, key)[0], getattr(together, key)[i]), (i, key)


def box_rows(seed: int, n_rows: int = 3, n_boxes: int = 40) -> list[rows.SenseRow]:
    """Rows among ``n_boxes`` boxes, some rotated, some on a grid the beams run along (sides
    and corners exactly on a beam), some over a row's origin; each row its own walls."""
    rng = np.random.default_rng(seed)
    grid = rng.random() < 0.5
    if grid:                                        # axis-aligned, on whole inches
        cx, cy = rng.integers(-80, 80, (2, n_boxes)).astype(float)
        angle = np.zeros(n_boxes)
        size = rng.integers(2, 12, (2, n_boxes)).astype(float)
    else:
        cx, cy = rng.uniform(-160, 160, (2, n_boxes))
        angle = rng.uniform(-np.pi, np.pi, n_boxes)
        size = rng.uniform(0.5, 30, (2, n_boxes))
    boxes = geometry.rect_corners(cx, cy, angle, size[0], size[1])
    sides = geometry.polygon_segments(boxes)
    robot = Robot()
    out = []
    for _ in range(n_rows):
        walls = rng.uniform(-200, 200, (int(rng.integers(0, 6)), 4))
        x, y = (0.0, 0.0) if grid else rng.uniform(-100, 100, 2)
        out.append(rows.SenseRow(float(x), float(y), float(rng.choice([0.0, np.pi / 2])) if grid
                                 else float(rng.uniform(-np.pi, np.pi)), robot, walls,
                                 np.concatenate([walls, sides]), boxes, rows.discs(boxes),
                                 np.zeros((0, 2)), np.zeros(0), 0.0, rng))
    return out


@hypothesis.settings(max_examples=200, deadline=None)
@hypothesis.given(st.lists(st.integers(0, 6), min_size=1, max_size=9), st.integers(0, 3),
       st.sampled_from([(), (2,), (4,), (4, 2)]), st.integers(0, 2 ** 32 - 1))
def test_rows_stacked_are_each_row_padded_with_zeros(lengths, extra, tail, seed):
    rng = np.random.default_rng(seed)
    arrays = [rng.normal(size=(n, *tail)) for n in lengths]
    width = max(lengths) + extra
    got = rows._stacked(arrays, width)
    assert got.shape == (len(arrays), width, *tail)
    for row, a in zip(got, arrays):
        assert same(row[:len(a)], a) and not row[len(a):].any()
    alike = [rng.normal(size=(lengths[0], *tail)) for _ in lengths]     # width left out
    assert same(rows._stacked(alike), np.stack(alike))
    padded = rows._stacked(arrays)                                      # to the longest
    assert padded.shape == (len(arrays), max(lengths), *tail)
    assert same(padded, got[:, :max(lengths)])
    if extra and max(lengths):
        with pytest.raises(ValueError, match="does not fit"):
            rows._stacked(arrays + [np.zeros((width, *tail))], width - 1)


@hypothesis.settings(max_examples=200, deadline=None)
@hypothesis.given(st.integers(1, 40), st.sampled_from([(1,), (3,), (0, 2), (13, 1), (2, 3)]),
                  st.sampled_from(["float", "bool", "view", "column", "mixed"]),
                  st.integers(0, 2 ** 32 - 1))
def test_a_records_ticks_stacked_are_np_array_of_them(ticks, shape, kind, seed):
    """:func:`loop._stacked` of parts whose bytes lie together or apart (views, as columns of
    a batch's block), or of other types (a state a user moved a run to with whole numbers)
    is ``np.array(parts)``: shape, type and bits."""
    rng = np.random.default_rng(seed)
    if kind == "float":
        parts = [rng.normal(size=shape) for _ in range(ticks)]
    elif kind == "bool":
        parts = [rng.random(shape) < 0.5 for _ in range(ticks)]
    elif kind == "mixed":
        parts = [rng.integers(-9, 9, size=shape) if j % 2 else rng.normal(size=shape)
                 for j in range(ticks)]
    else:                                       # rows or columns of larger arrays
        big = rng.normal(size=(ticks, *shape, 3))
        parts = list(big[..., 0] if kind == "column" else big[..., :1].reshape(ticks, *shape))
    got, want = loop._stacked(parts), np.array(parts)
    assert got.shape == want.shape and got.dtype == want.dtype and same(got, want)


@pytest.mark.parametrize("seed", range(10))
@pytest.mark.parametrize("boxes", [6, 40])           # beams test every side, or culled
def test_rows_sensed_with_the_stacks_kept_get_the_bits_of_rows_stacked_afresh(seed, boxes):
    angles = np.deg2rad(np.arange(-180.0, 180.0, 10.0))
    parts = box_rows(seed, n_rows=4, n_boxes=boxes)
    kept: rows.Kept = {}
    rng = np.random.default_rng(seed)
    for tick in range(6):
        before = {name: stack for name, (_, stack) in kept.items()}
        if tick % 2:                         # some rows gather other walls, or move boxes
            i = int(rng.integers(len(parts)))
            walls = rng.uniform(-200, 200, (int(rng.integers(0, 8)), 4))
            sides = parts[i].segments[len(parts[i].walls):]
            parts[i] = dataclasses.replace(parts[i], walls=walls,
                                           segments=np.concatenate([walls, sides]))
        if tick == 4:
            j = int(rng.integers(len(parts)))
            boxes = parts[j].boxes + 1.5
            parts[j] = dataclasses.replace(parts[j], boxes=boxes, discs=rows.discs(boxes),
                                           segments=np.concatenate(
                                               [parts[j].walls, geometry.polygon_segments(boxes)]))
        fresh = rows.sense(parts, angles, 150.0)
        again = rows.sense(parts, angles, 150.0, kept)
        for key in ("dirs", "static", "ranges", "clearance"):
            assert same(getattr(fresh, key), getattr(again, key)), (tick, key)
        if tick == 2:                                   # nothing changed: nothing stacked again
            assert before and all(kept[name][1] is stack for name, stack in before.items())


@pytest.mark.parametrize("seed", range(40))
def test_beams_among_many_boxes_test_only_the_boxes_they_may_hit_with_the_same_bits(
        seed, monkeypatch):
    parts = box_rows(seed)
    angles = np.deg2rad(np.arange(-180.0, 180.0, 2.5))
    origin = np.array([(r.x, r.y) for r in parts])
    a = np.array([r.heading for r in parts])[:, None] + angles
    dirs = np.stack([np.cos(a), np.sin(a)], axis=-1)
    seen = 0
    for max_range in (150.0, 40.0):
        for chosen in ([0], [1], [0, 1, 2]):
            some = [parts[i] for i in chosen]
            culled = rows._cast(rows._Stacks(some), origin[chosen], dirs[chosen], max_range)
            monkeypatch.setattr(rows, "CULL_FROM", 10 ** 9)
            every = rows._cast(rows._Stacks(some), origin[chosen], dirs[chosen], max_range)
            monkeypatch.undo()
            assert rows.CULL_FROM <= 40
            assert same(culled[0], every[0]) and same(culled[1], every[1]), (max_range, chosen)
            seen += int((culled[1] < culled[0]).sum())
    assert seen > 0                                         # the boxes are in view


@pytest.mark.parametrize("name", ["slalom.yaml", "office.yaml", "detour.yaml"])
def test_robots_perceived_together_get_the_bits_they_get_alone(name):
    sims = running(name)
    parts = [sim.sights(sim.sense()) for sim in sims]
    cfg, max_range = sims[0].settings, sims[0].world.sensors.range
    together = perception.perceive_all(_joined(parts), max_range, cfg)
    rows = [(part, i) for part in parts for i in range(len(part.routes))]
    for j, (part, i) in enumerate(rows):
        alone = perception.perceive_all(_joined([part], slice(i, i + 1)), max_range, cfg)
        for key in perception.INPUTS:
            assert same(alone[key][0], together[key][j]), key


def _joined(parts: list[perception.Sights], rows: slice = slice(None)) -> perception.Sights:
    """The ``rows`` of ``parts``' rows one after the other."""
    def join(name: str):
        values = [getattr(part, name)[rows] for part in parts]
        return (sum(values, []) if isinstance(values[0], list)
                else np.concatenate(values))

    return perception.Sights(**{f.name: join(f.name) for f in dataclasses.fields(perception.Sights)})


@pytest.mark.parametrize("name", ["slalom.yaml", "office.yaml", "detour.yaml"])
def test_robots_aim_together_with_the_bits_they_get_alone(name):
    sims = running(name)
    aims = []
    for sim in sims:
        s = sim.sense()
        aims += sim.aims(s, perception.frames(*sim.framing(s)))   # (tracked first by itself)
    cfg = sims[0].settings
    rng = np.random.default_rng(3)
    # rows with no cells, with few and with many (padding of every width), in any order
    aims += [dataclasses.replace(a, cells=a.cells[:k]) for a in aims[:3] for k in (0, 1, 5)]
    aims = [aims[i] for i in rng.permutation(len(aims))]
    assert any(len(a.cells) > 20 for a in aims)
    ahead, targets = perception.pursuit_points(aims, cfg)
    for i, a in enumerate(aims):
        one, target = perception.pursuit_point(a.route, a.f, a.p, a.cells, a.radius, a.need, cfg)
        assert same(one, ahead[i]) and same(target, targets[i])


def test_a_maps_near_cells_read_from_the_last_square_are_the_cells_of_a_fresh_look():
    world = load_world(packaged_path("worlds", "slalom.yaml"))
    grid = prepare(world).plan_grid
    rng = np.random.default_rng(5)
    kept, fresh = knowledge.RobotMap.of(grid), knowledge.RobotMap.of(grid)
    for _ in range(40):
        p = np.array([rng.uniform(0, 900), rng.uniform(-40, 40)])
        if rng.random() < 0.3:                        # a mark between two looks
            hits = p + rng.normal(0, 30, (3, 2))
            dirs = np.tile([1.0, 0.0], (3, 1))
            kept.mark(hits, dirs)
            fresh.mark(hits, dirs)
        given = bool(rng.random() < 0.2)
        for reach in (60.0, float(rng.uniform(10, 60)), float(rng.uniform(10, 80))):
            fresh._last_near = None                   # always looked up afresh
            assert same(kept.near(p, reach, given), fresh.near(p, reach, given))


@pytest.mark.parametrize("one_gather", [1, knowledge.ONE_GATHER])     # all in one copy or not
def test_many_maps_near_cells_asked_at_once_are_each_maps_own(monkeypatch, one_gather):
    monkeypatch.setattr(knowledge, "ONE_GATHER", one_gather)
    rng = np.random.default_rng(16)
    for _ in range(60):
        rows, cols = (int(n) for n in rng.integers(1, 40, 2))
        res = float(rng.choice([0.5, 2.0, 3.0]))
        grid = Grid(rng.random((rows, cols)) < 0.2, res, tuple(rng.normal(0, 5, 2).tolist()))
        maps = [knowledge.RobotMap.of(grid) for _ in range(int(rng.integers(2, 20)))]
        if rng.random() < 0.3:             # alike, not one grid: each map's cells copied
            maps.append(knowledge.RobotMap.of(Grid(grid.occupied.copy(), res, grid.origin)))
        for m in maps:
            m.mark(rng.uniform(-10, cols * res + 10, (5, 2)), np.tile([1.0, 0.0], (5, 1)))
        # squares inside, across the edges and wholly outside the grid, of one cell or more
        points = rng.uniform(-30, max(rows, cols) * res + 30, (len(maps), 2))
        reaches = rng.choice([0.0, res / 3, float(rng.uniform(0, 40))], len(maps))
        for given in (False, True):
            got = knowledge.near_all(maps, points, reaches, given)
            for m, p, reach, cells in zip(maps, points, reaches, got):
                m._last_near = None                   # looked up afresh
                assert same(cells, m.near(p, float(reach), given))
    other = knowledge.RobotMap.of(Grid(np.ones((4, 4), bool), 3.0, (0.0, 0.0)))
    two = [maps[0], other]                                 # grids unlike: one by one
    got = knowledge.near_all(two, np.array([[1.0, 1.0]] * 2), np.array([5.0, 5.0]))
    assert all(same(cells, m.near(np.array([1.0, 1.0]), 5.0)) for m, cells in zip(two, got))


def test_many_maps_brake_cells_asked_at_once_are_each_maps_own():
    """The brake's cells of runs in lockstep (:func:`.knowledge.brake_cells_all`: the
    occupied cells, then the squares flush with the given walls) are each map's alone, with
    the faces shared by the runs of a world, and with a map of another world among them."""
    rng = np.random.default_rng(12)
    grid = Grid(np.pad(np.zeros((20, 60), bool), 1, constant_values=True), 2.0, (-2.0, -2.0))
    walls = np.array([[0.0, 0.0, 120.0, 0.0], [120.0, 39.3, 0.0, 39.3]])
    faces = knowledge.wall_faces(walls, grid)
    # only along the wall that runs through free cells (39.3 in the row of 38 to 40), not the
    # one along the cells' edge (y = 0)
    assert len(faces) and np.unique(faces[:, 1]).tolist() == [40.3]
    maps = [knowledge.RobotMap.of(grid, faces) for _ in range(6)]
    for m in maps:
        m.mark(rng.uniform(0, 120, (5, 2)), np.tile([1.0, 0.0], (5, 1)))
    for mixed in (False, True):
        group = maps + [knowledge.RobotMap.of(grid)] if mixed else maps
        points = rng.uniform(-10, 130, (len(group), 2))
        reaches = rng.choice([0.0, 3.0, float(rng.uniform(0, 40))], len(group))
        got = knowledge.brake_cells_all(group, points, reaches)
        for m, p, reach, cells in zip(group, points, reaches, got):
            m._last_near = None
            assert same(cells, m.brake_cells(p, float(reach)))


@pytest.mark.parametrize("rows", [7, 400])             # 400: rows worked in blocks
def test_distances_from_many_routes_at_once_are_each_routes_own(rows):
    rng = np.random.default_rng(9)
    routes = [route.Route.of(np.cumsum(rng.normal(0, 40, (int(rng.integers(2, 40)), 2)),
                                       axis=0)) for _ in range(rows)]
    s = [float(rng.uniform(-20, r.length + 20)) for r in routes]
    points = rng.normal(0, 150, (rows, 36, 2))
    got = route.distances(routes, s, 120.0, points)
    for i, r in enumerate(routes):
        assert same(got[i], r.distance(points[i], s[i], 120.0))


@pytest.mark.parametrize("maps, unlike", [(5, False), (120, False), (7, True)])
def test_maps_cleared_together_are_each_cleared_as_alone(maps, unlike):
    """120 maps: marks worked in blocks; ``unlike``: grids of two shapes, each map's marks in
    sight found alone."""
    rng = np.random.default_rng(8)
    angles = np.deg2rad(np.arange(0, 360, 10))
    grids = [Grid(rng.random((60 - 10 * (unlike and i % 2), 80)) < 0.02, 2.0, (0.0, 0.0))
             for i in range(maps)]
    together = [knowledge.RobotMap.of(g) for g in grids]
    alone = [knowledge.RobotMap.of(g) for g in grids]
    cleared = False
    for _ in range(40):
        origins = rng.uniform([10, 10], [150, 110], (maps, 2))
        dirs = np.tile(np.stack([np.cos(angles), np.sin(angles)], axis=1), (maps, 1, 1))
        measured = rng.uniform(0, 60, (maps, len(angles)))
        for i in range(maps):
            seen = rng.random(len(angles)) < (0.5 if i else 0.0)   # map 0 never marks
            hits = origins[i] + measured[i, seen, None] * dirs[i, seen]
            together[i].mark(hits, dirs[i, seen])
            alone[i].mark(hits, dirs[i, seen])
        knowledge.clear_all(together, origins, dirs, measured, 40.0)
        for i in range(maps):
            alone[i].clear(origins[i], dirs[i], measured[i], 40.0)
            assert np.array_equal(together[i].occupied, alone[i].occupied)
            assert np.array_equal(together[i].marks, alone[i].marks)
            assert together[i]._changes == alone[i]._changes
        cleared |= any(m._changes > 40 for m in together[1:])   # some marks were seen through
    assert cleared


def seen_through_every_product(rel, k, dx, dy, reach, half):
    """knowledge._seen_through as it was written: both products of every mark and beam."""
    dx, dy = dx[k], dy[k]
    rx, ry = rel[:, 0, None], rel[:, 1, None]
    along = rx * dx + ry * dy
    across = np.abs(rx * dy - ry * dx)
    return ((along > 0) & (along < reach[k]) & (across < half[k, None])).any(axis=1)


@hypothesis.given(st.integers(0, 2**32 - 1), st.integers(0, 40), st.integers(1, 5))
def test_marks_seen_through_from_the_beams_near_them_are_those_of_every_beam(seed, marks, robots):
    rng = np.random.default_rng(seed)
    angles = rng.uniform(0, 2 * np.pi, (robots, 12))
    dx, dy = np.cos(angles), np.sin(angles)
    # marks on the cells of a grid, some of them on a beam
    rel = rng.integers(-20, 21, (marks, 2)) * 2.0
    k = np.sort(rng.integers(0, robots, marks))
    on = rng.random(marks) < 0.3
    pick = rng.integers(0, 12, marks)
    dist = rng.integers(0, 20, marks) * 2.0
    half = rng.choice([1.0, 2.0], robots)
    # on the beam, or off it by about half a cell: a hair inside or outside, where single
    # precision rounds either way
    off = rng.choice([0.0, 1.0], marks) * half[k] * (1 + rng.choice([-1, 1], marks)
                                                      * rng.choice([0.0, 1e-15, 1e-9, 1e-7], marks))
    dxk, dyk = dx[k, pick], dy[k, pick]
    rel[on, 0] = (dist * dxk - off * dyk)[on]
    rel[on, 1] = (dist * dyk + off * dxk)[on]
    reach = rng.choice([0.0, 10.0, 38.0, 60.0], (robots, 12))
    assert np.array_equal(knowledge._seen_through(rel, k, dx, dy, reach, half),
                          seen_through_every_product(rel, k, dx, dy, reach, half))
    # directions longer than a unit; coordinates beyond single precision, or so small that
    # its rounding is no longer relative (subnormal); directions beyond it
    for grow, far in ((3.0, 1.0), (1.0, 1e35), (1.0, 1e-44), (1e39, 1e-10)):
        args = rel * far, k, dx * grow, dy * grow, reach * far * grow, half * far * grow
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            assert np.array_equal(knowledge._seen_through(*args),
                                  seen_through_every_product(*args))


def test_marks_in_sight_of_many_maps_at_once_are_each_maps_own():
    rng = np.random.default_rng(17)
    grid = Grid(rng.random((50, 70)) < 0.02, 2.0, (-3.0, 5.0))
    maps = [knowledge.RobotMap.of(grid) for _ in range(9)]
    none = some = False
    for _ in range(30):
        for m in maps[1:]:                                  # map 0 never marks
            hits = rng.uniform(-10, 150, (int(rng.integers(0, 6)), 2))
            m.mark(hits, np.tile([0.0, 1.0], (len(hits), 1)))
        origins = rng.uniform(-60, 200, (len(maps), 2))
        max_range = float(rng.uniform(0, 60))
        k, *got = knowledge._in_sight_all(maps, origins, max_range)
        assert np.array_equal(k, np.sort(k, kind="stable"))
        for j, (m, o) in enumerate(zip(maps, origins)):
            alone = m._in_sight(o, max_range)
            assert (alone is None) == (j not in k)
            assert alone is None or all(same(a[k == j], b) for a, b in zip(got, alone))
            none |= alone is None
            some |= alone is not None
    assert none and some


def test_brake_sweeps_measured_together_are_each_measured_as_alone():
    rng = np.random.default_rng(12)
    robots = [Robot(), Robot(length=30.0, width=20.0, wheelbase=20.0)]
    for trial in range(30):
        sweeps = []
        for _ in range(int(rng.integers(1, 12))):
            robot = robots[int(rng.integers(0, 2))]
            pose = (float(rng.uniform(-5, 5)), float(rng.uniform(-5, 5)),
                    float(rng.uniform(-4, 4)))
            cells = rng.uniform(-70, 70, (int(rng.choice([0, 3, 40, 300])), 2))
            wheel = float(rng.choice([robot.steering_straight, rng.uniform(30, 150)]))
            if trial % 3 == 0:             # every wheel turned (their places by one formula)
                wheel = float(rng.uniform(30, 150))
            reach = float(rng.choice([29.5, 30.0, 30.5, 50.0]))   # own reaches, one batch
            body = safety.Body(robot, pose, 90.0, cells, 1.0, 0.0, reach)
            sweeps.append((body, wheel, bool(rng.random() < 0.3)))
        got = safety.free_travels(sweeps)
        for j, (body, wheel, backward) in enumerate(sweeps):
            assert same(got[j], body.free(wheel, backward, safety.Settings()))


def assert_placed_as_alone(routes, points, hints) -> None:
    """Robots placed on their routes together (:func:`perception.frames`) get the bits
    each gets alone."""
    together = perception.frames(routes, points, hints)
    for r, p, hint, f in zip(routes, points, hints, together):
        alone = perception.frame(r, p, hint)
        assert same(alone.s, f.s) and same(alone.e, f.e)
        assert same(alone.t, f.t) and same(alone.n, f.n)


def test_robots_placed_on_their_routes_together_get_the_bits_they_get_alone():
    rng = np.random.default_rng(10)
    routes = [route.Route.of(np.cumsum(rng.normal(0, 40, (int(rng.integers(2, 30)), 2)),
                                       axis=0)) for _ in range(9)]
    points = rng.normal(0, 120, (9, 2))
    hints = [float(rng.uniform(-200, r.length + 200)) for r in routes]
    assert_placed_as_alone(routes, points, hints)


def window_by_searchsorted(r: route.Route, lo: float, hi: float) -> tuple[int, int]:
    return (int(np.searchsorted(r.cum[1:], lo, side="left")),
            int(np.searchsorted(r.cum[:-1], hi, side="right")))


def test_a_routes_window_found_by_bisection_is_the_one_searchsorted_finds():
    rng = np.random.default_rng(11)
    for _ in range(200):
        r = route.Route.of(np.cumsum(rng.normal(0, 40, (int(rng.integers(2, 12)), 2)), axis=0))
        ends = [*r.cum, -0.0, math.inf, -math.inf, math.nan, *rng.uniform(-50, r.length + 50, 6)]
        for lo in ends:
            for hi in ends[::3]:
                assert r._window(lo, hi) == window_by_searchsorted(r, lo, hi)


def test_windows_of_many_routes_at_once_are_each_routes_own():
    rng = np.random.default_rng(16)
    for _ in range(100):
        routes = [route.Route.of(np.cumsum(rng.normal(0, 40, (int(rng.integers(2, 12)), 2)),
                                           axis=0)) for _ in range(int(rng.integers(1, 9)))]
        ends = [[*r.cum, -0.0, math.inf, -math.inf, math.nan, *rng.uniform(-50, r.length + 50, 6)]
                for r in routes]
        lo = np.array([rng.choice(e) for e in ends])
        hi = np.array([rng.choice(e) for e in ends])
        table, base, size, cum = route._laid(routes)
        first, stop = route._windows(cum, size, lo, hi)
        assert [r._window(a, b) for r, a, b in zip(routes, lo, hi)] == list(zip(first, stop))
        again = route._laid(list(routes))                 # the same routes: what was laid
        assert all(a is b and not a.flags.writeable for a, b in zip(again, (table, base, size,
                                                                            cum)))
        other = route._laid(routes[::-1])
        assert other[0].tobytes() == np.concatenate([r._rows for r in routes[::-1]]).tobytes()


def project_on_arrays(r: route.Route, p, s_hint, back=24.0, ahead=120.0):
    """:meth:`.route.Route.project` as it was written on arrays for every window."""
    a, e = r.points[:-1], r.points[1:] - r.points[:-1]
    ee = np.maximum((e * e).sum(axis=1), 1e-12)
    root = np.sqrt(ee)
    first, stop = window_by_searchsorted(r, s_hint - back, s_hint + ahead)
    if first >= stop:
        first, stop = 0, 1
    a, e, ee, root = a[first:stop], e[first:stop], ee[first:stop], root[first:stop]
    t = geometry.clip_arrays(((p - a) * e).sum(axis=1) / ee, 0.0, 1.0)
    closest = a + t[:, None] * e
    i = int(np.hypot(*(p - closest).T).argmin())
    tangent = e[i] / math.sqrt(ee[i])
    rel = p - closest[i]
    return (float(r.cum[first + i] + t[i] * root[i]),
            float(rel[0] * tangent[1] - rel[1] * tangent[0]), tangent)


def test_a_projection_in_floats_is_the_one_on_arrays():
    rng = np.random.default_rng(12)
    for k in range(300):
        r = route.Route.of(np.cumsum(rng.normal(0, 40, (int(rng.integers(2, 9)), 2)), axis=0))
        ends = [float(rng.choice(r.points[:, 0])), float(rng.choice(r.points[:, 1]))]
        p = np.array(ends if k % 5 == 0 else rng.normal(0, 100, 2))   # on a corner, or anywhere
        for hint in (*r.cum, *rng.uniform(-200, r.length + 200, 4)):
            for back, ahead in ((24.0, 120.0), (0.0, 1.0), (0.0, 0.0), (5.0, 30.0)):
                got = r.project(p, hint, back, ahead)
                want = project_on_arrays(r, p, hint, back, ahead)
                assert all(same(x, y) for x, y in zip(got, want))
                assert type(got[0]) is float and type(got[1]) is float


def test_a_projection_in_floats_leaves_near_ties_to_the_arrays():
    # a corner (a point on its bisector is as near to both sides), a route back on itself
    # (every point as near to two segments), gaps of zero, of 1e-150 and of 1e200
    corner = route.Route.of([[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]])
    back = route.Route.of([[0.0, 0.0], [50.0, 0.0], [0.0, 0.0]])
    rng = np.random.default_rng(14)
    points = [[150.0, -50.0], [60.0, 40.0], [50.0, 50.0], [100.0, 0.0], [30.0, 0.0],
              [30.0, 1e-150], [1e200, -1e200], [25.0, 3.0], [-0.0, -0.0], *rng.normal(50, 60, (20, 2))]
    for r in (corner, back):
        for p in map(np.array, points):
            for hint in (0.0, 60.0, 100.0, 150.0):
                got = r.project(p, hint, 200.0, 200.0)
                want = project_on_arrays(r, p, hint, 200.0, 200.0)
                assert all(same(x, y) for x, y in zip(got, want))


def test_floor_division_of_floats_is_numpys():
    # RobotMap._square divides Python floats where it divided NumPy scalars
    rng = np.random.default_rng(15)
    xs = [*rng.uniform(-500, 500, 300), *(rng.integers(-50, 50, 100) * 0.5), 0.0, -0.0,
          1e-300, -1e-300, 5e-324, math.inf, -math.inf, math.nan]
    with np.errstate(invalid="ignore"):                 # inf // res is NaN both ways
        for x in xs:
            for res in (2.0, 0.5, 0.1, 3.0, 1e-3, 7.25):
                assert same(x // res, np.float64(x) // np.float64(res))
                assert same(x // res, np.float64(x) // res)


def test_a_widened_point_in_a_band_is_the_two_sided_test():
    values = [math.nan, -math.inf, math.inf, 0.0, -0.0, 1.0, -1.0, 9.5, -9.5, 5e-324, 1e300]
    b, widen, half = (np.array(x).ravel() for x in np.meshgrid(values, values, values))
    with np.errstate(invalid="ignore"):                  # inf - inf
        want = (b + widen > -half) & (b - widen < half)
        assert np.array_equal(perception._in_band(b, widen, half), want)
    rng = np.random.default_rng(11)
    b, widen, half = rng.normal(0, 20, (3, 100_000))
    widen, half = np.abs(widen) * rng.choice([1.0, 0.0, -1.0], widen.shape), np.abs(half)
    want = (b + widen > -half) & (b - widen < half)
    assert np.array_equal(perception._in_band(b, widen, half), want)


def _plain_free_ways(ah, bh, widen, unknown, robots, cfg, route_bearing):
    """free_ways_rows as it was written before it went one band at a time."""
    length = np.array([r.length / 2 for r in robots])
    way = np.array([r.width / 2 + cfg.way_margin for r in robots])
    bands = np.stack([way, way + cfg.way_room], axis=1)[:, :, None, None]
    ways = np.repeat(perception._ways(cfg)[None], len(robots), axis=0)
    ways[:, 1] = geometry.clip_arrays(route_bearing, -cfg.way_fov / 2, cfg.way_fov / 2)
    phi = np.deg2rad(ways)[..., None]
    cos, sin = np.cos(phi), np.sin(phi)
    ah, bh = ah[:, None], bh[:, None]
    along = ah * cos + bh * sin
    across = np.abs(-ah * sin + bh * cos) - widen[:, None]
    inside = (along > 0)[:, None] & (across[:, None] < bands)
    front = np.where(inside[:, 0, 0] & unknown, along[:, 0], np.inf).min(axis=1, initial=np.inf)
    front = geometry.clip_arrays(front - length, 0.0, cfg.sight)
    toward = geometry.clip_arrays(route_bearing, -90.0, 90.0)
    score = -cfg.way_turn_cost * np.abs(ways)
    weight = np.cos(np.deg2rad(ways - toward[:, None])) + cfg.way_room_weight
    free = np.where(inside, along[:, None], np.inf).min(axis=3, initial=np.inf)
    free = geometry.clip_arrays(free - length[:, None, None], 0.0, cfg.way_reach)
    gain = 0.5 * free * weight[:, None]
    score += gain[:, 0]
    score += gain[:, 1]
    return front, ways[np.arange(len(robots)), score.argmax(axis=1)]


def test_free_ways_one_band_at_a_time_are_the_plain_ways():
    rng = np.random.default_rng(12)
    cfg = perception.Settings()
    for k in range(300):
        n, rows = int(rng.integers(1, 40)), int(rng.choice([1, 1, 3]))
        robots = [Robot(length=float(rng.uniform(10, 30)), width=float(rng.uniform(8, 24)))
                  for _ in range(rows)]
        ah, bh = rng.normal(0, rng.choice([15.0, 60.0]), (2, rows, n))
        if k % 5 == 0:
            ah[:, ::3] = bh[:, ::3] = 0.0          # padding at the robot's centre
        widen = np.abs(rng.normal(0, 3, (rows, n)))
        unknown = rng.random((rows, n)) < 0.4
        bearing = rng.uniform(-200, 200, rows)
        got = perception.free_ways_rows(ah, bh, widen, unknown, robots, cfg, bearing)
        want = _plain_free_ways(ah, bh, widen, unknown, robots, cfg, bearing)
        assert same(got[0], want[0]) and same(got[1], want[1])


def _edge_points(rng, body, cfg, rows, n):
    """Points ``(ah, bh, widen)`` on ways of the grid at a band's edge (across it by the band
    and the widening, to a rounding or two), some behind the robot on it, some at its
    centre, some anywhere."""
    phi = np.deg2rad(rng.choice(perception._ways(cfg)[2:], (rows, n)))
    widen = np.abs(rng.normal(0, 3, (rows, n)))
    band = np.where(rng.random((rows, n)) < 0.5, body["way"], body["roomy"])
    across = (band + widen) * rng.choice([-1.0, 1.0], (rows, n))
    across = across * (1.0 + rng.choice([-4e-16, -2e-16, 0.0, 2e-16, 4e-16], (rows, n)))
    along = rng.choice([rng.uniform(-40, 150), 1e-9, -1e-9, 0.0], (rows, n))
    ah = along * np.cos(phi) - across * np.sin(phi)
    bh = along * np.sin(phi) + across * np.cos(phi)
    anywhere = rng.random((rows, n)) < 0.3
    ah[anywhere], bh[anywhere] = rng.normal(0, 60, (2, int(anywhere.sum())))
    centre = rng.random((rows, n)) < 0.1
    ah[centre] = bh[centre] = 0.0
    return ah, bh, widen


def test_free_ways_tried_near_each_point_are_those_of_every_point_on_every_way():
    rng = np.random.default_rng(21)
    cfg = perception.Settings()
    for _ in range(300):
        rows, n = int(rng.integers(1, 6)), int(rng.integers(1, 40))
        robots = [Robot(length=float(rng.uniform(10, 30)), width=float(rng.uniform(8, 24)))
                  for _ in range(rows)]
        body = perception._bodies(tuple(robots), cfg)
        ah, bh, widen = _edge_points(rng, body, cfg, rows, n)
        unknown = rng.random((rows, n)) < 0.4
        bearing = rng.uniform(-200, 200, rows)
        ways = perception._ways_of(body, cfg, bearing)
        every = np.stack(perception._free_along(ah, bh, widen, unknown, ways, body)[1])
        assert same(perception._grid_free(ah, bh, widen, body, cfg), every[..., 2:])
        got = perception._free_ways_near(ah, bh, widen, unknown, body, cfg, bearing)
        want = perception._free_ways_block(ah, bh, widen, unknown, body, cfg, bearing)
        assert same(got[0], want[0]) and same(got[1], want[1])


@pytest.mark.parametrize("case", ["finite", "not finite", "no points", "ways all round"])
def test_free_ways_go_near_each_point_only_where_they_may(case, monkeypatch):
    """Rows enough for :func:`perception._free_ways_near` (300 robots, 36 points): finite
    points take it, and points not finite, rows of no points and ways all round do not;
    each gives the bits of every point on every way."""
    rng = np.random.default_rng(5)
    rows, n = 300, 0 if case == "no points" else 36
    cfg = perception.Settings(way_fov=360.0) if case == "ways all round" else perception.Settings()
    assert perception._near_ways(cfg) == (case != "ways all round")
    ah, bh = rng.normal(0, 60, (2, rows, n))
    if case == "not finite":
        ah[7, 3], bh[9, 5] = np.nan, np.inf
    widen, unknown = np.abs(rng.normal(0, 3, (rows, n))), rng.random((rows, n)) < 0.4
    bearing, robots = rng.uniform(-200, 200, rows), [Robot()] * rows
    near = []
    plain = perception._free_ways_near
    monkeypatch.setattr(perception, "_free_ways_near",
                        lambda *args: near.append(1) or plain(*args))
    with np.errstate(invalid="ignore"):                  # inf * 0
        got = perception.free_ways_rows(ah, bh, widen, unknown, robots, cfg, bearing)
        want = _plain_free_ways(ah, bh, widen, unknown, robots, cfg, bearing)
    assert same(got[0], want[0]) and same(got[1], want[1])
    assert bool(near) == (case == "finite")


def test_bearings_lanes_and_pursuits_of_rows_are_each_rows_python_floats():
    rng = np.random.default_rng(22)
    cfg = perception.Settings()
    odd = [math.nan, math.inf, -math.inf, 0.0, -0.0, 1e-300, 90.0, -90.0, 180.0, 1e-9]
    for k in range(60):
        n = int(rng.integers(1, 50))
        dx, dy, e = rng.normal(0, 60, (3, n))
        heading = rng.uniform(-2 * math.pi, 2 * math.pi, n)
        left, home, road = rng.uniform(0, 400, (3, n))
        half, room = rng.uniform(4, 14, n), rng.choice([math.inf, 0.0, 5.0, 30.0], n)
        bearing = rng.choice([rng.uniform(-120, 120), 89.99, -90.0, 0.0], n)
        far = rng.choice([rng.uniform(0, 60), 0.0, 1e-12, 5.0], n)
        if k % 4 == 0:              # odd values and ties, as Python's min and max meet them
            for x in (dx, dy, e, left, home, road, room, bearing, far):
                x[rng.random(n) < 0.2] = rng.choice(odd)
            road[rng.random(n) < 0.3] = cfg.road_cap
            home[rng.random(n) < 0.3] = left[0]
        got = perception._common_rows(dx, dy, heading, left, e, home, road, half, cfg, room)
        got = (*got, perception._pursuit_rows(bearing, far, cfg))
        for i in range(n):
            robot = Robot(width=float(2 * half[i]))
            want = perception._common_of(float(dx[i]), float(dy[i]), float(heading[i]),
                                         float(left[i]), float(e[i]), float(home[i]),
                                         float(road[i]), robot, cfg, float(room[i]))
            want = (*want, perception._pursuit_of(float(bearing[i]), float(far[i]), cfg))
            assert all(same(g[i], w) for g, w in zip(got, want)), (i, got, want)


def test_road_and_side_gaps_of_rows_are_the_plain_minima():
    rng = np.random.default_rng(13)
    cfg = perception.Settings()
    for _ in range(200):
        rows, n = int(rng.choice([1, 4])), int(rng.integers(1, 40))
        robots = [Robot(length=float(rng.uniform(10, 30)), width=float(rng.uniform(8, 24)))
                  for _ in range(rows)]
        a, b = rng.normal(0, 40, (2, rows, n))
        b[rng.random(b.shape) < 0.1] = 0.0
        valid, objects = rng.random((2, rows, n)) < 0.7
        half = np.array([r.width / 2 for r in robots])[:, None]
        length = np.array([r.length / 2 for r in robots])[:, None]

        def least(mask, values, none):
            return np.where(mask.any(axis=1),
                            np.where(mask, values, np.inf).min(axis=1, initial=np.inf), none)

        walls = valid & (rng.random((rows, n)) < 0.8)
        body = perception._bodies(tuple(robots), cfg)
        ah, bh = rng.normal(0, 40, (2, rows, n))             # the robots' own frames
        road, left, right = perception._sides(a, b, ah, bh, valid, walls, body, cfg, 200.0,
                                              objects)
        centre = np.hypot(ah, bh)
        side = walls & (np.abs(a) <= cfg.window)
        assert same(road, np.where((side & (b < 0)).any(axis=1),
                                   least(side & (b < 0), centre, 0.0), 200.0)
                    + np.where((side & (b > 0)).any(axis=1),
                               least(side & (b > 0), centre, 0.0), 200.0))
        ahead = np.where(objects, length, cfg.wall_ahead)
        near = valid & (a >= -cfg.wall_behind) & (a <= ahead) & (np.abs(b) >= half)
        over = np.abs(ah) - length
        axis = np.where(over > 0, np.hypot(over, np.abs(bh)), np.abs(bh))
        assert same(left, np.maximum(np.where((near & (b < 0)).any(axis=1),
                                              least(near & (b < 0), axis, 0.0) - half[:, 0],
                                              200.0), 0.0))
        assert same(right, np.maximum(np.where((near & (b > 0)).any(axis=1),
                                               least(near & (b > 0), axis, 0.0) - half[:, 0],
                                               200.0), 0.0))


def test_chords_cleared_from_the_squares_are_those_hypot_clears():
    rng = np.random.default_rng(11)
    dx, dy = rng.normal(0, 20, (2, 40, 30, 9))
    radius, need = rng.uniform(0, 2, (40, 1)), rng.uniform(0, 30, (40, 1))
    plain = np.hypot(dx, dy).min(axis=1)
    # chords exactly on the line, a rounding either side of it, and a few odd values
    need[:10] = plain[:10, :1] - radius[:10]
    need[10:20] = np.nextafter(plain[10:20, :1] - radius[10:20], np.inf)
    need[20:25] = np.nextafter(plain[20:25, :1] - radius[20:25], -np.inf)
    dx[25, 0, 0], dy[26, 3, 2], dx[27, :, :] = np.nan, np.inf, 1e-170
    dy[27, :, :] = 1e-170
    dx[28, :, 1], dy[28, :, 1] = 1e200, 1e200
    got = perception._clear_of(dx, dy, radius, need)
    assert np.array_equal(got, np.hypot(dx, dy).min(axis=1) - radius >= need)


def plain_pursuit_point(a: perception.Aim, cfg: perception.Settings):
    """The pursuit point measured against every cell, with hypot (as it was written)."""
    ahead = perception._lookaheads(cfg)
    if not len(a.cells):
        return float(ahead[-1]), perception.target_point(a.route, a.f, cfg, float(ahead[-1]))
    q = perception.target_points(a.route, a.f, ahead)
    e = q - a.p
    ee = np.maximum(e[:, 0] * e[:, 0] + e[:, 1] * e[:, 1], 1e-12)
    rel = a.cells - a.p
    rx, ry = rel[:, 0, None], rel[:, 1, None]
    t = np.clip((rx * e[:, 0] + ry * e[:, 1]) / ee, 0.0, 1.0)
    clear = np.hypot(rx - t * e[:, 0], ry - t * e[:, 1]).min(axis=0) - a.radius >= a.need
    k = len(ahead) - 1 if clear.all() else max(int(clear.argmin()) - 1, 0)
    return float(ahead[k]), q[k]


def test_pursuit_points_from_the_cells_near_their_chords_are_those_of_every_cell():
    sims = running("slalom.yaml", ticks=60)
    aims = []
    for sim in sims:
        s = sim.sense()
        sim.tracked(s)
        aims += sim.aims(s, perception.frames(*sim.framing(s)))
    cfg = sims[0].settings
    rng = np.random.default_rng(5)
    made = []
    for a in aims:
        q = perception.target_points(a.route, a.f, perception._lookaheads(cfg))
        for _ in range(30):      # cells about the chords, some at the box's edge, some far
            k = int(rng.integers(1, 40))
            on = q[rng.integers(0, len(q), k)] * rng.uniform(0, 1, (k, 1)) \
                + a.p * rng.uniform(0, 1, (k, 1))
            along = on + rng.normal(0, a.need + a.radius, (k, 2))
            if rng.random() < 0.3:
                along[0] = q[-1] + [a.need + a.radius, 0.0]
            made.append(dataclasses.replace(a, cells=np.concatenate([a.cells, along])))
    made += [dataclasses.replace(made[0], cells=np.full((3, 2), np.nan))]
    ahead, targets = perception.pursuit_points(made, cfg)
    for i, a in enumerate(made):
        one, target = plain_pursuit_point(a, cfg)
        assert same(one, ahead[i]) and same(target, targets[i])
        alone = perception.pursuit_point(a.route, a.f, a.p, a.cells, a.radius, a.need, cfg)
        assert same(alone[0], one) and same(alone[1], target)
    assert len({float(x) for x in ahead}) > 3          # short lookaheads among them


def test_free_ways_of_many_rows_worked_in_blocks_are_each_rows_own():
    rng = np.random.default_rng(13)
    cfg = perception.Settings()
    rows, n = 3 * perception.CACHED // (39 * 36) + 7, 36        # three blocks and a part
    robots = [Robot(length=float(rng.uniform(10, 30)), width=float(rng.uniform(8, 24)))
              for _ in range(rows)]
    ah, bh = rng.normal(0, 40.0, (2, rows, n))
    widen = np.abs(rng.normal(0, 3, (rows, n)))
    unknown = rng.random((rows, n)) < 0.4
    bearing = rng.uniform(-200, 200, rows)
    got = perception.free_ways_rows(ah, bh, widen, unknown, robots, cfg, bearing)
    for i in range(rows):
        one = perception.free_ways_rows(ah[i:i + 1], bh[i:i + 1], widen[i:i + 1],
                                        unknown[i:i + 1], robots[i:i + 1], cfg, bearing[i:i + 1])
        assert same(got[0][i], one[0][0]) and same(got[1][i], one[1][0])


def plain_sighting(free: movers.FreeSpace, now: float, origin, ranges, dirs, seen, ring: bool):
    """What one robot sees that its map does not show, as the tracker worked it out robot by
    robot: the seen beams cut into objects, each echo tested against the beams kept in the
    window (gathered), each object's vote, centre and half size, and its line of sight from
    the robot with the gate across it (:func:`.movers.sight_lines`), object by object."""
    hits = origin + ranges[:, None] * dirs
    idx = seen.nonzero()[0]
    runs = []
    if len(idx):
        pts = hits[idx]
        gap = np.hypot(*(pts[1:] - pts[:-1]).T)
        ends = [0, *(((idx[1:] - idx[:-1] > 1) | (gap > movers.LINK)).nonzero()[0] + 1), len(idx)]
        runs = [idx[a:b] for a, b in zip(ends[:-1], ends[1:])]
        if ring and len(runs) > 1 and idx[0] == 0 and idx[-1] == len(seen) - 1 \
                and math.dist(pts[0], pts[-1]) <= movers.LINK:
            runs = [np.concatenate([runs[-1], runs[0]])] + runs[1:-1]
    tested = entered = np.zeros(len(idx), dtype=bool)
    live = (free.times >= now - movers.WINDOW) & (free.times < now)
    if len(idx) and live.any():
        pose, kept = free.poses[live], free.ranges[live]
        rel = (hits[idx] + dirs[idx] * movers.STEP)[:, None, :] - pose[None, :, :2]
        dist = np.hypot(rel[..., 0], rel[..., 1])
        ahead = np.arctan2(rel[..., 1], rel[..., 0]) - pose[None, :, 2]
        if not ring:
            ahead = np.mod(ahead + np.pi, 2 * np.pi) - np.pi
        bearing = ahead - free.a0
        k = np.rint(bearing / free.step)
        inside = (k >= 0) & (k < kept.shape[1])
        k = np.mod(k, kept.shape[1]).astype(np.int64) if ring \
            else np.clip(k, 0, kept.shape[1] - 1).astype(np.int64)
        off = np.mod(bearing - k * free.step + np.pi, 2 * np.pi) - np.pi
        on = (np.abs(off) < np.pi / 2) & (dist * np.abs(np.sin(off)) < free.near)
        on &= True if ring else inside
        reach = kept[np.arange(len(pose))[None, :], k]
        passed = on & (dist * np.cos(off) < reach - movers.SHORT)
        # the closing speed along the lines of the beams that echoed it and did not pass it
        # (a = s age + c side, fitted through (0, 0); s what the side does not explain)
        age = np.broadcast_to(now - free.times[live], on.shape)
        side = dist * np.sin(off)
        ok = on & ~passed & (reach < free.far)
        a = reach - dist * np.cos(off) + movers.STEP
        closes = np.zeros(len(idx), dtype=bool)
        for e in range(len(idx)):
            m = ok[e]
            t, x, y = age[e][m], side[e][m], a[e][m]
            stt, sts, sss = float(t @ t), float(t @ x), float(x @ x)
            k = sts / sss if sss > 0 else 0.0
            d = stt - sts * k
            closes[e] = d > 1e-9 * stt and (float(y @ t) - float(y @ x) * k
                                            - movers.SURE * math.sqrt(2.0) * free.noise
                                            * math.sqrt(max(d, 0.0)) >= movers.MIN_SPEED * d)
        tested, entered = on.any(axis=1), passed.any(axis=1) | closes
    at = np.add.accumulate(seen, dtype=np.intp) - 1
    moved = [None if not (n := np.count_nonzero(tested[at[r]]))
             else 2 * np.count_nonzero(entered[at[r]]) >= n for r in runs]
    if not runs:
        return np.zeros((0, 2)), np.zeros(0), moved, np.zeros((0, 3))
    found = [hits[r] for r in runs]
    sizes = np.array([len(o) for o in found])
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    pts = np.concatenate(found)
    centres = np.add.reduceat(pts, starts, axis=0) / sizes[:, None]
    spread = np.hypot(*(pts - centres.repeat(sizes, axis=0)).T)
    sight = []
    for c in centres:
        rel = c - origin
        r = float(np.hypot(*rel))
        across = 2 * r * math.sin(abs(free.step) / 2)
        sight.append((*(rel / r), movers.GATE / across) if across > movers.GATE else (1.0, 0.0, 1.0))
    return centres, np.maximum.reduceat(spread, starts), moved, np.array(sight)


@pytest.mark.parametrize("ring", [True, False])
def test_what_robots_see_together_is_what_each_sees_alone(ring):
    rng = np.random.default_rng(21 + ring)
    beams, dt = 36, 0.05
    angles = (np.deg2rad(np.arange(beams) * 10.0) if ring
              else np.deg2rad(np.linspace(135, -135, beams)))              # a ring, a fan
    spaces, now = [], 3.0
    for _ in range(40):                          # robots driving about with a wall in view
        # (sensors of 0-1.5 in noise; a range of 150 in read by about a tenth of the beams)
        free = movers.FreeSpace.of(angles, ring, dt, 2.0, noise=0.5 * (len(spaces) % 4),
                                   far=150.0)
        x, y, h = rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(-4, 4)
        for k in range(int(rng.integers(0, 2 * movers.WINDOW / dt))):
            x, y, h = x + rng.normal(0, 2), y + rng.normal(0, 2), h + rng.normal(0, 0.05)
            d = np.stack([np.cos(angles + h), np.sin(angles + h)], axis=1)
            free.update(now - (k + 1) * dt, np.array([x, y]), d,
                        np.minimum(rng.uniform(5, 165, beams), 150.0))
        spaces.append(free)
    origins = rng.uniform(-50, 50, (40, 2))
    heading = rng.uniform(-4, 4, 40)
    dirs = np.stack([np.cos(angles + heading[:, None]), np.sin(angles + heading[:, None])], axis=2)
    ranges = rng.uniform(5, 150, (40, beams))
    ranges[::3] = 60 + rng.normal(0, 2, (14, beams))         # one object round the robot
    seen = rng.random((40, beams)) < rng.uniform(0, 1, (40, 1))
    seen[::4, [0, -1]] = True                               # across a ring's first beam
    seen[5] = False
    together = movers.sightings(spaces, now, origins, ranges, dirs, seen)
    for r, (centres, radii, moved, sight) in enumerate(together):
        plain = plain_sighting(spaces[r], now, origins[r], ranges[r], dirs[r], seen[r], ring)
        alone = movers.sightings(spaces[r:r + 1], now, origins[r:r + 1], ranges[r:r + 1],
                                 dirs[r:r + 1], seen[r:r + 1])[0]
        for got in (alone, (centres, radii, moved, sight)):
            assert same(got[0], plain[0]) and same(got[1], plain[1]) and got[2] == plain[2]
            assert np.allclose(got[3], plain[3], rtol=1e-12, atol=0)
        assert same(alone[3], sight)
    assert any(None in m and True in m and False in m for _, _, m, _ in together)
    assert any((s[:, 2] < 1).any() and (s[:, 2] == 1).any() for *_, s in together)


def test_cells_beyond_many_robots_readings_at_once_are_each_robots_own():
    sims = running("slalom.yaml", runs=3, ticks=60)
    maps, origins, dirs, measured, sensed = [], [], [], [], []
    for sim in sims:
        s = sim.sense()
        m, o, d, r, _ = sim.clearing(s)
        maps += m
        origins.append(o), dirs.append(d), measured.append(r), sensed.append(s)
    got = knowledge.beyond_cells(maps, *(np.concatenate(x) for x in (origins, dirs, measured)))
    for j, (sim, s) in enumerate(zip(sims, sensed)):
        assert same(got[j], sim._beyond(0, s))          # the one robot's own, worked alone
    other = knowledge.RobotMap.of(Grid(np.zeros((4, 4), bool), 3.0, (0.0, 0.0), ""))
    two = [np.concatenate([x[0], x[0]]) for x in (origins, dirs, measured)]
    assert knowledge.beyond_cells([maps[0], other], *two) is None   # grids unlike: alone


def test_route_gaps_measured_together_give_each_robots_own_room():
    sims = running("slalom.yaml", ticks=60)
    aims = []
    for sim in sims:
        s = sim.sense()
        sim.tracked(s)
        aims += sim.aims(s, perception.frames(*sim.framing(s)))
    aims += [dataclasses.replace(a, cells=a.cells[:k]) for a in aims for k in (0, 1, 7)]
    assert any(len(a.cells) > 20 for a in aims)
    gaps = perception.route_gaps(aims)
    for a, gap in zip(aims, gaps):
        alone = perception.route_room(a.f, a.p, a.cells, a.radius, 9.5)
        assert same(max(0.0, gap - a.radius - 9.5), alone)
        assert same(perception.route_gaps([a])[0], gap)


def test_robots_sharing_routes_placed_together_get_the_bits_they_get_alone():
    rng = np.random.default_rng(14)
    shared = [route.Route.of(np.cumsum(rng.normal(0, 30, (int(rng.integers(2, 40)), 2)),
                                       axis=0)) for _ in range(5)]
    routes = [shared[int(k)] for k in rng.integers(0, 5, 60)]       # each many rows' own
    points = rng.normal(0, 150, (60, 2))
    hints = [float(rng.uniform(-200, r.length + 200)) for r in routes]
    assert_placed_as_alone(routes, points, hints)


def _object_alone(r: route.Route, f: perception.Frame, a, points, ahead, blocking, widen,
                  length: float, cfg: perception.Settings) -> tuple[float, float, float]:
    """The object of one row, written out (distance, size, position)."""
    i = int(np.where(blocking, a, np.inf).argmin())
    near = ahead & (np.hypot(*(points - points[i]).T) <= cfg.cluster)
    distance = max(0.0, float(a[near].min()) - length)
    pts = points[near]
    centre = pts.mean(axis=0)
    _, e_o, t_o = r.project(centre, f.s, back=0.0, ahead=cfg.sight + cfg.cluster)
    across = (pts - centre) @ np.array([t_o[1], -t_o[0]]) + e_o
    lo, hi = float((across - widen[near]).min()), float((across + widen[near]).max())
    return distance, hi - lo, (lo + hi) / 2


def test_objects_of_many_rows_at_once_are_each_rows_own():
    rng = np.random.default_rng(16)
    cfg = perception.Settings()
    for k in range(40):
        rows_ = int(rng.integers(1, 9))
        beams = int(rng.choice([1, 2, 5, 36]))
        routes = [route.Route.of(np.cumsum(rng.normal(0, 40, (int(rng.integers(2, 9)), 2)), axis=0))
                  for _ in range(rows_)]
        frames = [perception.frame(r, rng.normal(0, 30, 2), rng.uniform(0, r.length))
                  for r in routes]
        points = rng.normal(0, 25, (rows_, beams, 2))
        a = rng.uniform(-20, 160, (rows_, beams))
        ahead = rng.random((rows_, beams)) < 0.8
        blocking = ahead & (rng.random((rows_, beams)) < 0.5)
        blocking[np.arange(rows_), rng.integers(0, beams, rows_)] = True
        ahead |= blocking
        widen = rng.uniform(0, 3, (rows_, beams))
        length = rng.uniform(-5, 20, rows_)
        got = perception._objects(routes, frames, a, points, ahead, blocking, widen, length, cfg)
        for j in range(rows_):
            want = _object_alone(routes[j], frames[j], a[j], points[j], ahead[j], blocking[j],
                                 widen[j], float(length[j]), cfg)
            assert same([got[0][j], got[1][j], got[2][j]], list(want)), (k, j)


def test_a_call_of_aimed_with_the_lookaheads_it_no_longer_takes_is_refused():
    """``Simulation.aimed`` once took the lookaheads before the targets; a call written so
    is refused at once (``gaps`` is by name), not read as targets and gaps."""
    sim = running("slalom.yaml")[0]
    s = sim.sense()
    aims = sim.aims(s, perception.frames(*sim.framing(s)))
    ahead, targets = perception.pursuit_points(aims, sim.settings)
    with pytest.raises(TypeError):
        sim.aimed(s, aims, ahead, targets)
    assert sim.aimed(s, aims, targets).target.tobytes() == targets.tobytes()
