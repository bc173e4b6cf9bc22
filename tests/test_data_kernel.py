"""The data kernel (issue 37, "parameters as run-time data"): one compiled kernel whose links'
masses, centres of mass and inertias are run-time data solves every variant of those values
as the numpy path solves that variant's own mechanism, losses included."""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from gearcli import analyse, load_mechanism, solve
from gearcli.dynamics.solve import Solver

ROOT = Path(__file__).resolve().parents[1]


def _worst(a, b, n):
    """Largest difference of the motor torques and joint reactions, per sample relative to
    the sample's largest reaction."""
    scale = np.abs(b.joint.reshape(n, -1)).max(axis=1)
    d = np.maximum(np.abs(a.motor - b.motor).max(axis=1), np.abs(a.joint - b.joint).reshape(n, -1).max(axis=1))
    return float((d / scale).max())


@pytest.mark.parametrize("name", ["bendix_wrist_rated", "cobot_6axis", "scara", "planetary_3p"])
def test_one_kernel_solves_every_inertial_variant(name):
    base = load_mechanism(ROOT / "mechanisms" / f"{name}.yaml")
    an = analyse(base)
    data = Solver(an, data_bodies=True)
    rng = np.random.default_rng(3)
    n = 1500
    q, qd, qdd = (0.3 * rng.uniform(-1, 1, (n, an.dof)) for _ in range(3))
    for k, scale in enumerate((1.0, 1.7, 0.4)):
        links = tuple(dataclasses.replace(L, mass=L.mass * scale, com=np.asarray(L.com) + 0.01 * k,
                                          inertia=np.asarray(L.inertia) * scale) if L.mass else L for L in base.links)
        variant = analyse(dataclasses.replace(base, links=links))
        got = data.solve_bodies(variant, q, qd, qdd)
        assert got.backend == "llvm"
        assert _worst(got, solve(variant, q, qd, qdd, backend="numpy"), n) < 1e-12
        if k:                          # the variant's values, not the first ones the kernel saw
            assert np.abs(got.motor - solve(an, q, qd, qdd, backend="numpy").motor).max() > 1e-6 * np.abs(got.motor).max()
    assert data.llvm_kernel().prog.data_bodies and np.isnan(data.llvm_kernel().prog.bodies["mass"]).all()


def test_solve_bodies_needs_a_data_solver_and_the_same_links():
    an = analyse(load_mechanism(ROOT / "mechanisms" / "paper_2dof.yaml"))
    with pytest.raises(ValueError, match="data_bodies=True"):
        Solver(an).solve_bodies(an, np.zeros((2, an.dof)), np.zeros((2, an.dof)), np.zeros((2, an.dof)))
    other = analyse(load_mechanism(ROOT / "mechanisms" / "bendix_wrist.yaml"))
    with pytest.raises(ValueError, match="set_bodies"):
        Solver(an, data_bodies=True).solve_bodies(other, np.zeros((2, an.dof)), np.zeros((2, an.dof)),
                                                  np.zeros((2, an.dof)))


def test_threads_sharing_a_data_kernel_keep_their_own_values():
    """A Dask worker's threads share one data kernel: each thread's variant is solved with its
    own values (they were one attribute of the kernel: a thread could solve with another's)."""
    from concurrent.futures import ThreadPoolExecutor
    base = load_mechanism(ROOT / "mechanisms" / "bendix_wrist_rated.yaml")
    an = analyse(base)
    data = Solver(an, data_bodies=True)
    rng = np.random.default_rng(5)
    n = 4000
    q, qd, qdd = (rng.uniform(-1, 1, (n, an.dof)) for _ in range(3))
    variants = [analyse(dataclasses.replace(base, links=tuple(
        dataclasses.replace(L, mass=L.mass * s) if L.mass else L for L in base.links))) for s in (0.5, 1.0, 2.0, 3.0)]
    want = [solve(v, q, qd, qdd, backend="numpy").motor for v in variants]
    data.solve_bodies(an, q[:2], qd[:2], qdd[:2])          # compiled before the threads start

    def run(k):
        return [data.solve_bodies(variants[k], q, qd, qdd).motor for _ in range(5)]
    with ThreadPoolExecutor(4) as pool:
        got = list(pool.map(run, range(4)))
    for k in range(4):
        assert all(np.allclose(g, want[k], rtol=0, atol=1e-12 * np.abs(want[k]).max()) for g in got[k])


VARIANTS = {   # (mechanism, the text a variant changes, its values): constants of the kernel, not run-time arrays
    "reducer ratio": ("cobot_6axis", "teeth: [200, 202]", ("teeth: [160, 162]", "teeth: [100, 102]")),
    "reducer efficiency": ("cobot_6axis", "efficiency: {forward: 0.78, backward: 0.65}",
                           ("efficiency: {forward: 0.7, backward: 0.5}", "efficiency: {forward: 0.9, backward: 0.8}")),
    "link mass": ("bendix_wrist_rated", "mass: 0.8", ("mass: 0.95", "mass: 1.3")),
}


@pytest.mark.parametrize("case", sorted(VARIANTS))
def test_variants_of_a_constant_share_one_compile(case, tmp_path, monkeypatch):
    """The kernel's constants are data (its constant pool, dynamics/llvm/build.py): mechanisms
    differing in a ratio, an efficiency or a mass generate the same IR, and the second and
    third are linked from the first one's object code (no compile), each solving with its
    own values as the numpy path solves its own mechanism (to 1e-12 of each sample's largest
    reaction), with and without the disk cache."""
    from gearcli import parse_mechanism
    from gearcli.dynamics.llvm import driver
    name, old, news = VARIANTS[case]
    text = (ROOT / "mechanisms" / f"{name}.yaml").read_text()
    assert text.count(old) >= 1
    rng = np.random.default_rng(5)
    for cache in ("on", "off"):
        monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path / "cache") if cache == "on" else "/dev/null/none")
        monkeypatch.setattr(driver, "_RECENT", {})
        keys, base_an = [], None
        for k, variant in enumerate((text,) + tuple(text.replace(old, new, 1) for new in news)):
            an = analyse(parse_mechanism(variant, file=f"{name}-{k}.yaml"))
            n = 400
            q, qd, qdd = (rng.uniform(-1, 1, (n, an.dof)) for _ in range(3))
            s = Solver(an, backend="llvm", jobs=1)
            got, ref = s.solve(q, qd, qdd), solve(an, q, qd, qdd, backend="numpy")
            assert got.backend == "llvm" and _worst(got, ref, n) < 1e-12
            jit = s.llvm_kernel().jit
            keys.append(jit.key)
            assert jit.from_cache == (k > 0), (cache, k)
            base_an = base_an if k else an
            if k:                      # the variant's own values, not the first one's
                assert np.abs(got.motor - solve(base_an, q, qd, qdd, backend="numpy").motor).max() > 1e-9
        assert len(set(keys)) == 1


def test_a_note_with_damaged_constants_is_not_used(tmp_path, monkeypatch):
    """A program note holds the kernel's constant pool (the object code holds zeros): one whose
    values are damaged is deleted and the kernel's code regenerated, with the right results."""
    from gearcli.dynamics.llvm import driver
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))
    an = analyse(load_mechanism(ROOT / "mechanisms" / "paper_2dof.yaml"))
    q, qd, qdd = (np.random.default_rng(2).uniform(-1, 1, (50, an.dof)) for _ in range(3))
    ref = solve(an, q, qd, qdd, backend="numpy")
    Solver(an, backend="llvm").solve(q, qd, qdd)
    (note,) = (tmp_path / "llvm").glob("*.prog")
    data = bytearray(note.read_bytes())
    data[-3] ^= 0x10                           # a bit of the last constant
    note.write_bytes(bytes(data))
    monkeypatch.setattr(driver, "_RECENT", {})
    s = Solver(an, backend="llvm")
    got = s.solve(q, qd, qdd)
    assert not s.llvm_kernel().jit.by_program and s.llvm_kernel().jit.from_cache
    assert _worst(got, ref, 50) < 1e-12
    again = Solver(an, backend="llvm")         # the note written again, whole: found by program
    assert _worst(again.solve(q, qd, qdd), ref, 50) < 1e-12 and again.llvm_kernel().jit.by_program
