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


def test_run_takes_its_flags_as_bools_and_names_them_in_its_signature():
    """``run(X, **kwargs)`` passed anything on: ``detail="no"`` was true (memberships and DOFs
    computed and kept), ``strict=0`` false. Its keywords are now its own, checked."""
    import inspect

    import numpy as np

    from mitos_cli.errors import InputError

    rb = load_rulebase()
    X = np.array([[78.0, 45.0, 4.0]])
    assert list(inspect.signature(rb.run).parameters) == ["X", "detail", "keep_values", "strict"]
    assert rb.run(X, detail=False).dof is None and rb.run(X).dof is not None
    assert rb.run(X, detail=np.bool_(False)).dof is None
    for bad in ({"detail": "no"}, {"strict": 0}, {"keep_values": None}):
        with pytest.raises(InputError, match=f"`{next(iter(bad))}` is True or False, not"):
            rb.run(X, **bad)
    with pytest.raises(TypeError, match="detial"):
        rb.run(X, detial=False)


def test_a_results_output_by_a_name_it_lacks_says_did_you_mean():
    """``run(X).output("steerign")`` was ``ValueError: tuple.index(x): x not in tuple``."""
    import numpy as np

    from mitos_cli.errors import InputError

    result = load_rulebase().run(np.array([[78.0, 45.0, 4.0]]))
    assert result.output("speed").tolist() == [result.outputs[0, 1]]
    with pytest.raises(InputError, match="unknown output `steerign`") as err:
        result.output("steerign")
    assert "did you mean `steering`?" in str(err.value)
    with pytest.raises(InputError, match="unknown output `0`"):
        result.output(0)
