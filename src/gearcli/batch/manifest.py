"""Design manifests (``gearcli verify DESIGN.yaml``): read, validate, and prepare every case.

The manifest is validated against ``schemas/design.schema.json``; then every case's
mechanism is loaded and analysed, its checks built, and every trajectory read, so that all
problems of the manifest and of every file it names are reported together (one line each,
``file:line: place: message``) before any work runs.
"""
from __future__ import annotations

import glob
import os
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import jsonschema

from ..design.checks import Check, Requirements, build_checks
from ..errors import Collector, GearcliError
from ..io.limits import input_problem
from ..io.trajectory import TrajectoryReader, forget_rows
from ..io.schema_words import schema_messages
from ..io.yaml_reader import json_path, number_issues
from ..io.yaml_safe import read_text, yaml_lines
from ..model.validate import MAX_ABS
from ..dynamics.determinacy import load_analysed
from ..io.schemas import packaged_schema

REQUIREMENT_KEYS = ("cycles_per_hour", "service_life_h", "bearing_life_h", "gear_life_h", "reducer_life_h", "screw_life_h",
                    "min_worm_efficiency", "min_static_safety",
                    "min_bending_safety", "min_contact_safety")


@lru_cache(maxsize=8)
def _analysis(mech_path: str, mtime: float | None):
    return load_analysed(mech_path)


def case_analysis(mech_path: str | Path):
    """The analysed mechanism, cached per process (keyed by path and modification time):
    the manifest's preparation and the jobs run in this process share it."""
    try:
        mtime = os.path.getmtime(mech_path)
    except (OSError, ValueError):       # load_mechanism says what is wrong with it
        mtime = None
    return _analysis(str(mech_path), mtime)


def design_schema() -> dict:
    """The JSON Schema of design manifests (``schemas/design.schema.json``)."""
    return packaged_schema("design.schema.json")


class ManifestError(GearcliError):
    """Problems in a manifest or in the files it names, one line each."""

    def __init__(self, lines: list[str]):
        self.problems = list(lines)
        super().__init__("\n".join(self.problems))

    def lines(self) -> list[str]:
        return list(self.problems)


@dataclass(frozen=True)
class Case:
    """One case of a manifest, ready to run."""

    name: str
    mechanism: Path
    trajectories: tuple[Path, ...]
    degrees: bool
    req: Requirements
    checks: tuple[Check, ...]
    shares: tuple = ()     # per trajectory: (hours|fraction|cycles_per_hour, value) or None


@dataclass(frozen=True)
class Manifest:
    path: Path
    name: str
    cases: tuple[Case, ...]
    slots: tuple = ()        # the slots of gearcli select, as written (validated by the schema)
    lines: dict = field(default_factory=dict, compare=False)   # YAML path -> line, for located errors


MIN_POSITIVE = 1e-12
"""Smallest positive number a manifest accepts (requirements, limits): below it products
with the loads leave float64's normal range (``cycles_per_hour: 1e-320``)."""


def _range_message(x) -> str:
    """What is wrong with a manifest number outside [MIN_POSITIVE, MAX_ABS] (finite)."""
    if x <= 0:
        return f"must be positive, got {x:g}"
    top = f"{MAX_ABS:.0e}".replace("e+", "e")
    return f"{x:g} is out of range ({MIN_POSITIVE:g} <= x <= {top} in SI units)"


def _schema_issues(data, col: Collector, skip: set) -> None:
    """Schema violations (except at the paths in ``skip``, already reported), in the words
    of mechanism files (:func:`gearcli.io.schema_words.schema_messages`)."""
    validator = jsonschema.Draft202012Validator(design_schema())
    for err in sorted(validator.iter_errors(data), key=lambda e: list(map(str, e.absolute_path))):
        if json_path(err.absolute_path) in skip:    # a non-finite or huge number, reported already
            continue
        leaf = _leaf(err)
        if err.validator == "anyOf":
            found = [(list(err.absolute_path), _any_of_message(err.validator_value))]
        elif leaf.validator in ("minimum", "maximum") and isinstance(leaf.instance, (int, float)) \
                and leaf.schema.get("minimum") == MIN_POSITIVE:        # the schema's "positive"
            found = [(list(leaf.absolute_path), _range_message(leaf.instance))]
        elif err.validator == "pattern" and err.absolute_path and err.absolute_path[-1] == "name" and err.instance:
            found = [(list(err.absolute_path), f"{err.instance!r}: a name without control characters"
                      + (" or spaces (one word)" if len(err.absolute_path) > 1 else ""))]
        else:
            found = schema_messages(err)
        for parts, message in found:
            if json_path(parts) not in skip:
                col.add(json_path(parts), message)


def _any_of_message(branches: list) -> str:
    """The words of an ``anyOf`` the value meets no branch of: keys of which one is needed
    (a limit's max_abs or max_rms, a slot's set or add), or a slot's target, a path or a
    list of paths."""
    keys = [b["required"][0] for b in branches if list(b) == ["required"] and len(b["required"]) == 1]
    if len(keys) == len(branches):
        return f"give {' or '.join(keys)} (or both)"
    return "expected a path of the mechanism files (e.g. links.arm.mass) or a list of such paths, none empty"


def _leaf(err):
    """The error itself, or inside a oneOf (trajectories given as a file name or as a list,
    one with its share) the deepest of its branches' errors, the one in the branch the value
    took: a share's number out of range is then worded as every other manifest number's
    (:func:`_range_message`)."""
    while err.validator == "oneOf" and err.context:
        err = max(err.context, key=lambda e: len(e.absolute_path))
    return err


def _with_enclosing(paths) -> set:
    """Every path of ``paths`` and every path enclosing one (``a.b[2].c``: ``a.b[2]``,
    ``a.b``, ``a``), so that :func:`_under` is one set lookup."""
    out = set()
    for p in paths:
        while p and p not in out:
            out.add(p)
            cut = max(p.rfind("."), p.rfind("["))
            p = p[:cut] if cut > 0 else ""
    return out


def _under(bad: set, path: str) -> bool:
    """Whether a problem was reported at ``path`` or inside it (``bad``: from
    :func:`_with_enclosing`)."""
    return path in bad


def load_manifest(path: str | Path) -> Manifest:
    """Read and validate a manifest and everything it names; raises
    :class:`~gearcli.errors.MechanismError` (an unreadable or non-YAML manifest) or
    :class:`ManifestError` listing every problem: numbers (finite, in range), the schema,
    and what the valid parts name (files, columns, requirements), in one round."""
    path = Path(path)
    forget_rows()            # rows a previous manifest's check kept and no job took
    data, lines = yaml_lines(read_text(path, "design manifest"), str(path))
    col = Collector(str(path), lines)
    if not isinstance(data, dict):
        col.add("", "a design manifest must be a YAML mapping with a list of cases")
    elif "links" in data and "cases" not in data:
        col.add("", "this is a mechanism file, not a design manifest: a manifest lists cases, each naming "
                    "a mechanism and its trajectories (docs/reference/manifest.md)")
    col.raise_if_any()
    number_issues(data, col)
    _schema_issues(data, col, {i.path for i in col.issues})
    bad = _with_enclosing(i.path for i in col.issues)
    issues: list[str] = []
    cases, names = [], {}
    specs = data.get("cases") if isinstance(data.get("cases"), list) else []
    for i, spec in enumerate(specs):
        if not isinstance(spec, dict):
            continue
        case = _prepare_case(spec, f"cases[{i}]", path.parent, col, issues, bad)
        if case is None:
            continue
        if case.name in names:
            col.add(f"cases[{i}].name", f"duplicate case name '{case.name}' (first at {names[case.name]})")
        names[case.name] = f"cases[{i}]"
        cases.append(case)
    if col.issues or issues:
        located = sorted(col.issues, key=lambda i: i.line or 0)
        raise ManifestError([str(i) for i in located] + issues)
    name = data["name"] if "name" in data else path.stem
    return Manifest(path, name, tuple(cases), tuple(data.get("slots", ())), lines)


def _shown(name: str) -> str:
    """A path from the manifest as it can be printed (a NUL byte as ``\\0``)."""
    return name.replace("\0", "\\0")


def _file_problem(name: str, base: Path) -> str | None:
    """Why the file ``name`` of the manifest (relative to its folder ``base``) cannot be
    read, found without opening it; None when it can."""
    if "\0" in name:
        return f"'{_shown(name)}': the path contains a NUL byte"
    why = input_problem(base / name)
    return None if why is None else f"'{name}' (relative to {base}): {why}"


SHARE_KEYS = ("hours", "fraction", "cycles_per_hour")


def _trajectory_paths(spec, where: str, base: Path, col: Collector, bad: set) -> tuple[list[Path], list]:
    """The trajectory files of a case and their mission-profile shares ((key, value), or
    None): every valid pattern expanded (a bad item is left out, its problem is reported
    already)."""
    value = spec["trajectories"]
    if not isinstance(value, (str, list)) or isinstance(value, str) and _under(bad, f"{where}.trajectories"):
        return [], []
    single = isinstance(value, str)
    patterns = [value] if single else value
    out, shares = [], []
    for j, pat in enumerate(patterns):
        sub = f"{where}.trajectories" + ("" if single else f"[{j}]")
        share = None
        if isinstance(pat, dict) and not _under(bad, sub):
            key = next((k for k in SHARE_KEYS if k in pat), None)
            if key is None or not isinstance(pat.get("file"), str):
                continue                                  # the schema said what is wrong
            share, pat, sub = (key, float(pat[key])), pat["file"], f"{sub}.file"
            if glob.has_magic(pat):
                col.add(sub, f"a trajectory with a share names one file, not a pattern: '{_shown(pat)}'")
                continue
            if key == "hours" and "service_life_h" not in spec:
                col.add(f"{where}.trajectories[{j}].hours", "hours of the profile need the case's service_life_h")
        if _under(bad, sub) or not isinstance(pat, str):
            continue
        if "\0" in pat:
            col.add(sub, f"'{_shown(pat)}': the path contains a NUL byte")
            continue
        full = str(base / pat)
        found = sorted(glob.glob(full)) if glob.has_magic(pat) else ([full] if os.path.lexists(full) else [])
        if not found:
            col.add(sub, f"no trajectory file matches '{pat}' (relative to {base})")
        for f in found:
            why = input_problem(f)
            if why:
                col.add(sub, f"'{f}': {why}")
            else:
                out.append(Path(f))
                shares.append(share)
    life = spec.get("service_life_h") if isinstance(spec.get("service_life_h"), (int, float)) else None
    time = sum(s[1] if s[0] == "fraction" else s[1] / life for s in shares if s and s[0] != "cycles_per_hour" and
               (s[0] == "fraction" or life))
    if time > 1 + 1e-12:
        col.add(f"{where}.trajectories", f"the profile's shares add up to {time:.4g} of the service time (more than all of it)")
    return out, shares


def _limits(spec: dict, where: str, bad: set) -> tuple:
    """The case's limits with every bad value left out (a bad item as ``{}``, so that the
    others keep their index in messages)."""
    out = []
    items = spec.get("limits") if isinstance(spec.get("limits"), list) else []
    for i, lim in enumerate(items):
        p = f"{where}.limits[{i}]"
        if not isinstance(lim, dict) or "column" not in lim or _under(bad, f"{p}.column"):
            out.append({})
            continue
        out.append({"column": lim["column"], **{k: float(lim[k]) for k in ("max_abs", "max_rms")
                                                 if k in lim and not _under(bad, f"{p}.{k}")}})
    return tuple(out)


def _prepare_case(spec: dict, where: str, base: Path, col: Collector, issues: list, bad: set) -> Case | None:
    """The case ``spec`` ready to run, or None; every problem of its valid parts goes to
    ``col`` (the manifest's) or ``issues`` (lines of the files it names)."""
    def ok(key: str) -> bool:
        return key in spec and not _under(bad, f"{where}.{key}")

    req = Requirements(**{k: float(spec[k]) for k in REQUIREMENT_KEYS if ok(k)},
                       limits=_limits(spec, where, bad), limits_path=f"{where}.limits")
    trajs, shares = _trajectory_paths(spec, where, base, col, bad) if "trajectories" in spec else ([], [])
    items = spec.get("trajectories")             # plain files repeat at the case's cycles_per_hour
    plain = isinstance(items, str) or isinstance(items, list) and any(isinstance(i, str) for i in items)
    for key, what in (("bearing_life_h", "a bearing life"), ("gear_life_h", "a gear fatigue life")):
        if ok(key) and "cycles_per_hour" not in spec and plain:
            col.add(f"{where}.{key}", f"{what} in hours needs the duty's cycles_per_hour")
    if not ok("mechanism"):
        return None
    mech_path = base / spec["mechanism"]
    why = _file_problem(spec["mechanism"], base)
    if why:
        col.add(f"{where}.mechanism", why)
        return None
    try:
        an = case_analysis(mech_path)
    except GearcliError as exc:
        issues += exc.lines()
        return None
    ccol = Collector(str(col.file), col.lines)
    mcol = Collector(an.mech.source, an.mech.lines)
    checks = _split_build(an, req, ccol, mcol)
    for issue in ccol.issues:
        col.add(issue.path, issue.message)
    issues += [str(i) for i in mcol.issues]
    if not checks and not _under(bad, f"{where}.limits"):
        col.add(f"{where}.mechanism", f"nothing to check: '{spec['mechanism']}' has no ratings and the case no limits")
    _unused_requirements({k: v for k, v in spec.items() if ok(k)}, spec["mechanism"], where, checks, col)
    degrees = None if _under(bad, f"{where}.degrees") else spec.get("degrees", False)
    for tp in trajs if degrees is not None else ():   # a bad 'degrees': the rows' scale is unknown
        try:
            TrajectoryReader(tp, an.independent_names, degrees=degrees,
                             linear=an.prismatic_independent, loads=an.mech.loads,
                             payloads=[p.name for p in an.mech.payloads]).check(keep=True)  # rows only,
            # no spline; the rows are kept for the job that solves the file in this process
        except GearcliError as exc:
            issues += exc.lines()
    name = spec["name"] if ok("name") else Path(spec["mechanism"]).stem
    return Case(name, mech_path, tuple(trajs), bool(degrees), req, tuple(checks), tuple(shares))


REQUIREMENT_CHECKS = {"bearing_life_h": ("L10 life", "joints[].bearings with C"),
                      "gear_life_h": ("bending fatigue life", "gears[].rating"),
                      "reducer_life_h": ("reducer life", "reducer (kind strain_wave or cycloidal) with a rating"),
                      "screw_life_h": ("screw life", "screw (kind screw) with a rating"),
                      "min_worm_efficiency": ("efficiency over the duty cycle", "worm pair (kind worm)"),
                      "min_static_safety": ("static safety s0", "joints[].bearings"),
                      "min_bending_safety": ("bending safety", "gears[].rating"),
                      "min_contact_safety": ("contact safety", "gears[].rating")}
"""Requirement key -> (quantity of the checks it sets, the ratings those checks need)."""


def _unused_requirements(spec: dict, mechanism: str, where: str, checks, col: Collector) -> None:
    """A requirement the case gives (valid keys of ``spec``) but no check uses is an
    error, not a silent no-op."""
    quantities = {c.quantity for c in checks} | ({"L10 life"} if any(c.kind == "life" for c in checks) else set())
    quantities |= {"reducer life"} if any(c.kind == "reducer_life" for c in checks) else set()
    quantities |= {"screw life"} if any(c.kind == "screw_life" for c in checks) else set()
    for key, (quantity, needs) in REQUIREMENT_CHECKS.items():
        if key in spec and quantity not in quantities:
            col.add(f"{where}.{key}", f"checks nothing: '{mechanism}' has no {needs} "
                    f"(remove {key} or rate the parts)")


def _split_build(an, req: Requirements, ccol: Collector, mcol: Collector) -> list[Check]:
    """Build the checks; problems with a manifest path (``limits``) go to ``ccol``, the
    others (ratings in the mechanism file) to ``mcol``."""
    both = Collector(mcol.file, mcol.lines)
    checks = build_checks(an, req, both)
    for issue in both.issues:
        if issue.path.startswith(req.limits_path):
            ccol.add(issue.path, issue.message)
        else:
            mcol.issues.append(issue)
    return checks
