"""One-line notes on a mechanism's external loads, helical pairs, racks and losses
(``check``, ``graph``, the ``solve`` summary) and their plain-data form (``graph --json``)."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

from .loss_notes import loss_notes

if TYPE_CHECKING:   # no numpy or analysis import for `gearcli --help`
    from ..analysis.graph import Analysis

OPPOSITE = {"right": "left", "left": "right"}


def _vec(x) -> str:
    return "[" + ", ".join(f"{float(v):.6g}" for v in x) + "]"


def load_dicts(an: Analysis) -> list[dict]:
    """Each external load: name, link, frame, point (m, link frame), force (N), moment (N*m)."""
    return [{"name": ld.name, "link": ld.link, "frame": ld.frame, "point": [float(v) for v in ld.point],
             "force": [float(v) for v in ld.force], "moment": [float(v) for v in ld.moment],
             **({"mass": float(ld.mass), "inertia": [[float(v) for v in row] for row in ld.inertia]} if ld.mass else {})}
            for ld in an.mech.loads]


def payload_dicts(an: Analysis) -> list[dict]:
    """Each payload that is picked and placed: name, link, mass (kg), com (m, link frame)."""
    return [{"name": p.name, "link": p.link, "mass": float(p.mass), "com": [float(v) for v in p.point],
             "inertia": [[float(v) for v in row] for row in p.inertia]} for p in an.mech.payloads]


def pair_dicts(an: Analysis) -> list[dict]:
    """Each helical pair (helix angle, hands of j and k) and rack (pinion, rack, pitch
    radius r and x_rack = x_per_rad * theta_pinion), in circuit order."""
    out = []
    for c in an.circuits:
        gp = an.mech.gears[c.gear]
        if gp.helix_angle:
            k_hand = gp.hand if gp.kind == "internal" else OPPOSITE[gp.hand]
            out.append({"pair": gp.name, "kind": "helical", "helix_angle_deg": math.degrees(gp.helix_angle),
                        "hands": {gp.j: gp.hand, gp.k: k_hand}})
        elif gp.kind == "rack" and c.geometry is not None:
            out.append({"pair": gp.name, "kind": "rack", "pinion": gp.j, "rack": gp.k,
                        "pitch_radius": c.geometry.r_j, "x_per_rad": 1.0 / c.ratio})
    return out


def _table_value(tab):
    """A drive element's efficiency or no-load torque as the file wrote it: a number, or its
    table's rows [[w_in, value], ...]."""
    return tab.values[0] if tab.is_constant else [list(r) for r in zip(tab.speeds, tab.values)]


def reducer_dicts(an: Analysis) -> list[dict]:
    """Each coaxial reducer (:mod:`gearcli.model.reducers`): kind, input, output, housing, the
    basic ratio i0, efficiencies (constant ones; a table: its rows), no-load torque (N*m)."""
    out = []
    for c in an.circuits:
        gp = an.mech.gears[c.gear]
        red = gp.reducer
        if red is None:
            continue

        out.append({"reducer": gp.name, "kind": gp.kind, "input": gp.j, "output": gp.k, "housing": gp.carrier,
                    "ratio": gp.ratio, "efficiency": {"forward": _table_value(red.forward), "backward": _table_value(red.backward)},
                    "no_load_torque": None if red.no_load_torque is None else _table_value(red.no_load_torque)})
    return out


def _reducer_line(d: dict) -> str:
    i0 = d["ratio"]
    eff = d["efficiency"]
    text = (f"{d['kind'].replace('_', '-')} reducer '{d['reducer']}': input '{d['input']}', output '{d['output']}', "
            f"housing '{d['housing']}', i0 = {i0:.6g} (input : output relative to the housing); pure torques, "
            f"T on the output, -T/i0 on the input, -T(1 - 1/i0) = {-(1 - 1 / i0):.6g} T on the housing "
            f"(a heavy edge input-output whose carrier is the housing; in the planetary view, the edge "
            f"output-housing with the input as carrier: theta_O,I = {1 - 1 / i0:.6g} * theta_H,I)")
    if eff["forward"] != 1.0 or eff["backward"] != 1.0:
        text += f"; efficiency forward {eff['forward']}, backward {eff['backward']}"
    if d["no_load_torque"] is not None:
        text += f"; no-load torque {d['no_load_torque']} N*m"
    return text


def screw_dicts(an: Analysis) -> list[dict]:
    """Each screw (:mod:`gearcli.model.screws`): screw, nut, carrier, lead (m/rev), hand, h
    (m/rad), efficiencies (constant ones; a table: its rows)."""
    out = []
    for c in an.circuits:
        gp = an.mech.gears[c.gear]
        sc = gp.screw
        if sc is None:
            continue

        out.append({"screw": gp.name, "screw_link": gp.j, "nut": gp.k, "carrier": an.names[c.carrier], "lead": sc.lead,
                    "hand": sc.hand, "h": sc.h, "efficiency": {"forward": _table_value(sc.forward), "backward": _table_value(sc.backward)}})
    return out


def _screw_line(d: dict) -> str:
    eff = d["efficiency"]
    text = (f"screw '{d['screw']}': screw '{d['screw_link']}' drives nut '{d['nut']}' (carrier '{d['carrier']}'), lead "
            f"{d['lead']:.6g} m/rev {d['hand']} hand: x_nut = {d['h']:.6g} m/rad * theta_screw; the axial force F on "
            "the nut along the axis with the torque h F, the opposite on the screw")
    if eff["forward"] != 1.0 or eff["backward"] != 1.0:
        text += f"; efficiency forward {eff['forward']}, backward {eff['backward']}"
        if not isinstance(eff["backward"], list) and eff["backward"] <= 0:
            text += " (self-locking: it holds its load without a brake; lowering needs the motor)"
    return text


def worm_dicts(an: Analysis) -> list[dict]:
    """Each worm pair (:mod:`gearcli.model.worms`): worm, wheel, teeth, lead angle and normal
    pressure angle (deg), mu, hand, the ratio e and the efficiencies from the geometry."""
    from ..model.worms import self_locking, worm_efficiencies  # noqa: PLC0415
    out = []
    for c in an.circuits:
        gp = an.mech.gears[c.gear]
        wm = gp.worm
        if wm is None:
            continue
        f, b = worm_efficiencies(wm.lead_angle, wm.pressure_angle, wm.mu)
        out.append({"pair": gp.name, "worm": gp.j, "wheel": gp.k, "teeth": [wm.z1, wm.z2],
                    "lead_angle_deg": math.degrees(wm.lead_angle), "pressure_angle_deg": math.degrees(wm.pressure_angle),
                    "friction_coefficient": wm.mu, "hand": wm.hand, "ratio": c.ratio, "efficiency": {"forward": f, "backward": b},
                    "self_locking": self_locking(wm.lead_angle, wm.pressure_angle, wm.mu)})
    return out


def _worm_line(d: dict) -> str:
    text = (f"worm pair '{d['pair']}': worm '{d['worm']}' ({d['teeth'][0]} start(s), {d['hand']} hand, lead angle "
            f"{d['lead_angle_deg']:.4g} deg) drives wheel '{d['wheel']}' ({d['teeth'][1]} teeth), theta_worm = "
            f"{d['ratio']:.6g} * theta_wheel; normal pressure angle {d['pressure_angle_deg']:.4g} deg, mu "
            f"{d['friction_coefficient']:g}: efficiency forward {d['efficiency']['forward']:.4f}, backward "
            f"{d['efficiency']['backward']:.4f}")
    if d["self_locking"]:
        text += " (self-locking: it holds a load without a brake; lowering needs the motor)"
    return text


def belt_dicts(an: Analysis) -> list[dict]:
    """Each timing belt (:mod:`gearcli.model.belts`): pulleys, pitch radii (m), pretension (N), the
    pull between the shafts at rest 2 T_i cos(alpha) (N) and the ratio e."""
    out = []
    for c in an.circuits:
        gp = an.mech.gears[c.gear]
        bt = gp.belt
        if bt is None:
            continue
        out.append({"belt": gp.name, "pulleys": [gp.j, gp.k], "radii": [bt.r_j, bt.r_k], "pretension": bt.pretension,
                    "shaft_pull_at_rest": 2 * bt.pretension * math.cos(c.belt.alpha), "ratio": c.ratio,
                    "efficiency": {"forward": _table_value(bt.forward), "backward": _table_value(bt.backward)}})
    return out


def _belt_line(d: dict) -> str:
    return (f"belt '{d['belt']}': pulley '{d['pulleys'][0]}' (r = {d['radii'][0]:.6g} m) drives '{d['pulleys'][1]}' "
            f"(r = {d['radii'][1]:.6g} m), theta_j = {d['ratio']:.6g} * theta_k; pretension {d['pretension']:.6g} N per "
            f"span: the shafts are pulled together by {d['shaft_pull_at_rest']:.6g} N at rest; spans T_i +- E/2")


def feature_notes(an: Analysis) -> list[str]:
    """Human-readable lines: ``load 'tip' on link '2' (frame base): force [..] N, moment [..]
    N*m at [..] m``, ``payload 'box' on link 'arm': ...``, ``helical pair ...``, ``rack pair
    ...``, then the losses
    (:func:`gearcli.report.loss_notes.loss_notes`)."""
    lines = [f"load '{d['name']}' on link '{d['link']}' (frame {d['frame']}): force {_vec(d['force'])} N, "
             f"moment {_vec(d['moment'])} N*m at {_vec(d['point'])} m (link frame)"
             + (f"; payload mass {d['mass']:.6g} kg (its weight and inertia move with the link)" if "mass" in d else "")
             for d in load_dicts(an)]
    lines += [f"payload '{d['name']}' on link '{d['link']}': {d['mass']:.6g} kg at {_vec(d['com'])} m (link frame), "
              f"carried where a trajectory's attach:{d['name']} is 1" for d in payload_dicts(an)]
    for d in pair_dicts(an):
        if d["kind"] == "helical":
            hands = ", ".join(f"'{k}' {v} hand" for k, v in d["hands"].items())
            lines.append(f"helical pair '{d['pair']}': helix angle {d['helix_angle_deg']:.6g} deg, {hands}")
        else:
            lines.append(f"rack pair '{d['pair']}': pinion '{d['pinion']}' (pitch radius {d['pitch_radius']:.6g} m) "
                         f"drives rack '{d['rack']}': x = {d['x_per_rad']:.6g} m/rad * theta")
    lines += [_reducer_line(d) for d in reducer_dicts(an)]
    lines += [_screw_line(d) for d in screw_dicts(an)]
    lines += [_worm_line(d) for d in worm_dicts(an)]
    lines += [_belt_line(d) for d in belt_dicts(an)]
    return lines + loss_notes(an)
