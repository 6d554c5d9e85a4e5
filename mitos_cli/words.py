"""Counted nouns for messages: ``plural(1, "rule")`` is ``1 rule``, ``plural(27, "rule")``
``27 rules``, so no user reads "(1 rules)"."""

from __future__ import annotations


def plural(n: int, word: str, many: str | None = None) -> str:
    """``n word``, the word in the plural unless ``n`` is 1 (``many`` spells an irregular
    plural: ``plural(2, "choice")``, ``plural(3, "entry", "entries")``). Thousands are
    grouped: ``12,000 samples``."""
    return f"{n:,} {word if n == 1 else many or word + 's'}"
