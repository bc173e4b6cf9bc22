"""Write docs/reference/mechanism.md, design-manifest.md and catalogue.md from
schemas/mechanism.schema.json, design.schema.json and catalogue.schema.json: each schema is
the one source of its file's keys (tests/test_docs.py fails when a page differs).

    python docs/gen_reference.py
"""
from __future__ import annotations

import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGES = {   # kind: (schema, page, title)
    "mechanism": ("mechanism.schema.json", "mechanism.md", "Mechanism file (YAML)"),
    "design": ("design.schema.json", "design-manifest.md", "Design manifest (YAML, gearcli verify)"),
    "catalogue": ("catalogue.schema.json", "catalogue.md", "Parts catalogue (CSV, gearcli select)"),
}


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


def _inline(spec: dict) -> list[dict]:
    """The inline object schemas of a property (itself, its items, its oneOf/anyOf branches,
    its if/then/else), whose keys the table lists under the property's dotted name."""
    found = []
    if "properties" in spec:
        found.append(spec)
    for k in ("items", "then", "else"):
        if isinstance(spec.get(k), dict):
            found += _inline(spec[k])
    for k in ("oneOf", "anyOf"):
        for branch in spec.get(k, []):
            found += _inline(branch)
    return found


def _rows(props: dict, required=(), prefix: str = "") -> list[str]:
    out = []
    for key, spec in props.items():
        name = f"`{prefix}{key}`" + (" (required)" if key in required else "")
        out.append(f"| {name} | {_cell(_type(spec))} | {_cell(spec.get('description', ''))} |")
        seen = set()
        for sub in _inline(spec):
            props_new = {k: v for k, v in sub["properties"].items() if k not in seen}
            seen |= set(props_new)
            out += _rows(props_new, sub.get("required", ()), f"{prefix}{key}.")
    return out


def _table(props: dict, required=()) -> list[str]:
    """The keys of ``props`` (an object's properties) with their type and description; the keys
    of an inline object (a rating, an inertia given as a mapping) follow their parent's row
    under a dotted name (``rating.rated_torque``)."""
    return ["| key | type | description |", "|---|---|---|"] + _rows(props, required)


def page(kind: str = "mechanism") -> str:
    schema_name, _, title = PAGES[kind]
    schema = json.loads((ROOT / "schemas" / schema_name).read_text())
    lines = [f"# {title}", "",
             f"Generated from `schemas/{schema_name}` by `docs/gen_reference.py`: the schema is",
             "the one source of these keys (a test fails when this page differs from it). SI units.", "",
             schema.get("description", ""), "", "## Top level", ""]
    lines += _table(schema["properties"], schema.get("required", ()))
    extra = schema.get("additionalProperties")
    if isinstance(extra, dict):         # a catalogue's free columns
        lines.append(f"| (any other column) | {_cell(_type(extra))} | {_cell(extra.get('description', ''))} |")
    for name, spec in schema.get("$defs", {}).items():
        if "properties" not in spec:
            continue
        lines += ["", f"## {name}", "", spec.get("description", ""), ""]
        lines += _table(spec["properties"], spec.get("required", ()))
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    for kind, (_, name, _) in PAGES.items():
        path = ROOT / "docs" / "reference" / name
        path.write_text(page(kind))
        print(f"wrote {path}")
