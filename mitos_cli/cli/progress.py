"""Progress of long commands (``simulate --runs``, ``compare``): a rich bar on stderr when
stderr is a terminal; otherwise nothing, or for a command that asks for it (``compare``, whose
sweeps run for minutes into a log) a plain line every few percent; and the words for Ctrl-C,
which exits 130 as a shell expects of an interrupted command."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, cast

from ..errors import Terminated

if TYPE_CHECKING:
    from rich.console import Console
    from rich.progress import Progress, TaskID

#: The exit code of a command stopped by Ctrl-C (128 + SIGINT), as shells report it.
INTERRUPTED = 130

#: The exit code of a command stopped by SIGTERM (128 + SIGTERM), as shells report it.
TERMINATED = 143

#: The exit code of a command stopped by SIGHUP (128 + SIGHUP): its terminal closed.
HUNG_UP = 129


#: Off a terminal, a progress line each time this many more percent are done.
LINE_EVERY_PERCENT = 5


class Bar:
    """What a command tells the bar: :meth:`update` ``(done, total)`` and :meth:`note`.
    Without a rich progress, ``lines`` prints ``what: done of total (p%)`` every few
    percent instead (nothing when it is false)."""

    def __init__(self, progress: Progress | None, console: Console, lines: bool = False,
                 what: str = "") -> None:
        self.progress, self.console, self.lines = progress, console, lines
        # described from the start: the bar's first frame had no words
        self.task = progress.add_task(what, total=None) if progress is not None else None
        self.what, self.shown = what, -1

    def update(self, done: int, total: int) -> None:
        if self.progress is not None:
            self.progress.update(cast("TaskID", self.task), completed=done, total=total)
        elif self.lines and total > 0:
            step = done * 100 // total // LINE_EVERY_PERCENT
            if step > self.shown:
                self.shown = step
                self.note(f"{self.what}: {done} of {total} ({done * 100 // total}%)")

    def describe(self, text: str) -> None:
        self.what = text
        if self.progress is not None:
            self.progress.update(cast("TaskID", self.task), description=text)

    def status(self, text: str) -> None:
        """Words after the description on the bar (``simulate slalom: runs at 12 s``) while
        nothing it counts has changed; off a terminal nothing (the lines keep their words)."""
        if self.progress is not None:
            self.progress.update(cast("TaskID", self.task), description=f"{self.what}: {text}")

    def note(self, text: str) -> None:
        """A line above the bar (on stderr, plain text: never read as markup)."""
        self.console.print(text, markup=False, highlight=False)


@contextmanager
def progress_bar(description: str, quiet: bool = False, lines: bool = False) -> Iterator[Bar]:
    """A bar labelled ``description`` while the block runs; none when ``quiet`` (``--json``).
    Off a terminal, plain lines every few percent if ``lines``, else nothing. The bar
    disappears when the block ends."""
    from rich.console import Console

    console = Console(stderr=True, highlight=False)
    if quiet or not console.is_terminal:
        yield Bar(None, console, lines=lines and not quiet, what=description)
        return
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                  TimeElapsedColumn(), TextColumn("eta"), TimeRemainingColumn(),
                  console=console, transient=True) as progress:
        yield Bar(progress, console, what=description)


def stopped_code(exc: BaseException) -> int:
    """The exit code of a command stopped by ``exc``: 143 for a SIGTERM, 129 for a SIGHUP,
    else 130."""
    return exc.code if isinstance(exc, Terminated) else INTERRUPTED


#: The signals that stop a command as Ctrl-C does (SIGHUP: not on Windows).
STOPPING = ("SIGTERM", "SIGHUP")


@contextmanager
def terminate_as_interrupt() -> Iterator[None]:
    """While the block runs, a SIGTERM or a SIGHUP raises :class:`Terminated` (``mitos
    compare`` and ``simulate``: the runs done kept, the workers ended, what was kept said,
    where the signal ended the process at once and left that to be guessed). Not from a
    thread other than the main one (only it may set a handler), nor for a signal ignored
    (a caller's choice: ``nohup`` ignores SIGHUP so that the command goes on)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def terminated(signum: int, frame: object) -> None:
        if signum != signal.SIGTERM:
            drop_lost_terminal()
        raise Terminated(128 + signum)

    previous = {}
    for name in STOPPING:
        number = getattr(signal, name, None)
        if number is not None and signal.getsignal(number) is not signal.SIG_IGN:
            previous[number] = signal.signal(number, terminated)
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


def drop_lost_terminal() -> None:
    """Point stdout and stderr at the null device where they are a terminal that has hung up
    (closed: every write to it fails, EIO). The words of a stop on SIGHUP, and the progress
    bar's last frame, ended in "cannot write the output: Input/output error" and exit 1 (a
    traceback where stderr was that terminal too). A file or a pipe is kept (``2> log``:
    the log says what was kept), and so is a terminal still there (``kill -HUP``)."""
    import errno
    import os

    for fd in (1, 2):
        try:
            os.write(fd, b"")           # (nothing; on a terminal hung up, EIO)
        except OSError as exc:
            if exc.errno == errno.EIO:
                null = os.open(os.devnull, os.O_WRONLY)
                os.dup2(null, fd)
                os.close(null)
