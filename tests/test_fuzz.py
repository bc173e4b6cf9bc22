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

This session's features have their own targets: the bundled ``planetary_3p`` (``planets:``
expansion, load sharing), ``rack_axis`` and ``helical_reduction`` mutated (also field by
field: ``planets: 65``, ``kind: rack``, ``hand: x`` ...) under check/graph/export/solve, the
llvm and numpy backends agreeing on every mutated mechanism; their trajectories solved to
``-o`` .csv/.parquet/.feather/.npz/unknown extensions with ``--precision``, ``--jobs``,
``--backend`` and ``--method`` (bad values: exit 2, nothing written; binary tables read
back and checked finite); a planetary with every kind of loss (mesh efficiency, joint and
bearing friction) mutated byte-wise and key by key; files of >= 2000 rows (parsed by pyarrow) with mutated cells,
which must give the same status, message (line, column) and bytes as the line-by-line
reader; the URDF exports of the three new mechanisms, mutated.

Profiles (``GEARCLI_FUZZ``): ``ci`` (default; deterministic, well under 2 minutes) and
``long`` (``GEARCLI_FUZZ=long python -m pytest tests/test_fuzz.py``; 2,500 inputs per
target, or ``GEARCLI_FUZZ_EXAMPLES``).  With ``GEARCLI_FUZZ_RECORD=stats.jsonl`` problems are recorded (one JSON line
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
settings.register_profile("long", max_examples=int(os.environ.get("GEARCLI_FUZZ_EXAMPLES", "2500")),
                          deadline=None, database=None,
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
        if result.exc_info and isinstance(result.exc_info[1], Hang):   # caught by the runner
            return None, True
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
            else:
                out += non_finite_in(p, input_names(inputs))
    return out


def input_names(inputs: dict) -> set[str]:
    """Every string under a ``name`` key of the YAML inputs (a design, case, gear, joint,
    bearing or motor name a Markdown report echoes; unreadable inputs give none)."""
    import yaml
    names: set[str] = set()

    def walk(node):
        if isinstance(node, dict):
            for k, v in node.items():
                if k == "name" and isinstance(v, str):
                    names.add(v)
                walk(v)
        elif isinstance(node, list):
            for v in node:
                walk(v)
    for fname, data in inputs.items():
        if fname.endswith((".yaml", ".yml")):
            try:
                walk(yaml.safe_load(data))
            except Exception:   # noqa: BLE001 (a hostile input: no names from it)
                pass
    return names


def table_of(path: Path) -> dict:
    """{column: float64 array} of a loads table in any output format (by extension)."""
    import numpy as np
    ext = path.suffix.lower()
    if ext == ".npz":
        with np.load(path, allow_pickle=False) as z:
            return {k: np.asarray(z[k]) for k in z.files}
    if ext in (".parquet", ".feather"):
        import pyarrow.feather as pf
        import pyarrow.parquet as pq
        t = pq.read_table(path) if ext == ".parquet" else pf.read_table(path)
        return {n: c.to_numpy() for n, c in zip(t.column_names, t.columns)}
    lines = path.read_bytes().decode().splitlines()
    head = lines[0].split(",")
    data = np.array([[float(x) for x in ln.split(",")] for ln in lines[1:]]).reshape(-1, len(head))
    return {h: data[:, i] for i, h in enumerate(head)}


def non_finite_in(path: Path, names: set[str] = frozenset()) -> list[str]:
    """A problem when an output file holds a NaN or an infinity (or cannot be read back);
    ``names``: the inputs' names, taken out of a Markdown report first (it echoes them)."""
    import numpy as np
    if path.suffix.lower() == ".json":     # strings may say 'inf' (a case named so): parse, look at numbers
        return _non_finite_json(path)
    if path.suffix.lower() not in (".parquet", ".feather", ".npz"):
        text = path.read_bytes()
        if path.suffix.lower() == ".csv":       # the header holds the file's names ('5-inf' is a fine gear name)
            text = text.partition(b"\n")[2]
        elif path.suffix.lower() == ".xml":     # JUnit: a design or case may be named '-inf'
            text = _without_xml_names(text)
        elif path.suffix.lower() == ".md":      # a case named 'NaN' (a long run's only finding)
            for name in sorted(names, key=len, reverse=True):
                text = text.replace(name.encode(), b"")
        return [f"non-finite number written to {path.name}"] if NON_FINITE.search(text) else []
    try:
        cols = table_of(path)
    except Exception as exc:   # noqa: BLE001 (any failure to read it back is the finding)
        return [f"output {path.name} unreadable: {type(exc).__name__}: {exc}"[:300]]
    bad = [k for k, v in cols.items() if v.dtype.kind == "f" and not np.isfinite(v).all()]
    return [f"non-finite number written to {path.name} (column {bad[0]})"] if bad else []


def _without_xml_names(text: bytes) -> bytes:
    """The XML text with every value of a ``name`` or ``classname`` attribute taken out (the
    names come from the manifest; the numbers are what the oracle judges)."""
    import xml.etree.ElementTree as ET
    try:
        root = ET.fromstring(text)
    except ET.ParseError:
        return text
    names = {v for el in root.iter() for k, v in el.attrib.items() if k in ("name", "classname")}
    for name in sorted(names, key=len, reverse=True):
        text = text.replace(name.encode(), b"")
    return text


def _non_finite_json(path: Path) -> list[str]:
    """A problem when a JSON output holds NaN/Infinity (not strict JSON) or is unreadable."""
    def refuse(token):
        raise ValueError(f"{token} in the JSON")
    try:
        json.loads(path.read_text(), parse_constant=refuse)
    except ValueError as exc:
        return [f"non-finite number written to {path.name}: {exc}"[:300]]
    return []


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


def test_non_finite_oracle_reads_json_numbers_not_strings(tmp_path):
    """A JSON report is flagged for NaN/Infinity among its numbers, not for a case named 'inf'
    (the final long run's one manifest finding)."""
    ok, bad = tmp_path / "ok.json", tmp_path / "bad.json"
    ok.write_text('{"checks": [{"case": "inf", "value": 1.5, "limit": null}]}')
    bad.write_text('{"checks": [{"case": "c", "value": Infinity}]}')
    assert non_finite_in(ok) == [] and len(non_finite_in(bad)) == 1


def test_non_finite_oracle_reads_csv_data_not_names(tmp_path):
    """The oracle flags a NaN/inf in the data rows of a CSV output, not a name in its header
    (a long run's only finding was a gear renamed '5-inf', whose columns are 'gear:5-inf:t')."""
    ok, bad = tmp_path / "ok.csv", tmp_path / "bad.csv"
    ok.write_text("t,gear:5-inf:t,gear:nan:t\n0,1.5,2\n0.1,1e+300,-3\n")
    bad.write_text("t,gear:5-1:t\n0,1.5\n0.1,-inf\n")
    assert non_finite_in(ok) == []
    assert non_finite_in(bad) == ["non-finite number written to bad.csv"]


def test_non_finite_oracle_reads_markdown_numbers_not_names(tmp_path):
    """The oracle flags a NaN/inf among a Markdown report's numbers, not a name the inputs
    give (a long run's only finding was a case named 'NaN': ``name: NaN`` is a string)."""
    ok, bad = tmp_path / "ok.md", tmp_path / "bad.md"
    ok.write_text("| ok | NaN | gear 5-inf | 1.5 | 2 |\n")
    bad.write_text("| ok | NaN | gear 5-1 | nan | 2 |\n")
    names = input_names({"design.yaml": b"cases:\n  - name: NaN\n", "mech.yaml": b"gears: [{name: 5-inf}]\n"})
    assert names == {"NaN", "5-inf"}
    assert non_finite_in(ok, names) == []
    assert non_finite_in(bad, names) == ["non-finite number written to bad.md"]


def test_non_finite_oracle_reads_junit_numbers_not_names(tmp_path):
    """The oracle flags a NaN/inf among a JUnit file's numbers, not in its names (a long run's
    only finding was a design named '-inf': testsuites name="-inf", classname="-inf.case")."""
    ok, bad = tmp_path / "ok.xml", tmp_path / "bad.xml"
    ok.write_text('<testsuites name="-inf" tests="1"><testsuite name="nan"><testcase classname="-inf.c" '
                  'name="inf" time="0"/></testsuite></testsuites>')
    bad.write_text('<testsuites name="d" tests="1"><testsuite name="s"><testcase classname="d.c" '
                   'name="x" time="nan"/></testsuite></testsuites>')
    assert non_finite_in(ok) == []
    assert non_finite_in(bad) == ["non-finite number written to bad.xml"]


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


class FullDiskRaw(io.FileIO):
    """The raw file under the text wrapper (the CSV writer writes bytes to ``f.buffer``) and
    the binary formats' file: ENOSPC once the budget is spent."""

    def write(self, b):
        FullDisk.budget -= len(b)
        if FullDisk.budget < 0:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return super().write(b)


@given(fault=st.sampled_from(["input", "mech", "dot", "dir", "devnull", "missing", "empty", "symlink",
                              "dangling", "hardlink", "enospc", "rename", "ok"]),
       command=st.sampled_from(["solve", "export"]), budget=st.integers(0, 20000), tmpfile=st.booleans(),
       ext=st.sampled_from([".csv", ".csv", ".parquet", ".feather", ".npz"]))
def test_fuzz_output_faults(fault, command, budget, tmpfile, ext):
    import gearcli.io.output as output
    warm_kernel()   # the compiled modules imported before os.O_TMPFILE is taken away below

    files = {"mech.yaml": (MECH_DIR / "paper_2dof.yaml").read_bytes(),
             "traj.csv": short_csv("paper_2dof_traj.csv")}
    real_fdopen, real_replace = os.fdopen, os.replace
    saved_tmpfile = getattr(os, "O_TMPFILE", None)
    saved_tmpfile_works = getattr(tempfile, "_O_TMPFILE_WORKS", False)

    def fdopen(fd, mode="r", **kw):
        FullDisk.budget = budget
        if "b" in mode:
            return FullDiskRaw(fd, "wb")
        f = io.BufferedWriter(FullDiskRaw(fd, "wb"))
        return FullDisk(f, encoding=kw.get("encoding"), newline=kw.get("newline"), write_through=True)

    def replace(*a, **k):
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        work = Path(d)
        for k, v in files.items():
            (work / k).write_bytes(v)
        own = "traj.csv" if command == "solve" else "mech.yaml"    # an input of the command
        sfx = "" if command == "solve" else ".urdf"     # export refuses a name it cannot read back
        out = "out" + (ext if command == "solve" else sfx)
        link, dangle = "link" + sfx, "dangle" + sfx
        target = {"input": work / own, "mech": work / "mech.yaml", "dot": f"{work}/./{own}",
                  "dir": work, "devnull": "/dev/null", "missing": work / "no" / out, "empty": "",
                  "symlink": work / link, "dangling": work / dangle, "hardlink": work / "hard",
                  }.get(fault, work / out)
        extra = {}
        if fault == "symlink":
            os.symlink("mech.yaml", work / link)
            extra[link] = None
        elif fault == "dangling":
            os.symlink("real.out", work / dangle)
            extra[dangle] = None
        elif fault == "hardlink":
            os.link(work / "mech.yaml", work / "hard")
        try:
            if fault == "enospc":
                output.os.fdopen = fdopen
            if fault == "rename":
                output.os.replace = replace
            if not tmpfile and saved_tmpfile is not None:
                del os.O_TMPFILE    # a system without it, for tempfile too (numba's cache probe uses it)
                tempfile._O_TMPFILE_WORKS = False
            args = (["solve", work / "mech.yaml", work / "traj.csv"] if command == "solve"
                    else ["export", work / "mech.yaml"]) + ["-o", target]
            result, hung = run_cli(args)
        finally:
            output.os.fdopen, output.os.replace = real_fdopen, real_replace
            if saved_tmpfile is not None:
                os.O_TMPFILE = saved_tmpfile
                tempfile._O_TMPFILE_WORKS = saved_tmpfile_works
        inputs = dict(files)
        if fault == "hardlink":
            inputs["hard"] = files["mech.yaml"]
        allowed = {out, "real.out", link, dangle}
        found = problems(result, hung, work, inputs, allowed)
        if fault in ("input", "mech", "dot", "dir", "devnull", "missing", "empty", "symlink", "hardlink") \
                and not hung and result.exit_code != 2:
            found.append(f"fault {fault} not refused (exit {result.exit_code})")
        if fault in ("symlink", "dangling") and not (work / (link if fault == "symlink" else dangle)).is_symlink():
            found.append("symlink replaced by a file")
        verdict("output", found, files, None if hung else result.exit_code)


# --- this session's features: planets, racks, helical pairs, output formats, kernel, fast reader ---
_WARM = []


def warm_kernel() -> None:
    """Compile (or load from the disk caches) the llvm kernel and the CSV writer once, outside
    the hang alarm: a first compile can take longer than the alarm on a busy machine."""
    if not _WARM:
        from typer.testing import CliRunner

        from gearcli.cli import app
        with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
            CliRunner().invoke(app, ["solve", str(MECH_DIR / "rack_axis.yaml"), str(MECH_DIR / "rack_axis_traj.csv"),
                                     "-o", f"{d}/w.csv", "--backend", "llvm"])
        _WARM.append(True)


def few(n: int):
    """``n`` examples in the ci profile (these targets run whole solves), the profile's count otherwise."""
    return settings(max_examples=n) if PROFILE == "ci" else settings()


NEW_YAMLS = ["planetary_3p.yaml", "rack_axis.yaml", "helical_reduction.yaml"]
NEW_TRAJ = {y: y.replace(".yaml", "_traj.csv") for y in NEW_YAMLS}
FIELDS = ["planets", "stiffness", "helix_angle_deg", "hand", "kind", "type", "teeth", "mesh_point", "axis",
          "module", "pressure_angle_deg", "force", "point", "frame", "link", "links", "xyz", "mass", "name"]
FIELD_VALUES = [b"0", b"1", b"2", b"-1", b"64", b"65", b"3.0", b"3.5", b"1e9", b"true", b"null", b"x", b"[]",
                b"[1, 2]", b"[0, 0, 0]", b"[.nan, 0, 1]", b"rack", b"internal", b"bevel", b"prismatic",
                b"revolute", b"left", b"right", b"90", b"45", b"-15", b"1e-300", b".inf", b"''", b"planet1",
                b"housing", b"carrier", b"{}", b"base", b"link", b"[24, 0]"]


@st.composite
def field_mutation(draw):
    """A value of a named YAML field replaced (``planets: 3`` -> ``planets: 65``)."""
    return draw(st.sampled_from(FIELDS)), draw(st.integers(0, 1 << 30)), draw(st.one_of(
        st.sampled_from(FIELD_VALUES), st.sampled_from(NASTY_NUMBERS)))


def apply_field(data: bytes, mut) -> bytes:
    key, a, blob = mut
    hits = list(re.finditer(rb"(?<![A-Za-z_])" + key.encode() + rb":\s*(\[[^\]\n]*\]|[^,}\n#]+)", data))
    if not hits:
        return data
    m = hits[a % len(hits)]
    return data[:m.start(1)] + blob + data[m.end(1):]


new_mutations = st.lists(st.one_of(mutation(), field_mutation(), field_mutation()), min_size=1, max_size=3)


def mutate(data: bytes, muts) -> bytes:
    for m in muts:
        data = apply_field(data, m) if isinstance(m[0], str) and m[0] in FIELDS else apply(data, m)
    return data


def solved(work: Path, backend: str, out: str):
    args = ["solve", work / "mech.yaml", work / "traj.csv", "-o", work / out, "--backend", backend,
            "--precision", "17"]
    result, hung = run_cli(args)
    return result, hung


@few(25)
@given(name=st.sampled_from(NEW_YAMLS), muts=new_mutations,
       command=st.sampled_from(["check", "graph", "json", "dot", "solve", "solve", "export"]))
def test_fuzz_new_mechanisms(name, muts, command):
    """Mutated planetary_3p / rack_axis / helical_reduction.  ``solve`` runs the llvm kernel and the
    numpy backends: same exit status, same message, same numbers (1e-9 of each column's peak)."""
    warm_kernel()
    import numpy as np
    files = {"mech.yaml": mutate((MECH_DIR / name).read_bytes(), muts), "traj.csv": short_csv(NEW_TRAJ[name], 30)}
    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        work = Path(d)
        for k, v in files.items():
            (work / k).write_bytes(v)
        if command != "solve":
            args = {"check": ["check"], "graph": ["graph"], "json": ["graph", "--json"], "dot": ["graph", "--dot"],
                    "export": ["export"]}[command] + [work / "mech.yaml"]
            result, hung = run_cli(args + (["-o", work / "out.urdf"] if command == "export" else []))
            found = problems(result, hung, work, files, ("out.urdf",))
            verdict("new-yaml", found, files, None if hung else result.exit_code)
            return
        found, codes, firsts, tables = [], [], [], []
        for backend, out in (("llvm", "k.csv"), ("numpy", "n.csv")):
            result, hung = solved(work, backend, out)
            found += problems(result, hung, work, files, ("k.csv", "n.csv"))
            if hung:
                break
            codes.append(result.exit_code)
            firsts.append(result.stderr.strip().splitlines()[:1] if result.exit_code else [])
            if result.exit_code == 0 and (work / out).is_file():
                tables.append(table_of(work / out))
        if len(codes) == 2 and (codes[0] != codes[1] or firsts[0] != firsts[1]):
            found.append(f"backends disagree: llvm exit {codes[0]} {firsts[0]}, numpy exit {codes[1]} {firsts[1]}")
        if len(tables) == 2 and (col := first_differing_column(*tables)) is not None:
            found.append(f"backends differ in column {col}")
        verdict("new-yaml", found, files, codes[-1] if codes else None)


def lossy_planetary() -> bytes:
    """planetary_3p with every kind of loss: mesh efficiency and loss factor, joint friction,
    bearing friction on a friction-only and on a rated bearing."""
    text = (MECH_DIR / "planetary_3p.yaml").read_bytes()
    text = text.replace(b"    stiffness: 3.0e8", b"    stiffness: 3.0e8\n    efficiency: 0.985")
    text = text.replace(b"    stiffness: 3.5e8", b"    stiffness: 3.5e8\n    loss_factor: 0.012")
    text = text.replace(b"axis: [0, 0, 1]}\n  - {name: JC", b"axis: [0, 0, 1], friction: {coulomb: 0.01, viscous: 1.0e-4},\n"
                        b"     bearings: [{name: b, position: 0.01, friction_coefficient: 0.0015, bore: 0.01}]}\n  - {name: JC")
    text = text.replace(b"    planets: 3", b"    planets: 3\n    friction: {viscous: 2.0e-5}\n    bearings:\n"
                        b"      - {name: pin, position: 0, C: 900, C0: 400, type: ball, friction_coefficient: 0.002, bore: 0.004}")
    assert text.count(b"friction") == 4
    return text


LOSS_FIELDS = ["efficiency", "loss_factor", "coulomb", "viscous", "friction_coefficient", "bore", "position",
               "C", "type", "locating"]


@few(20)
@given(muts=st.lists(st.one_of(mutation(), st.tuples(st.sampled_from(LOSS_FIELDS), st.integers(0, 1 << 30),
                                                     st.one_of(st.sampled_from(FIELD_VALUES),
                                                               st.sampled_from(NASTY_NUMBERS)))),
                     min_size=1, max_size=3),
       command=st.sampled_from(["check", "graph", "solve", "solve", "export"]))
def test_fuzz_lossy_mechanism(muts, command):
    """planetary_3p with every kind of loss (mesh, joint, bearing friction), mutated byte-wise
    and key by key (efficiency, friction coefficients, bores, bearing ratings), under
    check/graph/solve/export: exit 0 or 2 with located lines, nothing non-finite written."""
    data = lossy_planetary()
    for m in muts:
        data = apply_field(data, m) if isinstance(m[0], str) and m[0] in LOSS_FIELDS else apply(data, m)
    files = {"mech.yaml": data, "traj.csv": short_csv("planetary_3p_traj.csv", 30)}
    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        work = Path(d)
        for k, v in files.items():
            (work / k).write_bytes(v)
        args = {"check": ["check", work / "mech.yaml"], "graph": ["graph", work / "mech.yaml"],
                "export": ["export", work / "mech.yaml", "-o", work / "out.urdf"],
                "solve": ["solve", work / "mech.yaml", work / "traj.csv", "-o", work / "out.csv"]}[command]
        result, hung = run_cli(args)
        found = problems(result, hung, work, files, ("out.urdf", "out.csv"))
        verdict("lossy-yaml", found, files, None if hung else result.exit_code)


def first_differing_column(a: dict, b: dict) -> str | None:
    """The first column of output table ``a`` ({name: (N,) array}) missing from ``b`` or
    differing from it by more than 1e-9 of its sample's largest value (at least 1): the
    tolerance of the kernel tests, per sample, since a column can be the rounding residue of
    much larger loads that cancel (a sun bearing between three 1e9 kg planets: 2e-6 N
    against 3e10 N)."""
    import numpy as np
    if not a:
        return None
    names = list(a)
    if any(n not in b or b[n].shape != a[n].shape for n in names):
        return next(n for n in names if n not in b or b[n].shape != a[n].shape)
    A, B = np.column_stack([a[n] for n in names]), np.column_stack([b[n] for n in names])
    tol = 1e-9 * np.maximum(1.0, np.abs(A).max(axis=1, initial=0.0))
    bad = np.flatnonzero((np.abs(A - B) > tol[:, None]).any(axis=0))
    return names[bad[0]] if bad.size else None


def test_backend_oracle_scales_by_the_sample():
    """Rounding residue of cancelling loads is no difference; a real one is named."""
    import numpy as np
    rng = np.random.default_rng(1)
    big, small = rng.uniform(1e10, 3e10, 30), rng.uniform(-2e-6, 2e-6, 30)
    a = {"t": np.arange(30.0), "joint:JP1:fx": big, "joint:JS:fx": small}
    noisy = dict(a, **{"joint:JS:fx": small + rng.uniform(-1e-6, 1e-6, 30)})
    wrong = dict(a, **{"joint:JS:fx": small + np.where(np.arange(30) == 7, 50.0, 0.0)})
    assert first_differing_column(a, noisy) is None
    assert first_differing_column(a, wrong) == "joint:JS:fx"
    assert first_differing_column(a, {k: v for k, v in a.items() if k != "t"}) == "t"


EXTS = [".csv", ".parquet", ".feather", ".npz"] * 3 + [".CSV", ".Parquet", ".txt", ".xlsx", "", ".csv.gz", ".npy"]
KNOWN = {".csv", ".parquet", ".feather", ".npz", ""}   # no extension: CSV (README)


@few(30)
@given(name=st.sampled_from(NEW_YAMLS), muts=st.lists(mutation(), max_size=3), n=st.sampled_from([2, 3, 5, 30]),
       ext=st.sampled_from(EXTS), precision=st.sampled_from([None] * 6 + [1, 6, 9, 17, 17, 0, 18, -1, "x", "9.5"]),
       jobs=st.sampled_from([None] * 4 + [1, 2, 3, 0, -1, "two"]),
       backend=st.sampled_from([None, None, "auto", "llvm", "llvm", "numpy", "kernel", "numba", ""]), degrees=st.booleans(),
       method=st.sampled_from([None, None, "full"]))
def test_fuzz_new_trajectories(name, muts, n, ext, precision, jobs, backend, degrees, method):
    """Mutated trajectories of the new mechanisms written in every format with every option;
    a bad option or an unknown extension is exit 2 with nothing written."""
    warm_kernel()
    data = short_csv(NEW_TRAJ[name], n)
    for m in muts:
        data = apply(data, m)
    files = {"mech.yaml": (MECH_DIR / name).read_bytes(), "traj.csv": data}
    out = "out" + ext
    opts = [("--precision", precision), ("--jobs", jobs), ("--backend", backend), ("--method", method)]
    extra = [str(x) for k, v in opts if v is not None for x in (k, v)] + (["--degrees"] if degrees else [])
    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        work = Path(d)
        for k, v in files.items():
            (work / k).write_bytes(v)
        result, hung = run_cli(["solve", work / "mech.yaml", work / "traj.csv", "-o", work / out, *extra])
        found = problems(result, hung, work, files, (out,))
        bad_option = (ext.lower() not in KNOWN or precision not in (None, 1, 6, 9, 17)
                      or jobs not in (None, 1, 2, 3) or backend not in (None, "auto", "llvm", "numpy"))
        if not hung and bad_option and result.exit_code != 2:
            found.append(f"bad option or extension {ext!r} not refused (exit {result.exit_code})")
        if not hung and result.exit_code == 0 and not (work / out).is_file():
            found.append("exit 0 without the output file")
        if not hung and result.exit_code == 0 and not muts and precision is not None and ext.lower() == ".csv":
            cells = (work / out).read_text().splitlines()[1].split(",")
            digits = max(len(re.sub(r"[^0-9]", "", c.split("e")[0]).lstrip("0")) for c in cells)
            if digits > precision:
                found.append(f"--precision {precision} wrote {digits} significant digits")
        verdict("new-traj", found, files, None if hung else result.exit_code)


def long_trajectory(name: str, rows: int) -> bytes:
    """The bundled trajectory repeated (time shifted) to ``rows`` samples: read by pyarrow."""
    lines = (MECH_DIR / name).read_bytes().splitlines()
    head, body = lines[0], lines[1:]
    t_end, out, k = float(body[-1].split(b",")[0]), [head], 0
    while len(out) <= rows:
        for ln in body:
            if len(out) > rows:
                break
            cells = ln.split(b",")
            cells[0] = repr(float(cells[0]) + k * (t_end + 0.001)).encode()
            out.append(b",".join(cells))
        k += 1
    return b"\n".join(out) + b"\n"


CELLS = st.one_of(st.sampled_from(NASTY_NUMBERS), st.sampled_from(
    [b" 1.5", b"1.5 ", b"+1.5", b".5", b"5.", b"1E5", b"1e+05", b"0001", b"-0.0", b"Infinity", b"1.5e",
     b'"1.5"', b'"1.5', b"1.5\"", b"1.5,2", b"", b"\t", b"1\x00", b"\xff", b"\xc3\xa9", b"1e-400", b"1.0e-5000",
     b"0e0", b"- 1", b"1 2", b"+-1", b"nan(1)", b"-nan", b"+inf", b"1d5", b"\xef\xbb\xbf1"]),
    st.floats(allow_nan=True, allow_infinity=True).map(lambda x: repr(x).encode()),
    st.binary(min_size=1, max_size=6))


@few(10)
@given(name=st.sampled_from(["paper_2dof_traj.csv", "planetary_3p_traj.csv", "rack_axis_traj.csv",
                             "bendix_wrist_traj.csv"]),
       rows=st.sampled_from([2001, 4500]), cells=st.lists(st.tuples(st.integers(0, 1 << 30), st.integers(0, 99),
                                                                     CELLS), min_size=1, max_size=2),
       chunk=st.sampled_from([None, 2000, 3000]), sep=st.sampled_from([b",", b",", b";", b"\t"]),
       eol=st.sampled_from([b"\n", b"\n", b"\r\n"]), load_column=st.booleans())
def test_fuzz_large_trajectory(name, rows, cells, chunk, sep, eol, load_column):
    """Files of >= 2000 rows (pyarrow parses them) with mutated cells: the same exit status,
    message (line and column) and output bytes as the line-by-line reader (pyarrow off)."""
    warm_kernel()
    import gearcli.io.trajectory as trajectory
    mech = name.replace("_traj.csv", ".yaml")
    lines = long_trajectory(name, rows).split(b"\n")
    if load_column and mech in ("planetary_3p.yaml", "rack_axis.yaml"):     # their load 'payload'
        lines = [ln + (b",load:payload:fz" if i == 0 else b",%d" % (-i % 50) if ln else b"")
                 for i, ln in enumerate(lines)]
    for r, c, blob in cells:
        i = 1 + r % rows
        row = lines[i].split(b",")
        row[c % len(row)] = blob
        lines[i] = b",".join(row)
    files = {"mech.yaml": (MECH_DIR / mech).read_bytes(),
             "traj.csv": eol.join(ln.replace(b",", sep) if sep != b"," else ln for ln in lines)}
    runs, found = [], []
    for fast in (True, False):
        with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
            work = Path(d)
            for k, v in files.items():
                (work / k).write_bytes(v)
            saved = trajectory.FAST_PARSE_ROWS
            trajectory.FAST_PARSE_ROWS = saved if fast else 1 << 40
            try:
                result, hung = run_cli(["solve", work / "mech.yaml", work / "traj.csv", "-o", work / "out.csv"]
                                       + (["--chunk", str(chunk)] if chunk else []))
            finally:
                trajectory.FAST_PARSE_ROWS = saved
            found += problems(result, hung, work, files, ("out.csv",))
            if hung:
                break
            runs.append((result.exit_code, result.stderr.replace(str(work), "<dir>"),
                         (work / "out.csv").read_bytes() if (work / "out.csv").is_file() else None))
    if len(runs) == 2 and runs[0] != runs[1]:
        found.append(f"fast reader differs: exit {runs[0][0]} {runs[0][1].strip()[:200]!r} vs "
                     f"exit {runs[1][0]} {runs[1][1].strip()[:200]!r}"
                     + (" (outputs differ)" if runs[0][2] != runs[1][2] else ""))
    verdict("large-traj", found, files, runs[0][0] if runs else None)


_EXPORTED: dict = {}


def exported(name: str) -> bytes:
    """The URDF ``gearcli export`` writes for bundled ``name`` (made once; racks, helical
    pairs, planet copies and stiffness as gearcli extension elements)."""
    if name not in _EXPORTED:
        with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
            result, hung = run_cli(["export", MECH_DIR / name, "-o", f"{d}/m.urdf"])
            assert not hung and result.exit_code == 0, result.stderr
            _EXPORTED[name] = Path(f"{d}/m.urdf").read_bytes()
    return _EXPORTED[name]


@few(6)
@given(name=st.sampled_from(NEW_YAMLS), muts=mutations, command=st.sampled_from(["check", "graph", "solve", "solve"]))
def test_fuzz_new_urdf(name, muts, command):
    """Mutated URDF exports of planetary_3p, rack_axis and helical_reduction."""
    warm_kernel()
    data = exported(name)
    for m in muts:
        data = apply(data, m)
    files = {"mech.urdf": data, "traj.csv": short_csv(NEW_TRAJ[name], 30)}
    args = (lambda w: ["solve", w / "mech.urdf", w / "traj.csv", "-o", w / "out.csv", "--verify"]) \
        if command == "solve" else (lambda w: [command, w / "mech.urdf"])
    run_case("new-urdf", files, args)
