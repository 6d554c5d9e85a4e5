"""Navigation benchmark: every planner on the same worlds, with BARN's and MRPB's scores.

    python benchmarks/bench_nav.py                 # the full run (100 BARN worlds, 10 clutter draws)
    python benchmarks/bench_nav.py --quick         # a short run (10 BARN worlds, 2 clutter draws)
    python benchmarks/bench_nav.py --worlds 200    # more BARN worlds
    python benchmarks/bench_nav.py --planners fuzzy,dwa --jobs 2 --json out.json

Suites (docs/navigation.md says what each means and what was measured):

- ``mrpb``: MRPB 1.0's start/goal tests on its seven complete maps and its two partially
  unknown scenarios, read from ``../shared/maps/mrpb/`` (``--mrpb DIR``), with a robot of
  MRPB's size (:data:`mitos_cli.sim.mrpb.PIONEER`);
- ``barn-unknown`` / ``barn-known``: ``--worlds`` seeded BARN-style fields
  (:mod:`mitos_cli.sim.barn`), the poles unknown to the robot, then the same fields drawn in
  its map;
- ``clutter``: the shipped single-robot worlds (but ``figure4.yaml``, the paper's collision)
  and MRPB's office02 building with 3-6 seeded unknown boxes, bins and trolleys each
  (:func:`mitos_cli.sim.clutter.clutter`: a 40 in way left past each, a way to the goal the
  robot fits through, none on a moving obstacle's path), ``--draws`` per world;
- ``ticks``: one line, the speed aim: a BARN field of ``--ticks-obstacles`` unknown poles (one
  obstacle per pole), run by each planner on one core, in ticks per second of wall time.

Per suite and planner: success, collision, timeout and stuck rates (a test whose start and goal
the route planner cannot join for this robot counts as ``no route``), the mean time of the
successful runs, BARN's score and MRPB's safety. The work is split into tasks (one MRPB test,
one BARN field with its known twin, one clutter draw), each run by one of ``--jobs``
processes with every planner: a map is read once per process, a field generated and a route
planned once per task. Each run is a pure function of its world, planner and seed, and the
rows are gathered in a fixed order, so the figures do not depend on ``--jobs``. Progress on
stderr, the table on stdout.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import platform
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np
from options import guarded, positive_int, writable

from mitos_cli.errors import MitosError, Span, unknown
from mitos_cli.sim import barn, mrpb
from mitos_cli.sim.clutter import clutter
from mitos_cli.sim.loop import Scene, prepare, simulate
from mitos_cli.sim.planner import PLANNERS, make_planner
from mitos_cli.sim.scores import MRPB_SAFETY_IN, barn_score, mrpb_safety, optimal_time
from mitos_cli.sim.worldfile import load_world, resolve_world_path

HERE = Path(__file__).resolve().parent
MRPB_DIR = HERE.parent.parent / "shared" / "maps" / "mrpb"
SHIPPED = ("corridor", "slalom", "intersection", "moving", "office")
SUITES = ("mrpb", "barn-unknown", "barn-known", "clutter", "ticks")
OUTCOMES = ("success", "collision", "timeout", "stuck", "no route")


# --- what one process keeps: each map read once, each planner built once ------------------

@functools.cache
def scenario(root: str, name: str) -> tuple:
    return tuple(mrpb.scenario_worlds(Path(root), name))


@functools.cache
def clutter_base(root: str, b: int):
    """The ``b``-th clutter base world and its scene (the clutter is unknown to the robot, so
    the base's route and map are the cluttered world's too)."""
    base = (load_world(resolve_world_path(SHIPPED[b] + ".yaml")) if b < len(SHIPPED)
            else scenario(root, "office02")[b - len(SHIPPED)])
    return base, prepare(base)


_PLANNERS: dict[tuple, object] = {}


def planner_for(name: str, world):
    """The planner ``name`` for ``world``, built once per behavior, robot and sensors."""
    key = (name, world.behavior, world.agents[0].robot, world.sensors)
    if key not in _PLANNERS:
        _PLANNERS[key] = make_planner(name, world)
    return _PLANNERS[key]


def run(world, scene: Scene, planners: tuple[str, ...]) -> dict:
    """Every planner on ``world`` from its own seed: outcome, time and MRPB's safety each."""
    out = {}
    for p in planners:
        res = simulate(world, planner_for(p, world), world.seed, scene=scene)
        s = res.summary()
        out[p] = {"outcome": s["outcome"], "time_s": s["time_s"],
                  "mrpb_safety": mrpb_safety(res.clearance[:, 0])}
        del res
    return out


def attempt(world, scene_of) -> tuple[Scene | None, str | None]:
    """The world's scene, or why there is no route (the refusal's message)."""
    try:
        return scene_of(world), None
    except MitosError as exc:
        return None, getattr(exc, "message", None) or str(exc)


# --- tasks: a picklable description in, rows out -------------------------------------------

def task(job: tuple) -> list[dict]:
    """Rows ``{suite, world, length, refused, runs}`` of one task; a task that fails is one
    row naming the error, so one broken world does not lose the whole run."""
    try:
        return _task(job)
    except Exception as exc:            # noqa: BLE001 - reported in the table's notes
        return [{"suite": job[0], "world": label(job),
                 "error": f"{type(exc).__name__}: {exc}", "refused": None, "length": None,
                 "runs": {}}]


def _task(job: tuple) -> list[dict]:
    kind, planners = job[0], job[-1]
    rows = []
    if kind == "mrpb":
        _, root, name, i, _ = job
        w = scenario(root, name)[i]
        scene, why = attempt(w, prepare)
        rows.append(row("mrpb", w, scene, why, None, planners))
    elif kind == "barn":
        _, seed, suites, _ = job
        f = barn.field(seed, *barn.difficulty(seed))
        known = barn.world_of(f, known=True)
        k_scene, k_why = attempt(known, prepare)
        length = float(k_scene.routes[0].length) if k_scene else None
        if "barn-unknown" in suites:
            w = barn.world_of(f)
            scene, why = attempt(w, prepare)
            rows.append(row("barn-unknown", w, scene, why, length, planners))
        if "barn-known" in suites:
            rows.append(row("barn-known", known, k_scene, k_why, length, planners))
    elif kind == "clutter":
        _, root, b, j, seed, _ = job
        base, scene = clutter_base(root, b)
        rng = np.random.default_rng(np.random.SeedSequence([seed, b]).spawn(j + 1)[j])
        w = clutter(base, scene.static, scene.routes[0], rng, int(rng.integers(3, 7)))
        w = w.with_changes(name=f"{base.name}+clutter{j}", seed=base.seed + j)
        rows.append(row("clutter", w, scene, None, None, planners))
    return rows


def row(suite, w, scene, why, length, planners) -> dict:
    own = float(scene.routes[0].length) if scene else None
    return {"suite": suite, "world": w.name, "refused": why,
            "length": length if length is not None else own,
            "runs": run(w, scene, planners) if scene else {}}


def jobs_for(suites, planners, root: str, n_barn: int, seed: int, draws: int) -> list[tuple]:
    """The tasks, the suites interleaved (an MRPB test, a clutter draw, a field, ...): a run
    stopped early has measured some of each, and MRPB's long tests do not all come last."""
    by_suite: list[list[tuple]] = []
    if "mrpb" in suites:
        tests = []
        for name in (*mrpb.COMPLETE, *mrpb.PARTIALLY_UNKNOWN):
            count = len(mrpb.read_tests(Path(root) / name / "tests.txt"))
            tests += [("mrpb", root, name, i, planners) for i in range(count)]
        by_suite.append(tests)
    if "clutter" in suites:
        n_bases = len(SHIPPED) + len(mrpb.read_tests(Path(root) / "office02" / "tests.txt"))
        by_suite.append([("clutter", root, b, j, seed, planners)
                         for j in range(draws) for b in range(n_bases)])
    barn_suites = tuple(s for s in suites if s.startswith("barn"))
    if barn_suites:
        by_suite.append([("barn", s, barn_suites, planners) for s in range(seed, seed + n_barn)])
    out = []
    for k in range(max((len(t) for t in by_suite), default=0)):
        out += [t[k] for t in by_suite if k < len(t)]
    return out


def label(job: tuple) -> str:
    """A task in a few words, for the progress lines."""
    if job[0] == "mrpb":
        return f"mrpb {job[2]} #{job[3] + 1}"
    if job[0] == "clutter":
        return f"clutter base {job[2]} draw {job[3]}"
    return f"barn field {job[1]}"


def run_all(jobs: list[tuple], workers: int, progress, keep=None) -> list[dict]:
    """Every task's rows, in the order of ``jobs`` whatever the order they finish in;
    ``keep(rows)`` is told each task's rows as it finishes (``--rows``)."""
    done: list[list[dict] | None] = [None] * len(jobs)

    def finished(i: int, rows: list[dict], n: int) -> None:
        done[i] = rows
        if keep is not None:
            keep(rows)
        progress(n, len(jobs), jobs[i])

    if workers > 1 and len(jobs) > 1:
        with ProcessPoolExecutor(workers) as pool:
            futures = {pool.submit(task, j): i for i, j in enumerate(jobs)}
            for n, fut in enumerate(as_completed(futures), 1):
                finished(futures[fut], fut.result(), n)
    else:
        for i, j in enumerate(jobs):
            finished(i, task(j), i + 1)
    return [r for rows in done if rows for r in rows]


def suite_results(rows: list[dict], suites, planners) -> tuple[dict, list[str]]:
    """Per suite and planner the figures, and the notes on refused routes (counted)."""
    results: dict = {}
    notes = [f"{r['suite']} task {r['world']} failed and is left out: {r['error']}"
             for r in rows if r.get("error")]
    for suite in suites:
        mine = [r for r in rows if r["suite"] == suite]
        if not mine:
            continue
        refused = [r for r in mine if r["refused"]]
        results[suite] = {}
        for p in planners:
            summaries = [{"world": r["world"], **r["runs"][p]} for r in mine if r["runs"]]
            lengths = {r["world"]: r["length"] if r["length"] is not None else barn.GOAL_AHEAD
                       for r in mine}
            results[suite][p] = score_rows(summaries, lengths, len(refused))
        if refused:
            notes.append(f"{suite}: {len(refused)} of {len(mine)} without a route: "
                         + "; ".join(f"{r['world']} ({r['refused']})" for r in refused))
    return results, notes


def score_rows(summaries: list[dict], lengths: dict, refused: int) -> dict:
    n = len(summaries) + refused
    count = {o: sum(s["outcome"] == o for s in summaries) for o in OUTCOMES[:-1]}
    count["no route"] = refused
    ok = [s for s in summaries if s["outcome"] == "success"]
    scores = [barn_score(s["outcome"] == "success", s["time_s"],
                         optimal_time(lengths[s["world"]])) for s in summaries] + [0.0] * refused
    return {"runs": n, **{f"{o}_rate": count[o] / n if n else 0.0 for o in OUTCOMES},
            "mean_time_s": float(np.mean([s["time_s"] for s in ok])) if ok else None,
            "barn_score": float(np.mean(scores)) if scores else 0.0,
            "mrpb_safety": float(np.mean([s["mrpb_safety"] for s in summaries]))
            if summaries else None}


def table(results: dict) -> str:
    head = ["suite", "planner", "runs", "success", "collision", "timeout", "stuck", "no route",
            "time s", "BARN score", "MRPB safety"]
    rows = [head]
    for suite, by_planner in results.items():
        for p, r in by_planner.items():
            rows.append([suite, p, str(r["runs"])]
                        + [f"{100 * r[o + '_rate']:.1f}%" for o in OUTCOMES]
                        + ["-" if r["mean_time_s"] is None else f"{r['mean_time_s']:.1f}",
                           f"{r['barn_score']:.3f}",
                           "-" if r["mrpb_safety"] is None else f"{100 * r['mrpb_safety']:.1f}%"])
    widths = [max(len(r[i]) for r in rows) for i in range(len(head))]
    return "\n".join("  ".join(c.ljust(w) if i < 2 else c.rjust(w)
                               for i, (c, w) in enumerate(zip(r, widths))) for r in rows)


TICKS = 400                   # ticks timed per planner on the ticks line


def ticks_world(n_obstacles: int, seed: int):
    """A BARN corridor whose field holds ``n_obstacles`` unknown square poles of 0.15 m, one
    obstacle each (cells drawn at 35% and not smoothed, the nearest the field's middle kept)."""
    from dataclasses import replace

    rng = np.random.default_rng(np.random.SeedSequence([seed, 2]))
    filled = rng.random((barn.CELLS, barn.CELLS)) < 0.35
    rows, cols = np.nonzero(filled)
    if n_obstacles > len(rows):
        raise MitosError(f"the ticks line's field holds {len(rows)} poles, not {n_obstacles}",
                         hint=f"give `--ticks-obstacles {len(rows)}` or fewer (or another "
                              f"`--seed`)")
    order = np.argsort(np.hypot(cols - barn.CELLS / 2, rows - barn.CELLS / 2), kind="stable")
    base = barn.world_of(barn.Field(filled, 0.35, 0, seed, 1))
    pole = base.obstacles[0]
    poles = tuple(replace(pole, name=f"pole{i}",
                          x=float(barn.FIELD_AHEAD + (cols[k] + 0.5) * barn.CELL),
                          y=float(-barn.FIELD / 2 + (rows[k] + 0.5) * barn.CELL),
                          length=barn.CELL, width=barn.CELL)
                  for i, k in enumerate(order[:n_obstacles]))
    return base.with_changes(obstacles=poles, name=f"barn-poles-{len(poles)}")


def ticks_line(planners, n_obstacles: int, seed: int) -> dict:
    """The speed aim: ticks per second of wall time in this process (one core), each planner
    timed over ``TICKS`` ticks among ``n_obstacles`` unknown obstacles; a run that ends is
    started again from the next seed, outside the timing."""
    from mitos_cli.sim.loop import Simulation

    w = ticks_world(n_obstacles, seed)
    scene = prepare(w)
    out: dict = {"obstacles": len(w.obstacles), "world": w.name}
    for p in planners:
        sim = Simulation(w, planner_for(p, w), w.seed, scene=scene)
        sim.step()                                            # warm: compile, caches
        runs, wall, cpu, ticks = 1, 0.0, 0.0, 0
        while ticks < TICKS:
            t0, c0 = time.perf_counter(), time.process_time()
            try:
                sim.step()
            except RuntimeError:                              # the run ended: another seed
                sim.reset(w.seed + runs)
                runs += 1
                continue
            wall += time.perf_counter() - t0
            cpu += time.process_time() - c0
            ticks += 1
        # per CPU second too: on a shared machine the wall clock also counts the others' work
        out[p] = {"ticks": ticks, "wall_s": wall, "ticks_per_s": ticks / wall, "runs": runs,
                  "ticks_per_cpu_s": ticks / max(cpu, 1e-9)}
    return out


def aims(results: dict, ticks: dict | None) -> list[str]:
    """The aims of docs/navigation.md against this run, as Markdown table rows."""
    out = ["| aim | measured | met? |", "| --- | --- | --- |"]

    def r(suite, p, key):
        return results.get(suite, {}).get(p, {}).get(key)

    fz = results.get("barn-unknown", {}).get("fuzzy")
    if fz:
        dwa = r("barn-unknown", "dwa", "success_rate")
        own = fz["success_rate"] >= 0.90 and fz["collision_rate"] <= 0.05
        # without DWA's run its part is not judged: it read "yes" of `--planners fuzzy`
        met = "no" if not own or (dwa is not None and fz["success_rate"] < dwa) else \
            "yes" if dwa is not None else "its fuzzy part yes; DWA not run"
        out.append(f"| BARN-style, obstacles unknown: fuzzy success >= 90%, collisions <= 5%, "
                   f"at least DWA's success | fuzzy {100 * fz['success_rate']:.0f}% success, "
                   f"{100 * fz['collision_rate']:.0f}% collisions; DWA "
                   + ("-" if dwa is None else f"{100 * dwa:.0f}%")
                   + f" ({fz['runs']} fields) | {met} |")
    fm = results.get("mrpb", {}).get("fuzzy")
    if fm:
        reached = round(fm["success_rate"] * fm["runs"])
        out.append(f"| MRPB: every test reached by the fuzzy planner | {reached} of "
                   f"{fm['runs']} | {'yes' if reached == fm['runs'] else 'no'} |")
    fc = results.get("clutter", {}).get("fuzzy")
    if fc:
        out.append(f"| building maps with unknown clutter: >= 97% success | fuzzy "
                   f"{100 * fc['success_rate']:.1f}% ({fc['runs']} runs) | "
                   f"{'yes' if fc['success_rate'] >= 0.97 else 'no'} |")
    if ticks and isinstance(ticks.get("fuzzy"), dict):
        # the aim is the product's planner, as every other line here; the baselines beside it
        rate = ticks["fuzzy"]["ticks_per_s"]
        out.append(f"| {ticks['obstacles']} unknown obstacles: the fuzzy planner >= 100 ticks/s "
                   f"on one core | "
                   + ", ".join(f"{p} {v['ticks_per_s']:.0f} ({v['ticks_per_cpu_s']:.0f} per "
                               f"CPU s)" for p, v in ticks.items() if isinstance(v, dict))
                   + f" | {'yes' if rate >= 100 else 'no'} |")
    return out


def run_line(suites, n_barn: int, seed: int, draws: int, tasks: int, elapsed: float,
             jobs: int) -> str:
    """What was run, the suites' sizes only for the suites run: `--suites ticks` read "BARN:
    100 worlds from seed 0; clutter: 10 draws per world" of a run of neither."""
    said = []
    if any(s.startswith("barn") for s in suites):
        said.append(f"BARN: {n_barn} worlds from seed {seed}")
    if "clutter" in suites:
        said.append(f"clutter: {draws} draws per world")
    if set(suites) - {"ticks"}:
        said.append(f"MRPB safety distance {MRPB_SAFETY_IN:.2f} in (0.1 m)")
    if "ticks" in suites:
        said.append(f"ticks: the field of seed {seed}")
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return "; ".join(said) + (f"; {tasks} tasks in {elapsed:.0f} s on {jobs} of "
                              f"{os.cpu_count()} cores ({platform.processor() or platform.machine()})"
                              f", load average {load:.1f} at the end, Python "
                              f"{platform.python_version()}")


ROW_KEYS = {"suite": str, "world": str, "runs": dict}


ROW_EXPECTED = "a JSON object with `suite`, `world` and `runs`, as `--rows` writes"


def read_rows(path: Path) -> list[dict]:
    """The rows of a ``--rows`` file, each line checked; a torn last line (a run killed while
    it appended) is dropped with a note, a damaged line elsewhere is refused at its place,
    with the line. A byte-order mark (a Windows editor's save) is read past, as a world
    file's is: it was refused as line 1's "Unexpected UTF-8 BOM"."""
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise MitosError(f"cannot read rows from `{path}`: {exc}") from None
    numbered = [(n, line) for n, line in enumerate(text.splitlines(), 1) if line.strip()]
    rows = []
    for n, line in numbered:
        try:
            row = json.loads(line)
        except json.JSONDecodeError as exc:
            if n == numbered[-1][0] and not text.endswith("\n"):      # written in part
                print(f"note: {path.name}:{n}: a torn last line (a stopped run) is left out",
                      file=sys.stderr)
                break
            raise MitosError(f"cannot read rows from `{path}`: line {n}: {exc.msg}",
                             span=Span(str(path), n, exc.colno, line),
                             expected=ROW_EXPECTED) from None
        if not isinstance(row, dict) or any(not isinstance(row.get(k), t)
                                            for k, t in ROW_KEYS.items()):
            raise MitosError(f"cannot read rows from `{path}`: line {n} is not a row",
                             span=Span(str(path), n, 1, line), expected=ROW_EXPECTED)
        rows.append(row)
    return rows


def print_rows(path: Path, suites, planners) -> int:
    """The table and notes of the rows a run kept (``--rows``), however far it got."""
    rows = read_rows(path)
    kept = [p for p in planners if all(p in r["runs"] for r in rows if r.get("runs"))]
    results, notes = suite_results(rows, suites, kept)
    print(table(results))
    for note in notes:
        print("note:", note)
    print("\n".join(aims(results, None)))
    print(f"from {len(rows)} rows of `{path.name}`")
    return 0


@guarded
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="10 BARN worlds and 2 clutter draws")
    ap.add_argument("--worlds", type=positive_int, default=None, help="BARN worlds (default 100)")
    ap.add_argument("--draws", type=positive_int, default=None,
                    help="clutter draws per world (10)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the BARN fields and clutter")
    ap.add_argument("--planners", default=",".join(PLANNERS), help="comma-separated")
    ap.add_argument("--suites", default=",".join(SUITES), help="comma-separated")
    ap.add_argument("--mrpb", type=Path, default=MRPB_DIR, help="MRPB 1.0's maps and tests")
    ap.add_argument("--jobs", type=positive_int, default=os.cpu_count() or 1,
                    help="worker processes (default: the core count)")
    ap.add_argument("--ticks-obstacles", type=positive_int, default=300,
                    help="unknown obstacles of the ticks line (300)")
    ap.add_argument("--json", type=writable, default=None, help="write the figures here too")
    ap.add_argument("--rows", type=writable, default=None,
                    help="append each finished task's rows here as JSON lines (a stopped run "
                         "keeps what it measured)")
    ap.add_argument("--from-rows", type=Path, default=None,
                    help="print the table of a --rows file (a finished or stopped run) and "
                         "run nothing")
    args = ap.parse_args(argv)
    n_barn = args.worlds if args.worlds is not None else (10 if args.quick else 100)
    draws = args.draws if args.draws is not None else (2 if args.quick else 10)
    planners = tuple(p.strip() for p in args.planners.split(",") if p.strip())
    suites = tuple(s.strip() for s in args.suites.split(",") if s.strip())
    if not planners or not suites:
        ap.error(f"no {'planner' if not planners else 'suite'} given (comma-separated names)")
    try:
        for p in planners:
            if p not in PLANNERS:
                raise unknown("planner", p, PLANNERS)
        for s in suites:
            if s not in SUITES:
                raise unknown("suite", s, SUITES)
        start = time.perf_counter()

        def progress(done, total, job):
            print(f"[{time.perf_counter() - start:7.1f} s] {done}/{total} tasks ({label(job)})",
                  file=sys.stderr, flush=True)

        if args.from_rows:
            return print_rows(args.from_rows, suites, planners)
        needs = [s for s in ("mrpb", "clutter") if s in suites]
        if needs and not args.mrpb.is_dir():
            raise MitosError(
                f"MRPB 1.0's maps are not in `{args.mrpb}` (the suites "
                f"{' and '.join(needs)} drive them)",
                hint="give their folder with `--mrpb DIR` (by default ../shared/maps/mrpb "
                     "beside the repository), or leave those suites out: `--suites "
                     "barn-unknown,barn-known,ticks`")
        root = str(args.mrpb)
        if "ticks" in suites:
            ticks_world(args.ticks_obstacles, args.seed)       # as many poles as the field holds
        jobs = jobs_for(suites, planners, root, n_barn, args.seed, draws)
        keep = None
        if args.rows:
            args.rows.write_text("", encoding="utf-8")

            def keep(rows):
                with args.rows.open("a", encoding="utf-8") as fh:
                    fh.writelines(json.dumps(r) + "\n" for r in rows)

        rows = run_all(jobs, args.jobs, progress, keep)
        results, notes = suite_results(rows, suites, planners)
        elapsed = time.perf_counter() - start
        ticks = ticks_line(planners, args.ticks_obstacles, args.seed) if "ticks" in suites \
            else None
    except MitosError as exc:
        print(exc.render(), file=sys.stderr)
        return 1
    if results:                          # `--suites ticks` alone: no table, not its header
        print(table(results))
    if ticks:
        print(f"ticks: {ticks['obstacles']} unknown obstacles ({ticks['world']}), one core: "
              + ", ".join(f"{p} {ticks[p]['ticks_per_s']:.0f} ticks/s of wall time, "
                          f"{ticks[p]['ticks_per_cpu_s']:.0f} per CPU second ({ticks[p]['ticks']} "
                          f"ticks in {ticks[p]['wall_s']:.1f} s over {ticks[p]['runs']} runs)"
                          for p in planners)
              + " (aim: at least 100)")
    for note in notes:
        print("note:", note)
    print("\n".join(aims(results, ticks)))
    print(run_line(suites, n_barn, args.seed, draws, len(jobs), elapsed, args.jobs))
    if args.json:
        args.json.write_text(json.dumps({"results": results, "notes": notes, "ticks": ticks,
                                         "rows": rows, "barn_worlds": n_barn, "draws": draws,
                                         "seed": args.seed, "jobs": args.jobs,
                                         "seconds": elapsed}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
