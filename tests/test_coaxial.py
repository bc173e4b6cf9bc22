"""Real bearings of coaxial links (paper Fig. 5, Eqs. 23-24).

coaxial_fig5.yaml is paper_2dof with shaft 3 borne inside the hub of link 1 instead of on
the base.  Both files describe the same canonical graph, so the motor torques and tooth
forces must agree, the bearing of shaft 3 must carry the same wrench as the canonical joint
0-3 (Eq. 23-24: link 3's other loads are unchanged), and link 1's bearing must carry that
wrench in addition (link 1 now holds shaft 3): W_J1(fig5) = W_J1(paper) + W_J3(fig5),
all wrenches on the child, in the base frame, about one point.
"""
from pathlib import Path

import numpy as np

from gearcli.dynamics.solve import joint_space, solve
from gearcli import analyse
from gearcli.dynamics.kinematics import forward
from gearcli import load_mechanism

MECH = Path(__file__).resolve().parents[1] / "mechanisms"


def world_wrenches(an, q, res):
    """{joint name: (N, 6) wrench on the child, base frame, about the base origin}."""
    qa, _, _ = joint_space(an, q)
    kin = forward(an.mech, an.tree, qa)
    out = {}
    for ji, jt in enumerate(an.mech.joints):
        R, o = kin.Rj[ji], kin.oj[ji]
        f = np.einsum("nij,nj->ni", R, res.joint[:, ji, :3])
        m = np.einsum("nij,nj->ni", R, res.joint[:, ji, 3:]) + np.cross(o, f)
        out[jt.name] = np.hstack([f, m])
    return out


def test_fig5_bearings_are_the_canonical_reactions_redistributed():
    paper = analyse(load_mechanism(MECH / "paper_2dof.yaml"))
    fig5 = analyse(load_mechanism(MECH / "coaxial_fig5.yaml"))
    rng = np.random.default_rng(5)
    q, qd, qdd = (rng.normal(size=(200, 2)) for _ in range(3))
    rp, rf = solve(paper, q, qd, qdd), solve(fig5, q, qd, qdd)
    scale = np.abs(rp.joint).max()
    assert np.allclose(rf.motor, rp.motor, rtol=1e-12, atol=1e-12 * np.abs(rp.motor).max())
    assert np.allclose(rf.gear_t, rp.gear_t, rtol=1e-12, atol=1e-12 * np.abs(rp.gear_t).max())
    wp, wf = world_wrenches(paper, q, rp), world_wrenches(fig5, q, rf)
    assert np.allclose(wf["J3"], wp["J3"], atol=1e-11 * scale)                  # Eq. 23-24
    assert np.allclose(wf["J1"], wp["J1"] + wf["J3"], atol=1e-11 * scale)
    for name in ("J2", "J4", "J5"):
        assert np.allclose(wf[name], wp[name], atol=1e-11 * scale)
    assert np.abs(wf["J1"] - wp["J1"]).max() > 1e-3 * scale   # the hub bearing really changes
