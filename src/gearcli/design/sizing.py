"""Servo sizing: inertia ratio, torque-speed envelope, regenerative energy (issue 20).

Arrays of samples have shape (N,); torques in N*m, speeds in rad/s, inertias in kg*m^2,
energy in J.  Each function is one check of ``gearcli verify`` (:mod:`.checks` builds the
checks, :mod:`.evaluate` calls these functions on every sample).

* **Inertia ratio** (load-to-rotor): (J_m - J_rotor) / J_rotor, with J_m the inertia the
  motor sees (the diagonal of :func:`gearcli.dynamics.forward.motor_inertia`, rotor
  included); servo sizing guides bound it, typically at 5-10 (e.g. Hughes & Drury,
  *Electric Motors and Drives*, 5th ed., sec. 12.4; manufacturers' sizing guides).  Worst
  over the duty cycle.
* **Torque-speed envelope**: the utilisation |T| / T_max(omega) of every sample, T_max from
  a table ``[[omega, T_max], ...]`` (linear in |omega|, 0 beyond its last speed) or from a DC
  model, T_max = kt (V - kt omega_m) / R with omega_m the speed in the direction of the
  torque (more torque is available when braking).  The check passes when the worst
  utilisation is at most 1; the margin is 1 - utilisation.
* **Regenerative energy per cycle**: the integral of the negative mechanical power,
  E = integral of max(0, -T omega) dt over one trajectory (J, trapezoid rule): what the
  drive must dump or store.
"""
from __future__ import annotations

import numpy as np


def inertia_ratio(inertia_at_motor, rotor_inertia: float) -> np.ndarray:
    """(J_m - J_rotor) / J_rotor per sample (dimensionless); J_m includes the rotor."""
    return (np.asarray(inertia_at_motor, float) - rotor_inertia) / rotor_inertia


def table_peak_torque(speed, table) -> np.ndarray:
    """T_max (N*m) at each |speed| (rad/s) from ``table`` ((omega, T_max), ...) with
    omega increasing from 0: linear between rows, 0 beyond the last speed."""
    w, T = np.asarray(table, float).T
    return np.interp(np.abs(np.asarray(speed, float)), w, T, right=0.0)


def model_peak_torque(torque, speed, kt: float, resistance: float, voltage: float) -> np.ndarray:
    """T_max (N*m) of a DC motor at the supply voltage, in the direction of ``torque``:
    kt (V - kt omega_t) / R with omega_t = omega sign(T) (N*m/A, ohm, V, rad/s)."""
    s = np.where(np.asarray(torque, float) < 0, -1.0, 1.0)
    return np.maximum(kt * (voltage - kt * s * np.asarray(speed, float)) / resistance, 0.0)


def envelope_utilisation(torque, t_max) -> np.ndarray:
    """|T| / T_max per sample (dimensionless; inf where T_max is 0 and T is not)."""
    T, cap = np.abs(np.asarray(torque, float)), np.asarray(t_max, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(T == 0, 0.0, T / cap)


def regenerative_power(torque, speed) -> np.ndarray:
    """max(0, -T omega) per sample, W: the power flowing back from the mechanism."""
    return np.maximum(0.0, -np.asarray(torque, float) * np.asarray(speed, float))


def cycle_integral(x, t) -> float:
    """Trapezoid integral of the samples x over the times t of one cycle (0 for < 2 samples)."""
    x, t = np.asarray(x, float), np.asarray(t, float)
    return float(np.sum(0.5 * (x[1:] + x[:-1]) * np.diff(t))) if x.size > 1 else 0.0


def regenerative_energy(torque, speed, t) -> float:
    """Energy returned over one cycle (J): the trapezoid integral of max(0, -T omega) over
    the times t (s).  ``verify`` computes it in these two steps (the signal
    :func:`regenerative_power` per sample, then :func:`cycle_integral` per trajectory)."""
    return cycle_integral(regenerative_power(torque, speed), t)


SIGNALS = ("inertia_ratio", "envelope", "regen_power")
"""Signal kinds of the sizing checks (``Check.signal[0]``), evaluated by :func:`signal`."""


def signal(check, cols: dict) -> np.ndarray:
    """The sizing check's quantity at every sample from the output columns ``cols``
    (``motor:<m>``, ``motor:<m>:speed``, and ``motor:<m>:inertia`` for the inertia ratio)."""
    kind, name = check.signal[0], check.signal[1]
    if kind == "inertia_ratio":
        return inertia_ratio(cols[f"motor:{name}:inertia"], check.rating)
    T, w = cols[f"motor:{name}"], cols[f"motor:{name}:speed"]
    if kind == "regen_power":
        return regenerative_power(T, w)
    env = check.extra
    cap = (table_peak_torque(w, env["table"]) if "table" in env else
           model_peak_torque(T, w, env["kt"], env["resistance"], env["voltage"]))
    return envelope_utilisation(T, cap)


def sizing_checks(an, check_type) -> list:
    """The servo-sizing checks of every motor of ``an`` (``check_type``: :class:`.checks.Check`):
    inertia ratio (rating.rotor_inertia and max_inertia_ratio), torque-speed envelope
    (rating.torque_speed, else the DC model motors[].model of a rated motor), regenerative
    energy per cycle (rating.max_regen_energy)."""
    out = []
    for m in an.mech.motors:
        r, c = m.rating, f"motor {m.name}"
        if r is None:
            continue
        if r.max_inertia_ratio is not None:
            out.append(check_type(c, "inertia ratio", "", r.max_inertia_ratio, "peak", ("inertia_ratio", m.name), "",
                                  rating=r.rotor_inertia))
        env = ({"table": r.torque_speed} if r.torque_speed else {} if m.model is None else
               {"kt": m.model.kt, "resistance": m.model.resistance, "voltage": m.model.supply_voltage})
        if env:
            out.append(check_type(c, "torque-speed utilisation", "", 1.0, "peak", ("envelope", m.name), "", extra=env))
        if r.max_regen_energy is not None:
            out.append(check_type(c, "regenerative energy per cycle", "J", r.max_regen_energy, "energy",
                                  ("regen_power", m.name), "W"))
    return out


def inertia_columns(an, q, attach: dict | None = None, backend: str = "auto", solver=None) -> dict:
    """``{"motor:<m>:inertia": (N,)}`` the inertia each motor with a rated rotor inertia sees
    along the motion q (N, dof), kg*m^2 (:func:`gearcli.dynamics.forward.motor_inertia`,
    ``backend`` and ``solver`` its path), with the payloads ``attach`` carries at each sample."""
    rated = [k for k, m in enumerate(an.mech.motors) if m.rating is not None and m.rating.rotor_inertia is not None]
    if not rated:
        return {}
    from ..dynamics.forward import motor_inertia  # noqa: PLC0415

    J = motor_inertia(an, q, diagonal=True, attach=attach, backend=backend, solver=solver)
    return {f"motor:{an.mech.motors[k].name}:inertia": J[:, k] for k in rated}
