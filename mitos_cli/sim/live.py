"""``--live``: a terminal view of a run while it steps (rich, on stderr): a small character map
of the walls, obstacles and robots, and the current inputs and commands."""

from __future__ import annotations

import numpy as np


class LiveView:
    """Call :meth:`update` from ``simulate(on_tick=...)``; use as a context manager."""

    def __init__(self, world, scene, every: int = 2, cols: int = 72) -> None:
        from rich.console import Console
        from rich.live import Live

        self.world, self.scene, self.every = world, scene, max(1, every)
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
        self.live = Live(console=Console(stderr=True), auto_refresh=False, transient=False)

    def __enter__(self) -> LiveView:
        self.live.__enter__()
        return self

    def __exit__(self, *exc) -> None:
        self.live.__exit__(*exc)

    def _cell(self, x: float, y: float):
        xmin, ymin, xmax, ymax = self.box
        c = int((x - xmin) / (xmax - xmin) * self.cols)
        r = int((ymax - y) / (ymax - ymin) * self.rows)
        return (r, c) if 0 <= r < self.rows and 0 <= c < self.cols else None

    def update(self, k: int, state: dict) -> None:
        if k % self.every:
            return
        from rich.text import Text

        grid = self.background.copy()
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
        lines.append(f"t = {state['t']:6.2f} s  speed {state['speed'][0]:5.1f} in/s  steering "
                     f"{state['steering'][0]:5.1f} deg  clearance {state['clearance'][0]:5.1f} in")
        lines.append("  ".join(f"{k} {v[0]:.1f}" for k, v in inputs.items()))
        self.live.update(Text("\n".join(lines)), refresh=True)
