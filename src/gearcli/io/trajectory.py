"""Trajectories: CSV files of the independent joint angles, read in chunks.

Format: a header row, then one row per sample.  Columns ``t`` (s), ``q:<joint>`` (rad)
for every independent joint (the joints of the equivalent open-loop chain, named as in
the mechanism file), optionally ``qd:<joint>`` (rad/s) and ``qdd:<joint>`` (rad/s^2).
With ``degrees=True`` every angle column (q, qd, qdd) is in degrees (deg, deg/s, deg/s^2);
columns of prismatic joints (``linear``) are in m, m/s, m/s^2 either way.

Missing rates/accelerations are derived from the positions with a quintic interpolating
spline (:func:`scipy.interpolate.make_interp_spline`, k = 5, not-a-knot ends): for a smooth
motion sampled at step h the error of the first derivative is O(h^5) and of the second
O(h^4) (1.5e-8 rad/s^2 for a 1 Hz sine of 1 rad sampled at 1 kHz, 5e-12 rad/s on rates).  Long files are processed in
chunks; each chunk's spline is fitted over the chunk plus ``PAD`` samples of each
neighbour, so the result does not depend on the chunking to ~1e-14.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.interpolate import make_interp_spline

from ..errors import TrajectoryError

PAD = 64


@dataclass
class Trajectory:
    """Samples of the independent joints: ``t`` (N,), ``q``, ``qd``, ``qdd`` (N, dof)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray


def derivatives(t: np.ndarray, y: np.ndarray, order: int = 2) -> list[np.ndarray]:
    """First ``order`` derivatives of samples ``y`` (N, m) at times ``t`` by a quintic
    interpolating spline (lower degree when there are fewer than 6 samples)."""
    n = len(t)
    k = min(5, n - 1 if (n - 1) % 2 == 1 else n - 2)
    if k < 1:
        return [np.zeros_like(y) for _ in range(order)]
    spl = make_interp_spline(t, y, k=k)
    return [spl.derivative(i)(t) for i in range(1, order + 1)]


def _columns(header: list[str], names: list[str], file: str) -> dict:
    """Map of column kind -> list of column indices (or None) per independent joint."""
    pos: dict[str, int] = {}
    for i, h in enumerate(header):
        h = h.strip()
        if h in pos:
            raise TrajectoryError(f"{file}:1: column {i + 1} '{h}': duplicate column")
        pos[h] = i
    if "t" not in pos:
        raise TrajectoryError(f"{file}:1: missing column 't' (time, s)")
    known = {"t"} | {f"{p}:{n}" for p in ("q", "qd", "qdd") for n in names}
    for h, i in pos.items():
        if h not in known:
            raise TrajectoryError(f"{file}:1: column {i + 1} '{h}': unknown column (expected t, "
                                  + ", ".join(f"q:{n}" for n in names) + " and optional qd:/qdd: columns)")
    for n in names:
        if f"q:{n}" not in pos:
            raise TrajectoryError(f"{file}:1: missing column 'q:{n}' (independent joint '{n}', rad)")
    out = {"t": pos["t"]}
    for p in ("q", "qd", "qdd"):
        cols = [pos.get(f"{p}:{n}") for n in names]
        if p != "q" and any(c is None for c in cols) and any(c is not None for c in cols):
            missing = [f"{p}:{n}" for n, c in zip(names, cols) if c is None]
            raise TrajectoryError(f"{file}:1: give {p}: columns for every joint or for none (missing {', '.join(missing)})")
        out[p] = None if cols[0] is None else cols
    return out


def _parse_rows(lines: list[str], first_row: int, header: list[str], file: str) -> np.ndarray:
    """Rows of floats; on failure, find and report the first bad cell."""
    try:
        data = np.loadtxt(lines, delimiter=",", ndmin=2, dtype=float)
        if data.shape[1] != len(header):
            raise ValueError
    except ValueError:
        for r, line in enumerate(lines):
            cells = line.rstrip("\r\n").split(",")
            row = first_row + r
            if len(cells) != len(header):
                raise TrajectoryError(f"{file}:{row}: row has {len(cells)} columns, the header has {len(header)}") from None
            for c, cell in enumerate(cells):
                try:
                    float(cell)
                except ValueError:
                    raise TrajectoryError(f"{file}:{row}: column {c + 1} '{header[c].strip()}': "
                                          f"not a number: '{cell.strip()}'") from None
        raise TrajectoryError(f"{file}:{first_row}: cannot parse rows") from None
    bad = ~np.isfinite(data)
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise TrajectoryError(f"{file}:{first_row + r}: column {c + 1} '{header[c].strip()}': "
                              f"value is {data[r, c]} (NaN or infinite)")
    return data


class TrajectoryReader:
    """Reads a trajectory CSV in chunks of ``chunk`` samples (see module docstring).

    Iterating yields :class:`Trajectory` chunks in SI units.  ``names`` are the independent
    joint names (``Analysis.independent_names``); ``linear`` names those of prismatic joints,
    which ``degrees`` leaves alone.
    """

    def __init__(self, path: str | Path, names, degrees: bool = False, chunk: int = 100_000,
                 linear=()):
        self.path, self.names, self.degrees = Path(path), list(names), degrees
        self.linear = set(linear)
        self.chunk = max(int(chunk), 2 * PAD + 1)
        self.file = str(path)
        try:
            with open(self.path) as f:
                head = f.readline()
        except OSError as exc:
            raise TrajectoryError(f"{self.file}: cannot read file: {exc.strerror}") from None
        if not head.strip():
            raise TrajectoryError(f"{self.file}:1: empty file (expected a header row)")
        self.header = [h.strip() for h in head.rstrip("\r\n").split(",")]
        self.cols = _columns(self.header, self.names, self.file)

    def count(self) -> int:
        """Number of samples (data rows), by a fast line count."""
        with open(self.path, "rb") as f:
            n = sum(buf.count(b"\n") for buf in iter(lambda: f.read(1 << 20), b""))
            f.seek(-1, 2)
            if f.read(1) != b"\n":
                n += 1
        return max(n - 1, 0)

    def _raw(self):
        """Yield (first file row number, array of rows)."""
        with open(self.path) as f:
            f.readline()
            row = 2
            while True:
                lines = [ln for ln in itertools.islice(f, self.chunk) if ln.strip()]
                if not lines:
                    return
                yield row, _parse_rows(lines, row, self.header, self.file)
                row += len(lines)

    def __iter__(self):
        scale = np.array([1.0 if (not self.degrees or n in self.linear) else math.pi / 180.0
                          for n in self.names])
        c = self.cols
        last_t = None
        prev = None   # raw rows of the previous chunk (for the spline pad)
        pending = None
        for row, data in self._raw():
            t = data[:, c["t"]]
            dt = np.diff(t)
            if last_t is not None and t[0] <= last_t:
                raise TrajectoryError(f"{self.file}:{row}: column 1 't': time {t[0]:g} s is not after the previous {last_t:g} s")
            if np.any(dt <= 0):
                r = int(np.flatnonzero(dt <= 0)[0]) + 1
                raise TrajectoryError(f"{self.file}:{row + r}: column {c['t'] + 1} 't': time {t[r]:g} s is not after "
                                      f"the previous {t[r - 1]:g} s (time must increase strictly)")
            last_t = t[-1]
            if pending is not None:
                yield self._finish(prev, pending, data, scale)
                prev = pending
            pending = data
        if pending is None:
            raise TrajectoryError(f"{self.file}: no samples after the header")
        yield self._finish(prev, pending, None, scale)

    def _finish(self, prev, cur, nxt, scale) -> Trajectory:
        c = self.cols
        parts = [x for x in (None if prev is None else prev[-PAD:], cur, None if nxt is None else nxt[:PAD]) if x is not None]
        a = 0 if prev is None else min(PAD, len(prev))
        data = np.concatenate(parts) if len(parts) > 1 else cur
        t = data[:, c["t"]]
        q = data[:, c["q"]] * scale
        qd = data[:, c["qd"]] * scale if c["qd"] is not None else None
        qdd = data[:, c["qdd"]] * scale if c["qdd"] is not None else None
        if qd is None:
            qd, d2 = derivatives(t, q, 2)
            if qdd is None:
                qdd = d2
        elif qdd is None:
            (qdd,) = derivatives(t, qd, 1)
        sl = slice(a, a + len(cur))
        return Trajectory(t[sl], q[sl], qd[sl], qdd[sl])


def read_trajectory(path, names, degrees: bool = False, linear=()) -> Trajectory:
    """Read a whole trajectory CSV into memory (see :class:`TrajectoryReader`)."""
    parts = list(TrajectoryReader(path, names, degrees, chunk=1 << 62, linear=linear))
    return parts[0]


def write_trajectory(path, names, t, q, qd=None, qdd=None) -> None:
    """Write a trajectory CSV (rad, rad/s, rad/s^2)."""
    cols = [np.asarray(t)[:, None], np.asarray(q)]
    header = ["t"] + [f"q:{n}" for n in names]
    for p, x in (("qd", qd), ("qdd", qdd)):
        if x is not None:
            cols.append(np.asarray(x))
            header += [f"{p}:{n}" for n in names]
    np.savetxt(path, np.hstack(cols), delimiter=",", header=",".join(header), comments="", fmt="%.17g")
