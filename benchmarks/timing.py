"""Timing helpers shared by the benchmark scripts (medians and the load average)."""
from __future__ import annotations

import os
import time

import numpy as np


def median_time(fn, repeat: int, clock=time.perf_counter) -> float:
    """Median time of ``repeat`` calls of ``fn()``, s: wall time, or ``clock``'s
    (time.thread_time: this thread's CPU time, which leaves out the other processes' turns
    on a shared machine; only for work done in the calling thread)."""
    ts = []
    for _ in range(repeat):
        t0 = clock()
        fn()
        ts.append(clock() - t0)
    return float(np.median(ts))


def load_line() -> str:
    """The load average (1, 5, 15 min) and the core count, for the printed figures."""
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f} ({os.cpu_count()} cpus)"
