"""Trajectories: CSV files of the independent joint angles, read in chunks.

Format: a header row, then one row per sample.  Columns ``t`` (s), ``q:<joint>`` (rad)
for every independent joint (the joints of the equivalent open-loop chain, named as in
the mechanism file), optionally ``qd:<joint>`` (rad/s) and ``qdd:<joint>`` (rad/s^2).
With ``degrees=True`` every angle column (q, qd, qdd) is in degrees (deg, deg/s, deg/s^2);
columns of prismatic joints (``linear``) are in m, m/s, m/s^2 either way.  Optional
``load:<name>:fx`` ... ``mz`` columns override external loads per sample (:mod:`.load_columns`).

Missing rates/accelerations are derived from the positions with a quintic interpolating
spline (:func:`scipy.interpolate.make_interp_spline`, k = 5, not-a-knot ends; computed by
:mod:`.spline`, the same arithmetic without importing scipy.interpolate): for a smooth
motion sampled at step h the error of the first derivative is O(h^5) and of the second
O(h^4) (1.5e-8 rad/s^2 for a 1 Hz sine of 1 rad sampled at 1 kHz, 5e-12 rad/s on rates).  Long files are processed in
chunks; each chunk's spline is fitted over the chunk plus ``PAD`` samples of each
neighbour, so the result does not depend on the chunking to ~1e-14.

Hostile input is refused with an :class:`~gearcli.errors.Issue` naming the line and the
column: bytes that are not UTF-8 (a UTF-8 byte-order mark is accepted), a bad or empty
cell, a wrong number of cells, values that are not finite or beyond ``MAX_ABS`` in SI
units, time not increasing by at least ``MIN_STEP``, lines longer than ``MAX_LINE``.
Separators ``,``, ``;`` or tab (taken from the header) and double-quoted cells are
accepted.  Positions-only files need 3 samples (2 when rates are given): rates are then
derived by the highest-degree interpolating spline the samples allow (k = min(5, N - 1)).
"""
from __future__ import annotations

import math
import os
import stat
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import TrajectoryError
from .csv_numbers import parse_bytes
from .csv_rows import MAX_ABS, check_utf8, check_values, column_place, fail, parse_rows, show, split_row
from .load_columns import load_columns, load_samples
from .spline import derivatives
from .text_lines import line_chunks, plain_chunks

PAD = 64
MIN_STEP = 1e-9       # s, smallest time step
MAX_LINE = 1 << 20    # characters per line
FAST_PARSE_ROWS = 2000   # from this many rows a chunk is parsed by pyarrow (its import: ~0.2 s)
SEPARATORS = ",;\t"


@dataclass
class Trajectory:
    """Samples of the independent joints: ``t`` (N,), ``q``, ``qd``, ``qdd`` (N, dof);
    ``line`` (N,) the file line of every sample (None for arrays not read from a file);
    ``loads`` {load name: (N, 6)} for the external loads with ``load:`` columns;
    ``attach`` {payload name: (N,) 0 or 1} for the payloads with ``attach:`` columns."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    line: np.ndarray | None = None
    loads: dict | None = None
    attach: dict | None = None


def _expected(names: list[str]) -> str:
    qs = [f"q:{n}" for n in names[:6]] + (["…"] if len(names) > 6 else [])
    return "expected t, " + ", ".join(qs) + " and optional qd:/qdd: columns, separated by ',', ';' or tab"


def _columns(header: list[str], names: list[str], file: str, loads=(), payloads=()) -> dict:
    """Map of column kind -> list of column indices (or None) per independent joint,
    ``"load"`` -> the load columns (:func:`~.load_columns.load_columns`) and ``"attach"`` ->
    {payload: column} of the ``attach:<payload>`` columns (``payloads``: their names)."""
    pos: dict[str, int] = {}
    for i, h in enumerate(header):
        if h in pos:
            raise fail(file, 1, column_place(header, i), "duplicate column")
        pos[h] = i
    lcols = load_columns(pos, loads, file)
    known = {"t"} | {f"{p}:{n}" for p in ("q", "qd", "qdd") for n in names}
    known |= {h for h in pos if h.startswith("load:")}
    attach = {}
    for h, i in pos.items():
        if h.startswith("attach:"):
            if h[7:] not in payloads:
                raise fail(file, 1, column_place(header, i), f"'{show(h[7:])}' is not a payload (mechanism payloads: "
                           f"{show(', '.join(payloads), 80) or 'none'})")
            attach[h[7:]] = i
            known.add(h)
    for h, i in pos.items():
        if h not in known:
            joint = h.partition(":")[2] if h.partition(":")[0] in ("q", "qd", "qdd") else ""   # e.g. a gear shaft
            what = ("unknown column" + (f": '{show(joint)}' is not an independent joint" if joint else "")) if h else "empty column name"
            raise fail(file, 1, column_place(header, i), f"{what} ({_expected(names)})")
    if "t" not in pos:
        raise fail(file, 1, "", "missing column 't' (time, s)")
    for n in names:
        if f"q:{n}" not in pos:
            raise fail(file, 1, "", f"missing column 'q:{show(n)}' (independent joint '{show(n)}')")
    out = {"t": pos["t"], "load": lcols, "attach": attach}
    for p in ("q", "qd", "qdd"):
        cols = [pos.get(f"{p}:{n}") for n in names]
        if p != "q" and any(c is None for c in cols) and any(c is not None for c in cols):
            missing = [f"{p}:{n}" for n, c in zip(names, cols) if c is None]
            raise fail(file, 1, "", f"give {p}: columns for every joint or for none (missing "
                        f"{show(', '.join(missing), 80)})")
        out[p] = None if cols[0] is None else cols
    return out


def _check_time(t: np.ndarray, last_t: float | None, linenos: list[int], place: str, file: str) -> None:
    """Time must increase by at least ``MIN_STEP`` (also across chunks)."""
    tt = t if last_t is None else np.concatenate([[last_t], t])
    off = 0 if last_t is None else 1
    dt = np.diff(tt)
    bad = np.flatnonzero(dt < MIN_STEP * (1 - 1e-6))   # 1e-6: rounding of t values
    if bad.size == 0:
        return
    r = int(bad[0])
    ln = linenos[r + 1 - off]
    if dt[r] <= 0:
        raise fail(file, ln, place, f"time {tt[r + 1]:.9g} s is not after the previous {tt[r]:.9g} s "
                   "(time must increase strictly)")
    raise fail(file, ln, place, f"time step {dt[r]:.3g} s after t = {tt[r]:.9g} s is below the minimum "
                f"{MIN_STEP:g} s")


KEEP_BYTES = 128 << 20
"""Most bytes of checked rows held at once (:func:`keep_rows`)."""

_KEPT: dict = {}


def keep_rows(key: tuple | None, parts: list) -> bool:
    """Hold the checked rows ``parts`` ([(rows in SI units, line numbers)], as
    :meth:`TrajectoryReader._raw` yields them) of a file for its next reader in this process
    (``gearcli verify`` checks every trajectory before any work, then solves each: read
    once, not twice).  Taken once; the file's identity and modification time are in
    ``key``, so a changed file is read again.  Not held beyond :data:`KEEP_BYTES` in all;
    :func:`forget_rows` drops what was not taken.  True when held."""
    size = sum(d.nbytes + ln.nbytes for d, ln in parts)
    if key is None or size + sum(d.nbytes + ln.nbytes for v in _KEPT.values() for d, ln in v) > KEEP_BYTES:
        return False
    _KEPT[key] = parts
    return True


def forget_rows() -> None:
    """Drop every row held by :func:`keep_rows`."""
    _KEPT.clear()


class TrajectoryReader:
    """Reads a trajectory CSV in chunks of ``chunk`` samples (see module docstring).

    Iterating yields :class:`Trajectory` chunks in SI units.  ``names`` are the independent
    joint names (``Analysis.independent_names``); ``linear`` names those of prismatic joints,
    which ``degrees`` leaves alone; ``loads`` the mechanism's external loads
    (:class:`~gearcli.model.loads.Load`), whose ``load:`` columns override them per sample
    (never scaled by ``degrees``).  Every problem raises
    :class:`~gearcli.errors.TrajectoryError` with an :class:`~gearcli.errors.Issue`.
    """

    def __init__(self, path: str | Path, names, degrees: bool = False, chunk: int = 100_000,
                 linear=(), loads=(), payloads=()):
        self.path, self.names, self.degrees = Path(path), list(names), degrees
        self.loads = tuple(loads)
        self.payloads = tuple(payloads)
        self.linear = set(linear)
        self.chunk = max(int(chunk), 2 * PAD + 1)
        self.file = str(path)
        with self._open() as f:
            head = self._readline(f, 1)
        head = head.removeprefix("\ufeff")
        if not head.strip():
            raise fail(self.file, 1, "", "empty file (expected a header row: t,q:<joint>,...)")
        check_utf8(self.file, [head], [1])
        self.sep = next((s for s in SEPARATORS if s in head), ",")
        self.header = split_row(head, self.sep)
        self.cols = _columns(self.header, self.names, self.file, self.loads, self.payloads)
        self.scale = self._column_scale()

    def _open(self):
        """The file as text (undecodable bytes kept as surrogates, refused per chunk)."""
        try:
            if not stat.S_ISREG(os.stat(self.path).st_mode):
                raise fail(self.file, None, "", "not a regular file")
            return open(self.path, encoding="utf-8", errors="surrogateescape")
        except OSError as exc:
            raise fail(self.file, None, "", f"cannot read file: {exc.strerror}") from None

    def _readline(self, f, lineno: int) -> str:
        line = f.readline(MAX_LINE)
        if len(line) == MAX_LINE and not line.endswith("\n"):
            raise fail(self.file, lineno, "", f"line longer than {MAX_LINE} characters")
        return line

    def _column_scale(self) -> np.ndarray:
        """Factor to SI of every file column (pi/180 for angle columns with ``degrees``)."""
        scale = np.ones(len(self.header))
        if self.degrees:
            deg = math.pi / 180.0
            for p in ("q", "qd", "qdd"):
                for n, c in zip(self.names, self.cols[p] or ()):
                    if n not in self.linear:
                        scale[c] = deg
        return scale

    def count(self) -> int:
        """Number of samples (data rows), by a fast line count (:func:`count_rows`)."""
        return count_rows(self.path)

    def _raw(self):
        """Yield (array of rows in SI units (n, ncol), line numbers (n,)), checked: the
        chunks of plain lines straight from the bytes (:meth:`_plain_rows`), from the first
        other one on (blank or non-ASCII lines, a bad value: to report it) line by line;
        rows a check kept (:func:`keep_rows`) are taken instead, in chunks of ``chunk``."""
        kept = _KEPT.pop(self._key(), None) if _KEPT else None
        if kept is not None:
            data, lines = (np.concatenate(x) for x in zip(*kept)) if len(kept) > 1 else kept[0]
            for a in range(0, len(data), self.chunk):
                yield data[a:a + self.chunk], lines[a:a + self.chunk]
            return
        last_t = None
        with open(self.path, "rb") as f:
            f.readline()        # the header (checked in __init__)
            offset, lineno = f.tell(), 1
            for part, offset, first, rows in plain_chunks(f, offset, lineno, self.chunk, MAX_LINE):
                lineno = first - 1
                si = self._plain_rows(part, rows, last_t)
                if si is None:
                    break
                last_t = si[-1, self.cols["t"]]
                yield si, np.arange(first, first + len(si))
                offset, lineno = offset + len(part), lineno + len(si)
        yield from self._lines_raw(offset, lineno, last_t)

    def _plain_rows(self, part: bytes, rows: int, last_t: float | None) -> np.ndarray | None:
        """Rows (n, ncol) in SI units of the ``rows`` CSV lines ``part``, or None when they are
        fewer than ``FAST_PARSE_ROWS`` or any check of :meth:`_lines_raw` would fail on them."""
        data = parse_bytes(part, rows, len(self.header), self.sep) if rows >= FAST_PARSE_ROWS else None
        if data is None:
            return None
        si = data * self.scale
        t = si[:, self.cols["t"]] if last_t is None else np.concatenate([[last_t], si[:, self.cols["t"]]])
        ok = np.isfinite(data).all() and not (np.abs(si) > MAX_ABS).any()
        return si if ok and not (np.diff(t) < MIN_STEP * (1 - 1e-6)).any() else None

    def _lines_raw(self, offset: int, lineno: int, last_t: float | None):
        """:meth:`_raw` line by line from byte ``offset``, after line ``lineno``."""
        c_t = self.cols["t"]
        with self._open() as f:
            f.seek(offset)
            too_long = lambda n: fail(self.file, n, "", f"line longer than {MAX_LINE} characters")  # noqa: E731
            for lines, linenos in line_chunks(f, lineno, self.chunk, MAX_LINE, too_long):
                data = parse_rows(lines, linenos, self.header, self.sep, self.file, FAST_PARSE_ROWS)
                si = data * self.scale
                check_values(data, si, lines, linenos, self.header, self.sep, self.file)
                _check_time(si[:, c_t], last_t, linenos, column_place(self.header, c_t), self.file)
                last_t = si[-1, c_t]
                yield si, np.asarray(linenos)

    def check(self, keep: bool = False) -> int:
        """Read and check every row (cells, ranges, time) without deriving rates; the
        number of samples.  Raises like iteration would for the rows and for too few
        samples.  ``keep``: hold the checked rows for the next reader of the same unchanged
        file in this process (:func:`keep_rows`), which then does not read it again."""
        parts = list(self._raw())
        n = sum(len(data) for data, _ in parts)
        if n == 0:
            raise fail(self.file, None, "", "no samples after the header")
        need = 1 + (self.cols["qd"] is None) + (self.cols["qdd"] is None)
        if n < need:
            raise self._too_few(n, need, "q" if self.cols["qd"] is None else "qd")
        if keep:
            keep_rows(self._key(), parts)
        return n

    def _key(self) -> tuple | None:
        """What the rows of :meth:`_raw` depend on: the file (device, inode, size, modification
        time in ns) and the factor to SI of each column; None when it cannot be stat'ed."""
        try:
            st = os.stat(self.path)
        except OSError:
            return None
        return (os.path.abspath(self.path), st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, self.scale.tobytes())

    def __iter__(self):
        prev = None   # rows of the previous chunk (for the spline pad)
        pending = None
        for data, lines in self._raw():
            if pending is not None:
                yield self._finish(prev, pending, (data, lines))
                prev = pending
            pending = (data, lines)
        if pending is None:
            raise fail(self.file, None, "", "no samples after the header")
        yield self._finish(prev, pending, None)

    def _finish(self, prev, cur, nxt) -> Trajectory:
        c = self.cols
        parts = [x for x in (None if prev is None else (prev[0][-PAD:], prev[1][-PAD:]), cur,
                             None if nxt is None else (nxt[0][:PAD], nxt[1][:PAD])) if x is not None]
        a = 0 if prev is None else min(PAD, len(prev[0]))
        data = np.concatenate([p[0] for p in parts])
        lines = np.concatenate([p[1] for p in parts])
        t, q = data[:, c["t"]], data[:, c["q"]]
        qd = data[:, c["qd"]] if c["qd"] is not None else None
        qdd = data[:, c["qdd"]] if c["qdd"] is not None else None
        if qd is None:
            d = self._derive(t, q, 2 if qdd is None else 1, lines, "q")
            qd, qdd = d[0], (d[1] if qdd is None else qdd)
        elif qdd is None:
            (qdd,) = self._derive(t, qd, 1, lines, "qd")
        sl = slice(a, a + len(cur[0]))
        loads = load_samples(cur[0], c["load"], self.loads)
        attach = {}
        for name, col in c["attach"].items():
            v = cur[0][:, col]
            bad = np.flatnonzero((v != 0.0) & (v != 1.0))
            if bad.size:
                raise fail(self.file, int(cur[1][bad[0]]), column_place(self.header, col),
                           f"expected 0 or 1 (payload '{show(name)}' off or attached), got {v[bad[0]]:g}")
            attach[name] = v
        return Trajectory(t[sl], q[sl], qd[sl], qdd[sl], lines[sl], loads, attach or None)

    def _too_few(self, n: int, need: int, kind: str) -> TrajectoryError:
        given = "positions only" if kind == "q" else "no qdd: columns"
        return fail(self.file, None, "", f"{n} sample{'s' if n != 1 else ''} with {given}: rates and "
                    f"accelerations are derived by spline, which needs at least {need} samples (or "
                     "give the qd: and qdd: columns)")

    def _derive(self, t, y, order: int, lines, kind: str) -> list[np.ndarray]:
        """Spline derivatives, with a clear error when too few samples or not finite."""
        if len(t) < order + 1:
            raise self._too_few(len(t), order + 1, kind)
        try:
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                out = derivatives(t, y, order)
        except (ValueError, np.linalg.LinAlgError) as exc:
            raise fail(self.file, None, "", f"cannot fit the interpolating spline: {show(str(exc), 80)}") from None
        for i, d in enumerate(out):
            bad = ~np.isfinite(d)
            if bad.any():
                r, j = (int(x) for x in np.argwhere(bad)[0])
                what = ("qd" if i == 0 else "qdd") if kind == "q" else "qdd"
                raise fail(self.file, int(lines[r]), f"{what}:{show(self.names[j])}",
                           "derived by spline is not finite (time steps too small for the values?)")
        return out


def count_rows(path) -> int:
    """Data rows of a trajectory file (its lines less the header; a last line without its
    newline counts), by a fast line count; OSError when it cannot be read."""
    with open(path, "rb") as f:
        n = sum(buf.count(b"\n") for buf in iter(lambda: f.read(1 << 20), b""))
        if f.tell():
            f.seek(-1, 2)
            if f.read(1) != b"\n":
                n += 1
    return max(n - 1, 0)


READ_CHUNK = 1 << 17
"""Samples :func:`read_trajectory` parses at a time: the fast parser's buffers of one chunk
(~25 MB) instead of a whole file's (1e6 rows: ~180 MB, more than the arrays it makes)."""


def read_trajectory(path, names, degrees: bool = False, linear=(), loads=(), payloads=()) -> Trajectory:
    """Read a whole trajectory CSV into memory (see :class:`TrajectoryReader`), a chunk of
    :data:`READ_CHUNK` samples parsed at a time: the values of one parse, but for rates and
    accelerations derived from the angles, which depend on the chunking to ~1e-14 (the
    module docstring), as ``gearcli solve``'s do."""
    parts = list(TrajectoryReader(path, names, degrees, chunk=READ_CHUNK, linear=linear, loads=loads,
                                  payloads=payloads))
    if "pyarrow" in sys.modules:      # the fast parser's buffers, kept by its memory pool
        sys.modules["pyarrow"].default_memory_pool().release_unused()
    return parts[0] if len(parts) == 1 else _joined(parts)


def _joined(parts: list[Trajectory]) -> Trajectory:
    """One :class:`Trajectory` of consecutive chunks (for a moment both: twice the arrays)."""
    def cat(get):
        first = get(parts[0])
        if first is None:
            return None
        if isinstance(first, dict):
            return {k: np.concatenate([get(p)[k] for p in parts]) for k in first}
        return np.concatenate([get(p) for p in parts])
    fields = ("t", "q", "qd", "qdd", "line", "loads", "attach")
    return Trajectory(*(cat(lambda p, f=f: getattr(p, f)) for f in fields))


def write_trajectory(path, names, t, q, qd=None, qdd=None) -> None:
    """Write a trajectory CSV (rad, rad/s, rad/s^2)."""
    cols = [np.asarray(t)[:, None], np.asarray(q)]
    header = ["t"] + [f"q:{n}" for n in names]
    for p, x in (("qd", qd), ("qdd", qdd)):
        if x is not None:
            cols.append(np.asarray(x))
            header += [f"{p}:{n}" for n in names]
    np.savetxt(path, np.hstack(cols), delimiter=",", header=",".join(header), comments="", fmt="%.17g")
