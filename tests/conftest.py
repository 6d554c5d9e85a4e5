"""Test-wide settings."""

from __future__ import annotations

import os
import tempfile

# The parsed-rule-base cache of this test run lives in a fresh directory (inherited by the
# CLI subprocesses the tests start), never in the user's ~/.cache.
os.environ.setdefault("MITOS_CACHE_DIR", tempfile.mkdtemp(prefix="mitos-test-cache-"))
