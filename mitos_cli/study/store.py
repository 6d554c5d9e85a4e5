"""``results.csv``: one row per finished run, written the moment it arrives.

Each row is appended, flushed and fsync'ed, so a study that is killed (or whose worker dies)
loses no finished result; ``--resume`` reads the rows back and skips their tasks. A row cut off
by the kill (no final newline, fewer values than a row) is dropped and recomputed; a whole last
row without its newline (as an editor saves a file) is a row. Nothing is written before a study
is known to go on. Floats are written with ``repr``, so they read back bit for bit.
``study.json`` beside it records what the study was (seed, worlds, choices, runs, rule base).
A world is the file, not the path as typed: a study resumes from any directory, and its rows
keep the names of the worlds they were written with.
"""

from __future__ import annotations

import contextlib
import csv
import functools
import io
import json
import math
import os
import re
import shlex
import weakref
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from ..errors import MitosError, Span, did_you_mean
from ..fileio import bad_byte, file_in_the_way, read_text, unreadable
from ..resources import is_file
from ..words import plural
from .spec import KEY_FIELDS, Task

if TYPE_CHECKING:
    import _csv
    from collections.abc import Callable

#: what a run reports, in this order, after the key and the seed (``replans``: routes planned
#: again; ``backouts``: times a robot backed out; both summed over the robots)
RESULT_FIELDS = ("outcome", "collisions", "time_s", "path_length_in", "min_clearance_in",
                 "mean_speed_in_s", "steering_total_variation_deg", "ticks", "replans",
                 "backouts")
FLOAT_FIELDS = frozenset({"time_s", "path_length_in", "min_clearance_in", "mean_speed_in_s",
                          "steering_total_variation_deg"})
INT_FIELDS = frozenset({"collisions", "ticks", "run", "seed", "replans", "backouts"})
COLUMNS = (*KEY_FIELDS, "seed", *RESULT_FIELDS)
#: the columns of results.csv before it had ``replans`` and ``backouts`` (its rows cannot be
#: resumed: they lack figures every row of the study's report must have)
COLUMNS_BEFORE_REPLANS = COLUMNS[:-2]
#: the columns of a study with a world of several robots: each run of such a world has a row
#: per robot (``robot``: its name), then the run's own row (``robot`` empty: the fleet's
#: figures, as every run of a one-robot world has); ``ticks`` is the run's, empty in a
#: robot's row
FLEET_COLUMNS = (*KEY_FIELDS, "robot", "seed", *RESULT_FIELDS)
OUTCOMES = ("success", "collision", "timeout", "stuck")
#: a robot's own outcome may also be ``stopped``: still driving when another robot's collision
#: or stuck ended the run (``sim.loop.ROBOT_OUTCOMES``, which the simulator's import brings)
ROBOT_OUTCOMES = (*OUTCOMES, "stopped")
#: the fields no run reports below 0 (counts, a time, a length, a speed, a variation, the run's
#: index and seed; a clearance is below 0 where a robot overlaps what it hit)
NON_NEGATIVE = frozenset({"collisions", "time_s", "path_length_in", "mean_speed_in_s",
                          "steering_total_variation_deg", "ticks", "replans", "backouts", "run",
                          "seed"})


#: the largest size of a figure any run reports (a world's numbers are at most 1e7: 1e7 in/s
#: for 1e7 s), and small enough that no mean or spread of a study's figures overflows (a
#: `1e308`, or a count of 400 digits, made the tables `inf±inf`, or an OverflowError)
LARGEST_FIGURE = 1e15
TOO_LARGE = "more than any run reports"


class StudyError(MitosError):
    """A study directory that cannot be written or resumed."""

    kind = "study error"


def row_of(task: Task, result: dict) -> dict:
    """The CSV row of a finished task: its key, its seed and the simulator's result; with
    several robots, each robot's figures under ``robots`` (``robot``: its name; no ``ticks``),
    as :meth:`.SimResult.summary` gives them."""
    c = task.choice
    row = {"world": task.world, "planner": c.planner, "and": c.and_, "or": c.or_,
           "inference": c.inference, "run": task.run, "seed": task.seed}
    for f in RESULT_FIELDS:
        row[f] = result[f]
    if result.get("robots"):
        row["robots"] = [{"robot": r["robot"], **{f: r.get(f) for f in RESULT_FIELDS}}
                         for r in result["robots"]]
    return row


def key_of(row: dict) -> tuple[str, ...]:
    return tuple(str(row[k]) for k in KEY_FIELDS)


def _format(value: object) -> str:
    if value is None:               # (a robot's ticks: the run's row holds them)
        return ""
    if isinstance(value, float):
        return repr(value)          # shortest string that reads back to the same double
    return str(value)


def _expected(field: str, outcomes: tuple[str, ...] = OUTCOMES) -> str:
    """What a field of a row must be (``outcomes``: a run's, or a robot's)."""
    if field == "outcome":
        return "one of " + ", ".join(outcomes)
    kind = "a whole number" if field in INT_FIELDS else "a finite number"
    return kind + (", 0 or more" if field in NON_NEGATIVE else "")


def _wrong(field: str, value: Any,       # as parsed: the field decides str, int or float
           outcomes: tuple[str, ...] = OUTCOMES) -> str | None:
    """What is wrong with a row's parsed ``value`` of ``field`` (``None``: did not parse),
    or ``None`` when nothing is (``outcomes``: a run's, or a robot's)."""
    if value is None:
        return "not a number"
    if field == "outcome" and value not in outcomes:
        return "not an outcome of a " + ("run" if outcomes == OUTCOMES else "robot")
    if field in FLOAT_FIELDS and not math.isfinite(value):
        return "which no run reports"
    if field in RESULT_FIELDS and field != "outcome" and abs(value) > LARGEST_FIGURE:
        return TOO_LARGE
    if field in NON_NEGATIVE and value < 0:
        return "which no run reports"
    return None


def _label(row: dict) -> str:
    """A row's choice as messages name it: ``fuzzy, and=min``."""
    return ", ".join([row["planner"]] + [f"{k}={row[k]}" for k in ("and", "or", "inference")
                                         if row[k]])


def _parse(field: str, text: str) -> str | int | float:
    if field in FLOAT_FIELDS:
        return float(text)
    if field in INT_FIELDS:
        return int(text)
    return text


class ResultStore:
    """The results of one study directory."""

    def __init__(self, directory: str | Path) -> None:
        self.dir = Path(directory)
        self.path = self.dir / "results.csv"
        self.manifest_path = self.dir / "study.json"
        self._file: TextIO | None = None
        self._keep: int | None = None      # the bytes before a torn last line (see load)
        self._unended = False              # a whole last row without its newline
        self._at: list[tuple[int, str, list[str]]] = []   # each row's line: number, text, values
        self._names: dict[str, str] = {}   # a world as given now -> as the rows name it
        self._manifest_text = ""           # study.json as :meth:`manifest` read it last
        self._held: int | None = None      # the directory, locked while a study runs in it
        self.columns: tuple[str, ...] = COLUMNS    # the file's (:data:`FLEET_COLUMNS`: a row
                                                   # per robot)

    # -- reading -----------------------------------------------------------------------------

    def load(self) -> list[dict]:
        """The finished rows, one per run (a run of several robots with its robots' rows
        under ``robots``). Reading never writes: a last line without its newline is a row
        when it is a whole one (an editor saves a file so), and is left out when it was cut
        short (a kill in the middle of a row), and so are the robots' rows of a run whose own
        row, written after them, is not there; :meth:`start` mends the file only once the
        study goes on."""
        self._keep, self._unended = None, False
        self.columns = COLUMNS
        if not self.path.exists():
            return []
        _refuse_special(self.path, "results file")
        data, text = self._whole_lines()
        if not text:
            return []
        reader = csv.reader(io.StringIO(text, newline=""))
        try:
            self.columns = self._header(next(reader), text)
            rows = self._runs(reader, text, data)
            self._refuse_twice(rows)
            return rows
        except csv.Error as exc:               # a field past csv's limit
            line_no = reader.line_num
            line = text.splitlines()[line_no - 1] if line_no else ""
            raise StudyError(f"line {line_no} is not a row of results ({exc})",
                             span=Span(str(self.path), line_no, 1, line[:200]),
                             hint="the file was edited by hand; remove that line") from None

    def _whole_lines(self) -> tuple[bytes, str]:
        """The file's bytes and its text up to the end of its last whole line: a last line
        without its newline is kept (with one) when it is a whole row, as an editor saves a
        file, and is left out when a kill cut it short (:meth:`_mend` cuts it off later)."""
        try:
            data = self.path.read_bytes()
            cut = data.rfind(b"\n") + 1
            text = data[:cut].decode("utf-8-sig")          # (a byte-order mark is not content)
        except (OSError, UnicodeDecodeError) as exc:
            raise StudyError(unreadable("results file", self.path, exc), span=bad_byte(
                self.path, exc), hint=f"choose another output directory with -o, or remove "
                                      f"{self.path} to run the study again") from None
        last = _whole_line(data[cut:], text.partition("\n")[0].rstrip("\r") if cut else None)
        if last is not None:
            text, self._unended = text + last + "\n", True
        elif cut < len(data):                              # killed in the middle of a row
            self._keep = cut
        return data, text

    def _header(self, header: list[str], text: str) -> tuple[str, ...]:
        """The file's columns, refused unless this version wrote them (a file of an earlier
        version lacks figures every run reports now)."""
        top = Span(str(self.path), 1, 1, text.splitlines()[0][:200])   # (the header's line)
        if tuple(header) == COLUMNS_BEFORE_REPLANS:
            raise StudyError(f"{self.path} was written by an earlier version of mitos: its "
                             f"rows have no replans and backouts, which this version "
                             f"reports for every run", span=top,
                             hint="run the study again in another directory with -o")
        if tuple(header) not in (COLUMNS, FLEET_COLUMNS):
            raise StudyError(f"{self.path} is not a results file of this version of mitos",
                             span=top, expected="the columns " + ",".join(COLUMNS)
                             + " (with `robot` after `run` in a study of several robots)",
                             hint="choose another output directory with -o")
        return tuple(header)

    def _runs(self, reader: _csv.Reader, text: str, data: bytes) -> list[dict]:
        """The rows after the header, a run's robots' rows (written before the run's own) under
        its ``robots``; each row's line in :attr:`_at`. The robots' rows of a run whose own
        row is not there (killed as they were written) are left out, to be cut off."""
        lines, rows, self._at = text.splitlines(), [], []
        robots: list[tuple[dict, tuple[int, str, list[str]]]] = []   # before their run's
        ended = reader.line_num                        # the line the last run's rows end on
        for values in reader:
            line_no = reader.line_num                  # (a row's last line)
            at = (line_no, lines[line_no - 1], values)
            row = self._row(*at)
            name = row.pop("robot", "")
            if robots and key_of(robots[0][0]) != key_of(row):
                self._orphans(robots)
            if name:
                self._robot_once(robots, row, name, at)
                robots.append(({**row, "robot": name}, at))
                continue
            if robots:
                row["robots"] = self._robots_of(row, at, robots)
                robots = []
            rows.append(row)
            self._at.append(at)
            ended = line_no
        if robots:       # a run's robots without the run's own row: killed as they were
            self._keep, self._unended = _line_end(data, ended), False      # written
        return rows

    def _row(self, line_no: int, line: str, values: list[str]) -> dict:
        """Line ``line_no``'s ``values`` as a row, checked: what a run (or a robot of it) can
        report (a known outcome, whole numbers, finite figures, no count, time or length below
        0, a collision counted where the outcome is one), so that a row edited by hand cannot
        count as a run it is not (a misspelt outcome in no column, a ``nan`` left out of a
        mean, a time of -5 s in one)."""
        columns = self.columns
        if len(values) != len(columns):
            raise StudyError(f"expected {len(columns)} values in a row, found {len(values)}",
                             span=Span(str(self.path), line_no, 1, line[:200]),
                             hint="the file was edited by hand; remove that line")
        robot = "robot" in columns and values[columns.index("robot")] != ""
        outcomes = ROBOT_OUTCOMES if robot else OUTCOMES
        row: dict = {}                # each field's value as its kind parses it
        for j, (f, v) in enumerate(zip(columns, values)):
            if robot and f == "ticks":          # (the run's row holds them)
                row[f] = None
                if v != "":
                    raise StudyError(f"`ticks` is `{v:.40}` in the row of robot "
                                     f"`{values[columns.index('robot')]:.40}`",
                                     span=self._span(line_no, line, values, j),
                                     expected="empty: a run's ticks are in its own row",
                                     hint="the file was edited by hand; remove that line")
                continue
            try:
                row[f] = value = _parse(f, v)
            except ValueError:
                value = None
            bad = _wrong(f, value, outcomes)
            if bad:
                hint = did_you_mean(v, outcomes) if f == "outcome" else None
                raise StudyError(f"`{f}` is `{v:.40}`, {bad}",
                                 span=self._span(line_no, line, values, j),
                                 expected=_expected(f, outcomes) + (
                                     f", within ±{LARGEST_FIGURE:g}" if bad == TOO_LARGE else ""),
                                 hint=hint or "the file was edited by hand; remove that line")
        if (row["outcome"] == "collision") != (row["collisions"] > 0) or (
                robot and row["collisions"] > 1):
            j = columns.index("collisions")
            raise StudyError(f"`collisions` is `{values[j]}` in a row whose outcome is "
                             f"`{row['outcome']}`", span=self._span(line_no, line, values, j),
                             expected=("1 where the robot's outcome is `collision`, else 0"
                                       if robot else "1 or more where the outcome is "
                                       "`collision`, else 0 (a run's outcome is `collision` "
                                       "when a robot collided)"),
                             hint="the file was edited by hand; remove that line")
        return row

    def _robot_once(self, robots: list, row: dict, name: str,
                    at: tuple[int, str, list[str]]) -> None:
        """A robot's row for a run whose rows already hold one of that robot: refused."""
        for held, (line_no, _, _) in robots:
            if held["robot"] == name:
                raise StudyError(
                    f"robot `{name}` of run {row['run']} of {Path(row['world']).name} "
                    f"({_label(row)}) is here a second time: its first row is line {line_no}",
                    span=self._span(at[0], at[1], at[2], self.columns.index("robot")),
                    hint="the file was edited by hand; remove one of the two lines")

    def _orphans(self, robots: list) -> None:
        """Robots' rows followed by another run's rows, not their own run's: a run's rows
        are written together, its own last, so only a hand edit leaves them."""
        first, (line_no, line, values) = robots[0]
        raise StudyError(
            f"the row of robot `{first['robot']}` of run {first['run']} of "
            f"{Path(first['world']).name} ({_label(first)}) is not followed by its run's row "
            f"(`robot` empty), which ends a run's rows",
            span=self._span(line_no, line, values, self.columns.index("robot")),
            hint="the file was edited by hand; remove the robots' rows of that run")

    def _robots_of(self, row: dict, at: tuple[int, str, list[str]],
                   robots: list) -> list[dict]:
        """The robots' rows of run ``row`` (at ``at``), as :func:`row_of` gives them; its
        ``collisions`` must count its robots' (the simulator's do)."""
        out = [{"robot": r["robot"], **{f: r[f] for f in RESULT_FIELDS}} for r, _ in robots]
        crashed = sum(r["outcome"] == "collision" for r in out)
        if row["collisions"] != crashed:
            raise StudyError(f"`collisions` is `{row['collisions']}` in a run whose robots' "
                             f"rows hold {plural(crashed, 'collision')}",
                             span=self._span(*at, self.columns.index("collisions")),
                             expected="the robots' collisions, counted",
                             hint="the file was edited by hand; remove that run's lines")
        return out

    def _refuse_twice(self, rows: list[dict]) -> None:
        """A run held twice (a row copied, two results files joined): the study would count
        it twice, or take itself for one that leaves out runs. ``rows`` are those of
        :meth:`load`, in its order."""
        first: dict[tuple[str, ...], int] = {}
        for row, (line_no, line, values) in zip(rows, self._at):
            key = key_of(row)
            if key in first:
                raise StudyError(
                    f"run {row['run']} of {Path(row['world']).name} ({_label(row)}) is here a "
                    f"second time: its first row is line {first[key]}",
                    span=self._span(line_no, line, values, 0, len(KEY_FIELDS) - 1),
                    hint="the file was edited by hand, or two results files were joined; "
                         "remove one of the two lines")
            first[key] = line_no

    def _span(self, line_no: int, line: str, values: list[str], first: int,
              last: int | None = None) -> Span:
        """Where fields ``first`` to ``last`` (default: ``first``) of a row are on its line
        (its start where a field is quoted)."""
        last = first if last is None else last
        if line.split(",") != values:                   # a field quoted: no column to tell
            return Span(str(self.path), line_no, 1, line[:200])
        column = sum(len(w) + 1 for w in values[:first]) + 1
        width = sum(len(w) + 1 for w in values[first:last + 1]) - 1
        return Span(str(self.path), line_no, column, line[:200], end_column=column + width)

    def manifest(self) -> dict | None:
        """What ``study.json`` says the study was; ``None`` when there is none."""
        if not self.manifest_path.exists():
            return None
        _refuse_special(self.manifest_path, "study manifest")
        hint = (f"choose another output directory with -o, or remove {self.manifest_path} "
                f"and {self.path} to run the study again")
        try:
            text = read_text(self.manifest_path)
            got = json.loads(text)
        except (OSError, UnicodeDecodeError) as exc:
            raise StudyError(unreadable("study manifest", self.manifest_path, exc),
                             span=bad_byte(self.manifest_path, exc), hint=hint) from None
        except json.JSONDecodeError as exc:
            raise StudyError(f"{self.manifest_path} is not JSON: {exc.msg}",
                             span=Span(str(self.manifest_path), exc.lineno, exc.colno),
                             hint=hint) from None
        except RecursionError:                   # nested past what the reader follows
            raise StudyError(f"{self.manifest_path} is not a study manifest: it nests too "
                             f"deep to read", hint=hint) from None
        except ValueError as exc:                # a number of more digits than int() reads
            long = re.search(r"[0-9]{4000,}", text)
            raise StudyError(f"{self.manifest_path} is not a study manifest: {exc}",
                             span=long and _at(text, str(self.manifest_path), long.start()),
                             hint=hint) from None
        path = str(self.manifest_path)
        self._manifest_text = text
        wrong = _misshapen(got)
        if wrong is not None:
            key, why = wrong
            raise StudyError(f"{path} is not a study manifest: {why}",
                             span=(key and _key_span(text, path, key)) or Span(path, 1, 1),
                             expected="a JSON object (the study's seed, worlds and choices; "
                                      "its `digests` an object of file digests, its "
                                      "`command` a string)",
                             hint=hint)
        seed = got.get("seed")
        if type(seed) is not int or seed < 0:      # `"1"` said "made with --seed 1, not 1"
            raise StudyError(f"{path} is not a study manifest: its `seed` is "
                             f"{_written(text, 'seed') or _shown(got, 'seed')}, not a whole "
                             f"number", span=_key_span(text, path, "seed"),
                             expected="the study's --seed, such as 1", hint=hint)
        return got

    def _check_same_study(self, old: dict, manifest: dict, worlds: dict[str, str]) -> None:
        """The rows in the directory were made by the study ``manifest`` describes now: the
        same seed and behavior, and every world (``worlds``: as the rows name them -> as
        given now) and the rule base unchanged since."""
        if old.get("seed") != manifest.get("seed"):
            raise StudyError(f"{self.path} was made with --seed {old.get('seed')}, "
                             f"not {manifest.get('seed')}", span=self._said("seed"),
                             hint=f"resume with --seed {old.get('seed')}, or choose another "
                                  "directory with -o")
        _check_behavior(old, manifest, self.path, self._said("behavior"))
        now = manifest.get("digests") or {}
        _check_unchanged(old.get("digests") or {}, {
            **now, **{name: now[w] for name, w in worlds.items() if w in now}}, self.path,
            self._said)

    def _said(self, key: str) -> Span | None:
        """Where ``study.json`` (as :meth:`manifest` read it) writes ``key``, the place a
        refusal of what it records shows."""
        return _key_span(self._manifest_text, str(self.manifest_path), key)

    # -- writing -----------------------------------------------------------------------------

    def start(self, manifest: dict, tasks: list[Task], *, resume: bool,
              robots: dict[str, tuple[str, ...]] | None = None) -> tuple[list[dict], list[Task]]:
        """Open the directory for a study of ``tasks``: the rows already finished (with
        ``resume``, in task order) and the tasks still to run. ``robots``: each world of the
        study (as given) that has several robots, and their names: its runs have a row per
        robot (:data:`FLEET_COLUMNS`; a study without one writes :data:`COLUMNS`, as before).

        Without ``resume`` an existing ``results.csv`` with rows is an error rather than being
        overwritten; with it, the directory must hold a study (its ``study.json`` or
        ``results.csv``, with rows or not), which must have the same seed as the one that
        wrote the rows and give every finished run the seed it was made with
        (:func:`rows_for`). A world of the rows given now by another path (from another
        directory) is the same world when it is the same file or has the digest ``study.json``
        records for it (:func:`_worlds_of`); the rows go on naming it as they did.
        Everything is checked before anything is written: a refused study leaves the directory
        as it was.
        """
        self._open_dir(resume)
        self._hold()
        _refuse_special(self.manifest_path, "study manifest")   # (written to below)
        rows = loaded = self.load()
        if rows and not resume:
            raise StudyError(f"{self.path} already holds {plural(len(rows), 'result')}",
                             hint="pass --resume to continue that study, or choose another "
                                  "directory with -o")
        old = self.manifest() if rows else None
        given = list(manifest.get("worlds") or [])
        worlds = _worlds_of(rows, old or {}, manifest)
        if old is not None:
            self._check_same_study(old, manifest, worlds)
        if any(name != w for name, w in worlds.items()):   # the rows, their worlds named as now
            rows = [{**r, "world": worlds.get(r["world"], r["world"])} for r in rows]
            self._refuse_twice(rows)         # (one world under two of its names)
        self._names = _written_names(worlds)
        manifest = _renamed(manifest, self._names)
        finished, todo = rows_for(tasks, rows)
        kept = {key_of(r) for r in finished}
        at = [i for i, r in enumerate(rows) if key_of(r) not in kept]
        if at:
            line_no, line, values = self._at[at[0]]
            _refuse_narrower([rows[i] for i in at], old or {}, self.path, self.dir, given,
                             self._span(line_no, line, values, 0, len(KEY_FIELDS) - 1))
        robots = dict(robots or {})
        widen = bool(rows and robots) and self.columns == COLUMNS
        self._check_robots(rows, robots, widen)
        write_atomic(self.manifest_path, json.dumps(manifest, indent=2) + "\n")
        if not rows or widen:      # (a file of one robot's runs, widened: its rows as they were)
            self.columns = FLEET_COLUMNS if robots else COLUMNS
            write_atomic(self.path, ",".join(self.columns) + "\n"
                         + "".join(self._lines(r, named=True) for r in (loaded if widen else [])))
        else:
            self._mend()
        # kept open across append() calls (one fsync'd line per finished run); close() closes it
        self._file = open(self.path, "a", encoding="utf-8", newline="")  # noqa: SIM115
        return finished, todo

    def _open_dir(self, resume: bool) -> None:
        """The study's directory made (only it: a mistyped parent is refused, not made) or
        found, refused with what to do when it cannot hold the study: not there to resume,
        a file, out of this user's reach, or under a file."""
        try:                  # a directory this user cannot enter: a traceback here
            there = self.dir.exists()
            previous = self.manifest_path.exists() or self.path.exists()
        except OSError as exc:
            raise StudyError(f"cannot use the output directory {self.dir}: "
                             f"{exc.strerror or exc}",
                             hint="choose a directory you can write to with -o") from None
        if there and not self.dir.is_dir():
            raise StudyError(f"`{self.dir}` is a file, not a directory for the study's results",
                             hint="choose a directory with -o (a new one is made)")
        if resume and not previous:
            # a mistyped -o began a new study under the name, and "0 from before" was all
            # that said the study meant was not resumed
            raise StudyError(f"`{self.dir}` holds no study to resume (no study.json or "
                             f"results.csv)", hint="check the directory given with -o, or "
                             "leave out --resume to start a study there")
        parent = self.dir.parent
        if not there and not parent.is_dir():
            # a file in the way (`-o notes.txt/study`): "`notes.txt` does not exist" and
            # `mkdir -p notes.txt` were no help
            found = file_in_the_way(parent)
            if found is not None:
                raise StudyError(f"cannot create the output directory `{self.dir}`: `{found}` "
                                 f"is a file, not a directory",
                                 hint="choose another directory with -o")
            # the directory alone is made, as every other writer makes only its file: a
            # mistyped parent (`-o studeis/norms`) made a tree of directories without a word
            raise StudyError(f"cannot create the output directory `{self.dir}`: `{parent}` "
                             f"does not exist",
                             hint=f"create it first (`mkdir -p {shlex.quote(str(parent))}`), "
                                  f"or choose "
                                  f"another directory with -o (compare makes the last one)")
        try:
            self.dir.mkdir(exist_ok=True)
        except OSError as exc:
            raise StudyError(f"cannot create the output directory {self.dir}: "
                             f"{exc.strerror or exc}") from None

    def _check_robots(self, rows: list[dict], robots: dict[str, tuple[str, ...]],
                      widen: bool) -> None:
        """Every run of ``rows`` (their worlds named as given now) has a row for each robot
        of its world (``robots``), as the study writes them, and no others. A file written
        before `compare` wrote a row per robot (``widen``: no ``robot`` column, and the study
        has a world of several robots) may go on only where it holds no run of such a world:
        its rows are then written again with the column, empty."""
        for row, (line_no, line, values) in zip(rows, self._at):
            want, world = robots.get(row["world"], ()), Path(row["world"]).name
            if widen and want:
                raise StudyError(
                    f"{self.path} was written before `mitos compare` wrote a row per robot: "
                    f"its runs of {world} have none, which this version writes for each run of "
                    f"a world of several robots", span=Span(str(self.path), line_no, 1,
                                                            line[:200]),
                    hint="run the study again in another directory with -o")
            names = tuple(r["robot"] for r in row.get("robots", ()))
            if names != want:
                said = ", ".join(f"`{n}`" for n in names) or "no robot"
                raise StudyError(
                    f"run {row['run']} of {world} ({_label(row)}) has rows of {said}, where the "
                    f"world's robots are " + (", ".join(f"`{n}`" for n in want) or "one, with "
                                              "no row of its own"),
                    span=self._span(line_no, line, values, 0, len(KEY_FIELDS) - 1),
                    hint="the file was edited by hand; remove that run's lines, or choose "
                         "another directory with -o")

    def _lines(self, row: dict, named: bool = False) -> str:
        """The lines of a finished run (:func:`row_of`'s ``row``): its robots' rows, then its
        own, which ends them (written together, so that a kill leaves no run's own row
        without its robots'); ``named``: its world is named as the rows name it already."""
        if not named and row["world"] in self._names:
            row = {**row, "world": self._names[row["world"]]}
        out = io.StringIO()
        writer = csv.writer(out, lineterminator="\n")
        if "robot" not in self.columns:
            if row.get("robots"):           # (start() chose the columns from the worlds)
                raise RuntimeError("ResultStore: a run of several robots in a results file "
                                   "without a `robot` column")
            writer.writerow(_format(row[f]) for f in self.columns)
            return out.getvalue()
        for robot in row.get("robots", ()):
            writer.writerow(_format({**row, **robot}[f]) for f in self.columns)
        writer.writerow(_format({**row, "robot": ""}[f]) for f in self.columns)
        return out.getvalue()

    def _hold(self) -> None:
        """Lock the directory for this study until :meth:`close` (or the process's end, a
        kill included): two studies in one directory both appended to its results.csv, each
        run held twice, and both said they had finished. Where locks are not to be had (not
        POSIX, a file system without them), the study goes on as before.

        The lock is this process's alone: a ``flock`` belongs to the open file, which a
        forked child shares, so the workers of the study's pool held it too, and those of a
        study killed with ``kill -9`` kept it while they ran on (a `--resume` at once was
        refused). A child forked from here closes its copy at once (:func:`_let_go`); one
        started by ``exec`` never gets it (the descriptor is not inheritable)."""
        try:
            import fcntl
        except ImportError:
            return
        try:
            fd = os.open(self.dir, os.O_RDONLY)
        except OSError:
            return
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise StudyError(f"`{self.dir}` is in use by another study (a `mitos compare` "
                             f"still running there)", hint="wait for it to end, or choose "
                             "another directory with -o") from None
        except OSError:
            os.close(fd)
            return
        self._held = fd
        _HOLDING.add(self)
        _not_into_children()

    def _mend(self) -> None:
        """End the file where its last whole row ends, before rows are appended to it: a row
        cut short by a kill is cut off, a whole last row without its newline gets one."""
        if self._keep is not None:
            with open(self.path, "r+b") as fh:
                fh.truncate(self._keep)
        elif self._unended:
            with open(self.path, "ab") as fh:
                fh.write(b"\n")

    def append(self, row: dict) -> None:
        """Write one finished run's rows (:meth:`_lines`) and make them durable before
        returning (its world named as the rows before it name it)."""
        if self._file is None:
            raise RuntimeError("ResultStore.append before open")   # a programming error
        self._file.write(self._lines(row))
        self._file.flush()
        os.fsync(self._file.fileno())

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None
        if self._held is not None:
            os.close(self._held)            # (which lets the lock go)
            self._held = None
            _HOLDING.discard(self)

    def __enter__(self) -> ResultStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


#: the stores that hold their directory's lock in this process (:meth:`ResultStore._hold`)
_HOLDING: weakref.WeakSet[ResultStore] = weakref.WeakSet()


def _let_go() -> None:
    """In a child just forked: close the locked directories' descriptors it inherited (the
    locks stay with the parent), and forget them (the child's copy of a store must not close
    a number that has come to name another file)."""
    for store in list(_HOLDING):
        if store._held is not None:
            with contextlib.suppress(OSError):
                os.close(store._held)
            store._held = None
    _HOLDING.clear()


@functools.cache
def _not_into_children() -> None:
    """Have every child forked from now on let the locks go (once a process)."""
    if hasattr(os, "register_at_fork"):
        os.register_at_fork(after_in_child=_let_go)


def _refuse_special(path: Path, kind: str) -> None:
    """A :class:`StudyError` for ``path`` there but neither a regular file nor a directory
    (which has its own message): a named pipe, a device, a link to one. Reading it waited
    for ever (a pipe nothing writes to, /dev/zero), and so did writing study.json to one."""
    if path.exists() and not path.is_file() and not path.is_dir():
        raise StudyError(f"`{path}` is not a regular file, so not a {kind}",
                         hint=f"choose another output directory with -o, or remove {path}")


def _whole_line(data: bytes, header: str | None) -> str | None:
    """The last line of a results file, without its newline, as text if it is whole: the
    header (``header`` None: the file holds no other line), or a row with at least the values
    of a row under ``header``, the last not empty (a kill cuts a row short, never makes it
    longer); ``None`` when it was cut short or there is none."""
    try:
        line = data.decode("utf-8-sig" if header is None else "utf-8")
    except UnicodeDecodeError:
        return None                                   # cut inside a character
    if not line:
        return None
    if header is None:
        whole = (",".join(COLUMNS), ",".join(FLEET_COLUMNS))
        return line if line in whole or not any(w.startswith(line) for w in whole) else None
    try:
        values = next(csv.reader([line]))
    except (csv.Error, StopIteration):
        return None
    width = len(FLEET_COLUMNS) if header == ",".join(FLEET_COLUMNS) else len(COLUMNS)
    if len(values) > width or (len(values) == width and values[-1]):
        return line
    return None


def _line_end(data: bytes, line_no: int) -> int:
    """Where line ``line_no`` of ``data`` ends, its newline included."""
    at = 0
    for _ in range(line_no):
        at = data.index(b"\n", at) + 1
    return at


def write_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file and a rename."""
    from ..fileio import atomic_write

    atomic_write(path, text)


def _shown(got: dict, key: str) -> str:
    """``got[key]`` for a message: its JSON text, cut short, or ``missing``."""
    if key not in got:
        return "missing"
    text = json.dumps(got[key], ensure_ascii=False)
    return f"`{text if len(text) <= 40 else text[:37] + '...'}`"


def _misshapen(got: object) -> tuple[str | None, str] | None:
    """What is wrong with the shape of a study manifest read as ``got``: the key at fault
    (``None``: the whole) and why; ``None`` where nothing is. It is not an object, or its
    `digests` or `command` is not what the study wrote."""
    if not isinstance(got, dict):
        return None, f"it holds {_kind(got)}, not an object"
    digests = got.get("digests", {})
    if not isinstance(digests, dict) or not all(isinstance(v, str) for v in digests.values()):
        return "digests", f"its `digests` is {_shown(got, 'digests')}, not an object of file digests"
    if not isinstance(got.get("command", ""), str):
        return "command", f"its `command` is {_shown(got, 'command')}, not a string"
    return None


def _kind(value: object) -> str:
    """A JSON value's kind, as a reader of the file names it."""
    return ("a list" if isinstance(value, list) else "a string" if isinstance(value, str)
            else "null" if value is None else "a boolean" if isinstance(value, bool)
            else "a number")


def _written(text: str, key: str) -> str | None:
    """``key``'s value as the file writes it (`1e400`, which JSON reads as infinity and
    would show as `Infinity`), cut short; ``None`` where it is not a plain number."""
    found = re.search(rf'"{re.escape(key)}"\s*:\s*(-?[0-9][0-9.eE+-]*)', text)
    if found is None:
        return None
    value = found.group(1)
    return f"`{value if len(value) <= 40 else value[:37] + '...'}`"


def _key_span(text: str, path: str, key: str) -> Span | None:
    """Where ``"key":`` is written in the JSON ``text`` (its first place); ``None`` where it
    is not."""
    found = re.search(rf'"{re.escape(key)}"\s*:', text)
    return None if found is None else _at(text, path, found.start(), len(key) + 2)


def _at(text: str, path: str, index: int, width: int = 1) -> Span:
    """The place of ``text[index:index + width]``."""
    line = text.count("\n", 0, index) + 1
    column = index - (text.rfind("\n", 0, index) + 1) + 1
    return Span.in_text(text, path, line, column, column + width)


def _check_unchanged(old: dict, new: dict, path: Path, said: Callable[[str], Span | None]) -> None:
    """A world or rule base edited since the study began: its finished runs are of the old
    file, and resuming would average them with runs of the new one. ``said(name)``: where
    ``study.json`` records the first changed file's digest."""
    changed = [name for name, digest in new.items() if name in old and old[name] != digest]
    if changed:
        what = ", ".join(_changed_file(n) for n in changed)
        raise StudyError(f"{what} changed since the runs in {path} were made; resuming would "
                         f"mix runs of the old and the new file", span=said(changed[0]),
                         hint="choose another directory with -o (or put the file back)")


def _check_behavior(old: dict, new: dict, path: Path, span: Span | None = None) -> None:
    """A resume with another ``--behavior`` than the runs were made with: no column of a row
    names it, and its runs were averaged with the others (and study.json said all were)."""
    if "behavior" not in old or old["behavior"] == new.get("behavior"):
        return

    def said(behavior: str | None) -> str:
        return f"--behavior {behavior}" if behavior else "each world's own behavior"

    was = old["behavior"]
    raise StudyError(f"the runs in {path} were made with {said(was)}, not "
                     f"{said(new.get('behavior'))}; resuming would mix runs of the two",
                     span=span, hint=(f"resume with --behavior {was}" if was else "resume without "
                           "--behavior") + ", or choose another directory with -o")


def _changed_file(name: str) -> str:
    """A file of ``study.json``'s digests as a message names it (a world with a map: it or
    the map files it reads)."""
    from ..sim.worldfile import map_files

    if name == "rulebase":
        return "the rule base"
    return f"`{name}`" + (" or a map file it reads" if map_files(name) else "")


def _refuse_narrower(left: list[dict], old: dict, path: Path, out: Path,
                     worlds: list[str], span: Span | None = None) -> None:
    """A resumed study that leaves out runs already in ``results.csv`` (fewer worlds, norms,
    planners or runs; ``left``: their rows): its report would cover part of the file, and the
    study's own report would be replaced by it. Resuming may add runs, never drop them.
    ``worlds``: the study's, as given now (a world of the rows by the same file name is
    another file, or was changed since: it is said)."""
    first = left[0]
    command = old.get("command")
    if command:
        command = _writing_to(command, out)
    named = first["world"]
    alike = [] if named in worlds else [w for w in worlds if Path(w).name == Path(named).name]
    other = (f"; `{alike[0]}` given now is not the file the runs of `{named}` were made "
             f"with, or it was changed since") if alike else ""
    raise StudyError(
        f"{path} holds {plural(len(left), 'finished run')} this study leaves out (the first: "
        f"run {first['run']} of {Path(named).name}, {_label(first)}){other}; resuming would "
        f"report on part of the file", span=span,
        hint=(f"resume the study as it was made: {command} --resume" if command else
              "resume with the worlds, choices and runs the study was made with")
        + ", or choose another directory with -o")


def _worlds_of(rows: list[dict], old: dict, new: dict) -> dict[str, str]:
    """Each name the ``rows`` (or ``old``, the manifest they were made with) give a world of
    the study ``new`` (its manifest), and that world as ``new`` names it. A world is the
    file, not the path as typed (relative to another directory, a packaged world by its name
    or its path): the same name, else the same file from here, else the digest ``old``
    records for it (a world not yet taken first: two worlds may be alike)."""
    listed = old.get("worlds")
    recorded = list(dict.fromkeys(
        [w for w in (listed if isinstance(listed, list) else []) if isinstance(w, str)]
        + [r["world"] for r in rows]))
    worlds = list(new.get("worlds") or [])
    was, now = old.get("digests") or {}, new.get("digests") or {}
    found = {name: name for name in recorded if name in worlds}
    for name in recorded:
        here = _file(name) if name not in found else None
        same = [w for w in worlds if here is not None and _file(w) == here]
        if same:
            found[name] = same[0]
    for name in recorded:
        if name not in found and was.get(name) is not None:
            alike = [w for w in worlds if now.get(w) == was[name]]
            untaken = [w for w in alike if w not in found.values()]
            if alike:
                found[name] = (untaken or alike)[0]
    return found


def _written_names(worlds: dict[str, str]) -> dict[str, str]:
    """Each world (as given now) whose rows are written under another name, and that name:
    the first the rows give it (``worlds``: :func:`_worlds_of`), unless they name it as
    given."""
    names: dict[str, str] = {}
    for name, world in worlds.items():          # (the names as given come first)
        names.setdefault(world, name)
    return {world: name for world, name in names.items() if world != name}


def _file(path: str) -> str | None:
    """The file ``path`` names from here (a packaged world's name: its file), links followed;
    ``None`` when it names none."""
    from ..resources import world_file

    found = world_file(path)
    return os.path.realpath(found) if is_file(found) else None


def _renamed(manifest: dict, names: dict[str, str]) -> dict:
    """``manifest`` with its worlds named as the rows name them (``names``)."""
    if not names:
        return manifest
    return {**manifest, "worlds": [names.get(w, w) for w in manifest.get("worlds") or []],
            "digests": {names.get(k, k): v for k, v in (manifest.get("digests") or {}).items()}}


def _writing_to(command: str, out: Path) -> str:
    """The study's ``command`` with ``-o`` naming ``out``, the directory being resumed (a
    study copied or moved since it was made: its command names the old place)."""
    try:
        words = shlex.split(command)
    except ValueError:                       # (a study.json edited by hand)
        return command
    at = max((i for i, w in enumerate(words[:-1]) if w in ("-o", "--out")), default=None)
    if at is None:
        return command
    return shlex.join([*words[:at + 1], str(out), *words[at + 2:]])


def rows_for(tasks: Iterable[Task], rows: list[dict]) -> tuple[list[dict], list[Task]]:
    """Split a study into the rows already finished (in task order) and the tasks to run.

    A finished row whose seed differs from its task's means the worlds were given in another
    order or the study was made with another seed: an error, never a silent mix.
    """
    done = {key_of(r): r for r in rows}
    finished, todo = [], []
    for task in tasks:
        row = done.get(task.key)
        if row is None:
            todo.append(task)
            continue
        if row["seed"] != task.seed:
            raise StudyError(
                f"the finished run {task.run} of {task.world} ({task.choice.label}) was "
                f"made with seed {row['seed']}, but this study gives it {task.seed}",
                hint="give the worlds in the same order as the study being resumed")
        finished.append(row)
    return finished, todo
