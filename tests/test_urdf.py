"""URDF import and export.

* Real robot descriptions from ``example-robot-data`` (UR5, Panda, the Talos left arm, xArm7,
  Kinova, and the branched Talos, Romeo and Tiago-Pro with mimic joints): along a smooth
  trajectory exercising every joint, gearcli's equivalent torques equal Pinocchio's RNEA on
  the same file (``pin.buildModelFromUrdf``, projected by S^T where mimic joints couple
  coordinates), and each joint's reaction wrench, completed by the torque acting across the
  joint, equals Pinocchio's ``data.f`` in the joint's child frame, both to 1e-9.
* Transmissions: motor torques follow the documented mapping (SimpleTransmission reduction,
  ros_control DifferentialTransmission, PR2 WristTransmission), with the reductions read
  here from the files independently of gearcli.
* Mimic offsets, mimic across parents and rack-and-pinion (a prismatic joint mimicking a
  revolute one), fixed-joint lumping, inertial rpy: synthetic URDFs against Pinocchio.
* The bundled example ``mechanisms/geared_arm.urdf``.
* Export: YAML -> URDF -> gearcli gives the YAML's results to 1e-12 on the bundled
  mechanisms; yourdfpy loads the export without warnings; Pinocchio reads it too.
* Bad input: one line per problem, ``file:line: element: message``, exit status 2.
"""
from __future__ import annotations

import io
import logging
import re
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from gearcli import MechanismError
from metrics import rel_err
from gearcli.dynamics.solve import solve
from gearcli import analyse
from gearcli import load_mechanism
from gearcli.spatial import align_z
from gearcli.io.urdf_reader import load_urdf, parse_urdf
from oracles import joint_efforts
from gearcli.report.urdf_writer import export_urdf

pin = pytest.importorskip("pinocchio")

MECH_DIR = Path(__file__).resolve().parents[1] / "mechanisms"
GEARED_ARM = MECH_DIR / "geared_arm.urdf"
TOL = 1e-9
RESULT_FIELDS = ("motor", "tau", "joint", "gear_t", "gear_sep", "gear_radial", "gear_axial")


def _erd_robots() -> Path | None:
    for p in map(Path, sys.path):
        d = p / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if d.is_dir():
            return d
        for up in (p.parent, p.parent.parent, p.parents[3] if len(p.parents) > 3 else p):
            d = up / "share" / "example-robot-data" / "robots"
            if d.is_dir():
                return d
    return None


ERD = _erd_robots()
needs_erd = pytest.mark.skipif(ERD is None, reason="example-robot-data not installed")


def erd(rel: str) -> Path:
    return ERD / rel


def talos_left_arm(tmp_path) -> Path:
    """Talos' left arm as shipped: its shoulder transmission names arm_left_1_joint, which
    the file lacks (gearcli reports that, see test_talos_arm_dangling_transmission); drop it."""
    text = erd("talos_data/robots/talos_left_arm.urdf").read_text()
    text, n = re.subn(r'\s*<transmission name="arm_left_1_trans">.*?</transmission>', "", text, flags=re.S)
    assert n == 1
    out = tmp_path / "talos_left_arm.urdf"
    out.write_text(text)
    return out


# --------------------------------------------------------------------------------------
# Pinocchio cross-check
# --------------------------------------------------------------------------------------
def trajectory(dof: int, n: int = 25, seed: int = 0):
    """Smooth q, qd, qdd (n, dof): a different sinusoid for every joint."""
    rng = np.random.default_rng(seed)
    amp, w, ph = rng.uniform(0.3, 1.2, dof), rng.uniform(0.5, 3.0, dof), rng.uniform(0, 2 * np.pi, dof)
    t = np.linspace(0.0, 2.0, n)[:, None]
    return amp * np.sin(w * t + ph), amp * w * np.cos(w * t + ph), -amp * w * w * np.sin(w * t + ph)


def pinocchio_loads(path: Path, mech, q_all, qd_all, qdd_all):
    """Pinocchio's joint torques (n, J) and joint forces (n, J, 6) [f; m] in each joint's
    frame (the URDF child frame), for every gearcli joint (by name), mimic joints free."""
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    ids = [model.getJointId(jt.name) for jt in mech.joints]
    assert all(i < model.njoints for i in ids)
    assert model.nv == len(mech.joints)
    n, J = q_all.shape
    tau = np.zeros((n, J))
    f = np.zeros((n, J, 6))
    for s in range(n):
        qp, vp, ap = pin.neutral(model), np.zeros(model.nv), np.zeros(model.nv)
        for ji, jid in enumerate(ids):
            jm = model.joints[jid]
            if jm.nq == 2:  # continuous joint: (cos, sin)
                qp[jm.idx_q:jm.idx_q + 2] = np.cos(q_all[s, ji]), np.sin(q_all[s, ji])
            else:
                qp[jm.idx_q] = q_all[s, ji]
            vp[jm.idx_v], ap[jm.idx_v] = qd_all[s, ji], qdd_all[s, ji]
        t = pin.rnea(model, data, qp, vp, ap)
        for ji, jid in enumerate(ids):
            tau[s, ji] = t[model.joints[jid].idx_v]
            f[s, ji] = np.r_[data.f[jid].linear, data.f[jid].angular]
    return tau, f


def transmitted_wrench(an, res):
    """gearcli's whole wrench through each joint, (n, J, 6) in the URDF child frame: the
    reaction with its axial component replaced by the torque (force) acting across it."""
    eff = joint_efforts(an, res)
    W = res.joint.copy()
    for ji, jt in enumerate(an.mech.joints):
        W[:, ji, 5 if jt.type == "revolute" else 2] = eff[:, ji]
        A = align_z(jt.source["axis"])  # gearcli joint frame -> URDF child frame
        W[:, ji, :3] = W[:, ji, :3] @ A.T
        W[:, ji, 3:] = W[:, ji, 3:] @ A.T
    return W, eff


def rel(a, b) -> float:
    """The suite's metric with a floor of 1 (N, N*m): some loads of these robots are
    identically zero (e.g. Romeo's ideal couplings).  Never looser than the former
    max|a - b| / (1 + max|b|)."""
    return rel_err(a, b, tiny=1.0)


def check_against_pinocchio(path: Path, method: str = "full", offsets=None, n: int = 25):
    mech = load_urdf(path)
    an = analyse(mech)
    q, qd, qdd = trajectory(an.dof, n=n)
    res = solve(an, q, qd, qdd, method=method)
    q_all, qd_all, qdd_all = q @ an.S.T, qd @ an.S.T, qdd @ an.S.T
    if offsets:
        for name, c in offsets.items():
            q_all[:, [jt.name for jt in mech.joints].index(name)] += c
    tau_pin, f_pin = pinocchio_loads(path, mech, q_all, qd_all, qdd_all)
    W, eff = transmitted_wrench(an, res)
    assert rel(res.tau, tau_pin @ an.S) < TOL          # tau = S^T tau_full (virtual work)
    assert rel(res.motor @ an.A.T, tau_pin @ an.S) < TOL
    assert rel(eff, tau_pin) < TOL                      # torque across every joint
    assert rel(W, f_pin) < TOL                          # data.f, every joint, every sample
    return mech, an, res, tau_pin


ARMS = ["ur_description/urdf/ur5_robot.urdf", "panda_description/urdf/panda.urdf",
        "xarm_description/urdf/xarm7.urdf", "kinova_description/robots/kinova.urdf",
        "z1_description/urdf/z1.urdf"]


@needs_erd
@pytest.mark.parametrize("rel_path", ARMS)
def test_arms_match_pinocchio(rel_path):
    check_against_pinocchio(erd(rel_path))


@needs_erd
def test_talos_arm_with_transmissions_matches_pinocchio(tmp_path):
    check_against_pinocchio(talos_left_arm(tmp_path))


@needs_erd
@pytest.mark.parametrize("rel_path", ["talos_data/robots/talos_full_v2.urdf",
                                      "romeo_description/urdf/romeo.urdf",
                                      "tiago_pro_description/robots/tiago_pro.urdf"])
def test_branched_robots_with_mimic_match_pinocchio(rel_path):
    """Humanoids: the primary links form a tree; mimic joints across different parents."""
    mech, an, res, _ = check_against_pinocchio(erd(rel_path), n=8)
    assert an.open_loop == "tree" and mech.open_loop == "tree"
    assert any(gp.joints is not None and mech.joints[[j.name for j in mech.joints].index(gp.joints[0])].parent
               != mech.joints[[j.name for j in mech.joints].index(gp.joints[1])].parent for gp in mech.gears)


# cases whose block solve needs the general path for two-joint motors / joint couplings
NEEDS_GENERAL_BLOCKS = {"talos_left_arm", "talos_data/robots/talos_full_v2.urdf",
                        "tiago_pro_description/robots/tiago_pro.urdf"}
BLOCK_CASES = sorted(NEEDS_GENERAL_BLOCKS) + ["geared_arm", "xarm_description/urdf/xarm7.urdf",
                                              "panda_description/urdf/panda.urdf",
                                              "romeo_description/urdf/romeo.urdf"]


@needs_erd
@pytest.mark.parametrize("case", BLOCK_CASES)
def test_block_schedule_equals_full_solve(case, tmp_path):
    """The fast block solve must handle motors acting on two joints (differentials) and
    joint couplings (mimic): their wrenches are not one wrench applied +- to two links."""
    path = (talos_left_arm(tmp_path) if case == "talos_left_arm" else
            GEARED_ARM if case == "geared_arm" else erd(case))
    an = analyse(load_urdf(path))
    q, qd, qdd = trajectory(an.dof, n=6)
    full = solve(an, q, qd, qdd, method="full")
    block = solve(an, q, qd, qdd, method="block", verify=True)
    assert block.residual < 1e-9
    for f in RESULT_FIELDS:
        assert rel(getattr(block, f), getattr(full, f)) < 1e-9, f


# --------------------------------------------------------------------------------------
# transmissions: motor torques follow the documented mapping
# --------------------------------------------------------------------------------------
def _reduction(text: str, transmission: str, tag: str, name: str) -> float:
    block = re.search(rf'<transmission name="{transmission}".*?</transmission>', text, re.S).group(0)
    el = re.search(rf'<{tag} name="{name}">.*?</{tag}>', block, re.S).group(0)
    return float(re.search(r"<mechanicalReduction>\s*([-0-9.eE+]+)\s*<", el).group(1))


@needs_erd
def test_simple_transmission_reduction():
    """xArm7: every SimpleTransmission has mechanicalReduction 100: tau_joint = 100 tau_motor."""
    mech, an, res, tau_pin = check_against_pinocchio(erd("xarm_description/urdf/xarm7.urdf"))
    text = erd("xarm_description/urdf/xarm7.urdf").read_text()
    for mi, m in enumerate(mech.motors):
        jname = m.joints[0][0]
        n = _reduction(text, f"tran{jname[-1]}", "actuator", m.name)
        assert n == 100.0
        ji = [jt.name for jt in mech.joints].index(jname)
        assert rel(n * res.motor[:, mi], tau_pin[:, ji]) < TOL


@needs_erd
def test_differential_transmission_mapping(tmp_path):
    """Talos wrist (ros_control DifferentialTransmission):
    tau_j1 = n_j1 (n_a1 tau_a1 + n_a2 tau_a2), tau_j2 = n_j2 (n_a1 tau_a1 - n_a2 tau_a2)."""
    path = talos_left_arm(tmp_path)
    mech, an, res, tau_pin = check_against_pinocchio(path)
    text = path.read_text()
    na1 = _reduction(text, "wrist_left_trans", "actuator", "arm_left_6_motor")
    na2 = _reduction(text, "wrist_left_trans", "actuator", "arm_left_7_motor")
    nj1 = _reduction(text, "wrist_left_trans", "joint", "arm_left_6_joint")
    nj2 = _reduction(text, "wrist_left_trans", "joint", "arm_left_7_joint")
    assert (na1, na2, nj1, nj2) == (-1.0, 1.0, -1.0, -1.0)
    names = [m.name for m in mech.motors]
    ta1, ta2 = res.motor[:, names.index("arm_left_6_motor")], res.motor[:, names.index("arm_left_7_motor")]
    jn = [jt.name for jt in mech.joints]
    assert rel(nj1 * (na1 * ta1 + na2 * ta2), tau_pin[:, jn.index("arm_left_6_joint")]) < TOL
    assert rel(nj2 * (na1 * ta1 - na2 * ta2), tau_pin[:, jn.index("arm_left_7_joint")]) < TOL
    assert np.max(np.abs(ta1)) > 1e-3 and np.max(np.abs(ta2)) > 1e-3


@needs_erd
def test_pr2_wrist_transmission_mapping():
    """PR2 WristTransmission: tau_flex = n_f (n_r tau_r - n_l tau_l),
    tau_roll = n_ro (-n_r tau_r - n_l tau_l)."""
    path = erd("pr2_description/urdf/pr2.urdf")
    mech, an, res, tau_pin = check_against_pinocchio(path, n=8)
    text = path.read_text()
    block = re.search(r'<transmission name="r_wrist_trans".*?</transmission>', text, re.S).group(0)

    def red(tag):
        return float(re.search(rf'<{tag} mechanicalReduction="([-0-9.eE+]+)"', block).group(1))
    nr, nl, nf, nro = red("rightActuator"), red("leftActuator"), red("flexJoint"), red("rollJoint")
    names = [m.name for m in mech.motors]
    tr, tl = res.motor[:, names.index("r_wrist_r_motor")], res.motor[:, names.index("r_wrist_l_motor")]
    jn = [jt.name for jt in mech.joints]
    assert rel(nf * (nr * tr - nl * tl), tau_pin[:, jn.index("r_wrist_flex_joint")]) < TOL
    assert rel(nro * (-nr * tr - nl * tl), tau_pin[:, jn.index("r_wrist_roll_joint")]) < TOL


@needs_erd
def test_unsupported_and_ignored_transmissions_are_reported():
    talos = load_urdf(erd("talos_data/robots/talos_full_v2.urdf"))
    half = [w for w in talos.warnings if "HalfDifferentialTransmission" in w]
    assert len(half) == 1 and ":428: transmission 'talos_trans': " in half[0]
    assert "head_1_joint" in [m.name for m in talos.motors]  # driven directly instead
    kinova = load_urdf(erd("kinova_description/robots/kinova.urdf"))
    assert sum("drives fixed joint" in w for w in kinova.warnings) == 4
    assert [m.joints for m in kinova.motors][0] == (("j2s6s200_joint_1", 160.0),)


@needs_erd
def test_talos_arm_dangling_transmission():
    """The shipped talos_left_arm.urdf: a transmission names a joint the file lacks."""
    path = erd("talos_data/robots/talos_left_arm.urdf")
    with pytest.raises(MechanismError) as exc:
        load_urdf(path)
    line = path.read_text().splitlines().index('  <transmission name="arm_left_1_trans">') + 1
    assert exc.value.lines() == [f"{path}:{line}: transmission 'arm_left_1_trans': transmission "
                                 "'arm_left_1_trans' names unknown joint 'arm_left_1_joint'"]


# --------------------------------------------------------------------------------------
# synthetic URDFs: mimic offset and chains, rack and pinion, fixed-joint lumping
# --------------------------------------------------------------------------------------
def _inertial(m, xyz="0.05 0.01 -0.02", rpy="0.3 -0.2 0.5", I="0.002 0.0001 -0.0002 0.003 0.0003 0.0025"):
    ixx, ixy, ixz, iyy, iyz, izz = I.split()
    return (f'<inertial><origin xyz="{xyz}" rpy="{rpy}"/><mass value="{m}"/>'
            f'<inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" iyy="{iyy}" iyz="{iyz}" izz="{izz}"/></inertial>')


SYNTHETIC = f"""<?xml version="1.0"?>
<robot name="synthetic">
  <link name="base"/>
  <link name="a">{_inertial(2.0)}</link>
  <link name="b">{_inertial(1.5, "0.1 0 0", "0 0.4 0")}</link>
  <link name="b_tool">{_inertial(0.4, "0.02 0.03 0.01", "0.1 0.2 0.3")}</link>
  <link name="c">{_inertial(0.8, "0 0.05 0")}</link>
  <link name="d">{_inertial(0.3, "0.01 0 0.02")}</link>
  <link name="rack">{_inertial(0.2, "0 0 0", "0 0 0")}</link>
  <joint name="ja" type="revolute">
    <parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.2" rpy="0.1 0.2 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="1"/>
  </joint>
  <joint name="jb" type="continuous">
    <parent link="a"/><child link="b"/>
    <origin xyz="0.3 0.05 0" rpy="0 0.5 0"/><axis xyz="1 2 2"/>
  </joint>
  <joint name="tool" type="fixed">
    <parent link="b"/><child link="b_tool"/><origin xyz="0.2 0 0.1" rpy="0.4 0 -0.2"/>
  </joint>
  <joint name="jc" type="revolute">
    <parent link="b_tool"/><child link="c"/>
    <origin xyz="0.1 0 0" rpy="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="1"/>
    <mimic joint="ja" multiplier="-0.7" offset="0.25"/>
  </joint>
  <joint name="jd" type="revolute">
    <parent link="c"/><child link="d"/>
    <origin xyz="0 0.2 0"/><axis xyz="0 0 -1"/>
    <limit lower="-3" upper="3" effort="10" velocity="1"/>
    <mimic joint="jc" multiplier="1.3" offset="-0.4"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="a"/><child link="rack"/>
    <origin xyz="0 0.1 0" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/>
    <mimic joint="jb" multiplier="0.02" offset="0.01"/>
  </joint>
</robot>
"""


def test_mimic_offsets_chains_rack_and_pinion_against_pinocchio(tmp_path):
    """jc = -0.7 ja + 0.25 (different parents), jd = 1.3 jc - 0.4 (a mimic of a mimic),
    a prismatic rack = 0.02 jb + 0.01; a fixed joint lumps b_tool into b."""
    path = tmp_path / "synthetic.urdf"
    path.write_text(SYNTHETIC)
    mech = load_urdf(path)
    assert [lk.name for lk in mech.links] == ["base", "a", "b", "c", "d", "rack"]
    an = analyse(mech)
    assert an.dof == 2 and an.independent_names == ("ja", "jb")
    c_jc = 0.25
    offsets = {"jc": c_jc, "jd": 1.3 * c_jc - 0.4, "slide": 0.01}
    check_against_pinocchio(path, offsets=offsets)
    # the couplings are linear in the offset-shifted coordinates
    jn = [jt.name for jt in mech.joints]
    S = an.S
    assert S[jn.index("jc"), 0] == pytest.approx(-0.7) and S[jn.index("jd"), 0] == pytest.approx(-0.91)
    assert S[jn.index("slide"), 1] == pytest.approx(0.02)


def test_fixed_joint_lumping_is_exact(tmp_path):
    path = tmp_path / "synthetic.urdf"
    path.write_text(SYNTHETIC)
    mech = load_urdf(path)
    model = pin.buildModelFromUrdf(str(path))
    for jt in mech.joints:
        Y = model.inertias[model.getJointId(jt.name)]
        link = mech.link(jt.child)
        assert link.mass == pytest.approx(Y.mass, rel=1e-14)
        assert np.allclose(link.com, Y.lever, rtol=0, atol=1e-15)
        assert np.allclose(link.inertia, Y.inertia, rtol=0, atol=1e-15)


def test_links_without_inertial_are_massless():
    mech = parse_urdf("""<robot name="r"><link name="base"/><link name="x"/>
      <joint name="j" type="continuous"><parent link="base"/><child link="x"/></joint></robot>""")
    assert mech.link("x").mass == 0.0 and not mech.link("x").inertia.any()
    assert mech.joints[0].source["axis"] == [1.0, 0.0, 0.0]  # the URDF default axis
    an = analyse(mech)
    res = solve(an, np.ones((2, 1)), np.ones((2, 1)), np.ones((2, 1)))
    assert not res.motor.any() and not res.joint.any()


# --------------------------------------------------------------------------------------
# the bundled geared URDF
# --------------------------------------------------------------------------------------
def test_geared_arm_example(run_cli):
    res = run_cli("check", GEARED_ARM)
    assert res.exit_code == 0, res.stderr
    assert "3 dof" in res.stdout
    mech = load_urdf(GEARED_ARM)
    assert mech.warnings == ()
    an = analyse(mech)
    assert an.independent_names == ("shoulder", "elbow", "finger_left_joint")
    assert [m.name for m in mech.motors] == ["shoulder_motor", "elbow_motor", "gripper_motor"]
    lead = 2 * np.pi / 0.002
    assert np.allclose(an.A, np.diag([-3.0, 50.0, lead]), rtol=1e-12)
    pair = {mech.gears[c.gear].name: c for c in an.circuits}
    assert pair["pinion-shoulder"].geometry is not None            # tooth forces reported
    assert pair["pinion-shoulder"].geometry.r_j == pytest.approx(0.03)
    assert pair["mimic_finger_right_joint"].geometry is None        # ideal coupling
    assert mech.link("forearm").mass == pytest.approx(3.0)          # the tool is lumped in
    # equivalent torques against Pinocchio on the same file (mimic joints projected by S)
    q, qd, qdd = trajectory(an.dof)
    r = solve(an, q, qd, qdd, method="full", verify=True)
    assert r.residual < 1e-12
    tau_pin, _ = pinocchio_loads(GEARED_ARM, mech, q @ an.S.T, qd @ an.S.T, qdd @ an.S.T)
    assert rel(r.tau, tau_pin @ an.S) < TOL
    jn = [jt.name for jt in mech.joints]
    assert rel(50.0 * r.motor[:, 1], tau_pin[:, jn.index("elbow")]) < TOL
    assert rel(lead * r.motor[:, 2], tau_pin[:, jn.index("finger_left_joint")] + tau_pin[:, jn.index("finger_right_joint")]) < TOL


def test_geared_arm_solve_cli(run_cli, tmp_path):
    an = analyse(load_urdf(GEARED_ARM))
    q, qd, qdd = trajectory(an.dof, n=5)
    names = an.independent_names
    lines = ["t," + ",".join([f"q:{n}" for n in names] + [f"qd:{n}" for n in names] + [f"qdd:{n}" for n in names])]
    for i in range(5):
        lines.append(",".join(repr(float(x)) for x in [0.01 * i, *q[i], *qd[i], *qdd[i]]))
    traj = tmp_path / "traj.csv"
    traj.write_text("\n".join(lines) + "\n")
    res = run_cli("solve", GEARED_ARM, traj, "-o", tmp_path / "loads.csv", "--method", "full")
    assert res.exit_code == 0, res.stderr
    header = (tmp_path / "loads.csv").read_text().splitlines()[0]
    assert "elbow_motor" in header and "gripper_motor" in header


# --------------------------------------------------------------------------------------
# export
# --------------------------------------------------------------------------------------
def _same_results(an1, an2, n=30):
    q, qd, qdd = trajectory(an1.dof, n=n, seed=3)
    q, qd, qdd = 2 * q, 2 * qd, 2 * qdd
    r1, r2 = solve(an1, q, qd, qdd), solve(an2, q, qd, qdd)
    for f in RESULT_FIELDS:
        a, b = getattr(r1, f), getattr(r2, f)
        assert a.shape == b.shape
        assert np.max(np.abs(a - b), initial=0.0) <= 1e-12 * (1.0 + np.max(np.abs(a), initial=0.0)), f


@pytest.mark.parametrize("name", ["paper_2dof", "bendix_wrist", "coaxial_fig5"])
def test_export_round_trip(name, tmp_path):
    an = analyse(load_mechanism(MECH_DIR / f"{name}.yaml"))
    out = tmp_path / f"{name}.urdf"
    export_urdf(an.mech, out)
    back = load_urdf(out)
    assert back.warnings == ()
    an2 = analyse(back)
    assert an2.independent_names == an.independent_names
    assert an2.name_of(an2.primary) == an.name_of(an.primary)
    assert [an2.name_of(b) for b in an2.schedule] == [an.name_of(b) for b in an.schedule]
    assert np.allclose(an2.A, an.A, rtol=0, atol=1e-14)
    _same_results(an, an2)


def test_export_of_a_urdf_import_round_trips(tmp_path):
    """geared_arm.urdf: mimic with gear geometry, ideal prismatic mimic, reductions."""
    an = analyse(load_urdf(GEARED_ARM))
    out = tmp_path / "again.urdf"
    export_urdf(an, out)
    an2 = analyse(load_urdf(out))
    assert [m.joints for m in an2.mech.motors] == [m.joints for m in an.mech.motors]
    _same_results(an, an2)


@pytest.mark.parametrize("name", ["paper_2dof", "bendix_wrist", "rack_axis", "helical_reduction"])
def test_yourdfpy_loads_export_without_warnings(name, caplog):
    import yourdfpy

    text = export_urdf(load_mechanism(MECH_DIR / f"{name}.yaml"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with caplog.at_level(logging.DEBUG):
            u = yourdfpy.URDF.load(io.BytesIO(text.encode()), build_scene_graph=True, load_meshes=False)
            assert u.validate(), u.errors
    assert caplog.records == []
    mech = load_mechanism(MECH_DIR / f"{name}.yaml")
    assert [j.name for j in u.robot.joints] == [j.name for j in mech.joints]
    assert [lk.name for lk in u.robot.links] == [lk.name for lk in mech.links]
    assert u.base_link == mech.base
    # derived mimics for other tools: J5 follows J1 (paper, 5-1 spur pair, e = -3)
    if name == "paper_2dof":
        j5 = u.joint_map["J5"]
        assert j5.mimic.joint == "J1" and j5.mimic.multiplier == -3.0


def test_pinocchio_reads_export(tmp_path):
    """Pinocchio on the exported Bendix wrist (gears dropped, joints free) projected by S."""
    an = analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))
    out = tmp_path / "bendix.urdf"
    export_urdf(an, out)
    q, qd, qdd = trajectory(an.dof, n=10)
    res = solve(an, q, qd, qdd)
    tau_pin, _ = pinocchio_loads(out, an.mech, q @ an.S.T, qd @ an.S.T, qdd @ an.S.T)
    assert rel(res.tau, tau_pin @ an.S) < TOL


def test_bundled_schedules_unchanged():
    """The tree generalisation is opt-in: YAML mechanisms keep the paper's chain."""
    an = analyse(load_mechanism(MECH_DIR / "paper_2dof.yaml"))
    assert an.open_loop == "chain"
    assert [an.name_of(b) for b in an.schedule] == [["2"], ["4"], ["1"], ["3"], ["5"]]
    an = analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))
    assert [set(an.name_of(b)) for b in an.schedule] == [{"2", "3"}, {"6"}, {"8"}, {"1"}, {"4"}, {"5"}, {"7"}]


# --------------------------------------------------------------------------------------
# bad input: one line per problem, file:line: element: message, exit 2
# --------------------------------------------------------------------------------------
def robot(body: str, ns: bool = False) -> str:
    xmlns = ' xmlns:gearcli="https://gearcli.dev/urdf/1"' if ns else ""
    return f'<?xml version="1.0"?>\n<robot name="r"{xmlns}>\n{body}</robot>\n'


TWO_LINKS = """  <link name="base"/>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
"""
ARM_JOINT = """  <joint name="j1" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
"""


def line_of(text: str, needle: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), 1) if needle in line)


BAD = {
    "malformed_xml": (robot(TWO_LINKS + '  <joint name="j1" type="revolute">\n    <parent link="base">\n  </joint>\n'),
                      [("", "</joint>", r"malformed XML: .*parent")]),
    "unknown_child_link": (robot(TWO_LINKS + ARM_JOINT.replace('child link="arm"', 'child link="hand"')),
                           [("joint 'j1'", 'child link="hand"', "unknown child link 'hand'")]),
    "unknown_parent_link": (robot(TWO_LINKS + ARM_JOINT.replace('parent link="base"', 'parent link="bse"')),
                            [("joint 'j1'", 'parent link="bse"', "unknown parent link 'bse'")]),
    "floating_joint": (robot(TWO_LINKS + ARM_JOINT.replace('type="revolute"', 'type="floating"')),
                       [("joint 'j1'", '<joint name="j1"', "joint type 'floating' is not supported")]),
    "planar_joint": (robot(TWO_LINKS + ARM_JOINT.replace('type="revolute"', 'type="planar"')),
                     [("joint 'j1'", '<joint name="j1"', "joint type 'planar' is not supported")]),
    "unknown_joint_type": (robot(TWO_LINKS + ARM_JOINT.replace('type="revolute"', 'type="ball"')),
                           [("joint 'j1'", '<joint name="j1"', "unknown joint type 'ball'")]),
    "mimic_of_missing_joint": (robot(TWO_LINKS + ARM_JOINT.replace("  </joint>", '    <mimic joint="j0"/>\n  </joint>')),
                               [("joint 'j1'.mimic", "<mimic", "joint 'j1' mimics unknown joint 'j0'")]),
    "mimic_cycle": (robot(TWO_LINKS + '  <link name="hand"/>\n' + ARM_JOINT.replace("  </joint>", '    <mimic joint="j2"/>\n  </joint>')
                          + '  <joint name="j2" type="continuous">\n    <parent link="arm"/><child link="hand"/>\n'
                          '    <mimic joint="j1" multiplier="2"/>\n  </joint>\n'),
                    [("joint 'j1'.mimic", '<mimic joint="j2"', r"mimic cycle: j1 -> j2 -> j1")]),
    "transmission_missing_joint": (robot(TWO_LINKS + ARM_JOINT + """  <transmission name="t1">
    <type>transmission_interface/SimpleTransmission</type>
    <joint name="j9"/>
    <actuator name="m1"><mechanicalReduction>10</mechanicalReduction></actuator>
  </transmission>
"""), [("transmission 't1'", '<transmission name="t1"', "transmission 't1' names unknown joint 'j9'")]),
    "duplicate_link": (robot(TWO_LINKS + '  <link name="arm"/>\n' + ARM_JOINT),
                       [("link 'arm'", '<link name="arm"/>', "duplicate link name 'arm'")]),
    "negative_mass": (robot(TWO_LINKS.replace('mass value="1"', 'mass value="-1"') + ARM_JOINT),
                      [("link 'arm'.inertial", "<mass", "mass must not be negative")]),
    "missing_inertia_entries": (robot(TWO_LINKS.replace(' iyz="0"', "") + ARM_JOINT),
                                [("link 'arm'.inertial", "<inertia", "<inertia> misses iyz")]),
    "bad_number": (robot(TWO_LINKS + ARM_JOINT.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 x"/>')),
                   [("joint 'j1'", "<axis", r'xyz="0 0 x" is not 3 finite numbers')]),
    "two_roots": (robot(TWO_LINKS + '  <link name="stray"/>\n' + ARM_JOINT),
                  [("", '<robot name="r"', r"several root links \(base, stray\)")]),
    "zero_multiplier": (robot(TWO_LINKS + '  <link name="hand"/>\n' + ARM_JOINT
                              + '  <joint name="j2" type="continuous">\n    <parent link="arm"/><child link="hand"/>\n'
                              '    <mimic joint="j1" multiplier="0"/>\n  </joint>\n'),
                        [("joint 'j2'.mimic", '<mimic joint="j1"', "mimic multiplier must not be zero")]),
    "gear_unknown_link": (robot(TWO_LINKS + ARM_JOINT + '  <gearcli:gear name="g" j="arm" k="wheel" ratio="2"/>\n', ns=True),
                          [("gearcli:gear 'g'", "<gearcli:gear", "unknown link 'wheel'")]),
    "unknown_gearcli_element": (robot(TWO_LINKS + ARM_JOINT + '  <gearcli:gearbox name="g"/>\n', ns=True),
                                [("gearcli:gearbox", "<gearcli:gearbox", "unknown gearcli element gearcli:gearbox")]),
    "not_a_robot": ('<?xml version="1.0"?>\n<sdf version="1.6"/>\n',
                    [("", "<sdf", "not a URDF: the root element is <sdf>, expected <robot>")]),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_urdf(case, run_cli, tmp_path):
    text, expected = BAD[case]
    path = tmp_path / f"{case}.urdf"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2, (res.stdout, res.stderr)
    assert res.stdout == "" and "Traceback" not in res.stderr
    got = res.stderr.splitlines()
    assert len(got) == len(expected), got
    for line, (element, needle, pattern) in zip(got, expected):
        prefix = f"{path}:{line_of(text, needle)}: " + (f"{element}: " if element else "")
        assert line.startswith(prefix), (line, prefix)
        assert re.search(pattern, line[len(prefix):]), line
    with pytest.raises(MechanismError) as exc:
        load_urdf(path)
    assert exc.value.lines() == got


def test_mimic_on_a_fixed_joint_is_ignored_with_a_warning():
    text = robot(TWO_LINKS + '  <link name="pad"/>\n' + ARM_JOINT
                 + '  <joint name="f" type="fixed">\n    <parent link="arm"/><child link="pad"/>\n'
                 '    <mimic joint="j1"/>\n  </joint>\n')
    mech = parse_urdf(text, "m.urdf")
    assert mech.gears == ()
    assert mech.warnings == (f"m.urdf:{line_of(text, '<mimic')}: joint 'f': <mimic> of a fixed joint is ignored",)


def test_export_command_round_trip(run_cli, mech_dir, tmp_path):
    out = tmp_path / "bendix.urdf"
    r = run_cli("export", mech_dir / "bendix_wrist.yaml", "-o", out)
    assert r.exit_code == 0, r.stderr
    a = analyse(load_mechanism(mech_dir / "bendix_wrist.yaml"))
    b = analyse(load_urdf(out))
    q, qd, qdd = trajectory(a.dof, n=5)
    ra, rb = solve(a, q, qd, qdd), solve(b, q, qd, qdd)
    assert rel(rb.motor, ra.motor) < 1e-12 and rel(rb.joint, ra.joint) < 1e-12
    r = run_cli("check", out)
    assert r.exit_code == 0, r.stderr


def test_reader_warnings_are_printed_as_every_other_warning(run_cli, tmp_path):
    """``file:line: place: warning: what``, as the plausibility warnings (they were
    ``warning: file:line: place: what``; issue 34, section 5); --strict makes them errors."""
    text = robot(TWO_LINKS + '  <link name="pad"/>\n' + ARM_JOINT
                 + '  <joint name="f" type="fixed">\n    <parent link="arm"/><child link="pad"/>\n'
                 '    <mimic joint="j1"/>\n  </joint>\n')
    path = tmp_path / "m.urdf"
    path.write_text(text)
    r = run_cli("check", path)
    assert r.exit_code == 0
    line = f"{path}:{line_of(text, '<mimic')}: joint 'f': warning: <mimic> of a fixed joint is ignored"
    assert line in r.stderr.splitlines()
    r = run_cli("check", path, "--strict")
    assert r.exit_code == 2 and any(s.endswith("(--strict)") and "<mimic> of a fixed joint" in s
                                    for s in r.stderr.splitlines())
