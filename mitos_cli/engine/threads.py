"""Large batches spread over the machine's cores.

A sample's outputs come from its own inputs alone, by operations in an order fixed per sample
(:mod:`mitos_cli.engine.evaluation`), so which thread evaluates which block changes no bit.
NumPy releases the GIL inside each call on a block, so the threads run at once, as the BLAS
product of a hand-written kernel does. Blocks are handed out one at a time to whichever thread
is free (a core another process is using gets fewer), and a batch of one block stays in the
caller's thread: the simulator's ticks and one evaluation never see a thread.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable, Iterable, Iterator
from typing import TYPE_CHECKING, TypeVar

from ..errors import InputError
from ..machine import allowed_cpus

if TYPE_CHECKING:           # imported when a batch first needs a thread (10 ms, with logging)
    from concurrent.futures import ThreadPoolExecutor

#: The environment variable that sets the threads (``1``: every batch in the caller's thread).
ENV = "MITOS_NUM_THREADS"

#: Threads at most when :data:`ENV` is not set: each thread holds one block's buffers (about
#: 8 MB for the paper's 27 rules), and with more than four a batch of 10^6 rows would take
#: more memory than the hand-written kernel it is measured against.
DEFAULT_MAX = 4

#: Threads at most when :data:`ENV` sets them (each holds a block's buffers).
MAX = 256

T = TypeVar("T")
Blocks = Iterable[tuple[int, int]]

_lock = threading.Lock()
_pool: tuple[int, int, ThreadPoolExecutor] | None = None     # (pid, threads, pool)


def thread_count() -> int:
    """The threads a large batch may use: :data:`ENV` if set, else the CPUs this process may
    run on, at most :data:`DEFAULT_MAX`."""
    number = given()
    if number is not None:
        return number
    return min(allowed_cpus(), DEFAULT_MAX)


def given() -> int | None:
    """:data:`ENV`'s number, None when it is not set (the CLI checks it on start-up, so that
    a wrong value is refused whatever the batch's size)."""
    text = os.environ.get(ENV, "").strip()
    if not text:
        return None
    digits = text.lstrip("0")       # int() raises past 4,300 digits: count them first
    if not (text.isascii() and text.isdecimal() and len(digits) <= len(str(MAX))
            and 1 <= int(digits or "0") <= MAX):
        raise InputError(f"{ENV} is `{text}`, not a number of threads",
                         expected=f"a whole number from 1 to {MAX}",
                         hint=f"unset {ENV} to use the CPUs this process may run on "
                              f"(at most {DEFAULT_MAX}), or set it to 1 for one thread")
    return int(digits)


def map_blocks(work: Callable[[Blocks], T], n: int, width: int) -> list[T]:
    """``work(blocks)`` in as many threads as there are blocks of ``width`` samples in ``n``
    (at most :func:`thread_count`), each taking ``(start, end)`` ranges from one shared queue
    in order; the threads' results, the caller's first.

    An error is raised as one thread would raise it: the one from the earliest block (every
    block before it was taken, and finished, before it), so a message names the same sample
    however the blocks fell. Ctrl-C in the caller stops the handing out of blocks."""
    count = -(-n // width) if width > 0 else 0
    threads = min(thread_count(), count) if count > 1 else 1
    if threads == 1:
        return [work((s, min(s + width, n)) for s in range(0, n, width))]
    queue = _Queue(n, width)
    pool = _executor(threads - 1)
    futures = [pool.submit(_attempt, work, queue) for _ in range(threads - 1)]
    try:
        results = [_attempt(work, queue)]
    finally:
        queue.stop()                           # a no-op unless the caller was interrupted
    results += [f.result() for f in futures]
    done = [r for r in results if not isinstance(r, _Failed)]
    if len(done) < len(results):
        failed = [r for r in results if isinstance(r, _Failed)]
        raise min(failed, key=lambda f: f.start).error
    return done


class _Failed:
    """An error a thread raised, and the block it was evaluating (a plain class: a dataclass
    would add 2 ms to every command's start-up)."""

    __slots__ = ("start", "error")

    def __init__(self, start: int, error: Exception) -> None:
        self.start, self.error = start, error


class _Queue:
    """Block ranges in order, to whichever thread asks next; remembers each thread's last."""

    def __init__(self, n: int, width: int) -> None:
        self._starts = iter(range(0, n, width))
        self._n, self._width = n, width
        self._lock = threading.Lock()
        self._mine = threading.local()

    def __iter__(self) -> Iterator[tuple[int, int]]:
        while True:
            with self._lock:
                start = next(self._starts, None)
            if start is None:
                return
            self._mine.start = start
            yield start, min(start + self._width, self._n)

    def current(self) -> int:
        return getattr(self._mine, "start", -1)

    def stop(self) -> None:
        with self._lock:
            self._starts = iter(())


def _attempt(work: Callable[[Blocks], T], queue: _Queue) -> T | _Failed:
    try:
        return work(queue)
    except Exception as exc:                   # raised by map_blocks, in block order
        return _Failed(queue.current(), exc)


def _executor(threads: int) -> ThreadPoolExecutor:
    """The process's pool, made on first use with at least ``threads`` threads (and again in a
    forked child, whose copy of the parent's pool has no threads behind it). A pool that grows
    is replaced, not shut down: a batch in another thread may be submitting to it, and its
    threads end when it is no longer referenced."""
    from concurrent.futures import ThreadPoolExecutor

    global _pool
    with _lock:
        pid = os.getpid()
        if _pool is None or _pool[0] != pid or _pool[1] < threads:
            _pool = (pid, threads, ThreadPoolExecutor(threads, thread_name_prefix="mitos-batch"))
        return _pool[2]


def _forget_pool() -> None:
    global _lock, _pool
    _lock, _pool = threading.Lock(), None      # a lock held by a thread the child lacks


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool)
