"""The paper's numbers (Sec. 4): membership examples and the sample run (78, 45, 4).

The paper prints memberships and DOFs at one decimal; ``docs/paper.md`` says which numbers the
packaged rule base reproduces exactly and which it cannot (r8's DOF, the final outputs).
"""

from __future__ import annotations

from fractions import Fraction as F

import pytest

from mitos_cli import load_rulebase


@pytest.fixture(scope="module")
def rb():
    return load_rulebase()


def one(x: float) -> float:
    return round(x, 1)


def test_sample_run_fuzzified_inputs(rb):
    trace = rb.trace(road=78, size=45, position=4)
    shown = {i.name: {t: one(mu) for t, mu in i.memberships if one(mu) > 0}
             for i in trace.inputs}
    assert shown == {"road": {"MEDIUM": 0.7, "WIDE": 0.3},
                     "size": {"MED_SZ": 0.8, "LARGE_SZ": 0.2},
                     "position": {"CENTER": 0.4, "RIGHT": 0.6}}


def test_sample_run_dofs(rb):
    trace = rb.trace(road=78, size=45, position=4)
    dof = {r.label: one(r.dof) for r in trace.rules}
    paper = {"r4": 0.3, "r5": 0.2, "r7": 0.3, "r22": 0.4, "r23": 0.2, "r25": 0.6, "r26": 0.2}
    assert {k: dof[k] for k in paper} == paper
    # r8 is printed as 0.3 in the paper, but eq. 17 on its own inputs gives min(0.3, 0.2, 0.6)
    assert dof["r8"] == 0.2
    assert set(dof) == set(paper) | {"r8"}          # exactly the paper's eight rules fire


def test_sample_run_consequents_are_the_papers(rb):
    # the sample's "y1 is 20 / 0 / 40" read as turns left of straight: LS 70, ST 90, LM 50;
    # its speeds 40 and 30 are MEDIUM and MODERATE
    c = rb.compiled
    want = {"r4": (70, 40), "r5": (90, 30), "r7": (50, 40), "r8": (70, 30), "r22": (70, 30),
            "r23": (90, 30), "r25": (50, 30), "r26": (70, 30)}
    got = {label: tuple(c.cons_value[c.labels.index(label)]) for label in want}
    assert got == want


def test_sample_run_outputs(rb):
    # eqs. 18-19 with the exact DOFs, in exact arithmetic (docs/paper.md shows it)
    wide, medium = F(8, 30), F(22, 30)              # road 78
    med_sz, large_sz = F(25, 30), F(5, 30)          # size 45
    center, right = F(3, 7), F(4, 7)                # position 4
    fired = [  # (DOF, steering, speed) of r4 r5 r7 r8 r22 r23 r25 r26
        (min(wide, med_sz, center), 70, 40), (min(wide, large_sz, center), 90, 30),
        (min(wide, med_sz, right), 50, 40), (min(wide, large_sz, right), 70, 30),
        (min(medium, med_sz, center), 70, 30), (min(medium, large_sz, center), 90, 30),
        (min(medium, med_sz, right), 50, 30), (min(medium, large_sz, right), 70, 30)]
    total = sum(d for d, _, _ in fired)
    assert total == F(11, 5)
    steering = sum(d * y for d, y, _ in fired) / total
    speed = sum(d * y for d, _, y in fired) / total
    out = rb.evaluate(road=78, size=45, position=4)
    assert out["steering"] == pytest.approx(float(steering), rel=1e-14)
    assert out["speed"] == pytest.approx(float(speed), rel=1e-14)
    assert (round(out["steering"], 1), round(out["speed"], 1)) == (65.4, 32.4)


def test_paper_final_outputs_from_rounded_dofs():
    # what eqs. 18-19 give with the paper's printed DOFs (not the paper's 13.0 / 37.9)
    dofs = [0.3, 0.2, 0.3, 0.2, 0.4, 0.2, 0.6, 0.2]
    turn = [20, 0, 40, 20, 20, 0, 40, 20]           # the sample's y1, degrees left of straight
    speed = [40, 30, 40, 30, 30, 30, 30, 30]
    avg = lambda ys: sum(d * y for d, y in zip(dofs, ys)) / sum(dofs)  # noqa: E731
    assert (round(avg(turn), 1), round(avg(speed), 1)) == (24.2, 32.5)
    dofs[3] = 0.3                                   # r8 as printed
    assert (round(avg(turn), 1), round(avg(speed), 1)) == (24.0, 32.4)


def test_rule_16_is_r0(rb):
    out = rb.trace(road=100, size=5, position=-10)
    assert [(r.label, r.dof) for r in out.rules] == [("r0", 1.0)]
    assert rb.compiled.rule_text(0) == ("if road is WIDE and size is SMALL_SZ and position is "
                                        "LEFT then steering is RS and speed is MEDIUM")


@pytest.mark.parametrize("var, x, expected", [
    ("road", 80, {"MEDIUM": 0.7, "WIDE": 0.3}),
    ("road", 100, {"WIDE": 1.0}),
    ("size", 65, {"MED_SZ": 0.2, "LARGE_SZ": 0.8}),
    ("road", 78, {"MEDIUM": 0.7, "WIDE": 0.3}),
    ("size", 45, {"MED_SZ": 0.8, "LARGE_SZ": 0.2}),
    ("position", 4, {"CENTER": 0.4, "RIGHT": 0.6}),
])
def test_membership_examples(rb, var, x, expected):
    v = rb.rulebase.variables[var]
    got = {t.name: one(float(t.membership(x))) for t in v.terms}
    assert {k: m for k, m in got.items() if m > 0} == expected


def test_eq15_medium_road_width_is_30(rb):
    medium = rb.rulebase.variables["road"].term("MEDIUM")
    assert medium.shape == "triangle_pw" and medium.params == (70.0, 30.0)
    # eq. 15: mu(x) = 1 - |peak - x| / width, clipped at 0
    for x in (40.0, 55.0, 70.0, 78.0, 100.0, 130.0):
        assert float(medium.membership(x)) == pytest.approx(max(0.0, 1 - abs(70 - x) / 30))
