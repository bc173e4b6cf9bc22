"""Splitting a trajectory over threads, and the sign error of a compiled solve.

Used by the generated kernel's driver (:mod:`.driver`): the samples
are split into contiguous ranges that the threads take in turn (:func:`run_parts`: the
calling thread and workers of a persistent pool, created on first use, so that a call pays
no thread creation); a compiled kernel releases the GIL and each sample's arithmetic does
not depend on the split, so the results are bitwise identical for any number of jobs.
"""
from __future__ import annotations

import itertools
import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..signs import SignError

MIN_SAMPLES_PER_JOB = 2_000   # fewer samples per thread: the thread costs more than it saves
MIN_SAMPLES_PER_PART = 500    # smaller parts gain nothing (measured: 250, 500, 2000 samples)


def usable_cores() -> int:
    """Cores this process may run on (its CPU affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:               # not on Linux
        return max(1, os.cpu_count() or 1)


def threads_for(n: int, jobs: int | None) -> int:
    """Threads for n samples (``jobs`` None: every usable core; at least
    MIN_SAMPLES_PER_JOB samples a thread)."""
    jobs = usable_cores() if jobs is None else int(jobs)
    if jobs < 1:
        raise ValueError(f"jobs must be at least 1, got {jobs}")
    return max(1, min(jobs, n // MIN_SAMPLES_PER_JOB))


def job_ranges(n: int, jobs: int | None) -> list[tuple[int, int]]:
    """Contiguous (start, stop) sample ranges the threads take in turn: 8 a thread (at
    least MIN_SAMPLES_PER_PART samples each), so that a thread slowed by a busy core, or
    woken late, takes fewer of them instead of making the others wait (``jobs`` None:
    every core)."""
    threads = threads_for(n, jobs)
    if threads == 1:
        return [(0, n)]
    parts = max(threads, min(8 * threads, n // MIN_SAMPLES_PER_PART))
    cuts = [round(i * n / parts) for i in range(parts + 1)]
    return [(cuts[i], cuts[i + 1]) for i in range(parts)]


_POOL: ThreadPoolExecutor | None = None
_POOL_LOCK = threading.Lock()


def _pool(workers: int) -> ThreadPoolExecutor:
    """The persistent worker pool, with room for at least ``workers`` threads (one fewer
    than the cores unless more are asked for: the calling thread works too).  Its threads
    start on first use and then wait for work (daemon-like: they exit with the process)."""
    global _POOL
    with _POOL_LOCK:
        if _POOL is None or _POOL._max_workers < workers:
            old = _POOL
            _POOL = ThreadPoolExecutor(max(workers, usable_cores() - 1), thread_name_prefix="gearcli-jobs")
            if old is not None:
                old.shutdown(wait=False)
        return _POOL


def _forget_pool() -> None:
    """In a forked child: the parent's pool threads do not exist there; start a new pool."""
    global _POOL, _POOL_LOCK
    _POOL, _POOL_LOCK = None, threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool)


def run_parts(task, ranges: list, threads: int) -> int:
    """Run ``task(start, stop)`` over every range on ``threads`` threads; the sum of what
    the calls return.

    The calling thread and ``threads - 1`` workers of the persistent pool take the next
    range not yet taken until none is left (a thread slowed by a busy core takes fewer).
    ``task`` must release the GIL for the threads to run in parallel (a compiled kernel does).
    """
    if threads <= 1 or len(ranges) == 1:
        return sum(task(s, e) for s, e in ranges)
    taken = itertools.count()            # next() on it is atomic (the GIL)

    def take() -> int:
        total = 0
        for i in taken:
            if i >= len(ranges):
                return total
            total += task(*ranges[i])

    pool = _pool(threads - 1)
    futures = [pool.submit(take) for _ in range(threads - 1)]
    try:
        total = take()
    finally:       # a worker not started yet finds nothing left; wait for the running ones
        running = [f for f in futures if not f.cancel()]
        for f in running:
            f.exception()
    return total + sum(f.result() for f in running)


def sign_error(names: list, fail: np.ndarray, chunk: int) -> SignError:
    """The error the numpy path raises, from ``fail`` (N,) (the first failing block of each
    sample, -1 if none; ``names`` the signed meshes of each block): in the first chunk
    with a failure, the first sample failing at the earliest block that fails (that path
    stops at that block)."""
    first = int(np.flatnonzero(fail >= 0)[0])
    c0 = first - first % chunk
    part = fail[c0:c0 + chunk]
    block = int(part[part >= 0].min())
    return SignError(c0 + int(np.flatnonzero(part == block)[0]), names[block])
