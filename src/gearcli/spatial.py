"""Rotations, homogeneous transforms and batched vector helpers.

Batched arrays carry the sample axis first: vectors ``(N, 3)``, rotations ``(N, 3, 3)``.
"""
from __future__ import annotations

import numpy as np


def rot_x(a: float) -> np.ndarray:
    """Rotation matrix (3, 3) by ``a`` rad about x."""
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a: float) -> np.ndarray:
    """Rotation matrix (3, 3) by ``a`` rad about y."""
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a: float) -> np.ndarray:
    """Rotation matrix (3, 3) by ``a`` rad about z."""
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rpy_matrix(rpy) -> np.ndarray:
    """URDF roll-pitch-yaw (fixed axes x, y, z): R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    return rot_z(y) @ rot_y(p) @ rot_x(r)


def matrix_rpy(R: np.ndarray) -> np.ndarray:
    """Inverse of :func:`rpy_matrix` (roll, pitch, yaw)."""
    pitch = np.arctan2(-R[2, 0], np.hypot(R[0, 0], R[1, 0]))
    if np.hypot(R[0, 0], R[1, 0]) < 1e-12:
        return np.array([np.arctan2(-R[1, 2], R[1, 1]), pitch, 0.0])
    return np.array([np.arctan2(R[2, 1], R[2, 2]), pitch, np.arctan2(R[1, 0], R[0, 0])])


def align_z(axis) -> np.ndarray:
    """A rotation whose third column is the unit vector ``axis`` (minimal rotation from z)."""
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    z = np.array([0.0, 0.0, 1.0])
    v = np.cross(z, a)
    c = float(a @ z)
    if np.linalg.norm(v) < 1e-15:
        return np.eye(3) if c > 0 else rot_x(np.pi)
    K = skew(v)
    return np.eye(3) + K + K @ K / (1.0 + c)


def skew(v) -> np.ndarray:
    """Cross-product matrix [v]x (3, 3) of ``v`` (3,): [v]x u = v x u."""
    x, y, z = v
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def mv(R: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Batched matrix-vector product R x: (N,3,3) or (3,3) times (N,3) or (3,)."""
    if R.ndim == 2:
        return x @ R.T
    if x.ndim == 1:
        if R.flags.c_contiguous:   # one BLAS call instead of N small products
            return (R.reshape(-1, 3) @ x).reshape(R.shape[0], 3)
        return R @ x
    return np.einsum("nij,nj->ni", R, x)


def mtv(R: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Batched R^T x for R (N,3,3) and x (N,3)."""
    return np.einsum("nji,nj->ni", R, x)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of (N,3) arrays (broadcasting), faster than np.cross for small rows."""
    a, b = np.broadcast_arrays(a, b)
    out = np.empty(a.shape, dtype=np.result_type(a, b))
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    np.subtract(a1 * b2, a2 * b1, out=out[..., 0])
    np.subtract(a2 * b0, a0 * b2, out=out[..., 1])
    np.subtract(a0 * b1, a1 * b0, out=out[..., 2])
    return out
