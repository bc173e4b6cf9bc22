"""Mechanism files (YAML) -> :class:`~gearcli.model.mechanism.Mechanism`.

Parsing keeps each node's line (``yaml.compose``) under its YAML path, e.g.
``gears[2].mesh_point``, so that every later check can say where a problem is.  The file is
validated against ``schemas/mechanism.schema.json`` (jsonschema; its errors worded by
:mod:`.schema_words`), then checked for names, masses and inertias.  Problems are collected and raised together as a
:class:`~gearcli.errors.MechanismError`.  Degrees (``*_deg`` fields) are converted here;
nothing below this module knows about them.
"""
from __future__ import annotations

from pathlib import Path

from functools import lru_cache

import jsonschema
import numpy as np

from ..errors import Collector, IncompleteMechanismError
from ..model.friction import JointFriction
from ..model.mechanism import GearPair, Joint, Link, Mechanism, Motor
from .loads_reader import yaml_loads, yaml_payloads
from .planets import expand_planets, item_path
from .ratings_reader import rated_gears, rated_joints, rated_motors
from ..model.geometry import dh_transform, origin_axis_transform
from ..model.reducers import REDUCER_KINDS
from ..model.validate import check_inertia, gear_pair_problems, inertia_matrix, number_problem
from .reducer_specs import reducer_spec
from .element_specs import belt_spec, screw_spec, worm_spec
from .schema_words import schema_messages
from .yaml_safe import read_text, yaml_lines
from .schemas import packaged_schema


def mechanism_schema() -> dict:
    """The JSON Schema of mechanism files (``schemas/mechanism.schema.json``)."""
    return packaged_schema("mechanism.schema.json")


@lru_cache(maxsize=1)
def _validator():
    """A validator of the mechanism schema with its ``$defs`` references inlined (a third
    faster on large files: no reference lookup per item; the schema has no recursion)."""
    schema = mechanism_schema()
    return jsonschema.Draft202012Validator(_inline_refs(schema, schema.get("$defs", {})))


def _inline_refs(node, defs: dict):
    if isinstance(node, dict):
        ref = node.get("$ref", "")
        if len(node) == 1 and ref.startswith("#/$defs/"):
            return _inline_refs(defs[ref[len("#/$defs/"):]], defs)
        return {k: _inline_refs(v, defs) for k, v in node.items()}
    if isinstance(node, list):
        return [_inline_refs(v, defs) for v in node]
    return node


def load_yaml(path: str | Path) -> Mechanism:
    """Read a mechanism from a YAML file; raises :class:`~gearcli.errors.MechanismError`."""
    return parse_mechanism(read_text(path), str(path))


def json_path(parts) -> str:
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


def _schema_issues(data, col: Collector, skip: set) -> None:
    """Schema violations, except at the paths in ``skip`` (already reported)."""
    validator = _validator()
    for err in sorted(validator.iter_errors(data), key=lambda e: list(map(str, e.absolute_path))):
        for parts, message in schema_messages(err):
            if json_path(parts) not in skip:
                col.add(json_path(parts), message)


def number_issues(data, col: Collector, path: str = "") -> None:
    """Report numbers the schema lets through but no mechanism has: NaN, infinities (YAML
    .nan, .inf) and magnitudes beyond :data:`~gearcli.model.validate.MAX_ABS`."""
    if isinstance(data, dict):
        for k, v in data.items():
            number_issues(v, col, f"{path}.{k}" if path else str(k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            number_issues(v, col, f"{path}[{i}]")
    else:
        why = number_problem(data)
        if why:
            col.add(path, why)


def parse_mechanism(text: str, file: str = "<string>") -> Mechanism:
    """Parse the YAML text of a mechanism file (see docs/reference/mechanism-files.md for the format)."""
    data, lines = yaml_lines(text, file)
    col = Collector(file, lines)
    if not isinstance(data, dict):
        col.add("", "a mechanism file must be a YAML mapping" + (
            " (a .csv is a trajectory: gearcli solve MECH TRAJ.csv)" if file.lower().endswith(".csv") else ""))
    elif "cases" in data and "links" not in data:
        col.add("", "this is a design manifest (it lists cases), not a mechanism file: run gearcli verify on it")
    col.raise_if_any()
    return mechanism_from_data(data, file, lines)


def mechanism_from_data(data: dict, file: str = "<string>", lines: dict | None = None,
                        schema: bool = True) -> Mechanism:
    """The mechanism of a mechanism file's parsed YAML mapping ``data`` (``lines``: YAML path
    -> line, for the problems' places); ``schema=False`` skips the JSON Schema's checks, for
    data whose every value has passed them before (a sweep's variant, each of its values
    tried alone: :func:`gearcli.batch.sweep.plan_sweep`), and the checks of each number alone
    (:func:`number_issues`); the model's own checks still run."""
    lines = lines or {}
    col = Collector(file, lines)
    if schema:
        number_issues(data, col)
        _schema_issues(data, col, {i.path for i in col.issues})
    col.raise_if_any()
    later = Collector(file, lines)       # problems that leave the mechanism buildable (planet assembly)
    data = expand_planets(data, joint_geometry, col, later)
    col.raise_if_any()
    mech = _build(data, col, file, lines, reuse=not schema)
    if later.issues:
        col.issues[:0] = later.issues
    if col.issues and later.issues and len(col.issues) == len(later.issues):
        raise IncompleteMechanismError(col.issues, mech)
    col.raise_if_any()
    return mech


def _angle(spec: dict, key: str, col: Collector, path: str) -> float:
    if key in spec and f"{key}_deg" in spec:
        col.add(f"{path}.{key}_deg", f"give either {key} (rad) or {key}_deg, not both")
    if f"{key}_deg" in spec:
        return float(np.deg2rad(spec[f"{key}_deg"]))
    return float(spec.get(key, 0.0))


def joint_geometry(spec: dict, col: Collector, path: str):
    """(R_pj, p_pj, R_jc, p_jc) of a joint spec with ``dh`` or ``origin``/``axis``."""
    if "dh" in spec:
        if "origin" in spec or "axis" in spec:
            col.add(f"{path}.{'origin' if 'origin' in spec else 'axis'}",
                    "give the joint geometry either as dh or as origin/axis, not both")
        dh = spec["dh"]
        theta = _angle(dh, "theta", col, f"{path}.dh")
        alpha = _angle(dh, "alpha", col, f"{path}.dh")
        d, a = float(dh.get("d", 0.0)), float(dh.get("a", 0.0))
        return dh_transform(theta, d, a, alpha)
    origin = spec.get("origin", {})
    xyz = np.asarray(origin.get("xyz", [0.0, 0.0, 0.0]), float)
    if "rpy" in origin and "rpy_deg" in origin:
        col.add(f"{path}.origin.rpy_deg", "give either rpy (rad) or rpy_deg, not both")
    rpy = np.deg2rad(origin["rpy_deg"]) if "rpy_deg" in origin else np.asarray(origin.get("rpy", [0, 0, 0]), float)
    axis = np.asarray(spec.get("axis", [0.0, 0.0, 1.0]), float)
    if np.linalg.norm(axis) < 1e-12:
        col.add(f"{path}.axis", "joint axis must not be the zero vector")
        axis = np.array([0.0, 0.0, 1.0])
    return origin_axis_transform(xyz, rpy, axis)


class _Names:
    """Names declared in one list of the file (links, joints, ...): first path of each,
    duplicates and unknown references reported."""

    def __init__(self, col: Collector, what: str):
        self.col, self.what, self.first = col, what, {}

    def declare(self, name: str, path: str) -> None:
        if name in self.first:
            self.col.add(f"{path}.name", f"duplicate {self.what} name '{name}' (first at {self.first[name]})")
        self.first[name] = path

    def ref(self, value: str, path: str, what: str = "link") -> None:
        if value not in self.first:
            self.col.add(path, f"unknown {what} '{value}'")


def _build(data: dict, col: Collector, file: str, lines: dict, reuse: bool = False) -> Mechanism:
    """The Mechanism of validated ``data``: links, joints, gears, motors and loads in turn, each
    checked for names, references and values, and rated.  ``reuse``: each of the joints,
    gears and motors sections built before from the very same section object (and the same
    link names) is taken again (:data:`_PARTS`: a sweep's variants share the sections no
    value of theirs changes, :func:`gearcli.batch.sweep.variant_data`)."""
    links, link_list = _links(data, col)
    for key in ("base", "end_effector"):
        links.ref(data[key], key)
    loads = yaml_loads(data, col, set(links.first), data["base"])
    parts = tuple(_section(kind, data, col, links, reuse) for kind in ("joints", "gears", "motors"))
    return Mechanism(
        name=data["name"], base=data["base"], end_effector=data["end_effector"],
        links=tuple(link_list), joints=parts[0], gears=parts[1], motors=parts[2],
        gravity=np.asarray(data.get("gravity", [0.0, 0.0, -9.81]), float),
        source=file, lines=dict(lines), loads=loads,
        payloads=yaml_payloads(data, col, set(links.first), data["base"], loads),
    )


_BUILD = {"joints": (lambda data, col, links: _joints(data, col, links), rated_joints),
          "gears": (lambda data, col, links: _gears(data, col, links), rated_gears),
          "motors": (lambda data, col, links: _motors(data, col, links), rated_motors)}


def _section(kind: str, data: dict, col: Collector, links: _Names, reuse: bool) -> tuple:
    """The rated parts of section ``kind`` (joints, gears or motors) of ``data``; with
    ``reuse``, those built before from the very same section object and link names
    (:data:`_PARTS`), else built, rated and (without a new issue) kept."""
    section = data.get(kind)
    key = (kind, id(section), tuple(links.first), data["base"])
    hit = _PARTS.get(key) if reuse else None
    if hit is not None and hit[0] is section:
        return hit[1]
    build, rate = _BUILD[kind]
    before = len(col.issues)
    parts = rate(tuple(build(data, col, links)), data, col)
    if reuse and len(col.issues) == before:
        if len(_PARTS) >= 48:
            _PARTS.clear()
        _PARTS[key] = (section, parts)
    return parts


_PARTS: dict = {}
"""(section kind, its id, link names, base) -> (the section, its rated joints, gears or
motors): the parts of the mechanisms built with ``reuse`` (the sections are kept, so that
their ids stay theirs while they are keys).  The parts are frozen dataclasses, shared by
the mechanisms built from the same sections."""


def _links(data: dict, col: Collector) -> tuple[_Names, list[Link]]:
    """The link names (declared) and the links, masses and inertias checked."""
    names = _Names(col, "link")
    out: list[Link] = []
    for i, spec in enumerate(data["links"]):
        path = item_path(data, "links", i)
        name = spec["name"]
        names.declare(name, path)
        mass = float(spec.get("mass", 0.0))
        I = inertia_matrix(spec["inertia"]) if "inertia" in spec else np.zeros((3, 3))
        if name != data["base"]:
            if "mass" not in spec:
                col.add(path, f"link '{name}' has no mass")
            elif mass <= 0:
                col.add(f"{path}.mass", f"mass must be positive, got {mass:g} kg")
            why = check_inertia(I, mass)
            if why:
                col.add(f"{path}.inertia", why)
        out.append(Link(name, mass, np.asarray(spec.get("com", [0, 0, 0]), float), I, path))
    return names, out


def _joints(data: dict, col: Collector, links: _Names) -> list[Joint]:
    joints: list[Joint] = []
    names = _Names(col, "joint")
    for i, spec in enumerate(data["joints"]):
        path = item_path(data, "joints", i)
        names.declare(spec["name"], path)
        links.ref(spec["parent"], f"{path}.parent")
        links.ref(spec["child"], f"{path}.child")
        if spec["parent"] == spec["child"]:
            col.add(f"{path}.child", "a joint cannot connect a link to itself")
        R_pj, p_pj, R_jc, p_jc = joint_geometry(spec, col, path)
        source = {k: spec[k] for k in ("dh", "origin", "axis") if k in spec}
        joints.append(Joint(spec["name"], spec["parent"], spec["child"], R_pj, p_pj, R_jc, p_jc,
                            spec.get("type", "revolute"), spec.get("label"), source, path,
                            friction=joint_friction(spec, col, path),
                            position_limits=position_limits(spec, col, path)))
    return joints


def position_limits(spec: dict, col: Collector, path: str) -> tuple[float, float] | None:
    """``joints[].limits`` ({lower, upper}: rad, or m for a prismatic joint; finite: checked
    before) as (lower, upper); lower < upper, else a located error."""
    if "limits" not in spec:
        return None
    lower, upper = float(spec["limits"]["lower"]), float(spec["limits"]["upper"])
    if not lower < upper:
        u = "m" if spec.get("type") == "prismatic" else "rad"
        col.add(f"{path}.limits.upper", f"upper limit {upper:g} {u} must be above the lower limit {lower:g} {u}")
        return None
    return lower, upper


def joint_friction(spec: dict, col: Collector, path: str) -> JointFriction | None:
    """``joints[].friction`` ({coulomb, viscous}, both >= 0; finite: checked before)."""
    if "friction" not in spec:
        return None
    fr = spec["friction"]
    unit = {"coulomb": ("N", "N*m"), "viscous": ("N*s/m", "N*m*s/rad")}
    values = {}
    for key in ("coulomb", "viscous"):
        v = float(fr.get(key, 0.0))
        if not v >= 0:
            u = unit[key][0 if spec.get("type") == "prismatic" else 1]
            col.add(f"{path}.friction.{key}", f"{key} friction must be >= 0, got {v:g} {u}")
        values[key] = v
    if "static" in fr:
        v, u = float(fr["static"]), unit["coulomb"][0 if spec.get("type") == "prismatic" else 1]
        if not v >= values["coulomb"]:
            col.add(f"{path}.friction.static", f"static friction must be >= the Coulomb friction "
                    f"{values['coulomb']:g} {u}, got {v:g} {u}")
        values["static"] = v
    return JointFriction(**values)


def mesh_loss_factor(spec: dict, col: Collector, path: str) -> float:
    """``gears[].efficiency`` eta in (0, 1] or ``gears[].loss_factor`` c in [0, 1) (at most
    one of them; finite: checked before) as the loss factor c = 1 - eta; 0 when neither."""
    if "efficiency" in spec and "loss_factor" in spec:
        col.add(f"{path}.loss_factor", "give efficiency or loss_factor (= 1 - efficiency), not both")
        return 0.0
    if "efficiency" in spec:
        eta = float(spec["efficiency"])
        if not 0.0 < eta <= 1.0:
            col.add(f"{path}.efficiency", f"mesh efficiency must be in (0, 1], got {eta:g}")
            return 0.0
        c = 1.0 - eta
    elif "loss_factor" in spec:
        c = float(spec["loss_factor"])
        if not 0.0 <= c < 1.0:
            col.add(f"{path}.loss_factor", f"mesh loss factor must be in [0, 1), got {c:g}")
            return 0.0
    else:
        return 0.0
    if c and "mesh_point" not in spec:
        key = "efficiency" if "efficiency" in spec else "loss_factor"
        col.add(f"{path}.{key}", "a mesh loss needs the tooth geometry (mesh_point): the loss is "
                "|t| times the pitch-line speed")
    return c


_GEAR_FIELD = {"": "", "links": ".links", "kind": ".kind", "ratio": ".ratio", "cone_angles": ".cone_angles_deg",
               "helix_angle": ".helix_angle_deg", "hand": ".hand", "teeth": ".teeth"}


def _gears(data: dict, col: Collector, links: _Names) -> list[GearPair]:
    gears: list[GearPair] = []
    names = _Names(col, "gear pair")
    for i, spec in enumerate(data.get("gears", [])):
        path = item_path(data, "gears", i)
        if spec.get("kind") in REDUCER_KINDS:
            gears.append(_reducer(spec, col, links, names, path))
            continue
        if spec.get("kind") in ELEMENTS:
            gears.append(_element(spec, col, links, names, path))
            continue
        j, k = spec["links"]
        links.ref(j, f"{path}.links[0]")
        links.ref(k, f"{path}.links[1]")
        names.declare(spec.get("name", f"{j}-{k}"), path)
        if "carrier" in spec:
            links.ref(spec["carrier"], f"{path}.carrier")
        kind, cones = spec.get("kind", "external"), spec.get("cone_angles_deg")
        ratio = float(spec["ratio"]) if "ratio" in spec else None
        helix = float(np.deg2rad(spec["helix_angle_deg"])) if "helix_angle_deg" in spec else None
        helix_deg = float(spec["helix_angle_deg"]) if "helix_angle_deg" in spec else None
        for field, message in gear_pair_problems(j, k, kind, ratio, "teeth" in spec, "mesh_point" in spec,
                                                 cones is not None, helix_deg, spec.get("hand")):
            col.add(path + _GEAR_FIELD[field], message)
        gears.append(GearPair(
            spec.get("name", f"{j}-{k}"), j, k, kind, ratio,
            tuple(spec["teeth"]) if "teeth" in spec else None,
            np.asarray(spec["mesh_point"], float) if "mesh_point" in spec else None,
            spec.get("carrier"),
            float(np.deg2rad(spec.get("pressure_angle_deg", 20.0))),
            tuple(np.deg2rad(cones)) if cones is not None else None,
            path, helix_angle=helix or 0.0, hand=spec.get("hand"), stiffness=_stiffness(spec, col, path),
            loss_factor=mesh_loss_factor(spec, col, path),
        ))
    return gears


def _reducer(spec: dict, col: Collector, links: _Names, names: _Names, path: str) -> GearPair:
    """A strain-wave or cycloidal reducer (links: [input, output, housing]) as a GearPair with
    j = input, k = output, carrier = housing, ratio = i0 (:mod:`gearcli.model.reducers`)."""
    i, o, h = spec["links"]
    for n, (name, role) in enumerate(((i, "input"), (o, "output"), (h, "housing"))):
        links.ref(name, f"{path}.links[{n}]")
    if len({i, o, h}) < 3:
        col.add(f"{path}.links", f"a reducer's input, output and housing must be three different links, got {[i, o, h]}")
    names.declare(spec.get("name", f"{i}-{o}"), path)
    i0, red = reducer_spec(spec, path, col.add)
    teeth = tuple(spec["teeth"]) if "teeth" in spec else None
    return GearPair(spec.get("name", f"{i}-{o}"), i, o, spec["kind"], i0, teeth=teeth, carrier=h, path=path, reducer=red)


ELEMENTS = {"screw": (screw_spec, "[screw, nut]"), "worm": (worm_spec, "[worm, wheel]"),
            "belt": (belt_spec, "[input pulley, output pulley]")}
"""The two-member drive elements: kind -> (the reader of its keys, its links' roles)."""


def _element(spec: dict, col: Collector, links: _Names, names: _Names, path: str) -> GearPair:
    """A screw, worm pair or timing belt (links: [j, k]) as a GearPair carrying its model
    element (:mod:`gearcli.model.screws`, :mod:`~gearcli.model.worms`,
    :mod:`~gearcli.model.belts`); the ratio comes from the geometry (the analysis derives it)."""
    kind = spec["kind"]
    parse, roles = ELEMENTS[kind]
    j, k = spec["links"]
    for n, name in enumerate((j, k)):
        links.ref(name, f"{path}.links[{n}]")
    if j == k:
        col.add(f"{path}.links", f"a {kind} needs two different links {roles}")
    if "carrier" in spec:
        links.ref(spec["carrier"], f"{path}.carrier")
    name = spec.get("name", f"{j}-{k}")
    names.declare(name, path)
    teeth = tuple(spec["teeth"]) if kind == "worm" else None
    return GearPair(name, j, k, kind, None, teeth=teeth, carrier=spec.get("carrier"), path=path,
                    **{kind: parse(spec, path, col.add)})


def _stiffness(spec: dict, col: Collector, path: str) -> float | None:
    """``gears[].stiffness`` (N/m), which must be positive (finite: checked before)."""
    if "stiffness" not in spec:
        return None
    k = float(spec["stiffness"])
    if not k > 0:
        col.add(f"{path}.stiffness", f"mesh stiffness must be positive, got {k:g} N/m")
    return k


def _motors(data: dict, col: Collector, links: _Names) -> list[Motor]:
    motors: list[Motor] = []
    names = _Names(col, "motor")
    for i, spec in enumerate(data.get("motors", [])):
        path = f"motors[{i}]"
        names.declare(spec["name"], path)
        links.ref(spec["link"], f"{path}.link")
        if "stator" in spec:
            links.ref(spec["stator"], f"{path}.stator")
        motors.append(Motor(spec["name"], spec["link"], spec.get("stator"), path))
    return motors
