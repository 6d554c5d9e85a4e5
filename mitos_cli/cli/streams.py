"""The process's standard streams and terminal, made safe before a command runs and after it
ends: a closed stdin, stdout or stderr, a COLUMNS no layout can use, an encoding without a
character the output holds, and a Ctrl-C in Python's own clean-up (:func:`.app.main`)."""

from __future__ import annotations

import errno
import io
import sys

from ..errors import MitosError, WriteError


def end_quietly() -> None:
    """From here a Ctrl-C ends the process as the signal does (its status says interrupted,
    as a shell expects), not with a Python traceback from the clean-up it interrupts; what
    the command wrote is flushed now, so that none of it waits for that clean-up (a flush
    blocked on a slow reader is interrupted as the signal does too)."""
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_DFL)
    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):   # said by the command already, or by Python at exit
            pass


class ClosedOutput(io.TextIOBase):
    """Standard output the shell closed (``>&-``): Python makes ``sys.stdout`` None, and the
    first line written was an AttributeError's traceback (``--help``: nothing, exit 0). A
    write fails as one to a closed descriptor does (EBADF), which :func:`.app.main` says."""

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        raise OSError(errno.EBADF, "standard output is closed")


def closed_streams() -> None:
    """Stand in for a closed stdin, stdout or stderr (Python makes them None), and keep
    descriptors 0-2 taken by /dev/null, so that no file the command opens gets their number.
    A closed stdin reads as empty (`teach` ends as at Ctrl-D, `eval --batch -` says the CSV
    is empty; each was an AttributeError's traceback). With stderr closed,
    ``print(..., file=sys.stderr)`` writes to stdout: the warnings and errors went into the
    data (the first line of `export --to c 2>&- > planner.c`)."""
    import os

    for fd, name in ((0, "stdin"), (1, "stdout"), (2, "stderr")):
        if getattr(sys, name) is not None:
            continue
        try:
            os.fstat(fd)
        except OSError:                     # free: hold it
            null = os.open(os.devnull, os.O_RDONLY if fd == 0 else os.O_WRONLY)
            if null != fd:
                os.dup2(null, fd)
                os.close(null)
        # stderr: what would be said has nowhere to go (the exit code still says it)
        stand_in = ClosedOutput() if fd == 1 else open(   # noqa: SIM115  (the process's)
            os.devnull, "r" if fd == 0 else "w")
        setattr(sys, name, stand_in)


#: The widths the help and the usage errors may be laid out in: Rich takes COLUMNS as it is,
#: and at COLUMNS=0 (as some CI runners set it) printed an empty help and a usage error
#: without its message (exit 2, nothing said); below 20 the message was cut to pieces, and
#: COLUMNS=99999999999 ended in a MemoryError.
WIDTHS = (20, 1000)


def sane_widths() -> None:
    """COLUMNS (Rich's) and TERMINAL_WIDTH (Typer's) within :data:`WIDTHS`; 0 means unknown
    (unset), and a TERMINAL_WIDTH that is not a number is dropped (Typer's ``int()`` of it
    was a ValueError's traceback)."""
    import os

    for name in ("COLUMNS", "TERMINAL_WIDTH"):
        text = os.environ.get(name, "").strip()
        if not text:
            continue
        if not (text.isascii() and text.isdigit()):
            if name == "TERMINAL_WIDTH":
                del os.environ[name]
            continue                                    # (Rich ignores it)
        digits = text.lstrip("0")               # (int() of 5,000 digits raises)
        width = int(digits or "0") if len(digits) <= 6 else WIDTHS[1] + 1
        if width == 0:
            del os.environ[name]
        elif not WIDTHS[0] <= width <= WIDTHS[1]:
            os.environ[name] = str(min(max(width, WIDTHS[0]), WIDTHS[1]))


def of_stdout(exc: UnicodeEncodeError) -> bool:
    """Whether ``exc`` is stdout's encoding failing (an ASCII or Latin-1 locale,
    PYTHONIOENCODING=ascii, a Windows console's code page)."""
    import codecs

    encoding = getattr(sys.stdout, "encoding", None)
    try:
        codec = codecs.lookup(exc.encoding)
        return (encoding is not None and codec == codecs.lookup(encoding)
                and not codec.name.startswith("utf"))     # (UTF-8 writes every character:
    except LookupError:                                   # a lone surrogate is a file's)
        return False


def unencodable(exc: UnicodeEncodeError) -> MitosError:
    """Output stdout's encoding cannot write (the plots' Braille, a table's ``±``, a name):
    it was a UnicodeEncodeError's traceback after part of the output."""
    char = exc.object[exc.start]
    return WriteError(f"cannot write the output: standard output's encoding ({exc.encoding}) "
                      f"has no `{char}` (U+{ord(char):04X})",
                      hint="set PYTHONIOENCODING=utf-8, or use a UTF-8 locale")
