"""Reading an input file whole, within a size limit (every reader goes through here)."""
from __future__ import annotations

from pathlib import Path

from ..errors import Issue, MechanismError

MAX_BYTES = 16 * 2**20
"""Largest mechanism file read (16 MiB: a 100,000-line file is a few MiB)."""


def read_bytes(path: str | Path, kind: str = "mechanism file") -> bytes:
    """The bytes of ``path``; raises :class:`~gearcli.errors.MechanismError` (one line)
    when the file cannot be read or is larger than :data:`MAX_BYTES`."""
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_BYTES + 1)
    except OSError as exc:
        raise MechanismError([Issue(str(path), "", None, f"cannot read file: {exc.strerror}")]) from None
    if len(data) > MAX_BYTES:
        raise MechanismError([Issue(str(path), "", None, f"file is larger than {MAX_BYTES // 2**20} MiB, "
                                    f"the limit for a {kind}")])
    return data
