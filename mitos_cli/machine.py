"""What the machine offers this process: the CPUs it may run on and the memory still free.

The one place that asks, so that the engine's threads, ``simulate --runs``' processes and a
study's workers count the same CPUs (``os.cpu_count()`` counts the machine's: under
``taskset -c 0`` that is two processes on one CPU)."""

from __future__ import annotations

import os
from pathlib import Path

#: The memory controller's files of this process's cgroup (v2, then v1): a container's limit
#: (``docker run -m 2g``) is not in ``/proc/meminfo``, which shows the host's memory.
CGROUPS = (
    (Path("/sys/fs/cgroup/memory.max"), Path("/sys/fs/cgroup/memory.current"),
     Path("/sys/fs/cgroup/memory.stat"), "inactive_file"),
    (Path("/sys/fs/cgroup/memory/memory.limit_in_bytes"),
     Path("/sys/fs/cgroup/memory/memory.usage_in_bytes"),
     Path("/sys/fs/cgroup/memory/memory.stat"), "total_inactive_file"),
)

#: A cgroup "limit" at or above this is none (v1 writes 2^63 rounded down to a page).
NO_LIMIT = 1 << 60


#: The CPU controller's quota files (v2: ``"quota period"`` or ``"max period"``; v1: the two
#: numbers apart, -1 for none): ``docker run --cpus 2`` on a 64-core host leaves the affinity
#: at 64 CPUs and the time of 2.
CPU_QUOTAS = (
    (Path("/sys/fs/cgroup/cpu.max"), None),
    (Path("/sys/fs/cgroup/cpu/cpu.cfs_quota_us"), Path("/sys/fs/cgroup/cpu/cpu.cfs_period_us")),
)


def allowed_cpus() -> int:
    """The CPUs this process may run on (its affinity where the system has one), no more than
    its cgroup's CPU quota (rounded up), at least 1."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:              # not on Linux
        cpus = os.cpu_count() or 1
    quota = _cpu_quota()
    return max(1, cpus if quota is None else min(cpus, quota))


def _cpu_quota() -> int | None:
    for quota_file, period_file in CPU_QUOTAS:
        try:
            words = quota_file.read_text().split()
            if period_file is not None:
                words = [words[0], period_file.read_text().strip()]
            quota, period = (None if words[0] in ("max", "-1") else int(words[0])), int(words[1])
        except (OSError, ValueError, IndexError):
            continue
        if quota is None or quota <= 0 or period <= 0:
            return None
        return -(-quota // period)
    return None


def available_memory() -> int | None:
    """Bytes of memory new processes could take without swapping or meeting a container's
    limit: Linux's ``MemAvailable`` (free memory plus the caches it may drop), or the free
    pages POSIX counts, and no more than the cgroup's limit leaves; ``None`` where nothing is
    known."""
    found = [n for n in (_meminfo(), _cgroup_headroom()) if n is not None]
    return min(found) if found else None


def _meminfo() -> int | None:
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


def _cgroup_headroom() -> int | None:
    """The cgroup's limit less what it holds (its file cache it may drop counted free, as a
    container's working set is), ``None`` without a limit."""
    for limit_file, usage_file, stat_file, inactive in CGROUPS:
        try:
            text = limit_file.read_text().strip()
            if text == "max":
                return None
            limit, usage = int(text), int(usage_file.read_text())
        except (OSError, ValueError):
            continue
        if limit >= NO_LIMIT:
            return None
        return max(0, limit - usage + _stat(stat_file, inactive))
    return None


def _stat(path: Path, key: str) -> int:
    try:
        for line in path.read_text().splitlines():
            name, _, value = line.partition(" ")
            if name == key:
                return int(value)
    except (OSError, ValueError):
        pass
    return 0
