"""Which implementation a solve takes: "llvm" (the generated kernel) or "numpy" (the reference).

Two paths solve the same equations: the numpy reference (:mod:`.blocks`, :mod:`.general`:
covers everything, method "full" and ``verify`` included) and the kernel generated for each
mechanism as LLVM IR (:mod:`.llvm.kernel`: method "block"; its machine code is kept on disk,
:mod:`.llvm.cache`).  ``backend`` is one of :data:`BACKENDS`:

* "llvm": the generated kernel, or a ValueError saying why it cannot run here;
* "numpy": the reference;
* "auto": numpy for method "full" (only the reference assembles the full system), else
  llvm, except (each a :class:`Choice` with its one-line ``note``)

  - llvmlite does not import, or the kernel refuses the mechanism
    (:attr:`.solve.Solver.kernel_problem`, e.g. a block with more than 32 signed meshes):
    numpy for every call;
  - the first-call rule: while the kernel is neither compiled in this process nor its
    machine code in the disk cache, a call of fewer than :data:`FIRST_CALL_SAMPLES` samples
    (counting the samples this solver already solved by the block method, each call as at
    least :data:`CALL_SAMPLES`) is solved by numpy and compiles nothing: numpy solves such
    a call in less time than a cold compile takes (0.15-0.3 s for 5-10 moving links, ~4 s
    for Talos' 44; numpy solves ~200,000 samples/s of Bendix plus ~1.5 ms a call).  A run of
    small calls (a simulation's steps) compiles once they add up: 4-sample calls at the 20th.
"""
from __future__ import annotations

from dataclasses import dataclass

BACKENDS = ("auto", "llvm", "numpy")
FIRST_CALL_SAMPLES = 5_000
"""Samples (this call plus those solved before by the same solver) from which "auto" compiles
a kernel that is neither compiled nor in the disk cache; below, numpy solves the call."""
CALL_SAMPLES = 250
"""The least a call counts for, in samples: numpy's fixed cost of a call (~1-1.5 ms for the
Bendix, measured) is about that many samples' work (~5 us each)."""

@dataclass(frozen=True)
class Choice:
    """The path a solve takes (``path``: "llvm" or "numpy") and, when "auto" took numpy,
    why (``note``, one line; None otherwise); ``fallback``: the kernel cannot run here at
    all (not the first-call rule)."""

    path: str
    note: str | None = None
    fallback: bool = False


def llvm_refusal() -> str | None:
    """Why the generated kernel cannot run in this process (a covered kernel program), or None."""
    try:
        import llvmlite.binding  # noqa: F401, PLC0415
    except ImportError:
        return "llvmlite does not import"
    return None


def llvm_on_disk(sol) -> bool:
    """True when the llvm kernel of the :class:`~.solve.Solver` ``sol`` is in the disk cache
    for this host (keyed by its kernel program, so the IR need not be built to know)."""
    from .llvm.driver import kernel_on_disk  # noqa: PLC0415  (llvmlite: imported by llvm_available)

    return kernel_on_disk(sol.kernel_program(), sol.an)


def _first_call(sol, n: int | None) -> str | None:
    """The first-call rule's note when a call of n samples (None: a large call) should be
    solved by numpy rather than pay a cold compile, else None."""
    if n is None or sol.compiled_llvm():
        return None
    seen = max(n, CALL_SAMPLES) + sol.samples_solved
    if seen >= FIRST_CALL_SAMPLES or llvm_on_disk(sol):
        return None
    return (f"first-call rule: fewer than {FIRST_CALL_SAMPLES:,} samples, and the kernel is neither "
            f"compiled nor in the disk cache")


def choose(sol, method: str, backend: str, n: int | None) -> Choice:
    """The path a solve of n samples (None: a large call) by the :class:`~.solve.Solver`
    ``sol`` takes."""
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend '{backend}' (expected one of {', '.join(BACKENDS)})")
    if backend == "numpy":
        return Choice("numpy")
    if method == "full":
        if backend == "llvm":
            raise ValueError("backend 'llvm' solves method 'block' only")
        return Choice("numpy")           # asked for: only the reference assembles the full system
    if not sol.llvm_available():
        if backend == "llvm":
            raise ValueError(f"backend 'llvm' unavailable: {sol.llvm_problem}")
        return Choice("numpy", sol.llvm_problem, fallback=True)
    if backend == "llvm":
        return Choice("llvm")
    note = _first_call(sol, n)
    return Choice("numpy", note) if note else Choice("llvm")
