"""Timing belts (issue 36, ``kind: belt``): hand cases from the model statement
(``../shared/drive-elements.md`` C, README "Timing belts"), written here without the solver's
code, the deliberate bug they catch, the slack error and located input errors."""
from __future__ import annotations

import math

import numpy as np
import pytest

from gearcli import analyse, parse_mechanism, solve
from gearcli.report.columns import named_columns

pytestmark = pytest.mark.physics

BELT = """
name: belt_drive
gravity: [0, 0, 0]
base: frame
end_effector: big
links:
  - {{name: frame}}
  - {{name: small, mass: 0.1, inertia: [1.0e-5, 1.0e-5, 2.0e-5]}}
  - {{name: big, mass: 0.5, inertia: [1.0e-4, 1.0e-4, 2.0e-4]}}
joints:
  - {{name: Js, parent: frame, child: small, origin: {{xyz: [0, 0, 0]}}, axis: [0, 0, 1]}}
  - {{name: Jb, parent: frame, child: big, origin: {{xyz: [0.2, 0, 0]}}, axis: [0, 0, 1]}}
gears:
  - {{name: belt, kind: belt, links: [small, big], radii: [0.02, 0.04], pretension: {T}, belt_point: [0, 0, 0.01]{extra}}}
motors:
  - {{name: m, link: small}}
loads:
  - {{name: out, link: big, point: [0, 0, 0], frame: base, moment: [0, 0, {M}]}}
"""


def drive(T=100.0, M=-4.0, extra=""):
    return analyse(parse_mechanism(BELT.format(T=T, M=M, extra=extra)))


def at_speed(an, w, backend="numpy"):
    w = np.asarray(w, float)[:, None]
    return named_columns(an, solve(an, np.zeros_like(w), w, np.zeros_like(w), backend=backend))


def spans():
    """The outer tangents by hand: centres 0.2 m apart along x, r_j = 0.02, r_k = 0.04 m:
    sin(alpha) = (r_j - r_k)/d = -0.1; span A's normal m_A = cos(alpha) y + sin(alpha) x."""
    sa = (0.02 - 0.04) / 0.2
    ca = math.sqrt(1 - sa * sa)
    mA, mB = np.array([sa, ca, 0.0]), np.array([sa, -ca, 0.0])
    Cj, Ck = np.zeros(3), np.array([0.2, 0.0, 0.0])
    eA = (Ck + 0.04 * mA) - (Cj + 0.02 * mA)
    eB = (Ck + 0.04 * mB) - (Cj + 0.02 * mB)
    return eA / np.linalg.norm(eA), eB / np.linalg.norm(eB), ca


@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_belt_carrying_a_torque_by_hand(backend):
    """T_i = 100 N, 2 N*m on the 20 mm pulley (4 N*m on the 40 mm one): E = 100 N, the spans at
    150 N and 50 N; each shaft's radial load is the vector sum of its two span tensions; at rest
    without load both spans are at T_i and the shafts are pulled together by 2 T_i cos(alpha)."""
    eA, eB, ca = spans()
    c = at_speed(drive(), [0.0, 1.0, -1.0], backend)
    assert np.allclose(c["motor:m"], 2.0, rtol=1e-13)
    assert np.allclose(c["gear:belt:effective_pull"], 100.0, rtol=1e-12)
    assert np.allclose(c["gear:belt:tension_a"], 150.0, rtol=1e-12) and np.allclose(c["gear:belt:tension_b"], 50.0, rtol=1e-12)
    shaft = np.linalg.norm(150.0 * eA + 50.0 * eB)
    assert np.allclose(c["joint:Js:radial"], shaft, rtol=1e-12) and np.allclose(c["joint:Jb:radial"], shaft, rtol=1e-12)
    rest = at_speed(drive(M=0.0), [0.0], backend)
    assert rest["gear:belt:tension_a"][0] == pytest.approx(100.0, abs=1e-10)
    assert rest["joint:Js:radial"][0] == pytest.approx(2 * 100.0 * ca, rel=1e-12)


def test_the_hand_case_catches_swapped_spans(monkeypatch):
    """A deliberate bug, the spans swapped in E's column terms (+E/2 on span B, -E/2 on A; the
    terms both paths sum, :mod:`gearcli.dynamics.column_terms`): the hand case's tension of
    span A comes out 50 N, not 150 N, on either path."""
    from gearcli.dynamics import column_terms
    good = column_terms._mesh

    def swapped(an, ci, L, t_pos):
        cols = good(an, ci, L, t_pos)
        if an.mech.gears[an.circuits[ci].gear].belt is None:
            return cols
        return [[(kind, X, sgn, -coef, d, p) for kind, X, sgn, coef, d, p in terms] for terms in cols]
    monkeypatch.setattr(column_terms, "_mesh", swapped)
    for backend in ("numpy", "llvm"):
        c = at_speed(drive(), [1.0], backend)
        assert not np.allclose(c["gear:belt:tension_a"], 150.0, rtol=1e-6), backend


def test_a_slack_span_is_a_located_error(run_cli, tmp_path):
    """T_i = 40 N against E = 100 N: the slack span would be at -10 N; gearcli solve names the
    sample's time and line, exit 2, nothing written."""
    (tmp_path / "m.yaml").write_text(BELT.format(T=40.0, M=-4.0, extra=""))
    t = np.linspace(0, 1, 5)
    np.savetxt(tmp_path / "t.csv", np.column_stack([t, t, np.ones_like(t), 0 * t]), delimiter=",",
               header="t,q:Jb,qd:Jb,qdd:Jb", comments="")
    r = run_cli("solve", tmp_path / "m.yaml", tmp_path / "t.csv", "-o", tmp_path / "o.csv")
    assert r.exit_code == 2 and not (tmp_path / "o.csv").exists()
    assert "t.csv:2: sample t = 0 s: belt 'belt' goes slack: pretension T_i = 40 N < |E|/2 = 50 N" in r.stderr


def test_lossy_belt_loses_on_the_driven_pulley():
    """eta = 0.95 forward: the motor drives the big pulley at 1 rad/s against 4 N*m (4 W): the
    motor gives 4 / 0.95 W; backward (the load drives at -1 rad/s, eta_b = 0.9) it receives
    4 x 0.9 W; the loss is the difference, >= 0; E includes the loss (it is the span difference)."""
    an = drive(extra=", efficiency: {forward: 0.95, backward: 0.9}")
    c = at_speed(an, [1.0, -1.0])
    P = c["motor:m:power"]
    assert P[0] == pytest.approx(4.0 / 0.95, rel=1e-12) and P[1] == pytest.approx(-4.0 * 0.9, rel=1e-12)
    assert np.allclose(c["gear:belt:loss"], [4.0 / 0.95 - 4.0, 4.0 - 3.6], rtol=1e-12)


@pytest.mark.parametrize("old, new, place, message", [
    ("pretension: 100.0", "pretension: -1", "gears[0].pretension", ">= 0"),
    ("radii: [0.02, 0.04]", "radii: [0.02, -0.04]", "gears[0].radii", "positive"),
    ("radii: [0.02, 0.04]", "radii: [0.25, 0.04]", "gears[0].links", "overlap"),
    ("origin: {xyz: [0.2, 0, 0]}, axis: [0, 0, 1]", "origin: {xyz: [0.2, 0, 0]}, axis: [0, 0.1, 1]", "gears[0].links",
     "not parallel"),
    ("radii: [0.02, 0.04]", "teeth: [20, 40]", "gears[0]", "teeth and pitch"),
])
def test_belt_input_problems_are_located(run_cli, tmp_path, old, new, place, message):
    text = BELT.format(T=100.0, M=-4.0, extra="")
    assert old in text
    (tmp_path / "m.yaml").write_text(text.replace(old, new, 1))
    r = run_cli("check", tmp_path / "m.yaml")
    assert r.exit_code == 2 and "Traceback" not in r.stderr
    line = next((ln for ln in r.stderr.splitlines() if place + ":" in ln or place + "." in ln), "")
    assert message in line, r.stderr


def test_bundled_design_is_decided_by_the_belt_pretension(run_cli, tmp_path):
    """designs/scara_belt_bearings.yaml fails on the motor-pulley shaft's upper bearing life alone;
    the same case with the pretension lowered from 300 N to 100 N (still taut: |E|/2 < 100 N along
    the cycle) passes: the pretension, not the motion's load, decides it."""
    from pathlib import Path
    root = Path(__file__).resolve().parents[1]
    r = run_cli("verify", root / "designs" / "scara_belt_bearings.yaml")
    assert r.exit_code == 1 and r.stdout.count("FAILED") == 1
    assert "FAILED pick_and_place: bearing Jm1/upper: L10 life" in r.stdout
    (tmp_path / "scara.yaml").write_text((root / "mechanisms" / "scara.yaml").read_text().replace(
        "pretension: 300,", "pretension: 100,"))
    (tmp_path / "d.yaml").write_text((root / "designs" / "scara_belt_bearings.yaml").read_text().replace(
        "../mechanisms/scara.yaml", "scara.yaml").replace("../mechanisms/scara_traj.csv", str(root / "mechanisms" / "scara_traj.csv")))
    r = run_cli("verify", tmp_path / "d.yaml")
    assert r.exit_code == 0, r.stdout + r.stderr


def test_scara_urdf_round_trip_solves_bit_identically(run_cli, tmp_path):
    """The bundled SCARA (belt, strain-wave gear, ball screw) exported and read back: the
    elements in the file's order, every output column bit for bit the YAML's."""
    from pathlib import Path
    from gearcli import load_mechanism
    src = Path(__file__).resolve().parents[1] / "mechanisms" / "scara.yaml"
    assert run_cli("export", src, "-o", tmp_path / "s.urdf").exit_code == 0
    a, b = analyse(load_mechanism(src)), analyse(load_mechanism(tmp_path / "s.urdf"))
    assert [g.name for g in a.mech.gears] == [g.name for g in b.mech.gears]
    assert a.mech.gears[0].belt == b.mech.gears[0].belt
    rng = np.random.default_rng(8)
    q, qd, qdd = (rng.uniform(-1, 1, (100, 3)) for _ in range(3))
    ca, cb = (named_columns(x, solve(x, q, qd, qdd)) for x in (a, b))
    assert list(ca) == list(cb) and all(np.array_equal(ca[k], cb[k]) for k in ca)


@pytest.mark.parametrize("name, unit", [("gear:b:tension_a", "N"), ("gear:b:tension_b", "N"), ("gear:b:effective_pull", "N"),
                                        ("gear:s:force", "N"), ("gear:w:axial", "N"), ("gear:r:input_torque", "N·m"),
                                        ("gear:r:windup", "rad")])
def test_plot_reads_the_drive_elements_units_from_a_csv(name, unit):
    """gearcli plot groups a CSV's columns by the unit their names give (a CSV carries none): the
    drive elements' columns have theirs (they were drawn on a unit-less 'value' axis)."""
    from gearcli.report.loads_files import csv_unit
    assert csv_unit(name) == unit


CARRIED = """name: carried
gravity: [0, -3, -9.81]
base: frame
end_effector: big
links:
  - {name: frame}
  - {name: table, mass: 5.0, com: [0.05, 0.02, 0.1], inertia: [0.05, 0.06, 0.08]}
  - {name: small, mass: 0.1, inertia: [1.0e-5, 1.0e-5, 2.0e-5]}
  - {name: big, mass: 0.5, com: [0.02, 0, 0], inertia: [1.0e-4, 1.0e-4, 2.0e-4]}
joints:
  - {name: Jt, parent: frame, child: table, origin: {xyz: [0, 0, 0]}, axis: [0, 0, 1]}
  - {name: Js, parent: table, child: small, origin: {xyz: [-0.1, 0, 0.1]}, axis: [0, 0, 1]}
  - {name: Jb, parent: table, child: big, origin: {xyz: [-0.1, 0.2, 0.1]}, axis: [0, 0, 1]}
gears:
  - {name: belt, kind: belt, links: [small, big], radii: [0.02, 0.04], pretension: 2000, belt_point: [0, 0, 0.1], efficiency: {forward: 0.95, backward: 0.9}}
motors:
  - {name: mt, link: table}
  - {name: ms, link: small}
"""


@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_belt_on_a_turning_carrier_balances_power(backend):
    """The belt drive carried by a turntable that turns and accelerates under gravity (the carrier
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


def test_urdf_belt_with_an_odd_efficiency_table_is_a_located_error(run_cli, tmp_path):
    """efficiency_forward="0 0.9 10" (an odd count) on a gearcli:belt: one line naming the
    element and the attribute, exit 2, no traceback (it raised a numpy reshape error)."""
    (tmp_path / "m.yaml").write_text(BELT.format(T=100.0, M=-4.0, extra=", efficiency: {forward: 0.95}"))
    assert run_cli("export", tmp_path / "m.yaml", "-o", tmp_path / "m.urdf").exit_code == 0
    text = (tmp_path / "m.urdf").read_text()
    assert 'efficiency_forward="0.95"' in text
    (tmp_path / "m.urdf").write_text(text.replace('efficiency_forward="0.95"', 'efficiency_forward="0 0.9 10"'))
    r = run_cli("check", tmp_path / "m.urdf")
    assert r.exit_code == 2 and "Traceback" not in r.stderr
    assert "gearcli:belt 'belt': efficiency_forward: a table is pairs 'w_in value ...', got 3 numbers" in r.stderr


def test_simulate_stops_where_a_span_goes_slack(run_cli, tmp_path):
    """simulate, without --loads: a motor torque ramped 0 -> 5 N*m over 1 s accelerates the pulleys
    (no load).  By hand, alpha_s = tau / (I_s + I_b (r_s/r_b)^2) and the big pulley takes
    E r_b = I_b alpha_s r_s / r_b: E = 2.5e-3 alpha_s = 35.714 tau, so the 41 N pretension's slack
    span reaches zero at tau = 2.296 N*m, t = 0.45920 s.  The run stops at the first output
    sample past it (0.460 s), names the belt and that time, keeps the rows before it, exit 1."""
    (tmp_path / "m.yaml").write_text(BELT.format(T=41.0, M=0.0, extra=""))
    t = np.array([0.0, 1.0])
    np.savetxt(tmp_path / "u.csv", np.column_stack([t, 5.0 * t]), delimiter=",", header="t,motor:m", comments="")
    r = run_cli("simulate", tmp_path / "m.yaml", tmp_path / "u.csv", "-o", tmp_path / "o.csv", "--rtol", "1e-10")
    I_s, I_b, r_s, r_b = 2.0e-5, 2.0e-4, 0.02, 0.04
    tau_star = 2 * 41.0 / (I_b * r_s / r_b**2 / (I_s + I_b * (r_s / r_b) ** 2))
    t_star = tau_star / 5.0
    assert t_star == pytest.approx(0.4592, abs=1e-4)
    first = math.ceil(t_star * 1000) / 1000
    assert r.exit_code == 1, r.stderr
    assert f"belt 'belt' goes slack at t = {first:.9g} s: pretension T_i = 41 N < |E|/2 = " in r.stderr
    rows = np.loadtxt(tmp_path / "o.csv", delimiter=",", skiprows=1)
    assert rows[-1, 0] == pytest.approx(first - 1e-3, abs=1e-12) and len(rows) == round(first * 1000)
    # the rows written are the motion by hand: qd = tau(t) t / 2 / I_eff ... of the small pulley's joint
    qd_b = 5.0 * rows[:, 0] ** 2 / 2 / (I_s + I_b * (r_s / r_b) ** 2) * (r_s / r_b)
    assert np.allclose(rows[:, 2], qd_b, rtol=1e-7, atol=1e-9)


def test_simulate_without_slack_runs_to_the_end(run_cli, tmp_path):
    """The same ramp with 100 N of pretension (E/2 <= 89.3 N): no stop, every row written, exit 0."""
    (tmp_path / "m.yaml").write_text(BELT.format(T=100.0, M=0.0, extra=""))
    t = np.array([0.0, 1.0])
    np.savetxt(tmp_path / "u.csv", np.column_stack([t, 5.0 * t]), delimiter=",", header="t,motor:m", comments="")
    r = run_cli("simulate", tmp_path / "m.yaml", tmp_path / "u.csv", "-o", tmp_path / "o.csv")
    assert r.exit_code == 0, r.stderr
    assert len(np.loadtxt(tmp_path / "o.csv", delimiter=",", skiprows=1)) == 1001
