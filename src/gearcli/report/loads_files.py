"""Loads tables read back for ``gearcli plot``: files gearcli wrote, and files other programs
wrote in the same formats (CSV, Parquet, Feather, NPZ).

:func:`open_loads` reads a file's column names and units; :meth:`LoadsFile.values` gives one
column as float64 values (N,), or raises :class:`Undrawable` saying why it cannot be drawn
(strings, structs, lists, timestamps in a column other than ``t``, no finite value, values
beyond :data:`DRAWABLE`).  :meth:`LoadsFile.time` gives ``t`` in seconds.  A file that is not a
loads table at all (unreadable, no ``t`` first, an npz whose ``columns``/``units``/``loads``
arrays do not fit together, no rows) is a :class:`~gearcli.errors.GearcliError`: one line
naming the file and the place (CSV line and column, npz array, column name and row).

The first column must be ``t``.  In Parquet and Feather files it may be a timestamp (drawn as
seconds since the first row, :attr:`LoadsFile.t_origin` says which) or a duration (seconds);
any other ``t`` must hold finite numbers.  Integers, booleans, decimals and
dictionary-encoded numbers are drawn as float64; a null (missing) value is a gap, counted by
:meth:`LoadsFile.values`.
"""
from __future__ import annotations

import os
import re
import stat
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import GearcliError, capped, counted
from .table_files import format_of

DRAWABLE = 1e300
"""Largest magnitude drawn: matplotlib cannot lay out an axis over ±1e308 (its tick locator
fails on the span) and works up to ±1e307; a value beyond this bound leaves its column out."""

NAME_SHOWN = 60
"""Characters of a column name, unit or file name shown in a figure or message."""


class Undrawable(Exception):
    """A column that cannot be drawn; ``str()`` says why (gearcli's words)."""


def shown(text, limit: int = NAME_SHOWN) -> str:
    """``text`` as gearcli shows it: control, invisible and surrogate characters escaped
    (``\\n``, ``\\x00``, ``\\ud800``), cut to ``limit`` characters with an ellipsis."""
    text = str(text)[:limit + 1]
    text = "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text)
    return capped(text, limit)


@dataclass
class LoadsFile:
    """A loads table: ``names`` (file order, duplicates kept), ``units`` (same length, ''
    when the file has none), ``rows``; how to read a column depends on the format."""

    path: str
    names: list[str]
    units: list[str]
    rows: int
    _column: object       # index -> raw column (CSV: list of str; npz: float array; arrow: ChunkedArray)
    fmt: str
    t_origin: str = ""    # the first timestamp, when t holds timestamps

    def where(self, i: int, row: int | None = None) -> str:
        """``FILE:LINE: column K 'NAME'`` (CSV) or ``FILE: column 'NAME'[, row R]``."""
        if self.fmt == "csv":
            line = f":{row + 2}" if row is not None else ":1"
            return f"{self.path}{line}: column {i + 1} '{shown(self.names[i])}'"
        return f"{self.path}: column '{shown(self.names[i])}'" + (f", row {row + 1}" if row is not None else "")

    def values(self, i: int) -> tuple[np.ndarray, int]:
        """Column ``i`` as float64 (N,) and its number of missing (NaN) values; raises
        :class:`Undrawable` when nothing of it can be drawn, GearcliError for a CSV cell that
        is not a number (a CSV has no types: that is a mistake in the file)."""
        raw = self._column(i)
        if self.fmt == "csv":
            v = _csv_floats(raw, lambda row: self.where(i, row))
        elif self.fmt == "npz":
            v = raw
        else:
            v = _arrow_floats(raw)
        missing = int(np.count_nonzero(np.isnan(v)))
        finite = v[np.isfinite(v)]
        if finite.size == 0:
            raise Undrawable("no finite value")
        if np.abs(finite).max() > DRAWABLE:
            raise Undrawable(f"values beyond ±{DRAWABLE:g} cannot be drawn")
        if missing + finite.size < v.size:
            raise Undrawable("infinite values")
        return v, missing

    def time(self) -> np.ndarray:
        """``t`` in seconds (N,); a GearcliError naming the row of a value that is not a
        finite number of at most :data:`DRAWABLE`."""
        raw = self._column(0)
        if self.fmt == "csv":
            t = _csv_floats(raw, lambda row: self.where(0, row))
        elif self.fmt == "npz":
            t = raw
        else:
            t = self._arrow_time(raw)
        bad = ~np.isfinite(t) | (np.abs(t) > DRAWABLE)
        if bad.any():
            row = int(np.argmax(bad))
            what = (f"{t[row]:g} s is beyond ±{DRAWABLE:g} s and cannot be drawn" if np.isfinite(t[row])
                    else "a missing time" if np.isnan(t[row]) and self.fmt not in ("csv", "npz")
                    else "not a finite number")
            raise GearcliError(f"{self.where(0, row)}: {what}")
        return t

    def _arrow_time(self, col) -> np.ndarray:
        import pyarrow as pa  # noqa: PLC0415

        typ = col.type
        if pa.types.is_timestamp(typ) or pa.types.is_duration(typ):
            if col.null_count:
                raise GearcliError(f"{self.where(0, _first_null(col))}: a missing time")
            ticks = col.cast(pa.int64()).to_numpy()
            scale = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}[typ.unit]
            if pa.types.is_duration(typ):
                return ticks * scale
            span = float(ticks.max()) - float(ticks.min())
            if span * scale > DRAWABLE or span >= 2.0 ** 63:
                raise GearcliError(f"{self.where(0)}: the timestamps span more than can be drawn")
            self.t_origin = str(np.datetime64(int(ticks[0]), typ.unit)) + ("" if typ.tz is None else f" {typ.tz}")
            return (ticks - ticks[0]) * scale
        try:
            return _arrow_floats(col)
        except Undrawable as exc:
            raise GearcliError(f"{self.where(0)}: {exc} (t must be numbers of seconds, a duration or a "
                               f"timestamp)") from None


def _first_null(col) -> int:
    return int(np.argmax(col.is_null().to_numpy(zero_copy_only=False)))


def _csv_floats(cells: list[str], where) -> np.ndarray:
    try:
        return np.array([float(c) for c in cells], dtype=float)
    except ValueError:
        row = next(r for r, c in enumerate(cells) if not _is_float(c))
        raise GearcliError(f"{where(row)}: not a number") from None


def _is_float(text: str) -> bool:
    try:
        float(text)
        return True
    except ValueError:
        return False


def _arrow_floats(col) -> np.ndarray:
    """An Arrow column of numbers (integers, floats, booleans, decimals, dictionary-encoded
    numbers) as float64 with NaN for nulls; :class:`Undrawable` for any other type."""
    import pyarrow as pa  # noqa: PLC0415

    typ = col.type
    if pa.types.is_dictionary(typ):
        typ = typ.value_type
        if _numeric(typ):
            col = col.cast(typ)
    if pa.types.is_null(typ):
        raise Undrawable("no value")
    if not _numeric(typ):
        raise Undrawable(f"holds {_arrow_kind(typ)}, not numbers")
    try:
        return col.cast(pa.float64(), safe=False).to_numpy(zero_copy_only=False).astype(float, copy=False)
    except pa.ArrowException:
        raise Undrawable(f"holds {shown(typ, 40)} values that are not float numbers") from None


def _arrow_kind(typ) -> str:
    """What an Arrow type holds, in gearcli's words ('structs', 'lists', 'strings')."""
    import pyarrow as pa  # noqa: PLC0415

    t = pa.types
    for test, words in ((t.is_struct, "structs"), (t.is_map, "maps"), (t.is_union, "unions"),
                        (lambda x: t.is_list(x) or t.is_large_list(x) or t.is_fixed_size_list(x), "lists"),
                        (lambda x: t.is_string(x) or t.is_large_string(x), "strings"),
                        (lambda x: t.is_binary(x) or t.is_large_binary(x) or t.is_fixed_size_binary(x), "bytes"),
                        (t.is_timestamp, "timestamps"), (t.is_date, "dates"), (t.is_time, "times of day"),
                        (t.is_duration, "durations")):
        if test(typ):
            return words
    return f"{shown(typ, 40)} values"


def _numeric(typ) -> bool:
    import pyarrow as pa  # noqa: PLC0415

    return (pa.types.is_integer(typ) or pa.types.is_floating(typ) or pa.types.is_boolean(typ)
            or pa.types.is_decimal(typ))


# --- opening ----------------------------------------------------------------------------
def open_loads(path) -> LoadsFile:
    """The loads file ``path`` (CSV, Parquet, Feather or NPZ by its extension; CSV for any
    other) with its names and units; GearcliError when it is not a loads table."""
    fmt = format_of(str(path)) or "csv"
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError) as exc:      # ValueError: a NUL byte in the name
        raise GearcliError(f"{path}: cannot read file: {getattr(exc, 'strerror', None) or shown(exc, 200)}") from None
    if not stat.S_ISREG(mode):     # a FIFO would block for ever, /dev/zero never end
        raise GearcliError(f"{path}: not a regular file (a directory, FIFO or device)")
    if fmt == "csv":
        table = _open_csv(path)
    else:
        import pyarrow as pa  # noqa: PLC0415

        try:
            table = _open_npz(path) if fmt == "npz" else _open_arrow(path, fmt)
        except GearcliError:
            raise
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile, pa.ArrowException) as exc:
            why = getattr(exc, "strerror", None) or shown(exc, 200)
            raise GearcliError(f"{path}: cannot read the {fmt} file: {why}") from None
    if not table.names or table.names[0] != "t":
        raise GearcliError(f"{path}: not a loads table written by gearcli solve (first column 't')")
    if table.rows == 0:
        raise GearcliError(f"{path}: no data rows")
    return table


def _open_csv(path) -> LoadsFile:
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise GearcliError(f"{path}: cannot read file: {getattr(exc, 'strerror', None) or exc}") from None
    if not lines:
        raise GearcliError(f"{path}: empty file")
    names = lines[0].split(",")
    if names[0] != "t":
        raise GearcliError(f"{path}:1: the first column must be 't' (a CSV written by gearcli solve)")
    rows = [line.split(",") for line in lines[1:]]
    for r, cells in enumerate(rows):
        if len(cells) != len(names):
            raise GearcliError(f"{path}:{r + 2}: {counted(len(cells), 'cell')}, the header has {len(names)}")
    return LoadsFile(str(path), names, [csv_unit(n) for n in names], len(rows),
                     lambda i: [cells[i] for cells in rows], "csv")


def _open_npz(path) -> LoadsFile:
    if not zipfile.is_zipfile(path):     # np.load: EOFError on an empty file, pickle talk on others
        raise ValueError("not an npz file (no zip archive)")
    # our own file object: np.load leaves the file it opened unclosed when the archive is bad
    with open(path, "rb") as f, np.load(f, allow_pickle=False) as z:
        missing = [k for k in ("columns", "loads") if k not in z.files]
        if missing:
            raise GearcliError(f"{path}: not a loads table written by gearcli solve (no array "
                               f"{' or '.join(repr(k) for k in missing)})")
        names = _npz_names(path, z["columns"], "columns")
        units = _npz_names(path, z["units"], "units") if "units" in z.files else [""] * len(names)
        loads = z["loads"]
    if len(units) != len(names):
        raise GearcliError(f"{path}: 'units': {counted(len(units), 'entry', 'entries')} for "
                           f"{counted(len(names), 'column')} (one unit a column)")
    if loads.ndim != 2 or loads.shape[1] != len(names):
        raise GearcliError(f"{path}: 'loads': an array of shape (rows, {len(names)}) expected for "
                           f"{counted(len(names), 'column')}, got shape {loads.shape}")
    if loads.dtype.kind not in "biuf":
        raise GearcliError(f"{path}: 'loads': holds {_kind(loads.dtype)}, not numbers")
    data = loads.astype(float)
    return LoadsFile(str(path), names, [u.replace("*", "·") for u in units], data.shape[0],
                     lambda i: data[:, i], "npz")


def _kind(dtype: np.dtype) -> str:
    """What a numpy dtype holds, in words ('strings', 'complex numbers', 'float64 numbers')."""
    words = {"U": "strings", "S": "byte strings", "c": "complex numbers", "M": "timestamps", "m": "durations",
             "V": "structured records", "O": "objects", "b": "booleans"}
    return words.get(dtype.kind, f"{shown(dtype.name, 20)} numbers")


def _npz_names(path, arr: np.ndarray, key: str) -> list[str]:
    if arr.ndim != 1 or arr.dtype.kind not in "US":
        raise GearcliError(f"{path}: '{key}': a 1-D array of names expected, got a {arr.ndim}-d array of "
                           f"{_kind(arr.dtype)}")
    if arr.dtype.kind == "S":
        return [b.decode("utf-8", "replace") for b in arr.tolist()]
    return [str(s) for s in arr.tolist()]


def _open_arrow(path, fmt: str) -> LoadsFile:
    import pyarrow.feather as feather  # noqa: PLC0415
    import pyarrow.parquet as pq  # noqa: PLC0415

    if fmt == "parquet":      # not pq.read_table: its dataset reader refuses duplicate column names
        f = pq.ParquetFile(path)
        try:
            t = f.read()
        finally:
            f.close()
    else:
        t = feather.read_table(path)
    units = [(f.metadata or {}).get(b"unit", b"").decode("utf-8", "replace").replace("*", "·") for f in t.schema]
    return LoadsFile(str(path), [str(n) for n in t.column_names], units, t.num_rows, t.column, fmt)


# --- CSV units ----------------------------------------------------------------------------
def csv_unit(name: str) -> str:
    """Unit of a CSV column from its name (a CSV carries none): that of the output column
    of that name (N*m for tau:/motor: and joint:<J>:friction columns, also of a prismatic
    joint: only the binary formats know), none ('') for a name that is not an output column
    (e.g. q:J1)."""
    from .columns import column_unit  # noqa: PLC0415

    return column_unit(name) if OUTPUT_COLUMN.fullmatch(name) else ""


OUTPUT_COLUMN = re.compile(r"t|tau:[^:]+|motor:[^:]+(:speed|:power)?"
                           r"|gear:[^:]+:(t|sep|torque|loss|input_torque|windup|force|axial|tension_a|tension_b"
                           r"|effective_pull)"
                           r"|gear:[^:]+:[^:]+:(radial|axial)"
                           r"|joint:[^:]+:(fx|fy|fz|mx|my|mz|radial|axial|bending|friction|loss)")
