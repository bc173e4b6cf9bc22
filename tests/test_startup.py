"""Start-up: each command imports only what its path needs (checked in ``sys.modules`` of a
fresh process after the command ran; the times are in benchmarks/bench_startup.py)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MECH = ROOT / "mechanisms"

RUN = """
import json, sys
from gearcli.cli import app
sys.argv = ["gearcli", *json.loads(sys.argv[1])]
try:
    app()
except SystemExit as exc:
    code = exc.code
else:
    code = 0
print(json.dumps({"code": code, "loaded": sorted(m for m in json.loads(WATCHED) if m in sys.modules)}))
"""

# modules a command may pull in only on the paths that need them
SOLVER = ["gearcli.pipeline", "gearcli.dynamics.solve", "gearcli.dynamics.blocks", "gearcli.io.trajectory",
          "gearcli.report.table_files"]
KERNELS = ["llvmlite", "numba"]
URDF = ["lxml", "gearcli.io.urdf_reader"]
PYARROW = ["pyarrow"]
SCIPY = ["scipy", "scipy.sparse", "scipy.sparse.csgraph", "scipy.linalg"]
RICH = ["rich", "rich.console", "rich.table"]
WATCHED = SOLVER + KERNELS + URDF + PYARROW + SCIPY + RICH + ["numpy", "numpy.random", "gearcli.io.yaml_reader",
                                                          "jsonschema"]


def loaded_after(args, tmp_path) -> tuple[int, set[str]]:
    """(exit status, the watched modules imported) of ``gearcli ARGS`` in a fresh process
    whose disk caches are in ``tmp_path / "cache"``."""
    code = RUN.replace("WATCHED", repr(json.dumps(WATCHED)))
    env = dict(os.environ, GEARCLI_CACHE_DIR=str(tmp_path / "cache"))
    out = subprocess.run([sys.executable, "-c", code, json.dumps([str(a) for a in args])], capture_output=True,
                         text=True, check=True, cwd=tmp_path, env=env)
    res = json.loads(out.stdout.strip().splitlines()[-1])
    return res["code"], set(res["loaded"])


@pytest.mark.parametrize("command", [["check"], ["graph"], ["graph", "--json"], ["graph", "--dot"]])
def test_check_and_graph_do_not_import_the_solver(command, tmp_path):
    code, loaded = loaded_after([*command, MECH / "bendix_wrist.yaml"], tmp_path)
    assert code == 0
    assert "scipy.sparse.csgraph" in loaded and "jsonschema" in loaded   # an empty cache: the flow ran
    assert not loaded & set(SOLVER + KERNELS + URDF + PYARROW), loaded


@pytest.mark.parametrize("command", [["check"], ["graph"]])
def test_a_scheduled_mechanism_needs_no_scipy(command, tmp_path):
    """Once a process found the mechanism's schedule (disk cache), check and graph import
    no scipy module at all."""
    first, _ = loaded_after(["check", MECH / "bendix_wrist.yaml"], tmp_path)
    code, loaded = loaded_after([*command, MECH / "bendix_wrist.yaml"], tmp_path)
    assert first == code == 0
    assert "jsonschema" in loaded and not loaded & set(SCIPY + SOLVER), loaded


@pytest.mark.parametrize("args", [["--help"], ["check", "--help"], ["solve", "--help"], ["--version"]])
def test_help_imports_neither_numpy_nor_rich(args, tmp_path):
    code, loaded = loaded_after(args, tmp_path)
    assert code == 0 and not loaded, loaded


@pytest.mark.parametrize("mech", ["bendix_wrist.yaml", "does_not_exist.yaml"])
def test_check_prints_no_rich_table(mech, tmp_path):
    """check prints plain lines (and bad input one line each): rich is not imported."""
    code, loaded = loaded_after(["check", MECH / mech], tmp_path)
    assert code == (0 if mech == "bendix_wrist.yaml" else 2)
    assert not loaded & set(RICH), loaded


@pytest.mark.parametrize("mech, random", [("bendix_wrist.yaml", False), ("paper_2dof.yaml", False),
                                          ("rack_axis.yaml", False), ("planetary_3p.yaml", True)])
def test_random_configuration_only_when_home_is_not_enough(mech, random, tmp_path):
    """The determinacy check draws its random configuration (numpy.random) only when the
    home configuration does not settle the equations (the planetary set's redundant block is
    checked at both).  The second run (the first imports scipy, which imports numpy.random);
    only the redundant circuits need scipy then (the pivoted QR of coordinates.py)."""
    loaded_after(["check", MECH / mech], tmp_path)
    code, loaded = loaded_after(["check", MECH / mech], tmp_path)
    assert code == 0
    assert ("numpy.random" in loaded) == random and ("scipy" in loaded) == random, loaded


def test_urdf_check_does_not_import_the_yaml_reader(tmp_path):
    code, loaded = loaded_after(["check", MECH / "geared_arm.urdf"], tmp_path)
    assert code == 0
    assert "lxml" in loaded
    assert not loaded & set(SOLVER + KERNELS + PYARROW + ["gearcli.io.yaml_reader"]), loaded


def test_solve_of_a_yaml_mechanism_does_not_import_lxml(tmp_path):
    traj = tmp_path / "small.csv"
    with open(MECH / "bendix_wrist_traj.csv") as f:
        traj.write_text("".join(line for _, line in zip(range(101), f)))
    code, loaded = loaded_after(["solve", MECH / "bendix_wrist.yaml", traj, "-o", tmp_path / "x.csv"], tmp_path)
    assert code == 0
    assert "gearcli.dynamics.solve" in loaded
    assert not loaded & set(URDF), loaded


def test_bad_input_is_still_one_line_exit_2(tmp_path):
    """The lazy imports do not change what bad input gives (exit 2, no traceback)."""
    bad = tmp_path / "bad.yaml"
    bad.write_text("links: [\n")
    out = subprocess.run([sys.executable, "-c", "from gearcli.cli import app; app()", "check", str(bad)],
                         capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 2
    assert "Traceback" not in out.stderr
    assert str(bad) in out.stderr


def test_verify_in_one_process_analyses_each_mechanism_once(monkeypatch):
    """The manifest's preparation and the jobs run in this process share one analysis."""
    from gearcli.batch import manifest, verify  # noqa: PLC0415
    from gearcli.io import yaml_reader  # noqa: PLC0415

    calls = []
    real = yaml_reader.load_yaml
    monkeypatch.setattr(yaml_reader, "load_yaml", lambda p: calls.append(p) or real(p))   # every mechanism read
    manifest._analysis.cache_clear()
    out = verify.run_verify(ROOT / "designs" / "ci_example.yaml", jobs=1)
    assert len(out.rows) > 10
    assert len(calls) == 1, calls
