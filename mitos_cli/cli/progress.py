"""Progress of long commands (``simulate --runs``, ``compare``): a rich bar on stderr when
stderr is a terminal, nothing otherwise (a pipe or a file gets only the result), and the
words for Ctrl-C, which exits 130 as a shell expects of an interrupted command."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

#: The exit code of a command stopped by Ctrl-C (128 + SIGINT), as shells report it.
INTERRUPTED = 130


class Bar:
    """What a command tells the bar: :meth:`update` ``(done, total)`` and :meth:`note`."""

    def __init__(self, progress, console) -> None:
        self.progress, self.console = progress, console
        self.task = progress.add_task("", total=None) if progress is not None else None

    def update(self, done: int, total: int) -> None:
        if self.progress is not None:
            self.progress.update(self.task, completed=done, total=total)

    def describe(self, text: str) -> None:
        if self.progress is not None:
            self.progress.update(self.task, description=text)

    def note(self, text: str) -> None:
        """A line above the bar (on stderr, plain text: never read as markup)."""
        self.console.print(text, markup=False, highlight=False)


@contextmanager
def progress_bar(description: str, quiet: bool = False) -> Iterator[Bar]:
    """A bar labelled ``description`` while the block runs; none when ``quiet`` (``--json``)
    or when stderr is not a terminal. It disappears when the block ends."""
    from rich.console import Console

    console = Console(stderr=True, highlight=False)
    if quiet or not console.is_terminal:
        yield Bar(None, console)
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
        bar = Bar(progress, console)
        bar.describe(description)
        yield bar
