"""What the benchmark scripts share at their command line: option values checked by argparse
(a wrong one is a usage error, exit 2, before anything runs), files written at the end checked
before a run that may take hours, and errors said in one line (exit 1), never a traceback."""

from __future__ import annotations

import argparse
import functools
import io
import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))                      # this source tree's MITOS, not another

from mitos_cli.errors import MitosError  # noqa: E402


def positive_int(text: str) -> int:
    """An option's whole number of 1 or more (runs, repeats, workers, ...)."""
    return _int_from(text, 1)


def count(text: str) -> int:
    """An option's whole number of 0 or more."""
    return _int_from(text, 0)


def _int_from(text: str, least: int) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"`{text}` is not a whole number") from None
    if value < least:
        raise argparse.ArgumentTypeError(f"`{text}`: must be at least {least}")
    return value


def directory(text: str) -> Path:
    """An existing directory (a mistyped one would otherwise be searched to nothing)."""
    path = Path(text)
    if not path.is_dir():
        raise argparse.ArgumentTypeError(f"`{text}` is not a directory")
    return path


def writable(text: str) -> Path:
    """A file the run will write, checked now (:func:`mitos_cli.fileio.check_writable`, as
    the commands check theirs): a path it cannot write is said before the run, not after it
    with the figures lost."""
    from mitos_cli.fileio import check_writable

    try:
        check_writable(text)
    except MitosError as exc:
        raise argparse.ArgumentTypeError(exc.message) from None
    return Path(text)


def revision(text: str) -> str:
    """A git revision of this repository (``--against REV``)."""
    found = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--verify", "--quiet",
                            f"{text}^{{commit}}"], capture_output=True)
    if found.returncode != 0 or text.startswith("-"):
        raise argparse.ArgumentTypeError(f"unknown revision `{text}`")
    return text


def guarded(main: Callable[..., int | None]) -> Callable[..., int]:
    """``main`` with a MitosError rendered as ``mitos`` renders it and an OSError said in one
    line, both exit 1, instead of a traceback."""

    @functools.wraps(main)
    def run(argv: list[str] | None = None) -> int:
        try:
            return main(argv) or 0
        except MitosError as exc:
            print(exc.render(), file=sys.stderr)
            return 1
        except BrokenPipeError:
            # the reader went away (`| head`): said nothing, as `mitos` says nothing; it read
            # "error: Broken pipe"
            _quiet_stdout()
            return 1
        except OSError as exc:
            where = f": `{exc.filename}`" if exc.filename else ""
            print(f"error: {exc.strerror or exc}{where}", file=sys.stderr)
            return 1

    return run


def _quiet_stdout() -> None:
    """Stdout on the null device, so that the interpreter's last flush, of what the closed
    pipe did not take, raises nothing more at exit."""
    try:
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, sys.stdout.fileno())
        os.close(null)
    except (OSError, ValueError, io.UnsupportedOperation):
        pass
