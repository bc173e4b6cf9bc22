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
from .urdf_xml import NS, floats, q

GEAR_ATTRS = ("name", "j", "k", "kind", "ratio", "teeth", "carrier", "mesh_point", "pressure_angle",
              "pressure_angle_deg", "cone_angles", "cone_angles_deg", "helix_angle", "helix_angle_deg", "hand",
              "stiffness", "derived", "efficiency", "loss_factor")


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
        ext = {"mechanism": None, "gears": [], "motors": [], "loads": [], "payloads": []}
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
            elif local in ("motor_rating", "gear_rating", "motor_model"):
                continue  # read by io.ratings_reader
            else:
                self.add(f"gearcli:{local}", f"unknown gearcli element gearcli:{local} (expected gearcli:mechanism, "
                         "gearcli:gear, gearcli:motor, gearcli:load or gearcli:payload)", el)
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

