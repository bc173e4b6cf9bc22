"""Wall time of `gearcli verify` run serially, in processes and on Dask (prints figures; not a test).

    python benchmarks/bench_verify.py [--trajectories 8] [--samples 20000] [--repeat 3] [--serial]

Builds a manifest over the rated Bendix wrist with --trajectories trajectory files of
--samples samples each (a 1 Hz / 0.7 Hz / 1.3 Hz multi-sine) and every check switched on
(bearing lives with the ISO 281 table, static safeties, tooth stresses, gear fatigue by
rainflow + Miner), then reports the median wall time over --repeat runs of: the library's
``solve`` alone on the same samples (the floor), -j 1 (this process, end to end: manifest,
CSV reading, splines, solve, checks, JSON), -j 2 (process pool) and a Dask LocalCluster
with 2 worker processes (cluster start-up excluded), their rates, and that the three JSON
reports are identical (--serial: the library and -j 1 only).  The load average is printed
with the figures: the machine is shared, so compare the ratios rather than single numbers.

-j 1 is also broken down into its stages (medians over the repeats): the manifest (schema,
analysis, checks built, every trajectory's rows read and checked), the jobs' reading (the
spline of the rates; the rows are the manifest's), the solve inside verify (with the
solver path that ran), the checks, and the rest (reports, merging).  --cli adds `gearcli
verify -j 1` as a user runs it, in a fresh process each time (imports, the mechanism's
analysis and its compiled kernel from the disk cache included).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from gearcli.batch.verify import run_verify
from gearcli.io.trajectory import write_trajectory

ROOT = Path(__file__).resolve().parents[1]


def make_manifest(d: Path, n_traj: int, n: int) -> Path:
    t = np.linspace(0, n / 1000, n)
    for k in range(n_traj):
        a = 1 + 0.1 * k
        q = np.column_stack([a * np.sin(2 * np.pi * t), 0.5 * np.sin(2 * np.pi * 0.7 * t),
                             0.8 * np.cos(2 * np.pi * 1.3 * t)])
        write_trajectory(d / f"traj_{k:02d}.csv", ["J1", "J2", "J3"], t, q)
    man = d / "design.yaml"
    man.write_text(f"cases:\n  - name: wrist\n    mechanism: {ROOT / 'mechanisms' / 'bendix_wrist_rated.yaml'}\n"
                   "    trajectories: traj_*.csv\n    cycles_per_hour: 60\n    bearing_life_h: 20000\n"
                   "    gear_life_h: 20000\n")
    return man


def library_solve(d: Path, repeat: int) -> float:
    """Median time of the library's solve over the trajectories' samples (arrays in memory)."""
    from gearcli import analyse, load_mechanism, solve
    from gearcli.io.trajectory import read_trajectory

    an = analyse(load_mechanism(ROOT / "mechanisms" / "bendix_wrist_rated.yaml"))
    trs = [read_trajectory(p, an.independent_names) for p in sorted(d.glob("traj_*.csv"))]
    # warm as verify is warmed (one untimed run): the kernel, and the memory the results take
    for tr in trs:
        solve(an, tr.q, tr.qd, tr.qdd, jobs=1)
    return timed(lambda: [solve(an, tr.q, tr.qd, tr.qdd, jobs=1) for tr in trs], repeat)[0]


STAGES = (("manifest", "gearcli.batch.verify", "load_manifest"), ("reading + spline", "gearcli.batch.runner", "read_trajectory"),
          ("solve", "gearcli.batch.runner", "solve"), ("checks", "gearcli.batch.runner", "partials"))


@contextmanager
def stage_clock():
    """Time the stages of run_verify (wall time summed per stage; module functions wrapped)."""
    import importlib

    spent: dict = defaultdict(float)
    saved = []
    for label, module, name in STAGES:
        mod = importlib.import_module(module)
        fn = getattr(mod, name)
        saved.append((mod, name, fn))

        def wrapped(*a, _fn=fn, _label=label, **k):
            t0 = time.perf_counter()
            try:
                return _fn(*a, **k)
            finally:
                spent[_label] += time.perf_counter() - t0
        setattr(mod, name, wrapped)
    try:
        yield spent
    finally:
        for mod, name, fn in saved:
            setattr(mod, name, fn)


def cli_runs(man: Path, out: Path, repeat: int) -> float:
    """Median wall time of `gearcli verify -j 1` in a fresh process (a warm-up run first)."""
    cmd = [sys.executable, "-c", "from gearcli.cli import app; app()", "verify", str(man), "--json", str(out), "-j", "1"]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    subprocess.run(cmd, env=env, capture_output=True)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run(cmd, env=env, capture_output=True)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def timed(fn, repeat: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--trajectories", type=int, default=8)
    ap.add_argument("--samples", type=int, default=20_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--serial", action="store_true", help="the library solve and -j 1 only")
    ap.add_argument("--cli", action="store_true", help="also `gearcli verify -j 1` in fresh processes")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        man = make_manifest(d, args.trajectories, args.samples)

        def run(name, **kw):
            out = d / f"{name}.json"
            run_verify(man, json_path=out, **kw)
            return json.loads(out.read_text())

        lib_t = library_solve(d, args.repeat)
        run("serial", jobs=1)                  # warm: this process's analysis and kernel
        stages = []

        def staged():
            with stage_clock() as spent:
                out = run("serial", jobs=1)
            stages.append(dict(spent))
            return out
        serial_t, serial = timed(staged, args.repeat)
        cli_t = cli_runs(man, d / "cli.json", args.repeat) if args.cli else None
        if not args.serial:
            pool_t, pool = timed(lambda: run("pool", jobs=2), args.repeat)
            from dask.distributed import LocalCluster

            with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
                dask_t, dask = timed(lambda: run("dask", dask_address=cl.scheduler_address), args.repeat)
    total = args.trajectories * args.samples
    print(f"gearcli verify: {args.trajectories} trajectories x {args.samples:,} samples "
          f"({len(serial['checks'])} checks), medians of {args.repeat}; load average {os.getloadavg()[0]:.2f}")
    print(f"  library solve       {lib_t:7.2f} s  {total / lib_t:10,.0f} samples/s  (solve() on the same samples)")
    print(f"  -j 1 (serial)       {serial_t:7.2f} s  {total / serial_t:10,.0f} samples/s  "
          f"(end to end; {100 * (1 - lib_t / serial_t):.0f} % outside the solver)")
    med = {label: statistics.median(st.get(label, 0.0) for st in stages) for label, _, _ in STAGES}
    med["reports, merging, rest"] = max(serial_t - sum(med.values()), 0.0)
    backend = sorted({c["backend"] for c in serial["checks"]})
    for label, v in med.items():
        note = f"  (solver path: {', '.join(backend)})" if label == "solve" else ""
        print(f"      {label:22s} {v:6.3f} s  {100 * v / serial_t:4.0f} %{note}")
    if cli_t is not None:
        print(f"  gearcli verify -j 1 {cli_t:7.2f} s  {total / cli_t:10,.0f} samples/s  "
              "(a fresh process each run: imports, analysis, kernel from the disk cache)")
    if args.serial:
        return
    print(f"  -j 2 (processes)    {pool_t:7.2f} s  {total / pool_t:10,.0f} samples/s  speed-up {serial_t / pool_t:.2f}x")
    print(f"  --dask (2 workers)  {dask_t:7.2f} s  {total / dask_t:10,.0f} samples/s  speed-up {serial_t / dask_t:.2f}x")
    print(f"  identical reports: {serial == pool == dask}")


if __name__ == "__main__":
    main()
