"""``mitos eval --network`` (network.describe_network), ``mitos operators`` and the operators
shown by ``mitos eval``."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mitos_cli.api import load_rulebase, read_rulebase
from mitos_cli.cli.app import main
from mitos_cli.engine.describe import describe_network
from mitos_cli.fuzzy import norms
from mitos_cli.fuzzy.hedges import HEDGES


def run(capsys, *argv):
    with pytest.raises(SystemExit) as exit_:
        main(list(argv))
    out = capsys.readouterr()
    return exit_.value.code, out.out, out.err


def rules_file(tmp_path, text):
    (tmp_path / "t.terms.yaml").write_text(Path(read_rulebase().termsets[0].path).read_text())
    path = tmp_path / "t.rules"
    path.write_text('terms "t.terms.yaml"\n' + text)
    return path


def test_paper_network_layers():
    text = describe_network(load_rulebase().compiled)
    assert text.splitlines()[0] == ("behavior avoid_obstacle: 3 inputs, 27 rules, 2 outputs, "
                                    "36 neurons")
    assert "layer 1   9  membership neurons" in text
    assert "MEDIUM triangle(peak 70, width 30)" in text
    assert "NARROW left_shoulder(a 40, b 70)" in text       # parameters named as in the YAML
    assert "triangle_" not in text
    assert "layer 2  27  AND neurons, T-norm min (min(a, b)), 3 inputs" in text
    assert "layer 3   2  output neurons, weighted average" in text
    assert "steering: 27 rules, default 90" in text


def test_network_with_hedges_not_or_weights_and_mamdani(tmp_path):
    path = rules_file(tmp_path, """\
operators: and = product, or = einstein_sum, inference = mamdani, defuzzify = lom
if road is very WIDE and not size is LARGE_SZ then speed is MEDIUM with 0.5
if road is somewhat NARROW or position is LEFT then speed is SLOW
""")
    text = describe_network(load_rulebase(path).compiled)
    assert "hedge neurons, activation very (very x^2; eqs. 10-11), 1 input" in text
    assert "NOT neurons, inhibitory input 1 - x (eqs. 8-9)" in text
    assert "AND neurons, T-norm product (a * b), 2 inputs" in text
    assert "OR neurons, S-norm einstein_sum" in text
    assert "1 weighted (`with w` multiplies the DOF)" in text
    assert ("output neurons, Mamdani: implication min, aggregation max, defuzzify lom on "
            "101 samples") in text
    assert "speed: 2 rules -> 2 consequent sets (MEDIUM, SLOW)" in text


def test_eval_network_cli(capsys):
    with pytest.raises(SystemExit) as e:       # typer exits 0 at the end of a command
        main(["eval", "--network"])
    out = capsys.readouterr().out
    assert e.value.code in (0, None)
    assert out == describe_network(load_rulebase().compiled) + "\n"


def test_eval_shows_operators_in_force(capsys, tmp_path):
    path = rules_file(tmp_path, "operators: and = product, inference = mamdani, "
                                "resolution = 501\n"
                                "if road is WIDE then speed is MEDIUM\n")
    code, out, _ = run(capsys, "eval", str(path), "road=90")
    assert code in (0, None)
    assert ("and = product, or = max, inference = mamdani, implication = min, aggregation = "
            "max, defuzzify = centroid, resolution = 501") in out.splitlines()[0]
    code, out, _ = run(capsys, "eval", str(path), "road=90", "--json")
    assert json.loads(out)["operators"].startswith("and = product, or = max, inference = mamdani")


def test_operators_command_lists_everything(capsys):
    code, out, _ = run(capsys, "operators")
    assert code in (0, None)
    for n in [*norms.TNORMS.values(), *norms.SNORMS.values()]:
        assert f"{n.name}  " in out and n.formula in out
        for alias in n.aliases:
            assert alias in out
    for word in ("weighted_average", "weighted_sum", "mamdani", "centroid", "bisector", "mom",
                 "som", "lom", *HEDGES):
        assert word in out
    assert "min(a, b)   [alias minimum; dual max; default]" in out


def test_operators_command_json(capsys):
    code, out, _ = run(capsys, "operators", "--json")
    data = json.loads(out)
    assert [e["name"] for e in data["and"]] == list(norms.TNORMS)
    assert [e["name"] for e in data["or / aggregation"]] == list(norms.SNORMS)
    # the unbounded sum: an aggregation only, listed apart from the S-norms
    assert [(e["name"], e["aliases"]) for e in data["aggregation only"]] == [
        ("sum", ["unbounded_sum"])]
    assert {e["name"] for e in data["inference"] if e["default"]} == {"weighted_average"}
    # every T-norm is accepted as a Mamdani implication, so every one is listed as one
    from mitos_cli.lang.operators import IMPLICATIONS

    assert [e["name"] for e in data["implication"]] == list(IMPLICATIONS) == list(norms.TNORMS)


def test_operators_command_lists_every_sampling(capsys):
    """`sampling = left` (jFuzzyLogic's grid) is taken by a rule file but was missing from
    `mitos operators`, which docs/language.md says lists what a rule file can select."""
    from mitos_cli.lang.operators import SAMPLINGS

    code, out, _ = run(capsys, "operators", "--json")
    assert [e["name"] for e in json.loads(out)["sampling"]] == list(SAMPLINGS)
    code, out, _ = run(capsys, "operators")
    assert "  left       the left ends of `resolution` equal cells (jFuzzyLogic's)" in out


def test_operators_command_lists_the_accumulations(capsys):
    code, out, _ = run(capsys, "operators", "--json")
    data = json.loads(out)["accumulation"]
    assert [e["name"] for e in data] == ["sum", *norms.SNORMS]
    assert [e["name"] for e in data if e["default"]] == ["sum"]
    code, out, _ = run(capsys, "operators")
    assert "operators: accumulation = NAME" in out
    assert "  max                the rules of one value weigh max of their DOFs" in out


def test_unknown_operator_in_a_rule_file(capsys, tmp_path):
    path = rules_file(tmp_path, "operators: aggregation = probabilistic_summ\n"
                                "if road is WIDE then speed is MEDIUM\n")
    code, _, err = run(capsys, "eval", str(path), "road=90")
    assert code == 1
    assert "unknown aggregation `probabilistic_summ`" in err
    assert "did you mean `probabilistic_sum`?" in err
