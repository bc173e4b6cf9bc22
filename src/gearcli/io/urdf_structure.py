"""URDF structure checks (lxml, before any value is used): names, references, joint
types, numbers and the tree of <link>/<joint> elements.  A mixin of the reader in
:mod:`gearcli.io.urdf_reader`."""
from __future__ import annotations

import numpy as np

from .urdf_xml import floats as _floats
from .urdf_xml import placeholders, range_problem

JOINT_TYPES = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic"}
INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


class StructureChecks:
    """Checks of the raw elements; needs ``root``, ``lines``, ``add``, ``vector``, ``col``."""

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
        limit = el.find("limit")
        if limit is not None:
            stand_in = placeholders(limit)
            for attr in ("lower", "upper"):
                if attr not in stand_in:
                    self.vector(limit, attr, f"{path}.limit", n=1)

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
            shown = ", ".join(roots[:5]) + (f" and {len(roots) - 5} more" if len(roots) > 5 else "")
            self.add("", f"several root links ({shown}): a URDF must be one tree hanging from "
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
                why = range_problem(mass.get("value")) or "is not a finite number"
                self.add(f"{path}.inertial", f"mass \"{mass.get('value')}\" {why}", mass)
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
                why = range_problem(inertia.get(k)) or "is not a finite number"
                self.add(f"{path}.inertial", f"{k}=\"{inertia.get(k)}\" {why}", inertia)

