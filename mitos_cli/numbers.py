"""Numbers written as text (a CSV cell, a foreign file's value), read the one way every format
here means them: ASCII decimal, an optional exponent, ``nan``, ``inf``. Python's ``float``
alone also takes ``7_8`` (78) and other scripts' digits, which no file format writes. And the
one test of a whole number given in Python (a count, a width, a number of decimals)."""

from __future__ import annotations

import math
import operator
import re

#: The largest magnitude a number of a term set or a foreign file may have. The engine
#: multiplies at most two of them (a coefficient by an input, a sample point by a membership)
#: and sums at most a million products, so every intermediate stays below 1e306, inside a
#: double's range.
LARGEST = 1e150

_NUMBER = re.compile(r"\s*[-+]?(?:(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][-+]?[0-9]+)?"
                     r"|nan|inf|infinity)\s*", re.IGNORECASE | re.ASCII)


def parse_number(text: str) -> float:
    """``text`` as a float; ``ValueError`` for anything else (``7_8``, ``٧٨``, ``0x10``)."""
    if not _NUMBER.fullmatch(text):
        raise ValueError(f"not a number: {text!r}")
    return float(text)


def parse_value(text: str) -> float:
    """An input's value written as text: :func:`parse_number`, but a finite number past a
    float's range (``1e400``) is an ``OverflowError``, as ``10**400`` is, not ``inf``; ``inf``
    written as such stays ``inf``."""
    x = parse_number(text)
    if math.isinf(x) and "inf" not in text.lower():
        raise OverflowError(f"too large for a float: {text!r}")
    return x


def exact(x: float) -> str:
    """``x`` as ``:g`` writes it where that reads back as ``x`` (``78``, ``1e+308``, ``nan``),
    else the shortest text that does (``10.0000001``, which ``:g`` writes ``10``): a message
    that compares two numbers, or echoes one given, must not print different ones alike
    ("w = 100 lies outside its universe [0, 100]")."""
    text = f"{x:g}"
    return text if x != x or float(text) == x else repr(float(x))


def whole_number(value: object) -> int | None:
    """``value`` as an ``int`` where it is a whole number (an ``int``, NumPy's too), else
    ``None``: ``True`` is no 1, and ``2.5`` or ``"3"`` no whole number."""
    import numpy as np

    if isinstance(value, (bool, np.bool_)):
        return None
    try:
        return operator.index(value)  # type: ignore[arg-type]
    except TypeError:
        return None
