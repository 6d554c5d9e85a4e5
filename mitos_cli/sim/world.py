"""The world model: frozen dataclasses read from a world file by :mod:`.worldfile`.

Units everywhere: inches, seconds, degrees (headings counter-clockwise from +x, the usual
mathematical convention; steering 90 = straight, below 90 = left).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import Span


@dataclass(frozen=True)
class Pose:
    """A robot pose: the centre of its footprint (in) and its heading (deg, CCW from +x)."""

    x: float
    y: float
    heading: float = 0.0


@dataclass(frozen=True)
class Goal:
    x: float
    y: float
    tolerance: float = 12.0        # in: success when the footprint centre is this close


@dataclass(frozen=True)
class Robot:
    """The paper's tricycle: one front wheel that steers and drives, two rear wheels."""

    model: str = "tricycle"
    wheelbase: float = 16.0        # in, rear axle to front wheel
    length: float = 24.0           # in, footprint (a rectangle centred on the pose)
    width: float = 18.0            # in
    safety_margin: float = 2.0     # in: clearance below this counts as a near miss
    steering_min: float = 30.0     # deg (wide left)
    steering_max: float = 150.0    # deg (wide right)
    steering_straight: float = 90.0
    max_steering_rate: float = 180.0   # deg/s
    max_speed: float = 60.0        # in/s
    acceleration: float = 40.0     # in/s^2 (also the braking limit)
    max_reverse: float = 15.0      # in/s: the front wheel drives backward too (0: it cannot)
    brake: bool = True             # the emergency brake and backing out (sim/safety.py)
    give_way: bool = True          # shares its route with the world's other robots and gives
                                   # way where routes cross (sim/traffic.py)


@dataclass(frozen=True)
class Sensors:
    """Ultrasonic range sensors: a ``ring`` round the robot or a ``fan`` facing forward."""

    layout: str = "ring"
    count: int = 36
    fov: float = 360.0             # deg covered (a ring always covers 360)
    cone: float = 15.0             # deg, beam width (widens what one beam sees)
    range: float = 150.0           # in
    noise: float = 0.0             # in, standard deviation of the range noise

    @property
    def angles(self) -> np.ndarray:
        """Beam directions relative to the heading (rad, counter-clockwise): a ring's from
        straight ahead round to the left, a fan's from its left edge clockwise (a fan of 360
        deg stops a step short of its right edge, which is its left: its first and last beams
        looked along one line)."""
        if self.layout == "ring":
            return np.deg2rad(np.arange(self.count) * (360.0 / self.count))
        half = np.deg2rad(self.fov) / 2.0
        if self.count == 1:
            return np.zeros(1)
        return np.linspace(half, -half, self.count, endpoint=self.fov < 360.0)


@dataclass(frozen=True)
class Corridor:
    """A polyline of corridor centre points (in) carved ``width`` wide out of solid space."""

    points: tuple[tuple[float, float], ...]
    width: float


@dataclass(frozen=True)
class Grid:
    """An occupancy grid: ``occupied[row, col]`` with row 0 at the bottom (y grows upward)."""

    occupied: np.ndarray           # bool [rows, cols]
    resolution: float              # in per cell
    origin: tuple[float, float]    # in, lower-left corner of cell (0, 0)
    source: str = ""
    notes: tuple[str, ...] = field(default=(), compare=False, repr=False)
    # what its map file says that is legal but likely a mistake (``path:line:col: ...``)

    __hash__ = object.__hash__     # frozen dataclass with an array: hash by identity, in C

    def __repr__(self) -> str:      # the generated one printed a summary of the array
        rows, cols = self.occupied.shape
        source = f" from {self.source}" if self.source else ""
        return f"<Grid {rows:,} x {cols:,} cells of {self.resolution:g} in{source}>"


@dataclass(frozen=True)
class Motion:
    """How an obstacle moves: ``static``, ``velocity`` (in/s) or ``waypoints`` at ``speed``."""

    kind: str = "static"
    velocity: tuple[float, float] = (0.0, 0.0)
    waypoints: tuple[tuple[float, float], ...] = ()
    speed: float = 0.0
    mode: str = "loop"             # waypoints: loop | ping-pong | stop


@dataclass(frozen=True)
class Obstacle:
    """A circle (``radius``) or a rectangle (``length`` x ``width`` turned by ``angle``)."""

    name: str
    shape: str                     # circle | rectangle
    x: float
    y: float
    radius: float = 0.0
    length: float = 0.0
    width: float = 0.0
    angle: float = 0.0             # deg
    motion: Motion = field(default_factory=Motion)
    known: bool = False            # drawn on the robot's map (the route avoids it)

    @property
    def size(self) -> float:
        """Its narrowest extent (in): the diameter, or the shorter side."""
        return 2 * self.radius if self.shape == "circle" else min(self.length, self.width)

    @property
    def speed(self) -> float:
        """How fast it moves (in/s): 0 when it stands."""
        m = self.motion
        return (math.hypot(*m.velocity) if m.kind == "velocity" else
                m.speed if m.kind == "waypoints" else 0.0)


@dataclass(frozen=True)
class Jitter:
    """A randomisation range for ``--runs``: uniform offsets added to an obstacle's place."""

    obstacle: str
    dx: tuple[float, float] = (0.0, 0.0)
    dy: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class Randomise:
    obstacles: tuple[Jitter, ...] = ()
    sensor_noise: tuple[float, float] | None = None   # uniform range of the noise std (in)


@dataclass(frozen=True)
class Agent:
    """One robot of the world with its start and goal (the first is "the" robot)."""

    name: str
    robot: Robot
    start: Pose
    goal: Goal
    goal_span: Span | None = field(default=None, compare=False, repr=False)
    # where the world file writes its q_goal (a goal its route cannot reach is reported there)
    start_span: Span | None = field(default=None, compare=False, repr=False)
    # and its q_init (a start its route cannot leave)


#: ``route: {replan}``: when a robot plans its route again (:func:`.knowledge.replan`)
REPLANS = ("clearance", "blocked", "never")


@dataclass(frozen=True)
class World:
    name: str
    path: str
    seed: int
    dt: float                      # s
    time_limit: float              # s
    substeps: int
    agents: tuple[Agent, ...]
    sensors: Sensors
    corridors: tuple[Corridor, ...]
    grid: Grid | None
    obstacles: tuple[Obstacle, ...]
    randomise: Randomise
    behavior: str = "drive"
    knows: str = "map"             # what the robot is given: the map itself ("map"), another
    given: Grid | None = None      # grid ("given", this one), or nothing at all ("none")
    min_clearance: float | None = None   # in: the tightest squeeze its route may make
    replan: str = "clearance"      # when the route is planned again: one of REPLANS
    behavior_span: Span | None = field(default=None, compare=False, repr=False)
    # where the world file names ``behavior`` (the rule base, which knows the behaviors, is
    # chosen later: an unknown name is reported there, pointing here)
    notes: tuple[str, ...] = field(default=(), compare=False, repr=False)
    # what the file says that is legal but likely a mistake (``path:line:col: ...``), for the
    # CLI to print as warnings; a run never reads them

    @property
    def robot(self) -> Robot:
        return self.agents[0].robot

    @property
    def known_obstacles(self) -> tuple[Obstacle, ...]:
        return tuple(o for o in self.obstacles if o.known)

    def with_changes(self, **changes: Any) -> World:     # World's own fields, each its type
        return replace(self, **changes)

    def __repr__(self) -> str:
        """One line (the generated one was 1,000 to 1,500 characters, every robot limit and
        obstacle field spelt out); the fields are attributes, ``dataclasses.asdict`` lists
        them all."""
        from ..words import plural

        robots = len(self.agents)
        models = sorted({a.robot.model for a in self.agents})
        grid = (f", {self.grid.occupied.shape[0]:,} x {self.grid.occupied.shape[1]:,} grid"
                if self.grid is not None else "")
        corridors = f", {plural(len(self.corridors), 'corridor')}" if self.corridors else ""
        return (f"<World {self.name!r} ({self.path}): {plural(robots, 'robot')} "
                f"({', '.join(models)}){corridors}{grid}, {plural(len(self.obstacles), 'obstacle')}, "
                f"seed {self.seed}, dt {self.dt:g} s, time limit {self.time_limit:g} s>")
