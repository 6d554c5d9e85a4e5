"""Generated code only computes, whatever the names in the file it came from.

For each reader (.rules with its YAML term set, FCL, .fis, FLL) hypothesis writes rule bases
whose file, variable, term and behavior names carry quotes, triple quotes, ``*/``, line
breaks, backslashes, trigraphs and non-ASCII text, as far as that reader accepts them. The
exported Python module must contain nothing but a docstring, ``import numpy``, constant
assignments and plain functions that use only names they bind (no ``__import__``, ``open``,
``os`` ...), and agree with the engine; the C file must compile with the system ``cc``, keep
to ``#include <math.h>`` and ``#define``, define only ``PREFIX_eval`` and call nothing outside
libm; the scalar form that :mod:`mitos_cli.engine.scalar` ``exec``-s must be one function of floats.
"""

from __future__ import annotations

import ast
import importlib.util
import itertools
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mitos_cli.api import load_rulebase
from mitos_cli.interop.export import to_c, to_python

CC = shutil.which("cc") or shutil.which("gcc")
NM = shutil.which("nm")
LIBM = {"exp", "pow", "fabs", "sqrt", "cos"}
COUNTER = itertools.count()

PIECES = ['"', "'", '"""', "'''", "*/", "/*", "\\", "\n", "??/", "??=", "é", "∞", "\u2028",
          "#", "%s", "{}", "${x}", ";", "(", ")", " ", "x", "_", "0", "-", ".", "`", "\t",
          '__import__("os").system("touch ran")', "\\N{BULLET}", "\\x41"]
hostile = st.lists(st.sampled_from(PIECES), min_size=1, max_size=8).map("".join)
#: The rule language's and FCL's / FLL's name tokens, with the characters that sanitise alike.
rules_name = st.from_regex(r"[A-Za-z_]([A-Za-z0-9_\-]{0,6}[A-Za-z0-9_])?", fullmatch=True)
dotted_name = st.from_regex(r"[A-Za-z_][A-Za-z0-9_.]{0,6}", fullmatch=True)
KEYWORDS = {"if", "then", "and", "or", "not", "is", "with", "end", "use", "when", "behavior",
            "very", "somewhat", "seldom", "extremely", "any", "intensely", "more_or_less",
            "terms", "operators", "frozen", "IF", "THEN", "AND", "OR", "NOT", "IS", "WITH"}


def no_keyword(name: str) -> bool:
    return name.lower() not in {k.lower() for k in KEYWORDS} and not name.upper().startswith(
        ("END_", "VAR", "FUZZIFY", "DEFUZZIFY", "RULEBLOCK", "FUNCTION_BLOCK", "TERM", "RULE",
         "RANGE", "METHOD", "DEFAULT", "ACCU", "ACT", "LOCK", "OPTION"))


def file_name(text: str, suffix: str) -> str:
    """``text`` as a file name this system accepts (no ``/``, no NUL, short enough)."""
    name = text.replace("/", "|").replace("\0", "")[:80]
    return name + suffix


def distinct(names: list[str]) -> list[str]:
    """The names with an index appended where one repeats (readers refuse duplicates)."""
    seen: dict[str, int] = {}
    out = []
    for n in names:
        out.append(n if n not in seen else f"{n}{seen[n]}")
        seen[n] = seen.get(n, 0) + 1
    return out


# ---- one rule base per reader ----------------------------------------------------------------

def write_rules(d: Path, fname: str, names: list[str]) -> Path:
    a, b, y, t1, t2, beh = names
    (d / "t.terms.yaml").write_text(
        "variables:\n"
        f"  {a}: {{role: input, universe: [0, 10], terms: {{{t1}: {{shape: triangle, "
        f"points: [0, 0, 10]}}, {t2}: {{shape: triangle, points: [0, 10, 10]}}}}}}\n"
        f"  {b}: {{role: input, universe: [-1, 1], terms: {{{t1}: {{shape: gaussian, "
        f"points: [0, 0.5]}}}}}}\n"
        f"  {y}: {{role: output, universe: [0, 100], terms: {{{t1}: 10, {t2}: 90}}}}\n")
    path = d / file_name(fname, ".rules")
    path.write_text(f'terms "t.terms.yaml"\nbehavior {beh}:\n'
                    f"  r1: if {a} is {t1} and {b} is very {t1} then {y} is {t1}\n"
                    f"  r2: if {a} is {t2} or not {b} is {t1} then {y} is {t2}\nend\n")
    return path


def write_fcl(d: Path, fname: str, names: list[str]) -> Path:
    a, b, y, t1, t2, block = names
    path = d / file_name(fname, ".fcl")
    path.write_text(f"""FUNCTION_BLOCK {block}
VAR_INPUT {a} : REAL; {b} : REAL; END_VAR
VAR_OUTPUT {y} : REAL; END_VAR
FUZZIFY {a} RANGE := (0 .. 10); TERM {t1} := (0, 1) (10, 0); TERM {t2} := (0, 0) (10, 1);
END_FUZZIFY
FUZZIFY {b} RANGE := (-1 .. 1); TERM {t1} := (-1, 0) (0, 1) (1, 0); END_FUZZIFY
DEFUZZIFY {y} RANGE := (0 .. 100); TERM {t1} := 10; TERM {t2} := 90; METHOD : COGS;
DEFAULT := 50; END_DEFUZZIFY
RULEBLOCK {block} AND : MIN; OR : MAX; ACT : MIN; ACCU : MAX;
RULE 1 : IF {a} IS {t1} AND {b} IS {t1} THEN {y} IS {t1};
RULE 2 : IF {a} IS {t2} OR {b} IS NOT {t1} THEN {y} IS {t2};
END_RULEBLOCK
END_FUNCTION_BLOCK
""")
    return path


def write_fis(d: Path, fname: str, names: list[str]) -> Path:
    a, b, y, t1, t2, system = names
    path = d / file_name(fname, ".fis")
    path.write_text(f"""[System]
Name='{system}'
Type='sugeno'
Version=2.0
NumInputs=2
NumOutputs=1
NumRules=2
AndMethod='prod'
OrMethod='max'
ImpMethod='prod'
AggMethod='sum'
DefuzzMethod='wtaver'

[Input1]
Name='{a}'
Range=[0 10]
NumMFs=2
MF1='{t1}':'trimf',[0 0 10]
MF2='{t2}':'gaussmf',[2 10]

[Input2]
Name='{b}'
Range=[-1 1]
NumMFs=1
MF1='{t1}':'trapmf',[-1 -0.5 0 1]

[Output1]
Name='{y}'
Range=[0 100]
NumMFs=2
MF1='{t1}':'constant',[10]
MF2='{t2}':'linear',[3 -2 40]

[Rules]
1 1, 1 (1) : 1
2 -1, 2 (0.5) : 2
""")
    return path


def write_fll(d: Path, fname: str, names: list[str], blocks: tuple[str, str]) -> Path:
    a, b, y, t1, t2, z = names
    path = d / file_name(fname, ".fll")
    path.write_text(f"""Engine: {blocks[0]}
InputVariable: {a}
  range: 0.000 10.000
  term: {t1} Triangle 0 0 10
  term: {t2} Triangle 0 10 10
InputVariable: {b}
  range: -1 1
  term: {t1} Gaussian 0 0.5
OutputVariable: {y}
  range: 0 100
  default: 50
  defuzzifier: WeightedAverage
  term: {t1} Constant 10
  term: {t2} Constant 90
OutputVariable: {z}
  range: 0 100
  default: 50
  defuzzifier: WeightedAverage
  term: {t1} Constant 20
RuleBlock: {blocks[0]}
  conjunction: Minimum
  activation: General
  rule: if {a} is {t1} and {b} is {t1} then {y} is {t1}
  rule: if {a} is {t2} then {y} is {t2}
RuleBlock: {blocks[1]}
  conjunction: AlgebraicProduct
  activation: General
  rule: if {a} is {t1} and {b} is {t1} then {z} is {t1}
""")
    return path


# ---- what the generated code may contain -----------------------------------------------------

SAFE_BUILTINS = {"float", "dict", "zip", "len", "ValueError", "TypeError", "range", "abs", "min",
                 "max", "tuple", "list", "int", "bool", "any", "all", "enumerate", "isinstance",
                 "np"}


def _constant(node: ast.expr) -> None:
    """A literal, or ``float('inf')``: nothing a top-level assignment may compute."""
    if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
            and node.func.id == "float" and len(node.args) == 1 and not node.keywords
            and isinstance(node.args[0], ast.Constant)):
        return
    ast.literal_eval(node)


def assert_python_only_computes(source: str) -> None:
    tree = ast.parse(source)
    for i, node in enumerate(tree.body):
        if i == 0 and isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant):
            continue                                              # the docstring
        if isinstance(node, ast.Import):
            assert [a.name for a in node.names] in (["math"], ["numpy"]), ast.dump(node)
        elif isinstance(node, ast.Assign):
            assert all(isinstance(t, ast.Name) for t in node.targets)
            _constant(node.value)
        else:
            assert isinstance(node, ast.FunctionDef) and not node.decorator_list, ast.dump(node)
    bound = set(SAFE_BUILTINS)
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef):
            bound.add(node.name)
        elif isinstance(node, ast.arg):
            bound.add(node.arg)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            bound.add(node.id)
    for node in ast.walk(tree):
        assert not isinstance(node, (ast.Global, ast.Nonlocal, ast.ImportFrom)), ast.dump(node)
        assert not (isinstance(node, ast.Import) and node not in tree.body)
        if isinstance(node, ast.Name):
            assert node.id in bound, f"unbound name {node.id!r}"
        if isinstance(node, ast.Attribute):
            assert not node.attr.startswith("__"), node.attr


def assert_scalar_only_computes(fn) -> None:
    tree = ast.parse(fn.source)
    (node,) = tree.body
    assert isinstance(node, ast.FunctionDef) and node.name == "network"
    for sub in ast.walk(node):
        assert not isinstance(sub, (ast.Attribute, ast.Import, ast.ImportFrom, ast.Global,
                                    ast.Lambda))
        if isinstance(sub, ast.Call):
            assert isinstance(sub.func, ast.Name) and sub.func.id == "sqrt"
        if isinstance(sub, ast.Constant):
            assert sub.value is None or isinstance(sub.value, float | int)
        if isinstance(sub, ast.Name):
            assert re.fullmatch(r"[xvds]\d+|[rfabxy]|lo|hi|den|sqrt|nan|inf", sub.id), sub.id


def assert_c_only_computes(texts: dict[str, str], d: Path) -> None:
    """Each ``prefix: C text`` keeps to math.h and #define, compiles, defines only
    ``prefix_eval`` and calls nothing outside libm (one compiler run for all of them)."""
    for text in texts.values():
        for line in text.splitlines():
            if line.lstrip().startswith("#"):
                assert line == "#include <math.h>" or re.fullmatch(
                    r"#define [A-Za-z0-9_]+ .*", line), line
    for prefix, text in texts.items():
        (d / f"{prefix}.c").write_text(text)
    built = subprocess.run([CC, "-std=c99", "-pedantic-errors", "-Wall", "-Werror", "-c",
                            *(f"{p}.c" for p in texts)], cwd=d, capture_output=True, text=True)
    assert built.returncode == 0, built.stderr
    for prefix in texts:
        obj = str(d / f"{prefix}.o")
        undefined = subprocess.run([NM, "-u", obj], capture_output=True, text=True,
                                   check=True).stdout.split()
        assert set(undefined[1::2]) <= LIBM, undefined
        defined = subprocess.run([NM, "-g", "--defined-only", obj], capture_output=True,
                                 text=True, check=True).stdout.split()
        assert defined[2::3] == [f"{prefix}_eval"], defined


def check_exports(path: Path, d: Path, with_c: bool) -> None:
    """Every behavior of ``path``: Python and C exports only compute and agree."""
    from mitos_cli.engine import evaluation as engine
    from mitos_cli.engine.scalar import scalar_function

    behaviors = [b.name for b in load_rulebase(path).rulebase.behaviors] or [None]
    c_texts = {}
    for i, behavior in enumerate(behaviors):
        c = load_rulebase(path, behavior).compiled
        text = to_python(c, path.name)
        assert_python_only_computes(text)
        module_path = d / f"gen{next(COUNTER)}.py"
        module_path.write_text(text)
        spec = importlib.util.spec_from_file_location(module_path.stem, module_path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        assert tuple(c.inputs) == module.INPUTS and tuple(c.outputs) == module.OUTPUTS
        X = np.linspace(c.universe[:, 0], c.universe[:, 1], 7)
        np.testing.assert_allclose(module.evaluate(X), engine.evaluate(c, X).outputs,
                                   atol=1e-9, equal_nan=True)
        fn = scalar_function(c)
        if fn is not None:
            assert_scalar_only_computes(fn)
        c_texts[f"gen{i}"] = to_c(c, f"gen{i}", path.name)
    if with_c:
        assert_c_only_computes(c_texts, path.parent)
    assert not (d / "ran").exists()


needs_cc = pytest.mark.skipif(CC is None or NM is None, reason="no C compiler or nm on PATH")
SETTINGS = settings(max_examples=5, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.function_scoped_fixture,
                                           HealthCheck.too_slow, HealthCheck.filter_too_much])


@pytest.fixture()
def inside(tmp_path, monkeypatch):
    """Run where ``touch ran`` would leave its mark."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


def fresh(root: Path) -> Path:
    d = root / f"case{next(COUNTER)}"
    d.mkdir()
    return d


names_of = st.lists(rules_name.filter(no_keyword), min_size=6, max_size=6)
dotted_of = st.lists(dotted_name.filter(no_keyword), min_size=6, max_size=6)
fis_text = hostile.map(lambda s: "n" + re.sub(r"['\r\n\u2028\u2029\x0b\x0c\x1c-\x1e\x85]", "", s))
fll_block = hostile.map(lambda s: "b" + re.sub(r"[#\r\n\u2028\u2029\x0b\x0c\x1c-\x1e\x85]", "",
                                               s).strip())


def unique_vars(names: list[str]) -> bool:
    a, b, y, t1, t2, _ = names
    return len({a, b, y}) == 3 and t1 != t2


@SETTINGS
@given(fname=hostile, names=names_of.filter(unique_vars))
def test_rules_and_yaml(inside, fname, names):
    check_exports(write_rules(fresh(inside), fname, names), inside, with_c=CC is not None)


@SETTINGS
@given(fname=hostile, names=dotted_of.filter(unique_vars))
def test_fcl(inside, fname, names):
    check_exports(write_fcl(fresh(inside), fname, names), inside, with_c=CC is not None)


@SETTINGS
@given(fname=hostile, names=st.lists(fis_text, min_size=6, max_size=6))
def test_fis(inside, fname, names):
    a, b, y, t1, t2, system = names
    a, b, y = distinct([a, b, y])
    t1, t2 = distinct([t1, t2])
    check_exports(write_fis(fresh(inside), fname, [a, b, y, t1, t2, system]), inside,
                  with_c=CC is not None)


@SETTINGS
@given(fname=hostile, names=dotted_of.filter(lambda n: len({n[0], n[1], n[2], n[5]}) == 4
                                             and n[3] != n[4]),
       blocks=st.lists(fll_block, min_size=2, max_size=2, unique=True))
def test_fll(inside, fname, names, blocks):
    check_exports(write_fll(fresh(inside), fname, names, tuple(blocks)), inside,
                  with_c=CC is not None)


def test_the_reported_file_name_runs_nothing(inside):
    """The reproduction: a rule file whose name closes the module docstring."""
    d = fresh(inside)
    path = write_rules(d, '', ["a", "b", "y", "lo", "hi", "main"])
    evil = d / 'x""";__import__("pathlib").Path("ran").touch();"""y.rules'
    path.rename(evil)
    check_exports(evil, inside, with_c=CC is not None)
    text = to_python(load_rulebase(evil).compiled, evil.name)
    exec(compile(text, "gen", "exec"), {})
    assert not (inside / "ran").exists()


@needs_cc
def test_macro_names_that_sanitise_alike_stay_distinct(inside):
    d = fresh(inside)
    path = write_fcl(d, "f", ["a.b", "a_b", "A_b", "lo", "lo.", "fb"])
    check_exports(path, inside, with_c=True)
    text = to_c(load_rulebase(path).compiled, "gen", path.name)
    assert "#define GEN_IN_A_B 0" in text and "#define GEN_IN_A_B_2 1" in text
    assert "#define GEN_OUT_A_B 0" in text
