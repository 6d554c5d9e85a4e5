"""Obstacles over time: where each one is at time ``t`` (a pure function of the world and t),
their outlines as segments and circles for sensing and collisions, and randomised worlds."""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from .geometry import polygon_segments, rect_corners
from .world import Motion, Obstacle, World

if TYPE_CHECKING:
    #: circles (centres [C, 2], radii [C], obstacle of each), rectangle sides [S, 4] with
    #: the obstacle of each, and the rectangles' corners [Q, 4, 2]
    Shapes = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _along(path: np.ndarray, s: float) -> np.ndarray:
    """The point at arc length ``s`` (clamped) of polyline ``path[P, 2]``."""
    seg = np.diff(path, axis=0)
    lengths = np.hypot(seg[:, 0], seg[:, 1])
    cum = np.concatenate([[0.0], np.cumsum(lengths)])
    s = min(max(s, 0.0), cum[-1])
    i = min(int(np.searchsorted(cum, s, side="right")) - 1, len(seg) - 1)
    frac = (s - cum[i]) / lengths[i] if lengths[i] > 0 else 0.0
    return path[i] + frac * seg[i]


def position(o: Obstacle, t: float) -> tuple[float, float]:
    """Where obstacle ``o`` is at time ``t`` (s)."""
    m: Motion = o.motion
    if m.kind == "velocity":
        return o.x + m.velocity[0] * t, o.y + m.velocity[1] * t
    if m.kind != "waypoints":
        return o.x, o.y
    path = np.asarray(m.waypoints, float)
    if m.mode == "loop":
        path = np.vstack([path, path[:1]])
    length = float(np.hypot(*np.diff(path, axis=0).T).sum())
    s = m.speed * t
    if length <= 0:
        return o.x, o.y
    if m.mode == "loop":
        s = s % length
    elif m.mode == "ping-pong":
        s = s % (2 * length)
        s = s if s <= length else 2 * length - s
    p = _along(path, s)
    return float(p[0]), float(p[1])


def positions(obstacles: tuple[Obstacle, ...], t: float) -> np.ndarray:
    """Positions ``[O, 2]`` of all obstacles at time ``t``."""
    return np.array([position(o, t) for o in obstacles], dtype=float).reshape(-1, 2)


def shapes_at(obstacles: tuple[Obstacle, ...], where: np.ndarray) -> Shapes:
    """Circles (centres ``[C, 2]``, radii ``[C]``) and rectangle sides ``[S, 4]`` with the
    index of the obstacle each side belongs to."""
    circ = [i for i, o in enumerate(obstacles) if o.shape == "circle"]
    rect = [i for i, o in enumerate(obstacles) if o.shape == "rectangle"]
    centres = where[circ] if circ else np.zeros((0, 2))
    radii = np.array([obstacles[i].radius for i in circ], dtype=float)
    if rect:
        corners = rect_corners(where[rect, 0], where[rect, 1],
                               np.deg2rad([obstacles[i].angle for i in rect]),
                               np.array([obstacles[i].length for i in rect]),
                               np.array([obstacles[i].width for i in rect]))
        sides = polygon_segments(corners)
        owner = np.repeat(rect, 4)
    else:
        corners, sides, owner = np.zeros((0, 4, 2)), np.zeros((0, 4)), np.zeros(0, dtype=int)
    return centres, radii, np.asarray(circ, dtype=int), sides, owner, corners


def randomises_nothing(world: World) -> bool:
    """Whether every randomised run of ``world`` is the same run: no obstacle range wider
    than a point and no sensor noise, drawn or fixed (a study's n and intervals then count
    copies of one run)."""
    r = world.randomise
    moved = any(j.dx[0] != j.dx[1] or j.dy[0] != j.dy[1] for j in r.obstacles)
    noisy = world.sensors.noise > 0 or (r.sensor_noise is not None and max(r.sensor_noise) > 0)
    return not moved and not noisy


def copies_note(world: World, runs: int) -> str | None:
    """The warning for ``runs`` randomised runs of a world that randomises nothing."""
    if runs < 2 or not randomises_nothing(world):
        return None
    return (f"{world.path or world.name}: the world randomises nothing (no `randomise:` range, "
            f"no sensor noise): its {runs} runs are one run {runs} times, and their spread "
            f"and intervals count copies")


def randomised(world: World, rng: np.random.Generator) -> World:
    """A copy of ``world`` with obstacles moved and sensor noise drawn within its ranges.

    Draws happen in file order (every jitter, then the noise), so one generator state gives
    one world.
    """
    r = world.randomise
    obstacles = list(world.obstacles)
    index = {o.name: i for i, o in enumerate(obstacles)}
    for j in r.obstacles:
        dx = float(rng.uniform(*j.dx)) if j.dx[0] != j.dx[1] else j.dx[0]
        dy = float(rng.uniform(*j.dy)) if j.dy[0] != j.dy[1] else j.dy[0]
        o = obstacles[index[j.obstacle]]
        m = o.motion
        if m.kind == "waypoints":
            m = replace(m, waypoints=tuple((x + dx, y + dy) for x, y in m.waypoints))
        obstacles[index[j.obstacle]] = replace(o, x=o.x + dx, y=o.y + dy, motion=m)
    sensors = world.sensors
    if r.sensor_noise is not None:
        sensors = replace(sensors, noise=float(rng.uniform(*r.sensor_noise)))
    return replace(world, obstacles=tuple(obstacles), sensors=sensors)


def outline_points(obstacles: tuple[Obstacle, ...], where: np.ndarray, per: int = 16
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Points ``[P, 2]`` on every obstacle's outline and the obstacle index of each."""
    pts, owner = [], []
    angles = np.linspace(0, 2 * np.pi, per, endpoint=False)
    for i, o in enumerate(obstacles):
        if o.shape == "circle":
            p = where[i] + o.radius * np.stack([np.cos(angles), np.sin(angles)], axis=1)
        else:
            c = rect_corners(where[i, 0], where[i, 1], np.deg2rad(o.angle), o.length, o.width)
            f = np.linspace(0, 1, per // 4, endpoint=False)[:, None]
            p = np.concatenate([c[k] + f * (c[(k + 1) % 4] - c[k]) for k in range(4)])
        pts.append(p)
        owner.append(np.full(len(p), i))
    if not pts:
        return np.zeros((0, 2)), np.zeros(0, dtype=int)
    return np.concatenate(pts), np.concatenate(owner)
