"""The record layouts of the kernel program (:class:`.program.Program`), by name.

Each kind of record is a numpy record array (:func:`records`) whose columns the generator
reads by name (``rec.F``, ``rec.nlinks``): offsets and counts index the program's flat
arrays (``*0``: first position, ``n*``: count); a float column of several values is a
sub-array (``pose.R_pj`` row-major 3 x 3).  Frames and units as in the model: SI, link
frames, row-major matrices.
"""
from __future__ import annotations

import numpy as np

I, F = np.int64, np.float64


def _ints(*names: str) -> np.dtype:
    return np.dtype([(n, I) for n in names])


JOINT = _ints("joint", "parent", "child", "prismatic")
"""A real joint, in tree order: its index in the mechanism, parent and child link, 1 if prismatic."""
POSE = np.dtype([("R_pj", F, (9,)), ("p_pj", F, (3,)), ("R_jc", F, (9,)), ("p_jc", F, (3,))])
"""A joint's fixed placements: joint frame in the parent (R_pj, p_pj), child in the joint frame (R_jc, p_jc)."""
BODY = np.dtype([("mass", F), ("inertia", F, (9,)), ("com", F, (3,))])
"""A link: mass (kg), inertia about its centre of mass (link axes, kg m^2), centre of mass (link frame, m)."""
BLOCK = _ints("F", "link0", "nlinks", "n", "col0", "m", "t0", "ainv0", "prop0", "nprop", "cb0", "ncb", "term0", "nterm",
              "local")
"""A block of the schedule: frame link F (-1: world axes), its links (``block_links[link0:]``),
n unknowns (columns ``group_col[col0:]``), m signed meshes (``t_col[t0:]``, at ``t0`` in the signs row),
its pattern maps at ``ainv[ainv0:]`` (-1: a :class:`..pattern_maps.LowRank`), propagation
records ``props[prop0:]``, child-basis records ``child_basis[cb0:]``, column terms ``terms[term0:]``;
``local`` 1: a world-frame block solved in its one link's axes (:func:`.program._local_frame`; its
signed unknowns, a reducer's, do not change its matrix)."""
PROPAGATION = _ints("col0", "ncols", "signed", "cmat0", "primary", "later0", "nlater")
"""A solved group passed on to later links: its block columns (``ncols`` from ``col0``), 1 if a signed mesh, C_plus (then
C_sep) at ``cmat[cmat0:]``, the primary link, the later links ``later[later0:later0 + nlater]``."""
CHILD_BASIS = _ints("col0", "joint", "turn0")
"""A joint reaction solved in another link's basis: turned to the child's by -q of ``joint``,
or (joint -1) by -(q @ row) with the (J,) row at ``turns[turn0:]`` (:mod:`..coaxial_frames`)."""
TERM = _ints("link", "row", "col", "moment", "frame", "sign")
"""A column term of a world-frame block (:mod:`.terms`): target link, its row position in the
block (-1: a later link, the term propagates), block column, 1 for a moment (0 a force), frame
link X, signed-mesh position in the block (-1: unsigned)."""
TERM_VALUE = np.dtype([("coef", F), ("d", F, (3,)), ("p", F, (3,))])
"""A term's coefficient, direction d_X and point p_X in its frame link's axes."""
JOINT_OUT = _ints("col0", "prismatic")
"""Where a joint's reaction starts in the solution row, 1 if prismatic."""
GEAR_OUT = np.dtype([(n, F) for n in ("geometry", "tan_t", "t_rad_j", "sep_rad_j", "t_ax_j", "sep_ax_j",
                                       "t_rad_k", "sep_rad_k", "t_ax_k", "sep_ax_k", "reducer")])
"""A mesh's output coefficients: 1 if it has gear geometry, tan(phi_t), and the t and
|t| tan(phi_t) coefficients of the radial and axial components on gear j and on gear k; 1 for
a reducer (its gear_sep is the torque on its input)."""


def records(rows, dtype: np.dtype) -> np.recarray:
    """``rows`` (tuples in field order, or dicts by field name) as a record array of ``dtype``
    (no field may be named like an attribute of a numpy record: ``size``, ``shape`` ...)."""
    rows = [tuple(r[n] for n in dtype.names) if isinstance(r, dict) else tuple(r) for r in rows]
    return np.array(rows, dtype=dtype).view(np.recarray)

