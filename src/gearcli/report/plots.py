"""Figures (matplotlib, optional extra ``plot``): output columns over time, and a design
check's quantity along its worst trajectory with its limit.

Files are written through a temporary file and renamed; the format follows the extension
(``.png``, ``.svg``, ``.pdf``).
"""
from __future__ import annotations

import fnmatch
import warnings
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import GearcliError, plural
from ..io.output import atomic_output, output_target
from .loads_files import LoadsFile, Undrawable, csv_unit, open_loads, shown  # noqa: F401 (csv_unit: API)

FORMATS = (".png", ".svg", ".pdf")


def _pyplot():
    try:
        import matplotlib  # noqa: PLC0415 (optional dependency)
    except ImportError:
        raise GearcliError("plots need matplotlib: pip install 'gearcli[plot]'") from None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    return plt


def _save(fig, path: Path) -> None:
    """Write ``fig`` atomically (:func:`gearcli.io.output.atomic_output`)."""
    plt = _pyplot()
    try:
        with atomic_output(path, binary=True) as f:
            fig.savefig(f, dpi=100, format=path.suffix[1:])
    finally:
        plt.close(fig)


def check_output_path(path: str | Path) -> Path:
    path = Path(path)
    if path.suffix.lower() not in FORMATS:
        raise GearcliError(f"{path}: -o: the figure format must be one of {', '.join(FORMATS)} (from the extension)")
    return path


MAX_GLOB = 1000
"""Characters of a shell pattern at most: a 130,000-character '*x*x...' took 8 s to compile."""


def select_columns(header: list[str], patterns: list[str], file: str) -> list[int]:
    """Indices of the columns of ``header`` matching any of ``patterns`` (names or shell
    globs), in header order (a duplicated name: each of its columns); a pattern that matches
    nothing is an error."""
    chosen = np.zeros(len(header), dtype=bool)
    for p in patterns:
        if not any(c in p for c in "*?["):         # a name: compared, whatever its length
            hits = [i for i, h in enumerate(header) if h == p]
        elif len(p) > MAX_GLOB:
            raise GearcliError(f"COLUMN_OR_GLOB '{shown(p)}': a pattern with * ? [ of {len(p):,} characters is too long "
                               f"(at most {MAX_GLOB:,}; a name without them may be of any length)")
        else:
            hits = [i for i, h in enumerate(header) if fnmatch.fnmatchcase(h, p)]
        if not hits:
            raise GearcliError(f"{file}:1: no column matches '{shown(p)}'")
        chosen[hits] = True
    return [int(i) for i in np.flatnonzero(chosen)]


MAX_LINES = 24
"""Columns drawn at most (lines in a figure); more would be an unreadable figure whose
legends take seconds to lay out (5,000 columns took minutes)."""

MAX_AXES = 6
"""Axes (units) drawn at most, one above the other."""


def _math_free(text: str) -> str:
    """``text`` shown literally by matplotlib: ``$`` would start mathtext."""
    return text.replace("$", r"\$")


SCALE_SPREAD = 10.0
"""Columns of one unit whose peaks |x| differ by more than this factor get axes of their own:
a 0.5 N*m motor torque drawn beside a 50 N*m bearing moment would be a flat line at 0."""


MAX_SCALE_AXES = 3
"""Axes of one unit at most (the smallest peaks share the last)."""


def magnitude_groups(names: list[str], series: dict) -> list[list[str]]:
    """``names`` (columns of one unit) split into groups whose peaks max |x| lie within
    :data:`SCALE_SPREAD` of each other: sorted by peak, a group is closed when the next
    column's peak exceeds SCALE_SPREAD times the group's smallest non-zero peak (an all-zero
    or all-NaN column joins the smallest group; beyond :data:`MAX_SCALE_AXES` groups the
    smallest are merged).  Each group keeps the columns' order; groups come largest peak first."""
    def peak(n):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")             # an all-NaN column: nanmax warns
            v = np.nanmax(np.abs(np.asarray(series[n], float))) if np.size(series[n]) else np.nan
        return float(v) if np.isfinite(v) else 0.0
    peaks = {n: peak(n) for n in names}
    groups: list[list[str]] = []
    low = None
    for n in sorted(names, key=lambda n: peaks[n]):
        p = peaks[n]
        if groups and (p == 0.0 or low is None or p <= SCALE_SPREAD * low):
            groups[-1].append(n)
            low = low if low is not None or p == 0.0 else p
        else:
            groups.append([n])
            low = p if p > 0.0 else None
    while len(groups) > MAX_SCALE_AXES:               # the smallest share an axis
        groups[:2] = [groups[0] + groups[1]]
    order = {n: i for i, n in enumerate(names)}
    return [sorted(g, key=order.get) for g in reversed(groups)]


def plot_columns(t: np.ndarray, series: dict, units: dict, out: str | Path, title: str = "",
                 t_label: str = "t [s]") -> list[str]:
    """Columns over time: one axis per unit (sharing t), units on the axes, and within a
    unit one axis per group of peaks within :data:`SCALE_SPREAD` (:func:`magnitude_groups`);
    returns notes on
    what the figure leaves out or shows oddly, in gearcli's words (matplotlib's own warnings
    are never printed).

    ``series`` maps a label to (N,) values (NaN: a gap), ``units`` a label to its unit.  Labels,
    units and the title are shown as :func:`~gearcli.report.loads_files.shown` gives them.
    """
    plt = _pyplot()
    by_unit: dict[str, list[str]] = {}
    for name in series:
        by_unit.setdefault(units[name], []).append(name)
    groups = [(unit, g) for unit, names in by_unit.items() for g in magnitude_groups(names, series)]
    marker = "." if len(t) == 1 else None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fig, axes = plt.subplots(len(groups), 1, sharex=True, figsize=(8, 2.6 * len(groups) + 0.6), squeeze=False)
        try:
            for ax, (unit, names) in zip(axes[:, 0], groups):
                lines = [ax.plot(t, series[n], lw=1.2, marker=marker)[0] for n in names]
                ax.set_ylabel(_math_free(f"[{shown(unit, 20)}]") if unit else "value")
                ax.grid(alpha=0.3)
                ax.legend(lines, [_math_free(shown(n)) for n in names], fontsize="small", loc="best")
            axes[-1, 0].set_xlabel(_math_free(t_label))
            if title:
                axes[0, 0].set_title(_math_free(shown(title)))
            fig.tight_layout()
        except BaseException:
            plt.close(fig)
            raise
        _save(fig, check_output_path(out))
    if any("missing from font" in str(w.message) for w in caught):
        return ["some characters of the names are not in the figure's font and show as boxes"]
    return []


def plot_check(t: np.ndarray, y: np.ndarray, limit: float, out: str | Path, title: str, ylabel: str,
               limit_label: str, levels: tuple = ()) -> None:
    """A check's quantity ``y`` over ``t`` (its worst trajectory) and the level ``limit``;
    ``levels``: more (level, label) lines, dotted (the value a duty-cycle check compares)."""
    plt = _pyplot()
    with warnings.catch_warnings():     # matplotlib's (a glyph missing from the font) are not gearcli's
        warnings.simplefilter("ignore")
        fig, ax = plt.subplots(figsize=(7, 3.2))
        ax.plot(t, y, lw=1.2, label="value")
        if np.isfinite(limit):
            ax.axhline(limit, color="red", ls="--", lw=1.2, label=limit_label)
        for level, label in levels:
            ax.axhline(level, color="black", ls=":", lw=1.2, label=label)
        ax.set_xlabel("t [s]")
        ax.set_ylabel(ylabel)
        ax.set_title(title, fontsize="medium")
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small", loc="best")
        fig.tight_layout()
        _save(fig, check_output_path(out))


def read_loads(path) -> tuple[list[str], np.ndarray, dict]:
    """Header, (N, ncol) data and units (column -> unit) of a loads file written by
    ``gearcli solve``: CSV (units from the column names), Parquet, Feather or NPZ (units
    from the file's metadata); GearcliError for a column that is not numbers."""
    table = open_loads(path)
    data = np.column_stack([table.time()] + [_values_or_error(table, i)[0] for i in range(1, len(table.names))])
    return table.names, data, dict(zip(table.names, table.units))


def _values_or_error(table: LoadsFile, i: int):
    try:
        return table.values(i)
    except Undrawable as exc:
        raise GearcliError(f"{table.where(i)}: {exc}") from None


@dataclass
class PlotReport:
    """What ``gearcli plot`` drew: ``drawn`` columns of ``matched``; ``notes`` (gearcli's
    warnings: columns left out and why, gaps, the cap on lines)."""

    drawn: int
    matched: int
    notes: list[str]


def plot_loads_csv(path, patterns: list[str], out) -> PlotReport:
    """Plot the columns of a loads file (CSV, Parquet, Feather, NPZ) matching ``patterns``
    into ``out``.

    Columns that cannot be drawn (not numbers, no finite value, beyond ±1e300) are left out
    and named in the notes; only the first :data:`MAX_LINES` drawable columns of the first
    :data:`MAX_AXES` units are drawn (the notes say how many of how many).  Nothing
    drawable, or a ``t`` that is not finite seconds, is a GearcliError; nothing is written
    then.
    """
    name, out = out, check_output_path(out)
    output_target(name, [path])   # the name as given: Path('fig.png/') would drop the '/'
    table = open_loads(path)
    where = table.path
    wanted = select_columns(table.names, patterns, where)
    t = table.time()
    series, units, left_out, gaps = {}, {}, [], []
    skipped = 0
    repeated = {n for n, k in Counter(table.names).items() if k > 1}
    for i in wanted:
        if len(series) == MAX_LINES:
            skipped += 1
            continue
        unit = table.units[i]
        if unit not in set(units.values()) and len(set(units.values())) == MAX_AXES:
            skipped += 1
            continue
        try:
            v, missing = (t, 0) if i == 0 else table.values(i)
        except Undrawable as exc:
            left_out.append(f"'{shown(table.names[i], 40)}' ({exc})")
            continue
        label = table.names[i]
        if label in repeated:
            label = f"{label} [column {i + 1}]"
        series[label], units[label] = v, unit
        if missing:
            gaps.append(f"'{shown(table.names[i], 40)}' ({missing} of {len(v)})")
    if not series:
        raise GearcliError(f"{where}: nothing to draw: {_listed(left_out)}" if len(left_out) == 1 else
                           f"{where}: none of the {len(left_out):,} matching columns can be drawn: {_listed(left_out)}")
    notes = []
    if left_out:
        notes.append(f"{where}: left out {_count(len(left_out), 'column')} that cannot be drawn: {_listed(left_out)}")
    if skipped:
        notes.append(f"{where}: drew {len(series)} of {_count(len(wanted), 'matching column')} (at most {MAX_LINES} "
                     f"lines on {MAX_AXES} axes); name fewer columns or a narrower pattern to see the others")
    if gaps:
        notes.append(f"{where}: missing values drawn as gaps: {_listed(gaps)}")
    t_label = f"t [s] since {table.t_origin}" if table.t_origin else "t [s]"
    notes += plot_columns(t, series, units, out, title=Path(path).name, t_label=t_label)
    return PlotReport(len(series), len(wanted), notes)


def _count(n: int, noun: str) -> str:
    return f"{n:,} {plural(n, noun)}"


def _listed(items: list[str], shown_at_most: int = 3) -> str:
    more = len(items) - shown_at_most
    return ", ".join(items[:shown_at_most]) + (f" and {more:,} more" if more > 0 else "")
