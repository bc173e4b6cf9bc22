"""Any gearcli mechanism -> a URDF that other tools load and gearcli reads back exactly.

:func:`export_urdf` writes (through yourdfpy's writer, then lxml for what it does not
write):

* every link with its ``<inertial>`` (centre of mass and full tensor; massless links have
  none) and every joint of the kinematic tree (``continuous`` for a revolute joint without
  known limits, ``revolute`` with ``<limit lower upper>`` for position limits, ``prismatic``
  with placeholder limits of +-1000 m when none are known; attributes written only because
  URDF requires them are listed in ``gearcli:placeholder`` and ignored on reading);
* URDF puts a joint's axis through the child frame origin; a gearcli link frame may sit off
  the axis (a D-H ``a``), so each URDF link frame is the gearcli frame moved onto its joint
  axis (``frame_correction``), and centres of mass, inertias, child joints and mesh points
  are re-expressed in it.  Joint frames are unchanged, so the reaction wrenches (given in
  the joint frames) and every other result read back identically;
* couplings of two joints (``GearPair.joints``, URDF mimic) as ``<mimic>``; every other
  dependent joint whose motion follows one independent joint alone as
  ``<mimic gearcli:derived="true">``, and motors on one joint as ``<transmission
  gearcli:derived="true">`` (both for other tools; gearcli ignores them on reading);
* the exact gearcli data in extension elements (namespace :data:`gearcli.io.urdf_xml.NS`):
  ``gearcli:mechanism`` (end effector, gravity, open loop), ``gearcli:gear`` (full gear
  geometry; angles in rad), ``gearcli:motor`` (link, stator, transmission coefficients),
  ``gearcli:load`` (external loads, in the URDF link frame), ``gearcli:joint`` (axis labels)
  and ``gearcli:friction`` (joint friction; a gear's loss factor is a ``gearcli:gear`` attribute).
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from lxml import etree

from ..analysis.graph import Analysis, analyse
from ..model.mechanism import Mechanism
from ..spatial import align_z
from ..io import URDF_SUFFIXES
from ..io.output import OutputError, output_target, write_text
from ..io.urdf_reader import NS, q
from .urdf_ratings import add_rating_elements

PRISMATIC_LIMIT = 1000.0  # m, placeholder +- limits of a prismatic joint without known limits
PLACEHOLDER_EFFORT, PLACEHOLDER_VELOCITY = 1e6, 1e3   # URDF requires both; marked gearcli:placeholder


def _num(x: float) -> str:
    return repr(float(x) + 0.0)


def _mesh_loss(c: float) -> tuple[str, str]:
    """``("efficiency", "0.98")`` when 1 - c reads back to exactly c and is the shorter
    figure (a file's ``efficiency: 0.98`` is c = 0.020000000000000018), else
    ``("loss_factor", repr(c))``."""
    eta = 1.0 - c
    if 1.0 - float(_num(eta)) == c and len(_num(eta)) < len(_num(c)):
        return "efficiency", _num(eta)
    return "loss_factor", _num(c)


def _vec(v) -> str:
    return " ".join(_num(x) for x in np.ravel(v))


def frame_correction(jt) -> tuple[np.ndarray, np.ndarray]:
    """(R, t): the URDF frame of ``jt``'s child in the gearcli child frame.

    With a = R_jc^T z (the axis in the child frame), the URDF child frame is the joint frame
    turned by align_z(a)^T: its origin is on the axis and the joint turns about a in it.
    It equals the gearcli frame when the joint was given by origin and axis.
    """
    a = jt.R_jc.T[:, 2]
    Rp = align_z(a).T
    return jt.R_jc.T @ Rp, -jt.R_jc.T @ jt.p_jc


def export_urdf(mech: Mechanism | Analysis, path: str | Path | None = None) -> str:
    """URDF text of ``mech`` (a Mechanism or its Analysis); also written to ``path`` when
    given, atomically (:func:`gearcli.io.output.write_text`; never over the mechanism's
    own source file)."""
    an = mech if isinstance(mech, Analysis) else analyse(mech)
    if path is not None:
        urdf_target(path, _sources(an.mech))
    root = to_element(an)
    text = etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="utf-8").decode("utf-8")
    if path is not None:
        write_text(path, text, _sources(an.mech))
    return text


def urdf_target(path: str | os.PathLike, inputs=()) -> str | None:
    """:func:`~gearcli.io.output.output_target` for a URDF: also refuses (``NAME: -o: ...``,
    :class:`~gearcli.io.output.OutputError`) a name gearcli would not read back as URDF,
    i.e. one not ending in ``.urdf`` or ``.xml`` (:data:`gearcli.io.URDF_SUFFIXES`)."""
    target = output_target(path, inputs)
    name = os.fspath(path)
    if target is not None and Path(name).suffix.lower() not in URDF_SUFFIXES:
        raise OutputError(name, "export writes URDF; name the file .urdf or .xml")
    return target


def _sources(mech: Mechanism) -> list[str]:
    src = getattr(mech, "source", None)
    return [src] if isinstance(src, str) and src and Path(src).exists() else []


def to_element(an: Analysis):
    """The ``<robot>`` element of the URDF of analysed mechanism ``an``."""
    mech = an.mech
    corr = _frame_corrections(mech)
    body = _urdf_body(mech, corr)
    root = etree.Element("robot", attrib={"name": mech.name}, nsmap={"gearcli": NS})
    root.append(etree.Comment(f" written by gearcli export from {mech.source}; exact gear, motor and "
                              f"mechanism data in the gearcli elements (namespace {NS}) "))
    for el in list(body):
        root.append(el)
    jel = {el.get("name"): el for el in root.findall("joint")}
    _mark_placeholders(mech, jel)
    _add_mimics(an, jel, corr)
    _add_transmissions(an, root)
    _add_extension(an, root, corr)
    add_rating_elements(mech, root, jel)
    return root


def _mark_placeholders(mech: Mechanism, jel: dict) -> None:
    """``gearcli:placeholder`` on the ``<limit>`` attributes written only because URDF
    requires them (:func:`gearcli.io.urdf_xml.placeholders`): effort and velocity of a joint
    with position limits but no known ratings, everything of a prismatic joint without
    limits.  gearcli reads such a file back without invented ratings or limits."""
    for jt in mech.joints:
        el = jel[jt.name].find("limit")
        if el is None or (isinstance(jt.source, dict) and jt.source.get("limit")):
            continue
        el.set(q("placeholder"), "effort velocity" if jt.position_limits is not None else "lower upper effort velocity")


def _frame_corrections(mech: Mechanism) -> dict:
    """URDF frame (R, t) of every link in its gearcli frame."""
    corr = {mech.base: (np.eye(3), np.zeros(3))}
    for jt in mech.joints:
        corr[jt.child] = frame_correction(jt)
    return corr


def _to_urdf(corr: dict, link: str, x) -> np.ndarray:
    """Point ``x`` of ``link``'s gearcli frame in its URDF frame, m."""
    R, t = corr[link]
    return R.T @ (np.asarray(x, float) - t)


def _urdf_links(mech: Mechanism, corr: dict) -> list:
    import yourdfpy  # noqa: PLC0415

    links = []
    for link in mech.links:
        R, _ = corr[link.name]
        inertial = None
        if link.mass > 0 or np.any(link.inertia != 0):
            T = np.eye(4)
            T[:3, 3] = _to_urdf(corr, link.name, link.com)
            inertial = yourdfpy.Inertial(origin=T, mass=float(link.mass), inertia=R.T @ link.inertia @ R)
        links.append(yourdfpy.Link(name=link.name, inertial=inertial))
    return links


def _urdf_joint(jt, corr: dict):
    import yourdfpy  # noqa: PLC0415

    Rp, tp = corr[jt.parent]
    a = jt.R_jc.T[:, 2]
    T = np.eye(4)
    T[:3, :3] = Rp.T @ jt.R_pj @ align_z(a).T
    T[:3, 3] = Rp.T @ (jt.p_pj - tp)
    limit = None
    lim = jt.source.get("limit") if isinstance(jt.source, dict) else None
    if lim is None and jt.position_limits is not None:       # YAML joints[].limits: no effort/velocity
        lim = dict(lower=jt.position_limits[0], upper=jt.position_limits[1], effort=PLACEHOLDER_EFFORT,
                   velocity=PLACEHOLDER_VELOCITY)
    if jt.type == "prismatic":
        jtype = "prismatic"
        limit = yourdfpy.Limit(**lim) if lim else yourdfpy.Limit(
            effort=PLACEHOLDER_EFFORT, velocity=PLACEHOLDER_VELOCITY, lower=-PRISMATIC_LIMIT, upper=PRISMATIC_LIMIT)
    elif lim and (jt.source.get("urdf_type") == "revolute" or jt.position_limits is not None):
        jtype, limit = "revolute", yourdfpy.Limit(**lim)
    else:
        jtype = "continuous"
    return yourdfpy.Joint(name=jt.name, type=jtype, parent=jt.parent, child=jt.child,
                          origin=T, axis=np.array([float(x) + 0.0 for x in a]), limit=limit)


def _urdf_body(mech: Mechanism, corr: dict):
    """Links, inertials and the joint tree, written by yourdfpy."""
    import yourdfpy  # noqa: PLC0415

    robot = yourdfpy.Robot(name=mech.name, links=_urdf_links(mech, corr),
                           joints=[_urdf_joint(jt, corr) for jt in mech.joints])
    return yourdfpy.URDF(robot=robot, build_scene_graph=False, load_meshes=False).write_xml().getroot()


def _add_mimics(an: Analysis, jel: dict, corr: dict) -> None:
    """Joint couplings as <mimic> (with their gear geometry), derived mimics, axis labels."""
    mech, tree = an.mech, an.tree
    coupled = set()
    for gi, gp in enumerate(mech.gears):
        if gp.joints is None:
            continue
        b, a = gp.joints
        coupled.add(b)
        etree.SubElement(jel[b], "mimic", joint=a, multiplier=_num(gp.ratio), offset="0.0")
        if gp.mesh_point is not None:
            circ = next(c for c in an.circuits if c.gear == gi)
            carrier = tree.links[circ.carrier]
            g = etree.SubElement(jel[b], q("gear"), name=gp.name, kind=gp.kind, carrier=carrier)
            _gear_attrs(g, gp, _to_urdf(corr, carrier, gp.mesh_point))
    for ji, jt in enumerate(mech.joints):
        if jt.name in coupled or ji in an.independent:
            continue
        nz = np.flatnonzero(np.abs(an.S[ji]) > 1e-12)
        if len(nz) == 1 and an.independent[nz[0]] >= 0:
            leader = mech.joints[an.independent[nz[0]]].name
            etree.SubElement(jel[jt.name], "mimic", {q("derived"): "true"}, joint=leader,
                             multiplier=_num(float(f"{an.S[ji, nz[0]]:.12g}")), offset="0.0")
    for jt in mech.joints:
        if jt.label is not None:
            etree.SubElement(jel[jt.name], q("joint"), label=str(jt.label))
        if jt.friction is not None and jt.friction.active:
            etree.SubElement(jel[jt.name], q("friction"), coulomb=_num(jt.friction.coulomb),
                             viscous=_num(jt.friction.viscous),
                             **({} if jt.friction.static is None else {"static": _num(jt.friction.static)}))


def _add_transmissions(an: Analysis, root) -> None:
    """Derived <transmission> elements (for other tools) of motors acting on one joint."""
    mech, tree = an.mech, an.tree
    for mi, m in enumerate(mech.motors):
        x, s = an.motor_links[mi], an.motor_stators[mi]
        if m.joints:
            if len(m.joints) != 1:
                continue
            joint, n = m.joints[0]
        elif tree.parent[x] == s:
            joint, n = mech.joints[tree.parent_joint[x]].name, 1.0
        else:
            continue
        t = etree.SubElement(root, "transmission", {q("derived"): "true"}, name=f"{m.name}_transmission")
        etree.SubElement(t, "type").text = "transmission_interface/SimpleTransmission"
        etree.SubElement(etree.SubElement(t, "joint", name=joint), "hardwareInterface").text = \
            "hardware_interface/EffortJointInterface"
        act = etree.SubElement(t, "actuator", name=m.name)
        etree.SubElement(act, "mechanicalReduction").text = _num(n)


def _add_extension(an: Analysis, root, corr: dict) -> None:
    """The gearcli extension elements: mechanism, gear pairs, motors."""
    mech, tree = an.mech, an.tree
    mattrs = {"end_effector": mech.end_effector, "gravity": _vec(mech.gravity)}
    if an.open_loop == "tree":
        mattrs["open_loop"] = "tree"
    etree.SubElement(root, q("mechanism"), mattrs)
    for gi, gp in enumerate(mech.gears):
        if gp.joints is not None:
            continue
        if gp.reducer is not None:
            _add_reducer(root, gp)
            continue
        if gp.screw is not None:
            circ = next(c for c in an.circuits if c.gear == gi)
            _add_screw(root, gp, tree.links[circ.carrier])
            continue
        if gp.belt is not None:
            bt, circ = gp.belt, next(c for c in an.circuits if c.gear == gi)
            carrier = tree.links[circ.carrier]
            el = etree.SubElement(root, q("belt"), name=gp.name, j=gp.j, k=gp.k, carrier=carrier,
                                  radii=_vec([bt.r_j, bt.r_k]), pretension=_num(bt.pretension),
                                  belt_point=_vec(_to_urdf(corr, carrier, bt.belt_point)),
                                  efficiency_forward=_table(bt.forward), efficiency_backward=_table(bt.backward))
            if bt.rating is not None:
                for k in ("max_effective_pull", "min_slack_ratio"):
                    if getattr(bt.rating, k) is not None:
                        el.set(k, _num(getattr(bt.rating, k)))
            continue
        if gp.worm is not None:
            wm, circ = gp.worm, next(c for c in an.circuits if c.gear == gi)
            etree.SubElement(root, q("worm"), name=gp.name, worm=gp.j, wheel=gp.k, carrier=tree.links[circ.carrier],
                             teeth=f"{wm.z1} {wm.z2}", reference_diameter=_num(wm.d1), module=_num(wm.module),
                             lead_angle=_num(wm.lead_angle), pressure_angle=_num(wm.pressure_angle),
                             friction_coefficient=_num(wm.mu), hand=wm.hand)
            continue
        circ = next(c for c in an.circuits if c.gear == gi)
        carrier = tree.links[circ.carrier]
        g = etree.SubElement(root, q("gear"), name=gp.name, j=gp.j, k=gp.k, kind=gp.kind, carrier=carrier)
        if gp.ratio is not None:
            g.set("ratio", _num(gp.ratio))
        _gear_attrs(g, gp, None if gp.mesh_point is None else _to_urdf(corr, carrier, gp.mesh_point))
    for mi, m in enumerate(mech.motors):
        el = etree.SubElement(root, q("motor"), name=m.name, link=m.link, stator=tree.links[an.motor_stators[mi]])
        if m.joints:
            el.set("joints", " ".join(j for j, _ in m.joints))
            el.set("coefficients", _vec([c for _, c in m.joints]))
    _add_loads(mech, root, corr)


def _add_loads(mech: Mechanism, root, corr: dict) -> None:
    """One gearcli:load per external load, re-expressed in its link's URDF frame, and one
    gearcli:payload per payload that is picked and placed."""
    for pl in mech.payloads:
        R, _ = corr[pl.link]
        I = R.T @ pl.inertia @ R
        etree.SubElement(root, q("payload"), name=pl.name, link=pl.link, mass=_num(pl.mass),
                         com=_vec(_to_urdf(corr, pl.link, pl.point)),
                         inertia=_vec([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]))
    for ld in mech.loads:
        R, _ = corr[ld.link]
        f, m = (R.T @ ld.force, R.T @ ld.moment) if ld.frame == "link" else (ld.force, ld.moment)
        el = etree.SubElement(root, q("load"), name=ld.name, link=ld.link, frame=ld.frame,
                              point=_vec(_to_urdf(corr, ld.link, ld.point)), force=_vec(f), moment=_vec(m))
        if ld.mass:                      # a payload: mass, inertia about the point in URDF link axes
            I = R.T @ ld.inertia @ R
            el.set("mass", _num(ld.mass))
            el.set("inertia", _vec([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]))


def _table(tab) -> str:
    """A reducer's speed table as an attribute: one number, or the pairs "w1 v1 w2 v2 ..."."""
    if tab.is_constant:
        return _num(tab.values[0])
    return _vec([v for pair in zip(tab.speeds, tab.values) for v in pair])


def _add_reducer(root, gp) -> None:
    """One gearcli:reducer (with its gearcli:rating) of a strain-wave or cycloidal reducer."""
    red = gp.reducer
    el = etree.SubElement(root, q("reducer"), name=gp.name, kind=gp.kind, input=gp.j, output=gp.k, housing=gp.carrier)
    if gp.teeth is not None:
        el.set("teeth", f"{gp.teeth[0]} {gp.teeth[1]}")
    else:
        el.set("ratio", _num(gp.ratio))
    el.set("efficiency_forward", _table(red.forward))
    el.set("efficiency_backward", _table(red.backward))
    if red.no_load_torque is not None:
        el.set("no_load_torque", _table(red.no_load_torque))
    if red.torsional_stiffness is not None:
        el.set("torsional_stiffness_torque", _vec(red.torsional_stiffness[0]))
        el.set("torsional_stiffness_rate", _vec(red.torsional_stiffness[1]))
    r = red.rating
    if r is not None:
        rel = etree.SubElement(el, q("rating"), rated_torque=_num(r.rated_torque), rated_input_speed=_num(r.rated_input_speed),
                               rated_life=_num(r.rated_life), life_basis=r.life_basis, life_exponent=_num(r.life_exponent))
        for k in ("average_torque_limit", "repeated_peak_torque", "max_input_speed", "average_input_speed_limit"):
            if getattr(r, k) is not None:
                rel.set(k, _num(getattr(r, k)))


def _add_screw(root, gp, carrier: str) -> None:
    """One gearcli:screw (with its gearcli:rating) of a ball or lead screw; its efficiencies
    as numbers (those derived from a friction coefficient too)."""
    sc = gp.screw
    el = etree.SubElement(root, q("screw"), name=gp.name, screw=gp.j, nut=gp.k, carrier=carrier,
                          lead=_num(sc.lead), hand=sc.hand, efficiency_forward=_table(sc.forward),
                          efficiency_backward=_table(sc.backward))
    r = sc.rating
    if r is not None:
        rel = etree.SubElement(el, q("rating"), C_a=_num(r.C_a), C_0a=_num(r.C_0a))
        if r.max_speed is not None:
            rel.set("max_speed", _num(r.max_speed))


def _gear_attrs(el, gp, mesh_point) -> None:
    if gp.teeth is not None:
        el.set("teeth", f"{gp.teeth[0]} {gp.teeth[1]}")
    if mesh_point is not None:
        el.set("mesh_point", _vec(mesh_point))
    el.set("pressure_angle", _num(gp.pressure_angle))
    if gp.cone_angles is not None:
        el.set("cone_angles", _vec(gp.cone_angles))
    if gp.helix_angle:
        el.set("helix_angle", _num(gp.helix_angle))
        el.set("hand", str(gp.hand))
    if gp.stiffness is not None:
        el.set("stiffness", _num(gp.stiffness))
    if gp.loss_factor:
        el.set(*_mesh_loss(gp.loss_factor))
