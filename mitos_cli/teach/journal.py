"""The teaching journal: every change of a session, one JSON object per line, on disk at once.

A session lives in ``.mitos/teach/<session>/`` under the directory ``mitos teach`` runs in
(the rule file may be a packaged, read-only one, so not beside it): ``journal.jsonl`` holds
the changes and ``history`` the prompt's line history. Each entry is appended, flushed and
fsynced before the prompt answers, so Ctrl-C, a closed terminal, a crash or ``kill -9`` lose
nothing that was acknowledged; a line cut short by the kill is ignored when reading.

Entries carry ``seq`` (1, 2, ...), ``op`` and the data of the change (see
:mod:`mitos_cli.teach.session`); ``{"op": "undo", "of": seq}`` takes a change back, so the
state is the replay of the changes not undone.
"""

from __future__ import annotations

import atexit
import contextlib
import errno
import json
import math
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import LessonError, Span

ROOT = Path(".mitos") / "teach"
JOURNAL = "journal.jsonl"


#: the most characters of the rule file's name a session directory's name takes
STEM_CHARS = 64


def sessions_dir(base: Path | None = None) -> Path:
    return (base or Path.cwd()) / ROOT


def resume_command(directory: Path) -> str:
    """The command that continues the session in ``directory``: by its name where it lies
    under this directory's `.mitos/teach/`, else by its path (`--resume` alone picks the
    newest session here, which need not be this one)."""
    try:
        here = directory.parent.resolve() == sessions_dir().resolve()
    except OSError:
        here = False
    return (f"mitos teach --resume --session "
            f"{directory.name if here else directory.absolute().as_posix()}")


def new_session_dir(stem: str, base: Path | None = None) -> Path:
    """A fresh directory ``.mitos/teach/<stem>-<date>-<time>[-n]``, the stem cut to
    :data:`STEM_CHARS` characters: a rule file of a 245-character name could not be taught
    (the directory's name went over the 255 a file system allows, and the refusal blamed the
    directory the command ran in)."""
    root = sessions_dir(base)
    name = f"{stem[:STEM_CHARS]}-{time.strftime('%Y%m%d-%H%M%S')}"
    try:
        root.mkdir(parents=True, exist_ok=True)
        for n in range(1000):
            candidate = root / (name if n == 0 else f"{name}-{n}")
            try:
                candidate.mkdir()
                return candidate
            except FileExistsError:
                continue
    except OSError as exc:
        raise LessonError(f"cannot create the session directory {ROOT}/ here: "
                          f"{exc.strerror or exc}",
                          hint="run `mitos teach` from a directory you can write to (the "
                               "journal of the session lives there)") from None
    raise LessonError(f"cannot create a session directory in {root}")   # pragma: no cover


def find_session(name: str | None, base: Path | None = None) -> Path:
    """The session called ``name``, or the most recently changed one."""
    root = sessions_dir(base)
    # a session killed before its first entry was written has an empty journal: nothing to
    # resume there, so the newest session is the newest with a journal that holds something
    # (a file: a directory of that name raised IsADirectoryError, a traceback)
    found = sorted((p for p in root.glob("*/" + JOURNAL) if p.is_file() and p.stat().st_size),
                   key=lambda p: p.stat().st_mtime) if root.is_dir() else []
    if name is not None:
        direct = Path(name)
        if (direct / JOURNAL).is_file():
            return direct
        if (root / name / JOURNAL).is_file():
            return root / name
        from ..errors import unknown

        names = [p.parent.name for p in found]               # oldest first (by time)
        err = unknown("teaching session", name, names)
        if len(names) > 12:                                   # the newest are the likely ones
            err.expected = "one of the newest: " + ", ".join(reversed(names[-12:]))
        raise err
    if not found:
        raise LessonError(f"no teaching session to resume in {ROOT}/",
                          hint="start one with `mitos teach RULEBASE`")
    return found[-1].parent


@dataclass
class Journal:
    """An append-only JSON-lines file of one session's changes."""

    directory: Path
    entries: list[dict] = field(default_factory=list)
    skipped_tail: bool = False
    #: the journal line of each entry (for messages about an entry)
    lines: list[int] = field(default_factory=list)
    #: the damaged line the session was recovered up to (``open(recover=True)``), if any
    recovered_at: int | None = None
    #: where :meth:`cut` kept the journal as it was (``journal.jsonl.damaged``, or ``.2``, ...)
    kept: Path | None = None

    @property
    def path(self) -> Path:
        return self.directory / JOURNAL

    @classmethod
    def create(cls, directory: Path) -> Journal:
        directory.mkdir(parents=True, exist_ok=True)
        _lock(directory)
        journal = cls(directory)
        journal.path.touch()
        return journal

    @classmethod
    def open(cls, directory: Path, recover: bool = False) -> Journal:
        """Read an existing journal.

        A torn last line (what ``kill -9`` during a write leaves: the change was never
        acknowledged) is dropped, and the file as it was is kept aside as
        ``journal.jsonl.damaged``. A damaged line elsewhere is an error naming the journal's
        path and line; with ``recover`` the session is kept up to that line instead (the
        damaged file kept aside the same way).
        """
        _lock(directory)
        journal = cls(directory)
        raw = journal.path.read_bytes()
        lines = raw.split(b"\n")
        offset = 0
        for i, line in enumerate(lines):
            start, offset = offset, offset + len(line) + 1
            if not line.strip():
                continue
            problem = _problem(line, journal.next_seq)
            if problem is None:
                journal.entries.append(json.loads(line))
                journal.lines.append(i + 1)
                continue
            if i == len(lines) - 1:                # no newline after it: cut short by a kill
                journal.skipped_tail = True
            elif not recover or not journal.entries:
                shown = line[:120].decode("utf-8", "replace")
                # before the session's start there is nothing to continue: `--recover` then
                # said "not a teaching journal", where this hint had offered it
                hint = ("`mitos teach --resume --recover` continues the session with the "
                        f"changes before line {i + 1} (the damaged journal is kept aside)"
                        if journal.entries else "the session's start is damaged, so there is "
                        "nothing to continue: start a new session with `mitos teach RULEBASE`")
                raise LessonError(f"the journal is damaged: {problem}",
                                  span=Span(str(journal.path), i + 1, 1, shown), hint=hint)
            else:
                journal.recovered_at = i + 1
            journal.cut(start, raw)
            break
        else:
            if raw and not raw.endswith(b"\n"):   # whole, but its newline was never written
                with open(journal.path, "ab") as fh:
                    fh.write(b"\n")
        return journal

    def cut(self, at: int, raw: bytes | None = None) -> None:
        """Keep the journal as it is in ``journal.jsonl.damaged`` and truncate it at byte
        ``at`` (the start of the first line not kept)."""
        from ..fileio import atomic_write

        raw = self.path.read_bytes() if raw is None else raw
        self.kept = _unused(self.path.with_name(JOURNAL + ".damaged"))
        atomic_write(self.kept, raw)
        with open(self.path, "r+b") as fh:
            fh.truncate(at)
            fh.flush()
            os.fsync(fh.fileno())

    def discard_if_unused(self) -> bool:
        """Remove this session when its journal holds nothing but its start and the choice of a
        behavior (a lesson refused at its first commands): it would be the newest, the one
        ``mitos teach --resume`` picks, and holds nothing to continue (a run, a rule, an example
        is kept). True when removed; a directory holding anything else (a kept damaged journal,
        a file of the user's) stays."""
        if any(e["op"] not in ("start", "activate") for e in self.entries):
            return False
        known = {JOURNAL, "lock", "history"}
        try:
            if any(p.name not in known for p in self.directory.iterdir()):
                return False
            held = _HELD.pop(self.directory.resolve(), None)
            if held is not None:
                held.close()                    # type: ignore[attr-defined]
            for name in known:
                (self.directory / name).unlink(missing_ok=True)
            self.directory.rmdir()
        except OSError:
            return False
        return True

    @property
    def aside(self) -> Path:
        """Where :meth:`cut` kept the journal as it was."""
        return self.kept or self.path.with_name(JOURNAL + ".damaged")

    @property
    def next_seq(self) -> int:
        return (self.entries[-1]["seq"] + 1) if self.entries else 1

    def append(self, op: str, **data: object) -> dict:
        """Add an entry and make it durable before returning."""
        entry = {"seq": self.next_seq, "op": op, **data}
        line = json.dumps(entry, ensure_ascii=False, separators=(",", ":")) + "\n"
        with held_interrupt():
            try:
                _append_line(self.path, line.encode("utf-8"))
            except OSError as exc:
                raise LessonError(f"cannot write the journal {self.path}: "
                                  f"{exc.strerror or exc}; the change was not made") from None
            self.entries.append(entry)
            self.lines.append((self.lines[-1] + 1) if self.lines else 1)
        return entry

    def line_of(self, entry: dict) -> int:
        """The journal line of ``entry``."""
        for e, line in zip(self.entries, self.lines):
            if e is entry:
                return line
        return 0

    def active(self, upto: int | None = None) -> list[dict]:
        """The change entries that were not undone, in order (as they stood after entry
        ``upto``, when given)."""
        entries = self.entries if upto is None else [e for e in self.entries if e["seq"] <= upto]
        undone = {e["of"] for e in entries if e["op"] == "undo"}
        return [e for e in entries if e["seq"] not in undone and e["op"] not in RECORDS]


#: The signals held while the journal is written and while a save is journaled: Ctrl-C, and
#: the two that `mitos teach` answers as it (SIGHUP: not on Windows).
HELD = ("SIGINT", "SIGTERM", "SIGHUP")


@contextlib.contextmanager
def held_interrupt() -> Iterator[None]:
    """Hold a Ctrl-C (SIGINT), a SIGTERM or a SIGHUP until the block ends, then deliver it:
    one during the journal's fsync (the longest part of a change) was raised after the line
    was on disk and before the session counted it, so the next change was numbered alike and
    the journal was damaged there. SIGTERM and SIGHUP stop `mitos teach` as Ctrl-C does
    (:class:`~mitos_cli.errors.Terminated`), so they are held alike; one whose handler is the
    system's default ends the process once the block is done, as the signal does. (Only the
    main thread may set a handler: elsewhere, as before; an ignored signal, or one whose
    handler was set outside Python, is left alone.)"""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[tuple] = []
    previous = {}
    for name in HELD:
        number = getattr(signal, name, None)
        if number is None:
            continue
        handler = signal.getsignal(number)
        if handler is None or handler == signal.SIG_IGN:
            continue
        previous[number] = signal.signal(number, lambda *args: caught.append(args))
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
        if caught:
            _deliver(caught[0], previous[caught[0][0]])


def _deliver(caught: tuple, handler: object) -> None:
    """A signal held by :func:`held_interrupt`, given to the handler it was held from."""
    signum = caught[0]
    if callable(handler):
        handler(*caught)                      # Python's for SIGINT: raises KeyboardInterrupt
    elif signum == signal.SIGINT:
        raise KeyboardInterrupt
    else:
        signal.raise_signal(signum)           # the default: the process ends as by the signal


def _unused(path: Path) -> Path:
    """``path``, or ``path.2``, ``path.3``, ... when it is taken: a journal damaged a second
    time was kept over the first one kept aside, which may hold changes told after the first
    damaged line (`--recover` continued before them), so they were lost."""
    n = 1
    while path.exists() or path.is_symlink():
        n += 1
        path = path.with_name(f"{JOURNAL}.damaged.{n}")
    return path


def _append_line(path: Path, data: bytes) -> None:
    """Append ``data`` whole and durably, or not at all: a write the disk could take only part
    of (full, or over the size limit) is cut off again, since the next change appended after
    its half line would be read as one damaged line, and `--recover` would drop it."""
    with open(path, "ab", buffering=0) as fh:
        start = os.fstat(fh.fileno()).st_size
        try:
            view = memoryview(data)
            while view:
                written = fh.write(view)
                if not written:                 # (a regular file takes at least a byte)
                    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
                view = view[written:]
            os.fsync(fh.fileno())
        except OSError:
            with contextlib.suppress(OSError):
                fh.truncate(start)
                os.fsync(fh.fileno())
            raise


#: the sessions this process holds (their lock files stay open until it exits)
_HELD: dict[Path, object] = {}


@atexit.register
def _release() -> None:
    """Close the lock files still held as the process ends (the system would release their
    locks all the same; a file left to the interpreter's teardown is reported unclosed)."""
    for fh in _HELD.values():
        fh.close()                               # type: ignore[attr-defined]
    _HELD.clear()


def _lock(directory: Path) -> None:
    """Hold ``directory``'s session for this process: two processes appending to one journal
    would both number their next change alike and damage it (an advisory ``flock`` on
    ``lock``, released by the system when the process ends, ``kill -9`` included; where the
    system has no ``flock`` sessions are not locked)."""
    try:
        import fcntl
    except ImportError:                          # pragma: no cover - not POSIX
        return
    key = directory.resolve()
    if key in _HELD:
        return
    path = directory / "lock"
    try:
        fh = open(path, "a+", encoding="utf-8")  # noqa: SIM115 (held until the process ends)
    except OSError as exc:
        raise LessonError(f"cannot open the session's lock {path}: {exc.strerror or exc}") \
            from None
    try:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        fh.seek(0)
        pid = fh.read().strip()
        fh.close()
        raise LessonError(f"session {directory.name} is open in another `mitos teach`"
                          + (f" (process {pid})" if pid.isdigit() else ""),
                          hint="finish or quit that one first; two at once would both write "
                               "its journal") from None
    fh.truncate(0)
    fh.write(str(os.getpid()))
    fh.flush()
    _HELD[key] = fh


#: what each kind of entry must carry, and of which type
FIELDS: dict[str, dict[str, type]] = {"start": {"rules": str, "behavior": str},
                                      "rule": {"text": str, "behavior": str},
          "behavior": {"name": str}, "end": {}, "use": {"text": str},
          "frozen": {"labels": list, "behavior": str}, "operators": {"text": str,
                                                                    "behavior": str},
          "activate": {"behavior": str}, "examples": {"examples": list},
          "adapt": {"terms": dict}, "undo": {"of": int}, "save": {},
          "freeze": {"terms": list}, "release": {"terms": list},
          "simulate": {"world": str, "behavior": str}}

#: entries that record what happened without changing the rule base
RECORDS = ("undo", "start", "save", "simulate")


#: JSON's names for the types ``json.loads`` gives (for messages about a journal line)
_JSON_TYPE = {list: "array", dict: "object", int: "number", float: "number", bool: "boolean",
              type(None): "null"}


def _shown(entry: dict, key: str) -> str:
    """``entry[key]`` for a message: its JSON text when short, else its JSON type (a mutated
    journal's 200,000-element array is no help quoted whole)."""
    if key not in entry:
        return "missing"
    value = entry[key]
    text = json.dumps(value) if not isinstance(value, (list, dict)) else ""
    if text and len(text) <= 40:
        return text
    return f"a JSON {_JSON_TYPE.get(type(value), 'string')}"


def _finite(x: object) -> bool:
    """Whether ``x`` is a JSON number a float holds: finite, and not an integer of 400 digits
    (``math.isfinite`` of one raised ``OverflowError``)."""
    if type(x) is int:
        return abs(x) <= sys.float_info.max
    return type(x) is float and math.isfinite(x)


def _numbers(values: object) -> bool:
    """Whether ``values`` is a JSON object of finite numbers by name."""
    return isinstance(values, dict) and all(
        isinstance(k, str) and _finite(v)
        for k, v in values.items())


def _examples_problem(entry: dict) -> str | None:
    """What is wrong with an ``examples`` entry's examples (``None``: nothing); that their
    names are the behavior's is checked when the entry is replayed."""
    if not isinstance(entry.get("behavior", ""), str):
        return f"the `examples` change's `behavior` is {_shown(entry, 'behavior')}, not a name"
    for i, example in enumerate(entry["examples"], 1):
        if not isinstance(example, dict) or not _numbers(example.get("inputs")) \
                or not _numbers(example.get("targets")) \
                or not isinstance(example.get("source", ""), str):
            return (f"example {i} of the `examples` change is not inputs and targets given as "
                    f"numbers by name")
    return None


def _adapt_problem(entry: dict) -> str | None:
    """What is wrong with an ``adapt`` entry's learned numbers (``None``: nothing)."""
    terms = entry["terms"]
    if not all(isinstance(v, str) and isinstance(ts, dict) and all(
            isinstance(t, str) and isinstance(ps, list) and ps and all(
                _finite(x) for x in ps)
            for t, ps in ts.items()) for v, ts in terms.items()):
        return "the `adapt` change's `terms` are not parameters by variable and term"
    crisp = entry.get("crisp", [])
    if not isinstance(crisp, list) or not all(
            isinstance(c, list) and len(c) == 4 and isinstance(c[0], str)
            and type(c[1]) is int and c[1] >= 0 and isinstance(c[2], str)
            and _finite(c[3]) for c in crisp):
        return "the `adapt` change's `crisp` are not [behavior, rule, output, value] rows"
    q = entry.get("q", [0.0, 0.0])
    if not isinstance(q, list) or len(q) != 2 or not all(
            _finite(x) for x in q):
        return "the `adapt` change's `q` is not its Q before and after"
    return None


def _problem(line: bytes, seq: int) -> str | None:
    """What is wrong with one journal line (``None``: nothing)."""
    try:
        entry = json.loads(line)
    except (ValueError, UnicodeDecodeError, RecursionError):
        return "the line is not JSON"
    if not isinstance(entry, dict):
        return "the line is not a JSON object"
    try:                     # a `\ud800` escape: half a character, which no path or text holds
        json.dumps(entry, ensure_ascii=False).encode("utf-8")
    except UnicodeEncodeError:
        return "the line holds a `\\u` escape of half a character (a lone surrogate)"
    if entry.get("seq") != seq or type(entry.get("seq")) is not int:
        return f"expected change number {seq}, found {_shown(entry, 'seq')}"
    op = entry.get("op")
    if not isinstance(op, str):        # a list or an object cannot be looked up (TypeError)
        return f"the change's name (`op`) is {_shown(entry, 'op')}, not a string"
    if op not in FIELDS:
        return f"unknown change {_shown(entry, 'op')}"
    for key, kind in FIELDS[op].items():
        if not isinstance(entry.get(key), kind) or isinstance(entry.get(key), bool):
            return f"the `{op}` change has no valid `{key}`"
    for key in ("terms", "holds") if op in ("freeze", "release") else ():
        refs = entry.get(key, [])
        if not isinstance(refs, list) or not all(
                isinstance(ref, list) and len(ref) == 2 and all(isinstance(x, str) for x in ref)
                for ref in refs):
            return f"the `{op}` change's `{key}` are not [variable, term] pairs"
    # paths: a `save_as` of `true` was a TypeError, a save without its path a KeyError
    if op == "start" and not isinstance(entry.get("save_as"), (str, type(None))):
        return "the `start` change's `save_as` is not a path"
    if op == "save" and not isinstance(entry.get("path"), str):
        return "the `save` change has no valid `path`"
    if op == "examples":
        return _examples_problem(entry)
    if op == "adapt":
        return _adapt_problem(entry)
    if op == "frozen" and not all(isinstance(x, str) for x in entry["labels"]):
        return "the `frozen` change's `labels` are not rule labels"
    for key in ("rules", "path", "save_as", "world"):      # a path the system cannot open
        if "\0" in str(entry.get(key) or ""):
            return f"the `{op}` change's `{key}` holds a NUL byte"
    if op == "simulate" and (type(entry.get("seed")) not in (int, type(None))
                             or not all(isinstance(entry.get(k), (str, type(None)))
                                        for k in ("robot", "run", "verdict"))):
        return "the `simulate` record has no valid `seed`, `robot`, `run` or `verdict`"
    return None


class MemoryJournal(Journal):
    """A journal that keeps entries in memory only (library use, benchmarks, tests)."""

    def __init__(self) -> None:
        super().__init__(Path("."))

    def append(self, op: str, **data: object) -> dict:
        entry = {"seq": self.next_seq, "op": op, **data}
        self.entries.append(entry)
        return entry
