"""Test-wide settings."""

from __future__ import annotations

import os
import sys
import tempfile

# The parsed-rule-base cache of this test run lives in a fresh directory (inherited by the
# CLI subprocesses the tests start), never in the user's ~/.cache.
os.environ.setdefault("MITOS_CACHE_DIR", tempfile.mkdtemp(prefix="mitos-test-cache-"))

# The CLI tests start hundreds of Python processes: let them write and reuse byte code even
# where the environment says not to, or each one recompiles all of MITOS first.
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
sys.dont_write_bytecode = False
