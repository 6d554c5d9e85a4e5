"""Where the tasks of a study run: in this process, in a process pool, or on Dask.

Every executor is a generator of ``(task, result)`` pairs in the order they finish; the caller
writes each one down at once. A task's result depends on the task alone (its seed is in it), so
every executor gives the same results as a serial run, bit for bit; only the arrival order
differs. Tasks travel in chunks to keep the per-task overhead low, and the simulator steps a
chunk's runs of one world and choice together. From the local pool each result arrives as its
task finishes; from Dask, a chunk's results arrive together when the chunk ends.
"""

from __future__ import annotations

import contextlib
import functools
import os
import stat
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import install_hint
from ..fileio import process_alive
from .spec import Task
from .store import StudyError

if TYPE_CHECKING:
    from distributed import Client, LocalCluster

TaskFn = Callable[[Task], dict]
EXECUTORS = ("local", "dask")


@dataclass(frozen=True)
class Going:
    """Where the runs of a chunk still going are, in simulated seconds (what the simulator
    tells between its runs' ends, :class:`~mitos_cli.sim.lockstep.Clock`), and the tasks the
    chunk holds (so that a progress bar can tell when it has ended)."""

    seconds: float
    tasks: tuple[int, ...]


Part = tuple[Task, dict] | Going


def run_chunk(fn: TaskFn, tasks: Sequence[Task]) -> Iterator[Part]:
    """Run a chunk of tasks (what a worker does with one message), each ``(task, result)``
    as it finishes: together where the task function can (its ``each``: the simulator steps
    the runs of a world and choice in lockstep, and says where they are between their ends:
    :class:`Going`), else one after the other."""
    each = getattr(fn, "each", None)
    if each is None:
        for task in tasks:
            yield task, fn(task)
        return
    ids = tuple(task.index for task in tasks)
    for item in each(tasks):
        yield item if isinstance(item, tuple) else Going(item.seconds, ids)


def chunk_list(fn: TaskFn, tasks: Sequence[Task]) -> list[tuple[Task, dict]]:
    """:func:`run_chunk`'s results as one list (a Dask future's result: it arrives when the
    chunk has ended, so where its runs were on the way says nothing)."""
    return [part for part in run_chunk(fn, tasks) if not isinstance(part, Going)]


def chunks(tasks: Sequence[Task], workers: int, most: int = 8) -> list[list[Task]]:
    """Cut ``tasks`` into chunks: at least ~8 per worker for balance, at most ``most`` long."""
    size = max(1, min(most, len(tasks) // (8 * workers)))
    return [list(tasks[i:i + size]) for i in range(0, len(tasks), size)]


def lockstep_chunks(tasks: Sequence[Task], workers: int,
                    most: int | None = None) -> list[list[Task]]:
    """Cut ``tasks`` into chunks of one world and choice each, for a task function that runs
    a chunk together: each world and choice in as many chunks as a multiple of ``workers``,
    of at most ``most`` (default: a lockstep batch, :data:`.lockstep.BATCH`; a batch of 5
    runs costs about twice what one of 40 does a robot-tick), the chunks in the order of
    their first tasks (a sweep stopped half-way holds about as many runs of every world and
    choice)."""
    from ..sim.lockstep import BATCH
    from ..sim.runs import even_chunks

    groups: dict[tuple, list[Task]] = {}
    for task in tasks:
        groups.setdefault((task.world, task.choice), []).append(task)
    out = []
    for group in groups.values():
        size = even_chunks(len(group), workers, BATCH if most is None else most)
        out += [group[i:i + size] for i in range(0, len(group), size)]
    return sorted(out, key=lambda chunk: chunk[0].index)


def _chunks_for(fn: TaskFn, tasks: Sequence[Task], workers: int) -> list[list[Task]]:
    return (lockstep_chunks(tasks, workers) if hasattr(fn, "each")
            else chunks(tasks, workers))


def run_serial(fn: TaskFn, tasks: Sequence[Task]) -> Iterator[Part]:
    for chunk in _chunks_for(fn, tasks, 1):
        yield from run_chunk(fn, chunk)


def run_local(fn: TaskFn, tasks: Sequence[Task], workers: int) -> Iterator[Part]:
    """A pool of ``workers`` processes (one worker: this process, no pool), each result
    arriving as its task finishes.

    On an error or Ctrl-C the workers are terminated at once (``Pool.terminate``) rather than
    left to finish their chunks; every result that arrived is already on disk.
    """
    if workers <= 1 or len(tasks) <= 1:
        yield from run_serial(fn, tasks)
        return
    from ..sim.runs import pool_streaming

    parts = _chunks_for(fn, tasks, workers)
    yield from pool_streaming(functools.partial(run_chunk, fn), parts, min(workers, len(parts)))


def require_dask(scheduler: str | None) -> None:
    """Refuse ``--executor dask`` without dask.distributed (and, for the local cluster, the
    `cryptography` its TLS needs) before a study writes anything or shows its progress: the
    same words :func:`dask_client` and :func:`local_cluster` say, found without importing
    them (a second and more)."""
    from importlib.util import find_spec

    if find_spec("distributed") is None:
        raise StudyError("the Dask executor needs dask.distributed, which is not installed",
                         hint=f"{install_hint('dask')}, or use --executor local")
    if scheduler is None and find_spec("cryptography") is None:
        raise StudyError("the local Dask cluster needs `cryptography` for its TLS certificates",
                         hint=f"{install_hint('dask')}, or use --executor local")


def dask_client(scheduler: str | None, workers: int, timeout: str = "10s") -> Client:
    """A ``distributed.Client`` to ``scheduler`` (giving up after ``timeout``), or to a new
    LocalCluster of ``workers`` processes."""
    try:
        from distributed import Client
    except ImportError:
        raise StudyError("the Dask executor needs dask.distributed, which is not installed",
                         hint=f"{install_hint('dask')}, or use --executor local") from None
    if scheduler:
        try:
            return Client(scheduler, timeout=timeout)
        except (OSError, TimeoutError, ValueError) as exc:
            raise StudyError(f"cannot reach the Dask scheduler at {scheduler}: {exc}",
                             hint="start one with `dask scheduler` (and `dask worker ADDR` "
                                  "on each machine), or leave out --scheduler for a local "
                                  "cluster") from None
    cluster = local_cluster(workers)
    return Client(cluster, security=cluster.security)


#: The scheduler's HTTP server (its health and metrics routes: no dashboard is asked for) on
#: 127.0.0.1 at a port the system picks. ``dashboard_address=None`` leaves the dashboard out
#: but still binds that server to 8787 (``Scheduler.start_http_server``'s default), so two
#: studies at once (or two test workers) collided, the second warning "Port 8787 is already
#: in use" and taking another.
QUIET_HTTP = {"dashboard_address": "127.0.0.1:0"}


def local_cluster(workers: int) -> LocalCluster:
    """A LocalCluster of ``workers`` processes that only this process and its workers can use.

    Without ``security`` a LocalCluster accepts any connection on its port, and a client that
    connects can run code in the workers: any account on the machine could. Here the
    scheduler, nannies and workers listen on 127.0.0.1 only and speak mutual TLS with a
    certificate authority made for this cluster (``Security.temporary()``, in memory, handed
    to the workers as they start), so a connection without that certificate is refused
    during the handshake. The workers' scratch space (where Dask would spill pickled data) is
    a fresh 0700 directory of this user's, not the shared ``$TMPDIR/dask-scratch-space``,
    and is removed with the cluster. Its processes log only what is critical
    (``silence_logs``): a run's error reaches this process as the task's exception, and what
    they would log besides is the noise of a cluster closed under them (a study stopped with
    Ctrl-C: "Failed to communicate with scheduler during heartbeat" and its traceback, from
    a worker the closing cut off before it could be quieted).
    """
    import logging
    import shutil
    import tempfile
    import weakref

    from distributed import LocalCluster

    try:
        from distributed.security import Security

        security = Security.temporary()
    except ImportError:
        raise StudyError("the local Dask cluster needs `cryptography` for its TLS certificates",
                         hint=f"{install_hint('dask')}, or use --executor local") from None
    swept_scratch(tempfile.gettempdir())
    scratch = tempfile.mkdtemp(prefix=SCRATCH_PREFIX)
    (Path(scratch) / OWNER).write_text(f"{os.getpid()}\n", encoding="ascii")
    try:
        with interrupts_ignored_by_children():
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None, host="127.0.0.1",
                                   scheduler_kwargs=QUIET_HTTP,
                                   security=security, local_directory=scratch,
                                   silence_logs=logging.CRITICAL)
    except BaseException:
        shutil.rmtree(scratch, ignore_errors=True)
        raise
    weakref.finalize(cluster, shutil.rmtree, scratch, True)
    return cluster


#: The name of a local cluster's scratch directory, and the file in it that names the
#: process that made it.
SCRATCH_PREFIX = "mitos-dask-"
OWNER = "owner.pid"


def swept_scratch(tmp: str) -> list[Path]:
    """Remove the scratch directories under ``tmp`` that local clusters of this user left
    behind a process that no longer runs (a study killed with ``kill -9``, which no clean-up
    of its own outlives: the reliability campaign's kill harness left thirteen); returns
    those removed. Only a real directory (not a link) of this user's with an owner file naming a
    process that is gone; one without that file (made before it was written) is left. Not on
    Windows, where ``os.kill(pid, 0)`` would end the process it asks about."""
    import shutil

    if os.name == "nt":
        return []
    swept = []
    for path in Path(tmp).glob(SCRATCH_PREFIX + "*"):
        try:
            info = path.lstat()
            if not stat.S_ISDIR(info.st_mode) or info.st_uid != os.getuid():
                continue
            pid = int((path / OWNER).read_text(encoding="ascii"))
        except (OSError, ValueError):
            continue
        if pid <= 0 or process_alive(pid):
            continue
        shutil.rmtree(path, ignore_errors=True)
        swept.append(path)
    return swept


@contextlib.contextmanager
def interrupts_ignored_by_children() -> Iterator[None]:
    """Start processes that ignore Ctrl-C, as the local pool's workers do (``ignore_interrupts``).

    Ctrl-C reaches the whole process group: a LocalCluster's worker processes, interrupted in
    the middle of a run, printed distributed's tracebacks of their broken connections under
    the "interrupted:" line. An ignored signal stays ignored across ``exec``, so the processes
    spawned while SIGINT is ignored here never see it and this process answers it alone (it
    closes the cluster). The price: a Ctrl-C during the cluster's start (a second or two) is
    lost, and the next one stops the study.
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield                          # (only the main thread may set a handler)
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def quiet_logs() -> None:
    """Run in each local worker, and in this process, before a study stopped early closes
    the cluster: the runs it cancels are expected, not the warnings distributed logs for
    each (a worker's, or this process's client's "Couldn't gather 1 keys")."""
    import logging

    logging.getLogger("distributed").setLevel(logging.ERROR)
    for name in ("asyncio", "tornado"):   # "Task exception was never retrieved" for the
        logging.getLogger(name).setLevel(logging.CRITICAL)      # comms the closing cuts


def run_dask(fn: TaskFn, tasks: Sequence[Task], workers: int, scheduler: str | None = None,
             client: Client | None = None) -> Iterator[tuple[Task, dict]]:
    """Run on Dask's distributed scheduler (``client`` given: use it and leave it open).

    The workers of a remote cluster must have ``mitos`` installed and see the world files at
    the paths given on the command line (a shared file system).
    """
    own, stopped = client is None, False
    if client is None:             # a LocalCluster of no more processes than tasks (-j 500)
        client = dask_client(scheduler, min(workers, max(1, len(tasks))))
    try:
        from distributed import as_completed

        n = len(client.scheduler_info().get("workers", {})) or workers
        # (a chunk's rows arrive together when it ends: four chunks a worker, so that they
        # arrive through the sweep and Ctrl-C drops less that was not yet written down)
        futures = client.map(functools.partial(chunk_list, fn),
                             _chunks_for(fn, tasks, 4 * n), pure=False)
        try:
            for _future, part in as_completed(futures, with_results=True):
                yield from part
        except BaseException:
            stopped = True
            if own and getattr(client, "cluster", None) is not None:
                client.run(quiet_logs)      # its closing now cancels runs, which they log,
                quiet_logs()                # as do the nannies and the client, in this process
            raise
        finally:
            client.cancel(futures)
    finally:
        if own:
            cluster = getattr(client, "cluster", None)
            client.close()
            if cluster is not None:
                if stopped:
                    stop_workers(cluster)
                cluster.close()


#: Seconds a LocalCluster's worker stopped early is given to end the chunk it is in before it
#: is killed (Dask's nanny gives it 4: a Ctrl-C took 1 to 4 s to end the command).
STOP_WAIT = 0.25


def stop_workers(cluster: LocalCluster, wait: float = STOP_WAIT) -> None:
    """Close the worker processes of ``cluster`` (a study stopped early: Ctrl-C, an error),
    each given ``wait`` seconds to end, then killed. Closing a cluster waits, worker by
    worker, for the task each is in (a chunk of runs, whose results nobody will read now)
    for up to 4 s (``Nanny.close``'s default timeout of 5 s, 0.8 of it for the task) before
    it kills it; ``Nanny.close(timeout=...)`` is the same closing, with a shorter wait, all
    at once."""
    import asyncio

    async def close_all() -> None:
        await asyncio.gather(*(worker.close(timeout=wait / 0.8)
                               for worker in list(cluster.workers.values())),
                             return_exceptions=True)

    cluster.sync(close_all)


def execute(fn: TaskFn, tasks: Sequence[Task], executor: str = "local",
            workers: int | None = None, scheduler: str | None = None,
            client: Client | None = None) -> Iterator[Part]:
    """``(task, result)`` pairs as the tasks finish, on the chosen executor, and where the
    runs of each chunk going are between them (:class:`Going`; not from Dask, whose chunks'
    results arrive when they end)."""
    if workers is None:     # as many as the memory holds with the tasks' worlds' batches
        from ..sim.runs import default_workers

        worlds = getattr(fn, "worlds", None)
        workers = default_workers(worlds(tasks) if worlds is not None else ())
    if not tasks:
        return iter(())
    if executor == "local":
        return run_local(fn, tasks, workers)
    if executor == "dask":
        return run_dask(fn, tasks, workers, scheduler, client)
    from ..errors import unknown

    raise unknown("executor", executor, EXECUTORS)
