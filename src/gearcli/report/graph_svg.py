"""The canonical graph of an analysed mechanism as an inline SVG (the HTML design report):
links placed by level (the paper's levels, base on the left), thin edges to their canonical
parents labelled with their axis, heavy edges (gear pairs and drive elements) drawn bold and
dashed between their two members, labelled with the pair's name.  No layout library: a
column per level, the links of a level stacked in id order."""
from __future__ import annotations

import html

W, H, PAD = 150, 46, 30       # px between levels, between links of a level, the margin


def graph_svg(an) -> str:
    """The SVG (a string) of ``an``'s canonical graph."""
    names, level = an.names, an.level
    by_level: dict = {}
    for i in range(len(names)):
        by_level.setdefault(level[i], []).append(i)
    pos = {i: (PAD + W * lv, PAD + H * k) for lv, ids in by_level.items() for k, i in enumerate(ids)}
    width = PAD * 2 + W * max(by_level) + 110
    height = PAD * 2 + H * max(len(v) for v in by_level.values())
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" '
             f'font-size="11">']
    for i in an.tree.moving:
        p = an.canonical_parent[i]
        if p is None:
            continue
        (x1, y1), (x2, y2) = pos[p], pos[i]
        parts.append(f'<line x1="{x1}" y1="{y1}" x2="{x2}" y2="{y2}" stroke="#555" stroke-width="1.2"/>')
        parts.append(f'<text x="{(x1 + x2) / 2 + 3}" y="{(y1 + y2) / 2 - 3}" fill="#555">{html.escape(str(an.label[i]))}</text>')
    for c in an.circuits:
        (x1, y1), (x2, y2) = pos[c.j], pos[c.k]
        name = an.mech.gears[c.gear].name
        parts.append(f'<line x1="{x1}" y1="{y1}" x2="{x2}" y2="{y2}" stroke="#b05000" stroke-width="3.5" '
                     f'stroke-dasharray="6,3"/>')
        parts.append(f'<text x="{(x1 + x2) / 2 + 4}" y="{(y1 + y2) / 2 + 12}" fill="#b05000">{html.escape(name)}</text>')
    for i, (x, y) in pos.items():
        primary = i in set(an.primary)
        parts.append(f'<circle cx="{x}" cy="{y}" r="6" fill="{"#2d6cdf" if primary else "#fff"}" stroke="#2d6cdf"/>')
        parts.append(f'<text x="{x + 9}" y="{y + 4}">{html.escape(names[i])}</text>')
    parts.append("</svg>")
    return "".join(parts)
