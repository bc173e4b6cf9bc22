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
