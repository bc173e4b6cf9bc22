"""Speed of the layouts the compiled kernels used to leave to numpy (issue 18); prints figures.

    python benchmarks/bench_coverage.py [--repeat 5] [--samples 20000]

In one run, one thread, all loads, medians over --repeat, the load average stated at the
start and the end: samples/s of the generated llvm kernel and of the numpy path on the
Bendix wrist (the reference), planetary_3p, planetary_5p (one block with 1,024 sign
patterns: pattern_maps.LowRank) and servo_joint (a helical stage into a 3-planet planetary
whose sun turns: a redundant world-frame block, the KKT system a sample) and planetary_5p
with 9 planets (18 signed meshes: only the own-sign trials, numpy's rule above
signs.MAX_EXHAUSTIVE; numpy before, a file written to a temporary folder), each as a ratio
to the Bendix's llvm figure of the same run; and each kernel's cold compile (an empty
GEARCLI_CACHE_DIR, in a fresh process) and cached first call.  Before issue 18, "auto"
took numpy for planetary_5p and servo_joint: their numpy column is the "before".
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from timing import load_line, median_time  # noqa: E402 (benchmarks/timing.py)

from gearcli import analyse, load_mechanism, solve

ROOT = Path(__file__).resolve().parents[1]
NAMES = ("bendix_wrist", "planetary_3p", "planetary_5p", "servo_joint", "planetary_9p")
FIRST = ("import time, sys, numpy as np; t0 = time.perf_counter(); "
         "from gearcli import analyse, load_mechanism, solve; an = analyse(load_mechanism(sys.argv[1])); "
         "q = np.zeros((10, an.dof)); t1 = time.perf_counter(); solve(an, q, q, q, backend='llvm'); "
         "print(f'{time.perf_counter() - t1:.2f}')")


def motion(an, n):
    rng = np.random.default_rng(0)
    return rng.uniform(-np.pi, np.pi, (n, an.dof)), rng.normal(size=(n, an.dof)) * 3, rng.normal(size=(n, an.dof)) * 20


def first_call(path: Path, cache: str) -> str:
    env = dict(os.environ, GEARCLI_CACHE_DIR=cache, PYTHONPATH=str(ROOT / "src"))
    out = subprocess.run([sys.executable, "-c", FIRST, str(path)], capture_output=True, text=True, env=env, check=True)
    return out.stdout.strip()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--samples", type=int, default=20_000)
    a = ap.parse_args()
    n = a.samples
    print(f"one thread, {n} random samples, medians of {a.repeat}; {load_line()}")
    rows, ref = [], None
    tmp = tempfile.TemporaryDirectory()
    nine = Path(tmp.name) / "planetary_9p.yaml"
    nine.write_text((ROOT / "mechanisms" / "planetary_5p.yaml").read_text().replace("planets: 5", "planets: 9"))
    for name in NAMES:
        path = nine if name == "planetary_9p" else ROOT / "mechanisms" / f"{name}.yaml"
        with tempfile.TemporaryDirectory() as cache:
            cold, cached = first_call(path, cache), first_call(path, cache)
        an = analyse(load_mechanism(path))
        q, qd, qdd = motion(an, n)
        solve(an, q[:10], qd[:10], qdd[:10], backend="llvm")
        llvm = n / median_time(lambda: solve(an, q, qd, qdd, backend="llvm", jobs=1), a.repeat)
        m = max(n // 10, 500)
        numpy = m / median_time(lambda: solve(an, q[:m], qd[:m], qdd[:m], backend="numpy"), a.repeat)
        ref = ref or llvm
        rows.append((name, llvm, numpy, llvm / ref, llvm / numpy, cold, cached))
    print("\n| mechanism | llvm samples/s | numpy samples/s | llvm / Bendix llvm | llvm / numpy | cold compile s | cached s |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name, llvm, numpy, rb, rn, cold, cached in rows:
        print(f"| {name} | {llvm:,.0f} | {numpy:,.0f} | {rb:.3f} | {rn:.1f}x | {cold} | {cached} |")
    print(f"\n({load_line()} at the end)")


if __name__ == "__main__":
    main()
