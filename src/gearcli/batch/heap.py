"""Keep freed memory in the process while verify runs (glibc's malloc).

verify's checks make and drop many arrays of one trajectory's length (20,000 samples:
160 kB each).  glibc serves a block of 128 kB or more by ``mmap`` and returns it to the
system when freed, unless a larger block freed before raised its dynamic threshold (the
full output table verify built before it read columns lazily did so, by chance); every
page of every such array is then faulted in afresh (measured without that table: 46,000 to
70,000 page faults a run of ``benchmarks/bench_verify.py``, about half its wall time).  :func:`keep_freed_memory` sets
the thresholds once per process with ``mallopt`` (``M_MMAP_THRESHOLD`` 32 MiB, glibc's
largest dynamic value, and ``M_TRIM_THRESHOLD`` 256 MiB): blocks below 32 MiB come from the
heap and freed memory stays for the next array.  Larger arrays still use ``mmap``.  A
no-op where the C library is not glibc.
"""
from __future__ import annotations

import ctypes
import ctypes.util

M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3
MMAP_THRESHOLD = 32 << 20      # bytes
TRIM_THRESHOLD = 256 << 20     # bytes

_done = False


def keep_freed_memory() -> bool:
    """Set glibc's mmap and trim thresholds (module notes), once; True when they are set."""
    global _done
    if _done:
        return True
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):     # not glibc (macOS, Windows, musl without mallopt)
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    _done = bool(mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD)) and bool(mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD))
    return _done
