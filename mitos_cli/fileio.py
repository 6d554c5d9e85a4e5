"""Writing files so that nothing the user has is ever half-written.

Every file MITOS writes (saved rule bases and term sets, converted and exported files, plots,
traces, study results) goes through :func:`atomic_file`: the data goes to a temporary file in
the same directory, is flushed to disk, and only then replaces the target in one rename. A
crash leaves either the old file or the new one. New files get the usual permissions (0666
less the umask), not a temporary file's 0600; a file replaced keeps its own.
"""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import stat
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import IO

from .errors import MitosError, Span, WriteError, closest_file

#: the largest text file read (bytes): far beyond any rule base, world, lesson or batch here
MAX_TEXT_BYTES = 256 << 20


#: What a rule base is read from.
RULE_SUFFIXES = (".rules", ".fcl", ".fis", ".fll")


def nearby(path: str | Path, suffixes: tuple[str, ...] = RULE_SUFFIXES,
           also: Iterable[str] = ()) -> str | None:
    """"did you mean `DIR/NAME`?" for a file beside ``path`` whose name is close to its own
    and ends in one of ``suffixes`` (`rulebases/mitoss.rules`, `rulebases/mitos.rule`), or
    for one of the names ``also`` (the packaged files, where ``path`` may name one of them:
    `worlds/slalon.yaml` from a directory without `worlds/`), whichever is closest."""
    name = nearby_name(path, suffixes, also)
    return f"did you mean `{Path(path).parent / name}`?" if name is not None else None


#: folders of the repository that `pip install` does not copy, which the README's and the
#: help's examples name (`tests/data/inputs.csv`, `tests/data/interop/tipper.fis`)
REPOSITORY_ONLY = ("tests", "benchmarks")


def repository_only(path: str | Path) -> str | None:
    """What to do about an example's file that is not there because the command runs outside
    the repository: `mitos eval tests/data/interop/tipper.fis ...` from another directory said
    "not found" and no more, though the file is the repository's (the packaged rule bases and
    worlds are found from anywhere; these are not packaged)."""
    parts = Path(path).parts
    if Path(path).is_absolute() or len(parts) < 2 or parts[0] not in REPOSITORY_ONLY \
            or Path(parts[0]).exists():
        return None
    return (f"`{parts[0]}/` is a folder of the MITOS repository, which `pip install` does not "
            f"copy: run the example from the repository's root, or name a file of your own")


def nearby_name(path: str | Path, suffixes: tuple[str, ...] = RULE_SUFFIXES,
                also: Iterable[str] = ()) -> str | None:
    """The name :func:`nearby` suggests, without its directory: never the name given, nor a
    link that leads nowhere (a dangling link or a loop is listed in its directory, and
    "`loop1.yaml` not found, did you mean `loop1.yaml`?" was said of it), nor a directory
    (`mitos.rules/` was offered for `mitoss.rules`, and then refused as a directory)."""
    where, given = Path(path).parent, Path(path).name
    try:
        names = [p.name for p in where.iterdir() if p.suffix.lower() in suffixes
                 and p.name != given and _there(p)]
    except OSError:                 # no such directory: only ``also`` may be meant
        names = []
    # the name without its extension (`tiny` for `tiny.yaml`, `my` for `my.rules`): too far
    # from it for closest_file, and said "not found" with no word of the file beside it
    whole = sorted(n for n in names if any(n.lower() == given.lower() + s for s in suffixes))
    if whole:
        return whole[0]
    return closest_file(given, [*names, *(n for n in also if n != given)])


def _there(path: Path) -> bool:
    """Whether ``path`` leads to something a file may be read from (a link to nothing, or in a
    loop, does not, nor a directory; a named pipe does)."""
    try:
        return path.exists() and not path.is_dir()
    except OSError:
        return False


def broken_link(kind: str, path: str | Path) -> str | None:
    """What is wrong with ``path`` when it is a symbolic link that leads to no file, in words:
    "`dangling.yaml` is a link to `nonexist.yaml`, which does not exist", or for a loop what
    reading it says ("cannot read KIND `X`: Too many levels of symbolic links"); ``None``
    for anything else. A name that is such a link is there, so it is not "not found"."""
    path = Path(path)
    try:
        if not path.is_symlink():
            return None
        os.stat(path)
    except FileNotFoundError:
        last = path                 # the last link of a chain, whose target is missing
        with contextlib.suppress(OSError):
            for _ in range(40):
                target = last.parent / os.readlink(last)
                if not target.is_symlink():
                    break
                last = target
        through = f" (through `{last}`)" if last != path else ""
        return (f"`{path}` is a link to `{os.readlink(last)}`{through}, which does not "
                f"exist")
    except OSError as exc:
        return f"cannot read {kind} `{path}`: {exc.strerror or exc}"
    return None


def read_text(path: str | Path) -> str:
    """A file the user named, as text: UTF-8, with or without a byte-order mark (which is not
    content), read as :func:`read_bytes` reads it. Raises ``OSError`` (with a ``strerror`` to
    show) or ``UnicodeDecodeError`` (:class:`WideText` for UTF-16 or UTF-32), as
    ``Path.read_text`` does."""
    return decode_text(read_bytes(path))


def decode_text(data: bytes) -> str:
    """The text of a file's (or stdin's) bytes, the one way every text MITOS reads is decoded:
    UTF-8, a byte-order mark dropped. UTF-16 or UTF-32 (an editor's "Unicode", PowerShell's
    `>`), with its byte-order mark or without, raises :class:`WideText`: without the mark,
    ASCII in UTF-16 is valid UTF-8 with a NUL after each character, and was refused by the
    parser at its first NUL (`unexpected character '\x00'`), in no words about its
    encoding."""
    wide = wide_text(data)
    if wide is not None:
        raise wide
    return data.decode("utf-8-sig")


class WideText(UnicodeDecodeError):
    """Text in UTF-16 or UTF-32, which MITOS does not read: ``encoding`` as iconv names it
    (``UTF-16LE``; ``UTF-16`` with a byte-order mark, which says the order), ``order``
    (``little-endian``), ``marked`` (it begins with its byte-order mark); ``start`` is its
    first NUL byte (the mark's first byte in a file with none)."""

    def __init__(self, data: bytes, units: int, little: bool, marked: bool) -> None:
        name = f"UTF-{8 * units}"
        start = max(0, data.find(b"\0"))
        super().__init__("utf-8", data, start, start + 1, f"it looks like {name} text")
        self.name = name
        self.order = "little-endian" if little else "big-endian"
        self.marked = marked
        self.encoding = name if marked else name + ("LE" if little else "BE")

    def described(self) -> str:
        """``UTF-16 text (little-endian, without a byte-order mark), not UTF-8 (its first NUL
        byte is at line 1, column 2)``."""
        mark = "with its byte-order mark" if self.marked else "without a byte-order mark"
        where = byte_span(None, self.object, self.start)
        first = (f"its first NUL byte is at line {where.line}, column {where.column}"
                 if self.object[self.start] == 0 else "it begins with that mark")
        return f"{self.name} text ({self.order}, {mark}), not UTF-8 ({first})"


#: How many bytes of a file :func:`wide_text` looks at.
WIDE_HEAD = 1024

#: Byte-order marks, the longest first (UTF-32LE's begins with UTF-16LE's): (mark, code unit
#: bytes, little-endian).
_MARKS = ((b"\xff\xfe\x00\x00", 4, True), (b"\x00\x00\xfe\xff", 4, False),
          (b"\xff\xfe", 2, True), (b"\xfe\xff", 2, False))


def wide_text(data: bytes) -> WideText | None:
    """:class:`WideText` when ``data`` looks like UTF-16 or UTF-32: it begins with their
    byte-order mark; or, without a mark, its NUL bytes fall at the places
    of the high bytes of characters below U+0100 (UTF-16LE: each second byte) in at least a
    quarter of its first characters, and hardly ever elsewhere. A UTF-8 text holds no NUL
    (a stray one, or binary junk whose zeros fall anywhere, is no such pattern); else
    ``None``."""
    for mark, units, little in _MARKS:    # (no UTF-8 text begins with 0xff, 0xfe or NULs)
        if data.startswith(mark):
            return WideText(data, units, little, marked=True)
    if b"\0" not in data:
        return None
    head = data[:WIDE_HEAD]
    for units in (4, 2):
        chars = len(head) // units
        if chars < 2:
            continue
        nuls = [head[i::units][:chars].count(0) for i in range(units)]
        for little in (True, False):
            low = 0 if little else units - 1           # the byte of the character's value
            high = [n for i, n in enumerate(nuls) if i != low]
            if min(high) >= max(2, chars // 4) and nuls[low] * 8 <= min(high):
                return WideText(data, units, little, marked=False)
    return None


def text_encoding_hint(exc: OSError | UnicodeDecodeError) -> str | None:
    """What to do with a file :func:`read_text` refused as :class:`WideText`; else ``None``."""
    if not isinstance(exc, WideText):
        return None
    return (f"save it as UTF-8 (an editor's \"save with encoding\", or `iconv -f "
            f"{exc.encoding} -t UTF-8 FILE > NEW`)")


def read_bytes(path: str | Path) -> bytes:
    """A file the user named, opened once: a pipe (``--batch <(...)``, a named pipe) is a file
    a user may well name, and it can be read only once. At most :data:`MAX_TEXT_BYTES` are
    read: a device (``/dev/zero``) would be read without end. Raises ``OSError`` (with a
    ``strerror`` to show)."""
    path = Path(path)
    if _special(path) and path.is_dir():
        raise OSError(errno.EISDIR, "it is a directory", str(path))
    with open(path, "rb") as fh:
        data = fh.read(MAX_TEXT_BYTES + 1)
    if len(data) > MAX_TEXT_BYTES:
        raise OSError(errno.EFBIG, f"it is larger than {MAX_TEXT_BYTES >> 20} MB", str(path))
    return data


def _special(path: Path) -> bool:
    """Whether ``path`` is there but not a regular file (a directory, a device, a pipe); a
    name the system cannot look up (over 255 characters) is left to ``open`` to report."""
    try:
        return path.exists() and not path.is_file()
    except OSError:
        return False


def why_unreadable(exc: OSError | UnicodeDecodeError) -> str:
    """What :func:`read_text`'s failure means, in words: the system's reason, or where the
    bytes stop being UTF-8 text."""
    if isinstance(exc, UnicodeDecodeError):
        where = bad_byte(None, exc)
        assert where is not None
        if isinstance(exc, WideText):
            return f"it looks like {exc.described()}"
        return (f"it is not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at line "
                f"{where.line}, column {where.column})")
    return str(exc.strerror or exc)


def not_text(path: object, exc: UnicodeDecodeError) -> str:
    """A file that is not UTF-8, said as a rule file's and a term set's refusal says it:
    ``not a text file (byte 0xff is not UTF-8)``, or what :class:`WideText` it looks like."""
    if isinstance(exc, WideText):
        return f"`{path}` looks like {exc.described()}"
    return f"`{path}` is not a text file (byte 0x{exc.object[exc.start]:02x} is not UTF-8)"


def bad_byte(path: object, exc: OSError | UnicodeDecodeError) -> Span | None:
    """Where a file stops being UTF-8 text, for :func:`read_text`'s failure ``exc`` (``None``
    for any other failure to read it)."""
    if not isinstance(exc, UnicodeDecodeError):
        return None
    return byte_span(path, exc.object, exc.start)


def byte_span(path: object, data: bytes, start: int) -> Span:
    """Where byte ``start`` of a file's ``data`` is: its line and column (counted in bytes)."""
    line = data.count(b"\n", 0, start) + 1
    return Span(None if path is None else str(path), line,
                start - (data.rfind(b"\n", 0, start) + 1) + 1)


def unreadable(kind: str, path: object, exc: OSError | UnicodeDecodeError) -> str:
    """The words for a ``kind`` of file (``rule file``, ``term set``, ...) that could not be
    read: "not found" when it is not there (as every command says it), "is a directory", or
    "cannot read" with :func:`why_unreadable`'s reason."""
    if isinstance(exc, FileNotFoundError):
        return broken_link(kind, str(path)) or f"{kind} `{path}` not found"
    if isinstance(exc, IsADirectoryError):
        return f"`{path}` is a directory, not a {kind}"
    return f"cannot read {kind} `{path}`: {why_unreadable(exc)}"


def link_loop(path: str | Path) -> str | None:
    """The system's words when ``path`` is a symbolic link in a loop ("Too many levels of
    symbolic links"), else ``None``: ``Path.resolve`` of one raised a ``RuntimeError``, which
    every writer showed as a traceback."""
    try:
        if not Path(path).is_symlink():
            return None
        os.stat(path)
    except OSError as exc:
        return exc.strerror or str(exc) if exc.errno == errno.ELOOP else None
    return None


def named_yaml(path: str | Path) -> bool:
    """Whether ``path`` is named ``.yaml`` / ``.yml``, and so is the file its links lead to:
    such a file may be quoted in an error (docs/security.md), and a link ``x.yaml`` to
    ``/etc/shadow`` quoted a line of it."""
    return all(p.suffix.lower() in (".yaml", ".yml") for p in (Path(path), real_path(path)))


def real_path(path: str | Path) -> Path:
    """``path`` resolved (links followed), or as an absolute path where a link loop leaves
    nothing to resolve it to (``Path.resolve`` raised a ``RuntimeError`` there)."""
    try:
        return Path(path).resolve()
    except (OSError, RuntimeError):
        return Path(os.path.abspath(path))


#: what to do where a file stands in the place of a directory
IN_THE_WAY_HINT = "give a path inside a directory"


def file_in_the_way(directory: Path) -> Path | None:
    """The file that stands where ``directory`` or one of the directories above it should be
    (``notes.txt`` for ``notes.txt/a``), or None. The system says "No such file or
    directory" or "Not a directory" there, and a hint to create the directory cannot help."""
    try:
        found = next((p for p in (directory, *directory.parents) if p.exists()), None)
        return found if found is not None and not found.is_dir() else None
    except OSError:
        return None


def check_writable(path: str | Path) -> None:
    """Refuse, before any work, a file that cannot be written where it is named: its directory
    missing or not writable, the name a directory's, or a link in a loop (a device or a pipe,
    /dev/stdout, is written as it is). The words are those :func:`atomic_file` says when it
    writes."""
    path = Path(path)
    loop = link_loop(path)
    if loop is not None:
        raise WriteError(f"cannot write `{path}`: {loop}", hint=LOOP_HINT)
    try:
        if _special(path) and not path.is_dir():
            return
        if path.is_dir():
            raise WriteError(f"cannot write `{path}`: it is a directory",
                             hint="give a file name inside it")
        parent = path.parent if str(path.parent) else Path(".")
        blocker = None if parent.is_dir() else file_in_the_way(parent)
        if blocker is not None:
            raise WriteError(f"cannot write `{path}`: `{blocker}` is a file, not a directory",
                             hint=IN_THE_WAY_HINT)
        why = ("No such file or directory" if not parent.is_dir() else
               "Permission denied" if not os.access(parent, os.W_OK | os.X_OK) else None)
    except OSError as exc:          # a name the system cannot look up (over 255 characters)
        raise WriteError(f"cannot write `{path}`: {exc.strerror or exc}",
                         hint="each part of a path may have at most 255 characters"
                         if exc.errno == errno.ENAMETOOLONG else None) from None
    if why is not None:
        raise WriteError(f"cannot write `{path}`: {why}",
                         hint="check that the directory exists and is writable")


#: how long a save waits for another process's save into the same directory (s)
SAVE_LOCK_WAIT = 30.0


@contextlib.contextmanager
def save_lock(path: str | Path, error: type[MitosError] = WriteError) -> Iterator[None]:
    """Hold the directory that ``path`` is saved into (its nearest existing one) while a save
    checks what is there and writes: two processes that checked, then wrote, at once lost the
    first one's save without a word. An advisory ``flock`` on the directory itself (no file
    is left beside the user's), released by the system when the process ends; another save
    into the directory waits for it, up to :data:`SAVE_LOCK_WAIT` seconds. Where the system
    has no ``flock``, or the directory cannot be opened, saves are not locked."""
    try:
        import fcntl
    except ImportError:                          # pragma: no cover - not POSIX
        yield
        return
    import time

    directory = real_path(path).parent
    while not directory.is_dir() and directory != directory.parent:
        directory = directory.parent             # `save new/dir/taught.rules` makes new/
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        yield
        return
    try:
        deadline = time.monotonic() + SAVE_LOCK_WAIT
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() > deadline:
                    raise error(f"another program has been saving into {directory} for "
                                f"{SAVE_LOCK_WAIT:g} s; nothing was written",
                                hint="save again when it is done") from None
                time.sleep(0.01)
            except OSError:                      # a file system without locks
                break
        yield
    finally:
        os.close(fd)                             # releases the lock


#: what to do about an output named by a link in a loop
LOOP_HINT = "the symbolic link leads back to itself: remove it, or name another file"


@contextlib.contextmanager
def atomic_file(path: str | Path, binary: bool = False,
                error: type[MitosError] = WriteError) -> Iterator[IO]:
    """Open a temporary file that replaces ``path`` when the block ends without an error; a
    failure (a missing directory included) raises ``error`` naming the file: a
    :class:`WriteError`, the same from every command, unless a caller that catches its own
    kind (a teaching session's ``save``) asks for another."""
    if _special(Path(path)):      # before following links: /dev/stdout names a pipe
        with _in_place(Path(path), binary, error) as fh:
            yield fh
        return
    try:
        path = _target(Path(path))
    except OSError as exc:
        raise error(f"cannot write `{path}`: {exc.strerror or exc}", hint=LOOP_HINT) from None
    if _special(path):
        with _in_place(path, binary, error) as fh:
            yield fh
        return
    directory = path.parent if str(path.parent) else Path(".")
    tmp = directory / f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp"
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
    except OSError as exc:
        blocker = file_in_the_way(directory)
        if blocker is not None:
            raise error(f"cannot write `{path}`: `{blocker}` is a file, not a directory",
                        hint=IN_THE_WAY_HINT) from None
        raise error(f"cannot write `{path}`: {exc.strerror or exc}",
                    hint="check that the directory exists and is writable") from None
    _keep_mode(fd, path)
    try:
        with (os.fdopen(fd, "wb") if binary else
              os.fdopen(fd, "w", encoding="utf-8", newline="")) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError as exc:
        raise error(f"cannot write `{path}`: {exc.strerror or exc}") from None
    finally:
        with contextlib.suppress(OSError):
            os.unlink(tmp)


def _keep_mode(fd: int, path: Path) -> None:
    """Give the temporary file ``fd`` the permissions of the file ``path`` it replaces: a
    private (0600) rule file saved over became readable by all (0644), and a script lost its
    execute bit, where an editor or `cp` keeps them. A new file keeps 0666 less the umask."""
    try:
        st = os.stat(path)
        if stat.S_ISREG(st.st_mode):
            os.fchmod(fd, stat.S_IMODE(st.st_mode) & 0o777)
    except OSError:             # not there (a new file), or not ours to read: as it was
        pass


def replace_with(part: Path, path: str | Path) -> None:
    """Rename a finished file ``part`` (written beside ``path`` by a writer that wants a
    file name, as matplotlib's animation writers do) over ``path`` as :func:`atomic_file`
    does: through a link to the file it names, keeping a replaced file's permissions.
    Raises ``OSError``."""
    target = _target(Path(path))
    fd = os.open(part, os.O_RDONLY)
    try:
        _keep_mode(fd, target)
        os.fsync(fd)
    finally:
        os.close(fd)
    os.replace(part, target)


def _target(path: Path) -> Path:
    """The file a write goes to: through a symbolic link to the file it names (the link
    stays a link). A link in a loop names no file: ``OSError`` (renaming over it replaced
    the link)."""
    loop = link_loop(path)
    if loop is not None:
        raise OSError(errno.ELOOP, loop, str(path))
    try:
        return path.resolve() if path.is_symlink() else path
    except OSError:             # a name too long to look up: the write reports it
        return path


@contextlib.contextmanager
def _in_place(path: Path, binary: bool, error: type[MitosError]) -> Iterator[IO]:
    """Write to something that is not a regular file (a device such as /dev/null, a pipe) as
    it is: renaming a file over it would replace it."""
    if path.is_dir():
        raise error(f"cannot write `{path}`: it is a directory",
                    hint="give a file name inside it")
    try:
        with (open(path, "wb") if binary else
              open(path, "w", encoding="utf-8", newline="")) as fh:
            yield fh
    except OSError as exc:
        raise error(f"cannot write `{path}`: {exc.strerror or exc}") from None


def atomic_write(path: str | Path, data: str | bytes,
                 error: type[MitosError] = WriteError) -> None:
    """Replace ``path`` with ``data`` (text as UTF-8) in one step."""
    with atomic_file(path, binary=isinstance(data, bytes), error=error) as fh:
        fh.write(data)


# ---- several files as one set ------------------------------------------------------------------

def _manifest(anchor: Path) -> Path:
    return anchor.parent / f".{anchor.name}.saving.json"


def atomic_write_set(files: list[tuple[Path, str | bytes]], anchor: Path,
                     error: type[MitosError] = WriteError) -> None:
    """Replace several files so that readers see the old set or the new set, whole.

    Every new file is written beside its target and fsynced; then a manifest naming them
    (``.ANCHOR.saving.json`` beside ``anchor``, the set's main file) is written atomically:
    that rename is the moment the new set exists. The files are then renamed over their
    targets and the manifest removed. A crash before the manifest leaves the old set (and
    temporary files that :func:`finish_saves` removes); a crash after it leaves a manifest
    that :func:`finish_saves` carries out on the next read or save.
    """
    import json

    pending: list[tuple[Path, Path]] = []
    try:
        for path, data in files:
            try:
                path = _target(Path(path))
                tmp = path.parent / f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}.tmp"
                fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
                pending.append((tmp, path))
                _keep_mode(fd, path)
                with os.fdopen(fd, "wb") as fh:
                    fh.write(data.encode("utf-8") if isinstance(data, str) else data)
                    fh.flush()
                    os.fsync(fh.fileno())
            except OSError as exc:
                raise error(f"cannot write `{path}`: {exc.strerror or exc}") from None
        manifest = _manifest(Path(anchor))
        atomic_write(manifest, json.dumps(
            [[os.path.relpath(t, manifest.parent), os.path.relpath(p, manifest.parent)]
             for t, p in pending]), error=error)
    except BaseException:
        for tmp, _ in pending:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        raise
    finish_saves(Path(anchor), error=error)


def finish_saves(anchor: Path, error: type[MitosError] = WriteError) -> bool:
    """Complete a set save that a crash interrupted after its manifest was written, and remove
    temporary files of saves that died before it. True when something was completed."""
    import json

    anchor = Path(anchor)
    _remove_orphans(anchor.parent)
    manifest = _manifest(anchor)
    try:
        pairs = json.loads(manifest.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return False
    except (OSError, ValueError):              # torn manifest: its rename never happened
        with contextlib.suppress(OSError):
            manifest.unlink()
        return False
    base = manifest.parent
    try:
        for tmp, path in pairs:
            with contextlib.suppress(FileNotFoundError):    # renamed already (by another)
                os.replace(base / tmp, base / path)
        with contextlib.suppress(FileNotFoundError):
            manifest.unlink()
    except OSError as exc:
        raise error(f"cannot finish saving `{anchor}`: {exc.strerror or exc}") from None
    return True


def _remove_orphans(directory: Path) -> None:
    """Temporary files of writers that are no longer running, unless a manifest names them."""
    import json

    try:
        names = [p for p in directory.iterdir() if p.name.startswith(".")]
    except OSError:
        return
    named: set[str] = set()
    for m in (p for p in names if p.name.endswith(".saving.json")):
        with contextlib.suppress(OSError, ValueError):
            named.update(str((directory / t).resolve()) for t, _ in json.loads(m.read_text()))
    for p in names:
        parts = p.name.rsplit(".", 3)
        if len(parts) != 4 or parts[3] != "tmp" or not parts[1].isdigit():
            continue
        if str(p.resolve()) in named or process_alive(int(parts[1])):
            continue
        with contextlib.suppress(OSError):
            p.unlink()


def process_alive(pid: int) -> bool:
    """Whether process ``pid`` may still run: what it left (a temporary file, a scratch
    directory) is removed only when this says no. One of another user's counts as running;
    on Windows every process does, since ``os.kill(pid, 0)`` there ends the process."""
    if pid == os.getpid() or os.name == "nt":
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True
