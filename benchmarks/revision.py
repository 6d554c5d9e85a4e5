"""A git revision's ``mitos_cli`` imported beside this tree's, for benchmarks that time both in
one process (``--against REV``): interleaved rounds in one process see the same load, which
separate runs of two trees do not."""

from __future__ import annotations

import contextlib
import importlib
import shutil
import subprocess
import sys
import traceback
from collections.abc import Iterator
from pathlib import Path

from mitos_cli.errors import MitosError

#: the name the other tree's package is imported under
ALIAS = "mitos_cli_rev"


def package_of(rev: str, into: Path, paths: tuple[str, ...] = ("mitos_cli",)):
    """The ``mitos_cli`` package of git revision ``rev`` as ``mitos_cli_rev``: ``paths`` of its
    tree are exported into ``into`` and its package copied there under the new name (its
    imports of itself are relative, so it imports its own modules, not this tree's)."""
    root = Path(__file__).resolve().parents[1]
    archive = subprocess.run(["git", "-C", str(root), "archive", rev, *paths], check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    alias = into / "alias"
    shutil.copytree(into / "mitos_cli", alias / ALIAS)
    sys.path.insert(0, str(alias))
    try:
        with foreign(rev):
            theirs = importlib.import_module(ALIAS)
    finally:
        sys.path.remove(str(alias))
    assert Path(theirs.__file__).is_relative_to(alias), theirs.__file__
    return theirs


@contextlib.contextmanager
def foreign(rev: str | None) -> Iterator[None]:
    """Errors raised by revision ``rev``'s tree (its own error classes, a module or function
    this benchmark asks for that it lacks, a rule base of this tree it cannot read) said in
    one line naming the revision, not as a traceback through a copy of its package; this
    tree's own errors pass unchanged."""
    try:
        yield
    except MitosError:
        raise
    except Exception as exc:
        if rev is None or not _theirs(exc):
            raise
        what = getattr(exc, "message", None) or str(exc) or type(exc).__name__
        raise MitosError(f"revision `{rev}` cannot be measured by this benchmark: "
                         f"{type(exc).__name__}: {what.splitlines()[0]}",
                         hint="give a later revision, one whose simulator and rule base this "
                              "benchmark's calls fit") from None


def _theirs(exc: BaseException) -> bool:
    """Whether ``exc`` came from the other tree: its class is one of that tree's, it names
    that tree's modules, or it was raised in that tree's code."""
    if type(exc).__module__.startswith(ALIAS) or ALIAS in str(exc):
        return True
    frames = traceback.extract_tb(exc.__traceback__)
    return bool(frames) and ALIAS in Path(frames[-1].filename).parts


def differs(what: str, rev: str) -> MitosError:
    """Why ``--against REV`` stops: the two trees are timed on the same work, or not at all."""
    return MitosError(f"{what} differs between this tree and `{rev}`",
                      hint="the speed of two trees is compared on the same results; give a "
                           "revision that computes the same ones")
