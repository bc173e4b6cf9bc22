"""Random but valid geared mechanisms, generated as YAML text.

Nothing here uses gearcli: geometry, gear ratios and rotations are built with plain numpy
so that the tests compare gearcli with an independent construction.

* :func:`paper_2dof_variant` -- the two-dof manipulator of the paper's Fig. 1 (the layout
  of ``mechanisms/paper_2dof.yaml``) with random masses, lengths, centre-of-mass offsets,
  gear radii and inertias, plus the parameters of the paper's closed form (Eqs. 25-27).
* :func:`spatial_3dof` -- a three-dof spatial mechanism with skewed, non-parallel axes:
  an internal (ring) pair, a bevel pair, a compound secondary gear (bevel + spur), a
  coaxial input shaft borne by the link it drives (re-attached to the base by the
  canonical graph), a direct-drive end link, full inertia tensors, off-axis centres of
  mass and an arbitrary gravity direction.

Rolling at the pitch point P fixes every gear ratio (theta_{j,c} = e * theta_{k,c}, each
angle about its own joint's positive axis):  thd_j z_j x (P - o_j) = thd_k z_k x (P - o_k).
"""
from __future__ import annotations

import numpy as np
import yaml

# --- small independent geometry helpers ---------------------------------------------------


def unit(v) -> np.ndarray:
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def rolling_ratio(P, oj, zj, ok, zk) -> float:
    """e = theta_j / theta_k for gears rolling without slip at P (axes through o, along z)."""
    vj = np.cross(zj, np.asarray(P) - oj)   # pitch-point velocity of j per unit rate
    vk = np.cross(zk, np.asarray(P) - ok)
    assert np.linalg.norm(np.cross(vj, vk)) < 1e-12 * (vj @ vj), "pitch velocities not parallel"
    return float(vk @ vj / (vj @ vj))


def random_rotation(rng) -> np.ndarray:
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q @ np.diag(np.sign(np.diag(R)))
    if np.linalg.det(Q) < 0:
        Q[:, 0] = -Q[:, 0]
    return Q


def rpy_of(R) -> list[float]:
    """Roll, pitch, yaw with R = Rz(yaw) Ry(pitch) Rx(roll) (URDF fixed axes)."""
    pitch = np.arctan2(-R[2, 0], np.hypot(R[0, 0], R[1, 0]))
    roll = np.arctan2(R[2, 1], R[2, 2])
    yaw = np.arctan2(R[1, 0], R[0, 0])
    return [float(roll), float(pitch), float(yaw)]


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rpy_matrix(rpy) -> np.ndarray:
    r, p, y = rpy
    return _rz(y) @ _ry(p) @ _rx(r)


def box_moments(rng, mass, lo=0.01, hi=0.12) -> np.ndarray:
    """Principal moments of a solid box with random sides (satisfy the triangle inequality)."""
    a, b, c = rng.uniform(lo, hi, size=3)
    return mass / 12.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])


def random_inertia(rng, mass, lo=0.01, hi=0.12) -> np.ndarray:
    """A full (non-diagonal) positive-definite inertia tensor about the centre of mass."""
    Q = random_rotation(rng)
    return Q @ np.diag(box_moments(rng, mass, lo, hi)) @ Q.T


def inertia_spec(I) -> dict:
    I = np.asarray(I, float)
    return {"ixx": float(I[0, 0]), "iyy": float(I[1, 1]), "izz": float(I[2, 2]),
            "ixy": float(I[0, 1]), "ixz": float(I[0, 2]), "iyz": float(I[1, 2])}


def fl(v) -> list[float]:
    return [float(x) for x in np.asarray(v, float).ravel()]


def dump(doc: dict) -> str:
    return yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=1000)


# --- (a) the paper's two-dof manipulator, parametrically ------------------------------------


def paper_2dof_variant(rng, gravity=None) -> tuple[str, dict]:
    """YAML text of a random variant of the paper's Fig. 1 manipulator and its parameters.

    Layout (as mechanisms/paper_2dof.yaml): D-H joints J1 (base -> 1, a = a1) and J2
    (1 -> 2, a = a2); shaft 3 coaxial with J1 (d = -d3); shaft 4 carried by link 1 along x1
    at height h with its centre of mass at x = -s4 in link 1's frame; pinion 5 on the base at
    distance r1g + r5 from the shoulder axis (angle phi), meshing externally with link 1's
    gear of pitch radius r1g.  Bevel pairs 3-4 (apex (-a1, 0, h)) and 4-2 (apex (0, 0, h)) in
    link 1's frame, mesh points on random sides of the axes.  Centres of mass of 3, 4, 5 on
    their axes; shaft 4 axisymmetric about its axis x.

    Returned parameters use the paper's symbols; ``e15``, ``e43``, ``e24`` are from the
    rolling condition (theta_5 = e15 theta_1, theta_31 = e43 theta_41, theta_41 = e24 theta_21).
    """
    u = rng.uniform
    a1, a2 = u(0.25, 0.6), u(0.2, 0.5)
    s1, s2 = u(0.05, 0.9) * a1, u(0.05, 0.9) * a2
    s4 = u(0.1, 0.9) * a1
    c4 = u(-0.05, 0.05)                       # 4's centre of mass along its own axis
    h = u(0.03, 0.08)
    d3, d5 = u(0.05, 0.15), u(0.02, 0.1)
    r1g, r5 = u(0.05, 0.12), u(0.015, 0.04)
    r3, r43, r42, r2 = u(0.02, 0.05), u(0.02, 0.05), u(0.01, 0.04), u(0.02, 0.06)
    sg = rng.choice([-1.0, 1.0], size=4)
    phi = u(-np.pi, np.pi)
    m = {i: u(1.0, 5.0) if i in (1, 2) else u(0.1, 0.8) for i in range(1, 6)}
    I1 = box_moments(rng, m[1], 0.02, 0.5)
    I2 = box_moments(rng, m[2], 0.02, 0.4)
    I3 = box_moments(rng, m[3], 0.01, 0.06)
    I5 = box_moments(rng, m[5], 0.01, 0.05)
    rad4 = u(0.005, 0.02)                     # shaft 4: a cylinder along x
    len4 = u(0.1, 0.4)
    I4 = np.array([0.5 * m[4] * rad4 ** 2] + [m[4] * (3 * rad4 ** 2 + len4 ** 2) / 12] * 2)
    g = [0.0, 0.0, -9.81] if gravity is None else fl(gravity)

    # geometry of the gears (carrier frames)
    dir5 = np.array([np.cos(phi), np.sin(phi), 0.0])
    o5 = (r1g + r5) * dir5 + np.array([0, 0, -d5])
    P51 = r1g * dir5 + np.array([0, 0, -d5])
    ez, ex = np.array([0.0, 0, 1]), np.array([1.0, 0, 0])
    e15 = rolling_ratio(P51, o5, ez, np.zeros(3), ez)                    # carrier 0
    o3_1, o4_1, o2_1 = np.array([-a1, 0, 0]), np.array([-s4 - c4, 0, h]), np.zeros(3)
    P34 = np.array([-a1 + sg[0] * r3, 0, h + sg[1] * r43])               # carrier 1
    P42 = np.array([sg[2] * r2, 0, h + sg[3] * r42])
    e43 = rolling_ratio(P34, o3_1, ez, o4_1, ex)
    e24 = rolling_ratio(P42, o4_1, ex, o2_1, ez)

    doc = {
        "name": "paper_2dof_variant",
        "gravity": g,
        "base": "0",
        "end_effector": "2",
        "links": [
            {"name": "0"},
            {"name": "1", "mass": m[1], "com": [-s1, 0.0, 0.0], "inertia": fl(I1)},
            {"name": "2", "mass": m[2], "com": [-s2, 0.0, 0.0], "inertia": fl(I2)},
            {"name": "3", "mass": m[3], "com": [0.0, 0.0, u(-0.05, 0.05)], "inertia": fl(I3)},
            {"name": "4", "mass": m[4], "com": [c4, 0.0, 0.0], "inertia": fl(I4)},
            {"name": "5", "mass": m[5], "com": [0.0, 0.0, u(-0.05, 0.05)],
             "inertia": {"ixx": float(I5[0]), "iyy": float(I5[1]), "izz": float(I5[2])}},
        ],
        "joints": [
            {"name": "J1", "parent": "0", "child": "1", "dh": {"theta_deg": 0, "d": 0.0, "a": a1, "alpha_deg": 0}},
            {"name": "J2", "parent": "1", "child": "2", "dh": {"theta_deg": 0, "d": 0.0, "a": a2, "alpha_deg": 0}},
            {"name": "J3", "parent": "0", "child": "3", "dh": {"d": -d3}},
            {"name": "J4", "parent": "1", "child": "4", "origin": {"xyz": fl(o4_1)}, "axis": [1, 0, 0]},
            {"name": "J5", "parent": "0", "child": "5", "origin": {"xyz": fl(o5)}, "axis": [0, 0, 1]},
        ],
        "gears": [
            {"name": "5-1", "links": ["5", "1"], "kind": "external", "ratio": e15,
             "mesh_point": fl(P51), "pressure_angle_deg": float(u(14.5, 25.0))},
            {"name": "3-4", "links": ["3", "4"], "kind": "bevel", "ratio": e43, "mesh_point": fl(P34)},
            {"name": "4-2", "links": ["4", "2"], "kind": "bevel", "ratio": e24, "mesh_point": fl(P42)},
        ],
        "motors": [{"name": "motor3", "link": "3"}, {"name": "motor5", "link": "5"}],
    }
    params = dict(a1=a1, a2=a2, s1=s1, s2=s2, s4=s4, m1=m[1], m2=m[2], m3=m[3], m4=m[4], m5=m[5],
                  Izz1=I1[2], Izz2=I2[2], Izz3=I3[2], Izz5=I5[2],
                  Iax4=I4[0],    # link 4 about its own shaft axis (x4): the paper's "Izz(4)" in M22
                  Ivert4=I4[1],  # link 4 about an axis parallel to z0: the paper's "Iyy(4)" in J40
                  e15=e15, e43=e43, e24=e24)
    return dump(doc), params


# Parameters of the bundled mechanisms/paper_2dof.yaml, read off by hand.  The ratios come
# from the rolling condition worked out by hand: pinion 5 (r = 0.03) and link 1's gear
# (r = 0.09) mesh externally, e15 = -3; at P34 = (-0.37, 0, 0.08) shaft 3 (+z0) moves its
# pitch point along +y1, shaft 4 (+x1, P 0.03 above its axis) along -y1: e43 = -1; at
# P42 = (-0.04, 0, 0.07) shaft 4 (r = 0.02) moves it along -y1, link 2 (r = 0.04) along -y1
# as well: e24 = +2.
PAPER_2DOF_PARAMS = dict(a1=0.4, a2=0.3, s1=0.2, s2=0.15, s4=0.2, m1=4.0, m2=2.5, m3=0.5, m4=0.3, m5=0.2,
                         Izz1=0.06, Izz2=0.025, Izz3=0.0002, Izz5=0.00003, Iax4=0.00002, Ivert4=0.004,
                         e15=-3.0, e43=-1.0, e24=2.0)


# --- (b) a spatial three-dof mechanism ------------------------------------------------------------


def _pose_spec(R_parent, o_parent, R_child, o_child, axis_world) -> dict:
    """origin/axis spec of a joint whose child frame at home is (R_child, o_child)."""
    return {"origin": {"xyz": fl(R_parent.T @ (o_child - o_parent)), "rpy": rpy_of(R_parent.T @ R_child)},
            "axis": fl(R_child.T @ axis_world)}


def spatial_3dof(seed: int = 20240607, j5_parent: str = "1") -> tuple[str, dict]:
    """YAML text of a three-dof spatial mechanism and a dict describing it.

    Links: 1, 2, 3 primary (3 the end effector, driven directly by motor3 with its stator
    on link 2); 4 a pinion on the base inside the ring gear of link 1 (internal pair 4-1,
    carrier 0; J4's axis points opposite to J1's); 5 an input shaft coaxial with J1, borne by
    ``j5_parent`` ("1": a real bearing inside link 1, re-attached to the base by the canonical
    graph; "0": on the base), motor5's stator on the base; 6 a compound gear carried by
    link 1 with a bevel gear meshing with 5 (bevel pair 5-6, carrier 1; axis of 6 crosses J1's
    axis) and a spur gear meshing externally with link 2 (pair 6-2, carrier 1; J2's axis
    antiparallel to 6's).  All link frames are skewed; centres of mass are off the axes.
    """
    rng = np.random.default_rng(seed)
    u = rng.uniform
    W = {"0": (np.eye(3), np.zeros(3))}       # home pose (R, o) of each link frame in the world

    a1 = unit([0.3, -0.2, 1.0] + rng.normal(scale=0.1, size=3))
    O1 = np.array([0.05, -0.03, 0.25])
    d2 = unit(np.cross(a1, [1.0, 0.4, 0.1]) + 0.6 * a1)     # neither parallel nor perpendicular to a1
    sin12 = np.linalg.norm(np.cross(a1, d2))
    d3 = unit(rng.normal(size=3))

    def perp(axis, v):
        v = np.asarray(v, float) - (np.asarray(v, float) @ axis) * axis
        return unit(v)

    # radii from module * teeth so that tooth counts can be given
    mod = 0.002
    z4, zring = 12, 45           # internal pair
    z5, z6b = 18, 27             # bevel pair 5-6
    r4, Rr = mod * z4, mod * zring
    r5, r6b = mod * z5, mod * z6b
    r6s, r2 = 0.021, 0.063       # spur pair 6-2 (ratio given explicitly)

    # link 1 on axis a1 through O1; link 5 coaxial (same direction)
    W["1"] = (random_rotation(rng), O1)
    W["5"] = (random_rotation(rng), O1 - 0.06 * a1)
    # pinion 4 inside link 1's ring gear, axis antiparallel to a1
    uu = perp(a1, rng.normal(size=3))
    o4 = O1 + (Rr - r4) * uu + 0.02 * a1
    W["4"] = (random_rotation(rng), o4)
    P41 = O1 + Rr * uu - 0.015 * a1           # on the line of centres, same side of both axes
    # compound gear 6: axis along d2 through the apex on a1
    apex = O1 + 0.08 * a1
    W["6"] = (random_rotation(rng), apex + 0.03 * d2)
    P56 = apex + (r6b * a1 - r5 * d2) / sin12  # distance r5 from a1 and r6b from 6's axis
    # link 2: J2 parallel to 6's axis (antiparallel direction), external spur mesh with 6
    ww = perp(d2, rng.normal(size=3))
    O2 = apex + (r6s + r2) * ww + 0.05 * d2
    W["2"] = (random_rotation(rng), O2)
    P62 = apex + r6s * ww + 0.045 * d2
    # link 3 on a skew axis d3 through a point off link 2's axis
    O3 = O2 + np.array([0.12, -0.05, 0.08])
    W["3"] = (random_rotation(rng), O3)

    axes = {"1": a1, "5": a1, "4": -a1, "6": d2, "2": -d2, "3": d3}
    parents = {"1": "0", "2": "1", "3": "2", "4": "0", "5": j5_parent, "6": "1"}
    joints = []
    for name, child in (("J1", "1"), ("J2", "2"), ("J3", "3"), ("J4", "4"), ("J5", "5"), ("J6", "6")):
        p = parents[child]
        spec = {"name": name, "parent": p, "child": child}
        spec.update(_pose_spec(*W[p], *W[child], axes[child]))
        joints.append(spec)

    def in_frame(link, P):
        R, o = W[link]
        return fl(R.T @ (P - o))

    e41 = rolling_ratio(P41, o4, -a1, O1, a1)                 # carrier 0 = world
    e56 = rolling_ratio(P56, W["5"][1], a1, W["6"][1], d2)    # carrier 1 (world at home)
    e62 = rolling_ratio(P62, W["6"][1], d2, O2, -d2)
    elem = unit(P56 - apex)
    cones = [float(np.degrees(np.arccos(abs(elem @ a1)))), float(np.degrees(np.arccos(abs(elem @ d2))))]
    gears = [
        {"name": "4-1", "links": ["4", "1"], "kind": "internal", "ratio": e41,
         "mesh_point": in_frame("0", P41), "pressure_angle_deg": 20.0},
        {"name": "5-6", "links": ["5", "6"], "kind": "bevel", "teeth": [z5, z6b],
         "mesh_point": in_frame("1", P56), "cone_angles_deg": cones, "pressure_angle_deg": 22.5},
        {"name": "6-2", "links": ["6", "2"], "kind": "external", "ratio": e62,
         "mesh_point": in_frame("1", P62), "pressure_angle_deg": 25.0},
    ]

    links = [{"name": "0"}]
    masses = {"1": 2.2, "2": 1.4, "3": 0.9, "4": 0.15, "5": 0.35, "6": 0.12}
    for name in ("1", "2", "3", "4", "5", "6"):
        mass = masses[name]
        com = rng.normal(scale=0.04, size=3)   # off every axis
        links.append({"name": name, "mass": mass, "com": fl(com),
                      "inertia": inertia_spec(random_inertia(rng, mass, 0.02, 0.25 if name in "123" else 0.06))})
    gravity = 9.81 * unit([0.25, -0.4, -1.0])
    doc = {
        "name": "spatial_3dof",
        "description": "skewed axes, ring pair, bevel pair, compound gear, coaxial borne shaft",
        "gravity": fl(gravity),
        "base": "0",
        "end_effector": "3",
        "links": links,
        "joints": joints,
        "gears": gears,
        "motors": [{"name": "motor4", "link": "4"}, {"name": "motor5", "link": "5"},
                   {"name": "motor3", "link": "3", "stator": "2"}],
    }
    info = dict(ratios={"4-1": e41, "5-6": e56, "6-2": e62}, ring=("4-1", 1), gravity=gravity,
                home=W, axes=axes, parents=parents, links=links,   # for the tests' own kinematics
                gears_home={   # world frame at home; us_j: separating force on j along +-(radial of j)
                    "4-1": dict(j="4", k="1", carrier="0", P=P41, oj=o4, zj=-a1, ok=O1, zk=a1, apex=None,
                                phi_deg=20.0, us_j=-1.0),
                    "5-6": dict(j="5", k="6", carrier="1", P=P56, oj=W["5"][1], zj=a1, ok=W["6"][1], zk=d2,
                                apex=apex, phi_deg=22.5, us_j=-1.0),
                    "6-2": dict(j="6", k="2", carrier="1", P=P62, oj=W["6"][1], zj=d2, ok=O2, zk=-d2, apex=None,
                                phi_deg=25.0, us_j=-1.0)})
    return dump(doc), info


# --- (c) a planetary stage with the ring fixed to the base --------------------------------------


def planetary_2dof(seed: int = 7) -> tuple[str, dict]:
    """YAML text of a two-dof mechanism with a planetary stage on a tilted axis.

    Sun 1 (motor1, stator base) and arm 2 turn about the same base axis; planet 3, carried by
    the arm, meshes externally with the sun (pair 1-3) and internally with a ring gear fixed
    to the base (pair 3-0: the base is gear k, the ring).  Link 4 (end effector) turns on
    the arm about a skew axis, driven directly by motor4 with its stator on the arm.  Arm
    rotation = sun rotation / (1 + N_ring / N_sun).
    """
    rng = np.random.default_rng(seed)
    a = unit(rng.normal(size=3) + [0, 0, 2.0])
    u = unit(np.cross(a, rng.normal(size=3)))
    mod = 0.0025
    zs, zp = 20, 28
    zr = zs + 2 * zp
    rs, rp, rr = mod * zs, mod * zp, mod * zr
    O = np.array([0.02, 0.01, 0.1])
    W = {"0": (np.eye(3), np.zeros(3)),
         "1": (random_rotation(rng), O - 0.03 * a),
         "2": (random_rotation(rng), O + 0.02 * a)}
    W["3"] = (random_rotation(rng), O + (rs + rp) * u + 0.01 * a)
    W["4"] = (random_rotation(rng), O + 0.15 * a + 0.05 * u)
    axes = {"1": a, "2": a, "3": -a, "4": unit(rng.normal(size=3))}
    parents = {"1": "0", "2": "0", "3": "2", "4": "2"}
    joints = []
    for name, child in (("J1", "1"), ("J2", "2"), ("J3", "3"), ("J4", "4")):
        p = parents[child]
        spec = {"name": name, "parent": p, "child": child}
        spec.update(_pose_spec(*W[p], *W[child], axes[child]))
        joints.append(spec)
    R2, o2 = W["2"]
    P13 = O + rs * u + 0.01 * a
    P30 = O + rr * u + 0.01 * a
    links = [{"name": "0"}]
    for name, mass in (("1", 0.4), ("2", 1.1), ("3", 0.15), ("4", 0.7)):
        links.append({"name": name, "mass": mass, "com": fl(rng.normal(scale=0.02, size=3)),
                      "inertia": inertia_spec(random_inertia(rng, mass, 0.02, 0.1))})
    doc = {
        "name": "planetary_2dof",
        "gravity": fl(9.81 * unit([0.2, 0.1, -1.0])),
        "base": "0",
        "end_effector": "4",
        "links": links,
        "joints": joints,
        "gears": [
            {"name": "1-3", "links": ["1", "3"], "kind": "external", "teeth": [zs, zp],
             "mesh_point": fl(R2.T @ (P13 - o2))},
            {"name": "3-0", "links": ["3", "0"], "kind": "internal", "teeth": [zp, zr],
             "mesh_point": fl(R2.T @ (P30 - o2)), "pressure_angle_deg": 25.0},
        ],
        "motors": [{"name": "motor1", "link": "1"}, {"name": "motor4", "link": "4", "stator": "2"}],
    }
    return dump(doc), {"arm_per_sun": 1.0 / (1.0 + zr / zs)}
