"""The kinematics kernel as one numba-compiled scalar loop (the optional ``fast`` extra).

:mod:`linkage.kinematics.kernel` records the general path's numpy operations on a mechanism as a
graph and writes it out as straight-line whole-array numpy. Where numba is installed
(``pip install ".[fast]"``) and the environment variable ``LINKAGE_NUMBA`` is not ``"0"``, this
module writes the same graph out as ONE loop over the positions, ``for i in range(n):``, each
operation a scalar expression of the one before, writing straight into the result rows, and
compiles it with ``numba.njit(cache=True)``. Every operation of the graph is element-wise (no
reduction over the positions), so a position needs nothing from another.

The scalar expressions keep numpy's semantics: ``maximum`` / ``minimum`` / ``clip`` propagate NaN
and, of two equal values, give the second (as numpy's loops do, which keeps the sign of a zero);
``a ** 2`` is ``a * a``, ``a ** -1`` is ``1 / a``, other powers are ``pow``; division by zero gives
inf or NaN (numba's ``error_model="numpy"``); no fused multiply-add (numba's default, no
fastmath). Arithmetic is then the same bit for bit; ``sin``, ``cos``, ``atan2``, ``asin`` and
``hypot`` are the C library's, as numpy's are on most machines (where numpy has its own SIMD
versions they may differ in the last ulp).

A compile takes seconds (about 2.5 s for a four-bar to second analogs) and the kernel is made
per geometry, so a kernel moves to numba only once the numpy kernel has taken as long as the
switch costs (:class:`TieredKernel`; ``LINKAGE_NUMBA=1``: from the first call). numba caches a
compiled function next to its source file, so the generated source is written to
``<cache>/linkage/kernels/<hash>.py`` (``<cache>``: ``$LINKAGE_CACHE_DIR``, else
``$XDG_CACHE_HOME``, else ``~/.cache``) and imported as a module: a second process loads the
machine code instead of compiling it again. Where that directory cannot be written, or numba
fails, the numpy kernel stays. A ``where`` is an LLVM ``select`` (``_select``), not a branch: numba's
compile time grows with the branches of a function.

>>> source = scalar_source(_Demo(), rows=[0, 0], is_float=[True, False])
>>> print(source.split("def kernel")[1].strip())          # doctest: +NORMALIZE_WHITESPACE
(I, F, J):
    n = I.shape[1]
    for i in range(n):
        v0 = I[0, i]
        v1 = (v0 * v0)
        F[0, i] = v1
        v2 = (v1 > 1.0)
        v3 = _select(v2, 2, 0)
        J[0, i] = v3
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

__all__ = ["numba_kernel", "numba_enabled", "scalar_source", "cache_dir", "TieredKernel"]

#: numpy's semantics on scalars (what the generated loops call)
_HELPERS = '''
@intrinsic
def _select(typingctx, c, x, y):
    """``x if c else y`` as one LLVM ``select`` (a ternary would be a branch: numba's compile
    time grows with the branches)."""
    out = typingctx.unify_types(x, y)

    def codegen(context, builder, signature, args):
        c_, x_, y_ = args
        x_ = context.cast(builder, x_, signature.args[1], out)
        y_ = context.cast(builder, y_, signature.args[2], out)
        return builder.select(c_, x_, y_)

    return out(c, x, y), codegen


@njit
def _sign(a):
    return 1.0 if a > 0 else (-1.0 if a < 0 else (0.0 if a == 0 else a))


@njit
def _rem(a, b):
    return a % b
'''

_INFIX = {"add": "+", "subtract": "-", "multiply": "*", "divide": "/", "less": "<", "less_equal": "<=",
          "greater": ">", "greater_equal": ">=", "equal": "==", "not_equal": "!="}
_CALL = {"sqrt": "math.sqrt", "hypot": "math.hypot", "arctan2": "math.atan2", "arcsin": "math.asin",
         "cos": "math.cos", "sin": "math.sin", "absolute": "abs", "sign": "_sign", "remainder": "_rem",
         "isfinite": "math.isfinite", "isnan": "math.isnan"}


def numba_enabled() -> bool:
    """Whether the numba kernel is wanted (``LINKAGE_NUMBA`` is not ``"0"``) and numba imports."""
    if os.environ.get("LINKAGE_NUMBA", "1") == "0":
        return False
    return importlib.util.find_spec("numba") is not None


def cache_dir() -> Path:
    """The directory of the generated kernel modules (numba keeps its compiled code beside them)."""
    root = os.environ.get("LINKAGE_CACHE_DIR") or os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(root) / "linkage" / "kernels"


def _is_node(value) -> bool:
    return not isinstance(value, (bool, int, float))


def _literal(value, as_float: bool = False) -> str:
    if isinstance(value, bool):
        return repr(value)
    if isinstance(value, int) and not as_float:
        return repr(value)
    value = float(value)
    if np.isnan(value):
        return "NAN"
    if np.isinf(value):
        return "INF" if value > 0 else "(-INF)"
    text = repr(value)
    return f"({text})" if text.startswith("-") else text


def scalar_source(trace, rows: Sequence[int], is_float: Sequence[bool], name: str = "kernel") -> str:
    """The module source of the scalar loop kernel of ``trace`` (a :class:`kernel._Trace`).

    ``def kernel(I, F, J)``: for each position ``i < I.shape[1]``, the inputs ``I[:, i]`` (the first
    input's coordinate, then ``q, q', q''`` of each further input) give every output of
    ``trace.outputs``, the ``j``-th written to ``F[rows[j], i]`` (float rows) or ``J[rows[j], i]``
    (int rows) as ``is_float[j]`` says.
    """
    outputs = trace.outputs
    wanted, needed = trace.live()

    def target(j: int) -> str:
        return f"{'F' if is_float[j] else 'J'}[{rows[j]}, i]"

    body = []
    for node in trace.graph.nodes:
        if node.uid not in needed:
            continue
        op, args, floaty = node.op, node.args, node.dtype == "f"

        def arg(a, as_float=floaty):
            return f"v{a.uid}" if _is_node(a) else _literal(a, as_float)

        if op == "input":
            expr = f"I[{args[0]}, i]"
        elif op == "full":
            expr = _literal(args[0], True)
        elif op == "pow":
            base, k = arg(args[0]), args[1]
            expr = {2: f"({base} * {base})", -1: f"(1.0 / {base})", 0: "1.0", 1: base}.get(
                k, f"math.pow({base}, {_literal(k, True)})")
        elif op == "where":
            c, x, y = args
            expr = f"_select({arg(c)}, {arg(x)}, {arg(y)})"
        elif op in ("maximum", "minimum"):       # inline: numba's typing of a call costs more than a branch
            a, b = arg(args[0], True), arg(args[1], True)
            expr = f"_select(({a} {'>' if op == 'maximum' else '<'} {b}) | ({a} != {a}), {a}, {b})"
        elif op == "clip":       # numpy's: minimum(maximum(x, lo), hi)
            lo, hi, x = _literal(args[1], True), _literal(args[2], True), arg(args[0])
            body.append(f"        c{node.uid} = _select(({x} > {lo}) | ({x} != {x}), {x}, {lo})")
            expr = f"_select((c{node.uid} < {hi}) | (c{node.uid} != c{node.uid}), c{node.uid}, {hi})"
        elif op == "negative":
            expr = f"(-{arg(args[0])})"
        elif op in ("invert", "logical_not"):
            expr = f"(not {arg(args[0])})"
        elif op in ("bitwise_and", "logical_and", "bitwise_or", "logical_or"):
            word = "&" if op.endswith("and") else "|"
            if not all(not _is_node(a) or a.dtype == "b" for a in args):
                raise TypeError(f"numba kernel: {op} of non-booleans")
            expr = f"({arg(args[0])} {word} {arg(args[1])})"
        elif op in _INFIX:         # a constant is a float where the result or the other operand is
            as_float = floaty or any(_is_node(a) and a.dtype == "f" for a in args)
            expr = f"({arg(args[0], as_float)} {_INFIX[op]} {arg(args[1], as_float)})"
        elif op in _CALL:
            expr = f"{_CALL[op]}({', '.join(arg(a, True) for a in args)})"
        else:
            raise TypeError(f"numba kernel: the operation {op!r} has no scalar form")
        body.append(f"        v{node.uid} = {expr}")
        for j in wanted.get(node.uid, ()):
            body.append(f"        {target(j)} = v{node.uid}")
    for j, (_, value) in enumerate(outputs):
        if not _is_node(value):
            body.append(f"        {target(j)} = {_literal(value, is_float[j])}")
    head = ["# generated by linkage.kinematics.kernel_numba: the scalar loop kernel of one mechanism",
            "import math", "", "from numba import njit", "from numba.extending import intrinsic", "",
            "NAN = math.nan", "INF = math.inf", _HELPERS, "",
            '@njit(cache=True, error_model="numpy", nogil=True)',
            f"def {name}(I, F, J):", "    n = I.shape[1]", "    for i in range(n):"]
    return "\n".join(head + body) + "\n"


def _write(source: str) -> Path | None:
    """The generated module's file (written once, atomically; None where it cannot be)."""
    digest = hashlib.sha256(source.encode()).hexdigest()[:24]
    folder = cache_dir()
    path = folder / f"k{digest}.py"
    try:
        if not path.exists() or path.read_text() != source:
            folder.mkdir(parents=True, exist_ok=True)
            temporary = folder / f".k{digest}.{os.getpid()}.tmp"
            temporary.write_text(source)
            os.replace(temporary, path)
    except OSError:
        return None
    return path


#: loaded kernels by source
_LOADED: dict[str, Callable] = {}
#: whether numba has loaded or compiled a kernel in this process (its start-up is paid)
_STARTED = False
#: seconds: numba's import and start-up in a process, a compile, a load from numba's cache
#: (what :class:`TieredKernel` weighs against the time the numpy kernel has taken)
STARTUP_COST, COMPILE_COST, LOAD_COST = 0.7, 2.5, 0.02


def _load(source: str) -> Callable | None:
    """The jitted kernel of ``source`` (imported from its file; numba compiles it or loads it
    from its cache on the first call)."""
    global _STARTED
    fn = _LOADED.get(source)
    if fn is not None:
        return fn
    path = _write(source)
    if path is None:
        return None
    name = f"linkage_kernels.{path.stem}"
    module = sys.modules.get(name)
    if module is None:
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        sys.modules[name] = module
    fn = module.kernel
    fn.compile("(float64[:, ::1], float64[:, ::1], intp[:, ::1])")   # compiled, or loaded from numba's cache
    _STARTED = True
    _LOADED[source] = fn
    return fn


def _on_disk(source: str) -> bool:
    """Whether numba's cache next to the generated module holds its compiled code."""
    digest = hashlib.sha256(source.encode()).hexdigest()[:24]
    return any((cache_dir() / "__pycache__").glob(f"k{digest}.kernel-*.nbi"))


class TieredKernel:
    """A kernel of :mod:`linkage.kinematics.kernel` that moves from numpy to numba once it has
    earned it.

    Called as the numpy kernel (``kernel(I, O)``: blocks of input and output rows), it runs the
    numpy kernel and adds up its time. :meth:`whole` runs the numba kernel on whole rows once it
    is compiled: with ``LINKAGE_NUMBA=1`` from the first call; by default (ski rental) once the
    numpy kernel has taken as long as the switch costs -- numba's start-up if this process has
    not paid it, plus a compile (or a load where numba's cache has the kernel) -- so a mechanism
    analysed once or twice (a variant, a random mechanism in a test) never waits for a compile;
    never with ``LINKAGE_NUMBA=0``, or when numba fails (the numpy kernel stays).
    """

    def __init__(self, trace, rows: Sequence[int], is_float: Sequence[bool], numpy_kernel: Callable):
        self.trace, self.rows, self.is_float, self.numpy_kernel = trace, list(rows), list(is_float), numpy_kernel
        self.spent = 0.0                   # seconds taken by the numpy kernel so far
        self.jitted: Callable | None = None
        self.failed = False
        self._source: str | None = None
        self._cached: bool | None = None

    @property
    def source(self) -> str:
        """The generated module's source."""
        if self._source is None:
            self._source = scalar_source(self.trace, self.rows, self.is_float)
        return self._source

    def __call__(self, inputs, outputs) -> None:
        start = time.perf_counter()
        self.numpy_kernel(inputs, outputs)
        self.spent += time.perf_counter() - start

    def due(self) -> bool:
        """Whether the numba kernel should be compiled (or loaded) now."""
        mode = os.environ.get("LINKAGE_NUMBA", "")
        if mode == "0":
            return False
        if mode == "1":
            return True
        startup = 0.0 if _STARTED else STARTUP_COST
        if self.spent < startup + LOAD_COST:
            return False
        if self._cached is None:
            self._cached = _on_disk(self.source)
        return self.spent >= startup + (LOAD_COST if self._cached else COMPILE_COST)

    def compile(self) -> bool:
        """Compile (or load) the numba kernel now; False where numba fails."""
        if self.jitted is None and not self.failed:
            try:
                self.jitted = _load(self.source)
            except Exception:      # numba's own errors (typing, lowering, a broken cache) are many: fall back
                self.jitted = None
            self.failed = self.jitted is None
        return self.jitted is not None

    def whole(self, inputs: list[np.ndarray], floats: np.ndarray, ints: np.ndarray) -> bool:
        """Fill the ``(R, N)`` ``floats`` and ``(G + 1, N)`` ``ints`` rows (C order) from the ``(N,)``
        ``inputs`` by the numba kernel; False (nothing done) while the numpy kernel is the one."""
        jitted = self.jitted
        if jitted is None:
            if self.failed or not self.due() or not self.compile():
                return False
            jitted = self.jitted
        first = inputs[0]
        if len(inputs) == 1:
            stacked = first.reshape(1, -1) if first.flags.c_contiguous else np.ascontiguousarray(first)[None]
        else:
            stacked = np.empty((len(inputs), len(first)))
            for k, v in enumerate(inputs):
                stacked[k] = v
        jitted(stacked, floats, ints)
        return True


def numba_kernel(trace, rows: Sequence[int], is_float: Sequence[bool], numpy_kernel: Callable) -> Callable:
    """``numpy_kernel`` (the numpy kernel of ``trace``, its ``j``-th output going to row
    ``rows[j]``, a float row where ``is_float[j]``) as a :class:`TieredKernel` where numba is
    installed and ``LINKAGE_NUMBA`` is not ``"0"``; else ``numpy_kernel`` itself."""
    return TieredKernel(trace, rows, is_float, numpy_kernel) if numba_enabled() else numpy_kernel


class _Demo:
    """A two-output trace for the doctest: ``F[0] = x**2``, ``J[0] = 2 where x**2 > 1 else 0``."""

    def __init__(self):
        from types import SimpleNamespace as N
        x = N(op="input", args=(0,), dtype="f", uid=0)
        square = N(op="pow", args=(x, 2), dtype="f", uid=1)
        big = N(op="greater", args=(square, 1.0), dtype="b", uid=2)
        flag = N(op="where", args=(big, 2, 0), dtype="i", uid=3)
        self.graph = N(nodes=[x, square, big, flag])
        self.outputs = [("square", square), ("flag", flag)]

    def live(self):
        """The outputs' nodes and every node: all are needed here (see ``_Trace.live``)."""
        return {1: [0], 3: [1]}, {0, 1, 2, 3}
