"""``gears[].per_planet``: one planet's mesh stiffness differs without writing every planet
out by hand; and the load sharing of a planet path (two meshes in series)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from gearcli.dynamics.determinacy import analyse
from gearcli.dynamics.solve import solve
from gearcli.io.trajectory import read_trajectory
from gearcli.io.yaml_reader import parse_mechanism
from gearcli.report.columns import named_columns

MECH_DIR = Path(__file__).resolve().parents[1] / "mechanisms"
K = 3.0e8   # N/m, every mesh but the overridden one


def planetary(per_planet: str = "", k_ring: float = K, planets_line: str = "planets: 3") -> str:
    """planetary_3p.yaml (three planets declared once) with its sun and ring meshes at
    ``K`` and ``k_ring``, and ``per_planet`` (YAML flow text) on the sun-planet pair."""
    return f"""name: planetary
gravity: [0, 0, -9.81]
base: housing
end_effector: carrier
links:
  - {{name: housing}}
  - {{name: sun, mass: 0.08, com: [0, 0, -0.015], inertia: [1.2e-5, 1.2e-5, 4.0e-6]}}
  - {{name: carrier, mass: 0.35, com: [0, 0, 0.012], inertia: [2.5e-4, 2.5e-4, 3.8e-4]}}
  - {{name: planet, mass: 0.02, inertia: [6.0e-7, 6.0e-7, 8.0e-7]}}
joints:
  - {{name: JS, parent: housing, child: sun, origin: {{xyz: [0, 0, 0]}}, axis: [0, 0, 1]}}
  - {{name: JC, parent: housing, child: carrier, origin: {{xyz: [0, 0, 0.01]}}, axis: [0, 0, 1]}}
  - {{name: JP, parent: carrier, child: planet, origin: {{xyz: [0.021, 0, -0.01]}}, axis: [0, 0, 1], {planets_line}}}
gears:
  - name: sun-planet
    links: [sun, planet]
    teeth: [24, 18]
    mesh_point: [0.012, 0, -0.01]
    stiffness: {K!r}
{per_planet}
  - {{name: planet-ring, links: [planet, housing], kind: internal, teeth: [18, 60], mesh_point: [0.030, 0, -0.01], stiffness: {k_ring!r}}}
motors:
  - {{name: motor, link: sun}}
loads:
  - {{name: payload, link: carrier, point: [0.05, 0, 0.04], frame: link, force: [0, -10, -19.62]}}
"""


def by_hand(k_sun: list[float]) -> str:
    """The same gearbox with its three planets written out one by one (no ``planets:``)."""
    head = planetary().split("links:\n")[0]
    links = ["  - {name: housing}",
             "  - {name: sun, mass: 0.08, com: [0, 0, -0.015], inertia: [1.2e-5, 1.2e-5, 4.0e-6]}",
             "  - {name: carrier, mass: 0.35, com: [0, 0, 0.012], inertia: [2.5e-4, 2.5e-4, 3.8e-4]}"]
    joints = ["  - {name: JS, parent: housing, child: sun, origin: {xyz: [0, 0, 0]}, axis: [0, 0, 1]}",
              "  - {name: JC, parent: housing, child: carrier, origin: {xyz: [0, 0, 0.01]}, axis: [0, 0, 1]}"]
    gears = []
    for i in range(3):
        a = 2 * math.pi * i / 3
        c, s = math.cos(a), math.sin(a)
        links.append(f"  - {{name: planet{i + 1}, mass: 0.02, inertia: [6.0e-7, 6.0e-7, 8.0e-7]}}")
        joints.append(f"  - {{name: JP{i + 1}, parent: carrier, child: planet{i + 1}, origin: {{xyz: [{0.021 * c!r}, "
                      f"{0.021 * s!r}, -0.01], rpy: [0, 0, {a!r}]}}, axis: [0, 0, 1]}}")
        gears.append(f"  - {{name: sun-planet{i + 1}, links: [sun, planet{i + 1}], teeth: [24, 18], "
                     f"mesh_point: [{0.012 * c!r}, {0.012 * s!r}, -0.01], stiffness: {k_sun[i]!r}}}")
        gears.append(f"  - {{name: planet-ring{i + 1}, links: [planet{i + 1}, housing], kind: internal, teeth: [18, 60], "
                     f"mesh_point: [{0.030 * c!r}, {0.030 * s!r}, -0.01], stiffness: {K!r}}}")
    tail = "motors:\n" + planetary().split("motors:\n")[1]
    return head + "\n".join(["links:", *links, "joints:", *joints, "gears:", *gears]) + "\n" + tail


def tooth_forces(text: str, q, qd, qdd) -> dict[str, np.ndarray]:
    an = analyse(parse_mechanism(text, "planetary.yaml"))
    res = solve(an, q, qd, qdd, loads=None)
    cols = named_columns(an, res, np.zeros(len(q)))
    return {k: v for k, v in cols.items() if k.startswith("gear:") and k.endswith(":t")}


def static_sun_shares(text: str) -> np.ndarray:
    """Tangential force shares of the three sun meshes at rest (payload and gravity only)."""
    z = np.zeros((1, 1))
    t = tooth_forces(text, np.array([[0.3]]), z, z)
    s = np.array([t[f"gear:sun-planet{i}:t"][0] for i in (1, 2, 3)])
    return s / s.sum()


OVERRIDE = "    per_planet: [{planet: 2, stiffness: 1.5e+8}]"


def test_override_equals_the_planets_written_by_hand():
    tr = read_trajectory(MECH_DIR / "planetary_3p_traj.csv", ["JC"])
    sl = slice(0, None, 50)
    a = tooth_forces(planetary(OVERRIDE), tr.q[sl], tr.qd[sl], tr.qdd[sl])
    b = tooth_forces(by_hand([K, 1.5e8, K]), tr.q[sl], tr.qd[sl], tr.qdd[sl])
    assert a.keys() == b.keys() and len(a) == 6
    scale = max(np.abs(v).max() for v in b.values())
    for k in a:
        np.testing.assert_allclose(a[k], b[k], rtol=0, atol=1e-12 * scale, err_msg=k)
    plain = tooth_forces(planetary(), tr.q[sl], tr.qd[sl], tr.qdd[sl])
    assert np.abs(plain["gear:sun-planet2:t"] - a["gear:sun-planet2:t"]).max() > 0.1 * scale   # the override acts


def test_a_planet_path_is_two_meshes_in_series():
    """Sun and ring meshes at k, planet 2's sun mesh at k/2: the paths' stiffnesses are
    1/(1/k_s + 1/k_r) = k/2, k/3, k/2, so the shares are 3/8, 1/4, 3/8 (README) -- not
    0.4, 0.2, 0.4, which the sun meshes alone would give."""
    shares = static_sun_shares(planetary(OVERRIDE))
    np.testing.assert_allclose(shares, [3 / 8, 1 / 4, 3 / 8], rtol=0, atol=1e-12)
    assert np.abs(shares - [0.4, 0.2, 0.4]).max() > 0.02
    # any stiffnesses: the series formula, computed here from the stiffnesses alone
    k_sun, k_ring = [2.0e8, 0.7e8, 4.0e8], 5.0e8
    items = ", ".join(f"{{planet: {i + 1}, stiffness: {k!r}}}" for i, k in enumerate(k_sun))
    path = np.array([1 / (1 / ks + 1 / k_ring) for ks in k_sun])
    np.testing.assert_allclose(static_sun_shares(planetary(f"    per_planet: [{items}]", k_ring=k_ring)),
                               path / path.sum(), rtol=0, atol=1e-12)


def test_equal_meshes_share_equally():
    np.testing.assert_allclose(static_sun_shares(planetary()), [1 / 3] * 3, rtol=0, atol=1e-12)


@pytest.mark.parametrize("per_planet, where, message", [
    ("[{planet: 4, stiffness: 1.0e+8}]", "gears[0].per_planet[0].planet",
     "planet 4 does not exist: the copies are numbered 1 to 3 (planets: 3)"),
    ("[{planet: 2, stiffness: 1.0e+8}, {planet: 2, stiffness: 2.0e+8}]", "gears[0].per_planet[1].planet",
     "planet 2 is given twice (first at gears[0].per_planet[0])"),
    ("[{planet: 1, stiffness: -1.0}]", "gears[0].per_planet[0].stiffness", "mesh stiffness must be positive, got -1 N/m"),
    ("[{planet: 1}]", "gears[0].per_planet[0]", "missing required key 'stiffness'"),
    ("[{planet: 1, stiffness: 1.0e+8, mass: 2}]", "gears[0].per_planet[0].mass", "unknown key 'mass'"),
])
def test_bad_overrides_are_located(run_cli, tmp_path, per_planet, where, message):
    p = tmp_path / "planetary.yaml"
    p.write_text(planetary(f"    per_planet: {per_planet}"))
    line = next(i for i, x in enumerate(p.read_text().splitlines(), 1) if "per_planet" in x)
    r = run_cli("check", p)
    assert r.exit_code == 2 and r.stdout == ""
    assert any(x.startswith(f"{p}:{line}: {where}: {message}") for x in r.stderr.splitlines()), r.stderr


def test_override_on_a_pair_without_planets_is_an_error(run_cli, tmp_path):
    p = tmp_path / "planetary.yaml"
    p.write_text(planetary(OVERRIDE, planets_line="label: pin"))   # no planets: N
    r = run_cli("check", p)
    assert r.exit_code == 2
    line = next(i for i, x in enumerate(p.read_text().splitlines(), 1) if "per_planet" in x)
    assert f"{p}:{line}: gears[0].per_planet: per_planet is for a gear pair of a planet" in r.stderr
