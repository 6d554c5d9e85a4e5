"""Parsing the rule language with Lark (LALR, linear time: no input can make it hang).

:func:`parse_rules` turns text into a :class:`ParsedFile` of model objects whose names are not
yet checked (that is :mod:`mitos_cli.lang.resolve`'s job, outside Lark's callbacks). Lark's errors are
translated into :class:`RuleSyntaxError` with ``path:line:col``, the line, a caret and what was
expected, in words.
"""

from __future__ import annotations

import functools
import inspect
import math
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from lark import Lark, Token, Transformer, Tree, v_args
from lark.exceptions import (
    UnexpectedCharacters,
    UnexpectedEOF,
    UnexpectedInput,
    UnexpectedToken,
    VisitError,
)

from ..errors import MitosError, RuleSyntaxError, Span, did_you_mean, lines_of, lone_cr_as_lf
from ..fuzzy.hedges import HEDGES
from ..resources import grammar_text
from .bulk import without_cyclic_gc
from .cache import lark_parser
from .lexing import Glued, accepted_before, one_word, parse_apart, read_as_one_name
from .model import And, Behavior, Consequent, Expr, Not, Or, Prop, Rule, Setting, Use

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Iterator
    from types import SimpleNamespace

    from lark.tree import Meta

HEDGE_NAMES = tuple(HEDGES)          # the grammar's HEDGE words (tests/test_registries.py)

#: How terminals are named in error messages.
TERMINAL_WORDS = {
    "NAME": "a name", "STRING": 'a quoted file name ("...")', "SIGNED_NUMBER": "a number",
    "NOT": "`not`", "HEDGE": "a hedge (" + ", ".join(HEDGE_NAMES) + ")", "COLON": "`:`",
    "COMMA": "`,`", "EQUAL": "`=`", "LPAR": "`(`",
    "RPAR": "`)`", "$END": "the end of the input",
}


#: terminals never offered as "expected" (`not` in an action is read only to be refused)
UNSAID = frozenset({"ACTION_NOT"})


@functools.cache
def parser() -> Lark:
    """The rule-language parser, built once per process (its analysis kept in :mod:`.cache`)."""
    return lark_parser(grammar_text(), propagate_positions=True, maybe_placeholders=True,
                       start=["start", "rule", "expr"])


@dataclass(frozen=True)
class _Weight:
    """``with W`` as parsed: the number and where it stands."""

    value: float
    span: Span | None


@dataclass(frozen=True)
class ParsedFile:
    """A rule file as written: term-set paths, file-level items, behaviors."""

    text: str
    path: str | None
    terms: tuple[tuple[str, Span], ...] = ()
    operators: tuple[Setting, ...] = ()
    rules: tuple[Rule, ...] = ()
    uses: tuple[Use, ...] = ()
    frozen: tuple[str, ...] = ()
    behaviors: tuple[Behavior, ...] = ()
    #: where each of ``frozen`` (the top-level `frozen` labels) is written
    frozen_spans: tuple[Span | None, ...] = ()


def _words(name: str, words: dict[str, str] = TERMINAL_WORDS) -> str:
    """A terminal's name as users read it (``THEN`` -> `` `then` ``, ``NAME`` -> a name)."""
    if name in words:
        return words[name]
    if name.isupper() and name.isalpha():
        return f"`{name.lower()}`"
    return f"`{name}`"


def _expected(names: Iterable[str]) -> str:
    return _expected_words(names, TERMINAL_WORDS)


def _expected_words(names: Iterable[str], words_of: dict[str, str]) -> str:
    """The terminals ``names`` as a sentence (``a, b or c``), named as in ``words_of``."""
    words = sorted({_words(n, words_of) for n in names
                    if not n.startswith("__") and n not in UNSAID})
    if len(words) > 1:
        return ", ".join(words[:-1]) + " or " + words[-1]
    return words[0] if words else "something else"


def keyword_hint(token: Token, expected: Iterable[str]) -> str | None:
    """A misspelt keyword (``adapt epocs``, ``iff``): "did you mean" the closest keyword the
    parser expected there, if one is close."""
    words = [n.lower() for n in expected if n.isupper() and n.isalpha() and n != "NAME"]
    value = str(token.value)
    return did_you_mean(value, words) if words and value.isidentifier() else None


def _frozen_term(text: str, pos: int) -> str | None:
    """``frozen heading.AHEAD`` in a rule file, at the `.` (``pos``): the teaching prompt
    freezes terms so, but a rule file freezes rules; a term, in its term set."""
    label = re.search(r"\bfrozen[ \t]+(?:[\w\-]+[ \t]*,[ \t]*)*([A-Za-z_][\w\-]*)\Z",
                      text[:pos])
    term = re.match(r"\.([A-Za-z_][\w\-]*)", text[pos:])
    if label is None or term is None:
        return None
    var, name = label.group(1), term.group(1)
    return (f"a rule file freezes rules (`frozen r1`); a term is frozen in its term set, "
            f"`frozen: true` on `{name}` of `{var}` (`frozen {var}.{name}` is a `mitos teach` "
            "command)")


def _describe(token: Token) -> str:
    if token.type == "$END":
        return "the end of the input"
    return f"`{token.value}`"


def syntax_error(exc: UnexpectedInput, text: str, path: str | None) -> RuleSyntaxError:
    """Lark's exception as a user-facing error (never ``$END`` or ``Token(...)``)."""
    if isinstance(exc, UnexpectedCharacters):
        return _character_error(exc, text, path)
    if isinstance(exc, UnexpectedInput):
        negated = not_in_action_before(exc, text, path)
        if negated is not None:
            return negated
    if isinstance(exc, UnexpectedEOF) or (isinstance(exc, UnexpectedToken)
                                          and exc.token.type == "$END"):
        return _end_error(exc, text, path)
    assert isinstance(exc, UnexpectedToken)
    token = exc.token
    cut = _operators_cut_short(text, path, token.line)
    if cut is not None:
        return cut
    glued_name = _glued_name(exc, text, path)
    if glued_name is not None:
        return glued_name
    stray = _stray_label(exc, text, path)
    if isinstance(stray, RuleSyntaxError):
        return stray
    missing = _missing_colon(exc, text, path)
    if missing is not None:
        return missing
    glued = _GLUED_BEFORE.search(text, 0, token.start_pos or 0)
    if glued and glued.group(1) not in RESERVED and glued.group(1) not in HEDGE_NAMES:
        # `road iss WIDE`: read as `road is s`, then "unexpected `WIDE`"
        return _glued_is_error(text, path, glued.group(1), glued.start(2), glued.end(2), None)
    span = Span.in_text(text, path, token.line, token.column,
                        token.column + max(1, len(str(token.value))))
    expected = set(exc.expected)
    hint = _token_hint(text, token, expected)
    hint = _statement_hint(text, token.start_pos) or stray or hint
    return RuleSyntaxError(f"unexpected {_describe(token)}", span=span,
                           expected=_expected(expected), hint=hint)


def _character_error(exc: UnexpectedCharacters, text: str, path: str | None
                     ) -> RuleSyntaxError:
    """A character the lexer cannot start a token with, with a hint where one is a common
    slip (a name in non-ASCII letters, FCL's `;` at a rule's end, a term frozen as at the
    prompt)."""
    line, column = exc.line, exc.column
    pos: int = exc.pos_in_stream  # type: ignore[assignment]  # lark declares None; the lexer sets an int
    char = text[pos] if pos < len(text) else ""
    message = f"unexpected character `{char}`" if char.isprintable() else \
        f"unexpected character {char!r}"
    allowed = _expected(exc.allowed) if exc.allowed else None
    hint = None
    if char.isalpha() and not char.isascii():     # `température`: names are ASCII
        hint = ("names are ASCII letters, digits, `_` and `-` (`temperature`); other text "
                "belongs in a term set's `description`")
    elif char == ";":                               # FCL's `... then speed is SLOW;`
        hint = ("a rule needs no `;` at its end (FCL's rules have one: `mitos convert "
                "FILE.fcl --to rules` reads an FCL file)")
    elif char == "." and (frozen := _frozen_term(text, pos)) is not None:
        hint = frozen
    return RuleSyntaxError(message, span=Span.in_text(text, path, line, column),
                           expected=allowed, hint=hint)


def _end_error(exc: UnexpectedInput, text: str, path: str | None) -> RuleSyntaxError:
    """The input ended before a statement did: said at the end of its last non-blank line
    (LALR reports the end as a token, ``$END``, that users must never read), unless a label
    stands there alone (:func:`_stray_label`)."""
    if isinstance(exc, UnexpectedToken) and exc.token.type == "$END":
        stray = _stray_label(exc, text, path)
        if isinstance(stray, RuleSyntaxError):
            return stray
    lines = lines_of(text.rstrip()) or [""]
    line = len(lines)
    column = len(lines[-1]) + 1
    names = getattr(exc, "expected", None) or []
    return RuleSyntaxError("unexpected end of the input",
                           span=Span.in_text(text, path, line, column),
                           expected=_expected(names) if names else None,
                           hint=_statement_hint(text, len(text.rstrip())) or
                           "the last rule or behavior is incomplete (a behavior ends "
                           "with `end`)")


def _token_hint(text: str, token: Token, expected: set[str]) -> str | None:
    """What an unexpected ``token`` most likely means, from what the parser ``expected``
    there: a keyword read as a name, `=` for `is`, a misspelt keyword, conditions not joined
    or a missing `then`."""
    if token.type == "NAME" and "IS" in expected:
        before = _word_before(text, token)
        close = did_you_mean(before, RESERVED) if before else None
        if before in RESERVED:
            # `if road is WIDE and then ...`: the keyword was read as a variable's name
            return (f"`{before}` stands where a condition should be; a condition reads "
                    f"`variable is TERM`")
        if close and not _after_connective(text, token):
            # `r1: iff road is WIDE ...`: `iff` was read as a variable's name (but in
            # `if temp COLD`, `temp` is one: not "did you mean `terms`")
            return f"`{before}` is read as a variable's name: {close}"
        return "a condition reads `variable is TERM`"
    if str(token.value) == "=" and "IS" in expected and _word_before(text, token):
        # `then speed = 5`: a proposition is `speed is 5`, not an assignment
        return f"write `{_word_before(text, token)} is ...`: a condition or action reads " \
               f"`variable is TERM` (or `is 5` for a crisp value), not `=`"
    if "THEN" in expected and token.type in ("NAME",):
        return _keyword_as_term(text, token) or _hedge_hint(text, token) or \
            keyword_hint(token, expected) or _two_words(text, token) or \
            "join conditions with `and` / `or`, and start the actions with `then`"
    return keyword_hint(token, expected) or _joined_with_comma(text, token)


#: a line that begins a statement: a keyword, or a label and its colon
_STATEMENT_START = re.compile(r"[ \t]*(?:(?:behavior|end|use|terms|operators)\b|"
                              r"[A-Za-z_][\w\-]*[ \t]*:)")


def _operators_cut_short(text: str, path: str | None, line: int | None
                         ) -> RuleSyntaxError | None:
    """An ``operators:`` line that ends in ``=`` or ``,`` before a line that begins a statement
    (``operators: accumulation =`` then ``behavior b:``): its value is missing. Newlines do
    not end a statement, so the next line's first word was read as the value, and the error
    fell lines later (``unexpected `r1` ... expected `if```, two lines down); it is said at
    the end of the operators line. A setting wrapped on purpose (``and = min,`` then ``or =
    max``) goes on with a setting, not a statement, and is not this."""
    if line is None:
        return None
    lines = lines_of(text)
    for i in range(min(line, len(lines)) - 2, max(line - 5, -1), -1):
        code = lines[i].split("#", 1)[0].rstrip()
        if not re.match(r"[ \t]*operators[ \t]*:", code) or not code.endswith(("=", ",")):
            continue
        after = next((x for x in lines[i + 1:line] if x.split("#", 1)[0].strip()), "")
        if not _STATEMENT_START.match(after):
            return None
        last = code.rsplit(None, 2)
        shown = " ".join(last[-2:]) if code.endswith("=") else code.split(":", 1)[1].strip()
        return RuleSyntaxError(
            f"the operators line ends after `{shown}`: a "
            f"{'value' if code.endswith('=') else 'setting'} is missing",
            span=Span.in_text(text, path, i + 1, len(code), len(code) + 1),
            expected="`NAME = VALUE` settings, separated by commas "
                     "(`operators: and = min, or = max`)")
    return None


def _missing_colon(exc: UnexpectedToken, text: str, path: str | None) -> RuleSyntaxError | None:
    """A line that ends without the `:` it needs (`behavior drive` and the rules on the next
    line): said at the end of that line, not at the next line's first word."""
    last = (exc.token_history or [None])[-1]
    if set(exc.expected) != {"COLON"} or last is None or last.end_line is None \
            or last.end_line >= exc.token.line:
        return None
    line = lines_of(text)[last.end_line - 1]
    return RuleSyntaxError(f"missing `:` after `{line[:last.end_column - 1].strip()}`",
                           span=Span.in_text(text, path, last.end_line, last.end_column,
                                             last.end_column + 1),
                           expected="`:` at the end of the line")


def _label_word(exc: UnexpectedToken) -> Token | None:
    """The word the parser took for a rule's label just before the failing token, if it did.

    A rule may start with ``LABEL:``, so wherever a rule can start any word is read as a label
    and only the token after it can fail: ``speed is MEDIUM andd`` fails at the next line's
    ``r5``, ``ned`` for ``end`` at the next ``behavior``. The word was a label's start when the
    state before it also accepts ``if`` (a rule's start).
    """
    state = exc.state
    if state is None or len(state.state_stack) < 2 or not state.value_stack:
        return None
    word = state.value_stack[-1]
    if not isinstance(word, Token) or word.type != "NAME":
        return None
    return word if "IF" in state.parse_conf.states[state.state_stack[-2]] else None


def _before(text: str, word: Token, start: str) -> tuple[Token | None, set[str]]:
    """The token before ``word`` and what the parser accepts there (``text`` parsed again up
    to ``word``: only on an error, and linear)."""
    last = None
    interactive = parser().parse_interactive(text[:word.start_pos], start=start)
    for last in interactive.iter_parse():  # noqa: B007 - keep the last token
        pass
    return last, set(interactive.accepts())


#: how a word that may start a rule is named where it is expected
LABEL_WORDS = {**TERMINAL_WORDS, "NAME": "a rule's label (`r5:`)"}


def _stray_label(exc: UnexpectedToken, text: str, path: str | None) -> RuleSyntaxError | str | None:
    """The error at a word read as a rule's label whose ``:`` is missing: the word itself
    when it is no label (``andd`` at a line's end, ``ned`` for ``end``), else a hint for the
    error at the token after it (``r5 if ...``: the label without its ``:``).

    A label's ``:`` stands on the label's line: when the next token is on a later line (or is
    the end of the input), or the word is close to a keyword the parser accepted before it,
    the word is reported, with what could have stood there and "did you mean".
    """
    word = _label_word(exc)
    if word is None or exc.state is None:
        return None
    token = exc.token
    same_line = token.type != "$END" and token.line == word.line
    if same_line and token.type == "IF":            # `r5 if road is ...`
        return f"a rule's label ends with `:` (`{word}: if ...`)"
    try:
        last, accepts = _before(text, word, exc.state.parse_conf.start)
    except UnexpectedInput:             # cannot happen: the text parsed up to the word
        return None
    close = _keyword_near(text, word, accepts)
    if same_line and close is None:                 # `foo bar`
        if token.type == "IS" and _in_actions(text[:word.start_pos]):
            return (f"actions are joined with `and`: `... and {word} is ...` (as it stands, "
                    f"`{word}` is read as the label of a new rule, which ends with `:`)")
        return f"`{word}` is read as a rule's label, which ends with `:` (`{word}: if ...`)"
    after = f" after {_describe(last)}" if last is not None else ""
    span = Span.in_text(text, path, word.line or 1, word.column or 1,
                        (word.column or 1) + len(str(word)))
    hint = (f"`{word}` is not a keyword: {close}" if close else
            f"`{word}` is read as the label of a new rule, which needs `:` after it on the "
            f"same line (`{word}: if ...`)")
    return RuleSyntaxError(f"unexpected `{word}`{after}", span=span,
                           expected=_expected_words(accepts, LABEL_WORDS), hint=hint)


def _keyword_near(text: str, word: Token, accepts: set[str]) -> str | None:
    """"did you mean" the keyword ``word`` is closest to, among those accepted before it; a
    statement's keyword first when ``word`` starts its line (``ned``: `end`, not `and`)."""
    keywords = [n.lower() for n in accepts if n.isupper() and n.isalpha() and n != "NAME"]
    line_start = word.start_pos is not None and \
        text[:word.start_pos].rpartition("\n")[2].strip() == ""
    if line_start:
        first = did_you_mean(str(word), [k for k in keywords if k in STATEMENTS])
        if first:
            return first
    return did_you_mean(str(word), keywords) if keywords else None


def _hedge_hint(text: str, token: Token, allowed: tuple[str, ...] | None = None) -> str | None:
    """``road is vary WIDE``: the word before the term was meant as a hedge. ``allowed``: the
    hedges that may stand there (a teaching target takes only those that move a value along
    its scale), listed and offered instead of every hedge."""
    from ..fuzzy.hedges import HEDGES

    before = re.search(r"\bis\s+(?:not\s+)?([A-Za-z_][\w\-]*)\s*$",
                       text[:token.start_pos])
    if before is None or before.group(1) in HEDGES:
        return None
    word = before.group(1)
    pool = list(HEDGES) if allowed is None else list(allowed)
    close = did_you_mean(word, pool)            # only a near miss is taken for a hedge
    where = "hedges" if allowed is None else "hedges of a target"
    return f"`{word}` is not a hedge ({where}: {', '.join(pool)}); {close}" if close else None


#: `is`, then `not` and hedges, then a term or a number, at the end of the text before a token
_PROPOSITION_END = r"\bis\s+(?:[A-Za-z_][\w\-]*\s+)*[-+\w.]+\s*\Z"


def _in_actions(before: str) -> bool:
    """Whether ``before`` (the text up to a token) ends in an action: a `then` after the
    rule's `if`, and a proposition last."""
    keywords = re.findall(r"\b(if|then)\b", before)
    return keywords[-1:] == ["then"] and re.search(_PROPOSITION_END, before) is not None


def _joined_with_comma(text: str, token: Token) -> str | None:
    """``then steering is RS, speed is MEDIUM`` and ``if road is WIDE, size is SMALL_SZ``: a
    comma between actions or conditions, where the language joins them with words. The error
    said only "unexpected `,`, expected a name"."""
    before = text[:token.start_pos]
    if token.type != "COMMA" and str(token.value) != ",":
        return None
    if re.search(_PROPOSITION_END, before) is None:
        return None
    if _in_actions(before):
        return "actions are joined with `and`, not `,`: `then steering is LS and speed is SLOW`"
    return "conditions are joined with `and` or `or`, not `,`: `if a is X and b is Y`"


def joined_hint(text: str, token: Token) -> str | None:
    """How conditions and actions are joined, for an error at ``token`` where a rule's
    were joined with a comma, or two actions with nothing (``then steering is LS speed is
    SLOW``, where the teaching prompt expects `and` or `with` before `speed`)."""
    comma = _joined_with_comma(text, token)
    if comma is not None or token.type != "NAME":
        return comma
    before = text[:token.start_pos]
    if _in_actions(before) and re.match(r"\s*is\b", text[token.end_pos:]):
        return f"actions are joined with `and`: `... and {token} is ...`"
    return None


def _two_words(text: str, token: Token, allowed: tuple[str, ...] | None = None) -> str | None:
    """``position is FAR RIGHT``: two words after `is`, the first neither a hedge nor close to
    one (``vary``: :func:`_hedge_hint`). A term's name is one word; a missing `and` before a
    new condition (``road is WIDE size is ...``) is not this: there `is` follows. ``allowed``:
    the hedges that may stand there, as for :func:`_hedge_hint` (a teaching target's)."""
    from ..fuzzy.hedges import HEDGES

    before = re.search(r"\bis\s+(?:not\s+)?([A-Za-z_][\w\-]*)\s*$", text[:token.start_pos])
    if before is None or before.group(1) in HEDGES or before.group(1) == "not":
        return None
    if re.match(r"\s*is\b", text[token.end_pos:]):
        return None
    word = before.group(1)
    pool, which = (HEDGES, "a hedge") if allowed is None else (allowed, "a hedge of a target")
    return (f"`{word} {token}`: a term's name is one word (`{word}_{token}`), and `{word}` is "
            f"not {which} ({', '.join(pool)}), which would stand before the term")


def _keyword_as_term(text: str, token: Token) -> str | None:
    """``if road is any then speed is FAST``: after ``is``, ``not`` and hedges a term must
    come, so ``then`` was read as the term, and the error ("expected `then`") stood at
    ``speed``, after the `then` it asked for."""
    from ..fuzzy.hedges import HEDGES

    words = "|".join(("not", *HEDGES))
    found = re.search(rf"\bis\s+((?:(?:{words})\s+)*)(then|and|or|with|when)\s*\Z",
                      text[:token.start_pos])
    if found is None:
        return None
    given = " ".join([*found.group(1).split(), "TERM"])
    return (f"`{found.group(2)}` was read as a term: after `is` (and `not` and hedges) a term "
            f"is named (`is {given}`)")


#: words of the language that can also be read as names where a name is expected
RESERVED = {"if", "then", "and", "or", "not", "is", "with", "use", "when", "end", "behavior",
            "terms", "operators", "frozen"}


#: words that start a statement (`terms "a.yaml"`, `operators: ...`, `behavior b:`, ...)
STATEMENTS = ("terms", "operators", "behavior", "end", "use", "frozen")


def _statement_hint(text: str, pos: int | None) -> str | None:
    """``behaviour b:``, ``operator: and = min``, ``edn``: a misspelt statement keyword, read as
    a rule's label, when it is the first word of its line and the word just before ``pos``.
    A word with a colon is only taken for a keyword that takes one (``user:`` is a label)."""
    if pos is None:
        return None
    found = re.search(r"(?:^|\n)[ \t]*([A-Za-z_][\w\-]*)(:?)\s*\Z", text[:pos])
    if found is None or found.group(1) in RESERVED:
        return None
    word = found.group(1)
    pool = ("operators", "behavior") if found.group(2) else STATEMENTS
    close = did_you_mean(word, pool)
    return f"`{word}` is not a keyword: {close}" if close else None


def _after_connective(text: str, token: Token) -> bool:
    """Whether the word before ``token`` stands where a condition's variable does (after
    `if`, `and`, `or`, `not`, `when` or `(`): then it is a variable's name, not a keyword."""
    if token.start_pos is None:
        return False
    return re.search(r"(?:\b(?:if|and|or|not|when)\b|\()\s*[A-Za-z_][\w\-]*\s*\Z",
                     text[:token.start_pos]) is not None


#: the keywords that join (a word glued to one of them is read as one name: `WIDEand`)
_JOINING = ("and", "or", "then", "with", "when")


def _glued_name(exc: UnexpectedToken, text: str, path: str | None) -> RuleSyntaxError | None:
    """The error at or after a name that is a term glued to a joining keyword, said with
    :func:`glued_name_hint`."""
    token = exc.token
    hint = glued_name_hint(text, token)
    if hint is None or token.line is None or token.column is None:
        return None
    span = Span.in_text(text, path, token.line, token.column,
                        token.column + max(1, len(str(token.value))))
    return RuleSyntaxError(f"unexpected {_describe(token)}", span=span,
                           expected=_expected(exc.expected), hint=hint)


def glued_name_hint(text: str, token: Token) -> str | None:
    """A hint for the error at ``token`` when it or a word just before it is a term glued to a
    joining keyword (``road is WIDEand size ...``, ``speed is SLOWwith 0.5``) or such a keyword
    glued to the word after a term (``road is WIDE andsize is ...``, ``steering is RS andspeed
    is ...``): one name to the lexer, and the error said only what was expected there (or,
    for ``andspeed is``, that ``andspeed`` was a new rule's label without its ``:``)."""
    lines = lines_of(text)
    if token.type == "$END" or token.line is None or token.column is None \
            or token.line > len(lines):
        return None
    words = lines[token.line - 1][:token.column - 1].split()
    if token.type == "NAME":
        words.append(str(token))
    modifiers = {"is", "not", *HEDGE_NAMES}
    for i in range(len(words) - 1, max(len(words) - 3, 0), -1):
        word = words[i]
        if not re.fullmatch(r"[A-Za-z_][\w\-]*", word) or word in RESERVED:
            continue
        if words[i - 1] in modifiers:           # a term: `WIDEand`
            hint = read_as_one_name(word, set(_JOINING), set(_JOINING))
            if hint is not None:
                return hint
        elif i >= 2 and words[i - 2] in modifiers:      # after a term: `andsize`
            said = next((k for k in _JOINING if word.startswith(k) and len(word) > len(k)
                         and (word[len(k)].isalpha() or word[len(k)] == "_")), None)
            if said is not None:
                return (f"`{word}` is read as one name: `{said}` and `{word[len(said):]}` are "
                        f"two words")
    return None


def _word_before(text: str, token: Token) -> str:
    """The word just before ``token`` on its line (for hints)."""
    lines = lines_of(text)
    if token.line is None or token.column is None or not 0 < token.line <= len(lines):
        return ""
    words = lines[token.line - 1][:token.column - 1].split()
    return words[-1] if words else ""


def shift(span: Span | None, lines: int) -> Span | None:
    """``span`` moved down ``lines`` lines (text parsed alone, taken from a longer file)."""
    if span is None or not lines:
        return span
    import dataclasses

    return dataclasses.replace(span, line=span.line + lines)


def _span(meta: Meta | SimpleNamespace, text: str, path: str | None) -> Span | None:
    if getattr(meta, "empty", True):
        return None
    return Span.at(text, path, meta.start_pos, meta.line, meta.column, meta.end_column
                   if meta.end_line == meta.line else None)


#: what ``v_args(meta=True)`` marks a method with
_WITH_META = getattr(v_args(meta=True)(lambda self, meta, items: None), "visit_wrapper")  # noqa: B009


@functools.cache
def _callback(cls: type, name: str) -> Callable[[Transformer, Meta, list], object] | None:
    """``cls``'s method for the rule ``name`` as ``f(self, meta, children)``; None where Lark's
    own dispatch must decide (no such method, or another kind of ``v_args``)."""
    if name.startswith("_") or not hasattr(cls, name):
        return None
    found = next(vars(k)[name] for k in cls.__mro__ if name in vars(k))
    wrapper = getattr(found, "visit_wrapper", None)
    if wrapper is _WITH_META:
        base = found.base_func
        return lambda self, meta, children: base(self, meta, children)
    if wrapper is None and inspect.isfunction(found):
        return lambda self, meta, children: found(self, children)
    return None


class _ToModel(Transformer):
    """Tree -> model objects. Only builds: names are checked later."""

    def __init__(self, text: str, path: str | None, line_offset: int = 0) -> None:
        super().__init__(visit_tokens=False)  # tokens are kept as they are
        self.text, self.path = text, path
        self.counter = 0
        self.line_offset = line_offset        # the text starts at this line + 1 of its file

    def _transform_tree(self, tree: Tree) -> Any:     # what the callbacks build (model objects, tuples)
        """Lark's walk, without its generator per node (tokens are kept as they are)."""
        return self._call_userfunc(tree, [self._transform_tree(c) if isinstance(c, Tree) else c
                                          for c in tree.children])

    def _call_userfunc(self, tree: Tree, new_children: list | None = None) -> Any:
        """Lark's dispatch makes a new wrapper object at each node for a ``v_args`` method
        (a third of the transform of 10,000 rules); the method is found once per class."""
        call = _callback(type(self), tree.data)
        if call is None:
            return super()._call_userfunc(tree, new_children)
        children = tree.children if new_children is None else new_children
        try:
            return call(self, tree.meta, children)
        except Exception as exc:
            raise VisitError(tree.data, tree, exc) from exc

    def _s(self, meta: Meta | SimpleNamespace) -> Span | None:   # (teach builds a Meta's fields)
        span = _span(meta, self.text, self.path)
        return shift(span, self.line_offset)

    def transform(self, tree: Tree) -> Any:
        """Lark wraps what a callback raises in ``VisitError``; a MITOS error raised while
        building (a number past a float's range) is the user's, so it comes out as itself."""
        try:
            return super().transform(tree)
        except VisitError as exc:
            if isinstance(exc.orig_exc, MitosError):
                raise exc.orig_exc from None
            raise

    @v_args(meta=True)
    def number(self, meta: Meta, items: list[Token]) -> float:
        value = float(items[0])
        if math.isinf(value):             # the grammar's numbers have no `inf`: 1e400 overflowed
            raise RuleSyntaxError(f"`{items[0]}` is past a float's range", span=self._s(meta),
                                  expected="a number within ±1.8e308")
        if value == 0 and any(c in "123456789" for c in items[0].lower().partition("e")[0]):
            # 1e-400 underflowed: `with 1e-400` would switch the rule off without a word
            raise RuleSyntaxError(f"`{items[0]}` is too small for a float: it would read as 0",
                                  span=self._s(meta),
                                  expected="0, or a number of magnitude at least 5e-324")
        return value

    @v_args(meta=True)
    def proposition(self, meta: Meta, items: list[Token]) -> Prop:
        var, *mods, term = items
        negated = False
        hedges = []
        for m in mods:
            if m.type == "NOT":
                negated = not negated
            else:
                hedges.append(str(m))
        return Prop(str(var), str(term), tuple(hedges), negated, self._s(meta))

    @v_args(meta=True)
    def negation(self, meta: Meta, items: list[Expr]) -> Not:
        return Not(items[0], self._s(meta))

    @v_args(meta=True)
    def and_expr(self, meta: Meta, items: list[Expr]) -> And:
        flat: list[Expr] = []
        for item in items:
            flat.extend(item.items if isinstance(item, And) else [item])
        return And(tuple(flat), self._s(meta))

    @v_args(meta=True)
    def or_expr(self, meta: Meta, items: list[Expr]) -> Or:
        flat: list[Expr] = []
        for item in items:
            flat.extend(item.items if isinstance(item, Or) else [item])
        return Or(tuple(flat), self._s(meta))

    @v_args(meta=True)
    def term_consequent(self, meta: Meta, items: list[Token]) -> Consequent:
        var, *mods, term = items
        return Consequent(str(var), str(term), None, tuple(str(m) for m in mods), self._s(meta))

    @v_args(meta=True)
    def crisp_consequent(self, meta: Meta, items: list[Token | float]) -> Consequent:
        return Consequent(str(items[0]), None, float(items[1]), (), self._s(meta))

    def label(self, items: list[Token]) -> str:
        return str(items[0])

    @v_args(meta=True)
    def weight(self, meta: Meta, items: list[float]) -> _Weight:
        return _Weight(items[0], self._s(meta))

    @v_args(meta=True)
    def rule(self, meta: Meta, items: list[Any]) -> Rule | tuple:   # (label, expr, consequents..., weight)
        label, antecedent, *consequents, weight = items
        for c in consequents:
            if isinstance(c, tuple):
                return c
        return Rule(label or "", antecedent, tuple(consequents),
                    1.0 if weight is None else weight.value, self._s(meta),
                    None if weight is None else weight.span)

    @v_args(meta=True)
    def use_stmt(self, meta: Meta, items: list[Any]) -> Use:        # (name, condition, weight)
        name, condition, weight = items
        return Use(str(name), condition, 1.0 if weight is None else weight.value, self._s(meta),
                   None if weight is None else weight.span)

    def frozen_stmt(self, items: list[Any]  # tokens (Lark types their line and column Optional)
                    ) -> tuple[str, tuple[str, ...], tuple[Span | None, ...]]:
        return ("frozen", tuple(str(i) for i in items),
                tuple(shift(Span.at(self.text, self.path, i.start_pos, i.line, i.column,
                                    i.end_column), self.line_offset) for i in items))

    @v_args(meta=True)
    def op_assign(self, meta: Meta, items: list[Any]) -> Setting:   # (name, a token or a number)
        value = items[1]
        if isinstance(value, Token):
            value = str(value)
        else:                      # a number: as written (`1e9`, not the float's 1000000000.0)
            value = self.text[meta.start_pos:meta.end_pos].split("=", 1)[1].strip()
        return Setting(str(items[0]), value, self._s(meta))

    def operators_stmt(self, items: list[Setting]) -> tuple[str, tuple[Setting, ...]]:
        return ("operators", tuple(items))

    @v_args(meta=True)
    def terms_stmt(self, meta: Meta, items: list[Any]  # tokens, as frozen_stmt's
                   ) -> tuple[str, tuple[tuple[str, Span], ...]]:
        spans = []
        for tok in items:
            spans.append((_unquote(tok), Span.at(self.text, self.path, tok.start_pos,
                                                 tok.line, tok.column, tok.end_column)))
        return ("terms", tuple(spans))

    @v_args(meta=True)
    def behavior(self, meta: Meta, items: list[Any]) -> tuple[str, str, list, Span | None]:
        name, *body = items
        return ("behavior", str(name), body, self._s(meta))


def _unquote(token: Token) -> str:
    """A quoted file name's text (JSON escapes; a malformed escape is kept as written)."""
    import json

    try:
        return json.loads(str(token), strict=False)
    except ValueError:          # `"a\q"`: the grammar allows escapes JSON does not
        return str(token)[1:-1]


#: how deep conditions may nest (`not (not (a or (b and ...)))`): far beyond any readable
#: rule, and shallow enough for every later pass, which walks expressions recursively
MAX_NESTING = 100


def parse_tree(text: str, path: str | None = None, start: str = "start") -> Tree:
    try:
        tree = parse_apart(parser(), text, start=start,
                           apart=lambda a, b: keyword_glued(a, b, parser()))
    except Glued as glued:
        raise glued_error(glued, text, path, parser(), start) from None
    except UnexpectedInput as exc:
        raise syntax_error(exc, text, path) from None
    check_nesting(tree, text, path)
    check_modifiers(tree, text, path)
    return tree


def glued_error(glued: Glued, text: str, path: str | None, parser: Lark, start: str,
                words: Callable[[Iterable[str]], str | None] | None = None
                ) -> RuleSyntaxError:
    """A keyword glued to the word after it (``r1: ifroad is ...``, ``with0.5``, ``adapt
    epochs50``), which the lexer read as the keyword and the word: said at the word, with what
    could stand there (``words`` names the terminals) and "two words" (``road isWIDE`` as
    `_glued_is_error` says it), or "did you mean" the keyword (``iff``, ``thenn``)."""
    first, second = glued.first, glued.second
    start_pos, end_pos = first.start_pos or 0, second.end_pos or 0
    word = text[start_pos:end_pos]
    # `iff`, `iss`, `ifff`: a keyword and a letter, or its last letter again, is misspelt
    typo = str(second).isalpha() and (len(str(second)) == 1 or
                                      set(str(second).lower()) == {str(first)[-1:].lower()})
    if first.type == "IS" and glued.fits:
        return _glued_is_error(text, path, _name_before(text, start_pos) or "x", start_pos,
                               end_pos, None if typo else str(second))
    expected = accepted_before(parser, text, first, start)
    keywords = [e.lower() for e in expected if e.isupper() and e.isalpha() and e != "NAME"]
    said = next((k for k in keywords if word.startswith(k) and len(word) > len(k)), None)
    hint = None
    if typo:
        hint = did_you_mean(word, keywords)
    elif glued.fits and (_keyword(parser, first) or _keyword(parser, second)):
        hint = f"`{first}` and `{second}` are two words: `{first} {second}`"
    elif said is not None:          # `with0.5`: the name `with0`, then `.5`
        hint = f"`{said}` and `{word[len(said):]}` are two words: `{said} {word[len(said):]}`"
    elif not glued.fits:
        hint = did_you_mean(word, keywords)
    line, column = first.line or 1, first.column or 1
    return RuleSyntaxError(f"unexpected `{word}`",
                           span=Span.in_text(text, path, line, column, column + len(word)
                                             if "\n" not in word else None),
                           expected=(words or _expected)(expected), hint=hint)


def _name_before(text: str, end: int) -> str | None:
    r"""The name that ends ``text[:end]``, blanks after it aside (``road`` of ``if road
    isWIDE``), found from the end: ``re.search(r"([A-Za-z_][\w\-]*)\s*$", text[:end])`` tried
    every start in every word of the file, so a 20,000-letter word in a comment took 2.6 s to
    say ``isWIDE`` (40,000: 10 s)."""
    before = text[:end].rstrip()
    i = len(before)
    while i and (before[i - 1].isalnum() or before[i - 1] in "_-"):
        i -= 1
    word = before[i:]
    first = next((k for k, c in enumerate(word) if c == "_" or c.isascii() and c.isalpha()),
                 None)
    return word[first:] if first is not None else None


def keyword_glued(first: Token, second: Token, parser: Lark) -> bool:
    """A keyword of ``parser`` cut out of one word with what touches it (``ifroad``,
    ``with0.5``): names are ASCII, and a number glued to a name (``90x``) is said by
    :func:`syntax_error`."""
    return one_word(first, second) and str(first)[-1:].isascii() and \
        str(second)[:1].isascii() and (_keyword(parser, first) or _keyword(parser, second))


def _keyword(parser: Lark, token: Token) -> bool:
    """Whether ``token`` is a keyword of ``parser``'s grammar (``if``, ``seed``), as opposed to
    a name, a number or a file name."""
    from lark.lexer import PatternStr

    return any(t.name == token.type and isinstance(t.pattern, PatternStr)
               and t.pattern.value.isalpha() for t in parser.terminals)


#: `road iss WIDE`, read as `road is s` and then "unexpected `WIDE`"
_GLUED_BEFORE = re.compile(r"(?<![\w-])([A-Za-z_][\w-]*)[ \t]+(is\w[\w-]*)\s*$")


def _glued_is_error(text: str, path: str | None, var: str, start: int, end: int,
                    rest: str | None) -> RuleSyntaxError:
    """``is`` glued to the word after it, ``text[start:end]``, after the variable ``var``."""
    word = text[start:end]
    line = text.count("\n", 0, start) + 1
    column = start - (text.rfind("\n", 0, start) + 1) + 1
    hint = (f"`is` and `{rest}` are two words: `{var} is {rest}`" if rest is not None else
            did_you_mean(word, ["is"]) or f"`{var}` is a variable: write `{var} is TERM`")
    return RuleSyntaxError(f"unexpected `{word}`",
                           span=Span.in_text(text, path, line, column, column + len(word)),
                           expected="`is`", hint=hint)


#: what ``then y is not A`` is refused as: (the thing, the hint), or a hint made from its
#: variable and term; a lesson's targets (``correct ... -> steering is not LM``) say their own
TARGETS = ("a target", "a target is a term, with hedges if need be (`steering is very LM`); "
                       "`not` says what it should not be, which is no target")


def check_modifiers(tree: Tree, text: str, path: str | None,
                    actions: tuple[str, str] | None = None) -> None:
    """Refuse a ``not`` after a hedge (``x is very not LOW``), and any ``not`` in an action
    (``then y is not A``; ``actions`` names what actions are in the text, see :data:`TARGETS`).

    A proposition holds its hedges and one ``negated`` flag, applied last: ``very not LOW``
    would be evaluated as ``not very LOW`` (1 - 0.7^2 = 0.51 where very(1 - 0.7) = 0.09 was
    written). Refused, at the ``not``, rather than read as a different number.
    """
    if not any(_misplaced_not(node) for node in _subtrees(tree)):
        return                            # the usual case, without Lark's ordered walk
    for node in tree.iter_subtrees():     # the first in Lark's order, as before
        if node.data == "term_consequent":
            _check_action(node, text, path, actions)
        if node.data != "proposition":
            continue
        var, *mods, term = node.children
        tokens = [m for m in mods if isinstance(m, Token)]      # NOT and HEDGE, as written
        types = [m.type for m in tokens]
        if "HEDGE" not in types or "NOT" not in types[types.index("HEDGE"):]:
            continue
        hedge = tokens[types.index("HEDGE")]
        late = tokens[types.index("NOT", types.index("HEDGE"))]
        raise RuleSyntaxError(
            f"`not` after a hedge (`{var} is {' '.join(map(str, mods))} {term}`) is not "
            f"supported", span=Span.in_text(text, path, late.line or 1, late.column or 1,
                                            (late.column or 1) + len(late)),
            expected="`not` before the hedges: `VARIABLE is not HEDGE TERM`",
            hint=f"`{var} is not {hedge} {term}` means 1 - {hedge}({term}), a different "
                 f"number; for {hedge}(1 - {term}), define the complement of `{term}` as a "
                 f"term of `{var}` in the term set and write `{var} is {hedge} THAT_TERM`")


def _subtrees(tree: Tree) -> Iterator[Tree]:
    """Every subtree, in no particular order (a plain stack: Lark's ``iter_subtrees`` orders
    them and costs as much as the checks themselves)."""
    stack = [tree]
    while stack:
        node = stack.pop()
        yield node
        stack.extend(child for child in node.children if isinstance(child, Tree))


def _misplaced_not(node: Tree) -> bool:
    """Whether :func:`check_modifiers` refuses ``node``: a ``not`` in an action, or after a
    hedge."""
    if node.data == "term_consequent":
        return any(isinstance(m, Token) and m.type == "ACTION_NOT" for m in node.children[1:-1])
    if node.data != "proposition":
        return False
    types = [m.type for m in node.children[1:-1] if isinstance(m, Token)]
    return "HEDGE" in types and "NOT" in types[types.index("HEDGE"):]


def check_nesting(tree: Tree, text: str, path: str | None, limit: int = MAX_NESTING) -> None:
    """Refuse a tree nested deeper than ``limit`` (walked without recursion), at the first
    node past the limit."""
    stack = [(tree, 0)]
    while stack:
        node, depth = stack.pop()
        if depth > limit:
            meta = node.meta
            span = None if getattr(meta, "empty", True) else Span.at(
                text, path, meta.start_pos, meta.line, meta.column)
            raise RuleSyntaxError(f"conditions nested more than {limit} deep", span=span,
                                  hint="split the condition into several rules, or drop "
                                       "doubled `not`s and parentheses")
        stack.extend((child, depth + 1) for child in node.children if isinstance(child, Tree))


def _check_action(node: Tree, text: str, path: str | None,
                  actions: tuple[str, str] | None = None) -> None:
    """Refuse ``then y is not A``: an action sets an output to a term, never to a complement
    (the grammar reads the ``not`` only to say so here)."""
    var, *mods, term = node.children
    late = next((m for m in mods if isinstance(m, Token) and m.type == "ACTION_NOT"), None)
    if late is None:
        return
    exc = _not_in_action(text, path, late.line or 1, late.column or 1, str(var),
                         [str(m) for m in mods if isinstance(m, Token) and m.type == "HEDGE"],
                         str(term))
    if actions is not None:
        exc.message = exc.message.replace("an action", actions[0])
        exc.hint = actions[1]
    raise exc


def _not_in_action(text: str, path: str | None, line: int, column: int, var: str,
                   hedges: list[str], term: str | None) -> RuleSyntaxError:
    """The error at the ``not`` of ``then VAR is [HEDGE ...] not ...``."""
    written = " ".join([var, "is", *hedges, "not"] + ([term] if term else []))
    return RuleSyntaxError(
        f"`not` is not allowed in an action (`{written}`)",
        span=Span.in_text(text, path, line, column, column + 3),
        expected=f"`{var} is {' '.join(hedges + ['TERM'])}` or `{var} is NUMBER`",
        hint=f"an action sets `{var}` to a term, not to its complement: name the term meant "
             f"(or add one to the term set), or put the `not` in the condition "
             f"(`if not ... then {var} is {term or 'TERM'}`)")


#: ``VAR is [HEDGE ...] not`` followed by at most two words before the end of the text; the
#: search fails at once at every place but an identifier before ``is``, so it is linear in
#: the text (an unanchored scan for the last such `not` was quadratic: 2 s on 16 KB)
_ACTION_NOT = re.compile(r"\b([A-Za-z_][\w\-]*)\s+is\s+((?:(?:" + "|".join(HEDGE_NAMES)
                         + r")\s+)*)not(?![\w\-])(?:\s*\S+){0,2}\s*\Z")


def not_in_action_before(exc: UnexpectedInput, text: str, path: str | None,
                         actions: str = r"\bthen\b") -> RuleSyntaxError | None:
    """``then y is not`` with nothing a term could be after it (``y is not`` at the end of
    the file, or before ``with``): the parse fails a word or two later, at what was read as
    the term or a new rule's label; the `not` is the mistake, said there."""
    pos = getattr(exc, "pos_in_stream", None)
    if isinstance(exc, UnexpectedToken):
        pos = exc.token.start_pos if exc.token.type != "$END" else len(text)
    if pos is None:
        pos = len(text)
    before = text[:pos]
    then = [m.end() for m in re.finditer(actions, before, re.M)]
    if not then:
        return None
    found = _ACTION_NOT.search(before, then[-1])
    if found is None or re.search(r"\bif\b", before[then[-1]:found.start()]):
        return None
    at = found.start(2) + len(found.group(2))
    line = before.count("\n", 0, at) + 1
    column = at - (before.rfind("\n", 0, at) + 1) + 1
    return _not_in_action(text, path, line, column, found.group(1), found.group(2).split(),
                          None)


#: the longest rule file read (characters; FCL, FLL and .fis too): Lark takes some 5 ms a KB of
#: rules (FCL 9), and a 12 MB file of 200,000 rules took a minute and 1.7 GB, 256 MB would take
#: hours; the packaged rule base holds 8 KB. 16 MB, not 4: 100,000 rules of the reliability
#: page's kind (11 MB) load in about a minute, a documented size
MAX_RULE_FILE_CHARS = 16 << 20


def check_rule_file_size(text: str, path: str | None) -> None:
    """Refuse a rule file longer than :data:`MAX_RULE_FILE_CHARS`, before it is parsed."""
    if len(text) > MAX_RULE_FILE_CHARS:
        raise RuleSyntaxError(f"the file holds {len(text):,} characters; a rule file may hold "
                              f"at most {MAX_RULE_FILE_CHARS:,} ({MAX_RULE_FILE_CHARS >> 20} "
                              f"MB)", span=Span(path, 1, 1) if path else None,
                              hint="split the rule base into several files")


@without_cyclic_gc
def parse_rules(text: str, path: str | None = None) -> ParsedFile:
    """Parse a whole rule file into model objects (names unchecked)."""
    check_rule_file_size(text, path)
    text = lone_cr_as_lf(text)
    tree = parse_tree(text, path)
    items = _ToModel(text, path).transform(tree).children
    terms: list[tuple[str, Span]] = []
    operators: list[Setting] = []
    rules: list[Rule] = []
    uses: list[Use] = []
    frozen: list[str] = []
    behaviors: list[Behavior] = []
    frozen_spans: list[Span | None] = []
    for item in items:
        _collect(item, terms, operators, rules, uses, frozen, behaviors, frozen_spans)
    return ParsedFile(text, path, tuple(terms), tuple(operators), tuple(rules), tuple(uses),
                      tuple(frozen), tuple(behaviors), tuple(frozen_spans))


def check_settings(settings: tuple[Setting, ...]) -> tuple[Setting, ...]:
    """One ``operators:`` line sets each operator once: ``and = min, and = product`` would
    keep the last without a word. (Later lines may change what earlier ones set.)"""
    seen: dict[str, Setting] = {}
    for s in settings:
        if s.key in seen:
            raise RuleSyntaxError(f"`{s.key}` is set twice on one operators line "
                                  f"(`{seen[s.key].value}`, then `{s.value}`)", span=s.span,
                                  hint="keep one of them")
        seen[s.key] = s
    return settings


def _collect(item: Rule | Use | tuple, terms: list[tuple[str, Span]], operators: list[Setting],
             rules: list[Rule], uses: list[Use], frozen: list[str], behaviors: list[Behavior],
             frozen_spans: list[Span | None] | None = None) -> None:
    frozen_spans = [] if frozen_spans is None else frozen_spans
    if isinstance(item, Rule):
        rules.append(item)
    elif isinstance(item, Use):
        uses.append(item)
    elif isinstance(item, tuple) and item[0] == "error":
        raise RuleSyntaxError(item[1], span=item[2])
    elif item[0] == "terms":
        terms.extend(item[1])
    elif item[0] == "operators":
        operators.extend(check_settings(item[1]))
    elif item[0] == "frozen":
        frozen.extend(item[1])
        frozen_spans.extend(item[2])
    elif item[0] == "behavior":
        _, name, body, span = item
        b_rules: list[Rule] = []
        b_ops: list[Setting] = []
        b_uses: list[Use] = []
        b_frozen: list[str] = []
        b_spans: list[Span | None] = []
        for sub in body:
            _collect(sub, [], b_ops, b_rules, b_uses, b_frozen, [], b_spans)
        behaviors.append(Behavior(name, tuple(b_rules), tuple(b_uses),
                                  tuple(b_ops), tuple(b_frozen), span, tuple(b_spans)))


def parse_rule(text: str, path: str | None = None) -> Rule:
    """Parse one rule (a prompt line)."""
    result = _ToModel(text, path).transform(parse_tree(text, path, start="rule"))
    if isinstance(result, tuple):
        raise RuleSyntaxError(result[1], span=result[2])
    return result


def parse_expr(text: str, path: str | None = None) -> Expr:
    """Parse a condition such as ``road is WIDE and not size is LARGE_SZ``."""
    return _ToModel(text, path).transform(parse_tree(text, path, start="expr"))
