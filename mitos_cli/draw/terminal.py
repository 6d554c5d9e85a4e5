"""Pictures in the terminal, for users over SSH: membership plots in Unicode Braille, the rule
viewer as bars, a control surface as a table. No matplotlib here.

A Braille character is a 2 x 4 grid of dots, so a plot ``cols`` characters wide and ``rows``
high has ``2 cols x 4 rows`` dots. Curves are drawn column by column and joined vertically, so
steep edges stay connected. With ``color=True`` each character takes the ANSI colour of the
term that owns most of its dots.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

import numpy as np

from ..words import plural
from .data import RuleView, Surface, TermCurve, VariablePlot, visible

if TYPE_CHECKING:
    from .data.ruleviews import ConsequentView, OutputView

BRAILLE = 0x2800
#: dot (row, column) inside a cell -> bit of the Braille code point
DOT_BITS = ((0x01, 0x08), (0x02, 0x10), (0x04, 0x20), (0x40, 0x80))
#: ANSI colours of successive terms (bright, readable on dark and light backgrounds)
PALETTE = (34, 31, 32, 35, 33, 36, 94, 91, 92, 95)
RESET = "\x1b[0m"
#: the owner tag of the dotted line that marks a value (drawn grey)
VALUE_TAG = 999


def _paint(text: str, code: int | None, color: bool) -> str:
    return f"\x1b[{code}m{text}{RESET}" if color and code is not None else text


class Canvas:
    """A Braille dot canvas: ``owner[row, col]`` is the term index of each dot (-1 = empty)."""

    def __init__(self, cols: int, rows: int) -> None:
        self.cols, self.rows = cols, rows
        self.owner = np.full((rows * 4, cols * 2), -1, dtype=int)

    @property
    def width(self) -> int:
        return self.cols * 2

    @property
    def height(self) -> int:
        return self.rows * 4

    def column(self, col: int, top: int, bottom: int, tag: int) -> None:
        """Set dots ``top .. bottom`` (inclusive, any order) of one dot column."""
        if 0 <= col < self.width:
            lo, hi = sorted((top, bottom))
            self.owner[max(lo, 0):min(hi, self.height - 1) + 1, col] = tag

    def lines(self, color: bool = False) -> list[str]:
        out = []
        for r in range(self.rows):
            cells = []
            for c in range(self.cols):
                block = self.owner[r * 4:r * 4 + 4, c * 2:c * 2 + 2]
                code = BRAILLE
                for dy in range(4):
                    for dx in range(2):
                        if block[dy, dx] >= 0:
                            code |= DOT_BITS[dy][dx]
                ch = chr(code) if code != BRAILLE else " "
                tags = block[block >= 0]
                tag = int(np.bincount(tags).argmax()) if tags.size else None
                code_ = None if tag is None else 90 if tag == VALUE_TAG else \
                    PALETTE[tag % len(PALETTE)]
                cells.append(_paint(ch, code_, color))
            out.append("".join(cells))
        return out


def _to_dot_row(mu: np.ndarray, height: int) -> np.ndarray:
    """Membership 0..1 -> dot row (0 at the top); NaN (a formula term's, `sqrt(x - 6)` below
    6) -> ``height``, below the canvas: nothing is drawn there."""
    rows = np.full(mu.shape, height)
    finite = np.isfinite(mu)
    rows[finite] = np.rint((1.0 - np.clip(mu[finite], 0.0, 1.0)) * (height - 1))
    return rows


def _dot_x(plot: VariablePlot, width: int) -> np.ndarray:
    lo, hi = plot.universe
    return lo + (np.arange(width) + 0.5) / width * (hi - lo)


def _col_of(x: float, plot: VariablePlot, width: int) -> int:
    lo, hi = plot.universe
    return int(min(max(np.floor((x - lo) / (hi - lo) * width), 0), width - 1))


def _draw_curve(canvas: Canvas, plot: VariablePlot, curve: TermCurve, tag: int) -> None:
    if curve.kind == "singleton":
        col = _col_of(curve.center, plot, canvas.width)
        canvas.column(col, 0, canvas.height - 1, tag)
        return
    if curve.kind != "curve":
        return
    xs = _dot_x(plot, canvas.width)
    # a vertical edge between two dot columns must not be lost: sample both column edges too
    lo, hi = plot.universe
    step = (hi - lo) / canvas.width
    ys = np.interp(xs, curve.x, curve.y)
    left = np.interp(xs - step / 2, curve.x, curve.y)
    right = np.interp(xs + step / 2, curve.x, curve.y)
    rows, rl, rr = (_to_dot_row(v, canvas.height) for v in (ys, left, right))
    for c in range(canvas.width):
        drawn = [r for r in (rows[c], rl[c], rr[c]) if r < canvas.height]
        if drawn:
            canvas.column(c, min(drawn), max(drawn), tag)


def _label_lines(items: list[tuple[int, str, int]], width: int, color: bool) -> list[str]:
    """Place labels centred at character columns, on as many lines as overlaps need."""
    lines: list[list[tuple[int, str, int]]] = []
    for col, text, tag in sorted(items):
        start = min(max(col - len(text) // 2, 0), max(width - len(text), 0))
        for line in lines:
            if all(start > s + len(t) or start + len(text) < s for s, t, _ in line):
                line.append((start, text, tag))
                break
        else:
            lines.append([(start, text, tag)])
    out = []
    for line in reversed(lines):           # the first line sits closest to the plot
        text, pos = "", 0
        for start, label, tag in sorted(line):
            text += " " * (start - pos) + _paint(label, PALETTE[tag % len(PALETTE)], color)
            pos = start + len(label)
        out.append(text)
    return out


def _ticks(lo: float, hi: float, width: int) -> list[float]:
    """Round tick values across the universe (about one per 12 columns); never ``-0`` (the
    first tick of a universe from -8 was ``ceil(-0.8) * 10``, a negative zero)."""
    n = max(2, width // 12)
    raw = (hi - lo) / n
    mag = 10 ** np.floor(np.log10(raw))
    step = min((s * mag for s in (1, 2, 2.5, 5, 10) if s * mag >= raw), default=raw)
    first = np.ceil(lo / step) * step
    return [float(t) + 0.0 for t in np.arange(first, hi + step * 1e-9, step)]


def render_variable(plot: VariablePlot, width: int = 72, height: int = 6,
                    color: bool = False) -> str:
    """One variable's terms as a Braille plot with labels, axes and the marked value."""
    margin = 5                               # "1.0 ┤"
    cols = max(width - margin, 20)
    canvas = Canvas(cols, height)
    for tag, curve in enumerate(plot.curves):
        _draw_curve(canvas, plot, curve, tag)
    value_col = None
    if plot.value is not None:
        value_col = _col_of(plot.value, plot, canvas.width)
        col_dots = canvas.owner[:, value_col]
        empty = col_dots < 0
        marks = np.zeros(canvas.height, dtype=bool)
        marks[::2] = True
        col_dots[empty & marks] = VALUE_TAG          # a dotted line where no curve is

    head = f"{plot.name}"
    if plot.description:
        head += f": {plot.description}"
    if plot.unit:
        head += f" [{plot.unit}]"
    out = [head]
    labels = []
    for tag, curve in enumerate(plot.curves):
        if curve.kind in ("curve", "singleton"):
            labels.append((_col_of(curve.label_x, plot, canvas.width) // 2, curve.name, tag))
    out += [" " * margin + line for line in _label_lines(labels, cols, color)]
    body = canvas.lines(color)
    for r, line in enumerate(body):
        tick = {0: "1.0", height - 1: "0.0"}.get(r, "0.5" if r == (height - 1) // 2 else "")
        out.append(f"{tick:>3} {'┤' if tick else '│'}{line}")
    # x axis with round ticks
    lo, hi = plot.universe
    axis = ["─"] * cols
    ticks = _ticks(lo, hi, cols)
    tick_cols = [min(int((t - lo) / (hi - lo) * cols), cols - 1) for t in ticks]
    for c in tick_cols:
        axis[c] = "┬"
    out.append(" " * (margin - 1) + "└" + "".join(axis))
    numbers = [" "] * (cols + 8)
    for t, c in zip(ticks, tick_cols):
        text = f"{t:g}"
        start = max(0, min(c - len(text) // 2, cols - len(text)))
        if all(ch == " " for ch in numbers[max(start - 1, 0):start + len(text) + 1]):
            numbers[start:start + len(text)] = list(text)
    out.append(" " * margin + "".join(numbers).rstrip())
    if value_col is not None:
        marker = [" "] * cols
        marker[value_col // 2] = "▲"
        out.append(" " * margin + "".join(marker).rstrip())
        unit = f" {plot.unit}" if plot.unit else ""
        shown = ", ".join(f"{t} {mu:.2f}" for t, mu in plot.memberships if visible(mu))
        note = " (clamped to its universe)" if plot.clamped else ""
        line = f"{plot.name} = {plot.value:g}{unit}{note}"
        if plot.role == "input" or shown:
            line += f": {shown or 'no term holds it (all memberships 0)'}"
        out.append(" " * margin + line)
    for curve in (c for c in plot.curves if c.kind == "linear"):
        out.append(f"{' ' * margin}{curve.name}: {curve.formula} (Takagi-Sugeno, no membership curve)")
    return "\n".join(out)


def render_sheet(plots: tuple[VariablePlot, ...], width: int = 72, height: int = 6,
                 color: bool = False) -> str:
    return "\n\n".join(render_variable(p, width, height, color) for p in plots)


# ---------------------------------------------------------------- rule viewer


def _bar(value: float, width: int = 10) -> str:
    """A horizontal bar of eighths: 0.73 -> ███████▎."""
    eighths = int(round(max(0.0, min(1.0, value)) * width * 8))
    full, part = divmod(eighths, 8)
    text = "█" * full + ("" if part == 0 else chr(0x2590 - part))
    return text.ljust(width)


def _consequent_text(c: ConsequentView) -> str:
    if c.term is None:
        return f"{c.output} is {c.value:g}"
    text = f"{c.output} is {' '.join(c.hedges + (c.term,))}"
    return text if c.implied is not None else f"{text} ({c.value:g})"


def render_rule_view(view: RuleView, width: int = 72, color: bool = False) -> str:
    """The rule viewer as text: one block per fired rule with a bar per membership and DOF."""
    out = [f"behavior {view.behavior} ({plural(view.n_rules, 'rule')}; {view.operators})", ""]
    for i in view.inputs:
        unit = f" {i.unit}" if i.unit else ""
        mus = ", ".join(f"{t} {mu:.2f}" for t, mu in i.memberships if visible(mu))
        out.append(f"  {i.name} = {i.value:g}{unit}: {mus or 'no term holds it'}"
                   + (" (clamped to its universe)" if i.clamped else ""))
    out += ["", f"rules fired ({len(view.rows)} of {view.n_rules}):"]
    tw = max((len(p.text) for r in view.rows for p in r.props), default=0)
    lw = max((len(r.label) for r in view.rows), default=0)
    dw = max((len(r.dof_text) for r in view.rows), default=0)
    for row in view.rows:
        cons = " and ".join(_consequent_text(c) for c in row.consequents)
        out.append(f"  {row.label.ljust(lw)}  {row.dof_text.ljust(dw)} {_bar(row.dof)}  "
                   f"then {cons}")
        for p in row.props:
            out.append(f"  {' ' * lw}    {p.text.ljust(tw)}  {p.value:.2f} {_bar(p.value)}")
    if not view.rows:
        out.append("  (none)")
    out += ["", "outputs:"]
    for o in view.outputs:
        unit = f" {o.unit}" if o.unit else ""
        if np.isnan(o.value):
            out.append(f"  {o.name}: no rule fired and "
                       f"{'its default is nan' if o.nan_default else 'it has no default'}")
            continue
        how = " (no rule fired: its default)" if o.defaulted else ""
        out.append(f"  {o.name} = {o.value:.2f}{unit}{how}")
        if o.aggregate is not None:
            out.append(_aggregate_plot(o, width, color))
        top = max((w for _, w in o.stems), default=1.0)
        for v, w in o.stems:
            out.append(f"    {v:8.2f}{unit}  summed DOF {w:.2f} {_bar(w / top)}")
    return "\n".join(out)


def _aggregate_plot(o: OutputView, width: int, color: bool) -> str:
    """A Mamdani output's aggregated set as a small Braille plot with the result marked."""
    grid, aggregate = cast(np.ndarray, o.grid), cast(np.ndarray, o.aggregate)    # (Mamdani's)
    curve = TermCurve("aggregate", "curve", grid, aggregate, o.value, o.value)
    plot = VariablePlot(o.name, "output", o.unit, "", o.universe, (curve,), o.value)
    lines = render_variable(plot, width=width - 4, height=5, color=color).splitlines()
    return "\n".join("    " + line for line in lines[2:-1])   # no heading, labels, value line


# ---------------------------------------------------------------- surfaces as tables


def render_surface(s: Surface, max_cols: int = 11, max_rows: int = 11) -> str:
    """A control surface as a table of output values on a coarse grid (``-``: no rule fires).

    The full-resolution grid is subsampled evenly (ends included)."""
    def pick(n: int, k: int) -> np.ndarray:
        return np.unique(np.rint(np.linspace(0, n - 1, min(n, k))).astype(int))

    def fmt(v: float) -> str:
        return "-" if np.isnan(v) else f"{v:.1f}"

    title = f"{s.label} (behavior {s.behavior}"
    title += f"; {s.fixed_text})" if s.fixed else ")"
    lines = [title]
    xi = pick(len(s.x.values), max_cols)
    if s.y is None:
        rows = [(f"{s.x.values[i]:g}", fmt(s.z[i])) for i in xi]
        w0 = max(len(s.x.label), *(len(a) for a, _ in rows))
        w1 = max(len(s.output), *(len(b) for _, b in rows))   # right-aligned, as the x column
        lines.append(f"{s.x.label:>{w0}}  {s.output:>{w1}}")
        lines += [f"{a:>{w0}}  {b:>{w1}}" for a, b in rows]
        return "\n".join(lines)
    yi = pick(len(s.y.values), max_rows)
    head = [f"{s.x.values[i]:g}" for i in xi]
    cells = [[fmt(s.z[j, i]) for i in xi] for j in yi]
    w = max(max(len(h) for h in head), max(len(c) for row in cells for c in row))
    ylabels = [f"{s.y.values[j]:g}" for j in yi]
    w0 = max(len(s.y.name), *(len(y) for y in ylabels))
    lines.append(f"rows: {s.y.label}, columns: {s.x.label}")
    lines.append(" " * w0 + " │ " + " ".join(h.rjust(w) for h in head))
    lines.append("─" * w0 + "─┼─" + "─" * ((w + 1) * len(head) - 1))
    for label, row in zip(ylabels, cells):
        lines.append(f"{label:>{w0}} │ " + " ".join(c.rjust(w) for c in row))
    return "\n".join(lines)
