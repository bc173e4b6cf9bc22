"""The same mechanism written in other frames gives the same loads (issue 34, section 6).

Every link frame is turned by a random rotation (the base too, with gravity), and every
joint frame is spun about its own axis: the physics is unchanged, so every frame-free
output (motor torques, tooth forces, friction, losses, forward accelerations) must be
too.  The trajectory holds J2 still while J1 swings: gears 3, 4 and 2 then rest on their
carrier, link 1, and a friction couple must stay off however the world vectors round.
The turned mechanism is written here from the model's definition of the frames
(``child = parent * X_pj * Rz(q) * X_jc``), sharing no code with gearcli's kinematics.
"""
from __future__ import annotations

import dataclasses as dc
from pathlib import Path

import numpy as np
import pytest

import gearcli
from gearcli.dynamics.kinematics import forward
from gearcli.dynamics.solve import joint_space

ROOT = Path(__file__).resolve().parents[1]


def _rot(rng) -> np.ndarray:
    """A random rotation matrix (QR of a Gaussian matrix, det +1)."""
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    return Q if np.linalg.det(Q) > 0 else -Q


def _rz(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def turned(mech, seed: int):
    """``mech`` with each link frame F_i turned to F_i Q_i and each joint frame spun about
    its axis by a random angle: coms, inertias, joint placements, mesh points (in their
    carrier's frame) and gravity (in the base frame) rewritten to match."""
    rng = np.random.default_rng(seed)
    Q = {L.name: _rot(rng) for L in mech.links}
    spin = {j.name: _rz(rng.uniform(-3.0, 3.0)) for j in mech.joints}
    links = tuple(dc.replace(L, com=Q[L.name].T @ L.com, inertia=Q[L.name].T @ L.inertia @ Q[L.name])
                  for L in mech.links)
    joints = tuple(dc.replace(j, R_pj=Q[j.parent].T @ j.R_pj @ spin[j.name], p_pj=Q[j.parent].T @ j.p_pj,
                              R_jc=spin[j.name].T @ j.R_jc @ Q[j.child], p_jc=spin[j.name].T @ j.p_jc)
                   for j in mech.joints)
    an = gearcli.analyse(mech)
    carrier = {c.gear: mech.links[c.carrier].name for c in an.circuits}
    gears = tuple(gp if gp.mesh_point is None else
                  dc.replace(gp, mesh_point=Q[carrier[gi]].T @ gp.mesh_point)
                  for gi, gp in enumerate(mech.gears))
    return dc.replace(mech, gravity=Q[mech.base].T @ mech.gravity, links=links, joints=joints, gears=gears)


def _lossy_arm():
    mech = gearcli.load_mechanism(ROOT / "mechanisms" / "paper_2dof.yaml")
    return dc.replace(mech, gears=tuple(dc.replace(gp, loss_factor=0.05) for gp in mech.gears))


def _hold_j2(n: int = 60):
    """J1 swings through zero rate and back while J2 holds still (an exact 0 rate)."""
    t = np.linspace(0.0, 2.0, n)
    q = np.column_stack([np.sin(2 * t), np.full(n, 0.3)])
    qd = np.column_stack([2 * np.cos(2 * t), np.zeros(n)])
    qdd = np.column_stack([-4 * np.sin(2 * t), np.zeros(n)])
    return q, qd, qdd


@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_mesh_friction_of_a_gear_at_rest_on_its_carrier_does_not_depend_on_the_frames(backend):
    mech = _lossy_arm()
    a, b = gearcli.analyse(mech), gearcli.analyse(turned(mech, seed=3))
    q, qd, qdd = _hold_j2()
    ra = gearcli.solve(a, q, qd, qdd, backend=backend)
    rb = gearcli.solve(b, q, qd, qdd, backend=backend)
    scale = np.abs(ra.motor).max()
    assert np.abs(ra.motor - rb.motor).max() <= 1e-12 * scale
    assert np.abs(ra.gear_t - rb.gear_t).max() <= 1e-12 * np.abs(ra.gear_t).max()
    assert np.abs(ra.gear_loss - rb.gear_loss).max() <= 1e-12 * np.abs(ra.gear_loss).max()
    # the bevel pairs rest on link 1: no mesh loss at all, in either frames
    assert not ra.gear_loss[:, 1:].any() and not rb.gear_loss[:, 1:].any()


def test_forward_dynamics_of_a_gear_at_rest_on_its_carrier_does_not_depend_on_the_frames():
    mech = _lossy_arm()
    a, b = gearcli.analyse(mech), gearcli.analyse(turned(mech, seed=5))
    q, qd, qdd = _hold_j2(20)
    tau = gearcli.solve(a, q, qd, qdd, backend="numpy").motor
    for backend in ("numpy", "llvm"):
        fa = gearcli.forward_dynamics(a, q, qd, tau, backend=backend)
        fb = gearcli.forward_dynamics(b, q, qd, tau, backend=backend)
        assert np.abs(fa - qdd).max() <= 1e-9 * np.abs(qdd).max()
        assert np.abs(fa - fb).max() <= 1e-9 * np.abs(qdd).max()


def _bundled():
    return sorted((ROOT / "mechanisms").glob("*.yaml"))


@pytest.mark.parametrize("path", _bundled(), ids=lambda p: p.stem)
def test_mesh_rate_rows_give_the_relative_angular_velocity(path):
    """theta'_{j,c} from the joint rates equals (omega_j - omega_c) . z_j from the
    kinematics' world angular velocities, at random states, on every bundled mechanism."""
    try:
        an = gearcli.analyse(gearcli.load_mechanism(path))
    except gearcli.GearcliError:
        pytest.skip("not a mechanism on its own")
    rng = np.random.default_rng(7)
    qi, qdi = rng.uniform(-3, 3, (40, an.dof)), rng.normal(size=(40, an.dof)) * 4
    q, qd, _ = joint_space(an, qi, qdi)
    kin = forward(an.mech, an.tree, q, qd)
    for ci, c in enumerate(an.circuits):
        if c.row_j is None or c.geometry is None:
            continue
        zj = np.einsum("nij,j->ni", kin.R[c.carrier], c.zj)
        world = np.sum((kin.w[c.j] - kin.w[c.carrier]) * zj, axis=1)
        assert np.abs(qdi @ an.mesh_rate_rows[ci] - world).max() <= 1e-12 * max(1.0, np.abs(world).max())
