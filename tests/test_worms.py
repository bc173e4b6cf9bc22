"""Worm pairs (issue 36, ``kind: worm``): hand cases from the model statement
(``../shared/drive-elements.md`` D, README "Worm pairs"), written here without the solver's code:
the efficiencies' closed forms, self-locking and back-driving, the deliberate bug they catch,
the energy balance of the bundled worm lift and located input errors."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from gearcli import analyse, load_mechanism, parse_mechanism, solve
from gearcli.report.columns import named_columns

pytestmark = pytest.mark.physics
MECHS = Path(__file__).resolve().parents[1] / "mechanisms"
ALPHA, MU, D1, Z2 = math.radians(20.0), 0.1, 0.02, 40

WORM = """
name: worm
gravity: [0, 0, 0]
base: frame
end_effector: drum
links:
  - {{name: frame}}
  - {{name: worm, mass: 0.2, inertia: [2.0e-5, 1.0e-4, 1.0e-4]}}
  - {{name: drum, mass: 1.0, inertia: [1.0e-3, 2.0e-3, 1.0e-3]}}
joints:
  - {{name: Jw, parent: frame, child: worm, origin: {{xyz: [0, 0, 0]}}, axis: [1, 0, 0]}}
  - {{name: Jd, parent: frame, child: drum, origin: {{xyz: [0, 0, {a!r}]}}, axis: [0, 1, 0]}}
gears:
  - {{name: wp, kind: worm, links: [worm, drum], teeth: [1, {z2}], reference_diameter: {d1}, lead_angle_deg: {gamma},
     pressure_angle_deg: 20, friction_coefficient: {mu}, hand: {hand}}}
motors:
  - {{name: m, link: worm}}
loads:
  - {{name: rope, link: drum, point: [0, 0, 0], frame: base, moment: [0, -10, 0]}}
"""


def worm(gamma_deg, mu=MU, hand="right"):
    """A one-start worm of lead angle gamma against a 40-tooth wheel: the axial module
    d1 tan(gamma) and the centre distance d1/2 + Z2 m_x / 2 that the geometry requires."""
    m = D1 * math.tan(math.radians(gamma_deg))
    return analyse(parse_mechanism(WORM.format(a=D1 / 2 + Z2 * m / 2, z2=Z2, d1=D1, gamma=gamma_deg, mu=mu, hand=hand)))


def at_speed(an, w):
    """The drum at constant rates w (rad/s about +y), one sample each."""
    w = np.asarray(w, float)[:, None]
    return named_columns(an, solve(an, np.zeros_like(w), w, np.zeros_like(w), verify=True))


def closed_forms(gamma_deg, mu=MU):
    g = math.radians(gamma_deg)
    c = math.cos(ALPHA)
    return (c - mu * math.tan(g)) / (c + mu / math.tan(g)), (c - mu / math.tan(g)) / (c + mu * math.tan(g))


def test_self_locking_worm_at_5_degrees():
    """gamma = 5 deg, alpha_n = 20 deg, mu = 0.1: tan(gamma) = 0.0875 <= mu / cos(alpha_n) = 0.106,
    self-locking.  Lifting (the drum turning +y against the rope's -10 N*m): the motor's power is
    the load's 10 W / eta_f, eta_f = (cos an - mu tan g) / (cos an + mu cot g).  Lowering: the
    motor must still deliver power, the load's 10 W times -eta_b (eta_b < 0)."""
    eta_f, eta_b = closed_forms(5.0)
    assert eta_b < 0 and math.tan(math.radians(5)) <= MU / math.cos(ALPHA)
    c = at_speed(worm(5.0), [0.0, 1.0, -1.0])
    P = c["motor:m:power"]
    assert P[0] == 0.0 and P[1] == pytest.approx(10.0 / eta_f, rel=1e-12)
    assert P[2] > 0 and P[2] == pytest.approx(-10.0 * eta_b, rel=1e-12)
    assert c["motor:m"][0] == pytest.approx(10.0 / Z2, rel=1e-12)          # holding: lossless
    assert np.allclose(c["gear:wp:loss"], [0.0, 10.0 / eta_f - 10.0, 10.0 - 10.0 * eta_b], rtol=1e-12, atol=1e-15)


def test_back_drivable_worm_at_25_degrees():
    """gamma = 25 deg: the wheel back-drives the worm; lowering, the motor receives the load's
    10 W times eta_b = (cos an - mu cot g) / (cos an + mu tan g) > 0."""
    eta_f, eta_b = closed_forms(25.0)
    assert eta_b > 0
    c = at_speed(worm(25.0), [1.0, -1.0])
    assert c["motor:m:power"][0] == pytest.approx(10.0 / eta_f, rel=1e-12)
    assert c["motor:m:power"][1] == pytest.approx(-10.0 * eta_b, rel=1e-12)


def test_wheel_tangential_force_and_worm_thrust():
    """At rest the flank load's tangential part on the wheel is the drum's torque over the wheel's
    pitch radius, 10 / r2; the worm's thrust along its axis equals it (t_G is along z_w)."""
    an = worm(5.0)
    r2 = Z2 * D1 * math.tan(math.radians(5.0)) / 2
    c = at_speed(an, [0.0])
    assert c["gear:wp:t"][0] == pytest.approx(10.0 / r2, rel=1e-12)
    assert abs(c["gear:wp:axial"][0]) == pytest.approx(10.0 / r2, rel=1e-12)


def test_left_hand_reverses_the_worm():
    """A left-hand worm turns the other way for the same drum motion (the ratio's sign), with the
    same efficiencies."""
    right, left = worm(5.0), worm(5.0, hand="left")
    assert left.circuits[0].ratio == -right.circuits[0].ratio
    cr, cl = at_speed(right, [1.0]), at_speed(left, [1.0])
    assert cl["motor:m"][0] == pytest.approx(-cr["motor:m"][0], rel=1e-12)
    assert cl["motor:m:power"][0] == pytest.approx(cr["motor:m:power"][0], rel=1e-12)


def test_the_hand_case_catches_friction_along_the_wrong_direction(monkeypatch):
    """A deliberate bug, the friction along -h_hat instead of the sliding direction: friction then
    feeds power in, and lifting takes less than the load's power."""
    from gearcli.model import worms
    good = worms.worm_geometry

    def flipped(*args, **kw):
        geo, problems = good(*args, **kw)
        from dataclasses import replace
        return (replace(geo, h_hat=-geo.h_hat) if geo is not None else None), problems
    import gearcli.analysis.circuits as circuits
    monkeypatch.setattr(circuits, "worm_geometry", flipped)
    eta_f, _ = closed_forms(5.0)
    c = at_speed(worm(5.0), [1.0])
    assert c["motor:m:power"][0] != pytest.approx(10.0 / eta_f, rel=1e-3)


def test_bundled_worm_lift_balances_power_and_lowers_under_power():
    """mechanisms/worm_lift.yaml along its duty: the motor's power = dT/dt - P_gravity - P_loads +
    mu |N| |v_s| (the loss from the model, the sliding speed from the link velocities at the
    contact point) to 1e-9 per sample; lowering (drum rate < 0) the motor delivers power."""
    from test_losses import energy_terms
    from gearcli.dynamics.kinematics import forward
    from gearcli.io.trajectory import read_trajectory
    an = analyse(load_mechanism(MECHS / "worm_lift.yaml"))
    tr = read_trajectory(MECHS / "worm_lift_traj.csv", an.independent_names)
    res = solve(an, tr.q, tr.qd, tr.qdd)
    cols = named_columns(an, res, tr.t)
    dT, Pg, Pe = energy_terms(an, tr.q, tr.qd, tr.qdd)
    c = an.circuits[0]
    kin = forward(an.mech, an.tree, tr.q @ an.S.T, tr.qd @ an.S.T)
    P = c.worm.P                                   # the carrier is the (fixed) frame: base axes
    vw = np.cross(kin.w[c.j], P - kin.o[c.j][0])   # the worm's and the wheel's material points at P
    vg = np.cross(kin.w[c.k], P - kin.o[c.k][0])
    loss = an.mech.gears[0].worm.mu * np.abs(res.gear_t[:, 0]) * np.linalg.norm(vw - vg, axis=1)
    P_motor = cols["motor:motor:power"]
    scale = 1.0 + np.abs(P_motor) + np.abs(dT) + np.abs(Pg) + np.abs(Pe) + loss
    assert np.max(np.abs(P_motor - (dT - Pg - Pe + loss)) / scale) < 1e-9
    assert np.max(np.abs(cols["gear:stage:loss"] - loss) / scale) < 1e-11
    lowering = (tr.qd[:, 0] < -0.5) & (np.abs(tr.qdd[:, 0]) < 1.0)
    assert lowering.any() and np.all(P_motor[lowering] > 0)


@pytest.mark.parametrize("old, new, place, message", [
    ("axis: [0, 1, 0]", "axis: [0.1, 1, 0]", "gears[0].links", "not perpendicular"),
    ("reference_diameter: 0.02", "reference_diameter: 0.021", "gears[0].reference_diameter", "disagree"),
    ("friction_coefficient: 0.1", "friction_coefficient: -0.1", "gears[0].friction_coefficient", ">= 0"),
    ("lead_angle_deg: 5.0", "lead_angle_deg: 50", "gears[0].lead_angle_deg", "(0, 45]"),
    ("lead_angle_deg: 5.0", "module: 0.002, lead_angle_deg: 5.0", "gears[0]", "axial module or its lead_angle_deg"),
])
def test_worm_input_problems_are_located(run_cli, tmp_path, old, new, place, message):
    """Each bad worm declaration: one located line naming the key, exit 2, no traceback."""
    m = D1 * math.tan(math.radians(5.0))
    text = WORM.format(a=D1 / 2 + Z2 * m / 2, z2=Z2, d1=D1, gamma=5.0, mu=MU, hand="right")
    assert old in text
    (tmp_path / "m.yaml").write_text(text.replace(old, new, 1))
    r = run_cli("check", tmp_path / "m.yaml")
    assert r.exit_code == 2 and "Traceback" not in r.stderr
    line = next((ln for ln in r.stderr.splitlines() if place + ":" in ln or place + "." in ln), "")
    assert message in line, r.stderr


@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_urdf_round_trip_solves_bit_identically(run_cli, tmp_path, backend):
    """gearcli export writes a gearcli:worm (its module and lead angle as stored); read back, the
    worm is the same and every output column is bit for bit the YAML's, on both paths."""
    r = run_cli("export", MECHS / "worm_lift.yaml", "-o", tmp_path / "w.urdf")
    assert r.exit_code == 0, r.stderr
    a, b = analyse(load_mechanism(MECHS / "worm_lift.yaml")), analyse(load_mechanism(tmp_path / "w.urdf"))
    assert a.mech.gears[0].worm == b.mech.gears[0].worm and a.circuits[0].ratio == b.circuits[0].ratio
    rng = np.random.default_rng(6)
    q, qd, qdd = (rng.uniform(-3, 3, (150, 1)) for _ in range(3))
    ca, cb = (named_columns(x, solve(x, q, qd, qdd, backend=backend)) for x in (a, b))
    assert list(ca) == list(cb) and all(np.array_equal(ca[k], cb[k]) for k in ca)


def test_verify_says_a_self_locking_worm_holds_without_a_brake(run_cli, tmp_path):
    """gearcli verify's summary has one line per worm pair with its efficiencies; the bundled
    self-locking stage's says it holds a load without a brake."""
    (tmp_path / "d.yaml").write_text(
        f"cases:\n  - {{name: lift, mechanism: {MECHS / 'worm_lift.yaml'}, trajectories: [{MECHS / 'worm_lift_traj.csv'}], "
        "limits: [{column: 'motor:motor', max_abs: 1.0}]}\n")
    r = run_cli("verify", tmp_path / "d.yaml", "-j", "1")
    assert r.exit_code == 0, r.stderr
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("Worm pair stage of lift"))
    assert "self-locking: it holds a load without a brake" in line and "backward -0.1907" in line



def _lift_manifest(tmp_path, extra: str, mech=MECHS / "worm_lift.yaml") -> Path:
    (tmp_path / "d.yaml").write_text(
        f"cases:\n  - {{name: lift, mechanism: {mech}, trajectories: [{MECHS / 'worm_lift_traj.csv'}], {extra}}}\n")
    return tmp_path / "d.yaml"


def test_verify_checks_the_worm_pairs_efficiency_over_the_duty_cycle(run_cli, tmp_path):
    """``min_worm_efficiency``: the value verify reports is 1 - E_loss / E_in over the bundled
    lift's duty (lift, hold, lower), computed here from the drum's own equation alone: the
    mesh delivers P_G = (I_yy qdd - M_rope) qd to the drum; lifting (P_G > 0) the worm puts in
    P_G / eta_f, lowering the self-locking stage (P_G < 0) both members put in, all of it lost,
    (1 - eta_b) |P_G|; eta_f, eta_b from the model statement's closed forms.  Its plot is
    written.  Deliberate bug caught: the power in without the loss (P_in = |P_G|)."""
    import json
    import csv
    rows = np.array([[float(v) for v in r.values()] for r in csv.DictReader(open(MECHS / "worm_lift_traj.csv"))])
    t, qd, qdd = rows[:, 0], rows[:, 2], rows[:, 3]
    P_G = (4.0e-3 * qdd + 5.886) * qd               # the rope's moment about +y is -5.886 N*m
    g, a, mu = math.atan(0.002 / 0.028), ALPHA, 0.08
    eta_f = (math.cos(a) - mu * math.tan(g)) / (math.cos(a) + mu / math.tan(g))
    eta_b = (math.cos(a) - mu / math.tan(g)) / (math.cos(a) + mu * math.tan(g))
    assert eta_b < 0
    E_in = np.where(P_G > 0, P_G / eta_f, (1 - eta_b) * -P_G)
    E_loss = np.where(P_G > 0, P_G * (1 / eta_f - 1), (1 - eta_b) * -P_G)
    trap = lambda x: float(np.sum(0.5 * (x[1:] + x[:-1]) * np.diff(t)))  # noqa: E731
    want = 1.0 - trap(E_loss) / trap(E_in)
    assert 0.2 < want < eta_f - 0.1                 # the lowering's losses count
    r = run_cli("verify", _lift_manifest(tmp_path, "min_worm_efficiency: 0.25"), "-j", "1",
                "--json", tmp_path / "r.json", "--html", tmp_path / "r.html")
    assert r.exit_code == 0, r.stderr
    (check,) = json.loads((tmp_path / "r.json").read_text())["checks"]
    assert check["component"] == "worm pair stage" and check["quantity"] == "efficiency over the duty cycle"
    assert check["value"] == pytest.approx(want, rel=1e-9) and check["passed"]
    assert "efficiency over the duty cycle" in (tmp_path / "r.html").read_text() and "data:image/png" in (tmp_path / "r.html").read_text()
    r = run_cli("verify", _lift_manifest(tmp_path, f"min_worm_efficiency: {want + 0.01:.6f}"), "-j", "1")
    assert r.exit_code == 1 and "FAILED lift: worm pair stage: efficiency over the duty cycle" in r.stdout


@pytest.mark.parametrize("extra, message", [
    ("min_worm_efficiency: 0", "min_worm_efficiency"),
    ("min_worm_efficiency: 1.5", "min_worm_efficiency"),
])
def test_bad_worm_efficiency_requirement_is_located(run_cli, tmp_path, extra, message):
    r = run_cli("verify", _lift_manifest(tmp_path, extra), "-j", "1", "--json", tmp_path / "r.json")
    assert r.exit_code == 2 and "Traceback" not in r.stderr and not (tmp_path / "r.json").exists()
    assert f"d.yaml:2: cases[0].{message}:" in r.stderr, r.stderr


def test_worm_efficiency_requirement_without_a_worm_is_an_error(run_cli, tmp_path):
    r = run_cli("verify", _lift_manifest(tmp_path, "min_worm_efficiency: 0.3", MECHS / "screw_lift.yaml"), "-j", "1")
    assert r.exit_code == 2 and "cases[0].min_worm_efficiency: checks nothing" in r.stderr, r.stderr

CARRIED = """name: carried
gravity: [0, -3, -9.81]
base: frame
end_effector: drum
links:
  - {name: frame}
  - {name: table, mass: 5.0, com: [0.05, 0.02, 0.1], inertia: [0.05, 0.06, 0.08]}
  - {name: worm, mass: 0.2, inertia: [2.0e-5, 1.0e-4, 1.0e-4]}
  - {name: drum, mass: 1.0, com: [0.01, 0, 0.02], inertia: [1.0e-3, 2.0e-3, 1.0e-3]}
joints:
  - {name: Jt, parent: frame, child: table, origin: {xyz: [0, 0, 0]}, axis: [0, 0, 1]}
  - {name: Jw, parent: table, child: worm, origin: {xyz: [0.1, 0, 0.2]}, axis: [1, 0, 0]}
  - {name: Jd, parent: table, child: drum, origin: {xyz: [0.1, 0, 0.25]}, axis: [0, 1, 0]}
gears:
  - {name: wp, kind: worm, links: [worm, drum], teeth: [2, 20], reference_diameter: 0.02, module: 0.004, friction_coefficient: 0.05, hand: left}
motors:
  - {name: mt, link: table}
  - {name: mw, link: worm}
"""


@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_worm_pair_on_a_turning_carrier_balances_power(backend):
    """The worm pair carried by a turntable that turns and accelerates under gravity (the carrier
    moves): the motors' power = dT/dt - P_gravity + the losses (from the model statement,
    tests/test_losses.py), every loss >= 0, to 1e-9; the reported loss is that one."""
    from test_losses import energy_terms, own_losses
    an = analyse(parse_mechanism(CARRIED))
    rng = np.random.default_rng(5)
    q, qd, qdd = (rng.uniform(-2, 2, (200, an.dof)), rng.uniform(-2, 2, (200, an.dof)), rng.uniform(-3, 3, (200, an.dof)))
    res = solve(an, q, qd, qdd, backend=backend)
    dT, Pg, Pe = energy_terms(an, q, qd, qdd)
    total, parts = own_losses(an, q, qd, res)
    P = np.sum(res.motor * res.motor_speed, axis=1)
    scale = 1 + np.abs(P) + np.abs(dT) + np.abs(Pg) + total
    assert np.max(np.abs(P - (dT - Pg - Pe + total)) / scale) < 1e-9
    assert all(np.all(p >= 0) for p in parts) and np.max(total) > 0
    assert np.max(np.abs(res.gear_loss.sum(axis=1) - total) / scale) < 1e-11
