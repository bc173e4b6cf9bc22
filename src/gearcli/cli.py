"""The ``gearcli`` command line (typer + rich): check, graph, solve, simulate, export, verify, plot.

Every bad input (unreadable file, YAML or schema error, inconsistent geometry, ...) is
reported as one line per problem on stderr, ``file:line: yaml.path: message``, with exit
status 2 and no traceback; commands get that behaviour from
:func:`gearcli.exits.reports_bad_input`.
SI units throughout: m, kg, kg*m^2, rad (degrees only in ``*_deg`` fields of input files).
"""
from __future__ import annotations

import json
import math
import sys
from contextlib import nullcontext
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from . import __version__
from .errors import GearcliError, counted, plural
from .exits import EXIT_BROKEN_PIPE, EXIT_CHECK_FAILED, bad_input_exits, print_problems, reports_bad_input, stderr_may_fail
from .report.features import feature_notes
from .report.sharing import sharing_notes
from .report.tables import JSON_DIGITS, print_graph_tables, round_sig, stderr_console, stdout_console, summary_table

if TYPE_CHECKING:  # pragma: no cover
    from .analysis.graph import Analysis


class _App(typer.Typer):
    """A failure outside a command (``--help`` into a full stdout) is one line too, no
    traceback; a closed pipe there ends with status 141 too."""
    def __call__(self, *args, **kwargs):
        try:
            with bad_input_exits():
                if sys.stdout is None:    # closed (>&-): refused like any Unix tool does
                    raise OSError("stdout is closed")
                return super().__call__(*args, **kwargs)
        except typer.Exit as exc:
            sys.exit(exc.exit_code)
        except SystemExit as exc:
            if exc.code == 1 and type(sys.stdout).__name__ == "PacifyFlushWrapper":
                # click's (or typer's copy of click's) answer to a closed pipe during
                # --help/--version: stdout wrapped, exit 1; gearcli's is 141, as for commands
                sys.exit(EXIT_BROKEN_PIPE)
            raise


app = _App(
    name="gearcli",
    help="Dynamics of geared robotic mechanisms: canonical graph, structure matrix, motor "
         "torques, bearing loads and gear tooth forces.  SI units: m, kg, kg*m^2, rad, N, N*m.",
    no_args_is_help=True, add_completion=False, rich_markup_mode=None, pretty_exceptions_show_locals=False,
)

MECH_HELP = ("Mechanism file: YAML (schemas/mechanism.schema.json) or URDF (.urdf, .xml).  Lengths in m, "
             "masses in kg, inertias in kg*m^2, angles in rad (degrees in *_deg fields).")


def load_analysis(path: Path, strict: bool = False) -> Analysis:
    """Load and analyse a mechanism file (raises GearcliError on bad input).

    Input problems the loader worked around (``Mechanism.warnings``) and implausible values
    (:mod:`gearcli.model.plausibility`: a mechanism in mm, ...) go to stderr, one line each,
    without changing the exit status; with ``strict`` they are errors (exit status 2).
    """
    from .dynamics.determinacy import load_analysed  # noqa: PLC0415  (keeps --help fast; not the solver)

    an = load_analysed(path)
    report_mechanism_warnings(an, strict)
    return an


def report_mechanism_warnings(an: Analysis, strict: bool) -> None:
    """Print the loader's warnings and the plausibility findings of ``an``; with ``strict``
    raise them instead (:class:`~gearcli.report.unit_warnings.StrictError`)."""
    from .report.unit_warnings import StrictError, mechanism_issues, warning_lines  # noqa: PLC0415

    loader = list(getattr(an.mech, "warnings", ()))
    issues = mechanism_issues(an)
    if strict and (loader or issues):
        raise StrictError(issues, loader)
    print_problems([w.shown() if hasattr(w, "shown") else f"warning: {w}" for w in loader] + warning_lines(issues))


STRICT_OPTION = typer.Option(False, "--strict", help="Warnings are errors (exit 2): implausible values "
                             "(a mechanism in mm, a trajectory in degrees read as rad; docs/reference/mechanism-files.md, Plausibility "
                             "warnings) and input the reader worked around.")


# ---------------------------------------------------------------------------------------
# commands
# ---------------------------------------------------------------------------------------
def _version(value: bool) -> None:
    if value:
        typer.echo(f"gearcli {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                 help="Print the gearcli version and exit."),
) -> None:
    """Dynamics of geared robotic mechanisms (SI units: m, kg, kg*m^2, rad, N, N*m).

    Bad input is reported one problem per line on stderr as file:line: yaml.path: message,
    with exit status 2.
    """


@app.command()
@reports_bad_input
def check(mech: Path = typer.Argument(..., metavar="MECH", help=MECH_HELP, show_default=False),
          strict: bool = STRICT_OPTION) -> None:
    """Validate a mechanism file: schema, names, masses and inertias, joint tree, gear
    geometry (pitch radii in m, cone angles), motors against the degrees of freedom, and
    static determinacy of the loads, ratings against the geometry, losses (mesh efficiency
    in (0, 1], friction >= 0), and the plausibility of the values (warnings).  Prints a
    one-line summary, then one line per external load, helical or rack pair, lossy gear
    pair (efficiency, friction arm in m) and joint with friction; exit 2 on bad input."""
    an = load_analysis(mech, strict)
    _check_ratings(an)
    m = an.mech
    kinds = {"reducer": "reducer", "screw": "screw", "belt": "belt"}
    count = {k: sum(1 for c in an.circuits if getattr(m.gears[c.gear], k) is not None) for k in kinds}
    pairs = counted(len(an.circuits) - sum(count.values()), 'gear pair') + "".join(
        f", {counted(n, kinds[k])}" for k, n in count.items() if n)
    typer.echo(f"{mech}: OK ({an.dof} dof, {counted(len(m.links), 'link')}, {pairs}, {counted(len(m.motors), 'motor')})")
    for line in feature_notes(an) + sharing_notes(an):
        typer.echo(line)


def _check_ratings(an: Analysis) -> None:
    """The ratings against the mechanism, as ``verify`` checks them (a module that
    contradicts the pitch radii, ...): raises :class:`~gearcli.errors.MechanismError`."""
    m = an.mech
    if not any(g.rating for g in m.gears):   # the other ratings are checked by the readers
        return
    from .design.checks import Requirements, build_checks  # noqa: PLC0415
    from .errors import Collector  # noqa: PLC0415

    col = Collector(m.source, m.lines)
    build_checks(an, Requirements(), col)
    col.raise_if_any()


@app.command()
@reports_bad_input
def graph(
    mech: Path = typer.Argument(..., metavar="MECH", help=MECH_HELP, show_default=False),
    as_json: bool = typer.Option(False, "--json", help="Print the analysis as JSON (floats to "
                                 f"{JSON_DIGITS} significant digits; ratios dimensionless)."),
    as_dot: bool = typer.Option(False, "--dot", help="Print the canonical graph as Graphviz DOT "
                                "(render with: dot -Tsvg)."),
    real_joints: bool = typer.Option(False, "--real-joints", help="With --dot: draw the real "
                                     "joints (bearings) instead of the canonical thin edges."),
    svg: str = typer.Option(None, "--svg", metavar="GRAPH.svg", help="Also draw the canonical graph as SVG "
                            "(a column per level; heavy edges for the gear pairs and drive elements), as the "
                            "verify --html report does."),
    strict: bool = STRICT_OPTION,
) -> None:
    """Show the graph analysis: links with level, primary/secondary, carrier and axis label;
    gear pairs with their fundamental-circuit equations; coaxial groups; transmission lines;
    degrees of freedom; structure matrix A (rows: independent joints, columns: motors; motor
    input rotations in rad = A^T x joint rotations in rad); pseudo-triangularity; solve order."""
    if as_json and as_dot:
        raise GearcliError("graph: give at most one of --json and --dot")
    if real_joints and not as_dot:
        raise GearcliError("graph: --real-joints only applies to --dot")
    if svg is not None:
        from .io.output import atomic_output, output_target  # noqa: PLC0415
        if svg == "-":
            raise GearcliError("--svg: expected a file name, got '-' (the graph's tables go to stdout)")
        output_target(svg, (mech,), "--svg")
    an = load_analysis(mech, strict)
    if svg is not None:
        from .report.graph_svg import graph_svg  # noqa: PLC0415

        with atomic_output(svg, (mech,)) as f:
            f.write(graph_svg(an))
    if as_json:
        from .report.graph_json import analysis_dict  # noqa: PLC0415

        typer.echo(json.dumps(round_sig(analysis_dict(an)), indent=2))
    elif as_dot:
        from .report.dot import to_dot  # noqa: PLC0415

        typer.echo(to_dot(an, real=real_joints), nl=False)
    else:
        print_graph_tables(an, stdout_console())


# solve
# ---------------------------------------------------------------------------------------
TRAJ_HELP = ("Trajectory CSV: header t,q:<joint>,... for every independent joint (rad; m if prismatic), optional "
             "qd:/qdd: columns (rad/s, rad/s^2), load:<name>:fx..mz (N, N*m), attach:<payload> (0 or 1); time t in s, strictly increasing.")

METHOD_OPTION = typer.Option("block", "--method", metavar="block|full", help="'block': level-by-level schedule (fast); 'full': cross-check.")
JOBS_OPTION = typer.Option(None, "--jobs", "-j", min=1, metavar="N",
                           help="Threads: solve and CSV (default: all cores; same results).")
BACKEND_OPTION = typer.Option("auto", "--backend", metavar="auto|llvm|numpy", help="'llvm' (kernel generated for the mechanism), 'numpy' (reference) or 'auto': llvm, numpy where it cannot run (a notice says why) or for a short first run.")


@app.command()
@reports_bad_input
def solve(
    mech: Path = typer.Argument(..., metavar="MECH", help=MECH_HELP, show_default=False),
    traj: Path = typer.Argument(..., metavar="TRAJ.csv", help=TRAJ_HELP, show_default=False),
    output: str = typer.Option(None, "-o", "--output", metavar="OUT.csv|parquet|feather|npz",
                               help="Loads table to write, one row per sample, format by extension "
                                    "('-': CSV to stdout). Default: TRAJ.loads.csv beside the trajectory."),
    precision: int = typer.Option(None, "--precision", metavar="N", help="Significant digits of CSV "
                                  "values, 1..17 (default 9; 17 round-trips float64)."),
    degrees: bool = typer.Option(False, "--degrees", help="Angle columns of the trajectory are in "
                                 "degrees (deg, deg/s, deg/s^2)."),
    method: str = METHOD_OPTION,
    verify: bool = typer.Option(False, "--verify", help="Compute every link's Newton-Euler "
                                "residual from the solved forces and print the worst (relative)."),
    chunk: int = typer.Option(20_000, "--chunk", min=100, metavar="N", help="Samples processed at once (bounds memory)."),
    jobs: int = JOBS_OPTION,
    backend: str = BACKEND_OPTION,
    strict: bool = STRICT_OPTION,
) -> None:
    """Motor torques (N*m), bearing reaction wrenches (N, N*m, parent on child, joint frame)
    and gear tooth forces (N) at every sample of a trajectory.  Writes a table (CSV, Parquet,
    Feather or NPZ; columns in docs/reference/outputs.md) and prints, for every motor, gear mesh and bearing, the peak, RMS and time of
    the peak.  A mechanism with losses (gears[].efficiency or loss_factor, joints[].friction,
    bearings' friction_coefficient and bore) has them in the motor torques, adds the columns
    gear:<pair>:loss (W), joint:<joint>:friction (N*m; N if prismatic) and joint:<joint>:loss
    (W), and prints the energy lost (J) by element and each motor's line efficiency."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn  # noqa: PLC0415

    from .pipeline import check_solve_options, solve_file  # noqa: PLC0415
    from .report.progress import LateProgress  # noqa: PLC0415

    an = check_solve_options(load_analysis(mech, strict), method, backend)
    out = output if output is not None else str(traj.with_suffix(".loads.csv"))
    err = stderr_console()
    to_stdout = out == "-"
    bar = Progress(TextColumn("solving"), BarColumn(), TextColumn("{task.completed:,}/{task.total:,} samples"),
                   TimeRemainingColumn(), console=err, transient=True, disable=not err.is_terminal)
    with LateProgress(bar, "solve") as progress:   # shown once the run has taken a second
        report = solve_file(mech, traj, out, degrees=degrees, method=method, verify=verify,
                            chunk=chunk, progress=progress.update, analysis=an, precision=precision,
                            backend=backend, jobs=jobs, strict=strict)
    from .report.unit_warnings import warning_lines  # noqa: PLC0415

    print_problems(warning_lines(report.warnings) + report.notices())
    with stderr_may_fail() if to_stdout else nullcontext():   # the table is out: stderr is for information
        _print_summary(err if to_stdout else stdout_console(), report, verify)
    if not to_stdout:
        stdout_console().print(f"Wrote {counted(report.samples, 'row')} to {out}")


def _print_summary(console, report, verify: bool) -> None:
    """Peak/RMS table of a solve, ideal pairs, feature notes, the residual (``--verify``)."""
    an = report.analysis
    console.print(summary_table(report))
    ideal = [an.mech.gears[c.gear].name for c in an.circuits if c.geometry is None and an.mech.gears[c.gear].reducer is None
             and an.mech.gears[c.gear].screw is None and an.mech.gears[c.gear].worm is None
             and an.mech.gears[c.gear].belt is None]
    if ideal:
        console.print("Ideal pairs (no mesh geometry; mesh torque instead of tooth forces): " + ", ".join(ideal))
    for line in feature_notes(an) + sharing_notes(an) + [report.backend_line()]:
        console.print(line, markup=False)
    if report.losses is not None:
        for line in report.losses.lines():
            console.print(line, markup=False)
    if verify:
        console.print(f"Worst Newton-Euler residual (relative): {report.residual:.3g}")


# ---------------------------------------------------------------------------------------
# simulate
# ---------------------------------------------------------------------------------------
@app.command()
@reports_bad_input
def simulate(
    mech: Path = typer.Argument(..., metavar="MECH", help=MECH_HELP, show_default=False),
    drive: Path = typer.Argument(..., metavar="INPUT.csv", show_default=False,
                                 help="t, motor:<m> (N*m) or voltage:<m> (V), optional attach:<payload> (0 or 1)."),
    output: str = typer.Option(..., "-o", "--output", metavar="TRAJ.csv", help="Trajectory to write (t, q:, qd:, qdd:)."),
    t_end: float = typer.Option(None, "--t-end", metavar="T", help="End time, s (default: the input's last t)."),
    q0: str = typer.Option(None, "--q0", metavar="Q1,Q2,...", help="Initial joint angles, rad (m) (default 0)."),
    qd0: str = typer.Option(None, "--qd0", metavar="V1,V2,...", help="Initial rates, rad/s (m/s) (default 0)."),
    dt: float = typer.Option(1e-3, "--dt", metavar="S", help="Output time step, s."),
    rtol: float = typer.Option(1e-6, "--rtol", metavar="R", help="Relative tolerance of the integrator."),
    atol: float = typer.Option(1e-9, "--atol", metavar="A", help="Absolute tolerance (rad, rad/s, A)."),
    method: str = typer.Option("RK45", "--method", metavar="NAME", help="solve_ivp: RK45, DOP853, RK23, Radau, BDF, LSODA."),
    loads: str = typer.Option(None, "--loads", metavar="LOADS.csv", help="Also write the loads, as 'gearcli solve'."),
) -> None:
    """Integrate the exact geared dynamics under motor torques or voltages, losses included (its energy falls by them;
    --loads has gear:<pair>:loss, joint:<joint>:loss in W, joint:<joint>:friction).  Joints with Coulomb friction stick
    and slip (joints[].friction.static), held at rest by mesh, drive-element and bearing friction too, each up to its
    Coulomb value at the load; attach:<payload> columns (0/1, held from row to row) carry payloads.  A joint
    limit, a stall or a failure after the first sample stops it: the trajectory up to there is written (exit 1)."""
    from .simulation import simulate_with_progress  # noqa: PLC0415
    report = simulate_with_progress(mech, drive, output, stderr_console(), load_analysis(mech), t_end, q0, qd0, dt, rtol, atol, method, loads)
    if report.simulation.stop:
        print_problems([f"{drive}: stopped: {report.simulation.stop} (the trajectory up to there is written)"])
        raise typer.Exit(EXIT_CHECK_FAILED)


# ---------------------------------------------------------------------------------------
# export
# ---------------------------------------------------------------------------------------
@app.command()
@reports_bad_input
def export(
    mech: Path = typer.Argument(..., metavar="MECH", help=MECH_HELP, show_default=False),
    output: str = typer.Option(..., "-o", "--output", metavar="OUT.urdf",
                               help="URDF file to write, named .urdf or .xml (written to a temporary file, then renamed; "
                                    "'-' for stdout)."),
    strict: bool = STRICT_OPTION,
) -> None:
    """Write a URDF of the mechanism: links with inertials, the joint tree, geared joints as <mimic> where a single
    leader exists, motors as <transmission>, the gear geometry and losses (gearcli:gear efficiency or loss_factor,
    gearcli:friction coulomb viscous, gearcli:bearing friction_coefficient bore in m) in gearcli extension elements."""
    from .report.urdf_writer import export_urdf, urdf_target  # noqa: PLC0415

    urdf_target(output, (mech,))   # refuse a bad -o (also one not named .urdf/.xml) before any work
    an = load_analysis(mech, strict)
    if output == "-":
        typer.echo(export_urdf(an), nl=False)
        return
    export_urdf(an, output)
    typer.echo(f"Wrote {output}")


# ---------------------------------------------------------------------------------------
# verify, plot
# ---------------------------------------------------------------------------------------
@app.command()
@reports_bad_input
def verify(
    design: Path = typer.Argument(..., metavar="DESIGN.yaml", show_default=False,
                                  help="Design manifest (schemas/design.schema.json): cases of rated "
                                       "mechanisms, trajectories and limits."),
    junit: str = typer.Option(None, "--junit", metavar="FILE", help="Write JUnit XML (one testcase per check)."),
    json_out: str = typer.Option(None, "--json", metavar="FILE", help="Write the checks as JSON."),
    markdown: str = typer.Option(None, "--markdown", metavar="FILE", help="Write a Markdown table (CI job summary)."),
    html_out: str = typer.Option(None, "--html", metavar="REPORT.html", help="Write a self-contained HTML report "
                                 "(summary, sortable checks, each check's plot, the mechanisms' graphs, versions; "
                                 "no network needed: a CI artefact)."),
    plots: str = typer.Option(None, "--plots", metavar="DIR", help="Write a PNG of each failing or tight "
                               "(< 10 % margin) check along its worst trajectory."),
    spectra: str = typer.Option(None, "--spectra", metavar="DIR", help="Write each case's load spectra (time "
                                 "and revolutions per hour at each load level of every motor, gear mesh and "
                                 "rated bearing) as CSV and JSON."),
    jobs: int = typer.Option(None, "-j", "--jobs", min=1, metavar="N", help="Worker processes (default: the number of cores)."),
    dask: str = typer.Option(None, "--dask", metavar="ADDRESS", help="Run on an existing dask.distributed "
                             "cluster (scheduler address, e.g. tcp://host:8786)."),
    strict: bool = STRICT_OPTION,
) -> None:
    """Check motors (peak/RMS torque, speed, power; servo sizing: inertia ratio, torque-speed envelope, regenerative
    energy per cycle), bearings (ISO 281 life, static safety, tilting moment), gear teeth (bending and contact stress)
    and column limits along every trajectory of each case, with the motor torques of 'gearcli solve' (losses included:
    mesh efficiency, joint and bearing friction).  Exit 0 when every check passes, 1 when any fails, 2 on bad input."""
    from rich.progress import BarColumn, Progress, TextColumn  # noqa: PLC0415

    from .batch.manifest import load_manifest  # noqa: PLC0415
    from .batch.outputs import backends, rich_table, with_unit  # noqa: PLC0415
    from .batch.verify import count_jobs, run_verify  # noqa: PLC0415
    from .report.progress import LateProgress  # noqa: PLC0415

    manifest = load_manifest(design)
    _case_mechanism_warnings(manifest, strict)
    err = stderr_console()
    bar = Progress(TextColumn("verifying"), BarColumn(), TextColumn("{task.completed}/{task.total} trajectories"),
                   console=err, transient=True, disable=not err.is_terminal)
    with LateProgress(bar, "verify") as progress:   # shown once the run has taken a second
        progress.update(total=count_jobs(manifest))
        outcome = run_verify(design, jobs=jobs, dask_address=dask, junit=junit, json_path=json_out,
                             markdown_path=markdown, plots_dir=plots, manifest=manifest, spectra_dir=spectra,
                             html_path=html_out,
                             progress=lambda: progress.update(advance=1))
    stdout_console().print(rich_table(outcome.rows))
    typer.echo("".join(f"Backend of {case}: {backend}\n" for case, backend in backends(outcome.rows).items()), nl=False)
    for line in _worm_lines(manifest):
        typer.echo(line)
    failed = [r for r in outcome.rows if not r.passed]
    for r in failed:
        typer.echo(f"FAILED {r.case}: {r.name}: worst {with_unit(r.value, r.unit)} against limit {with_unit(r.limit, r.unit)}")
    typer.echo(f"{len(outcome.rows) - len(failed)} of {counted(len(outcome.rows), 'check')} passed" +
               (f"; {counted(len(outcome.plots), 'plot')} in {plots}" if plots else "") +
               (f"; load spectra of {counted(len(outcome.spectra) // 2, 'case')} in {spectra}" if spectra else ""))
    if failed:
        raise typer.Exit(EXIT_CHECK_FAILED)


@app.command()
@reports_bad_input
def sweep(
    design: Path = typer.Argument(..., metavar="DESIGN.yaml", show_default=False,
                                  help="Design manifest, as gearcli verify reads it."),
    vary: list[str] = typer.Option(..., "--vary", metavar="PATH=VALUES", help="A number of the cases' YAML "
                                   "mechanism files and its values: links.payload.mass=0.5,1,2 (a list), "
                                   "gears.g1.ratio=50:120:8 (a:b:n, n values), log:a:b:n (evenly in log); "
                                   "CASE:PATH for one case's mechanism.  Repeat for a grid.  A gear pair's ratio "
                                   "or teeth moves its mesh point (the axes kept)."),
    output: str = typer.Option(None, "-o", "--output", metavar="TABLE.csv|parquet|feather",
                               help="Write one row per variant: the varied values, every check's value, limit and "
                                    "margin %, the worst margin and its check."),
    plot: str = typer.Option(None, "--plot", metavar="FIG.png|svg|pdf", help="Draw the worst margin over one or "
                             "two varied values."),
    samples: int = typer.Option(None, "--samples", metavar="N", help="Verify N variants drawn at random from the "
                                "grid (seed --seed) instead of the whole grid."),
    seed: int = typer.Option(0, "--seed", metavar="S", help="Seed of --samples."),
    jobs: int = typer.Option(1, "-j", "--jobs", min=1, metavar="N", help="Worker processes."),
    dask: str = typer.Option(None, "--dask", metavar="ADDRESS", help="Run on an existing dask.distributed "
                             "cluster (scheduler address)."),
    resume: bool = typer.Option(False, "--resume", help="Continue an interrupted sweep from TABLE's partial file "
                                "(TABLE.partial: the variants it finished)."),
) -> None:
    """Verify a design over a grid of mechanism values: every check of the manifest on every variant (the
    mechanism files with the --vary numbers replaced), with a table and a plot of the worst margin.  Paths and
    values are checked before anything runs.  Exit 0 when the sweep ran (failing variants are rows of the table),
    2 on bad input."""
    from rich.progress import BarColumn, Progress, TextColumn  # noqa: PLC0415

    from .batch.manifest import load_manifest  # noqa: PLC0415
    from .batch.sweep import (PartialFile, output_names, parse_vary, partial_path, plan_sweep,  # noqa: PLC0415
                              plot_sweep, read_partial, run_sweep, table, write_table)
    from .io.output import output_target  # noqa: PLC0415
    from .report.progress import LateProgress  # noqa: PLC0415

    if jobs > 1 and dask is not None:
        raise GearcliError("sweep: give -j/--jobs or --dask, not both (a Dask cluster has its own workers)")
    varies = [parse_vary(v) for v in vary]
    manifest = load_manifest(design)
    inputs = [design] + [c.mechanism for c in manifest.cases] + [t for c in manifest.cases for t in c.trajectories]
    output_names(inputs, ("-o", output), plot)
    if plot is not None and len(varies) > 2:
        raise GearcliError(f"--plot: draws the worst margin over one or two varied values, {len(varies)} vary")
    if resume and output is None:
        raise GearcliError("--resume: give -o TABLE (the partial file TABLE.partial holds the finished variants)")
    plan = plan_sweep(manifest, varies, samples, seed)
    partial, done = None, {}
    if output is not None:
        partial = partial_path(output)
        output_target(str(partial), inputs)
        if resume and not partial.exists():
            raise GearcliError(f"--resume: {partial} does not exist: no interrupted sweep to continue")
        if not resume and partial.exists():
            raise GearcliError(f"{partial}: an interrupted sweep's finished variants: give --resume to continue it, "
                               f"or remove the file to start again")
        done = read_partial(partial, plan) if resume else {}
    err = stderr_console()
    bar = Progress(TextColumn("sweeping"), BarColumn(), TextColumn("{task.completed}/{task.total} variants"),
                   console=err, transient=True, disable=not err.is_terminal)
    record = PartialFile(partial, plan, resume) if partial is not None else None
    try:
        with LateProgress(bar, "sweep") as progress:
            progress.update(total=len(plan.variants))
            results = run_sweep(plan, jobs=jobs, dask_address=dask, progress=lambda n: progress.update(advance=n),
                                done=done, record=record)
    finally:
        if record is not None:
            record.close()
    cols = table(plan, results)
    if output is not None:
        write_table(cols, output, inputs)
        partial.unlink()
    if plot is not None:
        plot_sweep(plan, cols, plot, inputs)
    names = list(cols)[:len(varies)]
    passed = sum(cols["passed"])
    typer.echo(f"{counted(len(plan.variants), 'variant')} of {design}: {passed} pass every check"
               + (f" ({len(done)} from {partial})" if done else ""))
    not_run = [w for w in cols["worst_check"] if w.startswith("not run: ")]
    if not_run:
        typer.echo(f"{counted(len(not_run), 'variant')} could not run: the first: {not_run[0][9:]}")
    best = max(range(len(plan.variants)), key=lambda i: (cols["worst_margin_%"][i] == cols["worst_margin_%"][i],
                                                        cols["worst_margin_%"][i]))
    said = ", ".join(f"{n} = {cols[n][best]:g}" for n in names)
    typer.echo(f"best: {said}: worst margin {cols['worst_margin_%'][best]:.4g} % ({cols['worst_check'][best]})")
    for path, what in ((output, "table"), (plot, "plot")):
        if path is not None:
            typer.echo(f"Wrote the {what} to {path}")


@app.command()
@reports_bad_input
def select(
    design: Path = typer.Argument(..., metavar="DESIGN.yaml", show_default=False,
                                  help="Design manifest with slots: the parts to choose, each from a catalogue CSV."),
    objective: str = typer.Option("mass", "--objective", metavar="mass|cost|inertia", help="What the choice "
                                  "minimises: the sum of the chosen parts' catalogue column of that name."),
    output: str = typer.Option(None, "-o", "--output", metavar="DIR", help="Write the chosen design there: each "
                               "mechanism file with the chosen parts' values and a manifest gearcli verify runs."),
    table_out: str = typer.Option(None, "--table", metavar="TABLE.csv|parquet|feather", help="Write every "
                                  "combination, ranked: its parts, objective, worst margin and failing checks."),
    plot: str = typer.Option(None, "--plot", metavar="FIG.png|svg|pdf", help="Draw the objective against the "
                             "worst margin of every combination, with the feasible ones' Pareto front."),
    search: str = typer.Option("auto", "--search", metavar="auto|exhaustive|iterate", help="'exhaustive': verify "
                               "every combination (the lightest); 'iterate': choose slot by slot, each candidate verified with its "
                               "own loads, until no one-slot change is lighter; 'auto': exhaustive up to 2,000 "
                               "combinations."),
    jobs: int = typer.Option(1, "-j", "--jobs", min=1, metavar="N", help="Worker processes."),
    dask: str = typer.Option(None, "--dask", metavar="ADDRESS", help="Run on an existing dask.distributed "
                             "cluster (scheduler address)."),
) -> None:
    """Choose one part per slot from its catalogue (motors, reducers, bearings, ...) so that every check of the
    manifest passes at the least total mass (cost, inertia): every combination is verified with its own loads (a
    heavier outer part loads the inner joints).  Exit 0 with a feasible choice, 1 when none passes (the closest
    ones and their failing checks are shown), 2 on bad input."""
    from rich.progress import BarColumn, Progress, TextColumn  # noqa: PLC0415

    from .batch.manifest import load_manifest  # noqa: PLC0415
    from .batch.select import (EXHAUSTIVE_LIMIT, combinations, iterate, objective_of, plan_of,  # noqa: PLC0415
                               plot_pareto, prepare, rank, select_table, slots_of, write_choice)
    from .batch.sweep import output_names, run_sweep, write_table  # noqa: PLC0415
    from .report.progress import LateProgress  # noqa: PLC0415

    if jobs > 1 and dask is not None:
        raise GearcliError("select: give -j/--jobs or --dask, not both (a Dask cluster has its own workers)")
    manifest = load_manifest(design)
    inputs = [design] + [c.mechanism for c in manifest.cases] + [t for c in manifest.cases for t in c.trajectories]
    output_names(inputs, ("--table", table_out), plot)
    if output is not None and (not output.strip() or Path(output).exists() and not Path(output).is_dir()):
        raise GearcliError(f"-o: expected a directory for the chosen design, got '{output}'")
    slots = slots_of(manifest)
    inputs += [s.catalogue for s in slots]
    if search not in ("auto", "exhaustive", "iterate"):
        raise GearcliError(f"--search: expected auto, exhaustive or iterate, got '{search}'")
    varies = prepare(manifest, slots, objective)
    total = math.prod(len(s.parts) for s in slots)
    how = search if search != "auto" else ("exhaustive" if total <= EXHAUSTIVE_LIMIT else "iterate")
    err = stderr_console()
    bar = Progress(TextColumn("selecting"), BarColumn(), TextColumn("{task.completed}/{task.total} combinations"),
                   console=err, transient=True, disable=not err.is_terminal)
    from concurrent.futures import ProcessPoolExecutor  # noqa: PLC0415
    from contextlib import nullcontext  # noqa: PLC0415
    with LateProgress(bar, "select") as progress, \
            (ProcessPoolExecutor(max_workers=jobs) if jobs > 1 else nullcontext()) as pool:
        def evaluate(combos: list) -> list:
            progress.update(total=(progress.total or 0) + len(combos))
            return run_sweep(plan_of(manifest, varies, slots, combos), jobs=jobs, dask_address=dask,
                             progress=lambda n: progress.update(advance=n), pool=pool)
        if how == "exhaustive":
            combos = combinations(slots)
            results = evaluate(combos)
        else:
            verified, _ = iterate(slots, objective, evaluate)
            combos, results = list(verified), list(verified.values())
    ranked = rank(combos, [objective_of(slots, c, objective) for c in combos], results)
    plan = plan_of(manifest, varies, slots, [r.combo for r in ranked[:1]])
    if table_out is not None:
        write_table(select_table(slots, ranked, objective), table_out, inputs)
    if plot is not None:
        plot_pareto(ranked, objective, plot, inputs)
    feasible = sum(r.feasible for r in ranked)
    if how == "exhaustive":
        typer.echo(f"{counted(len(ranked), 'combination')} of {counted(len(slots), 'slot')}: {feasible} feasible")
    else:
        typer.echo(f"{len(ranked):,} of {total:,} {plural(total, 'combination')} of {counted(len(slots), 'slot')} verified "
                   f"by the iterative search: {feasible} feasible")

    def parts(r) -> str:
        return ", ".join(f"{s.name} = {s.parts[k].name}" for s, k in zip(slots, r.combo))
    if feasible:
        best = ranked[0]
        typer.echo(f"chosen: {parts(best)}: total {objective} {best.objective:.6g}, worst margin {best.worst:.4g} % "
                   f"({best.worst_check})")
        for s, k in zip(slots, best.combo):
            typer.echo(f"  {s.name}: {s.parts[k].name} ({s.parts[k].source})")
        if output is not None:
            for f in write_choice(manifest, slots, plan, best, Path(output)):
                typer.echo(f"Wrote {f}")
    else:
        typer.echo("no combination passes every check; the closest:")
        for r in ranked[:3]:
            typer.echo(f"  {parts(r)}: worst margin {r.worst:.4g} %; failing: {'; '.join(r.failing)}")
    for path, what in ((table_out, "ranked table"), (plot, "plot")):
        if path is not None:
            typer.echo(f"Wrote the {what} to {path}")
    if not feasible:
        raise typer.Exit(EXIT_CHECK_FAILED)


def _worm_lines(manifest) -> list[str]:
    """One line per worm pair of each case: its efficiencies from the geometry and, when
    self-locking, that it holds a load without a brake (docs/concepts/drive-elements.md, Worm pairs)."""
    from .batch.manifest import case_analysis  # noqa: PLC0415
    from .report.features import worm_dicts  # noqa: PLC0415

    out = []
    for case in manifest.cases:
        for d in worm_dicts(case_analysis(case.mechanism)):
            eff = d["efficiency"]
            out.append(f"Worm pair {d['pair']} of {case.name}: efficiency forward {eff['forward']:.4f}, backward "
                       f"{eff['backward']:.4f}" + ("; self-locking: it holds a load without a brake, and lowering "
                                                   "needs motor power" if d["self_locking"] else "; back-drivable"))
    return out


def _case_mechanism_warnings(manifest, strict: bool) -> None:
    """:func:`report_mechanism_warnings` of every mechanism of a manifest, once each."""
    from .batch.manifest import case_analysis  # noqa: PLC0415

    for path in dict.fromkeys(c.mechanism for c in manifest.cases):
        report_mechanism_warnings(case_analysis(path), strict)


@app.command()
@reports_bad_input
def plot(
    loads: Path = typer.Argument(..., metavar="LOADS", show_default=False,
                                 help="A loads file written by gearcli solve (.csv, .parquet, .feather, .npz)."),
    columns: list[str] = typer.Argument(..., metavar="COLUMN_OR_GLOB...", show_default=False,
                                        help="Column names or shell patterns, e.g. 'motor:*' 'gear:5-1:t'."),
    output: str = typer.Option(..., "-o", "--output", metavar="FIG.png|svg|pdf", help="Figure to write."),
) -> None:
    """Draw columns of a loads file over time (one axis per unit: N, N*m, rad/s, W; columns of
    one unit whose peaks differ more than tenfold on axes of their own, at most 3 a unit).
    Columns that cannot be drawn (not numbers, no finite value) are left out with a warning;
    at most 24 lines of 6 units are drawn."""
    from .io.limits import input_problem  # noqa: PLC0415
    from .report.plots import plot_loads_csv  # noqa: PLC0415

    why = input_problem(loads)     # a FIFO or a device is refused, not waited on or read without end
    if why:
        raise GearcliError(f"{loads}: {why}")
    report = plot_loads_csv(loads, columns, output)
    print_problems([f"warning: {note}" for note in report.notes])
    typer.echo(f"Wrote {output} ({counted(report.drawn, 'column')})")


if __name__ == "__main__":  # pragma: no cover
    app()
