"""Generated losses of one sample (:mod:`..losses`, :mod:`.loss_program`), for :mod:`.kernel`.

* :func:`mesh_rates`: each lossy mesh's rate theta'_{j,c} = (w_j - w_c) . R_c z_j and
  s_v = sign of it (0 at rest), known before any block solve;
* :func:`joint_friction`: each friction joint's own friction -F_c sign(q'_J) - F_v q'_J
  from the sample's joint rate (the law of :func:`..losses.friction_force`; the bearing
  friction is :mod:`.bearings`'); rhs[L] -= that generalised force Q times the joint's unit
  wrench: about the axis (revolute) or along it through the joint origin (prismatic), on
  the child, reversed on the parent;
* :func:`write_losses`: the loss outputs of the sample, as :func:`..losses.fill_losses`:
  ``gear_loss`` c_p |t_p| |theta'_{j,c}| r_j, ``joint_friction`` the own friction less the
  converged bearing friction s_J Mb_J of :mod:`.bearings`, ``joint_loss`` -friction * q'_J;
* :func:`lossy_block`: a constant-frame block with lossy meshes.  Mesh friction adds
  sigma_i s_v,i phi_i to the column of t_i (phi_i its couples in F per unit of sigma s_v t).
  A block with few patterns (:class:`TabledBlock`) runs the sign search over the changed
  matrix's stored maps of the sample's s_v pattern (:attr:`.loss_program.BlockLosses.maps`,
  the numpy path's maps, :func:`..blocks._constant_block`): a trial costs what a lossless
  one does.  Otherwise
  (:class:`LossyBlock`) the block matrix of sign pattern sigma is A_sigma + Phi D E^T,
  D = diag(sigma s_v), a rank-ml change of the matrix whose map X_sigma the block already
  has (stored maps, or :class:`~.world.LowRankBlock`).  By the Woodbury identity, with
  t0 = E^T X_sigma r and M = E^T X_sigma Phi (constants per pattern):

      t_l = (I + M D)^-1 t0   (an ml x ml solve),   x = X_sigma r - X_sigma Phi D t_l;

* :func:`world_columns`: a world-frame block's friction couples added to its matrix per
  sample (sigma s_v (R_c couple) on gear j's rows, minus on k's);
* :func:`couples_F`, :func:`propagate`: the solved couples s_v |t| on the links of later
  blocks (constant frame: in the mesh's propagation record, :func:`.blocks.propagate`).
"""
from __future__ import annotations

import llvmlite.ir as ir
import numpy as np

from .build import D, FLAGS, I64, Emitter
from .links import Sample, floats
from .signs import SignedBlock, _rows_switch, signs_of
from .world import lu_solve


def _signed(e: Emitter, v, pos: float, neg: float):
    """pos where v > 0, neg where v < 0, else 0.0 (a double; NaN gives 0: no sign pattern
    accepts a NaN sample anyway)."""
    zero = ir.Constant(D, 0.0)
    return e.b.select(e.b.fcmp_ordered(">", v, zero), ir.Constant(D, pos),
                      e.b.select(e.b.fcmp_ordered("<", v, zero), ir.Constant(D, neg), zero))


def _sign(e: Emitter, v):
    """sign(v) as a double: -1, 0 or 1 (np.sign; NaN gives 0: as :func:`_signed`)."""
    return _signed(e, v, 1.0, -1.0)


def mesh_rates(e: Emitter, s: Sample, lp) -> tuple[list, list]:
    """(theta'_{j,c}, s_v) of every lossy mesh (doubles)."""
    rates = []
    for k in range(len(lp.rate_meshes)):
        j, c = (int(v) for v in lp.rate_int[k])
        z = e.mv(s.R[c], floats(lp.rate_flt[k]))
        rates.append(e.const(e.dot(e.vsub(s.w[j], s.w[c]), z)))
    return rates, [_sign(e, r) for r in rates]


def joint_friction(e: Emitter, s: Sample, lp) -> dict:
    """rhs[L] -= Q * the unit wrench of each friction joint on L; returns {joint: its own
    friction Q} (the joints with Coulomb or viscous friction)."""
    own = {}
    for k in range(lp.joints.shape[0]):
        ji, child, parent, prismatic = (int(v) for v in lp.joints[k, :4])
        f = floats(lp.joint_flt[k])
        if not (f[6] or f[7]):         # bearing friction only (.bearings)
            continue
        qd = e.const(s.qd[ji])         # -F_c sign(q') - F_v q' (+0 at rest, as numpy's)
        Q = own[ji] = e.b.fsub(_signed(e, qd, -f[6], f[6]), e.const(e.mul(f[7], qd)), flags=FLAGS)
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
    return own


def write_losses(e: Emitter, s: Sample, lp, gear_col, rates: list, own: dict, rows: dict) -> None:
    """The sample's ``gear_loss`` (every circuit, 0 for an ideal pair), ``joint_friction`` and
    ``joint_loss`` (every joint, 0 without own friction) rows (``rows``: name -> double*)."""
    for k, ci in enumerate(lp.rate_meshes):
        c, rj = floats(lp.loss_flt[k])
        t = s.sol[int(gear_col[ci])]
        e.store(e.mul(e.mul(e.mul(c, e.call("fabs", t)), e.call("fabs", rates[k])), rj), rows["gear_loss"], ci)
    for ci in set(range(len(gear_col))) - set(lp.rate_meshes):
        e.store(0.0, rows["gear_loss"], ci)
    for ji in range(len(s.qd)):
        f = own.get(ji, 0.0)
        if ji in s.bearing:            # (0 - 0 = +0 at rest, as numpy's)
            f = e.b.fsub(e.const(f), s.bearing[ji], flags=FLAGS)
        e.store(f, rows["joint_friction"], ji)
        e.store(e.neg(e.mul(f, s.qd[ji])), rows["joint_loss"], ji)


def _product_table(e: Emitter, tables: dict, name: str, products: list, index, W: list):
    """get(i, c): entry (i, c) of the constant matrix products[index] (all of one shape),
    stored in one constant global array made once per W (``tables``); an entry 0 in every
    matrix is the constant 0."""
    key = tuple(tuple(w) for w in W)
    if key not in tables:
        P = np.array(products)
        tables[key] = (_table(e, f"ainv_{name}{len(tables)}", P.ravel()), np.all(P == 0.0, axis=0))
    table, zero = tables[key]
    width = zero.shape[1]
    base = e.b.mul(index, ir.Constant(I64, zero.size))
    return lambda i, c: 0.0 if zero[i, c] else e.load(table, e.b.add(base, ir.Constant(I64, i * width + c)))


def _table(e: Emitter, name: str, values) -> ir.Value:
    """A constant global array of ``values`` (doubles), its address through an empty asm: a
    register LLVM cannot fold into each load's offset (the JIT's large code model would load
    every entry's address by movabs)."""
    flat = [float(v) for v in values]
    g = ir.GlobalVariable(e.module, ir.ArrayType(D, len(flat)), name)
    g.global_constant, g.linkage, g.initializer = True, "internal", ir.Constant(g.type.pointee, flat)
    return e.b.asm(ir.FunctionType(D.as_pointer(), [D.as_pointer()]), "", "=r,0", [g.bitcast(D.as_pointer())], False)


def lossy_block(e: Emitter, inner, bl, sv: list, name: str):
    """The solve of a lossy constant-frame block (module docstring): its stored maps per
    (s_v, sigma) when it has them, else a :class:`LossyBlock` around ``inner``."""
    if bl.maps is None:
        return LossyBlock(inner, bl, sv, name)
    code = ir.Constant(I64, 0)
    for i, k in enumerate(bl.rates):       # sum_i (s_v,i + 1) 3^i
        digit = e.b.add(e.b.fptosi(e.const(sv[k]), I64), ir.Constant(I64, 1))
        code = e.b.add(code, e.b.mul(digit, ir.Constant(I64, 3 ** i)))
    return TabledBlock(e, bl.maps, inner.tcols, code, name)


class TabledBlock:
    """The stored maps of every (s_v, sigma) of a block in one constant global array, of
    each map only the entries not 0 in every map (``nz``: their columns per row): a trial
    (:func:`~.signs.resolve`) and :meth:`rows` of pattern p read the map at 2^m code + p,
    no branch on the sample's s_v pattern ``code`` (a switch into a search per code cost
    ~110 instructions a sample more on the Bendix)."""

    def __init__(self, e: Emitter, maps: tuple, tcols: list, code, name: str):
        self.tcols, self.n = tcols, maps[0].shape[0]
        self.maps, self.name, self.tables = maps, name, {}
        used = np.any(np.array(maps) != 0.0, axis=0)
        self.nz, self.at = [np.flatnonzero(u) for u in used], np.cumsum([0] + list(used.sum(axis=1)))
        self.table = _table(e, f"ainv_{name}_sv", [v for A in maps for v in A[used]])
        self.code = e.b.mul(code, ir.Constant(I64, 1 << len(tcols)))

    def products(self, e: Emitter, p, W: list) -> list:
        """[X W_j (n values) for each constant W_j of W] of pattern p: the products stored per
        map in a second constant table (made once per W), read without a product; an entry 0
        in every map is the constant 0 (bearing friction's unit couples, :func:`.bearings.converge`)."""
        cols = np.array(W, float).T
        get = _product_table(e, self.tables, f"{self.name}_w", [A @ cols for A in self.maps], e.b.add(p, self.code), W)
        return [[get(i, j) for i in range(self.n)] for j in range(len(W))]

    def rows(self, e: Emitter, fn, p, rows: list, r: list, tag: str) -> list:
        base = e.b.mul(e.b.add(p, self.code), ir.Constant(I64, int(self.at[-1])))
        return [e.const(e.dot([e.load(self.table, e.b.add(base, ir.Constant(I64, int(self.at[i]) + h)))
                               for h in range(len(self.nz[i]))], [r[j] for j in self.nz[i]])) for i in rows]


class LossyBlock:
    """A constant-frame block with lossy meshes around its lossless solve ``inner`` (a
    :class:`~.signs.SignedBlock` or :class:`~.world.LowRankBlock`): the
    module docstring's rank-ml correction of each trial and of the accepted solution."""

    def __init__(self, inner, bl, sv: list, name: str = ""):
        self.inner, self.bl, self.name, self.tables = inner, bl, name, {}
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
        lt = [self.tcols[i] for i in self.bl.positions]
        need = sorted(set(rows) | set(lt))
        xr, xf = self._products(e, fn, p, need, r, tag)
        return self._corrected(e, p, [xr], xf, rows)[0]

    def _corrected(self, e: Emitter, p, xrs: list, xf: list, rows: list) -> list:
        """Rows ``rows`` of the changed matrix's solution for each X r of ``xrs`` (row -> value)
        with pattern p's X Phi^T ``xf``: x = X r - X Phi^T D y, (1 + Phi X D) y = (X r)[lt],
        that matrix factored once."""
        bl, m = self.bl, len(self.tcols)
        lt = [self.tcols[i] for i in bl.positions]
        sig = signs_of(e, p, m)
        d = [e.mul(sig[i], sv) for i, sv in zip(bl.positions, self.d_sv)]
        K = [[e.add(1.0 if a == b else 0.0, e.mul(xf[b][lt[a]], d[b])) for b in range(len(lt))]
             for a in range(len(lt))]
        Y, singular = lu_solve(e, K, [[xr[c] for xr in xrs] for c in lt])
        nan, out = ir.Constant(D, float("nan")), []
        for j, xr in enumerate(xrs):
            dy = [e.mul(db, e.b.select(singular, nan, e.const(Y[b][j]))) for b, db in enumerate(d)]
            out.append([e.const(e.sub(xr[i], e.dot([xf[b][i] for b in range(len(lt))], dy))) for i in rows])
        return out

    def products(self, e: Emitter, p, W: list):
        """[the changed matrix's solution (n values) for each constant W_j of W] of pattern p:
        X W_j and X Phi^T stored per pattern in one constant table (made once per W, read
        without a switch), then :meth:`_corrected` (bearing friction's unit couples,
        :func:`.bearings.converge`); None where the inner maps are not stored per pattern."""
        if not isinstance(self.inner, SignedBlock):
            return None
        phi = self.bl.phi.T
        ml, n = phi.shape[1], self.n
        cols = np.array(W, float).T
        get = _product_table(e, self.tables, f"{self.name}_w", [np.hstack([X @ cols, X @ phi]) for X in self.inner.maps],
                             p, W)
        xrs = [{i: get(i, j) for i in range(n)} for j in range(len(W))]
        xf = [{i: get(i, len(W) + b) for i in range(n)} for b in range(ml)]
        return self._corrected(e, p, xrs, xf, list(range(n)))


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


def couples_F(e: Emitter, s: Sample, bl, x: list, tcols: list) -> dict:
    """A constant-frame block's solved friction couples on the links of later blocks: {t
    column: s_v |t| (couple on j in F)}, added to the wrench of the mesh's propagation record
    (+ on j, its primary link, - on k, as :func:`..blocks.solve_blocks`)."""
    return {tcols[n]: e.scale(floats(bl.couple_F[a]), e.mul(s.sv[k], e.call("fabs", x[tcols[n]])))
            for a, (n, k) in enumerate(zip(bl.positions, bl.rates)) if bl.later[a]}


def propagate(e: Emitter, s: Sample, lp, bl, x: list, tcols: list, sig: list) -> None:
    """rhs[L] -= a world-frame block's solved friction couples on the later links L:
    sigma s_v t (R_c couple), as the column of :class:`..equations.Columns` (+ on j, - on k)."""
    for a, (n, k, ci) in enumerate(zip(bl.positions, bl.rates, bl.circuits)):
        if not bl.later[a]:
            continue
        m = e.mv(s.R[_carrier(lp, k)], floats(lp.couple[ci]))
        amount = e.mul(e.mul(sig[n], s.sv[k]), x[tcols[n]])
        for L, sign in bl.later[a]:
            s.rhs[L] = s.rhs[L][:3] + tuple(e.sub(s.rhs[L][3 + h], e.mul(float(sign), e.mul(amount, m[h])))
                                            for h in range(3))
