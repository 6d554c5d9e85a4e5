"""The robot's own safety (sim/safety.py): the sweep of its body along an arc, the brake, and
backing out of a pocket; and in a run: it stops short of a wall a policy drives it at."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mitos_cli.sim import barn, geometry, kinematics, safety
from mitos_cli.sim.world import Robot

ROBOT = Robot(wheelbase=16.0, length=24.0, width=18.0)
AT = (0.0, 0.0, 0.0)           # x, y (in), heading (rad): facing +x


def test_straight_on_the_body_meets_a_cell_ahead_after_the_gap():
    cell = np.array([[40.0, 0.0]])                      # 40 in ahead of the centre
    free = safety.free_travel(cell, 0.0, AT, ROBOT, 0.0, False, 60.0, 1.0)
    assert free == pytest.approx(40.0 - 12.0 - 1.0, abs=1.0)   # front at 12 in, one step back
    assert safety.free_travel(cell, 0.0, AT, ROBOT, 0.0, True, 60.0, 1.0) == 60.0  # behind: free
    assert safety.free_travel(np.zeros((0, 2)), 0.0, AT, ROBOT, 0.0, False, 30.0) == 30.0
    assert safety.free_travel(np.array([[5.0, 0.0]]), 0.0, AT, ROBOT, 0.0, False, 30.0) == 0.0


def test_a_turn_sweeps_a_corner_into_what_a_straight_band_misses():
    pole = np.array([[14.0, -12.0]])                    # right of the front corner, off the band
    assert safety.free_travel(pole, 0.0, AT, ROBOT, 0.0, False, 30.0) == 30.0
    right = safety.free_travel(pole, 0.0, AT, ROBOT, 60.0, False, 30.0)     # full lock right
    left = safety.free_travel(pole, 0.0, AT, ROBOT, -60.0, False, 30.0)
    assert right < 10.0 and left == 30.0


@pytest.mark.parametrize("delta", [-60.0, -20.0, 0.0, 35.0])
def test_the_sweep_follows_the_tricycles_arc_about_the_rear_axle(delta):
    """The pose after driving the rear axle ``u`` inches is the kinematics' own (a cell placed
    just ahead of that pose's front is met there, not before)."""
    from mitos_cli.sim import kinematics

    lim = kinematics.Limits.of([ROBOT])
    steering = np.array([90.0 + delta])
    v = 10.0 / math.cos(math.radians(delta))            # rear axle at 10 in/s
    x, y, h = kinematics.advance(np.zeros(1), np.zeros(1), np.zeros(1), np.array([v]), steering,
                                 lim, 2.0, 64)           # 20 in of the rear axle's path
    ahead = np.array([[x[0] + 12.5 * math.cos(h[0]), y[0] + 12.5 * math.sin(h[0])]])
    free = safety.free_travel(ahead, 0.0, AT, ROBOT, delta, False, 40.0, 0.5)
    assert 19.0 <= free <= 20.5


def test_the_brake_lets_the_robot_stop_within_the_free_travel():
    assert safety.brake(50.0, 40.0, 1.0) == pytest.approx(math.sqrt(2 * 40 * 49))
    assert safety.brake(0.5, 40.0, 1.0) == 0.0
    v = safety.brake(20.0, 40.0, 1.0)
    assert v * v / (2 * 40.0) == pytest.approx(19.0)    # its stopping distance is the gap


def body(cells, side=1.0, wheel=90.0):
    return safety.Body(ROBOT, AT, wheel, np.asarray(cells, float).reshape(-1, 2), 1.0, side)


def test_the_guard_brakes_and_after_its_patience_backs_out_toward_the_route():
    cfg = safety.Settings()
    wall = [[14.5, y] for y in np.arange(-20.0, 21.0, 2.0)]     # just ahead of the front
    rec = safety.Recovery()
    (steer, speed), backs = safety.guard((90.0, 30.0), body(wall), rec, 0.05, cfg)
    assert speed < cfg.want and not backs                         # braked, not yet backing
    ticks = 1
    while not backs:
        (steer, speed), backs = safety.guard((90.0, 30.0), body(wall), rec, 0.05, cfg)
        ticks += 1
    assert ticks * 0.05 == pytest.approx(cfg.patience, abs=0.051)
    assert speed == -ROBOT.max_reverse and steer == ROBOT.steering_min   # route right: wheel left
    (steer, speed), again = safety.guard((90.0, 30.0), body(wall), rec, 0.05, cfg)
    assert speed < 0 and steer == ROBOT.steering_min and not again      # it goes on backing


def test_no_backing_out_without_room_behind_or_without_a_reverse_gear():
    cfg = safety.Settings()
    boxed = [[x, y] for x in (-14.5, 14.5) for y in np.arange(-20.0, 21.0, 2.0)]
    rec = safety.Recovery()
    for _ in range(60):
        (_, speed), backs = safety.guard((90.0, 30.0), body(boxed), rec, 0.05, cfg)
        assert not backs and speed < cfg.want
    forward_only = Robot(wheelbase=16.0, length=24.0, width=18.0, max_reverse=0.0)
    b = safety.Body(forward_only, AT, 90.0, np.array([[14.5, 0.0]]), 1.0, 1.0)
    rec = safety.Recovery()
    assert not any(safety.guard((90.0, 30.0), b, rec, 0.05, cfg)[1] for _ in range(60))


def test_backing_away_from_a_cell_the_body_touches_is_not_blocked_by_it():
    """A mark a noisy echo puts at the body's front edge stops the robot driving on, not
    backing away from it (it pinned robots in BARN's pole fields)."""
    edge = np.array([[12.5, 0.0]])                      # on the front edge, inside by 0.5 in
    assert safety.free_travel(edge, 1.0, AT, ROBOT, 0.0, False, 30.0) == 0.0
    assert safety.free_travel(edge, 1.0, AT, ROBOT, 0.0, True, 30.0) == 30.0
    for delta in (-60.0, 60.0):                         # backing on either lock swings away too
        assert safety.free_travel(edge, 1.0, AT, ROBOT, delta, True, 30.0) > 5.0


def test_the_guard_backs_out_on_the_other_lock_when_that_is_the_only_room():
    """Route to the right: the left lock first, then straight; boxed in behind on both, it
    backs out on the right lock rather than stay where it is."""
    cfg = safety.Settings()
    wall = [[14.5, y] for y in np.arange(-20.0, 21.0, 2.0)]
    free = {w: [] for w in (ROBOT.steering_min, ROBOT.steering_straight, ROBOT.steering_max)}
    # a pole behind the right rear corner: backing on the left lock or straight meets it
    cells = wall + [[-17.0, -8.0]]
    b = body(cells)
    for wheel in free:
        free[wheel] = b.free(wheel, True, cfg)
    assert free[ROBOT.steering_min] < cfg.back_room and \
        free[ROBOT.steering_straight] < cfg.back_room <= free[ROBOT.steering_max]
    rec = safety.Recovery()
    backs, steer = False, 90.0
    for _ in range(40):
        (steer, _), backs = safety.guard((90.0, 30.0), b, rec, 0.05, cfg)
        if backs:
            break
    assert backs and steer == ROBOT.steering_max


def test_the_guard_backs_out_on_a_wheel_between_the_locks_when_only_that_has_room():
    """Boxed in behind on both locks and straight (a mark behind the left rear corner, one
    off the right), a wheel between them still has room: the robot backs out on the one
    nearest the lock toward its route rather than stand held for good (BARN's ``barn-1070``,
    seed 1000, wedged so where 75 deg had 50 in behind and the locks and straight 0-3 in)."""
    cfg = safety.Settings()
    wall = [[14.5, y] for y in np.arange(-20.0, 21.0, 2.0)]
    b = body(wall + [[-13.0, -10.0], [-16.0, 9.0]])
    locks = (ROBOT.steering_min, ROBOT.steering_straight, ROBOT.steering_max)
    assert all(b.free(w, True, cfg) < cfg.back_room for w in locks)
    assert b.free(45.0, True, cfg) >= cfg.back_room
    rec = safety.Recovery()
    backs, steer, speed = False, 90.0, 0.0
    for _ in range(40):
        (steer, speed), backs = safety.guard((90.0, 30.0), b, rec, 0.05, cfg)
        if backs:
            break
    assert backs and steer == 45.0 and speed == -ROBOT.max_reverse and rec.wheel == 45.0


def test_a_robot_that_drives_out_and_back_is_not_stuck():
    """Stuck is driven less than 3 in in 6 s, not displaced less: a robot that backs out of a
    pocket and comes round near where it was had not stopped."""
    from mitos_cli.resources import packaged_path
    from mitos_cli.sim import Simulation, load_world

    world = load_world(packaged_path("worlds", "corridor.yaml"))
    sim = Simulation(world, seed=1)
    x0, y0 = float(sim._x[0]), float(sim._y[0])
    one = np.zeros(1)
    window = int(round(6.0 / world.dt))
    for k in range(window + 5):                         # 10 in out and back, every 2 s
        u = 10.0 * abs(math.sin(math.pi * k * world.dt / 2.0))
        sim.move_to(np.array([x0 + u]), np.array([y0]), one, one, one + 90.0)
    assert not sim._check_stuck()
    for _ in range(window + 1):                         # then it stands
        sim.move_to(np.array([x0]), np.array([y0]), one, one, one + 90.0)
    assert sim._check_stuck() and sim._outcomes[0] == "stuck"


def test_a_robot_stops_short_of_a_wall_its_command_drives_it_at():
    from mitos_cli.resources import packaged_path
    from mitos_cli.sim import Simulation, load_world

    world = load_world(packaged_path("worlds", "corridor.yaml"))
    sim = Simulation(world, seed=1)
    while not sim.done and sim.time < 4.0:
        sim.step(np.array([[40.0, 60.0]]))               # hard left at full speed
    res = sim.result()
    assert res.outcome != "collision" and res.clearance.min() > 0.0


WALL_AHEAD = """
name: wall-ahead
dt: 0.05
time_limit: 30
substeps: 4
robot: {{model: tricycle, wheelbase: 16, footprint: {{length: 24, width: 18}}, max_speed: 60, acceleration: 40}}
sensors: {{layout: ring, count: 36, cone: 15, range: 150, noise: 0}}
q_init: {{x: 30, y: 0, heading: 0}}
q_goal: {{x: 120, y: 28, tolerance: 4}}
map:
  corridors:
    - points: [[0, 0], [{end}, 0]]
      width: 70
"""


@pytest.mark.parametrize("speed", [20.0, 30.0, 45.0, 60.0])
def test_a_robot_driven_straight_at_a_wall_stops_short_of_it(tmp_path, speed):
    """The brake counts the tick the robot drives on at what it was told before the next
    command (it touched the wall at 3.7 in/s from a constant 30 in/s when it did not), and
    looks as far as stopping from its top speed takes (the 30 in it looked let a robot at 60
    in/s within 15 in of a wall before it braked)."""
    from mitos_cli.sim import Simulation, load_world

    path = tmp_path / "wall.yaml"
    path.write_text(WALL_AHEAD.format(end=400))
    sim = Simulation(load_world(path), seed=1)
    while not sim.done and sim.time < 20.0:
        sim.step(np.array([[90.0, speed]]))
    res = sim.result()
    assert res.outcome != "collision" and res.clearance.min() > 0.0
    assert res.clearance.min() < 4.0, res.clearance.min()      # and it came near it


def test_the_brake_looks_as_far_as_stopping_takes_within_what_the_robot_sees():
    cfg = safety.Settings()
    assert safety.reach_of(Robot(), 0.05, cfg, 150.0) == 50.0      # 3 + 45 + 1 in, a step over
    assert safety.reach_of(Robot(max_speed=10.0), 0.05, cfg, 150.0) == cfg.reach
    slow = Robot(max_speed=200.0, acceleration=1.0)                # 20,000 in to stop
    assert safety.reach_of(slow, 0.05, cfg, 150.0) == 150.0
    stuck = Robot(acceleration=1e-320)                             # inf to stop: not a traceback
    assert safety.reach_of(stuck, 0.05, cfg, 150.0) == 150.0
    # so it goes no faster than it can stop within its sensors' range
    assert safety.brake(150.0, 1.0, cfg.margin, 0.05) < 18.0


def _beside(heading: float, across: float) -> np.ndarray:
    """A cell's centre beside the middle of a robot at the origin heading ``heading`` (rad),
    ``across`` inches to its right."""
    c, s = math.cos(heading), math.sin(heading)
    return np.array([[across * s, -across * c]])


def test_a_cell_is_the_square_it_is_its_corner_meets_a_slanting_flank():
    """A cell 1.2 half sides off the flank: clear of a flank along the grid, but at 45 deg its
    corner (0.41 half sides out of the disc it was once taken for) reaches into the body."""
    across = ROBOT.width / 2 + 1.2
    square = (0.0, 0.0, 0.0)
    slant = (0.0, 0.0, math.pi / 4)
    assert safety.free_travel(_beside(0.0, across), 1.0, square, ROBOT, 0.0, False, 30.0) == 30.0
    assert safety.free_travel(_beside(math.pi / 4, across), 1.0, slant, ROBOT, 0.0, False,
                              30.0) == 0.0
    bodies = [(safety.Body(ROBOT, pose, 90.0, _beside(pose[2], across), 1.0, 0.0, 30.0), 90.0,
               False) for pose in (square, slant)]
    assert safety.free_travels(bodies).tolist() == [30.0, 0.0]      # alone or together


def test_a_wheel_is_not_turned_toward_what_the_robot_can_no_longer_stop_short_of():
    """Driving at 40 in/s with its wheel at 120, told to turn hard right (150) toward a wall
    5 in off its right flank: the hard turn leaves less room than it needs to stop, the arc
    it is on leaves more, so the wheel stays; standing, it may turn."""
    cfg = safety.Settings()
    wall = [[x, -14.0] for x in np.arange(-20.0, 80.0, 2.0)]
    cells = np.asarray(wall, float)

    def at(speed: float) -> safety.Body:
        return safety.Body(ROBOT, AT, 120.0, cells, 1.0, 0.0, 40.0, speed)

    moving = at(40.0)
    turned = safety.brake(moving.free(129.0, False, cfg), ROBOT.acceleration, cfg.margin, 0.05)
    kept = safety.brake(moving.free(120.0, False, cfg), ROBOT.acceleration, cfg.margin, 0.05)
    assert turned < 40.0 - ROBOT.acceleration * 0.05 and kept > turned
    (steer, speed), _ = safety.guard((150.0, 40.0), moving, safety.Recovery(), 0.05, cfg)
    assert steer == 120.0 and speed == pytest.approx(min(40.0, kept))
    (steer, _), _ = safety.guard((150.0, 40.0), at(0.0), safety.Recovery(), 0.05, cfg)
    assert steer == 150.0


def test_a_robot_still_rolling_back_keeps_its_wheel_where_turning_it_swings_its_rear_in():
    """Rolling back at 20 in/s, its wheel at 120, with a pole just behind its rear right
    corner, the robot is told to go forward at full right lock (150: a backing-out has just
    ended). Braking, it rolls on back about 5 in, and the wheel turned on to 129 swings its
    rear into the pole; so the wheel stays at 120, whose arc passes it. Measured along the
    forward arc alone, as before, the wheel turned. Standing, or rolling forward, it turns."""
    cfg = safety.Settings()
    cells = np.array([[-14.0, -11.5]])

    def at(speed: float) -> safety.Body:
        return safety.Body(ROBOT, AT, 120.0, cells, 1.0, 0.0, 40.0, speed)

    rolling, a = at(-20.0), ROBOT.acceleration
    turned = safety.brake(rolling.free(129.0, True, cfg), a, cfg.margin, 0.05)
    kept = safety.brake(rolling.free(120.0, True, cfg), a, cfg.margin, 0.05)
    assert turned < 20.0 - a * 0.05 < kept
    assert rolling.free(129.0, False, cfg) == rolling.free(120.0, False, cfg) == 40.0
    (steer, speed), backs = safety.guard((150.0, 10.0), rolling, safety.Recovery(), 0.05, cfg)
    assert (steer, speed, backs) == (120.0, 10.0, False)
    for speed in (0.0, 20.0):
        (steer, _), _ = safety.guard((150.0, 10.0), at(speed), safety.Recovery(), 0.05, cfg)
        assert steer == 150.0


def test_a_robot_rolling_back_inside_its_margin_keeps_the_arc_with_more_room():
    """Within the brake's 1 in margin of a pole behind its rear right corner, rolling back
    at 8 in/s, told to go forward at full left lock: neither arc leaves room to stop (the
    brake allows 0 on both), but straight back leaves 1 in and the wheel turned left 0.79,
    so the wheel stays straight (a BARN field's robot turned it and touched the pole)."""
    cfg = safety.Settings()
    rolling = safety.Body(ROBOT, AT, 90.0, np.array([[-14.5, -9.5]]), 1.0, 0.0, 40.0, -8.0)
    turned, kept = rolling.free(81.0, True, cfg), rolling.free(90.0, True, cfg)
    assert turned < kept <= cfg.margin
    (steer, _), _ = safety.guard((30.0, 10.0), rolling, safety.Recovery(), 0.05, cfg)
    assert steer == 90.0


def _gap(pose: tuple[float, float, float], robot: Robot, pole: tuple[float, ...]) -> float:
    """The signed distance (in) from the robot's body at ``pose`` to the pole (centre x, y,
    half length, half width): minus the depth when they overlap."""
    px, py, hl, hw = pole
    body = geometry.rect_corners(pose[0] - px, pose[1] - py, pose[2], robot.length, robot.width)
    return float(geometry.box_polygon_distance(hl, hw, body[None])[0])


def test_a_robot_rolling_back_with_no_arc_free_keeps_its_wheel_off_the_pole_beside_it():
    """BARN's ``barn-4026`` (seed 4000, the poles unknown) in round numbers: a backing-out
    ends at 14 in/s where a noisy mark lies inside the robot's rear right corner, so every arc
    ahead and behind reads 0 free, and the planner asks forward at full left lock. Braking,
    the robot rolls on back 2.3 in; a wheel turned left as it rolls swings its nose right,
    and its front right corner into the pole 0.35 in below its flank, which it had sensed
    (its marks lie a cell below). Neither arc leaving room, the arc it is on is the one it
    keeps: the wheel turns only toward more room while the robot cannot stop. Standing, it
    turns."""
    cfg, robot = safety.Settings(), barn.JACKAL
    pole = (4.0, -11.925, 5.0, 3.075)                  # x -1 to 9, y -15 to -8.85
    cells = np.array([[x, -10.2] for x in np.arange(-2.0, 10.5, 2.0)] + [[-10.6, -7.9]])
    limits, rec = kinematics.Limits.of([robot]), safety.Recovery()
    x, y, h, v, wheel = 0.0, 0.0, 0.0, -14.0, 90.0
    start = safety.Body(robot, (x, y, h), wheel, cells, 1.0, 0.0, 50.0, v)
    assert all(start.free(w, back, cfg) == 0.0 for w in (30.0, 81.0, 90.0) for back in (True, False))
    assert _gap((x, y, h), robot, pole) == pytest.approx(0.35)
    least, ticks = math.inf, 0
    while v != 0.0:
        body = safety.Body(robot, (x, y, h), wheel, cells, 1.0, 0.0, 50.0, v)
        (steer, speed), backs = safety.guard((30.0, 20.0), body, rec, 0.05, cfg)
        assert speed == 0.0 and not backs
        if ticks == 0:
            assert steer == 90.0
        moved = kinematics.step(*(np.array([q]) for q in (x, y, h, v, wheel, steer, speed)),
                                limits, 0.05, 4)
        x, y, h, v, wheel = (float(q[0]) for q in moved)
        least, ticks = min(least, _gap((x, y, h), robot, pole)), ticks + 1
    assert ticks == 7 and x == pytest.approx(-2.35, abs=0.01)
    assert least > 0.2                    # the wheel turned on to the lock: -0.40 (a contact)
    standing = safety.Body(robot, (x, y, h), wheel, cells, 1.0, 0.0, 50.0, 0.0)
    (steer, _), _ = safety.guard((30.0, 20.0), standing, rec, 0.05, cfg)
    assert steer == 30.0


def _first_touch(cells, radius, pose, robot, delta, backward, reach, fine=0.002, deeper=0.0):
    """Where along the rear axle's path the footprint first touches a cell (reaches ``deeper``
    than ``deeper`` into one), found by placing it every ``fine`` inch (``math.inf``: nowhere
    within ``reach``): the brake's answer checked by brute force."""
    u = np.arange(0.0, reach, fine) * (-1.0 if backward else 1.0)
    wb = robot.wheelbase
    arc = safety.Arc(*(np.full((1, 1), v) for v in (
        pose[2], -math.tan(math.radians(delta)) / wb, pose[0] - wb / 2 * math.cos(pose[2]),
        pose[1] - wb / 2 * math.sin(pose[2]), math.sin(pose[2]), math.cos(pose[2]), wb / 2,
        abs(delta) > 1e-7)))
    c, s, cx, cy = arc.centres(u[None])
    depth = safety._depth(cells[:, :1] - cx, cells[:, 1:] - cy, c, s, robot.length / 2,
                          robot.width / 2, radius)
    touched = (depth >= deeper).any(axis=0)
    return abs(float(u[touched.argmax()])) if touched.any() else math.inf


def test_at_full_lock_the_sweep_misses_no_corner_between_two_places():
    """office02#1 among seed 1000's clutter: a Pioneer turning at full lock with 0.44 in to a
    wall's corner was told 12 in were free (the sweep placed its body a whole inch of the rear
    axle's path apart, and its front corner swung 3 in past the corner between two places)."""
    pioneer = Robot(wheelbase=12.0, length=17.5, width=15.0)
    pose = (416.92, 116.01, math.radians(-79.0))
    corner = np.array([[426.18110236, 107.28346457]])
    r = 1.968503937007874 / 2
    first = _first_touch(corner, r, pose, pioneer, 60.0, False, 30.0)
    assert first < 1.0
    assert safety.free_travel(corner, r, pose, pioneer, 60.0, False, 30.0) <= first


def test_the_sweep_never_reaches_past_where_the_body_first_touches_deeper_than_a_graze():
    """No touch deeper than 1/16 in passes between two places unseen (a shallower graze may:
    counting every pair that might graze stopped robots sliding past their map's cells)."""
    rng = np.random.default_rng(20261204)
    robot = Robot(wheelbase=12.0, length=17.5, width=15.0)
    tight = 0
    for _ in range(300):
        pose = (0.0, 0.0, float(rng.uniform(-math.pi, math.pi)))
        cells = rng.uniform(-25, 25, (int(rng.integers(1, 12)), 2))
        cells = cells[np.hypot(*cells.T) > 13.0]         # none the body touches at the start
        if not len(cells):
            continue
        delta = float(rng.choice([60.0, -60.0, rng.uniform(-60, 60)]))
        backward = bool(rng.random() < 0.2)
        free = safety.free_travel(cells, 1.0, pose, robot, delta, backward, 30.0)
        first = _first_touch(cells, 1.0, pose, robot, delta, backward, 30.0, deeper=1 / 16)
        assert free <= first, (pose, delta, backward)
        tight += first < math.inf and free >= first - 2.0
    assert tight > 20                # and not far short of it: within two places' travel


def test_backing_out_measures_the_arc_of_the_wheel_as_it_will_be_not_the_lock():
    """A backing-out on the right lock with the wheel still straight: the next tick drives the
    arc of the wheel 9 deg off straight, which meets a cell behind and to the right after 1.6
    in; the lock's arc would leave 4.9 in. Measured on the lock, field 1076 of BARN's seed
    1000 backed into a pole at 12 in/s."""
    cell = np.array([[-15.0, -8.0]])
    body = safety.Body(ROBOT, AT, 90.0, cell, 1.0, 0.0, 30.0)
    rec = safety.Recovery(left=1.0, wheel=150.0)
    (steer, speed), _ = safety.guard((90.0, 20.0), body, rec, 0.05)
    after = safety.free_travel(cell, 1.0, AT, ROBOT, 9.0, True, 30.0)
    assert steer == 150.0 and speed == -safety.brake(after, ROBOT.acceleration, 1.0, 0.05)
    assert safety.first_sweep((90.0, 20.0), body, safety.Recovery(left=1.0, wheel=150.0),
                              0.05) == (99.0, True)


def test_a_backing_out_waits_for_its_wheel_where_the_arcs_on_the_way_are_shut():
    """Nose in at full left lock, backing out on the right lock: the arcs the wheel passes on
    its way over are shut behind, the lock's is not; the robot waits for the wheel instead of
    giving the backing-out up (three of 1,000 `slalom` runs were stuck so)."""
    cell = np.array([[-15.0, -8.0]])
    body = safety.Body(ROBOT, AT, 30.0, cell, 1.0, 0.0, 30.0)
    rec = safety.Recovery(left=1.0, wheel=150.0)
    on_the_way = safety.free_travel(cell, 1.0, AT, ROBOT, -51.0, True, 30.0)
    assert on_the_way <= 1.0 < safety.free_travel(cell, 1.0, AT, ROBOT, 60.0, True, 30.0)
    (steer, speed), _ = safety.guard((90.0, 20.0), body, rec, 0.05)
    assert (steer, speed) == (150.0, 0.0) and rec.left > 0


def test_the_coarse_pass_leaves_out_no_cell_that_comes_within_a_step_of_the_body():
    """:func:`safety._near` looks at every ``COARSE``-th place only; a cell it leaves out must
    be below ``-step`` at every place (never touched, nor a pair of places :func:`_between`
    looks between), and a cell it keeps at every place outside its window, on sweeps of every
    size and curvature (a small robot at full lock with a long step has no bound), with cells
    strewn about the footprint at every place."""
    rng = np.random.default_rng(20261205)
    left_out, gaps, windows = 0, [], []
    for _ in range(300):
        wb = float(rng.choice([4.0, rng.uniform(8, 40)]))
        robot = Robot(wheelbase=wb, length=wb * rng.uniform(1.0, 2.0), width=wb * rng.uniform(0.5, 1.5))
        radius, step = float(rng.uniform(0.2, 2.0)), float(rng.choice([0.25, 1.0, 2.0]))
        delta = float(rng.choice([60.0, -60.0, 0.0, rng.uniform(-60, 60)]))
        h, k, a, b, sin_h, cos_h, half, hl, hw, _, du = safety._sweep_of(
            (0.0, 0.0, float(rng.uniform(-math.pi, math.pi))), robot, delta, radius, step)
        u = safety._path(30.0, du, bool(rng.random() < 0.3))[None]
        arc = safety.Arc(*(np.full((1, 1), v) for v in (h, k, a, b, sin_h, cos_h, half,
                                                         abs(k) > 1e-9)))
        c, s, cx, cy = arc.centres(u)
        at = rng.integers(0, u.shape[1], 300)
        spread = hl + hw + 2 * radius + 6 * step
        px = cx[0, at, None] + rng.uniform(-spread, spread, (300, 1))
        py = cy[0, at, None] + rng.uniform(-spread, spread, (300, 1))
        reach = safety._depth(px - cx, py - cy, c, s, hl, hw, radius).max(axis=1)   # every place
        places = (c, s, cx, cy, *safety._room(c, s, hl, hw, radius))
        bound = safety._bound(*(np.full((1, 1), v) for v in (k, du, hl, hw, half, radius)), step)
        near, _, lo, hi = safety._near(px, py, np.zeros(300, dtype=np.intp), places, bound[:, 0],
                               np.array([u[0, -1] < 0]))
        assert not np.count_nonzero(~near & (reach >= -step))
        # each cell kept is below -step at every place outside its window
        depth = safety._depth(px - cx, py - cy, c, s, hl, hw, radius)         # [300, K]
        place = np.arange(u.shape[1])
        outside = (place < lo[:, None]) | (place > hi[:, None])
        assert not np.count_nonzero(outside[near] & (depth[near] >= -step))
        windows.append(float(np.mean(hi[near] - lo[near] + 1)) / u.shape[1])
        left_out += np.count_nonzero(~near)
        gaps += list(-step - reach[~near])
    assert left_out > 20_000 and min(gaps) < 1.0      # it leaves out many, some near the edge
    assert np.mean(windows) < 0.8                     # and the windows leave out places


def test_sweeps_measured_a_few_cells_at_a_time_get_the_bits_they_get_at_once(monkeypatch):
    """:func:`safety.free_travels` works out ``CHUNK`` elements at a time; a chunk of a cell
    or two (a sweep's cells split among chunks) gives each sweep what it gets alone."""
    rng = np.random.default_rng(7)
    sweeps = []
    for _ in range(12):
        pose = (float(rng.uniform(-5, 5)), float(rng.uniform(-5, 5)), float(rng.uniform(-4, 4)))
        cells = rng.uniform(-50, 50, (int(rng.choice([0, 5, 60])), 2))
        cells = cells[np.hypot(cells[:, 0] - pose[0], cells[:, 1] - pose[1]) > 16.0]
        body = safety.Body(ROBOT, pose, 90.0, cells, 1.0, 0.0, 30.0)
        sweeps.append((body, float(rng.choice([90.0, 30.0, 150.0, rng.uniform(30, 150)])),
                       bool(rng.random() < 0.3)))
    alone = [body.free(wheel, backward, safety.Settings()) for body, wheel, backward in sweeps]
    assert safety.free_travels(sweeps).tolist() == alone
    monkeypatch.setattr(safety, "CHUNK", 50)
    assert safety.free_travels(sweeps).tolist() == alone
    assert 30.0 in alone and len(set(alone)) > 3


def test_the_guard_given_its_first_sweep_measured_carries_out_what_it_does_alone():
    """:func:`safety.guard` with :func:`safety.first_sweep`'s sweep measured (``known``, as
    runs in lockstep measure theirs together) gives the command, the backing-out and the
    recovery state it gives measuring every sweep itself: driving, held, backing out, and a
    backing-out at its lock with the way behind shut, which hands back to the planner."""
    rng = np.random.default_rng(11)
    cases = 0
    for _ in range(400):
        cells = rng.uniform(-40, 40, (int(rng.integers(0, 80)), 2))
        cells = cells[np.hypot(cells[:, 0], cells[:, 1]) > 15.0]
        if rng.random() < 0.5:                                     # close behind it
            cells = np.vstack([cells, [rng.uniform(-17, -13), rng.uniform(-10, 10)]])
        lock = float(rng.choice([30.0, 150.0]))
        wheel = float(rng.choice([lock, rng.uniform(30, 150)]))
        body = safety.Body(ROBOT, AT, wheel, cells, 1.0, float(rng.uniform(-1, 1)), 30.0,
                           float(rng.uniform(-10, 40)))
        state = dict(held=float(rng.choice([0.0, 0.98])),
                     left=float(rng.choice([0.0, 0.0, 1.0])), wheel=lock)
        command = (float(rng.uniform(20, 160)), float(rng.uniform(-20, 60)))
        alone, together = safety.Recovery(**state), safety.Recovery(**state)
        first = safety.first_sweep(command, body, together, 0.05)
        known = (*first, body.free(*first, safety.Settings()))
        assert (safety.guard(command, body, alone, 0.05)
                == safety.guard(command, body, together, 0.05, known=known))
        assert alone == together
        cases += state["left"] > 0 and wheel == lock and alone.left == 0
    assert cases >= 10                # backing-outs handed back at their lock, the way shut


def _fleet_case(rng: np.random.Generator, n: int):
    """``n`` robots of their own shapes and limits (one with no reverse gear, now and then),
    scattered among cells, some close behind or ahead, with their commands, wheels, speeds and
    recovery states (held near its patience, backing out at a lock, at rest)."""
    robots = [Robot(wheelbase=float(rng.uniform(10, 20)), length=float(rng.uniform(18, 30)),
                    width=float(rng.uniform(12, 20)), steering_min=float(rng.choice([30, 45])),
                    steering_max=float(rng.choice([135, 150])),
                    max_steering_rate=float(rng.choice([90, 180])),
                    acceleration=float(rng.uniform(20, 60)),
                    max_reverse=float(rng.choice([15.0, 15.0, 0.0]))) for _ in range(n)]
    fleet = safety.Fleet(robots, rng.choice([0.5, 1.0], n).tolist(),
                         rng.choice([30.0, 40.0], n).tolist(), 0.05)
    x, y, h = rng.uniform(-200, 200, n), rng.uniform(-200, 200, n), rng.uniform(-4, 4, n)
    cells = []
    for j in range(n):
        own = rng.uniform(-45, 45, (int(rng.choice([0, 20, 90])), 2))
        own = own[np.hypot(own[:, 0], own[:, 1]) > 15.0]
        if rng.random() < 0.4:                                     # close behind it
            own = np.vstack([own, [rng.uniform(-19, -13), rng.uniform(-10, 10)]])
        if rng.random() < 0.5:                                     # just ahead of its front
            front = robots[j].length / 2
            own = np.vstack([own, [rng.uniform(front + 1, front + 3), rng.uniform(-5, 5)]])
        c, s = math.cos(h[j]), math.sin(h[j])
        cells.append(np.column_stack([x[j] + own[:, 0] * c - own[:, 1] * s,
                                      y[j] + own[:, 0] * s + own[:, 1] * c]))
    lock = np.where(rng.random(n) < 0.5, fleet.lo, fleet.hi)
    wheel = np.where(rng.random(n) < 0.3, lock, rng.uniform(30, 150, n))
    now = (x, y, h, wheel, rng.uniform(-20, 50, n), rng.uniform(-1, 1, n))
    state = np.column_stack([rng.choice([0.0, 0.5, 0.98], n), rng.choice([0.0, 0.0, 1.0], n),
                             lock])
    command = np.column_stack([rng.uniform(20, 160, n), rng.uniform(-20, 60, n)])
    return fleet, now, cells, state, command


def test_a_fleet_guarded_at_once_carries_out_what_each_robot_does_alone():
    """:meth:`safety.Fleet.guard` (most robots decided with arrays, the rest by
    :func:`safety.guard` with their first sweep known) gives every robot the command, the
    backing-out and the recovery state :func:`safety.guard` gives it alone, to the bit; the
    robots that do not brake, or are not among the rows, are left as they were."""
    rng = np.random.default_rng(5)
    kinds = {"eased": 0, "kept": 0, "rolled": 0, "held": 0, "backs": 0, "backing": 0}
    for _ in range(100):
        n = int(rng.integers(1, 12))
        fleet, now, cells, state, command = _fleet_case(rng, n)
        rows = np.flatnonzero(rng.random(n) < 0.8)
        want_command, want_state, want_backs = command.copy(), state.copy(), []
        for i in rows.tolist():
            x, y, h, wheel, speed, side = (float(v[i]) for v in now)
            body = safety.Body(fleet.robots[i], (x, y, h), wheel, cells[i], float(fleet.radius[i]),
                               side, float(fleet.reach[i]), speed)
            rec = safety.Recovery(*state[i].tolist())
            carried, backs = safety.guard(tuple(command[i].tolist()), body, rec, 0.05)
            want_command[i], want_state[i] = carried, (rec.held, rec.left, rec.wheel)
            want_backs += [i] if backs else []
            kinds["eased"] += carried[1] != command[i, 1]
            kept = carried[0] == wheel != command[i, 0] and not state[i, 1] > 0
            kinds["kept"] += kept
            kinds["rolled"] += kept and (speed < 0) != (command[i, 1] < 0)   # against it
            kinds["held"] += rec.held > state[i, 0]
            kinds["backs"] += int(backs)
            kinds["backing"] += state[i, 1] > 0
        got = fleet.guard(rows, command, state, now, [cells[i] for i in rows.tolist()])
        assert got == want_backs
        assert command.tobytes() == want_command.tobytes()
        assert state.tobytes() == want_state.tobytes()
    assert min(kinds.values()) >= 10, kinds


def test_a_fleets_sweeps_measured_together_are_each_robots_alone():
    """:meth:`safety.Fleet.free` (each sweep's numbers worked out for all at once) gives
    every sweep the bits :meth:`safety.Body.free` gives it alone, forward and backward."""
    rng = np.random.default_rng(6)
    for _ in range(30):
        n = int(rng.integers(2, 12))
        fleet, (x, y, h, wheel, speed, side), cells, _, _ = _fleet_case(rng, n)
        back = rng.random(n) < 0.3
        rows = np.arange(n)
        alone = [safety.Body(fleet.robots[i], (x[i], y[i], h[i]), 90.0, cells[i],
                             float(fleet.radius[i]), 0.0, float(fleet.reach[i]))
                 .free(float(wheel[i]), bool(back[i]), fleet.cfg) for i in rows]
        assert fleet.free(rows, x, y, h, wheel, back, cells).tolist() == alone


def test_fleets_joined_are_the_fleet_of_all_their_robots():
    """:meth:`safety.Fleet.joined` (the rows joined, as a batch joins its runs') holds every
    array the fleet of all the robots works out, to the bit."""
    rng = np.random.default_rng(7)
    parts = [_fleet_case(rng, int(n))[0] for n in (1, 3, 2)]
    joined = safety.Fleet.joined(parts)
    whole = safety.Fleet([r for f in parts for r in f.robots],
                         np.concatenate([f.radius for f in parts]).tolist(),
                         np.concatenate([f.reach for f in parts]).tolist(), 0.05)
    assert joined.robots == whole.robots and (joined.dt, joined.cfg) == (whole.dt, whole.cfg)
    names = [k for k, v in vars(whole).items() if isinstance(v, np.ndarray)]
    assert sorted(names) == sorted(safety._FLEET_ROWS)
    for name in names:
        assert getattr(joined, name).tobytes() == getattr(whole, name).tobytes(), name


def test_the_brake_of_one_robot_is_a_python_float():
    """:func:`safety.brake` of floats is a float (the fleet's arrays have their own)."""
    limit = safety.brake(30.0, 40.0, 2.0, 0.05)
    assert type(limit) is float and limit == safety._brakes(np.array([30.0]), np.array([40.0]),
                                                             2.0, 0.05)[0]


@pytest.mark.parametrize("chunk", [8192, 60])
def test_sweeps_measured_only_up_to_their_first_sure_touch_get_the_bits_they_get_alone(
        chunk, monkeypatch):
    """:func:`safety._travels` looks at each sweep's places only up to the first where the
    coarse pass finds a cell touched for sure (:func:`safety._near`); every sweep still gets
    what it gets alone, among walls close ahead, cells the body touches at the start (backing
    away from them) and no cell in reach, its places split among chunks or not; each cell is
    looked at in its window of places alone (:func:`safety._near`)."""
    monkeypatch.setattr(safety, "CHUNK", chunk)
    rng = np.random.default_rng(14)
    trimmed = []
    touches = safety._touches

    def spy(px, py, owner, places, back, step, lo, hi):
        trimmed.append(int(np.count_nonzero(hi - lo + 1 < places[0].shape[1])))
        return touches(px, py, owner, places, back, step, lo, hi)

    monkeypatch.setattr(safety, "_touches", spy)
    for _ in range(40):
        sweeps = []
        for _ in range(int(rng.integers(2, 10))):
            pose = (float(rng.uniform(-5, 5)), float(rng.uniform(-5, 5)),
                    float(rng.uniform(-4, 4)))
            cells = rng.uniform(-45, 45, (int(rng.choice([0, 3, 40, 120])), 2))
            if rng.random() < 0.3:                   # one under its body at the start
                cells = np.vstack([cells, np.array(pose[:2]) + rng.uniform(-10, 10, 2)])
            body = safety.Body(ROBOT, pose, 90.0, cells, float(rng.choice([0.5, 1.0])), 0.0,
                               float(rng.choice([30.0, 50.0])))
            sweeps.append((body, float(rng.choice([90.0, 30.0, 150.0, rng.uniform(30, 150)])),
                           bool(rng.random() < 0.4)))
        alone = [body.free(wheel, backward, safety.Settings()) for body, wheel, backward in sweeps]
        assert safety.free_travels(sweeps).tolist() == alone
    assert sum(trimmed) > 100                          # many sweeps were cut short


def test_a_sweep_of_no_place_among_others_keeps_its_reach():
    """A reach below 0 among sweeps measured together (no place to sweep, or one) gives what
    it gave before the sweeps were cut at their first sure touch (the first version of the cut raised); the
    others' are measured as ever."""
    cells = np.array([[10.0, 0.0], [3.0, 1.0]])
    for reach, before in ((-0.999, 0.0), (-1.0, -1.0), (-2.5, -2.5)):
        sweeps = [(safety.Body(ROBOT, AT, 90.0, cells, 1.0, 0.0, reach), 90.0, False),
                  (safety.Body(ROBOT, AT, 90.0, cells, 1.0, 0.0, 30.0), 90.0, False)]
        with np.errstate(all="ignore"):
            got = safety.free_travels(sweeps)
        assert got[1] == safety.free_travels(sweeps[1:])[0]
        assert got[0] == before


def test_a_fleet_asking_its_maps_round_each_sweeps_box_carries_out_what_it_does_with_its_squares():
    """:meth:`safety.Fleet.guard` given the robots' maps (:data:`safety.Near`: the first
    sweeps' cells asked round each sweep's box, the robot's square where the box reaches out
    of it, as :func:`.knowledge.near_all` asks them) gives the commands, recovery states and
    backings-out it gives with every robot's whole square of cells, to the bit: on maps of
    strewn cells and walls, robots near the map's edge and sweeps whose box leaves the
    square (long reaches at full lock)."""
    from mitos_cli.sim import knowledge
    from mitos_cli.sim.world import Grid

    rng = np.random.default_rng(8)
    boxes = {"inside": 0, "outside": 0}
    for _ in range(60):
        n = int(rng.integers(1, 10))
        fleet, now, _, state, command = _fleet_case(rng, n)
        fleet.reach[:] = rng.choice([30.0, 40.0, 150.0], n)       # (150: its box leaves it)
        fleet.squares[:] = fleet.reach + [math.hypot(r.length, r.width) for r in fleet.robots]
        res = float(rng.choice([1.0, 2.0, 2.5]))
        occupied = rng.random((220, 230)) < rng.choice([0.02, 0.1])
        occupied[:, int(rng.integers(0, 230))] = True                          # a wall
        grid = Grid(occupied, res, (-230.0 * res / 2, -220.0 * res / 2), "")
        maps = [knowledge.RobotMap.of(grid) for _ in range(n)]
        rows = np.flatnonzero(rng.random(n) < 0.8)

        def near(j, points, half, rows=rows, maps=maps):
            inside = half < fleet.squares[rows[j]]
            boxes["inside"] += int(np.count_nonzero(inside))
            boxes["outside"] += int(np.count_nonzero(~inside))
            return knowledge.near_all([maps[i] for i in rows[j].tolist()], points, half)

        squares = knowledge.near_all([maps[i] for i in rows.tolist()],
                                     np.column_stack([now[0], now[1]])[rows],
                                     fleet.squares[rows]) if len(rows) else []
        want_command, want_state = command.copy(), state.copy()
        want = fleet.guard(rows, want_command, want_state, now, squares)
        assert fleet.guard(rows, command, state, now, near) == want
        assert command.tobytes() == want_command.tobytes()
        assert state.tobytes() == want_state.tobytes()
    assert boxes["inside"] > 100 and boxes["outside"] > 20, boxes


SLANT_WALL = """
name: slant-wall
dt: 0.05
time_limit: 30
substeps: 4
robot: {{model: tricycle, wheelbase: 13, footprint: {{length: 20, width: 17}}, max_speed: 60,
        acceleration: 40, max_reverse: 15}}
sensors: {{layout: ring, count: 36, cone: 15, range: 150, noise: 0}}
q_init: {{x: 200, y: 20, heading: {heading}}}
q_goal: {{x: 380, y: 0, tolerance: 4}}
map:
  corridors:
    - points: [[0, 0], [400, 0]]
      width: {width}
"""


@pytest.mark.parametrize("speed", [15.0, 30.0, -15.0])
def test_a_robot_driven_aslant_at_a_wall_inside_a_free_cell_of_its_map_stops_short_of_it(
        tmp_path, speed):
    """A map drawn from walls frees each cell whose centre lies inside: here the wall
    (y = 35.58, a corridor 71.16 in wide) runs 1.16 in into the free row that reaches to
    36.42, so the map shows it 0.84 in too far. The brake keeps its 1 in margin along the
    arc, which at 17 deg is 0.3 in across it: a robot driving (or backing, as BARN's robots
    at the end of a backing-out) aslant at the wall touched it. It now also counts squares
    flush with the walls it is given (:func:`.knowledge.wall_faces`)."""
    from mitos_cli.sim import Simulation, load_world
    from mitos_cli.sim.knowledge import RASTER

    path = tmp_path / "slant.yaml"
    path.write_text(SLANT_WALL.format(heading=17.0 if speed > 0 else -17.0, width=71.16))
    sim = Simulation(load_world(path), seed=1)
    grid = sim._maps[0].grid
    top = 71.16 / 2
    row = math.floor((top - grid.origin[1]) / RASTER)
    centre = grid.origin[1] + (row + 0.5) * RASTER
    assert centre < top and not grid.occupied[row, 30:-30].any()      # the wall's row: free
    while not sim.done and sim.time < 6.0:
        sim.step(np.array([[90.0, speed]]))
    res = sim.result()
    assert res.outcome != "collision" and res.clearance.min() > 0.0, res.clearance.min()
    assert res.clearance.min() < 3.0                      # and it came near it
    faces = sim._maps[0].faces                            # a square flush with the wall
    flush = faces[np.abs(faces[:, 1] - (top + RASTER / 2)) < 1e-9]
    assert len(flush) and flush[:, 0].min() < 200.0 < flush[:, 0].max()
