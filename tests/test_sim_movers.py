"""What moves, as the robot's readings show it: segmentation, free space, tracks, where a
mover will pass, and a robot that waits for a cart where there is no way past it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.sim import knowledge, movers
from mitos_cli.sim.loop import clearances, prepare, simulate
from mitos_cli.sim.route import Clearance
from mitos_cli.sim.world import Goal
from mitos_cli.sim.worldfile import parse_world

ROOT = Path(__file__).resolve().parents[1]


def ring_hits(points: dict[int, tuple[float, float]], count: int = 36):
    hits = np.zeros((count, 2))
    seen = np.zeros(count, dtype=bool)
    for k, xy in points.items():
        hits[k], seen[k] = xy, True
    return hits, seen


# --- objects along the ring ----------------------------------------------------------------

def test_neighbouring_echoes_close_together_are_one_object_and_a_gap_cuts_them():
    hits, seen = ring_hits({3: (100, 0), 4: (100, 8), 5: (100, 16),     # one face
                            6: (100, 60),                                # too far from it
                            9: (0, 100)})                                # beams apart
    runs = movers.objects(hits, seen, ring=True)
    assert [r.tolist() for r in runs] == [[3, 4, 5], [6], [9]]


def test_an_object_across_the_first_beam_of_a_ring_is_one_object():
    hits, seen = ring_hits({0: (100, 0), 1: (100, 8), 35: (100, -8), 20: (-100, 0)})
    runs = movers.objects(hits, seen, ring=True)
    assert sorted(r.tolist() for r in runs) == [[20], [35, 0, 1]]
    assert len(movers.objects(hits, seen, ring=False)) == 3       # a fan does not wrap


# --- free space ----------------------------------------------------------------------------

def ring_free(count: int = 36, noise: float = 0.0):
    angles = np.deg2rad(np.arange(count) * (360.0 / count))
    return movers.FreeSpace.of(angles, ring=True, dt=0.05, resolution=2.0, noise=noise,
                               far=150.0), angles


def entered(free, now, points, dirs) -> list[bool | None]:
    """Per echo: None where no kept beam's line crossed it, else whether one passed it."""
    on, passed = free.entered(now, points, dirs)
    return [bool(p) if o else None for o, p in zip(on, passed)]


def test_an_echo_where_a_beam_passed_a_moment_ago_came_from_something_that_moved_there():
    free, angles = ring_free(noise=1.0)
    dirs = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    ranges = np.full(36, 150.0)
    ranges[0] = 80.0                                          # east: a wall at 80 in
    free.update(1.0, np.zeros(2), dirs, ranges)
    east = np.array([[1.0, 0.0]])
    assert entered(free, 1.2, np.array([[40.0, 0.0]]), east) == [True]    # came since
    assert entered(free, 1.2, np.array([[80.0, 0.0]]), east) == [False]   # the wall
    # noise on the echo of the wall (SHORT) is not something that came
    assert entered(free, 1.2, np.array([[80.0 - movers.SHORT / 2, 0]]), east) == [False]
    # half a cell off the line is still on it; between two beams no line crossed
    assert entered(free, 1.2, np.array([[40.0, 0.9]]), east) == [True]
    off = 60 * np.array([[math.cos(math.radians(5)), math.sin(math.radians(5))]])
    assert entered(free, 1.2, off, off / 60) == [None]
    # long ago is not a moment ago, and the same tick is not before it
    assert entered(free, 1.0 + movers.WINDOW + 0.1, np.array([[40.0, 0.0]]), east) == [None]
    assert entered(free, 1.0, np.array([[40.0, 0.0]]), east) == [None]


def closing(speed: float, ages: list[float], noise: float = 0.5, far: float = 150.0):
    """The echo straight ahead of a robot driving east at 40 in/s (now at x = 0) of a face
    that comes west at ``speed`` in/s and is 60 in off now, tested against the ring's beams
    cast ``ages`` s before (noise-free readings of a sensor of ``noise``; ``far``: its range)."""
    free, angles = ring_free(noise=noise)
    now = 2.0
    for age in sorted(ages, reverse=True):
        p = np.array([-40.0 * age, 0.0])
        dirs = np.stack([np.cos(angles), np.sin(angles)], axis=1)
        ranges = np.full(36, far)
        ranges[0] = min(60.0 + speed * age - p[0], far)     # the face where it was then
        free.update(now - age, p, dirs, ranges)
    return entered(free, now, np.array([[60.0, 0.0]]), np.array([[1.0, 0.0]]))


def test_an_echo_that_closes_along_its_line_faster_than_the_robot_drives_came():
    """A cart 15 in/s head-on comes 0.75-3.75 in nearer in the 0.05-0.25 s since the beams
    before on its line were cast (``SHORT + STEP``, 6 in, asks more of each), but their ranges
    shrink 15 in/s faster than the robot's own drive explains: a closing speed of 15 in/s,
    ``SURE`` standard deviations of the sensor's noise (0.5 in) beyond ``MIN_SPEED``."""
    young = [0.05, 0.1, 0.15, 0.2, 0.25]
    assert closing(15.0, young) == [True]
    assert closing(0.0, young) == [False]                # a box stands where it stood
    assert closing(-15.0, young) == [False]              # a cart going away
    # one beam of a moment ago cannot tell 15 in/s from the noise; the noisier the sensor,
    # the more beams it takes
    assert closing(15.0, [0.05]) == [False]
    assert closing(15.0, young, noise=1.5) == [False]
    assert closing(15.0, young + [0.3, 0.35, 0.4, 0.45, 0.5], noise=1.5) == [True]
    # slower than MIN_SPEED is standing, however sure
    assert closing(movers.MIN_SPEED * 0.8, young, noise=0.0) == [False]
    assert closing(movers.MIN_SPEED * 1.2, young, noise=0.0) == [True]


def test_an_echo_on_a_face_the_beams_meet_aslant_as_the_robot_turns_did_not_come():
    """A box's side seen at 13 deg: a beam that passed 1 in to one side of the echo ended
    cot(13 deg) = 4.3 in farther on. A robot turning at 2 deg/s sweeps its beams across
    the line as steadily as they age, so the echo lies 0.7-3.4 in nearer than beams 0.05-0.25
    s old saw, as a cart's at 14 in/s would; but that is what their side explains, and it is
    not told a closing speed. The same nearings on the line itself are."""
    (turned, angles), on_line = ring_free(noise=0.5), ring_free(noise=0.5)[0]
    now, r, omega = 2.0, 90.0, math.radians(2.0)
    for age in (0.25, 0.2, 0.15, 0.1, 0.05):
        h = -omega * age                                   # the heading then
        side = (r + movers.STEP) * math.sin(-h)            # how far the old beam 0 passes q
        along = (r + movers.STEP) * math.cos(h)
        nearer = side / math.tan(math.radians(13.0))
        for space, heading in ((turned, h), (on_line, 0.0)):
            dirs = np.stack([np.cos(angles + heading), np.sin(angles + heading)], axis=1)
            ranges = np.full(36, 150.0)
            ranges[0] = along - movers.STEP + nearer
            space.update(now - age, np.zeros(2), dirs, ranges)
    echo, east = np.array([[r, 0.0]]), np.array([[1.0, 0.0]])
    assert entered(turned, now, echo, east) == [False]
    assert entered(on_line, now, echo, east) == [True]


def test_a_beam_that_read_nothing_in_its_range_says_nothing_of_how_fast_an_echo_closes():
    """Beams that saw nothing within their range end there whatever lies beyond: an echo
    just inside that range, 1-3 in short of their end, neither came (they did not pass it
    by ``SHORT``) nor stood, and does not pull the closing speed of the beams that echoed
    it down to 0."""
    free, angles = ring_free(noise=0.5)
    dirs = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    now = 3.0
    for age in (1.3, 1.2, 1.1):                   # far back: the face out of range (150 in)
        free.update(now - age, np.array([-40.0 * age, 0.0]), dirs, np.full(36, 150.0))
    for age in (0.25, 0.2, 0.15, 0.1, 0.05):      # lately: the face coming at 15 in/s
        ranges = np.full(36, 150.0)
        ranges[0] = 100.0 + 15.0 * age + 40.0 * age
        free.update(now - age, np.array([-40.0 * age, 0.0]), dirs, ranges)
    echo = np.array([[100.0, 0.0]])
    # (the far beams end 150 - 40 t, 1 to 2 in beyond the echo 1.1-1.3 s later)
    assert entered(free, now, echo, np.array([[1.0, 0.0]])) == [True]


@pytest.mark.parametrize("heading_deg", [90, 0, 170, 180, -170, -90])
@pytest.mark.parametrize("fan_deg", [90, 270])                 # BARN's lidar spans 270 deg
def test_free_space_follows_the_robots_pose_and_a_fan_of_beams(heading_deg, fan_deg):
    n = 10
    angles = np.deg2rad(np.linspace(fan_deg / 2, -fan_deg / 2, n))   # a fan, left to right
    free = movers.FreeSpace.of(angles, ring=False, dt=0.05, resolution=2.0)
    heading = math.radians(heading_deg)
    dirs = np.stack([np.cos(angles + heading), np.sin(angles + heading)], axis=1)
    p = np.array([10.0, 10.0])
    free.update(0.0, p, dirs, np.full(n, 100.0))
    along = p + 50 * dirs                                       # on every beam's line
    assert entered(free, 0.5, along, dirs) == [True] * n
    back = -np.array([math.cos(heading), math.sin(heading)])  # straight behind: outside the fan
    assert entered(free, 0.5, p + 50 * back[None], back[None]) == [None]


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans(), st.integers(1, 40))
def test_spaces_stacked_keep_and_look_up_the_beams_as_each_space_alone(seed, ring, ticks):
    """Spaces.stacked: one write keeps every robot's beams as its own update would, and
    entered() looks a subset's echoes up in the stack with the bits of the spaces one by one."""
    rng = np.random.default_rng(seed)
    robots, beams = 5, 8
    angles = np.deg2rad(np.arange(beams) * (45.0 if ring else 20.0) - (0.0 if ring else 70.0))
    # (each robot's sensor its own noise, as randomised runs draw theirs; a range of 60 in)
    alone = [movers.FreeSpace.of(angles, ring, 0.05, 2.0, 0.5 * i, 60.0) for i in range(robots)]
    spaces = [movers.FreeSpace.of(angles, ring, 0.05, 2.0, 0.5 * i, 60.0) for i in range(robots)]
    stack = movers.Spaces.stacked(spaces)
    assert stack is not None
    for k in range(ticks):
        now = 0.05 * k
        at = rng.uniform(-20, 20, (robots, 2))
        heading = rng.uniform(-math.pi, math.pi, robots)
        dirs = np.stack([np.cos(heading[:, None] + angles), np.sin(heading[:, None] + angles)],
                        axis=2)
        ranges = np.minimum(rng.uniform(5, 66, (robots, beams)), 60.0)
        for sp, p, d, r in zip(alone, at, dirs, ranges):
            sp.update(now, p, d, r)
        stack.update(now, at, dirs, ranges)
    for a, b in zip(alone, spaces):
        assert a.slot == b.slot
        for name in ("times", "poses", "ranges"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), name
    rows = np.array([0, 2, 3])
    owner = rng.integers(0, len(rows), 12)
    points = rng.uniform(-40, 40, (12, 2))
    along = rng.normal(size=(12, 2))
    along /= np.hypot(*along.T)[:, None]
    now = 0.05 * ticks
    got = movers.entered(stack.picked(rows), now, points, along, owner)
    want = movers.entered([alone[i] for i in rows], now, points, along, owner)
    assert all(np.array_equal(g, w) for g, w in zip(got, want))


# --- tracks --------------------------------------------------------------------------------

def follow(tracker: movers.Tracker, centre, velocity, seconds: float, moved: bool | None,
           wobble: float = 3.0, dt: float = 0.05, t0: float = 0.0):
    """Feed ``tracker`` an object of two echoes 8 in apart whose centre moves at ``velocity``,
    one echo hopping ``wobble`` in from tick to tick (a sonar ring sees parts of a cart)."""
    c0, v = np.asarray(centre, float), np.asarray(velocity, float)
    t = t0
    for k in range(int(round(seconds / dt))):
        t = t0 + k * dt
        c = c0 + v * (t - t0)
        hop = wobble * (1 if k % 2 else -1)
        echoes = np.array([c + [0, -4 + hop], c + [0, 4]])
        tracker.update(t, [echoes], [moved])
    return t


def test_a_cart_coming_head_on_is_a_mover_with_its_velocity():
    tracker = movers.Tracker()
    t = follow(tracker, (300, 0), (-15, 0), 2.0, moved=True)
    found = tracker.movers(t, np.array([0.0, 0.0]), own=np.array([30.0, 0.0]))
    assert len(found) == 1
    assert np.allclose(found[0].velocity, (-15, 0), atol=1.5)
    assert not found[0].settled                               # 2 s < SETTLE
    t = follow(tracker, (300 - 15 * 2.05, 0), (-15, 0), 1.0, moved=True, t0=t + 0.05)
    assert tracker.movers(t, np.array([0.0, 0.0]), own=np.zeros(2))[0].settled


def test_what_moves_away_or_stands_is_no_mover():
    away = movers.Tracker()
    t = follow(away, (300, 0), (15, 0), 2.0, moved=True)
    assert away.movers(t, np.zeros(2), own=np.zeros(2)) == []
    across = movers.Tracker()                                  # passes across, 90 deg off
    t = follow(across, (300, -100), (0, 15), 2.0, moved=True)
    assert across.movers(t, np.zeros(2), own=np.zeros(2)) == []
    # a standing pole whose echoes slide along it as the robot passes: they never come
    # into space a beam had just passed through
    pole = movers.Tracker()
    t = follow(pole, (300, 0), (-15, 0), 2.0, moved=False)
    assert pole.movers(t, np.zeros(2), own=np.zeros(2)) == []
    # nor one whose echoes no beam's line had crossed before: nothing says it came
    unseen = movers.Tracker()
    t = follow(unseen, (300, 0), (-15, 0), 2.0, moved=None)
    assert unseen.movers(t, np.zeros(2), own=np.zeros(2)) == []
    # a robot that draws away from a cart faster than it comes is not in its way
    chase = movers.Tracker()
    t = follow(chase, (300, 0), (-15, 0), 2.0, moved=True)
    assert chase.movers(t, np.zeros(2), own=np.array([-40.0, 0.0])) == []


def test_a_mover_missed_for_a_tick_or_two_is_kept_where_it_should_be():
    tracker = movers.Tracker()
    t = follow(tracker, (300, 0), (-15, 0), 2.0, moved=True)
    assert tracker.movers(t, np.zeros(2), own=np.zeros(2))
    tracker.update(t + 0.2, [], [])
    found = tracker.movers(t + 0.2, np.zeros(2), own=np.zeros(2))
    assert len(found) == 1 and math.isclose(found[0].centre[0], 300 - 15 * (t + 0.2), abs_tol=2)
    tracker.update(t + movers.MAX_MISS + 0.1, [], [])
    assert tracker.movers(t + movers.MAX_MISS + 0.1, np.zeros(2), own=np.zeros(2)) == []


def hop_between_corners(tracker: movers.Tracker, x0: float, seconds=2.0, dt=0.05) -> float:
    """Feed ``tracker`` what a ring of 36 beams (10 deg apart) sees of a cart's face coming
    head-on at 15 in/s from ``x0`` in ahead of a robot at the origin: one echo a tick, at
    one front corner for 0.5 s, none for 0.25 s (the cart between two beams), then at the
    other corner, 16 in across (as `moving+clutter5` of the benchmark's seed 0 saw it).
    Returns the time of the last tick."""
    t = 0.0
    for k in range(int(round(seconds / dt))):
        t = k * dt
        if 0.5 <= t < 0.75:                                   # between two beams
            tracker.follow(t, np.zeros((0, 2)), np.zeros(0), [], np.zeros((0, 3)))
            continue
        centre = np.array([[x0 - 15 * t, 8.0 if t > 0.5 else -8.0]])
        tracker.follow(t, centre, np.zeros(1), [True],
                       movers.sight_lines(centre, np.zeros((1, 2)), np.deg2rad(10.0)))
    return t


def test_a_carts_two_corners_echoed_by_two_beams_far_off_are_one_track():
    """A ring's neighbouring beams lie 17 in apart 100 in off, so a cart 16 in wide is
    echoed at one front corner, then (missed a moment) at the other: one object, one track,
    found a mover. (On the tree before, each hop started a track, and none was followed
    long enough to be fitted a velocity.)"""
    tracker = movers.Tracker()
    t = hop_between_corners(tracker, 110.0)
    assert [tr.born for tr in tracker.tracks] == [0.0]          # followed from the first echo
    found = tracker.movers(t, np.zeros(2), own=np.zeros(2))
    assert len(found) == 1 and np.allclose(found[0].velocity, (-15, 0), atol=2)
    soon = movers.Tracker()                  # a mover 1.3 s after the first echo (a track
    t = hop_between_corners(soon, 110.0, seconds=1.3)     # started at the hop: 1.65 s)
    assert len(soon.movers(t, np.zeros(2), own=np.zeros(2))) == 1


def test_near_the_robot_two_objects_16_in_apart_stay_two_tracks():
    """Near the robot its beams lie closer than the gate, which stays round there: what
    lies 16 in apart 40 in off is two objects, as before."""
    tracker = movers.Tracker()
    hop_between_corners(tracker, 40.0, seconds=1.0)
    assert [tr.born for tr in tracker.tracks] == [0.0, 0.75]
    near = movers.sight_lines(np.array([[40.0, 8.0], [100.0, 0.0]]), np.zeros((2, 2)),
                              np.deg2rad(10.0))
    assert near[0].tolist() == [1.0, 0.0, 1.0]              # the plain distance
    assert near[1, 2] < 1 and np.allclose(near[1, :2], (1, 0))   # wider across the line


# --- where a mover will pass ---------------------------------------------------------------

def test_a_settled_mover_sweeps_past_the_robot_and_down_its_lane():
    m = movers.Mover(np.array([100.0, 0.0]), np.array([-15.0, 0.0]), 5.0, settled=True)
    ways = movers.swept(m, np.array([0.0, 0.0]), 0.0, length=24, width=18)
    along, lane = ways
    assert np.allclose(along[0], (100, 0)) and np.allclose(along[1], (-48, 0))   # 2 lengths
    far = movers.Mover(np.array([400.0, 0.0]), np.array([-15.0, 0.0]), 5.0, settled=True)
    assert np.allclose(movers.swept(far, np.zeros(2), 0.0, 24, 18)[0][1],
                       (400 - 15 * movers.HORIZON, 0))          # no farther than it goes
    assert along[2] == movers.HALF_WIDTH                  # a sonar ring sees a cart's middle
    assert np.allclose(lane[1], (0, 0))                   # straight at the robot
    beside = movers.swept(m, np.array([0.0, 40.0]), 0.0, length=24, width=18)
    assert len(beside) == 1                               # not in the robot's lane


def test_a_mover_whose_heading_is_not_known_yet_sweeps_only_down_the_robots_lane():
    m = movers.Mover(np.array([200.0, 0.0]), np.array([-15.0, 0.0]), 5.0, settled=False)
    assert movers.swept(m, np.array([0.0, 40.0]), 0.0, length=24, width=18) == []
    (a, b, _), = movers.swept(m, np.array([0.0, 0.0]), 0.0, length=24, width=18)
    assert np.allclose(a, (200, 0)) and np.allclose(b, (0, 0))


def test_a_mover_whose_path_overlaps_the_robots_lane_comes_down_it():
    """The lane is where the robot's body goes (half its width each side of its line), and
    a mover's path is ``HALF_WIDTH`` wide each side at least: a cart 19 in off the line of
    a robot whose heading wavers (`moving+clutter5`, seed 0: -12 deg at 60 in) comes down
    it; one whose path clears the lane does not."""
    robot = np.array([0.0, 0.0])
    for off, inside in ((19.0, True), (-20.5, True), (21.5, False)):
        m = movers.Mover(np.array([60.0, off]), np.array([-15.0, 0.0]), 5.0, settled=False)
        assert bool(movers.lane(m, robot, 0.0, 18.0)) is inside, off
    wide = movers.Mover(np.array([60.0, 22.0]), np.array([-15.0, 0.0]), 14.0, settled=False)
    assert movers.lane(wide, robot, 0.0, 18.0)                 # 9 + 14 in: a wide one


def test_a_robot_keeps_right_of_what_comes_down_its_lane_with_room():
    shape, res, origin = (40, 120), 2.0, (-20.0, -40.0)
    m = movers.Mover(np.array([150.0, 0.0]), np.array([-15.0, 0.0]), 5.0, settled=True)
    sw = movers.sweep([m], np.array([0.0, 0.0]), 0.0, 24, 18, shape, res, origin, room=3.5,
                      far=40)
    assert sw is not None and sw.keep_right is not None and sw.wide == movers.HALF_WIDTH
    rows, cols = np.mgrid[0:shape[0], 0:shape[1]]
    y = origin[1] + (rows + 0.5) * res
    x = origin[0] + (cols + 0.5) * res
    between = (x > 20) & (x < 130)
    # the robot's left (y > 0 facing the cart at +x) is kept clear of, its right is not
    assert sw.keep_right[between & (y > movers.HALF_WIDTH + 4) & (y < 38)].all()
    assert not sw.keep_right[between & (y < -(movers.HALF_WIDTH + 3.5) - 2)].any()
    # and on its right, the ways are 3.5 in wider than in ``cells``
    edge = between & (y < -movers.HALF_WIDTH) & (y > -(movers.HALF_WIDTH + 3.5))
    assert edge.any() and (sw.keep_right & ~sw.cells)[edge].all()
    beside = movers.sweep([m], np.array([0.0, 60.0]), 0.0, 24, 18, shape, res, origin)
    assert beside is not None and beside.keep_right is None     # not in its lane


@pytest.mark.parametrize("y, squeeze", [(12.0, True), (2.0, False), (-12.0, False)])
def test_a_robot_squeezes_right_of_what_comes_down_its_lane_on_its_left(y, squeeze):
    """Where keeping right with room is not possible, a robot whose oncoming mover comes on
    its left squeezes past on its right (``Sweep.left``) rather than cross in front of it; one
    dead ahead or on its right may be passed on either side."""
    shape, res, origin = (40, 120), 2.0, (-20.0, -40.0)
    m = movers.Mover(np.array([100.0, y]), np.array([-30.0, 0.0]), 5.0, settled=False)
    sw = movers.sweep([m], np.array([0.0, 0.0]), 0.0, 24, 18, shape, res, origin, room=3.5)
    assert sw is not None and sw.keep_right is not None
    assert (sw.left is not None) == squeeze
    if squeeze:
        assert not (sw.left & ~sw.keep_right).any()         # keep_right without the room


@pytest.mark.parametrize("y, right", [(-12.0, True), (-2.0, False), (12.0, False)])
def test_what_comes_down_its_lane_on_its_right_gives_the_robots_right_side(y, right):
    """A mover down the robot's lane half a body width or more on its right gives
    ``Sweep.right``: the robot's right of the line to it, from ``HALF_WIDTH`` off it; one
    dead ahead or on its left gives none."""
    shape, res, origin = (40, 120), 2.0, (-20.0, -40.0)
    m = movers.Mover(np.array([100.0, y]), np.array([-30.0, 0.0]), 5.0, settled=False)
    sw = movers.sweep([m], np.array([0.0, 0.0]), 0.0, 24, 18, shape, res, origin, room=3.5)
    assert sw is not None and (sw.right is not None) == right
    if right:
        assert sw.right is not None and sw.left is None
        rows, cols = np.mgrid[0:shape[0], 0:shape[1]]
        yy = origin[1] + (rows + 0.5) * res
        xx = origin[0] + (cols + 0.5) * res
        off = (yy * 100.0 - xx * y) / math.hypot(100.0, y)      # left of the line to it
        between = (xx > 5) & (xx < 95)
        assert sw.right[between & (off < -movers.HALF_WIDTH - 2) & (off > -30)].all()
        assert not sw.right[off > -movers.HALF_WIDTH + 1].any()


def _squeeze_below(right: bool) -> tuple[knowledge.RobotMap, object, object]:
    """`moving`'s hall, the robot at (300, 3) heading along it, a cart 100 in ahead 11 in
    on its right (unsettled: its way is the lane, straight at the robot) and a box above
    the cart's way: the only way on is squeezed between the cart's way and the lower wall
    (25 in for a robot that needs 11 in each side). ``right``: the sweep with its
    ``Sweep.right`` (else without, as it was until night 17)."""
    world, rmap, route, (asked, least) = corridor_map()
    g = rmap.grid
    box = np.array([[x, y] for x in np.arange(392.0, 410.0, 1.0)
                    for y in np.arange(15.0, 33.0, 1.0)])
    rmap.mark_cells(rmap.cell_indices(box))
    p = np.array([300.0, 3.0])
    cart = movers.Mover(np.array([400.0, -8.0]), np.array([-15.0, 0.0]), 5.0, settled=False)
    sw = movers.sweep([cart], p, 0.0, 24, 18, rmap.occupied.shape, g.resolution, g.origin,
                      room=asked - least, far=150)
    assert sw is not None and sw.right is not None and sw.left is None
    if not right:
        sw = movers.Sweep(sw.cells, sw.wide, sw.keep_right, sw.left)
    new = knowledge.replan(rmap, route, 270, p, world.agents[0].goal, 1.0, asked, least, 150,
                           moving=sw)
    return rmap, new, world.agents[0].goal


def test_a_robot_does_not_squeeze_right_of_a_mover_coming_on_its_right():
    """Seed 0's `moving+clutter6` of the navigation benchmark: with the way above the cart
    shut by a box, the route squeezed below its echoes, across its way, and the robot
    turned into the cart's lane (hit at 18.7 s). A mover on the robot's right is not
    passed on the right without the room: it goes to a refuge."""
    rmap, new, goal = _squeeze_below(right=False)
    assert new is not None and rmap.refuge is None             # the squeeze, as it was
    assert math.dist(new.goal, (goal.x, goal.y)) < 1e-9
    assert min(float(new.point_at(u)[1]) for u in np.arange(0, 150, 3.0)) < -25
    rmap, new, goal = _squeeze_below(right=True)
    assert new is not None and rmap.refuge is not None         # a refuge instead
    assert math.dist(new.goal, (rmap.refuge.x, rmap.refuge.y)) < 1e-9


def test_two_robots_that_meet_do_not_swerve_across_each_others_way():
    """`multirobot` run 1006 of `--runs 100 --seed 1000`: the oncoming robot, unable to keep
    right of the other with room, planned its way across in front of it, and the two met
    (both collided at 10.95 s); it now squeezes past on its right and both arrive."""
    from mitos_cli.sim.worldfile import load_world

    world = load_world(Path(__file__).resolve().parents[1] / "worlds" / "multirobot.yaml")
    assert simulate(world, None, 1006, randomise=True).robot_outcomes == ("success", "success")


@settings(max_examples=60, deadline=None)
@given(ax=st.floats(-50, 150), ay=st.floats(-50, 150), bx=st.floats(-50, 150),
       by=st.floats(-50, 150), radius=st.floats(0.5, 40))
def test_capsule_cells_are_the_cells_whose_centres_lie_within_the_radius(ax, ay, bx, by, radius):
    shape, res, origin = (40, 50), 2.5, (-20.0, -10.0)
    a, b = np.array([ax, ay]), np.array([bx, by])
    got = movers.capsule_cells(shape, res, origin, a, b, radius)
    rows, cols = np.mgrid[0:shape[0], 0:shape[1]]
    p = np.stack([origin[0] + (cols + 0.5) * res, origin[1] + (rows + 0.5) * res], axis=-1)
    e = b - a
    t = np.clip(((p - a) @ e) / max(float(e @ e), 1e-300), 0, 1) if e @ e else np.zeros(shape)
    d = np.hypot(*(p - a - t[..., None] * e).transpose(2, 0, 1))
    near_edge = np.abs(d - radius) < 1e-9
    assert np.array_equal(got[~near_edge], (d <= radius)[~near_edge])


# --- a robot that waits --------------------------------------------------------------------

YIELD = (ROOT / "worlds" / "moving.yaml").read_text(encoding="utf-8")
assert "\nseed: 3\n" in YIELD, "moving.yaml's seed moved: the yield world is built from it"
YIELD = YIELD[:YIELD.index("\nobstacles:")].replace("\nseed: 3\n", "\nseed: 12\n") + """
obstacles:
  - {name: oncoming, shape: rectangle, at: [1000, -14], length: 22, width: 16,
     velocity: [-15, 0]}
  - {name: trolley, shape: rectangle, at: [742, 23], length: 30, width: 18}
"""


def test_where_a_cart_and_a_trolley_leave_no_way_past_the_robot_waits_for_the_cart():
    # the cart comes head-on in the robot's lane; beside the trolley the way left between
    # them is 20 in, for a robot 18 in wide and its 2 in margin on each side
    world = parse_world(YIELD, "yield.yaml")
    res = simulate(world)
    assert res.outcome == "success" and res.clearance[:, 0].min() > 0
    cart = [o.name for o in world.obstacles].index("oncoming")
    ahead = res.obstacles[:, cart, 0] > res.pose[:, 0, 0]          # before it went by
    # it stood (slower than 5 in/s) a second or more before the cart went by...
    stood = np.convolve((res.speed[:, 0] < 5) & ahead, np.ones(int(1.0 / world.dt)), "valid")
    assert stood.max() == int(1.0 / world.dt)
    # ...and stood aside: while the cart went by, the robot was left of the cart's lane
    by = np.abs(res.obstacles[:, cart, 0] - res.pose[:, 0, 0]) < 20
    assert by.any() and (res.pose[by, 0, 1] > 0).all()


# --- replanning round what moves -----------------------------------------------------------

CORRIDOR = YIELD[:YIELD.index("\nobstacles:")]


def corridor_map():
    world = parse_world(CORRIDOR, "c.yaml")
    scene = prepare(world)
    grid = knowledge.plan_grid(knowledge.given(world, scene.static), scene.static, world)
    return (world, knowledge.RobotMap.of(grid), scene.routes[0],
            clearances(world, world.agents[0]))


def across(rmap, x: float, y0: float, y1: float, radius: float = 12.0) -> movers.Sweep:
    g = rmap.grid
    cells = movers.capsule_cells(rmap.occupied.shape, g.resolution, g.origin,
                                 np.array([x, y0]), np.array([x, y1]), radius)
    return movers.Sweep(cells, radius)


def test_with_no_way_past_what_comes_it_goes_to_a_refuge_and_waits_there_till_it_passed():
    world, rmap, route, (asked, least) = corridor_map()
    goal, p = world.agents[0].goal, np.array([300.0, -10.0])
    shut = across(rmap, 400, -60, 60)                       # the whole corridor, ahead
    to_refuge = knowledge.replan(rmap, route, 270, p, goal, 1.0, asked, least, 150,
                                 moving=shut)
    assert to_refuge is not None and rmap.refuge is not None
    place = np.array([rmap.refuge.x, rmap.refuge.y])
    g = rmap.grid
    free = ~(rmap.occupied | shut.cells)
    room = Clearance.of(~free, g.resolution, g.origin, cap=asked + 10)
    assert room.at(place[None])[0] >= asked                 # out of everyone's way
    assert math.dist(to_refuge.goal, place) < 1e-9
    # while something still comes toward it, it stays, even where a way past opens
    half = across(rmap, 400, -60, -30)
    again = knowledge.replan(rmap, to_refuge, 0, p, goal, 2.0, asked, least, 150, moving=half)
    assert again is not None and math.dist(again.goal, place) < 1e-9
    # once nothing does, it goes on to its goal
    on = knowledge.replan(rmap, again, 0, p, goal, 3.0, asked, least, 150)
    assert on is not None and rmap.refuge is None
    assert math.dist(on.goal, (goal.x, goal.y)) < 1e-9


def test_a_robot_at_its_refuge_waits_while_a_mover_comes_whose_way_is_not_drawn():
    # a cart whose heading is not known yet sweeps only down the robot's lane; the robot
    # turned out of that lane for its refuge, and the cart still comes toward it
    world, rmap, route, (asked, least) = corridor_map()
    goal, p = world.agents[0].goal, np.array([300.0, -10.0])
    cart = movers.Mover(np.array([380.0, -14.0]), np.array([-15.0, 0.0]), 8.0, settled=False)
    turned = math.radians(60.0)
    assert movers.swept(cart, p, turned, 24, 18) == []
    args = (p, turned, 24, 18, rmap.occupied.shape, rmap.grid.resolution, rmap.grid.origin)
    assert movers.sweep([cart], *args) is None                # nothing it must keep clear of
    waiting = movers.sweep([cart], *args, waiting=True)
    assert waiting is not None and not waiting.cells.any()
    assert movers.sweep([], *args, waiting=True) is None      # nothing comes: it goes on
    to_refuge = knowledge.replan(rmap, route, 270, p, goal, 1.0, asked, least, 150,
                                 moving=across(rmap, 400, -60, 60))
    assert to_refuge is not None and rmap.refuge is not None
    place = (rmap.refuge.x, rmap.refuge.y)
    again = knowledge.replan(rmap, to_refuge, 0, p, goal, 2.0, asked, least, 150,
                             moving=waiting)
    assert again is not None and math.dist(again.goal, place) < 1e-9
    assert rmap.refuge is not None


def test_while_its_movers_sweep_nothing_it_keeps_the_refuge_it_holds():
    """A robot bound for its refuge, turned out of its lane, is swept at by nothing (the
    cart's heading not known yet) but still stands in the lane the cart was drawn down. The
    refuge it holds, better seen, keeps less room than asked (a box by it); it keeps it all
    the same, and is not sent to the nearest place out of nothing's way, where it stands
    (seed 0's `moving+clutter6`: 61 in from the cart)."""
    world, rmap, route, (asked, least) = corridor_map()
    goal, p = world.agents[0].goal, np.array([300.0, -10.0])
    g = rmap.grid
    lane = movers.capsule_cells(rmap.occupied.shape, g.resolution, g.origin,
                                np.array([420.0, -10.0]), p, 12.0)    # straight at it
    coming = movers.Sweep(lane | across(rmap, 420, -60, 60).cells, 12.0)
    to_refuge = knowledge.replan(rmap, route, 270, p, goal, 1.0, asked, least, 150,
                                 moving=coming)
    assert to_refuge is not None and rmap.refuge is not None
    held = np.array([rmap.refuge.x, rmap.refuge.y])
    rmap.mark_cells(rmap.cell_indices(held[None] + [[0.0, least + 2.5]]))   # a box by it
    room = Clearance.of(rmap.occupied, g.resolution, g.origin, cap=asked + 10)
    assert least <= room.at(held[None])[0] < asked
    q = p + (held - p) * 0.3                                 # on its way, still in the lane
    col, row = rmap.cell_indices(q[None])[0]
    assert coming.cells[row, col]
    nothing = movers.Sweep(np.zeros_like(coming.cells), 0.0)            # waiting, undrawn
    again = knowledge.replan(rmap, to_refuge, 0, q, goal, 2.0, asked, least, 150,
                             moving=nothing)
    assert again is not None and rmap.refuge is not None
    assert math.dist(again.goal, held) < 1e-9                # the refuge it held
    assert math.dist((rmap.refuge.x, rmap.refuge.y), held) < 1e-9


def test_a_robot_at_its_refuge_waits_till_a_cart_beside_it_has_passed():
    """A cart coming down the other lane is 60 deg or more off the robot's bearing as it
    draws level with the robot at its refuge: it has not passed, and the robot that turned
    round for its goal then would swing into its lane (`moving+clutter9` of the dev seed
    6000). Waiting, the robot waits for it till it has passed; driving, it is not in its
    way."""
    tracker = movers.Tracker()
    t = follow(tracker, (100, -40), (-15, 0), 2.0, moved=True)   # now at (70, -40)
    robot = np.array([40.0, 15.0])                               # 62 deg off its heading
    assert tracker.movers(t, robot, own=np.zeros(2)) == []
    assert len(tracker.movers(t, robot, own=np.zeros(2), waiting=True)) == 1
    assert tracker.movers(t, np.array([80.0, 15.0]), own=np.zeros(2), waiting=True) == []


def test_a_robot_is_at_its_refuge_within_its_tolerance_not_on_its_way_there():
    """It waits for what has not passed it only standing at its refuge: on its way there it
    yields to what comes toward it, as a robot driving does (`worlds/README.md`'s annotated
    world: a robot that waited so on its way to its refuge moved it four times in 1.6 s and
    met the other robot)."""
    _, rmap, _, _ = corridor_map()
    assert not rmap.at_refuge(np.array([300.0, -10.0]))              # it holds none
    rmap.refuge = Goal(300.0, 20.0)
    assert rmap.refuge.tolerance == 12.0                              # a goal's
    assert rmap.at_refuge(np.array([308.0, 28.0]))                    # 11.3 in off
    assert rmap.at_refuge(np.array([312.0, 20.0]))                    # 12 in: reached
    assert not rmap.at_refuge(np.array([312.5, 20.0]))
    assert not rmap.at_refuge(np.array([300.0, -10.0]))               # on its way


def moving_draw(seed: int, j: int):
    """`moving` with the navigation benchmark's clutter draw ``j`` of ``seed`` (as
    `bench_nav.py` builds it) and the base's scene."""
    from mitos_cli.resources import packaged_path
    from mitos_cli.sim.clutter import clutter
    from mitos_cli.sim.worldfile import load_world

    base = load_world(packaged_path("worlds", "moving.yaml"))
    scene = prepare(base)
    rng = np.random.default_rng(np.random.SeedSequence([seed, 3]).spawn(j + 1)[j])
    world = clutter(base, scene.static, scene.routes[0], rng, int(rng.integers(3, 7)))
    return world.with_changes(name=f"moving+clutter{j}", seed=base.seed + j), scene


def test_a_robot_at_its_refuge_waits_till_the_cart_beside_it_has_passed_then_arrives():
    """Dev seed 6000's `moving+clutter9`: the robot, sent up out of the cart's lane, stands
    at its refuge facing away from its goal while the cart comes down the lower lane, 42 in
    below it; 60 deg off its bearing the cart has not passed it, and a robot that turned
    round for its goal then swung into the cart's lane and was hit (24.9 s). Standing at its
    refuge it waits till the cart has passed it, and arrives."""
    from mitos_cli.sim.loop import Simulation
    from mitos_cli.sim.planner import FuzzyPlanner

    world, scene = moving_draw(6000, 9)
    sim = Simulation(world, FuzzyPlanner(None, world.behavior), world.seed, scene=scene)
    cart = next(o for o in world.obstacles if o.name == "oncoming")
    waited = left = None
    while not sim.done:
        sim.step()
        p, rmap = sim.pose[0, :2], sim._maps[0]
        x = cart.x + cart.motion.velocity[0] * sim.time          # where the cart is (true)
        if rmap.at_refuge(p) and x > p[0] + 12:                   # beside it, not passed
            waited = sim.time
        if waited is not None and left is None and rmap.refuge is None:
            left = (sim.time, x - p[0])
    assert waited is not None and left is not None
    assert left[1] < 0                          # it left its refuge once the cart had passed
    assert sim.outcome == "success"


def test_a_robot_standing_in_a_movers_way_is_sent_out_of_it():
    world, rmap, route, (asked, least) = corridor_map()
    goal, p = world.agents[0].goal, np.array([300.0, -10.0])
    g = rmap.grid
    lane = movers.capsule_cells(rmap.occupied.shape, g.resolution, g.origin,
                                np.array([420.0, -10.0]), p, 12.0)    # straight at it
    shut = across(rmap, 420, -60, 60)
    coming = movers.Sweep(lane | shut.cells, 12.0)
    col, row = rmap.cell_indices(p[None])[0]
    assert coming.cells[row, col]                           # it stands in the cart's way
    to_refuge = knowledge.replan(rmap, route, 270, p, goal, 1.0, asked, least, 150,
                                 moving=coming)
    assert to_refuge is not None and rmap.refuge is not None
    place = np.array([rmap.refuge.x, rmap.refuge.y])
    room = Clearance.of(rmap.occupied | coming.cells, g.resolution, g.origin, cap=asked + 10)
    assert room.at(place[None])[0] >= asked                 # out of the cart's way
    assert math.dist(place, p) > 12.0                       # which it was not, where it stood



def _state(tracker: movers.Tracker) -> list:
    """A tracker's tracks as bytes and values, to compare bit for bit."""
    return [(tr.times, np.array(tr.centres).tobytes(), tr.radius, tr.moved, tr.mover,
             None if tr.v is None else tr.v.tobytes(), None if tr.fit is None else tr.fit.tobytes(),
             tr.born) for tr in tracker.tracks]


def test_trackers_followed_together_follow_as_each_alone():
    """Trackers matched in one pass (distances and their order for all) keep the tracks
    each keeps alone, tick after tick: objects that move on, stand, come and go, lie
    equally far from two tracks, and none at all."""
    rng = np.random.default_rng(5)
    together = [movers.Tracker() for _ in range(12)]
    alone = [movers.Tracker() for _ in range(12)]
    places = rng.uniform(-60, 60, (12, 4, 2))
    speeds = rng.choice([0.0, 20.0, 40.0], (12, 4, 1)) * rng.normal(size=(12, 4, 2))
    robots = rng.uniform(-200, 200, (12, 2))
    for k in range(60):
        now = k * 0.05
        seen = []
        for j in range(12):
            some = rng.random(4) < 0.7 if j % 5 else np.zeros(4, dtype=bool)
            centres = places[j, some] + speeds[j, some] * now + rng.normal(0, 0.5, (int(some.sum()), 2))
            if k % 9 == 0 and len(centres) > 1:
                centres[1] = centres[0] + 3.0          # two objects as far from one track
            radii = rng.uniform(1, 30, len(centres))
            # seen from robots near and far: round gates, and gates wide across the line
            sight = movers.sight_lines(centres, robots[j], np.deg2rad(10.0))
            seen.append((centres, radii, [bool(m) if m < 2 else None
                                          for m in rng.integers(0, 3, len(centres))], sight))
        movers.follow_all(together, now, seen)
        for tracker, got in zip(alone, seen):
            tracker.follow(now, *got)
        assert [_state(t) for t in together] == [_state(t) for t in alone], k
    assert any(tr.mover for t in alone for tr in t.tracks)


def test_only_the_robots_due_a_replanning_check_plan_again():
    """:func:`.knowledge.checks_due` names the robots whose :func:`.knowledge.replan` may plan
    again: with a mover across the way, exactly those do."""
    world, rmap, route, (asked, least) = corridor_map()
    goal, p, t = world.agents[0].goal, np.array([300.0, -10.0]), 5.0
    maps = [knowledge.RobotMap.of(rmap.grid) for _ in range(6)]
    for m, last in zip(maps, (-math.inf, t - 3.0, t - 0.5, t - 0.49, t - 0.1, t)):
        m.checked_at = last
    due = knowledge.checks_due(maps, t)
    assert due == [0, 1, 2] and knowledge.checks_due(maps, t, "never") == []
    for i, m in enumerate(maps):
        new = knowledge.replan(m, route, 270, p, goal, t, asked, least, 150,
                               moving=across(m, 400, -60, 60))
        assert (new is not None) == (i in due)
