"""What knowing less costs: simulated ticks per second of one robot among a few hundred
obstacles it does not know, the same run with them drawn on its map, a robot with no map, the
replanning world, and the route planner (exact distance transform + A*) on a real map.

    python benchmarks/bench_knowledge.py            # about a minute

Each figure is the best of three runs in this process (the machine is shared; the best is the
least disturbed). The aim: a run with a few hundred unknown obstacles keeps at least 100 ticks
per second of wall time on one core.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from options import guarded  # noqa: E402

from mitos_cli.sim.loop import prepare, simulate  # noqa: E402
from mitos_cli.sim.planner import FuzzyPlanner  # noqa: E402
from mitos_cli.sim.world import Obstacle  # noqa: E402
from mitos_cli.sim.worldfile import load_world  # noqa: E402

POLES = 300


def poles_world(known: bool):
    """A 3,000 in hall 100 in wide with ``POLES`` poles along both walls (not in the lane)."""
    base = load_world(ROOT / "worlds" / "corridor.yaml")
    from mitos_cli.sim.world import Corridor, Goal, Randomise

    poles = tuple(Obstacle(f"p{i}", "circle", 40.0 + 20.0 * (i // 2),
                           (-38.0 if i % 2 else 38.0), radius=4.0, known=known)
                  for i in range(POLES))
    agent = replace(base.agents[0], goal=Goal(3000.0, 0.0, 12.0))
    return replace(base, name=f"{POLES} poles ({'known' if known else 'unknown'})",
                   corridors=(Corridor(((0.0, 0.0), (3100.0, 0.0)), 100.0),),
                   obstacles=poles, agents=(agent,), time_limit=30.0,
                   randomise=Randomise())       # the corridor's jitter names its box, gone here


def best_rate(world, repeats: int = 3) -> tuple[float, object]:
    planner = FuzzyPlanner(None, world.behavior)
    best, res = 0.0, None
    for _ in range(repeats):
        scene = prepare(world)
        t = time.perf_counter()
        res = simulate(world, planner, scene=scene)
        best = max(best, res.ticks / (time.perf_counter() - t))
    return best, res


@guarded
def main(argv: list[str] | None = None) -> None:
    argparse.ArgumentParser(description=__doc__,
                            formatter_class=argparse.RawDescriptionHelpFormatter).parse_args(argv)
    print(f"machine: {platform.processor() or platform.machine()}, Python "
          f"{platform.python_version()}, one process")
    print(f"{'run':44} {'ticks':>6} {'ticks/s':>8}  outcome  replans")
    corridor = load_world(ROOT / "worlds" / "corridor.yaml")
    detour = load_world(ROOT / "worlds" / "detour.yaml")
    rows = [("corridor.yaml (the map only: the baseline)", corridor),
            (f"{POLES} unknown poles", poles_world(False)),
            (f"{POLES} known poles (drawn on its map)", poles_world(True)),
            ("detour.yaml (shut way, one replan)", detour),
            ("detour.yaml with `given: none`", replace(detour, knows="none"))]
    for label, world in rows:
        rate, res = best_rate(world)
        print(f"{label:44} {res.ticks:>6} {rate:>8.0f}  {res.outcome:8} "
              f"{res.metrics['replans']:>7}")
    office = load_world(ROOT / "worlds" / "office.yaml")
    times = []
    for _ in range(3):
        t = time.perf_counter()
        prepare(office)
        times.append(time.perf_counter() - t)
    print(f"route on office.yaml (600 x 600 cells: walls, distance transform, A*): "
          f"{min(times) * 1000:.0f} ms")


if __name__ == "__main__":
    sys.exit(main())
