"""JSON-Schema violations in gearcli's words.

jsonschema says ``[-0.2, 0] is too short`` or ``datetime.date(2024, 1, 1) is not of type
'number'``; :func:`schema_messages` says ``expected 3 numbers, got 2`` and ``expected a
number, got a date (2024-01-01)``.  :data:`WORDING` maps each validator keyword the schemas
(``schemas/*.schema.json``) use to the function that words its errors; a value is
described by its kind and as written in YAML (:func:`described`), never as a Python repr.
"""
from __future__ import annotations

import datetime as dt
import difflib

from ..errors import capped, counted

TYPE_NAMES = {"number": "a number", "integer": "a whole number", "string": "a string", "array": "a list",
              "object": "a mapping", "boolean": "true or false", "null": "an empty value"}
"""What a schema ``type`` asks for, in words."""

ITEM_NOUNS = {"number": "number", "integer": "whole number", "string": "name"}
"""What the items of a list are called in ``expected 3 numbers, got 4`` (by the items' type)."""

PATTERNS = {r"^[^:,\s]+$": "a name without spaces, colons or commas",
            r"^[^\x00-\x1f\x7f]+$": "a name without control characters",
            r"^[^\s\x00-\x1f\x7f]+$": "one word without control characters"}
"""What a schema ``pattern`` asks for, in words."""

BOUNDS = {"minimum": "at least", "exclusiveMinimum": "more than", "maximum": "at most",
          "exclusiveMaximum": "less than"}


def shown(text: str, limit: int = 60) -> str:
    """``text`` quoted, cut to ``limit`` characters, control characters escaped (``\\n``)."""
    text = "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text[:limit + 1])
    return f"'{capped(text, limit)}'"


def number(x) -> str:
    """A number as YAML writes it (``true`` is not one)."""
    return str(x)


def described(value) -> str:
    """A value's kind and the value as written in YAML: ``a date (2024-01-01)``, ``a string
    ('heavy')``, ``a list of 4 items``, ``an empty value`` (``mass:`` or ``null``)."""
    if value is None:
        return "an empty value"
    if isinstance(value, bool):
        return f"a boolean ({str(value).lower()})"
    if isinstance(value, (int, float)):
        return f"a number ({number(value)})"
    if isinstance(value, str):
        return f"a string ({shown(value)})" if value else "an empty string"
    if isinstance(value, dt.datetime):
        return f"a date and time ({value.isoformat(sep=' ')})"
    if isinstance(value, dt.date):
        return f"a date ({value.isoformat()})"
    if isinstance(value, list):
        return f"a list of {counted(len(value), 'item')}" if value else "an empty list"
    if isinstance(value, dict):
        keys = ", ".join(shown(str(k), 20) for k in list(value)[:5]) + (", …" if len(value) > 5 else "")
        return f"a mapping (keys: {keys})" if value else "an empty mapping"
    if isinstance(value, bytes):
        return f"binary data ({counted(len(value), 'byte')})"
    return f"a YAML {type(value).__name__}"        # !!set, !!omap items


def _type(err) -> str:
    want = err.validator_value if isinstance(err.validator_value, list) else [err.validator_value]
    if want == ["integer"] and isinstance(err.instance, float):
        return f"expected a whole number, got {number(err.instance)}"
    return f"expected {' or '.join(TYPE_NAMES.get(t, t) for t in want)}, got {described(err.instance)}"


def _length(err) -> str:
    """minItems, maxItems: ``expected 3 numbers, got 4``, ``expected at least 2 items, got 1``."""
    lo, hi = err.schema.get("minItems"), err.schema.get("maxItems")
    items = err.schema.get("items")
    noun = ITEM_NOUNS.get(items.get("type"), "item") if isinstance(items, dict) else "item"
    got = len(err.instance) if err.instance else "none"
    if lo == hi:
        return f"expected {counted(lo, noun)}, got {got}"
    if err.validator == "minItems":
        return f"expected at least {counted(lo, noun)}, got {got}"
    return f"expected at most {counted(hi, noun)}, got {got}"


def _enum(err) -> str:
    allowed = [str(v) for v in err.validator_value]
    got = shown(err.instance) if isinstance(err.instance, str) else described(err.instance)
    close = difflib.get_close_matches(err.instance, allowed, n=1) if isinstance(err.instance, str) else []
    return f"expected one of: {', '.join(allowed)}; got {got}" + (f" (did you mean '{close[0]}'?)" if close else "")


def _bound(err) -> str:
    return f"expected {BOUNDS[err.validator]} {number(err.validator_value)}, got {number(err.instance)}"


def _min_length(err) -> str:
    return "must not be empty"


def _min_properties(err) -> str:
    """minProperties (a select slot's set, add, match, at_least, at_most: at least one column)."""
    return "must not be empty (give at least one column)"


def _pattern(err) -> str | None:
    if err.instance == "" and err.schema.get("minLength"):
        return None                                 # said by minLength
    want = PATTERNS.get(err.validator_value, f"a string of the form {err.validator_value}")
    return f"expected {want}, got {shown(err.instance)}"


def _alternatives(err) -> str:
    """oneOf, anyOf (after :func:`schema_messages` found no single fitting branch)."""
    branches = [b for b in err.validator_value if isinstance(b, dict)]
    keys = [b["required"][0] for b in branches if list(b) == ["required"] and len(b["required"]) == 1]
    if keys and len(keys) == len(branches):        # one key of several
        given = [k for k in keys if isinstance(err.instance, dict) and k in err.instance]
        if err.validator == "anyOf":
            return f"give at least one of: {', '.join(keys)}"
        if given:
            return f"give only one of: {', '.join(keys)} (got {' and '.join(given)})"
        return f"give one of: {', '.join(keys)}"
    types = [t for b in branches for t in ([b["type"]] if isinstance(b.get("type"), str) else b.get("type", []))]
    if types:
        return f"expected {' or '.join(TYPE_NAMES.get(t, t) for t in types)}, got {described(err.instance)}"
    return f"{described(err.instance)} fits none of the forms allowed here"


WORDING = {"type": _type, "minItems": _length, "maxItems": _length, "enum": _enum, "minimum": _bound,
           "maximum": _bound, "exclusiveMinimum": _bound, "exclusiveMaximum": _bound, "minLength": _min_length,
           "pattern": _pattern, "oneOf": _alternatives, "anyOf": _alternatives, "minProperties": _min_properties}
"""Validator keyword -> its message (``required``, ``additionalProperties`` and the
branches of ``oneOf`` are worded in :func:`schema_messages`, which knows the paths)."""

STRUCTURAL = {"$schema", "$id", "$defs", "$ref", "title", "description", "properties", "items", "if", "then", "else"}
"""Keywords that never fail by themselves (their subschemas' errors are worded)."""


def schema_messages(err) -> list[tuple[list, str]]:
    """(path parts, message) pairs for one jsonschema error, in gearcli's words: an unknown
    key is reported at its own path (with a close match), a missing key by name, a oneOf by
    the branch whose type fits the value, everything else by :data:`WORDING`."""
    path = list(err.absolute_path)
    if err.validator == "additionalProperties" and isinstance(err.instance, dict):
        allowed = list(err.schema.get("properties", {}))
        out = []
        for key in (k for k in err.instance if k not in allowed):
            close = difflib.get_close_matches(str(key), allowed, n=1)
            hint = f"did you mean '{close[0]}'?" if close else f"allowed: {', '.join(allowed)}"
            out.append((path + [key], f"unknown key '{key}' ({hint})"))
        return out
    if err.validator == "required" and isinstance(err.instance, dict):
        # jsonschema gives one error per missing key, naming it only in its message
        missing = [r for r in err.validator_value if r not in err.instance]
        named = [r for r in missing if repr(r) in err.message] or missing
        return [(path, f"missing required key '{r}'") for r in named[:1]]
    if err.validator == "maxItems" and path and path[-1] == "bearings" and isinstance(err.instance, list):
        return [(path, f"a joint has one or two bearings, got {len(err.instance)}")]   # as in URDF files
    if err.validator == "oneOf" and err.context:
        branches: dict = {}
        for e in err.context:
            branches.setdefault(e.relative_schema_path[0], []).append(e)
        fitting = [b for b in branches.values()
                   if not any(e.validator == "type" and list(e.absolute_path) == path for e in b)]
        if len(fitting) == 1:
            return [m for e in fitting[0] for m in schema_messages(e)]
    words = WORDING.get(err.validator)
    message = words(err) if words else f"not allowed by the schema (rule {err.validator}: {err.validator_value})"
    return [] if message is None else [(path, message)]
