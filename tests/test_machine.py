"""What the machine offers: the CPUs and memory a container's limits leave, not only the host's."""

from __future__ import annotations

from pathlib import Path

import pytest

from mitos_cli import machine

GB = 1 << 30


def cgroup(tmp_path: Path, limit: str, usage: int, inactive: int, key: str) -> tuple:
    files = tmp_path / "limit", tmp_path / "usage", tmp_path / "stat"
    files[0].write_text(f"{limit}\n")
    files[1].write_text(f"{usage}\n")
    files[2].write_text(f"anon 5\n{key} {inactive}\nactive_file 7\n")
    return (*files, key)


def test_a_containers_limit_caps_the_memory_available(tmp_path, monkeypatch):
    """In `docker run -m 2g` on a 64 GB host /proc/meminfo shows the host: 16 workers of a
    batch of office runs (0.7 GB each) would be killed by the container's limit."""
    v2 = cgroup(tmp_path, str(2 * GB), GB + GB // 2, GB // 4, "inactive_file")
    monkeypatch.setattr(machine, "CGROUPS", (v2,))
    monkeypatch.setattr(machine, "_meminfo", lambda: 64 * GB)
    assert machine.available_memory() == GB // 2 + GB // 4      # limit - usage + dropped cache
    monkeypatch.setattr(machine, "_meminfo", lambda: GB // 8)
    assert machine.available_memory() == GB // 8                 # the host is the tighter


@pytest.mark.parametrize("limit", ["max", str(machine.NO_LIMIT), str((1 << 63) - 4096)])
def test_a_cgroup_without_a_limit_leaves_the_hosts_memory(tmp_path, monkeypatch, limit):
    v1 = cgroup(tmp_path, limit, GB, 0, "total_inactive_file")
    monkeypatch.setattr(machine, "CGROUPS", (v1,))
    monkeypatch.setattr(machine, "_meminfo", lambda: 3 * GB)
    assert machine.available_memory() == 3 * GB


def test_no_cgroup_files_and_no_meminfo_is_unknown(tmp_path, monkeypatch):
    gone = (tmp_path / "a", tmp_path / "b", tmp_path / "c", "inactive_file")
    monkeypatch.setattr(machine, "CGROUPS", (gone,))
    monkeypatch.setattr(machine, "_meminfo", lambda: None)
    assert machine.available_memory() is None


def test_this_machine_answers_with_whole_positive_numbers():
    assert machine.allowed_cpus() >= 1
    found = machine.available_memory()
    assert found is None or (isinstance(found, int) and found >= 0)


@pytest.mark.parametrize("v2, v1, cpus", [
    ("200000 100000", None, 2),          # docker run --cpus 2
    ("150000 100000", None, 2),          # 1.5 CPUs of time: two processes can use it
    ("max 100000", None, 8),
    (None, ("50000", "100000"), 1),
    (None, ("-1", "100000"), 8),
    (None, None, 8),
])
def test_a_containers_cpu_quota_caps_the_cpus_allowed(tmp_path, monkeypatch, v2, v1, cpus):
    import os

    if not hasattr(os, "sched_getaffinity"):
        pytest.skip("no CPU affinity on this platform")
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(8)))
    quota, period = tmp_path / "cfs_quota", tmp_path / "cfs_period"
    if v2 is not None:
        (tmp_path / "cpu.max").write_text(v2 + "\n")
    if v1 is not None:
        quota.write_text(v1[0] + "\n")
        period.write_text(v1[1] + "\n")
    monkeypatch.setattr(machine, "CPU_QUOTAS", ((tmp_path / "cpu.max", None), (quota, period)))
    assert machine.allowed_cpus() == cpus
