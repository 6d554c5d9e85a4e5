"""Large maps: time and peak memory of a run on a ROS map of 2,000 x 2,000 and 4,000 x 4,000
pixels (a 100 m and a 200 m floor at 5 cm a pixel), against another revision in the same run.

    python benchmarks/bench_bigmap.py                       # this tree alone
    python benchmarks/bench_bigmap.py --against 91e712d     # and that revision's, alternated
    python benchmarks/bench_bigmap.py --sizes 4000 --rounds 2

The maps are the packaged office map (`worlds/maps/mrpb_office02.pgm`, 600 x 600) tiled, its
bottom-left tile where the office world's start and goal are, written to a temporary
directory. For each size and tree, each in a fresh process (its peak resident memory is the
process's own): **one run** of the office world on it (5 simulated seconds: the map read,
the route planned, the robot's map and its replanning), **no way**: a goal three tiles away
that no corridor reaches (the search visits every node it can before it says so), and
**8 runs** (`run_many`, one worker: a lockstep batch, whose robots each keep a map). Wall
time of the process (best of ``--rounds``) and its peak resident memory (the largest); the
8 runs must give the same summaries in both trees.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from options import ROOT, guarded, positive_int, revision
from revision import differs

TASK = r"""
import json, sys, hashlib
sys.path.insert(0, sys.argv[1])
from mitos_cli.sim.worldfile import load_world
from mitos_cli.sim.loop import simulate
from mitos_cli.sim.runs import run_many
from mitos_cli.errors import MitosError
kind, path = sys.argv[2], sys.argv[3]
try:
    if kind == "runs":
        got = run_many([load_world(__import__("pathlib").Path(path))], runs=8, seed=1, workers=1)
        print(hashlib.sha256(json.dumps(got.to_json(), sort_keys=True).encode()).hexdigest())
    else:
        print(simulate(load_world(__import__("pathlib").Path(path))).outcome)
except MitosError as exc:
    print(exc.message.split(":")[0])
"""


def tiled(into: Path, n: int) -> None:
    """``big{n}.pgm`` / ``.yaml`` and the worlds ``w{n}.yaml`` (to the office's goal) and
    ``far{n}.yaml`` (to a goal no corridor reaches) in ``into``."""
    src = (ROOT / "worlds" / "maps" / "mrpb_office02.pgm").read_bytes()
    tile = np.frombuffer(src[-600 * 600:], np.uint8).reshape(600, 600)
    big = np.tile(tile, (n // 600 + 1, n // 600 + 1))[-n:, :n]
    (into / f"big{n}.pgm").write_bytes(f"P5\n{n} {n}\n255\n".encode() + big.tobytes())
    (into / f"big{n}.yaml").write_text(f"image: big{n}.pgm\nresolution: 0.05\norigin: "
                                       "[-15.0, -15.0, 0.0]\nnegate: 0\noccupied_thresh: "
                                       "0.65\nfree_thresh: 0.196\n")
    office = (ROOT / "worlds" / "office.yaml").read_text()
    world = office.replace("maps/mrpb_office02.yaml", f"big{n}.yaml") \
        .replace("time_limit: 120", "time_limit: 5")
    (into / f"w{n}.yaml").write_text(world)
    (into / f"far{n}.yaml").write_text(world.replace("q_goal: {x: -40, y: 320",
                                                     "q_goal: {x: 2322, y: 2682"))


@guarded
def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=_sizes, default="2000,4000",
                    help="map sides in pixels, comma-separated, each 1,700 to 8,000")
    ap.add_argument("--rounds", type=positive_int, default=1)
    ap.add_argument("--against", type=revision, default=None)
    args = ap.parse_args(argv)
    sizes = args.sizes
    with tempfile.TemporaryDirectory() as tmp:
        trees = {"this tree": ROOT}
        if args.against:
            theirs = Path(tmp) / "rev"
            theirs.mkdir()
            archive = subprocess.run(["git", "-C", str(ROOT), "archive", args.against,
                                      "mitos_cli", "grammar", "rulebases", "worlds"],
                                     check=True, capture_output=True).stdout
            subprocess.run(["tar", "-x", "-C", str(theirs)], input=archive, check=True)
            trees[args.against] = theirs
        print(f"{sys.version.split()[0]}, numpy {np.__version__}, {os.cpu_count()} CPUs, "
              f"load average {os.getloadavg()[0]:.2f} at start")
        for n in sizes:
            tiled(Path(tmp), n)
            print(f"\n{n} x {n} pixels ({n * 0.05:g} m square)")
            for kind, world in (("one run", f"w{n}.yaml"), ("no way", f"far{n}.yaml"),
                                ("runs", f"w{n}.yaml")):
                best: dict[str, tuple[float, float, str]] = {}
                for _ in range(args.rounds):          # the trees alternated, round by round
                    for name, tree in trees.items():
                        got = _one(tree, kind, Path(tmp) / world)
                        old = best.get(name)
                        best[name] = got if old is None else (min(old[0], got[0]),
                                                              max(old[1], got[1]), got[2])
                answers = {b[2] for b in best.values()}
                label = "8 runs" if kind == "runs" else kind
                for name, (wall, peak, answer) in best.items():
                    shown = "" if kind == "runs" else f", {answer}"
                    print(f"   {label:8s} {name:>12s}: {wall:6.2f} s, peak {peak:6.0f} MB{shown}")
                if len(trees) > 1:
                    if len(answers) > 1:         # timed on the same work, or not at all
                        raise differs(f"the {label} of {n} x {n} pixels", args.against)
                    mine, theirs = best.values()
                    print(compared(args.against, mine[:2], theirs[:2]))
        print(f"\nload average {os.getloadavg()[0]:.2f} at the end")


def compared(rev: str, mine: tuple[float, float], theirs: tuple[float, float]) -> str:
    """The line under two trees' figures, ``(wall s, peak MB)`` each: ratios, not "faster",
    which read "0.84x faster" where the other tree was the faster one."""
    return (f"   {'':8s} {'':>12s}  {rev} / this tree: time {theirs[0] / mine[0]:.2f}x, "
            f"peak memory {theirs[1] / mine[1]:.2f}x, same results")


#: The least map side: the goal of "no way" (2322, 2682 in) is pixel (1480, 1663) from the
#: map's corner; on a smaller map that goal lies outside it, and "no way" timed the refusal of
#: a goal off the map, not the search it is there to time.
LEAST = 1700


def _sizes(text: str) -> list[int]:
    """``--sizes``: map sides of :data:`LEAST` to 8,000 pixels (the largest map read)."""
    try:
        sizes = [int(s) for s in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"`{text}` is not a list of whole numbers") from None
    if not sizes or not all(LEAST <= s <= 8000 for s in sizes):
        raise argparse.ArgumentTypeError(f"`{text}`: each size from {LEAST:,} (the \"no way\" "
                                         "goal lies that far out) to 8,000")
    return sizes


def _one(tree: Path, kind: str, world: Path) -> tuple[float, float, str]:
    task = "runs" if kind == "runs" else "one"
    t = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-c", TASK, str(tree), task, str(world)],
                            stdout=subprocess.PIPE, text=True)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t
    out = proc.stdout.read().strip() if proc.stdout else ""
    if status != 0:
        raise SystemExit(f"the {kind} task failed in {tree}: exit status {status}")
    return wall, usage.ru_maxrss / 1024, out


if __name__ == "__main__":
    sys.exit(main())
