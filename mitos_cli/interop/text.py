"""The text of a file another tool wrote.

fuzzylite reads a file's bytes as they are and jFuzzyLogic in the platform's charset, and
MATLAB writes ``.fis`` files in the platform's encoding: on Windows that is Windows-1252, so a
file saved there with ``Temperatur (°C)`` in a name or a comment is not UTF-8. Such a file is
read as Windows-1252, with a note that says so. Bytes that are no text in either (a NUL, a
code point Windows-1252 leaves undefined, a UTF-16 or UTF-32 file), and a file that is UTF-8
in one place and not in another (read as Windows-1252, its UTF-8 would be garbled), are
refused at their line and column.
"""

from __future__ import annotations

import codecs
import dataclasses
import re
from collections.abc import Callable
from pathlib import Path

from ..errors import FormatError, RuleBaseError
from ..fileio import byte_span as _at
from ..fileio import not_text, read_bytes, text_encoding_hint, unreadable, wide_text
from ..lang.model import RuleBase
from ..lang.parse import check_rule_file_size
from ..lang.resolve import rule_file_not_found_hint

#: The encoding a file that is not UTF-8 is read in: what MATLAB and Java write on Windows.
LEGACY = "cp1252"


def read_foreign_file(path: Path, parse: Callable[[str, str], RuleBase]) -> RuleBase:
    """The rule base ``parse`` reads from ``path``'s text, noting a legacy encoding."""
    text, note = foreign_text(path)
    check_rule_file_size(text, str(path))
    rb = parse(text, str(path))
    return rb if note is None else dataclasses.replace(rb, notes=(note, *rb.notes))


def foreign_text(path: Path) -> tuple[str, str | None]:
    """``path``'s text, and a note when it was read as Windows-1252 (``None`` for UTF-8). The
    file is opened once: a second open of a named pipe waits for a writer that is gone."""
    try:
        raw = read_bytes(path)
    except OSError as exc:
        raise RuleBaseError(unreadable("rule file", path, exc),
                            hint=rule_file_not_found_hint(path)) from None
    wide = wide_text(raw)               # UTF-16 or UTF-32: as every reader says it
    if wide is not None:
        raise FormatError(not_text(path, wide), span=_at(path, raw, wide.start),
                          hint=text_encoding_hint(wide))
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        return _legacy(path, raw[:4], exc), (
            f"`{path.name}` is not UTF-8 ({_byte(path, exc.object, exc.start)}): read "
            "as Windows-1252, the encoding MATLAB and Java write on Windows")
    if "\0" in text:          # valid UTF-8, yet no text a fuzzy-logic tool writes
        raise _nul(path, text.encode("utf-8"))
    return text, None


#: A character of two to four bytes, written as UTF-8 writes it.
_MULTIBYTE = re.compile(rb"[\xc2-\xdf][\x80-\xbf]|[\xe0-\xef][\x80-\xbf]{2}|"
                        rb"[\xf0-\xf4][\x80-\xbf]{3}")


def _legacy(path: Path, head: bytes, exc: UnicodeDecodeError) -> str:
    """The text of ``path``, not UTF-8 (``exc``; ``head`` is its first bytes), as
    Windows-1252, or why it is not that either: a NUL, a file that is UTF-8 elsewhere (read as
    Windows-1252, its UTF-8 would be garbled), a byte Windows-1252 leaves undefined."""
    data: bytes = exc.object            # (without a UTF-8 byte-order mark: the decoder drops it)
    if b"\0" in data:
        raise _nul(path, data)
    utf8 = _MULTIBYTE.search(data)
    if head.startswith(codecs.BOM_UTF8) or utf8 is not None:
        said = ("begins with UTF-8's byte-order mark" if utf8 is None else
                f"is UTF-8 at line {_at(path, data, utf8.start()).line}")
        raise FormatError(f"`{path}` {said}, but {_byte(path, data, exc.start)} is not "
                          "UTF-8", span=_at(path, data, exc.start), hint="save it as UTF-8")
    try:
        return data.decode(LEGACY)
    except UnicodeDecodeError as undefined:
        raise FormatError(f"`{path}` is not a text file ({_byte(path, data, undefined.start)} "
                          "is neither UTF-8 nor Windows-1252 text)",
                          span=_at(path, data, undefined.start)) from None


def _nul(path: Path, data: bytes) -> FormatError:
    """The refusal of a file with a NUL byte in it that is not UTF-16 or UTF-32
    (:func:`~mitos_cli.fileio.wide_text`: refused before)."""
    at = data.find(b"\0")
    return FormatError(f"`{path}` is not a text file ({_byte(path, data, at)})",
                       span=_at(path, data, at))


def _byte(path: Path, data: bytes, start: int) -> str:
    where = _at(path, data, start)
    return f"byte 0x{data[start]:02x} at line {where.line}, column {where.column}"
