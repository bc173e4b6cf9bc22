"""Losses (mesh friction, joint friction): power balances and hand cases.

The references share no code with the solver's equations (Columns, blocks, losses):

* the power balance takes the rate of kinetic energy, the power of gravity and of the
  external loads from link velocities and accelerations of the kinematics alone (the velocity
  of a link origin is the acceleration recursion run with zero rates and q'' := q', i.e.
  J(q) q'), and the losses from their definitions (c |t| |theta'_jc| r_j, F_c |q'| + F_v q'^2);
* the hand cases are one-line statics of a gear pair, a planetary and a rack, written here
  from the model statement of the README ("Losses").
"""
from __future__ import annotations

import dataclasses
import textwrap
from pathlib import Path

import numpy as np
import pytest

from gearcli import analyse, load_mechanism, parse_mechanism, solve
from gearcli.dynamics.kinematics import forward
from gearcli.model.friction import JointFriction
from gearcli.model.reducers import SpeedTable
from gearcli.report.columns import named_columns

MECH = Path(__file__).resolve().parents[1] / "mechanisms"
BUNDLED = sorted(p.name for p in MECH.glob("*.yaml")) + ["geared_arm.urdf"]


def with_losses(mech, c=0.03, coulomb=0.05, viscous=0.002, mu=0.004, bore=0.02):
    """``mech`` with a loss factor on every pair with tooth geometry, friction on every joint
    and a friction coefficient on every bearing it lists."""
    gears = tuple(dataclasses.replace(g, loss_factor=c) if g.mesh_point is not None and g.joints is None else g
                  for g in mech.gears)
    joints = tuple(dataclasses.replace(j, friction=JointFriction(coulomb, viscous), bearings=None if not j.bearings
                                       else tuple(dataclasses.replace(b, friction_coefficient=mu, bore=bore)
                                                  for b in j.bearings))
                   for j in mech.joints)
    return dataclasses.replace(mech, gears=gears, joints=joints)


def own_bearing_loads(jt, w):
    """|load| (N,) of each bearing of joint ``jt`` from its reaction w (N, 6) (parent on child,
    joint frame, about its origin): one bearing takes |f|; two at z1, z2 carry the force and
    the tilting moment by the lever rule (the locating one takes fz too)."""
    if len(jt.bearings) == 1:
        return [np.linalg.norm(w[:, :3], axis=1)]
    z1, z2 = jt.bearings[0].position, jt.bearings[1].position
    # moments about bearing 1's point: (z2 - z1) e_z x R2 = M_xy - z1 e_z x F_xy (x, y parts)
    R2x = (w[:, 4] - z1 * w[:, 0]) / (z2 - z1)
    R2y = (-w[:, 3] - z1 * w[:, 1]) / (z2 - z1)
    R = [(w[:, 0] - R2x, w[:, 1] - R2y), (R2x, R2y)]
    return [np.sqrt(rx ** 2 + ry ** 2 + (w[:, 2] ** 2 if b.locating else 0.0))
            for (rx, ry), b in zip(R, jt.bearings)]


def random_motion(dof, n=60, seed=3):
    rng = np.random.default_rng(seed)
    return rng.uniform(-np.pi, np.pi, (n, dof)), rng.uniform(-3, 3, (n, dof)), rng.uniform(-8, 8, (n, dof))


def energy_terms(an, q, qd, qdd):
    """(dT/dt, power of gravity, power of the external loads) (N,) from kinematics only."""
    mech, tree = an.mech, an.tree
    qa, qda, qdda = q @ an.S.T, qd @ an.S.T, qdd @ an.S.T
    kin = forward(mech, tree, qa, qda, qdda)
    vel = forward(mech, tree, qa, np.zeros_like(qa), qda)   # a := J q', dw := J_w q' = omega
    dT = np.zeros(q.shape[0])
    Pg = np.zeros(q.shape[0])
    for L in tree.moving:
        link = mech.link(tree.links[L])
        R, w, dw = kin.R[L], kin.w[L], kin.dw[L]
        assert np.allclose(vel.dw[L], w, atol=1e-12 * (1 + np.abs(w).max()))
        r = np.einsum("nij,j->ni", R, link.com)
        v = vel.a[L] + np.cross(w, r)
        a = kin.a[L] + np.cross(dw, r) + np.cross(w, np.cross(w, r))
        Iw = R @ link.inertia @ R.transpose(0, 2, 1)
        dT += link.mass * np.sum(v * a, axis=1) + np.einsum("ni,nij,nj->n", w, Iw, dw)
        Pg += link.mass * (v @ mech.gravity)
    Pe = np.zeros(q.shape[0])
    for ld in mech.loads:
        L = tree.index[ld.link]
        R, w = kin.R[L], kin.w[L]
        r = np.einsum("nij,j->ni", R, ld.point)
        v = vel.a[L] + np.cross(w, r)
        F, M = np.asarray(ld.force, float), np.asarray(ld.moment, float)
        if ld.frame == "link":
            F, M = np.einsum("nij,j->ni", R, F), np.einsum("nij,j->ni", R, M)
        Pe += np.sum(F * v, axis=-1) + np.sum(M * w, axis=-1)
    return dT, Pg, Pe


def own_losses(an, q, qd, res):
    """Sum of the losses from their definitions (N,), and each one (for the sign test)."""
    mech, tree = an.mech, an.tree
    qa, qda = q @ an.S.T, qd @ an.S.T
    kin = forward(mech, tree, qa, qda)
    parts = []
    for ci, c in enumerate(an.circuits):
        gp = mech.gears[c.gear]
        if gp.reducer is not None:
            parts.append(own_reducer_loss(an, kin, ci, res))
            continue
        if gp.screw is not None:
            parts.append(own_screw_loss(an, kin, ci, res))
            continue
        if gp.belt is not None:
            parts.append(own_belt_loss(an, kin, ci, res))
            continue
        if gp.worm is not None:         # mu |N| |v_s|, the sliding speed from the links' velocities at P
            P = np.einsum("nij,j->ni", kin.R[c.carrier], c.worm.P) + kin.o[c.carrier]
            vel = forward(mech, tree, qa, np.zeros_like(qa), qda)
            vw = vel.a[c.j] + np.cross(kin.w[c.j], P - kin.o[c.j])
            vg = vel.a[c.k] + np.cross(kin.w[c.k], P - kin.o[c.k])
            parts.append(gp.worm.mu * np.abs(res.gear_t[:, ci]) * np.linalg.norm(vw - vg, axis=1))
            continue
        if not gp.loss_factor:
            continue
        zj = np.einsum("nij,j->ni", kin.R[c.carrier], c.geometry.zj)
        rate = np.sum((kin.w[c.j] - kin.w[c.carrier]) * zj, axis=1)
        parts.append(gp.loss_factor * np.abs(res.gear_t[:, ci]) * np.abs(rate) * c.geometry.r_j)
    for ji, jt in enumerate(mech.joints):
        if jt.friction is not None:
            parts.append(jt.friction.coulomb * np.abs(qda[:, ji]) + jt.friction.viscous * qda[:, ji] ** 2)
        for b, P in zip(jt.bearings or (), own_bearing_loads(jt, res.joint[:, ji]) if jt.bearings else ()):
            parts.append(0.5 * b.friction_coefficient * b.bore * P * np.abs(qda[:, ji]))
    return np.sum(parts, axis=0), parts


def own_reducer_loss(an, kin, ci, res):
    """A reducer's loss from the model statement (drive-elements.md A): the axis u = z_O, a and b
    the input's and the output's rates relative to the housing about u from the link angular
    velocities, T the printed gear:<r>:torque; the torque on I is -(T/i0)/eta_f where T b > 0,
    -(T/i0) eta_b where T b < 0, plus -T0 sign(a); the loss is minus the power the element
    delivers, -(tau_I a + T b).  The printed input_torque is checked against tau_I on the way."""
    c, gp = an.circuits[ci], an.mech.gears[an.circuits[ci].gear]
    red, i0 = gp.reducer, gp.ratio
    RH = kin.R[c.carrier]
    zI, zO = np.einsum("nij,j->ni", RH, c.zj), np.einsum("nij,j->ni", RH, c.zk)
    a = np.sum((kin.w[c.j] - kin.w[c.carrier]) * zO, axis=1)
    b = np.sum((kin.w[c.k] - kin.w[c.carrier]) * zO, axis=1)
    cols = named_columns(an, res)
    T = cols[f"gear:{gp.name}:torque"]
    eta_f = np.interp(np.abs(a), red.forward.speeds, red.forward.values)
    eta_b = np.interp(np.abs(a), red.backward.speeds, red.backward.values)
    flow = np.sign(T * b)
    tau_I = -(T / i0) * np.where(flow > 0, 1 / eta_f, np.where(flow < 0, eta_b, 1.0))
    if red.no_load_torque is not None:
        tau_I = tau_I - np.interp(np.abs(a), red.no_load_torque.speeds, red.no_load_torque.values) * np.sign(a)
    scale = 1.0 + np.abs(T)
    assert np.max(np.abs(cols[f"gear:{gp.name}:input_torque"] - tau_I * np.sum(zI * zO, axis=1)) / scale) < 1e-11
    return -(tau_I * a + T * b)


def own_belt_loss(an, kin, ci, res):
    """A belt's loss from the model statement (drive-elements.md C): the pulleys' rates relative
    to the carrier about z from the link angular velocities, the torque of the spans' pull E on
    each pulley (E/2 along e_A at its span-A point, -E/2 along e_B at its span-B point on j, the
    opposites on k) about its centre; power flows j -> k where E's power on k is > 0: the loss is
    (1 - eta_f) |E's torque on k| |omega_k|, else (1 - eta_b) |E's torque on j| |omega_j|."""
    c, gp = an.circuits[ci], an.mech.gears[an.circuits[ci].gear]
    bt, g = gp.belt, c.belt
    z = np.einsum("nij,j->ni", kin.R[c.carrier], c.zj)
    wj = np.sum((kin.w[c.j] - kin.w[c.carrier]) * z, axis=1)
    wk = np.sum((kin.w[c.k] - kin.w[c.carrier]) * z, axis=1)
    E = named_columns(an, res)[f"gear:{gp.name}:effective_pull"]
    tj = (np.cross(g.X[0, 0] - g.C_j, 0.5 * g.e[0]) + np.cross(g.X[1, 0] - g.C_j, -0.5 * g.e[1])) @ g.z
    tk = (np.cross(g.X[0, 1] - g.C_k, -0.5 * g.e[0]) + np.cross(g.X[1, 1] - g.C_k, 0.5 * g.e[1])) @ g.z
    speed = np.abs(wj)
    eta_f = np.interp(speed, bt.forward.speeds, bt.forward.values)
    eta_b = np.interp(speed, bt.backward.speeds, bt.backward.values)
    on_k = E * tk * wk
    return np.where(on_k > 0, (1 - eta_f) * np.abs(E * tk * wk), np.where(on_k < 0, (1 - eta_b) * np.abs(E * tj * wj), 0.0))


def own_screw_loss(an, kin, ci, res):
    """A screw's loss from the model statement (drive-elements.md B): u = z_S, a the screw's rate
    relative to the carrier from the link angular velocities, h = +-lead/(2 pi) by hand, F the
    printed gear:<s>:force; the torque on the nut h F / eta_f where F h a > 0 (the screw drives),
    h F eta_b where F h a < 0; the loss is minus the power the element delivers to screw and
    nut, -(F h a - tau_N a) (the nut does not turn relative to the carrier)."""
    c, gp = an.circuits[ci], an.mech.gears[an.circuits[ci].gear]
    sc = gp.screw
    u = np.einsum("nij,j->ni", kin.R[c.carrier], c.zj)
    a = np.sum((kin.w[c.j] - kin.w[c.carrier]) * u, axis=1)
    h = (1.0 if sc.hand == "right" else -1.0) * sc.lead / (2 * np.pi)
    F = named_columns(an, res)[f"gear:{gp.name}:force"]
    eta_f = np.interp(np.abs(a), sc.forward.speeds, sc.forward.values)
    eta_b = np.interp(np.abs(a), sc.backward.speeds, sc.backward.values)
    flow = np.sign(F * h * a)
    tau_N = h * F * np.where(flow > 0, 1 / eta_f, np.where(flow < 0, eta_b, 1.0))
    return -(F * h * a - tau_N * a)


def _load(name):
    return load_mechanism(MECH / name)


@pytest.mark.parametrize("name", BUNDLED)
@pytest.mark.parametrize("method", ["block", "full"])
def test_power_balance_with_losses(name, method):
    """Sum of motor power = dT/dt - P_gravity - P_loads + sum of losses, per sample, to 1e-9,
    on every bundled mechanism with losses switched on; the losses the solver reports equal
    their definitions and are >= 0, and they are real (the lossless balance is off by them)."""
    an = analyse(with_losses(_load(name)))
    q, qd, qdd = random_motion(an.dof)
    res = solve(an, q, qd, qdd, method=method, verify=True)
    assert res.residual < 1e-10
    dT, Pg, Pe = energy_terms(an, q, qd, qdd)
    total, parts = own_losses(an, q, qd, res)
    P_motor = np.sum(res.motor * res.motor_speed, axis=1)
    scale = 1.0 + np.abs(P_motor) + np.abs(dT) + np.abs(Pg) + np.abs(Pe) + total
    assert np.max(np.abs(P_motor - (dT - Pg - Pe + total)) / scale) < 1e-9
    assert all(np.all(p >= 0) for p in parts)
    reported = res.gear_loss.sum(axis=1) + res.joint_loss.sum(axis=1)
    assert np.max(np.abs(reported - total) / scale) < 1e-11
    if any(j.bearings for j in an.mech.joints):
        assert 2 <= np.median(res.bearing_iterations) and np.max(res.bearing_iterations) <= 10
    assert np.min(total) > 0 and np.max(np.abs(P_motor - (dT - Pg - Pe)) / scale) > 1e-4


@pytest.mark.parametrize("name", BUNDLED)
def test_lossless_mechanism_outputs_unchanged_and_without_loss_columns(name):
    """Efficiency 1 and zero friction written out: every output equals the file without them,
    bit for bit, and no loss column appears."""
    def stripped(m, mu):
        """m without losses: none at all (mu None), or every one written as zero (mu 0)."""
        fr = None if mu is None else JointFriction(0.0, 0.0)

        def red(r):
            """A reducer without losses: none at all, or efficiency 1 and a zero no-load torque."""
            if r is None:
                return None
            return r.lossless() if mu is None else dataclasses.replace(
                r.lossless(), no_load_torque=SpeedTable.constant(0.0))
        return dataclasses.replace(m, gears=tuple(dataclasses.replace(g, loss_factor=0.0, reducer=red(g.reducer),
                                                                      screw=g.screw and g.screw.lossless(),
                                                                      worm=g.worm and g.worm.lossless(),
                                                                      belt=g.belt and g.belt.lossless())
                                                  for g in m.gears),
                                   joints=tuple(dataclasses.replace(j, friction=fr, bearings=None if not j.bearings else
                                                tuple(dataclasses.replace(b, friction_coefficient=mu) for b in j.bearings))
                                                for j in m.joints))
    mech, zero = stripped(_load(name), None), stripped(_load(name), 0.0)
    a0, a1 = analyse(mech), analyse(zero)
    q, qd, qdd = random_motion(a0.dof, n=20)
    c0 = named_columns(a0, solve(a0, q, qd, qdd, backend="numpy"))
    c1 = named_columns(a1, solve(a1, q, qd, qdd, backend="numpy"))
    assert list(c0) == list(c1) and not any(k.endswith((":loss", ":friction")) for k in c1)
    for k in c0:
        assert np.array_equal(c0[k], c1[k]), k


# --- hand cases ----------------------------------------------------------------------------------

SPUR = """
name: spur_hoist
gravity: [0, 0, 0]
base: base
end_effector: drum
links:
  - {{name: base}}
  - {{name: pinion, mass: 0.1, inertia: [1.0e-5, 1.0e-5, 1.0e-5]}}
  - {{name: drum, mass: 1.0, inertia: [1.0e-3, 1.0e-3, 1.0e-3]}}
joints:
  - {{name: JP, parent: base, child: pinion, origin: {{xyz: [0, 0, 0]}}, axis: [0, 0, 1]}}
  - {{name: JD, parent: base, child: drum, origin: {{xyz: [0.075, 0, 0]}}, axis: [0, 0, 1]}}
gears:
  - {{name: stage, links: [pinion, drum], teeth: [15, 60], mesh_point: [0.015, 0, 0], efficiency: {eta}}}
motors:
  - {{name: m, link: pinion}}
loads:
  - {{name: rope, link: drum, frame: base, moment: [0, 0, {ML}]}}
"""


@pytest.mark.parametrize("eta", [0.97, 0.9])
def test_spur_pair_lifting_then_lowering(eta):
    """A 15/60 mm spur pair holding a load moment M_L on the drum, at constant speed.
    Lifting (the pinion drives): T = M_L (r_j + c rho) / (r_k - c rho); lowering (the load
    drives back, the motor brakes): T = M_L (r_j - c rho) / (r_k + c rho), rho = r_j r_k /
    (r_j + r_k): the friction couple opposes the motion both ways, so the motor needs more
    torque to lift than the lossless M_L r_j / r_k and less to hold back the lowering load."""
    ML, rj, rk, c = -4.0, 0.015, 0.06, 1.0 - eta     # the rope pulls the drum about -z
    an = analyse(parse_mechanism(SPUR.format(eta=eta, ML=ML)))
    rho = rj * rk / (rj + rk)
    w_pinion = 10.0
    qd_drum = np.array([[w_pinion * rj / rk]])      # the drum turns +z (lifting): the pinion -z
    lift = solve(an, [[0.0]], qd_drum, [[0.0]])
    lower = solve(an, [[0.0]], -qd_drum, [[0.0]])
    T_lift = abs(ML) * (rj + c * rho) / (rk - c * rho)
    T_lower = abs(ML) * (rj - c * rho) / (rk + c * rho)
    assert lift.motor_speed[0, 0] == pytest.approx(-w_pinion, rel=1e-12)
    assert lift.motor[0, 0] == pytest.approx(-T_lift, rel=1e-12)     # about -z, with the motion
    assert lower.motor[0, 0] == pytest.approx(-T_lower, rel=1e-12)   # about -z, against the motion
    ideal = abs(ML) * rj / rk
    assert T_lower < ideal < T_lift
    # the measured ratio: output / input power when lifting (0.9707 for eta = 0.97)
    ratio = ideal / T_lift
    assert ratio == pytest.approx((rk - c * rho) * rj / ((rj + c * rho) * rk), rel=1e-12)
    if eta == 0.97:
        assert round(ratio, 4) == 0.9707
    # loss reported = c |t| v_p, and = input - output power
    t = lift.gear_t[0, 0]
    assert lift.gear_loss[0, 0] == pytest.approx(c * abs(t) * w_pinion * rj, rel=1e-12)
    assert lift.gear_loss[0, 0] == pytest.approx((T_lift - ideal) * w_pinion, rel=1e-12)
    assert lower.gear_loss[0, 0] == pytest.approx((ideal - T_lower) * w_pinion, rel=1e-12)


RACK = """
name: rack_hand
gravity: [0, 0, 0]
base: frame
end_effector: carriage
links:
  - {{name: frame}}
  - {{name: pinion, mass: 0.2, inertia: [1.0e-4, 1.0e-4, 1.0e-4]}}
  - {{name: carriage, mass: 3.0, inertia: [0.01, 0.01, 0.01]}}
joints:
  - {{name: JP, parent: frame, child: pinion, origin: {{xyz: [0, 0, 0]}}, axis: [0, 0, 1]}}
  - {{name: JX, parent: frame, child: carriage, type: prismatic, origin: {{xyz: [0, -0.02, 0]}}, axis: [1, 0, 0],
      friction: {{coulomb: {Fc}, viscous: {Fv}}}}}
gears:
  - {{name: rack, kind: rack, links: [pinion, carriage], mesh_point: [0, -0.02, 0], efficiency: {eta}}}
motors:
  - {{name: m, link: pinion}}
loads:
  - {{name: push, link: carriage, frame: base, force: [{F}, 0, 0]}}
"""


def test_rack_axis_with_carriage_friction():
    """Pinion r = 20 mm drives a carriage against a load F at constant speed v, with Coulomb
    + viscous carriage friction and mesh efficiency eta: the rack needs a drive force
    |F| + F_c + F_v v, and the pinion torque r (1 + c) times that (the couple c |t| r on the
    pinion); the measured power ratio is 1 / (1 + c); the joint reports its friction and loss."""
    r, Fc, Fv, eta, F, v = 0.02, 12.0, 30.0, 0.9, -50.0, 0.25
    c = 1 - eta
    an = analyse(parse_mechanism(RACK.format(Fc=Fc, Fv=Fv, eta=eta, F=F)))
    res = solve(an, [[0.0]], [[v]], [[0.0]])
    drive = abs(F) + Fc + Fv * v
    assert res.motor_speed[0, 0] == pytest.approx(v / r, rel=1e-12)
    assert res.motor[0, 0] == pytest.approx(drive * r * (1 + c), rel=1e-12)
    jx = [j.name for j in an.mech.joints].index("JX")
    assert res.joint_friction[0, jx] == pytest.approx(-(Fc + Fv * v), rel=1e-12)
    assert res.joint_loss[0, jx] == pytest.approx(Fc * v + Fv * v * v, rel=1e-12)
    assert res.joint[0, jx, 2] == 0.0                      # friction is not in fz
    assert drive * v / (res.motor[0, 0] * v / r) == pytest.approx(1 / (1 + c), rel=1e-12)
    back = solve(an, [[0.0]], [[-v]], [[0.0]])            # reversed: friction reverses
    assert back.motor[0, 0] == pytest.approx((abs(F) - Fc - Fv * v) * r * (1 - c), rel=1e-12)


PLANETARY = """
name: planetary_hand
gravity: [0, 0, 0]
base: housing
end_effector: carrier
links:
  - {{name: housing}}
  - {{name: sun, mass: 0.1, inertia: [1.0e-5, 1.0e-5, 1.0e-5]}}
  - {{name: carrier, mass: 0.5, inertia: [1.0e-3, 1.0e-3, 1.0e-3]}}
  - {{name: planet, mass: 0.05, inertia: [1.0e-6, 1.0e-6, 1.0e-6]}}
joints:
  - {{name: JS, parent: housing, child: sun, origin: {{xyz: [0, 0, 0]}}, axis: [0, 0, 1]}}
  - {{name: JC, parent: housing, child: carrier, origin: {{xyz: [0, 0, 0]}}, axis: [0, 0, 1]}}
  - {{name: JP, parent: carrier, child: planet, origin: {{xyz: [{a}, 0, 0]}}, axis: [0, 0, 1], planets: 3}}
gears:
  - {{name: sp, links: [sun, planet], teeth: [12, 18], mesh_point: [{rs}, 0, 0], efficiency: {eta}}}
  - {{name: pr, links: [planet, housing], kind: internal, teeth: [18, 48], mesh_point: [{rr}, 0, 0], efficiency: {eta}}}
motors:
  - {{name: m, link: sun}}
loads:
  - {{name: out, link: carrier, frame: base, moment: [0, 0, {Tc}]}}
"""


def test_three_planet_planetary_efficiency_by_hand():
    """Sun input, ring fixed, carrier output against a load moment, constant speed, no
    gravity, equal mesh efficiencies.  By hand (each planet alike, tangential tooth forces F1
    from the sun and F2 from the ring, both pushing the planet the same way):
      carrier:  3 a (F1 + F2) = T_out;
      planet about its pin: r_p (F1 - F2) = C1 + C2 (both couples resist the planet's
        rotation relative to the carrier when the sun drives), C1 = c F1 rho1,
        C2 = c F2 rho2, rho1 = r_s r_p / (r_s + r_p), rho2 = r_p r_r / (r_r - r_p);
      sun: T_in = 3 (F1 r_s + C1).
    Efficiency T_out w_c / (T_in w_s), w_c / w_s = r_s / (r_s + r_r)."""
    rs, rp, eta, Tout = 0.012, 0.018, 0.98, 3.0
    rr, a, c = rs + 2 * rp, rs + rp, 1 - eta
    an = analyse(parse_mechanism(PLANETARY.format(a=a, rs=rs, rr=rr, eta=eta, Tc=-Tout)))
    rho1, rho2 = rs * rp / (rs + rp), rp * rr / (rr - rp)
    # r_p (F1 - F2) = c (F1 rho1 + F2 rho2); F1 + F2 = Tout / (3 a)
    A = np.array([[rp - c * rho1, -(rp + c * rho2)], [1.0, 1.0]])
    F1, F2 = np.linalg.solve(A, [0.0, Tout / (3 * a)])
    T_in = 3 * (F1 * rs + c * F1 * rho1)
    w_c = 2.0
    res = solve(an, [[0.0]], [[w_c]], [[0.0]])
    w_s = res.motor_speed[0, 0]
    assert w_s == pytest.approx(w_c * (rs + rr) / rs, rel=1e-12)
    assert res.motor[0, 0] == pytest.approx(T_in, rel=1e-11)
    assert Tout * w_c / (res.motor[0, 0] * w_s) == pytest.approx(Tout * rs / (T_in * (rs + rr)), rel=1e-11)
    sp = [an.mech.gears[cc.gear].name for cc in an.circuits].index("sp1")
    assert abs(res.gear_t[0, sp]) == pytest.approx(F1, rel=1e-11)


def test_zero_relative_speed_gives_no_mesh_couple():
    """sign(0) = 0: at rest the mesh loses nothing and the motor holds the lossless torque."""
    an = analyse(parse_mechanism(SPUR.format(eta=0.9, ML=-4.0)))
    res = solve(an, [[0.0]], [[0.0]], [[0.0]])
    assert res.motor[0, 0] == pytest.approx(-4.0 * 0.015 / 0.06, rel=1e-12)
    assert res.gear_loss[0, 0] == 0.0


# --- input ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("extra,place,message", [
    ("efficiency: 0", "gears[0].efficiency", "mesh efficiency must be in (0, 1], got 0"),
    ("efficiency: 1.2", "gears[0].efficiency", "mesh efficiency must be in (0, 1], got 1.2"),
    ("loss_factor: 1", "gears[0].loss_factor", "mesh loss factor must be in [0, 1), got 1"),
    ("loss_factor: -0.1", "gears[0].loss_factor", "mesh loss factor must be in [0, 1), got -0.1"),
    ("{efficiency: 0.9, loss_factor: 0.1}", "gears[0].loss_factor", "give efficiency or loss_factor"),
])
def test_bad_mesh_loss_input(run_cli, tmp_path, extra, place, message):
    text = SPUR.format(eta=0.97, ML=-4.0)
    if extra.startswith("{"):
        text = text.replace("efficiency: 0.97", extra[1:-1])
    else:
        text = text.replace("efficiency: 0.97", extra)
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and f"bad.yaml:{_line(text, place.split('.')[-1])}: {place}: " in lines[0]
    assert message in lines[0]


def _line(text: str, key: str) -> int:
    return next(i for i, ln in enumerate(text.splitlines(), 1) if f"{key}:" in ln and "name: stage" in ln)


def test_bad_joint_friction_and_loss_without_geometry(run_cli, tmp_path):
    text = RACK.format(Fc=-1.0, Fv=2.0, eta=0.9, F=-50.0)
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2
    assert "joints[1].friction.coulomb: coulomb friction must be >= 0, got -1 N" in res.stderr
    ideal = textwrap.dedent("""
        name: ideal
        base: b
        end_effector: y
        links: [{name: b}, {name: x, mass: 1, inertia: [1, 1, 1]}, {name: y, mass: 1, inertia: [1, 1, 1]}]
        joints:
          - {name: J1, parent: b, child: x, origin: {xyz: [0, 0, 0]}, axis: [0, 0, 1]}
          - {name: J2, parent: b, child: y, origin: {xyz: [1, 0, 0]}, axis: [0, 0, 1]}
        gears: [{name: p, links: [x, y], ratio: -2, efficiency: 0.9}]
        motors: [{name: m, link: x}]
        """)
    path.write_text(ideal)
    res = run_cli("check", path)
    assert res.exit_code == 2 and "gears[0].efficiency: a mesh loss needs the tooth geometry" in res.stderr


@pytest.mark.parametrize("name", ["planetary_3p.yaml", "rack_axis.yaml", "helical_reduction.yaml", "bendix_wrist.yaml"])
def test_urdf_export_keeps_losses(tmp_path, name):
    """Loss factors and joint friction survive export to URDF and reading back, and the
    solve of the read-back file equals the original's."""
    from gearcli.report.urdf_writer import export_urdf
    mech = with_losses(_load(name), c=0.025, coulomb=0.07, viscous=0.003)
    path = tmp_path / "lossy.urdf"
    export_urdf(mech, path)
    back = load_mechanism(path)
    assert [g.loss_factor for g in back.gears] == [g.loss_factor for g in mech.gears]
    assert [j.friction for j in back.joints] == [j.friction for j in mech.joints]
    a0, a1 = analyse(mech), analyse(back)
    q, qd, qdd = random_motion(a0.dof, n=10)
    r0, r1 = solve(a0, q, qd, qdd), solve(a1, q, qd, qdd)
    assert np.max(np.abs(r0.motor - r1.motor)) <= 1e-12 * (1 + np.max(np.abs(r0.motor)))
    assert np.max(np.abs(r0.gear_loss - r1.gear_loss)) <= 1e-12 * (1 + np.max(np.abs(r0.gear_loss)))


def test_urdf_bad_loss_input(run_cli, tmp_path):
    from gearcli.report.urdf_writer import export_urdf
    mech = with_losses(_load("rack_axis.yaml"))
    good = tmp_path / "lossy.urdf"
    export_urdf(mech, good)
    text = good.read_text()
    for old, new, message in [('loss_factor="0.03"', 'efficiency="1.5"', "mesh efficiency must be in (0, 1], got 1.5"),
                              ('loss_factor="0.03"', 'loss_factor="0.03" efficiency="0.9"', "give efficiency or loss_factor"),
                              ('coulomb="0.05"', 'coulomb="-2"', "coulomb friction must be >= 0, got -2 N*m"),
                              ('viscous="0.002"', 'viscous="0.002" stiction="1"', "unknown attribute 'stiction'")]:
        bad = tmp_path / "bad.urdf"
        bad.write_text(text.replace(old, new, 1))
        res = run_cli("check", bad)
        assert res.exit_code == 2, new
        lines = res.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"{bad}:") and message in lines[0], lines



@pytest.mark.parametrize("joint, element, message", [
    ('<joint name="elbow" type="revolute">',
     '<gearcli:friction coulomb="0.05"/><gearcli:friction coulomb="0.5" viscous="0.01"/>',
     "joint 'elbow': a second gearcli:friction element: give a joint's coulomb and viscous friction in one"),
    ('<joint name="tool_mount" type="fixed">', '<gearcli:friction coulomb="0.5"/>',
     "joint 'tool_mount': gearcli:friction on a fixed joint (its links are merged into one body: nothing turns there)"),
])
def test_urdf_friction_element_read_once_on_a_moving_joint(run_cli, mech_dir, tmp_path, joint, element, message):
    """Two gearcli:friction elements in one joint: the last one was taken, silently; one in a
    fixed joint was dropped, silently.  Each is a located error."""
    text = (mech_dir / "geared_arm.urdf").read_text()
    assert text.count(joint) == 1
    text = text.replace(joint, f"{joint}\n    {element}")
    bad = tmp_path / "arm.urdf"
    bad.write_text(text)
    line = next(i for i, ln in enumerate(text.splitlines(), 1) if element in ln)
    res = run_cli("check", bad)
    assert res.exit_code == 2 and res.stdout == ""
    assert res.stderr == f"{bad}:{line}: {message}\n"


def test_urdf_numbers_with_digit_separators_are_refused(run_cli, mech_dir, tmp_path):
    """Python's float() reads "0_002" as 2: a URDF's coulomb="0_002" gave 2 N*m of friction,
    bore="0_01" a 1 m bore and <mass value="0_15"> 15 kg, silently.  They are refused like
    any other malformed number (file:line, exit 2); ordinary forms (+2.e-3, 1E-2) still read."""
    good = tmp_path / "servo.urdf"
    assert run_cli("export", mech_dir / "servo_joint_rated.yaml", "-o", good).exit_code == 0
    text = good.read_text()
    for old, new, message in [('coulomb="0.002"', 'coulomb="0_002"', 'coulomb="0_002" is not a finite number'),
                              ('bore="0.01"', 'bore="0_01"', "bore must be a finite number, got '0_01'"),
                              ('<mass value="0.15"/>', '<mass value="0_15"/>', 'mass "0_15" is not a finite number')]:
        assert old in text
        bad = tmp_path / "bad.urdf"
        bad.write_text(text.replace(old, new, 1))
        line = next(i for i, ln in enumerate(bad.read_text().splitlines(), 1) if new in ln)
        res = run_cli("check", bad)
        assert res.exit_code == 2 and res.stdout == "", new
        lines = res.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"{bad}:{line}: ") and message in lines[0], lines
    ok = tmp_path / "ok.urdf"
    ok.write_text(text.replace('coulomb="0.002"', 'coulomb="+2.e-3"', 1).replace('bore="0.01"', 'bore="1E-2"', 1))
    a, b = load_mechanism(good), load_mechanism(ok)
    assert [(j.friction, j.bearings) for j in a.joints] == [(j.friction, j.bearings) for j in b.joints]


SHAFT = """
name: shaft_hand
gravity: [0, 0, 0]
base: base
end_effector: gear
links:
  - {{name: base}}
  - {{name: pinion, mass: 0.1, inertia: [1.0e-5, 1.0e-5, 1.0e-5]}}
  - {{name: gear, mass: 1.0, inertia: [1.0e-3, 1.0e-3, 1.0e-3]}}
joints:
  - {{name: JP, parent: base, child: pinion, origin: {{xyz: [0, 0, 0]}}, axis: [0, 0, 1]}}
  - name: JG
    parent: base
    child: gear
    origin: {{xyz: [0.075, 0, 0]}}
    axis: [0, 0, 1]
    bearings:
      - {{name: near, position: {z1}, friction_coefficient: {mu}, bore: {d}, locating: true}}
      - {{name: far, position: {z2}, friction_coefficient: {mu}, bore: {d}}}
gears:
  - {{name: stage, links: [pinion, gear], teeth: [15, 60], mesh_point: [0.015, 0, 0]}}
motors:
  - {{name: m, link: pinion}}
loads:
  - {{name: out, link: gear, frame: base, moment: [0, 0, {ML}]}}
"""


_SHAFT_BEARINGS = """    bearings:
      - {{name: near, position: {z1}, friction_coefficient: {mu}, bore: {d}, locating: true}}
      - {{name: far, position: {z2}, friction_coefficient: {mu}, bore: {d}}}
"""
_JP = "  - {{name: JP, parent: base, child: pinion, origin: {{xyz: [0, 0, 0]}}, axis: [0, 0, 1]}}\n"
assert SHAFT.count(_SHAFT_BEARINGS) == 1 and SHAFT.count(_JP) == 1
MOTOR_SHAFT = (SHAFT.replace("name: shaft_hand", "name: motor_shaft_hand").replace(_SHAFT_BEARINGS, "")
               .replace(_JP, "  - name: JP\n    parent: base\n    child: pinion\n    origin: {{xyz: [0, 0, 0]}}\n"
                             "    axis: [0, 0, 1]\n" + _SHAFT_BEARINGS))
"""SHAFT with its two bearings on the motor's pinion shaft JP instead of the gear's JG."""


def test_bearing_friction_on_the_motor_shaft_by_hand():
    """The overhung shaft's bearings moved to the motor's pinion shaft: the pinion's own
    balance about its axis holds the motor torque, so the friction couple changes only that
    torque, never the tooth force |t| = |M_L| / r_k nor the bearing loads it causes.  The
    lever rule on |g| = |t| / cos(phi) then gives the moment once, Mb = 1/2 mu d |g| (z2 +
    z1) / (z2 - z1), and |motor| = |t| r_j + Mb.  The fixed point meets it in its second
    iteration (the first only finds it); the kernel knows when the code is generated that
    the loads do not depend on the moment and takes it in one."""
    z1, z2, mu, d, ML, rj, rk = 0.02, 0.06, 0.05, 0.03, -4.0, 0.015, 0.06
    an = analyse(parse_mechanism(MOTOR_SHAFT.format(z1=z1, z2=z2, mu=mu, d=d, ML=ML)))
    t = abs(ML) / rk
    Mb = 0.5 * mu * d * t / np.cos(np.deg2rad(20)) * (z2 + z1) / (z2 - z1)
    for backend, iterations in (("numpy", 2), ("llvm", 1)):
        res = solve(an, [[0.0]], [[2.0]], [[0.0]], backend=backend)
        assert abs(res.gear_t[0, 0]) == pytest.approx(t, rel=1e-12)
        assert abs(res.motor[0, 0]) == pytest.approx(t * rj + Mb, rel=1e-12)
        assert abs(res.joint_friction[0, 0]) == pytest.approx(Mb, rel=1e-12)
        assert res.joint_friction[0, 0] * res.motor_speed[0, 0] < 0.0        # against the pinion's rate
        assert res.joint_loss[0, 0] == pytest.approx(Mb * abs(res.motor_speed[0, 0]), rel=1e-12)
        assert res.bearing_iterations[0] == iterations, backend


def test_overhung_shaft_bearing_friction_by_hand():
    """A gear overhung on a shaft with two bearings at z1, z2 beyond the mesh plane (z = 0),
    driven at constant speed against a load moment M_L, no gravity.  The tooth force
    |g| = |t| / cos(phi) splits by the lever rule into R1 = |g| z2 / (z2 - z1) and
    R2 = -|g| z1 / (z2 - z1), so the friction moment 1/2 mu d (|R1| + |R2|) =
    1/2 mu d |t| k / cos(phi), k = (z2 + z1) / (z2 - z1), grows with t itself:
    |t| r_k = M_L + 1/2 mu d k |t| / cos(phi), i.e. |t| = M_L / (r_k - mu d k / (2 cos phi))."""
    z1, z2, mu, d, ML, rj, rk = 0.02, 0.06, 0.05, 0.03, -4.0, 0.015, 0.06
    an = analyse(parse_mechanism(SHAFT.format(z1=z1, z2=z2, mu=mu, d=d, ML=ML)))
    k = (z2 + z1) / (z2 - z1)
    t = abs(ML) / (rk - mu * d * k / (2 * np.cos(np.deg2rad(20))))
    Mb = 0.5 * mu * d * k * t / np.cos(np.deg2rad(20))
    jg = 1
    for backend, fewest, most in (("numpy", 3, 12), ("llvm", 2, 4)):
        res = solve(an, [[0.0]], [[2.0]], [[0.0]], backend=backend)   # the gear turns +z against -z: lifting
        assert abs(res.gear_t[0, 0]) == pytest.approx(t, rel=1e-11)
        assert abs(res.motor[0, 0]) == pytest.approx(t * rj, rel=1e-11)
        assert res.joint_friction[0, jg] == pytest.approx(-Mb, rel=1e-11)
        assert res.joint_loss[0, jg] == pytest.approx(Mb * 2.0, rel=1e-11)
        assert res.joint[0, jg, 5] == 0.0
        # the fixed point contracts by ~ mu d k / (2 cos phi r_k) = 0.027 an iteration; Newton's
        # levels (the compiled path) by ~ the square
        assert fewest <= res.bearing_iterations[0] <= most, backend
    rest = solve(an, [[0.0]], [[0.0]], [[0.0]])          # at rest: no friction moment
    assert abs(rest.gear_t[0, 0]) == pytest.approx(abs(ML) / rk, rel=1e-12)
    assert rest.bearing_iterations[0] == 1


@pytest.mark.parametrize("mu,d", [(0.3, 0.06), (0.5, 0.08)])
def test_large_bearing_friction_converges_on_both_paths(mu, d):
    """The overhung shaft with friction that is a third and then 70 % of the load it changes
    (contraction mu d k / (2 cos phi r_k) = 0.32 and 0.71 an iteration): the numpy fixed point
    (~25 and ~80 iterations) and the kernel's Newton levels both reach the closed form; with
    the old limit of 50 iterations the numpy path raised at 0.71 where the kernel converged."""
    z1, z2, ML, rk = 0.02, 0.06, -4.0, 0.06
    an = analyse(parse_mechanism(SHAFT.format(z1=z1, z2=z2, mu=mu, d=d, ML=ML)))
    k = (z2 + z1) / (z2 - z1)
    t = abs(ML) / (rk - mu * d * k / (2 * np.cos(np.deg2rad(20))))
    n = 300
    for backend in ("numpy", "llvm"):
        res = solve(an, np.zeros((n, 1)), np.full((n, 1), 2.0), np.zeros((n, 1)), backend=backend)
        assert np.allclose(np.abs(res.gear_t[:, 0]), t, rtol=1e-11, atol=0.0), backend
        assert res.bearing_iterations.max() <= (100 if backend == "numpy" else 4)


def test_gear_in_the_plane_of_its_bearing():
    """The overhung shaft with its near bearing in the mesh plane (z1 = 0): it takes the whole
    tooth force, the far bearing nothing (R2 = -|g| z1 / (z2 - z1) = 0 at every moment), k = 1
    in the closed form.  Both paths reach it; the kernel's Newton levels keep the near
    bearing's Jacobian and their proof (the unloaded bearing's term is 0: it bends nothing),
    so they stop in two levels, not in the ~16 of the fixed point they fell back to while a
    zero load zeroed the joint's Jacobian."""
    z1, z2, mu, d, ML, rk = 0.0, 0.06, 0.3, 0.06, -4.0, 0.06
    an = analyse(parse_mechanism(SHAFT.format(z1=z1, z2=z2, mu=mu, d=d, ML=ML)))
    t = abs(ML) / (rk - mu * d / (2 * np.cos(np.deg2rad(20))))
    for backend, most in (("numpy", 30), ("llvm", 3)):
        res = solve(an, np.zeros((50, 1)), np.full((50, 1), 2.0), np.zeros((50, 1)), backend=backend)
        assert np.allclose(np.abs(res.gear_t[:, 0]), t, rtol=1e-11, atol=0.0), backend
        assert np.allclose(res.joint_friction[:, 1], -0.5 * mu * d * t / np.cos(np.deg2rad(20)), rtol=1e-11, atol=0.0)
        assert res.bearing_iterations.max() <= most, backend


@pytest.mark.parametrize("old,new,place,message", [
    ("friction_coefficient: 0.05, bore: 0.03, locating: true", "friction_coefficient: 0.05, locating: true",
     "joints[1].bearings[0].friction_coefficient", "bearing friction needs both friction_coefficient and bore"),
    ("friction_coefficient: 0.05, bore: 0.03, locating: true", "bore: 0.03, locating: true",
     "joints[1].bearings[0].bore", "bearing friction needs both friction_coefficient and bore"),
    ("friction_coefficient: 0.05, bore: 0.03, locating: true", "friction_coefficient: -0.1, bore: 0.03, locating: true",
     "joints[1].bearings[0].friction_coefficient", "bearing friction coefficient must be in [0, 1), got -0.1"),
    ("friction_coefficient: 0.05, bore: 0.03, locating: true", "friction_coefficient: 0.05, bore: 0, locating: true",
     "joints[1].bearings[0].bore", "bore must be positive, got 0"),
    ("friction_coefficient: 0.05, bore: 0.03, locating: true", "locating: true",
     "joints[1].bearings[0]", "a bearing needs a rating (C, C0, type) or friction"),
    ("friction_coefficient: 0.05, bore: 0.03, locating: true", "friction_coefficient: 0.05, bore: 0.03, C: 1000, locating: true",
     "joints[1].bearings[0].C", "a rated bearing needs C, C0 and type: C0, type missing"),
])
def test_bad_bearing_friction_input(run_cli, tmp_path, old, new, place, message):
    text = SHAFT.format(z1=0.02, z2=0.06, mu=0.05, d=0.03, ML=-4.0).replace(old, new)
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and f": {place}: " in lines[0] and message in lines[0], lines
    assert lines[0].startswith(f"{path}:{_line_of(text, new)}:")


def test_three_bearings_are_refused_in_gearclis_words(run_cli, tmp_path):
    """A third bearing was refused in jsonschema's words, "[{'name': 'near', ...… is too long"."""
    text = SHAFT.format(z1=0.02, z2=0.06, mu=0.05, d=0.03, ML=-4.0)
    far = next(ln for ln in text.splitlines() if "{name: far" in ln)
    text = text.replace(far, far + "\n" + far.replace("far", "third"))
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2 and res.stdout == ""
    assert res.stderr == f"{path}:{_line_of(text, 'bearings:')}: joints[1].bearings: a joint has one or two bearings, got 3\n"


def _line_of(text: str, fragment: str) -> int:
    return next(i for i, ln in enumerate(text.splitlines(), 1) if fragment in ln)


def test_bearing_friction_on_prismatic_joint_refused(run_cli, tmp_path):
    text = RACK.format(Fc=1.0, Fv=2.0, eta=0.9, F=-50.0).replace(
        "friction: {coulomb: 1.0, viscous: 2.0}}", "bearings: [{name: b, position: 0, friction_coefficient: 0.1, bore: 0.01}]}")
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2 and "joints[1].bearings: " in res.stderr and "prismatic" in res.stderr


def _verify_case(tmp_path, mech_text: str, limit: float) -> tuple[int, dict]:
    """verify --json of one case: the rack axis pushed back and forth, its motor's peak torque
    held to ``limit``; (exit status, the motor check's JSON record)."""
    import json
    (tmp_path / "m.yaml").write_text(mech_text)
    t = np.linspace(0.0, 2.0, 201)
    x = 0.05 * np.sin(np.pi * t)
    (tmp_path / "traj.csv").write_text("t,q:JX\n" + "".join(f"{a:.17g},{b:.17g}\n" for a, b in zip(t, x)))
    (tmp_path / "design.yaml").write_text(textwrap.dedent(f"""
        name: lossy_rack
        cases:
          - name: push
            mechanism: m.yaml
            trajectories: [traj.csv]
            limits:
              - {{column: "motor:m", max_abs: {limit}}}
        """))
    from gearcli.cli import app
    from typer.testing import CliRunner
    res = CliRunner().invoke(app, ["verify", str(tmp_path / "design.yaml"), "--json", str(tmp_path / "r.json")])
    report = json.loads((tmp_path / "r.json").read_text())
    return res.exit_code, next(c for c in report["checks"] if "motor:m" in c["component"] + c["quantity"])


def test_verify_uses_the_lossy_motor_torques(tmp_path):
    """verify's motor figure is the lossy solve's peak |torque|, and a limit between the
    lossless and the lossy peak passes without the losses and fails with them."""
    lossy = RACK.format(Fc=12.0, Fv=30.0, eta=0.9, F=-50.0)
    lossless = RACK.format(Fc=0.0, Fv=0.0, eta=1.0, F=-50.0)
    an_lossy, an_free = analyse(parse_mechanism(lossy)), analyse(parse_mechanism(lossless))
    t = np.linspace(0.0, 2.0, 201)
    code_free, free = _verify_case(tmp_path, lossless, 1.2)
    code_lossy, lossy_check = _verify_case(tmp_path, lossy, 1.2)
    assert code_free == 0 and code_lossy == 1
    assert free["value"] < 1.2 < lossy_check["value"]
    assert free["passed"] and not lossy_check["passed"]
    # the figure verify prints is the lossy solve's peak motor torque over the same motion
    x = 0.05 * np.sin(np.pi * t)
    v, a = 0.05 * np.pi * np.cos(np.pi * t), -0.05 * np.pi ** 2 * np.sin(np.pi * t)
    peak = np.max(np.abs(solve(an_lossy, x[:, None], v[:, None], a[:, None]).motor))
    assert lossy_check["value"] == pytest.approx(peak, rel=1e-3)      # spline vs exact rates
    assert an_lossy.mech.has_losses and not an_free.mech.has_losses


def test_bundled_design_verdict_changes_with_losses(run_cli, tmp_path):
    """designs/servo_joint_losses.yaml: the rated servo joint with its losses fails its motor's
    peak torque rating (named in the JUnit XML); the same case with every loss key removed
    from the mechanism passes."""
    import re
    root = Path(__file__).resolve().parents[1]
    res = run_cli("verify", root / "designs" / "servo_joint_losses.yaml", "--junit", tmp_path / "lossy.xml")
    assert res.exit_code == 1
    junit = (tmp_path / "lossy.xml").read_text()
    assert re.search(r'<testcase[^>]*name="motor motor: peak torque"[^>]*>\s*<failure', junit)
    assert junit.count("<failure") == 1
    text = (root / "mechanisms" / "servo_joint_rated.yaml").read_text()
    text = re.sub(r"\n\s*efficiency: [0-9.]+", "", text)
    text = re.sub(r"\n\s*friction: \{[^}]*\}[^\n]*", "", text)
    text = re.sub(r",\s*friction_coefficient: [0-9.]+, bore: [0-9.]+", "", text)
    text = text.replace("- {name: needle, position: 0.0}", "- {name: needle, position: 0.0, C: 2000, C0: 2000, type: roller}")
    body = text.split("name: servo_joint_rated", 1)[1]
    assert not re.search(r"friction\w*:|efficiency:", body)
    (tmp_path / "mechanisms").mkdir()
    (tmp_path / "designs").mkdir()
    (tmp_path / "mechanisms" / "servo_joint_rated.yaml").write_text(text)
    (tmp_path / "mechanisms" / "servo_joint_duty.csv").write_bytes((root / "mechanisms" / "servo_joint_duty.csv").read_bytes())
    (tmp_path / "designs" / "d.yaml").write_text((root / "designs" / "servo_joint_losses.yaml").read_text())
    res = run_cli("verify", tmp_path / "designs" / "d.yaml")
    assert res.exit_code == 0, res.stdout[-2000:]


def test_auto_solves_losses_compiled():
    """A lossy mechanism: "auto" takes the generated llvm kernel for a large call (and for
    any call once it is compiled), equal to the numpy reference (to 1e-12:
    tests/test_llvm_losses.py)."""
    from gearcli.dynamics import backends
    from gearcli.dynamics.solve import solver_for
    an = analyse(load_mechanism(MECH / "servo_joint_rated.yaml"))
    q, qd, qdd = random_motion(an.dof, n=5)
    assert solver_for(an).choice() == backends.Choice("llvm")
    fast, ref = solve(an, q, qd, qdd, backend="llvm"), solve(an, q, qd, qdd, backend="numpy")
    assert solve(an, q, qd, qdd).backend == "llvm" and ref.backend == "numpy"
    assert np.allclose(fast.motor, ref.motor, rtol=1e-12, atol=1e-12 * np.abs(ref.motor).max())


@pytest.mark.parametrize("friction, message", [
    ("{coulomb: 0.5, static: 0.3}", "joints[0].friction.static: static friction must be >= the Coulomb friction 0.5 N*m, got 0.3 N*m"),
    ("{static: -1}", "joints[0].friction.static: static friction must be >= the Coulomb friction 0 N*m, got -1 N*m"),
])
def test_static_friction_below_coulomb_is_refused(run_cli, tmp_path, friction, message):
    text = (MECH / "paper_2dof.yaml").read_text()
    dh = "    dh: {theta_deg: 0, d: 0.0, a: 0.4, alpha_deg: 0}\n"
    (tmp_path / "m.yaml").write_text(text.replace(dh, dh + f"    friction: {friction}\n", 1))
    r = run_cli("check", tmp_path / "m.yaml")
    assert r.exit_code == 2 and message in r.stderr and len(r.stderr.splitlines()) == 1


def test_static_friction_is_described_and_survives_the_urdf_round_trip(run_cli, tmp_path):
    from gearcli import load_mechanism
    text = (MECH / "paper_2dof.yaml").read_text()
    dh = "    dh: {theta_deg: 0, d: 0.0, a: 0.4, alpha_deg: 0}\n"
    (tmp_path / "m.yaml").write_text(text.replace(dh, dh + "    friction: {coulomb: 0.5, static: 0.75}\n", 1))
    r = run_cli("check", tmp_path / "m.yaml")
    assert r.exit_code == 0
    assert "friction of joint 'J1': Coulomb 0.5 N*m, viscous 0 N*m*s/rad, static 0.75 N*m" in r.stdout.splitlines()
    assert run_cli("export", tmp_path / "m.yaml", "-o", tmp_path / "m.urdf").exit_code == 0
    assert 'static="0.75"' in (tmp_path / "m.urdf").read_text()
    back = load_mechanism(tmp_path / "m.urdf")
    fr = next(j.friction for j in back.joints if j.name == "J1")
    assert (fr.coulomb, fr.static, fr.holding) == (0.5, 0.75, 0.75)
    plain = load_mechanism(MECH / "paper_2dof.yaml")
    assert all(j.friction is None for j in plain.joints)
