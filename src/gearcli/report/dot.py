"""Graphviz DOT drawings of a mechanism's graph (paper Figs. 2 and 6).

Vertices are links: the base is a grey box, primary links (the equivalent open-loop
chain) double circles, secondary links plain circles.  Thin edges (revolute joints) are thin
solid arrows parent -> child labelled by their axis label; heavy edges (gear pairs) are drawn
with ``penwidth=4`` and no arrow head, labelled by the pair name.  Links of one level share
a rank, so the drawing reads top-down from the root like the paper's canonical graphs.

Only geometry-free topology is drawn: no lengths or angles appear in the output.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    from ..analysis.graph import Analysis

HEAVY_PENWIDTH = 4


def quote(text: str) -> str:
    """A DOT double-quoted ID (backslashes and quotes escaped)."""
    return '"' + str(text).replace("\\", "\\\\").replace('"', '\\"') + '"'


def _attrs(**kw) -> str:
    return "[" + ", ".join(f"{k}={v if isinstance(v, (int, float)) else quote(v)}" for k, v in kw.items()) + "]"


def _vertex_lines(an: Analysis) -> list[str]:
    """One DOT statement per link: base box, primary double circle, secondary circle."""
    prim = set(an.primary)
    out = []
    for i, name in enumerate(an.names):
        if i == an.tree.base:
            attrs = _attrs(shape="box", style="filled", fillcolor="lightgrey", xlabel="base")
        elif i in prim:
            attrs = _attrs(shape="doublecircle")
        else:
            attrs = _attrs(shape="circle")
        out.append(f"  {quote(name)} {attrs};")
    return out


def _rank_lines(an: Analysis) -> list[str]:
    """``rank=same`` groups: links of one level side by side."""
    by_level: dict[int, list[str]] = {}
    for i, name in enumerate(an.names):
        by_level.setdefault(an.level[i], []).append(name)
    return ["  {rank=same; " + " ".join(quote(n) + ";" for n in names) + "}"
            for _, names in sorted(by_level.items())]


def _thin_lines(an: Analysis, real: bool) -> list[str]:
    """Thin edges: canonical (carrier -> link) or, with ``real``, the real joints."""
    n = an.names
    out = []
    if real:
        for jt in an.mech.joints:
            lab = an.label[an.tree.index[jt.child]]
            out.append(f"  {quote(jt.parent)} -> {quote(jt.child)} "
                       f"{_attrs(label=f'{lab} ({jt.name}){_SLIDES[jt.type]}', penwidth=1)};")
        return out
    for i in an.tree.moving:
        kind = an.mech.joints[an.tree.parent_joint[i]].type
        out.append(f"  {quote(n[an.canonical_parent[i]])} -> {quote(n[i])} "
                   f"{_attrs(label=an.label[i] + _SLIDES[kind], penwidth=1)};")
    return out


_SLIDES = {"revolute": "", "prismatic": " (prismatic)"}


def _heavy_lines(an: Analysis) -> list[str]:
    """Heavy edges: one per gear pair with a fundamental circuit."""
    n = an.names
    out = []
    for c in an.circuits:
        name = an.mech.gears[c.gear].name
        out.append(f"  {quote(n[c.j])} -> {quote(n[c.k])} "
                   f"{_attrs(label=name, penwidth=HEAVY_PENWIDTH, dir='none', style='bold', constraint='false')};")
    return out


def to_dot(an: Analysis, real: bool = False) -> str:
    """DOT source of the canonical graph of ``an`` (the real joint graph with ``real``).

    Rendering, e.g.: ``gearcli graph MECH --dot | dot -Tsvg > graph.svg``.
    """
    title = f"{an.mech.name}: {'graph of the real joints' if real else 'canonical graph'}"
    lines = [
        f"digraph {quote(an.mech.name)} {{",
        f"  graph {_attrs(label=title, labelloc='t', rankdir='TB')};",
        f"  node {_attrs(fontname='Helvetica')};",
        f"  edge {_attrs(fontname='Helvetica', fontsize=10)};",
        "  // vertices: links (box = base, double circle = primary, circle = secondary)",
        *_vertex_lines(an),
    ]
    if not real:
        lines += ["  // levels (thin-edge distance from the root)", *_rank_lines(an)]
    lines += ["  // thin edges: joints, labelled by axis (prismatic ones marked)", *_thin_lines(an, real),
              "  // heavy edges: gear pairs", *_heavy_lines(an), "}"]
    return "\n".join(lines) + "\n"
