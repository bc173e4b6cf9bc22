"""The one-source design (issue 39): every per-sample physics term written over the algebra is
called by both solver paths, and the numpy algebra folds constants as the kernel's emitter does
(so the two paths do the same operations; their equality tests then test the emitter)."""
from __future__ import annotations

import ast
import copy
from pathlib import Path

import numpy as np

from gearcli.algebra import ARRAYS

SRC = Path(__file__).resolve().parents[1] / "src" / "gearcli"


def trees() -> dict[Path, ast.AST]:
    return {path: ast.parse(path.read_text()) for path in SRC.rglob("*.py")}


def shared_terms(parsed) -> dict[str, Path]:
    """Every function of the package written over the algebra (first parameter ``al``)."""
    return {node.name: path for path, tree in parsed.items() for node in ast.walk(tree)
            if isinstance(node, ast.FunctionDef) and node.args.args and node.args.args[0].arg == "al"}


def called_names(tree) -> set[str]:
    """The names a module calls (as a name or an attribute)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            f = node.func
            out.add(f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else "")
    return out


def _without_terms(tree, terms) -> ast.AST:
    """The module without the bodies of its shared terms."""
    class Strip(ast.NodeTransformer):
        def visit_FunctionDef(self, node):
            return None if node.name in terms and node.args.args and node.args.args[0].arg == "al" else node
    return Strip().visit(copy.deepcopy(tree))


def test_every_shared_term_is_called_by_both_paths():
    """A term reaches the generator (a module of dynamics/llvm calls it, or a shared term that
    the generator reaches does) and the numpy path (a module outside dynamics/llvm calls it, or
    a shared term it reaches does): none is a helper that one path alone uses."""
    parsed = trees()
    terms = shared_terms(parsed)
    assert {"joint_frame", "child_motion", "inertia_wrench", "joint_friction", "mesh_loss", "power_flow_coefficients",
            "split_terms", "load_magnitudes", "unit_joint_wrench", "load_wrench"} <= set(terms)
    inner = {}                   # per shared term the shared terms its body calls
    for path, tree in parsed.items():
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef) and node.name in terms and terms[node.name] == path:
                inner[node.name] = called_names(node) & set(terms)
    llvm = SRC / "dynamics" / "llvm"
    reached = {"llvm": set(), "numpy": set()}
    for path, tree in parsed.items():           # calls from outside the shared terms' own bodies
        side = "llvm" if llvm in path.parents else "numpy"
        reached[side] |= called_names(_without_terms(tree, terms)) & set(terms)
    for side in reached:         # what a reached term calls is reached too
        todo = list(reached[side])
        while todo:
            for n in inner.get(todo.pop(), ()):
                if n not in reached[side]:
                    reached[side].add(n)
                    todo.append(n)
    assert set(terms) - reached["llvm"] == set(), "shared terms the generator never emits"
    assert set(terms) - reached["numpy"] == set(), "shared terms the numpy path never evaluates"


def test_the_numpy_algebra_folds_constants_as_the_emitter_does():
    """0.0 * x is 0.0 even where x is not finite (the emitter skips the product), 1.0 * x and
    -1.0 * x are x and -x, 0.0 + x is x; sign is 0 at an exact zero and at NaN, as the
    emitter's select chain gives."""
    x = np.array([np.inf, np.nan, -2.0])
    assert ARRAYS.mul(0.0, x) == 0.0 and ARRAYS.mul(x, 0.0) == 0.0
    assert ARRAYS.mul(1.0, x) is x and ARRAYS.add(0.0, x) is x and ARRAYS.sub(x, 0.0) is x
    assert np.array_equal(ARRAYS.mul(-1.0, x), -x, equal_nan=True)
    assert ARRAYS.sign(np.array([0.0, -0.0, np.nan, 3.0, -1e-300])).tolist() == [0.0, 0.0, 0.0, 1.0, -1.0]
    assert str(ARRAYS.plus_zero(-0.0)) == "0.0"


def test_the_emitter_folds_the_same_cases():
    """The kernel's side of the same rules: no instruction for 0.0 * v, 1.0 * v, 0.0 + v, v - 0.0,
    and constants combined as floats (0.0 + -0.0 is +0.0, as numpy's)."""
    import llvmlite.ir as ir

    from gearcli.dynamics.llvm.build import D, Emitter
    mod = ir.Module()
    fn = ir.Function(mod, ir.FunctionType(D, [D]), "f")
    e = Emitter(ir.IRBuilder(fn.append_basic_block()), mod)
    v = fn.args[0]
    assert e.mul(0.0, v) == 0.0 and e.mul(v, 0.0) == 0.0
    assert e.mul(1.0, v) is v and e.add(0.0, v) is v and e.sub(v, 0.0) is v
    assert str(e.add(0.0, -0.0)) == str(ARRAYS.add(0.0, -0.0)) == "0.0"
    assert not e.b.block.instructions            # nothing emitted so far
    assert e.mul(2.0, v) is not v and len(e.b.block.instructions) == 1


def test_one_sample_terms_equal_the_rows_of_a_batch():
    """The numpy path evaluates the shared terms of a one-sample call with Python floats
    (:class:`Floats`) and of N samples with arrays (:class:`Arrays`): the same operations,
    so the kinematics (Eqs. 2-5), the d'Alembert wrenches (Eqs. 17-18) and the joint-axis
    wrenches of one sample equal its row of the batch bit for bit (but a zero's sign), on
    every bundled mechanism, at rest and moving; and a one-sample solve equals its row to
    rounding (the block solves' LAPACK calls differ with the batch size, as before)."""
    import dataclasses

    import gearcli
    from gearcli.dynamics.inertia import inertia_load
    from gearcli.dynamics.kinematics import forward
    from gearcli.dynamics.wrenches import joint_axis_wrench

    def same(a, b):
        return np.array_equal(a, b, equal_nan=True)      # -0.0 == 0.0: the float path does not fold

    rng = np.random.default_rng(7)
    bits = 0
    for path in sorted((SRC.parents[1] / "mechanisms").glob("*.yaml")):
        an = gearcli.analyse(gearcli.load_mechanism(path))
        J = len(an.mech.joints)
        q, qd, qdd = (rng.normal(size=(3, J)) for _ in range(3))
        qd[0], qdd[0], qd[1, 0] = 0.0, 0.0, 0.0          # at rest, and one joint held
        kin = forward(an.mech, an.tree, q, qd, qdd)
        b_all = inertia_load(an, kin)
        for i in range(3):
            k1 = forward(an.mech, an.tree, q[i:i + 1], qd[i:i + 1], qdd[i:i + 1])
            assert isinstance(k1.link_terms(an.tree.moving[0])[1][0], float)   # the float path ran
            for name in ("R", "o", "w", "dw", "a", "Rj", "oj"):
                for x, y in zip(getattr(kin, name), getattr(k1, name)):
                    assert x is None or same(y[0], x[i]), (path.name, name, i)
                    bits += 1
            for L, b in inertia_load(an, k1).items():
                assert same(b[0], b_all[L][i]), (path.name, L, i)
            for ji, jt in enumerate(an.mech.joints):
                L = an.tree.index[jt.child]
                assert same(joint_axis_wrench(an, k1, ji, L)[0], joint_axis_wrench(an, kin, ji, L)[i])
        qi, qdi, qddi = (rng.normal(size=(3, an.dof)) for _ in range(3))
        batch = gearcli.solve(an, qi, qdi, qddi, backend="numpy")
        one = gearcli.solve(an, qi[1:2], qdi[1:2], qddi[1:2], backend="numpy")
        for f in dataclasses.fields(batch):
            b, o = getattr(batch, f.name), getattr(one, f.name)
            if isinstance(b, np.ndarray) and b.dtype.kind == "f" and b.ndim >= 1 and b.shape[0] == 3:
                assert np.allclose(o[0], b[1], rtol=0, atol=1e-13 * max(np.abs(b[1]).max(), 1.0)), f.name
    assert bits > 1000
