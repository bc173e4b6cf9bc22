"""``gearcli select``: choose parts from catalogues so that a design passes every check.

A design manifest's ``slots`` name the parts to choose: each slot has a catalogue (a CSV file,
one part a row, :func:`read_catalogue`) and maps some of its columns onto numbers of the
cases' mechanism files, in ``gearcli sweep``'s path terms: ``set`` replaces the file's value
(a motor's ratings, a reducer's rated torque), ``add`` adds to it (the part's mass to the
link that carries it, its inertia to the link it turns with).  Every combination of one part
per slot is a variant of the mechanism files, verified as ``gearcli verify`` verifies them,
each with its own loads: a heavier part on an outer joint raises the loads on the inner
ones, and the combination is judged on those (the exhaustive search needs no iteration
between choosing and solving, and so cannot cycle).  The feasible combinations (every check
passes) are ranked by the objective, the sum of the chosen parts' ``mass``, ``cost`` or
``inertia`` column; when none is feasible, the closest ones (largest worst margin) say which
checks fail them.
"""
from __future__ import annotations

import csv
import itertools
import math
from dataclasses import dataclass
from pathlib import Path

from ..errors import GearcliError, MechanismError
from .sweep import Plan, Vary, file_data, locate, path_steps, save_figure, variant_data

MAX_COMBINATIONS = 100_000
"""More combinations than this are refused by the exhaustive search (narrow the catalogues)."""

EXHAUSTIVE_LIMIT = 2_000
"""--search auto verifies every combination up to this many, else searches iteratively."""

OBJECTIVES = ("mass", "cost", "inertia")


@dataclass(frozen=True)
class Part:
    """One catalogue row: its ``name``, ``source``, numbers by column and CSV line."""

    name: str
    source: str
    values: dict
    line: int


@dataclass(frozen=True)
class Slot:
    name: str
    catalogue: Path
    parts: tuple[Part, ...]
    ops: tuple[tuple[str, str, str], ...]     # (catalogue column, mechanism path, "set" | "add")


def read_catalogue(path: Path) -> tuple[Part, ...]:
    """The parts of a catalogue CSV (schemas/catalogue.schema.json per row): a GearcliError
    naming the file, the line and the column of the first problem."""
    from ..io.schemas import packaged_schema  # noqa: PLC0415
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise GearcliError(f"{path}: cannot read the catalogue: {getattr(exc, 'strerror', None) or exc}") from None
    rows = list(csv.reader(text.splitlines()))
    if not rows or not any(c.strip() for c in rows[0]):
        raise GearcliError(f"{path}:1: an empty catalogue (expected a header with name, source and number columns)")
    header = [c.strip() for c in rows[0]]
    for k, c in enumerate(header):
        if not c:
            raise GearcliError(f"{path}:1: column {k + 1} has no name")
        if header.index(c) != k:
            raise GearcliError(f"{path}:1: column '{c}' twice")
    for need in ("name", "source"):
        if need not in header:
            raise GearcliError(f"{path}:1: no '{need}' column (a part's designation and where its numbers come from)")
    schema = packaged_schema("catalogue.schema.json")
    parts, names = [], {}
    for line, row in enumerate(rows[1:], start=2):
        if not any(c.strip() for c in row):
            continue
        if len(row) != len(header):
            raise GearcliError(f"{path}:{line}: {len(row)} cells, the header has {len(header)}")
        values = {}
        for c, cell in zip(header, row):
            cell = cell.strip()
            if c in ("name", "source"):
                if not cell:
                    raise GearcliError(f"{path}:{line}: column '{c}': empty (every part needs its {c})")
                continue
            try:
                x = float(cell)
            except ValueError:
                raise GearcliError(f"{path}:{line}: column '{c}': expected a number (SI units), got '{cell}'") from None
            if not math.isfinite(x):
                raise GearcliError(f"{path}:{line}: column '{c}': expected a finite number, got '{cell}'")
            minimum = schema["properties"].get(c, {}).get("minimum")
            if minimum is not None and x < minimum:
                raise GearcliError(f"{path}:{line}: column '{c}': expected at least {minimum:g}, got {x:g}")
            values[c] = x
        name, source = row[header.index("name")].strip(), row[header.index("source")].strip()
        if name in names:
            raise GearcliError(f"{path}:{line}: part '{name}' twice (first on line {names[name]})")
        names[name] = line
        parts.append(Part(name, source, values, line))
    if not parts:
        raise GearcliError(f"{path}: no parts (a header and no rows)")
    return tuple(parts)


def _where(manifest, key: str) -> str:
    line = manifest.lines.get(key)
    return f"{manifest.path}:{line}: {key}" if line else f"{manifest.path}: {key}"


def _admitted(manifest, i: int, spec: dict, path: Path, parts: tuple[Part, ...]) -> tuple[Part, ...]:
    """The parts of a slot's catalogue that meet its ``match``, ``at_least`` and ``at_most``
    (necessary conditions: a bore, a peak torque); a located error when a column is missing
    or no part is left."""
    tests = {"match": lambda x, v: abs(x - v) <= 1e-9 * max(abs(v), 1e-300),
             "at_least": lambda x, v: x >= v, "at_most": lambda x, v: x <= v}
    for kind, test in tests.items():
        for column, v in spec.get(kind, {}).items():
            where = _where(manifest, f"slots[{i}].{kind}.{column}")
            if any(column not in p.values for p in parts):
                raise GearcliError(f"{where}: the catalogue {path} has no number column '{column}'")
            parts = tuple(p for p in parts if test(p.values[column], v))
            if not parts:
                raise GearcliError(f"{where}: no part of {path} has {column} "
                                   f"{ {'match': '=', 'at_least': '>=', 'at_most': '<='}[kind]} {v:g} "
                                   f"(with the slot's other conditions before it)")
    return parts


def slots_of(manifest) -> tuple[Slot, ...]:
    """The manifest's slots with their catalogues read and every mapping checked against the
    catalogue (the column exists) and each case's mechanism (the path names a number)."""
    if not manifest.slots:
        raise GearcliError(f"{manifest.path}: no slots (select needs `slots:`, the parts to choose; "
                           f"docs/how-to/select.md)")
    slots, seen, targets = [], {}, {}      # targets: path -> (mode, where) of its first mapping
    for i, spec in enumerate(manifest.slots):
        name = spec["name"]
        if name in seen:
            raise GearcliError(f"{_where(manifest, f'slots[{i}].name')}: duplicate slot name '{name}' (first at {seen[name]})")
        seen[name] = f"slots[{i}]"
        path = (manifest.path.parent / spec["catalogue"])
        parts = _admitted(manifest, i, spec, path, read_catalogue(path))
        ops = []
        for mode in ("set", "add"):
            for column, given in spec.get(mode, {}).items():
                where = _where(manifest, f"slots[{i}].{mode}.{column}")
                missing = [p for p in parts if column not in p.values]
                if missing:
                    raise GearcliError(f"{where}: the catalogue {path} has no number column '{column}'")
                paths = [given] if isinstance(given, str) else given
                for target in paths:
                    _once(targets, target, mode, where, paths.count(target) > 1)
                    ops.append(_op(manifest, where, column, target, mode))
        slots.append(Slot(name, path, parts, tuple(ops)))
    return tuple(slots)


def _once(targets: dict, target: str, mode: str, where: str, repeated: bool) -> None:
    """A located error when a path is mapped twice in a way whose outcome would depend on
    the order: listed twice for one column, set twice, or both set and added.  Added by
    several columns or slots is a sum (a motor's and a reducer's inertia on one rotor)."""
    if repeated:
        raise GearcliError(f"{where}: '{target}' is listed twice (each part's value would go to it twice)")
    first = targets.setdefault(target, (mode, where))
    if first[1] != where and "set" in (mode, first[0]):
        how = "set" if first[0] == "set" else "added to"
        raise GearcliError(f"{where}: '{target}' is also {how} by {first[1].split(': ')[-1]}: a value set "
                           f"and another set or added would depend on the slots' order")


def _op(manifest, where: str, column: str, target: str, mode: str) -> tuple[str, str, str]:
    """One mapping of a slot, (column, path, mode), once the path names a number of every
    case's mechanism file (a located error otherwise)."""
    try:
        steps = path_steps(target, where)
    except GearcliError as exc:
        raise GearcliError(str(exc)) from None
    for case in manifest.cases:
        if Path(case.mechanism).suffix.lower() not in (".yaml", ".yml"):
            raise GearcliError(f"{where}: case '{case.name}': select varies YAML mechanism files, "
                               f"{case.mechanism} is not one")
        try:
            locate(file_data(str(case.mechanism)), steps, target)
        except GearcliError as exc:
            raise GearcliError(f"{where}: case '{case.name}' ({case.mechanism}): {exc}") from None
    return (column, target, mode)


def prepare(manifest, slots: tuple[Slot, ...], objective: str) -> tuple[Vary, ...]:
    """The variations one combination makes (each slot's set/add columns), once every part
    has been tried alone (the others at the file's values): a part that makes the mechanism
    invalid, or lacks the objective's column, is a located error before anything runs."""
    from ..io.yaml_reader import mechanism_from_data  # noqa: PLC0415
    if objective not in OBJECTIVES:
        raise GearcliError(f"--objective: expected one of {', '.join(OBJECTIVES)}, got '{objective}'")
    for s in slots:
        lacking = [p for p in s.parts if objective not in p.values]
        if lacking:
            raise GearcliError(f"{s.catalogue}:{lacking[0].line}: part '{lacking[0].name}' has no '{objective}' "
                               f"(--objective {objective} sums it over the chosen parts)")
    varies = tuple(Vary(f"{s.name}.{column}", None, target, path_steps(target, target), (), mode)
                   for s in slots for column, target, mode in s.ops)
    for s in slots:
        for part in s.parts:
            alone = [v for v in varies if v.text.startswith(f"{s.name}.")]
            values = [part.values[v.text.split(".", 1)[1]] for v in alone]
            for case in manifest.cases:
                try:
                    mechanism_from_data(variant_data(manifest, alone, values)[case.name], str(case.mechanism))
                except MechanismError as exc:
                    i = exc.issues[0]
                    raise GearcliError(f"{s.catalogue}:{part.line}: part '{part.name}' in slot '{s.name}', case "
                                       f"'{case.name}': {i.path + ': ' if i.path else ''}{i.message}") from None
    return varies


def values_of_combo(slots, combo) -> tuple[float, ...]:
    """The numbers a combination (one part index per slot) sets or adds, in the order of
    :func:`prepare`'s variations."""
    return tuple(s.parts[k].values[column] for s, k in zip(slots, combo) for column, _, _ in s.ops)


def objective_of(slots, combo, objective: str) -> float:
    return sum(s.parts[k].values[objective] for s, k in zip(slots, combo))


def combinations(slots) -> list[tuple[int, ...]]:
    """Every combination of one part per slot (at most :data:`MAX_COMBINATIONS`)."""
    total = math.prod(len(s.parts) for s in slots)
    if total > MAX_COMBINATIONS:
        raise GearcliError(f"select: {total:,} combinations, more than {MAX_COMBINATIONS:,} to verify each: "
                           f"use --search iterate, or narrow the catalogues (match, at_least, at_most)")
    return list(itertools.product(*(range(len(s.parts)) for s in slots)))


def plan_of(manifest, varies, slots, combos) -> Plan:
    return Plan(str(manifest.path), varies, tuple(values_of_combo(slots, c) for c in combos))


def iterate(slots, objective: str, evaluate, max_rounds: int = 50) -> tuple[dict, tuple]:
    """Choose slot by slot and re-verify until the choice is stable: start from each slot's
    part of the largest ``objective`` (the most capable, as a rule), then, slot after slot,
    take the lightest part whose design (the other slots as chosen so far) passes every check,
    each candidate verified with its own loads (``evaluate(combos) -> results``).  Returns
    ({combination: result} of every one verified, the stable choice).

    Each candidate is judged on its own loads, not on loads solved for an earlier choice, so
    once the choice passes, the current one is always among the candidates: the total
    objective never rises and, ties going to the lower part index, the search cannot cycle;
    it ends on a choice that no change of one slot makes lighter (a local optimum; the
    exhaustive search finds the lightest).  While the choice fails (the most capable part of
    a slot can fail a check a smaller one passes: a large motor's speed), a slot none of whose
    parts makes it pass takes the part that most reduces the sum of the failing checks'
    margins, if any does."""
    current = [max(range(len(s.parts)), key=lambda k: s.parts[k].values[objective]) for s in slots]
    verified: dict = {}

    def passed(r) -> bool:
        return not isinstance(r, str) and all(c[7] for c in r)

    def shortfall(r) -> float:       # the margins by which checks fail, summed (<= 0)
        return -math.inf if isinstance(r, str) else sum(min(c[6], 0.0) for c in r)
    for _ in range(max_rounds):
        before = tuple(current)
        for j, s in enumerate(slots):
            combos = [tuple(current[:j] + [k] + current[j + 1:]) for k in range(len(s.parts))]
            todo = [c for c in combos if c not in verified]
            verified.update(zip(todo, evaluate(todo)))
            ok = [c for c in combos if passed(verified[c])]
            if ok:
                current[j] = min(ok, key=lambda c: (objective_of(slots, c, objective), c[j]))[j]
            else:
                # no part of this slot makes the choice pass: climb towards passing, taking the
                # part that most reduces the failing checks' summed shortfall, if any does (it
                # falls strictly while the choice fails, so this phase cannot cycle either); the
                # most capable parts can fail a check a smaller one passes (a large motor's speed)
                here = tuple(current)
                best = max(combos, key=lambda c: (shortfall(verified[c]), -c[j]))
                if shortfall(verified[best]) > shortfall(verified[here]):
                    current[j] = best[j]
        if tuple(current) == before:
            return verified, before
    raise GearcliError(f"select: the iterative search did not settle in {max_rounds} rounds")


INERTIA_RATIO = "inertia ratio"
"""The quantity of a motor's load-to-rotor inertia ratio check (:mod:`gearcli.design.sizing`)."""


@dataclass(frozen=True)
class Ranked:
    """A combination: its part indices, objective, worst margin (%) and check, whether every
    check passes, the checks that fail it, and the largest load-to-rotor inertia ratio of
    its motors (NaN without an inertia-ratio check)."""

    combo: tuple[int, ...]
    objective: float
    worst: float
    worst_check: str
    feasible: bool
    failing: tuple[str, ...]
    inertia_ratio: float = math.nan


def rank(combos, objectives, results) -> list[Ranked]:
    """Feasible combinations first, by objective (then the larger worst margin); then the
    others by their worst margin, largest first (the closest to passing)."""
    out = []
    for combo, obj, r in zip(combos, objectives, results):
        if isinstance(r, str):
            out.append(Ranked(combo, obj, -math.inf, f"not run: {r}", False, (r,)))
            continue
        w = min(range(len(r)), key=lambda j: (r[j][7], r[j][6]))
        failing = tuple(f"{c[0]}: {c[1]}: {c[2]} ({c[6]:.3g} %)" for c in r if not c[7])
        ratios = [c[4] for c in r if c[2] == INERTIA_RATIO]
        out.append(Ranked(combo, obj, r[w][6], f"{r[w][0]}: {r[w][1]}: {r[w][2]}", not failing, failing,
                          max(ratios) if ratios else math.nan))
    return sorted(out, key=lambda x: (not x.feasible, x.objective if x.feasible else 0.0, -x.worst))


def write_choice(manifest, slots, plan: Plan, ranked: Ranked, directory: Path) -> list[Path]:
    """The chosen design in ``directory``: each case's mechanism file with the chosen parts'
    values, and a manifest (the original's cases, trajectories by absolute path, no slots)
    that ``gearcli verify`` runs on it.  Returns the files written."""
    import yaml  # noqa: PLC0415

    from ..io.output import atomic_output  # noqa: PLC0415
    from ..io.yaml_safe import read_text, yaml_lines  # noqa: PLC0415
    values = [s.parts[k].values[column] for s, k in zip(slots, ranked.combo) for column, _, _ in s.ops]
    datas = variant_data(manifest, plan.varies, values)
    directory.mkdir(parents=True, exist_ok=True)
    written, mech_files = [], {}
    for case in manifest.cases:
        key = str(case.mechanism)
        if key not in mech_files:
            target = directory / Path(case.mechanism).name
            if target.resolve() == Path(case.mechanism).resolve():
                raise GearcliError(f"{directory}: would overwrite the mechanism file {case.mechanism}: choose another -o")
            with atomic_output(target, [case.mechanism, manifest.path]) as f:
                chosen = ", ".join(f"{s.name} = {s.parts[k].name} ({s.parts[k].source})" for s, k in zip(slots, ranked.combo))
                f.write(f"# Written by gearcli select from {case.mechanism}: {chosen}\n")
                f.write(yaml.safe_dump(datas[case.name], sort_keys=False))
            mech_files[key] = target
            written.append(target)
    data, _ = yaml_lines(read_text(manifest.path, "design manifest"), str(manifest.path))
    data.pop("slots", None)
    base = manifest.path.parent

    def absolute(item):       # a trajectory path or glob (or a mission profile's item) from anywhere
        if isinstance(item, dict):
            return {**item, "file": str((base / item["file"]).resolve())}
        return str((base / item).resolve())
    for spec, case in zip(data["cases"], manifest.cases):
        spec["mechanism"] = mech_files[str(case.mechanism)].name
        items = spec["trajectories"] if isinstance(spec["trajectories"], list) else [spec["trajectories"]]
        spec["trajectories"] = [absolute(t) for t in items]
    design = directory / manifest.path.name
    if design.resolve() == manifest.path.resolve():
        raise GearcliError(f"{directory}: would overwrite the manifest {manifest.path}: choose another -o")
    with atomic_output(design, [manifest.path]) as f:
        f.write(f"# Written by gearcli select from {manifest.path}: the chosen parts' design\n")
        f.write(yaml.safe_dump(data, sort_keys=False))
    written.append(design)
    return written


def select_table(slots, ranked: list[Ranked], objective: str) -> dict[str, list]:
    """The ranked table: rank, each slot's part, the objective, the worst margin and check,
    the largest inertia ratio (with inertia-ratio checks), feasible, the failing checks."""
    cols: dict[str, list] = {"rank": list(range(1, len(ranked) + 1))}
    for j, s in enumerate(slots):
        cols[s.name] = [s.parts[r.combo[j]].name for r in ranked]
    cols[f"total_{objective}"] = [r.objective for r in ranked]
    cols["worst_margin_%"] = [r.worst for r in ranked]
    cols["worst_check"] = [r.worst_check for r in ranked]
    if any(math.isfinite(r.inertia_ratio) for r in ranked):
        cols["largest_inertia_ratio"] = [r.inertia_ratio for r in ranked]
    cols["feasible"] = [r.feasible for r in ranked]
    cols["failing_checks"] = ["; ".join(r.failing) for r in ranked]
    return cols


MARGIN_FLOOR = -100.0
"""The worst-margin panel's lower edge, %: a combination failing by more drawn on it (a
margin of -4000 % would otherwise squash the feasible ones, all above 0, into a line)."""


def _front(points) -> list:
    """The Pareto front of (x, y, ...) points, x to minimise and y to maximise: each point no
    other beats on both, by increasing x."""
    front, best = [], -math.inf
    for p in sorted(points, key=lambda p: (p[0], -p[1])):
        if p[1] > best:
            front.append(p)
            best = p[1]
    return front


def plot_pareto(ranked: list[Ranked], objective: str, path: str, inputs=()) -> None:
    """Total ``objective`` against the worst margin of every combination (feasible ones
    green, the others red; those failing by more than 100 % on the panel's lower edge), the
    Pareto front of the feasible ones (least objective for a margin) drawn through them, the
    chosen one ringed; with inertia-ratio checks, a second panel: the objective against the
    largest load-to-rotor inertia ratio and its front (least objective for a ratio)."""
    import matplotlib  # noqa: PLC0415
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    units = {"mass": "kg", "cost": "", "inertia": "kg·m²"}
    ratio = any(math.isfinite(r.inertia_ratio) for r in ranked)
    fig, axes = plt.subplots(1, 2 if ratio else 1, figsize=(12 if ratio else 7, 4.5), squeeze=False)
    ax = axes[0][0]
    ok = [r for r in ranked if r.feasible and math.isfinite(r.worst)]
    bad = [r for r in ranked if not r.feasible and math.isfinite(r.worst)]
    near = [r for r in bad if r.worst >= MARGIN_FLOOR]
    far = [r for r in bad if r.worst < MARGIN_FLOOR]
    if near:
        ax.scatter([r.objective for r in near], [r.worst for r in near], c="tab:red", s=18, label="a check fails")
    if far:
        ax.scatter([r.objective for r in far], [MARGIN_FLOOR] * len(far), c="tab:red", marker="v", s=22,
                   label=f"a check fails by more than {-MARGIN_FLOOR:g} %")
    if ok:
        ax.scatter([r.objective for r in ok], [r.worst for r in ok], c="tab:green", s=18, label="feasible")
        front = _front([(r.objective, r.worst) for r in ok])
        ax.plot([p[0] for p in front], [p[1] for p in front], "g-", lw=1, label="Pareto front")
        ax.scatter([ok[0].objective], [ok[0].worst], s=120, facecolors="none", edgecolors="k", label="chosen")
    ax.axhline(0.0, color="red", linestyle="--", lw=1)
    if far:
        ax.set_ylim(bottom=MARGIN_FLOOR * 1.05)
    unit = units[objective]
    xlabel = f"total {objective}" + (f" [{unit}]" if unit else "")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("worst margin [%] (below 0: a check fails)")
    ax.set_title(f"{len(ranked)} combinations: {len(ok)} feasible", fontsize=10)
    ax.legend(fontsize=8)
    if ratio:
        bx = axes[0][1]
        shown = [r for r in ranked if math.isfinite(r.inertia_ratio)]
        for group, colour, label in (([r for r in shown if not r.feasible], "tab:red", "a check fails"),
                                     ([r for r in shown if r.feasible], "tab:green", "feasible")):
            if group:
                bx.scatter([r.objective for r in group], [r.inertia_ratio for r in group], c=colour, s=18, label=label)
        okr = [r for r in ok if math.isfinite(r.inertia_ratio)]
        if okr:
            front = _front([(r.objective, -r.inertia_ratio) for r in okr])
            bx.plot([p[0] for p in front], [-p[1] for p in front], "g-", lw=1, label="Pareto front")
            bx.scatter([ok[0].objective], [ok[0].inertia_ratio], s=120, facecolors="none", edgecolors="k",
                       label="chosen")
        bx.set_yscale("log")
        bx.set_xlabel(xlabel)
        bx.set_ylabel("largest load-to-rotor inertia ratio of the motors")
        bx.set_title("inertia ratio (log scale)", fontsize=10)
        bx.legend(fontsize=8)
        bx.grid(True, alpha=0.3)
    save_figure(fig, ax, path, inputs)
