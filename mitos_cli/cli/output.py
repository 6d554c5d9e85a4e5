"""Where the CLI writes: data to stdout, diagnostics to stderr (user text never as markup)."""

from __future__ import annotations

import sys

from ..errors import MitosError


def err(message: str) -> None:
    """A diagnostic line on stderr."""
    print(message, file=sys.stderr)


def warn(message: str) -> None:
    err(f"warning: {message}")


def warn_notes(rulebase) -> None:
    """What a foreign file's reader changed to make the file fit, one warning each."""
    for note in getattr(rulebase, "notes", ()):
        warn(note)


def report_error(exc: MitosError) -> None:
    err(exc.render())


def emit(text: str) -> None:
    """Data on stdout."""
    sys.stdout.write(text if text.endswith("\n") else text + "\n")
