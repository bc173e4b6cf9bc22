"""The generated kernel's own behaviour (backend "llvm") and "auto"'s choice; its results
against the numpy path are compared in test_kernel.py."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("llvmlite")

from big_mechanisms import serial_chain  # noqa: E402
from gearcli import analyse, load_mechanism, parse_mechanism  # noqa: E402
from gearcli.dynamics import backends  # noqa: E402
from gearcli.dynamics.llvm.signs import SWITCH_LIMIT  # noqa: E402
from gearcli.dynamics.solve import solve, solver_for  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
MECH = ROOT / "mechanisms"


def test_compiled_once_per_solver_and_kept(monkeypatch, tmp_path):
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))   # an empty disk cache: really generated and compiled
    an = analyse(load_mechanism(MECH / "paper_2dof.yaml"))
    q = np.zeros((5, an.dof))
    solve(an, q, q, q, backend="numpy")
    solve(an, q, q, q, method="full")
    assert solver_for(an).samples_solved == backends.CALL_SAMPLES   # a call counts at least that (block method only)
    solve(an, q, q, q, backend="llvm")
    k = solver_for(an).llvm_kernel()
    assert k is not None and k.build_seconds > 0 and k.compile_seconds > 0
    solve(an, q, q, q, backend="llvm")
    assert solver_for(an).llvm_kernel() is k


def test_first_call_rule(monkeypatch, tmp_path):
    """"auto" with the kernel neither compiled nor on disk: a call of fewer than
    FIRST_CALL_SAMPLES samples (with those solved before) is solved by numpy, says why and
    compiles nothing; a call reaching it compiles; once compiled (or on disk), every call
    takes llvm.  Explicit backends ignore the rule."""
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))   # an empty disk cache
    an = analyse(load_mechanism(MECH / "helical_reduction.yaml"))
    sol = solver_for(an)
    K = backends.FIRST_CALL_SAMPLES
    q = np.zeros((10, an.dof))
    res = solve(an, q, q, q)
    assert res.backend == "numpy" and "first-call rule" in res.backend_note and not sol.compiled_llvm()
    C = backends.CALL_SAMPLES                                                  # what the 10-sample call counted
    assert sol.choice(n=K - C - 1).path == "numpy" and sol.choice(n=K - C).path == "llvm"
    assert sol.choice(n=None).path == "llvm"                                               # a large call
    assert sol.choice(backend="llvm", n=1).path == "llvm" and not sol.compiled_llvm()         # choosing compiles nothing
    big = np.zeros((K, an.dof))
    res = solve(an, big, big, big)
    assert res.backend == "llvm" and res.backend_note is None and sol.compiled_llvm()
    res = solve(an, q, q, q)
    assert res.backend == "llvm" and res.backend_note is None                            # compiled: always
    other = solver_for(analyse(load_mechanism(MECH / "helical_reduction.yaml")))          # its code on disk now
    assert other.choice(n=1).path == "llvm" and not other.compiled_llvm()
    assert sol.choice("full", "auto", 10).path == "numpy" and sol.choice("full", "auto", 10).note is None
    with pytest.raises(ValueError, match="backend 'llvm' solves method 'block' only"):
        sol.choice("full", "llvm")


def test_many_small_calls_compile_once_they_add_up(monkeypatch, tmp_path):
    """A run of small calls (a simulation's steps) counts its samples, each call as at least
    CALL_SAMPLES (numpy's fixed cost a call): numpy until they reach FIRST_CALL_SAMPLES,
    llvm after (a mutant that forgot the count, or the floor, would stay on numpy)."""
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))
    an = analyse(parse_mechanism(serial_chain(6)))
    q = np.zeros((1000, an.dof))
    seen = [solve(an, q, q, q).backend for _ in range(6)]
    assert seen == ["numpy"] * 4 + ["llvm"] * 2
    an = analyse(parse_mechanism(serial_chain(5)))          # 4-sample calls count CALL_SAMPLES each
    q = np.zeros((4, an.dof))
    calls = backends.FIRST_CALL_SAMPLES // backends.CALL_SAMPLES
    seen = [solve(an, q, q, q).backend for _ in range(calls + 1)]
    assert seen == ["numpy"] * (calls - 1) + ["llvm"] * 2


def test_unavailable_without_a_kernel_program():
    """A mechanism the kernel program does not cover: llvm refused with the reason, "auto"
    takes numpy."""
    an = analyse(load_mechanism(MECH / "coaxial_fig5.yaml"))
    sol = solver_for(an)
    sol.kernel_problem = "a stand-in reason"
    q = np.zeros((3, an.dof))
    with pytest.raises(ValueError, match="backend 'llvm' unavailable: a stand-in reason"):
        solve(an, q, q, q, backend="llvm")
    res = solve(an, q, q, q)
    assert (res.backend, res.backend_note) == ("numpy", "a stand-in reason")
    assert sol.choice().fallback


def test_both_pattern_codings_are_generated():
    """Bendix's signed blocks are a switch into straight-line code, planetary_3p's 2^6
    pattern maps a global table (their results: test_kernel.py)."""
    small = solver_for(analyse(load_mechanism(MECH / "bendix_wrist.yaml"))).llvm_kernel().jit.ir
    big = solver_for(analyse(load_mechanism(MECH / "planetary_3p.yaml"))).llvm_kernel().jit.ir
    assert "switch i64" in small and '@"ainv_' not in small
    assert '@"ainv_b0" = internal constant [' in big
    assert SWITCH_LIMIT < 64 * (32 + 6) * 30


def test_only_contraction_is_allowed():
    """No fast-math flag but ``contract`` (NaN must reach the sign search)."""
    text = solver_for(analyse(load_mechanism(MECH / "bendix_wrist.yaml"))).llvm_kernel().jit.ir
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


def _compiled_sincos():
    """A function f(x, c, s, n) writing the generated cos, sin of x[i] (llvm.trig.sincos)."""
    import ctypes

    import llvmlite.ir as ir

    from gearcli.dynamics.llvm.build import DP, I64, Emitter
    from gearcli.dynamics.llvm.driver import Jit
    from gearcli.dynamics.llvm.trig import sincos

    mod = ir.Module("sincos_test")
    fn = ir.Function(mod, ir.FunctionType(ir.VoidType(), [DP, DP, DP, I64]), "f")
    entry, body, done = (fn.append_basic_block(s) for s in ("entry", "body", "done"))
    b = ir.IRBuilder(entry)
    b.branch(body)
    b.position_at_end(body)
    i = b.phi(I64)
    i.add_incoming(ir.Constant(I64, 0), entry)
    e = Emitter(b, mod)
    c, s = sincos(e, e.load(fn.args[0], i))
    e.store(c, fn.args[1], i)
    e.store(s, fn.args[2], i)
    i1 = b.add(i, ir.Constant(I64, 1))
    i.add_incoming(i1, b.block)
    b.cbranch(b.icmp_signed("<", i1, fn.args[3]), body, done)
    b.position_at_end(done)
    b.ret_void()
    jit = Jit(mod)
    f = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int64)(jit.address("f"))
    return jit, f


def test_inline_sincos_matches_libm():
    """Within 2 ulp-sized steps (4e-16 absolute) of numpy's cos and sin: random angles, the
    quadrant boundaries k pi/4 and their neighbours, angles near the libm fallback limit and
    far beyond it; NaN and infinities give NaN."""
    rng = np.random.default_rng(4)
    k = np.arange(-400, 401) * (np.pi / 4)
    x = np.concatenate([rng.uniform(-20, 20, 20_000), rng.uniform(-1e5, 1e5, 2000), k, np.nextafter(k, 10),
                        np.nextafter(k, -10), [0.0, -0.0, 1e-300, 99_999.9, 100_000.1, -3e7, 1e15]])
    jit, f = _compiled_sincos()
    c, s = np.empty_like(x), np.empty_like(x)
    f(x.ctypes.data, c.ctypes.data, s.ctypes.data, x.size)
    assert np.abs(c - np.cos(x)).max() < 4e-16 and np.abs(s - np.sin(x)).max() < 4e-16
    bad = np.array([np.nan, np.inf, -np.inf])
    c, s = np.empty(3), np.empty(3)
    f(bad.ctypes.data, c.ctypes.data, s.ctypes.data, 3)
    assert np.isnan(c).all() and np.isnan(s).all()


def test_auto_takes_numpy_when_llvmlite_does_not_import():
    """Without llvmlite (its import blocked in a fresh process) "auto" solves with numpy and
    says why, backend "llvm" is refused with the reason, and the CLI prints one notice."""
    block = "import sys; sys.modules['llvmlite'] = None; sys.modules['llvmlite.binding'] = None; sys.modules['llvmlite.ir'] = None; "
    code = (block + "import numpy as np; from gearcli import analyse, load_mechanism, solve; "
            f"an = analyse(load_mechanism({str(MECH / 'bendix_wrist.yaml')!r})); q = np.zeros((9000, an.dof)); "
            "r = solve(an, q, q, q); print(r.backend, '|', r.backend_note)\n"
            "try:\n    solve(an, q, q, q, backend='llvm')\nexcept ValueError as e:\n    print(e)")
    env = {"PYTHONPATH": str(ROOT / "src"), "PATH": "/usr/bin:/bin"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.splitlines() == ["numpy | llvmlite does not import",
                                       "backend 'llvm' unavailable: llvmlite does not import"]


def test_an_unknown_backend_is_refused():
    """Only "auto", "llvm" and "numpy" (the retired numba kernel's "kernel" is an unknown
    name now: issue 39 removed its remains)."""
    from pathlib import Path
    an = analyse(load_mechanism(Path(__file__).resolve().parents[1] / "mechanisms" / "paper_2dof.yaml"))
    q = np.zeros((2, an.dof))
    for name in ("kernel", "numba", ""):
        with pytest.raises(ValueError, match=rf"^unknown backend '{name}' \(expected one of auto, llvm, numpy\)"):
            solve(an, q, q, q, backend=name)


def _paper_with_loads(count: int):
    """paper_2dof with ``count`` external loads on its two moving links (both frames)."""
    import yaml  # noqa: PLC0415

    doc = yaml.safe_load((MECH / "paper_2dof.yaml").read_text())
    links = [ln["name"] for ln in doc["links"] if ln["name"] != doc["base"]][:2]
    rng = np.random.default_rng(count)
    doc["loads"] = [{"name": f"l{i}", "link": links[i % 2], "frame": ("link", "base")[i // 2 % 2],
                     "point": [float(v) for v in rng.normal(size=3) * 0.1],
                     "force": [float(v) for v in rng.normal(size=3)],
                     "moment": [float(v) for v in rng.normal(size=3)]} for i in range(count)]
    return analyse(parse_mechanism(yaml.safe_dump(doc)))


def test_loads_are_run_time_data():
    """The kernel's code does not grow with the number of loads (issue 17: 1,000 constant
    loads compiled for 94 s): 4 and 400 loads on the same links give the same IR, and the
    400 loads' results equal the numpy path's."""
    few, many = _paper_with_loads(4), _paper_with_loads(400)
    ir_few = solver_for(few).llvm_kernel().jit.ir
    assert solver_for(many).llvm_kernel().jit.ir == ir_few
    q = np.random.default_rng(3).normal(size=(50, many.dof))
    ref = solve(many, q, q, q, backend="numpy")
    res = solve(many, q, q, q, backend="llvm")
    for f in ("motor", "joint"):
        a, b = getattr(res, f).reshape(50, -1), getattr(ref, f).reshape(50, -1)
        assert np.max(np.abs(a - b).max(axis=1) / (1 + np.abs(b).max(axis=1))) < 1e-12
