"""Generated friction terms of one sample (:mod:`..losses`, :mod:`.loss_program`), for :mod:`.kernel`:
what the sample's rates give before any block solve, and the loss outputs.  The laws are the
shared functions of :mod:`..loss_terms` (the numpy path calls the same ones); what is here is
where the generator applies them.

* :func:`mesh_rates`: each lossy mesh's rate theta'_{j,c} = r . q'_ind from the
  independent joint rates (:func:`..losses.relative_rate`) and s_v = sign of it (0 at rest,
  exactly, in any frames), which the lossy blocks read (:mod:`.losses`);
* :func:`reducer_terms`: each lossy reducer's input rate, power-flow coefficients and its
  no-load torque (a known load);
* :func:`joint_friction`: each friction joint's own friction -F_c sign(q'_J) - F_v q'_J
  from the sample's joint rate (the law of :func:`..loss_terms.joint_friction`; the bearing
  friction is :mod:`.bearings`'); rhs[L] -= that generalised force Q times the joint's unit
  wrench: about the axis (revolute) or along it through the joint origin (prismatic), on
  the child, reversed on the parent;
* :func:`write_losses` (and :func:`joint_friction`, for the joints without bearing
  friction): the loss outputs, as :func:`..losses.fill_losses`: ``gear_loss`` c_p |t_p|
  |theta'_{j,c}| r_j, ``joint_friction`` the own friction less the converged bearing
  friction s_J Mb_J of :mod:`.bearings`, ``joint_loss`` -friction * q'_J.
"""
from __future__ import annotations

from .. import loss_terms as laws  # by attribute when emitting: a monkeypatched law (tests/) reaches both paths
from ..wrenches import unit_joint_wrench
from .build import FLAGS, Emitter
from .links import Sample, floats


def mesh_rates(e: Emitter, s: Sample, lp) -> tuple[list, list]:
    """(theta'_{j,c}, s_v) of every lossy mesh (doubles)."""
    rates = [e.const(e.dot(floats(lp.rate_flt[k]), s.qdi)) for k in range(len(lp.rate_meshes))]
    return rates, [e.sign(r) for r in rates]


def worm_signs(e: Emitter, s: Sample, worms) -> list:
    """s_v of each lossy worm pair: the sign of its worm's rate relative to the carrier
    (:class:`.loss_program.WormLosses`; exactly 0 at rest)."""
    return [e.sign(e.const(e.dot(floats(worms.rate_flt[k]), s.qdi))) for k in range(len(worms.circuits))]


def reducer_terms(e: Emitter, s: Sample, red) -> list:
    """Per lossy power-flow element (:class:`.loss_program.ReducerLosses`): (s_w, A, B, its axis
    in world axes, w, T0(|a|), |a|) for the world-frame block columns
    (:func:`.losses.world_columns`) and the outputs (:func:`write_losses`), w = its drive-rate
    row . q'_ind (exactly 0 at rest); rhs -= a reducer's no-load torque -T0(|a|) s_w coef z on
    its sides, a known load (:func:`..losses.subtract_reducer_drag`)."""
    out = []
    for k in range(len(red.circuits)):
        w = e.const(e.dot(floats(red.rate_flt[k]), s.qdi))
        sw, speed = e.sign(w), e.const(e.mul(red.scale[k], e.call("fabs", w)))
        z = e.mv(s.R[int(red.carriers[k])], floats(red.axis[k]))
        fwd, bwd, t0 = red.tables[k]
        mode = red.mode[k] if red.mode else 0
        A, B = (e.const(v) for v in laws.power_flow_coefficients(e, speed, fwd, bwd, mode))
        T0 = 0.0 if t0 is None else e.const(e.interp(speed, t0))
        out.append((sw, A, B, z, w, T0, speed))
        if t0 is None:
            continue
        tq = e.const(laws.no_load_torque(e, T0, sw))
        for L, coef in red.sides[k]:
            if L >= 0:
                s.rhs[L] = s.rhs[L][:3] + tuple(e.sub(s.rhs[L][3 + h], e.mul(e.mul(coef, tq), z[h])) for h in range(3))
    return out


def joint_friction(e: Emitter, s: Sample, lp, rows: dict) -> dict:
    """rhs[L] -= Q * the unit wrench of each friction joint on L; returns {joint: its own
    friction Q} (the joints with Coulomb or viscous friction).  Writes the ``joint_friction``
    and ``joint_loss`` of every joint without bearing friction now (:func:`write_losses` the
    others'): kept to the sample's end, each would hold a register through every block."""
    own, late = {}, set(int(v) for v in lp.bearing_joints)
    for k in range(lp.joints.shape[0]):
        ji, child, parent, prismatic = (int(v) for v in lp.joints[k, :4])
        f = floats(lp.joint_flt[k])
        if not (f[6] or f[7]):         # bearing friction only (.bearings)
            continue
        Q = own[ji] = e.const(laws.joint_friction(e, f[6], f[7], e.const(s.qd[ji])))
        if ji not in late:
            _write_joint(e, s, ji, Q, rows)
        Rc, oc = s.R[child], s.o[child]
        z = e.mv(Rc, f[:3])
        oj = e.vadd(oc, e.mv(Rc, f[3:6])) if prismatic else None
        for L, sign in ((child, 1.0), (parent, -1.0)):
            if L < 0:
                continue
            w = unit_joint_wrench(e, z, oj, s.o[L], bool(prismatic))
            s.rhs[L] = tuple(e.sub(s.rhs[L][h], e.mul(e.mul(sign, Q), w[h])) for h in range(6))
    for ji in sorted(set(range(len(s.qd))) - late - set(own)):
        _write_joint(e, s, ji, 0.0, rows)
    return own


def write_losses(e: Emitter, s: Sample, lp, gear_col, rates: list, own: dict, rows: dict) -> dict:
    """The sample's ``gear_loss`` (every circuit, 0 for an ideal pair), and the
    ``joint_friction`` and ``joint_loss`` of the joints with bearing friction (their own
    friction ``own`` less the converged s_J Mb_J; :func:`joint_friction` wrote the others').
    Returns {circuit: the torque each lossy reducer exerts on its input} (``gear_sep``,
    :func:`.outputs.write_outputs`)."""
    for k, ci in enumerate(lp.rate_meshes):
        c, rj = floats(lp.loss_flt[k])
        t = s.sol[int(gear_col[ci])]
        e.store(laws.mesh_loss(e, c, rj, t, rates[k]), rows["gear_loss"], ci)
    inputs = _reducer_outputs(e, s, lp.reducers, gear_col, rows) if lp.reducers is not None else {}
    done = set(lp.reducers.circuits) if lp.reducers is not None else set()
    for ci in set(range(len(gear_col))) - set(lp.rate_meshes) - done:
        e.store(0.0, rows["gear_loss"], ci)
    for ji in (int(v) for v in lp.bearing_joints):
        f = own.get(ji, 0.0)
        if ji in s.bearing:            # (0 - 0 = +0 at rest, as numpy's)
            f = e.b.fsub(e.const(f), s.bearing[ji], flags=FLAGS)
        _write_joint(e, s, ji, f, rows)
    return inputs


def _reducer_outputs(e: Emitter, s: Sample, red, gear_col, rows: dict) -> dict:
    """Each lossy power-flow element's ``gear_loss`` -delta u w + T0 |a| (delta = c_r - 1 with
    sigma = sign(u): u = 0 makes both terms' product 0); returns each reducer's input torque
    (1 + delta) u - T0 s_w (:func:`..loss_terms.element_loss`,
    :func:`..loss_terms.input_torque`)."""
    out = {}
    for k, ci in enumerate(red.circuits):
        if red.mode and red.mode[k]:        # a belt's loss: :func:`..losses.fill_belts`, both paths
            continue
        sw, A, B, _, w, T0, speed = s.red[k]
        u = s.sol[int(gear_col[ci])]
        delta = laws.power_flow_delta(e, A, B, e.sign(u), sw)
        e.store(laws.element_loss(e, delta, u, w, T0, speed), rows["gear_loss"], ci)
        if red.reducer[k]:
            out[ci] = e.const(laws.input_torque(e, delta, u, T0, sw))
    return out


def _write_joint(e: Emitter, s: Sample, ji: int, f, rows: dict) -> None:
    """Joint ji's ``joint_friction`` f and ``joint_loss`` -f q'_J."""
    e.store(f, rows["joint_friction"], ji)
    e.store(e.neg(e.mul(f, s.qd[ji])), rows["joint_loss"], ji)
