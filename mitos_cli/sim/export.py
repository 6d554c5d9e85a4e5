"""A finished run as a CSV (one row per tick and robot) and as paper-style DOF traces.

Fired rules are not stored while stepping: the planner's inputs are, and the engine is exact
row by row, so evaluating all recorded inputs again in one detailed batch gives the very DOFs
the planner used (:meth:`FuzzyPlanner.explain`).
"""

from __future__ import annotations

import csv
import io
from typing import TYPE_CHECKING, cast

import numpy as np

from ..errors import InputError
from ..numbers import whole_number
from ..words import plural
from .loop import SimResult
from .perception import INPUTS

if TYPE_CHECKING:
    from typing import TextIO

    from ..engine.evaluation import Result
    from .planner import Planner


def explain(result: SimResult, planner: Planner, robot: int = 0) -> Result | None:
    """The detailed engine result for every tick of ``robot`` (rows = ticks), or None when the
    planner is not a rule base."""
    if not hasattr(planner, "explain"):
        return None
    robots = len(result.robot_outcomes)
    if (i := whole_number(robot)) is None or not 0 <= i < robots:   # (3 met an IndexError)
        raise InputError(f"robot is the index of one of the run's {plural(robots, 'robot')}, "
                         f"0 to {robots - 1}, not `{robot!r:.40}`")
    return planner.explain({k: v[:, i] for k, v in result.perceived.items()})


def fired_text(detail: Result, row: int, digits: int = 2) -> str:
    c = detail.compiled
    dof = cast(np.ndarray, detail.dof)[row]             # (a planner's explain keeps the DOFs)
    order = np.argsort(-dof, kind="stable")
    return " ".join(f"{c.labels[r]}={dof[r]:.{digits}f}" for r in order if dof[r] > 0)


POSE_COLUMNS = ("tick", "t", "robot", "x", "y", "pose_heading_deg", "speed", "steering",
                "cmd_steering", "cmd_speed", "clearance")
"""The columns before the ranges: tick (count), t (s), robot (its name), x, y (in),
pose_heading_deg (the robot's heading, deg CCW from +x), speed (in/s), steering (deg, 90
straight), cmd_steering (deg), cmd_speed (in/s), clearance (in). ``pose_heading_deg`` is not
the rule input ``heading`` (the route's bearing relative to the robot, positive right). The
``cmd_`` columns are the command after the robot's own brake and backing out (``safety.py``),
held to its steering lock and top speeds (:class:`.loop.Tick`), not the planner's raw request
(``mitos eval --batch`` on the rows gives that)."""


def columns(beams: int) -> list[str]:
    """Every column of :func:`write_csv`, in order, for a robot with ``beams`` range sensors;
    each name is unique, and the rule inputs keep their rule-base names (worlds/README.md has
    the table with units)."""
    return (list(POSE_COLUMNS) + [f"range_{b}" for b in range(beams)] + list(INPUTS)
            + [f"true_{k}" for k in INPUTS] + ["fired"])


def _num(v: float) -> str:
    """A CSV number: 6 significant digits, and to the hundredth from 10,000 on. At 6 digits a
    robot 2.5 km from the origin (a map's origin far from its corner) was written to the
    inch: its moves of 1-2 in a tick were lost, and the path recomputed from the file came
    out 5% long."""
    return f"{v:.6g}" if abs(v) < 1e4 else f"{v:.2f}"


def write_csv(result: SimResult, planner: Planner, out: TextIO) -> None:
    """One row per tick and active robot, columns :func:`columns` (``fired``: ``label=DOF``
    by DOF), and the last tick's row of a robot something drove into where it stood parked
    at its goal (its collision; ``fired`` empty: it planned nothing)."""
    n = result.pose.shape[1]
    B = result.ranges.shape[2]
    details = [explain(result, planner, i) for i in range(n)]
    w = csv.writer(out, lineterminator="\n")
    w.writerow(columns(B))
    names = [a.name for a in result.world.agents]
    for k in range(result.ticks):
        for i in range(n):
            driving = result.active is None or bool(result.active[k, i])
            if not driving and not (k == result.ticks - 1
                                    and result.robot_outcomes[i] == "collision"):
                continue
            row = [k, _num(result.t[k]), names[i],
                   *map(_num, result.pose[k, i]),
                   _num(result.speed[k, i]), _num(result.steering[k, i]),
                   *map(_num, result.command[k, i]),
                   _num(result.clearance[k, i]),
                   *map(_num, result.ranges[k, i]),
                   *(_num(result.perceived[key][k, i]) for key in INPUTS),
                   *(_num(result.true[key][k, i]) for key in INPUTS),
                   fired_text(cast("Result", details[i]), k) if details[i] is not None and driving else ""]
            w.writerow(row)


def csv_text(result: SimResult, planner: Planner) -> str:
    buf = io.StringIO()
    write_csv(result, planner, buf)
    return buf.getvalue()


def traces(result: SimResult, planner: Planner, every: int, digits: int = 1) -> str:
    """The first robot every ``every`` ticks (and at the last tick, and at each tick it
    replanned): the time, the pose and the perceived vs true inputs, then the DOF trace. A
    planner that is not a rule base has no DOF trace: its ticks come without, under a line
    that says so."""
    from ..engine.trace import trace_of

    detail = explain(result, planner, 0)
    replans = {k: route for k, i, route in getattr(result, "replanned", ()) if i == 0}
    ticks = sorted(set(range(0, result.ticks, max(1, every))) | {result.ticks - 1}
                   | set(replans))
    blocks = [] if detail is not None else [
        f"(planner {result.planner} is not a rule base: no DOF trace, only each tick's pose "
        f"and inputs)"]
    who = result.world.agents[0].name            # the first robot's trace ("robot" alone)
    agents = result.world.agents
    if len(agents) > 1:                           # (it said nothing of the others)
        blocks.insert(0, f"(the trace follows `{who}`, the first of the world's "
                         f"{len(agents)} robots; {_names([a.name for a in agents[1:]])} "
                         f"{'is' if len(agents) == 2 else 'are'} in the --out CSV, a row per "
                         f"tick and robot)")
    for k in ticks:
        if k < 0 or result.active is not None and not result.active[k, 0]:
            continue
        lines = [_tick_head(result, k, who), *_inputs_lines(result, k)]
        if k in replans:
            lines.append(f"  replanned: what it sensed lies in the way ahead; the new route "
                         f"runs {replans[k].length:.0f} in to the goal")
        if detail is not None:
            lines += ["", trace_of(detail, k).render(digits)]
        blocks.append("\n".join(lines))
    if len(blocks) == (detail is None) + (len(agents) > 1):    # not a tick of its own
        blocks.append(f"({who} drove no tick: it stood at its goal from the start)")
    return "\n\n".join(blocks)


def _names(names: list[str]) -> str:
    """``a``, ``a and b``, ``a, b and c``, each in backquotes."""
    quoted = [f"`{n}`" for n in names]
    return quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + " and " + quoted[-1]


def _tick_head(result: SimResult, k: int, who: str) -> str:
    """A traced tick's first line: the first robot's time, place, speed, wheel and room."""
    x, y, h = result.pose[k, 0]
    return (f"--- tick {k}, t = {result.t[k]:.2f} s: {who} at ({x:.1f}, {y:.1f}) in, pose "
            f"heading {h:.1f} deg, speed {result.speed[k, 0]:.1f} in/s, steering "
            f"{result.steering[k, 0]:.1f} deg, clearance {result.clearance[k, 0]:.1f} in")


def _inputs_lines(result: SimResult, k: int) -> list[str]:
    """The inputs the first robot perceived at tick ``k`` and those of the true geometry."""
    return ["  perceived: " + ", ".join(f"{key} {result.perceived[key][k, 0]:.1f}"
                                        for key in INPUTS),
            "  true:      " + ", ".join(f"{key} {result.true[key][k, 0]:.1f}" for key in INPUTS)]
