"""World files (YAML) -> :class:`~.world.World`, with a position for every complaint.

The format is documented in ``worlds/README.md``. Every error is a
:class:`~mitos_cli.errors.WorldError` naming the file, line and column: unknown keys (with
"did you mean"), missing fields, numbers out of range, a start or goal inside a wall, a map
image that cannot be read.
"""

from __future__ import annotations

import math
import os
from collections import Counter
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import MitosError, NameError_, Span, WorldError, closest, did_you_mean, unknown
from ..lang import yamlpos
from ..lang.yamlpos import YList, YMap
from .safety import TIGHTEST_TURN, fastest_point, full_lock, swing_words, tightest_turn
from .world import (
    REPLANS,
    Agent,
    Corridor,
    Goal,
    Jitter,
    Motion,
    Obstacle,
    Pose,
    Randomise,
    Robot,
    Sensors,
    World,
)

if TYPE_CHECKING:
    import numpy as np

    from .staticmap import StaticMap
    from .world import Grid

TOP_KEYS = ("name", "seed", "dt", "time_limit", "substeps", "behavior", "robot", "sensors",
            "q_init", "q_goal", "map", "obstacles", "robots", "randomise", "route")
ROBOT_KEYS = ("model", "wheelbase", "footprint", "safety_margin", "steering", "max_speed",
              "acceleration", "max_reverse", "brake", "give_way")
STEERING_KEYS = ("min", "max", "straight", "max_rate")
SENSOR_KEYS = ("layout", "count", "fov", "cone", "range", "noise")
MAP_KEYS = ("corridors", "grid", "unknown", "given")
ROUTE_KEYS = ("min_clearance", "replan")
OBSTACLE_KEYS = ("name", "shape", "at", "radius", "length", "width", "angle", "velocity",
                 "waypoints", "speed", "mode", "known")
AGENT_KEYS = ("name", "q_init", "q_goal", "robot")
RANDOMISE_KEYS = ("obstacles", "sensor_noise")
MODELS = ("tricycle",)
#: What a world's numbers are in, for one written with a unit (`wheelbase: 16in`).
UNITS = "a world's numbers are in inches, seconds and degrees"
LAYOUTS = ("ring", "fan")
SHAPES = ("circle", "rectangle")
MODES = ("loop", "ping-pong", "stop")
#: keys whose value is a thing of that name ("unknown shape `circel`" reads); for the others
#: ("unknown unknown `ocupied`" does not) an error quotes `key: value`
NOUN_KEYS = ("model", "layout", "shape", "mode")
#: a world's keys that hold for all its robots (written under a robot, they are misplaced)
SHARED_KEYS = tuple(k for k in TOP_KEYS if k not in ("name", "robot", "q_init", "q_goal",
                                                     "robots"))


#: The largest magnitude of any number in a world (inches, seconds, degrees): 1e7 in is
#: 254 km, larger than any building, and squares of larger coordinates lose the geometry.
LARGEST = 1e7


#: what a number beyond LARGEST means, for the keys that are not lengths in inches
BEYOND = {"time_limit": "times are in seconds: 1e7 s is 116 days",
          "dt": "times are in seconds: 1e7 s is 116 days",
          "substeps": "a count this large would never finish a tick",
          **dict.fromkeys(("heading", "fov", "cone", "angle", "min", "max", "straight"),
                          "angles are in degrees: 1e7 deg is 27,778 turns"),
          "max_rate": "a steering rate is in degrees a second: 1e7 deg/s is 27,778 turns a "
                      "second"}


#: a value of a key of words that means one of them (``replan: false``: never replan)
MEANT = {("replan", "false"): ("never", "`replan: never` keeps the route planned at the start")}


def _as_written(value: Any) -> str:
    """A scalar as YAML writes it, for a message to quote (``false``, not Python's ``False``;
    an empty value as nothing, not ``None``)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return "" if value is None else str(value)


def _sane(x: float, span: Span, what: str, key: str = "") -> float:
    if abs(x) > LARGEST:
        raise WorldError(f"{what} must be within ±{LARGEST:g}, not {x:g}", span=span,
                         hint=BEYOND.get(key, "world lengths are in inches: 1e7 in is 254 km"))
    return x


class _Reader:
    """Small typed accessors bound to one file."""

    def __init__(self, path: str) -> None:
        self.path = path

    def mapping(self, value: Any, span: Span, what: str, keys: tuple[str, ...],
                elsewhere: dict[str, str] | None = None) -> YMap:
        """``value`` as a mapping of ``keys``; an unknown key that ``elsewhere`` names is
        refused with its hint, where it belongs (`give_way` beside a robot's `robot:`)."""
        m = yamlpos.expect_map(value, span, WorldError, what)
        stray = next((k for k in m if k not in keys), None)
        if elsewhere and stray is not None:
            near = closest(stray, [*keys, *elsewhere]) if isinstance(stray, str) else None
            hint = (elsewhere.get(stray) or near in elsewhere and near not in keys
                    and f"did you mean `{near}`? {elsewhere[near]}")  # `max_sped`: not `seed`
            if hint:
                raise WorldError(f"unknown key `{stray}` in {what}", span=m.key_span(stray),
                                 expected="one of " + ", ".join(keys), hint=hint)
        yamlpos.check_keys(m, keys, WorldError, what)
        return m

    def number(self, m: YMap, key: str, what: str, default: float | None = None, *,
               positive: bool = False, minimum: float | None = None,
               maximum: float | None = None, sane: bool = True) -> float:
        if key not in m:
            if default is None:
                return yamlpos.require(m, key, WorldError, what)   # raises: `key` is missing
            return float(default)
        span = m.value_span(key)
        x = yamlpos.expect_number(m[key], span, WorldError, f"`{key}` in {what}", units=UNITS)
        if sane and (maximum is None or x <= maximum):     # else "at most", below
            _sane(x, span, f"`{key}` in {what}", key)
        if positive and x <= 0:
            raise WorldError(f"`{key}` in {what} must be positive, not {x:g}", span=span)
        if minimum is not None and x < minimum:
            raise WorldError(f"`{key}` in {what} must be at least {minimum:g}, not {x:g}",
                             span=span)
        if maximum is not None and x > maximum:
            raise WorldError(f"`{key}` in {what} must be at most {maximum:g}, not {x:g}",
                             span=span)
        return x

    def point(self, value: Any, span: Span, what: str,
              shape: str = "a point [x, y] (inches)") -> tuple[float, float]:
        if not isinstance(value, list) or len(value) != 2:
            raise WorldError(f"{what} must be {shape}", span=span)
        spans = value.item_spans if isinstance(value, YList) else [span] * 2
        x, y = (_sane(yamlpos.expect_number(v, at, WorldError, what, units=UNITS), at, what)
                for v, at in zip(value, spans))
        return x, y

    def points(self, value: Any, span: Span, what: str, least: int) -> tuple:
        if not isinstance(value, list) or len(value) < least:
            raise WorldError(f"{what} must be a list of at least "
                             f"{'one point' if least == 1 else f'{least} points'} [x, y]",
                             span=span)
        spans = value.item_spans if isinstance(value, YList) else [span] * len(value)
        return tuple(self.point(p, s, f"a point of {what}") for p, s in zip(value, spans))

    def choice(self, m: YMap, key: str, options: tuple[str, ...], what: str,
               default: str | None = None) -> str:
        if key not in m:
            if default is None:
                return yamlpos.require(m, key, WorldError, what)   # raises: `key` is missing
            return default
        if m[key] is None or isinstance(m[key], (list, dict)):   # "unknown model ``" said
            one_of = "one of " + ", ".join(options)
            raise WorldError(f"`{key}` in {what} must be {one_of}, not "        # nothing
                             f"{yamlpos.as_written(m[key], m.value_span(key))}",
                             span=m.value_span(key), expected=one_of,
                             hint=f"write `{key}: {options[0]}`" if len(options) == 1 else
                             f"write one of them, or leave `{key}` out" if default else None)
        value = _as_written(m[key])
        if value not in options:
            err = unknown(key, value, options)          # "unknown shape `circel`" ...
            message = (f"{err.message} in {what}" if key in NOUN_KEYS   # ... "in obstacle `box`"
                       else f"`{key}: {value}` in {what}: unknown value")
            meant = MEANT.get((key, value))
            raise WorldError(message, span=m.value_span(key), expected=err.expected,
                             hint=f"did you mean `{meant[0]}`? ({meant[1]})" if meant
                             else err.hint)
        return value

    def flag(self, m: YMap, key: str, what: str, default: bool, whose: str = "") -> bool:
        """``true`` or ``false`` (every yes/no key of a world: ``known``, ``brake``); ``1``
        and YAML 1.1's ``yes``/``no``/``on``/``off`` are refused where they stand. A value
        that is nothing (``null``, ``~``, empty) is quoted as written, and the hint says what
        leaving the key out takes: ``default``, ``whose`` it is (``the first robot's``)."""
        if key not in m:
            return default
        value = m[key]
        if not isinstance(value, bool):
            span = m.value_span(key)
            meant = yamlpos.yaml11_bool(value)
            left_out = (f"; left out, `{key}` is {_as_written(default)}"
                        + (f" ({whose})" if whose else ""))
            hint = (f"write `{key}: {str(meant).lower()}`: only true and false are yes/no "
                    f"values here (YAML 1.2), `{value}` is text" if meant is not None else
                    (isinstance(value, str) and did_you_mean(value, ("true", "false")))
                    or f"write `{key}: true` or `{key}: false`{left_out}")
            raise WorldError(f"`{key}` in {what} must be true or false, not "
                             f"{yamlpos.as_written(value, span)}",
                             span=span, expected="true or false", hint=hint)
        return value

    def range_pair(self, value: Any, span: Span, what: str) -> tuple[float, float]:
        lo, hi = self.point(value, span, what, "a range [low, high]")
        if lo > hi:
            raise WorldError(f"{what} must be [low, high] with low <= high", span=span)
        return lo + 0.0, hi + 0.0       # [0, -0.0]: a draw from it refused -0.0 below 0.0


def _example(m: dict, key: str) -> str:
    """``key``'s value as written, for a hint that moves it (``...`` for a list or mapping)."""
    value = m[key]
    return "..." if value is None or isinstance(value, (list, dict)) else _as_written(value)


def _robot_keys_elsewhere(m: Any, under: str) -> dict[str, str]:
    """Where a robot's key written outside a `robot:` belongs: `give_way: false` beside a
    `robots:` item's `name` was "unknown key" with no word of its `robot:` (``under``: which
    `robot:`), and at the top of the file it was offered `seed`."""
    written = m if isinstance(m, YMap) else {}
    return {k: f"`{k}` is a key of the robot itself: write it under {under}, as "
               f"`robot: {{{k}: {_example(written, k) if k in written else '...'}}}`"
            for k in ROBOT_KEYS}


def _pose_keys_elsewhere(m: Any) -> dict[str, str]:
    """Where a start's or a goal's key written beside them belongs (``heading: 180`` beside
    a `robots:` item's `q_init`), with the value as written."""
    shown = {k: _example(m, k) if isinstance(m, YMap) and k in m else "..."
             for k in ("heading", "tolerance")}
    return {"heading": f"`heading` is the start's: write it in `q_init`, as `q_init: {{x: ..., "
                       f"y: ..., heading: {shown['heading']}}}`",
            "tolerance": f"`tolerance` is the goal's: write it in `q_goal`, as `q_goal: {{x: "
                         f"..., y: ..., tolerance: {shown['tolerance']}}}`",
            **{k: f"`{k}` is a coordinate of `q_init` or `q_goal`: write it in one, as "
                  f"`q_init: {{x: ..., y: ...}}`" for k in ("x", "y")}}


def _shared_keys_elsewhere(first: bool, m: Any) -> dict[str, str]:
    """Where a key of a `robot:` block (``first``: the top one) or of a `robots:` item
    belongs that is not the robot's: the world's keys, and the item's."""
    hints = {k: f"`{k}` is the world's, the same for every robot: write it at the top level "
                f"of the file" for k in SHARED_KEYS} | _pose_keys_elsewhere(m)
    if first:
        hints.update({k: f"`{k}` is not the robot's: write it at the top level of the file, "
                         f"beside `robot:`" for k in ("q_init", "q_goal", "robots")})
        hints["name"] = ("the first robot is named `robot`; the world's other robots are "
                         "named in their `robots:` items (and `name` at the top level names "
                         "the world)")
    else:
        hints.update({k: f"`{k}` is the `robots:` item's: write it beside `robot:`, not "
                         f"under it" for k in AGENT_KEYS})
    return hints


def read_robot(r: _Reader, value: Any, span: Span, base: Robot | None = None,
               dt: float | None = None, who: str = "robot") -> Robot:
    """A `robot:` block; ``base``: the robot whose keys it changes (a `robots:` item's, the
    first robot), ``who``: the robot it is, for the messages (``robot `b```)."""
    m = r.mapping(value, span, who, ROBOT_KEYS, _shared_keys_elsewhere(base is None, value))
    d = base or Robot()
    foot, steer = (("robot footprint", "robot steering") if who == "robot" else
                   (f"the footprint of {who}", f"the steering of {who}"))
    if base is None or "model" in m:
        r.choice(m, "model", MODELS, who)
    fp = d.length, d.width
    if "footprint" in m:
        f = r.mapping(m["footprint"], m.value_span("footprint"), foot, ("length", "width"))
        side = next((k for k in ("length", "width") if k not in f), None)
        if base is not None and side is not None:   # (steering's keys are taken one by one)
            raise WorldError(f"missing `{side}` in {foot}", span=f.span,
                             expected="a footprint's length and width both",
                             hint=f"add `{side}: {getattr(d, side):g}` to keep the first "
                                  f"robot's {side}")
        fp = (r.number(f, "length", foot, positive=True),
              r.number(f, "width", foot, positive=True))
    elif base is None:
        yamlpos.require(m, "footprint", WorldError, "robot")
    st = YMap()
    st.span, st.key_spans, st.value_spans = m.span, {}, {}
    if "steering" in m:
        st = r.mapping(m["steering"], m.value_span("steering"), steer, STEERING_KEYS)
    smin = r.number(st, "min", steer, d.steering_min, minimum=0, maximum=180)
    smax = r.number(st, "max", steer, d.steering_max, minimum=0, maximum=180)
    straight = r.number(st, "straight", steer, d.steering_straight)
    if not smin < straight < smax:
        raise WorldError(f"steering needs min < straight < max, not {smin:g} < {straight:g} "
                         f"< {smax:g}", span=st.span)
    wheelbase = r.number(m, "wheelbase", who, None if base is None else d.wheelbase,
                         positive=True)
    _check_wheelbase(m, wheelbase, fp[0], inherited=base is not None and "wheelbase" not in m)
    whose = "" if base is None else "the first robot's"
    robot = Robot(
        model="tricycle",
        wheelbase=wheelbase,
        length=fp[0], width=fp[1],
        safety_margin=r.number(m, "safety_margin", who, d.safety_margin, minimum=0),
        steering_min=smin, steering_max=smax, steering_straight=straight,
        max_steering_rate=r.number(st, "max_rate", steer, d.max_steering_rate,
                                   positive=True),
        max_speed=r.number(m, "max_speed", who, d.max_speed, positive=True),
        acceleration=r.number(m, "acceleration", who, d.acceleration, positive=True),
        max_reverse=r.number(m, "max_reverse", who, d.max_reverse, minimum=0),
        brake=r.flag(m, "brake", who, d.brake, whose),
        give_way=r.flag(m, "give_way", who, d.give_way, whose))
    _check_turn(m, st, robot)
    if dt is not None:
        _check_tick(m, robot, dt)
    return robot


def _check_tick(m: YMap, robot: Robot, dt: float) -> None:
    """Refuse a robot whose body can move farther in one tick than its own length: it
    senses and brakes once a tick (`max_speed: 100000`, with `acceleration: 1000000`, drove
    through the walls and 4,000 in outside the map with "no collision" before contact was
    looked for between ticks, and DWA hung). In a turn the outer front corner moves faster
    than the wheel (:func:`~.safety.fastest_point`)."""
    key = "max_speed" if robot.max_speed >= robot.max_reverse else "max_reverse"
    fastest, swing = getattr(robot, key), fastest_point(robot)
    if fastest * dt * swing <= robot.length:
        return
    raise WorldError(f"at {key} {fastest:g} in/s the robot's body moves up to "
                     f"{fastest * dt * swing:.3g} in a tick (dt {dt:g} s; {swing_words(swing)}), "
                     f"farther than its own length ({robot.length:g} in): it senses and "
                     f"brakes once a tick, so it would pass things between two looks",
                     span=m.value_span(key) if key in m else m.span,
                     expected=f"a {key} of at most {robot.length / (dt * swing):.4g} in/s at "
                              f"this dt",
                     hint="speeds are in inches a second (the packaged robots' top speed: 60); "
                          "or a smaller `dt`")


def _check_turn(m: YMap, st: YMap, robot: Robot) -> None:
    """Refuse a robot whose tightest turn is narrower than :data:`~.safety.TIGHTEST_TURN`
    (`wheelbase: 0.01`, or `steering: {min: 0, max: 180}`, whose wheel stands across the
    body): its brake's sweep places the body along the arc closer together the tighter the
    turn, and a run took minutes and gigabytes, or died asking for terabytes."""
    radius = tightest_turn(robot)
    if radius >= TIGHTEST_TURN:
        return
    lock = full_lock(robot)
    side = "min" if robot.steering_straight - robot.steering_min == lock else "max"
    blame_lock = side in st and (lock > 60 or "wheelbase" not in m)   # the packaged: 60 deg
    span = (st.value_span(side) if blame_lock
            else m.value_span("wheelbase") if "wheelbase" in m else m.span)
    if lock >= 90:
        raise WorldError(f"the steering's lock is {lock:g} deg off straight: the wheel can "
                         f"stand across the robot, which then turns on the spot about its "
                         f"rear axle", span=span,
                         expected="a lock under 90 deg (`min` and `max` within 90 of "
                                  "`straight`)",
                         hint="the packaged robots steer 60 deg either way: "
                              "`steering: {min: 30, max: 150, straight: 90}`")
    expected = (f"a lock of at most "
                f"{math.degrees(math.atan(robot.wheelbase / TIGHTEST_TURN)):.3g} deg at this "
                f"wheelbase" if blame_lock else
                f"a wheelbase of at least {TIGHTEST_TURN * math.tan(math.radians(lock)):.3g} "
                f"in at this lock")
    raise WorldError(f"the robot's tightest turn has a radius of {radius:.3g} in (wheelbase "
                     f"{robot.wheelbase:.3g} in at a lock of {lock:g} deg): a tricycle turns "
                     f"about a point at least {TIGHTEST_TURN:g} in from its rear axle",
                     span=span, expected=expected,
                     hint="wheelbases are in inches (the packaged robots': 12 to 16 in); a "
                          "smaller lock (`steering: min` and `max` nearer `straight`) turns "
                          "wider")


def _check_wheelbase(m: YMap, wheelbase: float, length: float, inherited: bool = False) -> None:
    """Refuse a wheelbase longer than the footprint: the rear axle and the front wheel are on
    the robot, and a body shorter than its wheelbase (`wheelbase: 40` under a 24 in footprint)
    turns like a long robot while it collides like a short one. ``inherited``: the wheelbase
    is the first robot's, taken by a `robots:` item that gave only its footprint (the hint
    said "shorten `wheelbase`", which that item does not have)."""
    if wheelbase > length:
        key = "wheelbase" if "wheelbase" in m else "footprint"
        whose = ", the first robot's, which this robot takes" if inherited else ""
        raise WorldError(f"the wheelbase ({wheelbase:g} in{whose}) is longer than the robot's "
                         f"footprint ({length:g} in long): its wheels must fit under its body",
                         span=m.value_span(key) if key in m else m.span,
                         expected=f"a wheelbase of at most {length:g} in",
                         hint=f"give this robot its own `wheelbase` (at most {length:g} in) "
                              "beside its `footprint`, or lengthen the footprint" if inherited
                         else "shorten `wheelbase`, or lengthen `footprint: {length: ...}`")


def read_sensors(r: _Reader, value: Any, span: Span) -> Sensors:
    m = r.mapping(value, span, "sensors", SENSOR_KEYS)
    d = Sensors()
    layout = r.choice(m, "layout", LAYOUTS, "sensors", d.layout)
    count = r.number(m, "count", "sensors", d.count, minimum=1, maximum=720)
    if count != int(count):
        raise WorldError("`count` in sensors must be a whole number", span=m.value_span("count"))
    if layout == "ring" and "fov" in m and m["fov"] != 360:      # it was ignored
        raise WorldError("`fov` in sensors is for `layout: fan`: a ring looks all round",
                         span=m.value_span("fov"), hint="add `layout: fan`, or drop `fov`")
    return Sensors(layout, int(count),
                   r.number(m, "fov", "sensors", 180.0 if layout == "fan" else 360.0,
                            positive=True, maximum=360),
                   r.number(m, "cone", "sensors", d.cone, minimum=0, maximum=90),
                   r.number(m, "range", "sensors", d.range, positive=True),
                   r.number(m, "noise", "sensors", d.noise, minimum=0))


def read_pose(r: _Reader, value: Any, span: Span, what: str) -> Pose:
    m = r.mapping(value, span, what, ("x", "y", "heading"))
    return Pose(r.number(m, "x", what), r.number(m, "y", what), r.number(m, "heading", what, 0.0))


def read_goal(r: _Reader, value: Any, span: Span, what: str) -> Goal:
    m = r.mapping(value, span, what, ("x", "y", "tolerance"))
    return Goal(r.number(m, "x", what), r.number(m, "y", what),
                r.number(m, "tolerance", what, Goal.tolerance, positive=True))


def read_obstacle(r: _Reader, value: Any, span: Span, index: int) -> Obstacle:
    m = r.mapping(value, span, f"obstacle {index + 1}", OBSTACLE_KEYS)
    name = (_label(m, f"obstacle {index + 1}'s", "box (`randomise` and pictures use it)")
            if "name" in m else f"obstacle{index + 1}")
    what = f"obstacle `{name}`"
    shape = r.choice(m, "shape", SHAPES, what)
    at = r.point(yamlpos.require(m, "at", WorldError, what), m.value_span("at"), f"`at` of {what}")
    radius = length = width = angle = 0.0
    if shape == "circle":
        radius = r.number(m, "radius", what, positive=True)
        for k in ("length", "width", "angle"):
            if k in m:
                raise WorldError(f"a circle has a `radius`, not a `{k}`", span=m.key_span(k))
    else:
        length = r.number(m, "length", what, positive=True)
        width = r.number(m, "width", what, positive=True)
        angle = r.number(m, "angle", what, 0.0)
        if "radius" in m:
            raise WorldError("a rectangle has `length` and `width`, not a `radius`",
                             span=m.key_span("radius"))
    motion = Motion()
    if "velocity" in m and "waypoints" in m:
        raise WorldError(f"{what} has both `velocity` and `waypoints`; give one",
                         span=m.key_span("waypoints"))
    if "velocity" in m:
        motion = Motion("velocity", velocity=r.point(m["velocity"], m.value_span("velocity"),
                                                     f"`velocity` of {what}",
                                                     "a velocity [vx, vy] (in/s)"))
    elif "waypoints" in m:
        wps = r.points(m["waypoints"], m.value_span("waypoints"), f"`waypoints` of {what}", 1)
        motion = Motion("waypoints", waypoints=(at,) + wps,
                        speed=r.number(m, "speed", what, positive=True),
                        mode=r.choice(m, "mode", MODES, what, "loop"))
    for k in ("speed", "mode"):
        if k in m and motion.kind != "waypoints":
            raise WorldError(f"`{k}` belongs to an obstacle with `waypoints`", span=m.key_span(k))
    known = r.flag(m, "known", what, False)
    if known and motion.kind != "static":
        raise WorldError(f"{what} moves, so it cannot be `known`: the robot's map holds only "
                         "what stays put", span=m.value_span("known"),
                         hint="drop `known: true`, or the `velocity` / `waypoints`")
    return Obstacle(name, shape, at[0], at[1], radius, length, width, angle, motion, known)


def read_randomise(r: _Reader, value: Any, span: Span, names: list[str],
                   robots: tuple[str, ...] = ()) -> Randomise:
    """``randomise``: each named obstacle's offsets and the sensor noise (``robots``: the
    robots' names, which a user may give it: it does not move them)."""
    fixed = ("randomise moves obstacles and the sensor noise, not the robots: each robot "
             "starts at its `q_init`")
    m = r.mapping(value, span, "randomise", RANDOMISE_KEYS,
                  {k: fixed for k in ("robots", "robot", "q_init", "q_goal")})
    jitters = []
    if "obstacles" in m:
        if not names and m["obstacles"]:       # not "expected one of" nothing
            raise WorldError("randomise moves obstacles, and the world has none",
                             span=m.value_span("obstacles"),
                             hint=fixed if isinstance(m["obstacles"], YMap) and any(
                                 k in robots for k in m["obstacles"]) else
                             "add them under `obstacles:`, or drop `randomise: obstacles`")
        obs = r.mapping(m["obstacles"], m.value_span("obstacles"), "randomise obstacles",
                        tuple(names), {k: f"`{k}` is a robot: {fixed}" for k in robots
                                       if k not in names})
        for name, spec in obs.items():
            _check_offsets(spec, name)
            j = r.mapping(spec, obs.value_span(name), f"randomise of `{name}`", ("dx", "dy"))
            dx = r.range_pair(j["dx"], j.value_span("dx"), "dx") if "dx" in j else (0.0, 0.0)
            dy = r.range_pair(j["dy"], j.value_span("dy"), "dy") if "dy" in j else (0.0, 0.0)
            jitters.append(Jitter(name, dx, dy))
    noise = None
    if "sensor_noise" in m:
        noise = r.range_pair(m["sensor_noise"], m.value_span("sensor_noise"), "sensor_noise")
        if noise[0] < 0:
            raise WorldError("sensor_noise must not be negative", span=m.value_span("sensor_noise"))
    return Randomise(tuple(jitters), noise)


def _check_offsets(spec: Any, name: str) -> None:
    """An unknown key among an obstacle's offsets: `dz`, `x`, `dxy` are too far from `dx` and
    `dy` for the usual "did you mean" (two letters, one different), so name both."""
    if not isinstance(spec, YMap):
        return                                  # r.mapping says what it must be
    for key in spec:
        if key not in ("dx", "dy"):
            raise WorldError(f"unknown key `{key}` in randomise of `{name}`",
                             span=spec.key_span(key), expected="dx or dy (in, added to `at`)",
                             hint="did you mean `dx` or `dy`? (a world is flat: x and y only)")


def _list(mapping: YMap, key: str) -> list:
    """``mapping[key]`` as a list (absent or null: none); a mapping or a scalar there is an
    error at it (``obstacles:`` followed by a mapping was an ``AttributeError``)."""
    value = mapping.get(key)
    if value is None:
        return []
    if not isinstance(value, YList):
        raise WorldError(f"`{key}` must be a list", span=mapping.value_span(key),
                         expected=f"one `- ...` item per line under `{key}:`")
    return value


#: the most ticks a run may take (a tiny ``dt`` would otherwise run for hours)
MAX_TICKS = 100_000


def _seed(r: _Reader, top: YMap) -> int:
    """The world's seed, exactly: a whole number written in digits keeps every digit (read
    as a float, two seeds past 2**53 would give the same run)."""
    raw = top.get("seed", 0)
    if isinstance(raw, int) and not isinstance(raw, bool):
        if raw < 0:
            raise WorldError(f"seed must be at least 0, not {raw}", span=top.value_span("seed"))
        return raw
    seed = r.number(top, "seed", "the world file", 0.0, minimum=0, sane=False)
    if seed != int(seed) or seed > 2 ** 53:
        raise WorldError("seed must be a whole number, written in digits",
                         span=top.value_span("seed"))
    return int(seed)


#: cells of the robot's map of a corridor world (2 in each, knowledge.RASTER): 5e6 is a
#: building of 4,470 x 4,470 in (114 m square); a run takes about 160 bytes a cell (a corridor
#: of 18e6 cells took 2.9 GB)
MAX_RASTER_CELLS = 5_000_000


def _check_extent(corridors: list[Corridor], span: Span | None) -> None:
    """Refuse corridors whose bounding box the robot's map (a raster of 2 in cells, made when
    it must plan round something) cannot hold: it was a NumPy allocation of hundreds of GiB."""
    from .knowledge import RASTER

    xs = [x for c in corridors for x, _ in c.points]
    ys = [y for c in corridors for _, y in c.points]
    margin = max(c.width for c in corridors)
    width, height = max(xs) - min(xs) + margin, max(ys) - min(ys) + margin
    cells = (width / RASTER + 2) * (height / RASTER + 2)
    if cells > MAX_RASTER_CELLS:
        raise WorldError(f"the corridors span {width:,.0f} x {height:,.0f} in: the robot's map "
                         f"of them would be {cells:,.0f} cells of {RASTER:g} in, and at most "
                         f"{MAX_RASTER_CELLS:,} fit", span=span,
                         hint="a smaller building, or a `grid` map at a coarser resolution")


def _not_a_termset(doc: Any, span: Span) -> None:
    """Refuse a term set named as a world, saying so: "unknown key `variables` in the world
    file" said nothing of what the file was."""
    if isinstance(doc, YMap) and "variables" in doc and not any(k in doc for k in TOP_KEYS):
        raise WorldError(f"`{span.path}` is a term set, not a world file", span=span,
                         expected="a world: `name`, `q_init`, `q_goal`, `map` and more",
                         hint="a rule file reads a term set through its `terms` line; "
                              "`mitos plot terms` and `mitos check` take one alone")


def _not_a_map(doc: Any, span: Span) -> None:
    """Refuse a map_server map YAML named as a world (`mitos simulate worlds/maps/m.yaml`),
    saying so: "unknown key `image` in the world file" said nothing of what the file was."""
    if isinstance(doc, YMap) and "image" in doc and "resolution" in doc \
            and not any(k in doc for k in TOP_KEYS):
        name = Path(span.path or "map.yaml").name
        raise WorldError(f"`{span.path}` is a map (map_server's YAML: `image`, `resolution`), "
                         f"not a world file", span=span,
                         expected="a world: `name`, `q_init`, `q_goal`, `map` and more",
                         hint=f"a world drives on it by naming it, `map: {{grid: {name}}}` "
                              f"(`mitos docs worlds`; the packaged world `office` is one)")


def parse_world(text: str, path: str) -> World:
    """Parse world YAML ``text`` (read from ``path``, which anchors relative map paths)."""
    r = _Reader(path)
    doc = yamlpos.load(text, path, WorldError)
    _not_a_termset(doc, Span.in_text(text, path, 1, 1))
    _not_a_map(doc, Span.in_text(text, path, 1, 1))
    top = r.mapping(doc, Span.in_text(text, path, 1, 1), "the world file", TOP_KEYS,
                    _pose_keys_elsewhere(doc) | _robot_keys_elsewhere(doc, "`robot:`"))
    name = _name(top)
    seed = _seed(r, top)
    dt, limit, substeps = _timing(r, top)
    robot = read_robot(r, yamlpos.require(top, "robot", WorldError, "the world file"),
                       top.value_span("robot"), dt=dt)
    sensors = _sensors(r, top)
    agents, agent_spans = _agents(r, top, robot, dt)
    corridors, grid, knows, given = _map(r, top, path)
    min_clearance, replan = _route(r, top, agents)
    obstacles = _obstacles(r, top, dt)
    randomise = (read_randomise(r, top["randomise"], top.value_span("randomise"),
                                [o.name for o in obstacles], tuple(a.name for a in agents))
                 if "randomise" in top else Randomise())
    world = World(name, path, seed, dt, limit, substeps, tuple(agents), sensors,
                  tuple(corridors), grid, tuple(obstacles), randomise,
                  _behavior(top), knows, given, min_clearance, replan,
                  top.value_span("behavior") if "behavior" in top else None)
    static = check_free(world, agent_spans)
    check_starts(world, [s for s, _ in agent_spans])
    check_goals(world, [g for _, g in agent_spans])
    if "randomise" in top:
        check_jitters(world, top["randomise"].get("obstacles"))
    notes = [*(grid.notes if grid else ()), *(given.notes if given else ()),
             *walled_in(world, static, top)]
    return replace(world, notes=tuple(notes)) if notes else world


def _name(top: YMap) -> str:
    """The world's ``name``: text, printable (it is printed in every table and title)."""
    yamlpos.require(top, "name", WorldError, "the world file")
    return _label(top, "the world's", "corridor (it heads every verdict and table)")


def _label(m: YMap, whose: str, example: str) -> str:
    """``m``'s ``name`` as text, printable and not blank: a robot's or an obstacle's was taken
    as written, so `name:` named it `None`, `name: ""` left its table row and CSV rows blank
    and `name: [a, b]` printed `['a', 'b']`."""
    name, span = m["name"], m.value_span("name")
    name = "" if name is None else name             # `name:` written with nothing
    if not isinstance(name, str):                   # `name: [1, 2]` printed as a title
        raise WorldError(f"{whose} `name` must be text", span=span,
                         hint=f'quote it: name: "{name}"' if type(name) in (int, float)
                         else f"name: {example.split(' (')[0]}")
    if any(not c.isprintable() for c in name):
        raise WorldError(f"{whose} name holds a control character", span=span,
                         hint="letters, digits, `-`, `_`, spaces")
    if not name.strip():                            # a verdict of `: TIMEOUT after 1 s`
        raise WorldError(f"{whose} `name` is empty", span=span, hint=f"name: {example}")
    return name


def _count(n: float) -> str:
    """A large count in words a reader takes in: `1e-300` as dt made time_limit 60 a count
    of 302 digits, most of them a float's noise; `5e-324` made it `inf`."""
    if n == math.inf:
        return "over 1e308"
    return f"{n:,.0f}" if n < 1e15 else f"{n:.3g}"


def _timing(r: _Reader, top: YMap) -> tuple[float, float, int]:
    """``dt``, ``time_limit`` and ``substeps``: at least one tick, at most ``MAX_TICKS``."""
    dt = r.number(top, "dt", "the world file", None, positive=True, maximum=1.0)
    limit = r.number(top, "time_limit", "the world file", None, positive=True)
    if limit < dt:                                  # no tick would be run: no result
        raise WorldError(f"time_limit {limit:g} s is shorter than one tick (dt {dt:g} s)",
                         span=top.value_span("time_limit"),
                         expected=f"a time_limit of at least dt ({dt:g} s)")
    if limit / dt > MAX_TICKS:
        raise WorldError(f"time_limit {limit:g} s at dt {dt:g} s is {_count(limit / dt)} ticks; a "
                         f"run takes at most {MAX_TICKS:,}", span=top.value_span("dt"),
                         hint="a larger dt (0.05 s is the packaged worlds'), or a shorter "
                              "time_limit")
    substeps = r.number(top, "substeps", "the world file", 1.0, minimum=1, maximum=100)
    if substeps != int(substeps):                   # `substeps: 2.5` ran 2, without a word
        raise WorldError("`substeps` in the world file must be a whole number",
                         span=top.value_span("substeps"), expected="a count of integration steps "
                         "per tick, such as 4 (the packaged worlds')")
    return dt, limit, int(substeps)


def _sensors(r: _Reader, top: YMap) -> Sensors:
    """``sensors``, or the default ring."""
    return (read_sensors(r, top["sensors"], top.value_span("sensors"))
            if "sensors" in top else Sensors())


def _agents(r: _Reader, top: YMap, robot: Robot,
            dt: float) -> tuple[list[Agent], list[tuple[Span, Span]]]:
    """The first robot (``robot``, read already, ``q_init``, ``q_goal``) and the others under
    ``robots`` (their own ``robot`` or the first's), each with the spans of its start and
    goal (their checks point there)."""
    start = read_pose(r, yamlpos.require(top, "q_init", WorldError, "the world file"),
                      top.value_span("q_init"), "q_init")
    goal = read_goal(r, yamlpos.require(top, "q_goal", WorldError, "the world file"),
                     top.value_span("q_goal"), "q_goal")
    agents = [Agent("robot", robot, start, goal)]
    agent_spans = [(top.value_span("q_init"), top.value_span("q_goal"))]
    unnamed: set[str] = set()                   # the names given by place (`robot3`)
    for i, item in enumerate(_list(top, "robots")):
        span = top["robots"].item_span(i)
        named = item.get("name") if isinstance(item, YMap) else None
        who = (f"robot `{named}`" if isinstance(named, str) and named.strip()
               and named.isprintable() else f"robot {i + 2}")       # (its name is checked below)
        a = r.mapping(item, span, who, AGENT_KEYS,
                      {**_shared_keys_elsewhere(False, item),
                       **_robot_keys_elsewhere(item, "this robot's `robot:`")})
        aname = (_label(a, f"robot {i + 2}'s", "oncoming (it heads its column and CSV rows)")
                 if "name" in a else f"robot{i + 2}")
        _check_agent_name(a, aname, agents, span, unnamed)
        if "name" not in a:
            unnamed.add(aname)
        if "robot" in a and a["robot"] is None:
            raise WorldError(f"the `robot:` of `{aname}` is empty", span=a.value_span("robot"),
                             expected="the robot keys it changes, such as "
                                      "`robot: {max_speed: 40}`",
                             hint=f"or leave `robot:` out: `{aname}` is then the same robot "
                                  "as the first")
        arobot = (read_robot(r, a["robot"], a.value_span("robot"), robot, dt,
                             f"robot `{aname}`") if "robot" in a else robot)
        agents.append(Agent(aname, arobot,
                            read_pose(r, yamlpos.require(a, "q_init", WorldError, f"robot `{aname}`"),
                                      a.value_span("q_init"), f"q_init of `{aname}`"),
                            read_goal(r, yamlpos.require(a, "q_goal", WorldError, f"robot `{aname}`"),
                                      a.value_span("q_goal"), f"q_goal of `{aname}`")))
        agent_spans.append((a.value_span("q_init"), a.value_span("q_goal")))
    agents = [replace(agent, start_span=s, goal_span=g)
              for agent, (s, g) in zip(agents, agent_spans)]
    return agents, agent_spans


def _check_agent_name(a: YMap, aname: str, agents: list[Agent], span: Span,
                      unnamed: set[str]) -> None:
    """Refuse a robot's name that another robot has, or that heads the summary table's
    column of all the robots (``all robots``); an unnamed robot is named by its place
    (``robot3``, and ``unnamed`` holds those names), which a named one may have taken."""
    if aname == "all robots":
        raise WorldError("`all robots` heads the summary's column of every robot: a robot "
                         "cannot be named so", span=a.value_span("name"),
                         hint="name: oncoming (it heads its column and CSV rows)")
    if not any(b.name == aname for b in agents):
        return
    if "name" not in a:
        raise WorldError(f"this robot has no `name`, so it is called `{aname}`, as an earlier "
                         f"robot is named", span=span,
                         hint="give it a name of its own: `name: ...`")
    first = (" (the first robot, under `robot:`, is `robot`)" if aname == "robot" else
             f" (an earlier robot has no `name` and is called `{aname}` by its place)"
             if aname in unnamed else "")
    raise WorldError(f"two robots are named `{aname}`{first}: give each a name of its own",
                     span=a.value_span("name"))


#: the most corridor points a world may have in all: each corridor piece's walls are clipped by
#: the pieces they meet, so a polyline doubling back on itself costs the square of its points
#: (1,500 such points took 39 s and 2 GB to load); a building of more is a `grid:` map
MAX_CORRIDOR_POINTS = 1000


def _check_corridor_points(corridors: list[Corridor], mp: YMap) -> None:
    """Refuse more than :data:`MAX_CORRIDOR_POINTS` corridor points, at the corridor that
    passes the limit."""
    total = 0
    for i, c in enumerate(corridors):
        total += len(c.points)
        if total > MAX_CORRIDOR_POINTS:
            raise WorldError(f"the corridors have more than {MAX_CORRIDOR_POINTS:,} points "
                             f"({total:,} up to corridor {i + 1})",
                             span=mp["corridors"].item_span(i),
                             expected=f"at most {MAX_CORRIDOR_POINTS:,} points in all",
                             hint="draw a building of more as a map image (`grid: map.yaml`), "
                                  "or drop points along the straight stretches")


def _map(r: _Reader, top: YMap, path: str
         ) -> tuple[list[Corridor], Grid | None, str, Grid | None]:
    """``map``: its corridors, its grid (a map_server YAML), and what the robot is given."""
    mp = r.mapping(yamlpos.require(top, "map", WorldError, "the world file"),
                   top.value_span("map"), "map", MAP_KEYS)
    corridors = []
    for i, item in enumerate(_list(mp, "corridors")):
        c = r.mapping(item, mp["corridors"].item_span(i), f"corridor {i + 1}", ("points", "width"))
        pts = r.points(yamlpos.require(c, "points", WorldError, f"corridor {i + 1}"),
                       c.value_span("points"), f"`points` of corridor {i + 1}", 2)
        corridors.append(Corridor(pts, r.number(c, "width", f"corridor {i + 1}", positive=True)))
    _check_corridor_points(corridors, mp)
    unknown_occupied = r.choice(mp, "unknown", ("occupied", "free"), "map", "occupied") == "occupied"
    grid = None
    if "grid" in mp:
        from .gridmap import load_map_yaml

        _check_grid_path(mp)
        grid = load_map_yaml(Path(path).parent / str(mp["grid"]),
                             unknown_occupied=unknown_occupied, where=mp.value_span("grid"),
                             written=str(mp["grid"]))
    if not corridors and grid is None:
        raise WorldError("the map has neither `corridors` nor a `grid`", span=mp.span,
                         hint="add `corridors: [{points: [[0, 0], [600, 0]], width: 70}]`")
    if grid is None:
        _check_extent(corridors, mp.value_span("corridors"))
    knows, given = read_given(mp, path, unknown_occupied)
    return corridors, grid, knows, given


def _check_grid_path(mp: YMap) -> None:
    """``map.grid`` is a path: an empty ``grid:`` was "map file `None` not found", and
    ``grid: [m.yaml]`` "map file `['m.yaml']` not found"."""
    value, span = mp["grid"], mp.value_span("grid")
    if value is not None and not isinstance(value, (list, dict, bool)) and str(value).strip():
        return
    from .gridmap import not_a_path

    what = "is empty" if value is None or isinstance(value, str) else \
        f"must be a map_server YAML file, not {not_a_path(value)}"
    raise WorldError(f"`grid` in map {what}", span=span, expected="PATH.yaml",
                     hint="`grid: maps/office.yaml`: the map's YAML, relative to this world file")


def _route(r: _Reader, top: YMap, agents: list[Agent]) -> tuple[float | None, str]:
    """``route``: the least clearance the route keeps (None: the robot's own) and how it is
    replanned."""
    if "route" not in top:
        return None, "clearance"
    rt = r.mapping(top["route"], top.value_span("route"), "route", ROUTE_KEYS)
    min_clearance = (r.number(rt, "min_clearance", "route", positive=True)
                     if "min_clearance" in rt else None)
    if min_clearance is not None:
        _check_squeeze(min_clearance, rt.value_span("min_clearance"), agents)
    return min_clearance, r.choice(rt, "replan", REPLANS, "route", "clearance")


def _check_squeeze(least: float, span: Span, agents: list[Agent]) -> None:
    """Refuse a ``min_clearance`` below half a robot's width: it lets the route lead the
    centre through a gap the body cannot pass (`min_clearance: 8.8` through a 17.7 in door
    took the 18 in robot into the jamb), as no squeeze the refusals offer does."""
    widest = max(agents, key=lambda a: a.robot.width)
    half = widest.robot.width / 2
    if least >= half:
        return
    who = "the robot's" if len(agents) == 1 else f"robot `{widest.name}`'s"
    own = half + widest.robot.safety_margin
    raise WorldError(f"`min_clearance` in route must be at least {half:g} in, half {who} "
                     f"width ({widest.robot.width:g} in), not {least:g}: the route could lead "
                     "its centre through a gap its body does not pass", span=span,
                     expected=f"a min_clearance of at least {half:g} in",
                     hint=f"leave it out for the robot's own ({own:g} in: half its width and "
                          "its safety margin), or squeeze no closer than "
                          f"`min_clearance: {half:g}`")


def _obstacles(r: _Reader, top: YMap, dt: float) -> list[Obstacle]:
    """``obstacles``, each named once, none moving farther in a tick than its own size."""
    obstacles = [read_obstacle(r, item, top["obstacles"].item_span(i), i)
                 for i, item in enumerate(_list(top, "obstacles"))]
    counts = Counter(o.name for o in obstacles)     # names.count per obstacle was N^2
    for i, o in enumerate(obstacles):
        if counts[o.name] > 1:
            raise WorldError(f"two obstacles are named `{o.name}`",
                             span=top["obstacles"].item_span(i))
        if o.speed * dt > o.size:
            m = top["obstacles"][i]
            key = "velocity" if "velocity" in m else "speed"
            raise WorldError(f"obstacle `{o.name}` moves {o.speed * dt:.3g} in a tick (at "
                             f"{o.speed:g} in/s, dt {dt:g} s), farther than its own size "
                             f"({o.size:g} in): the robots sense it once a tick, so it "
                             "would pass them between two looks", span=m.value_span(key),
                             expected=f"a speed of at most {o.size / dt:.4g} in/s at this dt",
                             hint="speeds are in inches a second (the packaged cart's: 15); "
                                  "or a smaller `dt`")
    return obstacles


def _left_empty(span: Span) -> bool:
    """Whether a null value at ``span`` was written as nothing (``given:``, ``{given: }``), not
    as ``null`` or ``~``; where the line is not known, it was written."""
    if span.source_line is None:
        return False
    rest = span.source_line[max(0, span.column - span.source_start):].strip()
    return not rest or rest[0] in "#,}]"


def read_given(mp: YMap, path: str, unknown_occupied: bool) -> tuple[str, Grid | None]:
    """``map.given``: the robot's own map (a map_server YAML), ``none``, or (absent) the map."""
    if "given" not in mp:
        return "map", None
    value = mp["given"]
    span = mp.value_span("given")
    if value is None and _left_empty(span):
        # an empty `given:` quietly meant "no map at all", as an empty `unknown:` does not
        raise WorldError("`given:` in map is empty", span=span,
                         expected="a map_server YAML file or `none`",
                         hint="`given: none` for a robot with no map, `given: maps/told.yaml` for "
                              "the map it is told; leave `given` out: it plans on the map itself")
    if value is None or str(value).lower() in ("none", "null", "~"):
        return "none", None
    if not isinstance(value, str) or not value.strip():
        raise WorldError("`given` in map must be a map_server YAML file or `none`", span=span,
                         hint="`given: maps/office02_given.yaml`, or `given: none` for a robot "
                              "with no map")
    if not value.endswith((".yaml", ".yml")):
        raise WorldError(f"`given` in map must be `none` or a map_server YAML file, not "
                         f"`{value}`", span=span, expected="none or PATH.yaml",
                         hint=did_you_mean(value, ("none",)))
    from .gridmap import load_map_yaml

    return "given", load_map_yaml(Path(path).parent / value, unknown_occupied=unknown_occupied,
                                  where=span, written=value)


def _behavior(top: YMap) -> str:
    """The behavior the world names (``drive`` when none); an empty one is not `None`."""
    value = top.get("behavior", "drive")
    if not isinstance(value, str) or not value.strip():
        raise WorldError("behavior must be the name of a behavior of the rule base",
                         span=top.value_span("behavior"), hint="`behavior: drive`, or leave "
                         "the line out for the packaged `drive`")
    return value


def check_free(world: World, spans: list[tuple[Span, Span]]) -> StaticMap:
    """Refuse a start or goal that lies inside a wall (outside every corridor) or inside an
    obstacle where it stands when the run starts, and a start where the robot's body already
    reaches into a wall: each run would end at its first tick. Returns the static map."""
    import numpy as np

    from .staticmap import build_static

    static = build_static(world)
    for agent, (s_span, g_span) in zip(world.agents, spans):
        for what, p, span in (("start (q_init)", agent.start, s_span),
                              ("goal (q_goal)", agent.goal, g_span)):
            who = _who(agent)
            if not static.free(np.array([[p.x, p.y]]))[0]:
                off = _off_the_grid(static, p.x, p.y)
                if off is not None:
                    raise WorldError(f"the {what}{who} at ({p.x:g}, {p.y:g}) {off}", span=span,
                                     hint="check the map's `origin` and `resolution` (metres, "
                                          "in its YAML) and the point (inches)")
                grey = _unknown_cell(world, p.x, p.y)
                room = _nearest_room(static, agent, p.x, p.y)
                if grey is not None:
                    raise WorldError(f"the {what}{who} at ({p.x:g}, {p.y:g}) {grey}", span=span,
                                     hint=f"move it where the map is free{room}, or write "
                                          "`unknown: free` under `map:` to read unknown cells "
                                          "as free")
                raise WorldError(f"the {what}{who} at ({p.x:g}, {p.y:g}) lies inside a wall",
                                 span=span, hint=_units_hint(world, agent)
                                 or (f"move it where the map is free{room}" if room else
                                     "move it into a corridor (free space)"))
            # a moving obstacle leaves the goal (as `randomise` may move one over it); over
            # the start it is there at the first tick
            hit = _obstacle_at(world, p.x, p.y, still=what.startswith("goal"))
            if hit is not None:
                raise WorldError(f"the {what}{who} at ({p.x:g}, {p.y:g}) lies inside obstacle "
                                 f"`{hit}` (where it stands at the start)", span=span,
                                 hint="move it, or the obstacle")
        _check_body(world, agent, static, s_span)
        _check_goal_room(world, agent, static, g_span)
    return static


def _nearest_room(static: StaticMap, agent: Agent, x: float, y: float) -> str:
    """Where a start or goal given in a wall of a grid map might go instead: ``` (the nearest
    point with room for the robot turned any way: (812, -340))``, the nearest whole-inch point
    whose distance to every occupied (or unknown) cell leaves the robot's half diagonal and
    its safety margin. A user's own map gives no hint of which coordinates are free (an
    office map is mostly wall and unknown), and the world cannot be drawn until it loads.
    Empty for a map of corridors (which says "move it into a corridor"), or where no cell
    has that much room."""
    import numpy as np

    from .distance import squared_distances

    g = static.grid
    if g is None:
        return ""
    r = agent.robot
    # cell centres measure to cell centres: a wall's edge lies up to half a cell's diagonal
    # nearer, and a point rounded to whole inches up to 0.71 in further
    need = math.hypot(r.length, r.width) / 2 + r.safety_margin + g.resolution + 1.0
    need_sq = (need / g.resolution) ** 2                     # in cells, squared
    margin = int(math.ceil(need / g.resolution)) + 1         # cells a distance there can see
    rows, cols = g.occupied.shape
    # the point's cell, clipped to the map (a point off it is refused before this is asked)
    pr = min(max(int((y - g.origin[1]) // g.resolution), 0), rows - 1)
    pc = min(max(int((x - g.origin[0]) // g.resolution), 0), cols - 1)
    # a window round the point, widened until the nearest cell with room in it is nearer
    # than the window's edge (then none outside is nearer): a large map is never measured
    # whole, and a map whose every cell is far from the point ends at the whole map
    padded = np.pad(g.occupied, 1, constant_values=True)    # beyond the edge is solid
    reach = 32
    while True:
        r0, r1 = max(pr - reach, 0), min(pr + reach + 1, rows)
        c0, c1 = max(pc - reach, 0), min(pc + reach + 1, cols)
        # the window and the margin round it, in the padded map's indices (one more)
        pr0, pc0 = max(r0 + 1 - margin, 0), max(c0 + 1 - margin, 0)
        window = padded[pr0:r1 + 1 + margin, pc0:c1 + 1 + margin]
        top, left = r0 + 1 - pr0, c0 + 1 - pc0
        sq = squared_distances(window, 1.0, cap=margin)[top:top + r1 - r0, left:left + c1 - c0]
        found_r, found_c = np.nonzero(sq >= need_sq)
        whole = r0 == 0 and c0 == 0 and r1 == rows and c1 == cols
        if len(found_r):
            d2 = (found_r + r0 - pr) ** 2 + (found_c + c0 - pc) ** 2
            i = int(np.argmin(d2))
            if d2[i] <= reach ** 2 or whole:
                break
        elif whole:
            return ""
        reach *= 4
    cx = g.origin[0] + (found_c[i] + c0 + 0.5) * g.resolution
    cy = g.origin[1] + (found_r[i] + r0 + 0.5) * g.resolution
    return (f" (the nearest point with room for the robot turned any way: "
            f"({cx:.0f}, {cy:.0f}))")


#: in: how far apart the points of a goal's disc are looked at at most, and in how many
#: rings at most (:func:`_check_goal_room`): a wide tolerance is looked at more coarsely
GOAL_SAMPLE, GOAL_RINGS = 0.5, 40


def _check_goal_room(world: World, agent: Agent, static: StaticMap, span: Span) -> None:
    """Refuse a goal whose tolerance the robot's centre can never come within: every point of
    the disc lies nearer a wall or a still obstacle than half the robot's width, so no pose
    of its body puts its centre there (a goal 2 in from a wall with a tolerance of 5 in was
    driven at until the time limit, a timeout no planner could avoid). The disc is looked at
    every ``step`` in, and a goal is refused only where it falls short by more than that, so
    a goal the body can reach is never refused."""
    import numpy as np

    g, half = agent.goal, agent.robot.width / 2
    step = max(GOAL_SAMPLE, g.tolerance / GOAL_RINGS)
    reach = g.tolerance + half + step
    if _room(world, static, np.array([[g.x, g.y]]), reach)[0] >= half:
        return                                  # the goal itself has room: most goals
    pts = _disc(g.x, g.y, g.tolerance, step)
    walls = max(1, len(static.near(g.x, g.y, reach)))
    size = max(1, 2_000_000 // walls)           # points at a time: a bounded [P, walls]
    room = np.concatenate([_room(world, static, pts[i:i + size], reach, (g.x, g.y))
                           for i in range(0, len(pts), size)])
    best = float(room.max())
    if best + step >= half:
        return
    near = pts[int(np.argmax(room))]
    keep = max(agent.robot.length, agent.robot.width) / 2 + agent.robot.safety_margin
    raise WorldError(
        f"the goal (q_goal){_who(agent)} at ({g.x:g}, {g.y:g}) cannot be reached: within its "
        f"tolerance ({g.tolerance:g} in) the robot's centre keeps at most {best:.1f} in from "
        f"the walls and still obstacles (at ({near[0]:.1f}, {near[1]:.1f})), and its body, "
        f"{agent.robot.width:g} in wide, needs {half:g} in to stand there at all", span=span,
        hint=f"move the goal into the open, or widen its tolerance so that the robot can "
             f"reach it head-on, its centre half its length and its safety margin ({keep:g} "
             f"in) off the wall (`tolerance: {math.ceil(g.tolerance + keep - best - 1e-9)}` or more)")


def _disc(x: float, y: float, radius: float, step: float) -> np.ndarray:
    """Points ``[P, 2]`` of the disc of ``radius`` round (x, y): its centre and rings ``step``
    apart, their points about as far apart along each ring."""
    import numpy as np

    out = [np.array([[x, y]])]
    rings = int(np.ceil(radius / step))
    for k in range(1, rings + 1):
        r = radius * k / rings
        n = max(6, int(np.ceil(2 * np.pi * r / step)))
        a = np.arange(n) * (2 * np.pi / n)
        out.append(np.stack([x + r * np.cos(a), y + r * np.sin(a)], axis=1))
    return np.concatenate(out)


def _room(world: World, static: StaticMap, pts: np.ndarray, reach: float,
          centre: tuple[float, float] | None = None) -> np.ndarray:
    """Each point's distance ``[P]`` (in) to the nearest wall or still obstacle (0 off the
    free space and inside an obstacle; ``reach`` where none lies nearer than ``reach`` of
    ``centre``, default the first point)."""
    import numpy as np

    from .geometry import point_segment_distance, points_in_polygon
    from .obstacles import positions, shapes_at

    x, y = centre if centre is not None else (float(pts[0, 0]), float(pts[0, 1]))
    room = np.full(len(pts), reach)
    walls = static.near(x, y, reach)
    if len(walls):
        room = np.minimum(room, point_segment_distance(pts, walls).min(axis=1))
    still = tuple(o for o in world.obstacles if o.motion.kind == "static")
    if still:
        centres, radii, _, sides, _, corners = shapes_at(still, positions(still, 0.0))
        if len(centres):
            gap = np.hypot(pts[:, None, 0] - centres[None, :, 0],
                           pts[:, None, 1] - centres[None, :, 1]) - radii[None]
            room = np.minimum(room, np.maximum(gap, 0.0).min(axis=1))
        if len(sides):
            room = np.minimum(room, point_segment_distance(pts, sides).min(axis=1))
            room[np.asarray(points_in_polygon(pts, corners)).any(axis=1)] = 0.0
    room[~static.free(pts)] = 0.0
    return room


def _unknown_cell(world: World, x: float, y: float) -> str | None:
    """``lies in an unknown cell of the map `m.yaml` ...`` for a point whose cell is blocked
    only because it is unknown (grey, between the thresholds), else ``None``: "inside a wall
    ... move it into a corridor" sent the user of a SLAM map looking for a wall in a room its
    scan left grey."""
    from .gridmap import unknown_at, unknown_words

    g = world.grid
    if g is None or not unknown_at(g.source, x, y):
        return None
    return unknown_words(f"the map `{Path(g.source).name}`")


def _off_the_grid(static: StaticMap, x: float, y: float) -> str | None:
    """``lies outside the map `m.yaml` (x .. to .., y .. to .. in)`` for a point off the
    world's grid (all of which is wall: a wrong ``origin`` put every point there), else
    ``None``."""
    if static.grid is None:
        return None
    x0, y0, x1, y1 = static.bounds
    if x0 <= x < x1 and y0 <= y < y1:
        return None
    name = f" `{Path(static.grid.source).name}`" if static.grid.source else ""
    return f"lies outside the map{name} (x {x0:.6g} to {x1:.6g}, y {y0:.6g} to {y1:.6g} in)"


def _units_hint(world: World, agent: Agent) -> str | None:
    """Where a corridor is narrower than the robot, a hint that world lengths are inches
    (`width: 1.8`, metres by mistake, made the start "lie inside a wall" and said no more)."""
    narrow = [c.width for c in world.corridors if c.width < agent.robot.width]
    if not narrow:
        return None
    w = min(narrow)
    return (f"lengths in a world are inches: a corridor `width: {w:g}` is narrower than the "
            f"robot ({agent.robot.width:g} in wide){_as_metres(w, agent.robot.width)}")


def _as_metres(x: float, need: float) -> str:
    """``; if 1.8 is metres, write 71`` for a length that reads as metres and, so read, is at
    least ``need`` inches, else nothing (`width: 0.3` was told "write 12", still narrower than
    the robot, and `width: 0.001` "write 0", which the reader refuses)."""
    inches = f"{x / 0.0254:.0f}"
    return f"; if {x:g} is metres, write {inches}" if x < 20 and float(inches) >= need else ""


def walled_in(world: World, static: StaticMap, top: YMap) -> list[str]:
    """Warnings (``path:line:col: ...``) for obstacles that lie entirely inside a wall where
    they start, or that `randomise` can move entirely into one. Not refused: such an
    obstacle is harmless (no beam or robot reaches it), only pointless, and a generated or
    randomised world may hold one; but it is likely a mistake the user should hear of."""
    if not world.obstacles:
        return []
    notes = []
    written: YList = top["obstacles"]
    jitters = {j.obstacle: j for j in world.randomise.obstacles}
    moves: YMap | None = top["randomise"].get("obstacles") if "randomise" in top else None
    for i, o in enumerate(world.obstacles):
        if o.motion.kind != "static":           # it may come out of one (a doorway), but
            into = _moves_into_wall(static, o, world.time_limit)   # not go into one
            if into is not None:
                notes.append(f"{written.item_span(i)}: obstacle `{o.name}` moves into a wall "
                             f"at ({into[1]:g}, {into[2]:g}) after {into[0]:g} s: a mover "
                             "passes through walls here, where a real one would stop (check "
                             "its `waypoints` or `velocity`)")
            continue
        if _inside_wall(static, o, (o.x, o.y)):
            notes.append(f"{written.item_span(i)}: obstacle `{o.name}` at ({o.x:g}, {o.y:g}) "
                         "lies entirely inside a wall: no beam or robot can reach it (move "
                         "it into a corridor, or drop it)")
        elif moves is not None and o.name in jitters:
            off = _walled_offset(static, o, jitters[o.name])
            if off is not None:
                notes.append(f"{moves.value_span(o.name)}: randomise can move obstacle "
                             f"`{o.name}` entirely into a wall (dx {off[0]:g}, dy {off[1]:g} in "
                             f"puts it at ({o.x + off[0]:g}, {o.y + off[1]:g})): those runs "
                             "have no such obstacle (narrow its dx and dy)")
    return notes


#: The most places of a mover's way :func:`_moves_into_wall` looks at (about 0.1 s of a load).
MOVER_SAMPLES = 20_000


def _moves_into_wall(static: StaticMap, o: Obstacle, limit: float
                     ) -> tuple[float, float, float] | None:
    """When and where (``t, x, y``, rounded to 0.1) the centre of the moving obstacle ``o``
    first passes from free space into a wall within ``limit`` seconds, looked at every inch
    of its way (every 0.1 s where it moves slower; at most :data:`MOVER_SAMPLES` places, so
    a fast mover over a long time limit is looked at more coarsely, not for minutes), or
    None."""
    import numpy as np

    from .obstacles import position

    m = o.motion
    speed = float(np.hypot(*m.velocity)) if m.kind == "velocity" else m.speed
    if speed <= 0 or limit <= 0:
        return None
    span = min(limit, 3600.0)                   # (an hour of its way)
    step = max(min(0.1, 1.0 / speed), span / MOVER_SAMPLES)
    times = np.arange(int(span / step) + 1) * step
    at = np.array([position(o, float(t)) for t in times])
    free = static.free(at)
    into = np.flatnonzero(free[:-1] & ~free[1:])
    if not len(into):
        return None
    k = int(into[0]) + 1
    return round(float(times[k]), 1), round(float(at[k, 0]), 1), round(float(at[k, 1]), 1)


def _walled_offset(static: StaticMap, o: Obstacle, j: Jitter) -> tuple[float, float] | None:
    """An offset in `randomise`'s ranges (a 5 x 5 lattice over them, corners included) that
    puts ``o`` entirely inside a wall, or None."""
    import numpy as np

    for dx in np.linspace(j.dx[0], j.dx[1], 5):
        for dy in np.linspace(j.dy[0], j.dy[1], 5):
            if _inside_wall(static, o, (o.x + dx, o.y + dy)):
                return float(dx), float(dy)
    return None


def _inside_wall(static: StaticMap, o: Obstacle, at: tuple[float, float]) -> bool:
    """Whether obstacle ``o`` standing at ``at`` lies entirely in solid space: its centre is
    not free and no wall crosses or touches it."""
    import math

    import numpy as np

    from .geometry import box_segment_distance, point_segment_distance

    if static.free(np.array([at]))[0]:
        return False
    reach = o.radius if o.shape == "circle" else math.hypot(o.length, o.width) / 2
    walls = static.near(at[0], at[1], reach)
    if not len(walls):
        return True
    if o.shape == "circle":
        return bool(point_segment_distance(np.array([at]), walls).min() > o.radius)
    h = math.radians(o.angle)
    c, s = math.cos(h), math.sin(h)
    rel = walls.reshape(-1, 2) - at
    local = np.stack([rel[:, 0] * c + rel[:, 1] * s, -rel[:, 0] * s + rel[:, 1] * c], axis=1)
    return bool(box_segment_distance(o.length / 2, o.width / 2, local.reshape(-1, 4)).min() > 0)


def _obstacle_at(world: World, x: float, y: float, still: bool = False) -> str | None:
    """The name of the first obstacle that covers (x, y) when the run starts, or None;
    ``still``: of the obstacles that stay where they are (a goal under a cart that drives
    off was refused, where a `randomise` range that moves the cart over it is taken)."""
    import numpy as np

    from .geometry import points_in_polygon
    from .obstacles import positions, shapes_at

    obstacles = tuple(o for o in world.obstacles if not still or o.motion.kind == "static")
    if not obstacles:
        return None
    centres, radii, circ, _, _, corners = shapes_at(obstacles, positions(obstacles, 0.0))
    p = np.array([[x, y]])
    inside = np.hypot(*(centres - p).T) < radii
    if inside.any():
        return obstacles[int(circ[int(np.argmax(inside))])].name
    rect = [i for i, o in enumerate(obstacles) if o.shape == "rectangle"]
    if rect:
        within = np.asarray(points_in_polygon(p, corners))[0]
        if within.any():
            return obstacles[rect[int(np.argmax(within))]].name
    return None


def _who(agent: Agent) -> str:
    return "" if agent.name == "robot" else f" of `{agent.name}`"


def _body_corners(agent: Agent) -> np.ndarray:
    """The corners ``[4, 2]`` of ``agent``'s footprint at its start."""
    import math

    from .geometry import rect_corners

    st, robot = agent.start, agent.robot
    return rect_corners(st.x, st.y, math.radians(st.heading), robot.length, robot.width)


def _box_meets(hl: float, hw: float, centre: np.ndarray, heading: float, o: Obstacle,
              at: tuple[float, float]) -> bool:
    """Whether obstacle ``o`` standing at ``at`` reaches into the box ``[-hl, hl] x [-hw, hw]``
    centred at ``centre`` and turned ``heading`` rad (touching is not reaching in)."""
    return _box_gap(hl, hw, centre, heading, o, at) < 0.0


def _box_gap(hl: float, hw: float, centre: np.ndarray, heading: float, o: Obstacle,
             at: tuple[float, float]) -> float:
    """The signed distance from the box of :func:`_box_meets` to obstacle ``o`` at ``at``:
    the gap, 0 touching, minus the depth where it reaches in."""
    import math

    import numpy as np

    from .geometry import box_polygon_distance, rect_corners

    c, s = math.cos(heading), math.sin(heading)
    turn = np.array([[c, -s], [s, c]])                      # world -> box frame: @ turn
    if o.shape == "circle":
        x, y = (np.asarray(at, float) - centre) @ turn
        dx, dy = abs(x) - hl, abs(y) - hw
        inside = min(max(dx, dy), 0.0)                      # the box's signed distance
        return math.hypot(max(dx, 0.0), max(dy, 0.0)) + inside - o.radius
    corners = rect_corners(at[0], at[1], math.radians(o.angle), o.length, o.width)
    return float(box_polygon_distance(hl, hw, ((corners - centre) @ turn)[None])[0])


def check_starts(world: World, spans: list[Span]) -> None:
    """Refuse a start where a robot's body reaches into an obstacle or into another robot's
    body: the run would end in a collision at its first tick."""
    import math

    import numpy as np

    from .geometry import box_polygon_distance

    touch = " (a touch is a contact: the run would end in a collision at its first tick)"
    # each body lies within the circle of its half diagonal about its centre: two robots
    # whose circles are apart are not measured (every pair was: 400 robots took 12 s)
    xs = np.array([a.start.x for a in world.agents])
    ys = np.array([a.start.y for a in world.agents])
    reach = np.array([math.hypot(a.robot.length / 2, a.robot.width / 2)
                      for a in world.agents])
    for i, (agent, span) in enumerate(zip(world.agents, spans)):
        st, robot = agent.start, agent.robot
        hl, hw, h = robot.length / 2, robot.width / 2, math.radians(st.heading)
        centre = np.array([st.x, st.y])
        where = (f"at the start (q_init){_who(agent)}, ({st.x:g}, {st.y:g}) heading "
                 f"{st.heading:g} deg,")
        for o in world.obstacles:
            gap = _box_gap(hl, hw, centre, h, o, (o.x, o.y))
            if gap <= 0.0:              # (touching ended the run at 0.00 s, a collision)
                raise WorldError(f"{where} the robot's body ({robot.length:g} x "
                                 f"{robot.width:g} in) "
                                 + (f"reaches into obstacle `{o.name}`" if gap < 0.0 else
                                    f"touches obstacle `{o.name}`{touch}"),
                                 span=span, hint="move the start or the obstacle")
        c, s = math.cos(h), math.sin(h)
        apart = np.hypot(xs[:i] - st.x, ys[:i] - st.y)
        near = np.flatnonzero(apart <= (reach[:i] + reach[i]) * (1 + 1e-9) + 1e-9)
        for j in near:
            other = world.agents[j]
            local = (_body_corners(other) - centre) @ np.array([[c, -s], [s, c]])
            gap = float(box_polygon_distance(hl, hw, local[None])[0])
            if gap <= 0.0:
                raise WorldError(f"{where} the robot's body "
                                 + (f"overlaps robot `{other.name}`'s at its start" if gap < 0.0
                                    else f"touches robot `{other.name}`'s at its start{touch}"),
                                 span=span, hint="start the robots further apart")


def check_goals(world: World, spans: list[Span]) -> None:
    """Refuse two robots that cannot both stand at their goals: a robot at its goal parks
    there, an obstacle to the others, so the run could never end in success (two goals 0 in
    apart with tolerances of 12 and 1 in drove on to the time limit, as did a goal inside a
    robot that starts within its own goal's tolerance and so is parked from the first
    tick). ``spans``: each robot's goal, in the order of the world's agents."""
    for j, b in enumerate(world.agents):
        for i, a in enumerate(world.agents[:j]):
            for p, q, span in ((a, b, spans[j]), (b, a, spans[i])):
                found = _goal_taken(p, q)
                if found:
                    raise WorldError(found[0], span=span, hint=found[1])


def _parks_at_start(agent: Agent) -> bool:
    """Whether ``agent`` starts within its goal's tolerance: arrived at the first tick, it
    stays where it starts."""
    st, g = agent.start, agent.goal
    return math.hypot(st.x - g.x, st.y - g.y) <= g.tolerance


#: points on a goal's tolerance circle looked at (:func:`_goal_taken`)
GOAL_CIRCLE = 360


def _goal_taken(p: Agent, q: Agent) -> tuple[str, str] | None:
    """Why ``q`` may find no place at its goal once ``p`` stands at its own, or None. A robot
    stands at its goal with its centre anywhere within the tolerance, turned any way: ``p``
    where it entered its tolerance, and ``q`` wherever it finds room. A body is taken as
    the disc of half its narrower side about its centre (half its width, as
    :func:`_check_goal_room` keeps from walls), what every pose of it covers."""
    import numpy as np

    r = min(q.robot.length, q.robot.width) / 2
    g, t = q.goal, q.goal.tolerance
    if _parks_at_start(q):
        return None                    # (parked at both starts: check_starts refused it)
    if _parks_at_start(p):
        # the farthest that q's centre gets from p's body: on the circle of its tolerance
        # (the distance to a convex body is convex); between two of the points looked at
        # it is at most pi t / GOAL_CIRCLE farther
        st, body = p.start, p.robot
        h = math.radians(st.heading)
        a = np.linspace(0.0, 2 * math.pi, GOAL_CIRCLE, endpoint=False)
        dx, dy = g.x + t * np.cos(a) - st.x, g.y + t * np.sin(a) - st.y
        along = np.abs(dx * math.cos(h) + dy * math.sin(h)) - body.length / 2
        across = np.abs(-dx * math.sin(h) + dy * math.cos(h)) - body.width / 2
        far = float(np.hypot(np.maximum(along, 0.0), np.maximum(across, 0.0)).max())
        far += math.pi * t / GOAL_CIRCLE
        if far >= r:
            return None
        return (f"the goal (q_goal) of `{q.name}` at ({g.x:g}, {g.y:g}) is taken by "
                f"`{p.name}`, which starts within its own goal's tolerance and so stands "
                f"there from the first tick: within {t:g} in of the goal, `{q.name}`'s "
                f"centre comes at most {far:.1f} in from `{p.name}`'s body, and its own body "
                f"needs {r:g} in",
                f"move the goal, or start `{p.name}` farther from its own goal")
    # `p`, arrived first, parks where it enters its tolerance, which may be as close to
    # q's goal as `apart - tp` (on it, where that is negative); q's centre, within t of its
    # goal, then gets at most t farther from p's. Not where the two could stand at best
    # (`apart + tp + t`): two goals at one point with tolerances of 12 in were taken so, and
    # the robot that came second drove at the first, parked, till a collision or the time
    # limit (`fleet_tiny` so, with a time limit of 90 s: 1 success in 20 runs).
    rp = min(p.robot.length, p.robot.width) / 2
    pg, tp = p.goal, p.goal.tolerance
    apart = math.hypot(g.x - pg.x, g.y - pg.y)
    need = r + rp
    if t >= need or apart - tp + t >= need:
        return None
    least = need + tp - t
    return (f"the goals (q_goal) of `{p.name}` at ({pg.x:g}, {pg.y:g}) and `{q.name}` at "
            f"({g.x:g}, {g.y:g}) are {apart:.1f} in apart; two robots' goals must be at "
            f"least {least:g} in apart: half of each one's narrower side ({rp:g} + {r:g} in) "
            f"plus the first's tolerance less the second's ({tp:g} - {t:g} in). `{p.name}`, "
            f"arriving first, may park anywhere within {tp:g} in of its goal, and `{q.name}` "
            f"then has no room to stand within {t:g} in of its own",
            f"move the goals {math.ceil(least - apart - 1e-9)} in or more farther apart, "
            f"or widen `{q.name}`'s tolerance to {need:g} in")


def check_jitters(world: World, written: YMap) -> None:
    """Refuse a `randomise` range that can move an obstacle into a robot's body at its start
    or over a goal: every run drawn there would end at its first tick (a collision charged to
    the planner) or never reach its goal (``written``: the `randomise: obstacles:` mapping,
    for the positions)."""
    import numpy as np

    obstacles = {o.name: o for o in world.obstacles}
    for j in world.randomise.obstacles:
        o = obstacles[j.obstacle]
        for agent in world.agents:
            # a moving obstacle leaves the goal; over the start it is there at the first tick
            ends = (("start (q_init)", agent.start),) + (
                (("goal (q_goal)", agent.goal),) if o.motion.kind == "static" else ())
            for what, p in ends:
                if what.startswith("start"):
                    meets = _jitter_reaches_body(agent, o, j)
                    body = (f": into the robot's body ({agent.robot.length:g} x "
                            f"{agent.robot.width:g} in) there")
                else:
                    # the obstacle reaches p for some offset (dx, dy) in the ranges exactly
                    # when it meets the box of the points p - (dx, dy)
                    lo = np.array([p.x - j.dx[1], p.y - j.dy[1]])
                    hi = np.array([p.x - j.dx[0], p.y - j.dy[0]])
                    hl, hw = (hi - lo) / 2
                    meets = _box_meets(float(hl), float(hw), (lo + hi) / 2, 0.0, o, (o.x, o.y))
                    body = ""
                if meets:
                    raise WorldError(
                        f"randomise can move obstacle `{o.name}` over the {what}"
                        f"{_who(agent)} at ({p.x:g}, {p.y:g}){body} (dx {_range(j.dx)}, "
                        f"dy {_range(j.dy)} in)", span=written.value_span(o.name),
                        hint="narrow its dx and dy, or move the obstacle")


def _jitter_reaches_body(agent: Agent, o: Obstacle, j: Jitter) -> bool:
    """Whether obstacle ``o``, moved by an offset within jitter ``j``, reaches into
    ``agent``'s body at its start (touching is not reaching in): the body moved back by
    every offset (its footprint swept over the offsets' box) meets the obstacle where it
    stands. Only the start point was tested: a draw over the body's nose, not its centre,
    began every run of it in a collision."""
    import math

    import numpy as np

    from .geometry import box_polygon_depth, point_segment_distance, polygon_segments

    offsets = np.array([[dx, dy] for dx in j.dx for dy in j.dy])
    swept = _hull((_body_corners(agent)[:, None, :] - offsets[None]).reshape(-1, 2))
    if o.shape == "circle":
        centre = np.array([[o.x, o.y]])
        gap = float(point_segment_distance(centre, polygon_segments(swept[None])).min())
        edges = np.roll(swept, -1, axis=0) - swept
        to = centre - swept
        inside = bool((edges[:, 0] * to[:, 1] - edges[:, 1] * to[:, 0] > 0).all())
        return inside or gap < o.radius
    a = math.radians(o.angle)
    c, s = math.cos(a), math.sin(a)
    local = (swept - [o.x, o.y]) @ np.array([[c, -s], [s, c]])       # into its frame
    return bool(box_polygon_depth(o.length / 2, o.width / 2, local[None])[0] > 0.0)


def _hull(points: np.ndarray) -> np.ndarray:
    """The convex hull ``[k, 2]`` of ``points [P, 2]``, counter-clockwise (Andrew's monotone
    chain)."""
    import numpy as np

    pts = sorted(set(map(tuple, np.asarray(points, float).tolist())))
    if len(pts) < 3:
        return np.array(pts, float).reshape(-1, 2)

    def half(seq: list) -> list:
        out: list = []
        for p in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(p)
        return out

    return np.array(half(pts)[:-1] + half(pts[::-1])[:-1], float)


def _range(r: tuple[float, float]) -> str:
    return f"{r[0]:g}" if r[0] == r[1] else f"{r[0]:g} to {r[1]:g}"


def _check_body(world: World, agent: Agent, static: StaticMap, span: Span) -> None:
    """Refuse a start where the robot's footprint already touches a wall: the run would end
    in a collision at its first tick. Where it touches only unknown (grey) cells of the map,
    the refusal says so."""
    import math

    robot, (x, y, h) = agent.robot, (agent.start.x, agent.start.y,
                                      math.radians(agent.start.heading))
    if not _touches(static, x, y, h, robot.length / 2, robot.width / 2):
        return
    where = f"at the start (q_init){_who(agent)}, ({x:g}, {y:g}) heading {agent.start.heading:g} " \
        f"deg, the robot's body ({robot.length:g} x {robot.width:g} in) reaches into"
    lenient = _lenient_static(world)
    if lenient is not None and lenient.grid is not None and \
            not _touches(lenient, x, y, h, robot.length / 2, robot.width / 2):
        raise WorldError(f"{where} an unknown cell of the map `{Path(lenient.grid.source).name}` "
                         "(grey, between its free_thresh and occupied_thresh), which counts as "
                         "a wall", span=span,
                         hint=f"move the start further from the grey"
                              f"{_nearest_room(static, agent, x, y)}, or write `unknown: free` "
                              "under `map:` to read unknown cells as free")
    raise WorldError(f"{where} a wall", span=span,
                     hint=_units_hint(world, agent) or "move the start further from the wall"
                     f"{_nearest_room(static, agent, x, y)}, or turn it along the corridor")


def _touches(static: StaticMap, x: float, y: float, h: float, hl: float, hw: float) -> bool:
    """Whether a box of half-length ``hl`` and half-width ``hw`` at (x, y) heading ``h``
    (rad) touches a wall of ``static``."""
    import math

    import numpy as np

    from .geometry import box_segment_distance

    walls = static.near(x, y, math.hypot(hl, hw))
    if not len(walls):
        return False
    c, s = math.cos(h), math.sin(h)
    rel = walls.reshape(-1, 2) - (x, y)
    local = np.stack([rel[:, 0] * c + rel[:, 1] * s, -rel[:, 0] * s + rel[:, 1] * c], axis=1)
    return bool(box_segment_distance(hl, hw, local.reshape(-1, 4)).min() <= 0.0)


def _lenient_static(world: World) -> StaticMap | None:
    """The world's static map with its grid's unknown cells read free (for a refusal's
    words only: the map is read again), or ``None`` without a grid read from a file."""
    from .gridmap import load_map_yaml
    from .staticmap import build_static

    g = world.grid
    if g is None or not g.source:
        return None
    try:
        lenient = load_map_yaml(Path(g.source), unknown_occupied=False)
    except MitosError:
        return None
    return build_static(world.with_changes(grid=lenient))


def load_world(path: str | Path) -> World:
    """Read and check the world file at ``path``. A path that is not a file but names a
    packaged world (``figure4``, ``worlds/figure4.yaml``) reads the packaged one, as the
    command line and the Gymnasium environments do, so the documented calls work from any
    directory; anything else is an :class:`UnknownWorld` with the packaged names."""
    from ..fileio import bad_byte, named_yaml, read_text, text_encoding_hint, unreadable
    from ..resources import is_file

    path = Path(_world_path_given(path))
    if not is_file(path):
        path = resolve_world_path(path)
    try:
        text = read_text(path)
    except (OSError, UnicodeDecodeError) as exc:
        raise WorldError(unreadable("world file", path, exc), span=bad_byte(path, exc),
                         hint=text_encoding_hint(exc)) from None
    if not named_yaml(path):
        # Until the file is known to be a world, an error quotes nothing of it (a lesson may
        # name any file; docs/security.md).
        try:
            doc = yamlpos.load(text, str(path), WorldError)
        except WorldError:
            doc = None
        if not (isinstance(doc, dict) and "map" in doc):
            raise WorldError(f"`{path}` is not a world file", span=Span(str(path), 1, 1),
                             expected="a YAML file with `map:` (see `mitos docs worlds`)")
    return parse_world(text, str(path))


def map_files(path: str | Path) -> list[Path]:
    """The files the world file at ``path`` reads besides itself: the map_server YAML of
    ``map.grid`` and of ``map.given``, and each one's image, as far as they are named (a
    world that does not read is refused where it is loaded). A study's digest of a world
    covers them: an edited map was resumed as the same world, its runs mixed with the old."""
    from ..fileio import read_text

    def named(file: Path, key: str, within: str) -> Path | None:
        try:
            if not file.is_file():              # (a FIFO would be waited on without end)
                return None
            doc = yamlpos.load(read_text(file), str(file), WorldError)
        except (MitosError, OSError, UnicodeDecodeError, ValueError):
            return None
        if within:
            doc = doc.get(within) if isinstance(doc, dict) else None
        value = doc.get(key) if isinstance(doc, dict) else None
        return file.parent / value if isinstance(value, str) and value.strip() else None

    out = []
    for key in ("grid", "given"):
        spec = named(Path(path), key, "map")
        # (`given: none`; a given map is a .yaml, a grid any file that reads as a map file)
        if spec is None or key == "given" and spec.suffix.lower() not in (".yaml", ".yml"):
            continue
        image = named(spec, "image", "")
        out += [spec] + ([image] if image is not None else [])
    return out


def _world_path_given(path: object) -> str | os.PathLike:
    """``path`` if it can name a file; else a :class:`WorldError` saying what a world is
    given as (a dict or an int reached ``Path()``, whose TypeError said nothing of worlds)."""
    if isinstance(path, (str, os.PathLike)):
        _named(path)
        return path
    if isinstance(path, World):
        hint = "it is loaded already: give it to simulate() or Simulation() as it is"
    elif isinstance(path, dict):
        hint = ("write it to a .yaml file, or give its YAML text to "
                "mitos_cli.sim.worldfile.parse_world(text, 'name.yaml')")
    else:
        hint = "load_world('worlds/corridor.yaml'), or a packaged world's name: load_world('corridor')"
    raise WorldError(f"a world is read from a file: expected a path or a packaged world's name, "
                     f"not {type(path).__name__} `{path!r:.60}`", hint=hint)


def _named(path: str | os.PathLike) -> None:
    """A :class:`WorldError` if ``path`` is empty: ``Path("")`` is ``.``, and "`.` is a
    directory" named a path the user never gave."""
    if isinstance(path, str) and not path:
        raise WorldError("the world's name is empty",
                         hint="give a world file's path, or a packaged world's name such as "
                              "`corridor`")


class UnknownWorld(WorldError, NameError_):
    """A world name that is neither a file nor a packaged world (an unknown name, of a world)."""

    kind = "world error"


def resolve_world_path(name: str | Path, base: Path | None = None) -> Path:
    """The one way a world is found: a file as given (relative to ``base`` first, when a
    lesson names it), else the packaged world of that name (``figure4`` or ``figure4.yaml``);
    an unknown name gets the packaged names and a "did you mean"."""
    from ..resources import exists, is_dir, resolve

    _named(name)
    found = resolve("worlds", name, ".yaml", base)
    if found is not None:
        return found
    where = Path(name) if base is None else base / name
    if str(name) == "-":            # as `eval --batch -` and `teach --lesson -` read stdin
        raise UnknownWorld("a world is read from its file, not from standard input (`-`)",
                           hint="save it to a file and name that (a map it names is found "
                                "beside the world's file)")
    if is_dir(where):
        raise UnknownWorld(f"`{name}` is a directory, not a world file",
                           hint="name one of the world files (.yaml) in it")
    if exists(where):                               # a FIFO, a device: there, but not found
        raise UnknownWorld(f"`{name}` is not a regular file (a pipe or a device), not a world "
                           "file", hint="name a world file (.yaml), or a packaged world")
    from ..fileio import broken_link

    for given in dict.fromkeys([where, Path(name)]):    # a dangling link, a loop: it is there
        why = broken_link("world file", given)
        if why is not None:
            raise WorldError(why)
    raise world_not_found(name, where)


def _beside(where: Path, given: Path, packaged: list[str]) -> str | None:
    """"did you mean" a file that is there: one beside ``where`` (the path looked for first:
    beside the lesson that names the world), else beside ``given`` (the working directory),
    else a packaged world's name, written in ``given``'s directory, which finds it. A lesson's
    `simulate worlds/figur4.yaml` was offered `LESSONDIR/worlds/figure4.yaml`, a file that is
    not there: the packaged name was put in the lesson's directory."""
    from ..fileio import nearby_name
    from ..resources import is_file

    for place in dict.fromkeys([where, given]):
        name = nearby_name(place, (".yaml", ".yml"), packaged)
        if name is not None:
            at = place.parent if is_file(place.parent / name) else given.parent
            return f"did you mean `{(at / name).as_posix()}`?"
    return None


def world_not_found(name: str | Path, where: Path) -> UnknownWorld:
    """"world file `X` not found" (``where``: the path looked for), with the closest of the
    files beside it and, where the name may be a packaged world's, the packaged worlds. The packaged names are
    listed when the name was one's (``slalm``) or is close to one, not for any path
    (``nosuch.yaml``, ``foo/nosuch.yaml``: "did you mean office.yaml" was the shared ``.yaml``)."""
    from ..errors import closest_file
    from ..fileio import repository_only
    from ..resources import packaged_names, packaged_place

    given = Path(name)
    packaged = list(packaged_names("worlds", ".yaml"))
    # `worlds/slalon.yaml` from anywhere: `worlds/NAME.yaml` is a packaged world's name too
    maybe_packaged = packaged if packaged_place(given.parent.as_posix(), "worlds") else []
    bare = not given.suffix and len(given.parts) == 1      # a packaged world's name
    shown = packaged if given.suffix else [n[:-len(".yaml")] for n in packaged]
    close = closest_file(given.name, shown) if len(given.parts) == 1 else None
    hint = f"did you mean `{close}`?" if close else None
    if given.suffix or len(where.parts) > 1:      # a path: a file beside it first
        hint = _beside(where, given, maybe_packaged) or hint
    elif close is None:                           # `tiny` for the `tiny.yaml` beside it
        hint = _beside(where, given, [])
    same_name = given.name if given.name.endswith(".yaml") else given.name + ".yaml"
    if len(given.parts) > 1 and same_name in packaged:
        hint = (f"there is no `{given}`; the packaged world of that name is "
                f"`{same_name[:-len('.yaml')]}`")
    listing = ("one of the packaged worlds: " + ", ".join(shown)) if bare or close else None
    if any(c in given.name for c in "*?["):       # `worlds/*.yaml` away from the repository
        hint = (f"no file here matches the pattern, so the shell passed `{name}` on as "
                f"written; the packaged worlds go by name: `mitos list` shows them")
    if hint is None and listing is None:       # `tests/data/tiny.yaml` away from the repository
        hint = repository_only(name) or \
            "`mitos list` shows the packaged worlds, which are found by name (`slalom`)"
    return UnknownWorld(f"world file `{name}` not found", expected=listing, hint=hint)
