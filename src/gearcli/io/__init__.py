"""Input and output files: mechanism files (YAML, URDF), trajectories, output files.

:func:`load_mechanism` is the one entry point for mechanism files; it picks the reader by
the file's extension (``.urdf``/``.xml``: URDF, anything else: YAML), importing only that
reader (the URDF one imports lxml).
"""
from __future__ import annotations

from pathlib import Path

from ..model.mechanism import Mechanism


def load_mechanism(path: str | Path) -> Mechanism:
    """Read a mechanism from a YAML file or a URDF (``.urdf``/``.xml``) file.

    Raises :class:`~gearcli.errors.MechanismError` listing every problem found.
    """
    if Path(path).suffix.lower() in (".urdf", ".xml"):
        from .urdf_reader import load_urdf  # noqa: PLC0415  (lxml: only for URDF files)

        return load_urdf(path)
    from .yaml_reader import load_yaml  # noqa: PLC0415

    return load_yaml(path)


__all__ = ["load_mechanism"]
