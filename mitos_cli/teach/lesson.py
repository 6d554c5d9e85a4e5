"""Scripted lessons: the prompt's commands from a file (or stdin), stopping at the first error.

A lesson is one command per line; blank lines and ``#`` comments are skipped; a rule may
continue on the following lines (as in a rule file). The first command that fails raises its
:class:`~mitos_cli.errors.MitosError` with the lesson's ``path:line:col``, so a lesson is
reproducible and testable (``mitos teach ... --lesson FILE`` exits 1).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

from ..errors import MitosError, Span, WorldError, visible
from ..resources import exists
from .commands import incomplete
from .session import Session
from .text import quoted_column


def commands(text: str) -> Iterator[tuple[int, str]]:
    """``(first line number, command text)`` for each command of a lesson."""
    lines = lines_of(text)
    i = 0
    while i < len(lines):
        line = lines[i]
        start = i + 1
        i += 1
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        while incomplete(line) and i < len(lines) and lines[i].strip() \
                and not lines[i].lstrip().startswith("#"):
            line += "\n" + lines[i]
            i += 1
        yield start, line


def run_lesson(session: Session, text: str, path: str) -> bool:
    """Run every command of ``text``; False when the lesson said ``quit``. Ctrl-C stops the
    lesson (``KeyboardInterrupt``), also when an ``adapt`` caught it to keep its epochs. Its
    ``save PATH`` stays below the working directory (:attr:`Session.confined`)."""
    session.confined = Path.cwd()
    try:
        return _run(session, text, path)
    finally:
        session.confined = None


def _run(session: Session, text: str, path: str) -> bool:
    for lineno, line in commands(text):
        session.echo(f"{path}:{lineno}> {visible(line.splitlines()[0])}")
        session.interrupted = False
        was_open = session.state.block
        try:
            if not session.run(line, path, lineno):
                return False
            if session.interrupted:         # Ctrl-C in an `adapt`: what it learned is kept
                raise KeyboardInterrupt     # (journaled); the rest of the lesson is not run
            if session.state.block != was_open:     # where it opened, for the lesson's end
                session.opened_at = None if session.state.block is None else Span.in_text(
                    "\n" * (lineno - 1) + line, path, lineno, len(line) - len(line.lstrip()) + 1)
        except MitosError as exc:
            if isinstance(exc, WorldError) and exc.span is not None \
                    and exc.span.path not in (None, "<prompt>", path):
                exc.message += f" (simulated from {path}:{lineno})"   # where the world is wrong
                raise
            if exc.span is None or exc.span.path != path:
                start, end = quoted_column(exc.message, line)
                where = Span.in_text("\n" * (lineno - 1) + line, path, lineno, start,
                                     end or None)
                if exc.span is not None and exc.span.path in (None, "<prompt>"):
                    where = Span.in_text("\n" * (lineno - 1) + line, path, lineno,
                                         exc.span.column, exc.span.end_column)
                exc.span = where
            raise
    return True


def lines_of(text: str) -> list[str]:
    """The lines of a lesson as an editor counts them: ``str.splitlines`` also breaks at a form
    feed, U+2028 or U+0085 inside a line, so every line after one was named one too far on."""
    lines = re.split(r"\r\n|\r|\n", text)
    return lines[:-1] if lines[-1:] == [""] else lines


def lesson_end(text: str, path: str) -> Span:
    """Just after the last character of the lesson (where a missing ``end`` would go)."""
    lines = lines_of(text) or [""]
    return Span.in_text(text, path, len(lines), len(lines[-1]) + 1)


def read_lesson(source: str) -> tuple[str, str]:
    """The lesson text and the name to report (``-`` reads stdin)."""
    import sys

    from ..errors import LessonError
    from ..resources import resolve

    if source == "-":
        return sys.stdin.read(), "<stdin>"
    path = Path(source)
    if not exists(path):                   # a packaged lesson by name: `--lesson wider-turn`
        found = resolve("rulebases/lessons", source, ".lesson")
        if found is not None:
            path, source = found, str(found)
    from ..fileio import bad_byte, broken_link, read_text, unreadable

    try:
        return read_text(path), source
    except (OSError, UnicodeDecodeError) as exc:
        error = LessonError(unreadable("lesson", source, exc), span=bad_byte(source, exc))
        if isinstance(exc, FileNotFoundError) and broken_link("lesson", path) is None:
            # a mistyped name: a lesson file beside it, else the packaged lessons
            from ..errors import did_you_mean
            from ..fileio import nearby
            from ..resources import packaged_names

            names = [n[:-len(".lesson")] for n in packaged_names("rulebases/lessons", ".lesson")]
            error.expected = "a lesson file, or a packaged lesson: " + ", ".join(names)
            error.hint = nearby(path, (".lesson",)) or did_you_mean(path.stem, names)
        raise error from None
