"""Which implementation a solve takes: "llvm", "kernel" (numba) or "numpy" (the reference).

"auto" follows a cost model: the generated llvm kernel is compiled once per analysis
(:class:`~.llvm_driver.LlvmKernel`; ~0.15-0.3 s for 5-10 links, ~4 s for Talos' 44, or
0.02-0.4 s when its machine code is in the disk cache, :func:`llvm_on_disk`) and
then saves about :data:`SAVED_SECONDS_PER_SAMPLE` a sample against the numba kernel,
whose first use in a process costs :data:`NUMBA_START_SECONDS` (import and its disk
cache).  So "auto" takes llvm once it is compiled, or when its estimated compile time
(:func:`llvm_compile_estimate`) is at most what the numba kernel would cost extra for
this call and the samples this analysis solved before (rent-or-buy: a run of many small
calls, like the CLI's chunks, switches to llvm once the kernel's extra time would have
paid for the compile); else the numba kernel where it is available (numba imports); else llvm where it
is available whatever its compile time; else numpy.
"""
from __future__ import annotations

import sys
from functools import lru_cache

BACKENDS = ("auto", "llvm", "kernel", "numpy")
NUMBA_START_SECONDS = 0.4          # import numba and load the cached kernel (measured: 0.42 s)
SAVED_SECONDS_PER_SAMPLE = 1e-6    # numba kernel minus llvm kernel, a sample (measured: 0.8-1.3 us)


def llvm_compile_estimate(an, on_disk: bool = False) -> float:
    """Rough seconds to generate and compile the llvm kernel of ``an`` (measured: 0.14 s
    for 5 moving links, 0.25 s for 8, 4.4 s for 44; superlinear in the code size), or with
    ``on_disk`` (its machine code in the disk cache, :mod:`.llvm_cache`, found by its kernel
    program: loaded without generating the IR; measured 0.002-0.006 s from 5 to 44 links,
    ``benchmarks/bench_compile.py``): a flat 0.01 s."""
    n = len(an.tree.moving)
    return 0.01 if on_disk else 0.015 * n ** 1.5


def llvm_on_disk(sol) -> bool:
    """True when the llvm kernel of the :class:`~.solve.Solver` ``sol`` is in the disk cache
    for this host (keyed by its kernel program, so the IR need not be built to know)."""
    from .llvm_driver import kernel_on_disk  # noqa: PLC0415  (llvmlite: imported by llvm_available)

    return kernel_on_disk(sol.kernel_program(), sol.an)


@lru_cache(maxsize=1)
def numba_kernel_problem() -> str | None:
    """Why the numba kernel cannot run in this process, or None (imports it; once)."""
    try:
        from . import kernel_driver  # noqa: F401, PLC0415  (imports numba)
    except ImportError:
        return "numba does not import"
    except RuntimeError as exc:        # numba found no writable cache directory
        return f"numba: {exc}"
    return None


def _auto_llvm(sol, n: int | None) -> bool:
    """True when "auto" takes llvm for a call of n samples (None: a large call)."""
    if not sol.llvm_available():
        return False
    if sol.compiled_llvm() or n is None:
        return True
    numba_extra = 0.0 if "gearcli.dynamics.kernel" in sys.modules else NUMBA_START_SECONDS
    seen = n + sol.samples_solved          # a long run in many calls (the CLI's chunks) pays too
    return llvm_compile_estimate(sol.an, llvm_on_disk(sol)) <= numba_extra + seen * SAVED_SECONDS_PER_SAMPLE


def choose(sol, method: str, backend: str, n: int | None) -> str:
    """The path a solve of n samples by the :class:`~.solve.Solver` ``sol`` takes."""
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend '{backend}' (expected one of {', '.join(BACKENDS)})")
    if backend == "numpy" or (backend == "auto" and method == "full"):
        return "numpy"
    if method == "full":
        raise ValueError(f"backend '{backend}' solves method 'block' only")
    if backend == "llvm":
        if not sol.llvm_available():
            raise ValueError(f"backend 'llvm' unavailable: {sol.llvm_problem}")
        return "llvm"
    if backend == "auto" and _auto_llvm(sol, n):
        return "llvm"
    numba = None
    prog = sol.kernel_program()
    if prog is not None and not prog.numba_ok:
        numba = ("the numba kernel cannot solve a block of this mechanism (more sign patterns than "
                 "kernel_program.MAX_PATTERNS, or a redundant gear set without a constant frame)")
    elif prog is not None:
        numba = numba_kernel_problem()
        if numba is None:
            return "kernel"
    if backend == "kernel":
        raise ValueError(f"backend 'kernel' unavailable: {sol.kernel_problem or numba}")
    return "llvm" if sol.llvm_available() else "numpy"     # llvm even where it costs more than numba would
