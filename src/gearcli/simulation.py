"""File to file: mechanism + motor inputs CSV -> trajectory CSV (``gearcli simulate``).

Data flow: :func:`~gearcli.io.load_mechanism` -> :func:`~gearcli.analyse` ->
:func:`~gearcli.io.drive_input.read_drive_input` -> :func:`~gearcli.dynamics.simulate.simulate`
(scipy ``solve_ivp`` on :func:`~gearcli.dynamics.forward.forward_dynamics`) -> the trajectory
CSV, and with ``--loads`` :func:`gearcli.pipeline.solve_file` on it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .analysis.graph import Analysis
from .dynamics.determinacy import load_analysed
from .errors import GearcliError, counted
from .io.output import OutputError, atomic_output, output_target
from .pipeline import SolveReport, output_format, solve_file
from .report.table_files import format_of

MAX_SIMULATE_SAMPLES = 10_000_000
STALL_EVALUATIONS = 5_000    # evaluations of the dynamics without advancing STALL_FRACTION of the span
STALL_FRACTION = 1e-4


MIN_RTOL = 100 * np.finfo(float).eps
"""The least --rtol: solve_ivp raises a smaller one to this, with a warning of its own."""


class StallWatch:
    """Called with the time of every evaluation of the dynamics: raises StallError when
    :data:`STALL_EVALUATIONS` of them pass without the time reached advancing by
    :data:`STALL_FRACTION` of the span (the integrator's step collapsed: a smooth motion
    needs a few hundred evaluations a second).  A stiff system (a motor's L/R far below the
    motion's time scale) under an explicit method does this; friction that would hold a
    joint at rest no longer does (it sticks, :mod:`gearcli.dynamics.stick_slip`).  The
    message suggests the method."""

    def __init__(self, an: Analysis, input_path, t0: float, t1: float, method: str, progress=None):
        self.an, self.input_path, self.method, self.progress = an, input_path, method, progress
        self.step, self.mark, self.n, self.n_mark = STALL_FRACTION * (t1 - t0), t0, 0, 0

    def __call__(self, t: float) -> None:
        self.n += 1
        if t >= self.mark + self.step:
            self.mark, self.n_mark = t, self.n
        elif self.n - self.n_mark > STALL_EVALUATIONS:
            from .dynamics.simulate import StallError  # noqa: PLC0415
            raise StallError(f"simulation stalled at t = {self.mark:.6g} s: {STALL_EVALUATIONS:,} evaluations "
                                  f"of the dynamics without advancing {self.step:.3g} s{self.hint()}", self.mark)
        if self.progress is not None:
            self.progress(t)

    def hint(self) -> str:
        tau = [m.model.inductance / m.model.resistance for m in self.an.mech.motors
               if m.model is not None and m.model.inductance]
        if self.method not in ("RK45", "RK23", "DOP853"):
            return ""
        return (f": a motor's L/R of {min(tau):.3g} s makes the system stiff: give --method Radau or BDF" if tau
                else ": if the system is stiff, give --method Radau or BDF")


@dataclass
class SimulateReport:
    """What :func:`simulate_file` did: the simulation (:class:`~gearcli.dynamics.simulate.
    Simulation`: samples, why it stopped early, right-hand side evaluations), the output
    path, and the loads run (``--loads``: a :class:`SolveReport`, else None)."""

    analysis: Analysis = field(repr=False)
    simulation: object = field(repr=False)
    output: Path
    loads: SolveReport | None = None

    def summary(self, output: str, loads: str | None) -> list[str]:
        """What ``gearcli simulate`` prints on stdout."""
        sim = self.simulation
        rows = len(sim.t) if sim.rows is None else sim.rows
        out = [f"Wrote {counted(rows, 'row')} to {output} (t = {sim.t[0]:g} to {sim.t[-1]:g} s, "
               f"{counted(sim.nfev, 'evaluation')} of the dynamics)"]
        if self.loads is not None:
            out.append(f"Wrote {counted(self.loads.samples, 'row')} of loads to {loads}")
        return out


def state_option(text: str | None, an: Analysis, option: str) -> np.ndarray:
    """The (dof,) values of ``--q0``/``--qd0`` ("v1,v2,..." in ``an.independent_names``
    order; SI units), zeros when not given; GearcliError naming the option otherwise."""
    if text is None:
        return np.zeros(an.dof)
    cells = [c.strip() for c in text.split(",")]
    try:
        x = np.array([float(c) for c in cells])
    except ValueError:
        raise GearcliError(f"{option}: expected {an.dof} comma-separated numbers (joints "
                           f"{', '.join(an.independent_names)}), got '{text}'") from None
    if len(x) != an.dof or not np.isfinite(x).all():
        raise GearcliError(f"{option}: expected {an.dof} finite comma-separated numbers (joints "
                           f"{', '.join(an.independent_names)}), got '{text}'")
    return x


def simulate_file(mech_path, input_path, out_path, *, t_end: float | None = None, q0: str | None = None,
                  qd0: str | None = None, dt: float = 1e-3, rtol: float = 1e-6, atol: float = 1e-9,
                  method: str = "RK45", loads_path=None, progress=None,
                  analysis: Analysis | None = None, warn=None) -> SimulateReport:
    """``gearcli simulate``: integrate the mechanism under the motor torques or voltages of
    ``input_path`` (:mod:`gearcli.io.drive_input`) from its first time to ``t_end`` (default
    its last), writing the trajectory CSV ``out_path`` (``t, q:, qd:, qdd:`` every ``dt``
    seconds, 17 digits: what ``gearcli solve`` reads) atomically; with ``loads_path``,
    then the loads along it as ``gearcli solve`` writes them.  ``progress(total=..)`` once,
    then ``progress(t=...)`` with the time reached; ``warn(line)`` is told, before the
    integration starts, when an explicit method meets a stiff system
    (:func:`~gearcli.dynamics.simulate.stiffness_hint`)."""
    from .dynamics.simulate import (METHODS, SimulationError, StallError, joint_limits,  # noqa: PLC0415
                                    simulate, stiffness_hint)
    from .io.drive_input import read_drive_input  # noqa: PLC0415

    inputs = (mech_path, input_path)
    if str(out_path) == "-":
        raise OutputError("-", "simulate writes its trajectory to a file, not to stdout (give -o TRAJ.csv)")
    output_target(out_path, inputs)
    if format_of(str(out_path)) not in (None, "csv"):
        raise OutputError(str(out_path), f"simulate writes its trajectory as CSV, the file `gearcli solve` reads: "
                          f"give -o TRAJ.csv (and --loads LOADS.{format_of(str(out_path))} for the loads in that format)")
    if loads_path is not None:
        output_format(loads_path, inputs + (out_path,), None)
    if method not in METHODS:
        raise GearcliError(f"--method: expected one of {', '.join(METHODS)}, got '{method}'")
    for name, v in (("--rtol", rtol), ("--atol", atol), ("--dt", dt)):
        if not (math.isfinite(v) and v > 0):
            raise GearcliError(f"{name}: expected a positive number, got {v:g}")
    if rtol < MIN_RTOL:
        raise GearcliError(f"--rtol: expected at least {MIN_RTOL:.3g} (100 machine epsilons: the integrator can "
                           f"meet no tighter relative tolerance), got {rtol:g}")
    an = analysis or load_analysed(mech_path)
    x0, v0 = state_option(q0, an, "--q0"), state_option(qd0, an, "--qd0")
    for ji, name, lo, hi in joint_limits(an):
        if not lo <= an.S[ji] @ x0 <= hi:
            raise GearcliError(f"--q0: joint '{name}' starts at {an.S[ji] @ x0:g}, outside its limits [{lo:g}, {hi:g}]")
    drive = read_drive_input(input_path, an.mech.motors, [p.name for p in an.mech.payloads])
    t0, t1 = float(drive.t[0]), float(drive.t[-1] if t_end is None else t_end)
    if not (math.isfinite(t1) and t1 - t0 > 1e-9 * max(1.0, abs(t0))):
        raise GearcliError(f"--t-end: expected a time after the input's first t = {t0:.9g} s (by more than "
                           f"{1e-9 * max(1.0, abs(t0)):.3g} s), got {t1:.9g}")
    if (t1 - t0) / dt > MAX_SIMULATE_SAMPLES:
        raise GearcliError(f"--dt: {dt:g} s gives more than {MAX_SIMULATE_SAMPLES:,} samples over {t1 - t0:g} s")
    t_eval = t0 + dt * np.arange(int(math.floor((t1 - t0) / dt * (1 + 1e-12))) + 1)
    if t_eval[-1] < t1 - 1e-9 * min(dt, t1 - t0):     # (a --dt beyond the span: its two ends)
        t_eval = np.append(t_eval, t1)
    hint = stiffness_hint(an, x0, t1 - t0, method)
    if hint is not None and warn is not None:
        warn(f"{input_path}: warning: {hint}")
    if progress is not None:
        progress(total=t1 - t0)
    names = an.independent_names
    payloads = list(drive.attach)           # carried where attached: the trajectory says where
    header = ",".join(["t"] + [f"{p}:{n}" for p in ("q", "qd", "qdd") for n in names] + [f"attach:{p}" for p in payloads])
    watch = StallWatch(an, input_path, t0, t1, method, None if progress is None else (lambda t: progress(t=t - t0)))
    try:
        with atomic_output(out_path, inputs) as f:      # rows written as they are integrated
            f.write(header + "\n")

            def write(part):
                flags = drive.attach_flags(part.t)
                np.savetxt(f, np.column_stack([part.t, part.q, part.qd, part.qdd, flags]), delimiter=",", fmt="%.17g")
            sim = simulate(an, drive, t_eval, x0, v0, rtol=rtol, atol=atol, method=method, progress=watch, sink=write)
    except SimulationError as exc:       # before any sample: nothing written (the output is removed)
        said = str(exc) if isinstance(exc, StallError) else f"simulation failed: {exc}"
        raise GearcliError(f"{input_path}: {said} (nothing written)") from None
    report = SimulateReport(an, sim, Path(out_path))
    if loads_path is not None:
        report.loads = solve_file(mech_path, out_path, loads_path, analysis=an)
    return report


def simulate_with_progress(mech_path, input_path, out_path, console, analysis, t_end, q0, qd0, dt, rtol, atol,
                           method, loads_path) -> SimulateReport:
    """:func:`simulate_file` (the same arguments) with a progress bar of simulated time on
    ``console`` (stderr), then its summary lines on stdout: what ``gearcli simulate`` shows
    (the caller handles a stop at a joint limit)."""
    from .report.tables import stdout_console, time_progress  # noqa: PLC0415

    with time_progress("simulating", console) as tick:
        report = simulate_file(mech_path, input_path, out_path, t_end=t_end, q0=q0, qd0=qd0, dt=dt, rtol=rtol,
                               atol=atol, method=method, loads_path=loads_path, progress=tick, analysis=analysis,
                               warn=lambda line: console.print(line, markup=False, highlight=False, soft_wrap=True))
    stdout_console().print("\n".join(report.summary(str(out_path), loads_path)))
    return report
