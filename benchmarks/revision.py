"""A git revision's ``mitos_cli`` imported beside this tree's, for benchmarks that time both in
one process (``--against REV``): interleaved rounds in one process see the same load, which
separate runs of two trees do not."""

from __future__ import annotations

import importlib
import shutil
import subprocess
import sys
from pathlib import Path


def package_of(rev: str, into: Path, paths: tuple[str, ...] = ("mitos_cli",)):
    """The ``mitos_cli`` package of git revision ``rev`` as ``mitos_cli_rev``: ``paths`` of its
    tree are exported into ``into`` and its package copied there under the new name (its
    imports of itself are relative, so it imports its own modules, not this tree's)."""
    root = Path(__file__).resolve().parents[1]
    archive = subprocess.run(["git", "-C", str(root), "archive", rev, *paths], check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    alias = into / "alias"
    shutil.copytree(into / "mitos_cli", alias / "mitos_cli_rev")
    sys.path.insert(0, str(alias))
    try:
        theirs = importlib.import_module("mitos_cli_rev")
    finally:
        sys.path.remove(str(alias))
    assert Path(theirs.__file__).is_relative_to(alias), theirs.__file__
    return theirs
