"""Large generated mechanisms (100+ joints): the analysis finishes and its schedule is valid.

Validity is checked structurally (every link in exactly one block; each block's equations
contain only its own unknowns and unknowns of blocks solved before it; each block square)
and numerically (the block solve along random samples leaves a Newton-Euler residual at
rounding level, and agrees with the simultaneous solve).  No timing here: see
``benchmarks/bench_check.py``.
"""
from __future__ import annotations

import numpy as np
import pytest

from big_mechanisms import binary_tree_urdf, geared_chain, serial_chain
from gearcli import analyse, parse_mechanism, solve
from gearcli.analysis.schedule import unknown_groups
from gearcli.io.urdf_reader import parse_urdf


def assert_schedule_valid(an) -> None:
    moving = set(an.tree.moving)
    seen = [x for blk in an.schedule for x in blk]
    assert sorted(seen) == sorted(moving), "every moving link in exactly one block"
    block_of = {x: i for i, blk in enumerate(an.schedule) for x in blk}
    groups = unknown_groups(an)
    # a group is solved in the first block holding one of its links; every other link it
    # acts on must come in that block or later (its equations then use a known value)
    owned = [0] * len(an.schedule)
    for g in groups:
        first = min(block_of[x] for x in g.links)
        owned[first] += g.size
        assert all(block_of[x] >= first for x in g.links)
    assert owned == [6 * len(blk) for blk in an.schedule], "each block square"


def assert_solves(an, samples=4) -> None:
    rng = np.random.default_rng(1)
    q, qd, qdd = (rng.uniform(-1, 1, (samples, an.dof)) for _ in range(3))
    res = solve(an, q, qd, qdd, verify=True)
    assert np.all(np.isfinite(res.motor))
    assert res.residual < 1e-9
    full = solve(an, q, qd, qdd, method="full")
    np.testing.assert_allclose(res.motor, full.motor, rtol=1e-7, atol=1e-7 * np.abs(full.motor).max())


@pytest.mark.parametrize("n", [120, 200])
def test_serial_chain(n):
    an = analyse(parse_mechanism(serial_chain(n), f"chain{n}.yaml"))
    assert an.dof == n
    assert_schedule_valid(an)
    # a serial chain is solved one link at a time from the tip down
    assert an.schedule == tuple((i,) for i in range(n, 0, -1))
    if n == 120:
        assert_solves(an)


def test_geared_chain_100():
    an = analyse(parse_mechanism(geared_chain(100), "geared100.yaml"))
    assert an.dof == 100 and len(an.circuits) == 100
    assert_schedule_valid(an)
    # link Li (id 2i-1) carries its joint reaction and its mesh force: solved before its
    # pinion Pi (id 2i), which then gives the motor torque; from the tip down
    expected = tuple((x,) for i in range(100, 0, -1) for x in (2 * i - 1, 2 * i))
    assert an.schedule == expected
    assert_solves(an)


def test_binary_tree_126_joints():
    an = analyse(parse_urdf(binary_tree_urdf(6), "tree.urdf"))
    assert an.dof == 126
    assert_schedule_valid(an)
    level = {x: an.level[x] for x in an.tree.moving}
    order = [level[blk[0]] for blk in an.schedule]
    assert order == sorted(order, reverse=True), "deepest links first"
    assert_solves(an)
