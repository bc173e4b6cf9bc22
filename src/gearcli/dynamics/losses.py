"""Power losses of a drive: mesh friction and joint friction (docs/concepts/losses.md).

Mesh friction of pair p (gears j, k, carrier c; any kind with tooth geometry)
-----------------------------------------------------------------------------
With t_p the tangential tooth force (Eq. 14), c_p = 1 - eta_p the loss factor and
theta'_{j,c} the rate of gear j relative to the carrier about its axis z_j, the mesh
dissipates

    P_p = c_p |t_p| v_p,   v_p = |theta'_{j,c}| r_j            (pitch-line speed, m/s)

as an internal couple pair along the gears' relative angular velocity
omega_jk = omega_j - omega_k = theta'_{j,c} z_j - theta'_{k,c} z_k: -C_p u on gear j and
+C_p u on gear k, u = omega_jk / |omega_jk|, C_p = P_p / |omega_jk|.  The pair's net force
and moment stay zero, and the couples' power is -C_p u.(omega_j - omega_k) = -P_p.

With the ratio fixed, theta'_{k,c} = theta'_{j,c} / e (e = theta_{j,c} / theta_{k,c}), so
omega_jk = theta'_{j,c} u0 with the constant carrier-frame vector u0 = z_j - z_k / e (a rack
does not turn: u0 = z_j), and the couple on j is

    -C_p u = -c_p |t_p| s_v r_j u0 / |u0|^2 = -(sigma_p s_v) t_p * c_p r_j u0 / |u0|^2,

sigma_p = sign(t_p), s_v = sign(theta'_{j,c}) (0 at rest: no couple).  It is linear in t_p
for given signs, exactly like the separating force |t| tan(phi) of Eq. 14, so the block
solves and the sign rule carry over: the column of t_p gains sigma_p s_v times the moment
:func:`mesh_friction_moment` (on j; minus it on k).  For an external spur pair
r_j |u0|^-2 |u0| = r_j r_k / (r_j + r_k), for an internal pair r_j r_k / |r_k - r_j|, for a
rack r_j: the classic friction arm.

Joint friction (load-independent, the robotics convention)
----------------------------------------------------------
On the joint's child -F_c sign(q'_J) - F_v q'_J about (along) the axis, reversed on the
parent, q'_J the joint's own rate; it dissipates F_c |q'_J| + F_v q'_J^2.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import loss_terms as T
from ..algebra import ARRAYS, as_array
from .wrenches import joint_axis_wrench
from ..model.worms import worm_force
from ..model.belts import Belt, belt_arms, slack_problem
from ..errors import GearcliError
from ..spatial import cross


def mesh_friction_moment(an, ci: int) -> np.ndarray | None:
    """The friction couple on gear j of circuit ``ci`` per unit of sigma_p s_v t_p,
    -c_p r_j u0 / |u0|^2 (carrier frame; N*m per N, i.e. m), module docstring; gear k
    receives the opposite.  None for a lossless pair or one without tooth geometry."""
    c = an.circuits[ci]
    loss = an.mech.gears[c.gear].loss_factor
    if not loss or c.geometry is None or c.joints is not None:
        return None
    gm = c.geometry
    u0 = gm.zj if not np.isfinite(gm.r_k) else gm.zj - gm.zk / c.ratio
    return -loss * gm.r_j * u0 / float(u0 @ u0)


def relative_rate(an, kin, ci: int) -> np.ndarray:
    """theta'_{j,c} (N,): rate of gear j relative to its carrier about j's axis, rad/s.

    Formed from the joint rates, sum_d r_d q'_d over the independent rates with the
    coefficients r of :attr:`~gearcli.analysis.types.Analysis.mesh_rate_rows` (left to
    right, as the kernel's :func:`.llvm.friction_terms.mesh_rates`), not from world angular
    velocities (omega_j - omega_c) . z_j: a gear at rest on its carrier gives an exact 0, so
    no friction couple, in any frames."""
    return mesh_rate(an, kin.independent_rates(an), ci)


def mesh_rate(an, qd_ind: np.ndarray, ci: int) -> np.ndarray:
    """theta'_{j,c} (N,) of circuit ``ci`` from the independent rates ``qd_ind`` (N, dof)
    (:func:`relative_rate`)."""
    r = an.mesh_rate_rows[ci]
    out = np.zeros(qd_ind.shape[0])
    for d in np.flatnonzero(r):
        out = out + r[d] * qd_ind[:, d]
    return out


def reducers(an):
    """(circuit index, Reducer) of every coaxial reducer of ``an``."""
    gears = an.mech.gears
    return [(ci, gears[c.gear].reducer) for ci, c in enumerate(an.circuits) if gears[c.gear].reducer is not None]


def subtract_reducer_drag(an, kin, b: dict) -> None:
    """b_L -= the reducers' no-load running torques (:func:`.loss_terms.no_load_torque`:
    on the input about z_I, the opposite on the housing), in place: known loads, like joint
    friction."""
    moving = set(an.tree.moving)
    for ci, red in reducers(an):
        if red.no_load_torque is None:
            continue
        c = an.circuits[ci]
        a = relative_rate(an, kin, ci)
        T0 = ARRAYS.interp(ARRAYS.call("fabs", a), _table(red.no_load_torque))
        tq = np.broadcast_to(ARRAYS.plus_zero(T.no_load_torque(ARRAYS, T0, ARRAYS.sign(a))), a.shape)   # no -0 at rest
        z = np.einsum("nij,j->ni", kin.R[c.carrier], c.zj)
        w = np.concatenate([np.zeros_like(z), tq[:, None] * z], axis=1)
        for L, sign in ((c.j, 1.0), (c.carrier, -1.0)):
            if L in moving:
                b[L] -= sign * w


def subtract_belt_pretension(an, kin, b: dict) -> None:
    """b_L -= the belts' pretension forces (:mod:`gearcli.model.belts`), in place: on pulley j
    T_i e_A at X_jA and T_i e_B at X_jB, on k the opposites at X_kA, X_kB (a known load)."""
    moving = set(an.tree.moving)
    for c in an.circuits:
        bt = an.mech.gears[c.gear].belt
        if bt is None or not bt.pretension:
            continue
        Rc, oc = kin.R[c.carrier], kin.o[c.carrier]
        for side, L, sign in ((0, c.j, 1.0), (1, c.k, -1.0)):
            if L not in moving:
                continue
            for s in (0, 1):
                d = np.einsum("nij,j->ni", Rc, c.belt.e[s])
                P = oc + np.einsum("nij,j->ni", Rc, c.belt.X[s, side])
                b[L] -= sign * bt.pretension * np.concatenate([d, cross(P - kin.o[L], d)], axis=1)


class SlackError(GearcliError):
    """A belt's slack span would have a negative tension at a sample: |E|/2 > T_i."""

    def __init__(self, sample: int, belt: str, pretension: float, half: float):
        super().__init__()
        self.sample, self.belt, self.pretension, self.half = sample, belt, pretension, half

    def lines(self) -> list[str]:
        return [f"sample {self.sample}: belt '{self.belt}' goes slack: pretension T_i = {self.pretension:g} N < "
                f"|E|/2 = {self.half:.6g} N (raise the pretension, or lower the load)"]


def check_belts(an, res) -> None:
    """SlackError at the first sample of ``res`` where a belt's slack span would go below zero
    tension, |E|/2 > T_i (the commands call it on what they read from a file: the library's
    solve returns the tensions, negative ones included)."""
    for ci, c in enumerate(an.circuits):
        bt = an.mech.gears[c.gear].belt
        if bt is None:
            continue
        E = res.gear_t[:, ci]
        bad = slack_problem(bt, E)
        if bad is not None:
            raise SlackError(bad, an.mech.gears[c.gear].name, bt.pretension, abs(float(E[bad])) / 2)


def loss_couples(belt: Belt, tj: float, tk: float, rate, sigma) -> tuple[np.ndarray, np.ndarray]:
    """(on j, on k) (N,): a lossy belt's loss couple about z per unit of its effective pull E
    (the carrier takes the opposite), N*m per N.  ``rate`` (N,) is pulley j's rate relative
    to the carrier about z (from the joint rates), ``tj``, ``tk`` E's torque arms on j and k
    (:func:`gearcli.model.belts.belt_arms`), ``sigma`` = sign(E).

    The belt is two power-flow elements of drive rate w = tj omega_j = -tk omega_k (minus the
    power of E on k per unit E), s_w = sign(w), read at |omega_j| (the kernel's two elements
    of :mod:`.llvm.loss_program`, the same laws :func:`.loss_terms.power_flow_coefficients`
    modes 1 and 2 and :func:`.loss_terms.power_flow_delta`): where power flows j -> k
    (sigma s_w = -1) the driven pulley k gets -tk (1 - eta_f) per unit E, -(1 - eta_f) |E tk|
    against its rotation; where it flows k -> j (sigma s_w = +1) j gets -tj (1 - eta_b) per
    unit E; at rest (w = 0) nothing."""
    al, n = ARRAYS, np.shape(rate)[0]
    rate, sigma = np.asarray(rate, float), np.asarray(sigma, float)
    s_w, speed = al.sign(al.mul(float(tj), rate)), al.call("fabs", rate)
    tables = _table(belt.forward), _table(belt.backward)
    on_k = al.mul(-float(tk), T.power_flow_delta(al, *T.power_flow_coefficients(al, speed, *tables, 1), sigma, s_w))
    on_j = al.mul(float(tj), T.power_flow_delta(al, *T.power_flow_coefficients(al, speed, *tables, 2), sigma, s_w))
    return as_array(on_j, n), as_array(on_k, n)


def belt_loss(belt: Belt, tj: float, tk: float, rk: float, rate, E) -> np.ndarray:
    """The power a lossy belt dissipates (N,), W >= 0: minus the power of its loss couples
    (:func:`loss_couples`) times E, +0 at rest."""
    rate, E = np.asarray(rate, float), np.asarray(E, float)
    on_j, on_k = loss_couples(belt, tj, tk, rate, np.sign(E))
    return -(on_j * rate + on_k * rk * rate) * E + 0.0


def power_flow_sides(c, gp) -> tuple:
    """((link, coef), ...): where a lossy reducer's or screw's power-flow change delta u acts,
    as a moment coef delta u z about its axis z: a reducer's on its input (+1) and housing
    (-1), a screw's torque h u on the screw (-h) and the nut (+h) (circuit ``c`` of gear pair
    ``gp``; both paths' columns: :class:`.equations.Columns`, :mod:`.llvm.loss_program`)."""
    if gp.reducer is not None:
        return ((c.j, 1.0), (c.carrier, -1.0))
    return ((c.j, -gp.screw.h), (c.k, gp.screw.h))


def fill_belts(an, qd_ind: np.ndarray, res) -> None:
    """A solved ``res``'s belt fields, in place: ``gear_loss`` (a lossy mechanism) the loss of a
    lossy belt (:func:`belt_loss`)."""
    for ci, c in enumerate(an.circuits):
        bt = an.mech.gears[c.gear].belt
        if bt is None:
            continue
        E = res.gear_t[:, ci]
        if res.gear_loss is not None:
            res.gear_loss[:, ci] = belt_loss(bt, **belt_arms(c.belt), rate=mesh_rate(an, qd_ind, ci), E=E) if bt.lossy else 0.0


def fill_worms(an, qd_ind: np.ndarray, res) -> None:
    """A solved ``res``'s worm-pair fields, in place (:mod:`gearcli.model.worms`), from the flank
    loads N (``gear_t``) and the independent rates: ``gear_sep`` the wheel's tangential force
    F . t_G, ``gear_axial[:, ci, 0]`` the force on the worm along its axis (-F . z_w), and
    ``gear_loss`` (a lossy mechanism) mu |N| |v_s|, |v_s| = |w_W| d1 / (2 cos(gamma))."""
    for ci, c in enumerate(an.circuits):
        wm = an.mech.gears[c.gear].worm
        if wm is None:
            continue
        rate = mesh_rate(an, qd_ind, ci)
        F = worm_force(c.worm, wm, res.gear_t[:, ci], np.sign(rate))
        res.gear_sep[:, ci] = F @ c.worm.t_g
        res.gear_axial[:, ci, 0] = -(F @ c.worm.z_w)
        res.gear_radial[:, ci, :] = 0.0
        res.gear_axial[:, ci, 1] = 0.0
        if res.gear_loss is not None:
            res.gear_loss[:, ci] = wm.mu * np.abs(res.gear_t[:, ci]) * np.abs(rate) * wm.d1 / (2 * np.cos(wm.lead_angle))


def fill_reducers(an, qd_ind: np.ndarray, res) -> None:
    """A solved ``res``'s reducer fields, in place, from its unknowns u (``gear_t``) and the
    independent rates ``qd_ind``: ``gear_sep`` holds the torque each reducer exerts on its input
    about z_I, losses included (:func:`.loss_terms.input_torque`), and ``gear_loss`` (a lossy
    mechanism) its dissipated power, and a screw's (:func:`.loss_terms.element_loss`)."""
    for ci, c in enumerate(an.circuits):
        gp = an.mech.gears[c.gear]
        if gp.reducer is None and (gp.screw is None or res.gear_loss is None):
            continue
        u, f = res.gear_t[:, ci], power_flow_terms(an, ci, mesh_rate(an, qd_ind, ci))
        delta = T.power_flow_delta(ARRAYS, f.A, f.B, ARRAYS.sign(u), f.s_w)
        if gp.reducer is not None:
            res.gear_sep[:, ci] = T.input_torque(ARRAYS, delta, u, f.T0, f.s_w)
        if res.gear_loss is not None:
            res.gear_loss[:, ci] = T.element_loss(ARRAYS, delta, u, f.w, f.T0, f.speed)


@dataclass(frozen=True)
class PowerFlow:
    """A power-flow element's per-sample terms (:mod:`.loss_terms`): delta = A s_w^2 +
    B sigma s_w, its drive rate w and s_w = sign(w), its speed |a| and no-load torque T0."""

    A: object
    B: object
    s_w: np.ndarray
    w: np.ndarray
    speed: np.ndarray
    T0: object


def power_flow_terms(an, ci: int, a: np.ndarray) -> PowerFlow:
    """The :class:`PowerFlow` of circuit ``ci``, a reducer or a screw, at its rates ``a`` (N,):
    a reducer's input rate relative to the housing (its drive rate w = a), a screw's rate
    relative to the nut (w = -h a: :mod:`gearcli.model.screws`); the tables read at |a|."""
    gp = an.mech.gears[an.circuits[ci].gear]
    el = gp.reducer if gp.reducer is not None else gp.screw
    w = a if gp.reducer is not None else -gp.screw.h * a
    speed = ARRAYS.call("fabs", a)
    A, B = T.power_flow_coefficients(ARRAYS, speed, _table(el.forward), _table(el.backward))
    t0 = getattr(el, "no_load_torque", None)
    return PowerFlow(A, B, ARRAYS.sign(w), w, speed, 0.0 if t0 is None else ARRAYS.interp(speed, _table(t0)))


def _table(t) -> tuple:
    """A :class:`gearcli.model.power_flow.SpeedTable` as (speeds, values)."""
    return t.speeds, t.values


def mesh_loss(an, kin, ci: int, t: np.ndarray) -> np.ndarray:
    """Mesh power loss P_p = c_p |t_p| |theta'_{j,c}| r_j (N,), W (:func:`.loss_terms.mesh_loss`)."""
    c = an.circuits[ci]
    loss = an.mech.gears[c.gear].loss_factor
    if not loss or c.geometry is None:
        return np.zeros_like(t)
    return T.mesh_loss(ARRAYS, float(loss), float(c.geometry.r_j), t, relative_rate(an, kin, ci))


def friction_force(coulomb, viscous, qd: np.ndarray) -> np.ndarray:
    """The joint friction law, -F_c sign(qd) - F_v qd (:func:`.loss_terms.joint_friction`;
    broadcast: one joint's (N,) rates, or (N, J) with per-joint coefficients (J,)); +0.0 at rest."""
    return T.joint_friction(ARRAYS, coulomb, viscous, qd)


def joint_friction_forces(joints, qd_all: np.ndarray) -> np.ndarray:
    """(N, J) :func:`friction_force` of every joint (0 without friction) at the rates (N, J)."""
    return friction_force(*friction_coefficients(joints), qd_all)


def friction_coefficients(joints) -> tuple[np.ndarray, np.ndarray]:
    """(F_c (J,), F_v (J,)) of ``joints`` (0 without friction)."""
    fr = [(j.friction.coulomb, j.friction.viscous) if j.friction is not None else (0.0, 0.0) for j in joints]
    return np.array([f[0] for f in fr], float), np.array([f[1] for f in fr], float)


def joint_friction_force(jt, qd: np.ndarray) -> np.ndarray:
    """Friction generalised force on the joint's child, -F_c sign(qd) - F_v qd (N,); N*m
    (revolute) or N (prismatic); zeros without friction."""
    fr = jt.friction
    if fr is None:
        return np.zeros_like(qd)
    return friction_force(fr.coulomb, fr.viscous, qd)


def subtract_joint_friction(an, kin, b: dict, qd_all: np.ndarray) -> None:
    """b_L -= the joint friction wrenches on L (known from the joint rates ``qd_all`` (N, J)),
    in place: friction is a known load, moved to the right-hand side like gravity."""
    moving = set(an.tree.moving)
    for ji, jt in enumerate(an.mech.joints):
        if jt.friction is None or not jt.friction.active:
            continue
        Q = joint_friction_force(jt, qd_all[:, ji])
        for name in (jt.child, jt.parent):
            L = an.tree.index[name]
            if L in moving:
                b[L] -= Q[:, None] * joint_axis_wrench(an, kin, ji, L)


LOSS_FIELDS = ("gear_loss", "joint_friction", "joint_loss", "bearing_iterations")   # of a lossy mechanism


def fill_losses(an, kin, qd_all: np.ndarray, res, bearing: np.ndarray | None = None,
                iterations: np.ndarray | None = None) -> None:
    """Set the loss fields of the :class:`~.solve.Result` ``res`` from its tooth forces and
    the joint rates ``qd_all`` (N, J): ``gear_loss`` (N, G) mesh power loss, W (0 for an
    ideal pair); ``joint_friction`` (N, J) the friction on each joint's child about (along)
    its axis, N*m (N), with the bearing friction moments ``bearing`` (N, J) >= 0
    (:mod:`.bearing_friction`) against the rate; ``joint_loss`` (N, J) its power loss, W;
    ``bearing_iterations`` (N,) the fixed-point iterations of the bearing friction (None
    without it).  Nothing for a lossless mechanism (the fields stay None)."""
    if not an.mech.has_losses:
        return
    res.gear_loss = np.empty((qd_all.shape[0], len(an.circuits)))
    for ci in range(len(an.circuits)):
        res.gear_loss[:, ci] = mesh_loss(an, kin, ci, res.gear_t[:, ci])
    res.joint_friction = joint_friction_forces(an.mech.joints, qd_all)
    res.joint_loss = -(res.joint_friction * qd_all)          # -F q' = F_c |q'| + F_v q'^2, all joints at once
    _add_bearing(res, qd_all, bearing, iterations)


def _add_bearing(res, qd_all: np.ndarray, bearing: np.ndarray | None, iterations: np.ndarray | None) -> None:
    """The bearing friction moments (N, J) into ``res``'s joint friction and loss, in place."""
    if bearing is not None:
        res.joint_friction -= np.sign(qd_all) * bearing
        res.joint_loss += bearing * np.abs(qd_all)
        res.bearing_iterations = iterations


def fill_kernel_losses(res, arrays: dict, losses: dict) -> None:
    """The loss fields of ``res`` from the llvm kernel's loss outputs in ``arrays`` (gear_loss,
    joint_friction, joint_loss, the bearing friction included; none for a lossless
    mechanism) and the bearing iterations its driver put in ``losses`` ("iterations")."""
    for k in set(arrays) & {"gear_loss", "joint_friction", "joint_loss"}:
        setattr(res, k, arrays[k])
    res.bearing_iterations = losses.get("iterations")
