"""``mitos_cli.api`` as a Python user meets it: what ``LoadedRuleBase`` takes and what it says
when it does not."""

from __future__ import annotations

import pytest

from mitos_cli import load_rulebase
from mitos_cli.errors import NameError_


def test_with_operators_takes_and_underscore_and_suggests_it_for_a_misspelt_key():
    """The hint named ``and``, a rule file's key, which Python refuses as a keyword
    (``with_operators(and="product")`` is a SyntaxError): it names ``and_``."""
    rb = load_rulebase()
    product = rb.with_operators(and_="product")
    assert product.compiled.operators.and_ == "product"
    assert rb.with_operators(inference_="weighted_sum").compiled.operators.inference == \
        "weighted_sum"
    with pytest.raises(NameError_, match="unknown operator setting `andd`") as err:
        rb.with_operators(andd="product")
    assert "did you mean `and_`?" in str(err.value)
    assert "and_, " in str(err.value) and "or_, " in str(err.value)
    with pytest.raises(NameError_, match="did you mean `inference`"):
        rb.with_operators(inferense="mamdani")
