"""External loads (``loads:``, ``gearcli:load``, ``load:<name>:<c>`` trajectory columns).

Independent references: torques worked out by hand on a one-link geared arm (lever x force
/ gear ratio); Pinocchio's RNEA with ``fext`` on models built from the test's own geometry
(:mod:`oracles`: the paper's Eq. (1) products and the test's own transforms, the joint
coupling from the test's own ratios), the external wrench converted to Pinocchio's joint
frames by the test's own poses; the power balance on kinematics differentiated from the
test's own link poses.
"""
from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from factories_own import dh_geared
from gearcli import MechanismError, analyse, load_mechanism, parse_mechanism, solve
from gearcli.report.urdf_writer import export_urdf
from metrics import rel_err
from oracles import OwnJoint, OwnLink, OwnMech, OwnPinocchio, SineTrajectory, fd_motion, frame_with_z, homog, \
    kinetic_power, poses

ROOT = Path(__file__).resolve().parents[1]
TOL = 1e-9

# --- a one-link arm driven through a 4:1 spur reduction, for hand checks ------------------------
# Link 1 (gear of 40 teeth, pitch radius 0.1 m) turns about z0 at the origin; pinion 2 (10 teeth,
# radius 0.025 m) on the base at x = 0.125 m drives it; the motor drives the pinion.  Rolling:
# theta_2 = -4 theta_1.  Gravity along -z does no work (every axis is vertical).
ARM = """\
name: arm1
gravity: [0, 0, -9.81]
base: "0"
end_effector: "1"
links:
  - {name: "0"}
  - {name: "1", mass: 2.0, com: [0.2, 0, 0], inertia: [0.001, 0.02, 0.02]}
  - {name: "2", mass: 0.1, inertia: [0.00001, 0.00001, 0.00001]}
joints:
  - {name: J1, parent: "0", child: "1", origin: {xyz: [0, 0, 0]}, axis: [0, 0, 1]}
  - {name: J2, parent: "0", child: "2", origin: {xyz: [0.125, 0, 0]}, axis: [0, 0, 1]}
gears:
  - {name: "2-1", links: ["2", "1"], kind: external, teeth: [10, 40], mesh_point: [0.1, 0, 0]}
motors:
  - {name: m, link: "2"}
loads:
  - {name: tip, link: "1", point: [0.5, 0, 0], frame: FRAME, force: [0, 10, 0], moment: [0, 0, 0]}
"""


def arm(frame="base", **repl):
    text = ARM.replace("FRAME", frame)
    for old, new in repl.items():
        text = text.replace(old, new)
    return analyse(parse_mechanism(text))


def static(q):
    q = np.asarray(q, float).reshape(-1, 1)
    return q, np.zeros_like(q), np.zeros_like(q)


def test_static_tip_force_by_hand():
    """Holding a 10 N force at 0.5 m: the environment's torque on link 1 is 0.5 x 10 x
    cos(q) (force along base y) or 0.5 x 10 (force along the link's own y).  Virtual work,
    tau_m dtheta_2 + T_ext dtheta_1 = 0 with dtheta_2 = -4 dtheta_1, gives tau_m = T_ext / 4:
    1.25 N*m at q = 0.  The tooth force on the pinion is -T_ext / 0.1 m (it holds link 1
    back)."""
    q = np.array([0.0, 0.7, -2.0, np.pi / 2])
    res = solve(arm("base"), *static(q), verify=True)
    assert res.residual < 1e-12
    np.testing.assert_allclose(res.motor[:, 0], 0.5 * 10 * np.cos(q) / 4, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(res.gear_t[:, 0], -0.5 * 10 * np.cos(q) / 0.1, rtol=1e-12, atol=1e-12)
    res = solve(arm("link"), *static(q), method="full")
    np.testing.assert_allclose(res.motor[:, 0], np.full(4, 1.25), rtol=1e-12)
    # a pure moment of 3 N*m about z0, no force: 3 / 4 at every angle
    res = solve(arm("base", **{"force: [0, 10, 0], moment: [0, 0, 0]": "moment: [0, 0, 3]"}), *static(q))
    np.testing.assert_allclose(res.motor[:, 0], np.full(4, 0.75), rtol=1e-12)


def test_static_tip_force_bearing_reaction_by_hand():
    """At q = 0 (J1's frame = the base frame) the forces on link 1 are: the bearing
    reaction f, the weight (0, 0, -2 x 9.81), the tip force (0, 10, 0) and the tooth force of
    the pinion at (0.1, 0, 0): 5 N*m / 0.1 m = 50 N along -y (it holds link 1 back) and the
    separating force 50 tan(20 deg) along -x (away from the pinion).  They sum to zero."""
    an = arm("base")
    res = solve(an, *static([0.0]))
    t = 0.5 * 10 / 0.1
    sep = t * np.tan(np.radians(20.0))
    f = res.joint[0, 0, :3]
    np.testing.assert_allclose(f, [sep, -10.0 + t, 2.0 * 9.81], rtol=1e-12, atol=1e-12)


# --- the paper's arm and a random geared arm, against Pinocchio with fext ---------------------------

PAPER_LOADS = """
loads:
  - {name: tip, link: "2", point: [0, 0, 0], frame: base, force: [3, -4, 5], moment: [0.1, 0.2, -0.3]}
  - {name: upper, link: "1", point: [-0.1, 0.02, 0.03], frame: link, force: [1, 2, -1], moment: [0.5, 0, 0.2]}
  - {name: shaft, link: "4", point: [0.05, 0.01, 0], frame: link, force: [0, 0.5, 2], moment: [0.3, 0.1, 0]}
"""


def paper_own() -> OwnMech:
    """The test's own description of mechanisms/paper_2dof.yaml (Fig. 1): D-H rows of J1-J3,
    J4 along x1 at (-0.2, 0, 0.05) of link 1, J5 on the base at (0.12, 0, -0.05); the paper's
    ratios e15 = -3, e43 = -1, e24 = 2 give q5 = e15 q1, q4 = e24 q2, q3 = q1 + e43 e24 q2."""
    F4 = frame_with_z([1.0, 0, 0])
    joints = [OwnJoint("J1", "0", "1", dh=(0.0, 0.0, 0.4, 0.0)), OwnJoint("J2", "1", "2", dh=(0.0, 0.0, 0.3, 0.0)),
              OwnJoint("J3", "0", "3", dh=(0.0, -0.1, 0.0, 0.0)),
              OwnJoint("J4", "1", "4", X_pj=homog(F4, [-0.2, 0, 0.05]), X_jc=homog(F4.T)),
              OwnJoint("J5", "0", "5", X_pj=homog(None, [0.12, 0, -0.05]))]
    links = {"1": OwnLink("1", 4.0, np.array([-0.2, 0, 0]), np.diag([0.005, 0.06, 0.06])),
             "2": OwnLink("2", 2.5, np.array([-0.15, 0, 0]), np.diag([0.003, 0.025, 0.025])),
             "3": OwnLink("3", 0.5, np.zeros(3), np.diag([0.0004, 0.0004, 0.0002])),
             "4": OwnLink("4", 0.3, np.zeros(3), np.diag([0.00002, 0.004, 0.004])),
             "5": OwnLink("5", 0.2, np.zeros(3), np.diag([0.00005, 0.00005, 0.00003]))}
    S = np.array([[1, 0], [0, 1], [1, -1.0 * 2.0], [0, 2.0], [-3.0, 0]])
    motors = {"motor3": ("J3", S[2]), "motor5": ("J5", S[4])}
    return OwnMech("0", links, joints, S, np.array([0, 0, -9.81]), motors)


def random_arm_loads(seed: int) -> str:
    rng = np.random.default_rng(seed)
    out = ["", "loads:"]
    for name, link, frame in (("tool", "3", "link"), ("push", "2", "base"), ("drag", "4", "link"),
                              ("tool2", "3", "base")):
        p, f, m = rng.normal(scale=0.2, size=3), rng.normal(scale=20, size=3), rng.normal(scale=3, size=3)
        out.append(f"  - {{name: {name}, link: \"{link}\", point: {p.tolist()}, frame: {frame}, "
                   f"force: {f.tolist()}, moment: {m.tolist()}}}")
    return "\n".join(out) + "\n"


def loaded_case(key: str):
    if key == "paper_2dof":
        text = (ROOT / "mechanisms" / "paper_2dof.yaml").read_text() + PAPER_LOADS
        return analyse(parse_mechanism(text)), paper_own(), yaml.safe_load(PAPER_LOADS)["loads"]
    text, om = dh_geared(int(key.split(":")[1]))
    extra = random_arm_loads(int(key.split(":")[1]))
    return analyse(parse_mechanism(text + extra)), om, yaml.safe_load(extra)["loads"]


def world_load(om, T, spec, w):
    """One load in the world, from the test's own poses ``T``: force f_w (N, 3), moment
    m_w about the load point (N, 3) and the point p_w (N, 3)."""
    Tl = T[spec["link"]]
    R = Tl[:, :3, :3]
    f, m = w[:, :3], w[:, 3:]
    if spec["frame"] == "link":
        f, m = np.einsum("nij,nj->ni", R, f), np.einsum("nij,nj->ni", R, m)
    p = np.einsum("nij,j->ni", R, np.asarray(spec["point"], float)) + Tl[:, :3, 3]
    return f, m, p


def pinocchio_tau(om, specs, values, q_all, qd_all, qdd_all):
    """Joint torques (N, J) of Pinocchio's RNEA with the loads as fext (joint frames)."""
    import pinocchio as pin

    op = OwnPinocchio(om)
    T = poses(om, q_all)
    jid = {jt.child: i + 1 for i, jt in enumerate(om.joints)}
    Xjc = {jt.child: jt.X_jc for jt in om.joints}
    N = q_all.shape[0]
    fext_all = np.zeros((N, len(om.joints) + 1, 6))
    for spec in specs:
        f, m, p = world_load(om, T, spec, values[spec["name"]])
        Tj = T[spec["link"]] @ np.linalg.inv(Xjc[spec["link"]])
        Rj, oj = Tj[:, :3, :3], Tj[:, :3, 3]
        fext_all[:, jid[spec["link"]], :3] += np.einsum("nji,nj->ni", Rj, f)
        fext_all[:, jid[spec["link"]], 3:] += np.einsum("nji,nj->ni", Rj, m + np.cross(p - oj, f))
    tau = np.zeros((N, len(om.joints)))
    for n in range(N):
        fext = pin.StdVec_Force()
        for k in range(len(om.joints) + 1):
            fext.append(pin.Force(fext_all[n, k, :3].copy(), fext_all[n, k, 3:].copy()))
        tau[n] = pin.rnea(op.model, op.data, q_all[n], qd_all[n], qdd_all[n], fext)
    return tau


def own_A(an, om):
    return np.column_stack([om.motors[m.name][1] for m in an.mech.motors])


@pytest.mark.parametrize("key", ["paper_2dof", "dh_geared:0", "dh_geared:1"])
@pytest.mark.parametrize("per_sample", [False, True])
def test_pinocchio_rnea_with_fext(key, per_sample):
    """tau_ind = S^T tau_all (virtual work; meshes do no work) with Pinocchio's fext."""
    pytest.importorskip("pinocchio")
    an, om, specs = loaded_case(key)
    assert [ld.name for ld in an.mech.loads] == [s["name"] for s in specs]
    traj = SineTrajectory(an.dof, seed=4)
    q, qd, qdd = traj(np.linspace(0.0, 2.0, 25))
    N = q.shape[0]
    rng = np.random.default_rng(9)
    if per_sample:
        values = {s["name"]: rng.normal(scale=10, size=(N, 6)) for s in specs}
        res = solve(an, q, qd, qdd, loads=values, verify=True)
    else:
        values = {s["name"]: np.tile(np.r_[s["force"], s["moment"]], (N, 1)) for s in specs}
        res = solve(an, q, qd, qdd, verify=True)
    assert res.residual < 1e-12
    tau_all = pinocchio_tau(om, specs, values, q @ om.S.T, qd @ om.S.T, qdd @ om.S.T)
    tau_ind = tau_all @ om.S
    assert rel_err(res.tau, tau_ind) < TOL
    assert rel_err(res.motor, np.linalg.solve(own_A(an, om), tau_ind.T).T) < TOL
    # the loads matter: without them the torques differ by much more than the tolerance
    bare = solve(an, q, qd, qdd, loads={s["name"]: np.zeros(6) for s in specs})
    assert rel_err(bare.tau, tau_ind) > 1e-3
    assert rel_err(solve(an, q, qd, qdd, method="full", loads=values if per_sample else None).motor,
                   res.motor) < 1e-10


def test_power_balance_with_external_loads():
    """sum motor x input rate + sum (f . v_point + m . w) = dT/dt - sum m g . v_c, the point
    velocities and angular velocities differentiated from the test's own link poses."""
    an, om, specs = loaded_case("dh_geared:2")
    traj = SineTrajectory(an.dof, seed=11)
    t = np.linspace(0.0, 3.0, 40)
    q, qd, qdd = traj(t)
    rng = np.random.default_rng(3)
    values = {s["name"]: rng.normal(scale=10, size=(len(t), 6)) for s in specs}
    res = solve(an, q, qd, qdd, loads=values)
    st = fd_motion(om, traj, t)
    dT, Pg = kinetic_power(st, om.gravity)
    h = 2e-3
    D1 = np.array([1.0, -8.0, 0.0, 8.0, -1.0]) / 12.0
    Ts = [poses(om, traj(t + k * h)[0] @ om.S.T) for k in (-2, -1, 0, 1, 2)]
    P_ext = 0.0
    for s in specs:
        f, m, _ = world_load(om, Ts[2], s, values[s["name"]])
        ps = np.stack([world_load(om, Tk, s, values[s["name"]])[2] for Tk in Ts])
        v = np.tensordot(D1, ps, axes=1) / h
        P_ext = P_ext + np.sum(f * v, axis=1) + np.sum(m * st[s["link"]]["w"], axis=1)
    assert np.max(np.abs(P_ext)) > 1.0                      # the loads do work here
    P_motor = np.sum(res.motor * (qd @ own_A(an, om)), axis=1)
    assert rel_err(P_motor + P_ext, dT - Pg) < 1e-6


# --- trajectory columns ------------------------------------------------------------------------------

def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def test_csv_columns_override_per_sample(run_cli, tmp_path):
    """load:tip:fy and load:tip:mz given per sample, fx = 2 N kept from the file: the torque
    on link 1 is 0.5 cos(q) fy - 0.5 sin(q) fx + mz and the motor's a quarter of it."""
    mech = tmp_path / "arm.yaml"
    mech.write_text(ARM.replace("FRAME", "base").replace("force: [0, 10, 0]", "force: [2, 10, 0]"))
    q = np.linspace(-1.0, 1.0, 7)
    fy = np.linspace(-30.0, 40.0, 7)
    mz = np.linspace(1.0, -2.0, 7)
    rows = [[i * 0.1, q[i], 0.0, 0.0, fy[i], mz[i]] for i in range(7)]
    traj = tmp_path / "traj.csv"
    write_csv(traj, ["t", "q:J1", "qd:J1", "qdd:J1", "load:tip:fy", "load:tip:mz"], rows)
    out = tmp_path / "out.csv"
    r = run_cli("solve", mech, traj, "-o", out, "--verify")
    assert r.exit_code == 0, r.stderr
    with open(out) as f:
        got = np.array([float(row["motor:m"]) for row in csv.DictReader(f)])
    expected = (0.5 * np.cos(q) * fy - 0.5 * np.sin(q) * 2.0 + mz) / 4
    np.testing.assert_allclose(got, expected, rtol=1e-8, atol=1e-9)   # CSV: 9 significant digits


@pytest.mark.parametrize("column,cell,pattern", [
    ("load:nope:fx", "1.0", r"column 5 'load:nope:fx': unknown load 'nope' \(mechanism loads: tip\)"),
    ("load:tip:fw", "1.0", r"column 5 'load:tip:fw': a load column is load:<name>:<component>"),
    ("load:tip:fx", "nan", r":3: column 5 'load:tip:fx': value 'nan' is not a finite number"),
])
def test_csv_bad_load_columns(run_cli, tmp_path, column, cell, pattern):
    mech = tmp_path / "arm.yaml"
    mech.write_text(ARM.replace("FRAME", "base"))
    traj = tmp_path / "traj.csv"
    write_csv(traj, ["t", "q:J1", "qd:J1", "qdd:J1", column], [[0, 0, 0, 0, 1.0], [0.1, 0, 0, 0, cell]])
    out = tmp_path / "out.csv"
    r = run_cli("solve", mech, traj, "-o", out)
    assert r.exit_code == 2
    assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert r.stderr.startswith(str(traj)), r.stderr
    assert re.search(pattern, r.stderr), r.stderr
    assert not out.exists()


def test_library_rejects_bad_load_arrays():
    an = arm("base")
    q, qd, qdd = static([0.0, 0.1])
    with pytest.raises(ValueError, match="unknown load 'nope'"):
        solve(an, q, qd, qdd, loads={"nope": np.zeros(6)})
    with pytest.raises(ValueError, match=r"expected shape \(2, 6\)"):
        solve(an, q, qd, qdd, loads={"tip": np.zeros((3, 6))})
    with pytest.raises(ValueError, match="not finite"):
        solve(an, q, qd, qdd, loads={"tip": np.array([np.nan, 0, 0, 0, 0, 0])})


# --- bad mechanism files ---------------------------------------------------------------------------

@pytest.mark.parametrize("old,new,path,pattern", [
    ('link: "1", point', 'link: "9", point', "loads[0].link", r"load on unknown link '9'$"),
    ('link: "1", point', 'link: "0", point', "loads[0].link", r"load on the base link '0'"),
    ("frame: FRAME", "frame: world", "loads[0].frame", r"expected one of: base, link; got 'world'$"),
    ("frame: FRAME", "frame: base", "loads[0].force[1]", r"(?i)nan|not a finite"),
])
def test_yaml_bad_loads(run_cli, tmp_path, old, new, path, pattern):
    text = ARM.replace(old, new).replace("FRAME", "base")
    if path.endswith("force[1]"):
        text = text.replace("force: [0, 10, 0]", "force: [0, .nan, 0]")
    mech = tmp_path / "bad.yaml"
    mech.write_text(text)
    r = run_cli("check", mech)
    assert r.exit_code == 2 and "Traceback" not in r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, lines
    lineno = text.splitlines().index(next(ln for ln in text.splitlines() if "name: tip" in ln)) + 1
    prefix = f"{mech}:{lineno}: {path}: "
    assert lines[0].startswith(prefix), (lines[0], prefix)
    assert re.search(pattern, lines[0][len(prefix):]), lines[0]
    with pytest.raises(MechanismError):
        load_mechanism(mech)


def test_yaml_missing_frame_is_refused(tmp_path):
    with pytest.raises(MechanismError, match=r"loads\[0\].*missing required key 'frame'"):
        parse_mechanism(ARM.replace("frame: FRAME, ", ""))


# --- URDF: gearcli:load, export round trip -----------------------------------------------------------

def test_export_round_trip_with_loads(tmp_path):
    """paper_2dof's D-H link frames are off their joint axes, so the export moves the load
    points (and link-frame forces) into the URDF link frames; reading back gives the same
    loads to rounding."""
    text = (ROOT / "mechanisms" / "paper_2dof.yaml").read_text() + PAPER_LOADS
    an = analyse(parse_mechanism(text))
    urdf = tmp_path / "p.urdf"
    export_urdf(an, urdf)
    assert urdf.read_text().count("<gearcli:load ") == 3
    back = analyse(load_mechanism(urdf))
    assert [ld.name for ld in back.mech.loads] == ["tip", "upper", "shaft"]
    q, qd, qdd = SineTrajectory(2, seed=2)(np.linspace(0, 1, 20))
    a, b = solve(an, q, qd, qdd), solve(back, q, qd, qdd)
    assert rel_err(b.motor, a.motor) < 1e-12
    assert rel_err(b.joint, a.joint) < 1e-12


URDF_ARM = """<?xml version="1.0"?>
<robot name="r" xmlns:gearcli="https://gearcli.dev/urdf/1">
  <link name="base"/>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tool"/>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>
  <joint name="f" type="fixed"><parent link="arm"/><child link="tool"/><origin xyz="0.5 0 0" rpy="0 0 1.5707963267948966"/></joint>
  LOAD
</robot>
"""


def test_urdf_load_on_a_fixed_child_link(tmp_path):
    """A load on link 'tool' (fixed to 'arm' at x = 0.5 m, turned 90 deg about z): force 10 N
    along the tool's own x = the arm's y, at the tool origin: 5 N*m on the direct-drive motor."""
    path = tmp_path / "r.urdf"
    path.write_text(URDF_ARM.replace("LOAD", '<gearcli:load name="push" link="tool" frame="link" '
                                             'point="0 0 0" force="10 0 0" moment="0 0 0"/>'))
    an = analyse(load_mechanism(path))
    res = solve(an, *static([0.0, 1.0]))
    np.testing.assert_allclose(res.motor[:, 0], [-5.0, -5.0], rtol=1e-12)


@pytest.mark.parametrize("attrs,pattern", [
    ('link="nowhere" frame="base"', "load on unknown link 'nowhere'"),
    ('link="tool" frame="world"', "unknown load frame 'world'"),
    ('link="tool" frame="base" force="1 nan 0"', 'force="1 nan 0"'),
])
def test_urdf_bad_loads(run_cli, tmp_path, attrs, pattern):
    path = tmp_path / "r.urdf"
    path.write_text(URDF_ARM.replace("LOAD", f'<gearcli:load name="x" {attrs}/>'))
    r = run_cli("check", path)
    assert r.exit_code == 2 and "Traceback" not in r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, lines
    lineno = 1 + path.read_text().splitlines().index(next(ln for ln in path.read_text().splitlines()
                                                         if "gearcli:load" in ln))
    assert lines[0].startswith(f"{path}:{lineno}: gearcli:load 'x': "), lines[0]
    assert pattern in lines[0]


# --- real URDF arms: Pinocchio built from the same file (pin.buildModelFromUrdf) ----------------------

def _urdf_cases():
    from test_urdf import ERD, GEARED_ARM
    cases = [(GEARED_ARM, "tool", "upper_arm")]
    if ERD is not None:
        cases.append((ERD / "ur_description/urdf/ur5_robot.urdf", "tool0", "forearm_link"))
    return cases


@pytest.mark.parametrize("path,tip,mid", _urdf_cases(), ids=lambda x: getattr(x, "name", x))
def test_real_urdf_arm_with_fext_matches_pinocchio(tmp_path, path, tip, mid):
    """A link-frame wrench on the tip link (fixed to its parent joint's body in both files)
    and a base-frame one on a middle link; Pinocchio gets them as fext in its joint frames,
    placed by its own frame placements and joint poses."""
    pin = pytest.importorskip("pinocchio")
    from test_urdf import trajectory
    tip_w, mid_w, p_tip, p_mid = [3.0, -7.0, 12.0, 0.4, -0.2, 0.3], [-5.0, 2.0, 4.0, 0.1, 0.6, -0.2], \
        np.array([0.02, -0.03, 0.05]), np.array([0.1, 0.02, -0.01])
    el = "".join(f'<gearcli:load name="{n}" link="{lk}" frame="{fr}" point="{" ".join(map(str, p))}" '
                 f'force="{" ".join(map(str, w[:3]))}" moment="{" ".join(map(str, w[3:]))}"/>'
                 for n, lk, fr, p, w in (("tcp", tip, "link", p_tip, tip_w), ("push", mid, "base", p_mid, mid_w)))
    text = path.read_text()
    if "xmlns:gearcli" not in text:
        text = text.replace("<robot ", '<robot xmlns:gearcli="https://gearcli.dev/urdf/1" ', 1)
    loaded = tmp_path / path.name
    loaded.write_text(text.replace("</robot>", el + "\n</robot>"))
    an = analyse(load_mechanism(loaded))
    assert [ld.name for ld in an.mech.loads] == ["tcp", "push"]
    q, qd, qdd = trajectory(an.dof, n=12)
    res = solve(an, q, qd, qdd)
    q_all, qd_all, qdd_all = q @ an.S.T, qd @ an.S.T, qdd @ an.S.T
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    ids = [model.getJointId(jt.name) for jt in an.mech.joints]
    tau = np.zeros_like(q_all)
    for s in range(q_all.shape[0]):
        qp, vp, ap = pin.neutral(model), np.zeros(model.nv), np.zeros(model.nv)
        for ji, jid in enumerate(ids):
            jm = model.joints[jid]
            if jm.nq == 2:
                qp[jm.idx_q:jm.idx_q + 2] = np.cos(q_all[s, ji]), np.sin(q_all[s, ji])
            else:
                qp[jm.idx_q] = q_all[s, ji]
            vp[jm.idx_v], ap[jm.idx_v] = qd_all[s, ji], qdd_all[s, ji]
        pin.forwardKinematics(model, data, qp)
        fext = pin.StdVec_Force()
        for _ in range(model.njoints):
            fext.append(pin.Force.Zero())
        for link, frame, p, w in ((tip, "link", p_tip, tip_w), (mid, "base", p_mid, mid_w)):
            fr = model.frames[model.getFrameId(link)]
            X = fr.placement                                # link frame in its joint's frame
            Rj = data.oMi[fr.parentJoint].rotation
            f, m = np.asarray(w[:3]), np.asarray(w[3:])
            if frame == "link":
                f, m = X.rotation @ f, X.rotation @ m
            else:
                f, m = Rj.T @ f, Rj.T @ m
            arm = X.rotation @ p + X.translation
            fext[fr.parentJoint] = fext[fr.parentJoint] + pin.Force(f, m + np.cross(arm, f))
        t = pin.rnea(model, data, qp, vp, ap, fext)
        tau[s] = [t[model.joints[jid].idx_v] for jid in ids]
    assert rel_err(res.tau, tau @ an.S, tiny=1.0) < TOL
    bare = solve(an, q, qd, qdd, loads={"tcp": np.zeros(6), "push": np.zeros(6)})
    assert rel_err(bare.tau, tau @ an.S, tiny=1.0) > 1e-3
