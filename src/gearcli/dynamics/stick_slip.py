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
F_s is released, until every held joint's |Q_J| <= F_s,J.

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
bearing friction stay in the twin too; at a zero relative rate they give no couple.  Where
one of them turns with one independent coordinate i alone (its rate row r = a e_i, so a
rate of exactly 0 whenever q'_i is), that coordinate is a unit (with the joints whose rows
are parallel to e_i) and its elements hold it too, each up to its Coulomb value at the
current load, in the manner of :func:`gearcli.solve`'s own model.  A held unit's limits
against a push in its + and - direction are

    F_s + K_+,   F_s + K_-,    K_d = d (tau_d - tau_0)_i / u_i   (d = +-1),

tau_d the inverse dynamics of the twin at the held state's q, q'' with q'_i = d sign(u_i)
TINY: the elements of coordinate i slip in direction d at a vanishing rate (their full
Coulomb couples, with the tooth and bearing loads those couples give, solved together by
the solve), tau_0 the same at q'_i = 0 (none).  K_d is so the friction that would hold the
unit on the verge of slipping in direction d: held while -(F_s + K_+) <= Q <= F_s + K_-,
the unit slips exactly where the kinetic motion in direction d with zero acceleration
balances (tests/test_simulate.py, the spur stage and the pendulum by hand).  How the holding
divides among the elements short of that verge is not determined and not needed: it does
no work, and the held accelerations do not depend on it.  A held coordinate's rate and
acceleration are exactly 0, so its elements stay off (sign 0) in the twin.  An element
whose rate involves several coordinates holds nothing (it slips through 0).
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

SLACK = 1e-12
"""A held unit's limits are widened by SLACK times the state's torque scale (the largest of
its limits, |A T| and |tau_0|): a unit at a balance (Q ~1e-17 of rounding against limits
of 0, e.g. an unloaded gear pair) stays held instead of slipping at once and sticking again."""


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
            for unit in self.units:
                a = (unit[0] @ s) / (unit[0] @ unit[0])
                if np.allclose(a * unit[0], s, rtol=0.0, atol=1e-12 * np.abs(s).max()):
                    unit[1] += abs(a) * fr.coulomb
                    unit[2] += abs(a) * fr.holding
                    unit[3].append(ji)
                    break
            else:
                self.units.append([s, fr.coulomb, fr.holding, [ji]])
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
        self.coordinate = {}     # unit -> i, for a unit whose row is a e_i (its rate an exact 0 when held)
        for k, unit in enumerate(self.units):
            if np.count_nonzero(unit[0]) == 1:
                self.coordinate[k] = int(np.flatnonzero(unit[0])[0])
        self.probe = set()       # units whose coordinate has friction elements (mesh, drive, bearing)
        for i in element_coordinates(self.analysis):
            k = next((k for k, c in self.coordinate.items() if c == i), None)
            if k is None:
                k = len(self.units)
                self.units.append([np.eye(an.dof)[i], 0.0, 0.0, []])
                self.coordinate[k] = i
            self.probe.add(k)

    def name(self, u: int) -> str:
        """The unit's joints, e.g. "joint 'Jw'" or "joints 'Jp', 'Jw'" (its coordinate's
        name for a unit held by its friction elements alone)."""
        names = [self.an.mech.joints[ji].name for ji in self.units[u][3]]
        if not names:
            return f"coordinate '{self.an.independent_names[self.coordinate[u]]}'"
        return ("joint " if len(names) == 1 else "joints ") + ", ".join(f"'{n}'" for n in names)

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

    def limits(self, mode: Mode, q, qd, qdd, T, backend: str) -> np.ndarray:
        """(N, len(mode.stuck), 2): the most friction each held unit gives against a push in
        its + and in its - direction (held while -limit_+ <= Q <= limit_-), widened by
        :data:`SLACK`: F_s and F_s for a unit without friction elements; for one with them
        (:attr:`probe`), K_+ and K_- of the module docstring, the verge of slipping."""
        q, qd, qdd, T = (np.atleast_2d(np.asarray(v, float)) for v in (q, qd, qdd, T))
        n = q.shape[0]
        out = np.empty((n, len(mode.stuck), 2))
        for j, k in enumerate(mode.stuck):
            out[:, j, :] = self.units[k][2]
        scale = np.abs(np.einsum("nm,dm->nd", T, self.an.A)).max(axis=1, initial=0.0)
        for j, k in enumerate(mode.stuck):
            if k in self.probe:
                tau_0, verge = self._verge(mode, k, q, qd, qdd, backend)
                out[:, j, :] = verge
                scale = np.maximum(scale, np.abs(tau_0).max(axis=1))
        return out + SLACK * np.maximum(scale, out.max(axis=(1, 2), initial=0.0))[:, None, None] + 1e-300

    def _verge(self, mode: Mode, k: int, q, qd, qdd, backend: str) -> tuple[np.ndarray, np.ndarray]:
        """(tau_0 (N, dof), (N, 2) K_+ and K_-) of held unit k (module docstring): one solve
        of the twin over 3N samples, at rest (no friction at k) and on the verge of slipping
        in + and in - (its joints' couples -d F_s, its elements' rate d TINY)."""
        n, i = q.shape[0], self.coordinate[k]
        u_i = self.units[k][0][i]
        parts = []
        for d in (0.0, 1.0, -1.0):
            loads = self.loads(mode, qd)
            for name, ji, unit, a, side, axis, prismatic in self.couples:
                if unit == k:
                    w = loads[name]
                    w[:, (0 if prismatic else 3):(3 if prismatic else 6)] = (
                        -side * d * a * self.an.mech.joints[ji].friction.holding * axis)
            parts.append(load_values(self.analysis.mech, n, loads))
        rates = np.concatenate([qd] * 3)
        rates[n:2 * n, i], rates[2 * n:, i] = np.sign(u_i) * TINY, -np.sign(u_i) * TINY
        tau = solver_for(self.analysis).solve(
            np.concatenate([q] * 3), rates, np.concatenate([qdd] * 3), backend=backend, check_finite=False,
            loads={key: np.concatenate([p[key] for p in parts]) for key in parts[0]}).tau
        tau_0 = tau[:n]
        K = np.stack([(tau[n:2 * n, i] - tau_0[:, i]) / u_i, -(tau[2 * n:, i] - tau_0[:, i]) / u_i], axis=1)
        return tau_0, np.maximum(K, 0.0)

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
            over = beyond(Q[0], self.limits(trial, q, qd, qdd[0], T, backend)[0])
            i = int(np.argmax(over))
            if over[i] <= 0.0:
                return trial, qd
            k = held.pop(i)
            start[k] = -np.sign(Q[0, i]) or 1.0

    def events(self, mode: Mode, qd: np.ndarray, dof: int, holding) -> list:
        """The switch events of ``mode`` from state rates ``qd``: a slipping unit's rate
        crossing 0 against its direction, a stuck unit's Q reaching one of its limits
        (``holding(t, x)``: the held units' Q and :meth:`limits` at that state).  Each has
        ``switch`` = (unit, "stick" or "slip")."""
        out = []
        for k, (s, _, _, _) in enumerate(self.units):
            if k in mode.stuck:
                i = mode.stuck.index(k)
                ev = (lambda t, x, i=i: _margin(*holding(t, x), i))
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


def _margin(Q: np.ndarray, limits: np.ndarray, i: int) -> float:
    """How far held unit i's Q is inside its limits (< 0: beyond one)."""
    return min(limits[i, 0] + Q[i], limits[i, 1] - Q[i])


def beyond(Q: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """Each held unit's |Q| beyond its limit in Q's direction, relative to that limit
    (<= 0: within it)."""
    cap = np.where(Q < 0.0, limits[:, 0], limits[:, 1])
    return (np.abs(Q) - cap) / cap


def element_coordinates(an) -> list[int]:
    """The independent coordinates i that a load-dependent friction element turns with alone
    (its rate row a e_i): a lossy gear pair's or drive element's relative rate
    (:attr:`~gearcli.analysis.types.Analysis.mesh_rate_rows`) or a joint with bearing
    friction (its row of S)."""
    mech = an.mech
    rows = [an.mesh_rate_rows[ci] for ci, c in enumerate(an.circuits) if _lossy(mech.gears[c.gear])]
    rows += [np.asarray(an.S[ji], float) for ji in friction_joints(mech)]
    return sorted({int(np.flatnonzero(r)[0]) for r in rows if np.count_nonzero(r) == 1})


def _lossy(g) -> bool:
    return bool(g.loss_factor) or any(e is not None and e.lossy for e in (g.reducer, g.screw, g.worm, g.belt))
