"""Load sharing in a redundant gear set: the elastic model that splits the load among
parallel paths (N planets between one sun and one ring, a duplicated pair).

Rigid-body equations leave the tooth forces of a redundant set undetermined: the block of
equations has more unknowns n than equations m.  Among all solutions of the Newton-Euler
equations A x = r (every equation exactly) the model takes the one minimising the mesh
complementary energy sum t_i^2 / k_i, with k_i the mesh stiffness (``GearPair.stiffness``,
N/m; equal for all meshes by default).  The minimiser solves the KKT system

    [ D  A^T ] [ x ]   [ 0 ]
    [ A   0  ] [ l ] = [ r ],     D = diag(1/k_i on the tooth forces t, 0 elsewhere),

which is regular exactly when A has full row rank and every null direction of A changes
some t (:func:`null_directions_without_t` finds the ones that do not: bearing reactions a
redundancy leaves undetermined, beyond this model).  x = X r is linear in r: for a block
written in a constant frame X (n, m) is computed once per sign pattern of Eq. 14.
"""
from __future__ import annotations

import numpy as np

from ..errors import GearcliError

_RTOL = 1e-10


class SharingError(GearcliError):
    """The load-sharing model does not determine the loads (a singular KKT system)."""

    def __init__(self, message: str):
        super().__init__()
        self.message = message

    def lines(self) -> list[str]:
        """The one-line message of this error."""
        return [self.message]


def mesh_weights(an, groups) -> np.ndarray:
    """(n,) diagonal of D for the unknowns of ``groups``: for a mesh (tangential force or
    ideal-coupling torque) of a redundant set ``an.redundant``, 1/k scaled by the set's
    largest 1/k (1 for every mesh of a set without ``stiffness``: equal sharing); 1 for a
    determinate mesh (its t is fixed by the equations: the weight does not matter, and a
    weight of the sets' order keeps the KKT system well scaled); 0 for joint reactions and
    motor torques.  The objective separates by set, so only ratios within a set matter."""
    scale = {}
    for members in an.redundant:
        k = [an.mech.gears[an.circuits[i].gear].stiffness for i in members]
        kmin = min((x for x in k if x is not None), default=None)
        scale.update({i: 1.0 if kmin is None or x is None else kmin / x for i, x in zip(members, k)})
    w = []
    for g in groups:
        if g.kind == "mesh":
            w.append(scale.get(g.index, 1.0))
        else:
            w.extend([0.0] * g.size)
    return np.asarray(w, float)


def kkt(A: np.ndarray, w: np.ndarray) -> np.ndarray:
    """KKT matrices (..., n+m, n+m) of min x^T diag(w) x subject to A x = r, A (..., m, n);
    D is scaled by the largest |A| entry (the minimiser does not change) for balance."""
    *lead, m, n = A.shape
    s = np.max(np.abs(A), axis=(-2, -1), keepdims=True)
    K = np.zeros((*lead, n + m, n + m))
    K[..., :n, :n] = s * np.eye(n) * w
    K[..., :n, n:] = np.swapaxes(A, -1, -2)
    K[..., n:, :n] = A
    return K


def least_load_map(A: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(n, m) matrix X with x = X r the minimiser of sum w t^2 subject to A x = r, for one
    constant block matrix A (m, n), m < n.  Raises :class:`SharingError` if not unique."""
    m, n = A.shape
    rhs = np.vstack([np.zeros((n, m)), np.eye(m)])
    try:
        X = np.linalg.solve(kkt(A, w), rhs)[:n]
    except np.linalg.LinAlgError:
        X = None
    if X is None or not np.all(np.isfinite(X)) or np.max(np.abs(A @ X - np.eye(m))) > 1e-8:
        raise SharingError("the load-sharing (KKT) system of a redundant gear set is singular")
    return X


def least_load_solve(A: np.ndarray, r: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Minimisers x (N, n) of sum w t^2 subject to A x = r, sample by sample: A (N, m, n),
    r (N, m).  Raises :class:`SharingError` if a KKT system is singular."""
    N, m, n = A.shape
    rhs = np.concatenate([np.zeros((N, n)), r], axis=1)[:, :, None]
    try:
        return np.linalg.solve(kkt(A, w), rhs)[:, :n, 0]
    except np.linalg.LinAlgError:
        raise SharingError("the load-sharing (KKT) system of a redundant gear set is singular") from None


def null_directions_without_t(A: np.ndarray, w: np.ndarray) -> tuple[int, int]:
    """(rank of A (m, n), number of null directions of A that change no weighted unknown):
    the load sharing is unique exactly when the rank is m and that number is 0."""
    _, sv, Vt = np.linalg.svd(A)
    r = numerical_rank(sv)
    N = Vt[r:].T                                      # (n, d) null space
    Nt = N[w > 0]
    if N.shape[1] == 0:
        return r, 0
    st = np.linalg.svd(Nt, compute_uv=False) if Nt.size else np.zeros(0)
    seen = int(np.sum(st > 1e-8)) if st.size else 0
    return r, N.shape[1] - seen


def numerical_rank(sv: np.ndarray) -> int:
    """Numerical rank of a matrix from its singular values ``sv`` (largest first): those above
    _RTOL times the largest."""
    return int(np.sum(sv > _RTOL * sv[0])) if sv.size and sv[0] > 0 else 0
