"""Input and output files: mechanism files (YAML, URDF), trajectories, output files.

:func:`load_mechanism` is the one entry point for mechanism files; it picks the reader by
the file's extension (``.urdf``/``.xml``: URDF, anything else: YAML).
"""
from __future__ import annotations

from pathlib import Path

from ..model.mechanism import Mechanism
from .urdf_reader import load_urdf
from .yaml_reader import load_yaml


def load_mechanism(path: str | Path) -> Mechanism:
    """Read a mechanism from a YAML file or a URDF (``.urdf``/``.xml``) file.

    Raises :class:`~gearcli.errors.MechanismError` listing every problem found.
    """
    if Path(path).suffix.lower() in (".urdf", ".xml"):
        return load_urdf(path)
    return load_yaml(path)


__all__ = ["load_mechanism"]
