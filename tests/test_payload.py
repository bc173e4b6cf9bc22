"""Payload as a mass (issue 20): ``loads[].mass`` and ``loads[].inertia``.

* By hand: an arm turning about y with a payload at (0.5, 0, 0.1): the mass matrix is
  I_yy(link) + m_L x_c^2 + I_yy(payload) + m_p (0.5^2 + 0.1^2), the holding torque
  -(m_L x_c + m_p 0.5) g; every backend agrees.  Forgetting the parallel-axis term (the
  inertia about the link origin) or the payload's own inertia fails it.
* Export to URDF (``gearcli:load mass= inertia=``) and back: the same loads to 1e-12.
* Bad input: one line each, with the file, place and problem; exit 2.
"""
from __future__ import annotations

import numpy as np
import pytest

import gearcli
from gearcli import analyse, load_mechanism, parse_mechanism
from gearcli.dynamics.forward import mass_matrix
from gearcli.report.urdf_writer import export_urdf

M_L, X_C, IYY_L = 2.0, 0.2, 0.02
M_P, P, IYY_P = 3.0, (0.5, 0.0, 0.1), 0.005
G = 9.81

ARM = f"""name: payload_arm
gravity: [0, 0, -{G}]
base: frame
end_effector: arm
links:
  - name: frame
  - {{name: arm, mass: {M_L}, com: [{X_C}, 0, 0], inertia: [0.01, {IYY_L}, 0.03]}}
joints:
  - {{name: J1, parent: frame, child: arm, origin: {{xyz: [0, 0, 0.3]}}, axis: [0, 1, 0]}}
motors:
  - {{name: m1, link: arm}}
loads:
  - {{name: box, link: arm, frame: link, point: [{P[0]}, {P[1]}, {P[2]}], mass: {M_P}, inertia: [0.004, {IYY_P}, 0.006]}}
"""


def test_mass_matrix_and_weight_of_a_payload_by_hand():
    an = analyse(parse_mechanism(ARM))
    J = IYY_L + M_L * X_C ** 2 + IYY_P + M_P * (P[0] ** 2 + P[2] ** 2)
    assert mass_matrix(an, [0.7])[0, 0, 0] == pytest.approx(J, rel=1e-13)
    # gravity about +y at q = 0: r x (0, 0, -m g) = +m g x; the motor holds with the opposite
    hold = gearcli.solve(an, [0.0], [0.0], [0.0]).motor[0, 0]
    assert hold == pytest.approx(-(M_L * X_C + M_P * P[0]) * G, rel=1e-13)
    wrong_no_parallel_axis = IYY_L + M_L * X_C ** 2 + IYY_P
    wrong_point_mass = J - IYY_P
    assert abs(wrong_no_parallel_axis - J) > 1e-3 * J and abs(wrong_point_mass - J) > 1e-3 * J


def test_every_backend_carries_the_payload():
    an = analyse(parse_mechanism(ARM))
    rng = np.random.default_rng(0)
    q, qd, qdd = (rng.uniform(-2, 2, (50, 1)) for _ in range(3))
    ref = gearcli.solve(an, q, qd, qdd, backend="numpy")
    J = IYY_L + M_L * X_C ** 2 + IYY_P + M_P * (P[0] ** 2 + P[2] ** 2)
    # about a fixed axis: tau = J qdd - g (m x)_rotated: check the whole against the hand form
    c, s = np.cos(q[:, 0]), np.sin(q[:, 0])
    mx, mz = M_L * X_C + M_P * P[0], M_P * P[2]
    # the link's x axis turned by q about y: x -> (cos q, 0, -sin q), z -> (sin q, 0, cos q)
    gravity_torque = G * (mx * c + mz * s)          # (r x (0, 0, -m g)) . y
    np.testing.assert_allclose(ref.motor[:, 0], J * qdd[:, 0] - gravity_torque, rtol=0, atol=1e-12 * 100)
    for backend in ("llvm",):
        res = gearcli.solve(an, q, qd, qdd, backend=backend)
        np.testing.assert_allclose(res.motor, ref.motor, rtol=0, atol=1e-12 * np.abs(ref.motor).max())
        np.testing.assert_allclose(res.joint, ref.joint, rtol=0, atol=1e-12 * np.abs(ref.joint).max())


def test_payload_is_exported_to_urdf_and_read_back(tmp_path):
    an = analyse(parse_mechanism(ARM))
    out = tmp_path / "arm.urdf"
    export_urdf(an, str(out))
    assert 'mass="3.0"' in out.read_text()
    back = analyse(load_mechanism(out))
    assert back.mech.loads[0].mass == M_P
    np.testing.assert_allclose(back.mech.loads[0].inertia, np.diag([0.004, IYY_P, 0.006]), atol=1e-15)
    rng = np.random.default_rng(1)
    q, qd, qdd = (rng.uniform(-2, 2, (20, 1)) for _ in range(3))
    a, b = gearcli.solve(an, q, qd, qdd), gearcli.solve(back, q, qd, qdd)
    assert np.max(np.abs(a.motor - b.motor)) < 1e-12 * np.abs(a.motor).max()
    assert np.max(np.abs(a.joint - b.joint)) < 1e-12 * np.abs(a.joint).max()


@pytest.mark.parametrize("edit,message", [
    ("mass: 3.0", "mass: -1.0", ),
    ("mass: 3.0, inertia: [0.004, 0.005, 0.006]", "inertia: [0.004, 0.005, 0.006]"),
    ("inertia: [0.004, 0.005, 0.006]", "inertia: [0.001, 0.001, 0.006]"),
], ids=["negative mass", "inertia without mass", "triangle inequality"])
def test_bad_payload_is_one_line_and_exit_2(run_cli, tmp_path, edit, message):
    old, new = edit, message
    text = ARM.replace(old, new)
    assert text != ARM
    path = tmp_path / "arm.yaml"
    path.write_text(text)
    r = run_cli("check", path)
    assert r.exit_code == 2
    lines = r.stderr.strip().splitlines()
    line = next(i for i, t in enumerate(text.splitlines(), 1) if "name: box" in t)
    assert len(lines) == 1 and lines[0].startswith(f"{path}:{line}: loads[0]")
    expected = {"mass: -1.0": "loads[0].mass", "inertia: [0.004, 0.005, 0.006]": "a payload inertia needs a positive mass",
                "inertia: [0.001, 0.001, 0.006]": "payload principal moments"}[new]
    assert expected in lines[0]


def test_bad_payload_in_urdf(run_cli, tmp_path):
    an = analyse(parse_mechanism(ARM))
    out = tmp_path / "arm.urdf"
    export_urdf(an, str(out))
    text = out.read_text().replace('mass="3.0"', 'mass="-2"')
    out.write_text(text)
    r = run_cli("check", out)
    assert r.exit_code == 2
    line = next(i for i, t in enumerate(text.splitlines(), 1) if 'mass="-2"' in t)
    assert r.stderr.strip() == (f"{out}:{line}: gearcli:load 'box'.mass: payload mass must not be negative, got -2 kg")
