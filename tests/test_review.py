"""Findings of a new user's review of the README and ``--help``: each test pins one fixed
behaviour (library inputs, error messages, CLI options)."""
from __future__ import annotations

import math
from pathlib import Path
import warnings

import numpy as np
import pytest

from gearcli import analyse, parse_mechanism, solve
from gearcli.dynamics.signs import SignError

BACKENDS = ["numpy", "llvm"]

# a 2 kg arm on a horizontal axis (y), driven directly: no gear, so no sign search
ARM = """
name: arm
base: "0"
end_effector: "1"
links:
  - name: "0"
  - {name: "1", mass: 2.0, com: [0.3, 0, 0], inertia: [0.01, 0.02, 0.02]}
joints:
  - {name: J1, parent: "0", child: "1", origin: {xyz: [0, 0, 0]}, axis: [0, 1, 0]}
motors:
  - {name: m, link: "1"}
"""


@pytest.fixture(scope="module")
def arm():
    return analyse(parse_mechanism(ARM))


def test_sign_error_says_what_and_where():
    """str(SignError) was empty: a library traceback ended in a bare 'SignError'."""
    exc = SignError(7, ["5-1", "3-4"])
    assert "sample 7" in str(exc) and "5-1, 3-4" in str(exc)
    assert str(exc) == exc.lines()[0]


def test_one_dimensional_input_names_the_shape_given(arm):
    with pytest.raises(ValueError, match=r"got \(4, 3\)$"):
        solve(arm, np.zeros((4, 3)), np.zeros((4, 3)), np.zeros((4, 3)))
    with pytest.raises(ValueError, match=r"got \(3,\)$"):
        solve(arm, np.zeros(3), np.zeros(3), np.zeros(3))


@pytest.mark.parametrize("backend", BACKENDS)
def test_verify_residual_is_not_finite_when_loads_are_not(arm, backend):
    """A rate of 1e200 rad/s overflows (omega^2 = inf): the loads of that sample are not
    finite, and the residual of verify=True must say so (it was 0.0: Python's max keeps
    0.0 against a NaN)."""
    q = np.zeros((3, 1))
    qd = np.array([[0.0], [1e200], [0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        res = solve(arm, q, qd, q, backend=backend, verify=True)
    assert not np.isfinite(res.joint[1]).all()
    assert not math.isfinite(res.residual)
    # the finite samples alone: a sound solve, the static holding torque m g x_c
    with warnings.catch_warnings():
        res = solve(arm, q[[0, 2]], qd[[0, 2]], q[[0, 2]], backend=backend, verify=True)
    assert res.residual < 1e-12
    np.testing.assert_allclose(res.motor[:, 0], -2.0 * 9.81 * 0.3, rtol=1e-12)


# --- the command line -------------------------------------------------------------------
def test_progress_bar_leaves_a_non_terminal_stderr_empty(run_cli, mech_dir, tmp_path):
    """The progress bar (more than 4 chunks) printed a stray blank line into a redirected
    stderr (a CI log)."""
    out = tmp_path / "loads.csv"
    r = run_cli("solve", mech_dir / "paper_2dof.yaml", mech_dir / "paper_2dof_traj.csv", "-o", out,
                "--chunk", "100")
    assert r.exit_code == 0, r.stderr
    assert r.stderr == ""
    assert len(out.read_text().splitlines()) == 2002


@pytest.mark.parametrize("option", ["--junit", "--json", "--markdown"])
def test_verify_names_the_report_option_it_refuses(run_cli, mech_dir, tmp_path, option):
    """A bad report path was reported as '-o', an option verify does not have."""
    design = mech_dir.parent / "designs" / "ci_example.yaml"
    r = run_cli("verify", design, option, tmp_path / "missing" / "r.out")
    assert r.exit_code == 2
    assert r.stderr == f"{tmp_path / 'missing' / 'r.out'}: {option}: directory '{tmp_path / 'missing'}' does not exist\n"
    r = run_cli("verify", design, option, design)
    assert r.exit_code == 2
    assert r.stderr.startswith(f"{design}: {option}: is the input file")


def test_mechanism_help_says_urdf_too(run_cli):
    for command in ("check", "graph", "solve", "export"):
        assert "URDF" in run_cli(command, "--help").stdout


def test_solve_help_shows_the_readme_usage(run_cli):
    """The option values as the README's usage line writes them (was '<str>', '<int range>')."""
    text = " ".join(run_cli("solve", "--help").stdout.split())
    for usage in ("--method block|full", "--chunk N", "-j, --jobs N", "--backend auto|llvm|numpy",
                  "--precision N"):
        assert usage in text, usage


def test_plot_units_of_a_csv_come_only_from_output_column_names(tmp_path):
    """A CSV column that is no output column (a trajectory's q:J1) was drawn on an axis in N."""
    from gearcli.report.plots import read_loads

    path = tmp_path / "mixed.csv"
    path.write_text("t,q:J1,joint:J1:fx,joint:J1:bending,tau:J1,gear:g:p:radial,motor:m:speed,foo:bar:fx\n"
                    "0,1,2,3,4,5,6,7\n1,1,2,3,4,5,6,7\n")
    header, data, units = read_loads(path)
    assert data.shape == (2, 8)
    assert units == {"t": "s", "q:J1": "", "joint:J1:fx": "N", "joint:J1:bending": "N·m", "tau:J1": "N·m",
                     "gear:g:p:radial": "N", "motor:m:speed": "rad/s", "foo:bar:fx": ""}


def test_reprs_stay_readable(mech_dir, tmp_path):
    """repr(mech) printed the whole YAML path -> line map (hundreds of entries), and
    repr(solve_file(...)) the whole analysis on top, in a notebook."""
    from gearcli import load_mechanism, solve_file

    mech = load_mechanism(mech_dir / "paper_2dof.yaml")
    assert "links[0].name" not in repr(mech) and "paper_2dof" in repr(mech)
    rep = solve_file(mech_dir / "paper_2dof.yaml", mech_dir / "paper_2dof_traj.csv", tmp_path / "l.csv")
    assert "samples=2001" in repr(rep) and "Link(" not in repr(rep)
    assert rep.analysis.mech.lines["links[1].mass"] == 14    # kept, only not shown


def test_verify_refuses_jobs_with_dask(run_cli, mech_dir, tmp_path):
    """-j was silently ignored with --dask (the cluster has its own workers)."""
    design = mech_dir.parent / "designs" / "ci_example.yaml"
    r = run_cli("verify", design, "-j", "2", "--dask", "tcp://127.0.0.1:9", "--junit", tmp_path / "r.xml")
    assert r.exit_code == 2
    assert r.stderr == "verify: give -j/--jobs or --dask, not both (a Dask cluster has its own workers)\n"
    assert list(tmp_path.iterdir()) == []


def test_verify_plot_of_a_joint_rate_says_it_draws_its_magnitude(monkeypatch, mech_dir, tmp_path):
    """The plot of a tight velocity check draws |q_dot| and labelled it 'joint rate'."""
    import gearcli.batch.verify as bv

    drawn = []
    monkeypatch.setattr(bv, "plot_check", lambda t, y, limit, path, title, ylabel, limit_label, levels=():
                        drawn.append((np.asarray(y), limit, ylabel)))
    design = tmp_path / "arm.yaml"    # geared_arm's elbow reaches 2.83 of its 3 rad/s: tight
    design.write_text(f"name: arm\ncases:\n  - mechanism: {mech_dir / 'geared_arm.urdf'}\n"
                      f"    trajectories: {mech_dir / 'geared_arm_traj.csv'}\n")
    bv.run_verify(design, jobs=1, plots_dir=tmp_path / "plots")
    rates = [d for d in drawn if "rate" in d[2]]
    assert len(rates) == 1
    y, limit, ylabel = rates[0]
    assert ylabel == "|joint rate| [rad/s]" and limit == 3.0
    assert y.min() >= 0 and 2.8 < y.max() < 3.0


def test_missing_position_column_of_a_prismatic_joint_gives_no_angle_unit(run_cli, mech_dir, tmp_path):
    """The message said 'rad' for the rack axis's linear guide (q in m)."""
    traj = tmp_path / "t.csv"
    traj.write_text("t\n0\n1\n2\n")
    r = run_cli("solve", mech_dir / "rack_axis.yaml", traj, "-o", tmp_path / "o.csv")
    assert r.exit_code == 2
    assert r.stderr == f"{traj}:1: missing column 'q:Jx' (independent joint 'Jx')\n"


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
@pytest.mark.parametrize("args", [["--help"], ["--version"], ["solve", "--help"]])
def test_help_into_a_full_stdout_is_one_line_not_a_traceback(args):
    """--help and --version (outside any command) wrote a traceback when stdout failed."""
    import os
    import subprocess
    import sys

    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1] / "src")}
    with open("/dev/full", "w") as full:
        r = subprocess.run([sys.executable, "-c", "from gearcli.cli import app; app()", *args], stdout=full,
                           stderr=subprocess.PIPE, text=True, env=env, timeout=120)
    assert r.returncode == 2
    assert r.stderr == "stdout: cannot write: No space left on device\n"


def test_urdf_under_another_name_is_named_xml_not_a_yaml_error(run_cli, mech_dir, tmp_path):
    """A xacro file or a URDF named .txt gave 'YAML syntax error: mapping values are not allowed'."""
    xacro = tmp_path / "arm.urdf.xacro"
    xacro.write_bytes((mech_dir / "geared_arm.urdf").read_bytes())
    r = run_cli("check", xacro)
    assert r.exit_code == 2
    assert r.stderr == (f"{xacro}:1: this is XML, not YAML: a URDF is read from a file named .urdf or .xml "
                        "(expand a xacro file first)\n")
    merge = tmp_path / "m.yaml"       # YAML opening with '<<' (a merge key) stays a YAML problem
    merge.write_text("<<: *x\n")
    r = run_cli("check", merge)
    assert r.exit_code == 2 and "YAML syntax error" in r.stderr


@pytest.mark.parametrize("args", [["check", "{mech}"], ["solve", "{mech}", "{traj}", "-o", "{out}"], ["--help"]])
def test_closed_stdout_is_one_line_not_a_traceback(args, mech_dir, tmp_path):
    """With stdout closed (cron, '>&-') every command ended in an AttributeError traceback
    (and solve -o FILE wrote its file first)."""
    import os
    import subprocess
    import sys

    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1] / "src")}
    names = {"mech": mech_dir / "paper_2dof.yaml", "traj": mech_dir / "paper_2dof_traj.csv", "out": tmp_path / "o.csv"}
    code = "from gearcli.cli import app; app()"
    r = subprocess.run([sys.executable, "-c", code, *(a.format(**names) for a in args)], stderr=subprocess.PIPE,
                       text=True, env=env, timeout=120, preexec_fn=lambda: os.close(1))
    assert r.returncode == 2
    assert r.stderr == "stdout: cannot write: stdout is closed\n"
    assert list(tmp_path.iterdir()) == []


_URDF_LINK = ('<link name="{0}"><inertial><mass value="1"/>'
              '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>')
_URDF_TRANSMISSION = ('<transmission name="{0}"><type>transmission_interface/SimpleTransmission</type>'
                      '<joint name="{1}"/><actuator name="{2}"><mechanicalReduction>10</mechanicalReduction>'
                      '</actuator></transmission>')


@pytest.mark.parametrize("mimic_of_j2, expected", [
    ("j0", ["{f}:4: joint 'j1'.mimic: joint 'j1' mimics unknown joint 'j0'"]),
    ("j1", ["{f}:4: joint 'j1'.mimic: mimic cycle: j1 -> j2 -> j1 (each joint follows the next; no joint leads)"]),
])
def test_urdf_lists_mimic_and_transmission_problems_together(run_cli, tmp_path, mimic_of_j2, expected):
    """A bad <mimic> hid the transmissions' problems (shown only once it was fixed, as the
    README's bad.urdf example did not); a joint left without its leader makes up no motor
    (no 'duplicate motor name' against an actuator named like it)."""
    lines = ['<robot name="r">', '<link name="base"/>', _URDF_LINK.format("l1") + _URDF_LINK.format("l2"),
             '<joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>'
             f'<mimic joint="{"j0" if mimic_of_j2 == "j0" else "j2"}"/></joint>',
             '<joint name="j2" type="continuous"><parent link="base"/><child link="l2"/><origin xyz="1 0 0"/>'
             f'<axis xyz="0 0 1"/>{"" if mimic_of_j2 == "j0" else "<mimic joint=" + chr(34) + "j1" + chr(34) + "/>"}</joint>',
             _URDF_TRANSMISSION.format("t1", "j9", "a1"),
             _URDF_TRANSMISSION.format("t2", "j2", "j1"),
             "</robot>"]
    f = tmp_path / "bad.urdf"
    f.write_text("\n".join(lines) + "\n")
    r = run_cli("check", f)
    assert r.exit_code == 2
    want = [e.format(f=f) for e in expected] + [f"{f}:6: transmission 't1': transmission 't1' names unknown joint 'j9'"]
    assert r.stderr.splitlines() == want


def test_trajectory_column_of_a_dependent_joint_says_so(run_cli, mech_dir, tmp_path):
    """q:J3 (paper_2dof's bevel shaft, driven through the gears) was only an 'unknown column'."""
    traj = tmp_path / "t.csv"
    traj.write_text("t,q:J1,q:J2,q:J3\n0,0,0,0\n1,0,0,0\n2,0,0,0\n")
    r = run_cli("solve", mech_dir / "paper_2dof.yaml", traj, "-o", tmp_path / "o.csv")
    assert r.exit_code == 2
    assert r.stderr.startswith(f"{traj}:1: column 4 'q:J3': unknown column: 'J3' is not an independent joint (expected t, q:J1, q:J2")


@pytest.mark.parametrize("cell", ["q", "qd", "qdd", "q:", "qd:"])
def test_trajectory_bare_kind_column_is_one_line(run_cli, mech_dir, tmp_path, cell):
    """A header cell 'q' (no ':joint') raised IndexError in the dependent-joint message above
    (found by the long fuzz run): an unknown column, one line, exit 2, no output file."""
    traj = tmp_path / "t.csv"
    traj.write_text(f"t,q:J1,q:J2,{cell}\n0,0,0,0\n1,0,0,0\n2,0,0,0\n")
    r = run_cli("solve", mech_dir / "paper_2dof.yaml", traj, "-o", tmp_path / "o.csv")
    assert r.exit_code == 2
    assert r.stderr == f"{traj}:1: column 4 '{cell}': unknown column (expected t, q:J1, q:J2"  \
        + r.stderr.split("q:J2", 1)[1]
    assert "Traceback" not in r.stderr and r.stderr.count("\n") <= 1
    assert not (tmp_path / "o.csv").exists()


def test_named_columns_names_a_wrong_time_length(arm):
    """A t of the wrong length gave numpy's 'cannot reshape array of size 20 into shape (9,newaxis)'."""
    from gearcli import named_columns

    q = np.zeros((10, 1))
    res = solve(arm, q, q, q)
    with pytest.raises(ValueError, match=r"^t has shape \(9,\), the result has 10 samples$"):
        named_columns(arm, res, np.zeros(9))
    cols = named_columns(arm, res, np.arange(10) * 0.1)
    np.testing.assert_allclose(cols["motor:m"], -2.0 * 9.81 * 0.3, rtol=1e-12)
    assert cols["t"][3] == pytest.approx(0.3)


def test_solve_given_the_mechanism_instead_of_its_analysis_says_so():
    """gearcli.solve(mech, ...) failed with "'Mechanism' object has no attribute 'mech'"."""
    mech = parse_mechanism(ARM)
    q = np.zeros((3, 1))
    with pytest.raises(TypeError, match=r"^expected the Analysis of gearcli.analyse\(mechanism\), got a Mechanism$"):
        solve(mech, q, q, q)


def test_verify_lines_of_a_unitless_check_have_no_stray_spaces(run_cli, mech_dir, tmp_path):
    """A failing safety factor printed 'worst 49.38  against limit 1e+05 ' (an empty unit)."""
    text = (mech_dir.parent / "designs" / "ci_example.yaml").read_text()
    design = tmp_path / "d.yaml"
    design.write_text(text.replace("min_static_safety: 2.0", "min_static_safety: 100000.0")
                      .replace("../mechanisms/", f"{mech_dir}/"))
    r = run_cli("verify", design, "--junit", tmp_path / "r.xml")
    assert r.exit_code == 1
    failed = [line for line in r.stdout.splitlines() if line.startswith("FAILED")]
    assert failed and all("static safety s0: worst " in line for line in failed)
    assert all("  " not in line and line.endswith(" against limit 1e+05") for line in failed)
    junit = (tmp_path / "r.xml").read_text()
    assert "(limit 1e+05), margin" in junit and " )" not in junit and "  (" not in junit


def test_a_manifest_given_to_check_and_a_mechanism_given_to_verify_are_named(run_cli, mech_dir):
    """Each gave schema noise ("unknown key 'cases' (did you mean 'base'?)", four missing keys;
    "Additional properties are not allowed ...")."""
    design = mech_dir.parent / "designs" / "ci_example.yaml"
    r = run_cli("check", design)
    assert r.exit_code == 2
    assert r.stderr.splitlines() == [f"{design}:4: this is a design manifest (it lists cases), not a mechanism "
                                     "file: run gearcli verify on it"]
    mech = mech_dir / "paper_2dof.yaml"
    r = run_cli("verify", mech)
    assert r.exit_code == 2
    assert len(r.stderr.splitlines()) == 1
    assert r.stderr.startswith(f"{mech}:5: this is a mechanism file, not a design manifest: a manifest lists cases")


def test_swapped_solve_arguments_point_at_the_order(run_cli, mech_dir):
    traj = mech_dir / "paper_2dof_traj.csv"
    r = run_cli("solve", traj, mech_dir / "paper_2dof.yaml")
    assert r.exit_code == 2
    assert r.stderr == (f"{traj}:1: a mechanism file must be a YAML mapping "
                        "(a .csv is a trajectory: gearcli solve MECH TRAJ.csv)\n")
