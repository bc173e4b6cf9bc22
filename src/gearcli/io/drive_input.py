"""The input of ``gearcli simulate``: motor torques or DC-motor voltages over time (CSV).

Format: a header row, then one row per sample; ``t`` (s, strictly increasing) and, for
every motor ``m`` of the mechanism, either ``motor:<m>`` (its torque, N*m; N for a linear
input: the torque the motor applies to its input link about its positive joint axis, as the
``motor:`` columns ``gearcli solve`` writes) or ``voltage:<m>`` (V, for a motor with a DC
model ``motors[].model``; |V| at most its ``supply_voltage``).  Values are linear between
rows.  Cells, values and times are checked as in a trajectory file (one line naming the
file, line and column): :class:`~.trajectory.TrajectoryReader` reads the rows.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import counted
from .csv_rows import check_utf8, column_place, fail, show, split_row
from .trajectory import SEPARATORS, TrajectoryReader


@dataclass
class DriveInput:
    """``t`` (n,) s; ``values`` (n, M) per motor in ``mech.motors`` order: N*m for a torque
    column, V for a voltage column; ``voltage`` (M,) bool: which motors are driven by
    voltage; ``line`` (n,) the file line of every row."""

    t: np.ndarray
    values: np.ndarray
    voltage: np.ndarray
    line: np.ndarray
    file: str
    attach: dict = field(default_factory=dict)   # {payload: (n,) 0 or 1}, held from each row to the next

    def attach_flags(self, t) -> np.ndarray:
        """(n, P) 0/1 of every payload (``attach`` order) at the times t (n,): each row's
        ``attach:`` value holds until the next row (a pick or a place is a step, not a ramp)."""
        i = np.maximum(np.searchsorted(self.t, np.atleast_1d(t), side="right") - 1, 0)
        return np.column_stack([v[i] for v in self.attach.values()]) if self.attach else np.zeros((len(i), 0))

    def attached_at(self, t: float) -> tuple[str, ...]:
        """The payloads attached at time t (:meth:`attach_flags`)."""
        flags = self.attach_flags(t)[0]
        return tuple(name for name, f in zip(self.attach, flags) if f == 1.0)

    def at(self, t) -> np.ndarray:
        """The values at time(s) t: (M,) for a scalar t, (n, M) for an array; linear between
        rows, the first or last row's values outside them."""
        tt = np.asarray(t, float)
        out = np.stack([np.interp(tt, self.t, self.values[:, k]) for k in range(self.values.shape[1])], axis=-1)
        return out


class _DriveReader(TrajectoryReader):
    """The row reading of :class:`TrajectoryReader` with the columns of a drive input."""

    def __init__(self, path, motors, payloads=()):   # noqa: super().__init__ is for q columns
        self.payloads = tuple(payloads)
        self.path, self.names, self.degrees, self.loads, self.linear = Path(path), [], False, (), set()
        self.chunk, self.file = 1 << 62, str(path)
        with self._open() as f:
            head = self._readline(f, 1).removeprefix("\ufeff")
        if not head.strip():
            raise fail(self.file, 1, "", "empty file (expected a header row: t,motor:<motor>,...)")
        check_utf8(self.file, [head], [1])
        self.sep = next((s for s in SEPARATORS if s in head), ",")
        self.header = split_row(head, self.sep)
        self.cols = {"t": self._drive_columns(motors)}
        self.scale = np.ones(len(self.header))

    def _drive_columns(self, motors) -> int:
        pos: dict[str, int] = {}
        for i, h in enumerate(self.header):
            if h in pos:
                raise fail(self.file, 1, column_place(self.header, i), "duplicate column")
            pos[h] = i
        names = {m.name: m for m in motors}
        expected = "expected t and, for every motor, motor:<motor> (N*m) or voltage:<motor> (V)"
        self.attach_cols = {}
        for h, i in pos.items():
            kind, _, name = h.partition(":")
            if kind == "attach":
                if name not in self.payloads:
                    raise fail(self.file, 1, column_place(self.header, i), f"'{show(name)}' is not a payload "
                               f"(mechanism payloads: {', '.join(self.payloads) or 'none'})")
                self.attach_cols[name] = i
                continue
            if h != "t" and (kind not in ("motor", "voltage") or name not in names):
                what = f"'{show(name)}' is not a motor of the mechanism" if kind in ("motor", "voltage") else "unknown column"
                raise fail(self.file, 1, column_place(self.header, i), f"{what} ({expected}: {', '.join(names)})")
            if kind == "voltage" and names[name].model is None:
                raise fail(self.file, 1, column_place(self.header, i), f"motor '{name}' has no DC model "
                            "(motors[].model: kt, resistance, supply_voltage) to turn a voltage into a torque")
        if "t" not in pos:
            raise fail(self.file, 1, "", "missing column 't' (time, s)")
        for m in motors:
            both = [f"{k}:{m.name}" for k in ("motor", "voltage") if f"{k}:{m.name}" in pos]
            if len(both) != 1:
                what = "both motor: and voltage: columns" if both else "no column"
                raise fail(self.file, 1, "", f"motor '{m.name}' has {what} (give one of 'motor:{m.name}' "
                            f"(torque, N*m) and 'voltage:{m.name}' (V))")
        self.motor_cols = [pos.get(f"motor:{m.name}", pos.get(f"voltage:{m.name}")) for m in motors]
        self.voltage = np.array([f"voltage:{m.name}" in pos for m in motors])
        return pos["t"]


def read_drive_input(path, motors, payloads=()) -> DriveInput:
    """Read and check a drive input CSV for ``motors`` (``mech.motors``) and the payload
    names ``payloads`` (``attach:<payload>`` columns, 0 or 1); raises
    :class:`~gearcli.errors.TrajectoryError` naming the file, line and column."""
    r = _DriveReader(path, motors, payloads)
    parts = list(r._raw())
    data = np.concatenate([d for d, _ in parts]) if parts else np.zeros((0, len(r.header)))
    lines = np.concatenate([ln for _, ln in parts]) if parts else np.zeros(0, int)
    if len(data) == 0:
        raise fail(r.file, None, "", "no samples after the header")
    values = data[:, r.motor_cols]
    for k, m in enumerate(motors):
        if r.voltage[k]:
            over = np.flatnonzero(np.abs(values[:, k]) > m.model.supply_voltage)
            if over.size:
                i = int(over[0])
                raise fail(r.file, int(lines[i]), column_place(r.header, r.motor_cols[k]),
                            f"voltage {values[i, k]:g} V exceeds motor '{m.name}''s supply_voltage "
                            f"{m.model.supply_voltage:g} V")
    if len(data) < 2:
        raise fail(r.file, None, "", f"{counted(len(data), 'row')}: give at least 2 (values are linear between rows)")
    attach = {}
    for name, c in r.attach_cols.items():
        bad = np.flatnonzero((data[:, c] != 0.0) & (data[:, c] != 1.0))
        if bad.size:
            raise fail(r.file, int(lines[bad[0]]), column_place(r.header, c),
                       f"expected 0 or 1 (payload '{show(name)}' off or attached), got {data[bad[0], c]:g}")
        attach[name] = data[:, c]
    return DriveInput(data[:, r.cols["t"]], values, r.voltage, lines, r.file, attach)
