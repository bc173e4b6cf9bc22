"""``joints[].planets: N``: N identical planets equally spaced around the carrier axis,
declared once (a link, its joint on the carrier and its gear pairs) and expanded here,
before the mechanism is built.

The joint with ``planets: N`` (parent: the carrier, child: the planet link, geometry as
origin/axis) and every gear pair naming the planet are copied N times, copy k (k = 1..N)
turned by 360 (k - 1) / N degrees about the carrier's own joint axis (a line in the carrier
frame): the joint origin and its rpy, and the mesh points (in the carrier frame).  Names get
the copy number appended: link ``planet`` -> ``planet1`` ... ``planetN``, joint ``JP`` ->
``JP1`` ..., pair ``sun-planet`` -> ``sun-planet1`` ... (a pair without a name gets its
default ``j-k`` from the new link names).  Every copy keeps the YAML path of its original,
so problems are reported where the user wrote them.

A pair naming the planet may set values of some copies only, ``per_planet: [{planet: k,
stiffness: ...}, ...]`` (k = 1..N: the copy named ``<pair>k``); the other copies keep the
pair's own values.
"""
from __future__ import annotations

import copy

import numpy as np

from ..errors import Collector
from ..spatial import matrix_rpy, rpy_matrix

PATHS = "__paths__"   # key of the expanded data: the original YAML path of every list item


def item_path(data: dict, key: str, i: int) -> str:
    """The YAML path of item ``i`` of list ``key`` (``links``, ``joints``, ``gears``) as the
    user wrote it (a planet copy: its original's)."""
    paths = data.get(PATHS, {}).get(key)
    return paths[i] if paths is not None else f"{key}[{i}]"


def _turn(u: np.ndarray, phi: float) -> np.ndarray:
    """Rotation by ``phi`` (rad) about unit vector ``u`` (Rodrigues)."""
    K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return np.eye(3) + np.sin(phi) * K + (1 - np.cos(phi)) * K @ K


def _carrier_axis(data: dict, carrier: str, geometry, col: Collector, path: str):
    """(point (3,), unit direction (3,)) of the carrier's joint axis in the carrier frame,
    or None with an issue."""
    spec = next((j for j in data["joints"] if j["child"] == carrier), None)
    if spec is None:
        col.add(f"{path}.planets", f"the planets' carrier '{carrier}' turns on no joint: the planets are "
                "spaced around the carrier's joint axis")
        return None
    _, _, R_jc, p_jc = geometry(spec, Collector(""), path)
    return -R_jc.T @ p_jc, R_jc.T[:, 2]


def _misuse(data: dict, planet: str, carrier: str, path: str, col: Collector) -> bool:
    """Report uses of the planet link that a copy cannot follow (True if any)."""
    where = [f"joints[{i}]" for i, j in enumerate(data["joints"])
             if j["parent"] == planet or (j["child"] == planet and "planets" not in j)]
    where += [f"motors[{i}]" for i, m in enumerate(data.get("motors", [])) if planet in (m["link"], m.get("stator"))]
    where += [f"loads[{i}]" for i, ld in enumerate(data.get("loads", [])) if ld["link"] == planet]
    where += [f"gears[{i}].carrier" for i, g in enumerate(data.get("gears", []))
              if planet in g["links"] and g.get("carrier", carrier) != carrier]
    where += ["end_effector"] * (data["end_effector"] == planet)
    if where:
        col.add(f"{path}.planets", f"planet link '{planet}' cannot be used by {', '.join(where)}: only its "
                "joint on the carrier and its gear pairs are copied")
    return bool(where)


def _assembly_fits(data: dict, planet: str, n: int, path: str, col: Collector) -> bool:
    """Equal spacing of a simple planet (one external pair with a sun, one internal pair
    with a ring, the same planet tooth count in both, teeth given): every planet meshes
    both central gears only if (z_sun + z_ring) / N is a whole number."""
    pairs = [g for g in data.get("gears", []) if planet in g["links"]]
    kinds = sorted(g.get("kind", "external") for g in pairs)
    if kinds != ["external", "internal"] or not all("teeth" in g for g in pairs):
        return True
    own = {g["teeth"][g["links"].index(planet)] for g in pairs}
    central = [g["teeth"][1 - g["links"].index(planet)] for g in pairs]
    if len(own) != 1 or sum(central) % n == 0:
        return True
    col.add(f"{path}.planets", f"{n} equally spaced planets do not fit: (z_sun + z_ring) / N = "
            f"{sum(central)}/{n} is not a whole number (the planets' teeth cannot mesh the sun and the "
            "ring at every position)")
    return False


def _copies(spec: dict, n: int, a0, u, names: dict, place) -> list[dict]:
    """N copies of ``spec``: names from ``names`` {key: base name}, geometry by ``place``."""
    out = []
    for k in range(n):
        c = copy.deepcopy(spec)
        R = _turn(u, 2 * np.pi * k / n)
        for key, base in names.items():
            c[key] = f"{base}{k + 1}"
        place(c, R, lambda p: (a0 + R @ (np.asarray(p, float) - a0)).tolist())
        out.append(c)
    return out


def _place_joint(c: dict, R, move) -> None:
    c.pop("planets", None)
    origin = c.setdefault("origin", {})
    origin["xyz"] = move(origin.get("xyz", [0.0, 0.0, 0.0]))
    rpy = np.deg2rad(origin.pop("rpy_deg")) if "rpy_deg" in origin else origin.get("rpy", [0.0, 0.0, 0.0])
    origin["rpy"] = matrix_rpy(R @ rpy_matrix(rpy)).tolist()


def per_planet_problems(spec: dict, n: int, path: str, col: Collector) -> None:
    """Report bad ``per_planet`` items of the gear pair ``spec`` copied ``n`` times (a copy
    number outside 1..n or given twice, a stiffness that is not positive)."""
    seen: dict = {}
    for i, item in enumerate(spec.get("per_planet", ())):
        where = f"{path}.per_planet[{i}]"
        k = item["planet"]
        if not 1 <= k <= n:
            col.add(f"{where}.planet", f"planet {k} does not exist: the copies are numbered 1 to {n} (planets: {n})")
        elif k in seen:
            col.add(f"{where}.planet", f"planet {k} is given twice (first at {seen[k]})")
        seen.setdefault(k, where)
        if not item["stiffness"] > 0:
            col.add(f"{where}.stiffness", f"mesh stiffness must be positive, got {item['stiffness']:g} N/m")


def expand_planets(data: dict, geometry, col: Collector, later: Collector | None = None) -> dict:
    """``data`` with every ``planets: N`` joint expanded (see the module docstring); the
    original YAML path of every list item under :data:`PATHS`.  ``geometry(spec, col, path)``
    gives a joint's (R_pj, p_pj, R_jc, p_jc).  Issues go to ``col``; planets whose equal
    spacing does not fit are expanded all the same, their issue going to ``later`` (``col``
    when None), so that the analysis can still find the problems of their gear pairs."""
    planets = {j["child"] for j in data["joints"] if "planets" in j}
    for i, g in enumerate(data.get("gears", [])):
        if "per_planet" in g and not planets & set(g["links"]):
            col.add(f"gears[{i}].per_planet", "per_planet is for a gear pair of a planet (a link whose joint has "
                    f"planets: N); this pair's links {', '.join(map(repr, g['links']))} are not copied")
    if not planets:
        return data
    out = dict(data)
    lists = {key: [(f"{key}[{i}]", s) for i, s in enumerate(data.get(key, []))] for key in ("links", "joints", "gears")}
    for ji, spec in enumerate(data["joints"]):
        if "planets" not in spec:
            continue
        path, n, planet, carrier = f"joints[{ji}]", int(spec["planets"]), spec["child"], spec["parent"]
        if "dh" in spec or spec.get("type", "revolute") != "revolute":
            col.add(f"{path}.planets", "planets need a revolute joint given by origin/axis (not dh)")
            continue
        axis = _carrier_axis(data, carrier, geometry, col, path)
        if axis is None or _misuse(data, planet, carrier, path, col):
            continue
        if not _assembly_fits(data, planet, n, path, later or col) and later is None:
            continue
        a0, u = axis
        for gpath, g in lists["gears"]:
            if planet in g["links"]:
                per_planet_problems(g, n, gpath, col)
        lists["links"] = _expand(lists["links"], lambda s: s["name"] == planet,
                                 lambda s: _copies(s, n, a0, u, {"name": planet}, lambda c, R, m: None))
        lists["joints"] = _expand(lists["joints"], lambda s: s is spec,
                                  lambda s: _copies(s, n, a0, u, {"name": s["name"], "child": planet}, _place_joint))
        lists["gears"] = _expand(lists["gears"], lambda s: planet in s["links"],
                                 lambda s: _gear_copies(s, n, a0, u, planet))
    for key, items in lists.items():
        if key in data:
            out[key] = [s for _, s in items]
    out[PATHS] = {key: [p for p, _ in items] for key, items in lists.items()}
    return out


def _gear_copies(spec: dict, n: int, a0, u, planet: str) -> list[dict]:
    named = {"name": spec["name"]} if "name" in spec else {}
    copies = _copies(spec, n, a0, u, named, lambda c, R, m: None)
    for c in copies:
        c.pop("per_planet", None)
    for item in spec.get("per_planet", ()):
        if 1 <= item["planet"] <= n and item["stiffness"] > 0:
            copies[item["planet"] - 1]["stiffness"] = item["stiffness"]
    for k, c in enumerate(copies):
        R = _turn(u, 2 * np.pi * k / n)
        if "mesh_point" in c:
            c["mesh_point"] = (a0 + R @ (np.asarray(c["mesh_point"], float) - a0)).tolist()
        c["links"] = [f"{planet}{k + 1}" if x == planet else x for x in c["links"]]
    return copies


def _expand(items: list, match, copies) -> list:
    """``items`` [(path, spec)] with every matching spec replaced by its copies (same path)."""
    out = []
    for path, s in items:
        out += [(path, c) for c in copies(s)] if match(s) else [(path, s)]
    return out
