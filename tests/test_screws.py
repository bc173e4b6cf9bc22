"""Ball and lead screws (issue 36, ``kind: screw``): hand cases from the model statement
(``../shared/drive-elements.md`` B, README "Screws"), written here without the solver's code,
the deliberate bug they catch, the ISO 3408-5 life by hand, URDF and located input errors.

The energy balance of the bundled screw (mechanisms/screw_lift.yaml) is in tests/test_losses.py
(every bundled mechanism, the loss from the model statement) and the kernel's agreement with
numpy in tests/test_kernel.py.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from gearcli import analyse, load_mechanism, parse_mechanism, solve
from gearcli.report.columns import named_columns

pytestmark = pytest.mark.physics
MECHS = Path(__file__).resolve().parents[1] / "mechanisms"

LIFT = """
name: lift
gravity: [0, 0, 0]
base: frame
end_effector: carriage
links:
  - {{name: frame}}
  - {{name: screw, mass: 0.5, inertia: [1.0e-3, 1.0e-3, 2.0e-5]}}
  - {{name: carriage, mass: 2.0, inertia: [1.0e-3, 1.0e-3, 1.0e-3]}}
joints:
  - {{name: Js, parent: frame, child: screw, origin: {{xyz: [0, 0, 0]}}, axis: [0, 0, 1]}}
  - {{name: Jz, parent: frame, child: carriage, type: prismatic, origin: {{xyz: [0, 0, 0.1]}}, axis: [0, 0, {axis}]}}
gears:
  - {{name: bs, kind: screw, links: [screw, carriage], lead: 0.005, hand: {hand}{extra}}}
motors:
  - {{name: m, link: screw}}
loads:
  - {{name: w, link: carriage, point: [0, 0, 0], frame: base, force: [0, 0, -1000]}}
"""


def lift(extra=", efficiency: {forward: 0.9, backward: 0.8}", hand="right", axis=1):
    return analyse(parse_mechanism(LIFT.format(extra=extra, hand=hand, axis=axis)))


def at_speed(an, v, backend="numpy"):
    """The carriage at constant speed v (m/s along its joint axis), one sample per speed."""
    v = np.asarray(v, float)[:, None]
    return named_columns(an, solve(an, np.zeros_like(v), v, np.zeros_like(v), backend=backend))


@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_ball_screw_lifts_and_lowers_1_kN_by_hand(backend):
    """Lead 5 mm, 1 kN hanging on the nut: lifting (the screw drives, eta_f = 0.9) the motor
    gives T = F l / (2 pi eta_f) = 0.8842 N*m; lowering (the load drives, eta_b = 0.8)
    F l eta_b / (2 pi) = 0.6366 N*m; holding, lossless, F l / (2 pi) = 0.7958 N*m.  The axial
    force on the nut is +1 kN along the axis throughout, the nut's torque h F / eta taken by its
    guide (the prismatic joint's moment about its axis)."""
    c = at_speed(lift(), [0.0, 0.05, -0.05], backend)
    assert np.allclose(c["motor:m"], [1000 * 0.005 / (2 * math.pi), 0.8842, 0.6366], atol=5e-5)
    assert np.allclose(c["motor:m"][1:], [1000 * 0.005 / (2 * math.pi * 0.9), 1000 * 0.005 * 0.8 / (2 * math.pi)],
                       rtol=1e-12)
    assert np.allclose(c["gear:bs:force"], 1000.0, rtol=1e-13)
    assert np.allclose(c["joint:Jz:mz"], -c["motor:m"], rtol=1e-12)
    assert np.allclose(c["gear:bs:loss"], [0.0, 50 * (1 / 0.9 - 1), 50 * (1 - 0.8)], rtol=1e-12, atol=1e-15)


def test_left_hand_and_an_opposite_slide_axis_keep_the_torques():
    """A left-hand screw turns the other way for the same lift: the motor torque flips sign,
    its magnitude does not; the nut's joint axis written as -z flips the coordinate, not the
    physics."""
    right, left = at_speed(lift(), [0.05]), at_speed(lift(hand="left"), [0.05])
    assert np.allclose(left["motor:m"], -right["motor:m"], rtol=1e-13)
    down = at_speed(lift(axis=-1), [-0.05])       # q along -z: -0.05 m/s is lifting
    assert np.allclose(down["motor:m"], right["motor:m"], rtol=1e-13)


def test_self_locking_lead_screw_lowers_under_power():
    """A lead screw, mu = 0.2 on a 12 mm diameter, lead 2 mm: beta = atan(l / (pi d0)) = 3.04 deg
    < phi = atan(mu) = 11.3 deg, so eta_b = tan(beta - phi) / tan(beta) < 0: self-locking.
    Lowering at constant speed the motor must drive (its power > 0), with the torque
    -F h eta_b; lifting it gives F h / eta_f; both from the friction formulas."""
    an = analyse(parse_mechanism(LIFT.format(extra=", friction_coefficient: 0.2, diameter: 0.012", hand="right", axis=1)
                                 .replace("lead: 0.005", "lead: 0.002")))
    beta, phi = math.atan(0.002 / (math.pi * 0.012)), math.atan(0.2)
    eta_f, eta_b = math.tan(beta) / math.tan(beta + phi), math.tan(beta - phi) / math.tan(beta)
    assert eta_b < 0
    h = 0.002 / (2 * math.pi)
    c = at_speed(an, [0.01, -0.01])
    assert np.allclose(c["motor:m"], [1000 * h / eta_f, 1000 * h * eta_b], rtol=1e-12)
    assert c["motor:m:power"][1] > 0            # lowering needs the motor
    assert np.all(c["gear:bs:loss"] > 0)


def test_the_hand_case_catches_a_wrong_torque_sign(monkeypatch):
    """A deliberate bug, the screw torque's sign flipped (c_r -> -c_r): the lifting torque
    comes out -0.8842 N*m."""
    from gearcli.dynamics import loss_terms
    good = loss_terms.power_flow_delta              # c_r = 1 + delta -> -c_r
    monkeypatch.setattr(loss_terms, "power_flow_delta",
                        lambda al, A, B, sigma, s_w: al.sub(-2.0, good(al, A, B, sigma, s_w)))
    c = at_speed(lift(), [0.05])
    assert not np.allclose(c["motor:m"], [0.8842], atol=5e-5)


def test_iso_3408_life_of_a_two_segment_duty_by_hand(run_cli, tmp_path):
    """Two constant segments (600 cycles an hour): 2 s lifting 1 kN at 0.05 m/s, 1 s lowering
    400 N at 0.1 m/s.  By ISO 3408-5, with n the screw's speed: F_m = (sum |F|^3 n t / sum n t)^(1/3),
    n_m = 600 (revolutions a cycle) / 60 rev/min, L_h = (C_a / F_m)^3 10^6 / (60 n_m); static
    safety C_0a / 1 kN; the screw's top speed 0.1 m/s / h."""
    text = LIFT.format(extra=", efficiency: {forward: 0.9, backward: 0.8}, rating: {C_a: 12000, C_0a: 25000, max_speed: 300}",
                       hand="right", axis=1)
    (tmp_path / "m.yaml").write_text(text)
    for name, v, F, span in (("s1", 0.05, -1000.0, 2.0), ("s2", -0.1, -400.0, 1.0)):
        t = np.linspace(0.0, span, 201)
        np.savetxt(tmp_path / f"{name}.csv", np.column_stack([t, v * t, np.full_like(t, v), 0 * t, np.full_like(t, F)]),
                   delimiter=",", header="t,q:Jz,qd:Jz,qdd:Jz,load:w:fz", comments="")
    (tmp_path / "d.yaml").write_text("cases:\n  - {name: c, mechanism: m.yaml, trajectories: [s1.csv, s2.csv], "
                                     "cycles_per_hour: 600, screw_life_h: 5000}\n")
    r = run_cli("verify", tmp_path / "d.yaml", "--json", tmp_path / "o.json", "-j", "1")
    assert r.exit_code == 0, r.stderr
    got = {c["quantity"]: c["value"] for c in json.loads((tmp_path / "o.json").read_text())["checks"]}
    h = 0.005 / (2 * math.pi)
    n1, n2 = 0.05 / h, 0.1 / h                       # rad/s
    F_m = ((n1 * 1000**3 * 2 + n2 * 400**3 * 1) / (n1 * 2 + n2 * 1)) ** (1 / 3)
    n_m = 600 * (n1 * 2 + n2 * 1) / (2 * math.pi) / 60
    assert got["L10 life (ISO 3408-5)"] == pytest.approx((12000 / F_m) ** 3 * 1e6 / (60 * n_m), rel=1e-12)
    assert got["static safety s0"] == pytest.approx(25.0, rel=1e-13)
    assert got["speed"] == pytest.approx(0.1 / h, rel=1e-13)


def test_bundled_screw_lift_solves_on_both_paths():
    """mechanisms/screw_lift.yaml along its duty cycle: the kernel equals numpy to 1e-12 of
    each sample's largest load; the loss is >= 0 and the line efficiencies are the catalogue's."""
    from gearcli.io.trajectory import read_trajectory
    an = analyse(load_mechanism(MECHS / "screw_lift.yaml"))
    tr = read_trajectory(MECHS / "screw_lift_traj.csv", an.independent_names, linear=an.prismatic_independent,
                         payloads=["part"])
    ref = named_columns(an, solve(an, tr.q, tr.qd, tr.qdd, attach=tr.attach, backend="numpy"))
    got = named_columns(an, solve(an, tr.q, tr.qd, tr.qdd, attach=tr.attach, backend="llvm"))
    big = 1.0 + np.max(np.abs(np.column_stack(list(ref.values())[1:])), axis=1)
    for k in ref:
        assert np.max(np.abs(got[k] - ref[k]) / big) < 1e-12, k
    assert np.all(ref["gear:ballscrew:loss"] >= 0) and np.max(ref["gear:ballscrew:loss"]) > 0


@pytest.mark.parametrize("extra", [", efficiency: {forward: [[0, 0.85], [200, 0.92]], backward: 0.8}, "
                                   "rating: {C_a: 7600, C_0a: 12900, max_speed: 314}", ""], ids=["lossy", "lossless"])
@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_urdf_round_trip_solves_bit_identically(run_cli, tmp_path, extra, backend):
    """gearcli export writes a gearcli:screw; read back, every output column is the YAML's, bit
    for bit, and the screw (efficiency table, rating) is the same."""
    (tmp_path / "m.yaml").write_text(LIFT.format(extra=extra, hand="left", axis=1))
    assert run_cli("export", tmp_path / "m.yaml", "-o", tmp_path / "m.urdf").exit_code == 0
    a, b = (analyse(load_mechanism(tmp_path / f)) for f in ("m.yaml", "m.urdf"))
    assert a.mech.gears[0].screw == b.mech.gears[0].screw
    rng = np.random.default_rng(3)
    q, qd, qdd = (rng.uniform(-0.2, 0.2, (100, 1)) for _ in range(3))
    ca, cb = (named_columns(x, solve(x, q, qd, qdd, backend=backend)) for x in (a, b))
    assert list(ca) == list(cb) and all(np.array_equal(ca[k], cb[k]) for k in ca)


@pytest.mark.parametrize("old, new, place, message", [
    ("lead: 0.005", "lead: -0.005", "gears[0].lead", "lead must be positive"),
    ("lead: 0.005", "lead: 0", "gears[0].lead", "lead must be positive"),
    ("efficiency: {forward: 0.9, backward: 0.8}", "friction_coefficient: -0.1, diameter: 0.01",
     "gears[0].friction_coefficient", "must be >= 0"),
    ("efficiency: {forward: 0.9, backward: 0.8}", "friction_coefficient: 0.1", "gears[0].diameter",
     "needs both friction_coefficient and diameter"),
    ("efficiency: {forward: 0.9, backward: 0.8}", "efficiency: {forward: 0.9}, friction_coefficient: 0.1, diameter: 0.01",
     "gears[0].friction_coefficient", "not both"),
    ("efficiency: {forward: 0.9, backward: 0.8}", "efficiency: {forward: 1.1}", "gears[0].efficiency.forward", "(0, 1]"),
    ("type: prismatic, ", "", "gears[0].links[1]", "nut must slide on a prismatic"),
    ("origin: {xyz: [0, 0, 0.1]}", "origin: {xyz: [0.002, 0, 0.1]}", "gears[0].links", "not on one line"),
    ("hand: right", "hand: up", "gears[0].hand", "right"),
    ("links: [screw, carriage]", "links: [screw, screw]", "gears[0].links", "a screw needs two different links [screw, nut]"),
])
def test_screw_input_problems_are_located(run_cli, tmp_path, old, new, place, message):
    """Each bad screw declaration: one located line naming the key, exit 2, no traceback."""
    text = LIFT.format(extra=", efficiency: {forward: 0.9, backward: 0.8}", hand="right", axis=1)
    assert old in text
    (tmp_path / "m.yaml").write_text(text.replace(old, new, 1))
    r = run_cli("check", tmp_path / "m.yaml")
    assert r.exit_code == 2 and "Traceback" not in r.stderr
    line = next((ln for ln in r.stderr.splitlines() if place in ln), "")
    assert message in line, r.stderr
