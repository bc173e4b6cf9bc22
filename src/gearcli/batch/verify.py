"""``gearcli verify``: manifest in, verdicts and reports out (the CLI is a thin layer on it)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ..errors import GearcliError
from ..io.output import OutputError, output_target
from ..report.plots import plot_check
from ..report.rms import cumulative_rms
from .manifest import load_manifest
from .outputs import WARN_MARGIN, file_slug as _slug, rows_of, write_json, write_junit, write_markdown
from .runner import jobs_of, profile_plot, run_manifest, worst_samples
from .spectra import write_spectra

SIGNAL_LABELS = {"abs": "|{}|", "col": "RMS of {} from the start", "rate": "|joint rate|", "running_rms": "running RMS of {}", "bearing_P": "dynamic equivalent load P",
                 "bearing_P0": "static equivalent load P0", "bending": "Lewis root bending stress",
                 "contact": "Hertz contact stress", "inertia_ratio": "load-to-rotor inertia ratio",
                 "envelope": "|T| / T_max(speed)", "regen_power": "regenerative power",
                 "reducer_speed": "|input speed relative to the housing|",
                 "worm_efficiency": "efficiency 1 - loss / power in"}
LIMIT_LABELS = {"peak": "limit", "rms": "RMS limit", "safety": "allowable / required safety",
                "life": "P_eq giving the required life", "energy": "energy limit (integral over the cycle)",
                "reducer_average": "average torque limit (T_av, speed-weighted)",
                "reducer_speed_average": "average input speed limit (n_av)",
                "reducer_life": "T_av giving the required life",
                "screw_life": "F_m (cubic mean, speed-weighted) giving the required life",
                "slack": "|E| at the least slack ratio: T_i / (ratio + 1/2)",
                "worm_efficiency": "required efficiency over the duty cycle"}


@dataclass
class VerifyOutcome:
    rows: list
    results: list
    plots: list
    spectra: list = ()

    @property
    def passed(self) -> bool:
        return all(r.passed for r in self.rows)


def count_jobs(manifest) -> int:
    return len(jobs_of(manifest))


def run_verify(manifest_path, *, jobs: int | None = None, dask_address: str | None = None, junit=None,
               json_path=None, markdown_path=None, plots_dir=None, progress=None, manifest=None,
               spectra_dir=None, html_path=None) -> VerifyOutcome:
    """Run a manifest (already loaded with :func:`load_manifest` when ``manifest`` is given)
    and write the requested reports (``spectra_dir``: the load spectra, :mod:`.spectra`);
    ``progress(total=..)`` once, then ``progress()`` per job.
    ``jobs`` and ``dask_address`` exclude each other (the cluster has its own workers)."""
    if jobs is not None and dask_address is not None:
        raise GearcliError("verify: give -j/--jobs or --dask, not both (a Dask cluster has its own workers)")
    manifest = manifest or load_manifest(manifest_path)
    check_outputs(manifest, {"--junit": junit, "--json": json_path, "--markdown": markdown_path, "--html": html_path})
    for d, option in ((plots_dir, "--plots"), (spectra_dir, "--spectra")):
        if d is not None and not str(d).strip():
            raise OutputError(option, "empty directory name (give a directory for the files)", place="")
        if d is not None:
            make_plot_dir(Path(d), option)
    results = run_manifest(manifest, jobs=jobs, dask_address=dask_address, progress=progress)
    rows = rows_of(results)
    suite = manifest.name
    if junit:
        write_junit(rows, junit, suite)
    if json_path:
        write_json(rows, json_path, str(manifest_path))
    if markdown_path:
        write_markdown(rows, markdown_path, str(manifest_path))
    plots = write_plots(results, Path(plots_dir)) if plots_dir is not None else []
    spectra = write_spectra(results, Path(spectra_dir)) if spectra_dir is not None else []
    if html_path:
        write_html(rows, results, html_path, str(manifest_path))
    return VerifyOutcome(rows, results, plots, spectra)


def write_html(rows, results, path, manifest: str) -> None:
    """The self-contained HTML report (:mod:`.html_report`): every check's plot made in a
    temporary folder and inlined, each case's graph as SVG; written atomically."""
    import tempfile  # noqa: PLC0415

    from ..io.output import write_text  # noqa: PLC0415
    from ..report.graph_svg import graph_svg  # noqa: PLC0415
    from .html_report import html_report  # noqa: PLC0415
    from .manifest import case_analysis  # noqa: PLC0415
    with tempfile.TemporaryDirectory() as tmp:
        made = write_plots(results, Path(tmp), every=True)
        keys = [(r.case.name, v.check.component, v.check.quantity) for r in results for v in r.verdicts]
        plots = dict(zip(keys, made))
        graphs = {r.case.name: graph_svg(case_analysis(r.case.mechanism)) for r in results}
        write_text(path, html_report(rows, results, manifest, plots, graphs))


def check_outputs(manifest, paths: dict) -> None:
    """Refuse, before any work, report paths (``{option: path or None}``) that cannot be
    written or name an input file; the message names the option."""
    inputs = [manifest.path] + [p for c in manifest.cases for p in (c.mechanism, *c.trajectories)]
    for option, p in paths.items():
        if p is not None:
            output_target(p, inputs, option)


def make_plot_dir(directory: Path, option: str = "--plots") -> None:
    """Create the ``--plots`` (``--spectra``) directory before any work; problems are bad input."""
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise GearcliError(f"{directory}: {option}: cannot create the directory: {exc.strerror}") from None


def write_plots(results, directory: Path, every: bool = False) -> list[Path]:
    """One PNG per failing or tight (< 10 % margin) check (``every``: per check, in the order
    of the cases' verdicts): its quantity along the worst trajectory with the level that just
    meets the limit."""
    out = []
    for r in results:
        for n, v in enumerate(r.verdicts):
            if v.passed and v.margin >= WARN_MARGIN and not every:
                continue
            ch = v.check
            stem = f"{_slug(r.case.name)}__{_slug(ch.component)}__{_slug(ch.quantity)}"
            path = directory / (f"{stem}__{n}.png" if every else f"{stem}.png")
            status = "FAIL" if not v.passed else ("tight" if v.margin < WARN_MARGIN else "ok")
            if ch.kind in ("life", "fatigue", "reducer_life"):
                out.append(profile_plot(r, v, path, f"{r.case.name}: {ch.name} ({status}, margin {v.margin:.3g} %)"))
                continue
            t, y = worst_samples(r, v)
            if ch.kind == "rms":            # the RMS so far (its last value is the trajectory's RMS)
                y = cumulative_rms(y, t)
            label = SIGNAL_LABELS[ch.signal[0]].format(ch.signal[1] if ch.signal[0] in ("abs", "col", "running_rms") else "")
            title = (f"{r.case.name}: {ch.name} ({status}, margin {v.margin:.3g} %)\n"
                     f"worst trajectory {Path(r.case.trajectories[v.trajectory]).name}")
            ylabel = f"{label} [{ch.signal_unit}]" if ch.signal_unit else f"{label} (dimensionless)"
            levels = ((v.value, f"efficiency over the duty cycle: {v.value:.4g}"),) \
                if ch.kind == "worm_efficiency" and math.isfinite(v.value) else ()
            plot_check(t, y, v.signal_limit, path, title, ylabel, LIMIT_LABELS[ch.kind], levels)
            out.append(path)
    return out
