"""Running the compiled kernel (:mod:`.kernel`) over a trajectory, on one or more threads.

Imported only when the kernel backend is used (it imports numba).  The samples are split
into contiguous ranges that the threads take in turn; the kernel releases the GIL
(``nogil``) and each sample's arithmetic does not depend on the split, so the results are
bitwise identical for any number of jobs.
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .kernel import run
from .kernel_program import Program, load_arrays
from .signs import SignError

MIN_SAMPLES_PER_JOB = 2_000   # fewer samples per thread: the thread costs more than it saves


def usable_cores() -> int:
    """Cores this process may run on (its CPU affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:               # not on Linux
        return max(1, os.cpu_count() or 1)


def threads_for(n: int, jobs: int | None) -> int:
    """Threads for n samples (``jobs`` None: every usable core; at least
    MIN_SAMPLES_PER_JOB samples a thread)."""
    jobs = usable_cores() if jobs is None else int(jobs)
    if jobs < 1:
        raise ValueError(f"jobs must be at least 1, got {jobs}")
    return max(1, min(jobs, n // MIN_SAMPLES_PER_JOB))


def job_ranges(n: int, jobs: int | None) -> list[tuple[int, int]]:
    """Contiguous (start, stop) sample ranges the threads take in turn: 8 a thread (at
    least MIN_SAMPLES_PER_JOB samples each), so that a thread slowed by a busy core takes
    fewer of them instead of making the others wait (``jobs`` None: every core)."""
    threads = threads_for(n, jobs)
    if threads == 1:
        return [(0, n)]
    parts = max(threads, min(8 * threads, n // MIN_SAMPLES_PER_JOB))
    cuts = [round(i * n / parts) for i in range(parts + 1)]
    return [(cuts[i], cuts[i + 1]) for i in range(parts)]


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
        raise _sign_error(prog, fail, chunk)
    return out, {k: SG[:, i] for i, k in enumerate(prog.signed)}


def _sign_error(prog: Program, fail: np.ndarray, chunk: int) -> SignError:
    """The error the numpy path raises: in the first chunk with a failure, the first sample
    failing at the earliest block that fails (that path stops at that block)."""
    first = int(np.flatnonzero(fail >= 0)[0])
    c0 = first - first % chunk
    part = fail[c0:c0 + chunk]
    block = int(part[part >= 0].min())
    return SignError(c0 + int(np.flatnonzero(part == block)[0]), prog.names[block])
