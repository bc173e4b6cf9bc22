"""Shared fixtures: the bundled mechanism files and an in-process ``gearcli`` runner."""
from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

MECH_DIR = Path(__file__).resolve().parents[1] / "mechanisms"


@pytest.fixture(scope="session", autouse=True)
def _own_kernel_cache(tmp_path_factory):
    """The llvm kernels' disk cache of this test session: a fresh folder, not the user's."""
    mp = pytest.MonkeyPatch()
    mp.setenv("GEARCLI_CACHE_DIR", str(tmp_path_factory.mktemp("gearcli-cache")))
    yield
    mp.undo()


@pytest.fixture(scope="session")
def mech_dir() -> Path:
    """The directory of the bundled mechanism files."""
    return MECH_DIR


@pytest.fixture
def run_cli():
    """``run_cli("check", path)`` runs gearcli in-process; the result has ``exit_code``,
    ``stdout`` and ``stderr`` (separately captured)."""
    from gearcli.cli import app

    runner = CliRunner()

    def run(*args):
        return runner.invoke(app, [str(a) for a in args])

    return run


PHYSICS_FIRST = ("test_dynamics.py", "test_independent.py", "test_losses.py", "test_frame_conventions.py",
                 "test_payloads.py", "test_design_formulas.py", "test_forward.py")
"""The by-hand, closed-form and power-balance tests (marker ``physics``): they run first, so
that ``pytest -x`` meets a physics bug in the first minute, before the equality tests of the
two solver paths, which cannot see a bug made in both (issue 39, section 4)."""


def pytest_configure(config):
    config.addinivalue_line("markers", "physics: a by-hand, closed-form or power-balance test (run first)")


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(session, config, items):
    for item in items:
        if item.path.name in PHYSICS_FIRST:
            item.add_marker(pytest.mark.physics)
    items.sort(key=lambda it: (it.path.name not in PHYSICS_FIRST,
                               PHYSICS_FIRST.index(it.path.name) if it.path.name in PHYSICS_FIRST else 0))
