"""``mitos simulate --animate``: the frame count at --fps, a decoded frame showing the robot,
the formats refused with a clear message."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from mitos_cli.cli.app import app, main
from mitos_cli.draw.animation import animate_run, frame_ticks
from mitos_cli.draw.frame import ROBOT_COLOUR, TRAIL_COLOUR
from mitos_cli.errors import InputError
from mitos_cli.resources import packaged_path

PIL = pytest.importorskip("PIL.Image")
RUNNER = CliRunner()


def run_main(capsys, *args) -> tuple[int, str]:
    """Through ``main``, which turns our errors into a message and exit 1."""
    with pytest.raises(SystemExit) as info:
        main(["simulate", *map(str, args)])
    return info.value.code, capsys.readouterr().err


@pytest.fixture
def short_world(tmp_path):
    """The packaged moving-obstacle world cut to 2 s (40 ticks)."""
    text = packaged_path("worlds", "moving.yaml").read_text(encoding="utf-8")
    path = tmp_path / "moving2.yaml"
    path.write_text(text.replace("time_limit: 60", "time_limit: 2"), encoding="utf-8")
    return path


def test_frames_are_taken_at_fps_of_simulated_time():
    assert frame_ticks(40, 0.05, 10).tolist() == list(range(0, 40, 2)) + [39]
    assert frame_ticks(41, 0.05, 10).tolist() == list(range(0, 41, 2))
    assert frame_ticks(40, 0.05, 2.5).tolist() == [0, 8, 16, 24, 32, 39]
    assert frame_ticks(3, 0.05, 60).tolist() == [0, 1, 2]        # never finer than a tick
    assert frame_ticks(0, 0.05, 10).tolist() == []


def test_animate_writes_a_gif_of_the_run(short_world, tmp_path):
    gif = tmp_path / "run.gif"
    out = RUNNER.invoke(app, ["simulate", str(short_world), "--animate", str(gif),
                              "--fps", "2.5"])
    assert out.exit_code == 0, out.output
    assert f"wrote 6 frames to {gif}" in out.output
    with PIL.open(gif) as im:
        assert im.n_frames == 6                                   # ticks 0, 8, 16, 24, 32, 39
        assert im.info["duration"] == 400                         # ms: 2.5 frames per second
        im.seek(3)
        frame = np.asarray(im.convert("RGB")).astype(int)
    robot = np.array([int(ROBOT_COLOUR[i:i + 2], 16) for i in (1, 3, 5)])
    assert (np.abs(frame - robot).sum(axis=2) < 30).sum() > 20   # the footprint is drawn
    assert not list(tmp_path.glob(".*.part.*"))


def test_each_frame_shows_the_route_as_planned_at_its_tick(tmp_path, monkeypatch):
    """The animation drew the first route to the end: past detour's replan (at 8.65 s), the
    dashed line still ran through the stack the robot had turned back from."""
    from mitos_cli.draw import animation
    from mitos_cli.sim import load_world, simulate

    text = packaged_path("worlds", "detour.yaml").read_text(encoding="utf-8")
    path = tmp_path / "detour10.yaml"
    path.write_text(text.replace("time_limit: 90", "time_limit: 10"), encoding="utf-8")
    result = simulate(load_world(path))
    (tick, _, replanned), = result.replanned
    shown = []
    monkeypatch.setattr(animation, "show_routes", lambda lines, routes: shown.append(routes[0]))
    animate_run(result, tmp_path / "run.gif", fps=0.5)
    picked = frame_ticks(result.ticks, result.world.dt, 0.5)
    assert [route is replanned for route in shown] == [k >= tick for k in picked]
    assert shown[-1] is replanned and shown[0] is result.routes[0]


def test_animate_refuses_other_formats_and_many_runs(short_world, tmp_path, capsys):
    code, err = run_main(capsys, short_world, "--animate", tmp_path / "a.avi")
    # an extension the option does not take is a usage error, as --plot's (README)
    said = " ".join(err.replace("│", " ").split())         # the usage box wraps its lines
    assert code == 2 and "has extension .avi; the animation formats are .gif and .mp4" in said
    out = RUNNER.invoke(app, ["simulate", str(short_world), "--runs", "2", "--animate",
                              str(tmp_path / "a.gif")])
    assert out.exit_code == 2 and "--animate" in out.output


def test_mp4_without_ffmpeg_says_so(short_world, tmp_path, monkeypatch, capsys):
    from matplotlib import animation

    monkeypatch.setattr(animation.writers, "is_available", lambda name: False)
    code, err = run_main(capsys, short_world, "--animate", tmp_path / "a.mp4")
    assert code == 1
    assert "MP4 needs ffmpeg, which is not on the PATH" in err
    assert "write a .gif" in err


def test_animate_run_takes_the_fps_and_width_the_cli_takes(short_world, tmp_path):
    """From Python, fps 0 met a ZeroDivisionError, -1 and 1e-6 an OverflowError and NaN a
    ValueError deep inside, width_px 0 an IndexError, and `fps=True` was 1 frame a second."""
    from mitos_cli.sim import load_world, simulate

    result = simulate(load_world(short_world))
    gif = tmp_path / "a.gif"
    for fps in (0, -1, float("nan"), float("inf"), 1e-6, 60.5, True, "10", None):
        with pytest.raises(InputError, match=r"fps is a number of frames per second from 0.1 "
                                             r"to 60 \(as `mitos simulate --fps`\), not `"):
            animate_run(result, gif, fps=fps)
    for width in (0, -5, 99, 4001, 720.0, True, "720"):
        with pytest.raises(InputError, match=r"width_px is a whole number of pixels from 100 "
                                             r"to 4000, not `"):
            animate_run(result, gif, width_px=width)
    assert not gif.exists()
    assert animate_run(result, gif, fps=np.float64(2.5), width_px=np.int64(100)) == 6


def test_one_frame_is_counted_in_the_singular(tmp_path):
    """A run of one tick (the robot starts at its goal) said "wrote 1 frames"."""
    text = packaged_path("worlds", "corridor.yaml").read_text(encoding="utf-8")
    world = tmp_path / "there.yaml"
    world.write_text(text.replace("q_goal: {x: 570, y: -10", "q_goal: {x: 30, y: -10"),
                     encoding="utf-8")
    gif = tmp_path / "run.gif"
    out = RUNNER.invoke(app, ["simulate", str(world), "--animate", str(gif)])
    assert out.exit_code == 0, out.output
    assert f"wrote 1 frame to {gif}" in out.output


def test_a_detail_of_another_run_or_robot_is_refused(short_world, tmp_path):
    """The DOF panel of another run was drawn under this run's frames without a word, and
    explain(result, planner, robot=3) of a run of one robot met an IndexError."""
    from mitos_cli.sim import load_world, simulate
    from mitos_cli.sim.export import explain
    from mitos_cli.sim.planner import FuzzyPlanner

    result = simulate(load_world(short_world))
    planner = FuzzyPlanner()
    other = simulate(dataclasses.replace(load_world(short_world), time_limit=1.0))
    with pytest.raises(InputError, match=r"detail has 20 rows, and the run 40 ticks: it is of "
                                         r"another run"):
        animate_run(result, tmp_path / "run.gif", detail=explain(other, planner))
    with pytest.raises(InputError, match="detail is the engine's result for the run's ticks"):
        animate_run(result, tmp_path / "run.gif", detail="dof")
    with pytest.raises(InputError, match="robot is the index of one of the run's 1 robot"):
        explain(result, planner, robot=3)
    assert not (tmp_path / "run.gif").exists()
    assert animate_run(result, tmp_path / "run.gif", fps=2.5,
                       detail=explain(result, planner)) == 6
def test_an_animation_written_onto_a_link_goes_to_the_file_it_names(short_world, tmp_path):
    """`--animate link.gif` replaced the link with the animation, and the file it named kept
    the old one, where `--plot` and `--out` write through a link; a replaced file's
    permissions are kept, as theirs are."""
    real = tmp_path / "real"
    real.mkdir()
    (real / "run.gif").write_bytes(b"old")
    (real / "run.gif").chmod(0o600)
    link = tmp_path / "link.gif"
    link.symlink_to(real / "run.gif")
    out = RUNNER.invoke(app, ["simulate", str(short_world), "--animate", str(link),
                              "--fps", "2.5"])
    assert out.exit_code == 0, out.output
    assert link.is_symlink() and (real / "run.gif").read_bytes()[:3] == b"GIF"
    assert (real / "run.gif").stat().st_mode & 0o777 == 0o600
    assert not list(tmp_path.glob("**/.*.part.*"))


def test_each_robot_of_an_animation_takes_its_colour_in_the_runs_picture():
    """`back`, the third robot of a crossroads world, was teal in `--plot` and purple in
    `--animate`, the first robot's trail green beside its blue path; past five robots the
    animation's colours came round again."""
    from matplotlib.figure import Figure

    from mitos_cli.draw.animation import _robot_patches
    from mitos_cli.draw.world import ROBOT_COLOURS, ROBOT_STYLES
    from mitos_cli.sim import load_world

    world = load_world(packaged_path("worlds", "multirobot.yaml"))
    agent = world.agents[1]
    eight = dataclasses.replace(world, agents=(world.agents[0], *[
        dataclasses.replace(agent, name=f"r{k}") for k in range(1, 8)]))
    ax = Figure().add_subplot()
    robots, trails = _robot_patches(ax, eight, 8)
    import matplotlib.colors as mc

    bodies = [mc.to_hex(body.get_facecolor()) for _, body in robots]
    assert bodies == [ROBOT_COLOURS[i % 6] for i in range(8)]
    assert [(mc.to_hex(t.get_color()), t.get_linestyle()) for t in trails] == [
        (ROBOT_COLOURS[i % 6], ROBOT_STYLES[i // 6]) for i in range(8)]
    alone = load_world(packaged_path("worlds", "corridor.yaml"))
    ((_, body),), (trail,) = _robot_patches(Figure().add_subplot(), alone, 1)
    assert (mc.to_hex(body.get_facecolor()), mc.to_hex(trail.get_color())) == (
        ROBOT_COLOUR, TRAIL_COLOUR)                     # one robot: blue, its trail green


def test_each_robot_of_an_animation_is_named_at_its_goal_and_the_rules_are_the_firsts(tmp_path):
    """In a world of several robots the animation named none (the runs' picture names each at
    its goal), and its panel of fired rules did not say whose they were (the first robot's)."""
    import matplotlib.colors as mc
    from matplotlib.figure import Figure

    from mitos_cli.draw.animation import _robot_patches, _Scene
    from mitos_cli.draw.world import ROBOT_COLOURS
    from mitos_cli.sim import load_world

    world = load_world(Path(__file__).parent / "data" / "crossroads4.yaml")
    ax = Figure().add_subplot()
    _robot_patches(ax, world, 4)
    assert [(t.get_text(), t.xy, mc.to_hex(t.get_color())) for t in ax.texts] == [
        (a.name, (a.goal.x, a.goal.y), ROBOT_COLOURS[i]) for i, a in enumerate(world.agents)]
    alone = Figure().add_subplot()
    _robot_patches(alone, load_world(packaged_path("worlds", "corridor.yaml")), 1)
    assert len(alone.texts) == 0                      # one robot: its goal is plain
    from mitos_cli.sim import simulate
    from mitos_cli.sim.export import explain
    from mitos_cli.sim.planner import FuzzyPlanner

    res = simulate(dataclasses.replace(world, time_limit=0.1))
    scene = _Scene(res, explain(res, FuzzyPlanner()), 300, 100)
    assert "fired rules of `robot`, the first robot, by DOF (the bar's length: 0 to 1)" in [
        t.get_text() for a in scene.fig.axes for t in a.texts]
