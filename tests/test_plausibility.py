"""Plausibility warnings: a mechanism in mm and a trajectory in degrees read as radians are
valid input that gearcli warns about (file, line, place), and refuses under --strict; the
bundled files give no warning."""
from __future__ import annotations

import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from gearcli.dynamics.determinacy import analyse
from gearcli.io import load_mechanism
from gearcli.io.trajectory import TrajectoryReader
from gearcli.model.mechanism import Link
from gearcli.model.plausibility import (MAX_DENSITY, MIN_DENSITY, ellipsoid_density, link_density,
                                        sphere_density)
from gearcli.report.unit_warnings import RateWatch, mechanism_issues

MECH_DIR = Path(__file__).resolve().parents[1] / "mechanisms"
BUNDLED = sorted(MECH_DIR.glob("*.yaml")) + sorted(MECH_DIR.glob("*.urdf"))


def _scaled(match, factor):
    return match.group(1) + ", ".join(repr(float(x) * factor) for x in match.group(2).split(",")) + match.group(3)


def to_mm(text: str) -> str:
    """A mechanism file with its lengths in mm and its inertias in kg*mm^2 (masses in kg),
    line for line (comments kept)."""
    out = []
    for line in text.splitlines(keepends=True):
        code, hash_, comment = line.partition("#")
        code = re.sub(r"((?:com|xyz|mesh_point): \[)([^\]]*)(\])", lambda m: _scaled(m, 1e3), code)
        code = re.sub(r"(inertia: \[)([^\]]*)(\])", lambda m: _scaled(m, 1e6), code)
        code = re.sub(r"\b(i(?:xx|yy|zz|xy|xz|yz)): ([-0-9.e]+)", lambda m: f"{m.group(1)}: {float(m.group(2)) * 1e6!r}", code)
        code = re.sub(r"\b(d|a): ([-0-9.e]+)", lambda m: f"{m.group(1)}: {float(m.group(2)) * 1e3!r}", code)
        out.append(code + hash_ + comment)
    return "".join(out)


def to_degrees(src: Path, dst: Path, linear=()) -> None:
    """The trajectory ``src`` with its angle columns (q, qd, qdd of revolute joints) in degrees."""
    lines = src.read_text().splitlines()
    header = lines[0].split(",")
    angle = [h.split(":")[0] in ("q", "qd", "qdd") and h.split(":")[1] not in linear for h in header]
    rows = [",".join(repr(math.degrees(float(x))) if a else x for x, a in zip(r.split(","), angle)) for r in lines[1:]]
    dst.write_text("\n".join([lines[0]] + rows) + "\n")


def line_of(path: Path, text: str) -> int:
    """1-based number of the first line of ``path`` containing ``text``."""
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if text in line)


@pytest.fixture
def mm_file(tmp_path) -> Path:
    p = tmp_path / "paper_2dof_mm.yaml"
    p.write_text(to_mm((MECH_DIR / "paper_2dof.yaml").read_text()))
    return p


def test_mm_mechanism_warns_with_file_line_and_place(run_cli, mm_file):
    r = run_cli("check", mm_file)
    assert r.exit_code == 0, r.stderr
    assert "OK" in r.stdout
    lines = r.stderr.splitlines()
    inertia = line_of(mm_file, "inertia: [5000.0, 60000.0")
    dens = [x for x in lines if x.startswith(f"{mm_file}:{inertia}: links[1].inertia: warning: ")]
    assert len(dens) == 1 and "lighter than air" in dens[0] and "kg/m^3" in dens[0]
    dh = line_of(mm_file, "a: 400.0")
    assert any(x.startswith(f"{mm_file}:{dh}: joints[0].dh: warning: joint 'J1': offset [400, 0, 0] m") for x in lines)
    assert all(": warning: " in x for x in lines)
    assert f"{mm_file}: warning: 7 more lengths above 10 m" in lines   # 10 lengths, 3 shown


@pytest.mark.parametrize("command", ["check", "solve", "graph"])
def test_mm_mechanism_is_an_error_under_strict(run_cli, mm_file, tmp_path, command):
    out = tmp_path / "out.csv"
    extra = [MECH_DIR / "paper_2dof_traj.csv", "-o", out] if command == "solve" else []
    r = run_cli(command, mm_file, *extra, "--strict")
    assert r.exit_code == 2
    assert r.stdout == "" and not out.exists()
    lines = r.stderr.splitlines()
    inertia = line_of(mm_file, "inertia: [5000.0, 60000.0")
    assert any(x.startswith(f"{mm_file}:{inertia}: links[1].inertia: link '1': ") and x.endswith("(--strict)")
               for x in lines)
    assert not any("warning" in x for x in lines)


def test_degrees_trajectory_warns_and_suggests_degrees(run_cli, tmp_path):
    traj = tmp_path / "deg.csv"
    to_degrees(MECH_DIR / "planetary_3p_traj.csv", traj)
    r = run_cli("solve", MECH_DIR / "planetary_3p.yaml", traj, "-o", tmp_path / "out.csv")
    assert r.exit_code == 0, r.stderr
    lines = r.stderr.splitlines()
    # qd:JC is a column of this file: the warning names it and the row of its first fast sample
    rate = [x for x in lines if x.startswith(f"{traj}:2: column 3 'qd:JC': warning: joint 'JC' turns at 727.5 rad/s")]
    assert len(rate) == 1 and rate[0].endswith("is the trajectory in degrees? (give --degrees)")
    motor = [x for x in lines if "motor 'motor' turns at" in x]
    assert len(motor) == 1 and motor[0].startswith(f"{traj}:2: sample t = 0 s: warning: ")
    q = np.loadtxt(traj, delimiter=",", skiprows=1)[:, 1]
    first = int(np.argmax(np.abs(q) > 4 * math.pi)) + 2      # the file line of the first angle beyond two turns
    assert any(x.startswith(f"{traj}:{first}: column 2 'q:JC': warning: joint 'JC' at ") for x in lines)
    assert len(lines) == 3


def test_degrees_trajectory_derived_rates_name_their_column(run_cli, tmp_path):
    traj = tmp_path / "deg.csv"
    to_degrees(MECH_DIR / "paper_2dof_traj.csv", traj)
    r = run_cli("solve", MECH_DIR / "paper_2dof.yaml", traj, "-o", tmp_path / "out.csv")
    assert r.exit_code == 0
    assert any(x.startswith(f"{traj}:") and "qd:J1 (derived from column 2 'q:J1'): warning: joint 'J1' turns at"
               in x for x in r.stderr.splitlines())


def test_degrees_trajectory_is_an_error_under_strict(run_cli, tmp_path):
    traj, out = tmp_path / "deg.csv", tmp_path / "out.csv"
    to_degrees(MECH_DIR / "paper_2dof_traj.csv", traj)
    r = run_cli("solve", MECH_DIR / "paper_2dof.yaml", traj, "-o", out, "--strict")
    assert r.exit_code == 2
    assert not out.exists()
    lines = r.stderr.splitlines()
    assert lines and all(x.startswith(f"{traj}:") and x.endswith("(--strict)") for x in lines)
    assert any("column 3 'q:J2'" in x for x in lines)


def test_degrees_trajectory_read_with_degrees_is_quiet(run_cli, tmp_path):
    traj = tmp_path / "deg.csv"
    to_degrees(MECH_DIR / "paper_2dof_traj.csv", traj)
    r = run_cli("solve", MECH_DIR / "paper_2dof.yaml", traj, "--degrees", "--strict", "-o", tmp_path / "out.csv")
    assert r.exit_code == 0 and r.stderr == ""


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: p.name)
def test_bundled_mechanisms_give_no_warning(run_cli, path):
    r = run_cli("check", path, "--strict")
    assert r.exit_code == 0 and r.stderr == "", r.stderr


@pytest.mark.parametrize("traj", sorted(MECH_DIR.glob("*_traj.csv")), ids=lambda p: p.name)
def test_bundled_trajectories_give_no_warning(run_cli, traj, tmp_path):
    stem = traj.name.removesuffix("_traj.csv")
    mech = next(p for p in BUNDLED if p.stem == stem)
    r = run_cli("solve", mech, traj, "--strict", "-o", tmp_path / "out.npz")
    assert r.exit_code == 0 and r.stderr == "", r.stderr


def test_rate_watch_bounds_on_the_bundled_trajectories():
    """The bundled trajectories are well inside the rate bounds; in degrees, every one with a
    revolute joint is caught (the margin both ways)."""
    for traj in sorted(MECH_DIR.glob("*_traj.csv")):
        mech = next(p for p in BUNDLED if p.stem == traj.name.removesuffix("_traj.csv"))
        an = analyse(load_mechanism(mech))
        reader = TrajectoryReader(traj, an.independent_names, linear=an.prismatic_independent,
                                  payloads=[p.name for p in an.mech.payloads])
        watch = RateWatch(reader, an)
        for part in reader:
            watch.see(part)
        assert watch.issues == [], traj


def test_verify_strict_refuses_a_case_mechanism_in_mm(run_cli, tmp_path):
    rated = tmp_path / "rated.yaml"   # inertias in kg*mm^2 only: the gear geometry stays right
    rated.write_text(re.sub(r"(inertia: \[)([^\]]*)(\])", lambda m: _scaled(m, 1e6),
                            (MECH_DIR / "bendix_wrist_rated.yaml").read_text()))
    manifest = tmp_path / "design.yaml"
    manifest.write_text(f"cases:\n  - mechanism: {rated}\n    trajectories: [{MECH_DIR / 'bendix_wrist_traj.csv'}]\n"
                        "    min_static_safety: 1.0\n")
    r = run_cli("verify", manifest, "-j", "1")
    assert r.exit_code in (0, 1)
    assert any(x.startswith(f"{rated}:") and ": warning: link '" in x for x in r.stderr.splitlines())
    r = run_cli("verify", manifest, "-j", "1", "--strict")
    assert r.exit_code == 2 and r.stdout == ""
    assert all(x.endswith("(--strict)") for x in r.stderr.splitlines())


# -- the density bounds ------------------------------------------------------------------
def test_solid_sphere_and_ellipsoid_give_their_own_density():
    rho, R = 7850.0, 0.05
    m = rho * 4 / 3 * math.pi * R**3
    I = np.eye(3) * 0.4 * m * R**2
    assert ellipsoid_density(m, I) == pytest.approx(rho, rel=1e-12)
    assert sphere_density(m, I) == pytest.approx(rho, rel=1e-12)
    a, b, c = 0.1, 0.05, 0.02
    m = rho * 4 / 3 * math.pi * a * b * c
    I = np.diag([m * (b * b + c * c) / 5, m * (a * a + c * c) / 5, m * (a * a + b * b) / 5])
    rot = np.linalg.qr(np.random.default_rng(1).normal(size=(3, 3)))[0]
    assert ellipsoid_density(m, rot @ I @ rot.T) == pytest.approx(rho, rel=1e-9)   # any axes
    assert sphere_density(m, I) < rho       # the most compact body: a lower bound


def test_density_bounds_catch_mm_and_grams():
    a, b, c = 0.1, 0.05, 0.02          # a solid steel box
    m = 7850.0 * a * b * c
    box = np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) * m / 12
    steel_box = Link("box", m, inertia=box, path="links[1]")
    assert link_density(steel_box) is None
    mm = Link("box", m, inertia=steel_box.inertia * 1e6, path="links[1]")
    f = link_density(mm)
    assert f is not None and f.path == "links[1].inertia" and ellipsoid_density(mm.mass, mm.inertia) < MIN_DENSITY
    grams = Link("box", m * 1000, inertia=steel_box.inertia, path="links[1]")
    f = link_density(grams)
    assert f is not None and f.path == "links[1].mass" and sphere_density(grams.mass, grams.inertia) > MAX_DENSITY
    plate = Link("plate", 1.0, inertia=np.diag([0.001, 0.001, 0.002]), path="links[2]")   # I3 = I1 + I2: no volume
    assert link_density(plate) is None


def _erd_robots() -> Path | None:
    """The robots folder of example-robot-data, when installed (as in tests/test_urdf.py)."""
    for p in map(Path, sys.path):
        for d in (p / "cmeel.prefix" / "share" / "example-robot-data" / "robots",
                  p.parent / "share" / "example-robot-data" / "robots"):
            if d.is_dir():
                return d
    return None


ERD_ROOT = _erd_robots()


@pytest.mark.skipif(ERD_ROOT is None, reason="example-robot-data not installed")
@pytest.mark.parametrize("rel", ["ur_description/urdf/ur5_robot.urdf", "panda_description/urdf/panda.urdf",
                                 "xarm_description/urdf/xarm7.urdf", "kinova_description/robots/kinova.urdf",
                                 "z1_description/urdf/z1.urdf", "talos_data/robots/talos_full_v2.urdf"])
def test_robots_give_no_plausibility_warning(rel):
    an = analyse(load_mechanism(ERD_ROOT / rel))
    assert mechanism_issues(an) == []


# -- ratings ------------------------------------------------------------------------------
RATED = MECH_DIR / "bendix_wrist_rated.yaml"


def test_check_validates_the_ratings_as_verify_does(run_cli, tmp_path):
    """A module that contradicts module x teeth / 2 = pitch radius is refused by check (it was
    refused by verify only)."""
    bad = tmp_path / "rated.yaml"
    text = RATED.read_text()
    line = line_of(RATED, 'name: "5-6"') + 1
    lines = text.splitlines(keepends=True)
    lines[line - 1] = lines[line - 1].replace("module: 0.002", "module: 0.0025")
    bad.write_text("".join(lines))
    r = run_cli("check", bad)
    assert r.exit_code == 2 and r.stdout == ""
    assert r.stderr.splitlines()[0] == (f"{bad}:{line}: gears[1].rating.module: module 0.0025 m x 25 teeth / 2 = "
                                        "0.03125 m disagrees with the pitch radius 0.025 m of gear '5' from the mesh geometry")


def test_module_in_mm_is_a_warning_where_no_teeth_are_given(run_cli, tmp_path):
    """Pair 4-1 gives no tooth counts: its module is checked against a plausible tooth count
    (2 r / m from 5 to 2000)."""
    line = line_of(RATED, 'name: "4-1"') + 1
    lines = RATED.read_text().splitlines(keepends=True)
    for module, teeth in (("1.0e-5", "4e+03"), ("1.0", "0.04")):
        mm = tmp_path / f"rated_{module}.yaml"
        mm.write_text("".join(lines[:line - 1] + [lines[line - 1].replace("module: 0.001", f"module: {module}")]
                              + lines[line:]))
        r = run_cli("check", mm)
        assert r.stderr.splitlines()[0] == (
            f"{mm}:{line}: gears[0].rating.module: warning: gear pair '4-1': module {float(module):g} m and the pitch "
            f"radius 0.02 m of gear '4' give {teeth} teeth (2 r / m; expected 5 to 2000): module in mm or lengths "
            "in mm? (gearcli reads m)")
        # 4,000 teeth are rated (a warning); 0.04 teeth are not (the Lewis factor's error, as in verify)
        assert r.exit_code == (0 if module == "1.0e-5" else 2)
        assert run_cli("check", mm, "--strict").exit_code == 2


@pytest.mark.parametrize("mass,inertia", [(1e-300, [0.0008, 0.0006, 0.0005]), (1e12, [1e-300, 1e-300, 1e-300]),
                                          (1e-300, [1e12, 1e12, 1e12]), (5.0, [1e-300, 1e-300, 2e-300])])
def test_density_of_extreme_numbers_is_finite_or_inf_never_an_error(mass, inertia):
    """A mistyped mass or inertia within the accepted range (|x| <= 1e12, e.g. 1e-300 kg) gives
    a density (possibly 0 or inf), not an OverflowError (found by the long fuzz run)."""
    import warnings
    from gearcli.model.plausibility import ellipsoid_density, sphere_density
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for f in (ellipsoid_density, sphere_density):
            d = f(mass, np.diag(inertia))
            assert d >= 0 and not math.isnan(d)
