"""The arrays a solve writes its results into: fresh ones, or those of a previous result.

``solve(..., out=previous)`` writes into the arrays of a :class:`~.solve.Result` of the same
mechanism and sample count (what a streaming caller does, as Pinocchio's
``rneaInParallel`` writes into a preallocated tau): the compiled kernels then touch memory
already mapped instead of fresh pages that the operating system must zero first, the cost
that keeps two threads from doubling the speed on a large call.  The compiled kernels'
work arrays (the sign of every t used, the failing block of every sample) are kept with
``out`` for the next call.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import counted
from .losses import LOSS_FIELDS

FIELDS = ("motor", "tau", "joint", "gear_t", "gear_sep", "gear_radial", "gear_axial", "motor_speed")


def shapes(an, n: int) -> dict:
    """{field: shape} of the result arrays of n samples of ``an``'s mechanism."""
    J, G, M = len(an.mech.joints), len(an.circuits), len(an.motor_links)
    return {"motor": (n, M), "tau": (n, an.dof), "joint": (n, J, 6), "gear_t": (n, G), "gear_sep": (n, G),
            "gear_radial": (n, G, 2), "gear_axial": (n, G, 2), "motor_speed": (n, M)}


def check_out(an, n: int, out, inputs: dict) -> None:
    """ValueError unless every array of ``out`` (a Result) can take n samples of ``an``'s
    results in place: the shape of this mechanism, float64, C-ordered, writeable, sharing
    no memory with another of them or with an input (``inputs``: {name: array})."""
    for k, shape in shapes(an, n).items():
        a = getattr(out, k, None)
        if not isinstance(a, np.ndarray):
            raise ValueError(f"out.{k} is {type(a).__name__}, not an array: out must be a Result of this "
                             f"mechanism with {counted(n, 'sample')}")
        if a.shape != shape:
            raise ValueError(f"out.{k} has shape {a.shape}, expected {shape}: out must be a Result of "
                             f"this mechanism with {counted(n, 'sample')}")
        if a.dtype != np.float64 or not a.flags.c_contiguous or not a.flags.writeable:
            raise ValueError(f"out.{k} must be a writeable C-ordered float64 array (got {a.dtype}, "
                             f"C-ordered {a.flags.c_contiguous}, writeable {a.flags.writeable})")
    _check_apart([(f"out.{k}", getattr(out, k)) for k in FIELDS], inputs)


def _check_apart(named: list, inputs: dict) -> None:
    """ValueError if an array of ``named`` (name, array) shares memory with a later one or
    with an input (by bounds: ~0.3 us a pair, ~20 us a call)."""
    for i, (name, a) in enumerate(named):
        for other, b in named[i + 1:] + list(inputs.items()):
            if np.may_share_memory(a, b):
                raise ValueError(f"{name} shares memory with {other}: out's arrays must be apart from "
                                 "each other and from the inputs")


def loss_shapes(an, n: int) -> dict:
    """{field: shape} of the loss outputs a compiled kernel writes for n samples of a lossy
    mechanism ({} for a lossless one)."""
    if not an.mech.has_losses:
        return {}
    J, G = len(an.mech.joints), len(an.circuits)
    return {"gear_loss": (n, G), "joint_friction": (n, J), "joint_loss": (n, J)}


def result_arrays(an, n: int, out=None) -> dict:
    """{field: array} for n samples, the loss outputs of a lossy mechanism (:func:`loss_shapes`)
    included: ``out``'s arrays (checked before by :func:`check_out`; new loss arrays), or new
    uninitialised ones, views of one allocation apart from each other: a large one
    is mapped by the operating system in huge pages (numpy asks for them from 4 MB), so
    the kernel's first writes fault a page per 2 MB, not per 4 kB (planetary_5p, 20,000
    samples: page faults were a third of a solve's time)."""
    if out is not None:
        return {**{k: getattr(out, k) for k in FIELDS}, **one_allocation(loss_shapes(an, n))}
    return one_allocation({**shapes(an, n), **loss_shapes(an, n)})


def one_allocation(shapes: dict) -> dict:
    """{name: new uninitialised float64 array of shapes[name]}, C-ordered views of one
    allocation apart from each other."""
    sizes = {k: math.prod(shape) for k, shape in shapes.items()}      # (not np.prod: 5 us a shape)
    buf, arrays, at = np.empty(sum(sizes.values())), {}, 0
    for k, shape in shapes.items():
        arrays[k] = buf[at:at + sizes[k]].reshape(shape)
        at += sizes[k]
    return arrays


def work_arrays(n: int, signed: int, out=None) -> tuple:
    """(signs (n, max(signed, 1)), fail (n,) int64) for a compiled kernel: those kept with
    ``out`` when they fit, else new ones (kept with ``out`` when given)."""
    work = getattr(out, "_work", None) if out is not None else None
    if work is None or work[0].shape != (n, max(signed, 1)):
        work = (np.empty((n, max(signed, 1))), np.empty(n, np.int64))
        if out is not None:
            out._work = work
    return work


def copy_into(out, res) -> None:
    """The numpy path's result ``res`` copied into ``out``'s arrays (checked before); its
    loss fields (new arrays, or None for a lossless mechanism) replace ``out``'s, as the
    compiled path's do, never left from ``out``'s earlier call."""
    for k in FIELDS:
        np.copyto(getattr(out, k), getattr(res, k))
    for k in LOSS_FIELDS:
        setattr(out, k, getattr(res, k))
    out.residual = res.residual
