"""Speed and memory of gearcli's solver (prints figures; not a test).

    python benchmarks/bench_solve.py [--repeat 5] [--samples 100000] [--big 10000000]

Reports, as medians over --repeat runs:
  * samples/s of the library solver core (block schedule and full simultaneous solve, and
    their ratio) on the bundled paper_2dof and bendix_wrist mechanisms;
  * wall time of the whole `gearcli solve` command (CSV in and out) on --samples samples of
    paper_2dof;
  * with --big N: peak resident memory of `gearcli solve` on N samples (output discarded).
Aims on a 2-core machine: >= 300,000 samples/s (paper_2dof) and >= 100,000 samples/s
(Bendix) in the library; `gearcli solve` on 100,000 samples in < 5 s; 10 million samples in
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

from gearcli import solve
from gearcli import analyse
from gearcli import load_mechanism
from gearcli.io.trajectory import write_trajectory

ROOT = Path(__file__).resolve().parents[1]


def median_rate(fn, n, repeat):
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return n / float(np.median(ts)), float(np.median(ts))


def core(repeat: int, n: int) -> None:
    print(f"library solver core, {n} random samples, median of {repeat}")
    print(f"{'mechanism':<16}{'block /s':>14}{'full /s':>14}{'block/full':>12}")
    for name in ("paper_2dof", "bendix_wrist"):
        an = analyse(load_mechanism(ROOT / "mechanisms" / f"{name}.yaml"))
        rng = np.random.default_rng(0)
        q, qd, qdd = (rng.normal(size=(n, an.dof)) for _ in range(3))
        solve(an, q[:100], qd[:100], qdd[:100])
        rb, _ = median_rate(lambda: solve(an, q, qd, qdd), n, repeat)
        m = max(n // 10, 1000)
        rf, _ = median_rate(lambda: solve(an, q[:m], qd[:m], qdd[:m], method="full"), m, repeat)
        print(f"{name:<16}{rb:>14,.0f}{rf:>14,.0f}{rb / rf:>12.1f}")


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
    a = ap.parse_args()
    print(f"python {sys.version.split()[0]}, numpy {np.__version__}, {os.cpu_count()} cpus")
    core(a.repeat, a.samples)
    command(a.repeat, a.samples)
    if a.big:
        big(a.big)


if __name__ == "__main__":
    main()
