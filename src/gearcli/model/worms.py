"""Worm pairs: a cylindrical worm driving a wheel on crossed axes at 90 deg (``gears[].kind:
worm``; ``../shared/drive-elements.md`` D, docs/concepts/drive-elements.md "Worm pairs").

Geometry (carrier frame, fixed for the whole motion)
----------------------------------------------------
The worm W turns about z_w (its joint axis), the wheel G about z_g, perpendicular to it, both
relative to the carrier c.  n_c is the unit common normal from the worm axis toward the wheel
axis; the contact point P lies on it at d1/2 from the worm axis (d1 the worm's reference
diameter); the wheel's pitch radius r2 = a - d1/2 = Z2 m_x / 2 (a the centre distance, m_x the
axial module).  At P: c_hat = z_w x n_c (the worm's circumferential direction), the thread
tangent h_hat = cos(gamma) c_hat + s sin(gamma) z_w and the flank normal in the tangent plane
e_hat = -s sin(gamma) c_hat + cos(gamma) z_w, s = +1 for a right hand (-1 left), gamma the lead
angle (tan(gamma) = z1 m_x / d1).

Kinematics: the velocities of W and G at P have no component along e_hat, which gives
theta_W = e theta_G with e = -s kappa Z2 / z1, kappa = z_g . c_hat (+-1: z_g is +-c_hat); the
sliding velocity of W relative to G at P is (w_W d1 / (2 cos(gamma))) h_hat, w_W the worm's
rate relative to c, so its direction is s_v h_hat, s_v = sign(w_W).

Interaction (exact Coulomb sliding friction)
--------------------------------------------
The unknown N (N) is the signed flank load.  The force on G at P is
F = N cos(alpha_n) e_hat + |N| sin(alpha_n) n_c + mu |N| s_hat, s_hat = s_v h_hat the sliding
direction of W relative to G (friction on G drags it along W's sliding); W receives -F.  It
dissipates mu |N| |v_s|.  Forward (the worm drives) its efficiency is
(cos(alpha_n) - mu tan(gamma)) / (cos(alpha_n) + mu cot(gamma)), backward (the wheel drives)
(cos(alpha_n) - mu cot(gamma)) / (cos(alpha_n) + mu tan(gamma)); self-locking where
tan(gamma) <= mu / cos(alpha_n).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np


@dataclass(frozen=True)
class Worm:
    """What a worm pair adds to its :class:`~.mechanism.GearPair` (``j`` the worm, ``k`` the
    wheel): starts z1 and wheel teeth Z2, reference diameter d1 (m), axial module m_x (m),
    lead angle gamma (rad), normal pressure angle alpha_n (rad), friction coefficient mu, hand."""

    z1: int
    z2: int
    d1: float
    module: float
    lead_angle: float
    pressure_angle: float
    mu: float = 0.0
    hand: str = "right"
    path: str = field(default="", compare=False)

    @property
    def s(self) -> float:
        """+1 right hand, -1 left hand."""
        return 1.0 if self.hand == "right" else -1.0

    @property
    def lossy(self) -> bool:
        return self.mu > 0.0

    power_flow_lossy = lossy

    def lossless(self) -> "Worm":
        return replace(self, mu=0.0)


def worm_efficiencies(gamma: float, alpha_n: float, mu: float) -> tuple[float, float]:
    """(forward, backward) efficiency of a worm pair (module docstring; backward <= 0:
    self-locking)."""
    c, t = math.cos(alpha_n), math.tan(gamma)
    return (c - mu * t) / (c + mu / t), (c - mu / t) / (c + mu * t)


def self_locking(gamma: float, alpha_n: float, mu: float) -> bool:
    """True when the wheel cannot drive the worm: tan(gamma) <= mu / cos(alpha_n)."""
    return math.tan(gamma) <= mu / math.cos(alpha_n)


@dataclass(frozen=True, eq=False)
class WormGeometry:
    """A worm pair's directions and contact point in the carrier frame (module docstring)."""

    P: np.ndarray       # contact point
    n_c: np.ndarray     # common normal, worm axis -> wheel axis
    e_hat: np.ndarray   # flank normal in the tangent plane
    h_hat: np.ndarray   # thread tangent
    z_w: np.ndarray
    t_g: np.ndarray     # unit(z_g x (P - O_g)): the wheel's tangential direction at P
    ratio: float        # e = theta_W / theta_G
    r2: float           # wheel pitch radius, m


def worm_geometry(worm: Worm, ow, zw, og, zg, names=("worm", "wheel")) -> tuple[WormGeometry | None, list]:
    """The geometry of a worm pair from its two axis lines (points, directions) in the carrier
    frame; (None, problems) when the axes are not perpendicular or the wheel's pitch radius
    a - d1/2 disagrees with Z2 m_x / 2 (1e-9 relative)."""
    ow, zw, og, zg = (np.asarray(v, float) for v in (ow, zw, og, zg))
    zw, zg = zw / np.linalg.norm(zw), zg / np.linalg.norm(zg)
    if abs(float(zw @ zg)) > 1e-9:
        return None, [("links", f"the axes of worm '{names[0]}' and wheel '{names[1]}' are not perpendicular "
                       f"(angle {math.degrees(math.acos(min(1.0, abs(float(zw @ zg))))):.6g} deg): a worm pair has "
                       "crossed axes at 90 deg")]
    n = np.cross(zw, zg)
    n /= np.linalg.norm(n)
    a = float((og - ow) @ n)
    if a < 0:
        n, a = -n, -a
    r2 = a - worm.d1 / 2
    want = worm.z2 * worm.module / 2
    if abs(r2 - want) > 1e-9 * max(1.0, want):
        return None, [("reference_diameter", f"the wheel's pitch radius (centre distance {a:.9g} m - d1/2) is "
                       f"{r2:.9g} m, but Z2 m_x / 2 = {want:.9g} m: the axes' distance, reference_diameter, module "
                       "and teeth disagree")]
    # the worm axis point and the wheel axis point on the common normal
    s_w = float(np.linalg.lstsq(np.stack([zw, -zg], axis=1), og - ow, rcond=None)[0][0])
    foot_w = ow + s_w * zw
    P = foot_w + worm.d1 / 2 * n
    c_hat = np.cross(zw, n)
    g, s = worm.lead_angle, worm.s
    h_hat = math.cos(g) * c_hat + s * math.sin(g) * zw
    e_hat = -s * math.sin(g) * c_hat + math.cos(g) * zw
    kappa = float(np.sign(zg @ c_hat))
    O_g = foot_w + a * n
    t_g = np.cross(zg, P - O_g)
    t_g /= np.linalg.norm(t_g)
    return WormGeometry(P, n, e_hat, h_hat, zw, t_g, -s * kappa * worm.z2 / worm.z1, r2), []


def worm_force(geo: WormGeometry, worm: Worm, N, s_v) -> np.ndarray:
    """(n, 3) the force on the wheel at P (carrier frame) of flank loads N (n,) with the worm's
    sliding signs s_v (n,)."""
    N, s_v = np.asarray(N, float), np.asarray(s_v, float)
    a = worm.pressure_angle
    return (N[:, None] * (math.cos(a) * geo.e_hat) + np.abs(N)[:, None] * (math.sin(a) * geo.n_c)
            + (worm.mu * np.abs(N) * s_v)[:, None] * geo.h_hat)
