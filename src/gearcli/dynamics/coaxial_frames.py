"""Constant frames for blocks whose links turn about one line (a planetary's sun, carrier
and ring): a revolute joint's reaction space (the forces and the moments perpendicular to
its axis, at a point of the axis) is invariant under rotation about that axis, so its basis
may be carried by any link of a coaxial group holding the joint's parent and child.  The
block solver (:mod:`.blocks`) then writes the block in that link's frame F and turns the
solved reaction to the child's basis by the angle of the child relative to F, a linear
combination ``q @ row`` of the real joint coordinates (rad)."""
from __future__ import annotations

import numpy as np

from .kinematics import forward


def coaxial_links(an, ji: int) -> set[int]:
    """Links of every coaxial group that holds both the parent and the child of revolute
    joint ``ji`` (each turns about the joint's axis relative to both)."""
    jt = an.mech.joints[ji]
    p, c = an.tree.index[jt.parent], an.tree.index[jt.child]
    out: set[int] = set()
    for g in an.groups:
        if p in g.members and c in g.members:
            out |= set(g.members)
    return out


def _angles(an, ji: int, F: int, q: np.ndarray) -> np.ndarray:
    """(N,) angle of joint ``ji``'s child relative to link F about the joint axis, rad,
    at every real joint coordinate row of ``q`` (N, J) (home: 0)."""
    kin = forward(an.mech, an.tree, np.vstack([np.zeros(q.shape[1]), q]))
    c = an.tree.index[an.mech.joints[ji].child]
    E0 = kin.Rj[ji][0]
    dF = kin.R[F][1:] @ kin.R[F][0].T
    dc = kin.R[c][1:] @ kin.R[c][0].T
    m = E0.T @ np.swapaxes(dF, 1, 2) @ dc @ E0
    return np.arctan2(m[:, 1, 0], m[:, 0, 0])


def turn_row(an, ji: int, F: int) -> np.ndarray | None:
    """(J,) row with angle(child of ``ji`` relative to F about the axis) = q @ row, found
    from unit turns of each joint and checked at random configurations (the joint's axis
    line fixed in F, the angle linear in q); None if F cannot carry the joint's basis."""
    J = len(an.mech.joints)
    row = _angles(an, ji, F, 0.5 * np.eye(J)) / 0.5
    row = np.where(np.abs(row - np.round(row)) < 1e-9, np.round(row), row)
    q = np.random.default_rng(0).uniform(-0.4, 0.4, (3, J))
    kin = forward(an.mech, an.tree, np.vstack([np.zeros(J), q]))
    RF, oF, oj, zj = kin.R[F], kin.o[F], kin.oj[ji], kin.Rj[ji][:, :, 2]
    in_F = [np.einsum("nji,nj->ni", RF, v) for v in (oj - oF, zj)]   # axis line in F's frame
    fixed = all(np.allclose(v, v[0], atol=1e-9 * max(1.0, np.abs(v).max())) for v in in_F)
    same = np.allclose(np.angle(np.exp(1j * (_angles(an, ji, F, q) - q @ row))), 0.0, atol=1e-9)
    return row if fixed and same else None
