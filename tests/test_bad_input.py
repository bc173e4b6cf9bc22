"""Bad mechanism files: one line per problem on stderr, exit status 2, never a traceback.

Every case is derived from ``mechanisms/paper_2dof.yaml`` by a small text edit and checked
twice: through ``gearcli check`` (the exact one-line format ``file:line: yaml.path:
message``) and through the library (``MechanismError.issues`` with path and line).
"""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from gearcli import MechanismError, analyse, load_mechanism

PAPER = (Path(__file__).resolve().parents[1] / "mechanisms" / "paper_2dof.yaml").read_text()


# --------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------
def replaced(old: str, new: str, text: str = PAPER) -> str:
    """``text`` with the single occurrence of ``old`` replaced by ``new``."""
    assert text.count(old) == 1, f"{old!r} must occur once"
    return text.replace(old, new)


def inserted_before(marker: str, snippet: str, text: str = PAPER) -> str:
    """``text`` with ``snippet`` (whole lines) inserted before the line starting ``marker``."""
    return replaced(f"\n{marker}", f"\n{snippet}{marker}", text)


def line_of(text: str, needle: str, after: str | None = None) -> int:
    """1-based line of the first line containing ``needle`` (after the line with ``after``)."""
    lines = text.splitlines()
    start = 0 if after is None else line_of(text, after)
    for i in range(start, len(lines)):
        if needle in lines[i]:
            return i + 1
    raise AssertionError(f"{needle!r} not found")


def assert_bad(run_cli, tmp_path, text: str | bytes, expected: list[tuple[str, int | None, str]],
               name: str = "bad.yaml") -> list[str]:
    """Write ``text`` to ``tmp_path/name`` and check both the CLI and the library report
    exactly ``expected``: one (yaml path, line, message regex) per problem, in order."""
    path = tmp_path / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2, (res.stdout, res.stderr)
    assert res.stdout == ""
    assert "Traceback" not in res.stderr
    got = res.stderr.splitlines()
    assert len(got) == len(expected), got
    for line, (ypath, lineno, pattern) in zip(got, expected):
        where = f"{path}:{lineno}" if lineno is not None else f"{path}"
        prefix = f"{where}: {ypath}: " if ypath else f"{where}: "
        assert line.startswith(prefix), (line, prefix)
        assert re.search(pattern, line[len(prefix):]), (line, pattern)
    # the library raises the same issues
    with pytest.raises(MechanismError) as info:
        analyse(load_mechanism(path))
    issues = info.value.issues
    assert [str(i) for i in issues] == got
    assert [(i.path, i.line) for i in issues] == [(p, n) for p, n, _ in expected]
    assert all(i.file == str(path) for i in issues)
    return got


# --------------------------------------------------------------------------------------
# files, YAML and schema
# --------------------------------------------------------------------------------------
def test_missing_file(run_cli, tmp_path):
    path = tmp_path / "nope.yaml"
    res = run_cli("check", path)
    assert res.exit_code == 2
    assert res.stderr.splitlines() == [f"{path}: cannot read file: No such file or directory"]
    assert "Traceback" not in res.stderr


def test_directory_instead_of_file(run_cli, tmp_path):
    res = run_cli("check", tmp_path)
    assert res.exit_code == 2
    assert res.stderr.splitlines() == [f"{tmp_path}: not a regular file (a directory)"]


def test_not_utf8(run_cli, tmp_path):
    assert_bad(run_cli, tmp_path, b"\xff\xfename: x\n", [("", 1, "not a UTF-8 text file")])
    assert_bad(run_cli, tmp_path, b"name: x\nbase: a\ndescription: caf\xe9\n", [("", 3, r"not a UTF-8 text file \(byte 32\)")])


def test_empty_file(run_cli, tmp_path):
    assert_bad(run_cli, tmp_path, "", [("", None, "must be a YAML mapping")])


def test_top_level_list(run_cli, tmp_path):
    assert_bad(run_cli, tmp_path, "- a\n- b\n", [("", 1, "must be a YAML mapping")])


def test_yaml_syntax_error(run_cli, tmp_path):
    text = replaced("    mass: 4.0", "    mass: 4.0: kg")
    assert_bad(run_cli, tmp_path, text,
               [("", line_of(text, "4.0: kg"), r"^YAML syntax error: \S")])   # the problem text is libyaml's


def test_yaml_unclosed_flow_mapping(run_cli, tmp_path):
    text = replaced("dh: {theta_deg: 0, d: 0.0, a: 0.3, alpha_deg: 0}", "dh: {theta_deg: 0, d: 0.0, a: 0.3")
    lines = assert_bad(run_cli, tmp_path, text, [("", line_of(text, "name: J3"), "^YAML syntax error: ")])
    assert "expected ',' or '}'" in lines[0]


def test_duplicate_yaml_key(run_cli, tmp_path):
    text = replaced("    mass: 4.0\n", "    mass: 4.0\n    mass: 3.0\n")
    assert_bad(run_cli, tmp_path, text,
               [("links[1].mass", line_of(text, "mass: 3.0"), "^duplicate key 'mass'$")])


def test_schema_misspelt_key(run_cli, tmp_path):
    text = replaced("    mass: 4.0", "    mas: 4.0")
    assert_bad(run_cli, tmp_path, text,
               [("links[1].mas", line_of(text, "mas: 4.0"), r"unknown key 'mas' \(did you mean 'mass'\?\)")])


def test_many_problems_print_the_first_fifty_and_count_the_rest(run_cli, tmp_path):
    """20,000 unknown keys: 50 located lines and '… and 19,950 more problems' (the
    library's MechanismError keeps all 20,000)."""
    from gearcli.errors import MAX_SHOWN  # noqa: PLC0415

    n = 20_000
    text = PAPER + "".join(f"unknown_key_{i}: 1\n" for i in range(n))
    path = tmp_path / "many.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    got = res.stderr.splitlines()
    assert res.exit_code == 2 and MAX_SHOWN == 50 and len(got) == 51
    first = line_of(text, "unknown_key_0:")
    assert got[:50] == [f"{path}:{first + i}: unknown_key_{i}: unknown key 'unknown_key_{i}' (allowed: "
                        "name, description, gravity, base, end_effector, links, joints, gears, motors, loads, payloads)"
                        for i in range(50)]
    assert got[50] == "… and 19,950 more problems"
    with pytest.raises(MechanismError) as info:
        load_mechanism(path)
    assert len(info.value.issues) == n and len({i.path for i in info.value.issues}) == n


@pytest.mark.parametrize("n, last", [(50, None), (51, "… and 1 more problem"), (1_000, "… and 950 more problems")])
def test_shown_lines(n, last):
    from gearcli.errors import shown  # noqa: PLC0415

    lines = [f"f.yaml:{i}: x" for i in range(n)]
    out = shown(lines)
    assert out[:50] == lines[:50] and (out[50:] == [last] if last else len(out) == n)


def test_collector_adds_in_linear_time(monkeypatch):
    """Collector.add deduplicates through a set: adding n distinct issues compares a few,
    not n^2/2 (20,000 unknown keys took 2 min 19 s in check), and still drops repeats,
    also of issues a reader appended to ``issues`` directly."""
    from gearcli.errors import Collector, Issue  # noqa: PLC0415

    compared = []
    eq = Issue.__eq__
    monkeypatch.setattr(Issue, "__eq__", lambda a, b: compared.append(1) or eq(a, b))
    col = Collector("f.yaml", {"k0": 3})
    n = 3_000
    for i in range(n):
        col.add(f"k{i}", "unknown key")
    assert len(compared) < n
    col.issues.append(Issue("f.yaml", "direct", None, "appended"))
    for i in range(n):
        col.add(f"k{i}", "unknown key")
    col.add("direct", "appended")
    col.add("k0", "another problem")
    assert len(col.issues) == n + 2 and col.issues[0] == Issue("f.yaml", "k0", 3, "unknown key")
    assert col.issues[-1] == Issue("f.yaml", "k0", 3, "another problem")
    col.issues = []
    col.add("k1", "unknown key")
    assert len(col.issues) == 1


def test_schema_misspelt_nested_key(run_cli, tmp_path):
    text = replaced("dh: {theta_deg: 0, d: 0.0, a: 0.4", "dh: {theta_degs: 0, d: 0.0, a: 0.4")
    assert_bad(run_cli, tmp_path, text, [("joints[0].dh.theta_degs", line_of(text, "theta_degs"),
                                          "unknown key 'theta_degs' .*did you mean 'theta_deg'")])


def test_schema_wrong_type(run_cli, tmp_path):
    text = replaced("    mass: 4.0", "    mass: heavy")
    assert_bad(run_cli, tmp_path, text,
               [("links[1].mass", line_of(text, "mass: heavy"), r"^expected a number, got a string \('heavy'\)$")])


def test_schema_link_name_not_a_string(run_cli, tmp_path):
    text = replaced('  - name: "1"  ', "  - name: 1  ")
    assert_bad(run_cli, tmp_path, text,
               [("links[1].name", line_of(text, "- name: 1 "), r"^expected a string, got a number \(1\)$")])


def test_schema_bad_enum(run_cli, tmp_path):
    text = replaced("    kind: external", "    kind: spur")
    assert_bad(run_cli, tmp_path, text,
               [("gears[0].kind", line_of(text, "kind: spur"), r"^expected one of: external, internal, bevel, rack; got 'spur'$")])


def test_schema_missing_required_top_level_key(run_cli, tmp_path):
    text = replaced('end_effector: "2"\n', "")
    assert_bad(run_cli, tmp_path, text,
               [("", line_of(text, "name: paper_2dof"), "^missing required key 'end_effector'$")])


def test_schema_missing_required_key_in_item(run_cli, tmp_path):
    text = replaced('    parent: "1"\n    child: "2"\n', '    parent: "1"\n')
    assert_bad(run_cli, tmp_path, text,
               [("joints[1]", line_of(text, "- name: J2"), "^missing required key 'child'$")])


def test_schema_inertia_mapping_errors(run_cli, tmp_path):
    text = replaced("izz: 0.00003}", "izzz: 0.00003}")
    line = line_of(text, "izzz")
    assert_bad(run_cli, tmp_path, text, [
        ("links[5].inertia.izzz", line, r"unknown key 'izzz' \(did you mean 'izz'\?\)"),
        ("links[5].inertia", line, "^missing required key 'izz'$"),
    ])


def test_schema_short_vector(run_cli, tmp_path):
    text = replaced("mesh_point: [0.09, 0, -0.05]", "mesh_point: [0.09, 0]")
    assert_bad(run_cli, tmp_path, text,
               [("gears[0].mesh_point", line_of(text, "mesh_point: [0.09, 0]"), r"^expected 3 numbers, got 2$")])


@pytest.mark.parametrize("value", [".nan", ".inf", "-.inf"])
def test_non_finite_number(run_cli, tmp_path, value):
    text = replaced("    mass: 4.0", f"    mass: {value}")
    assert_bad(run_cli, tmp_path, text,
               [("links[1].mass", line_of(text, f"mass: {value}"), "is not a finite number")])


# --------------------------------------------------------------------------------------
# names
# --------------------------------------------------------------------------------------
def test_unknown_link_in_joint(run_cli, tmp_path):
    text = replaced('    child: "4"', '    child: "44"')
    assert_bad(run_cli, tmp_path, text,
               [("joints[3].child", line_of(text, 'child: "44"'), "^unknown link '44'$")])


def test_unknown_link_in_gear(run_cli, tmp_path):
    text = replaced('links: ["4", "2"]', 'links: ["4", "x"]')
    assert_bad(run_cli, tmp_path, text,
               [("gears[2].links[1]", line_of(text, '["4", "x"]'), "^unknown link 'x'$")])


def test_unknown_link_in_motor(run_cli, tmp_path):
    text = replaced('    link: "5"', '    link: "55"')
    assert_bad(run_cli, tmp_path, text,
               [("motors[1].link", line_of(text, 'link: "55"'), "^unknown link '55'$")])


def test_unknown_end_effector(run_cli, tmp_path):
    text = replaced('end_effector: "2"', 'end_effector: "9"')
    assert_bad(run_cli, tmp_path, text, [("end_effector", 9, "^unknown link '9'$")])


def test_duplicate_link_name(run_cli, tmp_path):
    text = inserted_before("\njoints:", '  - {name: "4", mass: 0.1}\n')
    assert_bad(run_cli, tmp_path, text, [
        ("links[6].name", line_of(text, '{name: "4", mass: 0.1}'), r"duplicate link name '4' \(first at links\[4\]\)"),
    ])


def test_duplicate_joint_name(run_cli, tmp_path):
    text = replaced("  - name: J5 ", "  - name: J4 ")
    assert_bad(run_cli, tmp_path, text, [
        ("joints[4].name", line_of(text, "name: J4", after="name: J4"),
         r"duplicate joint name 'J4' \(first at joints\[3\]\)"),
    ])


def test_duplicate_gear_pair_name(run_cli, tmp_path):
    text = replaced('  - name: "4-2"', '  - name: "3-4"')
    assert_bad(run_cli, tmp_path, text, [
        ("gears[2].name", line_of(text, '- name: "3-4"', after='- name: "3-4"'),
         r"duplicate gear pair name '3-4' \(first at gears\[1\]\)"),
    ])


# --------------------------------------------------------------------------------------
# links: masses and inertias
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("mass", ["0", "-1.5"])
def test_non_positive_mass(run_cli, tmp_path, mass):
    text = replaced("    mass: 4.0", f"    mass: {mass}")
    assert_bad(run_cli, tmp_path, text,
               [("links[1].mass", line_of(text, f"mass: {mass}"), f"^mass must be positive, got {re.escape(mass)} kg$")])


def test_missing_mass(run_cli, tmp_path):
    text = replaced("    mass: 0.3\n", "")
    assert_bad(run_cli, tmp_path, text, [("links[4]", line_of(text, '- name: "4"'), "^link '4' has no mass$")])


def test_inertia_not_positive_definite(run_cli, tmp_path):
    text = replaced("inertia: [0.005, 0.06, 0.06]", "inertia: [-0.005, 0.06, 0.06]")
    assert_bad(run_cli, tmp_path, text, [("links[1].inertia", line_of(text, "[-0.005, 0.06, 0.06]"),
                                          "^inertia tensor is not positive semi-definite")])


def test_inertia_products_not_positive_definite(run_cli, tmp_path):
    # eigenvalues of [[1, 2, 0], [2, 1, 0], [0, 0, 1]] mg*m^2 are -1, 1, 3
    text = replaced("{ixx: 0.00005, iyy: 0.00005, izz: 0.00003}",
                    "{ixx: 0.001, iyy: 0.001, izz: 0.001, ixy: 0.002}")
    assert_bad(run_cli, tmp_path, text, [("links[5].inertia", line_of(text, "ixy: 0.002"),
                                          "^inertia tensor is not positive semi-definite")])


def test_inertia_triangle_inequality(run_cli, tmp_path):
    text = replaced("inertia: [0.005, 0.06, 0.06]", "inertia: [0.005, 0.06, 0.07]")
    assert_bad(run_cli, tmp_path, text, [("links[1].inertia", line_of(text, "[0.005, 0.06, 0.07]"),
                                          r"violate the triangle inequality \(I1 \+ I2 >= I3\)")])


# --------------------------------------------------------------------------------------
# joints
# --------------------------------------------------------------------------------------
def test_link_not_connected_to_base(run_cli, tmp_path):
    text = inserted_before("\njoints:", '  - {name: "6", mass: 0.1}\n')
    assert_bad(run_cli, tmp_path, text, [("links[6]", line_of(text, 'name: "6"'),
                                          "^link '6' is not connected to the base '0' by joints$")])


def test_closed_loop_of_joints(run_cli, tmp_path):
    text = inserted_before("\ngears:", '  - {name: J6, parent: "1", child: "5", origin: {xyz: [-0.28, 0, -0.05]}}\n')
    assert_bad(run_cli, tmp_path, text, [("joints[5]", line_of(text, "name: J6"),
                                          "joint 'J6' closes a loop of joints between links '1' and '5'")])


def test_joint_written_child_to_parent(run_cli, tmp_path):
    text = replaced('    parent: "1"\n    child: "4"', '    parent: "4"\n    child: "1"')
    # J4 now hangs 1 from 4, and 4 from nothing
    lines = assert_bad(run_cli, tmp_path, text, [
        ("joints[3].parent", line_of(text, 'parent: "4"'), "written from child to parent"),
    ])
    assert "'4'" in lines[0]


def test_joint_to_itself(run_cli, tmp_path):
    text = replaced('    parent: "1"\n    child: "4"', '    parent: "4"\n    child: "4"')
    assert_bad(run_cli, tmp_path, text, [
        ("joints[3].child", line_of(text, 'child: "4"'), "cannot connect a link to itself"),
    ])


def test_dh_and_origin_both_given(run_cli, tmp_path):
    text = replaced("    dh: {theta_deg: 0, d: 0.0, a: 0.4, alpha_deg: 0}\n",
                    "    dh: {theta_deg: 0, d: 0.0, a: 0.4, alpha_deg: 0}\n    origin: {xyz: [0, 0, 0]}\n")
    assert_bad(run_cli, tmp_path, text, [("joints[0].origin", line_of(text, "origin: {xyz: [0, 0, 0]}"),
                                          "either as dh or as origin/axis, not both")])


def test_theta_and_theta_deg_both_given(run_cli, tmp_path):
    text = replaced("dh: {theta_deg: 0, d: 0.0, a: 0.4", "dh: {theta: 0, theta_deg: 0, d: 0.0, a: 0.4")
    assert_bad(run_cli, tmp_path, text, [("joints[0].dh.theta_deg", line_of(text, "theta: 0, theta_deg"),
                                          r"give either theta \(rad\) or theta_deg, not both")])


def test_zero_axis(run_cli, tmp_path):
    text = replaced("    axis: [1, 0, 0]", "    axis: [0, 0, 0]")
    assert_bad(run_cli, tmp_path, text, [("joints[3].axis", line_of(text, "axis: [0, 0, 0]"),
                                          "must not be the zero vector")])


# --------------------------------------------------------------------------------------
# gear pairs
# --------------------------------------------------------------------------------------
def test_gear_links_share_no_carrier(run_cli, tmp_path):
    text = inserted_before("\nmotors:", '  - {name: "5-2", links: ["5", "2"], ratio: 1.0}\n')
    assert_bad(run_cli, tmp_path, text, [("gears[3].links", line_of(text, 'name: "5-2"'),
                                          "gears '5' and '2' share no carrier")])


def test_gear_wrong_explicit_carrier(run_cli, tmp_path):
    text = replaced("    ratio: -3.0 ", '    carrier: "2"\n    ratio: -3.0 ')
    assert_bad(run_cli, tmp_path, text, [("gears[0].carrier", line_of(text, 'carrier: "2"'),
                                          r"'2' cannot carry gears '5' and '1'.*\(possible carrier: 0\)")])


def test_gear_same_link_twice(run_cli, tmp_path):
    text = replaced('links: ["5", "1"]', 'links: ["5", "5"]')
    assert_bad(run_cli, tmp_path, text, [("gears[0].links", line_of(text, '["5", "5"]'),
                                          "needs two different links")])


@pytest.mark.parametrize("ratio", ["-2.5", "3.0"])
def test_ratio_contradicts_geometry(run_cli, tmp_path, ratio):
    text = replaced("    ratio: -3.0 ", f"    ratio: {ratio} ")
    assert_bad(run_cli, tmp_path, text, [
        ("gears[0].ratio", line_of(text, f"ratio: {ratio}"),
         f"ratio {float(ratio):g} contradicts the mesh geometry: pitch radii 0.03 m and 0.09 m give e = -3"),
    ])


def test_cone_angle_contradicts_geometry(run_cli, tmp_path):
    text = replaced("cone_angles_deg: [45, 45]", "cone_angles_deg: [45, 50]")
    assert_bad(run_cli, tmp_path, text, [
        ("gears[1].cone_angles_deg[1]", line_of(text, "[45, 50]"),
         "cone angle 50 deg of gear '4' contradicts the geometry \\(45 deg\\)"),
    ])


def test_cone_angles_on_spur_pair(run_cli, tmp_path):
    text = replaced("    pressure_angle_deg: 20\n", "    pressure_angle_deg: 20\n    cone_angles_deg: [10, 80]\n")
    assert_bad(run_cli, tmp_path, text, [("gears[0].cone_angles_deg", line_of(text, "[10, 80]"),
                                          "cone angles are only for bevel gears, this pair is external")])


def test_teeth_contradict_geometry(run_cli, tmp_path):
    text = replaced("teeth: [20, 40]", "teeth: [20, 30]")
    assert_bad(run_cli, tmp_path, text, [
        ("gears[2].teeth", line_of(text, "[20, 30]"),
         "tooth counts 20:30 give |ratio| 1.5, but the mesh geometry gives 2"),
    ])


# pinion 5 moved inside the gear of link 1: the mesh point lies on the same side of both
# axes (a ring gear on link 1); tooth counts instead of the now wrong signed ratio
INTERNAL = replaced("    ratio: -3.0 ", "    teeth: [30, 90]  ",
                    replaced("origin: {xyz: [0.12, 0, -0.05]}", "origin: {xyz: [0.06, 0, -0.05]}"))


def test_internal_geometry_is_accepted(run_cli, tmp_path):
    path = tmp_path / "ring.yaml"
    path.write_text(replaced("kind: external", "kind: internal", INTERNAL))
    res = run_cli("check", path)
    assert res.exit_code == 0, res.stderr
    an = analyse(load_mechanism(path))
    assert an.circuits[0].ratio == pytest.approx(3.0)  # a ring turns with its pinion


def test_external_kind_for_internal_geometry(run_cli, tmp_path):
    assert_bad(run_cli, tmp_path, INTERNAL, [
        ("gears[0].kind", line_of(INTERNAL, "kind: external"),
         "external pair, but the mesh point lies on the same side of both axes"),
    ])


@pytest.mark.parametrize("kind, message", [
    ("internal", "internal pair, but the mesh point lies between the two axes"),
    ("bevel", "bevel gears need intersecting axes, these axes are parallel"),
])
def test_kind_contradicts_external_geometry(run_cli, tmp_path, kind, message):
    text = replaced("kind: external", f"kind: {kind}")
    assert_bad(run_cli, tmp_path, text, [("gears[0].kind", line_of(text, f"kind: {kind}"), message)])


def test_spur_kind_for_intersecting_axes(run_cli, tmp_path):
    text = replaced('    links: ["4", "2"]\n    kind: bevel', '    links: ["4", "2"]\n    kind: external')
    assert_bad(run_cli, tmp_path, text, [("gears[2].kind", line_of(text, "kind: external", after='name: "4-2"'),
                                          "external gears need parallel axes, these axes intersect")])


def test_skew_gear_axes(run_cli, tmp_path):
    text = replaced("    axis: [0, 0, 1]", "    axis: [0, 1, 0]")  # pinion 5 about y0
    assert_bad(run_cli, tmp_path, text, [
        ("gears[0].mesh_point", line_of(text, "mesh_point: [0.09, 0, -0.05]"),
         r"the gear axes are skew \(they miss each other by 0.12 m\)"),
    ])


def test_mesh_point_on_axis(run_cli, tmp_path):
    text = replaced("mesh_point: [0.09, 0, -0.05]", "mesh_point: [0, 0, -0.05]")
    assert_bad(run_cli, tmp_path, text, [("gears[0].mesh_point", line_of(text, "[0, 0, -0.05]"),
                                          "mesh point lies on the axis of gear '1'")])


def test_mesh_point_off_line_of_centres(run_cli, tmp_path):
    text = replaced("mesh_point: [0.09, 0, -0.05]", "mesh_point: [0.09, 0.01, -0.05]")
    assert_bad(run_cli, tmp_path, text, [("gears[0].mesh_point", line_of(text, "[0.09, 0.01, -0.05]"),
                                          "not on the line of centres")])


def test_bevel_mesh_point_off_plane(run_cli, tmp_path):
    text = replaced("mesh_point: [-0.37, 0, 0.08]", "mesh_point: [-0.37, 0.01, 0.08]")
    assert_bad(run_cli, tmp_path, text, [("gears[1].mesh_point", line_of(text, "[-0.37, 0.01, 0.08]"),
                                          "not in the plane of the two gear axes")])


def test_redundant_duplicate_gear_pair(run_cli, tmp_path):
    """A duplicated pair is a redundant gear set (issue 9): accepted, its load shared by mesh
    stiffness, the two pairs (and no other) named in a note."""
    text = inserted_before("\nmotors:", '  - {name: "5-1b", links: ["5", "1"], ratio: -3.0, '
                                        "mesh_point: [0.09, 0, -0.05]}\n")
    path = tmp_path / "dup.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 0, res.stderr
    assert res.stdout.splitlines()[1:] == ["note: redundant gear set '5-1', '5-1b': load shared by mesh "
                                           "stiffness, min sum t^2/k (equal stiffness)"]


def test_redundant_second_mesh_between_same_gears(run_cli, tmp_path):
    # a second, geometrically consistent mesh between 5 and 1, 10 mm lower: shared load
    text = inserted_before("\nmotors:", '  - {name: "5-1low", links: ["5", "1"], teeth: [20, 60], '
                                        "mesh_point: [0.09, 0, -0.06]}\n")
    path = tmp_path / "low.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 0, res.stderr
    assert "2 dof" in res.stdout.splitlines()[0]
    assert res.stdout.splitlines()[1].startswith("note: redundant gear set '5-1', '5-1low': ")


@pytest.mark.parametrize("value", ["0", "-2.0e8", ".nan", ".inf"])
def test_mesh_stiffness_not_positive_or_finite(run_cli, tmp_path, value):
    text = replaced("    ratio: -3.0   ", f"    stiffness: {value}\n    ratio: -3.0   ")
    reason = "mesh stiffness must be positive" if value in ("0", "-2.0e8") else "not a finite number|finite"
    assert_bad(run_cli, tmp_path, text, [("gears[0].stiffness", line_of(text, "stiffness:"), reason)])


# --------------------------------------------------------------------------------------
# motors
# --------------------------------------------------------------------------------------
def test_one_motor_missing(run_cli, tmp_path):
    text = replaced('  - name: motor5\n    link: "5"\n', "")
    assert_bad(run_cli, tmp_path, text, [("motors", line_of(text, "motors:"),
                                          r"^1 motor for 2 degrees of freedom")])


def test_one_motor_extra(run_cli, tmp_path):
    text = PAPER + '  - {name: motor4, link: "4"}\n'
    assert_bad(run_cli, tmp_path, text, [("motors", line_of(text, "motors:"),
                                          r"^3 motors for 2 degrees of freedom")])


def test_motors_not_driving_every_dof(run_cli, tmp_path):
    # both motors on shaft 3: nothing drives the second degree of freedom
    text = replaced('    link: "5"', '    link: "3"')
    assert_bad(run_cli, tmp_path, text, [("motors", line_of(text, "motors:"),
                                          "do not drive every degree of freedom")])


def test_motor_on_base(run_cli, tmp_path):
    text = replaced('    link: "5"', '    link: "0"')
    assert_bad(run_cli, tmp_path, text, [("motors[1].link", line_of(text, 'link: "0"'),
                                          "a motor cannot drive the base")])


def test_motor_stator_off_axis(run_cli, tmp_path):
    text = replaced('    link: "5"\n', '    link: "5"\n    stator: "1"\n')
    assert_bad(run_cli, tmp_path, text, [("motors[1].stator", line_of(text, 'stator: "1"'),
                                          "stator link '1' does not share the axis of input link '5'")])


# --------------------------------------------------------------------------------------
# several problems at once: all reported, one line each, in file order
# --------------------------------------------------------------------------------------
def test_several_problems_one_line_each(run_cli, tmp_path):
    text = replaced("    mass: 0.5", "    mass: -0.5", replaced("    mass: 4.0", "    mass: 0"))
    assert_bad(run_cli, tmp_path, text, [
        ("links[1].mass", line_of(text, "    mass: 0"), "must be positive"),
        ("links[3].mass", line_of(text, "mass: -0.5"), "must be positive"),
    ])
