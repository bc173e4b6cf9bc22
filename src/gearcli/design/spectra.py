"""Load spectra (load duration distributions): time and revolutions at each load level.

The table gear and bearing vendors ask for: for a load x(t) (torque, force or equivalent
load, SI units) and the rotation rate w(t) (rad/s) of the part carrying it, the seconds
spent and the revolutions turned with |x| in each bin [edge_b, edge_b+1), over the duty.
Times are the trapezoid weights of the samples (:func:`gearcli.report.rms.trapezoid_weights`),
revolutions |w| times them / 2 pi, so the spectra sum to the duration and the revolutions
that the RMS and the bearing lives use.
"""
from __future__ import annotations

import math

import numpy as np

from ..report.rms import trapezoid_weights

SPECTRUM_BINS = 20
"""Bins between 0 and the largest |x| of the duty."""


def bin_edges(peak: float, bins: int = SPECTRUM_BINS) -> np.ndarray:
    """``bins`` + 1 equal bins from 0 to ``peak`` (to 1 when the load is 0 throughout)."""
    return np.linspace(0.0, peak if peak > 0 else 1.0, bins + 1)


def load_spectrum(x, t, rate, edges) -> tuple[np.ndarray, np.ndarray]:
    """Seconds and revolutions with |x| in each bin of ``edges`` (the last bin closed).

    Parameters
    ----------
    x, t : array_like, shape (N,)
        Load and times, s.
    rate : array_like, shape (N,), or None
        Rotation rate of the loaded part, rad/s (None: no revolutions, zeros).
    edges : array_like, shape (B + 1,)
        Bin edges, ascending.

    Returns
    -------
    seconds, revolutions : ndarray, shape (B,)
    """
    w = trapezoid_weights(t)
    nb = len(edges) - 1
    k = np.clip(np.searchsorted(edges, np.abs(np.asarray(x, float)), side="right") - 1, 0, nb - 1)
    seconds = np.bincount(k, weights=w, minlength=nb)
    if rate is None:
        return seconds, np.zeros(nb)
    return seconds, np.bincount(k, weights=np.abs(np.asarray(rate, float)) * w / (2 * math.pi), minlength=nb)
