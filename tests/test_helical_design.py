"""Helical gears against textbook worked examples, and their rating (``gearcli verify``).

Shigley's *Mechanical Engineering Design* (9th ed.), Example 13-8: a 1 hp motor at
1800 rev/min drives an 18-tooth helical pinion, normal pressure angle 20 deg, helix angle
30 deg, normal diametral pitch 12 teeth/in.  The book: transverse pressure angle 22.8 deg,
pitch diameter 1.732 in, pitch-line velocity 816 ft/min, Wt = 40.4 lbf, Wr = 17.0 lbf,
Wa = 23.3 lbf, W = 49.6 lbf.  gearcli must reproduce the force components when the pinion
holds the corresponding torque.

The rating is checked on a helical pinion of a classical Lewis exercise (22 teeth, normal
pressure angle 20 deg, normal diametral pitch 8 teeth/in, face width 2 in, helix angle
25 deg, 30 hp at 1800 rev/min), the stresses computed here by hand: Lewis on the normal
section with the virtual tooth count z / cos^3(beta), Hertz with ISO 6336-2's helical zone
factor (base helix angle from sin(beta_b) = sin(beta) cos(alpha_n), a different route to
the one in the code) and helix angle factor 1 / sqrt(cos(beta)).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from gearcli import analyse, parse_mechanism, solve
from gearcli.design.checks import Requirements, build_checks
from gearcli.design.evaluate import Samples, signal
from gearcli.design.gears import hertz_contact_stress, zone_factor
from gearcli.errors import Collector
from gearcli.report.columns import named_columns

LBF = 4.4482216152605      # N
INCH = 0.0254              # m
PSI = LBF / INCH**2        # Pa


def pair_yaml(zp, zg, Pn, beta_deg, torque, rating=""):
    """Pinion (motor) and gear (loaded by ``torque`` against the pinion's positive drive: the
    gear turns the other way, so +torque about +z), axes +z,
    the pinion's pitch radius from the normal diametral pitch: d = z / (Pn cos beta)."""
    rp = zp / (Pn * math.cos(math.radians(beta_deg))) / 2 * INCH
    rg = rp * zg / zp
    helix = f"    helix_angle_deg: {beta_deg}\n    hand: right\n" if beta_deg else ""
    return f"""
name: helical_pair
base: housing
end_effector: gear
links:
  - {{name: housing}}
  - {{name: pinion, mass: 0.2, inertia: [1.0e-5, 1.0e-5, 1.0e-5]}}
  - {{name: gear, mass: 1.0, inertia: [1.0e-3, 1.0e-3, 1.0e-3]}}
joints:
  - {{name: Jp, parent: housing, child: pinion, origin: {{xyz: [0, 0, 0]}}}}
  - {{name: Jg, parent: housing, child: gear, origin: {{xyz: [{rp + rg!r}, 0, 0]}}}}
gears:
  - name: mesh
    links: [pinion, gear]
    teeth: [{zp}, {zg}]
    mesh_point: [{rp!r}, 0, 0]
    pressure_angle_deg: 20
{helix}{rating}motors:
  - {{name: motor, link: pinion}}
loads:
  - {{name: out, link: gear, frame: base, moment: [0, 0, {torque!r}]}}
""", rp, rg


def test_shigley_example_13_8_force_components():
    Pn, beta = 12.0, math.radians(30.0)
    d_in = 18 / (Pn * math.cos(beta))                     # 1.732 in
    V = math.pi * d_in * 1800 / 12                        # ft/min
    Wt = 33000 * 1.0 / V                                  # lbf
    assert d_in == pytest.approx(1.732, abs=5e-4) and V == pytest.approx(816, abs=0.5)
    text, rp, rg = pair_yaml(18, 36, Pn, 30, Wt * LBF * 2 * (d_in / 2 * INCH))
    res = solve(analyse(parse_mechanism(text)), np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)))
    t, sep, ax = abs(res.gear_t[0, 0]), res.gear_sep[0, 0], abs(res.gear_axial[0, 0, 0])
    book = {"Wt": 40.4, "Wr": 17.0, "Wa": 23.3, "W": 49.6}
    for got, key in ((t, "Wt"), (sep, "Wr"), (ax, "Wa"), (math.sqrt(t * t + sep * sep + ax * ax), "W")):
        assert got / LBF == pytest.approx(book[key], rel=2.5e-3), key   # the book rounds to 3 digits
    assert res.motor[0, 0] == pytest.approx(Wt * LBF * rp, rel=1e-12)


RATING = """    rating: {{module: {m}, face_width: {b}, bending_stress_limit: 300.0e6,
             contact_stress_limit: 1200.0e6}}
"""


def helical_rating_case(beta_deg):
    Pn, zp, zg, b_in = 8.0, 22, 40, 2.0
    beta = math.radians(beta_deg)
    d_in = zp / (Pn * math.cos(beta))
    Wt = 33000 * 30 / (math.pi * d_in * 1800 / 12)         # lbf
    torque_gear = Wt * LBF * (d_in * zg / zp / 2 * INCH)
    text, rp, rg = pair_yaml(zp, zg, Pn, beta_deg, torque_gear,
                             RATING.format(m=repr(INCH / Pn), b=repr(b_in * INCH)))
    return text, Wt, d_in, b_in, Pn, zp, zg


def gearcli_stresses(text):
    an = analyse(parse_mechanism(text))
    res = solve(an, np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)))
    col = Collector("<test>", {})
    checks = build_checks(an, Requirements(), col)
    assert not col.issues
    s = Samples(np.zeros(1), named_columns(an, res), np.zeros((1, 2)))
    by = {c.quantity: signal(c, s, an.mech)[0] for c in checks if c.component == "gear mesh"}
    return by["bending safety"], by["contact safety"]


def lewis_y(z):
    """Shigley Table 14-2 (20 deg, full depth), interpolated by hand for the teeth used here."""
    table = {21: 0.328, 22: 0.331, 24: 0.337, 26: 0.346, 28: 0.353, 30: 0.359, 34: 0.371, 38: 0.384, 43: 0.397, 50: 0.409, 60: 0.422, 75: 0.435}
    zs = sorted(table)
    hi = next(x for x in zs[1:] if x >= z)
    lo = zs[zs.index(hi) - 1]
    return table[lo] + (table[hi] - table[lo]) * (z - lo) / (hi - lo)


@pytest.mark.parametrize("beta_deg", [25.0, 0.0])
def test_helical_lewis_and_hertz_by_hand(beta_deg):
    text, Wt, d_in, b_in, Pn, zp, zg = helical_rating_case(beta_deg)
    beta, an_ = math.radians(beta_deg), math.radians(20.0)
    bending, contact = gearcli_stresses(text)
    # Lewis on the normal section: sigma = Wt Pn / (F Y(z_v)), z_v = z / cos^3(beta)
    zv = zp / math.cos(beta) ** 3
    sigma_F = Wt * Pn / (b_in * lewis_y(zv)) * PSI
    assert bending == pytest.approx(sigma_F, rel=1e-9)
    # ISO 6336-2: Z_H = sqrt(2 cos(beta_b) / (cos^2(alpha_t) tan(alpha_t))), Z_beta = cos(beta)^-1/2
    at = math.atan(math.tan(an_) / math.cos(beta))
    bb = math.asin(math.sin(beta) * math.cos(an_))
    ZH = math.sqrt(2 * math.cos(bb) / (math.cos(at) ** 2 * math.tan(at)))
    u = zg / zp
    sigma_H = ZH * 189.8e3 / math.sqrt(math.cos(beta)) * math.sqrt(Wt * LBF * (u + 1) / (d_in * INCH * b_in * INCH * u))
    assert contact == pytest.approx(sigma_H, rel=1e-9)
    if beta_deg == 25.0:     # by hand: z_v = 29.55, Y = 0.3577, Wt = 692 lbf, sigma = 7.74 kpsi
        assert zv == pytest.approx(29.55, abs=0.01) and Wt == pytest.approx(692.4, abs=0.5)
        assert sigma_F / PSI == pytest.approx(7743, rel=2e-3)


def test_spur_limits_of_the_helical_factors():
    a = math.radians(20.0)
    assert zone_factor(a, 0.0) == pytest.approx(math.sqrt(2 / (math.sin(a) * math.cos(a))), rel=1e-15)
    # ISO 6336-2 tabulates Z_H = 2.495 for a spur pair at 20 deg and smaller values for helical ones
    assert zone_factor(a) == pytest.approx(2.495, abs=5e-4)
    assert zone_factor(a, math.radians(25.0)) < zone_factor(a)
    # a rack: (u + 1) / u -> 1
    assert hertz_contact_stress([100.0], 0.05, 0.02, math.inf, a)[0] == pytest.approx(
        zone_factor(a) * 189.8e3 * math.sqrt(100.0 / (0.05 * 0.02)), rel=1e-15)


def test_helical_module_is_the_normal_module():
    """With teeth given, r = m_n z / (2 cos beta): the transverse module would be refused."""
    text, *_ = helical_rating_case(25.0)
    an = analyse(parse_mechanism(text.replace(repr(INCH / 8.0), repr(INCH / 8.0 / math.cos(math.radians(25.0))))))
    col = Collector("<test>", {})
    build_checks(an, Requirements(), col)
    assert any("normal module" in i.message for i in col.issues)
