"""Time of ``gearcli check`` on large generated mechanisms (prints figures; not a test).

    python benchmarks/bench_check.py [--repeat 5] [--chain 200] [--geared 100] [--unknown 2000,4000,20000]

For a serial chain of --chain revolute joints and a geared chain of --geared links (each
driven by a spur pinion on its parent), prints medians over --repeat runs of: reading the
YAML file, the analysis (``gearcli.analyse``: graph, schedule, determinacy check), and the
wall time of the whole ``gearcli check`` command in a subprocess (Python start-up
included), with the load average.  Aim: library load + analyse < 1 s for each.

Then the error path: ``gearcli check`` of paper_2dof.yaml with --unknown extra top-level
keys (one problem each): the wall time must grow linearly with the number of problems
(issue 17: 2,000 keys took 1.6 s, 4,000 4.0 s, 20,000 2 min 19 s while the collector
deduplicated by scanning a list), and the lines printed stay at MAX_SHOWN + 1.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from timing import median_time  # noqa: E402 (benchmarks/timing.py)

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from big_mechanisms import geared_chain, serial_chain  # noqa: E402
from gearcli import analyse, load_mechanism  # noqa: E402




def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--chain", type=int, default=200)
    ap.add_argument("--geared", type=int, default=100)
    ap.add_argument("--unknown", default="2000,4000,20000", help="counts of unknown keys (comma-separated; '' skips)")
    args = ap.parse_args()
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}, median of {args.repeat}")
    print(f"{'mechanism':<22}{'read [s]':>10}{'analyse [s]':>13}{'library [s]':>13}{'CLI [s]':>10}")
    with tempfile.TemporaryDirectory() as tmp:
        for label, text in ((f"serial chain {args.chain}", serial_chain(args.chain)),
                            (f"geared chain {args.geared}", geared_chain(args.geared))):
            path = Path(tmp) / "mech.yaml"
            path.write_text(text)
            mech = load_mechanism(path)
            t_read = median_time(lambda: load_mechanism(path), args.repeat)
            t_an = median_time(lambda: analyse(mech), args.repeat)
            cmd = [sys.executable, "-m", "gearcli.cli", "check", str(path)]
            env = dict(os.environ, PYTHONPATH=str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""))

            def run():
                subprocess.run(cmd, check=True, capture_output=True, env=env)
            t_cli = median_time(run, args.repeat)
            print(f"{label:<22}{t_read:>10.3f}{t_an:>13.3f}{t_read + t_an:>13.3f}{t_cli:>10.3f}")
    if args.unknown:
        unknown_keys([int(n) for n in args.unknown.split(",")], args.repeat)


def unknown_keys(counts: list[int], repeat: int) -> None:
    """``gearcli check`` (subprocess) of paper_2dof.yaml with n unknown top-level keys."""
    text = (ROOT / "mechanisms" / "paper_2dof.yaml").read_text()
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    print(f"\n{'unknown keys':<22}{'CLI [s]':>10}{'lines':>8}  last line")
    with tempfile.TemporaryDirectory() as tmp:
        for n in counts:
            path = Path(tmp) / "unknown.yaml"
            path.write_text(text + "".join(f"unknown_key_{i}: 1\n" for i in range(n)))
            cmd = [sys.executable, "-m", "gearcli.cli", "check", str(path)]
            out = []

            def run():
                r = subprocess.run(cmd, capture_output=True, text=True, env=env)
                assert r.returncode == 2, r.stderr[-500:]
                out[:] = r.stderr.splitlines()
            t_cli = median_time(run, repeat)
            print(f"{n:<22,}{t_cli:>10.3f}{len(out):>8}  {out[-1]}")


if __name__ == "__main__":
    main()
