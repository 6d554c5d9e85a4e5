"""Reading and writing batches of inputs as CSV (``mitos eval --batch``)."""

from __future__ import annotations

import csv
import io
from typing import TextIO

import numpy as np

from ..errors import InputError, Span, did_you_mean
from ..words import plural


def read_batch(text: str, path: str, inputs: tuple[str, ...],
               unused: tuple[str, ...] = ()) -> np.ndarray:
    """``X[n, k]`` from CSV text whose header names every input (any column order); columns
    named in ``unused`` (inputs of the rule base its rules never test) are read and dropped."""
    nul = text.find("\x00")
    if nul >= 0:
        lineno = text.count("\n", 0, nul) + 1
        column = nul - (text.rfind("\n", 0, nul) + 1) + 1
        raise InputError("the batch CSV holds a NUL byte (it is not a text file)",
                         span=Span.at(text, path, nul, lineno, column))
    lines = text.splitlines()
    if not lines or not lines[0].strip():
        raise InputError("the batch CSV is empty", span=Span(path, 1, 1),
                         expected="a header naming the inputs: " + ",".join(inputs))
    header = [h.strip() for h in _cells(lines[0], path, 1)]
    for h in header:
        if h not in inputs and h not in unused:
            raise InputError(f"batch column `{h}` is not an input of this behavior",
                             span=Span.in_text(text, path, 1, lines[0].find(h) + 1),
                             expected="columns " + ", ".join(inputs),
                             hint=did_you_mean(h, inputs))
    missing = [k for k in inputs if k not in header]
    if missing:
        raise InputError("the batch CSV has no column for " + ", ".join(missing),
                         span=Span.in_text(text, path, 1, 1),
                         expected="a header naming " + ", ".join(inputs))
    body = [line for line in lines[1:] if line.strip()]
    if not body:
        return np.empty((0, len(inputs)))
    try:
        data = np.loadtxt(io.StringIO("\n".join(body)), delimiter=",", ndmin=2, dtype=float)
    except ValueError:
        _raise_bad_row(lines, path, len(header))
    if data.shape[1] != len(header):
        _raise_bad_row(lines, path, len(header))
    if np.isnan(data).any():            # the engine refuses NaN: say where it stands
        r, c = (int(i) for i in np.argwhere(np.isnan(data))[0])
        numbers = [n for n, line in enumerate(lines[1:], start=2) if line.strip()]
        line = lines[numbers[r] - 1]
        cell = _cells(line, path, numbers[r])[c].strip()
        raise InputError(f"input `{header[c]}` is not a number (NaN)",
                         span=Span(path, numbers[r], 1, line[:200]),
                         hint=f"`{cell}` reads as NaN; give every input a finite value "
                              "(out-of-range values are clamped to the universe)")
    order = [header.index(k) for k in inputs]
    return np.ascontiguousarray(data[:, order])


def _raise_bad_row(lines: list[str], path: str, width: int) -> None:
    for n, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        cells = _cells(line, path, n)
        if len(cells) != width:
            raise InputError(f"row has {plural(len(cells), 'value')}, the header {width}",
                             span=Span(path, n, 1, line))
        for cell in cells:
            try:
                float(cell)
            except ValueError:
                raise InputError(f"`{cell.strip()}` is not a number",
                                 span=Span(path, n, max(1, line.find(cell) + 1), line)) from None
    raise InputError("the batch CSV could not be read", span=Span(path, 1, 1))


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


def write_batch(out: TextIO, inputs, X: np.ndarray, outputs, Y: np.ndarray,
                no_rule: np.ndarray | None = None) -> None:
    """Inputs and outputs as CSV; with ``no_rule`` (one text per row: the outputs no rule set,
    joined by ``;``) a last column ``no_rule``."""
    names = list(inputs) + list(outputs) + ([] if no_rule is None else ["no_rule"])
    out.write(",".join(names) + "\n")
    table = np.hstack([X, Y]) if len(X) else np.empty((0, len(inputs) + len(outputs)))
    if no_rule is None:
        np.savetxt(out, table, delimiter=",", fmt="%.12g")
        return
    cells = np.column_stack([table.astype(object), np.asarray(no_rule, dtype=object)])
    np.savetxt(out, cells, delimiter=",", fmt=["%.12g"] * table.shape[1] + ["%s"])
