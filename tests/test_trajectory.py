"""Trajectory CSV input: spline derivatives, chunking, degrees, and bad rows."""
import numpy as np
import pytest

from gearcli.errors import TrajectoryError
from gearcli.io.trajectory import TrajectoryReader, derivatives, read_trajectory, write_trajectory

NAMES = ["J1", "J2"]


def sine(t):
    q = np.column_stack([np.sin(2 * np.pi * t), 0.5 * np.cos(3 * t)])
    qd = np.column_stack([2 * np.pi * np.cos(2 * np.pi * t), -1.5 * np.sin(3 * t)])
    qdd = np.column_stack([-(2 * np.pi) ** 2 * np.sin(2 * np.pi * t), -4.5 * np.cos(3 * t)])
    return q, qd, qdd


def test_spline_derivatives_match_analytic_rates():
    t = np.linspace(0, 2, 2001)
    q, qd, qdd = sine(t)
    d1, d2 = derivatives(t, q)
    assert np.max(np.abs(d1 - qd)) < 1e-10     # README: 5e-12 rad/s
    assert np.max(np.abs(d2 - qdd)) < 3e-8     # README: 1.5e-8 rad/s^2


def test_spline_error_shrinks_with_step():
    errs = []
    for n in (201, 401, 801):
        t = np.linspace(0, 2, n)
        q, _, qdd = sine(t)
        errs.append(np.max(np.abs(derivatives(t, q)[1] - qdd)))
    assert errs[1] < errs[0] / 8 and errs[2] < errs[1] / 8   # at least third order


def test_chunked_reading_equals_whole_file(tmp_path):
    t = np.cumsum(np.random.default_rng(3).uniform(0.5e-3, 1.5e-3, 1500))  # uneven steps
    q, _, _ = sine(t)
    path = tmp_path / "traj.csv"
    write_trajectory(path, NAMES, t, q)
    whole = read_trajectory(path, NAMES)
    parts = list(TrajectoryReader(path, NAMES, chunk=200))
    assert len(parts) > 5
    for f in ("t", "q", "qd", "qdd"):
        joined = np.concatenate([getattr(p, f) for p in parts])
        assert np.allclose(joined, getattr(whole, f), rtol=0, atol=1e-9 * (1 + np.abs(getattr(whole, f)).max()))


def test_given_rates_are_used_and_degrees_convert(tmp_path):
    t = np.linspace(0, 1, 101)
    q, qd, qdd = sine(t)
    p_rad, p_deg = tmp_path / "rad.csv", tmp_path / "deg.csv"
    write_trajectory(p_rad, NAMES, t, q, qd, qdd)
    write_trajectory(p_deg, NAMES, t, np.rad2deg(q), np.rad2deg(qd), np.rad2deg(qdd))
    a = read_trajectory(p_rad, NAMES)
    b = read_trajectory(p_deg, NAMES, degrees=True)
    assert np.array_equal(a.qdd, qdd)  # taken as given, not re-derived
    for f in ("q", "qd", "qdd"):
        assert np.allclose(getattr(a, f), getattr(b, f), rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("text, where, what", [
    ("t,q:J1,q:J2\n0,0,0\n0.1,abc,0\n", ":3: column 2 'q:J1'", "not a number"),
    ("t,q:J1,q:J2\n0,0,0\n0.1,nan,0\n", ":3: column 2 'q:J1'", "NaN"),
    ("t,q:J1,q:J2\n0,0,0\n0.1,0,0\n0.1,0,0\n", ":4: column 1 't'", "not after"),
    ("t,q:J1\n0,0\n", ":1:", "missing column 'q:J2'"),
    ("t,q:J1,q:J2,q:J9\n0,0,0,0\n", ":1: column 4 'q:J9'", "unknown column"),
    ("t,q:J1,q:J2,q:J1\n0,0,0,0\n", ":1: column 4 'q:J1'", "duplicate"),
    ("t,q:J1,q:J2\n0,0,0\n0.1,0\n", ":3:", "2 columns"),
    ("t,q:J1,q:J2,qd:J1\n0,0,0,0\n", ":1:", "qd: columns for every joint"),
    ("q:J1,q:J2\n0,0\n", ":1:", "missing column 't'"),
    ("t,q:J1,q:J2\n", "", "no samples"),
])
def test_bad_rows_name_row_and_column(tmp_path, text, where, what):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(TrajectoryError) as err:
        read_trajectory(path, NAMES)
    msg = str(err.value)
    assert msg.startswith(str(path)) and where in msg and what in msg
    assert "\n" not in msg


def test_a_trajectory_read_in_chunks_is_the_one_parse(tmp_path, monkeypatch):
    """read_trajectory parses READ_CHUNK samples at a time (the fast parser's buffers of a
    1e6-row file were larger than the arrays it made) and joins them: with chunks of 7
    samples, every array (times, angles, rates, accelerations, line numbers, load and attach
    columns) equals one whole parse bit for bit, and a bad value in a later chunk is
    reported on its own line."""
    import gearcli.io.trajectory as trajectory
    from gearcli.model.loads import Load
    n = 50
    t = np.linspace(0.0, 1.0, n)
    rows = ["t,q:a,qd:a,qdd:a,load:tip:fz,attach:box"]
    rows += [f"{x:.17g},{np.sin(x):.17g},{np.cos(x):.17g},{-np.sin(x):.17g},{10 * x:.17g},{int(k % 9 < 4)}"
             for k, x in enumerate(t)]
    path = tmp_path / "t.csv"
    path.write_text("\n".join(rows) + "\n")
    loads = (Load("tip", "a", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),)

    def read():
        return read_trajectory(path, ["a"], loads=loads, payloads=["box"])
    whole = read()
    monkeypatch.setattr(trajectory, "READ_CHUNK", 7)
    parts = read()
    for f in ("t", "q", "qd", "qdd", "line"):
        assert np.array_equal(getattr(whole, f), getattr(parts, f)), f
    assert np.array_equal(whole.loads["tip"], parts.loads["tip"]) and whole.loads["tip"][:, 2].any()
    assert np.array_equal(whole.attach["box"], parts.attach["box"]) and 0 < parts.attach["box"].sum() < n
    rows[40] = rows[40].replace(",", ",x", 1)
    path.write_text("\n".join(rows) + "\n")
    with pytest.raises(TrajectoryError, match="t.csv:41"):
        read()
