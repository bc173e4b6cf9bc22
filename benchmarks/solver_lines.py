"""Lines of the solver by part: the shared physics, the numpy path's own code, the generator's own.

Every ``*.py`` file's newline count under ``src/gearcli/dynamics`` (what ``find
src/gearcli/dynamics -name '*.py' | xargs wc -l`` sums), plus ``src/gearcli/algebra.py``
and the shared terms of ``src/gearcli/model/shaft.py``, split as issue 39 counts them:

* shared physics: the algebra (:mod:`gearcli.algebra`) and every function written over it
  (first parameter ``al``), which both paths call; and the column terms both paths sum
  (``dynamics/column_terms.py``, :data:`SHARED`);
* numpy-only: the rest of ``dynamics/`` (the numpy path's control flow: plans, sign search,
  block solves, fixed points; and the losses' and forward dynamics' drivers);
* generator-only: the rest of ``dynamics/llvm/`` (the generator's control flow and layouts).

Forward dynamics (``forward.py``, ``simulate.py``, ``llvm/mass.py``, ``stick_slip.py``) is
also shown on its own line, inside the two "-only" parts::

    python benchmarks/solver_lines.py [--src DIR]
"""
from __future__ import annotations

import argparse
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FORWARD = {"forward.py", "simulate.py", "llvm/mass.py", "stick_slip.py"}
SHARED = {"column_terms.py"}     # modules of shared physics as a whole (the terms' lists, not over al)


def shared_lines(path: Path) -> int:
    """Lines of the functions of ``path`` written over the algebra (first parameter ``al``),
    docstrings included; every line of the algebra module itself."""
    if path.name == "algebra.py" and path.parent.name == "gearcli":
        return path.read_bytes().count(b"\n")
    n = 0
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.FunctionDef) and node.args.args and node.args.args[0].arg == "al":
            n += node.end_lineno - node.lineno + 1 + len(node.decorator_list)
    return n


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--src", type=Path, default=ROOT / "src", help="the source tree (default: this checkout's)")
    args = ap.parse_args()
    pkg = args.src / "gearcli"
    dyn = pkg / "dynamics"
    totals = {"shared physics (both paths)": 0, "numpy-only": 0, "generator-only": 0}
    forward = 0
    files = sorted(dyn.rglob("*.py")) + [p for p in (pkg / "algebra.py", pkg / "model" / "shaft.py") if p.exists()]
    for path in files:
        lines = path.read_bytes().count(b"\n")
        rel = path.relative_to(dyn).as_posix() if dyn in path.parents else ""
        shared = lines if rel in SHARED else shared_lines(path)
        in_dyn = dyn in path.parents
        if not in_dyn:                          # algebra.py, model/shaft.py: their shared terms only
            totals["shared physics (both paths)"] += shared
            continue
        own = "generator-only" if rel.startswith("llvm/") else "numpy-only"
        totals["shared physics (both paths)"] += shared
        totals[own] += lines - shared
        if rel in FORWARD:
            forward += lines - shared
    for name, n in totals.items():
        print(f"{name:32s} {n:6,d}")
    print(f"{'total':32s} {sum(totals.values()):6,d}")
    print(f"{'  of which forward dynamics':32s} {forward:6,d}")


if __name__ == "__main__":
    main()
