"""Human-readable reports: rich tables of the graph analysis and of a solve summary.

Numbers are shown to 6 significant digits (:func:`fmt_num`); the machine-readable forms are
the JSON of :mod:`gearcli.report.graph_json` and the CSV of :mod:`gearcli.report.columns`.
rich is imported when a table or console is made (``gearcli --help`` and ``check`` need none).
"""
from __future__ import annotations

import errno
import math
import os
from contextlib import contextmanager
from typing import TYPE_CHECKING

from ..errors import counted
from .features import feature_notes
from .sharing import sharing_notes

if TYPE_CHECKING:  # pragma: no cover
    from rich.console import Console
    from rich.table import Table

    from ..analysis.graph import Analysis

JSON_DIGITS = 12  # significant digits of floats in JSON output


def round_sig(obj, digits: int = JSON_DIGITS):
    """``obj`` with every float rounded to ``digits`` significant digits (-0.0 -> 0.0).

    Recurses into dicts, lists and tuples; so -0.9999999999999991 becomes -1.0.
    """
    if isinstance(obj, float):
        if not math.isfinite(obj):
            return obj
        return float(f"{obj:.{digits}g}") + 0.0
    if isinstance(obj, dict):
        return {k: round_sig(v, digits) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [round_sig(v, digits) for v in obj]
    return obj


def fmt_num(x: float) -> str:
    """A number for tables: 6 significant digits, no negative zero."""
    return f"{round_sig(float(x), 6):g}"


def format_blocks(blocks) -> str:
    """Solve order as ``{2} -> {4} -> {1, 3}`` from lists of link names."""
    return " -> ".join("{" + ", ".join(block) + "}" for block in blocks)


def stdout_console() -> Console:
    """Console for tables: no markup parsing of user names, no auto-highlighting; plain
    lines (solve order, ...) are never wrapped, so they stay greppable."""
    from rich.console import Console  # noqa: PLC0415

    console = _raises_on_closed_pipe(Console(markup=False, highlight=False, soft_wrap=True))
    if not console.is_terminal:   # piped or redirected: do not squeeze tables into 80 columns
        console.width = max(console.width, 132)
    return console


def _raises_on_closed_pipe(console: Console) -> Console:
    """``console`` raising :class:`BrokenPipeError` on a closed pipe, as every other write
    does, so that :func:`gearcli.exits.bad_input_exits` ends the run quietly with status 141
    (rich's own handler exits with status 1: ``gearcli graph ... | head -c 10`` did)."""
    def closed() -> None:
        console.quiet = True   # nothing more to write
        raise BrokenPipeError(errno.EPIPE, os.strerror(errno.EPIPE))

    console.on_broken_pipe = closed
    return console


def _table(title: str, **options) -> Table:
    """A rich table (rich imported here: only commands that print tables pay for it)."""
    from rich.table import Table  # noqa: PLC0415

    return Table(title=title, **options)


def stderr_console() -> Console:
    """Console on stderr (progress, or the summary when the table goes to stdout): no markup,
    no highlighting; as wide as :func:`stdout_console`'s when not a terminal."""
    from rich.console import Console  # noqa: PLC0415

    err = _raises_on_closed_pipe(Console(stderr=True, markup=False, highlight=False))
    if not err.is_terminal:
        err.width = max(err.width, 132)
    return err


def links_table(an: Analysis) -> Table:
    """One row per link: level, primary/secondary, carrier, axis label, real joint."""
    t = _table("Links (canonical graph)", title_justify="left")
    for col in ("link", "level", "role", "carrier", "axis", "real joint"):
        t.add_column(col)
    n, prim = an.names, set(an.primary)
    for i, name in enumerate(n):
        if i == an.tree.base:
            t.add_row(name, "0", "base", "-", "-", "-")
            continue
        jt = an.mech.joints[an.tree.parent_joint[i]]
        slides = " (prismatic)" if jt.type == "prismatic" else ""
        t.add_row(name, str(an.level[i]), "primary" if i in prim else "secondary",
                  n[an.canonical_parent[i]], str(an.label[i]), f"{jt.name}: {jt.parent} -> {jt.child}{slides}")
    return t


def gears_table(an: Analysis) -> Table:
    """One row per gear pair: links j, k, carrier c, kind, ratio e_kj and circuit equation."""
    t = _table("Gear pairs (fundamental circuits: theta_j,c = e_kj * theta_k,c)",
              title_justify="left")
    for col in ("pair", "j", "k", "carrier", "kind", "ratio e_kj", "equation"):
        t.add_column(col)
    n = an.names
    from .graph_json import analysis_dict  # noqa: PLC0415  (numpy-free import keeps --help fast)

    equations = [fc["equation"] for fc in analysis_dict(an)["fundamental_circuits"]]
    for c, equation in zip(an.circuits, equations):
        gp = an.mech.gears[c.gear]
        t.add_row(gp.name, n[c.j], n[c.k], n[c.carrier], gp.kind, fmt_num(c.ratio), equation)
    return t


def groups_table(an: Analysis) -> Table:
    """Coaxial groups: a carrier and the links turning about one line relative to it."""
    t = _table("Coaxial groups", title_justify="left")
    for col in ("carrier", "axis", "coaxial links"):
        t.add_column(col)
    for g in an.groups:
        if len(g.members) > 2:
            t.add_row(an.names[g.carrier], str(g.label), ", ".join(an.name_of(g.members[1:])))
    return t


def structure_table(an: Analysis) -> Table:
    """Structure matrix A: rows independent joints, columns motors (input = A^T x joint)."""
    t = _table("Structure matrix A", title_justify="left",
              caption="motor input rotations = A^T x independent joint rotations (rad)")
    t.add_column("joint \\ motor")
    for m in an.mech.motors:
        t.add_column(f"{m.name} ({m.link})", justify="right")
    for name, row in zip(an.independent_names, an.A):
        t.add_row(name, *(fmt_num(x) for x in row))
    return t


def print_graph_tables(an: Analysis, console: Console) -> None:
    """The human-readable ``gearcli graph`` report."""
    console.print(f"Mechanism {an.mech.name} ({an.mech.source})", style="bold")
    console.print(links_table(an))
    console.print(gears_table(an))
    if any(len(g.members) > 2 for g in an.groups):
        console.print(groups_table(an))
    console.print("Transmission lines:", style="bold")
    for line in an.transmission_lines:
        console.print("  " + " -> ".join(an.name_of(line)))
    console.print(f"Degrees of freedom: {an.dof}  (independent joints: {', '.join(an.independent_names)})")
    console.print(structure_table(an))
    console.print(f"Pseudo-triangular: {'yes' if an.pseudo_triangular else 'no'}")
    console.print("Solve order: " + format_blocks([an.name_of(b) for b in an.schedule]))
    for line in feature_notes(an) + sharing_notes(an):
        console.print(line, markup=False)


def summary_table(report) -> Table:
    """Peak magnitude, RMS and time of the peak of every motor, mesh and bearing load."""
    table = _table(f"{report.analysis.mech.name}: {counted(report.samples, 'sample')}")
    for col, just in (("load", "left"), ("unit", "left"), ("peak", "right"), ("RMS", "right"),
                      ("t at peak [s]", "right")):
        table.add_column(col, justify=just, no_wrap=(col == "load"))
    largest: dict[str, float] = {}
    for st in report.summary.stats:
        largest[st.unit] = max(largest.get(st.unit, 0.0), st.peak)
    for st in report.summary.stats:
        if st.peak <= 1e-12 * largest[st.unit]:   # rounding noise of an unloaded direction
            table.add_row(st.name, st.unit, "0", "0", "-")
        else:
            table.add_row(st.name, st.unit, fmt_num(st.peak), fmt_num(st.rms), fmt_num(st.t_peak))
    return table


@contextmanager
def time_progress(label: str, console):
    """Context yielding the ``tick(total=None, t=None)`` callback of a transient progress bar
    of simulated time on ``console`` (drawn on a terminal only): ``total`` (s) once, then
    the time reached."""
    from rich.progress import BarColumn, Progress, TextColumn  # noqa: PLC0415

    progress = Progress(TextColumn(label), BarColumn(), TextColumn("t = {task.completed:.3f} s"), console=console,
                        transient=True, disable=not console.is_terminal)
    task = []

    def tick(total=None, t=None):
        if total is not None:
            task.append(progress.add_task(label, total=total))
        else:
            progress.update(task[0], completed=t)

    with progress:
        yield tick
