"""Result tables: the output CSV columns (a stable contract) and the summary statistics.

Columns, in order (units SI):

* ``t`` (s);
* ``motor:<motor>`` (N*m): torque the motor applies to its input link about that link's
  positive joint axis (N for a prismatic input);
* ``tau:<joint>`` (N*m): equivalent torques on the independent joints (paper Eq. 25);
* per gear pair with geometry ``gear:<pair>:t`` (N, tangential force on gear j by gear k,
  positive when it turns j in j's positive sense), ``gear:<pair>:sep`` (N, separating
  force magnitude), ``gear:<pair>:<link>:radial`` and ``gear:<pair>:<link>:axial`` (N,
  the tooth force on that gear along its outward radial direction at the pitch point and
  along its positive axis), for j then k; per ideal pair (no geometry)
  ``gear:<pair>:torque`` (N*m, mesh torque on j about its axis; N for a coupling of a
  prismatic joint); per reducer (``kind: strain_wave | cycloidal``) ``gear:<r>:torque`` (N*m,
  the output torque T on the output about its joint axis), ``gear:<r>:input_torque`` (N*m,
  the torque the reducer exerts on its input about the input's joint axis, losses included)
  and, with a ``torsional_stiffness``, ``gear:<r>:windup`` (rad, the output's torsion angle
  under T, odd in T; reported, not fed back); per screw ``gear:<s>:force`` (N, the axial
  force on the nut along the screw's axis z_S); per worm pair ``gear:<w>:t`` (N, the wheel's
  tangential force F . t_G, positive when the flank load drives the wheel positively about its
  axis) and ``gear:<w>:axial`` (N, the force on the worm along its axis: its thrust); per belt
  ``gear:<b>:tension_a``, ``gear:<b>:tension_b`` (N, the span tensions T_i +- E/2) and
  ``gear:<b>:effective_pull`` (N, E);
* per real joint ``joint:<joint>:fx, fy, fz, mx, my, mz`` (N, N*m): reaction wrench the
  parent exerts on the child, in the joint frame, about its origin; then
  ``joint:<joint>:radial`` = hypot(fx, fy), ``axial`` = |fz|, ``bending`` = hypot(mx, my);
* per motor ``motor:<motor>:speed`` (rad/s, m/s for a prismatic input: the motor's input
  rate A^T qd) and ``motor:<motor>:power`` (W, torque x speed, negative when braking),
  appended last so that the columns above keep their positions;
* only for a mechanism with losses (``gears[].efficiency``, ``joints[].friction``), appended
  after those: per gear pair with geometry, reducer and screw ``gear:<pair>:loss`` (W, mesh,
  reducer or screw power loss), then
  per real joint ``joint:<joint>:friction`` (N*m, N for a prismatic joint: the friction on
  the child about (along) the axis; not included in ``mz``/``fz``) and ``joint:<joint>:loss``
  (W).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..dynamics.solve import Result
from ..model.reducers import windup
from .rms import rms_of, square_integral
from ..errors import counted


def column_names(an) -> list[str]:
    """Names of the output columns of ``an``, in the stable order of the CSV (docs/reference/mechanism-files.md,
    "Output columns"): t, motors, equivalent joint torques, gear meshes, joint reactions,
    then the appended motor speed and power columns."""
    mech = an.mech
    cols = ["t"]
    cols += [f"motor:{m.name}" for m in mech.motors]
    cols += [f"tau:{n}" for n in an.independent_names]
    for c in an.circuits:
        gp = mech.gears[c.gear]
        if gp.reducer is not None:
            cols += [f"gear:{gp.name}:torque", f"gear:{gp.name}:input_torque"]
            if gp.reducer.torsional_stiffness is not None:
                cols.append(f"gear:{gp.name}:windup")
            continue
        if gp.screw is not None:
            cols.append(f"gear:{gp.name}:force")
            continue
        if gp.worm is not None:
            cols += [f"gear:{gp.name}:t", f"gear:{gp.name}:axial"]
            continue
        if gp.belt is not None:
            cols += [f"gear:{gp.name}:{k}" for k in ("tension_a", "tension_b", "effective_pull")]
            continue
        if c.geometry is None:
            cols.append(f"gear:{gp.name}:torque")
            continue
        cols += [f"gear:{gp.name}:t", f"gear:{gp.name}:sep"]
        for link in (gp.j, gp.k):
            cols += [f"gear:{gp.name}:{link}:radial", f"gear:{gp.name}:{link}:axial"]
    for jt in mech.joints:
        cols += [f"joint:{jt.name}:{c}" for c in ("fx", "fy", "fz", "mx", "my", "mz", "radial", "axial", "bending")]
    for m in mech.motors:
        cols += [f"motor:{m.name}:speed", f"motor:{m.name}:power"]
    if mech.has_losses:
        cols += [f"gear:{mech.gears[c.gear].name}:loss" for c in an.circuits if has_loss_column(an, c)]
        for jt in mech.joints:
            cols += [f"joint:{jt.name}:friction", f"joint:{jt.name}:loss"]
    return cols


def has_loss_column(an, c) -> bool:
    """True when circuit ``c`` has a ``gear:<pair>:loss`` column (a lossy mechanism's pairs with
    tooth geometry, its reducers and screws)."""
    gp = an.mech.gears[c.gear]
    return (c.geometry is not None or gp.reducer is not None or gp.screw is not None or gp.worm is not None
            or gp.belt is not None)


TRANSPOSE_ROWS = 512
"""Samples per block when the joint reactions are transposed (:func:`column_sources`)."""


def column_sources(an, t: np.ndarray, res: Result) -> dict:
    """``{column name: function computing that (N,) column}`` for every output column of
    :func:`column_names`, in its order: the one definition of the columns' values, used by
    :func:`table` (all of them) and :class:`LazyColumns` (those asked for)."""
    if res.motor_speed is None:
        raise ValueError("Result.motor_speed is missing (results come from gearcli.solve)")
    if an.mech.has_losses and res.gear_loss is None:
        raise ValueError("Result.gear_loss is missing (results of a lossy mechanism come from gearcli.solve)")
    names = iter(column_names(an))
    out = {next(names): lambda: t}

    def put(f):
        out[next(names)] = f

    for mi in range(res.motor.shape[1]):
        put(lambda mi=mi: res.motor[:, mi])
    for di in range(res.tau.shape[1]):
        put(lambda di=di: res.tau[:, di])
    for ci, circ in enumerate(an.circuits):
        red = an.mech.gears[circ.gear].reducer
        if red is not None:         # T = -e u on the output about z_O; the input torque (gear_sep)
            put(lambda ci=ci, e=circ.ratio: -e * res.gear_t[:, ci])
            put(lambda ci=ci: res.gear_sep[:, ci])
            if red.torsional_stiffness is not None:
                put(lambda ci=ci, e=circ.ratio, red=red: windup(red, -e * res.gear_t[:, ci]))
            continue
        bt = an.mech.gears[circ.gear].belt
        if bt is not None:                               # span tensions T_i +- E/2 and E
            put(lambda ci=ci, T=bt.pretension: T + 0.5 * res.gear_t[:, ci])
            put(lambda ci=ci, T=bt.pretension: T - 0.5 * res.gear_t[:, ci])
            put(lambda ci=ci: res.gear_t[:, ci])
            continue
        if an.mech.gears[circ.gear].worm is not None:   # the wheel's tangential force, the worm's thrust
            put(lambda ci=ci: res.gear_sep[:, ci])
            put(lambda ci=ci: res.gear_axial[:, ci, 0])
            continue
        put(lambda ci=ci: res.gear_t[:, ci])       # (a screw: its axial force F on the nut)
        if circ.geometry is not None:
            put(lambda ci=ci: res.gear_sep[:, ci])
            for side in (0, 1):
                put(lambda ci=ci, side=side: res.gear_radial[:, ci, side])
                put(lambda ci=ci, side=side: res.gear_axial[:, ci, side])
    wrenches: list = []

    def wrench(ji: int) -> np.ndarray:
        """Joint ji's reaction wrench as (6, N), rows contiguous: the result's (N, J, 6) array
        transposed once to (J, 6, N), by blocks of rows that stay in the cache (a column
        gathered alone reads a cache line per sample)."""
        if not wrenches:
            n, J = res.joint.shape[:2]
            w = np.empty((J, 6, n))
            for a in range(0, n, TRANSPOSE_ROWS):
                w[:, :, a:a + TRANSPOSE_ROWS] = res.joint[a:a + TRANSPOSE_ROWS].transpose(1, 2, 0)
            wrenches.append(w)
        return wrenches[0][ji]

    for ji in range(res.joint.shape[1]):
        for a in range(6):
            put(lambda ji=ji, a=a: wrench(ji)[a])
        put(lambda ji=ji: np.hypot(wrench(ji)[0], wrench(ji)[1]))
        put(lambda ji=ji: np.abs(wrench(ji)[2]))
        put(lambda ji=ji: np.hypot(wrench(ji)[3], wrench(ji)[4]))
    for mi in range(res.motor_speed.shape[1]):
        put(lambda mi=mi: res.motor_speed[:, mi])
        put(lambda mi=mi: res.motor[:, mi] * res.motor_speed[:, mi])
    if an.mech.has_losses:
        for ci, circ in enumerate(an.circuits):
            if has_loss_column(an, circ):
                put(lambda ci=ci: res.gear_loss[:, ci])
        for ji in range(res.joint.shape[1]):
            put(lambda ji=ji: res.joint_friction[:, ji])
            put(lambda ji=ji: res.joint_loss[:, ji])
    if next(names, None) is not None:     # pragma: no cover (column_names and this list disagree)
        raise AssertionError("column_sources does not cover column_names")
    return out


def table(an, t: np.ndarray, res: Result) -> np.ndarray:
    """The output columns of :func:`column_names` as one (N, ncol) array, in Fortran order
    (each column contiguous: a Parquet/Arrow column without copy)."""
    sources = column_sources(an, t, res)
    out = np.empty((len(t), len(sources)), order="F")
    for i, f in enumerate(sources.values()):
        out[:, i] = f()
    return out


class LazyColumns(dict):
    """The output columns as :func:`named_columns` gives them, each computed (and kept) when
    first looked up (``cols[name]``): verify's checks read a few of the ~100 columns of a
    mechanism.  Values are those of :func:`named_columns` bit for bit (the same
    :func:`column_sources`); ``in``, ``len`` and iteration see the columns looked up so far
    and any set by hand."""

    def __init__(self, an, res: Result, t: np.ndarray):
        super().__init__()
        if np.shape(t) != res.motor.shape[:1]:
            raise ValueError(f"t has shape {np.shape(t)}, the result has {counted(res.motor.shape[0], 'sample')}")
        self._sources = column_sources(an, np.asarray(t, float), res)

    def __missing__(self, name: str) -> np.ndarray:
        x = np.ascontiguousarray(self._sources[name]())    # KeyError for an unknown column
        self[name] = x
        return x


def named_columns(an, res: Result, t: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """The output CSV columns as a dict ``{column name: (N,) array}`` (see module docstring);
    ``t`` defaults to the sample index."""
    if t is None:
        t = np.arange(res.motor.shape[0], dtype=float)
    if np.shape(t) != res.motor.shape[:1]:
        raise ValueError(f"t has shape {np.shape(t)}, the result has {counted(res.motor.shape[0], 'sample')}")
    tab = table(an, np.asarray(t, float), res)
    return {name: tab[:, i] for i, name in enumerate(column_names(an))}


def column_unit(name: str) -> str:
    """SI unit of an output column from its name alone (docs/reference/outputs.md's column table; a
    prismatic input or joint changes some: :func:`column_units`)."""
    last = name.rsplit(":", 1)[-1]
    if name.startswith("motor:"):
        return {"speed": "rad/s", "power": "W"}.get(last, "N·m") if name.count(":") == 2 else "N·m"
    if last == "loss" and name.startswith(("gear:", "joint:")):
        return "W"
    if name == "t":
        return "s"
    if name.startswith("gear:") and last == "windup":
        return "rad"
    if name.startswith("tau:") or last in ("torque", "input_torque", "mx", "my", "mz", "bending") or (
            last == "friction" and name.startswith("joint:")):
        return "N·m"
    return "N"


def column_units(an) -> list[str]:
    """SI unit of every output column of ``an``, in the order of :func:`column_names`:
    :func:`column_unit`, with N (and m/s) where a motor drives a prismatic input
    directly, an independent joint slides or an ideal pair's driven joint slides."""
    linear = {m.name for m in an.mech.motors if motor_linear(an, m.name)}
    sliding = {n for n, ji in zip(an.independent_names, an.independent)
               if ji >= 0 and an.mech.joints[ji].type == "prismatic"}
    ideal = {an.mech.gears[c.gear].name: _ideal_unit(an, c) for c in an.circuits if c.geometry is None}
    joint_type = {jt.name: jt.type for jt in an.mech.joints}
    units = []
    for name in column_names(an):
        kind, _, rest = name.partition(":")
        unit = column_unit(name)
        if kind == "motor" and rest.split(":")[0] in linear:
            unit = {"speed": "m/s", "power": "W"}.get(rest.split(":")[-1], "N") if ":" in rest else "N"
        elif kind == "tau" and rest in sliding:
            unit = "N"
        elif kind == "gear" and name.endswith(":torque"):
            unit = ideal[rest[:-len(":torque")]]
        elif kind == "joint" and name.endswith(":friction"):
            unit = "N" if joint_type[rest[:-len(":friction")]] == "prismatic" else "N·m"
        units.append(unit)
    return units


@dataclass
class Stat:
    """Peak magnitude, time of the peak and time-weighted RMS of one load column (SI unit
    ``unit``); the RMS is :mod:`gearcli.report.rms`'s (trapezoid rule over time)."""

    name: str
    unit: str
    peak: float = 0.0
    t_peak: float = float("nan")
    scale: float = 0.0    # integral of x^2 dt = scale**2 * ssq (no overflow for huge loads)
    ssq: float = 0.0
    span: float = 0.0     # s, the time the integral covers
    n: int = 0
    plain: float = 0.0    # sum of (x/scale)^2 over the samples: the RMS of a single instant

    @property
    def rms(self) -> float:
        if not self.n:
            return float("nan")
        return self.scale * rms_of(self.ssq, self.span, math.sqrt(self.plain / self.n))

    def add_scaled(self, m: float, s: float, plain: float = 0.0) -> None:
        """Accumulate an integral whose largest |x| is ``m`` > 0 and which is ``s * m**2``
        (``plain``: the samples' sum of squares / m**2)."""
        if m == 0.0:
            return
        if m > self.scale:
            r = (self.scale / m) ** 2
            self.ssq, self.plain = self.ssq * r + s, self.plain * r + plain
            self.scale = m
        else:
            r = (m / self.scale) ** 2
            self.ssq += s * r
            self.plain += plain * r


@dataclass
class Summary:
    """Peak magnitude, RMS and time of the peak of the main loads, accumulated by chunks
    (the last row of a chunk is kept for the trapezoid interval to the next one)."""

    columns: list[int]
    stats: list[Stat] = field(default_factory=list)
    _last: np.ndarray | None = None      # (1 + columns,) t and |x| of the previous chunk's last row

    @classmethod
    def for_mechanism(cls, an) -> "Summary":
        """An empty summary of every motor, gear mesh and bearing load of ``an``."""
        pick = []
        for i, (n, unit) in enumerate(zip(column_names(an), column_units(an))):
            kind = n.split(":")[0]
            last = n.rsplit(":", 1)[-1]
            if kind == "motor" and last in ("speed", "power") and n.count(":") == 2:
                pick.append((i, f"motor {n.split(':')[1]} {last}", unit))
            elif kind == "motor":
                pick.append((i, f"motor {n[6:]}", unit))
            elif kind == "gear" and last in ("t", "torque", "force", "effective_pull"):
                pair = n[5:-len(last) - 1]
                pick.append((i, f"gear {pair} {'tangential' if last == 't' else last}", unit))
            elif kind == "joint" and last in ("radial", "axial", "bending"):
                pick.append((i, f"bearing {n[6:-len(last) - 1]} {last}", unit))
        return cls([p[0] for p in pick], [Stat(p[1], p[2]) for p in pick])

    def add(self, tab: np.ndarray) -> None:
        """Accumulate a chunk ``tab`` (N, columns) of the output table (column 0 is t, s)."""
        if not tab.shape[0]:
            return
        t = tab[:, 0]
        X = np.abs(tab[:, self.columns])
        imax = np.argmax(X, axis=0)
        peak = X[imax, np.arange(X.shape[1])]
        rows = X if self._last is None else np.vstack([self._last[1:], X])
        tt = t if self._last is None else np.r_[self._last[0], t]
        m = np.maximum(peak, rows[0])
        Y = rows / np.where(m > 0.0, m, 1.0)        # scaled columns (no overflow when squared)
        integral = square_integral(Y, tt)
        plain = np.einsum("ij,ij->j", Y[-X.shape[0]:], Y[-X.shape[0]:])
        span = float(tt[-1] - tt[0])
        for k, st in enumerate(self.stats):
            v = peak[k]
            if v > st.peak or st.n == 0:
                st.peak, st.t_peak = float(v), float(t[imax[k]])
            st.add_scaled(float(m[k]), float(integral[k]), float(plain[k]))
            st.span += span
            st.n += X.shape[0]
        self._last = np.r_[t[-1], X[-1]]


def motor_linear(an, name: str) -> bool:
    """True when motor ``name`` drives a prismatic input directly (speed in m/s)."""
    mi = [m.name for m in an.mech.motors].index(name)
    link = an.mech.motors[mi].link
    return any(j.child == link and j.type == "prismatic" for j in an.mech.joints) and not an.mech.motors[mi].joints


def _ideal_unit(an, c) -> str:
    """Unit of an ideal pair's mesh torque column: N*m, or N when its driven joint slides."""
    if c.joints is not None and an.mech.joints[c.joints[0]].type == "prismatic":
        return "N"
    return "N·m"


def first_non_finite(tab: np.ndarray) -> tuple[int, int] | None:
    """(row, column) of the first NaN or infinite entry of ``tab`` (N, ncol), or None."""
    bad = ~np.isfinite(tab)
    if not bad.any():
        return None
    r, c = np.argwhere(bad)[0]
    return int(r), int(c)


def format_rows(tab: np.ndarray, fmt: str = "%.9g") -> str:
    """CSV text of the rows of ``tab`` (Python's ``%`` formatting; the reference of
    :func:`gearcli.report.csv_text.format_rows`, which writes the same bytes faster)."""
    n, m = tab.shape
    line = ",".join([fmt] * m) + "\n"
    return (line * n) % tuple((tab + 0.0).ravel().tolist())   # + 0.0: no negative zeros
