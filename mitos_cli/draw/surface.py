"""Control surfaces: an output over two inputs (3-D surface or heat map with contours), or
over one input (a curve), from a :class:`~mitos_cli.draw.data.Surface`.

Where no rule sets the output and it has no default, the surface is NaN: drawn as a hatched,
blank region with a legend entry saying so, never as a made-up number.
"""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError, unknown
from .data import Surface
from .output import finish, new_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch, Rectangle
    from mpl_toolkits.mplot3d import Axes3D

STYLES = ("surface", "heatmap")
CMAP = "viridis"
HATCH_COLOR = "#bbbbbb"


def title_of(s: Surface) -> str:
    over = s.x.name if s.y is None else f"{s.x.name} × {s.y.name}"
    text = f"{s.output} over {over}"
    if s.fixed:
        text += f"  ({s.fixed_text})"
    return text


def _masked_words(s: Surface) -> str:
    """What the blank (masked) points are: where no rule fires (NaN), and where the output
    is infinite (a Tsukamoto sigmoid inverted at 1), which is no \"no rule fires\"."""
    said = []
    if np.isnan(s.z).any():
        said.append("no rule fires (default nan)" if s.nan_default else
                    "no rule fires (no default)")
    if np.isinf(s.z).any():
        said.append(f"`{s.output}` infinite")
    return " or ".join(said)


def _no_rule_patch(s: Surface) -> Patch:
    from matplotlib.patches import Patch

    return Patch(facecolor="white", edgecolor=HATCH_COLOR, hatch="///", label=_masked_words(s))


def _nan_spans(x: np.ndarray, mask: np.ndarray) -> list[tuple[float, float]]:
    """The stretches of ``x`` nearer a masked sample than an unmasked one: each run of masked
    samples, widened half a step each side (``fill_between(where=...)`` drew a lone masked
    sample, the usual case on a coarse grid, zero wide: the legend's hatching was nowhere)."""
    edges = np.concatenate(([x[0]], (x[1:] + x[:-1]) / 2, [x[-1]]))
    spans = []
    start = None
    for i, masked in enumerate([*mask.tolist(), False]):
        if masked and start is None:
            start = i
        elif not masked and start is not None:
            spans.append((float(edges[start]), float(edges[i])))
            start = None
    return spans


def draw_curve(ax: Axes, s: Surface) -> None:
    """One input: the output as a line; spans where nothing fires shaded and hatched."""
    x, z = s.x.values, s.z
    ax.plot(x, z, color="#1f77b4", linewidth=2.2, label=s.output)
    mask = ~np.isfinite(z)
    if mask.any():
        for lo, hi in _nan_spans(x, mask):
            ax.axvspan(lo, hi, facecolor="none", edgecolor=HATCH_COLOR, hatch="///",
                       linewidth=0, gid="no-rule")
        ax.legend(handles=[ax.lines[0], _no_rule_patch(s)], fontsize=8)
    ax.set_xlim(x[0], x[-1])
    ax.set_xlabel(s.x.label)
    ax.set_ylabel(s.label)
    ax.grid(True, color="#e6e6e6")
    for side in ("top", "right"):
        ax.spines[side].set_visible(False)


def settled(z: np.ndarray) -> np.ndarray:
    """``z`` rounded to 10 significant digits of its largest value, for contouring: a plateau
    the engine computes as 40 in one cell and 40 + 1.4e-14 in the next was crossed by
    contour lines at 40 wherever the last bit changed (four stripes labelled 40 across the
    flat top of the speed heat map)."""
    finite = np.abs(z[np.isfinite(z)])
    if not finite.size or not finite.max():
        return z
    digits = 9 - int(np.floor(np.log10(finite.max())))
    return np.round(z, digits)


def _levels(z: np.ndarray, n: int = 10) -> np.ndarray | None:
    finite = z[np.isfinite(z)]
    if finite.size == 0 or finite.min() == finite.max():
        return None
    from matplotlib.ticker import MaxNLocator

    levels = MaxNLocator(n).tick_values(finite.min(), finite.max())
    return levels[(levels > finite.min()) & (levels < finite.max())]


def draw_heatmap(fig: Figure, ax: Axes, s: Surface) -> None:
    """Heat map with labelled contour lines; masked (blank, hatched) where nothing fires."""
    assert s.y is not None, "a heat map has two inputs"
    z = np.ma.masked_invalid(s.z)
    X, Y = np.meshgrid(s.x.values, s.y.values)
    ax.add_patch(_background(ax))
    mesh = ax.pcolormesh(X, Y, z, cmap=CMAP, shading="gouraud" if not z.mask.any() else "nearest",
                         rasterized=True)
    flat = settled(s.z)
    levels = _levels(flat)
    if levels is not None and len(levels):
        cs = ax.contour(X, Y, np.ma.masked_invalid(flat), levels=levels, colors="white",
                        linewidths=0.8, alpha=0.9)
        ax.clabel(cs, fontsize=7.5, fmt="%g", inline=True)
    bar = fig.colorbar(mesh, ax=ax, pad=0.02)
    bar.set_label(s.label)
    ax.set_xlabel(s.x.label)
    ax.set_ylabel(s.y.label)
    if z.mask.any():
        ax.legend(handles=[_no_rule_patch(s)], loc="upper right", fontsize=8)


def _background(ax: Axes) -> Rectangle:
    """A hatched rectangle under the mesh: it shows through the masked cells."""
    from matplotlib.patches import Rectangle

    return Rectangle((0, 0), 1, 1, transform=ax.transAxes, facecolor="white",
                     edgecolor=HATCH_COLOR, hatch="///", linewidth=0, zorder=0)


def draw_surface3d(fig: Figure, ax: Axes3D, s: Surface) -> None:
    """A shaded 3-D surface with its contours projected on the floor; masked cells are
    left out (holes), and a note says so."""
    assert s.y is not None, "a surface has two inputs"
    X, Y = np.meshgrid(s.x.values, s.y.values)
    z = np.ma.masked_invalid(s.z)
    finite = s.z[np.isfinite(s.z)]
    lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    if lo == hi:
        lo, hi = lo - 1, hi + 1
    floor = lo - 0.25 * (hi - lo)
    # every grid point up to 120 per axis; beyond that matplotlib samples (1e4 polygons max)
    surf = ax.plot_surface(X, Y, z, cmap=CMAP, vmin=lo, vmax=hi,
                           rcount=min(len(s.y.values), 120), ccount=min(len(s.x.values), 120),
                           linewidth=0.15, edgecolor=(1, 1, 1, 0.25), antialiased=True,
                           rasterized=True)     # an SVG keeps one image, not 3,600 polygons
    if finite.size:
        flat = settled(s.z)
        levels = _levels(flat)
        if levels is not None and len(levels):
            ax.contour(X, Y, np.ma.masked_invalid(flat), levels=levels, zdir="z", offset=floor,
                       cmap=CMAP, linewidths=0.8)
    ax.set_zlim(floor, hi + 0.02 * (hi - lo))
    ax.set_xlabel(s.x.label, labelpad=8)
    ax.set_ylabel(s.y.label, labelpad=8)
    ax.set_zlabel(s.label, labelpad=8)
    ax.view_init(elev=25, azim=-60)
    bar = fig.colorbar(surf, ax=ax, shrink=0.55, pad=0.1)
    bar.set_label(s.label)
    if z.mask.any():
        ax.text2D(0.0, 0.0, f"holes: {_masked_words(s)}", transform=ax.transAxes, fontsize=8,
                  color="#555555")


def draw_surface(s: Surface, path: str | Path | None = None, *, style: str = "surface",
                 title: str | None = None, show: bool = False) -> Figure:
    """Draw ``s`` (a curve when it has one input) to ``path`` (.png/.svg) and/or a window."""
    if style not in STYLES:         # (a bare ValueError, without a "did you mean")
        raise unknown("style", f"{style!s:.40}", STYLES, cls=InputError)
    if s.y is None:
        fig = new_figure((7.0, 4.2), show, layout="constrained")
        ax = fig.subplots()
        draw_curve(ax, s)
    elif style == "heatmap":
        fig = new_figure((7.6, 5.6), show, layout="constrained")
        ax = fig.subplots()
        draw_heatmap(fig, ax, s)
    else:
        fig = new_figure((8.4, 6.4), show)
        ax = fig.add_subplot(projection="3d")
        draw_surface3d(fig, ax, s)
    # (a behavior of thirteen inputs holds twelve fixed: on one line its title was wider than
    # the picture, and the layout squeezed the axes to nothing)
    heading = "\n".join(line for part in (title or title_of(s)).split("\n")
                        for line in textwrap.wrap(part, 90) or [part])
    if s.y is not None and style == "surface":
        fig.suptitle(heading, fontsize=12, y=0.9)
    else:
        ax.set_title(heading, fontsize=11, loc="left")
    return finish(fig, path, show)
