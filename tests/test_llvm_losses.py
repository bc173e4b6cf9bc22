"""The generated llvm kernel solves lossy mechanisms (issue 19) equal to the numpy reference.

The numpy path (:mod:`gearcli.dynamics.losses`, :mod:`gearcli.dynamics.bearing_friction`,
the friction maps of :func:`gearcli.dynamics.blocks._constant_block`) is the reference; the
kernel shares none of its per-sample arithmetic (its own kinematics, relative rates, joint
friction forces, loss outputs, the rank-ml correction of a block's maps and friction columns
of the world-frame blocks, :mod:`gearcli.dynamics.llvm.losses`), only constants (the couples,
the friction coefficients, the stored maps of a block with few (s_v, sign) patterns, made
as the numpy path makes them) and the bearing fixed point's constants.  Every
output, the loss outputs and the bearing iterations included, must agree to 1e-12 of the
sample's largest load on every bundled mechanism with losses switched on and on the hand
cases of tests/test_losses.py, along random motions in which tooth forces and relative
rates change sign, with samples at rest (s_v = 0); failures must be the numpy path's.  The
bearing iterations are counted per block in the kernel (:func:`iterations_agree`).
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from gearcli import analyse, load_mechanism, parse_mechanism
from gearcli.dynamics.bearing_friction import BearingFrictionError
from gearcli.dynamics.llvm.bearings import NEWTON_JOINTS
from gearcli.dynamics.llvm.signs import WARM
from gearcli.dynamics.signs import SignError
from gearcli.dynamics.solve import solve, solver_for
from metrics import nan_accelerations, per_sample_loads, sample_err
from test_losses import MOTOR_SHAFT, PLANETARY, RACK, SHAFT, SPUR, with_losses

pytest.importorskip("llvmlite")

MECH = Path(__file__).resolve().parents[1] / "mechanisms"
DESIGNS = Path(__file__).resolve().parents[1] / "designs"
FIELDS = ("motor", "tau", "joint", "gear_t", "gear_sep", "gear_radial", "gear_axial", "motor_speed",
          "gear_loss", "joint_friction", "joint_loss")
TOL = 1e-12
LOSSY = sorted(p.name for p in MECH.glob("*.yaml")) + ["geared_arm.urdf"]
HAND = {
    "spur": lambda: SPUR.format(eta=0.9, ML=-4.0),
    "rack": lambda: RACK.format(Fc=12.0, Fv=30.0, eta=0.9, F=-50.0),
    "planetary": lambda: PLANETARY.format(a=0.03, rs=0.012, rr=0.048, eta=0.98, Tc=-3.0),
    "shaft": lambda: SHAFT.format(z1=0.02, z2=0.06, mu=0.05, d=0.03, ML=-4.0),
    "motor_shaft": lambda: MOTOR_SHAFT.format(z1=0.02, z2=0.06, mu=0.05, d=0.03, ML=-4.0),
}


def mechanism(key: str):
    """A bundled file with losses on (``with_losses``), servo_joint_rated.yaml as it is (its
    own efficiencies, joint and bearing friction), or a hand case of tests/test_losses.py."""
    if key in HAND:
        return parse_mechanism(HAND[key]())
    mech = load_mechanism(MECH / key)
    return mech if mech.has_losses else with_losses(mech)


def motion(an, n, seed=0):
    """Random q, qd, qdd; every 7th sample at rest (qd = 0: s_v = 0, no Coulomb or bearing
    friction), every 11th with one joint rate zero."""
    rng = np.random.default_rng(seed)
    q, qd, qdd = (rng.uniform(-np.pi, np.pi, (n, an.dof)), rng.normal(size=(n, an.dof)) * 3.0,
                  rng.normal(size=(n, an.dof)) * 20.0)
    qd[::7] = 0.0
    qd[3::11, 0] = 0.0
    return q, qd, qdd


def worst(a, b) -> float:
    """The per-sample error of :func:`metrics.sample_err` over this file's fields."""
    return sample_err(a, b, FIELDS)


def iterations_agree(prog, qd_all, got, ref) -> None:
    """The kernel converges each constant-frame block's bearing friction alone, by Newton's
    method (llvm.bearing_newton) where it has up to llvm.bearings.NEWTON_JOINTS bearing
    joints, else by the fixed point on its loads (the numpy path's iterations), the numpy
    path every joint at once by the fixed point: from
    zero moments (the first sample of each run of llvm.signs.WARM) a block needs no more
    levels than the fixed point's iterations, and at least two where its joints move and their
    moments change the bearing loads (the fixed point then takes more than two: the first
    step is not yet proven within the tolerance); where they do not (the fixed point's second
    iteration only confirms g(0)) exactly one.  A warm start from the samples before (a
    smooth stretch) costs at most one iteration more on these random motions.  At rest
    (every bearing joint's rate 0): one iteration."""
    cold = np.arange(len(got)) % WARM == 0
    assert np.all(got[cold] <= ref[cold]) and np.all((got >= 1) & (got <= ref + 1))
    rest = np.all(qd_all[:, list(prog.losses.bearing_joints)] == 0.0, axis=1)
    assert rest.any() and np.all(got[rest] == 1) and np.all(got[cold & ~rest & (ref > 2)] > 1)
    assert np.all(got[cold & ~rest & (ref == 2)] == 1)


def moments_agree(res, ref, rtol: float = 4e-12) -> None:
    """Each joint's friction (its bearings' converged moments among it) equals the numpy
    path's to ``rtol`` of itself: both stop within TOL of the fixed point, Newton by its error
    bound, the fixed point by its change (a Newton step with a wrong Jacobian is off by
    ~Lambda |error|, ~1e-9 of the moment, which the sample-wide tolerance would not see)."""
    a, b = res.joint_friction, ref.joint_friction
    assert np.all(np.abs(a - b) <= rtol * np.abs(b) + 1e-300)


def test_warm_start_along_a_smooth_motion():
    """Along the Bendix wrist's bundled 1 kHz trajectory (rated, with losses) each block's
    fixed point starts from the extrapolated moments of the two samples before: fewer
    iterations than the numpy path's start from zero, and than the same samples in a random
    order (no smooth stretch: zero moments), to the same result (1e-12)."""
    an = analyse(mechanism("bendix_wrist_rated.yaml"))
    cols = np.loadtxt(MECH / "bendix_wrist_traj.csv", delimiter=",", skiprows=1)
    q, qd, qdd = cols[:, 1:4], cols[:, 4:7], cols[:, 7:10]
    ref = solve(an, q, qd, qdd, backend="numpy")
    res = solve(an, q, qd, qdd, backend="llvm", jobs=1)
    assert worst(res, ref) < TOL
    moments_agree(res, ref)
    assert np.median(res.bearing_iterations) < np.median(ref.bearing_iterations)
    order = np.random.default_rng(1).permutation(len(q))
    shuffled = solve(an, q[order], qd[order], qdd[order], backend="llvm", jobs=1).bearing_iterations
    assert np.mean(res.bearing_iterations) < np.mean(shuffled) - 0.5


@pytest.mark.parametrize("key", ["planetary_3p.yaml", "planetary_5p.yaml"])
def test_screened_trials_where_friction_reverses_a_tooth_force(key):
    """A lossy block of many meshes decides its sign trials on the lossless map's tooth
    forces t0 where a bound proves the friction cannot change a sign (``LossyBlock.trial``).
    Sweeping the acceleration through the planet-ring forces' reversal, both ways of turning:
    in a band around it t0 and the lossy t differ in sign (the friction shifts the
    reversal), and there the trials must take the exact solve.  llvm equals numpy on 8,001
    samples a way; with the bound halved the llvm path fails this test."""
    an = analyse(mechanism(key))
    n = 8001
    for rate in (1.0, -1.0):
        q, qd, qdd = np.zeros((n, 1)), np.full((n, 1), rate), np.linspace(-2000.0, 2000.0, n)[:, None]
        ref = solve(an, q, qd, qdd, backend="numpy")
        lossless = solve(analyse(load_mechanism(MECH / key)), q, qd, qdd, backend="numpy")
        assert (np.sign(ref.gear_t) != np.sign(lossless.gear_t)).any(axis=1).sum() > 20   # the band is met
        res = solve(an, q, qd, qdd, backend="llvm", jobs=1)
        assert worst(res, ref) < TOL


@pytest.mark.parametrize("key", ["planetary_3p.yaml", "planetary_5p.yaml"])
def test_inverse_cache_changes_no_bit(key):
    """A lossy block of many meshes keeps the factors of 1 + M_l D of the last two (p, D)
    met in a kernel call (``llvm.inverse_cache``): every sample's results must be bit for bit
    those of the same sample in another order, and alone (an empty cache), whatever came
    before.  Both ways of turning and a sweep through the planet-ring forces' reversal give
    four (p, D), more than the cache holds; with a key that leaves out D's digits the llvm
    path fails this test."""
    mech = load_mechanism(MECH / key)
    an = analyse(dataclasses.replace(mech, gears=tuple(dataclasses.replace(g, loss_factor=0.03) for g in mech.gears)))
    n = 2001
    qdd = np.tile(np.linspace(-2000.0, 2000.0, n // 2 + 1), 2)[:n, None]
    q, qd = np.zeros((n, 1)), np.where(np.arange(n) % 3 == 0, -1.0, 1.0)[:, None]
    res = solve(an, q, qd, qdd, backend="llvm", jobs=1)
    keys = {(tuple(np.sign(t)), float(v)) for t, v in zip(res.gear_t, qd[:, 0])}
    assert len(keys) >= 3
    order = np.random.default_rng(2).permutation(n)
    shuffled = solve(an, q[order], qd[order], qdd[order], backend="llvm", jobs=1)
    alone = [solve(an, q[i:i + 1], qd[i:i + 1], qdd[i:i + 1], backend="llvm", jobs=1) for i in order[:40]]
    for f in FIELDS:
        assert np.array_equal(getattr(shuffled, f), getattr(res, f)[order]), f
        assert all(np.array_equal(getattr(a, f)[0], getattr(res, f)[i]) for a, i in zip(alone, order)), f


@pytest.mark.parametrize("key", LOSSY + list(HAND))
def test_llvm_equals_numpy_with_losses(key):
    an = analyse(mechanism(key))
    sol = solver_for(an)
    assert sol.llvm_available() and sol.choice().path == "llvm"       # auto: the compiled path
    q, qd, qdd = motion(an, 500)
    loads = per_sample_loads(an, 500)
    ref = solve(an, q, qd, qdd, backend="numpy", loads=loads)
    res = solve(an, q, qd, qdd, backend="llvm", jobs=1, loads=loads)
    assert worst(res, ref) < TOL
    prog = sol.kernel_program()
    assert prog.losses is not None
    if ref.bearing_iterations is None:
        assert res.bearing_iterations is None
    else:
        iterations_agree(prog, qd @ np.asarray(an.S, float).T, res.bearing_iterations, ref.bearing_iterations)
        moments_agree(res, ref)
    lossy = [ci for ci, c in enumerate(an.circuits) if c.geometry is not None
             and an.mech.gears[c.gear].loss_factor]
    moving = np.any(qd != 0.0, axis=1)
    for ci in lossy:                   # both signs of t and of the relative rate, and rest
        t, loss = ref.gear_t[moving, ci], ref.gear_loss[:, ci]
        assert (t > 0).any() and (t < 0).any()
        assert np.all(loss[~moving] == 0.0) and np.all(res.gear_loss[~moving, ci] == 0.0)


def test_lossy_blocks_of_every_kind_are_covered():
    """The mechanisms above hold lossy meshes in a block whose (s_v, sign pattern) maps are
    stored (paper_2dof), one with the rank-ml correction of its stored pattern maps
    (planetary_3p), one solved from a LowRank base matrix (planetary_5p), a world-frame
    square block (geared_arm.urdf has a transmission) and a redundant world-frame one
    (servo_joint_rated)."""
    def lossy_blocks(key):
        prog = solver_for(analyse(mechanism(key))).kernel_program()
        return prog, prog.losses.blocks
    prog, blocks = lossy_blocks("planetary_5p.yaml")
    assert any(b in prog.lowrank for b in blocks)
    prog, blocks = lossy_blocks("planetary_3p.yaml")
    assert any(bl.phi is not None and bl.maps is None and b not in prog.lowrank for b, bl in blocks.items())
    prog, blocks = lossy_blocks("paper_2dof.yaml")
    assert blocks and all(bl.maps is not None for bl in blocks.values())
    prog, blocks = lossy_blocks("servo_joint_rated.yaml")
    assert any(bl.phi is None and b in prog.weights for b, bl in blocks.items())


@pytest.mark.parametrize("key", ["servo_joint_rated.yaml", "shaft"])
def test_threads_change_no_bit_with_bearing_friction(key):
    an = analyse(mechanism(key))
    n = 20_001
    q, qd, qdd = motion(an, n, seed=3)
    one = solve(an, q, qd, qdd, jobs=1, backend="llvm")
    two = solve(an, q, qd, qdd, jobs=2, backend="llvm")
    for f in FIELDS + ("bearing_iterations",):
        assert np.array_equal(getattr(one, f), getattr(two, f)), f


@pytest.mark.parametrize("key", ["servo_joint_rated.yaml", "bendix_wrist_rated.yaml", "shaft"])
def test_kernel_bearing_moments_are_the_fixed_point_of_its_reactions(key):
    """The converged moments the kernel applies (its joint friction less the Coulomb and
    viscous part) are, to 1e-12, bearing_friction.friction_moments of the kernel's own
    reactions: the split and M_b = 1/2 mu_b d_b P_b in IR, and the fixed point met."""
    from gearcli.dynamics.bearing_friction import friction_joints, friction_moments
    from gearcli.dynamics.losses import joint_friction_forces

    an = analyse(mechanism(key))
    q, qd, qdd = motion(an, 300)
    res = solve(an, q, qd, qdd, backend="llvm", jobs=1)
    qd_all = qd @ np.asarray(an.S, float).T
    joints = friction_joints(an.mech)
    own = joint_friction_forces(an.mech.joints, qd_all)
    applied = -np.sign(qd_all[:, joints]) * (res.joint_friction[:, joints] - own[:, joints])
    of_reactions = friction_moments(an.mech, joints, {("joint", ji): res.joint[:, ji, :5] for ji in joints})
    moving = qd_all[:, joints] != 0.0
    assert np.all(applied[~moving] == 0.0) and np.all(of_reactions[moving] > 0.0)
    # the fixed point's test keeps Mb with |g(Mb) - Mb| <= TOL g(Mb); `applied` carries the
    # rounding of its subtraction (a few ulps of the whole joint friction, Coulomb included)
    noise = 4 * np.finfo(float).eps * np.abs(res.joint_friction[:, joints])
    assert np.all((np.abs(applied - of_reactions) <= TOL * of_reactions + noise)[moving])


def test_bearing_friction_that_turns_a_tooth_force():
    """The shaft with the gear's weight on its bearings and small accelerations: bearing
    friction turns the tooth force's sign in many samples (the kernel's sign search at zero
    moments then no longer fits: it searches again at the current moments), samples at rest
    have none; the llvm path equals the numpy path, iterations as :func:`iterations_agree`."""
    def shaft(mu):
        text = SHAFT.format(z1=0.02, z2=0.06, mu=mu, d=0.03, ML=0.0)
        return analyse(parse_mechanism(text.replace("gravity: [0, 0, 0]", "gravity: [0, -9.81, 0]")))
    an, bare = shaft(0.05), shaft(0.0)
    rng = np.random.default_rng(1)
    n = 400
    q, qdd = rng.uniform(-3, 3, (n, 1)), rng.uniform(-0.3, 0.3, (n, 1))
    qd = rng.choice([-1.0, 1.0], (n, 1)) * rng.uniform(0.5, 2.0, (n, 1))
    qd[::9] = 0.0
    ref = solve(an, q, qd, qdd, backend="numpy")
    res = solve(an, q, qd, qdd, backend="llvm", jobs=1)
    turned = np.sign(ref.gear_t[:, 0]) != np.sign(solve(bare, q, qd, qdd, backend="numpy").gear_t[:, 0])
    assert turned.sum() > 50 and not turned[::9].any()
    assert worst(res, ref) < TOL
    assert np.array_equal(np.sign(res.gear_t), np.sign(ref.gear_t))
    iterations_agree(solver_for(an).kernel_program(), qd @ np.asarray(an.S, float).T, res.bearing_iterations,
                     ref.bearing_iterations)
    moments_agree(res, ref)


def test_verify_with_losses_on_the_llvm_path():
    """The residual of the llvm solution, checked against the right-hand side with the joint
    and the converged bearing friction."""
    an = analyse(mechanism("servo_joint_rated.yaml"))
    q, qd, qdd = motion(an, 300)
    res = solve(an, q, qd, qdd, backend="llvm", verify=True, chunk=128)
    assert res.residual is not None and res.residual < 1e-12


def _failure(an, q, qd, qdd, backend, error, chunk=20_000):
    with pytest.raises(error) as info, np.errstate(all="ignore"):
        solve(an, q, qd, qdd, backend=backend, chunk=chunk, jobs=2, check_finite=False)
    return info.value


@pytest.mark.parametrize("key", ["paper_2dof.yaml", "planetary_3p.yaml", "planetary_5p.yaml",
                                 "servo_joint_rated.yaml", "geared_arm.urdf"])
def test_sign_error_names_the_same_sample_with_losses(key):
    """NaN accelerations: no sign pattern of the first lossy block is consistent; the llvm
    path names the sample and meshes the numpy path names (every chunk size)."""
    an = analyse(mechanism(key))
    n = 2200
    q, qd, qdd = motion(an, n, seed=5)
    nan_accelerations(qdd, 8)
    for chunk in (7, 20_000):
        ref = _failure(an, q, qd, qdd, "numpy", SignError, chunk)
        got = _failure(an, q, qd, qdd, "llvm", SignError, chunk)
        assert (got.sample, got.meshes) == (ref.sample, ref.meshes)


def test_bearing_friction_that_does_not_converge_is_the_same_error():
    """Bearing friction so large (mu d k / (2 cos phi r_k) ~ 1.3 > 1) that the fixed point
    diverges on every moving sample: the llvm path raises the numpy path's
    BearingFrictionError (the same sample, joint and message); samples at rest converge."""
    an = analyse(parse_mechanism(SHAFT.format(z1=0.02, z2=0.06, mu=0.5, d=0.15, ML=-4.0)))
    q = np.zeros((6, 1))
    qd = np.array([[0.0], [0.0], [0.0], [2.0], [-1.0], [0.0]])
    ref = _failure(an, q, qd, q, "numpy", BearingFrictionError)
    got = _failure(an, q, qd, q, "llvm", BearingFrictionError)
    assert (got.sample, got.joint, got.lines()) == (ref.sample, ref.joint, ref.lines()) and ref.sample == 3


def _planetary_with_bearing_friction(mu: float, bore: float):
    mech = load_mechanism(MECH / "planetary_3p_rated.yaml")
    return analyse(dataclasses.replace(mech, joints=tuple(dataclasses.replace(j, bearings=tuple(
        dataclasses.replace(b, friction_coefficient=mu, bore=bore) for b in j.bearings)) for j in mech.joints)))


def test_friction_that_changes_the_sign_pattern_converges_as_on_the_numpy_path():
    """planetary_3p_rated with bearing friction large enough (mu 0.9, 40 mm bores) that the
    converged moments change tooth force signs: the block's affine model for its pattern at
    zero moments does not converge, the numpy path (its sign search each iteration) does;
    so does the kernel, by the whole block's loop from zero moments (it raised
    BearingFrictionError), to the same moments.  The block has more bearing joints than
    llvm.bearings.NEWTON_JOINTS (the fixed point on its loads)."""
    an = _planetary_with_bearing_friction(0.9, 0.04)
    assert max(len(bb.joints) for bb in solver_for(an).kernel_program().losses.bearing_blocks.values()) > NEWTON_JOINTS
    q, qd, qdd = motion(an, 40, seed=1)
    with np.errstate(all="ignore"):
        ref, res = (solve(an, q, qd, qdd, backend=b) for b in ("numpy", "llvm"))
    moments_agree(res, ref)
    assert np.max(worst(res, ref)) <= TOL


def test_a_many_joint_block_that_does_not_converge_fails_the_same_sample():
    """Larger still (50 mm bores): no pattern's iteration converges; both paths raise
    BearingFrictionError at the same sample (each names the joint of largest relative
    change in its own last iteration: the planets' are near ties)."""
    an = _planetary_with_bearing_friction(0.9, 0.05)
    q, qd, qdd = motion(an, 40, seed=1)
    ref = _failure(an, q, qd, qdd, "numpy", BearingFrictionError)
    got = _failure(an, q, qd, qdd, "llvm", BearingFrictionError)
    assert got.sample == ref.sample and got.joint in {j.name for j in an.mech.joints if j.bearings}


def test_friction_that_locks_the_mechanism_fails_the_same_sample_on_both_paths():
    """The rated Bendix wrist with absurd bearing friction (mu 5, 200 mm bores): the moments
    grow without bound, past the largest float.  Both paths raise BearingFrictionError at
    the same sample, never a result with an infinite friction moment (the kernel's test
    |g - Mb| <= TOL |g| held at g = inf, so its Newton blocks returned inf and NaN loads;
    the numpy path's sign search met the overflowed right-hand side, a SignError)."""
    mech = load_mechanism(MECH / "bendix_wrist_rated.yaml")
    an = analyse(dataclasses.replace(mech, joints=tuple(dataclasses.replace(j, bearings=tuple(
        dataclasses.replace(b, friction_coefficient=5.0, bore=0.2) for b in j.bearings)) for j in mech.joints)))
    q, qd, qdd = motion(an, 12, seed=1)
    ref = _failure(an, q, qd, qdd, "numpy", BearingFrictionError)
    got = _failure(an, q, qd, qdd, "llvm", BearingFrictionError)
    assert got.sample == ref.sample == 1          # sample 0 is at rest: no bearing friction there
    assert got.joint in {j.name for j in an.mech.joints if j.bearings}


# --- the comparison catches a wrong kernel ---------------------------------------------------
def _reversed_couples(lp):
    """The LossProgram with every friction couple of the kernel reversed (block maps' phi,
    propagated couples in F, the world-frame blocks' couples; the hot pairs' maps, made
    from phi with the program, dropped: every pair then takes the reversed correction)."""
    blocks = {b: dataclasses.replace(bl, phi=None if bl.phi is None else -bl.phi, hot=(),
                                     couple_F=None if bl.couple_F is None else -bl.couple_F)
              for b, bl in lp.blocks.items()}
    return dataclasses.replace(lp, blocks=blocks, couple={ci: -v for ci, v in lp.couple.items()})


def _hot_maps_rotated(lp):
    """The LossProgram with each hot pair's stored map (:mod:`gearcli.dynamics.llvm.lossy_maps`)
    under the next pair's key."""
    def rotated(hot):
        return tuple(zip([k for k, _ in hot], [L for _, L in hot][1:] + [L for _, L in hot][:1]))
    assert any(len(bl.hot) > 1 for bl in lp.blocks.values())
    return dataclasses.replace(lp, blocks={b: dataclasses.replace(bl, hot=rotated(bl.hot)) for b, bl in lp.blocks.items()})


def _joint_columns(lp, cols, factor):
    flt = lp.joint_flt.copy()
    flt[:, cols] *= factor
    return dataclasses.replace(lp, joint_flt=flt)


@pytest.mark.parametrize("key,mutate", [
    ("paper_2dof.yaml", _reversed_couples), ("servo_joint_rated.yaml", _reversed_couples),
    ("planetary_3p.yaml", _reversed_couples), ("planetary_3p.yaml", _hot_maps_rotated),
    ("rack", lambda lp: _joint_columns(lp, slice(0, 6), -1.0)),              # joint friction on the parent
    ("rack", lambda lp: _joint_columns(lp, [6], -1.0)),                      # Coulomb friction with the rate
    ("spur", lambda lp: dataclasses.replace(lp, rate_flt=-lp.rate_flt)),       # s_v reversed
    ("paper_2dof.yaml", lambda lp: dataclasses.replace(lp, loss_flt=lp.loss_flt * [1.0, 2.0])),  # gear_loss arm
])
def test_a_wrong_loss_program_is_caught(key, mutate):
    """A kernel with its friction couples, its joint friction loads, its relative rates or its
    mesh loss outputs wrong must fail the comparison of test_llvm_equals_numpy_with_losses."""
    an = analyse(mechanism(key))
    sol = solver_for(an)
    prog = sol.kernel_program()
    q, qd, qdd = motion(an, 300)
    ref = solve(an, q, qd, qdd, backend="numpy")
    assert worst(solve(an, q, qd, qdd, backend="llvm"), ref) < TOL
    kept = sol._llvm
    sol._program, sol._llvm = dataclasses.replace(prog, losses=mutate(prog.losses)), None
    try:
        res = solve(an, q, qd, qdd, backend="llvm")
    finally:
        sol._program, sol._llvm = prog, kept
    assert worst(res, ref) > 1e3 * TOL


def test_bundled_design_with_losses_takes_the_llvm_path():
    """designs/servo_joint_losses.yaml's mechanism is lossy and solved compiled by default."""
    import yaml
    doc = yaml.safe_load((DESIGNS / "servo_joint_losses.yaml").read_text())
    rel = doc["cases"][0]["mechanism"]
    an = analyse(load_mechanism((DESIGNS / rel).resolve()))
    assert an.mech.has_losses and solver_for(an).choice().path == "llvm"


@pytest.mark.parametrize("mu, bore", [(0.9, 0.12), (0.99, 0.11)])
def test_slow_bearing_friction_converges_on_both_paths(monkeypatch, mu, bore):
    """A spur pair whose wheel turns in a bearing of mu 0.9-0.99 on a bore near its pitch
    diameter: the fixed point contracts by ~0.96 an iteration, so 500 plain iterations did
    not reach the tolerance on the numpy path while the kernel's Newton levels converge in
    2-7 ("auto" then succeeded or failed by the trajectory's length; issue 34, section 5).
    The numpy path's Anderson rescue converges, to the kernel's moments within their
    tolerances (each stops within 1e-12 of its own iterate; ~1/(1 - Lambda) = 25 apart)."""
    from gearcli import parse_mechanism
    from gearcli.dynamics import bearing_friction
    from test_loss_cli import SPUR
    jw = "  - {name: Jw, parent: frame, child: wheel, origin: {xyz: [0.075, 0, 0]}, axis: [0, 0, 1]}"
    an = analyse(parse_mechanism(SPUR.replace(jw, (
        "  - name: Jw\n    parent: frame\n    child: wheel\n    origin: {xyz: [0.075, 0, 0]}\n    axis: [0, 0, 1]\n"
        f"    bearings:\n      - {{name: w, position: 0.0, friction_coefficient: {mu}, bore: {bore}}}")), "s.yaml"))
    t = np.linspace(0, 1, 200)
    q, qd, qdd = np.sin(3 * t)[:, None], 3 * np.cos(3 * t)[:, None], -9 * np.sin(3 * t)[:, None]
    ref, res = (solve(an, q, qd, qdd, backend=b) for b in ("numpy", "llvm"))
    assert ref.bearing_iterations.max() > bearing_friction.MAX_ITERATIONS        # the rescue was needed
    assert np.max(worst(res, ref)) <= 1e-11
    monkeypatch.setattr(bearing_friction, "RESCUE", 0)
    with pytest.raises(bearing_friction.BearingFrictionError):
        solve(an, q, qd, qdd, backend="numpy")
