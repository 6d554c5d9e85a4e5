"""The C backend of ``mitos export``: one self-contained C99 file.

The file needs only ``<math.h>`` (link with ``-lm``), allocates nothing (fixed-size locals
and ``static const`` tables) and exposes::

    int PREFIX_eval(const double in[PREFIX_N_INPUTS], double out[PREFIX_N_OUTPUTS]);

with ``PREFIX_IN_<NAME>`` / ``PREFIX_OUT_<NAME>`` index macros. Inputs are clamped to their
universes; an output no rule sets takes its default, or NaN when it has none, and the return
value counts such outputs (0: every output was set by its rules). A NaN input gives NaN
outputs and returns ``PREFIX_NAN_INPUT`` (-1), as the NumPy module and ``mitos eval`` do not
let it pass as a number either.
Names from the rule base appear only in comments, through :func:`comment`, and in
identifiers made by :mod:`.program`.
"""

from __future__ import annotations

import json

import numpy as np

from ...engine.compile import CompiledRuleBase
from ...errors import FormatError
from ...fuzzy.hedges import HEDGES
from ...fuzzy.norms import SNORMS, TNORMS, UNBOUNDED_SUM
from ...words import plural
from .program import PLAIN, Program, ident, num, program, unique_idents, weighted_sums

C_SHAPES = {
    "gaussian": """static double mf_gaussian(double x, double mean, double sigma) {
    return exp(-((x - mean) * (x - mean)) / (2.0 * sigma * sigma));
}""",
    "gaussian2": """static double mf_gaussian2(double x, double m1, double s1, double m2, double s2) {
    double a = x < m1 ? exp(-((x - m1) * (x - m1)) / (2.0 * s1 * s1)) : 1.0;
    double b = x > m2 ? exp(-((x - m2) * (x - m2)) / (2.0 * s2 * s2)) : 1.0;
    return a * b;
}""",
    "bell": """static double mf_bell(double x, double center, double width, double slope) {
    return 1.0 / (1.0 + pow(fabs((x - center) / width), 2.0 * slope));
}""",
    "sigmoid": """static double mf_sigmoid(double x, double inflection, double slope) {
    return 1.0 / (1.0 + exp(-(slope * (x - inflection))));
}""",
    "sigmoid_difference": """static double mf_sigmoid_difference(double x, double l, double r, \
double f, double rt) {
    return fabs(1.0 / (1.0 + exp(-(r * (x - l)))) - 1.0 / (1.0 + exp(-(f * (x - rt)))));
}""",
    "clipped_sigmoid_difference": """static double mf_clipped_sigmoid_difference(double x, \
double l, double r, double f, double rt) {
    double d = 1.0 / (1.0 + exp(-(r * (x - l)))) - 1.0 / (1.0 + exp(-(f * (x - rt))));
    return d > 0.0 ? d : (d == d ? 0.0 : d);
}""",
    "sigmoid_product": """static double mf_sigmoid_product(double x, double l, double r, \
double f, double rt) {
    return (1.0 / (1.0 + exp(-(r * (x - l))))) * (1.0 / (1.0 + exp(-(f * (x - rt)))));
}""",
    "s_shape": """static double mf_s_shape(double x, double s, double e) {
    if (x <= s) return 0.0;
    if (x <= 0.5 * (s + e)) { double t = (x - s) / (e - s); return 2.0 * t * t; }
    if (x < e) { double t = (x - e) / (e - s); return 1.0 - 2.0 * t * t; }
    return 1.0;
}""",
    "z_shape": """static double mf_z_shape(double x, double s, double e) {
    if (x <= s) return 1.0;
    if (x < 0.5 * (s + e)) { double t = (x - s) / (e - s); return 1.0 - 2.0 * t * t; }
    if (x < e) { double t = (x - e) / (e - s); return 2.0 * t * t; }
    return 0.0;
}""",
    "pi_shape": """static double mf_pi_shape(double x, double a, double b, double c, double d) {
    return mf_s_shape(x, a, b) * mf_z_shape(x, c, d);
}""",
    "cosine": """static double mf_cosine(double x, double center, double width) {
    if (x < center - 0.5 * width || x > center + 0.5 * width) return 0.0;
    return 0.5 * (1.0 + cos(2.0 / width * M_PI_ * (x - center)));
}""",
    "spike": """static double mf_spike(double x, double center, double width) {
    return exp(-fabs(10.0 / width * (x - center)));
}""",
    "concave": """static double mf_concave(double x, double i, double e) {
    if (i <= e && x < e) return (e - i) / (2.0 * e - i - x);
    if (i >= e && x > e) return (i - e) / (i - 2.0 * e + x);
    return 1.0;
}""",
    "semi_ellipse": """static double mf_semi_ellipse(double x, double start, double end) {
    double s = start < end ? start : end, e = start < end ? end : start;
    double r = (e - s) / 2.0, q;
    if (x < s || x > e) return 0.0;
    q = r * r - (x - (s + r)) * (x - (s + r));
    return sqrt(q > 0.0 ? q : 0.0) / r;
}""",
    "arc": """static double mf_arc(double x, double s, double e) {
    double r = e - s, q;
    if ((s < e && s <= x && x <= e) || (s > e && e <= x && x <= s)) {
        q = r * r - (x - e) * (x - e);
        return sqrt(q > 0.0 ? q : 0.0) / fabs(r);
    }
    return ((s < e && x > e) || (s > e && x < e)) ? 1.0 : 0.0;
}""",
    "binary": """static double mf_binary(double x, double start, double direction) {
    return ((direction > start && x >= start) || (direction < start && x <= start)) ? 1.0 : 0.0;
}""",
    "singleton": """static double mf_singleton(double x, double value) {
    return x == value ? 1.0 : 0.0;
}""",
}

C_NORMS = {n.name: n.c for n in (*TNORMS.values(), *SNORMS.values(), UNBOUNDED_SUM)}   # fuzzy/norms.py

C_HEDGES = {h.name: h.c for h in HEDGES.values()}   # fuzzy/hedges.py


def comment(text: str) -> str:
    """``text`` safe inside a C block comment: as it is when plain, else as an escaped string
    literal in which no ``*/``, ``/*``, trigraph or line break survives."""
    if PLAIN.fullmatch(text):
        return text
    quoted = json.dumps(text)                    # ASCII, no line breaks
    return quoted.replace("*/", "*\\/").replace("/*", "/\\*").replace("??", "?\\?")


def to_c(compiled: CompiledRuleBase, prefix: str = "mitos", source: str = "") -> str:
    """One C99 file computing the outputs of ``compiled`` (see the module docstring)."""
    p = program(compiled)
    P, U = ident(prefix), ident(prefix).upper()
    out = _c_header(p, P, U, source) + _c_helpers(p)
    signature = f"int {P}_eval(const double in[{U}_N_INPUTS], double out[{U}_N_OUTPUTS])"
    tables = [f"static const double {col}_xy[{len(params)}] = {{"
              f"{', '.join(num(v) for v in params)}}};"
              for _, col, shape, params, kernel in p.terms
              if kernel is None and shape == "discrete"]
    if tables:
        out += tables + [""]
    out += [signature, "{", f"    double x[{U}_N_INPUTS > 0 ? {U}_N_INPUTS : 1];",
            "    int fallback = 0;"]
    out += _c_nan_inputs(U, compiled.operators.inputs == "as_given")
    out += _c_body(p)
    out += _c_outputs(compiled, P)
    out += ["    return fallback;", "}", ""]
    return "\n".join(out)


def _without_default(c: CompiledRuleBase) -> str:
    """What an output without a default is where no rule sets it: NaN, but a weighted sum's
    is 0, the sum of nothing."""
    return "0, the empty sum," if c.operators.inference == "weighted_sum" else "NaN"


def _c_header(p: Program, P: str, U: str, source: str) -> list[str]:
    """The opening comment (what, from where, how to build) and the index macros."""
    c = p.compiled
    out = [f"/* Generated by `mitos export --to c` from {comment(source or 'a MITOS rule base')}",
           f" * (behavior `{comment(c.behavior)}`: {plural(len(p.rules), 'rule')}; "
           f"{comment(c.describe_operators())}).",
           " * C99, no allocation, only <math.h>: cc -std=c99 -c FILE.c, link with -lm.",
           f" * int {P}_eval(const double in[{U}_N_INPUTS], double out[{U}_N_OUTPUTS]):",
           (" * inputs are clamped to their universes; an output no rule sets takes its default"
            if c.operators.inputs == "clamped" else
            " * inputs are not clamped (inputs = as_given); an output no rule sets takes its "
            "default"),
           f" * ({_without_default(c)} when it has none). Returns how many outputs took that"
           " fallback (0: the rules",
           f" * set every output), or {U}_NAN_INPUT (-1) when an input is NaN"
           + (" or infinite" if c.operators.inputs == "as_given" else "") + ": then every",
           " * output is NaN. */",
           "", "#include <math.h>", "",
           f"#define {U}_N_INPUTS {len(c.inputs)}", f"#define {U}_N_OUTPUTS {len(c.outputs)}",
           f"#define {U}_NAN_INPUT (-1)  /* returned when an input is NaN */"]
    for i, name in enumerate(unique_idents(c.inputs, str.upper)):
        lo, hi = c.universe[i]
        out.append(f"#define {U}_IN_{name.upper()} {i}  /* [{lo:g}, {hi:g}] */")
    for j, name in enumerate(unique_idents(c.outputs, str.upper)):
        out.append(f"#define {U}_OUT_{name.upper()} {j}")
    # the prototype, so that `-Wmissing-prototypes` (common in embedded builds, often with
    # -Werror) passes, and the lines a caller copies into its own header are in one place
    return out + ["", f"int {P}_eval(const double in[{U}_N_INPUTS], double out[{U}_N_OUTPUTS]);",
                  "", "#define M_PI_ 3.14159265358979323846", ""]


def _c_helpers(p: Program) -> list[str]:
    """The static functions the program calls: shapes, norms, hedges."""
    ops = p.compiled.operators
    out = []
    if "kernel" in p.norms:
        out += ["static double mf_kernel(double x, double b, double s1, double c, double s2) {",
                "    /* piecewise-linear terms: clip(1 + min((x - b) s1, (c - x) s2), 0, 1) */",
                "    double rise = (x - b) * s1, fall = (c - x) * s2;",
                "    double y = 1.0 + (rise < fall ? rise : fall);",
                "    return y < 0.0 ? 0.0 : (y > 1.0 ? 1.0 : y);", "}", ""]
    for shape in p.shapes:
        if shape == "discrete":
            out += _c_discrete(), ""
        elif shape == "pi_shape":
            out += [C_SHAPES["s_shape"], C_SHAPES["z_shape"], C_SHAPES["pi_shape"], ""]
        elif shape in C_SHAPES:
            if shape in ("s_shape", "z_shape") and "pi_shape" in p.shapes:
                continue
            out += [C_SHAPES[shape], ""]
        else:
            raise FormatError(f"`mitos export --to c` has no C code for `{shape}` terms")
    for kind, name in (("t", ops.and_), ("s", ops.or_)):
        if f"{kind}norm" in p.norms:
            out += [f"static double {kind}norm(double a, double b) {{", f"    {C_NORMS[name]}",
                    "}", ""]
    if p.compiled.joins:
        out += ["static double accumulate(double a, double b) {",
                f"    {C_NORMS[ops.accumulation]}", "}", ""]
    if ops.inference == "mamdani":
        out += ["static double aggregate(double a, double b) {",
                f"    {C_NORMS[ops.aggregation]}", "}", ""]
        if ops.implication not in ("min", "product"):
            out += ["static double implication(double a, double b) {",
                    f"    {C_NORMS[ops.implication]}", "}", ""]
    for h in p.hedges:
        out += [f"static double hedge_{h}(double x) {{", f"    {C_HEDGES[h]}", "}", ""]
    return out


def _c_nan_inputs(U: str, as_given: bool = False) -> list[str]:
    """A NaN input makes every output NaN and the status negative: the clamp and the min
    t-norm (``a < b ? a : b``) would otherwise turn it into a plausible number. Under
    ``inputs = as_given`` (not clamped) an infinite input too: its terms have no number."""
    bad = "isnan(in[i]) || isinf(in[i])" if as_given else "isnan(in[i])"
    what = "a NaN or infinite input" if as_given else "a NaN input"
    return [f"    {{   /* {what}: every output NaN, return {U}_NAN_INPUT */",
            "        int i;",
            f"        for (i = 0; i < {U}_N_INPUTS; ++i) if ({bad}) {{",
            f"            for (i = 0; i < {U}_N_OUTPUTS; ++i) out[i] = NAN;",
            f"            return {U}_NAN_INPUT;",
            "        }",
            "    }"]


def _c_body(p: Program) -> list[str]:
    """Clamped inputs, then one ``const double`` per membership and per rule."""
    c = p.compiled
    out = []
    for i in range(len(c.inputs)):
        lo, hi = c.universe[i]
        if c.operators.inputs == "as_given":        # fuzzylite's, jFuzzyLogic's reading: not clamped
            out.append(f"    x[{i}] = in[{i}] + 0.0;")
            continue
        out.append(f"    x[{i}] = in[{i}] < {num(lo)} ? {num(lo)} : "
                   f"(in[{i}] > {num(hi)} ? {num(hi)} : in[{i}]);")
    for var, col, shape, params, kernel in p.terms:
        if kernel is not None:
            args = ", ".join(num(v) for v in kernel)
            out.append(f"    const double {col} = mf_kernel(x[{var}], {args});")
        elif shape == "discrete":
            out.append(f"    const double {col} = mf_discrete(x[{var}], {col}_xy, "
                       f"{len(params) // 2});")
        else:
            args = ", ".join(num(v) for v in params)
            out.append(f"    const double {col} = mf_{shape}(x[{var}], {args});")
    for col, text, weight in p.rules:
        w = "" if weight == 1.0 else f"{num(weight)} * "
        out.append(f"    const double {col} = {w}{text};")
    return out


def _c_discrete() -> str:
    return """static double mf_discrete(double x, const double *xy, int n) {
    /* piecewise linear through (x0, y0) ... (x{n-1}, y{n-1}), constant beyond the ends */
    int i;
    double y = xy[1];
    if (x != x) return x;
    for (i = 0; i + 1 < n; ++i) {
        double x0 = xy[2 * i], y0 = xy[2 * i + 1], x1 = xy[2 * i + 2], y1 = xy[2 * i + 3];
        if (x > x0) y = x >= x1 ? y1 : (x1 > x0 ? y0 + (x - x0) * ((y1 - y0) / (x1 - x0)) : y1);
    }
    return y;
}"""


def _c_outputs(c: CompiledRuleBase, P: str) -> list[str]:
    ops = c.operators
    out = []
    if ops.inference == "mamdani":
        return _c_mamdani(c, P)
    for j, name in enumerate(c.outputs):
        statements, numerator, denominator = weighted_sums(c, j, "c")
        default = c.default[j]
        fallback = "NAN" if np.isnan(default) else num(default)
        out.append(f"    {{   /* {comment(name)} */")
        out += [f"        {line}" for line in statements]
        out.append(f"        double num = {numerator};")
        if ops.inference == "weighted_sum" and j not in c.summed_defaults:
            out.append(f"        out[{j}] = num;")     # no rule firing: the empty sum, 0
        elif ops.inference == "weighted_sum":
            out.append(f"        double den = {denominator};")
            out.append(f"        if (den > 0.0) out[{j}] = num;")
            out.append(f"        else {{ out[{j}] = {fallback}; ++fallback; }}")
        else:
            out.append(f"        double den = {denominator};")
            out.append(f"        if (den > 0.0) out[{j}] = num / den;")
            out.append(f"        else {{ out[{j}] = {fallback}; ++fallback; }}")
        out.append("    }")
    return out


def _c_mamdani(c: CompiledRuleBase, P: str) -> list[str]:
    ops = c.operators
    imp = {"min": "d < s ? d : s", "product": "d * s"}.get(ops.implication, "implication(d, s)")
    out = []
    for j, table in enumerate(c.mamdani):
        name = c.outputs[j]
        res = len(table.grid)
        default = c.default[j]
        fallback = "NAN" if np.isnan(default) else num(default)
        rows = ",\n".join("        {" + ", ".join(num(v) for v in row) + "}" for row in table.sets)
        grid = ", ".join(num(v) for v in table.grid)
        out.append(f"    {{   /* {comment(name)}: Mamdani, {plural(res, 'sample')} */")
        if ops.defuzzify != "jfuzzylogic_bisector":    # which reads the universe's ends only
            out.append(f"        static const double grid[{res}] = {{{grid}}};")
        out.append(f"        static const double sets[{len(table.sets)}][{res}] = {{\n"
                   f"{rows}\n        }};")
        dofs = ", ".join(f"dof_{r}" for r in table.rules)
        set_of = ", ".join(str(int(s)) for s in table.set_of)
        n = len(table.rules)
        out.append(f"        const double dof[{max(n, 1)}] = {{{dofs or '0.0'}}};")
        out.append(f"        static const int set_of[{max(n, 1)}] = {{{set_of or '0'}}};")
        out.append(f"        double y[{res}];")
        out.append("        int i, r;")
        out.append(f"        for (i = 0; i < {res}; ++i) {{")
        out.append("            double acc = 0.0;")
        out.append(f"            for (r = 0; r < {n}; ++r) {{")
        out.append("                double d = dof[r], s = sets[set_of[r]][i];")
        out.append(f"                double b = {imp};")
        out.append("                acc = r == 0 ? b : aggregate(acc, b);")
        out.append("            }")
        out.append("            y[i] = acc;")
        out.append("        }")
        out += ["        " + line for line in _c_defuzzify(ops.defuzzify, res, j, fallback,
                                                      c.variables[name].universe)]
        out.append("    }")
    return out


def _c_defuzzify(method: str, res: int, j: int, fallback: str,
                 universe: tuple[float, float] = (0.0, 1.0)) -> list[str]:
    done = [f"if (value != value) {{ out[{j}] = {fallback}; ++fallback; }}",
            f"else out[{j}] = value;"]
    if method == "jfuzzylogic_bisector":     # jFuzzyLogic's DefuzzifierCenterOfArea loop
        lo, hi = (num(float(v)) for v in universe)
        return ["{", "    double sum_low = 0.0, sum_high = 0.0, value = NAN;",
                f"    int low = 0, high = {res} - 1;",
                "    while (low < high) {",
                "        if (sum_low <= sum_high) sum_low += y[++low];",
                "        else sum_high += y[--high];",
                "    }",
                f"    if (sum_low > 0.0) value = {lo} + (({hi} - {lo}) / {res}) * low;",
                *("    " + d for d in done), "}"]
    if method == "centroid":
        return ["{", "    double num = 0.0, den = 0.0, value = NAN;",
                f"    for (i = 0; i < {res}; ++i) {{ num += y[i] * grid[i]; den += y[i]; }}",
                "    if (den > 0.0) value = num / den;", *("    " + d for d in done), "}"]
    if method == "matlab_bisector":
        return ["{", "    double total = 0.0, area = 0.0, value = NAN;",
                f"    for (i = 0; i < {res}; ++i) total += y[i];",
                f"    if (total > 0.0) for (i = 0; i < {res}; ++i) {{",
                "        area += y[i];",
                "        if (area >= total / 2) { value = grid[i]; break; }",
                "    }", *("    " + d for d in done), "}"]
    if method == "bisector":
        return ["{", "    double total = 0.0, area = 0.0, best = INFINITY, sum = 0.0, value = NAN;",
                "    int count = 0;",
                f"    for (i = 0; i < {res}; ++i) total += y[i];",
                "    if (total > 0.0) {",
                f"        for (i = 0; i < {res}; ++i) {{",
                "            double gap;",
                "            area += y[i];",
                "            gap = fabs(area / total - 0.5);",
                "            if (gap < best) { best = gap; sum = grid[i]; count = 1; }",
                "            else if (gap == best) { sum += grid[i]; ++count; }",
                "        }",
                "        value = sum / count;",
                "    }", *("    " + d for d in done), "}"]
    pick = {"mom": ["        double sum = 0.0;", "        int count = 0;",
                    f"        for (i = 0; i < {res}; ++i) if (y[i] == top) {{ sum += grid[i]; "
                    f"++count; }}", "        value = sum / count;"],
            "som": [f"        for (i = 0; i < {res}; ++i) if (y[i] == top) {{ value = grid[i]; "
                    f"break; }}"],
            "lom": [f"        for (i = {res} - 1; i >= 0; --i) if (y[i] == top) {{ value = "
                    f"grid[i]; break; }}"],
            "matlab_som": ["        double best = INFINITY;",
                           f"        for (i = 0; i < {res}; ++i) if (y[i] == top && "
                           f"fabs(grid[i]) < best) {{ best = fabs(grid[i]); value = grid[i]; }}"],
            "matlab_lom": ["        double best = -1.0;",
                           f"        for (i = 0; i < {res}; ++i) if (y[i] == top && "
                           f"fabs(grid[i]) > best) {{ best = fabs(grid[i]); value = grid[i]; }}"],
            }[method]
    return ["{", "    double top = 0.0, value = NAN;",
            f"    for (i = 0; i < {res}; ++i) if (y[i] > top) top = y[i];",
            "    if (top > 0.0) {", *pick, "    }", *("    " + d for d in done), "}"]


