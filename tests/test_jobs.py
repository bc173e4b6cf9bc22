"""The persistent worker pool of the compiled backends (:func:`gearcli.dynamics.llvm.jobs.run_parts`)."""
from __future__ import annotations

import multiprocessing
import os
import threading
import time

import pytest

from gearcli.dynamics.llvm.jobs import job_ranges, run_parts


def _recording(log: list):
    def task(s, e):
        time.sleep(0.002)               # releases the GIL: the other threads take parts meanwhile
        log.append((s, e, threading.get_ident()))
        return e - s
    return task


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_every_part_once_and_the_sum(threads):
    log: list = []
    ranges = job_ranges(40_000, threads)
    assert run_parts(_recording(log), ranges, threads) == 40_000
    assert sorted((s, e) for s, e, _ in log) == ranges
    per_thread = {ident for _, _, ident in log}
    assert threading.get_ident() in per_thread                        # the caller works too
    if threads > 1:
        assert len(per_thread) > 1


def _workers() -> set:
    return {t.ident for t in threading.enumerate() if t.name.startswith("gearcli-jobs")}


def test_the_pool_threads_persist():
    run_parts(_recording([]), job_ranges(40_000, 2), 2)
    before = _workers()
    for _ in range(3):
        log: list = []
        run_parts(_recording(log), job_ranges(40_000, 2), 2)
        used = {ident for _, _, ident in log} - {threading.get_ident()}
        assert used and used <= before
    assert _workers() == before


def test_an_error_in_a_part_is_raised():
    def task(s, e):
        time.sleep(0.001)
        if s >= 20_000:
            raise RuntimeError(f"part {s}")
        return 1
    with pytest.raises(RuntimeError, match="part"):
        run_parts(task, job_ranges(40_000, 2), 2)
    assert run_parts(lambda s, e: 1, job_ranges(40_000, 2), 2) == len(job_ranges(40_000, 2))


def _threads_used(_=None) -> int:
    log: list = []
    run_parts(_recording(log), job_ranges(40_000, 2), 2)
    return len({ident for _, _, ident in log})


@pytest.mark.skipif(not hasattr(os, "fork"), reason="no fork here")
def test_a_forked_child_gets_its_own_workers():
    """The parent's pool threads do not exist in a forked child (a process pool): without a
    new pool there the caller would do every part alone."""
    assert _threads_used() == 2               # the parent's pool exists before the fork
    with multiprocessing.get_context("fork").Pool(1) as pool:
        assert pool.map(_threads_used, [0]) == [2]
