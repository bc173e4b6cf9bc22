"""Gear pair geometry in the carrier frame (fixed in the carrier for the whole motion).

Conventions (paper Eq. 8 and 14, ERRATA 7):

* ``ratio`` e_kj: theta_{j,c} = e_kj * theta_{k,c}, angles about each gear's positive axis.
* The contact force **on gear j by gear k** at the pitch point P is
  ``g = t * ut + |t| * tan(phi) * us``: ``t`` is tangential, positive when it turns j in
  its positive sense (``ut = z_j x rad_j``); ``us`` is the separating direction on j,
  perpendicular to the pitch element and pushing j away from k (for an internal pair the
  ring is pushed outwards).  Gear k receives ``-g``.
* ``rad_x`` is the unit vector from gear x's axis to P, perpendicular to the axis.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

RTOL_RATIO = 1e-6
TOL_ANGLE = 1e-4  # rad, for given cone angles
TOL_GEOM = 1e-9   # m and rad, for collinearity and coplanarity


@dataclass(frozen=True, eq=False)
class GearGeometry:
    """Vectors in the carrier frame.  ``ratio`` is e_kj from the geometry."""

    P: np.ndarray
    zj: np.ndarray
    zk: np.ndarray
    rad_j: np.ndarray
    rad_k: np.ndarray
    ut: np.ndarray
    us: np.ndarray
    r_j: float
    r_k: float
    ratio: float
    cone_j: float
    cone_k: float
    ring: int | None  # 0 if j is the ring of an internal pair, 1 if k is, else None


def _foot(P, o, z):
    d = P - o
    d = d - (d @ z) * z
    r = float(np.linalg.norm(d))
    return (d / r if r > 0 else d), r


def gear_geometry(kind: str, P, oj, zj, ok, zk, teeth=None, ratio=None, cones=None,
                  names=("j", "k")) -> tuple[GearGeometry | None, list[tuple[str, str]]]:
    """Geometry of a pair from the pitch point and the two axis lines (carrier frame).

    Returns the geometry and a list of (field, problem) pairs; the geometry is None when a
    problem makes it meaningless.
    """
    P, oj, zj, ok, zk = (np.asarray(x, float) for x in (P, oj, zj, ok, zk))
    zj, zk = zj / np.linalg.norm(zj), zk / np.linalg.norm(zk)
    problems: list[tuple[str, str]] = []
    nj, nk = names
    rad_j, r_j = _foot(P, oj, zj)
    rad_k, r_k = _foot(P, ok, zk)
    scale = max(1.0, r_j, r_k)
    for r, n in ((r_j, nj), (r_k, nk)):
        if r < TOL_GEOM * scale:
            problems.append(("mesh_point", f"mesh point lies on the axis of gear '{n}'"))
    if problems:
        return None, problems
    parallel = np.linalg.norm(np.cross(zj, zk)) < TOL_GEOM
    ring = None
    if parallel:
        if np.linalg.norm(np.cross(rad_j, rad_k)) > 1e-6:
            problems.append(("mesh_point", "mesh point is not on the line of centres of the two parallel axes"))
            return None, problems
        same_side = rad_j @ rad_k > 0
        if kind == "bevel":
            problems.append(("kind", "bevel gears need intersecting axes, these axes are parallel"))
        elif kind == "external" and same_side:
            problems.append(("kind", "external pair, but the mesh point lies on the same side of both "
                             "axes (that is an internal/ring pair)"))
        elif kind == "internal" and not same_side:
            problems.append(("kind", "internal pair, but the mesh point lies between the two axes "
                             "(that is an external pair)"))
        if kind == "internal":
            ring = 0 if r_j > r_k else 1
        element = zj
        cone_j = cone_k = 0.0
    else:
        # closest points of the two axis lines
        n = np.cross(zj, zk)
        n /= np.linalg.norm(n)
        gap = abs((ok - oj) @ n)
        if gap > TOL_GEOM * scale:
            problems.append(("mesh_point", f"the gear axes are skew (they miss each other by {gap:.4g} m): "
                             "only parallel (spur) and intersecting (bevel) axes are supported"))
            return None, problems
        # apex: oj + s zj = ok + u zk
        M = np.stack([zj, -zk], axis=1)
        s, u = np.linalg.lstsq(M, ok - oj, rcond=None)[0]
        apex = oj + s * zj
        if abs((P - apex) @ n) > 1e-6 * scale:
            problems.append(("mesh_point", "mesh point is not in the plane of the two gear axes"))
            return None, problems
        if kind != "bevel":
            problems.append(("kind", f"{kind} gears need parallel axes, these axes intersect (use kind: bevel)"))
        element = (P - apex) / np.linalg.norm(P - apex)
        cone_j = float(np.arccos(np.clip(abs(element @ zj), 0, 1)))
        cone_k = float(np.arccos(np.clip(abs(element @ zk), 0, 1)))
    ut = np.cross(zj, rad_j)
    tk = np.cross(zk, rad_k)
    c_j = r_j * (ut @ ut)
    c_k = r_k * (tk @ ut)
    e = c_k / c_j
    us = -rad_j + (rad_j @ element) * element
    us /= np.linalg.norm(us)
    if ring == 0:
        us = -us
    if ratio is not None and abs(ratio - e) > RTOL_RATIO * abs(e):
        problems.append(("ratio", f"ratio {ratio:g} contradicts the mesh geometry: pitch radii "
                         f"{r_j:.6g} m and {r_k:.6g} m give e = {e:.6g}"))
    if teeth is not None:
        te = teeth[1] / teeth[0]
        if abs(te - abs(e)) > RTOL_RATIO * abs(e):
            problems.append(("teeth", f"tooth counts {teeth[0]}:{teeth[1]} give |ratio| {te:.6g}, but the "
                             f"mesh geometry gives {abs(e):.6g}"))
    if cones is not None:
        for i, (given, geo, n) in enumerate(((cones[0], cone_j, nj), (cones[1], cone_k, nk))):
            if abs(given - geo) > TOL_ANGLE:
                problems.append((f"cone_angles_deg[{i}]", f"cone angle {np.rad2deg(given):.6g} deg of gear "
                                 f"'{n}' contradicts the geometry ({np.rad2deg(geo):.6g} deg)"))
    return GearGeometry(P, zj, zk, rad_j, rad_k, ut, us, r_j, r_k, e, cone_j, cone_k, ring), problems
