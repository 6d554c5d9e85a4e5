"""The ``help`` texts of the teaching prompt (one line per command, a paragraph per topic)."""

from __future__ import annotations

from ..errors import LessonError, unknown

SUMMARY = """\
Tell rules, correct outputs, let the robot adapt, save. Every change is journaled (`undo`).

  if road is WIDE and position is LEFT then steering is RS    tell a rule (label it `r28: if ...`
                                                 to name it; the same label replaces a rule)
  behavior NAME   ...rules, use, frozen...   end    a named behavior, recalled by `use NAME`
  use NAME                                       make NAME the active behavior
  eval road=78 size=45 position=4                the DOF trace of the active behavior
  correct road=78 size=45 position=4 -> steering=60 speed=20    an example of what you want
  simulate worlds/figure4.yaml [seed N] [robot NAME]    drive the active behavior through a world
  at 12.5s steering=55   |   at 11s to 13s steering is LM    corrections during that drive
  at 13s to 14.5s make a wider turn              ... or in words (`help at` lists them)
  frozen heading.AHEAD  |  unfrozen heading.AHEAD    keep a term as it is, or let it move
  operators: and = product                       operators of the open (or active) behavior
  adapt [epochs N] [rate ETA] [plot FILE] [unconstrained]    learn from the examples (Q never
                                                 increases; `unconstrained`: order and bounds only)
  show rules|terms|examples|behaviors|history [plot FILE]
  undo        take back the last change
  save [PATH] write the rule file and its term set (the original is kept unless named)
  help TOPIC  more on one command (e.g. `help adapt`)
  quit        leave (nothing is lost: `mitos teach --resume` continues)"""

TOPICS = {
    "rule": """\
A rule in the rule language, on one line (or continued on the next lines):
  r28: if road is NARROW and position is RIGHT then steering is LM and speed is SLOW
It goes to the open behavior (between `behavior NAME` and `end`), else the active one. A rule
with an existing label replaces that rule; without a label it gets the next free `rN`. The
answer is the rule as understood, and any conflict: another rule with the same condition and
different actions.""",
    "behavior": """\
behavior NAME     open a new behavior; the lines up to `end` are its rules, `use B [when C]
                  [with W]` lines (blend behavior B, weighted by condition C) and `frozen` lines
end               close it; it becomes the active behavior
A behavior is recalled by its name alone: `use NAME` here, `--behavior NAME` in `mitos eval`,
`behavior: NAME` in a world file.""",
    "use": """\
use NAME          make NAME the active behavior: `eval`, `correct`, `adapt`, `simulate` use it
Inside `behavior ... end`, `use B when C` blends B into the behavior being told.""",
    "frozen": """\
frozen r4, r5     adaptation leaves the consequents of rules r4 and r5 of the open (or active)
                  behavior alone. A term is frozen in the YAML term set with `frozen: true`.
frozen heading.AHEAD      adaptation leaves this term as it is (`save` writes `frozen: true`)
unfrozen heading.AHEAD    lift a freeze, or the hold of a centre term at its point""",
    "operators": """\
operators: and = product, or = probor
The operator settings of the open (or active) behavior, as an `operators:` line of a rule file
means (`inference = mamdani`, `defuzzify = bisector`, ...; `mitos operators` lists every norm
and inference). Settings its rules cannot be evaluated with are refused before they are kept.""",
    "eval": """\
eval road=78 size=45 position=4
The fuzzified inputs, the rules that fire with their DOFs, and the outputs, as `mitos eval`.""",
    "correct": """\
correct road=78 size=45 position=4 -> steering=60 speed=20
correct road=78 size=45 position=4 -> steering is very LM and speed is SLOW
An example: for these inputs, these outputs (numbers, or terms with hedges: `very` half a
term further from the centre, `extremely` a whole term, `somewhat` half a term toward it).
Outputs you leave out are not corrected.""",
    "simulate": """\
simulate WORLD [seed N] [robot NAME]
Drive the active behavior through a world file (a path, or the name of a packaged world) and
keep the recorded run, so that `at` can correct it (robot NAME's run; default the first;
a name that is no bare name is quoted, as `robot "cart 2"`).""",
    "at": """\
at 12.5s steering=55          one example: what the robot perceived at 12.5 s, and the output
                              it should have chosen
at 11s to 13s steering=55     one example per recorded tick from 11 s to 13 s
at 11s to 13s steering is LM  the same, in words
at 13s to 14.5s make a wider turn    an instruction: what the robot did at each tick of the
                              window, transformed into a target (the examples are shown):
{instructions}
A term further moves along the output's terms sorted by value (steering LB 30, LM 50, ...,
RB 150; smaller is to the left): 67 deg, 0.15 of the way from LS to LM, becomes 47 deg, 0.15
of the way from LM to LB.
`at` corrects the behavior that drove the run (the rules that produced the motion), also when
another behavior is active now: `use` it before `adapt`.""",
    "adapt": """\
adapt [epochs N] [rate ETA] [plot FILE] [unconstrained]
Gradient descent on Q = sum_k (y(x_k) - t_k)^2 over the examples (the paper's eqs. 13-14),
moving the break points of the active behavior's input terms and its output values. ETA in
(0, 1) is the learning factor (default 0.5), N the number of epochs (default 50). Peaks stay
ordered, widths positive, shared break points tied; every step is halved until Q decreases.
Frozen terms and the consequents of frozen rules keep their values; the terms keep their
meaning (order, coverage >= 0.5, distinct, centre terms at their point) unless
`unconstrained`. Afterwards the changed terms are listed before -> after and in words, with
the interpretability checks; `plot FILE` draws them (.png or .svg).""",
    "show": """\
show rules        the rules of the open (or active) behavior, new and changed ones marked
show terms        the terms of its variables, with the values they had before
show examples     the examples, with what the behavior answers now
show behaviors    the behaviors (* active)
show history      every change of this session (undone ones marked)
show terms plot FILE   also draw the terms that changed, before and after""",
    "undo": """\
undo              take back the last change (a rule, an example, an adaptation, ...); repeat
                  to walk further back. Saved files are not touched.""",
    "save": """\
save [PATH]       write PATH and its term set beside it (OUT.terms.yaml), changing only the
                  numbers that were learned (default: where the last `save` went, also after
                  `mitos teach --resume`, else the --save-as file); the original files are
                  overwritten only when you name them.""",
    "quit": """\
quit              leave the prompt (Ctrl-D too). Everything is in the journal under
                  .mitos/teach/; `mitos teach --resume` continues where you left off.""",
}
ALIASES = {"if": "rule", "rules": "rule", "end": "behavior", "exit": "quit", "terms": "show",
           "unfrozen": "frozen", "instructions": "at",
           "examples": "show", "history": "show", "behaviors": "show",
           # an instruction's first word (`help turn`: "unknown help topic"), and targets
           "instruction": "at", "turn": "at", "make": "at", "slow": "at", "speed": "at",
           "keep": "at", "target": "correct", "targets": "correct", "hedge": "correct",
           "hedges": "correct"}


def _instructions() -> str:
    """Each instruction of the registry and what it does, one line each."""
    from .instructions import INSTRUCTIONS

    return "\n".join(f"  {phrase:<28}{ins.meaning}" for phrase, ins in INSTRUCTIONS.items())


def help_text(topic: str | None = None) -> str:
    if topic is None or topic == "help":
        return SUMMARY
    key = ALIASES.get(topic, topic)
    if key not in TOPICS:
        error = unknown("help topic", topic, TOPICS, cls=LessonError)
        error.expected = "one of " + ", ".join(sorted(TOPICS))   # all of them: a short list
        raise error
    return TOPICS[key].replace("{instructions}", _instructions())
