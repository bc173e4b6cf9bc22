"""Where the time of `gearcli solve` goes (benchmarks/bench_speed.py, section 2).

:func:`stage_times` runs the stages the command overlaps in threads (reading thread,
solve, writing thread) one after the other in one thread, on the same samples and chunks
as the command, each timed alone (wall time; the solve with the command's default thread
count).  :func:`startup_time` is the wall time of the command on a 100-sample trajectory
in a fresh process: imports, mechanism analysis, kernel compilation or loading, a tiny
output.  The command's wall time minus the start-up, against the sum of the stages, says
how well the stages overlap.
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from gearcli import __version__
from gearcli.dynamics.solve import solve
from gearcli.io.output import atomic_output
from gearcli.io.trajectory import TrajectoryReader
from gearcli.io import load_mechanism
from gearcli.pipeline import analyse
from gearcli.report.columns import Summary, column_names, column_units, first_non_finite, table
from gearcli.report.table_files import open_table

READ = "read and check the CSV (pyarrow parser, checks)"
SPLINE = "spline rates and accelerations (quintic, banded LAPACK)"
SOLVE = "library solve (default threads)"
TABLE = "output table, finiteness check, summary statistics"
PARQUET = "Parquet writing (uncompressed, to the page cache)"
CSV = "CSV writing (9 digits, compiled formatter, its loading included)"


def startup_time(mech: Path, traj: Path, out_suffix: str = ".parquet") -> float:
    """Wall time (s) of ``gearcli solve`` on the first 100 samples of ``traj`` (fresh process)."""
    with tempfile.TemporaryDirectory() as d:
        small = Path(d) / "small.csv"
        with open(traj) as f:
            small.write_text("".join(next(f) for _ in range(101)))
        code = "import sys; from gearcli.cli import app; sys.argv[0] = 'gearcli'; app()"
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", code, "solve", str(mech), str(small), "-o", str(Path(d) / ("o" + out_suffix))],
                       check=True, stdout=subprocess.DEVNULL)
        return time.perf_counter() - t0


def stage_times(mech: Path, traj: Path, chunk: int = 20_000) -> dict[str, float]:
    """Seconds of every stage of ``gearcli solve mech traj -o out.parquet|csv``, one after the
    other in this thread (after a warm-up solve), by the command's own functions."""
    an = analyse(load_mechanism(mech))
    reader = TrajectoryReader(traj, an.independent_names, chunk=chunk, linear=an.prismatic_independent,
                              loads=an.mech.loads)
    out: dict[str, float] = {}
    t0 = time.perf_counter()
    n = reader.check()
    out[READ] = time.perf_counter() - t0
    t0 = time.perf_counter()
    parts = list(reader)
    out[SPLINE] = time.perf_counter() - t0 - out[READ]
    solve(an, parts[0].q[:100], parts[0].qd[:100], parts[0].qdd[:100])     # compile / load the kernel
    names, units = column_names(an), column_units(an)
    meta = {"gearcli_version": __version__, "mechanism": str(mech), "trajectory": str(traj)}
    summary = Summary.for_mechanism(an)
    with tempfile.TemporaryDirectory(dir=Path(traj).parent) as d:
        with atomic_output(Path(d) / "out.parquet", binary=True) as fp, atomic_output(Path(d) / "out.csv") as fc:
            files = {PARQUET: open_table("parquet", fp, names, units, meta, rows=n),
                     CSV: open_table("csv", fc, names, units, meta, rows=n)}
            for p in parts:
                res = _timed(out, SOLVE, lambda: solve(an, p.q, p.qd, p.qdd, loads=p.loads))
                tab = _timed(out, TABLE, lambda: table(an, p.t, res))
                _timed(out, TABLE, lambda: (first_non_finite(tab), summary.add(tab)))
                for key, f in files.items():
                    _timed(out, key, lambda: f.write(tab))
            for key, f in files.items():
                _timed(out, key, f.close)
    return out


def _timed(out: dict, key: str, fn):
    t0 = time.perf_counter()
    r = fn()
    out[key] = out.get(key, 0.0) + time.perf_counter() - t0
    return r


def floor_times(n_bytes: int, directory: Path, repeat: int = 3) -> dict[str, float]:
    """Lower bounds of any ``gearcli solve`` to a binary file of ``n_bytes``, medians of
    ``repeat``: a fresh Python importing only numpy and pyarrow.parquet (what any Parquet
    writer in Python loads; no gearcli), and writing ``n_bytes`` of float64 from memory to a
    new file in ``directory`` in 1 MB writes (no formatting, no pyarrow: the page-cache copy
    alone, a new file each time like the command's temporary file)."""
    imports, writes = [], []
    block = np.random.default_rng(0).standard_normal(1 << 17)      # 1 MB
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", "import numpy, pyarrow, pyarrow.parquet"], check=True)
        imports.append(time.perf_counter() - t0)
        path = Path(directory) / "floor.bin"
        t0 = time.perf_counter()
        with open(path, "wb", buffering=0) as f:
            left = n_bytes
            while left > 0:
                left -= f.write(memoryview(block).cast("B")[:min(left, block.nbytes)])
        writes.append(time.perf_counter() - t0)
        path.unlink()
    return {"a fresh Python importing numpy and pyarrow.parquet": float(np.median(imports)),
            f"writing the file's {n_bytes / 1e6:,.0f} MB from memory to a new file (1 MB writes)":
                float(np.median(writes))}


def print_floor(floor: dict[str, float], library: float) -> None:
    """Markdown table of :func:`floor_times` against the library solve time (s)."""
    print("\nLower bounds of any Python command writing this Parquet file (same run, medians):\n")
    print("| part | seconds | / library solve |\n|---|---|---|")
    for key, s in floor.items():
        print(f"| {key} | {s:.2f} | {s / library:.1f}x |")
    total = sum(floor.values())
    print(f"| both, without reading, spline, solve or table | {total:.2f} | {total / library:.1f}x |")


def print_stages(stages: dict[str, float], startup: float, cli: dict[str, float], n: int) -> None:
    """Markdown table of the stages, with the command's wall times for comparison."""
    print(f"\nStages of `gearcli solve` on the same {n:,} samples, each timed alone in one thread "
          "(the command overlaps reading+spline, solve+table and writing in three threads):\n")
    print("| stage | seconds |\n|---|---|")
    print(f"| start-up: the command on 100 samples (imports, analysis, kernel, tiny output) | {startup:.2f} |")
    for key, s in stages.items():
        print(f"| {key} | {s:.2f} |")
    common = sum(s for k, s in stages.items() if k not in (PARQUET, CSV))
    for key, out in ((PARQUET, "out.parquet"), (CSV, "out.csv")):
        if out in cli:
            print(f"| sum for `-o {out}` (start-up + stages) / the command's wall time | "
                  f"{startup + common + stages[key]:.2f} / {cli[out]:.2f} |")
