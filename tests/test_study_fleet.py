"""`mitos compare` on a world of several robots: a row per robot of each run in results.csv,
and under the fleet's row in the tables, report.md and --json; a one-robot study's files are
those of before, byte for byte; a fleet's runs resume, and go the same on every executor."""

from __future__ import annotations

import csv
import io
import json
import os
import shutil
from pathlib import Path

import pytest
from test_study_cli import run_compare

from mitos_cli.study import Study, make_choices, run_study
from mitos_cli.study.store import COLUMNS, FLEET_COLUMNS, ResultStore, StudyError

DATA = Path(__file__).parent / "data"
FLEET = DATA / "fleet_tiny.yaml"              # two robots head-on: collisions, stuck, stopped
TINY = DATA / "tiny.yaml"
GOLDEN = DATA / "compare_fleet_tiny"


def compare(capsys, *args) -> tuple[int, str, str]:
    ran = run_compare(capsys, *args)
    return ran.exit_code, ran.stdout, ran.stderr


def _cells(text: str) -> list[list[object]]:
    """A CSV's cells, numbers with a decimal point as floats to 1e-9 (a sum's last bits follow
    the NumPy build), the rest as written."""
    def cell(v: str) -> object:
        try:
            return pytest.approx(float(v), rel=1e-9, abs=1e-12) if "." in v else v
        except ValueError:
            return v

    return [[cell(v) for v in row] for row in csv.reader(io.StringIO(text))]


def _golden(path: Path, text: str) -> str:
    if os.environ.get("MITOS_UPDATE_GOLDEN"):
        path.write_text(text, encoding="utf-8")
    return path.read_text(encoding="utf-8")


def test_a_fleet_study_names_each_robot_in_its_table_report_and_csv(tmp_path, monkeypatch,
                                                                    capsys):
    """Golden: the table and report.md have a row per robot under the fleet's, with its
    `stopped` rate; results.csv a `robot` column, each run's robots' rows, then its own."""
    monkeypatch.chdir(tmp_path)
    shutil.copy(FLEET, "fleet_tiny.yaml")
    code, out, err = compare(capsys, "fleet_tiny.yaml", "--and", "min", "--planner",
                             "fuzzy,dwa", "--runs", 2, "-o", "st", "-j", 1, "--no-plots")
    assert code == 0, err
    assert out == _golden(GOLDEN / "stdout", out)
    report = Path("st/report.md").read_text(encoding="utf-8")
    assert report == _golden(GOLDEN / "report.md", report)
    results = Path("st/results.csv").read_text(encoding="utf-8")
    assert _cells(results) == _cells(_golden(GOLDEN / "results.csv", results))
    rows = list(csv.DictReader(io.StringIO(results)))
    assert tuple(rows[0]) == FLEET_COLUMNS
    assert [r["robot"] for r in rows] == ["robot", "oncoming", ""] * 4
    assert "| fleet_tiny | ↳ oncoming | 2 |" in report
    # --json: each robot's rates (with `stopped`) and figures under the fleet's summary
    code, out, err = compare(capsys, "fleet_tiny.yaml", "--and", "min", "--planner",
                             "fuzzy,dwa", "--runs", 2, "-o", "st", "--resume", "--json")
    assert code == 0 and "0 runs now, 4 from before" in err
    dwa = json.loads(out)["summaries"][1]
    assert dwa["choice"] == "dwa" and set(dwa["rates"]) == {"success", "collision", "timeout",
                                                             "stuck"}
    assert [(r["robot"], r["runs"], r["rates"]["stuck"]["k"], r["rates"]["stopped"]["k"])
            for r in dwa["robots"]] == [("robot", 2, 2, 0), ("oncoming", 2, 0, 2)]
    assert set(dwa["robots"][0]["metrics"]) == set(dwa["metrics"])
    # the ranking is on the fleet's outcome: a run is a success only where both robots' are
    own = [r for r in rows if r["robot"] == ""]
    for i, r in enumerate(own):
        robots = rows[3 * i:3 * i + 2]
        assert (r["outcome"] == "success") == all(x["outcome"] == "success" for x in robots)
        assert int(r["collisions"]) == sum(x["outcome"] == "collision" for x in robots)


def test_a_one_robot_study_writes_what_it_wrote_before(tmp_path, monkeypatch, capsys):
    """results.csv and report.md of a one-robot study are those recorded before studies had
    robots' rows (tests/data/compare_tiny_results.csv and compare_tiny_report.md), and it
    resumes and extends as before."""
    monkeypatch.chdir(tmp_path)
    shutil.copy(TINY, "tiny.yaml")
    args = ["tiny.yaml", "--and", "min,product", "-o", "st", "-j", 1, "--no-plots"]
    code, _, err = compare(capsys, *args, "--runs", 2)
    assert code == 0, err
    results = Path("st/results.csv").read_text(encoding="utf-8")
    assert results.splitlines()[0] == ",".join(COLUMNS) == (
        "world,planner,and,or,inference,run,seed,outcome,collisions,time_s,path_length_in,"
        "min_clearance_in,mean_speed_in_s,steering_total_variation_deg,ticks,replans,backouts")
    assert _cells(results) == _cells((DATA / "compare_tiny_results.csv").read_text())
    assert Path("st/report.md").read_text() == (DATA / "compare_tiny_report.md").read_text()
    code, _, err = compare(capsys, *args, "--runs", 3, "--resume")
    assert code == 0 and "3 runs now, 6 from before" in err
    assert Path("st/results.csv").read_text().startswith(results)


def test_each_robots_row_holds_what_simulate_gives_that_robot(tmp_path):
    """A robot's row is its figures in `mitos simulate WORLD --seed SEED --randomise`, the
    run's row the run's (the same summary `simulate --runs` shows per robot)."""
    from mitos_cli.sim import load_world, simulate
    from mitos_cli.sim.planner import make_planner

    study = Study([str(FLEET)], make_choices(["dwa"]), runs=2, seed=1)
    outcome = run_study(study, tmp_path / "st", workers=1)
    world = load_world(FLEET)
    for row in outcome.rows:
        alone = simulate(world, make_planner("dwa", world), row["seed"], randomise=True)
        assert (row["outcome"], row["time_s"], row["collisions"]) == (
            alone.outcome, alone.metrics["time_s"], alone.metrics["collisions"])
        assert [(r["robot"], r["outcome"], r["time_s"], r["path_length_in"],
                 r["min_clearance_in"], r["replans"], r["backouts"]) for r in row["robots"]] == [
            (m["name"], m["outcome"], m["time_s"], m["path_length_in"], m["min_clearance_in"],
             m["replans"], m["backouts"]) for m in alone.robot_metrics]
    assert {r["outcome"] for row in outcome.rows for r in row["robots"]} == {"stuck", "stopped"}
    (fleet,) = outcome.per_world()
    assert [r.robot for r in fleet.robots] == ["robot", "oncoming"]
    assert fleet.robots[1].rates["stopped"].k == 2 and "stopped" not in fleet.rates


def fleet_study(runs: int = 2) -> Study:
    return Study([str(FLEET)], make_choices(["fuzzy"], ["min"]), runs=runs, seed=1)


def test_the_pool_gives_a_fleet_s_rows_bit_for_bit(tmp_path):
    serial = run_study(fleet_study(3), tmp_path / "serial", workers=1)
    pool = run_study(fleet_study(3), tmp_path / "pool", workers=2)
    assert serial.rows == pool.rows and all(len(r["robots"]) == 2 for r in serial.rows)
    lines = [sorted((tmp_path / d / "results.csv").read_text().splitlines())
             for d in ("serial", "pool")]
    assert lines[0] == lines[1] and len(lines[0]) == 1 + 3 * 3


def test_a_run_whose_own_row_the_kill_cut_off_is_run_again(tmp_path):
    """A run's rows are written together, its own last: a file that ends in robots' rows
    (killed as they were written) loses them and runs that run again."""
    run_study(fleet_study(), tmp_path, workers=1)
    path = tmp_path / "results.csv"
    data = path.read_bytes()
    for cut in (data[:data.rstrip(b"\n").rfind(b"\n") + 1],          # the run's own row gone
                data[:-20]):                                          # torn in its own row
        path.write_bytes(cut)
        assert len(ResultStore(tmp_path).load()) == 1
        out = run_study(fleet_study(), tmp_path, workers=1, resume=True)
        assert (out.skipped, out.executed) == (1, 1)
        assert path.read_bytes() == data


def _lines(path: Path) -> list[str]:
    return path.read_text().splitlines(keepends=True)


@pytest.mark.parametrize("edit, says, line", [
    (lambda rows: rows[:2] + rows[3:], "the row of robot `robot` of run 1 of fleet_tiny.yaml "
     "(fuzzy, and=min) is not followed by its run's row", 2),
    (lambda rows: rows[:2] + [rows[1]] + rows[2:], "robot `oncoming` of run 1 of "
     "fleet_tiny.yaml (fuzzy, and=min) is here a second time: its first row is line 3", 4),
    (lambda rows: rows[:3] + rows[4:], "run 0 of fleet_tiny.yaml (fuzzy, and=min) has rows of "
     "`oncoming`, where the world's robots are `robot`, `oncoming`", 6),
    (lambda rows: [r.replace("collision,2,", "collision,1,") for r in rows],
     "`collisions` is `1` in a run whose robots' rows hold 2 collisions", 4),
    (lambda rows: [r.replace("min,,,1,robot,5339568970972937013,collision,1,4.2",
                             "min,,,1,robot,5339568970972937013,collision,3,4.2") for r in rows],
     "`collisions` is `3` in a row whose outcome is `collision`", 2),
    (lambda rows: [r.replace("collision,2,", "stopped,0,") for r in rows],
     "`outcome` is `stopped`, not an outcome of a run", 4),
])
def test_a_hand_edited_fleet_results_file_is_refused_at_its_line(tmp_path, edit, says, line):
    run_study(fleet_study(), tmp_path, workers=1)
    path = tmp_path / "results.csv"
    rows = _lines(path)
    header, body = rows[0], rows[1:]
    edited = header + "".join(edit(body))
    assert edited != header + "".join(body)
    path.write_text(edited)
    with pytest.raises(StudyError) as exc:
        run_study(fleet_study(), tmp_path, workers=1, resume=True)
    assert says in exc.value.message and exc.value.span.line == line


def test_a_robot_row_with_ticks_is_refused(tmp_path):
    run_study(fleet_study(), tmp_path, workers=1)
    path = tmp_path / "results.csv"
    rows = _lines(path)
    rows[1] = rows[1].replace(",,4,0\n", ",85,4,0\n")
    path.write_text("".join(rows))
    with pytest.raises(StudyError) as exc:
        ResultStore(tmp_path).load()
    assert "`ticks` is `85` in the row of robot `robot`" in exc.value.message
    assert exc.value.span.line == 2 and "empty" in exc.value.expected


def test_a_fleet_study_written_before_rows_per_robot_is_refused_on_resume(tmp_path):
    """results.csv as compare wrote it before: one row a run, no `robot` column. Its runs have
    no robots' rows, which the report would lack: refused, with what to do."""
    run_study(fleet_study(), tmp_path, workers=1)
    path = tmp_path / "results.csv"
    rows = list(csv.reader(io.StringIO(path.read_text())))
    at = rows[0].index("robot")
    old = [r[:at] + r[at + 1:] for r in rows[:1] + [r for r in rows[1:] if r[at] == ""]]
    assert tuple(old[0]) == COLUMNS
    path.write_text("".join(",".join(r) + "\n" for r in old))
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    with pytest.raises(StudyError) as exc:
        run_study(fleet_study(3), tmp_path, workers=1, resume=True)
    assert "was written before `mitos compare` wrote a row per robot: its runs of " \
           "fleet_tiny.yaml have none" in exc.value.message
    assert exc.value.span.line == 2 and "another directory" in exc.value.hint
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_a_one_robot_study_extended_with_a_fleet_gets_the_robot_column(tmp_path):
    """A study of one-robot worlds given a world of several robots on resume: its rows are
    written again with an empty `robot`, the fleet's runs with their robots' rows."""
    one = run_study(Study([str(TINY)], make_choices(["dwa"]), runs=2, seed=1), tmp_path,
                    workers=1)
    path = tmp_path / "results.csv"
    before = list(csv.DictReader(io.StringIO(path.read_text())))
    both = run_study(Study([str(TINY), str(FLEET)], make_choices(["dwa"]), runs=2, seed=1),
                     tmp_path, workers=1, resume=True)
    assert (both.skipped, both.executed) == (2, 2) and both.rows[::2] == one.rows
    after = list(csv.DictReader(io.StringIO(path.read_text())))
    assert tuple(after[0]) == FLEET_COLUMNS
    assert after[:2] == [{**r, "robot": ""} for r in before]
    assert [r["robot"] for r in after[2:]] == ["robot", "oncoming", ""] * 2
