"""The Dask executor on a 2-worker LocalCluster gives the local executor's results bit for bit,
and that cluster (the one ``mitos compare --executor dask`` starts) admits no other process."""

from __future__ import annotations

import os
import socket
import ssl
from pathlib import Path

import pytest

from mitos_cli.study import run_study

distributed = pytest.importorskip("distributed")

from test_study_cli import TINY  # noqa: E402
from test_study_core import fake_sim, small_study  # noqa: E402


@pytest.fixture(scope="module")
def client():
    from mitos_cli.study.executors import local_cluster

    with local_cluster(2) as cluster, distributed.Client(cluster, security=cluster.security) as c:
        yield c


def test_dask_equals_local_bit_for_bit(tmp_path, client):
    study = small_study(runs=8)
    local = run_study(study, tmp_path / "local", workers=2, task_fn=fake_sim)
    dask = run_study(study, tmp_path / "dask", executor="dask", client=client, task_fn=fake_sim)
    assert dask.executed == len(dask.rows) == 48
    assert dask.rows == local.rows                      # floats compared exactly


def test_real_simulator_on_dask_equals_serial(tmp_path, client):
    from mitos_cli.study import Study, make_choices

    world = tmp_path / "tiny.yaml"
    world.write_text(TINY)
    study = Study([str(world)], make_choices(["fuzzy", "potential_field"], ["product"], [], []),
                  runs=2, seed=5)
    serial = run_study(study, tmp_path / "serial", workers=1)
    dask = run_study(study, tmp_path / "dask", executor="dask", client=client)
    assert dask.rows == serial.rows and len(serial.rows) == 4


def test_dask_resume_skips_finished(tmp_path, client):
    study = small_study(runs=4)
    half = small_study(runs=2)
    run_study(half, tmp_path, executor="dask", client=client, task_fn=fake_sim)
    out = run_study(study, tmp_path, executor="dask", client=client, resume=True,
                    task_fn=fake_sim)
    assert (out.skipped, out.executed) == (12, 12)
    assert out.rows == run_study(study, tmp_path / "fresh", workers=1, task_fn=fake_sim).rows


def test_unreachable_scheduler_is_a_clear_error():
    from mitos_cli.study.executors import dask_client
    from mitos_cli.study.store import StudyError

    with pytest.raises(StudyError) as exc:
        dask_client("tcp://127.0.0.1:9", 2, timeout="0.5s")
    assert "cannot reach the Dask scheduler at tcp://127.0.0.1:9" in exc.value.message
    assert "dask scheduler" in exc.value.hint


def test_an_unreachable_scheduler_leaves_the_directory_as_it_was(tmp_path, monkeypatch):
    """The scheduler was reached only once the study had written study.json and the header
    of results.csv: a refused `--scheduler` left a study behind in a new directory."""
    from mitos_cli.study import executors
    from mitos_cli.study.store import StudyError

    reach = executors.dask_client
    monkeypatch.setattr(executors, "dask_client",
                        lambda scheduler, workers: reach(scheduler, workers, timeout="0.5s"))
    with pytest.raises(StudyError, match="cannot reach the Dask scheduler"):
        run_study(small_study(runs=1), tmp_path / "s", executor="dask",
                  scheduler="tcp://127.0.0.1:9", task_fn=fake_sim)
    assert not (tmp_path / "s").exists()


def test_a_plain_local_cluster_runs_a_strangers_code():
    """The attack on the cluster the Dask executor used to start: any local process that
    finds the port connects and runs code."""
    from mitos_cli.study.executors import QUIET_HTTP

    with distributed.LocalCluster(n_workers=1, processes=False, dashboard_address=None,
                                  scheduler_kwargs=QUIET_HTTP) as plain, \
            distributed.Client(plain.scheduler_address, timeout="5s") as stranger:
        assert stranger.run_on_scheduler(os.getpid) == os.getpid()


def _handshake(address: str, context: ssl.SSLContext) -> None:
    host, port = address.split("://")[1].rsplit(":", 1)
    with socket.create_connection((host, int(port)), timeout=5) as raw, \
            context.wrap_socket(raw, server_hostname=host) as tls:
        tls.sendall(b"\0" * 8)                # TLS 1.3 reports a refused certificate here
        if not tls.recv(1):
            raise ConnectionResetError("closed")


def test_a_stranger_cannot_reach_the_local_cluster(client):
    from distributed.security import Security

    info = client.scheduler_info()
    addresses = [client.scheduler.address, *info["workers"]]
    assert all(a.startswith("tls://127.0.0.1:") for a in addresses)
    for address in addresses:
        # a client with certificates of its own making is refused at the handshake
        with pytest.raises(OSError):
            distributed.Client(address, security=Security.temporary(), timeout="3s")
        # and one that brings no certificate at all
        bare = ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT)
        bare.check_hostname, bare.verify_mode = False, ssl.CERT_NONE
        with pytest.raises((ssl.SSLError, ConnectionError)):
            _handshake(address, bare)
    # nothing of the workers' lies in a directory others may write
    for worker in info["workers"].values():
        scratch = Path(worker["local_directory"]).parents[1]
        assert scratch.name.startswith("mitos-dask-") and scratch.stat().st_mode & 0o077 == 0
        assert (scratch / "owner.pid").read_text() == f"{os.getpid()}\n"
    # the owner's client still works, and its results are the serial run's (tests above)
    assert client.submit(sum, [1, 2]).result() == 3


def test_the_local_cluster_binds_no_dashboard_port():
    """`dashboard_address=None` still bound the scheduler's HTTP server to 8787: two studies
    at once (`pytest -n 2`'s two workers) collided, the second warning "Port 8787 is already
    in use". With 8787 taken, the cluster starts without a word, its HTTP server on
    127.0.0.1 at a port of the system's choosing and no dashboard."""
    import warnings

    from mitos_cli.study.executors import local_cluster

    taken = socket.socket()
    try:
        taken.bind(("127.0.0.1", 8787))
        taken.listen()
    except OSError:
        pass                                  # taken already: the case to test all the same
    try:
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            with local_cluster(1) as cluster:
                http = cluster.scheduler.http_server
                assert (http.address, cluster.scheduler.services["dashboard"]) == \
                    ("127.0.0.1", http)
                assert http.port not in (0, 8787)
        assert [str(w.message) for w in said if "already in use" in str(w.message)] == []
    finally:
        taken.close()


def test_a_local_cluster_has_no_more_workers_than_tasks(monkeypatch, tmp_path):
    """`compare -j 500 --executor dask` started 500 worker processes for a handful of tasks."""
    from mitos_cli.study import executors

    asked = []

    def no_cluster(scheduler, workers):
        asked.append(workers)
        raise RuntimeError("stop here")

    monkeypatch.setattr(executors, "dask_client", no_cluster)
    with pytest.raises(RuntimeError, match="stop here"):
        list(executors.run_dask(fake_sim, [object()] * 3, 500))
    assert asked == [3]


def test_a_fleet_on_dask_equals_serial(tmp_path, client):
    """A world of several robots: each run's robots' rows come back from the workers with it,
    bit for bit those of a serial study, and results.csv holds the same lines."""
    from test_study_fleet import fleet_study

    serial = run_study(fleet_study(), tmp_path / "serial", workers=1)
    dask = run_study(fleet_study(), tmp_path / "dask", executor="dask", client=client)
    assert dask.rows == serial.rows and all(len(r["robots"]) == 2 for r in dask.rows)
    lines = [sorted((tmp_path / d / "results.csv").read_text().splitlines())
             for d in ("serial", "dask")]
    assert lines[0] == lines[1] and len(lines[0]) == 1 + 2 * 3


def slow_after_the_first(task: int) -> dict:
    """A task function whose every task but the first runs for a minute."""
    import time

    if task != 0:
        time.sleep(60)
    return {"task": task}


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="finds the workers in /proc")
def test_a_study_stopped_early_closes_its_local_cluster_within_a_second():
    """A study on a LocalCluster stopped early (Ctrl-C) took 1 to 4 s to end: closing the
    cluster waits for the task each worker is in, 4 s at most, before it kills the worker.
    Nobody reads those tasks' results: the workers are given a quarter of a second now."""
    import time

    from test_study_cli import _alive, _children

    from mitos_cli.study.executors import run_dask

    def spawned() -> set[int]:              # (not multiprocessing's resource tracker)
        return {pid for pid in _children(os.getpid())
                if b"spawn_main" in Path(f"/proc/{pid}/cmdline").read_bytes()}

    others = spawned()                      # (the module's cluster, when it is up)
    parts = run_dask(slow_after_the_first, [0, 1, 2], workers=2)
    assert next(parts) == (0, {"task": 0})      # both workers are now in a minute's task
    workers = spawned() - others
    started = time.monotonic()
    parts.close()
    took = time.monotonic() - started
    assert len(workers) == 2
    assert took < 1.5 and not _alive(workers), f"{took:.2f} s"


@pytest.mark.skipif(os.name == "nt", reason="not swept on Windows (os.kill(pid, 0) ends a process)")
def test_scratch_left_by_a_process_that_is_gone_is_swept_and_nothing_else(tmp_path):
    """A study killed with `kill -9` left its cluster's scratch directory in the temporary
    directory for good (thirteen after the reliability campaign's kill harness): a local
    cluster's start removes those whose owner process is gone, and only those."""
    import subprocess
    import sys

    from mitos_cli.study.executors import swept_scratch

    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()

    def scratch(name: str, owner: str | None) -> Path:
        path = tmp_path / name
        (path / "dask-scratch-space" / "worker-1").mkdir(parents=True)
        if owner is not None:
            (path / "owner.pid").write_text(owner + "\n")
        return path

    dead = scratch("mitos-dask-dead", gone)
    alive = scratch("mitos-dask-alive", str(os.getpid()))
    old = scratch("mitos-dask-old", None)                 # made before owners were written
    junk = scratch("mitos-dask-junk", "not a pid")
    other = scratch("other-dead", gone)                   # not a cluster's
    link = tmp_path / "mitos-dask-link"
    link.symlink_to(dead.parent / "elsewhere", target_is_directory=True)
    (dead.parent / "elsewhere").mkdir()
    (dead.parent / "elsewhere" / "owner.pid").write_text(gone + "\n")

    assert swept_scratch(str(tmp_path)) == [dead]
    assert not dead.exists()
    assert all(p.exists() for p in (alive, old, junk, other, link, dead.parent / "elsewhere"))
    assert swept_scratch(str(tmp_path)) == []


def test_process_alive_never_signals_on_windows(monkeypatch):
    """`os.kill(pid, 0)` asks whether a process runs on POSIX and ends it on Windows: what a
    gone process left (a save's temporary file, a cluster's scratch) is kept there instead."""
    import mitos_cli.fileio as fileio

    asked: list = []
    monkeypatch.setattr(fileio.os, "kill", lambda *a: asked.append(a))
    monkeypatch.setattr(fileio.os, "name", "nt")
    assert fileio.process_alive(2 ** 22 + 1) and asked == []
