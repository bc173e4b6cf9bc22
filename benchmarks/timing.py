"""Timing helpers shared by the benchmark scripts (medians and the load average)."""
from __future__ import annotations

import os
import time

import numpy as np


def median_time(fn, repeat: int) -> float:
    """Median wall time of ``repeat`` calls of ``fn()``, s."""
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts))


def load_line() -> str:
    """The load average (1, 5, 15 min) and the core count, for the printed figures."""
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f} ({os.cpu_count()} cpus)"
