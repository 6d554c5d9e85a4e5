"""Scripted lessons: the prompt's commands from a file (or stdin), stopping at the first error.

A lesson is one command per line; blank lines and ``#`` comments are skipped; a rule may
continue on the following lines (as in a rule file). The first command that fails raises its
:class:`~mitos_cli.errors.MitosError` with the lesson's ``path:line:col``, so a lesson is
reproducible and testable (``mitos teach ... --lesson FILE`` exits 1).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from ..errors import (
    LessonError,
    MitosError,
    RuleSyntaxError,
    Span,
    WorldError,
    lines_of,
    visible,
)
from ..lang.parse import MAX_RULE_FILE_CHARS
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


#: the longest lesson read (characters), as a rule file (:data:`MAX_RULE_FILE_CHARS`)
MAX_LESSON_CHARS = MAX_RULE_FILE_CHARS
#: the most lines of commands a lesson may hold (blank lines and comments aside): a told rule
#: takes about 1 ms, so 100,000 run in some two minutes, as many rules as a rule file's
#: documented size; a lesson of millions ran for hours, with no limit
MAX_LESSON_LINES = 100_000


def check_lesson_size(text: str, path: str) -> None:
    """Refuse a lesson past :data:`MAX_LESSON_CHARS` or :data:`MAX_LESSON_LINES` before any
    of it runs, at its first line or at the first line past the limit."""
    if len(text) > MAX_LESSON_CHARS:
        raise LessonError(f"the lesson holds {len(text):,} characters; a lesson may hold at "
                          f"most {MAX_LESSON_CHARS:,} ({MAX_LESSON_CHARS >> 20} MB)",
                          span=Span(path, 1, 1), hint="split it into several lessons")
    said = 0
    for lineno, line in enumerate(lines_of(text), 1):
        if line.strip() and not line.lstrip().startswith("#"):
            said += 1
            if said > MAX_LESSON_LINES:
                raise LessonError(
                    f"the lesson holds more than {MAX_LESSON_LINES:,} lines of commands",
                    span=Span.in_text("\n" * (lineno - 1) + line, path, lineno, 1),
                    expected=f"at most {MAX_LESSON_LINES:,} lines of commands (blank lines "
                             f"and comments aside)", hint="split it into several lessons")


def run_lesson(session: Session, text: str, path: str) -> bool:
    """Run every command of ``text``; False when the lesson said ``quit``. Ctrl-C stops the
    lesson (``KeyboardInterrupt``; a SIGTERM or a SIGHUP, where the CLI answers them, its
    :class:`~mitos_cli.errors.Terminated`), also when an ``adapt`` caught it to keep its
    epochs. Its
    ``save PATH`` stays below the working directory (:attr:`Session.confined`). A lesson past
    the limits (:func:`check_lesson_size`) is refused before it runs."""
    check_lesson_size(text, path)
    session.confined = Path.cwd()
    try:
        return _run(session, text, path)
    finally:
        session.confined = None


def _run(session: Session, text: str, path: str) -> bool:
    for lineno, line in commands(text):
        session.echo(f"{path}:{lineno}> {visible(line.splitlines()[0])}")
        session.interrupted = None
        was_open = session.state.block
        try:
            if not session.run(line, path, lineno):
                return False
            if session.interrupted:         # Ctrl-C in an `adapt`: what it learned is kept
                raise session.interrupted   # (journaled); the rest of the lesson is not run
            if session.state.block != was_open:     # where it opened, for the lesson's end
                session.opened_at = None if session.state.block is None else Span.in_text(
                    "\n" * (lineno - 1) + line, path, lineno, len(line) - len(line.lstrip()) + 1)
        except MitosError as exc:
            if isinstance(exc, RuleSyntaxError):
                exc.hint = not_a_lesson(path) or exc.hint
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


def not_a_lesson(path: str) -> str | None:
    """What a file of another of MITOS's kinds, given to --lesson, is (by its extension):
    `mitos teach --lesson rulebases/mitos.rules` stopped at `terms` with "type `help`", a
    world at `name: figure4` with "expected `if`"."""
    name = Path(path).name
    suffix = Path(path).suffix.lower()
    if suffix == ".rules":
        return (f"`{name}` is a rule base, not a lesson: give it before the options "
                f"(`mitos teach {path} [--lesson LESSON]`)")
    if suffix in (".fcl", ".fis", ".fll"):
        return (f"`{name}` is a rule base, not a lesson: `mitos teach` reads the rule "
                f"language, so convert it (`mitos convert {path} --to rules`) and give the "
                f".rules file before the options")
    if suffix in (".yaml", ".yml"):
        return (f"`{name}` is a YAML file (a world, or a term set), not a lesson: a lesson "
                f"drives a world with `simulate {path}`")
    if suffix == ".csv":
        return (f"`{name}` is a CSV file, not a lesson: `mitos eval --batch {path}` "
                f"evaluates its rows; a lesson gives examples with `correct NAME=VALUE ... -> "
                f"OUTPUT=VALUE`")
    return None


def lesson_end(text: str, path: str) -> Span:
    """Just after the last character of the lesson (where a missing ``end`` would go)."""
    lines = lines_of(text) or [""]
    return Span.in_text(text, path, len(lines), len(lines[-1]) + 1)


def _read_stdin() -> str:
    """A lesson on stdin, read as a lesson file is (:func:`~mitos_cli.fileio.read_text`):
    UTF-8, a byte-order mark skipped, a byte that is not UTF-8 said at its line and column (as
    text it was a UnicodeDecodeError traceback, or a name holding `\\udce9`). No more than
    the limit and a character is kept."""
    import sys

    buffer = getattr(sys.stdin, "buffer", None)
    if buffer is None:                  # (a text stream with no bytes under it; none, closed)
        return sys.stdin.read(MAX_LESSON_CHARS + 1) if sys.stdin is not None else ""
    limit = 4 * (MAX_LESSON_CHARS + 1)  # bytes that hold a character past the limit
    data = buffer.read(limit)
    if len(data) >= limit:              # past the limit whatever it holds: said by its size
        return data.decode("utf-8-sig", errors="replace")
    from ..fileio import bad_byte, decode_text, text_encoding_hint, unreadable

    try:
        return decode_text(data)
    except UnicodeDecodeError as exc:
        raise LessonError(unreadable("lesson", "<stdin>", exc), span=bad_byte("<stdin>", exc),
                          hint=text_encoding_hint(exc)) from None


def read_lesson(source: str) -> tuple[str, str]:
    """The lesson text and the name to report (``-`` reads stdin)."""
    from ..resources import resolve

    if source == "-":
        text = _read_stdin()
        check_lesson_size(text, "<stdin>")
        return text, "<stdin>"
    path = Path(source)
    if not exists(path):                   # a packaged lesson by name: `--lesson wider-turn`
        found = resolve("rulebases/lessons", source, ".lesson")
        if found is not None:
            path, source = found, str(found)
    from ..fileio import bad_byte, broken_link, read_text, text_encoding_hint, unreadable

    try:
        text = read_text(path)
    except (OSError, UnicodeDecodeError) as exc:
        error = LessonError(unreadable("lesson", source, exc), span=bad_byte(source, exc),
                            hint=text_encoding_hint(exc))
        if isinstance(exc, FileNotFoundError) and broken_link("lesson", path) is None:
            # a mistyped name: a lesson file beside it, else the packaged lessons
            from ..errors import did_you_mean
            from ..fileio import nearby
            from ..resources import packaged_names

            names = [n[:-len(".lesson")] for n in packaged_names("rulebases/lessons", ".lesson")]
            error.expected = "a lesson file, or a packaged lesson: " + ", ".join(names)
            # `--lesson rulebases/mitos.rules` away from the repository: a packaged file, of
            # another kind, which `mitos teach` finds from anywhere
            packaged = path.suffix and (resolve("rulebases", source, ".rules")
                                        or resolve("worlds", source, ".yaml"))
            error.hint = (not_a_lesson(source) if packaged else None) \
                or nearby(path, (".lesson",)) or did_you_mean(path.stem, names)
        raise error from None
    check_lesson_size(text, source)             # before a session exists
    return text, source
