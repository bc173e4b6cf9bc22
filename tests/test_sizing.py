"""Servo sizing in ``gearcli verify`` (issue 20): inertia ratio, torque-speed envelope,
regenerative energy per cycle.

Each check is one function of :mod:`gearcli.design.sizing`, tested by hand here, and the
verdicts are computed through the path ``verify`` takes (``build_checks`` ->
``solve_samples`` -> ``partials`` -> ``combine``) on a motor, one spur stage (n = 3.5) and
a disc:

* inertia ratio = J_load / (n^2 J_rotor) to 1e-12;
* envelope: a table and the DC model's line kt (V - kt omega) / R, by hand;
* regenerative energy: braking the disc from omega_0 to rest returns 1/2 J_eff omega_0^2
  (at the motor), to the trapezoid rule's accuracy.
"""
from __future__ import annotations

import numpy as np
import pytest

from gearcli import analyse, parse_mechanism
from gearcli.batch.runner import solve_samples
from gearcli.design import sizing
from gearcli.design.checks import Requirements, build_checks
from gearcli.design.evaluate import combine, partials
from gearcli.errors import Collector
from test_forward import J_LOAD, J_ROTOR, TEETH, spur_stage_yaml

N_RATIO = TEETH[1] / TEETH[0]
J_EFF = J_ROTOR + J_LOAD / N_RATIO ** 2


# --- the functions, by hand ---------------------------------------------------------------

def test_inertia_ratio_function():
    assert sizing.inertia_ratio([3e-5, 6e-5], 3e-5).tolist() == [0.0, 1.0]


def test_table_envelope_is_linear_in_speed_and_zero_beyond():
    table = ((0.0, 2.0), (100.0, 2.0), (300.0, 0.5))
    T = sizing.table_peak_torque([-50.0, 200.0, 300.0, 301.0], table)
    assert T.tolist() == [2.0, 1.25, 0.5, 0.0]
    u = sizing.envelope_utilisation([1.0, -1.0, 0.0, 0.1], T)
    assert u.tolist() == [0.5, 0.8, 0.0, np.inf]


def test_dc_model_envelope_depends_on_the_quadrant():
    kt, R, V = 0.05, 2.0, 24.0
    # motoring at omega = 100 rad/s: kt (V - kt w) / R = 0.05 (24 - 5) / 2
    assert sizing.model_peak_torque([1.0], [100.0], kt, R, V)[0] == pytest.approx(0.475, rel=1e-15)
    # braking (torque against the motion): the back-EMF helps, 0.05 (24 + 5) / 2
    assert sizing.model_peak_torque([-1.0], [100.0], kt, R, V)[0] == pytest.approx(0.725, rel=1e-15)
    # beyond the no-load speed V/kt nothing is left in the direction of motion
    assert sizing.model_peak_torque([1.0], [500.0], kt, R, V)[0] == 0.0


def test_regenerative_energy_counts_negative_power_only():
    T, w, t = np.array([1.0, -2.0, -1.0, 3.0]), np.array([2.0, 3.0, -1.0, -1.0]), np.array([0.0, 1.0, 2.0, 4.0])
    assert sizing.regenerative_power(T, w).tolist() == [0.0, 6.0, 0.0, 3.0]
    assert sizing.regenerative_energy(T, w, t) == 3.0 + 3.0 + 3.0      # trapezoids of 1, 1 and 2 s


# --- through verify's path -----------------------------------------------------------------

RATING = "    rating: {peak_torque: 5, rms_torque: 2, max_speed: 1000"


def rated_stage(extra: str, model: str = "") -> str:
    text = spur_stage_yaml().replace("  - {name: servo, link: rotor}",
                                     "  - name: servo\n    link: rotor\n" + RATING + extra + "}" + model)
    assert "rating" in text
    return text


def verdicts(text, traj_path):
    an = analyse(parse_mechanism(text))
    checks = build_checks(an, Requirements(), Collector("x"))
    parts = partials(checks, solve_samples(an, traj_path, False), an.mech)
    return {c.quantity: combine(c, [p], None) for c, p in zip(checks, parts)}


def disc_trajectory(path, t, q, qd, qdd):
    np.savetxt(path, np.column_stack([t, q, qd, qdd]), delimiter=",", header="t,q:Jd,qd:Jd,qdd:Jd", comments="")
    return path


def test_inertia_ratio_of_a_spur_stage_through_verify(tmp_path):
    t = np.linspace(0, 1, 51)
    traj = disc_trajectory(tmp_path / "tr.csv", t, np.sin(t), np.cos(t), -np.sin(t))
    v = verdicts(rated_stage(f", rotor_inertia: {J_ROTOR}, max_inertia_ratio: 50"), traj)["inertia ratio"]
    assert abs(v.value - J_LOAD / (N_RATIO ** 2 * J_ROTOR)) < 1e-12
    assert v.passed == (J_LOAD / (N_RATIO ** 2 * J_ROTOR) <= 50)
    # a rotor inertia read as the whole J_m (no subtraction) would give ratio + 1
    assert abs((v.value + 1) - J_LOAD / (N_RATIO ** 2 * J_ROTOR)) > 0.5
    v = verdicts(rated_stage(f", rotor_inertia: {J_ROTOR}, max_inertia_ratio: 10"), traj)["inertia ratio"]
    assert not v.passed and v.margin == pytest.approx(100 * (10 - v.value) / 10)


def test_envelope_through_verify_reports_the_worst_sample(tmp_path):
    """Constant disc acceleration a: the motor torque is J_eff * (-n a) at every sample and
    its speed -n a t grows; against a table falling from 2 N*m at 0 to 0 at 400 rad/s."""
    a = 20.0
    t = np.linspace(0, 1, 101)
    traj = disc_trajectory(tmp_path / "tr.csv", t, 0.5 * a * t ** 2, a * t, np.full_like(t, a))
    v = verdicts(rated_stage(", torque_speed: [[0, 2], [400, 0]]"), traj)["torque-speed utilisation"]
    T, w = J_EFF * N_RATIO * a, N_RATIO * a * t                 # magnitudes at the motor
    expected = np.max(T / (2 * (1 - w / 400)))
    assert v.value == pytest.approx(expected, rel=1e-12)
    assert v.time == 1.0 and v.passed == (expected <= 1)
    # the DC model of the same motor when no table is given
    model = "\n    model: {kt: 0.05, resistance: 2.0, supply_voltage: 24.0}"
    v = verdicts(rated_stage("", model), traj)["torque-speed utilisation"]
    assert v.value == pytest.approx(np.max(T / (0.05 * (24 - 0.05 * w) / 2)), rel=1e-12)


def test_regenerative_energy_of_braking_the_disc(tmp_path):
    w0, tb = 30.0, 0.5                                           # disc rate, braking time
    t = np.linspace(0, tb, 2001)
    a = -w0 / tb
    traj = disc_trajectory(tmp_path / "tr.csv", t, w0 * t + 0.5 * a * t ** 2, w0 + a * t, np.full_like(t, a))
    v = verdicts(rated_stage(", max_regen_energy: 100"), traj)["regenerative energy per cycle"]
    kinetic = 0.5 * J_EFF * (N_RATIO * w0) ** 2                  # at the motor = at the disc
    assert v.value == pytest.approx(kinetic, rel=1e-6)
    assert v.check.unit == "J" and v.passed
    v = verdicts(rated_stage(f", max_regen_energy: {kinetic / 2}"), traj)["regenerative energy per cycle"]
    assert not v.passed


def test_sizing_rating_is_validated(run_cli, tmp_path):
    p = tmp_path / "m.yaml"
    p.write_text(rated_stage(", max_inertia_ratio: 5"))
    r = run_cli("check", p)
    assert r.exit_code == 2 and "motors[0].rating.max_inertia_ratio: max_inertia_ratio needs the motor's rotor_inertia" in r.stderr
    p.write_text(rated_stage(", torque_speed: [[0, 2], [0, 1]]"))
    r = run_cli("check", p)
    assert r.exit_code == 2 and "motors[0].rating.torque_speed: torque_speed rows [omega, T_max] need omega increasing" in r.stderr


def test_verify_prints_the_sizing_checks(run_cli, tmp_path):
    mech = tmp_path / "m.yaml"
    mech.write_text(rated_stage(f", rotor_inertia: {J_ROTOR}, max_inertia_ratio: 10, max_regen_energy: 100"))
    t = np.linspace(0, 1, 51)
    disc_trajectory(tmp_path / "tr.csv", t, np.sin(t), np.cos(t), -np.sin(t))
    (tmp_path / "d.yaml").write_text("name: d\ncases:\n  - name: c\n    mechanism: m.yaml\n    trajectories: [tr.csv]\n")
    r = run_cli("verify", tmp_path / "d.yaml", "--json", tmp_path / "r.json")
    assert r.exit_code == 1                                     # the ratio 326.5 exceeds 10
    assert "FAILED c: motor servo: inertia ratio: worst 326.5 against limit 10" in r.stdout
    import json
    rows = {row["quantity"]: row for row in json.loads((tmp_path / "r.json").read_text())["checks"]}
    assert rows["regenerative energy per cycle"]["passed"]


def test_sizing_ratings_are_exported_to_urdf_and_read_back(tmp_path):
    from gearcli import load_mechanism
    from gearcli.report.urdf_writer import export_urdf
    an = analyse(parse_mechanism(rated_stage(f", rotor_inertia: {J_ROTOR}, max_inertia_ratio: 10, max_regen_energy: 100")))
    export_urdf(an, str(tmp_path / "m.urdf"))
    r = load_mechanism(tmp_path / "m.urdf").motors[0].rating
    assert (r.rotor_inertia, r.max_inertia_ratio, r.max_regen_energy) == (J_ROTOR, 10.0, 100.0)


def test_inertia_ratio_plot_names_its_quantity_without_an_empty_unit(run_cli, tmp_path, monkeypatch):
    """The inertia ratio has no unit: its plot's y label is not "... []" (issue 34, section 3)."""
    import gearcli.batch.verify as verify
    labels = []
    real = verify.plot_check
    monkeypatch.setattr(verify, "plot_check", lambda *a: (labels.append(a[5]), real(*a)))
    (tmp_path / "stage.yaml").write_text(rated_stage(f", rotor_inertia: {J_ROTOR}, max_inertia_ratio: 0.01"))
    t = np.linspace(0, 1, 51)
    disc_trajectory(tmp_path / "tr.csv", t, np.sin(t), np.cos(t), -np.sin(t))
    (tmp_path / "d.yaml").write_text("cases:\n  - {name: c, mechanism: stage.yaml, trajectories: [tr.csv], "
                                     "cycles_per_hour: 100}\n")
    r = run_cli("verify", tmp_path / "d.yaml", "--plots", tmp_path / "plots", "-j", "1")
    assert r.exit_code == 1, r.stderr
    assert "load-to-rotor inertia ratio (dimensionless)" in labels
    assert not any(label.endswith("[]") for label in labels)
    assert (tmp_path / "plots").is_dir() and any((tmp_path / "plots").glob("*inertia*.png"))
