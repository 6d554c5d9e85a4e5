"""Rule text of fuzzylite's language (FLL ``rule:`` lines, FCL ``RULE n :`` lines) -> model.

Both grammars (``grammar/fll_rule.lark`` and ``grammar/fcl.lark``) name their rule nodes the
same way (``or_expr``, ``and_expr``, ``negation``, ``proposition``, ``bare_hedge``,
``conclusion``), so one converter serves both. Positions are mapped back into the file, so an
error points at the word in the file.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from lark import Token, Tree

from ..errors import FormatError, Span
from ..lang.model import And, Consequent, Expr, Not, Or, Prop
from ..lang.parse import MAX_NESTING
from ..lang.terms import Variable
from .common import fuzzylite_hedge

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

    #: a node of a Lark parse tree, a Tree or a Token as the grammar's position decides: Lark
    #: types every child as either (``list[Token | Tree]``), so the readers name nodes by this
    Node = Any

SpanOf = Callable[[object], Span]


def expression(tree: Node, span_of: SpanOf, variables: dict[str, Variable]) -> Expr:
    """An antecedent tree as a MITOS expression, refused past :data:`MAX_NESTING` levels
    first: 400 ``NOT``s or nested parentheses of an FCL or FLL rule were a RecursionError."""
    if isinstance(tree, Tree):
        check_depth(tree, span_of)
    return _expression(tree, span_of, variables)


#: the nodes that nest a condition (parentheses add none: the grammars inline them)
NESTING = ("or_expr", "and_expr", "negation")


def check_depth(tree: Node, span_of: SpanOf, limit: int = MAX_NESTING) -> None:
    """Refuse a condition (or a whole file's tree) whose ``and`` / ``or`` / ``not`` nest
    deeper than ``limit``, at the first node past it, as the rule language refuses one. Walked
    without recursion: Lark's ``scan_values`` and every later pass recurse."""
    stack = [(tree, 0)]
    while stack:
        node, depth = stack.pop()
        depth += node.data in NESTING
        if depth > limit:
            raise FormatError(f"conditions nested more than {limit} deep", span=span_of(node),
                              hint="split the condition into several rules, or drop doubled "
                                   "`NOT`s and parentheses")
        stack.extend((child, depth) for child in node.children if isinstance(child, Tree))


def _expression(tree: Node, span_of: SpanOf, variables: dict[str, Variable]) -> Expr:
    if isinstance(tree, Token):
        raise FormatError(f"unexpected `{tree}`", span=span_of(tree))
    kind = tree.data
    if kind in ("or_expr", "and_expr"):
        items = tuple(_expression(c, span_of, variables) for c in tree.children
                      if not isinstance(c, Token))
        cls = Or if kind == "or_expr" else And
        return cls(items, span_of(tree))
    if kind == "negation":
        return Not(_expression(tree.children[-1], span_of, variables), span_of(tree))
    if kind == "bare_hedge":
        var, *words = tree.children
        if [w.lower() for w in words] != ["any"]:
            raise FormatError(f"`{var} is {' '.join(words)}` names no term", span=span_of(tree),
                              hint="only `is any` may stand without a term")
        v = variables.get(str(var))
        if v is None:
            return Prop(str(var), "", ("any",), False, span_of(tree))   # checked later
        return Prop(v.name, v.terms[0].name, ("any",), False, span_of(tree))
    if kind == "bare_variable":
        raise FormatError(f"a condition without `IS` (`{tree.children[0]}`) is not supported",
                          span=span_of(tree), expected=f"`{tree.children[0]} IS TERM`")
    if kind == "proposition":
        var, *words, term = tree.children
        negated, hedges = _words(words, span_of, tree, allow_not=True)
        return Prop(str(var), str(term), hedges, negated, span_of(tree))
    if len(tree.children) == 1:
        return _expression(tree.children[0], span_of, variables)
    raise FormatError(f"unexpected `{kind}` in a rule", span=span_of(tree))


def conclusions(trees: Iterable[Tree], span_of: SpanOf) -> tuple[Consequent, ...]:
    """A rule's consequents as fuzzylite computes them: its hedges change the rule's activation
    degree for that consequent *and every one after it* (``Consequent.modify`` reassigns the
    degree), so ``then a is very x and b is y`` hedges ``b`` too. Each consequent gets the
    hedges accumulated so far, outermost first, which is what MITOS's hedge tuple means."""
    out: list[Consequent] = []
    carried: tuple[str, ...] = ()
    for tree in trees:
        c = conclusion(tree, span_of)
        carried = c.hedges + carried
        out.append(Consequent(c.var, c.term, c.value, carried, c.span))
    return tuple(out)


def conclusion(tree: Tree, span_of: SpanOf) -> Consequent:
    var, *words, term = tree.children
    _, hedges = _words(words, span_of, tree, allow_not=False)
    return Consequent(str(var), str(term), None, hedges, span_of(tree))


def _words(words: Sequence[Node], span_of: SpanOf, tree: Tree, allow_not: bool
           ) -> tuple[bool, tuple[str, ...]]:
    negated = False
    hedges = []
    for i, w in enumerate(words):
        word = str(w).lower()
        if word == "not":
            if not allow_not:
                raise FormatError("`not` in a consequent (the complement of an output term) is "
                                  "not supported", span=span_of(w))
            if i != 0:
                raise FormatError(f"`not` after a hedge (`{' '.join(map(str, words))}`) is not "
                                  f"supported", span=span_of(w),
                                  hint="write `not` first: `is not very TERM`")
            negated = True
            continue
        hedges.append(fuzzylite_hedge(word, span_of(w)))
    return negated, tuple(hedges)
