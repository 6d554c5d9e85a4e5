"""A simulated run as a picture, like the paper's Figures 4 and 10: the walls, the obstacles
(moving ones with their tracks), the route, the path coloured by speed and the robot's footprint
at intervals. Draws a finished :class:`~mitos_cli.sim.loop.SimResult`; never steps."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np

from ..errors import InputError
from .output import _matplotlib, finish, new_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    from ..sim.loop import SimResult
    from ..sim.staticmap import StaticMap
    from ..sim.world import Agent, Grid

PAD = 20.0      # in round the map
#: the colours of what is drawn besides the robots: the route, a replanned route, obstacles
#: (their fill, edge and time marks), the start and goal
ROUTE_COLOUR, REPLANNED_COLOUR = "#4a78b5", "#7a4ab5"
OBSTACLE_COLOURS = ("#b5524a", "#5c1f1a", "#8a2f27")
GOAL_COLOUR = "#2f6b2f"
RESERVED = (ROUTE_COLOUR, REPLANNED_COLOUR, *OBSTACLE_COLOURS, GOAL_COLOUR)
#: a colour per robot where a world has several (the first is the footprint blue of the frames):
#: none is one of ``RESERVED`` or near it (the third robot was the replanned route's purple)
ROBOT_COLOURS = ("#1f5fbf", "#d9731e", "#1f9e89", "#c23b8a", "#8c6d31", "#c9a400")
#: the paths' line styles, a round of the colours each: a seventh robot's path was the first's
ROBOT_STYLES = ("-", "--", ":", "-.")
TIME_STEPS = (1, 2, 5, 10, 15, 20, 30, 60, 120, 300, 600)     # s between time marks


def inward(ax: Axes, x: float, y: float, gap: float = 7.0, above: bool | None = None) -> dict:
    """``annotate`` arguments that put a label beside ``(x, y)`` on the side facing the middle
    of the axes, so that a label near an edge is not cut off (or pressed against it);
    ``above`` forces the vertical side."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    right = x > (x0 + x1) / 2
    above = y < (y0 + y1) / 2 if above is None else above
    return {"xytext": (-gap if right else gap, gap if above else -gap),
            "textcoords": "offset points", "ha": "right" if right else "left",
            "va": "bottom" if above else "top"}


def place_legend(ax: Axes, static: StaticMap) -> None:
    """The legend inside the map where there is room, under a long thin map (where inside it
    would cover the corridor)."""
    xmin, ymin, xmax, ymax = static.bounds
    if xmax - xmin > 2 * (ymax - ymin):
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, 0.0), borderaxespad=4.5,
                  ncol=4, fontsize=7, frameon=False)
    else:
        ax.legend(loc="best", fontsize=7, framealpha=0.85)


def time_step(t_end: float, most: int = 6) -> float:
    """The round interval (s) that puts at most ``most`` time marks on a run of ``t_end`` s."""
    return next((s for s in TIME_STEPS if t_end / s <= most), TIME_STEPS[-1])


def time_marks(ax: Axes, t: np.ndarray, xy: np.ndarray, step: float, colour: str, *,
               label: str | None = None, near: float = 0.0, above: bool | None = None) -> None:
    """Dots on a track ``xy[T, 2]`` at every ``step`` s of ``t[T]``, each with its time; a label
    is left out where it would fall within ``near`` in of an earlier one (a track that
    doubles back) or of the track's end. Obstacles' times go above their dots, robots' below (``above``)."""
    ks = [int(k) for k in np.searchsorted(t, np.arange(step, t[-1] + 1e-9, step))
          if k < len(t)] if len(t) else []
    placed: list[np.ndarray] = [xy[-1]] if len(xy) else []    # the end has its own label
    for n, k in enumerate(ks):
        ax.plot(*xy[k], marker="o", ms=3.5, mfc="white", mec=colour, mew=1.0, ls="none",
                zorder=6, label=label if n == 0 else None)
        if any(np.hypot(*(xy[k] - p)) < near for p in placed):
            continue
        placed.append(xy[k])
        ax.annotate(f"{t[k]:g} s", xy[k], fontsize=6.5, color=colour, zorder=6,
                    **inward(ax, float(xy[k, 0]), float(xy[k, 1]), gap=4.0, above=above))


def map_axes(static: StaticMap, *, show: bool = False, extra_width: float = 1.6) -> tuple[Figure, Axes]:
    """A figure sized to the map and its axes with the map drawn: solid space grey, the free
    grid cells and corridors white, the walls black. Returns ``(fig, ax)``."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Polygon

    xmin, ymin, xmax, ymax = static.bounds
    width, height = xmax - xmin + 2 * PAD, ymax - ymin + 2 * PAD
    scale = 9.0 / max(width, height)
    fig = new_figure((max(4.0, width * scale + extra_width), max(3.0, height * scale + 0.8)),
                     show=show)
    ax = fig.add_subplot(1, 1, 1)
    ax.set_aspect("equal")
    ax.set_facecolor("#d9d9d9")
    if static.grid is not None:
        draw_grid(ax, static.grid)
    for corners in static.rects:
        ax.add_patch(Polygon(corners, closed=True, facecolor="white", edgecolor="none"))
    ax.add_collection(LineCollection(static.walls.reshape(-1, 2, 2),  # type: ignore[arg-type]
                                     colors="black",
                                     linewidths=1.2))
    ax.set_xlim(xmin - PAD, xmax + PAD)
    ax.set_ylim(ymin - PAD, ymax + PAD)
    ax.set_xlabel("x (in)")
    ax.set_ylabel("y (in)")
    return fig, ax


#: the most cells a map is drawn with along a side: a picture is a few thousand pixels wide,
#: and matplotlib colour-mapped and resampled every cell of a 4,000 x 4,000 map (4 s, 700 MB)
DRAWN_CELLS = 2000


def draw_grid(ax: Axes, grid: Grid) -> None:
    """The grid's cells, occupied grey and free white. A map of more than
    :data:`DRAWN_CELLS` cells along a side is drawn in blocks of cells, a block grey where any
    of its cells is occupied (the walls are drawn as lines over it)."""
    cells: np.ndarray | np.bool_ = grid.occupied   # (NumPy types .any(axis=...) so)
    k = -(-max(cells.shape) // DRAWN_CELLS)
    if k > 1:
        rows, cols = cells.shape
        padded = np.zeros((-(-rows // k) * k, -(-cols // k) * k), dtype=bool)
        padded[:rows, :cols] = cells
        cells = padded.reshape(len(padded) // k, k, -1, k).any(axis=(1, 3))
    rows, cols = cells.shape
    size, (ox, oy) = grid.resolution * k, grid.origin
    ax.imshow(np.where(cells, 0.55, 1.0), origin="lower", cmap="gray", vmin=0, vmax=1,
              extent=(ox, ox + cols * size, oy, oy + rows * size), interpolation="nearest")


def _drove(result: SimResult, i: int) -> np.ndarray:
    """The ticks robot ``i`` drove, and the one it stopped at (arrived or collided)."""
    if result.active is None:
        return np.ones(len(result.t), dtype=bool)
    drove = result.active[:, i].copy()
    drove[1:] |= result.active[:-1, i]
    return drove


def draw_run(result: SimResult, path: str | Path | None = None, *, footprint_every: float = 1.0,
             show: bool = False) -> Figure:
    """Draw ``result``; save to ``path`` (.png or .svg) and/or ``show``. Footprints every
    ``footprint_every`` seconds. Returns the figure."""
    _matplotlib()                      # a clear error, not a traceback, without matplotlib
    world, static = result.world, cast("StaticMap", result.static)    # (a run has its map)
    xmin, ymin, xmax, ymax = static.bounds
    fig, ax = map_axes(static, show=show)
    _draw_routes(ax, result)
    t_end = float(result.t[-1]) if len(result.t) else 0.0
    marks = Marks(time_step(t_end), 0.04 * max(xmax - xmin, ymax - ymin))
    tracked = _draw_obstacles(ax, result, marks)
    # one robot: its path coloured by speed; several: a colour and a legend entry each
    vmax = max(1.0, float(np.nanmax(result.speed)) if result.speed.size else 1.0)
    every = _every(footprint_every, world.dt)
    line = None
    for i, agent in enumerate(world.agents):
        line = _draw_robot(ax, result, i, agent, every, vmax, marks, tracked) or line
    if line is not None:
        fig.colorbar(line, ax=ax, shrink=0.7, label="speed (in/s)")
    place_legend(ax, static)
    ax.set_xlim(xmin - PAD, xmax + PAD)
    ax.set_ylim(ymin - PAD, ymax + PAD)
    ax.set_xlabel("x (in)")
    ax.set_ylabel("y (in)")
    m = result.metrics
    ax.set_title(f"{world.name}: {result.outcome} after {m['time_s']:.2f} s "
                 f"(seed {result.seed}, min clearance {result.shown_clearance()} in)",
                 fontsize=9)
    return finish(fig, path, show)


def _every(seconds: object, dt: float) -> int:
    """Ticks between drawn footprints, for one every ``seconds`` (0: every tick), else an
    :class:`InputError` (NaN, infinity, 1e308 and text met ``int()``'s and ``round()``'s
    errors; -1 drew one every tick without a word)."""
    import numbers

    value = math.nan
    if isinstance(seconds, numbers.Real) and not isinstance(seconds, bool):
        try:
            value = float(seconds)
        except OverflowError:           # (10**400)
            value = math.inf
    if not (math.isfinite(value) and value >= 0):
        raise InputError(f"footprint_every is a number of seconds, 0 or more, not "
                         f"`{seconds!r:.40}`", hint="footprint_every=1.0 draws one a second")
    return max(1, int(round(min(value / dt, 1e9))))


@dataclass(frozen=True)
class Marks:
    """Time marks along the tracks: every ``step`` s, labels kept ``near`` apart."""

    step: float
    near: float


def _draw_routes(ax: Axes, result: SimResult) -> None:
    """The routes planned at the start (dashed) and each replan (dash-dotted)."""
    for route in result.routes:
        ax.plot(route.points[:, 0], route.points[:, 1], ls="--", lw=0.8, color=ROUTE_COLOUR,
                label="route" if route is result.routes[0] else None)
    for n, (_, _, route) in enumerate(getattr(result, "replanned", ())):
        ax.plot(route.points[:, 0], route.points[:, 1], ls="-.", lw=0.8, color=REPLANNED_COLOUR,
                label="replanned route" if n == 0 else None)


def _draw_obstacles(ax: Axes, result: SimResult, marks: Marks) -> list[int]:
    """Each obstacle where it ended; a moving one also where it started (faint) and its
    track with time marks. Returns the moving ones."""
    from matplotlib.patches import Circle, Polygon

    from ..sim.geometry import rect_corners

    track = result.obstacles                                  # [T, O, 2]
    named = _labelled(result)
    tracked: list[int] = []
    for j, o in enumerate(result.world.obstacles):
        xy = track[:, j] if len(track) else np.array([[o.x, o.y]])
        moving = np.ptp(xy, axis=0).max() > 1e-9 if len(xy) else False
        if moving:
            ax.plot(xy[:, 0], xy[:, 1], color=OBSTACLE_COLOURS[0], lw=0.8, ls=":",
                    label="obstacle track" if not tracked else None)
            time_marks(ax, result.t, xy, marks.step, OBSTACLE_COLOURS[2], near=marks.near,
                       above=True,
                       label="time marks (s)" if not tracked else None)
            tracked.append(j)
        for k, alpha in ((0, 0.25), (len(xy) - 1, 0.9)) if moving else ((len(xy) - 1, 0.9),):
            cx, cy = xy[k]
            patch: Circle | Polygon
            if o.shape == "circle":
                patch = Circle((cx, cy), o.radius)
            else:
                patch = Polygon(rect_corners(cx, cy, np.deg2rad(o.angle), o.length, o.width))
            patch.set(facecolor=OBSTACLE_COLOURS[0], edgecolor=OBSTACLE_COLOURS[1], alpha=alpha,
                      lw=0.8)
            ax.add_patch(patch)
        if j in named:
            ax.annotate(o.name, xy[-1], xytext=(6, 6), textcoords="offset points",
                        fontsize=8, color=OBSTACLE_COLOURS[1])
    return tracked


def _draw_robot(ax: Axes, result: SimResult, i: int, agent: Agent, every: int, vmax: float, marks: Marks,
                tracked: list[int]) -> LineCollection | None:
    """Robot ``i``: footprints every ``every`` ticks, its path (coloured by speed when it is
    alone: the line returned, for the colour bar), time marks where obstacles moved, a
    collision, its start and goal."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle, Polygon

    from ..sim.geometry import rect_corners

    several = len(result.world.agents) > 1
    drove = _drove(result, i)
    pose = result.pose[drove, i]
    speed = result.speed[drove, i]
    if len(pose) == 0:
        return None
    line = None
    colour = ROBOT_COLOURS[i % len(ROBOT_COLOURS)] if several else "#555555"
    for k in list(range(0, len(pose), every)) + [len(pose) - 1]:
        x, y, h = pose[k]
        ax.add_patch(Polygon(rect_corners(x, y, np.deg2rad(h), agent.robot.length,
                                          agent.robot.width),
                             closed=True, fill=False, edgecolor=colour, lw=0.5,
                             alpha=0.6 if several else 1.0))
    if several:
        style = ROBOT_STYLES[i // len(ROBOT_COLOURS) % len(ROBOT_STYLES)]
        ax.plot(pose[:, 0], pose[:, 1], color=colour, lw=2.0, ls=style,
                label=f"{agent.name}: {result.robot_outcomes[i]}")
    elif len(pose) > 1:
        segs = np.stack([pose[:-1, :2], pose[1:, :2]], axis=1)
        line = LineCollection(list(segs), cmap="viridis", linewidths=2.2)
        line.set_array(speed[:-1])
        line.set_clim(0, vmax)
        ax.add_collection(line)
    if tracked or several:           # where the robots were when the obstacles were there
        time_marks(ax, result.t[drove], pose[:, :2], marks.step,
                   colour if several else "#333333", near=marks.near, above=False,
                   label=None if tracked else "time marks (s)" if i == 0 else None)
    if result.robot_outcomes[i] == "collision":
        x, y = pose[-1, :2]
        ax.plot(x, y, marker="x", ms=9, mew=2.0, color="black", zorder=7, ls="none",
                label="collision" if "collision" not in result.robot_outcomes[:i] else None)
        # the run's end: a robot parked at its goal keeps its own time to its arrival; one
        # label where another robot's would meet it (two that ran into each other had two,
        # drawn over one another: the time is the run's, the same)
        label = ax.annotate(f"collision at {result.metrics['time_s']:.2f} s", (x, y),
                            fontsize=7.5, zorder=7, **inward(ax, x, y),
                            bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none",
                                  "alpha": 0.85})
        ax.apply_aspect()   # the map's equal aspect, as drawn: the boxes are measured on it
        box = label.get_window_extent().padded(2)
        if any(t is not label and t.get_text() == label.get_text()
               and t.get_window_extent().padded(2).overlaps(box) for t in ax.texts):
            label.remove()
    ax.plot(agent.start.x, agent.start.y, marker="o", color=GOAL_COLOUR, ms=5)
    ax.add_patch(Circle((agent.goal.x, agent.goal.y), agent.goal.tolerance, fill=False,
                        edgecolor=GOAL_COLOUR, lw=1.0, ls="--"))
    ax.annotate(agent.name if several else "goal",
                (agent.goal.x, agent.goal.y), xytext=(6, -10), textcoords="offset points",
                fontsize=8, color=GOAL_COLOUR)
    return line


LABEL_LIMIT = 12        # obstacles named on a plot; beyond this only the one hit is


def _labelled(result: SimResult) -> set[int]:
    """The obstacles whose names help: all of a few, else only the one a robot hit (nearest
    to where it stopped), so a generated field of a hundred poles is not written over."""
    obstacles = result.world.obstacles
    if len(obstacles) <= LABEL_LIMIT:
        return set(range(len(obstacles)))
    if result.outcome != "collision" or not len(result.obstacles) or not len(result.pose):
        return set()
    where = result.obstacles[-1]                                  # [O, 2]
    size = np.array([o.radius if o.shape == "circle" else np.hypot(o.length, o.width) / 2
                     for o in obstacles])
    out = set()
    for i, r in enumerate(result.robot_outcomes):
        if r == "collision":
            gap = np.hypot(*(where - result.pose[-1, i, :2]).T) - size
            out.add(int(np.argmin(gap)))
    return out
