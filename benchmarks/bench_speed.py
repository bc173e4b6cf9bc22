"""Side-by-side speed of gearcli and Pinocchio (issue 11); prints figures, not a test.

    python benchmarks/bench_speed.py [--quick] [--repeat 5] [--samples 20000] [--cli-samples 1000000]
                                     [--cli-repeat 1] [--big] [--skip cli,threads,links,n]

Prints, in one run (medians over --repeat, ratios from the same run, load average at the
start and the end, thread counts stated):

1. per mechanism (paper_2dof, Bendix wrist, UR5, Panda) samples/s of the gearcli library,
   all loads (``backend="kernel"`` and ``"numpy"`` when ``solve`` has a ``backend``
   parameter, else "n/a"; one and two workers when it has ``jobs``), ``method="full"``,
   Pinocchio ``pin.rnea`` in a Python loop and ``pin.rneaInParallel`` with 1 and 2
   threads (torques only).  Pinocchio loads UR5 and Panda from example-robot-data's URDF
   (the same file gearcli reads); for paper_2dof and Bendix it loads the URDF that
   ``gearcli export`` writes (every joint a free joint: the same tree);
2. ``gearcli solve`` end to end on --cli-samples Bendix samples (positions only, rates by
   spline) to CSV and to Parquet, wall time and peak memory, against the library solve of
   the same samples; the CSV formatting of today (Python ``%``) against the compiled one;
3. threads (benchmarks/bench_threads.py): one, two and the default (every core)
   interleaved on Bendix, llvm and numba kernel, 20,000 and 200,000 samples, fresh result
   arrays and ``out=`` reuse, on the machine as it is and with a busy process on a core
   (issue 11: >= 1.8x with two cores, the default within 10% of one thread when a core is
   taken);
4. per-sample cost against the size of a geared chain (2..64 links), and against the
   number of samples on Bendix (1e2..1e6, 1e7 with --big; one thread), each N in its own
   process with its peak resident memory.

Markdown tables are printed for the README ("Speed").
"""
from __future__ import annotations

import argparse
import inspect
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from bench_threads import threads_table  # noqa: E402 (benchmarks/bench_threads.py)
from cli_stages import floor_times, print_floor, print_stages, stage_times, startup_time  # noqa: E402 (benchmarks/cli_stages.py)
from timing import load_line, median_time  # noqa: E402 (benchmarks/timing.py)
from threadpoolctl import threadpool_info, threadpool_limits

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))      # big_mechanisms: generated geared chains

from gearcli import analyse, load_mechanism, solve  # noqa: E402
from gearcli.report.urdf_writer import export_urdf  # noqa: E402

try:
    try:
        from gearcli.dynamics.backends import BACKENDS  # noqa: E402
    except ImportError:            # an older gearcli: they were in solve
        from gearcli.dynamics.solve import BACKENDS  # noqa: E402
except ImportError:          # an older gearcli
    BACKENDS = ()

MECHS = ROOT / "mechanisms"
SOLVE_PARAMS = inspect.signature(solve).parameters


def erd_robots() -> Path | None:
    """example-robot-data's robots directory (installed as data by the pip package)."""
    for p in map(Path, sys.path):
        d = p / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if d.is_dir():
            return d
    return None






def rate(fn, n: int, repeat: int) -> float:
    fn()        # warm-up (compilation, caches)
    return n / median_time(fn, repeat)


# ---------------------------------------------------------------------------------------
# 1. library against Pinocchio
# ---------------------------------------------------------------------------------------
def subjects(tmp: Path) -> list[tuple[str, Path, Path]]:
    """(name, file gearcli reads, URDF Pinocchio reads) of the compared mechanisms."""
    out = []
    for name in ("paper_2dof", "bendix_wrist"):
        urdf = tmp / f"{name}.urdf"
        export_urdf(analyse(load_mechanism(MECHS / f"{name}.yaml")), urdf)
        out.append((name, MECHS / f"{name}.yaml", urdf))
    erd = erd_robots()
    if erd is not None:
        for name, rel in (("UR5", "ur_description/urdf/ur5_robot.urdf"), ("Panda", "panda_description/urdf/panda.urdf")):
            out.append((name, erd / rel, erd / rel))
    return out


def pinocchio_inputs(model, mech, an, q, qd, qdd):
    """Pinocchio's (nq, N), (nv, N), (nv, N) column-major inputs for gearcli's independent
    coordinates (q, qd, qdd) (N, dof): every gearcli joint by name, continuous joints as
    (cos, sin)."""
    import pinocchio as pin

    qa, va, aa = q @ an.S.T, qd @ an.S.T, qdd @ an.S.T
    n = q.shape[0]
    Q = np.repeat(pin.neutral(model)[:, None], n, axis=1)
    V, A = np.zeros((model.nv, n)), np.zeros((model.nv, n))
    for ji, jt in enumerate(mech.joints):
        jm = model.joints[model.getJointId(jt.name)]
        if jm.nq == 2:
            Q[jm.idx_q], Q[jm.idx_q + 1] = np.cos(qa[:, ji]), np.sin(qa[:, ji])
        else:
            Q[jm.idx_q] = qa[:, ji]
        V[jm.idx_v], A[jm.idx_v] = va[:, ji], aa[:, ji]
    return np.asfortranarray(Q), np.asfortranarray(V), np.asfortranarray(A)


def pinocchio_rates(urdf: Path, mech, an, q, qd, qdd, repeat: int) -> dict:
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    Q, V, A = pinocchio_inputs(model, mech, an, q, qd, qdd)
    n = Q.shape[1]
    m = min(n, 20_000)
    cols = [(np.ascontiguousarray(Q[:, i]), np.ascontiguousarray(V[:, i]), np.ascontiguousarray(A[:, i]))
            for i in range(m)]

    def loop():
        for qi, vi, ai in cols:
            pin.rnea(model, data, qi, vi, ai)
    out = {"rnea loop": rate(loop, m, repeat), "tau": pin_tau(model, mech, Q[:, :100], V[:, :100], A[:, :100])}
    for threads in (1, 2):
        pool = pin.ModelPool(model, threads)
        tau = np.zeros((model.nv, n), order="F")
        out[f"rneaInParallel {threads}"] = rate(lambda: pin.rneaInParallel(threads, pool, Q, V, A, tau), n, repeat)
    return out


def pin_tau(model, mech, Q, V, A) -> np.ndarray:
    """Pinocchio's torques (n, J) on gearcli's joints (by name), for the consistency check."""
    import pinocchio as pin

    data = model.createData()
    tau = np.column_stack([pin.rnea(model, data, Q[:, i], V[:, i], A[:, i]) for i in range(Q.shape[1])]).T
    return tau[:, [model.joints[model.getJointId(jt.name)].idx_v for jt in mech.joints]]


def same_problem(an, q, qd, qdd, tau_pin) -> float:
    """Relative difference of gearcli's equivalent torques and Pinocchio's (projected by S)."""
    m = tau_pin.shape[0]
    mine = solve(an, q[:m], qd[:m], qdd[:m]).tau
    ref = tau_pin @ an.S
    return float(np.abs(mine - ref).max() / max(np.abs(ref).max(), 1e-300))


def gearcli_rates(an, q, qd, qdd, repeat: int) -> dict:
    """samples/s of gearcli.solve: kernel / numpy backends (1 and 2 workers), full method."""
    n = q.shape[0]
    out = {}
    backends = ((("llvm",) if "llvm" in BACKENDS else ()) + (("kernel",) if "kernel" in BACKENDS else ())
                + ("numpy",)) if "backend" in SOLVE_PARAMS else (None,)
    for backend in backends:
        for jobs in ((1, 2) if "jobs" in SOLVE_PARAMS and backend != "numpy" else (None,)):   # numpy: 1 thread
            kw = {} if backend is None else {"backend": backend}
            if jobs is not None:
                kw["jobs"] = jobs
            with threadpool_limits(limits=1, user_api="blas"):
                r = rate(lambda: solve(an, q, qd, qdd, **kw), n, repeat)
            out[(backend or "default", jobs or 1)] = r
    m = max(n // 10, 1000)
    with threadpool_limits(limits=1, user_api="blas"):
        out["full"] = rate(lambda: solve(an, q[:m], qd[:m], qdd[:m], method="full"), m, repeat)
    return out


def fmt_rate(r) -> str:
    if r is None:
        return "n/a"
    return f"{r / 1e6:.2f}M" if r >= 1e6 else f"{r / 1e3:.0f}k"


def library_section(n: int, repeat: int) -> None:
    print(f"\n## Library, all loads (gearcli) vs torques only (Pinocchio): samples/s, {n:,} random samples, "
          f"median of {repeat}")
    print("gearcli: one BLAS thread; 'x2' = jobs=2 (two kernel threads; the numpy path has one); llvm = the "
          "kernel generated per mechanism (compiled in the warm-up run); "
          "Pinocchio rneaInParallel with 1 and 2 threads\n")
    head = ["mechanism", "gearcli llvm", "llvm x2", "gearcli kernel", "kernel x2", "gearcli numpy", "gearcli full",
            "pin rnea loop", "rneaInParallel 1", "rneaInParallel 2", "llvm / rIP 1", "llvm x2 / rIP 2",
            "kernel / rIP 1", "kernel x2 / rIP 2"]
    # the numba kernel's columns only where the code measured has one (it was retired in issue 18)
    keep = [i for i, h in enumerate(head)
            if "kernel" not in h or "kernel" in BACKENDS or "backend" not in SOLVE_PARAMS]
    print("| " + " | ".join(head[i] for i in keep) + " |\n|" + "---|" * len(keep))
    with tempfile.TemporaryDirectory() as d:
        for name, path, urdf in subjects(Path(d)):
            mech = load_mechanism(path)
            an = analyse(mech)
            rng = np.random.default_rng(0)
            q, qd, qdd = (rng.uniform(-1.5, 1.5, size=(n, an.dof)) for _ in range(3))
            g = gearcli_rates(an, q, qd, qdd, repeat)
            p = pinocchio_rates(urdf, mech, an, q, qd, qdd, repeat)
            diff = same_problem(an, q, qd, qdd, p["tau"])
            if diff > 1e-8:
                print(f"WARNING {name}: gearcli tau differs from Pinocchio's by {diff:.1e} (relative)")
            k1 = g.get(("kernel", 1), g.get(("default", 1)))
            k2 = g.get(("kernel", 2))
            l1, l2 = g.get(("llvm", 1)), g.get(("llvm", 2))
            ratio = (lambda a, b: "n/a" if a is None else f"{a / b:.2f}x")
            row = [f"{name} ({an.dof} dof, {len(mech.joints)} joints)", fmt_rate(l1), fmt_rate(l2),
                   fmt_rate(k1), fmt_rate(k2), fmt_rate(g.get(("numpy", 1))), fmt_rate(g["full"]),
                   fmt_rate(p["rnea loop"]), fmt_rate(p["rneaInParallel 1"]), fmt_rate(p["rneaInParallel 2"]),
                   ratio(l1, p["rneaInParallel 1"]), ratio(l2, p["rneaInParallel 2"]),
                   ratio(k1, p["rneaInParallel 1"]), ratio(k2, p["rneaInParallel 2"])]
            print("| " + " | ".join(row[i] for i in keep) + " |", flush=True)
    print("\nEvery row: gearcli's equivalent joint torques equal Pinocchio's (S^T tau) to 1e-8 relative or a "
          "WARNING line says otherwise.")
    if "backend" not in SOLVE_PARAMS:
        print("(gearcli.solve has no backend parameter here: 'gearcli kernel' is the default solve)")


# ---------------------------------------------------------------------------------------
# 2. the CLI end to end
# ---------------------------------------------------------------------------------------
def bendix_trajectory(path: Path, n: int) -> None:
    """Positions-only Bendix trajectory (t, q:J1..J3) of ``n`` samples at 1 kHz."""
    with open(path, "w") as f:
        f.write("t,q:J1,q:J2,q:J3\n")
        for s in range(0, n, 1_000_000):
            t = np.arange(s, min(n, s + 1_000_000)) * 1e-3
            q = [0.8 * np.sin(0.5 * t + k) + 0.1 * np.sin(3.1 * (k + 1) * t) for k in range(3)]
            np.savetxt(f, np.column_stack([t, *q]), delimiter=",", fmt="%.17g")


PEAK = ("import atexit, sys\n"
        "def _peak():\n"
        "    line = [x for x in open('/proc/self/status') if x.startswith('VmHWM')][0]\n"
        "    sys.stderr.write('PEAK_KB ' + line.split()[1] + '\\n')\n"
        "atexit.register(_peak)\n")
"""Prefix of a child's code: print its peak resident memory (VmHWM: this process only;
ru_maxrss would include the parent's memory at fork)."""

CLI = PEAK + "from gearcli.cli import app; sys.argv[0] = 'gearcli'; app()"
CLI_PY_FORMAT = PEAK + ("import gearcli.report.table_files as t; t.COMPILED_MIN_VALUES = 10**18\n"
                        "from gearcli.cli import app; sys.argv[0] = 'gearcli'; app()")


def run_measured(code: str, args: list[str]) -> tuple[float, float]:
    """(wall time s, peak resident memory MB) of ``python -c code args``."""
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-c", code, *args], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                       text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        raise SystemExit(f"failed ({r.returncode}): {' '.join(args)}\n{r.stderr}")
    kb = [float(x.split()[1]) for x in r.stderr.splitlines() if x.startswith("PEAK_KB ")]
    return wall, kb[-1] / 1024


def library_solve_time(mech: Path, traj: Path) -> float:
    """Seconds of gearcli.solve alone on the samples of ``traj`` (read and splined first),
    in chunks of 20,000 like the CLI, with the CLI's default threads (``jobs=None``: all
    cores; backend "auto")."""
    from gearcli import read_trajectory

    an = analyse(load_mechanism(mech))
    tr = read_trajectory(traj, an.independent_names)
    solve(an, tr.q[:100], tr.qd[:100], tr.qdd[:100])
    t0 = time.perf_counter()
    for s in range(0, len(tr.t), 20_000):
        solve(an, tr.q[s:s + 20_000], tr.qd[s:s + 20_000], tr.qdd[s:s + 20_000])
    return time.perf_counter() - t0


def cli_section(n: int, old_format: bool, repeat: int = 1) -> None:
    """Library solve and CLI runs, each the median of ``repeat`` runs (CLI runs interleaved)."""
    mech = MECHS / "bendix_wrist.yaml"
    print(f"\n## `gearcli solve` end to end, Bendix wrist, {n:,} samples (positions only; rates by spline)\n")
    with tempfile.TemporaryDirectory() as d:
        traj = Path(d) / "traj.csv"
        bendix_trajectory(traj, n)
        lib = np.median([library_solve_time(mech, traj) for _ in range(repeat)])
        rows = [(f"library `gearcli.solve` alone (same samples, chunks of 20,000, default threads: "
                 f"{os.cpu_count()} like the CLI's default --jobs)", lib, None, None)]
        runs = [("out.csv", CLI), ("out.parquet", CLI)]
        if old_format:
            runs.append(("old.csv", CLI_PY_FORMAT))
        measured, size = {out: [] for out, _ in runs}, {}
        for _ in range(repeat):
            for out, code in runs:
                measured[out].append(run_measured(code, ["solve", str(mech), str(traj), "-o", str(Path(d) / out)]))
                size[out] = (Path(d) / out).stat().st_size / 1e6
                (Path(d) / out).unlink()
        for out, code in runs:
            wall, rss = np.median([m[0] for m in measured[out]]), max(m[1] for m in measured[out])
            label = f"`gearcli solve -o {out}` ({size[out]:,.0f} MB)"
            if code is CLI_PY_FORMAT:
                label += ", CSV text by Python's `%` (the writer before issue 11)"
            rows.append((label, wall, rss, wall / lib))
        stages, startup = stage_times(mech, traj), startup_time(mech, traj)
        floor = floor_times(int(size["out.parquet"] * 1e6), Path(d), max(repeat, 3))
    print("| run | wall time | peak memory | / library solve |\n|---|---|---|---|")
    for label, wall, rss, ratio in rows:
        print(f"| {label} | {wall:.2f} s | {'' if rss is None else f'{rss:,.0f} MB'} | "
              f"{'' if ratio is None else f'{ratio:.1f}x'} |")
    print_stages(stages, startup, {out: float(np.median([m[0] for m in measured[out]])) for out in measured}, n)
    print_floor(floor, lib)


def format_section(n: int, repeat: int) -> None:
    """CSV text of the Bendix output table: Python's ``%`` (today) vs the compiled writer."""
    from gearcli.report.columns import table
    from gearcli.report.csv_text import compiled_rows, python_rows

    an = analyse(load_mechanism(MECHS / "bendix_wrist.yaml"))
    rng = np.random.default_rng(1)
    q, qd, qdd = (rng.uniform(-1.5, 1.5, size=(n, an.dof)) for _ in range(3))
    tab = table(an, np.arange(n) * 1e-3, solve(an, q, qd, qdd))
    slow = median_time(lambda: python_rows(tab), max(1, repeat // 2))
    compiled_rows(tab[:10])
    fast = median_time(lambda: compiled_rows(tab), repeat)
    assert python_rows(tab) == compiled_rows(tab)
    print(f"\nCSV text of {n:,} Bendix output rows ({tab.size:,} values, identical bytes): Python % "
          f"{slow:.2f} s ({slow / tab.size * 1e9:.0f} ns/value), compiled {fast:.2f} s "
          f"({fast / tab.size * 1e9:.0f} ns/value): {slow / fast:.1f}x")


# ---------------------------------------------------------------------------------------
# 3. scaling
# ---------------------------------------------------------------------------------------
def links_section(n: int, repeat: int, sizes) -> None:
    from big_mechanisms import geared_chain
    from gearcli.io.yaml_reader import parse_mechanism

    backends = ((("llvm",) if "llvm" in BACKENDS else ()) + (("kernel",) if "kernel" in BACKENDS else ())
                + ("numpy",)) if "backend" in SOLVE_PARAMS else ("default",)
    print(f"\n## Per-sample cost against mechanism size: geared chains (link i driven by a spur pinion on "
          f"link i-1), {n:,} samples, one worker, median of {repeat}\n")
    llvm = "llvm" in backends
    print("| links (+ pinions) | " + ("llvm first call (compile) | " if llvm else "")
          + " | ".join(f"{b} us/sample | {b} us/sample/link" for b in backends)
          + " |\n|---|" + ("---|" if llvm else "") + "---|---|" * len(backends))
    for links in sizes:
        an = analyse(parse_mechanism(geared_chain(links), f"geared{links}.yaml"))
        rng = np.random.default_rng(2)
        q, qd, qdd = (rng.uniform(-1.0, 1.0, size=(n, an.dof)) for _ in range(3))
        cells = []
        if llvm:      # a fresh analysis: its first llvm solve generates and compiles the kernel
            t0 = time.perf_counter()
            solve(an, q[:10], qd[:10], qdd[:10], backend="llvm", jobs=1)
            cells.append(f"{time.perf_counter() - t0:.2f} s")
        for b in backends:
            kw = {} if b == "default" else {"backend": b}
            if "jobs" in SOLVE_PARAMS:
                kw["jobs"] = 1
            with threadpool_limits(limits=1, user_api="blas"):
                us = 1e6 / rate(lambda: solve(an, q, qd, qdd, **kw), n, repeat)
            cells += [f"{us:.2f}", f"{us / links:.3f}"]
        print(f"| {links} | " + " | ".join(cells) + " |", flush=True)


SAMPLES_CHILD = PEAK + """
import time
import numpy as np
from threadpoolctl import threadpool_limits
from gearcli import analyse, load_mechanism, solve
n, backend = int(sys.argv[1]), sys.argv[2]
reuse = backend.endswith("+out")         # stream: every chunk into the same output arrays
backend = backend.removesuffix("+out")
kw = {"jobs": 1} if backend == "default" else {"backend": backend, "jobs": 1}
an = analyse(load_mechanism(sys.argv[3]))
rng = np.random.default_rng(3)
step = min(n, 100_000)
q, qd, qdd = (rng.uniform(-1.5, 1.5, size=(step, an.dof)) for _ in range(3))
# below 1e5 samples one solve is too short to time: the median of enough repeats to cover
# 2e5 samples; from 1e5 on, one pass over n samples in chunks of 1e5 (the same arrays)
rounds = max(5, 200_000 // n) if n < 100_000 else 1
with threadpool_limits(limits=1, user_api="blas"):
    solve(an, q[:100], qd[:100], qdd[:100], **kw)
    out = solve(an, q, qd, qdd, **kw) if reuse else None
    times = []
    for _ in range(rounds):
        t0 = time.perf_counter()
        for s in range(0, n, step):
            m = min(step, n - s)
            res = solve(an, q[:m], qd[:m], qdd[:m], **kw, **({"out": out} if reuse and m == step else {}))
            del res
        times.append(time.perf_counter() - t0)
print(float(np.median(times)))
"""


def samples_section(sizes) -> None:
    backends = ((("llvm", "llvm+out") if "llvm" in BACKENDS else ()) + (("kernel",) if "kernel" in BACKENDS else ())
                + ("numpy",)) if "backend" in SOLVE_PARAMS \
        else ("default",)
    print("\n## Per-sample cost and peak memory against the number of samples (Bendix wrist, library solve, "
          "one thread, in chunks of 100,000 generated samples, each N in a fresh process; below 1e5 the median "
          "of repeated solves covering 2e5 samples; 'llvm+out': every chunk written into the same Result, "
          "solve(..., out=res), as a streaming user does)\n")
    print("| samples | " + " | ".join(f"{b} us/sample | {b} peak memory" for b in backends)
          + " |\n|---|" + "---|---|" * len(backends))
    for n in sizes:
        cells = []
        for b in backends:
            r = subprocess.run([sys.executable, "-c", SAMPLES_CHILD, str(n), b, str(MECHS / "bendix_wrist.yaml")],
                               capture_output=True, text=True, check=True)
            dt = float(r.stdout.split()[0])
            rss = float([x for x in r.stderr.splitlines() if x.startswith("PEAK_KB ")][-1].split()[1]) / 1024
            cells += [f"{dt / n * 1e6:.2f}", f"{rss:,.0f} MB"]
        print(f"| {n:,} | " + " | ".join(cells) + " |", flush=True)


def threads_section(sizes: list, rounds: int) -> None:
    """Two threads against one, quiet and with a busy core (benchmarks/bench_threads.py)."""
    if "jobs" not in SOLVE_PARAMS:
        print("\n## Threads: this gearcli's solve has no jobs parameter")
        return
    threads_table(sizes, rounds)


def big_cli(n: int) -> None:
    """Peak memory of ``gearcli solve`` to Parquet on ``n`` Bendix samples."""
    with tempfile.TemporaryDirectory() as d:
        traj = Path(d) / "traj.csv"
        bendix_trajectory(traj, n)
        wall, rss = run_measured(CLI, ["solve", str(MECHS / "bendix_wrist.yaml"), str(traj),
                                       "-o", str(Path(d) / "out.parquet")])
    print(f"\n`gearcli solve -o out.parquet` on {n:,} Bendix samples: {wall:.0f} s, peak memory {rss:,.0f} MB")


def threads_line() -> str:
    blas = [f"{i['internal_api']} {i['num_threads']}" for i in threadpool_info() if i["user_api"] == "blas"]
    try:
        import numba
        nb = f"numba {numba.config.NUMBA_NUM_THREADS} threads"
    except ImportError:  # pragma: no cover
        nb = "numba absent"
    env = {k: os.environ[k] for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "NUMBA_NUM_THREADS")
           if k in os.environ}
    return (f"threads: BLAS default {', '.join(blas) or 'none'} (gearcli timings run with 1), {nb}, "
            f"environment {env or 'unset'}; solve parameters: {', '.join(SOLVE_PARAMS)}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="small sizes (about a minute)")
    ap.add_argument("--repeat", type=int, default=None, help="runs per figure (default 5, --quick 3)")
    ap.add_argument("--samples", type=int, default=None, help="samples per library figure (default 20,000)")
    ap.add_argument("--cli-repeat", type=int, default=1, help="runs per CLI figure (median; default 1)")
    ap.add_argument("--cli-samples", type=int, default=None, help="samples of the CLI runs (default 1,000,000)")
    ap.add_argument("--big", action="store_true", help="also 1e7 samples (library and CLI peak memory; minutes)")
    ap.add_argument("--skip", default="", help="comma list of sections to skip: lib,cli,threads,links,n")
    a = ap.parse_args()
    repeat = a.repeat or (3 if a.quick else 5)
    n = a.samples or (5_000 if a.quick else 20_000)
    cli_n = a.cli_samples or (100_000 if a.quick else 1_000_000)
    skip = set(filter(None, a.skip.split(",")))
    import pinocchio
    print(f"# gearcli speed, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; python {sys.version.split()[0]}, "
          f"numpy {np.__version__}, pinocchio {pinocchio.__version__}")
    print(load_line() + " at start")
    print(threads_line())
    if "lib" not in skip:
        library_section(n, repeat)
    if "cli" not in skip:
        cli_section(cli_n, old_format=not a.quick, repeat=a.cli_repeat)
        format_section(20_000 if a.quick else 100_000, repeat)
    if "threads" not in skip:
        threads_section([20_000] if a.quick else [20_000, 200_000], max(repeat, 7))
    if "links" not in skip:
        links_section(max(n // 4, 1000), repeat, (2, 4, 8, 16, 32, 64) if not a.quick else (2, 8, 32))
    if "n" not in skip:
        sizes = [10 ** k for k in range(2, 7 if not a.quick else 6)] + ([10 ** 7] if a.big else [])
        samples_section(sizes)
    if a.big and "cli" not in skip:
        big_cli(10 ** 7)
    print("\n" + load_line() + " at end")


if __name__ == "__main__":
    main()
