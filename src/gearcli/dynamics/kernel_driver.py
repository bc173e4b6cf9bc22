"""Running the compiled kernel (:mod:`.kernel`) over a trajectory, on one or more threads.

Imported only when the kernel backend is used (it imports numba).  The samples are split
over threads by :mod:`.jobs` (the kernel releases the GIL: ``nogil``); the results are
bitwise identical for any number of jobs.
"""
from __future__ import annotations

import numpy as np

from .jobs import job_ranges, run_parts, sign_error, threads_for, usable_cores  # noqa: F401  (re-exported)
from .kernel import run
from .kernel_program import Program, load_arrays
from .result_arrays import FIELDS as OUTPUTS


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


def kernel_solve(prog: Program, an, q, qd, qdd, values: dict, jobs: int | None, chunk: int, out: dict,
                 work: tuple) -> dict:
    """The loads of every sample, by the kernel, into ``out``.

    Parameters
    ----------
    q, qd, qdd : (N, dof) independent joint values.  values : {load name: (N, 6) or
    broadcast (1 row)} (:func:`.external.load_values`).  chunk : the numpy path's chunk
    (the sample a :class:`SignError` names is the one that path would name).  out :
    {name: array} the fields of :class:`~.solve.Result` (``OUTPUTS``, shaped as there,
    C-ordered float64), written.  work : (signs (N, max(1, signed meshes)), fail (N,)
    int64) work arrays (:func:`.result_arrays.work_arrays`).

    Returns
    -------
    {(kind, index): (N,) sign of t used}.
    """
    n = q.shape[0]
    SG, fail = work
    outs = tuple(out[k].reshape(n, int(np.prod(out[k].shape[1:]))) for k in OUTPUTS) + (SG, fail)
    ldrec, ldflt, vals = load_arrays(an, values, n)
    args = (prog.ints, prog.flts, ldrec, ldflt, vals, *(np.ascontiguousarray(a, float) for a in (q, qd, qdd)))
    failed = run_parts(lambda s, e, scr: run(*args, s, e, outs, scr), job_ranges(n, jobs), threads_for(n, jobs),
                       lambda: scratch(prog))
    if failed:
        raise sign_error(prog.names, fail, chunk)
    return {k: SG[:, i] for i, k in enumerate(prog.signed)}
