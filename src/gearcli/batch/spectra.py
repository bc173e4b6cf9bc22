"""``gearcli verify --spectra DIR``: the load spectra of every case, as CSV and JSON.

For each motor (torque, its speed), gear mesh (tangential force, the pinion's rate when it
turns on a joint of the carrier) and bearing with a life check (the ISO 281 equivalent load,
the joint rate), the seconds and revolutions per hour of service in each load bin
(:mod:`gearcli.design.spectra`), weighted by the case's mission profile like the lives.
"""
from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import numpy as np

from ..design.evaluate import profile_rates, signal
from ..design.spectra import bin_edges, load_spectrum
from ..io.output import write_text
from .manifest import case_analysis
from .outputs import file_slug
from .runner import solve_samples


def _quantities(case, an) -> list[tuple]:
    """(component, quantity, unit, load(s), rate(s) or None) per spectrum of a case."""
    out = []
    for m in an.mech.motors:
        col = f"motor:{m.name}"
        out.append((f"motor {m.name}", "torque", "N·m", lambda s, c=col: s.cols[c],
                    lambda s, c=col: s.cols[c + ":speed"]))
    gears = {}
    for ch in case.checks:
        if ch.kind in ("safety", "fatigue") and ch.signal[0] == "bending":
            gears.setdefault(ch.signal[1], ch.extra.get("passes"))
            if ch.extra.get("passes") is not None:
                gears[ch.signal[1]] = ch.extra["passes"]
    for name, passes in gears.items():
        rate = None if passes is None else (lambda s, p=passes: s.rates[:, p[0]] * p[1])
        out.append((f"gear {name}", "tangential force", "N", lambda s, c=f"gear:{name}:t": s.cols[c], rate))
    for ch in case.checks:
        if ch.kind == "life":
            out.append((ch.component, "equivalent load P", "N", lambda s, c=ch: signal(c, s, an.mech),
                        lambda s, j=ch.signal[1]: s.rates[:, j]))
    return out


def case_spectra(case) -> list[dict]:
    """The spectra of one case: one mapping per component (bins, s/h, fraction, rev/h)."""
    an = case_analysis(case.mechanism)
    quantities = _quantities(case, an)
    samples = [solve_samples(an, tp, case.degrees) for tp in case.trajectories]
    spans = [float(s.t[-1] - s.t[0]) if s.t.size else 0.0 for s in samples]
    rates = profile_rates(case.shares or (None,) * len(samples), spans, case.req.cycles_per_hour,
                          case.req.service_life_h)
    rates = [1.0 if r is None else r for r in rates]      # per duty cycle when no rate is known
    total_time = sum(r * T for r, T in zip(rates, spans))
    out = []
    for comp, qty, unit, load, rate in quantities:
        loads = [np.asarray(load(s), float) for s in samples]
        edges = bin_edges(max(float(np.max(np.abs(x))) if x.size else 0.0 for x in loads))
        sec, rev = np.zeros(len(edges) - 1), np.zeros(len(edges) - 1)
        for r, s, x in zip(rates, samples, loads):
            a, b = load_spectrum(x, s.t, None if rate is None else rate(s), edges)
            sec, rev = sec + r * a, rev + r * b
        out.append({"component": comp, "quantity": qty, "unit": unit, "edges": edges.tolist(),
                    "seconds_per_hour": sec.tolist(),
                    "fraction_of_time": (sec / total_time if total_time > 0 else sec * 0).tolist(),
                    "revolutions_per_hour": None if rate is None else rev.tolist()})
    return out


def write_spectra(results, directory: Path) -> list[Path]:
    """``<case>__spectra.json`` and ``.csv`` in ``directory`` for every case; the paths."""
    paths = []
    for r in results:
        spectra = case_spectra(r.case)
        base = directory / f"{file_slug(r.case.name)}__spectra"
        write_text(base.with_suffix(".json"), json.dumps({"case": r.case.name, "spectra": spectra}, indent=1) + "\n")
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["component", "quantity", "unit", "load_from", "load_to", "seconds_per_hour", "fraction_of_time",
                    "revolutions_per_hour"])
        for sp in spectra:
            e = sp["edges"]
            for b in range(len(e) - 1):
                rev = "" if sp["revolutions_per_hour"] is None else f"{sp['revolutions_per_hour'][b]:.9g}"
                w.writerow([sp["component"], sp["quantity"], sp["unit"], f"{e[b]:.9g}", f"{e[b + 1]:.9g}",
                            f"{sp['seconds_per_hour'][b]:.9g}", f"{sp['fraction_of_time'][b]:.9g}", rev])
        write_text(base.with_suffix(".csv"), buf.getvalue())
        paths += [base.with_suffix(".json"), base.with_suffix(".csv")]
    return paths
