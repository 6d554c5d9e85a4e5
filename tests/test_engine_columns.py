"""Arrays by name (``load_rulebase().evaluate(**columns)``) go through the engine as columns:
the same bits as the rows of ``evaluate`` and as one sample alone, the same messages."""

from __future__ import annotations

import warnings
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from mitos_cli import load_rulebase
from mitos_cli.engine.evaluation import BLOCK, evaluate, evaluate_columns, evaluate_one
from mitos_cli.errors import InputError, NoRuleFiredError

ROOT = Path(__file__).resolve().parents[1]


def test_columns_give_the_bits_of_the_rows_and_of_one_sample():
    rb = load_rulebase()
    c = rb.compiled
    rng = np.random.default_rng(5)
    n = BLOCK + 37                                      # more than one block
    X = rng.uniform(c.universe[:, 0] - 10, c.universe[:, 1] + 10, size=(n, 3))  # some clamped
    rows = evaluate(c, X, detail=False).outputs
    out = rb.evaluate(**{name: X[:, j] for j, name in enumerate(c.inputs)})
    for j, name in enumerate(c.outputs):
        assert np.array_equal(out[name], rows[:, j])
    assert np.array_equal(evaluate_columns(c, X.T), rows.T)
    for i in (0, 1, n - 1):
        assert evaluate_one(c, X[i].tolist()) == tuple(rows[i].tolist())


def test_a_scalar_broadcasts_and_a_sample_no_rule_fires_for_is_explained():
    rb = load_rulebase()
    out = rb.evaluate(road=np.array([78.0, 60.0]), size=45.0, position=4.0)
    assert out["steering"].shape == (2,)
    assert out["steering"][0] == rb.evaluate(road=78.0, size=45.0, position=4.0)["steering"]
    with pytest.raises(InputError, match="sample 2"):
        rb.evaluate(road=np.array([78.0, np.nan]), size=45.0, position=4.0)
    with pytest.raises(InputError, match="did you mean"):
        rb.evaluate(raod=np.array([78.0]), size=45.0, position=4.0)


def test_no_rule_fired_names_the_sample_as_the_rows_path_does(tmp_path):
    terms = (ROOT / "rulebases" / "mitos.terms.yaml").read_text(encoding="utf-8")
    (tmp_path / "t.terms.yaml").write_text(terms.replace("    default: 90\n", ""),
                                           encoding="utf-8")
    rules = tmp_path / "t.rules"
    rules.write_text('terms "t.terms.yaml"\n'
                     "r1: if road is WIDE then steering is RS and speed is SLOW",
                     encoding="utf-8")
    rb = load_rulebase(rules)
    with pytest.raises(NoRuleFiredError) as cols:
        rb.evaluate(road=np.array([150.0, 20.0]))
    with pytest.raises(NoRuleFiredError) as rows:
        evaluate(rb.compiled, np.array([[150.0], [20.0]]), detail=False)
    assert cols.value.message == rows.value.message == \
        "no rule sets `steering` for road=20 (1 of 2 samples)"


@pytest.mark.parametrize(("value", "message"), [
    (10**400, r"input `road` has a number too large for a float: `1000.*\(401 characters\)`"),
    ([78, 10**400], "input `road` has a number too large for a float"),
    (None, "input `road` is None, not a number"),
    ([78.0, None], "input `road` has None among its values"),
    (np.ma.masked_array([78.0, 60.0], mask=[False, True]), "input `road` has 1 masked values"),
    (np.array([78 + 1j]), "input `road` is complex, not real numbers"),
    ("wide", "input `road` must be a number, not `wide`"),
])
def test_what_numpy_would_misread_or_raise_about_is_refused_in_words(value, message):
    rb = load_rulebase()
    for call in (rb.evaluate, rb.trace):
        with pytest.raises(InputError, match=message):
            call(road=value, size=45, position=4)
    assert rb.evaluate(road=np.ma.masked_array([78.0]), size=45, position=4)["steering"][0] \
        == rb.evaluate(road=78.0, size=45, position=4)["steering"]


@pytest.mark.parametrize(("X", "message"), [
    ([["a", 45, 4]], r"the inputs must be numbers, not `\[\['a', 45, 4\]\]`"),
    ([[10**400, 45, 4]], "the inputs have a number too large for a float"),
    (None, "the inputs are None, not numbers"),
])
def test_a_batch_that_is_not_numbers_is_refused_in_words(X, message):
    with pytest.raises(InputError, match=message):
        load_rulebase().run(X)


_WIDE = pytest.mark.skipif(not np.isfinite(np.longdouble("1e400")),
                           reason="a long double here is a double")


@pytest.mark.parametrize(("value", "message"), [
    # the fuzz pass of 2026-12-03: each was evaluated at a number nobody gave
    (True, "input `road` must be a number, not a bool: `True`"),                   # 1
    (np.array([True, False]), "input `road` must be a number, not a bool"),
    ([78, True], "input `road` must be a number, not a bool"),                       # [78, 1]
    (np.datetime64("2020-01-01"), "input `road` must be a number, not a date"),     # 18,262 days
    (np.array([5], dtype="timedelta64[s]"), "input `road` must be a number, not a duration"),
    (bytearray(b"5"), r"input `road` must be a number, not bytes: `bytearray\(b'5'\)`"),  # 53
    (b"78", "input `road` must be a number, not bytes"),
    ("5_0", "input `road` must be a number, not `5_0`"),                              # 50
    ("78\x00", r"input `road` must be a number, not `78\\x00`"),                      # 78
    (["78\x00", "5"], r"input `road` must be a number, not `\['78\\x00', '5'\]`"),       # 78
    ("\uff15\uff10", "input `road` must be a number, not `\uff15\uff10`"),            # 50
    (np.array(["78", "7_8"]), r"input `road` must be a number, not `\['78' '7_8'\]`"),
    ("1e400", "input `road` has a number too large for a float: `1e400`"),         # inf
    (np.array(["78", "-1e999"]), "input `road` has a number too large for a float"),
    (Decimal("1e400"), r"input `road` has a number too large for a float: `1E\+400`"),  # inf
    ([Decimal(78), Decimal("-1e999")], "input `road` has a number too large for a float"),
    pytest.param(np.longdouble("1e400"), "input `road` has a number too large for a float",
                 marks=_WIDE),                                                  # a warning
    pytest.param(np.array([np.longdouble("1e400"), 78]), "input `road` has a number too large",
                 marks=_WIDE),
])
def test_what_numpy_or_float_would_read_as_another_number_is_refused(value, message):
    rb = load_rulebase()
    with warnings.catch_warnings():
        warnings.simplefilter("error")                # no "overflow encountered in cast"
        for call in (rb.evaluate, rb.trace):
            with pytest.raises(InputError, match=message):
                call(road=value, size=45, position=4)
        with pytest.raises(InputError, match=_as_a_batch(message)):
            rb.run([[value, 45, 4]] if np.ndim(value) == 0 and not isinstance(value, str)
                   else value)


def _as_a_batch(message: str) -> str:
    """A message about input `road` as the batch's (``run``), up to the value quoted."""
    head = message.split(":")[0].replace("input `road`", "the inputs").replace(" has ", " have ")
    for one, many in (("a number,", "numbers,"), ("a bool", "bools"), ("a date", "dates"),
                      ("a duration", "durations")):
        head = head.replace(one, many)
    return head


@pytest.mark.parametrize("value", [
    " 78 ", "78", "7.8e1", Decimal("78"), Fraction(156, 2), np.array(78), np.float16(78),
    np.array([78], dtype=np.longdouble), np.array([78], dtype=np.int8), [np.array(78.0)],
    np.array([Decimal("78")], dtype=object), "inf", Decimal("Infinity"),
])
def test_numbers_in_other_forms_are_the_numbers_they_say(value):
    rb = load_rulebase()
    expected = rb.evaluate(road=float(np.asarray(value, dtype=object).reshape(-1)[0]),
                           size=45.0, position=4.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = rb.evaluate(road=value, size=45, position=4)
        assert {k: float(np.asarray(v).reshape(-1)[0]) for k, v in out.items()} == expected
        assert rb.trace(road=value, size=45, position=4).outputs == \
            rb.trace(**{"road": float(np.asarray(value, dtype=object).reshape(-1)[0]),
                        "size": 45.0, "position": 4.0}).outputs


_ONE_FIELD = np.array([(78.0,), (120.0,)], dtype=[("road", "f8")])


@pytest.mark.parametrize(("value", "message"), [
    # NumPy casts a structure of one number field to that number without a word
    (_ONE_FIELD, r"input `road` is structured \(field `road`\), not a number"),
    (np.rec.array(_ONE_FIELD), r"input `road` is structured \(field `road`\)"),
    (_ONE_FIELD[0], r"input `road` is structured \(field `road`\), not a number: `\(78\.0?,\)`"),
    # (a record prints `(78.,)` on NumPy 1, `(78.0,)` on NumPy 2)
    (np.rec.array(_ONE_FIELD)[0], r"input `road` is structured \(field `road`\)"),
    ([_ONE_FIELD[0], _ONE_FIELD[1]], r"input `road` is structured \(field `road`\)"),
    (np.array([_ONE_FIELD[0]], dtype=object), r"input `road` is structured \(field `road`\)"),
    (np.zeros(2, dtype=[("a", [("x", "f8")])]), r"input `road` is structured \(field `a`\)"),
    (np.zeros(2, dtype=[("x", "f8", (1,))]), r"input `road` is structured \(field `x`\)"),
    (np.array([(78.0, 1.0)], dtype=[("x", "f8"), ("y", "f8")]),
     r"input `road` is structured \(fields `x`, `y`\)"),
    (np.zeros(1, dtype="V8"), r"input `road` is raw bytes \(a NumPy void\), not a number"),
    (np.array([{}, {}], dtype=object), r"input `road` must be a number, not `\[\{\} \{\}\]`"),
])
def test_a_structured_or_record_input_is_refused_not_read_as_its_field(value, message):
    """A structured array of one float field was evaluated as that field (docs/reliability.md,
    "Not done yet" of 2026-12-03); the field is asked for, never guessed."""
    rb = load_rulebase()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for call in (rb.evaluate, rb.trace):
            with pytest.raises(InputError, match=message) as info:
                call(road=value, size=45, position=4)
        if "structured" in message:
            assert info.value.hint is not None and "array[" in info.value.hint


class Frame:
    """What MITOS sees of a pandas DataFrame (``keys()`` and its columns by name; as an
    array, its values in its own column order), a polars DataFrame (``columns``) or a
    pyarrow Table (``column_names``)."""

    def __init__(self, names: list, rows: list, by: str = "keys") -> None:
        self.names = list(names)
        self.data = {n: np.array([r[j] for r in rows]) for j, n in enumerate(names)}
        self.rows = np.array(rows, dtype=float)
        if by != "keys":
            setattr(self, by, list(names))

    def keys(self):
        return self.names

    def __getitem__(self, name):
        return self.data[name]

    def __array__(self, dtype=None, copy=None):
        return self.rows

    def __len__(self):
        return len(self.rows)


class Polars(Frame):
    keys = None                 # type: ignore[assignment]


@pytest.mark.parametrize("by", ["keys", "columns", "column_names"])
def test_a_table_with_named_columns_is_read_by_name_not_by_position(by):
    """`rb.run(df)` of a pandas DataFrame whose columns came in another order than the rule
    base's inputs read them by position: the outputs of other inputs, without a word
    (size 45, road 78, position 4 gave 78.9 deg, not 65.4). A table that names its columns
    is read by name, as a dict is; one that does not (a DataFrame of an unnamed array,
    columns 0, 1, 2) by position."""
    rb = load_rulebase()
    want = rb.run(np.array([[78.0, 45.0, 4.0], [60.0, 20.0, -3.0]])).outputs
    kind = Frame if by != "columns" else Polars
    frame = kind(["size", "position", "road"], [[45.0, 4.0, 78.0], [20.0, -3.0, 60.0]], by=by)
    assert np.array_equal(rb.run(frame).outputs, want)
    assert np.array_equal(evaluate_columns(rb.compiled, frame), want.T)
    unnamed = kind([0, 1, 2], [[78.0, 45.0, 4.0], [60.0, 20.0, -3.0]], by=by)
    assert np.array_equal(rb.run(unnamed).outputs, want)
    with pytest.raises(InputError, match="unknown input `roads`") as info:
        rb.run(kind(["size", "position", "roads"], [[45.0, 4.0, 78.0]], by=by))
    assert "did you mean `road`" in str(info.value)


def test_a_table_naming_an_input_twice_is_refused_in_words():
    """A DataFrame with two `road` columns met "inputs must be numbers or 1-D arrays, not of
    shape (1, 2)" (its df["road"] is both); a column that is no numbers was shown with its
    index (a Series' repr: `0    a`)."""
    rb = load_rulebase()
    with pytest.raises(InputError, match="the table names `road` more than once"):
        rb.run(Frame(["size", "road", "position", "road"], [[45.0, 78.0, 4.0, 1.0]]))
    frame = Frame(["size", "road", "position"], [[45.0, 78.0, 4.0]])
    frame.data["size"] = np.array(["a"], dtype=object)
    with pytest.raises(InputError, match=r"input `size` must be a number, not `\['a'\]`"):
        rb.run(frame)


@pytest.mark.parametrize("call", ["run", "columns", "one"])
def test_a_mapping_is_read_by_name_whatever_its_keys(call):
    """A dict keyed 0, 1, 2 met a TypeError inside "did you mean" (`evaluate_one` of `{}` one
    in float()): a mapping's keys are names, each checked as one."""
    rb = load_rulebase()
    run = {"run": rb.run, "columns": lambda X: evaluate_columns(rb.compiled, X),
           "one": lambda X: evaluate_one(rb.compiled, X)}[call]
    with pytest.raises(InputError, match="inputs are named by text, not `0`"):
        run({0: 78.0, 1: 45.0, 2: 4.0})
    with pytest.raises(InputError, match="missing input `road`, `size`, `position`"):
        run({})


def test_one_sample_with_named_values_is_read_by_name():
    """A pandas Series (``keys()``, values by name) of one sample, in its own order."""
    rb = load_rulebase()

    class Series:               # iterates its values, in its own order, as pandas' does
        def __init__(self, **values):
            self.values = values

        def keys(self):
            return list(self.values)

        def __getitem__(self, name):
            return self.values[name]

        def __iter__(self):
            return iter(self.values.values())

        def __len__(self):
            return len(self.values)

    one = Series(position=4.0, road=78.0, size=45.0)
    assert evaluate_one(rb.compiled, one) == evaluate_one(rb.compiled, [78.0, 45.0, 4.0])


def test_a_structured_batch_is_read_by_its_fields():
    """A structured array was refused, with the way to columns in its fields' order; its
    fields name the inputs, so it is read by them, in any order."""
    rb = load_rulebase()
    X = np.array([(45.0, 78.0, 4.0)], dtype=[("size", "f8"), ("road", "f8"), ("position", "f8")])
    want = rb.run(np.array([[78.0, 45.0, 4.0]])).outputs
    assert np.array_equal(rb.run(X).outputs, want)
    assert np.array_equal(evaluate_columns(rb.compiled, X), want.T)
    with pytest.raises(InputError, match="unknown input `x`"):
        rb.run(np.array([(1.0, 2.0, 3.0)], dtype=[("x", "f8"), ("road", "f8"), ("size", "f8")]))


@pytest.mark.parametrize(("column", "message"), [
    # evaluate_columns read each column with `np.asarray(x, dtype=float)`: these were numbers
    (np.array([True]), "input `road` must be a number, not a bool"),
    (np.array(["2020-01-01"], dtype="M8[D]"), "input `road` must be a number, not a date"),
    (np.array([5], dtype="m8[s]"), "input `road` must be a number, not a duration"),
    (np.array([b"78"]), "input `road` must be a number, not bytes"),
    (np.array([(78.0,)], dtype=[("x", "f8")]), r"input `road` is structured \(field `x`\)"),
    # ... and these NumPy's own TypeError, ValueError or ComplexWarning
    (np.array([78 + 0j]), "input `road` is complex, not real numbers"),
    (np.array([{}], dtype=object), "input `road` must be a number"),
    (np.array(["x"], dtype=object), "input `road` must be a number, not `\\['x'\\]`"),
    (np.zeros(1, dtype="V8"), "input `road` is raw bytes"),
])
def test_evaluate_columns_reads_its_columns_as_the_named_inputs_are(column, message):
    c = load_rulebase().compiled
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError, match=message):
            evaluate_columns(c, [column, np.array([45.0]), np.array([4.0])])
    for bad, said in ((None, "the input columns are None"),
                      (np.ones((2, 1)), "expected 3 input columns .*, not 2"),
                      (np.array(5.0), "expected 3 input columns .*, not one number")):
        with pytest.raises(InputError, match=said):
            evaluate_columns(c, bad)


def test_evaluate_one_reads_values_as_the_batch_does():
    """The scalar form took ``True`` as 1; ints and NumPy floats are the numbers they say."""
    c = load_rulebase().compiled
    with pytest.raises(InputError, match="the inputs must be numbers, not bools"):
        evaluate_one(c, [True, 45.0, 4.0])
    with pytest.raises(InputError, match=r"the inputs are structured \(field `x`\)"):
        evaluate_one(c, [np.array((78.0,), dtype=[("x", "f8")])[()], 45.0, 4.0])
    expected = evaluate_one(c, [78.0, 45.0, 4.0])
    assert evaluate_one(c, [78, 45, 4]) == evaluate_one(c, np.array([78.0, 45.0, 4.0])) \
        == expected


def test_inputs_by_name_in_a_mapping_are_read_by_name_not_as_their_keys():
    """A dict given to ``run``, ``evaluate_columns`` or ``evaluate_one`` was iterated as a
    sequence: its keys were read as the values (``input `road` must be a number, not
    `road```), or the dict as one value. It gives the inputs by name, in any order, with the
    named path's checks and "did you mean"."""
    rb = load_rulebase()
    c = rb.compiled
    road = np.array([78.0, 120.0, 500.0])
    rows = evaluate(c, np.column_stack([road, np.full(3, 45.0), np.full(3, 4.0)]),
                    detail=False).outputs
    by_name = {"position": 4, "road": road, "size": np.full(3, 45.0)}   # not in inputs order
    assert np.array_equal(rb.run(by_name).outputs, rows)
    assert np.array_equal(evaluate(c, by_name).dof, rb.run(np.column_stack(
        [road, np.full(3, 45.0), np.full(3, 4.0)])).dof)
    assert np.array_equal(evaluate_columns(c, by_name), rows.T)
    assert evaluate_one(c, {"size": 45, "position": 4, "road": 78}) == tuple(rows[0].tolist())
    for call in (rb.run, lambda m: evaluate_columns(c, m), lambda m: evaluate_one(c, m)):
        with pytest.raises(InputError, match="unknown input `raod`") as err:
            call({"raod": 78.0, "size": 45.0, "position": 4.0})
        assert "did you mean `road`?" in str(err.value)
        with pytest.raises(InputError, match="missing input `position`"):
            call({"road": 78.0, "size": 45.0})
        with pytest.raises(InputError, match="input `road` is not a number"):
            call({"road": float("nan"), "size": 45.0, "position": 4.0})
