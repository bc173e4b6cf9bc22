"""Motor speed and power columns: appended after the stable columns, checked by hand."""
import numpy as np

from gearcli import analyse, load_mechanism, named_columns, solve
from gearcli.report.columns import column_names


def test_motor_speed_and_power_are_appended_and_follow_the_gear_ratio(mech_dir):
    an = analyse(load_mechanism(mech_dir / "paper_2dof.yaml"))
    names = column_names(an)
    motors = [m.name for m in an.mech.motors]
    new = [f"motor:{m}:{q}" for m in motors for q in ("speed", "power")]
    assert names[-len(new):] == new
    assert not any(n.endswith((":speed", ":power")) for n in names[:-len(new)])
    t = np.linspace(0, 1, 201)
    q = np.column_stack([np.sin(2 * t), 0.5 * np.cos(3 * t)])
    qd = np.column_stack([2 * np.cos(2 * t), -1.5 * np.sin(3 * t)])
    qdd = np.column_stack([-4 * np.sin(2 * t), -4.5 * np.cos(3 * t)])
    cols = named_columns(an, solve(an, q, qd, qdd), t)
    # motor5's gear 5 drives link 1 (joint J1) through the pair 5-1 with e = -3 (the README's
    # example: theta_5 = -3 theta_1 on the base), so its speed is -3 qd_J1.
    assert np.allclose(cols["motor:motor5:speed"], -3 * qd[:, 0], rtol=1e-12, atol=1e-12)
    for m in motors:
        assert np.allclose(cols[f"motor:{m}:power"], cols[f"motor:{m}"] * cols[f"motor:{m}:speed"])
