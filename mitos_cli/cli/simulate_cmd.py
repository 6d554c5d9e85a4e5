"""``mitos simulate``: drive a rule base through YAML worlds; verdict, metrics, traces, pictures."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Optional

import typer

from ..words import clearance, percent, plural
from . import complete
from .output import emit, err, json_text, warn
from .params import MAX_RUNS, WORDS, Factor, Number, file_arg, named, option_names
from .progress import Terminated, progress_bar, stopped_code, terminate_as_interrupt
from .targets import check_directory, check_suffix

if TYPE_CHECKING:
    from collections.abc import Iterable

    from ..sim.loop import SimResult
    from ..sim.planner import Planner
    from ..sim.runs import Runs
    from ..sim.world import World

REQUIRE = ("success",)


def _check_outputs(written: Iterable[tuple[str, Path | None]], read: list[Path]) -> None:
    """Refuse an output file that is a file the command reads or another output's: it was
    overwritten without a word (``--out world.yaml`` replaced the world with the CSV)."""
    from ..fileio import real_path

    inputs = {real_path(p) for p in read}
    seen: dict[Path, str] = {}
    for option, path in written:
        if path is None:
            continue
        key = real_path(path)
        if key in inputs:
            raise typer.BadParameter(f"`{path}` is a file this command reads; write to another "
                                     "file", param_hint=option)
        if key in seen:
            raise typer.BadParameter(f"`{path}` is named by {seen[key]} too; give each output "
                                     "its own file", param_hint=option)
        seen[key] = option


def _verdict(res: SimResult) -> str:
    m = res.metrics
    agents = res.world.agents
    close = [a for a, r in zip(agents, res.robot_metrics)
             if r["min_clearance_in"] < a.robot.safety_margin]
    near = ""
    if close and res.outcome != "collision":
        near = f"; closer than the safety margin ({close[0].robot.safety_margin:g} in)"
        if len(agents) > 1:                 # "(two) (2 in)" read as a margin named `two`
            near = "; " + _who_came_close(close)
    others = ("" if len(agents) == 1 else " (" + ", ".join(
        f"{a.name} {o}" for a, o in zip(agents, res.robot_outcomes)) + ")")
    shown = clearance(m["min_clearance_in"], close[0].robot.safety_margin if near else None)
    return (f"{res.world.name}: {res.outcome.upper()}{others} after {m['time_s']:.2f} s "
            f"(seed {res.seed}, {res.planner}); min clearance {shown} in{near}")


def _who_came_close(close: list) -> str:
    """``two came closer than its safety margin (2 in)``, ``robot and two came closer than
    their safety margin (2 in)``, or each with its own margin where they differ."""
    margins = [a.robot.safety_margin for a in close]
    if len(set(margins)) == 1:
        names = close[0].name if len(close) == 1 else \
            ", ".join(a.name for a in close[:-1]) + f" and {close[-1].name}"
        return (f"{names} came closer than {'its' if len(close) == 1 else 'their'} safety "
                f"margin ({margins[0]:g} in)")
    return f"{close[0].name} came closer than its safety margin ({margins[0]:g} in), " + \
        ", ".join(f"{a.name} than its ({m:g} in)" for a, m in zip(close[1:], margins[1:]))


def _table(rows: list[tuple[str, ...]]) -> str:
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return "\n".join(("  " + "  ".join(c.ljust(w) for c, w in zip(r, widths))).rstrip()
                     for r in rows)


_ROWS = (   # label, key, format (the overall figures, then each robot's)
    ("outcome", "outcome", str), ("reached goal", "reached_goal", lambda v: "yes" if v else "no"),
    ("collisions", "collisions", str), ("time", "time_s", lambda v: f"{v:.2f} s"),
    ("ticks", "ticks", str), ("path length", "path_length_in", lambda v: f"{v:.1f} in"),
    ("mean speed", "mean_speed_in_s", lambda v: f"{v:.1f} in/s"),
    ("min clearance", "min_clearance_in", lambda v: f"{clearance(v)} in"),
    ("steering total variation", "steering_total_variation_deg", lambda v: f"{v:.0f} deg"),
    ("replans", "replans", str), ("backed out", "backouts", str))


def _summary(res: SimResult) -> str:
    """The figures over all robots; with several, a column per robot beside them (path and
    steering variation are sums over the robots, the clearance the smallest)."""
    overall = res.summary()
    each = res.robot_metrics if len(res.robot_metrics) > 1 else ()
    rows = [("", "all robots", *(r["name"] for r in each))] if each else []
    margins = [a.robot.safety_margin for a in res.world.agents]
    for label, key, fmt in _ROWS:
        if key == "min_clearance_in":       # beside the margin, as the verdict says it
            cells = [f"{clearance(overall[key], min(margins))} in"]
            cells += [f"{clearance(r[key], m)} in" for r, m in zip(each, margins)]
            rows.append((label, *cells))
            continue
        cells = [fmt(overall[key])]
        for r in each:
            if key == "collisions":
                cells.append(str(int(r["outcome"] == "collision")))
            else:
                cells.append(fmt(r[key]) if key in r else "")
        rows.append((label, *cells))
    return _table(rows)


_RUNS_FIGURES = (   # heading, key: the runs table's figures, each a mean (± std) over the runs
    ("time s", "time_s"), ("path in", "path_length_in"), ("min clear in", "min_clearance_in"),
    ("speed in/s", "mean_speed_in_s"), ("replans", "replans"), ("backed out", "backouts"))


def _runs_table(runs: Runs) -> str:
    """One row per world; under a world of several robots, one row per robot (its outcome
    rates and figures: the world's row counts a run a success only if every robot's was)."""
    outcomes = ["success", "collision", "timeout", "stuck"]
    if any(w.robots for w in runs.worlds):         # a robot's own outcome may be `stopped`
        outcomes.append("stopped")
    head = ["world", "runs", *outcomes, *(h for h, _ in _RUNS_FIGURES)]
    rows = [head]
    for w in runs.worlds:
        for label, r in [(w.world, w)] + [(f"  {x.world}", x) for x in w.robots]:
            row = [label, str(len(r.summaries))]
            row += [percent(r.count(o), len(r.summaries)) if o in r.outcomes else "-"
                    for o in outcomes]
            for _, key in _RUNS_FIGURES:
                mean, std = r.stat(key)
                row.append(f"{mean:.1f}" if std is None else f"{mean:.1f} ± {std:.1f}")
            rows.append(row)
    widths = [max(len(r[i]) for r in rows) for i in range(len(head))]
    table = "\n".join("  ".join(c.ljust(wd) if i == 0 else c.rjust(wd)
                                for i, (c, wd) in enumerate(zip(r, widths))) for r in rows)
    return table + _runs_footnote(runs)


def _runs_footnote(runs: Runs) -> str:
    """What the figures of the runs table are: means (± standard deviations) over every run,
    a failed run's until it ended."""
    spread = any(len(r.summaries) > 1 for w in runs.worlds for r in (w, *w.robots))
    failed = any(r.rate("success") < 1 for w in runs.worlds for r in (w, *w.robots)
                 if "success" in r.outcomes)
    if not (spread or failed):
        return ""
    what = "mean ± standard deviation" if spread else "means"
    note = (f"\n(time, path, min clear, speed, replans and backed out: {what} over "
            f"{'every run' if failed else 'the runs'}")
    if failed:
        note += (", a collision's or a timeout's until it ended; `mitos compare` takes time and "
                 "path over the successful runs")
    return note + ")"


def _draw_runs(result: Runs, world: World, plot: Path) -> Runs:
    """Every run's path in one picture (``--runs N --plot``); the runs without their trails
    (which are the picture's, not the table's or the JSON's)."""
    from dataclasses import replace

    from ..draw.data.overlay import runs_overlay
    from ..draw.runs import draw_runs
    from ..sim.loop import prepare

    (w,) = result.worlds
    names = [a.name for a in world.agents]
    draw_runs(runs_overlay(w.world, w.summaries, names), world, prepare(world), plot)
    bare = tuple({k: v for k, v in s.items() if k != "trail"} for s in w.summaries)
    return replace(result, worlds=(replace(w, summaries=bare),))


def _run_many(loaded: list[World], runs: int, seed: int | None, planner: Planner, workers: int | None,
             plot: Path | None, quiet: bool) -> tuple[Runs, int | None, int]:
    """``run_many`` with a progress bar on a terminal. Returns the runs and, when Ctrl-C (or
    a SIGTERM, a SIGHUP) stopped them, how many were asked for (``None`` otherwise) and the
    exit code to stop with: the finished ones are kept."""
    from ..sim.runs import RunsInterrupted, run_many, trail

    label = f"{len(loaded)} worlds" if len(loaded) > 1 else loaded[0].name
    with progress_bar(f"simulate {label}", quiet=quiet) as bar:
        try:
            return run_many(loaded, runs, seed, planner, workers,
                            measure=trail if plot is not None else None, on_progress=bar.update,
                            on_clock=lambda t: bar.status(f"runs at {t:.0f} s")), None, 0
        except RunsInterrupted as stop:
            return stop.runs, stop.total, stopped_code(stop.interrupt)


def _write_text(path: Path, text: str) -> None:
    from ..fileio import atomic_write

    atomic_write(path, text)


def simulate_command(
    worlds: Annotated[Optional[list[str]], typer.Argument(
        click_type=WORDS, metavar="[WORLD.yaml]...", autocompletion=complete.worlds, callback=named,
        help="World files (default: the packaged corridor.yaml); names of packaged worlds "
             "such as figure4.yaml work from anywhere.")] = None,
    rulebase: Annotated[Optional[str], typer.Option(
        "--rulebase", "-r", metavar="PATH|NAME", callback=named,
        help="Rule base: a file, or a packaged one by name (`mitos list rulebases`; default: "
             "the packaged mitos.rules).")] = None,
    behavior: Annotated[Optional[str], typer.Option(
        "--behavior", "-b", metavar="NAME", callback=named,
        help="Behavior that drives (default: the world's, else `drive`).")] = None,
    seed: Annotated[Optional[int], typer.Option(
        "--seed", metavar="SEED", click_type=Number("the seed", 0),
        help="Seed (default: the world's); with --runs, run j uses SEED+j.")] = None,
    runs: Annotated[int, typer.Option(
        "--runs", metavar="N",
        click_type=Number("the number of randomised runs per world", 0, MAX_RUNS),
        help="Randomised runs per world (obstacle places, sensor noise); 0: the world once, "
             "as written (`compare` defaults to 20: it needs many).")] = 0,
    randomise: Annotated[bool, typer.Option(
        "--randomise", help="Randomise this one run as run j of --runs does (replay it with "
                            "--seed SEED+j).")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON instead of the table.")] = False,
    out: Annotated[Optional[Path], typer.Option(
        "--out", "-o", parser=file_arg, metavar="FILE.csv",
        help="Write one CSV row per tick (and robot) to FILE.csv (a name ending in .csv).")] = None,
    trace: Annotated[bool, typer.Option(
        "--trace", help="Every --every ticks (and at each replan and the last tick), print "
                        "the pose, speed, steering, clearance and "
                        "perceived vs true inputs, then the paper-style DOF trace (none for a "
                        "planner that is not a rule base); of the first robot where there are "
                        "several; on stderr with --json, which keeps stdout for the JSON.")] = False,
    every: Annotated[Optional[int], typer.Option(
        "--every", metavar="N", click_type=Number("the number of ticks between traces", 1),
        help="Ticks between traces (default 20); with --trace.")] = None,
    plot: Annotated[Optional[Path], typer.Option(
        "--plot", parser=file_arg, metavar="FILE.png|FILE.svg",
        help="Draw the run (world, obstacles, path); with --runs, every run's path in one "
             "picture, coloured by outcome.")] = None,
    live: Annotated[bool, typer.Option(
        "--live", help="Show a terminal view on stderr while it runs, paced by --speed.")] = False,
    speed: Annotated[Optional[float], typer.Option(
        "--speed", metavar="X", click_type=Factor("the real-time factor", 0.001, "as fast as it can"),
        help="Real-time factor of --live (implies it): 1 real time (the default), 4 four "
             "times faster, 0 as fast as it can.")] = None,
    animate: Annotated[Optional[Path], typer.Option(
        "--animate", parser=file_arg, metavar="FILE.gif|FILE.mp4",
        help="Write the run as an animation: map, footprint, sonar cones, trail, obstacles, "
             "time and the fired rules' DOFs (.mp4 needs ffmpeg).")] = None,
    fps: Annotated[Optional[float], typer.Option(
        "--fps", metavar="FPS",
        click_type=Number("the frames per second", 0.1, 60.0, whole=False),
        help="Animation frames per second of simulated time (plays in real time; default 10); "
             "with --animate.")] = None,
    require: Annotated[Optional[str], typer.Option(
        "--require", metavar="success", help="Exit 3 unless every run ends in this outcome.")] = None,
    workers: Annotated[Optional[int], typer.Option(
        "--workers", "-j", metavar="N", click_type=Number("the number of processes", 1),
        help="Processes for --runs (default: the CPUs allowed, fewer where memory is short).")] = None,
    planner_name: Annotated[str, typer.Option(
        "--planner", metavar="NAME", autocompletion=complete.planners,
        help="Who drives: fuzzy (the rule base), potential_field or dwa (baselines that "
             "see the same readings and follow the same route).")] = "fuzzy",
) -> None:
    """Simulate the rule base driving one tricycle robot or several through corridor worlds.

    With several robots (a world's `robots:`), the verdict names each robot's outcome, the
    table and --json give each robot's figures beside all robots', --runs a row per robot,
    --out a row per tick and robot, --plot every robot's path; --trace follows the first.
    """
    from ..resources import DEFAULT_WORLD
    from ..sim.planner import PLANNERS, make_planner, planner_kind

    require = _checked_require(require)
    planner_name = planner_name.lower()        # any case, as every option's fixed list
    several = [p.strip() for p in planner_name.split(",")]
    if len(several) > 1 and all(p in PLANNERS for p in several):   # compare's list, here
        raise typer.BadParameter(f"simulate drives with one planner (--planner NAME); "
                                 f"`mitos compare --planner {','.join(several)}` compares "
                                 f"them", param_hint="--planner")
    with option_names():                        # an unknown name fails before any file is read
        planner_kind(planner_name)
    if plot is not None:                        # before the run, as `plot -o` does
        from .plot_cmd import picture_path

        picture_path(str(plot), "'--plot'")
    if planner_name != "fuzzy" and (rulebase or behavior):
        raise typer.BadParameter(f"--rulebase and --behavior choose the fuzzy planner's rules; "
                                 f"`{planner_name}` has none", param_hint="--planner")
    live = live or speed is not None
    for world in worlds or []:        # `--planner dwa potential_field`: one planner drives
        if world.lower() in PLANNERS and not Path(world).exists():
            raise typer.BadParameter(f"`{world}` is a planner, read here as a world: simulate "
                                     f"drives with one (--planner NAME); `mitos compare "
                                     f"--planner {planner_name},{world}` compares them")
    loaded = _load_worlds(worlds or [DEFAULT_WORLD])
    from ..sim.obstacles import copies_note

    for note in (n for w in loaded for n in (*w.notes, copies_note(w, runs)) if n):
        warn(note)                            # likely mistakes: said, not refused
    _check_outputs((("--out", out), ("--plot", plot), ("--animate", animate)),
                   [Path(w.path) for w in loaded if w.path] + ([Path(rulebase)] if rulebase else []))
    for path in (out, plot, animate):         # before the run, not after it
        if path is not None:
            check_directory(path)
    if out is not None:                       # as --plot's and convert -o's: a usage error
        check_suffix(out, ".csv", "the table of ticks (--out)", "'--out' / '-o'")
    many = len(loaded) > 1 or runs > 0
    _check_run_options(many, len(loaded), runs, randomise, out, trace, live, animate, plot)
    _check_partners(many, trace, every, animate, fps, workers)
    planner = make_planner(planner_name, loaded[0], rulebase, behavior)
    # a SIGTERM (`kill PID`, a scheduler's time limit) or a SIGHUP (the terminal closed)
    # stops as Ctrl-C does, saying what was kept (they ended the process without a word,
    # the finished runs lost); exit 143, 129
    with terminate_as_interrupt():
        try:
            if many:
                _simulate_many(loaded, runs, seed, planner, workers, plot, as_json, require)
            else:
                _simulate_one(loaded[0], planner, seed, randomise, live, speed, trace,
                              every or 20, as_json, out, plot, animate, fps or 10.0, require)
        except Terminated as exc:      # where Ctrl-C ends quietly too (the output printed)
            raise typer.Exit(exc.code) from None


def _load_worlds(names: list[str]) -> list:
    """Each world, in order; one named twice (`a.yaml ./a.yaml` too) is a usage error, as
    `compare` says: it ran twice and printed two identical rows under one name."""
    from ..sim.worldfile import load_world, resolve_world_path

    loaded, seen = [], set()
    for name in names:
        path = resolve_world_path(name)
        if path.resolve() in seen:
            raise typer.BadParameter(f"the world `{name}` is given twice")
        seen.add(path.resolve())
        loaded.append(load_world(path))
    return loaded


def _check_partners(many: bool, trace: bool, every: int | None, animate: Path | None, fps: float | None,
                    workers: int | None) -> None:
    """An option that tunes another, given without it, is a usage error: `--every 5` alone
    printed no trace, `--fps 5` no animation, `-j 4` of one run started no process, each
    without a word."""
    for given, needed, partner, what in (
            (every, trace, "--trace", "--every sets the ticks between traces"),
            (fps, animate, "--animate FILE.gif", "--fps sets the animation's frames a second"),
            (workers, many, "--runs N (or several worlds)", "-j sets the processes of --runs")):
        if given is not None and not needed:
            raise typer.BadParameter(f"{what}: add {partner}, or leave it out")


def _checked_require(require: str | None) -> str | None:
    """``--require``'s outcome in lower case (any case is taken, as ``--to``'s names are)."""
    if require is None:
        return None
    require = require.lower()
    if require not in REQUIRE:                # a wrong name: as a planner's (exit 2)
        from ..errors import UsageError, unknown

        raise unknown("--require outcome", require, REQUIRE, cls=UsageError)
    return require


def _many(worlds: int, runs: int) -> str:
    """What ``simulate`` was asked to run, in words: ``3 worlds``, ``--runs 20``."""
    return " and ".join(part for part in (f"{worlds} worlds" if worlds > 1 else "",
                                          f"--runs {runs}" if runs > 0 else "") if part)


def _check_run_options(many: bool, worlds: int, runs: int, randomise: bool, out: Path | None, trace: bool,
                       live: bool, animate: Path | None, plot: Path | None) -> None:
    """Usage errors among the options, and a picture format or a missing matplotlib, all
    before any run: a mistake found after a long run costs the run."""
    if randomise and runs > 0:                # not "give one world": it was one
        raise typer.BadParameter("--runs randomises every run already; --randomise replays "
                                 "one of them (with --seed)", param_hint="--randomise")
    given = [name for name, on in (("--out", out), ("--animate", animate), ("--trace", trace),
                                   ("--live/--speed", live), ("--randomise", randomise)) if on]
    if many and given:                        # the way out that fits: one world had "give one"
        fix = ("drop --runs (--randomise --seed SEED replays one randomised run)"
               if worlds == 1 else "give one world" if runs == 0
               else "drop --runs and give one world")
        raise typer.BadParameter(f"{' and '.join(given)} "
                                 f"{'works' if len(given) == 1 else 'work'} on one run of one "
                                 f"world, not {_many(worlds, runs)}: {fix}")
    if plot is not None and worlds > 1:
        raise typer.BadParameter("--plot draws one world (with --runs, all its runs in one "
                                 "picture); give one world", param_hint="--plot")
    if plot is not None:
        from ..draw.output import check_format

        check_format(plot)
    if animate is not None:
        from ..draw.animation import FORMATS as MOVIES
        from ..draw.animation import check_format as check_animation

        suffix = animate.suffix.lower().lstrip(".")
        if suffix not in MOVIES:             # as --plot's: a usage error, before the run
            raise typer.BadParameter(
                f"`{animate}` has {'extension .' + suffix if suffix else 'no extension'}; the "
                f"animation formats are " + " and ".join(f".{f}" for f in MOVIES),
                param_hint="--animate")
        check_animation(animate)
    if plot is not None or animate is not None:
        from ..draw.output import require_matplotlib

        require_matplotlib()


def _simulate_many(loaded: list[World], runs: int, seed: int | None, planner: Planner,
                  workers: int | None, plot: Path | None, as_json: bool,
                   require: str | None) -> None:
    """Several worlds or ``--runs``: the outcome table (or JSON) and the runs' picture; after
    Ctrl-C, what finished."""
    result, stopped, code = _run_many(loaded, runs, seed, planner, workers, plot, as_json)
    if stopped is not None:
        if not result.worlds:
            err(f"interrupted before any run finished (0 of {stopped}); nothing written")
            raise typer.Exit(code)
        plot = plot if len(result.worlds) == len(loaded) else None
    if plot is not None:
        result = _draw_runs(result, loaded[0], plot)
    emit(json_text(result.to_json()) if as_json else _runs_table(result))
    if plot is not None:
        err(f"wrote picture of {plural(len(result.worlds[0].summaries), 'run')} to {plot}")
    if stopped is not None:
        done = sum(len(w.summaries) for w in result.worlds)
        what = "the JSON has" if as_json else "the table has"
        err(f"interrupted: {what} the {done} of {stopped} runs that had finished "
            f"(their seeds: runs_detail in --json)")
        raise typer.Exit(code)
    failed = any(s["outcome"] != "success" for w in result.worlds for s in w.summaries)
    if require and failed:
        raise typer.Exit(3)


def _simulate_one(world: World, planner: Planner, seed: int | None, randomise: bool, live: bool,
                  speed: float | None, trace: bool, every: int, as_json: bool, out: Path | None,
                  plot: Path | None, animate: Path | None, fps: float,
                  require: str | None) -> None:
    """One run: its verdict and figures (or JSON), and the trace, CSV, picture and
    animation asked for."""
    res = _run_one(world, planner, seed, randomise, live, speed)
    if trace:
        from ..sim.export import traces

        text = traces(res, planner, every)
        if as_json:
            err(text)
        else:
            emit(text + "\n")
    written: list[str] = []
    try:
        frames = _write_outputs(res, planner, out, plot, animate, fps, written)
    except KeyboardInterrupt as exc:
        err(_interrupted_writing(written))
        raise typer.Exit(stopped_code(exc)) from None
    if as_json:
        emit(json_text(res.summary()))
    else:
        emit(_verdict(res))
        emit(_summary(res))
    for path, what in ((out, "ticks"), (plot, "picture"), (animate, plural(frames, "frame"))):
        if path is not None:
            err(f"wrote {what} to {path}")
    if require and res.outcome != require:
        raise typer.Exit(3)
    sys.stdout.flush()


def _write_outputs(res: SimResult, planner: Planner, out: Path | None, plot: Path | None,
                  animate: Path | None, fps: float, written: list[str]) -> int:
    """The CSV, picture and animation asked for (each named in ``written`` once it is), and
    the animation's frames."""
    if out is not None:
        from ..sim.export import csv_text

        _write_text(out, csv_text(res, planner))
        written.append(f"the ticks to {out}")
    if plot is not None:
        from ..draw.world import draw_run

        draw_run(res, plot)
        written.append(f"the picture to {plot}")
    if animate is None:
        return 0
    from ..draw.animation import animate_run
    from ..sim.export import explain

    return animate_run(res, animate, fps=fps, detail=explain(res, planner))


def _interrupted_writing(written: list[str]) -> str:
    """What a Ctrl-C while the run's files were written leaves (it ended the command
    without a word, not saying which of them were there)."""
    if not written:
        return "interrupted after the run, before its files were written: nothing written"
    return f"interrupted: wrote {' and '.join(written)}; the rest is not written"


def _run_one(world: World, planner: Planner, seed: int | None, randomise: bool, live: bool,
            speed: float | None) -> SimResult:
    """The run, shown live on the terminal if asked; Ctrl-C ends the command, writing
    nothing."""
    from ..sim.loop import prepare, shared_scene, simulate

    scene = shared_scene(world, randomise)      # None: the draw moves what the robot is given
    try:
        if not live:
            return simulate(world, planner, seed, randomise=randomise, scene=scene)
        from ..sim.live import LiveView

        with LiveView(world, scene or prepare(world),
                      speed=1.0 if speed is None else speed) as view:
            return simulate(world, planner, seed, randomise=randomise, scene=scene,
                            on_tick=view.update)
    except KeyboardInterrupt as exc:
        err("interrupted: nothing written (the view shows the last tick drawn)" if live
            else "interrupted before the run ended: nothing written")
        raise typer.Exit(stopped_code(exc)) from None
