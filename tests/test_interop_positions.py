"""Numbers a reader cannot compute with are refused where they are written: a range that is
infinite, NaN, empty or too narrow, or a defuzzifier resolution beyond what MITOS samples
(each once told at the variable's name or at 1:1), in FLL, FIS and FCL."""

from __future__ import annotations

import pytest
from test_interop_errors import FCL, FIS, FLL, line_of

from mitos_cli.errors import MitosError
from mitos_cli.interop.fcl import parse_fcl
from mitos_cli.interop.fis import parse_fis
from mitos_cli.interop.fll import parse_fll


def _refused(parse, text: str, at: str, words: str) -> None:
    """``parse`` refuses ``text`` saying ``words``, its span starting where ``at`` does."""
    with pytest.raises(MitosError) as info:
        parse(text, "bad")
    span = info.value.span
    assert words in info.value.message, info.value.render()
    assert span is not None and span.line == line_of(text, at), info.value.render()
    assert span.column == text.splitlines()[span.line - 1].index(at) + 1, info.value.render()


@pytest.mark.parametrize("old, new, at, words", [
    ("range: 0 10", "range: -inf inf", "-inf inf", "the range is -inf"),
    ("range: 0 10", "range: nan 10", "nan 10", "its ends must be numbers"),
    ("range: 0 10", "range: 10 10", "10 10", "range [10, 10] is empty"),
    ("range: 0 10", "range: 0 1e-302", "0 1e-302", "too narrow to compute with"),
    ("range: 0 10", "range: 0 1e-320", "0 1e-320", "too narrow to compute with"),
    ("defuzzifier: Centroid 200", "defuzzifier: Centroid 1e9", "Centroid 1e9",
     "resolution must be a whole number from 3 to 100000"),
])
def test_fll(old: str, new: str, at: str, words: str) -> None:
    _refused(parse_fll, FLL.replace(old, new, 1), at, words)


@pytest.mark.parametrize("new, words", [
    ("Range=[-inf inf]", "the range is -inf"),
    ("Range=[0 1e-320]", "too narrow to compute with"),
])
def test_fis(new: str, words: str) -> None:
    assert "Range=[0 10]" in FIS
    _refused(parse_fis, FIS.replace("Range=[0 10]", new, 1), new[len("Range="):], words)


@pytest.mark.parametrize("new, words", [
    ("RANGE := (0 .. 1e-320);", "too narrow to compute with"),
    ("RANGE := (-inf .. inf);", "the range is -inf"),
])
def test_fcl(new: str, words: str) -> None:
    assert "RANGE := (0 .. 30);" in FCL
    _refused(parse_fcl, FCL.replace("RANGE := (0 .. 30);", new, 1), new[:-1], words)
