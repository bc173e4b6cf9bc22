"""The documentation site (issue 38): it builds with ``mkdocs build --strict`` (no broken link
or reference), its mechanism reference is the JSON Schema's (generated: the schema is the
one source), every ``$ gearcli ...`` line of its console blocks runs and exits 0 on the
files the pages name, and the CI workflow of the how-to parses and names a command that
passes.  (The pages' Python blocks run through docs/conftest.py, Sybil.)"""
from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def test_the_site_builds_strict(tmp_path):
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    r = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-d", str(tmp_path / "site")],
                       cwd=ROOT, capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert (tmp_path / "site" / "tutorial" / "index.html").is_file()
    assert "crossed_roller" in (tmp_path / "site" / "reference" / "mechanism" / "index.html").read_text()


def test_the_mechanism_reference_is_generated_from_the_schema():
    sys.path.insert(0, str(DOCS))
    try:
        import gen_reference
    finally:
        sys.path.pop(0)
    assert (DOCS / "reference" / "mechanism.md").read_text() == gen_reference.page(), \
        "docs/reference/mechanism.md differs from the schema: run python docs/gen_reference.py"


def test_the_cli_reference_is_generated_from_the_commands():
    sys.path.insert(0, str(DOCS))
    try:
        import gen_cli
    finally:
        sys.path.pop(0)
    assert (DOCS / "reference" / "cli.md").read_text() == gen_cli.page(), \
        "docs/reference/cli.md differs from the commands' help: run python docs/gen_cli.py"


def _pages_with_commands():
    for page in sorted(DOCS.rglob("*.md")):
        lines = [ln[2:] for block in re.findall(r"```console\n(.*?)```", page.read_text(), re.S)
                 for ln in block.splitlines() if ln.startswith("$ gearcli ")]
        if lines:
            yield pytest.param(lines, id=str(page.relative_to(DOCS)))


@pytest.fixture
def site(tmp_path):
    """A folder with what the pages' commands read (mechanisms/, designs/, docs/examples/)."""
    for d in ("mechanisms", "designs", "docs/examples"):
        shutil.copytree(ROOT / d, tmp_path / d)
    return tmp_path


@pytest.mark.parametrize("commands", list(_pages_with_commands()))
def test_every_console_command_of_the_pages_runs(run_cli, site, monkeypatch, commands):
    """A page's commands in order (a plot reads the loads its solve wrote), each exit 0."""
    monkeypatch.chdir(site)
    for command in commands:
        r = run_cli(*shlex.split(command)[1:])
        assert r.exit_code == 0, (command, r.stdout + r.stderr)


def test_the_ci_workflow_parses_and_its_verify_passes(run_cli, site, monkeypatch):
    wf = yaml.safe_load((DOCS / "examples" / "github-workflow.yml").read_text())
    steps = wf["jobs"]["verify"]["steps"]
    runs = [s["run"] for s in steps if "run" in s]
    verify = next(r for r in runs if r.startswith("gearcli verify"))
    monkeypatch.chdir(site)
    r = run_cli(*shlex.split(verify)[1:])
    assert r.exit_code == 0, r.stdout + r.stderr
    assert (site / "report.xml").is_file() and (site / "summary.md").is_file()
