"""What a lossy drive spends along a trajectory: energy lost by element and the measured
efficiency of each motor's transmission line (the ``gearcli solve`` summary), and the
fixed-point iterations of bearing friction (median and worst over the samples).

* **Energy lost** (J): the time integral of each element's power loss (``gear:<p>:loss``,
  ``joint:<J>:loss``), trapezoid rule over the samples' t, accumulated across chunks.
* **Line efficiency** of motor m: the power the motion needs at that motor without losses
  (the lossless solve of the same motion: the output the line delivers) over the power the
  motor gives with losses (its input), both integrated over the samples where the power
  flows forward (both positive): sum P_lossless / sum P_lossy.  It is the measured ratio,
  not the per-mesh efficiency eta (a 15/60 mm spur pair at eta = 0.97 driven by its pinion
  gives 0.9707; a rack driven by its pinion at eta = 0.9 gives 1 / (1 + 0.1) = 0.909).
  ``nan`` when the power never flows forward.  Above 1 where motors share the work of coupled
  links: the reaction of one line's friction couple can help another motor (the paper's arm
  with its bevel pair at eta = 0.98: motor3 0.9805, motor5 1.0009).
* **Back-driven efficiency** of motor m: over the samples where the load drives the motor
  (both powers negative: regenerating or braking), the power the motor receives with losses
  over what the motion gives without them: sum (-P_lossy) / sum (-P_lossless).  A 15/60 mm
  spur pair at eta = 0.97 back-driven by its wheel gives (r_j - c rho) r_k / (r_j (r_k + c
  rho)) = 0.9702.  ``nan`` when the load never drives the motor.
* Both include the acceleration energy of the line's own inertia, the rotor's too: the
  lossless power is what the whole motion needs at the motor, not the power at the output.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import counted
from .columns import has_loss_column


def lossless_twin(mech):
    """The same mechanism with every loss removed: efficiency 1, no joint friction, no
    bearing friction, reducers without losses (the ratings stay)."""
    def frictionless(bearings):
        return bearings and tuple(replace(b, friction_coefficient=None) for b in bearings)
    return replace(mech, gears=tuple(replace(g, loss_factor=0.0, reducer=g.reducer and g.reducer.lossless(),
                                             screw=g.screw and g.screw.lossless(), worm=g.worm and g.worm.lossless(),
                                             belt=g.belt and g.belt.lossless())
                                     for g in mech.gears),
                   joints=tuple(replace(j, friction=None, bearings=frictionless(j.bearings)) for j in mech.joints))


def _trapezoid_parts(t: np.ndarray, y: np.ndarray, t_prev, y_prev) -> np.ndarray:
    """Integral of y (N, k) over t (N,), trapezoid rule, continuing from the previous
    chunk's last sample (t_prev, y_prev) when given; (k,)."""
    if t_prev is not None:
        t = np.concatenate([[t_prev], t])
        y = np.concatenate([y_prev[None, :], y])
    if t.shape[0] < 2:
        return np.zeros(y.shape[1])
    dt = np.diff(t)[:, None]
    return np.sum(0.5 * dt * (y[1:] + y[:-1]), axis=0)


@dataclass
class LossSummary:
    """Energy lost per element and line efficiency per motor, accumulated by chunks."""

    elements: list[str]                 # "gear <pair>", "joint <J>"
    motors: list[str]
    energy: np.ndarray = None           # (elements,) J
    p_in: np.ndarray = None             # (motors,) J of forward input (lossy motor power > 0)
    p_out: np.ndarray = None            # (motors,) J delivered (lossless power) over the same samples
    b_in: np.ndarray = None             # (motors,) J the load gives back (-lossless power < 0), back-driven samples
    b_out: np.ndarray = None            # (motors,) J the motor receives (-lossy power) over the same samples
    iterations: np.ndarray = None       # histogram of the bearing friction iterations per sample
    _last: tuple = field(default=(None, None, None))

    @classmethod
    def for_mechanism(cls, an) -> "LossSummary":
        mech = an.mech
        el = [f"gear {mech.gears[c.gear].name}" for c in an.circuits if has_loss_column(an, c)]
        el += [f"joint {jt.name}" for jt in mech.joints]
        s = cls(el, [m.name for m in mech.motors])
        s.energy = np.zeros(len(el))
        s.p_in = np.zeros(len(s.motors))
        s.p_out = np.zeros(len(s.motors))
        s.b_in = np.zeros(len(s.motors))
        s.b_out = np.zeros(len(s.motors))
        return s

    def add(self, an, t: np.ndarray, res, lossless_motor: np.ndarray) -> None:
        """Accumulate a chunk: its times ``t`` (N,), the lossy ``res`` and the lossless motor
        torques (N, M) of the same motion."""
        geo = [ci for ci, c in enumerate(an.circuits) if has_loss_column(an, c)]
        loss = np.concatenate([res.gear_loss[:, geo], res.joint_loss], axis=1)
        p_lossy = res.motor * res.motor_speed
        p_ideal = lossless_motor * res.motor_speed
        forward = (p_lossy > 0) & (p_ideal > 0)
        backward = (p_lossy < 0) & (p_ideal < 0)
        t_prev, loss_prev, fwd_prev = self._last
        self.energy += _trapezoid_parts(t, loss, t_prev, loss_prev)
        both = np.concatenate([np.where(forward, p_lossy, 0.0), np.where(forward, p_ideal, 0.0),
                               np.where(backward, -p_ideal, 0.0), np.where(backward, -p_lossy, 0.0)], axis=1)
        e = _trapezoid_parts(t, both, t_prev, fwd_prev)
        M = len(self.motors)
        self.p_in += e[:M]
        self.p_out += e[M:2 * M]
        if self.b_in is None:
            self.b_in, self.b_out = np.zeros(M), np.zeros(M)
        self.b_in += e[2 * M:3 * M]
        self.b_out += e[3 * M:]
        if res.bearing_iterations is not None:
            h = np.bincount(res.bearing_iterations)
            old = self.iterations if self.iterations is not None else np.zeros(0, dtype=np.int64)
            self.iterations = np.zeros(max(h.size, old.size), dtype=np.int64)
            self.iterations[:h.size] += h
            self.iterations[:old.size] += old
        self._last = (t[-1], loss[-1], both[-1])

    @property
    def efficiency(self) -> np.ndarray:
        """(M,) measured line efficiency of each motor (nan: power never flowed forward)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(self.p_in > 0, self.p_out / np.where(self.p_in > 0, self.p_in, 1.0), np.nan)

    @property
    def backward_efficiency(self) -> np.ndarray:
        """(M,) measured back-driven efficiency of each motor's line (nan: the load never
        drove the motor)."""
        b_in = np.zeros(len(self.motors)) if self.b_in is None else self.b_in
        b_out = np.zeros(len(self.motors)) if self.b_out is None else self.b_out
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(b_in > 0, b_out / np.where(b_in > 0, b_in, 1.0), np.nan)

    def lines(self) -> list[str]:
        """The summary's lines: energy lost by element (largest first; elements equal to the
        printed digits, the copies of a planet, in file order) and line efficiencies."""
        total = float(self.energy.sum())
        out = [f"energy lost: {total:.6g} J in all"]
        shown = np.array([float(f"{e:.6g}") for e in self.energy])   # equal as printed: file order
        for i in np.argsort(-shown, kind="stable"):
            if self.energy[i] > 0:
                out.append(f"  {self.elements[i]}: {self.energy[i]:.6g} J ({100 * self.energy[i] / total:.3g} %)")
        if self.iterations is not None:
            cum = np.cumsum(self.iterations)
            median = int(np.searchsorted(cum, (cum[-1] + 1) // 2))
            out.append(f"bearing friction: converged in {counted(median, 'iteration')} per sample (median), "
                       f"{self.iterations.size - 1} at worst")
        for m, eta in zip(self.motors, self.efficiency):
            above = "; above 1: losses elsewhere do part of this motor's work (coupled lines)" if eta > 1 else ""
            out.append(f"line efficiency of motor {m}: " + ("- (its power never flows forward)" if np.isnan(eta)
                                                             else f"{eta:.4f} (lossless power / motor power where "
                                                                  f"the motor drives{above})"))
        for m, eta in zip(self.motors, self.backward_efficiency):
            if not np.isnan(eta):
                out.append(f"back-driven efficiency of motor {m}: {eta:.4f} (motor power / lossless power where "
                           "the load drives the motor: regenerating or braking)")
        out.append("(line efficiencies include the acceleration energy of each line's inertia, its rotor's too)")
        return out
