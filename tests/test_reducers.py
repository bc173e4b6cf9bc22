"""Coaxial reducers (strain-wave, cycloidal; issue 35): hand cases from the model statement
(``../shared/drive-elements.md`` A, README "Reducers"), written here without the solver's code,
the deliberate bugs they catch, the catalogue life by hand, and located input errors.

The energy balances of the bundled reducer mechanisms (lossless to 1e-12, lossy with every loss
>= 0 to 1e-9) are in tests/test_losses.py and tests/test_energy.py (every bundled mechanism).
"""
from __future__ import annotations

import json
import textwrap
from pathlib import Path

import numpy as np
import pytest

from gearcli import analyse, parse_mechanism, solve
from gearcli.report.columns import named_columns

pytestmark = pytest.mark.physics
MECHS = Path(__file__).resolve().parents[1] / "mechanisms"
DESIGNS = Path(__file__).resolve().parents[1] / "designs"

HOIST = """
name: hoist
gravity: [0, 0, 0]
base: housing
end_effector: drum
links:
  - {{name: housing}}
  - {{name: wg, mass: 0.1, inertia: [1.0e-5, 1.0e-5, 2.0e-5]}}
  - {{name: drum, mass: 1.0, inertia: [1.0e-2, 1.0e-2, 2.0e-2]}}
joints:
  - {{name: Jm, parent: housing, child: wg, origin: {{xyz: [0, 0, 0]}}, axis: [0, 0, 1]}}
  - {{name: Jd, parent: housing, child: drum, origin: {{xyz: [0, 0, 0.05]}}, axis: [0, 0, {axis}]}}
gears:
  - {{name: hd, kind: {kind}, links: [wg, drum, housing], ratio: {i0}{extra}}}
motors:
  - {{name: m, link: wg}}
loads:
  - {{name: rope, link: drum, point: [0, 0, 0], frame: base, moment: [0, 0, -50]}}
"""


def hoist(i0=-100.0, extra=", efficiency: {forward: 0.8, backward: 0.6}", kind="strain_wave", axis=1):
    return analyse(parse_mechanism(HOIST.format(i0=i0, extra=extra, kind=kind, axis=axis)))


def at_speed(an, b, backend="auto"):
    """The drum at constant speed b (rad/s about its joint axis), one sample per speed."""
    b = np.asarray(b, float)[:, None]
    return named_columns(an, solve(an, np.zeros_like(b), b, np.zeros_like(b), backend=backend))


def test_strain_wave_holds_lifts_and_lowers_a_load_by_hand():
    """A 100:1 strain-wave gear (i0 = -100) against a 50 N*m rope moment on the drum (about +z,
    -50): the output torque is T = 50 N*m at any constant speed.  Holding (b = 0): lossless,
    the motor gives T/i0 = -0.5 N*m.  Lifting (b > 0, T b > 0, power flows input -> output): the
    torque on the input is -(T/i0)/eta_f, so the motor gives -0.5/0.8 = -0.625 N*m.  Lowering
    (b < 0): -(T/i0) eta_b, the motor 0.5 x 0.6 = -0.3 N*m (it holds back less than it lifts)."""
    an = hoist()
    c = at_speed(an, [0.0, 1.5, -1.5])
    assert np.allclose(c["gear:hd:torque"], 50.0, rtol=1e-14)
    assert np.allclose(c["motor:m"], [-0.5, -0.5 / 0.8, -0.5 * 0.6], rtol=1e-13)
    assert np.allclose(c["gear:hd:input_torque"], [0.5, 0.5 / 0.8, 0.5 * 0.6], rtol=1e-13)
    # the loss: P_in - P_out = (motor power) - (rope power), >= 0: lifting 1.5 x 50 (1/0.8 - 1)
    assert np.allclose(c["gear:hd:loss"], [0.0, 75.0 * (1 / 0.8 - 1), 75.0 * (1 - 0.6)], rtol=1e-12)


def test_opposite_joint_axes_keep_the_model_ratio():
    """The drum's joint axis written as -z: i0 is about one common axis (the model's), so the
    motor torques are the same; the output torque is about the drum's own axis (-50 there)."""
    up, down = at_speed(hoist(), [1.5, -1.5]), at_speed(hoist(axis=-1), [-1.5, 1.5])
    assert np.allclose(down["motor:m"], up["motor:m"], rtol=1e-13)
    assert np.allclose(down["gear:hd:torque"], -50.0, rtol=1e-14)


def test_self_locking_reducer_needs_no_motor_torque_to_lower():
    """eta_b = 0 (self-locking): lowering at constant speed the input gets no torque from the
    element, the motor none either (an overhauling load needs the motor to drive it down)."""
    c = at_speed(hoist(extra=", efficiency: {forward: 0.5, backward: 0.0}"), [-1.0])
    assert c["motor:m"][0] == 0.0 and c["gear:hd:loss"][0] == pytest.approx(50.0)


def test_no_load_torque_opposes_the_input_rate():
    """T0 = 0.05 N*m against the input's rate a = i0 b: at b = +1 (a = -100 rad/s) the
    element's torque on the input gains +0.05; at rest nothing; the loss gains T0 |a|."""
    c = at_speed(hoist(extra=", no_load_torque: 0.05"), [0.0, 1.0, -1.0])
    assert np.allclose(c["gear:hd:input_torque"], [0.5, 0.55, 0.45], rtol=1e-13)
    assert np.allclose(c["gear:hd:loss"], [0.0, 5.0, 5.0], rtol=1e-12)


HOUSING = """
name: swivel
gravity: [0, 0, 0]
base: base
end_effector: out
links:
  - {name: base}
  - {name: housing, mass: 1.0, inertia: [1.0e-3, 1.0e-3, 1.0e-3]}
  - {name: wg, mass: 0.1, inertia: [1.0e-5, 1.0e-5, 2.0e-5]}
  - {name: out, mass: 1.0, inertia: [1.0e-2, 1.0e-2, 2.0e-2]}
joints:
  - {name: Jh, parent: base, child: housing, origin: {xyz: [0, 0, 0]}, axis: [1, 0, 0]}
  - {name: Jm, parent: housing, child: wg, origin: {xyz: [0, 0, 0.1]}, axis: [0, 0, 1]}
  - {name: Jo, parent: housing, child: out, origin: {xyz: [0, 0, 0.15]}, axis: [0, 0, 1]}
gears:
  - {name: hd, kind: cycloidal, links: [wg, out, housing], ratio: 81}
motors:
  - {name: m, link: wg}
  - {name: tilt, link: housing}
loads:
  - {name: tool, link: out, point: [0, 0, 0], frame: link, moment: [0, 0, 30]}
"""


def test_housing_takes_minus_T_times_one_minus_one_over_i0():
    """A cycloidal reducer (i0 = 81) whose housing tilts on a joint about x: at rest with a
    30 N*m tool moment on the output, T = -30 N*m; the input balances the motor, which gives
    T/i0; the housing takes the element's -T (1 - 1/i0) = 29.63 N*m and the motor stator's
    -T/i0 = 0.37 N*m, their sum reaching the base through the joint about x as a bending
    moment of |T| = 30 N*m (a wrong housing share would leave the housing unbalanced)."""
    an = analyse(parse_mechanism(HOUSING))
    q = np.zeros((1, 2))
    c = named_columns(an, solve(an, q, q, q))
    T, i0 = c["gear:hd:torque"][0], 81.0
    assert T == pytest.approx(-30.0, rel=1e-14)
    assert c["motor:m"][0] == pytest.approx(T / i0, rel=1e-13)
    housing_share = -T * (1 - 1 / i0)
    assert c["joint:Jh:bending"][0] == pytest.approx(abs(housing_share - c["motor:m"][0]), rel=1e-13)


LOSSY_SWIVEL = HOUSING.replace("gravity: [0, 0, 0]", "gravity: [0, -9.81, -3]").replace(
    "ratio: 81}", "ratio: 81, efficiency: {forward: [[0, 0.6], [50, 0.8], [200, 0.85]], backward: [[0, 0.3], [100, 0.5]]},"
    " no_load_torque: [[0, 0.02], [300, 0.2]]}")


@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_lossy_reducer_on_a_moving_housing_balances_power(backend):
    """The swivel with speed-dependent efficiencies and no-load torque (tables), its housing
    tilting: the motors' power = dT/dt - P_gravity + the reducer's loss (computed from the model
    statement in tests/test_losses.py, sharing no code with the solver), every loss >= 0, to
    1e-9, on both paths; the kernel equals numpy to 1e-12 of each sample's largest load."""
    from test_losses import energy_terms, own_losses
    an = analyse(parse_mechanism(LOSSY_SWIVEL))
    rng = np.random.default_rng(5)
    q, qd, qdd = rng.uniform(-2, 2, (300, 2)), rng.uniform(-4, 4, (300, 2)), rng.uniform(-9, 9, (300, 2))
    qd[::5, 1] = 0.0                       # the output at rest relative to the housing: lossless
    res = solve(an, q, qd, qdd, backend=backend)
    assert res.backend == backend
    dT, Pg, Pe = energy_terms(an, q, qd, qdd)
    total, parts = own_losses(an, q, qd, res)
    P_motor = np.sum(res.motor * res.motor_speed, axis=1)
    scale = 1.0 + np.abs(P_motor) + np.abs(dT) + np.abs(Pg) + total
    assert np.max(np.abs(P_motor - (dT - Pg - Pe + total)) / scale) < 1e-9
    assert all(np.all(p >= -1e-12 * scale) for p in parts) and np.all(total[::5] < 1e-12 * scale[::5])
    assert np.max(np.abs(res.gear_loss[:, 0] - total) / scale) < 1e-11
    if backend == "llvm":
        ref = named_columns(an, solve(an, q, qd, qdd, backend="numpy"))
        got = named_columns(an, res)
        big = 1.0 + np.max(np.abs(np.column_stack(list(ref.values())[1:])), axis=1)
        for k in ref:
            assert np.max(np.abs(got[k] - ref[k]) / big) < 1e-12, k


# --- deliberate bugs: each physics term's hand case catches its bug ---------------------------------

def test_the_hand_case_catches_a_missing_one_over_i0(monkeypatch):
    """A deliberate bug, the torque on the input without the 1/i0 (c_r times -i0): the holding
    motor torque of the hand case comes out 100x too large."""
    from gearcli.dynamics import loss_terms
    good = loss_terms.power_flow_delta              # c_r = 1 + delta -> -100 c_r
    monkeypatch.setattr(loss_terms, "power_flow_delta",
                        lambda al, A, B, sigma, s_w: al.sub(al.mul(-100.0, al.add(1.0, good(al, A, B, sigma, s_w))), 1.0))
    c = at_speed(hoist(), [0.0, 1.5], backend="numpy")     # (no kernel compiled, and cached, with the bug)
    assert not np.allclose(c["motor:m"], [-0.5, -0.5 / 0.8], rtol=1e-3)


def test_the_hand_case_catches_swapped_efficiencies(monkeypatch):
    """A deliberate bug, eta_f and eta_b swapped: lifting then needs -0.5/0.6, not -0.5/0.8."""
    from gearcli.dynamics import loss_terms
    good = loss_terms.power_flow_coefficients
    monkeypatch.setattr(loss_terms, "power_flow_coefficients",
                        lambda al, speed, forward, backward, mode=0: good(al, speed, backward, forward, mode))
    c = at_speed(hoist(), [1.5, -1.5], backend="numpy")
    assert not np.allclose(c["motor:m"], [-0.5 / 0.8, -0.5 * 0.6], rtol=1e-3)


def test_the_crossed_roller_hand_case_catches_a_missing_moment_term(run_cli, tmp_path, monkeypatch):
    """A deliberate bug, P_c without 2M/d_p: tests/test_verify.py's hand life of a crossed-roller
    bearing then differs (here: the cobot joint's bearing life changes by orders of magnitude)."""
    from gearcli.design import iso281
    good = iso281.crossed_roller_load
    case = ("cases:\n  - {name: c, mechanism: %s, trajectories: [%s], cycles_per_hour: 400, bearing_life_h: 1000}\n"
            % (MECHS / "cobot_joint.yaml", MECHS / "cobot_joint_traj.csv"))
    lives = []
    for fn in (good, lambda Fr, Fa, M, d_p: good(Fr, Fa, 0.0 * np.asarray(M), d_p)):
        monkeypatch.setattr(iso281, "crossed_roller_load", fn)
        doc = verify_json(run_cli, tmp_path, case)
        lives.append(checks(doc)[("bearing J2/crossed_roller", "L10 life")]["value"])
    assert lives[1] > 3 * lives[0]


# --- the catalogue life, by hand -----------------------------------------------------------------

RATED = """
    rating: {rated_torque: 60, rated_input_speed: 209.44, rated_life: 35000, life_basis: L50,
             average_torque_limit: 45, average_input_speed_limit: 300, repeated_peak_torque: 100,
             max_input_speed: 500}"""


def verify_json(run_cli, tmp_path, manifest):
    (tmp_path / "design.yaml").write_text(manifest)
    out = tmp_path / "out.json"
    r = run_cli("verify", tmp_path / "design.yaml", "--json", out, "-j", "1")
    assert r.exit_code in (0, 1), r.stderr
    return json.loads(out.read_text())


def checks(doc):
    return {(c["component"], c["quantity"]): c for c in doc["checks"]}


def test_two_segment_duty_life_by_hand(run_cli, tmp_path):
    """Two constant segments make one duty cycle (two trajectories, 600 cycles an hour, so
    1,800 s of motion and 1,800 s of pause an hour): 2 s at b = 1 rad/s (|a| = 100 rad/s)
    against 50 N*m, then 1 s at b = -2 rad/s (|a| = 200) against 20 N*m.  By the catalogue law
    T_av = ((100 50^3 2 + 200 20^3 1) / (100 2 + 200 1))^(1/3), n_av = 600 (200 + 200) / 3600,
    L50 = 35,000 (209.44 / n_av) (60 / T_av)^3."""
    rated = HOIST.format(i0=-100.0, extra="", kind="strain_wave", axis=1).replace(
        "ratio: -100.0}", "ratio: -100.0,\n" + textwrap.indent(textwrap.dedent(RATED).strip(), "     ") + "}")
    (tmp_path / "hoist.yaml").write_text(rated)
    for name, b, M, span in (("s1", 1.0, -50.0, 2.0), ("s2", -2.0, -20.0, 1.0)):
        t = np.linspace(0.0, span, 201)
        np.savetxt(tmp_path / f"{name}.csv", np.column_stack([t, b * t, np.full_like(t, b), 0 * t, np.full_like(t, M)]),
                   delimiter=",", header="t,q:Jd,qd:Jd,qdd:Jd,load:rope:mz", comments="")
    doc = verify_json(run_cli, tmp_path, "cases:\n  - {name: c, mechanism: hoist.yaml, trajectories: [s1.csv, s2.csv],"
                                         " cycles_per_hour: 600, reducer_life_h: 50000}\n")
    got = checks(doc)
    T_av = ((100 * 50**3 * 2 + 200 * 20**3 * 1) / (100 * 2 + 200 * 1)) ** (1 / 3)
    n_av = 600 * (200 + 200) / 3600
    assert got[("reducer hd", "average torque T_av")]["value"] == pytest.approx(T_av, rel=1e-12)
    assert got[("reducer hd", "average input speed n_av")]["value"] == pytest.approx(n_av, rel=1e-12)
    assert got[("reducer hd", "L50 life")]["value"] == pytest.approx(35000 * (209.44 / n_av) * (60 / T_av) ** 3, rel=1e-12)
    assert got[("reducer hd", "repeated peak torque")]["value"] == pytest.approx(50.0, rel=1e-13)
    assert got[("reducer hd", "input speed")]["value"] == pytest.approx(200.0, rel=1e-13)
    assert got[("reducer hd", "L50 life")]["passed"] is True


def test_bundled_reducer_design_fails_on_the_reducer_life(run_cli, tmp_path):
    """designs/cobot_joint_reducer.yaml: every check passes except the reducer's L50 life; its
    plot (|T| against the T_av the life needs, and the running life) and the tight average
    torque's are written."""
    r = run_cli("verify", DESIGNS / "cobot_joint_reducer.yaml", "--plots", tmp_path / "plots")
    assert r.exit_code == 1
    assert "FAILED pick_and_place: reducer hd: L50 life" in r.stdout
    assert r.stdout.count("FAILED") == 1
    assert sorted(p.name for p in (tmp_path / "plots").iterdir()) == [
        "pick_and_place__reducer_hd__L50_life.png", "pick_and_place__reducer_hd__average_torque_T_av.png"]


# --- input errors ----------------------------------------------------------------------------------

@pytest.mark.parametrize("old, new, place, message", [
    ("ratio: -100.0", "ratio: 1.0", "gears[0].ratio", "must not be 0 or 1"),
    ("ratio: -100.0", "ratio: 0", "gears[0].ratio", "must not be 0 or 1"),
    ("ratio: -100.0", "teeth: [202, 200]", "gears[0].teeth", "more teeth than the flexspline"),
    ("ratio: -100.0", "ratio: -100, teeth: [200, 202]", "gears[0].teeth", "give ratio or teeth, not both"),
    ("kind: strain_wave, links: [wg, drum, housing], ratio: -100.0", "kind: cycloidal, links: [wg, drum, housing], teeth: [200, 202]",
     "gears[0].teeth", "are for a strain_wave reducer"),
    ("forward: 0.8", "forward: 1.2", "gears[0].efficiency.forward", "must be in (0, 1]"),
    ("forward: 0.8", "forward: 0", "gears[0].efficiency.forward", "must be in (0, 1]"),
    ("backward: 0.6", "backward: -1", "gears[0].efficiency.backward", "must be in (-1, 1]"),
    ("backward: 0.6", "backward: [[0, 0.6], [10, 0.7], [5, 0.8]]", "gears[0].efficiency.backward[2]", "must start at >= 0 rad/s and increase"),
    ("backward: 0.6}", "backward: 0.6}, no_load_torque: -0.1", "gears[0].no_load_torque", "must be in [0, inf]"),
    ("links: [wg, drum, housing]", "links: [wg, drum, wg]", "gears[0].links", "three different links"),
    ("links: [wg, drum, housing]", "links: [wg, drum, nowhere]", "gears[0].links[2]", "nowhere"),
    ("backward: 0.6}", "backward: 0.6}, torsional_stiffness: {torque: [5, 2], rate: [1, 2, 3]}",
     "gears[0].torsional_stiffness.torque", "0 < T1 < T2"),
    ("backward: 0.6}", "backward: 0.6}, rating: {rated_torque: 60, rated_input_speed: 200, rated_life: 1000}",
     "gears[0].rating", "life_basis"),
])
def test_reducer_input_problems_are_located(run_cli, tmp_path, old, new, place, message):
    """Each bad reducer declaration: one located line naming the key, exit 2, no traceback."""
    text = HOIST.format(i0=-100.0, extra=", efficiency: {forward: 0.8, backward: 0.6}", kind="strain_wave", axis=1)
    assert old in text
    (tmp_path / "m.yaml").write_text(text.replace(old, new, 1))
    r = run_cli("check", tmp_path / "m.yaml")
    assert r.exit_code == 2 and "Traceback" not in r.stderr
    line = next((ln for ln in r.stderr.splitlines() if place in ln), "")
    assert message in line, r.stderr


def test_members_off_one_axis_are_a_located_error(run_cli, tmp_path):
    """The output's joint 1 mm off the input's axis: not a coaxial reducer."""
    text = HOIST.format(i0=-100.0, extra="", kind="strain_wave", axis=1).replace("xyz: [0, 0, 0.05]", "xyz: [0.001, 0, 0.05]")
    (tmp_path / "m.yaml").write_text(text)
    r = run_cli("check", tmp_path / "m.yaml")
    assert r.exit_code == 2 and "gears[0].links" in r.stderr and "do not turn about one axis" in r.stderr



# --- URDF ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("text", [LOSSY_SWIVEL, HOIST.format(i0=-100.0, extra="", kind="strain_wave", axis=1)],
                         ids=["lossy-tables", "lossless"])
@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_urdf_round_trip_solves_bit_identically(run_cli, tmp_path, text, backend):
    """gearcli export writes a gearcli:reducer (efficiency and no-load tables, stiffness, its
    gearcli:rating); read back, the reducer is the same and every output column is bit for bit
    the YAML's, on both paths."""
    from gearcli import load_mechanism
    (tmp_path / "m.yaml").write_text(text)
    r = run_cli("export", tmp_path / "m.yaml", "-o", tmp_path / "m.urdf")
    assert r.exit_code == 0, r.stderr
    a, b = (analyse(load_mechanism(tmp_path / f)) for f in ("m.yaml", "m.urdf"))
    assert a.mech.gears[0].reducer == b.mech.gears[0].reducer and a.mech.gears[0].ratio == b.mech.gears[0].ratio
    rng = np.random.default_rng(2)
    q, qd, qdd = (rng.uniform(-3, 3, (200, a.dof)) for _ in range(3))
    ca, cb = (named_columns(x, solve(x, q, qd, qdd, backend=backend)) for x in (a, b))
    assert list(ca) == list(cb) and all(np.array_equal(ca[k], cb[k]) for k in ca)


def test_cobot_joint_urdf_keeps_the_rating_and_the_crossed_roller(run_cli, tmp_path):
    """The bundled cobot joint exported and read back: the reducer's catalogue rating, teeth and
    the crossed-roller output bearing are the file's."""
    from gearcli import load_mechanism
    r = run_cli("export", MECHS / "cobot_joint.yaml", "-o", tmp_path / "c.urdf")
    assert r.exit_code == 0, r.stderr
    a, b = load_mechanism(MECHS / "cobot_joint.yaml"), load_mechanism(tmp_path / "c.urdf")
    assert b.gears[0].reducer.rating == a.gears[0].reducer.rating and b.gears[0].teeth == (200, 202)
    assert b.joints[1].bearings == a.joints[1].bearings


@pytest.mark.parametrize("attrs, message", [
    ('efficiency_forward="1.5"', ".efficiency_forward: forward efficiency eta_f must be in (0, 1], got 1.5"),
    ('efficiency_forward="0 0.5 10"', "a table is pairs"),
    ('ratio="1"', "must not be 0 or 1"),
    ('kind="planetary" ratio="-50"', "kind must be one of strain_wave, cycloidal"),
])
def test_urdf_reducer_problems_are_located(run_cli, tmp_path, attrs, message):
    """A bad gearcli:reducer: one line naming the element, exit 2."""
    (tmp_path / "m.yaml").write_text(HOIST.format(i0=-100.0, extra="", kind="strain_wave", axis=1))
    assert run_cli("export", tmp_path / "m.yaml", "-o", tmp_path / "m.urdf").exit_code == 0
    text = (tmp_path / "m.urdf").read_text()
    key = attrs.split("=")[0]
    import re
    text = re.sub(rf' {key}="[^"]*"', "", text) if key in text else text
    if "kind=" in attrs:
        text = text.replace('kind="strain_wave" ', "").replace(' ratio="-100.0"', "")
    text = text.replace("<gearcli:reducer ", f"<gearcli:reducer {attrs} ")
    (tmp_path / "m.urdf").write_text(text)
    r = run_cli("check", tmp_path / "m.urdf")
    assert r.exit_code == 2 and "Traceback" not in r.stderr
    assert any("gearcli:reducer 'hd'" in ln and message in ln for ln in r.stderr.splitlines()), r.stderr


# --- mass matrix, forward dynamics, simulate ---------------------------------------------------------

@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_mass_matrix_reflects_the_input_through_i0_squared(backend):
    """The cobot joint: M = I_arm about the joint axis (its own inertia, its mass at its centre
    of mass's distance from the axis) + i0^2 I_rotor: the wave generator's 2.0e-4 kg*m^2 seen
    100^2 times, by hand from the file's numbers (the payload attached: + 3 kg at 0.4 m)."""
    from gearcli import load_mechanism, mass_matrix
    an = analyse(load_mechanism(MECHS / "cobot_joint.yaml"))
    q = np.array([[0.0], [1.0]])
    I_arm = 3.0e-2 + 2.0 * 0.2**2          # Iyy about the centre of mass + m r^2 (r = 0.2 m off the axis)
    M = mass_matrix(an, q, backend=backend)
    assert np.allclose(M[:, 0, 0], I_arm + 100.0**2 * 2.0e-4, rtol=1e-12)
    M = mass_matrix(an, q, backend=backend, attach={"part": np.ones(2)})
    assert np.allclose(M[:, 0, 0], I_arm + 3.0 * 0.4**2 + 100.0**2 * 2.0e-4, rtol=1e-12)


def test_forward_dynamics_inverts_the_lossy_solve():
    """forward_dynamics of the motor torques solve gives back the accelerations, through the
    reducer's power-flow factor and no-load torque (forward and back-driven samples)."""
    from gearcli import forward_dynamics, load_mechanism
    an = analyse(load_mechanism(MECHS / "cobot_joint.yaml"))
    rng = np.random.default_rng(4)
    q, qd, qdd = rng.uniform(-1, 1, (50, 1)), rng.uniform(-2, 2, (50, 1)), rng.uniform(-6, 6, (50, 1))
    res = solve(an, q, qd, qdd)
    back = forward_dynamics(an, q, qd, res.motor)
    assert np.max(np.abs(back - qdd)) < 1e-9 * (1 + np.abs(qdd).max())


def test_simulate_runs_the_cobot_joint(run_cli, tmp_path):
    """gearcli simulate drives the cobot joint with the motor torques of a planned motion
    (solve, then simulate from the same start): the simulated angle follows the planned one.
    The motion never reverses: at a reversal the power-flow factor jumps between 1/eta_f and
    eta_b where a held state would be needed, which simulate does not model (README, Reducers)."""
    from gearcli import load_mechanism
    an = analyse(load_mechanism(MECHS / "cobot_joint.yaml"))
    t = np.linspace(0.0, 2.0, 401)
    from numpy import cos, pi, sin
    q = 0.5 * t + 0.1 * sin(pi * t)
    qd, qdd = 0.5 + 0.1 * pi * cos(pi * t), -0.1 * pi**2 * sin(pi * t)
    res = solve(an, q[:, None], qd[:, None], qdd[:, None])
    np.savetxt(tmp_path / "torque.csv", np.column_stack([t, res.motor[:, 0]]), delimiter=",",
               header="t,motor:motor", comments="")
    r = run_cli("simulate", MECHS / "cobot_joint.yaml", tmp_path / "torque.csv", "--q0", "0", "--qd0", repr(0.5 + 0.1 * pi),
                "-o", tmp_path / "sim.csv")
    assert r.exit_code == 0, r.stderr
    sim = np.genfromtxt(tmp_path / "sim.csv", delimiter=",", names=True)
    assert np.max(np.abs(np.interp(t, sim["t"], sim["qJ2"]) - q)) < 2e-3


def test_a_reducer_that_never_turns_has_no_finite_life(run_cli, tmp_path):
    """Holding a load without moving: n_av = 0, the catalogue life is infinite, reported with
    its reason (JSON value null and value_note), and the check passes."""
    rated = HOIST.format(i0=-100.0, extra="", kind="strain_wave", axis=1).replace(
        "ratio: -100.0}", "ratio: -100.0,\n" + textwrap.indent(textwrap.dedent(RATED).strip(), "     ") + "}")
    (tmp_path / "hoist.yaml").write_text(rated)
    t = np.linspace(0.0, 1.0, 11)
    np.savetxt(tmp_path / "hold.csv", np.column_stack([t, 0 * t, 0 * t, 0 * t]), delimiter=",",
               header="t,q:Jd,qd:Jd,qdd:Jd", comments="")
    doc = verify_json(run_cli, tmp_path, "cases:\n  - {name: c, mechanism: hoist.yaml, trajectories: [hold.csv],"
                                         " reducer_life_h: 1000}\n")
    life = checks(doc)[("reducer hd", "L50 life")]
    assert life["value"] is None and life["passed"] is True and "does not turn" in life["value_note"]


def test_check_states_both_graph_views_of_the_reducer(run_cli):
    """gearcli check describes the reducer in one line: i0 relative to the housing, and the
    planetary view (the input as carrier) theta_O,I = (1 - 1/i0) theta_H,I, which the joint
    rates obey (the wave generator at -100 rad/s relative to the housing per rad/s of the arm)."""
    r = run_cli("check", MECHS / "cobot_joint.yaml")
    assert r.exit_code == 0
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("strain-wave reducer 'hd'"))
    assert "i0 = -100" in line and "theta_O,I = 1.01 * theta_H,I" in line
    an = analyse(parse_mechanism((MECHS / "cobot_joint.yaml").read_text()))
    rates = an.S @ np.array([1.0])                    # every real joint's rate per unit of J2's
    names = [j.name for j in an.mech.joints]
    a, b = rates[names.index("Jm")], rates[names.index("J2")]  # input and output relative to the housing (the base)
    assert a == pytest.approx(-100.0) and (b - a) == pytest.approx(1.01 * (0.0 - a))
