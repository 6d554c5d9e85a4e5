"""Caches that only save time: parsed rule bases and analysed grammars, kept between runs.

Like Python's ``.pyc`` files: a rule-base entry is keyed by the rule file's bytes (with the
MITOS version and the grammar), and remembers the bytes of every term set the rule file named;
it is used only when all of them are unchanged. A grammar entry is Lark's analysis of one
grammar (its LALR tables), keyed by the grammar's text, the options, Lark's and Python's
versions.

Entries are pickles, so they are read only from a directory that this user alone can write,
and only after a keyed hash proves this user wrote them:

- the directory is ``$MITOS_CACHE_DIR``, else ``$XDG_CACHE_HOME/mitos``, else
  ``$HOME/.cache/mitos``; with none of these set (or ``MITOS_CACHE_DIR=off``) there is no cache;
- it is created with mode 0700; one that exists but is not a directory owned by this user, or
  that its group or others may write, is refused with a warning and no cache is used;
- a symbolic link on the way is followed if this user (or root) owns it, and the directory
  it leads to is the one checked and used; another user's link is refused;
- every entry starts with an HMAC-SHA256 of its name and contents under a random 32-byte key
  (``key`` in the directory, mode 0600, created on first use); an entry whose tag does not
  match is never unpickled.

A cache that cannot be read or written is ignored: it only ever saves time, never changes a
result. :func:`status` says where the cache is, or why there is none.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import hmac
import io
import os
import pickle
import secrets
import stat
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._version import __version__
from .model import RuleBase

if TYPE_CHECKING:
    from lark import Lark

_FORMAT = 10                 # raised when parsing changes (3: `very not` refused, `main` placed;
                             # 4: a formula's operators of one precedence are one node, a
                             # file-level operator set again is noted; 5: a control character
                             # in a name, description or unit refused; 6: a line break in a
                             # name or unit refused; 7: a bidirectional override refused too;
                             # 8: a format character in a name refused; 9: a keyword glued to
                             # the next word refused, `r1: ifroad is ...`; 10: lines at
                             # `\r` alone, not at U+2028 or a form feed)
_TAG = 32                    # bytes of HMAC-SHA256 before every entry
_KEY = "key"


@dataclass(frozen=True)
class Status:
    """Where the cache lives (``path``), or why there is none (``reason``; ``refused`` when a
    directory is there but unsafe, which deserves a warning)."""

    path: Path | None
    reason: str = ""
    refused: bool = False


def cache_dir() -> Path | None:
    """The configured cache directory (not yet checked), or None when no cache is wanted."""
    explicit = os.environ.get("MITOS_CACHE_DIR")
    if explicit:
        return None if explicit.lower() in ("off", "0", "no") else Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME")
    if base:
        return Path(base) / "mitos"
    home = os.environ.get("HOME")
    return Path(home) / ".cache" / "mitos" if home else None


def status() -> Status:
    """The cache directory if it is safe to use (creating it 0700), else why it is not used."""
    where = cache_dir()
    if where is None:
        return Status(None, "no cache: MITOS_CACHE_DIR is off, or neither XDG_CACHE_HOME nor "
                            "HOME is set")
    try:
        where.mkdir(mode=0o700, parents=True, exist_ok=True)
        foreign = _foreign_link(where)
        if foreign:
            return Status(None, foreign, refused=True)
        where = Path(os.path.realpath(where))      # used from here on: a link changed after
        st = os.stat(where)                        # this check is not followed
    except OSError as exc:
        with contextlib.suppress(OSError):     # a HOME this user cannot enter (`sudo -u`):
            if where.is_symlink() and not where.exists():   # "File exists" said nothing
                return Status(None, f"no cache: {where} is a symbolic link to "
                                    f"{os.readlink(where)}, which does not exist")
        return Status(None, f"no cache: cannot create {where}: {exc.strerror}")
    if not stat.S_ISDIR(st.st_mode):
        return Status(None, f"no cache: {where} is not a directory", refused=True)
    if st.st_uid != os.geteuid():
        return Status(None, f"no cache: {where} belongs to another user (uid {st.st_uid})",
                      refused=True)
    if st.st_mode & 0o022:
        return Status(None, f"no cache: {where} is writable by its group or others "
                            f"(mode {stat.S_IMODE(st.st_mode):04o}); `chmod 700` it to use it",
                      refused=True)
    return Status(where)


def _foreign_link(where: Path) -> str:
    """Why ``where`` is refused for a symbolic link on its way that another user owns (one
    in a shared ``XDG_CACHE_HOME`` could point the cache at any directory of ours); empty when
    there is none. A link of this user's (or root's: ``/var`` on macOS) is followed, and the
    directory it leads to is checked as any other."""
    path = Path(os.path.abspath(where))
    for part in [*reversed(path.parents), path]:
        st = os.lstat(part)
        if stat.S_ISLNK(st.st_mode) and st.st_uid not in (os.geteuid(), 0):
            return (f"no cache: {part} is a symbolic link of another user (uid {st.st_uid}); "
                    f"set MITOS_CACHE_DIR to a directory of yours")
    return ""


@functools.cache
def _warn(reason: str) -> None:
    """Say once per process why a configured cache directory is not used."""
    print(f"mitos: warning: {reason}", file=sys.stderr)


def _place() -> tuple[Path, bytes] | None:
    """The checked directory and this user's key, or None (with a warning if it was refused)."""
    st = status()
    if st.path is None:
        if st.refused:
            _warn(st.reason)
        return None
    try:
        return st.path, _key_of(st.path)
    except OSError:
        return None


def _key_of(where: Path) -> bytes:
    """The directory's key, made on first use; refused unless this user alone may read it."""
    path = where / _KEY
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    except FileNotFoundError:
        fd_tmp, tmp = tempfile.mkstemp(dir=where, prefix=".key-")     # mode 0600
        with os.fdopen(fd_tmp, "wb") as fh:
            fh.write(secrets.token_bytes(_TAG))
        try:
            os.link(tmp, path)                 # atomic: the first of two racing runs wins
        except FileExistsError:
            pass
        finally:
            os.unlink(tmp)
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    with os.fdopen(fd, "rb") as fh:
        st = os.fstat(fh.fileno())
        if st.st_uid != os.geteuid() or st.st_mode & 0o077 or st.st_size != _TAG:
            raise PermissionError(f"{path} is not a private key file")
        return fh.read()


def _tag(key: bytes, name: str, payload: bytes) -> bytes:
    return hmac.new(key, name.encode() + b"\0" + payload, hashlib.sha256).digest()


def load_entry(name: str) -> bytes | None:
    """The contents stored under ``name`` by :func:`store_entry`, if its tag proves it ours."""
    place = _place()
    if place is None:
        return None
    where, key = place
    try:
        data = (where / name).read_bytes()
    except OSError:
        return None
    tag, payload = data[:_TAG], data[_TAG:]
    return payload if hmac.compare_digest(tag, _tag(key, name, payload)) else None


def store_entry(name: str, payload: bytes) -> None:
    """Keep ``payload`` under ``name``, tagged; silently nothing if the cache is unusable."""
    place = _place()
    if place is None:
        return
    where, key = place
    try:
        fd, tmp = tempfile.mkstemp(dir=where, suffix=".tmp")
        with os.fdopen(fd, "wb") as fh:
            fh.write(_tag(key, name, payload) + payload)
        os.replace(tmp, where / name)
    except OSError:
        pass


# ---- rule bases ------------------------------------------------------------------------------

def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


@functools.cache
def _code_stamp() -> bytes:
    """The size and time of each module a parsed rule base is made by (the package's own,
    `lang/`, `fuzzy/`): in an editable install (`pip install -e`, a checkout that pulls) the
    code changes without a new version, and an entry the old code parsed was served as the
    new code's (the format number below catches only the changes someone remembers to count).
    A stat a module, no read (under a millisecond), and none for an installed copy, whose
    code changes only with its version."""
    root = Path(__file__).resolve().parent.parent
    if root.parent.name in ("site-packages", "dist-packages"):
        return b""
    parts = []
    for module in sorted([*root.glob("*.py"), *(root / "lang").glob("*.py"),
                          *(root / "fuzzy").glob("*.py")]):
        try:
            st = module.stat()
        except OSError:
            continue
        parts.append(f"{module.relative_to(root)}:{st.st_size}:{st.st_mtime_ns}")
    return "\n".join(parts).encode()


def _key(path: Path, data: bytes) -> str:
    from ..resources import data_dir

    grammar = (data_dir("grammar") / "mitos.lark").read_bytes()
    # The path as given and resolved: spans in the cached model quote the path as given.
    return _digest(b"\0".join([str(_FORMAT).encode(), __version__.encode(), _code_stamp(),
                               grammar, str(path).encode(), str(path.resolve()).encode(),
                               os.getcwd().encode(), data]))


def rulebase_entry(path: Path, data: bytes) -> str:
    """The name of the entry that holds the rule file ``path`` with contents ``data``."""
    return f"rulebase-{_key(path, data)}.pickle"


def cached_rulebase(path: Path, load: Callable[[Path], RuleBase]) -> RuleBase:
    """``load(path)``, or the cached result of an earlier call on the same files."""
    from ..resources import is_file

    if not is_file(path):                     # a device (/dev/zero) would be read without
        return load(path)                     # end: the loader reports what it is
    try:
        data = path.read_bytes()
    except OSError:
        return load(path)                     # let the loader report it
    if cache_dir() is None:
        return load(path)
    name = rulebase_entry(path, data)
    payload = load_entry(name)
    if payload is not None:
        try:
            termsets, rulebase = pickle.loads(payload)
            if all(_digest(Path(p).read_bytes()) == digest for p, digest in termsets):
                return rulebase
        except Exception:  # noqa: BLE001 - a stale entry, or one of an older MITOS: a miss
            pass
    rulebase = load(path)
    _store(name, path, rulebase)
    return rulebase


def _store(name: str, path: Path, rulebase: RuleBase) -> None:
    try:
        termsets = [(str((path.parent / p).resolve()), _digest((path.parent / p).read_bytes()))
                    for p in rulebase.termset_paths]
        payload = pickle.dumps((termsets, rulebase), protocol=pickle.HIGHEST_PROTOCOL)
    except Exception:  # noqa: BLE001 - an entry that cannot be made costs time, never a result
        return
    store_entry(name, payload)


# ---- grammars --------------------------------------------------------------------------------

def lark_parser(grammar: str, **options: Any) -> Lark:
    """``Lark(grammar, parser="lalr", **options)``, its analysis kept in the cache between runs.

    This replaces Lark's own ``cache=True``, which unpickles a file from the shared temporary
    directory that any other account can plant.
    """
    import lark
    from lark import Lark

    options = {"parser": "lalr", **options}
    name = "grammar-" + _digest("\0".join([grammar, repr(sorted(options.items())),
                                            lark.__version__, sys.version]).encode()) + ".pickle"
    payload = load_entry(name)
    if payload is not None:
        try:
            return Lark.load(io.BytesIO(payload))
        except Exception:  # noqa: BLE001 - an entry of another Lark: build it again
            pass
    parser = Lark(grammar, **options)
    if cache_dir() is not None:
        buffer = io.BytesIO()
        parser.save(buffer)
        store_entry(name, buffer.getvalue())
    return parser
