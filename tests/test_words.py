"""Counted nouns in messages (`mitos_cli.words.plural`), clearances beside their margin."""

import pytest

from mitos_cli.words import clearance, plural, tenths, with_unit


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


@pytest.mark.parametrize("x, margin, text", [
    (8.2162571612858, None, "8.2"), (-0.1, None, "-0.1"), (2.0, 2.0, "2.0"),
    (-0.04, None, "0.0"), (-0.0, None, "0.0"), (-0.04, 2.0, "0.0"),    # no -0.0
    (1.99, 2.0, "1.99"), (1.9999, 2.0, "1.9999"), (1.94, 2.0, "1.9"),
    (2.04, 2.0, "2.0"), (1.4, 2.0, "1.4"), (8.96, 9.0, "8.96"),
])
def test_a_clearance_shows_which_side_of_its_margin_it_lies(x, margin, text):
    """"min clearance -0.0 in" and "2.0 in; closer than the safety margin (2 in)" (1.99)."""
    assert clearance(x, margin) == text


@pytest.mark.parametrize("x, text", [(18.5, "18.5"), (16.0, "16"), (17.72, "17.7"),
                                     (21.96, "22"), (0.04, "0")])
def test_a_width_is_said_to_a_tenth_a_whole_one_without_its_point(x, text):
    assert tenths(x) == text
