"""Plots of the duty-cycle checks that need more than one curve against one line: bearing
lives (every trajectory's equivalent load) and gear fatigue (the S-N curve with the counted
cycles).  Written by ``gearcli verify --plots`` (:mod:`gearcli.batch.verify`)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .plots import _pyplot, _save, check_output_path


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
