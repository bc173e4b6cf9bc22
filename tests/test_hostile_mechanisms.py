"""Hostile mechanism files (issue 8): every one ends in exit status 2 with a single line
``file[:line]: place: what is wrong`` (capped in length), never a traceback, a hang or a
memory blow-up.

Each case is a small edit of a bundled mechanism or a generated file.  Cases run through
the in-process CLI runner; the resource-limit cases also through a real ``gearcli``
subprocess (so that a traceback, a crash or a runaway would be seen as the user sees it).
"""
from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAPER = (ROOT / "mechanisms" / "paper_2dof.yaml").read_text()
MAX_LINE = 700   # characters of one reported line (file name + place + capped message)


def replaced(old: str, new: str, text: str = PAPER) -> str:
    assert text.count(old) == 1, f"{old!r} must occur once"
    return text.replace(old, new)


def line_of(text: str, needle: str) -> int:
    return next(i + 1 for i, s in enumerate(text.splitlines()) if needle in s)


def check_one_line(res_code: int, stderr: str, stdout: str, path: Path, line: int | None,
                   place: str, reason: str) -> str:
    """Assert one located line on stderr, exit 2, nothing on stdout, no traceback."""
    assert "Traceback" not in stderr, stderr
    assert res_code == 2, (res_code, stderr[:2000])
    assert stdout == ""
    got = stderr.splitlines()
    assert len(got) == 1, got[:5]
    where = f"{path}:{line}" if line is not None else f"{path}"
    prefix = f"{where}: {place}: " if place else f"{where}: "
    assert got[0].startswith(prefix), (got[0][:300], prefix)
    assert re.search(reason, got[0][len(prefix):]), (got[0][:300], reason)
    assert len(got[0]) <= MAX_LINE + len(str(path))
    return got[0]


def bad(run_cli, tmp_path, text, line, place, reason, name="bad.yaml") -> str:
    path = tmp_path / name
    path.write_bytes(text) if isinstance(text, bytes) else path.write_text(text)
    res = run_cli("check", path)
    return check_one_line(res.exit_code, res.stderr, res.stdout, path, line, place, reason)


def bad_subprocess(tmp_path, text, line, place, reason, name="bad.yaml", timeout=60) -> str:
    path = tmp_path / name
    path.write_bytes(text) if isinstance(text, bytes) else path.write_text(text)
    env_path = str(ROOT / "src")
    res = subprocess.run([sys.executable, "-c", "import sys; sys.path.insert(0, sys.argv[1]); "
                          "from gearcli.cli import app; sys.argv = ['gearcli', 'check', sys.argv[2]]; app()",
                          env_path, str(path)], capture_output=True, text=True, timeout=timeout)
    return check_one_line(res.returncode, res.stderr, res.stdout, path, line, place, reason)


# --------------------------------------------------------------------------------------
# numbers: too large for a float, non-finite, beyond physical sense
# --------------------------------------------------------------------------------------
BIG_INT = "1" + "0" * 400


@pytest.mark.parametrize("old,new,place", [
    ("mass: 4.0", f"mass: {BIG_INT}", "links[1].mass"),
    ("com: [-0.2, 0, 0]", f"com: [-0.2, {BIG_INT}, 0]", "links[1].com[1]"),
    ("inertia: [0.005, 0.06, 0.06]", f"inertia: [0.005, {BIG_INT}, 0.06]", "links[1].inertia[1]"),
    ("theta_deg: 0, d: 0.0, a: 0.4", f"theta_deg: {BIG_INT}, d: 0.0, a: 0.4", "joints[0].dh.theta_deg"),
    ("theta_deg: 0, d: 0.0, a: 0.4", f"theta_deg: 0, d: {BIG_INT}, a: 0.4", "joints[0].dh.d"),
    ("origin: {xyz: [-0.2, 0, 0.05]}", f"origin: {{xyz: [-0.2, 0, 0.05], rpy_deg: [{BIG_INT}, 0, 0]}}",
     "joints[3].origin.rpy_deg[0]"),
    ("axis: [1, 0, 0]", f"axis: [{BIG_INT}, 0, 0]", "joints[3].axis[0]"),
    ("ratio: -3.0", f"ratio: -{BIG_INT}", "gears[0].ratio"),
    ("teeth: [30, 30]", f"teeth: [30, {BIG_INT}]", "gears[1].teeth[1]"),
    ("mesh_point: [0.09, 0, -0.05]", f"mesh_point: [{BIG_INT}, 0, -0.05]", "gears[0].mesh_point[0]"),
    ("pressure_angle_deg: 20", f"pressure_angle_deg: {BIG_INT}", "gears[0].pressure_angle_deg"),
    ("gravity: [0, 0, -9.81]", f"gravity: [0, 0, -{BIG_INT}]", "gravity[2]"),
])
def test_integer_too_large_for_a_float(run_cli, tmp_path, old, new, place):
    text = replaced(old, new)
    bad(run_cli, tmp_path, text, line_of(text, BIG_INT), place,
        r"an integer of 40[01] digits is out of range \(\|x\| <= 1e12 in SI units\)")


def test_integer_beyond_python_conversion_limit(run_cli, tmp_path):
    text = replaced("mass: 4.0", "mass: " + "9" * 5000)
    bad(run_cli, tmp_path, text, line_of(text, "9999"), "", r"an integer of 5000 digits is out of range")


@pytest.mark.parametrize("old,new,place,shown", [
    ("theta_deg: 0, d: 0.0, a: 0.4", "theta_deg: 1e300, d: 0.0, a: 0.4", "joints[0].dh.theta_deg", "1e+300"),
    ("mesh_point: [0.09, 0, -0.05]", "mesh_point: [1e300, 0, 0]", "gears[0].mesh_point[0]", "1e+300"),
    ("axis: [1, 0, 0]", "axis: [1e308, 0, 0]", "joints[3].axis[0]", "1e+308"),
    ("gravity: [0, 0, -9.81]", "gravity: [0, 0, -1e300]", "gravity[2]", "-1e+300"),
    ("mass: 4.0", "mass: 1e300", "links[1].mass", "1e+300"),
    ("mass: 4.0", "mass: 2e12", "links[1].mass", "2e+12"),
    ("inertia: [0.005, 0.06, 0.06]", "inertia: [0.005, 0.06, 1.5e13]", "links[1].inertia[2]", "1.5e+13"),
])
def test_number_beyond_physical_sense(run_cli, tmp_path, old, new, place, shown):
    text = replaced(old, new)
    bad(run_cli, tmp_path, text, line_of(text, new.split(":")[-1].strip()[:6]), place,
        rf"^{re.escape(shown)} is out of range \(\|x\| <= 1e12 in SI units\)$")


def test_non_finite_number(run_cli, tmp_path):
    text = replaced("mesh_point: [0.09, 0, -0.05]", "mesh_point: [.inf, 0, -0.05]")
    bad(run_cli, tmp_path, text, line_of(text, ".inf"), "gears[0].mesh_point[0]", "^inf is not a finite number$")


def test_largest_accepted_numbers_still_load(run_cli, tmp_path):
    """The limit is not a rounding accident: 1e12 itself is accepted (and then refused for
    what it means physically, not as a number)."""
    from gearcli import load_mechanism
    path = tmp_path / "ok.yaml"
    path.write_text(replaced("gravity: [0, 0, -9.81]", "gravity: [0, 0, -1e12]"))
    assert load_mechanism(path).gravity[2] == -1e12


# --------------------------------------------------------------------------------------
# structure: nesting, recursive aliases, alias bombs, size
# --------------------------------------------------------------------------------------
def test_deep_nesting(run_cli, tmp_path):
    text = "name: x\nlinks: " + "[" * 900 + "]" * 900 + "\n"
    bad(run_cli, tmp_path, text, 2, "", r"YAML nesting deeper than 64 levels")


@pytest.mark.parametrize("depth", [65, 999, 1001, 5000])
def test_deep_nesting_message_is_gearclis_at_any_depth(run_cli, tmp_path, depth):
    """libyaml's scanner reads flow collections ahead and has had a nesting limit of its own
    (1,000) since PyYAML 6.0.4: gearcli's guard must speak first at every depth, also for a
    collection that starts on the next line, behind a tag or an anchor."""
    text = "name: x\nlinks:\n  - !!seq &a " + "[" * depth + "]" * depth + "\n"
    bad(run_cli, tmp_path, text, 3, "", r"^YAML nesting deeper than 64 levels$")


@pytest.mark.parametrize("value", ["'" + "[" * 80 + "'", '"' + '\\"' + "{" * 80 + '"', "a" + "[" * 80,
                                   "x # " + "[" * 80])
def test_brackets_in_scalars_and_comments_are_not_nesting(value):
    """The guard counts only brackets that open a flow collection."""
    from gearcli.io.yaml_safe import flow_depth_guard, yaml_lines
    text = f"name: {value}\nlinks: []\n"
    flow_depth_guard(text, "f.yaml")
    assert yaml_lines(text, "f.yaml")[0]["links"] == []


def test_deep_nesting_subprocess(tmp_path):
    text = "name: x\nlinks: " + "[" * 200000 + "]" * 200000 + "\n"
    bad_subprocess(tmp_path, text, 2, "", r"YAML nesting deeper than 64 levels")


@pytest.mark.parametrize("text,line", [("a: &a [*a]\n", 1), ("name: x\nb: &b {c: [1, {d: *b}]}\n", 2)])
def test_self_referencing_alias(run_cli, tmp_path, text, line):
    bad(run_cli, tmp_path, text, line, "", r"alias '\*[ab]' refers to a node that contains it")


BOMB = ('a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]\n'
        + "".join(f"{c}: &{c} [{', '.join(['*' + p] * 9)}]\n" for p, c in zip("abcdefgh", "bcdefghi")))


def test_alias_bomb_fails_fast_and_small(tmp_path):
    assert len(BOMB) < 500
    line = bad_subprocess(tmp_path, BOMB, 9, "", "^YAML aliases expand the document to more than [\\d,]+ nodes", timeout=30)
    assert len(line) < 300 + len(str(tmp_path))


def test_alias_bomb_as_description(run_cli, tmp_path):
    inline = ("[&a [lol,lol,lol,lol,lol,lol,lol,lol,lol], "
              + ", ".join(f"&{c} [{', '.join(['*' + p] * 9)}]" for p, c in zip("abcdefg", "bcdefgh")) + "]")
    text = replaced("description: Two-dof geared manipulator of Fig. 1 in the paper", "description: " + inline)
    bad(run_cli, tmp_path, text, line_of(text, "description:"), "", "YAML aliases expand the document")


def test_aliases_within_reason_still_load(tmp_path):
    """Ordinary use of anchors (a shared inertia, reused many times) is not refused."""
    from gearcli import load_mechanism
    text = replaced("inertia: [0.005, 0.06, 0.06]", "inertia: &I [0.005, 0.06, 0.06]")
    text = replaced("inertia: [0.003, 0.025, 0.025]", "inertia: *I", text)
    path = tmp_path / "ok.yaml"
    path.write_text(text)
    mech = load_mechanism(path)
    assert mech.links[2].inertia[1, 1] == 0.06


def test_long_value_not_echoed(run_cli, tmp_path):
    text = PAPER + "description: [" + ", ".join(["xxxxxxxxxx"] * 20000) + "]\n"
    text = replaced("description: Two-dof geared manipulator of Fig. 1 in the paper\n", "", text)
    line = bad(run_cli, tmp_path, text, line_of(text, "description: ["), "description",
               r"^expected a string, got a list of 20000 items$")
    assert len(line) < 200 + len(str(tmp_path))


def test_100kB_link_name_not_echoed(run_cli, tmp_path):
    big = "y" * 100_000
    text = replaced('child: "2"', f'child: "{big}"')
    line = bad(run_cli, tmp_path, text, line_of(text, big), "joints[1].child", "^unknown link 'yyyy")
    assert big not in line


def test_file_size_limit(run_cli, tmp_path):
    text = PAPER + "#" + "x" * (17 * 2**20) + "\n"
    bad(run_cli, tmp_path, text, None, "", r"^file is larger than 16 MiB, the limit for a mechanism file$")


# --------------------------------------------------------------------------------------
# redundant planets: load shared by mesh stiffness (the pairs named in a note), 1 dof
# whatever their number, never "0 degrees of freedom"; planets that do not fit: refused
# --------------------------------------------------------------------------------------
def planetary(angles_deg, digits: int, planet_teeth=None) -> str:
    """Sun S and carrier C on the base axis, planets on C meshing S and a ring fixed to the
    base; coordinates rounded to ``digits`` decimals (as a designer writes them).  Module
    2 mm: planet i has ``planet_teeth[i]`` = (teeth meshing the sun, teeth meshing the ring),
    a stepped planet unless they are equal (default (10, 10), the one that fits)."""
    rs, rp = 0.02, 0.01
    rr = rs + 2 * rp
    links = ["  - {name: '0'}", "  - {name: S, mass: 0.2, inertia: [0.0001, 0.0001, 0.0001]}",
             "  - {name: C, mass: 0.5, inertia: [0.001, 0.001, 0.001]}"]
    joints = ["  - {name: JS, parent: '0', child: S}", "  - {name: JC, parent: '0', child: C, origin: {xyz: [0, 0, 0.01]}}"]
    gears = []
    for i, deg in enumerate(angles_deg):
        zs, zr = (10, 10) if planet_teeth is None else planet_teeth[i]
        rc = rs + zs * rp / 10
        c, s = (round(f(math.radians(deg)), digits) for f in (math.cos, math.sin))
        links.append(f"  - {{name: P{i}, mass: 0.05, inertia: [0.00001, 0.00001, 0.00001]}}")
        joints.append(f"  - {{name: JP{i}, parent: C, child: P{i}, origin: {{xyz: [{rc * c}, {rc * s}, 0]}}}}")
        gears.append(f"  - {{name: S-P{i}, links: [S, P{i}], teeth: [20, {zs}], mesh_point: [{rs * c}, {rs * s}, -0.01]}}")
        gears.append(f"  - {{name: P{i}-R, links: [P{i}, '0'], kind: internal, teeth: [{zr}, 40], "
                     f"mesh_point: [{rr * c}, {rr * s}, -0.01]}}")
    return ("name: planetary\nbase: '0'\nend_effector: C\nlinks:\n" + "\n".join(links) + "\njoints:\n"
            + "\n".join(joints) + "\ngears:\n" + "\n".join(gears) + "\nmotors:\n  - {name: M, link: S}\n")


@pytest.mark.parametrize("angles", [(0, 120), (0, 120, 240), (0, 90, 180, 270)])
@pytest.mark.parametrize("digits", [10, 12])
def test_redundant_planets(run_cli, tmp_path, angles, digits):
    path = tmp_path / "planets.yaml"
    path.write_text(planetary(angles, digits))
    res = run_cli("check", path)
    assert res.exit_code == 0, res.stderr
    lines = res.stdout.splitlines()
    assert lines[0] == f"{path}: OK (1 dof, {3 + len(angles)} links, {2 * len(angles)} gear pairs, 1 motor)"
    pairs = ", ".join(f"'S-P{i}', 'P{i}-R'" for i in range(len(angles)))
    assert lines[1:] == [f"note: redundant gear set {pairs}: load shared by mesh stiffness, min sum t^2/k "
                         "(equal stiffness)"]


@pytest.mark.parametrize("wrong", [(11, 9), (9, 11), (12, 8)])
def test_planet_that_does_not_fit(run_cli, tmp_path, wrong):
    """The third planet is stepped (each of its pairs fits its own geometry), so its ratio
    sun -> carrier differs from the others': the closure equations contradict (the train
    locks); refused, naming the pairs."""
    text = planetary((0, 120, 240), 12, planet_teeth=((10, 10), (10, 10), wrong))
    line = bad(run_cli, tmp_path, text, line_of(text, "gears:"), "gears",
               r"^gear pairs 'S-P0' \(gears\[0\]\), .*'P2-R' \(gears\[5\]\) form a redundant set whose "
               r"closure equations contradict \(teeth or mesh radii do not fit, relative misfit [0-9.e-]+\): "
               r"the gear trains lock$")
    assert "'S-P2'" in line


def test_single_planet_is_fine(run_cli, tmp_path):
    path = tmp_path / "one.yaml"
    path.write_text(planetary((0,), 10))
    res = run_cli("check", path)
    assert res.exit_code == 0, res.stderr


# --------------------------------------------------------------------------------------
# URDF
# --------------------------------------------------------------------------------------
ARM = (ROOT / "mechanisms" / "geared_arm.urdf").read_text()


def urdf_with_doctype(doctype: str, text: str = ARM) -> str:
    """``text`` with a DOCTYPE inserted after the XML declaration."""
    head, rest = text.split("\n", 1)
    assert head.startswith("<?xml")
    return f"{head}\n{doctype}\n{rest}"


def structure_matrix(run_cli, path) -> list:
    import json
    res = run_cli("graph", path, "--json")
    assert res.exit_code == 0, res.stderr
    assert res.stderr == ""
    return json.loads(res.stdout)["structure_matrix"]


def test_internal_entity_is_expanded(run_cli, tmp_path):
    text = urdf_with_doctype('<!DOCTYPE robot [<!ENTITY red "50">]>',
                             ARM.replace("<mechanicalReduction>50</mechanicalReduction>",
                                         "<mechanicalReduction>&red;</mechanicalReduction>"))
    text = text.replace("<mechanicalReduction>50</mechanicalReduction>", "")
    plain, ent = tmp_path / "plain.urdf", tmp_path / "entity.urdf"
    plain.write_text(ARM)
    ent.write_text(text)
    A = structure_matrix(run_cli, ent)
    assert A == structure_matrix(run_cli, plain)
    assert A[1][1] == 50.0


def test_internal_entity_changes_the_value(run_cli, tmp_path):
    """The entity's value is used (not a default): 40 instead of 50 shows in the matrix."""
    text = urdf_with_doctype('<!DOCTYPE robot [<!ENTITY red "40">]>',
                             ARM.replace("<mechanicalReduction>50</mechanicalReduction>",
                                         "<mechanicalReduction>&red;</mechanicalReduction>"))
    path = tmp_path / "entity40.urdf"
    path.write_text(text)
    assert structure_matrix(run_cli, path)[1][1] == 40.0


@pytest.mark.parametrize("decl", ['<!ENTITY red SYSTEM "{target}">', '<!ENTITY red PUBLIC "-//x//y" "{target}">'])
def test_external_entity_refused_and_not_read(tmp_path, decl):
    """The entity points at a FIFO: reading it would block (the subprocess would time out)
    or show its content; neither happens, and the message names the entity and its line."""
    import os
    fifo = tmp_path / "secret.fifo"
    os.mkfifo(fifo)
    text = urdf_with_doctype("<!DOCTYPE robot [\n" + decl.format(target=fifo) + "\n]>",
                             ARM.replace("<mechanicalReduction>50</mechanicalReduction>",
                                         "<mechanicalReduction>&red;</mechanicalReduction>"))
    line = bad_subprocess(tmp_path, text, 3, "DOCTYPE", r"^external entity 'red'.* is refused: gearcli reads "
                          "nothing but the file itself$", name="ext.urdf", timeout=60)
    assert "secret" in line  # names the target path, which it did not open


def test_external_entity_to_existing_file_not_read(run_cli, tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("TOP-SECRET-CONTENT\n")
    text = urdf_with_doctype(f'<!DOCTYPE robot [<!ENTITY red SYSTEM "file://{secret}">]>',
                             ARM.replace("<mechanicalReduction>50</mechanicalReduction>",
                                         "<mechanicalReduction>&red;</mechanicalReduction>"))
    line = bad(run_cli, tmp_path, text, 2, "DOCTYPE", "^external entity 'red'", name="ext.urdf")
    assert "TOP-SECRET" not in line


def test_external_entity_in_attribute_refused(run_cli, tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("TOP-SECRET-CONTENT\n")
    text = urdf_with_doctype(f'<!DOCTYPE robot [<!ENTITY red SYSTEM "file://{secret}">]>',
                             ARM.replace('<robot name="geared_arm"', '<robot name="&red;"'))
    line = bad(run_cli, tmp_path, text, line_of(text, "&red;"), "",
               "^malformed XML: Attribute references external entity 'red'$", name="ext.urdf")
    assert "TOP-SECRET" not in line


def test_external_parameter_entity_and_dtd_not_read(run_cli, tmp_path):
    import os
    fifo = tmp_path / "dtd.fifo"
    os.mkfifo(fifo)
    text = urdf_with_doctype(f'<!DOCTYPE robot SYSTEM "{fifo}" [<!ENTITY % p SYSTEM "{fifo}"> %p;]>')
    bad_subprocess(tmp_path, text, 2, "DOCTYPE", "^external entity 'p'", name="pe.urdf", timeout=60)


def test_xinclude_is_never_processed(run_cli, tmp_path):
    """An <xi:include> of a file holding a link is ignored: the robot is unchanged."""
    extra = tmp_path / "extra.xml"
    extra.write_text('<link name="intruder"/>')
    text = ARM.replace('<link name="base_link"/>', '<link name="base_link"/>\n  <xi:include '
                       f'xmlns:xi="http://www.w3.org/2001/XInclude" href="{extra}"/>')
    path = tmp_path / "xi.urdf"
    path.write_text(text)
    from gearcli import load_mechanism
    assert "intruder" not in load_mechanism(path).link_names


def test_entity_bomb(run_cli, tmp_path):
    ents = '<!ENTITY a "lollollollollol">' + "".join(
        f'<!ENTITY {c} "{("&" + p + ";") * 10}">' for p, c in zip("abcdefghi", "bcdefghij"))
    text = urdf_with_doctype(f"<!DOCTYPE robot [{ents}]>", ARM.replace('<robot name="geared_arm"', '<robot name="&j;"'))
    path = tmp_path / "bomb.urdf"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2 and "Traceback" not in res.stderr
    assert len(res.stderr.splitlines()) == 1 and res.stderr.startswith(f"{path}:")
    assert len(res.stderr) < 600 + len(str(path))


def test_undeclared_entity(run_cli, tmp_path):
    text = ARM.replace('<robot name="geared_arm"', '<robot name="&nope;"')
    bad(run_cli, tmp_path, text, line_of(text, "&nope;"), "", "malformed XML: Entity 'nope' not defined",
        name="u.urdf")


@pytest.mark.parametrize("old,new,place,reason", [
    ('<axis xyz="0 0 1"/>\n  </joint>\n\n  <joint name="pinion_joint"',
     '<axis xyz="1e308 0 0"/>\n  </joint>\n\n  <joint name="pinion_joint"', "joint 'shoulder'",
     r'^xyz="1e308 0 0": 1e\+308 is out of range \(\|x\| <= 1e12 in SI units\)$'),
    ('<origin xyz="0.4 0 0" rpy="0 0 0"/>', '<origin xyz="0.4 0 0" rpy="0 0 1e300"/>', "joint 'elbow'",
     r'^rpy="0 0 1e300": 1e\+300 is out of range'),
    ('pressure_angle_deg="20"', 'pressure_angle_deg="2e20"', "joint 'pinion_joint'.gearcli:gear",
     r'^pressure_angle_deg="2e20": 2e\+20 is out of range'),
    ('<mimic joint="shoulder" multiplier="-3"', '<mimic joint="shoulder" multiplier="-3e20"',
     "joint 'pinion_joint'.mimic", r'^multiplier="-3e20": -3e\+20 is out of range'),
    ("<mechanicalReduction>50</mechanicalReduction>", "<mechanicalReduction>5e20</mechanicalReduction>",
     "transmission 'elbow_trans'", r"mechanicalReduction.* 5e\+20 is out of range"),
    ("<mechanicalReduction>50</mechanicalReduction>", "<mechanicalReduction>1" + "0" * 400 + "</mechanicalReduction>",
     "transmission 'elbow_trans'", r"mechanicalReduction.* must be a finite nonzero number"),
])
def test_urdf_number_out_of_range(run_cli, tmp_path, old, new, place, reason):
    assert ARM.count(old) == 1, old
    text = ARM.replace(old, new)
    needle = {"joint 'shoulder'": "1e308", "joint 'elbow'": "1e300", "joint 'pinion_joint'.gearcli:gear": "2e20",
              "joint 'pinion_joint'.mimic": "-3e20", "transmission 'elbow_trans'": '<transmission name="elbow_trans"'}
    bad(run_cli, tmp_path, text, line_of(text, needle[place]), place, reason, name="n.urdf")


@pytest.mark.parametrize("old,new,place,reason", [
    ('<limit lower="-2.6" upper="2.6"', '<limit lower="-2_6" upper="2.6"', "joint 'elbow'.limit",
     r'^lower="-2_6" is not a finite number$'),
    ('<limit lower="-2.6" upper="2.6"', '<limit lower="-2.6" upper="nan"', "joint 'elbow'.limit",
     r'^upper="nan" is not a finite number$'),
    ("<mechanicalReduction>50</mechanicalReduction>", "<mechanicalReduction>5_0</mechanicalReduction>",
     "transmission 'elbow_trans'", r"mechanicalReduction '5_0' is not a number"),
])
def test_urdf_numbers_float_would_misread(run_cli, tmp_path, old, new, place, reason):
    """Python's float() takes "-2_6" as -26 and "5_0" as 50, and a NaN position limit: a
    joint limit of -26 rad, a reduction of 50 instead of 5, a limit that never stops
    simulate, all silently (exit 0).  Each is now a located error."""
    assert ARM.count(old) == 1, old
    text = ARM.replace(old, new)
    needle = new.split(">")[0] if "limit" in place else '<transmission name="elbow_trans"'
    bad(run_cli, tmp_path, text, line_of(text, needle), place, reason, name="n.urdf")


def test_urdf_mass_out_of_range(run_cli, tmp_path):
    text = ARM.replace('<mass value=', '<mass value="1e300" was=', 1)
    bad(run_cli, tmp_path, text, line_of(text, 'value="1e300"'), "link 'upper_arm'.inertial",
        r'^mass "1e300" 1e\+300 is out of range', name="m.urdf")


def test_urdf_5000_root_links_not_echoed(run_cli, tmp_path):
    links = "".join(f'<link name="orphan{i}"/>' for i in range(5000))
    text = ARM.replace('<link name="base_link"/>', '<link name="base_link"/>' + links)
    line = bad(run_cli, tmp_path, text, line_of(text, "<robot "), "",
               r"^several root links \(base_link, orphan0, orphan1, orphan2, orphan3 and 4996 more\)", name="r.urdf")
    assert "orphan4999" not in line


def test_urdf_100kB_name_not_echoed(run_cli, tmp_path):
    big = "n" * 100_000
    text = ARM.replace('<mimic joint="shoulder"', f'<mimic joint="{big}"')
    line = bad(run_cli, tmp_path, text, line_of(text, big), "joint 'pinion_joint'.mimic",
               "^joint 'pinion_joint' mimics unknown joint 'nnnn", name="big.urdf")
    assert big not in line


def test_urdf_deep_nesting(run_cli, tmp_path):
    text = ARM.replace('<link name="base_link"/>', '<link name="base_link"/>' + "<a>" * 5000 + "</a>" * 5000)
    bad(run_cli, tmp_path, text, line_of(text, "<a><a>"), "", "^malformed XML: ", name="deep.urdf")


def test_urdf_file_size_limit(run_cli, tmp_path):
    text = ARM + "<!--" + "x" * (17 * 2**20) + "-->\n"
    bad(run_cli, tmp_path, text, None, "", r"^file is larger than 16 MiB, the limit for a URDF file$", name="big.urdf")


def test_yourdfpy_prints_nothing(tmp_path):
    """A URDF that yourdfpy parses with its fallback (it logs 'Using different parsing
    approach.') gives exactly gearcli's output, nothing stray."""
    text = ARM.replace('<limit lower="-2.6" upper="2.6" effort="60" velocity="3"/>',
                       '<limit lower="-2.6" upper="2.6" effort="60" velocity="3"/><calibration rising="x"/>')
    path = tmp_path / "odd.urdf"
    path.write_text(text)
    res = subprocess.run([sys.executable, "-c", "import sys; sys.path.insert(0, sys.argv[1]); "
                          "from gearcli.cli import app; sys.argv = ['gearcli', 'check', sys.argv[2]]; app()",
                          str(ROOT / "src"), str(path)], capture_output=True, text=True, timeout=120)
    assert "Traceback" not in res.stderr
    lines = (res.stdout + res.stderr).splitlines()
    assert len(lines) == 1 and lines[0].startswith(str(path)), lines


def test_quiet_yourdfpy_silences_its_log_and_prints(capfd, caplog):
    import logging

    from gearcli.io.urdf_xml import quiet_yourdfpy
    with quiet_yourdfpy():
        logging.getLogger("yourdfpy.urdf").error("Using different parsing approach.")
        print("stray")
    out, err = capfd.readouterr()
    assert out == "" and err == "" and not caplog.records
    logging.getLogger("yourdfpy.urdf").error("visible again")
    assert [r.getMessage() for r in caplog.records] == ["visible again"]


# --------------------------------------------------------------------------------------
# truncated files: the line cited is one of the file's
# --------------------------------------------------------------------------------------
def test_truncated_file_without_final_newline_cites_its_last_line(run_cli, tmp_path):
    """libyaml puts the end of a stream without a final newline on the line after it."""
    text = "name: x\nlinks:\n  - {name: a, mass: 1"
    bad(run_cli, tmp_path, text, 3, "", "^YAML syntax error: \\S")   # gearcli's prefix and line; the rest is libyaml's
    bad(run_cli, tmp_path, "name: x\nlinks: [", 2, "", "^YAML syntax error: ")
    bad(run_cli, tmp_path, "name: x\nlinks: [\n", 3, "", "^YAML syntax error: ")   # the empty line after the newline


def test_every_truncation_cites_a_line_of_the_file():
    from gearcli.errors import MechanismError  # noqa: PLC0415
    from gearcli.io.yaml_reader import parse_mechanism  # noqa: PLC0415

    cuts = sorted({*range(1, len(PAPER), 23), *(i for i, c in enumerate(PAPER) if c in "[{:,")})
    beyond = []
    for cut in cuts:
        text = PAPER[:cut].rstrip("\n")
        last = text.count("\n") + 1
        try:
            parse_mechanism(text, "cut.yaml")
        except MechanismError as exc:
            beyond += [(cut, i.line, last, i.message) for i in exc.issues if i.line is not None and i.line > last]
    assert beyond == []


def test_alias_of_a_scalar_loads(run_cli, mech_dir, tmp_path):
    """A designer shares one mesh efficiency between pairs (``efficiency: &eta 0.985``, then
    ``efficiency: *eta``): an alias of a scalar is not recursive (it was refused as
    "refers to a node that contains it"), and an alias giving a pair both keys is the
    loss keys' own error."""
    text = (mech_dir / "servo_joint_rated.yaml").read_text()
    assert text.count("efficiency: 0.985") == 2
    text = text.replace("efficiency: 0.985", "efficiency: &eta 0.985", 1).replace("efficiency: 0.985", "efficiency: *eta")
    path = tmp_path / "servo.yaml"
    path.write_text(text)
    r, before = run_cli("check", path), run_cli("check", mech_dir / "servo_joint_rated.yaml")
    assert r.exit_code == 0, r.stderr
    assert r.stdout.splitlines()[1:] == before.stdout.splitlines()[1:]
    assert sum("efficiency 0.985 (loss factor 0.015)" in ln for ln in r.stdout.splitlines()) == 4   # 1 + 3 planets
    both = replaced("    ratio: -3.0 ", "    efficiency: &e 0.97\n    loss_factor: *e\n    ratio: -3.0 ")
    bad(run_cli, tmp_path, both, line_of(both, "loss_factor: *e"), "gears[0].loss_factor",
        r"^give efficiency or loss_factor \(= 1 - efficiency\), not both$")
