"""The output columns: table() and verify's LazyColumns against the columns written out by
name from the solver's arrays (README "Output columns"), bit for bit."""
import numpy as np
import pytest

from gearcli import analyse, load_mechanism, named_columns, solve
from gearcli.report.columns import LazyColumns, column_names, table


def expected_column(an, res, t, name):
    """The column by its name, from the Result's arrays (a reference independent of
    report.columns' own list)."""
    mech = an.mech
    kind, _, rest = name.partition(":")
    if name == "t":
        return t
    if kind == "tau":
        return res.tau[:, an.independent_names.index(rest)]
    if kind == "motor":
        m, _, what = rest.partition(":")
        k = [mo.name for mo in mech.motors].index(m)
        return {"": res.motor[:, k], "speed": res.motor_speed[:, k],
                "power": res.motor[:, k] * res.motor_speed[:, k]}[what]
    if kind == "gear":
        parts = rest.split(":")
        ci = [mech.gears[c.gear].name for c in an.circuits].index(parts[0])
        if len(parts) == 2:
            return {"t": res.gear_t, "torque": res.gear_t, "sep": res.gear_sep, "loss": res.gear_loss}[parts[1]][:, ci]
        gp = mech.gears[an.circuits[ci].gear]
        side = (gp.j, gp.k).index(parts[1])
        return (res.gear_radial if parts[2] == "radial" else res.gear_axial)[:, ci, side]
    j, _, what = rest.partition(":")
    ji = [jt.name for jt in mech.joints].index(j)
    w = res.joint[:, ji]
    return {"fx": w[:, 0], "fy": w[:, 1], "fz": w[:, 2], "mx": w[:, 3], "my": w[:, 4], "mz": w[:, 5],
            "radial": np.hypot(w[:, 0], w[:, 1]), "axial": np.abs(w[:, 2]), "bending": np.hypot(w[:, 3], w[:, 4]),
            "friction": None if res.joint_friction is None else res.joint_friction[:, ji],
            "loss": None if res.joint_loss is None else res.joint_loss[:, ji]}[what]


def _solved(an, n=1300):          # more than report.columns.TRANSPOSE_ROWS: several blocks
    rng = np.random.default_rng(5)
    t = np.linspace(0.0, 1.0, n)
    dof = len(an.independent_names)
    q, qd, qdd = (rng.uniform(-1, 1, (n, dof)) for _ in range(3))
    return t, solve(an, q, qd, qdd)


@pytest.mark.parametrize("name", ["paper_2dof.yaml", "bendix_wrist_rated.yaml", "servo_joint_rated.yaml", "ideal"])
def test_table_and_lazy_columns_equal_the_columns_by_name(mech_dir, name):
    if name == "ideal":
        from test_ideal_pairs import ideal_variant
        an = ideal_variant()[1]
    else:
        an = analyse(load_mechanism(mech_dir / name))
    t, res = _solved(an)
    names = column_names(an)
    tab = table(an, t, res)
    assert tab.shape == (len(t), len(names)) and tab.flags.f_contiguous
    lazy = LazyColumns(an, res, t)
    assert len(lazy) == 0                     # nothing computed before it is asked for
    eager = named_columns(an, res, t)
    for i, col in enumerate(names):
        ref = np.ascontiguousarray(expected_column(an, res, t, col), dtype=float)
        assert tab[:, i].tobytes() == ref.tobytes(), col
        assert eager[col].tobytes() == ref.tobytes(), col
        assert lazy[col].tobytes() == ref.tobytes(), col
    assert list(lazy) == names
    with pytest.raises(KeyError):
        lazy["motor:nosuch"]
