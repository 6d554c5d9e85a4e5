"""The ``mitos`` command: registers the commands and turns errors into messages.

Our own errors (:class:`MitosError`) print ``path:line:col: message`` and exit 1; usage errors
exit 2 (Click's convention, and our :class:`~mitos_cli.errors.UsageError`: an option's value
that is not one of its names); anything else is a bug and keeps its traceback.

Typer inspects the signature of every registered command (evaluating its annotations) before
it runs any of them, and each command module imports what it needs. :func:`main` therefore
builds the app with only the command it was asked for (about 30 ms less per ``mitos eval``);
``mitos``, ``mitos --help`` and unknown commands get the whole app.
"""

from __future__ import annotations

import errno
import importlib
import io
import sys
from typing import Annotated

import typer

from ..errors import MitosError, WriteError
from .help import epilog, paragraphs
from .params import OnceCommand

#: One line per command: its name -> (module in this package, command function or Typer app).
COMMANDS: dict[str, tuple[str, str]] = {
    "eval": ("eval_cmd", "eval_command"),
    "convert": ("convert_cmd", "convert_command"),
    "export": ("export_cmd", "export_command"),
    "operators": ("operators_cmd", "operators_command"),
    "check": ("check_cmd", "check_command"),
    "teach": ("teach_cmd", "teach_command"),
    "compare": ("compare_cmd", "compare_command"),
    "simulate": ("simulate_cmd", "simulate_command"),
    "plot": ("plot_cmd", "plot_app"),
    "list": ("list_cmd", "list_command"),
}


def _show_version(value: bool) -> None:
    if value:
        from .._version import __version__

        print(f"mitos {__version__}")
        raise typer.Exit()


def _root(version: Annotated[bool, typer.Option(
        "--version", callback=_show_version, is_eager=True,
        help="Print the version and exit.")] = False) -> None:
    """Instructible neurofuzzy motion planners: evaluate, check, simulate and teach fuzzy rule
    bases. Rule files, term sets, worlds and lessons are documented in the README."""


def build_app(only: str | None = None) -> typer.Typer:
    """The ``mitos`` app with every command, or with just the command ``only``."""
    app = typer.Typer(
        name="mitos",
        help="Instructible neurofuzzy motion planners: evaluate, check, simulate and teach "
             "fuzzy rule bases.",
        no_args_is_help=True,
        add_completion=True,
        pretty_exceptions_enable=False,
        context_settings={"help_option_names": ["-h", "--help"]},
    )
    app.callback()(_root)
    for name, (module, attr) in COMMANDS.items():
        if only is not None and name != only:
            continue
        target = getattr(importlib.import_module(f".{module}", __package__), attr)
        if isinstance(target, typer.Typer):
            app.add_typer(target, name=name)
        else:
            app.command(name, cls=OnceCommand, help=paragraphs(target.__doc__),
                        epilog=epilog(name))(target)
    return app


def __getattr__(name: str):
    if name == "app":                     # the whole app, for tests and embedding
        return build_app()
    raise AttributeError(name)


def main(argv: list[str] | None = None) -> None:
    """Entry point of the console script and ``python -m mitos_cli``.

    Typer answers a Ctrl-C during a command (exit 130, quietly); one while the command is
    being built, or after it, printed a traceback, or "Exception ignored" when it landed in
    Python's own clean-up (joining the batch threads, the atexit callbacks)."""
    try:
        _main(argv)
    except KeyboardInterrupt:
        from .progress import INTERRUPTED

        sys.exit(INTERRUPTED)
    finally:
        if argv is None:               # the process's own command line (not a caller's)
            _end_quietly()


def _end_quietly() -> None:
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


class _ClosedOutput(io.TextIOBase):
    """Standard output the shell closed (``>&-``): Python makes ``sys.stdout`` None, and the
    first line written was an AttributeError's traceback (``--help``: nothing, exit 0). A
    write fails as one to a closed descriptor does (EBADF), which :func:`main` says."""

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        raise OSError(errno.EBADF, "standard output is closed")


def _closed_streams() -> None:
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
        stand_in = _ClosedOutput() if fd == 1 else open(   # noqa: SIM115  (the process's)
            os.devnull, "r" if fd == 0 else "w")
        setattr(sys, name, stand_in)


#: The widths the help and the usage errors may be laid out in: Rich takes COLUMNS as it is,
#: and at COLUMNS=0 (as some CI runners set it) printed an empty help and a usage error
#: without its message (exit 2, nothing said); below 20 the message was cut to pieces, and
#: COLUMNS=99999999999 ended in a MemoryError.
WIDTHS = (20, 1000)


def _sane_widths() -> None:
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


def _main(argv: list[str] | None) -> None:
    _closed_streams()
    _sane_widths()
    args = sys.argv[1:] if argv is None else list(argv)
    first = args[0] if args else None
    app = build_app(first if first in COMMANDS else None)
    try:
        from ..engine.threads import given

        if not _asks_about(args):
            given()                # MITOS_NUM_THREADS, refused before any command runs
        app(args=args, prog_name="mitos", standalone_mode=True)
    except MitosError as exc:
        from .output import report_error

        report_error(exc)
        sys.exit(exc.exit_code)
    except OSError as exc:
        # a path argument the system refuses to look up (a name over 255 characters): the
        # user's input, not a bug, wherever in a command it was first used; or a full disk
        # under what the command writes (its output redirected to a file, /dev/full)
        from .output import report_error

        if exc.errno in (errno.ENAMETOOLONG, errno.ELOOP):
            report_error(path_error(exc))
        elif exc.errno == errno.EBADF and isinstance(sys.stdout, _ClosedOutput):
            report_error(WriteError("cannot write the output: standard output is closed",
                                    hint="write it to a file, or to /dev/null to drop it"))
        elif exc.errno in (errno.ENOSPC, errno.EDQUOT, errno.EIO, errno.EFBIG):
            report_error(WriteError(f"cannot write the output: {exc.strerror}",
                                    hint="free some space, or write somewhere else"))
        else:
            raise
        sys.exit(1)
    except UnicodeEncodeError as exc:
        from .output import report_error

        if not _of_stdout(exc):
            raise
        report_error(_unencodable(exc))
        sys.exit(1)


def _of_stdout(exc: UnicodeEncodeError) -> bool:
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


def _unencodable(exc: UnicodeEncodeError) -> MitosError:
    """Output stdout's encoding cannot write (the plots' Braille, a table's ``±``, a name):
    it was a UnicodeEncodeError's traceback after part of the output."""
    char = exc.object[exc.start]
    return WriteError(f"cannot write the output: standard output's encoding ({exc.encoding}) "
                      f"has no `{char}` (U+{ord(char):04X})",
                      hint="set PYTHONIOENCODING=utf-8, or use a UTF-8 locale")


#: Options that ask what MITOS or a command is, and run nothing.
ABOUT = ("-h", "--help", "--version", "--show-completion", "--install-completion")


def _asks_about(args: list[str]) -> bool:
    """The help, the version or the shell's completion: nothing of a wrong MITOS_NUM_THREADS
    is used there, and it refused them all (the completion printed its error as words)."""
    import os

    options = args[:args.index("--")] if "--" in args else args
    return not args or "_MITOS_COMPLETE" in os.environ or any(a in ABOUT for a in options)


def path_error(exc: OSError) -> MitosError:
    """An ``OSError`` about a path the system cannot look up, in words."""
    name = str(exc.filename) if exc.filename is not None else ""
    shown = name if len(name) <= 80 else name[:40] + "..." + name[-30:]
    if exc.errno == errno.ELOOP:
        return MitosError(f"`{shown}`: too many levels of symbolic links")
    return MitosError(f"the path `{shown}` is too long ({len(name):,} characters)",
                      hint="each part of a path may have at most 255 characters")
