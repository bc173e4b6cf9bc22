"""Generated trials and solutions of a many-mesh lossy block's hot (sign pattern, s_v)
pairs from their stored maps (:mod:`.lossy_maps`), for :mod:`.blocks`."""
from __future__ import annotations

import llvmlite.ir as ir
import numpy as np

from .build import I64, Emitter
from .links import floats
from .signs import SignedBlock


def sv_code(e: Emitter, bl, sv: list):
    """The sample's s_v code of block losses ``bl`` (i64): sum_i (s_v,i + 1) 3^i over its
    lossy meshes (:attr:`~.loss_program.BlockLosses.rates` order), as :func:`.lossy_maps.pair_key`'s
    and the index of :attr:`~.loss_program.BlockLosses.maps`."""
    code = ir.Constant(I64, 0)
    for i, k in enumerate(bl.rates):
        digit = e.b.add(e.b.fptosi(e.const(sv[k]), I64), ir.Constant(I64, 1))
        code = e.b.add(code, e.b.mul(digit, ir.Constant(I64, 3 ** i)))
    return code


class HotLossyBlock:
    """A :class:`~.losses.LossyBlock` ``block`` whose trials and solutions of the hot pairs
    ``bl.hot`` are products with their stored maps, a ``switch`` on the pair's key into
    straight-line code per pair (its constants from the kernel's pool,
    :class:`~.build.ConstantPool`), every other pair ``block``'s own."""

    def __init__(self, e: Emitter, block, bl, sv: list):
        self.block, self.keys, self.tcols, self.n = block, [k for k, _ in bl.hot], block.tcols, block.n
        self.ml, self.code, self.maps = len(bl.positions), sv_code(e, bl, sv), [L for _, L in bl.hot]
        self.kept = len(bl.positions) if block.screen is None else len(self.tcols)

    def _key(self, e: Emitter, p):
        """The i64 key of pattern p's pair (:func:`.lossy_maps.pair_key`)."""
        return e.b.add(e.b.mul(p, ir.Constant(I64, 3 ** self.ml)), self.code)

    def _either(self, e: Emitter, fn, p, rows: list, r: list, tag: str, default, extra: int = 0) -> list:
        """Rows ``rows`` of the stored map of p's pair where it is hot (then ``extra`` 0s),
        else ``default()``."""
        cases = [(k, lambda L=L: [e.const(e.dot(floats(L[i]), r)) for i in rows] + [0.0] * extra)
                 for k, L in zip(self.keys, self.maps)]
        return e.switch(fn, self._key(e, p), cases, tag, default=default)

    def trial(self, e: Emitter, fn, p, r: list, tol, tag: str):
        """(t, kept) as :meth:`~.losses.LossyBlock.trial` (kept 0s for a hot pair: its
        :meth:`full` reads its map too)."""
        m = len(self.tcols)
        v = self._either(e, fn, p, self.tcols, r, f"{tag}_hot", extra=self.kept,
                         default=lambda: [x for part in self.block.trial(e, fn, p, r, tol, tag) for x in part])
        return v[:m], v[m:]

    def full(self, e: Emitter, fn, p, r: list, kept: list, tag: str) -> list:
        rows = list(range(self.n))
        return self._either(e, fn, p, rows, r, f"{tag}_hot", lambda: self.block.full(e, fn, p, r, kept, tag))

    def rows(self, e: Emitter, fn, p, rows: list, r: list, tag: str) -> list:
        return self._either(e, fn, p, rows, r, f"{tag}_hot", lambda: self.block.rows(e, fn, p, rows, r, tag))

    def products(self, e: Emitter, p, W: list):
        """As :meth:`~.losses.LossyBlock.products` (bearing friction's unit couples W_j): a
        hot pair's L W_j constants, any other pair's from ``block`` (None where it has none)."""
        if not isinstance(self.block.inner, SignedBlock):
            return None
        n, k = self.n, len(W)
        cols = np.array(W, float).T
        cases = [(kk, lambda P=L @ cols: [float(v) for v in P.T.ravel()]) for kk, L in zip(self.keys, self.maps)]
        flat = e.switch(e.b.function, self._key(e, p), cases, "hot_w",
                        default=lambda: [v for col in self.block.products(e, p, W) for v in col])
        return [flat[j * n:(j + 1) * n] for j in range(k)]
