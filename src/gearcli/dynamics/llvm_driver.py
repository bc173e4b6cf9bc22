"""Compiling the generated kernel (:mod:`.llvm_kernel`) and running it, on one or more threads.

LLVM through llvmlite: the IR is optimised at O3 for the host CPU (new pass manager) and
compiled by MCJIT in memory, once per :class:`~.solve.Solver` (:class:`LlvmKernel` keeps
the engine alive: freeing it frees the code); the machine code is also kept on disk
(:mod:`.llvm_cache`), so a later process generating the same IR loads it instead.  Called through ctypes, which releases the
GIL: the threads of :mod:`.jobs` run the samples in parallel, each sample's arithmetic
independent of the split (bitwise identical results for any number of jobs).
"""
from __future__ import annotations

import ctypes
import time
import weakref
from functools import lru_cache

import numpy as np

from . import llvm_cache
from .jobs import job_ranges, run_parts, sign_error, threads_for
from .kernel_program import Program, load_arrays
from .llvm_blocks import problem
from .llvm_kernel import ARGS, build_module
from .llvm_outputs import OUTPUTS


@lru_cache(maxsize=1)
def _llvm():
    import llvmlite.binding as llvm  # noqa: PLC0415  (initialises LLVM: only when used)

    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    return llvm


@lru_cache(maxsize=1)
def _host() -> tuple[str, str]:
    """(host CPU name, its features for LLVM) ("" features: LLVM cannot list them here)."""
    llvm = _llvm()
    try:
        features = llvm.get_host_cpu_features().flatten()
    except RuntimeError:          # LLVM cannot list them on this host: the CPU name's defaults
        features = ""
    return llvm.get_host_cpu_name(), features


def _target_machine():
    """(llvmlite.binding, a new target machine for the host CPU): one per kernel (its
    execution engine owns the target machine and frees it with itself)."""
    llvm = _llvm()
    cpu, features = _host()
    return llvm, llvm.Target.from_default_triple().create_target_machine(opt=3, cpu=cpu, features=features)


def host_identity() -> str:
    """What the machine code depends on besides the IR: target triple, CPU name and
    features, llvmlite and LLVM versions (part of the disk cache's keys)."""
    import llvmlite  # noqa: PLC0415

    llvm = _llvm()
    cpu, features = _host()
    return f"{llvm.get_default_triple()}|{cpu}|{features}|{llvmlite.__version__}|{llvm.llvm_version_info}"


def mech_loads(an) -> list:
    """(link id, values in link axes, load point) of each external load of ``an``."""
    return [(an.tree.index[ld.link], ld.frame == "link", np.asarray(ld.point, float)) for ld in an.mech.loads]


class Jit:
    """An IR module compiled for the host CPU (O3); ``address(name)`` of its functions.

    The machine code comes from the disk cache (:mod:`.llvm_cache`) when an earlier process
    compiled the same IR on this host (``from_cache``: then no LLVM pass runs, MCJIT only
    links the stored object code), else MCJIT makes it in memory and it is stored.  ``cache``
    False: compile in memory, neither read nor write the cache.  Keeps the execution engine
    alive (freeing it frees the code)."""

    def __init__(self, module, cache: bool = True):
        llvm, tm = _target_machine()
        module.triple, module.data_layout = tm.triple, str(tm.target_data)
        self.ir = str(module)
        self.key = llvm_cache.object_key(self.ir, host_identity())
        cached = llvm_cache.load(self.key) if cache else None
        self.from_cache = cached is not None
        self._tm = tm
        self._module = None if cached else self._optimised(llvm, tm)
        mod = self._module
        if cached:                     # an empty module: MCJIT takes its code from the cache
            mod = llvm.parse_assembly("")
            mod.triple, mod.data_layout = tm.triple, str(tm.target_data)
        made = []
        self._engine = llvm.create_mcjit_compiler(mod, tm)
        self._engine.set_object_cache(lambda _m, buf: made.append(bytes(buf)), lambda _m: cached)
        self._engine.finalize_object()
        self.stored = bool(cache and made) and llvm_cache.store(self.key, made[0])

    def _optimised(self, llvm, tm):
        """``self.ir`` parsed, verified and optimised (O3 pass pipeline)."""
        mod = llvm.parse_assembly(self.ir)
        mod.verify()
        pto = llvm.create_pipeline_tuning_options(3)
        pto.loop_vectorization = False     # nothing to gain (measured), ~15% of the pass time
        pb = llvm.create_pass_builder(tm, pto)
        pb.getModulePassManager().run(mod, pb)
        return mod

    def address(self, name: str) -> int:
        return self._engine.get_function_address(name)

    def assembly(self) -> str:
        """The optimised module's machine code (to check what LLVM made of it; optimised
        again here when the code came from the cache)."""
        if self._module is None:
            self._module = self._optimised(_llvm(), self._tm)
        return self._tm.emit_assembly(self._module)


class LlvmKernel:
    """The compiled kernel of one mechanism.

    ``build_seconds`` (IR generation) and ``compile_seconds`` (LLVM optimisation and code
    generation) say what it cost; ``jit.ir`` is its IR, ``jit.assembly()`` its machine code."""

    def __init__(self, prog: Program, an):
        t0 = time.perf_counter()
        module = build_module(prog, mech_loads(an))
        t1 = time.perf_counter()
        self.jit = Jit(module)
        if self.jit.stored or self.jit.from_cache:
            llvm_cache.note_program(program_key(prog, an), self.jit.key)
        proto = ctypes.CFUNCTYPE(ctypes.c_int64, *([ctypes.c_void_p] * (len(ARGS) - 2) + [ctypes.c_int64] * 2))
        self._run = proto(self.jit.address("run"))
        self.build_seconds, self.compile_seconds = t1 - t0, time.perf_counter() - t1
        self.prog = prog

    def solve(self, an, q, qd, qdd, values: dict, jobs: int | None, chunk: int, out: dict, work: tuple) -> dict:
        """The loads of every sample into ``out``, as :func:`.kernel_driver.kernel_solve` does."""
        prog = self.prog
        n = q.shape[0]
        SG, fail = work
        ldrec, _, vals = load_arrays(an, values, n)
        ldrow = np.ascontiguousarray(ldrec[:, 2:4] if len(ldrec) else np.zeros((1, 2), np.int64))
        keep = [np.ascontiguousarray(a, float) for a in (q, qd, qdd)] + [np.ascontiguousarray(vals, float), ldrow]
        keep += [out[k] if out[k].size else np.empty((1, 1)) for k in OUTPUTS] + [SG, fail]
        ptrs = [a.ctypes.data for a in keep]
        failed = run_parts(lambda s, e, _: self._run(*ptrs, s, e), job_ranges(n, jobs), threads_for(n, jobs))
        if failed:
            raise sign_error(prog.names, fail, chunk)
        return {k: SG[:, i] for i, k in enumerate(prog.signed)}


_PROGRAM_KEYS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def program_key(prog: Program, an) -> str:
    """:func:`.llvm_cache.program_key` of ``prog`` and ``an``'s loads on this host (once per program)."""
    if prog not in _PROGRAM_KEYS:
        from .. import __version__  # noqa: PLC0415

        _PROGRAM_KEYS[prog] = llvm_cache.program_key(prog, mech_loads(an), host_identity(), __version__)
    return _PROGRAM_KEYS[prog]


def kernel_on_disk(prog: Program, an) -> bool:
    """True when the disk cache holds the machine code of ``prog``'s kernel for this host
    (its compile would be a load; without building the IR, so a guess should the generator
    have changed since: then it compiles)."""
    return llvm_cache.has_program(program_key(prog, an))


def llvm_problem(prog: Program) -> str | None:
    """Why the llvm backend cannot solve ``prog``'s mechanism (None: it can)."""
    try:
        import llvmlite.binding  # noqa: F401, PLC0415
    except ImportError:
        return "llvmlite does not import"
    return problem(prog)
