"""The other direction: mass matrix, forward dynamics and the inertia seen at the motors.

Equations of motion on the independent joints (paper Eq. 25; ``an.independent_names``)::

    M(q) qdd + h(q, qd) = tau = A tau_motors

``M`` (dof, dof) is the mass matrix of the whole geared mechanism (every gear, shaft and
rotor, exactly, through the fundamental circuit equations), ``h`` holds the velocity
(Coriolis, centrifugal) terms, gravity and the external loads, and ``A`` is the structure
matrix (motor input rotations = A^T q_ind, paper Eq. 22), so ``tau = A tau_motors`` by
virtual work.  Units: q in rad (m for a prismatic joint), torques in N*m (N); M in kg*m^2
(kg, or kg*m where a rotation and a slide are coupled).

Everything here is built on the inverse dynamics of :func:`gearcli.solve`, which is linear
in qdd (the separating tooth forces |t| tan(phi) are normal to the motion and do no work,
so they never enter tau): one batched solve over N * (dof + 1) samples gives, for every
sample, h = tau(q, qd, 0) and the columns M e_i = tau(q, qd, e_i) - h.  Hence
:func:`forward_dynamics` is the exact inverse of ``solve`` on whatever backend ``solve``
uses, and the mass matrix inherits its exactness (no diagonal "armature" approximation of
the rotors).

Losses (``gears[].efficiency``/``loss_factor``, ``joints[].friction``, bearing friction):
the mesh friction couple c |t| rho makes tau(q, qd, qdd) piecewise linear in qdd (linear for
each sign pattern of the tangential forces t, as the separating forces are), and the
bearing friction moments grow with the reactions the accelerations change.
:func:`forward_dynamics` then solves tau(q, qd, qdd) = A tau_motors as an implicit equation:
the M and h above give a secant start, then steps qdd -= M^-1 (tau(qdd) - A tau_motors),
one batched solve of the samples not yet settled each, until the torque residual is below
1e-12 of the sample's torque scale (the largest of the given torques, h and M: a sample
near a static balance, where those torques nearly vanish, still rounds at the size of its
inertia torques).  The secant M spans qdd = 0 to e_i, not the sign pattern of the
solution, so the steps converge linearly: 10-20 of them on the bundled mechanisms with
c = 0.03 and joint friction (most samples settle in about 10).  Joint Coulomb and viscous
friction depend on the rates only and sit in h.  At zero relative speed a mesh has no
friction couple (no stiction model); a transmission that self-locks under the given
torques has no unique acceleration: ValueError.
"""
from __future__ import annotations

import threading
import weakref

import numpy as np

from .external import load_values
from .solve import solve

CHUNK = 2_000
"""Forward samples per batched solve (each becomes dof + 1 inverse-dynamics samples)."""
SMALL = 16
"""Up to this many samples :func:`solve_spd` calls LAPACK (its Python loop costs more)."""
TOLERANCE = 1e-12
"""With losses: the torque residual at which :func:`forward_dynamics` stops, relative to the
sample's largest torque."""
STALLED = 1e-10
"""With losses: a residual within this of the sample's torque scale ends the iteration when a
step no longer reduces it (the solve's rounding reached before :data:`TOLERANCE`)."""
MAX_STEPS = 60
"""With losses: the most correction steps of :func:`forward_dynamics`."""


def _arrays(an, named: dict) -> list[np.ndarray]:
    """The named arrays as float (N, width) (a 1-D array is one sample); ValueError for a
    bad shape, different sample counts or a value that is not finite (first one named)."""
    out = []
    for name, (given, width, cols) in named.items():
        x = np.asarray(given, float)
        if x.ndim == 1:
            x = x[None, :]
        if x.ndim != 2 or x.shape[1] != width:
            raise ValueError(f"expected {name} with shape (N, {width}) or ({width},), got {np.shape(given)}")
        if not np.isfinite(x).all():
            i, j = np.argwhere(~np.isfinite(x))[0]
            raise ValueError(f"{name} is not finite at sample {i}, {cols[j]}: {x[i, j]}")
        out.append(x)
    if len({x.shape[0] for x in out}) != 1:
        raise ValueError(f"{', '.join(named)} must have the same number of samples, got {[x.shape[0] for x in out]}")
    return out


def _joints(an) -> list[str]:
    return [f"joint '{n}'" for n in an.independent_names]


def _stacked_chunks(an, q, qd, loads, backend, jobs):
    """Yield (slice, tau (m, dof + 1, dof)) chunk by chunk: [:, 0] = tau(q, qd, 0) = h,
    [:, 1 + i] = tau(q, qd, e_i), from one solve of m * (dof + 1) samples per chunk.  The
    chunk's tau is a view of the solve's result arrays, reused by the next chunk (and
    kept between calls, :func:`_result_buffer`): use it before asking for the next."""
    n, dof = q.shape
    k = dof + 1
    loads = load_values(an.mech, n, loads)     # checked, (n, 6) each
    unit = np.zeros((k, dof))
    unit[1:] = np.eye(dof)
    for s in range(0, n, CHUNK):
        sl = slice(s, min(s + CHUNK, n))
        m = sl.stop - sl.start
        Q = np.repeat(q[sl], k, axis=0)
        QD = np.repeat(qd[sl], k, axis=0)
        QDD = np.tile(unit, (m, 1))
        part = {name: np.repeat(w[sl], k, axis=0) for name, w in loads.items()}
        big = m > SMALL                # a few samples (an integrator's step): fresh arrays cost less than out='s checks
        res = solve(an, Q, QD, QDD, loads=part, backend=backend, jobs=jobs,
                    out=_result_buffer(an, m * k) if big else None, check_finite=False)
        if big:
            _keep_buffer(an, m * k, res)
        yield sl, res.tau.reshape(m, k, dof)


_BUFFERS = threading.local()


def _result_buffer(an, rows: int):
    """The result arrays of this thread's last solve of ``rows`` samples of ``an`` (None at
    first): reused, so that a stream of forward calls (an integrator's steps, a benchmark's
    repeats) does not allocate and fault in fresh result pages each time."""
    cache = getattr(_BUFFERS, "results", None)
    hit = cache.get(an) if cache is not None else None
    return hit[1] if hit is not None and hit[0] == rows else None


def _keep_buffer(an, rows: int, res) -> None:
    if not hasattr(_BUFFERS, "results"):
        _BUFFERS.results = weakref.WeakKeyDictionary()
    _BUFFERS.results[an] = (rows, res)


def _stacked_tau(an, q, qd, loads, backend, jobs):
    """tau (N, dof + 1, dof) of :func:`_stacked_chunks`, all chunks."""
    out = np.empty((q.shape[0], an.dof + 1, an.dof))
    for sl, tau in _stacked_chunks(an, q, qd, loads, backend, jobs):
        out[sl] = tau
    return out


def _columns(tau: np.ndarray) -> np.ndarray:
    """M (N, dof, dof) from the stacked torques of :func:`_stacked_tau`, symmetrised."""
    M = np.swapaxes(tau[:, 1:, :] - tau[:, :1, :], 1, 2)
    return 0.5 * (M + np.swapaxes(M, 1, 2))


def mass_matrix(an, q, backend: str = "auto", jobs: int | None = None) -> np.ndarray:
    """Mass matrix M(q) of the independent joints (paper Eq. 25-26), (N, dof, dof).

    ``q`` (N, dof) or (dof,): independent joint angles (rad; m for a prismatic joint) in the
    order of ``an.independent_names``.  M[s, i, j] is the generalised inertia torque on
    independent joint i (N*m; N for a prismatic one) per unit acceleration of joint j
    (rad/s^2; m/s^2): the kinetic energy is 1/2 qd^T M qd.  It includes every link of the
    mechanism: gears, shafts and motor rotors (their inertia as given on their links),
    exactly.  Symmetric positive definite for a well-posed mechanism.  ``backend``,
    ``jobs`` as in :func:`gearcli.solve`.  Raises ValueError for a bad shape or a value
    that is not finite.
    """
    (q,) = _arrays(an, {"q": (q, an.dof, _joints(an))})
    M = np.empty((q.shape[0], an.dof, an.dof))
    for sl, tau in _stacked_chunks(an, q, np.zeros_like(q), {}, backend, jobs):
        M[sl] = _columns(tau)
    return M


def forward_dynamics(an, q, qd, motor_torques, loads: dict | None = None, backend: str = "auto",
                     jobs: int | None = None) -> np.ndarray:
    """Accelerations qdd (N, dof) of the independent joints under given motor torques.

    ``q``, ``qd`` (N, dof) or (dof,): independent joint angles and rates (rad, rad/s; m,
    m/s for a prismatic joint), ``an.independent_names`` order.  ``motor_torques`` (N, M)
    or (M,): the torque each motor applies to its input link about that link's positive
    joint axis (N*m; N for a linear input), ``an.mech.motors`` order: the same convention
    as :attr:`gearcli.Result.motor`.  ``loads``: external loads as in :func:`gearcli.solve`
    (``{name: (N, 6) or (6,)}``; loads not given keep the file's constants); gravity is the
    mechanism's.  Returns qdd in rad/s^2 (m/s^2).

    The exact inverse of :func:`gearcli.solve`: ``solve(an, q, qd, forward_dynamics(an, q,
    qd, T)).motor == T`` to rounding.  It solves M qdd = A T - h with M and h from dof + 1
    inverse-dynamics samples per sample; with losses, the implicit equation of the module
    docstring.  Raises ValueError for bad shapes, a value that is not finite, or (losses)
    a sample without a settled acceleration.
    """
    motors = [f"motor '{m.name}'" for m in an.mech.motors]
    q, qd, T = _arrays(an, {"q": (q, an.dof, _joints(an)), "qd": (qd, an.dof, _joints(an)),
                            "motor_torques": (motor_torques, len(motors), motors)})
    target = np.einsum("nm,dm->nd", T, an.A)    # A T per sample; not matmul: BLAS threads would
    # start, then spin on the second core through the kernel calls below (up to 2x slower)
    if an.mech.has_losses:
        tau = _stacked_tau(an, q, qd, loads, backend, jobs)
        cols = tau[:, 1:, :] - tau[:, :1, :]                 # [s, i, :] = column i of M
        return _implicit(an, q, qd, target, np.swapaxes(cols, 1, 2), tau[:, 0, :], loads, backend, jobs)
    qdd = np.empty_like(q)
    for sl, tau in _stacked_chunks(an, q, qd, loads, backend, jobs):     # each chunk while it is in cache
        h = tau[:, 0, :]
        if tau.shape[0] <= SMALL:                                       # a few samples: LAPACK
            M = np.swapaxes(tau[:, 1:, :] - h[:, None, :], 1, 2)
            qdd[sl] = np.linalg.solve(M, (target[sl] - h)[:, :, None])[:, :, 0]
        else:
            rows = np.subtract(np.transpose(tau[:, 1:, :], (2, 1, 0)), h.T[:, None, :],
                               out=np.empty((q.shape[1], q.shape[1], tau.shape[0])))   # M[j, i, s], C order
            qdd[sl] = solve_spd(rows, target[sl] - h)
    return qdd


def _implicit(an, q, qd, target, M, h, loads, backend, jobs) -> np.ndarray:
    """qdd with tau(q, qd, qdd) = target (N, dof) for a mechanism with losses, where tau is
    piecewise linear in qdd (|t| of the mesh friction): from the secant solution
    M qdd = target - h, steps qdd -= M^-1 (tau(qdd) - target) on the samples not yet settled
    (one solve of those samples a step; linear convergence, 10-20 steps with c = 0.03).

    A sample settles when its residual is within :data:`TOLERANCE` of its torque scale, the
    largest of |target|, |h| and |M| (the torques of unit accelerations: a sample near a
    static balance, target and h ~ 0, still has inertia torques of that size, and its solve
    rounds to them), or when a step no longer reduces a residual already within
    :data:`STALLED` of that scale (rounding reached).  ValueError naming the first sample
    that does not settle in :data:`MAX_STEPS` (e.g. a self-locking transmission)."""
    qdd = np.linalg.solve(M, (target - h)[:, :, None])[:, :, 0]
    values = load_values(an.mech, len(q), loads)
    scale = np.maximum(np.maximum(np.abs(target).max(axis=1), np.abs(h).max(axis=1)),
                       np.abs(M).max(axis=(1, 2)))
    todo = np.arange(len(q))
    last = np.full(len(q), np.inf)
    for _ in range(MAX_STEPS):
        res = solve(an, q[todo], qd[todo], qdd[todo], loads={k: v[todo] for k, v in values.items()},
                    backend=backend, jobs=jobs, check_finite=False)
        r = res.tau - target[todo]
        size = np.abs(r).max(axis=1)
        done = (size <= TOLERANCE * scale[todo]) | ((size >= last[todo]) & (size <= STALLED * scale[todo]))
        last[todo] = size
        todo, r = todo[~done], r[~done]
        if todo.size == 0:
            return qdd
        qdd[todo] -= np.linalg.solve(M[todo], r[:, :, None])[:, :, 0]
    raise ValueError(f"forward dynamics with losses did not settle at sample {todo[0]} in {MAX_STEPS} steps "
                     "(no unique acceleration: a self-locking transmission?)")


def solve_spd(M: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x (N, d) with M[:, :, s] x[s] = b[s] for every sample s: Gaussian elimination without
    pivoting (stable for a symmetric positive definite M), vectorised over the samples.

    ``M`` (d, d, N), samples last so that every step is an operation on contiguous
    N-vectors (overwritten); ``b`` (N, d).  Loops over the d rows only: for small d it is
    ~25 times faster than ``np.linalg.solve`` on (N, d, d), whose cost is ~1 us a matrix
    (3 x 3: 0.02 against 0.5 us a sample), and as fast for d = 8-12.
    """
    d, n = M.shape[0], M.shape[2]
    if n <= SMALL:                                  # a few samples (an integrator's step): LAPACK
        return np.linalg.solve(np.moveaxis(M, 2, 0), b[:, :, None])[:, :, 0]
    y = np.array(b.T, dtype=float)                  # (d, N), a copy
    for i in range(d - 1):
        f = M[i + 1:, i] / M[i, i]
        M[i + 1:, i + 1:] -= f[:, None, :] * M[i, i + 1:][None]
        y[i + 1:] -= f * y[i]
    x = np.empty_like(y)
    for i in range(d - 1, -1, -1):
        x[i] = (y[i] - np.einsum("jn,jn->n", M[i, i + 1:], x[i + 1:])) / M[i, i]
    return x.T


def motor_inertia(an, q, diagonal: bool = False, backend: str = "auto", jobs: int | None = None) -> np.ndarray:
    """Inertia seen at the motors, (N, M, M) (or its diagonal (N, M) with ``diagonal``).

    In motor coordinates theta_m = A^T q_ind (rad; m for a linear input), the kinetic energy
    is 1/2 theta_m_dot^T J_m theta_m_dot with J_m = A^-1 M A^-T, and the motor torques that
    accelerate the resting mechanism are J_m theta_m_ddot (N*m).  J_m[s, a, a] is what motor
    a sees when the other motors hold still, in kg*m^2: its own rotor (its input link) plus
    the reflected inertia of everything it moves.  For coupled motors (a differential,
    the Bendix wrist) the off-diagonal terms couple them; the diagonal is what servo sizing
    compares with the rotor inertia.
    """
    M = mass_matrix(an, q, backend=backend, jobs=jobs)
    Ainv = np.linalg.inv(an.A)
    J = Ainv @ M @ Ainv.T
    J = 0.5 * (J + np.swapaxes(J, 1, 2))
    return np.diagonal(J, axis1=1, axis2=2).copy() if diagonal else J
