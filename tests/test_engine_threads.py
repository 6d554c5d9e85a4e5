"""A large batch is spread over threads: every sample keeps the bits it has in one thread and
alone, an error names the sample one thread would name, and a forked child still evaluates."""

from __future__ import annotations

import multiprocessing

import numpy as np
import pytest

from mitos_cli import load_rulebase
from mitos_cli.engine import evaluation, threads
from mitos_cli.engine.evaluation import BLOCK, GRID_BLOCK, evaluate, evaluate_columns
from mitos_cli.errors import InputError

THREADS = ("1", "2", "3", "8")


def _inputs(c, n: int, seed: int) -> np.ndarray:
    """``X[n, k]``, a tenth of each input outside its universe (clamped)."""
    rng = np.random.default_rng(seed)
    lo, hi = c.universe[:, 0], c.universe[:, 1]
    return rng.uniform(lo - (hi - lo) / 20, hi + (hi - lo) / 20, size=(n, len(c.inputs)))


def _bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a).view(np.int64)


@pytest.mark.parametrize("behavior", ["avoid_obstacle", "drive"])   # the grid path, the general
def test_columns_keep_their_bits_in_any_number_of_threads(behavior, monkeypatch):
    c = load_rulebase().behavior(behavior).compiled
    X = _inputs(c, 4 * GRID_BLOCK + 321, seed=11)          # five blocks, the last short
    outs = []
    for t in THREADS:
        monkeypatch.setenv(threads.ENV, t)
        outs.append(_bits(evaluate_columns(c, X.T)))
    assert all(np.array_equal(outs[0], o) for o in outs[1:])
    monkeypatch.setenv(threads.ENV, "1")
    for i in (0, GRID_BLOCK - 1, GRID_BLOCK, 3 * GRID_BLOCK + 5, len(X) - 1):
        assert np.array_equal(_bits(evaluate_columns(c, X[i:i + 1].T))[:, 0], outs[0][:, i])


def test_one_thread_takes_blocks_its_cache_holds_and_threads_take_wide_ones(monkeypatch):
    g = load_rulebase().compiled.grid_batch
    monkeypatch.setenv(threads.ENV, "1")
    narrow = evaluation._grid_width(g, 10**6)
    assert narrow == 1536 and narrow % 256 == 0          # 27 rules: 912 bytes a sample
    monkeypatch.setenv(threads.ENV, "2")
    assert evaluation._grid_width(g, 10**6) == GRID_BLOCK
    assert evaluation._grid_width(g, GRID_BLOCK) == narrow    # one block: the caller's thread


def test_rows_keep_their_bits_and_details_in_any_number_of_threads(monkeypatch):
    c = load_rulebase().compiled
    X = _inputs(c, 3 * BLOCK + 17, seed=12)
    results = []
    for t in THREADS:
        monkeypatch.setenv(threads.ENV, t)
        results.append(evaluate(c, X, keep_values=True))
    first = results[0]
    for r in results[1:]:
        for a, b in ((first.outputs, r.outputs), (first.dof, r.dof), (first.memberships, r.memberships),
                     (first.values, r.values), (first.inputs, r.inputs)):
            assert np.array_equal(_bits(a), _bits(b))
        assert first.clamped.tolist() == r.clamped.tolist()


def test_an_error_names_the_first_bad_sample_however_the_blocks_fall(monkeypatch):
    c = load_rulebase().compiled
    X = _inputs(c, 6 * GRID_BLOCK, seed=13)
    X[4 * GRID_BLOCK + 9, 0] = np.nan                       # a later block, taken first maybe
    X[GRID_BLOCK + 3, 2] = np.nan
    for t in THREADS:
        monkeypatch.setenv(threads.ENV, t)
        for _ in range(5):
            with pytest.raises(InputError, match=rf"`position` is not a number .*sample "
                                                 rf"{GRID_BLOCK + 4}\)"):
                evaluate_columns(c, X.T)
            with pytest.raises(InputError, match=rf"sample {GRID_BLOCK + 4}\)"):
                evaluate(c, X)


def test_an_error_names_the_first_bad_sample_not_the_first_input_with_one(monkeypatch):
    # in one block of 8,192 samples but two of 1,536: the sample, not the input, comes first
    c = load_rulebase().compiled
    X = _inputs(c, 3 * GRID_BLOCK, seed=15)
    X[2000, 0] = np.nan
    X[5, 2] = np.nan
    for t in THREADS:
        monkeypatch.setenv(threads.ENV, t)
        with pytest.raises(InputError, match=r"`position` is not a number .*sample 6\)"):
            evaluate_columns(c, X.T)
        with pytest.raises(InputError, match=r"`position` is not a number .*sample 6\)"):
            evaluate(c, X)


@pytest.mark.parametrize("value", ["0", "-1", "two", "1.5", "4 threads", "257", "\u0664"])
def test_a_thread_count_that_is_not_a_number_of_threads_is_refused(value, monkeypatch):
    c = load_rulebase().compiled
    monkeypatch.setenv(threads.ENV, value)
    with pytest.raises(InputError, match=f"{threads.ENV} is `{value}`") as info:
        evaluate_columns(c, _inputs(c, 3 * GRID_BLOCK, seed=14).T)
    assert "a whole number from 1 to 256" in str(info.value)


@pytest.mark.parametrize("value", ["9" * 5000, "0" * 5000 + "2"])
def test_a_thread_count_of_thousands_of_digits_is_read_without_int_s_limit(value, monkeypatch):
    # the fuzz pass of 2026-12-03: int() raised ValueError ("Exceeds the limit (4300 digits)")
    # from every command, before the message; leading zeros are still a number
    c = load_rulebase().compiled
    X = _inputs(c, 2 * GRID_BLOCK + 1, seed=16).T
    monkeypatch.setenv(threads.ENV, value)
    if value.endswith("2"):
        assert threads.given() == 2
        monkeypatch.setenv(threads.ENV, "1")
        one = evaluate_columns(c, X)
        monkeypatch.setenv(threads.ENV, value)
        assert np.array_equal(_bits(evaluate_columns(c, X)), _bits(one))
        return
    with pytest.raises(InputError, match=r"MITOS_NUM_THREADS is `9{40}\.\.\.9{20}` \(5,000 "
                                         r"characters\), not a number of threads"):
        evaluate_columns(c, X)


def test_the_cli_refuses_a_wrong_thread_count_before_any_command_runs():
    import os
    import subprocess
    import sys

    env = {**os.environ, threads.ENV: "two"}
    done = subprocess.run([sys.executable, "-m", "mitos_cli", "eval", "road=78", "size=45",
                           "position=4", "--json"], capture_output=True, text=True, env=env)
    assert done.returncode == 1 and done.stdout == ""
    assert done.stderr.startswith("input error: MITOS_NUM_THREADS is `two`, not a number of "
                                  "threads\nexpected a whole number from 1 to 256\n")


def _child(n: int) -> bytes:
    c = load_rulebase().compiled
    return evaluate_columns(c, _inputs(c, n, seed=15).T).tobytes()


@pytest.mark.skipif("fork" not in multiprocessing.get_all_start_methods(),
                    reason="no fork on this platform")
def test_a_forked_child_makes_its_own_threads(monkeypatch):
    monkeypatch.setenv(threads.ENV, "2")
    n = 3 * GRID_BLOCK
    expected = _child(n)                        # the parent's pool now has a thread
    with multiprocessing.get_context("fork").Pool(1) as pool:
        assert pool.apply_async(_child, (n,)).get(timeout=120) == expected


def test_the_earliest_block_s_error_wins_even_when_a_later_one_fails_first(monkeypatch):
    import time

    monkeypatch.setenv(threads.ENV, "3")

    def work(ranges):
        for start, _ in ranges:
            if start == 10:
                time.sleep(0.3)                 # the others reach block 40 first
                raise ValueError("block 10")
            if start == 40:
                raise ValueError("block 40")
        return "done"

    with pytest.raises(ValueError, match="block 10"):
        threads.map_blocks(work, 60, 10)
    sizes = threads.map_blocks(lambda ranges: sum(e - s for s, e in ranges), 65, 10)
    assert len(sizes) == 3 and sum(sizes) == 65          # three threads, every sample once


def test_batches_in_several_threads_at_once_with_pools_growing_under_them(monkeypatch):
    """A batch that grows the pool (more threads asked for) must not stop another batch
    submitting to the pool it took a moment before."""
    from concurrent.futures import ThreadPoolExecutor

    c = load_rulebase().compiled
    X = _inputs(c, 3 * GRID_BLOCK, seed=16)
    monkeypatch.setenv(threads.ENV, "1")
    expected = _bits(evaluate_columns(c, X.T))
    monkeypatch.setenv(threads.ENV, "2")

    def batch(k: int) -> bool:
        if k % 3 == 0:
            threads._executor(2 + k)              # another caller needing a larger pool
        return np.array_equal(_bits(evaluate_columns(c, X.T)), expected)

    with ThreadPoolExecutor(4) as callers:
        assert all(callers.map(batch, range(24)))


def test_a_network_of_many_neurons_takes_narrower_blocks_with_the_same_bits(tmp_path):
    """A block of 8,192 samples of a network of 3,000 terms held 197 MB of neuron values
    (10,000 terms: 655 MB); blocks now hold at most BLOCK_CELLS values, and a sample's
    outputs are the bits it has alone."""
    import tracemalloc

    from mitos_cli.api import read_rulebase
    from mitos_cli.engine.compile import compile_rulebase

    n = 3000
    terms = "".join(f"      T{i}: {{shape: triangle, peak: {i + 1}, width: 1}}\n"
                    for i in range(n))
    (tmp_path / "big.terms.yaml").write_text(
        f"variables:\n  x:\n    role: input\n    universe: [0, {n + 1}]\n    terms:\n{terms}"
        "  y:\n    role: output\n    universe: [0, 10]\n    default: 0\n    terms:\n"
        "      A: {shape: triangle, peak: 5, width: 5}\n")
    rules = "".join(f"r{i}: if x is T{i} then y is {i % 10}\n" for i in range(0, n, 7))
    (tmp_path / "big.rules").write_text('terms "big.terms.yaml"\n' + rules)
    compiled = compile_rulebase(read_rulebase(tmp_path / "big.rules"), None)
    X = np.random.default_rng(1).uniform(0, n + 1, (8192, 1))
    tracemalloc.start()
    try:
        got = evaluate(compiled, X, detail=False).outputs
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 250e6                                    # was 394 MB
    alone = np.array([evaluate(compiled, X[i:i + 1], detail=False).outputs[0]
                      for i in range(0, 8192, 997)])
    assert got[::997].tobytes() == alone.tobytes() and np.isfinite(got).all()
    assert evaluation.block_width(compiled) * compiled.n_columns <= evaluation.BLOCK_CELLS


def test_a_wrong_thread_count_leaves_the_help_version_and_completion_alone():
    """`MITOS_NUM_THREADS=two mitos --help` (or `--version`, or the shell's completion, which
    printed the refusal as the words it offered) was refused: nothing of it is used there."""
    import os
    import subprocess
    import sys

    env = {**os.environ, threads.ENV: "two"}
    for args in (["--help"], ["eval", "-h"], ["--version"]):
        done = subprocess.run([sys.executable, "-m", "mitos_cli", *args], capture_output=True,
                              text=True, env=env)
        assert done.returncode == 0 and done.stderr == "", (args, done.stderr)
    env.update(_MITOS_COMPLETE="complete_bash", COMP_WORDS="mitos sim", COMP_CWORD="1")
    done = subprocess.run([sys.executable, "-m", "mitos_cli"], capture_output=True, text=True,
                          env=env)
    assert done.stdout.split() == ["simulate"] and done.stderr == ""
