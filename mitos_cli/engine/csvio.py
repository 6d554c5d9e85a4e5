"""Reading and writing batches of inputs as CSV (``mitos eval --batch``).

The ``csv`` module reads the text as a file opened with ``newline=''`` is read: a record ends
at ``\\n``, ``\\r\\n`` or ``\\r`` outside quotes, and a quoted cell keeps its line breaks (and
form feeds), so passed-through cells come out as they went in. Rows are read in chunks; each
input column of a chunk is checked and converted by NumPy at once, and the first bad chunk
stops the reading. Only when something is wrong is the text walked again, to give the error
its line and column.
"""

from __future__ import annotations

import csv
import operator
import re
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from functools import partial
from itertools import islice
from typing import NoReturn, TextIO

import numpy as np

from ..errors import InputError, Span, closest
from ..numbers import parse_number
from ..words import plural

#: rows read, checked and converted at once
CHUNK = 1 << 16
#: where a record's lines end, as the ``csv`` module and ``newline=''`` see it
_BREAK = re.compile(r"\r\n|\r|\n")
#: a line and its line break (the last line may have none)
_LINE = re.compile(r"[^\r\n]*(?:\r\n|\r|\n)|[^\r\n]+")
_GROUP = operator.methodcaller("group")
#: the longest input cell kept as fixed-width bytes (a longer one is kept as text)
SHORT = 40
#: characters that make ``csv`` quote a cell it writes
_SPECIAL = (",", '"', "\r", "\n")


@dataclass(frozen=True)
class Batch:
    """A batch CSV as read: ``X[n, k]`` in the order of the inputs asked for, each input's
    cells as written (``given``: ASCII bytes, as a number is ASCII, or text for a cell too
    long for a fixed-width array), and the other columns
    (``extra`` names, ``columns[len(extra)][n]`` as written) to pass through."""

    X: np.ndarray
    given: tuple[np.ndarray, ...] = ()
    extra: tuple[str, ...] = ()
    columns: tuple[np.ndarray, ...] = ()


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
    _refuse_nul(text, path)
    expected = "a header naming the inputs: " + ",".join(inputs)
    if not text.strip():
        raise InputError("the batch CSV is empty", span=Span(path, 1, 1), expected=expected)
    reader = csv.reader(_lines(text), strict=True)
    try:
        header = next(reader)
    except csv.Error:
        _raise_csv_error(text, path)
    if _blank(header):
        raise InputError("the batch CSV's first line is empty: the header comes first",
                         span=Span(path, 1, 1), expected=expected,
                         hint="remove the empty lines above the header")
    header = [h.strip() for h in header]
    _check_header(header, text, path, inputs)
    order = [header.index(k) for k in inputs]
    extra = [c for c, h in enumerate(header) if h not in inputs]
    given: list[list[np.ndarray]] = [[] for _ in order]
    values: list[np.ndarray] = []
    kept: list[list[np.ndarray]] = [[] for _ in extra]
    done = 0
    chunks = _plain_chunks(text, len(header)) if '"' not in text else \
        _csv_chunks(reader, len(header), text, path)
    for rows, columns in chunks:
        if columns is None:                 # a row is not as wide as the header
            raise _bad_row(rows(), done, header, order, text, path) or AssertionError(rows)
        cells, X = _convert(rows, columns, done, header, order, text, path)
        for parts, col in zip(given, cells):
            parts.append(col)
        values.append(X)
        for parts, c in zip(kept, extra):
            parts.append(np.array(columns[c], dtype=object))
        done += len(X)
    X = np.concatenate(values) if values else np.empty((0, len(inputs)))
    return Batch(np.ascontiguousarray(X), tuple(_joined(p) for p in given),
                 tuple(header[c] for c in extra),
                 tuple(np.concatenate(p) if p else np.empty(0, dtype=object) for p in kept))


#: a chunk of data rows: a function giving them as lists of cells (for an error), and their
#: columns (``None`` when a row is not as wide as the header)
Chunk = tuple[Callable[[], list[list[str]]], "list[Sequence[str]] | None"]


def _csv_chunks(reader: Iterator[list[str]], width: int, text: str, path: str) -> Iterator[Chunk]:
    """The data rows as the ``csv`` module reads them (a text with quotes)."""
    while True:
        try:
            chunk = list(islice(reader, CHUNK))
        except csv.Error:
            _raise_csv_error(text, path)
        rows = [r for r in chunk if not _blank(r)]
        if rows:
            wide = all(len(r) == width for r in rows)
            yield partial(list, rows), (list(zip(*rows)) if wide else None)
        if len(chunk) < CHUNK:
            return


def _split(lines: list[str]) -> list[list[str]]:
    return [line.split(",") for line in lines]


def _plain_chunks(text: str, width: int) -> Iterator[Chunk]:
    """The data rows of a text without quotes, where a cell is what lies between two commas
    and a row a line: split by ``str`` methods, many times faster than the ``csv`` module
    (which reads it the same)."""
    first = _BREAK.search(text)
    pos, n = (first.end() if first else len(text)), len(text)
    while pos < n:
        end = min(n, pos + CHUNK * 32)               # about CHUNK lines of short rows
        if end < n:
            cut = max(text.rfind("\n", pos, end), text.rfind("\r", pos, end))
            if cut < 0:                               # a line longer than the block
                found = _BREAK.search(text, end)
                cut = found.start() if found else n - 1
            end = cut + 2 if text.startswith("\r\n", cut) else cut + 1
        block = text[pos:end]
        lines = list(filter(str.strip, _BREAK.split(block) if "\r" in block
                            else block.split("\n")))
        pos = end
        if not lines:
            continue
        rows = partial(_split, lines)
        if any(line.count(",") != width - 1 for line in lines):
            yield rows, None
            continue
        flat = ",".join(lines).split(",")
        yield rows, [flat[c::width] for c in range(width)]


def _joined(parts: list[np.ndarray]) -> np.ndarray:
    """One input's cells from its chunks': fixed-width bytes, or text where a chunk had a
    cell too long for that."""
    if all(p.dtype.kind == "S" for p in parts):
        return np.concatenate(parts) if parts else np.empty(0, dtype="S1")
    return np.concatenate([p.astype("U").astype(object) if p.dtype.kind == "S" else p
                           for p in parts])


def _lines(text: str) -> Iterator[str]:
    """The lines of ``text`` with their line breaks, as ``io.StringIO(text, newline='')``
    gives them, without the copy of the whole text (four bytes a character) it makes."""
    return map(_GROUP, _LINE.finditer(text))


def _blank(row: list[str]) -> bool:
    """An empty line (or one of spaces alone): skipped, as it holds no row."""
    return not row or (len(row) == 1 and not row[0].strip())


def _refuse_nul(text: str, path: str) -> None:
    nul = text.find("\x00")
    if nul >= 0:
        raise InputError("the batch CSV holds a NUL byte (it is not a text file)",
                         span=_span(text, path, nul))


def _check_header(header: list[str], text: str, path: str, inputs: tuple[str, ...]) -> None:
    """Every input has a column, named once; a misspelt name or a file separated by `;` or
    tabs is said as such."""
    starts = _scan(text, 0)[0]
    seen: dict[str, int] = {}
    for c, h in enumerate(header):
        if h in seen:
            raise InputError(f"batch column `{h}` is named twice (columns {seen[h] + 1} and "
                             f"{c + 1})", span=_span(text, path, starts[c]))
        seen[h] = c
    missing = [k for k in inputs if k not in header]
    if not missing:
        return
    if header and header[0].strip().lower().startswith("sep="):
        # Excel writes `sep=,` (or `sep=;`) above the header for itself
        raise InputError("the batch CSV starts with Excel's separator line, not a header",
                         span=_span(text, path, 0),
                         hint="delete the first line (`sep=...`), so that the header naming "
                              + ", ".join(inputs) + " comes first")
    if len(header) == 1:
        for sep, name in ((";", "`;`"), ("\t", "a tab")):
            if sep in header[0]:
                raise InputError(f"the header has one column; is the separator {name}? MITOS "
                                 f"reads comma-separated values", span=_span(text, path, 0),
                                 expected="a header naming " + ", ".join(inputs) + ", "
                                 "separated by commas",
                                 hint="save the file as CSV with `,` between the values")
    others = [h for h in header if h not in inputs]
    for h in others:
        joined = _names_in(h.strip(), inputs)
        if joined is not None and len(joined) > 1 and set(joined) & set(missing):
            # `road size` or `roadsize`: two names in one column, without the comma
            raise InputError("the batch CSV has no column for " + ", ".join(missing),
                             span=_span(text, path, starts[header.index(h)]),
                             expected="columns " + ", ".join(inputs),
                             hint=f"column `{h}` names {_and(joined)}: columns are separated "
                                  f"by commas, `{','.join(joined)}`")
    close = {k: closest(k, others) for k in missing}
    typos = [(k, h) for k, h in close.items() if h is not None]
    if typos:
        names = ", ".join(dict.fromkeys(f"`{h}`" for _, h in typos))
        meant = ", ".join(f"`{k}`" for k, _ in typos)
        column = "column" if len(typos) == 1 else "columns"
        raise InputError("the batch CSV has no column for " + ", ".join(missing),
                         span=_span(text, path, starts[header.index(typos[0][1])]),
                         expected="columns " + ", ".join(inputs),
                         hint=f"{column} {names} {'is' if len(typos) == 1 else 'are'} passed "
                              f"through as {'it is' if len(typos) == 1 else 'they are'}: did "
                              f"you mean {meant}?")
    raise InputError("the batch CSV has no column for " + ", ".join(missing),
                     span=_span(text, path, 0), expected="a header naming " + ", ".join(inputs))


def _and(names: Sequence[str]) -> str:
    quoted = [f"`{n}`" for n in names]
    return ", ".join(quoted[:-1]) + " and " + quoted[-1]


def _names_in(cell: str, names: Sequence[str]) -> list[str] | None:
    """``cell`` read as ``names`` written one after another, with or without blanks between
    (``road size``, ``roadsize`` -> road, size), or None when it is not. Each place the cell
    can be read to keeps the place before it (copying the rest of the cell and the names so far
    at each place took 5 s for a header cell of 100,000 characters)."""
    before: dict[int, tuple[int, str] | None] = {0: None}
    size = len(cell)
    for at in range(size + 1):
        if at not in before:
            continue
        if at == size:
            found: list[str] = []
            step = before[at]
            while step is not None:
                at, name = step
                if name:
                    found.append(name)
                step = before[at]
            return found[::-1]
        if cell[at].isspace():
            end = at
            while end < size and cell[end].isspace():
                end += 1
            before.setdefault(end, (at, ""))
            continue
        for name in names:
            if name and cell.startswith(name, at):
                before.setdefault(at + len(name), (at, name))
    return None


def _convert(rows: Callable[[], list[list[str]]], columns: list[Sequence[str]], done: int,
             header: list[str], order: list[int], text: str,
             path: str) -> tuple[list[np.ndarray], np.ndarray]:
    """One chunk's input cells (as written) and their numbers ``X[rows, k]``; the chunk's
    first bad row, as an error. ``done``: the data rows before the chunk."""
    cells, numbers = [], []
    for c in order:
        column = columns[c]
        try:
            if max(map(len, column)) > SHORT:
                raise ValueError                       # no fixed-width array that wide
            raw = np.array(column, dtype="S")         # a number is ASCII
            if raw.tobytes().find(b"_") >= 0:          # NumPy, as float, reads 7_8 as 78
                raise ValueError
            numbers.append(raw.astype(float))
        except (UnicodeEncodeError, ValueError):
            error = _bad_row(rows(), done, header, order, text, path)
            if error is not None:
                raise error from None
            # every cell reads as a number (parse_number's reading, which decides)
            raw = np.array(column, dtype=object)
            numbers.append(np.array([parse_number(v) for v in column], dtype=float))
        cells.append(raw)
    X = np.column_stack(numbers) if numbers else np.empty((len(columns[0]), 0))
    _refuse_overflow(X, columns, done, header, order, text, path)
    if np.isnan(X).any():               # the engine refuses NaN: say where it stands
        r, j = (int(i) for i in np.argwhere(np.isnan(X))[0])
        c = order[j]
        raise InputError(f"input `{header[c]}` is not a number (NaN) in row {done + r + 1}",
                         span=_cell_span(text, path, done + r, c),
                         hint=f"`{columns[c][r].strip()}` reads as NaN; give every input a finite "
                              "value (out-of-range values are clamped to the universe)")
    return cells, X


def _refuse_overflow(X: np.ndarray, columns: list[Sequence[str]], done: int, header: list[str],
                     order: list[int], text: str, path: str) -> None:
    """The first cell whose number is past a float's range (``1e400``, read as ``inf``), as
    the error ``10**400`` gets from the API; a cell written ``inf`` stays infinite."""
    for r, j in np.argwhere(np.isinf(X)):
        c = order[j]
        cell = columns[c][r].strip()
        if "inf" not in cell.lower():
            raise InputError(f"input `{header[c]}` has a number too large for a float: `{cell}` "
                             f"(row {done + r + 1})", span=_cell_span(text, path, done + r, c),
                             expected="numbers of magnitude at most 1.8e308")


def _bad_row(rows: list[list[str]], done: int, header: list[str], order: list[int],
             text: str, path: str) -> InputError | None:
    """The first row of a chunk that is not as wide as the header or whose input cell is not
    a number, as an error naming its column, row and position; ``None`` when there is none."""
    width = len(header)
    for i, cells in enumerate(rows):
        row = done + i
        if len(cells) != width:
            line = _record_line(text, row)
            trailing = len(cells) == width - 1 and not header[-1].strip()
            return InputError(f"row has {plural(len(cells), 'value')}, the header {width}",
                              span=_span(text, path, _line_offset(text, line)),
                              hint="the header ends in `,`: its last column has no name; "
                                   "delete that comma" if trailing else None)
        for c in order:
            cell = cells[c]
            if not cell.strip():
                return InputError(f"input `{header[c]}` is empty in row {row + 1} (column "
                                  f"{c + 1})", span=_cell_span(text, path, row, c),
                                  hint="give every input a number")
            try:
                parse_number(cell)
            except ValueError:
                return InputError(f"`{cell.strip()}` is not a number (input `{header[c]}`, "
                                  f"row {row + 1})", span=_cell_span(text, path, row, c),
                                  hint=comma_in_number(cell.strip()))
    return None


def comma_in_number(cell: str, name: str = "") -> str | None:
    """`78,5` (a spreadsheet's decimal comma, the cell quoted): the decimal point is `.`;
    `1,000` may be a thousands separator too, so both readings are offered. ``name``: the
    input, written before the number (`road=78.5`)."""
    if re.fullmatch(r"[-+]?\d+,\d+", cell) is None:
        return None
    whole, _, part = cell.partition(",")
    if len(part) == 3:
        return (f"a number has `.` for its decimals and no thousands separator: "
                f"`{name}{whole}.{part}` or `{name}{whole}{part}`")
    return f"the decimal separator is `.`: `{name}{whole}.{part}`"


# ---- positions, found again only for an error --------------------------------------------------

class _Broken(Exception):
    """A record the ``csv`` module refused, starting at ``line``."""

    def __init__(self, line: int, why: str) -> None:
        super().__init__(why)
        self.line, self.why = line, why


def _records(text: str) -> Iterator[tuple[int, list[str]]]:
    """``(first line, cells)`` of every record, the header and blank lines included."""
    reader = csv.reader(_lines(text), strict=True)
    line = 1
    while True:
        try:
            cells = next(reader)
        except StopIteration:
            return
        except csv.Error as exc:
            raise _Broken(line, str(exc)) from None
        yield line, cells
        line = reader.line_num + 1


def _record_line(text: str, row: int) -> int:
    """The line where data row ``row`` (0-based, blank lines not counted) starts."""
    records = (line for line, cells in islice(_records(text), 1, None) if not _blank(cells))
    try:
        return next(islice(records, row, None))
    except _Broken as broken:     # a cell past the csv module's field limit before the row:
        return broken.line        # (the fast path read it) the place the module stops at


def _line_offset(text: str, line: int) -> int:
    """Where ``line`` (1-based) starts in ``text``."""
    if line <= 1:
        return 0
    return next(islice(_BREAK.finditer(text), line - 2, None)).end()


def row_span(text: str, path: str, row: int) -> Span:
    """Where data row ``row`` (0-based, blank lines not counted) of a batch starts: for an
    error about the row as a whole (no rule fired there)."""
    return _span(text, path, _line_offset(text, _record_line(text, row)))


def _span(text: str, path: str, index: int) -> Span:
    """The span at character ``index`` of ``text``, its line and column counted as the
    ``csv`` module counts lines."""
    breaks = 0
    last = None
    for last in _BREAK.finditer(text, 0, index):  # noqa: B007 - the count and the last one
        breaks += 1
    start = last.end() if last is not None else 0
    return Span.at(text, path, index, breaks + 1, index - start + 1, breaks=_BREAK)


def _cell_span(text: str, path: str, row: int, column: int) -> Span:
    """Where cell ``column`` of data row ``row`` starts."""
    starts = _scan(text, _line_offset(text, _record_line(text, row)))[0]
    return _span(text, path, starts[column])


def _scan(text: str, start: int) -> tuple[list[int], tuple[str, int] | None]:
    """Where each cell of the record at ``start`` begins, as the ``csv`` module (strict, the
    default dialect) splits it; and, for a record it refuses, why and where: ``("open", i)``
    for a quote at ``i`` never closed, ``("after", i)`` for a character after a closing
    quote."""
    starts, i, n = [start], start, len(text)
    state, opened = "start", start
    while i < n:
        ch = text[i]
        if state == "quoted":
            if ch == '"':
                if text.startswith('"', i + 1):
                    i += 2
                    continue
                state = "closed"
        elif ch == ",":
            starts.append(i + 1)
            state = "start"
        elif ch in "\r\n":
            return starts, None
        elif state == "closed":
            return starts, ("after", i)
        elif ch == '"' and state == "start":
            state, opened = "quoted", i
        else:
            state = "plain"
        i += 1
    return starts, (("open", opened) if state == "quoted" else None)


def _raise_csv_error(text: str, path: str) -> NoReturn:
    """The record the ``csv`` module refused, in words, at the character that breaks it."""
    try:
        for _ in _records(text):
            pass
    except _Broken as broken:
        offset = _line_offset(text, broken.line)
        _, problem = _scan(text, offset)
        quote = 'a quote inside a quoted cell is written twice (`""`)'
        if problem is not None and problem[0] == "open":
            raise InputError("this quote opens a cell that is never closed",
                             span=_span(text, path, problem[1]),
                             expected='a closing `"` before the end of the file', hint=quote) \
                from None
        if problem is not None:
            raise InputError(f"`{text[problem[1]]}` after a quoted cell's closing quote",
                             span=_span(text, path, problem[1]),
                             expected="`,` or the end of the line", hint=quote) from None
        raise InputError(f"row cannot be read as CSV: {broken.why}",
                         span=_span(text, path, offset),
                         hint="a cell holds one number; a field this long is not one"
                         if "field larger" in broken.why else None) from None
    raise AssertionError("the csv module refused a text it now reads")


# ---- writing ---------------------------------------------------------------------------------

def flag_name(inputs: Sequence[str], outputs: Sequence[str]) -> str:
    """The name of ``--on-no-rule``'s column: ``no_rule``, or ``mitos_no_rule`` where an input
    or output has that name (a header naming two columns alike says neither)."""
    name = "no_rule"
    while name in inputs or name in outputs:
        name = "mitos_" + name
    return name


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


def write_batch(out: TextIO, inputs: Sequence[str], given: Sequence[np.ndarray],
                outputs: Sequence[str], Y: np.ndarray, no_rule: np.ndarray | None = None,
                extra: Sequence[str] = (), columns: Sequence[np.ndarray] = (),
                digits: int | None = None) -> None:
    """The inputs as written (``given``), the outputs, the passed-through ``extra`` columns
    (``columns``, as read) and, with ``no_rule`` (per row, the outputs no rule set, joined by
    ``;``), a last column ``no_rule``. Outputs are written in full (the shortest text that
    reads back as the same double) or with ``digits`` decimals."""
    names = [*inputs, *outputs, *extra,
             *(() if no_rule is None else (flag_name(inputs, outputs),))]
    out.write(",".join(_quoted(list(names))) + "\n")
    number = repr if digits is None else _decimals(digits)
    for start in range(0, len(Y), CHUNK):
        part = slice(start, start + CHUNK)
        cells = [_quoted((g[part].astype("U") if g.dtype.kind == "S" else g[part]).tolist())
                 for g in given]
        cells += [list(map(number, Y[part, j].tolist())) for j in range(Y.shape[1])]
        cells += [_quoted(c[part].tolist()) for c in columns]
        if no_rule is not None:
            cells.append(_quoted([str(s) for s in no_rule[part]]))
        out.write("\n".join(map(",".join, zip(*cells))) + "\n")


def _decimals(digits: int) -> Callable[[float], str]:
    """``x`` with ``digits`` decimals; from 1e15 on in full (``1e+300``), as the trace does
    (:data:`~.trace.LONG`): a float's digits end there, and 1e300 took 301 digits and 2
    decimals of noise."""
    from .trace import LONG

    fixed = f"{{:.{digits}f}}".format
    return lambda x: repr(x) if abs(x) >= LONG else fixed(x)


def _quoted(cells: list[str]) -> list[str]:
    """Cells as the ``csv`` module writes them: quoted where they hold a separator, a quote
    or a line break (looked for in one pass over the column, as most columns hold none)."""
    joined = "\x00".join(cells)
    if not any(ch in joined for ch in _SPECIAL):
        return cells
    return ['"' + c.replace('"', '""') + '"' if any(ch in c for ch in _SPECIAL) else c
            for c in cells]
