"""Every teaching command through the session (and its mistakes), undo and journal replay."""

import dataclasses
import json
import re
import shutil
from pathlib import Path

import pytest

from mitos_cli.api import default_rulebase_path
from mitos_cli.errors import LessonError, MitosError, NameError_, RuleBaseError, RuleSyntaxError
from mitos_cli.teach.journal import Journal
from mitos_cli.teach.prompt import at_prompt
from mitos_cli.teach.session import Session

RULEBASES = default_rulebase_path().parent


@pytest.fixture
def rules(tmp_path):
    for f in RULEBASES.iterdir():
        if f.is_file():
            shutil.copy(f, tmp_path / f.name)
    return tmp_path / "mitos.rules"


def session(rules, tmp_path=None, journal=None):
    out = []
    s = Session(rules, journal=journal, out=out.append)
    return s, out


def say(s, out, line):
    out.clear()
    s.run(line)
    return "\n".join(out)


def test_a_wrapped_rule_is_one_line_of_the_history_and_of_undo(rules):
    """A rule told over several lines was listed by `show history` (and said by `undo`) as
    typed: its next lines at the left margin, outside the numbered list."""
    s, out = session(rules)
    s.run("if road is NARROW\n   and size is SMALL_SZ\n   then speed is SLOW")
    assert say(s, out, "show history").splitlines()[1] == \
        "   2  if road is NARROW and size is SMALL_SZ then speed is SLOW"
    assert say(s, out, "undo") == "undone: if road is NARROW and size is SMALL_SZ then speed is SLOW"
    assert say(s, out, "show history").splitlines()[1:] == [
        "   2  if road is NARROW and size is SMALL_SZ then speed is SLOW  (undone)", "   3  undo"]


def test_the_history_names_the_packaged_rule_base_as_every_command_does():
    """`show history` of a session on the packaged rule base began `started on
    /.../site-packages/mitos_cli/_data/rulebases/mitos.rules`, where pip put it; every other
    answer calls it `rulebases/mitos.rules (packaged)`."""
    s, out = session(default_rulebase_path())
    assert say(s, out, "show history").splitlines()[0] == \
        "   1  started on rulebases/mitos.rules (packaged), behavior avoid_obstacle"


def test_advice_to_use_a_behavior_while_one_is_open_closes_it_first(rules):
    """While a behavior is open, `use NAME` is one of its lines (a blend), not a recall: the
    notes that said "`use b1` before `adapt`" led to "`b1` uses `b1`: a cycle" (b1 open again
    after `undo` of its `end`), or blended `drive` into the open behavior without a word."""
    s, out = session(rules)
    for line in ("behavior b1", "use drive", "end", "simulate figure4", "undo"):
        s.run(line)                                         # `undo`: b1 is open again
    text = say(s, out, "at 3s steering=50")
    assert "; `end` (it then becomes the active behavior) before `adapt`" in text
    with pytest.raises(LessonError) as info:
        s.run("adapt epochs 1")
    assert info.value.hint == ("the examples given so far correct b1: `end` (it then becomes "
                               "the active behavior) to adapt it")
    s.run("end")
    s.run("behavior b2")
    text = say(s, out, "simulate figure4")                  # b1 drives; the world's own: drive
    assert text.endswith("(`mitos simulate` drives figure4 with behavior drive: `end` (`use` "
                         "in the open behavior `b2` blends `drive` into it), then `use drive` "
                         "to drive it so here)")


def test_an_unknown_behavior_is_marked_at_its_name(rules):
    """`use driv` was marked from `use` to the end of the line, where every other unknown
    name (a term, a variable, a world, a label) is marked at itself."""
    from mitos_cli.teach.prompt import at_prompt

    s, _ = session(rules)
    for line, caret in (("use driv", "    ^^^^"), ("behavior b", None),
                        ("use drve when road is WIDE", "    ^^^^")):
        if caret is None:
            s.run(line)
            continue
        with pytest.raises(NameError_) as info:
            s.run(line, "<prompt>", 3)
        rendered = at_prompt(info.value, line, 3).render().splitlines()
        assert rendered[0].startswith("<prompt>:3:5: name error: unknown behavior `dr")
        assert rendered[2] == "    " + caret


def test_a_label_another_behavior_has_adds_a_rule_here_and_says_so(rules):
    """`r25: if ...` with `drive` active added a rule r25 to drive without a word, where the
    instructor most likely meant to replace avoid_obstacle's r25 (the paper's rule)."""
    s, out = session(rules)
    s.run("use drive")
    assert say(s, out, "r25: if road is NARROW then speed is SLOW").splitlines() == [
        "r25: if road is NARROW then speed is SLOW", "  added to drive (1 rule)",
        "  note: avoid_obstacle has a rule r25 too, which stays as it was (`use "
        "avoid_obstacle` to replace that one)"]
    assert "note" not in say(s, out, "r25: if road is WIDE then speed is SLOW")   # replaced
    assert "note" not in say(s, out, "r77: if road is WIDE then speed is FAST")


def test_a_told_rule_is_answered_as_understood_with_conflicts(rules):
    s, out = session(rules)
    text = say(s, out, "if road is  WIDE and size is SMALL_SZ and position is LEFT "
                       "then steering is RM and speed is MEDIUM")
    assert text.splitlines()[0] == ("r27: if road is WIDE and size is SMALL_SZ and position is "
                                    "LEFT then steering is RM and speed is MEDIUM")
    assert "added to avoid_obstacle (28 rules)" in text
    assert "conflict: r0 has the same condition but says steering is RS, speed is MEDIUM" in text
    text = say(s, out, "r27: if position is LEFT and road is WIDE and size is SMALL_SZ "
                       "then steering is RS and speed is MEDIUM")
    assert "replaces r27: if road is WIDE" in text and "note: r0 says the same" in text
    assert len(s.rulebase.behavior("avoid_obstacle").rules) == 28


def test_rule_mistakes_keep_the_session(rules):
    s, out = session(rules)
    with pytest.raises(NameError_) as info:
        s.run("if road is WIDEE then steering is LS")
    assert "did you mean `WIDE`?" in info.value.render()
    with pytest.raises(RuleBaseError, match="output variable"):
        s.run("if steering is LS then speed is SLOW")
    assert len(s.rulebase.behavior("avoid_obstacle").rules) == 27
    assert say(s, out, "eval road=78 size=45 position=4").endswith("speed = 32.4 in/s")


def test_behavior_end_use_and_recall_by_name(rules):
    s, out = session(rules)
    assert "tell its rules" in say(s, out, "behavior careful")
    assert s.focus == "careful"
    say(s, out, "if road is NARROW then speed is CREEP")
    say(s, out, "use avoid_obstacle when obstacle is NEAR")
    with pytest.raises(LessonError, match="still open"):
        s.run("behavior other")
    with pytest.raises(LessonError, match="close it with `end` before saving"):
        s.run("save x.rules")
    assert "careful learned (1 rule, 1 use)" in say(s, out, "end")
    assert s.state.active == "careful"
    assert "active behavior: avoid_obstacle" in say(s, out, "use avoid_obstacle")
    with pytest.raises(LessonError, match="no behavior is open"):
        s.run("end")
    with pytest.raises(LessonError, match="exists already"):
        s.run("behavior careful")
    with pytest.raises(NameError_, match="unknown behavior `carefull`"):
        s.run("use carefull")
    with pytest.raises(LessonError, match="belongs inside a behavior"):
        s.run("use careful when road is WIDE")
    s.run("behavior empty")
    with pytest.raises(LessonError, match="is empty"):
        s.run("end")
    s.run("undo")
    s.run("behavior loop")
    with pytest.raises(RuleBaseError, match="cycle"):
        s.run("use loop")
    s2, out2 = session(rules)
    s2.run("behavior a")
    s2.run("use avoid_obstacle")
    s2.run("end")
    s2.run("use avoid_obstacle")
    s2.run("r99: if road is WIDE then speed is TOP")
    s2.run("behavior b")
    s2.run("use a")
    s2.run("end")
    assert s2.state.active == "b"


def test_frozen_in_a_behavior_without_rules_names_the_behavior_that_has_the_rule(rules):
    """`use drive` then `frozen r1`: `drive` has no rules of its own, and the refusal listed
    none and hinted nothing; it now says whose rule `r1` is and how to freeze it."""
    s, _ = session(rules)
    s.run("use drive")
    with pytest.raises(NameError_) as caught:
        s.run("frozen r1")
    assert caught.value.hint == ("`drive` has no rules of its own; `r1` is a rule of "
                                 "`avoid_obstacle`: `use avoid_obstacle`, then `frozen r1`")
    with pytest.raises(NameError_) as caught:
        s.run("frozen zork")
    assert caught.value.hint == "`drive` has no rules of its own"


def test_frozen_names_a_variable_where_its_terms_go(rules):
    """`frozen heading` (a variable, where a rule's label or a term goes) said "unknown rule
    label `heading`" with the labels alone: a variable's terms are frozen one by one."""
    s, _ = session(rules)
    with pytest.raises(NameError_) as caught:
        s.run("frozen position")
    assert caught.value.message == "unknown rule label `position` of `avoid_obstacle`"
    assert caught.value.hint == ("`position` is a variable: freeze its terms, `frozen "
                                 "position.LEFT, position.CENTER, position.RIGHT` (or one of "
                                 "them: `frozen position.LEFT`)")


def test_frozen_and_operators(rules):
    s, out = session(rules)
    assert "leaves the consequents of r4, r5 alone" in say(s, out, "frozen r4, r5")
    assert s.rulebase.behavior("avoid_obstacle").frozen == ("r4", "r5")
    with pytest.raises(NameError_, match="unknown rule label"):
        s.run("frozen r77")
    assert "operators: and = product" in say(s, out, "operators: and = product")
    with pytest.raises(NameError_, match="T-norm"):
        s.run("operators: and = minn")


def test_eval_and_its_mistakes(rules):
    s, out = session(rules)
    text = say(s, out, "eval road=78 size=45 position=4")
    assert "r25: if road is MEDIUM and size is MED_SZ and position is RIGHT" in text
    assert "steering = 65.4 deg" in text
    with pytest.raises(LessonError, match="missing input `position`"):
        s.run("eval road=78 size=45")
    with pytest.raises(LessonError) as info:
        s.run("eval road=78 sise=45 position=4")
    assert "did you mean `size`?" in info.value.render()
    with pytest.raises(LessonError, match="given twice"):
        s.run("eval road=78 road=80 size=45 position=4")
    with pytest.raises(LessonError, match="does not use input `heading`"):
        s.run("eval road=78 size=45 position=4 heading=3")


def test_correct_adapt_and_show(rules, tmp_path):
    s, out = session(rules)
    text = say(s, out, "correct road=78 size=45 position=4 -> steering=60 speed=20")
    assert text == ("example 1: road=78 size=45 position=4 -> steering=60 speed=20   "
                    "(now steering=65.41 speed=32.42)")
    with pytest.raises(LessonError, match=r"outside its universe \[30, 150\]"):
        s.run("correct road=78 size=45 position=4 -> steering=10")
    with pytest.raises(LessonError, match="output variable `steer`"):
        s.run("correct road=78 size=45 position=4 -> steer=60")
    say(s, out, "correct road=90 size=30 position=-3 -> steering=120")
    y = [s._outputs(s.compiled(), [e.inputs])[0] for e in s.state.examples]
    q0 = (y[0]["steering"] - 60) ** 2 + (y[0]["speed"] - 20) ** 2 + (y[1]["steering"] - 120) ** 2
    text = say(s, out, "adapt epochs 15 rate 0.5 unconstrained")  # two examples, fitted
    assert f"epoch    0: Q = {q0:.6g}" in text                     # closely: far from meaning
    q = [float(x.split("Q = ")[1]) for x in text.splitlines() if x.startswith("  epoch")]
    assert q == sorted(q, reverse=True) and q[-1] < 0.1 * q[0]
    assert "changed (before -> after):" in text and "road.MEDIUM: peak 70, width 30  ->" in text
    assert "(was peak 70, width 30)" in say(s, out, "show terms")
    shown = say(s, out, "show examples")
    assert "1  road=78 size=45 position=4 -> steering=60 speed=20   (now steering=" in shown
    assert "* avoid_obstacle (27 rules)" in say(s, out, "show behaviors")
    assert "r25: if road is MEDIUM" in say(s, out, "show rules")
    history = say(s, out, "show history")
    assert f"adapt epochs 15 rate 0.5 unconstrained   (Q {q0:.4g} ->" in history
    with pytest.raises(LessonError, match="whole number"):
        s.run("adapt epochs 2.5")
    with pytest.raises(LessonError, match=r"\(0, 1\)"):
        s.run("adapt rate 2")
    with pytest.raises(LessonError, match="has no plot"):
        s.run("show rules plot x.png")
    png = tmp_path / "terms.png"
    assert "plotted" in say(s, out, f"show terms plot {png}")
    assert any(p.name.startswith("terms-") for p in tmp_path.iterdir())


def test_adapt_without_examples_gives_an_example_of_the_behaviors_own_inputs(rules):
    """With `drive` active, `adapt` offered `correct road=78 size=45 position=4 ->
    steering=60`, which `correct` refuses there (drive reads 13 inputs)."""
    s, _ = session(rules)
    with pytest.raises(LessonError) as info:
        s.run("adapt")
    assert "`correct road=78 size=45 position=4 -> steering=60`" in info.value.hint
    s.run("use drive")
    with pytest.raises(LessonError) as info:
        s.run("adapt")
    assert info.value.hint.startswith("give corrections: `correct road=... size=... "
                                      "position=... ... -> steering=...` (every input of "
                                      "`drive`)")


def test_adapt_without_examples_or_with_everything_frozen(rules):
    s, out = session(rules)
    with pytest.raises(LessonError, match="no examples for behavior `avoid_obstacle`"):
        s.run("adapt")
    with pytest.raises(LessonError, match="nothing to undo"):
        s.run("undo")
    with pytest.raises(LessonError, match="no simulation to correct yet"):
        s.run("at 3s steering=80")


def test_undo_walks_back_every_change(rules):
    s, out = session(rules)
    original = s.rulebase
    s.run("r27: if road is NARROW then steering is LB")
    s.run("correct road=78 size=45 position=4 -> steering=60")
    s.run("adapt epochs 5")
    changed = s.rulebase
    assert changed.variables != original.variables
    s.run("undo")
    assert s.rulebase.variables == original.variables and len(s.state.examples) == 1
    s.run("undo")
    assert s.state.examples == []
    assert "undone: r27: if road is NARROW" in say(s, out, "undo")
    assert s.rulebase == original
    with pytest.raises(LessonError, match="nothing to undo"):
        s.run("undo")


def test_journal_replay_rebuilds_the_same_state(rules, tmp_path):
    journal = Journal.create(tmp_path / "session")
    s, out = session(rules, journal=journal)
    for line in ["r27: if road is NARROW then steering is LB", "behavior b",
                 "if road is WIDE then speed is FAST", "end", "use avoid_obstacle",
                 "correct road=78 size=45 position=4 -> steering=60", "adapt epochs 5",
                 "frozen r4", "undo"]:
        s.run(line)
    lines = journal.path.read_text().splitlines()
    assert all(json.loads(x)["seq"] == i for i, x in enumerate(lines, 1))
    again = Session.resume(Journal.open(tmp_path / "session"), out=[].append)
    assert again.rulebase == s.rulebase
    assert again.state.examples == s.state.examples
    assert again.state.active == s.state.active == "avoid_obstacle"


def test_a_torn_last_journal_line_is_dropped(rules, tmp_path):
    journal = Journal.create(tmp_path / "j")
    s, _ = session(rules, journal=journal)
    s.run("r27: if road is NARROW then steering is LB")
    with open(journal.path, "a") as fh:
        fh.write('{"seq": 3, "op": "rule", "beh')
    j = Journal.open(tmp_path / "j")
    assert j.skipped_tail and len(j.entries) == 2
    assert Session.resume(j, out=[].append).rulebase == s.rulebase


@pytest.mark.parametrize("edit, says", [
    (lambda e: e["examples"][0].update(inputs=5), "not inputs and targets given as numbers"),
    (lambda e: e["examples"][0]["inputs"].update(size=[1, 2]), "given as numbers by name"),
    (lambda e: e["examples"][0]["targets"].update(steering=True), "given as numbers by name"),
    (lambda e: e["examples"][0]["inputs"].update(size=float("nan")), "given as numbers"),
    (lambda e: e["examples"][0]["inputs"].update(size=10**400), "given as numbers"),  # no float
    (lambda e: e.update(behavior=1.5), "`behavior` is 1.5, not a name"),
    (lambda e: e["examples"][0]["inputs"].pop("size"), "no value for `size`"),
    (lambda e: e["examples"][0]["targets"].update(spead=1.0), "`spead` is not one of its outputs"),
])
def test_a_journal_whose_examples_were_edited_is_refused_at_their_line(rules, tmp_path, edit,
                                                                         says):
    journal = Journal.create(tmp_path / "j")
    s, _ = session(rules, journal=journal)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    lines = journal.path.read_text().splitlines()
    entry = json.loads(lines[1])
    edit(entry)
    journal.path.write_text("\n".join([lines[0], json.dumps(entry)]) + "\n")
    with pytest.raises(LessonError, match=says) as info:
        Session.resume(Journal.open(tmp_path / "j"), out=[].append)
    assert info.value.span is not None and info.value.span.line == 2


@pytest.mark.parametrize("op, edit, says", [
    ("frozen", lambda e: e.update(labels=[1]), "`labels` are not rule labels"),
    ("frozen", lambda e: e.update(labels=[[1]]), "`labels` are not rule labels"),
    ("adapt", lambda e: e.update(q=[]), "`q` is not its Q before and after"),
    ("adapt", lambda e: e.update(q=[1.0, float("nan")]), "`q` is not its Q before and after"),
    ("adapt", lambda e: e.update(terms={"steering": {"LM": "x"}}), "`terms` are not parameters"),
    ("adapt", lambda e: e.update(crisp=[["x"]]), "`crisp` are not [behavior, rule, output"),
    ("start", lambda e: e.update(rules="a\0b"), "`rules` holds a NUL byte"),
    # JSON that Python reads but cannot use: an OverflowError, a UnicodeEncodeError (tracebacks)
    ("adapt", lambda e: e.update(q=[10**400, 1.0]), "`q` is not its Q before and after"),
    ("adapt", lambda e: e.update(terms={"road": {"NARROW": [10**400, 70]}}), "`terms` are not"),
    ("adapt", lambda e: e.update(crisp=[["b", 0, "steering", -10**400]]), "`crisp` are not"),
    ("start", lambda e: e.update(rules="a\ud800.rules"), "half a character (a lone surrogate)"),
    ("rule", lambda e: e.update(text="r27: if road is NARROW then steering is \udcff"),
     "half a character"),
    ("rule", lambda e: e.update(text="r27: if road is NOPE then steering is LB"),
     "unknown term `NOPE` of `road`"),
    ("rule", lambda e: e.update(text="r27: if road is NARROW then nope is LB"), "`nope`"),
    ("use", lambda e: e.update(text="use b"), "`b` uses `b`: a cycle"),
    ("adapt", lambda e: e.update(terms={"road": {"NARROW": [-1e9, 1e9]}}),
     "term `road.NARROW`: its core"),                      # learned where no term can be
    ("adapt", lambda e: e.update(terms={"rood": {"NARROW": [0, 10]}}), "unknown variable `rood`"),
    # taken in, then every later `eval` refused at `<prompt>`
    ("activate", lambda e: e.update(behavior="avoid_obstacel"), "unknown behavior"),
    ("operators", lambda e: e.update(text="operators: and = prodcut"), "unknown T-norm `prodcut`"),
    ("operators", lambda e: e.update(text="operators: inference = tsukamoto"),
     "cannot be evaluated with these operators"),
    ("frozen", lambda e: e.update(labels=["r99"]), "unknown rule label `r99`"),
    ("freeze", lambda e: e.update(terms=[["steering", "LX"]]), "unknown term `LX`"),
    ("release", lambda e: e.update(terms=[["steerin", "LS"]]), "unknown variable `steerin`"),
])
def test_a_journal_whose_changes_were_edited_is_refused_at_their_line(rules, tmp_path, op,
                                                                        edit, says):
    journal = Journal.create(tmp_path / "j")
    s, _ = session(rules, journal=journal)
    for line in ["r27: if road is NARROW then steering is LB", "behavior b", "use avoid_obstacle",
                 "end", "use avoid_obstacle", "frozen r4",
                 "correct road=78 size=45 position=4 -> steering=60", "adapt epochs 2",
                 "operators: and = product", "frozen steering.LS", "unfrozen steering.LS"]:
        s.run(line)
    lines = journal.path.read_text().splitlines()
    entries = [json.loads(x) for x in lines]
    at = next(i for i, e in enumerate(entries) if e["op"] == op)
    edit(entries[at])
    journal.path.write_text("".join(json.dumps(e) + "\n" for e in entries))
    with pytest.raises(MitosError, match=re.escape(says)) as info:
        Session.resume(Journal.open(tmp_path / "j"), out=[].append)
    assert info.value.span is not None and info.value.span.line == at + 1


def test_help(rules):
    s, out = session(rules)
    assert "adapt [epochs N] [rate ETA]" in say(s, out, "help")
    assert "Q = sum_k" in say(s, out, "help adapt")
    with pytest.raises(LessonError) as info:
        s.run("help adpt")
    assert "did you mean `adapt`?" in info.value.render()
    assert s.run("quit") is False


def test_every_command_of_the_table_has_help():
    """`operators:` is a command of docs/teach.md's table and of the prompt, but `help`
    listed no line for it and `help operators` was an unknown topic."""
    from mitos_cli.teach.commands import COMMAND_WORDS
    from mitos_cli.teach.help import SUMMARY, help_text

    for word in COMMAND_WORDS:
        assert help_text(word)
    assert "operators: and = product" in SUMMARY
    # every option of `simulate` and `adapt` (`robot NAME` and `unconstrained` were left out)
    assert "[seed N] [robot NAME]" in SUMMARY and "[plot FILE] [unconstrained]" in SUMMARY


def test_help_on_an_instruction_or_a_target_is_the_help_that_holds_it():
    """`help turn` (an instruction's first word, as `turn harder`) was "unknown help topic"."""
    from mitos_cli.teach.help import help_text
    from mitos_cli.teach.instructions import INSTRUCTIONS

    for phrase in INSTRUCTIONS:
        assert help_text(phrase.split()[0]) == help_text("at")
    assert "make a wider turn" in help_text("turn")
    for word in ("target", "targets", "hedges"):
        assert help_text(word) == help_text("correct")


def test_help_at_says_what_each_instruction_does():
    """`help at` named the instructions and sent the reader to docs/teach.md, which `pip
    install` does not copy: it says each one's transformation, from the registry."""
    from mitos_cli.teach.help import help_text
    from mitos_cli.teach.instructions import INSTRUCTIONS

    text = help_text("at")
    assert "docs/teach.md" not in text
    lines = text.splitlines()
    for phrase, ins in INSTRUCTIONS.items():
        assert f"  {phrase:<28}{ins.meaning}" in lines
    assert "  make a wider turn           the hardest steering of the window, one term further, " \
           "at every tick" in lines


def test_help_save_says_where_a_bare_save_goes():
    """A bare `save` writes where the last `save` went (also after `--resume`), else the
    `--save-as` file: `help save` said only "default: the --save-as file"."""
    from mitos_cli.teach.help import help_text

    text = " ".join(help_text("save").split())
    assert "default: where the last `save` went, also after `mitos teach --resume`, else the " \
           "--save-as file" in text


def test_simulate_and_at_and_their_mistakes(rules, tmp_path):
    s, out = session(rules)
    s.run("use drive")
    text = say(s, out, "simulate corridor")                 # a packaged world by name
    assert text.startswith("corridor with behavior drive: success after")
    with pytest.raises(NameError_) as info:
        s.run("simulate coridor")
    assert "did you mean `corridor`?" in info.value.render()
    with pytest.raises(LessonError, match="whole number"):
        s.run("simulate corridor seed 1.5")
    text = say(s, out, "at 2s steering=80")
    assert text.startswith("1 example from corridor at 2 s (#1):")
    text = say(s, out, "at 3s to 3.5s steering=85 speed=20")
    assert text.startswith("11 examples from corridor from 3 s to 3.5 s (#2-12):")
    assert "... (6 more: `show examples`)" in text
    e = s.state.examples[1]
    assert set(e.inputs) == set(s.compiled().inputs) and e.targets == {"steering": 85,
                                                                        "speed": 20}
    with pytest.raises(LessonError, match="outside it"):
        s.run("at 999s steering=80")
    with pytest.raises(LessonError, match="ends before it starts"):
        s.run("at 4s to 3s steering=80")
    with pytest.raises(LessonError, match="output variable `road`"):
        s.run("at 3s road=80")
    s.run("use avoid_obstacle")
    s.run("undo")
    text = say(s, out, f"adapt epochs 3 plot {tmp_path / 'a.svg'}")
    assert "plotted" in text and list(tmp_path.glob("a*.svg"))
    # a picture that cannot be drawn is the command's failure, as every other command's
    with pytest.raises(LessonError, match="unknown picture format"):
        s.run("adapt epochs 3 plot a.gif")
    # a plot that cannot be written is refused before the descent: once, the adaptation was
    # kept and journaled with only "error: cannot write" said, and adapting again adapted twice
    changes = len(s.journal.entries)
    with pytest.raises(LessonError, match="cannot write .*: No such file or directory"):
        s.run(f"adapt epochs 3 plot {tmp_path / 'missing' / 'a.svg'}")
    assert len(s.journal.entries) == changes
    # `show terms plot` names the file given, not the first one made from it (`a-road`)
    with pytest.raises(LessonError, match="cannot write `a`: unknown picture format"):
        s.run("show terms plot a")
    with pytest.raises(LessonError) as info:
        s.run("show terms plot t.txt", "<prompt>", 3)
    assert at_prompt(info.value, "show terms plot t.txt", 3).render().splitlines()[:3] == [
        "<prompt>:3:17: command error: cannot write `t.txt`: unknown picture format `txt`",
        "    show terms plot t.txt", "                    ^^^^^"]
    # a plot into a directory that is not there is refused at its name, before the table
    # (it printed every term, then "cannot write `nodir/t-road.png`" under the command word)
    out.clear()
    line = f"show terms plot {tmp_path / 'nodir' / 't.png'}"
    with pytest.raises(MitosError) as info:
        s.run(line, "<prompt>", 4)
    assert out == []
    assert at_prompt(info.value, line, 4).render().splitlines()[:3] == [
        f"<prompt>:4:17: command error: cannot write `{tmp_path / 'nodir' / 't.png'}`: No "
        f"such file or directory", "    " + line,
        " " * 20 + "^" * len(str(tmp_path / "nodir" / "t.png"))]


def test_a_hedge_or_time_that_cannot_be_used_is_refused_at_its_own_word(rules):
    """`seldom LB` in a target and `at` times outside the run (or a window ending before it
    starts) were all pointed at column 1, under the command word."""
    s, _ = session(rules)

    def place(line):
        with pytest.raises(LessonError) as info:
            s.run(line, "<prompt>", 4)
        span = info.value.span
        return span.line, span.column, span.end_column

    assert place("correct road=78 size=45 position=4 -> steering is seldom LB") == (4, 51, 57)
    s.run("use drive")
    s.run("simulate corridor")
    with pytest.raises(RuleSyntaxError, match="`1e400` is past a float's range") as past:
        s.run("at 1e400s steering=50", "<prompt>", 4)
    assert (past.value.span.line, past.value.span.column, past.value.span.end_column) == (4, 4, 9)
    assert place("at -1s steering=50") == (4, 4, 7)
    assert place("at 1s to 100s turn harder") == (4, 10, 14)
    assert place("at 5s to 2s steering is LB") == (4, 4, 12)
    assert place("at 5s to 2s steering=50") == (4, 4, 12)
    assert place("at 5s to 5.01s steering is very seldom LB") == (4, 33, 39)
    # an instruction this run cannot take is marked at the instruction (it stood at column 1)
    assert place("at 1s to 2s make a wider turn") == (4, 13, 30)           # it went straight
    s.run("use avoid_obstacle")
    s.run("simulate figure4")                               # no gap_left, gap_right here
    assert place("at 0s to 2s keep further from the wall") == (4, 13, 39)


def test_a_world_driven_with_another_behavior_than_its_own_says_so(rules):
    """A new session's behavior is the file's first (`avoid_obstacle`): Figure 4 then ends
    after 2 s, not at B; the verdict says which behavior `mitos simulate` drives it with."""
    s, out = session(rules)
    text = say(s, out, "simulate figure4")
    assert text.startswith("figure4 with behavior avoid_obstacle: collision after 2.15 s")
    assert text.endswith("(`mitos simulate` drives figure4 with behavior drive: `use drive` "
                         "to drive it so here)")
    s.run("use drive")
    text = say(s, out, "simulate figure4")
    assert text.startswith("figure4 with behavior drive: collision after 14.65 s")
    assert "mitos simulate" not in text


def test_simulating_a_behavior_that_cannot_drive_says_use_at_the_prompt(rules):
    """"simulate a behavior such as `drive` (--behavior)": at the prompt there is no
    --behavior; a behavior is chosen with `use`."""
    s, _ = session(rules)
    s.run("use follow_route")                                  # sets steering, not speed
    with pytest.raises(RuleBaseError) as info:
        s.run("simulate figure4")
    assert "--behavior" not in info.value.hint
    assert info.value.hint == ("simulate a behavior such as `drive` (`use drive`, then "
                               "`simulate` again)")


def test_simulating_a_behavior_of_inputs_not_perceived_says_use_at_the_prompt(tmp_path):
    (tmp_path / "g.yaml").write_text(
        "variables:\n  gizmo: {role: input, universe: [0, 1], terms: {LOW: {shape: "
        "left_shoulder, points: [0, 1]}}}\n  steering: {role: output, universe: [30, 150], "
        "terms: {LM: 50}}\n  speed: {role: output, universe: [0, 60], terms: {SLOW: 10}}\n",
        encoding="utf-8")
    rules = tmp_path / "g.rules"
    rules.write_text('terms "g.yaml"\nbehavior b:\n  if gizmo is LOW then steering is LM and '
                     'speed is SLOW\nend\n', encoding="utf-8")
    s, _ = session(rules)
    with pytest.raises(RuleBaseError) as info:
        s.run("simulate figure4")
    assert "which the simulator does not perceive" in info.value.message
    assert info.value.hint.endswith("simulate a behavior that reads them (`use NAME`, then "
                                    "`simulate` again)")            # this file has no drive


def test_at_corrects_the_behavior_that_drove_the_run(rules):
    """`use drive`, `simulate`, then `use avoid_obstacle` and `at ...`: the examples were made
    from avoid_obstacle's output (steering 70, an output nobody used: its context had weight
    0 on the straight) and taught its rules to steer hard left with no obstacle. A correction
    of what the robot did goes to the rules that did it: drive's, with a note."""
    s, out = session(rules)
    s.run("use drive")
    s.run("simulate figure4")
    s.run("use avoid_obstacle")
    text = say(s, out, "at 12s to 13s make a wider turn")
    assert text.startswith("note: figure4 was driven by `drive`, so this corrects drive (the "
                           "rules that produced the motion")
    assert "`use drive` before `adapt`" in text
    assert "(steering 89.96 -> 53.28 at 12 s)" in text         # drive's steering, not 70
    assert {e.behavior for e in s.state.examples} == {"drive"}
    assert "obstacle=200 heading=-14.93" in text                # drive's inputs
    text = say(s, out, "at 12s steering is LM")                 # noted once per run
    assert text.startswith("1 example from figure4 at 12 s (#22):")
    with pytest.raises(LessonError) as info:
        s.run("adapt epochs 1")
    assert "the examples given so far correct drive: `use drive`" in info.value.render()
    s.run("use drive")
    assert not say(s, out, "at 12s steering=55").startswith("note")
    with pytest.raises(LessonError, match=r"did not turn in that window \(steering within "
                                          r"1.2 of 90 at every tick\)"):
        s.run("at 10s to 11s make a wider turn")            # straight on: nothing to widen


def test_at_after_the_driving_behavior_was_undone(rules):
    s, out = session(rules)
    s.run("behavior mine")
    s.run("use drive")
    s.run("end")
    s.run("simulate figure4")
    s.run("undo")                       # `end`: `mine` is open again, then gone
    s.run("undo")
    s.run("undo")
    with pytest.raises(LessonError, match="driven by behavior `mine`, which is no longer in "
                                          "the rule base"):
        s.run("at 12s steering=55")


def test_examples_belong_to_the_behavior_they_correct(rules):
    s, out = session(rules)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    s.run("use drive")
    with pytest.raises(LessonError) as info:
        s.run("adapt")
    assert "the examples given so far correct avoid_obstacle: `use avoid_obstacle`" in \
        info.value.render()
    assert "[avoid_obstacle, correct]" in say(s, out, "show examples")


def test_save_to_a_directory_is_refused_before_writing(rules, tmp_path):
    """`save DIR` raised IsADirectoryError (a traceback that ended the session) after
    writing the term sets beside the directory as `DIR.mitos.terms.yaml`."""
    s, out = session(rules)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    folder = tmp_path / "out"
    folder.mkdir()
    before = sorted(tmp_path.iterdir())
    with pytest.raises(LessonError) as info:
        s.run(f"save {folder}")
    assert "is a directory; save names the rule file to write" in info.value.render()
    assert f"hint: save {(folder / 'taught.rules').as_posix()}" in info.value.render()
    assert sorted(tmp_path.iterdir()) == before and not any(folder.iterdir())
    assert say(s, out, f"save {folder / 'taught.rules'}").startswith("saved ")


def test_errors_at_the_prompt_are_placed_at_prompt(rules):
    """Syntax errors said `<prompt>:1:1`, checks of names `<input>:1:39`: one name for one
    place."""
    s, out = session(rules)
    for line, column in [("correct road=78 size=45 position=4 -> steerin=60", 39),
                         ("if road is NARROW then speed is SLOWW", 33),   # at the term
                         ("corect road=78", 1)]:
        with pytest.raises(MitosError) as info:
            s.run(line)
        assert str(info.value.span) == f"<prompt>:1:{column}", line


def test_show_terms_names_shapes_as_the_term_set_writes_them(rules):
    """`show terms` said `triangle_pw`, a registry name no term set can use."""
    s, out = session(rules)
    shown = say(s, out, "show terms").splitlines()
    assert "  MEDIUM     triangle       peak 70, width 30" in shown
    assert "  NARROW     left_shoulder  a 40, b 70" in shown
    assert "  STOP       singleton      0" in shown
    assert not [line for line in shown if "triangle_" in line]


def test_counts_of_one_are_singular(rules):
    """A new behavior with one rule was "learned (1 rules, 0 uses)"."""
    s, out = session(rules)
    say(s, out, "behavior careful")
    assert "added to careful (1 rule)" in say(s, out, "if road is NARROW then speed is CREEP")
    assert "behavior careful learned (1 rule, 0 uses)" in say(s, out, "end")
    assert "* careful (1 rule)" in say(s, out, "show behaviors")
    assert say(s, out, "show rules").startswith("behavior careful (1 rule)")
    say(s, out, "correct road=20 -> speed=15")
    text = say(s, out, "adapt epochs 1")
    assert "Q = sum (y - t)^2 over 1 example:" in text and "(1 epoch; RMS error" in text


def test_a_correction_outside_the_universe_is_noted_and_an_infinite_one_refused(rules):
    s, out = session(rules)
    text = say(s, out, "correct road=500 size=45 position=4 -> steering=60")
    assert "road = 500 lies outside its universe [0, 160]; the rules read it as 160" in text
    with pytest.raises(RuleSyntaxError) as info:         # was "road = inf is not finite"
        s.run("correct road=1e400 size=45 position=4 -> steering=60")
    assert info.value.message == "`1e400` is past a float's range"
    assert (info.value.span.line, info.value.span.column) == (1, 14)
    assert len(s.state.examples) == 1


def test_operators_the_rules_cannot_be_evaluated_with_are_refused_unjournaled():
    from mitos_cli.teach.journal import MemoryJournal

    journal = MemoryJournal()
    s = Session(default_rulebase_path(), journal=journal, out=[].append)
    with pytest.raises(LessonError, match="cannot be evaluated with these operators: "
                                          ".*Tsukamoto inference needs a monotonic"):
        s.run("operators: inference = tsukamoto")
    assert [e["op"] for e in journal.entries] == ["start"]
    s.run("operators: and = product")             # what the rules can take is journaled
    assert [e["op"] for e in journal.entries] == ["start", "operators"]


def test_ctrl_c_in_a_lessons_adapt_stops_the_lesson(monkeypatch):
    """At the prompt Ctrl-C ends an `adapt` early and the prompt goes on; in a lesson it
    stops the lesson (what the completed epochs learned is journaled, nothing after runs)."""
    from mitos_cli.teach import adapt as adapt_module
    from mitos_cli.teach.lesson import run_lesson

    real = adapt_module.adapt

    def interrupted(*args, **kwargs):
        kwargs["on_epoch"] = None
        result = real(*args, **{**kwargs, "epochs": 2})
        return dataclasses.replace(result, interrupted=True)

    monkeypatch.setattr(adapt_module, "adapt", interrupted)
    said: list[str] = []
    s = Session(default_rulebase_path(), out=said.append)
    with pytest.raises(KeyboardInterrupt):
        run_lesson(s, "correct road=78 size=45 position=4 -> steering=60\nadapt epochs 50\n"
                      "correct road=70 size=45 position=4 -> steering=80\n", "l.lesson")
    assert [e["op"] for e in s.journal.entries] == ["start", "examples", "adapt"]
    assert len(s.state.examples) == 1


def test_a_lessons_lines_are_counted_as_an_editor_counts_them():
    """A form feed (a page break) or U+0085 ends no line in an editor, but ``splitlines``
    broke the lesson there: every error after it was named a line too far on."""
    from mitos_cli.teach.lesson import run_lesson

    for odd in ("\f", "\x85", "\x1c"):
        s = Session(default_rulebase_path(), out=[].append)
        with pytest.raises(MitosError) as info:
            run_lesson(s, f"# a page{odd}\nuse avoid_obstacle\ncorect road=78\n", "l.lesson")
        assert (info.value.span.line, info.value.span.column) == (3, 1)


def test_a_name_said_in_an_error_is_placed_after_the_command_word_that_repeats_it():
    """`save save` and `simulate simulate` put the caret under the command, the first place
    the quoted name was found."""
    from mitos_cli.teach.lesson import run_lesson

    s = Session(default_rulebase_path(), out=[].append)
    for line, column in (("save save", 6), ("simulate simulate", 10)):
        with pytest.raises(MitosError) as info:
            s.run(line)
        assert at_prompt(info.value, line, 2).span.column == column
        with pytest.raises(MitosError) as info:
            run_lesson(s, line + "\n", "l.lesson")
        assert (info.value.span.line, info.value.span.column) == (1, column)


def test_a_rule_frozen_already_is_said_so_and_not_journaled(rules, tmp_path):
    """`frozen r4` again was journaled as a change (an unsaved change with nothing to save),
    and `frozen r4, r4` was saved as written; as for terms, what is frozen already is said."""
    s, out = session(rules)
    assert say(s, out, "frozen r4, r4") == \
        "avoid_obstacle: adaptation leaves the consequents of r4 alone"
    assert say(s, out, "frozen r4") == "avoid_obstacle: r4 is frozen already; nothing changes"
    assert say(s, out, "frozen r5, r4").splitlines() == [
        "avoid_obstacle: adaptation leaves the consequents of r5 alone",
        "avoid_obstacle: r4 is frozen already"]
    assert [e.get("labels") for e in s.journal.entries[1:]] == [["r4"], ["r5"]]
    s.run(f"save {tmp_path / 'out.rules'}")
    assert "    frozen r4, r5\n" in (tmp_path / "out.rules").read_text()


def test_a_window_reaches_the_last_tick_one_time_reaches(rules):
    """The tick at which the robot arrives is recorded and `at END` corrects it, but a window
    ending there left it out (the robot is no longer active at it)."""
    s, out = session(rules)
    s.run("use drive")
    s.run("simulate corridor")
    rec = s.simulation
    last = len(rec.t) - 1
    assert list(rec.rows(rec.end - 0.1, rec.end)) == [last - 2, last - 1, last]
    assert list(rec.rows(rec.end, None)) == [last]


def test_a_world_naming_a_behavior_the_rule_base_lacks_is_not_offered_to_use(rules, tmp_path):
    """A world file naming a behavior the rule base does not have (which `mitos simulate`
    refuses) got "`use cruise_ctl` to drive it so here": a name error if followed."""
    from mitos_cli.teach.simulation import world_path

    world = tmp_path / "wb.yaml"
    world.write_text(world_path("corridor").read_text().replace("behavior: drive",
                                                                "behavior: cruise_ctl"))
    s, out = session(rules)
    s.run("use drive")
    said = say(s, out, f"simulate {world}")
    assert "`use cruise_ctl`" not in said
    assert "(wb's world file names behavior `cruise_ctl`, which this rule base does not have)" \
        in said


def test_an_output_the_behavior_does_not_set_is_said_alike_in_words(rules):
    """`correct heading=5 -> speed=20` of `follow_route` (no speed) said the behavior does not
    use `speed`; the same in words, `speed is SLOW`, said "unknown output variable"."""
    s, out = session(rules)
    s.run("use follow_route")
    for target in ("speed=20", "speed is SLOW"):
        with pytest.raises(LessonError) as info:
            s.run(f"correct heading=5 -> {target}")
        assert info.value.message == "behavior `follow_route` does not use output `speed`"
        assert info.value.expected == "outputs steering"


@pytest.mark.parametrize("line, message, hint", [
    # an input given as a target (`at 13s road=3`: the road the robot should have seen) and an
    # output given as an input: "unknown output variable `road`" with the outputs alone
    ("correct road=78 size=45 position=4 -> road=60", "unknown output variable `road`",
     "`road` is an input: a target sets an output (steering, speed); the inputs are given "
     "before `->` (in `at`, the run gives them)"),
    ("correct road=78 size=45 steering=60 -> speed=3", "unknown input variable `steering`",
     "`steering` is an output: it goes after `->`, as a target (`-> steering=VALUE`)"),
])
def test_an_input_said_as_a_target_or_an_output_as_an_input_is_said_so(rules, line, message,
                                                                         hint):
    s, _ = session(rules)
    with pytest.raises(LessonError) as info:
        s.run(line)
    assert info.value.message == message
    assert info.value.hint == hint


def test_a_resumed_session_can_correct_the_run_it_recorded(tmp_path, monkeypatch):
    """`simulate` is journaled (a record, not a change): `--resume` drives the last run again
    on the rule base as it was then, so `at` corrects the same run; a seed is exact."""
    monkeypatch.chdir(tmp_path)
    s = Session(default_rulebase_path(), journal=Journal.create(tmp_path / "j"), out=[].append)
    s.run("use drive")
    s.run("simulate figure4 seed 9007199254740993")
    s.run("at 12.5s steering=55")
    assert s.simulation.seed == 9007199254740993
    with pytest.raises(LessonError, match="written in digits .* not `1e3`"):
        s.run("simulate figure4 seed 1e3")
    said: list[str] = []
    again = Session.resume(Journal.open(tmp_path / "j"), out=said.append)
    assert said[0].startswith("the last run is recorded again: figure4 (seed 9007199254740993)")
    assert again.simulation.result.summary() == s.simulation.result.summary()
    assert "simulate" not in [e["op"] for e in again.journal.active()]   # undo skips it
    again.run("at 13s steering=60")
    assert [e.source for e in again.state.examples] == ["figure4 t=12.5s", "figure4 t=13s"]


def test_a_resumed_session_says_when_the_run_driven_again_is_another(tmp_path, monkeypatch):
    """The world file edited between the run and `--resume`: the run driven again is another
    (8.7 s, not 7.65 s), and `at` would correct it without a word; the journal keeps what
    tells the runs apart, and the resumed session says they differ."""
    monkeypatch.chdir(tmp_path)
    world = tmp_path / "tiny.yaml"
    shutil.copy(Path(__file__).parent / "data" / "tiny.yaml", world)
    s = Session(default_rulebase_path(), journal=Journal.create(tmp_path / "j"), out=[].append)
    s.run("use drive")
    s.run("simulate tiny.yaml")
    said: list[str] = []
    Session.resume(Journal.open(tmp_path / "j"), out=said.append)
    assert len(said) == 1 and said[0].startswith("the last run is recorded again")
    world.write_text(world.read_text().replace("at: [150, -12]", "at: [150, 20]"))
    said.clear()
    Session.resume(Journal.open(tmp_path / "j"), out=said.append)
    assert said[1] == ("warning: this is not the run recorded before (success after 8.7 s, "
                       "now success after 7.65 s): `tiny.yaml` or a file it reads changed "
                       "since; `at` corrects the run driven now")


def test_a_world_simulated_by_a_relative_path_is_driven_again_from_another_directory(
        tmp_path, monkeypatch):
    """`simulate corridor.yaml` (a copy of the packaged world, its seed changed) was journaled
    as `corridor.yaml`, relative: `--resume --session DIR` from another directory drove the
    packaged `corridor` instead (another run, the warning blaming the world file), or a file
    of that name there. The world's path is kept absolute, as `save`'s is."""
    from mitos_cli.teach.simulation import world_path

    here, elsewhere = tmp_path / "here", tmp_path / "elsewhere"
    here.mkdir()
    elsewhere.mkdir()
    monkeypatch.chdir(here)
    text = world_path("corridor").read_text()
    (here / "corridor.yaml").write_text(text.replace("seed: 1\n", "seed: 77\n", 1))
    s = Session(default_rulebase_path(), journal=Journal.create(here / "j"), out=[].append)
    s.run("use drive")
    s.run("simulate corridor.yaml")
    assert s.journal.entries[-1]["world"] == str(here / "corridor.yaml")
    monkeypatch.chdir(elsewhere)
    said: list[str] = []
    again = Session.resume(Journal.open(here / "j"), out=said.append)
    assert len(said) == 1 and said[0].startswith("the last run is recorded again")
    assert again.simulation.fingerprint == s.simulation.fingerprint


@pytest.mark.parametrize("line, message, column", [
    ("frozen road.NARROWW", "unknown term `NARROWW` of `road`", 13),
    ("frozen roadd.NARROW", "unknown variable `roadd`", 8),
    ("frozen r400", "unknown rule label `r400` of `avoid_obstacle`", 8),
    ("correct road=78 size=45 position=4 -> steering=150.00001",
     "steering = 150.00001 lies outside its universe [30, 150]", 39),
])
def test_prompt_errors_point_at_what_is_wrong(line, message, column):
    from mitos_cli.teach.prompt import at_prompt

    s = Session(default_rulebase_path(), out=[].append)
    with pytest.raises(MitosError) as info:
        s.run(line)
    err = at_prompt(info.value, line, 1)
    assert err.message == message and err.span.column == column


def test_undoing_every_change_leaves_nothing_unsaved():
    s = Session(default_rulebase_path(), out=[].append)
    s.run("use drive")
    assert not s.unsaved                     # which behavior is active is not in the files
    s.run("use avoid_obstacle")
    s.run("correct road=78 size=45 position=4 -> steering=60")
    assert s.unsaved
    s.run("undo")
    assert not s.unsaved


def test_unfrozen_says_what_it_lifts(rules):
    """`unfrozen steering.ST` said "(no freeze, no hold at a point of symmetry)", as if there
    never was one, while it lifted ST's hold at 90 (save then writes `held: false`)."""
    s, out = session(rules)
    assert say(s, out, "unfrozen steering.ST") == (
        "adaptation may move steering.ST: its hold at 90 is lifted (the point its neighbours "
        "mirror each other about; `save` writes `held: false`)")
    assert say(s, out, "unfrozen steering.ST") == (
        "steering.ST is neither frozen nor held (its hold was lifted already): adaptation "
        "could move it already; nothing changes")
    s.run("frozen heading.AHEAD, road.NARROW")
    assert say(s, out, "unfrozen heading.AHEAD, road.NARROW").splitlines() == [
        "adaptation may move heading.AHEAD: its freeze and its hold at 0 are lifted (the point "
        "its neighbours mirror each other about; `save` writes `held: false`)",
        "adaptation may move road.NARROW: its freeze is lifted"]
    assert say(s, out, "unfrozen road.WIDE") == \
        "road.WIDE is neither frozen nor held: adaptation could move it already; nothing changes"


def test_frozen_or_unfrozen_that_changes_nothing_is_no_unsaved_change(rules):
    """`unfrozen heading.LEFT` of a term neither frozen nor held was journaled: "unsaved
    changes" at the end, and `save` then said "(no changes)". Like `frozen` of a frozen term,
    it now says that nothing changes, and journals nothing."""
    s, out = session(rules)
    seq = len(s.journal.active())
    assert say(s, out, "unfrozen heading.LEFT") == (
        "heading.LEFT is neither frozen nor held: adaptation could move it already; nothing "
        "changes")
    assert not s.unsaved and len(s.journal.active()) == seq
    s.run("frozen heading.LEFT")
    assert s.unsaved
    assert say(s, out, "frozen heading.LEFT") == (
        "heading.LEFT is frozen already: adaptation keeps it as it is; nothing changes")
    assert say(s, out, "frozen heading.LEFT, heading.AHEAD").splitlines() == [
        "adaptation keeps heading.AHEAD as it is (`unfrozen` lets it move; `save` writes "
        "`frozen: true`)",
        "heading.LEFT is frozen already: adaptation keeps it as it is"]
    assert s.journal.active()[-1]["terms"] == [["heading", "AHEAD"]]
    say(s, out, "undo")                                 # takes back the AHEAD freeze only
    assert say(s, out, "undo") == "undone: frozen heading.LEFT"
    assert not s.unsaved
    # several at once are "them" ("keeps steering.LM, road.MEDIUM as they are (`unfrozen`
    # lets it move ...)")
    assert say(s, out, "frozen steering.LM, road.MEDIUM") == (
        "adaptation keeps steering.LM, road.MEDIUM as they are (`unfrozen` lets them move; "
        "`save` writes `frozen: true`)")


def test_a_comma_between_values_is_named_and_a_hedge_past_the_scale_is_noted(rules):
    """`... -> steering=60, speed=20` expected "`->`, a name or the end of the line" though
    the `->` was there; `steering is extremely LB` became 30 without a word."""
    s, out = session(rules)
    with pytest.raises(RuleSyntaxError) as info:
        s.run("correct road=78 size=45 position=4 -> steering=60, speed=20")
    assert info.value.message == "unexpected `,`"
    assert info.value.expected == "a name or the end of the line"
    assert info.value.hint == "values are separated by spaces, not commas: `road=78 size=45`"
    with pytest.raises(RuleSyntaxError) as info:
        s.run("eval road=78, size=45 position=4")
    assert "`->`" not in info.value.expected and "not commas" in info.value.hint
    assert say(s, out, "correct road=78 size=45 position=4 -> steering is extremely LB") == (
        "note: `steering is extremely LB` lies past LB, the end of the steering scale: the "
        "target is LB's value, steering=30\n"
        "example 1: road=78 size=45 position=4 -> steering=30   (now steering=65.41)")
    assert say(s, out, "correct road=78 size=45 position=4 -> steering is very RB").startswith(
        "note: `steering is very RB` lies past RB")
    assert say(s, out, "correct road=78 size=45 position=4 -> steering is very LM").startswith(
        "example 3:")                                       # 40: inside the scale, no note
    # the middle term: a hedge moves a target away from it, so `very ST` is ST (said so)
    assert say(s, out, "correct road=78 size=45 position=4 -> steering is very ST") == (
        "note: `steering is very ST` is ST's own value, steering=90: a hedge moves a target "
        "away from the middle of the steering scale, where ST stands\n"
        "example 4: road=78 size=45 position=4 -> steering=90   (now steering=65.41)")


def test_not_adapted_names_the_frozen_input_terms_too(rules):
    """After `frozen heading.LEFT, heading.FAR_LEFT` and `frozen steering.LB`, `adapt` said
    only `not adapted: steering.LB is frozen`."""
    s, out = session(rules)
    for line in ("use follow_route", "frozen heading.LEFT, heading.FAR_LEFT",
                 "frozen steering.LB", "correct heading=-5 -> steering=40",
                 "correct heading=5 -> steering=90", "correct heading=-30 -> steering=60"):
        s.run(line)
    text = say(s, out, "adapt epochs 30")
    assert ("not adapted: heading.FAR_LEFT is frozen; heading.LEFT is frozen; steering.LB is "
            "frozen") in text.splitlines()


def test_a_journal_write_the_disk_took_half_of_is_taken_back(rules, tmp_path):
    """A full disk (here: the file size limit) that took part of a change's line left the
    half line, and the next change, appended after it, made one damaged line of both: the
    resume refused the journal, and `--recover` dropped the change that was acknowledged."""
    resource = pytest.importorskip("resource")
    journal = Journal.create(tmp_path / "j")
    s, _ = session(rules, journal=journal)
    s.run("r27: if road is NARROW then steering is LB")
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (journal.path.stat().st_size + 30, hard))
    try:
        with pytest.raises(LessonError, match="the change was not made"):
            s.run("r28: if road is WIDE then speed is FAST")
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
    s.run("r29: if road is MEDIUM then speed is MEDIUM")
    again = Session.resume(Journal.open(tmp_path / "j"), out=[].append)
    labels = [r.label for r in again.rulebase.behavior("avoid_obstacle").rules]
    assert labels[-2:] == ["r27", "r29"] and again.rulebase == s.rulebase


def test_a_journal_damaged_twice_keeps_both_as_they_were(rules, tmp_path):
    """A second damage (a torn last line after a `--recover`) kept the journal over the first
    copy kept aside, and the changes told after the first damaged line were lost with it."""
    journal = Journal.create(tmp_path / "j")
    s, _ = session(rules, journal=journal)
    for line in ["r27: if road is NARROW then steering is LB", "r28: if road is WIDE then speed is FAST",
                 "r29: if road is MEDIUM then speed is MEDIUM"]:
        s.run(line)
    lines = journal.path.read_text().splitlines(keepends=True)
    journal.path.write_text("".join(lines[:2] + ["x" + lines[2]] + lines[3:]))
    first = Journal.open(tmp_path / "j", recover=True)
    assert first.recovered_at == 3
    Session.resume(first, out=[].append).run("r28: if road is WIDE then speed is SLOW")
    with open(first.path, "a") as fh:
        fh.write('{"seq": 4, "op": "rule", "beh')
    second = Journal.open(tmp_path / "j")
    assert second.skipped_tail and second.aside.name == "journal.jsonl.damaged.2"
    assert "r29: if road is MEDIUM" in (tmp_path / "j" / "journal.jsonl.damaged").read_text()
    assert "speed is SLOW" in second.aside.read_text()


def test_a_session_resumed_elsewhere_saves_where_its_last_save_went(rules, tmp_path,
                                                                    monkeypatch):
    """The journal kept `save`'s path (and `--save-as`) as typed, relative to the directory
    the session ran in: resumed from another (`--resume --session DIR`), a bare `save` wrote
    a new file there, and the one saved before stayed as it was."""
    here, there = tmp_path / "here", tmp_path / "there"
    here.mkdir()
    there.mkdir()
    monkeypatch.chdir(here)
    s, _ = session(rules, journal=Journal.create(tmp_path / "j"))
    s.run("r27: if road is NARROW then steering is LB")
    s.run("save t1.rules")
    monkeypatch.chdir(there)
    again = Session.resume(Journal.open(tmp_path / "j"), out=[].append)
    again.run("r28: if road is WIDE then speed is FAST")
    again.run("save")
    assert "r28:" in (here / "t1.rules").read_text()
    assert list(there.iterdir()) == []


def test_undo_replays_without_checking_or_parsing_again(rules, monkeypatch):
    """`undo` replays every change left: it checked each again (compiling the behavior of
    every `correct`) and parsed each rule again, so each undo of a long lesson took longer
    (0.4 s at 470 changes; a 3,000-line lesson with undos did not end in a minute)."""
    import mitos_cli.teach.state as state

    s, _ = session(rules)
    for i in range(12):
        s.run(f"r{100 + i}: if road is WIDE and size is SMALL_SZ then speed is FAST")
        s.run(f"correct road={40 + i} size=45 position=4 -> steering=60")
    checks, parses = [], []
    monkeypatch.setattr(Session, "_check_entry", lambda self, e: checks.append(e))
    monkeypatch.setattr(state, "parse_rule", lambda text: parses.append(text))
    before = s.rulebase
    for _ in range(4):
        s.run("undo")
    assert checks == [] and parses == []
    labels = [r.label for r in s.rulebase.behavior("avoid_obstacle").rules]
    assert labels[-2:] == ["r108", "r109"] and len(s.state.examples) == 10
    assert s.rulebase != before


def test_ctrl_c_during_the_journal_write_keeps_the_journal_whole(rules, tmp_path, monkeypatch,
                                                                sigint):
    """Ctrl-C while the journal's line was being synced to disk (the longest part of a
    change) raised after the line was written and before the session counted it: the next
    change was numbered alike, and `--resume` refused the journal at it."""
    import os
    import signal
    import time

    import mitos_cli.teach.journal as journal_module

    journal = Journal.create(tmp_path / "j")
    s, _ = session(rules, journal=journal)
    real = os.fsync

    def interrupted(fd):
        real(fd)
        monkeypatch.setattr(journal_module.os, "fsync", real)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)                 # the signal is taken here, as after a slow fsync

    monkeypatch.setattr(journal_module.os, "fsync", interrupted)
    with pytest.raises(KeyboardInterrupt):
        s.run("r27: if road is NARROW then steering is LB")
    s.replay()                           # what the prompt does after a Ctrl-C
    s.run("r28: if road is WIDE then speed is FAST")
    again = Session.resume(Journal.open(tmp_path / "j"), out=[].append)
    assert again.rulebase == s.rulebase
    assert [r.label for r in again.rulebase.behavior("avoid_obstacle").rules][-2:] == \
        ["r27", "r28"]


@pytest.mark.parametrize("name", ["SIGTERM", "SIGHUP"])
def test_a_sigterm_or_sighup_during_the_journal_write_is_raised_once_it_is_counted(
        rules, tmp_path, monkeypatch, name):
    """`mitos teach` answers a SIGTERM and a SIGHUP as Ctrl-C (Terminated, a
    KeyboardInterrupt); one during the journal line's fsync must wait, as Ctrl-C does, until
    the line is synced and counted, or the next change is numbered alike."""
    import os
    import signal
    import time

    import mitos_cli.teach.journal as journal_module
    from mitos_cli.cli.progress import terminate_as_interrupt
    from mitos_cli.errors import Terminated

    journal = Journal.create(tmp_path / "j")
    s, _ = session(rules, journal=journal)
    real = os.fsync
    synced: list[int] = []

    def signalled(fd):
        monkeypatch.setattr(journal_module.os, "fsync", real)
        os.kill(os.getpid(), getattr(signal, name))
        time.sleep(0.05)                 # the signal is taken here, before the fsync
        real(fd)
        synced.append(fd)

    monkeypatch.setattr(journal_module.os, "fsync", signalled)
    with terminate_as_interrupt(), pytest.raises(Terminated) as stop:
        s.run("r27: if road is NARROW then steering is LB")
    assert stop.value.code == 128 + getattr(signal, name)
    assert synced and [e["seq"] for e in journal.entries] == [1, 2]
    s.run("r28: if road is WIDE then speed is FAST")
    again = Session.resume(Journal.open(tmp_path / "j"), out=[].append)
    assert [r.label for r in again.rulebase.behavior("avoid_obstacle").rules][-2:] == \
        ["r27", "r28"]


def test_a_rule_file_of_a_long_name_gets_a_session(tmp_path):
    """The session's directory is named after the rule file: a name of 245 characters made
    one of 261, which no file system allows, and the rule file could not be taught."""
    from mitos_cli.teach.journal import new_session_dir

    directory = new_session_dir("z" * 245, tmp_path)
    assert directory.is_dir() and directory.name.startswith("z" * 64 + "-")
    assert len(directory.name) < 100


@pytest.mark.parametrize(("told", "note"), [
    ("operators: aggregation = sum", "note: `aggregation = sum` has no effect: behavior `drive` "
     "uses weighted_average inference (add `inference = mamdani` to use it)"),
    ("operators: accumulation = max, inference = mamdani",
     "note: `accumulation = max` has no effect: behavior `drive` uses mamdani inference"),
    ("operators: inference = mamdani, aggregation = sum", None),
    ("operators: accumulation = max", None),
])
def test_a_told_operator_the_inference_ignores_is_noted(rules, told, note):
    """`operators: aggregation = sum` told to a weighted-average behavior was taken without a
    word (it changes no number; `mitos check` of the saved file says `idle-setting`)."""
    s, out = session(rules)
    s.run("use drive")
    text = say(s, out, told)
    assert text.startswith("drive: " + told)
    assert (note in text) if note else "note:" not in text


@pytest.mark.parametrize("line, hint", [
    ("if road is WIDE, size is SMALL_SZ then steering is LS",
     "conditions are joined with `and` or `or`, not `,`: `if a is X and b is Y`"),
    ("if road is WIDE then steering is LS, speed is SLOW",
     "actions are joined with `and`, not `,`: `then steering is LS and speed is SLOW`"),
    ("if road is WIDE then steering is LS speed is SLOW",
     "actions are joined with `and`: `... and speed is ...`"),
    ("correct road=78 size=45 position=4 -> steering is LS, speed is SLOW",
     "targets in words are joined with `and`, not `,`: `steering is LS and speed is SLOW`"),
])
def test_conditions_actions_and_targets_joined_with_a_comma_say_how_they_are_joined(rules, line,
                                                                                      hint):
    """A told rule with a comma between its conditions or actions, or two actions with no
    `and`, got no hint (the rule file's parser said "unexpected `,`" alone too); a target in
    words with a comma got the hint for values, "separated by spaces"."""
    s, _ = session(rules)
    with pytest.raises(RuleSyntaxError) as info:
        s.run(line)
    assert info.value.hint == hint


def test_show_history_says_an_adaptation_that_stopped_short(monkeypatch):
    """`show history` read `adapt epochs 100000 (Q 1.616e+04 -> 58.77)` for an adaptation
    Ctrl-C stopped after 632 epochs: the entry keeps how it stopped and after how many."""
    from mitos_cli.teach import adapt as adapt_module
    from mitos_cli.teach.text import history_text

    real = adapt_module.adapt

    def interrupted(*args, **kwargs):
        result = real(*args, **{**kwargs, "epochs": 2})
        return dataclasses.replace(result, interrupted=True)

    said: list[str] = []
    s = Session(default_rulebase_path(), out=said.append)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    monkeypatch.setattr(adapt_module, "adapt", interrupted)
    s.run("adapt epochs 50")
    entry = s.journal.entries[-1]
    assert (entry["op"], entry["stopped"], entry["ran"], entry["epochs"]) == \
        ("adapt", "interrupted", 2, 50)
    assert history_text(s.journal.entries).splitlines()[-1].endswith(
        "; interrupted after 2 epochs)")
    monkeypatch.setattr(adapt_module, "adapt", real)
    s.run("undo")
    s.run("adapt epochs 5000")                          # one example: it converges
    entry = s.journal.entries[-1]
    assert entry["stopped"] == "converged" and 0 < entry["ran"] < 5000
    assert f"; converged after {entry['ran']:,} epoch" in history_text(s.journal.entries)
    s.run("undo")
    s.run("adapt epochs 3")                             # all the epochs asked: as before
    assert "stopped" not in s.journal.entries[-1]
    last = history_text(s.journal.entries).splitlines()[-1]
    assert "adapt epochs 3   (Q " in last and ";" not in last


def test_the_journal_docs_teach_md_shows_is_the_one_its_session_writes(tmp_path):
    """docs/teach.md's journal showed a `simulate` by `drive` in a session that never made
    `drive` active (no `use drive` record) and an `adapt` whose Q ended at 0.00112 with no
    `stopped`: the session it shows, told at the prompt, writes those lines (`...` and
    `/abs/path/` standing for any text, and the run's fingerprint not compared)."""
    import doctest
    import subprocess
    import sys

    page = (Path(__file__).resolve().parent.parent / "docs" / "teach.md").read_text(
        encoding="utf-8")
    shown = [line for line in page.splitlines() if line.startswith('{"seq":')]
    told = ["if road is NARROW then speed is SLOW",
            "correct road=78 size=45 position=4 -> steering=60", "adapt epochs 20", "undo",
            "use drive", "simulate figure4"]
    res = subprocess.run([sys.executable, "-m", "mitos_cli", "teach", "rulebases/mitos.rules"],
                         cwd=tmp_path, input="\n".join(told) + "\n", capture_output=True,
                         text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    (journal,) = (tmp_path / ".mitos" / "teach").glob("*/journal.jsonl")
    written = journal.read_text(encoding="utf-8").splitlines()
    assert len(written) == len(shown) == 7
    checker = doctest.OutputChecker()
    for want, got in zip(shown, written):
        # the run's fingerprint hashes pose bits, which another libm may round otherwise
        want = re.sub(r'"run":"[0-9a-f]+"', '"run":"..."', want.replace("/abs/path/", "..."))
        assert checker.check_output(want + "\n", got + "\n", doctest.ELLIPSIS), (want, got)
