"""The least work of bearing friction in the generated kernel (issue 19); prints figures, not a test.

    python benchmarks/bearing_floor.py [--samples 20000] [--rounds 7] [--cpu] [--bendix-only]

Whatever way a sample's bearing friction converges (fixed point, Newton, a closed form), it
computes at least once, at the converged reactions: each bearing joint's split of its reaction
(:func:`gearcli.dynamics.llvm.bearings.split`), each bearing's load magnitude (a square root)
and the joint's moment (:func:`~gearcli.dynamics.llvm.bearings.moment`), the couple passed on
to the links of later blocks, and the outputs.  This script generates a kernel that does only
that, once, from each block's solution without bearing friction: the generator is patched in
this process so that a block's solution does not move with its moments (no columns X w_J),
takes M = g(0) without iterating (no Newton level, no fixed point), starts from zero (no warm
start) and skips the tooth forces' fit test.  Its figures are wrong; it is timed only, against
the lossless and the mesh + joint friction kernels of the same run, interleaved, in this
thread (``--cpu``: by its CPU time).  So "floor over lossless" is the least any exact bearing
friction solve can cost in this kernel's design, and "floor over mesh + joint" what the
bearing model's own arithmetic adds to mesh and joint friction.

The patched kernels are cached only in a directory of their own, made for the run and removed
after it (``GEARCLI_CACHE_DIR`` is always replaced): they never reach a user's kernel cache.
``bench_losses.py`` runs this script as a child process after its own rows.
"""
from __future__ import annotations

import atexit
import os
import shutil
import sys
import tempfile

_CACHE = tempfile.mkdtemp(prefix="gearcli-bearing-floor-")
os.environ["GEARCLI_CACHE_DIR"] = _CACHE       # before gearcli is imported: never the user's cache
atexit.register(shutil.rmtree, _CACHE, True)   # however the script ends (--help, an error)

import time  # noqa: E402
from pathlib import Path  # noqa: E402

import llvmlite.ir as ir  # noqa: E402
import numpy as np  # noqa: E402
from bench_losses import OTHERS, common_args, lossless, lossy, smooth  # noqa: E402 (benchmarks/)
from timing import load_line, median_time  # noqa: E402

import gearcli.dynamics.llvm.bearings as generated  # noqa: E402
from gearcli import analyse, load_mechanism, solve  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def patch_floor() -> None:
    """Make the generator emit the floor (module docstring) instead of the converged bearing
    friction, for every kernel generated after this call in this process."""
    def affine(e, jt, r, solve_block, rows, world, tag):        # x = x0: no columns X w_J
        x0, p = solve_block(r, tag)
        return x0, p, [[0.0] * len(x0) for _ in jt.sg]

    def fits(e, fn, tag, jt, r, p, t, Mb, to):                  # no fit test
        e.b.cbranch(ir.Constant(generated.I1, 1), *to)
        return e.b.block

    for name in ("_affine", "_warm", "_fits"):
        if not callable(getattr(generated, name, None)):
            raise SystemExit(f"bearing_floor: the generator has no {name} to patch any more; update this script")
    generated._affine = affine          # constant loads: bearing_newton.unaffected, M = g(0) once
    generated._warm = lambda e, lp, bb, jt, n: [ir.Constant(generated.D, 0.0) for _ in bb.joints]
    generated._fits = fits


def rows_of(name: str) -> dict:
    mech = lossless(load_mechanism(ROOT / "mechanisms" / name))
    return {"lossless": analyse(mech), "mesh + joint": analyse(lossy(mech, False)),
            "floor": analyse(lossy(mech, True))}


def measure(rows: dict, states: tuple, args) -> dict:
    """Median seconds per row, rounds interleaved, each round's figure the median of 5 calls;
    first a check that the floor row runs the patched kernel (its bearing friction off the numpy
    path's converged one, which the unpatched kernel equals to 1e-12)."""
    for an in rows.values():
        solve(an, *(a[:100] for a in states), backend="llvm", jobs=1)
    head = tuple(a[:100] for a in states)
    off = np.abs(solve(rows["floor"], *head, backend="llvm").joint_friction
                 - solve(rows["floor"], *head, backend="numpy").joint_friction).max()
    if not off > 1e-9:
        raise SystemExit(f"bearing_floor: the floor kernel converged its bearing friction (off by {off:.1e}): "
                         "the generator's patch did not take")
    clock = time.thread_time if args.cpu else time.perf_counter
    times = {k: [] for k in rows}
    for _ in range(args.rounds):
        for k, an in rows.items():
            times[k].append(median_time(lambda: solve(an, *states, backend="llvm", jobs=1), 5, clock))
    return {k: float(np.median(v)) for k, v in times.items()}


def line(label: str, med: dict) -> str:
    base = med["lossless"]
    return (f"  {label:44s} lossless {base * 1e3:5.1f} ms, mesh + joint {med['mesh + joint'] / base:5.2f}x, "
            f"bearing floor {med['floor'] / base:5.2f}x lossless = {med['floor'] / med['mesh + joint']:5.2f}x "
            f"mesh + joint")


def main(argv=None) -> int:
    args = common_args(__doc__.splitlines()[0]).parse_args(argv)
    patch_floor()
    print(f"Bearing friction's floor in the generated kernel (evaluated once, not converged: "
          f"figures wrong, timed only), {args.samples:,} samples, 1 thread, medians of {args.rounds}"
          f"{', thread CPU time' if args.cpu else ''}; {load_line()}")
    rng = np.random.default_rng(0)
    bendix = rows_of("bendix_wrist_rated.yaml")
    states = tuple(rng.uniform(-3, 3, (args.samples, bendix["lossless"].dof)) for _ in range(3))
    print(line("bendix_wrist_rated, random states", measure(bendix, states, args)), flush=True)
    print(line("bendix_wrist_rated, smooth motion", measure(bendix, smooth(args.samples), args)), flush=True)
    for name in () if args.bendix_only else OTHERS:
        rows = rows_of(name)
        if not any(j.bearings for j in rows["lossless"].mech.joints):
            continue
        states = tuple(rng.uniform(-3, 3, (args.samples, rows["lossless"].dof)) for _ in range(3))
        print(line(f"{name.removesuffix('.yaml')}, random states", measure(rows, states, args)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
