"""Membership plots: every term of a variable over its universe (the paper's Figures 5-9).

:func:`draw_sheet` draws :class:`~mitos_cli.draw.data.VariablePlot` objects, one panel per
variable (inputs first); :func:`draw_terms_before_after` shows how teaching moved the terms of
one variable. matplotlib is imported only inside these functions (through
:mod:`mitos_cli.draw.output`), never at import time.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from ..lang.terms import Variable
from ..numbers import whole_number
from .data import VariablePlot, variable_plot, visible
from .output import finish, literal_text, new_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: term colours (matplotlib's tab10, colour-blind friendlier than the default cycle's order)
COLORS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b",
          "#e377c2", "#7f7f7f", "#bcbd22")
VALUE_COLOR = "#222222"
LABEL_Y = 1.03          # term names sit just above the curves' tops ...
LABEL_STEP = 0.1        # ... or one step higher where they would overlap


def color(i: int) -> str:
    return COLORS[i % len(COLORS)]


def style_axes(ax: Axes, plot: VariablePlot) -> None:
    """Limits, labels and a light grid for a membership panel."""
    lo, hi = plot.universe
    # stems at the ends of the universe stay visible with a small margin
    pad = 0.03 * (hi - lo) if any(c.kind == "singleton" for c in plot.curves) else 0.0
    ax.set_xlim(lo - pad, hi + pad)
    ax.set_ylim(-0.02, 1.26)
    ax.set_yticks([0, 0.25, 0.5, 0.75, 1.0])
    ax.set_xlabel(plot.axis_label)
    ax.set_ylabel("membership μ")
    ax.grid(True, color="#e6e6e6", linewidth=0.7)
    ax.set_axisbelow(True)
    for side in ("top", "right"):
        ax.spines[side].set_visible(False)


def draw_curves(ax: Axes, plot: VariablePlot, *, colors: Sequence[str] | None = None,
                linestyle: str = "-", alpha: float = 1.0, fill: bool = True,
                labels: bool = True) -> list:
    """The terms of ``plot`` on ``ax`` (``colors[i]`` for curve ``i``, default the palette);
    returns the artists, whose data are the curves'."""
    artists: list = []
    for i, curve in enumerate(plot.curves):
        c = colors[i] if colors is not None else color(i)
        if curve.kind == "curve":
            (line,) = ax.plot(curve.x, curve.y, color=c, linewidth=2.0, linestyle=linestyle,
                              alpha=alpha, label=curve.name, solid_joinstyle="miter")
            artists.append(line)
            if fill:
                ax.fill_between(curve.x, curve.y, color=c, alpha=0.08 * alpha, linewidth=0)
        elif curve.kind == "singleton":
            stem = ax.vlines(curve.x, 0, curve.y, color=c, linewidth=2.2, linestyle=linestyle,
                             alpha=alpha, label=curve.name)
            ax.plot(curve.x, curve.y, "o", color=c, markersize=5, alpha=alpha)
            artists.append(stem)
        else:
            continue
        if labels:
            ax.text(curve.label_x, LABEL_Y, curve.name, color=c, ha="center", va="bottom",
                    fontsize=9, fontweight="bold", gid="term-label")
    linear = [c for c in plot.curves if c.kind == "linear"]
    if linear:
        text = "\n".join(f"{c.name}: {c.formula}" for c in linear)
        ax.text(0.02, 0.95, "Takagi-Sugeno consequents\n" + text, transform=ax.transAxes,
                va="top", fontsize=8, family="monospace",
                bbox=dict(boxstyle="round", facecolor="white", edgecolor="#cccccc"))
    return artists


def stagger_labels(fig: Figure) -> None:
    """Lift a term label one step where it would overlap the one to its left, measured on the
    laid-out figure (so long names such as MODERATE next to MEDIUM stay readable). The texts
    are made literal first: laying out parses them, and a `$$` in a description is no
    mathtext."""
    literal_text(fig)
    engine = fig.get_layout_engine()
    if engine is not None:
        engine.execute(fig)                     # place the axes as the saved figure has them
    renderer = fig.canvas.get_renderer()     # type: ignore[attr-defined]  # (an Agg canvas)
    for ax in fig.axes:
        labels = sorted((t for t in ax.texts if t.get_gid() == "term-label"),
                        key=lambda t: t.get_position()[0])
        right_edge = [-np.inf, -np.inf]              # per level, in display pixels
        for text in labels:
            box = text.get_window_extent(renderer)
            level = 0 if box.x0 > right_edge[0] + 2 else 1
            if level == 1 and box.x0 <= right_edge[1] + 2:
                level = 0
            right_edge[level] = box.x1
            if level:
                x, y = text.get_position()
                text.set_position((x, y + LABEL_STEP))


def mark_value(ax: Axes, plot: VariablePlot) -> None:
    """The value as a dashed line, its memberships as dots with their numbers."""
    if plot.value is None:
        return
    from matplotlib.patheffects import withStroke

    unit = f" {plot.unit}" if plot.unit else ""
    line = ax.axvline(plot.value, color=VALUE_COLOR, linestyle="--", linewidth=1.2,
                      label=f"{plot.name} = {plot.value:g}{unit}", zorder=5)
    lo, hi = plot.universe
    right = plot.value < lo + 0.8 * (hi - lo)
    names = [c.name for c in plot.curves]
    for term, mu in plot.memberships:
        if not visible(mu):
            continue
        c = color(names.index(term))
        ax.plot([plot.value], [mu], "o", color=c, markeredgecolor="white", markersize=7,
                zorder=6)
        ax.annotate(f"{mu:.2f}", (plot.value, mu), xytext=(6 if right else -6, 0),
                    textcoords="offset points", ha="left" if right else "right",
                    va="center", fontsize=8.5, color=c, fontweight="bold", zorder=7,
                    path_effects=[withStroke(linewidth=3, foreground="white")])
    ax.legend(loc="center right" if right else "center left", fontsize=8, frameon=True,
              handles=[line])


def panel_title(plot: VariablePlot, width: int = 60) -> str:
    """``road (input)`` and the description, wrapped at ``width`` characters."""
    import textwrap

    role = "input" if plot.role == "input" else "output"
    title = f"{plot.name} ({role})"
    if plot.description:
        title += "\n" + textwrap.fill(plot.description, width)
    return title


def draw_panel(ax: Axes, plot: VariablePlot, title_width: int = 60) -> list:
    """One variable on one axes: terms, labels, the marked value and its memberships."""
    style_axes(ax, plot)
    artists = draw_curves(ax, plot)
    mark_value(ax, plot)
    ax.set_title(panel_title(plot, title_width), fontsize=10, loc="left")
    return artists


def draw_sheet(plots: Sequence[VariablePlot], path: str | Path | None = None, *,
               title: str | None = None, show: bool = False, columns: int = 3) -> Figure:
    """All variables on one sheet: inputs in rows of up to ``columns`` panels, outputs on rows
    of their own (the paper's Figures 5-7 above, 8-9 below), each row filling the width.
    Written to ``path`` (.png or .svg) and/or shown; returns the figure."""
    plots = list(plots)
    if not plots:                   # (max() met an empty sequence)
        raise InputError("a sheet draws at least one variable, and none was given",
                         hint="sheet(rulebase) gives every variable's plot")
    if not all(isinstance(p, VariablePlot) for p in plots):     # (an AttributeError)
        wrong = next(p for p in plots if not isinstance(p, VariablePlot))
        raise InputError(f"a sheet draws VariablePlots, not {type(wrong).__name__} "
                         f"`{wrong!r:.40}`", hint="sheet(rulebase) gives every variable's plot")
    if (n := whole_number(columns)) is None or n < 1:
        raise InputError(f"columns is a whole number, 1 or more, not `{columns!r:.40}`")
    rows: list[list[VariablePlot]] = []
    for group in ([p for p in plots if p.role == "input"],
                  [p for p in plots if p.role != "input"]):
        rows += [group[i:i + columns] for i in range(0, len(group), columns)]
    widest = max(len(r) for r in rows)
    span = math.lcm(*(len(r) for r in rows))
    fig = new_figure((4.6 * widest if widest > 1 else 7.5, 3.3 * len(rows) + 0.5), show,
                     layout="constrained")
    grid = fig.add_gridspec(len(rows), span)
    for i, row in enumerate(rows):
        step = span // len(row)
        inches = fig.get_size_inches()[0] / len(row)
        for k, plot in enumerate(row):
            # ~ characters of 10 pt across the axes the title starts over (the panel less
            # its y label and ticks): the panel's whole width ran the third column's past
            # the figure's edge
            draw_panel(fig.add_subplot(grid[i, k * step:(k + 1) * step]), plot,
                       title_width=int((inches - 0.8) * 12.5))
    if title:
        fig.suptitle(title, fontsize=13, fontweight="bold")
    stagger_labels(fig)
    return finish(fig, path, show, tight=False)     # constrained layout sets the margins


def draw_terms_before_after(variable_before: Variable, variable_after: Variable,
                            path: str | Path | None, *, title: str | None = None,
                            show: bool = False) -> Figure:
    """Show how adaptation moved the terms of one variable.

    ``variable_before`` and ``variable_after`` are :class:`mitos_cli.lang.terms.Variable` objects
    of the same variable (e.g. ``loaded.rulebase.variables["road"]`` before and after
    ``teach``); ``path`` is the file to write (``.png`` or ``.svg``, chosen by extension;
    ``None`` writes nothing). Before is drawn dashed and faint, after solid, each term in its
    own colour; terms whose parameters changed are listed under the plot with their old and
    new values (``MEDIUM: peak 70 → 74, width 30 → 34``). Returns the matplotlib figure.
    Raises :class:`mitos_cli.draw.output.DrawError` (a ``MitosError``) for another extension
    or when matplotlib is missing.
    """
    _check_pair(variable_before, variable_after)
    before = variable_plot(variable_before)
    after = variable_plot(variable_after)
    changes = term_changes(variable_before, variable_after)
    fig = new_figure((8.0, 4.2 + 0.22 * len(changes)), show, layout="constrained")
    ax = fig.subplots()
    style_axes(ax, after)
    order = _colour_order(before, after)
    draw_curves(ax, before, colors=[color(order[c.name]) for c in before.curves],
                linestyle="--", alpha=0.55, fill=False, labels=False)
    draw_curves(ax, after, colors=[color(order[c.name]) for c in after.curves])
    stagger_labels(fig)
    from matplotlib.lines import Line2D

    ax.legend(handles=[Line2D([], [], color="#555555", linestyle="--", alpha=0.6,
                              label="before"),
                       Line2D([], [], color="#555555", linestyle="-", label="after")],
              loc="center right", fontsize=8)
    ax.set_title(title or f"{after.name}: terms before and after adaptation", loc="left",
                 fontsize=11)
    if changes:
        ax.text(0.0, -0.2, "changed: " + "\n         ".join(changes), transform=ax.transAxes,
                va="top", fontsize=8, family="monospace")
    return finish(fig, path, show)



def _check_pair(variable_before: Variable, variable_after: Variable) -> None:
    """Refuse anything but one :class:`Variable` twice (None met an AttributeError, and two
    variables were drawn as one moved, without a word)."""
    for given in (variable_before, variable_after):
        if not isinstance(given, Variable):
            raise InputError(f"a variable before and after is a Variable, not "
                             f"{type(given).__name__} `{given!r:.40}`",
                             hint="loaded.rulebase.variables['road'], before and after teach")
    if variable_before.name != variable_after.name:
        raise InputError(f"before and after are two variables, `{variable_before.name}` and "
                         f"`{variable_after.name}`: give the same variable twice")


def term_changes(variable_before: Variable, variable_after: Variable) -> list[str]:
    """One line per term that changed: new, removed, another shape, or its parameters
    (``MEDIUM: peak 70 → 74, width 30 → 34``)."""
    changes = []
    old = {t.name: t for t in variable_before.terms}
    for t in variable_after.terms:
        o = old.get(t.name)
        if o is None:
            changes.append(f"{t.name}: new")
        elif o.shape != t.shape:
            changes.append(f"{t.name}: {o.shape_name} ({o.params_text()}) → {t.shape_name} "
                           f"({t.params_text()})")
        elif o.params != t.params:
            names = t.kind.params if len(t.kind.params) == len(t.params) else \
                tuple(f"p{i + 1}" for i in range(len(t.params)))
            changes.append(f"{t.name}: " + ", ".join(
                f"{n} {a:g} → {b:g}" for n, a, b in zip(names, o.params, t.params) if a != b))
    for name in old:
        if name not in variable_after.term_names:
            changes.append(f"{name}: removed")
    return changes


def _colour_order(before: VariablePlot, after: VariablePlot) -> dict[str, int]:
    """Each term's colour index: a term keeps its colour in both plots (by its place among
    the after-terms; a removed term after them)."""
    order = {c.name: i for i, c in enumerate(after.curves)}
    for c in before.curves:
        order.setdefault(c.name, len(order))
    return order


__all__ = ["draw_sheet", "draw_panel", "draw_terms_before_after"]
