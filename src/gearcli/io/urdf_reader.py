"""URDF robot descriptions -> :class:`~gearcli.model.mechanism.Mechanism`.

What each URDF element becomes (docs/reference/urdf.md has the table with examples):

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
  ``q_B = m q_A + c`` (a :class:`~gearcli.model.mechanism.GearPair` with ``joints=(B, A)``).  The
  offset is absorbed into B's joint frame (B's coordinate is counted from the offset), so
  the kinematics stays linear.  Without gear geometry the coupling is ideal: a torque pair
  on the two joints, each joint's parent taking the reaction;
* ``<transmission>``: actuators driving joints through reductions
  (:mod:`gearcli.io.urdf_transmissions`); every movable joint that is neither a mimic follower nor
  driven by a transmission gets a direct-drive motor named after the joint (unless the file
  has ``gearcli:gear`` elements, whose motors must then be listed);
* extension elements in the namespace :data:`NS` (other URDF tools ignore them):
  ``<gearcli:mechanism end_effector= gravity= open_loop=/>``, ``<gearcli:gear .../>``
  (a full gear pair, attributes as in the YAML format), ``<gearcli:motor .../>``,
  ``<gearcli:load .../>`` (an external load, :mod:`gearcli.io.loads_reader`), and,
  inside a ``<joint>``, ``<gearcli:joint label=/>`` and ``<gearcli:gear .../>`` (the mesh
  geometry of that joint's mimic coupling).  Elements and attributes marked
  ``gearcli:derived="true"`` were written by :mod:`gearcli.report.urdf_writer` for other tools and
  are ignored here (the gearcli elements hold the exact data).

The primary links are a tree (``Mechanism.open_loop = "tree"``): the independent
coordinates are the joints that do not follow another through a mimic or gear pair, unless
``gearcli:mechanism`` gives an ``end_effector`` (the paper's open-loop chain).

Problems are collected with the element's name and line (``file:line: joint 'j2': ...``)
and raised together as :class:`~gearcli.errors.MechanismError`; input that is worked
around (unsupported transmissions, ignored friction) is listed in ``Mechanism.warnings``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from lxml import etree

from ..errors import Collector, Issue, LocatedWarning, MechanismError, plural
from ..model.mechanism import Joint, Link, Mechanism
from ..model.validate import check_inertia
from ..spatial import align_z, matrix_rpy
from .limits import read_bytes
from .ratings_reader import attach_urdf_ratings
from .loads_reader import UrdfLoads
from .urdf_extension import Extension
from .urdf_mimic import Mimics
from .urdf_structure import JOINT_TYPES, StructureChecks
from .urdf_xml import NS, floats as _floats, load_yourdfpy, parse_xml, placeholders, q, range_problem


def load_urdf(path: str | Path) -> Mechanism:
    """Read a URDF file; raises :class:`~gearcli.errors.MechanismError` on bad input."""
    return parse_urdf(read_bytes(path, "URDF file"), str(path))


def parse_urdf(text: str | bytes, file: str = "<string>") -> Mechanism:
    """Parse the text of a URDF (see the module docstring for the mapping)."""
    data = text.encode("utf-8") if isinstance(text, str) else text
    root = parse_xml(data, file)
    return attach_urdf_ratings(_Reader(root, data, file).build(), root, file)


def _transform(origin) -> np.ndarray:
    return np.eye(4) if origin is None else np.asarray(origin, float)


class _Reader(StructureChecks, Mimics, Extension, UrdfLoads):
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
        self.warnings.append(LocatedWarning(Issue(self.file, path, line, message)))

    def vector(self, el, attr: str, path: str, n: int = 3, default=None):
        text = el.get(attr) if el is not None else None
        if text is None:
            return default
        v = _floats(text, n)
        if v is None:
            what = "a finite number" if n == 1 else f"{n} finite numbers"
            why = range_problem(text)
            self.add(path, f"{attr}=\"{text}\": {why}" if why else f"{attr}=\"{text}\" is not {what}", el)
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
        elements = (self.extension_gears(ext) + self.extension_reducers(ext) + self.extension_screws(ext)
                    + self.extension_worms(ext) + self.extension_belts(ext))
        gears = self.couplings() + sorted(elements, key=lambda g: self.lines.get(g.path, 0))   # document order
        bad_pairs = bool(self.col.issues)   # go on to list the transmissions' problems too, with
        if bad_pairs:                       # no joint following another and no direct drive made up
            self.leader = {}
        joints = self.absorb_offsets(joints)
        motors = self.motors(ext, bool(ext["gears"]) or bad_pairs)
        loads = self.extension_loads(ext["loads"])
        payloads = self.extension_loads(ext["payloads"], payloads=True)
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
            open_loop=open_loop, warnings=tuple(self.warnings), loads=loads, payloads=payloads,
        )

    # -- values (yourdfpy) ----------------------------------------------------------------------
    def parse_values(self) -> None:
        try:
            urdf = load_yourdfpy(self.root)
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
            el = self.joint_el[name]
            if yj.type == "fixed":
                for sub in el.iterfind(f"{{{NS}}}friction"):
                    self.add(f"joint '{name}'", "gearcli:friction on a fixed joint (its links are merged into one "
                             "body: nothing turns there)", sub)
                continue
            path = f"joint '{name}'"
            parent, Tp = self.body_of[yj.parent]
            T = Tp @ _transform(yj.origin)
            axis = np.asarray(yj.axis, float)
            axis = axis / np.linalg.norm(axis)
            A = align_z(axis)
            label, friction = self.joint_extensions(el, path, JOINT_TYPES[yj.type] == "prismatic")
            source = {"origin": {"xyz": T[:3, 3].tolist(), "rpy": matrix_rpy(T[:3, :3]).tolist()},
                      "axis": axis.tolist(), "urdf_type": yj.type}
            lim, bounds = yj.limit, None
            stand_in = placeholders(el.find("limit"))
            if lim is not None and None not in (lim.lower, lim.upper, lim.effort, lim.velocity) and not stand_in:
                source["limit"] = {"lower": lim.lower, "upper": lim.upper, "effort": lim.effort,
                                   "velocity": lim.velocity}
            if (lim is not None and yj.type in ("revolute", "prismatic") and None not in (lim.lower, lim.upper)
                    and "lower" not in stand_in and float(lim.lower) < float(lim.upper)):
                bounds = (float(lim.lower), float(lim.upper))
            d = yj.dynamics
            if d is not None and any(_floats(x, 1) is not None and _floats(x, 1)[0] != 0
                                     for x in (d.damping, d.friction) if x is not None):
                dyn.append(name)
            joints.append(Joint(name, parent, yj.child, T[:3, :3] @ A, T[:3, 3].copy(), A.T, np.zeros(3),
                                JOINT_TYPES[yj.type], label, source, path, friction=friction,
                                position_limits=bounds))
        if dyn:
            more = f" and {len(dyn) - 4} more" if len(dyn) > 5 else ""
            self.warn("", f"<dynamics> damping and friction of {plural(len(dyn), 'joint')} {', '.join(dyn[:4] if more else dyn)}{more} are ignored "
                      "(gearcli reads joint friction from <gearcli:friction coulomb viscous/> only)")
        if not joints:
            self.add("", "the robot has no movable joints: nothing to analyse", self.root)
        self.movable = {j.name: j for j in joints}
        return joints

    def joint_extensions(self, el, path: str, prismatic: bool):
        """The (label, friction) of a movable joint's gearcli elements: gearcli:joint and one
        gearcli:friction; gearcli:bearing is read by io.ratings_reader, gearcli:gear by the gears."""
        label = friction = None
        for sub in el:
            if not isinstance(sub.tag, str) or etree.QName(sub).namespace != NS:
                continue
            local = etree.QName(sub).localname
            if local == "joint":
                label = sub.get("label")
                self.unknown_attrs(sub, ("label",), path)
            elif local == "bearing":
                continue  # read by io.ratings_reader
            elif local == "friction" and friction is not None:
                self.add(path, "a second gearcli:friction element: give a joint's coulomb and viscous "
                         "friction in one", sub)
            elif local == "friction":
                friction = self.joint_friction(sub, path, prismatic)
            elif local != "gear":
                self.add(path, f"unknown element gearcli:{local} in a joint (expected gearcli:joint, "
                         "gearcli:friction or gearcli:gear)", sub)
            elif el.find("mimic") is None:
                self.add(path, "gearcli:gear inside a joint gives the geometry of its <mimic> "
                         "coupling, but the joint has no <mimic>", sub)
        return label, friction

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


__all__ = ["NS", "load_urdf", "parse_urdf", "q"]

