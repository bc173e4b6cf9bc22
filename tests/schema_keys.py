"""Every key a JSON Schema defines (properties, $defs, oneOf branches), for the reference pages' checks."""
from __future__ import annotations


def schema_keys(node: dict):
    """Yield every property name of ``node`` and of the schemas nested in it."""
    for k, v in node.get("properties", {}).items():
        yield k
        yield from schema_keys(v)
    for v in node.get("$defs", {}).values():
        yield from schema_keys(v)
    for v in node.get("oneOf", []):
        yield from schema_keys(v)
