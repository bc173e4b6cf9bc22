"""Figures (matplotlib, optional extra ``plot``): output columns over time, and a design
check's quantity along its worst trajectory with its limit.

Files are written through a temporary file and renamed; the format follows the extension
(``.png``, ``.svg``, ``.pdf``).
"""
from __future__ import annotations

import fnmatch
import re
import zipfile
from pathlib import Path

import numpy as np

from ..errors import GearcliError, counted
from ..io.output import atomic_output, output_target
from .columns import column_unit
from .table_files import format_of

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


def select_columns(header: list[str], patterns: list[str], file: str) -> list[str]:
    """Columns of ``header`` matching any of ``patterns`` (names or shell globs), in header
    order; a pattern that matches nothing is an error."""
    out = []
    for p in patterns:
        hits = [h for h in header if fnmatch.fnmatchcase(h, p)]
        if not hits:
            raise GearcliError(f"{file}:1: no column matches '{p}'")
        out += [h for h in hits if h not in out]
    return [h for h in header if h in out]


def plot_columns(t: np.ndarray, series: dict, units: dict, out: str | Path, title: str = "") -> None:
    """Columns over time: one axis per unit (sharing t), units on the axes.

    ``series`` maps column name to (N,) values, ``units`` column name to its unit.
    """
    plt = _pyplot()
    groups: dict[str, list[str]] = {}
    for name in series:
        groups.setdefault(units[name], []).append(name)
    fig, axes = plt.subplots(len(groups), 1, sharex=True, figsize=(8, 2.6 * len(groups) + 0.6), squeeze=False)
    for ax, (unit, names) in zip(axes[:, 0], groups.items()):
        for n in names:
            ax.plot(t, series[n], label=n, lw=1.2)
        ax.set_ylabel(f"[{unit}]" if unit else "value")
        ax.grid(alpha=0.3)
        ax.legend(fontsize="small", loc="best")
    axes[-1, 0].set_xlabel("t [s]")
    if title:
        axes[0, 0].set_title(title)
    fig.tight_layout()
    _save(fig, check_output_path(out))


def plot_check(t: np.ndarray, y: np.ndarray, limit: float, out: str | Path, title: str, ylabel: str,
               limit_label: str) -> None:
    """A check's quantity ``y`` over ``t`` (its worst trajectory) and the level ``limit``."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 3.2))
    ax.plot(t, y, lw=1.2, label="value")
    if np.isfinite(limit):
        ax.axhline(limit, color="red", ls="--", lw=1.2, label=limit_label)
    ax.set_xlabel("t [s]")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize="medium")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", loc="best")
    fig.tight_layout()
    _save(fig, check_output_path(out))


def read_loads_csv(path: str | Path) -> tuple[list[str], np.ndarray]:
    """Header and (N, ncol) data of a loads CSV; bad files raise GearcliError naming the row."""
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise GearcliError(f"{path}: cannot read file: {getattr(exc, 'strerror', None) or exc}") from None
    if not lines:
        raise GearcliError(f"{path}: empty file")
    header = lines[0].split(",")
    if header[0] != "t":
        raise GearcliError(f"{path}:1: the first column must be 't' (a CSV written by gearcli solve)")
    rows = []
    for i, line in enumerate(lines[1:], start=2):
        cells = line.split(",")
        if len(cells) != len(header):
            raise GearcliError(f"{path}:{i}: {counted(len(cells), 'cell')}, the header has {len(header)}")
        try:
            rows.append([float(c) for c in cells])
        except ValueError:
            bad = next(j for j, c in enumerate(cells) if not _is_float(c))
            raise GearcliError(f"{path}:{i}: column {bad + 1} '{header[bad]}': not a number") from None
    if not rows:
        raise GearcliError(f"{path}: no data rows")
    return header, np.array(rows)


def _is_float(text: str) -> bool:
    try:
        float(text)
        return True
    except ValueError:
        return False


OUTPUT_COLUMN = re.compile(r"t|tau:[^:]+|motor:[^:]+(:speed|:power)?|gear:[^:]+:(t|sep|torque)"
                           r"|gear:[^:]+:[^:]+:(radial|axial)|joint:[^:]+:(fx|fy|fz|mx|my|mz|radial|axial|bending)")


def csv_unit(name: str) -> str:
    """Unit of a CSV column from its name (a CSV carries none): that of the output column
    of that name (N*m for tau:/motor: columns, also of a prismatic joint: only the binary
    formats know), none ('') for a name that is not an output column (e.g. q:J1)."""
    return column_unit(name) if OUTPUT_COLUMN.fullmatch(name) else ""


def read_loads(path) -> tuple[list[str], np.ndarray, dict]:
    """Header, (N, ncol) data and units (column -> unit) of a loads file written by
    ``gearcli solve``: CSV (units from the column names), Parquet, Feather or NPZ (units
    from the file's metadata)."""
    fmt = format_of(str(path))
    if fmt in (None, "csv"):
        header, data = read_loads_csv(path)
        return header, data, {n: csv_unit(n) for n in header}
    try:
        if fmt == "npz":
            if not zipfile.is_zipfile(path):     # np.load: EOFError on an empty file, pickle talk on others
                raise ValueError("not an npz file (no zip archive)")
            with np.load(path, allow_pickle=False) as z:
                header, units = [str(c) for c in z["columns"]], [str(u) for u in z["units"]]
                data = np.asarray(z["loads"], dtype=float)
        else:
            header, data, units = _read_arrow(path, fmt)
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
        raise GearcliError(f"{path}: cannot read the {fmt} file: {getattr(exc, 'strerror', None) or exc}") from None
    if not header or header[0] != "t" or data.ndim != 2 or data.shape[1] != len(header):
        raise GearcliError(f"{path}: not a loads table written by gearcli solve (first column 't')")
    return header, data, dict(zip(header, (u.replace("*", "·") for u in units)))


def _read_arrow(path, fmt: str):
    import pyarrow.feather as feather  # noqa: PLC0415
    import pyarrow.parquet as pq  # noqa: PLC0415

    t = pq.read_table(path) if fmt == "parquet" else feather.read_table(path)
    units = [(f.metadata or {}).get(b"unit", b"").decode() for f in t.schema]
    data = np.column_stack([t.column(i).to_numpy() for i in range(t.num_columns)]) if t.num_columns else np.zeros((0, 0))
    return t.column_names, data.astype(float), units


def plot_loads_csv(path, patterns: list[str], out) -> int:
    """Plot the columns of a loads file (CSV, Parquet, Feather, NPZ) matching
    ``patterns`` into ``out``; returns their count."""
    name, out = out, check_output_path(out)
    output_target(name, [path])   # the name as given: Path('fig.png/') would drop the '/'

    header, data, units = read_loads(path)
    names = select_columns(header, patterns, str(path))
    series = {n: data[:, header.index(n)] for n in names}
    plot_columns(data[:, 0], series, {n: units[n] for n in names}, out, title=Path(path).name)
    return len(names)
