"""jFuzzyLogic's ``FUNCTION`` output terms read as linear Takagi-Sugeno consequents.

jFuzzyLogic evaluates a ``FUNCTION`` term (``TERM t := FUNCTION (a * 0.6) + 1.2;``) at the
inputs and puts a singleton of height 1 at its value (``MembershipFunctionFuncion``), which
its ``COGF`` (as ``COGS``) averages with the rules' weights. A function linear in the inputs
is therefore MITOS's ``linear`` term; any other is refused at the operation that makes it
non-linear. The expression is parsed here, never run: numbers, input names, ``+ - * /`` with
the usual precedence, parentheses and a unary minus; ``^``, ``%`` and jFuzzyLogic's functions
(``exp ln log sin cos tan abs``) only of constants.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from dataclasses import replace

from ..errors import FormatError, Span

#: a linear form: coefficient per input name, then the constant under the key ``""``
Form = dict[str, float]

TOKEN = re.compile(r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)|(?P<name>[A-Za-z_]\w*)"
                   r"|(?P<op>[-+*/^%()]))")
FUNCTIONS: dict[str, Callable[[float], float]] = {
    "exp": math.exp, "ln": math.log, "log": math.log10, "sin": math.sin, "cos": math.cos,
    "tan": math.tan, "abs": abs}


def linear_function(text: str, span: Span, inputs: Sequence[str]) -> tuple[float, ...]:
    """The coefficients of ``FUNCTION ...`` (``text`` as written, keyword included) over
    ``inputs`` in their order, then the constant (fuzzylite's ``Linear`` layout); a
    FormatError at the place where it stops being linear in the inputs."""
    body = text[len("function"):]
    parser = _Parser(body, len("function"), span, set(inputs))
    form = parser.parse()
    params = tuple(form.get(x, 0.0) for x in inputs) + (form.get("", 0.0),)
    if not all(math.isfinite(p) for p in params):   # 1e308 * 10: inf, and inf - inf NaN
        k = next(i for i, p in enumerate(params) if not math.isfinite(p))
        what = f"coefficient of {inputs[k]}" if k < len(inputs) else "constant"
        raise FormatError(f"FUNCTION: its {what} comes to {params[k]:g}, past a float's range",
                          span=parser.at(0, len(body)), expected="numbers whose products and "
                          "sums stay within a float (about 1.8e308)")
    return params


#: how deep parentheses, unary signs and functions may nest in one FUNCTION (as conditions
#: nest: ``lang.parse.MAX_NESTING``); the parser recurses at each level
MAX_DEPTH = 100


class _Parser:
    """Recursive descent over the tokens of one function, each item a linear form."""

    def __init__(self, text: str, offset: int, span: Span, inputs: set[str]) -> None:
        self.span, self.inputs, self.offset = span, inputs, offset
        self.tokens: list[tuple[str, str, int]] = []
        self.depth = 0
        pos, end = 0, len(text.rstrip())   # (`text[pos:]` at each token: quadratic)
        while pos < end:
            m = TOKEN.match(text, pos)
            if m is None or not m.group(m.lastgroup or ""):
                at = pos + len(text[pos:]) - len(text[pos:].lstrip())
                raise FormatError(f"FUNCTION: unexpected `{text[at]}`", span=self.at(at, 1),
                                  expected="a number, an input, + - * / ^ % or parentheses")
            kind = m.lastgroup or ""
            self.tokens.append((kind, m.group(kind), m.start(kind)))
            pos = m.end()
        self.i = 0

    def at(self, position: int, length: int) -> Span:
        """The span of ``length`` characters at ``position`` of the function's text."""
        if self.span.end_column is None:
            return self.span
        column = self.span.column + self.offset + position
        return replace(self.span, column=column, end_column=column + max(length, 1))

    def peek(self) -> tuple[str, str, int] | None:
        return self.tokens[self.i] if self.i < len(self.tokens) else None

    def take(self) -> tuple[str, str, int]:
        token = self.peek()
        if token is None:
            end = self.tokens[-1][2] + len(self.tokens[-1][1]) if self.tokens else 0
            raise FormatError("FUNCTION: the expression ends too early", span=self.at(end, 1),
                              expected="a number, an input or `(`")
        self.i += 1
        return token

    def parse(self) -> Form:
        form = self.sum()
        if (token := self.peek()) is not None:
            raise FormatError(f"FUNCTION: unexpected `{token[1]}`",
                              span=self.at(token[2], len(token[1])),
                              expected="an operator (+ - * / ^ %) or the end")
        return form

    def sum(self) -> Form:
        form = self.product()
        while (token := self.peek()) is not None and token[1] in "+-":
            self.take()
            other = self.product()
            sign = 1.0 if token[1] == "+" else -1.0
            form = {k: form.get(k, 0.0) + sign * other.get(k, 0.0) for k in form | other}
        return form

    def product(self) -> Form:
        form = self.power()
        while (token := self.peek()) is not None and token[1] in "*/":
            self.take()
            other = self.power()
            if token[1] == "*":
                form = self.times(form, other, token)
            else:
                if not _constant(other):
                    raise self.nonlinear(token, "a division by an input")
                divisor = other.get("", 0.0)
                if divisor == 0.0:
                    raise FormatError("FUNCTION: a division by 0",
                                      span=self.at(token[2], 1))
                form = {k: v / divisor for k, v in form.items()}
        return form

    def times(self, a: Form, b: Form, token: tuple[str, str, int]) -> Form:
        if not _constant(a) and not _constant(b):
            raise self.nonlinear(token, "a product of two inputs")
        factor, form = (a.get("", 0.0), b) if _constant(a) else (b.get("", 0.0), a)
        return {k: factor * v for k, v in form.items()}

    def power(self) -> Form:
        form = self.unary()
        while (token := self.peek()) is not None and token[1] in "^%":
            self.take()
            other = self.unary()
            if not (_constant(form) and _constant(other)):
                what = "a power" if token[1] == "^" else "a remainder"
                raise self.nonlinear(token, f"{what} of an input")
            a, b = form.get("", 0.0), other.get("", 0.0)
            try:
                value = a ** b if token[1] == "^" else math.fmod(a, b)
            except (ArithmeticError, ValueError):
                value = None
            if not isinstance(value, float):   # (-8) ^ 0.5 is complex: float() a TypeError
                raise FormatError(f"FUNCTION: {a:g} {token[1]} {b:g} is not a number",
                                  span=self.at(token[2], 1))
            form = {"": value}
        return form

    def deeper(self, token: tuple[str, str, int]) -> None:
        """One level more of nesting at ``token``; past :data:`MAX_DEPTH`, refused there (50,000
        parentheses were a RecursionError, a traceback)."""
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise FormatError(f"FUNCTION: nested more than {MAX_DEPTH} deep",
                              span=self.at(token[2], len(token[1])),
                              hint="drop doubled signs and parentheses, or write the value")

    def unary(self) -> Form:
        token = self.peek()
        if token is not None and token[1] in "+-":
            self.take()
            self.deeper(token)
            form = self.unary()
            self.depth -= 1
            return form if token[1] == "+" else {k: -v for k, v in form.items()}
        return self.atom()

    def atom(self) -> Form:
        kind, value, position = self.take()
        if kind == "num":
            return {"": float(value)}
        if value == "(":
            self.deeper((kind, value, position))
            form = self.sum()
            closing = self.take()
            if closing[1] != ")":
                raise FormatError(f"FUNCTION: unexpected `{closing[1]}`",
                                  span=self.at(closing[2], len(closing[1])), expected="`)`")
            self.depth -= 1
            return form
        if kind == "name" and value.lower() in FUNCTIONS:
            self.deeper((kind, value, position))
            argument = self.atom()
            self.depth -= 1
            if not _constant(argument):
                raise self.nonlinear((kind, value, position), f"`{value}` of an input")
            try:
                return {"": float(FUNCTIONS[value.lower()](argument.get("", 0.0)))}
            except (ArithmeticError, ValueError):
                raise FormatError(f"FUNCTION: `{value}` of {argument.get('', 0.0):g} is not a "
                                  f"number", span=self.at(position, len(value))) from None
        if kind == "name":
            if value not in self.inputs:
                raise FormatError(f"FUNCTION: `{value}` is not an input variable",
                                  span=self.at(position, len(value)),
                                  expected="one of " + ", ".join(sorted(self.inputs)))
            return {value: 1.0}
        raise FormatError(f"FUNCTION: unexpected `{value}`", span=self.at(position, len(value)),
                          expected="a number, an input or `(`")

    def nonlinear(self, token: tuple[str, str, int], what: str) -> FormatError:
        return FormatError(
            f"FUNCTION: {what} is not linear in the inputs; MITOS reads a FUNCTION term as a "
            f"linear Takagi-Sugeno consequent (a sum of inputs times numbers, plus a number)",
            span=self.at(token[2], len(token[1])),
            hint="write a linear function, or a crisp value (`TERM t := 5;`)")


def _constant(form: Form) -> bool:
    """Whether ``form`` names no input (a coefficient that cancelled to 0 counts as none)."""
    return all(v == 0.0 for k, v in form.items() if k)
