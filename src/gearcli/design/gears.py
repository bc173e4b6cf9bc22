"""Gear teeth: nominal root bending stress (Lewis) and contact stress (Hertz, ISO 6336-2 form).

Forces in N, lengths in m, stresses in Pa; arrays of samples have shape (N,).

Sources
-------
* Lewis bending equation, metric form (Shigley's *Mechanical Engineering Design*, 9th ed.,
  Eq. 14-7; Budynas & Nisbett): sigma_F = K Ft / (b m Y), with Y the Lewis form factor of
  Table 14-2 (20 deg pressure angle, full-depth teeth).  K collects the application, dynamic
  and load-sharing factors (1 when not given).
* Hertz contact stress of two cylinders with the radii of curvature of the involutes at the
  pitch point, written as in ISO 6336-2:2019 (basic value, spur gears, no profile shift):
  sigma_H = Z_H Z_E sqrt(K Ft (u + 1) / (d1 b u)), zone factor Z_H = sqrt(2 / (sin a cos a)),
  u = z2 / z1 >= 1 (u + 1 -> u - 1 for an internal pair), elastic coefficient Z_E
  (189.8 sqrt(N/mm^2) for steel on steel).  Shigley Eq. 14-14 is the same stress.
* Helical gears (helix angle beta, normal pressure angle a_n, ``module`` = the normal module
  m_n): the transverse tangential force Ft (the ``gear:<pair>:t`` column) is used
  throughout.  Bending: the Lewis equation on the normal section, the load Ft / cos(beta)
  spread over the tooth length b / cos(beta), sigma_F = K Ft / (b m_n Y(z_v)), with Y
  taken at the virtual (formative) tooth count z_v = z / cos^3(beta) (Shigley's *Mechanical
  Engineering Design*, helical gears: the virtual number of teeth N / cos^3(psi); the
  helical tooth is rated as the spur tooth of its normal section).  Contact: ISO 6336-2:2019, zone factor for helical gears without
  profile shift Z_H = sqrt(2 cos(beta_b) / (cos^2(a_t) tan(a_t))), tan(a_t) = tan(a_n) /
  cos(beta), tan(beta_b) = tan(beta) cos(a_t), and helix angle factor Z_beta =
  1 / sqrt(cos(beta)); the contact ratio factor Z_eps is taken as 1 (its upper bound: a
  nominal, conservative value).  Both reduce to the spur formulas at beta = 0.
* A rack (z -> inf) has the Lewis factor 0.485 and u -> inf: (u + 1) / u -> 1.
* Bevel gears are rated on their virtual spur gears (Tredgold's approximation, Shigley
  sec. 15-1, ISO 10300): virtual tooth count z / cos(delta), virtual pitch diameter
  d / cos(delta), delta the pitch cone angle, at the mean pitch point.
"""
from __future__ import annotations

import math

import numpy as np

from ..model.ratings import STEEL_ELASTIC_COEFFICIENT
from . import magnitudes

# Shigley, Table 14-2: Lewis form factor Y, 20 deg pressure angle, full-depth teeth (the
# same 25 rows in several public gear-rating codes that cite the table; the rack's 0.485
# in one of them).
LEWIS_TABLE = (
    (12, 0.245), (13, 0.261), (14, 0.277), (15, 0.290), (16, 0.296), (17, 0.303),
    (18, 0.309), (19, 0.314), (20, 0.322), (21, 0.328), (22, 0.331), (24, 0.337),
    (26, 0.346), (28, 0.353), (30, 0.359), (34, 0.371), (38, 0.384), (43, 0.397),
    (50, 0.409), (60, 0.422), (75, 0.435), (100, 0.447), (150, 0.460), (300, 0.472),
    (400, 0.480),
)
LEWIS_RACK = 0.485


def lewis_form_factor(z: float) -> float:
    """Lewis form factor Y of a gear with ``z`` teeth (Shigley Table 14-2, 20 deg, full depth).

    Linear interpolation in the table between 12 and 400 teeth; above 400 the factor tends
    to the rack's 0.485 as 0.485 - 2/z.  Fewer than 12 teeth (undercut) raises ValueError.
    """
    if z < LEWIS_TABLE[0][0]:
        raise ValueError(f"the Lewis form factor is tabulated from 12 teeth, got {z:g}")
    if z > LEWIS_TABLE[-1][0]:
        return LEWIS_RACK - (LEWIS_RACK - LEWIS_TABLE[-1][1]) * LEWIS_TABLE[-1][0] / z
    zs, ys = zip(*LEWIS_TABLE)
    return float(np.interp(z, zs, ys))


def lewis_bending_stress(Ft, module: float, face_width: float, Y: float, K: float = 1.0) -> np.ndarray:
    """Nominal tooth-root bending stress sigma_F = K |Ft| / (b m Y), Pa.

    Parameters
    ----------
    Ft : array_like, shape (N,)
        Tangential tooth force, N.
    module, face_width : float
        Module m and face width b, m.
    Y : float
        Lewis form factor (:func:`lewis_form_factor`).
    K : float
        Product of the load factors (application, load sharing, ...).
    """
    s = magnitudes(Ft)
    s *= K
    s /= face_width * module * Y
    return s


def zone_factor(pressure_angle: float, helix_angle: float = 0.0) -> float:
    """ISO 6336-2 zone factor without profile shift, sqrt(2 cos(beta_b) / (cos^2(a_t) tan(a_t))):
    sqrt(2 / (sin a cos a)) for a spur pair; ``pressure_angle`` is the normal one (rad)."""
    at = math.atan(math.tan(pressure_angle) / math.cos(helix_angle))
    bb = math.atan(math.tan(helix_angle) * math.cos(at))
    return math.sqrt(2.0 * math.cos(bb) / (math.cos(at) ** 2 * math.tan(at)))


def helix_angle_factor(helix_angle: float) -> float:
    """ISO 6336-2:2019 helix angle factor Z_beta = 1 / sqrt(cos(beta)) (1 for spur gears)."""
    return 1.0 / math.sqrt(math.cos(helix_angle))


def virtual_helical_teeth(z: float, helix_angle: float) -> float:
    """Virtual (formative) tooth count of a helical gear, z / cos^3(beta)."""
    return z / math.cos(helix_angle) ** 3


def hertz_contact_stress(Ft, d1: float, face_width: float, u: float, pressure_angle: float,
                         ZE: float = STEEL_ELASTIC_COEFFICIENT, K: float = 1.0,
                         internal: bool = False, helix_angle: float = 0.0) -> np.ndarray:
    """Nominal contact stress at the pitch point, sigma_H = Z_H Z_E Z_beta sqrt(K |Ft| (u +- 1) / (d1 b u)), Pa.

    Parameters
    ----------
    Ft : array_like, shape (N,)
        Tangential tooth force, N.
    d1 : float
        Pitch diameter of the pinion (the smaller gear), m.
    face_width : float
        Face width b, m.
    u : float
        Gear ratio z2 / z1 >= 1 (inf for a rack).
    pressure_angle : float
        Normal pressure angle, rad.
    ZE : float
        Elastic coefficient, sqrt(Pa).
    K : float
        Product of the load factors.
    internal : bool
        An internal (ring) pair: u + 1 becomes u - 1.
    helix_angle : float
        Helix angle beta, rad (0: spur); Ft is then the transverse tangential force.
    """
    ratio = 1.0 - 1.0 / u if internal else 1.0 + 1.0 / u
    Z = zone_factor(pressure_angle, helix_angle) * helix_angle_factor(helix_angle) * ZE
    s = magnitudes(Ft)                        # Z sqrt(K |Ft| ratio / (d1 b)), in place
    s *= K
    s *= ratio
    s /= d1 * face_width
    np.sqrt(s, out=s)
    s *= Z
    return s


def virtual_spur(z: float, d: float, cone_angle: float) -> tuple[float, float]:
    """Tredgold's virtual spur gear of a bevel gear: (z / cos delta, d / cos delta)."""
    c = math.cos(cone_angle)
    return z / c, d / c
