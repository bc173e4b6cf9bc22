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
    """Row width of each output (``OUTPUTS``, "signs" and the loss outputs of :mod:`.kernel`) of
    ``prog``'s mechanism."""
    J, M, G = len(prog.joint_out), len(prog.motor_col), len(prog.gear_out)
    dof = prog.A.shape[0]
    return {"motor": M, "tau": dof, "joint": 6 * J, "gear_t": G, "gear_sep": G, "gear_radial": 2 * G,
            "gear_axial": 2 * G, "motor_speed": M, "signs": len(prog.signed), "gear_loss": G, "joint_friction": J,
            "joint_loss": J}


def _joints(e: Emitter, s: Sample, jout, row) -> None:
    for j, out in enumerate(jout):
        c0, d = int(out.col0), 6 * j
        x = [s.sol[c0 + h] for h in range(5)]
        vals = [x[0], x[1], 0.0, x[2], x[3], x[4]] if out.prismatic == 1 else x + [0.0]
        for h, v in enumerate(vals):
            e.store(v, row, d + h)


def _meshes(e: Emitter, s: Sample, gcol, gout, rows, inputs: dict) -> None:
    """gear_t, gear_sep (a reducer's: the torque on its input, ``inputs`` where lossy, else
    its t), radial and axial components."""
    gear_t, sep, rad, ax = rows
    for c, f in enumerate(gout):
        t = s.sol[int(gcol[c])]
        sp = e.mul(e.call("fabs", t), float(f.tan_t)) if f.geometry == 1.0 else 0.0
        e.store(t, gear_t, c)
        e.store(inputs.get(c, t) if f.reducer == 1.0 else sp, sep, c)
        e.store(e.add(e.mul(t, float(f.t_rad_j)), e.mul(sp, float(f.sep_rad_j))), rad, 2 * c)
        e.store(e.add(e.mul(t, float(f.t_ax_j)), e.mul(sp, float(f.sep_ax_j))), ax, 2 * c)
        e.store(e.neg(e.add(e.mul(t, float(f.t_rad_k)), e.mul(sp, float(f.sep_rad_k)))), rad, 2 * c + 1)
        e.store(e.neg(e.add(e.mul(t, float(f.t_ax_k)), e.mul(sp, float(f.sep_ax_k)))), ax, 2 * c + 1)


def write_outputs(e: Emitter, s: Sample, prog, qdi: list, rows: dict, inputs: dict | None = None) -> None:
    """Every output's row of this sample (``rows``: name -> double* to the row; ``inputs``:
    {circuit: a lossy reducer's input torque}, :func:`.friction_terms.write_losses`)."""
    A = prog.A
    _joints(e, s, prog.joint_out, rows["joint"])
    _meshes(e, s, prog.gear_col, prog.gear_out, [rows[k] for k in ("gear_t", "gear_sep", "gear_radial", "gear_axial")],
            inputs or {})
    motor = [s.sol[int(c)] for c in prog.motor_col]
    for i, v in enumerate(motor):
        e.store(v, rows["motor"], i)
    for d in range(A.shape[0]):
        e.store(e.dot(floats(A[d]), motor), rows["tau"], d)
    for i in range(len(motor)):
        e.store(e.dot(qdi, floats(A[:, i])), rows["motor_speed"], i)
