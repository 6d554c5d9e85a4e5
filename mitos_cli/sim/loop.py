"""The simulation loop: sense, perceive, plan (one batch for all robots), move; then verdict and
metrics. Stepping never draws; the :class:`SimResult` holds every tick as arrays.

Per tick ``k`` (time ``k * dt``): obstacles are placed at that time; each robot casts its beams
and perceives its inputs (the true values are computed afterwards, on demand, from the recorded
poses: :func:`true_inputs`); a robot whose footprint touches anything has collided
(the run ends); a robot within its goal's tolerance is done (it stops and stays as an obstacle);
the planner evaluates all active robots in one batch; the kinematics apply the steering-rate and
acceleration limits and integrate in ``substeps`` exact arcs. The run ends in ``success`` (every
robot at its goal), ``collision``, ``stuck`` or ``timeout``; a robot still driving when
another's collision or stuck ends the run reads ``stopped`` in its own outcome. A driving robot
is ``stuck`` when it drove less than ``STUCK_DISTANCE`` in ``STUCK_TIME`` (driven, not
displaced), or when in the last ``PROGRESS_TIME`` it came no more than ``PROGRESS_DISTANCE``
nearer its goal than the nearest it had been before them, neither in a straight line nor along
its route (the route's length left: a replanned route starts where the robot stands). The
second ends a robot that backs out and drives in again and again in one pocket; the successes
of the navigation benchmark went at most 32.1 s so (docs/navigation.md, night 13).

Randomness: ``SeedSequence(seed).spawn(1 + robots)``: the first stream randomises the world
(only when asked, for ``--runs``), then one stream of sensor noise per robot.
"""

from __future__ import annotations

import itertools
import math
import operator
import os
from collections.abc import Sequence
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from ..errors import CommandError, InputError, WorldError
from ..numbers import whole_number
from ..words import clearance as shown_clearance
from ..words import plural
from . import geometry, kinematics, knowledge, movers, perception, rows, safety, sensors, traffic
from . import obstacles as obs_mod
from .geometry import polygon_segments, rect_corners
from .planner import Percepts, Planner
from .route import NarrowPassage, Route, grid_route, plan_route
from .route import clearances as route_clearances
from .staticmap import StaticMap, build_static
from .world import Agent, Grid, World

if TYPE_CHECKING:
    from collections.abc import Callable

    from .obstacles import Shapes
    from .world import Robot

STUCK_TIME = 6.0        # s: a robot that drove less than STUCK_DISTANCE in it is stuck
STUCK_DISTANCE = 3.0    # in
PROGRESS_TIME = 40.0    # s: a robot that came no nearer its goal by PROGRESS_DISTANCE, in a
PROGRESS_DISTANCE = 1.0  # in  straight line or along its route, in it is stuck
BEHIND = 30.0           # in: a replanned route that starts this near behind the robot costs more
NEAR_SLACK = 24.0       # in: a robot's set of nearby walls is gathered again after this move
#: in^2: a squared move plainly within ``NEAR_SLACK`` (its rounding is some 1e-16 of it)
_WITHIN_SLACK = (NEAR_SLACK * (1.0 - 1e-9)) ** 2
#: in: the deepest contact the check between ticks may miss (:meth:`Simulation._between`)
GRAZE = 0.01
PATH_STEP = 4.0         # in: the spacing of the route points a planner is given (Percepts.path)
PATH_REACH = 100_000.0  # in: the farthest `path_reach` a planner may ask for (25,000 points)
OUTCOMES = ("success", "collision", "timeout", "stuck")
# a robot's own outcome may also be `stopped`: still driving when another robot's collision or
# stuck ended the run (the run's outcome is then that collision or stuck)
ROBOT_OUTCOMES = (*OUTCOMES, "stopped")


@dataclass(frozen=True)
class Scene:
    """What a run starts from: the true walls, what the robots are given, each one's route."""

    static: StaticMap
    routes: tuple[Route, ...]
    given: knowledge.Given | None = None
    plan_grid: Grid | None = None      # the cells each robot's own map starts from

    def __hash__(self) -> int:
        return id(self)


def clearances(world: World, agent: Agent) -> tuple[float, float]:
    """The clearance (in) ``agent``'s route asks for and the least it accepts
    (:func:`.route.clearances`, with the world's ``route: {min_clearance}``)."""
    return route_clearances(agent.robot, world.min_clearance)


def prepare(world: World, between: bool = True) -> Scene:
    """Walls, what the robots know and their routes (A* over the corridors or the grid they
    are given; the truth's own with the default ``given``). ``between``: a grid route refused
    by less than a node can stand off a passage's middle is looked for again between the
    cells (:func:`.route.grid_route`); ``False`` keeps the refusal of nodes at the cells'
    centres alone (the clutter suite's placements were decided by it)."""
    static = build_static(world)
    given = knowledge.given(world, static)
    routes = []
    for a in world.agents:
        asked, least = clearances(world, a)
        try:
            if given.plain and given.grid is None:
                routes.append(plan_route(static, world.corridors, a.start, a.goal, asked, least,
                                         half_width=a.robot.width / 2, between=between))
            else:
                known = StaticMap(given.walls, np.zeros((0, 4, 2)), given.grid, static.bounds)
                routes.append(grid_route(known, a.start, a.goal, asked, minimum=least,
                                         half_width=a.robot.width / 2,
                                         given=given.knows == "given", between=between))
        except WorldError as exc:       # no route to the goal: said at the goal's line
            if exc.span is None:        # (a start it cannot leave, at the start's)
                at_start = isinstance(exc, NarrowPassage) and exc.end == "start"
                exc.span = a.start_span if at_start else a.goal_span
                if len(world.agents) > 1:           # whose start and goal ("the corridors do
                    exc.message = f"robot `{a.name}`: {exc.message}"   # not connect ...")
            raise
    return Scene(static, tuple(routes), given, knowledge.plan_grid(given, static, world))


def _prepare_draw(world: World, randomised: bool, seed: int) -> Scene:
    """:func:`prepare` of a run's world; where the run is randomised and its draw moved an
    obstacle the robots are told of (``known: true``) so that no route is left, the refusal
    says so, with the seed that replays it: it read as the world's own ("the only way to the
    goal passes ..." at `q_goal`), though the world as written has its route."""
    try:
        return prepare(world)
    except WorldError as exc:
        drawn = {j.obstacle for j in world.randomise.obstacles}
        moved = [o for o in world.obstacles if o.known and o.name in drawn]
        if not randomised or not moved:
            raise
        where = ", ".join(f"`{o.name}` to ({o.x:.6g}, {o.y:.6g})" for o in moved)
        raise WorldError(
            f"the randomised run of seed {seed} drew {where}, where the robot is told it "
            f"stands (`known: true`), and then {exc.message}", span=exc.span,
            hint="narrow its range under `randomise:` so that every draw leaves the robot a "
                 f"way (`--seed {seed} --randomise` replays this one)") from None


def shared_scene(world: World, randomise: bool) -> Scene | None:
    """The scene every run of ``world`` can start from, prepared once; ``None`` when each
    randomised run must prepare its own, because its draw moves an obstacle drawn on the
    robots' map (``known: true``, as ``detour.yaml``'s cabinet): each run's robot is given
    its own map and route, as the run alone is (``--seed SEED+j --randomise``)."""
    if randomise:
        known = {o.name for o in world.obstacles if o.known}
        if any(j.obstacle in known and (j.dx != (0.0, 0.0) or j.dy != (0.0, 0.0))
               for j in world.randomise.obstacles):
            return None
    return prepare(world)


@dataclass
class SimResult:
    """A finished run: verdict, metrics and every tick as arrays (``T`` ticks, ``n`` robots)."""

    world: World
    seed: int
    planner: str
    outcome: str
    robot_outcomes: tuple[str, ...]
    collisions: int
    t: np.ndarray                  # [T] s
    pose: np.ndarray               # [T, n, 3] x, y (in), heading (deg)
    speed: np.ndarray              # [T, n] in/s
    steering: np.ndarray           # [T, n] deg (the wheel's actual angle)
    command: np.ndarray            # [T, n, 2] steering, speed commanded (Tick.command)
    ranges: np.ndarray             # [T, n, B] in (noisy readings)
    perceived: dict[str, np.ndarray]   # name -> [T, n]
    clearance: np.ndarray          # [T, n] in, footprint to the nearest thing
    obstacles: np.ndarray          # [T, O, 2] obstacle positions
    routes: tuple[Route, ...] = ()
    static: StaticMap | None = None
    active: np.ndarray | None = None   # [T, n] robot still driving at that tick
    progress: np.ndarray | None = None  # [T, n] arc length along each robot's route (in)
    replanned: tuple[tuple[int, int, Route], ...] = ()   # (tick, robot, new route) in order
    backed_out: tuple[tuple[int, int], ...] = ()   # (tick, robot) each backing-out began
    metrics: dict = field(default_factory=dict)    # the run's figures over all robots
    robot_metrics: tuple[dict, ...] = ()           # each robot's figures (name, outcome, ...)
    _true: dict | None = field(default=None, repr=False)

    def route_at(self, k: int, i: int) -> Route:
        """The route robot ``i`` followed at tick ``k`` (its last replan up to then); a tick or
        a robot the run does not have is an :class:`InputError` (a tick past the end gave the
        last route without a word, and a robot past the last an ``IndexError``)."""
        robots = len(self.routes)
        if (j := whole_number(i)) is None or not 0 <= j < robots:
            raise InputError(f"i is the index of one of the run's {plural(robots, 'robot')}, "
                             f"0 to {robots - 1}, not `{i!r:.40}`")
        if (tick := whole_number(k)) is None or not 0 <= tick < self.ticks:
            raise InputError(f"k is a tick of the run, 0 to {self.ticks - 1}, not `{k!r:.40}`")
        k, i = tick, j
        route = self.routes[i]
        for tick, j, r in self.replanned:
            if j == i and tick <= k:
                route = r
        return route

    @property
    def true(self) -> dict[str, np.ndarray]:
        """The inputs from the true geometry, name -> ``[T, n]`` (computed on first use from
        the recorded poses and obstacle places: stepping does not need them)."""
        if self._true is None:
            self._true = true_inputs(self)
        return self._true

    @property
    def ticks(self) -> int:
        return len(self.t)

    def __repr__(self) -> str:   # the generated one prints every array (144,000 characters)
        m = self.metrics
        robots = len(self.robot_outcomes)
        return (f"<SimResult {self.world.name!r} seed {self.seed}, {self.planner}: {self.outcome} "
                f"after {m.get('time_s', self.ticks * self.world.dt):g} s ({plural(self.ticks, 'tick')}"
                f"{f', {robots} robots' if robots > 1 else ''}), path "
                f"{m.get('path_length_in', 0.0):.1f} in, min clearance "
                f"{self.shown_clearance()} in>")

    def shown_clearance(self) -> str:
        """The run's least clearance as the verdict of ``mitos simulate`` prints it: to a
        tenth, with as many more digits as it takes to show which side of the robots' least
        safety margin it lies on (1.99 beside 2 is ``1.99``, not ``2.0``)."""
        margin = min((a.robot.safety_margin for a in self.world.agents), default=None)
        return shown_clearance(self.metrics.get("min_clearance_in", 0.0), margin)

    def _repr_png_(self) -> bytes | None:
        """A notebook shows the run as ``--plot`` draws it (nothing without matplotlib)."""
        try:
            import io

            from ..draw.world import draw_run
        except ImportError:
            return None
        try:
            fig = draw_run(self)
        except Exception:  # noqa: BLE001 - a picture is a courtesy; the repr still shows
            return None
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=80)
        import matplotlib.pyplot as plt

        plt.close(fig)
        return buf.getvalue()

    def summary(self) -> dict:
        """The ``--json`` contract: the run's figures over all robots and, when there are
        several, each robot's under ``robots``."""
        out = {"world": self.world.name, "seed": self.seed, "outcome": self.outcome,
               "reached_goal": all(o == "success" for o in self.robot_outcomes),
               **self.metrics}
        near = self.near_misses()
        if len(self.robot_metrics) > 1:
            out["robots"] = [{**m, "near_miss": flag} for m, flag in zip(self.robot_metrics, near)]
        out["near_miss"] = any(near) and self.outcome != "collision"
        return out

    def near_misses(self) -> list[bool]:
        """Per robot: it came closer than its ``safety_margin`` and did not collide."""
        return [m["min_clearance_in"] < a.robot.safety_margin and o != "collision"
                for a, m, o in zip(self.world.agents, self.robot_metrics, self.robot_outcomes)]


def _stop_ticks(res: SimResult) -> np.ndarray:
    """``[n]`` ticks each robot drove: to the tick it stopped at its goal, else the whole run."""
    assert res.active is not None, "Simulation.result() records who was active"
    stopped = ~res.active.reshape(res.ticks, len(res.robot_outcomes))
    return np.where(stopped.any(axis=0), stopped.argmax(axis=0) + 1, res.ticks)


def _moves(res: SimResult) -> int:
    """How many ticks the robots moved: every recorded tick, but for the last where the run
    ended on what was observed there (every robot at its goal, or a contact), which nothing
    moved on from. Timed as recorded ticks, a run read one tick late: figure4's contact,
    recorded at 14.65 s (its `--out` row, the `--runs` plot's label), read "after 14.70 s"."""
    ended_there = res.ticks and res.outcome in ("success", "collision")
    return res.ticks - 1 if ended_there else res.ticks


def _driven(res: SimResult) -> np.ndarray:
    """``[n]`` ticks each robot moved: until the tick it was observed at its goal, else as
    the run moved (:func:`_moves`)."""
    assert res.active is not None, "Simulation.result() records who was active"
    stopped = ~res.active.reshape(res.ticks, len(res.robot_outcomes))
    return np.where(stopped.any(axis=0), stopped.argmax(axis=0), _moves(res))


def _robot_metrics(res: SimResult, dt: float) -> tuple[dict, ...]:
    """Each robot's figures up to the tick it stopped (at its goal) or the run ended: its time,
    path, mean speed over that time and steering variation; its clearance over the whole run
    (a robot at its goal is still something the others can hit)."""
    out = []
    for i, (agent, outcome, ticks, moved) in enumerate(zip(
            res.world.agents, res.robot_outcomes, _stop_ticks(res).tolist(),
            _driven(res).tolist())):
        xy = res.pose[:ticks, i, :2]
        path = float(np.hypot(*np.diff(xy, axis=0).T).sum()) if len(xy) > 1 else 0.0
        time_s = float(moved * dt)
        out.append({
            "name": agent.name, "outcome": outcome, "reached_goal": outcome == "success",
            "time_s": round(time_s, 6), "path_length_in": path,
            "min_clearance_in": float(res.clearance[:, i].min()) if res.ticks else 0.0,
            "replans": sum(j == i for _, j, _ in res.replanned),
            "backouts": sum(j == i for _, j in res.backed_out),
            "mean_speed_in_s": path / time_s if time_s > 0 else 0.0,
            "steering_total_variation_deg":
                float(np.abs(np.diff(res.steering[:ticks, i])).sum())})
    return tuple(out)


def _metrics(res: SimResult, dt: float) -> dict:
    """The run's figures over all robots (one robot: its own): the time until the last robot
    stopped, the path and the steering variation summed over the robots, the mean speed of
    all the driving (total path over total driving time), the smallest clearance of any."""
    each = res.robot_metrics
    path = sum(m["path_length_in"] for m in each)
    driving = float(_driven(res).sum() * dt)
    return {"collisions": sum(m["outcome"] == "collision" for m in each),
            "time_s": round(float(_moves(res) * dt), 6), "path_length_in": path,
            "min_clearance_in": min(m["min_clearance_in"] for m in each),
            "replans": sum(m["replans"] for m in each),
            "backouts": sum(m["backouts"] for m in each),
            "mean_speed_in_s": path / driving if driving > 0 else 0.0,
            "steering_total_variation_deg": sum(m["steering_total_variation_deg"]
                                                for m in each),
            "ticks": int(res.ticks)}


def _footprints(pose: np.ndarray, robots: Sequence[Robot]) -> np.ndarray:
    return rect_corners(pose[:, 0], pose[:, 1], pose[:, 2],
                        np.array([r.length for r in robots]), np.array([r.width for r in robots]))


def _columns(*columns: np.ndarray) -> np.ndarray:
    """``np.stack(columns, axis=1)``, without its Python set-up (a tick makes a few)."""
    out = np.empty((len(columns[0]), len(columns)))
    for j, column in enumerate(columns):
        out[:, j] = column
    return out


class _Came(NamedTuple):
    """The move that brought a run's robots where they are: what :func:`kinematics.step`
    moved from (:meth:`Simulation.motion`), rows ``start:stop`` of its arrays (a batch's)."""

    motion: kinematics.Motion
    start: int
    stop: int

    def of_run(self) -> kinematics.Motion:
        a, b = self.start, self.stop
        m = self.motion
        return m if b - a == len(m[0]) else tuple(c[a:b] for c in m)   # type: ignore[return-value]


@dataclass(frozen=True)
class Tick:
    """What one tick recorded, rows are robots: the state the robots were in when they sensed,
    what they sensed and perceived, and what the planner commanded."""

    k: int
    t: float                        # s
    pose: np.ndarray                # [n, 3] x, y (in), heading (deg)
    speed: np.ndarray               # [n] in/s
    steering: np.ndarray            # [n] deg (the wheel's actual angle)
    #: [n, 2] steering (deg) and speed (in/s) commanded: the planner's (or step()'s), as the
    #: robot's own safety left them, held to its steering lock and top speeds (the drive
    #: takes no more; kinematics.hold_commands); before the rate and acceleration limits
    command: np.ndarray
    ranges: np.ndarray              # [n, B] in (noisy readings)
    block: np.ndarray = field(repr=False)   # [inputs, n]: the perceived rule inputs, a row each
    clearance: np.ndarray           # [n] in
    obstacles: np.ndarray           # [O, 2] obstacle positions
    active: np.ndarray              # [n] robot still driving after this tick's verdict
    progress: np.ndarray            # [n] arc length along each robot's route (in)

    @rows.once
    def inputs(self) -> dict[str, np.ndarray]:
        """name -> ``[n]`` perceived rule inputs: the rows of :attr:`block` (made when asked:
        a lockstep batch records a tick of each of its runs at once, and few are looked at)."""
        return dict(zip(perception.INPUTS, self.block))

    @classmethod
    def _of(cls, *values: Any) -> Tick:
        """``Tick(*values)`` (every field, in order), its fields written at once: the frozen
        ``__init__`` sets them one ``object.__setattr__`` at a time, twice the cost, and a
        lockstep batch records a tick of each of its runs every tick."""
        tick = object.__new__(cls)
        tick.__dict__.update(zip(_TICK_FIELDS, values))
        return tick

    def __repr__(self) -> str:   # the generated one printed every beam (840 characters a robot)
        n, beams = self.ranges.shape
        if n == 1:
            x, y, h = self.pose[0].tolist()
            state = (f"at ({x:.1f}, {y:.1f}) in heading {h:.1f} deg, speed "
                     f"{float(self.speed[0]):.1f} in/s, clearance {float(self.clearance[0]):.1f} in")
        else:
            state = f"{plural(n, 'robot')} ({int(np.count_nonzero(self.active))} still driving)"
        return f"<Tick {self.k} (t = {self.t:g} s): {state}; {plural(beams, 'beam')} a robot>"


_TICK_FIELDS = tuple(f.name for f in fields(Tick))


class _Paged(Tick):
    """A :class:`Tick` a lockstep batch recorded in a page of its :class:`_Book`: its fields
    the batch keeps in the page (:data:`_BOOKED`) are views of the run's rows of it, made
    when first read (a batch records a tick of each of its runs every tick, and few of those
    are read before :meth:`Simulation.result` copies the pages). Copied or pickled, it is a
    plain :class:`Tick` of its own arrays."""

    @classmethod
    def _on(cls, k: int, t: float, obstacles: np.ndarray, page: tuple[Any, ...], a: int,
            b: int) -> _Paged:
        """The tick ``k`` (at ``t`` s, the obstacles at ``obstacles``) of the rows ``a:b`` of
        ``page``: its place in a :class:`_Book` and the book's arrays (:data:`_BOOKED`), not
        the book: a tick holds nothing the garbage collector must go through (the book
        would be a reference a tick, as long as the run is kept, through every collection)."""
        tick = object.__new__(cls)
        tick.__dict__.update(k=k, t=t, obstacles=obstacles, _page=page, _a=a, _b=b)
        return tick

    def __getattr__(self, name: str) -> Any:         # (asked only where not made yet)
        kept = self.__dict__
        if "_page" not in kept or name not in _BOOKED:
            raise AttributeError(f"'Tick' object has no attribute {name!r}")
        page = kept["_page"]
        rows = page[1 + _BOOKED.index(name)][page[0], kept["_a"]:kept["_b"]]
        kept[name] = rows = rows.T if name == "block" else rows
        return rows

    def __reduce__(self) -> tuple[type[Tick], tuple[Any, ...]]:
        return Tick, tuple(getattr(self, name) for name in _TICK_FIELDS)


@dataclass
class _Sensed:
    """One tick's sensing and perception, filled stage by stage (rows are robots)."""

    t: float
    where: np.ndarray
    pose: np.ndarray
    ranges: np.ndarray
    targets: np.ndarray
    clearance: np.ndarray
    command: np.ndarray             # [n, 2] filled by the plan stage
    block: np.ndarray               # [inputs, n]: the rule inputs, a row each

    @rows.once
    def inputs(self) -> dict[str, np.ndarray]:
        """name -> ``[n]``: the rows of :attr:`block` (made when asked)."""
        return dict(zip(perception.INPUTS, self.block))

    def __repr__(self) -> str:   # what Simulation.observe() gives (1,100 characters a robot)
        n, beams = self.ranges.shape
        return (f"<observed tick (t = {self.t:g} s) of {plural(n, 'robot')}: .inputs (name -> [n]),"
                f" .ranges [n, {beams}], .pose, .clearance>")


#: The fields of a :class:`_Sensed` that a lockstep batch's tick holds for all its rows.
_SENSED_ROWS = ("pose", "ranges", "targets", "clearance", "command", "block")


class _RowsSensed(_Sensed):
    """One run's :class:`_Sensed` of a lockstep batch's tick: its arrays (:data:`_SENSED_ROWS`)
    views of the run's rows of the batch's, made when first read (most ticks, the batch
    reads its own arrays and no run's)."""

    @classmethod
    def _on(cls, t: float, where: np.ndarray, arrays: tuple[np.ndarray, ...], a: int,
            b: int) -> _RowsSensed:
        """The tick at ``t`` s (the obstacles at ``where``) of the rows ``a:b`` of the
        batch's ``arrays`` (:data:`_SENSED_ROWS`, ``block`` ``[inputs, rows]``)."""
        s = object.__new__(cls)
        s.__dict__.update(t=t, where=where, _rows=(arrays, a, b))
        return s

    def __getattr__(self, name: str) -> Any:         # (asked only where not made yet)
        rows = self.__dict__.get("_rows")
        if rows is None or name not in _SENSED_ROWS:
            raise AttributeError(f"'_Sensed' object has no attribute {name!r}")
        arrays, a, b = rows
        got = arrays[_SENSED_ROWS.index(name)]
        got = self.__dict__[name] = got[:, a:b] if name == "block" else got[a:b]
        return got


class Simulation:
    """One run of a world, stepped a tick at a time; :func:`simulate` is a loop over
    :meth:`step`. Each tick runs the stages :meth:`sense` (obstacle places, beams, noise,
    clearance), :meth:`perceive` (rule inputs), :meth:`check` (contact, along the move to
    the tick too, and arrival), :meth:`plan` (one batch for the active robots) and
    :meth:`act` (kinematics), in that order,
    then records a :class:`Tick`. :meth:`perceive` also keeps each robot's own map and
    replans its route when what it sensed shuts its way (:mod:`.knowledge`).

    Drive the simulator from Python, with your own planner or inspecting each tick::

        >>> from mitos_cli.sim import Simulation, load_world
        >>> from mitos_cli.resources import packaged_path
        >>> world = load_world(packaged_path("worlds", "corridor.yaml"))
        >>> class Straight:                       # any object with `name` and `plan`
        ...     name = "straight"
        ...     def plan(self, p):                # p: Percepts, rows are active robots
        ...         return np.full(len(p.pose), 90.0), np.full(len(p.pose), 20.0)
        >>> sim = Simulation(world, planner=Straight(), seed=1)
        >>> while not sim.done and sim.time < 2.0:
        ...     tick = sim.step()
        >>> sim.ticks, round(float(sim.pose[0, 0]), 1) > round(float(world.agents[0].start.x), 1)
        (40, True)
        >>> sim.result().ticks                    # the recorded arrays as a SimResult
        40

    ``result()`` may be called at any tick; a run that has not ended reports ``timeout``.
    """

    def __init__(self, world: World, planner: Planner | None = None, seed: int | None = None,
                 *, randomise: bool = False, scene: Scene | None = None) -> None:
        check_world(world)
        if planner is None:
            from .planner import FuzzyPlanner

            planner = FuzzyPlanner(None, world.behavior)
        self.planner = _check_planner(planner)
        self.randomise = _check_randomise(randomise)
        self._given_world, self._given_scene = world, scene
        self.reset(seed)

    def __repr__(self) -> str:
        name = getattr(self.planner, "name", type(self.planner).__name__)
        now = (f"ended: {self.outcome} ({plural(self.ticks, 'tick')})" if self.done
               else f"driving, {plural(self.ticks, 'tick')} ({self.time:g} s)")
        robots = f", {len(self.robots)} robots" if len(self.robots) > 1 else ""
        drawn = ", randomised" if self.randomise else ""
        return f"<Simulation {self.world.name!r} seed {self.seed}{drawn}, {name}{robots}: {now}>"

    # -- set-up -----------------------------------------------------------------------------

    def reset(self, seed: int | None = None, *, randomise: bool | None = None) -> Simulation:
        """Start the run again from ``seed`` (default: the world's); ``randomise`` (``True``
        or ``False``; default: as before) draws the obstacle places and sensor noise from the
        world's ranges, as the constructor's does (it was settable only there, or by writing
        the attribute)."""
        if randomise is not None:
            drawn = _check_randomise(randomise)
            if drawn != self.randomise:     # a scene given for the other kind of run (a
                self._given_scene = None    # lockstep's, shared) may not be this one's
            self.randomise = drawn
        world = self._given_world
        self.seed = world.seed if seed is None else check_seed(seed)
        self._streams = [np.random.default_rng(s) for s in
                         np.random.SeedSequence(self.seed).spawn(1 + len(world.agents))]
        self._noise = [sensors.Noise(rng) for rng in self._streams[1:]]   # each robot's
        if self.randomise:
            world = obs_mod.randomised(world, self._streams[0])
        self.world = world
        self.scene = self._given_scene or _prepare_draw(world, self.randomise, self.seed)
        fresh = getattr(self.planner, "fresh", None)     # a planner with a memory: empty it
        if fresh is not None:
            self.planner = fresh()
        self._setup_constants()
        self._setup_state()
        return self

    def _setup_constants(self) -> None:
        world = self.world
        self.robots = [a.robot for a in world.agents]
        self.n = len(self.robots)
        self.limits = kinematics.Limits.of(self.robots)
        self._bounds = kinematics.command_bounds(self.limits)
        sen = world.sensors
        self.angles = sen.angles
        beams = len(self.angles)
        spacing = (2 * math.pi / beams if sen.layout == "ring"
                   else math.radians(sen.fov) / max(beams - 1, 1))
        self._spacing = (min(spacing, 2 * math.tan(math.radians(sen.cone) / 2))
                         if sen.cone > 0 else 0.0)
        self._threshold = max(4.0, 3.0 * sen.noise)
        self._reach = sen.range + max(max(r.length, r.width) for r in self.robots)
        self._cfg = perception.Settings()
        self.dt = world.dt
        self.steps = int(math.floor(world.time_limit / self.dt + 1e-9))
        # (_between) how far each robot's body moves in a tick per in/s of its wheel, and the
        # fastest obstacle's move in a tick
        self._swing = np.array([safety.fastest_point(r) for r in self.robots]) * self.dt
        self._drift = max((o.speed for o in world.obstacles), default=0.0) * self.dt
        self._goals = np.array([[a.goal.x, a.goal.y] for a in world.agents], float)
        self._goal_x, self._goal_y = self._goals[:, 0].copy(), self._goals[:, 1].copy()
        self._tol = np.array([a.goal.tolerance for a in world.agents], float)
        self._stuck_window = max(1, int(round(STUCK_TIME / self.dt)))
        self._progress_window = max(1, int(round(PROGRESS_TIME / self.dt)))
        self._given = self.scene.given or knowledge.given(world, self.scene.static)
        self._plain = self._given.plain
        self._known_walls = StaticMap(self._given.walls, np.zeros((0, 4, 2)), None,
                                      self.scene.static.bounds)
        self._asked = [clearances(world, a) for a in world.agents]
        # each robot's Sights.squeeze: its least clearance, where that is less than half its
        # width and its margin (else none)
        self._squeeze = [least if least < r.width / 2 + r.safety_margin else math.inf
                         for r, (_, least) in zip(self.robots, self._asked)]
        # each robot's row of Sights: its beams' spacing, news threshold, least clearance
        # and squeeze (Simulation.aimed)
        self._sighting = (np.full(self.n, self._spacing), np.full(self.n, self._threshold),
                          np.array([least for _, least in self._asked]),
                          np.array(self._squeeze))
        self._safety = safety.Settings()
        self._brake_reach = [safety.reach_of(r, self.dt, self._safety, sen.range)
                             for r in self.robots]
        # (traffic) the robots that share their routes and give way, where two or more do
        self._traffic = [r.give_way for r in self.robots]
        if sum(self._traffic) < 2:
            self._traffic = []
        self._still = None
        self._still_discs = None        # discs round the still rectangles (rows.SenseRow)
        if not any(o.motion.kind in ("velocity", "waypoints") for o in world.obstacles):
            self._still = self._obstacles_at(0.0)
            self._still_discs = rows.discs(self._still[1][5])

    def _setup_state(self) -> None:
        agents, n = self.world.agents, self.n
        self._x = np.array([a.start.x for a in agents], float)
        self._y = np.array([a.start.y for a in agents], float)
        self._h = np.deg2rad(np.array([_half_turn(a.start.heading) for a in agents], float))
        self._v = np.zeros(n)
        self._steer = self.limits.straight.copy()
        self._s_hint = np.zeros(n)
        self._active = np.ones(n, dtype=bool)
        self._ways = traffic.Traffic()                 # (_give_way) who goes first where
        self._gave_way_at = np.full(n, -self._stuck_window - 1)   # the last tick each did
        self._near_at = [(math.inf, math.inf)] * n     # where each robot's wall set was gathered
        self._near_walls = [np.zeros((0, 4))] * n
        self._near_known = [np.zeros((0, 4))] * n
        self._cast_with: list[tuple | None] = [None] * n
        self._routes = list(self.scene.routes)          # replanning replaces them
        self._lengths = np.array([r.length for r in self._routes])   # in: theirs, [n]
        self._replanned: list[tuple[int, int, Route]] = []
        grid = self.scene.plan_grid or knowledge.plan_grid(self._given, self.scene.static,
                                                           self.world)
        faces = knowledge.faces_of(self._given, grid, self.scene.static.grid is None)
        self._maps = [knowledge.RobotMap.of(grid, faces) for _ in range(n)]
        self._trackers = [movers.Tracker() for _ in range(n)]
        ring = self.world.sensors.layout == "ring"
        self._free = [movers.FreeSpace.of(self.angles, ring, self.dt, grid.resolution,
                                          self.world.sensors.noise, self.world.sensors.range)
                      for _ in range(n)]
        self._seen = [np.zeros(len(self.angles), dtype=bool) for _ in range(n)]
        self._odometer: list[np.ndarray] = []      # in each robot has driven, after each move
        # in: each robot's least distance to its goal so far, in a straight line and along
        # its route, at the start and after each move (``[2, n]`` each, _check_stuck)
        self._best = [np.stack([np.hypot(self._x - self._goal_x, self._y - self._goal_y),
                                self._lengths.copy()])]
        self._fleet = safety.Fleet(self.robots, [m.grid.resolution / 2 for m in self._maps],
                                   self._brake_reach, self.dt, self._safety)
        self._recovery = safety.rest(n)                 # each robot's safety.Recovery, a row
        self._backed: list[tuple[int, int]] = []
        self._outcomes = ["timeout"] * n
        self._collided = 0
        self._k = 0
        self._bodies_at: tuple = (-1, 0.0, None, [])   # tick, half a cell, mates, outlines
        self._done = self.steps <= 0
        self._hit = np.zeros(n, dtype=bool)
        self._beyond_at: tuple = (None, [])             # see _beyond()
        self._epoch = next(_EPOCHS)                     # this start's (a Batch is of one)
        self._moved_by: object = None                   # the Batch.move that moved it last
        self._came: _Came | None = None                 # the move that brought it here
        self._watched: tuple = (None, [], [])           # see watching()
        beams = len(self.angles)                        # what watching() gives for no robot
        self._unseen = (np.zeros((0, 2)), np.zeros((0, beams)), np.zeros((0, beams, 2)),
                        np.zeros((0, beams), dtype=bool))
        self._observed: _Sensed | None = None
        self._deciding: _Sensed | None = None
        self.record: list[Tick] = []
        self._pages: list[tuple[_Book, int, int]] = []  # see _Book: (book, column, first tick)

    # -- state ------------------------------------------------------------------------------

    @property
    def ticks(self) -> int:
        """Ticks recorded so far."""
        return len(self.record)

    @property
    def time(self) -> float:
        """Time of the next tick (s)."""
        return self._k * self.dt

    @property
    def pose(self) -> np.ndarray:
        """``[n, 3]`` the robots' pose now: x, y (in), heading (deg)."""
        return np.stack([self._x, self._y, np.rad2deg(self._h)], axis=1)

    @property
    def speed(self) -> np.ndarray:
        """``[n]`` the robots' speed now (in/s)."""
        return self._v.copy()

    @property
    def steering(self) -> np.ndarray:
        """``[n]`` the wheels' angle now (deg, 90 straight)."""
        return self._steer.copy()

    @property
    def active(self) -> np.ndarray:
        """``[n]`` robots not yet at their goal: a robot whose run ended otherwise (a
        collision, stuck, out of time) keeps ``True`` (:attr:`robot_outcomes` says how each
        ended; :attr:`done` whether the run has)."""
        return self._active.copy()

    @property
    def clearance(self) -> np.ndarray:
        """``[n]`` each robot's clearance (in) where it stands: of the tick observed, else of
        the last tick recorded (``inf`` before the first is observed). A copy, as the other
        state is: the recorded tick's own array was given, and writing into it changed the
        run's clearance and the next tick's contact check."""
        if self._observed is not None:
            return self._observed.clearance.copy()
        return self.record[-1].clearance.copy() if self.record else np.full(self.n, math.inf)

    @property
    def done(self) -> bool:
        return self._done

    @property
    def robot_outcomes(self) -> tuple[str, ...]:
        """Each robot's outcome; ``driving`` for a robot still driving while the run goes on
        (as the Gymnasium environment's ``info`` says; it read ``timeout``)."""
        if self._done:
            return tuple(self._outcomes)
        return tuple("driving" if going and o == "timeout" else o
                     for o, going in zip(self._outcomes, self._active.tolist()))

    @property
    def outcome(self) -> str:
        """``success`` (every robot at its goal), ``collision``, ``stuck`` or ``timeout``;
        ``driving`` while the run goes on (it read ``timeout`` from the first tick, the
        outcome a run cut there has: :meth:`result` still reports that one)."""
        return self._verdict() if self._done else "driving"

    def _verdict(self) -> str:
        """The run's outcome were it to end now (a run cut short is a ``timeout``)."""
        outcomes = self._outcomes
        if "collision" in outcomes:
            return "collision"
        if all(o == "success" for o in outcomes):
            return "success"
        return "stuck" if "stuck" in outcomes else "timeout"

    # -- one tick ---------------------------------------------------------------------------

    @property
    def routes(self) -> tuple[Route, ...]:
        """Each robot's route now (its last replan)."""
        return tuple(self._routes)

    @property
    def progress(self) -> np.ndarray:
        """``[n]`` how far (in) each robot is along its route (:attr:`routes`) where it was
        last perceived: the route left to its goal is the route's length minus this. (A
        recorded tick's ``progress`` is along the route as it was then; a replan since starts
        the new route where the robot stood.)"""
        return self._s_hint.copy()

    @property
    def ending(self) -> bool:
        """The observed tick ends the run whatever is commanded: a robot touches something or
        every robot is at its goal (False before :meth:`observe`)."""
        return self._observed is not None and bool(np.count_nonzero(self._hit)
                                                   or not np.count_nonzero(self._active))

    def observe(self) -> _Sensed:
        """Sense, perceive and check the current tick, once; the next :meth:`step` goes on from
        there. What a policy outside the simulator decides on: ``.inputs`` (name -> ``[n]``),
        ``.ranges [n, B]``, ``.pose``, ``.clearance``."""
        if self._done:
            raise RuntimeError("the run has ended (reset() starts it again)")
        if self._observed is None:
            s = self.sense()
            self.perceive(s)
            self.conclude(s)
        assert self._observed is not None
        return self._observed

    def conclude(self, s: _Sensed) -> None:
        """The last stage of :meth:`observe`, once ``s`` is sensed and perceived: the check;
        ``s`` is then this tick's observation."""
        self.check(s)
        _read_only(s.where, s.pose, s.ranges, s.targets, s.clearance, s.block)
        self._observed = s

    @property
    def settings(self) -> perception.Settings:
        """The perception settings its robots perceive with."""
        return self._cfg

    @property
    def observed(self) -> bool:
        """Whether this tick has been observed (:meth:`observe`) and not yet decided."""
        return self._observed is not None

    def step(self, command: np.ndarray | None = None) -> Tick:
        """Advance one tick and return what it recorded. ``command`` (``[n, 2]`` steering in
        deg and speed in in/s) drives the active robots this tick instead of the planner."""
        tick, moves = self.decide(command)
        if moves:
            self.act(self.decided)
            self.moved()
        return tick

    def decide(self, command: np.ndarray | None = None) -> tuple[Tick, bool]:
        """The first half of :meth:`step`: observe, plan (or take ``command``), record the tick
        and the verdict; whether the robots move now (:meth:`act`, then :meth:`moved`; runs
        stepped in lockstep move all their robots in one batch between the two)."""
        s = self.commanded(command)
        self._guard(s)
        return self.verdict(s)

    def commanded(self, command: np.ndarray | None = None) -> _Sensed:
        """The start of :meth:`decide`: the tick observed, and the planner's commands (or
        ``command``) in it, before the guard."""
        if command is not None:         # checked before the tick is observed: a refused
            command = self._command(command)             # command leaves the run as it was
        s = self.observe()
        self._observed = None
        if command is None:
            self.plan(s)
        else:
            s.command[:] = command
            if not self._active.all():
                s.command[~self._active] = np.stack([self.limits.straight, np.zeros(self.n)],
                                                    axis=1)[~self._active]
        return s

    def _command(self, command: object) -> np.ndarray:
        """A command given from outside as ``[n, 2]`` finite floats, else a
        :class:`CommandError` (``None`` met NumPy's conversion errors; a bool was read as 1
        or 0, and text as ``float()`` reads it, ``"5_0"`` as 50)."""
        from ..engine.inputs import holds_bool, holds_text

        if holds_bool(command):
            raise CommandError(f"the command must be numbers, not bools: `{command!r:.80}`",
                               hint="give numbers: True and False would be read as 1 and 0")
        if holds_text(command):
            raise CommandError(f"the command must be numbers, not text: `{command!r:.80}`",
                               hint="give numbers: NumPy reads text as Python's float() does, "
                                    "`'5_0'` as 50")
        try:
            given = np.asarray(command, float)
        except OverflowError:           # (an int past a float's range: 10**400)
            raise _too_large("the command") from None
        except (TypeError, ValueError):
            given = None
        if given is None or given.size != 2 * self.n:
            shape = (f"of shape {given.shape}" if given is not None and given.ndim
                     else f"`{command!r:.40}`")
            raise CommandError(f"a command is [{self.n}, 2] (steering deg, speed in/s for each "
                               f"robot), not {shape}")
        return _finite(given.reshape(self.n, 2), "the command")

    def verdict(self, s: _Sensed) -> tuple[Tick, bool]:
        """The end of :meth:`decide`, once the guard has had its say on ``s``'s commands:
        the commands held to the robots' limits (:func:`.kinematics.hold_commands`), the tick
        recorded and the verdict."""
        kinematics.hold_commands(s.command, self._bounds)
        tick = self._record(s)
        return tick, self._judge(s, bool(np.count_nonzero(self._hit)),
                                 bool(np.count_nonzero(self._active)))

    def _judge(self, s: _Sensed, hit: bool, driving: bool) -> bool:
        """The verdict on tick ``s`` (``hit``: a robot touches something; ``driving``: a
        robot still drives): whether the robots move now."""
        if hit:
            self._collided = int(self._hit.sum())
            for i in np.flatnonzero(self._hit):
                self._outcomes[i] = "collision"
            self._stop_the_others()
        elif driving:
            self._deciding = s
            return True
        self._done = True
        return False

    @property
    def decided(self) -> _Sensed:
        """The tick :meth:`decide` recorded last (what :meth:`act` moves by)."""
        assert self._deciding is not None, "decide() first"
        return self._deciding

    def moved(self) -> None:
        """The second half of :meth:`step`, after :meth:`act`: the next tick, or the end of
        the run (stuck, or out of time)."""
        self._k += 1
        self._go_on(self._check_stuck())

    def _go_on(self, stuck: bool) -> None:
        """The next tick begins: the run ends if a robot is ``stuck`` or time is out."""
        if stuck:
            self._stop_the_others()
            self._done = True
        else:
            self._done = self._k >= self.steps

    def _stop_the_others(self) -> None:
        """The run ends for one robot's collision or stuck: the robots still driving read
        ``stopped`` (not ``timeout``: their time had not run out)."""
        for i in np.flatnonzero(self._active):
            if self._outcomes[i] == "timeout":
                self._outcomes[i] = "stopped"

    def sense(self) -> _Sensed:
        """Obstacle places at this tick's time, every robot's beams (noise from its own
        stream) and the clearance of its footprint (:mod:`.rows`: all robots at once)."""
        return self.sensed(rows.sense(self.sense_rows(), self.angles, self.world.sensors.range))

    def sense_rows(self) -> list[rows.SenseRow]:
        """What each robot senses with at this tick (:func:`.rows.sense` senses them; runs in
        lockstep sense the robots of all their runs together)."""
        n, x, y, h = self.n, self._x, self._y, self._h
        sen = self.world.sensors
        where, (centres, radii, _, rect_sides, _, rect_box) = self._obstacles_at(self.time)
        self._where = where
        if n > 1:                                        # other robots are obstacles to each
            footprints = _footprints(np.stack([x, y, h], axis=1), self.robots)
            robot_sides = polygon_segments(footprints).reshape(n, 4, 4)
        out = []
        xs, ys, hs = x.tolist(), y.tolist(), h.tolist()
        for i in range(n):
            if n > 1:
                others = np.concatenate([rect_sides] + [robot_sides[j] for j in range(n)
                                                        if j != i])
                boxes = np.concatenate([rect_box, footprints[:i], footprints[i + 1:]])
            else:
                others, boxes = rect_sides, rect_box
            discs = (self._still_discs if n == 1 and self._still_discs is not None
                     else rows.discs(boxes))
            walls = self._walls_near(i, xs[i], ys[i])
            out.append(rows.SenseRow(xs[i], ys[i], hs[i], self.robots[i],
                                     walls, self._joined(i, walls, others), boxes, discs,
                                     centres, radii, sen.noise, self._noise[i]))
        return out

    def sensed(self, got: rows.Sensed) -> _Sensed:
        """The tick's :class:`_Sensed` from its robots' rows of :func:`.rows.sense`, with what
        each robot's own map predicts along its beams."""
        n = self.n
        pose = _columns(self._x, self._y, self._h)
        self._beams(pose, list(got.dirs), list(got.static))
        return _Sensed(self.time, self._where, pose, got.ranges, np.zeros((n, 2)),
                       got.clearance, np.zeros((n, 2)),
                       np.zeros((len(perception.INPUTS), n)))     # one block, a row per input

    def _beams(self, pose: np.ndarray, dirs: list[np.ndarray], static: list[np.ndarray]) -> None:
        """Keep each robot's beams ``dirs`` at ``pose`` and what its own map predicts along
        them (the walls alone, ``static``, when it is given the map)."""
        self._dirs = dirs
        if self._plain:
            self._expected = static
        else:
            self._expected = [knowledge.expected_ranges(
                self._given, self._maps[i], pose[i, :2], dirs[i], self._near_known[i],
                self.world.sensors.range) for i in range(self.n)]

    def _joined(self, i: int, walls: np.ndarray, sides: np.ndarray) -> np.ndarray:
        """Robot ``i``'s nearby walls and then the obstacle sides as one array, kept while
        both are the same arrays (still obstacles, no new walls gathered)."""
        kept = self._cast_with[i]
        if kept is None or kept[0] is not walls or kept[1] is not sides:
            kept = self._cast_with[i] = (walls, sides, np.concatenate([walls, sides]))
        return kept[2]

    def _obstacles_at(self, t: float) -> tuple[np.ndarray, Shapes]:
        """Obstacle places ``[O, 2]`` at time ``t`` and their shapes
        (:func:`obstacles.shapes_at`); worked out once when nothing moves."""
        if self._still is not None:
            return self._still
        where = obs_mod.positions(self.world.obstacles, t)
        return where, obs_mod.shapes_at(self.world.obstacles, where)

    def _walls_near(self, i: int, x: float, y: float) -> np.ndarray:
        """Robot ``i``'s nearby walls (it is at ``x, y``), gathered again once it moved
        ``NEAR_SLACK`` away."""
        if math.hypot(x - self._near_at[i][0], y - self._near_at[i][1]) > NEAR_SLACK:
            self._near_at[i] = (x, y)
            self._near_walls[i] = self.scene.static.near(x, y, self._reach + NEAR_SLACK)
            if not self._plain and self._given.knows != "none":
                self._near_known[i] = self._known_walls.near(x, y, self._reach + NEAR_SLACK)
        return self._near_walls[i]

    def perceive(self, s: _Sensed) -> None:
        """The rule inputs and the route's target point of every robot from its readings;
        first, what they show that its map does not is marked on the map it plans on, and
        its route planned again if that shuts its way (:mod:`.knowledge`). All robots'
        inputs at once (:func:`.perception.perceive_all`)."""
        sights = self.sights(s)
        self.perceived(s, sights, perception.perceive_all(sights, self.world.sensors.range,
                                                          self._cfg))

    def sights(self, s: _Sensed) -> perception.Sights:
        """The robots' :class:`.perception.Sights` at tick ``s``: the marks their readings see
        through cleared from their maps (:meth:`clearing`), their :meth:`aims`, then every
        robot's pursuit point at once."""
        knowledge.clear_all(*self.clearing(s))
        self.tracked(s)
        aims = self.aims(s, perception.frames(*self.framing(s)))
        return self.aimed(s, aims, perception.pursuit_points(aims, self._cfg)[1])

    def framing(self, s: _Sensed) -> tuple[list[Route], np.ndarray, np.ndarray]:
        """What :func:`.perception.frames` places the robots on their routes from at tick
        ``s``: their routes, places and last arc lengths (:meth:`Batch.framing`: of runs in
        lockstep)."""
        return list(self._routes), s.pose[:, :2], self._s_hint

    def clearing(self, s: _Sensed) -> tuple[list[knowledge.RobotMap], np.ndarray, np.ndarray,
                                            np.ndarray, float]:
        """What :func:`.knowledge.clear_all` clears the robots' maps with at tick ``s``: the
        maps, where the robots are, their beams and readings, and the range."""
        dirs = self._dirs[0][None] if self.n == 1 else np.stack(self._dirs)
        return self._maps, s.pose[:, :2], dirs, s.ranges, self.world.sensors.range

    def tracked(self, s: _Sensed, sighted: list[movers.Seen] | None = None) -> None:
        """What each robot sees at tick ``s`` that its map does not show, followed: the beams
        it kept (:class:`.movers.FreeSpace`) and its tracks brought up to ``s``
        (:func:`.movers.follow_all`). ``sighted``: :func:`.movers.sightings` of what the
        robots that follow something see, their maps marked (:meth:`watching`; runs in
        lockstep mark, see and follow theirs together, :meth:`Batch.tracked`); ``None``:
        the maps are marked and the sightings seen here."""
        if sighted is None:
            spaces, *looks = self.watching(s)
            sighted = movers.sightings(spaces, s.t, *looks)
        if self.world.replan == "never":
            return
        for i in range(self.n):
            self._free[i].update(s.t, s.pose[i, :2], self._dirs[i], s.ranges[i])
        movers.follow_all([self._trackers[i] for i in self._watched[2]], s.t, sighted)

    def aims(self, s: _Sensed, frames: list[perception.Frame],
             near: list[np.ndarray] | None = None) -> list[perception.Aim]:
        """Each robot's :class:`.perception.Aim` at tick ``s``, its map cleared
        (:meth:`clearing`) and marked and its tracks followed (:meth:`tracked`): where it is
        on its route (its route replanned if need be, :meth:`replanned`) and what its pursuit
        point keeps clear of; ``frames``: where they are on their routes (:meth:`framing`);
        ``near``: what each robot's map holds within its lookahead and least clearance
        (:meth:`.knowledge.RobotMap.near`; ``None``: asked here). Runs in lockstep ask
        :meth:`Batch.aims` instead, for all their robots at once."""
        if self._watched[0] is not s:               # not yet tracked at this tick
            self.tracked(s)
        frames = list(frames)
        for i in knowledge.checks_due(self._maps, s.t, self.world.replan):
            frames[i] = self.replanned(s, i, frames[i])
        self._s_hint = np.array([f.s for f in frames])
        if near is None:    # what the route keeps clear of: the marks too, where it is
            given = self.world.replan != "clearance"        # replanned round them
            near = [m.near(p, self._cfg.lookahead + least, given=given)
                    for m, p, (_, least) in zip(self._maps, s.pose[:, :2], self._asked)]
        return [perception.Aim(route, f, p, cells, m.grid.resolution / 2,
                               least + self._cfg.lookahead_room)
                for route, f, p, cells, m, (_, least) in zip(self._routes, frames, s.pose[:, :2],
                                                             near, self._maps, self._asked)]

    def replanned(self, s: _Sensed, i: int, f: perception.Frame) -> perception.Frame:
        """Where robot ``i`` is on its route at tick ``s`` (``f``: where it was on the route it
        had), its route planned again first (:func:`.knowledge.replan`) where it drives and
        what it learned, a mover coming toward it (:meth:`_sweep`) or the refuge it waits at
        asks for it. Asked of the robots due a replanning check alone
        (:func:`.knowledge.checks_due`): no other's route is planned again."""
        _, learned, follows = self._watched
        rmap = self._maps[i]
        if not self._active[i]:
            return f
        sweep = self._sweep(i, s) if i in follows else None
        if not (learned[i] or sweep is not None or rmap.refuge is not None):
            return f
        route = knowledge.replan(rmap, self._routes[i], f.s, s.pose[i, :2],
                                 self.world.agents[i].goal, s.t, *self._asked[i],
                                 self._cfg.sight, self.world.replan,
                                 heading=math.degrees(self._h[i]), behind=BEHIND, moving=sweep)
        if route is None:
            return f
        self._routes[i] = route
        self._lengths[i] = route.length
        self._replanned.append((self._k, i, route))
        return perception.frame(route, s.pose[i, :2], 0.0)

    def aimed(self, s: _Sensed, aims: list[perception.Aim], targets: np.ndarray, *,
              gaps: list[float] | None = None) -> perception.Sights:
        """The robots' sights from their :meth:`aims` and their pursuit points ``targets
        [n, 2]``: what each keeps clear of (``gaps``: their :func:`.perception.route_gaps`,
        worked out here when ``None``) and which of their readings hit cells their routes
        were planned round (:meth:`.knowledge.RobotMap.accounted_cells`; runs in lockstep
        work both out together, :meth:`Batch.aimed`)."""
        if gaps is None:
            gaps = perception.route_gaps(aims)
        dirs, expected = ((self._dirs[0][None], self._expected[0][None]) if self.n == 1
                          else (np.stack(self._dirs), np.stack(self._expected)))
        spacing, threshold, least, squeeze = self._sighting
        return _sights(aims, self.robots, s.pose, dirs, s.ranges, expected, spacing, threshold,
                       least, self.accounted(s), targets, gaps, squeeze)

    def accounted(self, s: _Sensed) -> np.ndarray:
        """``[n, B]``: which readings at tick ``s`` hit cells the robots' routes were planned
        round (:meth:`.knowledge.RobotMap.accounted_cells`), where the routes are replanned
        round what they sense (else none; runs in lockstep look theirs up together,
        :func:`.knowledge.accounted_all`)."""
        kept = np.zeros(s.ranges.shape, dtype=bool)
        if self.world.replan == "clearance":
            for i in range(self.n):
                kept[i] = self._maps[i].accounted_cells(self._beyond(i, s))
        return kept

    def perceived(self, s: _Sensed, sights: perception.Sights,
                  inputs: dict[str, np.ndarray]) -> None:
        """Record the robots' inputs (their rows of :func:`.perception.perceive_all`) and
        target points in tick ``s``."""
        for j, key in enumerate(perception.INPUTS):
            s.block[j] = inputs[key]
        s.targets[:] = sights.target

    def _beyond(self, i: int, s: _Sensed) -> np.ndarray:
        """The cells ``[B, 2]`` (:meth:`.knowledge.RobotMap.cell_indices`) just beyond robot
        ``i``'s readings at tick ``s``, where their echoes came from: what :meth:`_learn`
        marks and :meth:`accounted` looks up, worked out once a tick for both."""
        if self._beyond_at[0] is not s:
            self._beyond_at = (s, [None] * self.n)
        cells = self._beyond_at[1]
        if cells[i] is None:
            rmap, dirs = self._maps[i], self._dirs[i]
            cells[i] = rmap.cell_indices(s.pose[i, :2] + s.ranges[i, :, None] * dirs
                                         + dirs * (rmap.grid.resolution / 2))
        return cells[i]

    def _learn(self, i: int, s: _Sensed, seen: np.ndarray) -> bool:
        """Mark on robot ``i``'s map the cells beyond its readings ``seen`` (:meth:`seeing`'s
        row): whether anything new was marked."""
        if not np.count_nonzero(seen):               # (a count is cheaper than .any())
            return False
        return self._maps[i].mark_cells(self._beyond(i, s)[seen])   # = rmap.mark(hits, dirs)

    def seeing(self, s: _Sensed) -> np.ndarray:
        """``[n, B]``: which readings at tick ``s`` show what each robot's map does not (every
        echo, with no map): what :meth:`_learn` marks robot by robot (:meth:`Batch.seeing`:
        runs in lockstep, by the same :func:`_news`)."""
        expected = None
        if self._given.knows != "none":
            expected = self._expected[0][None] if self.n == 1 else np.stack(self._expected)
        seen = _news(s.ranges, expected, self.world.sensors.range * 0.999, self._threshold)
        tracked = seen
        if self._traffic:
            seen, tracked = self._mates_echoes(seen, self._active, s.pose, self._v, s.ranges,
                                               self._dirs)
        self._seen = list(tracked)
        return seen

    def _mates_echoes(self, seen: np.ndarray, active: np.ndarray, pose: np.ndarray,
                      speed: np.ndarray, ranges: np.ndarray, dirs: list[np.ndarray] | np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
        """``seen [n, B]`` without the echoes of the mates each robot leaves off its map
        (:func:`.traffic.unmarked`, of the robots ``active`` at ``speed``; the brake counts
        their bodies instead, :meth:`_mates_bodies`), and without those of the robot each
        waits on only: what goes into its tracks, where a mate coming down its lane is a
        mover it keeps right of (:func:`.traffic.echoes`)."""
        off = traffic.unmarked(self._traffic, active, speed, self._ways.waits)
        if not off.any():
            return seen, seen
        of = traffic.echoes(pose, self.robots, ranges, np.asarray(dirs))      # [n, n, B]
        marked = seen & ~np.logical_or.reduce(of & off[:, :, None], axis=1)
        if not self._ways.waits:
            return marked, seen
        waits = np.zeros_like(off)
        for me, other in self._ways.waits:
            waits[me, other] = True
        return marked, seen & ~np.logical_or.reduce(of & waits[:, :, None], axis=1)

    def _mates_bodies(self, i: int, active: np.ndarray, pose: np.ndarray,
                      speed: np.ndarray) -> np.ndarray | None:
        """What robot ``i``'s brake counts of its mates this tick: their footprints
        stretched by the room each takes to stop (:func:`.traffic.outlines` of the robots
        ``active`` at ``pose [n, 3]`` and ``speed [n]``, made once a tick for all); ``None``
        where it has none."""
        half = self._maps[i].grid.resolution / 2
        if self._bodies_at[:2] != (self._k, half):
            share = traffic.mates(self._traffic, active)
            stretch = traffic.stopping(speed, self.robots, self.dt)
            shared = np.asarray(share.any(axis=0))
            self._bodies_at = (self._k, half, share,
                               traffic.outlines(pose, self.robots, shared, half, stretch))
        share, outlines = self._bodies_at[2:]
        of = share[i].nonzero()[0].tolist()
        if not of:
            return None
        return outlines[of[0]] if len(of) == 1 else np.concatenate([outlines[j] for j in of])

    def watching(self, s: _Sensed, learned: list[bool] | None = None
                 ) -> tuple[list[movers.FreeSpace], np.ndarray, np.ndarray, np.ndarray,
                            np.ndarray]:
        """Each robot's map marked from its readings at tick ``s`` (:meth:`_learn`), and what
        :func:`.movers.sightings` looks at for the robots that follow something (runs in
        lockstep see theirs together): the beams each kept, where it stands ``[F, 2]``, its
        readings ``[F, B]``, beams ``[F, B, 2]`` and which it sees that its map does not
        show ``[F, B]``. ``learned``: whether each robot's map was marked (runs in lockstep
        mark theirs together, :meth:`seeing`; ``None``: marked here)."""
        if learned is None:
            seen = self.seeing(s)
            learned = [self._learn(i, s, seen[i]) for i in range(self.n)]
        follows = ([] if self.world.replan == "never" else         # (what _sweep follows)
                   [i for i in range(self.n)
                    if self._trackers[i].tracks or np.count_nonzero(self._seen[i])])
        self._watched = (s, learned, follows)
        if not follows:
            return [], *self._unseen
        if self.n == 1:
            dirs, seen = self._dirs[0][None], self._seen[0][None]
        else:
            dirs, seen = np.stack(self._dirs), np.stack(self._seen)
        pick = slice(None) if len(follows) == self.n else follows    # (a slice is a view)
        return ([self._free[i] for i in follows], s.pose[pick, :2], s.ranges[pick], dirs[pick],
                seen[pick])

    def _sweep(self, i: int, s: _Sensed) -> movers.Sweep | None:
        """Where the movers among the tracks robot ``i`` follows (brought up to tick ``s``,
        :meth:`tracked`) will pass while it gets out of their way (``None`` when nothing
        comes toward it)."""
        p = s.pose[i, :2]
        rmap, tracker = self._maps[i], self._trackers[i]
        if not any(tr.mover for tr in tracker.tracks):          # nothing it follows moves
            return None
        h = float(self._h[i])
        # (a robot on its way to a refuge draws away from what it yields to; it waits for
        # it all the same; once at its refuge, for what has not passed it)
        own = (np.zeros(2) if rmap.refuge is not None
               else self._v[i] * np.array([math.cos(h), math.sin(h)]))
        found = tracker.movers(s.t, p, own, waiting=rmap.at_refuge(p))
        if not found:
            return None
        robot, grid = self.robots[i], rmap.grid
        asked, least = self._asked[i]
        room = asked - least
        return movers.sweep(found, p, h, robot.length, robot.width, rmap.occupied.shape,
                            grid.resolution, grid.origin, room, self.world.sensors.range,
                            waiting=rmap.refuge is not None)

    def check(self, s: _Sensed) -> None:
        """Contact (clearance <= 0, of a robot parked at its goal too) and arrival; an
        arrived robot stops driving."""
        active = self._active
        self._hit, arrived = _arrivals(active, s.clearance, self._x, self._y, self._goal_x,
                                       self._goal_y, self._tol)
        self._between(s.clearance, self._hit)
        if np.count_nonzero(arrived):
            for i in arrived.nonzero()[0]:
                self._outcomes[i] = "success"
            active &= ~arrived

    # -- contact between ticks ----------------------------------------------------------------

    def _between(self, clearance: np.ndarray, hit: np.ndarray) -> None:
        """Contact that began and ended between the last tick and this one, where contact is
        checked: looked for along the move (:meth:`_touched_between`) where a robot's
        clearance then and now add up to no more than its body and what it may touch came
        closer in the move (:meth:`_travel`), and a collision at this tick where found, its
        clearance the least found (``hit`` and ``clearance [n]`` are written in place).
        Elsewhere nothing can have touched: a point of the obstacle inside the body between
        the two ticks lay within that travel of the body at one of them."""
        if self._came is None or not self.record:
            return
        before, speed = self.record[-1].clearance, self._came.of_run()[3]
        if self.n == 1:             # (most worlds: the same sums as Batch's, in floats)
            room = max(abs(float(speed[0])), abs(float(self._v[0]))) * float(self._swing[0])
            if float(before[0]) + float(clearance[0]) > room + self._drift or hit[0]:
                return
        travel = self._travel(speed)
        maybe = (before + clearance <= travel) & ~hit
        if np.count_nonzero(maybe):
            self._look_between(maybe.nonzero()[0], before, clearance, hit, travel)

    def _travel(self, speed: np.ndarray) -> np.ndarray:
        """``[n]`` how much closer each robot's body and what it may touch can have come in
        its last move, from ``speed [n]`` its wheel's then: its fastest point's path
        (:func:`.safety.fastest_point`, at the faster of its speeds then and now; the speed
        ramps between them), the fastest other robot's and the fastest obstacle's."""
        own = np.maximum(np.abs(speed), np.abs(self._v)) * self._swing
        return own + self._drift + (own.max() if self.n > 1 else 0.0)    # (as Batch's)

    def _look_between(self, robots: np.ndarray, before: np.ndarray, clearance: np.ndarray,
                      hit: np.ndarray, travel: np.ndarray) -> None:
        """:meth:`_touched_between` of ``robots``; a contact found is a hit, at the least
        clearance found."""
        for i in robots.tolist():
            found = self._touched_between(i, float(before[i]), float(clearance[i]),
                                          float(travel[i]))
            if found is not None:
                hit[i], clearance[i] = True, found

    def _touched_between(self, i: int, before: float, now: float, travel: float) -> float | None:
        """Robot ``i``'s clearance where it touched something along its last move (else
        ``None``), by halving the move: a part whose ends' clearances add up to more than
        what the part's share of ``travel`` allows cannot have touched, the others are
        halved, down to parts too short for a contact deeper than :data:`GRAZE`."""
        parts = [(0.0, before, 1.0, now)]
        while parts:
            f0, a, f1, b = parts.pop()
            span = travel * (f1 - f0)
            if a + b > span or span <= 2.0 * GRAZE:
                continue
            f = (f0 + f1) / 2.0
            c = self._clearance_at(i, f)
            if c <= 0.0:
                return c
            parts += [(f, c, f1, b), (f0, a, f, c)]          # the earlier half first
        return None

    def _clearance_at(self, i: int, f: float) -> float:
        """Robot ``i``'s clearance the share ``f`` of the way through the last move: every
        robot where that move had it then (:func:`kinematics.along`), the obstacles where
        they were then; walls farther than a tick's sensing gathers are not looked at, so
        the clearance is at most what that leaves room for."""
        assert self._came is not None
        x, y, h = kinematics.along(*self._came.of_run(), self.limits, self.dt,
                                   self.world.substeps, f)
        _, (centres, radii, _, _, _, boxes) = self._obstacles_at(self.record[-1].t + f * self.dt)
        if self.n > 1:
            feet = _footprints(_columns(x, y, h), self.robots)
            boxes = np.concatenate([boxes, feet[:i], feet[i + 1:]])
        reach = self._reach + NEAR_SLACK
        px, py = float(x[i]), float(y[i])
        walls = self.scene.static.near(px, py, reach)
        robot = self.robots[i]
        row = rows.SenseRow(px, py, float(h[i]), robot, walls, walls, boxes, rows.discs(boxes),
                            centres, radii, 0.0, self._noise[i])
        return min(float(rows.clearance([row])[0]),
                   reach - math.hypot(robot.length, robot.width) / 2)

    def plan(self, s: _Sensed) -> None:
        """The planner's commands for the active robots, in one batch (the others: straight
        wheel, no speed)."""
        cmd = s.command
        cmd[:, 0] = self.limits.straight
        if np.count_nonzero(self._active):
            idx = np.flatnonzero(self._active)

            def rows(a: np.ndarray) -> np.ndarray:      # a copy of the active robots' rows
                return a.copy() if len(idx) == self.n else a[idx]

            # the inputs copied as one block (``s.inputs`` holds its rows), one row each
            block = s.block.copy() if len(idx) == self.n else s.block[:, idx]
            sub = Percepts(dict(zip(perception.INPUTS, block)), rows(s.ranges),
                           self.angles, rows(s.pose), rows(self._v), rows(s.targets),
                           rows(self._goals), rows(self._steer), idx, self._path(idx))
            c_steer, c_speed = _planned(self.planner.plan(sub), self._planner_name)
            try:
                cmd[idx, 0], cmd[idx, 1] = c_steer, c_speed
            except OverflowError:
                raise _too_large(f"the command of {self._planner_name}") from None
            except (TypeError, ValueError):
                raise CommandError(f"{self._planner_name} gave {np.shape(c_steer)} steering and "
                                 f"{np.shape(c_speed)} speed values for "
                                 f"{plural(len(idx), 'active robot')} (one each)") from None
            if not np.isfinite(cmd[idx]).all():
                _finite(cmd[idx], f"the command of {self._planner_name} at {s.t:g} s")

    def _path(self, idx: np.ndarray) -> np.ndarray | None:
        """``Percepts.path`` of the robots ``idx``: their routes from where they are to the
        planner's ``path_reach`` ahead, a point every ``PATH_STEP`` in (none when the planner
        does not ask)."""
        reach = getattr(self.planner, "path_reach", None)
        if reach is None:
            return None
        ahead = np.arange(0.0, _reach(reach, self._planner_name) + PATH_STEP / 2, PATH_STEP)
        return np.stack([self._routes[i].points_at(self._s_hint[i] + ahead) for i in idx])

    @property
    def _planner_name(self) -> str:
        return f"planner `{getattr(self.planner, 'name', type(self.planner).__name__)}`"

    def _guard(self, s: _Sensed) -> None:
        """The robot's own safety on every active robot's command (:mod:`.safety`): the brake,
        and backing out of a pocket when it has held the robot too long; their first sweeps
        measured together (:meth:`.safety.Fleet.guard`)."""
        if self._traffic:
            self._give_way(s.command, self._active, self._x, self._y, self._v, self._s_hint)
        fleet = self._fleet
        rows = (self._active & fleet.brakes).nonzero()[0]
        maps = [self._maps[i] for i in rows.tolist()]

        pose = np.stack([self._x, self._y, self._h], axis=1) if self._traffic else None

        def near(j: np.ndarray, points: np.ndarray, half: np.ndarray) -> list[np.ndarray]:
            cells = [maps[k].brake_cells(p, r) for k, p, r in zip(j.tolist(), points,
                                                                  half.tolist())]
            if pose is not None:
                cells = [_with_mates(c, self._mates_bodies(int(rows[k]), self._active, pose,
                                                           self._v))
                         for k, c in zip(j.tolist(), cells)]
            return cells

        now = (self._x, self._y, self._h, self._steer, self._v, s.inputs["heading"])
        for i in fleet.guard(rows, s.command, self._recovery, now, near):
            self._backed.append((self._k, i))

    def _give_way(self, command: np.ndarray, active: np.ndarray, x: np.ndarray, y: np.ndarray,
                  speed: np.ndarray, progress: np.ndarray) -> None:
        """The speeds of ``command [n, 2]`` held to where each robot gives way to another
        (:mod:`.traffic`), from the robots' ``active``, place (``x``, ``y``), ``speed`` and
        route ``progress``."""
        mates = [traffic.Mate(self._routes[i], float(progress[i]), float(x[i]), float(y[i]),
                              float(speed[i]), r, self._maps[i]) if share and active[i] else None
                 for i, (r, share) in enumerate(zip(self.robots, self._traffic))]
        limit = self._ways.limits(mates, self.dt)
        held = limit < command[:, 1]
        if held.any():
            command[held, 1] = limit[held]
        # (waiting: held, or told no faster than the limit: a planner that stops for the
        # robot it gives way to, at a limit of 0, waits as much as one the limit stops)
        waiting = limit <= command[:, 1]
        if waiting.any():
            self._gave_way_at[waiting] = self._k

    def act(self, s: _Sensed) -> None:
        """Steering-rate and acceleration limits and exact arcs, substep by substep; stopped
        robots stay put."""
        motion = self.motion(s)
        self.move_to(*kinematics.step(*motion, self.limits, self.dt, self.world.substeps))
        self._came = _Came(motion, 0, self.n)

    def motion(self, s: _Sensed | None = None) -> kinematics.Motion:
        """What :func:`kinematics.step` moves from, ``[n]`` each: x, y, heading, speed (0 for
        a stopped robot), steering, and the commanded steering and speed (of ``s``, default:
        the tick :meth:`decide` just recorded)."""
        s = self.decided if s is None else s
        return (self._x, self._y, self._h, np.where(self._active, self._v, 0.0), self._steer,
                s.command[:, 0], s.command[:, 1])

    def move_to(self, x: np.ndarray, y: np.ndarray, h: np.ndarray, v: np.ndarray,
                steer: np.ndarray) -> None:
        """The robots' state after :func:`kinematics.step` (fresh arrays, never changed in
        place: the history keeps them)."""
        driven = np.hypot(x - self._x, y - self._y)
        self._odometer.append(self._odometer[-1] + driven if self._odometer else driven)
        self._best.append(_nearer(self._best[-1], x, y, self._goal_x, self._goal_y,
                                  self._lengths - self._s_hint))
        self._x, self._y, self._h, self._v, self._steer = x, y, h, v, steer
        self._moved_by = None                           # (its own arrays, not a batch's)
        self._came = None                               # (act says how, when it moved it)

    def _check_stuck(self) -> bool:
        """A driving robot is stuck (the run ends) when it drove less than ``STUCK_DISTANCE``
        in ``STUCK_TIME``, or came no more than ``PROGRESS_DISTANCE`` nearer its goal than it
        had been, in a straight line or along its route, in ``PROGRESS_TIME``
        (:func:`_stalled`). Driven, not displaced: a robot backing out of a pocket and turning
        round may come back near where it was, and it was not stuck; one that does so again
        and again for ``PROGRESS_TIME`` without getting nearer its goal is."""
        odometer, window, best, slow = (self._odometer, self._stuck_window, self._best,
                                        self._progress_window)
        if len(odometer) <= window and len(best) <= slow:
            return False
        return self._stuck(_stalled(
            self._active, odometer[-1], odometer[-1 - window] if len(odometer) > window else None,
            best[-1], best[-1 - slow] if len(best) > slow else None))

    def _stuck(self, stuck: np.ndarray) -> bool:
        """Whether any robot is ``stuck [n]``; those read ``stuck``. A robot that gave way
        to another in the last ``STUCK_TIME`` is waiting, not stuck."""
        if self._traffic:
            stuck = stuck & (self._k - self._gave_way_at > self._stuck_window)
        for i in stuck.nonzero()[0]:
            self._outcomes[i] = "stuck"
        return bool(np.count_nonzero(stuck))

    def _record(self, s: _Sensed) -> Tick:
        return self._keep(s, _columns(self._x, self._y, np.rad2deg(self._h)), self._v.copy(),
                          self._steer.copy(), self._active.copy(), self._s_hint.copy())

    def _keep(self, s: _Sensed, pose: np.ndarray, speed: np.ndarray, steering: np.ndarray,
              active: np.ndarray, progress: np.ndarray) -> Tick:
        """Record tick ``s`` with the robots' state as it was observed (arrays no later
        tick changes in place: the record keeps them)."""
        tick = Tick(self._k, s.t, pose, speed, steering, s.command, s.ranges, s.block,
                    s.clearance, s.where, active, progress)
        _read_only(pose, speed, steering, s.command, active, progress)
        self.record.append(tick)
        return tick

    # -- the recorded run -------------------------------------------------------------------

    def result(self) -> SimResult:
        """The recorded ticks as a :class:`SimResult` with the run's metrics."""
        rec, dt = self.record, self.dt
        T = len(rec)
        if not T:
            raise RuntimeError("no tick recorded yet: result() reports the ticks step() ran")

        columns = self._booked()
        if columns is None:
            # every recorded field's arrays gathered in one pass over the ticks (one getter
            # call a tick, where a pass a field made ten getattr a tick)
            parts = dict(zip(_RECORDED, map(list, zip(*map(_RECORD_OF, rec)))))
            columns = {name: (_repeated if name == "obstacles" else _stacked)(parts[name])
                       for name in _RECORDED}

        def stack(attr: str) -> np.ndarray:
            return columns[attr]

        inputs = stack("block")                         # [T, inputs, n]
        res = SimResult(
            world=self.world, seed=self.seed,
            planner=getattr(self.planner, "name", type(self.planner).__name__),
            outcome=self._verdict(), robot_outcomes=tuple(self._outcomes),
            collisions=self._collided, t=np.arange(T) * dt, pose=stack("pose"),
            speed=stack("speed"), steering=stack("steering"),
            command=stack("command"), ranges=stack("ranges"),
            perceived=dict(zip(perception.INPUTS, inputs.transpose(1, 0, 2).copy())),
            clearance=stack("clearance"), obstacles=stack("obstacles").reshape(T, -1, 2),
            routes=self.scene.routes, static=self.scene.static, active=stack("active"),
            progress=stack("progress"), replanned=tuple(self._replanned),
            backed_out=tuple(self._backed))
        res.robot_metrics = _robot_metrics(res, dt)
        res.metrics = _metrics(res, dt)
        return res

    def _booked(self) -> dict[str, np.ndarray] | None:
        """The recorded fields stacked ``[T, ...]`` from the :class:`_Book` pages of the
        lockstep batches that recorded every tick of the run (a slice of a page a field, not
        an array a tick); ``None`` when a tick was recorded otherwise (the run alone, or
        stepped by hand) or the record is not the ticks the pages hold."""
        rec, pages = self.record, self._pages
        if not pages:
            return None
        parts: list[list[np.ndarray]] = [[] for _ in _BOOKED]
        at = 0
        for book, j, start in pages:
            ticks = book.ticks[j]
            n = len(ticks)
            if start != at or not n or not all(map(operator.is_, ticks, rec[at:at + n])) \
                    or ticks[0].pose.base is not book.pose:     # (a copy's: its own arrays)
                return None
            a, b = book.spans[j]
            for into, name in zip(parts, _BOOKED):
                into.append(book.rows(name, n, a, b))
            at += n
        if at != len(rec):
            return None
        out = {name: np.concatenate(into) for name, into in zip(_BOOKED, parts)}
        out["obstacles"] = _repeated([tick.obstacles for tick in rec])
        return out


#: The fields of a :class:`Tick` that :meth:`Simulation.result` stacks, and their getter.
_RECORDED = ("pose", "speed", "steering", "command", "ranges", "block", "clearance",
             "obstacles", "active", "progress")
_RECORD_OF = operator.attrgetter(*_RECORDED)


#: The fields of a :class:`Tick` a lockstep batch keeps in its :class:`_Book` pages.
_BOOKED = ("pose", "speed", "steering", "command", "ranges", "block", "clearance", "active",
           "progress")


def _repeated(parts: list[np.ndarray]) -> np.ndarray:
    """:func:`_stacked`, or one array repeated when every part is that array (obstacles that
    stand still: the same places every tick)."""
    first = parts[0]
    if all(map(operator.is_, parts, itertools.repeat(first))):
        return np.broadcast_to(first, (len(parts), *first.shape)).copy()
    return _stacked(parts)


class _Book:
    """Ticks a lockstep batch recorded, up to :attr:`TICKS` of them: each recorded field of
    all the batch's rows at each tick in one array ``[ticks, rows, ...]`` (a page), each
    run's :class:`Tick` views of its rows, and the ticks of each run (``ticks``; ``spans``:
    its rows). A run's result then copies its rows of a page in one slice a field instead of
    joining an array a tick (:meth:`Simulation._booked`)."""

    TICKS = 64

    def __init__(self, spans: list[tuple[int, int]], beams: int) -> None:
        rows = spans[-1][1]
        self.spans = spans
        self.pose = np.empty((self.TICKS, rows, 3))
        self.speed, self.steering, self.clearance, self.progress = (
            np.empty((self.TICKS, rows)) for _ in range(4))
        self.command = np.empty((self.TICKS, rows, 2))
        self.ranges = np.empty((self.TICKS, rows, beams))
        self.block = np.empty((self.TICKS, rows, len(perception.INPUTS)))   # a row's inputs
        self.active = np.empty((self.TICKS, rows), dtype=bool)
        self.ticks: list[list[Tick]] = [[] for _ in spans]

    @property
    def full(self) -> bool:
        return len(self.ticks[0]) == self.TICKS

    def rows(self, name: str, n: int, a: int, b: int) -> np.ndarray:
        """Rows ``a:b`` of the first ``n`` ticks of field ``name``, laid out as
        :func:`_stacked` lays out the ticks' arrays (a view)."""
        got = getattr(self, name)[:n, a:b]
        return got.transpose(0, 2, 1) if name == "block" else got


def _stacked(parts: list[np.ndarray]) -> np.ndarray:
    """``np.array(parts)`` of arrays of one shape, ``[len(parts), *shape]``: one concatenation
    (``np.array`` looks at each part on its own: 5 ms of a run's 500 ticks)."""
    return np.concatenate(parts).reshape(len(parts), *np.shape(parts[0]))


def _sights(aims: list[perception.Aim], robots: list, pose: np.ndarray, dirs: np.ndarray,
            measured: np.ndarray, expected: np.ndarray, spacing: np.ndarray,
            threshold: np.ndarray, least: np.ndarray, kept: np.ndarray, targets: np.ndarray,
            gaps: list[float], squeeze: np.ndarray) -> perception.Sights:
    """The robots' :class:`.perception.Sights` from their aims (``gaps``: their
    :func:`.perception.route_gaps`) and the rest of their rows: one rule for a run alone and
    for runs in lockstep. How far a lane may lie off its route is
    :func:`.perception.route_room`'s ``max(0.0, gap - radius - least)``, elementwise."""
    room = np.array(gaps) - np.array([a.radius for a in aims]) - least
    return perception.Sights([a.route for a in aims], [a.f for a in aims], robots, pose, dirs,
                             measured, expected, spacing, threshold,
                             np.where(room > 0.0, room, 0.0), least, kept, targets, squeeze)


def _with_mates(cells: np.ndarray, bodies: np.ndarray | None) -> np.ndarray:
    """A robot's brake cells, then its mates' bodies (``None``: it has none)."""
    return cells if bodies is None else np.concatenate([cells, bodies])


def _news(ranges: np.ndarray, expected: np.ndarray | None, far: float,
          threshold: float | np.ndarray) -> np.ndarray:
    """Which readings show what a robot's map does not: an echo (shorter than ``far``), and,
    where the map predicts ranges (``expected``), ``threshold`` shorter than predicted. One
    rule for a run alone and for runs in lockstep (``threshold`` a column: each run's)."""
    seen = ranges < far
    if expected is not None:
        seen &= ranges < expected - threshold
    return seen


def _half_turn(deg: float) -> float:
    """A start heading (deg) within ±180, as every later tick's is: a start written as 720
    was recorded as 720 at tick 0 (`--out`, `--trace`, the Gymnasium pose) and as 0 from tick
    1 on. One within ±180 is kept as written, to the bit."""
    return deg if -180.0 <= deg <= 180.0 else math.remainder(deg, 360.0) + 0.0   # (not -0)


def _arrivals(active: np.ndarray, clearance: np.ndarray, x: np.ndarray, y: np.ndarray,
              goal_x: np.ndarray, goal_y: np.ndarray, tol: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """Which robots touch something (clearance 0 or less) and which driving robots are at
    their goals: one rule for a run alone and for runs in lockstep. A robot parked at its
    goal counts too: a cart or another robot that drives into it has collided with it (only
    the driving robots counted, a cart drove 15 in deep into a parked robot and the run read
    a success without a collision)."""
    return (clearance <= 0.0,
            active & (np.hypot(x - goal_x, y - goal_y) <= tol))


#: The row of the route's side (``heading``) in a tick's block of inputs.
_SIDE = perception.INPUTS.index("heading")

#: Each start of a run (:meth:`Simulation.reset`) is told apart by a number from here.
_EPOCHS = itertools.count()


#: A run's arc lengths (:meth:`Batch.framing` asks whether each run's are still the batch's).
_HINT = operator.attrgetter("_s_hint")
#: What moved a run last, and what it has driven after each move (:meth:`Batch.move`).
_MOVED_BY, _ODOMETER = operator.attrgetter("_moved_by"), operator.attrgetter("_odometer")


def _all_moved_by(runs: list[Simulation], token: object) -> bool:
    """Whether every run of ``runs`` was moved last by the batch's move that left ``token``
    (one pass in C: a batch asks it of a hundred runs a few times a tick)."""
    return all(map(operator.is_, map(_MOVED_BY, runs), itertools.repeat(token)))


def row_spans(runs: list[Simulation]) -> list[tuple[int, int]]:
    """Where each run's robots lie in the rows of all of them, one run after the other."""
    stops = list(itertools.accumulate(run.n for run in runs))
    return list(zip([0, *stops[:-1]], stops))


class Batch:
    """Runs of one world stepped together (:mod:`.lockstep`), their robots one after the
    other in the batch's rows: the bookkeeping each run does alone each tick (its arrays, the
    check, the record, the verdict, the move) done once for the robots of all, elementwise,
    so each run keeps the bits it has alone. A run's pose, readings, inputs and commands of a
    tick are views of the batch's arrays, which are fresh each tick: a run's record keeps
    them, so no later tick may write into them. Whether each robot drives and its recovery
    are the batch's arrays from tick to tick, each run holding views of them, written in
    place only; so is the state :meth:`move` left, until a run is moved otherwise. A batch
    is of the runs as they were started (:meth:`serves`); they are at the same tick when it
    steps them."""

    def __init__(self, runs: list[Simulation]) -> None:
        self.runs = runs
        self._epochs = [run._epoch for run in runs]
        self.spans = row_spans(runs)
        self._starts = np.array([a for a, _ in self.spans])
        self._owner = [(run, i) for run in runs for i in range(run.n)]   # each row's robot
        self._single = len(self._owner) == len(runs)            # a robot a run (most worlds)
        # the runs whose robots give way to each other (Simulation._give_way), with their rows
        self._traffic = [(run, a, b) for run, (a, b) in zip(runs, self.spans) if run._traffic]
        # the runs' x, y, heading, speed and wheel as :meth:`move` left them (each run's
        # views of them), and the token it left on each run it moved
        self._moved: tuple[tuple[np.ndarray, ...], object] | None = None
        # the runs' rows of rows.sense, kept from tick to tick where each run is of one robot
        # among obstacles that stand still (sense_rows), and the sides of those obstacles
        self._keeps_rows = self._single and all(run._still is not None for run in runs)
        self._sensing: list[rows.SenseRow] = []
        # where each run's robot had its walls gathered as the batch last saw it (the run's
        # own tuple, and [rows, 2] of them): its walls stay while it is plainly near there
        self._gathered: list[tuple[float, float]] = []
        self._gathered_at = np.zeros((0, 2))
        self._sides = ([run._still[1][3] for run in runs if run._still is not None]
                       if self._keeps_rows else [])
        self._goal_x, self._goal_y, self._tol = (self._gather(name)
                                                 for name in ("_goal_x", "_goal_y", "_tol"))
        # whether each robot drives, its safety.Recovery and its route length
        # (Simulation.replanned writes it), shared; what the runs had driven after the
        # batch's last moves
        self._active, self._recovery = self._share("_active"), self._share("_recovery")
        self._straight = np.concatenate([run.limits.straight for run in runs])
        self._bounds = (np.concatenate([run._bounds[0] for run in runs]),
                        np.concatenate([run._bounds[1] for run in runs]))
        self._lengths = self._share("_lengths")
        self._trail: list[tuple[np.ndarray, np.ndarray]] = []
        self.stacked: rows.Kept = {}        # what its last rows.sense stacked of the runs' rows
        self.maps = [m for run in runs for m in run._maps]
        self._plain = all(run._plain for run in runs)
        # (Simulation.seeing: the runs of one world are given the same map and sensors; a
        # randomised run draws its own sensor noise, so its own news threshold)
        self._knows = runs[0]._given.knows != "none"
        self._far = runs[0].world.sensors.range * 0.999
        self._threshold = np.array([run._threshold for run in runs
                                    for _ in range(run.n)])[:, None]
        # (Simulation.aims)
        self.reaches = np.array([run._cfg.lookahead + least
                                 for run in runs for _, least in run._asked])
        self._when = runs[0].world.replan
        self._rows = [(j, i) for j, run in enumerate(runs) for i in range(run.n)]
        self._radius = [m.grid.resolution / 2 for m in self.maps]
        self._need = [least + run._cfg.lookahead_room for run in runs for _, least in run._asked]
        self.dilations = knowledge.Dilations()       # (knowledge.accounted_all)
        self._book: _Book | None = None              # the ticks it recorded last (verdict)
        # (Simulation.aimed)
        self._robots = [r for run in runs for r in run.robots]
        self._spacing, _, self._least, self._squeeze = (
            np.concatenate([run._sighting[j] for run in runs]) for j in range(4))
        # (Simulation.watching)
        self._follows = runs[0].world.replan != "never"
        self._trackers = [t for run in runs for t in run._trackers]
        self._spaces = [f for run in runs for f in run._free]
        self._kept = movers.Spaces.stacked(self._spaces) if self._follows else None
        self._seen = np.zeros((0, 0), dtype=bool)
        self._watching = np.zeros(0, dtype=np.intp)         # the rows that follow something
        # (aims) the tick's marks as watching() took them: whether each row's map was marked
        # and whether it follows something, [rows] each; None where each run took its own
        self._news: tuple[np.ndarray, np.ndarray] | None = None
        self._learned: list[bool] = []          # (watching) each row's map marked, for _watch
        self._limits: kinematics.Limits | None = None
        self._fleet = safety.Fleet.joined([run._fleet for run in runs])
        # (_between) each row's swing and its run's drift; what move() moved from last, and
        # the clearances verdict() recorded last
        self._swing = self._gather("_swing")
        self._drift = np.repeat([run._drift for run in runs], [b - a for a, b in self.spans])
        self._came: kinematics.Motion | None = None
        self._before = np.zeros(0)
        # the tick observed last (:meth:`sensed`): its runs' ticks, x, y and heading, readings,
        # robots' places, inputs (a row each), targets, commands, contacts and who drives
        self.ticks: list[_Sensed] = []
        self._now: tuple[np.ndarray, ...] | None = None
        # its robots' speeds and wheels (the batch's tick leaves them as they were until it
        # moves them) and their arc lengths along their routes (:meth:`aims`)
        self._drive: tuple[np.ndarray, np.ndarray] = (np.zeros(0), np.zeros(0))
        self._hint = np.zeros(0)
        # the arc lengths :meth:`aims` gave the runs, and each run's view of them
        self._hints: tuple[np.ndarray, list[np.ndarray]] = (np.zeros(0), [])
        self.got = rows.Sensed(np.zeros((0, 0, 2)), np.zeros((0, 0)), np.zeros((0, 0)), np.zeros(0))
        self.pose, self.at = np.zeros((0, 3)), np.zeros((0, 2))
        self.block = np.zeros((len(perception.INPUTS), 0))
        self.targets, self.command = np.zeros((0, 2)), np.zeros((0, 2))
        self.hit, self.active = np.zeros(0, dtype=bool), np.zeros(0, dtype=bool)

    def serves(self, runs: list[Simulation]) -> bool:
        """Whether this is the batch of ``runs``: the same runs, none started again since."""
        return (len(runs) == len(self.runs)
                and all(a is b and a._epoch == e for a, b, e in zip(runs, self.runs,
                                                                    self._epochs)))

    def _gather(self, name: str) -> np.ndarray:
        """The runs' arrays ``name`` one after the other (a fresh array)."""
        return np.concatenate([getattr(run, name) for run in self.runs])

    def _share(self, name: str) -> np.ndarray:
        """The runs' arrays ``name`` gathered into one of the batch's, each run given its
        view of it in place of its own: written in place only from then on, by the run alone
        or by the batch, both see every change."""
        whole = self._gather(name)
        for run, view in zip(self.runs, self._each(whole)):
            setattr(run, name, view)
        return whole

    def _each(self, rows: np.ndarray) -> list[np.ndarray]:
        """Each run's rows of ``rows [robots, ...]``, views, one run after the other (a robot
        a run: split in one pass, not sliced run by run)."""
        if self._single:
            return list(rows[:, None])
        return [rows[a:b] for a, b in self.spans]

    def _state(self) -> tuple[np.ndarray, ...]:
        """The runs' x, y, heading, speed and wheel, ``[rows]`` each: those :meth:`move` left
        while every run still holds its views of them (a run moved alone or started again
        holds arrays of its own, :meth:`Simulation.move_to`), else gathered afresh. Neither
        is written into here."""
        if self._moved is not None and _all_moved_by(self.runs, self._moved[1]):
            return self._moved[0]
        return tuple(self._gather(name) for name in ("_x", "_y", "_h", "_v", "_steer"))

    def sense_rows(self) -> list[rows.SenseRow]:
        """:meth:`Simulation.sense_rows` of every run. A run of one robot among obstacles that
        stand still keeps its row from tick to tick: only the robot's place and heading
        change, and its walls once it moved on (:meth:`Simulation._walls_near`)."""
        if not self._keeps_rows:
            return [part for run in self.runs for part in run.sense_rows()]
        if not self._sensing:
            self._sensing = [run.sense_rows()[0] for run in self.runs]
            self._gathered = [run._near_at[0] for run in self.runs]
            self._gathered_at = np.array(self._gathered)
            return self._sensing
        x, y, h = self._state()[:3]
        may = self._may_gather(x, y).tolist()
        x, y, h = x.tolist(), y.tolist(), h.tolist()
        gathered = self._gathered
        for j, (run, row, sides, far, *at) in enumerate(zip(self.runs, self._sensing,
                                                            self._sides, may, x, y, h)):
            row.x, row.y, row.heading = at
            if far or run._near_at[0] is not gathered[j]:
                walls = run._walls_near(0, at[0], at[1])
                row.walls, row.segments = walls, run._joined(0, walls, sides)
                gathered[j] = run._near_at[0]
                self._gathered_at[j] = gathered[j]
        return self._sensing

    def _may_gather(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """``[rows]``: whether each run's robot, at ``x, y``, may have moved ``NEAR_SLACK``
        from where its walls were gathered (:meth:`Simulation._walls_near`), as the batch
        last saw it: its squared distance not plainly within ``NEAR_SLACK`` (a margin far
        above rounding), so every robot left out is one whose ``math.hypot`` is within it and
        whose walls stay."""
        dx = x - self._gathered_at[:, 0]
        dy = y - self._gathered_at[:, 1]
        return ~(dx * dx + dy * dy < _WITHIN_SLACK)

    def sensed(self, got: rows.Sensed) -> list[_Sensed]:
        """:meth:`Simulation.sensed` of every run from the rows of all (``got``): the tick's
        arrays made once, each run's :class:`_Sensed` views of them."""
        x, y, h, *drive = self._state()
        self._now, self._drive = (x, y, h), (drive[0], drive[1])
        self._news = None
        pose = _columns(x, y, h)
        n = len(x)
        # a row per input, as alone, laid out a robot's inputs after another's: a run of one
        # robot holds a block [inputs, 1] whose bytes lie together (result() joins them)
        inputs = np.zeros((n, len(perception.INPUTS)))
        self.block = inputs.T
        self.targets, self.command = np.zeros((n, 2)), np.zeros((n, 2))
        dirs, static = list(got.dirs), list(got.static)
        arrays = (pose, got.ranges, self.targets, got.clearance, self.command, self.block)
        self.ticks = []
        for run, (a, b) in zip(self.runs, self.spans):
            if self._plain:                               # (Simulation._beams)
                run._dirs, run._expected = dirs[a:b], static[a:b]
            else:
                run._beams(pose[a:b], dirs[a:b], static[a:b])
            self.ticks.append(_RowsSensed._on(run.time, run._where, arrays, a, b))
        self.got, self.pose, self.at = got, pose, pose[:, :2].copy()
        return self.ticks

    def seeing(self) -> np.ndarray:
        """:meth:`Simulation.seeing` of every run at once: ``[rows, B]``."""
        expected = None
        if self._knows:
            expected = (self.got.static if self._plain else
                        np.array([e for run in self.runs for e in run._expected]))
        self._seen = seen = _news(self.got.ranges, expected, self._far, self._threshold)
        if self._traffic:
            seen = seen.copy()
        for run, a, b in self._traffic:           # (from the news, ``seen`` being a copy)
            seen[a:b], self._seen[a:b] = run._mates_echoes(
                self._seen[a:b], self._active[a:b], self.pose[a:b], self._drive[0][a:b],
                self.got.ranges[a:b], self.got.dirs[a:b])
        return seen           # (no run's own: a run reads it only where it marks its map)

    def tracked(self, sighted: list[movers.Seen]) -> None:
        """:meth:`Simulation.tracked` of every run once they are :meth:`watching`
        (``sighted``: what the robots that follow something see, in row order): every
        robot's beams kept, the tracks of all followed in one :func:`.movers.follow_all`."""
        if not self._follows:
            return
        got, t = self.got, self.ticks[0].t
        if self._kept is None:
            for space, p, dirs, ranges in zip(self._spaces, self.at, got.dirs, got.ranges):
                space.update(t, p, dirs, ranges)
        else:
            self._kept.update(t, self.at, got.dirs, got.ranges)
        movers.follow_all([self._trackers[i] for i in self._watching.tolist()], t, sighted)

    def watching(self, learned: list[bool]
                 ) -> tuple[Sequence[movers.FreeSpace], np.ndarray, np.ndarray, np.ndarray,
                            np.ndarray, np.ndarray]:
        """:meth:`Simulation.watching` of every run at once, their maps marked by
        :meth:`seeing` (``learned``: whether each row's was): the rows of the robots that
        follow something (those with tracks or news) with what :func:`.movers.sightings`
        looks at for them. Each run's watch is kept for the runs :meth:`aims` asks to
        replan (:meth:`_watch`), the only ones that read it."""
        follows = np.zeros(len(self._trackers), dtype=bool)
        if self._follows:
            follows = (np.array([bool(t.tracks) for t in self._trackers])
                       | np.logical_or.reduce(self._seen, axis=1))
        self._watching = rows = np.flatnonzero(follows)
        self._learned = learned
        self._news = (np.array(learned, dtype=bool), follows)
        got = self.got
        spaces = (self._kept.picked(rows) if self._kept is not None
                  else [self._spaces[i] for i in rows.tolist()])
        return spaces, rows, self.at[rows], got.ranges[rows], got.dirs[rows], self._seen[rows]

    def framing(self) -> tuple[list[Route], np.ndarray, np.ndarray]:
        """:meth:`Simulation.framing` of every run at once."""
        hint, views = self._hints
        if not (views and all(map(operator.is_, map(_HINT, self.runs), views))):
            hint = self._gather("_s_hint")        # (the runs' own, not those aims left)
        return [r for run in self.runs for r in run._routes], self.at, hint

    def aims(self, frames: list[perception.Frame],
             near: list[np.ndarray]) -> list[perception.Aim]:
        """:meth:`Simulation.aims` of every run at once, once they are tracked: the robots due
        a replanning check found in one pass (:func:`.knowledge.checks_due`), only their
        routes planned again (:meth:`Simulation.replanned`, robot by robot), and each robot's
        aim from the batch's rows (``frames``, ``near``: of the batch's rows)."""
        frames = list(frames)
        for row in self._may_replan(knowledge.checks_due(self.maps, self.ticks[0].t,
                                                         self._when)):
            j, i = self._rows[row]
            self._watch(j)
            frames[row] = self.runs[j].replanned(self.ticks[j], i, frames[row])
        hint = np.array([f.s for f in frames])
        self._hint = hint.copy()             # (for the record: no view of a run's own)
        self._hints = hint, self._each(hint)
        for run, mine in zip(self.runs, self._hints[1]):
            run._s_hint = mine
        routes = [route for run in self.runs for route in run._routes]
        return list(map(perception.Aim, routes, frames, self.at, near, self._radius,
                        self._need))

    def _watch(self, j: int) -> None:
        """Run ``j``'s watch of the tick (:meth:`Simulation.watching`), where :meth:`watching`
        marked its maps and saw for it: whether each of its robots' maps was marked, and
        which of them follow something."""
        run, s = self.runs[j], self.ticks[j]
        if self._news is None or run._watched[0] is s:      # (each run watched for itself)
            return
        a, b = self.spans[j]
        follows = self._news[1]
        run._watched = (s, self._learned[a:b], [i for i in range(b - a) if follows[a + i]])

    def _may_replan(self, due: list[int]) -> list[int]:
        """The rows of ``due`` (a replanning check due) whose route
        :meth:`Simulation.replanned` may plan again, in order: its first checks for all of them
        at once. A robot still driving whose map was marked this tick (:meth:`watching`), or
        that follows something (a mover among its tracks, :meth:`Simulation._sweep`) or waits
        at a refuge; the rest keep their routes. Most rows due are in none of these: a check
        stays due until there is something to check. Every row of ``due`` where the tick's
        marks were not taken here (each run marked its own)."""
        news = self._news
        if news is None or not due:
            return due
        learned, follows = news
        rows = np.array(due, dtype=np.intp)
        driving = self._active[rows]
        rest = rows[driving & ~learned[rows]].tolist()
        maybe = rows[driving & learned[rows]].tolist()
        maybe += [row for row in rest
                  if self.maps[row].refuge is not None
                  or follows[row] and any(tr.mover for tr in self._trackers[row].tracks)]
        return sorted(maybe)

    def aimed(self, aims: list[perception.Aim], targets: np.ndarray, gaps: list[float],
              accounted: np.ndarray) -> perception.Sights:
        """:meth:`Simulation.aimed` of every run at once, from the batch's rows
        (``accounted [rows, B]``: their :meth:`Simulation.accounted`)."""
        got = self.got
        expected = (got.static if self._plain else
                    np.array([e for run in self.runs for e in run._expected]))
        return _sights(aims, self._robots, self.pose, got.dirs, got.ranges, expected,
                       self._spacing, self._threshold[:, 0], self._least, accounted, targets,
                       gaps, self._squeeze)

    def conclude(self, inputs: dict[str, np.ndarray], targets: np.ndarray) -> None:
        """:meth:`Simulation.perceived` and :meth:`Simulation.conclude` of every run: the
        rows' ``inputs`` and ``targets`` kept, the check made once for every robot. The runs
        are not left observed (:attr:`Simulation.observed`): the batch decides for them."""
        for j, key in enumerate(perception.INPUTS):
            self.block[j] = inputs[key]
        self.targets[:] = targets
        x, y, _ = self._ticked()
        self.hit, arrived = _arrivals(self._active, self.got.clearance, x, y, self._goal_x,
                                      self._goal_y, self._tol)    # (hit: each run's at verdict)
        self._between()
        for row in arrived.nonzero()[0].tolist():
            run, i = self._owner[row]
            run._outcomes[i] = "success"
        self._active &= ~arrived                                  # (the runs' too)
        self.active = self._active.copy()

    def _ticked(self) -> tuple[np.ndarray, ...]:
        assert self._now is not None, "sensed() first"
        return self._now

    def _between(self) -> None:
        """:meth:`Simulation._between` of every run, the robots whose clearance then and now
        leaves no room for a contact between found in one comparison. The clearances then
        and the move are this batch's while it recorded and moved every run last; a run
        recorded or moved otherwise looks for itself."""
        runs, clearance, hit, moved = self.runs, self.got.clearance, self.hit, self._moved
        if (self._came is None or moved is None or len(self._before) != len(clearance)
                or not _all_moved_by(runs, moved[1])):
            for run, c, touched in zip(runs, self._each(clearance), self._each(hit)):
                run._between(c, touched)
            return
        own = np.maximum(np.abs(self._came[3]), np.abs(self._drive[0])) * self._swing
        travel = own + self._drift
        if not self._single:
            travel += np.repeat(np.maximum.reduceat(own, self._starts),
                                [b - a for a, b in self.spans])
        maybe = (self._before + clearance <= travel) & ~hit
        for row in maybe.nonzero()[0].tolist():
            run, i = self._owner[row]
            found = run._touched_between(i, float(self._before[row]), float(clearance[row]),
                                         float(travel[row]))
            if found is not None:
                hit[row], clearance[row] = True, found

    def commanded(self, commands: np.ndarray | None) -> list[_Sensed]:
        """:meth:`Simulation.commanded` of every run: ``commands [rows, 2]`` for all (the
        stopped robots' rows are set here), else each run's planner plans its own."""
        if commands is None:
            out = []
            for run, s in zip(self.runs, self.ticks):
                run._observed = s
                out.append(run.commanded())
            return out
        if not np.isfinite(commands).all():                 # refused as a run alone does
            for run, s, (a, b) in zip(self.runs, self.ticks, self.spans):
                _finite(commands[a:b], f"the command of {run._planner_name} at {s.t:g} s")
        stopped = ~self.active
        commands[stopped, 0] = self._straight[stopped]
        commands[stopped, 1] = 0.0
        self.command[:] = commands
        return self.ticks

    def guard(self) -> None:
        """:meth:`Simulation._guard` of every run at once, on the commands :meth:`commanded`
        set: one :meth:`.safety.Fleet.guard` for all on the robots' recovery (the batch's
        array, each run's its view), what the maps hold round the first sweeps of the robots
        that brake found in one :func:`.knowledge.near_all` (round each sweep's box, a
        quarter of the cells of the robot's square), and the backing-outs given back to each
        robot's run."""
        x, y, h = self._ticked()
        v, steer = self._drive
        for run, a, b in self._traffic:
            run._give_way(self.command[a:b], self.active[a:b], x[a:b], y[a:b], v[a:b],
                          self._hint[a:b])
        fleet = self._fleet
        rows = (self.active & fleet.brakes).nonzero()[0]
        if not len(rows):
            return
        maps = self.maps if len(rows) == len(self.maps) else [self.maps[i] for i in rows.tolist()]

        def near(j: np.ndarray, points: np.ndarray, half: np.ndarray) -> list[np.ndarray]:
            cells = knowledge.brake_cells_all(maps if len(j) == len(maps) else
                                              [maps[k] for k in j.tolist()], points, half)
            if self._traffic:
                cells = [self._with_mates(int(rows[k]), c, x, y, h, v)
                         for k, c in zip(j.tolist(), cells)]
            return cells

        backs = fleet.guard(rows, self.command, self._recovery,     # (the runs' too)
                            (x, y, h, steer, v, self.block[_SIDE]), near)
        for row in backs:
            run, i = self._owner[row]
            run._backed.append((run._k, i))

    def _with_mates(self, row: int, cells: np.ndarray, x: np.ndarray, y: np.ndarray,
                    h: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``cells`` (what the map of the robot of batch ``row`` holds round its sweep), then
        its mates' bodies (:meth:`Simulation._mates_bodies`) where its run's robots share."""
        run, i = self._owner[row]
        if not run._traffic:
            return cells
        a = row - i
        pose = np.stack([x[a:a + run.n], y[a:a + run.n], h[a:a + run.n]], axis=1)
        return _with_mates(cells, run._mates_bodies(i, self._active[a:a + run.n], pose,
                                                    v[a:a + run.n]))

    def verdict(self) -> list[Simulation]:
        """:meth:`Simulation.verdict` of every run, once the guard has had its say: the
        tick's fields written into a page of the batch's :class:`_Book`, each run's tick
        recorded (views of its rows) and judged; the runs whose robots move now (:attr:`runs`
        itself where all of them do)."""
        kinematics.hold_commands(self.command, self._bounds)    # (as each run's verdict)
        book, i = self._page()
        x, y, h = self._ticked()
        pose = book.pose[i]
        pose[:, 0], pose[:, 1], pose[:, 2] = x, y, np.rad2deg(h)
        book.speed[i], book.steering[i] = self._drive      # (the runs' own: kept apart)
        book.command[i], book.ranges[i], book.clearance[i] = (self.command, self.got.ranges,
                                                              self.got.clearance)
        self._before = self.got.clearance
        book.block[i], book.active[i], book.progress[i] = self.block.T, self.active, self._hint
        hit = np.logical_or.reduceat(self.hit, self._starts)
        driving = np.logical_or.reduceat(self.active, self._starts)
        page = (i, *(getattr(book, name) for name in _BOOKED))     # (_Paged: the runs' ticks)
        for run, s, mine, span, kept in zip(self.runs, self.ticks, self._each(self.hit),
                                            self.spans, book.ticks):
            run._hit = mine
            tick = _Paged._on(run._k, s.t, s.where, page, *span)
            run.record.append(tick)
            kept.append(tick)
        if np.count_nonzero(hit) == 0 and np.count_nonzero(driving) == len(driving):
            for run, s in zip(self.runs, self.ticks):      # (Simulation._judge: all drive on)
                run._deciding = s
            return self.runs                                # (its own list: not to be changed)
        return [run for run, s, touch, drives in zip(self.runs, self.ticks, hit.tolist(),
                                                       driving.tolist())
                if run._judge(s, touch, drives)]

    def _trail_of(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """What the runs' odometers and least distances to their goals (``[rows]`` and
        ``[2, rows]``) were after each of the batch's last moves, latest last, while every
        run was moved by each of them (:meth:`move`): each run's last entries are then its
        views of these (else none is kept)."""
        moved = self._moved
        if moved is None or not _all_moved_by(self.runs, moved[1]):
            self._trail = []
        return self._trail

    def _back(self, trail: list[tuple[np.ndarray, np.ndarray]], ago: int,
              each: Callable[[Simulation], np.ndarray], axis: int = 0) -> np.ndarray:
        """The runs' odometers (``axis`` 0: ``[rows]``) or least distances (``axis`` 1:
        ``[2, rows]``) ``ago`` moves back, ``each`` run's: the batch's own where its
        :meth:`_trail_of` goes back so far (an entry holds the two in that order), else the
        runs' joined along ``axis``."""
        if len(trail) >= ago:
            return trail[-ago][axis]
        return np.concatenate([each(run) for run in self.runs], axis=axis)

    def _page(self) -> tuple[_Book, int]:
        """The batch's :class:`_Book` with room for this tick's page, and the page: each run
        told when its ticks begin in a book (:meth:`Simulation._booked`)."""
        book = self._book
        if book is None or book.full:
            book = self._book = _Book(self.spans, self.got.ranges.shape[1])
            for j, run in enumerate(self.runs):
                run._pages.append((book, j, len(run.record)))
        return book, len(book.ticks[0])

    def move(self) -> None:
        """:meth:`Simulation.act` and :meth:`Simulation.moved` of every run (each one's
        robots moving, as after :meth:`verdict`) in one call of the kinematics; the runs of a
        batch have run as many ticks."""
        runs = self.runs
        if self._now is None or any(run._deciding is not s for run, s in zip(runs, self.ticks)):
            # (not every run of the tick the batch observed moves by it: each run's own)
            x, y, h, *drive = self._state()
            self._now, self._drive = (x, y, h), (drive[0], drive[1])
            self.active = self._active.copy()
            self.command = np.concatenate([run.decided.command for run in runs])
        x, y, h = self._now
        v, steer = self._drive
        if self._limits is None:
            self._limits = kinematics.Limits(*(np.concatenate(
                [getattr(run.limits, f.name) for run in runs]) for f in fields(kinematics.Limits)))
        world = runs[0].world
        command = self.command.T.copy()
        motion = (x, y, h, np.where(self.active, v, 0.0), steer, command[0], command[1])
        after = kinematics.step(*motion, self._limits, world.dt, world.substeps)
        driven = np.hypot(after[0] - x, after[1] - y)         # (Simulation.move_to)
        ticks = len(runs[0]._odometer)
        assert len(set(map(len, map(_ODOMETER, runs)))) == 1, "runs ticked together"
        trail = self._trail_of()
        if ticks:
            driven = self._back(trail, 1, lambda run: run._odometer[-1]) + driven
        hint, views = self._hints
        if not (views and all(map(operator.is_, map(_HINT, runs), views))):
            hint = self._gather("_s_hint")
        best = _nearer(self._back(trail, 1, lambda run: run._best[-1], axis=1), after[0],
                       after[1], self._goal_x, self._goal_y, self._lengths - hint)
        window, slow = runs[0]._stuck_window, runs[0]._progress_window  # (_check_stuck)
        stuck = None
        if ticks + 1 > window or ticks + 2 > slow:
            stuck = _stalled(
                self.active, driven, (self._back(trail, window, lambda run: run._odometer[-window])
                                      if ticks + 1 > window else None),
                best, (self._back(trail, slow, lambda run: run._best[-slow], axis=1)
                       if ticks + 2 > slow else None))
            stuck_any = np.logical_or.reduceat(stuck, self._starts).tolist()
        trail.append((driven, best))
        if len(trail) > max(window, slow):
            del trail[0]
        token = object()
        bests = list(best.T[:, :, None]) if self._single else [best[:, a:b] for a, b in self.spans]
        for j, (run, (a, b), *state, gone, nearest) in enumerate(zip(
                runs, self.spans, *map(self._each, after), self._each(driven), bests)):
            run._x, run._y, run._h, run._v, run._steer = state
            run._moved_by = token
            run._came = _Came(motion, a, b)
            run._odometer.append(gone)
            run._best.append(nearest)
            run._k += 1
            if stuck is not None and stuck_any[j]:
                run._go_on(run._stuck(stuck[a:b]))
            else:
                run._done = run._k >= run.steps             # (run._go_on(False))
        self._moved = (after, token)
        self._came = motion
        self._now = None


def _nearer(best: np.ndarray, x: np.ndarray, y: np.ndarray, goal_x: np.ndarray,
            goal_y: np.ndarray, left: np.ndarray) -> np.ndarray:
    """``[2, n]`` each robot's least distance to its goal (in), in a straight line and along
    its route: ``best`` so far, or where it stands now (``x``, ``y``; ``left``: its route
    left, its route's length less how far along it it is) where that is nearer."""
    return np.minimum(best, np.stack([np.hypot(x - goal_x, y - goal_y), left]))


def _stalled(active: np.ndarray, driven: np.ndarray, driven_then: np.ndarray | None,
             best: np.ndarray, best_then: np.ndarray | None) -> np.ndarray:
    """``[n]`` the driving robots (``active``) that are stuck: their odometers now and
    ``STUCK_TIME`` ago (``driven``, ``driven_then``) less than ``STUCK_DISTANCE`` apart, or
    their least distances to their goals now and ``PROGRESS_TIME`` ago (``best``,
    ``best_then``, ``[2, n]``: :func:`_nearer`) less than ``PROGRESS_DISTANCE`` apart both
    in a straight line and along the route (``None``: the run is younger)."""
    stuck = np.zeros(len(active), dtype=bool)
    if driven_then is not None:
        stuck |= driven - driven_then < STUCK_DISTANCE
    if best_then is not None:
        stuck |= np.logical_and.reduce(best_then - best < PROGRESS_DISTANCE)
    return active & stuck


def check_seed(seed: object) -> int:
    """``seed`` as an int of 0 or more, else an :class:`InputError` saying so (NumPy's
    SeedSequence refused a negative seed with a bare ValueError from its internals, and
    ``int()`` made 3.7 the seed 3 without a word; ``True`` is not 1 here, as it is not in
    the engine's inputs or Gymnasium's ``reset``)."""
    try:           # (a bool first: NumPy 1.x takes its own as an index, with a warning)
        value = -1 if isinstance(seed, (bool, np.bool_)) else operator.index(seed)  # type: ignore[arg-type]
    except TypeError:
        value = -1
    if value < 0:
        shown = (f"a number of {value.bit_length():,} bits" if value.bit_length() > 1000
                 else f"`{seed!r:.40}`")          # (repr of over 4,300 digits raises)
        raise InputError(f"a seed is a whole number, 0 or more, not {shown}",
                         hint="seed=1, as `mitos simulate --seed 1`")
    return value


def check_world(world: object) -> None:
    """A :class:`World` whose numbers a world file could hold, else a :class:`WorldError`
    saying how to get one (a path got as far as ``'str' object has no attribute 'behavior'``)
    or naming the field (a World changed in Python: :mod:`.worldcheck`)."""
    if isinstance(world, World):
        from .worldcheck import check_built

        check_built(world)
        return
    hint = (f"load_world({str(world)!r}) reads it" if isinstance(world, (str, os.PathLike))
            else "load_world('worlds/corridor.yaml') reads a world file")
    raise WorldError(f"a simulation runs a loaded World, not {type(world).__name__} "
                     f"`{world!r:.60}`", hint=hint)


def _check_planner(planner: Planner) -> Planner:
    """``planner`` if it has the :class:`Planner` protocol's ``plan``; else an
    :class:`InputError` now, not an AttributeError at the first tick."""
    if callable(getattr(planner, "plan", None)):
        return planner
    from .planner import PLANNERS

    hint = (f"make_planner({planner!r}, world) from mitos_cli.sim.planner builds it"
            if isinstance(planner, str) and planner in PLANNERS
            else "FuzzyPlanner(rules_path, behavior), or any object with `name` and "
                 "`plan(percepts)`")
    raise InputError(f"a planner is an object with a `plan(percepts)` method, not "
                     f"{type(planner).__name__} `{planner!r:.60}`", hint=hint)


def _check_randomise(randomise: object) -> bool:
    """``randomise`` if it is ``True`` or ``False``; else an :class:`InputError` (``"no"``
    was true: a randomised run where the world as written was asked for, without a word)."""
    if isinstance(randomise, (bool, np.bool_)):
        return bool(randomise)
    raise InputError(f"randomise is True or False, not `{randomise!r:.40}`",
                     hint="randomise=True draws obstacle places and sensor noise from the "
                          "world's randomise: ranges, as `mitos simulate --randomise`")


def _planned(given: Any, who: str) -> tuple[Any, Any]:
    """What a planner returned as its ``(steering, speed)``, else a :class:`CommandError` in
    words: one ``[n, 2]`` array met Python's "not enough values to unpack" inside the loop,
    ``None`` "cannot unpack non-iterable NoneType", and a bool was a command of 1 deg or 1
    in/s, where every other entry point refuses bools."""
    from ..engine.inputs import holds_bool

    try:
        steer, speed = given
    except (TypeError, ValueError):
        raise CommandError(f"{who} must return (steering[n], speed[n]), not {_kind(given)}",
                           hint="return two arrays (or numbers), one value each for the "
                                "percepts' rows (the active robots)") from None
    if (type(steer) is np.ndarray and type(speed) is np.ndarray
            and steer.dtype.kind == speed.dtype.kind == "f"):
        return steer, speed                          # (the packaged planners', every tick)
    if holds_bool(steer) or holds_bool(speed):
        raise CommandError(f"{who} must return numbers, not bools: `{given!r:.80}`",
                           hint="give numbers: True and False would be read as 1 and 0")
    return steer, speed


def _kind(value: object) -> str:
    """``value`` in a message: its type and shape or length (``ndarray of shape (1, 2)``)."""
    name = type(value).__name__
    if isinstance(value, np.ndarray):
        return f"{name} of shape {value.shape}"
    if value is None:
        return "None"
    if isinstance(value, (list, tuple)):
        return f"{name} of {plural(len(value), 'item')}"
    return f"{name} `{value!r:.40}`"


def _reach(reach: object, who: str) -> float:
    """A planner's ``path_reach`` as inches from 0 to :data:`PATH_REACH`, else an
    :class:`InputError` naming the planner: NaN, infinity, 1e308 or text met NumPy's
    ``arange`` errors at the first tick, and a negative reach gave an empty path silently."""
    value = math.nan
    if isinstance(reach, (int, float, np.integer, np.floating)) and not isinstance(reach, bool):
        try:
            value = float(reach)
        except OverflowError:           # (10**400)
            value = math.inf
    if not 0.0 <= value <= PATH_REACH:
        raise InputError(f"{who} asks for a `path_reach` of `{reach!r:.40}`: the route ahead it "
                         f"is given, in inches from 0 to {PATH_REACH:,.0f}",
                         hint="set path_reach to a number of inches, or leave it out (None) "
                              "for no path")
    return value


def _read_only(*arrays: np.ndarray) -> None:
    """Make a tick's arrays read-only once observed or recorded: they are the record, and
    what :meth:`Simulation.observe` and :meth:`Simulation.step` hand out. Writing into them
    (``tick.pose``, an observation's ranges scaled in place) changed ``result()``, and an
    observation's inputs what the planner then decided."""
    for a in arrays:
        a.flags.writeable = False


def _too_large(what: str) -> CommandError:
    """The refusal of a command holding an int past a float's range (``10**400``), which
    NumPy's conversion met with a bare ``OverflowError``."""
    return CommandError(f"{what} must be finite numbers (steering deg, speed in/s): one is too "
                        f"large for a float", expected="numbers of magnitude at most 1.8e308")


def _finite(command: np.ndarray, what: str) -> np.ndarray:
    """``command`` (steering, speed rows), refused unless every number is finite: a NaN
    turned the robot's pose into NaN and failed a tick later, far from its cause."""
    if not np.isfinite(command).all():
        raise CommandError(f"{what} must be finite numbers (steering deg, speed in/s), not "
                         f"{command.tolist()}")
    return command


def simulate(world: World, planner: Planner | None = None, seed: int | None = None, *,
             randomise: bool = False, scene: Scene | None = None,
             on_tick: Callable[[int, dict], None] | None = None) -> SimResult:
    """Run ``world`` with ``planner`` (default: the packaged rule base's ``drive``) from
    ``seed`` (default: the world's). ``randomise`` draws obstacle places and sensor noise from
    the world's ranges first. ``on_tick(k, state)`` is called after each tick (``--live``)."""
    sim = Simulation(world, planner, seed, randomise=randomise, scene=scene)
    while not sim.done:
        tick = sim.step()
        if on_tick is not None:
            on_tick(tick.k, {"t": tick.t, "pose": tick.pose, "speed": tick.speed,
                             "steering": tick.steering, "inputs": tick.inputs,
                             "clearance": tick.clearance, "obstacles": tick.obstacles})
    return sim.result()


def true_inputs(res: SimResult) -> dict[str, np.ndarray]:
    """The rule inputs from the true geometry at every tick (noise-free map rays across the
    route for the road, exact obstacle and robot outlines for the obstruction and the side
    gaps), name -> ``[T, n]``."""
    world, static = res.world, res.static
    assert static is not None and res.progress is not None, "Simulation.result() records both"
    agents = world.agents
    n = len(agents)
    robots = [a.robot for a in agents]
    sen = world.sensors
    angles = sen.angles
    reach = sen.range + max(max(r.length, r.width) for r in robots)
    cfg = perception.Settings()
    least = [clearances(world, a)[1] for a in agents]
    shape_outline, outline_owner = obs_mod.outline_points(
        world.obstacles, np.zeros((len(world.obstacles), 2)))
    out = {key: np.zeros((res.ticks, n)) for key in perception.INPUTS}
    for k in range(res.ticks):
        where = res.obstacles[k]
        outline = shape_outline + where[outline_owner] if len(where) else shape_outline
        pose = res.pose[k].copy()
        pose[:, 2] = np.deg2rad(pose[:, 2])
        corners = _footprints(pose, robots)
        for i in range(n):
            walls = static.near(pose[i, 0], pose[i, 1], reach)
            route = res.route_at(k, i)
            f = perception.frame(route, pose[i, :2], res.progress[k, i])
            dirs = sensors.beam_directions(pose[i, 2], angles)
            expected = geometry.ray_segments(pose[i, :2], dirs, walls, sen.range)
            things = np.concatenate([outline] + [corners[j] for j in range(n) if j != i])
            sides = perception.true_sides(f, tuple(pose[i]), dirs, expected, things, robots[i],
                                          sen.range, cfg)
            seen = expected < sen.range * 0.999
            wall_points = pose[i, :2] + expected[:, None][seen] * dirs[seen]
            known = np.concatenate([wall_points, things])
            ahead = perception.clear_lookahead(route, f, pose[i, :2], known, 0.0,
                                               least[i] + cfg.lookahead_room, cfg)
            room = perception.route_room(f, pose[i, :2], known, 0.0, least[i])
            tr = perception.truth(route, f, tuple(pose[i]), robots[i], sides, things, cfg,
                                  wall_points, ahead, room)
            for key in perception.INPUTS:
                out[key][k, i] = tr[key]
    return out
