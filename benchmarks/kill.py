"""Kill tests: ``kill -9`` a teaching session while it changes and saves, then resume it.

Run from the repository root (one command)::

    python benchmarks/kill.py --trials 50

Each trial starts ``mitos teach`` on a copy of the packaged rule base with a lesson that, six
times, tells a new rule, gives a correction, adapts one epoch and saves (so every save changes
both the rule file and its term set); kills it with ``SIGKILL`` at a random moment; and checks

- the saved files (after the leftovers of an interrupted save are dealt with, as the next run
  does) are the original pair, or exactly the pair of one save of an uninterrupted reference
  run: never a rule file of one save beside the term set of another, no temporary file left;
- ``mitos teach --resume`` reads the journal; every change the session had acknowledged
  before the kill (each lesson line echoed after it) is there, and the changes are a prefix of
  the reference run's.

and, with ``--sweep``, kills ``mitos compare -o DIR`` (2 T-norms x 4 runs on a small world) at a
random moment, runs ``--resume`` (the command again when the kill came before the study
began), and checks that ``results.csv`` then holds every run once,
that the rows written before the kill are untouched and that the rows are, bit for bit, those of
an uninterrupted sweep.

The test suite runs a few trials (``tests/test_reliability.py``); the figures in
``docs/reliability.md`` come from this command.
"""

from __future__ import annotations

import argparse
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))          # this tree's mitos_cli, here and in the killed runs
from options import guarded, positive_int  # noqa: E402

ENV = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
ROUNDS = 6


def lesson() -> str:
    out = []
    for k in range(ROUNDS):
        out += [f"k{k}: if road is WIDE and size is SMALL_SZ and position is LEFT "
                f"then steering is {40 + k}",
                f"correct road={70 + k} size=45 position=4 -> steering={100 + k}",
                "adapt epochs 1 rate 0.5", "save"]
    return "\n".join(out) + "\n"


CHANGES = {0, 1, 2}            # per round: which lines journal a change (save is not one)


def setup(work: Path) -> Path:
    rb = work / "rb"
    shutil.copytree(ROOT / "rulebases", rb, ignore=shutil.ignore_patterns("lessons"))
    (work / "k.lesson").write_text(lesson())
    return rb


def reference(work: Path) -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
    """The saved set (rule file and term sets) after each save, and the journal's (op, line) changes, of an
    uninterrupted run (in this process)."""
    from mitos_cli.teach.journal import Journal
    from mitos_cli.teach.lesson import commands
    from mitos_cli.teach.session import Session

    rb = setup(work)
    os.chdir(work)
    session = Session(rb / "mitos.rules", journal=Journal.create(work / "ref"),
                      save_as=work / "out.rules", out=lambda s: None)
    pairs = []
    for _, line in commands(lesson()):
        session.run(line)
        if line == "save":
            pairs.append(_pair(work))
    changes = [(e["op"], e.get("line")) for e in session.journal.active()]
    return pairs, changes


def _pair(work: Path) -> tuple[tuple[str, str], ...]:
    """The saved set: the rule file and its term sets (``out.*``), by name."""
    return tuple((p.name, p.read_text()) for p in sorted(work.glob("out.*"))
                 if not p.name.endswith(".tmp"))


def trial(work: Path, pairs, changes, delay: float) -> dict:
    """One kill at ``delay`` seconds after the start; raises AssertionError on a violation."""
    from mitos_cli.errors import LessonError
    from mitos_cli.fileio import finish_saves
    from mitos_cli.teach.journal import Journal, find_session
    from mitos_cli.teach.session import Session

    setup(work)
    env = dict(ENV, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen([sys.executable, "-m", "mitos_cli", "teach", "rb/mitos.rules",
                             "--lesson", "k.lesson", "--save-as", "out.rules"], cwd=work,
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env)
    time.sleep(delay)
    proc.send_signal(signal.SIGKILL)
    echoed = proc.communicate()[0].decode(errors="replace")
    finished = proc.returncode == 0
    # the next run: finish or drop an interrupted save, then the files must be one whole pair
    finish_saves(work / "out.rules")
    leftovers = [p.name for p in work.iterdir() if p.name.endswith(".tmp")]
    assert not leftovers, f"temporary files left: {leftovers}"
    if _pair(work):
        assert _pair(work) in pairs, "the saved rule file and term set are of different saves"
        saved = pairs.index(_pair(work)) + 1
    else:
        saved = 0
    # resume: every acknowledged change is in the journal, in the reference's order
    done = max(0, echoed.count("k.lesson:") - (0 if finished else 1))   # lines completed
    acknowledged = sum(1 for i in range(done) if i % 4 in CHANGES)
    os.chdir(work)
    try:
        journal = Journal.open(find_session(None, work))
    except LessonError as exc:            # killed before the session's first entry
        assert acknowledged == 0, f"no session to resume ({exc.message}), though changes " \
                                  f"were acknowledged"
        return {"saved": saved, "changes": 0, "torn": False}
    session = Session.resume(journal, out=lambda s: None)
    got = [(e["op"], e.get("line")) for e in session.journal.active()]
    assert got == changes[:len(got)], "the resumed changes differ from the reference's"
    assert len(got) >= acknowledged, f"{acknowledged - len(got)} acknowledged change(s) lost"
    return {"saved": saved, "changes": len(got), "torn": journal.skipped_tail}


def timing(work: Path) -> tuple[float, float]:
    """When an uninterrupted run here echoes its first lesson line, and when it ends (s)."""
    work.mkdir()
    setup(work)
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "mitos_cli", "teach", "rb/mitos.rules",
                             "--lesson", "k.lesson", "--save-as", "out.rules"], cwd=work,
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                            env=dict(ENV, PYTHONUNBUFFERED="1"))
    start = None
    for raw in proc.stdout:
        if start is None and b"k.lesson:" in raw:
            start = time.perf_counter() - t0
    proc.wait()
    return start or 0.0, time.perf_counter() - t0


def campaign(trials: int, seed: int, log=print) -> list[dict]:
    rng = random.Random(seed)
    base = Path(tempfile.mkdtemp(prefix="mitos-kill-"))
    cwd = os.getcwd()
    try:
        pairs, changes = reference(base / "reference")
        start, span = timing(base / "whole")
        results = []
        for i in range(trials):
            work = base / f"t{i}"
            work.mkdir()
            delay = rng.uniform(start, span)
            result = trial(work, pairs, changes, delay)
            results.append(result)
            log(f"trial {i + 1}: killed at {delay:.2f} s (lesson {start:.2f}-{span:.2f} s): "
                f"save {result['saved']} on disk, {result['changes']} changes resumed"
                + (" (torn last line dropped)" if result["torn"] else ""))
            os.chdir(cwd)
            shutil.rmtree(work, ignore_errors=True)
        return results
    finally:
        os.chdir(cwd)
        shutil.rmtree(base, ignore_errors=True)


# ---- sweeps --------------------------------------------------------------------------------------

TINY = (Path(__file__).resolve().parents[1] / "tests" / "data" / "tiny.yaml").read_text()
SWEEP_RUNS = 8


def _sweep(work: Path, resume: bool = False) -> list[str]:
    args = [sys.executable, "-m", "mitos_cli", "compare", "tiny.yaml", "--and", "min,product",
            "--planner", "fuzzy", "--runs", str(SWEEP_RUNS // 2), "-j", "1", "-o", "out",
            "--no-plots"]
    return args + (["--resume"] if resume else [])


def _rows(work: Path) -> list[str]:
    path = work / "out" / "results.csv"
    if not path.exists():
        return []
    lines = path.read_text().split("\n")
    return [line for line in lines[1:-1] if line]      # whole rows only


def sweep_trial(work: Path, whole: list[str], delay: float) -> dict:
    (work / "tiny.yaml").write_text(TINY)
    proc = subprocess.Popen(_sweep(work), cwd=work, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, env=ENV)
    time.sleep(delay)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    before = _rows(work)
    # killed before the study began (no study.json yet): there is nothing to resume, and
    # --resume refuses a directory that holds no study; the sweep is started again
    began = any((work / "out" / name).exists() for name in ("study.json", "results.csv"))
    r = subprocess.run(_sweep(work, resume=began), cwd=work, capture_output=True, text=True,
                       env=ENV)
    assert r.returncode == 0, r.stderr[-500:]
    after = _rows(work)
    assert after[:len(before)] == before, "a row written before the kill changed"
    assert len(after) == SWEEP_RUNS, f"{len(after)} rows, expected {SWEEP_RUNS}"
    assert sorted(after) == sorted(whole), "the rows differ from an uninterrupted sweep's"
    return {"before": len(before)}


def sweep_campaign(trials: int, seed: int, log=print) -> list[dict]:
    rng = random.Random(seed + 1)
    base = Path(tempfile.mkdtemp(prefix="mitos-sweep-"))
    try:
        ref = base / "whole"
        ref.mkdir()
        (ref / "tiny.yaml").write_text(TINY)
        t0 = time.perf_counter()
        subprocess.run(_sweep(ref), cwd=ref, capture_output=True, check=True, env=ENV)
        span = time.perf_counter() - t0
        whole = _rows(ref)
        results = []
        for i in range(trials):
            work = base / f"t{i}"
            work.mkdir()
            delay = rng.uniform(0.0, span)
            result = sweep_trial(work, whole, delay)
            results.append(result)
            log(f"sweep {i + 1}: killed at {delay:.2f} s of {span:.2f} s with "
                f"{result['before']} of {SWEEP_RUNS} rows written; resumed to {SWEEP_RUNS}")
            shutil.rmtree(work, ignore_errors=True)
        return results
    finally:
        shutil.rmtree(base, ignore_errors=True)


@guarded
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--trials", type=positive_int, default=50)
    ap.add_argument("--sweep", action="store_true", help="kill sweeps instead of teaching")
    ap.add_argument("--seed", type=int, default=20261201)
    args = ap.parse_args(argv)
    if args.sweep:
        results = sweep_campaign(args.trials, args.seed)
        counts = sorted({r["before"] for r in results})
        print(f"\n{len(results)} kills, no violation; rows written before the kill: "
              + ", ".join(f"{c} x{sum(r['before'] == c for r in results)}" for c in counts))
        return 0
    results = campaign(args.trials, args.seed)
    saves = sorted({r["saved"] for r in results})
    print(f"\n{len(results)} kills, no violation; saved state on disk: "
          + ", ".join(f"save {s} x{sum(r['saved'] == s for r in results)}" for s in saves)
          + f"; torn last journal lines dropped: {sum(r['torn'] for r in results)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
