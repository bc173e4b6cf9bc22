"""Hostile trajectories and output faults: exit 2 with one line naming file, place and
reason; no output file, no temporary file, inputs unchanged (issue 8)."""
from __future__ import annotations

import errno
import io
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from gearcli.io.trajectory import read_trajectory, write_trajectory

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
HEADER = "t,q:J1,q:J2\n"


@pytest.fixture
def work(tmp_path, mech_dir):
    """A directory holding a copy of paper_2dof.yaml (the mechanism) and nothing else."""
    shutil.copy(mech_dir / "paper_2dof.yaml", tmp_path / "mech.yaml")
    return tmp_path


def snapshot(d: Path) -> dict:
    return {p.name: (p.read_bytes() if p.is_file() and not p.is_symlink() else os.readlink(p))
            for p in d.iterdir()}


def one_line_error(r, *parts):
    """Exit 2, exactly one stderr line containing every part, no traceback."""
    assert r.exit_code == 2, (r.exit_code, r.stdout, r.stderr)
    lines = r.stderr.strip("\n").splitlines()
    assert len(lines) == 1, r.stderr
    for p in parts:
        assert p in lines[0], (p, lines[0])
    assert "Traceback" not in r.stderr + r.stdout
    return lines[0]


def solve_refused(run_cli, work, text: str | bytes, *parts, extra=()):
    """Solve a trajectory with ``text``; assert the one-line error and that nothing was
    written (the directory is as before)."""
    traj = work / "traj.csv"
    (traj.write_bytes if isinstance(text, bytes) else traj.write_text)(text)
    before = snapshot(work)
    r = run_cli("solve", work / "mech.yaml", traj, "-o", work / "out.csv", *extra)
    line = one_line_error(r, "traj.csv", *parts)
    assert snapshot(work) == before
    return line


def rows(t, q1, q2=None):
    q2 = np.zeros_like(t) if q2 is None else q2
    return HEADER + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, b, c in zip(t, q1, q2))


SMOOTH_T = np.linspace(0, 0.2, 41)
SMOOTH = rows(SMOOTH_T, np.sin(5 * SMOOTH_T), 0.3 * np.cos(3 * SMOOTH_T))


# --- trajectory CSV ---------------------------------------------------------------------
@pytest.mark.parametrize("text, parts", [
    (HEADER.encode() + b"0,0,0\n0.1,0\xff,0\n0.2,1,0\n", (":3: character 6:", "byte 0xff is not UTF-8")),
    (b"t,q:J1,q:\xe9\n0,0,0\n", (":1: character 10:", "byte 0xe9 is not UTF-8")),
    (HEADER + "0,0,0\n\n0.1,0,0\n0.2,abc,0\n", (":5: column 2 'q:J1':", "not a number: 'abc'")),
    (HEADER + "0,0,0\n0.1,0,0\n0.2,1_0,0\n", (":4: column 2 'q:J1':", "not a number: '1_0'")),
    (HEADER + "0,0,0\n0.1,,0\n0.2,1,0\n", (":3: column 2 'q:J1':", "empty cell")),
    ("t;q:J1;q:J2\n0;0;0\n0.1;1,5;0\n", (":3: column 2 'q:J1': not a number: '1,5' looks like a decimal comma: "
                                         "write 1.5",)),
    ("t\tq:J1\tq:J2\n0\t0\t0\n0,1\t-1,5e-3\t0\n", (":3: column 1 't': not a number: '0,1' looks like a decimal "
                                                 "comma: write 0.1",)),
    (HEADER + "0,0,0\n0,1,0,5,0,25\n", (":3: row has 6 columns, the header has 3 (separator ','): '0,1' looks like "
                                        "a decimal comma: write 0.1",)),
    (HEADER + "0,0,0\n1,0,5,0\n", (":3: row has 4 columns, the header has 3 (separator ','): '1,0' looks like "
                                   "a decimal comma: write 1.0",)),
    ("t q:J1 q:J2\n0 0 0\n", (":1: column 1 't q:J1 q:J2':", "unknown column", "separated by")),
    (HEADER + "0,0,0\n0.1,0,0\n0.2,0,0,\n", (":4:", "4 columns, the header has 3")),
    (HEADER + "0,0,0\n5e-324,0,0\n1,0,0\n", (":3: column 1 't':", "time step 4.94e-324 s", "minimum 1e-09 s")),
    (HEADER + "0,0,0\n1e-12,0,0\n1,0,0\n", (":3: column 1 't':", "time step 1e-12 s")),
    (HEADER + "0,0,0\n1e-300,0,0\n1,0,0\n", (":3: column 1 't':", "below the minimum")),
    (HEADER + "-1e300,0,0\n0,0,0\n1,0,0\n", (":2: column 1 't':", "value -1e300 is out of range")),
    (HEADER + "0,0,0\n1,1e308,0\n2,0,0\n", (":3: column 2 'q:J1':", "out of range")),
    (HEADER + "0,0,0\n1,0,1e200\n2,0,0\n", (":3: column 3 'q:J2':", "out of range")),
    (HEADER + "0,0,0\n1,1e999,0\n2,0,0\n", (":3: column 2 'q:J1':", "'1e999' is not a finite number")),
    (HEADER + "0,0,0\n1,-inf,0\n2,0,0\n", (":3: column 2 'q:J1':", "not a finite number")),
    (HEADER + "0,0,0\n", ("traj.csv: 1 sample with positions only", "at least 3 samples")),
    (HEADER + "0,0,0\n1,1,0\n", ("traj.csv: 2 samples with positions only", "at least 3 samples")),
    ("t,q:J1,q:J2,qd:J1,qd:J2\n0,0,0,0,0\n", ("1 sample with no qdd: columns", "at least 2 samples")),
    ("\ufefft,q:J1\n0,0\n", (":1:", "missing column 'q:J2'")),
    ("t,q:J1,q:J2\x00\n0,0,0\n", (":1: column 3 'q:J2\\x00':", "unknown column")),
    ("", (":1:", "empty file")),
])
def test_bad_trajectory_is_one_line_and_writes_nothing(run_cli, work, text, parts):
    line = solve_refused(run_cli, work, text, *parts)
    assert "missing column 't'" not in line


@pytest.mark.parametrize("row", ["0.2,0,0,", "0.2,0,0,0", "1,x,5,0", "1,2,3,4,5,6,7", "0,5,0,5e"])
def test_extra_cells_that_are_no_decimal_comma_are_not_called_one(run_cli, work, row):
    """A row with a '.' (its writer uses decimal points) or a cell that is not digits, or
    too few pairs of an integer and digits for its extra cells: no decimal-comma hint."""
    line = solve_refused(run_cli, work, HEADER + "0,0,0\n" + row + "\n", ":3:")
    assert "decimal comma" not in line


def test_degrees_with_huge_values_is_refused(run_cli, work):
    solve_refused(run_cli, work, HEADER + "0,0,0\n1,1e308,0\n2,0,0\n", ":3: column 2 'q:J1':",
                  "out of range", extra=("--degrees",))
    # 1e13 deg = 1.7e11 rad is within range, 1e15 deg = 1.7e13 rad is not: the limit is in SI
    solve_refused(run_cli, work, HEADER + "0,0,0\n1,1e15,0\n2,0,0\n", ":3:", "out of range", extra=("--degrees",))


def test_long_line_is_refused(run_cli, work):
    solve_refused(run_cli, work, HEADER + "0,0,0\n1," + "1" * (1 << 20) + ",0\n", ":3:", "line longer than")


def test_a_directory_as_trajectory_is_refused(run_cli, work):
    (work / "d.csv").mkdir()
    r = run_cli("solve", work / "mech.yaml", work / "d.csv", "-o", work / "out.csv")
    one_line_error(r, "d.csv", "not a regular file")


def load_out(path_or_text) -> np.ndarray:
    src = io.StringIO(path_or_text) if isinstance(path_or_text, str) else path_or_text
    return np.loadtxt(src, delimiter=",", skiprows=1)


@pytest.mark.parametrize("variant", ["bom", "semicolon", "tab", "quoted", "crlf", "spaces"])
def test_accepted_csv_dialects_give_the_same_loads(run_cli, work, variant):
    plain = work / "plain.csv"
    plain.write_text(SMOOTH)
    text = SMOOTH
    if variant == "bom":
        text = "\ufeff" + text
    elif variant == "semicolon":
        text = text.replace(",", ";")
    elif variant == "tab":
        text = text.replace(",", "\t")
    elif variant == "quoted":
        head, body = text.split("\n", 1)
        text = ",".join(f'"{h}"' for h in head.split(",")) + "\n" + body.replace("\n0", '\n"0"', 3)
    elif variant == "crlf":
        text = text.replace("\n", "\r\n")
    elif variant == "spaces":
        text = text.replace(",", " , ")
    other = work / "other.csv"
    other.write_bytes(text.encode("utf-8"))
    r1 = run_cli("solve", work / "mech.yaml", plain, "-o", work / "a.csv")
    r2 = run_cli("solve", work / "mech.yaml", other, "-o", work / "b.csv")
    assert r1.exit_code == 0 and r2.exit_code == 0, r2.stderr
    assert np.array_equal(load_out(work / "a.csv"), load_out(work / "b.csv"))


@pytest.mark.parametrize("n", [3, 4, 5])
def test_short_trajectories_use_the_highest_spline_degree(tmp_path, n):
    """n samples of a polynomial of degree n - 1 give its exact rates and accelerations."""
    t = np.array([0.0, 0.1, 0.25, 0.3, 0.45])[:n]
    c = np.array([0.2, -1.0, 3.0, 2.0, -4.0])[:n]          # q = sum c_i t^i
    q = sum(ci * t ** i for i, ci in enumerate(c))
    qd = sum(i * ci * t ** (i - 1) for i, ci in enumerate(c) if i >= 1)
    qdd = sum(i * (i - 1) * ci * t ** (i - 2) for i, ci in enumerate(c) if i >= 2) + 0 * t
    p = tmp_path / "short.csv"
    write_trajectory(p, ["J1", "J2"], t, np.column_stack([q, 0.5 * q]))
    tr = read_trajectory(p, ["J1", "J2"])
    assert np.allclose(tr.qd[:, 0], qd, rtol=0, atol=1e-9)
    assert np.allclose(tr.qdd[:, 0], qdd, rtol=0, atol=1e-8)
    assert np.allclose(tr.qd[:, 1], 0.5 * qd, rtol=0, atol=1e-9)


def test_two_samples_with_rates_derive_accelerations(tmp_path):
    p = tmp_path / "two.csv"
    write_trajectory(p, ["J1", "J2"], np.array([0.0, 0.5]), np.zeros((2, 2)),
                     qd=np.array([[1.0, 0.0], [2.0, -1.0]]))
    tr = read_trajectory(p, ["J1", "J2"])
    assert np.allclose(tr.qdd, [[2.0, -2.0], [2.0, -2.0]])   # linear spline of the rates


def test_line_numbers_of_samples_skip_blank_lines(tmp_path):
    p = tmp_path / "blank.csv"
    p.write_text(HEADER + "0,0,0\n\n0.1,0,0\n\n\n0.2,0,0\n")
    assert list(read_trajectory(p, ["J1", "J2"]).line) == [2, 4, 7]


def test_trajectory_errors_carry_an_issue(tmp_path):
    from gearcli.errors import TrajectoryError

    p = tmp_path / "bad.csv"
    p.write_text(HEADER + "0,0,0\n0.1,x,0\n")
    with pytest.raises(TrajectoryError) as err:
        read_trajectory(p, ["J1", "J2"])
    issue = err.value.issue
    assert (issue.file, issue.line, issue.path) == (str(p), 3, "column 2 'q:J1'")
    assert issue.message == "not a number: 'x'"


# --- outputs ----------------------------------------------------------------------------
def test_output_onto_an_input_is_refused(run_cli, work):
    traj = work / "traj.csv"
    traj.write_text(SMOOTH)
    os.symlink("traj.csv", work / "link.csv")
    os.link(traj, work / "hard.csv")
    before = snapshot(work)
    mech = work / "mech.yaml"
    for target in (traj, f"{work}/./traj.csv", mech, work / "link.csv", work / "hard.csv"):
        r = run_cli("solve", mech, traj, "-o", target)
        one_line_error(r, ": -o: is the input file", "choose another output file name")
    r = run_cli("export", mech, "-o", mech)
    one_line_error(r, "mech.yaml: -o: is the input file")
    cwd = os.getcwd()
    os.chdir(work)
    try:
        r = run_cli("solve", "mech.yaml", "traj.csv", "-o", "./traj.csv")
        one_line_error(r, "./traj.csv: -o: is the input file 'traj.csv'")
    finally:
        os.chdir(cwd)
    assert snapshot(work) == before


@pytest.mark.parametrize("target, parts", [
    ("", ("-o: empty file name",)),
    ("{work}", (": -o: is a directory",)),
    ("/dev/null", ("/dev/null: -o: is not a regular file",)),
    ("{work}/missing/out.{ext}", ("out.{ext}: -o: directory", "missing' does not exist")),
])
@pytest.mark.parametrize("command", ["solve", "export"])
def test_bad_output_targets(run_cli, work, target, parts, command):
    (work / "traj.csv").write_text(SMOOTH)
    before = snapshot(work)
    args = [work / "mech.yaml"] + ([work / "traj.csv"] if command == "solve" else [])
    ext = "csv" if command == "solve" else "urdf"
    r = run_cli(command, *args, "-o", target.format(work=work, ext=ext))
    one_line_error(r, *(p.format(ext=ext) for p in parts))
    assert snapshot(work) == before
    assert os.path.exists("/dev/null") and not os.path.isfile("/dev/null")


@pytest.mark.parametrize("suffix", ["/", "/.", "//"])
def test_output_name_ending_in_a_slash_is_refused(run_cli, work, suffix):
    """``-o out.csv/`` names a directory: refused by every command with -o (the system
    would strip the '/' and write out.csv), one line, exit 2, nothing written."""
    (work / "traj.csv").write_text(SMOOTH)
    assert run_cli("solve", work / "mech.yaml", work / "traj.csv", "-o", work / "loads.csv").exit_code == 0
    before = snapshot(work)
    for args, name in [(("solve", work / "mech.yaml", work / "traj.csv"), "out.csv"),
                       (("solve", work / "mech.yaml", work / "traj.csv"), "out.parquet"),
                       (("export", work / "mech.yaml"), "out.urdf"),
                       (("plot", work / "loads.csv", "motor:*"), "out.png")]:
        target = f"{work}/{name}{suffix}"
        r = run_cli(*args, "-o", target)
        assert one_line_error(r) == f"{target}: -o: names a directory (ends with '/'); give a file name"
        assert snapshot(work) == before


def test_output_through_a_symlink_writes_its_target_and_keeps_the_link(run_cli, work):
    (work / "traj.csv").write_text(SMOOTH)
    os.symlink("real.csv", work / "link.csv")            # dangling: real.csv does not exist yet
    r = run_cli("solve", work / "mech.yaml", work / "traj.csv", "-o", work / "link.csv")
    assert r.exit_code == 0, r.stderr
    assert (work / "link.csv").is_symlink() and os.readlink(work / "link.csv") == "real.csv"
    assert load_out(work / "real.csv").shape[0] == 41


@pytest.mark.parametrize("no_tmpfile", [False, True])
@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_new_outputs_honour_the_umask(run_cli, work, monkeypatch, mask, no_tmpfile):
    if no_tmpfile:
        monkeypatch.delattr(os, "O_TMPFILE", raising=False)
    (work / "traj.csv").write_text(SMOOTH)
    old = os.umask(mask)
    try:
        r1 = run_cli("solve", work / "mech.yaml", work / "traj.csv", "-o", work / "out.csv")
        r2 = run_cli("export", work / "mech.yaml", "-o", work / "out.urdf")
    finally:
        os.umask(old)
    assert r1.exit_code == 0 and r2.exit_code == 0, r1.stderr + r2.stderr
    for name in ("out.csv", "out.urdf"):
        assert (work / name).stat().st_mode & 0o777 == 0o666 & ~mask
    assert sorted(p.name for p in work.iterdir()) == ["mech.yaml", "out.csv", "out.urdf", "traj.csv"]


def test_unwritable_directory_is_refused(run_cli, work, monkeypatch):
    (work / "traj.csv").write_text(SMOOTH)
    ro = work / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    real_access = os.access
    if os.geteuid() == 0:   # root writes anywhere: simulate what a user sees
        monkeypatch.setattr(os, "access", lambda p, m, **k: False if str(p) == str(ro) else real_access(p, m, **k))
    try:
        for cmd, name in ((("solve", work / "mech.yaml", work / "traj.csv"), "out.csv"),
                          (("export", work / "mech.yaml"), "out.urdf")):
            r = run_cli(*cmd, "-o", ro / name)
            one_line_error(r, f"{name}: -o: directory", "is not writable")
        assert list(ro.iterdir()) == []
    finally:
        ro.chmod(0o755)


class FullDisk(io.TextIOWrapper):
    """A file whose writes fail with ENOSPC after ``limit`` characters."""

    limit = 5000

    def write(self, s):
        FullDisk.limit -= len(s)
        if FullDisk.limit < 0:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return super().write(s)


@pytest.mark.parametrize("no_tmpfile", [False, True])
@pytest.mark.parametrize("command", ["solve", "export"])
def test_full_disk_leaves_nothing(run_cli, work, monkeypatch, no_tmpfile, command):
    import gearcli.io.output as output

    if no_tmpfile:
        monkeypatch.delattr(os, "O_TMPFILE", raising=False)
    real_fdopen = os.fdopen

    def fdopen(fd, mode="r", **kw):
        f = real_fdopen(fd, mode + "b" if "b" not in mode else mode)
        FullDisk.limit = 5000 if command == "solve" else 100
        return FullDisk(f, encoding=kw.get("encoding"), newline=kw.get("newline"), write_through=True)

    monkeypatch.setattr(output.os, "fdopen", fdopen)
    (work / "traj.csv").write_text(SMOOTH)
    name = "out.csv" if command == "solve" else "out.urdf"   # the format comes from the extension
    (work / name).write_text("previous\n")
    before = snapshot(work)
    args = [work / "mech.yaml"] + ([work / "traj.csv"] if command == "solve" else [])
    r = run_cli(command, *args, "-o", work / name)
    one_line_error(r, f"{name}: -o: cannot write: No space left on device")
    assert snapshot(work) == before


def test_failed_rename_removes_the_temporary_file(work, monkeypatch):
    import gearcli.io.output as output

    monkeypatch.delattr(os, "O_TMPFILE", raising=False)

    def fail(*a, **k):
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    monkeypatch.setattr(output.os, "replace", fail)
    with pytest.raises(output.OutputError, match="cannot write: Input/output error"):
        output.write_text(work / "x.txt", "data")
    assert sorted(p.name for p in work.iterdir()) == ["mech.yaml"]


def test_interrupt_and_sigterm_mid_solve_leave_nothing(run_cli, work, monkeypatch):
    import gearcli.pipeline as pipeline

    (work / "traj.csv").write_text(SMOOTH)
    before = snapshot(work)
    real = pipeline.solve
    for no_tmpfile in (False, True):
        if no_tmpfile:
            monkeypatch.delattr(os, "O_TMPFILE", raising=False)
        monkeypatch.setattr(pipeline, "solve", lambda *a, **k: (_ for _ in ()).throw(KeyboardInterrupt()))
        r = run_cli("solve", work / "mech.yaml", work / "traj.csv", "-o", work / "out.csv")
        assert r.exit_code == 130 and r.stderr.strip() == "gearcli: interrupted", r.stderr
        assert snapshot(work) == before

        def term(*a, **k):
            res = real(*a, **k)
            os.kill(os.getpid(), signal.SIGTERM)
            return res
        monkeypatch.setattr(pipeline, "solve", term)
        r = run_cli("solve", work / "mech.yaml", work / "traj.csv", "-o", work / "out.csv")
        assert r.exit_code == 143 and r.stderr.strip() == "gearcli: terminated (SIGTERM)", r.stderr
        assert snapshot(work) == before
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL or callable(signal.getsignal(signal.SIGTERM))


def gearcli_cmd(*args) -> list[str]:
    return [sys.executable, "-c", "import sys; from gearcli.cli import app; sys.argv[0] = 'gearcli'; app()",
            *map(str, args)]


def env():
    return dict(os.environ, PYTHONPATH=str(SRC))


@pytest.mark.skipif(not hasattr(os, "O_TMPFILE"), reason="O_TMPFILE is Linux-only")
def test_sigkill_mid_write_leaves_no_file(work):
    t = np.arange(100_000) * 1e-3
    write_trajectory(work / "traj.csv", ["J1", "J2"], t, np.column_stack([np.sin(t), np.cos(t)]))
    before = snapshot(work)
    p = subprocess.Popen(gearcli_cmd("solve", work / "mech.yaml", work / "traj.csv", "-o", work / "out.csv",
                                     "--chunk", "2000"),
                         env=env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        writing = False
        while time.monotonic() < deadline and p.poll() is None and not writing:
            try:
                fds = [os.readlink(f"/proc/{p.pid}/fd/{fd}") for fd in os.listdir(f"/proc/{p.pid}/fd")]
            except OSError:
                fds = []
            writing = any(f.startswith(str(work)) and "deleted" in f for f in fds)
            time.sleep(0.01)
        assert writing, "the solve never opened its anonymous output file"
        time.sleep(0.2)
        p.kill()
    finally:
        p.wait()
    assert snapshot(work) == before


@pytest.mark.parametrize("args", [("check",), ("graph", "--json"), ("solve", "TRAJ", "-o", "-")])
def test_full_stdout_is_one_line_exit_2(mech_dir, args):
    args = [str(mech_dir / "paper_2dof_traj.csv") if a == "TRAJ" else a for a in args]
    with open("/dev/full", "w") as full:
        r = subprocess.run(gearcli_cmd(args[0], mech_dir / "paper_2dof.yaml", *args[1:]), env=env(),
                           stdout=full, stderr=subprocess.PIPE, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    assert r.stderr.strip().splitlines() == ["stdout: cannot write: No space left on device"], r.stderr


@pytest.mark.parametrize("args, stdout_full, status", [
    (("check", "BAD"), False, 2), (("graph", "--json", "BAD"), False, 2),
    (("solve", "MECH", "BADTRAJ", "-o", "OUT"), False, 2), (("export", "BAD", "-o", "OUT.urdf"), False, 2),
    (("check", "MECH"), False, 0), (("check", "MECH"), True, 2), (("check", "BAD"), True, 2)])
def test_full_stderr_keeps_the_exit_status(work, args, stdout_full, status):
    """``gearcli check bad.yaml 2>/dev/full`` exited 1 (the error printer's ENOSPC escaped):
    bad input is status 2 whatever happens to stderr, and nothing is written."""
    (work / "bad.yaml").write_text("links: [\n")
    (work / "traj.csv").write_text("t,q:J1,q:J2\n0,0,oops\n")
    names = {"BAD": work / "bad.yaml", "MECH": work / "mech.yaml", "BADTRAJ": work / "traj.csv",
             "OUT": work / "out.csv", "OUT.urdf": work / "out.urdf"}
    before = snapshot(work)
    with open("/dev/full", "w") as full:
        r = subprocess.run(gearcli_cmd(*[names.get(a, a) for a in args]), env=env(), timeout=120,
                           stdout=full if stdout_full else subprocess.PIPE, stderr=full, text=True)
    assert r.returncode == status
    assert snapshot(work) == before
    if not stdout_full:
        assert r.stdout == ("" if status else f"{work / 'mech.yaml'}: OK (2 dof, 6 links, 3 gear pairs, 2 motors)\n")


def test_full_stderr_does_not_fail_a_solve_to_stdout(mech_dir):
    """``solve ... -o - 2>/dev/full``: the table went whole to stdout, only the summary (on
    stderr) was lost; that exited 2 with 'stdout: cannot write' (unseen), now 0."""
    args = gearcli_cmd("solve", mech_dir / "paper_2dof.yaml", mech_dir / "paper_2dof_traj.csv", "-o", "-")
    ok = subprocess.run(args, env=env(), capture_output=True, text=True, timeout=120)
    assert ok.returncode == 0 and "paper_2dof: 2001 samples" in ok.stderr, ok.stderr
    with open("/dev/full", "w") as full:
        r = subprocess.run(args, env=env(), stdout=subprocess.PIPE, stderr=full, text=True, timeout=120)
    assert r.returncode == 0
    assert r.stdout == ok.stdout and r.stdout.count("\n") == 2002


class UnwritableStream(io.TextIOBase):
    """A stderr whose every write and flush fails (ENOSPC); the lines tried are kept."""

    def __init__(self):
        self.tried = []

    def write(self, s):
        self.tried.append(s)
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    def flush(self):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_unwritable_stderr_is_no_traceback(work, monkeypatch):
    """In-process: the failing error printer neither escapes as an exception nor changes
    the status; the one line was tried."""
    from gearcli.cli import app

    (work / "bad.yaml").write_text("links: [\n")
    err = UnwritableStream()
    monkeypatch.setattr(sys, "stderr", err)
    with pytest.raises(SystemExit) as exc:
        app(["check", str(work / "bad.yaml")], prog_name="gearcli")
    assert exc.value.code == 2
    tried = "".join(t.decode() if isinstance(t, bytes) else t for t in err.tried)
    assert tried.startswith(f"{work / 'bad.yaml'}:2: ") and tried.count("\n") == 1, tried


def test_broken_pipe_exits_quietly(mech_dir):
    p = subprocess.Popen(gearcli_cmd("solve", mech_dir / "paper_2dof.yaml", mech_dir / "paper_2dof_traj.csv",
                                     "-o", "-"),
                         env=env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    first = p.stdout.readline()
    p.stdout.close()
    err = p.stderr.read()
    p.wait(timeout=120)
    assert first.startswith(b"t,motor:")
    assert p.returncode == 141 and err == b"", err



@pytest.mark.parametrize("args", [
    ("check", "mechanisms/bendix_wrist.yaml"),
    ("graph", "mechanisms/bendix_wrist.yaml"),
    ("graph", "--json", "mechanisms/bendix_wrist.yaml"),
    ("graph", "--dot", "mechanisms/bendix_wrist.yaml"),
    ("export", "mechanisms/bendix_wrist.yaml", "-o", "-"),
    ("solve", "mechanisms/paper_2dof.yaml", "mechanisms/paper_2dof_traj.csv", "-o", "-", "--backend", "numpy"),
    ("verify", "designs/ci_example.yaml", "-j", "1"),
    ("--version",),
    ("solve", "--help"),
], ids=lambda a: " ".join(a[:2]) if a[0] == "graph" else a[0])
def test_every_command_ends_quietly_on_a_closed_pipe(args):
    """stdout is a pipe whose reader is gone before gearcli writes (``| head -c 0``, without
    the race): status 141, nothing on stderr, whatever prints the text (rich or echo)."""
    r, w = os.pipe()
    os.close(r)
    try:
        p = subprocess.run(gearcli_cmd(*args), env=env(), cwd=ROOT, stdout=w, stderr=subprocess.PIPE, timeout=300)
    finally:
        os.close(w)
    assert (p.returncode, p.stderr) == (141, b"")


def test_stdout_output_checks_the_whole_trajectory_first(run_cli, work):
    t = np.arange(3000) * 1e-3
    text = rows(t, np.sin(t)) + "3.0,oops,0\n"
    (work / "traj.csv").write_text(text)
    r = run_cli("solve", work / "mech.yaml", work / "traj.csv", "-o", "-", "--chunk", "500")
    one_line_error(r, "traj.csv:3002: column 2 'q:J1': not a number: 'oops'")
    assert r.stdout == ""


def test_export_to_stdout(run_cli, work):
    r = run_cli("export", work / "mech.yaml", "-o", "-")
    assert r.exit_code == 0 and r.stdout.startswith("<?xml") and "</robot>" in r.stdout
    assert sorted(p.name for p in work.iterdir()) == ["mech.yaml"]


@pytest.mark.parametrize("name", ["robot.yaml", "robot.csv", "robot", "robot.urdf.bak", ".urdf", "old.yaml"])
def test_export_refuses_a_name_it_cannot_read_back(run_cli, work, name):
    """gearcli reads a mechanism file as URDF only when it is named .urdf or .xml: export
    under another name wrote a URDF that ``gearcli check`` then failed to read as YAML."""
    (work / "old.yaml").write_text("previous\n")
    before = snapshot(work)
    r = run_cli("export", work / "mech.yaml", "-o", work / name)
    assert r.exit_code == 2
    assert r.stderr == f"{work / name}: -o: export writes URDF; name the file .urdf or .xml\n"
    assert r.stdout == ""
    assert snapshot(work) == before
    (work / "mech.yaml").write_text("links: [\n")       # refused before the mechanism is read
    r = run_cli("export", work / "mech.yaml", "-o", work / name)
    assert r.exit_code == 2 and r.stderr == f"{work / name}: -o: export writes URDF; name the file .urdf or .xml\n"


@pytest.mark.parametrize("name", ["robot.urdf", "ROBOT.URDF", "robot.xml"])
def test_export_names_that_read_back(run_cli, work, name):
    r = run_cli("export", work / "mech.yaml", "-o", work / name)
    assert r.exit_code == 0 and r.stdout == f"Wrote {work / name}\n", r.stderr
    r = run_cli("check", work / name)
    assert r.exit_code == 0 and r.stdout.startswith(f"{work / name}: OK (2 dof"), r.stderr


def test_export_urdf_library_refuses_a_yaml_name(work):
    from gearcli.io import load_mechanism
    from gearcli.io.output import OutputError
    from gearcli.report.urdf_writer import export_urdf

    with pytest.raises(OutputError, match=r"r\.yaml: -o: export writes URDF; name the file \.urdf or \.xml$"):
        export_urdf(load_mechanism(work / "mech.yaml"), work / "r.yaml")
    assert sorted(p.name for p in work.iterdir()) == ["mech.yaml"]


# --- never a silent wrong number -------------------------------------------------------
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_load_names_the_first_bad_sample(run_cli, work, monkeypatch, bad):
    import gearcli.pipeline as pipeline

    real = pipeline.solve

    def poisoned(*a, **k):
        res = real(*a, **k)
        res.joint[7:, 1, 2] = bad    # joint J2 fz from the 8th sample of the chunk on
        return res

    monkeypatch.setattr(pipeline, "solve", poisoned)
    (work / "traj.csv").write_text(SMOOTH)
    before = snapshot(work)
    r = run_cli("solve", work / "mech.yaml", work / "traj.csv", "-o", work / "out.csv")
    one_line_error(r, f"traj.csv:9: sample t = {SMOOTH_T[7]:.9g} s: load 'joint:J2:fz' is {bad}",
                   "nothing written")
    assert snapshot(work) == before


def test_verify_fails_beyond_its_tolerance(run_cli, work):
    """Angles of 1e6 rad sampled every microsecond: the equations lose their digits; the
    residual is far above the documented tolerance, so --verify refuses the result."""
    from gearcli.pipeline import VERIFY_TOLERANCE

    t = np.arange(300) * 1e-6
    write_trajectory(work / "traj.csv", ["J1", "J2"], t, np.column_stack([1e6 * np.sin(1e3 * t), np.cos(t)]))
    before = snapshot(work)
    r = run_cli("solve", work / "mech.yaml", work / "traj.csv", "-o", work / "out.csv", "--verify")
    line = one_line_error(r, "traj.csv: --verify: worst Newton-Euler residual",
                          f"exceeds the tolerance {VERIFY_TOLERANCE:g}", "nothing written")
    assert float(line.split("residual ")[1].split()[0]) > VERIFY_TOLERANCE
    assert snapshot(work) == before
    r = run_cli("solve", work / "mech.yaml", work / "traj.csv", "-o", work / "out.csv")
    assert r.exit_code == 0          # without --verify the (finite) loads are written


def test_verify_fails_on_a_non_finite_residual(run_cli, work, monkeypatch):
    import gearcli.pipeline as pipeline

    real = pipeline.solve

    def nan_residual(*a, **k):
        res = real(*a, **k)
        res.residual = float("nan")
        return res

    monkeypatch.setattr(pipeline, "solve", nan_residual)
    (work / "traj.csv").write_text(SMOOTH)
    before = snapshot(work)
    r = run_cli("solve", work / "mech.yaml", work / "traj.csv", "-o", work / "out.csv", "--verify")
    one_line_error(r, "--verify: worst Newton-Euler residual nan")
    assert snapshot(work) == before


def test_sound_verify_passes_and_prints_the_residual(run_cli, work):
    (work / "traj.csv").write_text(SMOOTH)
    r = run_cli("solve", work / "mech.yaml", work / "traj.csv", "-o", work / "out.csv", "--verify")
    assert r.exit_code == 0, r.stderr
    assert float(r.stdout.split("(relative):")[1].split()[0]) < 1e-12


@pytest.mark.parametrize("edit", [("mass: 4.0", "mass: 1.0e300"), ("[0, 0, -9.81]", "[0, 0, -1.0e300]")])
def test_absurd_mechanism_numbers_never_leak_warnings_or_nan(run_cli, work, edit):
    mech = work / "mech.yaml"
    text = mech.read_text()
    assert edit[0] in text
    mech.write_text(text.replace(edit[0], edit[1], 1))
    (work / "traj.csv").write_text(SMOOTH)
    r = run_cli("solve", mech, work / "traj.csv", "-o", work / "out.csv")
    assert r.exit_code in (0, 2) and "Warning" not in r.stderr and "Traceback" not in r.stderr, r.stderr
    if r.exit_code == 0:
        assert np.isfinite(load_out(work / "out.csv")).all()
    else:
        assert len(r.stderr.strip().splitlines()) == 1 and not (work / "out.csv").exists()


def test_summary_rms_of_huge_loads_does_not_overflow():
    from gearcli.report.columns import Stat, Summary

    summ = Summary([1], [Stat("x", "N")])
    t = np.arange(25.0)
    x = np.r_[np.full(10, 1e200), np.full(10, 3e200), np.full(5, 1.0)]
    for a, b in ((0, 10), (10, 20), (20, 25)):          # three chunks, joined by their end rows
        summ.add(np.column_stack([t[a:b], x[a:b]]))
    # trapezoid integral of x^2 in units of 1e400, by hand: 9 steps at 1, the step 1 -> 9
    # (1 + 9)/2, 9 steps at 9, the step 9 -> 0 (9 + 0)/2, then ~0; over 24 s
    expect = 1e200 * np.sqrt((9 * 1 + 5 + 9 * 9 + 4.5) / 24)
    assert np.isclose(summ.stats[0].rms, expect, rtol=1e-12)


def test_every_module_imports_and_no_private_atomic_writer_is_left():
    """One atomic writer (gearcli.io.output): no module keeps its own temp-file code."""
    import importlib
    import pkgutil

    import gearcli

    for m in pkgutil.walk_packages(gearcli.__path__, "gearcli."):
        importlib.import_module(m.name)
    for path in (SRC / "gearcli").rglob("*.py"):
        if path.name != "output.py":
            text = path.read_text()
            assert "mkstemp" not in text and "AtomicWriter" not in text and "os.replace" not in text, path


@pytest.mark.parametrize("text, parts", [
    (HEADER + "0,0,0\n1,0,0\n", ("2 samples with positions only", "at least 3")),
    ("t,q:J1,q:J2,qdd:J1,qdd:J2\n0,0,0,0,0\n", ("1 sample with positions only", "at least 2")),
    ("t,q:J1,q:J2,qd:J1,qd:J2\n0,0,0,0,0\n", ("1 sample with no qdd: columns", "at least 2")),
    (HEADER, ("no samples",)),
])
def test_stdout_check_refuses_short_files_before_writing(run_cli, work, text, parts):
    (work / "traj.csv").write_text(text)
    r = run_cli("solve", work / "mech.yaml", work / "traj.csv", "-o", "-")
    one_line_error(r, "traj.csv: ", *parts)
    assert r.stdout == ""


def test_check_counts_every_sample(tmp_path):
    from gearcli.io.trajectory import TrajectoryReader

    p = tmp_path / "t.csv"
    p.write_text(rows(np.arange(500) * 1e-3, np.zeros(500)))
    assert TrajectoryReader(p, ["J1", "J2"], chunk=200).check() == 500
