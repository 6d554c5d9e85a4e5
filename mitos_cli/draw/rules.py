"""The rule viewer: one input, every fired rule as a row (MATLAB's ``ruleview``, drawn from a
:class:`~mitos_cli.plotdata.RuleView`).

Columns are the inputs the fired rules test, then the outputs. In a rule's row, an input cell
shows the term the rule tests (after hedges and ``not``) with the part up to its membership
filled and the input value as a red line; the row's label gives the rule's DOF; an output cell
shows the rule's consequent: a stem as high as the DOF at the consequent value (weighted
average), or the rule's implied fuzzy set (Mamdani). The bottom row shows each output's
aggregate and the crisp result.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..plotdata import OutputView, RuleRow, RuleView
from .output import finish, new_figure

TERM_COLOR = "#1f77b4"
FILL_COLOR = "#f2b134"
OUT_COLOR = "#2a9d8f"
VALUE_COLOR = "#d62728"
MAX_ROWS = 30


def _clean(ax, bottom: bool) -> None:
    ax.set_ylim(0, 1.12)
    ax.set_yticks([])
    for side in ("top", "right", "left"):
        ax.spines[side].set_visible(False)
    ax.tick_params(axis="x", labelsize=7, length=2, labelbottom=bottom)


def draw_antecedent(ax, row: RuleRow, var: str, value: float, universe) -> None:
    """The propositions of ``row`` on ``var``: term curve, filled up to the membership."""
    props = [p for p in row.props if p.var == var]
    for p in props:
        ax.plot(p.x, p.y, color=TERM_COLOR, linewidth=1.2)
        ax.fill_between(p.x, np.minimum(p.y, p.value), color=FILL_COLOR, alpha=0.75,
                        linewidth=0)
    ax.axvline(value, color=VALUE_COLOR, linewidth=1.1)
    ax.set_xlim(*universe)
    _label(ax, " / ".join(f"{' '.join(('not',) * p.negated + p.hedges + (p.term,))} "
                          f"{p.value:.2f}" for p in props))


def _label(ax, text: str) -> None:
    ax.text(0.02, 0.97, text, transform=ax.transAxes, fontsize=7, va="top", color="#333333",
            bbox=dict(boxstyle="square,pad=0.1", facecolor="white", edgecolor="none",
                      alpha=0.75), zorder=10)


def draw_consequent(ax, row: RuleRow, out: OutputView) -> None:
    cons = [c for c in row.consequents if c.output == out.name]
    lo, hi = out.universe
    for c in cons:
        name = " ".join(c.hedges + (c.term,)) if c.term else f"{c.value:g}"
        if c.implied is not None and out.grid is not None:
            ax.plot(out.grid, c.full, color=TERM_COLOR, linewidth=1.0)
            ax.fill_between(out.grid, c.implied, color=OUT_COLOR, alpha=0.7, linewidth=0)
            ax.plot(out.grid, c.implied, color=OUT_COLOR, linewidth=0.8)
        else:
            ax.vlines([c.value], 0, [row.dof], color=OUT_COLOR, linewidth=2.4)
            ax.plot([c.value], [row.dof], "o", color=OUT_COLOR, markersize=3.5)
            if c.term:
                name += f" ({c.value:g})"
        _label(ax, name)
    pad = 0.03 * (hi - lo)
    ax.set_xlim(lo - pad, hi + pad)


def draw_aggregate(ax, out: OutputView) -> None:
    lo, hi = out.universe
    if out.aggregate is not None and out.grid is not None:
        ax.fill_between(out.grid, out.aggregate, color=OUT_COLOR, alpha=0.7, linewidth=0)
        ax.plot(out.grid, out.aggregate, color=OUT_COLOR, linewidth=0.8)
        top = 1.0
    else:
        top = max((w for _, w in out.stems), default=1.0)
        # summed DOFs, scaled so the tallest stem fills the cell (its value is printed)
        for v, w in out.stems:
            ax.vlines([v], 0, [0.75 * w / top], color=OUT_COLOR, linewidth=2.4)
            ax.text(v, 0.75 * w / top + 0.03, f"{w:.2f}", fontsize=6.5, ha="center",
                    va="bottom", color="#333333")
    unit = f" {out.unit}" if out.unit else ""
    if np.isnan(out.value):
        ax.text(0.5, 0.5, "no rule fired,\nno default", transform=ax.transAxes, fontsize=8,
                ha="center", va="center", color=VALUE_COLOR)
    else:
        ax.axvline(out.value, color=VALUE_COLOR, linewidth=1.6)
        how = " (default)" if out.defaulted else ""
        ax.set_title(f"{out.name} = {out.value:.1f}{unit}{how}", fontsize=8.5,
                     color=VALUE_COLOR, pad=2)
    pad = 0.03 * (hi - lo)
    ax.set_xlim(lo - pad, hi + pad)
    ax.set_xlabel(out.label, fontsize=8)


def draw_rules(view: RuleView, path: str | Path | None = None, *, title: str | None = None,
               show: bool = False, max_rows: int = MAX_ROWS):
    """Draw the rule viewer to ``path`` (.png/.svg) and/or a window; returns the figure.

    With more than ``max_rows`` fired rules the strongest ``max_rows`` are drawn (in
    rule-base order) and the title says how many were left out."""
    rows = list(view.rows)
    hidden = 0
    if len(rows) > max_rows:
        keep = sorted(sorted(range(len(rows)), key=lambda i: -rows[i].dof)[:max_rows])
        hidden = len(rows) - max_rows
        rows = [rows[i] for i in keep]
    used = {p.var for r in rows for p in r.props}
    inputs = [i for i in view.inputs if i.name in used] or list(view.inputs)
    outputs = list(view.outputs)
    ncols = len(inputs) + len(outputs)
    nrows = len(rows) + 1
    fig = new_figure((1.4 + 2.3 * ncols, 1.4 + 0.62 * nrows), show)
    grid = fig.add_gridspec(nrows, ncols, left=0.11, right=0.98, top=1 - 0.9 / (1.4 + 0.62 * nrows),
                            bottom=0.5 / (1.4 + 0.62 * nrows) + 0.02, hspace=0.35, wspace=0.12)
    universes = {i.name: i.universe for i in inputs}
    for r, row in enumerate(rows):
        for k, inp in enumerate(inputs):
            ax = fig.add_subplot(grid[r, k])
            _clean(ax, bottom=False)
            if any(p.var == inp.name for p in row.props):
                draw_antecedent(ax, row, inp.name, inp.value, universes[inp.name])
            else:
                ax.set_xlim(*universes[inp.name])
                ax.axvline(inp.value, color=VALUE_COLOR, linewidth=0.6, alpha=0.4)
            if r == 0:
                unit = f" {inp.unit}" if inp.unit else ""
                ax.set_title(f"{inp.name} = {inp.value:g}{unit}", fontsize=9, pad=3)
            if k == 0:
                ax.text(-0.08, 0.5, f"{row.label}\nDOF {row.dof:.2f}", transform=ax.transAxes,
                        ha="right", va="center", fontsize=8)
        for j, out in enumerate(outputs):
            ax = fig.add_subplot(grid[r, len(inputs) + j])
            _clean(ax, bottom=False)
            draw_consequent(ax, row, out)
            if r == 0:
                ax.set_title(out.name, fontsize=9, pad=3)
    # bottom row: the input axes' scales, then the outputs' aggregates and results
    for k, inp in enumerate(inputs):
        ax = fig.add_subplot(grid[nrows - 1, k])
        _clean(ax, bottom=True)
        ax.set_xlim(*universes[inp.name])
        ax.axvline(inp.value, color=VALUE_COLOR, linewidth=1.1)
        unit = f" [{inp.unit}]" if inp.unit else ""
        ax.set_xlabel(f"{inp.name}{unit}", fontsize=8)
        if k == 0:
            ax.text(-0.08, 0.5, "aggregate", transform=ax.transAxes, ha="right",
                    va="center", fontsize=8, fontweight="bold")
        if not rows and k == 0:
            ax.text(0.02, 0.5, "no rule fired", transform=ax.transAxes, fontsize=8)
    for j, out in enumerate(outputs):
        ax = fig.add_subplot(grid[nrows - 1, len(inputs) + j])
        _clean(ax, bottom=True)
        draw_aggregate(ax, out)
    heading = title or (f"Rule viewer: {len(view.rows)} of {view.n_rules} rules fired "
                        f"(behavior {view.behavior})")
    if hidden:
        heading += f"; the {hidden} weakest not shown"
    fig.suptitle(heading, fontsize=11, x=0.02, ha="left")
    return finish(fig, path, show)
