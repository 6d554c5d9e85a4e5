"""The library API: ``load_rulebase(path)`` and a handle that evaluates and traces.

>>> rb = load_rulebase()                      # the packaged MITOS rule base
>>> rb.evaluate(road=78, size=45, position=4)  # doctest: +SKIP
{'steering': 65.41..., 'speed': 32.42...}
>>> rb.trace(road=78, size=45, position=4).render()  # doctest: +SKIP
"""

from __future__ import annotations

import functools
import os
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np

from .engine.compile import CompiledRuleBase, compile_rulebase
from .engine.evaluation import (
    Result,
    as_batch,
    as_columns,
    evaluate,
    evaluate_columns,
    evaluate_floats,
)
from .engine.trace import Trace, trace_of
from .errors import MitosError
from .lang.model import RuleBase
from .lang.terms import TermSet
from .resources import DEFAULT_RULEBASE, packaged_path

if TYPE_CHECKING:
    from collections.abc import Mapping

    from numpy.typing import ArrayLike

#: The types the one-sample path of :meth:`LoadedRuleBase.evaluate` takes as they are (not
#: ``bool``, whose type is its own: ``True`` is refused, not read as 1)
_NUMBERS = {float, int}


def default_rulebase_path() -> Path:
    """The packaged MITOS rule base (``rulebases/mitos.rules``)."""
    return packaged_path("rulebases", DEFAULT_RULEBASE)


def read_rulebase(path: str | Path | None = None) -> RuleBase:
    """Read a rule base: a ``.rules`` file, or a foreign format chosen by extension.

    A path that does not exist but names a packaged rule base (``rulebases/mitos.rules``,
    ``mitos``) reads the packaged one, so the README's commands work from any directory.
    """
    from .resources import resolve

    if path is None:
        path = default_rulebase_path()
    else:
        path = resolve("rulebases", _path_given(path), ".rules") or Path(path)
    suffix = path.suffix.lower()
    if suffix in (".yaml", ".yml") and path.is_file():   # a term set or a world named
        from .errors import RuleBaseError

        raise RuleBaseError(f"`{path}` is a YAML file (a term set, or a world), not a rule "
                            f"base", hint="a rule base is a .rules, .fcl, .fis or .fll file; "
                            "a term set is read through the `terms` line of its .rules file "
                            "(`mitos plot terms` and `mitos check` also take one alone)")
    try:
        return _read_by_extension(path)
    except MitosError as exc:
        from .interop import hint_wrong_reader

        hint_wrong_reader(exc, path)
        raise


def is_termset_name(path: str | Path | None) -> bool:
    """Whether ``path`` names a YAML file, which the commands that draw or check terms read
    as a term set on its own."""
    return path is not None and Path(path).suffix.lower() in (".yaml", ".yml")


def read_termset(path: str | Path) -> TermSet:
    """Read a term set (YAML) on its own, to draw or check its terms before any rule reads
    them; a packaged one by its name (``rulebases/mitos.terms.yaml``) from anywhere."""
    from .errors import TermSetError
    from .fileio import nearby
    from .lang.termfile import load_termset
    from .resources import packaged_names, packaged_place, resolve

    if not (isinstance(path, str) and path or isinstance(path, os.PathLike)):
        raise TermSetError(f"a term set is read from a file: expected its path, not "
                           f"{type(path).__name__} `{path!r:.60}`",
                           hint="read_termset('rulebases/mitos.terms.yaml')")
    given = _path_given(path)
    found = resolve("rulebases", given, ".terms.yaml") or Path(given)
    try:
        return load_termset(found)
    except TermSetError as exc:
        if exc.hint is not None or found.exists():
            raise
        packaged = (packaged_names("rulebases", ".yaml")
                    if packaged_place(found.parent.as_posix(), "rulebases") else ())
        raise TermSetError(exc.message, span=exc.span,
                           hint=nearby(found, (".yaml", ".yml"), packaged)) from None


def read_terms(path: str | Path | None) -> RuleBase | TermSet:
    """What draws or checks terms reads: a rule base; a term set (YAML) alone; or the terms of
    a foreign file that has no rules (jFuzzyLogic's membership-function tests), which every
    other command refuses."""
    from .errors import NoRulesError

    if path is not None and is_termset_name(path):
        return read_termset(path)
    try:
        return read_rulebase(path)
    except NoRulesError as exc:
        return cast(TermSet, exc.termset)


def _read_by_extension(path: Path) -> RuleBase:
    """The rule base at ``path``, read by the reader its extension names."""
    if path.suffix.lower() in (".fcl", ".fis", ".fll"):
        from .interop import read_foreign

        return read_foreign(path)
    from .fileio import finish_saves
    from .lang.cache import cached_rulebase

    finish_saves(path)              # a save of this rule base that a crash left half done
    return cached_rulebase(path, _load_rules_file)


def _path_given(path: object) -> str | Path:
    """``path`` if it can name a file; else a :class:`RuleBaseError` saying what is taken
    (``load_rulebase(3)`` met pathlib's TypeError; ``""`` was read as ``.``, "a directory")."""
    if isinstance(path, str) and path:
        return path
    if isinstance(path, os.PathLike):
        return Path(path)
    from .errors import RuleBaseError

    if path == "":
        raise RuleBaseError("the rule base's name is empty",
                            hint="give a rule file's path, or None for the packaged one")
    raise RuleBaseError(f"a rule base is read from a file: expected a path or a packaged rule "
                        f"base's name, not {type(path).__name__} `{path!r:.60}`",
                        hint="load_rulebase('rulebases/mitos.rules'), or load_rulebase() for "
                             "the packaged one")


def _behavior_given(rulebase: RuleBase, name: object) -> str | None:
    """``name`` if it can name a behavior (``None``: the first); else the unknown-behavior
    error with the behaviors' names (an int met "'int' object is not iterable" inside; ``""``
    compiled the first behavior, as ``None`` does)."""
    if name is None or isinstance(name, str) and name:
        return name
    from .errors import unknown

    raise unknown("behavior", f"{name!r:.40}", [b.name for b in rulebase.behaviors])


def _load_rules_file(path: Path) -> RuleBase:
    from .lang.resolve import load_rules_file  # the parser (Lark) and YAML load only on a miss

    return load_rules_file(path)


class LoadedRuleBase:
    """A rule base with one behavior compiled, ready to evaluate."""

    def __init__(self, rulebase: RuleBase, behavior: str | None = None,
                 overrides: tuple = ()) -> None:
        self.rulebase = rulebase
        self.overrides = tuple(overrides)
        self.compiled: CompiledRuleBase = compile_rulebase(
            rulebase, _behavior_given(rulebase, behavior), self.overrides)

    def __repr__(self) -> str:
        return (f"<LoadedRuleBase {self.rulebase.path or '(text)'}, behavior "
                f"{self.compiled.behavior!r} of {len(self.behaviors)}: inputs "
                f"{', '.join(self.inputs)} -> outputs {', '.join(self.outputs)}>")

    @property
    def inputs(self) -> tuple[str, ...]:
        return self.compiled.inputs

    @property
    def outputs(self) -> tuple[str, ...]:
        return self.compiled.outputs

    @property
    def behaviors(self) -> tuple[str, ...]:
        return tuple(b.name for b in self.rulebase.behaviors)

    def behavior(self, name: str) -> LoadedRuleBase:
        """The same rule base with another behavior compiled (recalled by name alone)."""
        return self._behavior(_behavior_given(self.rulebase, name))

    @functools.cache  # noqa: B019 - a handful of behaviors, cached for the rule base's lifetime
    def _behavior(self, name: str) -> LoadedRuleBase:
        return LoadedRuleBase(self.rulebase, name, self.overrides)

    def with_operators(self, **settings: str) -> LoadedRuleBase:
        """The same behavior compiled with other operators, e.g. ``with_operators(and_="product")``
        (keys as in an ``operators:`` line; a trailing underscore is dropped). An output with a
        ``resolution`` of its own (its term set's) keeps it. An unknown key is a
        :class:`~mitos_cli.errors.NameError_` whose "did you mean" is a keyword this method
        takes (``and_``, not the ``and`` of a rule file, which Python does not parse here)."""
        import keyword

        from .errors import unknown
        from .lang.model import Setting
        from .lang.operators import KEYS

        for k in settings:
            if k.rstrip("_") not in KEYS:
                raise unknown("operator setting", k,
                              [f"{key}_" if keyword.iskeyword(key) else key for key in KEYS])
        extra = tuple(Setting(k.rstrip("_"), str(v)) for k, v in settings.items())
        return LoadedRuleBase(self.rulebase, self.compiled.behavior, self.overrides + extra)

    def run(self, X: ArrayLike | Mapping[str, ArrayLike], *, detail: bool = True,
            keep_values: bool = False, strict: bool = True) -> Result:
        """Evaluate a batch ``X[n, k]`` (columns in :attr:`inputs` order, or a mapping of
        the inputs' names to their columns). ``detail`` keeps the memberships and DOFs,
        ``keep_values`` every neuron's value; ``strict=False`` leaves NaN where no rule sets
        an output that has no default (else a ``NoRuleFiredError``). Each is ``True`` or
        ``False``: another value (``detail="no"``, which was true) is an ``InputError``."""
        from .errors import InputError

        flags = {"detail": detail, "keep_values": keep_values, "strict": strict}
        for name, flag in flags.items():
            if not isinstance(flag, (bool, np.bool_)):
                raise InputError(f"`{name}` is True or False, not `{flag!r:.40}`",
                                 hint=f"run(X, {name}=False)")
        return evaluate(self.compiled, X, detail=bool(detail), keep_values=bool(keep_values),
                        strict=bool(strict))

    def evaluate(self, **inputs: float | np.ndarray) -> dict[str, float | np.ndarray]:
        """Outputs for inputs given by name (floats, or arrays evaluated as one batch)."""
        c = self.compiled
        if len(inputs) == len(c.inputs) and _NUMBERS.issuperset(map(type, inputs.values())):
            try:                               # numbers by name: the one-sample path
                values = [float(inputs[name]) for name in c.inputs]
            except (KeyError, OverflowError):
                pass                           # a misspelt name, 10**400: as_columns explains
            else:
                return dict(zip(c.outputs, evaluate_floats(c, values)))
        columns = as_columns(c, inputs)
        if all(np.ndim(v) == 0 for v in inputs.values()):
            result = evaluate(c, np.array([columns]).reshape(1, -1), detail=False)
            return dict(zip(c.outputs, result.outputs[0].tolist()))
        out = evaluate_columns(c, columns)
        return {name: out[j] for j, name in enumerate(c.outputs)}

    def trace(self, **inputs: float) -> Trace:
        """The paper-style DOF trace of one evaluation."""
        X = as_batch(self.compiled, inputs)
        if X.shape[0] != 1:
            from .errors import InputError

            raise InputError("a trace takes one value per input")
        return trace_of(evaluate(self.compiled, X), given=X)


def load_rulebase(path: str | Path | None = None, behavior: str | None = None) -> LoadedRuleBase:
    """Load and compile a rule base (default: the packaged MITOS rule base)."""
    return LoadedRuleBase(read_rulebase(path), behavior)
