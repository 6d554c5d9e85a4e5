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
import sys
from typing import Annotated

import typer

from ..errors import MitosError, WriteError
from .help import epilog, paragraphs
from .meant import MeantGroup
from .params import OnceCommand
from .streams import ClosedOutput, closed_streams, end_quietly, of_stdout, sane_widths, unencodable

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
    "docs": ("docs_cmd", "docs_command"),
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


def _version() -> None:
    """Print the version of MITOS, as `mitos --version` does."""
    from .._version import __version__

    print(f"mitos {__version__}")


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
        cls=MeantGroup,
    )
    app.callback()(_root)
    if only == "version":           # `mitos version`, as `git version`: built for it alone,
        app.command("version", cls=OnceCommand,  # so that `mitos --help` lists --version once
                    help=paragraphs(_version.__doc__))(_version)
        return app
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


def __getattr__(name: str) -> typer.Typer:
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
            end_quietly()


def _main(argv: list[str] | None) -> None:
    closed_streams()
    sane_widths()
    args = sys.argv[1:] if argv is None else list(argv)
    if args[:1] == ["help"]:        # `mitos help`, `mitos help plot terms`: as git's and pip's
        words = args[1:]                # (it said "No such command 'help'", exit 2)
        while words[:1] == ["help"]:    # `mitos help help`: the help of mitos
            words = words[1:]
        args = [*words, "--help"]
    first = args[0] if args else None
    # `mitos version` (as `git version`; it was "No such command"), with its --help
    app = build_app(first if first in COMMANDS or first == "version" else None)
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
        elif exc.errno == errno.EBADF and isinstance(sys.stdout, ClosedOutput):
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

        if not of_stdout(exc):
            raise
        report_error(unencodable(exc))
        sys.exit(1)


#: Options that ask what MITOS or a command is, and run nothing.
ABOUT = ("-h", "--help", "--version", "--show-completion", "--install-completion")


def _asks_about(args: list[str]) -> bool:
    """The help, the version or the shell's completion: nothing of a wrong MITOS_NUM_THREADS
    is used there, and it refused them all (the completion printed its error as words)."""
    import os

    options = args[:args.index("--")] if "--" in args else args
    return (not args or args[:1] == ["version"] or "_MITOS_COMPLETE" in os.environ
            or any(a in ABOUT for a in options))


def path_error(exc: OSError) -> MitosError:
    """An ``OSError`` about a path the system cannot look up, in words."""
    name = str(exc.filename) if exc.filename is not None else ""
    shown = name if len(name) <= 80 else name[:40] + "..." + name[-30:]
    if exc.errno == errno.ELOOP:
        return MitosError(f"`{shown}`: too many levels of symbolic links")
    return MitosError(f"the path `{shown}` is too long ({len(name):,} characters)",
                      hint="each part of a path may have at most 255 characters")
