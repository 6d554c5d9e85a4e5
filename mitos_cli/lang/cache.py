"""A cache of parsed rule bases, so that a command does not parse an unchanged rule file again.

Like Python's ``.pyc`` files: an entry is keyed by the rule file's bytes (with the MITOS
version and the grammar), and remembers the bytes of every term set the rule file named; it
is used only when all of them are unchanged. Entries live in ``$MITOS_CACHE_DIR``, else
``$XDG_CACHE_HOME/mitos``, else ``~/.cache/mitos``; ``MITOS_CACHE_DIR=off`` disables the cache.
A cache that cannot be read or written is ignored: it only ever saves time.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import tempfile
from pathlib import Path
from typing import Callable

from .._version import __version__
from .model import RuleBase

_FORMAT = 1


def cache_dir() -> Path | None:
    explicit = os.environ.get("MITOS_CACHE_DIR")
    if explicit:
        return None if explicit.lower() in ("off", "0", "no") else Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "mitos"


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _key(path: Path, data: bytes) -> str:
    from ..resources import data_dir

    grammar = (data_dir("grammar") / "mitos.lark").read_bytes()
    # The path as given and resolved: spans in the cached model quote the path as given.
    return _digest(b"\0".join([str(_FORMAT).encode(), __version__.encode(), grammar,
                               str(path).encode(), str(path.resolve()).encode(),
                               os.getcwd().encode(), data]))


def cached_rulebase(path: Path, load: Callable[[Path], RuleBase]) -> RuleBase:
    """``load(path)``, or the cached result of an earlier call on the same files."""
    where = cache_dir()
    try:
        data = path.read_bytes()
    except OSError:
        return load(path)                     # let the loader report it
    if where is None:
        return load(path)
    entry = where / f"{_key(path, data)}.pickle"
    try:
        with open(entry, "rb") as fh:
            termsets, rulebase = pickle.load(fh)
        if all(_digest(Path(p).read_bytes()) == digest for p, digest in termsets):
            return rulebase
    except Exception:  # noqa: BLE001 - a missing, stale or corrupt entry is just a miss
        pass
    rulebase = load(path)
    _store(where, entry, path, rulebase)
    return rulebase


def _store(where: Path, entry: Path, path: Path, rulebase: RuleBase) -> None:
    try:
        termsets = [(str((path.parent / p).resolve()), _digest((path.parent / p).read_bytes()))
                    for p in rulebase.termset_paths]
        where.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=where, suffix=".tmp")
        with os.fdopen(fd, "wb") as fh:
            pickle.dump((termsets, rulebase), fh, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, entry)
    except Exception:  # noqa: BLE001 - an unwritable cache costs time, never a result
        pass
