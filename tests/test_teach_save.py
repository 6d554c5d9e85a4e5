"""Saving keeps the rule base linguistic: text surgery, atomic writes, round trip."""

import json
import re
import shutil
from pathlib import Path

import pytest

from mitos_cli.api import default_rulebase_path
from mitos_cli.errors import LessonError, MitosError
from mitos_cli.lang.resolve import load_rules_file
from mitos_cli.teach.save import atomic_write, save_rulebase
from mitos_cli.teach.session import Session

RULEBASES = default_rulebase_path().parent


@pytest.fixture
def rules(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    for f in RULEBASES.iterdir():
        if f.is_file():
            shutil.copy(f, src / f.name)
    return src / "mitos.rules"


def variables(rb):
    return [v for ts in rb.termsets for v in ts.variables]


def test_round_trip_load_save_load(rules, tmp_path):
    rb = load_rules_file(rules)
    out = tmp_path / "out" / "copy.rules"
    saved = save_rulebase(rb, rb, out)
    assert saved.changes == ()
    again = load_rules_file(out)
    assert again.behaviors == rb.behaviors
    assert variables(again) == variables(rb)
    original = rules.read_text().splitlines()
    written = out.read_text().splitlines()
    diff = [(a, b) for a, b in zip(original, written) if a != b]
    assert len(original) == len(written) and len(diff) == 1       # only the `terms` line
    assert diff[0][1] == 'terms "copy.mitos.terms.yaml", "copy.drive.terms.yaml"'
    assert (out.parent / "copy.mitos.terms.yaml").read_text() == \
        (rules.parent / "mitos.terms.yaml").read_text()


def test_saving_over_the_original_rewrites_in_place(rules):
    s = Session(rules, out=[].append)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    s.run("adapt epochs 5")
    s.run(f"save {rules}")
    assert sorted(p.name for p in rules.parent.iterdir()) == [
        "drive.terms.yaml", "mitos.rules", "mitos.terms.yaml"]
    assert load_rules_file(rules).behaviors == s.rulebase.behaviors
    assert variables(load_rules_file(rules)) == variables(s.rulebase)


def test_changed_numbers_only(rules, tmp_path):
    s = Session(rules, out=[].append)
    s.run("correct road=78 size=45 position=4 -> steering=60 speed=20")
    s.run("adapt epochs 10")
    s.run("r25: if road is MEDIUM and size is MED_SZ and position is RIGHT "
          "then steering is LB and speed is SLOW")
    s.run("r30: if road is NARROW then speed is 12")
    s.run("frozen r4")
    s.run("behavior wider")
    s.run("use avoid_obstacle when road is WIDE")
    s.run("end")
    out = tmp_path / "taught.rules"
    s.run(f"save {out}")
    before = (rules.parent / "mitos.terms.yaml").read_text().splitlines()
    after = (tmp_path / "taught.mitos.terms.yaml").read_text().splitlines()
    # besides numbers, a held centre term whose neighbours moved out of symmetry gets its point
    held = re.compile(r"\{shape: singleton, value: ([-\d.]+), held: \1\}")
    assert any(held.search(line) for line in after)
    after = [held.sub(r"\1", line) for line in after]
    assert len(before) == len(after)
    for a, b in zip(before, after):
        # same line, same keys and comments: only numbers differ, and a comment beside a
        # number that changed is marked as said before teaching
        b = b.removesuffix(" (before teaching)")
        if a != b:
            assert [w for w in a.replace(",", " ").split() if not _number(w)] == \
                   [w for w in b.replace(",", " ").split() if not _number(w)]
    assert "# eq. 15: width 30 in" in "\n".join(after)
    text = out.read_text()
    assert "    r25: if road is MEDIUM and size is MED_SZ and position is RIGHT then steering " \
           "is LB and speed is SLOW    # paper: y1 40, y2 30" in text
    assert "    r30: if road is NARROW then speed is 12\n    frozen r4\nend" in text
    assert text.rstrip().endswith("behavior wider:\n    use avoid_obstacle when road is WIDE\nend")
    again = load_rules_file(out)
    assert again.behaviors == s.rulebase.behaviors
    assert variables(again) == variables(s.rulebase)


#: a term set of one input (LO, HI) and one crisp output, for the crisp and unlabelled rules
LO_HI = ("variables:\n  x: {role: input, universe: [0, 10], terms: {"
         "LO: {shape: left_shoulder, points: [2, 8]}, HI: {shape: right_shoulder, "
         "points: [2, 8]}}}\n  y: {role: output, universe: [0, 100], terms: {A: 0}}\n")


def lo_hi_session(tmp_path, rules: str) -> Session:
    """A session on ``t.rules`` (its text ``rules``) and ``t.terms.yaml`` (:data:`LO_HI`)."""
    (tmp_path / "t.terms.yaml").write_text(LO_HI)
    (tmp_path / "t.rules").write_text(rules)
    return Session(tmp_path / "t.rules", out=[].append)


def test_crisp_consequents_are_edited_in_place(tmp_path):
    s = lo_hi_session(tmp_path, 'terms "t.terms.yaml"\n# comment\nr1: if x is LO\n'
                                '   then y is 20   # low\nr2: if x is HI then y is 80\n')
    s.run("correct x=0 -> y=30")
    s.run("correct x=10 -> y=70")
    s.run("adapt epochs 30")
    s.run(f"save {tmp_path / 'u.rules'}")
    text = (tmp_path / "u.rules").read_text()
    assert text.startswith('terms "u.terms.yaml"\n# comment\nr1: if x is LO\n   then y is ')
    assert "   # low (before teaching)\n" in text        # it spoke of 20, learned away
    r1, r2 = load_rules_file(tmp_path / "u.rules").behaviors[0].rules
    assert abs(r1.consequents[0].value - 30) < 1 and abs(r2.consequents[0].value - 70) < 1


def test_unlabelled_rules_are_saved_in_their_places(tmp_path):
    """Labels are optional: an unlabelled rule is edited where it stands, and a rule told
    without a label is added once, not every unlabelled rule of the file again."""
    s = lo_hi_session(tmp_path, 'terms "t.terms.yaml"\nbehavior b:\n'
                                '    if x is LO then y is 20   # low\n'
                                "    if x is HI then y is 80\nend\n")
    s.run(f"save {tmp_path / 'same.rules'}")
    assert (tmp_path / "same.rules").read_text() == (
        (tmp_path / "t.rules").read_text().replace("t.terms", "same.terms"))
    s.run("use b")
    s.run("correct x=0 -> y=30")
    s.run("correct x=10 -> y=70")
    s.run("adapt epochs 30")
    s.run("if x is HI then y is 90")
    s.run(f"save {tmp_path / 'u.rules'}")
    text = (tmp_path / "u.rules").read_text()
    assert text.count("if x is LO") == 1 and text.count("if x is HI") == 2
    assert "   # low (before teaching)\n" in text        # it spoke of 20, learned away
    r1, r2, r3 = load_rules_file(tmp_path / "u.rules").behaviors[0].rules
    assert abs(r1.consequents[0].value - 30) < 1 and abs(r2.consequents[0].value - 70) < 1
    assert r3.consequents[0].value == 90


def test_save_mistakes(rules, tmp_path):
    s = Session(rules, out=[].append)
    with pytest.raises(LessonError, match="say where to save") as info:
        s.run("save")
    assert info.value.hint == f"the original {rules} is kept unless you name it (`save {rules}`)"


def test_save_without_a_path_does_not_offer_to_write_over_the_packaged_rule_base():
    """`mitos teach` (the packaged rule base), then `save`, was told the original is kept
    unless named, with the packaged file's own path to name: where pip installed it."""
    from mitos_cli.api import default_rulebase_path

    s = Session(default_rulebase_path(), out=[].append)
    with pytest.raises(LessonError, match="say where to save") as info:
        s.run("save")
    assert info.value.hint == ("the session teaches the packaged rulebases/mitos.rules (the one "
                               "every command reads when none is named): save a copy of your "
                               "own")
    assert str(default_rulebase_path()) not in info.value.render()


def test_save_makes_one_missing_directory_and_refuses_a_missing_path(rules, tmp_path):
    """`save taught/new.rules` makes `taught/`; a path missing more than its last directory
    is most likely a typo, refused as every other writer refuses it (nothing is created)."""
    rb = load_rules_file(rules)
    assert save_rulebase(rb, rb, tmp_path / "taught" / "new.rules").rules.is_file()
    with pytest.raises(LessonError, match="the directory `.*nope` does not exist"):
        save_rulebase(rb, rb, tmp_path / "nope" / "deeper" / "x.rules")
    assert not (tmp_path / "nope").exists()


def test_atomic_write_leaves_no_half_file(tmp_path, monkeypatch):
    target = tmp_path / "a.rules"
    target.write_text("old")

    def boom(*a):
        raise OSError("disk full")

    monkeypatch.setattr("os.replace", boom)
    with pytest.raises(MitosError, match="cannot write .*a.rules.*: disk full"):
        atomic_write(target, "new")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.rules"]


def _number(word):
    try:
        float(word.strip("[]{}"))
        return True
    except ValueError:
        return False


def test_frozen_terms_survive_save_load_and_the_journal(rules, tmp_path):
    """`frozen VAR.TERM` is part of the model: the journal replays it, `save` writes
    `frozen: true` (flow mapping, bare crisp value) and `unfrozen` of a term frozen in the
    YAML writes `frozen: false`; loading the saved files gives the same terms."""
    from mitos_cli.teach.journal import Journal

    terms = rules.parent / "mitos.terms.yaml"
    text = terms.read_text()
    terms.write_text(text.replace("{shape: right_shoulder, points: [40, 70]}",
                                  "{shape: right_shoulder, points: [40, 70], frozen: true}", 1))
    before = {(v.name, t.name): t.frozen for v in variables(load_rules_file(rules))
              for t in v.terms}
    assert [k for k, f in before.items() if f] == [("size", "LARGE_SZ")]
    s = Session(rules, out=[].append, journal=Journal.create(tmp_path / "session"))
    s.run("frozen road.NARROW, steering.LS, position.CENTER")
    s.run("unfrozen size.LARGE_SZ")
    s.run("correct road=78 size=45 position=4 -> steering=60")
    s.run("adapt epochs 5")
    again = Session.resume(Journal.open(tmp_path / "session"), out=[].append)
    assert again.rulebase == s.rulebase
    s.run(f"save {tmp_path / 'out' / 'taught.rules'}")
    saved = load_rules_file(tmp_path / "out" / "taught.rules")
    frozen = {(v.name, t.name): t.frozen for v in variables(saved) for t in v.terms}
    assert sorted(k for k, f in frozen.items() if f) == [
        ("position", "CENTER"), ("road", "NARROW"), ("steering", "LS")]
    assert variables(saved) == variables(s.rulebase)
    # a new session on the saved files keeps the frozen terms where they are
    s2 = Session(tmp_path / "out" / "taught.rules", out=[].append)
    s2.run("correct road=78 size=45 position=4 -> steering=40")
    s2.run("adapt epochs 5")
    learned = {(v.name, t.name): t for v in variables(s2.rulebase) for t in v.terms}
    saved_terms = {(v.name, t.name): t for v in variables(saved) for t in v.terms}
    for key in [("position", "CENTER"), ("road", "NARROW"), ("steering", "LS")]:
        assert learned[key].params == saved_terms[key].params


def test_frozen_written_into_a_block_mapping_and_a_frozen_value_replaced():
    import dataclasses

    from mitos_cli.lang.termfile import parse_termset
    from mitos_cli.teach.save import edit_termset

    text = ("variables:\n  x:\n    role: input\n    universe: [0, 10]\n    terms:\n"
            "      LOW:\n        shape: left_shoulder\n        points: [2, 5]   # kept\n"
            "      HIGH: {shape: right_shoulder, points: [2, 5], frozen: true}\n")
    old = parse_termset(text, "x.yaml")
    flip = {"LOW": True, "HIGH": False}
    new = dataclasses.replace(old, variables=tuple(v.with_terms(tuple(
        dataclasses.replace(t, frozen=flip[t.name]) for t in v.terms)) for v in old.variables))
    written, changes = edit_termset(text, "x.yaml", old, new)
    assert written == text.replace("      LOW:\n", "      LOW:\n        frozen: true\n") \
        .replace("frozen: true}", "frozen: false}")
    assert changes == ["x.LOW: frozen", "x.HIGH: no longer frozen"]
    assert [t.frozen for t in parse_termset(written).variables[0].terms] == [True, False]


def test_a_released_centre_term_stays_released_after_save(rules, tmp_path):
    """`unfrozen position.CENTER` lifts its hold at 0: `save` writes `held: false`, the saved
    rule base lets it move and `mitos check` does not call it off-centre."""
    from mitos_cli.engine.check import check_rulebase
    from mitos_cli.teach.journal import Journal

    s = Session(rules, out=[].append, journal=Journal.create(tmp_path / "session"))
    s.run("unfrozen position.CENTER, road.NARROW")       # NARROW has no point: nothing to write
    s.run("correct road=78 size=45 position=2 -> steering=40")
    s.run("correct road=78 size=45 position=-1 -> steering=120")
    s.run("adapt epochs 20")
    centre = s.rulebase.variables["position"].term("CENTER")
    assert not centre.held and centre.params[0] != 0          # it moved off 0
    assert s.rulebase.variables["road"].term("NARROW").held
    assert Session.resume(Journal.open(tmp_path / "session"), out=[].append).rulebase \
        == s.rulebase
    s.run(f"save {tmp_path / 'out.rules'}")
    text = (tmp_path / "out.mitos.terms.yaml").read_text()
    assert "CENTER: {shape: triangle, peak: " in text and ", held: false}" in text
    assert text.count("held: false") == 1                 # NARROW has no point to release
    saved = load_rules_file(tmp_path / "out.rules")
    assert variables(saved) == variables(s.rulebase)
    assert not {f.code for f in check_rulebase(saved).findings} & {"off-centre"}
    p = Session(tmp_path / "out.rules", out=[].append)
    from mitos_cli.teach.adapt import parameterise
    assert ("position", "CENTER") not in {(v, t) for v, t, _ in parameterise(p.compiled()).held}


def test_held_must_be_true_false_or_a_point():
    from mitos_cli.errors import TermSetError
    from mitos_cli.lang.termfile import parse_termset

    text = ("variables:\n  x:\n    role: input\n    universe: [0, 10]\n    terms:\n"
            "      MID: {shape: triangle, points: [2, 5, 8], held: maybe}\n")
    with pytest.raises(TermSetError, match="`held` must be true, false or the point") as err:
        parse_termset(text, "x.yaml")
    assert (err.value.span.line, err.value.span.column) == (6, 55)
    mid = parse_termset(text.replace("maybe", "5"), "x.yaml").variables[0].terms[0]
    assert (mid.held, mid.held_at) == (True, 5.0)
    for written, said in (("null", "`null`"), ("~", "`~`"), ("[5]", "a list")):  # not `None`
        with pytest.raises(TermSetError) as err:
            parse_termset(text.replace("maybe", written), "x.yaml")
        assert err.value.message.endswith(f"held at, not {said}")
    with pytest.raises(TermSetError) as err:
        parse_termset(text.replace("role: input", "role: null"), "x.yaml")
    assert err.value.message.endswith("role must be `input` or `output`, not `null`")


def test_a_centre_term_stays_held_when_its_neighbours_lose_their_symmetry(rules, tmp_path):
    """The first `adapt` moves LM and LS but not RS and RM, so steering's terms no longer
    mirror each other about 90: ST must stay held at 90 in the next `adapt`, after `--resume`,
    in the saved files (`held: 90`) and when they are taught again; `mitos check` then tells
    when it is moved off by hand."""
    import dataclasses

    from mitos_cli.engine.check import check_rulebase
    from mitos_cli.lang import interpretability as meaning
    from mitos_cli.teach.journal import Journal

    s = Session(rules, out=[].append, journal=Journal.create(tmp_path / "session"))
    s.run("correct road=78 size=45 position=4 -> steering=60")
    s.run("adapt epochs 3")
    steering = s.rulebase.variables["steering"]
    assert meaning.mirror_point(steering) is None              # LM and LS moved alone
    assert steering.term("ST").held_at == 90
    s.run("correct road=70 size=45 position=4 -> steering=60")
    s.run("correct road=70 size=45 position=0 -> steering=80")
    s.run("adapt epochs 10")
    assert s.rulebase.variables["steering"].term("ST").params == (90.0,)
    assert Session.resume(Journal.open(tmp_path / "session"), out=[].append).rulebase \
        == s.rulebase
    s.run(f"save {tmp_path / 'out.rules'}")
    text = (tmp_path / "out.mitos.terms.yaml").read_text()
    assert "ST: {shape: singleton, value: 90, held: 90}" in text
    saved = load_rules_file(tmp_path / "out.rules")
    assert variables(saved) == variables(s.rulebase)
    assert not {f.code for f in check_rulebase(saved).findings} & {"off-centre"}

    again = Session(tmp_path / "out.rules", out=[].append)     # taught again: still held
    again.run("correct road=70 size=45 position=0 -> steering=100")
    again.run("adapt epochs 10")
    assert again.rulebase.variables["steering"].term("ST").params == (90.0,)

    moved = dataclasses.replace(saved.variables["steering"].term("ST"), params=(95.0,))
    var = saved.variables["steering"]
    var = var.with_terms(tuple(moved if t.name == "ST" else t for t in var.terms))
    issues = meaning.variable_issues(var)
    assert [i.code for i in issues] == ["off-centre"]
    assert "off the point 90 it is held at" in issues[0].message


def test_frozen_must_be_true_or_false():
    """`frozen: "no"` is a string, and a string is truthy: refuse it rather than freeze."""
    from mitos_cli.errors import TermSetError
    from mitos_cli.lang.termfile import parse_termset

    text = ("variables:\n  x:\n    role: input\n    universe: [0, 10]\n    terms:\n"
            "      MID: {shape: triangle, points: [2, 5, 8], frozen: \"no\"}\n")
    with pytest.raises(TermSetError, match="`frozen` must be true or false") as err:
        parse_termset(text, "x.yaml")
    assert err.value.span.line == 6


def test_a_frozen_crisp_value_that_also_moved_is_written_whole(rules, tmp_path):
    """`LS: 70`, adapted to 67 and frozen in one session, becomes `{shape: singleton,
    value: 67, frozen: true}` (the two edits of one number once overlapped: `67hape: ...`)."""
    s = Session(rules, out=[].append)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    s.run("adapt epochs 3")
    s.run("frozen steering.LS")
    s.run("unfrozen steering.ST")
    s.run(f"save {tmp_path / 'w.rules'}")
    saved = load_rules_file(tmp_path / "w.rules")
    def stated(rb):
        return [(v.name, t.name, t.params, t.frozen, t.held) for v in variables(rb) for t in v.terms]
    assert stated(saved) == stated(s.rulebase)
    text = (tmp_path / "w.mitos.terms.yaml").read_text()
    learned = s.rulebase.variables["steering"].term("LS").params[0]
    assert f"LS: {{shape: singleton, value: {learned:.4g}, frozen: true}}" in text


def test_operators_told_twice_are_saved_as_one_setting(rules, tmp_path):
    s = Session(rules, out=[].append)
    s.run("operators: and = product")
    s.run("operators: and = min, or = max")
    s.run(f"save {tmp_path / 'o.rules'}")
    text = (tmp_path / "o.rules").read_text()
    assert "operators: and = min, or = max\n" in text and "and = product" not in text
    assert load_rules_file(tmp_path / "o.rules").behaviors == s.rulebase.behaviors or \
        load_rules_file(tmp_path / "o.rules").behavior("avoid_obstacle").operators[-2:] \
        == s.rulebase.behavior("avoid_obstacle").operators[-2:]


def test_operators_told_at_top_level_are_set_where_the_file_sets_them(tmp_path):
    """A second file-level `operators:` line setting a key again is read with a warning;
    a save changes the key where the file sets it, and adds a line only for the others."""
    s = lo_hi_session(tmp_path, 'terms "t.terms.yaml"\noperators: and = min, or = max   # ours\n'
                                "r1: if x is LO then y is 20\nr2: if x is HI and x is LO then y is 80\n")
    s.run("operators: and = product")
    s.run("operators: inference = weighted_sum")
    s.run(f"save {tmp_path / 'o.rules'}")
    text = (tmp_path / "o.rules").read_text()
    assert "operators: and = product, or = max   # ours\n" in text
    assert text.count("operators:") == 2 and "operators: inference = weighted_sum\n" in text
    saved = load_rules_file(tmp_path / "o.rules")
    assert saved.notes == ()
    from mitos_cli.lang.operators import resolve

    assert resolve(saved.operators) == resolve(s.rulebase.behavior("main").operators,
                                               resolve(s.rulebase.operators))


def test_operators_told_in_a_behavior_are_set_where_the_behavior_sets_them(tmp_path):
    """Two `operators:` lines of one behavior setting a key again are read with a warning
    too, so a save changes the key on the behavior's own line rather than adding another."""
    s = lo_hi_session(tmp_path, 'terms "t.terms.yaml"\nbehavior b:\n    operators: and = min\n'
                                "    r1: if x is LO and x is HI then y is 20\nend\n")
    s.run("operators: and = product")
    s.run(f"save {tmp_path / 'o.rules'}")
    text = (tmp_path / "o.rules").read_text()
    assert "    operators: and = product\n" in text and text.count("operators:") == 1
    saved = load_rules_file(tmp_path / "o.rules")
    assert saved.notes == () and saved.behavior("b").operators == s.rulebase.behavior("b").operators[-1:]
    (tmp_path / "twice.rules").write_text(text.replace("end\n", "    operators: and = min\nend\n"))
    notes = load_rules_file(tmp_path / "twice.rules").notes
    assert len(notes) == 1 and "the later line wins for behavior `b`" in notes[0]


def test_save_refuses_to_write_over_a_term_set_the_rule_file_reads(tmp_path):
    (tmp_path / "a.rules").write_text(
        'terms "b.terms.yaml"\nbehavior b:\n    r0: if x is LO then y is A\n'
        '    r1: if x is HI then y is B\nend\n')
    terms = ("variables:\n  x: {role: input, universe: [0, 10], terms: {LO: {shape: "
             "left_shoulder, points: [2, 8]}, HI: {shape: right_shoulder, points: [2, 8]}}}\n"
             "  y: {role: output, universe: [0, 10], terms: {A: 2, B: 8}}\n")
    (tmp_path / "b.terms.yaml").write_text(terms)
    s = Session(tmp_path / "a.rules", out=[].append)
    s.run("correct x=5 -> y=3")
    s.run("adapt epochs 5")
    with pytest.raises(LessonError, match="over `.*b.terms.yaml`, the term set `a.rules` reads"):
        s.run(f"save {tmp_path / 'b.rules'}")
    assert (tmp_path / "b.terms.yaml").read_text() == terms and not (tmp_path / "b.rules").exists()
    with pytest.raises(LessonError, match=r"does not end in `\.rules`") as e:
        s.run(f"save {tmp_path / 'out.txt'}")
    assert e.value.hint == f"save {(tmp_path / 'out.rules').as_posix()}"
    # a dot-file's suffix is empty: `.rules` "did not end in `.rules`" (hint `.rules.rules`)
    with pytest.raises(LessonError, match=r"names no rule file: `\.rules` is the ending") as e:
        s.run(f"save {tmp_path / '.rules'}")
    assert e.value.hint == f"give it a name: `save {(tmp_path / 'taught.rules').as_posix()}`"
    s.run(f"save {tmp_path / 'a.rules'}")          # over the original: its term set in place
    assert (tmp_path / "b.terms.yaml").read_text() != terms


def test_a_save_whose_text_would_not_read_back_writes_nothing(rules, tmp_path, monkeypatch):
    """The read-back check: whatever the text surgery gets wrong, no broken file is written."""
    from mitos_cli.teach import save

    monkeypatch.setattr(save, "_apply", lambda text, edits: text + "\n}{ broken")
    s = Session(rules, out=[].append)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    s.run("adapt epochs 3")
    with pytest.raises(LessonError, match="does not hold the session's rule base.*nothing was "
                                          "written"):
        s.run(f"save {tmp_path / 'x.rules'}")
    assert list(tmp_path.iterdir()) == [rules.parent]


def test_save_never_replaces_a_term_set_the_user_did_not_name(rules, tmp_path):
    """`save out.rules` writes out.mitos.terms.yaml and out.drive.terms.yaml beside it: one
    already there that no out.rules reads is the user's, and nothing is written."""
    s = Session(rules, out=[].append)
    out = tmp_path / "out.rules"
    (tmp_path / "out.drive.terms.yaml").write_text("# mine\n")
    with pytest.raises(LessonError, match=r"is already there and no term set of `.*out.rules`"
                                          r"( \(\d+ characters\))?; saving as `out.rules` "
                                          r"would write") as e:     # a long path is abridged
        s.run(f"save {out}")
    assert e.value.hint == "remove it, or save under another name"
    assert (tmp_path / "out.drive.terms.yaml").read_text() == "# mine\n"
    assert not out.exists() and not (tmp_path / "out.mitos.terms.yaml").exists()
    (tmp_path / "out.drive.terms.yaml").unlink()
    s.run(f"save {out}")
    s.run("correct road=78 size=45 position=4 -> steering=60")
    s.run("adapt epochs 2")
    s.run("save")              # again over out.rules: the term sets it reads are its own
    assert "# mine" not in (tmp_path / "out.drive.terms.yaml").read_text()


def test_save_names_the_rule_file_it_could_not_write_and_the_directory_it_made(
        rules, tmp_path, monkeypatch):
    """`save /proc/x.rules` said only `cannot write /proc/x.mitos.terms.yaml: No such file or
    directory` (the term set, no hint); `save mitos.terms.yaml` hinted `save
    mitos.terms.rules`; `save nodir/x.rules` made `nodir/` without a word."""
    import os

    out: list[str] = []
    s = Session(rules, out=out.append)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    s.run("adapt epochs 2")
    locked = tmp_path / "locked"
    locked.mkdir()
    real_open = os.open

    def refuse(path, *args, **kwargs):
        if str(path).startswith(str(locked)):
            raise FileNotFoundError(2, "No such file or directory")
        return real_open(path, *args, **kwargs)

    monkeypatch.setattr(os, "open", refuse)
    with pytest.raises(LessonError) as info:
        s.run(f"save {locked / 'x.rules'}")
    assert info.value.message == (f"cannot save `{locked / 'x.rules'}`: cannot write "
                                  f"`{locked / 'x.mitos.terms.yaml'}`: No such file or directory")
    assert info.value.hint.startswith("save where you can write files (`save ~/x.rules`)")
    with pytest.raises(LessonError) as info:                  # the directory it made goes
        s.run(f"save {locked / 'sub' / 'x.rules'}")
    assert not (locked / "sub").exists()
    monkeypatch.undo()
    with pytest.raises(LessonError) as info:
        s.run(f"save {tmp_path / 'mitos.terms.yaml'}")
    assert info.value.message.endswith("save writes a rule file (and its term sets beside it)")
    assert info.value.hint == f"save {(tmp_path / 'mitos.rules').as_posix()}"
    with pytest.raises(LessonError) as info:                  # never the original itself
        s.run(f"save {rules.with_name('mitos.terms.yml')}")
    assert info.value.hint == f"save {rules.with_name('taught.rules').as_posix()}"
    out.clear()
    s.run(f"save {tmp_path / 'nodir' / 'x.rules'}")
    assert out[0] == f"created the directory {tmp_path / 'nodir'}"
    assert out[1].startswith(f"saved {tmp_path / 'nodir' / 'x.rules'}")


def test_a_lesson_whose_save_cannot_be_written_is_not_told_to_save_where_it_may_not(
        rules, tmp_path, monkeypatch):
    """A lesson's `save` into a directory it cannot write was answered "save where you can
    write files (`save ~/x.rules`)", which a lesson refuses (it writes below the working
    directory only): the hint names what a lesson can do."""
    import os

    monkeypatch.chdir(tmp_path)
    s = Session(rules, out=[].append)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    (tmp_path / "locked").mkdir()
    real_open = os.open

    def refuse(path, *args, **kwargs):
        if "locked" in str(path):
            raise OSError(30, "Read-only file system")
        return real_open(path, *args, **kwargs)

    monkeypatch.setattr(os, "open", refuse)
    s.confined = tmp_path                                   # as `run_lesson` sets it
    with pytest.raises(LessonError) as info:
        s.run("save locked/x.rules", "l.lesson", 2)
    assert info.value.message == ("cannot save `locked/x.rules`: cannot write "
                                  "`locked/x.mitos.terms.yaml`: Read-only file system")
    assert "~/" not in info.value.hint
    assert info.value.hint == ("a lesson saves below the working directory: save where you "
                               "can write there, or give the place with `--save-as PATH`; "
                               "the session keeps every change")


def test_a_save_into_a_directory_it_cannot_write_is_refused_by_the_checks(rules, tmp_path,
                                                                          monkeypatch):
    """`--save-as ro/x.rules` (a read-only or foreign directory) ran the whole lesson and
    failed at its end: the directory is asked for with the other checks, before a session
    starts (`check_save_target`), also for a last directory the save would make in it."""
    import os

    from mitos_cli.teach.save import check_save_target

    locked = tmp_path / "locked"
    locked.mkdir()
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda path, mode, **kw: False if Path(path) == locked
                        else real_access(path, mode, **kw))
    original = load_rules_file(rules)
    for target in (locked / "x.rules", locked / "new" / "x.rules"):
        with pytest.raises(LessonError) as info:
            check_save_target(original, target)
        assert info.value.message.startswith(f"cannot save `{target}`: cannot write in "
                                             f"`{locked}`: ")
        assert info.value.hint is None            # (the caller says where else to save)
    assert not (locked / "new").exists()
    check_save_target(original, tmp_path / "x.rules")        # the others are as before


def _two_termsets_named_alike(tmp_path):
    """A rule file reading `a/x.terms.yaml` (its input) and `b/x.terms.yaml` (its output)."""
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    (tmp_path / "a" / "x.terms.yaml").write_text(
        "variables:\n  x:\n    role: input\n    universe: [0, 10]\n    terms:\n"
        "      LO: {shape: left_shoulder, points: [2, 5]}\n"
        "      MID: {shape: triangle, peak: 5, width: 3}\n"
        "      HI: {shape: right_shoulder, points: [5, 8]}\n")
    (tmp_path / "b" / "x.terms.yaml").write_text(
        "variables:\n  y:\n    role: output\n    universe: [0, 100]\n    default: 50\n"
        "    terms: {A: 0, B: 25, C: 50, D: 75, E: 100}\n")
    rules = tmp_path / "two.rules"
    rules.write_text('terms "a/x.terms.yaml", "b/x.terms.yaml"\n\nbehavior main:\n'
                     "    r0: if x is LO then y is A\n    r1: if x is MID then y is C\n"
                     "    r2: if x is HI then y is E\nend\n")
    return rules


def test_two_term_sets_of_one_file_name_are_saved_to_two_files(tmp_path):
    """Named by file name alone, both went to `out.x.terms.yaml`, the output's over the
    input's: the save said so and succeeded, and the saved rule base did not load."""
    s = Session(_two_termsets_named_alike(tmp_path), out=[].append)
    s.run("correct x=3 -> y=20")
    s.run("adapt epochs 5")
    s.run(f"save {tmp_path / 'out.rules'}")
    assert (tmp_path / "out.rules").read_text().splitlines()[0] == \
        'terms "out.a.x.terms.yaml", "out.b.x.terms.yaml"'
    back = load_rules_file(tmp_path / "out.rules")
    assert variables(back) == variables(s.rulebase)


def test_a_terms_line_with_an_escape_json_does_not_know_is_saved(tmp_path):
    """`terms "b\\s.terms.yaml"` (a backslash, as in a path written on Windows) loads, the
    escape kept as written; saving it under another name raised a Python traceback."""
    src = _two_termsets_named_alike(tmp_path)
    (tmp_path / "b\\s.terms.yaml").write_text((tmp_path / "b" / "x.terms.yaml").read_text())
    rules = tmp_path / "one.rules"
    rules.write_text(src.read_text().replace('"b/x.terms.yaml"', '"b\\s.terms.yaml"'))
    s = Session(rules, out=[].append)
    s.run("correct x=3 -> y=20")
    s.run("adapt epochs 2")
    for name in ("out.rules", 'q"uote.rules'):       # a `"` in the new name: escaped
        s.run(f"save {json.dumps(str(tmp_path / name))}")
        assert variables(load_rules_file(tmp_path / name)) == variables(s.rulebase)


def test_a_rule_base_written_with_crlf_is_saved_with_crlf(rules, tmp_path):
    """Read with universal newlines, a rule base written on Windows was saved with `\\n`:
    `git diff` showed every line changed where only numbers were learned."""
    for f in rules.parent.iterdir():
        f.write_bytes(f.read_bytes().replace(b"\n", b"\r\n"))
    s = Session(rules, out=[].append)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    s.run("adapt epochs 5")
    s.run(f"save {tmp_path / 'out.rules'}")
    for name, src in (("out.rules", "mitos.rules"), ("out.mitos.terms.yaml", "mitos.terms.yaml")):
        before = (rules.parent / src).read_bytes().split(b"\r\n")
        after = (tmp_path / name).read_bytes()
        assert after.count(b"\n") == after.count(b"\r\n")
        lines = after.split(b"\r\n")
        assert len(lines) == len(before)
        assert sum(a != b for a, b in zip(before, lines)) < len(lines) // 3
    assert variables(load_rules_file(tmp_path / "out.rules")) == variables(s.rulebase)


def test_a_rule_base_written_with_a_bom_is_saved_with_it(rules, tmp_path):
    """A rule file beginning with a byte-order mark (Notepad's UTF-8) loads, but `save` parsed
    it with the mark: a Python traceback (lark's UnexpectedCharacters) ended the session."""
    for f in rules.parent.iterdir():
        f.write_bytes(b"\xef\xbb\xbf" + f.read_bytes())
    s = Session(rules, out=[].append)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    s.run("adapt epochs 5")
    s.run(f"save {tmp_path / 'out.rules'}")
    for name in ("out.rules", "out.mitos.terms.yaml", "out.drive.terms.yaml"):
        assert (tmp_path / name).read_bytes().startswith(b"\xef\xbb\xbf# ")     # one mark
    assert variables(load_rules_file(tmp_path / "out.rules")) == variables(s.rulebase)


def test_operators_told_for_the_top_level_rules_keep_the_other_behaviors_as_they_were(tmp_path):
    """The file has no block of `main`'s own: its operators go on the top-level `operators:`
    line, every behavior's default. Beside any behavior (in the file, or told) the save read
    back as another rule base and was refused as "a bug in MITOS"."""
    from mitos_cli.lang.operators import of_behavior

    src = _two_termsets_named_alike(tmp_path)
    rules = tmp_path / "mixed.rules"
    rules.write_text('terms "a/x.terms.yaml", "b/x.terms.yaml"\noperators: or = max\n'
                     "r0: if x is LO then y is A\nr1: if x is MID then y is C\n\n"
                     "behavior other:\n    r0: if x is HI then y is E\nend\n")
    assert src.exists()
    s = Session(rules, out=[].append)
    s.run("operators: and = product, or = probor")
    s.run("behavior told")
    s.run("if x is HI then y is D")
    s.run("end")
    s.run(f"save {tmp_path / 'out.rules'}")
    back = load_rules_file(tmp_path / "out.rules")
    for name in ("main", "other", "told"):
        assert of_behavior(back, back.behavior(name)) == \
            of_behavior(s.rulebase, s.rulebase.behavior(name))
    assert of_behavior(back, back.behavior("other")).and_ == "min"


def test_a_file_where_the_directory_goes_is_said_to_be_one(rules, tmp_path):
    """`save notes.txt/x.rules` beside a file `notes.txt` said "cannot create `notes.txt`:
    File exists", and `save notes.txt/a/x.rules` that the directory does not exist."""
    (tmp_path / "notes.txt").write_text("mine\n")
    s = Session(rules, out=[].append)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    for name in ("notes.txt/x.rules", "notes.txt/a/x.rules"):
        with pytest.raises(LessonError) as info:
            s.run(f"save {tmp_path / name}")
        assert info.value.message.endswith(f"`{tmp_path / 'notes.txt'}` is a file, not a directory")
    assert (tmp_path / "notes.txt").read_text() == "mine\n"


def test_saving_over_the_original_twice_and_elsewhere_after_it(rules, tmp_path):
    """A second save after a save over the original edited the file that save had written
    against the rule base read before it, wrote its new rules twice, and was refused as "a
    bug in MITOS": the session could save nothing more, under any name."""
    s = Session(rules, out=[].append)
    s.run("r27: if road is NARROW then speed is SLOW")
    s.run(f"save {rules}")
    s.run("r28: if road is WIDE then speed is FAST")
    s.run(f"save {rules}")
    s.run(f"save {tmp_path / 'other.rules'}")
    for path in (rules, tmp_path / "other.rules"):
        text = path.read_text()
        assert text.count("r27:") == text.count("r28:") == 1
        assert load_rules_file(path).behaviors == s.rulebase.behaviors


def test_a_resumed_session_undoes_what_its_save_over_the_original_wrote(rules, tmp_path):
    """--resume read the original as the session's own save had left it and applied the
    journal over it again: it warned that the files had changed, and `undo` said a rule was
    taken back that stayed in the rule base (and in the next save)."""
    from mitos_cli.teach.journal import Journal

    s = Session(rules, journal=Journal.create(tmp_path / "j"), out=[].append)
    s.run("r27: if road is NARROW then speed is SLOW")
    s.run("r28: if road is WIDE then speed is FAST")
    s.run(f"save {rules}")
    out: list[str] = []
    again = Session.resume(Journal.open(tmp_path / "j"), out=out.append)
    assert not any("changed since" in x for x in out)
    again.run("undo")
    assert [r.label for r in again.rulebase.behavior("avoid_obstacle").rules][-1] == "r27"
    again.run("save")
    assert "r28:" not in rules.read_text() and "r27:" in rules.read_text()


def test_a_save_over_an_original_another_program_changed_is_refused(rules, tmp_path):
    """Another program's change of the original since the session read it made every save
    fail as "a bug in MITOS"; a save over it would undo that change, so it is refused and
    says why, and a save under another name writes the session's rule base."""
    s = Session(rules, out=[].append)
    s.run("r27: if road is NARROW then speed is SLOW")
    edited = rules.read_text().replace("then steering is RM and speed is MEDIUM",
                                       "then steering is RB and speed is SLOW", 1)
    rules.write_text(edited)
    with pytest.raises(LessonError, match="changed since this session read them") as err:
        s.run(f"save {rules}")
    assert "mitos teach --resume" in err.value.hint
    assert rules.read_text() == edited
    s.run(f"save {tmp_path / 'taught.rules'}")
    assert load_rules_file(tmp_path / "taught.rules").behaviors == s.rulebase.behaviors


def test_two_sessions_saving_one_file_at_once_never_lose_a_save_silently(rules, monkeypatch):
    """Two `mitos teach` saving over the original at the same moment: each checked that the
    files were as it read them, then wrote, so B's save between A's check and A's write was
    undone by A's without a word (both said `saved`). The check and the write now hold the
    directory's lock: B waits for A, then finds the files changed and is refused."""
    import threading

    from mitos_cli.teach import save as save_module

    a, b = Session(rules, out=[].append), Session(rules, out=[].append)
    a.run("r27: if road is NARROW then speed is SLOW")
    b.run("r28: if road is WIDE then speed is FAST")
    real = save_module.save_rulebase
    outcome: dict[str, object] = {}

    def b_saves() -> None:
        try:
            b.run(f"save {rules}")
            outcome["b"] = "saved"
        except LessonError as exc:
            outcome["b"] = exc

    def a_save_with_b_inside(*args, **kwargs):
        if threading.current_thread() is threading.main_thread():
            outcome["thread"] = thread = threading.Thread(target=b_saves)
            thread.start()
            thread.join(1.0)                   # B saves now, between A's check and write
        return real(*args, **kwargs)

    monkeypatch.setattr(save_module, "save_rulebase", a_save_with_b_inside)
    a.run(f"save {rules}")
    outcome["thread"].join(30)
    text = rules.read_text()
    assert "r27:" in text and "r28:" not in text
    assert isinstance(outcome["b"], LessonError)
    assert "changed since this session read them" in outcome["b"].message


def test_a_save_over_what_another_session_saved_there_since_is_refused(rules, tmp_path):
    """Two sessions saving `taught.rules` in turn: A's second save undid B's without a word.
    A save over files this session saved is refused when another wrote them since."""
    target = tmp_path / "taught.rules"
    a, b = Session(rules, out=[].append), Session(rules, out=[].append)
    a.run("r27: if road is NARROW then speed is SLOW")
    a.run(f"save {target}")
    b.run("r28: if road is WIDE then speed is FAST")
    b.run(f"save {target}")
    a.run("r29: if road is MEDIUM then speed is SLOW")
    with pytest.raises(LessonError, match="changed since this session saved them there") as err:
        a.run("save")
    assert "save under another name" in err.value.hint
    assert "r28:" in target.read_text() and "r29:" not in target.read_text()
    a.run(f"save {tmp_path / 'taught2.rules'}")             # the session goes on
    b.run("r30: if road is NARROW then speed is FAST")
    b.run("save")                                            # its own files, unchanged since
    assert "r30:" in target.read_text()


def test_a_save_whose_term_set_name_is_too_long_is_a_command_error(rules, tmp_path):
    """`save OUT.rules` with a name of 240 characters: the term set's, 257, could not be
    looked up, and the `OSError` ended the teaching prompt with a bare "error:", no place."""
    from mitos_cli.teach.save import check_save_target

    s = Session(rules, out=[].append)
    s.run("r27: if road is NARROW then speed is SLOW")
    target = tmp_path / ("x" * 240 + ".rules")
    with pytest.raises(LessonError, match="File name too long") as err:
        s.run(f"save {target}")
    assert "at most 255 characters" in err.value.hint
    with pytest.raises(LessonError, match="File name too long"):
        check_save_target(s.original, target)
    s.run(f"save {tmp_path / 'short.rules'}")                 # the session goes on
    assert "r27:" in (tmp_path / "short.rules").read_text()


def test_a_save_over_the_original_killed_before_its_record_is_the_sessions_own(rules,
                                                                              tmp_path):
    """A kill after a save over the original wrote its files and before the journal recorded
    it: `--resume` said the files had been changed by another program and applied the
    journal over them, so `undo` could not take back what the save wrote."""
    from mitos_cli.teach.journal import Journal

    s = Session(rules, journal=Journal.create(tmp_path / "j"), out=[].append)
    s.run("r27: if road is NARROW then speed is SLOW")
    original = rules.read_text()
    save_rulebase(s.original, s.rulebase, rules, s.sources)      # the files, not the record
    out: list[str] = []
    again = Session.resume(Journal.open(tmp_path / "j"), out=out.append)
    assert not any("changed since" in x for x in out), out
    again.run("undo")
    again.run(f"save {rules}")
    assert rules.read_text() == original


def _signal_once_a_save_is_written(monkeypatch, signum: int) -> None:
    """Send this process ``signum`` once the next save has written its files, before the
    session takes note of them (the second digest of the files: the first is before)."""
    import os
    import time

    import mitos_cli.teach.session as session_module

    real = session_module.files_digest
    calls: list = []

    def signalled(rb):
        calls.append(rb)
        if len(calls) == 2:
            monkeypatch.setattr(session_module, "files_digest", real)
            os.kill(os.getpid(), signum)
            time.sleep(0.05)             # the signal is taken here
        return real(rb)

    monkeypatch.setattr(session_module, "files_digest", signalled)


def test_ctrl_c_once_a_save_over_the_original_is_written_keeps_the_next_save(rules, monkeypatch,
                                                                             sigint):
    """A Ctrl-C after a save over the original wrote its files and before the session took
    note of them: the next save over them was refused, as if another program had changed
    them."""
    import signal

    s = Session(rules, out=[].append)
    s.run("r27: if road is NARROW then speed is SLOW")
    _signal_once_a_save_is_written(monkeypatch, signal.SIGINT)
    with pytest.raises(KeyboardInterrupt):
        s.run(f"save {rules}")
    s.replay()                           # what the prompt does after a Ctrl-C
    s.run("r28: if road is WIDE then speed is FAST")
    s.run(f"save {rules}")
    assert "r28:" in rules.read_text() and not s.unsaved


def test_a_sigterm_once_a_save_is_written_waits_until_it_is_journaled(rules, monkeypatch):
    """A SIGTERM (which `mitos teach` answers as Ctrl-C) once a save over the original wrote
    its files is raised after the session took note of them and journaled the save."""
    import signal

    from mitos_cli.cli.progress import terminate_as_interrupt
    from mitos_cli.errors import Terminated

    s = Session(rules, out=[].append)
    s.run("r27: if road is NARROW then speed is SLOW")
    _signal_once_a_save_is_written(monkeypatch, signal.SIGTERM)
    with terminate_as_interrupt(), pytest.raises(Terminated):
        s.run(f"save {rules}")
    assert s.journal.entries[-1]["op"] == "save" and not s.unsaved
    s.run("r28: if road is WIDE then speed is FAST")
    s.run(f"save {rules}")
    assert "r28:" in rules.read_text() and not s.unsaved


def test_save_refuses_a_link_into_another_directory(tmp_path):
    """The rule file went where the link leads and its term sets beside the link, so the file
    written did not load; a link within the directory saves as before."""
    (tmp_path / "a.rules").write_text('terms "t.terms.yaml"\nr0: if x is LO then y is A\n')
    (tmp_path / "t.terms.yaml").write_text(
        "variables:\n  x: {role: input, universe: [0, 10], terms: {LO: {shape: left_shoulder, "
        "points: [2, 8]}}}\n  y: {role: output, universe: [0, 10], terms: {A: 2}}\n")
    (tmp_path / "real").mkdir()
    (tmp_path / "real" / "kept.rules").write_text("keep\n")
    (tmp_path / "link.rules").symlink_to(tmp_path / "real" / "kept.rules")
    s = Session(tmp_path / "a.rules", out=[].append)
    s.run("correct x=5 -> y=3")
    with pytest.raises(LessonError, match="is a link to .*kept.rules`, in another directory") as e:
        s.run(f"save {tmp_path / 'link.rules'}")
    assert e.value.hint == f"save to `{tmp_path / 'real' / 'kept.rules'}` itself, or under a name " \
                           "that is no link"
    assert (tmp_path / "real" / "kept.rules").read_text() == "keep\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.rules", "link.rules", "real",
                                                          "t.terms.yaml"]
    (tmp_path / "same.rules").symlink_to("kept2.rules")
    s.run(f"save {tmp_path / 'same.rules'}")
    assert load_rules_file(tmp_path / "kept2.rules").termset_paths == ("same.terms.yaml",)


def test_a_comment_on_a_number_that_changed_is_marked_and_the_rest_kept():
    """The shipped lesson's save kept `# eq. 15: width 30 in` beside `width: 17.71`, which it
    no longer is: a comment on the line of a number the save changes says it was so before
    teaching; a comment on an unchanged line, a `#` inside quotes and a header stay."""
    import dataclasses

    from mitos_cli.lang.termfile import parse_termset
    from mitos_cli.teach.save import edit_termset

    text = ("# the term set, as drawn   # (a header: kept)\n"
            "variables:\n  x:\n    description: \"x # not a comment\"\n    role: input\n"
            "    universe: [0, 100]\n    terms:\n"
            "      LOW:  {shape: left_shoulder, points: [20, 50]}   # eq. 3: 20 in\n"
            "      MID:\n        shape: triangle\n        peak: 50      # the centre\n"
            "        width: 30     # eq. 4: width 30\n"
            "      HIGH: {shape: right_shoulder, points: [50, 80]}  # at 80 (before teaching)\n"
            "      TOP:  {shape: right_shoulder, points: [80, 95]}  # untouched\n")
    old = parse_termset(text, "x.yaml")
    moved = {"LOW": (25.5, 50.0), "MID": (50.0, 24.5), "HIGH": (50.0, 75.0),
             "TOP": (80.0, 95.0)}
    new = dataclasses.replace(old, variables=tuple(v.with_terms(tuple(
        dataclasses.replace(t, params=moved[t.name]) for t in v.terms))
        for v in old.variables))
    written, changes = edit_termset(text, "x.yaml", old, new)
    assert written == (text
                       .replace("[20, 50]}   # eq. 3: 20 in",
                                "[25.5, 50]}   # eq. 3: 20 in (before teaching)")
                       .replace("width: 30     # eq. 4: width 30",
                                "width: 24.5     # eq. 4: width 30 (before teaching)")
                       .replace("[50, 80]}  # at 80 (before teaching)",
                                "[50, 75]}  # at 80 (before teaching)"))
    assert changes == ["x.LOW: (20, 50) -> (25.5, 50); its comment marked `(before teaching)`",
                       "x.MID: (50, 30) -> (50, 24.5); its comment marked `(before teaching)`",
                       "x.HIGH: (50, 80) -> (50, 75)"]
    assert parse_termset(written).variables[0] == new.variables[0]


def test_a_comment_beside_a_learned_crisp_value_is_marked(tmp_path):
    """The same in a rule file: adaptation moves a crisp consequent (`then y is 10`), and the
    comment on its line spoke of 10; a rule's comment on a line that kept its numbers stays."""
    (tmp_path / "r.terms.yaml").write_text(
        "variables:\n  x:\n    role: input\n    universe: [0, 10]\n    terms:\n"
        "      LOW: {shape: left_shoulder, points: [2, 8]}\n"
        "      HIGH: {shape: right_shoulder, points: [2, 8]}\n"
        "  y:\n    role: output\n    universe: [0, 100]\n    terms: {A: 0}\n")
    (tmp_path / "r.rules").write_text(
        'terms "r.terms.yaml"\n'
        "r1: if x is LOW then y is 10     # ten, as measured\n"
        "r2: if x is HIGH then y is 90    # ninety\n")
    s = Session(tmp_path / "r.rules", out=[].append)
    s.run("frozen x.LOW, x.HIGH")
    s.run("frozen r2")
    s.run("correct x=0 -> y=30")
    s.run("adapt epochs 20")
    s.run(f"save {tmp_path / 'out.rules'}")
    text = (tmp_path / "out.rules").read_text()
    learned = s.rulebase.behaviors[0].rules[0].consequents[0].value
    assert learned is not None and learned > 10
    assert text.splitlines()[1:3] == [
        f"r1: if x is LOW then y is {learned:.4g}     # ten, as measured (before teaching)",
        "r2: if x is HIGH then y is 90    # ninety"]
