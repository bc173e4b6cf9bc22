"""The generated per-sample kernel (backend "llvm") against the numpy block solve.

The numpy path (:func:`gearcli.dynamics.blocks.solve_blocks` over arrays) is the reference:
the kernel shares none of its arithmetic (its own scalar kinematics, loads, column terms
and sign search, the code :mod:`gearcli.dynamics.llvm.kernel` generates), only the
constant block matrices.  Every result
must agree to 1e-12 of the largest load of the sample, on every bundled mechanism and on the
test factories' mechanisms, along random trajectories large enough that tooth forces change
sign, with external loads; threads must not change a bit; a sample with no consistent sign
pattern must be named as the numpy path names it; and a wrong program entry must be caught.
"""
from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

pytest.importorskip("llvmlite")

from big_mechanisms import binary_tree_urdf, geared_chain, serial_chain  # noqa: E402
from factories import paper_2dof_variant, planetary_2dof, spatial_3dof  # noqa: E402
from factories_own import PUMA_YAML, dh_geared, urdf_prismatic_chain  # noqa: E402
from metrics import nan_accelerations, per_sample_loads, sample_err  # noqa: E402
from gearcli import analyse, load_mechanism, parse_mechanism  # noqa: E402
from gearcli.dynamics.llvm.jobs import job_ranges, threads_for  # noqa: E402
from gearcli.dynamics import backends  # noqa: E402
from gearcli.dynamics.signs import SignError  # noqa: E402
from gearcli.dynamics.solve import solve, solver_for  # noqa: E402
from gearcli.io.urdf_reader import load_urdf, parse_urdf  # noqa: E402
from test_urdf import ERD, erd, talos_left_arm  # noqa: E402

MECH = Path(__file__).resolve().parents[1] / "mechanisms"
FIELDS = ("motor", "tau", "joint", "gear_t", "gear_sep", "gear_radial", "gear_axial", "motor_speed")
TOL = 1e-12
# the lossy bundled files too (their loss outputs are compared in tests/test_llvm_losses.py)
ALL_BUNDLED = sorted(p.name for p in MECH.glob("*.yaml")) + ["geared_arm.urdf"]
LOSSY = [k for k in ALL_BUNDLED if k.endswith(".yaml") and load_mechanism(MECH / k).has_losses]
BUNDLED = ALL_BUNDLED
BACKENDS = ["llvm"]


def _with_loads(text: str) -> str:
    """The mechanism with two external loads: one in link axes (per sample in the tests),
    one constant in base axes."""
    doc = yaml.safe_load(text)
    names = [ln["name"] for ln in doc["links"] if ln["name"] != doc["base"]]
    doc["loads"] = [
        {"name": "tip", "link": doc.get("end_effector", names[-1]), "point": [0.11, -0.03, 0.02],
         "frame": "link", "force": [1.0, 2.0, -3.0], "moment": [0.1, 0.0, 0.2]},
        {"name": "side", "link": names[0], "point": [0.0, 0.05, 0.01], "frame": "base",
         "force": [0.0, -4.0, 1.5], "moment": [0.3, -0.1, 0.0]}]
    return yaml.safe_dump(doc)


def mechanism(key: str):
    if key in ALL_BUNDLED:
        return load_mechanism(MECH / key)
    kind, _, arg = key.partition(":")
    makers = {
        "variant": lambda: parse_mechanism(paper_2dof_variant(np.random.default_rng(int(arg)))[0]),
        "spatial": lambda: parse_mechanism(spatial_3dof(j5_parent=arg or "1")[0]),
        "planetary": lambda: parse_mechanism(planetary_2dof()[0]),
        "dh_geared": lambda: parse_mechanism(dh_geared(int(arg))[0]),
        "puma": lambda: parse_mechanism(PUMA_YAML),
        "prismatic": lambda: parse_urdf(urdf_prismatic_chain(int(arg))[0]),
        "geared_chain": lambda: parse_mechanism(geared_chain(int(arg))),
        "serial_chain": lambda: parse_mechanism(serial_chain(int(arg))),
        "tree": lambda: parse_urdf(binary_tree_urdf(int(arg))),
        "loaded": lambda: parse_mechanism(_with_loads((MECH / arg).read_text())),
        "planets": lambda: _planets("planetary_5p.yaml", arg),
        "servo": lambda: _planets("servo_joint.yaml", arg),
    }
    return makers[kind]()


def _planets(name: str, n: str):
    """A bundled mechanism with n planets in its planet set."""
    return parse_mechanism(re.sub(r"planets: \d+", f"planets: {n}", (MECH / name).read_text()))


GENERATED = ["variant:1", "variant:2", "spatial:1", "spatial:0", "planetary", "dh_geared:3", "puma",
             "prismatic:5", "geared_chain:7", "serial_chain:7", "tree:3",
             "loaded:paper_2dof.yaml", "loaded:bendix_wrist.yaml", "planets:9"]


def trajectory(an, n, seed=0):
    rng = np.random.default_rng(seed)
    return (rng.uniform(-np.pi, np.pi, (n, an.dof)), rng.normal(size=(n, an.dof)) * 3.0,
            rng.normal(size=(n, an.dof)) * 20.0)


def worst(a, b) -> float:
    """The per-sample error of :func:`metrics.sample_err` over this file's fields."""
    return sample_err(a, b, FIELDS)


def compiled_backend(an) -> None:
    """The generated kernel covers every mechanism here: "auto" takes llvm (a large call)."""
    sol = solver_for(an)
    assert sol.llvm_available() and sol.choice() == backends.Choice("llvm")


@pytest.mark.parametrize("key", ALL_BUNDLED + GENERATED + ["planets:15", "servo:12"])
def test_auto_backend_of_every_mechanism(key):
    """The path "auto" takes for a large call on every bundled mechanism (servo_joint.yaml,
    planetary_5p.yaml and the lossy servo_joint_rated.yaml among them), every test-factory
    mechanism, planetary_5p with 9 and 15 planets (one block of 18 and 30 signed meshes,
    more than signs.MAX_EXHAUSTIVE: the own-sign trials only) and servo_joint with 12 (a
    world-frame block of 25): llvm.  The robots:
    test_kernel_equals_numpy_on_robots."""
    assert solver_for(analyse(mechanism(key))).choice() == backends.Choice("llvm")


def test_auto_backend_cases_are_all_there():
    """The mechanisms issue 18 names are in the list above (a renamed file fails here)."""
    assert {"servo_joint.yaml", "planetary_5p.yaml", "bendix_wrist.yaml", "geared_arm.urdf"} <= set(BUNDLED)
    assert LOSSY == ["cobot_6axis.yaml", "cobot_joint.yaml", "cobot_joint_csf14.yaml", "planetary_3p_rated.yaml",
                     "rv_turret.yaml", "scara.yaml", "screw_lift.yaml", "servo_joint_rated.yaml", "turntable_dwell.yaml",
                     "worm_lift.yaml"]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("key", BUNDLED + GENERATED)
def test_kernel_equals_numpy(key, backend):
    an = analyse(mechanism(key))
    compiled_backend(an)
    q, qd, qdd = trajectory(an, 600)
    loads = per_sample_loads(an, 600)
    ref = solve(an, q, qd, qdd, backend="numpy", loads=loads)
    res = solve(an, q, qd, qdd, backend=backend, loads=loads, jobs=1)
    assert worst(res, ref) < TOL
    geared = [i for i, c in enumerate(an.circuits) if c.geometry is not None]
    for i in geared:                                      # both branches of |t| exercised
        assert (ref.gear_t[:, i] > 0).any() and (ref.gear_t[:, i] < 0).any()


@pytest.mark.skipif(ERD is None, reason="example-robot-data not installed")
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("case", ["ur_description/urdf/ur5_robot.urdf", "panda_description/urdf/panda.urdf",
                                  "talos_left_arm", "talos_data/robots/talos_full_v2.urdf"])
def test_kernel_equals_numpy_on_robots(case, backend, tmp_path):
    """Published robots; Talos' transmissions and mimic joints need world-frame blocks."""
    path = talos_left_arm(tmp_path) if case == "talos_left_arm" else erd(case)
    an = analyse(load_urdf(path))
    compiled_backend(an)
    q, qd, qdd = trajectory(an, 200)
    assert worst(solve(an, q, qd, qdd, backend=backend), solve(an, q, qd, qdd, backend="numpy")) < TOL


def test_low_rank_block_without_hot_patterns():
    """planetary_5p's block (10 signed meshes, 1,024 patterns) solved from one base matrix
    (pattern_maps.LowRank): with no hot pattern every trial is the generated k x k solve
    (llvm.dense_solve), which must equal the numpy path's direct pattern maps too."""
    from gearcli.dynamics.external import load_values
    from gearcli.dynamics.llvm.driver import LlvmKernel
    from gearcli.dynamics.result_arrays import result_arrays, work_arrays

    an = analyse(mechanism("planetary_5p.yaml"))
    prog = solver_for(an).kernel_program()
    assert prog.lowrank and prog.hot[0][0][0] == 0
    cold = dataclasses.replace(prog, hot={})
    n = 600
    q, qd, qdd = trajectory(an, n)
    ref = solve(an, q, qd, qdd, backend="numpy")
    arrays, work = result_arrays(an, n, None), work_arrays(n, len(prog.signed), None)
    LlvmKernel(cold, an).solve(an, q, qd, qdd, load_values(an.mech, n), 1, n, arrays, work)
    assert worst(type(ref)(**arrays), ref) < TOL


def test_redundant_world_block_by_kkt_and_by_basis():
    """servo_joint's redundant world-frame block is solved through a square basis (its two
    free planet meshes, llvm.basis._free_columns); without one, from the KKT system:
    both generated solves must equal the numpy path (sharing.least_load_solve)."""
    from gearcli.dynamics.external import load_values
    from gearcli.dynamics.llvm.driver import LlvmKernel
    from gearcli.dynamics.result_arrays import result_arrays, work_arrays

    an = analyse(mechanism("servo_joint.yaml"))
    prog = solver_for(an).kernel_program()
    assert prog.free and len(prog.free[0][0]) == 2
    n = 300
    q, qd, qdd = trajectory(an, n)
    ref = solve(an, q, qd, qdd, backend="numpy")
    assert worst(solve(an, q, qd, qdd, backend="llvm"), ref) < TOL
    arrays, work = result_arrays(an, n, None), work_arrays(n, len(prog.signed), None)
    LlvmKernel(dataclasses.replace(prog, free={}), an).solve(an, q, qd, qdd, load_values(an.mech, n), 1, n,
                                                             arrays, work)
    assert worst(type(ref)(**arrays), ref) < TOL


def test_static_pivots_fall_back_to_pivoting(monkeypatch, tmp_path):
    """With a pivot growth of 1 nearly every sample's basis solve finds a static pivot
    smaller than an entry below it and takes the pivoting loop code (llvm.world.lu_solve):
    that branch too must equal the numpy path."""
    from gearcli.dynamics.llvm import world as llvm_world
    from gearcli.dynamics.external import load_values
    from gearcli.dynamics.llvm.driver import LlvmKernel
    from gearcli.dynamics.result_arrays import result_arrays, work_arrays

    monkeypatch.setattr(llvm_world, "PIVOT_GROWTH", 1.0)
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))     # compiled with it, not the cached kernel
    an = analyse(mechanism("servo_joint.yaml"))
    prog = solver_for(an).kernel_program()
    n = 300
    q, qd, qdd = trajectory(an, n)
    ref = solve(an, q, qd, qdd, backend="numpy")
    arrays, work = result_arrays(an, n, None), work_arrays(n, len(prog.signed), None)
    kernel = LlvmKernel(prog, an)
    assert not kernel.jit.from_cache
    kernel.solve(an, q, qd, qdd, load_values(an.mech, n), 1, n, arrays, work)
    assert worst(type(ref)(**arrays), ref) < TOL


def test_general_blocks_are_exercised():
    """geared_arm.urdf has a block without a constant frame (a transmission), servo_joint.yaml
    a redundant one (a helical stage into a 3-planet planetary whose sun turns: the sun
    shaft's meshes are fixed in the housing and in the carrier); the kernel's world-frame
    solves (square: eliminated; redundant: the KKT system) are compared above."""
    an = analyse(mechanism("geared_arm.urdf"))
    assert any(p.F is None for p in solver_for(an).plans)
    servo = solver_for(analyse(mechanism("servo_joint.yaml")))
    assert any(p.F is None and p.offs[-1] > 6 * len(p.links) for p in servo.plans)
    assert servo.kernel_program().weights and servo.choice().path == "llvm"


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("key", ["bendix_wrist.yaml", "loaded:bendix_wrist.yaml"])
def test_threads_change_no_bit(key, backend):
    an = analyse(mechanism(key))
    n = 20_001
    assert threads_for(n, 2) == 2 and len(job_ranges(n, 2)) == 16     # taken in turn
    q, qd, qdd = trajectory(an, n, seed=3)
    loads = per_sample_loads(an, n)
    one = solve(an, q, qd, qdd, jobs=1, loads=loads, backend=backend)
    two = solve(an, q, qd, qdd, jobs=2, loads=loads, backend=backend)
    for f in FIELDS:
        assert np.array_equal(getattr(one, f), getattr(two, f)), f


def _sign_error(an, q, qd, qdd, backend, chunk):
    with pytest.raises(SignError) as info, np.errstate(all="ignore"):
        solve(an, q, qd, qdd, backend=backend, chunk=chunk, jobs=2, check_finite=False)   # the NaN reaches the kernel
    return info.value.sample, info.value.meshes


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("key", ["paper_2dof.yaml", "bendix_wrist.yaml", "geared_arm.urdf", "planetary_3p.yaml",
                                 "planetary_5p.yaml", "servo_joint.yaml", "planets:9"])
def test_sign_error_names_the_same_sample(key, backend):
    """Samples with no consistent sign pattern (a NaN acceleration fails the first geared
    block): the error names the sample, and the meshes, that the numpy path names."""
    an = analyse(mechanism(key))
    n = 4400
    q, qd, qdd = trajectory(an, n, seed=5)
    first = nan_accelerations(qdd, 12)
    for chunk in (7, 20_000):
        ref = _sign_error(an, q, qd, qdd, "numpy", chunk)
        assert ref[0] == first
        assert _sign_error(an, q, qd, qdd, backend, chunk) == ref


# two one-link arms on one base (a tree), each driven through a spur pair: arm a's blocks first
def _arm(tag: str, y: float) -> str:
    inertial = ('<inertial><origin xyz="0.2 0 0"/><mass value="4"/>'
                '<inertia ixx="0.005" ixy="0" ixz="0" iyy="0.06" iyz="0" izz="0.06"/></inertial>')
    small = ('<inertial><origin xyz="0 0 0"/><mass value="0.2"/>'
             '<inertia ixx="5e-05" ixy="0" ixz="0" iyy="5e-05" iyz="0" izz="3e-05"/></inertial>')
    return f"""
  <link name="{tag}">{inertial}</link>
  <link name="p{tag}">{small}</link>
  <joint name="J{tag}" type="continuous"><parent link="base"/><child link="{tag}"/>
    <origin xyz="0 {y} 0.1"/><axis xyz="0 0 1"/></joint>
  <joint name="K{tag}" type="continuous"><parent link="base"/><child link="p{tag}"/>
    <origin xyz="0.12 {y} 0.05"/><axis xyz="0 0 1"/><mimic joint="J{tag}" multiplier="-3" offset="0"/>
    <gearcli:gear name="g{tag}" kind="external" teeth="20 60" mesh_point="0.09 {y} 0.05" pressure_angle_deg="20"/>
  </joint>
  <transmission name="t{tag}"><type>transmission_interface/SimpleTransmission</type>
    <joint name="K{tag}"><hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>
    <actuator name="m{tag}"><mechanicalReduction>1</mechanicalReduction></actuator></transmission>"""


TWO_ARMS = ('<robot name="two_arms" xmlns:gearcli="https://gearcli.dev/urdf/1">\n'
            '  <gearcli:mechanism gravity="0 0 -9.81"/>\n  <link name="base"/>'
            + _arm("a", 0.0) + _arm("b", 1.0) + "\n</robot>\n")


@pytest.mark.parametrize("backend", BACKENDS)
def test_sign_error_follows_the_numpy_path_through_chunks_and_blocks(backend):
    """Sample 100 fails only in arm b's (later) block, sample 200 in arm a's (earlier) one
    (a rate so large that the kinematics of that arm overflow to NaN):
    in one chunk the numpy path stops at arm a's block and names sample 200; with chunks
    of 150 samples it names sample 100.  The kernel, which solves every sample through
    every block, must name the same."""
    an = analyse(parse_urdf(TWO_ARMS))
    col = {name: i for i, name in enumerate(an.independent_names)}
    q, qd, qdd = trajectory(an, 4400, seed=2)
    qd[100, col["Jb"]] = 1e200          # w x w overflows: NaN in arm b only (0 * 1e200 = 0)
    qd[200, col["Ja"]] = 1e200
    expect = {20_000: (200, ["'ga'"]), 150: (100, ["'gb'"])}
    for chunk, named in expect.items():
        assert _sign_error(an, q, qd, qdd, "numpy", chunk) == named
        assert _sign_error(an, q, qd, qdd, backend, chunk) == named


def test_backend_choice_and_errors():
    an = analyse(mechanism("paper_2dof.yaml"))
    q = np.zeros((3, an.dof))
    with pytest.raises(ValueError, match="unknown backend"):
        solve(an, q, q, q, backend="fortran")
    with pytest.raises(ValueError, match="method 'block' only"):
        solve(an, q, q, q, method="full", backend="llvm")
    with pytest.raises(ValueError, match="jobs"):
        solve(an, q, q, q, backend="llvm", jobs=0)
    res = solve(an, q, q, q, method="full")               # auto: numpy for the full solve
    assert res.motor.shape == (3, len(an.motor_links)) and res.backend == "numpy"
    sol = solver_for(an)
    kept, sol.llvm_problem = sol.llvm_problem, "a stand-in reason"   # as for a mechanism with losses
    try:
        assert sol.choice().path == "numpy"
        with pytest.raises(ValueError, match="unavailable: a stand-in reason"):
            solve(an, q, q, q, backend="llvm")
    finally:
        sol.llvm_problem = kept


@pytest.mark.parametrize("backend", BACKENDS)
def test_verify_with_the_kernel(backend):
    an = analyse(mechanism("loaded:bendix_wrist.yaml"))
    q, qd, qdd = trajectory(an, 300)
    res = solve(an, q, qd, qdd, backend=backend, verify=True, chunk=128, loads=per_sample_loads(an, 300))
    assert res.residual is not None and res.residual < 1e-12


# --- the comparison catches a wrong program ----------------------------------------------------
BENDIX = "loaded:bendix_wrist.yaml"
MUTATIONS = [(BENDIX, "poses", 10), (BENDIX, "bodies", None), (BENDIX, "ainv", 7), (BENDIX, "cmat", 3),
             ("servo_joint.yaml", "term_values", 2), ("planetary_3p.yaml", "ainv", "t row")]


def _t_row(prog) -> np.ndarray:
    """Flat positions in ``ainv`` of the first block's first t row, in every pattern's map."""
    rec = prog.blocks[0]
    n, nr, a0, t = int(rec.n), 6 * int(rec.nlinks), int(rec.ainv0), int(prog.t_col[rec.t0])
    return np.concatenate([a0 + k * n * nr + t * nr + np.arange(nr) for k in range(1 << int(rec.m))])


def _mutated(prog, an, field, flat):
    """``prog`` with one float of its array ``field`` (a record array: its floats in
    order) changed by 1e-6 of its size."""
    bad = np.array(getattr(prog, field))                  # a copy
    values = bad.view(np.float64).reshape(-1)
    flat = _t_row(prog) if flat == "t row" else 13 * an.tree.moving[-1] + 5 if flat is None else flat
    values[flat] += 1e-6 * (1.0 + abs(values[flat]))
    return dataclasses.replace(prog, **{field: bad.view(type(getattr(prog, field)))})


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("key,field,flat", MUTATIONS)
def test_a_wrong_program_entry_is_caught(key, field, flat, backend):
    """Perturb one entry of the program (a joint placement, an inertia, an inverse block
    matrix, a propagation column, a world-frame term; for planetary_3p, whose llvm code
    reads its 64 pattern maps from a table, one row of them): the comparison of
    test_kernel_equals_numpy must then fail."""
    an = analyse(mechanism(key))
    sol = solver_for(an)
    prog = sol.kernel_program()
    q, qd, qdd = trajectory(an, 400)
    loads = per_sample_loads(an, 400)
    ref = solve(an, q, qd, qdd, backend="numpy", loads=loads)
    assert worst(solve(an, q, qd, qdd, backend=backend, loads=loads), ref) < TOL
    kept = sol._llvm
    sol._program, sol._llvm = _mutated(prog, an, field, flat), None
    try:
        res = solve(an, q, qd, qdd, backend=backend, loads=loads)
    finally:
        sol._program, sol._llvm = prog, kept
    assert worst(res, ref) > 1e3 * TOL



def test_record_columns_are_read_by_name():
    """Every record layout of the program (llvm/records.py) names its columns so that
    ``rec.<name>`` is the column, never a numpy record attribute (a column named ``size``
    read 1 for every record: Bendix's first motor torque was 2x off)."""
    from gearcli.dynamics.llvm import records  # noqa: PLC0415

    layouts = [v for v in vars(records).values() if isinstance(v, np.dtype) and v.names]
    assert len(layouts) >= 10
    for layout in layouts:
        assert not set(layout.names) & set(dir(np.record)), layout.names
        rec = records.records([tuple(range(1, len(layout.names) + 1))] if all(
            layout[n].shape == () for n in layout.names) else [], layout)
        for k, name in enumerate(layout.names if len(rec) else ()):
            assert getattr(rec[0], name) == k + 1, name


def test_a_search_starts_from_the_pattern_of_the_sample_before():
    """Step 0 of a block's sign search tries the pattern the sample before settled on (every
    t positive for the first sample of a run of WARM samples, so that threads change no bit):
    seen where any pattern fits, at rest without gravity or loads (every t = 0, the loads
    then the numpy path's, zero).  servo_joint's ring meshes pull against its sun meshes, so
    a loaded sample's pattern is never every t positive."""
    from gearcli.dynamics.llvm.signs import WARM
    from gearcli.dynamics.result_arrays import result_arrays, work_arrays
    an = analyse(dataclasses.replace(mechanism("servo_joint.yaml"), gravity=np.zeros(3), loads=()))
    n, loaded = WARM + 8, [0, WARM - 1]
    q, qd, qdd = np.zeros((n, an.dof)), np.zeros((n, an.dof)), np.zeros((n, an.dof))
    qdd[loaded] = 2.0
    s = solver_for(an)
    sig = s.llvm_kernel().solve(an, q, qd, qdd, {}, 1, n, result_arrays(an, n), work_arrays(n, len(s.kernel_program().signed)), {})
    signs = np.column_stack(list(sig.values()))
    assert (signs[0] < 0).any()
    assert np.array_equal(signs[1:WARM - 1], np.broadcast_to(signs[0], (WARM - 2, signs.shape[1])))
    assert (signs[WARM:] == 1.0).all()                # a new run: every t positive first
    ref, res = (solve(an, q, qd, qdd, backend=b) for b in ("numpy", "llvm"))
    for f in FIELDS:
        assert np.abs(getattr(res, f) - getattr(ref, f)).max() <= TOL * np.abs(getattr(ref, f)).max(), f
    assert np.abs(ref.gear_t[2:WARM - 1]).max() == 0.0 == np.abs(res.gear_t[WARM:]).max()
