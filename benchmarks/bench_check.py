"""`mitos check` on many distinct terms that all overlap: random triangles of one variable on
[0, 100], feet in [0, 20] and [80, 100], peaks in [30, 70] (seeded), one rule. Every two
edges cross, so a variable of ``t`` terms has about ``2 t^2`` breakpoints: what the coverage
and ``indistinct`` findings measure (docs/reliability.md, "Many distinct terms that all
overlap").

    python benchmarks/bench_check.py                          # 100, 300, 600 and 2,000 terms
    python benchmarks/bench_check.py --sizes 100,300 --role output
    python benchmarks/bench_check.py --sizes 100,200,300 --step     # and one crisp step
    python benchmarks/bench_check.py --against OTHER/bin/mitos  # the same files, both timed
    python benchmarks/bench_check.py --write DIR               # only write the files

Each size is one run of ``mitos check`` as a subprocess (this tree's, ``python -m
mitos_cli``): wall and CPU time (user + system, what a loaded machine changes least) and the
child's largest resident set. The scaling exponent between two sizes is ``log(t2 / t1) /
log(n2 / n1)`` of the CPU times (start-up, about 0.3 s, included). With ``--against`` the same
files are checked by that command too, alternated with this tree's, and the two reports must
be the same to the byte (stdout and exit code), else the script says where they differ and
exits 1.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from options import ROOT, guarded, positive_int

UNIVERSE = (0.0, 100.0)


def triangles(n: int, seed: int) -> np.ndarray:
    """``n`` random triangles ``[n, 3]``: left foot, peak, right foot (3 decimals)."""
    rng = np.random.default_rng(seed)
    left = rng.uniform(0.0, 20.0, n)
    peak = rng.uniform(30.0, 70.0, n)
    right = rng.uniform(80.0, 100.0, n)
    return np.round(np.stack([left, peak, right], axis=1), 3)


def write_case(folder: Path, n: int, seed: int, role: str, step: bool = False) -> Path:
    """The rule file and term set of ``n`` terms of one ``role`` variable (and a crisp step,
    ``S``, if ``step``); the rule file."""
    tri = triangles(n, seed)
    terms = "\n".join(f"      T{k}: {{shape: triangle, points: [{a:g}, {b:g}, {c:g}]}}"
                      for k, (a, b, c) in enumerate(tri))
    if step:
        terms += "\n      S: {shape: trapezoid, points: [50, 50, 60, 70]}"
    few = "      LO: {shape: triangle, points: [0, 0, 100]}\n" \
          "      HI: {shape: triangle, points: [0, 100, 100]}"
    many_in, many_out = (terms, few) if role == "input" else (few, terms)
    (folder / f"t{n}.terms.yaml").write_text(
        "variables:\n"
        "  x:\n    role: input\n    universe: [0, 100]\n    terms:\n" + many_in + "\n"
        "  y:\n    role: output\n    universe: [0, 100]\n    default: 50\n    terms:\n"
        + many_out + "\n")
    rules = folder / f"t{n}.rules"
    first_in = "T0" if role == "input" else "LO"
    first_out = "T0" if role == "output" else "LO"
    rules.write_text(f'terms "t{n}.terms.yaml"\n\nbehavior b:\n'
                     f"    r0: if x is {first_in} then y is {first_out}\nend\n")
    return rules


def run(command: list[str], rules: Path, env: dict[str, str]
        ) -> tuple[float, float, float, int, bytes]:
    """Wall and CPU seconds, largest resident set (MB), exit code and stdout of one check."""
    t = time.perf_counter()
    proc = subprocess.Popen([*command, "check", str(rules)], stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, env={**env, "MITOS_CACHE_DIR": "off"})
    out = proc.stdout.read() if proc.stdout else b""
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t
    proc.returncode = os.waitstatus_to_exitcode(status)
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0, proc.returncode, out


def command(text: str) -> str:
    """``--against``: a command that runs (a path to a ``mitos`` or a name on ``PATH``),
    checked before the first size is timed, not met as a traceback after it."""
    if shutil.which(text) is None:
        raise argparse.ArgumentTypeError(f"`{text}` is not a command that runs (give the "
                                         "path of another tree's `mitos`)")
    return text


@guarded
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="100,300,600,2000",
                        help="numbers of terms, comma-separated (default 100,300,600,2000)")
    parser.add_argument("--seed", type=positive_int, default=11)
    parser.add_argument("--role", choices=("input", "output"), default="input",
                        help="the role of the variable with many terms (default input)")
    parser.add_argument("--step", action="store_true",
                        help="add a crisp step (a trapezoid with an upright edge) to the terms")
    parser.add_argument("--against", metavar="MITOS", type=command,
                        help="another `mitos` command to time on the same files")
    parser.add_argument("--write", metavar="DIR", help="write the files there and stop")
    args = parser.parse_args(argv)
    try:
        sizes = [positive_int(s) for s in args.sizes.split(",")]
    except argparse.ArgumentTypeError as e:
        parser.error(f"--sizes: {e}")
    if args.write:
        folder = Path(args.write)
        folder.mkdir(parents=True, exist_ok=True)
        for n in sizes:
            print(write_case(folder, n, args.seed, args.role, args.step))
        return 0
    ours = [sys.executable, "-m", "mitos_cli"]
    here = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(ROOT)] + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else []))}
    print(f"mitos check, {args.role} of n random overlapping triangles (seed {args.seed})"
          + (" and a crisp step" if args.step else "") + ", "
          f"one run each, load {os.getloadavg()[0]:.1f}")
    print(f"{'terms':>6} {'wall s':>8} {'CPU s':>7} {'MB':>6}" + (
        f" {'against wall':>12} {'CPU s':>7} {'MB':>6} {'CPU ratio':>9}" if args.against else "")
        + f" {'exponent (CPU)':>14}")
    failed = False
    last: tuple[int, float] | None = None
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            rules = write_case(Path(tmp), n, args.seed, args.role, args.step)
            wall, cpu, mb, code, out = run(ours, rules, here)
            line = f"{n:>6} {wall:>8.2f} {cpu:>7.2f} {mb:>6.0f}"
            if args.against:
                w2, cpu2, mb2, code2, out2 = run([args.against], rules, dict(os.environ))
                line += f" {w2:>12.2f} {cpu2:>7.2f} {mb2:>6.0f} {cpu2 / cpu:>8.1f}x"
                if (code, out) != (code2, out2):
                    failed = True
                    line += "  REPORTS DIFFER"
            if last is not None:
                line += f" {math.log(cpu / last[1]) / math.log(n / last[0]):>14.2f}"
            print(line, flush=True)
            last = (n, cpu)
    if failed:
        print("the reports differ from --against's (exit code or stdout)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
