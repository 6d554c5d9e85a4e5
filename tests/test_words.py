"""Counted nouns in messages (`mitos_cli.words.plural`)."""

import pytest

from mitos_cli.words import plural


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
