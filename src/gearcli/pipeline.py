"""File to file: mechanism + trajectory CSV -> loads CSV and summary (``gearcli solve``).

Data flow: :func:`~gearcli.loader.load_mechanism` -> :func:`~gearcli.graph.analyse` ->
:class:`~gearcli.trajectory.TrajectoryReader` (chunks) -> :func:`~gearcli.dynamics.solve` ->
:mod:`~gearcli.report`.  Memory is bounded by the chunk size, whatever the file length.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

from .dynamics.solve import solve
from .analysis.graph import Analysis
from .analysis.graph import analyse as analyse_graph
from .dynamics.determinacy import check_determinate
from .errors import Collector
from .io import load_mechanism
from .model.mechanism import Mechanism
from .report.columns import AtomicWriter, Summary, column_names, format_rows, table
from .io.trajectory import TrajectoryReader


def analyse(mech: Mechanism) -> Analysis:
    """Analyse ``mech`` and check that its loads are determined.

    The graph analysis (:func:`gearcli.analysis.graph.analyse`: canonical graph, levels,
    circuits, structure matrix, schedule) followed by the numerical determinacy check of the
    load equations (:func:`gearcli.dynamics.determinacy.check_determinate`).  Raises
    :class:`~gearcli.errors.MechanismError` listing every problem.
    """
    an = analyse_graph(mech)
    col = Collector(mech.source, mech.lines)
    check_determinate(an, col)
    col.raise_if_any()
    return an


def prismatic_independent(an: Analysis) -> list[str]:
    """Names of the independent coordinates that are prismatic joints (m, not rad)."""
    return [n for n, ji in zip(an.independent_names, an.independent)
            if ji >= 0 and an.mech.joints[ji].type == "prismatic"]


@dataclass
class SolveReport:
    analysis: Analysis
    samples: int
    summary: Summary
    residual: float | None
    output: Path | None


def solve_file(mech_path, traj_path, out_path=None, *, degrees: bool = False, method: str = "block",
               verify: bool = False, chunk: int = 20_000, progress=None, analysis: Analysis | None = None) -> SolveReport:
    """Solve a trajectory file and write the loads CSV (see :mod:`gearcli.report`).

    ``progress(total=None, advance=None)`` is called with ``total`` once (number of
    samples) and with ``advance`` after each chunk.  The output is written to a temporary
    file and renamed only when everything succeeded; ``out_path="-"`` writes to stdout and
    ``None`` writes nothing (summary only).
    """
    an = analysis or analyse(load_mechanism(mech_path))
    reader = TrajectoryReader(traj_path, an.independent_names, degrees=degrees, chunk=chunk,
                              linear=prismatic_independent(an))
    if progress is not None:
        progress(total=reader.count())
    summary = Summary.for_mechanism(an)
    worst = 0.0
    n = 0

    def run(f):
        nonlocal worst, n
        if f is not None:
            f.write(",".join(column_names(an)) + "\n")
        for part in reader:
            res = solve(an, part.q, part.qd, part.qdd, method=method, chunk=chunk, verify=verify)
            tab = table(an, part.t, res)
            summary.add(tab)
            if f is not None:
                f.write(format_rows(tab))
            if verify:
                worst = max(worst, res.residual)
            n += len(part.t)
            if progress is not None:
                progress(advance=len(part.t))

    out = None if out_path is None or str(out_path) == "-" else Path(out_path)
    if out_path is None:
        run(None)
    elif out is None:
        run(sys.stdout)
    else:
        with AtomicWriter(out) as f:
            run(f)
    return SolveReport(an, n, summary, worst if verify else None, out)
