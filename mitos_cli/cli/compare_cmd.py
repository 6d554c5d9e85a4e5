"""``mitos compare``: a study of operator choices and planners over worlds x seeded runs."""

from __future__ import annotations

import shlex
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Optional

import typer

from ..errors import UsageError, install_hint, unknown
from ..words import plural
from . import complete
from .output import emit, err, json_text, warn
from .params import MAX_RUNS, WORDS, Number, named, option_names
from .progress import INTERRUPTED, progress_bar, stopped_code, terminate_as_interrupt

if TYPE_CHECKING:
    from collections.abc import Sequence

    from ..study import Outcome, Study
    from ..study.spec import Choice, Task
    from ..study.stats import Mean, Rate
    from ..study.summary import Summary

DEFAULT_AND = "min,product,lukasiewicz,einstein"
#: ``--runs`` and its old spelling ``-n``
RUNS = Number("the number of runs per world and choice", 1, MAX_RUNS)


def compare_command(
    worlds: Annotated[list[str], typer.Argument(
        click_type=WORDS, metavar="WORLDS...", autocompletion=complete.worlds, callback=named,
        help="World files (or names of packaged worlds such as corridor.yaml).")],
    and_: Annotated[str, typer.Option(
        "--and", metavar="TNORMS", callback=named,
        help="T-norms of the fuzzy planner, comma-separated.")] = DEFAULT_AND,
    or_: Annotated[Optional[str], typer.Option(
        "--or", metavar="SNORMS", callback=named,
        help="S-norms, comma-separated (crossed with --and); `dual` pairs each T-norm with "
             "its De Morgan dual. Default: the rule base's.")] = None,
    inference: Annotated[Optional[str], typer.Option(
        "--inference", metavar="METHODS",
        help="Inference methods, comma-separated: weighted_average, weighted_sum, mamdani, "
             "tsukamoto (monotonic consequent terms only). Default: the rule base's.")] = None,
    planner: Annotated[str, typer.Option(
        "--planner", metavar="PLANNERS", autocompletion=complete.planner_list,
        help="Planners to compare, comma-separated: fuzzy, potential_field, dwa "
             "(`fuzzy,dwa`).")] = "fuzzy,potential_field",
    runs: Annotated[int, typer.Option(
        "--runs", metavar="N", click_type=RUNS,
        help="Randomised runs per world and choice (a comparison needs many; `simulate` "
             "runs a world once as written unless given --runs).")] = 20,
    runs_n: Annotated[Optional[int], typer.Option(
        "-n", click_type=RUNS, hidden=True, help="The old spelling of --runs.")] = None,
    seed: Annotated[int, typer.Option(
        "--seed", metavar="SEED", click_type=Number("the study's seed", 0),
        help="Seed of the whole study (runs are paired across choices).")] = 1,
    out: Annotated[str, typer.Option(
        "--out", "-o", metavar="DIR", callback=named,
        help="Directory for results.csv, report.md and the plots (made when missing; its "
             "parent must exist).")] = "study",
    executor: Annotated[str, typer.Option(
        "--executor", metavar="local|dask", autocompletion=complete.executors,
        help="local: a process pool on this machine; dask: dask.distributed.")] = "local",
    workers: Annotated[Optional[int], typer.Option(
        "--workers", "-j", metavar="N", click_type=Number("the number of processes", 1),
        help="Processes (local) or LocalCluster workers (dask). Default: the CPUs allowed, "
             "fewer where memory is short.")] = None,
    scheduler: Annotated[Optional[str], typer.Option(
        "--scheduler", metavar="ADDR", callback=named,
        help="Dask scheduler address (tcp://host:8786); without it a LocalCluster.")] = None,
    resume: Annotated[bool, typer.Option(
        "--resume", help="Continue the study in DIR: skip every run already in results.csv "
                         "(DIR must hold one; without --resume a study starts there).")] = False,
    rulebase: Annotated[Optional[str], typer.Option(
        "--rulebase", "-r", metavar="PATH|NAME", callback=named,
        help="Rule base of the fuzzy planner: a file, or a packaged one by name (`mitos list "
             "rulebases`; default: the packaged mitos.rules).")] = None,
    behavior: Annotated[Optional[str], typer.Option(
        "--behavior", "-b", metavar="NAME", callback=named,
        help="Behavior to drive with (default: the world's).")] = None,
    plots: Annotated[bool, typer.Option(
        "--plots/--no-plots", help="Draw the plots of report.md (needs matplotlib).")] = True,
    as_json: Annotated[bool, typer.Option(
        "--json", help="Print one JSON object (the summaries and the ranking; schema: "
                       "`mitos docs study`) instead of the tables.")] = False,
) -> None:
    """Compare T-norms, S-norms, inference methods and planners over worlds and seeded runs.

    Prints the table and the ranking; writes DIR/results.csv (one row per run, as it
    finishes), DIR/report.md and its plots.
    """
    if runs_n is not None:
        warn("`-n` is --resolution in `check` and `plot surface`; write --runs here")
        runs = runs_n
    # names in any case, as every option's fixed list reads them (--to FLL, --style HEATMAP;
    # `--planner DWA` was "unknown planner `DWA`, did you mean `dwa`?")
    and_, planner, executor = and_.lower(), planner.lower(), executor.lower()
    or_, inference = (None if v is None else v.lower() for v in (or_, inference))
    from ..study import Study, make_choices
    from ..study.executors import EXECUTORS
    from ..study.spec import split_list

    if executor not in EXECUTORS:              # a name MITOS does not know: exit 2
        raise unknown("executor", executor, EXECUTORS, cls=UsageError)
    if scheduler and executor != "dask":
        raise typer.BadParameter("--scheduler needs --executor dask", param_hint="--scheduler")
    if scheduler and workers is not None:      # (it was dropped without a word)
        raise typer.BadParameter("the cluster at --scheduler runs its own workers; -j sets "
                                 "those of a local pool or LocalCluster",
                                 param_hint="--workers")
    if executor == "dask":                      # before study.json or the progress bar
        from ..study.executors import require_dask

        require_dask(scheduler)
    _no_stray_choice(worlds, {"--planner": planner, "--and": and_, "--or": or_,
                              "--inference": inference})
    planners = _planners(planner, and_, or_, inference, rulebase, behavior)
    with option_names():                        # --planner, --and, --or, --inference: exit 2
        choices = make_choices(planners, split_list(and_), split_list(or_),
                               split_list(inference))
    paths = check_inputs(worlds, choices, rulebase, behavior, runs)
    study = Study(paths, choices, runs, seed, rulebase, behavior,
                  command=_command_line(worlds, and_, or_, inference, planner, rulebase,
                                        behavior, runs, seed, out))
    how = _how_run(executor, workers, scheduler, plots, as_json)
    outcome = run_with_progress(study, out, executor, workers, scheduler, resume,
                                quiet=as_json, how=how)

    try:
        report = _report(outcome, out, plots)   # (before stdout, which a reader may close)
    except KeyboardInterrupt:
        # exit 130 without a word, report.md perhaps of fewer runs than results.csv
        err(f"interrupted while writing the report: every run of the study "
            f"({plural(outcome.n_tasks, 'run')}) is in {Path(out) / 'results.csv'}; write it "
            f"with:\n  {study.command}{how} --resume")
        raise typer.Exit(INTERRUPTED) from None
    if as_json:
        emit(json_text(outcome_json(outcome, out)))
    else:
        _print_tables(outcome)
    err(f"{plural(outcome.executed, 'run')} now, {outcome.skipped} from before; "
        f"wrote {report.parent / 'results.csv'} and {report}")


def _no_stray_choice(worlds: list[str], given: dict[str, str | None]) -> None:
    """`--planner fuzzy potential_field` (a space for the comma) read `potential_field` as a
    world: "world file `potential_field` not found". A world argument that is no file and is
    the name of a planner, norm or inference method is a usage error that says so."""
    from ..fuzzy.norms import names
    from ..lang.operators import INFERENCES
    from ..study.spec import PLANNERS

    kinds = (("--planner", "a planner", PLANNERS), ("--and", "a T-norm", names("tnorm")),
             ("--or", "an S-norm", names("snorm")),
             ("--inference", "an inference method", INFERENCES))
    for world in worlds:
        if Path(world).exists():
            continue
        for flag, what, known in kinds:
            if world.lower() in known:
                before = given[flag]
                listed = (before if before and world.lower() in before.split(",") else
                          f"{before},{world}" if before else world)
                raise typer.BadParameter(
                    f"`{world}` is {what}, read here as a world: {flag} takes its names "
                    f"comma-separated, without spaces (`{flag} {listed}`)")


def _planners(planner: str, and_: str, or_: str | None, inference: str | None, rulebase: str | None,
              behavior: str | None) -> list[str]:
    """``--planner``'s names; the fuzzy planner's options without it are refused (they were
    dropped without a word)."""
    from ..study.spec import PLANNERS, split_list

    planners = split_list(planner)
    if not planners:
        raise typer.BadParameter("name at least one planner", param_hint="--planner")
    for name in planners:           # before what the planners lack (`--planner dwaa --and min`
        if name not in PLANNERS:    # said "--planner dwaa has no fuzzy planner")
            raise unknown("planner", name, PLANNERS, cls=UsageError)
    for flag, names, what in (("--and", and_, "T-norm"), ("--or", or_, "S-norm"),
                              ("--inference", inference, "inference method")):
        if names is not None and not split_list(names):     # (`--and ,` ran the rule base's)
            raise typer.BadParameter(f"name at least one {what}", param_hint=flag)
    fuzzy_only = [flag for flag, given in (("--and", and_ != DEFAULT_AND), ("--or", or_),
                                           ("--inference", inference), ("--rulebase", rulebase),
                                           ("--behavior", behavior)) if given]
    if "fuzzy" not in planners and fuzzy_only:
        verb = "chooses" if len(fuzzy_only) == 1 else "choose"
        raise typer.BadParameter(f"{', '.join(fuzzy_only)} {verb} the fuzzy planner's "
                                 f"operators and rules; --planner {planner} has no fuzzy planner",
                                 param_hint="--planner")
    return planners


def _command_line(worlds: list[str], and_: str, or_: str | None, inference: str | None, planner: str,
                  rulebase: str | None, behavior: str | None, runs: int,
                  seed: int, out: str) -> str:
    """The command that runs this study again, for report.md."""
    words = ["mitos", "compare", *worlds, "--and", and_, "--planner", planner]
    for flag, value in (("--or", or_), ("--inference", inference), ("--rulebase", rulebase),
                        ("--behavior", behavior)):
        if value:
            words += [flag, value]
    words += ["--runs", str(runs), "--seed", str(seed), "-o", out]
    return " ".join(shlex.quote(w) for w in words)


def _how_run(executor: str, workers: int | None, scheduler: str | None, plots: bool,
             as_json: bool) -> str:
    """The options given that say how the study runs and reports, not what it is (so
    ``study.json``'s command leaves them out), as words to add to the command that goes on
    after a Ctrl-C: without them a study on a Dask cluster went on on the local pool, and
    one asked for ``--no-plots`` or ``--json`` drew plots or printed tables."""
    words = [] if executor == "local" else ["--executor", executor]
    words += ["--scheduler", scheduler] if scheduler else []
    words += ["-j", str(workers)] if workers is not None else []
    words += [] if plots else ["--no-plots"]
    words += ["--json"] if as_json else []
    return "".join(" " + shlex.quote(w) for w in words)


def _report(outcome: Outcome, out: str, plots: bool) -> Path:
    """report.md (and its plots, unless matplotlib is missing: then without, and a warning)."""
    from ..study import write_report

    try:
        return write_report(outcome, out, plots=plots)
    except ImportError:
        warn(f"matplotlib is not installed: report.md has no plots ({install_hint('plot')})")
        return write_report(outcome, out, plots=False)


def _print_tables(outcome: Outcome) -> None:
    from rich.console import Console

    from ..study.report import overlap_note, rich_tables

    console = Console(highlight=False, soft_wrap=False)
    table, ranking = rich_tables(outcome.summaries, outcome.ranks)
    if not console.is_terminal:            # a file or a pipe: never cut the data short (160
        # columns cut a study's table of long names to `…` in every column, and dropped `n`)
        wide = Console(highlight=False, soft_wrap=False, width=1000)
        width = max(160, *(wide.measure(t).maximum for t in (table, ranking)))
        console = Console(highlight=False, soft_wrap=False, width=width)
    console.print(table)
    console.print(ranking)
    note = overlap_note(outcome.ranks)
    if note:                               # in a file, one line: never a label cut in two
        console.print(note, markup=False, soft_wrap=not console.is_terminal)


def outcome_json(outcome: Outcome, out: str) -> dict:
    """The ``--json`` object: the study, a summary per world and choice (and pooled over
    the worlds), and the ranking (docs/study.md, "compare --json")."""
    def rate(r: Rate) -> dict:
        return {"k": r.k, "n": r.n, "value": r.value, "lo": r.lo, "hi": r.hi}

    def number(x: float | None) -> float | None:
        return None if x is None or not math.isfinite(x) else x      # JSON has no inf / NaN

    def mean(m: Mean) -> dict:
        return {"n": m.n, "mean": number(m.mean), "std": number(m.std), "lo": number(m.lo),
                "hi": number(m.hi)}

    def summary(s: Summary) -> dict:
        out = {"world": s.world, "choice": s.choice.label, "runs": s.n,
               "rates": {k: rate(v) for k, v in s.rates.items()},
               "metrics": {k: mean(v) for k, v in s.metrics.items()}}
        if s.robots:            # a world of several robots: each one's own, under the fleet's
            out["robots"] = [{"robot": r.robot, "runs": r.n,
                              "rates": {k: rate(v) for k, v in r.rates.items()},
                              "metrics": {k: mean(v) for k, v in r.metrics.items()}}
                             for r in s.robots]
        return out

    import math

    from ..study.summary import ALL_WORLDS

    study = outcome.study
    return {
        "command": study.command, "out": out, "seed": study.seed, "runs": study.runs,
        "worlds": list(dict.fromkeys(s.world for s in outcome.summaries
                                     if s.world != ALL_WORLDS)),
        "choices": [c.label for c in study.choices],
        "tasks": outcome.n_tasks, "executed": outcome.executed, "skipped": outcome.skipped,
        "summaries": [summary(s) for s in outcome.summaries],
        "ranking": [{"place": r.place, "choice": r.summary.choice.label,
                     "success": rate(r.summary.rates["success"]), "paired_runs": r.paired_n,
                     "wins": r.wins, "losses": r.losses, "p_value": r.p_value}
                    for r in outcome.ranks],
    }


def check_inputs(worlds: list[str], choices: Sequence[Choice], rulebase: str | None,
                 behavior: str | None, runs: int = 0) -> list[str]:
    """Read every world and compile every choice once here, so a mistake is reported before
    any worker starts (and a world whose ``runs`` are copies of one is said). Returns the
    worlds as the study names them: a packaged world by its name (``corridor``, which the
    workers open wherever pip put it; its path named the world in results.csv, study.json and
    --json), any other by the path given."""
    from ..resources import is_file, packaged_world
    from ..sim.obstacles import copies_note
    from ..sim.worldfile import load_world, resolve_world_path
    from ..study.simtask import StudyContext, check_choice

    paths = []
    files: set[Path] = set()
    for name in worlds:
        path = str(resolve_world_path(name))
        world = load_world(path)
        for note in [*world.notes, copies_note(world, runs)]:   # likely mistakes, said
            if note:
                warn(note)
        if Path(path).resolve() in files:     # (`a.yaml` and `./a.yaml` too, as Study says)
            raise typer.BadParameter(f"the world `{name}` is given twice")
        files.add(Path(path).resolve())
        # a file found as given keeps its name (`worlds/corridor.yaml` in a checkout, even an
        # editable one, whose packaged worlds are those files); one found among the packaged
        # worlds is named as such
        paths.append(path if is_file(Path(name)) else packaged_world(path) or path)
    context = StudyContext(rulebase, behavior)
    for path in paths:
        for choice in choices:
            check_choice(choice, context, path)
    return paths


def run_with_progress(study: Study, out: str, executor: str, workers: int | None, scheduler: str | None,
                      resume: bool, quiet: bool = False, how: str = "") -> Outcome:
    """Run the study with a progress bar on stderr (on a terminal, without ``--json``; piped,
    a line every few percent). On Ctrl-C: say how many runs are kept in ``out`` and how to go
    on (the study's command, then ``how``: the options it was run with), and exit 130; on a
    SIGTERM the same, exiting 143, and on a SIGHUP (the terminal closed), exiting 129."""
    from ..study import run_study

    kept = {"before": 0, "now": 0, "total": 0}
    with progress_bar(f"runs ({executor})", quiet=quiet, lines=True) as bar:
        def on_start(skipped: int, total: int) -> None:
            kept.update(before=skipped, total=total)
            bar.update(skipped, total)
            if skipped:
                bar.note(f"resuming: {skipped} of {plural(total, 'run')} already in {out}")

        def on_result(task: Task, row: dict) -> None:
            kept["now"] += 1
            bar.update(kept["before"] + kept["now"], kept["total"])

        try:
            with terminate_as_interrupt():
                return run_study(study, out, executor=executor, workers=workers,
                                 scheduler=scheduler, resume=resume, on_start=on_start,
                                 on_result=on_result,
                                 on_clock=lambda t: bar.status(f"at {t:.0f} s"))
        except KeyboardInterrupt as exc:        # (a SIGTERM, a SIGHUP too: Terminated)
            stopped = stopped_code(exc)
    if not kept["total"] and not resume:      # before on_start: no run of it is kept
        err(f"interrupted before the study began in {out}; start it with:\n  {study.command}{how}")
        raise typer.Exit(stopped)
    done = max(kept["before"] + kept["now"], _rows_in(out))
    err(f"interrupted: {done} of {plural(kept['total'], 'run')} kept in "
        f"{Path(out) / 'results.csv'} ({done - kept['before']} now, {kept['before']} from "
        f"before); go on with:\n  {study.command}{how} --resume")
    raise typer.Exit(stopped)


def _rows_in(out: str) -> int:
    """The runs ``out/results.csv`` holds (0 where it cannot be read): a row written as the
    Ctrl-C came (in its fsync) was kept but not yet counted, and the message said one run
    fewer than the file held."""
    from ..errors import MitosError
    from ..study.store import ResultStore

    try:
        return len(ResultStore(out).load())
    except MitosError:
        return 0
