"""Plots of a comparison study: success rates with Wilson intervals, boxes of clearance.

matplotlib is imported inside the functions (Agg backend), so importing this module is cheap.
"""

from __future__ import annotations

import re
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING

from .output import literal_text

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping, Sequence
    from types import ModuleType
    from typing import Protocol

    from matplotlib.figure import Figure

    # what success_bars reads of a study's summaries (mitos_cli.study.summary.Summary, of a
    # layer above this one, which it may not import)
    class _Rate(Protocol):
        @property
        def value(self) -> float | None: ...
        @property
        def lo(self) -> float: ...
        @property
        def hi(self) -> float: ...
        @property
        def k(self) -> int: ...
        @property
        def n(self) -> int: ...

    class _Choice(Protocol):
        @property
        def label(self) -> str: ...

    class _Summary(Protocol):
        @property
        def world(self) -> str: ...
        @property
        def choice(self) -> _Choice: ...
        @property
        def rates(self) -> Mapping[str, _Rate]: ...


def _pyplot() -> ModuleType:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _short(world: str) -> str:
    return Path(world).stem if "/" in world or world.endswith((".yaml", ".yml")) else world


def _names(worlds: list[str]) -> dict[str, str]:
    """Each world as the plots name it: its file's stem, or its path as given where two
    worlds share a stem, as the tables do (`a/t.yaml` and `b/t.yaml` were two groups `t`)."""
    stems = [_short(w) for w in worlds]
    return {w: w if stems.count(_short(w)) > 1 else _short(w) for w in worlds}


def success_bars(summaries: Sequence[_Summary], worlds: list[str], labels: list[str],
                 path: str | Path) -> Path:
    """Grouped bars: success rate per world (groups) and choice (bars), Wilson 95% whiskers.

    ``summaries`` are :class:`mitos_cli.study.summary.Summary` objects.
    """
    import numpy as np

    plt = _pyplot()
    by_key = {(s.world, s.choice.label): s for s in summaries}
    n_w, n_c = len(worlds), len(labels)
    width = 0.8 / max(1, n_c)
    fig, ax = plt.subplots(figsize=(min(14.0, max(6.0, 0.3 * n_w * n_c + 2.0)), 4.6))
    cmap = plt.get_cmap("tab10")
    x = np.arange(n_w)
    for j, label in enumerate(labels):
        values, lo, hi = [], [], []
        for w in worlds:
            s = by_key.get((w, label))
            r = s.rates["success"] if s is not None else None
            if r is None or r.n == 0:
                values.append(np.nan)
                lo.append(0.0)
                hi.append(0.0)
                continue
            v = r.k / r.n
            values.append(100 * v)
            lo.append(100 * (v - r.lo))
            hi.append(100 * (r.hi - v))
        xs = x + (j - (n_c - 1) / 2) * width
        ax.bar(xs, values, width * 0.92, label=label, color=cmap(j % 10), yerr=[lo, hi],
               capsize=2, error_kw={"linewidth": 0.8})
        for xi, v in zip(xs, values):
            if v == 0:                      # an empty bar would be invisible
                ax.text(xi, 1.0, "0", ha="center", va="bottom", fontsize=7,
                        color=cmap(j % 10))
    ax.set_xticks(x)
    names = _names(worlds)
    # a name wider than its group is broken into lines that fit it: one line each (or at
    # 15 deg past four worlds), a long name ran across its neighbours' ("..._corrok dor")
    from matplotlib.font_manager import FontProperties

    size = FontProperties(size=plt.rcParams["xtick.labelsize"]).get_size_in_points()
    group = fig.get_figwidth() * 72 * 0.8 / max(1, n_w)          # points
    chars = max(4, int(0.9 * group / (0.65 * size)))
    ax.set_xticklabels([_broken(names[w], chars) for w in worlds])
    ax.set_ylim(0, 105)
    ax.set_ylabel("success rate (%)")
    ax.set_title("Success rate per world (whiskers: Wilson 95% interval)")
    ax.grid(axis="y", alpha=0.3)
    # the key at the foot of the figure, under the names however many lines they take (below
    # the axes by a fixed fraction, it lay over a name broken into five lines)
    ncol = min(3, n_c)
    fig.legend(fontsize=8, ncol=ncol, loc="lower center", frameon=False)
    literal_text(fig)                   # before the layout measures a world's or choice's name
    fig.tight_layout(rect=(0, (0.1 + 0.2 * -(-n_c // ncol)) / fig.get_figheight(), 1, 1))
    return _save(fig, plt, path)


def clearance_boxes(rows: list[dict], worlds: list[str], labels: list[str],
                    label_of: Callable[[dict], str], path: str | Path) -> Path:
    """One panel per world, one box per choice: minimum clearance (in) over all runs."""
    plt = _pyplot()
    n_w = len(worlds)
    cols = min(3, n_w)
    n_rows = -(-n_w // cols)
    fig, axes = plt.subplots(n_rows, cols, figsize=(4.2 * cols, 3.4 * n_rows + 0.6),
                             squeeze=False, sharey=False)
    cmap = plt.get_cmap("tab10")
    names = _names(worlds)
    for k, world in enumerate(worlds):
        ax = axes[k // cols][k % cols]
        data = [[r["min_clearance_in"] for r in rows
                 if r["world"] == world and label_of(r) == label] for label in labels]
        positions = [j + 1 for j, d in enumerate(data) if d]
        box = ax.boxplot([d for d in data if d], positions=positions, widths=0.6,
                         patch_artist=True, showfliers=True,
                         flierprops={"markersize": 3},
                         # black on every box colour (tab10's orange box hid an orange median)
                         medianprops={"color": "black", "linewidth": 1.6})
        colours = [cmap(j % 10) for j, d in enumerate(data) if d]
        for patch, colour in zip(box["boxes"], colours):
            patch.set_facecolor(colour)
            patch.set_alpha(0.75)
        ax.axhline(0.0, color="black", linewidth=0.6, alpha=0.6)
        ax.set_xticks(range(1, len(labels) + 1))
        ax.set_xticklabels([str(j + 1) for j in range(len(labels))])
        ax.set_title(_broken(names[world], int(4.2 * 72 * 0.8 / (0.65 * 10))), fontsize=10)
        ax.set_ylabel("min clearance (in)")
        ax.grid(axis="y", alpha=0.3)
    for k in range(n_w, n_rows * cols):
        axes[k // cols][k % cols].set_visible(False)
    width, height = fig.get_size_inches()
    # wrapped here: matplotlib's wrap=True measures the text as mathtext whatever parse_math
    # says, and stops on a `$` in a choice's label; one panel's width cut the title's ends
    title = textwrap.wrap("Minimum clearance over all runs (boxes: quartiles; whiskers: "
                          "1.5 IQR)", int(width * 11), break_long_words=False)
    fig.suptitle("\n".join(title), fontsize=11)
    legend = _packed([f"{j + 1}: {label}" for j, label in enumerate(labels)], int(width * 14))
    fig.text(0.5, 0.01, "\n".join(legend), ha="center", fontsize=8)
    literal_text(fig)
    fig.tight_layout(rect=(0, (0.1 + 0.13 * len(legend)) / height, 1, 1))   # (and the title)
    return _save(fig, plt, path)


def _broken(name: str, chars: int) -> str:
    """``name`` in lines of at most ``chars`` characters, broken after a ``_``, ``-``, ``.``,
    ``/`` or space where it can be, and inside a part longer than a line only there."""
    lines: list[str] = []
    line = ""
    for part in re.findall(r"[^_\-./ ]*[_\-./ ]|[^_\-./ ]+", name):
        if len(line) + len(part) <= chars:
            line += part
            continue
        if line:
            lines.append(line)
        while len(part) > chars:
            lines.append(part[:chars])
            part = part[chars:]
        line = part
    if line or not lines:
        lines.append(line)
    return "\n".join(text.rstrip() or text for text in lines)


def _packed(entries: list[str], width: int) -> list[str]:
    """``entries`` three spaces apart in lines of at most ``width`` characters, none split
    across two lines (a line wrapped at any space read "3: fuzzy" / "and=lukasiewicz")."""
    lines: list[str] = []
    for entry in entries:
        if lines and len(lines[-1]) + 3 + len(entry) <= width:
            lines[-1] += "   " + entry
        else:
            lines.append(entry)
    return lines


def _save(fig: Figure, plt: ModuleType, path: str | Path) -> Path:
    """Write ``fig`` to ``path`` as PNG, atomically: a directory (or an unwritable place)
    there is the :class:`WriteError` every command gives, where the rename into it was a
    traceback at the end of the study, its temporary file left behind."""
    from ..fileio import atomic_file

    path = Path(path)
    literal_text(fig)
    try:
        with atomic_file(path, binary=True) as fh:
            fig.savefig(fh, format="png", dpi=110)
    finally:
        plt.close(fig)
    return path
