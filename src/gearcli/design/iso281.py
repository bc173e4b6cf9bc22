"""ISO 281 load factors and life modification: the e/Y table of deep-groove ball bearings,
the rolling-element types, and a_ISO.

Arrays of samples have shape (N,); forces in N.

Sources
-------
* ISO 281:2007, Table 3 (radial ball bearings, single-row deep-groove, normal clearance):
  for Fa/Fr > e, X = 0.56 and Y, e depend on f0 Fa / C0 (f0 the bearing's geometry factor,
  about 12 to 17, printed in catalogues); the rows are :data:`BALL_F0_FA_C0`,
  :data:`BALL_E`, :data:`BALL_Y`.  ISO 281 allows linear interpolation between rows.
  Outside the tabulated range the end rows are held (no extrapolation).
* Catalogues that do not print f0 give the same rows against Fa/C0 (the f0 of a typical
  deep-groove bearing, about 12.3, folded in), with three intermediate rows; this is the
  table of Shigley's *Mechanical Engineering Design* (Budynas & Nisbett), Table 11-1:
  :data:`CATALOGUE_FA_C0`, :data:`CATALOGUE_E`, :data:`CATALOGUE_Y`.  It is used when a
  ball bearing gives no ``f0``.
* Rolling-element types (:data:`gearcli.model.ratings.BEARING_FACTOR_DEFAULTS`): life exponent p = 3
  for ball, 10/3 for roller bearings (ISO 281 §7.2); a cylindrical roller bearing
  (contact angle 0) carries no axial load, P = Fr (ISO 281 §7.3.2); a single-row tapered
  roller bearing of contact angle a has e = 1.5 tan a, X = 0.4, Y = 0.4 cot a (ISO 281
  Table 4).
* Life modification factor a_ISO (ISO 281:2007 §9.3, Eqs. (15)-(22), radial bearings):
  with x = e_C C_u / P (e_C contamination factor, C_u fatigue load limit, P the dynamic
  equivalent load) and kappa the viscosity ratio (clipped to 4 above 4),

    ball:   a_ISO = 0.1 [1 - (2.5671 - A/kappa^b)^0.83 x^(1/3)]^(-9.3)
    roller: a_ISO = 0.1 [1 - (1.5859 - A/kappa^b) x^0.4]^(-9.185)

  with (A, b) = (2.2649, 0.054381) for ball / (1.3993, 0.054381) for roller when
  0.1 <= kappa < 0.4; (1.9987, 0.19087) / (1.2348, 0.19087) when 0.4 <= kappa < 1;
  (1.9987, 0.071739) / (1.2348, 0.071739) when 1 <= kappa <= 4; a_ISO is limited to 50.
  Under a varying load a_ISO is taken per sample and the lives are combined by the
  Palmgren-Miner rule (ISO 281 §9.3.3 for variable operating conditions): each revolution
  at P_k uses up (P_k / C)^p / a_ISO(P_k) of a million-revolution life.

Checked against independent published copies (issue 21; the standard itself is not public):

* Table 3 rows, e, Y and X = 0.56: the same nine rows in several public bearing
  calculators (one quoting "ISO 281 Table 3, alpha = 0", one "SKF catalogue table 9,
  deep groove ball, Normal clearance"); P = Fr for Fa/Fr <= e, P0 = max(0.6 Fr + 0.5 Fa,
  Fr): SKF, https://www.skf.com/sg/products/bearings-units-housings/ball-bearings/deep-groove-ball-bearings/loads/index.html.
  (The C3-clearance column of the same catalogue table, e 0.29 ... 0.54, X 0.46, also in
  public code, is not this one.)
* Catalogue column: its nine anchor rows 0.014 ... 0.56 are the Table 3 rows divided by
  f0 = 12.3 (public copies of Shigley Table 11-1 / Mott Table 14-5 carry them); the three
  rows 0.021, 0.042, 0.070 are the midpoints (e 0.21, 0.24, 0.27; Y 2.15, 1.85, 1.63), as
  in a public copy of the 12-row Shigley table (e column) and of Mott's (Y 1.63 at 0.070).
* a_ISO, ball: 2.5671, (2.2649, 0.054381), (1.9987, 0.19087), (1.9987, 0.071739), 0.83,
  1/3, -9.3, the cap 50 and kappa in 0.1 ... 4 (clipped above 4) as ISO 281:2007 Eqs.
  (31)-(33) are quoted in an independent public ISO 281/16281 implementation.  Roller: the
  same source lists 1.5859, 1.3993, 1.2348 and the exponents 0.4 and -9.185 (Eqs.
  (34)-(36)); no public copy of the whole roller expression was found.  A public Python
  copy writes 0.019087 for the middle ball row: a typo (the rows then no longer meet at
  kappa = 0.4, which tests/test_design_formulas.py checks).
* Tapered roller e = 1.5 tan a and Y = 0.4 cot a: the same in public bearing calculators
  (e 0.54 ... 1.5, Y 1.1 ... 0.4 for a = 20 ... 45 deg).
"""
from __future__ import annotations

import math

import numpy as np

from . import magnitudes

BALL_F0_FA_C0 = (0.172, 0.345, 0.689, 1.03, 1.38, 2.07, 3.45, 5.17, 6.89)
BALL_E = (0.19, 0.22, 0.26, 0.28, 0.30, 0.34, 0.38, 0.42, 0.44)
BALL_Y = (2.30, 1.99, 1.71, 1.55, 1.45, 1.31, 1.15, 1.04, 1.00)
BALL_X = 0.56
"""ISO 281:2007 Table 3, single-row deep-groove ball bearings, normal clearance."""

CATALOGUE_FA_C0 = (0.014, 0.021, 0.028, 0.042, 0.056, 0.070, 0.084, 0.110, 0.17, 0.28, 0.42, 0.56)
CATALOGUE_E = (0.19, 0.21, 0.22, 0.24, 0.26, 0.27, 0.28, 0.30, 0.34, 0.38, 0.42, 0.44)
CATALOGUE_Y = (2.30, 2.15, 1.99, 1.85, 1.71, 1.63, 1.55, 1.45, 1.31, 1.15, 1.04, 1.00)
"""The same factors against Fa/C0 (catalogues without f0; Shigley Table 11-1)."""

A_ISO_MAX = 50.0
KAPPA_RANGE = (0.1, 4.0)
"""kappa below 0.1 is outside ISO 281's method (an error); above 4 it counts as 4."""

_A_ISO = {  # type -> (c, exponent of the bracket's x, outer exponent, power of the parenthesis, rows)
    "ball": (2.5671, 1.0 / 3.0, -9.3, 0.83, ((0.4, 2.2649, 0.054381), (1.0, 1.9987, 0.19087),
                                             (math.inf, 1.9987, 0.071739))),
    "roller": (1.5859, 0.4, -9.185, 1.0, ((0.4, 1.3993, 0.054381), (1.0, 1.2348, 0.19087),
                                          (math.inf, 1.2348, 0.071739))),
}


def ball_factors(Fa, C0: float, f0: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """e and Y of a deep-groove ball bearing at each sample's axial load (ISO 281 Table 3).

    Parameters
    ----------
    Fa : array_like, shape (N,)
        Axial load, N (sign ignored).
    C0 : float
        Basic static load rating, N.
    f0 : float or None
        The bearing's factor f0: the table is entered at f0 Fa / C0.  None: the
        catalogue column Fa / C0 (:data:`CATALOGUE_FA_C0`).

    Returns
    -------
    e, Y : ndarray, shape (N,)
        Linear interpolation between the tabulated rows, the end rows held outside them.
    """
    x = magnitudes(Fa)
    if f0 is None:
        x /= C0
        return np.interp(x, CATALOGUE_FA_C0, CATALOGUE_E), np.interp(x, CATALOGUE_FA_C0, CATALOGUE_Y)
    x *= f0                   # f0 Fa / C0, in place
    x /= C0
    return np.interp(x, BALL_F0_FA_C0, BALL_E), np.interp(x, BALL_F0_FA_C0, BALL_Y)


def dynamic_equivalent_load(Fr, Fa, X, Y, e) -> np.ndarray:
    """ISO 281 dynamic equivalent radial load of each sample, N.

    P = Fr when Fa <= e Fr, else X Fr + Y Fa (with Fr = 0 and Fa > 0: P = Y Fa).  ``X``,
    ``Y``, ``e`` are floats or arrays of shape (N,) (per-sample table factors).
    """
    Fr, Fa = magnitudes(Fr, Fa, X, Y, e), magnitudes(Fa, Fr, X, Y, e)
    low = Fa <= e * Fr
    P = np.multiply(X, Fr, out=np.empty_like(Fr))
    Fa *= Y                   # (in place)
    P += Fa
    np.copyto(P, Fr, where=low)
    return P


def bearing_equivalent_load(b, Fr, Fa) -> np.ndarray:
    """P of bearing rating ``b`` (:class:`gearcli.model.ratings.BearingRating`) per sample.

    A factor the rating gives (``X``, ``Y``, ``e``) is used as given; a ball bearing's
    missing ones come from ISO 281 Table 3 at each sample (:func:`ball_factors`, X = 0.56).
    Without axial load at any sample (a non-locating bearing) Fa <= e Fr holds everywhere,
    so P = Fr without the table (the same values for finite loads).
    """
    if not np.any(Fa):
        return np.abs(np.asarray(Fr, float))
    X, Y, e = b.X, b.Y, b.e
    if None in (X, Y, e):
        e_t, Y_t = ball_factors(Fa, b.C0, b.f0)
        X = BALL_X if X is None else X
        Y = Y_t if Y is None else Y
        e = e_t if e is None else e
    return dynamic_equivalent_load(Fr, Fa, X, Y, e)


def crossed_roller_load(Fr, Fa, M, d_p: float) -> np.ndarray:
    """Dynamic equivalent radial load P_c of a crossed-roller bearing, N (catalogue: THK
    "Cross-Roller Ring", IKO "Crossed Roller Bearings"; ``../shared/drive-elements.md`` A):
    its tilting moment M (N*m) acts as a radial load 2 M/d_p on the rollers of pitch
    diameter d_p (m), F = F_r + 2 M/d_p, and P_c = x F + y F_a with x = 1, y = 0.45 while
    F_a/F <= 1.5, else x = y = 0.67 (a pure axial load, F = 0: the second branch)."""
    Fr, Fa, M = (np.abs(np.asarray(v, float)) for v in (Fr, Fa, M))
    F = Fr + 2.0 * M / d_p
    low = Fa <= 1.5 * F
    return np.where(low, F + 0.45 * Fa, 0.67 * (F + Fa))


def crossed_roller_static_load(Fr, Fa, M, d_p: float) -> np.ndarray:
    """Static equivalent radial load of a crossed-roller bearing, N: F_r + 2 M/d_p + 0.44 F_a
    (THK, "Cross-Roller Ring": static equivalent radial load)."""
    Fr, Fa, M = (np.abs(np.asarray(v, float)) for v in (Fr, Fa, M))
    return Fr + 2.0 * M / d_p + 0.44 * Fa


def life_exponent(kind: str) -> float:
    """p of L10 = (C/P)^p: 3 for ball bearings, 10/3 for every roller type."""
    return 3.0 if kind == "ball" else 10.0 / 3.0


def a_iso(P, kind: str, kappa: float, e_C: float, Cu: float) -> np.ndarray:
    """ISO 281 life modification factor a_ISO at each sample's load P (formulas above).

    Parameters
    ----------
    P : array_like, shape (N,)
        Dynamic equivalent load, N (P = 0 gives a_ISO = 50: no fatigue).
    kind : str
        ``"ball"`` or a roller type (any type but ball uses the roller formulas).
    kappa : float
        Viscosity ratio nu / nu1, 0.1 <= kappa (clipped to 4).
    e_C : float
        Contamination factor, 0 < e_C <= 1.
    Cu : float
        Fatigue load limit, N.
    """
    if not kappa >= KAPPA_RANGE[0]:
        raise ValueError(f"kappa {kappa:g} is below {KAPPA_RANGE[0]:g}, outside ISO 281's method")
    kappa = min(kappa, KAPPA_RANGE[1])
    c, xe, outer, power, rows = _A_ISO["ball" if kind == "ball" else "roller"]
    A, b = next((A, b) for upper, A, b in rows if kappa < upper)
    P = np.abs(np.asarray(P, float))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        x = np.where(P > 0, e_C * Cu / np.where(P > 0, P, 1.0), math.inf)
        inner = 1.0 - (c - A / kappa ** b) ** power * x ** xe
        a = np.where(inner > 0, 0.1 * np.where(inner > 0, inner, 1.0) ** outer, A_ISO_MAX)
    return np.minimum(a, A_ISO_MAX)


def life_factor(b, P) -> np.ndarray | float:
    """The a_ISO of bearing rating ``b`` at loads P: its ``a_ISO`` when given, computed
    from ``kappa``, ``e_C`` and ``Cu`` when those are given, else 1 (basic rating life)."""
    if b.a_ISO is not None:
        return b.a_ISO
    if b.kappa is not None:
        return a_iso(P, b.type, b.kappa, b.e_C, b.Cu)
    return 1.0
