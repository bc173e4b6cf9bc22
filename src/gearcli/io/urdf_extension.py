"""gearcli URDF extension elements (``gearcli:mechanism``, ``gearcli:gear``,
``gearcli:motor``; ``gearcli:load`` is read by :mod:`gearcli.io.loads_reader`) and the motors of a URDF (extension motors, ``<transmission>``
actuators, direct drives).  A mixin of the reader in :mod:`gearcli.io.urdf_reader`."""
from __future__ import annotations

import math

import numpy as np
from lxml import etree

from ..errors import counted, plural
from ..model.friction import JointFriction
from ..model.mechanism import GearPair, Motor
from ..model.validate import gear_pair_problems
from .urdf_transmissions import KINDS as TRANSMISSION_KINDS
from .urdf_transmissions import read_transmissions
from .reducer_specs import reducer_spec
from .element_specs import belt_spec, screw_spec, worm_spec
from .urdf_xml import NS, floats, q
from ..model.reducers import LIFE_BASES, REDUCER_KINDS

GEAR_ATTRS = ("name", "j", "k", "kind", "ratio", "teeth", "carrier", "mesh_point", "pressure_angle",
              "pressure_angle_deg", "cone_angles", "cone_angles_deg", "helix_angle", "helix_angle_deg", "hand",
              "stiffness", "derived", "efficiency", "loss_factor")


REDUCER_ATTRS = ("name", "kind", "input", "output", "housing", "ratio", "teeth", "efficiency_forward",
                 "efficiency_backward", "no_load_torque", "torsional_stiffness_torque", "torsional_stiffness_rate")
BELT_ATTRS = ("name", "j", "k", "carrier", "radii", "pretension", "belt_point", "efficiency_forward", "efficiency_backward",
              "max_effective_pull", "min_slack_ratio")
WORM_ATTRS = ("name", "worm", "wheel", "carrier", "teeth", "reference_diameter", "module", "lead_angle", "lead_angle_deg",
              "pressure_angle", "pressure_angle_deg", "friction_coefficient", "hand")
SCREW_ATTRS = ("name", "screw", "nut", "carrier", "lead", "hand", "efficiency_forward", "efficiency_backward",
               "friction_coefficient", "diameter")
RATING_KEYS = ("rated_torque", "rated_input_speed", "rated_life", "life_basis", "life_exponent", "average_torque_limit",
               "repeated_peak_torque", "max_input_speed", "average_input_speed_limit")


def _attribute_path(path: str) -> str:
    """A reducer key's path named by its URDF attribute (``.efficiency.forward[1]`` ->
    ``.efficiency_forward``, ``.torsional_stiffness.rate`` -> ``.torsional_stiffness_rate``)."""
    import re  # noqa: PLC0415
    path = re.sub(r"\.efficiency\.(forward|backward)(\[\d+\])?", r".efficiency_\1", path)
    path = re.sub(r"\.no_load_torque\[\d+\]", ".no_load_torque", path)
    return re.sub(r"\.torsional_stiffness\.(torque|rate)", r".torsional_stiffness_\1", path)


def _helix_deg(el, kw: dict) -> float | None:
    """The helix angle in degrees as written (``helix_angle_deg``), else the degrees of
    ``helix_angle`` (rad); None when not given or unreadable (reported already)."""
    if "helix_angle" not in kw:
        return None
    given = floats(el.get("helix_angle_deg"), 1) if el.get("helix_angle") is None else None
    return float(given[0]) if given is not None else math.degrees(kw["helix_angle"])


class Extension:
    """Extension elements and motors; needs the reader's ``root``, ``lines``, ``add``,
    ``warn``, ``vector``, ``body_of``, ``movable``, ``joint_el``, ``joint_order``,
    ``leader`` and ``chain_leader``."""

    def read_extension(self) -> dict:
        ext = {"mechanism": None, "gears": [], "motors": [], "loads": [], "payloads": [], "reducers": [], "screws": [], "worms": [], "belts": []}
        for el in self.root:
            if not isinstance(el.tag, str) or etree.QName(el).namespace != NS:
                continue
            local = etree.QName(el).localname
            if el.get(q("derived")) == "true" or el.get("derived") == "true":
                continue
            if local == "mechanism":
                if ext["mechanism"] is not None:
                    self.add("gearcli:mechanism", "only one gearcli:mechanism element is allowed", el)
                ext["mechanism"] = el
                self.unknown_attrs(el, ("end_effector", "gravity", "open_loop", "description"), "gearcli:mechanism")
                if el.get("end_effector"):
                    self.lines["end_effector"] = el.sourceline
            elif local == "gear":
                ext["gears"].append(el)
            elif local == "motor":
                ext["motors"].append(el)
            elif local == "load":
                ext["loads"].append(el)
            elif local == "payload":
                ext["payloads"].append(el)
            elif local == "reducer":
                ext["reducers"].append(el)
            elif local == "screw":
                ext["screws"].append(el)
            elif local == "worm":
                ext["worms"].append(el)
            elif local == "belt":
                ext["belts"].append(el)
            elif local in ("motor_rating", "gear_rating", "motor_model"):
                continue  # read by io.ratings_reader
            else:
                self.add(f"gearcli:{local}", f"unknown gearcli element gearcli:{local} (expected gearcli:mechanism, "
                         "gearcli:gear, gearcli:reducer, gearcli:screw, gearcli:worm, gearcli:belt, gearcli:motor, gearcli:load or "
                         "gearcli:payload)", el)
        return ext

    def unknown_attrs(self, el, allowed, path: str) -> None:
        for attr in el.attrib:
            local = etree.QName(attr).localname
            if local not in allowed:
                self.add(path, f"unknown attribute '{local}' (allowed: {', '.join(allowed)})", el)

    def link_ref(self, name: str | None, path: str, el, what: str = "link"):
        """The body of link ``name`` and the link frame in it, or None (with an issue)."""
        if name is None:
            return None
        if name not in self.body_of:
            self.add(path, f"unknown {what} '{name}'", el)
            return None
        return self.body_of[name]

    def gear_geometry(self, el, path: str, allowed) -> dict:
        """GearPair keyword arguments from a gearcli:gear element's geometry attributes."""
        self.unknown_attrs(el, allowed, path)
        kw: dict = {}
        if el.get("name"):
            kw["name"] = el.get("name")
        kind = el.get("kind", "external")
        kw["kind"] = kind
        if el.get("teeth") is not None:
            t = self.vector(el, "teeth", path, n=2)
            if t is not None:
                if np.any(t <= 0) or np.any(t != np.round(t)):
                    self.add(path, f"teeth must be two positive integers, got \"{el.get('teeth')}\"", el)
                kw["teeth"] = (int(t[0]), int(t[1]))
        carrier = None
        if el.get("carrier") is not None:
            ref = self.link_ref(el.get("carrier"), path, el, "carrier link")
            if ref is not None:
                carrier = ref
                kw["carrier"] = ref[0]
        if el.get("mesh_point") is not None:
            P = self.vector(el, "mesh_point", path)
            if P is not None:
                if carrier is not None:  # the mesh point is in the carrier link's frame
                    T = carrier[1]
                    P = T[:3, :3] @ P + T[:3, 3]
                kw["mesh_point"] = P
        if el.get("hand") is not None:
            kw["hand"] = el.get("hand")
        if el.get("stiffness") is not None:
            k = self.vector(el, "stiffness", path, n=1)
            if k is not None and not k[0] > 0:
                self.add(path, f"mesh stiffness must be positive, got {k[0]:g} N/m", el)
            elif k is not None:
                kw["stiffness"] = float(k[0])
        loss = self.mesh_loss_factor(el, path)
        if loss:
            kw["loss_factor"] = loss
        for key in ("pressure_angle", "cone_angles", "helix_angle"):
            n = 2 if key == "cone_angles" else 1
            if el.get(key) is not None and el.get(f"{key}_deg") is not None:
                self.add(path, f"give either {key} (rad) or {key}_deg, not both", el)
            v = self.vector(el, key, path, n=n)
            if v is None:
                v = self.vector(el, f"{key}_deg", path, n=n)
                v = None if v is None else np.deg2rad(v)
            if v is not None:
                kw[key] = float(v[0]) if n == 1 else (float(v[0]), float(v[1]))
        return kw

    def mesh_loss_factor(self, el, path: str) -> float:
        """``efficiency`` eta in (0, 1] or ``loss_factor`` c in [0, 1) of a gearcli:gear (at most
        one; it needs ``mesh_point``) as the loss factor c = 1 - eta; 0 when neither."""
        eta, c = self.vector(el, "efficiency", path, n=1), self.vector(el, "loss_factor", path, n=1)
        if eta is not None and c is not None:
            self.add(path, "give efficiency or loss_factor (= 1 - efficiency), not both", el)
            return 0.0
        if eta is not None and not 0.0 < eta[0] <= 1.0:
            self.add(path, f"mesh efficiency must be in (0, 1], got {eta[0]:g}", el)
            return 0.0
        if c is not None and not 0.0 <= c[0] < 1.0:
            self.add(path, f"mesh loss factor must be in [0, 1), got {c[0]:g}", el)
            return 0.0
        loss = 1.0 - float(eta[0]) if eta is not None else (float(c[0]) if c is not None else 0.0)
        if loss and el.get("mesh_point") is None:
            self.add(path, "a mesh loss needs the tooth geometry (mesh_point): the loss is |t| times the "
                     "pitch-line speed", el)
        return loss

    def joint_friction(self, el, path: str, prismatic: bool) -> JointFriction:
        """A gearcli:friction element inside a joint: ``coulomb`` and ``viscous``, both >= 0."""
        self.unknown_attrs(el, ("coulomb", "viscous", "static"), f"{path}.gearcli:friction")
        values = {}
        for key, units in (("coulomb", ("N*m", "N")), ("viscous", ("N*m*s/rad", "N*s/m"))):
            v = self.vector(el, key, path, n=1)
            v = 0.0 if v is None else float(v[0])
            if not v >= 0:
                self.add(f"{path}.gearcli:friction", f"{key} friction must be >= 0, got {v:g} {units[prismatic]}", el)
            values[key] = v
        v = self.vector(el, "static", path, n=1)
        if v is not None:
            if not float(v[0]) >= values["coulomb"]:
                u = ("N*m", "N")[prismatic]
                self.add(f"{path}.gearcli:friction", f"static friction must be >= the Coulomb friction "
                         f"{values['coulomb']:g} {u}, got {float(v[0]):g} {u}", el)
            values["static"] = float(v[0])
        return JointFriction(**values)

    def check_gear_pair(self, el, path: str, j: str | None, k: str | None, kw: dict, ratio) -> None:
        """The checks every gear pair declaration gets (:func:`gearcli.model.validate.gear_pair_problems`);
        ``j``/``k`` None when unknown (already reported)."""
        same = j is not None and j == k
        for _, message in gear_pair_problems("j", "j" if same else "k", kw["kind"], ratio, "teeth" in kw,
                                             "mesh_point" in kw, "cone_angles" in kw, _helix_deg(el, kw),
                                             kw.get("hand")):
            self.add(path, message, el)

    def extension_gears(self, ext) -> list[GearPair]:
        gears = []
        names = {}
        for i, el in enumerate(ext["gears"]):
            name = el.get("name") or f"{el.get('j')}-{el.get('k')}"
            path = f"gearcli:gear '{name}'"
            self.lines[path] = el.sourceline
            if name in names:
                self.add(path, f"duplicate gear pair name '{name}' (first at line {names[name]})", el)
            names[name] = el.sourceline
            kw = self.gear_geometry(el, path, GEAR_ATTRS)
            kw.pop("name", None)
            ends = []
            for key in ("j", "k"):
                if not el.get(key):
                    self.add(path, f"gearcli:gear needs attribute {key} (a link name)", el)
                else:
                    ref = self.link_ref(el.get(key), path, el)
                    if ref is not None:
                        ends.append(ref[0])
            ratio = None
            if el.get("ratio") is not None:
                r = self.vector(el, "ratio", path, n=1)
                ratio = None if r is None else float(r[0])
            self.check_gear_pair(el, path, *(ends if len(ends) == 2 else (None, None)), kw, ratio)
            if len(ends) == 2:
                gears.append(GearPair(name, ends[0], ends[1], ratio=ratio, path=path, **kw))
        return gears

    def table_attr(self, el, attr: str, path: str):
        """A drive element's number-or-table attribute (``efficiency_forward``,
        ``no_load_torque``, ...) as the YAML value: a float, or [[w_in, value], ...] from
        "w1 v1 w2 v2 ..."; None with a problem (reported)."""
        text = el.get(attr)
        v = floats(text)
        if v is None or v.size == 0:
            self.add(path, f"{attr}=\"{text}\" is not a number or a table of pairs 'w_in value ...'", el)
            return None
        if v.size > 1 and v.size % 2:
            self.add(path, f"{attr}: a table is pairs 'w_in value ...', got {v.size} numbers", el)
            return None
        return float(v[0]) if v.size == 1 else [[float(a), float(b)] for a, b in v.reshape(-1, 2)]

    def efficiency_attrs(self, el, path: str) -> dict | None:
        """{"forward": ..., "backward": ...} of a drive element's ``efficiency_forward`` and
        ``efficiency_backward`` ({} without them; backward alone is refused), None with a problem."""
        eff = {}
        for k in ("forward", "backward"):
            if el.get(f"efficiency_{k}") is not None:
                v = self.table_attr(el, f"efficiency_{k}", path)
                if v is None:
                    return None
                eff[k] = v
        if eff and "forward" not in eff:
            self.add(path, "efficiency_backward needs efficiency_forward", el)
            return None
        return eff

    def extension_reducers(self, ext) -> list[GearPair]:
        """The gearcli:reducer elements (a strain-wave or cycloidal reducer, docs/concepts/drive-elements.md "Reducers"):
        attributes name, kind, input, output, housing, ratio or teeth, efficiency_forward,
        efficiency_backward and no_load_torque (a number, or a table "w1 v1 w2 v2 ..." over
        |w_in| rad/s), torsional_stiffness_torque "T1 T2" and torsional_stiffness_rate "K1 K2
        K3"; a child gearcli:rating with the catalogue keys.  Validated as the YAML keys are
        (:func:`.reducer_specs.reducer_spec`)."""
        out = []
        for el in ext["reducers"]:
            name = el.get("name") or f"{el.get('input')}-{el.get('output')}"
            path = f"gearcli:reducer '{name}'"
            self.lines[path] = el.sourceline
            self.unknown_attrs(el, REDUCER_ATTRS, path)
            spec = self._reducer_dict(el, path)
            ends = []
            for key in ("input", "output", "housing"):
                ref = self.link_ref(el.get(key), path, el) if el.get(key) else None
                if not el.get(key):
                    self.add(path, f"gearcli:reducer needs attribute {key} (a link name)", el)
                if ref is not None:
                    ends.append(ref[0])
            if spec is None or len(ends) < 3:
                continue
            if spec["kind"] not in REDUCER_KINDS:
                self.add(path, f"kind must be one of {', '.join(REDUCER_KINDS)}, got '{spec['kind']}'", el)
                continue
            i0, red = reducer_spec(spec, path, lambda p, m, el=el: self.add(_attribute_path(p), m, el))
            teeth = tuple(int(z) for z in spec["teeth"]) if "teeth" in spec else None
            out.append(GearPair(name, ends[0], ends[1], spec["kind"], i0, teeth=teeth, carrier=ends[2], path=path,
                                reducer=red))
        return out

    def extension_screws(self, ext) -> list[GearPair]:
        """The gearcli:screw elements (docs/concepts/drive-elements.md "Screws"): attributes name, screw, nut, carrier
        (links), lead (m/rev), hand, efficiency_forward and efficiency_backward (a number or a
        table "w1 v1 ..." over the screw's speed, rad/s), or friction_coefficient and diameter;
        a child gearcli:rating with C_a, C_0a, max_speed.  Validated as the YAML keys are
        (:func:`.element_specs.screw_spec`)."""
        out = []
        for el in ext["screws"]:
            name = el.get("name") or f"{el.get('screw')}-{el.get('nut')}"
            path = f"gearcli:screw '{name}'"
            self.lines[path] = el.sourceline
            self.unknown_attrs(el, SCREW_ATTRS, path)
            ends = []
            for key in ("screw", "nut"):
                ref = self.link_ref(el.get(key), path, el) if el.get(key) else None
                if not el.get(key):
                    self.add(path, f"gearcli:screw needs attribute {key} (a link name)", el)
                if ref is not None:
                    ends.append(ref[0])
            carrier = None
            if el.get("carrier") is not None:
                ref = self.link_ref(el.get("carrier"), path, el, "carrier link")
                carrier = None if ref is None else ref[0]
            spec = self._screw_dict(el, path)
            if spec is None or len(ends) < 2:
                continue
            sc = screw_spec(spec, path, lambda p, m, el=el: self.add(_attribute_path(p), m, el))
            out.append(GearPair(name, ends[0], ends[1], "screw", None, carrier=carrier, path=path, screw=sc))
        return out

    def extension_worms(self, ext) -> list[GearPair]:
        """The gearcli:worm elements (docs/concepts/drive-elements.md "Worm pairs"): attributes name, worm, wheel, carrier
        (links), teeth "z1 Z2", reference_diameter (m), module (m) and/or lead_angle (rad; both as
        gearcli export writes them: taken as given) or lead_angle_deg, pressure_angle (rad) or
        pressure_angle_deg, friction_coefficient, hand."""
        from ..model.worms import Worm  # noqa: PLC0415
        out = []
        for el in ext["worms"]:
            name = el.get("name") or f"{el.get('worm')}-{el.get('wheel')}"
            path = f"gearcli:worm '{name}'"
            self.lines[path] = el.sourceline
            self.unknown_attrs(el, WORM_ATTRS, path)
            ends = [ref[0] for key in ("worm", "wheel")
                    if (ref := self.link_ref(el.get(key), path, el) if el.get(key) else None) is not None]
            for key in ("worm", "wheel", "teeth", "reference_diameter", "hand"):
                if el.get(key) is None:
                    self.add(path, f"gearcli:worm needs attribute {key}", el)
            carrier = None
            if el.get("carrier") is not None:
                ref = self.link_ref(el.get("carrier"), path, el, "carrier link")
                carrier = None if ref is None else ref[0]
            nums = {k: self.vector(el, k, path, n=2 if k == "teeth" else 1) for k in
                    ("teeth", "reference_diameter", "module", "lead_angle", "lead_angle_deg", "pressure_angle",
                     "pressure_angle_deg", "friction_coefficient")}
            if len(ends) < 2 or nums["teeth"] is None or nums["reference_diameter"] is None or el.get("hand") is None:
                continue
            if nums["module"] is not None and nums["lead_angle"] is not None:      # as exported: exact
                t = nums["teeth"]
                pa = nums["pressure_angle"]
                wm = Worm(int(t[0]), int(t[1]), float(nums["reference_diameter"][0]), float(nums["module"][0]),
                          float(nums["lead_angle"][0]),
                          float(pa[0]) if pa is not None else math.radians(20.0),
                          float(nums["friction_coefficient"][0]) if nums["friction_coefficient"] is not None else 0.0,
                          el.get("hand"), path)
            else:
                spec = {"teeth": [int(v) for v in nums["teeth"]], "reference_diameter": float(nums["reference_diameter"][0]),
                        "hand": el.get("hand")}
                for k in ("module", "lead_angle_deg", "pressure_angle_deg", "friction_coefficient"):
                    if nums[k] is not None:
                        spec[k] = float(nums[k][0])
                wm = worm_spec(spec, path, lambda p, m, el=el: self.add(p, m, el))
            out.append(GearPair(name, ends[0], ends[1], "worm", None, teeth=(wm.z1, wm.z2) if wm else None,
                                carrier=carrier, path=path, worm=wm))
        return out

    def extension_belts(self, ext) -> list[GearPair]:
        """The gearcli:belt elements (docs/concepts/drive-elements.md "Timing belts"): attributes name, j, k, carrier (links),
        radii "r_j r_k" (m), pretension (N), belt_point "x y z" (the carrier link's URDF frame),
        efficiency_forward, efficiency_backward (numbers or tables "w1 v1 ..."), max_effective_pull,
        min_slack_ratio.  Validated as the YAML keys are (:func:`.element_specs.belt_spec`)."""
        out = []
        for el in ext["belts"]:
            name = el.get("name") or f"{el.get('j')}-{el.get('k')}"
            path = f"gearcli:belt '{name}'"
            self.lines[path] = el.sourceline
            self.unknown_attrs(el, BELT_ATTRS, path)
            ends = [ref[0] for key in ("j", "k") if (ref := self.link_ref(el.get(key), path, el) if el.get(key) else None)]
            carrier = self.link_ref(el.get("carrier"), path, el, "carrier link") if el.get("carrier") else None
            missing = [k for k in ("j", "k", "radii", "pretension", "belt_point") if el.get(k) is None]
            if missing:
                self.add(path, f"gearcli:belt needs attribute(s) {', '.join(missing)}", el)
                continue
            radii, T, P = self.vector(el, "radii", path, n=2), self.vector(el, "pretension", path, n=1), self.vector(el, "belt_point", path)
            if len(ends) < 2 or radii is None or T is None or P is None:
                continue
            if carrier is not None:              # the point is in the carrier link's URDF frame
                P = carrier[1][:3, :3] @ P + carrier[1][:3, 3]
            spec = {"radii": [float(v) for v in radii], "pretension": float(T[0]), "belt_point": list(P)}
            eff = self.efficiency_attrs(el, path)
            if eff is None:
                continue
            if eff:
                spec["efficiency"] = eff
            rating = {k: float(v[0]) for k in ("max_effective_pull", "min_slack_ratio")
                      if (v := self.vector(el, k, path, n=1)) is not None}
            if rating:
                spec["rating"] = rating
            bt = belt_spec(spec, path, lambda p, m, el=el: self.add(_attribute_path(p), m, el))
            out.append(GearPair(name, ends[0], ends[1], "belt", None, carrier=None if carrier is None else carrier[0],
                                path=path, belt=bt))
        return out

    def _screw_dict(self, el, path: str) -> dict | None:
        """The screw's attributes (and its gearcli:rating child) as the YAML mapping, or None
        when one is missing or unreadable (reported)."""
        spec: dict = {"kind": "screw"}
        for key in ("lead", "hand"):
            if el.get(key) is None:
                self.add(path, f"gearcli:screw needs attribute {key}", el)
                return None
        v = floats(el.get("lead"), 1)
        if v is None:
            self.add(path, f"lead=\"{el.get('lead')}\" is not a finite number", el)
            return None
        spec["lead"], spec["hand"] = float(v[0]), el.get("hand")
        if spec["hand"] not in ("right", "left"):
            self.add(path, f"hand must be 'right' or 'left', got '{spec['hand']}'", el)
            return None
        eff = self.efficiency_attrs(el, path)
        if eff is None:
            return None
        if eff:
            spec["efficiency"] = eff
        for key in ("friction_coefficient", "diameter"):
            if el.get(key) is not None:
                v = floats(el.get(key), 1)
                if v is None:
                    self.add(path, f"{key}=\"{el.get(key)}\" is not a finite number", el)
                    return None
                spec[key] = float(v[0])
        ratings = [c for c in el if isinstance(c.tag, str) and etree.QName(c).localname == "rating"]
        if ratings:
            r, rating = ratings[0], {}
            for k, text in r.attrib.items():
                x = floats(text, 1)
                if k not in ("C_a", "C_0a", "max_speed") or x is None or not x[0] > 0:
                    self.add(f"{path}.rating", f"gearcli:rating of a screw takes C_a, C_0a and max_speed (positive "
                             f"numbers), got {k}=\"{text}\"", r)
                    return None
                rating[k] = float(x[0])
            if "C_a" not in rating or "C_0a" not in rating:
                self.add(f"{path}.rating", "gearcli:rating of a screw needs C_a and C_0a", r)
                return None
            spec["rating"] = rating
        return spec

    def _reducer_dict(self, el, path: str) -> dict | None:
        """The reducer's attributes (and its gearcli:rating child) as the YAML mapping, or None
        when a number is unreadable (reported)."""
        spec: dict = {"kind": el.get("kind", "")}
        ok = True

        def numbers(attr, n=None):
            nonlocal ok
            text = el.get(attr)
            v = floats(text, n)
            if v is None or v.size == 0:
                self.add(path, f"{attr}=\"{text}\" is not {'a list of' if n is None else n} finite number(s)", el)
                ok = False
            return v

        for attr, key in (("ratio", "ratio"), ("teeth", "teeth")):
            if el.get(attr) is not None:
                v = numbers(attr, 1 if attr == "ratio" else 2)
                if v is not None:
                    spec[key] = float(v[0]) if attr == "ratio" else [int(z) for z in v]
        eff = self.efficiency_attrs(el, path)
        if eff is None:
            return None
        if eff:
            spec["efficiency"] = eff
        if el.get("no_load_torque") is not None:
            spec["no_load_torque"] = self.table_attr(el, "no_load_torque", path)
            ok = ok and spec["no_load_torque"] is not None
        if el.get("torsional_stiffness_torque") is not None or el.get("torsional_stiffness_rate") is not None:
            T, K = numbers("torsional_stiffness_torque", 2), numbers("torsional_stiffness_rate", 3)
            if T is not None and K is not None:
                spec["torsional_stiffness"] = {"torque": [float(v) for v in T], "rate": [float(v) for v in K]}
        ratings = [c for c in el if isinstance(c.tag, str) and etree.QName(c).localname == "rating"]
        if ratings:
            r = ratings[0]
            rating = {}
            for k, v in r.attrib.items():
                if k == "life_basis":
                    rating[k] = v
                    continue
                x = floats(v, 1)
                if x is None or not x[0] > 0:
                    self.add(f"{path}.rating", f"{k}=\"{v}\" is not a positive number", r)
                    ok = False
                else:
                    rating[k] = float(x[0])
            missing = [k for k in ("rated_torque", "rated_input_speed", "rated_life", "life_basis") if k not in rating]
            unknown = [k for k in rating if k not in RATING_KEYS]
            if missing or unknown or rating.get("life_basis", "L10") not in LIFE_BASES:
                self.add(f"{path}.rating", f"gearcli:rating needs {', '.join(RATING_KEYS[:4])} (life_basis L10 or L50)"
                         + (f"; missing {', '.join(missing)}" if missing else "")
                         + (f"; unknown {', '.join(unknown)}" if unknown else ""), r)
                ok = False
            spec["rating"] = rating
        return spec if ok else None

    # -- motors ------------------------------------------------------------------------------------
    def motors(self, ext, has_gears: bool) -> list[Motor]:
        """The gearcli:motor elements if any; else a motor per actuator of the usable
        <transmission>s and (without gearcli:gear elements) a direct drive per joint that is
        driven by none, in joint order."""
        if ext["motors"]:
            out = [self.extension_motor(el) for el in ext["motors"]]
            plain = [t for t in self.root.findall("transmission") if t.get(q("derived")) != "true"]
            if plain:
                n = len(plain)
                self.warn("", f"{counted(n, '<transmission> element')} {plural(n, 'is', 'are')} ignored: the gearcli:motor "
                          "elements define the motors")
            return [m for m in out if m is not None]
        driven: dict[str, str] = {}
        acts = self.transmission_motors(self.usable_transmissions(), driven)
        if not has_gears:
            # a direct drive for every joint that leads no driven mimic group
            led = {self.chain_leader(j) for j in driven}
            for name, jt in self.movable.items():
                if name not in self.leader and name not in led:
                    acts.append((self.joint_order.index(name), 0, Motor(name, jt.child, jt.parent, f"joint '{name}'")))
        acts.sort(key=lambda t: (t[0], t[1]))
        motors = [m for _, _, m in acts]
        seen: dict[str, str] = {}
        for m in motors:
            if m.name in seen:
                self.add(m.path, f"duplicate motor (actuator) name '{m.name}' (also in {seen[m.name]})")
            seen[m.name] = m.path
        return motors

    def usable_transmissions(self) -> list:
        """(spec, element) of each <transmission> that names known, movable joints and has a
        supported type; the others are reported (errors) or ignored (warnings)."""
        specs = read_transmissions(self.root)
        elements = self.root.findall("transmission")
        kept = []
        for spec, el in zip(specs, elements):
            if el.get(q("derived")) == "true":
                continue
            path = spec.path
            self.lines[path] = spec.line
            missing = [j for j in spec.joints if j not in self.joint_el]
            for j in missing:
                self.add(path, f"transmission '{spec.name}' names unknown joint '{j}'", el)
            if missing:
                continue
            for p in spec.problems:
                self.add(path, p, el)
            if spec.problems:
                continue
            if spec.kind not in TRANSMISSION_KINDS:
                self.warn(path, f"transmission type '{spec.kind or '?'}' is not supported and is ignored "
                          f"(supported: {', '.join(TRANSMISSION_KINDS)}); its joints are driven directly", el)
                continue
            fixed = [j for j in spec.joints if j not in self.movable]
            if fixed:
                self.warn(path, f"transmission '{spec.name}' drives fixed {plural(len(fixed), 'joint')} {', '.join(fixed)}: ignored", el)
                continue
            kept.append((spec, el))
        return kept

    def transmission_motors(self, kept: list, driven: dict) -> list:
        """(first joint position, order, Motor) per actuator of the transmissions ``kept``;
        ``driven[joint]`` = name of the transmission that drives it.  A transmission on a mimic
        follower is dropped when its leader has its own actuator."""
        acts: list[tuple[int, int, Motor]] = []
        own = {j for spec, _ in kept for j in spec.joints if j not in self.leader}
        for spec, el in kept:
            followers = [j for j in spec.joints if j in self.leader]
            if followers and all(self.chain_leader(j) in own for j in followers):
                n = len(followers)
                self.warn(spec.path, f"transmission '{spec.name}' drives {plural(n, 'joint')} {', '.join(followers)}, "
                          f"which {plural(n, 'follows', 'follow')} another joint through <mimic> "
                          f"whose actuator drives {plural(n, 'it', 'them')}: ignored", el)
                continue
            clash = [j for j in spec.joints if j in driven]
            if clash:
                self.add(spec.path, f"joint '{clash[0]}' is driven by transmissions '{driven[clash[0]]}' and "
                         f"'{spec.name}'", el)
                continue
            for j in spec.joints:
                driven[j] = spec.name
            for k, act in enumerate(spec.actuators):
                first = self.movable[act.joints[0][0]]
                pos = min(self.joint_order.index(j) for j, _ in act.joints)
                acts.append((pos, k, Motor(act.name, first.child, first.parent, spec.path,
                                           joints=tuple((j, float(c)) for j, c in act.joints))))
        return acts

    def extension_motor(self, el) -> Motor | None:
        name = el.get("name")
        path = f"gearcli:motor '{name}'"
        self.lines[path] = el.sourceline
        self.unknown_attrs(el, ("name", "link", "stator", "joints", "coefficients"), path)
        if not name or not el.get("link"):
            self.add(path, "gearcli:motor needs attributes name and link", el)
            return None
        link = self.link_ref(el.get("link"), path, el)
        stator = self.link_ref(el.get("stator"), path, el, "stator link") if el.get("stator") else None
        joints: tuple = ()
        if el.get("joints") is not None:
            names = el.get("joints").split()
            coefs = self.vector(el, "coefficients", path, n=len(names))
            if coefs is None:
                self.add(path, "gearcli:motor with joints needs as many coefficients", el)
                return None
            for j in names:
                if j not in self.movable:
                    self.add(path, f"motor '{name}' drives unknown joint '{j}'", el)
            joints = tuple(zip(names, map(float, coefs)))
        if link is None:
            return None
        return Motor(name, link[0], stator[0] if stator else None, path, joints=joints)

