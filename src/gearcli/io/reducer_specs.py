"""Reading a coaxial reducer's declaration (``gears[]`` with ``kind: strain_wave | cycloidal``),
whatever file it comes from: a schema-valid mapping (YAML, or a URDF extension element's
attributes) -> the signed basic ratio i0 and the :class:`~gearcli.model.reducers.Reducer`.

Every problem goes to ``add(path, message)`` at the key it concerns, so the readers locate it
(YAML line, URDF element).
"""
from __future__ import annotations

import math

from ..model.reducers import Reducer, ReducerRating, SpeedTable, strain_wave_ratio

RATIO_NOT_ONE = 1e-9
"""A basic ratio within this of 1 is refused: the output would turn with the input (a coaxial
element that does not reduce; the housing's torque -T (1 - 1/i0) vanishes)."""

DEFAULT_LIFE_EXPONENT = {"strain_wave": 3.0, "cycloidal": 10.0 / 3.0}


def reducer_ratio(spec: dict, path: str, add) -> float | None:
    """The signed basic ratio i0 from ``ratio`` or (strain-wave) ``teeth: [Z_F, Z_C]``; None
    with a problem when it is missing, contradictory, 0 or within 1e-9 of 1."""
    kind = spec["kind"]
    if "ratio" in spec and "teeth" in spec:
        add(f"{path}.teeth", "give ratio or teeth, not both")
        return None
    if "teeth" in spec:
        if kind != "strain_wave":
            add(f"{path}.teeth", f"teeth [Z_F, Z_C] are for a strain_wave reducer; give the {kind} reducer's ratio")
            return None
        z_f, z_c = spec["teeth"]
        if not z_c > z_f:
            add(f"{path}.teeth", f"the circular spline must have more teeth than the flexspline (Z_C > Z_F), "
                f"got Z_F = {z_f}, Z_C = {z_c}")
            return None
        return strain_wave_ratio(z_f, z_c)
    if "ratio" not in spec:
        add(path, f"a {kind} reducer needs its basic ratio (ratio, signed)"
            + (" or teeth [Z_F, Z_C]" if kind == "strain_wave" else ""))
        return None
    i0 = float(spec["ratio"])
    if i0 == 0.0 or abs(i0 - 1.0) <= RATIO_NOT_ONE:
        add(f"{path}.ratio", f"a reducer's basic ratio must not be 0 or 1 (a coaxial element that does not "
            f"reduce), got {i0:g}")
        return None
    return i0


def speed_table(value, path: str, add, what: str, low: float, high: float, low_open: bool) -> SpeedTable | None:
    """A number or a table [[w_in, v], ...] (w_in >= 0 increasing) as a :class:`SpeedTable`,
    every value in (low, high] (``low_open``) or [low, high]; None with a problem."""
    rows = [[0.0, value]] if isinstance(value, (int, float)) else value
    speeds, values, ok = [], [], True
    for r, (w, v) in enumerate(rows):
        at = path if isinstance(value, (int, float)) else f"{path}[{r}]"
        if not (low < v if low_open else low <= v) or not v <= high:
            rng = f"{'(' if low_open else '['}{low:g}, {high:g}]"
            add(at, f"{what} must be in {rng}, got {v:g}")
            ok = False
        if w < 0 or (speeds and not w > speeds[-1]):
            add(at, f"the speeds of a table must start at >= 0 rad/s and increase, got {w:g} after "
                f"{speeds[-1] if speeds else 0:g}")
            ok = False
        speeds.append(float(w))
        values.append(float(v))
    return SpeedTable(tuple(speeds), tuple(values)) if ok else None


def torsional_stiffness(spec: dict, path: str, add) -> tuple | None:
    """((T1, T2), (K1, K2, K3)) of ``torsional_stiffness``; None with a problem."""
    (T1, T2), K = spec["torque"], spec["rate"]
    ok = True
    if not 0 < T1 < T2:
        add(f"{path}.torque", f"the stiffness's torque limits must satisfy 0 < T1 < T2 (N*m), got [{T1:g}, {T2:g}]")
        ok = False
    if not all(k > 0 for k in K):
        add(f"{path}.rate", f"torsional stiffnesses must be positive (N*m/rad), got {list(K)}")
        ok = False
    return ((float(T1), float(T2)), tuple(float(k) for k in K)) if ok else None


def reducer_rating(kind: str, spec: dict, path: str, add) -> ReducerRating:
    """The :class:`ReducerRating` of a (schema-valid) ``rating`` mapping."""
    p = float(spec.get("life_exponent", DEFAULT_LIFE_EXPONENT[kind]))
    return ReducerRating(
        float(spec["rated_torque"]), float(spec["rated_input_speed"]), float(spec["rated_life"]),
        spec["life_basis"], p,
        *(float(spec[k]) if k in spec else None for k in (
            "average_torque_limit", "repeated_peak_torque", "max_input_speed", "average_input_speed_limit")),
        path=path)


def reducer_spec(spec: dict, path: str, add) -> tuple[float | None, Reducer]:
    """(i0, Reducer) of a schema-valid reducer declaration; problems to ``add``."""
    i0 = reducer_ratio(spec, path, add)
    kw = {}
    eff = spec.get("efficiency")
    if eff is not None:
        fwd = speed_table(eff["forward"], f"{path}.efficiency.forward", add, "forward efficiency eta_f", 0.0, 1.0, True)
        bwd = speed_table(eff.get("backward", eff["forward"]), f"{path}.efficiency.backward", add,
                          "backward efficiency eta_b", -1.0, 1.0, True)
        kw.update({k: v for k, v in (("forward", fwd), ("backward", bwd)) if v is not None})
    if "no_load_torque" in spec:
        t0 = speed_table(spec["no_load_torque"], f"{path}.no_load_torque", add, "no-load torque", 0.0, math.inf, False)
        kw["no_load_torque"] = t0
    if "torsional_stiffness" in spec:
        kw["torsional_stiffness"] = torsional_stiffness(spec["torsional_stiffness"], f"{path}.torsional_stiffness", add)
    if "rating" in spec:
        kw["rating"] = reducer_rating(spec["kind"], spec["rating"], f"{path}.rating", add)
    return i0, Reducer(**kw)
