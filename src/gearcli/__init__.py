"""gearcli: dynamics of geared robotic mechanisms (SI units: m, kg, kg*m^2, rad, N, N*m).

Public API::

    from gearcli import load_mechanism, analyse
    an = analyse(load_mechanism("mechanisms/paper_2dof.yaml"))
    an.dof, an.A, an.schedule

Names are imported lazily (PEP 562) so that ``import gearcli`` stays cheap and no
submodule import can become circular.  To export a new name, add it to ``_EXPORTS``.
"""
from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING

__version__ = "0.1.0"

# public name -> submodule defining it
_EXPORTS = {
    "load_mechanism": "io",
    "parse_mechanism": "io.yaml_reader",
    "analyse": "pipeline",
    "solve": "dynamics.solve",
    "Solver": "dynamics.forward",
    "Result": "dynamics.solve",
    "mass_matrix": "dynamics.forward",
    "forward_dynamics": "dynamics.forward",
    "motor_inertia": "dynamics.forward",
    "solve_file": "pipeline",
    "named_columns": "report.columns",
    "read_trajectory": "io.trajectory",
    "Analysis": "analysis.graph",
    "Mechanism": "model.mechanism",
    "MechanismError": "errors",
    "GearcliError": "errors",
}

__all__ = ["__version__", *_EXPORTS]

if TYPE_CHECKING:  # pragma: no cover
    from .analysis.graph import Analysis
    from .dynamics.forward import Solver, forward_dynamics, mass_matrix, motor_inertia
    from .dynamics.solve import Result, solve
    from .errors import GearcliError, MechanismError
    from .io import load_mechanism
    from .io.trajectory import read_trajectory
    from .io.yaml_reader import parse_mechanism
    from .model.mechanism import Mechanism
    from .pipeline import analyse, solve_file
    from .report.columns import named_columns


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'gearcli' has no attribute {name!r}")
    value = getattr(import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
