"""The graph analysis as plain data (``gearcli graph --json``)."""
from __future__ import annotations

from ..analysis.graph import Analysis, Circuit
from ..model.mechanism import Mechanism
from .features import load_dicts, pair_dicts, payload_dicts, reducer_dicts, screw_dicts, worm_dicts, belt_dicts
from .loss_notes import loss_dicts
from .sharing import sharing_sets


def analysis_dict(an: Analysis) -> dict:
    """Machine-readable summary of an analysis (the ``gearcli graph --json`` output)."""
    mech, n = an.mech, an.names
    return {
        "mechanism": mech.name,
        "dof": an.dof,
        "levels": {n[i]: an.level[i] for i in range(len(n))},
        "primary": [n[i] for i in an.primary],
        "secondary": [n[i] for i in an.secondary],
        "carriers": an.carriers,
        "canonical_graph": {
            "thin_edges": [
                {"parent": n[an.canonical_parent[i]], "child": n[i], "label": an.label[i]}
                for i in an.tree.moving
            ],
            "heavy_edges": [
                {"pair": mech.gears[c.gear].name, "links": [n[c.j], n[c.k]], "carrier": n[c.carrier]}
                for c in an.circuits
            ],
        },
        "coaxial_groups": [
            {"carrier": n[g.carrier], "label": g.label, "links": [n[i] for i in g.members[1:]]}
            for g in an.groups if len(g.members) > 2
        ],
        "fundamental_circuits": [
            {"pair": mech.gears[c.gear].name, "j": n[c.j], "k": n[c.k], "carrier": n[c.carrier],
             "ratio": c.ratio, "equation": _equation(mech, n, c)}
            for c in an.circuits
        ],
        "transmission_lines": [[n[i] for i in line] for line in an.transmission_lines],
        "independent_joints": list(an.independent_names),
        "motors": [m.name for m in mech.motors],
        "structure_matrix": an.A.tolist(),
        "pseudo_triangular": an.pseudo_triangular,
        "solve_order": [[n[i] for i in block] for block in an.schedule],
        "load_sharing": sharing_sets(an),
        "loads": load_dicts(an),
        "payloads": payload_dicts(an),
        "helical_and_rack_pairs": pair_dicts(an),
        "reducers": reducer_dicts(an),
        "screws": screw_dicts(an),
        "worms": worm_dicts(an),
        "belts": belt_dicts(an),
        "losses": loss_dicts(an),
    } | ({"open_loop": "tree"} if an.open_loop == "tree" else {})


def _equation(mech: Mechanism, n, c: Circuit) -> str:
    if c.joints is not None:
        b, a = (mech.joints[x].name for x in c.joints)
        return f"q_{b} = {c.ratio:.6g} * q_{a}"
    if mech.gears[c.gear].kind == "rack":   # x of the rack (m) = r theta of the pinion
        return (f"theta_{n[c.j]},{n[c.carrier]} = {c.ratio:.6g} * x_{n[c.k]},{n[c.carrier]}"
                f" (x = {1 / c.ratio:.6g} m * theta)")
    return f"theta_{n[c.j]},{n[c.carrier]} = {c.ratio:.6g} * theta_{n[c.k]},{n[c.carrier]}"
