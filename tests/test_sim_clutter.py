"""Seeded clutter: the same seed gives the same objects, and a way past each stays open."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from mitos_cli.sim.clutter import FREE_WAY_IN, KINDS, clutter, passable
from mitos_cli.sim.loop import prepare
from mitos_cli.sim.world import Motion, Obstacle
from mitos_cli.sim.worldfile import parse_world

HALL = """\
name: hall
dt: 0.05
time_limit: 30
robot: {model: tricycle, wheelbase: 16, footprint: {length: 24, width: 18}}
q_init: {x: 30, y: 0, heading: 0}
q_goal: {x: 1170, y: 0}
map:
  corridors:
    - points: [[0, 0], [1200, 0]]
      width: 80
"""


@pytest.fixture(scope="module")
def hall():
    world = parse_world(HALL, "hall.yaml")
    return world, prepare(world)


def draw(hall, seed, count=6, **kw):
    world, scene = hall
    return clutter(world, scene.static, scene.routes[0], np.random.default_rng(seed), count,
                   **kw)


def test_the_same_seed_gives_the_same_clutter(hall):
    assert draw(hall, 7).obstacles == draw(hall, 7).obstacles
    assert draw(hall, 7).obstacles != draw(hall, 8).obstacles


def across(o) -> tuple[float, float]:
    """Lowest and highest y of an object (the hall runs along x, so angle 0 or 180)."""
    half = o.radius if o.shape == "circle" else o.width / 2
    return o.y - half, o.y + half


@pytest.mark.parametrize("seed", range(8))
def test_every_object_leaves_the_free_way_and_stays_inside(hall, seed):
    w = draw(hall, seed)
    assert 1 <= len(w.obstacles) <= 6
    for o in w.obstacles:
        lo, hi = across(o)
        assert lo >= -40 - 1e-6 and hi <= 40 + 1e-6
        assert max(40 - hi, lo + 40) >= FREE_WAY_IN - 1e-6
        assert o.name.split("_")[0] in {k.name for k in KINDS}


def test_objects_keep_their_spacing_and_the_start_and_goal_free(hall):
    w = draw(hall, 3, count=12)
    xs = sorted(o.x for o in w.obstacles)
    assert all(b - a >= 90 - 1e-6 for a, b in zip(xs, xs[1:]))
    assert all(o.x - 30 >= 90 - 1e-6 and 1170 - o.x >= 90 - 1e-6 for o in w.obstacles)


def test_a_way_wider_than_the_hall_places_nothing(hall):
    assert draw(hall, 1, free_way_in=100.0).obstacles == ()


def test_the_clutter_is_unknown_to_the_route(hall):
    world, scene = hall
    cluttered = draw(hall, 2)
    again = prepare(cluttered)
    assert np.array_equal(again.routes[0].points, scene.routes[0].points)
    assert not any(getattr(o, "known", False) for o in cluttered.obstacles)
    assert math.isclose(again.routes[0].length, scene.routes[0].length)


@pytest.mark.parametrize(("y", "width", "way"), [(20.0, 40.0, True), (10.0, 40.0, True),
                                                 (5.0, 60.0, False), (0.0, 80.0, False)])
def test_a_way_is_passable_when_the_body_fits_through_it(hall, y, width, way):
    """The 18 in robot with its 2 in margin needs 22 in: 30 in pass, 15 in do not."""
    world, _ = hall
    box = Obstacle("box_1", "rectangle", 600.0, y, length=16.0, width=width)
    assert passable(world, (box,)) is way


def test_what_moves_does_not_shut_the_way(hall):
    world, _ = hall
    cart = Obstacle("cart", "rectangle", 600.0, 0.0, length=16.0, width=80.0,
                    motion=Motion("velocity", velocity=(-10.0, 0.0)))
    assert passable(world.with_changes(obstacles=(cart,)), ())


@pytest.mark.parametrize("seed", range(8))
def test_every_draw_leaves_the_robot_a_way_to_its_goal(hall, seed):
    w = draw(hall, seed, count=12)
    known = tuple(dataclasses.replace(o, known=True) for o in w.obstacles)
    prepare(w.with_changes(obstacles=known))          # raises when there is no way


def test_nothing_is_put_where_a_moving_obstacle_passes(hall):
    """A cart coming head-on in the lower half of the hall, 900 in in the run's 30 s (from
    x = 1150 to 250): every object stays out of the band it sweeps (the discs holding it and
    the object, and 2 in) or beyond where it gets to."""
    world, scene = hall
    cart = Obstacle("cart", "rectangle", 1150.0, -14.0, length=22.0, width=16.0,
                    motion=Motion("velocity", velocity=(-30.0, 0.0)))
    busy = world.with_changes(obstacles=(cart,))
    for seed in range(8):
        w = clutter(busy, scene.static, scene.routes[0], np.random.default_rng(seed), 6)
        reach_cart = math.hypot(22.0, 16.0) / 2
        for o in w.obstacles[1:]:
            reach = o.radius or math.hypot(o.length, o.width) / 2
            gap = reach_cart + reach + 2.0
            assert abs(o.y - -14.0) >= gap - 1e-6 or o.x <= 250.0 - gap + 2.0
