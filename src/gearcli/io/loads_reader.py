"""External loads (``loads:`` in YAML, ``<gearcli:load/>`` in URDF) -> :class:`~gearcli.model.loads.Load`."""
from __future__ import annotations

import numpy as np

from ..errors import Collector
from ..model.loads import LOAD_FRAMES, Load
from ..model.validate import check_inertia, inertia_matrix


def load_link_problem(link: str, links: set, base: str) -> str | None:
    """Why ``link`` cannot carry an external load (None when it can)."""
    if link not in links:
        return f"load on unknown link '{link}'"
    if link == base:
        return f"load on the base link '{link}': the base is fixed, the load would change no computed load"
    return None


def yaml_loads(data: dict, col: Collector, links: set, base: str) -> tuple[Load, ...]:
    """The ``loads:`` list of a schema-valid mechanism mapping (problems go to ``col``)."""
    out: list[Load] = []
    seen: dict[str, str] = {}
    for i, spec in enumerate(data.get("loads", [])):
        path = f"loads[{i}]"
        name = spec["name"]
        if name in seen:
            col.add(f"{path}.name", f"duplicate load name '{name}' (first at {seen[name]})")
        seen[name] = path
        why = load_link_problem(spec["link"], links, base)
        if why:
            col.add(f"{path}.link", why)
        mass, inertia = payload(spec.get("mass", 0.0), spec.get("inertia"), path, col.add)
        out.append(Load(name, spec["link"], spec["frame"],
                        *(np.asarray(spec.get(k, [0.0, 0.0, 0.0]), float) for k in ("point", "force", "moment")),
                        path=path, mass=mass, inertia=inertia))
    return tuple(out)


def yaml_payloads(data: dict, col: Collector, links: set, base: str, loads) -> tuple[Load, ...]:
    """The ``payloads:`` list of a schema-valid mechanism mapping as loads with a mass, no
    wrench, at their centre of mass (problems go to ``col``; names unique among the loads
    too: a payload attached becomes one)."""
    out: list[Load] = []
    seen: dict[str, str] = {ld.name: ld.path for ld in loads}
    for i, spec in enumerate(data.get("payloads", [])):
        path = f"payloads[{i}]"
        name = spec["name"]
        if name in seen:
            col.add(f"{path}.name", f"duplicate name '{name}' (first at {seen[name]})")
        seen[name] = path
        why = load_link_problem(spec["link"], links, base)
        if why:
            col.add(f"{path}.link", why.replace("load on", "payload on", 1).replace("the load would", "it would"))
        mass, inertia = payload(spec["mass"], spec.get("inertia"), path, col.add)
        out.append(Load(name, spec["link"], "link", np.asarray(spec.get("com", [0.0, 0.0, 0.0]), float),
                        path=path, mass=mass, inertia=inertia))
    return tuple(out)


def payload(mass, inertia, path: str, add) -> tuple[float, np.ndarray]:
    """A payload's mass (kg) and inertia (3, 3) about its point (kg*m^2), checked: mass not
    negative, inertia a physical tensor (positive semi-definite, triangle inequality), and
    no inertia without mass."""
    mass = float(mass)
    I = np.zeros((3, 3)) if inertia is None else (inertia if isinstance(inertia, np.ndarray) else inertia_matrix(inertia))
    if not mass >= 0:
        add(f"{path}.mass", f"payload mass must not be negative, got {mass:g} kg")
    elif np.any(I) and not mass > 0:
        add(f"{path}.inertia", "a payload inertia needs a positive mass")
    elif np.any(I):
        why = check_inertia(I, mass)
        if why:
            add(f"{path}.inertia", f"payload {why}")
    return mass, I


LOAD_ATTRS = ("name", "link", "frame", "point", "force", "moment", "mass", "inertia")
PAYLOAD_ATTRS = ("name", "link", "mass", "com", "inertia")


class UrdfLoads:
    """``<gearcli:load name= link= frame= point= force= moment= [mass= inertia=]/>`` elements
    (a payload's inertia "ixx iyy izz ixy ixz iyz" about the point, URDF link axes); a mixin of the
    URDF reader (needs ``add``, ``lines``, ``vector``, ``unknown_attrs``, ``body_of``, ``base``).

    The point (and, with ``frame="link"``, the force and moment) are given in the URDF
    link's frame and re-expressed in the frame of the body the link belongs to (fixed joints
    merged)."""

    def extension_loads(self, elements, payloads: bool = False) -> tuple[Load, ...]:
        """The loads of ``gearcli:load`` elements, or with ``payloads`` the payloads that are
        picked and placed of ``gearcli:payload`` elements (name, link, mass, com, inertia:
        the centre of mass and the inertia about it, URDF link frame and axes)."""
        out: list[Load] = []
        seen: dict[str, int] = {}
        kind, attrs = ("payload", PAYLOAD_ATTRS) if payloads else ("load", LOAD_ATTRS)
        for el in elements:
            name = el.get("name")
            path = f"gearcli:{kind} '{name}'"
            self.lines[path] = el.sourceline
            self.unknown_attrs(el, attrs, path)
            if not name or not el.get("link") or not (payloads or el.get("frame")):
                self.add(path, f"gearcli:{kind} needs attributes name, link and "
                         + ("mass" if payloads else "frame"), el)
                continue
            if name in seen:
                self.add(path, f"duplicate {kind} name '{name}' (first at line {seen[name]})", el)
            seen[name] = el.sourceline
            frame = "link" if payloads else el.get("frame")
            if frame not in LOAD_FRAMES:
                self.add(path, f"unknown load frame '{frame}' (expected {' or '.join(LOAD_FRAMES)})", el)
            link = el.get("link")
            ref = self.body_of.get(link)
            why = load_link_problem(link, set(self.body_of), None) or (
                load_link_problem(ref[0], {ref[0]}, self.base) if ref is not None else None)
            if why:
                self.add(path, why if ref is None or ref[0] == link else
                         f"{why} (link '{link}' is fixed to it)", el)
                continue
            body = ref[0]
            vals = [self.vector(el, k, path, default=np.zeros(3))
                    for k in (("com" if payloads else "point"), "force", "moment")]
            T = ref[1]
            R, p = T[:3, :3], T[:3, 3]
            point = R @ vals[0] + p
            force, moment = (R @ vals[1], R @ vals[2]) if frame == "link" else (vals[1], vals[2])
            mass = self.vector(el, "mass", path, n=1, default=np.zeros(1))[0]
            i6 = self.vector(el, "inertia", path, n=6, default=np.zeros(6))
            I = np.array([[i6[0], i6[3], i6[4]], [i6[3], i6[1], i6[5]], [i6[4], i6[5], i6[2]]])
            mass, I = payload(mass, R @ I @ R.T, path, lambda p, msg: self.add(p, msg, el))
            out.append(Load(name, body, frame, point, force, moment, path, mass=mass, inertia=I))
        return tuple(out)
