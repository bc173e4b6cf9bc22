"""External loads (``loads:`` in YAML, ``<gearcli:load/>`` in URDF) -> :class:`~gearcli.model.loads.Load`."""
from __future__ import annotations

import numpy as np

from ..errors import Collector
from ..model.loads import LOAD_FRAMES, Load


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
        out.append(Load(name, spec["link"], spec["frame"],
                        *(np.asarray(spec.get(k, [0.0, 0.0, 0.0]), float) for k in ("point", "force", "moment")),
                        path=path))
    return tuple(out)


LOAD_ATTRS = ("name", "link", "frame", "point", "force", "moment")


class UrdfLoads:
    """``<gearcli:load name= link= frame= point= force= moment=/>`` elements; a mixin of the
    URDF reader (needs ``add``, ``lines``, ``vector``, ``unknown_attrs``, ``body_of``, ``base``).

    The point (and, with ``frame="link"``, the force and moment) are given in the URDF
    link's frame and re-expressed in the frame of the body the link belongs to (fixed joints
    merged)."""

    def extension_loads(self, elements) -> tuple[Load, ...]:
        out: list[Load] = []
        seen: dict[str, int] = {}
        for el in elements:
            name = el.get("name")
            path = f"gearcli:load '{name}'"
            self.lines[path] = el.sourceline
            self.unknown_attrs(el, LOAD_ATTRS, path)
            if not name or not el.get("link") or not el.get("frame"):
                self.add(path, "gearcli:load needs attributes name, link and frame", el)
                continue
            if name in seen:
                self.add(path, f"duplicate load name '{name}' (first at line {seen[name]})", el)
            seen[name] = el.sourceline
            frame = el.get("frame")
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
            vals = [self.vector(el, k, path, default=np.zeros(3)) for k in ("point", "force", "moment")]
            T = ref[1]
            R, p = T[:3, :3], T[:3, 3]
            point = R @ vals[0] + p
            force, moment = (R @ vals[1], R @ vals[2]) if frame == "link" else (vals[1], vals[2])
            out.append(Load(name, body, frame, point, force, moment, path))
        return tuple(out)
