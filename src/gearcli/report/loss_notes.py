"""One-line notes on a mechanism's losses (``check``, ``graph``, the ``solve`` summary) and
their plain-data form (``graph --json`` ``losses``): each lossy gear pair and each joint with
friction, as the file gave them (docs/concepts/losses.md).

* A pair: efficiency eta and loss factor c = 1 - eta, and its friction arm rho (m): the
  couple is C = c |t| rho, rho = r_j / |u0| with u0 = z_j - z_k / e the gears' relative
  angular velocity per unit rate of j (a rack: u0 = z_j, rho = r); for an external spur pair
  rho = r_j r_k / (r_j + r_k), for an internal one r_j r_k / |r_k - r_j|.
* A joint: Coulomb (N*m; N for a prismatic joint) and viscous (N*m*s/rad; N*s/m) friction,
  and each bearing's friction coefficient and bore (m).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:   # no numpy or analysis import for `gearcli --help`
    from ..analysis.graph import Analysis


def _friction_arm(an: Analysis, ci: int) -> float:
    """rho (m) of circuit ``ci``: |couple on j| / (c |t|) (:mod:`gearcli.dynamics.losses`)."""
    from ..dynamics.losses import mesh_friction_moment  # noqa: PLC0415

    c = an.circuits[ci]
    moment = mesh_friction_moment(an, ci)
    return float((moment @ moment) ** 0.5) / an.mech.gears[c.gear].loss_factor


def gear_loss_dicts(an: Analysis) -> list[dict]:
    """Each gear pair with a mesh loss: pair, efficiency, loss_factor, friction_arm (m)."""
    out = []
    for ci, c in enumerate(an.circuits):
        gp = an.mech.gears[c.gear]
        if gp.loss_factor and c.geometry is not None and c.joints is None:
            out.append({"pair": gp.name, "efficiency": 1.0 - gp.loss_factor, "loss_factor": gp.loss_factor,
                        "friction_arm": _friction_arm(an, ci)})
    return out


def joint_loss_dicts(an: Analysis) -> list[dict]:
    """Each joint with friction: joint, type, coulomb, viscous (static when given) and its
    bearings with friction (name, friction_coefficient, bore in m)."""
    out = []
    for jt in an.mech.joints:
        bearings = [{"name": b.name, "friction_coefficient": b.friction_coefficient, "bore": b.bore}
                    for b in jt.bearings or () if b.friction_arm]
        fr = jt.friction
        if bearings or (fr is not None and fr.active):
            out.append({"joint": jt.name, "type": jt.type, "coulomb": fr.coulomb if fr else 0.0,
                        "viscous": fr.viscous if fr else 0.0, "bearings": bearings,
                        **({"static": fr.static} if fr is not None and fr.static is not None else {})})
    return out


def loss_dicts(an: Analysis) -> dict:
    """``{"gears": gear_loss_dicts, "joints": joint_loss_dicts}`` (``graph --json``)."""
    return {"gears": gear_loss_dicts(an), "joints": joint_loss_dicts(an)}


def loss_notes(an: Analysis) -> list[str]:
    """``mesh friction on pair 'p': efficiency 0.97 (loss factor 0.03), friction arm 0.012 m:
    couple 0.03 * 0.012 m * |t|`` and ``friction of joint 'J': Coulomb 0.002 N*m, viscous ...,
    bearing 'a' (mu 0.0015, bore 0.008 m)``."""
    lines = [f"mesh friction on pair '{d['pair']}': efficiency {d['efficiency']:.6g} (loss factor "
             f"{d['loss_factor']:.6g}), friction arm {d['friction_arm']:.6g} m: couple "
             f"{d['loss_factor']:.6g} * {d['friction_arm']:.6g} m * |t|" for d in gear_loss_dicts(an)]
    for d in joint_loss_dicts(an):
        force, rate = ("N", "N*s/m") if d["type"] == "prismatic" else ("N*m", "N*m*s/rad")
        parts = []
        if d["coulomb"] or d["viscous"]:
            parts.append(f"Coulomb {d['coulomb']:.6g} {force}, viscous {d['viscous']:.6g} {rate}"
                         + (f", static {d['static']:.6g} {force}" if d.get("static") is not None else ""))
        parts += [f"bearing '{b['name']}' (mu {b['friction_coefficient']:.6g}, bore {b['bore']:.6g} m)"
                  for b in d["bearings"]]
        lines.append(f"friction of joint '{d['joint']}': " + ", ".join(parts))
    return lines
