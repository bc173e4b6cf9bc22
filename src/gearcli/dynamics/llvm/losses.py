"""Generated losses of one sample (:mod:`..losses`, :mod:`.loss_program`), for :mod:`.kernel`.

* :func:`mesh_rates`: each lossy mesh's rate theta'_{j,c} = (w_j - w_c) . R_c z_j (written
  to the ``rate`` output) and s_v = sign of it (0 at rest), known before any block solve;
* :func:`joint_friction`: rhs[L] -= the joints' friction loads, the generalised force Q per
  sample from the input ``jq`` (Coulomb and viscous, computed by the driver with the
  formulas of :mod:`..losses`; the bearing friction is :mod:`.bearings`'): about the axis
  (revolute) or along it through the joint origin (prismatic), on the child, reversed on the
  parent;
* :class:`LossyBlock`: a constant-frame block with lossy meshes.  Mesh friction adds
  sigma_i s_v,i phi_i to the column of t_i (phi_i its couples in F per unit of sigma s_v t),
  so the block matrix of sign pattern sigma is A_sigma + Phi D E^T, D = diag(sigma s_v),
  a rank-ml change of the matrix whose map X_sigma the block already has (stored maps, or
  :class:`~.world.LowRankBlock`).  By the Woodbury identity, with t0 = E^T X_sigma r
  and M = E^T X_sigma Phi (constants per pattern):

      t_l = (I + M D)^-1 t0   (an ml x ml solve),   x = X_sigma r - X_sigma Phi D t_l,

  the same sign search as the numpy path, whose maps are those of the changed matrix
  (:func:`..blocks._constant_block`);
* :func:`world_columns`: a world-frame block's friction couples added to its matrix per
  sample (sigma s_v (R_c couple) on gear j's rows, minus on k's);
* :func:`propagate`: the solved couples s_v |t| on the links of later blocks.
"""
from __future__ import annotations

import llvmlite.ir as ir
import numpy as np

from .build import D, Emitter
from .links import Sample, floats
from .signs import SignedBlock, _rows_switch, signs_of
from .world import eliminate


def _sign(e: Emitter, v):
    """sign(v) as a double: -1, 0 or 1 (np.sign; NaN gives 0 here, NaN there: no
    sign pattern accepts a NaN sample anyway)."""
    pos = e.b.uitofp(e.b.fcmp_ordered(">", v, ir.Constant(D, 0.0)), D)
    neg = e.b.uitofp(e.b.fcmp_ordered("<", v, ir.Constant(D, 0.0)), D)
    return e.sub(pos, neg)


def mesh_rates(e: Emitter, s: Sample, lp, row) -> list:
    """s_v of every lossy mesh (doubles), its rate stored into ``row`` (double*)."""
    sv = []
    for k in range(len(lp.rate_meshes)):
        j, c = (int(v) for v in lp.rate_int[k])
        z = e.mv(s.R[c], floats(lp.rate_flt[k]))
        rate = e.dot(e.vsub(s.w[j], s.w[c]), z)
        e.store(rate, row, k)
        sv.append(_sign(e, e.const(rate)))
    return sv


def joint_friction(e: Emitter, s: Sample, lp, row) -> None:
    """rhs[L] -= Q * the unit wrench of each friction joint on L (``row``: the sample's Q)."""
    for k in range(lp.joints.shape[0]):
        ji, child, parent, prismatic = (int(v) for v in lp.joints[k, :4])
        f = floats(lp.joint_flt[k])
        Q = e.load(row, k)
        Rc, oc = s.R[child], s.o[child]
        z = e.mv(Rc, f[:3])
        for L, sign in ((child, 1.0), (parent, -1.0)):
            if L < 0:
                continue
            if prismatic:
                oj = e.vadd(oc, e.mv(Rc, f[3:6]))
                w = z + e.cx(e.vsub(oj, s.o[L]), z)
            else:
                w = (0.0, 0.0, 0.0) + z
            s.rhs[L] = tuple(e.sub(s.rhs[L][h], e.mul(e.mul(sign, Q), w[h])) for h in range(6))


class LossyBlock:
    """A constant-frame block with lossy meshes around its lossless solve ``inner`` (a
    :class:`~.signs.SignedBlock` or :class:`~.world.LowRankBlock`): the
    module docstring's rank-ml correction of each trial and of the accepted solution."""

    def __init__(self, inner, bl, sv: list):
        self.inner, self.bl = inner, bl
        self.tcols, self.n = inner.tcols, inner.n
        self.d_sv = [sv[k] for k in bl.rates]
        self.aug = None
        if isinstance(inner, SignedBlock) and inner.table is None:
            # one switch for X r and the constants X Phi: per pattern the rows [X, 0] and,
            # for each couple b, [0, (X Phi^T)[:, b] e_b], times [r, 1, ..., 1]
            ml, (n, nr) = len(bl.positions), inner.maps[0].shape
            self.aug = []
            for X in inner.maps:
                A = np.zeros((n * (1 + ml), nr + ml))
                A[:n, :nr] = X
                XP = X @ bl.phi.T
                for k in range(ml):
                    A[n * (1 + k):n * (2 + k), nr + k] = XP[:, k]
                self.aug.append(A)

    def _products(self, e: Emitter, fn, p, need: list, r: list, tag: str):
        """({row: (X r)[row]}, per couple b {row: (X Phi^T)[row, b]}) of pattern p."""
        ml, n = len(self.bl.positions), self.n
        if self.aug is not None:
            idx = need + [n * (1 + b) + i for b in range(ml) for i in need]
            vals = _rows_switch(e, fn, p, self.aug, idx, list(r) + [1.0] * ml, tag)
            k = len(need)
            return dict(zip(need, vals[:k])), [dict(zip(need, vals[k * (1 + b):k * (2 + b)])) for b in range(ml)]
        xr = dict(zip(need, self.inner.rows(e, fn, p, need, r, tag)))
        return xr, [dict(zip(need, self.inner.rows(e, fn, p, need, floats(self.bl.phi[b]), f"{tag}_phi{b}")))
                    for b in range(ml)]

    def rows(self, e: Emitter, fn, p, rows: list, r: list, tag: str) -> list:
        """Rows ``rows`` of the solution of the changed matrix for pattern p (i64)."""
        bl, m = self.bl, len(self.tcols)
        lt = [self.tcols[i] for i in bl.positions]
        need = sorted(set(rows) | set(lt))
        xr, xf = self._products(e, fn, p, need, r, tag)
        sig = signs_of(e, p, m)
        d = [e.mul(sig[i], sv) for i, sv in zip(bl.positions, self.d_sv)]
        K = [[e.add(1.0 if a == b else 0.0, e.mul(xf[b][lt[a]], d[b])) for b in range(len(lt))]
             for a in range(len(lt))]
        y = eliminate(e, K, [xr[c] for c in lt])
        dy = [e.mul(db, yb) for db, yb in zip(d, y)]
        return [e.const(e.sub(xr[i], e.dot([xf[b][i] for b in range(len(lt))], dy))) for i in rows]


def world_columns(lp, bl, s: Sample):
    """The hook of a world-frame block (:class:`~.world.WorldBlock` ``extra``):
    adds sigma s_v (R_c couple) to the moment rows of gear j (minus on k) in each lossy
    t column of the block matrix A (``tcols`` its t columns, ``sig`` the trial's signs;
    s_v from ``s.sv``)."""
    sv = s.sv

    def add(e: Emitter, A: list, tcols: list, sig: list) -> None:
        for n, k, ci, rows in zip(bl.positions, bl.rates, bl.circuits, bl.rows):
            fr = e.mv(s.R[_carrier(lp, k)], floats(lp.couple[ci]))
            coef = e.mul(sig[n], sv[k])
            for row, sign in rows:
                for h in range(3):
                    A[6 * row + 3 + h][tcols[n]] = e.add(A[6 * row + 3 + h][tcols[n]], e.mul(coef, e.mul(float(sign), fr[h])))
    return add


def _carrier(lp, k: int) -> int:
    return int(lp.rate_int[k, 1])


def propagate(e: Emitter, s: Sample, lp, bl, F: int, x: list, tcols: list, sig: list) -> None:
    """rhs[L] -= the solved friction couples on the later links L: s_v |t| (couple on j)
    on j, its opposite on k (the couple in F turned by R_F, as :func:`..blocks.solve_blocks`;
    world blocks: sigma s_v t (R_c couple), as the column of :class:`..equations.Columns`)."""
    sv = s.sv
    for a, (n, k, ci) in enumerate(zip(bl.positions, bl.rates, bl.circuits)):
        if not bl.later[a]:
            continue
        if bl.phi is not None:
            m = e.mv(s.R[F], floats(bl.couple_F[a]))
            amount = e.mul(sv[k], e.call("fabs", x[tcols[n]]))
        else:
            m = e.mv(s.R[_carrier(lp, k)], floats(lp.couple[ci]))
            amount = e.mul(e.mul(sig[n], sv[k]), x[tcols[n]])
        for L, sign in bl.later[a]:
            s.rhs[L] = s.rhs[L][:3] + tuple(e.sub(s.rhs[L][3 + h], e.mul(float(sign), e.mul(amount, m[h])))
                                            for h in range(3))
