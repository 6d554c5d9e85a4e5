"""Reading and writing batches of inputs as CSV (``mitos eval --batch``)."""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NoReturn, TextIO

import numpy as np

from ..errors import InputError, Span, did_you_mean
from ..numbers import parse_number
from ..words import plural


@dataclass(frozen=True)
class Batch:
    """A batch CSV as read: ``X[n, k]`` in the order of the inputs asked for, and the other
    columns (``extra`` names, ``cells[n][len(extra)]`` as written) to pass through."""

    X: np.ndarray
    extra: tuple[str, ...] = ()
    cells: tuple[tuple[str, ...], ...] = ()


def read_batch(text: str, path: str, inputs: tuple[str, ...],
               unused: tuple[str, ...] = ()) -> np.ndarray:
    """``X[n, k]`` from CSV text whose header names every input (any column order); other
    columns are read and dropped (:func:`read_table` keeps them)."""
    return read_table(text, path, inputs, unused).X


def read_table(text: str, path: str, inputs: tuple[str, ...],
               unused: tuple[str, ...] = ()) -> Batch:
    """The batch in ``text``: every input's column is a number per row; any other column (an
    input of the file its rules never test, in ``unused``, or anything else, e.g. the pose
    and ranges of a ``mitos simulate --out`` CSV) is kept as text, in its order, to be passed
    through. A header that lacks an input but has a column spelled like it is a typo: the
    error names it."""
    nul = text.find("\x00")
    if nul >= 0:
        lineno = text.count("\n", 0, nul) + 1
        column = nul - (text.rfind("\n", 0, nul) + 1) + 1
        raise InputError("the batch CSV holds a NUL byte (it is not a text file)",
                         span=Span.at(text, path, nul, lineno, column))
    lines = text.splitlines()
    if not any(line.strip() for line in lines):
        raise InputError("the batch CSV is empty", span=Span(path, 1, 1),
                         expected="a header naming the inputs: " + ",".join(inputs))
    if not lines[0].strip():
        raise InputError("the batch CSV's first line is empty: the header comes first",
                         span=Span(path, 1, 1),
                         expected="a header naming the inputs: " + ",".join(inputs),
                         hint="remove the empty lines above the header")
    header = [h.strip() for h in _cells(lines[0], path, 1)]
    starts = _starts(lines[0])
    seen: dict[str, int] = {}
    for c, h in enumerate(header):
        if h in seen:
            raise InputError(f"batch column `{h}` is named twice (columns {seen[h] + 1} and "
                             f"{c + 1})", span=Span(path, 1, starts[c], lines[0]))
        seen[h] = c
    missing = [k for k in inputs if k not in header]
    if missing:
        others = [h for h in header if h not in inputs]
        for k in missing:
            close = did_you_mean(k, others)
            if close:
                h = close.split("`")[1] if "`" in close else k
                c = header.index(h) if h in header else 0
                raise InputError(f"the batch CSV has no column for {k}",
                                 span=Span(path, 1, starts[c], lines[0]),
                                 expected="columns " + ", ".join(inputs),
                                 hint=f"column `{h}` is passed through as it is: did you "
                                      f"mean `{k}`?")
        raise InputError("the batch CSV has no column for " + ", ".join(missing),
                         span=Span.in_text(text, path, 1, 1),
                         expected="a header naming " + ", ".join(inputs))
    order = [header.index(k) for k in inputs]
    extra = [c for c, h in enumerate(header) if h not in inputs]
    numbers = [n for n, line in enumerate(lines[1:], start=2) if line.strip()]
    if not numbers:
        return Batch(np.empty((0, len(inputs))), tuple(header[c] for c in extra))
    body = [lines[n - 1] for n in numbers]
    if not extra:
        try:
            data = np.loadtxt(io.StringIO("\n".join(body)), delimiter=",", ndmin=2,
                              dtype=float, comments=None)   # `#` is not a number here either
        except ValueError:
            _raise_bad_row(lines, path, header, order)
        if data.shape[1] != len(header):
            _raise_bad_row(lines, path, header, order)
        picked = data[:, order]
        rows: list[list[str]] = []
    else:
        try:
            rows = list(csv.reader(body))
        except csv.Error:
            rows = [_cells(line, path, n) for n, line in zip(numbers, body)]
        if any(len(r) != len(header) for r in rows):
            _raise_bad_row(lines, path, header, order)
        try:
            picked = np.array([[parse_number(r[c]) for c in order] for r in rows],
                              dtype=float)
        except ValueError:
            _raise_bad_row(lines, path, header, order)
    if np.isnan(picked).any():          # the engine refuses NaN: say where it stands
        r, j = (int(i) for i in np.argwhere(np.isnan(picked))[0])
        c = order[j]
        line = lines[numbers[r] - 1]
        cell = _cells(line, path, numbers[r])[c].strip()
        raise InputError(f"input `{header[c]}` is not a number (NaN) in row {r + 1}",
                         span=Span(path, numbers[r], _starts(line)[c], line[:200]),
                         hint=f"`{cell}` reads as NaN; give every input a finite value "
                              "(out-of-range values are clamped to the universe)")
    return Batch(np.ascontiguousarray(picked), tuple(header[c] for c in extra),
                 tuple(tuple(row[c] for c in extra) for row in rows))


def _raise_bad_row(lines: list[str], path: str, header: list[str],
                   order: list[int]) -> NoReturn:
    """The first row that is not as wide as the header or whose input cell is not a number,
    as an error naming its column, row and position."""
    width = len(header)
    row = 0
    for n, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        row += 1
        cells = _cells(line, path, n)
        if len(cells) != width:
            raise InputError(f"row has {plural(len(cells), 'value')}, the header {width}",
                             span=Span(path, n, 1, line))
        starts = _starts(line)
        for c in order:
            cell = cells[c]
            if not cell.strip():
                raise InputError(f"input `{header[c]}` is empty in row {row} (column {c + 1})",
                                 span=Span(path, n, starts[c], line[:200]),
                                 hint="give every input a number")
            try:
                parse_number(cell)
            except ValueError:
                raise InputError(f"`{cell.strip()}` is not a number (input `{header[c]}`, "
                                 f"row {row})",
                                 span=Span(path, n, starts[c], line[:200])) from None
    raise InputError("the batch CSV could not be read", span=Span(path, 1, 1))


def _starts(line: str) -> list[int]:
    """The 1-based column where each cell of one CSV line starts, as the ``csv`` module splits
    it: a quote opens a quoted cell only at the cell's start (``a"b,c`` is two cells), ``""``
    inside one is a quote, and commas inside quotes do not separate cells."""
    starts, quoted, fresh, closed = [1], False, True, -2
    for i, ch in enumerate(line):
        if quoted:
            if ch == '"':
                quoted, closed = False, i
        elif ch == '"' and (fresh or closed == i - 1):
            quoted = True
        elif ch == ",":
            starts.append(i + 2)
            fresh = True
            continue
        fresh = False
    return starts


def _cells(line: str, path: str, n: int) -> list[str]:
    """One CSV line's cells, or an :class:`InputError` at that line (the ``csv`` module's own
    errors: a field over its size limit, a stray quote in strict dialects)."""
    try:
        return next(csv.reader([line]), [])
    except csv.Error as exc:
        shown = line if len(line) <= 200 else line[:200] + "..."
        raise InputError(f"row {n} cannot be read as CSV: {exc}", span=Span(path, n, 1, shown),
                         hint="a cell holds one number; a field this long is not one"
                         if "field larger" in str(exc) else None) from None


def passed_names(extra: tuple[str, ...], taken: tuple[str, ...]) -> tuple[str, ...]:
    """The names the passed-through columns are written under: their own, or ``given_NAME``
    where the output CSV already has a column ``NAME`` (an output such as the ``steering`` of
    a ``mitos simulate --out`` CSV, or ``no_rule``)."""
    used = set(taken) | set(extra)
    out = []
    for name in extra:
        if name in taken:
            new = "given_" + name
            while new in used:
                new = "given_" + new
            used.add(new)
            name = new
        out.append(name)
    return tuple(out)


def write_batch(out: TextIO, inputs, X: np.ndarray, outputs, Y: np.ndarray,
                no_rule: np.ndarray | None = None, extra: tuple[str, ...] = (),
                cells: Sequence[Sequence[str]] = ()) -> None:
    """Inputs and outputs as CSV; then the passed-through ``extra`` columns (``cells``, one
    sequence per row, written as read); with ``no_rule`` (one text per row: the outputs no rule
    set, joined by ``;``) a last column ``no_rule``."""
    tail = [] if no_rule is None else ["no_rule"]
    names = list(inputs) + list(outputs) + list(extra) + tail
    table = np.hstack([X, Y]) if len(X) else np.empty((0, len(inputs) + len(outputs)))
    if extra:
        w = csv.writer(out, lineterminator="\n")
        w.writerow(names)
        for i, row in enumerate(table):
            w.writerow([f"{v:.12g}" for v in row] + list(cells[i])
                       + ([] if no_rule is None else [no_rule[i]]))
        return
    out.write(",".join(names) + "\n")
    if no_rule is None:
        np.savetxt(out, table, delimiter=",", fmt="%.12g")
        return
    column = np.column_stack([table.astype(object), np.asarray(no_rule, dtype=object)])
    np.savetxt(out, column, delimiter=",", fmt=["%.12g"] * table.shape[1] + ["%s"])
