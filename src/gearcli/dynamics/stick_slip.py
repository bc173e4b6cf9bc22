"""Stick-slip joint friction for ``gearcli simulate``: Karnopp's switching model.

A joint J with Coulomb friction F_c (``joints[].friction.coulomb``) and static friction
F_s >= F_c (``joints[].friction.static``, default F_c) is, at any time, either

* **slipping**: its friction is -F_c sign(q'_J) (plus viscous), as in :func:`gearcli.solve`;
  at the instant it starts to slip its rate is exactly 0 and the sign is the direction d it
  starts to move in;
* **stuck**: its rate is 0 and stays 0 (q''_J = 0); its friction Q_J is whatever holds it,
  found with the accelerations (:func:`~.forward.held_dynamics`), and does no work.

The switches are integration events (located by :func:`scipy.integrate.solve_ivp` to the
floating-point resolution of t):

* a slipping joint whose rate crosses 0 sticks, if the friction that holds it is within
  +-F_s; else it goes on, turning the other way (d = -sign Q_J: where the other forces push);
* a stuck joint slips when the friction that would hold it exceeds F_s (|Q_J| = F_s), in the
  direction d = -sign Q_J.

Several joints at rest are classified together: all are held, then the one most beyond its
F_s (relative to it) is released, until every held joint's |Q_J| <= F_s,J.  With friction
elements (below) the limits are a unit's two margins, and it slips on the side beyond.

Joints geared to each other (their rows s_J parallel: s_J = a_J u) stick and slip together:
they are one unit of row u with F_c = sum |a_J| F_c,J and F_s = sum |a_J| F_s,J (how the
holding divides among them is not determined, and not needed).  A held unit whose row
depends on the other held ones' (not parallel: three joints of a two-dof differential) is
held by them and holds nothing itself.

The joints' own Coulomb friction is taken out of the mechanism the accelerations are solved
on (:attr:`StickSlip.analysis`, the twin without it) and applied as external loads of the
twin where it acts: a couple -F_c sign(q'_J) about the joint's axis on its child (a force
along it for a prismatic joint), reversed on its parent, so that a rate of exactly 0 takes
the direction it starts in and the tooth forces (and so the mesh friction) are those of
the friction where it is.  A held unit's friction enters as C^T Q on the independent
joints (its row s_J of q = S q_ind).  Viscous friction stays in the twin.

Load-dependent friction at rest
-------------------------------
Mesh friction, the losses of the drive elements (reducers, screws, belts, worms) and
bearing friction stay in the twin too; at a zero relative rate they give no couple.  Each
such element's rate is r . q'_ind (:func:`element_rows`); the row r is a unit (with the
joints and elements whose rows are parallel to it), and its elements hold it too, each up
to its Coulomb value at the load it carries, in the manner of :func:`gearcli.solve`'s own
model.  A held unit k's margins, how far it is from slipping in its + and - direction, are
the parts along its row u of

    tau_+ - A T   and   A T - tau_-       (the other held rows' parts apart),

tau_d the inverse dynamics of the twin at the held state's q, q'' on the verge of slipping
in direction d: the unit's joints' friction at -d F_s, its elements slipping (rate d TINY
along one coordinate, d PROBE |q'| along a row of several), with the tooth and bearing
loads those couples give, solved together by the solve; A T the motors' push.  Held while
both are >= 0: the unit slips exactly where the kinetic motion in direction d with zero
acceleration balances (tests/test_simulate.py, the spur stage, the pendulum and the arm on
a bearing by hand).  How the holding divides among the elements short of a verge is not
determined and not needed: it does no work, and the held accelerations do not depend on it.
A unit without elements keeps F_s + Q and F_s - Q.

A held row along one coordinate i has its rate and acceleration set exactly to 0, so its
elements stay off (sign 0) in the twin.  A held row of several coordinates keeps ~1e-16
|q'| of rounding in its rate, so its elements' couples may turn on in the twin; they act
along u and are taken up by the held Q, which the margins do not use, so the accelerations
and the switches do not depend on them.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..model.friction import JointFriction
from ..model.loads import Load
from .bearing_friction import friction_joints
from .external import load_values
from .forward import held_dynamics
from .solve import solver_for

TINY = 1e-150
"""The rate |q'_i| that turns a held coordinate's friction elements on in the probe of
:meth:`StickSlip.limits`: only its sign enters the friction; the velocity terms it adds
(~TINY times the rates) are far below rounding.  Not subnormal, not squared to one."""

PROBE = 1e-9
"""The rate along u, relative to the largest |q'| (at least 1), of a held unit whose row
involves several coordinates in the probe of :meth:`StickSlip.margins`: its held rate
keeps ~1e-16 |q'| of rounding, so TINY would not decide the sign; the velocity terms move
by ~1e-9 of theirs."""

SLACK = 1e-12
"""A held unit's margins are widened by SLACK times the state's torque scale (the largest of
|A T|, its F_s and |tau_d|): a unit at a balance (~1e-17 of rounding against a margin of 0,
e.g. an unloaded gear pair) stays held instead of slipping at once and sticking again."""


@dataclass
class Mode:
    """The joints' state between two switches: ``stuck`` (joint indices, in order) and
    ``start`` {joint: d}, the direction of a slipping joint whose rate is exactly 0."""

    stuck: tuple = ()
    start: dict = field(default_factory=dict)


class StickSlip:
    """The stick-slip units of an analysed mechanism ``an`` (joints with Coulomb or static
    friction, geared ones together) and its accelerations in a :class:`Mode` (whose
    ``stuck`` and ``start`` name units by index)."""

    def __init__(self, an):
        from .determinacy import analyse  # noqa: PLC0415

        S = np.asarray(an.S, float)
        self.an = an
        joints = [ji for ji, jt in enumerate(an.mech.joints)
                  if jt.friction is not None and jt.friction.holding > 0 and S[ji].any()]
        self.units = []          # [row u (dof,), F_c, F_s, joints]
        for ji in joints:
            fr, s = an.mech.joints[ji].friction, S[ji]
            k, a = self._unit_of(s)
            if k is None:
                self.units.append([s, fr.coulomb, fr.holding, [ji]])
            else:
                self.units[k][1] += abs(a) * fr.coulomb
                self.units[k][2] += abs(a) * fr.holding
                self.units[k][3].append(ji)
        self.analysis = an
        self.couples = []        # (load name, joint, unit, sign of a_J in the unit, child side, axis, prismatic)
        if joints:
            mech = an.mech
            twin = tuple(replace(jt, friction=JointFriction(0.0, jt.friction.viscous)) if ji in joints else jt
                         for ji, jt in enumerate(mech.joints))
            loads = list(mech.loads)
            for k, unit in enumerate(self.units):
                for ji in unit[3]:
                    jt = mech.joints[ji]
                    a = np.sign(S[ji] @ unit[0])
                    R_jc, p_jc = np.asarray(jt.R_jc, float), np.asarray(jt.p_jc, float)
                    sides = [(jt.child, R_jc[2, :], -R_jc.T @ p_jc, 1.0)]
                    if jt.parent != mech.base:
                        sides.append((jt.parent, np.asarray(jt.R_pj, float)[:, 2], np.asarray(jt.p_pj, float), -1.0))
                    for link, axis, point, side in sides:
                        name = f"stick-slip {jt.name} on {link}"
                        loads.append(Load(name, link, "link", point))
                        self.couples.append((name, ji, k, a, side, axis, jt.type == "prismatic"))
            self.analysis = analyse(replace(mech, joints=twin, loads=tuple(loads)))
        self.probe = set()       # units with friction elements (mesh, drive element, bearing) on their row
        for r in element_rows(self.analysis):
            k, _ = self._unit_of(r)
            if k is None:
                k = len(self.units)
                self.units.append([r, 0.0, 0.0, []])
            self.probe.add(k)
        self.coordinate = {}     # unit -> i, for a unit whose row is a e_i (its rate an exact 0 when held)
        for k, unit in enumerate(self.units):
            if np.count_nonzero(unit[0]) == 1:
                self.coordinate[k] = int(np.flatnonzero(unit[0])[0])

    def _unit_of(self, s: np.ndarray) -> tuple[int | None, float]:
        """(k, a) of the unit whose row u is parallel to ``s`` (s = a u), else (None, 0)."""
        for k, unit in enumerate(self.units):
            a = (unit[0] @ s) / (unit[0] @ unit[0])
            if np.allclose(a * unit[0], s, rtol=0.0, atol=1e-12 * np.abs(s).max()):
                return k, a
        return None, 0.0

    def rate(self, u: int, qd: np.ndarray):
        """Unit u's rate u . q'."""
        return qd @ self.units[u][0]

    def loads(self, mode: Mode, qd: np.ndarray) -> dict:
        """{load: (N, 6)}: each slipping joint's Coulomb friction -F_c sign(q'_J) (the unit's
        direction d at a rate of exactly 0) as a couple about (a force along) its axis on the
        child, the opposite on the parent (link frames); 0 for a held joint (C^T Q holds it)."""
        qd = np.atleast_2d(qd)
        out = {}
        for name, ji, k, a, side, axis, prismatic in self.couples:
            w = np.zeros((qd.shape[0], 6))
            if k not in mode.stuck:
                sign = np.sign(qd @ self.units[k][0])
                if k in mode.start:
                    sign = np.where(sign == 0.0, mode.start[k], sign)
                Q = -self.an.mech.joints[ji].friction.coulomb * a * sign
                w[:, :3] = 0.0
                w[:, (0 if prismatic else 3):(3 if prismatic else 6)] = side * Q[:, None] * axis
            out[name] = w
        return out

    def rows(self, held) -> tuple[np.ndarray, list]:
        """(C, held units that are its rows): the held units' rows, each kept only when it
        is independent of those before it."""
        C, kept = np.zeros((0, self.an.dof)), []
        for k in held:
            trial = np.vstack([C, self.units[k][0]])
            if np.linalg.matrix_rank(trial, tol=1e-9 * np.abs(trial).max()) > C.shape[0]:
                C, kept = trial, kept + [k]
        return C, kept

    def accelerations(self, mode: Mode, q, qd, T, backend: str) -> tuple[np.ndarray, np.ndarray]:
        """(qdd (N, dof), Q (N, len(mode.stuck))): :func:`~.forward.held_dynamics` of the
        twin with the held units' rows and the slipping units' friction (a dependent held
        unit's Q is 0)."""
        C, kept = self.rows(mode.stuck)
        qdd, Qk = held_dynamics(self.analysis, q, qd, T, C, self.loads(mode, qd), backend)
        Q = np.zeros((qdd.shape[0], len(mode.stuck)))
        for i, k in enumerate(kept):
            Q[:, mode.stuck.index(k)] = Qk[:, i]
        for k in mode.stuck:             # exactly 0 (the KKT solve leaves ~1e-17): the rate stays 0
            if k in self.coordinate:
                qdd[:, self.coordinate[k]] = 0.0
        return qdd, Q

    def margins(self, mode: Mode, q, qd, qdd, T, Q, backend: str) -> np.ndarray:
        """(N, len(mode.stuck), 2): how far each held unit is from slipping in its + and in
        its - direction (both >= 0: held), in its Q's units and widened by :data:`SLACK`:
        F_s + Q and F_s - Q for a unit without friction elements; for one with them
        (:attr:`probe`), the parts along u of tau_+ - A T and A T - tau_- (module docstring;
        the other held rows' parts apart); +inf for a unit held by the others."""
        q, qd, qdd, T, Q = (np.atleast_2d(np.asarray(v, float)) for v in (q, qd, qdd, T, Q))
        n = q.shape[0]
        out = np.empty((n, len(mode.stuck), 2))
        AT = np.einsum("nm,dm->nd", T, self.an.A)
        scale = np.abs(AT).max(axis=1, initial=0.0)
        C, kept = self.rows(mode.stuck)
        along = np.linalg.pinv(C) if any(k in self.probe for k in kept) else None   # (dof, held rows)
        for j, k in enumerate(mode.stuck):
            if k in self.probe and k not in kept:        # held by the others: holds nothing
                out[:, j, :] = np.inf
            elif k in self.probe:        # the differences' part along u_k, the other held rows apart
                tau, u = self._verges(mode, k, q, qd, qdd, backend), along[:, kept.index(k)]
                out[:, j, 0] = (tau[0] - AT) @ u
                out[:, j, 1] = (AT - tau[1]) @ u
                scale = np.maximum(scale, np.abs(tau).max(axis=(0, 2)))
            else:
                out[:, j, 0] = self.units[k][2] + Q[:, j]
                out[:, j, 1] = self.units[k][2] - Q[:, j]
                scale = np.maximum(scale, self.units[k][2])
        return out + (SLACK * scale + 1e-300)[:, None, None]

    def _verges(self, mode: Mode, k: int, q, qd, qdd, backend: str) -> np.ndarray:
        """(2, N, dof): tau_+ and tau_- of held unit k (module docstring), one solve of the
        twin over 2N samples on the verge of slipping in + and in -: its joints' couples
        -d F_s, its elements' rate d TINY (a row along one coordinate; else d PROBE |q'|
        along u, above the rounding the held rate keeps)."""
        n, u = q.shape[0], self.units[k][0]
        parts, rates = [], []
        for d in (1.0, -1.0):
            loads = self.loads(mode, qd)
            for name, ji, unit, a, side, axis, prismatic in self.couples:
                if unit == k:
                    loads[name][:, (0 if prismatic else 3):(3 if prismatic else 6)] = (
                        -side * d * a * self.an.mech.joints[ji].friction.holding * axis)
            parts.append(load_values(self.analysis.mech, n, loads))
            if k in self.coordinate:
                i = self.coordinate[k]
                rate = qd.copy()
                rate[:, i] = d * np.sign(u[i]) * TINY
            else:
                size = PROBE * np.maximum(np.abs(qd).max(axis=1), 1.0)
                rate = qd + d * size[:, None] * u / (u @ u)
            rates.append(rate)
        tau = solver_for(self.analysis).solve(
            np.concatenate([q] * 2), np.concatenate(rates), np.concatenate([qdd] * 2), backend=backend,
            check_finite=False, element_outputs=False,
            loads={key: np.concatenate([p[key] for p in parts]) for key in parts[0]}).tau
        return tau.reshape(2, n, -1)

    def classify(self, mode: Mode, at_rest: list, q, qd, T, backend: str) -> tuple[Mode, np.ndarray]:
        """The mode after the units ``at_rest`` (rate 0 now; the others keep theirs) are
        held if their friction can hold them: all are held with the stuck ones, then the one
        most beyond its F_s is released (d = -sign Q) until every held unit is within its
        F_s.  Returns the mode and the state's q' with the held units' rates exactly 0 (the
        event left ~1e-16 of them: q' less its part along the held rows)."""
        held = list(mode.stuck) + [k for k in at_rest if k not in mode.stuck]
        start = {k: d for k, d in mode.start.items() if k not in held}
        while True:
            C, _ = self.rows(held)
            if C.shape[0]:
                qd = qd - C.T @ np.linalg.solve(C @ C.T, C @ qd)
                for k in held:
                    if k in self.coordinate:
                        qd[self.coordinate[k]] = 0.0
            trial = Mode(tuple(held), start)
            if not held:
                return trial, qd
            qdd, Q = self.accelerations(trial, q[None, :], qd[None, :], T[None, :], backend)
            m = self.margins(trial, q, qd, qdd[0], T, Q[0], backend)[0]
            least = m.min(axis=1)
            over = np.where(np.isfinite(least), -least / np.maximum(m.sum(axis=1), 1e-300), -1.0)
            i = int(np.argmax(over))
            if over[i] <= 0.0:
                return trial, qd
            k = held.pop(i)
            start[k] = slip_direction(m[i])

    def events(self, mode: Mode, qd: np.ndarray, dof: int, margins) -> list:
        """The switch events of ``mode`` from state rates ``qd``: a slipping unit's rate
        crossing 0 against its direction, a stuck unit's margin reaching 0 (``margins(t,
        x)``: :meth:`margins` at that state).  Each has ``switch`` = (unit, "stick" or
        "slip")."""
        out = []
        for k, (s, _, _, _) in enumerate(self.units):
            if k in mode.stuck:
                i = mode.stuck.index(k)
                ev = (lambda t, x, i=i: float(margins(t, x)[i].min()))
                ev.direction, ev.switch = -1.0, (k, "slip")
            else:
                d = np.sign(qd @ s) or mode.start.get(k, 0.0)
                if not d:
                    continue
                ev = (lambda t, x, s=s: x[dof:2 * dof] @ s)
                ev.direction, ev.switch = -d, (k, "stick")
            ev.terminal = True
            out.append(ev)
        return out


def slip_direction(margin: np.ndarray) -> float:
    """The direction a held unit with margins (+, -) slips in: the side most beyond."""
    return 1.0 if margin[0] < margin[1] else -1.0


def element_rows(an) -> list[np.ndarray]:
    """The rate rows r (dof,) of the load-dependent friction elements, r . q'_ind their
    rate: a lossy gear pair's or drive element's relative rate
    (:attr:`~gearcli.analysis.types.Analysis.mesh_rate_rows`) and a joint with bearing
    friction (its row of S)."""
    mech = an.mech
    rows = [an.mesh_rate_rows[ci] for ci, c in enumerate(an.circuits) if mech.gears[c.gear].lossy]
    rows += [np.asarray(an.S[ji], float) for ji in friction_joints(mech)]
    return [r for r in rows if r.any()]

