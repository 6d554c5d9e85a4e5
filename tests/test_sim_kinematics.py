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
