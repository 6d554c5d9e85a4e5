"""Progress of long commands (``simulate --runs``, ``compare``): a rich bar on stderr when
stderr is a terminal; otherwise nothing, or for a command that asks for it (``compare``, whose
sweeps run for minutes into a log) a plain line every few percent; and the words for Ctrl-C,
which exits 130 as a shell expects of an interrupted command."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, cast

if TYPE_CHECKING:
    from rich.console import Console
    from rich.progress import Progress, TaskID

#: The exit code of a command stopped by Ctrl-C (128 + SIGINT), as shells report it.
INTERRUPTED = 130

#: The exit code of a command stopped by SIGTERM (128 + SIGTERM), as shells report it.
TERMINATED = 143


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


class Terminated(KeyboardInterrupt):
    """A SIGTERM (``kill PID``, a batch scheduler's time limit) raised where the command is, as
    Ctrl-C raises KeyboardInterrupt: what stops cleanly on one stops so on the other."""


def stopped_code(exc: KeyboardInterrupt) -> int:
    """The exit code of a command stopped by ``exc``: 143 for a SIGTERM, else 130."""
    return TERMINATED if isinstance(exc, Terminated) else INTERRUPTED


@contextmanager
def terminate_as_interrupt() -> Iterator[None]:
    """While the block runs, a SIGTERM raises :class:`Terminated` (``mitos compare``: its
    runs kept, the workers ended, the command that goes on said, where the signal ended the
    process at once and left that to be guessed). Not from a thread other than the main
    one (only it may set a handler), nor where SIGTERM is ignored (a caller's choice)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread() or \
            signal.getsignal(signal.SIGTERM) is signal.SIG_IGN:
        yield
        return

    def terminated(signum: int, frame: object) -> None:
        raise Terminated

    previous = signal.signal(signal.SIGTERM, terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
