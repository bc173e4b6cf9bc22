"""``gearcli simulate`` (issue 20): integrate the exact geared dynamics over time.

* Simulate then solve: ``gearcli solve`` on the written trajectory returns the input motor
  torques (Bendix wrist, coupled motors).
* By hand: a motor, one spur stage and a flywheel under a constant torque T: the motor
  accelerates at T / J_eff, J_eff = J_rotor + J_load / n^2, the disc at -T / (n J_eff);
  a DC motor without inductance reaches omega = V/kt with time constant R J_eff / kt^2.
* Energy: UR5 (Pinocchio's kinetic and potential energy of the written states, nothing of
  gearcli's) with zero torques and gravity keeps its energy to 1e-8 over 2 s (DOP853,
  tight tolerances).
* A joint limit stops the integration: message, exit status 1, the trajectory up to it.
* ``--loads`` writes what ``gearcli solve`` writes; bad input: one line, exit 2.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from test_forward import J_LOAD, J_ROTOR, TEETH, spur_stage_yaml

N_RATIO = TEETH[1] / TEETH[0]
J_EFF = J_ROTOR + J_LOAD / N_RATIO ** 2


def read_csv(path):
    names = path.read_text().splitlines()[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {n: data[:, i] for i, n in enumerate(names)}


def write(path, text):
    path.write_text(text)
    return path


def test_simulate_then_solve_returns_the_input_torques(run_cli, mech_dir, tmp_path):
    t = np.linspace(0.0, 0.5, 11)
    T = np.column_stack([0.05 * np.sin(6 * t), 0.03 * np.cos(4 * t), -0.04 * t])
    inp = tmp_path / "in.csv"
    np.savetxt(inp, np.column_stack([t, T]), delimiter=",", comments="",
               header="t,motor:motor4,motor:motor5,motor:motor7")
    r = run_cli("simulate", mech_dir / "bendix_wrist.yaml", inp, "-o", tmp_path / "traj.csv")
    assert r.exit_code == 0, r.stderr
    assert "Wrote 501 rows to" in r.stdout
    r = run_cli("solve", mech_dir / "bendix_wrist.yaml", tmp_path / "traj.csv", "-o", tmp_path / "loads.csv",
                "--precision", "17")
    assert r.exit_code == 0, r.stderr
    loads = read_csv(tmp_path / "loads.csv")
    for k, m in enumerate(("motor4", "motor5", "motor7")):
        expected = np.interp(loads["t"], t, T[:, k])
        assert np.max(np.abs(loads[f"motor:{m}"] - expected)) < 1e-9 * np.abs(T).max()


def test_flywheel_accelerates_at_torque_over_effective_inertia(run_cli, tmp_path):
    mech = write(tmp_path / "stage.yaml", spur_stage_yaml())
    T = 0.02
    inp = write(tmp_path / "in.csv", f"t,motor:servo\n0,{T}\n1,{T}\n")
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--rtol", "1e-10", "--atol", "1e-12")
    assert r.exit_code == 0, r.stderr
    tr = read_csv(tmp_path / "traj.csv")
    a_motor = T / J_EFF                           # the motor's acceleration, by hand
    a_disc = -a_motor / N_RATIO                   # external stage: the disc turns the other way
    assert np.max(np.abs(tr["qdd:Jd"] - a_disc)) < 1e-12 * abs(a_disc)
    assert np.max(np.abs(tr["qd:Jd"] - a_disc * tr["t"])) < 1e-9 * abs(a_disc)
    assert np.max(np.abs(tr["q:Jd"] - 0.5 * a_disc * tr["t"] ** 2)) < 1e-9 * abs(a_disc)


def test_armature_inertia_would_be_caught():
    """Forgetting the reflected rotor (J_load only) or reflecting it without the square of the
    ratio changes the disc's acceleration far beyond the test's tolerance."""
    exact = 0.02 / J_EFF / N_RATIO
    for wrong in (0.02 / N_RATIO / (J_LOAD / N_RATIO ** 2), 0.02 / N_RATIO / (J_ROTOR + J_LOAD / N_RATIO)):
        assert abs(wrong - exact) > 1e-3 * exact


DC = "\n    model: {kt: 0.05, resistance: 2.0, supply_voltage: 24.0}"


def dc_stage(inductance: float | None = None) -> str:
    model = DC if inductance is None else DC.replace("}", f", inductance: {inductance}}}")
    return spur_stage_yaml().replace("  - {name: servo, link: rotor}", "  - name: servo\n    link: rotor" + model)


def test_dc_motor_reaches_its_no_load_speed_exponentially(run_cli, tmp_path):
    mech = write(tmp_path / "stage.yaml", dc_stage())
    V, kt, R = 12.0, 0.05, 2.0
    inp = write(tmp_path / "in.csv", f"t,voltage:servo\n0,{V}\n3,{V}\n")
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--rtol", "1e-10", "--atol", "1e-12",
                "--dt", "0.01")
    assert r.exit_code == 0, r.stderr
    tr = read_csv(tmp_path / "traj.csv")
    tau = R * J_EFF / kt ** 2
    omega_motor = -N_RATIO * tr["qd:Jd"]
    assert np.max(np.abs(omega_motor - V / kt * (1 - np.exp(-tr["t"] / tau)))) < 1e-7 * V / kt


def test_dc_motor_with_inductance_follows_the_linear_model(run_cli, tmp_path):
    """J_eff w' = kt i, L i' = V - R i - kt w from rest: x(t) = x_ss + expm(A t)(x0 - x_ss)."""
    from scipy.linalg import expm
    V, kt, R, L = 12.0, 0.05, 2.0, 1e-3
    mech = write(tmp_path / "stage.yaml", dc_stage(inductance=L))
    inp = write(tmp_path / "in.csv", f"t,voltage:servo\n0,{V}\n0.3,{V}\n")
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--method", "Radau", "--dt", "0.01",
                "--rtol", "1e-10", "--atol", "1e-12")
    assert r.exit_code == 0, r.stderr
    tr = read_csv(tmp_path / "traj.csv")
    A = np.array([[0.0, kt / J_EFF], [-kt / L, -R / L]])
    x_ss = np.array([V / kt, 0.0])
    omega = np.array([(x_ss + expm(A * t) @ (0 - x_ss))[0] for t in tr["t"]])
    assert np.max(np.abs(-N_RATIO * tr["qd:Jd"] - omega)) < 1e-6 * omega.max()
    # the current starts at 0: no torque at t = 0, unlike the model without inductance
    assert tr["qdd:Jd"][0] == 0.0


PENDULUM = """<?xml version="1.0"?>
<robot name="pendulum">
  <link name="base"/>
  <link name="arm"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="swing" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-0.5" upper="1.0" effort="100" velocity="10"/>
  </joint>
</robot>
"""


def test_a_joint_limit_stops_the_simulation(run_cli, tmp_path):
    mech = write(tmp_path / "pendulum.urdf", PENDULUM)
    inp = write(tmp_path / "in.csv", "t,motor:swing\n0,0\n2,0\n")     # falls from horizontal
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv")
    assert r.exit_code == 1
    assert "in.csv: stopped: joint 'swing' reached its upper limit 1 at t = " in r.stderr
    tr = read_csv(tmp_path / "traj.csv")
    assert tr["q:swing"][-1] == pytest.approx(1.0, abs=1e-9)
    assert np.all(tr["q:swing"][:-1] < 1.0) and tr["t"][-1] < 2.0


def test_loads_option_writes_what_solve_writes(run_cli, mech_dir, tmp_path):
    inp = write(tmp_path / "in.csv", "t,motor:motor3,motor:motor5\n0,0.5,-1\n0.2,-0.5,1\n")
    r = run_cli("simulate", mech_dir / "paper_2dof.yaml", inp, "-o", tmp_path / "traj.csv",
                "--loads", tmp_path / "a.csv", "--q0", "0.1,-0.2", "--qd0", "1,0")
    assert r.exit_code == 0, r.stderr
    assert "Wrote 201 rows of loads to" in r.stdout
    r = run_cli("solve", mech_dir / "paper_2dof.yaml", tmp_path / "traj.csv", "-o", tmp_path / "b.csv")
    assert (tmp_path / "a.csv").read_text() == (tmp_path / "b.csv").read_text()
    tr = read_csv(tmp_path / "traj.csv")
    assert (tr["q:J1"][0], tr["q:J2"][0], tr["qd:J1"][0]) == (0.1, -0.2, 1.0)


@pytest.mark.parametrize("text,args,message", [
    ("t,motor:motor3\n0,1\n1,1\n", (), "in.csv:1: motor 'motor5' has no column (give one of 'motor:motor5'"),
    ("t,motor:motor3,motor:nope\n0,1,1\n1,1,1\n", (), "in.csv:1: column 3 'motor:nope': 'nope' is not a motor"),
    ("t,motor:motor3,voltage:motor5\n0,1,1\n1,1,1\n", (), "in.csv:1: column 3 'voltage:motor5': motor 'motor5' has no DC model"),
    ("t,motor:motor3,motor:motor5\n0,1,1\n1,x,1\n", (), "in.csv:3: column 2 'motor:motor3': not a number: 'x'"),
    ("t,motor:motor3,motor:motor5\n0,1,1\n", (), "in.csv: 1 row: give at least 2"),
    ("t,motor:motor3,motor:motor5\n0,1,1\n1,1,1\n", ("--q0", "1,2,3"), "--q0: expected 2 finite comma-separated numbers"),
    ("t,motor:motor3,motor:motor5\n0,1,1\n1,1,1\n", ("--rtol", "0"), "--rtol: expected a positive number"),
    ("t,motor:motor3,motor:motor5\n0,1,1\n1,1,1\n", ("--method", "Euler"), "--method: expected one of DOP853"),
    ("t,motor:motor3,motor:motor5\n0,1,1\n1,1,1\n", ("--t-end", "-1"), "--t-end: expected a time after"),
    # within rounding of the first time: was an AttributeError traceback (issue 34, section 5)
    ("t,motor:motor3,motor:motor5\n0,1,1\n1,1,1\n", ("--t-end", "1e-12"), "--t-end: expected a time after"),
    ("t,motor:motor3,motor:motor5\n5,1,1\n6,1,1\n", ("--t-end", "5.000000000000001"), "--t-end: expected a time after"),
    # scipy's own UserWarning (with a library path) reached stderr (issue 34, section 5)
    ("t,motor:motor3,motor:motor5\n0,1,1\n1,1,1\n", ("--rtol", "1e-300"), "--rtol: expected at least 2.22e-14"),
])
def test_bad_input_is_one_line_and_exit_2(run_cli, mech_dir, tmp_path, text, args, message):
    inp = write(tmp_path / "in.csv", text)
    r = run_cli("simulate", mech_dir / "paper_2dof.yaml", inp, "-o", tmp_path / "traj.csv", *args)
    assert r.exit_code == 2
    assert message in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "traj.csv").exists()


@pytest.mark.parametrize("name", ["traj.parquet", "traj.feather", "traj.npz"])
def test_a_trajectory_in_another_format_than_csv_is_refused(run_cli, mech_dir, tmp_path, name):
    """simulate -o t.parquet wrote CSV text under that name (issue 34, section 5): the
    trajectory is the CSV solve reads, so another loads format is refused before running."""
    inp = write(tmp_path / "in.csv", "t,motor:motor3,motor:motor5\n0,1,1\n1,1,1\n")
    r = run_cli("simulate", mech_dir / "paper_2dof.yaml", inp, "-o", tmp_path / name)
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1
    assert f"{tmp_path / name}: -o: simulate writes its trajectory as CSV, the file `gearcli solve` reads" in r.stderr
    assert not (tmp_path / name).exists()


def test_a_step_beyond_the_span_writes_its_two_ends(run_cli, mech_dir, tmp_path):
    """--dt larger than the span (was an AttributeError traceback: one sample, no span)."""
    inp = write(tmp_path / "in.csv", "t,motor:motor3,motor:motor5\n0,1,1\n1,1,1\n")
    r = run_cli("simulate", mech_dir / "paper_2dof.yaml", inp, "-o", tmp_path / "traj.csv", "--dt", "1e300")
    assert r.exit_code == 0, r.stderr
    assert list(read_csv(tmp_path / "traj.csv")["t"]) == [0.0, 1.0]


def test_voltage_above_the_supply_is_refused(run_cli, tmp_path):
    mech = write(tmp_path / "stage.yaml", dc_stage())
    inp = write(tmp_path / "in.csv", "t,voltage:servo\n0,12\n1,30\n")
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv")
    assert r.exit_code == 2
    assert "in.csv:3: column 2 'voltage:servo': voltage 30 V exceeds motor 'servo''s supply_voltage 24 V" in r.stderr


def test_lossless_simulation_conserves_energy(run_cli, tmp_path):
    pin = pytest.importorskip("pinocchio")
    from test_urdf import ERD, erd
    if ERD is None:
        pytest.skip("example-robot-data not installed")
    path = erd("ur_description/urdf/ur5_robot.urdf")
    names = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
             "wrist_3_joint"]
    inp = write(tmp_path / "in.csv", "t," + ",".join(f"motor:{n.replace('_joint', '_motor')}" for n in names) + "\n0" + ",0" * 6 + "\n2" + ",0" * 6 + "\n")
    r = run_cli("simulate", path, inp, "-o", tmp_path / "traj.csv", "--q0", "0.3,-1.0,0.5,0.2,0.4,0.1",
                "--method", "DOP853", "--rtol", "1e-11", "--atol", "1e-11", "--dt", "0.01")
    assert r.exit_code == 0, r.stderr
    tr = read_csv(tmp_path / "traj.csv")
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    assert [model.names[i] for i in range(1, model.njoints)] == names and model.nq == 6
    q = np.column_stack([tr[f"q:{n}"] for n in names])
    qd = np.column_stack([tr[f"qd:{n}"] for n in names])
    kin = np.array([pin.computeKineticEnergy(model, data, a, b) for a, b in zip(q, qd)])
    pot = np.array([pin.computePotentialEnergy(model, data, a) for a in q])
    E = kin + pot
    assert kin.max() > 10.0                      # the arm does fall: gravity does work
    assert np.max(np.abs(E - E[0])) < 1e-8 * kin.max()


@pytest.mark.parametrize("out,message", [
    ("-", "-: -o: simulate writes its trajectory to a file, not to stdout"),
    ("sub/", "-o: names a directory"),
])
def test_bad_output_is_refused_before_any_work(run_cli, mech_dir, tmp_path, out, message):
    inp = write(tmp_path / "in.csv", "t,motor:motor3,motor:motor5\n0,1,1\n1,1,1\n")
    (tmp_path / "sub").mkdir()
    r = run_cli("simulate", mech_dir / "paper_2dof.yaml", inp, "-o", out if out == "-" else f"{tmp_path}/{out}")
    assert r.exit_code == 2
    assert message in r.stderr and len(r.stderr.strip().splitlines()) == 1


# --- energy with losses --------------------------------------------------------------------------

LOSSY_PENDULUM = """
name: lossy_pendulum
gravity: [0, 0, -9.81]
base: frame
end_effector: wheel
links:
  - name: frame
  - {name: pinion, mass: 0.1, inertia: [1.0e-5, 2.0e-5, 1.0e-5]}
  - {name: wheel, mass: 1.0, com: [0.03, 0, 0], inertia: [1.0e-3, 1.5e-3, 1.0e-3]}
joints:
  - name: Jp
    parent: frame
    child: pinion
    axis: [0, 1, 0]
    friction: {coulomb: 0.002, viscous: 1.0e-5}
    bearings:
      - {name: a, position: 0.0, locating: true, friction_coefficient: 0.0015, bore: 0.008}
      - {name: b, position: 0.02, friction_coefficient: 0.0015, bore: 0.008}
  - {name: Jw, parent: frame, child: wheel, origin: {xyz: [0.075, 0, 0]}, axis: [0, 1, 0],
     friction: {viscous: 2.0e-4}}
gears:
  - {name: mesh, links: [pinion, wheel], teeth: [15, 60], mesh_point: [0.015, 0, 0], efficiency: 0.97}
motors:
  - {name: motor, link: pinion}
"""


def pendulum_energy(q, w):
    """Kinetic + potential energy (J) of LOSSY_PENDULUM by hand: horizontal axes along y, the
    pinion (Iyy 2e-5, centre of mass on its axis) turns at -4 w (15/60 external pair), the
    wheel (1 kg, Iyy 1.5e-3 about its centre of mass 0.03 m off its axis along its x) at w;
    rotating x about y by q gives z = -0.03 sin q."""
    kinetic = 0.5 * 2.0e-5 * (4 * w) ** 2 + 0.5 * (1.5e-3 + 1.0 * 0.03 ** 2) * w ** 2
    return kinetic, 1.0 * 9.81 * (-0.03 * np.sin(q))


def running_integral(t, p):
    """int_0^t p dt (trapezoid rule) at every sample."""
    return np.concatenate([[0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * np.diff(t))])


def test_energy_falls_by_exactly_the_integrated_losses(run_cli, tmp_path):
    """A gear-train pendulum with mesh friction, joint Coulomb and viscous friction and
    bearing friction, pushed by the motor for 0.1 s, then free (zero torque from 0.12 s):
    E(t) - E(0) = work of the motor - integral of every loss column that 'gearcli simulate
    --loads' writes, and E never rises once the motor is off.  Energy and motor power by
    hand (pendulum_energy), not from gearcli.  The balance holds to 6e-8 of the largest
    kinetic energy: the trapezoid rule every 0.1 ms, whose error concentrates where the
    mesh force or the rates change sign inside an interval (a kink of |t| v); the
    integrator's own error (rtol 1e-10) is far below.  A solve that differs by one ulp (a
    kernel whose arithmetic is ordered otherwise) moves it to 1.1e-7: the implicit
    acceleration's steps stop at the solve's rounding (forward.STALLED) and DOP853's adaptive
    steps follow them (20,058 against 17,283 solves, measured), hence 2e-7."""
    mech = write(tmp_path / "pendulum.yaml", LOSSY_PENDULUM)
    inp = write(tmp_path / "in.csv", "t,motor:motor\n0,-0.01\n0.1,-0.01\n0.12,0\n0.4,0\n")
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--q0", "0.8", "--dt", "1e-4",
                "--method", "DOP853", "--rtol", "1e-10", "--atol", "1e-12", "--loads", tmp_path / "loads.csv")
    assert r.exit_code == 0, r.stderr
    tr, lo = read_csv(tmp_path / "traj.csv"), read_csv(tmp_path / "loads.csv")
    t, w = tr["t"], tr["qd:Jw"]
    kinetic, potential = pendulum_energy(tr["q:Jw"], w)
    E = kinetic + potential
    losses = {c: lo[c] for c in lo if c.endswith(":loss")}
    assert sorted(losses) == ["gear:mesh:loss", "joint:Jp:loss", "joint:Jw:loss"]
    lost = running_integral(t, sum(losses.values()))
    work = running_integral(t, np.interp(t, [0, 0.1, 0.12, 0.4], [-0.01, -0.01, 0, 0]) * (-4 * w))
    assert work[-1] > 0.1 * lost[-1] > 0 and np.ptp(w) > 10     # the motor and every loss matter
    for c, p in losses.items():
        assert running_integral(t, p)[-1] > 0.02 * lost[-1], c
    assert np.max(np.abs(E - E[0] - work + lost)) < 2e-7 * kinetic.max()
    free = t >= 0.12
    assert np.all(np.diff(E[free]) <= 1e-12 * kinetic.max())
    # a deliberate bug: the bearing friction left out of the losses breaks the balance
    bearing = 0.5 * 0.0015 * 0.008 * np.abs(-4 * w)           # a floor: at least one bearing's moment
    assert np.max(np.abs(E - E[0] - work + lost - running_integral(t, bearing))) > 1e-5 * kinetic.max()


def test_lossy_forward_dynamics_settles_near_a_static_balance():
    """The pendulum swinging through its lowest point with the motor off: the torques
    (given, gravity, h) nearly vanish while the solve still rounds at the size of the
    inertia and reaction terms; the implicit solve must settle there (it used to stop with
    'did not settle', ending the simulation above at t = 0.41 s) and invert solve."""
    from gearcli import analyse, parse_mechanism, solve
    from gearcli.dynamics.forward import forward_dynamics
    an = analyse(parse_mechanism(LOSSY_PENDULUM))
    q = np.array([[np.pi / 2], [1.608406654001242], [np.pi / 2]])     # at rest; gravity = friction; moving
    qd = np.array([[0.0], [-7.65102391], [-7.65102391]])
    qdd = forward_dynamics(an, q, qd, np.zeros((3, 1)))
    res = solve(an, q, qd, qdd)
    assert np.max(np.abs(res.motor)) < 1e-13
    assert np.max(np.abs(qdd[:2, 0])) < 1e-12 and qdd[2, 0] > 1.0       # balanced; decelerating


def test_unsettled_forward_dynamics_is_one_line(run_cli, tmp_path, monkeypatch):
    """An acceleration that does not settle (here: no correction step allowed) ends the
    simulation with gearcli's one-line error naming the time, exit 2, nothing written."""
    from gearcli.dynamics import forward
    monkeypatch.setattr(forward, "MAX_STEPS", 0)
    mech = write(tmp_path / "pendulum.yaml", LOSSY_PENDULUM)
    inp = write(tmp_path / "in.csv", "t,motor:motor\n0,0\n0.1,0\n")
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--q0", "0.8")
    assert r.exit_code == 2
    assert "in.csv: simulation failed: t = 0 s: forward dynamics with losses did not settle" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and not (tmp_path / "traj.csv").exists()


def test_coulomb_friction_that_holds_the_pendulum_keeps_it_at_rest(run_cli, tmp_path):
    """The pendulum held horizontal by 0.5 N*m of Coulomb (= static) friction on its wheel
    (gravity pulls with 9.81 * 0.03 = 0.294 N*m): it sticks from the start and stays (it
    stalled the integrator, the wheel's rate reversing at 0 at every step: issue 34, section
    1).  With 0.2 N*m (and the pinion's 0.002 N*m times 4) it cannot hold: the pendulum falls."""
    inp = write(tmp_path / "in.csv", "t,motor:motor\n0,0\n0.2,0\n")
    for coulomb, held in ((0.5, True), (0.2, False)):
        mech = write(tmp_path / "pendulum.yaml", LOSSY_PENDULUM.replace("friction: {viscous: 2.0e-4}",
                                                                        f"friction: {{coulomb: {coulomb}}}"))
        r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv")
        assert r.exit_code == 0 and r.stderr == "", r.stderr
        tr = read_csv(tmp_path / "traj.csv")
        if held:
            assert np.all(tr["q:Jw"] == 0.0) and np.abs(tr["qd:Jw"]).max() <= 1e-15
            assert int(r.stdout.split(" evaluations")[0].split(", ")[-1]) < 100
        else:
            q = tr["q:Jw"]
            assert abs(q[-1]) > 0.01 and np.all(np.diff(q) * np.sign(q[-1]) >= 0)


def _stick_slip_stage(tmp_path, fc, fs):
    text = spur_stage_yaml().replace(
        "  - {name: Jd, parent: frame, child: disc, origin: {xyz: [0, 0, 0]}, axis: [0, 0, 1]}",
        f"  - {{name: Jd, parent: frame, child: disc, origin: {{xyz: [0, 0, 0]}}, axis: [0, 0, 1], "
        f"friction: {{coulomb: {fc}, static: {fs}}}}}")
    assert f"static: {fs}" in text
    return write(tmp_path / "stage.yaml", text)


def test_stick_slip_through_dwells_by_hand(run_cli, tmp_path):
    """A motor turns a disc through a 20/70 spur stage; the disc's joint has F_c = 0.6 and
    F_s = 0.9 N*m.  In the disc's coordinate (J = J_load + n^2 J_rotor) the motor pushes with
    f = -n T.  By hand (Karnopp): the disc rests until |f| reaches F_s (t_s = 0.1 F_s/(n T0)
    on the ramp), slips with J qd' = f + F_c, is braked by F_c alone once the torque is off,
    sticks where its rate reaches 0 (t_stop), rests through the dwell, and slips the other
    way when |f| reaches F_s again.  Every instant and rate from the closed form."""
    fc, fs, T0 = 0.6, 0.9, 0.5
    J = J_LOAD + N_RATIO ** 2 * J_ROTOR
    mech = _stick_slip_stage(tmp_path, fc, fs)
    rows = [(0.0, 0.0), (0.1, T0), (0.3, T0), (0.31, 0.0), (0.9, 0.0), (1.0, -T0), (1.1, -T0)]
    inp = write(tmp_path / "in.csv", "t,motor:servo\n" + "".join(f"{a!r},{b!r}\n" for a, b in rows))
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--rtol", "1e-10", "--atol", "1e-12")
    assert r.exit_code == 0, r.stderr
    tr = read_csv(tmp_path / "traj.csv")
    t, q, w = tr["t"], tr["q:Jd"], tr["qd:Jd"]
    n = N_RATIO
    t_s = 0.1 * fs / (n * T0)
    # f + F_c is linear on [t_s, 0.1], [0.1, 0.3], [0.3, 0.31]: the trapezoid rule is exact there
    nodes = np.array([t_s, 0.1, 0.3, 0.31])
    push = -n * np.interp(nodes, [a for a, _ in rows], [b for _, b in rows]) + fc
    w31 = np.sum(0.5 * (push[1:] + push[:-1]) * np.diff(nodes)) / J
    t_stop = 0.31 - w31 * J / fc
    t_s2 = 0.9 + 0.1 * fs / (n * T0)
    assert w31 < -1.0 and 0.31 < t_stop < 0.9
    rest = (t < t_s) | ((t > t_stop + 1e-9) & (t < t_s2))
    assert np.abs(w[rest]).max() <= 1e-12 and np.all(q[t < t_s] == 0.0)
    dwell = (t > t_stop + 1e-9) & (t < t_s2)
    assert np.ptp(q[dwell]) <= 1e-12 and q[dwell][0] < -0.5
    assert w[np.searchsorted(t, 0.31)] == pytest.approx(w31, rel=1e-8)
    moving = (t > t_s + 1e-9) & (t < t_stop - 1e-9)
    assert np.all(w[moving] < 0) and np.all(w[t > t_s2 + 1e-3] > 0)
    braking = moving & (t > 0.31)
    assert np.abs(tr["qdd:Jd"][braking] - fc / J).max() <= 1e-9 * fc / J
    # the stick came where the rate reaches 0: the last moving sample within a step of t_stop
    assert t_stop - 1e-3 <= t[moving][-1] < t_stop


@pytest.mark.parametrize("eta", [None, 0.9])
def test_a_joint_that_stays_stuck_does_no_work_and_energy_balances(run_cli, tmp_path, eta):
    """The same stage, energy by hand: E = 1/2 J w^2 (no gravity), the motor's work from
    the input torque and the motor speed -n w, the friction's loss from --loads.  Across
    every stick and slip, E(t) - E(0) = work - the integral of the losses (the stuck joint
    has none: it holds without moving).  With mesh efficiency 0.9 the mesh's friction holds
    its share at rest too, and its loss (gear:stage:loss) joins the balance."""
    fc, fs, T0 = 0.6, 0.9, 0.5
    J = J_LOAD + N_RATIO ** 2 * J_ROTOR
    mech = _stick_slip_stage(tmp_path, fc, fs)
    if eta is not None:
        mech = write(mech, mech.read_text().replace("mesh_point: [0.07, 0, 0]}", f"mesh_point: [0.07, 0, 0], efficiency: {eta}}}"))
        assert "efficiency" in mech.read_text()
    rows = [(0.0, 0.0), (0.1, T0), (0.3, T0), (0.31, 0.0), (0.9, 0.0), (1.0, -T0), (1.1, -T0)]
    inp = write(tmp_path / "in.csv", "t,motor:servo\n" + "".join(f"{a!r},{b!r}\n" for a, b in rows))
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--rtol", "1e-10", "--atol", "1e-12",
                "--dt", "1e-4", "--loads", tmp_path / "loads.csv")
    assert r.exit_code == 0, r.stderr
    tr, lo = read_csv(tmp_path / "traj.csv"), read_csv(tmp_path / "loads.csv")
    t, w = tr["t"], tr["qd:Jd"]
    E = 0.5 * J * w ** 2
    T = np.interp(t, [a for a, _ in rows], [b for _, b in rows])
    work = running_integral(t, T * (-N_RATIO * w))
    lost = running_integral(t, lo["joint:Jd:loss"] + (lo["gear:stage:loss"] if eta else 0.0))
    assert lost[-1] > 0.1 * work[-1] > 0
    if eta:
        assert running_integral(t, lo["gear:stage:loss"])[-1] > 0.05 * lost[-1]
    # 1.6e-5 measured: the trapezoid rule at 1 ms across the kinks of |t| v and of the rates
    # (Coulomb friction applied as generalised forces on the table, not at the motor's joint,
    # moved the tooth forces and so the mesh loss: 1.7e-2)
    assert np.max(np.abs(E - E[0] - work + lost)) < 5e-5 * E.max()


def _held_or_moved(run_cli, tmp_path, mech, motor, T, coordinate):
    """Simulate 0.05 s from rest under a constant motor torque T: ("held", 0) when the
    coordinate's angle and rate stay exactly 0, else ("moved", sign of its final angle)."""
    T = float(T)
    inp = write(tmp_path / "in.csv", f"t,motor:{motor}\n0,{T!r}\n0.05,{T!r}\n")
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv")
    assert r.exit_code == 0 and r.stderr == "", r.stderr
    tr = read_csv(tmp_path / "traj.csv")
    q, w = tr[f"q:{coordinate}"], tr[f"qd:{coordinate}"]
    if np.all(q == 0.0) and np.all(w == 0.0):
        return "held", 0.0
    assert np.all(np.diff(q) * np.sign(q[-1]) >= 0)      # one way, from the start
    return "moved", float(np.sign(q[-1]))


def test_mesh_friction_holds_the_stage_up_to_its_verge_by_hand(run_cli, tmp_path):
    """The spur stage with F_s = 0.9 N*m on the disc's joint and mesh efficiency 0.9 (c =
    0.1, friction arm rho = r_j r_k / (r_j + r_k)).  On the verge of turning the disc the
    motor's pinion pushes its tooth force t through the mesh: the disc, t r_k - c t rho =
    F_s; the pinion, T = t r_j + c t rho.  So the held band is |T| <= F_s (r_j + c rho) /
    (r_k - c rho) = 0.28344 N*m: the mesh friction holds its share at the load it carries
    (without it, F_s r_j / r_k = 0.25714 N*m; issue 34, section 1).  1e-6 inside the band
    the stage stays exactly at rest; 1e-6 beyond it, it turns the way the motor pushes."""
    fs, eta = 0.9, 0.9
    text = _stick_slip_stage(tmp_path, fs, fs).read_text()
    mech = write(tmp_path / "stage.yaml", text.replace("mesh_point: [0.07, 0, 0]}",
                                                        f"mesh_point: [0.07, 0, 0], efficiency: {eta}}}"))
    assert "efficiency" in mech.read_text()
    r_j, r_k, c = 0.001 * TEETH[0], 0.001 * TEETH[1], 1.0 - eta
    rho = r_j * r_k / (r_j + r_k)
    verge = fs * (r_j + c * rho) / (r_k - c * rho)
    assert verge > 1.1 * fs * r_j / r_k
    for sign in (1.0, -1.0):
        assert _held_or_moved(run_cli, tmp_path, mech, "servo", sign * verge * (1 - 1e-6), "Jd") == ("held", 0.0)
        # the motor turns the disc the other way (external pair): q_Jd = -q_motor / n
        assert _held_or_moved(run_cli, tmp_path, mech, "servo", sign * verge * (1 + 1e-6), "Jd") == ("moved", -sign)


def test_mesh_friction_alone_holds_the_pendulum_between_its_two_verges(run_cli, tmp_path):
    """LOSSY_PENDULUM without joint or bearing friction: only the mesh (c = 0.03, pinion
    r_j = 0.015, wheel r_k = 0.06) holds the wheel, whose weight pulls with G = 9.81 * 0.03
    N*m, against the motor.  By hand, lifting it: t r_k - c t rho = G, T = t r_j + c t rho;
    letting it sink: t r_k + c t rho = G, T = t r_j - c t rho.  Held for T between
    G (r_j - c rho)/(r_k + c rho) and G (r_j + c rho)/(r_k - c rho); below it sinks, above
    it rises.  Without the motor it falls: a mesh alone cannot hold a load with nothing on
    the other side."""
    text = LOSSY_PENDULUM.replace("    friction: {coulomb: 0.002, viscous: 1.0e-5}\n", "")
    text = re.sub(r"    bearings:\n(      - .*\n)+", "", text).replace(",\n     friction: {viscous: 2.0e-4}}", "}")
    assert "friction" not in text and "bearings" not in text
    mech = write(tmp_path / "pendulum.yaml", text)
    r_j, r_k, c, G = 0.015, 0.06, 0.03, 9.81 * 0.03
    rho = r_j * r_k / (r_j + r_k)
    low, high = G * (r_j - c * rho) / (r_k + c * rho), G * (r_j + c * rho) / (r_k - c * rho)
    # the motor's sign that lifts: its lossless balance, by the solve at rest
    from gearcli import analyse, load_mechanism, solve
    lift = np.sign(solve(analyse(load_mechanism(mech)), [0.0], [0.0], [0.0]).motor[0, 0])
    sink = _held_or_moved(run_cli, tmp_path, mech, "motor", 0.0, "Jw")
    assert sink[0] == "moved"
    assert _held_or_moved(run_cli, tmp_path, mech, "motor", lift * low * (1 - 1e-6), "Jw") == sink
    for T in (low * (1 + 1e-6), 0.5 * (low + high), high * (1 - 1e-6)):
        assert _held_or_moved(run_cli, tmp_path, mech, "motor", lift * T, "Jw") == ("held", 0.0)
    assert _held_or_moved(run_cli, tmp_path, mech, "motor", lift * high * (1 + 1e-6), "Jw") == ("moved", -sink[1])


def test_bearing_friction_holds_an_arm_within_its_moment_by_hand(run_cli, tmp_path):
    """An arm of 2 kg, centre of mass 0.5 m out, on one bearing of mu_b = 0.004 and bore
    0.05 m, driven directly: at rest the bearing carries the weight, P = m g, and its
    friction holds up to M_b = 1/2 mu_b d_b m g.  Held for |T - G| <= M_b, G = m g 0.5."""
    text = PENDULUM_YAML.replace("limits: {lower: -0.5, upper: 1.0}}",
                                 "bearings: [{name: b, position: 0.0, locating: true, "
                                 "friction_coefficient: 0.004, bore: 0.05}]}")
    assert "bearings" in text
    mech = write(tmp_path / "arm.yaml", text)
    G, M_b = 2.0 * 9.81 * 0.5, 0.5 * 0.004 * 0.05 * 2.0 * 9.81
    from gearcli import analyse, load_mechanism, solve
    lift = np.sign(solve(analyse(load_mechanism(mech)), [0.0], [0.0], [0.0]).motor[0, 0])
    for T, outcome in ((G - M_b * (1 + 1e-6), "moved"), (G - M_b * (1 - 1e-6), "held"), (G, "held"),
                       (G + M_b * (1 - 1e-6), "held"), (G + M_b * (1 + 1e-6), "moved")):
        assert _held_or_moved(run_cli, tmp_path, mech, "swing", lift * T, "swing")[0] == outcome


def test_a_differential_is_held_by_its_mesh_friction(run_cli, mech_dir, tmp_path):
    """The Bendix wrist with its four bevel pairs at efficiency 0.95: their rates involve
    J2 and J3 together (rows J2 - J3, -J2 - J3, -J3).  Under its static motor torques plus
    0.01 N*m on motor5, the meshes' friction holds J2 and J3 exactly at rest while J1 (no
    friction on its path) turns; before, the gears' rates reversed at 0 at every step and
    simulate stalled.  With 0.1 N*m more, beyond what they can hold, J2 and J3 move."""
    from gearcli import analyse, load_mechanism, solve
    text = re.sub(r"(kind: bevel, teeth: \[\d+, \d+\])", r"\1, efficiency: 0.95",
                  (mech_dir / "bendix_wrist.yaml").read_text())
    assert text.count("efficiency: 0.95") == 4
    mech = write(tmp_path / "wrist.yaml", text)
    T0 = solve(analyse(load_mechanism(mech)), np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 3))).motor[0]
    for delta, held in ((0.01, True), (0.1, False)):
        T = [float(v) for v in T0 + np.array([0.0, delta, 0.0])]
        inp = write(tmp_path / "in.csv", "t,motor:motor4,motor:motor5,motor:motor7\n"
                    + "".join(f"{t},{T[0]!r},{T[1]!r},{T[2]!r}\n" for t in (0.0, 0.05)))
        r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv")
        assert r.exit_code == 0 and r.stderr == "", r.stderr
        tr = read_csv(tmp_path / "traj.csv")
        assert tr["t"][-1] == 0.05 and abs(tr["q:J1"][-1]) > 1e-4
        rest = max(np.abs(tr[k]).max() for k in ("q:J2", "q:J3", "qd:J2", "qd:J3"))
        assert (rest <= 1e-15) if held else (rest > 1e-3)


def test_the_scara_starts_from_rest_under_its_duty_torques(run_cli, mech_dir, tmp_path):
    """The bundled SCARA (belt, strain-wave gear, ball screw, all lossy) from rest under the
    motor torques `solve` gives for the first 10 ms of its duty cycle: its friction holds the
    joints that rest and lets go of the one that moves.  Before, its gears' rates reversed
    at 0 at every step (their friction held nothing) and simulate stalled at t = 8e-5 s."""
    rows = (mech_dir / "scara_traj.csv").read_text().splitlines()[:12]
    traj = write(tmp_path / "traj.csv", "\n".join(rows) + "\n")
    r = run_cli("solve", mech_dir / "scara.yaml", traj, "-o", tmp_path / "loads.csv")
    assert r.exit_code == 0, r.stderr
    loads = read_csv(tmp_path / "loads.csv")
    motors = [k for k in loads if k.startswith("motor:") and k.count(":") == 1]
    assert len(motors) == 3
    inp = write(tmp_path / "in.csv", ",".join(["t"] + motors) + "\n" + "".join(
        ",".join(repr(float(loads[k][i])) for k in ["t"] + motors) + "\n" for i in range(len(loads["t"]))))
    start = read_csv(traj)
    q0 = ",".join(repr(float(start[f"q:{j}"][0])) for j in ("J1", "J2", "Jz"))
    r = run_cli("simulate", mech_dir / "scara.yaml", inp, "-o", tmp_path / "sim.csv", f"--q0={q0}")
    assert r.exit_code == 0 and r.stderr == "", r.stderr
    sim = read_csv(tmp_path / "sim.csv")
    assert sim["t"][-1] == pytest.approx(0.01) and len(sim["t"]) == 11
    moving = start["qd:Jz"][1:11]
    assert np.all(np.sign(sim["qd:Jz"][1:]) == np.sign(moving)) and np.abs(moving).min() > 0


def test_a_self_locking_worm_holds_its_load_between_its_verges(run_cli, mech_dir, tmp_path):
    """The bundled worm lift (self-locking): with the motor off the load hangs exactly still
    (before, the worm's friction held nothing at rest and simulate stalled at once).  It
    holds for any motor torque between the two quasi-static ones `solve` gives at a creeping
    1e-12 rad/s, lifting (0.3245 N*m) and lowering (-0.0281 N*m: it must be driven down),
    and moves, the way the motor pushes, 1e-6 beyond either."""
    from gearcli import analyse, load_mechanism, solve
    mech = mech_dir / "worm_lift.yaml"
    an = analyse(load_mechanism(mech))
    lift, lower = (float(solve(an, [[0.0]], [[v]], [[0.0]]).motor[0, 0]) for v in (1e-12, -1e-12))
    assert lower < 0.0 < lift
    assert _held_or_moved(run_cli, tmp_path, mech, "motor", 0.0, "Jd") == ("held", 0.0)
    for verge, way in ((lift, 1.0), (lower, -1.0)):
        assert _held_or_moved(run_cli, tmp_path, mech, "motor", verge * (1 - 1e-6), "Jd") == ("held", 0.0)
        assert _held_or_moved(run_cli, tmp_path, mech, "motor", verge * (1 + 1e-6), "Jd") == ("moved", way)


def test_a_stiff_motor_under_an_explicit_method_stalls_with_one_line(run_cli, tmp_path):
    """L/R = 5e-10 s under RK45: its stable step is ~1e-9 s, 0.3 s would take ~1e9
    evaluations.  simulate stops after STALL_EVALUATIONS, naming L/R and the way out; Radau
    runs it (472 evaluations)."""
    mech = write(tmp_path / "stage.yaml", dc_stage(inductance=1e-9))
    inp = write(tmp_path / "in.csv", "t,voltage:servo\n0,12\n0.3,12\n")
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv")
    assert r.exit_code == 2 and not (tmp_path / "traj.csv").exists()
    assert r.stderr == (f"{inp}: warning: motor 'servo''s L/R gives a time constant of 5e-10 s, 6e+08 times shorter "
                        "than the 0.3 s simulated: the system is stiff, RK45 will crawl or diverge; give --method Radau "
                        "or BDF\n"         # said before the integration starts (issue 34, section 5)
                        f"{inp}: simulation stalled at t = 0 s: 5,000 evaluations of the dynamics without advancing "
                        "3e-05 s: a motor's L/R of 5e-10 s makes the system stiff: give --method Radau or BDF "
                        "(nothing written)\n")
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--method", "Radau")
    assert r.exit_code == 0, r.stderr


# --- position limits in YAML ---------------------------------------------------------------------

PENDULUM_YAML = """
name: pendulum
base: base
end_effector: arm
links:
  - name: base
  - {name: arm, mass: 2.0, com: [0.5, 0, 0], inertia: [0.01, 0.01, 0.01]}
joints:
  - {name: swing, parent: base, child: arm, axis: [0, 1, 0], limits: {lower: -0.5, upper: 1.0}}
motors:
  - {name: swing, link: arm}
"""


def test_yaml_joint_limits_stop_the_simulation_as_urdf_limits_do(run_cli, tmp_path):
    """PENDULUM as a YAML file with joints[].limits: the same stop, message and exit status
    as the URDF's <limit>, the same trajectory; exported to URDF (a revolute joint with
    <limit lower upper>, effort and velocity marked as placeholders), read back with the
    same limits and no invented effort/velocity rating, and simulated identically."""
    import yourdfpy
    from gearcli import load_mechanism
    inp = write(tmp_path / "in.csv", "t,motor:swing\n0,0\n2,0\n")
    rows = {}
    for name, text in (("p.urdf", PENDULUM), ("p.yaml", PENDULUM_YAML)):
        r = run_cli("simulate", write(tmp_path / name, text), inp, "-o", tmp_path / f"{name}.csv")
        assert r.exit_code == 1
        assert "in.csv: stopped: joint 'swing' reached its upper limit 1 at t = " in r.stderr
        rows[name] = read_csv(tmp_path / f"{name}.csv")
    # the same trajectory to rounding: a later run may find on disk the kernel an earlier one
    # compiled (the first-call rule), and numpy and the kernel round differently (2e-13 seen)
    for key in ("t", "q:swing", "qd:swing"):
        assert np.abs(rows["p.yaml"][key] - rows["p.urdf"][key]).max() <= 1e-11 * np.abs(rows["p.urdf"][key]).max()
    r = run_cli("export", tmp_path / "p.yaml", "-o", tmp_path / "back.urdf")
    assert r.exit_code == 0, r.stderr
    robot = yourdfpy.URDF.load(str(tmp_path / "back.urdf"), load_meshes=False, build_scene_graph=False)
    jt = robot.robot.joints[0]
    assert (jt.type, jt.limit.lower, jt.limit.upper) == ("revolute", -0.5, 1.0)
    back = load_mechanism(tmp_path / "back.urdf").joints[0]
    assert back.position_limits == (-0.5, 1.0) and back.limit is None
    r = run_cli("simulate", tmp_path / "back.urdf", inp, "-o", tmp_path / "back.csv")
    assert r.exit_code == 1 and "reached its upper limit 1 at" in r.stderr
    back = read_csv(tmp_path / "back.csv")
    assert back.keys() == rows["p.yaml"].keys()
    for key in back:
        assert np.abs(back[key] - rows["p.yaml"][key]).max() <= 1e-11 * np.abs(back[key]).max()


def test_prismatic_placeholder_limits_are_not_read_back_as_limits(tmp_path):
    """A prismatic joint without limits is exported with URDF's required <limit> (+-1000 m)
    marked as placeholders: read back, it has no position limits and no rating."""
    from gearcli import load_mechanism, parse_mechanism
    from gearcli.report.urdf_writer import export_urdf
    text = PENDULUM_YAML.replace("axis: [0, 1, 0], limits: {lower: -0.5, upper: 1.0}", "type: prismatic, axis: [1, 0, 0]")
    export_urdf(parse_mechanism(text), tmp_path / "s.urdf")
    assert 'gearcli:placeholder="lower upper effort velocity"' in (tmp_path / "s.urdf").read_text()
    back = load_mechanism(tmp_path / "s.urdf").joints[0]
    assert back.type == "prismatic" and back.position_limits is None and back.limit is None


@pytest.mark.parametrize("limits,message", [
    ("{lower: 1.0, upper: 1.0}", "p.yaml:9: joints[0].limits.upper: upper limit 1 rad must be above the lower limit 1 rad"),
    ("{lower: 0.5, upper: -0.5}", "p.yaml:9: joints[0].limits.upper: upper limit -0.5 rad must be above the lower limit 0.5 rad"),
    ("{lower: -.inf, upper: 1.0}", "p.yaml:9: joints[0].limits.lower: -inf is not a finite number"),
    ("{lower: -0.5}", "p.yaml:9: joints[0].limits: missing required key 'upper'"),
    ("{lower: -0.5, upper: 1.0, effort: 3}", "p.yaml:9: joints[0].limits"),
])
def test_bad_yaml_joint_limits_are_located(run_cli, tmp_path, limits, message):
    mech = write(tmp_path / "p.yaml", PENDULUM_YAML.replace("{lower: -0.5, upper: 1.0}", limits))
    r = run_cli("check", mech)
    assert r.exit_code == 2
    assert message in r.stderr and len(r.stderr.strip().splitlines()) == 1


# --- the DC motor model in URDF --------------------------------------------------------------------

def test_dc_motor_model_survives_the_urdf_round_trip(run_cli, tmp_path):
    """motors[].model exported as <gearcli:motor_model/> and read back exactly (with and
    without inductance); a voltage-driven simulation of the exported URDF writes the same
    trajectory as the YAML's."""
    from gearcli import load_mechanism
    for L in (None, 1e-3):
        mech = write(tmp_path / "stage.yaml", dc_stage(inductance=L))
        r = run_cli("export", mech, "-o", tmp_path / "stage.urdf")
        assert r.exit_code == 0, r.stderr
        text = (tmp_path / "stage.urdf").read_text()
        assert "<gearcli:motor_model " in text and ("inductance=" in text) == (L is not None)
        yaml_model = load_mechanism(mech).motors[0].model
        back = load_mechanism(tmp_path / "stage.urdf").motors[0].model
        assert back == yaml_model and back.inductance == L and back.kt == 0.05
    inp = write(tmp_path / "in.csv", "t,voltage:servo\n0,12\n0.05,12\n")
    for name in ("stage.yaml", "stage.urdf"):
        r = run_cli("simulate", tmp_path / name, inp, "-o", tmp_path / f"{name}.csv", "--method", "Radau")
        assert r.exit_code == 0, r.stderr
    assert read_csv(tmp_path / "stage.urdf.csv")["qd:Jd"][-1] != 0.0
    # the same trajectory to rounding: the second run may find on disk the kernel the first
    # compiled (the first-call rule), and numpy and the kernel round differently
    a, b = read_csv(tmp_path / "stage.yaml.csv"), read_csv(tmp_path / "stage.urdf.csv")
    assert a.keys() == b.keys() and np.array_equal(a["t"], b["t"])
    for key in a:
        assert np.abs(a[key] - b[key]).max() <= 1e-11 * np.abs(a[key]).max(), key


@pytest.mark.parametrize("element,message", [
    ('<gearcli:motor_model motor="servo" kt="0.05" resistance="2"/>',
     "gearcli:motor_model 'servo': missing attribute 'supply_voltage'"),
    ('<gearcli:motor_model motor="servo" kt="-0.05" resistance="2" supply_voltage="24"/>',
     "gearcli:motor_model 'servo'.kt: kt must be positive, got -0.05"),
    ('<gearcli:motor_model motor="nope" kt="0.05" resistance="2" supply_voltage="24"/>',
     "gearcli:motor_model 'nope': unknown motor 'nope' (known: servo)"),
    ('<gearcli:motor_model motor="servo" kt="0.05" resistance="2" supply_voltage="24" volts="3"/>',
     "gearcli:motor_model 'servo': unknown attribute 'volts'"),
])
def test_bad_urdf_motor_model_is_located(run_cli, tmp_path, element, message):
    r = run_cli("export", write(tmp_path / "stage.yaml", spur_stage_yaml()), "-o", tmp_path / "s.urdf")
    assert r.exit_code == 0, r.stderr
    text = (tmp_path / "s.urdf").read_text().replace("</robot>", f"  {element}\n</robot>")
    mech = write(tmp_path / "s.urdf", text)
    line = text[:text.index("<gearcli:motor_model")].count("\n") + 1
    r = run_cli("check", mech)
    assert r.exit_code == 2
    assert f"s.urdf:{line}: {message}" in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_a_stiff_viscous_joint_is_named_before_an_explicit_method_diverges(run_cli, mech_dir, tmp_path):
    """viscous: 1e9 N*m*s/rad on the shoulder: a time constant of J/F_v ~ 4e-10 s.  RK45 is
    warned before it starts, and its divergence is said in gearcli's words (was numpy's
    "Singular matrix"); Radau integrates it (issue 34, section 5)."""
    text = (mech_dir / "paper_2dof.yaml").read_text()
    dh = "    dh: {theta_deg: 0, d: 0.0, a: 0.4, alpha_deg: 0}\n"
    assert text.count(dh) == 1
    mech = write(tmp_path / "visc.yaml", text.replace(dh, dh + "    friction: {viscous: 1.0e9}\n"))
    inp = write(tmp_path / "in.csv", "t,motor:motor3,motor:motor5\n0,0.1,0.2\n1,0.1,0.2\n")
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--t-end", "0.01")
    assert r.exit_code == 1 and read_csv(tmp_path / "traj.csv")["t"].tolist() == [0.0]   # up to where it stopped
    warning, error = r.stderr.strip().splitlines()
    assert re.fullmatch(rf"{re.escape(str(inp))}: warning: viscous friction 1e\+09 on joint 'J1' gives a time constant "
                        r"of [0-9.]+e-10 s, .* the system is stiff, RK45 will crawl or diverge; give --method Radau or BDF",
                        warning), warning
    assert error.startswith(f"{inp}: stopped: t = ") and error.endswith("(the trajectory up to there is written)")
    assert "the integration diverged" in error and "--method Radau or BDF" in error and "Singular" not in error
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--t-end", "0.01", "--method", "Radau")
    assert r.exit_code == 0 and r.stderr == ""
    tr = read_csv(tmp_path / "traj.csv")
    assert np.abs(tr["qd:J1"]).max() < 1e-9          # held by the damper: F_v qd ~ 0.2 N*m at most


def test_bearing_friction_that_fails_inside_simulate_names_the_time(run_cli, tmp_path):
    """A bearing friction that does not converge (mu 0.95 on a 120 mm bore under the wheel)
    stops simulate at the time it happens, not at "sample 0" of the evaluation (issue 34,
    section 5)."""
    from test_loss_cli import SPUR
    jw = "  - {name: Jw, parent: frame, child: wheel, origin: {xyz: [0.075, 0, 0]}, axis: [0, 0, 1]}"
    assert SPUR.count(jw) == 1
    mech = write(tmp_path / "lock.yaml", SPUR.replace(jw, (
        "  - name: Jw\n    parent: frame\n    child: wheel\n    origin: {xyz: [0.075, 0, 0]}\n    axis: [0, 0, 1]\n"
        "    bearings:\n      - {name: w, position: 0.0, friction_coefficient: 0.95, bore: 0.12}")))
    inp = write(tmp_path / "in.csv", "t,motor:motor\n0,1\n1,1\n")
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--qd0", "1")
    assert r.exit_code == 1          # stopped: the trajectory up to there is written (section 1)
    assert re.fullmatch(rf"{re.escape(str(inp))}: stopped: t = [0-9.e-]+ s: the bearing friction moments of "
                        r"joint '(Jp|Jw)' did not converge .* \(the trajectory up to there is written\)",
                        r.stderr.strip()), r.stderr
    assert "sample 0" not in r.stderr
    t_stop = float(r.stderr.split("t = ")[1].split(" s")[0])
    written = read_csv(tmp_path / "traj.csv")["t"]
    assert 0 < t_stop and written[-1] < t_stop


def test_a_tabulated_torque_is_integrated_row_interval_by_row_interval(run_cli, tmp_path):
    """A torque linear between rows whose slope jumps at each row: the disc's acceleration
    is piecewise linear, its angle piecewise cubic, which RK45 integrates exactly within a
    row interval.  Restarting at every row (issue 34, section 7) gives the closed form to
    rounding at any --rtol; integrating across the rows, the error did not follow --rtol."""
    rows = np.array([0.0, 0.13, 0.4, 0.71, 1.0])
    T = np.array([0.0, 0.02, -0.01, 0.03, 0.0])
    mech = write(tmp_path / "stage.yaml", spur_stage_yaml())
    inp = write(tmp_path / "in.csv", "t,motor:servo\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(rows, T)))
    a = -T / J_EFF / N_RATIO                     # the disc's acceleration at the rows (external stage)
    # closed form: per row interval, qdd linear, qd quadratic, q cubic from the interval's start
    t = np.linspace(0.0, 1.0, 1001)
    k = np.clip(np.searchsorted(rows, t, side="right") - 1, 0, len(rows) - 2)
    h = np.diff(rows)
    v0, q0 = np.zeros(len(rows)), np.zeros(len(rows))
    for i in range(len(rows) - 1):
        v0[i + 1] = v0[i] + h[i] * (a[i] + a[i + 1]) / 2
        q0[i + 1] = q0[i] + v0[i] * h[i] + h[i] ** 2 * (2 * a[i] + a[i + 1]) / 6
    s = t - rows[k]
    slope = (a[k + 1] - a[k]) / h[k]
    q_exact = q0[k] + v0[k] * s + a[k] * s ** 2 / 2 + slope * s ** 3 / 6
    scale = np.abs(q_exact).max()
    for rtol in ("1e-4", "1e-6", "1e-9"):
        r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--rtol", rtol, "--atol", "1e-12")
        assert r.exit_code == 0, r.stderr
        tr = read_csv(tmp_path / "traj.csv")
        assert np.allclose(tr["t"], t, rtol=0, atol=1e-15)
        assert np.abs(tr["q:Jd"] - q_exact).max() < 1e-12 * scale, rtol


def test_bundled_duty_cycle_with_dwells_runs_end_to_end(run_cli, mech_dir, tmp_path):
    """mechanisms/turntable_dwell.yaml along turntable_dwell_torque.csv: it indexes, is held
    by its friction through each dwell (rate exactly 0 from the stick on, angle constant),
    and its energy, 1/2 J w^2 by hand, balances the motor's work less every loss column of
    --loads (mesh friction of the 0.98 stage, Coulomb and viscous joint friction) across
    every stick and slip."""
    inp = mech_dir / "turntable_dwell_torque.csv"
    r = run_cli("simulate", mech_dir / "turntable_dwell.yaml", inp, "-o", tmp_path / "traj.csv",
                "--rtol", "1e-9", "--atol", "1e-11", "--loads", tmp_path / "loads.csv")
    assert r.exit_code == 0 and r.stderr == "", r.stderr
    tr, lo = read_csv(tmp_path / "traj.csv"), read_csv(tmp_path / "loads.csv")
    t, q, w = tr["t"], tr["q:Jt"], tr["qd:Jt"]
    for a, b in ((0.85, 1.2), (2.05, 2.4)):                 # the dwells, after the table has stopped
        dwell = (t >= a) & (t <= b)
        assert np.abs(w[dwell]).max() <= 1e-12 and np.ptp(q[dwell]) <= 1e-12
    assert np.abs(w).max() > 2.0 and q[t <= 1.2].min() < -0.5
    n = 70 / 20
    J = 0.12 + n ** 2 * 3.0e-5
    E = 0.5 * J * w ** 2
    rows = np.loadtxt(inp, delimiter=",", skiprows=1)
    work = running_integral(t, np.interp(t, rows[:, 0], rows[:, 1]) * (-n * w))
    losses = {c: lo[c] for c in lo if c.endswith(":loss")}
    assert sorted(losses) == ["gear:stage:loss", "joint:Jm:loss", "joint:Jt:loss"]
    lost = running_integral(t, sum(losses.values()))
    assert lost[-1] > 0.5 * work[-1] > 0
    # 1.6e-5 measured: the trapezoid rule at 1 ms across the kinks of |t| v and of the rates
    # (Coulomb friction applied as generalised forces on the table, not at the motor's joint,
    # moved the tooth forces and so the mesh loss: 1.7e-2)
    assert np.max(np.abs(E - E[0] - work + lost)) < 5e-5 * E.max()


def test_a_long_run_is_integrated_and_written_a_piece_at_a_time(run_cli, mech_dir, tmp_path, monkeypatch):
    """simulate --dt 1e-7 held every state, acceleration and a stacked copy (5e6 samples:
    1.1 GB; issue 34, section 5): samples are integrated PIECE at a time and written as they
    come (1e6 samples of the paper's arm: 452 -> 208 MB peak, below solve's 409 MB on the
    same file; measured 2026-12-07).  Here PIECE = 100: the sink never holds more, and the
    trajectory is the one integrated whole, to the tolerance."""
    from gearcli.dynamics import simulate as sim_module
    inp = write(tmp_path / "in.csv", "t,motor:motor3,motor:motor5\n0,0.1,0.2\n1,-0.1,0.1\n")
    args = ["simulate", mech_dir / "paper_2dof.yaml", inp, "--rtol", "1e-11", "--atol", "1e-13"]
    assert run_cli(*args, "-o", tmp_path / "whole.csv").exit_code == 0
    sizes = []
    real = sim_module._samples
    monkeypatch.setattr(sim_module, "PIECE", 100)
    monkeypatch.setattr(sim_module, "_samples", lambda d, segs, *a: (sizes.append(sum(len(s[0]) for s in segs)),
                                                                    real(d, segs, *a))[1])
    r = run_cli(*args, "-o", tmp_path / "pieces.csv")
    assert r.exit_code == 0 and "Wrote 1001 rows" in r.stdout, r.stdout
    assert sum(sizes) == 1001 and max(sizes) <= 101       # (the last piece takes the end too)
    a, b = read_csv(tmp_path / "whole.csv"), read_csv(tmp_path / "pieces.csv")
    assert np.array_equal(a["t"], b["t"])
    assert np.abs(a["q:J1"] - b["q:J1"]).max() < 1e-8 and np.abs(a["qd:J2"] - b["qd:J2"]).max() < 1e-7


@pytest.mark.parametrize("static", [100.0, 50.0])
def test_a_linear_guide_sticks_or_slips_under_the_process_force(run_cli, mech_dir, tmp_path, static):
    """rack_axis: the 80 N process force pushes the carriage against its guide's friction
    (Coulomb 40 N, static 100 or 50 N), the motor off.  100 N holds it (it stays at 0);
    50 N cannot, and it slides back at a = -(80 - 40) / (m + J/r^2) with m = 6 kg and the
    pinion's 7.2e-5 kg*m^2 on r = 24 mm: a prismatic joint's friction is a force along its axis."""
    text = (mech_dir / "rack_axis.yaml").read_text()
    guide = "    type: prismatic\n    origin: {xyz: [0, -0.024, 0.05]}\n    axis: [1, 0, 0]\n"
    assert text.count(guide) == 1
    mech = write(tmp_path / "rack.yaml", text.replace(guide, guide + f"    friction: {{coulomb: 40, static: {static}}}\n"))
    inp = write(tmp_path / "in.csv", "t,motor:motor\n0,0\n0.5,0\n")
    r = run_cli("simulate", mech, inp, "-o", tmp_path / "traj.csv", "--rtol", "1e-10", "--atol", "1e-12")
    assert r.exit_code == 0, r.stderr
    tr = read_csv(tmp_path / "traj.csv")
    if static == 100.0:
        assert np.all(tr["q:Jx"] == 0.0) and np.abs(tr["qd:Jx"]).max() <= 1e-12
    else:
        a = -(80.0 - 40.0) / (6.0 + 7.2e-5 / 0.024 ** 2)
        assert np.abs(tr["qdd:Jx"][1:] - a).max() <= 1e-9 * abs(a)
        assert tr["q:Jx"][-1] == pytest.approx(0.5 * a * 0.5 ** 2, rel=1e-9)
