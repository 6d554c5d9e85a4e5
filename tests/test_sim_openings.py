"""Perception of clutter (``front``, ``opening``, ``clutter``) and the ``drive`` rules that use
it: what the robot can drive straight on, the way it takes, how many objects it sees."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mitos_cli.sim import barn, perception
from mitos_cli.sim.world import Robot

ROBOT = Robot(length=24, width=18)
CFG = perception.Settings()


def ways(points, unknown=None, bearing=0.0):
    """``free_ways`` on points given in the robot's own frame (along, across right +)."""
    p = np.asarray(points, float).reshape(-1, 2)
    unknown = np.ones(len(p), bool) if unknown is None else np.asarray(unknown, bool)
    return perception.free_ways(p[:, 0], p[:, 1], np.zeros(len(p)), unknown, ROBOT, CFG, bearing)


def pole(along, across, r=3.0, n=24):
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.stack([along + r * np.cos(a), across + r * np.sin(a)], axis=1)


@settings(max_examples=40, deadline=None)
@given(st.floats(-85, 85))
def test_in_the_open_the_opening_is_the_route_bearing(bearing):
    front, opening = ways(np.zeros((0, 2)), bearing=bearing)
    assert front == CFG.sight
    # the bearing, or a way a degree or two nearer the heading (the turn cost)
    assert abs(opening - bearing) <= 2.5 and abs(opening) <= abs(bearing)


def test_a_pole_dead_ahead_shortens_front_and_the_opening_goes_round_it():
    front, opening = ways(pole(60, 0))
    assert front == pytest.approx(60 - 3 - ROBOT.length / 2, abs=0.2)
    assert abs(opening) >= 10
    # the way taken is clear of the pole for the body's width
    phi = np.deg2rad(opening)
    p = pole(60, 0)
    across = np.abs(-p[:, 0] * np.sin(phi) + p[:, 1] * np.cos(phi))
    assert across.min() >= ROBOT.width / 2 + CFG.way_margin


def test_a_pole_left_of_the_way_leaves_it_open_and_beside_the_band_front_stays_clear():
    front, opening = ways(pole(60, -25))                  # 25 in left of the heading
    assert front == CFG.sight and opening == pytest.approx(0.0)


def test_the_opening_takes_the_gap_between_two_poles_not_the_wall_beside_them():
    # poles 13 in either side of a 40 in gap straight ahead, and more poles left and right
    pts = np.concatenate([pole(50, -20), pole(50, 20), pole(50, -45), pole(50, 45)])
    front, opening = ways(pts)
    assert front == CFG.sight and opening == pytest.approx(0.0)
    # shut the gap: the robot must turn, toward the side the route lies on
    pts = np.concatenate([pts, pole(50, 0)])
    assert ways(pts, bearing=30.0)[1] > 0 and ways(pts, bearing=-30.0)[1] < 0


def test_walls_shape_the_opening_but_do_not_shorten_front():
    wall = np.stack([np.full(20, 40.0), np.linspace(-30, 30, 20)], axis=1)
    front, opening = ways(wall, unknown=np.zeros(20, bool))
    assert front == CFG.sight                             # the route handles walls
    assert abs(opening) > 30                              # but the way is not through one


def test_clutter_counts_separate_objects_ahead():
    hits = np.concatenate([pole(60, -30, n=6), pole(60, 30, n=6), pole(-60, 0, n=6)])
    ah = hits[:, 0]
    unknown = np.ones(len(hits), bool)
    assert perception.clutter(hits, unknown, ah, CFG) == 2          # the one behind: not
    assert perception.clutter(hits[:6], unknown[:6], ah[:6], CFG) == 1
    assert perception.clutter(hits, np.zeros(len(hits), bool), ah, CFG) == 0


def test_inputs_are_in_the_term_sets():
    from mitos_cli.sim.planner import FuzzyPlanner

    compiled = FuzzyPlanner(None, "drive").compiled
    assert {"front", "opening", "clutter"} <= set(compiled.inputs)
    assert {"front", "opening", "clutter"} <= set(perception.INPUTS)


def test_a_barn_run_is_deterministic():
    from mitos_cli.sim.loop import simulate

    w = barn.barn_world(2, 0.2, 4)
    a, b = simulate(w), simulate(w)
    assert a.outcome == b.outcome and np.array_equal(a.pose, b.pose)
    assert np.array_equal(a.perceived["opening"], b.perceived["opening"])
