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
