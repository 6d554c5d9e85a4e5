"""Navigation benchmark: every planner on the same worlds, with BARN's and MRPB's scores.

    python benchmarks/bench_nav.py                 # the full run (100 BARN worlds, 10 clutter draws)
    python benchmarks/bench_nav.py --quick         # a short run (10 BARN worlds, 2 clutter draws)
    python benchmarks/bench_nav.py --worlds 200    # more BARN worlds
    python benchmarks/bench_nav.py --planners fuzzy,dwa --json out.json

Suites (docs/navigation.md says what each means and what was measured):

- ``mrpb``: MRPB 1.0's start/goal tests on its seven complete maps, read from
  ``../shared/maps/mrpb/`` (``--mrpb DIR``), and its two partially unknown scenarios when the
  world model can hold a given map apart from the true building;
- ``barn-unknown`` / ``barn-known``: ``--worlds`` seeded BARN-style fields
  (:func:`mitos_cli.sim.barn.barn_worlds`), the poles unknown to the robot, then the same
  fields drawn in its map;
- ``clutter``: the shipped single-robot worlds (but ``figure4.yaml``, the paper's collision)
  and MRPB's office02 building with 3-6 seeded unknown boxes, bins and trolleys each
  (:func:`mitos_cli.sim.clutter.clutter`, a 40 in way left past each), ``--draws`` per world.

Per suite and planner: success, collision, timeout and stuck rates (a test whose start and goal
the route planner cannot join for this robot counts as ``no route``), the mean time of the
successful runs, BARN's score and MRPB's safety. Runs go through the simulator's process pool
(:func:`mitos_cli.sim.runs.run_many`, ``--workers``, default: up to 2); progress on stderr.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

from mitos_cli.errors import MitosError
from mitos_cli.sim import barn, mrpb
from mitos_cli.sim.clutter import clutter
from mitos_cli.sim.loop import prepare
from mitos_cli.sim.planner import PLANNERS, make_planner
from mitos_cli.sim.runs import run_many
from mitos_cli.sim.scores import MRPB_SAFETY_IN, barn_score, mrpb_safety, optimal_time
from mitos_cli.sim.worldfile import load_world, resolve_world_path

HERE = Path(__file__).resolve().parent
MRPB_DIR = HERE.parent.parent / "shared" / "maps" / "mrpb"
SHIPPED = ("corridor", "slalom", "intersection", "moving", "office")
OUTCOMES = ("success", "collision", "timeout", "stuck", "no route")


def measure(res) -> dict:
    """What the scores need from a run's ticks (computed in the worker)."""
    return {"mrpb_safety": mrpb_safety(res.clearance[:, 0]),
            "route_length_in": float(res.routes[0].length) if res.routes else 0.0}


def routable(worlds, known_twins=None):
    """The worlds whose route exists (the rest are ``no route`` for every planner), and the
    shortest path's length of each (its twin's when the obstacles are unknown to it)."""
    ok, lengths, refused = [], {}, []
    for i, w in enumerate(worlds):
        try:
            length = float(prepare(w).routes[0].length)
        except MitosError as exc:
            refused.append((w.name, exc.message if hasattr(exc, "message") else str(exc)))
            continue
        if known_twins:            # around the poles, if the route planner finds a way there
            with contextlib.suppress(MitosError):   # too tight for the route: the straight length
                length = float(prepare(known_twins[i]).routes[0].length)
        ok.append(w)
        lengths[w.name] = length
    return ok, lengths, refused


def mrpb_suite(root: Path) -> tuple[list, list[str]]:
    worlds, notes = [], []
    for name in mrpb.COMPLETE:
        worlds += mrpb.scenario_worlds(root, name)
    for name in mrpb.PARTIALLY_UNKNOWN:
        try:
            worlds += mrpb.scenario_worlds(root, name)
        except MitosError as exc:
            notes.append(f"{name}: left out ({exc.args[0] if exc.args else exc})")
    return worlds, notes


def clutter_suite(root: Path, draws: int, seed: int) -> list:
    bases = [load_world(resolve_world_path(n + ".yaml")) for n in SHIPPED]
    bases += mrpb.scenario_worlds(root, "office02")
    out = []
    for b, base in enumerate(bases):
        scene = prepare(base)
        for j, seq in enumerate(np.random.SeedSequence([seed, b]).spawn(draws)):
            rng = np.random.default_rng(seq)
            w = clutter(base, scene.static, scene.routes[0], rng, int(rng.integers(3, 7)))
            out.append(w.with_changes(name=f"{base.name}+clutter{j}", seed=base.seed + j))
    return out


def run_suite(name, worlds, planners, workers, lengths, refused, progress):
    """Rows per planner: rates, mean time, BARN score and MRPB safety."""
    rows = {}
    for p in planners:
        planner = make_planner(p, worlds[0]) if worlds else None
        summaries = []
        batch = max(2, 4 * (workers or 2))
        for i in range(0, len(worlds), batch):
            part = worlds[i:i + batch]
            res = run_many(part, 0, None, planner, workers, measure=measure)
            summaries += [s for w in res.worlds for s in w.summaries]
            progress(name, p, len(summaries), len(worlds))
        rows[p] = score_rows(summaries, lengths, len(refused))
    return rows


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


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="10 BARN worlds and 2 clutter draws")
    ap.add_argument("--worlds", type=int, default=None, help="BARN worlds (default 100)")
    ap.add_argument("--draws", type=int, default=None, help="clutter draws per world (10)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the BARN fields and clutter")
    ap.add_argument("--planners", default=",".join(PLANNERS), help="comma-separated")
    ap.add_argument("--suites", default="mrpb,barn-unknown,barn-known,clutter")
    ap.add_argument("--mrpb", type=Path, default=MRPB_DIR, help="MRPB 1.0's maps and tests")
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--json", type=Path, default=None, help="write the figures here too")
    args = ap.parse_args(argv)
    n_barn = args.worlds or (10 if args.quick else 100)
    draws = args.draws or (2 if args.quick else 10)
    planners = [p.strip() for p in args.planners.split(",") if p.strip()]
    suites = [s.strip() for s in args.suites.split(",") if s.strip()]
    try:
        for p in planners:
            if p not in PLANNERS:
                from mitos_cli.errors import unknown

                raise unknown("planner", p, PLANNERS)
        start = time.perf_counter()

        def progress(suite, planner, done, total):
            print(f"[{time.perf_counter() - start:7.1f} s] {suite} {planner}: {done}/{total}",
                  file=sys.stderr, flush=True)

        results, notes = {}, []
        for suite in suites:
            twins = None
            if suite == "mrpb":
                worlds, more = mrpb_suite(args.mrpb)
                notes += more
            elif suite == "barn-unknown":
                worlds = barn.barn_worlds(n_barn, args.seed)
                twins = barn.barn_worlds(n_barn, args.seed, known=True)
            elif suite == "barn-known":
                worlds = barn.barn_worlds(n_barn, args.seed, known=True)
            elif suite == "clutter":
                worlds = clutter_suite(args.mrpb, draws, args.seed)
            else:
                print(f"unknown suite `{suite}`", file=sys.stderr)
                return 2
            worlds, lengths, refused = routable(worlds, twins)
            notes += [f"{w}: no route ({why})" for w, why in refused]
            results[suite] = run_suite(suite, worlds, planners, args.workers, lengths, refused,
                                       progress)
    except MitosError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    elapsed = time.perf_counter() - start
    print(table(results))
    for note in notes:
        print("note:", note)
    print(f"BARN: {n_barn} worlds from seed {args.seed}; clutter: {draws} draws per world; "
          f"MRPB safety distance {MRPB_SAFETY_IN:.2f} in (0.1 m); {elapsed:.0f} s on "
          f"{os.cpu_count()} cores ({platform.processor() or platform.machine()}), "
          f"Python {platform.python_version()}")
    if args.json:
        args.json.write_text(json.dumps({"results": results, "notes": notes,
                                         "barn_worlds": n_barn, "draws": draws,
                                         "seed": args.seed, "seconds": elapsed}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
