"""The Python examples of these pages run as tests (Sybil): ``python -m pytest`` collects the
```python blocks of every page, in the repository's root folder (the pages' paths)."""
from __future__ import annotations

import os
from pathlib import Path

from sybil import Sybil
from sybil.parsers.markdown import PythonCodeBlockParser

ROOT = Path(__file__).resolve().parents[1]


def _at_root(namespace):
    namespace["_cwd"] = os.getcwd()
    os.chdir(ROOT)


def _back(namespace):
    os.chdir(namespace.pop("_cwd"))


pytest_collect_file = Sybil(parsers=[PythonCodeBlockParser()], patterns=["*.md"], setup=_at_root,
                            teardown=_back).pytest()
