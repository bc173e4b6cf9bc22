"""Property-based fuzzing of every input and output path through the CLI (in-process).

Mutations of the bundled YAML, URDF (``geared_arm.urdf``) and trajectory CSVs (byte flips,
numbers replaced by huge, tiny, non-finite or malformed ones, deleted/duplicated/swapped
lines, truncation, inserted bytes) and output faults (``-o`` onto an input, a directory, a
device, a missing directory, a symlink, an empty name; a disk that fills after a random
number of bytes; a failing rename) must give:

* exit status 0 or 2, never a traceback (status 1 with an exception), never a hang;
* on status 2, at least one line on stderr; no ``RuntimeWarning`` leaks;
* no NaN or infinity in any file written;
* no stray file in the directory (temporary or partial outputs);
* inputs unchanged.

Profiles (``GEARCLI_FUZZ``): ``ci`` (default; deterministic, well under 2 minutes) and
``long`` (``GEARCLI_FUZZ=long python -m pytest tests/test_fuzz.py``; 2,500 inputs per
target).  With ``GEARCLI_FUZZ_RECORD=stats.jsonl`` problems are recorded (one JSON line
per generated input, reproducer bytes included) instead of failing the test, so a long run
reports figures: inputs, tracebacks, hangs, bad exits, leftover files.
"""
from __future__ import annotations

import base64
import errno
import io
import json
import os
import re
import shutil
import signal
import tempfile
import time
import warnings
from pathlib import Path

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

MECH_DIR = Path(__file__).resolve().parents[1] / "mechanisms"
HANG_SECONDS = 30

settings.register_profile("ci", max_examples=40, deadline=None, derandomize=True, database=None,
                          suppress_health_check=list(HealthCheck), print_blob=True)
settings.register_profile("long", max_examples=2500, deadline=None, database=None,
                          suppress_health_check=list(HealthCheck), print_blob=True)
PROFILE = os.environ.get("GEARCLI_FUZZ", "ci")
settings.load_profile(PROFILE)
RECORD = os.environ.get("GEARCLI_FUZZ_RECORD")


def short_csv(name: str, n: int = 40) -> bytes:
    lines = (MECH_DIR / name).read_bytes().splitlines(keepends=True)
    return b"".join(lines[:n + 1])


# --- mutations ------------------------------------------------------------------------
NUMBER = re.compile(rb"-?\d+(?:\.\d*)?(?:[eE][+-]?\d+)?")
NASTY_NUMBERS = [b"1e300", b"-1e308", b"1e308", b"5e-324", b"1e-300", b"1e-12", b"nan", b"NaN", b"inf",
                 b"-inf", b".inf", b"1e999", b"0", b"-0", b"1e12", b"1e13", b"99999999999999999999999999",
                 b"0x10", b"", b"1_0", b"1,5", b"-", b"+", b"e5", b"1e", b"1..2", b"[]", b"{}", b"null", b"true"]


@st.composite
def mutation(draw):
    kind = draw(st.sampled_from(["flip", "number", "number", "delete", "duplicate", "swap", "truncate", "insert"]))
    return kind, draw(st.integers(0, 1 << 30)), draw(st.integers(0, 1 << 30)), draw(st.one_of(
        st.sampled_from(NASTY_NUMBERS),
        st.floats(allow_nan=True, allow_infinity=True).map(lambda x: repr(x).encode()),
        st.binary(min_size=1, max_size=8)))


def apply(data: bytes, mut) -> bytes:
    kind, a, b, blob = mut
    if kind == "flip" and data:
        i = a % len(data)
        return data[:i] + bytes([b % 256]) + data[i + 1:]
    if kind == "number":
        nums = list(NUMBER.finditer(data))
        if nums:
            m = nums[a % len(nums)]
            return data[:m.start()] + blob + data[m.end():]
        return data
    lines = data.splitlines(keepends=True)
    if kind in ("delete", "duplicate", "swap") and lines:
        i, j = a % len(lines), b % len(lines)
        if kind == "delete":
            del lines[i]
        elif kind == "duplicate":
            lines.insert(i, lines[i])
        else:
            lines[i], lines[j] = lines[j], lines[i]
        return b"".join(lines)
    if kind == "truncate":
        return data[:a % (len(data) + 1)]
    if kind == "insert":
        i = a % (len(data) + 1)
        return data[:i] + blob + data[i:]
    return data


mutations = st.lists(mutation(), min_size=1, max_size=4)


# --- running and checking -------------------------------------------------------------
class Hang(Exception):
    pass


def _alarm(signum, frame):
    raise Hang()


def run_cli(args) -> tuple[object, bool]:
    """(CliRunner result, hung?) for ``gearcli args`` in-process, with a time limit."""
    from typer.testing import CliRunner

    from gearcli.cli import app

    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(HANG_SECONDS)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = CliRunner().invoke(app, [str(a) for a in args])
        result.leaked = [f"{w.category.__name__}: {w.message}" for w in caught
                         if issubclass(w.category, RuntimeWarning)]
        return result, False
    except Hang:
        return None, True
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


NON_FINITE = re.compile(rb"(?i)(?<![a-z_])(nan|inf|infinity)(?![a-z_])")


def problems(result, hung: bool, work: Path, inputs: dict, allowed_outputs=()) -> list[str]:
    """Every broken promise of this run (empty when it behaved)."""
    if hung:
        return [f"hang (> {HANG_SECONDS} s)"]
    out = []
    if result.exit_code not in (0, 2):
        exc = result.exc_info
        kind = "traceback" if exc and not isinstance(exc[1], SystemExit) else "bad exit"
        detail = "".join(__import__("traceback").format_exception(*exc))[-1500:] if exc else result.stderr[-500:]
        out.append(f"{kind}: exit {result.exit_code}: {detail}")
    text = result.stdout + result.stderr
    if result.leaked:
        out.append(f"warning leaked to stderr: {result.leaked[0]}")
    if "Traceback" in text:
        out.append("traceback text in output")
    if result.exit_code == 2 and not result.stderr.strip():
        out.append("exit 2 without a message")
    for name, data in inputs.items():
        p = work / name
        if not p.is_file() or p.read_bytes() != data:
            out.append(f"input {name} changed")
    expected = set(inputs) | set(allowed_outputs)
    for p in work.iterdir():
        if p.name not in expected:
            out.append(f"leftover file {p.name}")
        elif p.name in allowed_outputs and p.is_file() and not p.is_symlink():
            if result.exit_code == 2:
                out.append(f"output {p.name} written although the exit status is 2")
            elif NON_FINITE.search(p.read_bytes()):
                out.append(f"non-finite number written to {p.name}")
    return out


def verdict(target: str, problems_found: list[str], files: dict, exit_code=None) -> None:
    """Fail the example, or record it (GEARCLI_FUZZ_RECORD)."""
    if RECORD:
        row = {"target": target, "exit": exit_code, "problems": problems_found}
        if problems_found:
            row["files"] = {k: base64.b64encode(v).decode() for k, v in files.items()}
        with open(RECORD, "a") as f:
            f.write(json.dumps(row) + "\n")
        return
    assert not problems_found, problems_found


def run_case(target: str, files: dict, args_of, outputs=("out.csv",)) -> None:
    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        work = Path(d)
        for name, data in files.items():
            (work / name).write_bytes(data)
        result, hung = run_cli(args_of(work))
        verdict(target, problems(result, hung, work, files, outputs), files, None if hung else result.exit_code)


# --- targets ----------------------------------------------------------------------------
YAMLS = ["paper_2dof.yaml", "bendix_wrist.yaml", "coaxial_fig5.yaml"]
TRAJ_OF = {"paper_2dof.yaml": "paper_2dof_traj.csv", "bendix_wrist.yaml": "bendix_wrist_traj.csv",
           "geared_arm.urdf": "geared_arm_traj.csv"}


@given(name=st.sampled_from(YAMLS), muts=mutations, solve=st.booleans())
def test_fuzz_yaml(name, muts, solve):
    data = (MECH_DIR / name).read_bytes()
    for m in muts:
        data = apply(data, m)
    files = {"mech.yaml": data}
    if solve and name in TRAJ_OF:
        files["traj.csv"] = short_csv(TRAJ_OF[name])
        run_case("yaml", files, lambda w: ["solve", w / "mech.yaml", w / "traj.csv", "-o", w / "out.csv", "--verify"])
    else:
        run_case("yaml", files, lambda w: ["check", w / "mech.yaml"])


@given(muts=mutations, command=st.sampled_from(["check", "graph", "solve"]))
def test_fuzz_urdf(muts, command):
    data = (MECH_DIR / "geared_arm.urdf").read_bytes()
    for m in muts:
        data = apply(data, m)
    files = {"mech.urdf": data}
    if command == "solve":
        files["traj.csv"] = short_csv("geared_arm_traj.csv")
        run_case("urdf", files, lambda w: ["solve", w / "mech.urdf", w / "traj.csv", "-o", w / "out.csv"])
    else:
        run_case("urdf", files, lambda w: [command, w / "mech.urdf"] + (["--json"] if command == "graph" else []))


@given(name=st.sampled_from(sorted(TRAJ_OF)), muts=mutations, n=st.sampled_from([1, 2, 3, 5, 40]),
       degrees=st.booleans(), to_stdout=st.booleans())
def test_fuzz_trajectory(name, muts, n, degrees, to_stdout):
    data = short_csv(TRAJ_OF[name], n)
    for m in muts:
        data = apply(data, m)
    ext = Path(name).suffix
    files = {f"mech{ext}": (MECH_DIR / name).read_bytes(), "traj.csv": data}

    def args(w):
        return (["solve", w / f"mech{ext}", w / "traj.csv", "-o", "-" if to_stdout else w / "out.csv", "--verify"]
                + (["--degrees"] if degrees else []))
    if to_stdout:
        with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
            work = Path(d)
            for k, v in files.items():
                (work / k).write_bytes(v)
            result, hung = run_cli(args(work))
            found = problems(result, hung, work, files)
            if not hung and NON_FINITE.search(result.stdout.encode()):
                found.append("non-finite number written to stdout")
            verdict("csv", found, files, None if hung else result.exit_code)
    else:
        run_case("csv", files, args)


class FullDisk(io.TextIOWrapper):
    budget = 0

    def write(self, s):
        FullDisk.budget -= len(s)
        if FullDisk.budget < 0:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return super().write(s)


@given(fault=st.sampled_from(["input", "mech", "dot", "dir", "devnull", "missing", "empty", "symlink",
                              "dangling", "hardlink", "enospc", "rename", "ok"]),
       command=st.sampled_from(["solve", "export"]), budget=st.integers(0, 20000), tmpfile=st.booleans())
def test_fuzz_output_faults(fault, command, budget, tmpfile):
    import gearcli.io.output as output

    files = {"mech.yaml": (MECH_DIR / "paper_2dof.yaml").read_bytes(),
             "traj.csv": short_csv("paper_2dof_traj.csv")}
    real_fdopen, real_replace = os.fdopen, os.replace
    saved_tmpfile = getattr(os, "O_TMPFILE", None)

    def fdopen(fd, mode="r", **kw):
        f = real_fdopen(fd, "wb")
        FullDisk.budget = budget
        return FullDisk(f, encoding=kw.get("encoding"), newline=kw.get("newline"), write_through=True)

    def replace(*a, **k):
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        work = Path(d)
        for k, v in files.items():
            (work / k).write_bytes(v)
        own = "traj.csv" if command == "solve" else "mech.yaml"    # an input of the command
        target = {"input": work / own, "mech": work / "mech.yaml", "dot": f"{work}/./{own}",
                  "dir": work, "devnull": "/dev/null", "missing": work / "no" / "out.csv", "empty": "",
                  "symlink": work / "link", "dangling": work / "dangle", "hardlink": work / "hard",
                  }.get(fault, work / "out.csv")
        extra = {}
        if fault == "symlink":
            os.symlink("mech.yaml", work / "link")
            extra["link"] = None
        elif fault == "dangling":
            os.symlink("real.out", work / "dangle")
            extra["dangle"] = None
        elif fault == "hardlink":
            os.link(work / "mech.yaml", work / "hard")
        try:
            if fault == "enospc":
                output.os.fdopen = fdopen
            if fault == "rename":
                output.os.replace = replace
            if not tmpfile and saved_tmpfile is not None:
                del os.O_TMPFILE
            args = (["solve", work / "mech.yaml", work / "traj.csv"] if command == "solve"
                    else ["export", work / "mech.yaml"]) + ["-o", target]
            result, hung = run_cli(args)
        finally:
            output.os.fdopen, output.os.replace = real_fdopen, real_replace
            if saved_tmpfile is not None:
                os.O_TMPFILE = saved_tmpfile
        inputs = dict(files)
        if fault == "hardlink":
            inputs["hard"] = files["mech.yaml"]
        allowed = {"out.csv", "real.out", "link", "dangle"}
        found = problems(result, hung, work, inputs, allowed)
        if fault in ("input", "mech", "dot", "dir", "devnull", "missing", "empty", "symlink", "hardlink") \
                and not hung and result.exit_code != 2:
            found.append(f"fault {fault} not refused (exit {result.exit_code})")
        if fault in ("symlink", "dangling") and not (work / ("link" if fault == "symlink" else "dangle")).is_symlink():
            found.append("symlink replaced by a file")
        verdict("output", found, files, None if hung else result.exit_code)
