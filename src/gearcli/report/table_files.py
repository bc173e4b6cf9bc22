"""Output table files, written chunk by chunk: CSV, Parquet, Feather (Arrow IPC), NPZ.

The format follows the extension of the output name (:func:`format_of`).  Every writer
takes a file object opened by :func:`gearcli.io.output.atomic_output` (text for CSV,
binary for the others), the column names and units, and file metadata; ``write(tab)``
appends a chunk ``(n, ncol)`` of rows and ``close()`` finishes the file.

* ``.csv``: header line, then ``"%.<precision>g"`` values (:mod:`gearcli.report.csv_text`).
* ``.parquet`` / ``.feather``: one float64 column per output column, each with field
  metadata ``unit`` (ASCII, e.g. ``N*m``); file (schema) metadata ``gearcli_version``,
  ``mechanism``, ``trajectory``, ``conventions``.  pyarrow (a dependency) writes them; one
  Parquet row group / Arrow record batch per chunk;
  Parquet pages uncompressed (:data:`PARQUET_OPTIONS`).
* ``.npz``: one 2-D float64 array ``loads`` (N, ncol) in column order, plus ``columns``
  and ``units`` (ncol,) string arrays and one 0-d string array per metadata key; streamed
  into the zip (ZIP64), so the number of rows must be known in advance.
"""
from __future__ import annotations

import os
import zipfile
from pathlib import Path

import numpy as np

from .csv_text import write_rows

FORMATS = {".csv": "csv", ".parquet": "parquet", ".feather": "feather", ".npz": "npz"}
"""Output file extension -> format (a name without extension is CSV)."""

CONVENTIONS = ("SI units (s, N, N*m, rad/s, W); joint:<j>:* = wrench of the parent on the child in the "
               "joint frame about its origin; motor:<m> = torque on the input link about its positive joint "
               "axis; gear:<pair>:t = tangential tooth force on gear j by gear k, positive turning j "
               "positively; columns as in docs/reference/outputs.md")
"""One line on the frames and sign conventions, stored in binary files' metadata."""

COMPILED_MIN_VALUES = 2_000_000
"""CSV outputs of at least this many values use the compiled formatter (its import and
cached compilation cost ~1 s, Python's formatting ~0.4 us a value)."""


PARQUET_OPTIONS = {"compression": "none", "use_dictionary": False, "write_statistics": ["t"],
                   "write_batch_size": 1 << 16}
"""Parquet writer options: pages uncompressed (float64 loads hardly compress: snappy saved 12%
of the 1e6-sample Bendix file, mostly on constant columns, and made its writing 2.5x slower);
min/max statistics only for the time column (row-group pruning by time; computing them for
every column cost ~20% of the writing); a chunk's column encoded in one batch (the default,
1,024 values a batch, cost 10% more; the file is the same)."""


def format_of(name: str) -> str | None:
    """Format of the output file ``name`` by its extension (case-insensitive): ``csv``
    (also for a name without extension and ``-``, stdout), ``parquet``, ``feather``,
    ``npz``; None for another extension.  A name that is only an extension (``.parquet``,
    a hidden file to :class:`~pathlib.Path`) has that extension."""
    suffix = extension(name).lower() if name != "-" else ""
    return "csv" if suffix == "" else FORMATS.get(suffix)


def extension(name: str) -> str:
    """The extension of file ``name`` as written ('' for none; ``.parquet`` for ``.parquet``)."""
    return Path("x" + Path(name).name).suffix


def ascii_unit(unit: str) -> str:
    """``N·m`` -> ``N*m`` (units in binary files' metadata are ASCII)."""
    return unit.replace("·", "*")


class CsvTable:
    """CSV: header, then rows of ``precision`` significant digits."""

    def __init__(self, f, names, units, metadata, *, precision: int = 9, rows: int | None = None,
                 jobs: int | None = None):
        self.f, self.precision = f, precision
        self.jobs = jobs or os.cpu_count() or 1
        self.compiled = rows is not None and rows * len(names) >= COMPILED_MIN_VALUES
        f.write(",".join(names) + "\n")

    def write(self, tab: np.ndarray) -> None:
        write_rows(self.f, tab, self.precision, compiled=self.compiled, jobs=self.jobs)

    def close(self) -> None:
        pass

    def abort(self) -> None:
        """Release the writer after a failure (the output file is discarded anyway)."""


class ArrowTable:
    """Parquet or Feather (Arrow IPC file) through pyarrow, one batch per chunk."""

    def __init__(self, f, names, units, metadata, *, kind: str = "parquet", **_):
        import pyarrow as pa  # noqa: PLC0415 (heavy import, only for these formats)

        self.pa = pa
        fields = [pa.field(n, pa.float64(), nullable=False, metadata={"unit": ascii_unit(u)})
                  for n, u in zip(names, units)]
        self.schema = pa.schema(fields, metadata={k: str(v) for k, v in metadata.items()})
        if kind == "parquet":
            import pyarrow.parquet as pq  # noqa: PLC0415

            self.writer = pq.ParquetWriter(f, self.schema, **PARQUET_OPTIONS)
        else:
            self.writer = pa.ipc.new_file(f, self.schema)

    def write(self, tab: np.ndarray) -> None:
        cols = np.ascontiguousarray(np.asarray(tab, float).T)
        self.writer.write_table(self.pa.Table.from_arrays(list(cols), schema=self.schema))

    def close(self) -> None:
        self.writer.close()

    def abort(self) -> None:
        """Release the writer after a failure (the output file is discarded anyway)."""
        _quietly(self.writer.close)


class NpzTable:
    """NPZ: arrays ``loads`` (N, ncol), ``columns``, ``units`` and the metadata strings."""

    def __init__(self, f, names, units, metadata, *, rows: int | None = None, **_):
        if rows is None:
            raise ValueError("NpzTable needs the number of rows in advance")
        self.rows, self.done = rows, 0
        self.zip = zipfile.ZipFile(f, "w", compression=zipfile.ZIP_STORED, allowZip64=True)
        self.member = None
        try:
            self._array("columns", np.array(names, dtype=str))
            self._array("units", np.array([ascii_unit(u) for u in units], dtype=str))
            for key, value in metadata.items():
                self._array(key, np.array(str(value)))
            self.member = self.zip.open("loads.npy", "w", force_zip64=True)
            header = {"descr": "<f8", "fortran_order": False, "shape": (rows, len(names))}
            np.lib.format.write_array_header_1_0(self.member, header)
        except BaseException:
            self.abort()
            raise

    def _array(self, name: str, a: np.ndarray) -> None:
        with self.zip.open(name + ".npy", "w") as m:
            np.lib.format.write_array(m, a, allow_pickle=False)

    def write(self, tab: np.ndarray) -> None:
        tab = np.ascontiguousarray(tab, dtype="<f8")
        self.done += tab.shape[0]
        if self.done > self.rows:
            raise ValueError(f"NpzTable: more rows than the {self.rows} announced")
        self.member.write(memoryview(tab).cast("B"))

    def close(self) -> None:
        if self.done != self.rows:
            raise ValueError(f"NpzTable: {self.done} rows written, {self.rows} announced")
        self.member.close()
        self.zip.close()

    def abort(self) -> None:
        """Release the writer after a failure (the output file is discarded anyway)."""
        if self.member is not None:
            _quietly(self.member.close)
        _quietly(self.zip.close)


def _quietly(close) -> None:
    try:
        close()
    except Exception:   # noqa: BLE001 (the failure being reported is the first one)
        pass


def open_table(fmt: str, f, names, units, metadata, *, precision: int = 9, rows: int | None = None,
               jobs: int | None = None):
    """The writer of format ``fmt`` (see :data:`FORMATS`) on the open file ``f``; ``jobs``
    threads format CSV (default: all cores)."""
    if fmt == "csv":
        return CsvTable(f, names, units, metadata, precision=precision, rows=rows, jobs=jobs)
    if fmt in ("parquet", "feather"):
        return ArrowTable(f, names, units, metadata, kind=fmt)
    return NpzTable(f, names, units, metadata, rows=rows)
