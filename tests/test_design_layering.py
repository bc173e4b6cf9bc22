"""The design and batch packages keep the one-way import direction (lazy imports included)."""
import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "gearcli"
ALLOWED = {
    "model": {"model", "errors", "spatial"},
    "io": {"io", "model", "errors", "spatial"},
    "design": {"design", "model", "analysis", "dynamics", "report", "errors", "spatial"},
    "batch": {"batch", "pipeline", "design", "report", "dynamics", "analysis", "io", "model", "errors", "spatial"},
    "report": {"report", "dynamics", "analysis", "io", "model", "errors", "spatial"},
}
FILES = {"design": SRC.glob("design/*.py"), "batch": SRC.glob("batch/*.py"),
         "model": [SRC / "model" / "ratings.py"], "io": [SRC / "io" / "ratings_reader.py"],
         "report": [SRC / "report" / "plots.py"]}


def gearcli_imports(path: Path):
    pkg = path.relative_to(SRC).parts[:-1]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = list(pkg[: len(pkg) - node.level + 1])
                parts = base + (node.module.split(".") if node.module else [])
                if not parts:       # "from . import x" at the top package
                    parts = [a.name for a in node.names]
                yield parts[0] if parts else ""
            elif node.module and node.module.startswith("gearcli."):
                yield node.module.split(".")[1]
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("gearcli."):
                    yield a.name.split(".")[1]


def test_new_packages_import_only_to_their_left():
    bad = []
    for layer, files in FILES.items():
        for f in files:
            for target in gearcli_imports(f):
                if target.removesuffix(".py") not in ALLOWED[layer]:
                    bad.append(f"{f.relative_to(SRC)} imports gearcli.{target}")
    assert not bad, bad
    assert list(SRC.glob("design/*.py")) and list(SRC.glob("batch/*.py"))
