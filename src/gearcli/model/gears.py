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

    Steps: the radial feet of P on both axes; the pitch element and cone angles of parallel
    (:func:`_parallel`) or intersecting (:func:`_intersecting`) axes; the contact directions
    and the geometric ratio (:func:`_contact`); the given ratio, tooth counts and cone angles
    against the geometry (:func:`_given_values`).

    Returns the geometry and a list of (field, problem) pairs; the geometry is None when a
    problem makes it meaningless.
    """
    P, oj, zj, ok, zk = (np.asarray(x, float) for x in (P, oj, zj, ok, zk))
    zj, zk = zj / np.linalg.norm(zj), zk / np.linalg.norm(zk)
    rad_j, r_j = _foot(P, oj, zj)
    if kind == "rack":
        return rack_geometry(P, zj, zk, rad_j, r_j, ratio, names)
    rad_k, r_k = _foot(P, ok, zk)
    scale = max(1.0, r_j, r_k)
    problems = [("mesh_point", f"mesh point lies on the axis of gear '{n}'")
                for r, n in ((r_j, names[0]), (r_k, names[1])) if r < TOL_GEOM * scale]
    if problems:
        return None, problems
    if np.linalg.norm(np.cross(zj, zk)) < TOL_GEOM:
        pitch = _parallel(kind, zj, rad_j, rad_k, r_j, r_k, problems)
    else:
        pitch = _intersecting(kind, P, oj, zj, ok, zk, scale, problems)
    if pitch is None:
        return None, problems
    element, cone_j, cone_k, ring = pitch
    ut, us, e = _contact(zj, zk, rad_j, rad_k, r_j, r_k, element, ring)
    problems += _given_values(ratio, teeth, cones, e, r_j, r_k, cone_j, cone_k, names)
    return GearGeometry(P, zj, zk, rad_j, rad_k, ut, us, r_j, r_k, e, cone_j, cone_k, ring), problems


def mesh_point_for_ratio(g: GearGeometry, ratio: float) -> np.ndarray:
    """The mesh point (carrier frame, m) that gives the pair of geometry ``g`` the ratio
    ``ratio`` (its magnitude |e_kj| = r_k / r_j; the sign is the geometry's), the axes kept:
    a design sweep's variant of a ratio or of tooth counts (issue 37: "ratios and radii,
    which move the mesh points").

    * Parallel axes: the centre distance d is kept, the point stays on the line of centres:
      external r_j + r_k = d, so r_j' = d / (1 + |e|); internal |r_k - r_j| = d, so
      r_j' = d / (|e| - 1) (k the ring, |e| > 1) or d / (1 - |e|) (j the ring, |e| < 1).
      P' = F_j + r_j' rad_j, F_j = P - r_j rad_j the foot of P on gear j's axis.
    * Intersecting axes (bevel): the cone distance L = r_j / sin(cone_j) and the shaft
      angle S = cone_j + cone_k are kept: r_k / r_j = sin(cone_k) / sin(cone_j), so
      tan(cone_j') = sin S / (|e| + cos S); P' = A + L (cos(cone_j') a_j + sin(cone_j') rad_j),
      A the apex (where the axes through the feet F_j, F_k of P meet), a_j the direction
      of gear j's axis from A towards F_j.
    A ratio the geometry cannot take (an internal pair through |e| = 1, a zero) is a ValueError.
    """
    e = abs(float(ratio))
    if not np.isfinite(e) or e <= 0.0:
        raise ValueError(f"a gear ratio must be finite and nonzero, got {ratio:g}")
    foot = g.P - g.r_j * g.rad_j
    if g.cone_j == 0.0 and g.cone_k == 0.0:            # parallel axes
        if g.ring is None:
            return foot + (g.r_j + g.r_k) / (1.0 + e) * g.rad_j
        if (g.ring == 1) != (e > 1.0):
            raise ValueError(f"an internal pair's |ratio| must stay {'above' if g.ring == 1 else 'below'} 1 "
                             f"(its ring is gear {'k' if g.ring == 1 else 'j'}), got {e:g}")
        return foot + abs(g.r_k - g.r_j) / abs(e - 1.0) * g.rad_j
    S = g.cone_j + g.cone_k
    s, _ = np.linalg.lstsq(np.stack([g.zj, -g.zk], axis=1), g.P - g.r_k * g.rad_k - foot, rcond=None)[0]
    apex = foot + s * g.zj
    a_j = (foot - apex) / np.linalg.norm(foot - apex)
    L = float(np.linalg.norm(g.P - apex))
    cone = np.arctan2(np.sin(S), e + np.cos(S))
    return apex + L * (np.cos(cone) * a_j + np.sin(cone) * g.rad_j)


def rack_geometry(P, zj, zk, rad_j, r_j, ratio, names):
    """Rack and pinion: pinion j turning about (oj, zj), rack k sliding along zk.

    The rack's pitch line passes through the pitch point P along zk; it must be tangent to
    the pinion's pitch circle there: zk = +-ut with ut = zj x rad_j.  Rolling without
    slip, x_k = r_j (ut . zk) theta_j, so e_kj = theta_j / x_k = 1 / (r_j (ut . zk)) (rad/m).
    The separating force on the pinion, us = -rad_j, is normal to the pitch line (and to
    the rack's pitch plane, spanned by zk and zj), pushing the pinion away from the rack;
    the rack receives the opposite.  ``rad_k`` = -rad_j (from the rack towards P, as for
    an external pair), ``r_k`` = inf.
    """
    if r_j < TOL_GEOM * max(1.0, float(np.linalg.norm(P))):
        return None, [("mesh_point", f"mesh point lies on the axis of pinion '{names[0]}'")]
    ut = np.cross(zj, rad_j)
    along = float(ut @ zk)
    if abs(abs(along) - 1.0) > 1e-9:
        return None, [("mesh_point", f"the axis of rack '{names[1]}' is not tangent to the pitch circle of "
                       f"pinion '{names[0]}' at the mesh point (it must be perpendicular to the pinion axis "
                       f"and to the pinion radius through the mesh point; angle to the tangent "
                       f"{np.degrees(np.arccos(min(1.0, abs(along)))):.4g} deg)")]
    e = 1.0 / (r_j * np.sign(along))
    problems = []
    if ratio is not None and abs(ratio - e) > RTOL_RATIO * abs(e):
        problems.append(("ratio", f"ratio {ratio:g} rad/m contradicts the mesh geometry: pinion pitch radius "
                         f"{r_j:.6g} m and the rack direction give e = {e:.6g} rad/m"))
    return GearGeometry(P, zj, zk, rad_j, -rad_j, ut, -rad_j, r_j, float("inf"), float(e), 0.0, 0.0,
                        None), problems


def _parallel(kind, zj, rad_j, rad_k, r_j, r_k, problems):
    """Spur pair (parallel axes): (pitch element, cone_j, cone_k, ring), or None when the
    mesh point is off the line of centres; ``problems`` gets the kind contradictions."""
    if np.linalg.norm(np.cross(rad_j, rad_k)) > 1e-6:
        problems.append(("mesh_point", "mesh point is not on the line of centres of the two parallel axes"))
        return None
    same_side = rad_j @ rad_k > 0
    if kind == "bevel":
        problems.append(("kind", "bevel gears need intersecting axes, these axes are parallel"))
    elif kind == "external" and same_side:
        problems.append(("kind", "external pair, but the mesh point lies on the same side of both "
                         "axes (that is an internal/ring pair)"))
    elif kind == "internal" and not same_side:
        problems.append(("kind", "internal pair, but the mesh point lies between the two axes "
                         "(that is an external pair)"))
    ring = (0 if r_j > r_k else 1) if kind == "internal" else None
    return zj, 0.0, 0.0, ring


def _intersecting(kind, P, oj, zj, ok, zk, scale, problems):
    """Bevel pair (intersecting axes): (pitch element from the apex to P, cone_j, cone_k,
    None), or None when the axes are skew or P is off their plane."""
    n = np.cross(zj, zk)
    n /= np.linalg.norm(n)
    gap = abs((ok - oj) @ n)
    if gap > TOL_GEOM * scale:
        problems.append(("mesh_point", f"the gear axes are skew (they miss each other by {gap:.4g} m): "
                         "only parallel (spur) and intersecting (bevel) axes are supported"))
        return None
    # apex: oj + s zj = ok + u zk
    s, _ = np.linalg.lstsq(np.stack([zj, -zk], axis=1), ok - oj, rcond=None)[0]
    apex = oj + s * zj
    if abs((P - apex) @ n) > 1e-6 * scale:
        problems.append(("mesh_point", "mesh point is not in the plane of the two gear axes"))
        return None
    if kind != "bevel":
        problems.append(("kind", f"{kind} gears need parallel axes, these axes intersect (use kind: bevel)"))
    element = (P - apex) / np.linalg.norm(P - apex)
    cone_j = float(np.arccos(np.clip(abs(element @ zj), 0, 1)))
    cone_k = float(np.arccos(np.clip(abs(element @ zk), 0, 1)))
    return element, cone_j, cone_k, None


def _contact(zj, zk, rad_j, rad_k, r_j, r_k, element, ring):
    """Tangential and separating unit vectors on gear j (ut, us) and the ratio e_kj from
    rolling at the pitch point."""
    ut = np.cross(zj, rad_j)
    tk = np.cross(zk, rad_k)
    e = (r_k * (tk @ ut)) / (r_j * (ut @ ut))
    us = -rad_j + (rad_j @ element) * element
    us /= np.linalg.norm(us)
    return ut, (-us if ring == 0 else us), e


def _given_values(ratio, teeth, cones, e, r_j, r_k, cone_j, cone_k, names) -> list[tuple[str, str]]:
    """(field, problem) for a ratio, tooth counts or cone angles that contradict the geometry."""
    problems = []
    if ratio is not None and abs(ratio - e) > RTOL_RATIO * abs(e):
        problems.append(("ratio", f"ratio {ratio:g} contradicts the mesh geometry: pitch radii "
                         f"{r_j:.6g} m and {r_k:.6g} m give e = {e:.6g}"))
    if teeth is not None:
        te = teeth[1] / teeth[0]
        if abs(te - abs(e)) > RTOL_RATIO * abs(e):
            problems.append(("teeth", f"tooth counts {teeth[0]}:{teeth[1]} give |ratio| {te:.6g}, but the "
                             f"mesh geometry gives {abs(e):.6g}"))
    if cones is not None:
        for i, (given, geo, n) in enumerate(((cones[0], cone_j, names[0]), (cones[1], cone_k, names[1]))):
            if abs(given - geo) > TOL_ANGLE:
                problems.append((f"cone_angles_deg[{i}]", f"cone angle {np.rad2deg(given):.6g} deg of gear "
                                 f"'{n}' contradicts the geometry ({np.rad2deg(geo):.6g} deg)"))
    return problems


def helical_terms(gm: GearGeometry, pressure_angle: float, helix_angle: float = 0.0,
                  hand: str | None = None) -> tuple[float, np.ndarray]:
    """(tan phi_t, a): the tooth force on gear j is ``g = t (ut + a) + |t| tan(phi_t) us``.

    For a spur pair (beta = 0) phi_t is the pressure angle and a = 0.  For a helical pair
    ``pressure_angle`` is the normal one phi_n: tan(phi_t) = tan(phi_n) / cos(beta), and the
    contact force is normal to the tooth line.  On a right-hand gear j the tooth line
    advances like a right-hand screw, along cos(beta) z_j + sin(beta) ut (whichever way z_j
    points), so a force perpendicular to it with tangential part t ut has the axial part
    a t = -t tan(beta) z_j; on a left-hand gear j, +t tan(beta) z_j.  (3,) carrier frame.
    """
    tan_t = float(np.tan(pressure_angle) / np.cos(helix_angle))
    if not helix_angle:
        return tan_t, np.zeros(3)
    sign = -1.0 if hand == "right" else 1.0
    return tan_t, sign * float(np.tan(helix_angle)) * gm.zj
