"""A teaching session: the rule base being taught, the examples, and every change journaled.

:class:`Session` executes :mod:`~mitos_cli.teach.commands` objects and answers in text. Each
change becomes a journal entry *first* and is then applied by :func:`apply` (a pure state
transition), so replaying the journal's entries rebuilds the state exactly: that is how
``undo`` and ``mitos teach --resume`` work. The changes are

==============  ==========================================================================
``rule``        a rule told in ``behavior`` (added, or replacing the rule with its label)
``behavior``    a new behavior opened (``behavior NAME``); ``end`` closes it
``use``         ``use B [when C]`` in the open behavior
``frozen``      ``frozen r4, r5`` in the open (or active) behavior
``operators``   an ``operators:`` line in the open (or active) behavior
``activate``    ``use NAME`` at the top: the behavior taught and evaluated from now on
``examples``    corrections (``correct``, or ``at`` on a simulation): inputs and targets
``freeze``      ``frozen heading.AHEAD``: terms adaptation keeps as they are
``release``     ``unfrozen heading.AHEAD``: a freeze or a hold at a point lifted
``adapt``       learned term parameters and crisp values (with Q before and after)
==============  ==========================================================================
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np

from ..engine.compile import CompiledRuleBase, compile_rulebase
from ..errors import LessonError, MitosError, RuleBaseError, Span, unknown
from ..fileio import real_path, save_lock
from ..lang.interpretability import held_term
from ..lang.model import (
    And,
    Behavior,
    Expr,
    Not,
    Prop,
    Rule,
    RuleBase,
    format_expr,
    format_number,
    format_rule,
    format_use,
)
from ..lang.operators import resolve
from ..lang.parse import parse_rule
from ..lang.resolve import check_expr, check_rule, load_rules_file
from ..lang.terms import check_term
from ..words import plural
from . import commands as cmd
from . import text
from .journal import RECORDS, Journal, MemoryJournal, held_interrupt
from .save import Sources
from .state import State, apply, files_digest, journaled, learned_changes, variables

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

    from ..lang.model import Setting
    from .adapt import Adaptation
    from .simulation import Recording


def _canonical(expr: Expr) -> str:
    """An antecedent written so that reordered ``and`` / ``or`` items compare equal."""
    if isinstance(expr, Prop):
        return format_expr(expr)
    if isinstance(expr, Not):
        return f"not ({_canonical(expr.expr)})"
    op = " and " if isinstance(expr, And) else " or "
    return "(" + op.join(sorted(_canonical(i) for i in expr.items)) + ")"


def _consequents(rule: Rule) -> dict:
    return {c.var: (c.term, c.value, c.hedges) for c in rule.consequents}


_NUMBERED = re.compile(r"r(\d+)")
#: how many rules with a told rule's condition the answer names (the rest are counted)
SHOWN_SAME = 5
#: the paper's learning factor eta when `adapt` names none
DEFAULT_RATE = 0.5


@dataclasses.dataclass
class _RuleIndex:
    """One behavior's rules by label and by condition, valid while the behavior's ``rules``
    is the tuple it was built from. Telling a rule used to walk every rule three times
    (its label, a free label, rules with the same condition, each condition written out
    again): a lesson of N rules took time N^2 (4,000 rules, 32 s). Built once, the index is
    updated with each told rule; any other change of the rules builds it again."""

    rules: tuple[Rule, ...]
    position: dict[str, int]                 # label -> its rule's index in ``rules``
    same: dict[str, list[Rule]]              # canonical condition -> its rules, in order
    numbered: int                            # the largest N of the labels `rN` (-1: none)

    @classmethod
    def of(cls, rules: tuple[Rule, ...]) -> _RuleIndex:
        index = cls(rules, {}, {}, -1)
        for i, r in enumerate(rules):
            index.position.setdefault(r.label, i)
            index.same.setdefault(_canonical(r.antecedent), []).append(r)
            index._number(r.label)
        return index

    def _number(self, label: str) -> None:
        m = _NUMBERED.fullmatch(label)
        if m:
            self.numbered = max(self.numbered, int(m.group(1)))

    def next_label(self) -> str:
        """A free label: `rN` after the largest `rN`, else after the number of rules."""
        n = self.numbered + 1 if self.numbered >= 0 else len(self.rules) + 1
        while f"r{n}" in self.position:
            n += 1
        return f"r{n}"

    def told(self, rules: tuple[Rule, ...], before: Rule | None, new: Rule) -> None:
        """``new`` was added (``before`` is None) or replaced ``before``: ``rules`` now."""
        key = _canonical(new.antecedent)
        if before is not None:
            old = self.same[_canonical(before.antecedent)]
            at = next(i for i, r in enumerate(old) if r is before)
            if old is self.same.get(key):
                old[at] = new                     # same condition: keep its place
            else:
                del old[at]
                self.same.setdefault(key, []).append(new)
        else:
            self.position[new.label] = len(rules) - 1
            self.same.setdefault(key, []).append(new)
        self._number(new.label)
        self.rules = rules



class Session:
    """The state of one teaching session and the commands that change it."""

    def __init__(self, rules_path: str | Path, behavior: str | None = None,
                 journal: Journal | None = None, save_as: str | Path | None = None,
                 out: Callable[[str], None] | None = None,
                 progress: Callable | None = None, sources: Sources | None = None) -> None:
        # as `mitos teach` and read_rulebase: the file, else a packaged rule base by its path
        # or name (a name the system cannot look up, too long, is simply not found)
        from ..resources import resolve

        self.rules_path = resolve("rulebases", rules_path, ".rules") or Path(rules_path)
        if sources is not None:                     # the files as the session began
            self.original = sources.rulebase(self.rules_path)
        else:
            try:
                self.original = load_rules_file(self.rules_path)
            except MitosError as exc:       # a .fis, .fcl or .fll: convert it first
                from ..interop import hint_wrong_reader

                hint_wrong_reader(exc, self.rules_path, "mitos teach")
                raise
            sources = _sources(self.original)
        self.sources = sources
        #: the digest the original's files have as far as the session knows (read, or saved
        #: over by it): a save over them refuses files another program changed since
        self.files_seen = files_digest(self.original)
        self.journal = journal if journal is not None else MemoryJournal()
        self.save_as = Path(save_as) if save_as is not None else None
        #: the digest of the files each save wrote, by where (resolved): a later save there
        #: refuses files another program or session wrote since
        self.saves_seen: dict[Path, tuple[tuple[Path, ...], str]] = {}
        self.out = out or print
        self.progress = progress
        self.echo: Callable[[str], None] = lambda text: None     # lessons echo their lines
        active = behavior or self.original.default_behavior
        self.original.behavior(active)              # unknown behavior: did you mean
        self.start_behavior = active
        self.simulation: Recording | None = None
        self._noted: tuple[int, str] | None = None     # `at` said whom the run corrects
        self.base: Path | None = None       # where a lesson's relative world paths start
        #: the directory a lesson's `save PATH` must lie below (set while a lesson runs): a
        #: lesson may come from anyone, and its `save /any/where.rules` wrote over that file
        self.confined: Path | None = None
        self.saved_seq = 0
        #: what cut the last command's adaptation short (Ctrl-C, or a SIGTERM's or SIGHUP's
        #: Terminated), to be raised again once what it learned is journaled
        self.interrupted: KeyboardInterrupt | None = None
        self.opened_at: Span | None = None  # where a lesson opened the behavior still open
        self.state = State(self.original, active)
        self._indexes: dict[str, _RuleIndex] = {}
        if not self.journal.entries:
            self.journal.append("start", rules=str(self.rules_path.resolve()),
                                behavior=active, digest=self.files_seen,
                                save_as=None if self.save_as is None
                                else os.path.abspath(self.save_as),
                                **({} if sources is None else {"sources": sources.to_json()}))

    # -- resume ------------------------------------------------------------------------------
    @classmethod
    def resume(cls, journal: Journal, out: Callable[[str], None] | None = None,
               progress: Callable | None = None, recover: bool = False) -> Session:
        start = journal.entries[0] if journal.entries else None
        first = Span(str(journal.path), journal.lines[0] if journal.lines else 1, 1)
        if start is None or start.get("op") != "start":
            raise LessonError("not a teaching journal (it does not begin with the session's "
                              "start)", span=first)
        try:
            session = cls(start["rules"], start["behavior"], journal, start.get("save_as"),
                          out, progress)
            known = _own_digest(journal.entries, session.rules_path)
            sources = Sources.from_json(start.get("sources"))
            live = session.files_seen
            if live != known and sources is not None:
                with contextlib.suppress(MitosError):    # (a copy edited by hand: as now)
                    known = _killed_save(cls(start["rules"], start["behavior"], journal,
                                             start.get("save_as"), out, progress, sources),
                                         live) or known
            if live == known and sources is not None:
                # as it began (the files may hold its own saves, which `undo` takes back)
                with contextlib.suppress(MitosError):    # (a copy edited by hand: as now)
                    session = cls(start["rules"], start["behavior"], journal,
                                  start.get("save_as"), out, progress, sources)
                    session.files_seen = known
        except MitosError as exc:       # the rule file or behavior the journal names
            if exc.span is None:
                exc.span = first
            raise
        if session.files_seen != known:
            session.out(f"warning: {start['rules']} or its term set changed since the session "
                        f"{'started' if known == start.get('digest') else 'saved over them'}; "
                        f"the journal's changes are applied to the files as they are now")
        session.replay(recover)
        session._simulate_again()
        saves = [e for e in journal.entries if e["op"] == "save"]
        session.saved_seq = saves[-1]["seq"] if saves else 0
        if saves:                                   # a bare `save` goes where the last went
            session.save_as = Path(saves[-1]["path"])
        return session

    def replay(self, recover: bool = False, checked: bool = True) -> None:
        """Apply the journal's changes. One that cannot be applied (a journal edited by hand,
        or rule files changed under it) is an error at its journal line; with ``recover``
        the session keeps the changes before it and the journal is cut there. Unchecked
        (``undo``: every change left was checked when told or resumed, and none after it
        needs the one taken back) only applies them: the checks compiled the behavior of
        every `correct` again, and each `undo` of a long lesson took longer (0.4 s at 470
        changes, a 3,000-line lesson did not end in a minute)."""
        self.state = State(self.original, self.start_behavior)
        if not checked:
            for entry in self.journal.active():
                apply(self.state, entry)
            return
        for entry in self.journal.active():
            try:
                self._check_entry(entry)
                apply(self.state, entry)
                if entry["op"] == "examples":
                    self._check_examples(entry)
            except (MitosError, KeyError, TypeError, ValueError, AttributeError,
                    IndexError) as exc:
                line = self.journal.line_of(entry)
                why = exc.message if isinstance(exc, MitosError) else \
                    f"{type(exc).__name__}: {exc}"
                if not recover or not line:
                    inner = exc.hint if isinstance(exc, MitosError) and exc.hint else None
                    raise LessonError(
                        f"change {entry.get('seq')} of the journal cannot be applied ({why})",
                        span=Span(str(self.journal.path), line or 1, 1),
                        hint=_then(inner, "`mitos teach --resume --recover` continues the "
                                          "session with the changes before it (the journal "
                                          "is kept aside)")) from None
                self.journal.recovered_at = line
                self._cut_journal(line)
                return

    def _check_entry(self, entry: dict) -> None:
        """What the prompt checks of a change when it is told, checked again of a replayed
        entry (a journal edited by hand): the rule's names, the `use`'s cycle, the behavior
        made active, the operators, the rule labels and terms frozen. (An unknown behavior or
        T-norm was taken in, and every later `eval` refused it at `<prompt>`.)"""
        op = entry["op"]
        if op == "activate":
            self.rulebase.behavior(entry["behavior"])          # unknown: did you mean
        elif op == "operators":
            b = self.rulebase.behavior(entry["behavior"])
            settings = journaled(entry, cmd.TellOperators).settings
            resolve(settings, resolve(b.operators, resolve(self.rulebase.operators)))
            self._check_operators(b, settings)
        elif op == "frozen":
            b = self.rulebase.behavior(entry["behavior"])
            labels = [r.label for r in b.rules]
            for label in entry["labels"]:
                if label not in labels:
                    raise self._unknown_label(b, label, labels)
        elif op in ("freeze", "release"):
            self._term_refs([*entry["terms"], *entry.get("holds", [])])
        elif op == "rule":
            check_rule(parse_rule(entry["text"]), self.rulebase.variables)
        elif op == "use":
            use = journaled(entry, cmd.TellUse).use
            if use.behavior == entry["behavior"] \
                    or _reaches(self.rulebase, use.behavior, entry["behavior"]):
                raise RuleBaseError(f"`{use.behavior}` uses `{entry['behavior']}`: a cycle")
        elif op == "adapt":                      # what adaptation can learn: well-formed terms
            variables = self.rulebase.variables
            for name, terms in entry["terms"].items():
                if name not in variables:
                    raise unknown("variable", name, list(variables), cls=LessonError)
                v = variables[name]
                for term, params in terms.items():
                    check_term(v.term(term).with_params(tuple(map(float, params))), v.universe,
                               name, peak_inside=v.role == "output")

    def _check_examples(self, entry: dict) -> None:
        """That a replayed ``examples`` entry gives every input of its behavior and corrects
        only its outputs (a journal edited by hand may not)."""
        compiled = self.compiled(entry.get("behavior") or None)
        for i, example in enumerate(entry["examples"], 1):
            missing = [k for k in compiled.inputs if k not in example["inputs"]]
            wrong = [k for k in example["targets"] if k not in compiled.outputs]
            if missing or wrong or not example["targets"]:
                raise LessonError(
                    f"example {i} does not correct behavior `{compiled.behavior}`: " + (
                        f"no value for {', '.join(f'`{k}`' for k in missing)}" if missing else
                        f"`{wrong[0]}` is not one of its outputs" if wrong else "no target"))

    def _simulate_again(self) -> None:
        """The run the last ``simulate`` recorded, driven again on the rule base as it was
        then (a run is a function of the rules, the world and the seed), so that ``at``
        corrects it after a resume as before."""
        from .simulation import run_world

        runs = [e for e in self.journal.entries if e["op"] == "simulate"]
        if not runs:
            return
        last = runs[-1]
        before = [e for e in self.journal.entries if e["seq"] < last["seq"]]
        undone = {e["of"] for e in before if e["op"] == "undo"}
        state = State(self.original, self.start_behavior)
        for entry in before:
            if entry["seq"] not in undone and entry["op"] not in RECORDS:
                apply(state, entry)
        try:
            self.simulation = run_world(last["world"], state.rulebase, last["behavior"],
                                        last.get("seed"), None, last.get("robot"))
        except MitosError as exc:           # the world file changed or went since
            self.out(f"warning: the last run ({last.get('line', 'simulate')}) cannot be driven "
                     f"again: {exc.message}; `simulate` it again to correct it")
            return
        self.out(f"the last run is recorded again: "
                 f"{self.simulation.describe(self.use_advice)}")
        if last.get("run") not in (None, self.simulation.fingerprint):   # (older journals: none)
            self.out(f"warning: this is not the run recorded before ({last.get('verdict')}, "
                     f"now {self.simulation.verdict}): `{Path(last['world']).name}` or a file "
                     f"it reads changed since; `at` corrects the run driven now")

    def _cut_journal(self, line: int) -> None:
        """Truncate the journal before ``line`` (kept whole aside) and forget later entries."""
        raw = self.journal.path.read_bytes()
        at = sum(len(x) + 1 for x in raw.split(b"\n")[:line - 1])
        self.journal.cut(at, raw)
        keep = [i for i, n in enumerate(self.journal.lines) if n < line]
        self.journal.entries = [self.journal.entries[i] for i in keep]
        self.journal.lines = [self.journal.lines[i] for i in keep]

    # -- helpers -------------------------------------------------------------------------------
    @property
    def rulebase(self) -> RuleBase:
        return self.state.rulebase

    @property
    def focus(self) -> str:
        """The behavior told rules go to: the open one, else the active one."""
        return self.state.block or self.state.active

    @property
    def unsaved(self) -> bool:
        def changes(upto: int | None = None) -> list[int]:   # what `save` would write
            return [e["seq"] for e in self.journal.active(upto) if e["op"] != "activate"]

        return changes() != changes(self.saved_seq)

    def compiled(self, behavior: str | None = None) -> CompiledRuleBase:
        name = behavior or self.state.active
        b = self.rulebase.behavior(name)
        if not b.rules and not b.uses:
            raise LessonError(f"behavior `{name}` has no rules yet",
                              hint="tell it a rule, or `use` another behavior")
        return compile_rulebase(self.rulebase, name)

    def change(self, op: str, line: str, **data: object) -> dict:
        """Journal a change (durably), then apply it."""
        entry = self.journal.append(op, line=line, **data)
        apply(self.state, entry)
        return entry

    # -- commands ------------------------------------------------------------------------------
    def run(self, line: str, path: str | None = None, lineno: int = 1) -> bool:
        """Parse and execute one line; False after ``quit``."""
        command = cmd.parse_command(line, path, lineno)
        return self.execute(command, line.strip())

    def execute(self, c: cmd.Command, line: str = "") -> bool:
        handler = getattr(self, "_" + type(c).__name__.lower())
        return handler(c, line) is not False

    def _index(self, b: Behavior) -> _RuleIndex:
        index = self._indexes.get(b.name)
        if index is None or index.rules is not b.rules:
            index = self._indexes[b.name] = _RuleIndex.of(b.rules)
        return index

    def _tellrule(self, c: cmd.TellRule, line: str) -> None:
        rule = c.rule
        check_rule(rule, self.rulebase.variables)
        b = self.rulebase.behavior(self.focus)
        index = self._index(b)
        if not rule.label:
            rule = dataclasses.replace(rule, label=index.next_label())
        at = index.position.get(rule.label)
        before = None if at is None else b.rules[at]
        self.change("rule", line, behavior=b.name, text=format_rule(rule))
        head = f"{format_rule(rule)}"
        if before is None:
            self.out(f"{head}\n  added to {b.name} ({plural(len(b.rules) + 1, 'rule')})")
            elsewhere = [o.name for o in self.rulebase.behaviors if o.name != b.name
                         and c.rule.label and rule.label in self._index(o).position]
            if elsewhere:                   # (the one the instructor meant to replace?)
                self.out(f"  note: {elsewhere[0]} has a rule {rule.label} too, which stays as "
                         f"it was ({self.use_advice(elsewhere[0])} to replace that one)")
        else:
            self.out(f"{head}\n  replaces {format_rule(before)}")
        after = self.rulebase.behavior(b.name).rules
        new = after[len(after) - 1 if at is None else at]   # where `apply` put it
        index.told(after, before, new)
        same = index.same[_canonical(new.antecedent)]
        shown = 0
        for other in same:
            if other is new or other.label == rule.label:
                continue
            if shown == SHOWN_SAME:
                self.out(f"  and {plural(len(same) - 1 - shown, 'more rule')} with the same "
                         f"condition")
                break
            shown += 1
            if _consequents(other) != _consequents(rule):
                self.out(f"  conflict: {other.label} has the same condition but says "
                         f"{', '.join(text.say(x) for x in other.consequents)}")
            else:
                self.out(f"  note: {other.label} says the same")

    def _openbehavior(self, c: cmd.OpenBehavior, line: str) -> None:
        if self.state.block is not None:
            raise LessonError(f"behavior `{self.state.block}` is still open",
                              hint="close it with `end` first")
        if c.name in [b.name for b in self.rulebase.behaviors]:
            raise LessonError(f"behavior `{c.name}` exists already",
                              hint=f"`use {c.name}` makes it the active behavior; rules told "
                                   f"then go to it")
        self.change("behavior", line, name=c.name)
        self.out(f"behavior {c.name}: tell its rules (and `use` lines), then `end`")

    def _closebehavior(self, c: cmd.CloseBehavior, line: str) -> None:
        name = self.state.block
        if name is None:
            raise LessonError("no behavior is open", hint="`behavior NAME` opens one")
        b = self.rulebase.behavior(name)
        if not b.rules and not b.uses:
            raise LessonError(f"behavior `{name}` is empty",
                              hint="tell it a rule or a `use` line before `end` (or `undo`)")
        self.change("end", line, activate=name)
        self.out(f"behavior {name} learned ({plural(len(b.rules), 'rule')}, "
                 f"{plural(len(b.uses), 'use')}); "
                 f"it is now active (recall another by `use NAME`)")

    def _telluse(self, c: cmd.TellUse, line: str) -> None:
        use = c.use
        names = [b.name for b in self.rulebase.behaviors]
        if use.behavior not in names:
            raise unknown("behavior", use.behavior, names,
                          span=use.span and use.span.naming(use.behavior))
        if self.state.block is None:
            if use.condition is not None or use.weight != 1.0:
                raise LessonError("`use B when C` blends behaviors and belongs inside a "
                                  "behavior", span=use.span,
                                  hint="open one with `behavior NAME`, or write `use "
                                       f"{use.behavior}` to make it the active behavior")
            self.compiled(use.behavior)
            self.change("activate", line, behavior=use.behavior)
            b = self.rulebase.behavior(use.behavior)
            self.out(f"active behavior: {use.behavior} ({plural(len(b.rules), 'rule')}"
                     + (f", uses {', '.join(u.behavior for u in b.uses)}" if b.uses else "")
                     + ")")
            return
        if use.condition is not None:
            check_expr(use.condition, self.rulebase.variables)
        if not 0.0 <= use.weight <= 1.0:
            raise RuleBaseError(f"a weight must lie in [0, 1], not {use.weight:g}",
                                span=use.span)
        if _reaches(self.rulebase, use.behavior, self.state.block):
            raise RuleBaseError(f"`{use.behavior}` uses `{self.state.block}`: a cycle",
                                span=use.span)
        self.change("use", line, behavior=self.state.block, text=format_use(use))
        self.out(f"{format_use(use)}\n  added to {self.state.block}")

    def _tellfrozen(self, c: cmd.TellFrozen, line: str) -> None:
        """Freeze rules; one named twice counts once, and one frozen already is said so and
        not journaled, as `frozen` of a frozen term (`frozen r1` again was a change that
        `save` wrote nothing new for; `frozen r0, r0` was saved as written)."""
        b = self.rulebase.behavior(self.focus)
        labels = [r.label for r in b.rules]
        for label in c.labels:
            if label not in labels:
                raise self._unknown_label(b, label, labels)
        named = list(dict.fromkeys(c.labels))
        new = [x for x in named if x not in b.frozen]
        already = [x for x in named if x in b.frozen]
        if new:
            self.change("frozen", line, behavior=b.name, labels=new)
            self.out(f"{b.name}: adaptation leaves the consequents of {', '.join(new)} alone")
        if already:
            self.out(f"{b.name}: {', '.join(already)} {'is' if len(already) == 1 else 'are'} "
                     "frozen already" + ("; nothing changes" if not new else ""))

    def _unknown_label(self, b: Behavior, label: str, labels: list[str]) -> MitosError:
        """``frozen LABEL`` of a rule the active behavior does not have; when no label is
        close, the hint names the behavior that has it (`drive` has no rules of its own: it
        uses the behaviors that do)."""
        exc = unknown("rule label", label, labels, owner=b.name)
        var = self.rulebase.variables.get(label)
        if var is not None and var.terms:           # `frozen heading`: its terms, one by one
            terms = [f"{label}.{t.name}" for t in var.terms]
            shown = ", ".join(terms[:5]) + (", ..." if len(terms) > 5 else "")
            exc.hint = (f"`{label}` is a variable: freeze its terms, `frozen {shown}` (or one "
                        f"of them: `frozen {terms[0]}`)")
        elif exc.hint is None:
            owners = [o.name for o in self.rulebase.behaviors
                      if o.name != b.name and any(r.label == label for r in o.rules)]
            own = "" if labels else f"`{b.name}` has no rules of its own; "
            if owners:
                exc.hint = (f"{own}`{label}` is a rule of `{owners[0]}`: "
                            f"{self.use_advice(owners[0])}, then `frozen {label}`")
            elif own:
                exc.hint = own.rstrip("; ")
        return exc

    def _term_refs(self, refs: Iterable[Sequence[str]]) -> list[list[str]]:
        """The terms ``refs`` (``frozen``, ``unfrozen``) names, checked: an unknown variable is
        a name error, as an unknown term or rule label is (it was a lesson error, a "command
        error" at the prompt), with its "did you mean"."""
        variables = self.rulebase.variables
        for var, term in refs:
            if var not in variables:
                raise unknown("variable", var, list(variables))
            variables[var].term(term)                    # unknown term: did you mean
        return [list(r) for r in refs]

    def _freezeterms(self, c: cmd.FreezeTerms, line: str) -> None:
        """Freeze terms; a term frozen already is said so and not journaled (a command that
        changes nothing is no unsaved change: `save` would write nothing for it)."""
        terms = self._term_refs(c.terms)
        variables = self.rulebase.variables
        new = [[v, t] for v, t in terms if not variables[v].term(t).frozen]
        already = [f"{v}.{t}" for v, t in terms if [v, t] not in new]
        if new:
            self.change("freeze", line, terms=new)
            self.out("adaptation keeps " + ", ".join(f"{v}.{t}" for v, t in new)
                     + (" as it is (`unfrozen` lets it move" if len(new) == 1 else
                        " as they are (`unfrozen` lets them move")
                     + "; `save` writes `frozen: true`)")
        if already:
            self.out(", ".join(already) + (" is" if len(already) == 1 else " are")
                     + " frozen already: adaptation keeps "
                     + ("it" if len(already) == 1 else "them") + " as "
                     + ("it is" if len(already) == 1 else "they are")
                     + ("; nothing changes" if not new else ""))

    def _releaseterms(self, c: cmd.ReleaseTerms, line: str) -> None:
        """Lift freezes and holds; a term with neither is said so and not journaled, as
        `frozen` of a frozen term."""
        terms = self._term_refs(c.terms)
        lifted = [(v, t, *self._lifted(v, t)) for v, t in terms]          # before the change
        changed = [[v, t] for v, t, _, lifts in lifted if lifts]
        # the centre terms among them, as the files wrote them: `save` writes `held: false`
        written = self.original.variables
        holds = [[v, t] for v, t in changed if v in written
                 and (held := held_term(written[v])) is not None and held[0].name == t]
        if changed:
            self.change("release", line, terms=changed, holds=holds)
        for _, _, text_, _ in lifted:
            self.out(text_ + ("" if changed else "; nothing changes"))

    def _lifted(self, var: str, term: str) -> tuple[str, bool]:
        """What `unfrozen VAR.TERM` lifts, said before it does: a freeze, a hold at a point of
        symmetry, both, or nothing (the term could move already); and whether it lifts
        anything."""
        now = self.rulebase.variables[var]
        what, notes = [], []
        if (var, term) in self.state.frozen_terms or now.term(term).frozen:
            what.append("its freeze")
        held = held_term(now)
        if held is not None and held[0].name == term and held[0].held \
                and (var, term) not in self.state.released:
            what.append(f"its hold at {format_number(held[1])}")
            notes.append("the point its neighbours mirror each other about; `save` writes "
                         "`held: false`")
        if not what:
            already = " (its hold was lifted already)" if (var, term) in self.state.released \
                and held is not None and held[0].name == term else ""
            return (f"{var}.{term} is neither frozen nor held{already}: adaptation could move "
                    "it already"), False
        return (f"adaptation may move {var}.{term}: " + " and ".join(what)
                + (" is" if len(what) == 1 else " are") + " lifted"
                + (f" ({'; '.join(notes)})" if notes else "")), True

    def _telloperators(self, c: cmd.TellOperators, line: str) -> None:
        from ..engine.check import MAMDANI_ONLY

        b = self.rulebase.behavior(self.focus)
        ops = resolve(c.settings, resolve(b.operators, resolve(self.rulebase.operators)))
        self._check_operators(b, c.settings)
        text = "operators: " + ", ".join(f"{s.key} = {s.value}" for s in c.settings)
        self.change("operators", line, behavior=b.name, text=text)
        self.out(f"{b.name}: {text}")
        # as `mitos check`'s idle-setting says of the saved file: told at the prompt it was
        # taken without a word, though it changes no number
        weighted = ops.inference in ("weighted_average", "weighted_sum")
        for setting in c.settings:
            if (setting.key == "accumulation" and not weighted) or \
                    (setting.key in MAMDANI_ONLY and ops.inference != "mamdani"):
                self.out(f"note: `{setting.key} = {setting.value}` has no effect: behavior "
                         f"`{b.name}` uses {ops.inference} inference"
                         + (" (add `inference = mamdani` to use it)"
                            if setting.key in MAMDANI_ONLY else ""))

    def _check_operators(self, b: Behavior, settings: tuple[Setting, ...]) -> None:
        """Refuse operators the behavior's rules cannot be evaluated with (Tsukamoto
        inference on terms that are not monotonic, ...) before they are journaled."""
        from .state import _replace_behavior

        if not b.rules and not b.uses:
            return
        trial = _replace_behavior(self.rulebase, dataclasses.replace(
            b, operators=b.operators + tuple(settings)))
        try:
            compile_rulebase(trial, b.name)
        except MitosError as exc:
            where = f" ({exc.span.path}:{exc.span.line})" if exc.span is not None else ""
            raise LessonError(f"behavior `{b.name}` cannot be evaluated with these operators: "
                              f"{exc.message}{where}", hint=exc.hint or
                              "keep its operators, or tell rules these operators can evaluate"
                              ) from None

    def _values(self, given: tuple[cmd.Assign, ...], names: tuple[str, ...], role: str,
                compiled: CompiledRuleBase, require_all: bool) -> dict:
        out = {}
        for a in given:
            if a.name not in names:
                raise _not_its(a.name, a.span, role, names, compiled)
            if a.name in out:
                raise LessonError(f"`{a.name}` is given twice", span=a.span)
            if not math.isfinite(a.value):      # (a guard: the grammar reads 1e400 as an error)
                raise LessonError(f"{a.name} = {a.value:g} is not a finite number", span=a.span,
                                  hint="give a value inside the variable's universe")
            if role == "output":
                lo, hi = compiled.variables[a.name].universe
                if not lo <= a.value <= hi:
                    raise LessonError(f"{a.name} = {format_number(a.value)} lies outside its universe "
                                      f"[{lo:g}, {hi:g}]", span=a.span)
            out[a.name] = a.value
        missing = [n for n in names if n not in out]
        if require_all and missing:
            raise LessonError("missing input " + ", ".join(f"`{m}`" for m in missing),
                              expected="a value for each of " + ", ".join(names),
                              hint="give them as " + " ".join(f"{m}=VALUE" for m in missing))
        return out

    def _eval(self, c: cmd.Eval, line: str) -> None:
        from ..engine.evaluation import as_batch, evaluate
        from ..engine.trace import trace_of

        compiled = self.compiled()
        values = self._values(c.inputs, compiled.inputs, "input", compiled, True)
        X = as_batch(compiled, values)
        self.out(trace_of(evaluate(compiled, X), given=X).render())

    def _correct(self, c: cmd.Correct, line: str) -> None:
        compiled = self.compiled()
        inputs = self._values(c.inputs, compiled.inputs, "input", compiled, True)
        targets = self._values(c.targets, compiled.outputs, "output", compiled, False)
        for name, value in inputs.items():
            lo, hi = compiled.variables[name].universe
            if not lo <= value <= hi:
                self.out(f"note: {name} = {value:g} lies outside its universe [{lo:g}, {hi:g}]; "
                         f"the rules read it as {min(max(value, lo), hi):g}")
        now = self._outputs(compiled, [inputs])[0]
        self.change("examples", line, behavior=compiled.behavior,
                    examples=[{"inputs": inputs, "targets": targets, "source": "correct"}])
        self.out(f"example {len(self.state.examples)}: " + text.example_text(inputs, targets, now))

    def _said(self, said: tuple[cmd.Said, ...], compiled: CompiledRuleBase) -> tuple[cmd.Assign, ...]:
        """``steering is very LM`` -> ``steering=40`` (the hedged term's value)."""
        from .instructions import HEDGE_STEPS, at_the_middle, hedged, not_a_target_hedge, past_the_end

        out = []
        for t in said:
            if t.name not in compiled.outputs:
                raise _not_its(t.name, t.span, "output", compiled.outputs, compiled)
            if t.term is None:
                out.append(cmd.Assign(t.name, cast(float, t.value), t.span))   # (a crisp value)
                continue
            var = compiled.variables[t.name]
            var.term(t.term, t.span and t.span.ending(t.term))
            for h in t.hedges:          # said at the hedge, not at the line's start
                if h not in HEDGE_STEPS:
                    raise not_a_target_hedge(h, t.term, t.span and t.span.naming(h))
            value = hedged(var, t.term, t.hedges)
            end = past_the_end(var, t.term, t.hedges)
            words = " ".join(t.hedges + (t.term,))
            if end is not None:
                self.out(f"note: `{t.name} is {words}` lies past {end}, the end of the "
                         f"{t.name} scale: the target is {end}'s value, "
                         f"{t.name}={format_number(value)}")
            elif t.hedges and at_the_middle(var, t.term):
                self.out(f"note: `{t.name} is {words}` is {t.term}'s own value, "
                         f"{t.name}={format_number(value)}: a hedge moves a target away from "
                         f"the middle of the {t.name} scale, where {t.term} stands")
            out.append(cmd.Assign(t.name, value, t.span))
        return tuple(out)

    def _correctsaid(self, c: cmd.CorrectSaid, line: str) -> None:
        compiled = self.compiled()
        self._correct(cmd.Correct(c.inputs, self._said(c.targets, compiled)), line)

    def _atsaid(self, c: cmd.AtSaid, line: str) -> None:
        rec = self._recording()
        compiled = self._driver(rec, note=False)
        self._at(cmd.At(c.start, c.stop, self._said(c.targets, compiled), c.places), line)

    def _atinstruction(self, c: cmd.AtInstruction, line: str) -> None:
        from .instructions import Window, instruction, targets

        try:
            ins = instruction(c.words)
        except LessonError as exc:
            exc.span = c.span
            exc.hint = self._output_said(c.words) or exc.hint
            raise
        rec = self._recording()
        compiled = self._driver(rec)
        rows = rec.rows(c.start, c.stop, c.places)
        inputs = [rec.inputs_at(i, compiled.inputs) for i in rows]
        now = self._outputs(compiled, inputs)
        window = Window({o: np.array([y[o] for y in now]) for o in compiled.outputs},
                        {k: np.array([x[k] for x in inputs]) for k in compiled.inputs},
                        compiled.variables)
        try:                            # (what this run cannot take: at the instruction)
            wanted = targets(ins, window)
        except LessonError as exc:
            exc.span = exc.span or c.span
            raise
        keep = np.flatnonzero(np.isfinite(wanted))
        if keep.size == 0:
            raise LessonError(f"`{ins.words}`: the robot went straight {rec.when(rows)}, so "
                              "there is no turn to change", span=c.span,
                              hint="name the window of a turn")
        first = keep[0]
        did = float(window.outputs[ins.output][first])
        self.out(f"{ins.words}: {ins.meaning} ({ins.output} {text.num(did)} -> "
                 f"{text.num(float(wanted[first]))} at {rec.time(rows[first]):g} s)")
        self._add_window(compiled, rec, rows[keep], [inputs[i] for i in keep],
                         [{ins.output: float(wanted[i])} for i in keep], line)

    def _output_said(self, words: tuple[str, ...]) -> str | None:
        """What to write when an `at` line names an output where an instruction goes, alone
        or with one of its terms but no `is` (`at 13s steering`, `at 13s speed SLOW`)."""
        var = self.rulebase.variables.get(words[0])
        if var is None or var.role != "output" or len(words) > 2:
            return None
        names = [t.name for t in var.terms]
        if len(words) == 2 and words[1] not in names:
            return None
        said = (f"`{var.name} is {words[1]}`" if len(words) == 2 else
                f"`{var.name} is TERM` (`{var.name} is {names[0]}`)")
        return f"say what `{var.name}` should be: {said} or `{var.name}=VALUE`"

    def use_advice(self, name: str) -> str:
        """How to make behavior ``name`` the active one now: `use NAME`, but while a behavior
        is open a `use` line is one of its lines (a blend), so it is closed first."""
        block = self.state.block
        if block is None:
            return f"`use {name}`"
        if block == name:
            return "`end` (it then becomes the active behavior)"
        return (f"`end` (`use` in the open behavior `{block}` blends `{name}` into it), then "
                f"`use {name}`")

    def _recording(self) -> Recording:
        if self.simulation is None:
            raise LessonError("no simulation to correct yet",
                              hint="run `simulate WORLD` first, then `at 12.5s steering=55`")
        return self.simulation

    def _driver(self, rec: Recording, note: bool = True) -> CompiledRuleBase:
        """The behavior that drove the recorded run, whichever behavior is active now.

        ``at`` corrects what the robot did: the paper's instructor watches the motion and
        says what it should have been, so the correction must reach the rules that produced
        it. Those are the recording behavior's (with the behaviors it ``use``s, each weighted
        by its context at that tick, which is how `adapt` spreads the correction over them).
        The active behavior's output at the same inputs may be one nobody used (`use
        avoid_obstacle` after a `drive` run: its rules had weight 0 on the straight), so its
        rules are not taught from the run; a note says where the examples went."""
        names = [b.name for b in self.rulebase.behaviors]
        if rec.behavior not in names:
            raise LessonError(f"the run was driven by behavior `{rec.behavior}`, which is no "
                              "longer in the rule base (undone)",
                              hint="`simulate` the world again to correct a run of the "
                                   "active behavior")
        if note and rec.behavior != self.state.active \
                and self._noted != (id(rec), self.state.active):
            self._noted = (id(rec), self.state.active)      # once per run and active behavior
            self.out(f"note: {rec.name} was driven by `{rec.behavior}`, so this corrects "
                     f"{rec.behavior} (the rules that produced the motion, with the behaviors "
                     f"it uses), not the active `{self.state.active}`; "
                     f"{self.use_advice(rec.behavior)} before `adapt` (to teach "
                     f"`{self.state.active}` from a run, `simulate` with it active)")
        return self.compiled(rec.behavior)

    def _outputs(self, compiled: CompiledRuleBase, inputs: list[dict]) -> list[dict]:
        from ..engine.evaluation import evaluate

        X = np.array([[x[k] for k in compiled.inputs] for x in inputs], dtype=float)
        y = evaluate(compiled, X, detail=False).outputs
        return [dict(zip(compiled.outputs, map(float, row))) for row in y]

    def _simulate(self, c: cmd.Simulate, line: str) -> None:
        from .simulation import run_world, world_path

        seed = _seed(c.seed) if c.seed is not None else None
        self.compiled()
        self.simulation = run_world(c.world, self.rulebase, self.state.active, seed, self.base,
                                    c.robot, c.robot_span)
        # the path as it names the world from anywhere (`--resume --session DIR` elsewhere
        # drove the packaged world of a relative path's name, or a file of that name there)
        self.journal.append("simulate", line=line,
                            world=os.path.abspath(world_path(c.world, self.base)),
                            behavior=self.state.active, seed=seed, robot=c.robot,
                            run=self.simulation.fingerprint, verdict=self.simulation.verdict)
        self.out(self.simulation.describe(self.use_advice))

    def _at(self, c: cmd.At, line: str) -> None:
        rec = self._recording()
        compiled = self._driver(rec)
        rows = rec.rows(c.start, c.stop, c.places)
        targets = self._values(c.targets, compiled.outputs, "output", compiled, False)
        inputs = [rec.inputs_at(i, compiled.inputs) for i in rows]
        self._add_window(compiled, rec, rows, inputs, [targets] * len(rows), line)

    def _add_window(self, compiled: CompiledRuleBase, rec: Recording, rows: np.ndarray, inputs: list[dict],
                    targets: list[dict], line: str) -> None:
        """Examples from ticks ``rows`` of the recorded run, journaled and shown."""
        now = self._outputs(compiled, inputs)
        examples = [{"inputs": x, "targets": t, "source": f"{rec.name} t={rec.time(i):g}s"}
                    for x, t, i in zip(inputs, targets, rows)]
        self.change("examples", line, behavior=compiled.behavior, examples=examples)
        first = len(self.state.examples) - len(examples) + 1
        self.out(f"{plural(len(examples), 'example')} from "
                 f"{rec.name} {rec.when(rows)} (#{first}"
                 + (f"-{len(self.state.examples)}" if len(examples) > 1 else "") + "):")
        for x, t, y in list(zip(inputs, targets, now))[:5]:
            self.out("  " + text.example_text(x, t, y))
        if len(examples) > 5:
            self.out(f"  ... ({len(examples) - 5} more: `show examples`)")

    def training_set(self, compiled: CompiledRuleBase) -> tuple[np.ndarray, np.ndarray]:
        """``X[n, k]`` and targets ``[n, m]`` (NaN: not given) from the usable examples."""
        usable = [e for e in self.state.examples if e.behavior == compiled.behavior]
        if not usable:
            others = sorted({e.behavior for e in self.state.examples})
            # the example is of this behavior's own inputs (`drive` reads 13: `road=78 size=45
            # position=4` was an example that `correct` refuses there)
            shown = " ".join(f"{k}=..." for k in compiled.inputs[:3]) + (
                " ..." if len(compiled.inputs) > 3 else "")
            example = ("correct road=78 size=45 position=4 -> steering=60"
                       if tuple(compiled.inputs) == ("road", "size", "position") else
                       f"correct {shown} -> {compiled.outputs[0]}=...")
            hint = (f"the examples given so far correct {', '.join(others)}: "
                    f"{self.use_advice(others[0])} to adapt it" if others else
                    f"give corrections: `{example}` (every input of `{compiled.behavior}`), "
                    f"or `simulate WORLD` then `at 12.5s {compiled.outputs[0]}=55`")
            raise LessonError(f"no examples for behavior `{compiled.behavior}` to learn from",
                              hint=hint)
        X = np.array([[e.inputs[k] for k in compiled.inputs] for e in usable], dtype=float)
        T = np.array([[e.targets.get(o, np.nan) for o in compiled.outputs] for e in usable],
                     dtype=float)
        return X, T

    def _adapt(self, c: cmd.Adapt, line: str) -> None:
        from .adapt import learned_rulebase
        from .learned import in_words

        compiled = self.compiled()
        X, T = self.training_set(compiled)
        epochs = _whole(c.epochs, "epochs", 1) if c.epochs is not None else 50
        if epochs > cmd.MAX_EPOCHS:     # 10^300 epochs is a hang, not a lesson
            raise LessonError(f"at most {cmd.MAX_EPOCHS:,} epochs in one `adapt`, not {epochs:,}",
                              hint="adapt again to go on from where it stopped")
        rate = DEFAULT_RATE if c.rate is None else c.rate
        result = self._learn(c, compiled, X, T, epochs, rate)
        self.interrupted = result.stopped_by or (KeyboardInterrupt() if result.interrupted
                                                 else None)
        before = self.rulebase
        terms, crisp = learned_changes(before, learned_rulebase(result.parameters,
                                                                result.values))
        history = [float(q) for q in result.history]
        self.out(text.q_lines(history, len(X), result))
        kept = result.parameters.frozen_reasons     # frozen terms, rules, shapes not learned
        if not terms and not crisp:
            if kept:
                self.out("not adapted: " + "; ".join(kept))
            self.out(_nothing_changed(history, result.rounded,
                                      self._lower(c, compiled, X, T, rate, history[0])))
            return
        # an adaptation that stopped short says so in `show history` (it read as all epochs)
        ran = len(history) - 1 - (1 if result.rounded else 0)
        stopped = ("interrupted" if result.interrupted else
                   "converged" if result.converged else None)
        self.change("adapt", line, behavior=compiled.behavior, terms=terms, crisp=crisp,
                    q=[history[0], history[-1]], epochs=epochs, rate=rate,
                    **({"stopped": stopped, "ran": ran} if stopped else {}))
        self.out(text.changed_table(before, self.rulebase, crisp))
        if kept:
            self.out("not adapted: " + "; ".join(kept))
        labels = [f"{owner}/{before.behavior(owner).rules[i].label}" for owner, i, _, _ in crisp]
        self.out(in_words(before, self.rulebase, result.parameters, labels))
        self.out(self.interpretability())
        if c.plot is not None:
            self._plot_terms(before, self.rulebase, c.plot)

    def _learn(self, c: cmd.Adapt, compiled: CompiledRuleBase, X: np.ndarray, T: np.ndarray,
               epochs: int, rate: float) -> Adaptation:
        """The descent itself, with the session's frozen and released terms and a progress
        bar."""
        from .adapt import adapt, parameterise

        params = parameterise(compiled, constrained=c.constrained,
                              frozen_terms=self.state.frozen_terms, released=self.state.released)
        if params.n_free == 0:
            raise LessonError(f"nothing in behavior `{compiled.behavior}` may be adapted",
                              hint="every term and consequent it uses is frozen")
        if c.plot is not None:   # checked before the descent, whose change is kept anyway
            from ..draw.output import check_format
            from ..fileio import check_writable

            with _drawing():
                check_format(c.plot)
                _check_below(c.plot, self.confined, "terms.png")
                check_writable(c.plot)
        progress = self.progress(epochs) if self.progress else None
        try:
            return adapt(compiled, X, T, epochs=epochs, rate=rate, parameters=params,
                         on_epoch=(progress.update if progress else None))
        finally:
            if progress:
                progress.close()

    def _lower(self, c: cmd.Adapt, compiled: CompiledRuleBase, X: np.ndarray, T: np.ndarray,
               rate: float, q: float) -> float | None:
        """The Q one epoch at the default rate reaches, when an ``adapt`` at a smaller rate
        changed nothing: `adapt rate 1e-300` moves no number, and said Q could not go lower."""
        from .adapt import adapt, parameterise

        if rate >= DEFAULT_RATE:
            return None
        params = parameterise(compiled, constrained=c.constrained,
                              frozen_terms=self.state.frozen_terms, released=self.state.released)
        lower = adapt(compiled, X, T, epochs=1, rate=DEFAULT_RATE, parameters=params).history[-1]
        return lower if lower < q else None

    def _plot_terms(self, before: RuleBase, after: RuleBase, path: str) -> None:
        try:
            from ..draw.terms import draw_terms_before_after
        except ImportError:                          # pragma: no cover - optional module
            raise LessonError("plots need the drawing module (mitos_cli.draw)") from None
        changed = [(a, b) for a, b in zip(variables(before), variables(after))
                   if a.terms != b.terms]
        if not changed:
            raise LessonError("no term has changed yet, so there is nothing to compare",
                              hint="`adapt` first, or `show terms` for the numbers")
        target = Path(path)
        written = []
        for old, new in changed:
            dest = target if len(changed) == 1 else \
                target.with_name(f"{target.stem}-{new.name}{target.suffix}")
            with _drawing():
                draw_terms_before_after(old, new, dest)
            written.append(str(dest))
        self.out("plotted " + ", ".join(written))

    def _show(self, c: cmd.Show, line: str) -> None:
        if c.plot is not None and c.what != "terms":
            raise LessonError(f"`show {c.what}` has no plot", hint="`show terms plot FILE`")
        if c.what == "rules":
            self.out(self.describe_rules())
        elif c.what == "terms":
            if c.plot is not None:      # the name given, not the first one made from it
                from ..draw.output import check_format
                from ..fileio import check_writable

                with _drawing():        # (and before the table, which said it all first)
                    check_format(c.plot)
                    _check_below(c.plot, self.confined, "terms.png")
                    check_writable(c.plot)
            self.out(text.terms_table(self.original, self.rulebase, self._shownvariables()))
            if c.plot is not None:
                self._plot_terms(self.original, self.rulebase, c.plot)
        elif c.what == "examples":
            self.out(self.describe_examples())
        elif c.what == "behaviors":
            self.out(self.describe_behaviors())
        else:
            self.out(self.describe_history())

    def _shownvariables(self) -> list[str]:
        try:
            c = self.compiled()
            return list(c.inputs) + list(c.outputs)
        except MitosError:
            return list(self.rulebase.variables)

    def _undo(self, c: cmd.Undo, line: str) -> None:
        active = self.journal.active()
        if not active:
            raise LessonError("nothing to undo")
        last = active[-1]
        self.journal.append("undo", of=last["seq"], line=line)
        self.replay(checked=False)
        self.out(f"undone: {text.one_line(last.get('line') or '') or last['op']}")

    def _save(self, c: cmd.Save, line: str) -> None:
        from .save import save_rulebase

        # `save ~/taught.rules` at the prompt, where no shell expands the `~`
        target = Path(c.path).expanduser() if c.path is not None else self.save_as
        if target is None:
            from ..resources import packaged_name

            packaged = packaged_name(str(self.rules_path))
            raise LessonError("say where to save: `save taught.rules`",
                              hint=f"the original {self.rules_path} is kept unless you name "
                                   f"it (`save {self.rules_path}`)" if packaged is None else
                              f"the session teaches the packaged {packaged} (the one every "
                              f"command reads when none is named): save a copy of your own")
        if self.state.block is not None:
            raise LessonError(f"behavior `{self.state.block}` is still open",
                              hint="close it with `end` before saving")
        if c.path is not None:
            _check_below(c.path, self.confined)
        if _is_dir(target):                 # checked before any term set is written beside it
            raise LessonError(f"`{target}` is a directory; save names the rule file to write",
                              hint=f"save {(target / 'taught.rules').as_posix()}")
        over = _same_file(target, self.rules_path)
        # the check and the write hold the directory: another session's save between them was
        # undone by this one without a word (two `mitos teach` saving one file at once)
        with save_lock(target, LessonError):
            if over:
                self._check_unchanged()
            self._check_own_save(target)
            # a Ctrl-C once the files are written waits for what the session knows of them:
            # the next save over them was refused as if another program had changed them
            with held_interrupt():
                saved = save_rulebase(self.original, self.rulebase, target, self.sources,
                                      LESSON_SAVE_HINT if self.confined is not None else None)
                if over:
                    self.files_seen = files_digest(self.original)
                written = (saved.rules,) + saved.termsets
                self.saves_seen[real_path(target)] = (written, _saved_digest(written))
                # the path as it names the file from anywhere: `--resume --session DIR` may
                # run elsewhere, and a bare `save` then wrote a new file there
                entry = self.journal.append("save", path=os.path.abspath(target), line=line,
                                            **({"digest": self.files_seen} if over else {}))
                self.saved_seq = entry["seq"]
                self.save_as = target                  # a later bare `save` goes here too
        files = ", ".join(_named(p) for p in (saved.rules,) + saved.termsets)
        if saved.created is not None:
            self.out(f"created the directory {saved.created}")
        self.out(f"saved {files}" + (f" ({plural(len(saved.changes), 'change')})" if saved.changes
                                     else " (no changes)"))
        for change in saved.changes:
            self.out(f"  {change}")
        self.out(self.interpretability())

    def _check_unchanged(self) -> None:
        """Refuse a save over the original files when another program (or session) changed
        them since this session read or saved them: the save would undo that change."""
        if files_digest(self.original) == self.files_seen:
            return
        raise LessonError(f"{self.rules_path} or its term sets changed since this session read "
                          f"them (another program or session wrote them); saving over them "
                          f"would undo that change",
                          hint="save under another name (`save taught.rules`), or quit and "
                               "`mitos teach --resume`, which applies this session's changes to "
                               "the files as they are now")

    def _check_own_save(self, target: Path) -> None:
        """Refuse a save over files this session saved at ``target`` before when another
        program or session wrote them since (two sessions saving `taught.rules` in turn):
        the save would undo that change."""
        seen = self.saves_seen.get(real_path(target))
        if seen is None or _saved_digest(seen[0]) == seen[1]:
            return
        raise LessonError(f"{target} or its term sets changed since this session saved them "
                          f"there (another program or session wrote them); saving over them "
                          f"would undo that change",
                          hint="save under another name (`save taught2.rules`), or compare "
                               "the two first")

    def interpretability(self) -> str:
        """The interpretability line of `adapt` and `save` (new term gaps marked)."""
        return text.interpretability_text(self.rulebase, self.original)

    def _help(self, c: cmd.Help, line: str) -> None:
        from .help import help_text

        self.out(help_text(c.topic))

    def _quit(self, c: cmd.Quit, line: str) -> bool:
        return False

    # -- descriptions ------------------------------------------------------------------------
    def describe_rules(self) -> str:
        return text.rules_text(self.rulebase.behavior(self.focus), self.original,
                               self.state.block)

    def describe_examples(self) -> str:
        if not self.state.examples:
            return "no examples yet (`correct ...` or `at ...` after `simulate`)"
        lines = []
        try:
            compiled = self.compiled()
            usable = [e for e in self.state.examples if e.behavior == compiled.behavior]
            now = dict(zip(map(id, usable), self._outputs(compiled, [e.inputs for e in usable])))
        except MitosError:
            now = {}
        for i, e in enumerate(self.state.examples, 1):
            where = ", ".join(x for x in (e.behavior, e.source) if x)
            lines.append(f"{i:>3}  {text.example_text(e.inputs, e.targets, now.get(id(e)))}"
                         + (f"   [{where}]" if where else ""))
        return "\n".join(lines)

    def describe_behaviors(self) -> str:
        return text.behaviors_text(self.rulebase, self.state.active, self.state.block)

    def describe_history(self) -> str:
        return text.history_text(self.journal.entries)


# ---- small helpers ---------------------------------------------------------------------------

@contextlib.contextmanager
def _drawing() -> Iterator[None]:
    """A picture a command cannot draw or write (`plot t.txt`, a missing directory) is that
    command's failure, a `command error` (a lesson's `lesson error`) as every other command's:
    it was a bare `error`, the drawing module's word."""
    from ..draw.output import DrawError
    from ..errors import WriteError

    try:
        yield
    except (DrawError, WriteError) as exc:
        raise LessonError(exc.message, span=exc.span, expected=exc.expected,
                          hint=exc.hint) from None


def _not_its(name: str, span: Span | None, role: str, names: tuple[str, ...],
             compiled: CompiledRuleBase) -> LessonError:
    """A name that is not one of the behavior's inputs or outputs: one of the rule base's it
    does not use (`speed` of `follow_route`), else unknown; said alike for `speed=20` and
    `speed is SLOW` (the words said "unknown output variable" of a variable that exists)."""
    known = [v.name for v in compiled.variables.values() if v.role == role]
    if name in known:
        return LessonError(f"behavior `{compiled.behavior}` does not use {role} `{name}`",
                           span=span, expected=f"{role}s " + ", ".join(names))
    error = unknown(f"{role} variable", name, names, span=span, cls=LessonError)
    assert isinstance(error, LessonError)
    other = compiled.variables.get(name)
    if error.hint is None and other is not None:    # an input as a target, or the reverse
        error.hint = (f"`{name}` is an input: a target sets an output ({', '.join(names)}); the "
                      "inputs are given before `->` (in `at`, the run gives them)"
                      if role == "output" else
                      f"`{name}` is an output: it goes after `->`, as a target "
                      f"(`-> {name}=VALUE`)")
    return error


def _reaches(rb: RuleBase, start: str, target: str) -> bool:
    seen, stack = set(), [start]
    while stack:
        name = stack.pop()
        if name == target:
            return True
        if name in seen:
            continue
        seen.add(name)
        stack.extend(u.behavior for u in rb.behavior(name).uses)
    return False


def _nothing_changed(history: list[float], rounded: bool, lower: float | None = None) -> str:
    """Why an ``adapt`` changed nothing: the descent found nothing lower, or what it found
    was lost to the grid learned values are kept to (``history``: Q per epoch, the rounded
    one last when ``rounded``); or its rate was too small, when one epoch at the default rate
    reaches ``lower``."""
    descent = history[:-1] if rounded else history
    if lower is not None:
        return (f"nothing changed: the steps this rate takes are too small to lower Q; one "
                f"epoch at the default rate takes it to {lower:.6g} (`adapt rate "
                f"{DEFAULT_RATE:g}`)")
    if rounded and min(descent) < history[0]:
        return (f"nothing changed: the descent lowered Q to {min(descent):.6g}, but every value "
                f"it moved rounds back to what it was (learned values are kept to a readable "
                f"grid), so Q stays {history[0]:.6g}")
    return "nothing changed: Q cannot go lower from here with these examples"


def _seed(text: str) -> int:
    """A seed exactly as written: digits (``9007199254740993`` is not a float's
    ``9007199254740992``, and ``1e3`` is not a seed)."""
    if not re.fullmatch(r"\+?\d+", text):
        raise LessonError(f"a seed is a whole number written in digits (such as 42), not "
                          f"`{text}`")
    return int(text)


def _whole(value: float, what: str, least: int) -> int:
    if not math.isfinite(value) or value != int(value) or value < least:
        raise LessonError(f"{what} must be a whole number of at least {least}, not {value:g}")
    return int(value)



def _sources(original: RuleBase) -> Sources | None:
    """The texts of ``original``'s files (``None`` for a rule base that has none to keep)."""
    if original.path is None or Path(original.path).suffix.lower() != ".rules":
        return None
    with contextlib.suppress(OSError, UnicodeDecodeError):
        return Sources.read(original)
    return None


def _is_dir(path: Path) -> bool:
    """Whether ``path`` is a directory; a name the system cannot look up (too long) is not
    one (the save's checks say what is wrong with it)."""
    try:
        return path.is_dir()
    except OSError:
        return False


#: where a lesson's `save` that could not be written may go instead (not `~/`: a lesson
#: writes below the working directory only, :func:`_check_below`)
LESSON_SAVE_HINT = ("a lesson saves below the working directory: save where you can write "
                    "there, or give the place with `--save-as PATH`; the session keeps every "
                    "change")


def _check_below(written: str, root: Path | None, example: str = "taught.rules") -> None:
    """Refuse a file a lesson writes (``save``, ``plot``) outside ``root`` (absolute, ``~``, a
    ``..`` or a link that leads out): where a lesson runs (``root`` set), the files it writes
    are the user's to place (``--save-as``, the prompt)."""
    from ..fileio import real_path

    if root is None:
        return
    inside = real_path(root)
    target = real_path(root / written)
    if Path(written).is_absolute() or written.startswith("~") or \
            inside not in target.parents:
        raise LessonError(f"a lesson writes files below the working directory only, and "
                          f"`{written}` lies outside it",
                          expected=f"a relative path such as {example}",
                          hint="a lesson may come from anyone: name the place yourself, with "
                               "`--save-as PATH` or at the prompt")


def _saved_digest(paths: Iterable[Path]) -> str:
    """A digest of the bytes of ``paths`` as they are now (a file missing counts as empty)."""
    import hashlib

    h = hashlib.sha256()
    for path in paths:
        with contextlib.suppress(OSError):
            h.update(Path(path).read_bytes())
        h.update(b"\0")
    return h.hexdigest()[:16]


def _same_file(a: Path, b: Path) -> bool:
    from ..fileio import real_path

    return real_path(a) == real_path(b)


def _killed_save(began: Session, live: str) -> str | None:
    """``live`` when the files are what a save over them of the whole session writes: its
    last command, a save whose files were written and whose journal record a kill cut off
    (its digest is not journaled, and the files were said to be changed by another program,
    the journal applied over them again); else ``None``."""
    from .save import saved_files

    try:
        began.replay(checked=False)
        files, _ = saved_files(began.original, began.rulebase, began.rules_path, began.sources)
    except (MitosError, OSError, KeyError, TypeError, ValueError, AttributeError, IndexError):
        return None
    *terms, (_, rules) = files
    texts = (rules, *(t for _, t in terms))
    if not all(isinstance(t, str) for t in texts):
        return None
    written = Sources(str(texts[0]), tuple(str(t) for t in texts[1:])).digest()
    return live if written == live else None


def _own_digest(entries: list[dict], rules: Path) -> str | None:
    """The digest the original files had when the session last knew them: after its last
    save over them, else when it started."""
    for e in reversed(entries):
        if e["op"] == "save" and isinstance(e.get("digest"), str) \
                and _same_file(Path(e["path"]), rules):
            return e["digest"]
    return entries[0].get("digest") if entries else None


def _then(first: str | None, second: str) -> str:
    """Two hints as one: the inner error's (a "did you mean") before what to do next."""
    if not first:
        return second
    return f"{first.rstrip('.')}; {second}" if not first.endswith("?") else f"{first} {second}"


def _named(path: Path) -> str:
    """A saved file as the prompt names it: relative to the working directory when below it.
    A resumed session's save path is absolute (the journal keeps it so, to save where it did
    from anywhere), and `saved a.rules` read `saved /home/.../a.rules`."""
    try:
        relative = os.path.relpath(os.path.abspath(path))
    except ValueError:                  # (another drive, on Windows)
        return str(path)
    return str(path) if relative.startswith("..") else relative
