"""Counts in messages agree with their nouns: "1 sample", "1 gear pair", "1 check passed"
(a review found "1 samples", "1 gear pairs" in the CLI's output; "1 motor(s) for 2 degree(s)"
is in test_bad_input.py)."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from gearcli import analyse, parse_mechanism, solve
from gearcli.errors import counted, plural

ROOT = Path(__file__).resolve().parents[1]
MECHS = ROOT / "mechanisms"
ONE_SAMPLE = "t,q:J1,q:J2,qd:J1,qd:J2,qdd:J1,qdd:J2\n0,0.1,0.2,0,0,0,0\n"
TWO_SAMPLES = ONE_SAMPLE + "0.1,0.1,0.2,0,0,0,0\n"


def test_counted_and_plural():
    assert [counted(n, "gear pair") for n in (0, 1, 2)] == ["0 gear pairs", "1 gear pair", "2 gear pairs"]
    assert counted(1, "sample") == "1 sample" and counted(20000, "sample") == "20000 samples"
    assert [plural(n, "is", "are") for n in (1, 2)] == ["is", "are"]


@pytest.mark.parametrize("text, samples", [(ONE_SAMPLE, "1 sample"), (TWO_SAMPLES, "2 samples")])
def test_solve_counts_rows_and_samples(run_cli, tmp_path, text, samples):
    (tmp_path / "t.csv").write_text(text)
    out = tmp_path / "l.csv"
    r = run_cli("solve", MECHS / "paper_2dof.yaml", tmp_path / "t.csv", "-o", out)
    assert r.exit_code == 0, r.stderr
    lines = [ln.strip() for ln in r.stdout.splitlines()]
    assert lines[0] == f"paper_2dof: {samples}"       # the summary table's title
    assert lines[-1] == f"Wrote {samples.replace('sample', 'row')} to {out}"


def test_plot_of_one_column(run_cli, tmp_path):
    (tmp_path / "t.csv").write_text(TWO_SAMPLES)
    assert run_cli("solve", MECHS / "paper_2dof.yaml", tmp_path / "t.csv", "-o", tmp_path / "l.csv").exit_code == 0
    r = run_cli("plot", tmp_path / "l.csv", "motor:motor5", "-o", tmp_path / "f.svg")
    assert r.exit_code == 0 and r.stdout == f"Wrote {tmp_path / 'f.svg'} (1 column)\n", r.stderr


@pytest.mark.parametrize("limit, status, last, md", [
    (1000, 0, "1 of 1 check passed", "1 check passed."),
    (0.001, 1, "0 of 1 check passed; 1 plot in {plots}", "**1 of 1 check failed.**")])
def test_verify_of_one_check(run_cli, tmp_path, limit, status, last, md):
    rows = (MECHS / "paper_2dof_traj.csv").read_text().splitlines(keepends=True)[:21]
    (tmp_path / "t.csv").write_text("".join(rows))
    (tmp_path / "d.yaml").write_text(
        f"name: one\ncases:\n  - name: c\n    mechanism: {MECHS / 'paper_2dof.yaml'}\n    trajectories: [t.csv]\n"
        f"    limits:\n      - {{column: 'motor:motor5', max_abs: {limit}}}\n")
    plots = tmp_path / "plots"
    r = run_cli("verify", tmp_path / "d.yaml", "-j", "1", "--markdown", tmp_path / "r.md",
                *(["--plots", plots] if status else []))
    assert r.exit_code == status, r.stderr
    assert r.stdout.splitlines()[-1] == last.format(plots=plots)
    assert (tmp_path / "r.md").read_text().splitlines()[2] == md


def test_trajectory_row_of_one_cell(run_cli, tmp_path):
    (tmp_path / "t.csv").write_text("t,q:J1,q:J2\n0,0,0\n0.1\n")
    r = run_cli("solve", MECHS / "paper_2dof.yaml", tmp_path / "t.csv", "-o", tmp_path / "l.csv")
    assert r.exit_code == 2
    assert r.stderr == f"{tmp_path / 't.csv'}:3: row has 1 column, the header has 3 (separator ',')\n"


def test_library_messages_of_one_sample():
    from gearcli import named_columns
    from gearcli.io.spline import derivatives, spline_derivatives

    an = analyse(parse_mechanism((MECHS / "paper_2dof.yaml").read_text()))
    q = np.zeros((1, 2))
    res = solve(an, q, q, q)
    with pytest.raises(ValueError, match=r"^t has shape \(2,\), the result has 1 sample$"):
        named_columns(an, res, np.zeros(2))
    q3 = np.zeros((3, 2))
    with pytest.raises(ValueError, match=r"out must be a Result of this mechanism with 3 samples$"):
        solve(an, q3, q3, q3, out=res)
    with pytest.raises(ValueError, match=r"^1 sample: the quintic spline needs at least 6$"):
        spline_derivatives(np.zeros(1), np.zeros((1, 1)))
    with pytest.raises(ValueError, match=r"^1 sample allows a spline of degree 0 < 2$"):
        derivatives(np.zeros(1), np.zeros((1, 1)))


def _exported() -> str:
    from gearcli.io import load_mechanism
    from gearcli.report.urdf_writer import export_urdf

    return export_urdf(load_mechanism(MECHS / "paper_2dof.yaml"))


def test_urdf_warnings_of_one_joint_and_one_transmission(tmp_path):
    from gearcli.io import load_mechanism

    text = _exported()
    assert text.count('<transmission name="') >= 1 and "<dynamics" not in text
    one_plain = re.sub(r'(<transmission name="[^"]*") gearcli:derived="true"', r"\1", text, count=1)
    one_damped = re.sub(r'(<joint name="(J\d)" type="(revolute|continuous)">)', r'\1<dynamics damping="0.5"/>', text,
                        count=1)
    (tmp_path / "a.urdf").write_text(one_plain)
    (tmp_path / "b.urdf").write_text(one_damped)
    warns = load_mechanism(tmp_path / "a.urdf").warnings
    assert any(": 1 <transmission> element is ignored: the gearcli:motor elements define the motors" in w
               for w in warns), warns
    warns = load_mechanism(tmp_path / "b.urdf").warnings
    assert any(re.search(r": <dynamics> damping and friction of joint J\d are ignored", w) for w in warns), warns
