"""URDF ``<mimic>`` couplings -> gear pairs (``joints=(B, A)``), their cycles and offsets.
A mixin of the reader in :mod:`gearcli.io.urdf_reader`."""
from __future__ import annotations

from dataclasses import replace

from ..model.mechanism import GearPair, Joint
from ..spatial import rot_z
from .urdf_xml import q

MIMIC_GEAR_ATTRS = ("name", "kind", "teeth", "carrier", "mesh_point", "pressure_angle",
                    "pressure_angle_deg", "cone_angles", "cone_angles_deg", "stiffness")


class Mimics:
    """Mimic couplings; needs the reader's ``joint_order``, ``joint_el``, ``movable``,
    ``yjoints``, ``lines``, ``add`` and ``gear_geometry``."""

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
            self.check_gear_pair(gear, f"joint '{b}'.gearcli:gear", jb.child, ja.child, kw, m)
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


    def chain_leader(self, name: str) -> str:
        while name in self.leader:
            name = self.leader[name][0]
        return name

