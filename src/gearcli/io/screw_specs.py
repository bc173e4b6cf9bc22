"""Reading a screw's declaration (``gears[]`` with ``kind: screw``), whatever file it comes
from: a schema-valid mapping (YAML, or a URDF extension element's attributes) -> the
:class:`~gearcli.model.screws.Screw`.  Problems go to ``add(path, message)`` at their key."""
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
