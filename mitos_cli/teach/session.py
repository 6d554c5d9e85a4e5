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
``adapt``       learned term parameters and crisp values (with Q before and after)
==============  ==========================================================================
"""

from __future__ import annotations

import dataclasses
import hashlib
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ..lang.resolve import check_expr, check_rule, load_rules_file
from ..engine.compile import CompiledRuleBase, compile_rulebase
from ..errors import LessonError, MitosError, RuleBaseError, unknown
from ..lang.model import And, Behavior, Expr, Not, Prop, Rule, RuleBase, format_expr, \
    format_number, format_rule, format_use
from ..lang.operators import resolve
from ..lang.parse import parse_rule
from ..words import plural
from . import commands as cmd
from .journal import Journal, MemoryJournal


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


# ---- pure state transitions ----------------------------------------------------------------

def _replace_behavior(rb: RuleBase, b: Behavior) -> RuleBase:
    behaviors = tuple(b if x.name == b.name else x for x in rb.behaviors)
    if b.name not in [x.name for x in rb.behaviors]:
        behaviors += (b,)
    return dataclasses.replace(rb, behaviors=behaviors)


def _put_rule(b: Behavior, rule: Rule) -> Behavior:
    rules = list(b.rules)
    for i, r in enumerate(rules):
        if rule.label and r.label == rule.label:
            rules[i] = rule
            break
    else:
        rules.append(rule)
    return dataclasses.replace(b, rules=tuple(rules))


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


def apply(state: State, entry: dict) -> None:
    """Apply one journal entry to ``state`` (no checks: entries were checked when told)."""
    op = entry["op"]
    rb = state.rulebase
    if op == "rule":
        rule = parse_rule(entry["text"])
        state.rulebase = _replace_behavior(rb, _put_rule(rb.behavior(entry["behavior"]), rule))
    elif op == "behavior":
        state.rulebase = _replace_behavior(rb, Behavior(entry["name"]))
        state.block = entry["name"]
    elif op == "end":
        state.block = None
        if entry.get("activate"):
            state.active = entry["activate"]
    elif op == "use":
        b = rb.behavior(entry["behavior"])
        use = cmd.parse_command(entry["text"]).use
        state.rulebase = _replace_behavior(rb, dataclasses.replace(b, uses=b.uses + (use,)))
    elif op == "frozen":
        b = rb.behavior(entry["behavior"])
        labels = b.frozen + tuple(x for x in entry["labels"] if x not in b.frozen)
        state.rulebase = _replace_behavior(rb, dataclasses.replace(b, frozen=labels))
    elif op == "operators":
        b = rb.behavior(entry["behavior"])
        settings = cmd.parse_command(entry["text"]).settings
        state.rulebase = _replace_behavior(rb, dataclasses.replace(
            b, operators=b.operators + settings))
    elif op == "activate":
        state.active = entry["behavior"]
    elif op == "examples":
        state.examples += [Example(e["inputs"], e["targets"], e.get("source", ""),
                                   entry.get("behavior", ""))
                           for e in entry["examples"]]
    elif op == "adapt":
        rb = _set_params(rb, entry["terms"])
        state.rulebase = _set_crisp(rb, entry.get("crisp", []))
    else:                                        # pragma: no cover - journal from the future
        raise LessonError(f"the journal holds an unknown change `{op}`")


# ---- the session ----------------------------------------------------------------------------

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


def files_digest(rb: RuleBase) -> str:
    h = hashlib.sha256()
    for path in [rb.path] + [str(Path(rb.path).parent / p) for p in rb.termset_paths]:
        try:
            h.update(Path(path).read_bytes())
        except OSError:
            pass
    return h.hexdigest()[:16]


class Session:
    """The state of one teaching session and the commands that change it."""

    def __init__(self, rules_path: str | Path, behavior: str | None = None,
                 journal: Journal | None = None, save_as: str | Path | None = None,
                 out: Callable[[str], None] | None = None,
                 progress: Callable | None = None) -> None:
        self.rules_path = Path(rules_path)
        self.original = load_rules_file(self.rules_path)
        self.journal = journal if journal is not None else MemoryJournal()
        self.save_as = Path(save_as) if save_as is not None else None
        self.out = out or print
        self.progress = progress
        self.echo: Callable[[str], None] = lambda text: None     # lessons echo their lines
        active = behavior or self.original.default_behavior
        self.original.behavior(active)              # unknown behavior: did you mean
        self.start_behavior = active
        self.simulation = None
        self.base: Path | None = None       # where a lesson's relative world paths start
        self.saved_seq = 0
        self.state = State(self.original, active)
        if not self.journal.entries:
            self.journal.append("start", rules=str(self.rules_path.resolve()),
                                behavior=active, digest=files_digest(self.original),
                                save_as=None if self.save_as is None else str(self.save_as))

    # -- resume ------------------------------------------------------------------------------
    @classmethod
    def resume(cls, journal: Journal, out: Callable[[str], None] | None = None,
               progress: Callable | None = None) -> "Session":
        start = journal.entries[0] if journal.entries else None
        if start is None or start.get("op") != "start":
            raise LessonError(f"{journal.path}: not a teaching journal (no start entry)")
        session = cls(start["rules"], start["behavior"], journal, start.get("save_as"), out,
                      progress)
        if files_digest(session.original) != start.get("digest"):
            session.out(f"warning: {start['rules']} or its term set changed since the session "
                        f"started; the journal's changes are applied to the files as they are now")
        session.replay()
        saves = [e["seq"] for e in journal.entries if e["op"] == "save"]
        session.saved_seq = saves[-1] if saves else 0
        return session

    def replay(self) -> None:
        self.state = State(self.original, self.start_behavior)
        for entry in self.journal.active():
            apply(self.state, entry)

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
        changes = [e["seq"] for e in self.journal.entries
                   if e["op"] not in ("start", "save")]
        return bool(changes) and changes[-1] > self.saved_seq

    def compiled(self, behavior: str | None = None) -> CompiledRuleBase:
        name = behavior or self.state.active
        b = self.rulebase.behavior(name)
        if not b.rules and not b.uses:
            raise LessonError(f"behavior `{name}` has no rules yet",
                              hint="tell it a rule, or `use` another behavior")
        return compile_rulebase(self.rulebase, name)

    def change(self, op: str, line: str, **data) -> dict:
        """Journal a change (durably), then apply it."""
        entry = self.journal.append(op, line=line, **data)
        apply(self.state, entry)
        return entry

    # -- commands ------------------------------------------------------------------------------
    def run(self, line: str, path: str | None = None, lineno: int = 1) -> bool:
        """Parse and execute one line; False after ``quit``."""
        command = cmd.parse_command(line, path, lineno)
        return self.execute(command, line.strip())

    def execute(self, c, line: str = "") -> bool:
        handler = getattr(self, "_" + type(c).__name__.lower())
        return handler(c, line) is not False

    def _tellrule(self, c: cmd.TellRule, line: str) -> None:
        rule = c.rule
        check_rule(rule, self.rulebase.variables)
        b = self.rulebase.behavior(self.focus)
        if not rule.label:
            rule = dataclasses.replace(rule, label=_next_label(b))
        before = next((r for r in b.rules if r.label == rule.label), None)
        self.change("rule", line, behavior=b.name, text=format_rule(rule))
        head = f"{format_rule(rule)}"
        if before is None:
            self.out(f"{head}\n  added to {b.name} ({plural(len(b.rules) + 1, 'rule')})")
        else:
            self.out(f"{head}\n  replaces {format_rule(before)}")
        b = self.rulebase.behavior(b.name)
        key = _canonical(rule.antecedent)
        for other in b.rules:
            if other.label != rule.label and _canonical(other.antecedent) == key:
                if _consequents(other) != _consequents(rule):
                    self.out(f"  conflict: {other.label} has the same condition but says "
                             f"{', '.join(_say(x) for x in other.consequents)}")
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
            raise unknown("behavior", use.behavior, names, span=use.span)
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
        b = self.rulebase.behavior(self.focus)
        labels = [r.label for r in b.rules]
        for label in c.labels:
            if label not in labels:
                raise unknown(f"rule label in behavior `{b.name}`", label, labels)
        self.change("frozen", line, behavior=b.name, labels=list(c.labels))
        self.out(f"{b.name}: adaptation leaves the consequents of {', '.join(c.labels)} alone")

    def _telloperators(self, c: cmd.TellOperators, line: str) -> None:
        b = self.rulebase.behavior(self.focus)
        resolve(c.settings, resolve(b.operators, resolve(self.rulebase.operators)))
        text = "operators: " + ", ".join(f"{s.key} = {s.value}" for s in c.settings)
        self.change("operators", line, behavior=b.name, text=text)
        self.out(f"{b.name}: {text}")

    def _values(self, given: tuple[cmd.Assign, ...], names: tuple[str, ...], role: str,
                compiled: CompiledRuleBase, require_all: bool) -> dict:
        out = {}
        for a in given:
            if a.name not in names:
                known = [v.name for v in compiled.variables.values() if v.role == role]
                if a.name in known:
                    raise LessonError(f"behavior `{compiled.behavior}` does not use "
                                      f"{role} `{a.name}`", span=a.span,
                                      expected=f"{role}s " + ", ".join(names))
                raise unknown(f"{role} variable", a.name, names, span=a.span, cls=LessonError)
            if a.name in out:
                raise LessonError(f"`{a.name}` is given twice", span=a.span)
            if role == "output":
                lo, hi = compiled.variables[a.name].universe
                if not lo <= a.value <= hi:
                    raise LessonError(f"{a.name} = {a.value:g} lies outside its universe "
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
        self.out(trace_of(evaluate(compiled, as_batch(compiled, values))).render())

    def _correct(self, c: cmd.Correct, line: str) -> None:
        compiled = self.compiled()
        inputs = self._values(c.inputs, compiled.inputs, "input", compiled, True)
        targets = self._values(c.targets, compiled.outputs, "output", compiled, False)
        now = self._outputs(compiled, [inputs])[0]
        self.change("examples", line, behavior=compiled.behavior,
                    examples=[{"inputs": inputs, "targets": targets, "source": "correct"}])
        self.out(f"example {len(self.state.examples)}: " + _example_text(inputs, targets, now))

    def _outputs(self, compiled: CompiledRuleBase, inputs: list[dict]) -> list[dict]:
        from ..engine.evaluation import evaluate

        X = np.array([[x[k] for k in compiled.inputs] for x in inputs], dtype=float)
        y = evaluate(compiled, X, detail=False).outputs
        return [dict(zip(compiled.outputs, map(float, row))) for row in y]

    def _simulate(self, c: cmd.Simulate, line: str) -> None:
        from .simulation import run_world

        seed = _whole(c.seed, "seed", 0) if c.seed is not None else None
        self.compiled()
        self.simulation = run_world(c.world, self.rulebase, self.state.active, seed, self.base)
        self.out(self.simulation.describe())

    def _at(self, c: cmd.At, line: str) -> None:
        if self.simulation is None:
            raise LessonError("no simulation to correct yet",
                              hint="run `simulate WORLD` first, then `at 12.5s steering=55`")
        compiled = self.compiled()
        rows = self.simulation.rows(c.start, c.stop)
        targets = self._values(c.targets, compiled.outputs, "output", compiled, False)
        inputs = [self.simulation.inputs_at(i, compiled.inputs) for i in rows]
        now = self._outputs(compiled, inputs)
        when = self.simulation.when(rows)
        examples = [{"inputs": x, "targets": targets, "source": f"{self.simulation.name} "
                     f"t={self.simulation.time(i):g}s"} for x, i in zip(inputs, rows)]
        self.change("examples", line, behavior=compiled.behavior, examples=examples)
        first = len(self.state.examples) - len(examples) + 1
        self.out(f"{plural(len(examples), 'example')} from "
                 f"{self.simulation.name} {when} (#{first}"
                 + (f"-{len(self.state.examples)}" if len(examples) > 1 else "") + "):")
        for x, y in list(zip(inputs, now))[:5]:
            self.out("  " + _example_text(x, targets, y))
        if len(examples) > 5:
            self.out(f"  ... ({len(examples) - 5} more: `show examples`)")

    def training_set(self, compiled: CompiledRuleBase) -> tuple[np.ndarray, np.ndarray]:
        """``X[n, k]`` and targets ``[n, m]`` (NaN: not given) from the usable examples."""
        usable = [e for e in self.state.examples if e.behavior == compiled.behavior]
        if not usable:
            others = sorted({e.behavior for e in self.state.examples})
            hint = (f"the examples given so far correct {', '.join(others)}: `use "
                    f"{others[0]}` to adapt it" if others else
                    "give corrections: `correct road=78 size=45 position=4 -> steering=60`, "
                    "or `simulate WORLD` then `at 12.5s steering=55`")
            raise LessonError(f"no examples for behavior `{compiled.behavior}` to learn from",
                              hint=hint)
        X = np.array([[e.inputs[k] for k in compiled.inputs] for e in usable], dtype=float)
        T = np.array([[e.targets.get(o, np.nan) for o in compiled.outputs] for e in usable],
                     dtype=float)
        return X, T

    def _adapt(self, c: cmd.Adapt, line: str) -> None:
        from .adapt import adapt, learned_rulebase, parameterise

        epochs = _whole(c.epochs, "epochs", 1) if c.epochs is not None else 50
        rate = 0.5 if c.rate is None else c.rate
        compiled = self.compiled()
        X, T = self.training_set(compiled)
        params = parameterise(compiled)
        if params.n_free == 0:
            raise LessonError(f"nothing in behavior `{compiled.behavior}` may be adapted",
                              hint="every term and consequent it uses is frozen")
        if c.plot is not None:
            from ..draw.output import check_format

            check_format(c.plot)
        progress = self.progress(epochs) if self.progress else None
        try:
            result = adapt(compiled, X, T, epochs=epochs, rate=rate, parameters=params,
                           on_epoch=(progress.update if progress else None))
        finally:
            if progress:
                progress.close()
        before_rb = self.rulebase
        after = learned_rulebase(result.parameters, result.values)
        terms = {}
        for v_old, v_new in zip(_variables(before_rb), _variables(after)):
            for t_old, t_new in zip(v_old.terms, v_new.terms):
                if t_old.params != t_new.params:
                    terms.setdefault(v_new.name, {})[t_new.name] = list(t_new.params)
        crisp = []
        for b_old, b_new in zip(before_rb.behaviors, after.behaviors):
            for i, (r_old, r_new) in enumerate(zip(b_old.rules, b_new.rules)):
                for c_old, c_new in zip(r_old.consequents, r_new.consequents):
                    if c_old.value != c_new.value:
                        crisp.append([b_new.name, i, c_new.var, c_new.value])
        history = [float(q) for q in result.history]
        self.out(_q_lines(history, len(X), result))
        if not terms and not crisp:
            self.out("nothing changed: Q cannot go lower from here with these examples")
            return
        self.change("adapt", line, behavior=compiled.behavior, terms=terms, crisp=crisp,
                    q=[history[0], history[-1]], epochs=epochs, rate=rate)
        self.out(changed_table(before_rb, self.rulebase, crisp))
        if result.parameters.frozen_reasons:
            self.out("not adapted: " + "; ".join(result.parameters.frozen_reasons))
        if c.plot is not None:
            self._plot_terms(before_rb, self.rulebase, c.plot)

    def _plot_terms(self, before: RuleBase, after: RuleBase, path: str) -> None:
        try:
            from ..draw.terms import draw_terms_before_after
        except ImportError:                          # pragma: no cover - optional module
            raise LessonError("plots need the drawing module (mitos_cli.draw)") from None
        changed = [(a, b) for a, b in zip(_variables(before), _variables(after))
                   if a.terms != b.terms]
        if not changed:
            raise LessonError("no term has changed yet, so there is nothing to compare",
                              hint="`adapt` first, or `show terms` for the numbers")
        target = Path(path)
        written = []
        for old, new in changed:
            dest = target if len(changed) == 1 else \
                target.with_name(f"{target.stem}-{new.name}{target.suffix}")
            draw_terms_before_after(old, new, dest)
            written.append(str(dest))
        self.out("plotted " + ", ".join(written))

    def _show(self, c: cmd.Show, line: str) -> None:
        if c.plot is not None and c.what != "terms":
            raise LessonError(f"`show {c.what}` has no plot", hint="`show terms plot FILE`")
        if c.what == "rules":
            self.out(self.describe_rules())
        elif c.what == "terms":
            self.out(terms_table(self.original, self.rulebase, self._shown_variables()))
            if c.plot is not None:
                self._plot_terms(self.original, self.rulebase, c.plot)
        elif c.what == "examples":
            self.out(self.describe_examples())
        elif c.what == "behaviors":
            self.out(self.describe_behaviors())
        else:
            self.out(self.describe_history())

    def _shown_variables(self) -> list[str]:
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
        self.replay()
        self.out(f"undone: {last.get('line') or last['op']}")

    def _save(self, c: cmd.Save, line: str) -> None:
        from .save import save_rulebase

        target = Path(c.path) if c.path is not None else self.save_as
        if target is None:
            raise LessonError("say where to save: `save taught.rules`",
                              hint=f"the original {self.rules_path} is kept unless you name "
                                   f"it (`save {self.rules_path}`)")
        if self.state.block is not None:
            raise LessonError(f"behavior `{self.state.block}` is still open",
                              hint="close it with `end` before saving")
        if target.is_dir():                 # checked before any term set is written beside it
            raise LessonError(f"`{target}` is a directory; save names the rule file to write",
                              hint=f"save {(target / 'taught.rules').as_posix()}")
        saved = save_rulebase(self.original, self.rulebase, target)
        entry = self.journal.append("save", path=str(target), line=line)
        self.saved_seq = entry["seq"]
        files = ", ".join(str(p) for p in (saved.rules,) + saved.termsets)
        self.out(f"saved {files}" + (f" ({plural(len(saved.changes), 'change')})" if saved.changes
                                     else " (no changes)"))
        for change in saved.changes:
            self.out(f"  {change}")

    def _help(self, c: cmd.Help, line: str) -> None:
        from .help import help_text

        self.out(help_text(c.topic))

    def _quit(self, c: cmd.Quit, line: str) -> bool:
        return False

    # -- descriptions ------------------------------------------------------------------------
    def describe_rules(self) -> str:
        b = self.rulebase.behavior(self.focus)
        old = {}
        try:
            old = {r.label: r for r in self.original.behavior(b.name).rules}
        except MitosError:
            pass
        lines = [f"behavior {b.name} ({plural(len(b.rules), 'rule')})"
                 + ("  [open]" if self.state.block == b.name else "")]
        for r in b.rules:
            mark = "" if old.get(r.label) == r else ("  (new)" if r.label not in old
                                                        else "  (changed)")
            frozen = "  [frozen]" if r.label in b.frozen else ""
            lines.append(f"  {format_rule(r)}{frozen}{mark}")
        lines += [f"  {format_use(u)}" for u in b.uses]
        return "\n".join(lines)

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
            lines.append(f"{i:>3}  {_example_text(e.inputs, e.targets, now.get(id(e)))}"
                         + (f"   [{where}]" if where else ""))
        return "\n".join(lines)

    def describe_behaviors(self) -> str:
        lines = []
        for b in self.rulebase.behaviors:
            mark = "*" if b.name == self.state.active else " "
            extra = f", uses {', '.join(u.behavior for u in b.uses)}" if b.uses else ""
            lines.append(f"{mark} {b.name} ({plural(len(b.rules), 'rule')}{extra})"
                         + ("  [open]" if b.name == self.state.block else ""))
        return "\n".join(lines) + "\n(* active: `use NAME` recalls another)"

    def describe_history(self) -> str:
        undone = {e["of"] for e in self.journal.entries if e["op"] == "undo"}
        lines = []
        for e in self.journal.entries:
            if e["op"] == "start":
                lines.append(f"{e['seq']:>4}  started on {e['rules']} ({e['behavior']})")
                continue
            text = e.get("line") or e["op"]
            if e["op"] == "adapt":
                text += f"   (Q {e['q'][0]:.4g} -> {e['q'][1]:.4g})"
            if e["op"] == "save":
                text = f"save {e['path']}"
            mark = "  (undone)" if e["seq"] in undone else ""
            lines.append(f"{e['seq']:>4}  {text}{mark}")
        return "\n".join(lines)


# ---- small helpers ---------------------------------------------------------------------------

def _variables(rb: RuleBase):
    return [v for ts in rb.termsets for v in ts.variables]


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


def _next_label(b: Behavior) -> str:
    numbers = [int(m.group(1)) for r in b.rules if (m := re.fullmatch(r"r(\d+)", r.label))]
    n = max(numbers) + 1 if numbers else len(b.rules) + 1
    labels = {r.label for r in b.rules}
    while f"r{n}" in labels:
        n += 1
    return f"r{n}"


def _say(c) -> str:
    if c.term is None:
        return f"{c.var} is {format_number(c.value)}"
    return f"{c.var} is {' '.join(c.hedges + (c.term,))}"


def _whole(value: float, what: str, least: int) -> int:
    if value != int(value) or value < least:
        raise LessonError(f"{what} must be a whole number of at least {least}, not {value:g}")
    return int(value)


def _num(x: float) -> str:
    return f"{x:.4g}" if abs(x) < 1e4 else f"{x:.6g}"


def _example_text(inputs: dict, targets: dict, now: dict | None) -> str:
    text = " ".join(f"{k}={_num(v)}" for k, v in inputs.items()) + " -> " + \
        " ".join(f"{k}={_num(v)}" for k, v in targets.items())
    if now:
        text += "   (now " + " ".join(f"{k}={_num(now[k])}" for k in targets if k in now) + ")"
    return text


def _q_lines(history: list[float], n: int, result) -> str:
    rounding = history[-1] if result.rounded else None
    if result.rounded:
        history = history[:-1]
    epochs = len(history) - 1
    lines = [f"Q = sum (y - t)^2 over {plural(n, 'example')}:"]
    shown = list(range(len(history)))
    if len(shown) > 22:
        step = max(1, len(shown) // 20)
        shown = sorted(set(shown[::step]) | {len(shown) - 1})
    for i in shown:
        lines.append(f"  epoch {i:>4}: Q = {history[i]:.6g}")
    if rounding is not None:
        lines.append(f"  rounded  : Q = {rounding:.6g}   (learned values to a readable grid)")
        history = history + [rounding]
    note = "converged" if result.converged else ("interrupted" if result.interrupted
                                                 else plural(epochs, 'epoch'))
    lines.append(f"Q {history[0]:.6g} -> {history[-1]:.6g} ({note}; RMS error "
                 f"{(history[-1] / max(n, 1)) ** 0.5:.3g})")
    return "\n".join(lines)


def _params_text(t) -> str:
    return t.params_text(format_number)


def changed_table(before: RuleBase, after: RuleBase, crisp: list) -> str:
    lines = ["changed (before -> after):"]
    for v_old, v_new in zip(_variables(before), _variables(after)):
        for t_old, t_new in zip(v_old.terms, v_new.terms):
            if t_old.params != t_new.params:
                lines.append(f"  {v_new.name}.{t_new.name}: {_params_text(t_old)}  ->  "
                             f"{_params_text(t_new)}")
    for owner, index, var, value in crisp:
        rule = before.behavior(owner).rules[index]
        old = next(c.value for c in rule.consequents if c.var == var)
        lines.append(f"  {owner}/{rule.label}: {var} is {format_number(old)}  ->  "
                     f"{format_number(value)}")
    return "\n".join(lines)


def terms_table(original: RuleBase, current: RuleBase, names: list[str]) -> str:
    old = {v.name: v for v in _variables(original)}
    lines = []
    for v in _variables(current):
        if v.name not in names:
            continue
        lo, hi = v.universe
        lines.append(f"{v.name} ({v.role}, [{format_number(lo)}, {format_number(hi)}]"
                     + (f" {v.unit}" if v.unit else "") + ")")
        for t in v.terms:
            o = old[v.name].term(t.name) if v.name in old else None
            was = f"   (was {_params_text(o)})" if o is not None and o.params != t.params else ""
            frozen = "  [frozen]" if t.frozen else ""
            lines.append(f"  {t.name:<10} {t.shape_name:<14} {_params_text(t)}{frozen}{was}")
    return "\n".join(lines)
