"""What the generated llvm kernel costs to make, against the numba kernel's start; prints figures.

    python benchmarks/bench_compile.py [--repeat 3]

Per mechanism (paper_2dof, Bendix wrist, planetary_3p, UR5, Panda, Talos full), each
measurement in a fresh Python process (medians over --repeat): the llvm kernel's IR
generation and LLVM optimisation + machine code (``LlvmKernel.build_seconds``,
``compile_seconds``), the size of its IR, the first ``solve(backend="llvm")`` of 100
samples (import of llvmlite included) and the first ``solve(backend="kernel")`` of 100
samples (numba import and its compiled code from the disk cache), and the estimate
"auto" uses (:func:`gearcli.dynamics.backends.llvm_compile_estimate`).  Load average at
the start and the end.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
from timing import load_line  # noqa: E402 (benchmarks/timing.py)

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import json, sys, time
t0 = time.perf_counter()
import numpy as np
from gearcli import analyse, load_mechanism, solve
from gearcli.dynamics.solve import solver_for
from gearcli.dynamics.backends import llvm_compile_estimate
path, backend = sys.argv[1], sys.argv[2]
an = analyse(load_mechanism(path))
q = np.zeros((100, an.dof))
t1 = time.perf_counter()
solve(an, q, q, q, backend=backend, jobs=1)
t2 = time.perf_counter()
out = {"first": t2 - t1, "estimate": llvm_compile_estimate(an)}
if backend == "llvm":
    k = solver_for(an).llvm_kernel()
    out.update(build=k.build_seconds, compile=k.compile_seconds, ir_kb=len(k.jit.ir) / 1e3,
               instructions=k.jit.ir.count("\\n  %"))
print(json.dumps(out))
"""


def subjects() -> list[tuple[str, Path]]:
    out = [(name, ROOT / "mechanisms" / f"{name}.yaml") for name in ("paper_2dof", "bendix_wrist", "planetary_3p")]
    for p in map(Path, sys.path):
        d = p / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if d.is_dir():
            out += [("UR5", d / "ur_description/urdf/ur5_robot.urdf"), ("Panda", d / "panda_description/urdf/panda.urdf"),
                    ("Talos full", d / "talos_data/robots/talos_full_v2.urdf")]
            break
    return out


def child(path: Path, backend: str) -> dict:
    r = subprocess.run([sys.executable, "-c", CHILD, str(path), backend], capture_output=True, text=True, check=True,
                       env={"PYTHONPATH": str(ROOT / "src"), "PATH": "/usr/bin:/bin"})
    return json.loads(r.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    print(f"# llvm kernel: compile cost, fresh processes, medians of {args.repeat}\n{load_line()} at start\n")
    print("| mechanism | moving links | IR build | LLVM (O3) | IR size | instructions | first llvm solve | "
          "first kernel solve (numba cache) | auto's estimate |\n|---|---|---|---|---|---|---|---|---|")
    for name, path in subjects():
        runs = [child(path, "llvm") for _ in range(args.repeat)]
        kern = [child(path, "kernel")["first"] for _ in range(args.repeat)]
        med = {k: float(np.median([r[k] for r in runs])) for k in runs[0]}
        from gearcli import analyse, load_mechanism  # noqa: PLC0415
        links = len(analyse(load_mechanism(path)).tree.moving)
        print(f"| {name} | {links} | {med['build']:.3f} s | {med['compile']:.3f} s | {med['ir_kb']:.0f} kB | "
              f"{med['instructions']:.0f} | {med['first']:.2f} s | {np.median(kern):.2f} s | {med['estimate']:.2f} s |",
              flush=True)
    print(f"\n{load_line()} at end")


if __name__ == "__main__":
    main()
