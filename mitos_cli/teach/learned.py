"""What adaptation learned, said in the instructor's terms.

One line per term that moved, by its centre (a crisp term's value, a fuzzy set's peak or core
middle): ``steering.LS: 70 -> 62 deg, toward LM``; a term held at its point of symmetry says
so (``steering.ST: unchanged (held at 90)``; ``heading.AHEAD: held at 0, its slopes moved
with its neighbours`` when its feet, shared with its neighbours' peaks, moved). A term whose
centre moved more than :data:`MEANING_SHIFT` of the way to its written neighbour on that side
is flagged: it now means something close to that neighbour; one that went past where the
neighbour was written says so (``out.MID: 30 -> 42.5, past HI (written at 40) ...``).

The numbers are the terms' own as ``changed (before -> after)`` prints them (adaptation rounds
them to a readable grid): ``130 -> 130.87``, never ``130.9`` beside a table that says 130.87,
and never ``110 -> 110`` for a move to 109.97.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from ..lang.interpretability import centre
from ..lang.model import RuleBase, format_number

if TYPE_CHECKING:
    from .adapt import Parameters

#: Share of the distance to the next term beyond which a move "changes the meaning".
MEANING_SHIFT = 0.5


def _num(x: float) -> str:
    """As the table of changes writes a number (``format_number``), without the noise of the
    core's middle (``0.5 * (b + c)``) in its last bits."""
    return format_number(round(x, 9) + 0.0)          # + 0.0: -0.0 reads as 0


def _moved(a: float, b: float) -> tuple[str, str]:
    """``a`` and ``b`` said so that they differ when they do (a move smaller than the noise
    :func:`_num` drops is written out in full)."""
    before, after = _num(a), _num(b)
    return (before, after) if before != after or a == b else (repr(a), repr(b))


def in_words(before: RuleBase, after: RuleBase, parameters: Parameters, rules: Sequence[str] = ()) -> str:
    """The learned changes of ``before`` -> ``after`` in words (``parameters``: what was
    adapted and what was held; ``rules``: the labels of rules whose own crisp values were
    learned, so that "no term moved" does not read as "nothing was learned")."""
    held = {(v, t): point for v, t, point in parameters.held}
    adapted = {k.var for k in parameters.knots}
    lines = ["learned, in words:"]
    old_vars = before.variables
    for name, new in after.variables.items():
        old = old_vars.get(name)
        if old is None or name not in adapted:
            continue
        unit = f" {new.unit}" if new.unit else ""
        order = sorted(old.terms, key=centre)
        if old.terms == new.terms:
            continue
        for t_old, t_new in zip(old.terms, new.terms):
            key = (name, t_new.name)
            if key in held:
                moved = "" if t_old.params == t_new.params else \
                    ", its slopes moved with its neighbours"
                lines.append(f"  {name}.{t_new.name}: "
                             + (f"held at {_num(held[key])}{unit}{moved}" if moved else
                                f"unchanged (held at {_num(held[key])}{unit})"))
                continue
            a, b = centre(t_old), centre(t_new)
            if t_old.params == t_new.params:
                continue
            if a == b:
                lines.append(f"  {name}.{t_new.name}: centre unchanged at {_num(a)}{unit}, "
                             f"its slopes moved")
                continue
            i = order.index(t_old)
            j = i + (1 if b > a else -1)
            before_, after_ = _moved(a, b)
            text = f"  {name}.{t_new.name}: {before_} -> {after_}{unit}"
            if 0 <= j < len(order):
                text += _toward(a, b, order[j].name, centre(order[j]), unit)
            elif 0 <= 2 * i - j < len(order):      # an end term moved out: from its neighbour
                text += f", away from {order[2 * i - j].name}"
            lines.append(text)
    if len(lines) == 1:
        lines.append("  no term moved" + (f"; only {_written_in(rules)} did (the table above)"
                                          if rules else ""))
    elif any("held at" in x for x in lines):
        lines.append("  (a held term is the centre of mirror-symmetric terms; `unfrozen "
                     "VARIABLE.TERM` lets it move)")
    return "\n".join(lines)


def _written_in(rules: Sequence[str]) -> str:
    """``the crisp value written in rule `r1```, ``the crisp values written in rules `r1`,
    `r2` and `r3``` (each rule once, in order)."""
    names = [f"`{r}`" for r in dict.fromkeys(rules)]
    values = "values" if len(rules) > 1 else "value"
    if len(names) == 1:
        return f"the crisp {values} written in rule {names[0]}"
    return f"the crisp values written in rules {', '.join(names[:-1])} and {names[-1]}"


def _toward(a: float, b: float, neighbour: str, there: float, unit: str) -> str:
    """Which way a centre moved from ``a`` to ``b``: toward the ``neighbour`` written at
    ``there`` (flagged past :data:`MEANING_SHIFT` of the way), or past it."""
    share = abs(b - a) / max(abs(there - a), 1e-12)
    if share > 1.0:
        return (f", past {neighbour} (written at {_num(there)}{unit}: it now lies beyond what "
                f"{neighbour} meant)")
    if share == 1.0:
        return f", onto {neighbour} (it now means what {neighbour} meant)"
    text = f", toward {neighbour}"
    if share > MEANING_SHIFT:
        text += f" ({share:.0%} of the way: it now means nearly what {neighbour} meant)"
    return text
