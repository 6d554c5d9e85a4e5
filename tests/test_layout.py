"""The stage layout: 0.1's module paths still import (the same module, with a warning)."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

from mitos_cli._moved import MOVED


@pytest.mark.parametrize("old,new", sorted(MOVED.items()))
def test_old_path_is_the_new_module_with_a_warning(old, new):
    code = (f"import warnings; warnings.simplefilter('error')\n"
            f"try:\n    import mitos_cli.{old}\nexcept DeprecationWarning as w:\n    print(w)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert f"mitos_cli.{old} moved to mitos_cli.{new}" in out.stdout
    with pytest.warns(DeprecationWarning):
        old_mod = importlib.import_module(f"mitos_cli.{old}")
    assert old_mod is importlib.import_module(f"mitos_cli.{new}")
    assert old_mod.__name__ == f"mitos_cli.{new}"


def test_old_engine_names_are_served_from_evaluation():
    from mitos_cli.engine import evaluation

    with pytest.warns(DeprecationWarning, match="mitos_cli.engine.evaluation.evaluate"):
        from mitos_cli.engine import evaluate
    assert evaluate is evaluation.evaluate
    with pytest.raises(ImportError):
        from mitos_cli.engine import no_such_name  # noqa: F401


def test_the_package_lists_the_names_it_gives_lazily():
    """`dir(mitos_cli)` (a notebook's tab completion) had no `load_rulebase`, which the
    package gives through its module `__getattr__`: every name of `__all__` is listed, and
    each is there."""
    import mitos_cli

    assert set(mitos_cli.__all__) <= set(dir(mitos_cli))
    assert all(getattr(mitos_cli, name) is not None for name in mitos_cli.__all__)
