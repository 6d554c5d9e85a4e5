"""What a notebook prints for the big objects: a line saying what it is and its sizes."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mitos_cli import load_rulebase
from mitos_cli.engine.evaluation import as_batch, evaluate


def test_reprs_are_one_line_with_the_sizes():
    rb = load_rulebase()
    r = evaluate(rb.compiled, as_batch(rb.compiled, {"road": np.full(1000, 78.0), "size": 45.0,
                                                      "position": 4.0}))
    texts = {repr(rb), repr(rb.rulebase), repr(rb.compiled), repr(r)}
    for text in texts:
        assert "\n" not in text and len(text) < 300, text
    assert "27 rules" in repr(rb.compiled) and "and = min" in repr(rb.compiled)
    assert "1,000 samples x 2 outputs (steering, speed)" in repr(r)
    assert "1 sample x 2 outputs" in repr(rb.run(np.array([[78.0, 45.0, 4.0]])))  # "1 samples"
    assert f"{len(rb.behaviors)} behaviors (avoid_obstacle, " in repr(rb.rulebase)


def test_a_trace_prints_a_line_outside_a_notebook():
    """``rb.trace(...)`` at a Python prompt printed its nested dataclasses: 2,000 characters
    for the paper's 27 rules, 2,700 for ``drive``."""
    rb = load_rulebase()
    assert repr(rb.trace(road=500, size=45, position=4)) == (
        "<Trace of 'avoid_obstacle' at road=500, size=45, position=4: steering 63.93 deg, "
        "speed 37.5 in/s; 4 of 27 rules fired>")
    drive = rb.behavior("drive")
    text = repr(drive.trace(**dict(zip(drive.inputs, [78, 45, 4, 100, 0, 0, 200, 50, 50, 100,
                                                       0, 5, 30]))))
    assert "\n" not in text and len(text) < 200 and "obstacle=100, ...: steering " in text


def test_a_trace_shows_itself_in_a_notebook():
    html = load_rulebase().trace(road=78, size=45, position=4)._repr_html_()
    assert html.startswith("<pre>") and "steering = 65.4 deg" in html


def test_a_finished_run_prints_a_line_and_draws_itself():
    import pytest

    from mitos_cli.resources import packaged_path
    from mitos_cli.sim import load_world, simulate

    result = simulate(load_world(str(packaged_path("worlds", "corridor.yaml"))))
    text = repr(result)
    assert "\n" not in text and len(text) < 200
    ticks = result.ticks
    # timed to the tick that found it at its goal, the last of the ticks recorded
    assert "'corridor' seed 1" in text and \
        f"success after {(ticks - 1) * 0.05:g} s ({ticks} ticks)" in text
    pytest.importorskip("matplotlib")
    assert result._repr_png_().startswith(b"\x89PNG")


def test_many_runs_print_a_line_each_not_every_summary():
    """Runs and WorldRuns printed every run's summary: 1,000 runs were some 370,000
    characters in a notebook."""
    from mitos_cli.sim.runs import Runs, WorldRuns

    summary = {"world": "tiny", "seed": 1, "outcome": "success", "time_s": 8.3}
    world = WorldRuns("tiny", tuple({**summary, "seed": j} for j in range(1000)))
    runs = Runs((world,) * 8)
    for text in (repr(world), repr(runs)):
        assert "\n" not in text and len(text) < 200, text
    assert repr(world) == ("<WorldRuns 'tiny': 1,000 runs: success 100%, collision 0%, "
                           "timeout 0%, stuck 0%>")
    assert repr(runs).startswith("<Runs of 8 worlds: 'tiny' x 1000, ") and "(2 more)" in repr(runs)
    assert repr(WorldRuns("none", ())) == "<WorldRuns 'none': 0 runs>"


def test_no_runs_have_no_rate_nor_mean_and_say_so():
    """A hand-built WorldRuns of no runs raised ZeroDivisionError for a rate and gave a NaN
    mean with a RuntimeWarning."""
    import pytest

    from mitos_cli.errors import InputError
    from mitos_cli.sim.runs import WorldRuns

    none = WorldRuns("none", ())
    for ask, words in ((lambda: none.rate("success"), "its rate of `success` is undefined"),
                       (lambda: none.stat("time_s"), "its mean `time_s` is undefined"),
                       (none.figures, "its rate of `success` is undefined")):
        with pytest.raises(InputError, match="'none' holds no runs: " + words):
            ask()
    with pytest.raises(InputError, match="did you mean `success`"):
        none.rate("sucess")


def test_a_world_a_simulation_a_lockstep_and_their_ticks_print_a_line_each():
    """A World printed every field of every robot, sensor and obstacle (1,000-1,500
    characters; a grid's array summary with it), a Simulation and a Lockstep their address,
    a Tick every beam (840 characters a robot) and ``observe()`` 1,100: a notebook user
    stepping a run by hand was flooded, or told nothing."""
    from mitos_cli.resources import packaged_path
    from mitos_cli.sim import Lockstep, Simulation, load_world

    tiny = load_world(str(Path(__file__).parent / "data" / "tiny.yaml"))
    office = load_world(str(packaged_path("worlds", "office.yaml")))
    corridor = load_world(str(packaged_path("worlds", "corridor.yaml")))
    two = load_world(str(packaged_path("worlds", "multirobot.yaml")))
    sim = Simulation(corridor, seed=4)
    tick = sim.step()
    seen = sim.observe()
    lock = Lockstep(corridor, None, seeds=[1, 2, 3])
    pair = Simulation(two, randomise=True)
    texts = [repr(w) for w in (office, corridor, two, tiny)]
    texts += [repr(office.grid), repr(sim), repr(tick), repr(seen), repr(lock), repr(pair),
              repr(pair.step())]
    for text in texts:
        assert "\n" not in text and len(text) < 300 and "array(" not in text, text
    assert repr(corridor).startswith("<World 'corridor' (") and \
        "1 robot (tricycle), 1 corridor, 1 obstacle, seed 1, dt 0.05 s, time limit 60 s>" \
        in repr(corridor)
    assert "600 x 600 grid" in repr(office) and repr(office.grid).startswith("<Grid 600 x 600 cells")
    assert repr(sim) == "<Simulation 'corridor' seed 4, fuzzy:drive: driving, 1 tick (0.05 s)>"
    assert repr(tick).startswith("<Tick 0 (t = 0 s): at (") and "36 beams a robot" in repr(tick)
    assert repr(pair).startswith("<Simulation 'multirobot' seed 5, randomised, fuzzy:drive, "
                                 "2 robots: driving, 1 tick")
    assert repr(lock) == "<Lockstep of 3 runs of 'corridor', fuzzy:drive: 3 driving, 0 ended>"
    assert "(1 tick)" in repr(sim.result())           # a run cut after one tick ("1 ticks")
    while not sim.done:
        sim.step()
    assert repr(sim) == f"<Simulation 'corridor' seed 4, fuzzy:drive: ended: {sim.outcome} " \
        f"({sim.ticks:,} ticks)>"


def test_a_study_outcome_its_summaries_and_ranks_print_a_line_each(tmp_path):
    """An Outcome printed every row and every summary's rates and means (11,000 characters
    for a study of 12 runs; half a million for docs/study.md's 700), a Summary or a Rank
    1,100-1,200."""
    from mitos_cli.study import Study, make_choices, run_study

    tiny = str(Path(__file__).parent / "data" / "tiny.yaml")
    choices = make_choices(["fuzzy", "potential_field"], ["min", "product", "einstein"], [], [])
    outcome = run_study(Study([tiny], choices, runs=2, seed=1), tmp_path, workers=1)
    texts = [repr(outcome), *map(repr, outcome.summaries), *map(repr, outcome.ranks)]
    for text in texts:
        assert "\n" not in text and len(text) < 300, text
    assert repr(outcome).startswith("<Outcome: 8 of 8 runs (8 now, 0 from before), 1 world x "
                                    "4 choices; 1. ") and repr(outcome).endswith(" (1 more)>")
    fuzzy_min = next(s for s in outcome.summaries if s.choice.label == "fuzzy and=min")
    assert repr(fuzzy_min).startswith(f"<Summary {tiny!r}, fuzzy and=min: 2 runs, success ")
    leader, last = outcome.ranks[0], outcome.ranks[-1]
    assert repr(leader).startswith("<Rank 1: ") and repr(leader).endswith("; leader>")
    assert f"{last.wins} won / {last.losses} lost vs leader, McNemar p " in repr(last)


def test_the_data_of_the_pictures_print_a_line_each():
    """mitos_cli.draw.data's VariablePlot printed every curve's points (20,000 characters for
    the packaged rule base's sheet), a Surface its axes and z, a RuleView every row's view
    (6,000 characters)."""
    from mitos_cli.draw.data import rule_view, sheet, surface

    rb = load_rulebase()
    plots = sheet(rb, values={"road": 78})
    texts = [*map(repr, plots), repr(surface(rb, "steering", "road", "position")),
             repr(rule_view(rb, {"road": 78, "size": 45, "position": 4}))]
    for text in texts:
        assert "\n" not in text and len(text) < 200 and "array(" not in text, text
    assert texts[0] == ("<VariablePlot 'road' (input) [0, 160] in: 3 terms (NARROW, MEDIUM, "
                        "WIDE), marked at 78>")
    assert texts[-2] == ("<Surface of 'steering' over road x position (61 x 61 points, size=50 "
                         "held; NaN at 0)>")
    assert texts[-1] == ("<RuleView of 'avoid_obstacle': 8 of 27 rules fired; steering 65.41 "
                         "deg, speed 32.42 in/s>")
