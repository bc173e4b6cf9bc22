"""Gear pairs given without mesh geometry (ideal couplings) in YAML files.

Motor and joint torques depend only on the kinematics and the inertia, not on where the
tooth forces act, so an ideal version of paper_2dof (mesh points removed, same signed
ratios) must give the same motor torques as the geared file; its loads must still balance
every link, and the block schedule must agree with the full solve.
"""
from pathlib import Path

import numpy as np
import yaml

from gearcli.dynamics.solve import solve
from gearcli import analyse
from gearcli import load_mechanism, parse_mechanism

MECH = Path(__file__).resolve().parents[1] / "mechanisms"


def ideal_variant():
    geared = analyse(load_mechanism(MECH / "paper_2dof.yaml"))
    data = yaml.safe_load((MECH / "paper_2dof.yaml").read_text())
    ratio = {geared.mech.gears[c.gear].name: c.ratio for c in geared.circuits}
    for g in data["gears"]:
        for key in ("mesh_point", "teeth", "cone_angles_deg"):
            g.pop(key, None)
        g["ratio"] = ratio[g["name"]]
    return geared, analyse(parse_mechanism(yaml.safe_dump(data), "ideal.yaml"))


def test_ideal_pairs_give_the_same_motor_torques_and_balance():
    geared, ideal = ideal_variant()
    assert all(c.geometry is None for c in ideal.circuits)
    assert ideal.schedule and np.allclose(ideal.A, geared.A)
    rng = np.random.default_rng(11)
    q, qd, qdd = (rng.normal(size=(300, 2)) for _ in range(3))
    rg = solve(geared, q, qd, qdd)
    rb = solve(ideal, q, qd, qdd, verify=True)
    rf = solve(ideal, q, qd, qdd, method="full", verify=True)
    scale = np.abs(rg.motor).max()
    assert np.allclose(rb.motor, rg.motor, atol=1e-12 * scale)
    assert rb.residual < 1e-12 and rf.residual < 1e-12
    for f in ("motor", "joint", "gear_t"):
        a, b = getattr(rb, f), getattr(rf, f)
        assert np.allclose(a, b, atol=1e-12 * np.abs(b).max()), f
    # an ideal mesh torque on j equals the tooth force times j's pitch radius
    for ci, c in enumerate(geared.circuits):
        assert np.allclose(rb.gear_t[:, ci], rg.gear_t[:, ci] * c.geometry.r_j, atol=1e-9 * scale)
