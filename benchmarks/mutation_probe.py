"""Mutation probe: do the independent tests catch deliberate physics bugs?

For every mutation in :data:`MUTATIONS` (file under ``src/gearcli``, exact old snippet, new
snippet, description) the probe copies ``src/`` to a temporary directory, applies the
edits, and runs the independent tests (:data:`TESTS`, stop at the first failure) with
``PYTHONPATH`` pointing at the copy.  It prints a table: caught / missed and the test that
caught each bug.

Usage (from the repository root, test extra installed)::

    python benchmarks/mutation_probe.py              # all mutations
    python benchmarks/mutation_probe.py -k alpha     # those whose name contains "alpha"
    python benchmarks/mutation_probe.py -x --tests "tests --ignore=tests/test_independent.py"

Exit status 0 when every mutation is caught, 1 when one is missed, 2 when a snippet is not
found exactly once in the current source (the list must be kept in sync with ``src/``) or
when the unmutated copy fails the tests.  A mutation of the array implementation only
(:data:`NUMPY_ONLY`) runs with the numpy path as the default backend; the others run with
the default (the compiled kernel wherever it applies, recompiled in each copy: ~20 s CPU).
Consistency checks that share gearcli's own
kinematics or equation assembly (block vs full solve, the Newton-Euler residual of the
solution, balances on gearcli's kinematics) are deliberately not in :data:`TESTS`.
"""
from __future__ import annotations

import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# Independent tests only, the fastest and most telling first.
TESTS = [
    "tests/test_independent.py",
    "tests/test_dynamics.py::test_paper_closed_form",
    "tests/test_dynamics.py::test_paper_static_weight_on_vertical_bearings",
    "tests/test_dynamics.py::test_spatial_gear_constraints",
    "tests/test_dynamics.py::test_separating_force",
    "tests/test_dynamics.py::test_planetary_structure",
    "tests/test_dynamics.py::test_ring_pair_is_exercised",
    "tests/test_dynamics.py::test_pinocchio_rnea",
    "tests/test_dynamics.py::test_pinocchio_bearing_reactions",
    "tests/test_dynamics.py::test_pinocchio_joint_reaction_of_gearless_subtree",
    "tests/test_rack.py::test_static_rack_by_hand",
    "tests/test_rack.py::test_rack_sign_from_geometry",
    "tests/test_rack.py::test_power_balance_along_bundled_trajectory",
    "tests/test_rack.py::test_pinion_riding_on_the_carriage",
    "tests/test_rack.py::test_pinocchio_rnea_with_the_tooth_force_as_fext",
    "tests/test_helical.py::test_static_helical_by_hand",
    "tests/test_helical_bundled.py::test_static_reduction_by_hand",
    "tests/test_helical_bundled.py::test_bearing_radial_and_axial_loads_by_hand",
    "tests/test_helical_bundled.py::test_power_balance_along_bundled_trajectory",
    "tests/test_losses.py::test_spur_pair_lifting_then_lowering",
    "tests/test_losses.py::test_rack_axis_with_carriage_friction",
    "tests/test_losses.py::test_three_planet_planetary_efficiency_by_hand",
    "tests/test_losses.py::test_overhung_shaft_bearing_friction_by_hand",
    "tests/test_losses.py::test_gear_in_the_plane_of_its_bearing",
    "tests/test_losses.py::test_power_balance_with_losses[block-servo_joint_rated.yaml]",
    "tests/test_llvm_losses.py::test_llvm_equals_numpy_with_losses[servo_joint_rated.yaml]",
    "tests/test_llvm_losses.py::test_llvm_equals_numpy_with_losses[planetary_3p_rated.yaml]",
    "tests/test_llvm_losses.py::test_screened_trials_where_friction_reverses_a_tooth_force",
    "tests/test_llvm_losses.py::test_friction_that_locks_the_mechanism_fails_the_same_sample_on_both_paths",
    "tests/test_losses.py::test_power_balance_with_losses[block-bendix_wrist_rated.yaml]",
    "tests/test_helical_bundled.py::test_pinocchio_rnea_per_shaft_with_tooth_forces",
    "tests/test_load_sharing.py::test_each_planet_carries_one_nth_of_the_lumped_planet",
    "tests/test_load_sharing.py::test_unequal_stiffness_shares_in_proportion",
    "tests/test_load_sharing.py::test_least_load_map_two_parallel_springs",
    "tests/test_load_sharing.py::test_split_path_drive_by_hand",
    "tests/test_reducers.py::test_strain_wave_holds_lifts_and_lowers_a_load_by_hand",
    "tests/test_reducers.py::test_lossy_reducer_on_a_moving_housing_balances_power",
    "tests/test_screws.py::test_ball_screw_lifts_and_lowers_1_kN_by_hand",
    "tests/test_screws.py::test_self_locking_lead_screw_lowers_under_power",
]


@dataclass(frozen=True)
class Mutation:
    name: str
    description: str
    edits: tuple   # ((path under src/gearcli, old snippet, new snippet), ...)

    @property
    def numpy_path(self) -> bool:
        """True for a bug in the array implementation only (its kinematics, loads or
        columns): the compiled kernel, the default backend, does not run that code, so the
        mutated copy is made to solve by the numpy path (:data:`NUMPY_DEFAULT`)."""
        return any(e[0] in NUMPY_ONLY for e in self.edits)

    @property
    def default_edits(self) -> tuple:
        """The edit choosing the path the mutated code is on as "auto"'s: numpy for the
        array implementation, llvm for the generator's."""
        if self.numpy_path:
            return (NUMPY_DEFAULT,)
        if any(e[0].startswith("dynamics/llvm") for e in self.edits):
            return (LLVM_DEFAULT,)
        return ()


NUMPY_ONLY = {"dynamics/equations.py", "dynamics/losses.py"}     # (the shared terms run on both paths)
# the edit that makes "auto" take the numpy path in a copy
NUMPY_DEFAULT = ("dynamics/backends.py", 'if backend == "numpy":', 'if backend in ("numpy", "auto"):')
# the edit that makes "auto" take the llvm kernel whenever it can (no first-call rule)
LLVM_DEFAULT = ("dynamics/backends.py", "note = _first_call(sol, n)", "note = None")


MUTATIONS = [
    Mutation("dh-alpha-sign", "D-H twist alpha read with the wrong sign (Rx(-alpha))",
             (("model/geometry.py",
               "return rot_z(theta), np.array([0.0, 0.0, d]), rot_x(alpha), np.array([a, 0.0, 0.0])",
               "return rot_z(theta), np.array([0.0, 0.0, d]), rot_x(-alpha), np.array([a, 0.0, 0.0])"),)),
    # the shared terms (gearcli.algebra): one edit makes the bug on both paths
    Mutation("joint-rotation-transposed", "joint rotation R0 Rz(q) applied as R0 Rz(q)^T",
             (("dynamics/kinematics.py",
               "Rj += [al.add(al.mul(cq, r0), al.mul(sq, r1)), al.sub(al.mul(cq, r1), al.mul(sq, r0)), R0[3 * i + 2]]",
               "Rj += [al.sub(al.mul(cq, r0), al.mul(sq, r1)), al.add(al.mul(cq, r1), al.mul(sq, r0)), R0[3 * i + 2]]"),)),
    Mutation("drop-w-x-z-qd", "angular acceleration without the w_parent x z qd term",
             (("dynamics/kinematics.py",
               "dwc = al.vadd(al.vadd(dw_p, al.scale(z, qdd)), al.scale(al.cx(w_p, z), qd))",
               "dwc = al.vadd(dw_p, al.scale(z, qdd))"),)),
    Mutation("gravity-sign", "gravity vector used with the wrong sign in the inertia loads",
             (("dynamics/inertia.py", "al.vsub(arm_acceleration(al, a_i, alpha_i, omega_i, rc), g)",
               "al.vadd(arm_acceleration(al, a_i, alpha_i, omega_i, rc), g)"),)),
    Mutation("inertia-about-origin", "CoM inertia used as if about the link origin (parallel-axis terms dropped)",
             (("dynamics/inertia.py",
               "return F + al.vadd(al.mv(R_0i, Nb), al.cx(rc, F))",
               "return F + al.vadd(al.mv(R_0i, Nb), al.cx(rc, al.scale(al.vsub(a_i, g), m)))"),)),
    Mutation("separating-force-sign", "separating force pulls the gears together",
             (("model/gears.py",
               "us = -rad_j + (rad_j @ element) * element",
               "us = rad_j - (rad_j @ element) * element"),)),
    Mutation("tan-to-sin", "separating force abs(t) sin(phi) instead of abs(t) tan(phi)",
             (("model/gears.py",
               "tan_t = float(np.tan(pressure_angle) / np.cos(helix_angle))",
               "tan_t = float(np.sin(pressure_angle) / np.cos(helix_angle))"),)),
    Mutation("gear-ratio-inverted", "circuit equation theta_j = theta_k / e instead of theta_j = e theta_k",
             (("analysis/circuits.py", "return Circuit(gi, j, k, c, float(ratio), row_j - ratio * row_k,",
               "return Circuit(gi, j, k, c, float(ratio), ratio * row_j - row_k,"),)),
    Mutation("moment-cross-order", "moment of a force as f x r instead of r x f",
             (("dynamics/wrenches.py",
               "return al.scale(d, coef) + al.scale(al.cx(arm, d), coef)",
               "return al.scale(d, coef) + al.scale(al.cx(d, arm), coef)"),)),
    Mutation("coriolis-factor-2", "prismatic Coriolis acceleration w x v instead of 2 w x v",
             (("dynamics/kinematics.py",
               "al.scale(al.cx(w_p, al.scale(z, qd)), 2.0)",
               "al.scale(al.cx(w_p, al.scale(z, qd)), 1.0)"),)),
    # further bugs, beyond the list of issue 7
    Mutation("drop-centripetal", "acceleration of a point on a turning body without w x (w x r)",
             (("dynamics/kinematics.py",
               "return al.vadd(a, al.vadd(al.cx(dw, r), al.cx(w, al.cx(w, r))))",
               "return al.vadd(a, al.cx(dw, r))"),)),
    Mutation("inertia-world-axes", "inertia tensor (link axes) applied to world-frame w",
             (("dynamics/inertia.py", "wb = al.mtv(R_0i, omega_i)", "wb = omega_i"),)),
    Mutation("no-stator-reaction", "motor torque not reacted on the stator",
             (("dynamics/column_terms.py", "L, 1.0, 1.0 if L == x else -1.0)]", "L, 1.0, 1.0 if L == x else 0.0)]"),)),
    Mutation("ring-as-gear-j", "ring gear j of an internal pair pushed inwards",
             (("model/gears.py", "return ut, (-us if ring == 0 else us), e", "return ut, us, e"),)),
    Mutation("bevel-sep-radial", "bevel separating force along the radius, not normal to the pitch element",
             (("model/gears.py",
               "us = -rad_j + (rad_j @ element) * element",
               "us = -rad_j + 0.0 * element"),)),
    # issue 9: racks and helical gears
    Mutation("rack-sign", "rack displacement x = -r theta where the geometry gives x = +r theta",
             (("model/gears.py", "e = 1.0 / (r_j * np.sign(along))", "e = -1.0 / (r_j * np.sign(along))"),)),
    Mutation("helical-hand", "axial thrust of a helical gear with the hand reversed",
             (("model/gears.py", 'sign = -1.0 if hand == "right" else 1.0', 'sign = 1.0 if hand == "right" else -1.0'),)),
    # issue 9: load sharing in redundant gear sets
    Mutation("sharing-weights-ignored", "mesh stiffness ignored: every mesh of a redundant set weighted alike",
             (("dynamics/sharing.py", "w.append(scale.get(g.index, 1.0))", "w.append(1.0)"),)),
    Mutation("sharing-weights-inverted", "min sum k t^2 instead of min sum t^2 / k",
             (("dynamics/sharing.py", "else kmin / x for i, x", "else x / kmin for i, x"),)),
    # issue 19: losses (the numpy reference solves every lossy mechanism)
    Mutation("loss-couple-reversed", "mesh friction couple along the relative angular velocity instead of against it",
             (("dynamics/losses.py", "return -loss * gm.r_j * u0 / float(u0 @ u0)",
               "return loss * gm.r_j * u0 / float(u0 @ u0)"),)),
    Mutation("loss-arm-pitch-radius", "mesh friction arm r_j instead of r_j / |u0| (rho = r_j r_k / (r_j + r_k))",
             (("dynamics/losses.py", "return -loss * gm.r_j * u0 / float(u0 @ u0)",
               "return -loss * gm.r_j * u0 / float(np.sqrt(u0 @ u0))"),)),
    Mutation("loss-coulomb-sign", "joint Coulomb friction with the rate instead of against it",
             (("dynamics/loss_terms.py", "al.signed(qd, 0.0 - F_c, F_c)", "al.signed(qd, F_c, 0.0 - F_c)"),)),
    Mutation("power-flow-swapped", "power-flow efficiency: eta_f and eta_b swapped in the coefficients",
             (("dynamics/loss_terms.py", "inv_f, eta_b = al.div(1.0, al.interp(speed, forward)), al.interp(speed, backward)",
               "inv_f, eta_b = al.div(1.0, al.interp(speed, backward)), al.interp(speed, forward)"),)),
    Mutation("bearing-split", "bearing split: the tilting moment's x part with the wrong sign",
             (("model/shaft.py", "R2y = al.mul(al.sub(al.neg(mx), al.mul(z1, fy)), inv)",
               "R2y = al.mul(al.sub(mx, al.mul(z1, fy)), inv)"),)),
    Mutation("bearing-locating", "bearing friction: the axial force left out of the locating bearing's load",
             (("dynamics/llvm/bearing_newton.py", "[x, y, R[4] if loc else 0.0]", "[x, y, 0.0]"),
              ("dynamics/bearing_friction.py", "al.mul(loc1, fz2)", "al.mul(0.0, fz2)"))),
    # the generated llvm kernel
    Mutation("llvm-propagation-sign", "llvm: a solved wrench passed on to a later link with the primary's sign",
             (("dynamics/llvm/blocks.py", "1.0 if L == P else -1.0", "1.0"),)),
    Mutation("llvm-child-basis-turn", "llvm: joint reaction turned to the child's basis by +q instead of -q",
             (("dynamics/llvm/blocks.py", "e.add(e.mul(cq, x0), e.mul(sq, x1))", "e.sub(e.mul(cq, x0), e.mul(sq, x1))"),)),
    Mutation("term-point", "column term's point without its frame link's origin (the shared term: both paths)",
             (("dynamics/wrenches.py", "return al.vadd(o_X, al.mv(R_X, p_X))", "return al.mv(R_X, p_X)"),)),
    # issue 19: losses in the generated kernel
    Mutation("llvm-loss-couple-sign", "llvm: constant-frame block, mesh friction couple with the rate instead of against it",
             (("dynamics/llvm/losses.py", "return [e.mul(sig[i], sv) for", "return [e.mul(e.neg(sig[i]), sv) for"),)),
    Mutation("llvm-world-couple-sign", "llvm: world-frame block, mesh friction couple with the rate instead of against it",
             (("dynamics/llvm/losses.py", "coef = e.mul(sig[n], sv[k])", "coef = e.neg(e.mul(sig[n], sv[k]))"),)),
    Mutation("llvm-joint-friction-sign", "llvm: joint friction applied to the parent instead of the child",
             (("dynamics/llvm/friction_terms.py", "((child, 1.0), (parent, -1.0))", "((child, -1.0), (parent, 1.0))"),)),
    Mutation("llvm-joint-loss-sign", "llvm: joint loss output F q' instead of -F q'",
             (("dynamics/llvm/friction_terms.py", "e.store(e.neg(e.mul(f, s.qd[ji])), rows", "e.store(e.mul(f, s.qd[ji]), rows"),)),
    Mutation("llvm-gear-loss-rate", "llvm: mesh loss output with the rate row's coefficients halved",
             (("dynamics/llvm/friction_terms.py", "rates = [e.const(e.dot(floats(lp.rate_flt[k]), s.qdi))",
               "rates = [e.const(e.dot(tuple(0.5 * v for v in floats(lp.rate_flt[k])), s.qdi))"),)),
    Mutation("llvm-table-sv", "llvm: stored (s_v, sign) maps of a constant-frame block read with s_v reversed",
             (("dynamics/llvm/hot_pairs.py", "digit = e.b.add(e.b.fptosi(e.const(sv[k]), I64), ir.Constant(I64, 1))",
               "digit = e.b.sub(ir.Constant(I64, 1), e.b.fptosi(e.const(sv[k]), I64))"),)),
    Mutation("llvm-bearing-one-step", "llvm: bearing friction Newton levels stopped at the first (the moments they start from)",
             (("dynamics/llvm/bearing_newton.py", "    e.b.cbranch(ok, out, tried)\n",
               "    e.b.cbranch(ir.Constant(I1, 1), out, tried)\n"),)),
    Mutation("llvm-bearing-jacobian", "llvm: bearing friction Newton step without its Jacobian (a fixed-point step taken as Newton's)",
             (("dynamics/llvm/bearing_newton.py", "Nk = [e.add(e.mul(Nk[i], q), e.mul(e.mul(h, Dk), e.dot(u, ug[i]))) for i in range(K)]",
               "Nk = [e.mul(Nk[i], q) for i in range(K)]"),)),
    Mutation("llvm-bearing-bound", "llvm: bearing friction Newton step accepted without its error bound",
             (("dynamics/llvm/bearing_newton.py", "lhs = e.mul(e.mul(0.5, e.add(1.0, lam)), e.mul(S, e.mul(rn, rn)))", "lhs = 0.0"),)),
    Mutation("llvm-bearing-unaffected", "llvm: bearing friction taken as g(0) in one iteration where the loads do depend on the moments",
             (("dynamics/llvm/bearing_newton.py", "return all(_constant(sigma) for bearings", "return True or all(_constant(sigma) for bearings"),)),
    Mutation("llvm-bearing-unloaded", "llvm: an unloaded bearing (P_b = 0) zeroing its joint's Jacobian (Newton falls back to fixed-point steps)",
             (("dynamics/llvm/bearing_newton.py", "q = e.b.select(e.b.fcmp_ordered(\">\", e.const(p), zero), e.const(p), one)", "q = p"),)),
    Mutation("llvm-bearing-world-columns", "llvm: bearing friction in a world-frame block with the joints' unit-couple solutions in reverse order",
             (("dynamics/llvm/bearings.py", "X, world.more = world.more_x, ()", "X, world.more = world.more_x[::-1], ()"),)),
    Mutation("llvm-bearing-product-table", "llvm: bearing friction's unit couples in a lossy block taken from the stored X W without the mesh friction's correction",
             (("dynamics/llvm/losses.py", "        return self._corrected(e, p, xrs, xf, list(range(n)))",
               "        return [[xr[i] for i in range(n)] for xr in xrs]"),)),
    Mutation("llvm-bearing-strict-fit", "llvm: bearing friction's converged tooth forces taken as fitting the zero-moment pattern whatever their signs",
             (("dynamics/llvm/bearings.py", "ok = _consistent(e, t, neg, ir.Constant(D, 0.0))",
               "ok = _consistent(e, t, neg, ir.Constant(D, float('inf')))"),)),
    Mutation("llvm-bearing-later-couple", "llvm: bearing friction couple passed on to a later block's link with the child's sign on the parent",
             (("dynamics/llvm/bearings.py", "e.mul(sign, e.mul(amount, jt.zw[j][h]))", "e.mul(amount, jt.zw[j][h])"),)),
    Mutation("llvm-inverse-cache-key", "llvm: a lossy block's cached inverse of 1 + M_l D looked up by the sign pattern alone, not D's relative-speed digits",
             (("dynamics/llvm/losses.py", "key = e.add(e.mul(3.0, key), e.add(db, 1.0))", "key = e.add(e.mul(3.0, key), 1.0)"),)),
    Mutation("llvm-inverse-cache-slot", "llvm: a cache hit in a lossy block's inverse cache read from the other entry",
             (("dynamics/llvm/inverse_cache.py", "slot_hit = b_.select(hit[1], ir.Constant(I64, 1), ir.Constant(I64, 0))",
               "slot_hit = b_.select(hit[1], ir.Constant(I64, 0), ir.Constant(I64, 1))"),)),
    Mutation("llvm-mesh-screen", "llvm: a lossy block's trials screened with half the bound on the friction's change of a tooth force",
             (("dynamics/llvm/losses.py", "self.screen = mu / (1.0 - rho)", "self.screen = 0.5 * mu / (1.0 - rho)"),)),
    Mutation("llvm-mesh-couple-map", "llvm: a lossy block's accepted solution corrected by the couples' map of pattern 0",
             (("dynamics/llvm/losses.py", "xr, get = self.inner.rows(e, fn, p, rows, r, tag), self._couple_map(e, p)",
               "xr, get = self.inner.rows(e, fn, p, rows, r, tag), self._couple_map(e, ir.Constant(I64, 0))"),)),
    Mutation("llvm-constant-pool-key", "llvm: the kernels' constant pool keyed by each constant in single precision (nearby constants share one entry)",
             (("dynamics/llvm/build.py", 'i = self.index.setdefault(struct.pack("<d", a), len(self.index))',
               'i = self.index.setdefault(struct.pack("<f", a), len(self.index))'),
              ("dynamics/llvm/build.py", 'values = [struct.unpack("<d", k)[0] for k in self.index] or [0.0]',
               'values = [struct.unpack("<f", k)[0] for k in self.index] or [0.0]'))),
    Mutation("llvm-hot-lossy-map", "llvm: a hot (pattern, s_v) pair's stored lossy map made with D's signs reversed",
             (("dynamics/llvm/lossy_maps.py", "for i in bl.positions]) * sv)", "for i in bl.positions]) * -sv)"),)),
    Mutation("llvm-hot-tabled-pattern", "llvm: a tabled signed block's hot pattern cases each computing the next hot pattern's map",
             (("dynamics/llvm/signs.py", "lambda A=self.maps[k]: [e.dot(floats(A[i]), r) for i in rows]) for k in self.hot]",
               "lambda A=self.maps[self.hot[(j + 1) % len(self.hot)]]: [e.dot(floats(A[i]), r) for i in rows]) for j, k in enumerate(self.hot)]"),)),
    Mutation("llvm-hot-pair-products", "llvm: a hot lossy pair's products with bearing friction's unit couples reversed",
             (("dynamics/llvm/hot_pairs.py", "lambda P=L @ cols:", "lambda P=-(L @ cols):"),)),
    Mutation("llvm-first-pattern-run", "llvm: a sign search starting from the sample before's pattern across a run of WARM samples (threads could change a result)",
             (("dynamics/llvm/kernel.py", 'first = e.b.select(fresh, ir.Constant(I64, 0), next(before))', 'first = next(before)'),)),
    Mutation("llvm-bearing-pattern-fallback", "llvm: a signed block whose bearing friction does not converge for its pattern at zero moments records the failure (instead of the whole block's loop, as the numpy path)",
             (("dynamics/llvm/bearings.py", "failed = (lambda g, change: None) if m else (", "failed = (lambda g, change: _failed(e, prog, bb, g, change, fail, n)) if m else ("),)),
    Mutation("llvm-bearing-infinite-moment", "llvm: a bearing friction moment grown to infinity passes the fixed point's test (inf <= TOL inf)",
             (("dynamics/llvm/bearing_newton.py", "return change, e.b.and_(ok, finite), finite", "return change, ok, ir.Constant(I1, 1)"),)),
    Mutation("bearing-infinite-moment", "numpy: a bearing friction moment grown to infinity passes the fixed point's test (then the sign search meets the overflow)",
             (("dynamics/bearing_friction.py", "finite = np.isfinite(new)", "finite = np.ones_like(new, dtype=bool)"),)),
    Mutation("llvm-data-body-com", "llvm data kernel: a link's centre of mass read one double early (the inertia's last entry)",
             (("dynamics/llvm/kernel.py", "return v[0], tuple(v[1:10]), tuple(v[10:13])", "return v[0], tuple(v[1:10]), tuple(v[9:12])"),)),
    Mutation("llvm-sin-quadrant", "llvm: inline sin with the quadrant's sign flipped",
             (("dynamics/llvm/trig.py", "b.select(sin_neg, e.neg(sin_mag), sin_mag)", "b.select(sin_neg, sin_mag, e.neg(sin_mag))"),)),
]


class SnippetError(Exception):
    pass


def copy_source(dest: Path) -> Path:
    """Copy src/ (and the schemas/ it reads at run time) under ``dest``; returns dest/src."""
    shutil.copytree(ROOT / "src", dest / "src", ignore=shutil.ignore_patterns("__pycache__"))
    if (ROOT / "schemas").is_dir():
        shutil.copytree(ROOT / "schemas", dest / "schemas")
    return dest / "src"


def apply(src: Path, m: Mutation) -> None:
    """Apply m's edits to the copy ``src`` (…/gearcli); each old snippet must occur once."""
    for rel, old, new in m.edits + m.default_edits:
        path = src / rel
        if not path.is_file():
            raise SnippetError(f"{m.name}: file src/gearcli/{rel} does not exist")
        text = path.read_text()
        n = text.count(old)
        if n != 1:
            raise SnippetError(f"{m.name}: snippet found {n} times (expected once) in src/gearcli/{rel}:\n  {old!r}")
        path.write_text(text.replace(old, new))


def run_tests(src_root: Path, tests, stop_first: bool) -> tuple[bool, list, int, float]:
    """(passed, failing tests, tests run, seconds) with gearcli imported from src_root."""
    env = dict(os.environ, PYTHONPATH=str(src_root), PYTHONDONTWRITEBYTECODE="1")
    cmd = [sys.executable, "-m", "pytest", "-o", "addopts=", "-q", "-rfE", "-p", "no:cacheprovider", *tests]
    if stop_first:
        cmd.insert(3, "-x")
    t0 = time.perf_counter()
    out = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    failing = re.findall(r"^(?:FAILED|ERROR) (\S+)", out.stdout, re.M)
    counts = {k: int(n) for n, k in re.findall(r"(\d+) (passed|failed|error|errors)\b", out.stdout)}
    total = sum(counts.values())
    if out.returncode not in (0, 1) and not failing:
        failing = [f"pytest exit {out.returncode}: {out.stdout[-300:]}"]
    return out.returncode == 0, failing, total, dt


def check_import(src_root: Path) -> None:
    env = dict(os.environ, PYTHONPATH=str(src_root))
    got = subprocess.run([sys.executable, "-c", "import gearcli; print(gearcli.__file__)"], env=env,
                         capture_output=True, text=True).stdout.strip()
    if not got.startswith(str(src_root)):
        raise SystemExit(f"mutation_probe: gearcli imported from {got!r}, not from the copy {src_root}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-k", default="", help="only mutations whose name contains this")
    ap.add_argument("-x", action="store_true", help="stop each run at the first failing test (faster)")
    ap.add_argument("--tests", default=" ".join(TESTS), help="pytest arguments selecting the tests to run, "
                    "one string (default: the independent tests)")
    args = ap.parse_args(argv)
    todo = [m for m in MUTATIONS if args.k in m.name]
    rows, missed = [], 0
    with tempfile.TemporaryDirectory(prefix="gearcli-mut-") as tmp:
        base = copy_source(Path(tmp) / "clean")
        check_import(base)
        for m in todo:            # every snippet first: fail loudly before spending minutes
            scratch = Path(tmp) / "check"
            try:
                apply(copy_source(scratch) / "gearcli", m)
            except SnippetError as e:
                print(f"mutation_probe: {e}", file=sys.stderr)
                return 2
            finally:
                shutil.rmtree(scratch)
        ok, failing, total, dt = run_tests(base, shlex.split(args.tests), False)
        if not ok:
            print(f"mutation_probe: the unmutated source fails {failing}", file=sys.stderr)
            return 2
        print(f"unmutated source: {total} tests pass ({dt:.1f} s)", flush=True)
        for m in todo:
            copy = copy_source(Path(tmp) / m.name)
            apply(copy / "gearcli", m)
            passed, failing, _, dt = run_tests(copy, shlex.split(args.tests), args.x)
            missed += passed
            status = "MISSED" if passed else ("caught" if args.x else f"caught by {len(failing)} of {total}")
            first = failing[0] if failing else ""
            rows.append((m, status, first))
            print(f"  {m.name}: {status} {first} ({dt:.1f} s)", flush=True)
            shutil.rmtree(copy.parent)
    print()
    print("| mutation | bug | in | result | first failing test |")
    print("|---|---|---|---|---|")
    for m, status, first in rows:
        where = ", ".join(sorted({e[0] for e in m.edits}))
        first = first.replace("tests/", "", 1)
        print(f"| `{m.name}` | {m.description} | {where} | {status} | {'`' + first + '`' if first else '-'} |")
    print(f"\n{len(rows) - missed} of {len(rows)} mutations caught")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
