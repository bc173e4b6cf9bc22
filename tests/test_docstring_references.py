"""Every dotted reference in a docstring names something that exists (issue 39): the roles
:func:, :class:, :mod:, :meth:, :attr:, :data: with a dotted target (relative ones resolved
from the module's package, Sphinx's way) and every plain ``gearcli.x.y`` in the text.  Stale
names (``gearcli.loader``, ``gearcli.graph``) crept in as modules were moved."""
from __future__ import annotations

import ast
import dataclasses
import importlib
import re
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "gearcli"
ROLE = re.compile(r":(?:func|class|mod|meth|attr|data|exc):`~?([A-Za-z_.][\w.]*)`")
PLAIN = re.compile(r"(?<![\w.`~])(gearcli(?:\.[A-Za-z_]\w*)+)")


def _module_name(path: Path) -> str:
    parts = ("gearcli",) + path.relative_to(SRC).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _docstrings(tree):
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = ast.get_docstring(node, clean=False)
            if doc:
                yield doc


def _resolve(dotted: str) -> bool:
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for name in parts[i:]:
            if hasattr(obj, name):
                obj = getattr(obj, name)
            elif dataclasses.is_dataclass(obj) and name in {f.name for f in dataclasses.fields(obj)}:
                return True
            elif name in getattr(obj, "__annotations__", {}):
                return True
            elif isinstance(obj, type) and f"self.{name} " in _source(obj):      # an instance attribute
                return True
            else:
                return False
        return True
    return False


def _source(cls) -> str:
    import inspect
    try:
        return inspect.getsource(cls)
    except (OSError, TypeError):
        return ""


def _absolute(ref: str, module: str, is_package: bool) -> str | None:
    if ref.startswith("gearcli."):
        return ref
    if not ref.startswith("."):
        return None                       # a bare name: the module's own (not checked here)
    dots = len(ref) - len(ref.lstrip("."))
    base = module.split(".") if is_package else module.split(".")[:-1]
    base = base[:len(base) - (dots - 1)]
    return ".".join(base + [ref.lstrip(".")]) if ref.lstrip(".") else ".".join(base)


def test_every_dotted_reference_in_a_docstring_resolves():
    bad = []
    for path in sorted(SRC.rglob("*.py")):
        module = _module_name(path)
        for doc in _docstrings(ast.parse(path.read_text())):
            refs = [(r, _absolute(r, module, path.name == "__init__.py")) for r in ROLE.findall(doc)]
            refs += [(r, r) for r in PLAIN.findall(doc)]
            for ref, target in refs:
                if target is not None and not _resolve(target.rstrip(".")):
                    bad.append(f"{path.relative_to(SRC)}: {ref}")
    assert not bad, "\n".join(sorted(set(bad)))
