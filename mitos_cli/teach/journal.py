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

import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import LessonError

ROOT = Path(".mitos") / "teach"
JOURNAL = "journal.jsonl"


def sessions_dir(base: Path | None = None) -> Path:
    return (base or Path.cwd()) / ROOT


def new_session_dir(stem: str, base: Path | None = None) -> Path:
    """A fresh directory ``.mitos/teach/<stem>-<date>-<time>[-n]``."""
    root = sessions_dir(base)
    name = f"{stem}-{time.strftime('%Y%m%d-%H%M%S')}"
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
    found = sorted((p for p in root.glob("*/" + JOURNAL)), key=lambda p: p.stat().st_mtime) \
        if root.is_dir() else []
    if name is not None:
        direct = Path(name)
        if (direct / JOURNAL).is_file():
            return direct
        if (root / name / JOURNAL).is_file():
            return root / name
        from ..errors import unknown

        raise unknown("teaching session", name, [p.parent.name for p in found],
                      cls=LessonError)
    if not found:
        raise LessonError(f"no teaching session to resume in {ROOT}/",
                          hint="start one with `mitos teach RULES`")
    return found[-1].parent


@dataclass
class Journal:
    """An append-only JSON-lines file of one session's changes."""

    directory: Path
    entries: list[dict] = field(default_factory=list)
    skipped_tail: bool = False

    @property
    def path(self) -> Path:
        return self.directory / JOURNAL

    @classmethod
    def create(cls, directory: Path) -> Journal:
        directory.mkdir(parents=True, exist_ok=True)
        journal = cls(directory)
        journal.path.touch()
        return journal

    @classmethod
    def open(cls, directory: Path) -> Journal:
        """Read an existing journal (a last line cut short by a kill is dropped)."""
        journal = cls(directory)
        raw = journal.path.read_bytes()
        lines = raw.split(b"\n")
        for i, line in enumerate(lines):
            if not line.strip():
                continue
            try:
                journal.entries.append(json.loads(line))
            except (json.JSONDecodeError, UnicodeDecodeError):
                if i == len(lines) - 1:
                    journal.skipped_tail = True
                    with open(journal.path, "r+b") as fh:     # drop the torn line for good
                        fh.truncate(len(raw) - len(line))
                    break
                raise LessonError(f"{journal.path}:{i + 1}: the journal is damaged "
                                  f"(not JSON)") from None
        return journal

    @property
    def next_seq(self) -> int:
        return (self.entries[-1]["seq"] + 1) if self.entries else 1

    def append(self, op: str, **data) -> dict:
        """Add an entry and make it durable before returning."""
        entry = {"seq": self.next_seq, "op": op, **data}
        line = json.dumps(entry, ensure_ascii=False, separators=(",", ":")) + "\n"
        try:
            with open(self.path, "a", encoding="utf-8") as fh:
                fh.write(line)
                fh.flush()
                os.fsync(fh.fileno())
        except OSError as exc:
            raise LessonError(f"cannot write the journal {self.path}: "
                              f"{exc.strerror or exc}; the change was not made") from None
        self.entries.append(entry)
        return entry

    def active(self) -> list[dict]:
        """The change entries that were not undone, in order."""
        undone = {e["of"] for e in self.entries if e["op"] == "undo"}
        return [e for e in self.entries if e["seq"] not in undone and e["op"] not in
                ("undo", "start", "save")]


class MemoryJournal(Journal):
    """A journal that keeps entries in memory only (library use, benchmarks, tests)."""

    def __init__(self) -> None:
        super().__init__(Path("."))

    def append(self, op: str, **data) -> dict:
        entry = {"seq": self.next_seq, "op": op, **data}
        self.entries.append(entry)
        return entry
