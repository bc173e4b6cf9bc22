"""Write docs/reference/mechanism.md from schemas/mechanism.schema.json: the schema is the
one source of the mechanism file's keys (tests/test_docs.py fails when the page differs).

    python docs/gen_reference.py
"""
from __future__ import annotations

import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "schemas" / "mechanism.schema.json"
PAGE = ROOT / "docs" / "reference" / "mechanism.md"


def _type(spec: dict) -> str:
    if "$ref" in spec:
        return spec["$ref"].rsplit("/", 1)[-1]
    if "enum" in spec:
        return ", ".join(f"`{v}`" for v in spec["enum"])
    if spec.get("type") == "array" and "items" in spec:
        return f"list of {_type(spec['items'])}"
    if "if" in spec and "then" in spec:
        return f"{_type(spec['then'])} (by kind) or {_type(spec['else'])}"
    if "oneOf" in spec:
        return " or ".join(_type(s) for s in spec["oneOf"])
    return str(spec.get("type", "value"))


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _table(props: dict, required=()) -> list[str]:
    out = ["| key | type | description |", "|---|---|---|"]
    for key, spec in props.items():
        name = f"`{key}`" + (" (required)" if key in required else "")
        out.append(f"| {name} | {_cell(_type(spec))} | {_cell(spec.get('description', ''))} |")
    return out


def page() -> str:
    schema = json.loads(SCHEMA.read_text())
    lines = ["# Mechanism file (YAML)", "",
             "Generated from `schemas/mechanism.schema.json` by `docs/gen_reference.py`: the schema is",
             "the one source of these keys (a test fails when this page differs from it). SI units.", "",
             schema.get("description", ""), "", "## Top level", ""]
    lines += _table(schema["properties"], schema.get("required", ()))
    for name, spec in schema.get("$defs", {}).items():
        if "properties" not in spec:
            continue
        lines += ["", f"## {name}", "", spec.get("description", ""), ""]
        lines += _table(spec["properties"], spec.get("required", ()))
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    PAGE.write_text(page())
    print(f"wrote {PAGE}")
