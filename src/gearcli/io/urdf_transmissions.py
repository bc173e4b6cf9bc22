"""URDF ``<transmission>`` elements -> actuators acting on joints with coefficients.

Every supported transmission becomes one :class:`~gearcli.model.mechanism.Motor` per actuator with
``joints = ((joint, c), ...)``: the actuator's input rotation is ``theta_a = sum c q_joint``
and its torque ``tau_a`` acts as ``c * tau_a`` about (along) each joint's axis, on the
joint's child and, reversed, on its parent.  So the joint torques are ``tau_j = C^T tau_a``
(C: actuators x joints) and the motor column of a result is the *actuator* torque, before
the reduction.  With n the ``mechanicalReduction`` values (default 1):

========================================  ==============================================
ROS transmission                          coefficients c (rows: actuators)
========================================  ==============================================
``SimpleTransmission``                    actuator a, joint j: ``c = n``
                                          (tau_j = n tau_a, theta_a = n q_j)
``DifferentialTransmission``              a1: ``(n_a1 n_j1,  n_a1 n_j2)``
(ros_control; roles actuator1/2,          a2: ``(n_a2 n_j1, -n_a2 n_j2)``
joint1/2)                                 (tau_j1 = n_j1 (n_a1 tau_a1 + n_a2 tau_a2),
                                          tau_j2 = n_j2 (n_a1 tau_a1 - n_a2 tau_a2))
``WristTransmission`` (PR2: right/left    right: ``( n_r n_flex, -n_r n_roll)``
actuator, flex/roll joint)                left:  ``(-n_l n_flex, -n_l n_roll)``
                                          (tau_flex = n_flex (n_r tau_r - n_l tau_l),
                                          tau_roll = -n_roll (n_r tau_r + n_l tau_l))
========================================  ==============================================

Joint offsets (``<offset>``, ``reference_position``) only move the zero of the actuator
angle; they do not change the torques and are ignored.  Other transmission types are
reported (see :func:`read_transmissions`) and their joints are driven directly.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from ..model.validate import number_problem
from .urdf_xml import decimal_numbers

KINDS = ("SimpleTransmission", "DifferentialTransmission", "WristTransmission")


@dataclass
class Actuation:
    """One actuator of a transmission: ``joints`` are (joint name, coefficient c)."""

    name: str
    joints: tuple[tuple[str, float], ...]


@dataclass
class TransmissionSpec:
    """A ``<transmission>`` as read: ``kind`` without its package prefix; ``joints`` every
    joint it names (for reference checks); ``actuators`` empty when unsupported."""

    name: str
    kind: str
    line: int | None
    joints: list[str] = field(default_factory=list)
    actuators: list[Actuation] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)

    @property
    def path(self) -> str:
        return f"transmission '{self.name}'"


def _number(text: str | None, what: str, problems: list[str], default: float = 1.0) -> float:
    if text is None or not text.strip():
        return default
    try:
        (value,) = decimal_numbers(text)   # not float(): "1_0" is not 10
    except ValueError:
        problems.append(f"{what} '{text.strip()}' is not a number")
        return default
    if value == 0 or value != value or abs(value) == float("inf"):
        problems.append(f"{what} must be a finite nonzero number, got {text.strip()}")
        return default
    why = number_problem(value)
    if why:
        problems.append(f"{what} {why}")
        return default
    return value


def _by_role(elements, prefix: str):
    """Order two elements by their <role> (``actuator1``/``actuator2``), else file order."""
    roles = [(e.findtext("role") or "").strip() for e in elements]
    if all(r in (f"{prefix}1", f"{prefix}2") for r in roles) and len(set(roles)) == 2:
        return [e for _, e in sorted(zip(roles, elements), key=lambda t: t[0])]
    return list(elements)


def _parts(t, n: int, kind: str, probs: list) -> tuple[list, list]:
    """The <joint> and <actuator> children of transmission ``t`` when there are ``n`` of
    each; otherwise a problem is recorded and both lists are empty."""
    joints, acts = t.findall("joint"), t.findall("actuator")
    if len(joints) != n or len(acts) != n:
        word = {1: "one", 2: "two"}[n]
        probs.append(f"a {kind} needs {word} <joint> and {word} <actuator>, "
                     f"got {len(joints)} and {len(acts)}")
        return [], []
    return joints, acts


def read_transmissions(root) -> list[TransmissionSpec]:
    """Every ``<transmission>`` child of ``root`` (an lxml ``<robot>`` element)."""
    out = []
    for i, t in enumerate(root.findall("transmission")):
        name = t.get("name") or f"#{i + 1}"
        kind = (t.findtext("type") or t.get("type") or "").strip().split("/")[-1]
        spec = TransmissionSpec(name, kind, t.sourceline)
        spec.joints = [j.get("name") for j in t.findall("joint")]
        probs = spec.problems
        if kind == "SimpleTransmission":
            joints, acts = _parts(t, 1, kind, probs)
            if joints:
                a = acts[0]
                text = a.findtext("mechanicalReduction")
                if text is None:
                    text = t.findtext("mechanicalReduction")  # the older (PR2) layout
                n = _number(text, "mechanicalReduction", probs)
                spec.actuators = [Actuation(a.get("name") or name, ((joints[0].get("name"), n),))]
        elif kind == "DifferentialTransmission":
            joints, acts = _parts(t, 2, kind, probs)
            if joints:
                a1, a2 = _by_role(acts, "actuator")
                j1, j2 = _by_role(joints, "joint")
                na1, na2 = (_number(a.findtext("mechanicalReduction"), "mechanicalReduction", probs) for a in (a1, a2))
                nj1, nj2 = (_number(j.findtext("mechanicalReduction"), "mechanicalReduction", probs) for j in (j1, j2))
                n1, n2 = j1.get("name"), j2.get("name")
                spec.actuators = [Actuation(a1.get("name") or f"{name}_1", ((n1, na1 * nj1), (n2, na1 * nj2))),
                                  Actuation(a2.get("name") or f"{name}_2", ((n1, na2 * nj1), (n2, -na2 * nj2)))]
        elif kind == "WristTransmission":
            parts = [t.find(tag) for tag in ("rightActuator", "leftActuator", "flexJoint", "rollJoint")]
            if any(p is None for p in parts):
                probs.append("a WristTransmission needs rightActuator, leftActuator, flexJoint and rollJoint")
            else:
                r, left, flex, roll = parts
                nr, nl, nf, nro = (_number(p.get("mechanicalReduction"), "mechanicalReduction", probs)
                                   for p in parts)
                spec.joints = [flex.get("name"), roll.get("name")]
                f, ro = spec.joints
                spec.actuators = [Actuation(r.get("name") or f"{name}_right", ((f, nr * nf), (ro, -nr * nro))),
                                  Actuation(left.get("name") or f"{name}_left", ((f, -nl * nf), (ro, -nl * nro)))]
        if any(j is None for j in spec.joints):
            probs.append("a <joint> of this transmission has no name")
            spec.joints = [j for j in spec.joints if j is not None]
            spec.actuators = []
        out.append(spec)
    return out
