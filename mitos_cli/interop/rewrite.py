"""fuzzylite's chained engines restated exactly in MITOS's model, so the engine needs no new step.

In fuzzylite a condition on an *output* (``if Power is LOW then InversePower is HIGH``) does
not test a defuzzified value: it is the aggregated activation of that output's term so far,
i.e. of the rules before it (in rule order) that conclude ``Power is LOW``, joined by the
output's aggregation. :func:`unchain` writes the condition as the disjunction of those rules'
conditions. Exact when the disjunction is the aggregation (or one rule concludes the term)
and those rules have weight 1 and no hedge. A hedge on the chained condition is moved onto
the propositions when the norms are min and max: for a non-decreasing hedge ``h``,
``h(max(a, b)) = max(h(a), h(b))`` bit for bit (max returns one of its arguments).

Anything outside those conditions is refused by name, at the rule.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..errors import FormatError
from ..lang.model import And, Expr, Not, Or, Prop, Rule
from ..lang.parse import MAX_NESTING

if TYPE_CHECKING:
    from collections.abc import Iterator

#: how many propositions the chained conditions of one rule block may hold, written out. Each
#: tested output becomes the conditions of the rules that set it, which may test outputs in
#: turn: a file of 30 rules each testing the previous output twice is 2^30 propositions (a
#: few KB that took minutes, then hours, to read). A million took 24 s to evaluate once and
#: 136 s to convert (written out, then read back and compared); 100,000 take 1 s and 9 s.
MAX_WRITTEN = 100_000


def push_hedges(expr: Expr, hedges: tuple[str, ...], and_: str, or_: str, rule: Rule,
                why: str) -> Expr:
    """``hedges`` applied to the value of ``expr``, written on its propositions."""
    if not hedges:
        return expr
    if isinstance(expr, Prop):
        if expr.negated:
            raise FormatError(f"rule `{rule.label}`: {why} over `not` cannot be written as a "
                              f"MITOS condition", span=rule.span)
        return Prop(expr.var, expr.term, hedges + expr.hedges, False, expr.span)
    if isinstance(expr, Not):
        raise FormatError(f"rule `{rule.label}`: {why} over `not (...)` cannot be written as "
                          f"a MITOS condition", span=rule.span)
    norm = and_ if isinstance(expr, And) else or_
    if len(expr.items) > 1 and norm not in ("min", "max"):
        raise FormatError(f"rule `{rule.label}`: {why} needs the rule's "
                          f"{'and' if isinstance(expr, And) else 'or'} to be min or max "
                          f"(here `{norm}`), whose hedged value is the value of its hedged "
                          f"operands", span=rule.span)
    return type(expr)(tuple(push_hedges(i, hedges, and_, or_, rule, why) for i in expr.items),
                      expr.span)


def unchain(rules: list[Rule], outputs: set[str], and_: str, or_: str,
            aggregation: str | None, notes: list[str]) -> list[Rule]:
    """Rules whose conditions test outputs, rewritten to test the conditions of the earlier
    rules that set those outputs' terms (fuzzylite's chained engines)."""
    sources: dict[tuple[str, str], list[Expr]] = {}
    out: list[Rule] = []
    chained = 0
    # the variables any rule tests, once (looked up for each weighted consequent, it made
    # reading quadratic in the rules: 8,000 FCL rules WITH a weight took two minutes)
    tested = {p.var for r in rules for p in _props(r.antecedent)}
    sizes: dict[int, tuple[Expr, int, int]] = {}
    written = 0

    def charge(joined: Expr, rule: Rule, at: Prop) -> None:
        """Count ``joined``'s propositions against :data:`MAX_WRITTEN` before it is used."""
        nonlocal written
        written += _size(joined, sizes)[1]
        if written > MAX_WRITTEN:
            raise FormatError(
                f"rule `{rule.label}` tests `{at.var} is {at.term}`: written out, the chained "
                f"conditions of this rule block would hold more than {MAX_WRITTEN:,} "
                f"propositions", span=at.span or rule.span,
                hint="MITOS restates each tested output as the conditions of the rules that "
                     "set it; a chain that tests each output more than once doubles at each "
                     "step: test each output once, or give the condition its own input")

    def expand(expr: Expr, rule: Rule) -> Expr:
        if isinstance(expr, Prop):
            if expr.var not in outputs:
                return expr
            joined = _setters(expr, rule, sources.get((expr.var, expr.term), []), aggregation,
                              or_)
            charge(joined, rule, expr)
            hedged = push_hedges(joined, expr.hedges, and_, or_, rule,
                                 "a hedge on a chained output")
            return Not(hedged, expr.span) if expr.negated else hedged
        if isinstance(expr, Not):
            return Not(expand(expr.expr, rule), expr.span)
        return type(expr)(tuple(expand(i, rule) for i in expr.items), expr.span)

    for rule in rules:
        antecedent = expand(rule.antecedent, rule)
        if antecedent != rule.antecedent:
            chained += 1
            _check_nesting(rule, _size(antecedent, sizes)[0])
            rule = Rule(rule.label, antecedent, rule.consequents, rule.weight, rule.span)
        for c in rule.consequents:
            if c.term is None or c.var not in outputs:
                continue
            if (rule.weight != 1.0 or c.hedges) and c.var in tested:
                raise FormatError(f"rule `{rule.label}` sets the chained output `{c.var}` "
                                  f"with a weight or hedge, which the rules testing it would "
                                  f"see: not supported", span=c.span or rule.span)
            sources.setdefault((c.var, c.term), []).append(antecedent)
        out.append(rule)
    if chained:
        notes.append(f"{rules[0].span.path if rules[0].span else '<input>'}: {chained} rules "
                     f"test outputs (a chained engine): each such condition is read as the "
                     f"conditions of the earlier rules that set that term, which is what "
                     f"fuzzylite computes")
    return out


def _setters(expr: Prop, rule: Rule, found: list[Expr], aggregation: str | None,
             or_: str) -> Expr:
    """The conditions ``found`` of the earlier rules that set the output term ``expr`` tests,
    joined by the rule block's disjunction, which is what fuzzylite's aggregation computes
    only when the two are the same (or one rule sets it); refused otherwise, and when no
    rule before sets it (fuzzylite reads 0 there, which is surely not what was meant)."""
    if not found:
        raise FormatError(f"rule `{rule.label}` tests `{expr.var} is {expr.term}`, "
                          f"which no rule before it sets (always 0 in fuzzylite)",
                          span=expr.span or rule.span,
                          hint="move the rules that set it before this one")
    if len(found) > 1 and aggregation != or_:
        raise FormatError(
            f"rule `{rule.label}` tests the output `{expr.var}`, which aggregates "
            f"{len(found)} rules with `{aggregation or 'sum'}`; MITOS "
            f"can restate that only when the rule block's disjunction is the same "
            f"(here `{or_}`)", span=expr.span or rule.span)
    return found[0] if len(found) == 1 else Or(tuple(found), expr.span)


def _check_nesting(rule: Rule, depth: int) -> None:
    """Refuse a rewritten condition nested ``depth`` deep past :data:`MAX_NESTING`: the rule
    language reads no deeper, and every later pass walks conditions recursively."""
    if depth > MAX_NESTING:
        raise FormatError(
            f"rule `{rule.label}` tests chained outputs: written out, its condition "
            f"nests {depth} deep, more than {MAX_NESTING}", span=rule.span,
            hint="MITOS restates each tested output as the conditions of the rules "
                 "that set it, which adds their nesting at each step of the chain; "
                 "shorten the chain")


def _size(expr: Expr, memo: dict[int, tuple[Expr, int, int]]) -> tuple[int, int]:
    """The nesting depth and the number of propositions of ``expr`` read as a tree, in time
    proportional to its distinct nodes: chained conditions share the conditions they repeat
    (``memo`` keeps each node it measured alive, so its ``id`` stays its own)."""
    stack: list[tuple[Expr, bool]] = [(expr, False)]
    while stack:
        node, ready = stack.pop()
        if id(node) in memo:
            continue
        if isinstance(node, Prop):
            memo[id(node)] = (node, 1, 1)
            continue
        items = (node.expr,) if isinstance(node, Not) else node.items
        if not ready:
            stack.append((node, True))
            stack.extend((i, False) for i in items if id(i) not in memo)
            continue
        depth = 1 + max((memo[id(i)][1] for i in items), default=0)
        memo[id(node)] = (node, depth, sum(memo[id(i)][2] for i in items))
    return memo[id(expr)][1:]


def _props(expr: Expr) -> Iterator[Prop]:
    if isinstance(expr, Prop):
        yield expr
    elif isinstance(expr, Not):
        yield from _props(expr.expr)
    else:
        for item in expr.items:
            yield from _props(item)
