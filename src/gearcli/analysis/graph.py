"""Graph analysis of a geared mechanism (paper: "Graph Representation" and "Kinematics").

Links are vertices, joints thin edges labelled by their axis line, gear pairs heavy edges.
:func:`analyse` derives, once per mechanism, everything the solver needs:

* the canonical graph (Tsai 1988): a link hanging from its parent through a joint collinear
  with the parent's own joint is re-attached to the grandparent, until every thin-edged path
  from the root has distinct axis labels; the canonical parent is the link's *carrier*;
* levels (thin-edge distance from the root), primary links (the equivalent open-loop
  chain, EOLC, base -> end-effector) and secondary links;
* coaxial groups (a carrier and the links turning about one line relative to it), the
  carrier and fundamental circuit of each gear pair, transmission lines;
* the linear map q = S q_ind from the independent (EOLC) joint angles to every real joint
  angle, and the structure matrix A (input rotations = A^T q_ind, paper Eq. 22);
* the solution schedule (:mod:`gearcli.analysis.schedule`).

Problems are reported with the file and YAML path of the offending element.
"""
from __future__ import annotations

from dataclasses import replace

from ..errors import Collector
from ..model.mechanism import Mechanism
from .canonical import axis_labels, canonical_angle_rows, canonical_parents, coaxial_groups, eolc, levels
from .circuits import circuits as find_circuits
from .context import home_axes
from .coordinates import independent_coordinates
from .schedule import solution_schedule
from .structure import motors as find_motors
from .structure import structure_matrix, transmission_lines
from .tree import build_tree
from .types import Analysis, Circuit, CoaxialGroup, TOL_LINE

__all__ = ["Analysis", "Circuit", "CoaxialGroup", "TOL_LINE", "analyse"]


def analyse(mech: Mechanism) -> Analysis:
    """Canonical graph, levels, circuits, structure matrix and schedule of ``mech``.

    The steps follow the paper's graph analysis, one private function each; problems are
    collected in a :class:`~gearcli.errors.Collector` and raised after each step that
    later steps depend on.  Raises :class:`~gearcli.errors.MechanismError` listing every
    structural problem.
    """
    col = Collector(mech.source, mech.lines)
    tree = build_tree(mech, col)
    col.raise_if_any()
    h = home_axes(mech, tree)
    cparent = canonical_parents(h)
    primary = eolc(h, cparent)
    label = axis_labels(h, set(primary[1:]), col)
    level = levels(h, cparent)
    canon = canonical_angle_rows(h, cparent)
    groups = coaxial_groups(h, cparent, label)
    if len(primary) < 2:
        col.add("end_effector", "the end-effector must be a moving link, not the base")
        col.raise_if_any()
    circuits = find_circuits(h, groups, canon, col)
    col.raise_if_any()
    ind = independent_coordinates(h, cparent, canon, primary, circuits, col)
    mot = find_motors(h, cparent, groups, canon, ind.S.shape[1], col)
    A = structure_matrix(mot.rows, ind.S, col)
    tlines, pseudo = transmission_lines(h, circuits, ind.primary, ind.chain, mot.links)

    an = Analysis(mech, tree, tuple(cparent), tuple(label), tuple(level), tuple(ind.primary),
                  ind.independent, ind.independent_names, tuple(groups), tuple(circuits),
                  ind.S, tuple(mot.links), tuple(mot.stators), A, tuple(tlines), pseudo,
                  motor_joints=tuple(mot.joints) if any(x is not None for x in mot.joints) else (),
                  open_loop=ind.open_loop, redundant=ind.redundant)
    blocks = solution_schedule(an, col)
    col.raise_if_any()
    return replace(an, schedule=blocks)
