"""Generated mesh friction in the block solves of one sample (:mod:`..losses`, :mod:`.loss_program`),
for :mod:`.blocks` (the sample's rates, joint friction and loss outputs: :mod:`.friction_terms`).

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
  sample (sigma s_v (R_c couple) on gear j's rows, minus on k's), and its reducers' power-flow
  change delta z_I (:class:`.loss_program.ReducerLosses`; + on the input, - on the housing);
* :func:`couples_F`, :func:`propagate`: the solved couples s_v |t| on the links of later
  blocks (constant frame: in the mesh's propagation record, :func:`.blocks.propagate`).
"""
from __future__ import annotations

import llvmlite.ir as ir
import numpy as np

from .build import D, I1, I64, Emitter
from .hot_pairs import sv_code
from .inverse_cache import InverseCache
from .links import Sample, floats
from .signs import SignedBlock, signs_of
from .world import lu_solve
from .. import loss_terms
from ..signs import sign_patterns
from ..wrenches import mesh_friction_column, power_flow_column, worm_friction, worm_friction_column


def _product_table(e: Emitter, tables: dict, name: str, products: list, index, key):
    """get(i, c): entry (i, c) of the constant matrix products[index] (all of one shape),
    stored in one constant global array made once per ``key`` (``tables``); an entry 0 in
    every matrix is the constant 0 (its address emitted at each call: calls may sit in blocks
    that do not dominate one another)."""
    if key not in tables:
        P = np.array(products)
        tables[key] = (_global(e, f"ainv_{name}{len(tables)}", P.ravel()), np.all(P == 0.0, axis=0))
    g, zero = tables[key]
    table = _address(e, g)
    width = zero.shape[1]
    base = e.b.mul(index, ir.Constant(I64, zero.size))
    return lambda i, c: 0.0 if zero[i, c] else e.load(table, e.b.add(base, ir.Constant(I64, i * width + c)))


def _table(e: Emitter, name: str, values) -> ir.Value:
    """A constant global array of ``values`` (doubles), its address through an empty asm: a
    register LLVM cannot fold into each load's offset (the JIT's large code model would load
    every entry's address by movabs)."""
    return _address(e, _global(e, name, values))


def _global(e: Emitter, name: str, values) -> ir.GlobalVariable:
    flat = [float(v) for v in values]
    g = ir.GlobalVariable(e.module, ir.ArrayType(D, len(flat)), name)
    g.global_constant, g.linkage, g.initializer = True, "internal", ir.Constant(g.type.pointee, flat)
    return g


def _address(e: Emitter, g: ir.GlobalVariable) -> ir.Value:
    return e.b.asm(ir.FunctionType(D.as_pointer(), [D.as_pointer()]), "", "=r,0", [g.bitcast(D.as_pointer())], False)


def lossy_block(e: Emitter, inner, bl, sv: list, name: str):
    """The solve of a lossy constant-frame block (module docstring): its stored maps per
    (s_v, sigma) when it has them, else a :class:`LossyBlock` around ``inner``."""
    if bl.maps is None:
        return LossyBlock(inner, bl, sv, name)
    return TabledBlock(e, bl.maps, inner.tcols, sv_code(e, bl, sv), name)


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
        get = _product_table(e, self.tables, f"{self.name}_w", [A @ cols for A in self.maps], e.b.add(p, self.code),
                             tuple(tuple(w) for w in W))
        return [[get(i, j) for i in range(self.n)] for j in range(len(W))]

    def rows(self, e: Emitter, fn, p, rows: list, r: list, tag: str) -> list:
        base = e.b.mul(e.b.add(p, self.code), ir.Constant(I64, int(self.at[-1])))
        return [e.const(e.dot([e.load(self.table, e.b.add(base, ir.Constant(I64, int(self.at[i]) + h)))
                               for h in range(len(self.nz[i]))], [r[j] for j in self.nz[i]])) for i in rows]


DOMINANT = 0.5
"""A :class:`LossyBlock` whose every pattern's M_l = (X Phi^T)[lossy t rows] has absolute
row sums below this solves 1 + M_l D (D = diag(sigma s_v), entries -1, 0, 1: strictly
diagonally dominant for every sample, its pivots within a factor 2 of 1) without
pivoting, and its trials are screened (:meth:`LossyBlock.trial`); friction arms are c rho_p,
so a row sums to ~c: 0.033 on the 3-planet stage."""

SCREEN_PATTERNS = 4096
"""Sign patterns of a low-rank block (:class:`~.world.LowRankBlock`) up to which the code
generator computes every pattern's tooth map for its screen (1,024 for 5 planets: ~20 ms)."""

SCREEN_ROUNDING = 1e-12
"""Added to a screen's factor: the rounding of the exact solve (K ~ 1: ~1e-15 of max |t0_l|)."""


class LossyBlock:
    """A constant-frame block with lossy meshes around its lossless solve ``inner`` (a
    :class:`~.signs.SignedBlock` or :class:`~.world.LowRankBlock`): the module docstring's
    rank-ml correction.  A trial (:meth:`trial`) decides on the inner map's tooth rows where
    a screen proves the friction cannot change the decision, else solves the ml x ml system
    for t_l; the accepted pattern's solution (:meth:`full`) solves it once and corrects the
    inner map's X r by the stored (X Phi^T) D t_l (X (r - Phi^T D t_l) around a low-rank
    block)."""

    def __init__(self, inner, bl, sv: list, name: str = ""):
        self.inner, self.bl, self.name, self.tables, self._caches = inner, bl, name, {}, {}
        self.tcols, self.n = inner.tcols, inner.n
        self.d_sv = [sv[k] for k in bl.rates]
        self.screen = None
        M = self._tooth_maps()
        if M is not None:
            M = np.abs(M)
            rho, mu = M[:, list(bl.positions)].sum(axis=2).max(), M.sum(axis=2).max()
            if rho < DOMINANT:
                self.screen = mu / (1.0 - rho) * (1.0 + 1e-9) + SCREEN_ROUNDING

    def _tooth_maps(self):
        """(X_p Phi^T)[tcols] (2^m, m, ml) of every pattern p (a low-rank block's from its
        Woodbury form, up to :data:`SCREEN_PATTERNS` of them), or None."""
        phi, m = self.bl.phi, len(self.tcols)
        if isinstance(self.inner, SignedBlock):
            return np.array([(X @ phi.T)[self.tcols] for X in self.inner.maps])
        if 1 << m > SCREEN_PATTERNS:
            return None
        return np.array([self.inner.lr.solve(sg, phi)[:, self.tcols].T for sg in sign_patterns(m)])

    def _couple_map(self, e: Emitter, p):
        """get(i, b): entry (i, b) of pattern p's X Phi^T (n x ml), from a constant table (an
        entry 0 in every map the constant 0); the inner maps stored per pattern only."""
        return _product_table(e, self.tables, f"{self.name}_phi", [X @ self.bl.phi.T for X in self.inner.maps], p, "X Phi^T")

    def _tooth_map(self, e: Emitter, fn, p, tag: str) -> list:
        """(X Phi^T)[tcols] (m rows of ml) of pattern p: read from :meth:`_couple_map` when
        the inner maps are stored per pattern, else the inner solve of each couple."""
        phi, m = self.bl.phi, len(self.tcols)
        if isinstance(self.inner, SignedBlock):
            get = self._couple_map(e, p)
            return [[get(i, b) for b in range(phi.shape[0])] for i in self.tcols]
        cols = [self.inner.rows(e, fn, p, self.tcols, floats(phi[b]), f"{tag}_phi{b}") for b in range(phi.shape[0])]
        return [[col[i] for col in cols] for i in range(m)]

    def _d(self, e: Emitter, p) -> list:
        """D = diag(sigma s_v) of pattern p (i64), per lossy t (-1, 0 or 1)."""
        sig = signs_of(e, p, len(self.tcols))
        return [e.mul(sig[i], sv) for i, sv in zip(self.bl.positions, self.d_sv)]

    def _exact(self, e: Emitter, fn, p, t0: list, tag: str):
        """(t, y) of pattern p (i64) from the inner map's tooth rows t0: the changed matrix's
        m tooth forces t = t0 - M y and y = D t_l, (1 + M_l D) t_l = t0_l (M = (X
        Phi^T)[tcols], l the lossy ones; NaN where that matrix is singular)."""
        M = self._tooth_map(e, fn, p, tag)
        d = self._d(e, p)
        lt = self.bl.positions
        K = [[e.add(1.0 if a == b else 0.0, e.mul(M[lt[a]][b], d[b])) for b in range(len(lt))] for a in range(len(lt))]
        Y, singular = lu_solve(e, K, [[t0[i]] for i in lt], dominant=self.screen is not None)
        nan = ir.Constant(D, float("nan"))
        y = [e.mul(db, e.b.select(singular, nan, e.const(Y[b][0]))) for b, db in enumerate(d)]
        return [e.const(e.sub(t0[i], e.dot(M[i], y))) for i in range(len(self.tcols))], y

    def _cached(self, e: Emitter, fn, p, t0: list, tag: str) -> list:
        """:meth:`_exact`'s y, 1 + M_l D inverted once per call and (p, D) (:mod:`.inverse_cache`)."""
        d, lt, key = self._d(e, p), self.bl.positions, e.b.sitofp(p, D)
        if (1 << len(self.tcols)) * 3 ** len(lt) > 1 << 53:      # no exact key: no cache
            return self._exact(e, fn, p, t0, tag)[1]
        for db in d:                   # (p, D's digits) in base 3, exact in a double
            key = e.add(e.mul(3.0, key), e.add(db, 1.0))
        cache = self._caches.get(fn) or self._caches.setdefault(fn, InverseCache(e, fn, len(lt)))

        def make():
            M, ks = self._tooth_map(e, fn, p, f"{tag}_m"), range(len(lt))
            return [[e.add(1.0 if a == b else 0.0, e.mul(M[lt[a]][b], d[b])) for b in ks] for a in ks]
        Y = cache.solve(e, fn, key, make, [t0[i] for i in lt], tag)
        return [e.mul(db, y) for db, y in zip(d, Y)]

    def trial(self, e: Emitter, fn, p, r: list, tol, tag: str):
        """(t, kept) of a trial of pattern p (i64) with sign tolerance ``tol``: tooth forces
        t whose signs and consistency (:func:`~.signs.resolve`) are those of the changed
        matrix's.  Without a screen t is :meth:`_exact`'s and kept its y.  With one (1 +
        M_l D diagonally dominant for every pattern, :data:`DOMINANT`) t is the inner map's
        t0 wherever every |t0_i| exceeds screen max_l |t0_l| + tol (|t_i - t0_i| = |M_i y|
        <= mu max|t_l| <= mu / (1 - rho) max|t0_l|, mu the largest row sum of |M|, rho that
        of |M_l|: no t_i can then change sign or cross tol), else :meth:`_exact`'s (a
        branch, rarely taken); kept is t0 and :meth:`full` solves the accepted pattern's
        system once."""
        t0 = self.inner.rows(e, fn, p, self.tcols, r, tag)
        if self.screen is None:
            return self._exact(e, fn, p, t0, tag)
        big = 0.0
        for i in self.bl.positions:
            a = e.call("fabs", t0[i])
            big = a if isinstance(big, float) else e.b.select(e.b.fcmp_ordered(">", a, big), a, big)
        bound = e.add(e.mul(self.screen, big), tol)
        sure = ir.Constant(I1, 1)
        for v in t0:                      # (a NaN is never sure)
            sure = e.b.and_(sure, e.b.fcmp_ordered(">", e.call("fabs", v), bound))
        pre, exact, merge = e.b.block, fn.append_basic_block(f"{tag}_exact"), fn.append_basic_block(f"{tag}_screened")
        e.b.cbranch(sure, merge, exact)
        e.b.position_at_end(exact)
        t_ex = self._exact(e, fn, p, t0, f"{tag}_e")[0]
        done = e.b.block
        e.b.branch(merge)
        e.b.position_at_end(merge)
        return e.phis([pre, done], [[e.const(v) for v in t0], [e.const(v) for v in t_ex]]), t0

    def full(self, e: Emitter, fn, p, r: list, kept: list, tag: str) -> list:
        """The changed matrix's solution (n values) of pattern p from what its :meth:`trial`
        kept (with a screen, y is :meth:`_exact`'s of the kept t0): X r - (X Phi^T) y with
        the inner maps stored per pattern (X r does not wait for y: the solve's divisions
        run beside it; 1.56x -> 1.26x the lossless kernel on the 3-planet stage against X (r
        - Phi^T y)), else X (r - Phi^T y)."""
        y = kept if self.screen is None else self._cached(e, fn, p, kept, f"{tag}_y")
        phi, rows = self.bl.phi, list(range(self.n))
        if isinstance(self.inner, SignedBlock):
            xr, get = self.inner.rows(e, fn, p, rows, r, tag), self._couple_map(e, p)
            return [e.const(e.sub(xr[i], e.dot([get(i, b) for b in range(phi.shape[0])], y))) for i in rows]
        shifted = [e.sub(r[i], e.dot([float(v) for v in phi[:, i]], y)) for i in range(len(r))]
        return self.inner.rows(e, fn, p, rows, shifted, tag)

    def rows(self, e: Emitter, fn, p, rows: list, r: list, tag: str) -> list:
        """Rows ``rows`` of the solution of the changed matrix for pattern p (i64)."""
        t0 = self.inner.rows(e, fn, p, self.tcols, r, f"{tag}_t")
        x = self.full(e, fn, p, r, t0 if self.screen is not None else self._exact(e, fn, p, t0, f"{tag}_t")[1], tag)
        return [x[i] for i in rows]

    def _corrected(self, e: Emitter, p, xrs: list, xf: list, rows: list) -> list:
        """Rows ``rows`` of the changed matrix's solution for each X r of ``xrs`` (row -> value)
        with pattern p's X Phi^T ``xf``: x = X r - X Phi^T D y, (1 + Phi X D) y = (X r)[lt],
        that matrix factored once."""
        lt = [self.tcols[i] for i in self.bl.positions]
        d = self._d(e, p)
        K = [[e.add(1.0 if a == b else 0.0, e.mul(xf[b][lt[a]], d[b])) for b in range(len(lt))]
             for a in range(len(lt))]
        Y, singular = lu_solve(e, K, [[xr[c] for xr in xrs] for c in lt], dominant=self.screen is not None)
        nan, out = ir.Constant(D, float("nan")), []
        for j, xr in enumerate(xrs):
            dy = [e.mul(db, e.b.select(singular, nan, e.const(Y[b][j]))) for b, db in enumerate(d)]
            out.append([e.const(e.sub(xr[i], e.dot([xf[b][i] for b in range(len(lt))], dy))) for i in rows])
        return out

    def products(self, e: Emitter, p, W: list):
        """[the changed matrix's solution (n values) for each constant W_j of W] of pattern p:
        X W_j stored per pattern in a constant table (made once per W, read without a
        switch) and :meth:`_couple_map`'s X Phi^T, then :meth:`_corrected` (bearing
        friction's unit couples, :func:`.bearings.converge`); None where the inner maps are
        not stored per pattern."""
        if not isinstance(self.inner, SignedBlock):
            return None
        ml, n = self.bl.phi.shape[0], self.n
        cols = np.array(W, float).T
        get = _product_table(e, self.tables, f"{self.name}_w", [X @ cols for X in self.inner.maps], p,
                             tuple(tuple(w) for w in W))
        xrs = [{i: get(i, j) for i in range(n)} for j in range(len(W))]
        getf = self._couple_map(e, p)
        xf = [{i: getf(i, b) for i in range(n)} for b in range(ml)]
        return self._corrected(e, p, xrs, xf, list(range(n)))


def world_columns(lp, bl, s: Sample):
    """The hook of a world-frame block (:class:`~.world.WorldBlock` ``extra``):
    adds sigma s_v (R_c couple) to the moment rows of gear j (minus on k) in each lossy
    t column of the block matrix A (``tcols`` its t columns, ``sig`` the trial's signs;
    s_v from ``s.sv``)."""
    sv = s.sv

    def add(e: Emitter, A: list, tcols: list, sig: list) -> None:
        def column(row, col, w):
            for h in range(6):
                if not (isinstance(w[h], float) and w[h] == 0.0):
                    A[6 * row + h][col] = e.add(A[6 * row + h][col], w[h])

        for n, k, ci, rows in zip(bl.positions, bl.rates, bl.circuits, bl.rows):
            fr = e.mv(s.R[_carrier(lp, k)], floats(lp.couple[ci]))
            for row, sign in rows:
                column(row, tcols[n], mesh_friction_column(e, float(sign), sig[n], sv[k], fr))
        for n, k, rows, _ in bl.worms:               # friction sigma s_v mu h_hat, a force at P
            f, P = _worm_friction(e, s, lp.worms, k, sig[n])
            for row, L, sign in rows:
                column(row, tcols[n], worm_friction_column(e, float(sign), f, P, s.o[L]))
        for n, k, rows, _ in bl.reducers:
            delta, z = _reducer_delta(e, s.red[k], sig[n])
            for row, coef in rows:
                column(row, tcols[n], power_flow_column(e, float(coef), delta, z))
    return add


def _worm_friction(e: Emitter, s: Sample, worms, k: int, sigma):
    """(f, P): worm pair k's friction force on the wheel per unit N and its contact point, in
    world axes (:func:`..wrenches.worm_friction`)."""
    c = int(worms.carriers[k])
    return worm_friction(e, sigma, s.worm_sv[k], float(worms.mu[k]), s.R[c], s.o[c], floats(worms.h_hat[k]),
                         floats(worms.point[k]))


def _reducer_delta(e: Emitter, terms, sigma):
    """(delta, z): a power-flow element's change of its torque's factor, delta = A s_w^2 + B
    sigma s_w (:func:`..loss_terms.power_flow_delta`, :class:`.loss_program.ReducerLosses`),
    and its axis in world axes."""
    s_w, A, B, z = terms[:4]
    return loss_terms.power_flow_delta(e, A, B, sigma, s_w), z


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
        fr = e.mv(s.R[_carrier(lp, k)], floats(lp.couple[ci]))
        for L, sign in bl.later[a]:            # its column (the shared term) times the solved t
            col = mesh_friction_column(e, float(sign), sig[n], s.sv[k], fr)
            s.rhs[L] = s.rhs[L][:3] + tuple(e.sub(s.rhs[L][3 + h], e.mul(col[3 + h], x[tcols[n]])) for h in range(3))
    for n, k, _, later in bl.worms:             # the worm's friction force on the later links
        f, P = _worm_friction(e, s, lp.worms, k, sig[n])
        f = e.scale(f, x[tcols[n]])
        for L, sign in later:
            w = f + e.cx(e.vsub(P, s.o[L]), f)
            s.rhs[L] = tuple(e.sub(s.rhs[L][h], e.mul(sign, w[h])) for h in range(6))
    for n, k, _, later in bl.reducers:          # the power-flow change coef delta u z on its sides
        delta, z = _reducer_delta(e, s.red[k], sig[n])
        amount = e.mul(delta, x[tcols[n]])
        for L, coef in later:
            s.rhs[L] = s.rhs[L][:3] + tuple(e.sub(s.rhs[L][3 + h], e.mul(float(coef), e.mul(amount, z[h])))
                                            for h in range(3))
