"""Cross-checks of the inverse dynamics (gearcli.dynamics.solve).

Independent references: the paper's closed form (Eqs. 25-27, corrected per ERRATA 2-5), the
factories' own rolling ratios, the directions of the tooth force (Eq. 14), and Pinocchio's
recursive Newton-Euler algorithm on the real joint tree.  Consistency checks, which share
gearcli's kinematics or equation assembly and so cannot see a bug in them, are marked as
such: the block solve against the world-frame equations and against the simultaneous
solve, and the momentum and power balances on gearcli's own kinematics.  The balances on
independently differentiated kinematics are in test_independent.py.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest

from factories import PAPER_2DOF_PARAMS, paper_2dof_variant, planetary_2dof, spatial_3dof
from gearcli.dynamics.solve import joint_space, solve
from gearcli import analyse
from gearcli.dynamics.kinematics import forward
from gearcli.spatial import cross
from gearcli import load_mechanism, parse_mechanism
from metrics import rel_err

ROOT = Path(__file__).resolve().parents[1]
MECH_DIR = ROOT / "mechanisms"
TOL = 1e-9


# --- mechanisms under test ------------------------------------------------------------------

def velocities(mech, tree, kin, qd: np.ndarray):
    """Angular velocity and velocity of the origin of every link (world): a velocity recursion
    of the test's own, separate from gearcli's forward kinematics (which it reuses only for
    the joint frames)."""
    N = qd.shape[0]
    L = len(tree.links)
    w = [None] * L
    v = [None] * L
    w[tree.base] = np.zeros((N, 3))
    v[tree.base] = np.zeros((N, 3))
    for ji in tree.order:
        jt = mech.joints[ji]
        c = tree.index[jt.child]
        p = tree.parent[c]
        z = kin.Rj[ji][:, :, 2]
        r = kin.oj[ji] - kin.o[p]
        vj = v[p] + cross(w[p], r)
        if jt.type == "prismatic":
            w[c] = w[p]
            vj = vj + z * qd[:, ji:ji + 1]
        else:
            w[c] = w[p] + z * qd[:, ji:ji + 1]
        v[c] = vj + cross(w[c], kin.o[c] - kin.oj[ji])
    return w, v


@lru_cache(maxsize=None)
def analysis(key: str):
    """Analysis of a bundled file ("file:NAME") or a generated mechanism."""
    if key.startswith("file:"):
        return analyse(load_mechanism(MECH_DIR / f"{key[5:]}.yaml"))
    if key.startswith("variant:"):
        return analyse(parse_mechanism(paper_2dof_variant(np.random.default_rng(int(key[8:])))[0]))
    if key == "spatial":
        return analyse(parse_mechanism(spatial_3dof()[0]))
    if key == "spatial_j5_on_base":
        return analyse(parse_mechanism(spatial_3dof(j5_parent="0")[0]))
    if key == "planetary":
        return analyse(parse_mechanism(planetary_2dof()[0]))
    raise KeyError(key)


BUNDLED = ["file:paper_2dof", "file:bendix_wrist"] + (
    ["file:coaxial_fig5"] if (MECH_DIR / "coaxial_fig5.yaml").exists() else [])
GENERATED = ["spatial", "spatial_j5_on_base", "planetary", "variant:1", "variant:2"]
ALL = BUNDLED + GENERATED
SPATIAL = ["file:paper_2dof", "file:bendix_wrist", "spatial"]


def random_states(an, n=60, seed=0, scale=(1.0, 2.0, 5.0)):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (n, an.dof)) * scale[0]
    qd = rng.normal(size=(n, an.dof)) * scale[1]
    qdd = rng.normal(size=(n, an.dof)) * scale[2]
    return q, qd, qdd


@lru_cache(maxsize=None)
def solved(key: str, method: str = "block"):
    an = analysis(key)
    q, qd, qdd = random_states(an)
    return q, qd, qdd, solve(an, q, qd, qdd, method=method, verify=True)


# --- independent helpers ---------------------------------------------------------------------------

def rz(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def com_state(an, q_all, qd_all, qdd_all):
    """Per moving link: world centre of mass x_c, its velocity v_c and acceleration a_c,
    angular velocity w, angular acceleration dw and world inertia I_w, from gearcli's
    kinematics (forward) and the separate velocity recursion (velocities)."""
    mech, tree = an.mech, an.tree
    kin = forward(mech, tree, q_all, qd_all, qdd_all)
    wv, vv = velocities(mech, tree, kin, qd_all)
    out = {}
    for L in tree.moving:
        link = mech.links[L]
        R = kin.R[L]
        rc = np.einsum("nij,j->ni", R, link.com)
        w, dw = kin.w[L], kin.dw[L]
        assert np.allclose(wv[L], w, rtol=0, atol=1e-12)
        out[L] = dict(
            m=link.mass, x=kin.o[L] + rc, v=vv[L] + np.cross(wv[L], rc),
            a=kin.a[L] + np.cross(dw, rc) + np.cross(w, np.cross(w, rc)),
            w=w, dw=dw, I=np.einsum("nij,jk,nlk->nil", R, link.inertia, R))
    return kin, wv, out


def kinetic_energy(an, q_all, qd_all) -> np.ndarray:
    mech, tree = an.mech, an.tree
    kin = forward(mech, tree, q_all, qd_all)
    w, v = velocities(mech, tree, kin, qd_all)
    T = 0.0
    for L in tree.moving:
        link = mech.links[L]
        R = kin.R[L]
        rc = np.einsum("nij,j->ni", R, link.com)
        vc = v[L] + np.cross(w[L], rc)
        wb = np.einsum("nji,nj->ni", R, w[L])            # body-frame angular velocity
        T = T + 0.5 * link.mass * np.sum(vc * vc, axis=1) + 0.5 * np.einsum("ni,ij,nj->n", wb, link.inertia, wb)
    return T


def motor_power(an, res, wv, kin) -> np.ndarray:
    """Sum of motor torque x angular velocity of the input relative to its stator about the
    input's joint axis."""
    P = 0.0
    for mi, (x, s) in enumerate(zip(an.motor_links, an.motor_stators)):
        z = kin.Rj[an.tree.parent_joint[x]][:, :, 2]
        P = P + res.motor[:, mi] * np.sum((wv[x] - wv[s]) * z, axis=1)
    return P


class Trajectory:
    """A smooth analytic trajectory of the independent coordinates (sums of sines)."""

    def __init__(self, dof, seed):
        rng = np.random.default_rng(seed)
        self.q0 = rng.uniform(-np.pi, np.pi, dof)
        self.A = rng.uniform(0.3, 1.2, (3, dof))
        self.w = rng.uniform(0.5, 3.0, (3, dof))
        self.p = rng.uniform(0, 2 * np.pi, (3, dof))

    def __call__(self, t):
        t = np.asarray(t, float)[:, None, None]
        arg = self.w * t + self.p
        q = self.q0 + np.sum(self.A * np.sin(arg), axis=1)
        qd = np.sum(self.A * self.w * np.cos(arg), axis=1)
        qdd = -np.sum(self.A * self.w ** 2 * np.sin(arg), axis=1)
        return q, qd, qdd


# --- 1. closed form of the paper (Eqs. 25-27 with ERRATA 2-5) -----------------------------------

def closed_form_tau(p, q, qd, qdd) -> np.ndarray:
    """Equivalent joint torques [tau1, tau2] of the two-dof manipulator (gravity along -z0
    does no work).  Izz(4) of M22 is link 4's moment about its shaft axis (Iax4), Iyy(4) of
    J40 its moment about the vertical (Ivert4)."""
    C, S = np.cos(q[:, 1]), np.sin(q[:, 1])
    m1, m2, m4 = p["m1"], p["m2"], p["m4"]
    a1, a2, s1, s2, s4 = p["a1"], p["a2"], p["s1"], p["s2"], p["s4"]
    e15, e43, e24 = p["e15"], p["e43"], p["e24"]
    J10 = m1 * (a1 - s1) ** 2 + p["Izz1"]
    J20 = m2 * a1 ** 2 + 2 * m2 * a1 * (a2 - s2) * C + m2 * (a2 - s2) ** 2 + p["Izz2"]   # ERRATA 3
    J21 = m2 * (a2 - s2) ** 2 + p["Izz2"]
    J40 = m4 * (a1 - s4) ** 2 + p["Ivert4"]
    k1 = m2 * a1 * (a2 - s2)
    k2 = k1 * C + J21
    M11 = J10 + J20 + p["Izz3"] + J40 + e15 ** 2 * p["Izz5"]
    M12 = k2 + e43 * e24 * p["Izz3"]
    M22 = J21 + e43 ** 2 * e24 ** 2 * p["Izz3"] + e24 ** 2 * p["Iax4"]                    # ERRATA 2
    tau1 = M11 * qdd[:, 0] + M12 * qdd[:, 1] - 2 * k1 * S * qd[:, 0] * qd[:, 1] - k1 * S * qd[:, 1] ** 2  # ERRATA 4
    tau2 = M12 * qdd[:, 0] + M22 * qdd[:, 1] + k1 * S * qd[:, 0] ** 2
    return np.column_stack([tau1, tau2])


def paper_A(p) -> np.ndarray:
    """Structure matrix of Eq. (22) for motors [motor3, motor5]: tau = A motor."""
    return np.array([[1.0, p["e15"]], [p["e24"] * p["e43"], 0.0]])


def _paper_cases():
    yield "file", analyse(load_mechanism(MECH_DIR / "paper_2dof.yaml")), PAPER_2DOF_PARAMS
    for seed in range(6):
        g = [0.0, 0.0, -np.random.default_rng(100 + seed).uniform(1.0, 20.0)]
        text, p = paper_2dof_variant(np.random.default_rng(seed), gravity=g)
        yield f"variant{seed}", analyse(parse_mechanism(text)), p


PAPER_CASES = list(_paper_cases())


@pytest.mark.parametrize("name,an,p", PAPER_CASES, ids=[c[0] for c in PAPER_CASES])
@pytest.mark.parametrize("method", ["block", "full"])
def test_paper_closed_form(name, an, p, method):
    assert list(an.independent_names) == ["J1", "J2"]
    assert [an.mech.motors[i].name for i in range(2)] == ["motor3", "motor5"]
    np.testing.assert_allclose(an.A, paper_A(p), rtol=1e-12, atol=1e-12)
    q, qd, qdd = random_states(an, n=200, seed=7)
    res = solve(an, q, qd, qdd, method=method)
    tau = closed_form_tau(p, q, qd, qdd)
    assert rel_err(res.tau, tau) < TOL
    assert rel_err(res.motor, np.linalg.solve(paper_A(p), tau.T).T) < TOL
    # each term on its own: inertia only, velocity only
    z = np.zeros_like(q)
    assert rel_err(solve(an, q, z, qdd, method=method).tau, closed_form_tau(p, q, z, qdd)) < TOL
    assert rel_err(solve(an, q, qd, z, method=method).tau, closed_form_tau(p, q, qd, z)) < TOL


@pytest.mark.parametrize("name,an,p", PAPER_CASES, ids=[c[0] for c in PAPER_CASES])
def test_paper_static_weight_on_vertical_bearings(name, an, p):
    """At rest, gravity along -z0 needs no motor torque; the bearings J1, J3, J5 (all with
    z along z0, on the base) carry the weight of all moving links and no horizontal force."""
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, (25, 2))
    z = np.zeros_like(q)
    res = solve(an, q, z, z)
    g = -an.mech.gravity[2]
    weight = g * sum(p[f"m{i}"] for i in range(1, 6))
    assert np.max(np.abs(res.motor)) < 1e-9 * weight
    names = [jt.name for jt in an.mech.joints]
    fz = sum(res.joint[:, names.index(n), 2] for n in ("J1", "J3", "J5"))
    np.testing.assert_allclose(fz, weight, rtol=1e-12)
    # horizontal forces of the three base bearings (rotate each joint frame into the base)
    fh = 0.0
    for n in ("J1", "J3", "J5"):
        ji = names.index(n)
        jt = an.mech.joints[ji]
        Rw = np.stack([jt.R_pj @ rz(t) for t in q @ an.S[ji]])
        fh = fh + np.einsum("nij,nj->ni", Rw, res.joint[:, ji, :3])
    np.testing.assert_allclose(fh[:, :2], 0.0, atol=1e-12 * weight)
    np.testing.assert_allclose(fh[:, 2], weight, rtol=1e-12)


# --- 2. block solve vs the world-frame equations (consistency) ---------------------------------

@pytest.mark.parametrize("key", ALL)
def test_block_solve_satisfies_world_frame_equations(key):
    """Consistency, not physics: the block solver works with constant matrices in frames of
    its own choosing (dynamics.blocks); ``verify`` re-assembles every link's equations in the
    world frame (dynamics.loads) with the sign pattern the solve chose.  Both share the
    inertia loads, so a wrong inertia load passes here (see test_independent.py)."""
    *_, res = solved(key, "block")
    assert res.residual is not None and res.residual < TOL


# --- 3. global momentum balance of all moving links ----------------------------------------------

@pytest.mark.parametrize("key", ALL)
def test_global_momentum_balance(key):
    """Consistency (shares gearcli's kinematics: see test_independent.py for the balance on
    differentiated positions).  The base acts on the moving links only through its
    bearings, the motor stators it holds and gears fixed to it.  Their resultant (force, and moment about the world origin)
    plus gravity equals the rate of change of linear and angular momentum of all moving
    links."""
    an = analysis(key)
    mech, tree = an.mech, an.tree
    q, qd, qdd, res = solved(key)
    qa, qda, qdda = joint_space(an, q, qd, qdd)
    kin, _, st = com_state(an, qa, qda, qdda)
    g = mech.gravity
    F_ext = 0.0
    M_ext = 0.0
    for gi, c in enumerate(an.circuits):
        if tree.base not in (c.j, c.k):
            continue
        assert c.j != tree.base, "factories put the fixed gear second"
        # tooth force on the moving gear j from the reported components, in its own basis
        ji = tree.parent_joint[c.j]
        z, o = kin.Rj[ji][:, :, 2], kin.oj[ji]
        P = kin.o[c.carrier] + np.einsum("nij,j->ni", kin.R[c.carrier], mech.gears[c.gear].mesh_point)
        d = P - o
        d = d - np.sum(d * z, axis=1, keepdims=True) * z
        rad = d / np.linalg.norm(d, axis=1, keepdims=True)
        gj = res.gear_t[:, gi, None] * np.cross(z, rad) + res.gear_radial[:, gi, 0, None] * rad \
            + res.gear_axial[:, gi, 0, None] * z
        F_ext = F_ext + gj
        M_ext = M_ext + np.cross(P, gj)
    for ji, jt in enumerate(mech.joints):
        if tree.index[jt.parent] != tree.base:
            continue
        Rw = np.stack([jt.R_pj @ rz(t) for t in qa[:, ji]])      # base -> joint frame (own computation)
        f = np.einsum("nij,nj->ni", Rw, res.joint[:, ji, :3])
        n = np.einsum("nij,nj->ni", Rw, res.joint[:, ji, 3:])
        F_ext = F_ext + f
        M_ext = M_ext + np.cross(jt.p_pj, f) + n
    for mi, (x, s) in enumerate(zip(an.motor_links, an.motor_stators)):
        if s == tree.base:   # the reaction on the stator leaves the system of moving links
            M_ext = M_ext + res.motor[:, mi, None] * kin.Rj[tree.parent_joint[x]][:, :, 2]
    dP, dH = 0.0, 0.0
    for L, s in st.items():
        F_ext = F_ext + s["m"] * g
        M_ext = M_ext + np.cross(s["x"], s["m"] * g)
        dP = dP + s["m"] * s["a"]
        dH = dH + np.cross(s["x"], s["m"] * s["a"]) + np.einsum("nij,nj->ni", s["I"], s["dw"]) \
            + np.cross(s["w"], np.einsum("nij,nj->ni", s["I"], s["w"]))
    assert rel_err(F_ext, dP) < TOL
    assert rel_err(M_ext, dH) < TOL


# --- 4. power balance ---------------------------------------------------------------------------------

@pytest.mark.parametrize("key", ALL)
def test_power_balance_analytic(key):
    """Consistency (shares gearcli's kinematics: see test_independent.py for the balance on
    differentiated positions).  sum(motor torque x relative input rate) = dT/dt - sum m g.v_c,
    with dT/dt = sum m v_c.a_c + w.(I dw) (w.(w x I w) = 0)."""
    an = analysis(key)
    q, qd, qdd, res = solved(key)
    qa, qda, qdda = joint_space(an, q, qd, qdd)
    kin, wv, st = com_state(an, qa, qda, qdda)
    dT = sum(s["m"] * np.sum(s["v"] * s["a"], axis=1) + np.einsum("ni,nij,nj->n", s["w"], s["I"], s["dw"])
             for s in st.values())
    Pg = sum(s["m"] * (s["v"] @ an.mech.gravity) for s in st.values())
    P = motor_power(an, res, wv, kin)
    assert rel_err(P, dT - Pg) < TOL
    # the same power through the equivalent joint torques: tau . qd_ind
    assert rel_err(np.sum(res.tau * qd, axis=1), dT - Pg) < TOL


@pytest.mark.parametrize("key", ALL)
def test_power_balance_finite_difference(key):
    """Along a smooth trajectory, motor power = dT/dt + dV/dt with dT/dt from a five-point
    central difference of the kinetic energy in time (h = 1e-3 s, error O(h^4)).  Partly
    independent: T comes from gearcli's velocity recursion, the motor torques from its
    accelerations (test_independent.py differentiates the test's own link poses instead)."""
    an = analysis(key)
    traj = Trajectory(an.dof, seed=11)
    t = np.linspace(0.0, 3.0, 40)
    h = 1e-3

    def energy(tt):
        qi, qdi, _ = traj(tt)
        qa, qda, _ = joint_space(an, qi, qdi)
        T = kinetic_energy(an, qa, qda)
        kin = forward(an.mech, an.tree, qa)
        V = 0.0
        for L in an.tree.moving:
            link = an.mech.links[L]
            xc = kin.o[L] + np.einsum("nij,j->ni", kin.R[L], link.com)
            V = V - link.mass * (xc @ an.mech.gravity)
        return T + V

    dE = (-energy(t + 2 * h) + 8 * energy(t + h) - 8 * energy(t - h) + energy(t - 2 * h)) / (12 * h)
    q, qd, qdd = traj(t)
    res = solve(an, q, qd, qdd)
    qa, qda, qdda = joint_space(an, q, qd, qdd)
    kin = forward(an.mech, an.tree, qa, qda, qdda)
    wv, _ = velocities(an.mech, an.tree, kin, qda)
    P = motor_power(an, res, wv, kin)
    assert rel_err(P, dE) < 2e-8


# --- 5. block schedule vs simultaneous solve ---------------------------------------------------------

FIELDS = ("motor", "tau", "joint", "gear_t", "gear_sep", "gear_radial", "gear_axial")


@pytest.mark.parametrize("key", BUNDLED + ["spatial", "spatial_j5_on_base", "planetary"])
def test_block_equals_full(key):
    an = analysis(key)
    q, qd, qdd, blk = solved(key, "block")
    *_, full = solved(key, "full")
    # the data must exercise both signs of the tangential tooth forces (Eq. 14, |t|)
    t = blk.gear_t
    big = np.abs(t) > 1e-6 * np.max(np.abs(t))
    flips = [(np.any((t[:, g] > 0) & big[:, g]) and np.any((t[:, g] < 0) & big[:, g])) for g in range(t.shape[1])]
    assert all(flips), flips
    for f in FIELDS:
        a, b = getattr(blk, f), getattr(full, f)
        assert a.shape == b.shape
        assert rel_err(a, b) < TOL, f
    # also along a trajectory where the tooth forces change sign as time goes on
    traj = Trajectory(an.dof, seed=5)
    qt, qdt, qddt = traj(np.linspace(0.0, 4.0, 120))
    r1 = solve(an, qt, qdt, qddt, method="block", verify=True)
    r2 = solve(an, qt, qdt, qddt, method="full", verify=True)
    assert np.any(np.diff(np.sign(r1.gear_t), axis=0) != 0)
    for f in FIELDS:
        assert rel_err(getattr(r1, f), getattr(r2, f)) < TOL, f
    assert r1.residual < TOL and r2.residual < TOL


# --- 6. separating force of the tooth contact (Eq. 14, ERRATA 7) ----------------------------------

@pytest.mark.parametrize("key", BUNDLED + ["spatial", "spatial_j5_on_base", "planetary", "variant:1"])
def test_separating_force(key):
    an = analysis(key)
    *_, res = solved(key)
    for gi, c in enumerate(an.circuits):
        gp = an.mech.gears[c.gear]
        t = res.gear_t[:, gi]
        sep = res.gear_sep[:, gi]
        scale = np.max(np.abs(t))
        assert scale > 0
        # sep = |t| tan(phi) is checked against the test's own geometry and the file's phi in
        # test_independent.py::test_tooth_force_own_geometry (re-running the formula here
        # would compare the code with itself)
        # the force components off the tangential direction add up to the separating force,
        # on both gears (radial and axial are orthogonal to the pitch velocity)
        for side in (0, 1):
            off = np.hypot(res.gear_radial[:, gi, side], res.gear_axial[:, gi, side])
            np.testing.assert_allclose(off, sep, rtol=1e-9, atol=1e-12 * scale)
        on = np.abs(t) > 1e-9 * scale
        rad = res.gear_radial[on, gi]
        ax = res.gear_axial[on, gi]
        if gp.kind == "external":
            assert np.all(rad < 0), gp.name            # pushed towards its own axis
            np.testing.assert_allclose(ax, 0.0, atol=1e-12 * scale)
            np.testing.assert_allclose(-rad, np.stack([sep[on]] * 2, axis=1), rtol=1e-9)
        elif gp.kind == "internal":
            ring = 0 if c.geometry.r_j > c.geometry.r_k else 1
            assert np.all(rad[:, ring] > 0), gp.name    # the ring is pushed away from its axis
            assert np.all(rad[:, 1 - ring] < 0), gp.name
            np.testing.assert_allclose(ax, 0.0, atol=1e-12 * scale)
        else:   # bevel: pushed towards its own axis and away from the cone apex
            assert np.all(rad < 0), gp.name
            gm = c.geometry
            oj, ok = gm.P - gm.r_j * gm.rad_j, gm.P - gm.r_k * gm.rad_k   # gear centres on the axes
            s, u = np.linalg.lstsq(np.stack([gm.zj, -gm.zk], axis=1), ok - oj, rcond=None)[0]
            apex = oj + s * gm.zj
            for side, z in ((0, gm.zj), (1, gm.zk)):
                away = np.sign((gm.P - apex) @ z)
                assert away != 0
                assert np.all(away * ax[:, side] > 0), gp.name


def test_planetary_structure():
    """Arm turns 1 / (1 + N_ring / N_sun) times as fast as the sun (Willis), the fixed ring
    (the base) takes an outward separating force."""
    an = analysis("planetary")
    _, info = planetary_2dof()
    np.testing.assert_allclose(an.A, np.diag([1.0 / info["arm_per_sun"], 1.0]), rtol=1e-12, atol=1e-14)
    kinds = [an.mech.gears[c.gear].kind for c in an.circuits]
    gi = kinds.index("internal")
    assert an.circuits[gi].k == an.tree.base
    *_, res = solved("planetary")
    on = np.abs(res.gear_t[:, gi]) > 0
    assert on.sum() > 10 and np.all(res.gear_radial[on, gi, 1] > 0) and np.all(res.gear_radial[on, gi, 0] < 0)


def test_ring_pair_is_exercised():
    text, info = spatial_3dof()
    mech = parse_mechanism(text)
    kinds = {g.name: g.kind for g in mech.gears}
    assert sorted(kinds.values()) == ["bevel", "external", "internal"]
    an = analysis("spatial")
    names = [mech.gears[c.gear].name for c in an.circuits]
    gi = names.index("4-1")
    *_, res = solved("spatial")
    on = np.abs(res.gear_t[:, gi]) > 0
    assert on.sum() > 10
    assert np.all(res.gear_radial[on, gi, 1] > 0)   # link 1 carries the ring
    assert np.all(res.gear_radial[on, gi, 0] < 0)


# --- 7. the generated spatial mechanism's kinematic constraints -------------------------------------

@pytest.mark.parametrize("key,j5_parent", [("spatial", "1"), ("spatial_j5_on_base", "0")])
def test_spatial_gear_constraints(key, j5_parent):
    """q = S q_ind obeys the rolling ratios computed by the factory, with the relative angles
    written out by hand from the joint layout."""
    an = analysis(key)
    _, info = spatial_3dof(j5_parent=j5_parent)
    e = info["ratios"]
    names = [jt.name for jt in an.mech.joints]
    S = {n: an.S[names.index(n)] for n in names}
    theta51 = S["J5"] if j5_parent == "1" else S["J5"] - S["J1"]    # J5, J1 have the same direction
    np.testing.assert_allclose(S["J4"], e["4-1"] * S["J1"], atol=1e-12)
    np.testing.assert_allclose(theta51, e["5-6"] * S["J6"], atol=1e-12)
    np.testing.assert_allclose(S["J6"], e["6-2"] * S["J2"], atol=1e-12)
    np.testing.assert_allclose(np.stack([S["J1"], S["J2"], S["J3"]]), np.eye(3), atol=1e-15)
    # motor input rotations relative to their stators (motor5 on the base, coaxial with J1)
    A_T = np.stack([S["J4"], S["J5"] + (S["J1"] if j5_parent == "1" else 0.0), S["J3"]])
    np.testing.assert_allclose(an.A.T, A_T, atol=1e-12)


# --- 8. Pinocchio on the real joint tree -------------------------------------------------------------

class PinTree:
    """The real joint tree as a Pinocchio model (one revolute RZ joint per real joint, each
    body's inertia expressed in its joint frame).  ``order[k]`` is the gearcli joint index of
    Pinocchio joint k + 1, ``jid[L]`` the Pinocchio joint carrying link L, ``X[L]`` link L's
    frame in that joint's frame."""

    def __init__(self, an):
        pin = pytest.importorskip("pinocchio")
        mech, tree = an.mech, an.tree
        model = pin.Model()
        model.gravity = pin.Motion(np.asarray(mech.gravity, float), np.zeros(3))
        self.jid = {tree.base: 0}
        self.X = {tree.base: pin.SE3.Identity()}
        self.order = []
        for ji in tree.order:
            jt = mech.joints[ji]
            assert jt.type == "revolute"
            p, c = tree.index[jt.parent], tree.index[jt.child]
            placement = self.X[p] * pin.SE3(jt.R_pj, jt.p_pj)
            jid = model.addJoint(self.jid[p], pin.JointModelRZ(), placement, jt.name)
            link = mech.links[c]
            com = jt.R_jc @ link.com + jt.p_jc
            I = jt.R_jc @ link.inertia @ jt.R_jc.T
            model.appendBodyToJoint(jid, pin.Inertia(link.mass, com, I), pin.SE3.Identity())
            self.jid[c] = jid
            self.X[c] = pin.SE3(jt.R_jc, jt.p_jc)
            self.order.append(ji)
        self.model, self.data = model, model.createData()

    def rnea(self, q, qd, qdd, fext=None):
        """Joint torques (gearcli joint order) for one sample of every real joint's q."""
        pin = pytest.importorskip("pinocchio")
        o = self.order
        args = (self.model, self.data, q[o], qd[o], qdd[o]) + (() if fext is None else (fext,))
        tau = np.zeros(len(o))
        tau[o] = pin.rnea(*args)
        return tau


PIN_KEYS = SPATIAL + (["file:coaxial_fig5"] if "file:coaxial_fig5" in BUNDLED else []) \
    + ["spatial_j5_on_base", "planetary", "variant:2"]


@pytest.mark.parametrize("key", PIN_KEYS)
def test_pinocchio_rnea(key):
    """Pinocchio's RNEA on the real joint tree, projected on the independent coordinates by
    virtual work (tau_ind = S^T tau_all: gear meshes roll at the pitch point and do no work),
    gives the equivalent joint torques; motor torques follow from tau = A motor."""
    pt = PinTree(analysis(key))
    an = analysis(key)
    q, qd, qdd, res = solved(key)
    qa, qda, qdda = joint_space(an, q, qd, qdd)
    tau_all = np.array([pt.rnea(qa[n], qda[n], qdda[n]) for n in range(qa.shape[0])])
    tau_ind = tau_all @ an.S
    assert rel_err(res.tau, tau_ind) < TOL
    assert rel_err(res.motor, np.linalg.solve(an.A, tau_ind.T).T) < TOL


@pytest.mark.parametrize("key", PIN_KEYS)
def test_pinocchio_bearing_reactions(key):
    """Cut every gear mesh and every motor: apply gearcli's tooth forces (t along the pitch
    velocity of j, the reported radial and axial components along j's own radial direction
    and axis, the opposite force on k, at the mesh point) and motor torques (on the input,
    reversed on the stator) as external forces in Pinocchio.  Then the RNEA must need no
    joint torque at all, and the wrench Pinocchio transmits through each joint (parent on
    child, joint frame, about the joint origin) is gearcli's bearing reaction."""
    pin = pytest.importorskip("pinocchio")
    an = analysis(key)
    mech, tree = an.mech, an.tree
    pt = PinTree(an)
    model, data = pt.model, pt.data
    q, qd, qdd, res = solved(key)
    qa, qda, qdda = joint_space(an, q, qd, qdd)
    N, J = qa.shape
    tau = np.zeros((N, J))
    f = np.zeros((N, J, 6))
    side_err = 0.0
    for n in range(N):
        pin.forwardKinematics(model, data, qa[n, pt.order])
        fext = [pin.Force.Zero() for _ in range(model.njoints)]

        def push(L, force, point=None, moment=None):
            if L == tree.base:
                return
            i = pt.jid[L]
            F = pin.Force(np.zeros(3), moment) if point is None else pin.Force(force, np.cross(point, force))
            fext[i] = fext[i] + data.oMi[i].actInv(F)

        def axis(L):
            M = data.oMi[pt.jid[L]]
            return M.rotation[:, 2].copy(), M.translation.copy()

        for gi, c in enumerate(an.circuits):
            gp = mech.gears[c.gear]
            assert gp.mesh_point is not None
            Mc = data.oMi[pt.jid[c.carrier]] * pt.X[c.carrier]
            P = Mc.rotation @ gp.mesh_point + Mc.translation
            basis = []
            for L in (c.j, c.k):
                # a gear fixed to the base turns, relative to the carrier, about the
                # carrier's own joint axis
                z, o = axis(c.carrier if L == tree.base else L)
                d = P - o
                d = d - (d @ z) * z
                rad = d / np.linalg.norm(d)
                basis.append((rad, z, np.cross(z, rad)))
            (rj, zj, uj), (rk, zk, uk) = basis
            g = res.gear_t[n, gi] * uj + res.gear_radial[n, gi, 0] * rj + res.gear_axial[n, gi, 0] * zj
            # the reported components on gear k are those of -g
            side_err = max(side_err, abs(-g @ rk - res.gear_radial[n, gi, 1]), abs(-g @ zk - res.gear_axial[n, gi, 1]))
            push(c.j, g, P)
            push(c.k, -g, P)
        for mi, (x, s) in enumerate(zip(an.motor_links, an.motor_stators)):
            z, _ = axis(x)
            push(x, None, moment=res.motor[n, mi] * z)
            push(s, None, moment=-res.motor[n, mi] * z)
        tau[n] = pt.rnea(qa[n], qda[n], qdda[n], fext)
        for ji in range(J):
            fj = data.f[pt.jid[tree.index[mech.joints[ji].child]]]
            f[n, ji] = np.concatenate([fj.linear, fj.angular])
    scale = np.max(np.abs(res.joint))
    assert side_err < TOL * scale
    assert np.max(np.abs(tau)) < TOL * scale
    assert rel_err(res.joint, f) < TOL


def test_pinocchio_joint_reaction_of_gearless_subtree():
    """Link 3 of the spatial mechanism is driven directly (motor3, stator on link 2) and has no
    gear in its subtree: Pinocchio's joint force f[J3] without any external force is gearcli's
    bearing reaction, its moment about the axis the motor torque."""
    pin = pytest.importorskip("pinocchio")
    an = analysis("spatial")
    pt = PinTree(an)
    q, qd, qdd, res = solved("spatial")
    qa, qda, qdda = joint_space(an, q, qd, qdd)
    names = [jt.name for jt in an.mech.joints]
    j3 = names.index("J3")
    jid = pt.model.getJointId("J3")
    mi = [m.name for m in an.mech.motors].index("motor3")
    f = np.zeros((qa.shape[0], 6))
    for n in range(qa.shape[0]):
        pt.rnea(qa[n], qda[n], qdda[n])
        f[n] = np.concatenate([pt.data.f[jid].linear, pt.data.f[jid].angular])
    assert rel_err(res.joint[:, j3, :5], f[:, :5]) < TOL
    assert np.max(np.abs(res.joint[:, j3, 5])) == 0.0
    assert rel_err(res.motor[:, mi], f[:, 5]) < TOL
