"""Payloads that are picked and placed: ``payloads:`` of the mechanism file, carried only at
the samples where they are attached (trajectory columns ``attach:<name>``, 0 or 1; the
``attach=`` argument of :func:`gearcli.solve`, :func:`gearcli.forward_dynamics` and
:func:`gearcli.mass_matrix`).

A payload attached is a rigid part of its link: its weight, its d'Alembert loads and its
inertia in the mass matrix, exactly as a ``loads[]`` entry with a mass.  The samples are
grouped by the set of payloads attached; each group is solved, vectorised, on the mechanism
carrying that set (:meth:`gearcli.model.mechanism.Mechanism.attached`, analysed once per set
and kept with the analysis: a kernel of its own), and the results go back to their samples.
"""
from __future__ import annotations

import weakref

import numpy as np

_VARIANTS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def attach_flags(an, attach: dict | None, n: int) -> np.ndarray | None:
    """(n, P) bool of ``attach`` ({payload name: (n,) or scalar 0/1}) in the order of
    ``an.mech.payloads`` (a payload not given: not attached); None when nothing is given.
    ValueError for an unknown name, a bad shape or a value other than 0 and 1."""
    if not attach:
        return None
    names = [p.name for p in an.mech.payloads]
    flags = np.zeros((n, len(names)), bool)
    for name, v in attach.items():
        if name not in names:
            raise ValueError(f"attach: unknown payload '{name}' (mechanism payloads: {', '.join(names) or 'none'})")
        v = np.asarray(v, float)
        if v.ndim == 0:
            v = np.full(n, float(v))
        if v.shape != (n,):
            raise ValueError(f"attach['{name}']: expected shape ({n},) or a scalar, got {v.shape}")
        bad = np.flatnonzero((v != 0.0) & (v != 1.0))
        if bad.size:
            raise ValueError(f"attach['{name}']: sample {bad[0]}: expected 0 or 1, got {v[bad[0]]!r}")
        flags[:, names.index(name)] = v == 1.0
    return flags


def carrying(an, attached: tuple[str, ...]):
    """The analysis of ``an``'s mechanism carrying the payloads ``attached`` (``an`` itself
    for none); analysed once per set, kept while ``an`` lives."""
    if not attached:
        return an
    from .determinacy import analyse  # noqa: PLC0415
    cache = _VARIANTS.setdefault(an, {})
    if attached not in cache:
        cache[attached] = analyse(an.mech.attached(attached))
    return cache[attached]


def groups(an, flags: np.ndarray) -> list[tuple[tuple[str, ...], np.ndarray]]:
    """[(payloads attached, sample indices)] of ``flags`` (n, P), in order of first sample."""
    names = [p.name for p in an.mech.payloads]
    codes = flags.astype(np.int64) @ (1 << np.arange(flags.shape[1], dtype=np.int64))
    out = []
    for code in dict.fromkeys(codes.tolist()):
        out.append((tuple(n for b, n in enumerate(names) if code >> b & 1), np.flatnonzero(codes == code)))
    return out


def loads_at(loads: dict | None, rows) -> dict:
    """The per-sample load values of ``loads`` ({name: (N, 6) or (6,)}) at ``rows`` (a
    group's samples); a constant wrench as it is."""
    return {k: (np.asarray(v, float)[rows] if np.ndim(v) == 2 else v) for k, v in (loads or {}).items()}


def by_groups(an, flags: np.ndarray, run, n: int, carry=carrying):
    """``run(analysis, rows)`` of every group of samples (:func:`groups`), its array results
    (samples first) scattered back to the n samples.  ``run`` returns a result whose array
    fields have the group's samples first (a :class:`~.solve.Result`, or an array).
    ``carry(an, attached)``: the analysis carrying the payloads ``attached`` (a sweep's data
    kernel takes ``an``'s with the mechanism's :meth:`~gearcli.model.mechanism.Mechanism.attached`,
    whose links' inertial values alone differ)."""
    parts = [(rows, run(carry(an, attached), rows)) for attached, rows in groups(an, flags)]
    first = parts[0][1]
    if isinstance(first, np.ndarray):
        out = np.empty((n,) + first.shape[1:], first.dtype)
        for rows, r in parts:
            out[rows] = r
        return out
    from dataclasses import fields, replace  # noqa: PLC0415
    merged = {}
    for f in fields(first):
        v = getattr(first, f.name)
        if isinstance(v, np.ndarray) and v.ndim and v.shape[0] == len(parts[0][0]):
            full = np.empty((n,) + v.shape[1:], v.dtype)
            for rows, r in parts:
                full[rows] = getattr(r, f.name)
            merged[f.name] = full
    if first.residual is not None:
        merged["residual"] = float(np.max([r.residual for _, r in parts]))
    return replace(first, **merged)
