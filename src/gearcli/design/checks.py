"""The design checks of one mechanism: which quantity of which component, against what limit.

:func:`build_checks` turns the ratings of an analysed mechanism (``Motor.rating``,
``Joint.bearings``, ``Joint.limit``, ``GearPair.rating``) and a case's requirements
(:class:`Requirements`) into a list of :class:`Check`.  Each check names a *signal*, a
quantity with one value per trajectory sample (computed by :mod:`gearcli.design.evaluate`),
and how the samples of a duty cycle are reduced to the value compared with the limit:

* ``peak``: max over the samples <= limit;
* ``rms``: time-weighted RMS over the whole duty cycle <= limit;
* ``safety``: ``rating`` / max over the samples >= limit (static safety, tooth stresses);
* ``life``: ISO 281 rating life in hours >= limit (``rating`` = C, ``exponent`` = p);
* ``fatigue``: gear tooth life in hours (rainflow + Miner, :mod:`gearcli.design.fatigue`)
  >= limit (``rating`` = the allowable stress).
* ``energy``: the integral of the signal over each trajectory (a cycle), worst one <= limit;
* ``reducer_average``, ``reducer_speed_average``, ``reducer_life``: a reducer's
  speed-weighted average torque T_av, average input speed n_av (<= limit) and catalogue life
  (>= limit) over the duty cycle (:mod:`gearcli.model.reducers`);
* ``slack``: a belt's least slack-span tension over |E|, ``rating`` (T_i) / max |E| - 1/2 >= limit;
* ``screw_life``: a screw's ISO 3408-5 life from its speed-weighted cubic-mean axial load
  (>= limit, :mod:`gearcli.model.screws`).
* ``worm_efficiency``: a worm pair's efficiency over the duty cycle, 1 - (energy lost) / (energy
  its members put in), >= limit (:func:`gearcli.design.evaluate.worm_powers`).

Servo sizing (inertia ratio, torque-speed envelope, regenerative energy) is in :mod:`.sizing`.
"""
from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field

from ..errors import Collector
from .iso281 import life_exponent
from .fatigue import dynamic_factor
from .gears import lewis_form_factor, virtual_helical_teeth, virtual_spur
from .sizing import sizing_checks

MODULE_RTOL = 0.01
"""Relative tolerance of module * teeth / 2 against the pitch radius from the geometry."""


@dataclass(frozen=True)
class Requirements:
    """A case's requirements (manifest keys of the same names); None: not checked."""

    cycles_per_hour: float | None = None
    service_life_h: float | None = None
    bearing_life_h: float | None = None
    gear_life_h: float | None = None
    reducer_life_h: float | None = None
    screw_life_h: float | None = None
    min_worm_efficiency: float | None = None
    min_static_safety: float = 1.0
    min_bending_safety: float = 1.0
    min_contact_safety: float = 1.0
    limits: tuple = ()   # ({"column": str, "max_abs": float, "max_rms": float} or {} (skipped), ...)
    limits_path: str = "limits"


@dataclass(frozen=True)
class Check:
    """One check.  ``signal`` is a tuple understood by :func:`gearcli.design.evaluate.signal`."""

    component: str
    quantity: str
    unit: str            # unit of the value compared with the limit
    limit: float
    kind: str            # "peak" | "rms" | "safety" | "life" | "energy"
    signal: tuple
    signal_unit: str     # unit of the signal (what a plot shows)
    rating: float = 0.0  # safety: allowable of the signal; life: C
    exponent: float = 0.0
    extra: dict = field(default_factory=dict, compare=False)

    @property
    def name(self) -> str:
        return f"{self.component}: {self.quantity}"


def build_checks(an, req: Requirements, col: Collector) -> list[Check]:
    """Every check of the analysed mechanism ``an`` under ``req``; problems go to ``col``."""
    checks = _motor_checks(an) + sizing_checks(an, Check) + _bearing_checks(an, req, col) + _gear_checks(an, req, col)
    checks += _reducer_checks(an, req) + _screw_checks(an, req) + _belt_checks(an) + _worm_checks(an, req)
    checks += _joint_limit_checks(an) + _column_checks(an, req, col)
    return checks


def _belt_checks(an) -> list[Check]:
    """A rated belt's checks (:class:`~gearcli.model.belts.BeltRating`): max |E| <=
    ``max_effective_pull``; the least slack-span tension over |E|, T_i / max|E| - 1/2, >=
    ``min_slack_ratio``."""
    out = []
    for c in an.circuits:
        gp = an.mech.gears[c.gear]
        r = gp.belt.rating if gp.belt is not None else None
        if r is None:
            continue
        comp, E = f"belt {gp.name}", ("abs", f"gear:{gp.name}:effective_pull")
        if r.max_effective_pull is not None:
            out.append(Check(comp, "effective pull", "N", r.max_effective_pull, "peak", E, "N"))
        if r.min_slack_ratio is not None:
            out.append(Check(comp, "slack ratio", "", r.min_slack_ratio, "slack", E, "N", rating=gp.belt.pretension))
    return out


def _worm_checks(an, req: Requirements) -> list[Check]:
    """With the case's ``min_worm_efficiency``, every worm pair's efficiency over the duty
    cycle (energies, so a self-locking pair lowered by its motor counts at 0) >= the limit.
    ``extra``: the worm's rate row over the joint rates relative to the carrier, the ratio e
    (theta_W = e theta_G) and the wheel's pitch radius r2 (:mod:`gearcli.model.worms`)."""
    if req.min_worm_efficiency is None:
        return []
    out = []
    for c in an.circuits:
        gp = an.mech.gears[c.gear]
        if gp.worm is None:
            continue
        x = {"row": tuple(float(v) for v in c.row_j), "ratio": float(c.ratio), "r2": float(c.worm.r2)}
        out.append(Check(f"worm pair {gp.name}", "efficiency over the duty cycle", "", req.min_worm_efficiency,
                         "worm_efficiency", ("worm_efficiency", gp.name), "", extra=x))
    return out


def _screw_checks(an, req: Requirements) -> list[Check]:
    """The ISO 3408-5 checks of every rated screw (:class:`~gearcli.model.screws.ScrewRating`):
    static safety C_0a / max |F| >= ``min_static_safety``, the screw's speed (max |a|, with
    ``max_speed``) and, with ``screw_life_h``, the life L_h = (C_a / F_m)^3 10^6 / (60 n_m)
    from the speed-weighted cubic-mean axial load F_m."""
    out = []
    for c in an.circuits:
        gp = an.mech.gears[c.gear]
        r = gp.screw.rating if gp.screw is not None else None
        if r is None:
            continue
        comp, F = f"screw {gp.name}", ("abs", f"gear:{gp.name}:force")
        x = {"row": tuple(float(v) for v in c.row_j), "rating": r}
        out.append(Check(comp, "static safety s0", "", req.min_static_safety, "safety", F, "N", rating=r.C_0a))
        if r.max_speed is not None:
            out.append(Check(comp, "speed", "rad/s", r.max_speed, "peak", ("reducer_speed", gp.name), "rad/s", extra=x))
        if req.screw_life_h is not None:
            out.append(Check(comp, "L10 life (ISO 3408-5)", "h", req.screw_life_h, "screw_life", F, "N",
                             rating=r.C_a, exponent=3.0, extra=x))
    return out


def _reducer_checks(an, req: Requirements) -> list[Check]:
    """The catalogue checks of every rated reducer (:class:`~gearcli.model.reducers.ReducerRating`):
    repeated peak torque (max |T|), maximum input speed (max |a|), average torque T_av, average
    input speed n_av and, with ``reducer_life_h``, the life L = L_n (n_N/n_av) (T_N/T_av)^p.
    T is ``gear:<r>:torque``; a, the input's rate relative to the housing, is the circuit's row
    over the real joint rates (``extra["row"]``)."""
    out = []
    for c in an.circuits:
        gp = an.mech.gears[c.gear]
        r = gp.reducer.rating if gp.reducer is not None else None
        if r is None:
            continue
        comp, T = f"reducer {gp.name}", ("abs", f"gear:{gp.name}:torque")
        speed = ("reducer_speed", gp.name)
        x = {"row": tuple(float(v) for v in c.row_j), "rating": r}
        if r.repeated_peak_torque is not None:
            out.append(Check(comp, "repeated peak torque", "N·m", r.repeated_peak_torque, "peak", T, "N·m"))
        if r.max_input_speed is not None:
            out.append(Check(comp, "input speed", "rad/s", r.max_input_speed, "peak", speed, "rad/s", extra=x))
        if r.average_torque_limit is not None:
            out.append(Check(comp, "average torque T_av", "N·m", r.average_torque_limit, "reducer_average", T,
                             "N·m", exponent=r.life_exponent, extra=x))
        if r.average_input_speed_limit is not None:
            out.append(Check(comp, "average input speed n_av", "rad/s", r.average_input_speed_limit,
                             "reducer_speed_average", speed, "rad/s", extra=x))
        if req.reducer_life_h is not None:
            out.append(Check(comp, f"{r.life_basis} life", "h", req.reducer_life_h, "reducer_life", T, "N·m",
                             rating=r.rated_torque, exponent=r.life_exponent, extra=x))
    return out


def _motor_checks(an) -> list[Check]:
    out = []
    for m in an.mech.motors:
        r = m.rating
        if r is None:
            continue
        c = f"motor {m.name}"
        out += [Check(c, "peak torque", "N·m", r.peak_torque, "peak", ("abs", f"motor:{m.name}"), "N·m"),
                Check(c, "RMS torque", "N·m", r.rms_torque, "rms", ("col", f"motor:{m.name}"), "N·m"),
                Check(c, "speed", "rad/s", r.max_speed, "peak", ("abs", f"motor:{m.name}:speed"), "rad/s")]
        if r.thermal_window is not None:
            out.append(Check(c, f"running RMS torque ({r.thermal_window:g} s)", "N·m", r.rms_torque, "peak",
                             ("running_rms", f"motor:{m.name}", r.thermal_window), "N·m"))
        if r.max_power is not None:
            out.append(Check(c, "power", "W", r.max_power, "peak", ("abs", f"motor:{m.name}:power"), "W"))
    return out


def _bearing_checks(an, req: Requirements, col: Collector) -> list[Check]:
    out = []
    for ji, jt in enumerate(an.mech.joints):
        if not jt.bearings:
            continue
        if jt.type != "revolute":
            col.add(jt.bearings[0].path, f"bearings are rated on revolute joints; '{jt.name}' is {jt.type}")
            continue
        for bi, b in enumerate(jt.bearings):
            if not b.rated:          # friction only: no rating to check
                continue
            c = f"bearing {jt.name}/{b.name}"
            if req.bearing_life_h is not None:
                life = "L10 life" if b.a_ISO is None and b.kappa is None else "Lnm life (a_ISO)"
                out.append(Check(c, life, "h", req.bearing_life_h, "life", ("bearing_P", ji, bi), "N",
                                 rating=b.C, exponent=life_exponent(b.type)))
            out.append(Check(c, "static safety s0", "", req.min_static_safety, "safety", ("bearing_P0", ji, bi),
                             "N", rating=b.C0))
            if b.M is not None:
                out.append(Check(c, "tilting moment", "N·m", b.M, "peak", ("abs", f"joint:{jt.name}:bending"), "N·m"))
    return out


def _gear_checks(an, req: Requirements, col: Collector) -> list[Check]:
    out = []
    for c in an.circuits:
        gp = an.mech.gears[c.gear]
        r = gp.rating
        if r is None or c.geometry is None:
            continue
        g = c.geometry
        mt = r.module / math.cos(gp.helix_angle)    # transverse module (helical: module is the normal one)
        teeth = gp.teeth if gp.teeth is not None else (2 * g.r_j / mt, 2 * g.r_k / mt)
        if gp.teeth is not None:
            for link, z, rad in zip((gp.j, gp.k), gp.teeth, (g.r_j, g.r_k)):
                if abs(mt * z / 2 - rad) > MODULE_RTOL * rad:
                    what = "module" if not gp.helix_angle else "normal module / cos(helix angle)"
                    col.add(f"{r.path}.module", f"{what} {mt:g} m x {z} teeth / 2 = {mt * z / 2:g} m "
                            f"disagrees with the pitch radius {rad:g} m of gear '{link}' from the mesh geometry")
        try:
            stress = _stress_factors(gp, g, teeth, r)
        except ValueError as exc:
            col.add(f"{r.path}.module", f"gear pair '{gp.name}': {exc}")
            continue
        comp = f"gear {gp.name}"
        out += [Check(comp, "bending safety", "", req.min_bending_safety, "safety", ("bending", gp.name),
                      "Pa", rating=r.bending_stress_limit, extra=stress),
                Check(comp, "contact safety", "", req.min_contact_safety, "safety", ("contact", gp.name),
                      "Pa", rating=r.contact_stress_limit, extra=stress)]
        if req.gear_life_h is not None:
            passes = _tooth_passes(an, c, gp, teeth)
            out += [Check(comp, f"{kind} fatigue life", "h", req.gear_life_h, "fatigue", (kind, gp.name), "Pa",
                          rating=limit, extra={**stress, "passes": passes})
                    for kind, limit in (("bending", r.bending_stress_limit), ("contact", r.contact_stress_limit))]
    return out


def _tooth_passes(an, c, gp, teeth) -> tuple | None:
    """(joint index, factor): the pinion's revolutions relative to the carrier are
    factor x the turns of that joint (a gear of the pair jointed straight to the carrier;
    factor = its teeth / the pinion's teeth).  None when neither gear is: no tooth passes."""
    carrier = an.names[c.carrier]
    for link, z in zip((gp.j, gp.k), teeth):
        for ji, jt in enumerate(an.mech.joints):
            if jt.child == link and jt.parent == carrier and jt.type == "revolute":
                return ji, z / min(teeth)
    return None


def _stress_factors(gp, g, teeth, r) -> dict:
    """Lewis and Hertz constants of a pair (:mod:`gearcli.design.gears`).

    Bevel gears use their virtual spur gears (:func:`gearcli.design.gears.virtual_spur`);
    helical gears the Lewis factor of their virtual tooth counts z / cos^3(beta) with the
    normal module, and the helical zone and helix angle factors (``beta``).
    """
    zj, dj = virtual_spur(teeth[0], 2 * g.r_j, g.cone_j)
    zk, dk = virtual_spur(teeth[1], 2 * g.r_k, g.cone_k)
    beta = gp.helix_angle
    K = r.application_factor * r.load_sharing_factor
    if r.quality_number is not None:      # AGMA K_v at the highest pitch-line velocity (rating)
        K *= float(dynamic_factor(r.pitch_line_velocity, r.quality_number))
    Y = min(lewis_form_factor(virtual_helical_teeth(z, beta)) for z in (zj, zk))
    d1, u = min(dj, dk), max(dj, dk) / min(dj, dk)
    return {"K": K, "Y": Y, "d1": d1, "u": u, "alpha": gp.pressure_angle, "internal": g.ring is not None,
            "module": r.module, "b": r.face_width, "ZE": r.elastic_coefficient, "beta": beta}


def _joint_limit_checks(an) -> list[Check]:
    out = []
    independent = set(an.independent_names)
    for ji, jt in enumerate(an.mech.joints):
        lim = jt.limit
        if lim is None:
            continue
        lin = jt.type == "prismatic"
        if lim.effort is not None and jt.name in independent:
            out.append(Check(f"joint {jt.name}", "effort", "N" if lin else "N·m", lim.effort, "peak",
                             ("abs", f"tau:{jt.name}"), "N" if lin else "N·m"))
        if lim.velocity is not None:
            out.append(Check(f"joint {jt.name}", "velocity", "m/s" if lin else "rad/s", lim.velocity, "peak",
                             ("rate", ji), "m/s" if lin else "rad/s"))
    return out


def _column_checks(an, req: Requirements, col: Collector) -> list[Check]:
    if not req.limits:
        return []
    from ..report.columns import column_names, column_unit  # noqa: PLC0415 (imports the solver: not for check)

    out = []
    names = column_names(an)
    for i, lim in enumerate(req.limits):
        if "column" not in lim:     # left out by the manifest reader (a bad item, reported there)
            continue
        name = lim["column"]
        if name not in names:
            close = difflib.get_close_matches(name, names, n=1)
            col.add(f"{req.limits_path}[{i}].column", f"unknown output column '{name}'"
                    + (f" (did you mean '{close[0]}'?)" if close else ""))
            continue
        unit = column_unit(name)
        if "max_abs" in lim:
            out.append(Check(f"column {name}", "max abs", unit, lim["max_abs"], "peak", ("abs", name), unit))
        if "max_rms" in lim:
            out.append(Check(f"column {name}", "RMS", unit, lim["max_rms"], "rms", ("col", name), unit))
    return out

