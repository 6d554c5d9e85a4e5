"""A :class:`World` built or changed in Python (``dataclasses.replace``), checked before a run
as :mod:`.worldfile` checks a world file's numbers and names: a ``time_limit`` of NaN was a
bare ``ValueError`` in the loop, one of 0 "no tick recorded yet", an infinite one an
``OverflowError``. Each refusal is a :class:`WorldError` naming the field
(``agents[0].robot.max_speed``); a world read from a file passes, having been checked there.
What needs the map (a start inside a wall) is the reader's alone."""

from __future__ import annotations

import math
from numbers import Integral, Real
from typing import NoReturn

from ..errors import WorldError, did_you_mean
from .safety import TIGHTEST_TURN, fastest_point, swing_words, tightest_turn
from .world import REPLANS, Agent, Obstacle, Robot, World
from .worldfile import BEYOND, LARGEST, LAYOUTS, MAX_TICKS, MODELS, MODES, SHAPES

#: what a world's ``knows`` may be (:func:`.worldfile.read_given`)
KNOWS = ("map", "given", "none")
#: the fields of a point that is a dataclass's ``x`` and ``y``
XY = (".x", ".y")


def check_built(world: World) -> None:
    """Refuse ``world`` unless its numbers and names are what a world file may hold."""
    c = _Fields(world.name)
    seed = world.seed
    if not isinstance(seed, Integral) or isinstance(seed, bool) or seed < 0:
        c.refuse("seed", seed, "a whole number of 0 or more")
    dt = c.number("dt", world.dt, positive=True, maximum=1.0)
    limit = c.number("time_limit", world.time_limit, positive=True)
    if limit < dt:
        c.refuse("time_limit", limit, f"at least dt ({dt:g} s): no tick would run")
    if limit / dt > MAX_TICKS:
        c.refuse("time_limit", limit, f"at most {MAX_TICKS:,} ticks of dt {dt:g} s "
                 f"({MAX_TICKS * dt:g} s)")
    c.number("substeps", world.substeps, minimum=1, maximum=100, whole=True)
    if not world.agents:
        c.refuse("agents", world.agents, "at least one Agent (the robot)")
    for i, agent in enumerate(world.agents):
        _agent(c, f"agents[{i}]", agent)
        _tick_drive(c, f"agents[{i}]", agent.robot, dt)
    _sensors(c, world)
    for i, corridor in enumerate(world.corridors):
        if not isinstance(corridor.points, (tuple, list)) or len(corridor.points) < 2:
            c.refuse(f"corridors[{i}].points", corridor.points,   # (min() of no points in NumPy)
                     "a list of at least 2 points (x, y)")
        for j, p in enumerate(corridor.points):
            c.point(f"corridors[{i}].points[{j}]", p)
        c.number(f"corridors[{i}].width", corridor.width, positive=True)
    for name in ("grid", "given"):
        grid = getattr(world, name)
        if grid is not None:
            c.number(f"{name}.resolution", grid.resolution, positive=True)
            c.point(f"{name}.origin", grid.origin)
    for i, o in enumerate(world.obstacles):
        _obstacle(c, f"obstacles[{i}]", o)
        if o.speed * dt > o.size:           # (as a world file's; see worldfile._obstacles)
            key = "velocity" if o.motion.kind == "velocity" else "speed"
            c.refuse(f"obstacles[{i}].motion.{key}", getattr(o.motion, key),
                     f"at most {o.size / dt:.4g} in/s at dt {dt:g} s: a tick's move farther "
                     f"than the obstacle's own size ({o.size:g} in) passes the robots between "
                     "two of their looks")
    _randomise(c, world)
    c.choice("replan", world.replan, REPLANS)
    c.choice("knows", world.knows, KNOWS)
    if world.knows == "given" and world.given is None:
        c.refuse("given", None, "the Grid the robot is given, as `knows` is \"given\"")
    if not world.corridors and world.grid is None:
        c.refuse("corridors", world.corridors, "at least one Corridor, where there is no grid")
    if world.min_clearance is not None:
        least = c.number("min_clearance", world.min_clearance, positive=True)
        half = max(a.robot.width for a in world.agents) / 2
        if least < half:
            c.refuse("min_clearance", least, f"at least half the widest robot's width ({half:g} "
                     "in): the route could lead its centre through a gap its body does not pass")


def _agent(c: _Fields, at: str, agent: Agent) -> None:
    r = agent.robot
    c.choice(f"{at}.robot.model", r.model, MODELS)
    length = c.number(f"{at}.robot.length", r.length, positive=True)
    c.number(f"{at}.robot.width", r.width, positive=True)
    wheelbase = c.number(f"{at}.robot.wheelbase", r.wheelbase, positive=True)
    if wheelbase > length:
        c.refuse(f"{at}.robot.wheelbase", wheelbase, f"at most the robot's length ({length:g} "
                 "in): its wheels must fit under its body")
    c.number(f"{at}.robot.safety_margin", r.safety_margin, minimum=0)
    low = c.number(f"{at}.robot.steering_min", r.steering_min, minimum=0, maximum=180)
    high = c.number(f"{at}.robot.steering_max", r.steering_max, minimum=0, maximum=180)
    if low >= high:                 # (else the straight wheel was blamed for lying between)
        c.refuse(f"{at}.robot.steering_min", low, f"below steering_max ({high:g})")
    straight = c.number(f"{at}.robot.steering_straight", r.steering_straight)
    if not low < straight < high:
        c.refuse(f"{at}.robot.steering_straight", straight,
                 f"between steering_min ({low:g}) and steering_max ({high:g})")
    radius = tightest_turn(r)
    if not radius >= TIGHTEST_TURN:   # (the brake's sweep asked for terabytes at 1e-10 in)
        raise WorldError(f"world `{c.world}`: robot `{agent.name}`: its tightest turn has a "
                         f"radius of {radius:.3g} in (wheelbase {r.wheelbase:.3g} in, steering "
                         f"{low:g} to {high:g} deg, straight {straight:g}): a tricycle turns "
                         f"about a point at least {TIGHTEST_TURN:g} in from its rear axle",
                         hint="a longer wheelbase (in inches), or a lock under 90 deg nearer "
                              "straight")
    c.number(f"{at}.robot.max_steering_rate", r.max_steering_rate, positive=True)
    c.number(f"{at}.robot.max_speed", r.max_speed, positive=True)
    c.number(f"{at}.robot.acceleration", r.acceleration, positive=True)
    c.number(f"{at}.robot.max_reverse", r.max_reverse, minimum=0)
    c.point(f"{at}.start", (agent.start.x, agent.start.y), XY)
    c.number(f"{at}.start.heading", agent.start.heading)
    c.point(f"{at}.goal", (agent.goal.x, agent.goal.y), XY)
    c.number(f"{at}.goal.tolerance", agent.goal.tolerance, positive=True)


def _tick_drive(c: _Fields, at: str, robot: Robot, dt: float) -> None:
    """A tick's move of any point of the body at most the robot's length, as a world file's
    (it senses and brakes once a tick)."""
    swing = fastest_point(robot)
    for key in ("max_speed", "max_reverse"):
        if getattr(robot, key) * dt * swing > robot.length:
            c.refuse(f"{at}.robot.{key}", getattr(robot, key),
                     f"at most {robot.length / (dt * swing):.4g} in/s at dt {dt:g} s: a "
                     f"tick's move of the body farther than the robot's length "
                     f"({robot.length:g} in) passes things between two of its looks "
                     f"({swing_words(swing)})")


def _sensors(c: _Fields, world: World) -> None:
    s = world.sensors
    c.choice("sensors.layout", s.layout, LAYOUTS)
    c.number("sensors.count", s.count, minimum=1, maximum=720, whole=True)
    c.number("sensors.fov", s.fov, positive=True, maximum=360)
    c.number("sensors.cone", s.cone, minimum=0, maximum=90)
    c.number("sensors.range", s.range, positive=True)
    c.number("sensors.noise", s.noise, minimum=0)


def _obstacle(c: _Fields, at: str, o: Obstacle) -> None:
    c.choice(f"{at}.shape", o.shape, SHAPES)
    c.point(at, (o.x, o.y), XY)
    if o.shape == "circle":
        c.number(f"{at}.radius", o.radius, positive=True)
    else:
        c.number(f"{at}.length", o.length, positive=True)
        c.number(f"{at}.width", o.width, positive=True)
        c.number(f"{at}.angle", o.angle)
    m = o.motion
    if o.known and m.kind != "static":
        c.refuse(f"{at}.known", o.known, "False for an obstacle that moves: the robot's map "
                 "holds only what stays put")
    c.choice(f"{at}.motion.kind", m.kind, ("static", "velocity", "waypoints"))
    if m.kind == "velocity":
        c.point(f"{at}.motion.velocity", m.velocity)
    elif m.kind == "waypoints":
        if not m.waypoints:
            c.refuse(f"{at}.motion.waypoints", m.waypoints, "at least one point [x, y]")
        for j, p in enumerate(m.waypoints):
            c.point(f"{at}.motion.waypoints[{j}]", p)
        c.number(f"{at}.motion.speed", m.speed, positive=True)
        c.choice(f"{at}.motion.mode", m.mode, MODES)


def _randomise(c: _Fields, world: World) -> None:
    names = [o.name for o in world.obstacles]
    for i, j in enumerate(world.randomise.obstacles):
        c.choice(f"randomise.obstacles[{i}].obstacle", j.obstacle, tuple(names))
        c.span(f"randomise.obstacles[{i}].dx", j.dx)
        c.span(f"randomise.obstacles[{i}].dy", j.dy)
    noise = world.randomise.sensor_noise
    if noise is not None and c.span("randomise.sensor_noise", noise)[0] < 0:
        c.refuse("randomise.sensor_noise", noise, "a range of noise of 0 or more")


class _Fields:
    """The checks, each refusal naming the world and the field."""

    def __init__(self, world: str) -> None:
        self.world = world

    def refuse(self, field: str, value: object, expected: str, hint: str | None = None
               ) -> NoReturn:
        shown = repr(float(value)) if isinstance(value, float) else f"{value!r:.60}"
        raise WorldError(f"world `{self.world}`: `{field}` must be {expected}, not {shown}",
                         hint=hint or "a World built or changed in Python is checked as its "
                                      "world file would be")

    def number(self, field: str, value: object, *, positive: bool = False,
               minimum: float | None = None, maximum: float | None = None,
               whole: bool = False) -> float:
        if not isinstance(value, Integral if whole else Real) or isinstance(value, bool):
            self.refuse(field, value, "a whole number (an int)" if whole else "a number")
        x = float(value)
        if not math.isfinite(x):
            self.refuse(field, value, "a finite number")
        if abs(x) > LARGEST and (maximum is None or x <= maximum):
            name = field.rsplit(".", 1)[-1]               # the world file's key, for BEYOND
            key = {"max_steering_rate": "max_rate"}.get(name, name.removeprefix("steering_"))
            self.refuse(field, value, f"within ±{LARGEST:g} ("
                        f"{BEYOND.get(key, 'world lengths are in inches: 1e7 in is 254 km')})")
        if positive and x <= 0:
            self.refuse(field, value, "positive")
        if minimum is not None and x < minimum:
            self.refuse(field, value, f"at least {minimum:g}")
        if maximum is not None and x > maximum:
            self.refuse(field, value, f"at most {maximum:g}")
        return x

    def point(self, field: str, value: object, parts: tuple[str, str] = ("[0]", "[1]")
              ) -> tuple[float, float]:
        """A pair of numbers, ``parts`` naming them (``.x``, ``.y`` of a pose)."""
        if not isinstance(value, (tuple, list)) or len(value) != 2:
            self.refuse(field, value, "a point (x, y) in inches")
        return (self.number(field + parts[0], value[0]), self.number(field + parts[1], value[1]))

    def span(self, field: str, value: object) -> tuple[float, float]:
        if not isinstance(value, (tuple, list)) or len(value) != 2:
            self.refuse(field, value, "a range (low, high)")
        lo, hi = self.point(field, value)
        if lo > hi:
            self.refuse(field, value, "a range (low, high) with low <= high")
        return lo, hi

    def choice(self, field: str, value: object, options: tuple[str, ...]) -> None:
        """One of ``options``, a misspelt one with a "did you mean" as the reader gives
        (``model="tricycl"`` ran as a tricycle)."""
        if value not in options:
            near = did_you_mean(value, options) if isinstance(value, str) else None
            self.refuse(field, value, _one_of(options), near)


def _one_of(options: tuple[str, ...], shown: int = 8) -> str:
    """What a choice expects: its options, or the first few of many (a world of 300 obstacles
    listed every name)."""
    if not options:
        return "a name the world has, and it has none"
    if len(options) <= shown:
        return "one of " + ", ".join(options)
    return f"one of {len(options)} names: {', '.join(options[:shown])}, ..."
