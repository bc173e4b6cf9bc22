"""Losses as a designer meets them on the command line: ``check``/``graph`` name every lossy
pair and joint (one line each, the friction arm from the README's closed forms, computed
here by hand), ``graph --json`` has them as ``losses``, and the ``solve`` summary's energy
and line efficiency are the hand values of a 15/60 mm spur pair (README, "Losses")."""
from __future__ import annotations

import json
import re
import textwrap
from pathlib import Path

import pytest
import yaml

SPUR = """\
name: spur_lossy
gravity: [0, 0, -9.81]
base: frame
end_effector: wheel
links:
  - name: frame
  - {name: pinion, mass: 0.1, inertia: [1.0e-5, 1.0e-5, 1.0e-5]}
  - {name: wheel, mass: 1.0, inertia: [1.0e-3, 1.0e-3, 1.0e-3]}
joints:
  - name: Jp
    parent: frame
    child: pinion
    axis: [0, 0, 1]
    friction: {coulomb: 0.002, viscous: 1.0e-5}
    bearings:
      - {name: a, position: 0.0, locating: true, friction_coefficient: 0.0015, bore: 0.008}
      - {name: b, position: 0.02, friction_coefficient: 0.0015, bore: 0.008}
  - {name: Jw, parent: frame, child: wheel, origin: {xyz: [0.075, 0, 0]}, axis: [0, 0, 1]}
gears:
  - {name: mesh, links: [pinion, wheel], teeth: [15, 60], mesh_point: [0.015, 0, 0], efficiency: 0.97}
motors:
  - {name: motor, link: pinion}
loads:
  - {name: brake, link: wheel, frame: base, moment: [0, 0, 2.0]}
"""

# the wheel turns at -1 rad/s (the pinion at +4 rad/s) for 1 s against the brake's 2 N*m
TRAJ = "t,q:Jw,qd:Jw,qdd:Jw\n0,0,-1,0\n0.5,-0.5,-1,0\n1,-1,-1,0\n"


def _spur_only(text: str) -> str:
    """The spur pair with its mesh loss only (no joint or bearing friction)."""
    start, end = text.index("    friction: {coulomb"), text.index("  - {name: Jw")
    return text[:start] + text[end:]


def test_check_and_graph_print_one_line_per_lossy_pair_and_joint(run_cli, tmp_path):
    path = tmp_path / "spur.yaml"
    path.write_text(SPUR)
    rho = 0.015 * 0.060 / (0.015 + 0.060)          # external spur: r_j r_k / (r_j + r_k) = 0.012 m
    pair = (f"mesh friction on pair 'mesh': efficiency 0.97 (loss factor 0.03), friction arm {rho:.6g} m: "
            f"couple 0.03 * {rho:.6g} m * |t|")
    joint = ("friction of joint 'Jp': Coulomb 0.002 N*m, viscous 1e-05 N*m*s/rad, "
             "bearing 'a' (mu 0.0015, bore 0.008 m), bearing 'b' (mu 0.0015, bore 0.008 m)")
    r = run_cli("check", path)
    assert r.exit_code == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0] == f"{path}: OK (1 dof, 3 links, 1 gear pair, 1 motor)"
    assert lines[2:] == [pair, joint]                      # Jw has no friction: no line
    g = run_cli("graph", path)
    assert pair in g.stdout.splitlines() and joint in g.stdout.splitlines()
    doc = json.loads(run_cli("graph", "--json", path).stdout)
    assert doc["losses"]["gears"] == [{"pair": "mesh", "efficiency": 0.97, "loss_factor": pytest.approx(0.03, rel=1e-12),
                                       "friction_arm": pytest.approx(rho, rel=1e-12)}]
    assert doc["losses"]["joints"] == [{"joint": "Jp", "type": "revolute", "coulomb": 0.002, "viscous": 1e-5,
                                        "bearings": [{"name": "a", "friction_coefficient": 0.0015, "bore": 0.008},
                                                     {"name": "b", "friction_coefficient": 0.0015, "bore": 0.008}]}]


def test_check_lists_internal_and_rack_arms_and_prismatic_units(run_cli, mech_dir, tmp_path):
    """Internal pair: rho = r_j r_k / |r_k - r_j| (planet 9 mm, ring 30 mm); rack: rho = r
    (24 mm); a prismatic joint's friction in N and N*s/m."""
    plan = (mech_dir / "planetary_3p.yaml").read_text().replace(
        "    stiffness: 3.5e8\n", "    stiffness: 3.5e8\n    loss_factor: 0.015\n")
    assert "loss_factor" in plan
    (tmp_path / "p.yaml").write_text(plan)
    r = run_cli("check", tmp_path / "p.yaml")
    assert r.exit_code == 0, r.stderr
    rho = 0.009 * 0.030 / (0.030 - 0.009)
    notes = [ln for ln in r.stdout.splitlines() if ln.startswith("mesh friction")]
    assert notes == [f"mesh friction on pair 'planet-ring{k}': efficiency 0.985 (loss factor 0.015), friction arm "
                     f"{rho:.6g} m: couple 0.015 * {rho:.6g} m * |t|" for k in (1, 2, 3)]
    rack = (mech_dir / "rack_axis.yaml").read_text()
    rack = rack.replace("    pressure_angle_deg: 20\n", "    pressure_angle_deg: 20\n    efficiency: 0.9\n")
    rack = rack.replace("    axis: [1, 0, 0]\n", "    axis: [1, 0, 0]\n    friction: {coulomb: 5.0, viscous: 20.0}\n")
    (tmp_path / "r.yaml").write_text(rack)
    r = run_cli("check", tmp_path / "r.yaml")
    assert r.exit_code == 0, r.stderr
    assert r.stdout.splitlines()[-2:] == [
        "mesh friction on pair 'rack': efficiency 0.9 (loss factor 0.1), friction arm 0.024 m: couple 0.1 * 0.024 m * |t|",
        "friction of joint 'Jx': Coulomb 5 N, viscous 20 N*s/m"]


@pytest.mark.parametrize("name", ["rack_axis.yaml", "planetary_3p.yaml", "bendix_wrist_rated.yaml"])
def test_lossless_check_has_no_loss_lines(run_cli, mech_dir, name):
    r = run_cli("check", mech_dir / name)
    assert r.exit_code == 0
    assert not any(ln.startswith(("mesh friction", "friction of joint")) for ln in r.stdout.splitlines())
    assert json.loads(run_cli("graph", "--json", mech_dir / name).stdout)["losses"] == {"gears": [], "joints": []}


def test_solve_summary_spur_pair_by_hand(run_cli, tmp_path):
    """15/60 mm at eta = 0.97, pinion driving at 4 rad/s against 2 N*m on the wheel: the
    tooth force t = M / (r_k - c rho), the mesh loss c |t| r_j w = 0.0603622 W for 1 s, and
    the line efficiency (r_k - c rho) r_j / (r_k (r_j + c rho)) = 0.9707 (README)."""
    mech, traj = tmp_path / "spur.yaml", tmp_path / "traj.csv"
    mech.write_text(_spur_only(SPUR))
    traj.write_text(TRAJ)
    r = run_cli("solve", mech, traj, "-o", tmp_path / "out.csv")
    assert r.exit_code == 0, r.stderr
    rj, rk, c, M, w = 0.015, 0.060, 0.03, 2.0, 4.0
    rho = rj * rk / (rj + rk)
    t = M / (rk - c * rho)
    energy = c * t * rj * w * 1.0
    eta = (rk - c * rho) * rj / (rk * (rj + c * rho))
    assert f"{eta:.4f}" == "0.9707"
    lines = r.stdout.splitlines()
    assert f"energy lost: {energy:.6g} J in all" in lines
    assert f"  gear mesh: {energy:.6g} J (100 %)" in lines
    assert f"line efficiency of motor motor: {eta:.4f} (lossless power / motor power where the motor drives)" in lines


def test_line_efficiency_counts_bearing_friction(run_cli, tmp_path):
    """Bearing friction alone on the pinion shaft: bearing 'a' (in the gear's plane) carries
    the whole reaction, P = sqrt((t/cos phi)^2 + (m g)^2) with t = 2 N*m / r_k, and the line
    efficiency is t r_j / (t r_j + mu d P / 2) = 0.9996 (was 1.0000: the lossless motion
    the summary compares with kept the bearing friction)."""
    import math
    text = _spur_only(SPUR).replace(", efficiency: 0.97", "").replace(
        "    axis: [0, 0, 1]\n  - {name: Jw",
        "    axis: [0, 0, 1]\n    bearings:\n"
        "      - {name: a, position: 0.0, locating: true, friction_coefficient: 0.0015, bore: 0.008}\n"
        "      - {name: b, position: 0.02, friction_coefficient: 0.0015, bore: 0.008}\n  - {name: Jw", 1)
    assert "efficiency" not in text and text.count("friction_coefficient") == 2
    mech, traj = tmp_path / "spur.yaml", tmp_path / "traj.csv"
    mech.write_text(text)
    traj.write_text(TRAJ)
    r = run_cli("solve", mech, traj, "-o", tmp_path / "out.csv")
    assert r.exit_code == 0, r.stderr
    rj, rk, t = 0.015, 0.060, 2.0 / 0.060
    P = math.hypot(t / math.cos(math.radians(20)), 0.1 * 9.81)
    moment = 0.5 * 0.0015 * 0.008 * P
    eta = t * rj / (t * rj + moment)
    assert f"{eta:.4f}" == "0.9996"
    assert f"line efficiency of motor motor: {eta:.4f} (lossless power / motor power where the motor drives)" \
        in r.stdout.splitlines()
    assert f"  joint Jp: {moment * 4.0:.6g} J (100 %)" in r.stdout.splitlines()


def test_coupled_lines_efficiency_above_one_is_explained(run_cli, mech_dir, tmp_path):
    """The paper's arm with its bevel pair at eta = 0.98: the bevel's friction couple reacts
    on link 1 and helps motor5, whose line efficiency is above 1 (measured, not a bug: the
    two motors' extra work equals the energy lost, computed here from the power columns of
    the lossy and lossless solves); the summary says why instead of printing a bare 1.0009."""
    import numpy as np
    text = (mech_dir / "paper_2dof.yaml").read_text()
    assert text.count("    cone_angles_deg: [45, 45]\n") == 1
    (tmp_path / "bev.yaml").write_text(text.replace("    cone_angles_deg: [45, 45]\n",
                                                    "    cone_angles_deg: [45, 45]\n    efficiency: 0.98\n"))
    traj = mech_dir / "paper_2dof_traj.csv"
    r = run_cli("solve", tmp_path / "bev.yaml", traj, "-o", tmp_path / "lossy.csv")
    assert r.exit_code == 0, r.stderr
    assert run_cli("solve", mech_dir / "paper_2dof.yaml", traj, "-o", tmp_path / "ideal.csv").exit_code == 0
    lines = r.stdout.splitlines()
    assert "line efficiency of motor motor3: 0.9805 (lossless power / motor power where the motor drives)" in lines
    assert ("line efficiency of motor motor5: 1.0009 (lossless power / motor power where the motor drives; above 1: "
            "losses elsewhere do part of this motor's work (coupled lines))") in lines
    lossy, ideal = (np.genfromtxt(tmp_path / f, delimiter=",", names=True) for f in ("lossy.csv", "ideal.csv"))
    t = lossy["t"]
    extra = sum(np.trapezoid(lossy[f"motor{m}power"] - ideal[f"motor{m}power"], t) for m in ("motor3", "motor5"))
    lost = float(next(ln for ln in lines if ln.startswith("energy lost:")).split()[2])
    assert extra == pytest.approx(lost, rel=1e-5) and f"{lost:.4g}" == "0.3803"


def test_summary_lists_equal_losses_in_file_order(run_cli, mech_dir, tmp_path):
    """The three copies of a planet lose the same energy (to rounding): the summary lists
    them 1, 2, 3 (was: by their rounding noise, 2, 1, 3)."""
    plan = (mech_dir / "planetary_3p.yaml").read_text()
    plan = plan.replace("    stiffness: 3.0e8                   # N/m\n", "    stiffness: 3.0e8\n    efficiency: 0.98\n")
    plan = plan.replace("    stiffness: 3.5e8\n", "    stiffness: 3.5e8\n    loss_factor: 0.015\n")
    assert plan.count("efficiency: 0.98") == 1 and plan.count("loss_factor") == 1
    (tmp_path / "p.yaml").write_text(plan)
    traj = (mech_dir / "planetary_3p_traj.csv").read_text().splitlines()[:200]
    (tmp_path / "t.csv").write_text("\n".join(traj) + "\n")
    r = run_cli("solve", tmp_path / "p.yaml", tmp_path / "t.csv", "-o", tmp_path / "out.csv")
    assert r.exit_code == 0, r.stderr
    listed = [ln.split(":")[0].strip() for ln in r.stdout.splitlines() if ln.startswith("  gear ")]
    assert listed == [f"gear sun-planet{k}" for k in (1, 2, 3)] + [f"gear planet-ring{k}" for k in (1, 2, 3)]


def test_summary_iterations_agree_with_their_noun():
    import numpy as np

    from gearcli.report.loss_summary import LossSummary
    s = LossSummary(["joint J"], ["m"], energy=np.array([1.0]), p_in=np.array([2.0]), p_out=np.array([1.5]),
                    iterations=np.array([0, 7]))
    assert "bearing friction: converged in 1 iteration per sample (median), 1 at worst" in s.lines()
    s.iterations = np.array([0, 0, 0, 5, 1])
    assert "bearing friction: converged in 3 iterations per sample (median), 4 at worst" in s.lines()


def test_help_names_the_losses_and_their_units(run_cli):
    solve = " ".join(run_cli("solve", "--help").stdout.split())
    for text in ("gears[].efficiency", "joints[].friction", "gear:<pair>:loss (W)", "joint:<joint>:friction (N*m; N if",
                 "joint:<joint>:loss (W)", "energy lost (J)", "line efficiency"):
        assert text in solve, text
    check = " ".join(run_cli("check", "--help").stdout.split())
    assert "losses (mesh efficiency in (0, 1], friction >= 0)" in check
    assert "lossy gear pair (efficiency, friction arm in m)" in check
    simulate = " ".join(run_cli("simulate", "--help").stdout.split())
    for text in ("losses included (its energy falls by them;", "gear:<pair>:loss, joint:<joint>:loss in W",
                 "joint:<joint>:friction)"):
        assert text in simulate, text
    export = " ".join(run_cli("export", "--help").stdout.split())
    for text in ("gearcli:gear efficiency or loss_factor", "gearcli:friction coulomb viscous",
                 "gearcli:bearing friction_coefficient bore in m"):
        assert text in export, text
    verify = " ".join(run_cli("verify", "--help").stdout.split())
    assert "with the motor torques of 'gearcli solve' (losses included: mesh efficiency, joint and bearing friction)" \
        in verify


def test_bearing_friction_on_a_slide_points_to_joint_friction(run_cli, mech_dir, tmp_path):
    rack = (mech_dir / "rack_axis.yaml").read_text().replace(
        "    axis: [1, 0, 0]\n",
        "    axis: [1, 0, 0]\n    bearings: [{name: g, position: 0, friction_coefficient: 0.002, bore: 0.01}]\n")
    path = tmp_path / "r.yaml"
    path.write_text(rack)
    r = run_cli("check", path)
    assert r.exit_code == 2 and r.stdout == ""
    line = next(i for i, ln in enumerate(rack.splitlines(), 1) if "bearings: [{name: g" in ln)
    assert r.stderr == (f"{path}:{line}: joints[1].bearings: rolling-bearing ratings and friction (ISO 281 life in "
                        "revolutions, a moment about the axis) are for revolute joints; a prismatic joint's linear "
                        "guide is not rated, and its friction is joints[].friction (coulomb N, viscous N*s/m)\n")


@pytest.mark.parametrize("old, new, key, message", [
    ("efficiency: 0.97", "efficiency: 0.03", "gears[0].efficiency",
     "gear pair 'mesh': mesh efficiency 0.03 (loss factor 0.97) is below 0.5; a gear mesh loses 0.5 to 3 % at the "
     "pitch point: efficiency and loss_factor swapped? (loss_factor = 1 - efficiency)"),
    ("efficiency: 0.97", "loss_factor: 0.97", "gears[0].loss_factor",
     "gear pair 'mesh': mesh efficiency 0.03 (loss factor 0.97) is below 0.5; a gear mesh loses 0.5 to 3 % at the "
     "pitch point: efficiency and loss_factor swapped? (loss_factor = 1 - efficiency)"),
    ("efficiency: 0.97", "loss_factor: 0.999999", "gears[0].loss_factor",     # was "(loss factor 1)": not allowed
     "gear pair 'mesh': mesh efficiency 1e-06 (loss factor 0.999999) is below 0.5; a gear mesh loses 0.5 to 3 % at "
     "the pitch point: efficiency and loss_factor swapped? (loss_factor = 1 - efficiency)"),
    ("bore: 0.008}\n      - {name: b", "bore: 8}\n      - {name: b", "joints[0].bearings[0].bore",
     "joint 'Jp': bearing 'a': bore 8 m is above 2 m: in mm? (gearcli reads m)"),
])
def test_implausible_losses_are_warned_and_strict_refuses(run_cli, tmp_path, old, new, key, message):
    text = SPUR.replace(old, new)
    assert text != SPUR
    path = tmp_path / "m.yaml"
    path.write_text(text)
    line = next(i for i, ln in enumerate(text.splitlines(), 1) if new.split("\n")[0] in ln)
    r = run_cli("check", path)
    assert r.exit_code == 0 and r.stdout.startswith(f"{path}: OK")
    assert r.stderr == f"{path}:{line}: {key}: warning: {message}\n"
    r = run_cli("check", "--strict", path)
    assert r.exit_code == 2 and r.stdout == ""
    assert r.stderr == f"{path}:{line}: {key}: {message} (--strict)\n"


def test_plausible_losses_give_no_warning(run_cli, tmp_path):
    path = tmp_path / "m.yaml"
    path.write_text(SPUR.replace("efficiency: 0.97", "efficiency: 0.5").replace("bore: 0.008}", "bore: 2.0}"))
    r = run_cli("check", "--strict", path)
    assert r.exit_code == 0 and r.stderr == ""


def test_csv_loss_columns_are_drawn_with_their_units(run_cli, tmp_path, monkeypatch):
    """A CSV carries no units: the plot takes them from the names, W for gear:<p>:loss and
    joint:<J>:loss, N*m for joint:<J>:friction of a revolute joint (was: no unit, all three
    on one axis labelled 'value'); the Parquet of the same solve carries the same units."""
    pytest.importorskip("matplotlib")
    from gearcli.report import plots
    mech, traj = tmp_path / "spur.yaml", tmp_path / "traj.csv"
    mech.write_text(SPUR)
    traj.write_text(TRAJ)
    units = {}
    for ext in (".csv", ".parquet"):
        assert run_cli("solve", mech, traj, "-o", tmp_path / f"loads{ext}").exit_code == 0
        header, _, units[ext] = plots.read_loads(tmp_path / f"loads{ext}")
    assert [units[".csv"][n] for n in ("gear:mesh:loss", "joint:Jp:friction", "joint:Jp:loss")] == ["W", "N·m", "W"]
    assert units[".csv"] == units[".parquet"]
    seen = {}
    save = plots._save

    def spy(fig, path):
        seen["ylabels"] = sorted(ax.get_ylabel() for ax in fig.axes)
        save(fig, path)
    monkeypatch.setattr(plots, "_save", spy)
    r = run_cli("plot", tmp_path / "loads.csv", "gear:*:loss", "joint:Jp:friction", "joint:*:loss",
                "-o", tmp_path / "f.png")
    assert r.exit_code == 0, r.stderr
    assert seen["ylabels"] == ["[N·m]", "[W]"]


def _readme_example() -> tuple[str, list[str]]:
    """The YAML and the console lines of the loss model page's example (indented 2 spaces)."""
    text = (Path(__file__).resolve().parents[1] / "docs" / "concepts" / "losses.md").read_text()
    part = text[text.index("* **Example** (a 15/60 mm spur pair"):]
    blocks = re.findall(r"\n  ```(yaml|console)\n(.*?)\n  ```\n", part, re.S)[:2]
    assert [b[0] for b in blocks] == ["yaml", "console"]
    yaml_text, console = (textwrap.dedent(b[1]) for b in blocks)
    return yaml_text + "\n", console.splitlines()


def test_readme_loss_example_runs_as_written(run_cli, tmp_path, monkeypatch):
    yaml_text, console = _readme_example()
    monkeypatch.chdir(tmp_path)
    Path("spur_lossy.yaml").write_text(yaml_text)
    assert yaml.safe_load(yaml_text) == yaml.safe_load((Path(__file__).resolve().parents[1] / "docs" / "examples" / "spur_lossy.yaml").read_text())
    assert console[0].startswith("$ cp docs/examples/spur_lossy.yaml .")
    printf = console[1]
    assert printf.startswith("$ printf '") and printf.endswith("' > spur_traj.csv")
    Path("spur_traj.csv").write_text(printf[len("$ printf '"):-len("' > spur_traj.csv")].replace("\\n", "\n"))
    i_check = console.index("$ gearcli check spur_lossy.yaml")
    i_solve = console.index("$ gearcli solve spur_lossy.yaml spur_traj.csv -o loads.csv")
    r = run_cli("check", "spur_lossy.yaml")
    assert r.exit_code == 0 and r.stderr == ""
    assert r.stdout.splitlines() == console[i_check + 1:i_solve]
    r = run_cli("solve", "spur_lossy.yaml", "spur_traj.csv", "-o", "loads.csv")
    assert r.exit_code == 0 and r.stderr == ""      # 3 samples: numpy by the first-call rule, no notice
    tail = console[i_solve + 2:]                 # after the '…' line standing for the table
    assert console[i_solve + 1].startswith("…")
    assert r.stdout.splitlines()[-len(tail):] == tail


def test_export_writes_the_mesh_loss_as_the_file_gave_it(run_cli, mech_dir, tmp_path):
    """efficiency 0.98 is exported as efficiency="0.98" (was loss_factor="0.020000000000000018"),
    loss_factor 0.015 as loss_factor="0.015"; both read back to the same loss factor."""
    from gearcli import load_mechanism
    plan = (mech_dir / "planetary_3p.yaml").read_text()
    plan = plan.replace("    stiffness: 3.0e8                   # N/m\n", "    stiffness: 3.0e8\n    efficiency: 0.98\n")
    plan = plan.replace("    stiffness: 3.5e8\n", "    stiffness: 3.5e8\n    loss_factor: 0.015\n")
    (tmp_path / "p.yaml").write_text(plan)
    assert run_cli("export", tmp_path / "p.yaml", "-o", tmp_path / "p.urdf").exit_code == 0
    urdf = (tmp_path / "p.urdf").read_text()
    assert urdf.count('efficiency="0.98"') == 3 and urdf.count('loss_factor="0.015"') == 3
    assert "0.020000000000000018" not in urdf
    before = {g.name: g.loss_factor for g in load_mechanism(tmp_path / "p.yaml").gears}
    after = {g.name: g.loss_factor for g in load_mechanism(tmp_path / "p.urdf").gears}
    assert after == before and before["sun-planet1"] == 1.0 - 0.98


def test_friction_that_locks_names_the_sample_by_its_time_and_line(run_cli, tmp_path):
    """Bearing friction so large on the wheel's shaft (mu 0.9, 500 mm bores) that its moments
    grow without bound: ``solve`` stops with one line naming the trajectory, the first moving
    sample's time and file line (it is in the second chunk, where the solver's own "sample i"
    counts from the chunk's start: "sample 21" before), and writes nothing."""
    text = SPUR.replace("    bearings:\n      - {name: a, position: 0.0, locating: true, friction_coefficient: 0.0015, bore: 0.008}\n"
                        "      - {name: b, position: 0.02, friction_coefficient: 0.0015, bore: 0.008}\n", "")
    text = text.replace("  - {name: Jw, parent: frame, child: wheel, origin: {xyz: [0.075, 0, 0]}, axis: [0, 0, 1]}\n",
                        "  - name: Jw\n    parent: frame\n    child: wheel\n    origin: {xyz: [0.075, 0, 0]}\n"
                        "    axis: [0, 0, 1]\n    bearings:\n"
                        "      - {name: a, position: 0.0, locating: true, friction_coefficient: 0.9, bore: 0.5}\n"
                        "      - {name: b, position: 0.02, friction_coefficient: 0.9, bore: 0.5}\n")
    assert text.count("friction_coefficient: 0.9") == 2
    mech, traj, out = tmp_path / "lock.yaml", tmp_path / "lock.csv", tmp_path / "out.csv"
    mech.write_text(text)
    rows = [f"{0.01 * i:.2f},0,0,0" if i < 150 else f"{0.01 * i:.2f},{-0.01 * (i - 150):.2f},-1,0" for i in range(250)]
    traj.write_text("t,q:Jw,qd:Jw,qdd:Jw\n" + "\n".join(rows) + "\n")
    for backend in ("numpy", "llvm"):
        r = run_cli("solve", mech, traj, "--chunk", 100, "--backend", backend, "-o", out)
        assert r.exit_code == 2, (r.exit_code, r.stderr)
        lines = r.stderr.strip("\n").splitlines()
        assert len(lines) == 1 and "Traceback" not in r.stderr + r.stdout, r.stderr
        assert lines[0].startswith(f"{traj}:152: sample t = 1.5 s: the bearing friction moments of joint 'Jw' "
                                   "did not converge"), lines[0]
        assert not out.exists()


def test_solve_summary_back_driven_spur_pair_by_hand(run_cli, tmp_path):
    """The same 15/60 mm pair at eta = 0.97 with the wheel turning the other way: the brake's
    2 N*m now drives the wheel, which back-drives the pinion.  The friction couple reverses:
    the pinion torque is t (r_j - c rho) and the wheel's M = t (r_k + c rho), so the motor
    receives (r_j - c rho) r_k / (r_j (r_k + c rho)) = 0.9702 of the lossless power (issue 34,
    section 3: the summary said only "-" for a line whose power flows backward)."""
    mech, traj = tmp_path / "spur.yaml", tmp_path / "traj.csv"
    mech.write_text(_spur_only(SPUR))
    traj.write_text(TRAJ.replace(",-1,0", ",1,0").replace("-0.5,", "0.5,").replace("\n1,-1,", "\n1,1,"))
    assert traj.read_text() == "t,q:Jw,qd:Jw,qdd:Jw\n0,0,1,0\n0.5,0.5,1,0\n1,1,1,0\n"
    r = run_cli("solve", mech, traj, "-o", tmp_path / "out.csv")
    assert r.exit_code == 0, r.stderr
    rj, rk, c = 0.015, 0.060, 0.03
    rho = rj * rk / (rj + rk)
    eta_b = (rj - c * rho) * rk / (rj * (rk + c * rho))
    assert f"{eta_b:.4f}" == "0.9702"
    lines = r.stdout.splitlines()
    assert "line efficiency of motor motor: - (its power never flows forward)" in lines
    assert (f"back-driven efficiency of motor motor: {eta_b:.4f} (motor power / lossless power where the load "
            "drives the motor: regenerating or braking)") in lines
    assert "(line efficiencies include the acceleration energy of each line's inertia, its rotor's too)" in lines
