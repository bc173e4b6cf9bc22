"""Lines of the solver (``src/gearcli/dynamics``) by part, as issue 18 counts them.

Every ``*.py`` file's newline count (what ``find src/gearcli/dynamics -name '*.py' | xargs
wc -l`` sums), grouped into the losses of both paths and forward dynamics (the files
listed below), the llvm generator (the rest of ``dynamics/llvm/``) and the numpy reference
inverse solver (the rest of ``dynamics/``: the kinematics, loads, equations, plans, sign
search and solves both paths share or check against)::

    python benchmarks/solver_lines.py [--src DIR]
"""
from __future__ import annotations

import argparse
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LOSSES = {"losses.py", "bearing_friction.py", "llvm/losses.py", "llvm/friction_terms.py", "llvm/loss_program.py", "llvm/bearings.py",
          "llvm/bearing_newton.py"}
FORWARD = {"forward.py", "simulate.py", "llvm/mass.py"}


def part(rel: str) -> str:
    """The part of the solver a file (path below dynamics/) belongs to."""
    if rel in LOSSES:
        return "losses (both paths)"
    if rel in FORWARD:
        return "forward dynamics"
    if rel.startswith("llvm/"):
        return "llvm generator"
    return "numpy reference inverse solver"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--src", type=Path, default=ROOT / "src", help="the source tree (default: this checkout's)")
    args = ap.parse_args()
    dyn = args.src / "gearcli" / "dynamics"
    totals: dict[str, int] = {}
    for path in sorted(dyn.rglob("*.py")):
        name = part(path.relative_to(dyn).as_posix())
        totals[name] = totals.get(name, 0) + path.read_bytes().count(b"\n")
    for name in ("numpy reference inverse solver", "llvm generator", "losses (both paths)", "forward dynamics"):
        print(f"{name:32s} {totals.get(name, 0):6,d}")
    print(f"{'total':32s} {sum(totals.values()):6,d}")

if __name__ == "__main__":
    main()
