"""Start-up time of every ``gearcli`` command: median wall time of fresh processes.

Each figure is the median of ``--repeat`` (default 7) fresh ``python`` processes running
the command on a small input (the Bendix wrist, a 100-sample trajectory with its rates and
accelerations, or its positions only: then the spline's scipy.linalg is needed), next to floors
measured the same way: an empty interpreter and the bare imports of the libraries the
commands need.  With several ``--src`` trees (e.g. ``--src /work/main/src --src src``) the
same commands run from each tree in turn, interleaved, so the trees are compared in one run::

    python benchmarks/bench_startup.py [--repeat 7] [--src DIR ...]

The load average (1, 5, 15 min) is printed before and after.  The LLVM kernel and the
solution schedule come from the disk caches (one warm-up run of each command precedes the
timed ones; ``--cold`` gives each run an empty cache folder instead: the first run of a
mechanism).
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CLI = "import sys; from gearcli.cli import app; sys.argv[0] = 'gearcli'; sys.exit(app())"

FLOORS = {   # what the commands cannot do without, imported alone
    "python -c pass": "pass",
    "import numpy": "import numpy",
    "import typer._adapters (typer's parsing: pydantic)": "import typer._adapters",
    "import numpy, yaml, jsonschema, typer._adapters (check's libraries)":
        "import numpy, yaml, jsonschema, typer._adapters",
    "import numpy, scipy.linalg": "import numpy, scipy.linalg",
    "import numpy, scipy.sparse.csgraph": "import numpy, scipy.sparse.csgraph",
    "import numpy, pyarrow.parquet": "import numpy, pyarrow.parquet",
}


def commands(tmp: Path) -> dict[str, list[str]]:
    """The timed commands (arguments after ``gearcli``)."""
    mech = ROOT / "mechanisms" / "bendix_wrist.yaml"
    traj, positions = tmp / "small.csv", tmp / "positions.csv"
    with open(ROOT / "mechanisms" / "bendix_wrist_traj.csv") as src:
        lines = [line for _, line in zip(range(101), src)]
    traj.write_text("".join(lines))
    q = [i for i, name in enumerate(lines[0].strip().split(",")) if name == "t" or name.startswith("q:")]
    positions.write_text("".join(",".join(line.strip().split(",")[i] for i in q) + "\n" for line in lines))
    return {
        "gearcli --help": ["--help"],
        "gearcli check bendix_wrist.yaml": ["check", str(mech)],
        "gearcli graph bendix_wrist.yaml": ["graph", str(mech)],
        "gearcli solve (100 samples) -o x.parquet": ["solve", str(mech), str(traj), "-o", str(tmp / "x.parquet")],
        "gearcli solve (100 samples) -o x.csv": ["solve", str(mech), str(traj), "-o", str(tmp / "x.csv")],
        "gearcli solve (100 samples, positions only: spline) -o x.csv":
            ["solve", str(mech), str(positions), "-o", str(tmp / "y.csv")],
        "gearcli verify designs/ci_example.yaml": ["verify", str(ROOT / "designs" / "ci_example.yaml")],
    }


CACHE: dict = {"dir": None, "cold": False}   # gearcli's disk caches of the timed runs


def run_once(argv: list[str], src: str | None) -> float:
    """Wall time of one fresh process, s (its output discarded; a failure stops the script)."""
    env = dict(os.environ)
    if src is not None:
        env["PYTHONPATH"] = src
    with tempfile.TemporaryDirectory() as empty:
        env["GEARCLI_CACHE_DIR"] = empty if CACHE["cold"] else CACHE["dir"]
        t0 = time.perf_counter()
        proc = subprocess.run(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, cwd=ROOT)
        dt = time.perf_counter() - t0
    if proc.returncode not in (0, 1):   # verify exits 1 when a check fails
        raise SystemExit(f"{' '.join(argv)}: exit {proc.returncode}\n{proc.stderr.decode()}")
    return dt


def medians(jobs: dict[str, list[str]], srcs: list[str | None], repeat: int) -> dict[tuple[str, str | None], float]:
    """Median wall time of each job from each source tree, runs interleaved round-robin."""
    times: dict[tuple[str, str | None], list[float]] = {(j, s): [] for j in jobs for s in srcs}
    for name, argv in jobs.items():
        for src in srcs:
            run_once(argv, src)   # warm-up: disk cache, kernel cache
    for _ in range(repeat):
        for name, argv in jobs.items():
            for src in srcs:
                times[(name, src)].append(run_once(argv, src))
    return {k: statistics.median(v) for k, v in times.items()}


def load_line() -> str:
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f} ({os.cpu_count()} cpus)"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=7, help="fresh processes per figure (median)")
    ap.add_argument("--cold", action="store_true", help="an empty kernel/schedule cache for every run")
    ap.add_argument("--src", action="append", help="source tree to put on PYTHONPATH (repeatable; "
                    "default: the installed gearcli)")
    args = ap.parse_args()
    srcs = [str(Path(s).resolve()) for s in args.src] if args.src else [None]
    print(f"{time.strftime('%H:%M UTC', time.gmtime())}, {load_line()}, python {sys.version.split()[0]}, "
          f"median of {args.repeat} fresh processes, {'empty' if args.cold else 'warm'} disk caches")
    with tempfile.TemporaryDirectory() as tmp:
        CACHE.update(dir=str(Path(tmp) / "cache"), cold=args.cold)
        cmds = {k: [sys.executable, "-c", CLI, *v] for k, v in commands(Path(tmp)).items()}
        floors = {k: [sys.executable, "-c", v] for k, v in FLOORS.items()}
        res = medians(cmds, srcs, args.repeat)
        res.update(medians(floors, [None], args.repeat))
    head = ["run"] + [f"`{s}`" if s else "s" for s in srcs]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for name in [*cmds, *floors]:
        if name in floors:
            cells = [f"{res[(name, None)]:.3f} s"] + [""] * (len(srcs) - 1)
        else:
            cells = [f"{res[(name, s)]:.3f} s" for s in srcs]
        print(f"| {name} | " + " | ".join(cells) + " |")
    print(f"after: {load_line()}")


if __name__ == "__main__":
    main()
