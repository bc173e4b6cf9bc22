"""verify's per-trajectory reduction (design.evaluate.partials) against the plain definition
written out here: every check of the rated Bendix wrist and the rated paper arm, bit for bit
but a bearing life's sums, to the last bit (the fast paths: the peak searched once per signal and without |x| for signals that are
never negative, life sums without dividing by a_ISO = 1, rainflow on turning points)."""
import math
from pathlib import Path

import fatpack
import numpy as np
import pytest

from gearcli.batch.manifest import case_analysis
from gearcli.batch.runner import solve_samples
from gearcli.design import bearings as B
from gearcli.design import fatigue as F
from gearcli.design import iso281, sizing
from gearcli.design.checks import Requirements, build_checks
from gearcli.design.evaluate import bearing_of, partials, signal
from gearcli.errors import Collector
from gearcli.io.trajectory import write_trajectory
from gearcli.report.rms import rms_of

ROOT = Path(__file__).resolve().parents[1]


def reference(checks, s, mech):
    out = []
    span = float(s.t[-1] - s.t[0])
    w = np.empty_like(s.t)
    d = np.diff(s.t)
    w[0], w[-1], w[1:-1] = d[0] / 2, d[-1] / 2, (d[:-1] + d[1:]) / 2
    for ch in checks:
        x = signal(ch, s, mech)
        k = int(np.argmax(np.abs(x)))
        peak, tp = float(np.abs(x[k])), float(s.t[k])
        total = wsum = revs = 0.0
        score = peak
        if ch.kind == "rms":
            x2 = x * x
            total, wsum = float(0.5 * np.einsum("i,i->", d, x2[:-1] + x2[1:])), span
            score = rms_of(total, wsum, peak)
        elif ch.kind == "energy":
            peak = score = sizing.cycle_integral(x, s.t)
        elif ch.kind == "life":
            n = np.abs(s.rates[:, ch.signal[1]]) * w / (2 * math.pi)
            total = float(np.sum(n * x ** ch.exponent / iso281.life_factor(bearing_of(ch, mech), x)))
            wsum = revs = float(np.sum(n))
            score = B.equivalent_load(total, wsum, ch.exponent)
        elif ch.kind == "fatigue":
            rev, _ = fatpack.find_reversals(x, k=F.RAINFLOW_CLASSES)
            cycles, residue = fatpack.find_rainflow_cycles(rev)
            closed, _ = fatpack.find_rainflow_cycles(fatpack.concatenate_reversals(residue, residue))
            peaks = np.max(np.abs(np.concatenate([c for c in (cycles, closed) if c.ndim == 2 and len(c)])), axis=1)
            total = float(np.sum(1.0 / F.cycles_to_failure(peaks, ch.rating, ch.signal[0])))
            revs = float(len(peaks))
            ji, factor = ch.extra["passes"]
            n = np.abs(s.rates[:, ji]) * w / (2 * math.pi) * factor
            total += float(np.sum(n / F.cycles_to_failure(x, ch.rating, ch.signal[0])))
            revs += float(np.sum(n))
            score = total
        out.append((peak, tp, total, wsum, revs, score, span))
    return out


@pytest.mark.parametrize("mech", ["bendix_wrist_rated.yaml", "paper_2dof_rated.yaml"])
def test_partials_equal_the_plain_definition(tmp_path, mech):
    an = case_analysis(ROOT / "mechanisms" / mech)
    t = np.linspace(0.0, 3.0, 3000)
    dof = len(an.independent_names)
    q = np.column_stack([(0.8 + 0.2 * j) * np.sin(2 * np.pi * (0.7 + 0.3 * j) * t) for j in range(dof)])
    write_trajectory(tmp_path / "m.csv", an.independent_names, t, q)
    checks = build_checks(an, Requirements(cycles_per_hour=60, bearing_life_h=2e4, gear_life_h=2e4), Collector("x"))
    kinds = {c.kind for c in checks}
    assert {"peak", "rms", "safety", "life", "fatigue"} <= kinds
    s = solve_samples(an, tmp_path / "m.csv", False)
    got, ref = partials(checks, s, an.mech), reference(checks, s, an.mech)
    for ch, g, r in zip(checks, got, ref):
        if ch.kind == "life":      # the product cubes by two products (bearings.life_sum), the reference by pow:
            assert np.allclose(g[:7], r, rtol=1e-15, atol=0), ch.name      # the last bits may differ
        else:
            assert np.array(g[:7]).tobytes() == np.array(r).tobytes(), ch.name
        if ch.kind == "fatigue":     # the counts the damage came from: the counted cycles, by stress
            levels = [s for s, n in g[7][0] for _ in range(n)]
            assert levels == sorted(F.rainflow_peaks(signal(ch, s, an.mech)).tolist())
        else:
            assert g[7] is None
