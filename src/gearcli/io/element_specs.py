"""Reading the declarations of screws, worm pairs and belts (``gears[]`` with ``kind: screw |
worm | belt``), whatever file they come from: a schema-valid mapping (YAML, or a URDF extension
element's attributes) -> the model's element.  Problems go to ``add(path, message)`` at their
key."""
from __future__ import annotations

from ..model.power_flow import SpeedTable
from ..model.screws import Screw, ScrewRating, friction_efficiencies
from .reducer_specs import speed_table


def screw_spec(spec: dict, path: str, add) -> Screw | None:
    """The Screw of a schema-valid screw declaration; None with a problem."""
    lead = float(spec["lead"])
    ok = True
    if not lead > 0:
        add(f"{path}.lead", f"a screw's lead must be positive (m per revolution), got {lead:g}")
        ok = False
    kw = {}
    if "efficiency" in spec and "friction_coefficient" in spec:
        add(f"{path}.friction_coefficient", "give efficiency or friction_coefficient (with diameter), not both")
        ok = False
    elif "efficiency" in spec:
        eff = spec["efficiency"]
        fwd = speed_table(eff["forward"], f"{path}.efficiency.forward", add, "forward efficiency eta_f", 0.0, 1.0, True)
        bwd = speed_table(eff.get("backward", eff["forward"]), f"{path}.efficiency.backward", add,
                          "backward efficiency eta_b", -1.0, 1.0, True)
        ok = ok and fwd is not None and bwd is not None
        kw.update(forward=fwd, backward=bwd)
    elif "friction_coefficient" in spec or "diameter" in spec:
        mu, d0 = spec.get("friction_coefficient"), spec.get("diameter")
        if mu is None or d0 is None:
            add(f"{path}.{'diameter' if d0 is None else 'friction_coefficient'}",
                "a screw's efficiency from friction needs both friction_coefficient and diameter")
            return None
        if not mu >= 0:
            add(f"{path}.friction_coefficient", f"friction coefficient must be >= 0, got {mu:g}")
            ok = False
        if not d0 > 0:
            add(f"{path}.diameter", f"screw diameter must be positive (m), got {d0:g}")
            ok = False
        if ok:
            eta_f, eta_b = friction_efficiencies(lead, float(d0), float(mu))
            kw.update(forward=SpeedTable.constant(eta_f), backward=SpeedTable.constant(eta_b))
    if "rating" in spec:
        r = spec["rating"]
        kw["rating"] = ScrewRating(float(r["C_a"]), float(r["C_0a"]),
                                   float(r["max_speed"]) if "max_speed" in r else None, path=f"{path}.rating")
    return Screw(lead, spec["hand"], **kw) if ok else None


def worm_spec(spec: dict, path: str, add):
    """The :class:`~gearcli.model.worms.Worm` of a schema-valid worm declaration; None with a
    problem (negative or zero sizes, module and lead angle both or neither, mu < 0)."""
    import math  # noqa: PLC0415

    from ..model.worms import Worm  # noqa: PLC0415
    z1, z2 = spec["teeth"]
    d1 = float(spec["reference_diameter"])
    ok = True
    if not d1 > 0:
        add(f"{path}.reference_diameter", f"the worm's reference diameter must be positive (m), got {d1:g}")
        ok = False
    if ("module" in spec) == ("lead_angle_deg" in spec):
        add(path, "a worm pair needs its axial module or its lead_angle_deg (one of them)")
        return None
    if "module" in spec:
        m = float(spec["module"])
        if not m > 0:
            add(f"{path}.module", f"the axial module must be positive (m), got {m:g}")
            return None
        gamma = math.atan(z1 * m / d1) if d1 > 0 else 0.0
    else:
        g = float(spec["lead_angle_deg"])
        if not 0 < g <= 45:
            add(f"{path}.lead_angle_deg", f"the lead angle must be in (0, 45] degrees, got {g:g}")
            return None
        gamma = math.radians(g)
        m = d1 * math.tan(gamma) / z1
    mu = float(spec.get("friction_coefficient", 0.0))
    if not mu >= 0:
        add(f"{path}.friction_coefficient", f"friction coefficient must be >= 0, got {mu:g}")
        ok = False
    alpha = math.radians(float(spec.get("pressure_angle_deg", 20.0)))
    return Worm(int(z1), int(z2), d1, m, gamma, alpha, mu, spec["hand"], path) if ok else None


def belt_spec(spec: dict, path: str, add):
    """The :class:`~gearcli.model.belts.Belt` of a schema-valid belt declaration; None with a
    problem (radii or teeth with pitch, positive sizes, pretension >= 0, efficiencies in (0, 1])."""
    import math  # noqa: PLC0415

    import numpy as np  # noqa: PLC0415

    from ..model.belts import Belt, BeltRating  # noqa: PLC0415
    ok = True
    if "radii" in spec and ("teeth" in spec or "pitch" in spec):
        add(f"{path}.radii", "give radii, or teeth and pitch, not both")
        return None
    if "radii" in spec:
        r_j, r_k = (float(v) for v in spec["radii"])
    elif "teeth" in spec and "pitch" in spec:
        p = float(spec["pitch"])
        if not p > 0:
            add(f"{path}.pitch", f"belt pitch must be positive (m), got {p:g}")
            return None
        r_j, r_k = (p * z / (2 * math.pi) for z in spec["teeth"])
    else:
        add(path, "a belt needs its pulleys' pitch radii (radii), or teeth and pitch")
        return None
    if not (r_j > 0 and r_k > 0):
        add(f"{path}.radii", f"pitch radii must be positive (m), got [{r_j:g}, {r_k:g}]")
        ok = False
    T_i = float(spec["pretension"])
    if not T_i >= 0:
        add(f"{path}.pretension", f"pretension must be >= 0 (N), got {T_i:g}")
        ok = False
    kw = {}
    if "efficiency" in spec:
        eff = spec["efficiency"]
        fwd = speed_table(eff["forward"], f"{path}.efficiency.forward", add, "forward efficiency eta_f", 0.0, 1.0, True)
        bwd = speed_table(eff.get("backward", eff["forward"]), f"{path}.efficiency.backward", add,
                          "backward efficiency eta_b", 0.0, 1.0, True)
        ok = ok and fwd is not None and bwd is not None
        kw.update(forward=fwd, backward=bwd)
    if "rating" in spec:
        r = spec["rating"]
        kw["rating"] = BeltRating(r.get("max_effective_pull"), r.get("min_slack_ratio"), path=f"{path}.rating")
    return Belt(r_j, r_k, T_i, np.asarray(spec["belt_point"], float), **kw) if ok else None
