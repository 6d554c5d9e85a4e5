"""A study from start to finish: plan the tasks, skip the finished, run, record, summarize.

>>> from mitos_cli.study import Study, run_study
>>> study = Study(worlds=["worlds/corridor.yaml"], choices=make_choices(
...     ["fuzzy", "potential_field"], ["min", "product"], [], []), runs=20, seed=1)
>>> outcome = run_study(study, "out/")            # doctest: +SKIP
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from ..words import plural
from .executors import Going, TaskFn, execute
from .spec import Choice, Task, expand
from .store import ResultStore, key_of, row_of
from .summary import ALL_WORLDS, Rank, Summary, choice_of, rank, summaries

if TYPE_CHECKING:
    from collections.abc import Iterable

    from distributed import Client

    from ..sim.world import World


@dataclass(frozen=True)
class Study:
    """What to compare: worlds x choices x runs, from one seed, with one rule base.
    ``worlds`` are world files (``str`` or ``Path``), each given once."""

    worlds: list[str]
    choices: list[Choice]
    runs: int
    seed: int
    rulebase: str | None = None
    behavior: str | None = None
    command: str = "mitos compare"

    def __post_init__(self) -> None:
        """``runs`` (1 or more, as ``mitos compare --runs``) and ``seed`` checked as
        :func:`~mitos_cli.sim.runs.run_many` checks them, else an :class:`InputError`
        (``runs=-1`` was NumPy's OverflowError, ``seed=-1`` its ValueError, ``seed=True`` ran
        as the seed 1, ``runs=0`` compared nothing); NumPy integers become ints (the study's
        ``study.json`` is JSON)."""
        from ..sim.loop import check_seed
        from ..sim.runs import whole

        object.__setattr__(self, "worlds", world_files(self.worlds))
        object.__setattr__(self, "choices", _once(self.choices))
        object.__setattr__(self, "runs", whole("runs", self.runs, 1))
        object.__setattr__(self, "seed", check_seed(self.seed))

    def tasks(self) -> list[Task]:
        return expand(self.worlds, self.choices, self.runs, self.seed)

    def manifest(self) -> dict:
        return {"worlds": list(self.worlds), "choices": [c.label for c in self.choices],
                "runs": self.runs, "seed": self.seed, "rulebase": self.rulebase,
                "behavior": self.behavior, "command": self.command,
                "digests": self.digests()}

    def digests(self) -> dict[str, str]:
        """A digest of each input file (the worlds with the maps they read, the rule base and
        its term sets), so that `--resume` can refuse to mix runs of a file that changed with
        runs of the new one. The simulator's caches are keyed on them (:mod:`.simtask`)."""
        from ..api import read_rulebase
        from ..errors import MitosError
        from .simtask import RULEBASE, rulebase_digest, world_digest

        found = {path: world_digest(path) for path in self.worlds}
        with contextlib.suppress(MitosError):    # (reported where the rule base is read)
            found[RULEBASE] = rulebase_digest(read_rulebase(self.rulebase))
        return {name: d for name, d in found.items() if d is not None}


def world_files(worlds: object) -> list[str]:
    """``worlds`` as a list of world files (a ``Path`` as its text), else an
    :class:`InputError` saying what a study takes: one path was read a character at a time, a
    ``Path`` or a ``World`` failed later with a bare TypeError, and a world given twice had
    each of its rows summarize the runs of both (``mitos compare`` refuses it)."""
    from ..errors import InputError
    from ..resources import world_file
    from ..sim.world import World

    if isinstance(worlds, (str, os.PathLike)):
        raise InputError(f"a Study takes a list of world files, not the path `{worlds}`",
                         hint=f"Study([{str(worlds)!r}], ...)")
    if isinstance(worlds, World):
        raise InputError("a Study takes a list of world files, not one World",
                         hint=_world_hint(worlds))
    try:
        given = list(worlds)  # type: ignore[call-overload]  # anything iterable is tried
    except TypeError:
        raise InputError(f"a Study takes a list of world files, not {type(worlds).__name__} "
                         f"`{worlds!r:.60}`") from None
    if not given:
        raise InputError("a Study needs at least one world file")
    out: list[str] = []
    seen: dict[Path, str] = {}
    for w in given:
        name = _world_file(w)
        if name == ALL_WORLDS:              # (its rows were taken for the pooled ones)
            raise InputError(f"a world named `{name}` is not told apart from the rows pooled "
                             f"over the worlds", hint=f"give it by its full path: "
                                                  f"{str(Path(name).resolve())!r}")
        key = world_file(name).resolve()       # (`corridor` is where pip put corridor.yaml)
        if key in seen:
            also = "" if seen[key] == name else f" (as `{seen[key]}`)"
            raise InputError(f"the world `{name}` is given twice{also}",
                             hint="give each world once; more runs of it: runs=N")
        seen[key] = name
        out.append(name)
    return out


def _once(choices: Iterable[Choice]) -> list[Choice]:
    """``choices`` as a list, else an :class:`InputError` for one given twice: its runs share
    one key, so each row of it summarized both (``n`` twice the runs), and its --resume
    refused the results file it had written."""
    from ..errors import InputError

    hint = "make_choices(['fuzzy'], ['min', 'product'], [], []) makes a list of them"
    if isinstance(choices, (Choice, str, bytes)) or not hasattr(choices, "__iter__"):
        raise InputError(f"a Study's choices are a list of choices, not {type(choices).__name__} "
                         f"`{choices!r:.60}`", hint=hint)    # (one met "not iterable")
    out = list(choices)
    if not out:                         # (0 of 0 runs, and a report that compared nothing)
        raise InputError("a Study needs at least one choice", hint=hint)
    for choice in out:
        if not isinstance(choice, Choice):
            raise InputError(f"a Study's choices are choices, not {type(choice).__name__} "
                             f"`{choice!r:.60}`", hint=hint)
    for i, choice in enumerate(out):
        if choice in out[:i]:
            raise InputError(f"the choice `{choice.label}` is given twice",
                             hint="give each choice once (make_choices does); more runs of "
                                  "it: runs=N")
    return out


def _world_file(world: object) -> str:
    """One world of a study as the file's text, else an :class:`InputError` saying why: each
    run reads the file, and ``study.json`` records its digest."""
    from ..errors import InputError
    from ..sim.world import World

    if isinstance(world, World):
        raise InputError("a Study runs world files, not loaded worlds (each run reads the "
                         "file, and study.json records its digest)", hint=_world_hint(world))
    name = os.fspath(world) if isinstance(world, (str, os.PathLike)) else None
    if not isinstance(name, str):
        raise InputError(f"a Study runs world files, not {type(world).__name__} "
                         f"`{world!r:.60}`", hint="Study(['worlds/corridor.yaml'], ...)")
    return name


def _world_hint(world: World) -> str:
    """Where a loaded World can go instead: its file, or :func:`run_many`."""
    if world.path:
        return f"give its file: Study([{str(world.path)!r}], ...)"
    return "save it as a .yaml file, or run it as it is with run_many([world], ...)"


@dataclass
class Outcome:
    """What a study produced: the rows in task order and their summaries."""

    study: Study
    rows: list[dict]
    n_tasks: int
    skipped: int                           # finished before (``resume``)
    executed: int                          # run now
    summaries: list[Summary] = field(default_factory=list)
    ranks: list[Rank] = field(default_factory=list)

    def __repr__(self) -> str:
        """A line: the runs and the first places (the generated one printed every row: 11,000
        characters for 9 runs, half a million for the 700 of docs/study.md)."""
        worlds = len(self.study.worlds)
        head = ", ".join(f"{r.place}. {r.summary.choice.label}" for r in self.ranks[:3])
        more = f" ({len(self.ranks) - 3} more)" if len(self.ranks) > 3 else ""
        return (f"<Outcome: {len(self.rows):,} of {plural(self.n_tasks, 'run')} ({self.executed:,} "
                f"now, {self.skipped:,} from before), {plural(worlds, 'world')} x "
                f"{plural(len(self.study.choices), 'choice')}; {head or 'no ranking'}{more}>")

    @property
    def complete(self) -> bool:
        return len(self.rows) == self.n_tasks

    def per_world(self) -> list[Summary]:
        return [s for s in self.summaries if s.world != ALL_WORLDS]

    def pooled(self) -> list[Summary]:
        pooled = [s for s in self.summaries if s.world == ALL_WORLDS]
        return pooled or self.per_world()


def default_task_fn(study: Study, digests: dict[str, str] | None = None) -> TaskFn:
    """The simulator as a picklable task function, running the files as ``digests`` (the
    ones ``study.json`` records; default: as they are now) say they are."""
    from .simtask import Simulator, StudyContext

    digests = study.digests() if digests is None else digests
    return Simulator(StudyContext(study.rulebase, study.behavior,
                                  tuple(sorted(digests.items()))))


def run_study(study: Study, out_dir: str | Path, *, executor: str = "local",
              workers: int | None = None, scheduler: str | None = None, resume: bool = False,
              task_fn: TaskFn | None = None, client: Client | None = None,
              on_start: Callable[[int, int], None] | None = None,
              on_result: Callable[[Task, dict], None] | None = None,
              on_clock: Callable[[float], None] | None = None) -> Outcome:
    """Run every unfinished task of ``study``, appending each result to ``out_dir/results.csv``
    as it arrives, and summarize all finished rows (in task order, whatever the executor).

    ``on_start(skipped, total)`` is called once, ``on_result(task, row)`` per finished task,
    ``on_clock(seconds)`` between, with where the earliest chunk of runs going is (runs in
    lockstep end together, late in their chunk).
    ``workers`` is checked as :func:`~mitos_cli.sim.runs.run_many` checks it (0, -5, 2.5 and
    True all ran without a word).
    """
    from ..sim.runs import whole

    if workers is not None:
        workers = whole("workers", workers, 1)
    tasks = study.tasks()
    manifest = study.manifest()
    fn = task_fn or default_task_fn(study, manifest["digests"])
    own = _scheduler_client(executor, scheduler, client, workers)
    with ResultStore(out_dir) as store, contextlib.ExitStack() as stack:
        if own is not None:
            stack.callback(own.close)
        finished, todo = store.start(manifest, tasks, resume=resume,
                                     robots=_robots(fn, study.worlds))
        if on_start is not None:
            on_start(len(finished), len(tasks))
        by_index: dict[int, dict] = {}
        going = Clocks(on_clock)
        for part in execute(fn, todo, executor, workers, scheduler, own or client):
            if isinstance(part, Going):
                going.told(part)
                continue
            task, result = part
            going.ended(task.index)
            row = row_of(task, result)
            store.append(row)
            by_index[task.index] = row
            if on_result is not None:
                on_result(task, row)
    done = {key_of(r): r for r in finished}
    rows = []
    for task in tasks:
        found = by_index.get(task.index) or done.get(task.key)
        if found is not None:
            rows.append(found)
    outcome = Outcome(study, rows, len(tasks), len(finished), len(by_index))
    outcome.summaries = summaries(rows, study.worlds, study.choices)
    outcome.ranks = rank(rows, outcome.pooled())
    return outcome


def _robots(fn: TaskFn, worlds: list[str]) -> dict[str, tuple[str, ...]]:
    """Each world of several robots and their names, as the task function (the simulator's:
    :meth:`.Simulator.robots`) tells them; none from one that does not."""
    robots = getattr(fn, "robots", None)
    if robots is None:
        return {}
    found = {world: tuple(robots(world)) for world in worlds}
    return {world: names for world, names in found.items() if names}


class Clocks:
    """Where the chunks of runs going are, for ``on_clock``: the earliest of them, each
    forgotten once every run of it has ended."""

    def __init__(self, on_clock: Callable[[float], None] | None) -> None:
        self.on_clock = on_clock
        self.seconds: dict[tuple[int, ...], float] = {}
        self.left: dict[tuple[int, ...], set[int]] = {}
        self.done: set[int] = set()

    def told(self, going: Going) -> None:
        left = self.left.setdefault(going.tasks, set(going.tasks) - self.done)
        if left:
            self.seconds[going.tasks] = going.seconds
        if self.on_clock is not None and self.seconds:
            self.on_clock(min(self.seconds.values()))

    def ended(self, index: int) -> None:
        self.done.add(index)
        for chunk, left in self.left.items():
            if index in left:
                left.discard(index)
                if not left:
                    self.seconds.pop(chunk, None)
                return


def _scheduler_client(executor: str, scheduler: str | None, client: Client | None,
                      workers: int | None) -> Client | None:
    """A client of the Dask scheduler at ``scheduler``, reached before the study writes
    anything (``None``: no scheduler to reach, or a ``client`` given): one that could not be
    reached left study.json and results.csv's header behind in a directory that held none."""
    if executor != "dask" or not scheduler or client is not None:
        return None
    from . import executors

    return executors.dask_client(scheduler, workers or 1)


def write_report(outcome: Outcome, out_dir: str | Path, plots: bool = True) -> Path:
    """``report.md`` (and its plots ``success.png``, ``clearance.png``; without them, those
    of an earlier report are removed) in ``out_dir``."""
    from ..errors import InputError
    from .report import render_markdown
    from .store import write_atomic

    if not isinstance(plots, bool):     # ("no" drew them, as any true value did)
        raise InputError(f"plots is True or False, not `{plots!r:.40}`",
                         hint="plots=False writes report.md without its pictures")
    out = Path(out_dir)
    images: dict[str, str] = {}
    if plots and outcome.rows:
        from ..draw.study import clearance_boxes, success_bars

        labels = [c.label for c in outcome.study.choices]
        worlds = list(outcome.study.worlds)
        pooled = [s for s in outcome.summaries if s.world == ALL_WORLDS]
        success_bars(outcome.per_world() + pooled, worlds + ([ALL_WORLDS] if pooled else []),
                     labels, out / "success.png")
        clearance_boxes(outcome.rows, worlds, labels, lambda r: choice_of(r).label,
                        out / "clearance.png")
        images = {"Success rate per world and choice": "success.png",
                  "Minimum clearance per world and choice": "clearance.png"}
    else:
        _drop_plots(out)
    text = render_markdown(outcome.study.manifest(), outcome.summaries, outcome.ranks, images,
                           len(outcome.rows), outcome.n_tasks)
    path = out / "report.md"
    write_atomic(path, text)
    return path


#: the plots :func:`write_report` draws beside report.md
PLOTS = ("success.png", "clearance.png")


def _drop_plots(out: Path) -> None:
    """Remove the plots an earlier report of the study drew: a report written without plots
    (``--no-plots``, no matplotlib) left them beside it, figures of fewer runs than the
    report's, to be taken for the study's."""
    for name in PLOTS:
        with contextlib.suppress(FileNotFoundError):
            (out / name).unlink()
