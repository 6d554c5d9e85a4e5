"""MRPB 1.0's scenarios as worlds: a folder's ``map.yaml`` and the start/goal tests of its
``tests.txt`` (Wen et al. 2021; the maps and tests are described in ``../shared/maps/SOURCES.md``
of the source tree).

``tests.txt`` holds lines ``test N: start (x, y, yaw) -> goal (x, y, yaw)`` in metres and
radians in the map frame (``#`` starts a comment). Each test becomes a world with a robot of
MRPB's size (:data:`PIONEER`), the packaged ring of sonars, the goal within 12 in, and a time
limit of ``TIME_PER_M`` seconds per metre of the route the robot plans on the map it is given
(at least ``MIN_TIME_S``). MRPB sets no limit of its own. The limit is measured along the route,
as BARN's ``t_opt`` is along the shortest path: along the straight line from start to goal
(as it was measured before), ``track``'s 14.7 m asked a robot to drive its 72.9 m loop in 88 s,
0.83 m/s on average, where the other tests ask 0.17 m/s; a world the route planner refuses
keeps the straight line's limit (it is never driven).

MRPB's robot is a Pioneer 3-DX (the benchmark's ``p3dx`` description: a top plate of 0.445 x
0.38 m; its costmaps plan it as a disc of 0.25 m radius). Its tests are laid out for that size:
``track``'s only way passes a 0.56 m (22 in) gap that the packaged 24 x 18 in tricycle cannot
take with its safety margin. :data:`PIONEER` keeps the tricycle's kinematics and limits (the
simulator drives tricycles) on the Pioneer's footprint.

A *partially unknown* scenario (``NAME_partially_unknown``) drives in the complete building
(``NAME``'s map) while the robot is given the folder's own map, which lacks the furniture; that
is a world given one map and driving in another (``World.knows = "given"``, as ``map.given``
says in a world file). Where the furniture stood, the given map is *unknown* (grey, between
the thresholds), and every test's goal lies in it: the given map is read with unknown cells
free, as MRPB's ``move_base`` reads it (the static layer keeps them as no information and the
global planner's ``allow_unknown`` plans through them), while the true building keeps its
unknown cells occupied.

Loading is the cost of reading the PGMs (600 x 600 to 760 x 760 pixels) and planning each
test's route for its limit (2.3 s for all 25 tests); :func:`scenario_worlds` reads each map
once for all of its tests.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path
from typing import Any

from ..errors import MitosError, Span, WorldError
from ..fileio import bad_byte, read_text, text_encoding_hint, unreadable
from .gridmap import INCH_PER_M, load_map_yaml
from .loop import prepare
from .world import Agent, Goal, Pose, Randomise, Robot, Sensors, World
from .worldfile import LARGEST

COMPLETE = ("maze", "narrow_graph", "office01add", "office02", "room02", "shopping_mall",
            "track")
PARTIALLY_UNKNOWN = {"office02_partially_unknown": "office02",
                     "shopping_mall_partially_unknown": "shopping_mall"}
TIME_PER_M = 6.0           # s per metre of the planned route (6.6 in/s along it)
MIN_TIME_S = 60.0
#: MRPB's Pioneer 3-DX footprint (0.445 x 0.38 m) on the tricycle; the wheelbase scaled from
#: the packaged tricycle's 16 in on 24 in of length
PIONEER = Robot(wheelbase=12.0, length=17.5, width=15.0)
_POSE = r"\(\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)\s*\)"
_TEST = re.compile(r"^\s*test\s+(\d+)\s*:\s*start\s*" + _POSE + r"\s*->\s*goal\s*" + _POSE
                   + r"\s*$")


def read_tests(path: Path) -> list[tuple[int, Pose, Pose]]:
    """The tests of a ``tests.txt``: (number, start, goal) with poses in inches and degrees.
    A byte-order mark (a Windows editor's) is read past, as a world file's is."""
    try:
        text = read_text(path)
    except (OSError, UnicodeDecodeError) as exc:
        raise WorldError(unreadable("MRPB tests", path, exc), span=bad_byte(path, exc),
                         hint=text_encoding_hint(exc)) from None
    out = []
    for i, line in enumerate(text.splitlines(), 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        m = _TEST.match(line)
        if not m:
            raise WorldError("not an MRPB start/goal test", span=Span(str(path), i, 1, line),
                             expected="`test N: start (x, y, yaw) -> goal (x, y, yaw)` in "
                                      "metres and radians")
        v = [_number(m, k, Span(str(path), i, 1, line)) for k in range(2, 8)]
        out.append((int(m.group(1)),
                    Pose(v[0] * INCH_PER_M, v[1] * INCH_PER_M, math.degrees(v[2])),
                    Pose(v[3] * INCH_PER_M, v[4] * INCH_PER_M, math.degrees(v[5]))))
    if not out:
        raise WorldError(f"`{path}` holds no MRPB start/goal test", span=Span(str(path), 1, 1))
    return out


def _number(m: re.Match, group: int, span: Span) -> float:
    """Group ``group`` of a test line (x, y, yaw; x, y, yaw from group 2) as a finite number
    within a world's reach once in inches and degrees, refused at its column: `8.6.71` (the
    pattern takes digits and dots) was a ValueError's traceback, and `1e999` a start at
    infinity."""
    written, at = m.group(group), replace(span, column=m.start(group) + 1)
    try:
        value = float(written)
    except ValueError:
        raise WorldError(f"`{written}` in an MRPB test is not a number", span=at,
                         expected="a number (metres, or radians for a yaw)") from None
    if not math.isfinite(value):
        raise WorldError(f"`{written}` in an MRPB test is not a finite number", span=at)
    yaw = group in (4, 7)
    if abs(math.degrees(value) if yaw else value * INCH_PER_M) > LARGEST:
        reach = f"{math.radians(LARGEST):,.0f} rad" if yaw else f"{LARGEST / INCH_PER_M:,.0f} m"
        raise WorldError(f"`{written}` in an MRPB test lies beyond ±{reach}, where a world's "
                         "numbers lie", span=at, expected="metres and radians in the map frame")
    return value


def scenario_worlds(root: Path, name: str, robot: Robot | None = None,
                    sensors: Sensors | None = None) -> list[World]:
    """One world per start/goal test of the scenario ``name`` under ``root`` (MRPB's folder
    layout: ``root/NAME/map.yaml`` and ``root/NAME/tests.txt``)."""
    folder = Path(root) / name
    robot = robot or PIONEER
    sensors = sensors or Sensors(noise=0.5)
    truth = PARTIALLY_UNKNOWN.get(name)
    grid = load_map_yaml(folder.parent / (truth or name) / "map.yaml")
    extra: dict[str, Any] = {}
    if truth:
        extra = {"knows": "given", "given": load_map_yaml(folder / "map.yaml", unknown_occupied=False)}
    worlds = []
    for number, start, goal in read_tests(folder / "tests.txt"):
        crow = math.hypot(goal.x - start.x, goal.y - start.y)
        world = World(
            name=f"mrpb/{name}#{number}", path=str(folder / "map.yaml"), seed=number, dt=0.05,
            time_limit=time_limit(crow), substeps=4,
            agents=(Agent("robot", robot, start, Goal(goal.x, goal.y, 12.0)),),
            sensors=sensors, corridors=(), grid=grid, obstacles=(), randomise=Randomise(),
            **extra)
        worlds.append(_limited_by_route(world))
    return worlds


def time_limit(length_in: float) -> float:
    """The time limit (s) of a test whose way is ``length_in`` inches long."""
    return max(MIN_TIME_S, TIME_PER_M * length_in / INCH_PER_M)


def _limited_by_route(world: World) -> World:
    """``world`` with its time limit measured along the route its robot plans."""
    try:
        length = float(prepare(world).routes[0].length)
    except MitosError:
        return world                       # refused: the straight line's limit stays
    return world.with_changes(time_limit=time_limit(length))
