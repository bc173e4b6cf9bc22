"""``solve(..., out=previous)``: the results written into the arrays of an earlier Result.

Every backend must give, bit for bit, what a fresh solve gives, in ``out``'s own arrays
(which come filled with NaN, so an entry a backend skips shows), and return ``out``; a
Result of another shape, sample count or layout is refused; a failed call (no consistent
sign pattern) leaves nothing behind that spoils the next call.
"""
from __future__ import annotations

import numpy as np
import pytest

from test_kernel import FIELDS, mechanism, per_sample_loads, trajectory
from gearcli import analyse
from gearcli.dynamics.signs import SignError
from gearcli.dynamics.solve import solve

BACKENDS = ["numpy", "llvm"]


def _poisoned(res):
    """``res`` with every array filled with NaN, and the arrays (to check they are kept)."""
    for f in FIELDS:
        getattr(res, f)[...] = np.nan
    return res, [getattr(res, f) for f in FIELDS]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("key", ["loaded:bendix_wrist.yaml", "planetary_3p.yaml", "prismatic:4"])
@pytest.mark.parametrize("jobs", [1, 2])
def test_out_gives_the_fresh_bits(key, backend, jobs):
    an = analyse(mechanism(key))
    n = 4_321
    q, qd, qdd = trajectory(an, n, seed=7)
    loads = per_sample_loads(an, n)
    fresh = solve(an, q, qd, qdd, backend=backend, loads=loads, jobs=jobs)
    q2, qd2, qdd2 = trajectory(an, n, seed=8)
    out, arrays = _poisoned(solve(an, q2, qd2, qdd2, backend=backend, jobs=jobs))
    got = solve(an, q, qd, qdd, backend=backend, loads=loads, jobs=jobs, out=out)
    assert got is out
    for f, a in zip(FIELDS, arrays):
        assert getattr(got, f) is a, f
        assert np.array_equal(a, getattr(fresh, f)), f
    assert got.residual is None
    again = solve(an, q2, qd2, qdd2, backend=backend, jobs=jobs, out=out, verify=True)
    assert again is out and again.residual is not None and again.residual < 1e-9
    assert np.array_equal(out.motor, solve(an, q2, qd2, qdd2, backend=backend).motor)


@pytest.mark.parametrize("backend", BACKENDS)
def test_out_of_another_shape_is_refused(backend):
    an = analyse(mechanism("bendix_wrist.yaml"))
    other = analyse(mechanism("paper_2dof.yaml"))
    q, qd, qdd = trajectory(an, 300)
    with pytest.raises(ValueError, match="out.* 300 samples"):
        solve(an, q, qd, qdd, backend=backend, out=solve(an, q[:299], qd[:299], qdd[:299]))
    qo, qdo, qddo = trajectory(other, 300)
    with pytest.raises(ValueError, match="out.*shape"):
        solve(an, q, qd, qdd, backend=backend, out=solve(other, qo, qdo, qddo))
    res = solve(an, q, qd, qdd)
    res.joint = np.asfortranarray(res.joint)
    with pytest.raises(ValueError, match="out.joint .*C-ordered"):
        solve(an, q, qd, qdd, backend=backend, out=res)
    res = solve(an, q, qd, qdd)
    res.tau = res.tau.astype(np.float32)
    with pytest.raises(ValueError, match="out.tau .*float64"):
        solve(an, q, qd, qdd, backend=backend, out=res)
    res = solve(an, q, qd, qdd)
    with pytest.raises(ValueError, match="out.tau shares memory with q"):
        solve(an, res.tau, qd, qdd, backend=backend, out=res)      # tau (N, dof) like q
    res.motor_speed = res.motor[::-1][::-1]                        # a view of motor
    with pytest.raises(ValueError, match="out.motor shares memory with out.motor_speed"):
        solve(an, q, qd, qdd, backend=backend, out=res)
    res.motor_speed = None
    with pytest.raises(ValueError, match="out.motor_speed is NoneType"):
        solve(an, q, qd, qdd, backend=backend, out=res)


@pytest.mark.parametrize("backend", ["llvm"])
def test_out_after_a_sign_error(backend):
    """The failing-block record kept with ``out`` is reset sample by sample by the kernel."""
    an = analyse(mechanism("bendix_wrist.yaml"))
    n = 5_000
    q, qd, qdd = trajectory(an, n, seed=2)
    out = solve(an, q, qd, qdd, backend=backend, jobs=2)
    bad = qdd.copy()
    bad[[10, 4_000], 0] = np.nan
    for _ in range(2):        # the second time with the work arrays kept from the first
        with pytest.raises(SignError) as info, np.errstate(all="ignore"):
            solve(an, q, qd, bad, backend=backend, jobs=2, out=out, check_finite=False)
        assert info.value.sample == 10
    fresh = solve(an, q, qd, qdd, backend=backend, jobs=1)
    solve(an, q, qd, qdd, backend=backend, jobs=2, out=out)
    for f in FIELDS:
        assert np.array_equal(getattr(out, f), getattr(fresh, f)), f


@pytest.mark.parametrize("backend", ["llvm"])
def test_callers_on_several_threads_share_the_pool(backend):
    """Two threads solving at once (one pool: a caller whose worker is taken does the parts
    itself), each into its own out: the numbers of one-thread solves."""
    from concurrent.futures import ThreadPoolExecutor   # noqa: PLC0415
    an = analyse(mechanism("bendix_wrist.yaml"))
    trajs = [trajectory(an, 9_000, seed=s) for s in (11, 12)]
    refs = [solve(an, *t, backend=backend, jobs=1) for t in trajs]
    outs = [solve(an, *t, backend=backend, jobs=1) for t in trajs[::-1]]

    def stream(i):
        for _ in range(4):
            solve(an, *trajs[i], backend=backend, jobs=2, out=outs[i])
    with ThreadPoolExecutor(2) as callers:
        list(callers.map(stream, [0, 1]))
    for ref, out in zip(refs, outs):
        for f in FIELDS:
            assert np.array_equal(getattr(out, f), getattr(ref, f)), f


@pytest.mark.parametrize("backend", BACKENDS)
def test_out_carries_this_calls_losses(backend):
    """A lossy mechanism's loss fields (mesh and joint losses, friction, bearing iterations)
    in ``out`` are this call's, equal to a fresh solve's, never the previous call's (the
    numpy path once copied only the lossless fields into ``out``)."""
    an = analyse(mechanism("servo_joint_rated.yaml"))
    q, qd, qdd = trajectory(an, 500, seed=3)
    q2, qd2, qdd2 = trajectory(an, 500, seed=4)
    fresh = solve(an, q, qd, qdd, backend=backend)
    out = solve(an, q2, qd2, qdd2, backend=backend)
    got = solve(an, q, qd, qdd, backend=backend, out=out)
    for f in ("gear_loss", "joint_friction", "joint_loss", "bearing_iterations"):
        assert getattr(fresh, f) is not None, f
        np.testing.assert_array_equal(getattr(got, f), getattr(fresh, f), err_msg=f)
