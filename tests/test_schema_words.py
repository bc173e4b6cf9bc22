"""Schema violations reach users in gearcli's words (``expected 3 numbers, got 4``), never
in jsonschema's (``[-0.2, 0, 0, 1] is too long``) or as a Python repr
(``datetime.date(2024, 1, 1)``): one located line per problem, exit status 2.

Each validator keyword the schemas use has a case through the CLI; a seeded set of
mutations of a bundled mechanism and manifest checks that no message carries jsonschema's
phrases.
"""
from __future__ import annotations

import copy
import datetime as dt
import json
import random
from pathlib import Path

import pytest
import yaml

from gearcli.errors import GearcliError
from gearcli.io.schema_words import STRUCTURAL, WORDING

ROOT = Path(__file__).resolve().parents[1]
PAPER = (ROOT / "mechanisms" / "paper_2dof.yaml").read_text()
RATED = (ROOT / "mechanisms" / "paper_2dof_rated.yaml").read_text()

JSONSCHEMA_PHRASES = ("is not of type", "is too long", "is too short", "is a required property", "was unexpected",
                      "is not one of", "is less than", "is greater than", "does not match", "should be non-empty",
                      "is not valid under", "is valid under each", "Additional properties", "datetime.", "None",
                      "{'", "['")


def one_line(run_cli, tmp_path, text: str, needle: str, place: str, command: str = "check",
             name: str = "bad.yaml") -> str:
    """The message of the one line ``file:line: place: message`` the CLI prints for ``text``
    (line: the first line holding ``needle``), exit status 2."""
    path = tmp_path / name
    path.write_text(text)
    res = run_cli(command, path)
    assert res.exit_code == 2 and res.stdout == "", (res.exit_code, res.stdout)
    lines = res.stderr.splitlines()
    assert len(lines) == 1, lines
    line = next(i for i, s in enumerate(text.splitlines(), 1) if needle in s)
    prefix = f"{path}:{line}: {place}: "
    assert lines[0].startswith(prefix), (lines[0], prefix)
    return lines[0][len(prefix):]


def edited(old: str, new: str, text: str = PAPER) -> str:
    assert text.count(old) == 1, old
    return text.replace(old, new)


@pytest.mark.parametrize("old, new, place, message", [
    # type: the expected kind, and the value's kind as written (never a Python repr)
    ("    mass: 4.0", "    mass: 2024-01-01", "links[1].mass", "expected a number, got a date (2024-01-01)"),
    ("    mass: 4.0", "    mass: 2024-01-01 10:30:00", "links[1].mass",
     "expected a number, got a date and time (2024-01-01 10:30:00)"),
    ("    mass: 4.0", "    mass: heavy", "links[1].mass", "expected a number, got a string ('heavy')"),
    ("    mass: 4.0", "    mass: true", "links[1].mass", "expected a number, got a boolean (true)"),
    ("    mass: 4.0", "    mass:", "links[1].mass", "expected a number, got an empty value"),
    ("    mass: 4.0", "    mass: {a: 1}", "links[1].mass", "expected a number, got a mapping (keys: 'a')"),
    ("    mass: 4.0", "    mass: [4, 1]", "links[1].mass", "expected a number, got a list of 2 items"),
    ("com: [-0.2, 0, 0]", "com: 3", "links[1].com", "expected a list, got a number (3)"),
    ("com: [-0.2, 0, 0]", "com: [-0.2, x, 0]", "links[1].com[1]", "expected a number, got a string ('x')"),
    ('  - name: "1" ', "  - name: 1 ", "links[1].name", "expected a string, got a number (1)"),
    # minItems / maxItems
    ("com: [-0.2, 0, 0]", "com: [-0.2, 0, 0, 1]", "links[1].com", "expected 3 numbers, got 4"),
    ("com: [-0.2, 0, 0]", "com: [-0.2, 0]", "links[1].com", "expected 3 numbers, got 2"),
    ("com: [-0.2, 0, 0]", "com: []", "links[1].com", "expected 3 numbers, got none"),
    ("teeth: [30, 30]", "teeth: [30, 30, 30]", "gears[1].teeth", "expected 2 whole numbers, got 3"),
    ('links: ["5", "1"]', 'links: ["5"]', "gears[0].links", "expected 2 names, got 1"),
    # enum
    ("kind: external", "kind: extrenal", "gears[0].kind",
     "expected one of: external, internal, bevel, rack; got 'extrenal' (did you mean 'external'?)"),
    ("kind: external", "kind: 3", "gears[0].kind", "expected one of: external, internal, bevel, rack; got a number (3)"),
    # minimum / exclusiveMinimum / exclusiveMaximum; integer
    ("teeth: [30, 30]", "teeth: [0, 30]", "gears[1].teeth[0]", "expected at least 1, got 0"),
    ("teeth: [30, 30]", "teeth: [2.5, 30]", "gears[1].teeth[0]", "expected a whole number, got 2.5"),
    ("pressure_angle_deg: 20", "pressure_angle_deg: 0", "gears[0].pressure_angle_deg", "expected more than 0, got 0"),
    ("pressure_angle_deg: 20", "pressure_angle_deg: 45", "gears[0].pressure_angle_deg", "expected less than 45, got 45"),
    # minLength, pattern: one line for an empty name (not both)
    ("  - name: J1 ", '  - name: "" ', "joints[0].name", "must not be empty"),
    ("  - name: J1 ", '  - name: "J 1" ', "joints[0].name",
     "expected a name without spaces, colons or commas, got 'J 1'"),
    # oneOf with no branch fitting the value's type
    ("inertia: [0.005, 0.06, 0.06]", "inertia: 5", "links[1].inertia",
     "expected a list or a mapping, got a number (5)"),
    # required, additionalProperties (gearcli's words already)
    ("  - name: J1                      # shoulder: link 1 about z0\n    parent: \"0\"", "  - name: J1", "joints[0]",
     "missing required key 'parent'"),
    ("inertia: [0.005, 0.06, 0.06]", "inertia: {ixx: 1, iyy: 1, izz: 1, ixy: 0, foo: 2}", "links[1].inertia.foo",
     "unknown key 'foo' (allowed: ixx, iyy, izz, ixy, ixz, iyz)"),
])
def test_mechanism_schema_errors_in_gearclis_words(run_cli, tmp_path, old, new, place, message):
    text = edited(old, new)
    assert one_line(run_cli, tmp_path, text, new.strip().splitlines()[0], place) == message


def test_maximum_of_an_integer(run_cli, tmp_path):
    text = (ROOT / "mechanisms" / "planetary_3p.yaml").read_text()
    text = edited("    planets: 3", "    planets: 65", text)
    assert one_line(run_cli, tmp_path, text, "planets: 65", "joints[2].planets") == "expected at most 64, got 65"


def test_a_long_value_is_described_not_echoed(run_cli, tmp_path):
    text = edited("description: Two-dof geared manipulator of Fig. 1 in the paper",
                  "description: [" + ", ".join(["xxxxxxxxxx"] * 5000) + "]")
    assert one_line(run_cli, tmp_path, text, "description: [", "description") == \
        "expected a string, got a list of 5000 items"


def test_control_characters_are_escaped(run_cli, tmp_path):
    text = edited("kind: external", 'kind: "ext\\u0007"')
    assert one_line(run_cli, tmp_path, text, "kind: ", "gears[0].kind") == \
        "expected one of: external, internal, bevel, rack; got 'ext\\x07'"


MANIFEST = """cases:
  - name: CASE
    mechanism: {mech}
    trajectories: TRAJ
"""


@pytest.mark.parametrize("case, traj, needle, place, message", [
    ("one", "[{file: t.csv}]", "trajectories", "cases[0].trajectories[0]",
     "give one of: hours, fraction, cycles_per_hour"),
    ("one", "[{file: t.csv, hours: 1, fraction: 0.5}]", "trajectories", "cases[0].trajectories[0]",
     "give only one of: hours, fraction, cycles_per_hour (got hours and fraction)"),
    ("one", "[{file: t.csv, fraction: 1.5}]", "trajectories", "cases[0].trajectories[0].fraction",
     "expected at most 1, got 1.5"),
    ("one", "[]", "trajectories", "cases[0].trajectories", "expected at least 1 item, got none"),
    ("one", "5", "trajectories", "cases[0].trajectories", "expected a string or a list, got a number (5)"),
    ("''", "t.csv", "name:", "cases[0].name", "must not be empty"),
])
def test_manifest_schema_errors_in_gearclis_words(run_cli, tmp_path, case, traj, needle, place, message):
    text = MANIFEST.format(mech=ROOT / "mechanisms" / "paper_2dof_rated.yaml").replace("CASE", case)
    text = text.replace("TRAJ", traj)
    (tmp_path / "t.csv").write_text((ROOT / "mechanisms" / "paper_2dof_traj.csv").read_text())
    assert one_line(run_cli, tmp_path, text, needle, place, command="verify", name="d.yaml") == message


def _keywords(node, out: set) -> set:
    """Every keyword of a schema (names under ``properties``/``$defs`` are not keywords)."""
    if isinstance(node, dict):
        for k, v in node.items():
            out.add(k)
            for sub in (v.values() if k in ("properties", "$defs") and isinstance(v, dict) else [v]):
                _keywords(sub, out)
    elif isinstance(node, list):
        for v in node:
            _keywords(v, out)
    return out


@pytest.mark.parametrize("schema", ["mechanism.schema.json", "design.schema.json"])
def test_every_keyword_of_the_schemas_has_gearclis_wording(schema):
    """A keyword added to a schema without an entry in the table would fall back to a
    generic message: add its wording to ``gearcli.io.schema_words.WORDING``."""
    used = _keywords(json.loads((ROOT / "schemas" / schema).read_text()), set())
    assert used - set(WORDING) - STRUCTURAL - {"required", "additionalProperties"} == set()


HOSTILE = [dt.date(2024, 1, 1), dt.datetime(2024, 1, 1, 10, 30), "x y", "", None, True, 2.5, 0, -1, 70,
           [], [1, 2, 3, 4], {"q": 1}, "bevl"]


def _leaves(node, path=()):
    """(path, value) of every node below ``node``."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield path + (k,), v
            yield from _leaves(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield path + (i,), v
            yield from _leaves(v, path + (i,))


def _mutated(data, path, value):
    out = copy.deepcopy(data)
    node = out
    for p in path[:-1]:
        node = node[p]
    if value is _DELETE:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return out


_DELETE = object()


def _messages(parse, data) -> list[str]:
    try:
        parse(yaml.safe_dump(data, sort_keys=False))
    except GearcliError as exc:
        return exc.lines()
    return []


def test_no_message_of_mutated_files_is_in_jsonschemas_words(tmp_path):
    """Seeded mutations (a node replaced by a date, a string, an empty value, a list of the
    wrong length, a mapping, ... or deleted; a key added) of a rated mechanism and of a
    manifest: every message is one line in gearcli's words."""
    from gearcli.batch.manifest import load_manifest
    from gearcli.io.yaml_reader import parse_mechanism

    def manifest(text):
        path = tmp_path / "m.yaml"
        path.write_text(text)
        return load_manifest(path)

    (tmp_path / "t.csv").write_text((ROOT / "mechanisms" / "paper_2dof_traj.csv").read_text())
    mech = tmp_path / "mech.yaml"
    mech.write_text(RATED)
    design = {"name": "d", "cases": [{"name": "c", "mechanism": str(mech), "trajectories": [
        {"file": "t.csv", "fraction": 0.5}, "t.csv"], "cycles_per_hour": 10, "min_static_safety": 1.5,
        "limits": [{"column": "gear:5-1:t", "max_abs": 1000}]}]}
    rng = random.Random(20261126)
    seen, count = set(), 0
    for parse, data, n in ((lambda t: parse_mechanism(t, "m.yaml"), yaml.safe_load(RATED), 120),
                           (manifest, design, 50)):
        leaves = list(_leaves(data))
        for path, _ in rng.sample(leaves, min(n, len(leaves))):
            for value in rng.sample(HOSTILE, 3) + [_DELETE]:
                for line in _messages(parse, _mutated(data, path, value)):
                    count += 1
                    seen.add(line.split(": ", 2)[-1])
                    assert "\n" not in line and not any(p in line for p in JSONSCHEMA_PHRASES), line
        parent = next(p for p, v in leaves if isinstance(v, dict))
        assert _messages(parse, _mutated(data, parent + ("nonsense",), 1))     # an unknown key
    assert count > 300 and len(seen) > 100, (count, len(seen))     # the mutations reached many checks
