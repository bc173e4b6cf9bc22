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
the friction where it is.  A held joint's friction enters as C^T Q on the independent
joints (its row s_J of q = S q_ind).  Viscous, mesh and bearing friction stay in the twin:
a mesh or bearing at rest has no couple (sign 0), and holds nothing (docs/concepts/losses.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..model.friction import JointFriction
from ..model.loads import Load
from .forward import held_dynamics


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

    def name(self, u: int) -> str:
        """The unit's joints, e.g. "joint 'Jw'" or "joints 'Jp', 'Jw'"."""
        names = [self.an.mech.joints[ji].name for ji in self.units[u][3]]
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
        return qdd, Q

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
            trial = Mode(tuple(held), start)
            if not held:
                return trial, qd
            _, Q = self.accelerations(trial, q[None, :], qd[None, :], T[None, :], backend)
            over = np.abs(Q[0]) / np.array([self.units[k][2] for k in held]) - 1.0
            i = int(np.argmax(over))
            if over[i] <= 0.0:
                return trial, qd
            k = held.pop(i)
            start[k] = -np.sign(Q[0, i]) or 1.0

    def events(self, mode: Mode, qd: np.ndarray, dof: int, held_Q) -> list:
        """The switch events of ``mode`` from state rates ``qd``: a slipping unit's rate
        crossing 0 against its direction, a stuck unit's |Q| reaching F_s (``held_Q(t, x)``:
        the held units' Q at that state).  Each has ``switch`` = (unit, "stick" or "slip")."""
        out = []
        for k, (s, _, fs, _) in enumerate(self.units):
            if k in mode.stuck:
                i = mode.stuck.index(k)
                ev = (lambda t, x, i=i, fs=fs: fs - abs(held_Q(t, x)[i]))
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
