"""The Python backend of ``mitos export``: one module that needs only NumPy.

``evaluate(X)`` maps inputs ``X[n, k]`` to outputs ``Y[n, m]`` with MITOS's own arithmetic
(the shape functions are copied from :mod:`mitos_cli.fuzzy.shapes` by source). Names from the rule
base appear only as ``repr`` literals (``INPUTS``, ``OUTPUTS``), in the docstring through
:func:`doc_text`, and in identifiers made by :mod:`.program`.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, cast

import numpy as np

from ...engine.compile import CompiledRuleBase
from ...fuzzy.hedges import HEDGES
from ...fuzzy.norms import SNORMS, TNORMS, UNBOUNDED_SUM
from ...words import plural
from .program import PLAIN, Program, num, program, weighted_sums

if TYPE_CHECKING:
    from collections.abc import Iterable

PY_NORMS = {n.name: n.numpy for n in (*TNORMS.values(), *SNORMS.values(), UNBOUNDED_SUM)}   # fuzzy/norms.py

PY_HEDGES = {h.name: h.numpy for h in HEDGES.values()}   # fuzzy/hedges.py


def doc_text(text: str) -> str:
    """``text`` safe inside a triple-quoted docstring: as it is when plain, else as its
    ASCII ``repr`` with every ``"`` escaped, so that no quote or backslash can end it."""
    return text if PLAIN.fullmatch(text) else ascii(text).replace('"', '\\"')


#: evaluate_one's check of its keywords: a TypeError as a Python function's call gives, with
#: the closest input for an unknown one (a bare KeyError, or a typo silently ignored, before;
#: ``raod`` got no hint, a swap of two letters counting as two edits). Plain Python, no
#: import: the module imports NumPy alone (tests/test_export_hostile.py).
CHECK_NAMES = [
    "def _check_names(inputs):",
    '    """A missing or unknown input, as a TypeError naming it."""',
    "    for name in inputs:",
    "        if name not in INPUTS:",
    "            close = _closest(name)",
    "            hint = (f'; did you mean {close!r}?' if close is not None",
    "                    else '; the inputs are ' + ', '.join(f'{n!r}' for n in INPUTS))",
    "            raise TypeError(f'evaluate_one() got an unexpected keyword argument '",
    "                            f'{name!r}{hint}')",
    "    missing = [name for name in INPUTS if name not in inputs]",
    "    if missing:",
    "        raise TypeError(f'evaluate_one() missing {len(missing)} required keyword '",
    "                        f\"argument{'s' if len(missing) > 1 else ''}: \"",
    "                        + ', '.join(f'{n!r}' for n in missing))",
    "",
    "",
    "def _closest(name):",
    '    """The input fewest edits from ``name`` in any case (at most a third of its length; two',
    '    letters swapped are one edit), else the one input it begins, or None."""',
    "    low = name.lower()",
    "    best, found = max(1, len(name) // 3) + 1, None",
    "    for other in INPUTS:",
    "        edits = _edits(low, other.lower())",
    "        if edits < best:",
    "            best, found = edits, other",
    "    if found is None and len(name) >= 3:",
    "        starts = [other for other in INPUTS if other.lower().startswith(low)]",
    "        found = starts[0] if len(starts) == 1 else None",
    "    return found",
    "",
    "",
    "def _edits(a, b):",
    '    """Insertions, deletions, substitutions and swaps of two neighbours from ``a`` to ``b``."""',
    "    before, row = None, list(range(len(b) + 1))",
    "    for i in range(1, len(a) + 1):",
    "        above, row = row, [i] + [0] * len(b)",
    "        for j in range(1, len(b) + 1):",
    "            row[j] = min(above[j] + 1, row[j - 1] + 1, above[j - 1] + (a[i - 1] != b[j - 1]))",
    "            if i > 1 and j > 1 and a[i - 1] == b[j - 2] and a[i - 2] == b[j - 1]:",
    "                row[j] = min(row[j], before[j - 2] + 1)",
    "        before = above",
    "    return row[-1]",
    ""]


#: evaluate's and evaluate_one's check of their values: what NumPy would take silently (a bool
#: as 1 or 0) or reject with its own words from deep inside (a 3-D ``X``: "could not broadcast";
#: an array for one input: "only 0-dimensional arrays can be converted").
CHECK_VALUES = [
    "def _rows(X):",
    '    """``X`` as floats ``[n, k]`` (one sample ``[k]`` as one row), or an error saying why not."""',
    "    if _holds_bool(X):",
    "        raise TypeError('X must hold numbers, not bools: True and False would be read as 1 '",
    "                        'and 0')",
    "    X = np.atleast_2d(np.asarray(X, dtype=float))",
    "    if X.ndim != 2:",
    "        raise ValueError(f'X must be 2-D, one row of {len(INPUTS)} inputs per sample '",
    "                         f'(X[n, {len(INPUTS)}]), not of shape {X.shape}')",
    "    if X.shape[1] != len(INPUTS):",
    "        raise ValueError(f'expected {len(INPUTS)} input columns ({\", \".join(INPUTS)}), '",
    "                         f'not {X.shape[1]}')",
    "    return X",
    "",
    "",
    "def _holds_bool(value):",
    '    """Whether ``value`` is a bool or holds one (NumPy reads a bool among numbers as 1 or 0)."""',
    "    if isinstance(value, (bool, np.bool_)):",
    "        return True",
    "    if isinstance(value, np.ndarray):",
    "        return value.dtype == bool or (value.dtype.kind == 'O'",
    "                                         and any(_holds_bool(v) for v in value.flat))",
    "    if isinstance(value, (list, tuple)):",
    "        for v in value:",
    "            if isinstance(v, (bool, np.bool_, list, tuple, np.ndarray)) and _holds_bool(v):",
    "                return True",
    "    return False",
    "",
    "",
    "def _value(name, value):",
    '    """One input\'s value as a float: not a bool (read as 1 or 0), not several values."""',
    "    if isinstance(value, float):   # (NumPy's float64 too; a bool is an int)",
    "        return float(value)",
    "    if _holds_bool(value):",
    "        raise TypeError(f'evaluate_one() takes numbers, not bools: {name}={value!r} would be '",
    "                        'read as 1 or 0')",
    "    if isinstance(value, (list, tuple)) or np.ndim(value) != 0:",
    "        raise TypeError(f'evaluate_one() takes one number per input, not {value!r:.60} for '",
    "                        f'{name!r}; evaluate(X) takes many samples, one row each')",
    "    return float(value)",
    ""]


def to_python(compiled: CompiledRuleBase, source: str = "") -> str:
    """A NumPy-only module with ``evaluate(X) -> Y`` for ``X[n, k]`` (and ``INPUTS``,
    ``OUTPUTS``, ``evaluate_one(**inputs)``)."""
    p = program(compiled)
    ops = compiled.operators
    out = _py_header(p, source)
    out += _py_shapes(p.shapes)
    out += ["def tnorm(a, b):", f"    return {PY_NORMS[ops.and_]}", "", "",
            "def snorm(a, b):", f"    return {PY_NORMS[ops.or_]}", "", ""]
    if compiled.joins:
        out += ["def accumulate(a, b):", f"    return {PY_NORMS[ops.accumulation]}", "", ""]
    for h in p.hedges:
        out += [f"def hedge_{h}(x):", "    with np.errstate(invalid='ignore'):",
                f"        return {PY_HEDGES[h]}", "", ""]
    out += _py_evaluate(p)
    out += _py_row(p)
    out += ["def evaluate_one(**inputs):",
            '    """Outputs by name for one value per input (by name)."""',
            "    _check_names(inputs)",
            "    values = [_value(name, inputs[name]) for name in INPUTS]",
            "    y = None if _evaluate_row is None else _evaluate_row(*values)",
            "    if y is None:",
            "        y = evaluate(np.array([values]))[0]",
            "    return dict(zip(OUTPUTS, (float(v) for v in y)))", "", "",
            *CHECK_NAMES, "", *CHECK_VALUES]
    return "\n".join(out)


def _py_row(p: Program) -> list[str]:
    """``_evaluate_row(x0, ...)``: ``evaluate``'s row for one sample in plain floats, for
    ``evaluate_one``, whose forty-odd NumPy calls on one row took 130 us (the paper's base).
    The same operations in the same order give the same bits (IEEE 754 rounds ``+ - * /``
    and ``sqrt`` alike in Python and NumPy; tests/test_export_python_row.py holds them).
    ``None`` (for the whole module) where a shape, hedge or join has no exact float form, and
    from a call whose input is NaN or, not clamped, outside its universe: ``evaluate`` then."""
    c = p.compiled
    ops = c.operators
    hedges = [h for h in p.hedges if HEDGES[h].scalar]
    if (p.shapes or len(hedges) < len(p.hedges) or ops.inference == "mamdani"
            or c.accumulated is not None):
        return ["_evaluate_row = None  # (no exact form in floats: evaluate_one uses evaluate)",
                "", ""]
    out = []
    for fn, name in (("tnorm", ops.and_), ("snorm", ops.or_)):
        out += [f"def _{fn}1(a, b):", *_indented({**TNORMS, **SNORMS}[name].scalar),
                "    return r", "", ""]
    for h in hedges:
        out += [f"def _hedge1_{h}(x):",
                *_indented(HEDGES[h].scalar.replace("sqrt(", "math.sqrt(")), "    return x", "", ""]
    args = [f"x{i}" for i in range(len(c.inputs))]
    out += [f"def _evaluate_row({', '.join(args)}):",
            '    """``evaluate``\'s row for one sample, or None (``evaluate`` then)."""',
            f"    if {' or '.join(f'{x} != {x}' for x in args)}:", "        return None"]
    for x, (lo, hi) in zip(args, c.universe.tolist()):
        if ops.inputs == "clamped":       # np.clip: min(max(x, lo), hi), each as NumPy's
            out += [f"    {x} = {x} if {x} > {num(lo)} else {num(lo)}",
                    f"    {x} = {x} if {x} < {num(hi)} else {num(hi)}"]
        else:                             # outside: evaluate (an infinite one is NaN there)
            out += [f"    if not {num(lo)} <= {x} <= {num(hi)}:", "        return None",
                    f"    {x} = {x} + 0.0"]
    if any("x[" in text for _, text, _ in p.rules) or c.cons_linear is not None:
        out.append(f"    x = [{', '.join(args)}]")
    for var, col, _, _, kernel in p.terms:
        out.append(f"    {col} = _kernel1(x{var}, {', '.join(num(v) for v in kernel)})")
    for col, text, weight in p.rules:
        w = "" if weight == 1.0 else f"{num(weight)} * "
        out.append(f"    {col} = {w}{_floats(text)} + 0.0")
    out += _py_row_outputs(c)
    return out + ["", "", *KERNEL1]


def _py_row_outputs(c: CompiledRuleBase) -> list[str]:
    """``_py_outputs``' weighted sums, division and defaults on floats."""
    out, ys = [], []
    for j in range(len(c.outputs)):
        _, numerator, denominator = weighted_sums(c, j, "python")
        out.append(f"    num = {_floats(numerator)} + 0.0")
        if c.operators.inference == "weighted_sum" and j not in c.summed_defaults:
            out.append(f"    y{j} = num")
        else:
            out.append(f"    den = {_floats(denominator)} + 0.0")
            out.append(f"    y{j} = num if den > 0.0 else math.nan" if c.operators.inference
                       == "weighted_sum" else
                       f"    y{j} = num / den if den > 0.0 else math.nan")
        if not np.isnan(c.default[j]):
            out.append(f"    y{j} = {num(c.default[j])} if y{j} != y{j} else y{j}")
        ys.append(f"y{j}")
    return out + [f"    return ({', '.join(ys)},)"]


#: ``mf_kernel`` on floats inside the universe (no NaN): np.minimum, then np.clip as
#: min(max(v, 0), 1); ``1.0 +`` leaves no signed zero to tell the two choices of a tie apart.
KERNEL1 = [
    "def _kernel1(x, b, s1, c, s2):",
    "    r = (x - b) * s1",
    "    f = (c - x) * s2",
    "    v = 1.0 + (r if r <= f else f)",
    "    v = v if v > 0.0 else 0.0",
    "    return v if v < 1.0 else 1.0",
    "", ""]


def _indented(statements: str) -> list[str]:
    return ["    " + line for line in statements.splitlines()]


def _floats(text: str) -> str:
    """A rule's or a sum's text calling the float forms of the norms and hedges."""
    return re.sub(r"(?<![\w.])(tnorm|snorm|hedge)([_(])", r"_\g<1>1\2", text)


def _py_header(p: Program, source: str) -> list[str]:
    """The docstring, the constants and the two helpers every module uses."""
    c = p.compiled
    return [
        f'"""Generated by `mitos export --to python` from '
        f'{doc_text(source or "a MITOS rule base")}',
        f"(behavior `{doc_text(c.behavior)}`: {plural(len(p.rules), 'rule')}; "
        f"{doc_text(c.describe_operators())}).", "",
        # (one line; `inputs = as_given` had the clamped line too, then its own)
        "``evaluate(X)`` maps inputs ``X[n, k]`` (columns in INPUTS order, clamped to their\n"
        "universes) to outputs ``Y[n, m]`` (OUTPUTS order); an output no rule sets takes its"
        if c.operators.inputs == "clamped" else
        "``evaluate(X)`` maps inputs ``X[n, k]`` (columns in INPUTS order, not clamped: an\n"
        "infinite one gives NaN) to outputs ``Y[n, m]`` (OUTPUTS order); an output no rule "
        "sets takes its",
        f'default ({"0, the empty sum," if c.operators.inference == "weighted_sum" else "NaN"} '
        'when it has none). Needs only NumPy."""', "",
        "import math", "", "import numpy as np", "",
        f"INPUTS = {tuple(map(str, c.inputs))!r}", f"OUTPUTS = {tuple(map(str, c.outputs))!r}",
        f"UNIVERSE = {[tuple(map(float, u)) for u in c.universe]!r}",
        f"DEFAULT = {[None if np.isnan(d) else float(d) for d in c.default]!r}", "", "",
        "def _div(n, d, zero):", "    with np.errstate(invalid='ignore', divide='ignore'):",
        "        q = n / d", "    return np.where(d == 0, zero, q)", "", "",
        "def mf_kernel(x, b, s1, c, s2):",
        # an input far outside the universe (not clamped: `inputs = as_given`) makes a slope
        # overflow to +-inf, whose membership is then 0 or 1, as the engine's: no warning
        "    with np.errstate(over='ignore'):",
        "        return np.clip(1.0 + np.minimum((x - b) * s1, (c - x) * s2), 0.0, 1.0)", "", ""]


#: Rows the exported ``evaluate`` works on at a time: its arrays of a membership or a rule
#: (128 KB each) stay in cache. 10^6 rows of the paper's 27 rules took 0.096 s in blocks of
#: 16,384 against 0.20 s whole (8,192 to 65,536: 0.096-0.102 s; 1,024: 0.22 s); every
#: operation is per row, so a row gets the same bits in any block.
BLOCK = 16384


def _py_evaluate(p: Program) -> list[str]:
    """``evaluate(X)`` over blocks of :data:`BLOCK` rows, and ``_evaluate_block``: clamped
    inputs, one array per membership and per rule, the outputs."""
    c = p.compiled
    out = [f"BLOCK = {BLOCK}  # rows at a time: a block's arrays stay in cache", "", "",
           "def evaluate(X):", '    """Outputs ``Y[n, m]`` for inputs ``X[n, k]``."""',
           "    X = _rows(X)",
           "    Y = np.empty((X.shape[0], len(OUTPUTS)))",
           "    for i in range(0, X.shape[0], BLOCK):",
           "        Y[i:i + BLOCK] = _evaluate_block(X[i:i + BLOCK])",
           "    return Y", "", "",
           "def _evaluate_block(X):",
           '    """``evaluate`` of at most ``BLOCK`` rows ``X``, checked."""',
           "    lo = np.array([u[0] for u in UNIVERSE]); hi = np.array([u[1] for u in UNIVERSE])",
           "    x = np.clip(X, lo, hi).T" if c.operators.inputs == "clamped" else
           "    X = np.where(np.isinf(X), np.nan, X)  # not clamped: infinite reads as NaN\n"
           "    x = X.T + 0.0",
           "    Y = np.empty((X.shape[0], len(OUTPUTS)))"]
    for var, col, shape, params, kernel in p.terms:
        if kernel is not None:
            out.append(f"    {col} = mf_kernel(x[{var}], {', '.join(num(v) for v in kernel)})")
        else:
            out.append(f"    {col} = mf_{shape}(x[{var}], {', '.join(num(v) for v in params)})")
    for col, text, weight in p.rules:
        w = "" if weight == 1.0 else f"{num(weight)} * "
        out.append(f"    {col} = {w}{text} + np.zeros(X.shape[0])")
    return out + _py_outputs(c) + ["    return Y", "", ""]


def _py_shapes(shapes: Iterable[str]) -> list[str]:
    """NumPy shape functions: MITOS's own (copied by source) so results agree exactly."""
    import ast
    import inspect

    from ...fuzzy import shapes as shapes_mod

    out = []
    done: set[str] = set()

    def emit(name: str) -> None:
        if name in done:
            return
        done.add(name)
        deps = {"pi_shape": ("s_shape", "z_shape"), "sigmoid_difference": ("sigmoid",),
                "clipped_sigmoid_difference": ("sigmoid",),
                "sigmoid_product": ("sigmoid",), "gaussian2": ("gaussian",),
                "rectangle": ("trapezoid",), "ramp": ("trapezoid",)}.get(name, ())
        for d in deps:
            emit(d)
        fn = getattr(shapes_mod, name)
        # the header without its annotations, which name the type checker's aliases (ArrayLike,
        # Param): the program defines none of them, and would fail at the `def`
        lines = inspect.getsource(fn).splitlines()
        node = cast(ast.FunctionDef, ast.parse(inspect.getsource(fn)).body[0])
        first = node.body[0].lineno                                   # (the docstring)
        params = ", ".join(str(p.replace(annotation=p.empty))
                           for p in inspect.signature(fn).parameters.values())
        src = "\n".join([f"def mf_{name}({params}):", *lines[first - 1:]]) + "\n"
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
            universe = c.variables[table.name].universe
            out += ["        " + line for line in _py_defuzzify(ops.defuzzify, universe)]
            out.append(f"        Y[:, {j}] = value")
    else:
        for j in range(len(c.outputs)):
            statements, numerator, denominator = weighted_sums(c, j, "python")
            out += [f"    {line}" for line in statements]
            out.append(f"    num = {numerator} + np.zeros(X.shape[0])")
            if ops.inference == "weighted_sum" and j not in c.summed_defaults:
                out.append(f"    Y[:, {j}] = num")          # no rule firing: the empty sum, 0
            elif ops.inference == "weighted_sum":
                out.append(f"    den = {denominator} + np.zeros(X.shape[0])")
                out.append(f"    Y[:, {j}] = np.where(den > 0, num, np.nan)")
            else:
                out.append(f"    den = {denominator} + np.zeros(X.shape[0])")
                out.append(f"    Y[:, {j}] = _div(num, np.where(den > 0, den, 1.0), 0.0)")
                out.append(f"    Y[den <= 0, {j}] = np.nan")
    for j in range(len(c.outputs)):
        d = c.default[j]
        if not np.isnan(d):
            out.append(f"    Y[np.isnan(Y[:, {j}]) & ~np.isnan(X).any(axis=1), {j}] = {num(d)}")
    return out


def _py_defuzzify(method: str, universe: tuple[float, float]) -> list[str]:
    if method == "centroid":
        return ["den = Yj.sum(axis=1)",
                "value = np.where(den > 0, (Yj * grid).sum(axis=1) / np.where(den > 0, den, 1), "
                "np.nan)"]
    if method == "matlab_bisector":
        return ["area = np.cumsum(Yj, axis=1)", "total = area[:, -1:]",
                "value = np.where(total[:, 0] > 0, "
                "grid[np.argmax(area >= total / 2, axis=1)], np.nan)"]
    if method == "jfuzzylogic_bisector":   # mamdani.walk_from_both_ends
        lo, hi = (num(float(v)) for v in universe)
        return ["n, z = Yj.shape[1], np.zeros((len(Yj), 1))",
                "left = np.concatenate([z, np.cumsum(Yj[:, 1:], axis=1)], axis=1)",
                "right = np.concatenate([z, np.cumsum(Yj[:, n - 2:0:-1], axis=1)], axis=1)",
                "low = np.count_nonzero(left[:, :n - 1] <= right[:, ::-1], axis=1)",
                f"value = np.where(left[np.arange(len(Yj)), low] > 0, "
                f"{lo} + (({hi} - {lo}) / n) * low, np.nan)"]
    if method == "bisector":
        return ["area = np.cumsum(Yj, axis=1)", "total = area[:, -1:]",
                "gap = np.abs(area / total - 0.5)",
                "ties = gap == gap.min(axis=1, keepdims=True)",
                "value = np.where(total[:, 0] > 0, np.where(ties, grid, 0.0).sum(axis=1) "
                "/ np.maximum(ties.sum(axis=1), 1), np.nan)"]
    pick = {"mom": "np.where(peak, grid, 0.0).sum(axis=1) / np.maximum(peak.sum(axis=1), 1)",
            "som": "grid[np.argmax(peak, axis=1)]",
            "lom": "grid[len(grid) - 1 - np.argmax(peak[:, ::-1], axis=1)]",
            "matlab_som": "grid[np.argmin(np.where(peak, np.abs(grid), np.inf), axis=1)]",
            "matlab_lom": "grid[np.argmax(np.where(peak, np.abs(grid), -1.0), axis=1)]",
            }[method]
    return ["top = Yj.max(axis=1, keepdims=True)", "peak = (Yj > 0) & (Yj == top)",
            f"value = np.where(peak.any(axis=1), {pick}, np.nan)"]
