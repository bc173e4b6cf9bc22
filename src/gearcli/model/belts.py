"""Timing belts: an open drive of two pulleys (``gears[].kind: belt``;
``../shared/drive-elements.md`` C, docs/concepts/drive-elements.md "Timing belts").

Geometry (carrier frame, fixed for the whole motion)
----------------------------------------------------
Pulleys j (the input, named first) and k turn about parallel axes z (j's joint axis; k's in the
same or the opposite direction) relative to the carrier c, pitch radii r_j, r_k (``radii``, or
``teeth`` and ``pitch``: r = p z / (2 pi)).  The belt runs in the plane through ``belt_point``
normal to z; C_j, C_k are the axes' points in it, d = |C_k - C_j| > |r_j - r_k|.  With
e = (C_k - C_j)/d, n = z x e and sin(alpha) = (r_j - r_k)/d the two outer common tangents
(spans A and B) have outward normals m_A = cos(alpha) n + sin(alpha) e and m_B = -cos(alpha) n +
sin(alpha) e; span S touches j at X_jS = C_j + r_j m_S and k at X_kS = C_k + r_k m_S, its unit
direction e_S from j's tangent point to k's.

Constraint: the belt does not slip, so both pulleys' pitch circles move the belt at one speed
and turn the same way: r_j theta_{j,c} = r_k theta_{k,c} about z, i.e. theta_{j,c} = e theta_{k,c}
with e = (r_k / r_j)(z_k . z_j) about each pulley's own axis.

Interaction: the unknown E (N) is the effective pull, T_A = T_i + E/2 and T_B = T_i - E/2 the
span tensions (T_i the installation tension, ``pretension``).  On j: T_A e_A at X_jA and T_B e_B
at X_jB; on k the opposites at X_kA, X_kB.  The pretension's part is a known load (it pulls the
pulleys together, 2 T_i cos(alpha) along e at rest); E's is the unknown's column.  Valid while
both spans are taut: a sample with min(T_A, T_B) < 0 is an error.  Belt mass and stretch are
neglected.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from .power_flow import SpeedTable


@dataclass(frozen=True)
class BeltRating:
    """``max_effective_pull`` (N) and ``min_slack_ratio`` (the slack span's tension over |E|;
    Gates: 0.1-0.3), each checked when given."""

    max_effective_pull: float | None = None
    min_slack_ratio: float | None = None
    path: str = field(default="", compare=False)


@dataclass(frozen=True)
class Belt:
    """What a belt adds to its :class:`~.mechanism.GearPair` (``j`` the input pulley, ``k`` the
    other): pitch radii (m), pretension T_i (N), the belt plane's point (carrier frame, m),
    efficiencies (tables over the input pulley's speed) and rating."""

    r_j: float
    r_k: float
    pretension: float
    belt_point: np.ndarray
    forward: SpeedTable = SpeedTable.constant(1.0)
    backward: SpeedTable = SpeedTable.constant(1.0)
    rating: BeltRating | None = None

    def __eq__(self, other):
        return (isinstance(other, Belt) and (self.r_j, self.r_k, self.pretension, self.forward, self.backward, self.rating)
                == (other.r_j, other.r_k, other.pretension, other.forward, other.backward, other.rating)
                and np.array_equal(self.belt_point, other.belt_point))

    __hash__ = None

    @property
    def lossy(self) -> bool:
        return any(v != 1.0 for v in self.forward.values + self.backward.values)

    power_flow_lossy = lossy

    def lossless(self) -> "Belt":
        return replace(self, forward=SpeedTable.constant(1.0), backward=SpeedTable.constant(1.0))


@dataclass(frozen=True, eq=False)
class BeltGeometry:
    """The spans in the carrier frame: tangent points X (2 spans x 2 pulleys: [[X_jA, X_kA],
    [X_jB, X_kB]]), span directions e_S (2, 3), the axis z, the centres, alpha."""

    X: np.ndarray        # (2, 2, 3)
    e: np.ndarray        # (2, 3) e_A, e_B
    z: np.ndarray
    C_j: np.ndarray
    C_k: np.ndarray
    alpha: float
    ratio: float         # e = theta_j / theta_k about each pulley's own axis

    @cached_property
    def arms(self) -> dict:
        """:func:`belt_arms`' values."""
        z = self.z
        tj = float(z @ (np.cross(self.X[0, 0] - self.C_j, 0.5 * self.e[0])
                        + np.cross(self.X[1, 0] - self.C_j, -0.5 * self.e[1])))
        tk = float(z @ (np.cross(self.X[0, 1] - self.C_k, -0.5 * self.e[0])
                        + np.cross(self.X[1, 1] - self.C_k, 0.5 * self.e[1])))
        return {"tj": tj, "tk": tk, "rk": -tj / tk}


def belt_geometry(belt: Belt, oj, zj, ok, zk, names=("j", "k")) -> tuple[BeltGeometry | None, list]:
    """The spans of a belt from its pulleys' axis lines (points, directions; carrier frame);
    (None, problems) when the axes are not parallel or the pulleys overlap."""
    oj, zj, ok, zk = (np.asarray(v, float) for v in (oj, zj, ok, zk))
    zj, zk = zj / np.linalg.norm(zj), zk / np.linalg.norm(zk)
    if np.linalg.norm(np.cross(zj, zk)) > 1e-9:
        return None, [("links", f"the axes of pulleys '{names[0]}' and '{names[1]}' are not parallel: a belt drive's "
                       "pulleys turn about parallel axes")]
    z, p = zj, belt.belt_point
    C_j = oj + ((p - oj) @ z) * z
    C_k = ok + ((p - ok) @ z) * z
    d = float(np.linalg.norm(C_k - C_j))
    if not d > abs(belt.r_j - belt.r_k):
        return None, [("links", f"the pulleys '{names[0]}' and '{names[1]}' overlap: centre distance {d:.6g} m <= "
                       f"|r_j - r_k| = {abs(belt.r_j - belt.r_k):.6g} m")]
    e = (C_k - C_j) / d
    n = np.cross(z, e)
    sa = (belt.r_j - belt.r_k) / d
    ca = math.sqrt(1.0 - sa * sa)
    X, E = np.zeros((2, 2, 3)), np.zeros((2, 3))
    for s, sign in enumerate((1.0, -1.0)):
        m = sign * ca * n + sa * e
        X[s, 0], X[s, 1] = C_j + belt.r_j * m, C_k + belt.r_k * m
        E[s] = (X[s, 1] - X[s, 0]) / np.linalg.norm(X[s, 1] - X[s, 0])
    return BeltGeometry(X, E, z, C_j, C_k, math.asin(sa), (belt.r_k / belt.r_j) * float(zk @ zj)), []


def slack_problem(belt: Belt, E) -> int | None:
    """Index of the first sample whose slack span would have a negative tension, |E|/2 >
    T_i, or None."""
    bad = np.flatnonzero(np.abs(np.asarray(E, float)) / 2.0 > belt.pretension)
    return int(bad[0]) if bad.size else None


def belt_arms(geo: BeltGeometry) -> dict:
    """{"tj", "tk": the torque about z of the effective pull's forces on pulley j and on k per
    unit E (m), "rk": the ratio of k's rate about z to j's, r_j / r_k} (a new dict; computed
    once per geometry: every solve's loss outputs ask for it, a simulate step a dozen times)."""
    return dict(geo.arms)
