"""Speed of mechanisms with drive elements (issues 35, 36); prints figures, not a test.

    python benchmarks/bench_drive_elements.py [--samples 20000] [--rounds 5]

The generated kernel (backend llvm, one thread) on random states of

* mechanisms/cobot_joint.yaml (one lossy strain-wave reducer: a world-frame block with the
  power-flow sign, the no-load torque, a crossed-roller joint),
* mechanisms/cobot_6axis.yaml (six lossy strain-wave reducers, 13 links),
* their lossless twins (efficiencies 1, no no-load torque),
* mechanisms/screw_lift.yaml (a lossy ball screw: a world-frame block with its power-flow sign)
  and mechanisms/worm_lift.yaml (a self-locking worm pair: its friction force at the contact),
* mechanisms/scara.yaml (a lossy belt, strain-wave gear and ball screw; random states within
  its belt's pretension: |E| stays below 2 T_i for the rates and accelerations drawn here),
* mechanisms/bendix_wrist.yaml, the reference point (issue 35's target: each reducer
  mechanism at least 0.5x its samples/s in the same run; issue 36's the same for the worm
  joint),

rows interleaved round by round so that load drift hits all alike, medians of --rounds of the
median of 3 calls, with the load average.  The kernels are compiled (or loaded from the disk
cache) before timing.
"""
from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np
from timing import load_line, median_time  # noqa: E402 (benchmarks/timing.py)

from gearcli import analyse, load_mechanism, solve

ROOT = Path(__file__).resolve().parents[1]


def lossless(mech):
    """``mech`` with its reducers' losses removed."""
    return dataclasses.replace(mech, gears=tuple(
        dataclasses.replace(g, reducer=g.reducer.lossless()) if g.reducer is not None else g for g in mech.gears))


NAMES = ("bendix_wrist", "cobot_joint", "cobot_6axis", "screw_lift", "worm_lift", "scara")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=20000)
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    mechs = {name: load_mechanism(ROOT / "mechanisms" / f"{name}.yaml")
             for name in NAMES}
    rows = {"bendix_wrist": mechs["bendix_wrist"]}
    for name in ("cobot_joint", "cobot_6axis"):
        rows[name] = mechs[name]
        rows[f"{name} (lossless)"] = lossless(mechs[name])
    rows["screw_lift"], rows["worm_lift"], rows["scara"] = mechs["screw_lift"], mechs["worm_lift"], mechs["scara"]
    rng = np.random.default_rng(0)
    cases = {}
    for name, mech in rows.items():
        an = analyse(mech)
        n = args.samples
        q, qd, qdd = (rng.uniform(-2, 2, (n, an.dof)), rng.uniform(-2, 2, (n, an.dof)), rng.uniform(-5, 5, (n, an.dof)))
        if name == "scara":              # (solve does not refuse a slack belt; keep it plausible)
            q, qd, qdd = q * 0.5, qd * 0.5, qdd * 0.5
        res = solve(an, q[:10], qd[:10], qdd[:10], backend="llvm", jobs=1)       # compile (or load) first
        assert res.backend == "llvm"
        cases[name] = lambda an=an, q=q, qd=qd, qdd=qdd: solve(an, q, qd, qdd, backend="llvm", jobs=1)
    times = {name: [] for name in cases}
    for _ in range(args.rounds):
        for name, fn in cases.items():
            times[name].append(median_time(fn, 3))
    print(f"{args.samples:,} random samples a call, llvm, one thread; medians of {args.rounds} rounds; {load_line()}")
    ref = args.samples / float(np.median(times["bendix_wrist"]))
    for name, ts in times.items():
        rate = args.samples / float(np.median(ts))
        print(f"  {name:28s} {rate:12,.0f} samples/s   {rate / ref:5.2f}x the Bendix wrist")


if __name__ == "__main__":
    main()
