"""Generated writing of one sample's results (what :func:`..solve._result` does).

From the sample's solution row (:attr:`.links.Sample.sol`): the joint reaction
wrenches with the zero component along (about) the joint's own axis, the motor torques,
the tooth forces t with their separating, radial and axial components (the constants of
:func:`.output_maps.output_constants`), tau = A motor and the motor speeds A^T qd.
"""
from __future__ import annotations

from .build import Emitter
from .links import Sample, floats
from ..result_arrays import FIELDS as OUTPUTS


def widths(prog) -> dict:
    """Row width of each output (``OUTPUTS`` and "signs") of ``prog``'s mechanism."""
    J, M, G = prog.ints[12].shape[0], prog.ints[13].shape[0] - 1, prog.flts[8].shape[0] - 1
    dof = prog.flts[9].shape[0]
    return {"motor": M, "tau": dof, "joint": 6 * J, "gear_t": G, "gear_sep": G, "gear_radial": 2 * G,
            "gear_axial": 2 * G, "motor_speed": M, "signs": len(prog.signed)}


def _joints(e: Emitter, s: Sample, jout, row) -> None:
    for j in range(jout.shape[0]):
        c0, d = int(jout[j, 0]), 6 * j
        x = [s.sol[c0 + h] for h in range(5)]
        vals = [x[0], x[1], 0.0, x[2], x[3], x[4]] if jout[j, 1] == 1 else x + [0.0]
        for h, v in enumerate(vals):
            e.store(v, row, d + h)


def _meshes(e: Emitter, s: Sample, gcol, mflt, rows) -> None:
    gear_t, sep, rad, ax = rows
    for c in range(mflt.shape[0] - 1):
        t = s.sol[int(gcol[c])]
        f = floats(mflt[c])
        sp = e.mul(e.call("fabs", t), f[1]) if f[0] == 1.0 else 0.0
        e.store(t, gear_t, c)
        e.store(sp, sep, c)
        e.store(e.add(e.mul(t, f[2]), e.mul(sp, f[3])), rad, 2 * c)
        e.store(e.add(e.mul(t, f[4]), e.mul(sp, f[5])), ax, 2 * c)
        e.store(e.neg(e.add(e.mul(t, f[6]), e.mul(sp, f[7]))), rad, 2 * c + 1)
        e.store(e.neg(e.add(e.mul(t, f[8]), e.mul(sp, f[9]))), ax, 2 * c + 1)


def write_outputs(e: Emitter, s: Sample, prog, qdi: list, rows: dict) -> None:
    """Every output's row of this sample (``rows``: name -> double* to the row)."""
    jout, mcol, gcol = prog.ints[12], prog.ints[13], prog.ints[14]
    mflt, A = prog.flts[8], prog.flts[9]
    _joints(e, s, jout, rows["joint"])
    _meshes(e, s, gcol, mflt, [rows[k] for k in ("gear_t", "gear_sep", "gear_radial", "gear_axial")])
    motor = [s.sol[int(c)] for c in mcol[:-1]]
    for i, v in enumerate(motor):
        e.store(v, rows["motor"], i)
    for d in range(A.shape[0]):
        e.store(e.dot(floats(A[d]), motor), rows["tau"], d)
    for i in range(len(motor)):
        e.store(e.dot(qdi, floats(A[:, i])), rows["motor_speed"], i)
