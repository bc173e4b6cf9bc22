"""Mass matrix, forward dynamics and the inertia seen at the motors (issue 20).

* ``mass_matrix`` of the paper's two-dof arm equals the closed form of Eqs. 26-27 (with
  ERRATA items 2-3), its parameters read here from ``mechanisms/paper_2dof.yaml`` and the
  gear ratios from the rolling condition at the file's mesh points (plain numpy), and on
  random variants of the arm (tests/factories.py).
* Round trip: ``solve(forward_dynamics(q, qd, T)).motor == T`` on every bundled mechanism at
  random states (with its external loads, and with per-sample loads).
* Hand case: a motor, one spur stage and a disc: the inertia at the motor is
  J_rotor + J_load / n^2, the inertia ratio J_load / (n^2 J_rotor).
* The mass kernel (backend llvm: M and h per sample, sign pattern 0, no search) equals the
  numpy reference (the stacked solve of dof + 1 inverse-dynamics samples) on every bundled
  mechanism; the first-call rule keeps small first calls on the reference.
* Deliberate bugs the checks catch: the structure matrix untransposed (motor torques
  mapped by A^T), rotors as a diagonal "armature" (what Drake/MuJoCo/Pinocchio do), and a
  mass kernel that solves a block with pattern 0 but passes |t| tan(phi) on to the later links.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

import gearcli
from factories import paper_2dof_variant, rolling_ratio
from gearcli import analyse, load_mechanism, parse_mechanism
from gearcli.dynamics import forward
from gearcli.dynamics.forward import forward_dynamics, mass_matrix, motor_inertia
from metrics import rel_err

MECH_DIR = Path(__file__).resolve().parents[1] / "mechanisms"
BUNDLED = sorted(p.name for p in MECH_DIR.glob("*.yaml")) + ["geared_arm.urdf"]


# --- the paper's closed form --------------------------------------------------------------------

def file_params(path: Path) -> dict:
    """The closed form's parameters read from the YAML file of the paper's arm (its layout:
    D-H joints J1, J2; shaft 4 along x1; centres of mass of 3, 4, 5 on their axes)."""
    doc = yaml.safe_load(path.read_text())
    links = {lk["name"]: lk for lk in doc["links"]}
    joints = {j["name"]: j for j in doc["joints"]}
    gears = {g["name"]: g for g in doc["gears"]}

    def moments(name):
        i = links[name]["inertia"]
        return [i["ixx"], i["iyy"], i["izz"]] if isinstance(i, dict) else i

    a1, a2 = joints["J1"]["dh"]["a"], joints["J2"]["dh"]["a"]
    o4 = np.array(joints["J4"]["origin"]["xyz"], float)            # shaft 4's axis point, link-1 frame
    o5 = np.array(joints["J5"]["origin"]["xyz"], float)            # pinion 5's axis point, base frame
    ez, ex = np.array([0.0, 0, 1]), np.array([1.0, 0, 0])
    p = dict(a1=a1, a2=a2, s1=-links["1"]["com"][0], s2=-links["2"]["com"][0],
             s4=-(o4[0] + links["4"]["com"][0]),                    # link 4's centre of mass at x = -s4
             m1=links["1"]["mass"], m2=links["2"]["mass"], m4=links["4"]["mass"],
             Izz1=moments("1")[2], Izz2=moments("2")[2], Izz3=moments("3")[2], Izz5=moments("5")[2],
             Iax4=moments("4")[0], Ivert4=moments("4")[2])
    p["e15"] = rolling_ratio(gears["5-1"]["mesh_point"], o5, ez, np.zeros(3), ez)
    p["e43"] = rolling_ratio(gears["3-4"]["mesh_point"], np.array([-a1, 0, 0]), ez, o4, ex)
    p["e24"] = rolling_ratio(gears["4-2"]["mesh_point"], o4, ex, np.zeros(3), ez)
    return p


def closed_form_M(p, q) -> np.ndarray:
    """Paper Eq. 26 with Eqs. 27a-f, ERRATA 2 (e43^2 e24^2 Izz(3) in M22) and 3 (m2 a1^2
    in J20); Izz(4) of M22 is link 4's moment about its shaft, Iyy(4) of J40 about the vertical."""
    C = np.cos(q[:, 1])
    m1, m2, m4 = p["m1"], p["m2"], p["m4"]
    a1, a2, s1, s2, s4 = p["a1"], p["a2"], p["s1"], p["s2"], p["s4"]
    e15, e43, e24 = p["e15"], p["e43"], p["e24"]
    J10 = m1 * (a1 - s1) ** 2 + p["Izz1"]
    J20 = m2 * a1 ** 2 + 2 * m2 * a1 * (a2 - s2) * C + m2 * (a2 - s2) ** 2 + p["Izz2"]
    J21 = m2 * (a2 - s2) ** 2 + p["Izz2"]
    J40 = m4 * (a1 - s4) ** 2 + p["Ivert4"]
    k2 = m2 * a1 * (a2 - s2) * C + J21
    M11 = J10 + J20 + p["Izz3"] + J40 + e15 ** 2 * p["Izz5"]
    M12 = k2 + e43 * e24 * p["Izz3"]
    M22 = J21 + e43 ** 2 * e24 ** 2 * p["Izz3"] + e24 ** 2 * p["Iax4"] + 0 * C
    return np.stack([np.stack([M11, M12], -1), np.stack([M12, M22], -1)], -2)


def test_file_parameters_read_as_by_hand():
    p = file_params(MECH_DIR / "paper_2dof.yaml")
    assert (p["e15"], p["e43"], p["e24"]) == pytest.approx((-3.0, -1.0, 2.0), abs=1e-12)
    assert (p["s1"], p["s2"], p["s4"]) == pytest.approx((0.2, 0.15, 0.2), abs=1e-15)


@pytest.mark.parametrize("backend", ["llvm", "numpy"])
def test_mass_matrix_equals_paper_closed_form(backend):
    an = analyse(load_mechanism(MECH_DIR / "paper_2dof.yaml"))
    q = np.random.default_rng(1).uniform(-np.pi, np.pi, (40, 2))
    M = mass_matrix(an, q, backend=backend)
    ref = closed_form_M(file_params(MECH_DIR / "paper_2dof.yaml"), q)
    assert M.shape == (40, 2, 2)
    assert np.max(np.abs(M - ref)) < 1e-12


@pytest.mark.parametrize("seed", range(4))
def test_mass_matrix_of_random_paper_variants(seed):
    text, p = paper_2dof_variant(np.random.default_rng(seed))
    an = analyse(parse_mechanism(text))
    q = np.random.default_rng(seed + 10).uniform(-np.pi, np.pi, (20, 2))
    assert rel_err(mass_matrix(an, q), closed_form_M(p, q)) < 1e-12


def test_rotors_as_armature_would_be_caught():
    """The diagonal approximation (rotor inertia times the squared ratio on M's diagonal,
    no coupling) misses e43 e24 Izz(3) in M12: the closed-form check sees it."""
    p = file_params(MECH_DIR / "paper_2dof.yaml")
    q = np.zeros((1, 2))
    exact = closed_form_M(p, q)
    armature = exact.copy()
    armature[:, 0, 1] -= p["e43"] * p["e24"] * p["Izz3"]
    armature[:, 1, 0] = armature[:, 0, 1]
    assert np.max(np.abs(armature - exact)) > 1e4 * 1e-12


def test_one_sample_and_shapes():
    an = analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))
    q = np.array([0.1, -0.2, 0.3])
    assert mass_matrix(an, q).shape == (1, 3, 3)
    assert forward_dynamics(an, q, q, np.zeros(3)).shape == (1, 3)
    assert motor_inertia(an, q).shape == (1, 3, 3)
    assert motor_inertia(an, q, diagonal=True).shape == (1, 3)


def test_bad_input_is_named():
    an = analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))
    q = np.zeros((2, 3))
    with pytest.raises(ValueError, match=r"motor_torques is not finite at sample 1, motor '"):
        forward_dynamics(an, q, q, np.array([[0.0, 0, 0], [0, np.nan, 0]]))
    with pytest.raises(ValueError, match=r"expected qd with shape \(N, 3\)"):
        forward_dynamics(an, q, np.zeros((2, 2)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="same number of samples"):
        forward_dynamics(an, q, np.zeros((3, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"q is not finite at sample 0, joint '"):
        mass_matrix(an, [np.inf, 0, 0])


# --- round trip ------------------------------------------------------------------------------

def random_state(an, n, seed):
    rng = np.random.default_rng(seed)
    return (rng.uniform(-np.pi, np.pi, (n, an.dof)), rng.uniform(-3, 3, (n, an.dof)),
            rng.uniform(-5, 5, (n, len(an.mech.motors))))


def round_trip_error(an, fd, q, qd, T, loads=None) -> float:
    """max|solve(fd(q, qd, T)).motor - T| relative to the largest torque."""
    qdd = fd(an, q, qd, T, loads=loads)
    return rel_err(gearcli.solve(an, q, qd, qdd, loads=loads).motor, T)


@pytest.mark.parametrize("name", BUNDLED)
def test_round_trip_on_every_bundled_mechanism(name):
    an = analyse(load_mechanism(MECH_DIR / name))
    q, qd, T = random_state(an, 60, seed=len(name))
    assert round_trip_error(an, forward_dynamics, q, qd, T) < 1e-10
    llvm = (lambda an, q, qd, T, loads=None: forward_dynamics(an, q, qd, T, loads=loads, backend="llvm"))
    assert round_trip_error(an, llvm, q, qd, T) < 1e-10


# --- the mass kernel (backend llvm) against the numpy reference ---------------------------------

def kernel_error(an, q, qd, loads=None) -> tuple[float, float]:
    """max over samples of |M_llvm - M_numpy| and |h_llvm - h_numpy|, each relative to the
    sample's largest reference torque (of M and h: the reference's columns tau(e_i) - h
    round at the size of h)."""
    from gearcli.dynamics.solve import solver_for
    M, h, _ = forward._mass_and_h(solver_for(an), q, qd, np.zeros_like(q), loads, "llvm", None)
    Mr, hr, _ = forward._mass_and_h(solver_for(an), q, qd, np.zeros_like(q), loads, "numpy", None)
    scale = np.maximum(np.abs(Mr).max(axis=(1, 2)), np.abs(hr).max(axis=1))
    return (float(np.max(np.abs(M - Mr).max(axis=(1, 2)) / scale)),
            float(np.max(np.abs(h - hr).max(axis=1) / scale)))


@pytest.mark.parametrize("name", BUNDLED)
def test_mass_kernel_equals_the_reference(name):
    """M and h to 1e-12 of the sample's torque scale, at random states with the file's
    loads (a lossy mechanism: M only, the lossless one, which the reference gives at rest;
    the kernel's h is lossless, :func:`forward._mass_and_h`)."""
    an = analyse(load_mechanism(MECH_DIR / name))
    q, qd, _ = random_state(an, 50, seed=len(name) + 1)
    if an.mech.has_losses:
        qd = np.zeros_like(qd)
    err_M, err_h = kernel_error(an, q, qd)
    assert err_M < 1e-12
    if not an.mech.has_losses:
        assert err_h < 1e-12


def test_mass_kernel_with_per_sample_loads():
    an = analyse(load_mechanism(MECH_DIR / "rack_axis.yaml"))
    q, qd, _ = random_state(an, 30, seed=3)
    W = np.random.default_rng(4).uniform(-100, 100, (30, 6))
    assert max(kernel_error(an, q, qd, {"payload": W})) < 1e-12


def test_mass_kernel_passing_abs_t_on_would_be_caught(monkeypatch, tmp_path):
    """Pattern 0 in a block but |t| tan(phi) in the wrenches passed on to the later links
    (the solve kernel's propagation, right only for the consistent pattern): the Bendix
    wrist's signed bevel block then gets inconsistent forces, and M is off by percents."""
    from gearcli.dynamics.llvm import blocks
    from gearcli.dynamics.llvm.mass import MassKernel
    from gearcli.dynamics.solve import solver_for

    right = blocks._wrench_in_F
    monkeypatch.setattr(blocks, "_wrench_in_F", lambda e, rec, cmat, x, fixed=False: right(e, rec, cmat, x))
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))      # not the right code from the cache
    an = analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))
    q, _, _ = random_state(an, 20, seed=12)
    wrong = MassKernel(solver_for(an).kernel_program(), an).run(an, q, np.zeros_like(q), {}, np.zeros_like(q), None)[0]
    assert rel_err(wrong, mass_matrix(an, q, backend="numpy")) > 1e-3


def test_beyond_max_kernel_dof_the_stacked_llvm_solve(monkeypatch):
    """More independent joints than MAX_KERNEL_DOF: no mass kernel (its compile grows with
    dof^2), the stacked solve on the llvm solve kernel, equal to the reference."""
    from gearcli.dynamics.solve import solver_for

    monkeypatch.setattr(forward, "MAX_KERNEL_DOF", 2)
    an = analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))
    q, qd, _ = random_state(an, 20, seed=14)
    assert max(kernel_error(an, q, qd)) < 1e-12
    sol = solver_for(an)
    assert sol.mass_kernel[0] is None and sol.compiled_llvm()


def test_first_call_rule_keeps_a_small_first_call_on_the_reference(monkeypatch, tmp_path):
    """"auto": a first call of fewer than FIRST_CALL_SAMPLES / (dof + 1) samples does not
    compile the mass kernel (nor the solve kernel) when the disk cache does not hold it; a
    large one does."""
    from gearcli.dynamics.backends import FIRST_CALL_SAMPLES
    from gearcli.dynamics.solve import solver_for

    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))
    an = analyse(load_mechanism(MECH_DIR / "geared_arm.urdf"))
    sol = solver_for(an)
    q, qd, T = random_state(an, FIRST_CALL_SAMPLES // (an.dof + 1), seed=13)
    small = forward_dynamics(an, q[:10], qd[:10], T[:10])
    assert sol.mass_kernel[0] is None and not sol.compiled_llvm()
    assert rel_err(small, forward_dynamics(an, q[:10], qd[:10], T[:10], backend="numpy")) < 1e-12
    forward_dynamics(an, q, qd, T)
    assert sol.mass_kernel[0] is not None


def test_round_trip_with_per_sample_loads():
    an = analyse(load_mechanism(MECH_DIR / "rack_axis.yaml"))
    q, qd, T = random_state(an, 30, seed=3)
    W = np.random.default_rng(4).uniform(-100, 100, (30, 6))
    assert round_trip_error(an, forward_dynamics, q, qd, T, loads={"payload": W}) < 1e-10
    # the loads matter: without them, the same torques accelerate differently
    assert np.max(np.abs(forward_dynamics(an, q, qd, T, loads={"payload": W}) - forward_dynamics(an, q, qd, T))) > 1.0


def test_round_trip_across_chunks(monkeypatch):
    """Samples split over several batched solves (the last one shorter) land in order."""
    monkeypatch.setattr(forward, "CHUNK", 7)
    an = analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))
    q, qd, T = random_state(an, 30, seed=5)
    assert round_trip_error(an, forward_dynamics, q, qd, T) < 1e-10


def test_untransposed_structure_matrix_would_be_caught():
    """A forward dynamics that maps the motor torques by A^T instead of A (the input-rotation
    map, a plausible slip) fails the round trip on the Bendix wrist's coupled motors."""
    an = analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))

    def wrong(an, q, qd, T, loads=None):
        return forward_dynamics(an, q, qd, T @ an.A @ np.linalg.inv(an.A.T))   # tau = A^T T

    q, qd, T = random_state(an, 20, seed=6)
    assert round_trip_error(an, wrong, q, qd, T) > 1e-3


# --- inertia at the motor: the hand case ----------------------------------------------------------

J_ROTOR, J_LOAD, TEETH = 3.0e-5, 0.12, (20, 70)


def spur_stage_yaml(j_rotor=J_ROTOR, j_load=J_LOAD, teeth=TEETH) -> str:
    """A motor turning a pinion (rotor + pinion: j_rotor about the axis) that drives a disc
    (j_load) through one external spur stage, n = teeth[1] / teeth[0]; vertical axes."""
    r1 = 0.001 * teeth[0]
    r2 = 0.001 * teeth[1]
    return f"""
name: spur_stage
base: frame
end_effector: disc
links:
  - name: frame
  - {{name: rotor, mass: 0.4, inertia: [1.0e-4, 1.0e-4, {j_rotor}]}}
  - {{name: disc, mass: 3.0, inertia: [0.07, 0.07, {j_load}]}}
joints:
  - {{name: Jm, parent: frame, child: rotor, origin: {{xyz: [{r1 + r2}, 0, 0]}}, axis: [0, 0, 1]}}
  - {{name: Jd, parent: frame, child: disc, origin: {{xyz: [0, 0, 0]}}, axis: [0, 0, 1]}}
gears:
  - {{name: stage, links: [rotor, disc], kind: external, teeth: [{teeth[0]}, {teeth[1]}], mesh_point: [{r2}, 0, 0]}}
motors:
  - {{name: servo, link: rotor}}
"""


def test_inertia_ratio_of_a_spur_stage_by_hand():
    an = analyse(parse_mechanism(spur_stage_yaml()))
    n = TEETH[1] / TEETH[0]
    J = motor_inertia(an, np.array([[0.0], [1.3], [-2.0]]), diagonal=True)
    assert np.max(np.abs(J - (J_ROTOR + J_LOAD / n ** 2))) < 1e-12 * J_ROTOR
    ratio = (J - J_ROTOR) / J_ROTOR
    assert np.max(np.abs(ratio - J_LOAD / (n ** 2 * J_ROTOR))) < 1e-12
    # the mass matrix on the disc's joint: J_load + n^2 J_rotor
    assert mass_matrix(an, [0.4])[0, 0, 0] == pytest.approx(J_LOAD + n ** 2 * J_ROTOR, rel=1e-13)


def test_motor_inertia_of_coupled_motors_is_the_full_matrix():
    """Bendix wrist: A^-1 M A^-T, symmetric, with off-diagonal coupling; its kinetic energy
    in motor rates equals 1/2 qd^T M qd."""
    an = analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))
    q, qd, _ = random_state(an, 10, seed=8)
    J = motor_inertia(an, q)
    M = mass_matrix(an, q)
    w = qd @ an.A                                   # motor rates A^T qd
    assert rel_err(np.einsum("ni,nij,nj->n", w, J, w), np.einsum("ni,nij,nj->n", qd, M, qd)) < 1e-12
    assert np.max(np.abs(J - np.swapaxes(J, 1, 2))) == 0.0
    assert np.max(np.abs(J - np.einsum("nii->ni", J)[:, :, None] * np.eye(3))) > 1e-6


def test_few_and_many_samples_solve_alike():
    """One sample a call (an integrator's steps) and 40 in one call: the same accelerations."""
    an = analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))
    q, qd, T = random_state(an, 40, seed=9)
    many = forward_dynamics(an, q, qd, T)
    few = np.vstack([forward_dynamics(an, q[i], qd[i], T[i]) for i in range(0, 40, 8)])
    assert rel_err(few, many[::8]) < 1e-13


# --- with losses: the implicit equation ---------------------------------------------------------

@pytest.mark.parametrize("name", ["paper_2dof.yaml", "bendix_wrist.yaml", "rack_axis.yaml", "planetary_3p.yaml",
                                  "helical_reduction.yaml"])
def test_round_trip_with_losses(name, monkeypatch):
    """Mesh friction (c = 0.03) and joint friction on every element: tau is piecewise linear
    in qdd; forward_dynamics solves the implicit equation (losses issue 19) so that solve
    returns the torques.  One secant step alone (MAX_STEPS = 0) does not."""
    from test_losses import with_losses
    an = analyse(with_losses(load_mechanism(MECH_DIR / name)))
    assert an.mech.has_losses
    q, qd, T = random_state(an, 40, seed=11)
    assert round_trip_error(an, forward_dynamics, q, qd, T) < 1e-10
    # the mass matrix is the lossless one (at rest no mesh slides, friction is 0)
    lossless = analyse(load_mechanism(MECH_DIR / name))
    assert rel_err(mass_matrix(an, q), mass_matrix(lossless, q)) < 1e-10    # numpy vs llvm rounding
    monkeypatch.setattr(forward, "MAX_STEPS", 0)
    with pytest.raises(ValueError, match=r"forward dynamics with losses did not settle at sample \d+ in 0 steps"):
        forward_dynamics(an, q, qd, T)


def test_reused_result_arrays_never_leak_into_returned_values():
    """forward_dynamics and mass_matrix reuse their solve's result arrays between calls (per
    thread): what a call returned stays as it was after later calls, from this thread and
    from another one."""
    import threading
    an = analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))
    q, qd, T = random_state(an, 50, seed=21)
    # the kernel (which reuses the arrays) whatever the cache holds: numpy's batched LAPACK
    # rounds a reversed (negative-stride) stack differently, so [::-1] is equal only there
    first, M = forward_dynamics(an, q, qd, T, backend="llvm"), mass_matrix(an, q, backend="llvm")
    kept = first.copy(), M.copy()
    other = []
    worker = threading.Thread(target=lambda: other.append(forward_dynamics(an, q[::-1], qd[::-1], T[::-1],
                                                                           backend="llvm")))
    worker.start()
    second = forward_dynamics(an, q[::-1], qd[::-1], T[::-1], backend="llvm")
    worker.join()
    mass_matrix(an, q[::-1], backend="llvm")
    assert np.array_equal(first, kept[0]) and np.array_equal(M, kept[1])
    assert np.array_equal(second, other[0]) and np.array_equal(second, first[::-1])


@pytest.mark.parametrize("mu", [0.5, 0.8])
def test_forward_dynamics_with_slow_bearing_friction_settles_the_same_on_both_backends(monkeypatch, mu):
    """Bearing friction of mu on a 120 mm bore under the wheel of a spur pair: the lossless
    M makes a correction step contract by only ~Lambda (0.5-0.85), so 60 steps did not settle
    and each backend failed at its own sample (the result depended on the kernel cache:
    issue 34, section 5).  Newton steps with the lossy Jacobian settle both, to the same
    accelerations, which solve turns back into the torques."""
    from test_loss_cli import SPUR
    jw = "  - {name: Jw, parent: frame, child: wheel, origin: {xyz: [0.075, 0, 0]}, axis: [0, 0, 1]}"
    an = analyse(parse_mechanism(SPUR.replace(jw, (
        "  - name: Jw\n    parent: frame\n    child: wheel\n    origin: {xyz: [0.075, 0, 0]}\n    axis: [0, 0, 1]\n"
        f"    bearings:\n      - {{name: w, position: 0.0, friction_coefficient: {mu}, bore: 0.12}}")), "spur.yaml"))
    rng = np.random.default_rng(0)
    q, qd, T = rng.uniform(-3, 3, (50, 1)), rng.normal(size=(50, 1)) * 5, rng.normal(size=(50, 1)) * 0.5
    acc = {b: forward_dynamics(an, q, qd, T, backend=b) for b in ("numpy", "llvm")}
    assert rel_err(acc["numpy"], acc["llvm"]) < 1e-10
    for b in ("numpy", "llvm"):
        assert np.abs(gearcli.solve(an, q, qd, acc[b], backend=b).motor - T).max() < 1e-10 * np.abs(T).max()
    monkeypatch.setattr(forward, "SECANT_STEPS", forward.MAX_STEPS)      # the lossless M alone: no settling
    with pytest.raises(ValueError, match="did not settle"):
        forward_dynamics(an, q, qd, T, backend="numpy")


@pytest.mark.parametrize("backend", ["numpy", "llvm"])
@pytest.mark.parametrize("name", ["paper_2dof.yaml", "bendix_wrist.yaml", "planetary_3p.yaml", "servo_joint.yaml",
                                  "rack_axis.yaml", "geared_arm.urdf"])
def test_mass_matrix_is_exactly_symmetric(name, backend):
    """M == M^T to the bit, as documented (issue 39: a mutation that dropped the
    symmetrisation passed the whole suite, whose tolerances hid a 1e-16 asymmetry)."""
    an = analyse(load_mechanism(MECH_DIR / name))
    q, _, _ = random_state(an, 50, seed=4)
    M = mass_matrix(an, q, backend=backend)
    assert np.array_equal(M, np.swapaxes(M, 1, 2))


def test_an_explicit_solver_holds_its_own_kernels():
    """gearcli.Solver(an, backend=...): solve, forward_dynamics, mass_matrix and
    motor_inertia with the solver's kernels and defaults, the same values as the module
    functions; a solver made for llvm compiles its own kernels, the convenience's stay
    untouched (issue 39, section 2)."""
    from gearcli.dynamics.solve import solver_for
    an = analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))
    q, qd, T = random_state(an, 30, seed=9)
    s = gearcli.Solver(an, backend="llvm", jobs=1)
    assert not s.compiled_llvm() and s.mass_kernel[0] is None
    qdd = s.forward_dynamics(q, qd, T)
    assert s.mass_kernel[0] is not None
    res = s.solve(q, qd, qdd)
    assert s.compiled_llvm() and res.backend == "llvm"
    assert rel_err(res.motor, T) < 1e-12
    assert rel_err(qdd, forward_dynamics(an, q, qd, T, backend="numpy")) < 1e-10
    assert rel_err(s.mass_matrix(q), mass_matrix(an, q, backend="numpy")) < 1e-12
    assert rel_err(s.motor_inertia(q), motor_inertia(an, q, backend="numpy")) < 1e-12
    assert solver_for(an) is not s
    numpy_solver = gearcli.Solver(an, backend="numpy")
    assert numpy_solver.solve(q, qd, qdd).backend == "numpy" and not numpy_solver.compiled_llvm()
