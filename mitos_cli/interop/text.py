"""The text of a file another tool wrote.

fuzzylite reads a file's bytes as they are and jFuzzyLogic in the platform's charset, and
MATLAB writes ``.fis`` files in the platform's encoding: on Windows that is Windows-1252, so a
file saved there with ``Temperatur (°C)`` in a name or a comment is not UTF-8. Such a file is
read as Windows-1252, with a note that says so; bytes that are no text in either (a NUL, an
undefined code point, a UTF-16 file) are refused at their line and column.
"""

from __future__ import annotations

import codecs
import dataclasses
from collections.abc import Callable
from pathlib import Path

from ..errors import FormatError, Span
from ..fileio import bad_byte, read_text, unreadable
from ..lang.model import RuleBase

#: The encoding a file that is not UTF-8 is read in: what MATLAB and Java write on Windows.
LEGACY = "cp1252"


def read_foreign_file(path: Path, parse: Callable[[str, str], RuleBase]) -> RuleBase:
    """The rule base ``parse`` reads from ``path``'s text, noting a legacy encoding."""
    text, note = foreign_text(path)
    rb = parse(text, str(path))
    return rb if note is None else dataclasses.replace(rb, notes=(note, *rb.notes))


def foreign_text(path: Path) -> tuple[str, str | None]:
    """``path``'s text, and a note when it was read as Windows-1252 (``None`` for UTF-8)."""
    try:
        return read_text(path), None
    except UnicodeDecodeError as exc:
        data: bytes = exc.object
        if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
            raise FormatError(f"`{path}` is UTF-16 text; MITOS reads UTF-8 or Windows-1252",
                              span=_at(path, data, 0), hint="save it as UTF-8") from None
        nul = data.find(b"\0")
        if nul < 0 and not data.startswith(codecs.BOM_UTF8):
            try:
                text = data.decode(LEGACY)
            except UnicodeDecodeError:
                pass
            else:
                return text, (f"`{path.name}` is not UTF-8 ({_byte(path, data, exc.start)}): "
                              "read as Windows-1252, the encoding MATLAB and Java write on Windows")
        bad = nul if nul >= 0 else exc.start
        raise FormatError(f"`{path}` is not a text file ({_byte(path, data, bad)} is neither "
                          "UTF-8 nor Windows-1252 text)", span=_at(path, data, bad)) from None
    except OSError as exc:
        raise FormatError(unreadable("rule file", path, exc)) from None


def _at(path: Path, data: bytes, start: int) -> Span:
    """Where byte ``start`` of ``data`` is: its line and column (counted in bytes)."""
    span = bad_byte(path, UnicodeDecodeError("utf-8", data, start, start + 1, "not text"))
    assert span is not None
    return span


def _byte(path: Path, data: bytes, start: int) -> str:
    where = _at(path, data, start)
    return f"byte 0x{data[start]:02x} at line {where.line}, column {where.column}"
