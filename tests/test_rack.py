"""Rack and pinion (``gears[].kind: rack``) and prismatic joints in YAML (issue 9).

The bundled linear axis ``mechanisms/rack_axis.yaml``: a pinion of pitch radius r = 24 mm
turning about +z at (0, 0, 0.05) meshes, on its -y side, a rack under a carriage sliding
along +x.  At the mesh point the pinion's pitch-line velocity for a positive turn is
+z x (-y) r = +x r, so x = r theta (the test's own rolling condition, not gearcli's).
Everything below is computed from that geometry by hand: forces by statics, energies
from the test's own kinematics (carriage translating, pinion spinning about its axis).
"""
from __future__ import annotations

import re

import numpy as np
import pytest

from gearcli import MechanismError, analyse, load_mechanism, parse_mechanism, solve
from gearcli.report.urdf_writer import export_urdf
from metrics import rel_err

R = 0.024                        # pinion pitch radius, m
M_C, M_P, IZZ_P = 6.0, 0.25, 7.2e-5
COM_C = np.array([0.0, -0.04, 0.03])      # carriage CoM in its frame (axes = base axes)
O_C = np.array([0.0, -0.024, 0.05])       # carriage frame origin at x = 0
LOAD_F = np.array([-80.0, 0.0, -49.05])   # payload force, base frame
LOAD_P = np.array([0.05, -0.04, 0.08])    # its point, carriage frame
G = 9.81
TAN20 = np.tan(np.radians(20.0))


@pytest.fixture(scope="module")
def text(mech_dir):
    return (mech_dir / "rack_axis.yaml").read_text()


@pytest.fixture(scope="module")
def axis(text):
    return analyse(parse_mechanism(text))


def static(x):
    x = np.asarray(x, float).reshape(-1, 1)
    return x, np.zeros_like(x), np.zeros_like(x)


@pytest.mark.parametrize("method", ["block", "full"])
def test_static_rack_by_hand(axis, method):
    """Holding the payload: the rack pushes the carriage with +80 N along x; the motor
    torque is F r, the separating force F tan(20 deg) pushes the pinion to +y."""
    x = np.array([0.0, 0.037, -0.11])
    res = solve(axis, *static(x), method=method, verify=True)
    assert res.residual < 1e-12
    np.testing.assert_allclose(res.motor[:, 0], 80.0 * R, rtol=1e-12)
    np.testing.assert_allclose(res.tau[:, 0], 80.0, rtol=1e-12)      # equivalent force on Jx, N
    np.testing.assert_allclose(res.gear_t[:, 0], -80.0, rtol=1e-12)  # on the pinion, along u_t = +x
    np.testing.assert_allclose(res.gear_sep[:, 0], 80.0 * TAN20, rtol=1e-12)
    # pinion (j): radial component along its outward radius at the mesh point (-y): -sep;
    # rack (k): along the axis +x (its drive force) +80, normal to its pitch line -sep
    np.testing.assert_allclose(res.gear_radial[:, 0], [[-80 * TAN20, -80 * TAN20]] * 3, rtol=1e-12)
    np.testing.assert_allclose(res.gear_axial[:, 0], [[0.0, 80.0]] * 3, atol=1e-12)
    names = [j.name for j in axis.mech.joints]
    jp, jx = names.index("Jp"), names.index("Jx")
    # pinion bearing: -(tooth force (-80, 80 tan20, 0)) - weight, no moment (CoM and mesh
    # point in the bearing's plane); in its joint frame at theta = 0 (axes = base axes)
    np.testing.assert_allclose(res.joint[0, jp], [80.0, -80 * TAN20, M_P * G, 0, 0, 0], atol=1e-12)
    radial = np.hypot(res.joint[:, jp, 0], res.joint[:, jp, 1])
    np.testing.assert_allclose(radial, 80.0 / np.cos(np.radians(20.0)), rtol=1e-12)
    # linear guide: no force along the axis (the drive force is the rack's); the rest
    # balances weight, payload and the rack's tooth force (80, -80 tan20, 0) at the mesh point
    fz = res.joint[:, jx, 2]
    assert np.max(np.abs(fz)) < 1e-12
    for n, xi in enumerate(x):
        oj = O_C + [xi, 0, 0]
        forces = [(oj + COM_C, [0, 0, -M_C * G]), (oj + LOAD_P, LOAD_F),
                  (np.array([0, -R, 0.05]), [80.0, -80 * TAN20, 0.0])]
        f = -sum(np.asarray(F) for _, F in forces)
        m = -sum(np.cross(p - oj, F) for p, F in forces)
        along = np.array([1.0, 0, 0])
        assert abs(f @ along) < 1e-12
        np.testing.assert_allclose(np.hypot(*res.joint[n, jx, :2]), np.linalg.norm(f), rtol=1e-12)
        np.testing.assert_allclose(res.joint[n, jx, 5], m @ along, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(np.hypot(*res.joint[n, jx, 3:5]), np.linalg.norm(m - (m @ along) * along),
                                   rtol=1e-12)


def test_rack_sign_from_geometry(text):
    """x = +r theta with the mesh on the -y side; on the +y side the rack runs the other
    way, x = -r theta, and the holding torque changes sign."""
    here = analyse(parse_mechanism(text))
    mirrored = analyse(parse_mechanism(text.replace("[0, -0.024, 0.05]", "[0, 0.024, 0.05]")))
    # motor input rotation = A^T x: theta = x / r
    np.testing.assert_allclose(here.A[0, 0], 1 / R, rtol=1e-12)
    np.testing.assert_allclose(mirrored.A[0, 0], -1 / R, rtol=1e-12)
    np.testing.assert_allclose(solve(mirrored, *static([0.0])).motor[0, 0], -80 * R, rtol=1e-12)


def own_power_terms(x, xd, xdd, gravity):
    """Kinetic energy rate, potential energy rate and payload power from the test's own
    kinematics: the carriage translates with xd along +x, the pinion spins at xd / r."""
    th_d, th_dd = xd / R, xdd / R
    dT = M_C * xd * xdd + IZZ_P * th_d * th_dd
    dV = -M_C * gravity[0] * xd            # the pinion's centre does not move
    p_ext = LOAD_F[0] * xd
    return dT, dV, p_ext


@pytest.mark.parametrize("gravity", [[0, 0, -9.81], [-4.905, 0, -8.496]])
@pytest.mark.parametrize("method", ["block", "full"])
def test_power_balance_along_bundled_trajectory(mech_dir, text, gravity, method):
    """Motor power tau * theta_dot = d/dt (kinetic + potential) - payload power, along the
    bundled trajectory (analytic rates), also with gravity tilted along the axis."""
    data = np.loadtxt(mech_dir / "rack_axis_traj.csv", delimiter=",", skiprows=1)
    x, xd, xdd = data[:, 1:2], data[:, 2:3], data[:, 3:4]
    an = analyse(parse_mechanism(text.replace("gravity: [0, 0, -9.81]", f"gravity: {gravity}")))
    res = solve(an, x, xd, xdd, method=method, verify=True)
    assert res.residual < 1e-12
    dT, dV, p_ext = own_power_terms(x[:, 0], xd[:, 0], xdd[:, 0], np.asarray(gravity))
    p_motor = res.motor[:, 0] * xd[:, 0] / R
    assert rel_err(p_motor, dT + dV - p_ext) < 1e-12
    assert np.ptp(p_motor) > 10.0      # the motion really exercises the balance


@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_block_equals_full_on_bundled_trajectory(mech_dir, axis, backend):
    """Consistency check: the block schedule (both backends) against the full solve."""
    data = np.loadtxt(mech_dir / "rack_axis_traj.csv", delimiter=",", skiprows=1)
    q, qd, qdd = data[:, 1:2], data[:, 2:3], data[:, 3:4]
    a, b = solve(axis, q, qd, qdd, method="block", backend=backend), solve(axis, q, qd, qdd, method="full")
    for f in ("motor", "joint", "gear_t", "gear_sep", "gear_radial", "gear_axial"):
        assert rel_err(getattr(a, f), getattr(b, f)) < 1e-12, f


def test_rack_export_round_trip(tmp_path, axis):
    path = tmp_path / "rack.urdf"
    export_urdf(axis, path)
    back = analyse(load_mechanism(path))
    gp = back.mech.gears[0]
    assert gp.kind == "rack" and (gp.j, gp.k) == ("pinion", "carriage")
    assert [j.type for j in back.mech.joints] == [j.type for j in axis.mech.joints]
    x = np.linspace(-0.2, 0.2, 9)[:, None]
    a, b = solve(axis, x, np.cos(x), np.sin(x)), solve(back, x, np.cos(x), np.sin(x))
    for f in ("motor", "joint", "gear_t", "gear_sep", "gear_radial", "gear_axial"):
        assert rel_err(getattr(b, f), getattr(a, f)) < 1e-12, f


def test_prismatic_dh_joint(tmp_path):
    """A D-H prismatic joint slides along the parent's z (the variable adds to d): a
    vertical slider of 2 kg holds its weight with a 19.62 N force and sits at d + q."""
    text = """
name: slider
base: frame
end_effector: ram
links:
  - {name: frame}
  - {name: ram, mass: 2.0, com: [0.0, 0.0, 0.1]}
joints:
  - {name: Jz, parent: frame, child: ram, type: prismatic, dh: {d: 0.1, a: 0.2, alpha_deg: 90}}
motors:
  - {name: lin, link: ram}
"""
    an = analyse(parse_mechanism(text))
    from gearcli.dynamics.kinematics import forward
    kin = forward(an.mech, an.tree, np.array([[0.3]]))
    np.testing.assert_allclose(kin.o[an.tree.index["ram"]][0], [0.2, 0.0, 0.4], atol=1e-15)
    res = solve(an, *static([0.3]))
    np.testing.assert_allclose(res.motor[0, 0], 2.0 * G, rtol=1e-12)
    # the CoM, 0.1 m along the ram's z = -y of the base (alpha = 90 deg), is at (0.2, -0.1)
    # from the guide's axis (the base z): the guide takes the weight's moment, no force
    np.testing.assert_allclose(np.hypot(*res.joint[0, 0, 3:5]), 2.0 * G * np.hypot(0.2, 0.1), rtol=1e-12)
    assert np.max(np.abs(res.joint[0, 0, [0, 1, 2, 5]])) < 1e-12


BAD = [
    (("type: prismatic\n", "\n"), "gears[0].links[1]", "the rack of a rack pair must slide on a prismatic joint"),
    (("links: [pinion, carriage]", "links: [carriage, pinion]"), "gears[0].links[0]",
     "the pinion of a rack pair must turn on a revolute joint"),
    (("kind: rack", "kind: rack\n    helix_angle_deg: 10\n    hand: right"), "gears[0].helix_angle_deg",
     "only for external and internal"),
    (("kind: rack", "kind: rack\n    teeth: [24, 100]"), "gears[0].teeth", "a rack pair takes no tooth counts"),
    (("kind: rack", "kind: rack\n    ratio: 40"), "gears[0].ratio", "contradicts the mesh geometry"),
    (("    mesh_point: [0, -0.024, 0.05]", ""), "gears[0]", "a rack pair needs its mesh_point"),
    (("axis: [1, 0, 0]", "axis: [1, 0.1, 0]"), "gears[0].mesh_point", "not tangent to the pitch circle"),
    (("kind: rack", "kind: external\n    ratio: -1"), "gears[0].links[1]",
     "slides on a prismatic joint relative to the carrier: an external gear must turn"),
    (("type: prismatic", "type: slider"), "joints[1].type", "expected one of: revolute, prismatic; got 'slider'"),
]


@pytest.mark.parametrize("edit,place,pattern", BAD)
def test_bad_rack_input(run_cli, tmp_path, text, edit, place, pattern):
    assert edit[0] in text
    bad = text.replace(*edit, 1)
    path = tmp_path / "bad.yaml"
    path.write_text(bad)
    r = run_cli("check", path)
    assert r.exit_code == 2 and "Traceback" not in r.stderr
    first = r.stderr.splitlines()[0]
    assert re.match(rf"{re.escape(str(path))}:\d+: {re.escape(place)}: ", first), first
    assert re.search(pattern, first), first
    with pytest.raises(MechanismError):
        analyse(load_mechanism(path))


def test_check_graph_and_solve_list_loads_racks_and_helical_pairs(run_cli, mech_dir, tmp_path):
    rack, hel = mech_dir / "rack_axis.yaml", mech_dir / "helical_reduction.yaml"
    r = run_cli("check", rack)
    assert r.exit_code == 0
    lines = r.stdout.splitlines()
    assert lines[0] == f"{rack}: OK (1 dof, 3 links, 1 gear pair, 1 motor)"
    assert lines[1] == ("load 'payload' on link 'carriage' (frame base): force [-80, 0, -49.05] N, "
                        "moment [0, 0, 0] N*m at [0.05, -0.04, 0.08] m (link frame)")
    assert lines[2] == ("rack pair 'rack': pinion 'pinion' (pitch radius 0.024 m) drives rack 'carriage': "
                        "x = 0.024 m/rad * theta")
    r = run_cli("check", hel)
    assert "helical pair 'stage1': helix angle 20 deg, 'input' right hand, 'intermediate' left hand" in r.stdout
    assert "helical pair 'stage2': helix angle 15 deg, 'intermediate' left hand, 'output' right hand" in r.stdout
    g = run_cli("graph", rack)
    assert "rack pair 'rack'" in g.stdout and "load 'payload'" in g.stdout
    assert "theta_pinion,frame = 41.6667 * x_carriage,frame (x = 0.024 m * theta)" in g.stdout
    import json
    doc = json.loads(run_cli("graph", "--json", hel).stdout)
    assert doc["loads"] == [{"name": "resisting", "link": "output", "frame": "base", "point": [0, 0, 0.1],
                             "force": [0, 0, 0], "moment": [0, 0, -20]}]
    assert [p["hands"] for p in doc["helical_and_rack_pairs"]] == [
        {"input": "right", "intermediate": "left"}, {"intermediate": "left", "output": "right"}]
    s = run_cli("solve", rack, mech_dir / "rack_axis_traj.csv", "-o", tmp_path / "out.csv")
    assert s.exit_code == 0 and "rack pair 'rack'" in s.stdout and "load 'payload'" in s.stdout


def test_bearings_on_a_prismatic_joint_are_refused(run_cli, tmp_path, text):
    bad = text.replace("    type: prismatic\n", "    type: prismatic\n    bearings:\n"
                       "      - {name: a, position: 0.0, C: 5400, C0: 2360, type: ball}\n")
    path = tmp_path / "bad.yaml"
    path.write_text(bad)
    r = run_cli("check", path)
    assert r.exit_code == 2
    first = r.stderr.splitlines()[0]
    assert re.match(rf"{re.escape(str(path))}:\d+: joints\[1\]\.bearings: rolling-bearing ratings", first), first


PINION_ON_CARRIAGE = """
name: pinion_on_carriage
base: frame
end_effector: carriage
links:
  - {name: frame}
  - {name: carriage, mass: 5.0}
  - {name: pinion, mass: 0.3, inertia: [1.0e-4, 1.0e-4, 1.5e-4]}
joints:
  - {name: Jx, parent: frame, child: carriage, type: prismatic, origin: {xyz: [0, 0, 0]}, axis: [1, 0, 0]}
  - {name: Jp, parent: carriage, child: pinion, origin: {xyz: [0, 0.03, 0]}, axis: [0, 0, 1]}
gears:
  - {name: rack, links: [pinion, frame], kind: rack, mesh_point: [0, 0, 0], carrier: carriage}
motors:
  - {name: m1, link: pinion}
loads:
  - {name: push, link: carriage, point: [0, 0, 0], frame: base, force: [-100, 0, 0]}
"""


@pytest.mark.parametrize("method", ["block", "full"])
def test_pinion_riding_on_the_carriage(method):
    """The motor pinion rides on the carriage (the carrier) and meshes a rack fixed in the
    frame below it: at the mesh point (0, -0.03) from the pinion axis, u_t = +x, so the
    frame runs +r theta relative to the carriage and the carriage x = -r theta.  Power
    balance by hand: tau theta_dot = d/dt(m x_dot^2/2 + I theta_dot^2/2) - F x_dot."""
    an = analyse(parse_mechanism(PINION_ON_CARRIAGE))
    np.testing.assert_allclose(an.A[0, 0], -1 / 0.03, rtol=1e-12)
    x, xd, xdd = (np.array([[0.0], [0.1], [-0.2]]), np.array([[0.0], [0.3], [-0.5]]),
                  np.array([[0.0], [2.0], [1.0]]))
    res = solve(an, x, xd, xdd, method=method, verify=True)
    assert res.residual < 1e-12
    th_d, th_dd = -xd / 0.03, -xdd / 0.03
    # the pinion's centre moves with the carriage: its kinetic energy has 0.3 x_dot^2 / 2 too
    dT = (5.0 + 0.3) * xd * xdd + 1.5e-4 * th_d * th_dd
    np.testing.assert_allclose(res.motor * th_d, dT - (-100.0) * xd, atol=1e-12)
    np.testing.assert_allclose(res.motor[0, 0], -100.0 * 0.03, rtol=1e-12)


def test_rack_tooth_rating_by_hand(text):
    """A rated rack pair: the pinion's teeth follow from its pitch radius and the module
    (2 x 0.024 / 0.002 = 24, Lewis Y = 0.337 from Shigley's table), the rack has Y = 0.485
    (the pinion governs), and the Hertz stress has (u + 1) / u = 1 (a rack is u -> inf):
    sigma_H = Z_H Z_E sqrt(|t| / (d1 b)), Z_H = sqrt(2 / (sin 20 cos 20))."""
    from gearcli.design.checks import Requirements, build_checks
    from gearcli.design.evaluate import Samples, signal
    from gearcli.errors import Collector
    from gearcli.report.columns import named_columns
    rated = text.replace("    pressure_angle_deg: 20\n", "    pressure_angle_deg: 20\n    rating: {module: 0.002, "
                         "face_width: 0.02, bending_stress_limit: 2.0e8, contact_stress_limit: 8.0e8}\n")
    an = analyse(parse_mechanism(rated))
    res = solve(an, *static([0.0]))
    col = Collector("<test>", {})
    checks = [c for c in build_checks(an, Requirements(), col) if c.component == "gear rack"]
    assert not col.issues and len(checks) == 2
    s = Samples(np.zeros(1), named_columns(an, res), np.zeros((1, 2)))
    got = {c.quantity: signal(c, s, an.mech)[0] for c in checks}
    a = np.radians(20.0)
    assert got["bending safety"] == pytest.approx(80.0 / (0.02 * 0.002 * 0.337), rel=1e-12)
    ZH = np.sqrt(2 / (np.sin(a) * np.cos(a)))
    assert got["contact safety"] == pytest.approx(ZH * 189.8e3 * np.sqrt(80.0 / (0.048 * 0.02)), rel=1e-12)


def test_graph_marks_the_prismatic_joint(run_cli, mech_dir):
    rack = mech_dir / "rack_axis.yaml"
    assert "Jx: frame -> carriage (prismatic)" in run_cli("graph", rack).stdout
    assert '"frame" -> "carriage" [label="a (prismatic)", penwidth=1];' in run_cli("graph", rack, "--dot").stdout


def test_urdf_bearings_on_a_prismatic_joint_are_refused(run_cli, tmp_path, axis):
    path = tmp_path / "rack.urdf"
    export_urdf(axis, path)
    text = path.read_text().replace(
        '<joint name="Jx" type="prismatic">',
        '<joint name="Jx" type="prismatic">\n    <gearcli:bearing name="a" position="0.0" C="5400.0" C0="2360.0" '
        'type="ball"/>')
    path.write_text(text)
    r = run_cli("check", path)
    assert r.exit_code == 2 and "Traceback" not in r.stderr
    assert "joint 'Jx'" in r.stderr and "rolling-bearing ratings" in r.stderr, r.stderr


def test_pinocchio_rnea_with_the_tooth_force_as_fext(mech_dir, axis):
    """Oracle: pinion (revolute about z) and carriage (prismatic along x) in Pinocchio with
    the test's own inertias; the tooth force rebuilt from gearcli's t with the test's own
    directions (tangential +x on the pinion, separating +y pushing it off the rack) and the
    payload as fext.  RNEA gives the motor torque on the pinion and no force along the
    guide (the rack's teeth drive the carriage), and its transmitted joint wrenches are
    gearcli's bearing and guide reactions."""
    pin = pytest.importorskip("pinocchio")
    data_csv = np.loadtxt(mech_dir / "rack_axis_traj.csv", delimiter=",", skiprows=1)[::40]
    x, xd, xdd = data_csv[:, 1:2], data_csv[:, 2:3], data_csv[:, 3:4]
    res = solve(axis, x, xd, xdd)
    model = pin.Model()
    o_p = np.array([0.0, 0.0, 0.05])
    jp = model.addJoint(0, pin.JointModelRZ(), pin.SE3(np.eye(3), o_p), "Jp")
    model.appendBodyToJoint(jp, pin.Inertia(M_P, np.zeros(3), np.diag([6.0e-5, 6.0e-5, IZZ_P])), pin.SE3.Identity())
    jx = model.addJoint(0, pin.JointModelPX(), pin.SE3(np.eye(3), O_C), "Jx")
    model.appendBodyToJoint(jx, pin.Inertia(M_C, COM_C, np.diag([0.02, 0.03, 0.04])), pin.SE3.Identity())
    data = model.createData()
    names = [j.name for j in axis.mech.joints]
    P = np.array([0.0, -R, 0.05])
    for n in range(x.shape[0]):
        t = res.gear_t[n, 0]
        g = np.array([t, abs(t) * TAN20, 0.0])          # on the pinion
        th = x[n, 0] / R
        Rz = pin.utils.rotate("z", th)
        oc = O_C + [x[n, 0], 0, 0]
        f_c, m_c = -g + LOAD_F, np.cross(P - oc, -g) + np.cross(LOAD_P, LOAD_F)
        fext = pin.StdVec_Force()
        fext.append(pin.Force.Zero())
        fext.append(pin.Force(Rz.T @ g, Rz.T @ np.cross(P - o_p, g)))
        fext.append(pin.Force(f_c, m_c))
        tau = pin.rnea(model, data, np.array([th, x[n, 0]]), np.array([xd[n, 0] / R, xd[n, 0]]),
                       np.array([xdd[n, 0] / R, xdd[n, 0]]), fext)
        assert abs(tau[0] - res.motor[n, 0]) < 1e-9 * (1 + abs(res.motor[n, 0]))
        assert abs(tau[1]) < 1e-9 * (1 + abs(t))
        jr = res.joint[n, names.index("Jp")]
        assert rel_err(data.f[jp].vector, np.r_[jr[:5], res.motor[n, 0]]) < 1e-9
        jr = res.joint[n, names.index("Jx")]        # guide frame: z along x; compare invariants
        fp, mp = data.f[jx].linear, data.f[jx].angular
        assert abs(np.hypot(jr[0], jr[1]) - np.linalg.norm(fp[1:])) < 1e-9 * np.linalg.norm(fp)
        assert abs(jr[5] - mp[0]) < 1e-9 * (1 + np.linalg.norm(mp))
        assert abs(np.linalg.norm(jr[3:6]) - np.linalg.norm(mp)) < 1e-9 * (1 + np.linalg.norm(mp))


def test_pinocchio_reads_the_exported_axis(tmp_path, text):
    """The exported URDF in Pinocchio (the rack's mimic ignored, both joints free), with the
    payload removed: RNEA projected by S (q = S x) is gearcli's equivalent force on Jx."""
    pytest.importorskip("pinocchio")
    from test_urdf import pinocchio_loads
    an = analyse(parse_mechanism(text.split("loads:")[0]))
    path = tmp_path / "axis.urdf"
    export_urdf(an, path)
    x = np.linspace(-0.15, 0.15, 7)[:, None]
    xd, xdd = np.cos(10 * x), np.sin(20 * x)
    res = solve(an, x, xd, xdd)
    tau_pin, _ = pinocchio_loads(path, an.mech, x @ an.S.T, xd @ an.S.T, xdd @ an.S.T)
    assert rel_err(res.tau, tau_pin @ an.S) < 1e-9
