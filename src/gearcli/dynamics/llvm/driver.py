"""Compiling the generated kernel (:mod:`.kernel`) and running it, on one or more threads.

LLVM through llvmlite: the IR is optimised for the host CPU (new pass manager: O3, or no
middle-end pass for an IR above :data:`BIG_IR`, :func:`pass_level`; code generation at O3)
and compiled by MCJIT in memory, once per :class:`~..solve.Solver` (:class:`LlvmKernel` keeps
the engine alive: freeing it frees the code); the machine code is also kept on disk
(:mod:`.cache`), so a later process generating the same IR loads it instead; one solving the
same kernel program with the same generator source (:func:`generator_digest`) loads it without
generating the IR.  Called through ctypes, which releases the GIL: the threads of :mod:`.jobs` run the samples in parallel, each sample's arithmetic
independent of the split (bitwise identical results for any number of jobs).
"""
from __future__ import annotations

import ctypes
import mmap
import sys
import threading
import hashlib
import time
import weakref
from functools import lru_cache
from pathlib import Path

import numpy as np

from . import cache as llvm_cache
from .signs import WARM
from .jobs import job_ranges, run_parts, sign_error, threads_for
from .program import Program, body_rows, load_arrays
from .kernel import ARGS, LOSS_OUTPUTS, build_module
from .links import load_groups
from .outputs import OUTPUTS
from ..bearing_friction import BearingFrictionError


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


GENERATOR = ("kernel", "blocks", "build", "links", "outputs", "signs", "dense_solve", "trig", "world", "driver",
             "losses", "friction_terms", "inverse_cache", "hot_pairs", "mass", "bearings", "bearing_newton", "types",
             "../result_arrays", "../signs", "../bearing_friction", "../kinematics", "../inertia", "../loss_terms",
             "../wrenches", "../../algebra", "../../model/shaft")
"""The modules (paths from :mod:`gearcli.dynamics.llvm`, without .py) whose code makes a kernel program's IR text: the
generator's own and the shared physics terms it emits (:mod:`gearcli.algebra`; a test checks that every module they
import from the package is listed or makes only hashed input)."""


@lru_cache(maxsize=1)
def generator_digest() -> str | None:
    """SHA-256 of the source of the :data:`GENERATOR` modules (None: one cannot be read).
    Part of the program key: a program key found in the disk cache then names the object
    code of the very IR this code would generate for that program."""
    h = hashlib.sha256()
    here = Path(__file__).parent
    try:
        for name in GENERATOR:
            h.update(hashlib.sha256((here / f"{name}.py").read_bytes()).digest())
    except OSError:
        return None
    return h.hexdigest()


BIG_IR = 1 << 20
"""Characters of IR text above which the middle-end passes are skipped (O0 pipeline; the
code generator still runs at O3).  The generator folds constants and emits straight-line
SSA, so the O3 passes add little to such code but most of its compile time: measured
2026-12-07 (jobs=1, 20,000 samples, medians of 7, load ~1): planetary_5p with every loss
(4.6 MB of IR) 10.7 -> 3.7 s cold compile, 11.9 -> 12.8 ms a solve; planetary_3p_rated
(4.7 MB) 3.7 -> 1.7 s, 12.6 -> 13.2 ms; servo_joint_rated (1.1 MB) 2.3 -> 1.4 s, 36.3 ->
31.0 ms; planetary_5p (1.3 MB) 2.7 -> 0.8 s, 8.9 -> 9.1 ms.  Below it (the Bendix wrist,
the paper's arm) O3 stays: compile is cheap there."""


def pass_level(ir: str) -> int:
    """The optimisation level of the middle-end pass pipeline for IR text ``ir``: 3, or 0
    above :data:`BIG_IR` (a function of the IR alone, so the disk cache's object key, the IR
    and the host, still names one machine code)."""
    return 0 if len(ir) > BIG_IR else 3


def address(a: np.ndarray) -> int:
    """The address of an array's data: through ctypes' buffer view (0.9 us), not ``a.ctypes``
    (3.3 us: a kernel call passes ~23 arrays, and a simulate step makes a dozen calls of one
    sample); a read-only or empty array takes ``a.ctypes.data``."""
    try:
        return ctypes.addressof(ctypes.c_char.from_buffer(a))
    except (TypeError, ValueError, BufferError):
        return a.ctypes.data


def writable_copy(dest: int, values: np.ndarray) -> None:
    """Copy ``values`` to address ``dest`` in read-only memory (a loaded kernel's constant
    pool): its pages made writable for the copy, then read-only again."""
    page = mmap.PAGESIZE
    lo, hi = dest // page * page, -(-(dest + values.nbytes) // page) * page
    if sys.platform == "win32":
        old = ctypes.c_ulong()
        protect = ctypes.windll.kernel32.VirtualProtect
        ok = protect(ctypes.c_void_p(lo), ctypes.c_size_t(hi - lo), 0x04, ctypes.byref(old))   # PAGE_READWRITE
        ctypes.memmove(dest, address(values), values.nbytes)
        ok = ok and protect(ctypes.c_void_p(lo), ctypes.c_size_t(hi - lo), old.value, ctypes.byref(old))
    else:
        protect = _libc().mprotect
        ok = protect(ctypes.c_void_p(lo), ctypes.c_size_t(hi - lo), mmap.PROT_READ | mmap.PROT_WRITE) == 0
        ctypes.memmove(dest, address(values), values.nbytes)
        ok = ok and protect(ctypes.c_void_p(lo), ctypes.c_size_t(hi - lo), mmap.PROT_READ) == 0
    if not ok:
        raise OSError(ctypes.get_errno(), "cannot write a kernel's constant pool")


@lru_cache(maxsize=1)
def _libc():
    lib = ctypes.CDLL(None, use_errno=True)
    lib.mprotect.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int]
    return lib


RECENT_OBJECTS = 8
"""Object codes this process made that it keeps in memory (:data:`_RECENT`)."""

_RECENT_LOCK = threading.Lock()
_RECENT: dict = {}
"""{object key: object code} of the last :data:`RECENT_OBJECTS` kernels this process compiled:
another program whose IR is the same (a sweep's variant of a ratio, an efficiency: only
the constant pools' values differ, :class:`.build.ConstantPool`) links it without a
compile, whether or not the disk cache is writable."""


class Jit:
    """An IR module compiled for the host CPU (:func:`pass_level`); ``address(name)`` of its functions.

    ``module``: the module, or a function making it, called only when needed
    (``build_seconds``: what that took, 0 before).  The machine code comes from the disk
    cache (:mod:`.cache`) when an earlier process compiled the same IR on this host
    (``from_cache``: then no LLVM pass runs, MCJIT only links the stored object code;
    ``by_program``: found by ``program_key`` without generating the IR, the entry found
    then that of kernel program ``fingerprint``, :func:`.cache.program_fingerprint`, kept in
    the entries it stores) or when this process compiled it (:data:`_RECENT`), else MCJIT
    makes it in memory and it is stored.  ``cache`` False: compile in memory, neither read
    nor write the caches.  ``ir`` is the IR text (generated on first use when the code came
    by program key); ``pools`` the values of its constant pools ({symbol: values}, from the
    generator or the program's note), written into the loaded code (:meth:`_fill_pools`).
    Keeps the execution engine alive (freeing it frees the code)."""

    def __init__(self, module, cache: bool = True, program_key: str | None = None, fingerprint: str = ""):
        llvm, tm = _target_machine()
        self._tm, self._ir, self.build_seconds, self.pools = tm, None, 0.0, {}
        self._make = module if callable(module) else (lambda: module)
        hit = llvm_cache.load_program(program_key, fingerprint) if program_key and cache else None
        self.by_program = hit is not None
        if hit is not None:
            self.key, cached, self.pools = hit
        else:
            self.key = llvm_cache.object_key(self.ir, host_identity())
            cached = llvm_cache.load(self.key, adopt=fingerprint) if cache else None
            cached = _RECENT.get(self.key) if cached is None and cache else cached
        self.from_cache = cached is not None
        self._module = None if cached else self._optimised(llvm, tm)
        mod = self._module
        if cached:                     # an empty module: MCJIT takes its code from the cache
            mod = llvm.parse_assembly("")
            mod.triple, mod.data_layout = tm.triple, str(tm.target_data)
        made = []
        self._engine = llvm.create_mcjit_compiler(mod, tm)
        self._engine.set_object_cache(lambda _m, buf: made.append(bytes(buf)), lambda _m: cached)
        self._engine.finalize_object()
        self._fill_pools()
        if made and cache:
            with _RECENT_LOCK:           # kernels made on several threads (a Dask worker's)
                _RECENT[self.key] = made[0]
                while len(_RECENT) > RECENT_OBJECTS:
                    _RECENT.pop(next(iter(_RECENT)))
        self.stored = bool(cache and made) and llvm_cache.store(self.key, made[0], fingerprint)

    def _fill_pools(self) -> None:
        """Write the constant pools' values (:class:`.build.ConstantPool`: data, not part of
        the IR or the object code) into the loaded code's read-only pool arrays."""
        for name, values in self.pools.items():
            v = np.ascontiguousarray(values, float)
            writable_copy(self._engine.get_global_value_address(name), v)

    @property
    def ir(self) -> str:
        """The module's IR text for the host (the module made here on first use)."""
        if self._ir is None:
            t0 = time.perf_counter()
            module = self._make()
            self.build_seconds += time.perf_counter() - t0
            module.triple, module.data_layout = self._tm.triple, str(self._tm.target_data)
            self._ir, self.pools = str(module), dict(getattr(module, "pool_values", {}))
        return self._ir

    def _optimised(self, llvm, tm):
        """``self.ir`` parsed, verified and optimised (the pass pipeline of :func:`pass_level`)."""
        mod = llvm.parse_assembly(self.ir)
        mod.verify()
        pto = llvm.create_pipeline_tuning_options(pass_level(self.ir))
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

    ``build_seconds`` (IR generation: 0 when the code came from the disk cache by program
    key) and ``compile_seconds`` (LLVM optimisation and code generation, or the cache load)
    say what it cost; ``jit.ir`` is its IR, ``jit.assembly()`` its machine code.  A subclass
    compiles another function of the same program (:class:`.mass.MassKernel`): its
    ``ENTRY`` name, ``INTS`` (the arguments that are i64, after ``POINTERS`` pointers),
    :meth:`build` and :meth:`ids`."""

    ENTRY, POINTERS, INTS = "run", len(ARGS) - 2, 2

    def __init__(self, prog: Program, an):
        t0 = time.perf_counter()
        loads = mech_loads(an)
        fingerprint, pkey = self.ids(prog, an)
        self.jit = Jit(lambda: self.build(prog, loads), program_key=pkey if generator_digest() else None,
                       fingerprint=fingerprint)
        if self.jit.stored or (self.jit.from_cache and not self.jit.by_program):
            llvm_cache.note_program(pkey, self.jit.key, self.jit.pools)
        proto = ctypes.CFUNCTYPE(ctypes.c_int64, *([ctypes.c_void_p] * self.POINTERS + [ctypes.c_int64] * self.INTS))
        self._run = proto(self.jit.address(self.ENTRY))
        self.build_seconds = self.jit.build_seconds
        self.compile_seconds = time.perf_counter() - t0 - self.build_seconds
        self.prog = prog
        self.bodies = body_rows(an) if prog.data_bodies else None   # a data kernel's bodies (set_bodies)
        self._local = threading.local()      # set_bodies per thread: a Dask worker's threads share the kernel
        self._load_order, groups = load_groups(loads)
        self._load_groups = np.array([[k0, k1] for _, k0, k1 in groups] or [[0, 0]], np.int64)

    @staticmethod
    def build(prog: Program, loads):
        """The IR module of the kernel (:func:`.kernel.build_module`)."""
        return build_module(prog, loads)

    @staticmethod
    def ids(prog: Program, an) -> tuple[str, str]:
        """(fingerprint, program key) of the kernel (:func:`_program_ids`)."""
        return _program_ids(prog, an)

    def set_bodies(self, an) -> None:
        """A data kernel (:attr:`.program.Program.data_bodies`) solves with the masses, centres
        of mass and inertias of ``an``'s links from now on, in this thread (``an``: the same
        mechanism but for those values)."""
        rows = body_rows(an)
        if not self.prog.data_bodies or rows.shape != self.bodies.shape:
            raise ValueError("set_bodies: a data kernel, and a mechanism with its links, are needed")
        self._local.bodies = rows            # this thread's solves (another thread keeps its own)

    def load_args(self, an, values: dict, n: int) -> list:
        """The external loads' arguments of the code (vals, ldpt, ldrow, ldgrp), contiguous."""
        return load_arrays(an, values, n, self._load_order) + [self._load_groups]

    def solve(self, an, q, qd, qdd, values: dict, jobs: int | None, chunk: int, out: dict, work: tuple,
              losses: dict | None = None) -> dict:
        """The loads of every sample into ``out``, as the numpy path (:func:`..blocks.solve_blocks`) does.

        A lossy mechanism (``prog.losses``): the kernel computes the joints' own friction and
        writes the loss outputs (``out``'s gear_loss, joint_friction, joint_loss); the bearing
        friction converges in the kernel, block by block (:mod:`.bearings`), and joins the
        joint friction and loss outputs there; ``losses`` (a dict) then receives "bearing"
        (N, K) the converged moments of the joints :func:`..bearing_friction.friction_joints`
        and "iterations" (N,): per sample the most iterations over its blocks."""
        prog = self.prog
        lp = prog.losses
        if lp is None or not lp.bearing_joints:
            self._launch(an, q, qd, qdd, values, jobs, chunk, out, work, np.empty((1, 1)))
            return {k: work[0][:, i] for i, k in enumerate(prog.signed)}
        moments = np.empty((q.shape[0], lp.out_width))           # the kernel's converged moments and iterations
        self._launch(an, q, qd, qdd, values, jobs, chunk, out, work, moments)
        if losses is not None:
            K = len(lp.bearing_joints)
            losses.update(bearing=moments[:, :K], iterations=moments[:, K].astype(np.int64))
        return {k: work[0][:, i] for i, k in enumerate(prog.signed)}

    def _launch(self, an, q, qd, qdd, values, jobs, chunk, out, work, moments) -> None:
        """One run of the kernel over every sample of q (raises the numpy path's SignError or
        BearingFrictionError); ``out`` holds the loss outputs of a lossy mechanism too."""
        n = q.shape[0]
        SG, fail = work
        none = np.empty((1, 1))
        keep = [np.ascontiguousarray(a, float) for a in (q, qd, qdd)] + self.load_args(an, values, n)
        keep += [getattr(self._local, "bodies", self.bodies) if self.prog.data_bodies else none]
        keep += [out[k] if out[k].size else none for k in OUTPUTS] + [SG]
        keep += [out[k] if out.get(k) is not None and out[k].size else none for k in LOSS_OUTPUTS] + [moments, fail]
        ptrs = [address(a) for a in keep]
        # the threads' ranges cut at multiples of WARM: a bearing fixed point's warm start (.bearings) and a sign
        # search's first trial (.kernel: the pattern of the sample before) stay in their run
        cuts = sorted({min(n, WARM * round(a / WARM)) for a, _ in job_ranges(n, jobs)} | {n})
        ranges = [(a, b) for a, b in zip(cuts, cuts[1:]) if b > a]
        failed = run_parts(lambda s, e: self._run(*ptrs, s, e), ranges, threads_for(n, jobs))
        if failed:                    # a block's sign search, else a bearing fixed point (.bearings)
            nb = len(self.prog.blocks)
            if np.any((fail >= 0) & (fail < nb)):
                raise sign_error(self.prog.names, np.where(fail < nb, fail, -1), chunk)
            s = int(np.flatnonzero(fail >= nb)[0])
            joint = an.mech.joints[self.prog.losses.bearing_joints[int(fail[s]) - nb]].name
            raise BearingFrictionError(s, joint)


_PROGRAM_KEYS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _program_ids(prog: Program, an) -> tuple[str, str]:
    """(:func:`.cache.program_fingerprint`, :func:`.cache.program_key`) of ``prog`` and
    ``an``'s loads on this host, gearcli's version and :func:`generator_digest` (once per program)."""
    if prog not in _PROGRAM_KEYS:
        from ... import __version__  # noqa: PLC0415

        version = f"{__version__}|{generator_digest()}"
        fingerprint = llvm_cache.program_fingerprint(prog, mech_loads(an))
        _PROGRAM_KEYS[prog] = fingerprint, llvm_cache.program_key(fingerprint, host_identity(), version)
    return _PROGRAM_KEYS[prog]


def kernel_on_disk(prog: Program, an) -> bool:
    """True when the disk cache holds the machine code of ``prog``'s kernel for this host
    (its compile would be a load; without building the IR, so a guess should the generator
    have changed since: then it compiles)."""
    return llvm_cache.has_program(_program_ids(prog, an)[1])
