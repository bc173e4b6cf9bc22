"""`gearcli solve`: the CSV contract, agreement with the library, and bad input."""
from schema_keys import schema_keys
import io
import re
import json
from pathlib import Path

import numpy as np
import pytest

from gearcli.dynamics.solve import solve
from gearcli import analyse
from gearcli import load_mechanism
from gearcli.io.yaml_reader import mechanism_schema
from gearcli.report.columns import column_names
from gearcli.io.trajectory import read_trajectory, write_trajectory

ROOT = Path(__file__).resolve().parents[1]
BUNDLED = [("paper_2dof", "paper_2dof_traj.csv"), ("bendix_wrist", "bendix_wrist_traj.csv")]


def load_csv(path):
    text = Path(path).read_text()
    header = text.splitlines()[0].split(",")
    return header, np.loadtxt(io.StringIO(text), delimiter=",", skiprows=1, ndmin=2)


@pytest.mark.parametrize("name, traj", BUNDLED)
def test_solve_writes_the_documented_columns_and_matches_the_library(run_cli, mech_dir, tmp_path, name, traj):
    mech, tpath = mech_dir / f"{name}.yaml", mech_dir / traj
    out = tmp_path / "loads.csv"
    r = run_cli("solve", mech, tpath, "-o", out, "--verify")
    assert r.exit_code == 0, r.stderr
    assert "peak" in r.stdout and "RMS" in r.stdout
    resid = float(r.stdout.split("residual (relative):")[1].split()[0])
    assert resid < 1e-9
    an = analyse(load_mechanism(mech))
    header, data = load_csv(out)
    assert header == column_names(an)
    tr = read_trajectory(tpath, an.independent_names)
    assert data.shape[0] == len(tr.t)
    res = solve(an, tr.q, tr.qd, tr.qdd)
    col = {h: i for i, h in enumerate(header)}
    for mi, m in enumerate(an.mech.motors):
        assert np.allclose(data[:, col[f"motor:{m.name}"]], res.motor[:, mi], rtol=1e-8, atol=1e-9)
    jt = an.mech.joints[0].name
    assert np.allclose(data[:, col[f"joint:{jt}:fx"]], res.joint[:, 0, 0], rtol=1e-8, atol=1e-8)
    assert np.allclose(data[:, col[f"joint:{jt}:radial"]], np.hypot(res.joint[:, 0, 0], res.joint[:, 0, 1]),
                       rtol=1e-8, atol=1e-8)
    assert np.all(data[:, [i for h, i in col.items() if h.endswith(":mz")]] == 0)


@pytest.mark.parametrize("name, traj", BUNDLED)
def test_full_method_gives_the_same_csv(run_cli, mech_dir, tmp_path, name, traj):
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert run_cli("solve", mech_dir / f"{name}.yaml", mech_dir / traj, "-o", a).exit_code == 0
    assert run_cli("solve", mech_dir / f"{name}.yaml", mech_dir / traj, "-o", b, "--method", "full").exit_code == 0
    _, x = load_csv(a)
    _, y = load_csv(b)
    assert np.allclose(x, y, rtol=1e-8, atol=1e-9 * np.abs(x).max())


def test_degrees_flag_and_stdout(run_cli, mech_dir, tmp_path):
    t = np.linspace(0, 1, 301)
    q = np.column_stack([np.sin(3 * t), np.cos(2 * t)])
    rad, deg = tmp_path / "rad.csv", tmp_path / "deg.csv"
    write_trajectory(rad, ["J1", "J2"], t, q)
    write_trajectory(deg, ["J1", "J2"], t, np.rad2deg(q))
    r1 = run_cli("solve", mech_dir / "paper_2dof.yaml", rad, "-o", "-")
    r2 = run_cli("solve", mech_dir / "paper_2dof.yaml", deg, "-o", "-", "--degrees")
    assert r1.exit_code == 0 and r2.exit_code == 0
    x = np.loadtxt(io.StringIO(r1.stdout), delimiter=",", skiprows=1)
    y = np.loadtxt(io.StringIO(r2.stdout), delimiter=",", skiprows=1)
    assert x.shape == (301, len(r1.stdout.splitlines()[0].split(",")))
    assert np.allclose(x, y, rtol=1e-7, atol=1e-7)
    assert "peak" in r1.stderr   # summary goes to stderr when the CSV goes to stdout


def test_chunking_does_not_change_the_output(run_cli, mech_dir, tmp_path):
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    traj = mech_dir / "paper_2dof_traj.csv"
    assert run_cli("solve", mech_dir / "paper_2dof.yaml", traj, "-o", a).exit_code == 0
    assert run_cli("solve", mech_dir / "paper_2dof.yaml", traj, "-o", b, "--chunk", "300").exit_code == 0
    _, x = load_csv(a)
    _, y = load_csv(b)
    assert np.allclose(x, y, rtol=1e-7, atol=1e-8 * np.abs(x).max())


@pytest.mark.parametrize("text, expect", [
    ("t,q:J1,q:J2\n0,0,0\n0.001,zz,0\n", "bad.csv:3: column 2 'q:J1': not a number"),
    ("t,q:J1,q:J2\n0,0,0\n0.001,0,nan\n", "bad.csv:3: column 3 'q:J2'"),
    ("t,q:J1,q:J2\n0,0,0\n-1,0,0\n", "bad.csv:3: column 1 't'"),
    ("t,q:J1\n0,0\n", "bad.csv:1: missing column 'q:J2'"),
    ("t,q:J1,q:J2,q:J3\n0,0,0,0\n", "bad.csv:1: column 4 'q:J3': unknown column"),
])
def test_bad_trajectory_one_line_exit_2_and_no_output(run_cli, mech_dir, tmp_path, text, expect):
    bad = tmp_path / "bad.csv"
    bad.write_text(text)
    out = tmp_path / "out.csv"
    out.write_text("previous contents\n")
    r = run_cli("solve", mech_dir / "paper_2dof.yaml", bad, "-o", out)
    assert r.exit_code == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and expect in lines[0], r.stderr
    assert "Traceback" not in r.stderr
    assert out.read_text() == "previous contents\n"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out.csv")]  # no temp left


def test_bad_mechanism_and_missing_files(run_cli, mech_dir, tmp_path):
    r = run_cli("solve", tmp_path / "nope.yaml", mech_dir / "paper_2dof_traj.csv", "-o", tmp_path / "o.csv")
    assert r.exit_code == 2 and "nope.yaml" in r.stderr and "Traceback" not in r.stderr
    r = run_cli("solve", mech_dir / "paper_2dof.yaml", tmp_path / "nope.csv", "-o", tmp_path / "o.csv")
    assert r.exit_code == 2 and "nope.csv" in r.stderr
    assert not (tmp_path / "o.csv").exists()
    r = run_cli("solve", mech_dir / "paper_2dof.yaml", mech_dir / "paper_2dof_traj.csv", "--method", "magic")
    assert r.exit_code == 2 and "--method" in r.stderr


def test_the_references_document_every_schema_key_and_output_column():
    """Every key of the mechanism schema has an entry in the generated reference
    (docs/reference/mechanism.md) and is named in the guide (mechanism-files.md, the drive
    elements' and losses' pages); every output column of the paper's arm is in the column
    reference (docs/reference/outputs.md)."""
    docs = ROOT / "docs"
    generated = (docs / "reference" / "mechanism.md").read_text()
    guide = "".join((docs / p).read_text() for p in ("reference/mechanism-files.md", "concepts/losses.md",
                                                     "concepts/drive-elements.md", "how-to/planetary.md"))
    schema = mechanism_schema()
    keys = schema_keys(schema)
    missing = sorted({k for k in keys if not re.search(rf"^\| `([\w.]+\.)?{k}`( \(required\))? \|", generated, re.M)})
    assert not missing, f"docs/reference/mechanism.md lacks entries for {missing} (run python docs/gen_reference.py)"
    missing = sorted({k for k in keys if not re.search(rf"`[^`\n]*\b{k}\b[^`\n]*`", guide)})
    assert not missing, f"the mechanism guide lacks {missing}"
    readme = (docs / "reference" / "outputs.md").read_text()
    an = analyse(load_mechanism(ROOT / "mechanisms" / "paper_2dof.yaml"))
    for c in column_names(an):
        parts = c.split(":")
        if len(parts) == 1:
            assert f"`{c}`" in readme
            continue
        assert f"`{parts[0]}:<" in readme, c
        if len(parts) > 2:
            assert f"`{parts[-1]}`" in readme or f":{parts[-1]}`" in readme, c


def test_degrees_leaves_prismatic_columns_in_metres(run_cli, mech_dir, tmp_path):
    names = ["shoulder", "elbow", "finger_left_joint"]          # the last one slides (m)
    t = np.linspace(0, 1, 201)
    q = np.column_stack([0.5 * np.sin(3 * t), 0.3 * np.cos(2 * t), 0.01 + 0.004 * np.sin(5 * t)])
    deg = q.copy()
    deg[:, :2] = np.rad2deg(q[:, :2])
    rad_p, deg_p = tmp_path / "rad.csv", tmp_path / "deg.csv"
    write_trajectory(rad_p, names, t, q)
    write_trajectory(deg_p, names, t, deg)
    r1 = run_cli("solve", mech_dir / "geared_arm.urdf", rad_p, "-o", "-")
    r2 = run_cli("solve", mech_dir / "geared_arm.urdf", deg_p, "-o", "-", "--degrees")
    assert r1.exit_code == 0 and r2.exit_code == 0, r1.stderr + r2.stderr
    x = np.loadtxt(io.StringIO(r1.stdout), delimiter=",", skiprows=1)
    y = np.loadtxt(io.StringIO(r2.stdout), delimiter=",", skiprows=1)
    assert np.allclose(x, y, rtol=1e-7, atol=1e-7 * np.abs(x).max())


def test_readme_library_example_runs(monkeypatch):
    """The library page's first Python example runs as written, and its named columns match."""
    readme = (ROOT / "docs" / "reference" / "library.md").read_text()
    block = readme.split("```python", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(ROOT)
    env: dict = {}
    exec(compile(block, "library.md", "exec"), env)   # noqa: S102 (our own page)
    res, an, cols = env["res"], env["an"], env["cols"]
    assert res.residual < 1e-9
    assert list(cols) == column_names(an)
    assert np.array_equal(cols["motor:motor5"], res.motor[:, 1])
    assert np.allclose(cols["joint:J1:bending"], np.hypot(res.joint[:, 0, 3], res.joint[:, 0, 4]))


def test_summary_states_the_backend_and_auto_says_why_numpy(run_cli, mech_dir, tmp_path, monkeypatch):
    """The summary's Backend line names the path that ran; "auto" on a mechanism the kernel
    refuses (planetary_5p with 18 planets: 36 signed meshes in a block) solves with numpy and
    prints one notice line on stderr; the first-call rule (an empty disk cache, 2,001 rows)
    is stated in the summary only."""
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path / "cache"))
    out = tmp_path / "loads.csv"
    traj = mech_dir / "bendix_wrist_traj.csv"
    for backend, line in (("llvm", "Backend: llvm"), ("numpy", "Backend: numpy")):
        r = run_cli("solve", mech_dir / "bendix_wrist.yaml", traj, "-o", out, "--backend", backend)
        assert r.exit_code == 0 and line in r.stdout.splitlines() and r.stderr == "", r.stderr
    r = run_cli("solve", mech_dir / "paper_2dof.yaml", mech_dir / "paper_2dof_traj.csv", "-o", out)
    assert r.exit_code == 0 and r.stderr == ""
    assert ("Backend: numpy (auto: first-call rule: fewer than 5,000 samples, and the kernel is neither "
            "compiled nor in the disk cache)") in r.stdout.splitlines()
    many = tmp_path / "planetary_18p.yaml"
    many.write_text((mech_dir / "planetary_5p.yaml").read_text().replace("planets: 5", "planets: 18"))
    r = run_cli("solve", many, mech_dir / "planetary_3p_traj.csv", "-o", out)
    reason = "a block has more than 32 signed meshes, or a singular separating-force-free matrix"
    assert r.exit_code == 0 and f"Backend: numpy (auto: {reason})" in r.stdout.splitlines()
    assert r.stderr.splitlines() == [f"notice: solved with numpy, not the llvm kernel: {reason}"]


def test_an_unknown_backend_is_one_line_exit_2(run_cli, mech_dir, tmp_path):
    """``--backend kernel`` (the numba kernel, retired in issue 18; its remains removed in
    issue 39) is an unknown backend: one line, nothing written."""
    out = tmp_path / "loads.csv"
    r = run_cli("solve", mech_dir / "bendix_wrist.yaml", mech_dir / "bendix_wrist_traj.csv", "-o", out,
                "--backend", "kernel")
    assert r.exit_code == 2 and not out.exists()
    assert r.stderr.splitlines() == ["--backend: expected one of auto, llvm, numpy, got 'kernel'"]
