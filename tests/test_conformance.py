"""Conformance: MITOS's readers and engine against published reference outputs.

1. pyfuzzylite 8 ships ~60 FLL engines, each with an ``.fld`` table of inputs and the outputs
   fuzzylite computed (found in the installed package at test time; pyfuzzylite is in the
   ``test`` extra). Every engine MITOS reads must reproduce its table within 1e-6; every engine
   MITOS refuses must be refused for the documented reason; the one table that differs is
   explained (``docs/conformance.md``).
2. MATLAB's documentation publishes ``evalfis`` outputs of its tipper: MITOS's ``.fis`` reader
   reproduces them to the printed digits.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from mitos_cli.api import read_rulebase
from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.errors import FormatError

DATA = Path(__file__).parent / "data" / "interop"
TOLERANCE = 1e-6


def examples_dir() -> Path | None:
    spec = importlib.util.find_spec("fuzzylite")
    if spec is None or not spec.submodule_search_locations:
        return None
    path = Path(list(spec.submodule_search_locations)[0]) / "examples"
    return path if path.is_dir() else None


EXAMPLES = examples_dir()
FILES = sorted(p.relative_to(EXAMPLES).as_posix() for p in EXAMPLES.rglob("*.fll")) \
    if EXAMPLES else []
needs_fuzzylite = pytest.mark.skipif(EXAMPLES is None, reason="pyfuzzylite is not installed "
                                     "(pip install -e '.[test,agreement]'); its examples are the reference")

#: Engines MITOS refuses, and the words of the refusal (its cause).
REFUSED = {
    "takagi_sugeno/approximation.fll": "lock-previous: true",
}
#: Engines MITOS reads whose table it does not match, and why (checked below).
MISMATCH = {
    # the .fld was written by an older fuzzylite; pyfuzzylite 8 itself differs from it by
    # the same 7.6e-5, and MITOS agrees with pyfuzzylite 8 to 1e-12
    "terms/discrete.fll": "pyfuzzylite 8 disagrees with its own table",
}


def read_fld(path: Path) -> tuple[list[str], np.ndarray]:
    lines = path.read_text().splitlines()
    return lines[0].split(), np.array([[float(v) for v in line.split()]
                                       for line in lines[1:] if line.strip()])


def mitos_outputs(fll: Path) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """MITOS's outputs on the table's inputs, and the table's outputs, by name (a hybrid
    engine read as one behavior per rule block: each behavior gives its own outputs)."""
    rb = read_rulebase(fll)
    header, table = read_fld(fll.with_suffix(".fld"))
    col = {name: i for i, name in enumerate(header)}
    got = {}
    for behavior in rb.behaviors:
        compiled = compile_rulebase(rb, behavior.name)
        X = table[:, [col[name] for name in compiled.inputs]]
        result = evaluate(compiled, X, strict=False, detail=False)
        got.update({name: result.outputs[:, j] for j, name in enumerate(compiled.outputs)})
    return got, {name: table[:, col[name]] for name in got}


def worst(got: np.ndarray, ref: np.ndarray) -> float:
    """Largest |difference|, with NaN = NaN (no rule fired), equal infinities equal, and NaN
    vs number = inf."""
    both = (np.isnan(got) & np.isnan(ref)) | (got == ref)     # NaN = NaN, inf = inf
    with np.errstate(invalid="ignore"):                      # inf - inf
        diff = np.abs(np.where(both, 0.0, got - ref))
    return float(np.where(np.isnan(diff), np.inf, diff).max())


@needs_fuzzylite
@pytest.mark.parametrize("name", FILES)
def test_fuzzylite_example(name: str) -> None:
    fll = EXAMPLES / name
    if name in REFUSED:
        with pytest.raises(FormatError) as info:
            read_rulebase(fll)
        assert REFUSED[name] in info.value.message
        assert info.value.span is not None and info.value.span.line >= 1
        return
    got, ref = mitos_outputs(fll)
    assert got, "no outputs"
    for output in got:
        error = worst(got[output], ref[output])
        if name in MISMATCH:
            assert error > TOLERANCE
            continue
        assert error <= TOLERANCE, f"{name}: `{output}` differs from fuzzylite by {error:.3g}"


@needs_fuzzylite
def test_discrete_mismatch_is_the_tables_not_ours() -> None:
    import fuzzylite as fl

    fll = EXAMPLES / "terms" / "discrete.fll"
    got, ref = mitos_outputs(fll)
    engine = fl.FllImporter().from_file(fll)
    _, table = read_fld(fll.with_suffix(".fld"))
    engine.input_variables[0].value = table[:, 0]
    engine.process()
    theirs = np.asarray(engine.output_variables[0].value, dtype=float)
    assert worst(theirs, ref["steer"]) > TOLERANCE          # fuzzylite 8 vs its own table
    assert worst(got["steer"], theirs) < 1e-12               # MITOS vs fuzzylite 8


@needs_fuzzylite
def test_hybrid_engines_become_one_behavior_per_rule_block() -> None:
    rb = read_rulebase(EXAMPLES / "hybrid" / "tipper.fll")
    assert [b.name for b in rb.behaviors] == ["mamdani", "takagiSugeno"]
    inference = {b.name: dict((s.key, s.value) for s in b.operators)["inference"]
                 for b in rb.behaviors}
    assert inference == {"mamdani": "mamdani", "takagiSugeno": "weighted_average"}


@needs_fuzzylite
def test_figures_reported_in_docs() -> None:
    loaded = [n for n in FILES if n not in REFUSED]
    matched = [n for n in loaded if n not in MISMATCH]
    doc = (Path(__file__).parents[1] / "docs" / "conformance.md").read_text()
    assert f"{len(loaded)} of {len(FILES)}" in doc and f"{len(matched)} of {len(loaded)}" in doc
    for name in list(REFUSED) + list(MISMATCH):
        assert name in doc, f"{name} is not explained in docs/conformance.md"


#: MATLAB's documented outputs of its tipper (mathworks.com/help/fuzzy/mamfis.evalfis.html:
#: evalfis(fis, [2 1]) = 7.0169; [4 5; 7 8] -> 14.4585, 20.3414).
MATLAB_TIPPER = [((2, 1), 7.0169), ((4, 5), 14.4585), ((7, 8), 20.3414)]


def test_matlab_tipper_documented_outputs() -> None:
    rb = read_rulebase(DATA / "tipper.fis")
    compiled = compile_rulebase(rb)
    X = np.array([x for x, _ in MATLAB_TIPPER], dtype=float)
    tip = evaluate(compiled, X).outputs[:, 0]
    # MATLAB prints 4 decimals: agreement to half a unit in the last printed digit
    np.testing.assert_allclose(tip, [y for _, y in MATLAB_TIPPER], rtol=0, atol=5e-5)
