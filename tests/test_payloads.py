"""Payloads that are picked and placed (issue 34, section 2): ``payloads:`` carried only where
a trajectory's ``attach:<name>`` column is 1, through solve, verify, simulate, mass_matrix
and forward_dynamics.

The hand case: an arm of mass m_a (centre of mass at r_a, inertia I_a about it) turning about
a horizontal axis, picking a box of mass m_p at r_p (inertia I_p about its centre).  About the
axis, tau = I qdd + g cos(q) sum(m r) with I = I_a + m_a r_a^2 (+ I_p + m_p r_p^2 while the box
is carried): the loaded and unloaded moves give the two loads below, by hand.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

import gearcli

M_A, R_A, I_A = 2.0, 0.2, 0.03
M_P, R_P, I_P = 1.5, 0.4, 0.002
G = 9.81
ARM = f"""
name: arm
gravity: [0, 0, -{G}]
base: frame
end_effector: arm
links:
  - name: frame
  - {{name: arm, mass: {M_A}, com: [{R_A}, 0, 0], inertia: [0.001, {I_A}, {I_A}]}}
joints:
  - {{name: J, parent: frame, child: arm, axis: [0, -1, 0]}}
motors:
  - {{name: m, link: arm, rating: {{peak_torque: 20, rms_torque: 15, max_speed: 50}}}}
payloads:
  - {{name: box, link: arm, mass: {M_P}, com: [{R_P}, 0, 0], inertia: [{I_P}, {I_P}, {I_P}]}}
"""


def by_hand(q, qdd, carried):
    """Motor torque about the axis (axis -y: a positive angle lifts the arm's +x end)."""
    inertia = I_A + M_A * R_A ** 2 + carried * (I_P + M_P * R_P ** 2)
    return inertia * qdd + G * np.cos(q) * (M_A * R_A + carried * M_P * R_P)


@pytest.fixture
def an():
    return gearcli.analyse(gearcli.parse_mechanism(ARM, "arm.yaml"))


def motion(n=200):
    t = np.linspace(0.0, 2.0, n)
    q = 0.5 * np.sin(np.pi * t)
    qd = 0.5 * np.pi * np.cos(np.pi * t)
    qdd = -0.5 * np.pi ** 2 * np.sin(np.pi * t)
    carried = ((t >= 0.5) & (t < 1.5)).astype(float)       # picked at 0.5 s, placed at 1.5 s
    return t, q, qd, qdd, carried


@pytest.mark.parametrize("backend", ["numpy", "llvm"])
def test_pick_and_place_loads_by_hand(an, backend):
    t, q, qd, qdd, carried = motion()
    res = gearcli.solve(an, q[:, None], qd[:, None], qdd[:, None], attach={"box": carried}, backend=backend)
    expected = by_hand(q, qdd, carried)
    assert np.abs(res.motor[:, 0] - expected).max() < 1e-12 * np.abs(expected).max()
    # the two loads differ by the box's: far beyond the tolerance (the box is not ignored)
    assert np.abs(by_hand(q, qdd, 1.0) - by_hand(q, qdd, 0.0)).min() > 0.1
    # the joint reactions are those of the mechanism carrying the box, where it is carried
    heavy = gearcli.analyse(an.mech.attached(["box"]))
    on = carried == 1
    ref = gearcli.solve(heavy, q[on, None], qd[on, None], qdd[on, None], backend=backend)
    assert np.array_equal(res.joint[on], ref.joint)


def test_mass_matrix_and_forward_dynamics_carry_the_payload(an):
    q = np.array([[0.0], [0.3], [0.3]])
    carried = np.array([0.0, 0.0, 1.0])
    M = gearcli.mass_matrix(an, q, attach={"box": carried})[:, 0, 0]
    assert M == pytest.approx(I_A + M_A * R_A ** 2 + carried * (I_P + M_P * R_P ** 2), rel=1e-13)
    T = by_hand(q[:, 0], np.array([1.0, 2.0, 2.0]), carried)[:, None]
    qdd = gearcli.forward_dynamics(an, q, np.zeros_like(q), T, attach={"box": carried})
    assert qdd[:, 0] == pytest.approx([1.0, 2.0, 2.0], rel=1e-12)


def _trajectory(path, t, q, qd, qdd, carried, values=None):
    flags = carried if values is None else values
    path.write_text("t,q:J,qd:J,qdd:J,attach:box\n" + "".join(
        f"{float(a)!r},{float(b)!r},{float(c)!r},{float(d)!r},{e:g}\n" for a, b, c, d, e in zip(t, q, qd, qdd, flags)))
    return path


def test_solve_and_verify_read_the_attach_column(run_cli, tmp_path):
    (tmp_path / "arm.yaml").write_text(ARM)
    t, q, qd, qdd, carried = motion()
    traj = _trajectory(tmp_path / "pick.csv", t, q, qd, qdd, carried)
    r = run_cli("solve", tmp_path / "arm.yaml", traj, "-o", tmp_path / "loads.csv", "--precision", "17")
    assert r.exit_code == 0, r.stderr
    lo = np.genfromtxt(tmp_path / "loads.csv", delimiter=",", names=True)
    expected = by_hand(q, qdd, carried)
    assert np.abs(lo["motorm"] - expected).max() < 1e-12 * np.abs(expected).max()
    (tmp_path / "d.yaml").write_text("cases:\n  - {name: pick, mechanism: arm.yaml, trajectories: [pick.csv], "
                                     "cycles_per_hour: 100}\n")
    r = run_cli("verify", tmp_path / "d.yaml", "--json", tmp_path / "r.json", "-j", "1")
    assert r.exit_code == 0, r.stderr
    peak = next(c for c in json.loads((tmp_path / "r.json").read_text())["checks"] if c["quantity"] == "peak torque")
    assert peak["value"] == pytest.approx(np.abs(expected).max(), rel=1e-12)


@pytest.mark.parametrize("header, value, message", [
    ("attach:box", "2", "pick.csv:3: column 5 'attach:box': expected 0 or 1 (payload 'box' off or attached), got 2"),
    ("attach:crate", "1", "pick.csv:1: column 5 'attach:crate': 'crate' is not a payload (mechanism payloads: box)"),
])
def test_bad_attach_columns_are_located(run_cli, tmp_path, header, value, message):
    (tmp_path / "arm.yaml").write_text(ARM)
    t, q, qd, qdd, carried = motion(10)
    values = np.zeros(10)
    values[1] = float(value)
    traj = _trajectory(tmp_path / "pick.csv", t, q, qd, qdd, carried, values)
    traj.write_text(traj.read_text().replace("attach:box", header))
    r = run_cli("solve", tmp_path / "arm.yaml", traj, "-o", tmp_path / "loads.csv")
    assert r.exit_code == 2 and message in r.stderr and not (tmp_path / "loads.csv").exists()


def test_simulate_picks_and_places_and_solve_returns_its_torques(run_cli, tmp_path):
    """The input's attach column holds from each row to the next; the written trajectory has
    it, so solve of it returns the input torques to rounding (the pick at 0.5 s and the place
    at 1.5 s included)."""
    (tmp_path / "arm.yaml").write_text(ARM)
    inp = tmp_path / "in.csv"
    inp.write_text("t,motor:m,attach:box\n0,5,0\n0.5,5,1\n1.0,9.5,1\n1.5,4,0\n2,4,0\n")
    r = run_cli("simulate", tmp_path / "arm.yaml", inp, "-o", tmp_path / "traj.csv", "--q0", "0.2",
                "--loads", tmp_path / "loads.parquet", "--rtol", "1e-9")
    assert r.exit_code == 0, r.stderr
    tr = np.genfromtxt(tmp_path / "traj.csv", delimiter=",", names=True)
    import pyarrow.parquet as pq
    lo = {c: v.to_numpy() for c, v in zip(pq.read_table(tmp_path / "loads.parquet").column_names,
                                           pq.read_table(tmp_path / "loads.parquet").columns)}
    lo["motorm"] = lo["motor:m"]
    carried = ((tr["t"] >= 0.5) & (tr["t"] < 1.5)).astype(float)
    assert np.array_equal(tr["attachbox"], carried)
    T = np.interp(tr["t"], [0, 0.5, 1, 1.5, 2], [5, 5, 9.5, 4, 4])
    assert np.abs(lo["motorm"] - T).max() < 1e-12 * np.abs(T).max()
    assert tr["qddJ"] == pytest.approx((T - by_hand(tr["qJ"], 0.0, carried)) /
                                       (I_A + M_A * R_A ** 2 + carried * (I_P + M_P * R_P ** 2)), rel=1e-10, abs=1e-10)


def test_payloads_survive_the_urdf_round_trip_bit_for_bit(run_cli, tmp_path):
    (tmp_path / "arm.yaml").write_text(ARM)
    t, q, qd, qdd, carried = motion()
    traj = _trajectory(tmp_path / "pick.csv", t, q, qd, qdd, carried)
    assert run_cli("export", tmp_path / "arm.yaml", "-o", tmp_path / "arm.urdf").exit_code == 0
    assert "<gearcli:payload " in (tmp_path / "arm.urdf").read_text()
    for src, out in (("arm.yaml", "a.csv"), ("arm.urdf", "b.csv")):
        r = run_cli("solve", tmp_path / src, traj, "-o", tmp_path / out, "--precision", "17")
        assert r.exit_code == 0, r.stderr
    assert (tmp_path / "a.csv").read_text() == (tmp_path / "b.csv").read_text()


def test_check_and_graph_describe_the_payload(run_cli, tmp_path):
    (tmp_path / "arm.yaml").write_text(ARM)
    r = run_cli("check", tmp_path / "arm.yaml")
    assert r.exit_code == 0
    assert ("payload 'box' on link 'arm': 1.5 kg at [0.4, 0, 0] m (link frame), carried where a trajectory's "
            "attach:box is 1") in r.stdout.splitlines()
    d = json.loads(run_cli("graph", tmp_path / "arm.yaml", "--json").stdout)
    assert [(p["name"], p["link"], p["mass"], p["com"]) for p in d["payloads"]] == [("box", "arm", 1.5, [0.4, 0, 0])]
