"""Parsing with words kept whole (rule files, lessons, FCL files, FLL ``rule:`` lines).

Where a grammar allows only a keyword, Lark's contextual lexer looks for that keyword alone, so
it takes a keyword off the front of a longer word and reads the rest as the next token:
``IF dist ISlo`` was read as ``IS lo``, ``WITH0.5`` as ``WITH 0.5``, ``END_FUZZIFYDEFUZZIFY``
as two keywords. The engines that wrote these formats cut words apart only at blanks and
punctuation (jFuzzyLogic's ANTLR lexer takes the longest match, fuzzylite splits a rule at its
spaces), and refuse such a word where a keyword stands; :func:`parse_apart` does too, and so
does the rule language, whose every keyword is a word of its own.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from lark.exceptions import UnexpectedToken

if TYPE_CHECKING:
    from collections.abc import Callable

    from lark import Lark, Token, Tree


class Glued(Exception):
    """``first`` and ``second`` were cut out of one word; ``fits`` says whether ``second`` may
    follow ``first`` there (two words written as one: ``ISlo``) or not (a misspelt keyword:
    ``END_RULEBLOCKx``)."""

    def __init__(self, first: Token, second: Token, fits: bool) -> None:
        super().__init__(f"{first}{second}")
        self.first, self.second, self.fits = first, second, fits


def _word_char(c: str) -> bool:
    return c.isalnum() or c == "_"


def one_word(first: Token, second: Token) -> bool:
    """Whether the lexer cut ``first`` and ``second`` out of one word (``IS`` and ``lo`` out of
    ``ISlo``, ``WITH`` and ``0.5`` out of ``WITH0.5``, ``0.5`` and ``.5`` out of ``0.5.5``)."""
    if first.end_pos != second.start_pos:       # the usual case: a blank or a comment between
        return False
    a, b = str(first), str(second)
    return _word_char(a[-1:] or " ") and \
        (_word_char(b[:1] or " ") or (b[:1] == "." and b[1:2].isdigit()))


def parse_apart(parser: Lark, text: str, start: str | None = None,
                apart: Callable[[Token, Token], bool] = one_word) -> Tree:
    """``parser.parse(text, start)``, raising :class:`Glued` at two tokens cut out of one word
    (``apart`` says which: :func:`one_word`, or a language's own exceptions to it).

    Lark's errors are raised as they are, each :class:`UnexpectedToken` with its
    ``interactive_parser`` and, as ``token_history``, the token before it."""
    interactive = parser.parse_interactive(text, start=start)
    last: Token | None = None
    try:
        for token in interactive.iter_parse():
            # (the positions first: a blank or a comment between is the usual case)
            if last is not None and last.end_pos == token.start_pos and apart(last, token):
                raise Glued(last, token, token.type in interactive.accepts())
            last = token
        return interactive.feed_eof(last)
    except UnexpectedToken as exc:
        if last is not None and exc.token.type != "$END" and apart(last, exc.token):
            # `END_RULEBLOCKx`: the rest of the word refused after the keyword
            raise Glued(last, exc.token, False) from None
        if exc.interactive_parser is None:      # set by Lark's parse(), not by feed_token()
            exc.interactive_parser = interactive
        if not exc.token_history and last is not None:
            exc.token_history = [last]
        raise


def accepted_before(parser: Lark, text: str, token: Token, start: str | None = None
                    ) -> set[str]:
    """The terminals ``parser`` accepts where ``token`` of ``text`` begins (``text`` parsed
    again up to it: only on an error, and linear)."""
    interactive = parser.parse_interactive(text[:token.start_pos], start=start)
    for _ in interactive.iter_parse():
        pass
    return set(interactive.accepts())


def read_as_one_name(name: str, expected: set[str], keywords: set[str],
                     fold: Callable[[str], str] = str) -> str | None:
    """A hint for ``name``, a word the lexer read as one name (as the engines do) before a
    syntax error, when it is a word glued to a keyword the parser expects next (``poorTHEN``,
    ``REALRANGE``) or two keywords glued (``END_VARVAR_OUTPUT``). ``fold`` puts a word in the
    keywords' case (``str.upper`` for FCL, whose keywords are in any case)."""
    folded = fold(name)
    for keyword in sorted(keywords, key=len, reverse=True):
        cut = len(name) - len(keyword)
        if cut > 0 and folded.endswith(keyword) and (keyword in expected or
                                                     folded[:cut] in keywords):
            return (f"`{name}` is read as one name: `{name[:cut]}` and `{name[cut:]}` are two "
                    f"words")
    return None
