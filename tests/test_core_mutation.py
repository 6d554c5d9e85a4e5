"""Mutated rule files and term sets either load or raise our own error with a position.

Hypothesis mutates the packaged rule base and its term set (tokens inserted, deleted, swapped;
truncation; binary junk) and asserts that loading and compiling them ends in one of two ways:
a rule base, or a :class:`MitosError` that says where (a span with path and line). Any other
exception, or a slow load (the deadline), fails the test.
"""

from __future__ import annotations

import re
from datetime import timedelta
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mitos_cli.engine.compile import compile_rulebase
from mitos_cli.engine.evaluation import evaluate
from mitos_cli.errors import MitosError
from mitos_cli.lang.resolve import load_rules_file

ROOT = Path(__file__).resolve().parents[1]
RULES = (ROOT / "rulebases" / "mitos.rules").read_text(encoding="utf-8").replace(
    '"mitos.terms.yaml"', '"t.terms.yaml"')
TERMS = (ROOT / "rulebases" / "mitos.terms.yaml").read_text(encoding="utf-8")
TOKEN = re.compile(r"\s+|[A-Za-z_][\w\-]*|-?\d+(?:\.\d+)?|.", re.S)
JUNK = ["(", ")", ":", ",", "\"", "'", "#", "=", "-", "[", "]", "{", "}", "is", "not", "and",
        "or", "if", "then", "with", "end", "behavior", "use", "when", "frozen", "terms",
        "operators", "very", "1e999", "nan", "-0", "0", "1.5", "\t", "\n", "  ", ": |", "- ",
        "&anchor", "*anchor", "!!python/object:os.system", "%YAML 1.1", "---", "\x00", "é"]


def mutations(text: str):
    tokens = TOKEN.findall(text)
    assert "".join(tokens) == text
    vocab = sorted(set(tokens) | set(JUNK))
    index = st.integers(0, len(tokens) - 1)
    insert = st.tuples(st.just("insert"), index, st.sampled_from(vocab))
    delete = st.tuples(st.just("delete"), index, st.just(""))
    swap = st.tuples(st.just("swap"), index, index.map(str))
    return st.lists(st.one_of(insert, delete, swap), min_size=1, max_size=4).map(
        lambda ops: _apply(list(tokens), ops))


def _apply(tokens: list[str], ops) -> bytes:
    for op, i, arg in ops:
        i = min(i, len(tokens) - 1)
        if op == "insert":
            tokens.insert(i, arg)
        elif op == "delete" and len(tokens) > 1:
            del tokens[i]
        elif op == "swap":
            j = min(int(arg), len(tokens) - 1)
            tokens[i], tokens[j] = tokens[j], tokens[i]
    return "".join(tokens).encode("utf-8")


def damaged(text: str):
    data = text.encode("utf-8")
    truncated = st.integers(0, len(data)).map(lambda n: data[:n])
    junk = st.tuples(st.integers(0, len(data)), st.binary(min_size=1, max_size=40)).map(
        lambda t: data[:t[0]] + t[1] + data[t[0]:])
    only_junk = st.binary(max_size=200)
    return st.one_of(mutations(text), truncated, junk, only_junk)


def load_or_fail_well(tmp: Path, rules: bytes, terms: bytes) -> None:
    (tmp / "t.rules").write_bytes(rules)
    (tmp / "t.terms.yaml").write_bytes(terms)
    try:
        rb = load_rules_file(tmp / "t.rules")
        for b in rb.behaviors:
            compiled = compile_rulebase(rb, b.name)
            X = np.tile(compiled.universe.mean(axis=1), (3, 1))
            evaluate(compiled, X, strict=False)
    except MitosError as exc:
        assert exc.span is not None, f"no position: {exc.render()}"
        assert exc.span.path in (str(tmp / "t.rules"), str(tmp / "t.terms.yaml")), exc.span
        assert exc.span.line >= 1 and exc.span.column >= 1
        text = exc.render()
        assert "$END" not in text and "Token(" not in text


MUTATION_SETTINGS = settings(max_examples=150, deadline=timedelta(seconds=2),
                             suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                    HealthCheck.too_slow])


@given(rules=damaged(RULES))
@MUTATION_SETTINGS
def test_mutated_rule_files(tmp_path, rules):
    load_or_fail_well(tmp_path, rules, TERMS.encode("utf-8"))


@given(terms=damaged(TERMS))
@MUTATION_SETTINGS
def test_mutated_term_sets(tmp_path, terms):
    load_or_fail_well(tmp_path, RULES.encode("utf-8"), terms)
