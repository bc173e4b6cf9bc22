"""Rating formulas against hand calculations and textbook worked examples.

Every reference figure is computed here from first principles or quoted from the cited
example; none is produced by the code under test.
"""
import math

import numpy as np
import pytest

from gearcli.design import bearings as B
from gearcli.design import gears as G
from gearcli.design import motors as Mo

LBF = 4.4482216152605      # N
INCH = 0.0254              # m
PSI = LBF / INCH**2        # Pa


def test_dynamic_equivalent_load_switches_at_e():
    # ISO 281: P = Fr when Fa/Fr <= e, else X Fr + Y Fa.  By hand: 0.56*1000 + 1.6*500 = 1360.
    P = B.equivalent_dynamic_load([1000.0, 1000.0, 0.0, -1000.0], [500.0, 200.0, 300.0, -270.0], 0.56, 1.6, 0.27)
    assert P == pytest.approx([1360.0, 1000.0, 480.0, 1000.0])


def test_l10_closed_form_at_constant_load_and_speed():
    # Constant load P at constant speed n: L10h = (C/P)^3 1e6 / (60 n[rpm]) for a ball bearing.
    C, P, rpm, T = 12_000.0, 1_500.0, 900.0, 4.0          # N, N, rev/min, cycle length s
    t = np.linspace(0.0, T, 4001)
    rate = np.full_like(t, rpm * 2 * math.pi / 60)
    dt = B.sample_weights(t)
    Peq = B.duty_equivalent_load(np.full_like(t, P), rate, dt, 3.0)
    assert Peq == pytest.approx(P, rel=1e-12)
    revs_per_cycle = np.sum(rate * dt) / (2 * math.pi)
    life = B.rating_life_hours(B.rating_life_mrev(C, Peq, 3.0), revs_per_cycle * 3600.0 / T)
    assert life == pytest.approx((C / P) ** 3 * 1e6 / (60 * rpm), rel=1e-9)   # 8^3 * 1e6 / 54000 = 9481.5 h by hand
    assert life == pytest.approx(9481.48, rel=1e-6)


def test_catalogue_rating_example_shigley_11_1():
    # Shigley, Mechanical Engineering Design, 9th ed., Example 11-1: 5000 h at 1725 rev/min
    # under 400 lbf needs a catalogue rating C10 = 400 (5000*1725*60/1e6)^(1/3) = 3211 lbf.
    C = 3211 * LBF
    life = B.rating_life_hours(B.rating_life_mrev(C, 400 * LBF, 3.0), 1725 * 60)
    assert life == pytest.approx(5000, rel=2e-3)
    assert B.required_equivalent_load(C, 5000, 1725 * 60, 3.0) == pytest.approx(400 * LBF, rel=2e-3)


def test_duty_equivalent_load_weights_by_revolutions():
    # Two steps: P1 = 2 kN for n1 = 300 rev, P2 = 1 kN for n2 = 900 rev (rates 30 and 90
    # rad/s*2pi over equal times).  P_eq = ((n1 P1^3 + n2 P2^3)/(n1 + n2))^(1/3) by hand.
    dt = np.full(200, 0.05)
    rate = np.r_[np.full(100, 2 * math.pi * 60.0), np.full(100, -2 * math.pi * 180.0)]
    P = np.r_[np.full(100, 2000.0), np.full(100, 1000.0)]
    n1, n2 = 60.0 * 5.0, 180.0 * 5.0
    ref = ((n1 * 2000.0**3 + n2 * 1000.0**3) / (n1 + n2)) ** (1 / 3)
    assert B.duty_equivalent_load(P, rate, dt, 3.0) == pytest.approx(ref, rel=1e-12)
    assert B.duty_equivalent_load(P, np.zeros(200), dt, 3.0) == 0.0


def test_static_safety_iso76_by_hand():
    # P0 = max(X0 Fr + Y0 Fa, Fr): (2000, 1000) -> max(1700, 2000) = 2000; (1000, 3000) -> 2100.
    P0 = B.static_equivalent_load([2000.0, 1000.0], [1000.0, -3000.0], 0.6, 0.5)
    assert P0 == pytest.approx([2000.0, 2100.0])
    assert B.static_safety(10_000.0, P0) == pytest.approx(10_000.0 / 2100.0)


def test_two_bearing_split_is_the_simply_supported_shaft():
    # A radial load W at z = a on a shaft on supports at z = 0 and z = L: the beam
    # reactions are W (L - a)/L and W a/L.  The joint reaction is that load moved to the
    # joint origin: F = W, M = r x W with r = (0, 0, a).
    L, a = 0.12, 0.03
    W = np.array([[300.0, -400.0, 50.0], [0.0, 1000.0, 0.0]])
    M = np.cross(np.array([0.0, 0.0, a]), W)
    R1, R2 = B.split_two_bearings(W, M, 0.0, L)
    assert R1 == pytest.approx(W[:, :2] * (L - a) / L)
    assert R2 == pytest.approx(W[:, :2] * a / L)
    # overhung load beyond the second support: the first reaction reverses (lever rule)
    R1, R2 = B.split_two_bearings(W, np.cross(np.array([0.0, 0.0, 0.2]), W), 0.0, L)
    assert R1 == pytest.approx(W[:, :2] * (L - 0.2) / L)
    assert R2 == pytest.approx(W[:, :2] * 0.2 / L)


def test_iso_factor_defaults_are_the_documented_ones():
    r = B.FACTOR_DEFAULTS["roller"]
    tan15 = math.tan(math.radians(15))
    assert r["e"] == pytest.approx(1.5 * tan15, abs=0.005) and r["Y"] == pytest.approx(0.4 / tan15, abs=0.005)
    assert B.LIFE_EXPONENT == {"ball": 3.0, "roller": pytest.approx(10 / 3)}


def test_lewis_example_shigley_14_1():
    # Shigley 9th ed., Example 14-1: 16 teeth (Y = 0.296), P = 8 teeth/in, F = 1.5 in,
    # Kv = 1.52 at 628 ft/min; allowable 10 kpsi gives Wt = F Y sigma / (Kv P) = 365 lbf.
    # Conversely 365 lbf gives sigma = Kv Wt P / (F Y) = 10 kpsi; metric module m = 1/P.
    Y = G.lewis_form_factor(16)
    assert Y == pytest.approx(0.296)
    sigma = G.lewis_bending_stress([365 * LBF, -365 * LBF], INCH / 8, 1.5 * INCH, Y, K=1.52)
    ref = 1.52 * 365 * 8 / (1.5 * 0.296) * PSI
    assert sigma == pytest.approx([ref, ref], rel=1e-12)
    assert sigma[0] == pytest.approx(10_000 * PSI, rel=2e-3)


def test_lewis_form_factor_interpolates_and_refuses_undercut_pinions():
    assert G.lewis_form_factor(23) == pytest.approx((0.331 + 0.337) / 2)
    assert 0.480 < G.lewis_form_factor(1000) < 0.485
    with pytest.raises(ValueError):
        G.lewis_form_factor(10)


def test_hertz_example_shigley_14_3():
    # Shigley 9th ed., Example 14-3: the 16-tooth pinion (d = 2 in) of Example 14-1 with a
    # 50-tooth gear (d = 6.25 in), Wt = 382 lbf, Kv = 1.52, F = 1.5 in, 20 deg, Cp = 1817
    # sqrt(psi) (steel on cast iron): sigma_C = Cp sqrt(Kv Wt / (F cos phi) (1/r1 + 1/r2)),
    # r = d sin(phi) / 2 (radii of curvature of the involutes at the pitch point) = 72.5 kpsi.
    phi = math.radians(20)
    r1, r2 = 2 * math.sin(phi) / 2, 6.25 * math.sin(phi) / 2
    ref_psi = 1817 * math.sqrt(1.52 * 382 / (1.5 * math.cos(phi)) * (1 / r1 + 1 / r2))
    assert ref_psi == pytest.approx(72_500, rel=2e-3)
    sigma = G.hertz_contact_stress(382 * LBF, 2 * INCH, 1.5 * INCH, 50 / 16, phi,
                                   ZE=1817 * math.sqrt(PSI), K=1.52)
    assert float(sigma) == pytest.approx(ref_psi * PSI, rel=1e-12)


def test_hertz_internal_pair_uses_the_difference_of_curvatures():
    # Internal pair: 1/r1 - 1/r2 replaces the sum (concave ring flank).
    phi, d1, d2, Ft, b = math.radians(20), 0.04, 0.12, 800.0, 0.01
    r1, r2 = d1 * math.sin(phi) / 2, d2 * math.sin(phi) / 2
    ZE = G.STEEL_ELASTIC_COEFFICIENT
    ref = ZE * math.sqrt(Ft / (b * math.cos(phi)) * (1 / r1 - 1 / r2))
    assert float(G.hertz_contact_stress(Ft, d1, b, 3.0, phi, internal=True)) == pytest.approx(ref, rel=1e-12)


def test_steel_elastic_coefficient_from_its_definition():
    # Z_E = sqrt(1 / (pi (2 (1 - nu^2) / E))) for two equal materials, E = 206 GPa, nu = 0.3.
    ref = math.sqrt(1 / (math.pi * 2 * (1 - 0.3**2) / 206e9))
    assert G.STEEL_ELASTIC_COEFFICIENT == pytest.approx(ref, rel=1e-3)


def test_motor_rms_of_a_sine_over_whole_periods():
    t = np.linspace(0, 3.0, 3001)                    # three periods of 1 s
    tau = 4.0 * np.sin(2 * math.pi * t) + 1.0        # RMS^2 = 1 + 16/2 by hand
    assert Mo.rms(tau, B.sample_weights(t)) == pytest.approx(3.0, rel=1e-9)
    assert Mo.mechanical_power([2.0, -2.0], [3.0, 3.0]) == pytest.approx([6.0, -6.0])
    assert B.sample_weights(t).sum() == pytest.approx(3.0)
