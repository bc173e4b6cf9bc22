"""Plausibility of the numbers in a mechanism and a trajectory: the signs of a unit mistake.

A mechanism written in millimetres, or a trajectory in degrees read as radians, is valid
input: every value is finite and every check of the geometry passes.  These checks look
for values that no real mechanism has and return findings, which the command line prints
as warnings (``--strict``: errors).  Each check is one function; the bounds are generous
(the bundled mechanisms, and the robots of example-robot-data, pass by a wide margin) and
stated in docs/reference/mechanism-files.md ("Plausibility warnings").

Mechanism checks take the model (:mod:`gearcli.model.mechanism`) and return
:class:`Finding` (YAML path or URDF element, message).  Trajectory checks take sample
arrays (N, k) in SI units and return, for each column with a value out of bounds, the
first such sample: (row, column, value).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MIN_DENSITY = 1.0
"""kg/m^3: below it, a link is lighter than air for the size its inertia implies (the solid
ellipsoid with the link's principal moments; a hollow or irregular body is denser than that
ellipsoid, never lighter).  A mechanism in mm (lengths x 1000, kg*mm^2 inertias x 1e6)
comes to 1e-9 of its true density."""

MAX_DENSITY = 25_000.0
"""kg/m^3: above it, a link is denser than osmium (22,590 kg/m^3) even when its mass is
spread over the most compact body with its moments of inertia (the solid sphere with the
same sum of principal moments)."""

MAX_LENGTH = 10.0
"""m: a joint offset, a centre of mass or a mesh point farther than this from its frame's
origin (a link of a robot is not 10 m long; in mm, 10 mm is 10 m)."""

TEETH_RANGE = (5.0, 2000.0)
"""Tooth counts 2 r / m (pitch radius r from the mesh geometry, transverse module m from the
rating) outside this range mean the module and the lengths are in different units."""

MIN_EFFICIENCY = 0.5
"""A mesh efficiency below it (a loss factor above 1 - it): a spur, helical, bevel or rack
mesh loses 0.5-3 % at the pitch point (no worm pairs in gearcli); 0.03 is a loss factor
given as ``efficiency``, or 0.97 an efficiency given as ``loss_factor``."""

MAX_BORE = 2.0
"""m: a bearing bore above it (a robot's largest slewing bearings are about 1 m); in mm,
a 2 mm bore reads as 2 m."""

MAX_JOINT_RATE = 100.0
"""rad/s at a revolute independent joint (955 rpm at the output of a gear train)."""

MAX_ANGLE = 4.0 * math.pi
"""rad: a revolute independent joint more than two turns from zero."""

MAX_MOTOR_SPEED = 1500.0
"""rad/s at a motor with a rotary input (14,300 rpm)."""


@dataclass(frozen=True)
class Finding:
    """One implausible value: where (YAML path or URDF element) and what (one line)."""

    path: str
    message: str


def _g(x: float) -> str:
    return f"{x:.3g}"


def _vec(v) -> str:
    return "[" + ", ".join(_g(float(x)) for x in v) + "]"


def ellipsoid_density(mass: float, inertia: np.ndarray) -> float:
    """kg/m^3 of the uniform solid ellipsoid of ``mass`` (kg) whose principal moments are
    those of ``inertia`` (3, 3) about the centre of mass (kg*m^2): semi-axes a_i^2 =
    5 (I_j + I_k - I_i) / (2 m); inf when a principal moment is on the triangle bound (a
    plate or a rod: no volume), nan for a point mass (no moments)."""
    w = np.linalg.eigvalsh(inertia)
    if not mass > 0 or not w.sum() > 0:
        return math.nan
    # in logarithms: a mass of 1e-300 kg or moments of 1e12 must not overflow (a mistyped file)
    with np.errstate(all="ignore"):
        axes2 = 5.0 * (w.sum() - 2.0 * w) / (2.0 * mass)
        if np.any(axes2 <= 0.0):
            return math.inf
        return float(np.exp(math.log(mass) - math.log(4.0 / 3.0 * math.pi) - 0.5 * float(np.sum(np.log(axes2)))))


def sphere_density(mass: float, inertia: np.ndarray) -> float:
    """kg/m^3 of the uniform solid sphere of ``mass`` whose principal moments add up to those
    of ``inertia`` (I = 2/5 m R^2 each: R^2 = 5 tr(I) / (6 m)), the most compact body with
    that sum; nan for a point mass."""
    tr = float(np.trace(inertia))
    if not mass > 0 or not tr > 0:
        return math.nan
    # m / (4/3 pi R^3) in logarithms (no overflow for a mistyped 1e-300 kg)
    with np.errstate(all="ignore"):
        return float(np.exp(math.log(mass) - math.log(4.0 / 3.0 * math.pi)
                            - 1.5 * (math.log(5.0 * tr) - math.log(6.0 * mass))))


def link_density(link) -> Finding | None:
    """A link whose mass and inertia imply a density outside [MIN_DENSITY, MAX_DENSITY]."""
    low, high = ellipsoid_density(link.mass, link.inertia), sphere_density(link.mass, link.inertia)
    moments = _vec(np.linalg.eigvalsh(link.inertia))
    if low < MIN_DENSITY:
        return Finding(f"{link.path}.inertia", f"link '{link.name}': mass {_g(link.mass)} kg with principal moments "
                       f"{moments} kg*m^2 implies a density of {_g(low)} kg/m^3 (the solid ellipsoid with these "
                       f"moments), below {_g(MIN_DENSITY)} kg/m^3, lighter than air: lengths in mm or the inertia "
                       "in kg*mm^2? (gearcli reads m, kg, kg*m^2)")
    if high > MAX_DENSITY:
        return Finding(f"{link.path}.mass", f"link '{link.name}': mass {_g(link.mass)} kg with principal moments "
                       f"{moments} kg*m^2 implies a density of at least {_g(high)} kg/m^3 (the solid sphere with "
                       f"these moments), above {_g(MAX_DENSITY)} kg/m^3, denser than any metal: the mass in g or "
                       "the inertia too small? (gearcli reads kg, kg*m^2)")
    return None


def _far(what: str, v, path: str) -> Finding | None:
    d = float(np.max(np.abs(v)))
    if not d > MAX_LENGTH:
        return None
    return Finding(path, f"{what} {_vec(v)} m is {_g(d)} m from the frame's origin (more than {_g(MAX_LENGTH)} m): "
                   "lengths in mm? (gearcli reads m)")


def _joint_place(joint) -> str:
    """The path of the joint's geometry keys (YAML ``dh`` or ``origin``; URDF: the element)."""
    if "dh" in joint.source:
        return f"{joint.path}.dh"
    return f"{joint.path}.origin.xyz" if "origin" in joint.source else joint.path


def long_lengths(mech) -> list[Finding]:
    """Joint offsets, centres of mass and mesh points farther than :data:`MAX_LENGTH`."""
    found = []
    for link in mech.links:
        found.append(_far(f"link '{link.name}': centre of mass", link.com, f"{link.path}.com"))
    for j in mech.joints:
        offset = j.p_pj if np.max(np.abs(j.p_pj)) >= np.max(np.abs(j.p_jc)) else j.p_jc
        found.append(_far(f"joint '{j.name}': offset", offset, _joint_place(j)))
    for g in mech.gears:
        if g.mesh_point is not None:
            found.append(_far(f"gear pair '{g.name}': mesh point", g.mesh_point, f"{g.path}.mesh_point"))
    return [f for f in found if f is not None]


def densities(mech) -> list[Finding]:
    """:func:`link_density` of every link with mass."""
    found = (link_density(link) for link in mech.links if link.mass > 0)
    return [f for f in found if f is not None]


def module_teeth(an) -> list[Finding]:
    """Gear ratings whose module gives 2 r / m teeth outside :data:`TEETH_RANGE` for the
    pitch radius r of the mesh geometry (pairs without tooth counts; with them, the design
    checks require module x teeth / 2 = r within 1 %)."""
    found = []
    for c in an.circuits:
        gp = an.mech.gears[c.gear]
        if gp.rating is None or c.geometry is None or gp.teeth is not None:
            continue
        mt = gp.rating.module / math.cos(gp.helix_angle)
        for link, r in ((gp.j, c.geometry.r_j), (gp.k, c.geometry.r_k)):
            if not (math.isfinite(r) and r > 0):
                continue
            z = 2.0 * r / mt
            if not TEETH_RANGE[0] <= z <= TEETH_RANGE[1]:
                found.append(Finding(f"{gp.rating.path}.module", f"gear pair '{gp.name}': module {_g(mt)} m and the "
                                     f"pitch radius {_g(r)} m of gear '{link}' give {_g(z)} teeth (2 r / m; expected "
                                     f"{TEETH_RANGE[0]:g} to {TEETH_RANGE[1]:g}): module in mm or lengths in mm? "
                                     "(gearcli reads m)"))
                break
    return found


def _key_path(mech, path: str, keys: tuple[str, ...]) -> str:
    """``path.key`` of the first key the file gave (located in ``mech.lines``), else ``path``."""
    return next((f"{path}.{k}" for k in keys if f"{path}.{k}" in mech.lines), path)


def mesh_losses(mech) -> list[Finding]:
    """Gear pairs whose mesh efficiency is below :data:`MIN_EFFICIENCY`."""
    found = []
    for g in mech.gears:
        eta = 1.0 - g.loss_factor
        if eta < MIN_EFFICIENCY:
            found.append(Finding(_key_path(mech, g.path, ("efficiency", "loss_factor")),
                                 f"gear pair '{g.name}': mesh efficiency {eta:.6g} (loss factor {g.loss_factor:.6g}) "
                                 f"is below {_g(MIN_EFFICIENCY)}; a gear mesh loses 0.5 to 3 % at the pitch point: "
                                 "efficiency and loss_factor swapped? (loss_factor = 1 - efficiency)"))
    return found


def large_bores(mech) -> list[Finding]:
    """Bearings (with friction) whose bore is above :data:`MAX_BORE`."""
    found = []
    for j in mech.joints:
        for b in j.bearings or ():
            if b.bore is not None and b.bore > MAX_BORE:
                found.append(Finding(_key_path(mech, b.path, ("bore",)), f"joint '{j.name}': bearing '{b.name}': "
                                     f"bore {_g(b.bore)} m is above {_g(MAX_BORE)} m: in mm? (gearcli reads m)"))
    return found


def mechanism_findings(an) -> dict[str, list[Finding]]:
    """The findings of the analysed mechanism ``an`` by kind (what they are, plural: lengths,
    densities, gear modules), each once."""
    return {f"lengths above {MAX_LENGTH:g} m": list(dict.fromkeys(long_lengths(an.mech))),
            f"link densities outside {MIN_DENSITY:g} to {MAX_DENSITY:,.0f} kg/m^3": list(dict.fromkeys(densities(an.mech))),
            "gear modules that contradict the pitch radii": list(dict.fromkeys(module_teeth(an))),
            f"mesh efficiencies below {MIN_EFFICIENCY:g}": mesh_losses(an.mech),
            f"bearing bores above {MAX_BORE:g} m": large_bores(an.mech)}


# -- trajectories -------------------------------------------------------------------------
def first_beyond(x: np.ndarray, limit: float, columns: np.ndarray) -> list[tuple[int, int, float]]:
    """For every selected column of ``x`` (N, k) (``columns``: boolean (k,)) with |x| >
    ``limit`` somewhere: (first such row, column, value)."""
    x = np.asarray(x, float)
    beyond = (np.abs(x) > limit) & np.asarray(columns, bool)[None, :]
    hit = beyond.any(axis=0)
    rows = beyond.argmax(axis=0)
    return [(int(rows[c]), int(c), float(x[rows[c], c])) for c in np.flatnonzero(hit)]


def fast_joints(qd: np.ndarray, revolute: np.ndarray) -> list[tuple[int, int, float]]:
    """Revolute joint rates (rad/s) above :data:`MAX_JOINT_RATE` (:func:`first_beyond`)."""
    return first_beyond(qd, MAX_JOINT_RATE, revolute)


def turned_joints(q: np.ndarray, revolute: np.ndarray) -> list[tuple[int, int, float]]:
    """Revolute joint angles (rad) beyond :data:`MAX_ANGLE` (:func:`first_beyond`)."""
    return first_beyond(q, MAX_ANGLE, revolute)


def fast_motors(speed: np.ndarray, rotary: np.ndarray) -> list[tuple[int, int, float]]:
    """Rotary motor speeds (rad/s) above :data:`MAX_MOTOR_SPEED` (:func:`first_beyond`)."""
    return first_beyond(speed, MAX_MOTOR_SPEED, rotary)
