"""Time integration of the exact geared dynamics (``gearcli simulate``).

State: the independent joint angles q and rates qd (rad, rad/s; m, m/s for a prismatic
joint; ``an.independent_names`` order) and, for every motor driven by voltage whose DC
model has an inductance, its winding current i (A, starting at 0).  The motor torques are

* a ``motor:<m>`` column: the given torque (N*m), linear between the input's rows;
* a ``voltage:<m>`` column with a DC model ``(kt, R, L, V_supply)``: kt * i, with
  L di/dt = V - R i - kt omega, or without L, i = (V - kt omega) / R; omega = (A^T qd)_m is
  the motor's speed relative to its stator (rad/s).

The accelerations are :func:`~.forward.forward_dynamics` (exact, every gear and rotor),
integrated by :func:`scipy.integrate.solve_ivp` row interval by row interval of the input
(:func:`row_intervals`: its values are linear between rows, their slope may jump at one).  Joints with position limits (YAML
``joints[].limits``, a URDF ``<limit lower upper>``) stop the integration when they reach
one (a terminal event); the stop is reported, with the samples up to it.  A timing belt
whose slack span would go below zero tension at an output sample (|E|/2 > T_i, E from the
inverse dynamics of the samples integrated, as ``--loads`` solves them) stops it too, with
the samples before that one (:meth:`_Kept.append`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


from .payloads import carrying
from .stick_slip import Mode, StickSlip, slip_direction

METHODS = ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")


@dataclass
class Simulation:
    """Samples of a simulated motion: ``t`` (n,) s; ``q``, ``qd``, ``qdd`` (n, dof) of the
    independent joints; ``motor`` (n, M) the motor torques applied (N*m); ``current``
    (n, M) the winding currents (A; NaN for a torque-driven motor); ``stop``: why the
    integration ended early (a joint limit reached), else None; ``nfev``: right-hand side
    evaluations."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    motor: np.ndarray
    current: np.ndarray
    stop: str | None
    nfev: int
    rows: int | None = None     # samples in all (a streamed run's, whose arrays are empty)


class SimulationError(Exception):
    """The integrator failed (the message says why and when; ``t``: when, s)."""

    def __init__(self, message: str, t: float | None = None):
        super().__init__(message)
        self.t = t


class StallError(SimulationError):
    """The integrator's step collapsed (``gearcli.simulation.StallWatch``)."""


EXPLICIT = ("RK45", "RK23", "DOP853")
"""The explicit methods: their step is bounded by the fastest time constant (stiffness)."""


def time_constants(an, q0: np.ndarray) -> list[tuple[str, float]]:
    """The fast time constants of the motion from (q0, at rest), s: each inductive motor's
    L/R, and the viscous friction's fastest decay, 1 / the largest eigenvalue of
    M(q0)^-1 D, D = sum_J F_v,J s_J s_J^T over the joints with viscous friction (s_J the
    joint's row of q = S q_ind), named after the joint whose own F_v s_J^T M^-1 s_J is
    largest.  An explicit method needs steps below about these."""
    from scipy.linalg import eigh  # noqa: PLC0415
    from .forward import mass_matrix  # noqa: PLC0415

    out = [(f"motor '{m.name}''s L/R", m.model.inductance / m.model.resistance) for m in an.mech.motors
           if m.model is not None and m.model.inductance]
    visc = [(ji, jt.friction.viscous) for ji, jt in enumerate(an.mech.joints)
            if jt.friction is not None and jt.friction.viscous > 0]
    if visc:
        M = mass_matrix(an, np.asarray(q0, float)[None, :], backend="numpy")[0]
        S = np.asarray(an.S, float)
        D = sum(c * np.outer(S[ji], S[ji]) for ji, c in visc)
        lam = float(eigh(D, M, eigvals_only=True)[-1])
        if lam > 0:
            own = [c * S[ji] @ np.linalg.solve(M, S[ji]) for ji, c in visc]
            ji, c = visc[int(np.argmax(own))]
            out.append((f"viscous friction {c:g} on joint '{an.mech.joints[ji].name}'", 1.0 / lam))
    return out


def stiffness_hint(an, q0: np.ndarray, span: float, method: str) -> str | None:
    """What makes the system stiff for an explicit ``method`` over ``span`` (s): the fastest
    :func:`time_constants` when it is below 1e-5 of the span (the method then takes at
    least ~1e5 steps), else None."""
    if method not in EXPLICIT:
        return None
    fast = [(what, tau) for what, tau in time_constants(an, q0) if tau < 1e-5 * span]
    if not fast:
        return None
    what, tau = min(fast, key=lambda f: f[1])
    return (f"{what} gives a time constant of {tau:.3g} s, {span / tau:.3g} times shorter than the {span:.6g} s "
            f"simulated: the system is stiff, {method} will crawl or diverge; give --method Radau or BDF")


def joint_limits(an) -> list[tuple[int, str, float, float]]:
    """(joint index, name, lower, upper) of every real joint with position limits
    (``joints[].limits`` of a YAML file, a URDF ``<limit lower upper>`` on a revolute or
    prismatic joint; rad or m)."""
    return [(ji, jt.name, *jt.position_limits) for ji, jt in enumerate(an.mech.joints)
            if jt.position_limits is not None]


class Drive:
    """The motor torques of a drive input (:class:`~gearcli.io.drive_input.DriveInput`) as a
    function of time, rates and winding currents; see the module docstring."""

    def __init__(self, an, drive):
        self.an, self.drive = an, drive
        models = [m.model for m in an.mech.motors]
        volt = np.asarray(drive.voltage, bool)
        self.volt = volt
        self.kt = np.array([m.kt if m is not None else 0.0 for m in models])
        self.R = np.array([m.resistance if m is not None else 1.0 for m in models])
        self.inductive = np.array([bool(v and models[k].inductance is not None) for k, v in enumerate(volt)])
        self.L = np.array([models[k].inductance for k in np.flatnonzero(self.inductive)])

    def torques(self, t, qd, current):
        """(..., M) motor torques at time(s) t with rates qd (..., dof) and the inductive
        motors' currents (..., n_L); also the winding currents (NaN for torque columns)."""
        u = self.drive.at(t)
        w = np.einsum("...d,dm->...m", qd, self.an.A)         # motor speeds A^T qd (no BLAS threads)
        i = np.where(self.volt, (u - self.kt * w) / self.R, np.nan)
        i[..., self.inductive] = current
        return np.where(self.volt, self.kt * i, u), i

    def current_rate(self, t, qd, current):
        """dI/dt (n_L,) of the inductive motors: (V - R i - kt omega) / L."""
        k = self.inductive
        u = self.drive.at(t)[..., k]
        w = np.einsum("...d,dm->...m", qd, self.an.A)[..., k]
        return (u - self.R[k] * current - self.kt[k] * w) / self.L


def _accelerations(ss, mode, q, qd, T, backend, t):
    """(qdd, Q) of :meth:`.stick_slip.StickSlip.accelerations` (the held dynamics of the
    mode) at time(s) t, its failures those of :func:`_located`."""
    return _located(lambda: ss.accelerations(mode, np.atleast_2d(q), np.atleast_2d(qd), np.atleast_2d(T), backend),
                    qd, t)


def _located(work, qd, t):
    """``work()``, its failures a :class:`SimulationError` at time(s) t: a value that is not
    finite, an acceleration with losses that does not settle, a sign search or bearing
    friction that fails (named by its time), an integration that diverged (rates ``qd``)."""
    from .bearing_friction import BearingFrictionError  # noqa: PLC0415
    from .losses import SlackError  # noqa: PLC0415
    from .signs import SignError                        # noqa: PLC0415
    when = f"t = {t:.9g} s" if np.ndim(t) == 0 else f"t = {t[0]:.9g} to {t[-1]:.9g} s"
    first = float(t) if np.ndim(t) == 0 else float(t[0])
    try:
        return work()
    except (SignError, BearingFrictionError, SlackError) as exc:     # its "sample i" counts this call's states
        at = t if np.ndim(t) == 0 else t[min(exc.sample, len(t) - 1)]
        raise SimulationError(f"t = {at:.9g} s: {exc.lines()[0].removeprefix(f'sample {exc.sample}: ')}",
                              float(at)) from None
    except np.linalg.LinAlgError:       # M from tau differences at an exploded state
        raise SimulationError(f"{when}: the integration diverged (joint rates up to {np.abs(qd).max():.3g}: the mass "
                              "matrix is singular to working precision there); a stiff system needs --method Radau "
                              "or BDF", first) from None
    except ValueError as exc:
        raise SimulationError(f"{when}: {exc}", first) from None


def simulate(an, drive, t_eval, q0, qd0, rtol: float = 1e-8, atol: float = 1e-10, method: str = "DOP853",
             progress=None, backend: str = "auto", sink=None) -> Simulation:
    """Integrate from (q0, qd0) at t_eval[0] to t_eval[-1]; samples at ``t_eval`` (s).

    ``drive`` a :class:`~gearcli.io.drive_input.DriveInput`; ``rtol``, ``atol``, ``method``
    those of :func:`scipy.integrate.solve_ivp` (atol in rad, rad/s, A); ``progress(t)`` is
    called with the time reached.  Raises :class:`SimulationError` when the integrator
    fails or the state stops being finite before any sample; after one, the samples up to
    there are kept and ``stop`` says why.  With ``sink``, each run of samples is passed to
    ``sink(simulation)`` as soon as it is integrated (a :class:`Simulation` of those samples,
    in time order) and the one returned holds no samples: ``t`` the first and last times,
    ``rows`` their count (streaming: memory bounded by :data:`PIECE` samples).
    """
    from scipy.integrate import solve_ivp  # noqa: PLC0415  (scipy is a dependency; import when used)

    dof = an.dof
    d = Drive(an, drive)
    nL = int(d.inductive.sum())
    variants = {}

    def stick_slip(t):
        """The stick-slip joints of the mechanism carrying the payloads attached at t."""
        attached = drive.attached_at(t)
        if attached not in variants:
            variants[attached] = StickSlip(carrying(an, attached))
        return variants[attached]

    ss = stick_slip(t_eval[0])
    state = {"mode": Mode(), "memo": (None, None, None), "held": (None, None), "ss": ss}

    def dynamics(t, x):
        """(qdd, Q) at (t, x) in the current mode; the last one kept for the events."""
        key = (t, x.tobytes())
        if state["memo"][0] == key:
            return state["memo"][1:]
        q, qd, cur = x[:dof], x[dof:2 * dof], x[2 * dof:]
        T, _ = d.torques(t, qd, cur)
        qdd, Q = _accelerations(state["ss"], state["mode"], q, qd, T, backend, t)
        state["memo"] = (key, qdd[0], Q[0])
        return qdd[0], Q[0]

    def margins(t, x):
        """The held units' margins at (t, x) (:meth:`.stick_slip.StickSlip.margins`), the
        last one kept: every slip event of a step asks for it."""
        key = (t, x.tobytes())
        if state["held"][0] != key:
            qdd, Q = dynamics(t, x)
            T, _ = d.torques(t, x[dof:2 * dof], x[2 * dof:])
            m = _located(lambda: state["ss"].margins(state["mode"], x[:dof], x[dof:2 * dof], qdd, T, Q, backend)[0],
                         x[dof:2 * dof], t)
            state["held"] = (key, m)
        return state["held"][1]

    def rhs(t, x):
        qdd = dynamics(t, x)[0]
        if progress is not None:
            progress(t)
        qd, cur = x[dof:2 * dof], x[2 * dof:]
        return np.concatenate([qd, qdd, d.current_rate(t, qd, cur)]) if nL else np.concatenate([qd, qdd])

    limits = _limit_events(an)
    x = np.concatenate([q0, qd0, np.zeros(nL)])
    segments, stop, nfev = _Kept(sink, d, dof, backend), None, 0
    if ss.units:                  # joints at rest at the start: held where their friction can
        at_rest = [k for k in range(len(ss.units)) if ss.rate(k, x[dof:2 * dof]) == 0.0]
        state["mode"], x[dof:2 * dof] = _switch(ss, Mode(), at_rest, x, d, t_eval[0], dof, backend)
    try:
        for a, b in row_intervals(drive.t, t_eval[0], t_eval[-1]):
            ss = state["ss"] = stick_slip(a)         # a pick or a place happens at a row
            state["memo"], state["held"] = (None, None, None), (None, None)
            while True:
                # [a, b): a sample at a row takes the row's values (a pick or a place there)
                last = b >= t_eval[-1]
                wanted = t_eval[(t_eval >= a) & ((t_eval < b) | (last & (t_eval <= b)))]
                piece = b if len(wanted) <= PIECE else float(wanted[PIECE])   # at most PIECE samples held
                wanted = wanted[wanted < piece] if piece < b else wanted
                switches = ss.events(state["mode"], x[dof:2 * dof], dof, margins)
                events = limits + switches
                sol = _integrate(solve_ivp, rhs, a, piece, x, wanted, method, rtol, atol, events, segments,
                                 (state["mode"], ss))
                nfev += int(sol.nfev)
                if sol.status != 1:
                    x = sol.y[:, -1]
                    if piece < b:
                        a = piece
                        continue
                    break
                k = next(i for i, te in enumerate(sol.t_events) if len(te))
                te, xe = float(sol.t_events[k][0]), sol.y_events[k][0].copy()
                _keep(segments, sol, wanted[wanted < te], (state["mode"], ss))
                if hasattr(events[k], "joint"):
                    name, side, bound = events[k].joint
                    stop = f"joint '{name}' reached its {side} limit {bound:g} at t = {te:.6g} s"
                    segments.append((np.array([te]), xe[None, :], (state["mode"], ss)))
                    raise _Stopped()
                state["mode"], xe[dof:2 * dof] = _after_switch(ss, state["mode"], events[k].switch, xe, d, te,
                                                               dof, backend, margins)
                state["memo"], state["held"] = (None, None, None), (None, None)
                x, a = xe, te
                if a >= b:
                    break
    except _Stopped as why:
        stop = why.reason or stop
    except SimulationError as exc:       # the motion up to the failure is kept (and written)
        if not segments:
            raise
        stop = str(exc)
    if sink is not None:
        return Simulation(np.array(segments.ends), *(np.zeros((0, n)) for n in (dof, dof, dof, len(d.kt), len(d.kt))),
                          stop, nfev, segments.rows)
    return _samples(d, segments, stop, nfev, dof, backend)


PIECE = 20_000
"""Output samples integrated in one call at most (the integration restarts after them): a
run of millions of samples (--dt 1e-7) is held a piece at a time, not whole."""


class _Kept(list):
    """The samples integrated so far, as segments (t, x, (mode, stick-slip units)); with a
    ``sink`` each segment's samples (t, q, qd, qdd, motor torques, currents) go to it as
    soon as they are kept, in time order, and only the count and the first and last times
    stay (:func:`simulate`'s streaming)."""

    def __init__(self, sink, d, dof, backend):
        super().__init__()
        self.sink, self.d, self.dof, self.backend = sink, d, dof, backend
        self.rows, self.ends = 0, []
        self.belts = any(d.an.mech.gears[c.gear].belt is not None for c in d.an.circuits)

    def append(self, segment) -> None:
        """Keep ``segment``; with a belt whose span goes slack at one of its samples, keep the
        samples before that one and raise :class:`_Stopped` naming the belt and the time."""
        slack = _slack(self.d, segment, self.dof, self.backend) if self.belts else None
        if slack is not None:
            k, reason = slack
            if k:
                self._add((segment[0][:k], segment[1][:k], segment[2]))
            raise _Stopped(reason)
        self._add(segment)

    def _add(self, segment) -> None:
        if self.sink is None:
            super().append(segment)
            self.rows += len(segment[0])
            return
        sim = _samples(self.d, [segment], None, 0, self.dof, self.backend)
        self.sink(sim)
        self.rows += len(sim.t)
        self.ends = [self.ends[0] if self.ends else float(sim.t[0]), float(sim.t[-1])]

    def __bool__(self) -> bool:
        return self.rows > 0


def _slack(d, segment, dof, backend) -> tuple[int, str] | None:
    """(index, reason) of the first sample of ``segment`` where a belt's slack span would go
    below zero tension (:func:`~.losses.check_belts` on the inverse dynamics of its samples,
    the payloads it carries attached), else None."""
    from .losses import SlackError, check_belts  # noqa: PLC0415
    from .solve import solve  # noqa: PLC0415
    sim = _samples(d, [segment], None, 0, dof, backend)
    an = segment[2][1].an           # the mechanism carrying this segment's payloads
    res = solve(an, sim.q, sim.qd, sim.qdd, backend=backend)
    try:
        check_belts(an, res)
    except SlackError as exc:
        return exc.sample, (f"belt '{exc.belt}' goes slack at t = {sim.t[exc.sample]:.9g} s: pretension T_i = "
                            f"{exc.pretension:g} N < |E|/2 = {exc.half:.6g} N (raise the pretension, or lower the load)")
    return None


def _limit_events(an) -> list:
    """The terminal events of the joints' position limits (``joint``: name, side, bound)."""
    dof, out = an.dof, []
    for ji, name, lo, hi in joint_limits(an):
        row = an.S[ji]
        for side, bound in (("lower", lo), ("upper", hi)):
            sign = 1.0 if side == "lower" else -1.0
            ev = (lambda t, x, row=row, b=bound, s=sign: s * (row @ x[:dof] - b))
            ev.terminal, ev.direction = True, -1.0
            ev.joint = (name, side, bound)
            out.append(ev)
    return out


def _after_switch(ss, mode, switch, xe, d, te, dof, backend, margins):
    """(mode, q') after the stick-slip event ``switch`` = (unit, "stick" or "slip") at
    (te, xe): a unit whose rate reached 0 is held if it can be; a held one whose margin
    reached 0 slips on that side (the others classified again)."""
    k, kind = switch
    if kind == "stick":
        return _switch(ss, mode, [k], xe, d, te, dof, backend)
    side = slip_direction(margins(te, xe)[mode.stuck.index(k)])
    released = Mode(tuple(j for j in mode.stuck if j != k), {**mode.start, k: side})
    return _switch(ss, released, [], xe, d, te, dof, backend)


class _Stopped(Exception):
    """A joint limit or a slack belt ended the integration (``reason``: the belt's, else None:
    the caller has set the joint limit's)."""

    def __init__(self, reason: str | None = None):
        super().__init__(reason)
        self.reason = reason


def _integrate(solve_ivp, rhs, a, b, x, wanted, method, rtol, atol, events, segments, mode):
    """solve_ivp over [a, b] from x with samples ``wanted`` (and b, the next start); the
    samples up to b kept in ``segments`` (when no event ends it).  On a failure, the
    samples before it (integrated again up to the last of them) are kept, then the
    SimulationError (``t``: when) goes on."""
    at = np.union1d(wanted, [b])
    try:
        sol = solve_ivp(rhs, (a, b), x, method=method, t_eval=at, rtol=rtol, atol=atol, events=events or None)
    except SimulationError as exc:
        before = wanted[wanted < (exc.t if exc.t is not None else a)]
        if before.size == 1 and before[0] == a:       # the start alone: its state is x
            segments.append((before, x[None, :].copy(), mode))
        elif before.size:
            try:
                again = solve_ivp(rhs, (a, float(before[-1])), x, method=method, t_eval=before, rtol=rtol, atol=atol)
                _keep(segments, again, before, mode)
            except SimulationError:
                pass
        raise
    if sol.status == -1:
        raise SimulationError(f"the integrator failed at t = {sol.t[-1] if len(sol.t) else a:.9g} s: {sol.message}")
    if sol.status == 0:
        _keep(segments, sol, wanted, mode)
    return sol


def _keep(segments: list, sol, wanted: np.ndarray, mode) -> None:
    keep = np.isin(sol.t, wanted)
    if keep.any():
        segments.append((sol.t[keep], sol.y.T[keep], mode))


def _switch(ss, mode, at_rest, x, d, t, dof, backend):
    """:meth:`StickSlip.classify` at state x and time t: (the new mode, q' with the held
    joints' rates exactly 0)."""
    q, qd, cur = x[:dof], x[dof:2 * dof], x[2 * dof:]
    T, _ = d.torques(t, qd, cur)
    try:
        return ss.classify(mode, at_rest, q, qd, T, backend)
    except ValueError as exc:
        raise SimulationError(f"t = {t:.9g} s: {exc}", t) from None


def _samples(d, segments, stop, nfev, dof, backend) -> Simulation:
    """The :class:`Simulation` of the kept ``segments`` (t, x, (mode, stick-slip joints of
    the payloads attached)): accelerations of each segment's samples in its mode, one call
    per segment."""
    t = np.concatenate([s[0] for s in segments])
    x = np.concatenate([s[1] for s in segments])
    q, qd, cur = x[:, :dof], x[:, dof:2 * dof], x[:, 2 * dof:]
    T, current = d.torques(t, qd, cur)
    qdd = np.empty_like(q)
    at = 0
    for ts, _, (mode, ss) in segments:
        sl = slice(at, at + len(ts))
        qdd[sl] = _accelerations(ss, mode, q[sl], qd[sl], T[sl], backend, t[sl])[0]
        at += len(ts)
    return Simulation(t, q, qd, qdd, T, current, stop, nfev)


def row_intervals(rows: np.ndarray, t0: float, t1: float) -> list[tuple[float, float]]:
    """The intervals [a, b] between the input's rows ``rows`` (s) that cover [t0, t1]: the
    integration restarts at every row, where the input's slope may jump (across a kink an
    integrator's error estimate fails, and its error stops following --rtol)."""
    inner = rows[(rows > t0) & (rows < t1)]
    edges = np.concatenate([[t0], inner, [t1]])
    return [(float(a), float(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a]
