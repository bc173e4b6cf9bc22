"""Generated world-frame block solve (a block without a constant frame), one sample.

As the numpy path (:func:`..blocks.solve_blocks`, a general block): the block's balances in base axes about each link's origin,
assembled from the column terms of :mod:`.terms` (the pose-dependent wrenches
:func:`.blocks.term_wrench` emits) for a sign pattern of its t, then solved by
Gaussian elimination with partial pivoting (the first largest pivot), straight-line: the
row swaps are selects.  A zero pivot (a singular matrix) makes the
whole solution NaN, which no sign pattern accepts.
"""
from __future__ import annotations

import llvmlite.ir as ir

from .build import D, I1, Emitter
from .links import floats
from .signs import signs_of
from .dense_solve import loop_solve


PIVOT_GROWTH = 100.0
"""A static pivot smaller than the largest entry below it by more than this factor sends
the sample's solve to the pivoting loop code (:func:`lu_solve` with a fixed ``order``).  Measured on servo_joint
(60,000 random samples, q to +-50 rad; against the numpy path's KKT solve): 4 gives 1.5e-15
of the sample's largest load but takes the loop code for most samples (18,000 samples/s),
32 1.1e-14 (75,000), 100 3.1e-14 (244,000), 1e4 1.6e-12 (305,000): a moment row's entries
are a force row's times a lever of ~0.02 m, so ratios of ~50 are the units, not a poor
pivot.  Those figures are without the row swaps of :func:`.basis._swaps`: 2.5 % of random
poses had a poor static pivot, one of a planet's pair of rows that turns with its angle;
with them, 1.1e-15 on the same test and the pivoting loop code is rare."""


def _zero(v) -> bool:
    """True for a constant exact 0.0 (a zero of the matrix's structure)."""
    return isinstance(v, float) and v == 0.0


def _swap_rows(e: Emitter, A: list, X: list, c: int, a: int) -> None:
    """Rows c and a (> c) exchanged (columns >= c of A, and X) where |A[a][c]| > |A[c][c]|
    (a NaN is never larger)."""
    if _zero(A[a][c]):
        return
    sw = e.b.fcmp_ordered(">", e.const(e.call("fabs", A[a][c])), e.const(e.call("fabs", A[c][c])))
    for M, lo in ((A, c), (X, 0)):
        for j in range(lo, len(M[c])):
            u, v = e.const(M[c][j]), e.const(M[a][j])
            if M[c][j] is M[a][j] or (isinstance(M[c][j], float) and M[c][j] == M[a][j]):
                continue
            M[c][j], M[a][j] = e.b.select(sw, v, u), e.b.select(sw, u, v)


def lu_solve(e: Emitter, A: list, B: list, order: list | None = None, swaps: list | None = None,
             dominant: bool = False):
    """(X, bad): X = A^-1 B (A (k, k), B (k, m), lists of rows of values) by straight-line
    elimination, ``bad`` (i1) true for a zero pivot (a singular matrix).

    Without ``order``: partial pivoting (the first largest pivot), each row below swapped
    up in turn where its entry is larger (selects, :func:`_swap_rows`).  With ``order``:
    elimination in that fixed row order (partial pivoting's order at the home pose,
    :func:`.basis._free_columns`), without selects but the one row per column of ``swaps``
    (:func:`.basis._swaps`; -1: none), the one pivoting a turning frame needs, so the zeros
    of the matrix's structure fold away; ``bad`` is then also true when a pivot is smaller
    than the largest entry below it by more than :data:`PIVOT_GROWTH` (the caller then
    solves with pivoting).  ``dominant``: A is known strictly diagonally dominant (every row's
    off-diagonal entries smaller in sum than its diagonal one, whatever the sample), so
    elimination in row order needs no pivoting and no test: ``bad`` is the constant false."""
    if dominant:
        order, swaps = list(range(len(A))), [-1] * len(A)
    k, static = len(A), order is not None
    A = [list(A[i]) for i in (order if static else range(k))]
    X = [list(B[i]) for i in (order if static else range(k))]
    bad = ir.Constant(I1, 0)
    inv = [1.0] * k                  # 1 / pivot: a product per row, not a division (latency)
    for c in range(k):
        for a in ([swaps[c]] if swaps[c] >= 0 else []) if static else range(c + 1, k):
            _swap_rows(e, A, X, c, a)
        piv = A[c][c]
        if _zero(piv):
            return X, ir.Constant(I1, 1)
        if not isinstance(piv, float) and not dominant:
            a = e.call("fabs", piv)
            bad = e.b.or_(bad, e.b.fcmp_ordered("==", a, ir.Constant(D, 0.0)))
            for v in (A[i][c] for i in range(c + 1, k) if static and not _zero(A[i][c])):
                bad = e.b.or_(bad, e.b.fcmp_ordered(">", e.const(e.call("fabs", v)), e.const(e.mul(PIVOT_GROWTH, a))))
        inv[c] = e.div(1.0, piv)
        for i in range(c + 1, k):
            if _zero(A[i][c]):
                continue
            f = e.mul(A[i][c], inv[c])
            for j in range(c + 1, k):
                A[i][j] = e.sub(A[i][j], e.mul(f, A[c][j]))
            X[i] = [e.sub(X[i][h], e.mul(f, X[c][h])) for h in range(len(X[i]))]
    for c in range(k - 1, -1, -1):
        for h in range(len(X[c])):
            v = X[c][h]
            for j in range(c + 1, k):
                v = e.sub(v, e.mul(A[c][j], X[j][h]))
            X[c][h] = e.mul(v, inv[c])
    return X, bad


def eliminate(e: Emitter, A: list, r: list) -> list:
    """x = A^-1 r (A square, a list of rows of values; partial pivoting), NaN if singular."""
    X, singular = lu_solve(e, A, [[v] for v in r])
    nan = ir.Constant(D, float("nan"))
    return [e.b.select(singular, nan, e.const(row[0])) for row in X]


class WorldBlock:
    """A block solved in world axes: its matrix from the terms, for a sign pattern p.

    A square block is eliminated straight-line (:func:`eliminate`).  A redundant one (a gear
    set with more unknowns n than its 6B equations, ``weights`` the load-sharing weights of
    :func:`..sharing.mesh_weights`) is solved through a square basis (``free``: the columns
    left out, :func:`.basis._free_columns`; :meth:`_by_basis`), or where none was
    found from the KKT system of :func:`..sharing.kkt` (:meth:`_least_load`), each with
    the loop code of :mod:`.dense_solve`, the
    matrices in stack arrays of the ``fn`` ``run``.

    ``full_trial``: a trial solves the whole block (:func:`.signs.resolve` keeps
    that solution for the pattern it accepts)."""

    full_trial = True
    extra = None        # the block's mesh friction columns, added per trial (losses.world_columns)
    more = ()           # right-hand sides each solve also solves (:meth:`solve`)
    more_x = ()

    def __init__(self, s, prog, k0: int, nt: int, n: int, tcols: list, wrench, fn, weights, free):
        self.s, self.trec, self.tval = s, prog.terms, prog.term_values
        self.terms = [k for k in range(k0, k0 + nt) if self.trec[k].row >= 0]
        self.n, self.tcols, self.wrench = n, tcols, wrench
        self.fn, self.weights, self.free, self.mem = fn, weights, free, None

    def _stack(self, e: Emitter, sizes):
        """Stack arrays of these sizes (doubles), made once per sizes in ``run``'s entry block."""
        if self.mem is None:
            self.mem = {}
        if sizes not in self.mem:
            self.mem[sizes] = e.stack(self.fn, sizes)
        return self.mem[sizes]

    def _by_basis(self, e: Emitter, A: list, R: list) -> list:
        """The least-load solution through the basis A_B (every column but the d ``free``):
        [p | Q] = A_B^-1 [r | A_free] (:func:`lu_solve` in the stored row order, or the
        pivoting loop code of :mod:`.dense_solve` when a static pivot is poor), then the free unknowns from
        (Q^T W_B Q + W_free) x_free = Q^T W_B p (d x d, :func:`eliminate`) and x_B = p - Q x_free:
        the minimiser of sum w x^2 over the solutions of A x = r, for each r of ``R``."""
        k, (free, order, swaps), w = len(R[0]), self.free, self.weights
        basis = [j for j in range(self.n) if j not in free]
        nR = len(R)
        m = nR + len(free)
        AB = [[A[i][j] for j in basis] for i in range(k)]
        RHS = [[r[i] for r in R] + [A[i][j] for j in free] for i in range(k)]
        fast, bad = lu_solve(e, AB, RHS, order, swaps)
        fn = self.fn
        slow, done = fn.append_basic_block("basis_pivot"), fn.append_basic_block("basis_done")
        pre = e.b.block
        e.b.cbranch(bad, slow, done)
        e.b.position_at_end(slow)
        loaded = loop_solve(e, self._stack(e, (k * k, k * m)), AB, RHS)
        slow_end = e.b.block
        e.b.branch(done)
        e.b.position_at_end(done)
        merged = e.phis([pre, slow_end], [[v for row in fast for v in row], [v for row in loaded for v in row]])
        P = [merged[i * m:(i + 1) * m] for i in range(k)]
        wb = [(a, float(w[j])) for a, j in enumerate(basis) if w[j] > 0]
        S = [[e.add(float(w[free[g]]) if g == h else 0.0,
                    e.dot([e.mul(wj, P[a][nR + g]) for a, wj in wb], [P[a][nR + h] for a, _ in wb]))
              for h in range(len(free))] for g in range(len(free))]
        out = []
        for c in range(nR):
            rhs = [e.dot([e.mul(wj, P[a][nR + g]) for a, wj in wb], [P[a][c] for a, _ in wb]) for g in range(len(free))]
            xf = eliminate(e, S, rhs)
            x = [0.0] * self.n
            for g, j in enumerate(free):
                x[j] = xf[g]
            for a, j in enumerate(basis):
                x[j] = e.const(e.sub(P[a][c], e.dot([P[a][nR + h] for h in range(len(free))], xf)))
            out.append(x)
        return out

    def solve(self, e: Emitter, sig: list, r: list) -> list:
        """x of the block for the signs ``sig`` (values) of its t; the solutions of ``more``
        (further right-hand sides, bearing friction's unit couples, :func:`.bearings.converge`)
        with the same matrix, factored once, into ``more_x``."""
        X = self.solve_columns(e, sig, [r] + list(self.more))
        self.more_x = X[1:]
        return X[0]

    def solve_columns(self, e: Emitter, sig: list, R: list) -> list:
        """[x of the block for the signs ``sig`` and right-hand side r, for each r of ``R``]:
        the block's matrix built and factored once."""
        nr = len(R[0])
        A = [[0.0] * self.n for _ in range(nr)]
        for k in self.terms:
            term = self.trec[k]
            row, col = int(term.row), int(term.col)
            w = self.wrench(e, self.s, term, self.tval[k], int(term.link), sig)
            for h in range(6):
                A[6 * row + h][col] = e.add(A[6 * row + h][col], w[h])
        if self.extra is not None:
            self.extra(e, A, self.tcols, sig)
        if nr == self.n:
            X, singular = lu_solve(e, A, [[r[i] for r in R] for i in range(nr)])
            nan = ir.Constant(D, float("nan"))
            return [[e.b.select(singular, nan, e.const(row[c])) for row in X] for c in range(len(R))]
        if self.free is not None:
            return self._by_basis(e, A, R)
        return self._least_load(e, A, R)

    def _least_load(self, e: Emitter, A: list, R: list) -> list:
        """The minimiser of sum w x^2 subject to A x = r (:func:`..sharing.least_load_solve`)
        from its KKT system with D unscaled: the minimiser does not depend on D's scale, and
        the one numpy applies (the largest |A| entry) is of order 1 for unit directions and
        levers of metres."""
        nr, n = len(A), self.n
        size = n + nr
        K = [[0.0] * size for _ in range(size)]       # the KKT matrix of sharing.kkt
        for i in range(n):
            K[i][i] = float(self.weights[i])
            for a in range(nr):
                K[i][n + a], K[n + a][i] = A[a][i], A[a][i]
        m = len(R)
        x = loop_solve(e, self._stack(e, (size * size, size * m)), K, [[0.0] * m] * n + [[r[a] for r in R] for a in range(nr)])
        return [[row[c] for row in x[:n]] for c in range(m)]

    def rows(self, e: Emitter, fn, p, rows: list, r: list, tag: str) -> list:
        """Rows ``rows`` of the solution for pattern p (i64)."""
        x = self.solve(e, signs_of(e, p, len(self.tcols)), r)
        return [x[i] for i in rows]


class LowRankBlock:
    """A constant-frame block with too many sign patterns to store their maps, solved from
    one base matrix (:class:`~..pattern_maps.LowRank`, the Woodbury form, its numpy twin
    ``LowRank.solve``).  A trial with one of the ``hot`` patterns (pattern 0, the search's
    first, and the ones random motions meet most, :func:`.program._hot_maps`) is a
    product with its map, straight-line with the constants (a ``switch`` over them); any
    other pattern computes y = Y r and g = G r, solves the k x k system
    (C_sigma + W) c = g (a call of the loop code of :mod:`.dense_solve`: such a pattern is
    rare, its code small) and takes x = y - Z c."""

    def __init__(self, lr, tcols: list, hot):
        self.lr, self.tcols, self.n = lr, tcols, lr.Y.shape[0]
        self.hot, self.maps = (list(hot[0]), hot[1]) if hot else ([], [])
        self.mem = None

    def rows(self, e: Emitter, fn, p, rows: list, r: list, tag: str) -> list:
        """Rows ``rows`` of the solution for pattern p (i64)."""
        hot = [(h, lambda A=A: [e.dot(floats(A[i]), r) for i in rows]) for h, A in zip(self.hot, self.maps)]
        return e.switch(fn, p, hot, tag, default=lambda: self._solved(e, fn, p, rows, r))

    def _solved(self, e: Emitter, fn, p, rows: list, r: list) -> list:
        """Rows ``rows`` of the solution for pattern p by the k x k solve."""
        m, k = len(self.tcols), self.lr.k
        if self.mem is None:                  # one stack slot per block
            self.mem = e.stack(fn, (k * k, k))
        sig = signs_of(e, p, m)
        M = [[float(v) for v in row] for row in self.lr.W]       # C_sigma + W
        for i in range(k):
            for j in range(k):
                if self.lr.redundant and (j == i + m or i == j + m):
                    M[i][j] = e.add(M[i][j], sig[min(i, j)])
                elif not self.lr.redundant and i == j:
                    M[i][j] = e.add(M[i][j], sig[i])
        cv = [row[0] for row in loop_solve(e, self.mem, M, [[e.dot(floats(self.lr.G[i]), r)] for i in range(k)])]
        return [e.sub(e.dot(floats(self.lr.Y[i]), r), e.dot(floats(self.lr.Z[i]), cv)) for i in rows]
