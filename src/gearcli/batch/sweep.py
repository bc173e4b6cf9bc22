"""``gearcli sweep``: a design manifest verified over a grid of mechanism values.

A ``--vary PATH=VALUES`` names one number of a case's YAML mechanism file in the file's own
terms and the values it takes:

* PATH: dot-separated keys from the top of the mechanism file; in a list of named items
  (``links``, ``joints``, ``gears``, ``motors``, ``loads``, ``payloads``, a joint's
  ``bearings``) the next key is the item's ``name``; ``[i]`` picks element i of a list
  (0-based).  ``links.payload.mass``, ``gears.hd1.ratio``,
  ``motors.m1.rating.rotor_inertia``, ``loads.tip.force[2]``.  ``CASE:PATH`` varies the
  mechanism of that case alone; without it, every case's mechanism (each must have PATH).
* VALUES: ``1,2,5`` (a list), ``a:b:n`` (n values from a to b, evenly spaced) or
  ``log:a:b:n`` (n values from a to b, evenly spaced in log); SI units, as the file.

The variants are the full grid of the values (or, with ``samples``, that many grid points
drawn at random with a fixed seed).  Each variant's mechanism files are the originals with
the varied numbers replaced, checked as ``gearcli check`` would (a value the file would not
accept is a located error before anything runs: every value is tried alone first), then every
check of the manifest is run on them as ``gearcli verify`` runs it.  One row per variant:
the varied values, every check's value, limit and margin (%), the worst margin and its
check.  Rows come back in variant order whichever way they ran (this process, local
processes, a Dask cluster), so the table is the same bytes.
"""
from __future__ import annotations

import copy
import dataclasses
import json
import math
import re
import threading
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
from ..errors import GearcliError, MechanismError

NAMED_LISTS = ("links", "joints", "gears", "motors", "loads", "payloads", "bearings")
"""Lists whose items are picked by their ``name`` in a --vary path."""

MAX_VARIANTS = 1_000_000
"""A grid larger than this is refused (give --samples)."""


@dataclass(frozen=True)
class Vary:
    """One ``--vary``: ``case`` (None: every case), the path's ``steps`` (a key, a name in a
    named list, or an int index), its text and its values."""

    text: str
    case: str | None
    path: str
    steps: tuple
    values: tuple[float, ...]
    mode: str = "set"        # "add": the value is added to the file's (gearcli select's parts)


def _number(text: str, where: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise GearcliError(f"{where}: expected a number, got '{text}'") from None
    if not math.isfinite(x):
        raise GearcliError(f"{where}: expected a finite number, got '{text}'")
    return x


def values_of(text: str, where: str) -> tuple[float, ...]:
    """The values of a VALUES text: ``1,2,5``, ``a:b:n`` or ``log:a:b:n``."""
    text = text.strip()
    log = text.startswith("log:")
    if log or ":" in text:
        parts = text[4:].split(":") if log else text.split(":")
        if len(parts) != 3:
            raise GearcliError(f"{where}: expected {'log:' if log else ''}a:b:n (from a to b in n values), got '{text}'")
        a, b = _number(parts[0], where), _number(parts[1], where)
        try:
            n = int(parts[2])
        except ValueError:
            raise GearcliError(f"{where}: expected a whole number of values n >= 1 in a:b:n, got '{parts[2]}'") from None
        if n < 1 or n > MAX_VARIANTS:
            raise GearcliError(f"{where}: expected 1 <= n <= {MAX_VARIANTS:,} values in a:b:n, got {n}")
        if log:
            if a <= 0 or b <= 0:
                raise GearcliError(f"{where}: a log range needs a > 0 and b > 0, got {a:g} and {b:g}")
            return tuple(float(v) for v in np.geomspace(a, b, n))
        return tuple(float(v) for v in np.linspace(a, b, n))
    items = [s for s in text.split(",")]
    if not text or any(not s.strip() for s in items):
        raise GearcliError(f"{where}: expected numbers separated by commas, a:b:n or log:a:b:n, got '{text}'")
    return tuple(_number(s.strip(), where) for s in items)


def path_steps(path: str, where: str) -> tuple:
    """The steps of a --vary (or slot) PATH: its keys and names, and an int per ``[i]``;
    ``where`` names the option in the error of a malformed part."""
    steps = []
    for part in path.split("."):
        m = re.fullmatch(r"([^\[\]]+)((?:\[\d+\])*)", part)
        if not m:
            raise GearcliError(f"{where}: '{part}' is not a key, a name or key[i] (path '{path}')")
        steps.append(m.group(1))
        steps += [int(i) for i in re.findall(r"\[(\d+)\]", m.group(2))]
    return tuple(steps)


def parse_vary(text: str) -> Vary:
    """A ``--vary PATH=VALUES`` option's text, checked for its form (not yet against a file)."""
    where = f"--vary '{text}'"
    if "=" not in text:
        raise GearcliError(f"{where}: expected PATH=VALUES (e.g. links.payload.mass=0.5,1,2)")
    lhs, rhs = text.split("=", 1)
    case, path = (lhs.split(":", 1) if ":" in lhs else (None, lhs))
    path = path.strip()
    if not path:
        raise GearcliError(f"{where}: the path before '=' is empty")
    return Vary(text, case.strip() if case is not None else None, path, path_steps(path, where),
                values_of(rhs, where))


def locate(data, steps: tuple, path: str):
    """(container, key) of the number ``steps`` name in the YAML ``data``; a GearcliError
    (without its place: the caller adds it) when a step does not exist or the target is not
    a number."""
    node, at = data, []
    for k, step in enumerate(steps):
        last = k == len(steps) - 1
        if isinstance(step, int):
            if not isinstance(node, list):
                raise GearcliError(f"{'.'.join(map(str, at)) or 'the file'} is not a list (path '{path}')")
            if step >= len(node):
                raise GearcliError(f"{'.'.join(map(str, at))} has {len(node)} elements, no [{step}] (path '{path}')")
            container, key = node, step
        elif isinstance(node, list) and at and at[-1] in NAMED_LISTS:
            names = [item.get("name") for item in node if isinstance(item, dict)]
            if step not in names:
                raise GearcliError(f"no {at[-1][:-1] if at[-1] != 'bearings' else 'bearing'} named '{step}' "
                                   f"(the file has {', '.join(map(str, names)) or 'none'}; path '{path}')")
            container, key = node, names.index(step)
        elif isinstance(node, dict):
            if step not in node:
                raise GearcliError(f"no key '{step}' in {'.'.join(map(str, at)) or 'the file'} "
                                   f"(it has {', '.join(map(str, node)) or 'none'}; path '{path}')")
            container, key = node, step
        else:
            raise GearcliError(f"{'.'.join(map(str, at))} has no key '{step}' (it is a value; path '{path}')")
        at.append(step)
        node = container[key]
        if last:
            if isinstance(node, bool) or not isinstance(node, (int, float)):
                kind = "a list" if isinstance(node, list) else "a mapping" if isinstance(node, dict) else f"'{node}'"
                raise GearcliError(f"is {kind} in the file, not a number (path '{path}')")
            return container, key
    raise GearcliError(f"empty path '{path}'")


def _set(data, v: Vary, value: float) -> None:
    """The number ``v`` names in ``data`` set to ``value`` (or, ``v.mode`` "add", increased by it)."""
    container, key = locate(data, v.steps, v.path)
    old = container[key]
    new = old + value if v.mode == "add" else value
    container[key] = int(new) if isinstance(old, int) and float(new).is_integer() else float(new)


@dataclass(frozen=True)
class Plan:
    """What a sweep runs: the manifest, its ``varies`` and the variants (per variant one
    value per vary), and whether each value of the kernel's constants gets a data kernel
    (:func:`per_value_kernels`)."""

    manifest_path: str
    varies: tuple[Vary, ...]
    variants: tuple[tuple[float, ...], ...]
    per_value_kernels: bool = False     # a data kernel per value of the kernel's constants (:func:`per_value_kernels`)


@lru_cache(maxsize=8)
def file_data(mech_path: str) -> dict:
    """A mechanism file's YAML data as written (read once; copied before a variant changes it)."""
    from ..io.yaml_safe import read_text, yaml_lines  # noqa: PLC0415
    return yaml_lines(read_text(mech_path), mech_path)[0]


def variant_data(manifest, varies, values) -> dict[str, dict]:
    """{case name: its mechanism file's YAML data with the variant's values}."""
    out = {}
    for case in manifest.cases:
        mine = [(v, x) for v, x in zip(varies, values) if v.case is None or v.case == case.name]
        # the file's sections a value changes are copied, the others shared (a mechanism is
        # built from its data without changing it): a deep copy of the whole file was a
        # tenth of a variant's time
        data = dict(file_data(str(case.mechanism)))
        for key in dict.fromkeys(v.steps[0] for v, _ in mine):
            data[key] = _section_copy(str(case.mechanism), key, tuple((v, x) for v, x in mine if v.steps[0] == key))
        out[case.name] = data
    return out


def _section_copy(mech_path: str, key: str, values: tuple):
    """Section ``key`` of the mechanism file with the variant's ``values`` ((vary, value) of
    the paths into it) set, a gear pair's mesh point following its ratio; the same object
    for the same values, kept for the next variants (the last :data:`SECTION_COPIES`): the
    reader then reuses the parts it built from it (:func:`gearcli.io.yaml_reader._section`),
    e.g. the gear pairs of one ratio while the masses vary."""
    k = (mech_path, key, tuple((v.path, v.case, v.mode, x) for v, x in values))
    with _SECTIONS_LOCK:                # a Dask worker's threads share it
        if k not in _SECTIONS:
            if len(_SECTIONS) >= SECTION_COPIES:
                _SECTIONS.pop(next(iter(_SECTIONS)))
            data = dict(file_data(mech_path))
            data[key] = copy.deepcopy(data[key])
            for v, x in values:
                _set(data, v, x)
            for v in {v.steps[1]: v for v, _ in values if moves_mesh_point(v.steps)}.values():
                _follow_mesh_point(mech_path, data, v)
            _SECTIONS[k] = data[key]
        return _SECTIONS[k]


SECTION_COPIES = 64
_SECTIONS: dict = {}
_SECTIONS_LOCK = threading.RLock()


def moves_mesh_point(steps: tuple) -> bool:
    """True when a path names a gear pair's ``ratio`` or ``teeth``: a variant of it moves the
    pair's mesh point, if it has one (:func:`_follow_mesh_point`)."""
    return len(steps) >= 3 and steps[0] == "gears" and steps[2] in ("ratio", "teeth")


def _both_given(data: dict, steps: tuple) -> str:
    """A hint for a varied ratio or tooth count of a pair that gives both (the other one then
    contradicts the variant: vary the tooth counts alone, the file's ratio removed), or ""."""
    if not moves_mesh_point(steps):
        return ""
    pair = next((g for g in data.get("gears", ()) if isinstance(g, dict) and g.get("name") == steps[1]), {})
    return (f" (gear pair '{steps[1]}' gives both ratio and teeth: remove its ratio and vary its teeth)"
            if "ratio" in pair and "teeth" in pair else "")


TOOTHED = ("external", "internal", "bevel")
"""The kinds of gear pair whose mesh point a ratio variant moves (spur, helical, ring, bevel;
not a rack, whose ratio is its pinion's radius, nor a worm, a belt or a reducer)."""


def _follow_mesh_point(mech_path: str, data: dict, v: Vary) -> None:
    """Move the mesh point of the pair ``v`` names (its ratio or tooth counts varied) to where
    its axes, as the file places them, give it the variant's ratio
    (:func:`gearcli.model.gears.mesh_point_for_ratio`: the centre distance or the cone
    distance kept); a pair without a mesh point (a reducer, a coupling) or not :data:`TOOTHED`
    is left as it is."""
    from ..model.gears import mesh_point_for_ratio  # noqa: PLC0415
    pairs = data["gears"]
    i = next(i for i, g in enumerate(pairs) if isinstance(g, dict) and g.get("name") == v.steps[1])
    pair = pairs[i] = dict(pairs[i])
    geometry = _file_geometry(mech_path).get(v.steps[1])
    if "mesh_point" not in pair or geometry is None or pair.get("kind", "external") not in TOOTHED:
        return
    if v.steps[2] == "teeth" and not all(isinstance(z, (int, float)) and z > 0 for z in pair["teeth"]):
        return                          # the reader says what is wrong with the tooth counts
    ratio = pair["teeth"][1] / pair["teeth"][0] if v.steps[2] == "teeth" else pair["ratio"]
    try:
        pair["mesh_point"] = [float(x) for x in mesh_point_for_ratio(geometry, ratio)]
    except ValueError as exc:
        raise GearcliError(f"--vary '{v.text}': gear pair '{v.steps[1]}': {exc}") from None


@lru_cache(maxsize=8)
def _file_geometry(mech_path: str) -> dict:
    """{gear pair name: its mesh geometry (carrier frame)} of the mechanism file as written."""
    from ..dynamics.determinacy import load_analysed  # noqa: PLC0415
    an = load_analysed(mech_path)
    return {an.mech.gears[c.gear].name: c.geometry for c in an.circuits if c.geometry is not None}


def plan_sweep(manifest, varies: list[Vary], samples: int | None = None, seed: int = 0) -> Plan:
    """The variants of ``varies`` over ``manifest``'s cases, every path and value checked
    before anything runs: a case name that is not the manifest's, a path a case's mechanism
    lacks, a mechanism that is not YAML, a value the file would not accept (each value tried
    alone, the others at the file's own values; a value of a constant of the kernel (a ratio,
    a point) analysed too: a ratio that contradicts its pair's mesh point)."""
    from ..dynamics.determinacy import analyse  # noqa: PLC0415
    from ..io.yaml_reader import mechanism_from_data  # noqa: PLC0415
    if not varies:
        raise GearcliError("sweep: give at least one --vary PATH=VALUES")
    names = [c.name for c in manifest.cases]
    paths = [v.path if v.case is None else f"{v.case}:{v.path}" for v in varies]
    for p in paths:
        if paths.count(p) > 1:
            raise GearcliError(f"--vary {p}: given twice")
    for v in varies:
        where = f"--vary '{v.text}'"
        if v.case is not None and v.case not in names:
            raise GearcliError(f"{where}: no case named '{v.case}' in {manifest.path} (cases: {', '.join(names)})")
        for case in manifest.cases:
            if v.case is not None and v.case != case.name:
                continue
            if Path(case.mechanism).suffix.lower() not in (".yaml", ".yml"):
                raise GearcliError(f"{where}: case '{case.name}': sweep varies YAML mechanism files, "
                                   f"{case.mechanism} is not one (gearcli export writes a URDF; write the YAML by hand)")
            try:
                locate(file_data(str(case.mechanism)), v.steps, v.path)
            except GearcliError as exc:
                raise GearcliError(f"{where}: case '{case.name}' ({case.mechanism}): {exc}") from None
            for x in dict.fromkeys(v.values):
                data = variant_data(manifest, [v], [x])[case.name]
                try:
                    mech = mechanism_from_data(data, str(case.mechanism))
                    if not (run_time(v.steps) or checks_only(v.steps)):     # a ratio against its mesh point, ...
                        analyse(mech)
                except MechanismError as exc:
                    i = exc.issues[0]
                    said = f"{i.path}: {i.message}" if i.path else i.message
                    raise GearcliError(f"{where}: case '{case.name}': the value {x:g}: {said}"
                                       f"{_both_given(data, v.steps)}") from None
    sizes = [len(v.values) for v in varies]
    total = math.prod(sizes)
    if samples is None:
        if total > MAX_VARIANTS:
            raise GearcliError(f"sweep: the grid has {total:,} variants, more than {MAX_VARIANTS:,}: give --samples N")
        grid = np.indices(sizes).reshape(len(sizes), -1).T
    else:
        if samples < 1:
            raise GearcliError(f"--samples: expected at least 1, got {samples}")
        grid = np.random.default_rng(seed).integers(0, sizes, size=(samples, len(sizes)))
    variants = tuple(tuple(v.values[i] for v, i in zip(varies, row)) for row in grid)
    return Plan(str(manifest.path), tuple(varies), variants, per_value_kernels(varies, variants))


@lru_cache(maxsize=4)
def _manifest(path: str):
    from .manifest import load_manifest  # noqa: PLC0415
    return load_manifest(path)


INERTIAL = ("mass", "com", "inertia")
"""The keys of a link or a payload a data kernel takes at run time (:func:`data_kernel_applies`)."""

LOAD_VALUES = ("force", "moment", "mass", "inertia")
"""The keys of a load a data kernel takes at run time: its wrench (an input of every solve)
and the mass and inertia it carries (merged into its link's)."""


BEARING_RATINGS = ("C", "C0", "X", "Y", "e", "X0", "Y0", "M", "f0", "a_ISO", "kappa", "e_C", "Cu", "pitch_diameter")
"""The numbers of a joint's bearing that only the design checks read (its friction and
position enter the solve)."""


def checks_only(steps: tuple) -> bool:
    """True when a path names a number that only the design checks read, never the solve:
    a part's ``rating`` (a motor's, a gear pair's, a reducer's, a screw's, a belt's) or a
    bearing's load ratings and factors (:data:`BEARING_RATINGS`)."""
    return (len(steps) >= 4 and steps[2] == "rating"
            or len(steps) == 5 and steps[0] == "joints" and steps[2] == "bearings" and steps[4] in BEARING_RATINGS)


def run_time(steps: tuple) -> bool:
    """True when a path names a value the data kernel reads at run time: a link's or a
    payload's mass, centre of mass or inertia, a load's wrench, mass or inertia (not its
    point, a constant of the kernel)."""
    if len(steps) < 3:
        return False
    return (steps[0] in ("links", "payloads") and steps[2] in INERTIAL
            or steps[0] == "loads" and steps[2] in LOAD_VALUES)


def data_kernel_applies(varies) -> bool:
    """True when every --vary names a value the data kernel reads at run time
    (:func:`run_time`) or a number only the checks read (:func:`checks_only`): the
    variants' solves differ only in those values
    (:attr:`gearcli.dynamics.llvm.program.Program.data_bodies`), so one compile serves them all."""
    return all(run_time(v.steps) or checks_only(v.steps) for v in varies)


STRUCTURE_VARIANTS = 2
"""Variants per value of the other --vary paths (a ratio, a radius, a point) from which each
such value gets a data kernel of its own (:func:`per_value_kernels`).  The kernels of the
values share one compile (the IR holds no value of the mechanism:
:class:`gearcli.dynamics.llvm.build.ConstantPool`): a value's kernel costs its analysis, its
IR and a link, 0.13 s for the Bendix wrist (2026-12-08), what the numpy path takes for
one or two variants of 10,000 samples (95 ms each)."""


def per_value_kernels(varies, variants) -> bool:
    """True when some --vary names a value the data kernel takes as a constant (a ratio, a
    radius, a load's point: not :func:`data_kernel_applies`) and the planned ``variants``
    have on average at least :data:`STRUCTURE_VARIANTS` for each combination of such values
    (the others vary the values the kernel reads at run time or the checks alone read):
    each combination then gets a data kernel that solves its variants
    (:func:`_structure_solver`), where the numpy path would solve each.  (Random points,
    ``--samples``, rarely repeat a combination: the numpy path.)"""
    fixed = [i for i, v in enumerate(varies) if not (run_time(v.steps) or checks_only(v.steps))]
    if not fixed:
        return False
    combos = {tuple(x[i] for i in fixed) for x in variants}
    return len(variants) >= STRUCTURE_VARIANTS * len(combos)


def _structure_solver(mech_path: str, key: tuple, mech):
    """The data solver of the mechanism ``mech`` whose constants (not its inertial values, its
    loads' wrenches or its ratings) are those of the values ``key`` ((path, value) of the
    --vary paths that are not the data kernel's), built for the first variant of those
    values and kept for the next (the last 4 kept: a grid's variants come value by value),
    or None where the llvm backend cannot solve it."""
    from ..dynamics.determinacy import analyse  # noqa: PLC0415
    from ..dynamics.solve import Solver  # noqa: PLC0415
    k = (mech_path, key)
    if k not in _STRUCTURES:
        if len(_STRUCTURES) >= 4:
            _STRUCTURES.pop(next(iter(_STRUCTURES)))
        solver = Solver(analyse(mech), data_bodies=True)
        _STRUCTURES[k] = solver if solver.llvm_available() else None
    return _STRUCTURES[k]


_STRUCTURES: dict = {}


@lru_cache(maxsize=8)
def _data_solver(mech_path: str):
    """A solver of the mechanism file as it is whose kernel reads the links' inertial values
    at run time (compiled on its first solve, then kept for every variant), or None where the
    llvm backend cannot solve it (the numpy path then)."""
    from ..dynamics.determinacy import load_analysed  # noqa: PLC0415
    from ..dynamics.solve import Solver  # noqa: PLC0415
    solver = Solver(load_analysed(mech_path), data_bodies=True)
    return solver if solver.llvm_available() else None


class _Bodies:
    """One variant's links on the data kernel, as :func:`~gearcli.dynamics.forward.mass_matrix`'s
    stacked solve calls a solver (its ``an`` and ``solve``)."""

    def __init__(self, kernel, an):
        self.kernel, self.an = kernel, an

    def solve(self, q, qd, qdd, loads=None, **_):
        # the carried payloads' entries (no external load given: their masses are the bodies')
        known = {ld.name for ld in self.kernel.an.mech.loads}
        return self.kernel.solve_bodies(self.an, q, qd, qdd, {k: v for k, v in (loads or {}).items() if k in known})


class VariantKernel:
    """The solves of one variant (``an``: the file's analysis with the variant's mechanism)
    on the data kernel ``kernel``: a trajectory's samples, group by group of the payloads
    carried (each group's mechanism :meth:`~gearcli.model.mechanism.Mechanism.attached`:
    the same links with other inertial values), and the inertia the motors see (the mass
    matrix's columns solved on the kernel)."""

    def __init__(self, kernel, an):
        self.kernel, self.an = kernel, an

    def _carry(self, an, attached):
        return an if not attached else dataclasses.replace(an, mech=an.mech.attached(attached))

    def _groups(self, attach, n: int, run):
        from ..dynamics.payloads import attach_flags, by_groups  # noqa: PLC0415
        if not attach:
            return run(self.an, slice(None))
        return by_groups(self.an, attach_flags(self.an, attach, n), run, n, carry=self._carry)

    def solve(self, p):
        from ..dynamics.payloads import loads_at  # noqa: PLC0415
        # the variant's loads (their wrenches are run-time inputs), a trajectory's columns over them
        given = {ld.name: ld.wrench for ld in self.an.mech.loads} | dict(p.loads or {})

        def run(a, rows):
            part = loads_at(given, rows)
            return self.kernel.solve_bodies(a, p.q[rows], p.qd[rows], p.qdd[rows], part or None)
        return self._groups(p.attach, len(p.q), run)

    def inertia(self, q, attach) -> dict:
        from ..design.sizing import inertia_columns  # noqa: PLC0415
        rated = [f"motor:{m.name}:inertia" for m in self.an.mech.motors
                 if m.rating is not None and m.rating.rotor_inertia is not None]
        if not rated:
            return {}

        def run(a, rows):
            cols = inertia_columns(a, q[rows], None, "numpy", solver=_Bodies(self.kernel, a))
            return np.column_stack([cols[k] for k in rated])
        J = self._groups(attach, len(q), run)
        return {k: J[:, i] for i, k in enumerate(rated)}


def _trajectory(path: str, names: tuple, degrees: bool, linear: tuple, loads: tuple, payloads: tuple):
    """The trajectory file read for a variant, kept for the next: the reading depends on the
    loads only by their names and wrenches (a ``load:`` column replaces a component of the
    wrench), so a variant of a load's mass or inertia reads nothing again."""
    from ..io.trajectory import read_trajectory  # noqa: PLC0415
    key = (path, names, degrees, linear, tuple((ld.name, ld.wrench.tobytes()) for ld in loads), payloads)
    if key not in _TRAJECTORIES:
        if len(_TRAJECTORIES) >= 64:
            _TRAJECTORIES.clear()
        _TRAJECTORIES[key] = read_trajectory(path, list(names), degrees=degrees, linear=np.asarray(linear, bool),
                                             loads=loads, payloads=list(payloads))
    return _TRAJECTORIES[key]


_TRAJECTORIES: dict = {}


def run_variant(manifest_path: str, varies: tuple[Vary, ...], values: tuple[float, ...],
                per_value: bool = False) -> list[tuple]:
    """Every check of the manifest on one variant: [(case, component, quantity, unit, value,
    limit, margin %, passed)] in the manifest's order of cases and checks (picklable in and
    out: a local process or a Dask worker runs it the same).  Variants of values the data
    kernel reads at run time or the checks alone read are solved by one data kernel per
    mechanism and process (:func:`data_kernel_applies`), payloads picked and placed included;
    the others by the numpy path, or, where a value of theirs has
    :data:`STRUCTURE_VARIANTS` variants or more (``per_value``: the plan's
    :func:`per_value_kernels`), by a data kernel per value."""
    from ..design.checks import build_checks  # noqa: PLC0415
    from ..design.evaluate import combine, partials, profile_rates  # noqa: PLC0415
    from ..dynamics.determinacy import analyse  # noqa: PLC0415
    from ..errors import Collector  # noqa: PLC0415
    from ..io.yaml_reader import mechanism_from_data  # noqa: PLC0415
    from .runner import solve_samples  # noqa: PLC0415

    manifest = _manifest(manifest_path)
    datas = variant_data(manifest, varies, values)
    data_kernel = data_kernel_applies(varies)
    structures = per_value and not data_kernel
    out = []
    for case in manifest.cases:
        # every value passed the schema alone (plan_sweep): the model's checks run here
        mech = mechanism_from_data(datas[case.name], str(case.mechanism), schema=False)
        solver = _data_solver(str(case.mechanism)) if data_kernel else None
        if structures:
            key = tuple((v.path, x) for v, x in zip(varies, values) if (v.case is None or v.case == case.name)
                        and not (run_time(v.steps) or checks_only(v.steps)))
            solver = _structure_solver(str(case.mechanism), key, mech) if key else _data_solver(str(case.mechanism))
        # the links' inertial values change no part of the analysis (topology, geometry, schedule):
        # the solver's, of the same constants, serves
        an = analyse(mech) if solver is None else dataclasses.replace(solver.an, mech=mech)
        checks = build_checks(an, case.req, Collector(str(case.mechanism)))
        parts = []
        for tp in case.trajectories:
            tr = _trajectory(str(tp), tuple(an.independent_names), case.degrees,
                             tuple(bool(x) for x in an.prismatic_independent), tuple(an.mech.loads),
                             tuple(p.name for p in an.mech.payloads))
            vk = None if solver is None else VariantKernel(solver, an)
            samples = solve_samples(an, tp, case.degrees, threads=1, backend="numpy", checks=checks, tr=tr,
                                    solve_with=vk and vk.solve, inertia_with=vk and vk.inertia)
            parts.append(partials(checks, samples, an.mech))
        spans = [p[0][6] if p else 0.0 for p in parts]
        rates = profile_rates(case.shares or (None,) * len(parts), spans, case.req.cycles_per_hour,
                              case.req.service_life_h)
        for k, ch in enumerate(checks):
            v = combine(ch, [p[k] for p in parts], rates)
            out.append((case.name, ch.component, ch.quantity, ch.unit, float(v.value), float(ch.limit),
                        float(v.margin), bool(v.passed)))
    return out


def _chunks(n: int, size: int) -> list[range]:
    return [range(a, min(a + size, n)) for a in range(0, n, size)]


def _run_chunk(manifest_path: str, varies, variants, per_value: bool = False) -> list:
    """:func:`run_variant` of each variant; a variant that cannot be built or solved (values
    that are each valid alone but not together, a belt that goes slack) is the one-line
    reason, a string, in its place."""
    from .heap import keep_freed_memory  # noqa: PLC0415
    keep_freed_memory()          # each variant makes and drops the same arrays: no page faults for each (.heap)
    out = []
    for values in variants:
        try:
            out.append(run_variant(manifest_path, varies, values, per_value))
        except GearcliError as exc:
            out.append(" ".join(exc.lines()[0].split()) if exc.lines() else str(exc))
    return out


def run_sweep(plan: Plan, jobs: int = 1, dask_address: str | None = None, progress=None,
              done: dict | None = None, record=None, pool=None) -> list:
    """Every variant's checks (:func:`run_variant`, or the reason it could not run), in
    variant order; ``jobs`` local processes or the Dask scheduler at ``dask_address``;
    ``progress(n)`` after each n variants.  ``done``: {variant index: its result} of an
    earlier run (``--resume``), not run again; ``record(first, results)`` is told each
    chunk's results as it finishes (the partial file).  ``pool``: a process pool of
    ``jobs`` workers kept across calls (select's iterative search calls this once per slot:
    a pool each time would start the workers, and load the kernel in each, every time)."""
    n = len(plan.variants)
    done = dict(done or {})
    todo = [i for i in range(n) if i not in done]
    size = max(1, min(64, len(todo) // (8 * max(jobs, 1)) or 1))
    parts = [todo[a:a + size] for a in range(0, len(todo), size)]
    if progress and done:
        progress(len(done))

    def finished(idx: list, rows: list) -> None:
        done.update(zip(idx, rows))
        if record:
            record(idx, rows)
        if progress:
            progress(len(idx))

    def args(idx: list):
        return plan.manifest_path, plan.varies, [plan.variants[i] for i in idx], plan.per_value_kernels

    if dask_address is not None:
        from dask.distributed import as_completed as dask_completed  # noqa: PLC0415 (optional)

        from .runner import dask_client  # noqa: PLC0415
        with dask_client(dask_address) as client:
            futures = {client.submit(_run_chunk, *args(idx), pure=False): k for k, idx in enumerate(parts)}
            for fut in dask_completed(list(futures), loop=client.loop):
                finished(parts[futures[fut]], fut.result())
    elif jobs <= 1 or len(parts) <= 1:
        for idx in parts:
            finished(idx, _run_chunk(*args(idx)))
    else:
        from concurrent.futures import ProcessPoolExecutor, as_completed  # noqa: PLC0415
        from contextlib import nullcontext  # noqa: PLC0415
        with nullcontext(pool) if pool is not None else ProcessPoolExecutor(max_workers=jobs) as workers:
            futures = {workers.submit(_run_chunk, *args(idx)): k for k, idx in enumerate(parts)}
            for fut in as_completed(futures):
                finished(parts[futures[fut]], fut.result())
    return [done[i] for i in range(n)]


def _fingerprint(plan: Plan) -> str:
    """What a partial file must match to be resumed: the manifest, the --vary texts, the variants."""
    import hashlib  # noqa: PLC0415
    text = json.dumps([str(Path(plan.manifest_path).resolve()), [v.text for v in plan.varies],
                       [list(v) for v in plan.variants]])
    return hashlib.sha256(text.encode()).hexdigest()


def partial_path(output: str) -> Path:
    """The partial file of a sweep writing ``output``: finished variants, one JSON line each."""
    p = Path(output)
    return p.with_name(p.name + ".partial")


def read_partial(path: Path, plan: Plan) -> dict:
    """{variant index: result} of a partial file written for the same ``plan``; a
    GearcliError naming the file and line when it is not one."""
    lines = path.read_text().splitlines()
    if not lines:
        raise GearcliError(f"{path}:1: an empty partial file (remove it to start again)")
    try:
        head = json.loads(lines[0])
    except json.JSONDecodeError:
        raise GearcliError(f"{path}:1: not a sweep's partial file (remove it to start again)") from None
    if not isinstance(head, dict) or head.get("plan") != _fingerprint(plan):
        raise GearcliError(f"{path}:1: written by a sweep of other variants (another manifest, --vary or "
                           f"--samples): remove it, or run that sweep with --resume")
    done = {}
    for k, line in enumerate(lines[1:], start=2):
        try:
            item = json.loads(line)
            i, rows = int(item["i"]), item["result"]
        except (json.JSONDecodeError, KeyError, TypeError, ValueError):
            if k == len(lines):          # the line being written when the run stopped
                break
            raise GearcliError(f"{path}:{k}: not a finished variant's line (remove the file to start again)") from None
        if not 0 <= i < len(plan.variants):
            raise GearcliError(f"{path}:{k}: variant {i} is not one of the {len(plan.variants)} of this sweep")
        done[i] = rows if isinstance(rows, str) else [tuple(r) for r in rows]
    return done


class PartialFile:
    """Appends each finished chunk to the partial file (a header line with the plan's
    fingerprint first), flushed, so that an interrupted sweep keeps what it finished."""

    def __init__(self, path: Path, plan: Plan, resume: bool):
        self.path = path
        self.f = open(path, "a" if resume else "x", encoding="utf-8")
        if not resume:
            self.f.write(json.dumps({"plan": _fingerprint(plan)}) + "\n")
            self.f.flush()

    def __call__(self, idx: list, rows: list) -> None:
        for i, r in zip(idx, rows):
            self.f.write(json.dumps({"i": i, "result": r}) + "\n")
        self.f.flush()

    def close(self) -> None:
        self.f.close()


def table(plan: Plan, results: list) -> dict[str, list]:
    """The sweep's table, {column: values} in order: the varied values (named by their
    paths), then per check ``CASE: COMPONENT: QUANTITY`` value, limit and margin %, then
    ``worst_margin_%``, ``worst_check`` and ``passed``; a variant that could not run has NaN
    checks, its reason as ``worst_check``, and ``passed`` false."""
    cols: dict[str, list] = {}
    for k, v in enumerate(plan.varies):
        name = v.path if v.case is None else f"{v.case}:{v.path}"
        cols[name] = [values[k] for values in plan.variants]
    ran = next((r for r in results if not isinstance(r, str)), [])
    checks = [f"{c[0]}: {c[1]}: {c[2]}" for c in ran]
    nan = (math.nan,) * 8
    for j, name in enumerate(checks):
        unit = ran[j][3]
        u = f" [{unit}]" if unit else ""
        for field, at in ((f"value{u}", 4), (f"limit{u}", 5), ("margin %", 6)):
            cols[f"{name}: {field}"] = [(nan if isinstance(r, str) else r[j])[at] for r in results]
    worst, why = [], []
    for r in results:
        if isinstance(r, str) or not r:
            worst.append(math.nan)
            why.append(f"not run: {r}" if isinstance(r, str) else "")
            continue
        w = min(range(len(r)), key=lambda j: (r[j][7], r[j][6]))
        worst.append(r[w][6])
        why.append(checks[w])
    cols["worst_margin_%"], cols["worst_check"] = worst, why
    cols["passed"] = [not isinstance(r, str) and all(c[7] for c in r) for r in results]
    return cols


def write_table(cols: dict[str, list], path: str, inputs=()) -> None:
    """CSV (9 significant digits, as the loads files), Parquet or Feather by the extension,
    written atomically."""
    from ..io.output import atomic_output  # noqa: PLC0415
    ext = Path(path).suffix.lower()
    if ext in (".parquet", ".feather"):
        import pyarrow as pa  # noqa: PLC0415
        t = pa.table(cols)
        with atomic_output(path, inputs, binary=True) as f:
            if ext == ".parquet":
                import pyarrow.parquet as pq  # noqa: PLC0415
                pq.write_table(t, f)
            else:
                import pyarrow.feather as feather  # noqa: PLC0415
                feather.write_feather(t, f, compression="uncompressed")
        return
    import csv  # noqa: PLC0415

    def cell(x):
        if isinstance(x, bool):
            return "true" if x else "false"
        if isinstance(x, float):
            return "inf" if x == math.inf else "-inf" if x == -math.inf else f"{x:.9g}"
        return x
    with atomic_output(path, inputs) as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(list(cols))
        for row in zip(*cols.values()):
            w.writerow([cell(x) for x in row])


def plot_sweep(plan: Plan, cols: dict[str, list], path: str, inputs=()) -> None:
    """The worst margin (%) of each variant over one varied value (a line, the points marked)
    or two (each variant a square of the grid coloured by its margin, the 0 % contour where
    the design starts to fail; random samples: a scatter); the 0 % line is the pass/fail
    boundary.  Written atomically (PNG, SVG or PDF by the extension)."""
    import matplotlib  # noqa: PLC0415
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    names = list(cols)[:len(plan.varies)]
    worst = np.asarray(cols["worst_margin_%"], float)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    if len(names) == 1:
        x = np.asarray(cols[names[0]], float)
        order = np.argsort(x, kind="stable")
        ax.plot(x[order], worst[order], "o-", label="worst margin of the variant")
        ax.axhline(0.0, color="red", linestyle="--", label="0 %: a check fails below")
        ax.set_xlabel(names[0])
        ax.set_ylabel("worst margin [%]")
        ax.legend(fontsize=8)
    else:
        x, y = (np.asarray(cols[n], float) for n in names)
        lim = max(float(np.nanmax(np.abs(worst[np.isfinite(worst)]))) if np.isfinite(worst).any() else 1.0, 1e-9)
        xs, ys = np.unique(x), np.unique(y)
        full = len(xs) * len(ys) == len(x) and len(set(zip(x, y))) == len(x)
        if full:
            Z = np.full((len(ys), len(xs)), np.nan)
            Z[np.searchsorted(ys, y), np.searchsorted(xs, x)] = worst
            mesh = ax.pcolormesh(xs, ys, Z, cmap="RdYlGn", vmin=-lim, vmax=lim, shading="nearest")
            if len(xs) > 1 and len(ys) > 1 and np.nanmin(Z) < 0 < np.nanmax(Z):
                ax.contour(xs, ys, Z, levels=[0.0], colors="black", linewidths=1.2)
        else:
            mesh = ax.scatter(x, y, c=worst, cmap="RdYlGn", vmin=-lim, vmax=lim, edgecolors="k", linewidths=0.3)
        fig.colorbar(mesh, ax=ax, label="worst margin [%] (below 0: a check fails)")
        ax.set_xlabel(names[0])
        ax.set_ylabel(names[1])
    ax.set_title(f"{Path(plan.manifest_path).name}: worst margin of {len(worst)} variants", fontsize=10)
    save_figure(fig, ax, path, inputs)


def save_figure(fig, ax, path: str, inputs=()) -> None:
    """A sweep's or a selection's figure, gridded, written atomically (PNG, SVG or PDF by the extension)."""
    import matplotlib.pyplot as plt  # noqa: PLC0415

    from ..io.output import atomic_output  # noqa: PLC0415
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    with atomic_output(path, inputs, binary=True) as f:
        fig.savefig(f, format=Path(path).suffix.lower().lstrip("."), dpi=110)
    plt.close(fig)


def output_names(inputs, table: tuple[str, str | None] = ("-o", None), plot: str | None = None) -> None:
    """Refuse, before anything runs, a table name (``table``: its option and name) that is not
    .csv, .parquet or .feather and a plot name that is not .png, .svg or .pdf, or either naming
    an input or an unwritable place (:func:`gearcli.io.output.output_target`)."""
    from ..io.output import output_target  # noqa: PLC0415
    from ..report.table_files import format_of  # noqa: PLC0415
    option, name = table
    if name is not None:
        if name == "-" or format_of(name) not in ("csv", "parquet", "feather"):
            raise GearcliError(f"{option}: expected a .csv, .parquet or .feather file name, got '{name}'")
        output_target(name, inputs, option)
    if plot is not None:
        if plot == "-" or Path(plot).suffix.lower() not in (".png", ".svg", ".pdf"):
            raise GearcliError(f"--plot: expected a .png, .svg or .pdf file name, got '{plot}'")
        output_target(plot, inputs, "--plot")
