"""Evaluate design checks: signals along one trajectory, partial sums, the duty-cycle verdict.

The work is split so that it can run anywhere: :func:`partials` reduces one trajectory to a
few numbers per check (picklable, small), and :func:`combine` merges the partials of every
trajectory of a case, always in the case's trajectory order, so the verdict is the same
whichever process or machine evaluated each trajectory.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import bearings as B
from . import fatigue as F
from . import iso281
from . import sizing
from .checks import Check
from ..report.rms import running_rms, rms_of, square_integral, trapezoid_weights
from .gears import hertz_contact_stress, lewis_bending_stress
from ..model.reducers import reducer_life
from ..model.screws import screw_life_hours
from ..model.shaft import split_components


@dataclass(frozen=True)
class Samples:
    """One solved trajectory: times ``t`` (N,), output columns by name (each (N,)), and the
    rates of every real joint ``rates`` (N, J), rad/s."""

    t: np.ndarray
    cols: dict
    rates: np.ndarray
    backend: str = ""     # the solver path that ran: "llvm", or "numpy (auto: why)" (gearcli.batch)
    merged: dict | None = None   # {check index: its partials}, merged from a long trajectory's parts


def bearing_loads(s: Samples, joint: str, bearings) -> list[tuple[np.ndarray, np.ndarray]]:
    """Radial and axial load (N) on each bearing of a joint, per sample.

    One bearing takes the whole reaction force; two share its force and tilting moment as
    a shaft on two supports (:func:`gearcli.model.shaft.split_components`), the
    locating one taking the axial force.
    """
    c = s.cols
    axial = np.abs(c[f"joint:{joint}:fz"])
    none = np.zeros_like(s.t)
    if len(bearings) == 1:
        return [(c[f"joint:{joint}:radial"], axial)]
    R1x, R1y, R2x, R2y = split_components(*(c[f"joint:{joint}:{k}"] for k in ("fx", "fy", "mx", "my")),
                                          bearings[0].position, bearings[1].position)
    # |(x, y)| as sqrt(x^2 + y^2): np.hypot's care for overflow costs 3-7x, and a load squared is far from it
    return [(_norm(x, y), axial if b.locating else none) for x, y, b in ((R1x, R1y, bearings[0]), (R2x, R2y, bearings[1]))]


def _norm(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """sqrt(x^2 + y^2) per sample, in one new array."""
    r = x * x
    r += y * y
    return np.sqrt(r, out=r)


def signal(check: Check, s: Samples, mech, cache: dict | None = None) -> np.ndarray:
    """The check's quantity at every sample, (N,), in ``check.signal_unit``; ``cache`` (one
    per trajectory) keeps signals and bearing loads that several checks share."""
    if cache is None:
        cache = {}
    key = (check.signal, check.extra.get("K"))
    if key not in cache:
        cache[key] = _signal(check, s, mech, cache)
    return cache[key]


def _signal(check: Check, s: Samples, mech, cache: dict) -> np.ndarray:
    kind = check.signal[0]
    if kind == "abs":
        return np.abs(s.cols[check.signal[1]])
    if kind == "col":
        return s.cols[check.signal[1]]
    if kind == "rate":
        return np.abs(s.rates[:, check.signal[1]])
    if kind == "running_rms":
        return running_rms(s.cols[check.signal[1]], s.t, check.signal[2])
    if kind == "reducer_speed":         # |a|: the input's rate relative to the housing
        return np.abs(s.rates @ np.asarray(check.extra["row"]))
    if kind in sizing.SIGNALS:
        return sizing.signal(check, s.cols)
    if kind == "worm_efficiency":       # 1 - loss / power in; NaN where no power flows (a gap in plots)
        P_in, loss = worm_powers(check, s)
        out = np.full(P_in.shape, np.nan)
        flows = P_in > 0.0
        out[flows] = 1.0 - loss[flows] / P_in[flows]
        return out
    if kind in ("bearing_P", "bearing_P0"):
        jt = mech.joints[check.signal[1]]
        b = jt.bearings[check.signal[2]]
        if ("loads", jt.name) not in cache:        # one joint's at a time: its bearings' checks follow each other
            for k in [k for k in cache if k[0] == "loads"]:
                del cache[k]
            cache[("loads", jt.name)] = bearing_loads(s, jt.name, jt.bearings)
        Fr, Fa = cache[("loads", jt.name)][check.signal[2]]
        if b.type == "crossed_roller":           # its only bearing: the joint's tilting moment too,
            c, z = s.cols, b.position            # about the bearing's centre, z along the axis:
            M = np.hypot(c[f"joint:{jt.name}:mx"] + z * c[f"joint:{jt.name}:fy"],    # M_O - z e_z x F
                         c[f"joint:{jt.name}:my"] - z * c[f"joint:{jt.name}:fx"])
            return (iso281.crossed_roller_load if kind == "bearing_P" else iso281.crossed_roller_static_load)(
                Fr, Fa, M, b.pitch_diameter)
        if kind == "bearing_P":
            return iso281.bearing_equivalent_load(b, Fr, Fa)
        return B.static_equivalent_load(Fr, Fa, b.X0, b.Y0)
    x, ft = check.extra, s.cols[f"gear:{check.signal[1]}:t"]
    if kind == "bending":
        return lewis_bending_stress(ft, x["module"], x["b"], x["Y"], x["K"])
    if kind == "contact":
        return hertz_contact_stress(ft, x["d1"], x["b"], x["u"], x["alpha"], x["ZE"], x["K"], x["internal"],
                                    x.get("beta", 0.0))
    raise ValueError(f"unknown signal {check.signal!r}")


def worm_powers(check: Check, s: Samples) -> tuple[np.ndarray, np.ndarray]:
    """(P_in, loss), W, of a worm pair at each sample: the power its two members put into the
    mesh, relative to the carrier, and the power it dissipates (``gear:<w>:loss``).

    The flank load delivers P_G = r2 t w_G to the wheel (t = ``gear:<w>:t``, its moment r2 t
    about the wheel's axis; w_G = w_W / e, w_W the worm's rate relative to the carrier from
    ``extra["row"]``) and the worm puts in P_W = P_G + loss, so P_in = max(P_W, 0) +
    max(-P_G, 0): P_W when the worm drives (efficiency P_G / P_W = eta_f), -P_G when the
    wheel drives and the worm receives power (1 - loss / P_in = eta_b), and loss itself when
    the wheel pushes a self-locking worm that the motor also pushes (efficiency 0)."""
    x, name = check.extra, check.signal[1]
    w_G = (s.rates @ np.asarray(x["row"])) / x["ratio"]
    P_G = x["r2"] * s.cols[f"gear:{name}:t"] * w_G
    loss = s.cols[f"gear:{name}:loss"]
    return np.maximum(P_G + loss, 0.0) + np.maximum(-P_G, 0.0), loss


def bearing_of(check: Check, mech):
    """The :class:`~gearcli.model.ratings.BearingRating` of a life check."""
    return mech.joints[check.signal[1]].bearings[check.signal[2]]


def partials(checks: list[Check], s: Samples, mech) -> list[tuple]:
    """Per check, the trajectory's (peak, t at peak, sum, weight sum, revolutions, score, span,
    counts).

    ``sum``/``weight`` are the trapezoid integral of x^2 and the time span (rms,
    :mod:`gearcli.report.rms`), or the Palmgren-Miner sum n_k P_k^p / a_ISO and the
    revolutions (life, :func:`gearcli.design.bearings.life_sum`); ``score`` ranks
    trajectories for "worst trajectory" (peak, RMS or equivalent load); ``counts`` (gear
    fatigue only, else None) the cycles the damage was computed from, per repetition: the
    rainflow cycles as ((stress, number), ...) by stress (Pa) and the tooth passes.
    """
    out: list = [None] * len(checks)
    for i, merged in (s.merged or {}).items():       # a long trajectory's, part by part
        out[i] = merged
    span = float(s.t[-1] - s.t[0]) if s.t.size else 0.0
    cache: dict = {}
    component = None
    # one component's checks after another, its signals (stresses, equivalent loads) dropped
    # when the next begins: a long trajectory holds a few (N,) arrays, not every check's; the
    # revolutions of each joint and the last joint's bearing loads (its other bearings' checks
    # follow) are kept
    for i, ch in sorted(enumerate(checks), key=lambda ic: ic[1].component):
        if out[i] is not None:
            continue
        if ch.component != component:
            cache = {k: v for k, v in cache.items() if k[0] in ("revs", "loads")}
            component = ch.component
        total = wsum = revs = 0.0
        counts = None
        if ch.kind == "worm_efficiency":   # energies lost and put in; the least efficiency and its time
            P_in, loss = worm_powers(ch, s)
            total, wsum = sizing.cycle_integral(loss, s.t), sizing.cycle_integral(P_in, s.t)
            x = signal(ch, s, mech, cache)
            k = int(np.nanargmin(x)) if np.any(P_in > 0.0) else 0
            peak, tp = (float(x[k]), float(s.t[k])) if x.size and P_in[k] > 0.0 else (math.inf, math.nan)
            out[i] = (peak, tp, total, wsum, revs, total / wsum if wsum > 0.0 else 0.0, span, counts)
            continue
        x = signal(ch, s, mech, cache)
        k = _peak_index(cache, ch, x)
        peak, tp = (float(np.abs(x[k])), float(s.t[k])) if x.size else (0.0, math.nan)
        score = peak
        if ch.kind == "rms":
            total, wsum = float(square_integral(x, s.t)), span
            score = rms_of(total, wsum, peak)
        elif ch.kind == "energy":          # per trajectory (cycle): the integral, not a sample
            peak = score = sizing.cycle_integral(x, s.t)
        elif ch.kind == "life":
            n = _revolutions(cache, s, ch.signal[1])
            total = B.life_sum(x, n, ch.exponent, iso281.life_factor(bearing_of(ch, mech), x))
            wsum = revs = float(np.sum(n))
            score = B.equivalent_load(total, wsum, ch.exponent)
        elif ch.kind in REDUCER_KINDS:
            total, wsum, revs = _reducer_sums(ch, s, x, _weights(cache, s))
            score = total
        elif ch.kind == "fatigue":
            peaks = F.rainflow_peaks(x)
            total = F.miner_damage(peaks, ch.rating, ch.signal[0])
            revs = passes = float(len(peaks))
            if ch.extra.get("passes") is not None:       # each pinion tooth: one cycle per revolution
                ji, factor = ch.extra["passes"]
                n = _revolutions(cache, s, ji) * factor
                total += F.pass_damage(x, n, ch.rating, ch.signal[0])
                revs += float(np.sum(n))
            score = total
            levels, number = np.unique(peaks, return_counts=True)
            counts = (tuple(zip(levels.tolist(), number.tolist())), revs - passes)
        out[i] = (peak, tp, total, wsum, revs, score, span, counts)
    return out


def mergeable(check: Check) -> bool:
    """True when a check's partials over consecutive parts of one trajectory merge into the
    whole trajectory's (:func:`merge_partials`): extremes and trapezoid sums.  Not a gear's
    fatigue (rainflow pairs reversals across the parts), a running RMS over a time window
    (a window spans parts) or a cycle's energy (its time is that of the largest |x|)."""
    return check.kind not in ("fatigue", "energy") and check.signal[0] != "running_rms"


def merge_partials(check: Check, parts: list[tuple]) -> tuple:
    """The :func:`partials` tuple of a whole trajectory from those of its consecutive parts,
    each part starting at the sample the one before ended on (so that the trapezoid weights
    of the parts add up to the whole's: the shared sample's two halves).  Peaks are the
    largest (the earliest on a tie; a worm's least efficiency, the smallest), sums, weights,
    revolutions and spans add, and the score follows from them as in :func:`partials`.
    Equal to the whole trajectory's partials to rounding (the sums' order differs)."""
    nan = [k for k, p in enumerate(parts) if p[0] != p[0]]        # the whole's argmax finds a NaN first
    if nan:
        best = nan[0]
    elif check.kind == "worm_efficiency":
        best = min(range(len(parts)), key=lambda k: (parts[k][0], k))
    else:
        best = max(range(len(parts)), key=lambda k: (parts[k][0], -k))
    peak, tp = parts[best][0], parts[best][1]
    total, wsum, revs, span = (sum(p[j] for p in parts) for j in (2, 3, 4, 6))
    score = peak
    if check.kind == "rms":
        score = rms_of(total, wsum, peak)
    elif check.kind == "life":
        score = B.equivalent_load(total, wsum, check.exponent)
    elif check.kind in REDUCER_KINDS:
        score = total
    elif check.kind == "worm_efficiency":
        score = total / wsum if wsum > 0.0 else 0.0
    return (peak, tp, total, wsum, revs, score, span, None)


REDUCER_KINDS = ("reducer_average", "reducer_speed_average", "reducer_life", "screw_life")
"""Checks reduced by speed-weighted means over the duty cycle (:func:`_reducer_sums`)."""


def _reducer_sums(ch: Check, s: Samples, x: np.ndarray, dt: np.ndarray) -> tuple[float, float, float]:
    """A reducer check's sums over one trajectory (trapezoid weights ``dt``): T_av and the life,
    (sum |a| |T|^p dt, sum |a| dt, span); n_av, (sum |a| dt, span, span)."""
    a = np.abs(s.rates @ np.asarray(ch.extra["row"]))
    span = float(s.t[-1] - s.t[0]) if s.t.size else 0.0
    turned = float(np.sum(a * dt))
    if ch.kind == "reducer_speed_average":
        return turned, span, span
    return float(np.sum(a * x ** ch.exponent * dt)), turned, span


def reducer_duty(check: Check, parts: list[tuple], rates) -> tuple[float, float]:
    """(T_av N*m, n_av rad/s) of a reducer over the duty cycle: T_av from the trajectories' sums
    weighted by their repetitions per hour; n_av = the input's turning per hour / 3600 s when
    the repetitions are known (the cycle's pauses count), else per second of the trajectories."""
    w = [1.0 if r is None else r for r in rates]
    known = all(r is not None for r in rates)
    if check.kind == "reducer_speed_average":
        turned = sum(r * p[2] for r, p in zip(w, parts))
        return math.nan, turned / (3600.0 if known else max(sum(p[3] for p in parts), 1e-300))
    num, den = sum(r * p[2] for r, p in zip(w, parts)), sum(r * p[3] for r, p in zip(w, parts))
    T_av = (num / den) ** (1.0 / check.exponent) if den > 0 else 0.0
    n_av = den / (3600.0 if known else max(sum(p[6] for p in parts), 1e-300))
    return T_av, n_av


NON_NEGATIVE = frozenset({"reducer_speed", "abs", "rate", "running_rms", "bearing_P", "bearing_P0", "bending", "contact"})
"""Signals that are never negative by construction: their largest |x| is their largest x."""


def _peak_index(cache: dict, check: Check, x: np.ndarray) -> int:
    """Index of the first largest |x| (0 when empty), once per signal (a gear's stress feeds
    its safety and its fatigue check); a :data:`NON_NEGATIVE` signal is searched without
    taking |x| (the same index: -0.0 equals 0.0, a NaN is found first either way)."""
    key = ("peak", check.signal, check.extra.get("K"))
    if key not in cache:
        if not x.size:
            cache[key] = 0
        else:
            cache[key] = int(np.argmax(x if check.signal[0] in NON_NEGATIVE else np.abs(x)))
    return cache[key]


def _revolutions(cache: dict, s: Samples, ji: int) -> np.ndarray:
    """Revolutions of joint ``ji`` at each sample (:func:`gearcli.design.bearings.revolutions`),
    once per trajectory."""
    if ("revs", ji) not in cache:
        cache[("revs", ji)] = B.revolutions(s.rates[:, ji], s.t, _weights(cache, s))
    return cache[("revs", ji)]


def _weights(cache: dict, s: Samples) -> np.ndarray:
    """The trapezoid weights of the trajectory's times (:func:`~gearcli.report.rms.trapezoid_weights`),
    once per trajectory."""
    if ("revs", "weights") not in cache:
        cache[("revs", "weights")] = trapezoid_weights(s.t)
    return cache[("revs", "weights")]


@dataclass(frozen=True)
class Verdict:
    """The outcome of one check over a case's duty cycle."""

    check: Check
    value: float
    passed: bool
    margin: float          # %, positive when passing
    trajectory: int        # index of the worst trajectory in the case
    time: float            # s, time of the worst sample in it
    signal_limit: float    # the signal level that just meets the limit (for plots)
    details: dict = field(default_factory=dict, compare=False)   # what the JSON report adds (:func:`details_of`)


def profile_equivalent_load(check: Check, parts: list[tuple], rates) -> float:
    """A bearing life check's P_eq over the profile, N: the trajectories' sums of P^p over
    revolutions weighted by their repetitions per hour ``rates`` (:func:`profile_rates`;
    None or a missing rate: equal repetitions), the load the life is computed from."""
    if not isinstance(rates, (list, tuple)):
        rates = [rates] * len(parts)
    w = [1.0 if r is None else r for r in rates]
    return B.equivalent_load(sum(r * p[2] for r, p in zip(w, parts)), sum(r * p[3] for r, p in zip(w, parts)),
                             check.exponent)


def profile_rates(shares, spans, cycles_per_hour: float | None, service_life_h: float | None) -> list:
    """Repetitions per hour of service of each trajectory of a mission profile.

    A trajectory's share is ("cycles_per_hour", r): r; ("fraction", f) of the time: f 3600 / T;
    ("hours", h) of the service life L: (h / L) 3600 / T (T its duration, s); None: the
    case's ``cycles_per_hour`` (the trajectories together make one duty cycle repeated at
    that rate), or None when that is not given either (no life can be computed).
    """
    out = []
    for share, T in zip(shares, spans):
        if share is None:
            out.append(cycles_per_hour)
        elif share[0] == "cycles_per_hour":
            out.append(share[1])
        else:
            f = share[1] if share[0] == "fraction" else share[1] / service_life_h
            out.append(f * 3600.0 / T if T > 0 else 0.0)
    return out


def combine(check: Check, parts: list[tuple], rates) -> Verdict:
    """Merge the partials of a case's trajectories (in order) into a :class:`Verdict`;
    ``rates``: each trajectory's repetitions per hour (:func:`profile_rates`), or one number
    for all.  RMS, equivalent loads, revolutions and damage are weighted by them."""
    if not isinstance(rates, (list, tuple)):
        rates = [rates] * len(parts)
    w = [1.0 if r is None else r for r in rates]         # RMS: equal repetitions when unknown
    per_hour = [r or 0.0 for r in rates]
    scores = [p[5] for p in parts]
    worst = 0 if len(scores) == 1 else int(np.argmax(scores))   # (one trajectory: no numpy call)
    t_worst = parts[worst][1]
    peak = max(p[0] for p in parts)
    if check.kind in ("peak", "energy"):
        value, sig_lim = peak, check.limit
    elif check.kind == "rms":
        value = rms_of(sum(r * p[2] for r, p in zip(w, parts)), sum(r * p[3] for r, p in zip(w, parts)), peak)
        sig_lim = check.limit
    elif check.kind == "safety":
        value = B.static_safety(check.rating, peak)
        sig_lim = check.rating / check.limit
    elif check.kind == "slack":                    # T_i / max|E| - 1/2 >= limit: |E| <= T_i / (limit + 1/2)
        value = check.rating / peak - 0.5 if peak > 0 else math.inf
        sig_lim = check.rating / (check.limit + 0.5)
    elif check.kind in REDUCER_KINDS:
        value, sig_lim = _reducer_value(check, parts, rates)
    elif check.kind == "worm_efficiency":           # 1 - E_loss / E_in, each trajectory weighted
        E_in = sum(r * p[3] for r, p in zip(w, parts))
        value = 1.0 - sum(r * p[2] for r, p in zip(w, parts)) / E_in if E_in > 0.0 else math.inf
        sig_lim = check.limit
    elif check.kind == "fatigue":
        value = F.life_hours(sum(r * p[2] for r, p in zip(per_hour, parts)))
        cycles = check.limit * sum(r * p[4] for r, p in zip(per_hour, parts))
        factor = F.bending_cycle_factor if check.signal[0] == "bending" else F.pitting_cycle_factor
        sig_lim = check.rating * float(factor(max(cycles, 1.0)))
    else:
        P_eq = profile_equivalent_load(check, parts, rates)
        rev_h = sum(r * p[4] for r, p in zip(per_hour, parts))
        value = B.rating_life_hours(B.rating_life_mrev(check.rating, P_eq, check.exponent), rev_h)
        sig_lim = B.required_equivalent_load(check.rating, check.limit, rev_h, check.exponent)
    if check.kind in ("peak", "rms", "energy", "reducer_average", "reducer_speed_average"):
        margin = 100.0 * (check.limit - value) / check.limit
    else:
        margin = math.inf if math.isinf(value) else 100.0 * (value - check.limit) / check.limit
    return Verdict(check, value, margin >= 0, margin, worst, t_worst, sig_lim, details_of(check, parts, per_hour))


def _reducer_value(check: Check, parts: list[tuple], rates) -> tuple[float, float]:
    """(value, signal level that just meets the limit) of a reducer check: T_av and its limit;
    n_av and its limit; the life L = L_n (n_N/n_av) (T_N/T_av)^p (h) and the T_av that gives the
    required life, T_N (L_n n_N / (n_av L_req))^(1/p); a screw's life (ISO 3408-5) L_h =
    (C_a / F_m)^3 10^6 / (60 n_m) and the F_m that gives the required life."""
    if not isinstance(rates, (list, tuple)):
        rates = [rates] * len(parts)
    T_av, n_av = reducer_duty(check, parts, rates)
    if check.kind == "reducer_average":
        return T_av, check.limit
    if check.kind == "reducer_speed_average":
        return n_av, check.limit
    r = check.extra["rating"]
    if check.kind == "screw_life":           # T_av is F_m (p = 3), n_av the mean speed in rad/s
        n_m = n_av * 60.0 / (2.0 * math.pi)
        need = r.C_a * (1e6 / (60.0 * n_m * check.limit)) ** (1.0 / 3.0) if n_m > 0 else math.inf
        return screw_life_hours(r.C_a, T_av, n_m), need
    life = reducer_life(r, T_av, n_av)
    need = (r.rated_torque * (r.rated_life * r.rated_input_speed / (n_av * check.limit)) ** (1.0 / r.life_exponent)
            if n_av > 0 else math.inf)
    return life, need


STRESS_SIGNALS = ("bending", "contact")


def details_of(check: Check, parts: list[tuple], per_hour: list) -> dict:
    """The stresses a gear check used, for the JSON report: the peak stress (MPa) of a
    bending or contact check and, for a fatigue check, its rainflow cycles
    [[stress MPa, cycles per hour], ...] (largest stress first) and tooth passes per hour,
    each trajectory's counts times its repetitions per hour (``per_hour``)."""
    if check.signal[0] not in STRESS_SIGNALS:
        return {}
    out = {"peak_stress_MPa": max(p[0] for p in parts) / 1e6}
    if check.kind == "fatigue":
        cycles: dict = {}
        for rate, p in zip(per_hour, parts):
            for stress, n in p[7][0]:
                cycles[stress] = cycles.get(stress, 0.0) + rate * n
        out["rainflow_MPa_per_hour"] = [[k / 1e6, cycles[k]] for k in sorted(cycles, reverse=True)]
        out["tooth_passes_per_hour"] = sum(rate * p[7][1] for rate, p in zip(per_hour, parts))
    return out
