"""Property-based fuzzing of ``gearcli verify``: mutated design manifests (in-process CLI).

The bundled manifests ``designs/ci_example.yaml`` and ``designs/ci_tight.yaml`` (on the
rated Bendix wrist and the first 40 samples of its trajectory) are mutated byte-wise as in
:mod:`test_fuzz` (flips, numbers replaced by huge, tiny, non-finite or malformed ones,
deleted/duplicated/swapped lines, truncation, inserted bytes), key by key (a requirement or
limit set to a 400-digit integer, ``.nan``, ``1.0e-320``, ``0``, a string, a list ...), and
path by path (the mechanism or a trajectory named with a NUL byte, as a FIFO, a directory,
a missing file or a glob), then run through ``verify -j 1`` with ``--json``, ``--junit``
and ``--markdown`` reports.  Every run must give:

* exit status 0, 1 (a check failed) or 2, never a traceback, never a hang (a FIFO is
  refused, not waited on);
* on status 2, at least one line on stderr and no report written; no ``RuntimeWarning``;
* a ``--json`` report that parses as strict JSON (no ``NaN``/``Infinity``);
* no NaN or infinity in any report (names taken from the manifest aside);
* no stray file in the directory, inputs unchanged (the FIFO and the directory too).

Profiles and recording are those of :mod:`test_fuzz`: ``GEARCLI_FUZZ=ci`` (default; a few
seconds) or ``long`` (``GEARCLI_FUZZ=long python -m pytest tests/test_fuzz_manifests.py``;
2,500 inputs per target), and ``GEARCLI_FUZZ_RECORD=stats.jsonl`` records one JSON line per
input (exit status, problems, reproducer bytes) instead of failing.
"""
from __future__ import annotations

import json
import math
import os
import re
import stat
import tempfile
from pathlib import Path

import pytest

pytest.importorskip("hypothesis")
from hypothesis import given  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from test_fuzz import (MECH_DIR, NASTY_NUMBERS, apply, few, mutation, problems, run_cli,  # noqa: E402
                       short_csv, verdict)

DESIGN_DIR = Path(__file__).resolve().parents[1] / "designs"
MANIFESTS = ["ci_example.yaml", "ci_tight.yaml"]
REPORTS = {"--json": "out.json", "--junit": "out.xml", "--markdown": "out.md"}
SPECIAL = ("fifo.yaml", "fifo.csv", "sub")      # a FIFO of each kind and a directory, made per run


def manifest_bytes(name: str) -> bytes:
    """The bundled manifest naming the copies in the working directory."""
    text = (DESIGN_DIR / name).read_text()
    text = text.replace("../mechanisms/bendix_wrist_rated.yaml", "mech.yaml")
    return text.replace("../mechanisms/bendix_wrist_traj.csv", "traj.csv").encode()


# --- key and path mutations ---------------------------------------------------------------
KEYS = ["cycles_per_hour", "bearing_life_h", "min_static_safety", "min_bending_safety", "min_contact_safety",
        "max_abs", "max_rms", "degrees", "name", "column", "mechanism", "trajectories"]
BIG = str(9 ** 420).encode()
VALUES = [BIG, b"-" + BIG, b".nan", b".NaN", b".inf", b"-.inf", b"1.0e-320", b"5e-324", b"1e-13", b"1e-12",
          b"0", b"-0.0", b"-1", b"1e12", b"1e13", b"1.0e+308", b"0x10", b"0o17", b"1_000", b"true", b"null",
          b"~", b"''", b'"x"', b"[]", b"[1, 2]", b"{}", b"{a: 1}", b"motor:motor5", b'"gear:4-1:t"', b"wrist motion",
          b'"a\\0b"', b'"\\t"', b"&a 3", b"*a", b"!!str 3", b"!!float 1e400", b"2001-01-01", b"1:30"]
PATHS = [b'"mech\\0.yaml"', b'"traj\\0.csv"', b"fifo.yaml", b"fifo.csv", b"sub", b"sub/", b"missing.yaml",
         b"missing.csv", b"'*.csv'", b"'*'", b"'[]'", b"traj.csv", b"mech.yaml", b"/dev/zero", b"/dev/null",
         b".", b"''", b"[traj.csv, traj.csv]", b"[fifo.csv, traj.csv]", b'["traj.csv\\0"]', b"[sub, '*.csv']"]


@st.composite
def key_mutation(draw):
    """A key's value replaced (``max_abs: 20`` -> ``max_abs: .inf``); paths get path values."""
    key = draw(st.sampled_from(KEYS))
    pool = PATHS if key in ("mechanism", "trajectories") else VALUES
    return key, draw(st.integers(0, 1 << 30)), draw(st.one_of(st.sampled_from(pool), st.sampled_from(NASTY_NUMBERS)))


def apply_key(data: bytes, mut) -> bytes:
    key, a, blob = mut
    hits = list(re.finditer(rb"(?<![A-Za-z_])" + key.encode() + rb":\s*(\[[^\]\n]*\]|[^,}\n#]+?)(?=\s*(?:[,}#\n]|$))",
                            data))
    if not hits:
        return data
    m = hits[a % len(hits)]
    return data[:m.start(1)] + blob + data[m.end(1):]


manifest_mutations = st.lists(st.one_of(mutation(), key_mutation(), key_mutation()), min_size=1, max_size=4)


def mutate(data: bytes, muts) -> bytes:
    for m in muts:
        data = apply_key(data, m) if m[0] in KEYS else apply(data, m)
    return data


# --- the oracle beyond test_fuzz.problems -------------------------------------------------
class _AsChecked:
    """A CliRunner result whose exit status 1 (a check failed: reports written) is judged as
    0 by :func:`test_fuzz.problems`, whose contract knows 0 and 2 only."""

    def __init__(self, result):
        self._r = result
        self.exit_code = 0 if result.exit_code == 1 and not _crashed(result) else result.exit_code

    def __getattr__(self, name):
        return getattr(self._r, name)


def _crashed(result) -> bool:
    exc = result.exc_info
    return bool(exc) and not isinstance(exc[1], SystemExit)


MARKS = ("❌", "⚠️", "✅")
JUNIT_TEXT = re.compile(r": worst (?P<value>\S+)(?: [^ (]+)? \(limit (?P<limit>\S+)(?: [^ )]+)?\), "
                        r"margin (?P<margin>\S+) %, in .* at t = (?P<time>\S+) s$", re.S)


def _finite(text: str) -> bool:
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


def json_numbers(path: Path) -> list[str]:
    """Problems of a --json report: not strict JSON, or a number that is not finite."""
    def refuse(constant):
        raise ValueError(f"{constant} in the --json report")
    try:
        doc = json.loads(path.read_text(), parse_constant=refuse)
    except ValueError as exc:
        return [f"--json report is not strict JSON: {str(exc)[:200]}"]
    bad = [k for c in doc.get("checks", []) for k, v in c.items() if isinstance(v, float) and not math.isfinite(v)]
    return [f"non-finite {bad[0]} in the --json report"] if bad else []


def markdown_numbers(path: Path) -> list[str]:
    """Problems of a --markdown report: a worst value, limit, margin or time that is not a
    finite number (the cells of a row; the case name may hold anything)."""
    for line in path.read_text().splitlines():
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]
        if len(cells) == 10 and cells[0] in MARKS:
            bad = [c for c in (cells[4], cells[5], cells[7], cells[9]) if not _finite(c)]
            if bad:
                return [f"non-finite number in the --markdown report: {bad[0]!r}"]
    return []


def junit_numbers(path: Path) -> list[str]:
    """Problems of a --junit report: not XML, or a number of a check's line that is not finite."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        return [f"--junit report is not XML: {exc}"]
    for tc in root.iter("testcase"):
        for el in tc:
            text = el.get("message") if el.tag == "failure" else el.text
            m = JUNIT_TEXT.search(text or "")
            if m is None:
                return [f"--junit report: unexpected check line {text!r:.200}"]
            bad = [v for v in m.groupdict().values() if not _finite(v)]
            if bad:
                return [f"non-finite number in the --junit report: {bad[0]!r}"]
    return []


CHECK_REPORT = {"--json": json_numbers, "--markdown": markdown_numbers, "--junit": junit_numbers}


def report_problems(result, work: Path, asked: list[str]) -> list[str]:
    """Every report asked for written on exit 0/1, strict JSON, no NaN/inf in any report;
    the FIFOs and the directory untouched."""
    found = []
    if result.exit_code in (0, 1) and not _crashed(result):
        for option in asked:
            p = work / REPORTS[option]
            if not p.is_file():
                found.append(f"exit {result.exit_code} without the {option} report")
            else:
                found += CHECK_REPORT[option](p)
    for name in ("fifo.yaml", "fifo.csv"):
        if not stat.S_ISFIFO(os.lstat(work / name).st_mode):
            found.append(f"{name} replaced")
    if any((work / "sub").iterdir()):
        found.append("file written into the directory 'sub'")
    return found


def run_verify(target: str, files: dict, reports: list[str], extra=()) -> None:
    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        work = Path(d)
        for name, data in files.items():
            (work / name).write_bytes(data)
        os.mkfifo(work / "fifo.yaml")
        os.mkfifo(work / "fifo.csv")
        (work / "sub").mkdir()
        args = ["verify", work / "design.yaml", "-j", "1", *extra]
        for option in reports:
            args += [option, work / REPORTS[option]]
        result, hung = run_cli(args)
        if hung:
            verdict(target, problems(result, hung, work, files), files, None)
            return
        found = problems(_AsChecked(result), hung, work, files, set(REPORTS.values()) | set(SPECIAL))
        found += report_problems(result, work, reports)
        verdict(target, found, files, result.exit_code)


def inputs(manifest: bytes) -> dict:
    return {"design.yaml": manifest, "mech.yaml": (MECH_DIR / "bendix_wrist_rated.yaml").read_bytes(),
            "traj.csv": short_csv("bendix_wrist_traj.csv", 40)}


report_sets = st.lists(st.sampled_from(sorted(REPORTS)), unique=True, max_size=3)


# --- targets ------------------------------------------------------------------------------
@few(25)
@given(name=st.sampled_from(MANIFESTS), muts=manifest_mutations, reports=report_sets)
def test_fuzz_manifest(name, muts, reports):
    """Mutated manifests, byte-wise and key by key."""
    run_verify("manifest", inputs(mutate(manifest_bytes(name), muts)), reports)


@pytest.mark.parametrize("key", ["mechanism", "trajectories"])
@pytest.mark.parametrize("value", PATHS, ids=lambda v: v.decode())
def test_fuzz_manifest_paths(key, value):
    """The mechanism or the trajectories named by every bad path (NUL, FIFO, directory,
    device, missing, glob), each in every profile: a FIFO blocked verify for ever."""
    data = apply_key(manifest_bytes("ci_example.yaml"), (key, 0, value))
    assert data != manifest_bytes("ci_example.yaml") or value in (b"mech.yaml", b"traj.csv")
    run_verify("manifest-path", inputs(data), sorted(REPORTS))


def test_manifest_oracle_flags_what_it_must(tmp_path):
    """The oracle's own checks: non-strict JSON and a NaN or inf among a report's numbers
    are findings; a case named 'inf' or 'nan' is not."""
    class R:
        exit_code, exc_info = 1, None
    os.mkfifo(tmp_path / "fifo.yaml")
    os.mkfifo(tmp_path / "fifo.csv")
    (tmp_path / "sub").mkdir()
    row = "| ✅ | nan | motor m | peak torque | {} | 0.5 | N·m | 40 | t.csv | 1 |\n"
    xml = ('<testsuites><testsuite name="inf"><testcase classname="x.inf" name="motor m: peak torque">'
           '<failure message="motor m: peak torque: worst {} N·m (limit 0.5 N·m), margin -3 %, in t.csv at '
           't = 1 s" /></testcase></testsuite></testsuites>')
    asked = ["--json", "--markdown", "--junit"]
    (tmp_path / "out.json").write_text('{"checks": [{"case": "inf", "value": null, "limit": 0.5}]}')
    (tmp_path / "out.md").write_text(row.format("0.3"))
    (tmp_path / "out.xml").write_text(xml.format("0.3"))
    assert report_problems(R(), tmp_path, asked) == []
    (tmp_path / "out.json").write_text('{"checks": [{"value": NaN}]}')
    (tmp_path / "out.md").write_text(row.format("nan"))
    (tmp_path / "out.xml").write_text(xml.format("inf"))
    assert report_problems(R(), tmp_path, asked) == [
        "--json report is not strict JSON: NaN in the --json report",
        "non-finite number in the --markdown report: 'nan'",
        "non-finite number in the --junit report: 'inf'"]
    (tmp_path / "out.json").write_text('{"checks": [{"value": 1e999}]}')
    (tmp_path / "out.md").unlink()
    assert report_problems(R(), tmp_path, asked)[:2] == [
        "non-finite value in the --json report", "exit 1 without the --markdown report"]
