"""URDF robot descriptions -> :class:`~gearcli.model.Mechanism`.

What each URDF element becomes (see ``docs/urdf.md`` for the table with examples):

* the **root link** is the fixed base; every other link hangs from it by one joint;
* ``revolute`` and ``continuous`` joints -> revolute joints, ``prismatic`` -> prismatic
  joints (the drive force along the axis is reported like a motor torque); geometry
  ``R_pj = rpy(origin) @ align_z(axis)``, ``p_pj = xyz``, ``R_jc = align_z(axis)^T``, so the
  joint frame is the URDF child frame turned to put z on the axis (the same frame when the
  axis is z);
* ``fixed`` joints merge their child into the parent body: mass, centre of mass and
  inertia are lumped exactly, and joints hanging from the merged link are re-expressed in
  the body frame; ``floating`` and ``planar`` joints are errors;
* ``<inertial>``: the tensor, given about the centre of mass in the ``<origin>`` frame
  (xyz and rpy), is rotated into the link frame; links without ``<inertial>`` are massless;
* ``<mimic joint="A" multiplier="m" offset="c"/>`` in joint B: a coupling
  ``q_B = m q_A + c`` (a :class:`~gearcli.model.GearPair` with ``joints=(B, A)``).  The
  offset is absorbed into B's joint frame (B's coordinate is counted from the offset), so
  the kinematics stays linear.  Without gear geometry the coupling is ideal: a torque pair
  on the two joints, each joint's parent taking the reaction;
* ``<transmission>``: actuators driving joints through reductions
  (:mod:`gearcli.transmissions`); every movable joint that is neither a mimic follower nor
  driven by a transmission gets a direct-drive motor named after the joint (unless the file
  has ``gearcli:gear`` elements, whose motors must then be listed);
* extension elements in the namespace :data:`NS` (other URDF tools ignore them):
  ``<gearcli:mechanism end_effector= gravity= open_loop=/>``, ``<gearcli:gear .../>``
  (a full gear pair, attributes as in the YAML format), ``<gearcli:motor .../>``, and,
  inside a ``<joint>``, ``<gearcli:joint label=/>`` and ``<gearcli:gear .../>`` (the mesh
  geometry of that joint's mimic coupling).  Elements and attributes marked
  ``gearcli:derived="true"`` were written by :mod:`gearcli.urdf_export` for other tools and
  are ignored here (the gearcli elements hold the exact data).

The primary links are a tree (``Mechanism.open_loop = "tree"``): the independent
coordinates are the joints that do not follow another through a mimic or gear pair, unless
``gearcli:mechanism`` gives an ``end_effector`` (the paper's open-loop chain).

Problems are collected with the element's name and line (``file:line: joint 'j2': ...``)
and raised together as :class:`~gearcli.errors.MechanismError`; input that is worked
around (unsupported transmissions, ignored friction) is listed in ``Mechanism.warnings``.
"""
from __future__ import annotations

import io
from dataclasses import replace
from pathlib import Path

import numpy as np
from lxml import etree

from ..errors import Collector, Issue, MechanismError
from ..model.validate import check_inertia
from ..model.mechanism import GEAR_KINDS, GearPair, Joint, Link, Mechanism, Motor
from ..spatial import align_z, matrix_rpy, rot_z
from .ratings_reader import attach_urdf_ratings
from .urdf_transmissions import KINDS as TRANSMISSION_KINDS
from .urdf_transmissions import read_transmissions

NS = "https://gearcli.dev/urdf/1"
"""XML namespace of gearcli's URDF extension elements (prefix ``gearcli``)."""

JOINT_TYPES = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic"}
INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
GEAR_ATTRS = ("name", "j", "k", "kind", "ratio", "teeth", "carrier", "mesh_point", "pressure_angle",
              "pressure_angle_deg", "cone_angles", "cone_angles_deg", "derived")
MIMIC_GEAR_ATTRS = ("name", "kind", "teeth", "carrier", "mesh_point", "pressure_angle",
                    "pressure_angle_deg", "cone_angles", "cone_angles_deg")


def q(tag: str) -> str:
    """Qualified name of a gearcli extension element or attribute."""
    return f"{{{NS}}}{tag}"


def load_urdf(path: str | Path) -> Mechanism:
    """Read a URDF file; raises :class:`~gearcli.errors.MechanismError` on bad input."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise MechanismError([Issue(str(path), "", None, f"cannot read file: {exc.strerror}")]) from None
    return parse_urdf(data, str(path))


def parse_urdf(text: str | bytes, file: str = "<string>") -> Mechanism:
    """Parse the text of a URDF (see the module docstring for the mapping)."""
    data = text.encode("utf-8") if isinstance(text, str) else text
    parser = etree.XMLParser(remove_comments=True, resolve_entities=False, no_network=True)
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        line = exc.lineno if getattr(exc, "lineno", None) else None
        msg = str(exc.msg if getattr(exc, "msg", None) else exc)
        msg = msg.split(", line ")[0]
        raise MechanismError([Issue(file, "", line, f"malformed XML: {msg}")]) from None
    return attach_urdf_ratings(_Reader(root, data, file).build(), root, file)


def _floats(text: str | None, n: int | None = None) -> np.ndarray | None:
    """Whitespace-separated finite numbers, or None if malformed (or the wrong count)."""
    if text is None:
        return None
    try:
        v = np.array([float(x) for x in text.split()], float)
    except ValueError:
        return None
    if (n is not None and v.size != n) or not np.all(np.isfinite(v)):
        return None
    return v


def _transform(origin) -> np.ndarray:
    return np.eye(4) if origin is None else np.asarray(origin, float)


class _Reader:
    """One URDF being read: elements by name, issues and warnings with their lines."""

    def __init__(self, root, data: bytes, file: str):
        self.root, self.data, self.file = root, data, file
        self.lines: dict[str, int] = {}
        self.col = Collector(file, self.lines)
        self.warnings: list[str] = []

    # -- reporting ------------------------------------------------------------------------
    def add(self, path: str, message: str, element=None) -> None:
        if element is not None and path not in self.lines:
            self.lines[path] = element.sourceline
        line = element.sourceline if element is not None else self.col.line_of(path)
        self.col.issues.append(Issue(self.file, path, line, message))

    def warn(self, path: str, message: str, element=None) -> None:
        line = element.sourceline if element is not None else self.col.line_of(path)
        self.warnings.append(str(Issue(self.file, path, line, message)))

    def vector(self, el, attr: str, path: str, n: int = 3, default=None):
        text = el.get(attr) if el is not None else None
        if text is None:
            return default
        v = _floats(text, n)
        if v is None:
            what = "a finite number" if n == 1 else f"{n} finite numbers"
            self.add(path, f"{attr}=\"{text}\" is not {what}", el)
            return default
        return v

    # -- the whole file ---------------------------------------------------------------------
    def build(self) -> Mechanism:
        root = self.root
        if not isinstance(root.tag, str) or etree.QName(root).localname != "robot" or etree.QName(root).namespace:
            raise MechanismError([Issue(self.file, "", root.sourceline, f"not a URDF: the root element is "
                                        f"<{root.tag}>, expected <robot>")])
        self.lines[""] = root.sourceline
        if not root.get("name"):
            raise MechanismError([Issue(self.file, "", root.sourceline, "the <robot> element has no name")])
        for key in ("gears", "motors", "end_effector"):
            self.lines[key] = root.sourceline
        self.check_structure()
        self.col.raise_if_any()
        self.parse_values()
        self.col.raise_if_any()
        self.merge_fixed()
        links = self.bodies_to_links()
        ext = self.read_extension()
        joints = self.movable_joints()
        self.col.raise_if_any()
        gears = self.couplings() + self.extension_gears(ext)
        self.col.raise_if_any()
        joints = self.absorb_offsets(joints)
        motors = self.motors(ext, bool(ext["gears"]))
        self.col.raise_if_any()
        mech_el = ext["mechanism"]
        end_effector, open_loop = self.end_effector(mech_el)
        gravity = np.array([0.0, 0.0, -9.81])
        if mech_el is not None:
            gravity = self.vector(mech_el, "gravity", "gearcli:mechanism", default=gravity)
        self.col.raise_if_any()
        return Mechanism(
            name=root.get("name") or Path(self.file).stem, base=self.base, end_effector=end_effector,
            links=tuple(links), joints=tuple(joints), gears=tuple(gears), motors=tuple(motors),
            gravity=np.asarray(gravity, float), source=self.file, lines=dict(self.lines),
            open_loop=open_loop, warnings=tuple(self.warnings),
        )

    # -- structure (lxml): names, references, types, numbers, tree ---------------------------
    def register(self, el, kind: str, seen: dict) -> str | None:
        """Record a named <link>/<joint> in ``seen``; its path, or None (reported) when it has
        no name or a duplicate one."""
        name = el.get("name")
        if not name:
            self.add(kind, f"a <{kind}> has no name", el)
            return None
        path = f"{kind} '{name}'"
        if name in seen:
            self.add(path, f"duplicate {kind} name '{name}' (first at line {seen[name].sourceline})", el)
            return None
        seen[name] = el
        self.lines[path] = el.sourceline
        return path

    def check_structure(self) -> None:
        """Names, references, types and numbers of every <link> and <joint>, then that the
        joints form one tree (sets ``self.base``)."""
        self.link_el: dict[str, object] = {}
        for el in self.root.findall("link"):
            path = self.register(el, "link", self.link_el)
            if path is not None:
                self.check_inertial(el, path)
        self.joint_el: dict[str, object] = {}
        self.parent_of: dict[str, str] = {}   # link -> parent link
        self.joint_into: dict[str, str] = {}  # link -> joint whose child it is
        for el in self.root.findall("joint"):
            path = self.register(el, "joint", self.joint_el)
            if path is not None:
                self.check_joint(el, path)
        if self.col.issues:
            return
        self.check_tree()

    def check_joint(self, el, path: str) -> None:
        """Type, parent and child links (recorded in ``parent_of``/``joint_into``), origin,
        axis and mimic numbers of one <joint>."""
        jtype = el.get("type")
        if jtype in ("floating", "planar"):
            self.add(path, f"joint type '{jtype}' is not supported: gearcli analyses mechanisms on a "
                     "fixed base with one-degree-of-freedom joints (revolute, continuous, prismatic, fixed)", el)
        elif jtype not in JOINT_TYPES and jtype != "fixed":
            self.add(path, f"unknown joint type '{jtype}' (expected revolute, continuous, prismatic or fixed)"
                     if jtype else "the joint has no type", el)
        self.check_joint_ends(el, path)
        origin = el.find("origin")
        self.vector(origin, "xyz", path)
        self.vector(origin, "rpy", path)
        axis_el = el.find("axis")
        axis = self.vector(axis_el, "xyz", path)
        if axis is not None and np.linalg.norm(axis) < 1e-12 and jtype in JOINT_TYPES:
            self.add(path, "the joint axis is the zero vector", axis_el)
        mimic = el.find("mimic")
        if mimic is not None:
            for attr in ("multiplier", "offset"):
                self.vector(mimic, attr, f"{path}.mimic", n=1)

    def check_joint_ends(self, el, path: str) -> None:
        """The joint's <parent> and <child> links: known, distinct, one parent joint a link."""
        ends = {}
        for end in ("parent", "child"):
            sub = el.find(end)
            link = sub.get("link") if sub is not None else None
            if not link:
                self.add(path, f"the joint has no <{end} link=\"...\"/>", el)
            elif link not in self.link_el:
                self.add(path, f"unknown {end} link '{link}'", sub)
            else:
                ends[end] = link
        if len(ends) == 2:
            p, c = ends["parent"], ends["child"]
            if p == c:
                self.add(path, f"the joint connects link '{p}' to itself", el)
            elif c in self.joint_into:
                self.add(path, f"link '{c}' is already the child of joint '{self.joint_into[c]}' "
                         "(a URDF is a tree: each link has one parent joint)", el)
            else:
                self.joint_into[c] = el.get("name")
                self.parent_of[c] = p

    def check_tree(self) -> None:
        """One root link (the base, ``self.base``) from which every link hangs, no loop."""
        root = self.root
        roots = [n for n in self.link_el if n not in self.parent_of]
        if not self.link_el:
            self.add("", "the robot has no links", root)
        elif not roots:
            self.add("", "the joints form a loop: no link is the root (a URDF must be a tree)", root)
        elif len(roots) > 1:
            self.add("", f"several root links ({', '.join(roots)}): a URDF must be one tree hanging from "
                     "one root link (the fixed base)", root)
        else:
            self.base = roots[0]
            # a loop not through the root: some link does not reach the root
            for link in self.link_el:
                seen, x = set(), link
                while x in self.parent_of and x not in seen:
                    seen.add(x)
                    x = self.parent_of[x]
                if x != self.base:
                    j = self.joint_into[link]
                    self.add(f"joint '{j}'", f"the joints form a loop through link '{link}' (a URDF must be a tree)",
                             self.joint_el[j])
                    break

    def check_inertial(self, el, path: str) -> None:
        inertial = el.find("inertial")
        if inertial is None:
            return
        self.vector(inertial.find("origin"), "xyz", f"{path}.inertial")
        self.vector(inertial.find("origin"), "rpy", f"{path}.inertial")
        mass = inertial.find("mass")
        if mass is None or mass.get("value") is None:
            self.add(f"{path}.inertial", "<inertial> has no <mass value=\"...\"/>", inertial)
        else:
            m = _floats(mass.get("value"), 1)
            if m is None:
                self.add(f"{path}.inertial", f"mass \"{mass.get('value')}\" is not a finite number", mass)
            elif m[0] < 0:
                self.add(f"{path}.inertial", f"mass must not be negative, got {m[0]:g} kg", mass)
        inertia = inertial.find("inertia")
        if inertia is None:
            self.add(f"{path}.inertial", "<inertial> has no <inertia .../>", inertial)
            return
        missing = [k for k in INERTIA_KEYS if inertia.get(k) is None]
        if missing:
            self.add(f"{path}.inertial", f"<inertia> misses {', '.join(missing)}", inertia)
        for k in INERTIA_KEYS:
            if inertia.get(k) is not None and _floats(inertia.get(k), 1) is None:
                self.add(f"{path}.inertial", f"{k}=\"{inertia.get(k)}\" is not a finite number", inertia)

    # -- values (yourdfpy) ----------------------------------------------------------------------
    def parse_values(self) -> None:
        import yourdfpy  # noqa: PLC0415  (slow import, only for URDF)

        try:
            urdf = yourdfpy.URDF.load(io.BytesIO(self.data), build_scene_graph=False, load_meshes=False,
                                      build_collision_scene_graph=False, load_collision_meshes=False)
        except Exception as exc:  # noqa: BLE001  (yourdfpy raises bare KeyError/ValueError)
            self.add("", f"yourdfpy cannot read this URDF: {type(exc).__name__}: {exc}")
            return
        self.ylinks = {l.name: l for l in urdf.robot.links}
        self.yjoints = {j.name: j for j in urdf.robot.joints}
        self.joint_order = [j.name for j in urdf.robot.joints]
        self.link_order = [l.name for l in urdf.robot.links]

    # -- fixed joints: bodies ------------------------------------------------------------------------
    def merge_fixed(self) -> None:
        """``body_of[link] = (body, T)``: the body a link belongs to and the link frame in
        the body frame (4x4); a body is the root or the child of a movable joint."""
        children: dict[str, list[str]] = {}
        for j in self.joint_order:
            children.setdefault(self.yjoints[j].parent, []).append(j)
        self.body_of = {self.base: (self.base, np.eye(4))}
        stack = [self.base]
        while stack:
            link = stack.pop()
            body, T = self.body_of[link]
            for j in children.get(link, []):
                yj = self.yjoints[j]
                if yj.type == "fixed":
                    self.body_of[yj.child] = (body, T @ _transform(yj.origin))
                else:
                    self.body_of[yj.child] = (yj.child, np.eye(4))
                stack.append(yj.child)
        self.bodies = [n for n in self.link_order if self.body_of[n][0] == n]
        for j in self.joint_order:
            el = self.joint_el[j]
            mimic = el.find("mimic")
            if self.yjoints[j].type == "fixed" and mimic is not None and mimic.get(q("derived")) != "true":
                self.warn(f"joint '{j}'", "<mimic> of a fixed joint is ignored", mimic)

    def bodies_to_links(self) -> list[Link]:
        members: dict[str, list[str]] = {b: [] for b in self.bodies}
        for n in self.link_order:
            members[self.body_of[n][0]].append(n)
        links = []
        for b in self.bodies:
            parts = []
            for n in members[b]:
                yi = self.ylinks[n].inertial
                if yi is None:
                    continue
                T = self.body_of[n][1] @ _transform(yi.origin)
                I = np.asarray(yi.inertia, float) if yi.inertia is not None else np.zeros((3, 3))
                parts.append((float(yi.mass or 0.0), T[:3, 3], T[:3, :3] @ I @ T[:3, :3].T))
            mass, com, inertia = _lump(parts)
            path = f"link '{b}'"
            if b != self.base and mass > 0 and np.abs(np.linalg.eigvalsh(inertia)).max() > 1e-12:
                why = check_inertia(inertia, mass)  # (round-off on a zero tensor is no problem)
                if why:
                    self.warn(path, f"{why} (used as given)", self.link_el[b])
            links.append(Link(b, mass, com, inertia, path))
        return links

    # -- movable joints ---------------------------------------------------------------------------
    def movable_joints(self) -> list[Joint]:
        joints = []
        dyn = []
        for name in self.joint_order:
            yj = self.yjoints[name]
            if yj.type == "fixed":
                continue
            el = self.joint_el[name]
            path = f"joint '{name}'"
            parent, Tp = self.body_of[yj.parent]
            T = Tp @ _transform(yj.origin)
            axis = np.asarray(yj.axis, float)
            axis = axis / np.linalg.norm(axis)
            A = align_z(axis)
            label = None
            for sub in el:
                if not isinstance(sub.tag, str) or etree.QName(sub).namespace != NS:
                    continue
                local = etree.QName(sub).localname
                if local == "joint":
                    label = sub.get("label")
                    self.unknown_attrs(sub, ("label",), path)
                elif local == "bearing":
                    continue  # read by io.ratings_reader
                elif local != "gear":
                    self.add(path, f"unknown element gearcli:{local} in a joint (expected gearcli:joint "
                             "or gearcli:gear)", sub)
                elif el.find("mimic") is None:
                    self.add(path, "gearcli:gear inside a joint gives the geometry of its <mimic> "
                             "coupling, but the joint has no <mimic>", sub)
            source = {"origin": {"xyz": T[:3, 3].tolist(), "rpy": matrix_rpy(T[:3, :3]).tolist()},
                      "axis": axis.tolist(), "urdf_type": yj.type}
            lim = yj.limit
            if lim is not None and None not in (lim.lower, lim.upper, lim.effort, lim.velocity):
                source["limit"] = {"lower": lim.lower, "upper": lim.upper, "effort": lim.effort,
                                   "velocity": lim.velocity}
            d = yj.dynamics
            if d is not None and any(_floats(x, 1) is not None and _floats(x, 1)[0] != 0
                                     for x in (d.damping, d.friction) if x is not None):
                dyn.append(name)
            joints.append(Joint(name, parent, yj.child, T[:3, :3] @ A, T[:3, 3].copy(), A.T, np.zeros(3),
                                JOINT_TYPES[yj.type], label, source, path))
        if dyn:
            more = f" and {len(dyn) - 4} more" if len(dyn) > 5 else ""
            self.warn("", f"<dynamics> damping and friction of joint(s) {', '.join(dyn[:4] if more else dyn)}{more} are ignored "
                      "(gearcli computes the loads of rigid, frictionless joints)")
        if not joints:
            self.add("", "the robot has no movable joints: nothing to analyse", self.root)
        self.movable = {j.name: j for j in joints}
        return joints

    # -- mimic couplings ------------------------------------------------------------------------
    def couplings(self) -> list[GearPair]:
        """A GearPair(joints=(B, A)) per <mimic> of a movable joint; the offsets stay in
        ``self.leader`` (absorbed into the joint frames later)."""
        elements = self.mimic_leaders()
        self.check_mimic_cycles(elements)
        if self.col.issues:
            return []
        return [self.mimic_pair(b, a, m) for b, (a, m, c) in self.leader.items()]

    def mimic_leaders(self) -> dict:
        """``self.leader[B] = (A, multiplier, offset)`` for each valid <mimic> of a movable
        joint B; returns the <mimic> elements by follower name."""
        self.leader: dict[str, tuple[str, float, float]] = {}
        elements = {}
        for name in self.joint_order:
            if name not in self.movable:
                continue
            el = self.joint_el[name].find("mimic")
            if el is None or el.get(q("derived")) == "true":
                continue
            path = f"joint '{name}'.mimic"
            self.lines[path] = el.sourceline
            a = el.get("joint")
            if not a:
                self.add(path, "<mimic> has no joint attribute", el)
                continue
            if a not in self.joint_el:
                self.add(path, f"joint '{name}' mimics unknown joint '{a}'", el)
                continue
            if a not in self.movable:
                self.add(path, f"joint '{name}' mimics fixed joint '{a}'", el)
                continue
            m = float(self.yjoints[name].mimic.multiplier)
            c = float(self.yjoints[name].mimic.offset)
            if m == 0:
                self.add(path, "mimic multiplier must not be zero (a joint locked at its offset is a fixed joint)", el)
                continue
            self.leader[name] = (a, m, c)
            elements[name] = el
        return elements

    def check_mimic_cycles(self, elements: dict) -> None:
        """Report each cycle of joints following one another (once, from its first joint)."""
        reported: set[str] = set()
        for start in self.leader:
            seen, x = [], start
            while x in self.leader and x not in seen:
                seen.append(x)
                x = self.leader[x][0]
            if x in seen and x not in reported:
                cyc = seen[seen.index(x):]
                reported.update(cyc)
                first = min(cyc, key=self.joint_order.index)
                loop = cyc[cyc.index(first):] + cyc[:cyc.index(first)] + [first]
                self.add(f"joint '{first}'.mimic", f"mimic cycle: {' -> '.join(loop)} "
                         "(each joint follows the next; no joint leads)", elements[first])

    def mimic_pair(self, b: str, a: str, m: float) -> GearPair:
        """The coupling q_B = m q_A, with the mesh geometry of B's gearcli:gear if any."""
        jb, ja = self.movable[b], self.movable[a]
        gear = self.joint_el[b].find(q("gear"))
        kw = {}
        if gear is not None:
            kw = self.gear_geometry(gear, f"joint '{b}'.gearcli:gear", MIMIC_GEAR_ATTRS)
            if jb.parent != ja.parent:
                self.add(f"joint '{b}'.gearcli:gear", f"gear geometry on a mimic needs both joints on one "
                         f"carrier, but '{b}' hangs from '{jb.parent}' and '{a}' from '{ja.parent}' "
                         "(give the pair as a top-level gearcli:gear)", gear)
            kw.setdefault("carrier", jb.parent)
        name = kw.pop("name", None) or f"mimic_{b}"
        return GearPair(name, jb.child, ja.child, ratio=m, joints=(b, a), path=f"joint '{b}'.mimic", **kw)

    def absorb_offsets(self, joints: list[Joint]) -> list[Joint]:
        """q_B = m q_A + c: count B from its offset (B's joint frame turned, or slid, by the
        total offset along its mimic chain), so that q_B' = m q_A' is linear."""
        total: dict[str, float] = {}

        def offset(name: str) -> float:
            if name not in self.leader:
                return 0.0
            if name not in total:
                a, m, c = self.leader[name]
                total[name] = m * offset(a) + c
            return total[name]

        out = []
        for jt in joints:
            c = offset(jt.name)
            if c == 0.0:
                out.append(jt)
            elif jt.type == "prismatic":
                out.append(replace(jt, p_pj=jt.p_pj + c * jt.R_pj[:, 2]))
            else:
                out.append(replace(jt, R_pj=jt.R_pj @ rot_z(c)))
        return out

    # -- gearcli extension elements -----------------------------------------------------------------
    def read_extension(self) -> dict:
        ext = {"mechanism": None, "gears": [], "motors": []}
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
            elif local in ("motor_rating", "gear_rating"):
                continue  # read by io.ratings_reader
            else:
                self.add(f"gearcli:{local}", f"unknown gearcli element gearcli:{local} (expected gearcli:mechanism, "
                         "gearcli:gear or gearcli:motor)", el)
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
        if kind not in GEAR_KINDS:
            self.add(path, f"unknown gear kind '{kind}' (expected {', '.join(GEAR_KINDS)})", el)
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
        for key in ("pressure_angle", "cone_angles"):
            n = 1 if key == "pressure_angle" else 2
            if el.get(key) is not None and el.get(f"{key}_deg") is not None:
                self.add(path, f"give either {key} (rad) or {key}_deg, not both", el)
            v = self.vector(el, key, path, n=n)
            if v is None:
                v = self.vector(el, f"{key}_deg", path, n=n)
                v = None if v is None else np.deg2rad(v)
            if v is not None:
                kw[key] = float(v[0]) if n == 1 else (float(v[0]), float(v[1]))
        if "cone_angles" in kw and kind != "bevel":
            self.add(path, f"cone angles are only for bevel gears, this pair is {kind}", el)
        return kw

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
                if r is not None:
                    ratio = float(r[0])
                    if ratio == 0:
                        self.add(path, "gear ratio must not be zero", el)
            if ratio is None and "teeth" not in kw:
                self.add(path, "a gear pair needs a ratio or tooth counts (teeth)", el)
            if ratio is None and "mesh_point" not in kw:
                self.add(path, "a gear pair without mesh_point needs an explicit signed ratio", el)
            if len(ends) == 2:
                if ends[0] == ends[1]:
                    self.add(path, "a gear pair needs two different links", el)
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
                self.warn("", f"{len(plain)} <transmission> element(s) are ignored: the gearcli:motor "
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
                self.warn(path, f"transmission '{spec.name}' drives fixed joint(s) {', '.join(fixed)}: ignored", el)
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
                self.warn(spec.path, f"transmission '{spec.name}' drives joint(s) {', '.join(followers)}, which "
                          "follow another joint through <mimic> whose actuator drives them: ignored", el)
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

    def chain_leader(self, name: str) -> str:
        while name in self.leader:
            name = self.leader[name][0]
        return name

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

    # -- end effector ------------------------------------------------------------------------------
    def end_effector(self, mech_el) -> tuple[str, str]:
        open_loop = "tree"
        if mech_el is not None:
            if mech_el.get("end_effector"):
                ref = self.link_ref(mech_el.get("end_effector"), "end_effector", mech_el)
                open_loop = mech_el.get("open_loop", "chain")
                if open_loop not in ("chain", "tree"):
                    self.add("gearcli:mechanism", f"open_loop must be 'chain' or 'tree', got '{open_loop}'", mech_el)
                if ref is not None:
                    return ref[0], open_loop
            elif mech_el.get("open_loop") not in (None, "tree"):
                self.add("gearcli:mechanism", "open_loop=\"chain\" needs an end_effector", mech_el)
        # the tip of the longest chain of movable joints that follows no other joint
        depth = {self.base: (0, True)}

        def walk(body: str):
            if body not in depth:
                jt = next(j for j in self.movable.values() if j.child == body)
                d, free = walk(jt.parent)
                depth[body] = (d + 1, free and jt.name not in self.leader)
            return depth[body]
        best = max((b for b in self.bodies if b != self.base), default=self.base,
                   key=lambda b: (walk(b)[1], walk(b)[0]))
        return best, open_loop


def _lump(parts) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass and inertia about it (body axes) of rigidly joined parts, each
    (mass, centre of mass, inertia about its centre in body axes)."""
    if not parts:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    if len(parts) == 1:
        m, c, I = parts[0]
        return m, np.asarray(c, float).copy(), 0.5 * (I + I.T)
    M = sum(m for m, _, _ in parts)
    com = sum(m * c for m, c, _ in parts) / M if M > 0 else np.zeros(3)
    I = np.zeros((3, 3))
    for m, c, Ic in parts:
        d = c - com
        I += Ic + m * ((d @ d) * np.eye(3) - np.outer(d, d))
    return M, com, 0.5 * (I + I.T)


__all__ = ["NS", "load_urdf", "parse_urdf"]
