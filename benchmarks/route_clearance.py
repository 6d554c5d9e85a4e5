"""Route clearance: the routes the simulator plans on grids, measured exactly.

    python benchmarks/route_clearance.py                      # shipped worlds, MRPB, 20 BARN
    python benchmarks/route_clearance.py --barn 100 --seed 1000 --json out.json
    python benchmarks/route_clearance.py --drive fuzzy --barn 0   # and every replan on the way

Every route planned on a grid at the start of a run (the shipped worlds that have one or draw
``known`` obstacles, MRPB's 25 tests with the Pioneer, ``--barn`` BARN fields drawn in the map
as ``barn-known`` drives them) is measured against the occupied cells of the grid it was
planned on, each cell the square it is: the smallest distance from each piece of the polyline
to any of them (:func:`mitos_cli.sim.geometry.box_segment_distance`, exact), against the least
clearance the route accepts (``route: {min_clearance}``, else half the robot's width and its
margin). The first and last pieces are held to no more than the start and goal themselves
keep. A route planned along corridors' centre lines is measured against the walls by the
planner itself and is left out. The clutter suite drives its base worlds' routes (the clutter
is unknown to the robot), so it adds no route of its own.

Each route's path before straightening (the nodes A* went through, as
:func:`mitos_cli.sim.route._simplify` is given them) is measured the same way, and each
straight piece against the stretch of that path it replaces: a piece *cuts inside* where it
keeps less than the least clearance and less than that stretch kept, so a shortfall made by
straightening is told apart from one already in the path (a replan lets the route leave the
robot's side through whatever is free, `leave`).

``--drive PLANNER``: run each MRPB test with that planner too and measure every route planned
on the way (the replans, on the robot's own map as it was then). Prints one line per shortfall
and a summary; exits 1 when a straight piece cuts inside.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from options import count, guarded, writable

from mitos_cli.errors import MitosError, unknown
from mitos_cli.sim import barn, knowledge, loop, mrpb
from mitos_cli.sim import route as route_mod
from mitos_cli.sim.geometry import box_segment_distance
from mitos_cli.sim.loop import clearances, prepare, simulate
from mitos_cli.sim.planner import PLANNERS, make_planner
from mitos_cli.sim.worldfile import load_world

HERE = Path(__file__).resolve().parent
MRPB_DIR = HERE.parent.parent / "shared" / "maps" / "mrpb"
TOL = 1e-9          # in: a shortfall smaller than this is rounding


def squares_near(grid, occ: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The centres ``[N, 2]`` of the occupied cells that overlap the box ``lo``-``hi``."""
    res, (ox, oy) = grid.resolution, grid.origin
    rows, cols = occ.shape
    c0, r0 = np.floor((lo - (ox, oy)) / res).astype(int)
    c1, r1 = np.floor((hi - (ox, oy)) / res).astype(int) + 1
    c0, r0, c1, r1 = max(c0, 0), max(r0, 0), min(c1, cols), min(r1, rows)
    if c0 >= c1 or r0 >= r1:
        return np.zeros((0, 2))
    r, c = np.nonzero(occ[r0:r1, c0:c1])
    return np.stack([ox + (c + c0 + 0.5) * res, oy + (r + r0 + 0.5) * res], axis=1)


def segment_rooms(points: np.ndarray, grid, occ: np.ndarray, reach: float) -> np.ndarray:
    """Each piece's distance ``[M - 1]`` from the occupied squares (``reach`` or more read as
    ``inf``)."""
    out = np.full(len(points) - 1, np.inf)
    h = grid.resolution / 2
    for k, (a, b) in enumerate(zip(points[:-1], points[1:])):
        centres = squares_near(grid, occ, np.minimum(a, b) - reach, np.maximum(a, b) + reach)
        if len(centres):
            d = float(box_segment_distance(h, h, np.concatenate([a, b])[None]
                                           - np.tile(centres, 2)).min())
            out[k] = d if d < reach else np.inf
    return out


def point_room(p: np.ndarray, grid, occ: np.ndarray, reach: float) -> float:
    """The distance of point ``p`` from the occupied squares (``inf`` beyond ``reach``)."""
    centres = squares_near(grid, occ, p - reach, p + reach)
    if not len(centres):
        return np.inf
    q = np.maximum(np.abs(p - centres) - grid.resolution / 2, 0.0)
    d = float(np.hypot(q[:, 0], q[:, 1]).min())
    return d if d < reach else np.inf


def measure(raw: np.ndarray, kept: np.ndarray, grid, occ: np.ndarray, floor: float) -> dict:
    """The straightened route ``raw[kept]`` against ``floor`` and against the path ``raw``:
    how far it comes inside the floor (its ends held to what the start and goal keep), how far
    a piece comes inside both the floor and the stretch it replaces, and where."""
    reach = floor + 2 * grid.resolution
    idx = np.flatnonzero(kept)
    pts = raw[idx]
    rooms = segment_rooms(pts, grid, occ, reach)
    own = segment_rooms(raw, grid, occ, reach)
    start, goal = (point_room(p, grid, occ, reach) for p in (pts[0], pts[-1]))
    need, own_need = np.full(len(rooms), floor), np.full(len(own), floor)
    need[0] = own_need[0] = min(floor, start)
    need[-1], own_need[-1] = min(need[-1], goal), min(own_need[-1], goal)
    stretch = np.array([min(floor, own[i:j].min()) for i, j in zip(idx[:-1], idx[1:])])
    short, cut = need - rooms, stretch - rooms
    k = int(cut.argmax())
    return {"floor": floor, "least": float(rooms.min()), "shortfall": max(float(short.max()), 0.0),
            "path_least": float(own.min()),
            "path_shortfall": max(float((own_need - own).max()), 0.0),
            "cut": max(float(cut[k]), 0.0), "piece": [pts[k].tolist(), pts[k + 1].tolist()],
            "pieces": len(rooms), "nodes": len(raw)}


@dataclass
class Recorder:
    """Every grid route planned while it is installed: the call's floor and cells, the path
    ``_simplify`` was given and which of its points it kept (the outermost call's; a search
    between the cells plans on a grid of its own inside it)."""

    calls: list[dict] = field(default_factory=list)
    depth: int = 0
    last: tuple[np.ndarray, np.ndarray] | None = None

    def install(self) -> list[tuple[object, str, object]]:
        grid_route, simplify = route_mod.grid_route, route_mod._simplify

        def recorded_simplify(points, *a, **kw):
            out = simplify(points, *a, **kw)
            kept = np.zeros(len(points), dtype=bool)
            j = 0
            for i, p in enumerate(points):            # out is points[keep], in order
                if j < len(out) and np.array_equal(p, out[j]):
                    kept[i], j = True, j + 1
            self.last = (np.array(points), kept)
            return out

        def recorded_route(static, start, goal, clearance, cell=6.0, minimum=None,
                           occupied=None, **kw):
            self.depth += 1
            try:
                r = grid_route(static, start, goal, clearance, cell, minimum, occupied, **kw)
                if self.depth == 1 and self.last is not None:
                    occ = static.grid.occupied if occupied is None else occupied
                    floor = clearance if minimum is None else min(minimum, clearance)
                    self.calls.append({"grid": static.grid, "occ": occ.copy(), "floor": floor,
                                       "raw": self.last[0], "kept": self.last[1],
                                       "replan": bool(kw.get("leave", 0.0))})
            finally:
                self.depth -= 1
                if not self.depth:
                    self.last = None
            return r

        patched = [(route_mod, "_simplify", recorded_simplify)]
        patched += [(m, "grid_route", recorded_route) for m in (route_mod, loop, knowledge)]
        old = [(m, name, getattr(m, name)) for m, name, _ in patched]
        for m, name, new in patched:
            setattr(m, name, new)
        return old

    def take(self) -> list[dict]:
        out = [measure(c["raw"], c["kept"], c["grid"], c["occ"], c["floor"]) | {
            "replan": c["replan"]} for c in self.calls]
        del self.calls[:]
        return out


def worlds(args) -> list[tuple[str, object]]:
    out: list[tuple[str, object]] = []
    for path in sorted((HERE.parent / "worlds").glob("*.yaml")):
        out.append(("shipped", load_world(path)))
    if args.mrpb.is_dir():
        for name in (*mrpb.COMPLETE, *mrpb.PARTIALLY_UNKNOWN):
            out += [("mrpb", w) for w in mrpb.scenario_worlds(args.mrpb, name)]
    else:
        print(f"no MRPB maps in {args.mrpb}: MRPB left out", file=sys.stderr)
    for s in range(args.seed, args.seed + args.barn):
        out.append(("barn-known", barn.world_of(barn.field(s, *barn.difficulty(s)), known=True)))
    return out


def report(suite: str, name: str, m: dict) -> None:
    if m["shortfall"] <= TOL and m["cut"] <= TOL:
        return
    (ax, ay), (bx, by) = m["piece"]
    when = "a replan" if m["replan"] else "the route"
    print(f"{suite:10s} {name}: {when} keeps {m['least']:.2f} in of {m['floor']:.2f} "
          f"(short by {m['shortfall']:.2f}); its path before straightening keeps "
          f"{m['path_least']:.2f}; straightening cuts inside by {m['cut']:.2f} at "
          f"({ax:.1f}, {ay:.1f})-({bx:.1f}, {by:.1f})")


@guarded
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mrpb", type=Path, default=MRPB_DIR, help="MRPB 1.0's maps and tests")
    ap.add_argument("--barn", type=count, default=20, help="BARN fields (20)")
    ap.add_argument("--seed", type=int, default=1000, help="the first BARN field's seed (1000)")
    ap.add_argument("--drive", default=None, help="run MRPB's tests with this planner too")
    ap.add_argument("--json", type=writable, default=None,
                    help="write every route's figures here")
    args = ap.parse_args(argv)
    if args.drive is not None:
        # said now, not as a traceback at MRPB's first test after the routes of every world
        if args.drive not in PLANNERS:
            raise unknown("planner", args.drive, PLANNERS)
        if not args.mrpb.is_dir():
            raise MitosError(f"`--drive {args.drive}` drives MRPB's tests, and MRPB 1.0's maps "
                             f"are not in `{args.mrpb}`",
                             hint="give their folder with `--mrpb DIR` (by default "
                                  "../shared/maps/mrpb beside the repository)")
    rec = Recorder()
    old = rec.install()
    rows: list[dict] = []
    try:
        for suite, w in worlds(args):
            del rec.calls[:]
            try:
                scene = prepare(w)
            except MitosError as exc:
                print(f"{w.name}: no route ({exc})", file=sys.stderr)
                continue
            for agent, m in zip(w.agents, rec.take()):
                report(suite, w.name, m)
                rows.append({"suite": suite, "world": w.name, "agent": agent.name,
                             "asked": clearances(w, agent)[0]} | m)
            if args.drive and suite == "mrpb":
                simulate(w, make_planner(args.drive, w), w.seed, scene=scene)
                for m in rec.take():
                    report("replan", w.name, m)
                    rows.append({"suite": "replan", "world": w.name} | m)
    finally:
        for m, name, f in old:
            setattr(m, name, f)
    for suite in dict.fromkeys(r["suite"] for r in rows):
        mine = [r for r in rows if r["suite"] == suite]
        short = [r["shortfall"] for r in mine if r["shortfall"] > TOL]
        cut = [r["cut"] for r in mine if r["cut"] > TOL]
        raw = [r for r in mine if r["path_shortfall"] > TOL]
        print(f"{suite}: {len(mine)} routes, {len(short)} inside their least clearance"
              + (f" (by up to {max(short):.2f} in)" if short else "")
              + f", {len(cut)} cut inside by straightening"
              + (f" (by up to {max(cut):.2f} in)" if cut else "")
              + f"; {len(raw)} whose path before straightening is inside it")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1), encoding="utf-8")
    return 1 if any(r["cut"] > TOL for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
