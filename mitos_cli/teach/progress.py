"""The adaptation progress bar (rich, on stderr, only on a terminal)."""

from __future__ import annotations


class EpochProgress:
    """``update(epoch, Q)`` per epoch; ``close()`` at the end. Silent without a terminal."""

    def __init__(self, epochs: int) -> None:
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

        console = Console(stderr=True)
        self.progress = Progress(TextColumn("adapting"), BarColumn(), MofNCompleteColumn(),
                                 TextColumn("{task.fields[q]}"), TimeElapsedColumn(),
                                 console=console, transient=True,
                                 disable=not console.is_terminal)
        self.task = self.progress.add_task("adapt", total=epochs, q="")
        self.progress.start()

    def update(self, epoch: int, q: float) -> None:
        self.progress.update(self.task, completed=epoch, q=f"Q = {q:.6g}")

    def close(self) -> None:
        self.progress.stop()


def epoch_progress(epochs: int) -> EpochProgress:
    return EpochProgress(epochs)
