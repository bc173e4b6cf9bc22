"""Large generated mechanisms (YAML text) for scaling tests and benchmarks.

Plain Python string building, no gearcli: a serial chain of n revolute joints, a binary
tree of revolute joints (URDF), and a geared chain (each link driven by a spur pinion carried by
its parent link).
"""
from __future__ import annotations


def _link(name: str) -> str:
    return f"  - {{name: '{name}', mass: 1.0, com: [0.1, 0, 0], inertia: [0.001, 0.01, 0.01]}}\n"


def serial_chain(n: int) -> str:
    """YAML text of a spatial serial chain of ``n`` revolute D-H joints, one motor each."""
    out = [f"name: chain{n}\nbase: L0\nend_effector: L{n}\nlinks:\n  - {{name: L0}}\n"]
    out += [_link(f"L{i}") for i in range(1, n + 1)]
    out.append("joints:\n")
    for i in range(1, n + 1):
        alpha = 90 if i % 2 else -90
        out.append(f"  - {{name: J{i}, parent: L{i - 1}, child: L{i}, "
                   f"dh: {{d: 0.05, a: 0.2, alpha_deg: {alpha}}}}}\n")
    out.append("motors:\n")
    out += [f"  - {{name: M{i}, link: L{i}}}\n" for i in range(1, n + 1)]
    return "".join(out)


def geared_chain(n: int) -> str:
    """YAML text of a planar chain of ``n`` links, link i driven by pinion Pi (on link i-1,
    axis parallel to joint i, 0.06 m from it) through an external spur pair (radii 0.04 and
    0.02 m, ratio -2); one motor per pinion."""
    out = [f"name: geared{n}\nbase: L0\nend_effector: L{n}\nlinks:\n  - {{name: L0}}\n"]
    for i in range(1, n + 1):
        out.append(_link(f"L{i}"))
        out.append(f"  - {{name: P{i}, mass: 0.1, inertia: [0.0001, 0.0001, 0.0001]}}\n")
    out.append("joints:\n")
    for i in range(1, n + 1):
        out.append(f"  - {{name: J{i}, parent: L{i - 1}, child: L{i}, dh: {{a: 0.3}}}}\n")
        out.append(f"  - {{name: K{i}, parent: L{i - 1}, child: P{i}, origin: {{xyz: [0.06, 0, 0.01]}}}}\n")
    out.append("gears:\n")
    for i in range(1, n + 1):
        out.append(f"  - {{name: G{i}, links: [P{i}, L{i}], kind: external, ratio: -2.0, "
                   f"mesh_point: [0.04, 0, 0.01]}}\n")
    out.append("motors:\n")
    out += [f"  - {{name: M{i}, link: P{i}}}\n" for i in range(1, n + 1)]
    return "".join(out)


def binary_tree_urdf(depth: int) -> str:
    """URDF text of a binary tree of revolute joints, 2**(depth+1) - 2 joints (each a
    direct-drive motor), every link with a small inertia."""
    out = ['<robot name="tree">\n', '  <link name="n"/>\n']
    names = ["n"]
    level = ["n"]
    for _ in range(depth):
        nxt = []
        for p in level:
            for side, y in (("a", 0.1), ("b", -0.1)):
                c = p + side
                out.append(f'  <link name="{c}"><inertial><mass value="1"/>'
                           f'<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'
                           f'</inertial></link>\n')
                out.append(f'  <joint name="j_{c}" type="revolute"><parent link="{p}"/><child link="{c}"/>'
                           f'<origin xyz="0.2 {y} 0" rpy="0 0 0"/><axis xyz="0 {1 if side == "a" else 0} '
                           f'{0 if side == "a" else 1}"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                           f'</joint>\n')
                nxt.append(c)
                names.append(c)
        level = nxt
    out.append("</robot>\n")
    return "".join(out)
