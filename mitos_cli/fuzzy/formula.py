"""Membership functions given as formulas (fuzzylite's ``Function`` term), parsed, never eval'd.

``parse("lt(x, 0.5) * x / 0.5 + gt(x, 0.5) * (1 - x) / 0.5")`` returns a :class:`Formula`: a
tree of operators, functions, numbers and the variable ``x``, evaluated elementwise with NumPy
on arrays of any shape. The language is fuzzylite's: ``+ - * / % ^ **``, unary ``- + ~ !``
(``~`` and ``!`` bind tighter than ``^``, as in fuzzylite; ``-`` looser, as in mathematics),
``and`` / ``or``, the comparison functions ``gt ge eq neq le lt`` (1 or 0), ``min max pow
atan2 fmod`` and the one-argument functions of :data:`FUNCTIONS`, ``pi``. A precedence-climbing
parser (linear in the text) reports the column of what it could not read and what it expected.
A run of operators of one precedence (``x/10 + 0*x + ...``, a long polynomial) is one n-ary
node, parsed and evaluated in a loop, and the tree is evaluated without recursion; nesting
(parentheses, function calls, unary operators) deeper than :data:`MAX_NESTING` is refused at
its column, as the rule language refuses conditions nested too deep.
Only ``x`` is a variable: a formula over other variables of an engine would make a term depend
on values the membership layer does not see, so it is refused by name.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, NoReturn

import numpy as np

from ..errors import MitosError, Span, TermSetError, did_you_mean

if TYPE_CHECKING:
    from numpy.typing import ArrayLike


def _cmp(op: Callable) -> Callable:
    return lambda a, b: op(a, b).astype(float)


#: Functions of one argument (fuzzylite's names), each a NumPy ufunc.
FUNCTIONS: dict[str, Callable] = {
    "acos": np.arccos, "asin": np.arcsin, "atan": np.arctan, "ceil": np.ceil, "cos": np.cos,
    "cosh": np.cosh, "exp": np.exp, "abs": np.fabs, "fabs": np.fabs, "floor": np.floor,
    "log": np.log, "log10": np.log10, "round": np.round, "sin": np.sin, "sinh": np.sinh,
    "sqrt": np.sqrt, "tan": np.tan, "tanh": np.tanh, "log1p": np.log1p, "acosh": np.arccosh,
    "asinh": np.arcsinh, "atanh": np.arctanh,
}
#: Functions of two arguments.
FUNCTIONS2: dict[str, Callable] = {
    "gt": _cmp(np.greater), "ge": _cmp(np.greater_equal), "eq": _cmp(np.equal),
    "neq": _cmp(np.not_equal), "le": _cmp(np.less_equal), "lt": _cmp(np.less),
    "min": np.minimum, "max": np.maximum, "pow": np.float_power, "atan2": np.arctan2,
    "fmod": np.fmod,
}
CONSTANTS = {"pi": np.pi}
#: Binary operators: (precedence, right-associative, function); higher binds tighter.
BINARY: dict[str, tuple[int, bool, Callable]] = {
    "or": (1, False, lambda a, b: np.logical_or(a, b).astype(float)),
    "and": (2, False, lambda a, b: np.logical_and(a, b).astype(float)),
    "+": (3, False, np.add), "-": (3, False, np.subtract),
    "*": (4, False, np.multiply), "/": (4, False, np.true_divide), "%": (4, False, np.remainder),
    "^": (6, True, np.float_power), "**": (6, True, np.float_power),
}
UNARY: dict[str, Callable] = {"-": np.negative, "+": np.positive, "~": np.negative,
                              "!": lambda a: np.logical_not(a).astype(float)}
UNARY_PRECEDENCE = 5          # -x^2 is -(x^2), as in mathematics (fuzzylite has no unary -)
#: fuzzylite's own unary operators bind tighter than ``^`` (its precedence 100 against 90):
#: ``~x^2`` is ``(~x)^2``, x squared, as fuzzylite 6 and 8 compute it
TIGHT_UNARY = ("~", "!")

_TOKEN = re.compile(r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)|"
                    r"(?P<name>[A-Za-z_][A-Za-z_0-9]*)|(?P<op>\*\*|[-+*/%^(),~!]))")

#: how deep parentheses, function calls and unary operators may nest: far beyond any readable
#: formula, and shallow enough for the parser, which recurses once per level
MAX_NESTING = 100

Node = tuple  # ("num", value) | ("x",) | ("un", op, node) | ("call", f, args)
#             | ("chain", first, ((op, node), ...)): operators of one precedence, in order


@dataclass(frozen=True)
class Formula:
    """A parsed formula of ``x``; equal when the text is."""

    text: str
    tree: Node = field(compare=False, repr=False)

    def __call__(self, x: ArrayLike) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        with np.errstate(all="ignore"):
            return np.broadcast_to(_eval(self.tree, x), x.shape).astype(float)


def _children(node: Node) -> tuple[Node, ...]:
    kind = node[0]
    if kind == "un":
        return (node[2],)
    if kind == "chain":
        return (node[1], *(operand for _, operand in node[2]))
    if kind == "call":
        return node[2]
    return ()


def _apply(node: Node, values: list, x: np.ndarray) -> np.ndarray | float:
    """``node``'s value from its children's ``values``: a chain folds from the left, or from
    the right for a right-associative operator (``x^2^3`` is ``x^(2^3)``)."""
    kind = node[0]
    if kind == "num":
        return node[1]
    if kind == "x":
        return x
    if kind == "un":
        return UNARY[node[1]](values[0])
    if kind == "call":
        return (FUNCTIONS.get(node[1]) or FUNCTIONS2[node[1]])(*values)
    ops = [op for op, _ in node[2]]
    if BINARY[ops[0]][1]:
        acc = values[-1]
        for op, left in zip(reversed(ops), reversed(values[:-1])):
            acc = BINARY[op][2](left, acc)
        return acc
    acc = values[0]
    for op, right in zip(ops, values[1:]):
        acc = BINARY[op][2](acc, right)
    return acc


def _eval(tree: Node, x: np.ndarray) -> np.ndarray | float:
    """The tree's value, walked with a stack of its own (no recursion, whatever its depth)."""
    stack: list[tuple[Node, bool]] = [(tree, False)]
    values: list = []
    while stack:
        node, done = stack.pop()
        children = _children(node)
        if done or not children:
            start = len(values) - len(children)      # its children's values, last on top
            args = values[start:]
            del values[start:]
            values.append(_apply(node, args, x))
            continue
        stack.append((node, True))
        stack.extend((child, False) for child in reversed(children))
    return values[0]


class _Parser:
    def __init__(self, text: str, span: Span | None, error: type[MitosError]) -> None:
        self.text, self.span, self.error = text, span, error
        self.tokens: list[tuple[str, str, int]] = []
        pos = 0
        while pos < len(text):
            m = _TOKEN.match(text, pos)
            if m is None or m.end() == pos:
                if not text[pos:].strip():
                    break
                col = pos + len(text[pos:]) - len(text[pos:].lstrip())
                self.fail(col, f"cannot read `{text[col]}` in the formula",
                          "a number, `x`, a function, an operator or a parenthesis")
            assert m is not None          # fail() raised otherwise
            kind = m.lastgroup or "op"
            self.tokens.append((kind, m.group(kind), m.start(kind)))
            pos = m.end()
        self.i = self.depth = 0

    def fail(self, column: int, message: str, expected: str | None = None) -> NoReturn:
        span = self.span
        if span is not None:
            span = replace(span, column=span.column + column, end_column=span.column + column + 1)
        raise self.error(message, span=span, expected=expected)

    def peek(self) -> tuple[str, str, int] | None:
        return self.tokens[self.i] if self.i < len(self.tokens) else None

    def take(self, value: str, expected: str) -> None:
        tok = self.peek()
        if tok is None or tok[1] != value:
            self.fail(tok[2] if tok else len(self.text),
                      f"expected `{value}`" + (f", not `{tok[1]}`" if tok else " at the end"),
                      expected)
        self.i += 1

    def binary_op(self) -> str | None:
        tok = self.peek()
        if tok is not None and tok[1] in BINARY and tok[0] in ("op", "name"):
            return tok[1]
        return None

    def expression(self, min_prec: int = 0) -> Node:
        """Operators binding at least ``min_prec``: each run of one precedence is one chain,
        read in a loop, so a sum of a thousand terms costs no deeper recursion than one."""
        left = self.unary()
        while (op := self.binary_op()) is not None:
            prec = BINARY[op][0]
            if prec < min_prec:
                break
            rest = []
            while op is not None and BINARY[op][0] == prec:
                self.i += 1
                rest.append((op, self.expression(prec + 1)))
                op = self.binary_op()
            left = ("chain", left, tuple(rest))
        return left

    def nest(self, col: int) -> None:
        """One level deeper (a parenthesis, a function call, a unary operator) at ``col``."""
        self.depth += 1
        if self.depth > MAX_NESTING:
            self.fail(col, f"the formula is nested more than {MAX_NESTING} deep "
                           f"(parentheses, function calls and unary operators)",
                      "a formula with fewer levels: drop doubled signs and parentheses")

    def unary(self) -> Node:
        tok = self.peek()
        if tok is not None and tok[0] == "op" and tok[1] in UNARY:
            self.nest(tok[2])
            self.i += 1
            operand = self.unary() if tok[1] in TIGHT_UNARY else self.expression(UNARY_PRECEDENCE)
            node = ("un", tok[1], operand)
            self.depth -= 1
            return node
        return self.atom()

    def atom(self) -> Node:
        tok = self.peek()
        if tok is None:
            self.fail(len(self.text), "the formula ends too early",
                      "a number, `x`, a function or `(`")
        assert tok is not None
        kind, value, col = tok
        self.i += 1
        if kind == "num":
            return ("num", float(value))
        if value == "(":
            self.nest(col)
            inner = self.expression()
            self.take(")", "`)` closing the `(`")
            self.depth -= 1
            return inner
        if kind != "name":
            self.i -= 1
            self.fail(col, f"unexpected `{value}` in the formula",
                      "a number, `x`, a function or `(`")
        if value == "x":
            return ("x",)
        if value in CONSTANTS:
            return ("num", CONSTANTS[value])
        arity = 1 if value in FUNCTIONS else 2 if value in FUNCTIONS2 else 0
        if not arity:
            known = ["x", *CONSTANTS, *FUNCTIONS, *FUNCTIONS2]
            hint = did_you_mean(value, known)
            self.fail(col, f"unknown name `{value}` in the formula (a formula of the term's "
                           f"variable `x` may use only `x`, numbers, `pi` and functions)"
                      + (f"; {hint}" if hint else ""), None)
        self.take("(", f"`(` after the function `{value}`")
        self.nest(col)
        args = [self.expression()]
        for _ in range(arity - 1):
            self.take(",", f"`,`: `{value}` takes {arity} arguments")
            args.append(self.expression())
        self.take(")", f"`)`: `{value}` takes {arity} argument{'s' if arity > 1 else ''}")
        self.depth -= 1
        return ("call", value, tuple(args))


def parse(text: str, span: Span | None = None,
          error: type[MitosError] = TermSetError) -> Formula:
    """``text`` as a :class:`Formula`; ``span`` is where the text starts in its file (errors
    point at the column inside it), ``error`` the class to raise."""
    if not text.strip():
        raise error("a formula term needs a formula", span=span,
                    expected="a formula of x, e.g. `1 / (1 + x^2)`")
    p = _Parser(text, span, error)
    try:
        tree = p.expression()
    except RecursionError:       # within MAX_NESTING, but called from a deep stack already
        raise error(f"the formula is nested too deep to read here (at most {MAX_NESTING} "
                    f"levels, and fewer from deep inside a program)", span=span,
                    expected="a formula with fewer levels") from None
    tok = p.peek()
    if tok is not None:
        p.fail(tok[2], f"unexpected `{tok[1]}` after a complete formula",
               "an operator, or the end of the formula")
    return Formula(text.strip(), tree)
