"""The batched regressor's arithmetic compiled per robot, several samples at once in SIMD lanes.

:func:`~dynid.dynamics._regressor_kernel.sample_columns` is run once on symbols instead of numbers. The
robot's constants (joint axes, fixed rotations and translations, gravity) are folded in, and the products by
0 or 1 and the sums with 0 are dropped. What remains is one straight-line sequence of additions, subtractions,
multiplications and negations per sample, about 3000 for a 6-joint arm, and each joint's cosine and sine.
It is written out as LLVM IR on vectors of :data:`LANES` doubles, one sample per lane, and compiled for this
CPU by llvmlite (numba's code generator, already installed with it). The cosines and sines are the C
library's, called lane by lane, as in numba's kernel.

The operations are those of ``sample_columns``, in the same order, each lane on its own sample, with no
reassociation and no fused multiply-add. So the numbers are those of numba's kernel, bit for bit, and of the
NumPy form wherever NumPy's cosine is the C library's (tests compare the three).

The columns to write (``colmap``) and the number of columns are arguments of the compiled function, so one
function per robot serves every column selection: a column that is not selected is computed and stored
into a scratch slot. Each block of samples is zeroed first; the entries no column writes stay zero.

Machine code is cached on disk (``$XDG_CACHE_HOME/dynid`` or ``~/.cache/dynid``) under a hash of the IR, the
CPU and llvmlite's version, and the IR (zlib-compressed) under a hash of the robot's constants and of the two modules'
source, so that a process neither traces nor compiles a robot it has met before (an identification builds several:
its model, the description's rigid body, the gravity directions the geometry checks try). Compiling takes 0.4-0.5 s
for a 6-joint arm; loading from the cache, about 0.015 s.
"""

from __future__ import annotations

import ctypes
import functools
import hashlib
import os
import struct
import threading
import zlib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from ..runtime.threads import cores
from . import _regressor_kernel

LANES = 4
"""Samples per vector (4 doubles: 256-bit registers, which every x86-64 CPU with AVX2 has)."""


# ---- tracing: sample_columns run on symbols ------------------------------------------------------------

class _Graph:
    """Operations in the order ``sample_columns`` performs them; equal operations on equal operands are one."""

    def __init__(self):
        self.nodes: list[tuple] = []
        self._seen: dict = {}

    def node(self, op, *args):
        key = (op,) + tuple(("s", a.id) if isinstance(a, _Sym) else a for a in args)
        if key not in self._seen:
            self._seen[key] = _Sym(self, len(self.nodes))
            self.nodes.append((op, args))
        return self._seen[key]


class _Sym:
    """A value of one sample, known only when the compiled code runs. Python floats are constants and are
    folded: ``x*0 = 0``, ``x*1 = x``, ``x*(-1) = -x``, ``x ± 0 = x``, ``0 - x = -x`` (exact, up to the sign
    of a zero)."""

    def __init__(self, graph, id_):
        self.graph, self.id = graph, id_

    def __add__(self, other):
        other = _operand(other)
        return self if isinstance(other, float) and other == 0.0 else self.graph.node("fadd", self, other)

    def __radd__(self, other):
        other = _operand(other)
        return self if other == 0.0 else self.graph.node("fadd", other, self)

    def __sub__(self, other):
        other = _operand(other)
        return self if isinstance(other, float) and other == 0.0 else self.graph.node("fsub", self, other)

    def __rsub__(self, other):
        other = _operand(other)
        return -self if other == 0.0 else self.graph.node("fsub", other, self)

    def __mul__(self, other):
        return self._times(_operand(other), self_first=True)

    def __rmul__(self, other):
        return self._times(_operand(other), self_first=False)

    def _times(self, other, self_first):
        if isinstance(other, float):
            if other == 0.0:
                return 0.0
            if other == 1.0:
                return self
            if other == -1.0:
                return -self
        return self.graph.node("fmul", *((self, other) if self_first else (other, self)))

    def __neg__(self):
        op, args = self.graph.nodes[self.id]
        return args[0] if op == "fneg" else self.graph.node("fneg", self)

    def cos(self):  # np.cos(symbol)
        return self.graph.node("cos", self)

    def sin(self):
        return self.graph.node("sin", self)


def _operand(x):
    return x if isinstance(x, _Sym) else float(x)


class _Input:
    def __init__(self, graph, name, shape):
        self.graph, self.name, self.shape = graph, name, shape

    def __getitem__(self, index):
        return self.graph.node("load", self.name, tuple(int(i) for i in index[1:]))


class _Output:
    def __init__(self, n, m):
        self.shape = (None, n, m)
        self.stores: dict = {}

    def __setitem__(self, index, value):
        self.stores[tuple(int(i) for i in index[1:])] = value if isinstance(value, _Sym) else float(value)


def _trace(rp, pp, axes, gravity, npj: int, n_drive: int, prismatic, parent):
    """The operations of one sample and, for each (joint, standard column) that some column of the
    regressor takes, the value stored there (a symbol, or a constant)."""
    n = rp.shape[0]
    graph = _Graph()
    q, dq, ddq = (_Input(graph, name, (None, n)) for name in ("q", "dq", "ddq"))
    drive = _Input(graph, "drive", (None, n, n_drive))
    out = _Output(n, n * npj)
    colmap = np.arange(n * npj)
    drive_map = np.arange(n)[:, None] * npj + 10 + np.arange(n_drive)
    rp_, pp_, axes_, gravity_ = (np.array(np.asarray(a, dtype=float).tolist(), dtype=object) for a in (rp, pp, axes, gravity))
    scratch = tuple(np.empty(s, dtype=object) for s in ((n, 3, 3), (n, 3), (n, 3), (n, 3), (n, 3), (n, 3), (3, 3)))
    robot = _regressor_kernel.RobotArrays(rp_, pp_, axes_, gravity_, npj, colmap, drive_map,
                                          np.asarray(prismatic, dtype=float), np.asarray(parent, dtype=np.int64))
    _regressor_kernel.sample_columns(0, robot, (q, dq, ddq), out, drive, scratch)
    return graph, {key: v for key, v in out.stores.items() if isinstance(v, _Sym) or v != 0.0}


# ---- LLVM IR -------------------------------------------------------------------------------------------

def _hex(x: float) -> str:
    return f"0x{struct.unpack('<Q', struct.pack('<d', x))[0]:016X}"


def _live(graph: _Graph, stores: dict) -> set:
    """The nodes a stored value depends on (the others are not emitted)."""
    live, stack = set(), [v.id for v in stores.values() if isinstance(v, _Sym)]
    while stack:
        i = stack.pop()
        if i not in live:
            live.add(i)
            op, args = graph.nodes[i]
            if op != "load":
                stack.extend(a.id for a in args if isinstance(a, _Sym))
    return live


def _store_lines(stores: dict, head: list, body: list, counter, vec: str) -> None:
    """The stores of each (joint, column) value, lane by lane: where the column goes is read once per call (``head``),
    the selected column's offset in a row or the scratch slot; the stores go in the loop (``body``)."""
    for (joint, column), value in sorted(stores.items()):
        d = f"%d{joint}_{column}"
        head.append(f"  %c{joint}_{column} = getelementptr i64, ptr %colmap, i64 {column}")
        head.append(f"  {d} = load i64, ptr %c{joint}_{column}, align 8")
        head.append(f"  %k{joint}_{column} = icmp sge i64 {d}, 0")
        head.append(f"  %j{joint}_{column} = mul i64 %m, {joint}")
        head.append(f"  %o{joint}_{column} = add i64 %j{joint}_{column}, {d}")
        for lane in range(LANES):
            base = "%b_out" if lane == 0 else f"%b_out{lane}"
            p, s, x = (f"%{c}{next(counter)}" for c in "psx")
            body.append(f"  {p} = getelementptr double, ptr {base}, i64 %o{joint}_{column}")
            body.append(f"  {s} = select i1 %k{joint}_{column}, ptr {p}, ptr %scratch")
            if isinstance(value, _Sym):
                body.append(f"  {x} = extractelement {vec} %t{value.id}, i32 {lane}")
                body.append(f"  store double {x}, ptr {s}, align 8")
            else:
                body.append(f"  store double {_hex(value)}, ptr {s}, align 8")


def _ir(graph: _Graph, stores: dict, n: int, npj: int, n_drive: int) -> str:
    """``kernel(q, dq, ddq, drive, out, colmap, m, start, stop)``: samples ``start:stop`` (a multiple
    of LANES apart) of ``out`` (N, n, m), C order; ``colmap`` (n·npj,) int64 (-1: not written)."""
    w = LANES
    vec = f"<{w} x double>"
    live = _live(graph, stores)

    def const(x):
        return "<" + ", ".join([f"double {_hex(x)}"] * w) + ">"

    def ref(a):
        return f"%t{a.id}" if isinstance(a, _Sym) else const(a)

    strides = {"q": n, "dq": n, "ddq": n, "drive": n * n_drive}
    head = ["define void @kernel(ptr noalias %q, ptr noalias %dq, ptr noalias %ddq, ptr noalias %drive, "
            "ptr noalias %out, ptr noalias %colmap, i64 %m, i64 %start, i64 %stop) {",
            "entry:", f"  %scratch = alloca {vec}, align 32", f"  %nm = mul i64 {n}, %m",
            f"  %block = mul i64 %nm, {8 * w}"]
    body = ["loop:", "  %k = phi i64 [ %start, %entry ], [ %next, %loop ]", "  %row = mul i64 %k, %nm",
            "  %b_out = getelementptr double, ptr %out, i64 %row",
            "  call void @llvm.memset.p0.i64(ptr %b_out, i8 0, i64 %block, i1 false)"]
    for name, stride in strides.items():
        body.append(f"  %i_{name} = mul i64 %k, {stride}")
        body.append(f"  %b_{name} = getelementptr double, ptr %{name}, i64 %i_{name}")
    for lane in range(1, w):
        body.append(f"  %lane{lane} = mul i64 %nm, {lane}")
        body.append(f"  %b_out{lane} = getelementptr double, ptr %b_out, i64 %lane{lane}")
    counter = iter(range(10**9))

    def lanes(result, scalar):
        """``result`` = the vector of ``scalar(lane)`` (which emits its lines and names the lane's double)."""
        prev = "undef"
        for lane in range(w):
            x = scalar(lane)
            nxt = result if lane == w - 1 else f"%x{next(counter)}"
            body.append(f"  {nxt} = insertelement {vec} {prev}, double {x}, i32 {lane}")
            prev = nxt

    def two_steps(first, second):
        """A lane's double from two lines: ``%a = first(lane)`` then ``%b = second(%a)``."""
        def scalar(lane):
            a, b = f"%x{next(counter)}", f"%x{next(counter)}"
            body.append(f"  {a} = {first(lane)}")
            body.append(f"  {b} = {second(a)}")
            return b
        return scalar

    for i, (op, args) in enumerate(graph.nodes):
        if i not in live:
            continue
        if op in ("cos", "sin"):  # by the C library, lane by lane (as numba's kernel: math.cos is the C library's)
            lanes(f"%t{i}", two_steps(lambda lane, v=ref(args[0]): f"extractelement {vec} {v}, i32 {lane}",
                                      lambda x, f=op: f"call double @{f}(double {x})"))
        elif op == "load":
            name, index = args
            offset = index[0] * n_drive + index[1] if name == "drive" else index[0]
            lanes(f"%t{i}", two_steps(lambda lane, b=f"%b_{name}", s=strides[name], o=offset:
                                      f"getelementptr double, ptr {b}, i64 {lane * s + o}",
                                      lambda p: f"load double, ptr {p}, align 8"))
        elif op == "fneg":
            body.append(f"  %t{i} = fneg {vec} {ref(args[0])}")
        else:
            body.append(f"  %t{i} = {op} {vec} {ref(args[0])}, {ref(args[1])}")
    _store_lines(stores, head, body, counter, vec)
    head.append("  %empty = icmp sge i64 %start, %stop")
    head.append("  br i1 %empty, label %exit, label %loop")
    body += [f"  %next = add i64 %k, {w}", "  %done = icmp sge i64 %next, %stop", "  br i1 %done, label %exit, label %loop",
             "exit:", "  ret void", "}", "declare void @llvm.memset.p0.i64(ptr, i8, i64, i1)",
             "declare double @cos(double)", "declare double @sin(double)"]
    return "\n".join(head + body) + "\n"


# ---- compilation and its cache -------------------------------------------------------------------------

_kernels: dict = {}
_lock = threading.Lock()


def _cache_folder() -> Path | None:
    try:
        return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "dynid"
    except RuntimeError:  # no home folder: no cache
        return None


_CHECK = 32
"""Bytes of SHA-256 after each cached object: a file that does not match (cut short, damaged) is ignored."""


def _read_cache(path: Path | None) -> bytes | None:
    if path is None:
        return None
    try:
        data = path.read_bytes()
    except OSError:
        return None
    body, check = data[:-_CHECK], data[-_CHECK:]
    return body if len(data) > _CHECK and hashlib.sha256(body).digest() == check else None


def _write_cache(path: Path | None, data: bytes) -> None:
    """Write atomically (a temporary file renamed), so that another process reads all of it or nothing."""
    if path is None:
        return
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_bytes(data + hashlib.sha256(data).digest())
        os.replace(tmp, path)
    except OSError:
        pass  # no writable cache: compiled again next time


def _compile(ir: str):
    """The compiled ``kernel`` of ``ir`` as a ctypes function (the engine is kept alive with it): the cached
    machine code when there is a valid one, else compiled and cached."""
    import llvmlite
    import llvmlite.binding as llvm

    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    cpu, features = llvm.get_host_cpu_name(), llvm.get_host_cpu_features().flatten()
    machine = llvm.Target.from_default_triple().create_target_machine(cpu=cpu, features=features, opt=2)
    key = hashlib.sha256("\n".join((ir, cpu, features, llvmlite.__version__)).encode()).hexdigest()[:32]
    folder = _cache_folder()
    path = None if folder is None else folder / f"regressor-{key}.o"
    cached = _read_cache(path)
    module = llvm.parse_assembly(ir)
    module.verify()
    engine = llvm.create_mcjit_compiler(module, machine)
    engine.set_object_cache(lambda _module, buffer: _write_cache(path, buffer), lambda _module: cached)
    if cached is None:
        builder = llvm.create_pass_builder(machine, llvm.PipelineTuningOptions(speed_level=2))
        builder.getModulePassManager().run(module, builder)
    engine.finalize_object()
    pointer, i64 = ctypes.c_void_p, ctypes.c_int64
    function = ctypes.CFUNCTYPE(None, *[pointer] * 6, i64, i64, i64)(engine.get_function_address("kernel"))
    return function, engine


def kernel(rp, pp, axes, gravity, npj: int, n_drive: int, prismatic, parent):
    """The compiled regressor of a robot (its joints' fixed geometry, kinds and parents, gravity), compiled or loaded
    once per process."""
    key = (np.asarray(rp, float).tobytes(), np.asarray(pp, float).tobytes(), np.asarray(axes, float).tobytes(),
           np.asarray(gravity, float).tobytes(), int(npj), int(n_drive), np.asarray(prismatic, float).tobytes(),
           np.asarray(parent, np.int64).tobytes())
    with _lock:
        if key not in _kernels:
            folder, name = _cache_folder(), _ir_key(key)
            path = None if folder is None or name is None else folder / f"regressor-ir-{name}.ll.z"
            cached = _read_cache(path)
            if cached is None:
                graph, stores = _trace(rp, pp, axes, gravity, npj, n_drive, prismatic, parent)
                ir = _ir(graph, stores, len(rp), npj, n_drive)
                _write_cache(path, zlib.compress(ir.encode()))
            else:
                ir = zlib.decompress(cached).decode()
            _kernels[key] = _compile(ir)
        return _kernels[key][0]


def _ir_key(key: tuple) -> str | None:
    """The name of a robot's traced IR in the cache: its constants and kinds (``key``) and the source of the tracing
    and of the arithmetic traced, so that a change of either traces again; None where the source cannot be read (the
    IR is then traced every time, as the machine code's own cache still works)."""
    source = _source_digest()
    if source is None:
        return None
    digest = hashlib.sha256(source)
    for part in key:
        digest.update(repr(part).encode())
    return digest.hexdigest()[:32]


@functools.cache
def _source_digest() -> bytes | None:
    """SHA-256 of this module's and :mod:`dynid.dynamics._regressor_kernel`'s source, read once per process."""
    digest = hashlib.sha256()
    try:
        for module in (__file__, _regressor_kernel.__file__):
            digest.update(Path(module).read_bytes())
    except OSError:
        return None
    return digest.digest()


PARALLEL_SAMPLES = 4096
"""From this many samples on, the samples are split over the cores (threads; the compiled code runs
without the GIL); below, one call."""


def simd_regressor(robot, motion, out, drive) -> None:
    """What :func:`dynid.dynamics._regressor_kernel.joint_torque_regressor` computes (the same arguments, but
    ``drive(a, b)`` giving the drive columns (b - a, n, T) of samples ``a:b``; every entry of ``out``
    (N, n, m), C-ordered, is written), by the compiled code of :func:`kernel`, :data:`LANES` samples at a time. The
    samples after the last whole group of lanes go through it padded. ``colmap`` must place the drive
    columns where ``drive_map`` does (as :func:`dynid.dynamics.regressor.regressor` builds them)."""
    rp, pp, axes, gravity, npj, colmap, drive_map, prismatic, parent = robot
    q, dq, ddq = motion
    n_s, n = q.shape
    m, n_drive = out.shape[2], drive_map.shape[1]
    function = kernel(rp, pp, axes, gravity, npj, n_drive, prismatic, parent)
    columns = np.ascontiguousarray(colmap[:n * npj], dtype=np.int64)
    q, dq, ddq = (np.ascontiguousarray(a, dtype=float) for a in (q, dq, ddq))
    drives = np.empty((n_s, n, n_drive))

    def run(arrays, target, start, stop):
        function(*(a.ctypes.data for a in arrays), target.ctypes.data, columns.ctypes.data, m, start, stop)

    def part(start, stop):  # the drive columns are computed in the thread of their samples
        drives[start:stop] = drive(start, stop)
        run((q, dq, ddq, drives), out, start, stop)

    whole = n_s - n_s % LANES
    workers = min(cores(), max(1, whole // PARALLEL_SAMPLES))
    bounds = [whole * i // workers // LANES * LANES for i in range(workers)] + [whole]
    if workers == 1:
        part(0, whole)
    else:
        with ThreadPoolExecutor(max_workers=workers) as pool:
            list(pool.map(lambda i: part(bounds[i], bounds[i + 1]), range(workers)))
    if whole < n_s:  # the last samples, padded with copies of the last one to a whole group of lanes
        pad = np.r_[np.arange(whole, n_s), np.full(LANES - (n_s - whole), n_s - 1)]
        drives[whole:] = drive(whole, n_s)
        tail = np.empty((LANES, n, m))
        run(tuple(np.ascontiguousarray(a[pad]) for a in (q, dq, ddq, drives)), tail, 0, LANES)
        out[whole:] = tail[:n_s - whole]
