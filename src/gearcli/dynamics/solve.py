"""Inverse dynamics of a geared mechanism along a trajectory (paper, "Dynamic Analysis").

:func:`solve` takes the independent joint angles (the equivalent open-loop chain), their
rates and accelerations, arrays shaped (N, dof), and returns a :class:`Result` with the
motor torques, the reaction wrench of every real joint and the contact force of every gear
mesh at every sample.

Method ``"block"`` (default) solves the Newton-Euler equations block by block in the
schedule of :mod:`gearcli.analysis.schedule` (highest level first, one link or a few coupled
levels at a time; :mod:`.blocks`).  Method ``"full"`` assembles all 6 x (moving links)
equations and solves them simultaneously (:mod:`.general`); it exists to cross-check the
schedule.  Both are exact: the |t| of the separating tooth force (Eq. 14) makes the
equations piecewise linear, and each sample is solved with the sign pattern of the
tangential forces that is consistent with its own solution (:mod:`.signs`).

Model/Data split: the :class:`~gearcli.analysis.graph.Analysis` is never modified; the
precomputed block plans live in a :class:`Solver`, built once per analysis.
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from threadpoolctl import ThreadpoolController

from ..analysis.schedule import unknown_groups
from .backends import CALL_SAMPLES, Choice, choose, llvm_refusal
from .blocks import make_plans, solve_blocks
from .equations import Columns
from .general import is_geared, solve_full
from .external import external_wrenches, load_values, subtract_external
from .inertia import inertia_load
from .inputs import motion_arrays
from .llvm.output_maps import gear_outputs
from .llvm.program import MAX_SIGNED, build_program
from .kinematics import forward
from .bearing_friction import solve_with_bearing_friction, subtract_bearing_friction
from .losses import (LOSS_FIELDS, fill_belts, fill_kernel_losses, fill_losses, fill_reducers, fill_worms,
                     subtract_belt_pretension, subtract_joint_friction, subtract_reducer_drag)
from .result_arrays import check_out, copy_into, result_arrays, work_arrays
from .signs import SignError, sign_violation

DEFAULT_CHUNK = 20_000


@dataclass
class Result:
    """Loads along a trajectory; every array has the samples first.

    ``motor`` (N, M): torque (N*m; N for a prismatic input) each motor applies to its input
    link about that link's positive joint axis.
    ``tau`` (N, dof): equivalent torques on the independent joints (paper Eq. 25),
    tau = A @ motor with A the structure matrix.
    ``joint`` (N, J, 6): reaction wrench [fx, fy, fz, mx, my, mz] the parent exerts on the
    child, in the joint frame (z along the axis, x fixed in the child), about the joint
    frame origin; N and N*m.  mz of a revolute joint (fz of a prismatic one) is zero: the
    motor torque is reported in ``motor``.
    ``gear_t`` (N, G): tangential tooth force on gear j by gear k, N, positive when it turns
    j in j's positive sense (for an ideal coupling: the mesh torque on j, N*m).
    ``gear_sep`` (N, G): separating force magnitude |t| tan(phi), N (phi_t = the transverse
    pressure angle, tan(phi_n) / cos(beta), for a helical pair).
    ``gear_radial``, ``gear_axial`` (N, G, 2): components of the tooth force on gear j and on
    gear k along each gear's own outward radial direction (towards the pitch point) and its
    positive axis, N.
    ``residual``: with ``verify``, the worst relative Newton-Euler residual of any link and
    sample, and of the sign of every t against the sign pattern used (else None).
    ``gear_loss``, ``joint_friction``, ``joint_loss``, ``bearing_iterations``: the losses of a
    lossy mechanism (:func:`.losses.fill_losses`), else None; ``bearing_iterations`` (N,) the
    bearing friction's fixed-point iterations, on the llvm path the most over the sample's
    blocks (:mod:`.llvm.bearings`: each block converges its own joints).
    ``backend``: the path that ran, "llvm" or "numpy"; ``backend_note``: why "auto" took numpy.
    """

    motor: np.ndarray
    tau: np.ndarray
    joint: np.ndarray
    gear_t: np.ndarray
    gear_sep: np.ndarray
    gear_radial: np.ndarray
    gear_axial: np.ndarray
    residual: float | None = None
    motor_speed: np.ndarray | None = None   # (N, M) motor speeds A^T qd, rad/s (m/s linear)
    # Losses, None for a lossless mechanism (:func:`.losses.fill_losses`; W, N*m or N, W, count).
    gear_loss: np.ndarray | None = None
    joint_friction: np.ndarray | None = None
    joint_loss: np.ndarray | None = None
    bearing_iterations: np.ndarray | None = None
    backend: str | None = None
    backend_note: str | None = None


@lru_cache(maxsize=1)
def _blas_controller() -> ThreadpoolController:
    return ThreadpoolController()


def one_blas_thread():
    """Context limiting BLAS to one thread.  The controller (the scan of the loaded
    libraries) is built once: ``threadpool_limits`` rescans on every call, ~3 ms, as long
    as a 5,000-sample kernel solve."""
    return _blas_controller().limit(limits=1, user_api="blas")


def joint_space(an, q_ind, qd_ind=None, qdd_ind=None):
    """Every real joint's angle, rate, acceleration (N, J) from the independent ones."""
    S = an.S
    q = np.asarray(q_ind, float) @ S.T
    qd = None if qd_ind is None else np.asarray(qd_ind, float) @ S.T
    qdd = None if qdd_ind is None else np.asarray(qdd_ind, float) @ S.T
    return q, qd, qdd


class Solver:
    """Inverse dynamics of one analysed mechanism: owns the precomputed block plans.

    ``Solver(an).solve(q, qd, qdd)``: the block plans, the compiled solve kernel and the mass
    kernel's state (:mod:`.forward`) of one analysis; ``backend`` and ``jobs`` are the
    defaults of its calls.  :func:`solve` keeps one per analysis; the public
    :class:`gearcli.Solver` (:class:`.forward.Solver`) adds the forward-dynamics methods.
    """

    def __init__(self, an, backend: str = "auto", jobs: int | None = None, data_bodies: bool = False):
        self.an = an
        self.backend, self.jobs = backend, jobs
        self.data_bodies = data_bodies   # the kernel reads the links' inertial values at run time (solve_bodies)
        self.groups = unknown_groups(an)
        self.plans = make_plans(an)
        self._program = None
        self.kernel_problem: str | None = None
        self._llvm, self.llvm_problem = None, None      # llvm_problem: str | None
        self.samples_solved = 0          # by the block method, every backend ("auto"'s first-call rule)
        self.mass_kernel = (None, 0)     # (the mass kernel, or None; samples "auto" counted: .forward)

    def kernel_program(self):
        """The compiled kernel's program of this mechanism (:mod:`.llvm.program`), or None
        when the kernel cannot be used here (``self.kernel_problem`` says why); built on
        first use."""
        if self._program is None and self.kernel_problem is None:
            self._program = build_program(self.an, self.plans, data_bodies=self.data_bodies)
            if not self._program.covered:
                self.kernel_problem = (f"a block has more than {MAX_SIGNED} signed meshes, or a singular "
                                       "separating-force-free matrix")
        return self._program if self.kernel_problem is None else None

    def llvm_kernel(self):
        """The generated kernel of this mechanism (:class:`.llvm.driver.LlvmKernel`), or None
        when the llvm backend cannot be used here (``self.llvm_problem`` says why);
        compiled on first use and kept."""
        if self._llvm is None and self.llvm_available():
            from .llvm.driver import LlvmKernel  # noqa: PLC0415  (imports llvmlite)
            self._llvm = LlvmKernel(self.kernel_program(), self.an)
        return self._llvm

    def solve_bodies(self, an, q, qd, qdd, loads: dict | None = None) -> Result:
        """:meth:`solve` on the llvm path, one thread, with the masses, centres of mass and
        inertias of ``an``'s links: ``an`` is this solver's mechanism but for those values (a
        sweep's variant), solved by the one kernel compiled for all of them (a solver made
        with ``data_bodies=True``); the result is ``an``'s loads, to rounding."""
        if not self.data_bodies:
            raise ValueError("solve_bodies needs a Solver(an, data_bodies=True)")
        kernel = self.llvm_kernel()
        if kernel is None:
            raise ValueError(f"the llvm backend cannot solve this mechanism: {self.llvm_problem}")
        kernel.set_bodies(an)
        return self.solve(q, qd, qdd, loads=loads, backend="llvm", jobs=1)

    def llvm_available(self) -> bool:
        """True when the llvm backend can solve this mechanism (without compiling it)."""
        if self.llvm_problem is None and self._llvm is None:
            self.llvm_problem = self.kernel_problem if self.kernel_program() is None else llvm_refusal()
        return self.llvm_problem is None

    def compiled_llvm(self) -> bool:
        """True once the llvm kernel of this mechanism is compiled."""
        return self._llvm is not None

    def choice(self, method: str = "block", backend: str = "auto", n: int | None = None) -> Choice:
        """The path a solve of n samples (None: a large call) takes (``.path``: "llvm" or
        "numpy") and the note of why "auto" took numpy (:class:`.backends.Choice`)."""
        return choose(self, method, backend, n)

    def solve(self, q, qd, qdd, method: str = "block", chunk: int = DEFAULT_CHUNK,
              verify: bool = False, loads: dict | None = None, backend: str | None = None,
              jobs: int | None = None, out: Result | None = None, check_finite: bool = True,
              element_outputs: bool = True) -> Result:
        """See :func:`solve` (``backend``, ``jobs`` None: the solver's).  ``element_outputs``
        False leaves the worm pairs' and belts' numpy-computed outputs unfilled (a caller
        that reads ``tau`` alone: forward dynamics' settling, a stick-slip verge)."""
        backend = self.backend if backend is None else backend
        jobs = self.jobs if jobs is None else jobs
        q, qd, qdd = motion_arrays(self.an, q, qd, qdd, check_finite)
        if method not in ("block", "full"):
            raise ValueError(f"unknown method '{method}' (expected 'block' or 'full')")
        if chunk < 1:
            raise ValueError(f"chunk must be at least 1, got {chunk}")
        values = load_values(self.an.mech, q.shape[0], loads)
        if out is not None:
            check_out(self.an, q.shape[0], out, {"q": q, "qd": qd, "qdd": qdd,
                                                  **{f"load '{k}'": v for k, v in values.items()}})
        how = self.choice(method, backend, q.shape[0])
        if method == "block":
            self.samples_solved += max(q.shape[0], CALL_SAMPLES)
        if how.path != "numpy" and not verify:     # no BLAS call: the limit would cost ~30 us a call
            return self._by_kernel(how, q, qd, qdd, values, jobs, chunk, verify, out, element_outputs)
        # the operands are 3x3 to 48x48 matrices: BLAS threads only contend (2-3x slower
        # with a busy second core), so one BLAS thread, whatever the environment says
        with one_blas_thread():
            if how.path != "numpy":
                return self._by_kernel(how, q, qd, qdd, values, jobs, chunk, verify, out, element_outputs)
            res = self._by_numpy(q, qd, qdd, method, chunk, verify, values)
        fill_reducers(self.an, qd, res)
        if element_outputs:
            fill_worms(self.an, qd, res)
            fill_belts(self.an, qd, res)
        res.motor_speed = qd @ self.an.A
        if out is not None:
            copy_into(out, res)
            res = out
        res.backend, res.backend_note = how.path, how.note
        return res

    def _by_kernel(self, how, q, qd, qdd, values, jobs, chunk, verify, out=None, element_outputs=True) -> Result:
        arrays = result_arrays(self.an, q.shape[0], out)
        work, losses = work_arrays(q.shape[0], len(self.kernel_program().signed), out), {}
        sig = self.llvm_kernel().solve(self.an, q, qd, qdd, values, jobs, chunk, arrays, work, losses)
        res = Result(**arrays) if out is None else out
        res.residual, res.backend, res.backend_note = None, how.path, how.note
        fill_kernel_losses(res, arrays, losses)      # (a reducer's input torque and loss: the kernel's)
        if element_outputs:
            fill_worms(self.an, qd, res)              # a worm pair's outputs from N (numpy, both paths)
            fill_belts(self.an, qd, res)              # a belt's loss (numpy, both paths)
        if verify:
            x_all = _unknowns(self.an, res)
            worst = 0.0
            for s in range(0, q.shape[0], chunk):
                sl = slice(s, s + chunk)
                _, qd_all, kin, b = self._loads(q[sl], qd[sl], qdd[sl], {k: v[sl] for k, v in values.items()})
                subtract_bearing_friction(self.an, kin, b, qd_all, losses.get("bearing"), sl)
                worst = _worst(worst, residual(self.an, self.groups, Columns(self.an, kin), b,
                                               {k: v[sl] for k, v in x_all.items()}, {k: v[sl] for k, v in sig.items()}))
            res.residual = worst
        return res

    def _by_numpy(self, q, qd, qdd, method, chunk, verify, values) -> Result:
        parts = []
        for s in range(0, q.shape[0], chunk):
            sl = slice(s, s + chunk)
            try:
                parts.append(self._chunk(q[sl], qd[sl], qdd[sl], method, verify,
                                         {k: v[sl] for k, v in values.items()}))
            except SignError as exc:
                raise SignError(exc.sample + s, exc.meshes) from None
        if len(parts) == 1:
            res = parts[0]
        else:
            res = Result(*(np.concatenate([getattr(p, f) for p in parts]) for f in
                           ("motor", "tau", "joint", "gear_t", "gear_sep", "gear_radial", "gear_axial")))
            res.residual = _worst(*(p.residual for p in parts)) if verify else None
            for f in (f for f in LOSS_FIELDS if getattr(parts[0], f) is not None):
                setattr(res, f, np.concatenate([getattr(p, f) for p in parts]))
        return res

    def _loads(self, q_ind, qd_ind, qdd_ind, values):
        """Every joint's q, qd, the kinematics and right-hand sides (inertia, loads, friction)."""
        an = self.an
        q, qd, qdd = joint_space(an, q_ind, qd_ind, qdd_ind)
        kin = forward(an.mech, an.tree, q, qd, qdd, qd_ind=qd_ind)
        b = inertia_load(an, kin)
        subtract_external(b, external_wrenches(an, kin, values))
        subtract_joint_friction(an, kin, b, qd)
        subtract_reducer_drag(an, kin, b)
        subtract_belt_pretension(an, kin, b)
        return q, qd, kin, b

    def _chunk(self, q_ind, qd_ind, qdd_ind, method, verify, values) -> Result:
        an = self.an
        q, qd, kin, b = self._loads(q_ind, qd_ind, qdd_ind, values)
        cols = Columns(an, kin) if (method == "full" or verify) else None
        x, sig, b, bearing, res_it = solve_with_bearing_friction(an, kin, b, qd, (
            lambda rhs: solve_blocks(an, self.plans, kin, rhs, q)) if method == "block" else (
            lambda rhs: solve_full(an, cols, rhs)))
        res = _result(an, self.groups, x)
        fill_losses(an, kin, qd, res, bearing, res_it)
        if verify:
            res.residual = residual(an, self.groups, cols, b, x, sig)
        return res


_SOLVERS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def solver_for(an) -> Solver:
    """The :class:`Solver` of ``an`` (built on first use, kept while ``an`` lives)."""
    sol = _SOLVERS.get(an)
    if sol is None:
        if not hasattr(an, "schedule"):    # e.g. the Mechanism itself
            raise TypeError(f"expected the Analysis of gearcli.analyse(mechanism), got a {type(an).__name__}")
        sol = _SOLVERS[an] = Solver(an)
    return sol


def solve(an, q, qd, qdd, method: str = "block", chunk: int = DEFAULT_CHUNK, verify: bool = False,
          loads: dict | None = None, backend: str = "auto", jobs: int | None = None,
          out: Result | None = None, check_finite: bool = True, attach: dict | None = None) -> Result:
    """Inverse dynamics along a trajectory.

    Parameters
    ----------
    an : Analysis
        From :func:`gearcli.analyse`.
    q, qd, qdd : array_like, shape (N, dof) or (dof,)
        Independent joint angles (rad), rates (rad/s) and accelerations (rad/s^2), in the
        order of ``an.independent_names`` (m, m/s, m/s^2 for a prismatic joint).
    method : {"block", "full"}
        Block schedule (default) or one simultaneous solve of all equations.
    chunk : int
        Samples processed at once (bounds memory).
    verify : bool
        Also compute the worst Newton-Euler residual of any link (``Result.residual``,
        relative to the largest load of the sample) and check the sign of every t.
    loads : dict, optional
        ``{load name: array (N, 6) or (6,)}``: [fx, fy, fz, mx, my, mz] of an external load
        of ``an.mech.loads`` (N, N*m about the load point, in the load's frame: base or
        link), overriding the constant of the mechanism file; loads not given keep it.
    backend : {"auto", "llvm", "numpy"}
        "llvm": a kernel generated for this mechanism (:mod:`.llvm.kernel`; compiled on
        first use, 0.1-0.3 s for 5-10 links, kept with the analysis and on disk; method
        "block" only); "numpy": the array implementation (the reference); "auto" (default):
        llvm, except numpy for method "full", where llvmlite does not import or the kernel
        refuses the mechanism (a block with > 32 signed meshes), and by the first-call rule
        of :mod:`.backends` (``Result.backend`` says which ran, ``Result.backend_note`` why numpy).  Both give the
        same results to rounding.
    jobs : int, optional
        Threads a compiled kernel splits the samples over (contiguous ranges; results
        bitwise identical for any number); None: every usable core.  The numpy path uses one.
    out : Result, optional
        A result of this mechanism with as many samples (its arrays float64, C-ordered,
        writeable, apart from each other and from the inputs; e.g. the previous call's, when
        streaming a trajectory in equal blocks): its arrays are overwritten with this
        call's results (in place by the compiled kernels; copied by the numpy path) and
        ``out`` itself is returned (if the call raises, ``out``'s contents are undefined).
        Faster for large calls: no fresh pages for the operating system to zero, the
        cost that does not scale with threads.
    check_finite : bool
        Refuse a NaN or infinite ``q``, ``qd`` or ``qdd`` (default; ValueError naming the
        sample and joint); False skips the check, for inputs already checked (:mod:`.inputs`).
    attach : dict, optional
        ``{payload name: (N,) of 0 and 1}``: where each payload of ``an.mech.payloads`` is
        carried (a payload not given is not); the samples are solved in groups by the set
        attached (:mod:`.payloads`; ``out`` is not used then).

    Raises
    ------
    SignError
        when no sign pattern of the tooth forces is consistent at some sample (named).
    ValueError
        for bad shapes (of ``out`` too), a non-finite motion value, an unknown load name or a
        load value that is not finite, an unknown
        backend, or backend "llvm" where it is unavailable.
    """
    if attach:
        from .payloads import attach_flags, by_groups, loads_at  # noqa: PLC0415
        q, qd, qdd = (np.atleast_2d(np.asarray(v, float)) for v in (q, qd, qdd))
        n = q.shape[0]
        flags = attach_flags(an, attach, n)

        def run(a, rows):
            part = loads_at(loads, rows)
            return solver_for(a).solve(q[rows], qd[rows], qdd[rows], method=method, chunk=chunk, verify=verify,
                                       loads=part or None, backend=backend, jobs=jobs, check_finite=check_finite)
        return by_groups(an, flags, run, n)
    return solver_for(an).solve(q, qd, qdd, method=method, chunk=chunk, verify=verify, loads=loads,
                                backend=backend, jobs=jobs, out=out, check_finite=check_finite)


def _worst(*values: float) -> float:
    """The largest value, NaN if any is NaN (Python's max would keep 0.0 against a NaN)."""
    return float(np.max(values))


def residual(an, groups, cols, b, x_all, sig) -> float:
    """Worst relative Newton-Euler residual over links and samples, and worst relative
    disagreement of a solved t with the sign used for its separating force."""
    worst = 0.0
    for L in an.tree.moving:
        tot = -b[L]
        for g in groups:
            if L in g.links:
                C = cols.group(g, L, sig.get((g.kind, g.index), 1.0))
                tot = tot + np.einsum("nij,nj->ni", C, x_all[(g.kind, g.index)])
        scale = 1.0 + np.max(np.abs(b[L]), axis=1)
        worst = _worst(worst, float(np.max(np.abs(tot).max(axis=1) / scale)))
    signed = [(g.kind, g.index) for g in groups if is_geared(an, g)]
    if signed:
        t = np.column_stack([x_all[k][:, 0] for k in signed])
        signs = np.column_stack([np.broadcast_to(sig.get(k, 1.0), t.shape[:1]) for k in signed])
        scale = 1.0 + np.max(np.abs(np.concatenate([b[L] for L in an.tree.moving], axis=1)), axis=1)
        worst = _worst(worst, sign_violation(t, signs, scale))
    return worst


def _unknowns(an, res: Result) -> dict:
    """{(kind, index): (N, size)} every unknown back from a result (the inverse of
    :func:`_result`: joint reactions in the child's basis without the axis component)."""
    x = {("motor", i): res.motor[:, i:i + 1] for i in range(res.motor.shape[1])}
    x.update({("mesh", ci): res.gear_t[:, ci:ci + 1] for ci in range(res.gear_t.shape[1])})
    for ji, jt in enumerate(an.mech.joints):
        x[("joint", ji)] = res.joint[:, ji, _reaction_axes(jt)]
    return x


def _reaction_axes(jt) -> list[int]:
    """The components [fx, fy, fz, mx, my, mz] of a joint's reaction that are unknowns (not
    along / about its own axis)."""
    return [0, 1, 3, 4, 5] if jt.type == "prismatic" else [0, 1, 2, 3, 4]


def _result(an, groups, x_all) -> Result:
    mech = an.mech
    N = next(iter(x_all.values())).shape[0]
    J, G, M = len(mech.joints), len(an.circuits), len(an.motor_links)
    joint = np.zeros((N, J, 6))
    for ji, jt in enumerate(mech.joints):
        joint[:, ji, _reaction_axes(jt)] = x_all[("joint", ji)]
    motor = np.column_stack([x_all[("motor", i)][:, 0] for i in range(M)]) if M else np.zeros((N, 0))
    gt, sep, rad, ax = np.zeros((N, G)), np.zeros((N, G)), np.zeros((N, G, 2)), np.zeros((N, G, 2))
    for ci in range(G):
        gt[:, ci] = x_all[("mesh", ci)][:, 0]
    k = gear_outputs(an)            # g = t (ut + a) + s us on j, -g on k (s = |t| tan phi_t)
    geo = np.flatnonzero(k.geometry == 1.0)
    t = gt[:, geo]
    s = sep[:, geo] = np.abs(t) * k.tan_t[geo]
    rad[:, geo, 0] = t * k.t_rad_j[geo] + s * k.sep_rad_j[geo]
    ax[:, geo, 0] = t * k.t_ax_j[geo] + s * k.sep_ax_j[geo]
    rad[:, geo, 1] = -(t * k.t_rad_k[geo] + s * k.sep_rad_k[geo])
    ax[:, geo, 1] = -(t * k.t_ax_k[geo] + s * k.sep_ax_k[geo])
    tau = motor @ an.A.T
    return Result(motor, tau, joint, gt, sep, rad, ax)
