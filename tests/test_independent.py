"""Cross-checks against references that share no code with gearcli's kinematics or dynamics.

The references come from :mod:`oracles`: link frames as the test's own product of the
paper's Eq. (1) D-H matrices (non-zero twists alpha and offsets theta) or of its own
transforms; velocities and accelerations by central differences of those positions and
orientations only; Pinocchio models built from the same own transforms; joint coupling and
structure matrix from the factories' own rolling ratios.  gearcli is used only through its
public API (``parse_mechanism``, ``load_mechanism``, ``analyse``, ``solve``) and
``dynamics.kinematics.forward`` for its link frames.
"""
from __future__ import annotations

import tempfile
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest

from factories_own import PUMA_YAML, dh_geared, puma_own, spatial_own, urdf_prismatic_chain
from gearcli import analyse, load_mechanism, parse_mechanism, solve
from gearcli.dynamics.kinematics import forward
from metrics import rel_err
from oracles import OwnPinocchio, SineTrajectory, fd_motion, joint_frames, kinetic_power, momentum_rates, poses

TOL = 1e-9        # exact references (frames, Pinocchio)
TOL_FD = 1e-6     # five-point differences, h = 2e-3 s: measured errors ~1e-9 (O(h^4) + rounding/h^2)


@lru_cache(maxsize=None)
def case(key: str):
    """(Analysis, OwnMech) of a mechanism and the test's own description of it."""
    name, _, seed = key.partition(":")
    if name == "puma":
        return analyse(parse_mechanism(PUMA_YAML)), puma_own()
    if name == "dh_geared":
        text, om = dh_geared(int(seed))
        return analyse(parse_mechanism(text)), om
    if name == "spatial":
        text, om = spatial_own()
        return analyse(parse_mechanism(text)), om
    if name == "urdf_chain":
        text, om = urdf_prismatic_chain(int(seed))
        path = Path(tempfile.mkdtemp(prefix="gearcli-test-")) / "chain.urdf"
        path.write_text(text)
        return analyse(load_mechanism(path)), om
    raise KeyError(key)


DH = ["puma", "dh_geared:0", "dh_geared:1", "dh_geared:2"]
ALL = DH + ["urdf_chain:0", "urdf_chain:1", "spatial"]
BASE_FRAMES_KNOWN = DH + ["urdf_chain:0", "urdf_chain:1"]   # base joints: D-H or axis z


def joint_order(an, om) -> list[int]:
    """Position in ``om.joints`` of every gearcli joint (gearcli's order)."""
    assert list(an.independent_names) == [f"J{i}" for i in (1, 2, 3)]
    return [om.joint_names.index(jt.name) for jt in an.mech.joints]


def own_A(an, om) -> np.ndarray:
    """Structure matrix from the factory's own input rotations: tau = A motor."""
    return np.column_stack([om.motors[m.name][1] for m in an.mech.motors])


def random_q(dof, n=40, seed=0):
    q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (n, dof))
    q[0] = 0.0
    return q


# --- 1. link frames: gearcli vs the test's own Eq. (1) product ----------------------------------

@pytest.mark.parametrize("key", ALL)
def test_link_frames_match_own_product(key):
    an, om = case(key)
    if key in DH:   # the twists are really exercised
        assert any(abs(np.sin(j.dh[3])) > 0.25 for j in om.joints if j.dh is not None)
        assert any(abs(np.sin(j.dh[0])) > 0.25 for j in om.joints if j.dh is not None) or key == "puma"
    q_all = random_q(an.dof) @ om.S.T
    kin = forward(an.mech, an.tree, q_all[:, joint_order(an, om)])
    T = poses(om, q_all)
    for name in om.links:
        L = an.tree.index[name]
        assert rel_err(kin.R[L], T[name][:, :3, :3]) < TOL, name
        assert rel_err(kin.o[L], T[name][:, :3, 3]) < TOL, name


@pytest.mark.parametrize("key", BASE_FRAMES_KNOWN)
def test_joint_frames_of_base_joints(key):
    """The documented joint frame: Rz(theta + q) Tz(d) of the parent for D-H, the URDF
    joint frame for an axis along z; the bearing reactions of the balances below use it."""
    an, om = case(key)
    q_all = random_q(an.dof, seed=1) @ om.S.T
    kin = forward(an.mech, an.tree, q_all[:, joint_order(an, om)])
    F = joint_frames(om, q_all)
    for ji, jt in enumerate(an.mech.joints):
        if jt.parent == om.base or key in DH:
            assert rel_err(kin.Rj[ji], F[jt.name][:, :3, :3]) < TOL, jt.name
            assert rel_err(kin.oj[ji], F[jt.name][:, :3, 3]) < TOL, jt.name


# --- 2. Pinocchio on a model built from the test's own D-H product -------------------------------

@pytest.mark.parametrize("key", DH + ["urdf_chain:0"])
@pytest.mark.parametrize("method", ["block", "full"])
def test_own_pinocchio_rnea(key, method):
    """RNEA of the own model, projected by virtual work (tau_ind = S^T tau_all with the
    factory's own S), gives gearcli's equivalent torques; motor torques follow from the own
    structure matrix."""
    pytest.importorskip("pinocchio")
    an, om = case(key)
    traj = SineTrajectory(an.dof, seed=3)
    q, qd, qdd = traj(np.linspace(0.0, 2.0, 30))
    res = solve(an, q, qd, qdd, method=method)
    tau_all, f = OwnPinocchio(om).rnea(q @ om.S.T, qd @ om.S.T, qdd @ om.S.T)
    tau_ind = tau_all @ om.S
    assert rel_err(res.tau, tau_ind) < TOL
    assert rel_err(res.motor, np.linalg.solve(own_A(an, om), tau_ind.T).T) < TOL
    if key == "puma":   # no gears: the bearing reactions are Pinocchio's transmitted wrenches
        order = joint_order(an, om)
        assert rel_err(res.joint[:, :, :5], f[:, order, :5]) < TOL
        assert rel_err(res.motor, f[:, order, 5]) < TOL


# --- 3. power and momentum balances on differentiated positions ------------------------------------

@lru_cache(maxsize=None)
def fd_case(key, method="block"):
    an, om = case(key)
    traj = SineTrajectory(an.dof, seed=11)
    t = np.linspace(0.0, 3.0, 40)
    q, qd, qdd = traj(t)
    return an, om, q, qd, qdd, solve(an, q, qd, qdd, method=method), fd_motion(om, traj, t)


@pytest.mark.parametrize("key", ALL)
def test_power_balance_own_kinematics(key):
    """sum(motor torque x input rate relative to the stator) = dT/dt - sum m g.v_c, with
    v_c, a_c, w, dw differentiated from the own link poses."""
    an, om, q, qd, qdd, res, st = fd_case(key)
    dT, Pg = kinetic_power(st, om.gravity)
    rates = qd @ own_A(an, om)                     # (N, M): input rotations' rates
    assert rel_err(np.sum(res.motor * rates, axis=1), dT - Pg) < TOL_FD
    assert rel_err(np.sum(res.tau * qd, axis=1), dT - Pg) < TOL_FD


@pytest.mark.parametrize("key", BASE_FRAMES_KNOWN)
@pytest.mark.parametrize("method", ["block", "full"])
def test_momentum_balance_own_kinematics(key, method):
    """The base acts on the moving links through its bearings and the motor stators it
    holds (no gear is fixed to it here).  With the reactions rotated by the own joint frames,
    their resultant plus gravity equals the rate of change of the total linear momentum, and
    their moment about the world origin that of the angular momentum, both differentiated
    from the own link poses."""
    an, om, q, qd, qdd, res, st = fd_case(key, method)
    q_all = q @ om.S.T
    F = joint_frames(om, q_all)
    g = np.asarray(om.gravity, float)
    F_ext = sum(s["m"] * g for s in st.values())
    M_ext = sum(np.cross(s["x"], s["m"] * g) for s in st.values())
    for ji, jt in enumerate(an.mech.joints):
        if jt.parent != om.base:
            continue
        R, o = F[jt.name][:, :3, :3], F[jt.name][:, :3, 3]
        f = np.einsum("nij,nj->ni", R, res.joint[:, ji, :3])
        F_ext = F_ext + f
        M_ext = M_ext + np.cross(o, f) + np.einsum("nij,nj->ni", R, res.joint[:, ji, 3:])
    for mi, m in enumerate(an.mech.motors):
        jt = om.joints[om.joint_names.index(om.motors[m.name][0])]
        if jt.parent == om.base:
            assert jt.kind == "revolute"      # stator on the base: the motor torque enters from outside
            M_ext = M_ext + res.motor[:, mi, None] * F[jt.name][:, :3, 2]
    dP, dH = momentum_rates(st)
    assert rel_err(F_ext, dP) < TOL_FD
    assert rel_err(M_ext, dH) < TOL_FD


# --- 4. the tooth force of Eq. (14) in the test's own geometry -------------------------------------

@pytest.mark.parametrize("key", ["dh_geared:0", "dh_geared:1", "spatial"])
def test_tooth_force_own_geometry(key):
    """Spur pairs (external; internal with the ring as gear j for odd dh_geared seeds, as
    gear k in spatial) and a bevel pair (spatial): rebuild the force on gear j from the
    reported t, radial and axial components along the test's own directions (pitch point,
    axes and cone apex moved with the own carrier pose).  Per ERRATA 7 its separating
    component is perpendicular to the pitch element (the axis for spur gears, apex -> pitch
    point for bevel gears), towards j's own axis (outwards for a ring), of size |t| tan(phi)
    with phi as written in the file (degrees); the sep column says the same; the force has
    no other component off the tangent; and the components reported on gear k are those of
    -g along k's own radial direction and axis."""
    an, om = case(key)
    rng = np.random.default_rng(5)
    q, qd, qdd = random_q(an.dof, n=60, seed=5), rng.normal(size=(60, an.dof)) * 2, rng.normal(size=(60, an.dof)) * 5
    res = solve(an, q, qd, qdd)
    T = poses(om, q @ om.S.T)
    names = [an.mech.gears[c.gear].name for c in an.circuits]
    for pair, gm in om.gears.items():
        gi = names.index(pair)
        Tc = T[gm["carrier"]]
        Rc, oc = Tc[:, :3, :3], Tc[:, :3, 3]
        P = Rc @ gm["P"] + oc
        e = Rc @ gm["zj"] if gm.get("apex") is None else P - (Rc @ gm["apex"] + oc)
        e = e / np.linalg.norm(e, axis=1, keepdims=True)          # pitch element
        basis = []
        for o, z in ((gm["oj"], gm["zj"]), (gm["ok"], gm["zk"])):
            zw = Rc @ z
            d = P - (Rc @ o + oc)
            d = d - np.sum(d * zw, axis=1, keepdims=True) * zw
            basis.append((d / np.linalg.norm(d, axis=1, keepdims=True), zw))
        (rj, zj), (rk, zk) = basis
        t = res.gear_t[:, gi]
        g = t[:, None] * np.cross(zj, rj) + res.gear_radial[:, gi, 0, None] * rj + res.gear_axial[:, gi, 0, None] * zj
        sep = np.abs(t) * np.tan(np.radians(gm["phi_deg"]))
        assert np.max(t) > 0 > np.min(t)     # both signs of |t| exercised
        us = rj - np.sum(rj * e, axis=1, keepdims=True) * e
        us = gm["us_j"] * us / np.linalg.norm(us, axis=1, keepdims=True)
        assert rel_err(np.sum(g * us, axis=1), sep) < TOL
        assert rel_err(res.gear_sep[:, gi], sep) < TOL
        assert np.max(np.abs(np.sum(g * e, axis=1))) < TOL * np.max(np.abs(t))
        assert rel_err(res.gear_radial[:, gi, 1], -np.sum(g * rk, axis=1)) < TOL
        assert np.max(np.abs(res.gear_axial[:, gi, 1] + np.sum(g * zk, axis=1))) < TOL * np.max(np.abs(t))
