"""Test-wide settings."""

from __future__ import annotations

import os
import sys
import tempfile

import pytest

# The parsed-rule-base cache of this test run lives in a fresh directory (inherited by the
# CLI subprocesses the tests start), never in the user's ~/.cache.
os.environ.setdefault("MITOS_CACHE_DIR", tempfile.mkdtemp(prefix="mitos-test-cache-"))

# The CLI tests start hundreds of Python processes: let them write and reuse byte code even
# where the environment says not to, or each one recompiles all of MITOS first.
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
sys.dont_write_bytecode = False

# Property tests draw the same examples on every run (each test's from its own name), so a
# red CI is a defect anyone can reproduce, never a draw that passes on the next try. Explore
# new examples on purpose: `python -m pytest --hypothesis-profile=explore` (docs/reliability.md).
from hypothesis import settings  # noqa: E402

settings.register_profile("repeatable", derandomize=True, database=None)
settings.register_profile("explore", max_examples=500)
settings.load_profile("repeatable")


@pytest.fixture
def sigint():
    """Ctrl-C as Python takes it by default, for a test that sends itself one: a test run
    started in the background inherits SIGINT ignored, and the signal was then lost ("DID NOT
    RAISE KeyboardInterrupt")."""
    import signal

    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)
