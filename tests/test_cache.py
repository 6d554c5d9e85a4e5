"""The parsed-rule-base cache: a hit equals a fresh parse; any changed file is a miss."""

from __future__ import annotations

import os
import pickle
import shutil
from pathlib import Path

import pytest

from mitos_cli import api
from mitos_cli.lang import cache
from mitos_cli.lang.resolve import load_rules_file

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture()
def copy(tmp_path, monkeypatch):
    monkeypatch.setenv("MITOS_CACHE_DIR", str(tmp_path / "cache"))
    for name in ("mitos.rules", "mitos.terms.yaml", "drive.terms.yaml"):
        shutil.copy(REPO / "rulebases" / name, tmp_path / name)
    return tmp_path


def entries(root: Path) -> list[Path]:
    return sorted((root / "cache").glob("rulebase-*.pickle"))


def test_second_read_is_a_hit_and_equal(copy):
    first = api.read_rulebase(copy / "mitos.rules")
    assert len(entries(copy)) == 1
    calls = []
    second = cache.cached_rulebase(copy / "mitos.rules", lambda p: calls.append(p))
    assert calls == [] and second == first == load_rules_file(copy / "mitos.rules")


def test_a_changed_term_set_is_a_miss(copy):
    api.read_rulebase(copy / "mitos.rules")
    terms = copy / "mitos.terms.yaml"
    terms.write_text(terms.read_text().replace("peak: 70, width: 30", "peak: 72, width: 30"))
    rb = api.read_rulebase(copy / "mitos.rules")
    assert rb.variables["road"].term("MEDIUM").params == (72.0, 30.0)


def test_a_changed_rule_file_is_a_miss(copy):
    api.read_rulebase(copy / "mitos.rules")
    rules = copy / "mitos.rules"
    rules.write_text(rules.read_text().replace("then steering is RS and speed is MEDIUM    # the",
                                               "then steering is RM and speed is MEDIUM    # the"))
    rb = api.read_rulebase(rules)
    assert rb.behavior("avoid_obstacle").rules[0].consequents[0].term == "RM"
    assert len(entries(copy)) == 2


def test_a_corrupt_entry_is_a_miss(copy):
    api.read_rulebase(copy / "mitos.rules")
    (entry,) = entries(copy)
    entry.write_bytes(b"not a pickle")
    assert api.read_rulebase(copy / "mitos.rules") == load_rules_file(copy / "mitos.rules")
    pickle.loads(cache.load_entry(entry.name))        # rewritten with a good entry


def test_off_disables_it(copy, monkeypatch):
    monkeypatch.setenv("MITOS_CACHE_DIR", "off")
    api.read_rulebase(copy / "mitos.rules")
    assert not (copy / "cache").exists()


def test_errors_are_not_cached(copy):
    from mitos_cli.errors import RuleSyntaxError

    (copy / "bad.rules").write_text('terms "mitos.terms.yaml"\nif road is then\n')
    for _ in range(2):
        with pytest.raises(RuleSyntaxError):
            api.read_rulebase(copy / "bad.rules")
    assert entries(copy) == []


def test_changed_code_of_a_checkout_is_a_miss(copy, monkeypatch):
    """An editable install changes its code without a new version (a pull, an edit of the
    parser): an entry the old code made was served to the new one. The key holds each
    module's size and time (an installed copy's code goes with its version: no stat)."""
    api.read_rulebase(copy / "mitos.rules")
    stamp = cache._code_stamp()
    if "site-packages" not in cache.__file__:                  # the suite runs on a checkout
        assert b"lang/parse.py:" in stamp and b"fuzzy/shapes.py:" in stamp
    monkeypatch.setattr(cache, "_code_stamp", lambda: stamp + b"\nlang/parse.py:1:2")
    calls = []
    cache.cached_rulebase(copy / "mitos.rules", lambda p: calls.append(p))
    assert calls == [copy / "mitos.rules"]                      # a miss: parsed again


def test_a_cache_under_a_home_this_user_cannot_enter_is_no_cache(copy, monkeypatch):
    """`sudo -u other mitos ...` keeps root's HOME: the cache's mkdir was refused, and then
    asking whether the path was a broken symbolic link was refused too, a `PermissionError`
    traceback from every command that reads a rule file. It is no cache, said why."""
    from pathlib import Path as P

    def denied(self, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(self))

    where = copy / "home" / ".cache" / "mitos"
    monkeypatch.setenv("MITOS_CACHE_DIR", str(where))
    monkeypatch.setattr(P, "mkdir", denied)
    monkeypatch.setattr(P, "is_symlink", denied)
    status = cache.status()
    assert status.path is None and not status.refused
    assert status.reason == f"no cache: cannot create {where}: Permission denied"
    assert api.read_rulebase(copy / "mitos.rules").behaviors    # read, not cached


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0,
                    reason="root enters any directory")
def test_mitos_runs_with_a_cache_it_cannot_enter(copy, monkeypatch, capsys):
    from mitos_cli.cli.app import main

    home = copy / "home"
    (home / ".cache").mkdir(parents=True)
    home.chmod(0o000)
    try:
        monkeypatch.setenv("MITOS_CACHE_DIR", str(home / ".cache" / "mitos"))
        with pytest.raises(SystemExit) as info:
            main(["eval", str(copy / "mitos.rules"), "road=78", "size=45", "position=4",
                  "-b", "avoid_obstacle"])
        assert info.value.code == 0 and "Traceback" not in capsys.readouterr().err
    finally:
        home.chmod(0o700)
