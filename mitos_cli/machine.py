"""What the machine offers this process: the CPUs it may run on and the memory still free.

The one place that asks, so that the engine's threads, ``simulate --runs``' processes and a
study's workers count the same CPUs (``os.cpu_count()`` counts the machine's: under
``taskset -c 0`` that is two processes on one CPU)."""

from __future__ import annotations

import os


def allowed_cpus() -> int:
    """The CPUs this process may run on (its affinity where the system has one), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:              # not on Linux
        return max(1, os.cpu_count() or 1)


def available_memory() -> int | None:
    """Bytes of memory a new process could take without swapping (Linux's ``MemAvailable``:
    free memory plus the caches it may drop), else the free pages POSIX counts; ``None``
    where neither is known."""
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return None
