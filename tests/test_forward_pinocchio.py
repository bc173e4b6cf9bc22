"""Mass matrix and forward dynamics of direct-drive arms against Pinocchio (issue 20).

UR5 and Panda from ``example-robot-data``, read by gearcli (direct-drive motors) and by
``pin.buildModelFromUrdf``: gearcli's ``mass_matrix`` equals Pinocchio's CRBA, and its
``forward_dynamics`` Pinocchio's ABA, to 1e-10 of their largest entry.  Panda's second
finger mimics the first (q_all = S q): there the reference is S^T M_crba S, and the
accelerations solve S^T M S qdd = T - S^T nle(q, S qd) (Pinocchio's nonLinearEffects).
"""
from __future__ import annotations

import numpy as np
import pytest

from gearcli import analyse
from gearcli.dynamics.forward import forward_dynamics, mass_matrix
from gearcli.io.urdf_reader import load_urdf
from metrics import rel_err
from test_urdf import erd, needs_erd

pin = pytest.importorskip("pinocchio")

ARMS = ["ur_description/urdf/ur5_robot.urdf", "panda_description/urdf/panda.urdf"]


def pin_config(model, mech, q_all):
    """Pinocchio's q of one sample of gearcli joint angles (a continuous joint is (cos, sin))."""
    qp = pin.neutral(model)
    idx_v = []
    for ji, jt in enumerate(mech.joints):
        jm = model.joints[model.getJointId(jt.name)]
        if jm.nq == 2:
            qp[jm.idx_q:jm.idx_q + 2] = np.cos(q_all[ji]), np.sin(q_all[ji])
        else:
            qp[jm.idx_q] = q_all[ji]
        idx_v.append(jm.idx_v)
    return qp, idx_v


@needs_erd
@pytest.mark.parametrize("backend", ["llvm", "numpy"])    # the mass kernel, the stacked reference
@pytest.mark.parametrize("rel_path", ARMS)
def test_mass_matrix_and_forward_dynamics_equal_pinocchio(rel_path, backend):
    path = erd(rel_path)
    mech = load_urdf(path)
    an = analyse(mech)
    assert np.array_equal(an.A, np.eye(an.dof))      # direct drive
    S = an.S                                         # real joint angles = S q (a mimic finger)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    rng = np.random.default_rng(0)
    n = 12
    q, qd, T = rng.uniform(-2, 2, (n, an.dof)), rng.uniform(-2, 2, (n, an.dof)), rng.uniform(-20, 20, (n, an.dof))
    M = mass_matrix(an, q, backend=backend)
    qdd = forward_dynamics(an, q, qd, T, backend=backend)
    M_pin, qdd_pin = np.zeros_like(M), np.zeros_like(qdd)
    for s in range(n):
        qp, iv = pin_config(model, mech, S @ q[s])
        Mp = pin.crba(model, data, qp)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T          # CRBA fills the upper triangle
        M_pin[s] = S.T @ Mp[np.ix_(iv, iv)] @ S
        v = np.zeros(model.nv)
        v[iv] = S @ qd[s]
        if S.shape[0] == S.shape[1]:
            tau = np.zeros(model.nv)
            tau[iv] = T[s]
            qdd_pin[s] = pin.aba(model, data, qp, v, tau)[iv]
        else:
            nle = pin.nonLinearEffects(model, data, qp, v)[iv]
            qdd_pin[s] = np.linalg.solve(M_pin[s], T[s] - S.T @ nle)
    assert rel_err(M, M_pin) < 1e-10
    assert rel_err(qdd, qdd_pin) < 1e-10
