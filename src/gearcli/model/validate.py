"""Semantic checks shared by every mechanism reader (YAML and URDF).

Each check returns why a value is not physical, or None; the readers attach the message
to the place in their file.
"""
from __future__ import annotations

import math

import numpy as np

from .mechanism import GEAR_KINDS


def inertia_matrix(spec) -> np.ndarray:
    """Inertia tensor from ``[Ixx, Iyy, Izz]`` or ``{ixx, iyy, izz, ixy, ixz, iyz}``."""
    if isinstance(spec, dict):
        ixx, iyy, izz = spec["ixx"], spec["iyy"], spec["izz"]
        ixy, ixz, iyz = spec.get("ixy", 0.0), spec.get("ixz", 0.0), spec.get("iyz", 0.0)
        return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], float)
    return np.diag(np.asarray(spec, float))


def check_inertia(I: np.ndarray, mass: float) -> str | None:
    """Why ``I`` is not a physical inertia tensor about the centre of mass, or None."""
    w = np.linalg.eigvalsh(I)
    scale = max(float(np.max(np.abs(w))), 1e-300)
    if mass > 0 and np.all(w == 0):
        return None  # point mass
    if w[0] < -1e-12 * scale:
        return f"inertia tensor is not positive semi-definite (eigenvalues {np.array2string(w, precision=4)})"
    a, b, c = w
    if a + b < c * (1 - 1e-9) - 1e-15:
        return (f"principal moments {np.array2string(w, precision=4)} violate the triangle "
                "inequality (I1 + I2 >= I3)")
    return None


MAX_ABS = 1e12
"""Largest magnitude accepted for any number in a mechanism file (SI units): beyond it
products of lengths, masses and rates leave the range where float64 results mean anything."""


def number_problem(x) -> str | None:
    """Why the number ``x`` (int or float; bools are not numbers here) is refused, or None:
    not finite, or larger in magnitude than :data:`MAX_ABS`."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return None
    if isinstance(x, float) and not math.isfinite(x):
        return f"{x} is not a finite number"
    if abs(x) > MAX_ABS:
        text = f"{x:.6g}" if isinstance(x, float) or abs(x) < 10**300 else f"an integer of {len(str(abs(x)))} digits"
        limit = f"{MAX_ABS:.0e}".replace("e+", "e")
        return f"{text} is out of range (|x| <= {limit} in SI units)"
    return None


def gear_pair_problems(j: str, k: str, kind: str, ratio: float | None, has_teeth: bool,
                       has_mesh_point: bool, has_cones: bool, helix_deg: float | None = None,
                       hand: str | None = None) -> list[tuple[str, str]]:
    """Problems of a gear pair's declaration, whatever file it comes from: (field, message)
    with field ``""`` (the pair), ``"links"``, ``"kind"``, ``"ratio"``, ``"cone_angles"``,
    ``"helix_angle"``, ``"hand"`` or ``"teeth"``; ``ratio`` and ``helix_deg`` (the helix angle in
    degrees, as the user wrote it: the range is checked on that number, not on a conversion)
    None when not given.
    (The geometric checks are in :mod:`gearcli.model.gears`.)"""
    out: list[tuple[str, str]] = _helix_problems(kind, has_mesh_point, helix_deg, hand)
    if kind not in GEAR_KINDS:
        out.append(("kind", f"unknown gear kind '{kind}' (expected {', '.join(GEAR_KINDS)})"))
    if j == k:
        out.append(("links", "a gear pair needs two different links"))
    if kind == "rack":
        out += _rack_problems(has_teeth, has_mesh_point)
    elif ratio is None and not has_teeth:
        out.append(("", "a gear pair needs a ratio or tooth counts (teeth)"))
    if ratio == 0:
        out.append(("ratio", "gear ratio must not be zero"))
    if ratio is None and not has_mesh_point and kind != "rack":
        out.append(("", "a gear pair without mesh_point needs an explicit signed ratio"))
    if has_cones and kind != "bevel":
        out.append(("cone_angles", f"cone angles are only for bevel gears, this pair is {kind}"))
    return out


def _rack_problems(has_teeth: bool, has_mesh_point: bool) -> list[tuple[str, str]]:
    out = []
    if not has_mesh_point:
        out.append(("", "a rack pair needs its mesh_point (the pitch point on the rack's pitch line)"))
    if has_teeth:
        out.append(("teeth", "a rack pair takes no tooth counts (the pinion's pitch radius comes from "
                    "the mesh point; give a rating's module for the stress checks)"))
    return out


HELIX_MAX_DEG = 60.0
"""Helix angles are accepted in [0, HELIX_MAX_DEG) degrees."""


def _helix_problems(kind: str, has_mesh_point: bool, helix: float | None, hand: str | None) -> list:
    """``helix`` in degrees (compared as given: 60 is refused, 59.99999999 accepted)."""
    out = []
    if helix is not None and not 0.0 <= helix < HELIX_MAX_DEG:
        out.append(("helix_angle", f"helix angle must be in [0, {HELIX_MAX_DEG:g}) degrees, got {helix:g}"))
    if helix and kind not in ("external", "internal"):
        out.append(("helix_angle", f"a helix angle is only for external and internal parallel-axis pairs, "
                    f"this pair is {kind}"))
    elif helix and not has_mesh_point:
        out.append(("helix_angle", "a helix angle needs the tooth geometry (mesh_point)"))
    if hand is not None and hand not in ("right", "left"):
        out.append(("hand", f"hand must be 'right' or 'left', got '{hand}'"))
    if hand is not None and not helix:
        out.append(("hand", "hand given without a (non-zero) helix angle"))
    if helix and hand is None:
        out.append(("hand", "a helical pair needs the hand of gear j: right or left"))
    return out
