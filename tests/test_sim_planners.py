"""The planner registry and ``mitos simulate --planner``."""

from __future__ import annotations

import pytest

from mitos_cli.cli.app import main
from mitos_cli.errors import MitosError
from mitos_cli.sim.planner import PLANNERS, make_planner
from mitos_cli.sim.worldfile import load_world, resolve_world_path
from mitos_cli.study.spec import PLANNERS as STUDY_PLANNERS


@pytest.fixture(scope="module")
def corridor():
    return load_world(resolve_world_path("corridor.yaml"))


def test_every_registered_planner_builds_and_names_itself(corridor):
    assert list(PLANNERS) == ["fuzzy", "potential_field", "dwa"]
    assert tuple(PLANNERS) == STUDY_PLANNERS
    names = [make_planner(name, corridor).name for name in PLANNERS]
    assert names == ["fuzzy:drive", "potential_field", "dwa"]


def test_an_unknown_planner_suggests_the_nearest(corridor):
    with pytest.raises(MitosError) as info:
        make_planner("dwb", corridor)
    assert "unknown planner `dwb`" in str(info.value)
    assert "did you mean `dwa`" in str(info.value)


def run(capsys, *args) -> tuple[int, str, str]:
    try:
        main(["simulate", *map(str, args)])
        code = 0
    except SystemExit as exc:
        code = exc.code or 0
    out, err = capsys.readouterr()
    return code, out, err


def test_simulate_planner_unknown_is_a_usage_error_with_did_you_mean(capsys):
    code, _, err = run(capsys, "corridor.yaml", "--planner", "potential")
    assert code == 2 and "did you mean `potential_field`" in err


def test_simulate_planner_with_rules_for_another_planner_is_a_usage_error(capsys):
    code, _, err = run(capsys, "corridor.yaml", "--planner", "dwa", "--behavior", "drive")
    assert code == 2 and "`dwa` has none" in err


def test_simulate_json_names_the_planner(capsys, tmp_path):
    world = tmp_path / "w.yaml"
    text = resolve_world_path("corridor.yaml").read_text().replace("time_limit: 60",
                                                                   "time_limit: 1")
    world.write_text(text)
    code, out, _ = run(capsys, world, "--planner", "potential_field")
    assert code == 0 and "potential_field" in out


def test_compare_knows_dwa(capsys, tmp_path):
    try:
        main(["compare", "corridor.yaml", "--planner", "dwx", "-o", str(tmp_path / "s")])
    except SystemExit as exc:
        assert exc.code == 2
    assert "did you mean `dwa`" in capsys.readouterr().err


TERMS = """\
variables:
  x:
    role: input
    universe: [0, 10]
    terms:
      LOW: {shape: left_shoulder, points: [2, 8]}
  road:
    role: input
    universe: [0, 200]
    terms:
      WIDE: {shape: right_shoulder, points: [40, 80]}
  steering:
    role: output
    universe: [0, 180]
    terms:
      ST: {shape: triangle, points: [80, 90, 100]}
  speed:
    role: output
    universe: [0, 60]
    terms:
      SLOW: {shape: triangle, points: [0, 10, 20]}
"""


def test_a_behavior_the_simulator_cannot_drive_is_pointed_at(capsys, tmp_path):
    """A new user's third review: "reads input `x`, which the simulator does not perceive"
    came with no file:line:column. Now it points at the first use of `x` (through `use`
    too) and lists the inputs the simulator perceives; "sets no `steering`" points at the
    behavior."""
    (tmp_path / "x.terms.yaml").write_text(TERMS)
    rules = tmp_path / "sim1.rules"
    rules.write_text('terms "x.terms.yaml"\n\nbehavior drive:\n    use slow when road is WIDE\n'
                     'end\n\nbehavior slow:\n    if road is WIDE and x is LOW then speed is SLOW\n'
                     'end\n')
    code, _, err = run(capsys, "corridor.yaml", "-r", rules)
    assert code == 1, err
    assert f"{rules}:8:25: rule base error: behavior `drive` reads input `x`" in err
    assert "expected inputs among road, size, position, obstacle, heading" in err
    rules.write_text('terms "x.terms.yaml"\n\nbehavior drive:\n'
                     '    if road is WIDE then speed is SLOW\nend\n')
    code, _, err = run(capsys, "corridor.yaml", "-r", rules)
    assert code == 1 and f"{rules}:3:" in err and "sets no `steering`" in err, err
