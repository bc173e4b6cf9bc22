"""Speed of gearcli sweep (issue 37's target: 1,000 mass/inertia/ratio/payload variants of the
rated Bendix wrist over a 10,000-sample duty cycle, every check, at >= 50 variants/s with one
compile in all); prints figures, not a test.

    python benchmarks/bench_sweep.py [--variants 200] [--rounds 3] [--points 1] [--jobs 1] [--dask-workers 0]

The duty cycle is the bundled Bendix motion resampled to 10,000 samples (a temporary file),
verified with designs/ci_example.yaml's checks; the variants vary the tool flange's mass, its
inertia about its axis, the mass of a tool (a load) on it and the ratio of the pinion pair
4-1 (``--ratios`` values from -2.5 to -3.5; each moves the pair's mesh point along the line
of centres).  The masses and inertias are values the data kernel reads at run time; each
ratio gets a data kernel of its own, which is the first one's code with its own constant
pool (no compile: the IR holds no value of the mechanism).  The script prints the
variants per second, the kernels built in this process and how many of them were compiled
(the others linked from the first's object code; a Dask or -j run's workers build their
own), and the load average.  ``--numpy`` times the numpy path instead.
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from timing import load_line  # noqa: E402 (benchmarks/timing.py)

from gearcli.batch.manifest import load_manifest
from gearcli.batch import sweep
from gearcli.batch.sweep import parse_vary, plan_sweep, run_sweep
from gearcli.dynamics.llvm import driver

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variants", type=int, default=200, help="about this many variants (the issue's figure: 1000)")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--rounds", type=int, default=3, help="sweeps timed one after another (the median is quoted: "
                    "this shared machine's rate moves by 1.5x from one second to the next)")
    ap.add_argument("--numpy", action="store_true", help="time the numpy path (no data kernel)")
    ap.add_argument("--points", type=int, default=1, help="also vary the tool's point (a constant of the kernel: "
                    "one data kernel per point) over this many values, the variants split among them")
    ap.add_argument("--ratios", type=int, default=4, help="values of the pinion pair's ratio (1: not varied)")
    ap.add_argument("--dask-workers", type=int, default=0, help="also time a dask LocalCluster of this many "
                    "single-threaded worker processes (0: not)")
    args = ap.parse_args()
    src = ROOT / "mechanisms" / "bendix_wrist_traj.csv"
    head = src.read_text().splitlines()[0]
    d = np.loadtxt(src, delimiter=",", skiprows=1)
    t = np.linspace(d[0, 0], d[-1, 0], 10_000)
    q = np.column_stack([np.interp(t, d[:, 0], d[:, k]) for k in range(1, d.shape[1])])
    tmp = Path(tempfile.mkdtemp())
    os.environ["GEARCLI_CACHE_DIR"] = str(tmp / "cache")       # a cold disk cache: the compiles counted are real
    np.savetxt(tmp / "traj.csv", np.column_stack([t, q]), delimiter=",", header=head, comments="", fmt="%.17g")
    # the wrist with a tool on its flange: a load whose mass (kg) a variant sets
    mech = (ROOT / "mechanisms" / "bendix_wrist_rated.yaml").read_text()
    (tmp / "wrist.yaml").write_text(mech + "\nloads:\n  - {name: tool, link: \"3\", point: [0, 0.06, 0.03], frame: link, "
                                    "mass: 0.4, inertia: [2.0e-4, 2.0e-4, 1.0e-4]}\n")
    design = (ROOT / "designs" / "ci_example.yaml").read_text()
    design = design.replace("../mechanisms/bendix_wrist_rated.yaml", str(tmp / "wrist.yaml"))
    design = design.replace("../mechanisms/bendix_wrist_traj.csv", str(tmp / "traj.csv"))
    (tmp / "d.yaml").write_text(design)
    n_mass = max(1, args.variants // (10 * args.points * args.ratios))
    varies = [parse_vary(f"links.3.mass=0.6:1.2:{n_mass}"), parse_vary("links.3.inertia.izz=0.0011,0.0015"),
              parse_vary("loads.tool.mass=0.2:1.0:5")]
    if args.ratios > 1:
        varies.insert(0, parse_vary(f"gears.4-1.ratio=-2.5:-3.5:{args.ratios}"))
    if args.points > 1:
        varies.insert(0, parse_vary(f"loads.tool.point[1]=0.04:0.08:{args.points}"))
    compiles = []
    real = driver.Jit.__init__

    def counted(self, *a, **k):                # every kernel the run builds: compiled, or linked from object code
        real(self, *a, **k)
        compiles.append(not self.from_cache)
    driver.Jit.__init__ = counted
    if args.numpy:
        sweep.data_kernel_applies = sweep.per_value_kernels = lambda varies, variants=None: False
    plan = plan_sweep(load_manifest(tmp / "d.yaml"), varies)
    n, times = len(plan.variants), []
    for _ in range(args.rounds):
        t0 = time.perf_counter()
        rows = run_sweep(plan, jobs=args.jobs)
        times.append(time.perf_counter() - t0)
    dt = float(np.median(times))
    print(f"gearcli sweep, rated Bendix wrist, 10,000 samples, {len(rows[0])} checks a variant:")
    print(f"  -j {args.jobs}: {n} variants, median of {len(times)} rounds {dt:.2f} s: {n / dt:.2f} variants/s "
          f"({dt / n * 1e3:.0f} ms a variant; rounds {', '.join(f'{n / x:.1f}' for x in times)} variants/s); "
          f"kernels built here: {len(compiles)}, compiled: {sum(compiles)} "
          f"({'numpy path' if args.numpy else 'data kernels'})")
    if args.dask_workers:
        from dask.distributed import LocalCluster
        with LocalCluster(n_workers=args.dask_workers, threads_per_worker=1, dashboard_address=None) as cluster:
            run_sweep(plan, dask_address=cluster.scheduler_address)      # warm the workers (imports)
            t0 = time.perf_counter()
            again = run_sweep(plan, dask_address=cluster.scheduler_address)
            dd = time.perf_counter() - t0
        same = "the same results" if again == rows else "DIFFERENT results"
        print(f"  dask LocalCluster, {args.dask_workers} workers: {n / dd:.2f} variants/s, {dt / dd:.2f}x -j {args.jobs} "
              f"({same})")
    print(f"  {load_line()}")


if __name__ == "__main__":
    main()
