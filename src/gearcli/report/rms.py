"""Time-weighted RMS: the one definition used by ``solve``'s summary (:mod:`.columns`), ``verify``
(:mod:`gearcli.design.evaluate`) and its plots.

The RMS of a signal x(t) sampled at times t_0 < ... < t_{N-1} (s, any spacing) is

    RMS = sqrt( integral of x^2 dt / (t_{N-1} - t_0) ),

the integral by the trapezoid rule, sum_k (x_k^2 + x_{k+1}^2) / 2 (t_{k+1} - t_k).  On a
uniform grid it is not the plain mean of the squares: the two end samples weigh half a step.
A single sample (no time span) has RMS |x|.  Over several trajectories (a duty cycle) the
integrals and the spans add: sqrt(sum of integrals / sum of spans).

The running RMS over a thermal window W (s) at time t is sqrt(integral of x^2 over
[t - W, t] / W): the motor is taken as idle (x = 0) before the trajectory starts; the
integral at t - W is interpolated linearly in the cumulative trapezoid integral.  Its peak
is the continuous-duty (thermal) load of a motor whose thermal time constant is about W
(servo sizing practice, e.g. Hughes & Drury, *Electric Motors and Drives*, 5th ed., sec. 12.4).
"""
from __future__ import annotations

import math

import numpy as np


def trapezoid_weights(t) -> np.ndarray:
    """Time weight w_k of each sample (s) with sum_k w_k x_k = the trapezoid integral of x.

    w_k = (t_{k+1} - t_{k-1}) / 2 inside, half a step at the two ends; sums to t_{N-1} - t_0.
    A single sample gets weight 0.
    """
    t = np.asarray(t, float)
    if t.size < 2:
        return np.zeros_like(t)
    d = np.diff(t)
    w = np.empty_like(t)
    w[0], w[-1] = d[0] / 2, d[-1] / 2
    w[1:-1] = (d[:-1] + d[1:]) / 2
    return w


def square_integral(x, t) -> np.ndarray | float:
    """Trapezoid integral of x^2 over t: x of shape (N,) gives a float, (N, k) one per column."""
    x, t = np.asarray(x, float), np.asarray(t, float)
    if t.size < 2:
        return 0.0 if x.ndim == 1 else np.zeros(x.shape[1:])
    x2 = x * x
    d = np.diff(t)
    # einsum, not d @ ...: a BLAS call per column costs more than the sum (threads, start-up)
    return 0.5 * np.einsum("i,i...->...", d, x2[:-1] + x2[1:])


def rms_of(integral: float, span: float, fallback: float = math.nan) -> float:
    """sqrt(integral / span); ``fallback`` (the RMS of samples at one instant) when span = 0."""
    return math.sqrt(integral / span) if span > 0 else fallback


def rms(x, t) -> float:
    """Time-weighted RMS of one trajectory (trapezoid rule, definition above); nan if empty."""
    x, t = np.asarray(x, float), np.asarray(t, float)
    if x.size == 0:
        return math.nan
    return rms_of(float(square_integral(x, t)), float(t[-1] - t[0]), float(np.sqrt(np.mean(x * x))))


def running_rms(x, t, window: float) -> np.ndarray:
    """RMS over the last ``window`` seconds at every sample, (N,) (definition above)."""
    x, t = np.asarray(x, float), np.asarray(t, float)
    if t.size < 2:
        return np.abs(x) * 0.0
    x2 = x * x
    cum = np.concatenate(([0.0], np.cumsum(np.diff(t) * (x2[:-1] + x2[1:]) * 0.5)))
    start = np.interp(t - window, t, cum, left=0.0)
    return np.sqrt(np.maximum(cum - start, 0.0) / window)


def cumulative_rms(x, t) -> np.ndarray:
    """RMS from the start to every sample, (N,): sqrt(integral of x^2 over [t_0, t] / (t - t_0))
    (|x_0| at the first sample); its last value is :func:`rms`."""
    x, t = np.asarray(x, float), np.asarray(t, float)
    if t.size < 2:
        return np.abs(x)
    x2 = x * x
    cum = np.concatenate(([0.0], np.cumsum(np.diff(t) * (x2[:-1] + x2[1:]) * 0.5)))
    span = t - t[0]
    out = np.abs(x).copy()
    out[1:] = np.sqrt(cum[1:] / np.where(span[1:] > 0, span[1:], 1.0))
    return out
