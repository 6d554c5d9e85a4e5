"""A world of several robots: the run's outcome and figures cover every robot, and each robot's
own figures are reported beside them (``--json`` ``robots``, a table column, ``--runs`` rows)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from mitos_cli.cli.app import app
from mitos_cli.sim.loop import simulate
from mitos_cli.sim.worldfile import load_world, parse_world

RUNNER = CliRunner()
ROOT = Path(__file__).resolve().parents[1]
ROBOT_KEYS = ["name", "outcome", "reached_goal", "time_s", "path_length_in", "min_clearance_in",
              "replans", "backouts",
              "mean_speed_in_s", "steering_total_variation_deg"]
# Two robots in two separate corridors: `robot` starts 30 in from its goal and reaches it;
# `second` is rammed from behind by a cart at 120 in/s it cannot outrun.
REAR_END = """\
name: rearend
seed: 1
dt: 0.05
time_limit: 5
robot:
  model: tricycle
  wheelbase: 16
  footprint: {length: 24, width: 18}
q_init: {x: 530, y: -15, heading: 0}
q_goal: {x: 560, y: -15}
robots:
  - name: second
    q_init: {x: 60, y: 185, heading: 0}
    q_goal: {x: 560, y: 185}
map:
  corridors:
    - points: [[0, 0], [600, 0]]
      width: 70
    - points: [[0, 200], [600, 200]]
      width: 70
obstacles:
  - {name: ram, shape: rectangle, at: [-150, 185], length: 20, width: 20, velocity: [120, 0]}
"""


@pytest.fixture()
def rear_end(tmp_path: Path) -> Path:
    p = tmp_path / "rearend.yaml"
    p.write_text(REAR_END, encoding="utf-8")
    return p


def run(*args):
    res = RUNNER.invoke(app, ["simulate", *map(str, args)])
    assert res.exit_code == 0, res.output
    return res.stdout


def test_the_second_robots_collision_is_the_runs(rear_end):
    data = json.loads(run(rear_end, "--json"))
    first, second = data["robots"]
    assert [list(r) for r in data["robots"]] == [ROBOT_KEYS + ["near_miss"]] * 2
    assert (first["name"], first["outcome"], first["reached_goal"]) == ("robot", "success", True)
    assert (second["name"], second["outcome"], second["reached_goal"]) == \
        ("second", "collision", False)
    assert data["outcome"] == "collision" and data["reached_goal"] is False
    assert data["collisions"] == 1
    # the run's clearance is the second robot's penetration, not the first robot's gap
    assert first["min_clearance_in"] > 2.0
    assert second["min_clearance_in"] < 0.0
    assert data["min_clearance_in"] == second["min_clearance_in"]
    res = simulate(load_world(rear_end))
    # the command's JSON is SimResult.summary(), near_miss beside each outcome included
    assert data["near_miss"] is False and [r["near_miss"] for r in data["robots"]] == \
        [False, False]
    assert res.summary() == data
    assert second["min_clearance_in"] == res.clearance[-1, 1] == res.clearance.min()
    # each robot's time is until it stopped at its goal or the run ended
    # the run ended on the contact its last tick observed: nothing moved on from it
    assert first["time_s"] < data["time_s"] == second["time_s"] == round((res.ticks - 1) * 0.05, 6)
    assert data["path_length_in"] == pytest.approx(first["path_length_in"]
                                                   + second["path_length_in"])
    driving = first["time_s"] + second["time_s"]
    assert data["mean_speed_in_s"] == pytest.approx(data["path_length_in"] / driving)
    assert data["steering_total_variation_deg"] == pytest.approx(
        first["steering_total_variation_deg"] + second["steering_total_variation_deg"])


def test_the_table_has_a_column_per_robot(rear_end):
    lines = run(rear_end).splitlines()
    assert lines[0].startswith("rearend: COLLISION (robot success, second collision) after ")
    assert lines[1].split() == ["all", "robots", "robot", "second"]
    rows = {line[:28].strip(): line[28:].split() for line in lines[2:]}
    assert rows["outcome"] == ["collision", "success", "collision"]
    assert rows["reached goal"] == ["no", "yes", "no"]
    assert rows["collisions"] == ["1", "0", "1"]
    clear = [float(v) for v in rows["min clearance"][::2]]
    assert clear[0] == clear[2] < 0 < clear[1]


def test_one_robot_timing_out_times_the_run_out(rear_end):
    text = rear_end.read_text().replace("time_limit: 5", "time_limit: 2") \
        .replace("velocity: [120, 0]", "velocity: [0, 0]")
    data = simulate(parse_world(text, "slow.yaml")).summary()
    assert [r["outcome"] for r in data["robots"]] == ["success", "timeout"]
    assert data["outcome"] == "timeout" and data["reached_goal"] is False
    assert data["collisions"] == 0 and data["min_clearance_in"] > 0


def test_a_robot_still_driving_when_another_collides_reads_stopped(rear_end):
    """Not `timeout` (its time had not run out): the run ended for the other's collision."""
    text = rear_end.read_text().replace("q_init: {x: 530, y: -15", "q_init: {x: 60, y: -15")
    data = simulate(parse_world(text, "far.yaml")).summary()
    assert [r["outcome"] for r in data["robots"]] == ["stopped", "collision"]
    assert data["outcome"] == "collision" and data["time_s"] < 5
    rows = json.loads(run(_write(rear_end, text), "--runs", 1, "--workers", 1, "--json"))
    assert [(r["name"], r["stopped_rate"]) for r in rows[0]["robots"]] == \
        [("robot", 1.0), ("second", 0.0)]
    assert "stopped_rate" not in rows[0]             # the run's outcome is never `stopped`
    table = run(_write(rear_end, text), "--runs", 1, "--workers", 1).splitlines()
    assert table[0].split()[2:7] == ["success", "collision", "timeout", "stuck", "stopped"]
    assert table[1].split()[6] == "-" and table[2].split()[6] == "100%"


def test_a_robot_still_driving_when_another_is_stuck_reads_stopped(rear_end):
    import numpy as np

    from mitos_cli.sim.loop import STUCK_TIME, Simulation

    class FirstStands:                               # robot 0 never moves: stuck after 6 s
        name = "first-stands"

        def plan(self, p):
            speed = np.where(np.arange(len(p.pose)) == 0, 0.0, 10.0)
            return np.full(len(p.pose), 90.0), speed

    text = rear_end.read_text().replace("time_limit: 5", "time_limit: 20") \
        .replace("velocity: [120, 0]", "velocity: [0, 0]")
    sim = Simulation(parse_world(text, "stand.yaml"), planner=FirstStands())
    while not sim.done:
        sim.step()
    assert sim.robot_outcomes == ("stuck", "stopped") and sim.outcome == "stuck"
    assert sim.time < STUCK_TIME + 1


def test_a_robot_parked_at_its_goal_that_a_cart_drives_into_has_collided(rear_end):
    """`robot` parks at its goal after 1.6 s; a cart from behind drives into it at 3.8 s
    while `second` still drives. The run read a timeout with no collision, the cart 19 in
    deep in the parked robot and `near_miss` true ("without colliding")."""
    from mitos_cli.sim.lockstep import run_lockstep

    text = rear_end.read_text().replace("time_limit: 5", "time_limit: 8").replace(
        "{name: ram, shape: rectangle, at: [-150, 185], length: 20, width: 20, "
        "velocity: [120, 0]}",
        "{name: cart, shape: rectangle, at: [300, -15], length: 20, width: 20, "
        "velocity: [60, 0]}")
    world = parse_world(text, "parked.yaml")
    res = simulate(world)
    data = res.summary()
    assert res.robot_outcomes == ("collision", "stopped") and data["outcome"] == "collision"
    assert data["collisions"] == 1 and data["near_miss"] is False
    assert res.active[-1].tolist() == [False, True]          # parked, hit, the run ends
    assert res.clearance[-1, 0] <= 0 < res.clearance[:-1, 0].min()
    assert 3.0 < data["time_s"] < 4.0
    (together,) = run_lockstep(world, None, [world.seed])       # the same rule in lockstep
    assert together.summary() == data
    from mitos_cli.sim.export import csv_text
    from mitos_cli.sim.planner import FuzzyPlanner

    rows = [r for r in csv_text(res, FuzzyPlanner(None, "drive")).splitlines()[1:]
            if r.split(",")[2] == "robot"]          # its drive, then the tick it was hit
    last = rows[-1].split(",")
    assert int(last[0]) == res.ticks - 1 and float(last[10]) <= 0 and last[-1] == ""


def _write(path: Path, text: str) -> Path:
    out = path.with_name("variant.yaml")
    out.write_text(text, encoding="utf-8")
    return out


def test_runs_count_a_run_a_success_only_if_every_robot_succeeded(rear_end):
    rows = json.loads(run(rear_end, "--runs", 2, "--workers", 1, "--json"))
    (row,) = rows
    assert row["collision_rate"] == 1.0 and row["success_rate"] == 0.0
    assert [(r["name"], r["success_rate"], r["collision_rate"]) for r in row["robots"]] == \
        [("robot", 1.0, 0.0), ("second", 0.0, 1.0)]
    detail = row["runs_detail"]
    assert row["min_clearance_in"]["mean"] == pytest.approx(
        sum(d["robots"][1]["min_clearance_in"] for d in detail) / 2)
    table = run(rear_end, "--runs", 2, "--workers", 1).splitlines()
    assert [line.split()[0] for line in table] == ["world", "rearend", "robot", "second",
                                                   "(time,"]           # the means' footnote
    assert table[-1].startswith("(time, path, min clear, speed, replans and backed out: mean ± "
                                "standard deviation over every run, a collision's or a "
                                "timeout's until it ended")
    for r in [row, *row["robots"]]:                   # each robot's counts, and the world's sum
        assert set(r["replans"]) == set(r["backouts"]) == {"mean", "std"}
    assert row["replans"]["mean"] == pytest.approx(
        sum(r["replans"]["mean"] for r in row["robots"]))
    assert table[1].split()[2:4] == ["0%", "100%"] and table[2].split()[2] == "100%"


def test_one_robot_json_has_no_robots_list_and_is_as_before():
    """Single-robot output did not change with the multi-robot figures (byte for byte: the
    golden case was recorded before them)."""
    golden = ROOT / "tests" / "golden" / "simulate_corridor_json"
    assert (golden / "cmd").read_text().split()[1:] == ["simulate", "worlds/corridor.yaml",
                                                        "--json"]
    data = simulate(load_world(ROOT / "worlds" / "corridor.yaml")).summary()
    assert "robots" not in data
    # the command adds only `near_miss` (the text's "closer than the safety margin") to it
    assert json.dumps(dict(data, near_miss=False), indent=2) + "\n" == \
        (golden / "stdout").read_text()


def test_two_robots_of_one_name_are_refused(tmp_path, capsys):
    from mitos_cli.cli.app import main

    p = tmp_path / "twins.yaml"
    p.write_text(REAR_END.replace("name: second", "name: robot"), encoding="utf-8")
    with pytest.raises(SystemExit) as info:
        main(["simulate", str(p)])
    err = capsys.readouterr().err
    assert info.value.code == 1
    assert f"{p}:12:11:" in err and "two robots are named `robot`" in err
    assert "- name: robot" in err and "Traceback" not in err


def test_the_trace_of_a_fleet_says_whom_it_follows(rear_end):
    """`--trace` follows the first robot; in a world of several it said nothing of the
    others, whose ticks are in the --out CSV."""
    text = run(rear_end, "--trace", "--every", "1000")
    assert text.startswith("(the trace follows `robot`, the first of the world's 2 robots; "
                           "`second` is in the --out CSV, a row per tick and robot)\n\n"
                           "--- tick 0, t = 0.00 s: robot at (530.0, -15.0) in"), text[:300]
    crossroads = run(ROOT / "tests" / "data" / "crossroads4.yaml", "--trace", "--every", "5000",
                     "--planner", "dwa")
    assert crossroads.startswith(
        "(the trace follows `robot`, the first of the world's 4 robots; `west`, `north` and "
        "`south` are in the --out CSV, a row per tick and robot)\n\n(planner dwa is not a rule "
        "base: no DOF trace"), crossroads[:300]
    single = run(ROOT / "worlds" / "corridor.yaml", "--trace", "--every", "5000")
    assert single.startswith("--- tick 0,")


def test_simulate_help_speaks_of_several_robots():
    res = RUNNER.invoke(app, ["simulate", "--help"], env={"COLUMNS": "200"})
    text = " ".join(res.stdout.replace("│", " ").split())
    assert "Simulate the rule base driving one tricycle robot or several" in text
    assert ("With several robots (a world's `robots:`), the verdict names each robot's "
            "outcome") in text
    assert "Write one CSV row per tick (and robot) to FILE.csv" in text
