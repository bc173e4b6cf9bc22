"""The generated kernel's own behaviour (backend "llvm"); its results against the numpy
path are compared in test_kernel.py with the numba kernel's."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("llvmlite")

from gearcli import analyse, load_mechanism  # noqa: E402
from gearcli.dynamics import solve as solve_mod  # noqa: E402
from gearcli.dynamics.llvm_signs import SWITCH_LIMIT  # noqa: E402
from gearcli.dynamics.solve import solve, solver_for  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
MECH = ROOT / "mechanisms"


def test_compiled_once_per_solver_and_kept():
    an = analyse(load_mechanism(MECH / "paper_2dof.yaml"))
    q = np.zeros((5, an.dof))
    solve(an, q, q, q, backend="llvm")
    k = solver_for(an).llvm_kernel()
    assert k is not None and k.build_seconds > 0 and k.compile_seconds > 0
    solve(an, q, q, q, backend="llvm")
    assert solver_for(an).llvm_kernel() is k


def test_auto_policy(monkeypatch):
    """"auto": llvm once compiled, or from LLVM_MIN_SAMPLES samples, or when the numba
    kernel is not loaded; the numba kernel for a small call otherwise."""
    import gearcli.dynamics.kernel  # noqa: F401, PLC0415  (the numba kernel loaded)
    an = analyse(load_mechanism(MECH / "helical_reduction.yaml"))
    sol = solver_for(an)
    assert sol.backend(n=10) == "kernel"
    assert sol.backend(n=solve_mod.LLVM_MIN_SAMPLES) == "llvm"
    monkeypatch.delitem(sys.modules, "gearcli.dynamics.kernel")
    assert sol.backend(n=10) == "llvm"
    monkeypatch.undo()
    q = np.zeros((3, an.dof))
    solve(an, q, q, q, backend="llvm")
    assert sol.backend(n=10) == "llvm"                   # compiled: always
    assert sol.backend("full", "auto", 10) == "numpy"
    with pytest.raises(ValueError, match="backend 'llvm' solves method 'block' only"):
        sol.backend("full", "llvm")


def test_both_pattern_codings_are_generated():
    """Bendix's signed blocks are a switch into straight-line code, planetary_3p's 2^6
    pattern maps a global table (their results: test_kernel.py)."""
    small = solver_for(analyse(load_mechanism(MECH / "bendix_wrist.yaml"))).llvm_kernel().ir
    big = solver_for(analyse(load_mechanism(MECH / "planetary_3p.yaml"))).llvm_kernel().ir
    assert "switch i64" in small and '@"ainv_' not in small
    assert '@"ainv_b0" = internal constant [' in big
    assert SWITCH_LIMIT < 64 * (32 + 6) * 30


def test_only_contraction_is_allowed():
    """No fast-math flag but ``contract`` (NaN must reach the sign search)."""
    text = solver_for(analyse(load_mechanism(MECH / "bendix_wrist.yaml"))).llvm_kernel().ir
    assert " contract " in text
    for flag in ("fast", "nnan", "ninf", "nsz", "arcp", "afn", "reassoc"):
        assert f" {flag} " not in text


def test_llvm_path_does_not_import_numba():
    """The llvm backend needs neither numba nor its cache (a faster start)."""
    code = ("import sys, numpy as np; from gearcli import analyse, load_mechanism, solve; "
            f"an = analyse(load_mechanism({str(MECH / 'bendix_wrist.yaml')!r})); q = np.zeros((4, an.dof)); "
            "solve(an, q, q, q, backend='llvm'); solve(an, q, q, q); print('numba' in sys.modules)")
    env = {"PYTHONPATH": str(ROOT / "src"), "PATH": "/usr/bin:/bin"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.strip() == "False"
