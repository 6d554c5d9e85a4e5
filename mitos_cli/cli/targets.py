"""Where ``convert``, ``export`` and ``simulate`` may write: a file whose extension says what it
holds, in a directory that is there, and never one of the files the command reads (nothing the
user wrote is ever lost)."""

from __future__ import annotations

import os
from pathlib import Path

import typer

OUTPUT_OPTION = "'-o' / '--output'"


def check_suffix(path: Path, suffix: str, what: str, option: str = OUTPUT_OPTION) -> None:
    """``-o`` must end in ``suffix`` (any case): a C file called ``out.py`` or an FCL file
    called ``out.fis`` would be read later as what it is not. A device or a pipe
    (``/dev/stdout``) has no extension to check."""
    if _special(path) or path.suffix.lower() == suffix:
        return
    has = f"extension {path.suffix}" if path.suffix else "no extension"
    raise typer.BadParameter(f"`{path}` has {has}; {what} is written to a {suffix} file",
                             param_hint=option)


def check_directory(path: Path) -> None:
    """Refuse, before any work, a file that cannot be written where it is named: its directory
    missing or not writable, or the name a directory's. ``simulate --runs 1000 --plot
    typo/runs.png`` ran every run, then failed on the picture and lost them all. (The check
    itself is :func:`mitos_cli.fileio.check_writable`, which scripts below the CLI use too.)"""
    from ..fileio import check_writable

    check_writable(path)


def source_files(rulebase: object, path: Path) -> list[tuple[Path, str]]:
    """The files ``rulebase`` was read from, each with a phrase saying what it is: the rule
    file and the term sets its ``terms`` line names."""
    files = [(path, "the input")]
    for rel in getattr(rulebase, "termset_paths", ()):
        files.append((path.parent / rel, f"a term set `{path.name}` reads (`terms \"{rel}\"`)"))
    return files


def refuse_inputs(targets: list[Path], sources: list[tuple[Path, str]]) -> None:
    """A usage error (exit 2) when a file about to be written is one of ``sources`` (through
    a symbolic or hard link too)."""
    for target in targets:
        for source, what in sources:
            if same_file(target, source):
                raise typer.BadParameter(f"`{target}` would overwrite {what}; give -o another "
                                         f"name", param_hint=OUTPUT_OPTION)


def refuse_strays(named: Path, companions: list[Path]) -> None:
    """A usage error when a file written beside ``named`` (the term set of ``-o OUT.rules``)
    is already there and is not ``named``'s own (the existing ``named`` does not read it):
    the user named only ``named``."""
    from ..lang.resolve import strays

    for path in strays(named, companions):
        raise typer.BadParameter(
            f"`{path}` is already there and no term set of `{named}`; writing `{named}` "
            f"would write its term set over it: remove it, or choose another -o",
            param_hint=OUTPUT_OPTION)


def refuse_existing(targets: list[Path], named: str) -> None:
    """A usage error when a file written by default (no ``-o``) is already there: only a file
    the user names on purpose is replaced."""
    for target in targets:
        if target.exists() or target.is_symlink():
            raise typer.BadParameter(
                f"`{target}` is already there and without -o nothing is overwritten; "
                f"`-o {named}` replaces it on purpose, or write elsewhere with -o",
                param_hint=OUTPUT_OPTION)


def same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` are one file (a link to it included); a path that is not there
    yet is compared by its resolved name."""
    from ..fileio import real_path

    try:
        return os.path.samefile(a, b)
    except OSError:             # (a link in a loop is no file: the write says so)
        return real_path(a) == real_path(b)


def _special(path: Path) -> bool:
    try:
        return path.exists() and not path.is_file() and not path.is_dir()
    except OSError:
        return False
