"""Ratings in exported URDFs: the gearcli extension elements read by
:mod:`gearcli.io.ratings_reader` (``gearcli:bearing`` inside a joint, ``gearcli:motor_rating``,
``gearcli:motor_model`` (the DC model of ``gearcli simulate``) and ``gearcli:gear_rating``
under the robot), numbers written exactly (``repr``)."""
from __future__ import annotations

from lxml import etree

from ..io.urdf_reader import NS


def _q(tag: str) -> str:
    return f"{{{NS}}}{tag}"


def _attrs(obj, keys) -> dict:
    out = {}
    for k in keys:
        v = getattr(obj, k)
        if v is None:
            continue
        out[k] = ("true" if v else "false") if isinstance(v, bool) else (v if isinstance(v, str) else repr(float(v)))
    return out


def add_rating_elements(mech, root, joint_elements: dict) -> None:
    """Append the ratings of ``mech`` to the ``<robot>`` element ``root`` (joints by name)."""
    for jt in mech.joints:
        for b in jt.bearings or ():
            etree.SubElement(joint_elements[jt.name], _q("bearing"),
                             _attrs(b, ("name", "position", "C", "C0", "type", "X", "Y", "e", "X0", "Y0",
                                        "locating", "M", "f0", "a_ISO", "kappa", "e_C", "Cu",
                                        "friction_coefficient", "bore", "pitch_diameter")))
    for m in mech.motors:
        if m.rating is not None:
            etree.SubElement(root, _q("motor_rating"), {"motor": m.name,
                             **_attrs(m.rating, ("peak_torque", "rms_torque", "max_speed", "max_power", "thermal_window", "rotor_inertia",
                                                 "max_inertia_ratio", "max_regen_energy"))})
        if m.model is not None:
            etree.SubElement(root, _q("motor_model"), {"motor": m.name, **_attrs(m.model, (
                "kt", "resistance", "inductance", "supply_voltage"))})
    for g in mech.gears:
        if g.rating is not None:
            etree.SubElement(root, _q("gear_rating"), {"gear": g.name, **_attrs(g.rating, (
                "module", "face_width", "bending_stress_limit", "contact_stress_limit", "elastic_coefficient",
                "application_factor", "load_sharing_factor", "quality_number", "pitch_line_velocity"))})
