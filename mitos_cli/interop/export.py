"""Code export: a compiled behavior as one self-contained C99 file or one NumPy-only module.

Both are generated from the same straight-line program: one membership per input term, one
expression per rule (the AND / OR / NOT / hedge neurons written out as calls of ``tnorm``,
``snorm`` and ``hedge_*``), then the output layer. The arithmetic is MITOS's own (the same
compiled kernel for piecewise-linear terms, the same norm formulas, Mamdani consequent sets
sampled by :mod:`mitos_cli.engine.mamdani` and stored as tables), so the generated code agrees with
``mitos eval`` to rounding (the tests check 1e-9).

The C file needs only ``<math.h>`` (link with ``-lm``), allocates nothing (fixed-size locals
and ``static const`` tables) and exposes::

    int PREFIX_eval(const double in[PREFIX_N_INPUTS], double out[PREFIX_N_OUTPUTS]);

with ``PREFIX_IN_<NAME>`` / ``PREFIX_OUT_<NAME>`` index macros. Inputs are clamped to their
universes (NaN inputs give NaN outputs); an output no rule sets takes its default, or NaN when
it has none, and the return value counts such outputs (0: every output was set by its rules).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from ..lang.model import flatten
from ..engine.compile import CompiledRuleBase
from ..errors import FormatError
from ..lang.model import And, Expr, Not, Prop
from ..fuzzy.shapes import kernel_params
from ..words import plural

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
    "sigmoid_difference": """static double mf_sigmoid_difference(double x, double l, double r, double f, double rt) {
    return fabs(1.0 / (1.0 + exp(-(r * (x - l)))) - 1.0 / (1.0 + exp(-(f * (x - rt)))));
}""",
    "sigmoid_product": """static double mf_sigmoid_product(double x, double l, double r, double f, double rt) {
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

C_NORMS = {
    "min": "return a < b ? a : b;",
    "product": "return a * b;",
    "lukasiewicz": "double lo = a < b ? a : b, hi = a < b ? b : a, t = lo - (1.0 - hi);\n"
                   "    return t > 0.0 ? t : 0.0;",
    "drastic": "return a == 1.0 ? b : (b == 1.0 ? a : 0.0);",
    "einstein": "return (a * b) / (1.0 + (1.0 - a) * (1.0 - b));",
    "hamacher": "double hi = a < b ? b : a, lo = a < b ? a : b, d = hi + lo * (1.0 - hi);\n"
                "    return d == 0.0 ? 0.0 : (a * b) / d;",
    "nilpotent_minimum": "double lo = a < b ? a : b, hi = a < b ? b : a;\n"
                         "    return lo > 1.0 - hi ? lo : 0.0;",
    "max": "return a < b ? b : a;",
    "probabilistic_sum": "double hi = a < b ? b : a, lo = a < b ? a : b;\n"
                         "    return hi + lo * (1.0 - hi);",
    "bounded_sum": "double s = a + b;\n    return s < 1.0 ? s : 1.0;",
    "drastic_sum": "return a == 0.0 ? b : (b == 0.0 ? a : 1.0);",
    "einstein_sum": "return (a + b) / (1.0 + a * b);",
    "hamacher_sum": "double d = 1.0 - a * b;\n"
                    "    return d == 0.0 ? 1.0 : (a * (1.0 - b) + b * (1.0 - a)) / d;",
    "nilpotent_maximum": "return a + b < 1.0 ? (a < b ? b : a) : 1.0;",
}

C_HEDGES = {
    "very": "return x * x;",
    "extremely": "return x * x * x;",
    "somewhat": "return sqrt(x);",
    "more_or_less": "return sqrt(x);",
    "seldom": "return x <= 0.5 ? sqrt(0.5 * x) : 1.0 - sqrt(0.5 * (1.0 - x));",
    "intensely": "return x <= 0.5 ? 2.0 * x * x : 1.0 - 2.0 * (1.0 - x) * (1.0 - x);",
    "any": "(void)x;\n    return 1.0;",
}

PY_NORMS = {
    "min": "np.minimum(a, b)",
    "product": "a * b",
    "lukasiewicz": "np.maximum(0.0, np.minimum(a, b) - (1.0 - np.maximum(a, b)))",
    "drastic": "np.where(a == 1.0, b, np.where(b == 1.0, a, 0.0))",
    "einstein": "(a * b) / (1.0 + (1.0 - a) * (1.0 - b))",
    "hamacher": "_div(a * b, np.maximum(a, b) + np.minimum(a, b) * (1.0 - np.maximum(a, b)), "
                "0.0)",
    "nilpotent_minimum": "np.where(np.minimum(a, b) > 1.0 - np.maximum(a, b), np.minimum(a, b), "
                         "0.0)",
    "max": "np.maximum(a, b)",
    "probabilistic_sum": "np.maximum(a, b) + np.minimum(a, b) * (1.0 - np.maximum(a, b))",
    "bounded_sum": "np.minimum(1.0, a + b)",
    "drastic_sum": "np.where(a == 0.0, b, np.where(b == 0.0, a, 1.0))",
    "einstein_sum": "(a + b) / (1.0 + a * b)",
    "hamacher_sum": "_div(a * (1.0 - b) + b * (1.0 - a), 1.0 - a * b, 1.0)",
    "nilpotent_maximum": "np.where(a + b < 1.0, np.maximum(a, b), 1.0)",
}

PY_HEDGES = {
    "very": "x * x",
    "extremely": "x * x * x",
    "somewhat": "np.sqrt(x)",
    "more_or_less": "np.sqrt(x)",
    "seldom": "np.where(x <= 0.5, np.sqrt(0.5 * x), 1.0 - np.sqrt(0.5 * np.maximum(1.0 - x, 0)))",
    "intensely": "np.where(x <= 0.5, 2.0 * x * x, 1.0 - 2.0 * (1.0 - x) ** 2)",
    "any": "np.where(np.isnan(x), np.nan, 1.0)",
}


def num(value: float) -> str:
    """A float literal valid in C and Python that reads back to the same double."""
    value = float(value)
    if np.isnan(value) or np.isinf(value):
        raise ValueError(value)
    text = repr(value)
    return text if ("." in text or "e" in text or "n" in text) else text + ".0"


def ident(name: str) -> str:
    """``name`` as a C / Python identifier fragment."""
    out = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return out if out and not out[0].isdigit() else "_" + out


@dataclass(frozen=True)
class Program:
    """The straight-line form of a compiled behavior, shared by the C and Python writers."""

    compiled: CompiledRuleBase
    terms: tuple            # (var index, column name, shape, params, kernel or None)
    rules: tuple            # (column name, expression text, weight)
    shapes: tuple           # non-linear shapes used
    hedges: tuple           # hedges used
    norms: tuple            # "tnorm" / "snorm" where some rule uses them


def program(compiled: CompiledRuleBase) -> Program:
    """Build the straight-line program of ``compiled``."""
    terms = []
    shapes: set[str] = set()
    names: dict[tuple[str, str], str] = {}
    for i, (var, tname) in enumerate(compiled.term_names):
        term = compiled.variables[var].term(tname)
        col = f"mu_{ident(var)}_{ident(tname)}"
        names[(var, tname)] = col
        kernel = kernel_params(term.corners) if term.corners is not None else None
        if kernel is None:
            shapes.add(term.shape)
        terms.append((int(compiled.term_var[i]), col, term.shape, term.params, kernel))
    hedges: set[str] = set()
    used: set[str] = set()
    referenced: set[str] = set()

    def expr(e: Expr, negate: bool = False) -> str:
        """C / Python text of ``e``, or of ``not e``; ``not not x`` is ``x`` exactly, as the
        compiler has it (``1 - (1 - x)`` would round a tiny membership to 0)."""
        if isinstance(e, Prop):
            text = names[(e.var, e.term)]
            referenced.add(text)
            for h in reversed(e.hedges):
                hedges.add(h)
                text = f"hedge_{h}({text})"
            return f"(1.0 - {text})" if e.negated != negate else text
        if isinstance(e, Not):
            return expr(e.expr, not negate)
        fn = "tnorm" if isinstance(e, And) else "snorm"
        parts = [expr(i) for i in e.items]
        if len(parts) > 1:
            used.add(fn)
        acc = parts[0]
        for p in parts[1:]:
            acc = f"{fn}({acc}, {p})"
        return f"(1.0 - {acc})" if negate else acc

    rules = []
    flat = flatten(compiled.rulebase, compiled.behavior)
    for r, (label, rule, uses) in enumerate(flat):
        text = expr(rule.antecedent)
        for use in uses:
            if use.condition is not None:
                text = f"{text} * {expr(use.condition)}"
        rules.append((f"dof_{r}", text, float(compiled.weight[r])))
    terms = [t for t in terms if t[1] in referenced]
    shapes = {t[2] for t in terms if t[4] is None}
    if any(t[4] is not None for t in terms):
        used.add("kernel")
    return Program(compiled, tuple(terms), tuple(rules), tuple(sorted(shapes)),
                   tuple(sorted(hedges)), tuple(sorted(used)))


# ---------------------------------------------------------------------------------------------
# C


def to_c(compiled: CompiledRuleBase, prefix: str = "mitos", source: str = "") -> str:
    """One C99 file computing the outputs of ``compiled`` (see the module docstring)."""
    p = program(compiled)
    ops = compiled.operators
    P, U = ident(prefix), ident(prefix).upper()
    k, m = len(compiled.inputs), len(compiled.outputs)
    out = [f"/* Generated by `mitos export --to c` from {source or 'a MITOS rule base'}",
           f" * (behavior `{compiled.behavior}`: {plural(len(p.rules), 'rule')}; "
           f"{ops.describe()}).",
           " * C99, no allocation, only <math.h>: cc -std=c99 -c FILE.c, link with -lm.",
           f" * int {P}_eval(const double in[{U}_N_INPUTS], double out[{U}_N_OUTPUTS]):",
           " * inputs are clamped to their universes; an output no rule sets takes its default",
           " * (NaN when it has none); returns how many outputs took that fallback. */",
           "", "#include <math.h>", "",
           f"#define {U}_N_INPUTS {k}", f"#define {U}_N_OUTPUTS {m}"]
    for i, name in enumerate(compiled.inputs):
        lo, hi = compiled.universe[i]
        out.append(f"#define {U}_IN_{ident(name).upper()} {i}  /* [{lo:g}, {hi:g}] */")
    for j, name in enumerate(compiled.outputs):
        out.append(f"#define {U}_OUT_{ident(name).upper()} {j}")
    out += ["", "#define M_PI_ 3.14159265358979323846", ""]
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
    if ops.inference == "mamdani":
        out += ["static double aggregate(double a, double b) {",
                f"    {C_NORMS[ops.aggregation]}", "}", ""]
        if ops.implication not in ("min", "product"):
            out += ["static double implication(double a, double b) {",
                    f"    {C_NORMS[ops.implication]}", "}", ""]
    for h in p.hedges:
        out += [f"static double hedge_{h}(double x) {{", f"    {C_HEDGES[h]}", "}", ""]
    discrete = []
    out += [f"int {P}_eval(const double in[{U}_N_INPUTS], double out[{U}_N_OUTPUTS])", "{",
            f"    double x[{U}_N_INPUTS > 0 ? {U}_N_INPUTS : 1];", "    int fallback = 0;"]
    for i in range(k):
        lo, hi = compiled.universe[i]
        out.append(f"    x[{i}] = in[{i}] < {num(lo)} ? {num(lo)} : "
                   f"(in[{i}] > {num(hi)} ? {num(hi)} : in[{i}]);")
    for var, col, shape, params, kernel in p.terms:
        if kernel is not None:
            args = ", ".join(num(v) for v in kernel)
            out.append(f"    const double {col} = mf_kernel(x[{var}], {args});")
        elif shape == "discrete":
            discrete.append((col, params))
            out.append(f"    const double {col} = mf_discrete(x[{var}], {col}_xy, "
                       f"{len(params) // 2});")
        else:
            args = ", ".join(num(v) for v in params)
            out.append(f"    const double {col} = mf_{shape}(x[{var}], {args});")
    for col, text, weight in p.rules:
        w = "" if weight == 1.0 else f"{num(weight)} * "
        out.append(f"    const double {col} = {w}{text};")
    out += _c_outputs(compiled, P)
    out += ["    return fallback;", "}", ""]
    if discrete:
        tables = [f"static const double {col}_xy[{len(params)}] = {{"
                  f"{', '.join(num(v) for v in params)}}};" for col, params in discrete]
        at = out.index(f"int {P}_eval(const double in[{U}_N_INPUTS], double out[{U}_N_OUTPUTS])")
        out[at:at] = tables + [""]
    return "\n".join(out)


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


def _weighted_sums(c: CompiledRuleBase, j: int) -> tuple[str, str]:
    """Output ``j``'s weighted sums as expressions over ``dof_<r>`` and ``x[i]``, the same
    text in C and in Python: ``sum(dof * y)`` (``y`` crisp or linear) and ``sum(dof)``."""
    terms = []
    for r in np.flatnonzero(c.cons_mask[:, j]):
        value = num(c.cons_value[r, j])
        if c.cons_linear is not None:
            parts = [num(c.cons_linear[r, j, -1])] + [
                f"{num(a)} * x[{i}]" for i, a in enumerate(c.cons_linear[r, j, :-1])
                if a != 0.0]
            value = "(" + " + ".join(parts) + ")"
        terms.append((f"dof_{r}", value))
    numerator = " + ".join(f"{d} * {v}" for d, v in terms) or "0.0"
    denominator = " + ".join(d for d, _ in terms) or "0.0"
    return numerator, denominator


def _c_outputs(c: CompiledRuleBase, P: str) -> list[str]:
    ops = c.operators
    out = []
    if ops.inference == "mamdani":
        return _c_mamdani(c, P)
    for j, name in enumerate(c.outputs):
        numerator, denominator = _weighted_sums(c, j)
        default = c.default[j]
        fallback = "NAN" if np.isnan(default) else num(default)
        out.append(f"    {{   /* {name} */")
        out.append(f"        double num = {numerator};")
        if ops.inference == "weighted_sum":
            out.append(f"        out[{j}] = num;")
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
        out.append(f"    {{   /* {name}: Mamdani, {plural(res, 'sample')} */")
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
        out += ["        " + line for line in _c_defuzzify(ops.defuzzify, res, j, fallback)]
        out.append("    }")
    return out


def _c_defuzzify(method: str, res: int, j: int, fallback: str) -> list[str]:
    done = [f"if (value != value) {{ out[{j}] = {fallback}; ++fallback; }}",
            f"else out[{j}] = value;"]
    if method == "centroid":
        return ["{", "    double num = 0.0, den = 0.0, value = NAN;",
                f"    for (i = 0; i < {res}; ++i) {{ num += y[i] * grid[i]; den += y[i]; }}",
                "    if (den > 0.0) value = num / den;", *("    " + d for d in done), "}"]
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
                    f"grid[i]; break; }}"]}[method]
    return ["{", "    double top = 0.0, value = NAN;",
            f"    for (i = 0; i < {res}; ++i) if (y[i] > top) top = y[i];",
            "    if (top > 0.0) {", *pick, "    }", *("    " + d for d in done), "}"]


# ---------------------------------------------------------------------------------------------
# Python (NumPy only)


def to_python(compiled: CompiledRuleBase, source: str = "") -> str:
    """A NumPy-only module with ``evaluate(X) -> Y`` for ``X[n, k]`` (and ``INPUTS``,
    ``OUTPUTS``, ``evaluate_one(**inputs)``)."""
    p = program(compiled)
    ops = compiled.operators
    out = [f'"""Generated by `mitos export --to python` from {source or "a MITOS rule base"}',
           f"(behavior `{compiled.behavior}`: {plural(len(p.rules), 'rule')}; "
           f"{ops.describe()}).", "",
           "``evaluate(X)`` maps inputs ``X[n, k]`` (columns in INPUTS order, clamped to their",
           "universes) to outputs ``Y[n, m]`` (OUTPUTS order); an output no rule sets takes its",
           'default (NaN when it has none). Needs only NumPy."""', "",
           "import numpy as np", "",
           f"INPUTS = {tuple(compiled.inputs)!r}", f"OUTPUTS = {tuple(compiled.outputs)!r}",
           f"UNIVERSE = {[tuple(map(float, u)) for u in compiled.universe]!r}",
           f"DEFAULT = {[None if np.isnan(d) else float(d) for d in compiled.default]!r}", "", "",
           "def _div(n, d, zero):", "    with np.errstate(invalid='ignore', divide='ignore'):",
           "        q = n / d", "    return np.where(d == 0, zero, q)", "", "",
           "def mf_kernel(x, b, s1, c, s2):",
           "    return np.clip(1.0 + np.minimum((x - b) * s1, (c - x) * s2), 0.0, 1.0)", "", ""]
    out += _py_shapes(p.shapes)
    out += ["def tnorm(a, b):", f"    return {PY_NORMS[ops.and_]}", "", "",
            "def snorm(a, b):", f"    return {PY_NORMS[ops.or_]}", "", ""]
    for h in p.hedges:
        out += [f"def hedge_{h}(x):", "    with np.errstate(invalid='ignore'):",
                f"        return {PY_HEDGES[h]}", "", ""]
    out += ["def evaluate(X):", '    """Outputs ``Y[n, m]`` for inputs ``X[n, k]``."""',
            "    X = np.atleast_2d(np.asarray(X, dtype=float))",
            f"    if X.shape[1] != {len(compiled.inputs)}:",
            f"        raise ValueError('expected {len(compiled.inputs)} input columns: ' "
            f"+ ', '.join(INPUTS))",
            "    lo = np.array([u[0] for u in UNIVERSE]); hi = np.array([u[1] for u in UNIVERSE])",
            "    x = np.clip(X, lo, hi).T",
            "    Y = np.empty((X.shape[0], len(OUTPUTS)))"]
    for var, col, shape, params, kernel in p.terms:
        if kernel is not None:
            out.append(f"    {col} = mf_kernel(x[{var}], {', '.join(num(v) for v in kernel)})")
        else:
            out.append(f"    {col} = mf_{shape}(x[{var}], {', '.join(num(v) for v in params)})")
    for col, text, weight in p.rules:
        w = "" if weight == 1.0 else f"{num(weight)} * "
        out.append(f"    {col} = {w}{text} + np.zeros(X.shape[0])")
    out += _py_outputs(compiled)
    out += ["    return Y", "", "",
            "def evaluate_one(**inputs):",
            '    """Outputs by name for one value per input (by name)."""',
            "    row = np.array([[float(inputs[name]) for name in INPUTS]])",
            "    return dict(zip(OUTPUTS, (float(v) for v in evaluate(row)[0])))", ""]
    return "\n".join(out)


def _py_shapes(shapes) -> list[str]:
    """NumPy shape functions: MITOS's own (copied by source) so results agree exactly."""
    import inspect

    from ..fuzzy import shapes as shapes_mod

    out = []
    done: set[str] = set()

    def emit(name: str) -> None:
        if name in done:
            return
        done.add(name)
        deps = {"pi_shape": ("s_shape", "z_shape"), "sigmoid_difference": ("sigmoid",),
                "sigmoid_product": ("sigmoid",), "gaussian2": ("gaussian",),
                "rectangle": ("trapezoid",), "ramp": ("trapezoid",)}.get(name, ())
        for d in deps:
            emit(d)
        fn = getattr(shapes_mod, name)
        src = inspect.getsource(fn).replace(f"def {name}(", f"def mf_{name}(", 1)
        for d in deps + ("_nan_of",):
            src = re.sub(rf"(?<![\w.]){d}\(", f"mf_{d}(", src)
        out.extend([src.rstrip(), "", ""])

    if any(s not in ("singleton",) for s in shapes):
        out += ["INF = float('inf')", "", "",
                "def mf__nan_of(x):", "    return np.where(np.isnan(x), np.nan, 1.0)", "", ""]
    for s in shapes:
        emit(s)
    return out


def _py_outputs(c: CompiledRuleBase) -> list[str]:
    ops = c.operators
    out = []
    if ops.inference == "mamdani":
        out.append("    with np.errstate(invalid='ignore', divide='ignore'):")
        for j, table in enumerate(c.mamdani):
            grid = "[" + ", ".join(num(v) for v in table.grid) + "]"
            sets = "[" + ", ".join("[" + ", ".join(num(v) for v in row) + "]"
                                   for row in table.sets) + "]"
            dofs = ", ".join(f"dof_{r}" for r in table.rules)
            imp = f"(lambda a, b: {PY_NORMS[ops.implication]})(D, S)"
            agg = PY_NORMS[ops.aggregation]
            out += [f"        grid = np.array({grid})", f"        sets = np.array({sets})",
                    f"        D = np.stack([{dofs}])[:, :, None]",
                    f"        S = sets[{[int(s) for s in table.set_of]!r}][:, None, :]",
                    f"        I = {imp}", "        a = I[0]", "        for b in I[1:]:",
                    f"            a = {agg}", "        Yj = a"]
            out += ["        " + line for line in _py_defuzzify(ops.defuzzify)]
            out.append(f"        Y[:, {j}] = value")
    else:
        for j, name in enumerate(c.outputs):
            numerator, denominator = _weighted_sums(c, j)
            out.append(f"    num = {numerator} + np.zeros(X.shape[0])")
            if ops.inference == "weighted_sum":
                out.append(f"    Y[:, {j}] = num")
            else:
                out.append(f"    den = {denominator} + np.zeros(X.shape[0])")
                out.append(f"    Y[:, {j}] = _div(num, np.where(den > 0, den, 1.0), 0.0)")
                out.append(f"    Y[den <= 0, {j}] = np.nan")
    for j in range(len(c.outputs)):
        d = c.default[j]
        if not np.isnan(d):
            out.append(f"    Y[np.isnan(Y[:, {j}]) & ~np.isnan(X).any(axis=1), {j}] = {num(d)}")
    return out


def _py_defuzzify(method: str) -> list[str]:
    if method == "centroid":
        return ["den = Yj.sum(axis=1)",
                "value = np.where(den > 0, (Yj * grid).sum(axis=1) / np.where(den > 0, den, 1), "
                "np.nan)"]
    if method == "bisector":
        return ["area = np.cumsum(Yj, axis=1)", "total = area[:, -1:]",
                "gap = np.abs(area / total - 0.5)",
                "ties = gap == gap.min(axis=1, keepdims=True)",
                "value = np.where(total[:, 0] > 0, np.where(ties, grid, 0.0).sum(axis=1) "
                "/ np.maximum(ties.sum(axis=1), 1), np.nan)"]
    pick = {"mom": "np.where(peak, grid, 0.0).sum(axis=1) / np.maximum(peak.sum(axis=1), 1)",
            "som": "grid[np.argmax(peak, axis=1)]",
            "lom": "grid[len(grid) - 1 - np.argmax(peak[:, ::-1], axis=1)]"}[method]
    return ["top = Yj.max(axis=1, keepdims=True)", "peak = (Yj > 0) & (Yj == top)",
            f"value = np.where(peak.any(axis=1), {pick}, np.nan)"]
