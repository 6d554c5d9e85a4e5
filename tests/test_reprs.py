"""What a notebook prints for the big objects: a line saying what it is and its sizes."""

from __future__ import annotations

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
    assert f"{len(rb.behaviors)} behaviors (avoid_obstacle, " in repr(rb.rulebase)


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
