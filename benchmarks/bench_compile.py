"""What the generated llvm kernel costs to make, cold and from the disk cache; prints figures.

    python benchmarks/bench_compile.py [--repeat 3] [--startup-repeat 5]

Per mechanism (every bundled one, UR5, Panda, Talos full, geared chains of 16, 32 and 64
links: the first-call table of the README), each
measurement in a fresh Python process (medians over --repeat): the llvm kernel's IR
generation and LLVM optimisation + machine code (``LlvmKernel.build_seconds``,
``compile_seconds``), the size of its IR, the first ``solve(backend="llvm")`` of 100
samples (import of llvmlite included).  "cold": each process with an empty llvm disk cache (its own
``GEARCLI_CACHE_DIR``); "cached": a fresh process whose cache holds the kernel (stored by
the cold runs): the IR is still built, the O3 passes and code generation are a load.  Then
the wall time of ``gearcli solve MECH traj.csv -o out.parquet`` on 100 samples (backend
auto: numpy by the first-call rule when cold, llvm when cached; fresh processes, cold and cached runs interleaved, medians).  Load average at the
start and the end.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from cli_stages import startup_time  # noqa: E402 (benchmarks/cli_stages.py)
from timing import load_line  # noqa: E402 (benchmarks/timing.py)

ROOT = Path(__file__).resolve().parents[1]
CHAINS = (16, 32, 64)

CHILD = """
import json, sys, time
t0 = time.perf_counter()
import numpy as np
from gearcli import analyse, load_mechanism, solve
from gearcli.dynamics.solve import solver_for
path, backend = sys.argv[1], sys.argv[2]
an = analyse(load_mechanism(path))
q = np.zeros((100, an.dof))
t1 = time.perf_counter()
solve(an, q, q, q, backend=backend, jobs=1)
t2 = time.perf_counter()
out = {"first": t2 - t1}
if backend == "llvm":
    k = solver_for(an).llvm_kernel()
    out.update(build=k.build_seconds, compile=k.compile_seconds, ir_kb=len(k.jit.ir) / 1e3,
               instructions=k.jit.ir.count("\\n  %"), from_cache=k.jit.from_cache)
print(json.dumps(out))
"""


def subjects(tmp: Path | None = None, chains=CHAINS) -> list[tuple[str, Path]]:
    """Every bundled mechanism (mechanisms/*.yaml, geared_arm.urdf), UR5, Panda and Talos
    (example-robot-data, where installed) and, given a folder ``tmp`` to write them in, the
    geared chains of tests/big_mechanisms.py with ``chains`` links."""
    out = [(p.stem, p) for p in sorted((ROOT / "mechanisms").glob("*.yaml"))]
    out.append(("geared_arm (URDF)", ROOT / "mechanisms" / "geared_arm.urdf"))
    for p in map(Path, sys.path):
        d = p / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if d.is_dir():
            out += [("UR5", d / "ur_description/urdf/ur5_robot.urdf"), ("Panda", d / "panda_description/urdf/panda.urdf"),
                    ("Talos full", d / "talos_data/robots/talos_full_v2.urdf")]
            break
    if tmp is not None:
        out.append(("planetary_5p, every loss (10 lossy pairs)", lossy_copy(ROOT / "mechanisms" / "planetary_5p.yaml",
                                                                             tmp / "planetary_5p_lossy.yaml")))
        out.append(("lossy drive, 14 links, 16 lossy pairs", ROOT / "benchmarks" / "lossy_drive_16_pairs.yaml"))
        sys.path.insert(0, str(ROOT / "tests"))
        from big_mechanisms import geared_chain  # noqa: PLC0415
        for links in chains:
            path = tmp / f"geared{links}.yaml"
            path.write_text(geared_chain(links))
            out.append((f"geared chain, {links} links", path))
    return out


def lossy_copy(src: Path, dst: Path) -> Path:
    """``src`` with every loss (issue 34's cold-compile case: a mechanism of many lossy pairs):
    efficiency 0.97 on every pair with a mesh point, Coulomb and viscous friction on every joint."""
    import yaml  # noqa: PLC0415
    data = yaml.safe_load(src.read_text())
    for g in data.get("gears", []):
        if "mesh_point" in g:
            g["efficiency"] = 0.97
    for j in data["joints"]:
        j["friction"] = {"coulomb": 0.05, "viscous": 0.002}
    dst.write_text(yaml.safe_dump(data, sort_keys=False))
    return dst


def child(path: Path, backend: str, cache: Path) -> dict:
    r = subprocess.run([sys.executable, "-c", CHILD, str(path), backend], capture_output=True, text=True, check=True,
                       env={"PYTHONPATH": str(ROOT / "src"), "PATH": "/usr/bin:/bin", "GEARCLI_CACHE_DIR": str(cache)})
    return json.loads(r.stdout.strip().splitlines()[-1])


def llvm_runs(path: Path, repeat: int, tmp: Path) -> tuple[dict, dict]:
    """Medians of ``repeat`` cold processes (each an empty cache) and ``repeat`` cached ones."""
    cold = [child(path, "llvm", tmp / f"cold{i}") for i in range(repeat)]
    warm = [child(path, "llvm", tmp / "cold0") for _ in range(repeat)]
    assert not any(r["from_cache"] for r in cold) and all(r["from_cache"] for r in warm)
    return ({k: float(np.median([r[k] for r in runs])) for k in runs[0]} for runs in (cold, warm))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--startup-repeat", type=int, default=5)
    ap.add_argument("--no-cli", action="store_true", help="skip the gearcli solve wall times")
    ap.add_argument("--only", nargs="*", help="only the mechanisms whose names contain one of these words")
    args = ap.parse_args()
    print(f"# llvm kernel: compile cost, fresh processes, medians of {args.repeat}\n{load_line()} at start\n")
    print("| mechanism | moving links | IR build | LLVM (O3; O0 passes above 1 MB of IR), cold | IR text + load, cached | IR size | instructions | "
          "first llvm solve, cold | first llvm solve, cached |\n|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name, path in subjects(Path(tmp)):
            if args.only and not any(w in name for w in args.only):
                continue
            med, warm = llvm_runs(path, args.repeat, Path(tmp) / name.replace(" ", "_"))
            from gearcli import analyse, load_mechanism  # noqa: PLC0415
            links = len(analyse(load_mechanism(path)).tree.moving)
            print(f"| {name} | {links} | {med['build']:.3f} s | {med['compile']:.3f} s | {warm['compile']:.3f} s | "
                  f"{med['ir_kb']:.0f} kB | {med['instructions']:.0f} | {med['first']:.2f} s | {warm['first']:.2f} s |",
                  flush=True)
    if args.no_cli:
        print(f"\n{load_line()} at end")
        return
    print(f"\n{load_line()}\n\n| `gearcli solve`, 100 samples | cold cache | cached | cached / cold |\n|---|---|---|---|")
    for name, path in subjects():
        if name in ("paper_2dof", "bendix_wrist", "Panda", "Talos full"):
            cold, warm = startup_pair(path, args.startup_repeat)
            print(f"| {name} | {cold:.2f} s | {warm:.2f} s | {warm / cold:.2f} |", flush=True)
    print(f"\n{load_line()} at end")


def startup_pair(path: Path, repeat: int) -> tuple[float, float]:
    """Median wall times of the command with an empty cache and with the kernel cached."""
    from gearcli import analyse, load_mechanism  # noqa: PLC0415
    names = analyse(load_mechanism(path)).independent_names
    t = np.linspace(0.0, 1.0, 101)
    q = 0.5 * np.sin(np.outer(t, np.arange(1, len(names) + 1)))
    times = {"cold": [], "cached": []}
    with tempfile.TemporaryDirectory() as d:
        traj = Path(d) / "traj.csv"
        np.savetxt(traj, np.column_stack([t, q]), delimiter=",", header=",".join(["t"] + [f"q:{n}" for n in names]),
                   comments="")
        child(path, "llvm", Path(d) / "warm")           # the kernel on disk (the command's auto decides)
        for i in range(repeat):
            for kind, cache in (("cold", Path(d) / f"cold{i}"), ("cached", Path(d) / "warm")):
                os.environ["GEARCLI_CACHE_DIR"] = str(cache)
                times[kind].append(startup_time(path, traj))
        del os.environ["GEARCLI_CACHE_DIR"]
    return float(np.median(times["cold"])), float(np.median(times["cached"]))


if __name__ == "__main__":
    main()
