"""File to file: mechanism + trajectory CSV -> loads CSV and summary (``gearcli solve``).

Data flow: :func:`~gearcli.io.load_mechanism` -> :func:`~gearcli.analysis.graph.analyse` ->
:class:`~gearcli.io.trajectory.TrajectoryReader` (chunks) -> :func:`~gearcli.dynamics.solve` ->
:mod:`~gearcli.report`.  Memory is bounded by the chunk size, whatever the file length.
"""
from __future__ import annotations

import math
import queue
import sys
import threading
import warnings
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .dynamics.backends import BACKENDS, Choice
from .dynamics.solve import solve, solver_for
from .analysis.graph import Analysis
from .dynamics.bearing_friction import BearingFrictionError
from .dynamics.losses import SlackError, check_belts
from .dynamics.determinacy import analyse, load_analysed
from .dynamics.signs import SignError
from . import __version__
from .errors import GearcliError, Issue, TrajectoryError
from .io.output import OutputError, atomic_output, output_target
from .io.trajectory import Trajectory, TrajectoryReader
from .report.loss_summary import LossSummary, lossless_twin
from .report.columns import Summary, column_names, column_units, first_non_finite, table
from .report.table_files import CONVENTIONS, FORMATS, extension, format_of, open_table
from .report.unit_warnings import RateWatch

PREFETCH_CHUNKS = 8
"""Chunks the reading thread may be ahead of the solve: they are read and splined while the
first solve compiles the kernel (~0.25 s for the Bendix wrist); ~2 MB each of 20,000 samples."""

VERIFY_TOLERANCE = 1e-8
"""``--verify`` fails when the worst relative Newton-Euler residual exceeds this (or is
not finite); a sound solve gives ~1e-15."""


@dataclass
class SolveReport:
    """What :func:`solve_file` did: the analysis, the number of samples, the load summary,
    the worst residual (with ``verify``) and the output path (None: stdout or nothing)."""

    analysis: Analysis = field(repr=False)   # the whole mechanism: not in repr
    samples: int
    summary: Summary
    residual: float | None
    output: Path | None
    losses: LossSummary | None = None   # a mechanism with losses: energy lost, line efficiencies
    warnings: list[Issue] = field(default_factory=list)   # implausible rates (report.unit_warnings.RateWatch)
    backend: Choice = Choice("numpy")     # the path that solved every chunk, and why "auto" took numpy

    def backend_line(self) -> str:
        """The summary's line naming the backend that ran (and why "auto" took numpy)."""
        how = self.backend
        return f"Backend: {how.path}" + (f" (auto: {how.note})" if how.note else "")

    def notices(self) -> list[str]:
        """The stderr notice of a run that "auto" solved with numpy because the kernel cannot
        run here (one line; none for the first-call rule, which the summary states)."""
        how = self.backend
        return [f"notice: solved with numpy, not the llvm kernel: {how.note}"] if how.fallback else []


def check_solve_options(an: Analysis, method: str, backend: str) -> Analysis:
    """``an``, or :class:`GearcliError` for a bad ``--method`` or ``--backend`` (the kernel
    must be available for the mechanism when asked for)."""
    if method not in ("block", "full"):
        raise GearcliError(f"--method: expected 'block' or 'full', got '{method}'")
    if backend not in BACKENDS:
        raise GearcliError(f"--backend: expected one of {', '.join(BACKENDS)}, got '{backend}'")
    try:
        solver_for(an).choice(method, backend)
    except ValueError as exc:
        raise GearcliError(f"--backend: {exc}") from None
    return an


def solve_file(mech_path, traj_path, out_path=None, *, degrees: bool = False, method: str = "block",
               verify: bool = False, chunk: int = 20_000, progress=None, analysis: Analysis | None = None,
               precision: int | None = None, backend: str = "auto", jobs: int | None = None,
               strict: bool = False) -> SolveReport:
    """Solve a trajectory file and write the loads table (see :mod:`gearcli.report`).

    The format of ``out_path`` follows its extension (:mod:`gearcli.report.table_files`:
    ``.csv`` or none, ``.parquet``, ``.feather``, ``.npz``; another one is an
    :class:`~gearcli.io.output.OutputError`); ``precision`` (1..17 significant digits,
    default 9) applies to CSV only.  ``progress(total=None, advance=None)`` is called with
    ``total`` once (number of samples) and with ``advance`` after each chunk.  The output
    is written atomically (:func:`gearcli.io.output.atomic_output`: nothing is written
    unless everything succeeded); ``out_path="-"`` writes CSV to stdout after the whole
    trajectory was read and checked, streaming the loads (a non-finite load or a failed
    ``verify`` found while streaming stops the output with an error); ``None`` writes
    nothing (summary only).

    Every output sample is checked finite before it is written
    (:class:`~gearcli.errors.TrajectoryError` naming the first bad sample and column);
    with ``verify`` the worst residual of every chunk must be finite and at most
    :data:`VERIFY_TOLERANCE`.  ``backend`` and ``jobs`` as in :func:`~gearcli.dynamics.solve.solve`;
    the backend is chosen once for the whole trajectory (its row count; "auto"'s first-call
    rule, :mod:`gearcli.dynamics.backends`) and every chunk is solved by it: the report's
    ``backend`` and ``backend_note`` say which and, when "auto" took numpy, why.

    Implausible joint angles, joint rates and motor speeds (a trajectory in degrees read as
    radians: :class:`~gearcli.report.unit_warnings.RateWatch`) are listed in the report's
    ``warnings``; with ``strict`` the first one is a
    :class:`~gearcli.report.unit_warnings.StrictError` (nothing written).
    """
    fmt = output_format(out_path, (mech_path, traj_path), precision)   # refuse a bad -o before any work
    an = analysis or load_analysed(mech_path)
    reader = TrajectoryReader(traj_path, an.independent_names, degrees=degrees, chunk=chunk,
                              linear=an.prismatic_independent, loads=an.mech.loads,
                              payloads=[p.name for p in an.mech.payloads])
    to_stdout = out_path is not None and str(out_path) == "-"
    rows = reader.check() if to_stdout or fmt == "npz" else reader.count()   # exact count first
    watch = RateWatch(reader, an, strict)
    if progress is not None:
        progress(total=rows)
    summary, how = Summary.for_mechanism(an), solver_for(an).choice(method, backend, rows)   # one backend a run
    losses = LossSummary.for_mechanism(an) if an.mech.has_losses else None
    twin = analyse(lossless_twin(an.mech)) if losses is not None else None
    names = column_names(an)
    worst, n = 0.0, 0

    def solve_chunks(table_file):
        # one warnings scope around the reading thread's lifetime: catch_warnings is process-wide,
        # so the reader's own (in derivatives) must nest inside it, never interleave with another
        with warnings.catch_warnings(), Prefetch(reader, depth=PREFETCH_CHUNKS) as parts:
            warnings.simplefilter("ignore")
            for part in parts:
                tabs, residual = [], 0.0
                for sub in progress_slices(part, step):     # the part's solve in steps the bar shows
                    with np.errstate(all="ignore"), at_samples(reader.file, sub):
                        res = solve(an, sub.q, sub.qd, sub.qdd, method=method, chunk=chunk, verify=verify,
                                    loads=sub.loads, backend=how.path, jobs=jobs, check_finite=False,  # read checked
                                    attach=sub.attach)
                        check_belts(an, res)
                        tabs.append(table(an, sub.t, res))
                        if losses is not None:
                            losses.add(an, sub.t, res, lossless_motor(twin, sub, method, chunk, backend, jobs))
                    residual = float(np.max([residual, res.residual])) if verify else residual   # NaN stays NaN
                    if progress is not None:
                        progress(advance=len(sub.t))
                record(table_file, part, tabs[0] if len(tabs) == 1 else np.concatenate(tabs), residual)

    # with a progress bar, a part's solve goes in steps of a multiple of the kernel's warm-start
    # runs (results bit-identical to one call: the runs restart at the same samples), ~1/40 of the run
    step = None if progress is None else max(WARM_RUN, rows // 40 // WARM_RUN * WARM_RUN)

    def record(table_file, part, tab, residual):
        nonlocal worst, n
        watch.see(part)
        _check_loads(reader, part, tab, names)
        if verify:
            _check_residual(reader, part, residual)
            worst = max(worst, residual)
        summary.add(tab)
        if table_file is not None:
            table_file.write(tab)
        n += len(part.t)

    def opened(f):
        meta = {"gearcli_version": __version__, "mechanism": str(mech_path), "trajectory": str(traj_path),
                "conventions": CONVENTIONS}
        return BackgroundWriter(open_table(fmt, f, names, column_units(an), meta, precision=precision or 9,
                                           rows=rows, jobs=jobs))

    out = None if out_path is None or to_stdout else Path(out_path)
    if out is None:   # no output, or stdout
        _run(solve_chunks, None if out_path is None else opened(sys.stdout))
    else:
        with atomic_output(out, (mech_path, traj_path), binary=fmt != "csv") as f:
            _run(solve_chunks, opened(f))
    return SolveReport(an, n, summary, worst if verify else None, out, losses, watch.issues, how)


WARM_RUN = 256
"""Samples of the kernel's warm-start run (:data:`gearcli.dynamics.llvm.signs.WARM`, not
imported: that imports llvmlite): a progress step is a multiple of it."""


def progress_slices(part, step: int | None):
    """``part`` (a :class:`~.io.trajectory.Trajectory`) whole, or in slices of ``step``
    samples (its loads and attach flags sliced with it)."""
    n = len(part.t)
    if step is None or step >= n:
        yield part
        return
    for s in range(0, n, step):
        sl = slice(s, s + step)
        yield Trajectory(part.t[sl], part.q[sl], part.qd[sl], part.qdd[sl],
                         None if part.line is None else part.line[sl],
                         None if part.loads is None else {k: v[sl] for k, v in part.loads.items()},
                         None if part.attach is None else {k: v[sl] for k, v in part.attach.items()})


def lossless_motor(twin: Analysis, part, method: str, chunk: int, backend: str, jobs) -> np.ndarray:
    """Motor torques (N, M) of a chunk's motion without losses (the lines' output power for
    the summary's line efficiencies, :mod:`gearcli.report.loss_summary`)."""
    return solve(twin, part.q, part.qd, part.qdd, method=method, chunk=chunk, loads=part.loads,
                 backend=backend, jobs=jobs, check_finite=False, attach=part.attach).motor


def _run(solve_chunks, table_file) -> None:
    """``solve_chunks(table_file)``, then close the table file (abort it on failure)."""
    try:
        solve_chunks(table_file)
        if table_file is not None:
            table_file.close()
    except BaseException:
        if table_file is not None:
            table_file.abort()
        raise


class Prefetch:
    """Context manager iterating ``items`` one item ahead in a background thread (reading and
    spline differentiation of chunk k + 1 overlap the solve of chunk k; parsing, LAPACK and
    the kernel release the GIL).  Items arrive in order; an exception raised by ``items``
    is raised as soon as it is known, in place of the items still queued (the run fails
    anyway: a bad row near the end of a file is reported without solving the chunks read
    before it); leaving the context stops the thread (after the item it is producing)."""

    def __init__(self, items, depth: int = 1):
        self.items, self.queue, self.stop = items, queue.Queue(maxsize=depth), threading.Event()
        self.thread = threading.Thread(target=self._run, name="gearcli-read", daemon=True)
        self.error: BaseException | None = None

    def __enter__(self):
        self.thread.start()
        return self._iter()

    def __exit__(self, *exc) -> None:
        self.stop.set()
        self.thread.join()

    def _run(self) -> None:
        try:
            for x in self.items:
                if not self._put((True, x)):
                    return
        except BaseException as exc:   # noqa: BLE001 (re-raised in the consuming thread)
            self.error = exc
            self._put((False, exc))
            return
        self._put((False, None))

    def _put(self, item) -> bool:
        while not self.stop.is_set():
            try:
                self.queue.put(item, timeout=0.05)
                return True
            except queue.Full:
                continue
        return False

    def _iter(self):
        while True:
            ok, x = self.queue.get()
            if self.error is not None:
                raise self.error
            if ok:
                yield x
            elif x is None:
                return
            else:
                raise x


class BackgroundWriter:
    """A table writer (:func:`~gearcli.report.table_files.open_table`) whose ``write`` runs in
    a background thread, overlapping the solve of the next chunk (pyarrow and the compiled
    CSV formatter release the GIL).  One write at a time, in order; a failed write raises at
    the next ``write`` or at ``close``; ``abort`` waits for the running write first."""

    def __init__(self, table_file):
        self.file, self.pending = table_file, None
        self.pool = ThreadPoolExecutor(1, thread_name_prefix="gearcli-write")

    def _wait(self) -> None:
        pending, self.pending = self.pending, None
        if pending is not None:
            pending.result()

    def write(self, tab: np.ndarray) -> None:
        self._wait()
        self.pending = self.pool.submit(self.file.write, tab)

    def close(self) -> None:
        try:
            self._wait()
            self.file.close()
        finally:
            self.pool.shutdown()

    def abort(self) -> None:
        """Release the writer after a failure, once the write under way is over."""
        self.pool.shutdown(wait=True, cancel_futures=True)
        self.file.abort()


def output_format(out_path, inputs, precision: int | None) -> str:
    """The format of ``out_path`` (``csv`` when None); raises for a bad target, an unknown
    extension or a bad ``precision``."""
    if precision is not None and not (isinstance(precision, int) and 1 <= precision <= 17):
        raise GearcliError(f"--precision: expected 1 to 17 significant digits, got {precision}")
    if out_path is None:
        return "csv"
    output_target(out_path, inputs)
    fmt = format_of(str(out_path))
    if fmt is None:
        raise OutputError(str(out_path), f"unknown output format '{extension(str(out_path))}' (the extension "
                          f"chooses it: {', '.join(FORMATS)})")
    if precision is not None and fmt != "csv":
        raise OutputError(str(out_path), f"--precision applies to CSV output only, not {fmt}")
    return fmt


@contextmanager
def at_samples(file: str, part):
    """Re-raise a solve's error of one sample of ``part`` (a :class:`~.io.trajectory.Trajectory`
    read from ``file``; the error's ``sample`` its row in ``part``: :class:`SignError`,
    :class:`BearingFrictionError`) at that sample's time and file line, where "sample i" of
    a chunk alone would name a row counted from the chunk's start."""
    try:
        yield
    except (SignError, BearingFrictionError, SlackError) as exc:
        i, text = exc.sample, exc.lines()[0]
        text = text.removeprefix(f"sample {i}: ")
        line = None if part.line is None else int(part.line[i])
        raise TrajectoryError(Issue(str(file), f"sample t = {part.t[i]:.9g} s", line,
                                    f"{text} (nothing written)")) from None


def _sample_line(reader: TrajectoryReader, part, i: int) -> int | None:
    return None if part.line is None else int(part.line[i])


def _check_loads(reader: TrajectoryReader, part, tab: np.ndarray, names: list[str]) -> None:
    """Raise naming the first sample (and output column) whose load is not finite."""
    bad = first_non_finite(tab)
    if bad is None:
        return
    i, c = bad
    raise TrajectoryError(Issue(reader.file, f"sample t = {part.t[i]:.9g} s", _sample_line(reader, part, i),
                                f"load '{names[c]}' is {tab[i, c]} (the trajectory gives no finite loads "
                                "here; nothing written)"))


def _check_residual(reader: TrajectoryReader, part, r: float) -> None:
    if math.isfinite(r) and r <= VERIFY_TOLERANCE:
        return
    raise TrajectoryError(Issue(reader.file, "--verify", None,
                                f"worst Newton-Euler residual {r:.3g} between t = {part.t[0]:.9g} s and "
                                f"{part.t[-1]:.9g} s exceeds the tolerance {VERIFY_TOLERANCE:g} "
                                "(loads not trustworthy; nothing written)"))

