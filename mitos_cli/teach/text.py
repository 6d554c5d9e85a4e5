"""The text a teaching session prints: examples, Q per epoch, changed terms, the rules,
behaviors and history it shows. Pure functions of the state; the session prints them."""

from __future__ import annotations

import contextlib
from typing import TYPE_CHECKING, cast

from ..lang.model import RuleBase, format_number, format_rule, format_use
from ..words import plural
from .state import variables

if TYPE_CHECKING:
    from ..lang.model import Behavior, Consequent
    from ..lang.terms import Term
    from .adapt import Adaptation


def say(c: Consequent) -> str:
    if c.term is None:
        return f"{c.var} is {format_number(cast(float, c.value))}"     # (a crisp value)
    return f"{c.var} is {' '.join(c.hedges + (c.term,))}"



def num(x: float) -> str:
    return f"{x:.4g}" if abs(x) < 1e4 else f"{x:.6g}"


def example_text(inputs: dict, targets: dict, now: dict | None) -> str:
    text = " ".join(f"{k}={num(v)}" for k, v in inputs.items()) + " -> " + \
        " ".join(f"{k}={num(v)}" for k, v in targets.items())
    if now:
        text += "   (now " + " ".join(f"{k}={num(now[k])}" for k in targets if k in now) + ")"
    return text


def q_lines(history: list[float], n: int, result: Adaptation) -> str:
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


def params_text(t: Term) -> str:
    return t.params_text(format_number)


def changed_table(before: RuleBase, after: RuleBase, crisp: list) -> str:
    lines = ["changed (before -> after):"]
    for v_old, v_new in zip(variables(before), variables(after)):
        for t_old, t_new in zip(v_old.terms, v_new.terms):
            if t_old.params != t_new.params:
                lines.append(f"  {v_new.name}.{t_new.name}: {params_text(t_old)}  ->  "
                             f"{params_text(t_new)}")
    for owner, index, var, value in crisp:
        rule = before.behavior(owner).rules[index]
        old = next(c.value for c in rule.consequents if c.var == var)
        lines.append(f"  {owner}/{rule.label}: {var} is {format_number(old)}  ->  "
                     f"{format_number(value)}")
    return "\n".join(lines)


def terms_table(original: RuleBase, current: RuleBase, names: list[str]) -> str:
    old = {v.name: v for v in variables(original)}
    lines = []
    for v in variables(current):
        if v.name not in names:
            continue
        lo, hi = v.universe
        lines.append(f"{v.name} ({v.role}, [{format_number(lo)}, {format_number(hi)}]"
                     + (f" {v.unit}" if v.unit else "") + ")")
        for t in v.terms:
            o = old[v.name].term(t.name) if v.name in old else None
            was = f"   (was {params_text(o)})" if o is not None and o.params != t.params else ""
            frozen = ("  [frozen]" if t.frozen else "") + \
                ("  [held: false]" if not t.held else "" if t.held_at is None else
                 f"  [held at {format_number(t.held_at)}]")
            lines.append(f"  {t.name:<10} {t.shape_name:<14} {params_text(t)}{frozen}{was}")
    return "\n".join(lines)


def rules_text(b: Behavior, original: RuleBase, open_block: str | None) -> str:
    """Behavior ``b``'s rules, new and changed ones (against ``original``) marked."""
    from ..errors import MitosError

    old = {}
    with contextlib.suppress(MitosError):
        old = {r.label: r for r in original.behavior(b.name).rules}
    lines = [f"behavior {b.name} ({plural(len(b.rules), 'rule')})"
             + ("  [open]" if open_block == b.name else "")]
    for r in b.rules:
        mark = "" if old.get(r.label) == r else ("  (new)" if r.label not in old
                                                    else "  (changed)")
        frozen = "  [frozen]" if r.label in b.frozen else ""
        lines.append(f"  {format_rule(r)}{frozen}{mark}")
    lines += [f"  {format_use(u)}" for u in b.uses]
    return "\n".join(lines)


def behaviors_text(rb: RuleBase, active: str, open_block: str | None) -> str:
    lines = []
    for b in rb.behaviors:
        mark = "*" if b.name == active else " "
        extra = f", uses {', '.join(u.behavior for u in b.uses)}" if b.uses else ""
        lines.append(f"{mark} {b.name} ({plural(len(b.rules), 'rule')}{extra})"
                     + ("  [open]" if b.name == open_block else ""))
    return "\n".join(lines) + "\n(* active: `use NAME` recalls another)"


def one_line(command: str) -> str:
    """A command as one line: a rule told over several lines joined by single spaces (its
    next lines stood at the left margin of the history's numbered list)."""
    return " ".join(part.strip() for part in command.splitlines() if part.strip())


def _rule_file(path: str) -> str:
    """The rule file a session started on: the packaged one as every command names it
    (``rulebases/mitos.rules (packaged)``, not where pip put it), any other as recorded."""
    from ..resources import packaged_name

    packaged = packaged_name(path)
    return path if packaged is None else f"{packaged} (packaged)"


def history_text(entries: list[dict]) -> str:
    undone = {e["of"] for e in entries if e["op"] == "undo"}
    lines = []
    for e in entries:
        if e["op"] == "start":
            lines.append(f"{e['seq']:>4}  started on {_rule_file(e['rules'])}, "
                         f"behavior {e['behavior']}")
            continue
        text = one_line(e.get("line") or "") or e["op"]
        if e["op"] == "adapt":
            stopped = e.get("stopped")
            ran = e.get("ran")
            after = (f"; {stopped} after {plural(ran, 'epoch')}"
                     if stopped in ("interrupted", "converged") and isinstance(ran, int) else "")
            text += f"   (Q {e['q'][0]:.4g} -> {e['q'][1]:.4g}{after})"
        if e["op"] == "save":
            text = f"save {e['path']}"
        mark = "  (undone)" if e["seq"] in undone else ""
        lines.append(f"{e['seq']:>4}  {text}{mark}")
    return "\n".join(lines)


def interpretability_text(rb: RuleBase, written: RuleBase | None = None) -> str:
    """What ``mitos check`` says about the terms' meaning, for the prompt: its
    interpretability findings and its term gaps, a gap that ``written`` (the rule base as the
    files wrote it) did not have marked as opened since (adaptation may not open one, but
    `adapt ... unconstrained` may, and `mitos check` would report it)."""
    from ..lang import interpretability as meaning

    lines = [f"  {i.message} ({i.hint})" for i in meaning.rulebase_issues(rb.variables.values())]
    for var in rb.variables.values():
        before = written.variables.get(var.name) if written is not None else None
        old = meaning.term_gaps(before) if before is not None else []
        slack = (var.universe[1] - var.universe[0]) / (meaning.GAP_RESOLUTION - 1)
        for gap in meaning.term_gaps(var):
            new = before is not None and not any(g.left - slack <= gap.left and
                                                 gap.right <= g.right + slack for g in old)
            lines.append(f"  {meaning.gap_message(var, gap)}"
                         + (", a gap the terms as written did not have" if new
                            else "") + f" ({meaning.GAP_HINT})")
    if not lines:
        return "interpretability: terms in order, universes covered, terms distinct, " \
               "centre terms on their points"
    return "\n".join(["interpretability:"] + lines)


def quoted_column(message: str, line: str) -> tuple[int, int]:
    """Where in ``line`` the first name an error message quotes (`` `NARROWW` ``) is written,
    as 1-based columns ``(start, end)``; ``(1, None)``-like ``(1, 0)`` when none is (the caret
    then stands at the start of the line). A name is looked for after the command word
    first: `help help`, `simulate simulate` said the unknown topic or world at the command."""
    import re

    command = re.match(r"\s*\S+", line)
    for name in re.findall(r"`([^`\s]+)`", message):
        for start in (command.end() if command else 0, 0):
            found = re.compile(r"(?<![\w.])" + re.escape(name) + r"(?![\w])").search(line, start)
            if found is None and "." not in name:                                  # `TERM`
                found = re.compile(r"(?<=\.)" + re.escape(name) + r"(?![\w])").search(line, start)
            if found is not None:
                return found.start() + 1, found.end() + 1
    return 1, 0
