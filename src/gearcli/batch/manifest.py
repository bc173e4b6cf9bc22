"""Design manifests (``gearcli verify DESIGN.yaml``): read, validate, and prepare every case.

The manifest is validated against ``schemas/design.schema.json``; then every case's
mechanism is loaded and analysed, its checks built, and every trajectory read, so that all
problems of the manifest and of every file it names are reported together (one line each,
``file:line: place: message``) before any work runs.
"""
from __future__ import annotations

import glob
import os
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import jsonschema

from ..design.checks import Check, Requirements, build_checks
from ..errors import Collector, GearcliError, Issue, MechanismError
from ..io import load_mechanism
from ..io.trajectory import TrajectoryReader
from ..io.yaml_reader import yaml_lines
from ..pipeline import analyse, prismatic_independent
from ..io.schemas import packaged_schema

REQUIREMENT_KEYS = ("cycles_per_hour", "bearing_life_h", "min_static_safety", "min_bending_safety",
                    "min_contact_safety")


@lru_cache(maxsize=8)
def _analysis(mech_path: str, mtime: float | None):
    return analyse(load_mechanism(mech_path))


def case_analysis(mech_path: str | Path):
    """The analysed mechanism, cached per process (keyed by path and modification time):
    the manifest's preparation and the jobs run in this process share it."""
    try:
        mtime = os.path.getmtime(mech_path)
    except OSError:       # load_mechanism says what is wrong with it
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


@dataclass(frozen=True)
class Manifest:
    path: Path
    name: str
    cases: tuple[Case, ...]


def _schema_issues(data, col: Collector) -> None:
    validator = jsonschema.Draft202012Validator(design_schema())
    for err in sorted(validator.iter_errors(data), key=lambda e: list(map(str, e.absolute_path))):
        path = ""
        for p in err.absolute_path:
            path += f"[{p}]" if isinstance(p, int) else (f".{p}" if path else str(p))
        msg = err.message
        if err.validator == "additionalProperties":
            allowed = ", ".join(err.schema.get("properties", {}))
            msg = f"{msg} (allowed: {allowed})"
        elif err.validator == "anyOf":
            msg = "give max_abs or max_rms (or both)"
        col.add(path, msg)


def load_manifest(path: str | Path) -> Manifest:
    """Read and validate a manifest and everything it names; raises
    :class:`~gearcli.errors.MechanismError` listing every problem."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise MechanismError([Issue(str(path), "", None, f"cannot read file: {getattr(exc, 'strerror', exc)}")]) from None
    data, lines = yaml_lines(text, str(path))
    col = Collector(str(path), lines)
    if not isinstance(data, dict):
        col.add("", "a design manifest must be a YAML mapping with a list of cases")
    elif "links" in data and "cases" not in data:
        col.add("", "this is a mechanism file, not a design manifest: a manifest lists cases, each naming "
                    "a mechanism and its trajectories (README, Design checks in CI)")
    col.raise_if_any()
    _schema_issues(data, col)
    col.raise_if_any()
    issues: list[str] = []
    cases, names = [], {}
    for i, spec in enumerate(data["cases"]):
        case = _prepare_case(spec, f"cases[{i}]", path.parent, col, issues)
        if case is None:
            continue
        if case.name in names:
            col.add(f"cases[{i}].name", f"duplicate case name '{case.name}' (first at {names[case.name]})")
        names[case.name] = f"cases[{i}]"
        cases.append(case)
    if col.issues or issues:
        raise ManifestError([str(i) for i in col.issues] + issues)
    return Manifest(path, data.get("name", path.stem), tuple(cases))


def _trajectory_paths(spec, where: str, base: Path, col: Collector) -> list[Path]:
    patterns = spec["trajectories"]
    patterns = [patterns] if isinstance(patterns, str) else patterns
    out = []
    for j, pat in enumerate(patterns):
        full = str(base / pat)
        found = sorted(glob.glob(full)) if glob.has_magic(pat) else ([full] if Path(full).is_file() else [])
        if not found:
            sub = f"{where}.trajectories" + (f"[{j}]" if not isinstance(spec["trajectories"], str) else "")
            col.add(sub, f"no trajectory file matches '{pat}' (relative to {base})")
        out += [Path(f) for f in found]
    return out


def _prepare_case(spec: dict, where: str, base: Path, col: Collector, issues: list) -> Case | None:
    mech_path = base / spec["mechanism"]
    req = Requirements(**{k: spec[k] for k in REQUIREMENT_KEYS if k in spec},
                       limits=tuple(spec.get("limits", ())), limits_path=f"{where}.limits")
    if req.bearing_life_h is not None and req.cycles_per_hour is None:
        col.add(f"{where}.bearing_life_h", "a bearing life in hours needs the duty's cycles_per_hour")
    trajs = _trajectory_paths(spec, where, base, col)
    try:
        an = case_analysis(mech_path)
    except GearcliError as exc:
        issues += exc.lines()
        return None
    ccol = Collector(str(col.file), col.lines)
    mcol = Collector(an.mech.source, an.mech.lines)
    checks = _split_build(an, req, ccol, mcol)
    col.issues += ccol.issues
    issues += [str(i) for i in mcol.issues]
    if not checks:
        col.add(f"{where}.mechanism", f"nothing to check: '{spec['mechanism']}' has no ratings and the case no limits")
    _unused_requirements(spec, where, checks, col)
    for tp in trajs:
        try:
            TrajectoryReader(tp, an.independent_names, degrees=spec.get("degrees", False),
                             linear=prismatic_independent(an), loads=an.mech.loads).check()   # rows only, no spline
        except GearcliError as exc:
            issues += exc.lines()
    name = spec.get("name", Path(spec["mechanism"]).stem)
    return Case(name, mech_path, tuple(trajs), bool(spec.get("degrees", False)), req, tuple(checks))


REQUIREMENT_CHECKS = {"bearing_life_h": ("L10 life", "joints[].bearings with C"),
                      "min_static_safety": ("static safety s0", "joints[].bearings"),
                      "min_bending_safety": ("bending safety", "gears[].rating"),
                      "min_contact_safety": ("contact safety", "gears[].rating")}
"""Requirement key -> (quantity of the checks it sets, the ratings those checks need)."""


def _unused_requirements(spec: dict, where: str, checks, col: Collector) -> None:
    """A requirement the case gives but no check uses is an error, not a silent no-op."""
    quantities = {c.quantity for c in checks} | ({"L10 life"} if any(c.kind == "life" for c in checks) else set())
    for key, (quantity, needs) in REQUIREMENT_CHECKS.items():
        if key in spec and quantity not in quantities:
            col.add(f"{where}.{key}", f"checks nothing: '{spec['mechanism']}' has no {needs} "
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
