"""BARN-style worlds: cellular-automaton obstacle fields with a guaranteed way through.

After Perille et al., "Benchmarking Metric Ground Navigation" (BARN, 2020): a field of 30 x 30
cells of 0.15 m is filled at random with a *fill percentage*, then smoothed by a cellular
automaton for a number of *smoothing iterations* (a cell with at least ``FILL_THRESHOLD`` of its
8 neighbours filled becomes filled, one with at most ``CLEAR_THRESHOLD`` becomes free, the rest
keep their state); a field with no way through for the robot is drawn again. "A way through"
is the route planner's own: the least clearance a route accepts for the robot
(:func:`.route.clearances`: half its width and its safety margin), kept by a route that
:func:`.route.grid_route` finds on the field drawn as a map, so every known field has a route
and the unknown field's poles leave the robot that same way. The robot is
Jackal-sized (20 x 17 in), starts in front of the field, and must reach a goal 10 m ahead
(within 1 m) in 100 s, as BARN's protocol has it.

The layout, in inches (the project's unit; 1 m = 39.37 in), x along the way to the goal:

- the robot starts at (0, 0) heading +x; the field's first column of cells is
  ``FIELD_AHEAD`` ahead of it; the goal is at (10 m, 0) with a 1 m tolerance;
- the field is 4.5 m wide, centred on y = 0, between two walls that run from behind the start to
  beyond the goal (a corridor as wide as the field), so the robot must cross the field;
- each filled cell is a 0.15 m square pole.

Two ways to give the field to the robot (``known``):

- unknown (default): the map is the bare corridor and every run of filled cells along a row is a
  rectangle under ``obstacles:``. The route is straight down the corridor; only the range
  readings show the poles, as in BARN, where the robot has no map;
- known: the map is an occupancy grid of 0.15 m cells holding the walls and the poles, and there
  are no obstacles: the route is planned around the poles.

``barn_world(seed, fill, smoothing)`` is a pure function of its arguments; ``barn_worlds(n, seed)``
draws n worlds whose difficulty (fill 0.15-0.30, smoothing 2-4, BARN's range) and field come
from ``SeedSequence(seed)``. ``python -m mitos_cli.sim.barn --seed S --out world.yaml`` writes
one as a world file (a known one also writes its map as PGM + map_server YAML beside it).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .gridmap import INCH_PER_M
from .route import NarrowPassage, clearances, grid_route
from .staticmap import StaticMap
from .world import Agent, Corridor, Goal, Grid, Obstacle, Pose, Randomise, Robot, Sensors, World

if TYPE_CHECKING:
    from collections.abc import Sequence

M = INCH_PER_M                 # in per metre
CELLS = 30                     # the field is CELLS x CELLS cells
CELL = 0.15 * M                # in: a cell's side (0.15 m)
FIELD = CELLS * CELL           # in: the field's side (4.5 m)
FIELD_AHEAD = 1.0 * M          # in: from the start to the field's first column
GOAL_AHEAD = 10.0 * M          # in: BARN's goal, 10 m ahead of the start
GOAL_TOLERANCE = 1.0 * M       # in: BARN's success radius
TIME_LIMIT = 100.0             # s: BARN's limit
BEHIND = 1.0 * M               # in: corridor behind the start
BEYOND = 1.0 * M               # in: corridor beyond the goal
FILL_THRESHOLD = 5             # filled neighbours that fill a cell
CLEAR_THRESHOLD = 1            # filled neighbours (or fewer) that clear a cell
FILLS = (0.15, 0.20, 0.25, 0.30)
SMOOTHINGS = (2, 3, 4)
MAX_DRAWS = 2000               # fields drawn before giving up on a way through

JACKAL = Robot(wheelbase=13.0, length=20.0, width=17.0)   # 0.508 x 0.430 m
LIDAR = Sensors(layout="fan", count=109, fov=270.0, cone=0.0, range=150.0, noise=0.5)


@dataclass(frozen=True)
class Field:
    """A generated field: ``filled[row, col]``, row 0 at the bottom (y grows with the row),
    column 0 nearest the start; and how it was made."""

    filled: np.ndarray
    fill: float
    smoothing: int
    seed: int
    draws: int                 # fields drawn until one had a way through

    def __hash__(self) -> int:
        return id(self)


def smooth(filled: np.ndarray, iterations: int) -> np.ndarray:
    """BARN's cellular automaton: ``iterations`` rounds of the fill / clear thresholds (cells
    outside the field count as free)."""
    f = filled.copy()
    for _ in range(iterations):
        p = np.pad(f, 1).astype(np.int8)
        n = sum(p[1 + dr:1 + dr + f.shape[0], 1 + dc:1 + dc + f.shape[1]]
                for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc)
        f = np.where(n >= FILL_THRESHOLD, True, np.where(n <= CLEAR_THRESHOLD, False, f))
    return f


def cell_boxes(filled: np.ndarray) -> np.ndarray:
    """``[K, 4]`` x0, y0, x1, y1 (in) of every filled cell in the world frame."""
    rows, cols = np.nonzero(filled)
    x0 = FIELD_AHEAD + cols * CELL
    y0 = -FIELD / 2 + rows * CELL
    return np.stack([x0, y0, x0 + CELL, y0 + CELL], axis=1)


RASTER = 4                     # raster points per cell side for the way-through test


def blocked_raster(filled: np.ndarray, clearance: float) -> np.ndarray:
    """Points of a raster over the field (``RASTER`` per cell side, at their centres) that lie
    closer than ``clearance`` to a pole or a side wall: the pole raster dilated by a disc (to
    within half a raster step, 0.74 in)."""
    k = RASTER
    step = CELL / k
    poles = np.kron(filled, np.ones((k, k), dtype=bool))
    reach = int(np.ceil(clearance / step)) + 1
    size = CELLS * k
    padded = np.zeros((size + 2 * reach, size + 2 * reach), dtype=bool)
    padded[reach:reach + size, reach:reach + size] = poles
    out = np.zeros((size, size), dtype=bool)
    for dr in range(-reach, reach + 1):
        for dc in range(-reach, reach + 1):
            # the nearest point of the raster square (dr, dc) steps away, in steps
            gap = np.hypot(max(abs(dr) - 0.5, 0.0), max(abs(dc) - 0.5, 0.0)) * step
            if gap < clearance:
                out |= padded[reach + dr:reach + dr + size, reach + dc:reach + dc + size]
    y = (np.arange(size) + 0.5) * step - FIELD / 2
    out[np.abs(y) > FIELD / 2 - clearance, :] = True
    return out


def way_through(filled: np.ndarray, clearance: float) -> bool:
    """Whether a disc of radius ``clearance`` can cross the field from its first column to its
    last between the side walls (8-connected over the raster); the open corridor before and
    after the field joins the start and the goal to any such crossing."""
    free = ~blocked_raster(filled, clearance)
    reached = np.zeros_like(free)
    reached[:, 0] = free[:, 0]
    while True:
        grown = reached.copy()
        grown[1:] |= reached[:-1]
        grown[:-1] |= reached[1:]
        grown[:, 1:] |= reached[:, :-1]
        grown[:, :-1] |= reached[:, 1:]
        grown[1:, 1:] |= reached[:-1, :-1]
        grown[:-1, :-1] |= reached[1:, 1:]
        grown[1:, :-1] |= reached[:-1, 1:]
        grown[:-1, 1:] |= reached[1:, :-1]
        grown &= free
        if grown[:, -1].any():
            return True
        if (grown == reached).all():
            return False
        reached = grown


def routable(filled: np.ndarray, robot: Robot = JACKAL) -> bool:
    """Whether the route planner finds a way from the start to the goal through the field
    drawn as a map, keeping at least the least clearance it accepts for ``robot``."""
    g = grid(filled)
    rows, cols = g.occupied.shape
    bounds = (g.origin[0], g.origin[1], g.origin[0] + cols * g.resolution,
              g.origin[1] + rows * g.resolution)
    static = StaticMap(np.zeros((0, 4)), np.zeros((0, 4, 2)), g, bounds)
    asked, least = clearances(robot)
    try:
        grid_route(static, Pose(0.0, 0.0), Goal(GOAL_AHEAD, 0.0), asked, minimum=least,
                   explain=False)
    except NarrowPassage:
        return False
    return True


def field(seed: int, fill: float = 0.25, smoothing: int = 3, robot: Robot = JACKAL) -> Field:
    """A field with a way through for ``robot`` (see the module docstring): drawn from
    ``SeedSequence(seed)`` until one has it. The raster test of a disc of the least clearance
    (:func:`way_through`) is the quick, exact geometric filter; the route planner's own
    search (:func:`routable`) has the last word, so the two cannot disagree."""
    if not 0.0 <= fill < 1.0:
        raise ValueError(f"fill must lie in [0, 1), not {fill}")
    if smoothing < 0:
        raise ValueError(f"smoothing must be at least 0, not {smoothing}")
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    clearance = clearances(robot)[1]
    for draw in range(1, MAX_DRAWS + 1):
        f = smooth(rng.random((CELLS, CELLS)) < fill, smoothing)
        if way_through(f, clearance) and routable(f, robot):
            return Field(f, fill, smoothing, seed, draw)
    raise ValueError(f"no field with a way through in {MAX_DRAWS} draws "
                     f"(fill {fill}, smoothing {smoothing}): lower the fill")


def _row_runs(filled: np.ndarray) -> list[tuple[int, int, int]]:
    """Runs of filled cells along each row: (row, first column, last column + 1)."""
    out: list[tuple[int, int, int]] = []
    for r in range(filled.shape[0]):
        padded = np.concatenate([[0], filled[r].astype(np.int8), [0]])
        step = np.diff(padded)
        out.extend((r, int(a), int(b)) for a, b in zip(np.flatnonzero(step == 1),
                                                         np.flatnonzero(step == -1)))
    return out


def obstacles(filled: np.ndarray) -> tuple[Obstacle, ...]:
    """Every run of filled cells along a row as one rectangle (the union of its cells)."""
    out = []
    for r, a, b in _row_runs(filled):
        x = FIELD_AHEAD + (a + b) / 2 * CELL
        y = -FIELD / 2 + (r + 0.5) * CELL
        out.append(Obstacle(name=f"pole_r{r}_c{a}", shape="rectangle", x=round(x, 4),
                            y=round(y, 4), length=round((b - a) * CELL, 4),
                            width=round(CELL, 4)))
    return tuple(out)


MAP_FINE = 4                   # map cells per field cell side (0.0375 m, 1.48 in)


def grid(filled: np.ndarray) -> Grid:
    """The walls and the poles as an occupancy grid (row 0 at the bottom) of cells a quarter
    of a pole's side: the same squares, on cells fine enough for the route to find a way the
    robot fits with an inch to spare (:func:`routable`)."""
    before = int(np.ceil((BEHIND + FIELD_AHEAD) / CELL))     # columns before the field
    total = before + int(np.ceil((GOAL_AHEAD + BEYOND - FIELD_AHEAD) / CELL))
    occ = np.zeros((CELLS + 2, total), dtype=bool)
    occ[0, :] = occ[-1, :] = True                      # the side walls
    occ[1:-1, before:before + CELLS] = filled
    origin = (FIELD_AHEAD - before * CELL, -FIELD / 2 - CELL)
    fine = np.kron(occ, np.ones((MAP_FINE, MAP_FINE), dtype=bool))
    return Grid(fine, CELL / MAP_FINE, (round(origin[0], 6), round(origin[1], 6)),
                source="barn")


def barn_world(seed: int, fill: float = 0.25, smoothing: int = 3, *, known: bool = False,
               robot: Robot = JACKAL, sensors: Sensors = LIDAR) -> World:
    """The BARN-style world of ``seed`` with the given difficulty (see the module docstring)."""
    f = field(seed, fill, smoothing, robot)
    return world_of(f, known=known, robot=robot, sensors=sensors)


def world_of(f: Field, *, known: bool = False, robot: Robot = JACKAL,
             sensors: Sensors = LIDAR) -> World:
    """The world around a generated field."""
    name = f"barn-{f.seed}-f{round(f.fill * 100):d}-s{f.smoothing}" + ("-known" if known else "")
    agent = Agent("robot", robot, Pose(0.0, 0.0, 0.0),
                  Goal(round(GOAL_AHEAD, 4), 0.0, round(GOAL_TOLERANCE, 4)))
    corridor = Corridor(((round(-BEHIND, 4), 0.0), (round(GOAL_AHEAD + BEYOND, 4), 0.0)),
                        round(FIELD, 4))
    return World(name=name, path=name + ".yaml", seed=f.seed, dt=0.05, time_limit=TIME_LIMIT,
                 substeps=4, agents=(agent,), sensors=sensors,
                 corridors=() if known else (corridor,),
                 grid=grid(f.filled) if known else None,
                 obstacles=() if known else obstacles(f.filled), randomise=Randomise())


def difficulty(seed: int) -> tuple[float, int]:
    """The (fill, smoothing) of the ``seed``-th world of :func:`barn_worlds`: BARN's grid of
    difficulties, one drawn per world from the seed."""
    rng = np.random.default_rng(np.random.SeedSequence([seed, 1]))
    return float(FILLS[rng.integers(len(FILLS))]), int(SMOOTHINGS[rng.integers(len(SMOOTHINGS))])


def barn_worlds(n: int, seed: int = 0, *, known: bool = False) -> list[World]:
    """``n`` BARN-style worlds for seeds ``seed .. seed + n - 1``, each with its own difficulty
    (:func:`difficulty`)."""
    return [barn_world(s, *difficulty(s), known=known) for s in range(seed, seed + n)]


def world_yaml(w: World, map_file: str | None = None) -> str:
    """A world file for ``w`` (``map_file``: the map_server YAML of a known world's grid)."""
    a = w.agents[0]
    r, s = a.robot, w.sensors
    lines = [f"# A BARN-style world (mitos_cli.sim.barn): {w.name}",
             f"name: {w.name}", f"seed: {w.seed}", f"dt: {w.dt:.10g}",
             f"time_limit: {w.time_limit:.10g}", f"substeps: {w.substeps}", "",
             "robot:", f"  model: {r.model}", f"  wheelbase: {r.wheelbase:.10g}",
             f"  footprint: {{length: {r.length:.10g}, width: {r.width:.10g}}}",
             f"  safety_margin: {r.safety_margin:.10g}",
             f"  steering: {{min: {r.steering_min:.10g}, max: {r.steering_max:.10g}, "
             f"straight: {r.steering_straight:.10g}, max_rate: {r.max_steering_rate:.10g}}}",
             f"  max_speed: {r.max_speed:.10g}", f"  acceleration: {r.acceleration:.10g}", "",
             f"sensors: {{layout: {s.layout}, count: {s.count}, fov: {s.fov:.10g}, "
             f"cone: {s.cone:.10g}, range: {s.range:.10g}, noise: {s.noise:.10g}}}", "",
             f"q_init: {{x: {a.start.x:.10g}, y: {a.start.y:.10g}, heading: {a.start.heading:.10g}}}",
             f"q_goal: {{x: {a.goal.x:.10g}, y: {a.goal.y:.10g}, tolerance: {a.goal.tolerance:.10g}}}",
             "", "map:"]
    if w.grid is not None:
        if map_file is None:
            raise ValueError("a known world needs the name of its map file")
        lines.append(f"  grid: {map_file}")
    for c in w.corridors:
        pts = ", ".join(f"[{x:.10g}, {y:.10g}]" for x, y in c.points)
        lines += ["  corridors:", f"    - points: [{pts}]", f"      width: {c.width:.10g}"]
    if w.obstacles:
        lines += ["", "obstacles:"]
        lines += [f"  - {{name: {o.name}, shape: rectangle, at: [{o.x:.10g}, {o.y:.10g}], "
                  f"length: {o.length:.10g}, width: {o.width:.10g}}}" for o in w.obstacles]
    return "\n".join(lines) + "\n"


def companions(out: Path, known: bool) -> list[Path]:
    """The files written beside the world file ``out``: a known world's map (PGM and its
    map_server YAML)."""
    out = Path(out)
    return [out.with_suffix(".pgm"), out.with_name(out.stem + ".map.yaml")] if known else []


def write_world(w: World, out: Path) -> list[Path]:
    """Write ``w`` to ``out`` (and a known world's map beside it), each file whole or not at
    all (:func:`~mitos_cli.fileio.atomic_write_set`); the files written."""
    from ..fileio import atomic_write, atomic_write_set

    out = Path(out)
    if w.grid is None:
        atomic_write(out, world_yaml(w))
        return [out]
    g = w.grid
    pgm, map_yaml = companions(out, True)
    img = np.where(g.occupied[::-1], 0, 254).astype(np.uint8)
    map_text = (f"image: {pgm.name}\nresolution: {g.resolution / M:.12g}\n"
                f"origin: [{g.origin[0] / M:.12g}, {g.origin[1] / M:.12g}, 0.0]\n"
                "negate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    atomic_write_set([(pgm, f"P5\n{img.shape[1]} {img.shape[0]}\n255\n".encode() + img.tobytes()),
                      (map_yaml, map_text), (out, world_yaml(w, map_yaml.name))], out)
    return [out, pgm, map_yaml]


#: the most smoothing iterations the command takes (BARN uses 2-4; the automaton has long
#: settled by then, and a huge number would only keep the command busy)
MAX_SMOOTHING = 100


def _whole(text: str, low: int, high: int | None, what: str) -> int:
    """``text`` as a whole number in ``[low, high]``, or argparse's usage error saying
    ``what`` it is."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a whole number is expected, not `{text}`") from None
    if value < low or (high is not None and value > high):
        raise argparse.ArgumentTypeError(f"{what}, not {value}")
    return value


def _seed(text: str) -> int:
    return _whole(text, 0, None, "the seed is a whole number of 0 or more")


def _fill(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a number is expected, not `{text}`") from None
    if not 0.0 <= value < 1.0:      # NaN too
        hint = (f" (a percentage? --fill {value / 100:g} is {value:g}%)"
                if 1.0 <= value < 100.0 else "")
        raise argparse.ArgumentTypeError(
            f"the fill is the fraction of cells filled, in [0, 1), not {text}{hint}")
    return value


def _smoothing(text: str) -> int:
    return _whole(text, 0, MAX_SMOOTHING, "the smoothing iterations are a whole number from 0 "
                                          f"to {MAX_SMOOTHING}")


def _out(text: str) -> Path:
    path = Path(text)
    try:
        if path.is_dir():           # said as every writer says it, with exit 1, when checked
            return path
    except OSError:                 # a name too long to look up: the same
        return path
    if path.suffix.lower() not in (".yaml", ".yml"):
        has = f"extension {path.suffix}" if path.suffix else "no extension"
        raise argparse.ArgumentTypeError(f"`{text}` has {has}; the world is written to a "
                                         f".yaml file")
    return path


class _Parser(argparse.ArgumentParser):
    """argparse, with "did you mean" for a misspelt option, as `mitos` says it: `--sed 7`
    was "the following arguments are required: --out" (or "unrecognized arguments: --sed 7")
    and no more. An unknown option is looked for first, so that it is not hidden behind a
    required one it was meant to be."""

    def parse_args(self, args: Sequence[str] | None = None,  # type: ignore[override]
                   namespace: None = None) -> argparse.Namespace:
        import sys

        from ..errors import did_you_mean

        words = list(sys.argv[1:] if args is None else args)
        known = [o for a in self._actions for o in a.option_strings]
        for word in words:
            name = word.split("=", 1)[0]
            if name.startswith("--") and name not in known:
                close = did_you_mean(name, known)
                self.error(f"unknown option {name}" + (f"; {close}" if close else ""))
        return super().parse_args(words, namespace)


def _parser() -> argparse.ArgumentParser:
    ap = _Parser(prog="python -m mitos_cli.sim.barn", description="Write a BARN-style world file.",
                 allow_abbrev=False)
    ap.add_argument("--seed", type=_seed, default=0,
                    help="whole number >= 0 that draws the field, and the difficulty when "
                         "--fill or --smoothing is not given (default: 0)")
    ap.add_argument("--fill", type=_fill,
                    help="fraction of cells filled before smoothing, in [0, 1), e.g. 0.25 "
                         "(default: drawn from the seed, 0.15-0.30)")
    ap.add_argument("--smoothing", type=_smoothing,
                    help=f"cellular-automaton smoothing iterations, 0-{MAX_SMOOTHING} "
                         "(default: drawn from the seed, 2-4)")
    ap.add_argument("--known", action="store_true",
                    help="draw the poles in the robot's map (also writes OUT.pgm and "
                         "OUT.map.yaml beside the world file)")
    ap.add_argument("--out", type=_out, required=True, metavar="OUT.yaml",
                    help="world file to write")
    return ap


def _check_out(out: Path, known: bool) -> None:
    """Refuse, before a field is drawn, a world file that cannot be written, and a known
    world's map that would replace a file the user did not name (one the world file at
    ``out`` does not read)."""
    from ..errors import MitosError
    from ..fileio import check_writable

    check_writable(out)
    try:
        own = out.read_text(encoding="utf-8") if out.is_file() else ""
    except (OSError, UnicodeDecodeError):
        own = ""
    pgm, map_yaml = companions(out, True)
    for path in companions(out, known):
        if (path.exists() or path.is_symlink()) and f"grid: {map_yaml.name}\n" not in own:
            raise MitosError(f"`{path}` is already there, and a known world's map is written "
                             f"there beside `{out}`",
                             hint="remove it, or choose another --out")


def main(argv: list[str] | None = None) -> int:
    """``python -m mitos_cli.sim.barn``: errors as ``mitos`` gives them (``error:`` and a hint;
    exit 2 for a bad option, 1 for a file that cannot be written or a field that cannot be
    drawn), never a traceback."""
    from ..errors import MitosError

    ap = _parser()
    args = ap.parse_args(argv)
    fill, smoothing = difficulty(args.seed)
    fill = fill if args.fill is None else args.fill
    smoothing = smoothing if args.smoothing is None else args.smoothing
    try:
        _check_out(args.out, args.known)
        try:
            w = barn_world(args.seed, fill, smoothing, known=args.known)
        except ValueError as exc:
            raise MitosError(str(exc)) from None
        written = write_world(w, args.out)
    except MitosError as exc:
        print(exc.render(), file=sys.stderr)
        return 1
    for p in written:
        print(p)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
