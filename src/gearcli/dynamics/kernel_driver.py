"""Running the compiled kernel (:mod:`.kernel`) over a trajectory, on one or more threads.

Imported only when the kernel backend is used (it imports numba).  The samples are split
over threads by :mod:`.jobs` (the kernel releases the GIL: ``nogil``); the results are
bitwise identical for any number of jobs.
"""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .jobs import job_ranges, sign_error, threads_for, usable_cores  # noqa: F401  (re-exported)
from .kernel import run
from .kernel_program import Program, load_arrays


def scratch(prog: Program) -> tuple:
    """Per-thread work arrays of :func:`.kernel.run` (R, o, w, dw, a, rhs per link; cos,
    sin, q, qd, qdd per joint; block right-hand side, solution, signs and matrix; the
    solution row)."""
    nL, J = prog.flts[1].shape[0], prog.flts[2].shape[0]
    brec = prog.ints[1]
    nr = max([6] + [6 * int(b) for b in brec[:, 2]])
    nx = max([nr] + [int(b) for b in brec[:, 3]])
    R = np.zeros((nL, 3, 3))
    R[:] = np.eye(3)                          # the base stays at rest
    return (R, np.zeros((nL, 3)), np.zeros((nL, 3)), np.zeros((nL, 3)), np.zeros((nL, 3)),
            np.zeros((nL, 6)), np.zeros((J, 2)), np.zeros(J), np.zeros(J), np.zeros(J),
            np.zeros(nx), np.zeros(nx), np.ones(max([1] + [int(b) for b in brec[:, 5]])), np.zeros((nr, nx)),
            np.zeros(prog.ncols))


OUTPUTS = ("motor", "tau", "joint", "gear_t", "gear_sep", "gear_radial", "gear_axial", "motor_speed")


def kernel_solve(prog: Program, an, q, qd, qdd, values: dict, jobs: int | None, chunk: int):
    """The loads of every sample, by the kernel.

    Parameters
    ----------
    q, qd, qdd : (N, dof) independent joint values.  values : {load name: (N, 6) or
    broadcast (1 row)} (:func:`.external.load_values`).  chunk : the numpy path's chunk
    (the sample a :class:`SignError` names is the one that path would name).

    Returns
    -------
    ({name: array} the fields of :class:`~.solve.Result` (``OUTPUTS``, shaped as there),
    {(kind, index): (N,) sign of t}).
    """
    n, dof = q.shape
    J, G, M = len(an.mech.joints), len(an.circuits), len(an.motor_links)
    out = {"motor": np.empty((n, M)), "tau": np.empty((n, dof)), "joint": np.empty((n, J, 6)),
           "gear_t": np.empty((n, G)), "gear_sep": np.empty((n, G)), "gear_radial": np.empty((n, G, 2)),
           "gear_axial": np.empty((n, G, 2)), "motor_speed": np.empty((n, M))}
    SG = np.empty((n, len(prog.signed)))
    fail = np.full(n, -1, np.int64)
    outs = tuple(a.reshape(n, int(np.prod(a.shape[1:]))) for a in out.values()) + (SG, fail)
    ldrec, ldflt, vals = load_arrays(an, values, n)
    args = (prog.ints, prog.flts, ldrec, ldflt, vals, *(np.ascontiguousarray(a, float) for a in (q, qd, qdd)))
    ranges = job_ranges(n, jobs)
    if len(ranges) == 1:
        run(*args, 0, n, outs, scratch(prog))
    else:
        with ThreadPoolExecutor(threads_for(n, jobs)) as pool:
            for f in [pool.submit(run, *args, s, e, outs, scratch(prog)) for s, e in ranges]:
                f.result()
    if np.any(fail >= 0):
        raise sign_error(prog.names, fail, chunk)
    return out, {k: SG[:, i] for i, k in enumerate(prog.signed)}
