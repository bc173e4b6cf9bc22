"""Helical parallel-axis gear pairs (``gears[].helix_angle_deg``, ``gears[].hand``).

Hand-computed static case: the one-link arm of test_external_loads (pinion 2, 10 teeth,
r = 0.025 m at x = 0.125 m, drives link 1, 40 teeth, r = 0.1 m) made helical, beta = 20 deg,
right-hand pinion, normal pressure angle 20 deg, holding 10 N at 0.5 m.  The pinion's tooth
line advances like a right-hand screw: along cos(b) z + sin(b) u_t, u_t = -y at the mesh
point (0.1, 0, 0) for the pinion turning positively about z.  The contact force is normal
to it; its tangential part on the pinion is +50 N along +y (it holds link 1 back), i.e.
t = -50 N along u_t, so its axial part is -t tan(b) z = +50 tan(20 deg) z on the pinion.
"""
from __future__ import annotations

import re

import numpy as np
import pytest

from gearcli import MechanismError, analyse, load_mechanism, parse_mechanism, solve
from gearcli.report.urdf_writer import export_urdf
from metrics import rel_err
from test_external_loads import ARM

HELICAL = ARM.replace("FRAME", "base").replace(
    'mesh_point: [0.1, 0, 0]}', 'mesh_point: [0.1, 0, 0], helix_angle_deg: 20, hand: HAND}')


def helical(hand="right"):
    return analyse(parse_mechanism(HELICAL.replace("HAND", hand)))


def static(q):
    q = np.asarray(q, float).reshape(-1, 1)
    return q, np.zeros_like(q), np.zeros_like(q)


@pytest.mark.parametrize("method", ["block", "full"])
def test_static_helical_by_hand(method):
    tb = np.tan(np.radians(20.0))
    res = solve(helical("right"), *static([0.0]), method=method, verify=True)
    assert res.residual < 1e-12
    # axial thrust changes no torque about parallel axes: motor torque as for spur gears
    np.testing.assert_allclose(res.motor[0], [0.5 * 10 / 4], rtol=1e-12)
    np.testing.assert_allclose(res.gear_t[0], [-50.0], rtol=1e-12)
    # separating force with the transverse pressure angle tan(phi_n) / cos(beta)
    np.testing.assert_allclose(res.gear_sep[0], [50 * np.tan(np.radians(20.0)) / np.cos(np.radians(20.0))],
                               rtol=1e-12)
    # axial on the pinion (j) along its +z, on link 1 (k) the opposite
    np.testing.assert_allclose(res.gear_axial[0, 0], [50 * tb, -50 * tb], rtol=1e-12)
    # bearing J2 of the pinion (joint frame = base frame, origin on the pinion axis):
    # f = -(tooth force) - weight; the thrust at radius 0.025 m on the -x side gives a
    # moment r x g = (-0.025, 0, 0) x (gx, 50, 50 tb) = (0, 0.025 * 50 tb, -0.025 * 50),
    # the bearing takes -(its x, y components); the z one is the motor's.
    sep = 50 * np.tan(np.radians(20.0)) / np.cos(np.radians(20.0))
    ji = [j.name for j in helical().mech.joints].index("J2")
    np.testing.assert_allclose(res.joint[0, ji], [-sep, -50.0, -50 * tb + 0.1 * 9.81, 0.0, -0.025 * 50 * tb, 0.0],
                               rtol=1e-12, atol=1e-12)
    # the left hand reverses the thrust, and so does the torque
    left = solve(helical("left"), *static([0.0]), method=method)
    np.testing.assert_allclose(left.gear_axial[0, 0], [-50 * tb, 50 * tb], rtol=1e-12)
    neg = solve(helical("right"), *static([np.pi]), method=method)      # tip force reversed about J1
    np.testing.assert_allclose(neg.gear_axial[0, 0], [-50 * tb, 50 * tb], rtol=1e-12)


def test_helical_export_round_trip(tmp_path):
    an = helical("left")
    path = tmp_path / "h.urdf"
    export_urdf(an, path)
    back = analyse(load_mechanism(path))
    assert back.mech.gears[0].hand == "left" and abs(back.mech.gears[0].helix_angle - np.radians(20)) < 1e-15
    q = np.linspace(-1, 1, 9)[:, None]
    a, b = solve(an, q, np.cos(q), np.sin(q)), solve(back, q, np.cos(q), np.sin(q))
    assert rel_err(b.gear_axial, a.gear_axial) < 1e-12 and rel_err(b.joint, a.joint) < 1e-12


@pytest.mark.parametrize("edit,field,pattern", [
    (("helix_angle_deg: 20, hand: HAND", "hand: right"), "hand", "hand given without a"),
    (("helix_angle_deg: 20, hand: HAND", "helix_angle_deg: 20"), "hand", "needs the hand of gear j"),
    (("kind: external", "kind: bevel"), "helix_angle_deg", "only for external and internal"),
    (("hand: HAND", "hand: up"), "hand", "expected one of: right, left; got 'up'"),
])
def test_bad_helical(run_cli, tmp_path, edit, field, pattern):
    text = HELICAL.replace(*edit).replace("HAND", "right")
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    r = run_cli("check", path)
    assert r.exit_code == 2 and "Traceback" not in r.stderr
    line = 1 + next(i for i, ln in enumerate(text.splitlines()) if "mesh_point" in ln)
    first = r.stderr.splitlines()[0]
    assert first.startswith(f"{path}:{line}: gears[0].{field}: "), first
    assert re.search(pattern, first), first
    with pytest.raises(MechanismError):
        load_mechanism(path)


@pytest.mark.parametrize("deg,ok", [(60, False), ("60.0", False), (60.5, False), (-1, False),
                                    (59.99999999, True), (59.999999999999, True), (0.001, True)])
def test_helix_angle_range_in_degrees(run_cli, tmp_path, deg, ok):
    """The documented range [0, 60) is checked on the degrees as written: 60 itself is
    refused (it was accepted: radians(60) compared with a literal a few ulps above it)."""
    text = HELICAL.replace("helix_angle_deg: 20", f"helix_angle_deg: {deg}").replace("HAND", "right")
    path = tmp_path / "h.yaml"
    path.write_text(text)
    r = run_cli("check", path)
    if ok:
        assert r.exit_code == 0, r.stderr
        return
    line = 1 + next(i for i, ln in enumerate(text.splitlines()) if "mesh_point" in ln)
    assert r.exit_code == 2 and r.stderr.splitlines() == [
        f"{path}:{line}: gears[0].helix_angle_deg: helix angle must be in [0, 60) degrees, got {float(deg):g}"]


@pytest.mark.parametrize("attr,ok", [('helix_angle_deg="60"', False), ('helix_angle_deg="59.99999999"', True),
                                     ('helix_angle="1.0471976"', False), ('helix_angle="1.0471975"', True)])
def test_helix_angle_range_urdf(tmp_path, attr, ok):
    """The same range in a URDF's gearcli:gear, in degrees or radians (pi/3 = 1.04719755...)."""
    path = tmp_path / "h.urdf"
    export_urdf(helical("right"), path)
    text = path.read_text()
    assert text.count('helix_angle="') == 1
    path.write_text(re.sub(r'helix_angle="[^"]*"', attr, text))
    if ok:
        load_mechanism(path)
        return
    with pytest.raises(MechanismError, match=r"helix angle must be in \[0, 60\) degrees, got 60$"):
        load_mechanism(path)
