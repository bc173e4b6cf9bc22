"""Plots of the duty-cycle checks that need more than one curve against one line: bearing
lives (every trajectory's equivalent load) and gear fatigue (the S-N curve with the counted
cycles).  Written by ``gearcli verify --plots`` (:mod:`gearcli.batch.verify`)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .plots import _pyplot, _save, check_output_path
from .rms import trapezoid_weights


def plot_life(traces: list[tuple], P_eq: float, P_req: float, out: str | Path, title: str) -> None:
    """A bearing's dynamic equivalent load P along every trajectory of the profile, one after
    another, each with its own equivalent load (dotted), the profile's P_eq (solid) and the
    P_eq that just gives the required life (dashed red).

    ``traces``: (name, t (N,), P (N,), the trajectory's P_eq) per trajectory, s and N.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 3.4))
    t0 = 0.0
    for k, (name, t, P, peq) in enumerate(traces):
        tt = t - t[0] + t0
        line, = ax.plot(tt, P, lw=1.0, label=f"P, {name}")
        ax.hlines(peq, tt[0], tt[-1], colors=line.get_color(), linestyles=":", lw=1.4,
                  label=f"P_eq of {name}: {peq:.4g} N")
        t0 = tt[-1]
    ax.axhline(P_eq, color="black", lw=1.2, label=f"P_eq of the profile: {P_eq:.4g} N")
    if np.isfinite(P_req):
        ax.axhline(P_req, color="red", ls="--", lw=1.2, label=f"P_eq giving the required life: {P_req:.4g} N")
    ax.set_xlabel("t [s] (trajectories one after another)")
    ax.set_ylabel("dynamic equivalent load P [N]")
    ax.set_title(title, fontsize="medium")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="x-small", loc="best")
    fig.tight_layout()
    _save(fig, check_output_path(out))


def plot_sn(N: np.ndarray, S: np.ndarray, peaks: np.ndarray, cycles_in_life: float, out: str | Path,
            title: str, ylabel: str, passes: tuple | None = None) -> None:
    """An S-N curve (``S`` at ``N`` cycles) and the counted cycles over the required life:
    the rainflow cycles, largest first, against their cumulated number (``cycles_in_life``
    in all), and ``passes`` = (cumulated tooth passes, stress) when the pinion turns (only
    their points with passes and stress, which a log axis can show: a curve with none is left
    out, legend entry too); a spectrum crossing the curve fails Miner's sum long before the
    required life."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 3.4))
    ax.loglog(N, S, color="red", lw=1.2, label="allowable stress (S-N curve)")
    if passes is not None:          # a log axis has no place for 0 passes (a pinion at rest) or 0 stress
        shown = (np.asarray(passes[0]) > 0) & (np.asarray(passes[1]) > 0)
        if shown.any():
            ax.loglog(passes[0][shown], passes[1][shown], lw=1.2, marker="." if shown.sum() == 1 else None,
                      label="tooth passes, cumulated over the required life")
    peaks = peaks[peaks > 0]
    if peaks.size:
        order = np.sort(peaks)[::-1]
        n = np.arange(1, order.size + 1) * cycles_in_life / order.size
        ax.loglog(n, order, ".", ms=3, label="counted cycles, cumulated over the required life")
    ax.set_xlabel("cycles N")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize="medium")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize="small", loc="best")
    fig.tight_layout()
    _save(fig, check_output_path(out))


def plot_reducer_life(traces: list[tuple], T_av: float, T_req: float, life: float, required: float, basis: str,
                      rating, out: str | Path, title: str) -> None:
    """A reducer's life check (:mod:`gearcli.model.reducers`): above, |T| along every trajectory
    of the profile one after another with the duty's speed-weighted T_av (solid) and the T_av
    that just gives the required life (dashed red); below, the running life over the motion so
    far, L_n (n_N / n_av(t)) (T_N / T_av(t))^p from the sums up to t (pauses between cycles
    not counted), with the case's life (pauses counted) and the required one.

    ``traces``: (name, t (N,), |T| (N,), |a| (N,)) per trajectory, s, N*m, rad/s.
    """
    plt = _pyplot()
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7.5, 5.6), sharex=True)
    t0, num, den = 0.0, 0.0, 0.0
    p = rating.life_exponent
    for name, t, T, a in traces:
        tt = t - t[0] + t0
        ax.plot(tt, T, lw=1.0, label=f"|T|, {name}")
        w = trapezoid_weights(t)
        n_run, d_run = num + np.cumsum(a * T ** p * w), den + np.cumsum(a * w)
        elapsed = np.maximum(tt, 1e-300)
        with np.errstate(divide="ignore", invalid="ignore"):
            T_run = (n_run / d_run) ** (1.0 / p)
            L = rating.rated_life * (rating.rated_input_speed / (d_run / elapsed)) * (rating.rated_torque / T_run) ** p
        L = np.where(np.isfinite(L) & (L > 0), L, np.nan)
        bx.plot(tt, L, lw=1.0, label=f"running {basis} life, {name}")
        num, den, t0 = n_run[-1], d_run[-1], tt[-1]
    ax.axhline(T_av, color="black", lw=1.2, label=f"T_av of the duty: {T_av:.4g} N·m")
    if np.isfinite(T_req):
        ax.axhline(T_req, color="red", ls="--", lw=1.2, label=f"T_av giving the required life: {T_req:.4g} N·m")
    ax.set_ylabel("|output torque T| [N·m]")
    ax.set_title(title, fontsize="medium")
    bx.axhline(required, color="red", ls="--", lw=1.2, label=f"required: {required:.4g} h")
    if np.isfinite(life):
        bx.axhline(life, color="black", lw=1.2, label=f"{basis} life of the duty (pauses counted): {life:.4g} h")
    bx.set_yscale("log")
    bx.set_xlabel("t [s] (trajectories one after another)")
    bx.set_ylabel(f"{basis} life [h]")
    for a_ in (ax, bx):
        a_.grid(alpha=0.3)
        a_.legend(fontsize="x-small", loc="best")
    fig.tight_layout()
    _save(fig, check_output_path(out))
