"""One moment of a run as an RGB image: the walls, the route, the obstacles where they are now,
the robot's footprint and the trail it left. The background is drawn once; each frame moves the
few artists that change, so a frame costs a canvas draw, not a new figure (the Gymnasium
environment's ``rgb_array`` render)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .output import _matplotlib, literal_text, new_figure
from .world import draw_grid

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

    from matplotlib.axes import Axes
    from numpy.typing import ArrayLike

    from ..sim.route import Route
    from ..sim.staticmap import StaticMap
    from ..sim.world import World

ROBOT_COLOUR = "#1f5fbf"     # the footprint (a test looks for this colour in the frames)
TRAIL_COLOUR = "#2ca02c"
OBSTACLE_COLOUR = "#b5524a"


class RunFrame:
    """Draws frames of one world: ``rgb(pose, obstacles, trail)`` -> ``uint8 [H, W, 3]``.
    ``pose`` is the robot's (x, y in inches, heading in degrees), ``obstacles [O, 2]`` their
    places, ``trail [T, 2]`` the path so far. ``show`` draws into a window instead (pyplot;
    :class:`~mitos_cli.draw.output.DrawError` where none can open)."""

    def __init__(self, world: World, static: StaticMap, routes: Sequence[Route], *, width_px: int = 640,
                 show: bool = False) -> None:
        _matplotlib()
        from matplotlib.patches import Circle, Polygon

        self.world = world
        xmin, ymin, xmax, ymax = static.bounds
        pad = 20.0
        w, h = xmax - xmin + 2 * pad, ymax - ymin + 2 * pad
        dpi = 80
        fw = width_px / dpi
        fh = max(0.8, min(fw * h / w, 12.0)) + 0.3
        self.fig = new_figure((fw, fh), show=show, dpi=dpi)
        ax = self.ax = self.fig.add_axes((0.0, 0.0, 1.0, 1.0 - 0.3 / fh))
        ax.set_aspect("equal")
        ax.set_axis_off()
        ax.set_facecolor("#d9d9d9")
        self.fig.patch.set_facecolor("#d9d9d9")
        self._routes = draw_background(ax, world, static, routes)
        self._obstacles = []
        for o in world.obstacles:
            patch = (Circle((o.x, o.y), o.radius) if o.shape == "circle"
                     else Polygon(np.zeros((4, 2)), closed=True))
            patch.set(facecolor=OBSTACLE_COLOUR, edgecolor="#5c1f1a", lw=0.8)
            ax.add_patch(patch)
            self._obstacles.append((o, patch))
        (self._trail,) = ax.plot([], [], color=TRAIL_COLOUR, lw=1.6)
        robot = world.agents[0].robot
        self._size = (robot.length, robot.width)
        self._robot = Polygon(np.zeros((4, 2)), closed=True, facecolor=ROBOT_COLOUR,
                              edgecolor="black", lw=0.6)
        ax.add_patch(self._robot)
        self._title = self.fig.text(0.01, 1.0 - 0.15 / fh, "", fontsize=9, va="center")
        ax.set_xlim(xmin - pad, xmax + pad)
        ax.set_ylim(ymin - pad, ymax + pad)
        literal_text(self.fig)          # a world's name or label is drawn as written

    def update(self, pose: np.ndarray, obstacles: np.ndarray, trail: ArrayLike,
               t: float | None = None, routes: Sequence[Route] | None = None) -> None:
        """Move the artists to this moment; ``routes``, the robots' routes now (a replan
        changes them; the frame showed the first ones to the end)."""
        from matplotlib.patches import Circle

        from ..sim.geometry import rect_corners

        if routes is not None:
            show_routes(self._routes, routes)

        x, y, h = (float(v) for v in pose)
        self._robot.set_xy(rect_corners(x, y, np.deg2rad(h), *self._size))
        trail = np.asarray(trail, float).reshape(-1, 2)
        self._trail.set_data(trail[:, 0], trail[:, 1])
        for (o, patch), (cx, cy) in zip(self._obstacles, np.asarray(obstacles).reshape(-1, 2)):
            if isinstance(patch, Circle):
                patch.set_center((cx, cy))
            else:
                patch.set_xy(rect_corners(cx, cy, np.deg2rad(o.angle), o.length, o.width))
        if t is not None:
            self._title.set_text(f"{self.world.name}  t = {t:5.2f} s")

    def rgb(self, pose: np.ndarray, obstacles: np.ndarray, trail: ArrayLike,
            t: float | None = None, routes: Sequence[Route] | None = None) -> np.ndarray:
        """The frame as ``uint8 [H, W, 3]``."""
        self.update(pose, obstacles, trail, t, routes)
        canvas = self.fig.canvas
        canvas.draw()
        return np.asarray(canvas.buffer_rgba())[..., :3].copy()    # type: ignore[attr-defined]  # (Agg)

    def close(self) -> None:
        import sys

        if "matplotlib.pyplot" in sys.modules:
            import matplotlib.pyplot as plt

            plt.close(self.fig)


def show_routes(lines: list, routes: Iterable[Route]) -> None:
    """Move each robot's route line (:func:`draw_background`'s) to its route now."""
    for line, route in zip(lines, routes):
        line.set_data(route.points[:, 0], route.points[:, 1])


def draw_background(ax: Axes, world: World, static: StaticMap, routes: Sequence[Route]) -> list:
    """What does not move but the routes: free space, walls, the routes (whose lines it
    returns: a replan moves them, :func:`show_routes`) and the goals."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle, Polygon

    if static.grid is not None:
        draw_grid(ax, static.grid)
    for corners in static.rects:
        ax.add_patch(Polygon(corners, closed=True, facecolor="white", edgecolor="none"))
    ax.add_collection(LineCollection(static.walls.reshape(-1, 2, 2),  # type: ignore[arg-type]
                                     colors="black",
                                     linewidths=1.0))
    lines = [ax.plot(route.points[:, 0], route.points[:, 1], ls="--", lw=0.7,
                     color="#4a78b5")[0] for route in routes]
    for agent in world.agents:
        ax.add_patch(Circle((agent.goal.x, agent.goal.y), agent.goal.tolerance, fill=False,
                            edgecolor="#2f6b2f", lw=1.0, ls="--"))
    return lines
