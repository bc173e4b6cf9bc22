"""Run a manifest's checks: one job per (case, trajectory), serially, in processes or on Dask.

A job solves one trajectory and reduces it to the partial sums of every check of its case
(:func:`gearcli.design.evaluate.partials`); the partials are merged per case in trajectory
order (:func:`gearcli.design.evaluate.combine`).  Jobs carry only paths and flags, so they
run the same in this process, in a process pool (``jobs`` > 1) or on a Dask cluster
(``dask_address``), and the results are identical whichever way they ran.
"""
from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..design.checks import build_checks
from ..design.evaluate import Samples, Verdict, combine, partials, profile_equivalent_load, profile_rates, signal
from ..design.sizing import inertia_columns
from ..dynamics.solve import solve
from ..errors import Collector, GearcliError
from ..io.trajectory import count_rows, forget_rows, read_trajectory
from ..dynamics.losses import check_belts
from ..pipeline import at_samples
from ..report.columns import LazyColumns
from .heap import keep_freed_memory
from .manifest import Case, Manifest, case_analysis


@dataclass(frozen=True)
class Job:
    """One trajectory of one case (picklable: paths and flags only)."""

    case: int
    trajectory: int
    mechanism: str
    path: str
    degrees: bool
    req: object   # design.checks.Requirements
    backend: str = "auto"   # the path the whole command's work chose (:func:`command_backends`)


STREAM = 1 << 16
"""Samples verify solves at once (a multiple of the kernel's 256-sample warm-start runs, so
the results are those of one call): of each part only the columns its checks read are kept."""


def solve_samples(an, traj_path, degrees: bool, threads: int | None = None, backend: str = "auto",
                  checks=None, tr=None, solve_with=None, inertia_with=None) -> Samples:
    """Solve a trajectory file: times, every output column (each computed when a check
    first reads it: :class:`~gearcli.report.columns.LazyColumns`), and every real joint's
    rate; ``threads``: the solver's threads (None: every core).  With ``checks``, a long
    trajectory is solved :data:`STREAM` samples at a time, the checks that reduce to
    extremes and sums evaluated part by part, and only the columns the others read kept
    (:func:`_streamed`; 1e6 samples of the rated arm peak at 0.35-0.39 GB, where they took
    1.48 GB, then 0.63 GB; its solve takes 0.25 GB).  ``tr``: the trajectory already read
    (a sweep solves the same one for every variant); ``solve_with(part)``: the solve of a
    trajectory part (a sweep's data kernel), instead of :func:`~gearcli.dynamics.solve.solve`;
    ``inertia_with(q, attach)``: the motors' inertia columns likewise, instead of
    :func:`~gearcli.design.sizing.inertia_columns` on ``backend``."""
    if tr is None:
        tr = read_trajectory(traj_path, an.independent_names, degrees=degrees, linear=an.prismatic_independent,
                             loads=an.mech.loads, payloads=[p.name for p in an.mech.payloads])
    solve_with = solve_with or (lambda p: solve(an, p.q, p.qd, p.qdd, loads=p.loads, jobs=threads, check_finite=False,
                                                attach=p.attach, backend=backend))   # (read checked the values)
    # servo sizing: inertia at the rated motors (numpy where the solve was told numpy: a sweep's variant)
    inertia_with = inertia_with or (lambda q, attach: inertia_columns(an, q, attach,
                                                                      "numpy" if backend == "numpy" else "auto"))
    if checks is not None and len(tr.t) > STREAM:
        return _streamed(an, traj_path, tr, backend, checks, solve_with, inertia_with)
    with at_samples(traj_path, tr):
        res = solve_with(tr)
        check_belts(an, res)
    cols = LazyColumns(an, res, tr.t)
    cols.update(inertia_with(tr.q, tr.attach))
    return Samples(tr.t, cols, tr.qd @ an.S.T, backend_text(res))


def _read_by(checks, an, part, cols) -> list[str]:
    """The columns ``checks`` read (their signals looked up on one part's lazy columns)."""
    probe = Samples(part.t, cols, part.qd @ an.S.T)
    for ch in checks:
        signal(ch, probe, an.mech)
    return list(cols)


def _streamed(an, traj_path, tr, backend, checks, solve_with, inertia_with) -> Samples:
    """:func:`solve_samples` of ``tr`` a :data:`STREAM` of samples at a time.  The checks
    whose partials merge (:func:`~gearcli.design.evaluate.mergeable`: extremes and sums) are
    evaluated part by part, each part with the last sample of the one before (the trapezoid
    weights then add up to the whole's), and merged into ``Samples.merged``; only the
    columns the others read (a gear's fatigue, a running RMS, a cycle's energy) are kept for
    the whole trajectory.  1e6 samples of the rated arm keep 5 columns instead of 34."""
    from ..design.evaluate import merge_partials, mergeable  # noqa: PLC0415
    from ..pipeline import progress_slices  # noqa: PLC0415
    each = [i for i, ch in enumerate(checks) if mergeable(ch)]
    whole = [ch for ch in checks if not mergeable(ch)]
    kept, names, how, at, prev, parts = None, None, "", 0, None, []
    for part in progress_slices(tr, STREAM):
        with at_samples(traj_path, part):
            res = solve_with(part)
            check_belts(an, res)
        cols = LazyColumns(an, res, part.t)
        cols.update(inertia_with(part.q, part.attach))
        if kept is None:
            kept = {k: np.empty(len(tr.t), cols[k].dtype) for k in _read_by(whole, an, part, cols)}
            names, how = _read_by([checks[i] for i in each], an, part, cols), backend_text(res)
        for k, v in kept.items():
            v[at:at + len(part.t)] = cols[k]
        at += len(part.t)
        here = ({k: np.asarray(cols[k]) for k in names}, part.t, part.qd @ an.S.T)
        if prev is not None:
            here = ({k: np.concatenate([prev[0][k], v]) for k, v in here[0].items()},
                    np.concatenate([prev[1], here[1]]), np.concatenate([prev[2], here[2]]))
        parts.append(partials([checks[i] for i in each], Samples(here[1], here[0], here[2]), an.mech))
        prev = ({k: v[-1:] for k, v in here[0].items()}, here[1][-1:], here[2][-1:])
        del res, cols, here
    merged = {i: merge_partials(checks[i], [p[k] for p in parts]) for k, i in enumerate(each)}
    return Samples(tr.t, kept, tr.qd @ an.S.T, how, merged)


def backend_text(res) -> str:
    """The solver path of a :class:`~gearcli.dynamics.solve.Result`: "llvm", "numpy", or
    "numpy (auto: why)" when backend "auto" took numpy."""
    return res.backend + (f" (auto: {res.backend_note})" if res.backend_note else "")


def run_job(job: Job, threads: int | None = None) -> tuple[list[tuple], str]:
    """(the partials of every check of the job's case on the job's trajectory, the solver
    path that ran, :func:`backend_text`) (``threads``: the solver's threads; the pools give
    each worker its share of the cores)."""
    if _rows(job.path) <= STREAM:   # no page faults for every new array (:mod:`.heap`); not for a
        keep_freed_memory()          # long trajectory, whose freed arrays would stay as resident memory
    an = case_analysis(job.mechanism)
    checks = build_checks(an, job.req, Collector(job.mechanism))
    samples = solve_samples(an, job.path, job.degrees, threads, job.backend, checks)
    return partials(checks, samples, an.mech), samples.backend


def jobs_of(manifest: Manifest) -> list[Job]:
    backends = command_backends(manifest)
    return [Job(ci, ti, str(c.mechanism), str(tp), c.degrees, c.req, backends[str(c.mechanism)])
            for ci, c in enumerate(manifest.cases) for ti, tp in enumerate(c.trajectories)]


def command_backends(manifest: Manifest) -> dict[str, str]:
    """{mechanism: the backend of its solves}: "auto"'s first-call rule applied to the whole
    command's work, every sample of every trajectory of that mechanism in the manifest
    (``verify`` knows them all before it starts: 20 trajectories of 2,201 samples are one
    compile's worth, not 20 small first calls sent to numpy).  The path chosen is passed
    to every job, so the report's backend line says "llvm" or why numpy."""
    from ..dynamics.solve import solver_for      # noqa: PLC0415
    rows: dict[str, int] = {}
    for c in manifest.cases:
        for tp in c.trajectories:
            rows[str(c.mechanism)] = rows.get(str(c.mechanism), 0) + _rows(tp)
    out = {}
    for mech, n in rows.items():
        how = solver_for(case_analysis(mech)).choice("block", "auto", max(n, 1))
        out[mech] = "llvm" if how.path == "llvm" else "auto"
    return out


@dataclass(frozen=True)
class CaseResult:
    case: Case
    verdicts: tuple[Verdict, ...]
    backend: str = ""     # the solver paths of its trajectories (backend_text), distinct ones joined by "; "


def run_manifest(manifest: Manifest, jobs: int | None = None, dask_address: str | None = None,
                 progress=None) -> list[CaseResult]:
    """Run every job and merge the partials; ``progress()`` is called after each job.

    ``jobs``: worker processes (None: the number of cores; 1: this process);
    ``dask_address``: the scheduler of an existing dask.distributed cluster (then ``jobs``
    is ignored).
    """
    todo = jobs_of(manifest)
    try:
        if dask_address is not None:
            results = _run_dask(todo, dask_address, progress)
        else:
            results = _run_local(todo, jobs or os.cpu_count() or 1, progress)
    finally:
        forget_rows()       # rows the manifest's check kept for jobs (taken by the serial ones)
    out = []
    for ci, case in enumerate(manifest.cases):
        parts = [results[(ci, ti)][0] for ti in range(len(case.trajectories))]
        backend = "; ".join(dict.fromkeys(results[(ci, ti)][1] for ti in range(len(case.trajectories))))
        spans = [p[0][6] if p else 0.0 for p in parts]
        rates = profile_rates(case.shares or (None,) * len(parts), spans, case.req.cycles_per_hour,
                              case.req.service_life_h)
        verdicts = [combine(ch, [p[k] for p in parts], rates) for k, ch in enumerate(case.checks)]
        out.append(CaseResult(case, tuple(verdicts), backend))
    return out


def _run_local(todo: list[Job], workers: int, progress) -> dict:
    results = {}
    if workers <= 1 or len(todo) <= 1:
        for job in todo:
            results[(job.case, job.trajectory)] = run_job(job)
            if progress:
                progress()
        return results
    workers = min(workers, len(todo))
    share = max(1, (os.cpu_count() or 1) // workers)    # no more solver threads than cores
    with ProcessPoolExecutor(max_workers=workers) as pool:
        futures = {pool.submit(run_job, job, share): job for job in todo}
        for fut in as_completed(futures):
            job = futures[fut]
            results[(job.case, job.trajectory)] = fut.result()
            if progress:
                progress()
    return results


DASK_TIMEOUT = 10.0
"""s to wait for the Dask scheduler before reporting it unreachable."""


def dask_client(address: str):
    try:
        from dask.distributed import Client  # noqa: PLC0415 (optional dependency)
    except ImportError:
        raise GearcliError("--dask needs dask.distributed: pip install 'gearcli[design]'") from None
    try:
        return Client(address, set_as_default=False, timeout=DASK_TIMEOUT)
    except (OSError, TimeoutError, ValueError, TypeError) as exc:
        raise GearcliError(f"--dask: cannot connect to the scheduler at '{address}': "
                           f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None


def _run_dask(todo: list[Job], address: str, progress) -> dict:
    from dask.distributed import as_completed as dask_completed  # noqa: PLC0415 (optional)

    results = {}
    with dask_client(address) as client:
        # one solver thread per task: a Dask worker already runs tasks in its own threads
        futures = {client.submit(run_job, job, 1, pure=False): job for job in todo}
        for fut in dask_completed(list(futures), loop=client.loop):
            job = futures[fut]
            results[(job.case, job.trajectory)] = fut.result()
            if progress:
                progress()
    return results


def profile_plot(result: CaseResult, verdict: Verdict, path, title: str):
    """The plot of a life or fatigue check over every trajectory of its case (the check's
    partials recomputed per trajectory): bearing loads with their equivalent loads, or the
    S-N curve with the counted cycles (:mod:`gearcli.report.check_plots`); returns ``path``."""
    from ..design import bearings as B  # noqa: PLC0415
    from ..design import fatigue as F  # noqa: PLC0415
    from ..report.check_plots import plot_life, plot_sn  # noqa: PLC0415

    ch, case = verdict.check, result.case
    an = case_analysis(case.mechanism)
    samples = [solve_samples(an, tp, case.degrees) for tp in case.trajectories]
    parts = [partials([ch], s, an.mech)[0] for s in samples]
    rates = profile_rates(case.shares or (None,) * len(samples), [p[6] for p in parts], case.req.cycles_per_hour,
                          case.req.service_life_h)
    if ch.kind == "reducer_life":
        from ..design.evaluate import reducer_duty  # noqa: PLC0415
        from ..report.check_plots import plot_reducer_life  # noqa: PLC0415
        row = np.asarray(ch.extra["row"])
        traces = [(Path(tp).stem, s.t, signal(ch, s, an.mech), np.abs(s.rates @ row))
                  for tp, s in zip(case.trajectories, samples)]
        T_av, _ = reducer_duty(ch, parts, rates)
        plot_reducer_life(traces, T_av, verdict.signal_limit, verdict.value, ch.limit, ch.extra["rating"].life_basis,
                          ch.extra["rating"], path, title)
        return path
    if ch.kind == "life":
        traces = [(Path(tp).stem, s.t, signal(ch, s, an.mech), p[5]) for tp, s, p in zip(case.trajectories, samples, parts)]
        plot_life(traces, profile_equivalent_load(ch, parts, rates), verdict.signal_limit, path, title)
        return path
    hours = [ch.limit * (r or 0.0) for r in rates]          # repetitions of each trajectory in the required life
    sig = [signal(ch, s, an.mech) for s in samples]
    counted = [F.rainflow_peaks(x) for x in sig]
    peaks = np.concatenate(counted)
    passes = None
    if ch.extra.get("passes") is not None:
        ji, factor_z = ch.extra["passes"]
        n = np.concatenate([h * B.revolutions(s.rates[:, ji], s.t) * factor_z for h, s in zip(hours, samples)])
        x = np.concatenate(sig)
        order = np.argsort(x)[::-1]
        passes = (np.cumsum(n[order]), x[order])
    total = sum(h * len(c) for h, c in zip(hours, counted))
    top = max([total] + ([float(passes[0][-1])] if passes is not None and passes[0].size else []))
    N = np.logspace(2, max(12.0, np.log10(max(top, 1.0)) + 1), 200)
    factor = F.bending_cycle_factor if ch.signal[0] == "bending" else F.pitting_cycle_factor
    plot_sn(N, ch.rating * factor(N), peaks, max(total, 1.0), path, title,
            f"{'root bending' if ch.signal[0] == 'bending' else 'contact'} stress [Pa]", passes)
    return path


def worst_samples(result: CaseResult, verdict: Verdict) -> tuple[np.ndarray, np.ndarray]:
    """Time and signal of a check along its worst trajectory (for plots)."""
    an = case_analysis(result.case.mechanism)
    s = solve_samples(an, result.case.trajectories[verdict.trajectory], result.case.degrees)
    return s.t, signal(verdict.check, s, an.mech)



def _rows(path) -> int:
    """Data rows of a trajectory (0 when it cannot be read: the job then says why)."""
    try:
        return count_rows(path)
    except OSError:
        return 0
