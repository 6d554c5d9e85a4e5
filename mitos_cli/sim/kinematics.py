"""The paper's tricycle: one front wheel that steers and drives, two rear wheels.

With ``delta = steering - 90`` (deg) and drive speed ``v`` of the front wheel, the rear axle
moves forward at ``v cos(delta)`` and the robot turns at ``v sin(delta) / wheelbase``, to the
LEFT (counter-clockwise, positive yaw rate) when ``steering < 90``. The pose is the footprint
centre, half a wheelbase ahead of the rear axle. All functions work on arrays of robots.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from collections.abc import Sequence

    from .world import Robot

#: What :func:`step` moves from, ``[n]`` each: x, y, heading, speed, steering, and the
#: commanded steering and speed.
Motion = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
               np.ndarray]


@dataclass(frozen=True)
class Limits:
    """Per-robot limits as arrays ``[n]`` (inches, seconds, degrees)."""

    wheelbase: np.ndarray
    steering_min: np.ndarray
    steering_max: np.ndarray
    straight: np.ndarray
    max_rate: np.ndarray           # deg/s
    max_speed: np.ndarray          # in/s
    acceleration: np.ndarray       # in/s^2
    max_reverse: np.ndarray        # in/s, backward

    @classmethod
    def of(cls, robots: Sequence[Robot]) -> Limits:
        def col(attr: str) -> np.ndarray:
            return np.array([getattr(r, attr) for r in robots], dtype=float)

        return cls(col("wheelbase"), col("steering_min"), col("steering_max"),
                   col("steering_straight"), col("max_steering_rate"), col("max_speed"),
                   col("acceleration"), col("max_reverse"))


@dataclass(frozen=True)
class _Ramp:
    """What :func:`step` derives from the limits alone, ``[substeps, n]`` or ``[n]``: how far
    the wheel and the speed may have moved after each substep (up and down), the top speed
    backward (negative), half the wheelbase and the wheelbase negated (``-v sin(delta) / wb``
    is ``v sin(delta) / -wb`` to the bit, one call fewer)."""

    steer_up: np.ndarray
    steer_down: np.ndarray
    speed_up: np.ndarray
    speed_down: np.ndarray
    reverse: np.ndarray
    half: np.ndarray
    back_wheelbase: np.ndarray


_RAMPS: dict[int, tuple[Limits, float, int, _Ramp]] = {}


def _ramp(lim: Limits, dt: float, substeps: int) -> _Ramp:
    """:class:`_Ramp` of ``lim``, kept for the last few limits (a run's do not change)."""
    kept = _RAMPS.get(id(lim))
    if kept is not None and kept[0] is lim and kept[1] == dt and kept[2] == substeps:
        return kept[3]
    sdt = dt / substeps
    k = np.arange(1, substeps + 1, dtype=float)[:, None]
    d_steer = k * (lim.max_rate * sdt)
    d_speed = k * (lim.acceleration * sdt)
    ramp = _Ramp(d_steer, -d_steer, d_speed, -d_speed, -lim.max_reverse, lim.wheelbase / 2.0,
                 -lim.wheelbase)
    if len(_RAMPS) >= 16:
        del _RAMPS[next(iter(_RAMPS))]
    _RAMPS[id(lim)] = (lim, dt, substeps, ramp)
    return ramp


def _clip(x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    return np.minimum(np.maximum(x, lo), hi)


def command_bounds(lim: Limits) -> tuple[np.ndarray, np.ndarray]:
    """The least and the greatest command each robot's drive takes, ``[n, 2]`` each
    (steering deg, speed in/s): its steering lock, and its top speeds backward and forward.
    :func:`step` turns the wheel and drives toward a command held to them."""
    return (np.stack([lim.steering_min, 0.0 - lim.max_reverse], axis=1),  # (no reverse: 0, not -0)
            np.stack([lim.steering_max, lim.max_speed], axis=1))


def hold_commands(command: np.ndarray, bounds: tuple[np.ndarray, np.ndarray]) -> None:
    """``command [n, 2]`` held in place to ``bounds`` (:func:`command_bounds`), as :func:`step`
    holds it, so that :func:`step` from a held command moves as from the command itself. Only
    a number past a bound is replaced: one within them is left as it is to the bit (NumPy's
    ``maximum(0.0, -0.0)`` is ``-0.0``, and a speed of 0 for a robot with no reverse was
    recorded as `-0`)."""
    np.copyto(command, bounds[0], where=command < bounds[0])
    np.copyto(command, bounds[1], where=command > bounds[1])


def limit_commands(steering: np.ndarray, speed: np.ndarray, cmd_steering: np.ndarray,
                   cmd_speed: np.ndarray, lim: Limits, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """The steering and speed actually reached after ``dt`` given the commands: clamped to the
    steering range and top speed, moved at most ``max_rate * dt`` and ``acceleration * dt``."""
    target = _clip(cmd_steering, lim.steering_min, lim.steering_max)
    step = lim.max_rate * dt
    new_steering = steering + _clip(target - steering, -step, step)
    target_v = _clip(cmd_speed, -lim.max_reverse, lim.max_speed)
    dv = lim.acceleration * dt
    new_speed = speed + _clip(target_v - speed, -dv, dv)
    return new_steering, new_speed


def advance(x: np.ndarray, y: np.ndarray, heading: np.ndarray, speed: np.ndarray,
            steering: np.ndarray, lim: Limits, dt: float, substeps: int = 1
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Integrate the pose over ``dt`` at constant speed and steering, in ``substeps`` exact arcs.

    ``heading`` in radians (CCW from +x). Returns the new (x, y, heading) of the centre.
    """
    delta = np.deg2rad(steering - lim.straight)
    forward = speed * np.cos(delta)                 # rear-axle speed, in/s
    yaw_rate = -speed * np.sin(delta) / lim.wheelbase   # steering < 90 -> delta < 0 -> left
    half = lim.wheelbase / 2.0
    rx = x - half * np.cos(heading)
    ry = y - half * np.sin(heading)
    h = heading
    h_dt = dt / substeps
    for _ in range(substeps):
        dh = yaw_rate * h_dt
        # exact arc: chord length 2 R sin(dh / 2) along the mean heading (straight when dh -> 0)
        half_dh = dh / 2.0
        safe = np.where(half_dh == 0.0, 1.0, half_dh)
        chord = forward * h_dt * np.where(half_dh == 0.0, 1.0, np.sin(safe) / safe)
        mid = h + dh / 2.0
        rx = rx + chord * np.cos(mid)
        ry = ry + chord * np.sin(mid)
        h = h + dh
    h = np.remainder(h + np.pi, 2.0 * np.pi) - np.pi
    return rx + half * np.cos(h), ry + half * np.sin(h), h


def _substeps(steering: np.ndarray, speed: np.ndarray, cmd_steering: np.ndarray, cmd_speed: np.ndarray,
              lim: Limits, dt: float,
              substeps: int) -> tuple[_Ramp, np.ndarray, np.ndarray]:
    """The wheel and the speed after each substep, ``[substeps, n]`` each, moved toward the
    commands within their limits (and the :class:`_Ramp` they were moved by)."""
    ramp = _ramp(lim, dt, substeps)
    target = _clip(cmd_steering, lim.steering_min, lim.steering_max)
    target_v = _clip(cmd_speed, ramp.reverse, lim.max_speed)
    steer_k = steering + _clip(target - steering, ramp.steer_down, ramp.steer_up)
    speed_k = speed + _clip(target_v - speed, ramp.speed_down, ramp.speed_up)
    return ramp, steer_k, speed_k


def step(x: np.ndarray, y: np.ndarray, heading: np.ndarray, speed: np.ndarray, steering: np.ndarray,
         cmd_steering: np.ndarray, cmd_speed: np.ndarray, lim: Limits, dt: float,
         substeps: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """One tick: in each of ``substeps`` equal parts of ``dt``, move the steering and speed
    toward the commands within their limits, then drive an exact arc. All substeps at once:
    rows ``k = 1..substeps`` of ``[substeps, n]`` arrays (the ramp toward a clipped target is
    ``start + clip(target - start, -k d, k d)``). Returns (x, y, heading, speed, steering)."""
    sdt = dt / substeps
    ramp, steer_k, speed_k = _substeps(steering, speed, cmd_steering, cmd_speed, lim, dt,
                                       substeps)
    delta = np.deg2rad(steer_k - lim.straight)
    dh = speed_k * np.sin(delta) / ramp.back_wheelbase * sdt        # -v sin(delta) / wb dt
    half_dh = dh / 2.0
    zero = half_dh == 0.0
    ratio = np.where(zero, 1.0, np.sin(half_dh) / np.where(zero, 1.0, half_dh))
    chord = speed_k * np.cos(delta) * sdt * ratio
    h_after = heading + np.add.accumulate(dh, axis=0)               # np.cumsum, called bare
    mid = h_after - half_dh
    half = ramp.half
    rx = x - half * np.cos(heading) + np.add.reduce(chord * np.cos(mid), axis=0)
    ry = y - half * np.sin(heading) + np.add.reduce(chord * np.sin(mid), axis=0)
    h = np.remainder(h_after[-1] + np.pi, 2.0 * np.pi) - np.pi
    return rx + half * np.cos(h), ry + half * np.sin(h), h, speed_k[-1], steer_k[-1]


def along(x: np.ndarray, y: np.ndarray, heading: np.ndarray, speed: np.ndarray, steering: np.ndarray,
          cmd_steering: np.ndarray, cmd_speed: np.ndarray, lim: Limits, dt: float,
          substeps: int, f: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where :func:`step` from the same state has the robots after the share ``f`` (0 to 1)
    of its tick: its whole substeps, then that part of the next one's arc (the contact check
    between ticks looks there). ``f = 1`` gives :func:`step`'s pose, up to rounding."""
    sdt = dt / substeps
    ramp, steer_k, speed_k = _substeps(steering, speed, cmd_steering, cmd_speed, lim, dt,
                                       substeps)
    whole = min(int(f * substeps), substeps)
    part = f * substeps - whole
    share = np.zeros((substeps, 1))
    share[:whole] = 1.0
    if whole < substeps:
        share[whole] = part
    delta = np.deg2rad(steer_k - lim.straight)
    dh = speed_k * np.sin(delta) / ramp.back_wheelbase * sdt * share
    half_dh = dh / 2.0
    zero = half_dh == 0.0
    ratio = np.where(zero, 1.0, np.sin(half_dh) / np.where(zero, 1.0, half_dh))
    chord = speed_k * np.cos(delta) * sdt * share * ratio
    mid = heading + np.cumsum(dh, axis=0) - half_dh
    half = ramp.half
    rx = x - half * np.cos(heading) + (chord * np.cos(mid)).sum(axis=0)
    ry = y - half * np.sin(heading) + (chord * np.sin(mid)).sum(axis=0)
    h = np.remainder(heading + dh.sum(axis=0) + np.pi, 2.0 * np.pi) - np.pi
    return rx + half * np.cos(h), ry + half * np.sin(h), h
