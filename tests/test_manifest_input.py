"""`gearcli verify` manifests and the files they name held to the rules of mechanism files:
every number finite and in range, only regular files read (a FIFO is refused, never waited
on), every problem located (``file:line: key path: what``), reported in one round, exit 2;
`--json` is strict JSON; `gearcli check` refuses the ratings `verify` would refuse."""
from __future__ import annotations

import json
import math
import os
import signal
from contextlib import contextmanager
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DESIGNS = ROOT / "designs"
MECH = ROOT / "mechanisms"
RATED = MECH / "bendix_wrist_rated.yaml"
TRAJ = MECH / "bendix_wrist_traj.csv"
HANG_SECONDS = 60
BIG = 9 ** 420          # 401 digits: Python int, too large for a float


class Hung(Exception):
    pass


@contextmanager
def no_hang(seconds: int = HANG_SECONDS):
    """Fail (not hang) when the block takes longer than ``seconds`` (a FIFO opened for reading)."""
    def alarm(signum, frame):
        raise Hung(f"still running after {seconds} s: blocked on a FIFO?")
    old = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def run_bounded(run_cli, *args):
    with no_hang():
        r = run_cli(*args)
    if r.exc_info and isinstance(r.exc_info[1], Hung):     # the runner caught it
        pytest.fail(str(r.exc_info[1]))
    return r


def manifest(tmp_path, case: str, name: str = "design.yaml") -> Path:
    """A manifest of one case: the rated wrist, its trajectory, and ``case`` (more keys,
    one per line, indented as keys of the case)."""
    path = tmp_path / name
    path.write_text(f"cases:\n  - mechanism: {RATED}\n    trajectories: [{TRAJ}]\n{case}")
    return path


def lines_of(r) -> list[str]:
    return r.stderr.strip().splitlines()


# -- numbers -----------------------------------------------------------------------------------
CASE_KEYS = {"cycles_per_hour": "    cycles_per_hour: {}\n    bearing_life_h: 20000\n",
             "bearing_life_h": "    cycles_per_hour: 900\n    bearing_life_h: {}\n",
             "min_static_safety": "    min_static_safety: {}\n",
             "limits[0].max_abs": "    limits:\n      - {{column: 'gear:4-1:t', max_abs: {}}}\n",
             "limits[0].max_rms": "    limits:\n      - {{column: 'gear:4-1:t', max_rms: {}}}\n"}
LINE = {"cycles_per_hour": 4, "bearing_life_h": 5, "min_static_safety": 4, "limits[0].max_abs": 5,
        "limits[0].max_rms": 5}


@pytest.mark.parametrize("key", sorted(CASE_KEYS))
@pytest.mark.parametrize("value, message", [
    (str(BIG), "an integer of 401 digits is out of range (|x| <= 1e12 in SI units)"),
    (f"-{BIG}", "an integer of 401 digits is out of range (|x| <= 1e12 in SI units)"),
    (".nan", "nan is not a finite number"),
    (".inf", "inf is not a finite number"),
    ("-.inf", "-inf is not a finite number"),
    ("1.0e-320", "9.99989e-321 is out of range (1e-12 <= x <= 1e12 in SI units)"),
    ("2.0e+12", "2e+12 is out of range (|x| <= 1e12 in SI units)"),
    ("0", "must be positive, got 0"),
    ("-3", "must be positive, got -3"),
])
def test_manifest_numbers_are_finite_and_in_range(run_cli, tmp_path, key, value, message):
    """A 400-digit integer raised OverflowError, 1e-320 cycles per hour ZeroDivisionError,
    and .nan/.inf were accepted (``max_abs: .inf`` failed a passing check)."""
    man = manifest(tmp_path, CASE_KEYS[key].format(value))
    r = run_cli("verify", man, "-j", "1", "--json", tmp_path / "r.json")
    assert r.exit_code == 2, (r.stdout, r.stderr)
    assert lines_of(r) == [f"{man}:{LINE[key]}: cases[0].{key}: {message}"]
    assert not (tmp_path / "r.json").exists()


def test_tiny_duty_gives_finite_figures_not_zero_division():
    """The library below the manifest: a duty so short that life_h x rev/h underflows, and a
    load so small that (C/P)^p overflows a float, give inf (no check level, infinite life),
    never ZeroDivisionError or OverflowError."""
    from gearcli.design import bearings as B

    assert B.required_equivalent_load(1000.0, 1e-12, 5e-324, 3.0) == math.inf
    assert B.rating_life_mrev(1e12, 1e-300, 10 / 3) == math.inf
    assert B.required_equivalent_load(1000.0, 1e6, 1.0, 3.0) == pytest.approx(1000.0)   # (1)^(1/3): C itself


def test_json_report_is_strict_json_with_null_for_non_finite(tmp_path):
    """``--json`` wrote ``"limit": Infinity``; every non-finite number is null."""
    from gearcli.batch.outputs import Row, write_json

    rows = [Row("c", "bearing J1/a", "L10 life", math.inf, 2e4, "h", math.inf, True, "t.csv", 0.5),
            Row("c", "column x", "max abs", 1.0, math.inf, "N", math.nan, False, "t.csv", math.nan)]
    out = tmp_path / "r.json"
    write_json(rows, out, "d.yaml")

    def refuse(name):
        raise AssertionError(f"{name} in --json output")
    doc = json.loads(out.read_text(), parse_constant=refuse)
    assert [(c["value"], c["limit"], c["margin_pct"], c["time"]) for c in doc["checks"]] == \
        [(None, 2e4, None, 0.5), (1.0, None, None, None)]


def test_bundled_json_report_parses_strictly(run_cli, tmp_path):
    out = tmp_path / "r.json"
    r = run_cli("verify", DESIGNS / "ci_example.yaml", "-j", "1", "--json", out)
    assert r.exit_code == 0, r.stderr
    doc = json.loads(out.read_text(), parse_constant=lambda c: pytest.fail(f"{c} in --json output"))
    assert doc["passed"] and all(math.isfinite(c["limit"]) for c in doc["checks"])


def test_urdf_ratings_are_finite_and_in_range(run_cli, tmp_path):
    """``<limit effort="inf">`` was a limit no load could pass (NaN margin); ratings from URDF
    files now need what YAML ratings need."""
    arm = (MECH / "geared_arm.urdf").read_text()
    line = next(i for i, x in enumerate(arm.splitlines(), 1) if 'effort="60"' in x)
    for value, why in (("inf", "inf is not a finite number"), ("1e300", "1e+300 is out of range (|x| <= 1e12 in SI units)")):
        path = tmp_path / "arm.urdf"
        path.write_text(arm.replace('effort="60"', f'effort="{value}"'))
        r = run_cli("check", path)
        assert r.exit_code == 2
        assert lines_of(r) == [f"{path}:{line}: joint 'elbow'.limit: limit effort=\"{value}\": {why}"]
    text = arm.replace("</robot>", '  <gearcli:motor_rating motor="elbow_motor" peak_torque="2" rms_torque="1" '
                                   'max_speed="1e13"/>\n</robot>')
    path.write_text(text)
    r = run_cli("check", path)
    line = next(i for i, x in enumerate(text.splitlines(), 1) if "motor_rating" in x)
    assert lines_of(r) == [f"{path}:{line}: gearcli:motor_rating 'elbow_motor'.max_speed: "
                           "1e+13 is out of range (|x| <= 1e12 in SI units)"]


# -- one round -------------------------------------------------------------------------------
def test_schema_and_semantic_problems_come_in_one_round(run_cli, tmp_path):
    """Schema errors no longer hide the problems of the valid parts (files, columns,
    requirements): all are listed, in the manifest's line order."""
    (tmp_path / "bad.yaml").write_text("name: x\n")
    man = tmp_path / "design.yaml"
    man.write_text(f"""cases:
  - mechanism: {RATED}
    trajectories: [{TRAJ}, 3, nope_*.csv]
    min_static_safty: 2
    min_bending_safety: .nan
    bearing_life_h: 100
    limits:
      - {{column: "gear:4-1:tt", max_abs: 1}}
      - {{column: "gear:4-1:t"}}
      - {{column: 5, max_abs: 1.0e-300}}
  - mechanism: bad.yaml
    trajectories: {TRAJ}
    degrees: 3
  - 7
""")
    r = run_cli("verify", man)
    assert r.exit_code == 2
    assert lines_of(r) == [
        f"{man}:3: cases[0].trajectories[1]: expected a string, got a number (3)",
        f"{man}:3: cases[0].trajectories[2]: no trajectory file matches 'nope_*.csv' (relative to {tmp_path})",
        f"{man}:4: cases[0].min_static_safty: unknown key 'min_static_safty' (did you mean 'min_static_safety'?)",
        f"{man}:5: cases[0].min_bending_safety: nan is not a finite number",
        f"{man}:6: cases[0].bearing_life_h: a bearing life in hours needs the duty's cycles_per_hour",
        f"{man}:8: cases[0].limits[0].column: unknown output column 'gear:4-1:tt' (did you mean 'gear:4-1:t'?)",
        f"{man}:9: cases[0].limits[1]: give max_abs or max_rms (or both)",
        f"{man}:10: cases[0].limits[2].column: expected a string, got a number (5)",
        f"{man}:10: cases[0].limits[2].max_abs: 1e-300 is out of range (1e-12 <= x <= 1e12 in SI units)",
        f"{man}:13: cases[1].degrees: expected true or false, got a number (3)",
        f"{man}:14: cases[2]: expected a mapping, got a number (7)",
        f"{tmp_path / 'bad.yaml'}:1: missing required key 'base'",
        f"{tmp_path / 'bad.yaml'}:1: missing required key 'end_effector'",
        f"{tmp_path / 'bad.yaml'}:1: missing required key 'links'",
        f"{tmp_path / 'bad.yaml'}:1: missing required key 'joints'",
    ]


def test_case_names_have_no_control_characters(run_cli, tmp_path):
    man = manifest(tmp_path, '    name: "a\\0b"\n')
    r = run_cli("verify", man)
    assert r.exit_code == 2
    assert lines_of(r) == [f"{man}:4: cases[0].name: 'a\\x00b': a name without control characters or spaces (one word)"]


# -- paths ----------------------------------------------------------------------------------
def test_nul_byte_in_a_manifest_path_is_a_located_error(run_cli, tmp_path):
    """``ValueError: embedded null byte`` came out of case_analysis."""
    man = tmp_path / "design.yaml"
    man.write_text(f'cases:\n  - mechanism: "wr\\0ist.yaml"\n    trajectories: [{TRAJ}]\n'
                   f'  - mechanism: {RATED}\n    trajectories: ["{TRAJ}\\0"]\n')
    r = run_bounded(run_cli, "verify", man)
    assert r.exit_code == 2, r.stderr
    assert lines_of(r) == [f"{man}:2: cases[0].mechanism: 'wr\\0ist.yaml': the path contains a NUL byte",
                           f"{man}:5: cases[1].trajectories[0]: '{TRAJ}\\0': the path contains a NUL byte"]


@pytest.fixture
def fifo(tmp_path):
    def make(name: str) -> Path:
        path = tmp_path / name
        os.mkfifo(path)
        return path
    return make


@pytest.mark.parametrize("command", ["check", "graph", "export", "solve"])
def test_a_fifo_as_mechanism_is_refused_not_waited_on(run_cli, tmp_path, fifo, command):
    for name in ("m.yaml", "m.urdf"):
        path = fifo(name)
        extra = {"export": ["-o", tmp_path / "out.urdf"], "solve": [TRAJ, "-o", tmp_path / "out.csv"]}.get(command, [])
        r = run_bounded(run_cli, command, path, *extra)
        assert r.exit_code == 2
        assert lines_of(r) == [f"{path}: not a regular file (a FIFO)"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.urdf", "m.yaml"]


def test_a_device_as_mechanism_is_refused_not_read_without_end(run_cli):
    r = run_bounded(run_cli, "check", "/dev/zero")
    assert r.exit_code == 2 and lines_of(r) == ["/dev/zero: not a regular file (a character device)"]


def test_a_fifo_as_manifest_is_refused(run_cli, fifo):
    path = fifo("design.yaml")
    r = run_bounded(run_cli, "verify", path)
    assert r.exit_code == 2 and lines_of(r) == [f"{path}: not a regular file (a FIFO)"]


def test_fifos_and_directories_named_by_a_manifest_are_located_errors(run_cli, tmp_path, fifo):
    fifo("m.yaml")
    fifo("t.csv")
    (tmp_path / "d.csv").mkdir()
    man = tmp_path / "design.yaml"
    man.write_text(f"cases:\n  - mechanism: m.yaml\n    trajectories: [t.csv, d.csv, '*.csv']\n"
                   f"  - mechanism: {RATED}\n    trajectories: t.csv\n")
    r = run_bounded(run_cli, "verify", man)
    assert r.exit_code == 2
    assert lines_of(r) == [
        f"{man}:2: cases[0].mechanism: 'm.yaml' (relative to {tmp_path}): not a regular file (a FIFO)",
        f"{man}:3: cases[0].trajectories[0]: '{tmp_path / 't.csv'}': not a regular file (a FIFO)",
        f"{man}:3: cases[0].trajectories[1]: '{tmp_path / 'd.csv'}': not a regular file (a directory)",
        f"{man}:3: cases[0].trajectories[2]: '{tmp_path / 'd.csv'}': not a regular file (a directory)",
        f"{man}:3: cases[0].trajectories[2]: '{tmp_path / 't.csv'}': not a regular file (a FIFO)",
        f"{man}:5: cases[1].trajectories: '{tmp_path / 't.csv'}': not a regular file (a FIFO)",
    ]


def test_a_fifo_as_trajectory_or_loads_file_is_refused(run_cli, tmp_path, fifo):
    traj = fifo("t.csv")
    r = run_bounded(run_cli, "solve", MECH / "paper_2dof.yaml", traj, "-o", tmp_path / "o.csv")
    assert r.exit_code == 2 and len(lines_of(r)) == 1 and "not a regular file" in r.stderr
    for name in ("l.csv", "l.npz", "l.parquet"):
        loads = fifo(name)
        r = run_bounded(run_cli, "plot", loads, "motor:*", "-o", tmp_path / "f.png")
        assert r.exit_code == 2 and lines_of(r) == [f"{loads}: not a regular file (a FIFO)"]
    assert not (tmp_path / "f.png").exists() and not (tmp_path / "o.csv").exists()


# -- check reads ratings as verify does ---------------------------------------------------------
def test_check_refuses_ratings_verify_would_refuse(run_cli, tmp_path):
    """A gear rating's module against the pitch radii was checked by verify only."""
    text = RATED.read_text()
    bad = text.replace("rating: {module: 0.002", "rating: {module: 0.0025", 1)
    path = tmp_path / "wrist.yaml"
    path.write_text(bad)
    line = next(i for i, x in enumerate(bad.splitlines(), 1) if "module: 0.0025" in x)
    r = run_cli("check", path)
    assert r.exit_code == 2 and "OK" not in r.stdout
    assert lines_of(r) == [
        f"{path}:{line}: gears[1].rating.module: module 0.0025 m x 25 teeth / 2 = 0.03125 m disagrees with the "
        f"pitch radius 0.025 m of gear '{g}' from the mesh geometry" for g in ("5", "6")]
    r = run_cli("check", RATED)
    assert r.exit_code == 0 and "OK" in r.stdout
