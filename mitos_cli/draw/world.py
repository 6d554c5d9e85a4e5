"""A simulated run as a picture, like the paper's Figures 4 and 10: the walls, the obstacles
(moving ones with their tracks), the route, the path coloured by speed and the robot's footprint
at intervals. Draws a finished :class:`~mitos_cli.sim.loop.SimResult`; never steps."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .output import _matplotlib, finish, new_figure

PAD = 20.0      # in round the map


def map_axes(static, *, show: bool = False, extra_width: float = 1.6):
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
        g = static.grid
        rows, cols = g.occupied.shape
        ax.imshow(np.where(g.occupied, 0.55, 1.0), origin="lower", cmap="gray", vmin=0, vmax=1,
                  extent=(g.origin[0], g.origin[0] + cols * g.resolution, g.origin[1],
                          g.origin[1] + rows * g.resolution), interpolation="nearest")
    for corners in static.rects:
        ax.add_patch(Polygon(corners, closed=True, facecolor="white", edgecolor="none"))
    ax.add_collection(LineCollection(static.walls.reshape(-1, 2, 2), colors="black",
                                     linewidths=1.2))
    ax.set_xlim(xmin - PAD, xmax + PAD)
    ax.set_ylim(ymin - PAD, ymax + PAD)
    ax.set_xlabel("x (in)")
    ax.set_ylabel("y (in)")
    return fig, ax


def draw_run(result, path: str | Path | None = None, *, footprint_every: float = 1.0,
             show: bool = False):
    """Draw ``result``; save to ``path`` (.png or .svg) and/or ``show``. Footprints every
    ``footprint_every`` seconds. Returns the figure."""
    _matplotlib()                      # a clear error, not a traceback, without matplotlib
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle, Polygon

    from ..sim.geometry import rect_corners

    world, static = result.world, result.static
    xmin, ymin, xmax, ymax = static.bounds
    pad = PAD
    fig, ax = map_axes(static, show=show)
    for route in result.routes:
        ax.plot(route.points[:, 0], route.points[:, 1], ls="--", lw=0.8, color="#4a78b5",
                label="route" if route is result.routes[0] else None)
    for n, (_, _, route) in enumerate(getattr(result, "replanned", ())):
        ax.plot(route.points[:, 0], route.points[:, 1], ls="-.", lw=0.8, color="#7a4ab5",
                label="replanned route" if n == 0 else None)

    # obstacles: where they started (faint, for moving ones), their tracks, where they ended
    track = result.obstacles                                  # [T, O, 2]
    named = _labelled(result)
    for j, o in enumerate(world.obstacles):
        xy = track[:, j] if len(track) else np.array([[o.x, o.y]])
        moving = np.ptp(xy, axis=0).max() > 1e-9 if len(xy) else False
        if moving:
            ax.plot(xy[:, 0], xy[:, 1], color="#b5524a", lw=0.8, ls=":")
        for k, alpha in ((0, 0.25), (len(xy) - 1, 0.9)) if moving else ((len(xy) - 1, 0.9),):
            cx, cy = xy[k]
            patch: Circle | Polygon
            if o.shape == "circle":
                patch = Circle((cx, cy), o.radius)
            else:
                patch = Polygon(rect_corners(cx, cy, np.deg2rad(o.angle), o.length, o.width))
            patch.set(facecolor="#b5524a", edgecolor="#5c1f1a", alpha=alpha, lw=0.8)
            ax.add_patch(patch)
        if j in named:
            ax.annotate(o.name, xy[-1], xytext=(6, 6), textcoords="offset points",
                        fontsize=8, color="#5c1f1a")

    # robots: footprints at intervals, path coloured by speed, start and goal
    vmax = max(1.0, float(np.nanmax(result.speed)) if result.speed.size else 1.0)
    step = max(1, int(round(footprint_every / world.dt)))
    line = None
    for i, agent in enumerate(world.agents):
        alive = result.active[:, i] if result.active is not None else slice(None)
        pose = result.pose[alive, i]
        speed = result.speed[alive, i]
        if len(pose) == 0:
            continue
        for k in list(range(0, len(pose), step)) + [len(pose) - 1]:
            x, y, h = pose[k]
            ax.add_patch(Polygon(rect_corners(x, y, np.deg2rad(h), agent.robot.length,
                                              agent.robot.width),
                                 closed=True, fill=False, edgecolor="#555555", lw=0.5))
        if len(pose) > 1:
            segs = np.stack([pose[:-1, :2], pose[1:, :2]], axis=1)
            line = LineCollection(list(segs), cmap="viridis", linewidths=2.2)
            line.set_array(speed[:-1])
            line.set_clim(0, vmax)
            ax.add_collection(line)
        ax.plot(agent.start.x, agent.start.y, marker="o", color="#2f6b2f", ms=5)
        ax.add_patch(Circle((agent.goal.x, agent.goal.y), agent.goal.tolerance, fill=False,
                            edgecolor="#2f6b2f", lw=1.0, ls="--"))
        ax.annotate(agent.name if len(world.agents) > 1 else "goal",
                    (agent.goal.x, agent.goal.y), xytext=(6, -10), textcoords="offset points",
                    fontsize=8, color="#2f6b2f")
    if line is not None:
        fig.colorbar(line, ax=ax, shrink=0.7, label="speed (in/s)")
    ax.set_xlim(xmin - pad, xmax + pad)
    ax.set_ylim(ymin - pad, ymax + pad)
    ax.set_xlabel("x (in)")
    ax.set_ylabel("y (in)")
    m = result.metrics
    ax.set_title(f"{world.name}: {result.outcome} after {m['time_s']:.1f} s "
                 f"(seed {result.seed}, min clearance {m['min_clearance_in']:.1f} in)",
                 fontsize=9)
    return finish(fig, path, show)


LABEL_LIMIT = 12        # obstacles named on a plot; beyond this only the one hit is


def _labelled(result) -> set[int]:
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
