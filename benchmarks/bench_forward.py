"""Speed of forward dynamics against inverse dynamics (prints figures; not a test).

    python benchmarks/bench_forward.py [--repeat 5] [--samples 20000] [--jobs 1]

For the Bendix wrist (bundled) and Panda (example-robot-data, if installed), in the same
run: samples/s of ``gearcli.solve`` (with fresh result arrays, and with ``out=`` reusing
them) and of ``gearcli.forward_dynamics`` on the same random states (--repeat interleaved
rounds after warm-up calls that compile the llvm solve and mass kernels,
:mod:`gearcli.dynamics.llvm.mass`; medians, and the median of the same-round ratios),
those ratios against the limit 1/(dof + 1) (what dof + 1 inverse-dynamics calls cost: the
issue 20 target is ratio >= limit), and ``mass_matrix`` alone.  Also the wall time of
``gearcli simulate`` of 2 s of the Bendix wrist with default tolerances (target < 5 s).
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from timing import load_line, median_time  # noqa: E402 (benchmarks/timing.py)

import gearcli
from gearcli.dynamics.forward import forward_dynamics, mass_matrix

ROOT = Path(__file__).resolve().parents[1]


def panda_path() -> Path | None:
    for p in map(Path, sys.path):
        d = p / "cmeel.prefix" / "share" / "example-robot-data" / "robots" / "panda_description" / "urdf" / "panda.urdf"
        if d.is_file():
            return d
    return None


def bench(name: str, path: Path, n: int, repeat: int, jobs: int | None) -> None:
    an = gearcli.analyse(gearcli.load_mechanism(path))
    rng = np.random.default_rng(0)
    q, qd = rng.uniform(-1, 1, (n, an.dof)), rng.uniform(-1, 1, (n, an.dof))
    T = rng.uniform(-1, 1, (n, len(an.mech.motors)))
    qdd = rng.uniform(-1, 1, (n, an.dof))
    gearcli.solve(an, q[:10], qd[:10], qdd[:10], jobs=jobs)        # compile / load the kernel
    out = gearcli.solve(an, q, qd, qdd, jobs=jobs)
    forward_dynamics(an, q, qd, T, jobs=jobs)                      # compile / load the mass kernel
    calls = {"solve": lambda: gearcli.solve(an, q, qd, qdd, jobs=jobs),
             "solve out=": lambda: gearcli.solve(an, q, qd, qdd, jobs=jobs, out=out),
             "forward": lambda: forward_dynamics(an, q, qd, T, jobs=jobs),
             "mass_matrix": lambda: mass_matrix(an, q, jobs=jobs)}
    times = {k: [] for k in calls}
    for _ in range(repeat):              # interleaved, so that a change of load hits all alike
        for k, fn in calls.items():
            times[k].append(median_time(fn, 1))
    t = {k: float(np.median(v)) for k, v in times.items()}
    limit = 1.0 / (an.dof + 1)
    print(f"{name} (dof {an.dof}), {n:,} samples, jobs {jobs or 'all'}, medians of {repeat} interleaved rounds:")
    print(f"  solve            {n / t['solve']:12,.0f} samples/s   (fresh result arrays, as a caller gets them)")
    print(f"  solve out=       {n / t['solve out=']:12,.0f} samples/s   (result arrays reused)")
    for label in ("solve", "solve out="):
        ratio = float(np.median(np.array(times[label]) / np.array(times["forward"])))   # same-round ratios
        print(f"  forward_dynamics {n / t['forward']:12,.0f} samples/s   against {label}: ratio {ratio:.3f}, limit "
              f"1/(dof+1) = {limit:.3f}: {ratio / limit:.0%} of the limit "
              f"({'meets' if ratio >= limit else 'misses'} the target)")
    print(f"  mass_matrix      {n / t['mass_matrix']:12,.0f} samples/s")


def bench_simulate() -> None:
    with tempfile.TemporaryDirectory() as d:
        inp = Path(d) / "torques.csv"
        t = np.linspace(0.0, 2.0, 201)
        cols = "t,motor:motor4,motor:motor5,motor:motor7"
        rows = np.column_stack([t, 0.02 * np.sin(3 * t), 0.01 * np.cos(2 * t), -0.015 * np.sin(t)])
        np.savetxt(inp, rows, delimiter=",", header=cols, comments="")
        cmd = [sys.executable, "-m", "gearcli.cli", "simulate", str(ROOT / "mechanisms" / "bendix_wrist.yaml"),
               str(inp), "-o", str(Path(d) / "traj.csv")]
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            print(f"gearcli simulate: exit {proc.returncode}: {proc.stderr.strip()[-300:]}")
            return
        print(f"gearcli simulate, 2 s of the Bendix wrist, default tolerances: {wall:.2f} s wall (target < 5 s; "
              f"new process, imports included)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--samples", type=int, default=20_000)
    ap.add_argument("--jobs", type=int, default=None)
    args = ap.parse_args()
    print(load_line())
    bench("bendix_wrist", ROOT / "mechanisms" / "bendix_wrist.yaml", args.samples, args.repeat, args.jobs)
    panda = panda_path()
    if panda is None:
        print("panda: example-robot-data not installed, skipped")
    else:
        bench("panda", panda, args.samples, args.repeat, args.jobs)
    bench_simulate()
    print(load_line(), "(at the end)")


if __name__ == "__main__":
    main()
