"""Ratings read from mechanism files (YAML and URDF) and their bad-input reports."""
from pathlib import Path

import numpy as np
import pytest

from gearcli import analyse, load_mechanism, named_columns, solve
from gearcli.io.trajectory import read_trajectory
from gearcli.model.ratings import BEARING_FACTOR_DEFAULTS

ROOT = Path(__file__).resolve().parents[1]
ARM = (ROOT / "mechanisms" / "geared_arm.urdf").read_text()
RATED_ARM = ARM.replace('''    <axis xyz="0 0 1"/>
  </joint>

  <joint name="pinion_joint"''', '''    <axis xyz="0 0 1"/>
    <gearcli:bearing name="low" position="0" C="8000" C0="5000" type="ball" locating="true"/>
    <gearcli:bearing name="high" position="0.04" C="8000" C0="5000" type="ball" Y="1.8"/>
  </joint>

  <joint name="pinion_joint"''', 1).replace('</robot>', '''  <gearcli:motor_rating motor="elbow_motor" peak_torque="2" rms_torque="1" max_speed="300"/>
  <gearcli:gear_rating gear="pinion-shoulder" module="0.003" face_width="0.01" bending_stress_limit="2e8" contact_stress_limit="9e8"/>
</robot>''')


def test_yaml_ratings_with_documented_defaults(mech_dir):
    mech = load_mechanism(mech_dir / "bendix_wrist_rated.yaml")
    assert all(m.rating is not None and m.rating.peak_torque == 0.5 for m in mech.motors)
    assert all(j.bearings for j in mech.joints)
    j3 = next(j for j in mech.joints if j.name == "J3")
    (xrb,) = j3.bearings
    assert (xrb.type, xrb.X, xrb.Y, xrb.e, xrb.X0, xrb.Y0, xrb.M, xrb.locating) == \
        ("roller", 0.4, 1.49, 0.4, 0.5, 0.82, 15.0, True)
    j1 = mech.joints[0]
    assert [b.locating for b in j1.bearings] == [True, False] and j1.bearings[1].position == 0.05
    g = mech.gears[1].rating
    assert (g.module, g.face_width, g.elastic_coefficient, g.application_factor) == (0.002, 0.008, 189.8e3, 1.0)
    # deep-groove ball: X, Y, e from ISO 281 Table 3 per sample (None), ISO 76 X0, Y0 fixed
    assert BEARING_FACTOR_DEFAULTS["ball"] == {"X": None, "Y": None, "e": None, "X0": 0.6, "Y0": 0.5}
    assert BEARING_FACTOR_DEFAULTS["roller"] == BEARING_FACTOR_DEFAULTS["tapered_roller"]


def test_urdf_limits_and_rating_elements(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(RATED_ARM)
    mech = load_mechanism(path)
    shoulder = next(j for j in mech.joints if j.name == "shoulder")
    assert [b.name for b in shoulder.bearings] == ["low", "high"] and shoulder.bearings[1].Y == 1.8
    elbow = next(j for j in mech.joints if j.name == "elbow")
    assert (elbow.limit.effort, elbow.limit.velocity) == (60.0, 3.0)
    assert next(m for m in mech.motors if m.name == "elbow_motor").rating.max_speed == 300.0
    assert next(g for g in mech.gears if g.name == "pinion-shoulder").rating.module == 0.003


def test_urdf_joint_limits_are_checked_against_tau_and_rate(run_cli, tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(RATED_ARM)
    traj = ROOT / "mechanisms" / "geared_arm_traj.csv"
    (tmp_path / "d.yaml").write_text(f"cases:\n  - {{mechanism: arm.urdf, trajectories: [{traj}]}}\n")
    out = tmp_path / "r.json"
    r = run_cli("verify", tmp_path / "d.yaml", "--json", out, "-j", "1")
    assert r.exit_code in (0, 1), r.stderr
    import json
    checks = {(c["component"], c["quantity"]): c for c in json.loads(out.read_text())["checks"]}
    an = analyse(load_mechanism(path))
    tr = read_trajectory(traj, an.independent_names, linear=["finger_left_joint"])
    cols = named_columns(an, solve(an, tr.q, tr.qd, tr.qdd), tr.t)
    assert checks[("joint elbow", "effort")]["value"] == pytest.approx(np.abs(cols["tau:elbow"]).max(), rel=1e-12)
    assert checks[("joint elbow", "effort")]["limit"] == 60.0
    assert checks[("joint elbow", "velocity")]["value"] == pytest.approx(np.abs(tr.qd[:, 1]).max(), rel=1e-12)
    assert checks[("joint finger_left_joint", "velocity")]["unit"] == "m/s"
    assert ("gear pinion-shoulder", "contact safety") in checks
    assert ("bearing shoulder/high", "static safety s0") in checks


def test_urdf_module_disagreeing_with_the_mesh_names_the_rating_element(run_cli, tmp_path):
    text = RATED_ARM.replace('module="0.003"', 'module="0.0015"')
    (tmp_path / "arm.urdf").write_text(text)
    traj = ROOT / "mechanisms" / "geared_arm_traj.csv"
    (tmp_path / "d.yaml").write_text(f"cases:\n  - {{mechanism: arm.urdf, trajectories: [{traj}]}}\n")
    r = run_cli("verify", tmp_path / "d.yaml")
    line = next(i for i, x in enumerate(text.splitlines(), 1) if "gearcli:gear_rating" in x)
    assert r.exit_code == 2
    assert (f"arm.urdf:{line}: gearcli:gear_rating 'pinion-shoulder'.module: module 0.0015 m x 20 teeth / 2 = "
            "0.015 m disagrees with the pitch radius 0.03 m of gear 'pinion'") in r.stderr


@pytest.mark.parametrize("edit, message", [
    (('type="ball" Y="1.8"', 'type="balls" Y="1.8"'), "gearcli:bearing[1].type: bearing type must be one of ball, cylindrical_roller, tapered_roller, roller, crossed_roller, got 'balls'"),
    (('C0="5000" type="ball" Y', 'C0="5e3" tipe="ball" Y'), "unknown attribute 'tipe'"),
    (('locating="true"', 'locating="false"'), "with two bearings, exactly one needs 'locating: true'"),
    (('motor="elbow_motor"', 'motor="elbow"'), "unknown motor 'elbow' (known: shoulder_motor, elbow_motor, gripper_motor)"),
    (('peak_torque="2"', 'peak_torque="-2"'), "peak_torque must be positive, got -2"),
    (('max_speed="300"', 'max_speed="fast"'), "max_speed must be a finite number, got 'fast'"),
])
def test_urdf_rating_errors(run_cli, tmp_path, edit, message):
    path = tmp_path / "arm.urdf"
    text = RATED_ARM.replace(*edit)
    assert text != RATED_ARM
    path.write_text(text)
    r = run_cli("check", path)
    assert r.exit_code == 2, r.stdout
    line = next(i for i, x in enumerate(text.splitlines(), 1) if edit[1] in x)
    assert any(x.startswith(f"{path}:") and message in x for x in r.stderr.splitlines()), r.stderr
    assert f"{path}:{line}:" in r.stderr or "locating" in message


@pytest.mark.parametrize("edit, message", [
    ("{name: xrb, position: 0.0, C: 2900, C0: 3300, type: roller, M: 15}",
     "joints[2].bearings[0].type: expected one of: ball, cylindrical_roller, tapered_roller, roller, crossed_roller; got 'rolling'"),
    ("rating: {peak_torque: 0.5, rms_torque: 0.3, max_speed: 15, max_power: 5}}",
     "motors[0].rating.rms_torque: rms_torque 0.9 exceeds peak_torque 0.5"),
])
def test_yaml_rating_errors(run_cli, tmp_path, edit, message):
    text = (ROOT / "mechanisms" / "bendix_wrist_rated.yaml").read_text()
    new = edit.replace("type: roller", "type: rolling").replace("rms_torque: 0.3", "rms_torque: 0.9")
    bad = text.replace(edit, new, 1)
    assert bad != text
    path = tmp_path / "w.yaml"
    path.write_text(bad)
    r = run_cli("check", path)
    assert r.exit_code == 2
    assert message in r.stderr, r.stderr


def test_export_keeps_every_rating(tmp_path, mech_dir):
    from gearcli.report.urdf_writer import export_urdf

    mech = load_mechanism(mech_dir / "bendix_wrist_rated.yaml")
    path = tmp_path / "w.urdf"
    export_urdf(mech, path)
    back = load_mechanism(path)
    for a, b in zip(mech.joints, back.joints):
        assert a.name == b.name and a.bearings == b.bearings and b.bearings
    assert [m.rating for m in back.motors] == [m.rating for m in mech.motors]
    by_name = {g.name: g.rating for g in back.gears}
    assert all(by_name[g.name] == g.rating for g in mech.gears)
