"""The teaching language: every command parses to its object; mistyped lines say what was
expected, in words, at path:line:col."""

import contextlib
import re
import time

import pytest

from mitos_cli.errors import LessonError, RuleSyntaxError
from mitos_cli.teach import commands as c
from mitos_cli.teach.commands import incomplete, parse_command


@pytest.mark.parametrize("line, expected", [
    ("behavior wider", c.OpenBehavior("wider")),
    ("behavior wider:", c.OpenBehavior("wider")),
    ("end", c.CloseBehavior()),
    ("frozen r4, r5", c.TellFrozen(("r4", "r5"))),
    ("eval road=78 size=45 position=-4",
     c.Eval((c.Assign("road", 78), c.Assign("size", 45), c.Assign("position", -4)))),
    ("correct road=78 size=45 position=4 -> steering=60 speed=20",
     c.Correct((c.Assign("road", 78), c.Assign("size", 45), c.Assign("position", 4)),
               (c.Assign("steering", 60), c.Assign("speed", 20)))),
    ("simulate worlds/figure4.yaml", c.Simulate("worlds/figure4.yaml")),
    ('simulate "my world.yaml" seed 3', c.Simulate("my world.yaml", "3")),
    # a world's robots may be named as no bare word can be (`name: "cart 2"`, `name: "7"`)
    ('simulate two.yaml robot "cart 2"', c.Simulate("two.yaml", None, "cart 2")),
    ('simulate seven.yaml seed 1 robot "7"', c.Simulate("seven.yaml", "1", "7")),
    ("at 12.5s steering=55", c.At(12.5, None, (c.Assign("steering", 55),))),
    ("at 11 to 13s steering=55 speed=10",
     c.At(11, 13, (c.Assign("steering", 55), c.Assign("speed", 10)))),
    ("adapt", c.Adapt()),
    ("adapt epochs 20 rate 0.3 plot terms.png", c.Adapt(20, 0.3, "terms.png")),
    ("show rules", c.Show("rules")),
    ("show terms plot out/t.svg", c.Show("terms", "out/t.svg")),
    ("undo", c.Undo()),
    ("save", c.Save()),
    ("save taught.rules", c.Save("taught.rules")),
    ("help", c.Help()),
    ("help adapt", c.Help("adapt")),
    ("quit", c.Quit()),
    ("exit", c.Quit()),
])
def test_commands_parse(line, expected):
    assert parse_command(line) == expected


def test_rule_lines_are_rules_of_the_rule_language():
    cmd = parse_command("r27: if road is NARROW and not position is very RIGHT "
                        "then steering is LM and speed is 15 with 0.5")
    assert isinstance(cmd, c.TellRule)
    assert cmd.rule.label == "r27" and cmd.rule.weight == 0.5
    assert cmd.rule.consequents[1].value == 15
    use = parse_command("use avoid_obstacle when obstacle is NEAR with 0.8")
    assert isinstance(use, c.TellUse) and use.use.weight == 0.8
    assert use.use.condition is not None
    ops = parse_command("operators: and = product")
    assert isinstance(ops, c.TellOperators) and ops.settings[0].value == "product"


@pytest.mark.parametrize("line, message, expected, hint", [
    ("corect road=1", "unknown command `corect`", "one of behavior", "did you mean `correct`?"),
    ("r1 if road is WIDE then speed is SLOW", "unknown command `r1`", None,
     "a rule label ends with a colon"),
    ("eval road", "the line ends too early", "`=`", "eval road=78"),
    ("eval road=x", "unexpected `x`", "a number", None),
    ("correct road=1 steering=3", "the line ends too early", "`->`", "correct INPUT=VALUE"),
    ("show rulez", "unexpected `rulez`", "rules, terms, examples, behaviors or history", None),
    ("r1: if road WIDE then steering is LS", "unexpected `WIDE`", "`is`",
     "variable is TERM"),
    ("simulate", "the line ends too early", "a file name", "simulate worlds/figure4.yaml"),
    ("at 12.5s", "the line ends too early", "a name", "at 12.5s OUTPUT=VALUE"),
    ("behavior", "the line ends too early", "a name", None),
    ("= 3", "unexpected `=`", "a name", "a line is a rule"),
    ("adapt epochs", "the line ends too early", "a number", None),
    ("adapt epocs 5", "unexpected `epocs`", "`epochs`", "did you mean `epochs`?"),
    ("quit now", "unexpected `now`", "the end of the line", None),
    ("unfrozen r4", "the line ends too early", "`.`", "released with `undo`"),
    ("save out dir.rules", "unexpected `dir`", "the end of the line", "is quoted"),
    ("correct road=1 -> steering is vry LM", "unexpected `LM`", None, "did you mean `very`?"),
    ("correct road=1 -> steering is not LM",
     "`not` is not allowed in a target (`steering is not LM`)", None, "`not` says what it "),
    ("r1: if road is very not WIDE then speed is SLOW",
     "`not` after a hedge (`road is very not WIDE`) is not supported", None,
     "a different number"),
    ("correct road=1 -> steering is not",
     "`not` is not allowed in a target (`steering is not`)", None, "`not` says what it "),
    ("r1: if road is WIDE then speed is not",
     "`not` is not allowed in an action (`speed is not`)", None, "not to its complement"),
    ("r1: if road is WIDE then speed is not SLOW",
     "`not` is not allowed in an action (`speed is not SLOW`)", None, "not to its complement"),
    ("use dr\u00efve", "unexpected `\u00efve`", None, "ASCII letters"),
    ("at 5ms steering=70", "a time must be a number of seconds, not `5ms`", "a decimal number",
     "a time is in seconds"),
    ("adapt epochs 3 rate 0.9 rate 0.01", "`rate` is given twice in one `adapt`", None,
     "give each option once"),
    ("simulate figure4 seed 2x", "unexpected `x`", None, "a seed is a whole number"),
    # a keyword glued to the next word was read as the two (`seed5` as `seed 5`, `5robot a` as
    # `5 robot a`, `epochs50` as `epochs 50`, `plotx.png` as `plot x.png`)
    ("simulate figure4 seed5", "unexpected `seed5`", "`robot` or the end of the line",
     "`seed` and `5` are two words: `seed 5`"),
    ("simulate figure4 seed 5robot oncoming", "unexpected `5robot`", "a seed",
     "`5` and `robot` are two words: `5 robot`"),
    ("simulate figure4 robotcart", "unexpected `robotcart`", "`robot`",
     "`robot` and `cart` are two words: `robot cart`"),
    ("adapt epochs50 rate 0.5", "unexpected `epochs50`", "`epochs`, `plot`, `rate`",
     "`epochs` and `50` are two words: `epochs 50`"),
    ("show rules plotx.png", "unexpected `plotx.png`", "`plot` or the end of the line",
     "`plot` and `x.png` are two words: `plot x.png`"),
    ("show rulesplot x.png", "unexpected `rulesplot`", "rules, terms",
     "`rules` and `plot` are two words: `rules plot`"),
    ("r1: if road is WIDE then speed is SLOW with0.5", "unexpected `with0.5`", "`with`",
     "`with` and `0.5` are two words: `with 0.5`"),
    ("use avoid_obstacle whenroad is WIDE", "unexpected `whenroad`", "`when`",
     "`when` and `road` are two words: `when road`"),
    ("at 13s to14s make a wider turn", "unexpected `to14s`", "`to` and the time",
     "`to` and `14s` are two words: `to 14s`"),
    ("at 12.5s to14s steering=55", "unexpected `to14s`", "`to` and the time",
     "`to` and `14s` are two words: `to 14s`"),
    # a term glued to `and` is one name (the error at the next word said only what was
    # expected there)
    ("correct road=78 -> steering is LMand speed is SLOW", "unexpected `speed`", "`and`",
     "`LMand` is read as one name: `LM` and `and` are two words"),
    ("r1: if road is WIDEand size is SMALL_SZ then speed is SLOW", "unexpected `size`",
     "`then`", "`WIDEand` is read as one name: `WIDE` and `and` are two words"),
    ("simulate figure4 seed x", "unexpected `x`", "a seed", "a seed is a whole number"),
    ("simulate my world.yaml", "unexpected `world`", "`robot` or `seed`", "is quoted"),
    # a mistyped option after the world's name was taken for a name with a space in it
    ("simulate figure4 sed 3", "unexpected `sed`", "`robot` or `seed`", "did you mean `seed`?"),
    ("simulate multirobot robt oncoming", "unexpected `robt`", "`robot` or `seed`",
     "did you mean `robot`?"),
    ("simulate figure4 seed 3 robo x", "unexpected `robo`", "`robot`",
     "did you mean `robot`?"),
    # the end of a `simulate` line after `seed` or `robot` said "name a world file"
    ("simulate figure4 seed", "the line ends too early", "a seed",
     "`simulate figure4 seed 42`"),
    ("simulate multirobot robot", "the line ends too early", "a name",
     "name the robot whose run `at` corrects, as the world names it"),
    # a robot's name that is no plain word, and the options in the other order
    ("simulate two.yaml robot cart 2", "unexpected `2`", "the end of the line",
     'quoted: `robot "cart 2"`'),
    # (a world's path holding the word `robot` is not where the robot's name begins)
    ("simulate robots/two.yaml robot cart 2", "unexpected `2`", "the end of the line",
     'quoted: `robot "cart 2"`'),
    ("simulate multirobot robot oncoming seed 2", "unexpected `seed`", "the end of the line",
     "the seed comes before the robot: `simulate multirobot seed 2 robot oncoming`"),
    # a relative instruction where a target goes: it needs a window of the recorded run
    ("correct heading=-5 -> turn harder", "unexpected `harder`", "`is`",
     "`turn harder` is an instruction: it takes a window of the recorded run, "
     "`at 13s to 14.5s turn harder`"),
    ("correct heading=-5 -> go faster", "unexpected `faster`", "`is`",
     "a target reads `OUTPUT=VALUE` or `OUTPUT is TERM`; a relative instruction"),
    # an instruction said as a term after `is`: "unexpected `harder`, expected `and`" alone
    ("correct heading=-5 -> steering is turn harder", "unexpected `harder`",
     "`and` or the end of the line", "`turn harder` is an instruction, not a term: say it "
     "alone after the window, `at 13s to 14.5s turn harder`, not after inputs"),
    ("at 13s to 14.5s steering is make a wider turn", "unexpected `a`", None,
     "`make a wider turn` is an instruction, not a term: say it alone after the window, "
     "`at 13s to 14.5s make a wider turn`"),
    ("at 12s speed is slow down", "unexpected `down`", None, "`at 12s slow down`"),
    # a window written otherwise: `at13s` (glued: "type `help`"), `from 13s to 14s` ("did you
    # mean `frozen`?"), `at 13s until 14s` ("give values as NAME=VALUE")
    ("at13s turn harder", "unknown command `at13s`", None,
     "`at` and `13s` are two words: `at 13s turn harder`"),
    ("from 13s to 14s turn harder", "unknown command `from`", None,
     "a window of the recorded run is written `at 13s to 14s ...`"),
    ("at 13s until 14s turn harder", "unexpected `14`", None,
     "a window is written `at 13s to 14s`: the word between its times is `to`"),
    ("at 13s - 14s steering=50", "unexpected `-`", None,
     "a window is written `at 13s to 14s`: the word between its times is `to`"),
    # an instruction and a target on one line: it was "unexpected `=`, expected a name" alone
    ("at 13s to 14.5s turn harder steering=50", "unexpected `=`", None,
     "one correction per `at` line: the instruction, `at 13s to 14.5s turn harder`, or the "
     "target, `at 13s to 14.5s steering=50`, each on a line of its own"),
    ("at 2s slow down speed=10", "unexpected `=`", None,
     "`at 2s slow down`, or the target, `at 2s speed=10`"),
    # a bare instruction: it is no command; the window, and the list
    ("turn harder", "unknown command `turn`: an instruction takes a window of the recorded "
     "run, `at 13s to 14.5s turn harder`", "`turn harder`, `turn less`, `make a wider turn`, "
     "`slow down`, `speed up`, `keep further from the wall`, `keep right`", "simulate WORLD"),
    ("make a wider turn", "unknown command `make`: an instruction takes a window of the "
     "recorded run, `at 13s to 14.5s make a wider turn`", "`at START [to END]`", None),
    # a target alone (`at 12.5s steering is very LM` in the README, without its `at`): it
    # said only "unknown command `steering`", "type `help`"
    ("speed=20", "unknown command `speed`: `speed=20` alone is neither a rule nor a correction",
     "a rule (`if ... then speed=20`), or a correction (`at TIME speed=20`, `correct "
     "NAME=VALUE ... -> speed=20`)", "`at 12.5s ...` corrects the run `simulate WORLD` recorded"),
    ("steering is  very LM", "unknown command `steering`: `steering is very LM` alone is "
     "neither a rule nor a correction", "`at TIME steering is very LM`",
     "`help at` and `help correct` say more"),
    ("speed = 20", "unknown command `speed`: `speed = 20` alone is neither a rule nor a "
     "correction", "`correct NAME=VALUE ... -> speed = 20`", None),
    # a rule without its `if` (also the second line of a wrapped rule after Ctrl-C)
    ("size is SMALL_SZ then speed is SLOW", "unknown command `size`: a rule begins with `if`",
     "`if CONDITION then ACTION`", "`if size is SMALL_SZ then speed is SLOW`"),
    # a target takes only the hedges that move a value along its scale
    ("at 1s to 2s steering is vry LM", "unexpected `LM`", None,
     "`vry` is not a hedge (hedges of a target: very, extremely, somewhat, more_or_less); "
     "did you mean `very`?"),
    ("r1: if road is vry WIDE then speed is SLOW", "unexpected `WIDE`", None,
     "(hedges: very, extremely, somewhat, more_or_less, seldom, intensely, any)"),
    # adapt's options are named (`adapt 50` said only the list; after a number the merged
    # LALR states said "expected `,`, `->` or a name")
    ("adapt 50", "unexpected `50`", "`epochs`, `plot`, `rate`, `unconstrained` or the end of "
     "the line", "adapt's options are named: `adapt epochs 50` (how many epochs)"),
    ("adapt epochs 60 0.5", "unexpected `0.5`", "`unconstrained` or the end of the line",
     "`adapt rate 0.5` (the learning rate)"),
    ("adapt epochs 5 robot", "unexpected `robot`", "`epochs`, `plot`, `rate`, `unconstrained` "
     "or the end of the line", None),
    # what to show: the one meant (it said only the list)
    ("show rule", "unexpected `rule`", "rules, terms", "did you mean `rules`?"),
    ("show Terms", "unexpected `Terms`", "rules, terms", "did you mean `terms`?"),
    # `=` for `is`, and FCL's `;` (which was "`SLOW` is not a hedge ... did you mean `seldom`?")
    ("if road = WIDE then speed is SLOW", "unexpected `=`", "`is`",
     "write `road is ...`: a condition or action reads `variable is TERM`"),
    ("r9: if road is WIDE then speed = 5", "unexpected `=`", "`is`", "write `speed is ...`"),
    ("r9: if road is WIDE then speed is SLOW;", "unexpected `;`", "`and` or `with`",
     "a rule or command needs no `;` at its end"),
])
def test_mistyped_lines_say_what_was_expected(line, message, expected, hint):
    with pytest.raises(RuleSyntaxError) as info:
        parse_command(line, "lesson.lesson", 7)
    err = info.value
    assert err.message == message
    assert err.span.path == "lesson.lesson" and err.span.line == 7
    if expected:
        assert expected in err.expected
    if hint:
        assert hint in err.hint
    text = err.render()
    assert text.startswith("lesson.lesson:7:")
    assert "$END" not in text and "Token(" not in text and "__ANON" not in text


@pytest.mark.parametrize("line", [
    "correct road=78 -> steering is LB LM",
    "correct road=78 -> steering is vary LB",
    "correct road=78 -> steering is LM with 0.5",
    "at 1s to 2s steering is LB speed",
])
def test_a_target_is_not_offered_a_with_it_refuses(line):
    """A target reuses the rule language's consequent, which `with W` may follow in a rule: the
    error offered `with`, and following it gave the same error without it."""
    with pytest.raises(RuleSyntaxError) as info:
        parse_command(line)
    assert info.value.expected == "`and` or the end of the line"


def test_an_arrow_in_an_at_line_is_not_taken_for_a_window():
    """`at 13s - 14s` is said to be a window written with `to`; the arrow of `correct ... ->`
    copied into an `at` line is said to be none of `at`'s (it would have been told "a window is
    written `at 13s to END`")."""
    with pytest.raises(RuleSyntaxError) as info:
        parse_command("at 13s -> steering=50")
    assert info.value.message == "unexpected `->`"
    assert info.value.hint == "`at` takes no `->`: its targets follow the time, `at 13s " \
        "steering=50`"


TARGET_HEDGES = "a hedge (very, extremely, somewhat, more_or_less)"


@pytest.mark.parametrize("line, message, expected", [
    # a target cut short after `is` (or a hedge): it offered every hedge of a rule's condition,
    # `seldom, intensely, any` among them, which the target then refused ("`seldom LM` has no
    # meaning for a target value")
    ("at 13s to 14.5s steering is", "the line ends too early",
     f"{TARGET_HEDGES}, a name or a number"),
    ("correct road=78 -> steering is very", "the line ends too early",
     f"{TARGET_HEDGES} or a name"),
    ("at 13s steering is extremely", "the line ends too early", f"{TARGET_HEDGES} or a name"),
    ("correct road=78 -> steering is very 5", "unexpected `5`", f"{TARGET_HEDGES} or a name"),
])
def test_a_target_is_offered_only_the_hedges_it_takes(line, message, expected):
    with pytest.raises(RuleSyntaxError) as info:
        parse_command(line)
    assert info.value.message == message
    assert info.value.expected == expected


def test_a_rule_is_still_offered_every_hedge():
    with pytest.raises(RuleSyntaxError) as info:
        parse_command("if road is")
    assert "seldom, intensely, any" in info.value.expected


@pytest.mark.parametrize("line, hint", [
    # a word before the term that is no hedge and close to none: no hint at all, where a rule's
    # condition says the same (`road is sligthly WIDE`: "a term's name is one word ...")
    ("correct road=78 -> steering is sligthly LM",
     "`sligthly LM`: a term's name is one word (`sligthly_LM`), and `sligthly` is not a hedge "
     "of a target (very, extremely, somewhat, more_or_less), which would stand before the term"),
    ("at 13s to 14s speed is rather SLOW",
     "`rather SLOW`: a term's name is one word (`rather_SLOW`), and `rather` is not a hedge of "
     "a target (very, extremely, somewhat, more_or_less), which would stand before the term"),
])
def test_two_words_in_a_target_are_said_to_be_one_term_or_a_hedge(line, hint):
    with pytest.raises(RuleSyntaxError) as info:
        parse_command(line)
    assert info.value.expected == "`and` or the end of the line"
    assert info.value.hint == hint


@pytest.mark.parametrize("line, message, column, hint", [
    ("correct road=0x1F size=45 position=4 -> steering=60", "`road` must be a number, not "
     "`0x1F`", 14, None),
    ("eval road=7_8 size=45 position=4", "`road` must be a number, not `7_8`", 11, None),
    ("eval road=78 size=4_", "`size` must be a number, not `4_`", 19, None),
    ("eval road=1.2.3", "`road` must be a number, not `1.2.3`", 11, None),
    ("correct road=78 -> steering is 6_0", "`steering` must be a number, not `6_0`", 32, None),
    ("adapt epochs 0x10", "`epochs` must be a number, not `0x10`", 14, None),
    ("at 0x10s steering=50", "a time must be a number of seconds, not `0x10s`", 4,
     "a time is in seconds"),
    ("at 3s to 1_2s turn harder", "a time must be a number of seconds, not `1_2s`", 10,
     "a time is in seconds"),
])
def test_a_malformed_number_is_named_at_its_own_place(line, message, column, hint):
    """The lexer read `0x1F` as `0` and a name `x1F`, so the error fell on the next word
    ("unexpected `size`, expected `=`"); `mitos eval` names the value for the same text."""
    with pytest.raises(RuleSyntaxError) as info:
        parse_command(line, "lesson.lesson", 3)
    err = info.value
    assert err.message == message
    assert (err.span.line, err.span.column) == (3, column)
    assert err.expected.startswith("a decimal number such as 78, -4.5 or 1e3")
    assert err.hint == hint or hint in err.hint


@pytest.mark.parametrize("line, name", [
    ('save "C:\\Users\\me\\taught.rules"', "C:\\Users\\me\\taught.rules"),   # `\U`: no escape
    ('simulate "a\\qb.yaml"', "a\\qb.yaml"),
    ('save "out/\\u0074.rules"', "out/t.rules"),                     # a JSON escape, as `terms`
])
def test_a_quoted_file_name_is_read_as_a_rule_files_terms(line, name):
    """A quoted name with a backslash that is no JSON escape (a Windows path) ended in a Lark
    VisitError traceback; it is read as the rule language reads `terms "..."`."""
    got = parse_command(line)
    assert (got.world if isinstance(got, c.Simulate) else got.path) == name


@pytest.mark.parametrize("line, column, says", [
    ("save out/t\0.rules", 6, "holds a NUL byte"),
    ('save "out/t\0.rules"', 7, "holds a NUL byte"),
    ("adapt epochs 1 plot a\0.png", 21, "holds a NUL byte"),
    ("simulate a\0.yaml", 10, "holds a NUL byte"),
    ('save "out/\\ud800.rules"', 6, "half a character (a lone surrogate)"),
    ("save out/" + "a" * 300 + ".rules", 6, "a part of more than 255 bytes"),
])
def test_a_file_name_no_system_can_open_is_refused_at_it(line, column, says):
    """`save out/t<NUL>.rules`, `adapt ... plot a<NUL>.png` and `save "\\ud800.rules"` ended in
    the system's ValueError or UnicodeEncodeError traceback; a name too long for a file system
    was said with no place."""
    with pytest.raises(LessonError, match=re.escape(says)) as info:
        parse_command(line, "lesson.lesson", 3)
    assert (info.value.span.line, info.value.span.column) == (3, column)


@pytest.mark.parametrize("line", ["eval " + "a" * 30_000,
                                  "at 1s to 2s steering is S" + "a" * 30_000 + "T",
                                  "correct road=78 -> " + "a" * 30_000])
def test_a_long_word_is_read_in_time(line):
    """The search for a name glued to a malformed number began at every letter of a word and
    went over the rest of it each time: a lesson line of 100,000 letters took a quarter of an
    hour (the fuzzer's hang); it is read at once."""
    started = time.perf_counter()
    with contextlib.suppress(RuleSyntaxError, LessonError):
        parse_command(line, "lesson.lesson", 3)
    assert time.perf_counter() - started < 10


@pytest.mark.parametrize("line", ["eval road=+5 size=.5 position=5.", "eval road=1E+2 size=-.5e1",
                                  "at 1.5 to 2s speed=+1e1", "at 3 to 3.1 steering is 60",
                                  "adapt epochs 5 rate .5"])
def test_every_number_the_grammar_reads_is_still_read(line):
    parse_command(line)


@pytest.mark.parametrize("line, column, example", [
    ('simulate ""', 10, "simulate worlds/figure4.yaml"),
    ('simulate " " seed 3', 10, "simulate worlds/figure4.yaml"),
    ('save ""', 6, "save taught.rules"),
    ('show terms plot ""', 17, "plot terms.png"),
    ('adapt epochs 3 plot ""', 21, "plot terms.png"),
])
def test_an_empty_file_name_is_refused_at_its_place(line, column, example):
    """`Path('')` is the current directory: `simulate ""` was "`` is a directory, not a world
    file" at column 1."""
    with pytest.raises(LessonError) as info:
        parse_command(line, "lesson.lesson", 2)
    err = info.value
    assert err.message == "the file name is empty: it names no file"
    assert (err.span.line, err.span.column) == (2, column)
    assert err.hint == f"give a file name, e.g. `{example}`"


def test_a_rule_may_continue_on_the_next_line():
    assert incomplete("r1: if road is WIDE")
    assert incomplete("if road is WIDE and size is SMALL_SZ")
    assert not incomplete("if road is WIDE then steering is LS")
    assert not incomplete("eval road=")          # not a rule: an error, not a continuation
    cmd = parse_command("r1: if road is WIDE\n    then steering is LS")
    assert isinstance(cmd, c.TellRule)


@pytest.mark.parametrize("line, message, column", [
    ("adapt rate 1e-400", "`1e-400` is too small for a float: it would read as 0", 12),
    ("adapt rate 0", "must lie in (0, 1), not 0", 12),
    ("adapt epochs 3 rate 1e400", "`1e400` is past a float's range", 21),
    ("adapt epochs 2.5", "epochs must be a whole number of at least 1, not 2.5", 14),
    ("adapt rate 0.5 epochs 1e999", "`1e999` is past a float's range", 23),
    ("adapt epochs 99999999999999999999", "at most 100,000 epochs in one `adapt`, not "
     "99999999999999999999", 14),
])
def test_adapt_values_that_cannot_be_used_are_refused_where_written(line, message, column):
    """Before the session looks for examples, and as the instructor wrote the value."""
    with pytest.raises((LessonError, RuleSyntaxError)) as info:
        parse_command(line, "lesson.lesson", 4)
    err = info.value
    assert message in err.message
    assert (err.span.line, err.span.column) == (4, column)


def test_an_adapt_whose_gain_rounds_away_says_so():
    """Q lowered by the descent but lost to the grid learned values are kept to is not "Q
    cannot go lower"."""
    from mitos_cli.teach.session import _nothing_changed

    said = _nothing_changed([1.1e-3, 5e-5, 1.6e-6, 1.1e-3], rounded=True)
    assert "lowered Q to 1.6e-06" in said and "rounds back" in said and "stays 0.0011" in said
    assert "cannot go lower" in _nothing_changed([2.0, 2.0, 2.0], rounded=True)
    assert "cannot go lower" in _nothing_changed([2.0, 2.0], rounded=False)


def test_an_adapt_at_a_rate_too_small_to_move_anything_says_so():
    """`adapt rate 1e-300` moves no number: it said "Q cannot go lower from here", which the
    next `adapt` at the default rate showed false."""
    from mitos_cli.api import default_rulebase_path
    from mitos_cli.teach.session import Session

    out: list[str] = []
    s = Session(default_rulebase_path(), out=out.append)
    s.run("correct road=78 size=45 position=4 -> steering=60")
    out.clear()
    s.run("adapt epochs 5 rate 1e-300")
    said = "\n".join(out)
    assert "cannot go lower" not in said
    assert "the steps this rate takes are too small to lower Q; one epoch at the default " \
           "rate takes it to" in said and "(`adapt rate 0.5`)" in said


def test_a_window_without_a_target_does_not_ask_for_its_to_again():
    """`at 5s to 6s` ending there was told it expected "`to` or a name" (LALR's merged
    states): the `to` is written already."""
    with pytest.raises(RuleSyntaxError) as info:
        parse_command("at 5s to 6s", "l.lesson", 3)
    assert info.value.message == "the line ends too early"
    assert info.value.expected == "a name" and (info.value.span.line, info.value.span.column) == (3, 12)
    with pytest.raises(RuleSyntaxError) as info:
        parse_command("at 5s")
    assert "`to`" in info.value.expected
