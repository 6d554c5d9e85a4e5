"""`mitos compare` end to end on a tiny world: table, CSV, report, executors, kill + --resume."""

from __future__ import annotations

import csv
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mitos_cli.cli.app import main
from mitos_cli.study import Study, make_choices, run_study
from mitos_cli.study.store import ResultStore

ROOT = Path(__file__).resolve().parent.parent

TINY = (Path(__file__).parent / "data" / "tiny.yaml").read_text()   # also benchmarks/kill.py's


@pytest.fixture(scope="module")
def tiny(tmp_path_factory) -> str:
    path = tmp_path_factory.mktemp("worlds") / "tiny.yaml"
    path.write_text(TINY)
    return str(path)


class Ran:
    def __init__(self, code: int, out: str, err: str) -> None:
        self.exit_code, self.stdout, self.stderr = code, out, err
        self.output = out + err


def run_compare(capsys, *args) -> Ran:
    """``mitos compare ARGS`` in this process: exit code, stdout, stderr."""
    try:
        main(["compare", *map(str, args)])
        code = 0
    except SystemExit as exc:
        code = exc.code or 0
    out, err = capsys.readouterr()
    return Ran(code, out, err)


@pytest.fixture
def compare(capsys):
    """:func:`run_compare` with this test's ``capsys``."""
    return lambda *args: run_compare(capsys, *args)


def read_rows(directory) -> list[dict]:
    with open(Path(directory) / "results.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def test_compare_writes_table_csv_and_report(tiny, tmp_path, compare):
    out = tmp_path / "study"
    r = compare(tiny, "--and", "min,product", "--runs", 2, "-o", out, "-j", 1)
    assert r.exit_code == 0, r.output
    assert "Outcomes per world and choice" in r.stdout and "Ranking" in r.stdout
    header = next(line for line in r.stdout.splitlines() if "success" in line)
    assert all(word in header for word in ("collision", "timeout", "stuck"))   # sum to 100%
    assert header.split()[-3:] == ["replans", "backed", "out"]
    for label in ("fuzzy and=min", "fuzzy and=product", "potential_field"):
        assert label in r.output
    rows = read_rows(out)
    assert len(rows) == 6 and {row["outcome"] for row in rows} <= {
        "success", "collision", "timeout", "stuck"}
    report = (out / "report.md").read_text()
    assert "Paired comparison" in report and "| fuzzy and=min |" in report
    assert "| steering TV (deg) * | replans | backed out |" in report
    assert (out / "success.png").stat().st_size > 1000
    assert (out / "clearance.png").stat().st_size > 1000
    # paired: every choice drove run r with the same seed
    seeds = {}
    for row in rows:
        seeds.setdefault(row["run"], set()).add(row["seed"])
    assert all(len(s) == 1 for s in seeds.values())


def test_the_note_under_the_ranking_is_one_line_in_a_file(tiny, tmp_path, compare):
    """Piped or into a file the table is as wide as it needs, but the note under the ranking
    was wrapped at that width, splitting a choice's label over two lines (`fuzzy` /
    `and=lukasiewicz`) for whoever reads it with grep."""
    norms = "min,product,lukasiewicz,einstein,hamacher,nilpotent_minimum"
    r = compare(tiny, "--and", norms, "--planner", "fuzzy", "--runs", 1, "-o",
                tmp_path / "s", "-j", 1, "--no-plots")
    assert r.exit_code == 0, r.output
    lines = r.stdout.splitlines()
    note = next(i for i, line in enumerate(lines) if "not distinguishable" in line)
    assert lines[note].startswith("5 of 5 choices are not distinguishable from the leader")
    assert len(lines[note]) > max(len(line) for line in lines[:note])    # wider than the tables
    leader = lines[note].split("leader (")[1].split(")")[0]
    assert sorted(lines[note].split("): ")[1].split(", ")) == \
        sorted(f"fuzzy and={n}" for n in norms.split(",") if f"fuzzy and={n}" != leader)
    assert lines[note + 1:] == []


def test_each_row_has_the_replans_and_backouts_of_its_run(tiny, tmp_path, compare):
    """results.csv had no replans or backouts: a row carries its run's, the very figures
    `mitos simulate WORLD --seed SEED --randomise` prints for it."""
    from mitos_cli.sim import load_world, simulate
    from mitos_cli.sim.planner import make_planner

    out = tmp_path / "study"
    r = compare(tiny, "--planner", "dwa", "--runs", 2, "-o", out, "-j", 1, "--no-plots")
    assert r.exit_code == 0, r.output
    world = load_world(tiny)
    for row in read_rows(out):
        alone = simulate(world, make_planner("dwa", world), int(row["seed"]), randomise=True)
        assert (row["outcome"], float(row["time_s"]), int(row["replans"]),
                int(row["backouts"])) == (alone.outcome, alone.metrics["time_s"],
                                          alone.metrics["replans"], alone.metrics["backouts"])


def test_real_simulator_pool_equals_serial(tiny, tmp_path):
    study = Study([tiny], make_choices(["fuzzy", "potential_field"], ["einstein"], [], []),
                  runs=2, seed=5)
    serial = run_study(study, tmp_path / "serial", workers=1)
    pool = run_study(study, tmp_path / "pool", workers=2)
    assert serial.rows == pool.rows and len(serial.rows) == 4


def test_killed_sweep_resumes_without_recomputing(tiny, tmp_path):
    out = tmp_path / "killed"
    args = ["compare", tiny, "--and", "min,product", "--planner", "fuzzy", "--runs", "4",
            "-j", "1", "-o", str(out), "--no-plots"]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-m", "mitos_cli", *args], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    results = out / "results.csv"
    deadline = time.monotonic() + 60
    try:
        while time.monotonic() < deadline:
            if results.exists() and results.read_text().count("\n") >= 4:   # header + 3 rows
                break
            time.sleep(0.02)
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    before = ResultStore(out).load()
    assert 3 <= len(before) < 8, "the sweep should have been killed half-way"
    r = subprocess.run([sys.executable, "-m", "mitos_cli", *args, "--resume"], env=env,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert f"resuming: {len(before)} of 8 runs already in" in r.stderr
    assert f"{8 - len(before)} runs now, {len(before)} from before" in r.stderr
    after = ResultStore(out).load()
    keys = [(x["and"], x["run"]) for x in after]
    assert len(after) == 8 and len(set(keys)) == 8            # nothing ran twice
    assert after[:len(before)] == before                       # finished rows untouched


def _children(pid: int) -> set[int]:
    """The live processes whose parent is ``pid`` (Linux's /proc)."""
    found = set()
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            state, ppid = stat.read_text().rsplit(")", 1)[1].split()[:2]
        except (OSError, IndexError):
            continue                        # (ended while we looked)
        if int(ppid) == pid and state != "Z":
            found.add(int(stat.parent.name))
    return found


def _alive(pids: set[int]) -> set[int]:
    alive = set()
    for pid in pids:
        try:
            if Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z":
                alive.add(pid)
        except (OSError, IndexError):
            pass
    return alive


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds the workers in /proc")
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM], ids=["KILL", "TERM"])
def test_a_study_stopped_mid_run_lets_go_of_its_directory_at_once(tiny, tmp_path, compare, sig):
    """`kill -9` of a `compare` on a pool: its workers ran their chunks on, seconds, holding
    the directory's lock (a --resume at once: "`DIR` is in use by another study", exit 1)
    and printing the tracebacks of the pipes they found broken. A SIGTERM ended it so too,
    without a word of what was kept. Killed, the workers end with it; terminated, it stops as
    on Ctrl-C (exit 143)."""
    out = tmp_path / "killed"
    args = [tiny, "--planner", "fuzzy", "--and", "min,product", "--runs", "24", "-j", "2",
            "-o", str(out), "--no-plots"]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    log = tmp_path / "stderr.txt"
    with open(log, "w") as stderr:
        proc = subprocess.Popen([sys.executable, "-m", "mitos_cli", "compare", *args], env=env,
                                stdout=subprocess.DEVNULL, stderr=stderr)
    results = out / "results.csv"
    deadline = time.monotonic() + 60
    try:
        # the first choice's 24 runs are in: both workers are in the second's chunks
        while time.monotonic() < deadline and proc.poll() is None:
            if results.exists() and results.read_text().count("\n") >= 25:
                break
            time.sleep(0.01)
        workers = _children(proc.pid)
    finally:
        proc.send_signal(sig)
        code = proc.wait(timeout=60)
    gone = time.monotonic() + 1.0
    while _alive(workers) and time.monotonic() < gone:
        time.sleep(0.01)
    assert len(workers) >= 2 and not _alive(workers), "the workers ran on"
    before = ResultStore(out).load()
    assert 24 <= len(before) < 48, "the study should have been stopped half-way"
    said = log.read_text()
    if sig == signal.SIGKILL:
        assert code == -signal.SIGKILL and "Traceback" not in said
    else:
        assert code == 143, said
        assert f"interrupted: {len(before)} of 48 runs kept in {results}" in said
        assert f"--runs 24 --seed 1 -o {out} -j 2 --no-plots --resume" in said
    ran = compare(*args, "--resume")                # at once
    assert ran.exit_code == 0, ran.stderr
    assert f"{48 - len(before)} runs now, {len(before)} from before" in ran.stderr
    after = ResultStore(out).load()
    assert len({(x["and"], x["run"]) for x in after}) == len(after) == 48
    assert after[:len(before)] == before


def test_a_reader_that_stops_early_still_gets_the_report_written(tiny, tmp_path):
    """`mitos compare ... | head -1`: the tables went to stdout before report.md was written,
    so a reader that had gone ended the command before the study's report."""
    out = tmp_path / "piped"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-m", "mitos_cli", "compare", tiny, "--and", "min",
                             "--planner", "fuzzy", "--runs", "1", "-o", str(out), "--no-plots"],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    assert proc.stdout is not None
    proc.stdout.close()                                      # the reader is gone at once
    proc.wait(timeout=120)
    assert (out / "report.md").exists() and len(read_rows(out)) == 1


def test_existing_results_need_resume(tiny, tmp_path, compare):
    out = tmp_path / "s"
    assert compare(tiny, "--and", "min", "--planner", "fuzzy", "--runs", 1, "-o", out, "-j", 1,
                   "--no-plots").exit_code == 0
    r = compare(tiny, "--and", "min", "--planner", "fuzzy", "--runs", 1, "-o", out, "-j", 1)
    assert r.exit_code == 1 and "already holds 1 result" in r.stderr and "--resume" in r.stderr


def test_resume_of_a_directory_without_a_study_is_a_user_error(tiny, tmp_path, compare,
                                                                 monkeypatch):
    """`compare corridor --resume -o nosuchdir` exited 0: "5 runs now, 0 from before"."""
    monkeypatch.chdir(tmp_path)
    r = compare(tiny, "--and", "min", "--planner", "fuzzy", "--runs", 1, "-o", "nosuchdir",
                "--resume")
    assert r.exit_code == 1 and r.stdout == "" and not (tmp_path / "nosuchdir").exists()
    assert "study error: `nosuchdir` holds no study to resume" in r.stderr
    assert "leave out --resume to start a study there" in r.stderr


def test_an_output_that_is_a_file_is_refused_as_such(tiny, tmp_path, compare):
    afile = tmp_path / "afile"
    afile.write_text("mine\n")
    r = compare(tiny, "--and", "min", "--planner", "fuzzy", "--runs", 1, "-o", afile, "-j", 1)
    assert r.exit_code == 1 and f"`{afile}` is a file, not a directory" in r.stderr
    assert afile.read_text() == "mine\n"


@pytest.mark.parametrize("args, code, words", [
    (["worlds/corridr.yaml"], 1, "did you mean `worlds/corridor.yaml`"),
    (["TINY", "--and", "einstien"], 2, "unknown T-norm `einstien`"),
    # the unbounded sum is no S-norm: a name `--or` does not take, as `--and sum` (was exit 1)
    (["TINY", "--or", "sum"], 2, "the unbounded sum is a Mamdani aggregation only"),
    (["TINY", "--or", "max,unbounded_sum"], 2, "did you mean `bounded_sum`"),
    (["TINY", "--planner", "potential"], 2, "did you mean `potential_field`"),
    (["TINY", "--scheduler", "tcp://x:1"], 2, "--scheduler needs --executor dask"),
    # an empty address ran the study on this machine without a word, as if left out
    (["TINY", "--scheduler", ""], 2, "'--scheduler': must name something, not be empty"),
    (["TINY", "--executor", "dask", "--scheduler", " "], 2, "must name something, not be empty"),
    (["TINY", "--executor", "dsk"], 2, "did you mean `dask`"),
    (["TINY", "--behavior", "drve"], 1, "drive"),
    (["TINY", "TINY"], 2, "given twice"),
    (["TINY", "TINY_AGAIN"], 2, "given twice"),    # (another spelling: Study's exit 1)
    (["TINY", "--planner", "dwa", "--and", "product"], 2, "--and chooses the fuzzy planner's"),
    # an unknown planner is said as such, not as one without a fuzzy planner
    (["TINY", "--planner", "dwaa", "--and", "product"], 2, "unknown planner `dwaa`"),
    (["TINY", "--runs", "1000000"], 2, "a whole number from 1 to 100000, not `1000000`"),  # (no
    (["TINY", "-n", "1000000"], 2, "a whole number from 1 to 100000, not `1000000`"),  # memory)
])
def test_user_errors(tiny, tmp_path, compare, args, code, words):
    again = str(Path(tiny).parent / ".." / Path(tiny).parent.name / "tiny.yaml")
    r = compare(*[{"TINY": tiny, "TINY_AGAIN": again}.get(a, a) for a in args], "-o",
                tmp_path / "e")
    assert r.exit_code == code, r.output
    said = " ".join(r.output.replace("│", " ").split())    # (Rich's box wraps a long path)
    assert words in said, r.output
    assert not (tmp_path / "e" / "results.csv").exists()


def test_no_planner_is_a_usage_error(tiny, tmp_path, compare):
    r = compare(tiny, "--planner", ",", "-o", tmp_path / "e")
    assert r.exit_code == 2 and "name at least one planner" in r.output


def _approx(obj):
    if isinstance(obj, float):
        return pytest.approx(obj, rel=1e-9, abs=1e-12)
    if isinstance(obj, dict):
        return {k: _approx(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_approx(v) for v in obj]
    return obj


def test_compare_json_is_the_documented_object(tiny, tmp_path, monkeypatch, compare):
    """The --json schema (docs/study.md), golden: tests/data/compare_tiny.json."""
    import json
    import shutil

    monkeypatch.chdir(tmp_path)
    shutil.copy(tiny, "tiny.yaml")
    r = compare("tiny.yaml", "--and", "min,product", "--runs", 2, "-o", "st", "-j", 1,
                "--no-plots", "--json")
    assert r.exit_code == 0, r.output
    data = json.loads(r.stdout)
    golden = Path(__file__).parent / "data" / "compare_tiny.json"
    if os.environ.get("MITOS_UPDATE_GOLDEN"):
        golden.write_text(r.stdout)
    # the schema and every word exactly; figures to 1e-9 (a sum's last bits follow the NumPy build)
    assert data == _approx(json.loads(golden.read_text()))
    assert [s["choice"] for s in data["summaries"]] == data["choices"]
    assert {k for s in data["summaries"] for k in s["rates"]} == {
        "success", "collision", "timeout", "stuck"}
    assert len(read_rows("st")) == data["tasks"] == data["executed"] == 6


@pytest.mark.parametrize("order", [("--runs", 3, "-n", 1), ("-n", 1, "--runs", 3)])
def test_runs_and_its_old_spelling_together_are_a_usage_error(tiny, tmp_path, compare, order):
    """`-n` is `--runs`: `--runs 3 -n 1` ran one run a choice, its warning only about the
    spelling."""
    r = compare(tiny, "--planner", "dwa", *order, "-o", tmp_path / "s")
    assert r.exit_code == 2 and "are one option, given twice" in r.stderr
    assert not (tmp_path / "s").exists()


def _line_of(path, text: str) -> int:
    """The number of the first line of ``path`` holding ``text``."""
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if text in line)


def test_resume_refuses_a_world_that_changed(tmp_path, compare):
    """Resuming after the world file was edited would average runs of two different worlds
    (it did: 50% success, where the edited world alone gives 0%)."""
    world = tmp_path / "w.yaml"
    world.write_text(TINY)
    out = tmp_path / "s"
    args = (world, "--planner", "dwa", "-o", out, "-j", 1, "--no-plots")
    assert compare(*args, "--runs", 1).exit_code == 0
    world.write_text(TINY + "\n# edited\n")
    r = compare(*args, "--runs", 2, "--resume")
    assert r.exit_code == 1 and "changed since the runs in" in r.stderr
    # the place: the digest study.json recorded for it, the line shown and marked
    line = _line_of(out / "study.json", 'w.yaml": "')
    assert f"study.json:{line}:5: study error" in r.stderr and 'w.yaml": "' in r.stderr
    assert len(read_rows(out)) == 1
    world.write_text(TINY)                               # put back: it resumes
    assert compare(*args, "--runs", 2, "--resume").exit_code == 0


def test_resume_refuses_another_behavior(tiny, tmp_path, compare):
    """No column of a row names the behavior: a resume with another `--behavior` averaged
    runs of `drive` with runs of `avoid_obstacle`, and study.json then said all were the
    latter's."""
    out = tmp_path / "s"
    args = (tiny, "--and", "min", "--planner", "fuzzy", "-o", out, "-j", 1, "--no-plots")
    assert compare(*args, "--runs", 1).exit_code == 0
    r = compare(*args, "--runs", 2, "--resume", "--behavior", "avoid_obstacle")
    assert r.exit_code == 1 and "were made with each world's own behavior, not --behavior " \
        "avoid_obstacle" in r.stderr, r.output
    line = _line_of(out / "study.json", '"behavior": null')
    assert f"study.json:{line}:3: study error" in r.stderr and '"behavior": null,' in r.stderr
    assert "resume without --behavior" in r.stderr and len(read_rows(out)) == 1
    assert compare(*args, "--runs", 2, "--resume").exit_code == 0
    r = compare(*args, "--runs", 3, "--resume", "--behavior", "drive")
    assert r.exit_code == 1 and "resume without --behavior" in r.stderr


def grid_world(directory: Path) -> Path:
    """``tiny.yaml`` on a map_server map (a 10 x 2 m hall, 5 cm a pixel) beside it."""
    width, height = 200, 40
    (directory / "m.pgm").write_bytes(b"P5\n%d %d\n255\n" % (width, height) + bytes(
        0 if y in (0, height - 1) else 254 for y in range(height) for _ in range(width)))
    (directory / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\norigin: [0, -1, 0]\n")
    world = directory / "g.yaml"
    world.write_text(TINY.replace("  corridors:\n    - points: [[0, 0], [280, 0]]\n"
                                  "      width: 70\n", "  grid: m.yaml\n"))
    return world


@pytest.mark.parametrize("edit", ["m.yaml", "m.pgm"])
def test_resume_refuses_a_map_that_changed(tmp_path, compare, edit):
    """A world's digest was of its own file: a map (its YAML or its image) edited between a
    study and its resume was resumed as the same world, the runs of both maps averaged."""
    world = grid_world(tmp_path)
    out = tmp_path / "s"
    args = (world, "--planner", "dwa", "-o", out, "-j", 1, "--no-plots")
    assert compare(*args, "--runs", 1).exit_code == 0
    before = (tmp_path / edit).read_bytes()
    (tmp_path / edit).write_bytes(before.replace(b"0.05", b"0.04") if edit == "m.yaml"
                                  else before[:-1] + bytes([255 - before[-1]]))
    r = compare(*args, "--runs", 2, "--resume")
    assert r.exit_code == 1 and "`" + str(world) + "` or a map file it reads changed since" \
        in r.stderr, r.output
    assert len(read_rows(out)) == 1
    (tmp_path / edit).write_bytes(before)                   # put back: it resumes
    assert compare(*args, "--runs", 2, "--resume").exit_code == 0



def test_a_grid_map_file_not_named_yaml_is_in_the_worlds_digest(tmp_path):
    """A `grid:` map file is read by its content whatever its name, but the digest took only
    one ending in .yaml: an edited `m.map` (or its image) resumed as the same world."""
    from mitos_cli.sim.worldfile import map_files
    from mitos_cli.study.simtask import world_digest

    world = grid_world(tmp_path)
    (tmp_path / "m.yaml").rename(tmp_path / "m.map")
    world.write_text(world.read_text().replace("grid: m.yaml", "grid: m.map"))
    assert map_files(world) == [tmp_path / "m.map", tmp_path / "m.pgm"]
    before = world_digest(str(world))
    image = (tmp_path / "m.pgm").read_bytes()
    (tmp_path / "m.pgm").write_bytes(image[:-1] + bytes([255 - image[-1]]))
    assert world_digest(str(world)) != before


def test_a_study_resumes_from_another_directory(tmp_path, compare, monkeypatch):
    """A world is the file, not the path typed: a study made with `tiny.yaml` from its own
    directory "left out" its runs when resumed from anywhere else, even with the command its
    hint gave. The rows go on naming the world as they did."""
    home, elsewhere, out = tmp_path / "home", tmp_path / "elsewhere", tmp_path / "s"
    home.mkdir()
    elsewhere.mkdir()
    world = home / "tiny.yaml"
    world.write_text(TINY)
    args = ("--planner", "dwa", "-o", out, "-j", 1, "--no-plots")
    monkeypatch.chdir(home)
    assert compare("tiny.yaml", *args, "--runs", 1).exit_code == 0
    monkeypatch.chdir(elsewhere)
    r = compare("../home/tiny.yaml", *args, "--runs", 2, "--resume")      # by its digest
    assert r.exit_code == 0, r.output
    assert "1 run now, 1 from before" in r.stderr
    assert [row["world"] for row in read_rows(out)] == ["tiny.yaml"] * 2
    world.write_text(TINY + "\n# edited\n")
    r = compare(world, *args, "--runs", 3, "--resume")
    assert r.exit_code == 1 and "home/tiny.yaml` " in r.stderr       # (a long path is cut)
    assert "given now is not the file the runs of `tiny.yaml` were made with, or it was " \
           "changed since" in r.stderr
    monkeypatch.chdir(home)
    r = compare(world, *args, "--runs", 3, "--resume")                   # the same file
    assert r.exit_code == 1 and "`tiny.yaml` changed since the runs in" in r.stderr
    world.write_text(TINY)
    r = compare(world, *args, "--runs", 3, "--resume")
    assert r.exit_code == 0 and "1 run now, 2 from before" in r.stderr
    assert [row["world"] for row in read_rows(out)] == ["tiny.yaml"] * 3
    assert compare("tiny.yaml", *args, "--runs", 3, "--resume").exit_code == 0


def test_worlds_of_one_stem_are_told_apart(tmp_path, compare):
    (tmp_path / "sub").mkdir()
    for w in (tmp_path / "w.yaml", tmp_path / "sub" / "w.yaml"):
        w.write_text(TINY)
    r = compare(tmp_path / "w.yaml", tmp_path / "sub" / "w.yaml", "--planner", "dwa",
                "--runs", 1, "-o", tmp_path / "s", "-j", 1, "--no-plots")
    assert r.exit_code == 0, r.output
    report = (tmp_path / "s" / "report.md").read_text()
    assert f"| {tmp_path / 'w.yaml'} |" in report and f"| {tmp_path / 'sub' / 'w.yaml'} |" in report


def test_without_matplotlib_the_report_has_no_plots(tiny, tmp_path, compare, monkeypatch):
    """A study is not lost for want of matplotlib: report.md is written without its plots,
    and the user is told how to get them."""
    import mitos_cli.study as study

    real = study.write_report

    def no_matplotlib(outcome, out, plots=True):
        if plots:
            raise ImportError("No module named 'matplotlib'")
        return real(outcome, out, plots=False)

    monkeypatch.setattr(study, "write_report", no_matplotlib)
    out = tmp_path / "study"
    r = compare(tiny, "--and", "min", "--planner", "fuzzy", "--runs", 1, "-o", out, "-j", 1)
    assert r.exit_code == 0, r.output
    assert "matplotlib is not installed: report.md has no plots" in r.stderr
    assert "pip install 'matplotlib>=3.6' (the `plot` extra" in r.stderr
    assert (out / "report.md").is_file() and not (out / "success.png").exists()


def test_a_report_without_plots_leaves_no_plots_of_before(tiny, tmp_path, compare):
    """A study extended with `--resume --no-plots` (or where matplotlib is missing) kept the
    plots of its earlier report beside the new one: figures of fewer runs, to be published
    as the study's."""
    out = tmp_path / "study"
    args = (tiny, "--planner", "dwa", "-o", out, "-j", 1)
    assert compare(*args, "--runs", 1).exit_code == 0
    assert (out / "success.png").is_file() and (out / "clearance.png").is_file()
    assert compare(*args, "--runs", 2, "--resume", "--no-plots").exit_code == 0
    assert not (out / "success.png").exists() and not (out / "clearance.png").exists()
    assert ".png" not in (out / "report.md").read_text()


def test_a_world_that_randomises_nothing_is_said_to_give_copies(tmp_path, compare):
    """A world with no `randomise:` range and no sensor noise gave `n = 3` of one run, its
    intervals of zero width, without a word."""
    world = tmp_path / "fixed.yaml"
    world.write_text(TINY.split("randomise:")[0].replace("noise: 0.5", "noise: 0"))
    r = compare(world, "--planner", "dwa", "--runs", 3, "-o", tmp_path / "s", "-j", 1,
                "--no-plots")
    assert r.exit_code == 0 and "the world randomises nothing" in r.stderr
    assert "its 3 runs are one run 3 times" in r.stderr
    assert len({row["time_s"] for row in read_rows(tmp_path / "s")}) == 1


def test_a_directory_where_a_plot_goes_is_a_clear_error(tiny, tmp_path, compare):
    """`success.png` a directory: the plot's rename into it was an IsADirectoryError
    traceback, its `success.tmp.png` left beside it."""
    out = tmp_path / "s"
    (out / "success.png").mkdir(parents=True)
    r = compare(tiny, "--planner", "dwa", "--runs", 1, "-o", out, "-j", 1)
    assert r.exit_code == 1 and "Traceback" not in r.output
    # (a long path is shortened in the middle: pytest-xdist's tmp_path can be)
    assert re.search(r"cannot write `[^`]*success\.png`( \(\d+ characters\))?: it is a "
                     r"directory", r.stderr), r.stderr
    assert sorted(p.name for p in out.iterdir()) == ["results.csv", "study.json", "success.png"]


@pytest.mark.parametrize("flag, what", [("--and", "T-norm"), ("--or", "S-norm"),
                                        ("--inference", "inference method")])
def test_a_list_of_no_names_is_a_usage_error(tiny, tmp_path, compare, flag, what):
    """`--and ,` compared the rule base's own operators, labelled `fuzzy`, without a word."""
    r = compare(tiny, "--planner", "fuzzy", flag, ",", "-o", tmp_path / "s")
    assert r.exit_code == 2 and f"name at least one {what}" in r.stderr
    assert not (tmp_path / "s").exists()


def test_workers_with_a_scheduler_are_a_usage_error(tiny, tmp_path, compare):
    """`-j 8` with `--scheduler` was dropped without a word: the cluster's workers run it."""
    r = compare(tiny, "--planner", "dwa", "--executor", "dask", "--scheduler",
                "tcp://127.0.0.1:9", "-j", 8, "-o", tmp_path / "s")
    said = " ".join(r.stderr.replace("│", " ").split())          # (as rich's box wraps it)
    assert r.exit_code == 2 and "the cluster at --scheduler runs its own workers" in said
    assert not (tmp_path / "s").exists()


@pytest.mark.parametrize("missing, words", [
    ("distributed", "the Dask executor needs dask.distributed, which is not installed"),
    ("cryptography", "the local Dask cluster needs `cryptography`"),
])
def test_dask_not_installed_is_said_before_anything_is_written(tiny, tmp_path, compare,
                                                               monkeypatch, missing, words):
    """It printed `runs (dask): 0 of 2 (0%)` first and left study.json and an empty
    results.csv behind."""
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == missing else real(name, *a))
    out = tmp_path / "study"
    r = compare(tiny, "--and", "min", "--planner", "fuzzy", "--runs", 2, "-o", out,
                "--executor", "dask")
    assert r.exit_code == 1 and words in r.stderr
    assert ("pip install 'dask[distributed]>=2024.1' 'cryptography>=41' (the `dask` extra of "
            "mitos-planner), or use --executor local") in r.stderr
    assert "runs (dask)" not in r.stderr and not out.exists()


def test_compare_help_names_every_inference_method():
    """`--inference`'s help listed weighted_average, weighted_sum and mamdani; `tsukamoto`,
    which the option takes, was named on no page."""
    import typer.main

    from mitos_cli.cli.app import build_app
    from mitos_cli.lang.operators import INFERENCES

    command = typer.main.get_group(build_app("compare")).commands["compare"]
    option = next(p for p in command.params if p.name == "inference")
    assert all(name in option.help for name in INFERENCES), option.help


@pytest.mark.parametrize("args, said", [
    (["--planner", "fuzzy", "potential_field"],
     "`potential_field` is a planner, read here as a world: --planner takes its names "
     "comma-separated, without spaces (`--planner fuzzy,potential_field`)"),
    (["--and", "min", "product"],
     "`product` is a T-norm, read here as a world: --and takes its names comma-separated, "
     "without spaces (`--and min,product`)"),
    (["--or", "max", "probabilistic_sum"], "`probabilistic_sum` is an S-norm"),
    (["--inference", "weighted_average", "Mamdani"], "`Mamdani` is an inference method"),
    (["lukasiewicz"], "(`--and min,product,lukasiewicz,einstein`)"),     # --and left as it was
])
def test_a_choice_given_apart_from_its_option_is_said_to_be_one(tiny, tmp_path, compare, args,
                                                                said):
    """`--planner fuzzy potential_field` (a space for the comma) read `potential_field` as a
    world: "world file `potential_field` not found", exit 1. Nothing is run or written."""
    ran = compare(tiny, *args, "--runs", "1", "-o", tmp_path / "s")
    assert ran.exit_code == 2, ran.output
    assert said in " ".join(ran.stderr.replace("│", " ").split()), ran.stderr
    assert not (tmp_path / "s").exists()


def test_a_packaged_world_is_named_as_the_user_named_it_in_every_output(tmp_path, compare,
                                                                        monkeypatch):
    """`mitos compare corridor` wrote the world in results.csv, study.json and --json by where
    pip had put it (`.../site-packages/mitos_cli/_data/worlds/corridor.yaml`) while the report
    said `corridor`: a packaged world is named by its stem everywhere (`worlds/corridor.yaml`
    from outside a clone is the packaged one too), a file of the user's by the path given, and
    the study resumes under those names."""
    import json

    from mitos_cli.resources import data_dir

    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "tiny.yaml").write_text(TINY)
    args = ("--planner", "potential_field", "-o", "s", "-j", 1, "--no-plots")
    r = compare("worlds/corridor.yaml", "mine/tiny.yaml", *args, "--runs", 1, "--json")
    assert r.exit_code == 0, r.output
    assert [row["world"] for row in read_rows("s")] == ["corridor", "mine/tiny.yaml"]
    manifest = json.loads((tmp_path / "s" / "study.json").read_text())
    assert manifest["worlds"] == ["corridor", "mine/tiny.yaml"]
    assert set(manifest["digests"]) == {"corridor", "mine/tiny.yaml", "rulebase"}
    said = json.loads(r.stdout)
    assert said["worlds"] == ["corridor", "mine/tiny.yaml"]
    assert {s["world"] for s in said["summaries"]} >= {"corridor", "mine/tiny.yaml"}
    report = (tmp_path / "s" / "report.md").read_text()
    assert "`corridor (packaged)`, `mine/tiny.yaml`" in report
    place = str(Path(str(data_dir("worlds"))).resolve())
    for text in (r.stdout, r.stderr, report, (tmp_path / "s" / "results.csv").read_text(),
                 json.dumps(manifest)):
        assert place not in text
    r = compare("corridor", "mine/tiny.yaml", *args, "--runs", 2, "--resume")
    assert r.exit_code == 0, r.output
    assert "2 runs now, 2 from before" in r.stderr
    assert [row["world"] for row in read_rows("s")] == ["corridor", "mine/tiny.yaml"] * 2


def test_a_world_file_found_as_given_keeps_the_name_given(tmp_path, compare, monkeypatch):
    """In a checkout `worlds/corridor.yaml` is the user's file as given (an editable install's
    packaged worlds are those very files): the rows name it so, not `corridor`."""
    monkeypatch.chdir(ROOT)
    r = compare("worlds/corridor.yaml", "--planner", "potential_field", "-o", tmp_path / "s",
                "-j", 1, "--no-plots", "--runs", 1)
    assert r.exit_code == 0, r.output
    assert [row["world"] for row in read_rows(tmp_path / "s")] == ["worlds/corridor.yaml"]


def test_a_study_that_named_a_packaged_world_by_its_path_resumes_by_its_name(tmp_path, compare,
                                                                             monkeypatch):
    """Rows that name the packaged corridor by its installed path (as compare wrote them
    before, or as the user typed it) resume with `corridor` given, and keep their name."""
    from mitos_cli.resources import data_dir

    monkeypatch.chdir(tmp_path)
    path = str(Path(str(data_dir("worlds"))).resolve() / "corridor.yaml")
    args = ("--planner", "potential_field", "-o", "s", "-j", 1, "--no-plots")
    assert compare(path, *args, "--runs", 1).exit_code == 0
    r = compare("corridor", *args, "--runs", 2, "--resume")
    assert r.exit_code == 0, r.output
    assert "1 run now, 1 from before" in r.stderr
    assert [row["world"] for row in read_rows("s")] == [path, path]


def test_a_rule_base_without_the_worlds_behavior_says_how_to_choose_one(tiny, tmp_path,
                                                                        compare):
    """`mitos compare tiny.yaml -r tipper.fis` said "unknown behavior `drive`, expected one of
    main" with no position and no word of why `drive` was looked for, nor how to choose
    another, which `mitos simulate` says."""
    tipper = Path(__file__).parent / "data" / "interop" / "tipper.fis"
    r = compare(tiny, "--planner", "fuzzy", "-r", tipper, "--runs", 1, "-o", tmp_path / "s")
    assert r.exit_code == 1 and "unknown behavior `drive`" in r.stderr, r.output
    lines = r.stderr.splitlines()
    assert lines[0].startswith(f"{tiny}:") and lines[1].strip() == "behavior: drive", r.stderr
    assert lines[-1] == (
        "hint: the world is driven by its `behavior: drive`, which this rule base lacks: "
        "choose one of its behaviors (--behavior NAME; behavior= from Python)")
    assert not (tmp_path / "s" / "results.csv").exists()


def test_tables_piped_are_never_cut_short(tiny, tmp_path, compare, monkeypatch):
    """Piped or into a file, the tables were drawn 160 columns wide whatever they held: a long
    world name or choice cut every column to `…` and dropped `n`."""
    import shutil

    monkeypatch.chdir(tmp_path)
    shutil.copy(tiny, "a_rather_long_world_name_for_a_study.yaml")
    r = compare("a_rather_long_world_name_for_a_study.yaml", "--and", "lukasiewicz", "--or",
                "probabilistic_sum", "--inference", "weighted_average", "--runs", 2, "-o", "st",
                "-j", 1, "--no-plots")
    assert r.exit_code == 0, r.output
    assert "…" not in r.stdout
    header = next(line for line in r.stdout.splitlines() if "success" in line)
    assert header.split()[:4] == ["world", "choice", "n", "success"]
    assert "fuzzy and=lukasiewicz or=probabilistic_sum inference=weighted_average" in r.stdout
    assert "a_rather_long_world_name_for_a_study " in r.stdout
