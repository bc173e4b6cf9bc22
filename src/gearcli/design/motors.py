"""Motor duty: RMS (thermal, continuous) torque, speed and mechanical power.

Arrays of samples have shape (N,); torques in N*m, speeds in rad/s, power in W.

Sources: the RMS torque over a duty cycle, T_rms = sqrt(sum T_k^2 dt_k / sum dt_k), is the
continuous-torque criterion of servo motor sizing (e.g. Hughes & Drury, *Electric Motors
and Drives*, 5th ed., sec. 12.4; manufacturers' sizing guides); mechanical power P = T w.
"""
from __future__ import annotations

import numpy as np


def rms(x, dt) -> float:
    """Time-weighted root mean square sqrt(sum x_k^2 dt_k / sum dt_k) (nan if sum dt = 0)."""
    x, dt = np.asarray(x, float), np.asarray(dt, float)
    total = float(np.sum(dt))
    return float(np.sqrt(np.sum(x * x * dt) / total)) if total > 0 else float("nan")


def mechanical_power(torque, speed) -> np.ndarray:
    """Mechanical power the motor delivers, P = T w (W; negative when it brakes)."""
    return np.asarray(torque, float) * np.asarray(speed, float)
