"""Counted nouns for messages: ``plural(1, "rule")`` is ``1 rule``, ``plural(27, "rule")``
``27 rules``, so no user reads "(1 rules)"; and a clearance as it is printed beside the
margin it is compared with (:func:`clearance`); a rate that is neither none nor all never
printed as 0% or 100% (:func:`percent`)."""

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


def clearance(x: float, margin: float | None = None) -> str:
    """A clearance (in) to a tenth, as every verdict prints it, but never ``-0.0`` (a
    clearance of -0.04 in is 0.0 to a tenth), and with as many more digits as it takes to
    show which side of ``margin`` it lies on (1.99 beside a margin of 2 is ``1.99``: "2.0
    in; closer than the safety margin (2 in)" read as a contradiction)."""
    for digits in range(1, 18):
        text = f"{x:.{digits}f}"
        if margin is None or (float(text) < margin) == (x < margin):
            break
    return text[1:] if text.startswith("-") and float(text) == 0 else text


def tenths(x: float) -> str:
    """A length to a tenth of an inch, a whole one without ``.0`` (``18.5``, ``16``): a
    corridor 18.5 in wide was "18 in wide" beside a centre that keeps "9.2 in" of it."""
    text = f"{x:.1f}"
    return text[:-2] if text.endswith(".0") else text


def percent(k: int, n: int) -> str:
    """``k`` of ``n`` as a whole percentage, with as many more digits as it takes not to read
    as none or all when it is neither: 1 collision in 200 runs is ``0.5%``, not ``0%``, and
    199 successes in 200 ``99.5%``, not ``100%`` (in a published table, a planner that never
    collided)."""
    for digits in range(8):
        text = f"{100 * k / n:.{digits}f}"
        if not ((float(text) == 0 and k > 0) or (float(text) == 100 and k < n)):
            break
    return text + "%"
