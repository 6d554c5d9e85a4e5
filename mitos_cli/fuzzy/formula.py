"""Membership functions given as formulas (fuzzylite's ``Function`` term), parsed, never eval'd.

``parse("lt(x, 0.5) * x / 0.5 + gt(x, 0.5) * (1 - x) / 0.5")`` returns a :class:`Formula`: a
tree of operators, functions, numbers and the variable ``x``, evaluated elementwise with NumPy
on arrays of any shape. The language is fuzzylite's: ``+ - * / % ^ **``, unary ``- + ~ !``,
``and`` / ``or``, the comparison functions ``gt ge eq neq le lt`` (1 or 0), ``min max pow
atan2 fmod`` and the one-argument functions of :data:`FUNCTIONS`, ``pi``. A precedence-climbing
parser (linear in the text) reports the column of what it could not read and what it expected.
Only ``x`` is a variable: a formula over other variables of an engine would make a term depend
on values the membership layer does not see, so it is refused by name.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import MitosError, Span, TermSetError, did_you_mean


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
UNARY_PRECEDENCE = 5          # -x^2 is -(x^2), as in fuzzylite and mathematics

_TOKEN = re.compile(r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)|"
                    r"(?P<name>[A-Za-z_][A-Za-z_0-9]*)|(?P<op>\*\*|[-+*/%^(),~!]))")

Node = tuple  # ("num", value) | ("x",) | ("un", op, node) | ("bin", op, a, b) | ("call", f, args)


@dataclass(frozen=True)
class Formula:
    """A parsed formula of ``x``; equal when the text is."""

    text: str
    tree: Node = field(compare=False, repr=False)

    def __call__(self, x) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        with np.errstate(all="ignore"):
            return np.broadcast_to(_eval(self.tree, x), x.shape).astype(float)


def _eval(node: Node, x: np.ndarray):
    kind = node[0]
    if kind == "num":
        return node[1]
    if kind == "x":
        return x
    if kind == "un":
        return UNARY[node[1]](_eval(node[2], x))
    if kind == "bin":
        return BINARY[node[1]][2](_eval(node[2], x), _eval(node[3], x))
    args = [_eval(a, x) for a in node[2]]
    return (FUNCTIONS.get(node[1]) or FUNCTIONS2[node[1]])(*args)


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
        self.i = 0

    def fail(self, column: int, message: str, expected: str | None = None):
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
        left = self.unary()
        while (op := self.binary_op()) is not None:
            prec, right_assoc, _ = BINARY[op]
            if prec < min_prec:
                break
            self.i += 1
            right = self.expression(prec if right_assoc else prec + 1)
            left = ("bin", op, left, right)
        return left

    def unary(self) -> Node:
        tok = self.peek()
        if tok is not None and tok[0] == "op" and tok[1] in UNARY:
            self.i += 1
            return ("un", tok[1], self.expression(UNARY_PRECEDENCE))
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
            inner = self.expression()
            self.take(")", "`)` closing the `(`")
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
        args = [self.expression()]
        for _ in range(arity - 1):
            self.take(",", f"`,`: `{value}` takes {arity} arguments")
            args.append(self.expression())
        self.take(")", f"`)`: `{value}` takes {arity} argument{'s' if arity > 1 else ''}")
        return ("call", value, tuple(args))


def parse(text: str, span: Span | None = None,
          error: type[MitosError] = TermSetError) -> Formula:
    """``text`` as a :class:`Formula`; ``span`` is where the text starts in its file (errors
    point at the column inside it), ``error`` the class to raise."""
    if not text.strip():
        raise error("a formula term needs a formula", span=span,
                    expected="a formula of x, e.g. `1 / (1 + x^2)`")
    p = _Parser(text, span, error)
    tree = p.expression()
    tok = p.peek()
    if tok is not None:
        p.fail(tok[2], f"unexpected `{tok[1]}` after a complete formula",
               "an operator, or the end of the formula")
    return Formula(text.strip(), tree)
