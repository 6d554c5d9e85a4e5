"""The paper's story end to end (Figure 4 -> Figure 10): untaught, the robot fails at obstacle B
by the corner; the shipped lesson tells it to make a wider turn and it adapts; taught, the same
world succeeds with safe clearance, and the other worlds still succeed."""

from pathlib import Path

import pytest

from mitos_cli.api import default_rulebase_path
from mitos_cli.lang.resolve import load_rules_file
from mitos_cli.resources import data_dir

ROOT = Path(__file__).resolve().parent.parent
LESSON = ROOT / "rulebases" / "lessons" / "wider-turn.lesson"
WORLDS = Path(str(data_dir("worlds")))

pytestmark = pytest.mark.skipif(not (WORLDS / "figure4.yaml").is_file(),
                                reason="worlds/figure4.yaml is not there")


def drive(rulebase, world):
    from mitos_cli.sim.loop import simulate
    from mitos_cli.sim.planner import FuzzyPlanner
    from mitos_cli.sim.worldfile import load_world

    w = load_world(WORLDS / f"{world}.yaml")
    result = simulate(w, FuzzyPlanner(rulebase, w.behavior))
    margin = w.agents[0].robot.safety_margin
    return result, margin


@pytest.fixture(scope="module")
def taught(tmp_path_factory):
    from mitos_cli.teach.lesson import run_lesson
    from mitos_cli.teach.session import Session

    out = tmp_path_factory.mktemp("taught")
    said = []
    session = Session(default_rulebase_path(), out=said.append)
    session.base = LESSON.parent
    run_lesson(session, LESSON.read_text(encoding="utf-8"), str(LESSON))
    session.run(f"save {out / 'taught.rules'}")
    return session, out / "taught.rules", said


def test_untaught_the_robot_fails_at_obstacle_b():
    result, margin = drive(load_rules_file(default_rulebase_path()), "figure4")
    assert result.outcome == "collision" or result.metrics["min_clearance_in"] < margin
    xy = result.pose[-1, 0, :2]
    assert xy[0] > 450 and xy[1] > 0                      # by the corner, around obstacle B


def test_the_lesson_corrects_and_adapts(taught):
    session, _, said = taught
    text = "\n".join(said)
    assert "figure4 with behavior drive: collision" in text
    assert "examples from figure4" in text
    assert "changed (before -> after):" in text and "heading.AHEAD" in text
    assert "figure4 with behavior drive: success" in text
    adapt = [e for e in session.journal.entries if e["op"] == "adapt"][0]
    assert adapt["q"][1] < 0.5 * adapt["q"][0]


def test_taught_the_robot_succeeds_with_safe_clearance(taught):
    _, path, _ = taught
    rb = load_rules_file(path)                            # from the saved files
    result, margin = drive(rb, "figure4")
    assert result.outcome == "success"
    assert result.metrics["min_clearance_in"] >= margin


@pytest.mark.parametrize("world", ["corridor", "slalom"])
def test_the_other_worlds_still_succeed(taught, world):
    _, path, _ = taught
    before, margin = drive(load_rules_file(default_rulebase_path()), world)
    after, _ = drive(load_rules_file(path), world)
    assert before.outcome == "success"
    assert after.outcome == "success"
    assert after.metrics["min_clearance_in"] >= margin


def test_what_was_learned_is_linguistic(taught):
    _, path, _ = taught
    original = default_rulebase_path().read_text(encoding="utf-8").splitlines()
    saved = path.read_text(encoding="utf-8").splitlines()
    assert [a for a, b in zip(original, saved) if a != b] == [
        'terms "mitos.terms.yaml", "drive.terms.yaml"']    # rules untouched: terms moved
    drive_terms = (path.parent / "taught.drive.terms.yaml").read_text(encoding="utf-8")
    assert "AHEAD" in drive_terms
    # the width the paper's eq. 15 gives moved: its comment says it was so before teaching
    terms = (path.parent / "taught.mitos.terms.yaml").read_text(encoding="utf-8")
    assert "MEDIUM: {shape: triangle, peak: 70, width: 17.71}       # eq. 15: width 30 in " \
        "(before teaching)\n" in terms


def test_the_lesson_is_in_words_and_the_taught_rule_base_keeps_its_meaning(taught):
    from mitos_cli.engine.check import check_rulebase

    session, path, said = taught
    text = "\n".join(said)
    lesson = LESSON.read_text(encoding="utf-8")
    assert "at 13s to 14.5s make a wider turn" in lesson and "steering=" not in lesson
    assert "make a wider turn: the hardest steering of the window, one term further" in text
    assert "heading.AHEAD: held at 0 deg, its slopes moved with its neighbours" in text
    assert "steering.ST: unchanged (held at 90 deg)" in text
    assert text.count("interpretability: terms in order, universes covered") == 2  # adapt, save
    codes = {f.code for f in check_rulebase(load_rules_file(path)).findings}
    assert not codes & {"term-order", "coverage", "indistinct", "off-centre"}


def test_500_epochs_of_the_lesson_hold_order_coverage_and_points_at_every_epoch(taught):
    """The constraints at every epoch of a long run; Q against the unconstrained run is
    reported by benchmarks/bench_teach.py (it is not within 10%: see docs/teach.md)."""

    from mitos_cli.lang import interpretability as meaning
    from mitos_cli.teach.adapt import adapt, learned_rulebase, parameterise

    session, _, _ = taught
    compiled = compile_untaught(session)
    X, T = session.training_set(compiled)
    p = parameterise(compiled)
    checked = []

    def check(values):
        rb = learned_rulebase(p, values)
        for name in compiled.inputs + compiled.outputs:
            issues = meaning.variable_issues(rb.variables[name])
            assert not issues, (len(checked), issues)
        for var, term, point in p.held:
            assert meaning.centre(rb.variables[var].term(term)) == point
        checked.append(1)

    result = adapt(compiled, X, T, epochs=500, rate=0.5, parameters=p, on_values=check)
    check(result.values)
    assert len(checked) == len(result.history) - result.rounded
    assert {("heading", "AHEAD"), ("steering", "ST")} <= {(v, t) for v, t, _ in p.held}


def test_500_epochs_of_the_lesson_do_not_stop_beside_a_kink(taught):
    """The steepest step, scaled to the knot that moves most, stopped at Q 367.6 after 500
    epochs (367.1 when converged) where Q still fell along a feasible direction: `heading`'s
    knot at -25.8 deg lay 0.0008 deg from an example's input, where Q's slope in it turns, so
    every full step carried it over and was halved until the other knots hardly moved. Tried
    beside it once it is halved, a step with each knot its own share (halved where its slope
    turns) goes on to 334.9."""
    from mitos_cli.teach.adapt import adapt

    session, _, _ = taught
    compiled = compile_untaught(session)
    X, T = session.training_set(compiled)
    result = adapt(compiled, X, T, epochs=500, rate=0.5)
    assert result.q_after < 345


def compile_untaught(session):
    from mitos_cli.engine.compile import compile_rulebase

    return compile_rulebase(session.original, "drive")


def test_what_docs_teach_md_shows_of_the_shipped_lesson_is_what_it_says(taught):
    """docs/teach.md shows three pieces of the shipped lesson, held by no test: the examples
    `at 13s to 14.5s make a wider turn` makes (its first line is the prompt's echo), what was
    learned in words, and the `git diff` of the saved term sets. Each is what the lesson says
    and saves (`...` standing for any lines)."""
    import doctest
    import re

    from test_docs_api import fenced_blocks

    _, path, said = taught
    text = "\n".join(said) + "\n"
    page = (ROOT / "docs" / "teach.md").read_text(encoding="utf-8")
    blocks = [code for _, _, code in fenced_blocks(page)]
    examples = next(b for b in blocks if b.startswith("drive> at 13s to 14.5s make a wider"))
    words = next(b for b in blocks if b.startswith("learned, in words:"))
    checker, flags = doctest.OutputChecker(), doctest.ELLIPSIS
    for shown in (examples.split("\n", 1)[1], words):
        assert checker.check_output("...\n" + shown + "...", text, flags), shown
    diff = next(b for b in blocks if b.startswith("-      MEDIUM:"))
    saved = "".join(p.read_text(encoding="utf-8") for p in path.parent.glob("taught.*.yaml"))
    written = "".join((ROOT / "rulebases" / n).read_text(encoding="utf-8")
                      for n in ("mitos.terms.yaml", "drive.terms.yaml"))
    for sign, line in re.findall(r"^([-+])(.*)$", diff, re.M):
        assert line in (saved if sign == "+" else written).splitlines(), (sign, line)
