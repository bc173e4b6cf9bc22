"""Mechanisms generated together with the tests' own description of them (:mod:`oracles`).

Each factory returns the mechanism text (YAML or URDF) and an :class:`oracles.OwnMech`
built from the same parameters by the test's own transforms, never from what gearcli read.

* :data:`PUMA_YAML` -- a literal D-H table with twists of +-90 deg and theta offsets.
* :func:`dh_geared` -- a random three-dof D-H arm with non-zero twists alpha and offsets
  theta, a base pinion (even seeds) or ring gear (odd seeds: internal pair whose gear j is
  the ring) driving link 1 (carrier 0) and a pinion carried
  by link 1 driving link 2 (carrier 1), the third joint driven directly; full inertia
  tensors, off-axis centres of mass, an arbitrary gravity direction.
* :func:`urdf_prismatic_chain` -- a URDF revolute / prismatic / revolute chain on skewed
  axes: the prismatic joint slides on a turning link (Coriolis acceleration).
* :func:`spatial_own` -- the description of :func:`factories.spatial_3dof` (J5 on the base).
"""
from __future__ import annotations

import numpy as np

from factories import dump, fl, inertia_spec, random_inertia, rolling_ratio, rpy_matrix, spatial_3dof, unit
from oracles import OwnJoint, OwnLink, OwnMech, frame_with_z, homog

PUMA_DH = [  # theta offset, d, a, alpha (rad); file order J1, J2, J3
    (0.0, 0.0, 0.0, np.pi / 2), (-np.pi / 2, 0.0, 0.4318, 0.0), (np.pi / 2, 0.15005, 0.0203, -np.pi / 2)]
PUMA_LINKS = [(17.4, [0.0, -0.0312, 0.0], [0.35, 0.30, 0.25]), (4.8, [-0.216, 0.0062, 0.1], [0.13, 0.524, 0.539]),
              (0.82, [0.0, 0.014, -0.07], [0.066, 0.03, 0.086])]

PUMA_YAML = """\
name: puma_like
gravity: [0, 0, -9.81]
base: "0"
end_effector: "3"
links:
  - {name: "0"}
  - {name: "1", mass: 17.4, com: [0, -0.0312, 0], inertia: [0.35, 0.30, 0.25]}
  - {name: "2", mass: 4.8, com: [-0.216, 0.0062, 0.1], inertia: [0.13, 0.524, 0.539]}
  - {name: "3", mass: 0.82, com: [0, 0.014, -0.07], inertia: [0.066, 0.03, 0.086]}
joints:
  - {name: J1, parent: "0", child: "1", dh: {theta_deg: 0, d: 0.0, a: 0.0, alpha_deg: 90}}
  - {name: J2, parent: "1", child: "2", dh: {theta_deg: -90, d: 0.0, a: 0.4318, alpha_deg: 0}}
  - {name: J3, parent: "2", child: "3", dh: {theta: 1.5707963267948966, d: 0.15005, a: 0.0203, alpha: -1.5707963267948966}}
motors:
  - {name: m1, link: "1"}
  - {name: m2, link: "2"}
  - {name: m3, link: "3"}
"""


def puma_own() -> OwnMech:
    joints = [OwnJoint(f"J{i + 1}", str(i), str(i + 1), dh=row) for i, row in enumerate(PUMA_DH)]
    links = {str(i + 1): OwnLink(str(i + 1), m, np.array(c), np.diag(I)) for i, (m, c, I) in enumerate(PUMA_LINKS)}
    motors = {f"m{i + 1}": (f"J{i + 1}", np.eye(3)[i]) for i in range(3)}
    return OwnMech("0", links, joints, np.eye(3), np.array([0.0, 0.0, -9.81]), motors)


def _random_links(rng, names, com_scale=0.06):
    links, specs = {}, []
    for name in names:
        mass = rng.uniform(0.2, 3.0)
        com = rng.normal(scale=com_scale, size=3)
        I = random_inertia(rng, mass, 0.02, 0.2)
        links[name] = OwnLink(name, mass, com, I)
        specs.append({"name": name, "mass": float(mass), "com": fl(com), "inertia": inertia_spec(I)})
    return links, specs


def dh_geared(seed: int) -> tuple[str, OwnMech]:
    """YAML text and own description of the geared D-H arm (see the module docstring)."""
    rng = np.random.default_rng(seed)
    u = rng.uniform
    sgn = rng.choice([-1.0, 1.0], size=3)
    rows = [tuple(float(x) for x in (u(-np.pi, np.pi), u(-0.2, 0.2), u(0.15, 0.5), sgn[i] * u(0.3, 2.8))) for i in range(3)]
    links, link_specs = _random_links(rng, ["1", "2", "3", "4", "5"])
    ez = np.array([0.0, 0, 1])
    # gear 4 on the base, axis parallel to J1's (z0), meshing with link 1's gear of radius r1:
    # a pinion (external pair) for even seeds, a ring around link 1's gear (internal pair,
    # the ring is gear j) for odd seeds
    ring = seed % 2 == 1
    r1, r4, phi, h4, yaw4 = u(0.06, 0.12), u(0.015, 0.04), u(-np.pi, np.pi), u(-0.1, 0.1), u(-np.pi, np.pi)
    if ring:
        r4 = u(0.15, 0.25)
    dir4 = np.array([np.cos(phi), np.sin(phi), 0.0])
    o4, P41 = (r1 + (-r4 if ring else r4)) * dir4 + h4 * ez, r1 * dir4 + h4 * ez
    e41 = rolling_ratio(P41, o4, ez, np.zeros(3), ez)
    # pinion 5 carried by link 1, axis parallel to J2's (z1), meshing with link 2's gear of radius r2
    r2, r5, beta, h5 = u(0.05, 0.1), u(0.015, 0.03), u(-np.pi, np.pi), u(-0.1, 0.1)
    dir5 = np.array([np.cos(beta), np.sin(beta), 0.0])
    o5, P52 = (r2 + r5) * dir5 + h5 * ez, r2 * dir5 + h5 * ez
    e52 = rolling_ratio(P52, o5, ez, np.zeros(3), ez)
    deg = [True, False, True]                 # both spellings of the angles
    jspecs = []
    for i, (th, d, a, al) in enumerate(rows):
        spec = {"theta_deg": float(np.degrees(th)), "d": d, "a": a, "alpha_deg": float(np.degrees(al))} if deg[i] \
            else {"theta": th, "d": d, "a": a, "alpha": al}
        jspecs.append({"name": f"J{i + 1}", "parent": str(i), "child": str(i + 1), "dh": spec})
    jspecs.append({"name": "J4", "parent": "0", "child": "4", "origin": {"xyz": fl(o4), "rpy": [0.0, 0.0, float(yaw4)]}})
    jspecs.append({"name": "J5", "parent": "1", "child": "5", "origin": {"xyz": fl(o5)}, "axis": [0, 0, 1]})
    pa = [float(u(14.5, 25.0)), float(u(14.5, 25.0))]
    gravity = 9.81 * unit(rng.normal(size=3))
    doc = {"name": f"dh_geared_{seed}", "gravity": fl(gravity), "base": "0", "end_effector": "3",
           "links": [{"name": "0"}] + link_specs, "joints": jspecs,
           "gears": [{"name": "4-1", "links": ["4", "1"], "kind": "internal" if ring else "external", "ratio": e41,
                      "mesh_point": fl(P41), "pressure_angle_deg": pa[0]},
                     {"name": "5-2", "links": ["5", "2"], "kind": "external", "ratio": e52,
                      "mesh_point": fl(P52), "pressure_angle_deg": pa[1]}],
           "motors": [{"name": "motor4", "link": "4"}, {"name": "motor5", "link": "5"},
                      {"name": "motor3", "link": "3", "stator": "2"}]}
    joints = [OwnJoint(f"J{i + 1}", str(i), str(i + 1), dh=row) for i, row in enumerate(rows)]
    joints += [OwnJoint("J4", "0", "4", X_pj=homog(rpy_matrix([0, 0, yaw4]), o4)),
               OwnJoint("J5", "1", "5", X_pj=homog(None, o5))]
    S = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [e41, 0, 0], [0, e52, 0]], float)
    motors = {"motor4": ("J4", S[3]), "motor5": ("J5", S[4]), "motor3": ("J3", S[2])}
    # us_j: the separating force on j points along us_j * (j's outward radial direction):
    # outwards for a ring, towards its own axis otherwise
    gears = {"4-1": dict(j="4", k="1", carrier="0", P=P41, oj=o4, zj=ez, ok=np.zeros(3), zk=ez, phi_deg=pa[0],
                         us_j=1.0 if ring else -1.0),
             "5-2": dict(j="5", k="2", carrier="1", P=P52, oj=o5, zj=ez, ok=np.zeros(3), zk=ez, phi_deg=pa[1],
                         us_j=-1.0)}
    return dump(doc), OwnMech("0", links, joints, S, gravity, motors, gears)


def _urdf_inertial(link: OwnLink, rpy) -> str:
    Ii = rpy_matrix(rpy).T @ link.inertia @ rpy_matrix(rpy)   # the tensor in the inertial origin's axes
    return (f'<inertial><origin xyz="{" ".join(map(repr, fl(link.com)))}" rpy="{" ".join(map(repr, fl(rpy)))}"/>'
            f'<mass value="{float(link.mass)!r}"/><inertia ixx="{float(Ii[0, 0])!r}" iyy="{float(Ii[1, 1])!r}" izz="{float(Ii[2, 2])!r}" '
            f'ixy="{float(Ii[0, 1])!r}" ixz="{float(Ii[0, 2])!r}" iyz="{float(Ii[1, 2])!r}"/></inertial>')


def urdf_prismatic_chain(seed: int) -> tuple[str, OwnMech]:
    """URDF text and own description of base -J1 (revolute, axis z)- l1 -J2 (prismatic,
    skewed axis)- l2 -J3 (revolute, skewed axis)- l3, each joint driven directly."""
    rng = np.random.default_rng(seed)
    links, _ = _random_links(rng, ["l1", "l2", "l3"])
    parts = ['<robot name="prismatic_chain">', '<link name="base"/>']
    joints = []
    for name, parent, child, kind in (("J1", "base", "l1", "revolute"), ("J2", "l1", "l2", "prismatic"),
                                      ("J3", "l2", "l3", "revolute")):
        xyz, rpy = rng.normal(scale=0.2, size=3), rng.uniform(-np.pi, np.pi, 3)
        axis = np.array([0.0, 0.0, 1.0]) if name == "J1" else unit(rng.normal(size=3))
        A = frame_with_z(axis)
        joints.append(OwnJoint(name, parent, child, kind, X_pj=homog(rpy_matrix(rpy) @ A, xyz), X_jc=homog(A.T)))
        parts.append(f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
                     f'<origin xyz="{" ".join(map(repr, fl(xyz)))}" rpy="{" ".join(map(repr, fl(rpy)))}"/>'
                     f'<axis xyz="{" ".join(map(repr, fl(axis)))}"/>'
                     f'<limit lower="-10" upper="10" effort="100" velocity="10"/></joint>')
        parts.append(f'<link name="{child}">{_urdf_inertial(links[child], rng.uniform(-np.pi, np.pi, 3))}</link>')
    parts.append("</robot>")
    gravity = np.array([0.0, 0.0, -9.81])
    motors = {n: (n, np.eye(3)[i]) for i, n in enumerate(("J1", "J2", "J3"))}
    return "\n".join(parts), OwnMech("base", links, joints, np.eye(3), gravity, motors)


def spatial_own() -> tuple[str, OwnMech]:
    """:func:`factories.spatial_3dof` with J5 on the base, and its description from the
    factory's home poses and world axes: X_pj = T_p0^-1 (o_c0, frame_with_z(axis)),
    X_jc = (o_c0, frame_with_z(axis))^-1 T_c0."""
    text, info = spatial_3dof(j5_parent="0")
    W, axes, parents = info["home"], info["axes"], info["parents"]
    T0 = {k: homog(R, o) for k, (R, o) in W.items()}
    joints = []
    for name, child in (("J1", "1"), ("J2", "2"), ("J3", "3"), ("J4", "4"), ("J5", "5"), ("J6", "6")):
        Tj = homog(frame_with_z(axes[child]), W[child][1])
        joints.append(OwnJoint(name, parents[child], child, X_pj=np.linalg.inv(T0[parents[child]]) @ Tj,
                               X_jc=np.linalg.inv(Tj) @ T0[child]))
    links = {s["name"]: OwnLink(s["name"], s["mass"], np.array(s["com"]), _tensor(s["inertia"]))
             for s in info["links"] if s["name"] != "0"}
    e = info["ratios"]
    # J4 = e41 q1; J6 = e62 q2; J5 - J1 = e56 J6 (J5 and J1 on the same axis, same direction)
    S = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [e["4-1"], 0, 0], [1, e["5-6"] * e["6-2"], 0],
                  [0, e["6-2"], 0]], float)
    motors = {"motor4": ("J4", S[3]), "motor5": ("J5", S[4]), "motor3": ("J3", S[2])}
    gears = {}
    for name, gh in info["gears_home"].items():   # world at home -> carrier frame
        Rc, oc = W[gh["carrier"]]
        gm = dict(gh)
        for key in ("P", "oj", "ok", "apex"):
            gm[key] = None if gh[key] is None else Rc.T @ (gh[key] - oc)
        gm["zj"], gm["zk"] = Rc.T @ gh["zj"], Rc.T @ gh["zk"]
        gears[name] = gm
    return text, OwnMech("0", links, _ordered(joints), S, info["gravity"], motors, gears)


def _tensor(spec) -> np.ndarray:
    return np.array([[spec["ixx"], spec["ixy"], spec["ixz"]], [spec["ixy"], spec["iyy"], spec["iyz"]],
                     [spec["ixz"], spec["iyz"], spec["izz"]]])


def _ordered(joints):
    assert all(j.parent != k.child for i, j in enumerate(joints) for k in joints[i:]), "parents first"
    return joints


