"""Where gearcli keeps its disk caches (the llvm kernels' machine code, solution schedules):
``$GEARCLI_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/gearcli`` or ``~/.cache/gearcli``."""
from __future__ import annotations

import os
from pathlib import Path


def cache_root() -> Path:
    """The root folder of gearcli's disk caches (not created here)."""
    root = os.environ.get("GEARCLI_CACHE_DIR")
    if not root:
        xdg = os.environ.get("XDG_CACHE_HOME")
        root = os.path.join(xdg, "gearcli") if xdg else os.path.join(os.path.expanduser("~"), ".cache", "gearcli")
    return Path(root)
