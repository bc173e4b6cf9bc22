"""The disk cache of the llvm kernels' machine code (dynamics/llvm_cache.py, Jit): a fresh
process loads what another compiled, bitwise the same results as compiling in memory;
corrupted, truncated or unwritable caches fall back to compiling; keys tell hosts apart."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("llvmlite")

from big_mechanisms import serial_chain  # noqa: E402
from cache_faults import SPECIAL, make_special  # noqa: E402
from gearcli import analyse, load_mechanism, parse_mechanism  # noqa: E402
from gearcli.dynamics import backends  # noqa: E402
from gearcli.dynamics.llvm import cache as llvm_cache  # noqa: E402
from gearcli.dynamics.solve import solve, solver_for  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
BENDIX = ROOT / "mechanisms" / "bendix_wrist.yaml"
PAPER = ROOT / "mechanisms" / "paper_2dof.yaml"

# A fresh process: solve 200 random samples (one with angles of 3e5 rad) with the llvm kernel (cache on or off), print
# whether its code came from the cache, was stored, and every output array's bytes (hex).
CHILD = """
import json, sys, numpy as np
from gearcli import analyse, load_mechanism
from gearcli.dynamics.solve import solve, solver_for
from gearcli.dynamics.llvm import cache as llvm_cache
from gearcli.dynamics.llvm import driver as llvm_driver
if sys.argv[2] == "off":
    jit = llvm_driver.Jit
    llvm_driver.Jit = lambda module, **kw: jit(module, cache=False, **kw)
if sys.argv[2] == "other generator":   # as if the IR generator's source had changed
    llvm_driver.generator_digest = lambda: "0" * 64
an = analyse(load_mechanism(sys.argv[1]))
rng = np.random.default_rng(7)
q, qd, qdd = (rng.uniform(-2, 2, (200, an.dof)) for _ in range(3))
q[0] = 3e5                       # beyond the inline sin/cos: calls libm (a relocation in the object code)
r = solve(an, q, qd, qdd, backend="llvm", jobs=1)
k = solver_for(an).llvm_kernel()
arrays = {k2: v.tobytes().hex() for k2, v in sorted(vars(r).items()) if isinstance(v, np.ndarray)}
built = k.build_seconds > 0
key_of_ir = llvm_cache.object_key(k.jit.ir, llvm_driver.host_identity())   # the IR this code generates
print(json.dumps({"from_cache": k.jit.from_cache, "stored": k.jit.stored, "by_program": k.jit.by_program,
                  "built": built, "ir_is_key": key_of_ir == k.jit.key, "arrays": arrays}))
"""


def run_child(cache_dir, mode: str = "on", mech: Path = BENDIX) -> dict:
    env = {"PYTHONPATH": str(ROOT / "src"), "PATH": "/usr/bin:/bin", "GEARCLI_CACHE_DIR": str(cache_dir)}
    out = subprocess.run([sys.executable, "-c", CHILD, str(mech), mode], capture_output=True, text=True,
                         env=env, timeout=300)
    assert out.returncode == 0, (out.returncode, out.stderr[-2000:])    # a crash signal: negative
    assert out.stderr == ""                      # no warning, no traceback, whatever the cache
    return json.loads(out.stdout)


def objects(cache_dir) -> list[Path]:
    return sorted((Path(cache_dir) / "llvm").glob("*.obj"))


def test_second_process_loads_from_the_cache(tmp_path):
    """First process compiles and stores, second loads (no LLVM pass), a third with the
    cache off compiles in memory: the three give bitwise identical results."""
    first, second = run_child(tmp_path), run_child(tmp_path)
    memory = run_child(tmp_path / "unused", "off")
    assert (first["from_cache"], first["stored"]) == (False, True)
    assert (second["from_cache"], second["stored"]) == (True, False)
    assert (memory["from_cache"], memory["stored"]) == (False, False)
    assert not (tmp_path / "unused" / "llvm").exists()     # (the schedule cache may use the folder)
    assert len(first["arrays"]) > 3 and first["arrays"] == second["arrays"] == memory["arrays"]
    assert len(objects(tmp_path)) == 1
    # the second found the code by program key without generating the IR; generated on
    # demand afterwards, that IR is the one the stored code was compiled from
    assert (first["by_program"], first["built"]) == (False, True)
    assert (second["by_program"], second["built"]) == (True, False)
    assert first["ir_is_key"] and second["ir_is_key"] and memory["ir_is_key"]


def test_another_generator_source_does_not_load_by_program(tmp_path):
    """The program key hashes the IR generator's source: with another digest the note is
    not found, the IR is generated and its own key finds the same object code."""
    first = run_child(tmp_path)
    other = run_child(tmp_path, "other generator")
    assert (other["from_cache"], other["by_program"], other["built"], other["stored"]) == (True, False, True, False)
    assert other["arrays"] == first["arrays"] and other["ir_is_key"]
    assert len(list((tmp_path / "llvm").glob("*.prog"))) == 2


def test_generator_lists_every_module_the_ir_comes_from():
    """Every module of gearcli.dynamics that a GENERATOR module imports is in GENERATOR,
    except those whose output the program key hashes (the program and its record layouts, the cache's own key format)
    or that only run the code (threads; the losses' numpy formulas and the bearing friction's
    fixed point around the kernel); so is every module of dynamics/llvm/."""
    import ast  # noqa: PLC0415
    import os  # noqa: PLC0415

    from gearcli.dynamics.llvm.driver import GENERATOR  # noqa: PLC0415

    here = ROOT / "src" / "gearcli" / "dynamics" / "llvm"
    exempt = {"cache", "program", "basis", "records", "loss_program", "lossy_maps", "terms", "output_maps", "jobs", "__init__",
              "../losses", "../bearing_friction", "../../__version__"}
    assert {p.stem for p in here.glob("*.py")} - exempt <= set(GENERATOR)
    for name in GENERATOR:
        path = (here / f"{name}.py").resolve()
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.ImportFrom) or not node.level:
                continue
            base = path.parents[node.level - 1]          # the package the relative import starts from
            used = [base / node.module.replace(".", "/")] if node.module else [base / a.name for a in node.names]
            used = [os.path.relpath(u, here.resolve()) for u in used]
            assert set(used) - exempt - SHAPE_ONLY <= set(GENERATOR), (name, used)


SHAPE_ONLY = {"../../model/mechanism", "../../analysis/tree", "../../spatial", "../../errors", "../../model/gears",
              "../../model/ratings"}
"""Modules the shared terms import for types, constants or numpy helpers of their numpy callers, never for IR."""


@pytest.mark.parametrize("damage", ["flip a byte", "truncate", "empty", "header only"])
def test_a_damaged_entry_is_recompiled(tmp_path, damage):
    reference = run_child(tmp_path)
    (obj,) = objects(tmp_path)
    data = bytearray(obj.read_bytes())
    if damage == "flip a byte":
        data[len(data) // 2] ^= 0x40
    elif damage == "truncate":
        data = data[: len(data) - 100]
    elif damage == "empty":
        data = bytearray()
    else:
        data = data[: len(llvm_cache.MAGIC) + 40]
    obj.write_bytes(bytes(data))
    again = run_child(tmp_path)
    assert (again["from_cache"], again["stored"]) == (False, True)
    assert again["arrays"] == reference["arrays"]
    assert run_child(tmp_path)["from_cache"] is True       # the rewritten entry is whole


def files_of(cache_dir, run) -> dict[str, Path]:
    """The .obj and .prog files ``run()`` adds to the cache, by suffix."""
    before = set((Path(cache_dir) / "llvm").glob("*")) if (Path(cache_dir) / "llvm").exists() else set()
    run()
    new = sorted(set((Path(cache_dir) / "llvm").glob("*")) - before)
    assert sorted(p.suffix for p in new) == [".obj", ".prog"]
    return {p.suffix: p for p in new}


@pytest.mark.parametrize("swap", ["entries and notes", "entries only", "notes only", "a note naming the other entry",
                                  "an entry copied over the other"])
def test_foreign_entries_are_never_run(tmp_path, swap):
    """Two mechanisms' kernel-cache entries swapped (issue 17: the checksum covered the
    payload only, so the other kernel's code ran: SIGABRT, SIGSEGV or values 1e300x too
    large): each process proves the entry is its own before the first call, else
    recompiles and repairs the entry; the results equal a clean run bit for bit (in a
    subprocess: a crash fails the test)."""
    clean = {m: run_child(tmp_path / "clean", "off", m) for m in (BENDIX, PAPER)}
    a = files_of(tmp_path, lambda: run_child(tmp_path, "on", BENDIX))
    b = files_of(tmp_path, lambda: run_child(tmp_path, "on", PAPER))
    data = {p: p.read_bytes() for f in (a, b) for p in f.values()}
    if swap in ("entries and notes", "entries only"):
        a[".obj"].write_bytes(data[b[".obj"]])
        b[".obj"].write_bytes(data[a[".obj"]])
    if swap in ("entries and notes", "notes only"):
        a[".prog"].write_bytes(data[b[".prog"]])
        b[".prog"].write_bytes(data[a[".prog"]])
    if swap == "a note naming the other entry":        # self-consistent, but for the other program
        a[".prog"].write_bytes(a[".prog"].stem.encode() + b" " + b[".obj"].stem.encode())
    if swap == "an entry copied over the other":
        a[".obj"].write_bytes(data[b[".obj"]])
    for m in (BENDIX, PAPER):
        got = run_child(tmp_path, "on", m)
        assert got["arrays"] == clean[m]["arrays"], m.name
        intact = m == PAPER and swap in ("a note naming the other entry", "an entry copied over the other")
        assert got["by_program"] == intact         # loaded by program only where its note and entry are its own
    for m in (BENDIX, PAPER):                                     # repaired: own entries, found by program
        again = run_child(tmp_path, "on", m)
        assert (again["from_cache"], again["by_program"], again["arrays"]) == (True, True, clean[m]["arrays"])
    assert sorted(p.name for p in (tmp_path / "llvm").iterdir()) == sorted(p.name for f in (a, b) for p in f.values())


@pytest.mark.parametrize("kind", SPECIAL)
@pytest.mark.parametrize("suffix", [".obj", ".prog"])
def test_a_special_file_as_entry_is_never_read(tmp_path, kind, suffix):
    """A FIFO or /dev/zero in an entry's place blocked for ever (issue 17): only regular
    files are opened; the special file is removed and the entry written again (a folder
    that is not empty stays: then the kernel is compiled in memory), results unchanged."""
    reference = run_child(tmp_path)
    (path,) = (tmp_path / "llvm").glob(f"*{suffix}")
    make_special(path, kind, full=True)
    got = run_child(tmp_path)                 # (a timeout: the test fails)
    assert got["arrays"] == reference["arrays"] and not got["by_program"]
    if kind == "folder":
        assert path.is_dir() and not path.is_symlink()
    else:
        assert path.is_file() and not path.is_symlink() and run_child(tmp_path)["by_program"]


@pytest.mark.skipif(hasattr(os, "geteuid") and os.geteuid() == 0, reason="root writes anywhere")
def test_a_read_only_dir_compiles_in_memory(tmp_path):
    (tmp_path / "llvm").mkdir()
    os.chmod(tmp_path / "llvm", 0o500)
    try:
        got = run_child(tmp_path)
    finally:
        os.chmod(tmp_path / "llvm", 0o700)
    assert (got["from_cache"], got["stored"]) == (False, False)


@pytest.mark.parametrize("where", ["a file, not a folder", "below a file", "/proc: no folder can be made"])
def test_an_unusable_location_compiles_in_memory(tmp_path, where):
    """Works as root too (a file in the way cannot be a folder)."""
    (tmp_path / "f").write_text("x")
    cache = {"a file, not a folder": tmp_path / "f", "below a file": tmp_path / "f" / "deeper",
             "/proc: no folder can be made": Path("/proc/gearcli-test")}[where]
    got = run_child(cache)
    assert (got["from_cache"], got["stored"]) == (False, False)
    assert run_child(tmp_path / "ok")["arrays"] == got["arrays"]


def test_concurrent_cold_compiles(tmp_path):
    """Four processes compiling two kernels (two each) into an empty cache at once: all
    store atomically, the entries left are whole (the next process of each loads by
    program), no temporary file is left, and every result equals a clean run bit for bit."""
    clean = {m: run_child(tmp_path / "clean", "off", m) for m in (BENDIX, PAPER)}
    env = {"PYTHONPATH": str(ROOT / "src"), "PATH": "/usr/bin:/bin", "GEARCLI_CACHE_DIR": str(tmp_path / "c")}
    mechs = [BENDIX, PAPER, BENDIX, PAPER]
    procs = [subprocess.Popen([sys.executable, "-c", CHILD, str(m), "on"], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, env=env, text=True) for m in mechs]
    outs = [p.communicate(timeout=600) for p in procs]
    assert [p.returncode for p in procs] == [0] * 4, [e[-2000:] for _, e in outs]
    for m, (out, err) in zip(mechs, outs):
        assert err == "" and json.loads(out)["arrays"] == clean[m]["arrays"]
    assert len(objects(tmp_path / "c")) == 2 and not list((tmp_path / "c").rglob(".gearcli.*"))
    for m in (BENDIX, PAPER):
        again = run_child(tmp_path / "c", "on", m)
        assert (again["by_program"], again["arrays"]) == (True, clean[m]["arrays"])


def test_host_identity_names_cpu_and_features():
    from gearcli.dynamics.llvm.driver import _host, host_identity  # noqa: PLC0415

    cpu, features = _host()
    assert f"|{cpu}|{features}|" in host_identity() and cpu


def test_keys_depend_on_ir_and_host():
    ir = "define i64 @f() {\n  ret i64 1\n}\n"
    host = "x86_64-unknown-linux-gnu|znver3|+avx2,+fma|0.44.0|(20, 1, 0)"
    key = llvm_cache.object_key(ir, host)
    assert len(key) == 64 and key == llvm_cache.object_key(ir, host)
    assert key != llvm_cache.object_key(ir.replace("1", "2"), host)
    assert key != llvm_cache.object_key(ir, host.replace("+avx2", "-avx2"))
    assert key != llvm_cache.object_key(ir, host.replace("znver3", "skylake"))
    assert key != llvm_cache.object_key(ir, host.replace("0.44.0", "0.45.0"))


def test_program_key_follows_the_program_and_loads():
    from gearcli.dynamics.llvm.driver import host_identity, mech_loads  # noqa: PLC0415

    a, b = (solver_for(analyse(parse_mechanism(serial_chain(n)))) for n in (3, 3))
    other = solver_for(analyse(parse_mechanism(serial_chain(4))))
    host = host_identity()

    def key(sol, loads=None, host=host):
        fingerprint = llvm_cache.program_fingerprint(sol.kernel_program(), mech_loads(sol.an) if loads is None else loads)
        return llvm_cache.program_key(fingerprint, host, "1")
    assert key(a) == key(b)
    assert key(a) != key(other)
    assert key(a) != key(a, host=host + "x")
    assert key(a) != key(a, [(1, True, np.zeros(3))])


def test_auto_counts_a_cached_kernel_as_cheap(tmp_path, monkeypatch):
    """A 15-link chain: with an empty disk cache "auto" solves 10 samples by numpy (the
    first-call rule); once its code is on disk (another analysis compiled it) "auto" takes
    llvm for 10 samples, loading it."""
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))
    first = solver_for(analyse(parse_mechanism(serial_chain(15))))
    assert not backends.llvm_on_disk(first)
    assert first.choice(n=10).path == "numpy"
    q = np.zeros((2, first.an.dof))
    solve(first.an, q, q, q, backend="llvm")
    second = solver_for(analyse(parse_mechanism(serial_chain(15))))
    assert backends.llvm_on_disk(second)
    assert second.choice(n=10).path == "llvm"
    assert second.llvm_kernel().jit.from_cache
    assert "run:" in second.llvm_kernel().jit.assembly()    # optimised again on demand


def test_programs_sharing_one_ir_share_the_entry(tmp_path, monkeypatch):
    """Two kernel programs that differ only in a load's point (a run-time array) generate the
    same IR: the second finds
    the first's entry by its IR key, adds its own fingerprint to it (no second entry) and is
    found by program from then on, and so is the first; a program not in the entry is not."""
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))

    def kernel(text):
        s = solver_for(analyse(parse_mechanism(text)))
        q = np.zeros((2, s.an.dof))
        solve(s.an, q, q, q, backend="llvm", jobs=1)
        return s.llvm_kernel().jit
    load = "loads:\n  - {name: tip, link: L3, point: [P, 0, 0], frame: base, force: [0, 10, 0], moment: [0, 0, 0]}\n"
    a, b = serial_chain(3) + load.replace("P", "0.5"), serial_chain(3) + load.replace("P", "0.25")
    first = kernel(a)
    assert (first.from_cache, first.stored) == (False, True)
    second = kernel(b)
    assert (second.from_cache, second.by_program, second.key) == (True, False, first.key)
    assert len(objects(tmp_path)) == 1
    assert kernel(b).by_program and kernel(a).by_program
    (obj,) = objects(tmp_path)
    assert llvm_cache.load(obj.stem, "0" * 64) is None and llvm_cache.load(obj.stem) is not None


def test_prune_keeps_the_newest(tmp_path):
    for i in range(6):
        (tmp_path / f"{i:064x}.obj").write_bytes(b"x" * 100)
        os.utime(tmp_path / f"{i:064x}.obj", (1000 + i, 1000 + i))
    (tmp_path / ".gearcli.a.tmp").write_bytes(b"")
    os.utime(tmp_path / ".gearcli.a.tmp", (1, 1))
    llvm_cache.prune(tmp_path, max_entries=4, max_bytes=10**6)
    assert sorted(p.stem[-1] for p in tmp_path.glob("*.obj")) == ["2", "3", "4", "5"]
    llvm_cache.prune(tmp_path, max_entries=10, max_bytes=250)
    assert sorted(p.stem[-1] for p in tmp_path.glob("*.obj")) == ["4", "5"]
    assert not (tmp_path / ".gearcli.a.tmp").exists()
