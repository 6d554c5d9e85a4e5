"""The state a teaching session rebuilds from its journal, and the pure transitions.

Each change of a session is a journal entry (``{"op": ..., ...}``) applied by :func:`apply`,
a pure state transition with no checks (entries were checked when told), so replaying the
entries not undone over the original files rebuilds the state exactly: that is how ``undo``
and ``mitos teach --resume`` work. The operations are listed in
:mod:`mitos_cli.teach.session`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import hashlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

from ..errors import LessonError
from ..lang.model import Behavior, Rule, RuleBase
from ..lang.parse import parse_rule
from ..lang.terms import Term
from . import commands as cmd

if TYPE_CHECKING:
    from ..lang.terms import Variable

_C = TypeVar("_C")


@dataclass(frozen=True)
class Example:
    """One correction: input values by name and the outputs the instructor wanted."""

    inputs: dict
    targets: dict
    source: str = ""
    behavior: str = ""           # the behavior whose outputs the targets correct


@dataclass
class State:
    """What a replay of the journal rebuilds."""

    rulebase: RuleBase
    active: str
    block: str | None = None
    examples: list[Example] = field(default_factory=list)
    frozen_terms: set = field(default_factory=set)      # (variable, term)
    released: set = field(default_factory=set)          # (variable, term)
    # the rules tuple _put_rule made last and its labels' positions, so that the next rule put
    # into that tuple finds its label without walking every rule (a lesson telling N rules was
    # N^2): one entry, handed on to the new tuple; any other tuple builds its own
    labels: tuple[tuple[Rule, ...], dict[str, int]] = ((), {})


def _replace_behavior(rb: RuleBase, b: Behavior) -> RuleBase:
    behaviors = tuple(b if x.name == b.name else x for x in rb.behaviors)
    if b.name not in [x.name for x in rb.behaviors]:
        behaviors += (b,)
    return dataclasses.replace(rb, behaviors=behaviors)


def _put_rule(state: State, b: Behavior, rule: Rule) -> Behavior:
    """``b`` with ``rule`` in place of the first rule with its label, or added at the end
    (``state.labels`` remembers the labels' positions in the tuple it makes)."""
    rules, positions = state.labels
    if rules is not b.rules:
        positions = {}
        for i, r in enumerate(b.rules):
            positions.setdefault(r.label, i)
    at = positions.get(rule.label) if rule.label else None
    if at is None:
        new = b.rules + (rule,)
        positions.setdefault(rule.label, len(b.rules))
    else:
        new = b.rules[:at] + (rule,) + b.rules[at + 1:]
    state.labels = (new, positions)
    return dataclasses.replace(b, rules=new)


def _set_params(rb: RuleBase, terms: dict) -> RuleBase:
    termsets = tuple(dataclasses.replace(ts, variables=tuple(
        v.with_terms(tuple(t.with_params(tuple(terms[v.name][t.name]))
                           if t.name in terms.get(v.name, {}) else t for t in v.terms))
        for v in ts.variables)) for ts in rb.termsets)
    return dataclasses.replace(rb, termsets=termsets)


def _set_crisp(rb: RuleBase, crisp: list) -> RuleBase:
    for owner, index, var, value in crisp:
        b = rb.behavior(owner)
        rule = b.rules[index]
        cons = tuple(dataclasses.replace(c, value=float(value)) if c.var == var and c.term is None
                     else c for c in rule.consequents)
        rules = list(b.rules)
        rules[index] = dataclasses.replace(rule, consequents=cons)
        rb = _replace_behavior(rb, dataclasses.replace(b, rules=tuple(rules)))
    return rb


@functools.lru_cache(maxsize=4096)
def _told(text: str) -> Rule:
    """A journaled rule's text, parsed once: `undo` replays every change, and parsing each
    rule again was most of its time in a long lesson (a rule is immutable)."""
    return parse_rule(text)


def apply(state: State, entry: dict) -> None:
    """Apply one journal entry to ``state`` (no checks: entries were checked when told)."""
    op = entry["op"]
    rb = state.rulebase
    if op == "rule":
        rule = _told(entry["text"])
        state.rulebase = _replace_behavior(rb, _put_rule(state, rb.behavior(entry["behavior"]),
                                                         rule))
    elif op == "behavior":
        state.rulebase = _replace_behavior(rb, Behavior(entry["name"]))
        state.block = entry["name"]
    elif op == "end":
        state.block = None
        if entry.get("activate"):
            state.active = entry["activate"]
    elif op == "use":
        b = rb.behavior(entry["behavior"])
        use = journaled(entry, cmd.TellUse).use
        state.rulebase = _replace_behavior(rb, dataclasses.replace(b, uses=b.uses + (use,)))
    elif op == "frozen":
        b = rb.behavior(entry["behavior"])
        labels = b.frozen + tuple(x for x in entry["labels"] if x not in b.frozen)
        state.rulebase = _replace_behavior(rb, dataclasses.replace(b, frozen=labels))
    elif op == "operators":
        b = rb.behavior(entry["behavior"])
        settings = journaled(entry, cmd.TellOperators).settings
        state.rulebase = _replace_behavior(rb, dataclasses.replace(
            b, operators=b.operators + settings))
    elif op == "activate":
        state.active = entry["behavior"]
    elif op == "examples":
        state.examples += [Example(e["inputs"], e["targets"], e.get("source", ""),
                                   entry.get("behavior", ""))
                           for e in entry["examples"]]
    elif op == "freeze":
        for var, term in entry["terms"]:
            state.frozen_terms.add((var, term))
            state.released.discard((var, term))
        state.rulebase = _set_flags(state.rulebase, entry["terms"], frozen=True)
    elif op == "release":
        for var, term in entry["terms"]:
            state.frozen_terms.discard((var, term))
            state.released.add((var, term))
        state.rulebase = _set_flags(state.rulebase, entry["terms"], frozen=False)
        state.rulebase = _set_flags(state.rulebase, entry.get("holds", []), held=False)
    elif op == "adapt":
        learned = _set_params(rb, entry["terms"])
        state.rulebase = _keep_holds(rb, _set_crisp(learned, entry.get("crisp", [])))
    else:                                        # pragma: no cover - journal from the future
        raise LessonError(f"the journal holds an unknown change `{op}`")




def _keep_holds(before: RuleBase, after: RuleBase) -> RuleBase:
    """``after`` with each centre term held in ``before`` (by the symmetry of its neighbours)
    written with its point (``held_at``) where ``after``'s terms are no longer symmetric
    about it: the hold outlives the symmetry adaptation moved, in the next ``adapt`` and in
    the saved files (``held: 90``), and ``mitos check`` can tell it moved."""
    from ..lang.interpretability import TOLERANCE, held_term

    pinned: dict[tuple[str, str], float] = {}
    for old, new in zip(variables(before), variables(after)):
        held = held_term(old)
        if held is None or not held[0].held or held[0].held_at is not None:
            continue
        still = held_term(new)
        tol = TOLERANCE * (old.universe[1] - old.universe[0])
        if still is None or still[0].name != held[0].name or abs(still[1] - held[1]) > tol:
            pinned[(old.name, held[0].name)] = float(held[1])
    if not pinned:
        return after
    termsets = tuple(dataclasses.replace(ts, variables=tuple(
        v.with_terms(tuple(dataclasses.replace(t, held_at=pinned[(v.name, t.name)])
                           if (v.name, t.name) in pinned else t for t in v.terms))
        for v in ts.variables)) for ts in after.termsets)
    return dataclasses.replace(after, termsets=termsets)


def _set_flags(rb: RuleBase, refs: list, frozen: bool | None = None,
               held: bool | None = None) -> RuleBase:
    """The rule base with the terms ``refs`` ([variable, term] pairs) frozen or not, held at
    their point or not (``None``: as they are): the flags are part of the model, so ``save``
    writes them (``frozen: true``, ``held: false`` in the YAML)."""
    names = {tuple(r) for r in refs}

    def flagged(t: Term) -> Term:
        return dataclasses.replace(t, frozen=t.frozen if frozen is None else frozen,
                                   held=t.held if held is None else held)

    termsets = tuple(dataclasses.replace(ts, variables=tuple(
        v.with_terms(tuple(flagged(t) if (v.name, t.name) in names else t for t in v.terms))
        for v in ts.variables)) for ts in rb.termsets)
    return dataclasses.replace(rb, termsets=termsets)


def learned_changes(before: RuleBase, after: RuleBase) -> tuple[dict, list]:
    """What an adaptation changed, as its journal entry keeps it: new term parameters
    ``{variable: {term: params}}`` and crisp consequents ``[behavior, rule index, output,
    value]``."""
    terms: dict = {}
    for v_old, v_new in zip(variables(before), variables(after)):
        for t_old, t_new in zip(v_old.terms, v_new.terms):
            if t_old.params != t_new.params:
                terms.setdefault(v_new.name, {})[t_new.name] = list(t_new.params)
    crisp = []
    for b_old, b_new in zip(before.behaviors, after.behaviors):
        for i, (r_old, r_new) in enumerate(zip(b_old.rules, b_new.rules)):
            for c_old, c_new in zip(r_old.consequents, r_new.consequents):
                if c_old.value != c_new.value:
                    crisp.append([b_new.name, i, c_new.var, c_new.value])
    return terms, crisp


def journaled(entry: dict, kind: type[_C]) -> _C:
    """The command a journal entry recorded, which must be of the entry's kind."""
    parsed = cmd.parse_command(entry["text"])
    if not isinstance(parsed, kind):
        raise LessonError(f"the journal's `{entry['op']}` change holds `{entry['text']}`")
    return parsed


def variables(rb: RuleBase) -> list[Variable]:
    """Every variable of every term set, in file order."""
    return [v for ts in rb.termsets for v in ts.variables]


def files_digest(rb: RuleBase) -> str:
    h = hashlib.sha256()
    if rb.path is None:                    # a rule base from text has no files
        return h.hexdigest()[:16]
    for path in [rb.path] + [str(Path(rb.path).parent / p) for p in rb.termset_paths]:
        with contextlib.suppress(OSError):
            h.update(Path(path).read_bytes())
    return h.hexdigest()[:16]

