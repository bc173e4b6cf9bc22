"""The JSON Schemas shipped with gearcli (``schemas/*.schema.json``)."""
from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources
from pathlib import Path


@lru_cache(maxsize=None)
def packaged_schema(filename: str) -> dict:
    """The schema ``schemas/<filename>``: from the installed package, else from the source tree."""
    try:
        text = resources.files("gearcli").joinpath(f"schemas/{filename}").read_text()
    except (FileNotFoundError, ModuleNotFoundError, OSError):
        text = (Path(__file__).resolve().parents[3] / "schemas" / filename).read_text()
    return json.loads(text)
