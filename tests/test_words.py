"""Counted nouns in messages (`mitos_cli.words.plural`)."""

import pytest

from mitos_cli.words import plural, with_unit


@pytest.mark.parametrize("n, word, many, text", [
    (0, "rule", None, "0 rules"),
    (1, "rule", None, "1 rule"),
    (2, "rule", None, "2 rules"),
    (1, "more region", None, "1 more region"),
    (3, "entry", "entries", "3 entries"),
    (1, "entry", "entries", "1 entry"),
    (12000, "sample", None, "12,000 samples"),
])
def test_plural(n, word, many, text):
    assert plural(n, word, many) == text


@pytest.mark.parametrize("number, unit, text", [
    ("1", "objects", "1 object"), ("0", "objects", "0 objects"), ("2", "objects", "2 objects"),
    ("1.0", "objects", "1.0 objects"), ("-1", "objects", "-1 object"),
    ("1", "inches", "1 inch"), ("1", "in", "1 in"), ("1", "in/s", "1 in/s"), ("1", "s", "1 s"),
    ("1", "deg", "1 deg"), ("1", "mass", "1 mass"), ("1", "", "1"), ("1", "Pas", "1 Pas"),
])
def test_a_counted_unit_is_singular_after_exactly_one(number, unit, text):
    assert with_unit(number, unit) == text
