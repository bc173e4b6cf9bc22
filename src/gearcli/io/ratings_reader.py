"""Component ratings in mechanism files -> :mod:`gearcli.model.ratings`, attached to the model.

YAML keys (schema in ``schemas/mechanism.schema.json``): ``motors[].rating``,
``joints[].bearings``, ``gears[].rating``.  URDF: each joint's ``<limit effort velocity>``,
and the extension elements ``<gearcli:bearing .../>`` inside a ``<joint>``,
``<gearcli:motor_rating motor= .../>`` and ``<gearcli:gear_rating gear= .../>`` under
``<robot>`` (attributes named as the YAML keys).  Problems are reported like every other
input problem (file, line, place, message) and raised together.
"""
from __future__ import annotations

import math
from dataclasses import replace

from ..errors import Collector, Issue, LocatedWarning, MechanismError
from ..model.mechanism import Mechanism
from ..model.validate import number_problem
from ..model.ratings import (BEARING_FACTOR_DEFAULTS, STEEL_ELASTIC_COEFFICIENT, BearingRating, GearRating,
                             JointLimit, MotorModel, MotorRating)
from .planets import item_path

NS = "https://gearcli.dev/urdf/1"
MOTOR_KEYS = ("peak_torque", "rms_torque", "max_speed", "max_power", "thermal_window", "rotor_inertia",
              "max_inertia_ratio", "max_regen_energy")   # and torque_speed (YAML only: a table)
MODEL_KEYS = ("kt", "resistance", "inductance", "supply_voltage")   # motors[].model, <gearcli:motor_model>
BEARING_KEYS = ("name", "position", "C", "C0", "type", "X", "Y", "e", "X0", "Y0", "locating", "M", "f0", "a_ISO",
                "pitch_diameter",
                "kappa", "e_C", "Cu", "friction_coefficient", "bore")
RATING_KEYS = ("C", "C0", "type")     # a rated bearing has all three (the design checks need them)
LIFE_FACTOR_KEYS = ("kappa", "e_C", "Cu")
GEAR_KEYS = ("module", "face_width", "bending_stress_limit", "contact_stress_limit",
             "elastic_coefficient", "application_factor", "load_sharing_factor", "quality_number",
             "pitch_line_velocity")


def _positive(spec: dict, keys, path: str, add) -> None:
    for key in keys:
        v = spec.get(key)
        if isinstance(v, (int, float)) and not isinstance(v, bool) and not v > 0:
            add(f"{path}.{key}", f"{key} must be positive, got {v:g}")


def motor_rating(spec: dict, path: str, add) -> MotorRating:
    """A :class:`MotorRating` from a mapping with the keys of :data:`MOTOR_KEYS`."""
    _positive(spec, MOTOR_KEYS, path, add)
    if spec["rms_torque"] > spec["peak_torque"]:
        add(f"{path}.rms_torque", f"rms_torque {spec['rms_torque']:g} exceeds peak_torque {spec['peak_torque']:g}")
    opt = {k: (None if spec.get(k) is None else float(spec[k])) for k in MOTOR_KEYS[3:]}
    if opt["max_inertia_ratio"] is not None and opt["rotor_inertia"] is None:
        add(f"{path}.max_inertia_ratio", "max_inertia_ratio needs the motor's rotor_inertia")
    table = spec.get("torque_speed")
    if table is not None:
        table = tuple((float(w), float(T)) for w, T in table)
        w = [r[0] for r in table]
        if w[0] < 0 or any(b <= a for a, b in zip(w, w[1:])) or any(r[1] < 0 for r in table):
            add(f"{path}.torque_speed", "torque_speed rows [omega, T_max] need omega increasing from 0 or more "
                "and T_max not negative")
    return MotorRating(float(spec["peak_torque"]), float(spec["rms_torque"]), float(spec["max_speed"]),
                       opt["max_power"], path, thermal_window=opt["thermal_window"], rotor_inertia=opt["rotor_inertia"],
                       max_inertia_ratio=opt["max_inertia_ratio"], torque_speed=table,
                       max_regen_energy=opt["max_regen_energy"])


def motor_model(spec: dict, path: str, add) -> MotorModel:
    """A :class:`MotorModel` from ``motors[].model`` (kt, resistance, inductance, supply_voltage)."""
    _positive(spec, MODEL_KEYS, path, add)
    ind = spec.get("inductance")
    return MotorModel(float(spec["kt"]), float(spec["resistance"]), float(spec["supply_voltage"]),
                      None if ind is None else float(ind), path)


def bearing_ratings(specs: list[dict], path: str, add) -> tuple[BearingRating, ...]:
    """The bearings of one joint (one or two), factors defaulted by type (documented)."""
    out = []
    for i, spec in enumerate(specs):
        p = f"{path}[{i}]"
        _positive(spec, ("C", "C0", "X", "Y", "e", "M", "f0", "a_ISO", "kappa", "e_C", "Cu", "bore", "pitch_diameter"),
                  p, add)
        crossed = spec.get("type") == "crossed_roller"
        if crossed and spec.get("pitch_diameter") is None:
            add(f"{p}.pitch_diameter", "a crossed-roller bearing needs its pitch_diameter d_p (m): its tilting moment "
                "M loads it as 2 M/d_p")
        elif crossed and len(specs) != 1:
            add(f"{p}.type", "a crossed-roller bearing is a joint's only bearing (it carries the tilting moment itself)")
        elif spec.get("pitch_diameter") is not None and not crossed:
            add(f"{p}.pitch_diameter", "pitch_diameter is for a crossed_roller bearing")
        if not _rated_or_friction(spec, p, add):
            continue
        if "type" not in spec:      # friction only: no rating, no factors
            out.append(BearingRating(spec["name"], float(spec["position"]), None, None, None, None, None, None,
                                     None, None, bool(spec.get("locating", len(specs) == 1)), path=p,
                                     friction_coefficient=float(spec["friction_coefficient"]),
                                     bore=float(spec["bore"])))
            continue
        f = {**BEARING_FACTOR_DEFAULTS[spec["type"]], **{k: spec[k] for k in ("X", "Y", "e", "X0", "Y0") if k in spec}}
        if spec.get("M") is not None and len(specs) == 2:
            add(f"{p}.M", "a moment rating M is for a single bearing (two bearings carry the moment as radial loads)")
        if len(specs) == 1 and spec.get("locating") is False:
            add(f"{p}.locating", "a joint's only bearing takes the axial load: it cannot be non-locating")
        _life_factor_keys(spec, p, add)
        opt = {k: None if spec.get(k) is None else float(spec[k])
               for k in ("M", "f0", "a_ISO", "friction_coefficient", "bore", "pitch_diameter") + LIFE_FACTOR_KEYS}
        out.append(BearingRating(spec["name"], float(spec["position"]), float(spec["C"]), float(spec["C0"]),
                                 spec["type"], *(None if f[k] is None else float(f[k]) for k in ("X", "Y", "e")),
                                 float(f["X0"]), float(f["Y0"]), bool(spec.get("locating", len(specs) == 1)),
                                 path=p, **opt))
    if len(out) == 2 and len(specs) == 2:
        if out[0].name == out[1].name:
            add(f"{path}[1].name", f"duplicate bearing name '{out[1].name}'")
        if out[0].position == out[1].position:
            add(f"{path}[1].position", "two bearings of a joint need different positions")
        if sum(b.locating for b in out) != 1:
            add(path, "with two bearings, exactly one needs 'locating: true' (the one that takes the axial load)")
    return tuple(out)


def _rated_or_friction(spec: dict, p: str, add) -> bool:
    """A bearing entry is rated (C, C0 and type), or carries friction (friction_coefficient
    and bore, which go together), or both; True when it can be built."""
    rating = [k for k in RATING_KEYS if k in spec]
    ok = True
    if rating and len(rating) < len(RATING_KEYS):
        missing = [k for k in RATING_KEYS if k not in spec]
        add(f"{p}.{rating[0]}", f"a rated bearing needs C, C0 and type: {', '.join(missing)} missing")
        ok = False
    if ("friction_coefficient" in spec) != ("bore" in spec):
        given, other = ("bore", "friction_coefficient") if "bore" in spec else ("friction_coefficient", "bore")
        add(f"{p}.{given}", f"bearing friction needs both friction_coefficient and bore: {other} missing")
        ok = False
    mu = spec.get("friction_coefficient")
    if isinstance(mu, (int, float)) and not isinstance(mu, bool) and not 0 <= mu < 1:
        add(f"{p}.friction_coefficient", f"bearing friction coefficient must be in [0, 1), got {mu:g}")
        ok = False
    if not rating and "friction_coefficient" not in spec and "bore" not in spec:
        add(p, "a bearing needs a rating (C, C0, type) or friction (friction_coefficient, bore)")
        ok = False
    return ok


def _life_factor_keys(spec: dict, p: str, add) -> None:
    """a_ISO is given, or computed from all of kappa, e_C, Cu (ISO 281 section 9.3), not both."""
    given = [k for k in LIFE_FACTOR_KEYS if k in spec]
    if given and "a_ISO" in spec:
        add(f"{p}.a_ISO", f"give a_ISO or {', '.join(LIFE_FACTOR_KEYS)} to compute it, not both")
    elif given and len(given) < len(LIFE_FACTOR_KEYS):
        missing = [k for k in LIFE_FACTOR_KEYS if k not in spec]
        add(f"{p}.{given[0]}", f"a_ISO from {', '.join(LIFE_FACTOR_KEYS)} needs all three: {', '.join(missing)} missing")
    if isinstance(spec.get("kappa"), (int, float)) and 0 < spec["kappa"] < 0.1:
        add(f"{p}.kappa", f"kappa {spec['kappa']:g} is below 0.1, outside ISO 281's a_ISO method")
    if isinstance(spec.get("e_C"), (int, float)) and spec["e_C"] > 1:
        add(f"{p}.e_C", f"the contamination factor e_C is at most 1, got {spec['e_C']:g}")
    if "f0" in spec and spec.get("type") != "ball":
        add(f"{p}.f0", f"f0 enters the ISO 281 table of deep-groove ball bearings, not a {spec.get('type')} bearing")


def gear_rating(spec: dict, path: str, add) -> GearRating:
    """A :class:`GearRating` from a mapping with the keys of :data:`GEAR_KEYS`."""
    _positive(spec, GEAR_KEYS, path, add)
    kv = [k for k in ("quality_number", "pitch_line_velocity") if k in spec]
    if len(kv) == 1:
        other = "pitch_line_velocity" if kv[0] == "quality_number" else "quality_number"
        add(f"{path}.{kv[0]}", f"the dynamic factor K_v needs both quality_number and pitch_line_velocity: {other} missing")
    return GearRating(float(spec["module"]), float(spec["face_width"]), float(spec["bending_stress_limit"]),
                      float(spec["contact_stress_limit"]), float(spec.get("elastic_coefficient", STEEL_ELASTIC_COEFFICIENT)),
                      float(spec.get("application_factor", 1.0)), float(spec.get("load_sharing_factor", 1.0)), path,
                      *(None if spec.get(k) is None else float(spec[k]) for k in ("quality_number", "pitch_line_velocity")))


PRISMATIC_BEARINGS = ("rolling-bearing ratings and friction (ISO 281 life in revolutions, a moment about the axis) "
                      "are for revolute joints; a prismatic joint's linear guide is not rated, and its friction is "
                      "joints[].friction (coulomb N, viscous N*s/m)")


def rated_motors(motors: tuple, data: dict, col: Collector) -> tuple:
    """The motors with their ``rating`` and ``model`` of the YAML ``data`` attached."""
    motors = tuple(replace(m, rating=motor_rating(s["rating"], f"motors[{i}].rating", col.add))
                   if "rating" in s else m for i, (m, s) in enumerate(zip(motors, data.get("motors", []))))
    return tuple(replace(m, model=motor_model(s["model"], f"motors[{i}].model", col.add))
                 if "model" in s else m for i, (m, s) in enumerate(zip(motors, data.get("motors", []))))


def rated_joints(joints: tuple, data: dict, col: Collector) -> tuple:
    """The joints with their ``bearings`` of the YAML ``data`` attached."""
    joints = tuple(replace(j, bearings=bearing_ratings(s["bearings"], f"{item_path(data, 'joints', i)}.bearings",
                                                       col.add))
                   if "bearings" in s else j for i, (j, s) in enumerate(zip(joints, data["joints"])))
    for i, j in enumerate(joints):
        if j.bearings and j.type == "prismatic":
            col.add(f"joints[{i}].bearings", PRISMATIC_BEARINGS)
    return joints


def rated_gears(gears: tuple, data: dict, col: Collector) -> tuple:
    """The gear pairs with their ``rating`` of the YAML ``data`` attached (a reducer's, a
    screw's, a worm's and a belt's are their readers')."""
    out = []
    for i, (g, s) in enumerate(zip(gears, data.get("gears", []))):
        if "rating" in s and g.reducer is None and g.screw is None and g.worm is None and g.belt is None:   # theirs: io.reducer_specs, io.element_specs
            path = f"{item_path(data, 'gears', i)}.rating"   # a planet copy: its original's path
            if g.mesh_point is None:
                col.add(path, "a gear rating needs the mesh geometry (mesh_point)")
            g = replace(g, rating=gear_rating(s["rating"], path, col.add))
        out.append(g)
    return tuple(out)


# -- URDF ---------------------------------------------------------------------------------
def _urdf_spec(el, keys, required, path: str, add) -> dict | None:
    """Attributes of a rating element as a mapping: numbers parsed, ``type`` and ``name``
    kept as strings, ``locating`` as a boolean; None (with issues) when one is bad."""
    from lxml import etree  # noqa: PLC0415  (URDF only: YAML mechanisms do not import lxml)

    from .urdf_xml import decimal_numbers  # noqa: PLC0415  (likewise)

    spec: dict = {}
    ok = True
    for attr, text in el.attrib.items():
        key = etree.QName(attr).localname
        if key not in keys:
            add(path, f"unknown attribute '{key}' (allowed: {', '.join(keys)})")
            ok = False
        elif key in ("name", "motor", "gear"):
            spec[key] = text
        elif key == "type":
            if text not in BEARING_FACTOR_DEFAULTS:
                add(f"{path}.type", f"bearing type must be one of {', '.join(BEARING_FACTOR_DEFAULTS)}, got '{text}'")
                ok = False
            spec[key] = text
        elif key == "locating":
            if text not in ("true", "false"):
                add(f"{path}.locating", f"locating must be 'true' or 'false', got '{text}'")
                ok = False
            spec[key] = text == "true"
        else:
            try:
                (spec[key],) = decimal_numbers(text)   # not float(): "0_02" is not 2
            except ValueError:
                spec[key] = math.nan
            if not math.isfinite(spec[key]):
                add(f"{path}.{key}", f"{key} must be a finite number, got '{text}'")
                ok = False
            elif why := number_problem(spec[key]):    # as in YAML files: |x| <= 1e12
                add(f"{path}.{key}", why)
                ok = False
    for key in required:
        if key not in spec:
            add(path, f"missing attribute '{key}'")
            ok = False
    return spec if ok else None


def _urdf_limit(el, path: str, warn, add) -> JointLimit | None:
    """A joint's ``<limit effort velocity>``; non-positive values are not limits (warning),
    a non-finite or out-of-range one (``effort="inf"``) is an error, as in YAML files."""
    lim = el.find("limit")
    if lim is None:
        return None
    from .urdf_xml import decimal_numbers, placeholders  # noqa: PLC0415  (URDF only: YAML mechanisms do not import lxml)

    vals = {}
    stand_in = placeholders(lim)
    for key in ("effort", "velocity"):
        text, v = (None if key in stand_in else lim.get(key)), None
        if text is not None:
            try:
                (v,) = decimal_numbers(text)
            except ValueError:
                v = None
            why = None if v is None else number_problem(v)
            if why:
                add(f"{path}.limit", f"limit {key}=\"{text}\": {why}")
                v = None
            elif v is None or not v > 0:
                warn(f"{path}.limit", f"limit {key}=\"{text}\" is not a positive limit: not checked", lim)
        vals[key] = v if v is not None and v > 0 else None
    return None if vals == {"effort": None, "velocity": None} else JointLimit(vals["effort"], vals["velocity"], path)


def _ext(el, local: str) -> list:
    return [s for s in el if isinstance(s.tag, str) and s.tag == f"{{{NS}}}{local}"]


def attach_urdf_ratings(mech: Mechanism, root, file: str) -> Mechanism:
    """``mech`` (read from the URDF ``root``) with joint limits and gearcli rating elements."""
    issues: list[Issue] = []
    warnings = list(mech.warnings)
    lines = dict(mech.lines)   # rating paths -> element lines, for checks made later

    def adder(el):
        return lambda path, msg: issues.append(Issue(file, path, el.sourceline, msg))

    def warn(path, msg, el):
        warnings.append(LocatedWarning(Issue(file, path, el.sourceline, msg)))

    joints = {j.name: j for j in mech.joints}
    for el in root.findall("joint"):
        name, path = el.get("name"), f"joint '{el.get('name')}'"
        specs = []
        for i, b in enumerate(_ext(el, "bearing")):
            lines[f"{path}.gearcli:bearing[{i}]"] = b.sourceline
            specs.append(_urdf_spec(b, BEARING_KEYS, ("name", "position"),
                                    f"{path}.gearcli:bearing[{i}]", adder(b)))
        if name not in joints:
            if specs:
                adder(el)(path, "bearings on a fixed joint (its links are merged into one body)")
            continue
        if len(specs) > 2:
            adder(el)(path, f"a joint has one or two bearings, got {len(specs)}")
        elif specs and joints[name].type == "prismatic":
            adder(el)(path, PRISMATIC_BEARINGS)
        elif specs and None not in specs:
            joints[name] = replace(joints[name], bearings=bearing_ratings(specs, f"{path}.gearcli:bearing", adder(el)))
        limit = _urdf_limit(el, path, warn, adder(el.find("limit") if el.find("limit") is not None else el))
        if limit is not None:
            joints[name] = replace(joints[name], limit=limit)
    motors = {m.name: m for m in mech.motors}
    gears = {g.name: g for g in mech.gears}
    for kind, table, keys, builder in (("motor", motors, MOTOR_KEYS, motor_rating),
                                       ("gear", gears, GEAR_KEYS, gear_rating)):
        required = [k for k in keys if k not in ("max_power", "elastic_coefficient", "application_factor",
                                                 "load_sharing_factor", "thermal_window", "quality_number",
                                                 "pitch_line_velocity", *MOTOR_KEYS[5:])]
        for el in _ext(root, f"{kind}_rating"):
            path = f"gearcli:{kind}_rating '{el.get(kind)}'"
            lines[path] = el.sourceline
            spec = _urdf_spec(el, (kind, *keys), (kind, *required), path, adder(el))
            if spec is None:
                continue
            if spec[kind] not in table:
                adder(el)(path, f"unknown {kind} '{spec[kind]}' (known: {', '.join(table)})")
            elif kind == "gear" and table[spec[kind]].mesh_point is None:
                adder(el)(path, "a gear rating needs the mesh geometry (a gearcli:gear with mesh_point)")
            else:
                table[spec[kind]] = replace(table[spec[kind]], rating=builder(spec, path, adder(el)))
    _urdf_motor_models(root, motors, lines, adder)
    if issues:
        raise MechanismError(issues)
    return replace(mech, joints=tuple(joints.values()), motors=tuple(motors.values()),
                   gears=tuple(gears.values()), warnings=tuple(warnings), lines=lines)


def _urdf_motor_models(root, motors: dict, lines: dict, adder) -> None:
    """``<gearcli:motor_model motor="NAME" kt resistance supply_voltage [inductance]/>`` (children
    of ``robot``; as ``motors[].model``) onto ``motors`` (by name), in place."""
    seen: set = set()
    for el in _ext(root, "motor_model"):
        path = f"gearcli:motor_model '{el.get('motor')}'"
        lines[path] = el.sourceline
        spec = _urdf_spec(el, ("motor", *MODEL_KEYS), ("motor", "kt", "resistance", "supply_voltage"), path, adder(el))
        if spec is None:
            continue
        if spec["motor"] not in motors:
            adder(el)(path, f"unknown motor '{spec['motor']}' (known: {', '.join(motors)})")
        elif spec["motor"] in seen:
            adder(el)(path, f"a second gearcli:motor_model for motor '{spec['motor']}'")
        else:
            seen.add(spec["motor"])
            motors[spec["motor"]] = replace(motors[spec["motor"]], model=motor_model(spec, path, adder(el)))
