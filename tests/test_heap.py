"""verify keeps freed memory in the process (batch.heap): new arrays of a trajectory's
length reuse it instead of faulting fresh pages in."""
import subprocess
import sys

import pytest

PROBE = """
import resource, sys
import numpy as np
if sys.argv[1] == "keep":
    from gearcli.batch.heap import keep_freed_memory
    assert keep_freed_memory() is True and keep_freed_memory() is True   # idempotent
x = np.random.default_rng(0).random(20_000)
def checks():            # like a trajectory's checks: several 160 kB arrays alive, then freed
    ys = [np.hypot(x, x) * 2.0 for _ in range(10)]
    return sum(float(y[0]) for y in ys)
for _ in range(5):
    checks()
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(40):
    checks()
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def _faults(mode: str) -> int:
    out = subprocess.run([sys.executable, "-c", PROBE, mode], capture_output=True, text=True, check=True)
    return int(out.stdout)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_arrays_of_a_trajectory_reuse_freed_memory_without_page_faults():
    # 40 rounds x 10 arrays of 160 kB: glibc alone maps and faults them in afresh (~12,800
    # pages here); with keep_freed_memory the freed heap serves them
    assert _faults("keep") < 100
    assert _faults("default") > 1000       # the probe does show the problem without it
