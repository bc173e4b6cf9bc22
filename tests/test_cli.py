"""The ``gearcli`` command line: help, version, check and graph on the bundled files."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

import gearcli
from gearcli.report.tables import format_blocks, round_sig

BUNDLED = ("paper_2dof", "bendix_wrist", "coaxial_fig5")


def test_help(run_cli):
    res = run_cli("--help")
    assert res.exit_code == 0
    for command in ("check", "graph", "solve", "export", "verify", "plot"):   # gearcli's, not click's words
        assert command in res.stdout


def test_no_arguments_shows_help(run_cli):
    res = run_cli()
    assert all(command in res.stdout + res.stderr for command in ("check", "graph", "solve"))


@pytest.mark.parametrize("command", ["check", "graph"])
def test_command_help(run_cli, command):
    res = run_cli(command, "--help")
    assert res.exit_code == 0
    assert "MECH" in res.stdout   # gearcli's argument name (the usage line's own words are click's)
    assert "kg" in res.stdout  # units are documented


def test_graph_help_lists_options(run_cli):
    out = run_cli("graph", "--help").stdout
    for option in ("--json", "--dot", "--real-joints"):
        assert option in out


def test_version(run_cli):
    res = run_cli("--version")
    assert res.exit_code == 0
    assert res.stdout.strip() == f"gearcli {gearcli.__version__}" == "gearcli 0.1.0"


@pytest.mark.parametrize("name, summary", [
    ("paper_2dof", "OK (2 dof, 6 links, 3 gear pairs, 2 motors)"),
    ("bendix_wrist", "OK (3 dof, 9 links, 5 gear pairs, 3 motors)"),
    ("coaxial_fig5", "OK (2 dof, 6 links, 3 gear pairs, 2 motors)"),
])
def test_check_bundled(run_cli, mech_dir, name, summary):
    path = mech_dir / f"{name}.yaml"
    res = run_cli("check", path)
    assert res.exit_code == 0, res.stderr
    assert res.stdout.strip() == f"{path}: {summary}"
    assert res.stderr == ""


def test_graph_tables_paper(run_cli, mech_dir):
    res = run_cli("graph", mech_dir / "paper_2dof.yaml")
    assert res.exit_code == 0, res.stderr
    out = res.stdout
    assert "Solve order: {2} -> {4} -> {1} -> " in out
    assert "Pseudo-triangular: yes" in out
    assert "Degrees of freedom: 2" in out
    for text in ("Links", "Gear pairs", "Coaxial groups", "Transmission lines", "Structure matrix",
                 "theta_5,0 = -3 * theta_1,0", "3 -> 4 -> 2", "5 -> 1", "motor3", "motor5",
                 "primary", "secondary"):
        assert text in out, text


def test_graph_tables_bendix(run_cli, mech_dir):
    res = run_cli("graph", mech_dir / "bendix_wrist.yaml")
    assert res.exit_code == 0, res.stderr
    assert "Solve order: {" in res.stdout and "Pseudo-triangular: no" in res.stdout
    assert "Solve order: {3, 2} -> " in res.stdout or "Solve order: {2, 3} -> " in res.stdout


@pytest.mark.parametrize("name", BUNDLED)
def test_graph_json_is_json(run_cli, mech_dir, name):
    res = run_cli("graph", mech_dir / f"{name}.yaml", "--json")
    assert res.exit_code == 0, res.stderr
    d = json.loads(res.stdout)
    for key in ("dof", "levels", "primary", "carriers", "transmission_lines", "structure_matrix",
                "pseudo_triangular", "solve_order"):
        assert key in d


def test_graph_rejects_json_and_dot(run_cli, mech_dir):
    res = run_cli("graph", mech_dir / "paper_2dof.yaml", "--json", "--dot")
    assert res.exit_code == 2
    assert res.stderr.splitlines() == ["graph: give at most one of --json and --dot"]


def test_graph_bad_input(run_cli, tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text("name: x\n")
    res = run_cli("graph", path, "--json")
    assert res.exit_code == 2 and res.stdout == ""
    assert res.stderr.splitlines() == [f"{path}:1: missing required key '{k}'"
                                       for k in ("base", "end_effector", "links", "joints")]


def test_console_script_subprocess(mech_dir, tmp_path):
    """The real entry point: exit codes and streams as a user sees them."""
    ok = subprocess.run([sys.executable, "-m", "gearcli.cli", "check", str(mech_dir / "paper_2dof.yaml")],
                        capture_output=True, text=True)
    assert ok.returncode == 0 and "OK (2 dof" in ok.stdout
    missing = tmp_path / "missing.yaml"
    bad = subprocess.run([sys.executable, "-m", "gearcli.cli", "check", str(missing)],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr == f"{missing}: cannot read file: No such file or directory\n"


def test_round_sig():
    assert round_sig(-0.9999999999999991) == -1.0
    assert round_sig({"a": [1.9999999999999996, 3, "x"], "b": (0.1 + 0.2,)}) == {"a": [2.0, 3, "x"], "b": [0.3]}
    assert str(round_sig(-0.0)) == "0.0"
    assert round_sig(True) is True


def test_format_blocks():
    assert format_blocks([["2"], ["4"], ["1"], ["3"], ["5"]]) == "{2} -> {4} -> {1} -> {3} -> {5}"
    assert format_blocks([["3", "2"], ["6"]]) == "{3, 2} -> {6}"


def test_public_api():
    for name in ("load_mechanism", "parse_mechanism", "analyse", "Mechanism", "Analysis",
                 "MechanismError", "GearcliError", "__version__"):
        assert hasattr(gearcli, name), name
        assert name in gearcli.__all__
    assert issubclass(gearcli.MechanismError, gearcli.GearcliError)
    with pytest.raises(AttributeError):
        gearcli.no_such_name  # noqa: B018


def test_cli_import_stays_light():
    """`gearcli --help` must not pay for numpy, scipy or the analysis (report modules the
    CLI imports at the top use them only under TYPE_CHECKING or inside functions)."""
    import subprocess
    import sys
    code = "import sys, gearcli.cli; print(sorted(m for m in ('numpy', 'scipy') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
