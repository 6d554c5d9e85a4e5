"""Seeded clutter: boxes, bins and trolleys the robot does not know, put in its way.

:func:`clutter` adds ``count`` unknown obstacles along a robot's route, each standing against
one side of the corridor (the side drawn at random, its distance from that wall at random)
so that a way at least ``free_way_in`` wide stays open between it and the opposite wall. The
width across is measured with rays along the route's normal to the walls of the world (the
obstacles already in the world are kept at least ``spacing_in`` away, as are the start and
the goal), at the object's middle and at both its ends along the route, and the narrowest of
the three counts. A place where the corridor is too narrow for the object and the way is
skipped; the next draw tries another. Objects are at least ``spacing_in`` apart along the
route, so two of them never close the way between them.

Nothing is put where a moving obstacle of the world passes during the run (its path, from the
start to the time limit, widened by both objects' sizes and ``MOVING_GAP_IN``): a cart would
drive through a box as if it were not there, which no building shows.

The width across the route is a promise about a straight corridor; where the route bends
through a door, an object beside the door can shut it for a body coming round the bend, with
the ray across the route still finding 40 in. So every object is also checked the way BARN's
generator checks its fields (:func:`passable`): drawn on the map with everything else that
stands still, the route planner must still find a way from the start to the goal that the
robot's body fits through (its half width and margin from everything); an object that shuts
it is drawn again. Neither check draws from the generator: a draw none of whose objects fails
them is what the seed gave before they were made (an object drawn again changes the ones
after it).

Everything comes from the generator passed in: the same seed gives the same clutter.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..errors import MitosError
from . import obstacles as obs_mod
from .geometry import ray_segments
from .loop import prepare
from .route import Route
from .staticmap import StaticMap
from .world import Obstacle, World


@dataclass(frozen=True)
class Kind:
    """A kind of clutter: a ``length`` x ``width`` rectangle, or a circle when ``radius``."""

    name: str
    length: float = 0.0            # in, along the route
    width: float = 0.0             # in, across it
    radius: float = 0.0            # in

    @property
    def along(self) -> float:
        return 2 * self.radius if self.radius else self.length

    @property
    def across(self) -> float:
        return 2 * self.radius if self.radius else self.width

    @property
    def reach(self) -> float:
        """The radius of the disc round its centre that holds it."""
        return holding_radius(self.radius, self.length, self.width)


#: what an office or a hospital corridor holds (inches)
KINDS = (Kind("box", 16.0, 16.0), Kind("bin", radius=8.0), Kind("trolley", 30.0, 18.0))

FREE_WAY_IN = 40.0         # in: the way left open past every object
SPACING_IN = 90.0          # in: between objects, and from the start, the goal, other obstacles
MOVING_GAP_IN = 2.0        # in: between an object and where a moving obstacle passes
REACH_IN = 400.0           # in: how far across the route the walls are looked for
MAX_TRIES = 40             # draws per object before giving up on it


def widths_across(static: StaticMap, route: Route, s: float) -> tuple[float, float, float]:
    """Free room to the left and to the right of the route at arc length ``s`` (in, to the
    nearest wall along the normal) and the route's heading there (rad)."""
    a, b = route.point_at(s - 1.0), route.point_at(s + 1.0)
    heading = math.atan2(b[1] - a[1], b[0] - a[0])
    p = route.point_at(s)
    left = np.array([[-math.sin(heading), math.cos(heading)]])
    dirs = np.vstack([left, -left])
    walls = static.near(float(p[0]), float(p[1]), REACH_IN)
    room = ray_segments(p, dirs, walls, REACH_IN)
    return float(room[0]), float(room[1]), heading


def clutter(world: World, static: StaticMap, route: Route, rng: np.random.Generator,
            count: int, *, free_way_in: float = FREE_WAY_IN, spacing_in: float = SPACING_IN,
            kinds: tuple[Kind, ...] = KINDS) -> World:
    """``world`` with up to ``count`` unknown objects of ``kinds`` along ``route`` (see the
    module's docstring); fewer when the route has no room for them."""
    placed: list[Obstacle] = []
    taken = [0.0, route.length]                                    # start and goal
    others = np.array([[o.x, o.y] for o in world.obstacles]).reshape(-1, 2)
    paths = moving_paths(world)
    for k in range(count):
        for _ in range(MAX_TRIES):
            kind = kinds[int(rng.integers(len(kinds)))]
            s = float(rng.uniform(0.0, route.length))
            side = 1.0 if rng.random() < 0.5 else -1.0             # +1: against the left wall
            u = float(rng.random())
            if min(abs(s - t) for t in taken) < spacing_in:
                continue
            rooms = [widths_across(static, route, s + d * kind.along / 2) for d in (-1, 0, 1)]
            left = min(r[0] for r in rooms)
            right = min(r[1] for r in rooms)
            slack = left + right - kind.across - free_way_in
            if slack < 0:
                continue
            heading = rooms[1][2]
            wall = left if side > 0 else right                     # room toward the wall
            offset = side * (wall - kind.across / 2 - u * slack)   # centre, + = left
            p = route.point_at(s)
            x = float(p[0] - math.sin(heading) * offset)
            y = float(p[1] + math.cos(heading) * offset)
            if len(others) and np.hypot(*(others - (x, y)).T).min() < spacing_in:
                continue
            if any(np.hypot(*(centres - (x, y)).T).min() < reach + kind.reach + MOVING_GAP_IN
                   for centres, reach in paths):
                continue
            name = f"{kind.name}_{k + 1}"
            if kind.radius:
                new = Obstacle(name, "circle", x, y, radius=kind.radius)
            else:
                new = Obstacle(name, "rectangle", x, y, length=kind.length, width=kind.width,
                               angle=math.degrees(heading))
            if not passable(world, (*placed, new)):
                continue
            placed.append(new)
            taken.append(s)
            break
    return world.with_changes(obstacles=world.obstacles + tuple(placed))


def holding_radius(radius: float, length: float, width: float) -> float:
    """The radius of the disc round a shape's centre that holds it: a circle's own, else half
    a rectangle's diagonal."""
    return radius or math.hypot(length, width) / 2


def moving_paths(world: World) -> list[tuple[np.ndarray, float]]:
    """Where each moving obstacle of ``world`` goes during a run: its centre at every tick up
    to the time limit ``[T, 2]``, and the radius of the disc round its centre that holds it."""
    times = np.arange(0.0, world.time_limit + world.dt, world.dt)
    out = []
    for o in world.obstacles:
        if o.motion.kind == "static":
            continue
        reach = holding_radius(o.radius if o.shape == "circle" else 0.0, o.length, o.width)
        out.append((np.array([obs_mod.position(o, float(t)) for t in times]), reach))
    return out


def passable(world: World, objects: tuple[Obstacle, ...]) -> bool:
    """Whether the robot of ``world`` still has a way to its goal that its body fits through
    with ``objects`` and the world's obstacles that stand still drawn on its map (moving ones
    pass by)."""
    still = tuple(dataclasses.replace(o, known=True) for o in (*world.obstacles, *objects)
                  if o.motion.kind == "static")
    try:        # nodes at the cells' centres alone: the placements the suite's figures drew
        prepare(world.with_changes(obstacles=still), between=False)
    except MitosError:
        return False
    return True
