"""Tab completion at the teaching prompt (``mitos_cli.teach.prompt.Completer``): the words
that may come next, from what the session knows. Tested on ``words``, the line before the
cursor, without a terminal."""

from __future__ import annotations

import pytest

from mitos_cli.api import default_rulebase_path
from mitos_cli.teach.prompt import Completer
from mitos_cli.teach.session import Session


@pytest.fixture(scope="module")
def completer():
    return Completer(Session(default_rulebase_path(), out=lambda line: None))


STEERING = {"LB", "LM", "LS", "ST", "RS", "RM", "RB"}
HEDGES = {"very", "extremely", "somewhat", "more_or_less"}


@pytest.mark.parametrize("line", [
    "correct road=78 size=45 position=4 -> steering is ",
    "at 12.5s steering is ",
    "at 11s to 13s steering is ",
    "correct road=78 -> speed is SLOW and steering is ",
])
def test_the_terms_of_the_output_after_is(completer, line):
    """After `steering is` a target takes a term of steering (or a hedge): the prompt offered
    `steering=` and `speed=`, which cannot follow `is`."""
    words = set(completer.words(line))
    assert words >= STEERING and words >= HEDGES
    assert not any(w.endswith("=") for w in words)


def test_a_term_after_a_hedge_and_and_after_a_term(completer):
    assert set(completer.words("at 12s steering is very ")) == STEERING
    assert set(completer.words("correct road=78 -> speed is ")) >= {"SLOW"}
    assert completer.words("at 12s steering is very LM ") == ["and"]
    assert completer.words("at 12s steering is LM ") == ["and"]
    assert set(completer.words("at 12s steering is LM and ")) == {"steering=", "speed="}


def test_after_at_a_time_the_outputs_to_and_the_instructions(completer):
    words = set(completer.words("at 12s "))
    assert words >= {"steering=", "speed=", "to"}
    assert words >= {"turn", "make", "slow", "speed", "keep"}
    assert completer.words("at ") == [] and completer.words("at 11s to ") == []
    assert "to" not in completer.words("at 11s to 13s ")
    assert set(completer.words("at 11s to 13s make ")) == {"a"}
    assert set(completer.words("at 11s to 13s make a ")) == {"wider"}
    assert set(completer.words("at 11s to 13s turn ")) == {"harder", "less"}
    assert set(completer.words("at 11s to 13s keep ")) == {"further", "right"}


def test_inputs_before_the_arrow(completer):
    words = completer.words("correct road=78 ")
    assert "size=" in words and "->" in words and "steering=" not in words
    assert "->" not in completer.words("eval road=78 ")
    # `st<tab>` gives `steering=` at once (a word form is typed: `steering is ...`)
    assert set(completer.words("correct road=78 -> ")) == {"steering=", "speed="}


def test_simulate_completes_worlds_its_options_and_the_worlds_robots(completer):
    """After `simulate` the prompt offered the rule language's words (`road`, `is`, `then`),
    none of which can follow it; after `robot` too, where the world's robots go."""
    assert set(completer.words("simulate ")) >= {"figure4", "multirobot", "corridor"}
    assert set(completer.words("simulate fig")) >= {"figure4"}
    assert set(completer.words("simulate figure4 ")) == {"seed", "robot"}
    assert completer.words("simulate figure4 seed ") == []              # a number goes here
    assert completer.words("simulate figure4 seed 3 ") == ["robot"]
    assert set(completer.words("simulate multirobot robot ")) == {"robot", "oncoming"}
    assert set(completer.words("simulate multirobot seed 2 robot onc")) == {"robot", "oncoming"}
    assert completer.words("simulate nowhere.yaml robot ") == []     # no world: nothing


def test_commands_complete_only_what_may_follow_them(completer):
    """`save`, `undo`, `end` and `quit` were offered the rule language's words; `adapt` lacked
    `unconstrained`; `unfrozen` (and `frozen`) take terms as `heading.AHEAD`."""
    for line in ("save ", "undo ", "end ", "quit ", "exit "):
        assert completer.words(line) == [], line
    assert set(completer.words("adapt ")) == {"epochs", "rate", "plot", "unconstrained"}
    assert {"heading.AHEAD", "steering.ST"} <= set(completer.words("unfrozen "))
    assert {"heading.AHEAD", "r4"} <= set(completer.words("frozen "))
