"""Speed and memory of gearcli's solver (prints figures; not a test).

    python benchmarks/bench_solve.py [--repeat 5] [--samples 100000] [--big 10000000]

Reports, as medians over --repeat runs, with the load average:
  * samples/s of the library solver core on the bundled paper_2dof and bendix_wrist
    mechanisms: the generated kernel (backend="llvm") with 1 and 2 jobs, the numpy block
    path, the full simultaneous solve, and the ratios kernel/numpy and 2 jobs/1 job;
  * with --first-call: the kernel's first call in a fresh process, compiling (an empty
    GEARCLI_CACHE_DIR) and then loading the machine code from that disk cache;
  * wall time of the whole `gearcli solve` command (CSV in and out) on --samples samples of
    paper_2dof;
  * with --big N: peak resident memory of `gearcli solve` on N samples (output discarded).
Aims on a 2-core machine: >= 300,000 samples/s (paper_2dof) and >= 100,000 samples/s
(Bendix) in the library (numpy path); issue 11: the kernel on Bendix at Pinocchio's
rneaInParallel figure on one core (1.24M samples/s on a quiet machine; side by side in
benchmarks/bench_speed.py) and >= 1.8x that with two jobs; `gearcli solve` on 100,000 samples in < 5 s; 10 million samples in
< 1 GB.
"""
from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from timing import load_line, median_time  # noqa: E402 (benchmarks/timing.py)

from gearcli import solve
from gearcli import analyse
from gearcli import load_mechanism
from gearcli.io.trajectory import write_trajectory

ROOT = Path(__file__).resolve().parents[1]


def median_rate(fn, n, repeat):
    """(samples/s, median s) of ``repeat`` calls of ``fn()`` on ``n`` samples."""
    t = median_time(fn, repeat)
    return n / t, t




def core(repeat: int, n: int) -> None:
    """samples/s of the compiled kernel and the numpy path, one and two jobs, same run."""
    print(f"library solver core, {n} random samples, median of {repeat}; {load_line()}")
    cols = ("llvm j1", "llvm j2", "numpy", "full", "llvm/numpy", "j2/j1")
    print(f"{'mechanism':<16}" + "".join(f"{c:>14}" for c in cols))
    for name in ("paper_2dof", "bendix_wrist"):
        an = analyse(load_mechanism(ROOT / "mechanisms" / f"{name}.yaml"))
        rng = np.random.default_rng(0)
        q, qd, qdd = (rng.normal(size=(n, an.dof)) for _ in range(3))
        solve(an, q[:100], qd[:100], qdd[:100], backend="llvm")    # compiled (or cached) once
        k1, _ = median_rate(lambda: solve(an, q, qd, qdd, backend="llvm", jobs=1), n, repeat)
        k2, _ = median_rate(lambda: solve(an, q, qd, qdd, backend="llvm", jobs=2), n, repeat)
        rb, _ = median_rate(lambda: solve(an, q, qd, qdd, backend="numpy"), n, repeat)
        m = max(n // 10, 1000)
        rf, _ = median_rate(lambda: solve(an, q[:m], qd[:m], qdd[:m], method="full"), m, repeat)
        figs = (f"{k1:,.0f}", f"{k2:,.0f}", f"{rb:,.0f}", f"{rf:,.0f}", f"{k1 / rb:.1f}x", f"{k2 / k1:.2f}x")
        print(f"{name:<16}" + "".join(f"{c:>14}" for c in figs))
    print(f"({load_line()} at the end)")


def first_calls() -> None:
    """Cost of the kernel's first call in a fresh process: compiled, then from the disk cache."""
    code = ("import time, numpy as np; from pathlib import Path; from gearcli import analyse, load_mechanism, solve; "
            f"an = analyse(load_mechanism(Path({str(ROOT / 'mechanisms' / 'bendix_wrist.yaml')!r}))); "
            "q = np.zeros((10, an.dof)); t = time.process_time(); w = time.perf_counter(); "
            "solve(an, q, q, q, backend='llvm', jobs=1); "
            "print(f'{time.perf_counter() - w:.2f} s wall, {time.process_time() - t:.2f} s CPU')")
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, GEARCLI_CACHE_DIR=d)    # an empty cache: the first run compiles
        for what in ("first call, compiling", "first call of a new process, from the disk cache"):
            out = subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True, text=True)
            print(f"kernel {what}: {out.stdout.strip()}")


def trajectory_file(path: Path, n: int) -> None:
    t = np.arange(n) * 1e-3
    q = np.column_stack([1.2 * np.sin(np.pi * t), 0.9 * np.sin(1.5 * np.pi * t + 0.4)])
    write_trajectory(path, ["J1", "J2"], t, q)


def command(repeat: int, n: int) -> None:
    with tempfile.TemporaryDirectory() as d:
        traj = Path(d) / "traj.csv"
        trajectory_file(traj, n)
        out = Path(d) / "out.csv"
        cmd = ["gearcli", "solve", str(ROOT / "mechanisms" / "paper_2dof.yaml"), str(traj), "-o", str(out)]
        ts = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
            ts.append(time.perf_counter() - t0)
        size = out.stat().st_size / 1e6
    print(f"`gearcli solve` paper_2dof, {n} samples (CSV in, {size:.0f} MB CSV out): "
          f"median {np.median(ts):.2f} s over {repeat} runs ({n / np.median(ts):,.0f} samples/s)")


def big(n: int) -> None:
    with tempfile.TemporaryDirectory() as d:
        traj = Path(d) / "traj.csv"
        t0 = time.perf_counter()
        with open(traj, "w") as f:
            f.write("t,q:J1,q:J2\n")
            step = 1_000_000
            for s in range(0, n, step):
                t = np.arange(s, min(n, s + step)) * 1e-3
                q = np.column_stack([t, 1.2 * np.sin(np.pi * t), 0.9 * np.sin(1.5 * np.pi * t)])
                np.savetxt(f, q, delimiter=",", fmt="%.10g")
        print(f"wrote {n:,} samples in {time.perf_counter() - t0:.0f} s")
        cmd = ["gearcli", "solve", str(ROOT / "mechanisms" / "paper_2dof.yaml"), str(traj), "-o", "-"]
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        wall = time.perf_counter() - t0
        rss = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(f"`gearcli solve -o -` on {n:,} samples: {wall:.0f} s, peak RSS {rss:.0f} MB")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--samples", type=int, default=100_000)
    ap.add_argument("--big", type=int, default=0, help="also measure memory on this many samples")
    ap.add_argument("--first-call", action="store_true", help="also time the kernel's first call "
                    "(compiling, then from the disk cache; about a minute)")
    a = ap.parse_args()
    print(f"python {sys.version.split()[0]}, numpy {np.__version__}, {os.cpu_count()} cpus")
    core(a.repeat, a.samples)
    if a.first_call:
        first_calls()
    command(a.repeat, a.samples)
    if a.big:
        big(a.big)


if __name__ == "__main__":
    main()
