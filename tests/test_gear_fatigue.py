"""Gear tooth fatigue: AGMA stress-cycle factors and K_v against Shigley's worked example,
rainflow counts against the library, Miner sums by hand, and the check through verify."""
import math

import numpy as np
import pytest

from gearcli.design import fatigue as F


def test_stress_cycle_factors_shigley_example_14_4():
    # Budynas & Nisbett, Shigley's Mechanical Engineering Design, 9th ed., Example 14-4 (a
    # 17-tooth pinion driving a 52-tooth gear, pinion life 10^8 cycles, gear 10^8 / (52/17)
    # = 3.27(10^7)), printed: (Y_N)_P = 1.3558(10^8)^-0.0178 = 0.977, (Y_N)_G = 0.996,
    # (Z_N)_P = 1.4488(10^8)^-0.023 = 0.948, (Z_N)_G = 0.973.
    NP, NG = 1e8, 3.27e7
    assert round(float(F.bending_cycle_factor(NP)), 3) == 0.977
    assert round(float(F.bending_cycle_factor(NG)), 3) == 0.996
    assert round(float(F.pitting_cycle_factor(NP)), 3) == 0.948
    assert round(float(F.pitting_cycle_factor(NG)), 3) == 0.973


def test_stress_cycle_curves_meet_at_their_knees():
    # The AGMA curves (Shigley Figs. 14-14, 14-15) are continuous: the bending branches meet
    # at Y_N = 1.0396 at 3e6 cycles, the pitting ones at Z_N = 1.000 at 1e7, by hand:
    # 1.3558 (3e6)^-0.0178 = 2.3194 (3e6)^-0.0538 = 1.0396; 1.4488 (1e7)^-0.023 = 2.466 (1e7)^-0.056 = 1.000.
    # A constant or exponent copied wrong (e.g. 0.0323 with 1.3558) breaks the meeting.
    for N, factor, value in ((3e6, F.bending_cycle_factor, 1.0396), (1e7, F.pitting_cycle_factor, 1.0)):
        above, below = float(factor(N)), float(factor(N * (1 - 1e-12)))
        assert above == pytest.approx(value, abs=3e-4) and below == pytest.approx(value, abs=3e-4)


def test_dynamic_factor_shigley_example_14_4():
    # Same example: Q_v = 6, V = 801.1 ft/min; B = 0.25 (12 - 6)^(2/3) = 0.8255,
    # A = 50 + 56 (1 - 0.8255) = 59.77, K_v = ((59.77 + sqrt(801.1)) / 59.77)^0.8255 = 1.377.
    # The SI form takes V in m/s with sqrt(200 V): V = 801.1 / 200 m/s gives the same number.
    assert round(float(F.dynamic_factor(801.1 / 200, 6)), 3) == 1.377
    assert float(F.dynamic_factor(0.0, 6)) == 1.0


def test_cycles_to_failure_inverts_the_curves_on_both_branches():
    S = 2.0e8
    for sigma, kind, factor in ((0.9 * S, "bending", F.bending_cycle_factor), (1.3 * S, "bending", F.bending_cycle_factor),
                                (0.95 * S, "contact", F.pitting_cycle_factor), (1.2 * S, "contact", F.pitting_cycle_factor)):
        N = float(F.cycles_to_failure(sigma, S, kind))
        assert S * float(factor(N)) == pytest.approx(sigma, rel=1e-9)
    # 1.3 S in bending is on the low-cycle branch: (2.3194 / 1.3)^(1/0.0538) cycles, by hand
    assert float(F.cycles_to_failure(1.3 * S, S, "bending")) == pytest.approx((2.3194 / 1.3) ** (1 / 0.0538), rel=1e-9)
    assert float(F.cycles_to_failure(0.0, S, "bending")) == math.inf


def test_rainflow_counts_equal_fatpacks_on_a_random_signal():
    import fatpack

    rng = np.random.default_rng(7)
    y = np.cumsum(rng.normal(size=5000))
    peaks = F.rainflow_peaks(y)
    ranges, means = fatpack.find_rainflow_ranges(y, k=F.RAINFLOW_CLASSES, return_means=True)
    assert len(peaks) == len(ranges) > 100
    # each cycle's largest |stress| from the library's range and mean
    ref = np.maximum(np.abs(means + ranges / 2), np.abs(means - ranges / 2))
    assert np.sort(peaks) == pytest.approx(np.sort(ref), rel=1e-12)


def test_rainflow_of_a_known_history_and_miner_by_hand():
    # 0 -> 5 -> 1 -> 4 -> 0: the inner cycle 1-4 (largest 4) and, closing the residue of a
    # repeating history, 0-5 (largest 5).  Classes of 5/1024 resolve them to 5/2048.
    y = np.interp(np.linspace(0, 4, 401), [0, 1, 2, 3, 4], [0.0, 5.0, 1.0, 4.0, 0.0]) * 1e8
    peaks = np.sort(F.rainflow_peaks(y))
    assert peaks == pytest.approx([4e8, 5e8], abs=5e8 / 1024)
    S = 4.5e8
    hand = 0.0
    for p in peaks:              # N_f of the AGMA bending curve, written out
        n = (1.3558 * S / p) ** (1 / 0.0178)
        if n < 3e6:
            n = (2.3194 * S / p) ** (1 / 0.0538)
        hand += 1 / n
    assert F.miner_damage(peaks, S, "bending") == pytest.approx(hand, rel=1e-12)
    assert F.life_hours(2 * hand) == pytest.approx(1 / (2 * hand))
    assert len(F.rainflow_peaks(np.full(10, 3.0))) == 0


def test_rated_arm_gear_checks_carry_k_v_and_the_pinion_passes():
    from gearcli import analyse, load_mechanism
    from gearcli.design.checks import Requirements, build_checks
    from gearcli.errors import Collector
    from pathlib import Path

    an = analyse(load_mechanism(Path(__file__).resolve().parents[1] / "mechanisms" / "paper_2dof_rated.yaml"))
    checks = {c.name: c for c in build_checks(an, Requirements(cycles_per_hour=1200, gear_life_h=2e4), Collector("x"))}
    ch = checks["gear 5-1: bending fatigue life"]
    B = 0.25 * (12 - 8) ** (2 / 3)                     # Q_v = 8, V = 0.5 m/s, K_A = 1.25, by hand
    A = 50 + 56 * (1 - B)
    assert ch.extra["K"] == pytest.approx(1.25 * ((A + math.sqrt(200 * 0.5)) / A) ** B, rel=1e-12)
    ji, factor = ch.extra["passes"]                    # the pinion 5 turns on J5 about the base
    assert an.mech.joints[ji].name == "J5" and factor == 1.0
    # the bevel pair 3-4 (carrier: link 1): gear 4 turns on J4 in link 1, 30/30 teeth
    ji, factor = checks["gear 3-4: contact fatigue life"].extra["passes"]
    assert an.mech.joints[ji].name == "J4" and factor == 1.0


def test_bundled_realistic_design_passes_and_its_tight_twin_fails_on_the_expected_check(run_cli, tmp_path):
    import xml.etree.ElementTree as ET
    from pathlib import Path

    designs = Path(__file__).resolve().parents[1] / "designs"
    r = run_cli("verify", designs / "paper_arm_duty.yaml", "--junit", tmp_path / "ok.xml", "-j", "1")
    assert r.exit_code == 0, r.stdout + r.stderr
    r = run_cli("verify", designs / "paper_arm_duty_tight.yaml", "--junit", tmp_path / "tight.xml", "-j", "1")
    assert r.exit_code == 1, r.stdout + r.stderr
    failed = [tc.get("name") for tc in ET.parse(tmp_path / "tight.xml").iter("testcase") if tc.find("failure") is not None]
    assert failed == ["bearing J5/upper: L10 life"]


def test_life_and_fatigue_plots_are_drawn_over_the_whole_profile(run_cli, tmp_path):
    from pathlib import Path

    designs = Path(__file__).resolve().parents[1] / "designs"
    text = (designs / "paper_arm_duty.yaml").read_text().replace("../mechanisms/", str(designs.parent / "mechanisms") + "/")
    # a thousand times the duty: gear 5-1's contact fatigue life drops to 4.6e11 h, short of 1e12 h,
    # and every bearing's L10 falls short of 1e5 h: their checks fail and are plotted
    text = text.replace("gear_life_h: 20000 ", "gear_life_h: 1.0e+12").replace("bearing_life_h: 20000 ", "bearing_life_h: 1.0e+5")
    text = text.replace("cycles_per_hour: 1200 ", "cycles_per_hour: 1.2e+6 ")
    (tmp_path / "d.yaml").write_text(text)
    r = run_cli("verify", tmp_path / "d.yaml", "-j", "1", "--plots", tmp_path / "pl")
    assert r.exit_code == 1, r.stdout + r.stderr
    names = sorted(p.name for p in (tmp_path / "pl").iterdir())
    assert "pick_and_place__bearing_J5_upper__L10_life.png" in names
    assert "pick_and_place__gear_5-1__contact_fatigue_life.png" in names
    assert all((tmp_path / "pl" / n).read_bytes()[:4] == b"\x89PNG" for n in names)


def _rainflow_peaks_reference(y):
    """The counting as written before the turning-point filter: fatpack on every sample."""
    import fatpack

    if y.size < 2 or np.ptp(y) == 0.0:
        return np.zeros(0)
    rev, _ = fatpack.find_reversals(y, k=F.RAINFLOW_CLASSES)
    if rev.size < 2:
        return np.zeros(0)
    cycles, residue = fatpack.find_rainflow_cycles(rev)
    closed, _ = fatpack.find_rainflow_cycles(fatpack.concatenate_reversals(residue, residue))
    parts = [c for c in (cycles, closed) if c.ndim == 2 and len(c)]
    return np.max(np.abs(np.concatenate(parts)), axis=1) if parts else np.zeros(0)


def test_rainflow_on_turning_points_equals_counting_every_sample():
    # The fast path (fatpack on the turning points only) gives the same cycles, bit for bit,
    # as fatpack on every sample: smooth duties, plateaus, values repeated by rounding,
    # noise, a lone spike, monotone ramps with flat ends.
    rng = np.random.default_rng(11)
    t = np.linspace(0.0, 20.0, 20_000)
    smooth = 1e8 * np.abs(np.sin(2 * np.pi * t) + 0.5 * np.sin(2 * np.pi * 0.7 * t) + 0.3 * np.cos(2 * np.pi * 1.3 * t))
    signals = [smooth, np.round(smooth / 3e6) * 3e6, np.clip(smooth, 2e7, 1.2e8),
               np.cumsum(rng.normal(size=5000)), rng.normal(size=3000), np.round(rng.normal(size=3000) * 3),
               np.r_[np.zeros(50), 1.0, np.zeros(50)], np.r_[np.zeros(20), np.linspace(0, 1, 40), np.ones(20), 0.5],
               np.r_[np.ones(5), np.linspace(1, -1, 7), -np.ones(3), np.linspace(-1, 2, 4)], np.array([0.0, 1.0, 0.0])]
    for y in signals:
        got, ref = F.rainflow_peaks(y), _rainflow_peaks_reference(y)
        assert got.tobytes() == ref.tobytes()
    assert len(F.turning_points(smooth)) < 200      # the filter does cut the work on a smooth duty
    assert len(F.rainflow_peaks(smooth)) > 10


def test_a_ramp_is_one_swing_of_the_repeated_duty():
    # fatpack finds no reversal in a monotone history (IndexError in the library); the duty
    # repeats, so a ramp up to s and back to the start is one cycle at s (was a traceback).
    for y in (np.linspace(1e7, 9e7, 500), np.r_[np.zeros(20), np.linspace(0, 8e7, 40), np.full(20, 8e7)],
              np.array([3e7, 8e7]), np.linspace(8e7, 0.0, 30), np.array([0.0, 8e7, 8e7 - 1.0])):
        peaks = F.rainflow_peaks(y)
        assert len(peaks) == 1
        assert peaks[0] == pytest.approx(np.abs(y).max(), abs=np.ptp(y) / 1024)


def test_cycles_to_failure_equals_both_branches_evaluated_everywhere():
    # the low-cycle branch is evaluated only where the high-cycle one falls below its range;
    # the old definition (both everywhere, then chosen) gives the same bits, NaN and inf too
    rng = np.random.default_rng(3)
    S = 3.0e8
    sigma = np.r_[S * rng.uniform(0.0, 2.0, 5000), 0.0, -1.2 * S, np.nan, np.inf]
    for kind, ((n_hi, a_hi, b_hi), (_, a_lo, b_lo)) in (("bending", F._BENDING), ("contact", F._CONTACT)):
        s = np.abs(sigma)
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            hi, lo = (a_hi * S / s) ** (1 / b_hi), (a_lo * S / s) ** (1 / b_lo)
            ref = np.where(hi >= n_hi, hi, np.minimum(lo, n_hi))
        assert F.cycles_to_failure(sigma, S, kind).tobytes() == ref.tobytes()
        assert (ref < n_hi).sum() > 1000          # both branches are exercised
    assert np.shape(F.cycles_to_failure(0.5 * S, S, "bending")) == ()


def test_a_stress_flat_to_rounding_has_no_cycle():
    # A tooth force that flips sign at equal magnitude: the bending stress varies by an ulp
    # (was an IndexError traceback from verify, issue 34 section 5); it has no cycle and no
    # rainflow damage, while a real ripple of 1e-6 of the stress is still counted.
    s = 1.2e8
    up = np.nextafter(s, 2 * s)
    for y in (np.array([s, up, s, up, s]), np.array([s, np.nextafter(s, 0.0)] * 50), np.r_[np.full(9, s), up]):
        assert F.rainflow_peaks(y).size == 0
        assert F.miner_damage(F.rainflow_peaks(y), 2e8, "bending") == 0.0
    ripple = s * (1 + 1e-6 * np.sin(np.linspace(0, 6 * np.pi, 300)))
    assert F.rainflow_peaks(ripple).size >= 3


def test_sn_plot_names_only_the_curves_it_draws(tmp_path, monkeypatch):
    """A pinion at rest under load has no tooth pass: the S-N plot's legend named "tooth
    passes" with no line (a log axis drops 0 passes; issue 34, section 3).  Passes at a
    single point are drawn as a point."""
    pytest.importorskip("matplotlib")
    from gearcli.report import check_plots
    seen = []
    save = check_plots._save
    monkeypatch.setattr(check_plots, "_save", lambda fig, path: (
        seen.append([(t.get_text(), ln) for ax in fig.axes for t, ln in zip(ax.get_legend().get_texts(), ax.get_lines())]),
        save(fig, path)))
    N = np.logspace(2, 12, 50)
    S = 2e8 * F.bending_cycle_factor(N)
    peaks = np.array([1.5e8, 1.2e8])
    check_plots.plot_sn(N, S, peaks, 1e6, tmp_path / "a.png", "t", "stress [Pa]", (np.zeros(5), np.full(5, 1e8)))
    check_plots.plot_sn(N, S, peaks, 1e6, tmp_path / "b.png", "t", "stress [Pa]", (np.array([0.0, 3e7]), np.array([1e8, 1e8])))
    names = [[text for text, _ in fig] for fig in seen]
    assert names[0] == ["allowable stress (S-N curve)", "counted cycles, cumulated over the required life"]
    assert names[1][1] == "tooth passes, cumulated over the required life"
    passes_line = seen[1][1][1]
    assert list(passes_line.get_xdata()) == [3e7] and passes_line.get_marker() == "."
    assert (tmp_path / "a.png").stat().st_size > 0


def test_json_report_carries_the_stresses_and_rainflow_counts_it_used(run_cli, tmp_path):
    """Every gear check's JSON entry has its peak stress (MPa); a fatigue check also the
    rainflow cycles an hour by stress and the tooth passes an hour (issue 34, section 3).
    Miner's sum of the listed cycles, by the S-N curve, is the rainflow part of the damage:
    with the tooth passes' part it makes the reported life's 1/L."""
    import json
    out = tmp_path / "r.json"
    from pathlib import Path
    designs = Path(__file__).resolve().parents[1] / "designs"
    r = run_cli("verify", designs / "paper_arm_duty.yaml", "--json", out, "-j", "1")
    assert r.exit_code == 0, r.stderr
    checks = json.loads(out.read_text())["checks"]
    gear = [c for c in checks if c["component"].startswith("gear ")]
    assert len(gear) == 12 and all("peak_stress_MPa" in c for c in gear)
    assert not any("peak_stress_MPa" in c for c in checks if not c["component"].startswith("gear "))
    for c in (c for c in gear if c["quantity"].endswith("fatigue life")):
        cycles = np.array(c["rainflow_MPa_per_hour"])
        assert cycles[0, 0] == pytest.approx(c["peak_stress_MPa"], rel=1e-12)
        assert np.all(np.diff(cycles[:, 0]) < 0) and np.all(cycles[:, 1] % 1200 == 0)    # 1200 repetitions an hour
        assert c["tooth_passes_per_hour"] > 0
        kind = "bending" if c["quantity"].startswith("bending") else "contact"
        allowable = 2.2e8 if kind == "bending" else 7.6e8
        rainflow = np.sum(cycles[:, 1] / F.cycles_to_failure(cycles[:, 0] * 1e6, allowable, kind))
        assert 0 < rainflow < 1 / c["value"]
        # a tooth pass at the peak stress damages at most as much as one more cycle at that stress
        worst_pass = c["tooth_passes_per_hour"] / F.cycles_to_failure(c["peak_stress_MPa"] * 1e6, allowable, kind)
        assert 1 / c["value"] <= rainflow + worst_pass * (1 + 1e-9)
