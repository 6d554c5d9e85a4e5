"""Agreement with an independent implementation: pyfuzzylite 8 (``import fuzzylite as fl``).

The same engines are written once as MITOS files and once as FuzzyLite Language (FLL), built
independently (no MITOS interop code), and evaluated on the same random inputs.

Where the definitions coincide the outputs agree to 1e-9 (they differ only by rounding, ~1e-13):

- every T-norm (conjunction) and S-norm (disjunction) by the same name: fuzzylite uses the
  textbook formulas; MITOS rearranges some for exact identities in floating point;
- hedges ``very`` (x^2), ``somewhat`` (sqrt x) and ``not`` (1 - x) in antecedents;
- rule weights (``with w`` multiplies the activation degree in both);
- Takagi-Sugeno weighted average and weighted sum, with constant and linear consequents
  (fuzzylite's ``Linear`` takes one coefficient per engine input plus the constant: MITOS's
  ``linear`` shape has the same layout);
- Mamdani with any implication, any aggregation and all five defuzzifiers: MITOS samples the
  output universe at the midpoints of ``resolution`` equal cells, which is fuzzylite's
  integration rule (``Op.midpoints``) with ``resolution`` divisions, so the discretisation is
  the same and no extra tolerance is needed. The maximum-based defuzzifiers (mom, som, lom,
  bisector) compare memberships for equality; mom, som and lom compare plateau values that
  are copies of a DOF, so they agree to 1e-9 too. The bisector compares two cumulative areas
  with half the total: for a symmetric output set the half falls exactly between two samples,
  rounding (1e-16) decides the tie, and the results may differ by up to one cell,
  ``(hi - lo) / resolution``, on a few samples (tested: at most that, 98 % within 1e-9).

Where they differ (tested below as differences, so that a change on either side is noticed):

- fuzzylite's ``extremely`` is 2x^2 / 1 - 2(1-x)^2 (a contrast intensifier), MITOS's is x^3;
- a hedged consequent (``then speed is very SLOW``): fuzzylite hedges the rule's activation
  degree, MITOS the consequent set (Zadeh's reading, ``mu_SLOW(y)^2``);
- singleton consequents under Mamdani: fuzzylite's centroid sees them only where a midpoint
  equals the value (almost never: NaN); MITOS discretises them into one-cell spikes.
"""

from __future__ import annotations

import numpy as np
import pytest

fl = pytest.importorskip("fuzzylite")

from mitos_cli.api import load_rulebase  # noqa: E402
from mitos_cli.engine.evaluation import evaluate  # noqa: E402
from mitos_cli.fuzzy import norms  # noqa: E402

FL_TNORM = {"min": "Minimum", "product": "AlgebraicProduct", "lukasiewicz": "BoundedDifference",
            "drastic": "DrasticProduct", "einstein": "EinsteinProduct",
            "hamacher": "HamacherProduct", "nilpotent_minimum": "NilpotentMinimum"}
FL_SNORM = {"max": "Maximum", "probabilistic_sum": "AlgebraicSum", "bounded_sum": "BoundedSum",
            "drastic_sum": "DrasticSum", "einstein_sum": "EinsteinSum",
            "hamacher_sum": "HamacherSum", "nilpotent_maximum": "NilpotentMaximum"}
FL_DEFUZZIFIER = {"centroid": "Centroid", "bisector": "Bisector", "mom": "MeanOfMaximum",
                  "som": "SmallestOfMaximum", "lom": "LargestOfMaximum"}
FL_IMPLICATION = {"min": "Minimum", "product": "AlgebraicProduct"}

# (name, universe, terms as (name, MITOS YAML, FLL term))
INPUTS = [
    ("road", (0, 160), [
        ("NARROW", "{shape: left_shoulder, points: [40, 70]}", "Ramp 70 40"),
        ("MEDIUM", "{shape: triangle, peak: 70, width: 30}", "Triangle 40 70 100"),
        ("WIDE", "{shape: right_shoulder, points: [70, 100]}", "Ramp 70 100")]),
    ("size", (0, 100), [
        ("SMALL_SZ", "{shape: left_shoulder, points: [10, 40]}", "Ramp 40 10"),
        ("MED_SZ", "{shape: trapezoid, points: [10, 35, 45, 70]}", "Trapezoid 10 35 45 70"),
        ("LARGE_SZ", "{shape: right_shoulder, points: [40, 70]}", "Ramp 40 70")]),
    ("position", (-60, 60), [
        ("LEFT", "{shape: left_shoulder, points: [-7, 0]}", "Ramp 0 -7"),
        ("CENTER", "{shape: triangle, points: [-7, 0, 7]}", "Triangle -7 0 7"),
        ("RIGHT", "{shape: right_shoulder, points: [0, 7]}", "Ramp 0 7")]),
]
PEAKS = {"LB": 30, "LM": 50, "LS": 70, "ST": 90, "RS": 110, "RM": 130, "RB": 150}
SPEEDS = {"CREEP": 10, "SLOW": 20, "MODERATE": 30, "MEDIUM": 40, "FAST": 50}

# the paper's 27 rules (constant consequents)
ROADS, SIZES, POSITIONS = ("WIDE", "NARROW", "MEDIUM"), ("SMALL_SZ", "MED_SZ", "LARGE_SZ"), \
    ("LEFT", "CENTER", "RIGHT")
PAPER_RULES = [
    f"if road is {r} and size is {s} and position is {p} then steering is "
    f"{['RS', 'RM', 'RS', 'LS', 'LS', 'ST', 'LS', 'LM', 'LS'][3 * pi + si]} and speed is "
    f"{[['MEDIUM', 'MEDIUM', 'MODERATE'], ['SLOW', 'SLOW', 'CREEP'], ['MODERATE'] * 3][ri][si]}"
    for ri, r in enumerate(ROADS) for pi, p in enumerate(POSITIONS) for si, s in enumerate(SIZES)]

# OR, NOT, hedges, parentheses and weights
MIXED_RULES = [
    "if road is NARROW and size is very LARGE_SZ then steering is LM and speed is SLOW",
    "if road is somewhat MEDIUM and position is not LEFT then steering is LS and speed is "
    "MODERATE with 0.8",
    "if road is WIDE or size is SMALL_SZ then steering is ST and speed is FAST",
    "if (position is LEFT or position is CENTER) and size is MED_SZ then steering is RS "
    "with 0.6",
    "if position is RIGHT and size is not SMALL_SZ then steering is LM and speed is CREEP",
    "if road is very WIDE and position is somewhat CENTER then steering is RB and speed is "
    "MEDIUM with 0.3",
]


def output_terms(kind: str):
    """steering and speed terms as (name, MITOS YAML, FLL) for the chosen consequent kind."""
    def of(table, width):
        if kind == "constant":
            return [(n, f"{v}", f"Constant {v}") for n, v in table.items()]
        return [(n, f"{{shape: triangle, points: [{v - width}, {v}, {v + width}]}}",
                 f"Triangle {v - width} {v} {v + width}") for n, v in table.items()]
    steering, speed = of(PEAKS, 20), of(SPEEDS, 10)
    if kind == "linear":            # constants, with LS and RS as linear consequents
        steering = [(n, f"{v}", f"Constant {v}") for n, v in PEAKS.items()
                    if n not in ("LS", "RS")]
        steering += [
            ("LS", "{shape: linear, coefficients: {road: -0.25, size: 0.1, position: 0.5}, "
                   "constant: 85}", "Linear -0.25 0.1 0.5 85"),
            ("RS", "{shape: linear, coefficients: {position: -1.5}, constant: 110}",
             "Linear 0 0 -1.5 110")]
        speed = [(n, f"{v}", f"Constant {v}") for n, v in SPEEDS.items()]
    return [("steering", (30, 150), steering), ("speed", (0, 60), speed)]


def build(tmp_path, rules, kind, *, conj="min", disj="max", inference="weighted_average",
          implication="min", aggregation="max", defuzzify="centroid", resolution=101):
    """The same engine for MITOS (compiled) and fuzzylite (an ``fl.Engine``)."""
    outputs = output_terms(kind)
    yaml = ["variables:"]
    for name, (lo, hi), terms in INPUTS:
        yaml += [f"  {name}:", "    role: input", f"    universe: [{lo}, {hi}]", "    terms:"]
        yaml += [f"      {t}: {spec}" for t, spec, _ in terms]
    for name, (lo, hi), terms in outputs:
        yaml += [f"  {name}:", "    role: output", f"    universe: [{lo}, {hi}]", "    terms:"]
        yaml += [f"      {t}: {spec}" for t, spec, _ in terms]
    (tmp_path / "a.terms.yaml").write_text("\n".join(yaml) + "\n")
    ops = (f"operators: and = {conj}, or = {disj}, inference = {inference}, implication = "
           f"{implication}, aggregation = {aggregation}, defuzzify = {defuzzify}, resolution = "
           f"{resolution}")
    (tmp_path / "a.rules").write_text('terms "a.terms.yaml"\n' + ops + "\n" + "\n".join(rules)
                                      + "\n")
    compiled = load_rulebase(tmp_path / "a.rules").compiled

    if inference == "mamdani":
        defuzzifier = f"{FL_DEFUZZIFIER[defuzzify]} {resolution}"
        agg, imp = FL_SNORM[aggregation], FL_IMPLICATION[implication]
    else:
        kind_ = "WeightedAverage" if inference == "weighted_average" else "WeightedSum"
        defuzzifier, agg, imp = f"{kind_} TakagiSugeno", "none", "none"
    fll = ["Engine: agreement"]
    for name, (lo, hi), terms in INPUTS:
        fll += [f"InputVariable: {name}", "  enabled: true", f"  range: {lo} {hi}",
                "  lock-range: false"] + [f"  term: {t} {f}" for t, _, f in terms]
    for name, (lo, hi), terms in outputs:
        fll += [f"OutputVariable: {name}", "  enabled: true", f"  range: {lo} {hi}",
                "  lock-range: false", f"  aggregation: {agg}", f"  defuzzifier: {defuzzifier}",
                "  default: nan", "  lock-previous: false"]
        fll += [f"  term: {t} {f}" for t, _, f in terms]
    fll += ["RuleBlock: rules", "  enabled: true", f"  conjunction: {FL_TNORM[conj]}",
            f"  disjunction: {FL_SNORM[disj]}", f"  implication: {imp}",
            "  activation: General"] + [f"  rule: {r}" for r in rules]
    engine = fl.FllImporter().from_string("\n".join(fll) + "\n")
    return compiled, engine


def samples(n=300, seed=0):
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    return np.column_stack([rng.uniform(lo, hi, n) for _, (lo, hi), _ in INPUTS])


def run_both(compiled, engine, X):
    names = [name for name, _, _ in INPUTS]
    columns = [names.index(k) for k in compiled.inputs]       # the inputs MITOS's rules use
    mitos = evaluate(compiled, X[:, columns], strict=False).outputs
    for j, (name, _, _) in enumerate(INPUTS):
        engine.input_variable(name).value = X[:, j].copy()
    engine.process()
    theirs = np.column_stack([np.atleast_1d(engine.output_variable(o).value)
                              for o in compiled.outputs])
    return mitos, theirs


def assert_agree(mitos, theirs, tol=1e-9):
    assert (np.isnan(mitos) == np.isnan(theirs)).all(), "different samples fired no rule"
    assert np.isfinite(mitos).any()
    ok = np.isfinite(mitos)
    assert (np.abs(mitos - theirs)[ok] <= np.broadcast_to(tol, mitos.shape)[ok]).all(), \
        f"max difference {np.nanmax(np.abs(mitos - theirs))}"


PAIRS = [(t, norms.lookup("snorm", t.dual).name) for t in norms.TNORMS.values()]


@pytest.mark.parametrize("conj,disj", [(t.name, s) for t, s in PAIRS],
                         ids=[t.name for t, _ in PAIRS])
@pytest.mark.parametrize("rules", ["paper", "mixed"])
def test_sugeno_constant_weighted_average_every_norm(tmp_path, conj, disj, rules):
    compiled, engine = build(tmp_path, PAPER_RULES if rules == "paper" else MIXED_RULES,
                             "constant", conj=conj, disj=disj)
    assert_agree(*run_both(compiled, engine, samples()))


@pytest.mark.parametrize("inference", ["weighted_average", "weighted_sum"])
def test_sugeno_linear(tmp_path, inference):
    compiled, engine = build(tmp_path, PAPER_RULES + MIXED_RULES, "linear", conj="product",
                             disj="probabilistic_sum", inference=inference)
    assert compiled.cons_linear is not None
    assert_agree(*run_both(compiled, engine, samples(seed=1)))


@pytest.mark.parametrize("aggregation", sorted(norms.SNORMS))
@pytest.mark.parametrize("implication", ["min", "product"])
def test_mamdani_centroid_every_aggregation(tmp_path, implication, aggregation):
    compiled, engine = build(tmp_path, MIXED_RULES, "triangle", conj="min", disj="max",
                             inference="mamdani", implication=implication,
                             aggregation=aggregation, resolution=101)
    assert_agree(*run_both(compiled, engine, samples(120, seed=2)))


@pytest.mark.parametrize("conj,disj", [(t.name, s) for t, s in PAIRS],
                         ids=[t.name for t, _ in PAIRS])
def test_mamdani_every_tnorm_and_snorm_in_antecedents(tmp_path, conj, disj):
    compiled, engine = build(tmp_path, MIXED_RULES + PAPER_RULES[::3], "triangle", conj=conj,
                             disj=disj, inference="mamdani", resolution=1000)
    assert_agree(*run_both(compiled, engine, samples(100, seed=3)))


@pytest.mark.parametrize("defuzzify", ["centroid", "bisector", "mom", "som", "lom"])
@pytest.mark.parametrize("implication", ["min", "product"])
def test_mamdani_defuzzifiers(tmp_path, implication, defuzzify):
    compiled, engine = build(tmp_path, MIXED_RULES, "triangle", inference="mamdani",
                             implication=implication, defuzzify=defuzzify, resolution=501)
    mitos, theirs = run_both(compiled, engine, samples(300, seed=4))
    if defuzzify != "bisector":
        assert_agree(mitos, theirs)
        return
    # A symmetric output set puts half its area exactly between two samples: they tie, and
    # rounding (1e-16) decides which one (or both) is taken, a difference of up to one cell.
    # Everything else agrees to 1e-9.
    cell = np.array([120.0, 60.0]) / 501
    assert_agree(mitos, theirs, tol=cell + 1e-9)
    assert (np.abs(mitos - theirs) <= 1e-9).mean() > 0.98


def test_differences_are_the_documented_ones(tmp_path):
    # extremely: fuzzylite's contrast intensifier vs MITOS's cube
    x = np.array([0.2, 0.5, 0.8])
    from mitos_cli.fuzzy.hedges import HEDGES

    assert np.allclose(fl.Extremely().hedge(x), [0.08, 0.5, 0.92])
    assert np.allclose(HEDGES["extremely"].fn(x), x ** 3)
    # hedged consequent: degree hedged (fuzzylite) vs set hedged (MITOS)
    rules = ["if road is NARROW then speed is very SLOW", "if road is WIDE then speed is FAST"]
    compiled, engine = build(tmp_path, rules, "triangle", inference="mamdani")
    X = np.array([[55.0, 50, 0], [85.0, 50, 0]])       # both rules fire at 0.5
    mitos, theirs = run_both(compiled, engine, X)
    assert compiled.outputs == ("speed",)
    assert np.isfinite(mitos).all() and not np.allclose(mitos[:, 0], theirs[:, 0])
