"""Teaching that keeps the meaning of the words: the constraints of adaptation (under random
corrections), the interpretability findings, corrections in words and what was learned."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mitos_cli.api import default_rulebase_path
from mitos_cli.engine.check import check_rulebase
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.errors import LessonError
from mitos_cli.lang import interpretability as meaning
from mitos_cli.lang.parse import parse_rules
from mitos_cli.lang.resolve import build_rulebase, load_rules_file
from mitos_cli.lang.termfile import parse_termset
from mitos_cli.teach.adapt import adapt, feasible, learned_rulebase, parameterise
from mitos_cli.teach.instructions import Window, hedged, instruction, scale_of, targets

PAPER = load_rules_file(default_rulebase_path())
AVOID = compile_rulebase(PAPER, "avoid_obstacle")
FOLLOW = compile_rulebase(PAPER, "follow_route")


def constraints_hold(compiled, p, values) -> None:
    """Order, coverage, distinctness and held points of the learned terms."""
    rb = learned_rulebase(p, values)
    assert feasible(p, values)
    for name in compiled.inputs + compiled.outputs:
        var = rb.variables[name]
        assert meaning.variable_issues(var) == [], name
    for var, term, point in p.held:
        assert meaning.centre(rb.variables[var].term(term)) == pytest.approx(point, abs=1e-9)
    for name in compiled.inputs + compiled.outputs:        # each nearer its own written place
        written = sorted(compiled.variables[name].terms, key=meaning.centre)
        now = {t.name: meaning.centre(t) for t in rb.variables[name].terms}
        places = [meaning.centre(t) for t in written]
        for j, t in enumerate(written):
            if j:
                assert now[t.name] >= (places[j - 1] + places[j]) / 2 - 1e-9, (name, t.name)
            if j + 1 < len(written):
                assert now[t.name] <= (places[j] + places[j + 1]) / 2 + 1e-9, (name, t.name)


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000), n=st.integers(1, 30), behavior=st.sampled_from(["a", "f"]))
def test_random_corrections_keep_order_coverage_distinctness_and_points(seed, n, behavior):
    compiled = AVOID if behavior == "a" else FOLLOW
    rng = np.random.default_rng(seed)
    lo = np.array([compiled.variables[k].universe[0] for k in compiled.inputs])
    hi = np.array([compiled.variables[k].universe[1] for k in compiled.inputs])
    X = rng.uniform(lo, hi, (n, len(lo)))
    T = np.column_stack([rng.uniform(*compiled.variables[o].universe, n)
                         for o in compiled.outputs])
    T[rng.random(T.shape) < 0.3] = np.nan                   # outputs left out
    p = parameterise(compiled)
    seen = []
    result = adapt(compiled, X, T, epochs=15, rate=0.9, parameters=p,
                   on_values=lambda v: seen.append(v.copy()))
    for v in seen + [result.values]:                       # every epoch, and the rounded end
        constraints_hold(compiled, p, v)
    epochs = result.history[:-1] if result.rounded else result.history
    assert all(b <= a for a, b in zip(epochs, epochs[1:]))  # Q never increases
    assert result.q_after <= result.q_before


def test_one_correction_does_not_move_a_term_onto_its_neighbour():
    """The issue's own example: `correct heading=-5 -> steering=60` pulled `LEFT`'s peak (and
    `FAR_LEFT`'s edge) to -1.87 deg, next to `AHEAD`'s 0. A term now moves at most half the
    way to its neighbour as written; unconstrained, it still goes all the way."""
    X = np.array([[-5.0]])
    T = np.array([[60.0]])
    held = adapt(FOLLOW, X, T, epochs=5)
    rb = learned_rulebase(held.parameters, held.values)
    assert -42.5 <= meaning.centre(rb.variables["heading"].term("LEFT")) <= -12.5 + 1e-9
    free = adapt(FOLLOW, X, T, epochs=5, constrained=False)
    rb = learned_rulebase(free.parameters, free.values)
    assert meaning.centre(rb.variables["heading"].term("LEFT")) > -12.5


def test_unconstrained_moves_what_constrained_holds():
    X = np.array([[78.0, 45.0, 4.0], [90.0, 30.0, -3.0]])
    T = np.array([[60.0, 20.0], [120.0, np.nan]])
    free = adapt(AVOID, X, T, epochs=15, constrained=False)
    held = adapt(AVOID, X, T, epochs=15)
    assert free.q_after < held.q_after < held.q_before
    names = {(v, t) for v, t, _ in held.parameters.held}
    assert ("steering", "ST") in names and ("position", "CENTER") in names
    released = parameterise(AVOID, released={("position", "CENTER")})
    assert ("position", "CENTER") not in {(v, t) for v, t, _ in released.held}
    frozen = parameterise(AVOID, frozen_terms={("steering", "LS")})
    ls = next(i for i, k in enumerate(frozen.knots) if k.label == "steering: LS")
    assert frozen.projector[ls, ls] == 0.0


TERMS = """
variables:
  x:
    role: input
    universe: [0, 10]
    terms:
      A: {shape: triangle, points: [0, 2, 4]}
      B: {shape: triangle, points: [2, 4, 6]}
      C: {shape: triangle, points: [5, 8, 10]}
  y: {role: output, universe: [0, 100], terms: {S: 10, M: 50, M2: 52, L: 90}}
  z:
    role: input
    universe: [-10, 10]
    terms:
      NEG: {shape: left_shoulder, points: [-6, -2]}
      MID: {shape: triangle, points: [-2, 1, 4]}
      POS: {shape: right_shoulder, points: [2, 6]}
  w:
    role: input
    universe: [0, 10]
    terms:
      P: {shape: triangle, points: [0, 5, 10]}
      Q: {shape: triangle, points: [0.2, 5, 9.8]}
  v:
    role: input
    universe: [0, 10]
    terms:
      HI: {shape: triangle, points: [4, 6, 8]}
      LO: {shape: triangle, points: [0, 2, 4]}
      MD: {shape: triangle, points: [2, 4, 6]}
"""


def test_check_reports_each_interpretability_problem():
    rb = build_rulebase(parse_rules("behavior b:\n r1: if x is A and z is MID and w is P "
                                    "and v is HI then y is S\nend\n"),
                        (parse_termset(TERMS),), ("t.yaml",))
    found = {(f.code, f.message.split("`")[1]) for f in check_rulebase(rb).findings}
    assert ("coverage", "x") in found                      # between B (6) and C (5..8)
    assert ("indistinct", "y.M") in found                 # 50 and 52
    assert ("indistinct", "w.P") in found                 # two nearly equal triangles
    assert ("term-order", "v.LO") in found                # written after HI, lies below it
    assert ("off-centre", "z.MID") in found               # NEG / POS mirror about 0
    assert not [f for f in check_rulebase(PAPER).findings
                if f.code in ("term-order", "coverage", "indistinct", "off-centre")]


@pytest.mark.parametrize("terms", [
    "{STOP: 0, LOW: 1000, HIGH: 3000}",           # in order: 0 and 3000 mirror about anything
    "{SHUT: 0, OPEN: 1000, HALF: 500}",           # out of order: term-order says so
    "{N: {shape: triangle, points: [400, 600, 800]}, L: {shape: triangle, points: [0, 200, 400]}, "
    "M: {shape: triangle, points: [200, 400, 600]}}"])
def test_off_centre_needs_a_symmetry_the_writer_meant(terms):
    """`vent: {SHUT: 0, OPEN: 1, HALF: 0.5}` was told "`OPEN` is centred on 1, off the point
    0.25 its neighbours mirror each other about; move it back to 0.25"."""
    text = ("variables:\n  x: {role: input, universe: [0, 3000], terms: {A: {shape: "
            "left_shoulder, points: [0, 3000]}}}\n"
            f"  y: {{role: output, universe: [0, 3000], terms: {terms}}}\n")
    var = parse_termset(text).variables[1]
    assert "off-centre" not in [i.code for i in meaning.variable_issues(var)]


@pytest.mark.parametrize("terms, universe, flagged", [
    # 3 values from 40 to 60: half of 10 is 5 (the universe's 100 / 2 / 2 would be 25)
    ("{LO: 40, MID: 44, HI: 60}", "[0, 100]", [("LO", "MID", "closer than 5,")]),
    # written in a corner of a wide universe: as far apart as their number allows
    ("{STOP: 0, CRAWL: 5, SLOW: 10}", "[0, 60]", []),
    ("{LB: 30, LM: 50, LS: 70, ST: 90, RS: 110, RM: 130, RB: 150}", "[30, 150]", []),
])
def test_crisp_values_are_kept_apart_by_their_own_spread(terms, universe, flagged):
    """docs/teach.md said "spread evenly over the universe"; the measure (one for check and
    adapt) spreads them from the smallest to the largest, and the docs now say so."""
    text = ("variables:\n  x: {role: input, universe: [0, 1], terms: {A: {shape: "
            "left_shoulder, points: [0, 1]}}}\n"
            f"  o: {{role: output, universe: {universe}, terms: {terms}}}\n")
    var = parse_termset(text).variables[1]
    found = [i for i in meaning.variable_issues(var) if i.code == "indistinct"]
    assert [(i.terms[0], i.terms[1]) for i in found] == [f[:2] for f in flagged]
    for issue, (_, _, says) in zip(found, flagged):
        assert says in issue.message
    values = np.array([t.params[0] for t in var.terms])
    assert meaning.least_distance(values) == pytest.approx(
        0.5 * (values.max() - values.min()) / (len(values) - 1))


def test_coverage_is_exact_at_a_crossing():
    corners = np.array([[-np.inf, -np.inf, 0.0, 4.0], [2.0, 6.0, np.inf, np.inf]])
    low, where = meaning.coverage(corners, (0.0, 10.0))
    assert low == pytest.approx(0.25) and where == pytest.approx(3.0)   # (4 - x) / 4 = (x - 2) / 4



def _input(terms: str, universe: str = "[0, 100]"):
    return parse_termset(f"variables:\n  x: {{role: input, universe: {universe}, terms: "
                         f"{terms}}}\n").variables[0]


@pytest.mark.parametrize("terms, universe, stretches", [
    # the audit's: LOW falls to 0.5 at 35, HIGH rises to it at 65; least 0.2 at 50
    ("{LOW: {shape: left_shoulder, points: [10, 60]}, HIGH: {shape: right_shoulder, "
     "points: [40, 90]}}", "[0, 100]", "x in [35, 65]"),
    # two dips, the ends rounded to the universe's thousandth (100/3 -> 33.3)
    ("{A: {shape: left_shoulder, points: [0, 50]}, B: {shape: triangle, points: "
     "[100/3, 50, 200/3]}, C: {shape: right_shoulder, points: [60, 100]}}".replace(
         "100/3", repr(100 / 3)).replace("200/3", repr(200 / 3)),
     "[0, 100]", "x in [25, 41.7] and [58.3, 80]"),
    # a gap on [30, 40] and a dip at 78: the stretches around the gap are named too
    ("{A: {shape: left_shoulder, points: [10, 30]}, B: {shape: triangle, points: "
     "[40, 60, 90]}, C: {shape: right_shoulder, points: [70, 90]}}", "[0, 100]",
     "x in [20, 50] and [75, 80]"),
    # only around a gap on [4, 6]: each shoulder falls from 1 to 0 between two breakpoints,
    # which were all the measure saw (no finding)
    ("{LO: {shape: left_shoulder, points: [2, 4]}, HI: {shape: right_shoulder, points: "
     "[6, 8]}}", "[0, 10]", "x in [3, 7]"),
    # gaussians: on samples, the ends where the largest membership crosses 0.5
    ("{LO: {shape: gaussian, mean: 0, sigma: 1}, HI: {shape: gaussian, mean: 10, sigma: 1}}",
     "[0, 10]", "x in [1.18, 8.82]"),
])
def test_coverage_names_the_stretches_below_the_threshold(terms, universe, stretches):
    """`mitos check` said "covered only to 0.2 at x = 50", one point, where the issue asks
    for the input range: the stretches below 0.5 are named, the least kept."""
    (issue,) = [i for i in meaning.variable_issues(_input(terms, universe))
                if i.code == "coverage"]
    assert f"less than 0.5 for {stretches} (every point" in issue.message


def test_coverage_stretches_end_where_the_largest_membership_is_the_threshold():
    var = _input("{LOW: {shape: left_shoulder, points: [10, 60]}, HIGH: {shape: "
                 "right_shoulder, points: [40, 90]}}")
    corners = np.array([t.corners for t in var.terms], dtype=float)
    ((a, b),) = meaning.uncovered(corners, var.universe)
    assert (a, b) == pytest.approx((35.0, 65.0))
    x = np.linspace(0, 100, 1001)
    top = meaning.memberships(corners, x).max(axis=0)
    ((sa, sb),) = meaning.uncovered_on(top, x)          # on samples: the same stretch
    assert (sa, sb) == pytest.approx((35.0, 65.0))
    (issue,) = meaning.variable_issues(var)
    assert issue.message.startswith("`x` is covered only to 0.2 at x = 50, less than 0.5 "
                                    "for x in [35, 65]")
    gapped = _input("{A: {shape: left_shoulder, points: [10, 30]}, B: {shape: triangle, "
                    "points: [40, 60, 90]}, C: {shape: right_shoulder, points: [70, 90]}}")
    (issue,) = [i for i in meaning.variable_issues(gapped) if i.code == "coverage"]
    assert "covered only to 0.4 at x = 78 outside its term gaps, less" in issue.message
    around = _input("{LO: {shape: left_shoulder, points: [2, 4]}, HI: {shape: right_shoulder, "
                    "points: [6, 8]}}", "[0, 10]")
    (issue,) = meaning.variable_issues(around)
    assert issue.message.startswith("`x` is covered to 0.5 except next to its term gaps, "
                                    "less than 0.5 for x in [3, 7] (every point")
    vertical = _input("{LO: {shape: trapezoid, points: [0, 0, 3, 3]}, HI: {shape: trapezoid, "
                      "points: [7, 7, 10, 10]}}", "[0, 10]")
    assert meaning.variable_issues(vertical) == []       # the gap (3, 7) is all there is

def test_hedged_terms_move_along_the_scale():
    steering = PAPER.variables["steering"]
    assert hedged(steering, "LM", ()) == 50
    assert hedged(steering, "LM", ("very",)) == 40                 # half a term further left
    assert hedged(steering, "RM", ("extremely",)) == 150
    assert hedged(steering, "LS", ("somewhat",)) == 80             # half a term toward ST
    assert hedged(steering, "ST", ("very",)) == 90
    with pytest.raises(LessonError, match="has no meaning"):
        hedged(steering, "LM", ("seldom",))


def window(steering, speed=None, gap_left=None, gap_right=None):
    n = len(steering)
    outputs = {"steering": np.array(steering, dtype=float)}
    if speed is not None:
        outputs["speed"] = np.array(speed, dtype=float)
    inputs = {"gap_left": np.array(gap_left if gap_left else [50.0] * n),
              "gap_right": np.array(gap_right if gap_right else [50.0] * n)}
    return Window(outputs, inputs, PAPER.variables)


@pytest.mark.parametrize("words, steering, expected", [
    ("turn harder", [70, 85, 90, 110], [50, 65, np.nan, 130]),
    ("turn less", [50, 85, 90, 130], [70, 90, 90, 110]),
    ("make a wider turn", [77, 67, 70], [47, 47, 47]),
    ("keep right", [90, 140], [110, 150]),
])
def test_steering_instructions_in_term_steps(words, steering, expected):
    np.testing.assert_allclose(targets(instruction(tuple(words.split())), window(steering)),
                               expected)


def test_a_wider_turn_is_one_turn():
    """A window turning both ways (left to 50, right 130) is refused: one target for both turns
    would steer the left turn hard right. A slight drift past straight (88) is one turn."""
    with pytest.raises(LessonError, match="turned both ways in that window \\(1 of 4 ticks"):
        targets(instruction(("make", "a", "wider", "turn")), window([50, 60, 70, 130]))
    np.testing.assert_allclose(targets(instruction(("make", "a", "wider", "turn")),
                                       window([70, 60, 92])), [40, 40, 40])


def test_speed_and_wall_instructions():
    w = window([90, 90], speed=[25, 60], gap_left=[5, 40], gap_right=[40, 5])
    np.testing.assert_allclose(targets(instruction(("slow", "down")), w), [15, 50])
    np.testing.assert_allclose(targets(instruction(("speed", "up")), w), [35, 60])
    np.testing.assert_allclose(targets(instruction(tuple(["keep", "further", "from", "the", "wall"])),
                                       w), [110, 70])           # away from the nearer side


def test_keeping_from_the_wall_needs_a_nearer_side():
    """Equal gaps (150 and 150 in the open of a crossing: no wall in sight) have no nearer side:
    they gave a target one term to the right; now no example, and a window of them is refused."""
    wall = instruction(tuple(["keep", "further", "from", "the", "wall"]))
    w = window([70, 70, 90], gap_left=[150, 150, 40], gap_right=[150, 150, 5])
    np.testing.assert_allclose(targets(wall, w), [np.nan, np.nan, 70])
    with pytest.raises(LessonError, match="equal on both sides at every tick"):
        targets(wall, window([70, 90], gap_left=[150, 150], gap_right=[150, 150]))


def test_unknown_instruction_says_did_you_mean_and_lists_them():
    with pytest.raises(LessonError) as info:
        instruction(("make", "a", "wide", "turn"))
    text = str(info.value.render() if hasattr(info.value, "render") else info.value)
    assert "unknown instruction `make a wide turn`" in text
    assert info.value.hint == "did you mean `make a wider turn`?"
    assert "`turn harder`" in info.value.expected and "`keep right`" in info.value.expected


def test_two_instructions_joined_by_and_are_said_one_per_line():
    """`at 12s to 13s make a wider turn and slow down` offered only `make a wider turn`, as if
    the rest were a typo: each instruction is its own `at` line."""
    with pytest.raises(LessonError) as info:
        instruction(("make", "a", "wider", "turn", "and", "slow", "down"))
    assert info.value.message == "unknown instruction `make a wider turn and slow down`"
    assert info.value.hint == ("one instruction per `at` line: `at ... make a wider turn`, "
                               "then `at ... slow down` (same window)")


@pytest.mark.parametrize("said, hint", [
    # an output named alone, or with a term of it but no `is`: it was "unknown instruction
    # `steering`", hint "docs/teach.md defines each instruction" (and `speed SLOW`: "did you
    # mean `speed up`?")
    ("steering", "say what `steering` should be: `steering is TERM` (`steering is LB`) or "
     "`steering=VALUE`"),
    ("speed SLOW", "say what `speed` should be: `speed is SLOW` or `speed=VALUE`"),
])
def test_an_output_named_as_an_instruction_is_said_to_need_is_or_a_value(said, hint):
    from mitos_cli.teach.session import Session

    s = Session(default_rulebase_path(), out=[].append)
    s.run("use drive")
    s.run("simulate figure4")
    with pytest.raises(LessonError) as info:
        s.run(f"at 13s to 14s {said}")
    assert info.value.message == f"unknown instruction `{said}`"
    assert info.value.hint == hint


def test_a_window_between_two_ticks_names_the_ticks_around_it():
    """`at 13.01s to 13.02s` said "no recorded tick between 13.01 s and 13.02 s" alone."""
    from mitos_cli.teach.session import Session

    s = Session(default_rulebase_path(), out=[].append)
    s.run("use drive")
    s.run("simulate figure4")
    with pytest.raises(LessonError) as info:
        s.run("at 13.01s to 13.02s turn harder")
    assert info.value.message == "no recorded tick between 13.01 s and 13.02 s"
    assert info.value.hint == ("the ticks of the run are 0.05 s apart: the nearest are at 13 s "
                               "and 13.05 s (`at 13.01s` alone takes the nearest tick)")


def test_scale_centre_is_the_mirror_point():
    assert scale_of(PAPER.variables["steering"]).centre == 3.0       # ST


def test_an_unknown_instruction_at_the_prompt_names_its_place_and_the_list(tmp_path):
    import subprocess
    import sys

    lesson = "use drive\nsimulate figure4\nat 13s to 14s make a wide turn\n"
    # run where the session may live: in the repository it would stay, for `--resume` there
    res = subprocess.run([sys.executable, "-m", "mitos_cli", "teach", "rulebases/mitos.rules",
                          "--lesson", "-"], cwd=tmp_path, input=lesson, capture_output=True,
                         text=True, timeout=120)
    assert res.returncode == 1
    # marked at its words (it was marked from the `at`, at column 1)
    assert "<stdin>:3:15: lesson error: unknown instruction `make a wide turn`" in res.stderr
    assert "    at 13s to 14s make a wide turn\n" + " " * 18 + "^" * 16 + "\n" in res.stderr
    assert "did you mean `make a wider turn`?" in res.stderr
    assert "`turn harder`, `turn less`, `make a wider turn`, `slow down`" in res.stderr
    assert "Traceback" not in res.stderr


def test_outside_the_repository_packaged_rules_and_lessons_are_found_and_save_remembers(
        tmp_path):
    import subprocess
    import sys

    def teach(*args, stdin=None):
        return subprocess.run([sys.executable, "-m", "mitos_cli", "teach", *args], cwd=tmp_path,
                              input=stdin, capture_output=True, text=True, timeout=120)

    res = teach("rulebases/mitos.rules", "--lesson", "-",
                stdin="correct road=78 size=45 position=4 -> steering is LM\nsave a.rules\n")
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "a.rules").is_file()
    res = teach("--resume", stdin="correct road=78 size=45 position=4 -> steering=55\n"
                                  "adapt epochs 2\nsave\n")
    assert res.returncode == 0, res.stderr
    assert "saved a.rules" in res.stdout                   # where the earlier `save` went
    res = teach("--lesson", "no-such-lesson")
    assert res.returncode == 1 and "lesson `no-such-lesson` not found" in res.stderr
    assert "a packaged lesson: wider-turn" in res.stderr
    res = teach("rulebases/mitos.rules", "--lesson", "wider-trun")     # a packaged name, mistyped
    assert res.returncode == 1 and "did you mean `wider-turn`?" in res.stderr


def test_a_session_from_python_finds_the_packaged_rule_base(tmp_path, monkeypatch):
    """docs/teach.md's "From Python" example, run outside the repository."""
    from mitos_cli.teach.session import Session

    monkeypatch.chdir(tmp_path)
    s = Session("rulebases/mitos.rules", out=[].append)
    assert s.rules_path == default_rulebase_path()
    s.run("correct road=78 size=45 position=4 -> steering=60")
    s.run("adapt epochs 20")
    s.run("save taught.rules")
    assert (tmp_path / "taught.rules").is_file()


def test_a_session_on_a_path_too_long_to_look_up_says_so(tmp_path, monkeypatch):
    """A journal's rule base named by a path the system cannot look up (a part over 255
    characters) is a positioned refusal, not an OSError (found by the fuzzing campaign)."""
    from mitos_cli.errors import MitosError
    from mitos_cli.teach.session import Session

    monkeypatch.chdir(tmp_path)
    with pytest.raises(MitosError, match="too long"):
        Session(str(tmp_path / ("x" * 300 + "mitos.rules")), out=[].append)


def test_simulation_corrections_name_the_robot():
    from mitos_cli.teach.session import Session

    said = []
    s = Session(default_rulebase_path(), out=said.append)
    s.run("use drive")
    s.run("simulate multirobot robot oncoming")
    assert "multirobot (robot oncoming) with behavior drive" in said[-1]
    s.run("at 2s steering is ST")
    first = s.state.examples[-1].inputs
    s.run("simulate multirobot")
    s.run("at 2s steering is ST")
    assert s.state.examples[-1].inputs != first               # the other robot's perception
    with pytest.raises(LessonError, match="did you mean `oncoming`"):
        s.run("simulate multirobot robot oncomin")


def test_a_robot_is_named_as_its_world_names_it(tmp_path, monkeypatch):
    """A world's robot may be named with a space or in digits (`name: "cart 2"`, as `mitos
    simulate` reads it): `robot NAME` takes it quoted, where it was a syntax error. An unknown
    robot is marked at its own name: where the name was also a word before it (the world's
    name), the caret stood under the world."""
    from mitos_cli.teach.prompt import at_prompt
    from mitos_cli.teach.session import Session
    from mitos_cli.teach.simulation import world_path

    monkeypatch.chdir(tmp_path)
    text = world_path("multirobot").read_text()
    (tmp_path / "two.yaml").write_text(text.replace("name: oncoming", 'name: "cart 2"'))
    said = []
    s = Session(default_rulebase_path(), out=said.append)
    s.run("use drive")
    s.run('simulate two.yaml robot "cart 2"')
    assert "two (robot cart 2) with behavior drive" in said[-1]
    line = "simulate multirobot seed 3 robot multirobot"
    with pytest.raises(LessonError) as info:
        s.run(line, "<prompt>", 4)
    assert at_prompt(info.value, line, 4).render().splitlines()[:3] == [
        "<prompt>:4:34: command error: unknown robot `multirobot` of `multirobot`",
        "    " + line, " " * 37 + "^" * 10]


def test_a_robot_that_stopped_is_corrected_only_up_to_its_stop():
    """In a world of several robots, one that reached its goal stands still while the others
    drive on: its window (and its verdict) are its own, not the world's."""
    from mitos_cli.teach.session import Session

    said = []
    s = Session(default_rulebase_path(), out=said.append)
    s.run("use drive")
    s.run("simulate multirobot")
    first = min(s.simulation.result.robot_metrics, key=lambda m: m["time_s"])["name"]
    s.run(f"simulate multirobot robot {first}")
    rec = s.simulation
    own = rec.result.robot_metrics[rec.robot]
    assert rec.end < float(rec.t[-1])                   # the other robot drives on
    assert f"success after {own['time_s']:g} s" in said[-1]
    assert f"(0 to {rec.end:g} s)" in said[-1]
    with pytest.raises(LessonError, match=f"robot {first}'s run lasted 0 to"):
        s.run(f"at {float(rec.t[-1]):g}s steering=80")
    s.run(f"at {rec.end:g}s steering=80")               # its last tick is still its own


def test_the_measures_memberships_are_the_terms_own():
    for var in PAPER.variables.values():
        terms = [t for t in var.terms if t.corners is not None]
        if not terms:
            continue
        corners = np.array([t.corners for t in terms], dtype=float)
        x = np.unique(np.concatenate([np.linspace(*var.universe, 97),
                                      corners[np.isfinite(corners)]]))
        expected = np.array([t.membership(x) for t in terms])
        np.testing.assert_allclose(meaning.memberships(corners, x), expected, atol=1e-12)


SMOOTH = """
variables:
  g:
    role: input
    universe: [0, 10]
    terms:
      LO: {shape: gaussian, mean: 0, sigma: 2.5}
      MD: {shape: gaussian, mean: 5, sigma: 2.5}
      HI: {shape: gaussian, mean: 10, sigma: 2.5}
  n:
    role: input
    universe: [0, 10]
    terms:
      LO: {shape: gaussian, mean: 0, sigma: 1}
      HI: {shape: gaussian, mean: 10, sigma: 1}
  b:
    role: input
    universe: [3.5, 10]
    terms:
      P: {shape: bell, center: 5, width: 2, slope: 2}
      Q: {shape: bell, center: 5.2, width: 2, slope: 2}
      R: {shape: right_shoulder, points: [5.5, 7.5]}
  s:
    role: input
    universe: [-5, 5]
    terms:
      NEG: {shape: sigmoid, inflection: 0, slope: -2}
      POS: {shape: sigmoid, inflection: 0.5, slope: 2}
  o:
    role: input
    universe: [-5, 5]
    terms:
      NEG: {shape: sigmoid, inflection: -1, slope: -2}
      POS: {shape: sigmoid, inflection: 1, slope: 2}
      MID: {shape: gaussian, mean: 0, sigma: 1}
  y:
    role: output
    universe: [0, 100]
    terms: {S: 50}
"""


def test_findings_for_every_shape_on_samples():
    """Gaussians, bells and sigmoids are measured on RESOLUTION samples of the universe."""
    rb = build_rulebase(parse_rules("behavior b:\n r1: if g is LO and n is LO and b is P "
                                    "and s is NEG and o is POS then y is S\nend\n"),
                        (parse_termset(SMOOTH),), ("t.yaml",))
    v = rb.variables
    assert meaning.variable_issues(v["g"]) == []            # covered to exp(-0.5) = 0.61
    (cover,) = meaning.variable_issues(v["n"])
    assert cover.code == "coverage" and "covered only to 3.727e-06 at n = 5" in cover.message
    found = {(i.code, i.terms) for i in meaning.variable_issues(v["b"])}
    assert found == {("indistinct", ("P", "Q"))}
    (low,) = meaning.variable_issues(v["s"])                # NEG and POS cross at 0.25: 0.42
    assert low.code == "coverage" and "at s = 0.25" in low.message
    (order,) = meaning.variable_issues(v["o"])              # by the registry's centres
    assert order.code == "term-order" and order.terms == ("POS", "MID")
    codes = {f.code for f in check_rulebase(rb).findings}
    assert {"coverage", "indistinct", "term-order"} <= codes


def test_sampled_measures_agree_with_the_exact_ones():
    """The samples hold the breakpoints, so piecewise-linear terms measure exactly as on the
    breakpoints alone: the resolution only matters where smooth terms bend between samples."""
    for var in PAPER.variables.values():
        sets = [t for t in var.terms if t.corners is not None]
        if len(sets) < 2:
            continue
        corners = np.array([t.corners for t in sets], dtype=float)
        x = meaning.sample_points(sets, var.universe)
        mu = meaning.sampled(sets, x)
        np.testing.assert_allclose(meaning.similarity_on(mu, x),
                                   meaning.similarity(corners, var.universe), atol=1e-12)
        exact = meaning.coverage(corners, var.universe)[0]
        assert meaning.coverage_on(mu, x, var.universe)[0] == pytest.approx(exact, abs=1e-12)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_tied_ruspini_partitions_hold_at_every_ordered_point(seed):
    """What adaptation does not measure (``by_construction``) holds wherever the knots go in
    order: covered to 0.5, no two sets more than 1/3 alike."""
    from mitos_cli.teach.adapt import ruspini

    p = parameterise(compile_rulebase(PAPER, "drive"))
    assert all(part.by_construction for part in p.partitions)
    rng = np.random.default_rng(seed)
    values = p.values.copy()
    for ids in p.order:
        lo, hi = p.lo[ids[0]], p.hi[ids[0]]
        values[ids] = np.sort(rng.uniform(lo, hi, len(ids)))
    for part in p.partitions:
        cover, similar = meaning.measures(part.corners(values), part.universe)
        assert cover >= 0.5 - 1e-9 and similar <= 1 / 3 + 1e-9, part.var
    gappy = np.array([[-np.inf, -np.inf, 0.0, 4.0], [2.0, 6.0, np.inf, np.inf]])
    assert not ruspini(np.array([[-1, -1, 0, 1], [2, 3, -1, -1]]), gappy, (0.0, 10.0))


def _cube(mu: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Similarity as it was formed before 2026-12-03: every pair's minima and maxima at once."""
    both = np.minimum(mu[:, None, :], mu[None, :, :])
    either = np.maximum(mu[:, None, :], mu[None, :, :])
    dx = np.diff(x)

    def area(m):
        return ((m[..., 1:] + m[..., :-1]) * 0.5 * dx).sum(axis=-1)

    inter, union = area(both), area(either)
    return np.divide(inter, union, out=np.zeros_like(inter), where=union > 0)


def test_similarity_keeps_its_bits_by_rows_by_overlap_and_for_repeated_terms():
    rng = np.random.default_rng(20261210)
    for _ in range(200):
        t = int(rng.integers(1, 10))
        x = np.unique(rng.uniform(0, 10, int(rng.integers(2, 200))))
        mu = np.clip(rng.normal(0.2, 0.5, (t, len(x))), 0.0, 1.0)
        mu[rng.integers(t)] = 0.0                          # a term 0 everywhere
        mu[rng.integers(t)] = mu[rng.integers(t)]          # a repeated term
        assert np.array_equal(meaning.similarity_on(mu, x).view(np.int64),
                              _cube(mu, x).view(np.int64))


def test_many_terms_are_measured_in_memory_proportional_to_them():
    """The fuzz pass of 2026-12-03 (`mitos check` through the CLI, FLL): the dimmer's output
    with `term: HIGH Sigmoid 0.75 20` repeated 740 times was a MemoryError (the similarity of
    every pair formed a [740, 740, 1,000] cube of minima and another of maxima, 4.4 GB each);
    200 triangles in one variable took 4.4 GB. Now: repeated terms are measured once, and a
    row at a time, only against the terms it overlaps."""
    import resource
    import time

    x = np.linspace(0.0, 1.0, 1001)
    mu = np.vstack([1 / (1 + np.exp(-20 * (x - 0.75)))] * 740 + [np.exp(-(x / 0.2) ** 2 / 2)])
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    start = time.process_time()
    s = meaning.similarity_on(mu, x)
    assert s.shape == (741, 741) and s[0, 739] == 1.0 and s[0, 740] < 1.0
    triangles = np.array([[c - 0.01, c, c + 0.01, c + 0.01] for c in np.linspace(0, 1, 400)])
    xs = meaning.breakpoints(triangles, (0.0, 1.0))
    meaning.similarity_on(meaning.memberships(triangles, xs), xs)
    assert time.process_time() - start < 10               # was minutes, or a MemoryError
    grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - peak     # KB on Linux
    assert grown < 500_000                                                   # was gigabytes


def _old_most(mu: np.ndarray, x: np.ndarray) -> tuple[float, int, int]:
    """The most similar pair as `mitos check` found it before 2026-12-05: the whole [t, t]
    matrix, its diagonal set to -1, the first largest in reading order."""
    s = _cube(mu, x)
    np.fill_diagonal(s, -1.0)
    i, j = np.unravel_index(int(np.argmax(s)), s.shape)
    return float(s[i, j]), int(i), int(j)


def _agrees(new: tuple[float, int, int], mu: np.ndarray, x: np.ndarray) -> None:
    """``new`` is a most similar pair of the whole matrix (its similarity the matrix's largest
    to rounding, since each pair is summed over its own stretch of the points), and the
    matrix's own first where no other pair comes within rounding of it."""
    old = _old_most(mu, x)
    s = _cube(mu, x)
    np.fill_diagonal(s, -1.0)
    assert abs(new[0] - old[0]) <= 1e-12 and abs(s[new[1], new[2]] - old[0]) <= 1e-12
    if np.sum(s >= old[0] - 1e-9) == 1:
        assert new[1:] == old[1:]


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), t=st.integers(1, 14), n=st.integers(2, 80),
       narrow=st.booleans(), repeats=st.integers(0, 4), zeros=st.integers(0, 2))
def test_the_most_similar_pair_is_the_one_the_whole_matrix_gave(seed, t, n, narrow, repeats,
                                                                  zeros):
    """Measuring only pairs whose supports overlap, each on its own stretch, and repeated
    terms once, finds the pair the whole matrix did, its similarity to rounding: ties, terms 0
    everywhere, -0.0, terms that all overlap or none."""
    rng = np.random.default_rng(seed)
    x = np.unique(rng.uniform(0, 10, n))
    mu = np.clip(rng.normal(0.2, 0.5, (t, len(x))), 0.0, 1.0)
    if narrow:                                             # supports of a few points
        for row in mu:
            a = int(rng.integers(0, len(x)))
            row[:a] = 0.0
            row[a + int(rng.integers(0, 4)):] = 0.0
    for _ in range(zeros):
        mu[rng.integers(t)] = -0.0 if rng.random() < 0.5 else 0.0
    for _ in range(repeats):
        mu[rng.integers(t)] = mu[rng.integers(t)]
    _agrees(meaning.most_similar_on(mu, x), mu, x)


def test_a_variable_of_20000_terms_is_checked_in_memory_proportional_to_them():
    """The fuzz pass of 2026-12-05: an FLL output with 20,000 terms took 6.6 GB and 85 s in
    `mitos check` (the [t, t] matrix of similarities, twice), or a MemoryError. Its terms
    as memberships on the samples are 160 MB; the check now needs little more."""
    import time
    import tracemalloc

    from mitos_cli.lang.terms import Term, Variable

    terms = tuple(Term(f"L{i}", "gaussian", ((i % 200) / 200, 0.001 if i % 2 else 0.2))
                  for i in range(20_000))
    var = Variable("y", "output", (0.0, 1.0), terms)
    tracemalloc.start()
    start = time.process_time()
    try:
        found = meaning.variable_issues(var)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert time.process_time() - start < 30
    assert peak < 400e6                                    # was over 6 GB
    assert {(f.code, f.terms) for f in found} >= {("indistinct", ("L0", "L200"))}


def _every_crossing(corners: np.ndarray, universe: tuple[float, float]) -> np.ndarray:
    """The breakpoints as they were before 2026-12-05: the lines of every two sloped edges
    crossed, whether the edges overlap or not."""
    lo, hi = universe
    a, b, c, d = corners.T
    rise = np.isfinite(a) & np.isfinite(b) & (b > a)
    fall = np.isfinite(c) & np.isfinite(d) & (d > c)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        slope = np.concatenate([1.0 / (b[rise] - a[rise]), -1.0 / (d[fall] - c[fall])])
        offset = np.concatenate([-a[rise] / (b[rise] - a[rise]), d[fall] / (d[fall] - c[fall])])
        cross = (offset[None, :] - offset[:, None]) / (slope[:, None] - slope[None, :])
    x = np.concatenate([[lo, hi], corners[np.isfinite(corners)], cross.ravel()])
    return np.unique(x[np.isfinite(x) & (x >= lo) & (x <= hi)])


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), t=st.integers(1, 10), whole=st.booleans())
def test_only_overlapping_edges_are_crossed(seed, t, whole):
    """Two edges cross only where both are: the breakpoints of overlapping edges alone are
    some of the old ones, and measure every pair and the coverage as all of them did (to
    rounding: the trapezoids are cut at fewer points)."""
    rng = np.random.default_rng(seed)
    universe = (0.0, 10.0)
    corners = np.sort(rng.uniform(0, 10, (t, 4)), axis=1)
    corners[rng.integers(t), :2] = -np.inf
    corners[rng.integers(t), 2:] = np.inf
    if whole:                                              # ties: edges meeting at corners
        corners = np.round(corners)
        # no edge standing upright inside the universe: it is measured there on the points
        # beside it, which both sets of breakpoints leave to chance
        upright = np.isfinite(corners[:, 0]) & (corners[:, 0] == corners[:, 1])
        corners[upright & (corners[:, 0] > 0), 0] -= 0.5
        upright = np.isfinite(corners[:, 3]) & (corners[:, 2] == corners[:, 3])
        corners[upright & (corners[:, 3] < 10), 3] += 0.5
    x, every = meaning.breakpoints(corners, universe), _every_crossing(corners, universe)
    assert np.isin(x, every).all()
    mu, old = meaning.memberships(corners, x), meaning.memberships(corners, every)
    np.testing.assert_allclose(meaning.similarity_on(mu, x), meaning.similarity_on(old, every),
                               atol=1e-12)
    assert mu.max(axis=0).min() == pytest.approx(old.max(axis=0).min(), abs=1e-12)


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), t=st.integers(1, 30), whole=st.booleans(),
       sort=st.booleans())
def test_the_envelope_from_each_terms_support_is_every_terms_largest(seed, t, whole, sort):
    """Each term is measured only from its left corner to its right one: the same bits as
    every term at every point (quadratic in the terms: 20,000 triangles took 7 s)."""
    rng = np.random.default_rng(seed)
    corners = np.sort(rng.uniform(-10, 10, (t, 4)), axis=1)
    corners[rng.integers(t), :2] = -np.inf
    corners[rng.integers(t), 2:] = np.inf
    if whole:                                       # ties: vertical edges, points on corners
        corners = np.round(corners) + 0.0
    x = np.concatenate([rng.uniform(-12, 12, rng.integers(0, 40)), corners[np.isfinite(corners)]])
    x = np.sort(x) if sort else x
    assert meaning.envelope(corners, x).tobytes() == \
        meaning.memberships(corners, x).max(axis=0).tobytes()


def test_a_vertical_edge_at_minus_zero_is_0_beside_it():
    """`[0, -0, 3, 9]` divided by -0.0 and read 1 left of its vertical edge."""
    corners = np.array([[0.0, -0.0, 3.0, 9.0]])
    assert meaning.memberships(corners, np.array([-9.0, 0.0, 2.0])).tolist() == [[0.0, 1.0, 1.0]]
    assert meaning.envelope(corners, np.array([-9.0])).tolist() == [0.0]


def test_many_triangles_have_breakpoints_in_proportion():
    """2,000 triangles in one FLL variable took 23 GB in `mitos check`: the lines of every two
    edges crossed gave millions of points, each a column of the memberships."""
    rng = np.random.default_rng(20261205)
    peaks = np.sort(rng.uniform(0, 1, 1000))
    width = rng.uniform(0.001, 0.003, 1000)
    triangles = np.stack([peaks - width, peaks, peaks, peaks + width], axis=1)
    assert len(meaning.breakpoints(triangles, (-1.0, 2.0))) < 10 * len(triangles)


def test_a_repeated_term_is_crossed_once():
    """A fuzzed FLL output of 17,500 copies of one triangle: every two of its 35,000 edges
    were crossed (600 million pairs), and `mitos check` grew to 24 GB before it was killed.
    Each different edge is crossed once now: the breakpoints of one copy."""
    one = np.array([[0.0, 0.5, 0.5, 1.0], [0.25, 0.75, 0.75, 1.25]])
    many = np.repeat(one, 17_500, axis=0)
    assert meaning.breakpoints(many, (0.0, 1.0)).tobytes() == \
        meaning.breakpoints(one, (0.0, 1.0)).tobytes()


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), t=st.integers(1, 10), whole=st.booleans(),
       repeats=st.integers(0, 2))
def test_the_most_similar_piecewise_linear_pair_is_the_one_the_whole_matrix_gave(
        seed, t, whole, repeats):
    """Piecewise-linear terms are measured a pair at a time from their corners, never all
    their memberships at once: the same pair, its similarity to rounding."""
    rng = np.random.default_rng(seed)
    corners = np.sort(rng.uniform(-2, 12, (t, 4)), axis=1)
    corners[rng.integers(t), :2] = -np.inf
    corners[rng.integers(t), 2:] = np.inf
    if whole:
        corners = np.round(corners)
    for _ in range(repeats):
        corners[rng.integers(t)] = corners[rng.integers(t)]
    x = meaning.breakpoints(corners, (0.0, 10.0))
    mu = meaning.memberships(corners, x)
    _agrees(meaning.most_similar(corners, (0.0, 10.0)), mu, x)
    assert np.array_equal(meaning.envelope(corners, x), mu.max(axis=0))


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), t=st.integers(2, 10), repeats=st.integers(0, 3))
def test_each_pair_on_its_own_points_gives_the_whole_matrixs_most_similar_pair(seed, t,
                                                                              repeats):
    """`mitos check` measures each overlapping pair on its own corners and edge crossings, not
    on every breakpoint of the variable (quadratic in the terms: 300 triangles took 56 s):
    the same pair, its similarity to rounding; a term with a vertical edge is left to the
    sum over every breakpoint."""
    rng = np.random.default_rng(seed)
    corners = np.sort(rng.uniform(-2, 12, (t, 4)), axis=1)
    corners[rng.integers(t), :2] = -np.inf
    corners[rng.integers(t), 2:] = np.inf
    for _ in range(repeats):
        corners[rng.integers(t)] = corners[rng.integers(t)]
    x = meaning.breakpoints(corners, (0.0, 10.0))
    found = meaning.most_similar_by_pairs(corners, (0.0, 10.0))
    assert found is not None
    _agrees(found, meaning.memberships(corners, x), x)
    step = np.vstack([corners, [[3.0, 3.0, 6.0, 7.0]]])          # a crisp step at 3
    assert meaning.most_similar_by_pairs(step, (0.0, 10.0)) is None


def test_an_input_of_2000_triangles_is_checked_without_all_its_memberships():
    """Every term's memberships at every breakpoint is terms times about three times as many
    points: for 2,000 triangles 96 MB at once, several times over (and 23 GB before only
    overlapping edges were crossed). A term's memberships are formed when it is measured."""
    import tracemalloc

    from mitos_cli.lang.terms import Term, Variable

    peaks, step = np.linspace(0, 1, 2000), 1 / 1999
    terms = tuple(Term(f"T{i}", "triangle", (p - step, p, p + step)) for i, p in enumerate(peaks))
    var = Variable("x", "input", (0.0, 1.0), terms[:1000] + (Term("T", "triangle", (
        peaks[999] - step, peaks[999] + step / 10, peaks[999] + step)),) + terms[1000:])
    tracemalloc.start()
    try:
        found = meaning.variable_issues(var)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 150e6                                    # was 884 MB
    assert [(f.code, f.terms) for f in found] == [("indistinct", ("T999", "T"))]


def test_coverage_is_kept_per_stretch_of_the_universe():
    """Where the written terms cover to 0.5 they must keep doing so, and a stretch covered less
    keeps its written least; one bound for the universe was 0 once any gap was written."""
    corners = np.array([[0.0, 0.0, 1.0, 3.0], [7.0, 9.0, 10.0, 10.0]])   # tipper's food
    ends, least = meaning.coverage_spans(corners, (0.0, 10.0))
    np.testing.assert_allclose(ends, [0, 2, 8, 10])
    np.testing.assert_allclose(least, [0.5, 0, 0.5])
    inward = np.array([[0.53, 0.53, 0.58, 1.462], [7.0, 9.0, 10.0, 10.0]])
    assert meaning.span_coverage(inward, (0.0, 10.0), ends)[0] == 0.0   # [0, 0.53] uncovered
    vertical = np.array([[0.0, 0.0, 3.0, 3.0], [7.0, 7.0, 10.0, 10.0]])  # 1 at 3 and 7, 0 between
    assert meaning.coverage_spans(vertical, (0.0, 10.0))[1].tolist() == [0.5, 0.0, 0.5]
    dip = np.array([[-np.inf, -np.inf, 0.0, 4.0], [2.0, 6.0, np.inf, np.inf]])
    ends, least = meaning.coverage_spans(dip, (0.0, 10.0))
    np.testing.assert_allclose(ends, [0, 2, 4, 10])
    np.testing.assert_allclose(least, [0.5, 0.25, 0.5])


TIPPER_TERMS = """\
variables:
  service:
    role: input
    universe: [0, 10]
    terms:
      poor: {shape: gaussian, points: [0, 1.5]}
      good: {shape: gaussian, points: [5, 1.5]}
      excellent: {shape: gaussian, points: [10, 1.5]}
  food:
    role: input
    universe: [0, 10]
    terms:
      rancid: {shape: trapezoid, points: [0, 0, 1, 3]}
      delicious: {shape: trapezoid, points: [7, 9, 10, 10]}
  tip:
    role: output
    universe: [0, 30]
    default: 15
    terms:
      cheap: {shape: triangle, points: [0, 5, 10]}
      average: {shape: triangle, points: [10, 15, 20]}
      generous: {shape: triangle, points: [20, 25, 30]}
"""

TIPPER_RULES = """\
terms "tipper.terms.yaml"
operators: inference = mamdani, sampling = endpoints

r1: if service is poor or food is rancid then tip is cheap
r2: if service is good then tip is average
r3: if service is excellent or food is delicious then tip is generous
"""


def test_a_converted_controller_keeps_the_end_of_its_universe_covered(tmp_path):
    """`mitos convert tipper.fis` then teaching it: its `food` is written with a gap on [3, 7],
    so the one coverage bound was 0, and examples that want `rancid` off at the most rancid
    food moved its vertical edge on 0 inward (food in [0, 0.22] in no term), which neither
    adapt nor save reported. The edge now stays (the descent goes on with the other knots),
    the written gap may shrink but not widen, and a gap adaptation does open
    (`unconstrained`) is in the interpretability line."""
    from mitos_cli.teach.session import Session

    (tmp_path / "tipper.terms.yaml").write_text(TIPPER_TERMS)
    (tmp_path / "tipper.rules").write_text(TIPPER_RULES)
    rng = np.random.default_rng(2)
    lines = [f"correct service={s:.3f} food={f:.4f} -> tip=25"
             for s, f in zip(rng.uniform(6, 10, 60), rng.uniform(0, 0.02, 60))]
    lines += [f"correct service={s:.3f} food={f:.3f} -> tip={5 + 2 * s:.2f}"
              for s, f in zip(rng.uniform(0, 10, 60), rng.uniform(0.6, 10, 60))]
    for constrained in (True, False):
        out: list[str] = []
        s = Session(tmp_path / "tipper.rules", out=out.append)
        for line in lines:
            s.run(line)
        out.clear()
        s.run("adapt epochs 60" + ("" if constrained else " unconstrained"))
        text = "\n".join(out)
        food = s.rulebase.variables["food"]
        gaps = meaning.term_gaps(food)
        assert "changed (before -> after)" in text            # the descent went on
        if constrained:
            assert food.term("rancid").corners[:2] == (0.0, 0.0)
            # the written gap [3, 7] may shrink (the compass closes part of it), not widen
            (a, b, _, _), = gaps
            assert 3.0 <= a < b <= 7.0 and "did not have" not in text
            assert f"input `food`: every term is 0 for food in [{a:g}, {b:g}] (widen a " \
                   "neighbouring term" in text
        else:
            assert gaps[0].left == 0.0 and gaps[0].right > 0.0
            end = ")" if gaps[0].open_right else "]"       # up to a vertical edge, or onto 0
            assert (f"input `food`: every term is 0 for food in [0, {gaps[0].right:.6g}{end}, a gap "
                    "the terms as written did not have (widen") in text
            out.clear()
            s.run(f"save {tmp_path / 'u.rules'}")
            assert "a gap the terms as written did not have" in "\n".join(out)


def test_a_variable_with_a_term_of_another_shape_keeps_its_coverage(tmp_path):
    """`mitos convert robot_jfuzzylogic.fcl`: `dist` has a `discrete` term `far` beside two
    triangles. A variable with any term adaptation does not move was no partition, so its
    coverage was not kept: one `adapt` moved `near` [0, 0, 1] off 0 and left dist in [0, 0.057]
    to no term, which only the interpretability line said. It is now measured on samples."""
    from mitos_cli.teach.session import Session

    (tmp_path / "r.terms.yaml").write_text(
        "variables:\n  dist:\n    role: input\n    universe: [0, 3]\n    terms:\n"
        "      near: {shape: triangle, points: [0, 0, 1]}\n"
        "      ok: {shape: triangle, points: [0, 1, 2]}\n"
        "      far: {shape: discrete, points: [1, 0, 2, 1, 3, 1]}\n"
        "  turn: {role: output, universe: [-45, 45], default: 0, terms: {L: -30, N: 0, R: 30}}\n")
    (tmp_path / "r.rules").write_text('terms "r.terms.yaml"\n\nr1: if dist is near then turn is L\n'
                                      "r2: if dist is ok then turn is N\n"
                                      "r3: if dist is far then turn is R\n")
    s = Session(tmp_path / "r.rules", out=[].append)
    s.run("correct dist=1 -> turn=-30")
    s.run("adapt epochs 5")
    dist = s.rulebase.variables["dist"]
    assert dist.term("ok").corners != (0.0, 1.0, 1.0, 2.0)           # it learned
    assert meaning.term_gaps(dist) == []
    x = np.linspace(0, 3, 3001)
    assert meaning.sampled(dist.terms, x).max(axis=0).min() >= 0.5 - 1e-9


def _said(before: dict[str, float], after: dict[str, float]) -> list[str]:
    """What `in_words` says when the crisp output `o` (deg) moves from ``before`` to
    ``after``."""
    from types import SimpleNamespace

    from mitos_cli.teach.learned import in_words

    def rulebase(values):
        terms = ", ".join(f"{k}: {v!r}" for k, v in values.items())
        text = f"variables:\n  x: {{role: input, universe: [0, 1], terms: {{A: {{shape: " \
               f"left_shoulder, points: [0, 1]}}}}}}\n  o: {{role: output, unit: deg, " \
               f"universe: [0, 200], terms: {{{terms}}}}}\n"
        rules = "behavior b:\n" + "".join(f" if x is A then o is {k}\n" for k in values) + "end\n"
        return build_rulebase(parse_rules(rules), (parse_termset(text),), ("t.yaml",))

    parameters = SimpleNamespace(held=(), knots=(SimpleNamespace(var="o"),))
    return in_words(rulebase(before), rulebase(after), parameters).splitlines()[1:]


def test_learned_words_show_a_small_move_and_the_table_s_digits():
    """`steering.RS: 110 -> 110 deg, toward ST` for 109.97; `130 -> 130.9` beside a table of
    changes that said 130.87."""
    said = _said({"ST": 90.0, "RS": 110.0, "RM": 130.0, "RB": 150.0},
                 {"ST": 90.0, "RS": 109.97, "RM": 130.87, "RB": 150.0 + 1e-12})
    assert said == ["  o.RS: 110 -> 109.97 deg, toward ST",
                    "  o.RM: 130 -> 130.87 deg, toward RB",
                    f"  o.RB: 150.0 -> {150.0 + 1e-12!r} deg, away from RM"]   # never "150 -> 150"


def test_learned_words_say_which_neighbour_an_end_term_moved_away_from():
    """`size.SMALL_SZ: 10 -> 7.36 in` said no direction, where every other move names the
    neighbour it went toward."""
    said = _said({"LO": 10.0, "MID": 30.0, "HI": 60.0}, {"LO": 5.0, "MID": 30.0, "HI": 64.0})
    assert said == ["  o.LO: 10 -> 5 deg, away from MID", "  o.HI: 60 -> 64 deg, away from MID"]


def test_learned_words_say_past_a_neighbour_not_a_share_over_the_whole_way():
    """`out.MID: 30 -> 42.5, toward HI (125% of the way: it now means nearly what HI
    meant)`: it went past HI."""
    said = _said({"LO": 0.0, "MID": 30.0, "HI": 40.0}, {"LO": 0.0, "MID": 42.5, "HI": 60.0})
    assert said[0] == ("  o.MID: 30 -> 42.5 deg, past HI (written at 40 deg: it now lies "
                       "beyond what HI meant)")
    said = _said({"LO": 0.0, "MID": 30.0, "HI": 40.0}, {"LO": 0.0, "MID": 37.0, "HI": 60.0})
    assert said[0] == ("  o.MID: 30 -> 37 deg, toward HI (70% of the way: it now means "
                       "nearly what HI meant)")


def test_learned_words_name_the_rules_whose_crisp_values_moved(tmp_path):
    """When only a rule's own crisp value was learned (`main/r1: y is 40 -> 45` in the table),
    the words said "no term moved", as if nothing had been learned."""
    from mitos_cli.teach.session import Session

    (tmp_path / "r.terms.yaml").write_text(
        "variables:\n  x: {role: input, universe: [0, 1], terms: {A: {shape: left_shoulder, "
        "points: [0, 1]}, B: {shape: right_shoulder, points: [0, 1]}}}\n"
        "  y: {role: output, universe: [0, 100], terms: {LO: 10, HI: 90}}\n")
    (tmp_path / "r.rules").write_text('terms "r.terms.yaml"\n\nr1: if x is A then y is 40\n'
                                      "r2: if x is B then y is HI\n")
    said: list[str] = []
    s = Session(tmp_path / "r.rules", out=said.append)
    s.run("correct x=0 -> y=45")
    s.run("adapt epochs 50")
    words = next(x for x in said if x.startswith("learned, in words:")).splitlines()
    assert words[1] == ("  no term moved; only the crisp value written in rule `main/r1` did "
                        "(the table above)")


def test_each_pair_is_measured_on_its_own_stretch(monkeypatch):
    """Overlapping pairs were measured at every breakpoint of the variable: 20,000 narrow
    triangles took 70 s of `mitos check`, quadratic in the terms. A pair's memberships are
    now formed on the points where either is above 0 (and one each side): in proportion to
    the terms."""
    formed = []
    real = meaning.memberships

    def counted(corners, x):
        mu = real(corners, x)
        formed.append(mu.size)
        return mu

    n = 2000
    peaks = np.arange(n, dtype=float)
    triangles = np.stack([peaks - 1, peaks, peaks, peaks + 1], axis=1)
    monkeypatch.setattr(meaning, "memberships", counted)
    found = meaning.most_similar(triangles, (-1.0, float(n)))
    assert found[1:] == (0, 1) and abs(found[0] - 1 / 7) < 1e-12
    assert sum(formed) < 50 * n                        # was 2 * 2,000 pairs * 4,000 points
