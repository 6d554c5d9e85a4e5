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
