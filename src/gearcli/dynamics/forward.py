"""The other direction: mass matrix, forward dynamics and the inertia seen at the motors.

Equations of motion on the independent joints (paper Eq. 25; ``an.independent_names``)::

    M(q) qdd + h(q, qd) = tau = A tau_motors

``M`` (dof, dof) is the mass matrix of the whole geared mechanism (every gear, shaft and
rotor, exactly, through the fundamental circuit equations), ``h`` holds the velocity
(Coriolis, centrifugal) terms, gravity and the external loads, and ``A`` is the structure
matrix (motor input rotations = A^T q_ind, paper Eq. 22), so ``tau = A tau_motors`` by
virtual work.  Units: q in rad (m for a prismatic joint), torques in N*m (N); M in kg*m^2
(kg, or kg*m where a rotation and a slide are coupled).

M and h are those of the inverse dynamics of :func:`gearcli.solve`, which is linear in qdd
(the separating tooth forces |t| tan(phi) act at the pitch point, where the meshing teeth
have no relative velocity: they do no work and never enter tau): h = tau(q, qd, 0) and the
columns M e_i = tau(q, qd, e_i) - h, so :func:`forward_dynamics` is the exact inverse of
``solve`` and the mass matrix inherits its exactness (no diagonal "armature" approximation
of the rotors).  Two implementations, equal to 1e-12 of each sample's largest torque
(tests/test_forward.py):

* the mass kernel (:mod:`.llvm.mass`; backend "llvm", and "auto" where the llvm backend
  runs): generated per mechanism, compiled once and kept on disk as the solve kernel is;
  per sample one h pass and dof column passes (qd = 0, qdd = e_i, no gravity, no loads)
  sharing the pose, every signed block solved with one sign pattern and no search (the
  torques do not depend on it), writing only M, h and qdd = M^-1 (A T - h) (in the same
  loop).  A forward sample costs about 1.1 solve samples on Bendix (dof 3) and 3.5 on
  Panda (dof 8), against dof + 1 (``benchmarks/bench_forward.py --jobs 1``, 2026-11-26
  11:45 UTC, load 3.2: Bendix 2.24 M forward samples/s against 2.52 M for solve, 3.6x
  the 1/(dof + 1) limit; Panda 601,000 against 2.08 M, 2.5x);
* the numpy reference (backend "numpy", and "auto"'s first-call rule of :mod:`.backends`,
  a call counting as n (dof + 1) samples, while the kernel is neither compiled nor on
  disk): one numpy solve of the N (dof + 1) stacked samples, dof + 1 inverse dynamics.
  Beyond :data:`MAX_KERNEL_DOF` independent joints the same stacked solve runs on the
  solve's own backend (the llvm solve kernel) instead of compiling the mass kernel.

Losses (``gears[].efficiency``/``loss_factor``, ``joints[].friction``, bearing friction):
the mesh friction couple c |t| rho makes tau(q, qd, qdd) piecewise linear in qdd (linear for
each sign pattern of the tangential forces t, as the separating forces are), and the
bearing friction moments grow with the reactions the accelerations change.
:func:`forward_dynamics` then solves tau(q, qd, qdd) = A tau_motors as an implicit equation:
the M and h above give a secant start, then steps qdd -= M^-1 (tau(qdd) - A tau_motors),
one batched full solve (losses included) of the samples not yet settled each, until the
torque residual is below 1e-12 of the sample's torque scale (the largest of the given
torques, h and M: a sample near a static balance, where those torques nearly vanish,
still rounds at the size of its inertia torques).  The mass kernel's M and h are the
lossless ones (the reference's span qdd = 0 to e_i with the friction of that pattern);
neither is the solution's own slope, so the steps converge linearly: with c = 0.03 and
joint friction on the bundled mechanisms 9-11 steps from the kernel's lossless M (10-20
from the reference's secant).  Joint Coulomb and viscous friction depend on the rates only
(the first step takes them in).  At zero relative speed a mesh has no friction couple (no
stiction model); a transmission that self-locks under the given torques has no unique
acceleration: ValueError.
"""
from __future__ import annotations


import numpy as np

from .backends import CALL_SAMPLES, FIRST_CALL_SAMPLES
from .external import load_values
from .inputs import joint_names, sample_arrays
from .llvm.cache import has_program
from .solve import Solver as _Solver
from .solve import solver_for

CHUNK = 2_000
"""Forward samples per batched solve (each becomes dof + 1 inverse-dynamics samples)."""
TOLERANCE = 1e-12
"""With losses: the torque residual at which :func:`forward_dynamics` stops, relative to the
sample's largest torque."""
STALLED = 1e-10
"""With losses: a residual within this of the sample's torque scale ends the iteration when a
step no longer reduces it (the solve's rounding reached before :data:`TOLERANCE`)."""
MAX_STEPS = 60
"""With losses: the most correction steps of :func:`forward_dynamics`."""
SECANT_STEPS = 8
"""With losses: the correction steps taken with the lossless M; a sample still not settled
then takes Newton steps with the lossy Jacobian (:func:`_lossy_jacobian`, dof + 1 solves)."""
FEW_SAMPLES, FEW_SECANT_STEPS = 4, 1
STEP = 1e-4
"""The lossy Jacobian's difference step, relative to a sample's largest |qdd| (at least 1):
small enough that the friction's sign pattern and the bearing friction's curvature seldom
change across it (a step of 1 did, and Newton then converged linearly, at ~0.04 a step, on
a quarter of the SCARA's states), large enough that the differences' rounding (~1e-12 of
the torques) leaves Newton quadratic to TOLERANCE."""
"""A call of at most FEW_SAMPLES samples (a simulate step, a stick-slip switch) takes
FEW_SECANT_STEPS steps with M before Newton's: each step is then a solve call's overhead
(~0.5 ms), and the SCARA's settling took 12.6 calls with 8 (docs/performance.md)."""


def _stacked_chunks(sol, q, qd, loads, backend, jobs):
    """The reference of :func:`_mass_and_h`: yield (slice, tau (m, dof + 1, dof)) chunk by
    chunk, [:, 0] = tau(q, qd, 0) = h, [:, 1 + i] = tau(q, qd, e_i), from one solve of
    m * (dof + 1) samples per chunk (``backend`` "numpy": the numpy reference)."""
    n, dof = q.shape
    k = dof + 1
    unit = np.zeros((k, dof))
    unit[1:] = np.eye(dof)
    for s in range(0, n, CHUNK):
        sl = slice(s, min(s + CHUNK, n))
        m = sl.stop - sl.start
        part = {name: np.repeat(w[sl], k, axis=0) for name, w in loads.items()}
        res = sol.solve(np.repeat(q[sl], k, axis=0), np.repeat(qd[sl], k, axis=0), np.tile(unit, (m, 1)),
                        loads=part, backend=backend, jobs=jobs, check_finite=False)
        yield sl, res.tau.reshape(m, k, dof)


MAX_KERNEL_DOF = 12
"""Up to this many independent joints the mass kernel; beyond, the stacked solve on the
solve's backend: the mass kernel's IR grows with dof^2 and its compile faster (serial
chains at load 4: 8 joints 2.2 s, 16 10 s, 24 43 s, against 0.7, 1.3 and 2.2 s for the
solve kernel)."""


def _mass_kernel(sol, n: int, backend: str):
    """(the mass kernel (:class:`.llvm.mass.MassKernel`) for a call of n samples, or None
    and the backend of the stacked solve instead).  ``backend`` as :func:`gearcli.solve`'s:
    "numpy" the numpy reference; "llvm" the kernel (or ValueError); "auto" the kernel where
    the llvm backend can run, by the first-call rule of :mod:`.backends` (a call counting as
    n (dof + 1) samples, the solve's work it replaces; its own compile and disk cache
    entries), else the numpy reference.  Beyond :data:`MAX_KERNEL_DOF`: the stacked solve."""
    an = sol.an
    if backend == "numpy":
        return None, "numpy"
    if sol.choice("block", backend, None).path == "numpy":      # ValueError for a bad backend
        return None, "numpy"
    if an.dof > MAX_KERNEL_DOF:
        return None, backend
    from .llvm.mass import MassKernel  # noqa: PLC0415  (imports llvmlite)
    kernel, seen = sol.mass_kernel
    if kernel is None:
        seen += max(n * (an.dof + 1), CALL_SAMPLES)
        prog = sol.kernel_program()
        if backend == "auto" and seen < FIRST_CALL_SAMPLES and not has_program(MassKernel.ids(prog, an)[1]):
            sol.mass_kernel = (None, seen)
            return None, "numpy"
        kernel = MassKernel(prog, an)
        sol.mass_kernel = (kernel, seen)
    return kernel, backend


def _mass_and_h(sol, q, qd, target, loads, backend, jobs):
    """(M (N, dof, dof), h (N, dof), qdd (N, dof) = M^-1 (target - h)) of every sample: the
    mass kernel's (lossless) or the numpy reference's (for a lossy mechanism the secant of
    the module docstring)."""
    an = sol.an
    n, dof = q.shape
    values = load_values(an.mech, n, loads)      # checked, (n, 6) each
    kernel, stacked = _mass_kernel(sol, n, backend)
    got = None if kernel is None else kernel.run(an, q, qd, values, target, jobs)
    if got is not None:
        return got
    M, h = np.empty((n, dof, dof)), np.empty((n, dof))       # stacked (also a kernel sample not finite:
    for sl, tau in _stacked_chunks(sol, q, qd, values, stacked, jobs):      # then the solve names it)
        M[sl] = np.swapaxes(tau[:, 1:, :] - tau[:, :1, :], 1, 2)
        M[sl] = 0.5 * (M[sl] + np.swapaxes(M[sl], 1, 2))
        h[sl] = tau[:, 0, :]
    return M, h, np.linalg.solve(M, (target - h)[:, :, None])[:, :, 0]


def mass_matrix(an, q, backend: str = "auto", jobs: int | None = None, attach: dict | None = None,
                solver=None) -> np.ndarray:
    """Mass matrix M(q) of the independent joints (paper Eq. 25-26), (N, dof, dof).

    ``q`` (N, dof) or (dof,): independent joint angles (rad; m for a prismatic joint) in the
    order of ``an.independent_names``.  M[s, i, j] is the generalised inertia torque on
    independent joint i (N*m; N for a prismatic one) per unit acceleration of joint j
    (rad/s^2; m/s^2): the kinetic energy is 1/2 qd^T M qd.  It includes every link of the
    mechanism: gears, shafts and motor rotors (their inertia as given on their links),
    exactly.  Symmetric positive definite for a well-posed mechanism.  ``backend``,
    ``jobs`` and ``attach`` (the payloads carried at each sample) as in
    :func:`gearcli.solve`.  Raises ValueError for a bad shape or a value that is not finite.
    """
    (q,) = sample_arrays({"q": (q, an.dof, joint_names(an))})
    if attach:                  # payloads carried at some samples (:mod:`.payloads`)
        from .payloads import attach_flags, by_groups  # noqa: PLC0415
        return by_groups(an, attach_flags(an, attach, len(q)), lambda a, rows: mass_matrix(a, q[rows], backend, jobs),
                         len(q))
    return _mass_and_h(solver or solver_for(an), q, np.zeros_like(q), np.zeros_like(q), None, backend, jobs)[0]


def forward_dynamics(an, q, qd, motor_torques, loads: dict | None = None, backend: str = "auto",
                     jobs: int | None = None, attach: dict | None = None, solver=None) -> np.ndarray:
    """Accelerations qdd (N, dof) of the independent joints under given motor torques.

    ``q``, ``qd`` (N, dof) or (dof,): independent joint angles and rates (rad, rad/s; m,
    m/s for a prismatic joint), ``an.independent_names`` order.  ``motor_torques`` (N, M)
    or (M,): the torque each motor applies to its input link about that link's positive
    joint axis (N*m; N for a linear input), ``an.mech.motors`` order: the same convention
    as :attr:`gearcli.Result.motor`.  ``loads``: external loads as in :func:`gearcli.solve`
    (``{name: (N, 6) or (6,)}``; loads not given keep the file's constants); gravity is the
    mechanism's; ``attach`` the payloads carried at each sample, as in :func:`gearcli.solve`.
    Returns qdd in rad/s^2 (m/s^2).

    The exact inverse of :func:`gearcli.solve`: ``solve(an, q, qd, forward_dynamics(an, q,
    qd, T)).motor == T`` to rounding.  It solves M qdd = A T - h with M and h of the mass
    kernel (or the numpy reference, module docstring); with losses, the implicit equation
    of the module docstring.  Raises ValueError for bad shapes, a value that is not finite, or (losses)
    a sample without a settled acceleration.
    """
    motors = [f"motor '{m.name}'" for m in an.mech.motors]
    q, qd, T = sample_arrays({"q": (q, an.dof, joint_names(an)), "qd": (qd, an.dof, joint_names(an)),
                              "motor_torques": (motor_torques, len(motors), motors)})
    if attach:                  # payloads carried at some samples (:mod:`.payloads`)
        from .payloads import attach_flags, by_groups, loads_at  # noqa: PLC0415

        def run(a, rows):
            part = loads_at(loads, rows)
            return forward_dynamics(a, q[rows], qd[rows], T[rows], part or None, backend, jobs)
        return by_groups(an, attach_flags(an, attach, len(q)), run, len(q))
    target = np.einsum("nm,dm->nd", T, an.A)    # A T per sample; not matmul: BLAS threads would
    # start, then spin on the second core through the kernel calls below (up to 2x slower)
    sol = solver or solver_for(an)
    M, h, qdd = _mass_and_h(sol, q, qd, target, loads, backend, jobs)
    return _implicit(sol, q, qd, target, M, h, qdd, loads, backend, jobs) if an.mech.has_losses else qdd


def held_dynamics(an, q, qd, motor_torques, C: np.ndarray, loads: dict | None = None,
                  backend: str = "auto", solver=None) -> tuple[np.ndarray, np.ndarray]:
    """(qdd (N, dof), Q (N, k)): the accelerations of the independent joints with k joints
    held at rest by friction, and the generalised friction forces Q that hold them.

    ``C`` (k, dof): each held joint's row of q = S q_ind, so its rate is C qd (0) and its
    acceleration C qdd = 0; its friction Q acts on the independent joints as C^T Q (N*m or
    N, on the joint's child about (along) its axis, as ``joints[].friction``'s).
    ``loads`` as :func:`forward_dynamics`'s (the slipping joints' Coulomb friction as a
    couple on their links, :mod:`.stick_slip`).  Solves M qdd + h = A T + C^T Q, C qdd = 0,
    per sample (with losses, tau(qdd) for M qdd + h, as :func:`forward_dynamics`)."""
    q, qd, T = (np.atleast_2d(np.asarray(v, float)) for v in (q, qd, motor_torques))
    target = np.einsum("nm,dm->nd", T, an.A)
    sol = solver or solver_for(an)
    M, h, qdd = _mass_and_h(sol, q, qd, target, loads, backend, None)
    C = np.asarray(C, float).reshape(-1, an.dof)
    k = C.shape[0]
    Q = np.zeros((len(q), k))
    if k:
        x = np.linalg.solve(_kkt(M, C), np.concatenate([target - h, np.zeros((len(q), k))], axis=1)[:, :, None])
        qdd, Q = x[:, :an.dof, 0], x[:, an.dof:, 0]
    if an.mech.has_losses:
        qdd, Q = _settle(sol, q, qd, target, M, h, qdd, Q, C, loads, backend, None)
    return qdd, Q


def _kkt(J: np.ndarray, C: np.ndarray) -> np.ndarray:
    """[[J, -C^T], [C, 0]] (N, dof + k, dof + k) of the held dynamics (:func:`held_dynamics`)."""
    n, dof, k = J.shape[0], J.shape[1], C.shape[0]
    K = np.zeros((n, dof + k, dof + k))
    K[:, :dof, :dof] = J
    K[:, :dof, dof:] = -C.T
    K[:, dof:, :dof] = C
    return K


def _implicit(sol, q, qd, target, M, h, qdd, loads, backend, jobs) -> np.ndarray:
    """qdd with tau(q, qd, qdd) = target (N, dof) for a mechanism with losses, where tau is
    piecewise linear in qdd (|t| of the mesh friction): from ``qdd``, the secant solution
    M qdd = target - h, steps qdd -= M^-1 (tau(qdd) - target) on the samples not yet settled
    (one solve of those samples a step; linear convergence, 10-20 steps with c = 0.03), and
    after :data:`SECANT_STEPS` of them Newton steps with the lossy Jacobian.

    A sample settles when its residual is within :data:`TOLERANCE` of its torque scale, the
    largest of |target|, |h| and |M| (the torques of unit accelerations: a sample near a
    static balance, target and h ~ 0, still has inertia torques of that size, and its solve
    rounds to them), or when a step no longer reduces a residual already within
    :data:`STALLED` of that scale (rounding reached).  ValueError naming the first sample
    that does not settle in :data:`MAX_STEPS` (e.g. a self-locking transmission)."""
    return _settle(sol, q, qd, target, M, h, qdd, np.zeros((len(q), 0)), np.zeros((0, sol.an.dof)), loads,
                   backend, jobs)[0]


def _settle(sol, q, qd, target, M, h, qdd, Q, C, loads, backend, jobs) -> tuple[np.ndarray, np.ndarray]:
    """(qdd, Q) with tau(q, qd, qdd) = target + C^T Q and C qdd = 0 (no held joint: k = 0,
    :func:`_implicit`), from the secant solution: steps with the lossless M, then Newton
    steps with the lossy Jacobian, each solving [[J, -C^T], [C, 0]] (d qdd, d Q) = (r, 0)."""
    an = sol.an
    values = load_values(an.mech, len(q), loads)
    scale = np.maximum(np.maximum(np.abs(target).max(axis=1), np.abs(h).max(axis=1)),
                       np.abs(M).max(axis=(1, 2)))
    todo = np.arange(len(q))
    last = np.full(len(q), np.inf)
    dof, k = an.dof, C.shape[0]
    # a few samples (a simulate step): a solve call costs its overhead, not its samples, and
    # Newton (2 calls a step, exact where the signs hold) settles in 2-3 steps, M in ~10
    secant = SECANT_STEPS if len(q) > FEW_SAMPLES else FEW_SECANT_STEPS

    def tau(rows, acc):
        return sol.solve(q[rows], qd[rows], acc, loads={key: v[rows] for key, v in values.items()},
                         backend=backend, jobs=jobs, check_finite=False, element_outputs=False).tau

    for step in range(MAX_STEPS):
        r = tau(todo, qdd[todo]) - target[todo] - Q[todo] @ C
        size = np.abs(r).max(axis=1)
        done = (size <= TOLERANCE * scale[todo]) | ((size >= last[todo]) & (size <= STALLED * scale[todo]))
        last[todo] = size
        todo, r = todo[~done], r[~done]
        if todo.size == 0:
            return qdd, Q
        J = M[todo] if step < secant else _lossy_jacobian(tau, todo, qdd[todo], r + target[todo] + Q[todo] @ C)
        if k == 0:
            qdd[todo] -= np.linalg.solve(J, r[:, :, None])[:, :, 0]
        else:
            d = np.linalg.solve(_kkt(J, C), np.concatenate([r, np.zeros((len(todo), k))], axis=1)[:, :, None])[:, :, 0]
            qdd[todo] -= d[:, :dof]
            Q[todo] -= d[:, dof:]
    raise ValueError(f"forward dynamics with losses did not settle at sample {todo[0]} in {MAX_STEPS} steps "
                     "(no unique acceleration: a self-locking transmission?)")


def _lossy_jacobian(tau, rows, qdd: np.ndarray, tau0: np.ndarray) -> np.ndarray:
    """d tau / d qdd (n, dof, dof) of the samples ``rows`` at ``qdd`` (their torques
    ``tau0``), by differences over a step of :data:`STEP` max(1, |qdd|) per sample: exact,
    to rounding, where the friction's sign pattern holds across it (tau is piecewise linear
    in qdd), and the slope
    of the losses that the lossless M leaves out (bearing friction of large mu d / lever
    converges at ~Lambda a step with M: it stopped at MAX_STEPS, both backends at their own
    sample)."""
    n, dof = qdd.shape
    delta = STEP * np.maximum(1.0, np.abs(qdd).max(axis=1))
    shifted = np.repeat(qdd, dof, axis=0) + (np.tile(np.eye(dof), (n, 1)) * np.repeat(delta, dof)[:, None])
    cols = tau(np.repeat(rows, dof), shifted).reshape(n, dof, dof)      # [sample, column i, tau]
    return np.transpose(cols - tau0[:, None, :], (0, 2, 1)) / delta[:, None, None]


def motor_inertia(an, q, diagonal: bool = False, backend: str = "auto", jobs: int | None = None,
                  attach: dict | None = None, solver=None) -> np.ndarray:
    """Inertia seen at the motors, (N, M, M) (or its diagonal (N, M) with ``diagonal``).

    In motor coordinates theta_m = A^T q_ind (rad; m for a linear input), the kinetic energy
    is 1/2 theta_m_dot^T J_m theta_m_dot with J_m = A^-1 M A^-T, and the motor torques that
    accelerate the resting mechanism are J_m theta_m_ddot (N*m).  J_m[s, a, a] is what motor
    a sees when the other motors hold still, in kg*m^2: its own rotor (its input link) plus
    the reflected inertia of everything it moves.  For coupled motors (a differential,
    the Bendix wrist) the off-diagonal terms couple them; the diagonal is what servo sizing
    compares with the rotor inertia.
    """
    M = mass_matrix(an, q, backend=backend, jobs=jobs, attach=attach, solver=solver)
    Ainv = np.linalg.inv(an.A)
    J = Ainv @ M @ Ainv.T
    J = 0.5 * (J + np.swapaxes(J, 1, 2))
    return np.diagonal(J, axis1=1, axis2=2).copy() if diagonal else J


class Solver(_Solver):
    """An explicit solver of one analysed mechanism (``gearcli.Solver(an, backend="auto",
    jobs=None)``): it holds the block plans and the compiled solve and mass kernels as long
    as it lives (Pinocchio's Model/Data in spirit), and its methods take the arguments of
    :func:`gearcli.solve`, :func:`forward_dynamics`, :func:`mass_matrix` and
    :func:`motor_inertia` without the analysis, ``backend`` and ``jobs`` defaulting to its
    own.  The module functions keep one (plain) solver per analysis, a convenience;
    "auto"'s first-call rule counts each solver's own calls."""

    def forward_dynamics(self, q, qd, motor_torques, loads: dict | None = None, backend: str | None = None,
                         jobs: int | None = None, attach: dict | None = None):
        """:func:`.forward.forward_dynamics` of this solver's mechanism, with its kernels."""
        return forward_dynamics(self.an, q, qd, motor_torques, loads, backend or self.backend,
                                jobs if jobs is not None else self.jobs, attach, solver=self)

    def mass_matrix(self, q, backend: str | None = None, jobs: int | None = None, attach: dict | None = None):
        """:func:`.forward.mass_matrix` of this solver's mechanism, with its kernels."""
        return mass_matrix(self.an, q, backend or self.backend, jobs if jobs is not None else self.jobs, attach,
                           solver=self)

    def motor_inertia(self, q, diagonal: bool = False, backend: str | None = None, jobs: int | None = None,
                      attach: dict | None = None):
        """:func:`.forward.motor_inertia` of this solver's mechanism, with its kernels."""
        return motor_inertia(self.an, q, diagonal, backend or self.backend, jobs if jobs is not None else self.jobs,
                             attach, solver=self)

