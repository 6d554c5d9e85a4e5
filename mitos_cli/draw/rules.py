"""The rule viewer: one input, every fired rule as a row (MATLAB's ``ruleview``, drawn from a
:class:`~mitos_cli.draw.data.RuleView`).

Columns are the inputs the fired rules test, then the outputs. In a rule's row, an input cell
shows the term the rule tests (after hedges and ``not``) with the part up to its membership
filled and the input value as a red line; the row's label gives the rule's DOF; an output cell
shows the rule's consequent: a stem as high as the DOF at the consequent value (weighted
average), or the rule's consequent set and its implied set (Mamdani). The bottom row shows each
output's aggregate and the crisp result.

Each column of rule rows is one axes, the rows stacked as bands ``[k, k + 1)`` from the top
(one axes per cell would cost a second per 40 cells in tick layout alone); the bottom row has
an axes per column with the scales. Artists carry ``gid`` ``"<label>:<variable>"`` (rows) and
``"aggregate:<output>"`` so tests can find what was drawn.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from ..numbers import whole_number
from ..words import plural
from .data import OutputView, RuleRow, RuleView
from .output import finish, new_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from .data.ruleviews import InputValue

TERM_COLOR = "#1f77b4"
FILL_COLOR = "#f2b134"
OUT_COLOR = "#2a9d8f"
VALUE_COLOR = "#d62728"
MAX_ROWS = 30
BAND = 0.8          # a row's curves span [base, base + BAND]; the rest is the gap to the next
ROW_INCHES = 0.62
GAP_INCHES = 0.34   # between the last rule and the aggregates
LABEL_PAD = 6.0     # pt between a row's label and its first cell
LABEL_SIZE = 8      # pt, the row labels and "aggregate"


def _bare(ax: Axes) -> None:
    ax.set_yticks([])
    for side in ("top", "right", "left"):
        ax.spines[side].set_visible(False)


def _label(ax: Axes, x: float, y: float, text: str) -> None:
    """A cell's caption at its top left (``x`` in axes fraction, ``y`` in data)."""
    ax.text(x, y, text, transform=ax.get_yaxis_transform(), fontsize=7, va="top",
            color="#333333", zorder=10,
            bbox=dict(boxstyle="square,pad=0.1", facecolor="white", edgecolor="none",
                      alpha=0.75))


def draw_antecedent(ax: Axes, base: float, row: RuleRow, var: str) -> None:
    """The propositions of ``row`` on ``var`` in the band at ``base``: each term curve, filled
    up to its membership (after hedges and ``not``)."""
    props = [p for p in row.props if p.var == var]
    for p in props:
        gid = f"{row.label}:{var}"
        ax.plot(p.x, base + BAND * p.y, color=TERM_COLOR, linewidth=1.2, gid=gid)
        x, y = clipped(p.x, p.y, p.value)
        ax.fill_between(x, base, base + BAND * y, color=FILL_COLOR, alpha=0.75, linewidth=0,
                        gid=gid)
    if props:
        _label(ax, 0.02, base + BAND + 0.12,
               " / ".join(f"{' '.join(('not',) * p.negated + p.hedges + (p.term,))} "
                          f"{p.value:.2f}" for p in props))


def clipped(x: np.ndarray, y: np.ndarray, level: float) -> tuple[np.ndarray, np.ndarray]:
    """The curve ``(x, y)`` cut at ``level``: what lies under both. The curve is sampled at
    its breakpoints only, so ``min(y, level)`` on those samples joined the foot of a shoulder
    to its top at ``level``: the term *scaled* by the membership, not filled up to it as the
    docs say. The points where the curve crosses ``level`` are inserted first."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    d = y - level
    k = np.flatnonzero(d[:-1] * d[1:] < 0)           # a crossing inside segment k
    t = d[k] / (d[k] - d[k + 1])
    xs = np.insert(x, k + 1, x[k] + t * (x[k + 1] - x[k]))
    ys = np.insert(y, k + 1, level)
    return xs, np.minimum(ys, level)


def spikes(grid: np.ndarray, y: np.ndarray, cells: int = 3) -> list[tuple[float, float]] | None:
    """``(x, height)`` of each run of nonzero samples when every run is at most ``cells``
    long: a Mamdani set made of singletons, which the engine samples as one-cell spikes and
    which reads better as stems. ``None`` for a set with any wider part."""
    on = np.concatenate([[False], y > 0, [False]])
    edges = np.flatnonzero(np.diff(on.astype(np.int8)))
    starts, ends = edges[::2], edges[1::2]
    if len(starts) == 0 or np.any(ends - starts > cells):
        return None
    peaks = [a + int(np.argmax(y[a:b])) for a, b in zip(starts, ends)]
    return [(float(grid[k]), float(y[k])) for k in peaks]


def draw_consequent(ax: Axes, base: float, row: RuleRow, out: OutputView) -> None:
    """The consequent of ``row`` for ``out`` in the band at ``base``."""
    for c in (c for c in row.consequents if c.output == out.name):
        gid = f"{row.label}:{out.name}"
        name = " ".join(c.hedges + (c.term,)) if c.term else f"{c.value:g}"
        sets = ((out.grid, c.full, c.implied) if out.grid is not None and c.full is not None
                and c.implied is not None else None)      # Mamdani: the consequent's sets
        if sets is not None and spikes(sets[0], sets[1]) is not None:
            # a singleton: its full height dotted, the implied height as a stem
            top = float(np.max(sets[2]))
            ax.vlines([c.value], base, base + BAND, color=TERM_COLOR, linewidth=1.0,
                      linestyles=":", gid=gid)
            ax.vlines([c.value], base, base + BAND * top, color=OUT_COLOR, linewidth=2.4,
                      gid=gid)
            ax.plot([c.value], [base + BAND * top], "o", color=OUT_COLOR, markersize=3.5)
            if c.term:
                name += f" ({c.value:g})"
        elif sets is not None:
            grid, full, implied = sets
            ax.plot(grid, base + BAND * full, color=TERM_COLOR, linewidth=1.0, gid=gid)
            ax.fill_between(grid, base, base + BAND * implied, color=OUT_COLOR,
                            alpha=0.7, linewidth=0, gid=gid)
        else:
            ax.vlines([c.value], base, base + BAND * row.dof, color=OUT_COLOR, linewidth=2.4,
                      gid=gid)
            ax.plot([c.value], [base + BAND * row.dof], "o", color=OUT_COLOR, markersize=3.5)
            if c.term:
                name += f" ({c.value:g})"
        _label(ax, 0.02, base + BAND + 0.12, name)


def draw_aggregate(ax: Axes, out: OutputView) -> None:
    """An output's aggregate (summed DOFs or aggregated set) and its crisp result."""
    lo, hi = out.universe
    gid = f"aggregate:{out.name}"
    stems = (spikes(out.grid, out.aggregate)
             if out.aggregate is not None and out.grid is not None else None)
    # `aggregation = sum` may lift the set above 1: the axis grows with it
    tall = max(1.0, float(np.nanmax(out.aggregate, initial=0.0))) if out.aggregate is not None \
        else 1.0
    if stems is not None:                    # Mamdani over singletons: the heights as stems
        for v, w in stems:
            ax.vlines([v], 0, [w], color=OUT_COLOR, linewidth=2.4, gid=gid)
            ax.text(v, w + 0.03, f"{w:.2f}", fontsize=6.5, ha="center", va="bottom",
                    color="#333333")
        ax.set_ylim(0, 1.25 * tall)
    elif out.aggregate is not None and out.grid is not None:
        ax.fill_between(out.grid, out.aggregate, color=OUT_COLOR, alpha=0.7, linewidth=0,
                        gid=gid)
        ax.plot(out.grid, out.aggregate, color=OUT_COLOR, linewidth=0.8, gid=gid)
        ax.set_ylim(0, 1.12 * tall)
    else:
        top = max((w for _, w in out.stems), default=1.0)
        # summed DOFs, scaled so the tallest stem fills the cell (its value is printed)
        for v, w in out.stems:
            ax.vlines([v], 0, [w / top], color=OUT_COLOR, linewidth=2.4, gid=gid)
            ax.text(v, w / top + 0.03, f"{w:.2f}", fontsize=6.5, ha="center", va="bottom",
                    color="#333333")
        ax.set_ylim(0, 1.45)                 # room for the summed DOFs under the title
    unit = f" {out.unit}" if out.unit else ""
    if np.isnan(out.value):
        ax.text(0.5, 0.5, "no rule fired,\n" + ("default nan" if out.nan_default else "no default"),
                transform=ax.transAxes, fontsize=8,
                ha="center", va="center", color=VALUE_COLOR)
    else:
        ax.axvline(out.value, color=VALUE_COLOR, linewidth=1.6, gid=f"result:{out.name}")
        how = " (default)" if out.defaulted else ""
        ax.set_title(f"{out.name} = {out.value:.1f}{unit}{how}", fontsize=8.5,
                     color=VALUE_COLOR, pad=2)
    pad = 0.03 * (hi - lo)
    ax.set_xlim(lo - pad, hi + pad)
    ax.set_xlabel(out.label, fontsize=8)


def draw_rules(view: RuleView, path: str | Path | None = None, *, title: str | None = None,
               show: bool = False, max_rows: int = MAX_ROWS) -> Figure:
    """Draw the rule viewer to ``path`` (.png/.svg) and/or a window; returns the figure.

    With more than ``max_rows`` fired rules the strongest ``max_rows`` are drawn (in
    rule-base order) and the title says how many were left out."""
    if not isinstance(view, RuleView):          # (None met an AttributeError)
        raise InputError(f"draw_rules draws a RuleView, not {type(view).__name__}",
                         hint="rule_view(compiled, values) from mitos_cli.draw.data makes one")
    # ("x" and 2.5 met TypeErrors inside; 0 and -1 were taken without a word)
    if (most := whole_number(max_rows)) is None or most < 1:
        raise InputError(f"max_rows is a whole number, 1 or more, not `{max_rows!r:.40}`",
                         hint=f"max_rows={MAX_ROWS}, as --max-rules")
    rows, hidden = _strongest(list(view.rows), most)
    used = {p.var for r in rows for p in r.props}
    inputs = [i for i in view.inputs if i.name in used] or list(view.inputs)
    outputs = list(view.outputs)
    ncols = len(inputs) + len(outputs)
    n = max(len(rows), 1)
    height = 1.6 + ROW_INCHES * (n + 1.3)
    width = 1.4 + 2.3 * ncols
    fig = new_figure((width, height), show)
    # a fixed gap between the rules and the aggregates (room for the results' titles),
    # whatever the number of rows: gridspec's hspace is a fraction of the mean axes height
    span = height - 0.75 - 0.55
    left = _left_margin([_row_label(r) for r in rows], width)
    grid = fig.add_gridspec(2, ncols, height_ratios=(n, 1.3), left=left, right=0.98,
                            top=1 - 0.75 / height, bottom=0.55 / height,
                            hspace=2 * GAP_INCHES / (span - GAP_INCHES), wspace=0.12)
    bases = [n - 1 - k for k in range(len(rows))]          # first rule on top
    for k, inp in enumerate(inputs):
        _input_column(fig.add_subplot(grid[0, k]), inp, rows, bases, n, first=k == 0)
    for j, out in enumerate(outputs):
        _output_column(fig.add_subplot(grid[0, len(inputs) + j]), out, rows, bases, n)
    # bottom row: the input axes' scales, then the outputs' aggregates and results
    for k, inp in enumerate(inputs):
        _input_scale(fig.add_subplot(grid[1, k]), inp, first=k == 0)
    for j, out in enumerate(outputs):
        ax = fig.add_subplot(grid[1, len(inputs) + j])
        _bare(ax)
        ax.tick_params(axis="x", labelsize=7, length=2)
        draw_aggregate(ax, out)
    heading = title or (f"Rule viewer: {len(view.rows)} of {plural(view.n_rules, 'rule')} fired "
                        f"(behavior {view.behavior})")
    if hidden:
        heading += f"; the {hidden} weakest not shown"
    fig.suptitle(heading, fontsize=11, x=0.02, y=1 - 0.2 / height, ha="left")
    return finish(fig, path, show, tight=False)       # margins are set above


def _row_label(row: RuleRow) -> str:
    """A row's label: the rule and its DOF (split where weights and contexts scale it)."""
    return f"{row.label}\n" + row.dof_text.replace(" = ", "\n= ")


def _text_inches(text: str, weight: str = "normal") -> float:
    """The width of ``text`` (its widest line) at the labels' size, in inches."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextToPath

    font = FontProperties(size=LABEL_SIZE, weight=weight)
    return max(TextToPath().get_text_width_height_descent(line, font, ismath=False)[0]
               for line in text.split("\n")) / 72


def _left_margin(labels: list[str], width: float) -> float:
    """The figure fraction left of the first column that holds the widest row label and
    "aggregate" (a fraction of the figure's width cut `DOF` to `OOF` and `aggregate` to
    `gregate` in a narrow figure), and never less than it was (0.11)."""
    need = max([_text_inches("aggregate", "bold")] + [_text_inches(t) for t in labels])
    return max(0.11, (need + LABEL_PAD / 72 + 0.12) / width)


def _strongest(rows: list, max_rows: int) -> tuple[list, int]:
    """The ``max_rows`` rows of the largest DOFs, in rule-base order, and how many are left
    out."""
    if len(rows) <= max_rows:
        return rows, 0
    keep = sorted(sorted(range(len(rows)), key=lambda i: -rows[i].dof)[:max_rows])
    return [rows[i] for i in keep], len(rows) - max_rows


def _input_column(ax: Axes, inp: InputValue, rows: list, bases: list[int], n: int, first: bool) -> None:
    """An input's column: each rule's antecedent term on its row, the input's value across;
    the first column also labels the rows with the rules and their DOFs."""
    _bare(ax)
    ax.set_xticks([])
    ax.spines["bottom"].set_visible(False)
    ax.set_xlim(*inp.universe)
    ax.set_ylim(-0.05, n + 0.05)
    for base, row in zip(bases, rows):
        ax.axhline(base, color="black", linewidth=0.8)
        draw_antecedent(ax, base, row, inp.name)
        if first:
            ax.annotate(_row_label(row), (0, base + BAND / 2),
                        xycoords=ax.get_yaxis_transform(), xytext=(-LABEL_PAD, 0),
                        textcoords="offset points", ha="right", va="center",
                        fontsize=LABEL_SIZE)
    ax.axvline(inp.value, color=VALUE_COLOR, linewidth=1.1)
    unit = f" {inp.unit}" if inp.unit else ""
    ax.set_title(f"{inp.name} = {inp.value:g}{unit}", fontsize=9, pad=3)
    if not rows and first:
        ax.text(0.02, 0.5, "no rule fired", transform=ax.transAxes, fontsize=9)


def _output_column(ax: Axes, out: OutputView, rows: list, bases: list[int], n: int) -> None:
    """An output's column: each rule's consequent, clipped by its DOF, on its row."""
    _bare(ax)
    ax.set_xticks([])
    ax.spines["bottom"].set_visible(False)
    lo, hi = out.universe
    pad = 0.03 * (hi - lo)
    ax.set_xlim(lo - pad, hi + pad)
    ax.set_ylim(-0.05, n + 0.05)
    for base, row in zip(bases, rows):
        ax.axhline(base, color="black", linewidth=0.8)
        draw_consequent(ax, base, row, out)
    ax.set_title(out.name, fontsize=9, pad=3)


def _input_scale(ax: Axes, inp: InputValue, first: bool) -> None:
    """Under an input's column, its scale and value (the first labels the row)."""
    _bare(ax)
    ax.tick_params(axis="x", labelsize=7, length=2)
    ax.set_xlim(*inp.universe)
    ax.axvline(inp.value, color=VALUE_COLOR, linewidth=1.1)
    unit = f" [{inp.unit}]" if inp.unit else ""
    ax.set_xlabel(f"{inp.name}{unit}", fontsize=8)
    if first:
        ax.annotate("aggregate", (0, 0.5), xycoords="axes fraction", xytext=(-LABEL_PAD, 0),
                    textcoords="offset points", ha="right", va="center", fontsize=LABEL_SIZE,
                    fontweight="bold")
