"""The tricycle: straight at 90, LEFT (counter-clockwise) below 90, exact arcs, limits."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mitos_cli.sim import kinematics
from mitos_cli.sim.world import Robot


def lim(**kw):
    return kinematics.Limits.of([Robot(**kw)])


def drive(steering: float, speed: float = 30.0, t: float = 1.0, **kw):
    limits = lim(max_steering_rate=1e9, acceleration=1e9, **kw)
    x, y, h = np.zeros(1), np.zeros(1), np.zeros(1)
    v, s = np.zeros(1), np.full(1, 90.0)
    for _ in range(int(round(t / 0.05))):
        x, y, h, v, s = kinematics.step(x, y, h, v, s, np.array([steering]), np.array([speed]),
                                        limits, 0.05, 4)
    return float(x[0]), float(y[0]), float(h[0])


def test_straight_ahead_at_90():
    x, y, h = drive(90.0)
    assert x == pytest.approx(30.0) and y == 0.0 and h == 0.0


def test_steering_below_90_turns_left():
    x, y, h = drive(70.0, t=0.5)
    assert h > 0 and y > 0          # counter-clockwise, toward +y


def test_steering_above_90_turns_right():
    x, y, h = drive(110.0, t=0.5)
    assert h < 0 and y < 0


def test_turn_rate_and_forward_speed_follow_the_paper():
    # delta = steering - 90; turn rate v sin(delta) / wheelbase; rear axle at v cos(delta)
    x, y, h = drive(60.0, speed=20.0, t=0.25, wheelbase=16.0)
    assert h == pytest.approx(20.0 * math.sin(math.radians(30)) / 16.0 * 0.25, rel=1e-12)


def test_a_full_circle_comes_back_exactly():
    # rear axle radius L / tan(delta); a full turn returns the pose (exact arcs)
    L, delta, v = 16.0, math.radians(30), 20.0
    period = 2 * math.pi / (v * math.sin(delta) / L)
    limits = lim(max_steering_rate=1e9, acceleration=1e9, wheelbase=L)
    steps = 1000
    x, y, h = np.zeros(1), np.zeros(1), np.zeros(1)
    v_, s = np.full(1, v), np.full(1, 60.0)
    for _ in range(steps):
        x, y, h, v_, s = kinematics.step(x, y, h, v_, s, s, v_, limits, period / steps, 1)
    assert abs(x[0]) < 1e-9 and abs(y[0]) < 1e-9 and abs(h[0]) < 1e-9


def test_steering_rate_and_acceleration_limits():
    limits = lim(max_steering_rate=100.0, acceleration=40.0)
    s, v = kinematics.limit_commands(np.array([90.0]), np.array([0.0]), np.array([30.0]),
                                     np.array([60.0]), limits, 0.1)
    assert s[0] == pytest.approx(80.0) and v[0] == pytest.approx(4.0)


def test_commands_are_clamped_to_the_robot():
    limits = lim(max_steering_rate=1e9, acceleration=1e9)
    s, v = kinematics.limit_commands(np.array([90.0]), np.array([0.0]), np.array([0.0]),
                                     np.array([99.0]), limits, 0.1)
    assert s[0] == 30.0 and v[0] == 60.0


@pytest.mark.parametrize("seed", range(5))
def test_along_is_step_at_its_ends_and_at_each_substep(seed):
    """:func:`kinematics.along` (where the contact check between ticks looks) has the robots
    where they start at 0, where :func:`kinematics.step` puts them at 1, and after k of its
    substeps where a tick of k substeps as long puts them."""
    rng = np.random.default_rng(seed)
    n = 6
    limits = kinematics.Limits.of([Robot()] * n)
    state = (rng.uniform(-100, 100, n), rng.uniform(-100, 100, n), rng.uniform(-3, 3, n),
             rng.uniform(-15, 60, n), rng.uniform(30, 150, n), rng.uniform(0, 180, n),
             rng.uniform(-30, 90, n))
    assert np.allclose(np.stack(kinematics.along(*state, limits, 0.05, 4, 0.0)),
                       np.stack(state[:3]), atol=1e-12)
    assert np.allclose(np.stack(kinematics.along(*state, limits, 0.05, 4, 1.0)),
                       np.stack(kinematics.step(*state, limits, 0.05, 4)[:3]), atol=1e-9)
    for k in (1, 2, 3):
        assert np.allclose(np.stack(kinematics.along(*state, limits, 0.05, 4, k / 4)),
                           np.stack(kinematics.step(*state, limits, 0.05 * k / 4, k)[:3]),
                           atol=1e-9)
    # between substeps it stays on the arc: a hundredth of a tick moves it a hundredth
    points = np.array([kinematics.along(*state, limits, 0.05, 4, f)[:2]
                       for f in np.linspace(0, 1, 101)])
    assert np.hypot(*np.diff(points, axis=0).transpose(1, 0, 2)).max() <= 60 * 0.05 / 100 + 1e-9


def test_holding_commands_leaves_those_within_the_limits_to_the_bit():
    """Only a number past a bound is replaced (`np.maximum(0.0, -0.0)` is -0.0, so a speed of
    0 of a robot with no reverse, `max_reverse: 0`, would have read -0), and the kinematics
    move from a held command as from the command itself."""
    limits = kinematics.Limits.of([Robot(max_reverse=0.0), Robot(steering_min=40.0)])
    bounds = kinematics.command_bounds(limits)
    command = np.array([[90.0, 0.0], [200.0, -0.0]])
    kinematics.hold_commands(command, bounds)
    assert command.tolist() == [[90.0, 0.0], [150.0, -0.0]]
    assert np.signbit(command[:, 1]).tolist() == [False, True]
    command = np.array([[-5.0, -30.0], [30.0, 900.0]])
    kinematics.hold_commands(command, bounds)
    assert command.tolist() == [[30.0, 0.0], [40.0, 60.0]]
    assert not np.signbit(command[0, 1])                    # backward, held to 0: not -0
    state = (np.zeros(2), np.zeros(2), np.zeros(2), np.array([5.0, 5.0]), np.full(2, 90.0))
    wild = np.array([[-5.0, -30.0], [30.0, 900.0]])
    assert np.array_equal(np.stack(kinematics.step(*state, wild[:, 0], wild[:, 1], limits,
                                                   0.05, 2)),
                          np.stack(kinematics.step(*state, command[:, 0], command[:, 1],
                                                   limits, 0.05, 2)))
