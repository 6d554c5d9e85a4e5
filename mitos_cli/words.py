"""Counted nouns for messages: ``plural(1, "rule")`` is ``1 rule``, ``plural(27, "rule")``
``27 rules``, so no user reads "(1 rules)"."""

from __future__ import annotations


def plural(n: int, word: str, many: str | None = None) -> str:
    """``n word``, the word in the plural unless ``n`` is 1 (``many`` spells an irregular
    plural: ``plural(2, "choice")``, ``plural(3, "entry", "entries")``). Thousands are
    grouped: ``12,000 samples``."""
    return f"{n:,} {word if n == 1 else many or word + 's'}"


def with_unit(number: str, unit: str) -> str:
    """``number unit`` as a person writes it: a counted unit in the singular after exactly one
    (``1 object``, ``2 objects``, ``1.0 objects``, ``1 in/s``, ``1 s``). A unit is taken as a
    counted noun when it is a lower-case word of three letters or more ending in ``s``; one
    in ``ches``, ``shes``, ``xes`` or ``sses`` drops ``es`` (``inches``)."""
    if not unit:
        return number
    if number.lstrip("+-") == "1" and len(unit) >= 3 and unit.isalpha() and unit.islower() \
            and unit.endswith("s") and not unit.endswith("ss"):
        unit = unit[:-2] if unit.endswith(("ches", "shes", "xes", "sses")) else unit[:-1]
    return f"{number} {unit}"
