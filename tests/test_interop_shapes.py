"""The shapes of the foreign formats against pyfuzzylite 8's terms, point by point, with the
parameter order each reader uses (FLL and fuzzylite's FCL: fuzzylite's order), including NaN
and +/-inf inputs and values beyond every corner."""

from __future__ import annotations

import numpy as np
import pytest

from mitos_cli.fuzzy.shapes import SHAPES
from mitos_cli.interop.common import FUZZYLITE_SHAPES, fuzzylite_term
from mitos_cli.interop.fcl import JFUZZY_SHAPES
from mitos_cli.interop.fis import MF_TYPES

fl = pytest.importorskip("fuzzylite", reason="pyfuzzylite is not installed")

INF, NAN = float("inf"), float("nan")
X = np.concatenate([np.linspace(-3.0, 9.0, 601), [-INF, INF, -1e300, 1e300]])

#: fuzzylite term -> parameter sets (in fuzzylite's order)
CASES = {
    "Triangle": [(0, 2, 5), (1, 1, 4), (0, 3, 3)],
    "Trapezoid": [(0, 1, 3, 6), (0, 0, 2, 4), (-INF, -INF, 2, 4), (1, 3, INF, INF)],
    "Rectangle": [(1, 4), (4, 1)],
    "Gaussian": [(2, 0.7), (5, 3)],
    "GaussianProduct": [(1, 0.5, 3, 1), (3, 0.5, 1, 1)],
    "Bell": [(2, 1.5, 3), (4, 0.5, 1)],
    "Sigmoid": [(2, 4), (5, -2)],
    "SigmoidDifference": [(1, 5, 3, 4), (4, 10, 30, 6)],
    "SigmoidProduct": [(1, 5, -3, 4), (2, 20, -10, 5)],
    "PiShape": [(0, 2, 3, 6), (1, 1.5, 1.5, 2)],
    "SShape": [(1, 4)],
    "ZShape": [(1, 4)],
    "Ramp": [(1, 4), (4, 1)],
    "Cosine": [(3, 4), (0, 1)],
    "Spike": [(3, 4), (0, 1)],
    "Concave": [(2, 5), (5, 2), (0.85, 0.25)],
    "Arc": [(1, 4), (4, 1)],
    "Binary": [(2, INF), (2, -INF)],
    "SemiEllipse": [(1, 4), (4, 1)],
    "Discrete": [(0, 0, 1, 1, 2, 0.5, 4, 1, 6, 0), (-1, 1, 3, 0)],
}


@pytest.mark.parametrize("kind", sorted(CASES))
def test_shape_equals_fuzzylite(kind: str) -> None:
    for params in CASES[kind]:
        theirs = fl.Discrete("t", list(params)) if kind == "Discrete" else \
            getattr(fl, kind)("t", *params)
        with np.errstate(all="ignore"):      # fuzzylite's overflows are its own business
            want = np.asarray(theirs.membership(X), dtype=float)
        term = fuzzylite_term("t", kind, list(params), 0, None)    # as the FLL reader does
        with np.errstate(over="raise", invalid="raise", divide="raise"):   # none escape ours
            got = term.membership(X)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12, equal_nan=True,
                                   err_msg=f"{kind}{params}")
        assert np.isnan(term.membership(np.array([NAN]))).all()


def test_every_fuzzylite_term_type_is_mapped() -> None:
    """Every term class pyfuzzylite defines is either read (and tested above) or refused."""
    from mitos_cli.interop.common import FORMULA_TERMS

    classes = {name for name in dir(fl.term) if isinstance(getattr(fl.term, name), type)
               and issubclass(getattr(fl.term, name), fl.Term)
               and name not in ("Term", "Activated", "Aggregated")}
    assert classes <= set(FUZZYLITE_SHAPES) | set(FORMULA_TERMS), classes - set(FUZZYLITE_SHAPES)
    assert set(CASES) | {"Constant", "Linear"} == set(FUZZYLITE_SHAPES)


def test_matlab_and_jfuzzylogic_orders() -> None:
    """MATLAB's and jFuzzyLogic's parameter orders land on the same MITOS shapes."""
    x = np.linspace(-2, 8, 101)
    gauss = SHAPES["gaussian"].membership(x, (3.0, 1.2))
    sig, c = 1.2, 3.0
    matlab = dict(MF_TYPES)["gaussmf"]
    assert tuple((sig, c)[i] for i in matlab[2]) == (3.0, 1.2)
    np.testing.assert_allclose(gauss, np.exp(-(x - 3.0) ** 2 / (2 * 1.2 ** 2)), atol=1e-15)
    # gbellmf [a b c] and jFuzzyLogic's gbell a b mean are width, slope, center
    for params in (tuple((2.0, 4.0, 5.0)[i] for i in MF_TYPES["gbellmf"][2]),
                   JFUZZY_SHAPES["gbell"][2]((2.0, 4.0, 5.0))):
        assert params == (5.0, 2.0, 4.0)
        np.testing.assert_allclose(SHAPES["bell"].membership(x, params),
                                   1 / (1 + np.abs((x - 5) / 2) ** 8), atol=1e-15)
    # sigmf [a c] and jFuzzyLogic's sigm gain center: slope first
    assert tuple((2.0, 3.0)[i] for i in MF_TYPES["sigmf"][2]) == (3.0, 2.0)
    assert JFUZZY_SHAPES["sigm"][2]((2.0, 3.0)) == (3.0, 2.0)
    # jFuzzyLogic's COSINE net_max offset: (cos(pi (x - offset) / net_max) + 1) / 2 within
    # offset +- net_max (its MembershipFunctionCosine), 0 outside
    net_max, offset = 1.5, 3.0
    want = np.where(np.abs(x - offset) <= net_max,
                    (np.cos((x - offset) * np.pi / net_max) + 1) / 2, 0.0)
    got = SHAPES["cosine"].membership(x, JFUZZY_SHAPES["cosine"][2]((net_max, offset)))
    np.testing.assert_allclose(got, want, atol=1e-12)
    # linzmf [a b]: 1 below a falling to 0 at b
    ramp = SHAPES["ramp"].membership(np.array([0.0, 1.0, 1.5, 2.0, 3.0]),
                                     tuple((1.0, 2.0)[i] for i in MF_TYPES["linzmf"][2]))
    np.testing.assert_allclose(ramp, [1, 1, 0.5, 0, 0])
