"""The tests' own kinematics and Pinocchio models, built without gearcli.

A mechanism is described here by :class:`OwnMech`, written by the factories from their own
parameters (D-H tables, home poses, axes), never from what gearcli read:

* every joint has a fixed transform ``X_pj`` (parent link frame -> joint frame at q = 0,
  z = the joint axis) and ``X_jc`` (moved joint frame -> child link frame); a D-H joint
  instead keeps its table row and its link frame is the product of the paper's Eq. (1)
  matrices, ``T_c = T_p @ dh(theta + q, d, a, alpha)`` (ERRATA 1: third row 0, S_alpha,
  C_alpha, d);
* ``S`` (J, dof) maps the independent coordinates to every joint's, from the rolling
  ratios the factory computed itself.

:func:`fd_motion` differentiates link positions and orientations only (five-point central
differences in time), so velocities and accelerations owe nothing to gearcli's recursion.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


# --- homogeneous transforms --------------------------------------------------------------------

def dh(theta, d, a, alpha) -> np.ndarray:
    """Paper Eq. (1) (with ERRATA 1) for angles ``theta`` of any shape (...) -> (..., 4, 4)."""
    theta = np.asarray(theta, float)
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(alpha), np.sin(alpha)
    T = np.zeros(theta.shape + (4, 4))
    T[..., 0, :] = np.stack([ct, -st * ca, st * sa, a * ct], axis=-1)
    T[..., 1, :] = np.stack([st, ct * ca, -ct * sa, a * st], axis=-1)
    T[..., 2, 1], T[..., 2, 2], T[..., 2, 3] = sa, ca, d
    T[..., 3, 3] = 1.0
    return T


def homog(R=None, p=None) -> np.ndarray:
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    if p is not None:
        T[:3, 3] = p
    return T


def frame_with_z(axis) -> np.ndarray:
    """Some rotation whose third column is the unit ``axis`` (Gram-Schmidt)."""
    z = np.asarray(axis, float) / np.linalg.norm(axis)
    helper = np.eye(3)[np.argmin(np.abs(z))]
    x = helper - (helper @ z) * z
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _motion(kind: str, q: np.ndarray) -> np.ndarray:
    """(N, 4, 4) rotation about z (revolute) or translation along z (prismatic)."""
    T = np.broadcast_to(np.eye(4), q.shape + (4, 4)).copy()
    if kind == "revolute":
        c, s = np.cos(q), np.sin(q)
        T[:, 0, 0], T[:, 0, 1], T[:, 1, 0], T[:, 1, 1] = c, -s, s, c
    else:
        T[:, 2, 3] = q
    return T


# --- the tests' own mechanism description ---------------------------------------------------------

@dataclass
class OwnJoint:
    name: str
    parent: str
    child: str
    kind: str = "revolute"            # or "prismatic"
    dh: tuple | None = None           # (theta, d, a, alpha): link frame by Eq. (1)
    X_pj: np.ndarray = field(default_factory=lambda: np.eye(4))
    X_jc: np.ndarray = field(default_factory=lambda: np.eye(4))

    def __post_init__(self):
        if self.dh is not None:       # Rz(theta) Tz(d) | Rz(q) | Tx(a) Rx(alpha)
            th, d, a, al = self.dh
            self.X_pj, self.X_jc = dh(th, d, 0.0, 0.0), dh(0.0, 0.0, a, al)


@dataclass
class OwnLink:
    name: str
    mass: float = 0.0
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))       # link frame, m
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))  # about the CoM, link axes


@dataclass
class OwnMech:
    base: str
    links: dict                       # name -> OwnLink (moving links)
    joints: list                      # OwnJoint, parents before children
    S: np.ndarray                     # (J, dof): q_all = S q_ind, joints in list order
    gravity: np.ndarray
    motors: dict = field(default_factory=dict)   # motor name -> (joint name, input rotation row of A^T)
    gears: dict = field(default_factory=dict)    # pair name -> own geometry (carrier frame)

    @property
    def joint_names(self) -> list[str]:
        return [j.name for j in self.joints]


def poses(om: OwnMech, q_all: np.ndarray) -> dict:
    """World pose (N, 4, 4) of every link for every joint's coordinate ``q_all`` (N, J)."""
    q_all = np.atleast_2d(q_all)
    N = q_all.shape[0]
    T = {om.base: np.broadcast_to(np.eye(4), (N, 4, 4))}
    for i, jt in enumerate(om.joints):
        if jt.dh is not None:
            th, d, a, al = jt.dh
            rel = dh(th + q_all[:, i], d, a, al)
        else:
            rel = jt.X_pj @ _motion(jt.kind, q_all[:, i]) @ jt.X_jc
        T[jt.child] = T[jt.parent] @ rel
    return T


def joint_frames(om: OwnMech, q_all: np.ndarray) -> dict:
    """World pose (N, 4, 4) of every joint frame (fixed in the child, z = axis)."""
    T = poses(om, q_all)
    return {jt.name: T[jt.parent] @ jt.X_pj @ _motion(jt.kind, np.atleast_2d(q_all)[:, i])
            for i, jt in enumerate(om.joints)}


def _vee_skew(M: np.ndarray) -> np.ndarray:
    """Axial vector of the antisymmetric part of M (N, 3, 3)."""
    return 0.5 * np.stack([M[:, 2, 1] - M[:, 1, 2], M[:, 0, 2] - M[:, 2, 0], M[:, 1, 0] - M[:, 0, 1]], axis=1)


D1 = np.array([1.0, -8.0, 0.0, 8.0, -1.0]) / 12.0          # five-point first derivative (x h)
D2 = np.array([-1.0, 16.0, -30.0, 16.0, -1.0]) / 12.0      # five-point second derivative (x h^2)


def fd_motion(om: OwnMech, traj, t: np.ndarray, h: float = 2e-3) -> dict:
    """Centre-of-mass and rotational motion of every moving link by central differences of
    its pose only, along ``traj(t) -> (q_ind, ...)``.

    Returns ``{link: dict(m, x, v, a, R, w, dw, I)}``, world frame, arrays (N, 3) or
    (N, 3, 3).  With R' = W R (W = skew(w)) and R'' = (W' + W W) R, w and w' are the axial
    vectors of R' R^T and R'' R^T (W W is symmetric).  Truncation error O(h^4).
    """
    samples = [poses(om, traj(t + k * h)[0] @ om.S.T) for k in (-2, -1, 0, 1, 2)]
    out = {}
    for name, link in om.links.items():
        Ts = np.stack([s[name] for s in samples])              # (5, N, 4, 4)
        xs = Ts[:, :, :3, :3] @ link.com + Ts[:, :, :3, 3]     # (5, N, 3)
        Rs = Ts[:, :, :3, :3]
        R = Rs[2]
        dR = np.tensordot(D1, Rs, axes=1) / h
        ddR = np.tensordot(D2, Rs, axes=1) / h ** 2
        Rt = np.transpose(R, (0, 2, 1))
        out[name] = dict(m=link.mass, x=xs[2], v=np.tensordot(D1, xs, axes=1) / h,
                         a=np.tensordot(D2, xs, axes=1) / h ** 2, R=R,
                         w=_vee_skew(dR @ Rt), dw=_vee_skew(ddR @ Rt),
                         I=R @ link.inertia @ Rt)
    return out


def kinetic_power(st: dict, gravity) -> tuple[np.ndarray, np.ndarray]:
    """dT/dt = sum m v.a + w.(I dw)  (w.(w x I w) = 0) and the power of gravity sum m g.v."""
    dT = sum(s["m"] * np.sum(s["v"] * s["a"], axis=1) + np.einsum("ni,nij,nj->n", s["w"], s["I"], s["dw"])
             for s in st.values())
    Pg = sum(s["m"] * (s["v"] @ np.asarray(gravity, float)) for s in st.values())
    return dT, Pg


def momentum_rates(st: dict) -> tuple[np.ndarray, np.ndarray]:
    """d/dt of the total linear momentum and of the angular momentum about the world origin."""
    dP = sum(s["m"] * s["a"] for s in st.values())
    dH = sum(np.cross(s["x"], s["m"] * s["a"]) + np.einsum("nij,nj->ni", s["I"], s["dw"])
             + np.cross(s["w"], np.einsum("nij,nj->ni", s["I"], s["w"])) for s in st.values())
    return dP, dH


class SineTrajectory:
    """q_ind(t) = q0 + sum_k A_k sin(w_k t + p_k), with exact rates and accelerations."""

    def __init__(self, dof: int, seed: int, amp=(0.3, 1.2), freq=(0.5, 3.0)):
        rng = np.random.default_rng(seed)
        self.q0 = rng.uniform(-np.pi, np.pi, dof)
        self.A = rng.uniform(*amp, (3, dof))
        self.w = rng.uniform(*freq, (3, dof))
        self.p = rng.uniform(0, 2 * np.pi, (3, dof))

    def __call__(self, t):
        arg = self.w * np.asarray(t, float)[:, None, None] + self.p
        return (self.q0 + np.sum(self.A * np.sin(arg), axis=1), np.sum(self.A * self.w * np.cos(arg), axis=1),
                -np.sum(self.A * self.w ** 2 * np.sin(arg), axis=1))


# --- Pinocchio from the tests' own description ------------------------------------------------------

class OwnPinocchio:
    """A Pinocchio model of ``om``'s joint tree: joint placements and body inertias from the
    test's own transforms (D-H rows split as Rz(theta) Tz(d) | q | Tx(a) Rx(alpha))."""

    def __init__(self, om: OwnMech):
        import pinocchio as pin

        self.pin = pin
        model = pin.Model()
        model.gravity = pin.Motion(np.asarray(om.gravity, float), np.zeros(3))
        jid, X = {om.base: 0}, {om.base: np.eye(4)}   # link -> Pinocchio joint, link frame in it
        for jt in om.joints:
            M = X[jt.parent] @ jt.X_pj
            jm = pin.JointModelRZ() if jt.kind == "revolute" else pin.JointModelPZ()
            i = model.addJoint(jid[jt.parent], jm, pin.SE3(M[:3, :3].copy(), M[:3, 3].copy()), jt.name)
            link = om.links[jt.child]
            Rjc, pjc = jt.X_jc[:3, :3], jt.X_jc[:3, 3]
            model.appendBodyToJoint(i, pin.Inertia(link.mass, Rjc @ link.com + pjc, Rjc @ link.inertia @ Rjc.T),
                                    pin.SE3.Identity())
            jid[jt.child], X[jt.child] = i, jt.X_jc
        self.model, self.data, self.om = model, model.createData(), om

    def rnea(self, q_all, qd_all, qdd_all):
        """Joint torques (N, J) and transmitted wrenches data.f (N, J, 6), joint frames."""
        pin, m, d = self.pin, self.model, self.data
        N, J = q_all.shape
        tau, f = np.zeros((N, J)), np.zeros((N, J, 6))
        for n in range(N):
            tau[n] = pin.rnea(m, d, q_all[n], qd_all[n], qdd_all[n])
            for i in range(J):
                f[n, i] = np.concatenate([d.f[i + 1].linear, d.f[i + 1].angular])
        return tau, f


# moved from gearcli.report.efforts (issue 39: the product never called it; the URDF
# test compares it with Pinocchio's joint torques)
def joint_efforts(an, res) -> np.ndarray:
    """(N, J) generalised force on every real joint about (along) its axis, on the child:
    the sum of the motors acting on it and the ideal couplings of its coordinate (N*m, N).

    Valid when every motor acts on real joints (a transmission motor, or a motor whose stator
    is its link's joint parent) and every ideal pair is a joint coupling (``GearPair.joints``):
    true for every URDF import.  Together with ``Result.joint`` it gives the whole wrench each
    joint transmits (what Pinocchio calls ``data.f``).
    """
    mech, tree = an.mech, an.tree
    N = res.motor.shape[0]
    out = np.zeros((N, len(mech.joints)))
    for mi in range(len(an.motor_links)):
        mj = an.motor_joints[mi] if an.motor_joints else None
        if mj is None:
            ji = tree.parent_joint[an.motor_links[mi]]
            if tree.parent[an.motor_links[mi]] != an.motor_stators[mi]:
                raise ValueError(f"motor '{mech.motors[mi].name}' does not act on one real joint")
            mj = ((ji, 1.0),)
        for ji, c in mj:
            out[:, ji] += c * res.motor[:, mi]
    for ci, c in enumerate(an.circuits):
        if c.joints is None:
            if c.geometry is None:
                raise ValueError(f"ideal pair '{mech.gears[c.gear].name}' is not a joint coupling")
            continue
        b, a = c.joints
        out[:, b] += res.gear_t[:, ci]
        out[:, a] -= c.ratio * res.gear_t[:, ci]
    return out
