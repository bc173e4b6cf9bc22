"""What losses cost in the solve (issue 19); prints figures, not a test.

    python benchmarks/bench_losses.py [--samples 20000] [--rounds 5] [--cpu] [--bendix-only]

The rated Bendix wrist (5 meshes, 8 joints, 15 bearings), random states, one thread.  Rows,
interleaved round by round so that load drift hits all alike, medians of --rounds (an llvm
row's round: the median of 5 calls, a call of a few ms being at the mercy of one scheduler
tick on a busy machine):

* lossless, numpy and the compiled llvm kernel (the reference points);
* mesh + joint friction (every mesh at 3 % loss, every joint with Coulomb + viscous friction),
  numpy: the couples ride in the tooth-force columns (one extra set of block maps per pattern
  of relative-speed signs met); llvm: each block's sign search over the stored maps of the
  sample's relative-speed signs (:mod:`gearcli.dynamics.llvm.losses`), the joint friction and
  the loss outputs computed in the kernel;
* the same with bearing friction on every bearing (mu 0.0015, bore 20 mm), numpy and llvm:
  a fixed-point iteration per sample, whose iterations are printed (median and worst); numpy:
  :func:`gearcli.dynamics.bearing_friction.fixed_point`, every joint at once; llvm: inside the
  kernel, block by block (:mod:`gearcli.dynamics.llvm.bearings`), by Newton's method on each
  constant-frame block's moments (:mod:`gearcli.dynamics.llvm.bearing_newton`), a sample's
  count the most levels over its blocks;
* llvm lossless and with bearing friction along a smooth motion (the analytic motion of
  mechanisms/bendix_wrist_traj.csv, continued to --samples at 1 kHz): random states give the
  kernel's warm start (a block's fixed point from the samples before) nothing to start from.

Then (unless --bendix-only) the same losses on the many-mesh blocks of :data:`OTHERS`, each
llvm over its own lossless kernel.  Last (unless --no-floor), in a child process with a patched
generator and a kernel cache of its own, :mod:`bearing_floor`: the bearing friction model
evaluated once per sample and not converged, the least any exact bearing friction solve costs
in this kernel, over its own lossless and mesh + joint kernels.

The cost of losses in the compiled path (issue 19's target: at most 20 %) is each llvm row
over the lossless llvm row of the same run.  ``--cpu``: each call timed by this thread's CPU
time instead of the wall clock (every row runs in this thread: one thread, one BLAS thread);
on a busy machine the wall clock also counts the other processes' turns (load 5: the
lossless llvm row 4.4 to 8.1 ms from run to run, its CPU time 4.2 to 4.5 ms at load 6).
"""
from __future__ import annotations

import argparse
import dataclasses
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from timing import load_line, median_time  # noqa: E402 (benchmarks/timing.py)

from gearcli import analyse, load_mechanism, solve
from gearcli.model.friction import JointFriction

ROOT = Path(__file__).resolve().parents[1]


def lossy(mech, bearings: bool):
    gears = tuple(dataclasses.replace(g, loss_factor=0.03) for g in mech.gears)
    joints = tuple(dataclasses.replace(
        j, friction=JointFriction(0.02, 1e-4),
        bearings=tuple(dataclasses.replace(b, friction_coefficient=0.0015, bore=0.02) for b in j.bearings)
        if bearings and j.bearings else j.bearings) for j in mech.joints)
    return dataclasses.replace(mech, gears=gears, joints=joints)


def lossless(mech):
    """``mech`` without any loss (its own efficiencies and frictions removed)."""
    joints = tuple(dataclasses.replace(j, friction=None, bearings=tuple(
        dataclasses.replace(b, friction_coefficient=None) for b in j.bearings) if j.bearings else j.bearings)
        for j in mech.joints)
    return dataclasses.replace(mech, gears=tuple(dataclasses.replace(g, loss_factor=0.0) for g in mech.gears),
                               joints=joints)


OTHERS = ("planetary_3p_rated.yaml", "planetary_5p.yaml", "servo_joint_rated.yaml")
"""Many-mesh blocks: a 32-unknown constant-frame block with stored maps (3 planets), one from
a low-rank base matrix (5 planets: 1,024 sign patterns), a redundant world-frame one (the
servo joint)."""


def others(args) -> None:
    """llvm, lossless against :func:`lossy` (mesh + joint, then + bearing friction) on each
    of :data:`OTHERS` (their own losses removed first), interleaved, random states."""
    rng = np.random.default_rng(0)
    for name in OTHERS:
        mech = lossless(load_mechanism(ROOT / "mechanisms" / name))
        rows = {"lossless": analyse(mech), "mesh + joint": analyse(lossy(mech, False))}
        if any(j.bearings for j in mech.joints):
            rows["+ bearing"] = analyse(lossy(mech, True))
        q, qd, qdd = (rng.uniform(-3, 3, (args.samples, rows["lossless"].dof)) for _ in range(3))
        for an in rows.values():
            solve(an, q[:100], qd[:100], qdd[:100], backend="llvm", jobs=1)
        times = {k: [] for k in rows}
        for _ in range(args.rounds):
            for k, an in rows.items():
                times[k].append(median_time(lambda: solve(an, q, qd, qdd, backend="llvm", jobs=1), 5,
                                            time.thread_time if args.cpu else time.perf_counter))
        med = {k: float(np.median(v)) for k, v in times.items()}
        bearing = f"{med['+ bearing'] / med['lossless']:.2f}x" if "+ bearing" in med else "(no bearings)"
        print(f"  {name:26s} llvm lossless {med['lossless'] * 1e3:6.1f} ms, mesh + joint friction "
              f"{100 * (med['mesh + joint'] / med['lossless'] - 1):+4.0f} %, + bearing friction {bearing}")


def common_args(description: str) -> argparse.ArgumentParser:
    """The options this script shares with bearing_floor.py."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--samples", type=int, default=20_000)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--cpu", action="store_true", help="time by this thread's CPU time, not the wall clock")
    ap.add_argument("--bendix-only", action="store_true", help="leave out the many-mesh blocks (planetaries, servo joint)")
    return ap


def main(argv=None) -> int:
    ap = common_args(__doc__.splitlines()[0])
    ap.add_argument("--no-floor", action="store_true", help="leave out bearing_floor.py's rows (bearing friction's least cost)")
    args = ap.parse_args(argv)
    mech = load_mechanism(ROOT / "mechanisms" / "bendix_wrist_rated.yaml")
    cases = {"lossless, llvm": (analyse(mech), "llvm"), "lossless, numpy": (analyse(mech), "numpy"),
             "mesh + joint friction, numpy": (analyse(lossy(mech, False)), "numpy"),
             "+ bearing friction, numpy": (analyse(lossy(mech, True)), "numpy")}
    cases["mesh + joint friction, llvm"] = (cases["mesh + joint friction, numpy"][0], "llvm")
    cases["+ bearing friction, llvm"] = (cases["+ bearing friction, numpy"][0], "llvm")
    rng = np.random.default_rng(0)
    dof = cases["lossless, numpy"][0].dof
    q, qd, qdd = (rng.uniform(-3, 3, (args.samples, dof)) for _ in range(3))
    states = {k: (q, qd, qdd) for k in cases}
    cases["lossless, llvm, smooth motion"] = cases["lossless, llvm"]
    cases["+ bearing friction, llvm, smooth motion"] = cases["+ bearing friction, llvm"]
    states["lossless, llvm, smooth motion"] = states["+ bearing friction, llvm, smooth motion"] = smooth(args.samples)
    for an, backend in cases.values():                 # warm up: compile, plans, caches
        solve(an, q[:100], qd[:100], qdd[:100], backend=backend, jobs=1)
    times = {k: [] for k in cases}
    for _ in range(args.rounds):
        for name, (an, backend) in cases.items():
            reps = 5 if backend == "llvm" else 1           # a few ms: the median of 5 calls a round
            times[name].append(median_time(lambda: solve(an, *states[name], backend=backend, jobs=1), reps,
                                           time.thread_time if args.cpu else time.perf_counter))
    print(f"Bendix wrist (rated), {args.samples:,} random samples, 1 thread, medians of {args.rounds}"
          f"{', thread CPU time' if args.cpu else ''}; {load_line()}")
    base = float(np.median(times["lossless, numpy"]))
    fast = float(np.median(times["lossless, llvm"]))
    for name, ts in times.items():
        t = float(np.median(ts))
        ref = float(np.median(times["lossless, llvm, smooth motion"])) if "smooth" in name else fast
        print(f"  {name:40s} {t * 1e3:9.1f} ms  {args.samples / t:12,.0f} samples/s  {t / base:6.3f}x numpy lossless"
              f"  {t / ref:6.2f}x llvm lossless{' (smooth)' if 'smooth' in name else ''}")
    for name in ("mesh + joint friction, llvm", "+ bearing friction, llvm"):
        print(f"  cost of losses in the compiled path, {name.split(',')[0]}: "
              f"{100 * (float(np.median(times[name])) / fast - 1):+.0f} % (target: at most +20 %)")
    res = solve(cases["+ bearing friction, numpy"][0], q, qd, qdd, backend="numpy")
    it = res.bearing_iterations
    print(f"  bearing friction iterations per sample: median {int(np.median(it))}, worst {int(it.max())}")
    fast_it = solve(cases["+ bearing friction, llvm"][0], q, qd, qdd, backend="llvm").bearing_iterations
    print(f"  (llvm, the most over a sample's blocks: median {int(np.median(fast_it))}, worst {int(fast_it.max())})")
    it = solve(cases["+ bearing friction, llvm"][0], *smooth(args.samples), backend="llvm").bearing_iterations
    print(f"  (llvm, smooth motion: median {int(np.median(it))}, worst {int(it.max())}, mean {it.mean():.2f})")
    if not args.bendix_only:
        print(f"Many-mesh blocks, the same losses, {args.samples:,} random samples, llvm over its lossless kernel:")
        others(args)
    if not args.no_floor:
        sys.stdout.flush()
        flags = (["--cpu"] if args.cpu else []) + (["--bendix-only"] if args.bendix_only else [])
        subprocess.run([sys.executable, str(Path(__file__).with_name("bearing_floor.py")), "--samples",
                        str(args.samples), "--rounds", str(args.rounds), *flags], check=True)
    return 0


def smooth(n: int):
    """q, qd, qdd (n, 3) of mechanisms/make_trajectories.py's Bendix wrist motion at 1 kHz."""
    t = np.arange(n)[:, None] * 1e-3
    A, f, ph = np.array([1.0, 0.7, 2.0]), np.array([1.0, 1.5, 0.75]) * np.pi, np.array([0.0, 0.5, 1.0])
    return A * np.sin(f * t + ph), A * f * np.cos(f * t + ph), -A * f**2 * np.sin(f * t + ph)


if __name__ == "__main__":
    sys.exit(main())
