"""A finished run as a moving picture (``mitos simulate --animate run.gif``): the map, each
robot's footprint, sonar cones and trail, the obstacles where they are, the time and, for a
rule-base planner, the fired rules' DOFs as a bar panel. GIF through Pillow (which matplotlib
installs), MP4 through ffmpeg where it is on the PATH.

Frames are taken from the recorded ticks at ``fps`` frames per second of simulated time: tick
``k * step`` with ``step = round(1 / (fps * dt))`` (at least 1), plus the last tick, and the
file plays at ``fps`` (real time).
"""

from __future__ import annotations

import functools
import math
import numbers
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ..errors import InputError, WriteError
from ..numbers import whole_number
from ..words import plural
from .frame import OBSTACLE_COLOUR, ROBOT_COLOUR, TRAIL_COLOUR, draw_background, show_routes
from .output import DrawError, _matplotlib, file_path, literal_text, new_figure

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable

    from matplotlib.animation import AbstractMovieWriter
    from matplotlib.axes import Axes
    from matplotlib.backend_bases import RendererBase
    from matplotlib.collections import PolyCollection
    from matplotlib.figure import Figure

    from ..engine.evaluation import Result
    from ..sim.loop import SimResult
    from ..sim.staticmap import StaticMap
    from ..sim.world import World

FORMATS = ("gif", "mp4")
BARS = 8                    # fired rules shown, by DOF
#: frames per second, as ``mitos simulate --fps`` takes them
FPS = (0.1, 60.0)
#: the picture's width in pixels (the CLI's is 720)
WIDTH_PX = (100, 4000)


def check_format(path: str | Path) -> str:
    """``gif`` or ``mp4`` by the extension (mp4 only where ffmpeg is found)."""
    suffix = file_path(path, "an animation").suffix.lower().lstrip(".")
    if suffix not in FORMATS:
        raise DrawError(f"cannot write `{path}`: unknown animation format "
                        f"`{suffix or '(no extension)'}`",
                        expected="a file name ending in .gif or .mp4")
    if suffix == "mp4":
        _matplotlib()
        from matplotlib import animation

        if not animation.writers.is_available("ffmpeg"):
            raise DrawError(f"cannot write `{path}`: MP4 needs ffmpeg, which is not on the PATH",
                            hint="install ffmpeg, or write a .gif (Pillow needs nothing more)")
    return suffix


def frame_ticks(ticks: int, dt: float, fps: float) -> np.ndarray:
    """The recorded ticks drawn at ``fps`` frames per simulated second (and the last one)."""
    if ticks == 0:
        return np.zeros(0, dtype=int)
    step = max(1, int(round(1.0 / (fps * dt))))
    picked = np.arange(0, ticks, step)
    return picked if picked[-1] == ticks - 1 else np.append(picked, ticks - 1)


def check_fps(fps: object) -> float:
    """``fps`` as a number of frames per second in :data:`FPS`, else an :class:`InputError`
    (0 met a ZeroDivisionError, -1 and 1e-6 an OverflowError, NaN a ValueError inside, and
    ``True`` was 1 frame per second)."""
    try:
        real = isinstance(fps, numbers.Real) and not isinstance(fps, (bool, np.bool_))
        value = float(fps) if real else math.nan  # type: ignore[arg-type]
    except OverflowError:                                   # 10**400
        value = math.nan
    if not FPS[0] <= value <= FPS[1]:
        raise InputError(f"fps is a number of frames per second from {FPS[0]:g} to {FPS[1]:g} "
                         f"(as `mitos simulate --fps`), not `{fps!r:.40}`")
    return value


def check_width(width_px: object) -> int:
    """``width_px`` as a whole number of pixels in :data:`WIDTH_PX`, else an
    :class:`InputError` (0 met an IndexError inside, -5 matplotlib's "figure size must be
    positive", and a width of millions of pixels would fill the memory)."""
    n = whole_number(width_px)
    if n is None or not WIDTH_PX[0] <= n <= WIDTH_PX[1]:
        raise InputError(f"width_px is a whole number of pixels from {WIDTH_PX[0]} to "
                         f"{WIDTH_PX[1]}, not `{width_px!r:.40}`")
    return n


def _check_detail(detail: object, ticks: int) -> None:
    """``detail`` if it is an engine result of one row per tick of the run (``explain(result,
    planner)``), else an :class:`InputError`: another run's drew its fired rules under this
    one's frames without a word, and a shorter one met an IndexError."""
    if detail is None:
        return
    dof = getattr(detail, "dof", None)
    if dof is None or getattr(detail, "compiled", None) is None:
        raise InputError(f"detail is the engine's result for the run's ticks, not "
                         f"{type(detail).__name__} `{detail!r:.40}`",
                         hint="detail=mitos_cli.sim.export.explain(result, planner)")
    if len(dof) != ticks:
        raise InputError(f"detail has {plural(len(dof), 'row')}, and the run "
                         f"{plural(ticks, 'tick')}: it is of another run",
                         hint="detail=mitos_cli.sim.export.explain(result, planner), of this "
                              "result")


def animate_run(result: SimResult, path: str | Path, *, fps: float = 10.0, detail: Result | None = None,
                width_px: int = 720) -> int:
    """Write ``result`` as an animation to ``path``; ``detail`` is the planner's engine result
    for robot 0 (rows = ticks, :func:`mitos_cli.sim.export.explain`) for the DOF panel.
    Returns the number of frames written."""
    fps, width_px = check_fps(fps), check_width(width_px)
    fmt = check_format(path)
    _check_detail(detail, result.ticks)
    _matplotlib()
    from matplotlib import animation

    dpi = 80
    scene = _Scene(result, detail, width_px, dpi)
    picked = frame_ticks(result.ticks, result.world.dt, fps)
    writer = (_gif_writer()(fps=fps) if fmt == "gif"
              else animation.FFMpegWriter(fps=fps))  # type: ignore[arg-type]
    _save(scene.fig, scene.draw, picked, writer, Path(path), fmt, dpi)
    return len(picked)


class _Scene:
    """The figure of a run and its moving parts (obstacles, robots and trails, sonar cones,
    the DOF panel), which :meth:`draw` sets to a tick."""

    PAD = 20.0                                 # world units round the map

    def __init__(self, result: SimResult, detail: Result | None, width_px: int, dpi: int) -> None:
        self.result, self.detail = result, detail
        static = cast("StaticMap", result.static)                  # (a run has its map)
        xmin, ymin, xmax, ymax = static.bounds
        w, h = xmax - xmin + 2 * self.PAD, ymax - ymin + 2 * self.PAD
        fw = width_px / dpi
        map_h = max(1.0, min(fw * h / w, 9.0))
        panel_h = 1.6 if detail is not None else 0.0
        fh = map_h + panel_h + 0.35
        self.fig = new_figure((fw, fh), dpi=dpi)
        self.fig.patch.set_facecolor("white")
        ax = self.fig.add_axes((0.0, (panel_h + 0.05) / fh, 1.0, map_h / fh))
        ax.set_aspect("equal")
        ax.set_axis_off()
        ax.set_facecolor("#d9d9d9")
        self.route_lines = draw_background(ax, result.world, static, result.routes)
        ax.set_xlim(xmin - self.PAD, xmax + self.PAD)
        ax.set_ylim(ymin - self.PAD, ymax + self.PAD)
        self.title = self.fig.text(0.01, 1.0 - 0.17 / fh, "", fontsize=10, va="center")
        self.obstacles = _obstacle_patches(ax, result.world)
        self.robots, self.trails = _robot_patches(ax, result.world, result.pose.shape[1])
        self.cones = _cone_collection(ax, static.bounds)
        self.half_cone = max(result.world.sensors.cone, 2.0) / 2
        self.bars: list | None = None
        self.texts: list[_SlotText] | None = None
        if detail is not None:
            agents = result.world.agents
            self.bars, self.texts = _dof_panel(self.fig, fh, panel_h, dpi,
                                               agents[0].name if len(agents) > 1 else None)

    def draw(self, k: int) -> None:
        """The frame of tick ``k``."""
        result, world = self.result, self.result.world
        self.title.set_text(f"{world.name}   t = {result.t[k]:5.2f} s   ({result.planner})")
        if result.replanned:                # each robot's route as it was at tick k
            show_routes(self.route_lines,
                        [result.route_at(k, i) for i in range(len(self.route_lines))])
        self._draw_obstacles(k)
        self._draw_robots(k)
        if self.bars is not None and self.texts is not None:
            self._draw_dofs(k, self.bars, self.texts)

    def _draw_obstacles(self, k: int) -> None:
        from matplotlib.patches import Circle

        from ..sim.geometry import rect_corners

        for (o, patch), (cx, cy) in zip(self.obstacles, self.result.obstacles[k].reshape(-1, 2)):
            if isinstance(patch, Circle):
                patch.set_center((cx, cy))
            else:
                patch.set_xy(rect_corners(cx, cy, np.deg2rad(o.angle), o.length, o.width))

    def _draw_robots(self, k: int) -> None:
        from ..sim.geometry import rect_corners

        result, sen = self.result, self.result.world.sensors
        sectors = []
        for i, ((robot, body), trail) in enumerate(zip(self.robots, self.trails)):
            x, y, heading = result.pose[k, i]
            body.set_xy(rect_corners(x, y, np.deg2rad(heading), robot.length, robot.width))
            trail.set_data(result.pose[:k + 1, i, 0], result.pose[:k + 1, i, 1])
            sectors.append(_sectors(x, y, np.rad2deg(sen.angles) + heading, result.ranges[k, i],
                                    self.half_cone))
        self.cones.set_verts(list(np.concatenate(sectors)))

    def _draw_dofs(self, k: int, bars: list, texts: list[_SlotText]) -> None:
        detail = cast("Result", self.detail)                       # (drawn only with a detail)
        dof, compiled = cast(np.ndarray, detail.dof)[k], detail.compiled
        order = [r for r in np.argsort(-dof, kind="stable")[:BARS] if dof[r] > 0]
        for slot, (bar, text) in enumerate(zip(bars, texts)):
            r = order[slot] if slot < len(order) else None
            bar.set_width(float(dof[r]) if r is not None else 0.0)
            text.show(None if r is None else (f"{dof[r]:.2f}",
                                              f"{compiled.labels[r]}: {compiled.rule_text(r)}"))


def _obstacle_patches(ax: Axes, world: World) -> list:
    """Each obstacle of ``world`` with its patch (placed by :meth:`_Scene.draw`)."""
    from matplotlib.patches import Circle, Polygon

    obstacles = []
    for o in world.obstacles:
        patch = (Circle((o.x, o.y), o.radius) if o.shape == "circle"
                 else Polygon(np.zeros((4, 2)), closed=True))
        patch.set(facecolor=OBSTACLE_COLOUR, edgecolor="#5c1f1a", lw=0.8, zorder=3)
        ax.add_patch(patch)
        obstacles.append((o, patch))
    return obstacles


def _robot_patches(ax: Axes, world: World, n: int) -> tuple[list, list]:
    """Each robot's body (with its robot) and trail: one robot blue with a green trail;
    several each in its colour and line style of ``--plot``'s picture of the run
    (:data:`~mitos_cli.draw.world.ROBOT_COLOURS`; the third robot was teal there and purple
    here, and past five robots the colours came round again)."""
    from matplotlib.patches import Polygon

    from .world import ROBOT_COLOURS, ROBOT_STYLES

    robots, trails = [], []
    for i, agent in enumerate(world.agents):
        colour = ROBOT_COLOURS[i % len(ROBOT_COLOURS)] if n > 1 else ROBOT_COLOUR
        (trail,) = ax.plot([], [], color=colour if n > 1 else TRAIL_COLOUR, lw=1.6,
                           ls=ROBOT_STYLES[i // len(ROBOT_COLOURS) % len(ROBOT_STYLES)],
                           alpha=1.0 if i == 0 else 0.6, zorder=4)
        body = Polygon(np.zeros((4, 2)), closed=True, facecolor=colour, edgecolor="black",
                       lw=0.6, zorder=5)
        ax.add_patch(body)
        if n > 1:                       # its name at its goal, as --plot writes it (no robot
            ax.annotate(agent.name, (agent.goal.x, agent.goal.y), xytext=(6, -10),  # was named)
                        textcoords="offset points", fontsize=8, color=colour, zorder=6)
        robots.append((agent.robot, body))
        trails.append(trail)
    return robots, trails


def _cone_collection(ax: Axes, bounds: tuple[float, float, float, float]) -> PolyCollection:
    """The sonar cones' collection, clipped to the map: no cone past the outer walls."""
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Rectangle

    xmin, ymin, xmax, ymax = bounds
    cones = PolyCollection([], facecolor="#f2c14e", edgecolor="none", alpha=0.35, zorder=2)
    ax.add_collection(cones)
    cones.set_clip_path(Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, transform=ax.transData))
    return cones


def _dof_panel(fig: Figure, fh: float, panel_h: float, dpi: int,
               who: str | None = None) -> tuple[list, list]:
    """The panel of the fired rules under the map: :data:`BARS` bars and their texts;
    ``who``: the robot whose rules they are, where there are several (the first's)."""
    bax = fig.add_axes((0.01, 0.05 / fh, 0.98, (panel_h - 0.1) / fh))
    bax.set_xlim(0, 1)
    bax.set_ylim(BARS - 0.5, -1.3)
    bax.set_axis_off()
    whose = f" of `{who}`, the first robot," if who is not None else ""
    bax.text(0.0, -1.0, f"fired rules{whose} by DOF (the bar's length: 0 to 1)", fontsize=7,
             va="center", color="#333333")
    bars = bax.barh(range(BARS), np.zeros(BARS), color="#b8cbe6", height=0.8)
    return list(bars), [_SlotText(fig, bax, slot, dpi) for slot in range(BARS)]


def _sectors(x: float, y: float, bearings: np.ndarray, ranges: np.ndarray,
             half: float, steps: int = 8) -> np.ndarray:
    """``[B, steps + 2, 2]``: each beam's cone as a polygon, its apex at ``(x, y)`` and its
    arc of ``ranges`` round ``bearings`` +- ``half`` (deg) in ``steps`` chords (one array for
    every cone of a frame, where a matplotlib Wedge per beam built its Bezier arc anew)."""
    theta = np.deg2rad(bearings[:, None] + np.linspace(-half, half, steps + 1))
    out = np.empty((len(bearings), steps + 2, 2))
    out[:, 0] = x, y
    out[:, 1:, 0] = x + ranges[:, None] * np.cos(theta)
    out[:, 1:, 1] = y + ranges[:, None] * np.sin(theta)
    return out


class _SlotText:
    """A bar's text (its DOF, then the rule) as bitmaps pasted at its place: each text is
    rendered once and kept, since a run's frames show the same few rules again and again, and
    rendering their glyphs anew each frame took nine tenths of a frame's drawing."""

    FONTSIZE = 7
    _cache: dict[tuple[str, int], np.ndarray] = {}

    def __init__(self, fig: Figure, bax: Axes, slot: int, dpi: int) -> None:
        self.dpi = dpi
        x, y = bax.transData.transform((0.003, slot))      # pixels; the text's middle
        gap = self.bitmap("0.00  ").shape[1]                # the rule after the DOF
        bitmap = _bitmap_class()
        self.dof = fig.add_artist(bitmap(int(round(x)), y))
        self.rule = fig.add_artist(bitmap(int(round(x)) + gap, y))

    def show(self, texts: tuple[str, str] | None) -> None:
        """Show ``(dof, rule)``, or nothing."""
        for image, text in zip((self.dof, self.rule), texts or ("", "")):
            image.pixels = self.bitmap(text) if text else None   # type: ignore[attr-defined]  # (a Bitmap)

    def bitmap(self, text: str) -> np.ndarray:
        """``text`` drawn in black on a clear ground, cropped to its line (RGBA, uint8)."""
        key = (text, self.dpi)
        if key not in self._cache:
            self._cache[key] = _render_text(text, self.FONTSIZE, self.dpi)
        return self._cache[key]


@functools.cache
def _bitmap_class() -> type:
    """The artist class, made on first use: matplotlib is imported only for an animation."""
    from matplotlib.artist import Artist

    class Bitmap(Artist):
        """RGBA pixels drawn as they are (no resampling) with their left edge at ``x`` and
        their middle at ``y`` (figure pixels)."""

        def __init__(self, x: int, y: float) -> None:
            super().__init__()
            self.x, self.y = x, y
            self.pixels: np.ndarray | None = None
            self.set_zorder(5)

        def draw(self, renderer: RendererBase) -> None:
            if self.pixels is None or not self.get_visible():
                return
            gc = renderer.new_gc()
            renderer.draw_image(gc, self.x, int(round(self.y - self.pixels.shape[0] / 2)),
                                self.pixels[::-1])
            gc.restore()

    return Bitmap


def _render_text(text: str, fontsize: float, dpi: int) -> np.ndarray:
    """``text`` rendered alone on a clear figure just large enough for it."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(dpi=dpi)
    canvas = FigureCanvasAgg(fig)
    fig.patch.set_alpha(0.0)
    label = fig.text(0, 0, text, fontsize=fontsize, va="bottom", ha="left", parse_math=False)
    box = label.get_window_extent(canvas.get_renderer())
    width, height = int(np.ceil(box.width)) + 2, int(np.ceil(box.height)) + 2
    fig.set_size_inches(width / dpi, height / dpi)
    label.set_position((1 / width, 1 / height))
    canvas.draw()
    return np.asarray(canvas.buffer_rgba()).copy()


@functools.cache
def _gif_writer() -> type:
    """matplotlib's Pillow writer, each frame reduced to its palette as it is taken, by
    Pillow's fast octree: the flat colours of a map need no more, and the median cut Pillow
    otherwise runs on every frame when the GIF is saved took a third of an animation's time."""
    from matplotlib import animation
    from PIL import Image

    class GifWriter(animation.PillowWriter):
        _frames: list                            # PillowWriter's, set up by its setup()

        def grab_frame(self, **savefig_kwargs: Any) -> None:      # savefig's own
            super().grab_frame(**savefig_kwargs)
            frame = self._frames[-1]
            if frame.mode == "RGB":              # not a frame with transparency
                self._frames[-1] = frame.quantize(method=Image.Quantize.FASTOCTREE)

    return GifWriter


def _save(fig: Figure, draw: Callable[[int], object], picked: Iterable[int], writer: AbstractMovieWriter,
          path: Path, fmt: str, dpi: int) -> None:
    """One canvas draw per frame into matplotlib's writer. The writers want a file name:
    write beside the target, then rename it into place (a stopped run leaves no half-written
    animation), through a link as every other file is written (the link was replaced by the
    animation, and the file it named kept the old one), under a name of this process's (two
    runs wrote one part file)."""
    import os

    from ..fileio import replace_with

    part = path.with_name(f".{path.name}.{os.getpid()}.part.{fmt}")
    literal_text(fig)
    try:
        with writer.saving(fig, str(part), dpi):
            for k in picked:
                draw(int(k))
                writer.grab_frame()
        replace_with(part, path)
    except OSError as exc:
        raise WriteError(f"cannot write `{path}`: {exc.strerror or exc}") from None
    finally:
        if part.exists():
            part.unlink()
