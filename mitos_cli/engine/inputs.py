"""What the engine takes as numbers: one input's values, or a batch, as a float array, and
in words what is refused. NumPy reads many things as floats that are not the numbers a user
meant (``None`` as NaN, ``True`` as 1, a date as a count of days, masked entries as what lies
under the mask); the rule base would evaluate them without a word."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping

import numpy as np

from ..errors import InputError


def floats(value: object, what: str, many: bool = False) -> np.ndarray:
    """``value`` as a float array, or an :class:`InputError` about ``what`` (one input, or
    ``many`` inputs) saying why it is not numbers. Besides what ``float()`` refuses, what
    NumPy would turn into numbers silently or into its own exceptions: ``None`` (read as NaN),
    the masked entries of a masked array (read as what lies under the mask), complex numbers
    (their imaginary part dropped), numbers past a float's range (an ``OverflowError``; a
    ``Decimal`` or a long double read as infinite), bools (read as 1 and 0), dates and
    durations (read as counts of their unit), bytes (a ``bytearray`` read as its byte values),
    structured and record arrays (a single number field read as that field) and text outside
    the one number grammar of every file here (``5_0`` read as 50)."""
    if type(value) is np.ndarray and value.dtype == float:        # the common case
        return value
    has, is_ = ("have", "are") if many else ("has", "is")
    if value is None:
        raise InputError(f"{what} {is_} None, not {'numbers' if many else 'a number'}",
                         hint=f"give {'them numbers' if many else 'it a number'}")
    if isinstance(value, np.ma.MaskedArray):
        if np.ma.count_masked(value):
            raise InputError(f"{what} {has} {np.ma.count_masked(value)} masked values",
                             hint="fill them (`.filled(...)`) or leave those samples out")
        value = value.data
    try:
        if _is_bytes(value):
            raise _NotNumbers("S")
        raw = np.asarray(value)
        if raw.dtype.kind == "c":
            raise InputError(f"{what} {is_} complex, not real numbers: `{_brief(value)}`")
        if raw.dtype == object and any(v is None for v in raw.flat):
            raise InputError(f"{what} {has} None among {'their' if many else 'its'} values",
                             hint="give every sample a number")
        if raw.dtype.kind == "V":
            raise _NotNumbers("V", raw.dtype)
        if raw.dtype.kind in _KINDS:
            raise _NotNumbers(raw.dtype.kind)
        if raw.dtype.kind in "iuf" and isinstance(value, (list, tuple)) and _holds_bool(value):
            raise _NotNumbers("b")                 # [True, 2.5] is [1.0, 2.5] to NumPy
        if raw.dtype.kind == "U" and not isinstance(value, np.ndarray):
            raw = np.asarray(value, dtype=object)  # as written: "U" drops trailing NULs ("78\0")
        if raw.dtype.kind == "U" or raw.dtype == object:
            return _one_by_one(raw)
        with np.errstate(over="raise"):            # a long double past 1.8e308
            return np.asarray(raw, dtype=float)
    except _NotNumbers as exc:
        if exc.kind == "V":
            raise _structured(what, value, exc.dtype, many) from None
        one, several, hint = _KINDS[exc.kind]
        raise InputError(f"{what} must be {'numbers' if many else 'a number'}, not "
                         f"{several if many else one}: `{_brief(value)}`", hint=hint) from None
    except (OverflowError, FloatingPointError):
        raise InputError(f"{what} {has} a number too large for a float: `{_brief(value)}`",
                         expected="numbers of magnitude at most 1.8e308") from None
    except (TypeError, ValueError):
        raise InputError(f"{what} must be {'numbers' if many else 'a number'}, "
                         f"not `{_brief(value)}`",
                         expected="a decimal number such as 78, -4.5 or 1e3") from None


class _NotNumbers(Exception):
    """Values NumPy reads as numbers though they are not the numbers meant: a key of
    :data:`_KINDS`."""

    def __init__(self, kind: str, dtype: np.dtype | None = None) -> None:
        super().__init__(kind)
        self.kind = kind
        self.dtype = dtype            # of a structured value ("V"), for its fields' names


def named_columns(table: object) -> dict[str, object] | None:
    """The columns of a table that names them, by name: a mapping or anything with ``keys()``
    (a pandas DataFrame or Series), a polars DataFrame (``columns``), a pyarrow Table
    (``column_names``), a structured NumPy array (its fields); ``None`` for anything else,
    and for a table other than a mapping whose names are not all text (a DataFrame of an
    unnamed array, numbered 0, 1, ...: read by position). Read by position, a table whose
    columns come in another order than the rule base's inputs gave the outputs of other
    inputs, without a word."""
    if type(table) in (list, tuple) or table is None:                     # the usual calls
        return None
    if isinstance(table, Mapping):      # whatever its keys: each is checked as a name
        return dict(table)
    if isinstance(table, np.ndarray):
        names = table.dtype.names
        return None if not names else {name: table[name] for name in names}
    keys = getattr(table, "keys", None)
    if callable(keys):
        names = keys()
    else:
        names = getattr(table, "column_names", None)
        if names is None:
            names = getattr(table, "columns", None)
    if names is None or isinstance(names, (str, bytes)):
        return None
    try:
        names = list(names)
    except TypeError:
        return None
    if not names or not all(isinstance(name, str) for name in names):
        return None
    twice = sorted(name for name, n in Counter(names).items() if n > 1)
    if twice:           # a DataFrame's df["road"] of two columns met "not of shape (1, 2)"
        raise InputError("the table names " + ", ".join(f"`{n}`" for n in twice[:8])
                         + " more than once", hint="give each input one column")
    # a DataFrame's column as an array: a Series' repr ("0    a") put its index in messages
    return {name: np.asarray(table[name]) for name in names}  # type: ignore[index]


def _structured(what: str, value: object, dtype: np.dtype | None, many: bool) -> InputError:
    """The error for a structured array or record (NumPy's kind ``V``): NumPy casts one of a
    single number field to that number without a word, so which field was meant is asked
    for, never guessed; a void without fields is raw bytes."""
    is_, numbers = ("are", "numbers") if many else ("is", "a number")
    names = dtype.names if dtype is not None else None
    if not names:
        return InputError(f"{what} {is_} raw bytes (a NumPy void), not {numbers}: "
                          f"`{_brief(value)}`", hint="decode them into numbers first")
    fields = ", ".join(f"`{n}`" for n in names[:12]) + (", ..." if len(names) > 12 else "")
    hint = ("give one float column per input: "
            "`numpy.lib.recfunctions.structured_to_unstructured(array)` has one column per "
            "field, in the fields' order" if many else
            f"give the field's values (`array[{names[0]!r}]`)")
    return InputError(f"{what} {is_} structured (field{'s' if len(names) > 1 else ''} "
                      f"{fields}), not {numbers}: `{_brief(value)}`",
                      expected="a float array [n, k]" if many else
                      "a number or a 1-D array of numbers", hint=hint)


#: What NumPy casts to float without complaint though it is no measurement, by array kind:
#: (one, several, hint).
_KINDS = {
    "b": ("a bool", "bools", "give numbers: True and False would be read as 1 and 0"),
    "M": ("a date", "dates", "give the number the input measures, not a date"),
    "m": ("a duration", "durations",
          "give the number in the input's unit (seconds: `d / np.timedelta64(1, 's')`)"),
    "S": ("bytes", "bytes",
          "decode text first (`.decode()`): NumPy reads a bytearray as its byte values"),
}


def _is_bytes(value: object) -> bool:
    """``bytes``, a ``bytearray`` or a view of one: NumPy reads the last two as byte values
    (``bytearray(b"5")`` is 53), where ``float()`` reads them as text (5)."""
    if isinstance(value, memoryview):
        value = value.obj
    return isinstance(value, (bytes, bytearray))


def holds_bool(value: object) -> bool:
    """Whether ``value`` is a bool, a bool array, or a list, tuple or object array holding
    one: what NumPy reads as 1 or 0 where a number was meant (a robot's command, say)."""
    if isinstance(value, (bool, np.bool_)):
        return True
    if isinstance(value, np.ndarray):
        return value.dtype == bool or (value.dtype == object and any(
            isinstance(v, (bool, np.bool_)) for v in value.flat))
    return isinstance(value, (list, tuple)) and _holds_bool(value)


def holds_text(value: object) -> bool:
    """Whether ``value`` is text, or a list, tuple or array holding some (``["90", 20]``):
    what NumPy reads as numbers as Python's ``float()`` does (``"5_0"`` as 50) where numbers
    were given (a robot's command, say)."""
    if isinstance(value, (list, tuple)):
        return any(holds_text(v) for v in value)
    if isinstance(value, np.ndarray):
        return value.dtype.kind in "US" or (value.dtype == object
                                            and any(holds_text(v) for v in value.flat))
    return isinstance(value, (str, bytes, np.str_, np.bytes_))


def _holds_bool(values: list | tuple) -> bool:
    """Whether a list or tuple, or one nested in it, holds a bool (NumPy reads a bool among
    numbers as 1 or 0, and says nothing). By the set of types: 20 ms for a million floats."""
    types = set(map(type, values))
    if bool in types or np.bool_ in types:
        return True
    return bool(types & {list, tuple}) and any(_holds_bool(v) for v in values
                                                if type(v) in (list, tuple))


def _one_by_one(raw: np.ndarray) -> np.ndarray:
    """Text or Python objects ``raw`` as floats, each value alone: text by the number grammar
    of the files (:func:`~mitos_cli.numbers.parse_value`), anything else by ``float()``,
    with the kinds of :data:`_KINDS` refused, and a number ``float()`` makes
    infinite though it is finite (``Decimal("1e400")``, ``"1e400"``) an ``OverflowError``."""
    from ..numbers import parse_value

    out = np.empty(raw.shape)
    flat = out.reshape(-1)
    for i, v in enumerate(raw.flat):
        if isinstance(v, str):
            flat[i] = parse_value(v)
            continue
        if isinstance(v, (bool, np.bool_)):
            raise _NotNumbers("b")
        if isinstance(v, (np.datetime64, np.timedelta64)):
            raise _NotNumbers("M" if isinstance(v, np.datetime64) else "m")
        if _is_bytes(v):
            raise _NotNumbers("S")
        if isinstance(v, np.void):                 # a record among objects
            raise _NotNumbers("V", v.dtype)
        x = float(v)
        if x in (np.inf, -np.inf) and not v == x:
            raise OverflowError(v)
        flat[i] = x
    return out


def _brief(value: object) -> str:
    text = str(value)
    return text if len(text) <= 60 else f"{text[:40]}...{text[-15:]} ({len(text):,} characters)"
