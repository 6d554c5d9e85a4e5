"""``mitos operators``: every operator a rule file can select, with its formula and aliases."""

from __future__ import annotations

from typing import Annotated

import typer

from .output import emit, json_text

INFERENCE = {
    "weighted_average": "y = sum_r(dof_r * y_r) / sum_r(dof_r); y_r = the consequent's value "
                        "(term centre) or a . x + c (linear); the paper's eqs. 18-19",
    "weighted_sum": "y = sum_r(dof_r * y_r) (Takagi-Sugeno without normalisation)",
    "mamdani": "y = defuzzify(S_r implication(dof_r, mu_r(y))) on `resolution` samples",
    "tsukamoto": "y = sum_t(w_t * z_t) / sum_t(w_t); w_t = sum of the dofs of the rules "
                 "concluding term t, z_t = mu_t^-1(w_t) (monotonic terms only; fuzzylite's "
                 "Tsukamoto)",
}
#: The classic implications; any other T-norm T gives mu'(y) = T(dof, mu(y)).
IMPLICATION = {
    "min": "mu'(y) = min(dof, mu(y)) (clipping)",
    "product": "mu'(y) = dof * mu(y) (scaling)",
}
INPUTS = {
    "clamped": "taken at the universe's nearer end (MATLAB's evalfis; fuzzylite's lock-range: true)",
    "as_given": ("its terms evaluated at the value given (jFuzzyLogic's; fuzzylite's lock-range: "
                 "false)"),
}
SAMPLING = {
    "midpoints": "the midpoints of `resolution` equal cells (fuzzylite's integration rule)",
    "endpoints": "`resolution` evenly spaced points including both ends (MATLAB's evalfis)",
    "left": "the left ends of `resolution` equal cells (jFuzzyLogic's)",
    "trapezoid": "`resolution` evenly spaced points including both ends, the two ends weighing "
                 "half in the centroid and bisector (Octave's trapz)",
}
DEFUZZIFY = {
    "centroid": "sum(y mu(y)) / sum(mu(y)) over the samples (midpoint rule)",
    "bisector": "the sample where the cumulative area is closest to half the total",
    "mom": "mean of the samples where mu(y) is maximal",
    "som": "smallest sample where mu(y) is maximal",
    "lom": "largest sample where mu(y) is maximal",
    "matlab_bisector": "the first sample where the running area reaches half the total "
                       "(MATLAB's evalfis, a .fis file's bisector)",
    "matlab_som": "the sample where mu(y) is maximal smallest in absolute value (MATLAB's som)",
    "matlab_lom": "the sample where mu(y) is maximal largest in absolute value (MATLAB's lom)",
    "jfuzzylogic_bisector": "where two running areas walking in from both ends meet, the "
                            "smaller taking the next sample (jFuzzyLogic's COA)",
}


def catalogue() -> dict[str, list[dict]]:
    """Every operator by setting key: name, formula, aliases, default, dual."""
    from ..fuzzy import norms
    from ..fuzzy.hedges import HEDGES
    from ..lang.operators import Operators

    d = Operators()

    def entry(name: str, formula: str, default: str | None, **extra: object) -> dict:
        return {"name": name, "formula": formula, "default": name == default, **extra}

    return {
        "and": [entry(n.name, n.formula, d.and_, aliases=list(n.aliases), dual=n.dual)
                for n in norms.TNORMS.values()],
        "or / aggregation": [entry(n.name, n.formula, d.or_, aliases=list(n.aliases),
                                   dual=n.dual) for n in norms.SNORMS.values()],
        "aggregation only": [entry(norms.UNBOUNDED_SUM.name, norms.UNBOUNDED_SUM.formula,
                                   d.aggregation, aliases=list(norms.UNBOUNDED_SUM.aliases))],
        "inference": [entry(k, v, d.inference) for k, v in INFERENCE.items()],
        "implication": [entry(n.name, IMPLICATION.get(n.name, f"mu'(y) = {n.name}(dof, mu(y))"),
                              d.implication) for n in norms.TNORMS.values()],
        "defuzzify": [entry(k, v, d.defuzzify) for k, v in DEFUZZIFY.items()],
        "sampling": [entry(k, v, d.sampling) for k, v in SAMPLING.items()],
        "accumulation": [entry("sum", "every rule counts: y = sum(dof y) / sum(dof)",
                               d.accumulation)] + [
            entry(n.name, f"the rules of one value weigh {n.name} of their DOFs",
                  d.accumulation) for n in norms.SNORMS.values()],
        "inputs": [entry(k, v, d.inputs) for k, v in INPUTS.items()],
        "hedges": [entry(h.name, h.formula, None) for h in HEDGES.values()],
    }


TITLES = {
    "and": "T-norms (AND neurons)                    operators: and = NAME",
    "or / aggregation": "S-norms (OR neurons, Mamdani aggregation)  operators: or = NAME, "
                        "aggregation = NAME",
    "aggregation only": "the unbounded sum (Mamdani only, not `or`)  operators: aggregation = sum",
    "inference": "inference methods (output layer)         operators: inference = NAME",
    "implication": "Mamdani implication (any T-norm)         operators: implication = NAME",
    "defuzzify": "Mamdani defuzzifiers                     operators: defuzzify = NAME, "
                 "resolution = N (default {resolution})",
    "sampling": "Mamdani grid                             operators: sampling = NAME",
    "accumulation": "rules of one value (weighted inference)  operators: accumulation = NAME",
    "inputs": "an input outside its universe            operators: inputs = NAME",
    "hedges": "hedges (activations, eqs. 10-11)         `road is very WIDE`",
}


def render(cat: dict[str, list[dict]]) -> str:
    from ..lang.operators import Operators

    lines = ["The paper's defaults: and = min, or = max, inference = weighted_average "
             "(eqs. 17-19)."]
    for key, entries in cat.items():
        lines += ["", TITLES[key].format(resolution=Operators().resolution)]
        width = max(len(e["name"]) for e in entries)
        for e in entries:
            notes = []
            if e.get("aliases"):
                notes.append("alias " + ", ".join(e["aliases"]))
            if e.get("dual"):
                notes.append(f"dual {e['dual']}")
            if e["default"]:
                notes.append("default")
            tail = f"   [{'; '.join(notes)}]" if notes else ""
            lines.append(f"  {e['name'].ljust(width)}  {e['formula']}{tail}")
    return "\n".join(lines)


def operators_command(
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """List every T-norm, S-norm, inference method, implication, defuzzifier and hedge."""
    cat = catalogue()
    emit(json_text(cat) if as_json else render(cat))
