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
import textwrap
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
    for kind, (_, name, _) in gen_reference.PAGES.items():
        assert (DOCS / "reference" / name).read_text() == gen_reference.page(kind), \
            f"docs/reference/{name} differs from the schema: run python docs/gen_reference.py"


def test_the_cli_reference_is_generated_from_the_commands():
    sys.path.insert(0, str(DOCS))
    try:
        import gen_cli
    finally:
        sys.path.pop(0)
    assert (DOCS / "reference" / "cli.md").read_text() == gen_cli.page(), \
        "docs/reference/cli.md differs from the commands' help: run python docs/gen_cli.py"


NOT_RUN = re.compile(r"<!-- not run: (.+?) -->\s*$")
SHELL = re.compile(r"[|<>;&`]|\$\(")


def _blocks(text: str):
    """(language, body, reason not run or None) of each fenced console/bash block of a page: a
    block that cannot run says why in an HTML comment on the line before it
    (``<!-- not run: a cluster address -->``)."""
    for m in re.finditer(r"^( *)```(console|bash)\n(.*?)^\1```", text, re.S | re.M):
        before = text[:m.start()].rstrip("\n").rsplit("\n", 1)[-1]
        reason = NOT_RUN.search(before)
        yield m.group(2), textwrap.dedent(m.group(3)), reason.group(1) if reason else None


def _steps(lang: str, body: str):
    """The commands of a block with the exit status and output lines they show: ``$ cmd`` and
    the lines after it (a console block; ``$ echo $?`` then N sets the status before it, as
    does a trailing ``# exit N``); each line of a bash block is a command that exits 0."""
    if lang == "bash":
        return [[ln, 0, []] for ln in body.splitlines() if ln.strip() and not ln.startswith("#")]
    steps = []
    for ln in body.splitlines():
        if ln.startswith("$ echo $?"):
            steps[-1].append("status")
        elif ln.startswith("$ "):
            m = re.search(r"\s#\s*exit (\d+)\s*$", ln)
            steps.append([ln[2:], int(m.group(1)) if m else 0, []])
        elif steps and steps[-1][-1] == "status":
            steps[-1].pop()
            steps[-1][1] = int(ln.strip())
        elif steps:
            steps[-1][2].append(ln)
    return steps


PAGES = sorted(DOCS.rglob("*.md")) + [ROOT / "README.md"]


def _pages_with_commands():
    for page in PAGES:
        steps = [s for lang, body, reason in _blocks(page.read_text()) if reason is None for s in _steps(lang, body)]
        if steps:
            yield pytest.param(steps, id=str(page.relative_to(ROOT)))


def _shown(lines: list[str]) -> list[str]:
    """The output lines a page shows that the run must print (whitespace collapsed; an
    abridged line, one with '…', and box-drawing rules are not compared)."""
    out = []
    for ln in lines:
        t = " ".join(ln.split())
        if t and "…" not in t and not re.fullmatch(r"[┏┡└┃━╇┩┳┴─┬┼┻┛┗┓┘┐┌\s]+", t):
            out.append(t)
    return out


@pytest.fixture
def site(tmp_path):
    """A folder with what the pages' commands read (mechanisms/, designs/, docs/examples/, catalogues/)."""
    for d in ("mechanisms", "designs", "docs/examples", "benchmarks", "catalogues"):
        shutil.copytree(ROOT / d, tmp_path / d)
    return tmp_path


def _run(run_cli, command: str, site: Path):
    """(exit status, stdout + stderr) of one page command: gearcli in-process, anything with
    a shell operator (a pipe, a redirection) through bash with this environment's gearcli."""
    if command.startswith("gearcli ") and not SHELL.search(command.split(" #", 1)[0]):
        r = run_cli(*shlex.split(command, comments=True)[1:])
        return r.exit_code, r.stdout + r.stderr
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}",
           "COLUMNS": "200"}
    r = subprocess.run(["bash", "-c", command], cwd=site, capture_output=True, text=True, env=env, timeout=600)
    return r.returncode, r.stdout + r.stderr


def _check(run_cli, site: Path, steps) -> None:
    """Run a page's steps in order (a plot reads the loads its solve wrote); each must exit with
    the status the page shows (0 unless it says otherwise) and print every output line it
    shows."""
    for command, status, lines in steps:
        code, out = _run(run_cli, command, site)
        assert code == status, (command, out)
        printed = " ".join(out.split())
        missing = [t for t in _shown(lines) if t not in printed]
        assert not missing, (command, missing, out)


@pytest.mark.parametrize("steps", list(_pages_with_commands()))
def test_every_console_example_runs_and_shows_its_output(run_cli, site, monkeypatch, steps):
    monkeypatch.chdir(site)
    monkeypatch.setenv("COLUMNS", "200")
    _check(run_cli, site, steps)


def test_the_examples_that_do_not_run_say_why():
    """An example is never skipped silently: those marked not run have a reason, and the
    marked ones are the installs and the minutes-long benchmarks."""
    marked = [(page.name, reason) for page in PAGES for _, _, reason in _blocks(page.read_text()) if reason]
    assert all(len(reason) > 10 for _, reason in marked)
    assert {p for p, _ in marked} <= {"README.md", "getting-started.md", "performance.md"}, marked


def test_a_broken_example_fails(run_cli, site, monkeypatch):
    """The runner catches a page whose example breaks: the tutorial with a key renamed in its
    YAML (its check exits 2), and the README with an output line the command does not print."""
    monkeypatch.chdir(site)
    tutorial = next(p.values[0] for p in _pages_with_commands() if p.id == "docs/tutorial.md")
    _check(run_cli, site, tutorial[:1])
    text = (DOCS / "examples" / "geared_joint.yaml").read_text()
    (site / "docs" / "examples" / "geared_joint.yaml").write_text(text.replace("mass:", "masss:", 1))
    with pytest.raises(AssertionError):
        _check(run_cli, site, tutorial[:1])
    readme = next(p.values[0] for p in _pages_with_commands() if p.id == "README.md")
    _check(run_cli, site, readme[:1])
    wrong = [[readme[0][0], 0, [ln.replace("5 gear pairs", "4 gear pairs") for ln in readme[0][2]]]]
    with pytest.raises(AssertionError):
        _check(run_cli, site, wrong)


def test_the_ci_workflow_parses_and_its_verify_passes(run_cli, site, monkeypatch):
    wf = yaml.safe_load((DOCS / "examples" / "github-workflow.yml").read_text())
    steps = wf["jobs"]["verify"]["steps"]
    runs = [s["run"] for s in steps if "run" in s]
    verify = next(r for r in runs if r.startswith("gearcli verify"))
    monkeypatch.chdir(site)
    r = run_cli(*shlex.split(verify)[1:])
    assert r.exit_code == 0, r.stdout + r.stderr
    assert (site / "report.xml").is_file() and (site / "summary.md").is_file()


def test_the_readme_is_a_landing_page():
    """At most 250 lines, no issue number or project history, its picture and every file it
    links present, and each feature links to a page of the site."""
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) <= 250
    assert not re.search(r"(?i)\bissues?\s*#?\d", text)
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text)
    assert links and all((ROOT / link).exists() for link in links if not link.startswith("http")), links
    assert "docs/images/paper_2dof_loads.png" in links
    features = text.split("## What it does", 1)[1].split("\n## ", 1)[0]
    items = re.split(r"\n- ", features)[1:]
    assert len(items) >= 10 and all("](docs/" in item for item in items)


def test_the_benchmarks_the_pages_name_exist():
    named = {m for page in PAGES for m in re.findall(r"benchmarks/\w+\.py", page.read_text())}
    assert named and all((ROOT / m).is_file() for m in named), named


def test_the_tutorials_graph_picture_is_what_graph_svg_draws():
    """The picture the tutorial shows is gearcli's drawing of its mechanism, not a stale copy
    (regenerate: gearcli graph docs/examples/geared_joint.yaml --svg docs/images/geared_joint_graph.svg)."""
    from gearcli import analyse, load_mechanism
    from gearcli.report.graph_svg import graph_svg
    drawn = graph_svg(analyse(load_mechanism(DOCS / "examples" / "geared_joint.yaml")))
    assert (DOCS / "images" / "geared_joint_graph.svg").read_text() == drawn
