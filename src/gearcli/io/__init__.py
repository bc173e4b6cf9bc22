"""Input and output files: mechanism files (YAML, URDF), trajectories, output files.

:func:`load_mechanism` is the one entry point for mechanism files; it picks the reader by
the file's extension (``.urdf``/``.xml``: URDF, anything else: YAML; XML under another name
is refused as such), importing only that reader (the URDF one imports lxml).
"""
from __future__ import annotations

from pathlib import Path

from ..errors import Issue, MechanismError
from ..model.mechanism import Mechanism
from .limits import open_regular

URDF_SUFFIXES = (".urdf", ".xml")
"""Extensions (any case) of the mechanism files read as URDF; every other name is YAML."""


def load_mechanism(path: str | Path) -> Mechanism:
    """Read a mechanism from a YAML file or a URDF (``.urdf``/``.xml``) file.

    Raises :class:`~gearcli.errors.MechanismError` listing every problem found.
    """
    if Path(path).suffix.lower() in URDF_SUFFIXES:
        from .urdf_reader import load_urdf  # noqa: PLC0415  (lxml: only for URDF files)

        return load_urdf(path)
    from .yaml_reader import load_yaml  # noqa: PLC0415

    try:
        return load_yaml(path)
    except MechanismError:
        if _looks_like_xml(path):     # a URDF or xacro file under another name: say so
            raise MechanismError([Issue(str(path), "", 1, "this is XML, not YAML: a URDF is read from a file "
                                        "named .urdf or .xml (expand a xacro file first)")]) from None
        raise


def _looks_like_xml(path) -> bool:
    try:
        with open_regular(path) as f:     # a FIFO is refused, not waited on
            head = f.read(256).lstrip(b"\xef\xbb\xbf \t\r\n")
    except (OSError, MechanismError):
        return False
    return head[:1] == b"<" and (head[1:2].isalpha() or head[1:2] in (b"?", b"!"))


__all__ = ["URDF_SUFFIXES", "load_mechanism"]
