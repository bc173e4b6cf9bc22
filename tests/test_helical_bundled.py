"""The bundled two-stage helical reduction (``mechanisms/helical_reduction.yaml``, issue 9).

Everything expected here is derived in the test from the geometry in the file's comments,
not from gearcli's formulas:

* tooth line: a helix of helix angle beta on the pitch cylinder of gear j (axis +z),
  c(s) = o + r (cos s, sin s, 0) + (r s / tan beta) (0, 0, 1) for a right hand (the
  left hand: -r s / tan beta); its tangent at the mesh point;
* contact force on gear j: tangential t u_t, separating s away from the partner and axial
  a z, normal to the tooth line (t (u_t . l) + a (z . l) = 0) with the normal pressure
  angle phi_n in the plane normal to the tooth line: s = |t| tan(phi_n) / cos(beta)
  (the tangential part in the normal plane is |t| / cos(beta));
* statics of three shafts turning about z; kinematics of rolling external pairs,
  omega_j r_j = -omega_k r_k;
* bearings: a shaft on two supports, the locating one taking the thrust (ISO 281 Fr, Fa).
"""
from __future__ import annotations

import numpy as np
import pytest

from gearcli import analyse, load_mechanism, solve
from gearcli.design.evaluate import Samples, bearing_loads
from gearcli.report.columns import named_columns
from metrics import rel_err

Z = np.array([0.0, 0.0, 1.0])
G = np.array([0.0, 0.0, -9.81])
PHI_N = np.radians(20.0)
SHAFTS = {  # name: (axis origin, mass, CoM (on the axis), Izz)
    "input": (np.array([0.0, 0, 0]), 0.4, np.array([0, 0, 0.02]), 6.0e-5),
    "intermediate": (np.array([0.06, 0, 0]), 1.1, np.array([0, 0, 0.035]), 1.2e-3),
    "output": (np.array([0.124, 0, 0]), 1.6, np.array([0, 0, 0.06]), 1.9e-3),
}
# stage: (gear j, gear k, mesh point, beta, hand of j)
STAGES = {"stage1": ("input", "intermediate", np.array([0.015, 0, 0.02]), np.radians(20.0), "right"),
          "stage2": ("intermediate", "output", np.array([0.076, 0, 0.06]), np.radians(15.0), "left")}
LOAD_MZ = -20.0   # resisting moment on the output, N m
RATIOS = {"input": 9.0, "intermediate": -3.0, "output": 1.0}   # omega / omega_output, by rolling
JOINT_OF = {"input": "Jin", "intermediate": "Jmid", "output": "Jout"}


def own_ratios():
    """omega_x / omega_output by rolling at the pitch points: omega_j r_j = -omega_k r_k."""
    w = {"output": 1.0}
    for j, k, P, _, _ in reversed(list(STAGES.values())):
        rj = np.linalg.norm((P - SHAFTS[j][0])[:2])
        rk = np.linalg.norm((P - SHAFTS[k][0])[:2])
        w[j] = -w[k] * rk / rj
    return w


def tooth_line(o, P, beta, hand):
    """Unit tangent of the helix through P on the pitch cylinder about (o, +z)."""
    d = (P - o)[:2]
    r, s = np.linalg.norm(d), np.arctan2(d[1], d[0])
    lead = (1.0 if hand == "right" else -1.0) * r / np.tan(beta)
    tangent = np.array([-r * np.sin(s), r * np.cos(s), lead])
    return tangent / np.linalg.norm(tangent)


def force_on_j(stage, t):
    """Contact force (3,) on gear j of ``stage`` for tangential force t (N)."""
    j, k, P, beta, hand = STAGES[stage]
    o = SHAFTS[j][0]
    rad = (P - o) * [1, 1, 0]
    rad /= np.linalg.norm(rad)
    ut = np.cross(Z, rad)
    line = tooth_line(o, P, beta, hand)
    a = -t * (ut @ line) / (Z @ line)
    s = abs(t) * np.tan(PHI_N) / np.cos(beta)
    return t * ut + a * Z - s * rad


def moment_arm(shaft, P, stage):
    """z-moment on ``shaft`` per unit t of a force t u_t(stage) at P."""
    j, _, Pj, _, _ = STAGES[stage]
    rad = (Pj - SHAFTS[j][0]) * [1, 1, 0]
    ut = np.cross(Z, rad / np.linalg.norm(rad))
    return float(Z @ np.cross(P - SHAFTS[shaft][0], ut))


def hand_statics():
    """Tangential forces and motor torque holding the resisting moment, by moment
    balances about each shaft's axis (only the tangential parts have a z-moment)."""
    P1, P2 = STAGES["stage1"][2], STAGES["stage2"][2]
    t2 = LOAD_MZ / moment_arm("output", P2, "stage2")          # output gets -g2
    t1 = t2 * moment_arm("intermediate", P2, "stage2") / moment_arm("intermediate", P1, "stage1")
    motor = -t1 * moment_arm("input", P1, "stage1")
    return {"stage1": t1, "stage2": t2}, motor


def shaft_forces(t):
    """External forces (point, force) on each shaft: tooth forces and weight."""
    out = {n: [(o + com, m * G)] for n, (o, m, com, _) in SHAFTS.items()}
    for stage, (j, k, P, _, _) in STAGES.items():
        g = force_on_j(stage, t[stage])
        out[j].append((P, g))
        out[k].append((P, -g))
    return out


def hand_reactions(t):
    """Bearing reaction (f, m) of each shaft's joint about its origin, base axes (q = 0)."""
    out = {}
    for name, forces in shaft_forces(t).items():
        o = SHAFTS[name][0]
        f = -sum(F for _, F in forces)
        m = -sum(np.cross(p - o, F) for p, F in forces)
        if name == "output":
            m = m - LOAD_MZ * Z
        out[name] = (f, m)
    return out


@pytest.fixture(scope="module")
def an(mech_dir):
    return analyse(load_mechanism(mech_dir / "helical_reduction.yaml"))


def static(q):
    q = np.asarray(q, float).reshape(-1, 1)
    return q, np.zeros_like(q), np.zeros_like(q)


def test_own_ratios_are_the_files():
    w = own_ratios()
    assert all(abs(w[n] - RATIOS[n]) < 1e-12 for n in RATIOS)


@pytest.mark.parametrize("method", ["block", "full"])
def test_static_reduction_by_hand(an, method):
    t, motor = hand_statics()
    assert abs(motor - 20.0 / 9.0) < 1e-12 and t["stage2"] > 0 > t["stage1"]
    res = solve(an, *static([0.0, 0.7, -2.1]), method=method, verify=True)
    assert res.residual < 1e-12
    np.testing.assert_allclose(res.motor[:, 0], motor, rtol=1e-12)
    gi = {gp.name: i for i, gp in enumerate(an.mech.gears)}
    for stage, (j, k, P, beta, hand) in STAGES.items():
        i = gi[stage]
        g = force_on_j(stage, t[stage])
        np.testing.assert_allclose(res.gear_t[:, i], t[stage], rtol=1e-12)
        np.testing.assert_allclose(res.gear_sep[:, i], abs(t[stage]) * np.tan(PHI_N) / np.cos(beta), rtol=1e-12)
        # axial on j along its +z and on k along its +z (-g)
        np.testing.assert_allclose(res.gear_axial[:, i, 0], g @ Z, rtol=1e-12)
        np.testing.assert_allclose(res.gear_axial[:, i, 1], -(g @ Z), rtol=1e-12)
        assert abs(g @ Z) > 0.2 * abs(t[stage])       # the thrust is really there
    ji = {jt.name: i for i, jt in enumerate(an.mech.joints)}
    for name, (f, m) in hand_reactions(t).items():
        x = res.joint[:, ji[JOINT_OF[name]]]
        np.testing.assert_allclose(x[0], np.r_[f, m[:2], 0.0], rtol=1e-12, atol=1e-12 * np.abs(f).max())
        # axisymmetric shafts: the same radial, axial and bending loads at every angle
        np.testing.assert_allclose(np.hypot(x[:, 0], x[:, 1]), np.hypot(f[0], f[1]), rtol=1e-12)
        np.testing.assert_allclose(x[:, 2], f[2], rtol=1e-12)
        np.testing.assert_allclose(np.hypot(x[:, 3], x[:, 4]), np.hypot(m[0], m[1]), rtol=1e-12)


def own_bearing_loads(f, m, za, zb):
    """Radial loads on supports at za, zb on the axis carrying (f, m) about the joint origin:
    Ra + Rb = f_xy and za z x Ra + zb z x Rb = m_xy (4 equations, solved as such)."""
    A = np.zeros((4, 4))
    A[0:2, 0:2] = A[0:2, 2:4] = np.eye(2)
    for c, zpos in ((0, za), (2, zb)):
        A[2:4, c:c + 2] = zpos * np.array([[0.0, -1.0], [1.0, 0.0]])   # z x (Rx, Ry) = (-Ry, Rx)
    R = np.linalg.solve(A, np.r_[f[:2], m[:2]])
    return np.linalg.norm(R[:2]), np.linalg.norm(R[2:])


def test_bearing_radial_and_axial_loads_by_hand(an):
    """Per bearing Fr and Fa (the thrust on the locating bearing) as the design checks use
    them, against the shaft-on-two-supports statics of the hand reactions."""
    t, _ = hand_statics()
    res = solve(an, *static([0.0]))
    cols = named_columns(an, res)
    s = Samples(np.zeros(1), cols, np.zeros((1, 3)))
    reactions = hand_reactions(t)
    for jt in an.mech.joints:
        name = next(n for n, jn in JOINT_OF.items() if jn == jt.name)
        f, m = reactions[name]
        pos = [b.position for b in jt.bearings]
        own = own_bearing_loads(f, m, *pos)
        for bi, b in enumerate(jt.bearings):
            Fr, Fa = bearing_loads(s, jt.name, jt.bearings)[bi]
            np.testing.assert_allclose(Fr, own[bi], rtol=1e-12)
            np.testing.assert_allclose(Fa, abs(f[2]) if b.locating else 0.0, rtol=1e-12, atol=1e-12)
    # the intermediate shaft's gear and pinion have the same hand: their thrusts oppose
    g1, g2 = force_on_j("stage1", t["stage1"]), force_on_j("stage2", t["stage2"])
    assert (-g1 @ Z) * (g2 @ Z) < 0


def trajectory(mech_dir):
    data = np.loadtxt(mech_dir / "helical_reduction_traj.csv", delimiter=",", skiprows=1)
    return data[:, 0], data[:, 1:2], data[:, 2:3], data[:, 3:4]


@pytest.mark.parametrize("method", ["block", "full"])
def test_power_balance_along_bundled_trajectory(mech_dir, an, method):
    """motor power = d/dt kinetic energy - power of the resisting moment (the CoMs are on
    the axes: no potential energy change), with the test's own rolling ratios."""
    _, q, qd, qdd = trajectory(mech_dir)
    res = solve(an, q, qd, qdd, method=method, verify=True)
    assert res.residual < 1e-12
    w = own_ratios()
    dT = sum(SHAFTS[n][3] * w[n] ** 2 for n in SHAFTS) * qd[:, 0] * qdd[:, 0]
    p_motor = res.motor[:, 0] * w["input"] * qd[:, 0]
    assert rel_err(p_motor, dT - LOAD_MZ * qd[:, 0]) < 1e-12
    assert np.ptp(p_motor) > 50.0


def test_pinocchio_rnea_per_shaft_with_tooth_forces(mech_dir, an):
    """Each shaft alone in Pinocchio (a revolute joint about z at its axis, its own inertia),
    the tooth forces rebuilt from gearcli's t with the test's own helical contact direction
    as fext: RNEA's joint torque is the motor torque on the input shaft and zero on the
    others, and the wrench transmitted by the joint (data.f) is gearcli's bearing reaction
    (plus the motor torque about z)."""
    pin = pytest.importorskip("pinocchio")
    _, q, qd, qdd = trajectory(mech_dir)
    q, qd, qdd = q[::50], qd[::50], qdd[::50]
    res = solve(an, q, qd, qdd)
    w = own_ratios()
    gi = {gp.name: i for i, gp in enumerate(an.mech.gears)}
    ji = {jt.name: i for i, jt in enumerate(an.mech.joints)}
    for name, (o, mass, com, izz) in SHAFTS.items():
        model = pin.Model()
        jid = model.addJoint(0, pin.JointModelRZ(), pin.SE3(np.eye(3), o), name)
        I = np.diag(list(np.diag(an.mech.link(name).inertia)))
        model.appendBodyToJoint(jid, pin.Inertia(mass, com, I), pin.SE3.Identity())
        data = model.createData()
        for n in range(q.shape[0]):
            th = w[name] * q[n, 0]
            Rz = pin.utils.rotate("z", th)
            F, M = np.zeros(3), np.zeros(3)
            for stage, (j, k, P, _, _) in STAGES.items():
                if name in (j, k):
                    g = force_on_j(stage, res.gear_t[n, gi[stage]]) * (1.0 if name == j else -1.0)
                    F, M = F + g, M + np.cross(P - o, g)
            if name == "output":
                M = M + LOAD_MZ * Z
            fext = pin.StdVec_Force()
            fext.append(pin.Force.Zero())
            fext.append(pin.Force(Rz.T @ F, Rz.T @ M))
            tau = pin.rnea(model, data, np.array([th]), np.array([w[name] * qd[n, 0]]),
                           np.array([w[name] * qdd[n, 0]]), fext)
            motor = res.motor[n, 0] if name == "input" else 0.0
            assert abs(tau[0] - motor) < 1e-9 * (1 + abs(res.motor[n, 0]))
            x = res.joint[n, ji[JOINT_OF[name]]]
            want = np.r_[x[:5], motor]
            assert rel_err(data.f[jid].vector, want) < 1e-9


@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_block_equals_full_on_bundled_trajectory(mech_dir, an, backend):
    """Consistency check: the block schedule (both backends) against the full solve."""
    _, q, qd, qdd = trajectory(mech_dir)
    a, b = solve(an, q, qd, qdd, method="block", backend=backend), solve(an, q, qd, qdd, method="full")
    for f in ("motor", "joint", "gear_t", "gear_sep", "gear_radial", "gear_axial"):
        assert rel_err(getattr(a, f), getattr(b, f)) < 1e-12, f
