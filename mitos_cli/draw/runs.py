"""Many runs of one world in one picture (``mitos simulate WORLD --runs N --plot runs.png``):
the map, the route, every run's path coloured by the run's outcome (a legend with the counts),
each collision marked with an x and its time, and where each run's obstacles started (faint:
randomised runs move them). Draws a :class:`~mitos_cli.draw.data.overlay.RunsOverlay`."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .output import _matplotlib, finish

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.text import Annotation
    from matplotlib.transforms import Bbox

    from ..sim.loop import Scene
    from ..sim.world import World
    from .data.overlay import RunsOverlay

#: a colour per outcome (success green, collision red, timeout amber, stuck purple)
COLOURS = {"success": "#2f8f3f", "collision": "#c8322a", "timeout": "#d99a1e",
           "stuck": "#7a4ab5"}


def draw_runs(overlay: RunsOverlay, world: World, scene: Scene, path: str | Path | None = None, *,
              show: bool = False) -> Figure:
    """Draw ``overlay`` (the runs of ``world``, whose map and routes are ``scene``'s); save to
    ``path`` (.png or .svg) and/or ``show``. Returns the figure."""
    _matplotlib()
    from matplotlib.patches import Circle, Polygon

    from ..sim.geometry import rect_corners
    from .world import map_axes, place_legend

    fig, ax = map_axes(scene.static, show=show, extra_width=0.4)
    for route in scene.routes:
        ax.plot(route.points[:, 0], route.points[:, 1], ls="--", lw=0.8, color="#4a78b5",
                label="route" if route is scene.routes[0] else None, zorder=2)
    for centres in overlay.obstacles:
        for o, (cx, cy) in zip(world.obstacles, centres):
            patch: Circle | Polygon
            if o.shape == "circle":
                patch = Circle((cx, cy), o.radius)
            else:
                patch = Polygon(rect_corners(cx, cy, np.deg2rad(o.angle), o.length, o.width))
            patch.set(facecolor="#b5524a", edgecolor="none",
                      alpha=max(0.06, 0.6 / len(overlay.obstacles)), zorder=1)
            ax.add_patch(patch)
    for o in world.obstacles:
        ax.annotate(o.name, (o.x, o.y), xytext=(6, 6), textcoords="offset points", fontsize=8,
                    color="#5c1f1a")
    alpha = max(0.25, min(0.9, 6.0 / max(1, len(overlay.seeds))))
    for outcome, paths in overlay.paths.items():
        colour = COLOURS.get(outcome, "#555555")
        for n, xy in enumerate(paths):
            ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=1.2, alpha=alpha, zorder=3,
                    label=overlay.label(outcome) if n == 0 else None)
    for n, c in enumerate(overlay.collisions):
        ax.plot(c.x, c.y, marker="x", ms=7, mew=1.6, color="black", zorder=5,
                label="collision" if n == 0 else None)
    _label_collisions(ax, overlay.collision_places())
    for agent in world.agents:
        ax.plot(agent.start.x, agent.start.y, marker="o", color="#2f6b2f", ms=5, zorder=4)
        ax.add_patch(Circle((agent.goal.x, agent.goal.y), agent.goal.tolerance, fill=False,
                            edgecolor="#2f6b2f", lw=1.0, ls="--", zorder=4))
        ax.annotate(agent.name if len(world.agents) > 1 else "goal",
                    (agent.goal.x, agent.goal.y), xytext=(6, -10), textcoords="offset points",
                    fontsize=8, color="#2f6b2f")
    place_legend(ax, scene.static)
    seeds = overlay.seeds
    ax.set_title(f"{overlay.world}: {len(seeds)} runs (seeds {seeds[0]}..{seeds[-1]}), "
                 "paths by the run's outcome", fontsize=9)
    return finish(fig, path, show)


def _label_collisions(ax: Axes, places: list[tuple[float, float, int, float, float]]) -> None:
    """A label per place (``12×, 14.5-14.9 s``), on the side facing the middle (a collision
    near a wall keeps its label in the map); a place whose label would overlap one drawn
    already is counted in that one. The places are 20 in wide, but on a map of 800 in a
    label is wider than that, and labels of places 25 in apart were drawn over one another
    (``10.910.5 s``)."""
    from .world import inward

    ax.apply_aspect()       # the map's equal aspect, as drawn: the boxes are measured on it
    drawn: list[tuple[Annotation, list, Bbox]] = []     # each label, its place, its box

    def label(place: list) -> tuple[Annotation, list, Bbox]:
        x, y, count, first, last = place
        when = f"{first:.1f} s" if count == 1 else f"{count}×, {first:.1f}-{last:.1f} s"
        text = ax.annotate(when, (x, y), fontsize=7, zorder=6, **inward(ax, x, y),
                           bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none",
                                 "alpha": 0.8})
        return text, place, text.get_window_extent().padded(3)   # (the figure's renderer)

    def meeting(box: Bbox, but: int = -1) -> int | None:
        return next((k for k, d in enumerate(drawn) if k != but and d[2].overlaps(box)), None)

    for place in places:
        drawn.append(label(list(place)))
        at = len(drawn) - 1
        # merged, a label grows ("12×, 5.1-49.8 s"), and may meet another: merge on
        while (other := meeting(drawn[at][2], at)) is not None:
            keep, gone = min(at, other), max(at, other)
            into, more = drawn[keep][1], drawn[gone][1]
            into[2] += more[2]
            into[3], into[4] = min(into[3], more[3]), max(into[4], more[4])
            for text, _, _ in (drawn[keep], drawn[gone]):
                text.remove()
            del drawn[gone]
            drawn[keep] = label(into)
            at = keep
