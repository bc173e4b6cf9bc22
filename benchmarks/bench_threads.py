"""Two threads against one on the compiled backends (issue 11); prints figures, not a test.

    python benchmarks/bench_threads.py [--rounds 9] [--sizes 20000,200000] [--backends llvm,kernel]
                                       [--conditions quiet,busy] [--outputs fresh,out=]

Bendix wrist, random samples.  For each condition (``quiet``: the machine as it is;
``busy``: a process spinning on a core, another user's job), backend (``llvm``, the numba
``kernel``), size and output mode (``fresh``: new result arrays every call; ``out=``: the
previous call's result reused, :func:`gearcli.solve`'s ``out``), one call each with jobs
1, 2 and the default (every core) interleaved round by round (load drift hits all three),
medians of --rounds; the ratios are from the same rows; each row states the cores other
processes used while it ran (from /proc/stat: the busy process counts, ~1) and the load
average when it ended.  Issue 11 asks >= 1.8x with two threads, and the default within 10% of one
thread when the other core is busy.  Measure on a quiet machine (load average well below
the core count): on 2 shared cores, another job takes the second thread's core.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits
from timing import load_line  # noqa: E402 (benchmarks/timing.py)

from gearcli import analyse, load_mechanism, solve

MECHS = Path(__file__).resolve().parents[1] / "mechanisms"
BUSY = "import time\nwhile True:\n    sum(range(1000))\n"
"""A process keeping one core busy (another user's job)."""
JOBS = (1, 2, None)


def cpu_seconds() -> tuple:
    """(CPU seconds every process of the machine has used, this process's), to tell how
    many cores other jobs took meanwhile (Linux /proc/stat; the load average lags a minute)."""
    with open("/proc/stat") as f:
        fields = [int(x) for x in f.readline().split()[1:]]
    machine = (sum(fields) - fields[3] - fields[4]) / os.sysconf("SC_CLK_TCK")     # not idle, not iowait
    t = os.times()
    return machine, t.user + t.system


def interleaved(fns: dict, n: int, rounds: int) -> dict:
    """{label: median samples/s}, the calls interleaved round by round (two warm-ups), and
    "others": the cores other processes used meanwhile (mean)."""
    times = {k: [] for k in fns}
    for _ in range(2):
        for f in fns.values():
            f()                                   # compilation, caches, out='s work arrays
    (m0, s0), w0 = cpu_seconds(), time.perf_counter()
    for _ in range(rounds):
        for k, f in fns.items():
            t0 = time.perf_counter()
            f()
            times[k].append(time.perf_counter() - t0)
    (m1, s1), w1 = cpu_seconds(), time.perf_counter()
    return {**{k: n / float(np.median(v)) for k, v in times.items()}, "others": ((m1 - m0) - (s1 - s0)) / (w1 - w0)}


def calls(an, backend: str, n: int, reuse: bool) -> dict:
    """{jobs: a solve of n samples} (``reuse``: all write into the one previous result, as
    a streaming caller does)."""
    rng = np.random.default_rng(4)
    q, qd, qdd = (rng.uniform(-1.5, 1.5, size=(n, an.dof)) for _ in range(3))
    kept: list = [None]

    def one(j):
        if reuse:
            kept[0] = solve(an, q, qd, qdd, backend=backend, jobs=j, out=kept[0])
        else:
            solve(an, q, qd, qdd, backend=backend, jobs=j)
    return {j: (lambda j=j: one(j)) for j in JOBS}


def available(an, backends: list) -> list:
    """The backends of ``backends`` this gearcli can run on ``an``."""
    out = []
    for b in backends:
        try:
            solve(an, np.zeros((2, an.dof)), np.zeros((2, an.dof)), np.zeros((2, an.dof)), backend=b, jobs=1)
            out.append(b)
        except ValueError:
            pass
    return out


def fmt(r: float) -> str:
    return f"{r / 1e6:.2f}M" if r >= 1e6 else f"{r / 1e3:.0f}k"


def threads_table(sizes, rounds: int, backends=("llvm",), conditions=("quiet", "busy"),
                  outputs=("fresh", "out=")) -> None:
    """The table (markdown) of every condition, backend, size and output mode."""
    an = analyse(load_mechanism(MECHS / "bendix_wrist.yaml"))
    print(f"\n## Threads: Bendix wrist, jobs 1 / 2 / default interleaved, medians of {rounds} rounds "
          f"(samples/s)\n")
    print("| condition | backend | samples | outputs | jobs=1 | jobs=2 | default | 2 / 1 | default / 1 | "
          "other jobs' cores | load |\n|---|---|---|---|---|---|---|---|---|---|---|")
    for cond in conditions:
        busy = subprocess.Popen([sys.executable, "-c", BUSY]) if cond == "busy" else None
        try:
            for backend in available(an, list(backends)):
                for n in sizes:
                    for reuse in [o == "out=" for o in outputs]:
                        with threadpool_limits(limits=1, user_api="blas"):
                            r = interleaved(calls(an, backend, n, reuse), n, rounds)
                        print(f"| {cond} | {backend} | {n:,} | {'out=' if reuse else 'fresh'} | {fmt(r[1])} | "
                              f"{fmt(r[2])} | {fmt(r[None])} | {r[2] / r[1]:.2f}x | {r[None] / r[1]:.2f}x | "
                              f"{r['others']:.2f} | {load_line().removeprefix('load average ')} |", flush=True)
        finally:
            if busy is not None:
                busy.kill()
                busy.wait()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=9, help="interleaved rounds per row (median)")
    ap.add_argument("--sizes", default="20000,200000", help="comma list of sample counts")
    ap.add_argument("--backends", default="llvm,kernel", help="comma list: llvm, kernel")
    ap.add_argument("--conditions", default="quiet,busy", help="comma list: quiet, busy")
    ap.add_argument("--outputs", default="fresh,out=", help="comma list: fresh, out= (an older gearcli: fresh)")
    a = ap.parse_args()
    print(f"# gearcli threads, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; {load_line()} at start")
    threads_table([int(s) for s in a.sizes.split(",")], a.rounds, a.backends.split(","), a.conditions.split(","),
                  a.outputs.split(","))
    print("\n" + load_line() + " at end")


if __name__ == "__main__":
    main()
