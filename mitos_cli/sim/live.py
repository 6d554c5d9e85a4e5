"""``--live``: a terminal view of a run while it steps (rich, on stderr): a small character map
of the walls, obstacles, robots and the trail, and the current inputs and commands.

The view is paced: with ``speed`` 1 a 26 s run takes 26 s on the wall clock, with 4 a quarter
of that, with 0 as fast as the simulator goes. Frames are drawn at most ``fps`` times a wall
second whatever the pace (drawing every tick of a fast run would cost more than the run), and
the last tick is always drawn, so the view ends on the final state.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from rich.console import Console

    from .loop import Scene
    from .world import World

#: Wall-clock frames per second of the view (a terminal redraw is ~1 ms for the 72 x 30 map).
FPS = 20.0


class Pacer:
    """Holds a run to ``speed`` times real time: :meth:`wait` ``(t)`` returns once ``t / speed``
    wall seconds have passed since the first call (never, with ``speed`` 0). The clock and the
    sleep are arguments so tests need not wait."""

    def __init__(self, speed: float, clock: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        if not speed >= 0:
            raise ValueError(f"speed must be >= 0, not {speed}")
        self.speed, self.clock, self.sleep = speed, clock, sleep
        self.start: float | None = None

    def wait(self, t: float) -> float:
        """Sleep until simulated time ``t`` is due; returns the wall seconds slept."""
        now = self.clock()
        if self.start is None:
            self.start = now - (t / self.speed if self.speed else 0.0)
        if not self.speed:
            return 0.0
        late = self.start + t / self.speed - now
        if late > 0:
            self.sleep(late)
            return late
        return 0.0


class LiveView:
    """Call :meth:`update` from ``simulate(on_tick=...)``; use as a context manager.

    ``speed`` is the real-time factor (0: unpaced); ``fps`` caps the redraws per wall second.
    """

    def __init__(self, world: World, scene: Scene, *, speed: float = 1.0, fps: float = FPS, cols: int = 72,
                 console: Console | None = None, clock: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        from rich.console import Console
        from rich.live import Live

        self.world, self.scene = world, scene
        self.pacer = Pacer(speed, clock, sleep)
        self.clock, self.gap = clock, 1.0 / fps
        self.last_draw: float | None = None
        self.pending: dict | None = None          # the newest state not yet drawn
        self.frames = 0
        xmin, ymin, xmax, ymax = scene.static.bounds
        pad = 0.04 * max(xmax - xmin, ymax - ymin)       # show the outer walls
        xmin, ymin, xmax, ymax = xmin - pad, ymin - pad, xmax + pad, ymax + pad
        self.box = (xmin, ymin, xmax, ymax)
        # a character is about twice as tall as wide
        rows = int(round(cols * (ymax - ymin) / (xmax - xmin) / 2))
        self.cols, self.rows = cols, min(max(rows, 5), 30)
        rows = self.rows
        # the static background, once: a cell shows a wall when its centre is not free
        xs = xmin + (np.arange(cols) + 0.5) * (xmax - xmin) / cols
        ys = ymax - (np.arange(rows) + 0.5) * (ymax - ymin) / rows
        gx, gy = np.meshgrid(xs, ys)
        free = scene.static.free(np.stack([gx.ravel(), gy.ravel()], axis=1)).reshape(rows, cols)
        self.background = np.where(free, " ", "#")
        self.trail = np.zeros((rows, cols), dtype=bool)     # cells the first robot crossed
        self.live = Live(console=console or Console(stderr=True), auto_refresh=False,
                         transient=False)

    def __enter__(self) -> LiveView:
        self.live.__enter__()
        return self

    def __exit__(self, *exc: Any) -> None:      # (rich's Live.__exit__ takes them as they come)
        if self.pending is not None:               # end on the last tick, however it ended
            self._draw(self.pending)
        self.live.__exit__(*exc)
        if not self.live.console.is_terminal:      # a file or pipe: end the frame's last line
            self.live.console.line()

    def _cell(self, x: float, y: float) -> tuple[int, int] | None:
        xmin, ymin, xmax, ymax = self.box
        c = int((x - xmin) / (xmax - xmin) * self.cols)
        r = int((ymax - y) / (ymax - ymin) * self.rows)
        return (r, c) if 0 <= r < self.rows and 0 <= c < self.cols else None

    def update(self, k: int, state: dict) -> None:
        """One tick: mark the trail, wait until the tick is due, redraw if a frame is due."""
        x, y, _ = state["pose"][0]
        cell = self._cell(x, y)
        if cell:
            self.trail[cell] = True
        self.pacer.wait(state["t"])
        now = self.clock()
        if self.last_draw is not None and now - self.last_draw < self.gap - 1e-9:
            self.pending = state
            return
        self.last_draw = now
        self._draw(state)

    def text(self, state: dict) -> str:
        """The frame for ``state``: the map, then the time, commands and rule inputs."""
        grid = np.where(self.trail & (self.background == " "), ".", self.background)
        for x, y in state["obstacles"]:
            cell = self._cell(x, y)
            if cell:
                grid[cell] = "o"
        for a in self.world.agents:
            cell = self._cell(a.goal.x, a.goal.y)
            if cell:
                grid[cell] = "G"
        for i, (x, y, _) in enumerate(state["pose"]):
            cell = self._cell(x, y)
            if cell:
                grid[cell] = "R" if i == 0 else "r"
        inputs = state["inputs"]
        lines = ["".join(row) for row in grid]
        lines.append("R robot" + ("  r other robots" if len(self.world.agents) > 1 else "")
                     + "  G goal  o obstacle  . trail  # wall")
        pace = f"x{self.pacer.speed:g}" if self.pacer.speed else "unpaced"
        lines.append(f"t = {state['t']:6.2f} s ({pace})  speed {state['speed'][0]:5.1f} in/s  "
                     f"steering {state['steering'][0]:5.1f} deg  "
                     f"clearance {state['clearance'][0]:5.1f} in")
        line = ""
        for word in (f"{k} {v[0]:.1f}" for k, v in inputs.items()):  # wrapped to the map
            if line and len(line) + 2 + len(word) > self.cols:
                lines.append(line)
                line = ""
            line = f"{line}  {word}" if line else word
        lines.append(line)
        return "\n".join(lines)

    def _draw(self, state: dict) -> None:
        from rich.text import Text

        self.pending = None
        self.frames += 1
        self.live.update(Text(self.text(state)), refresh=True)
