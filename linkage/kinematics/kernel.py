"""A compiled kinematics kernel per mechanism: straight-line numpy generated from its structure.

:func:`linkage.analyze` walks the groups of a mechanism, each group solving itself through dicts
of arrays and per-pair row objects (:meth:`assur.dyad.Dyad.solve`). For a mechanism whose
groups are all closed-form dyads (RRR, RRP, RPR, PRP, RPP) this module writes the same
computation out once as ONE straight-line Python function of whole-array numpy operations --
inputs, every group's position, closure check, conditioning, error bound, statuses, first and
second analogs and the second analogs' flags -- compiled with :func:`exec` and kept per
mechanism, order and assembly branches.

How it is written: the general path's own code (each kind's ``_place``, the pair rows of
:mod:`assur.rows`, ``Dyad._conditioning`` and ``Dyad._eliminate``) is run once on symbolic
arrays (:class:`_Sym`) that record every numpy operation in a graph, with the error bounds and
second-analog statuses of :mod:`assur.base`; the steps of :meth:`Dyad.solve` and of ``run_blocks``
/ :func:`linkage.kinematics.inputs.input_state` are restated here on the same symbols. The graph keeps the general path's operations in their order (so the numbers are the
same, bit for bit where numpy evaluates them alike), with what does not depend on the input
angle folded to constants, identical subexpressions merged, dead ones dropped and the
temporaries' buffers reused (``out=``) once their last use is passed.

>>> import numpy as np, linkage
>>> mech = linkage.load("four_bar")
>>> got = run_kernel(mech, np.radians([0.0, 90.0]), order=2)
>>> got["status"].tolist(), got["poses"]["3"].shape
([0, 0], (2, 3))

Use :func:`kernel_for` for the callable, :func:`run_kernel` for the results; both give None
where the kernel does not apply (a group without a closed form, a driven cylinder, branches
that change between the requested positions), and the general path is the answer there.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from typing import Any

import numpy as np

from assur.base import (ANALOG_TOL, CANNOT_ASSEMBLE, CLOSURE_TOL, OK, SINGULAR, DrivenPrismaticJoint, error_bound,
                        rotate, second_analog_status)
from assur.dyad import Dyad
from assur.rows import rows_of, xy

from ..model.mechanism import Mechanism
from ..structure import Structure, structure_of
from .assembly import assembly_plans
from .inputs import input_angles
from .kernel_numba import numba_kernel
from .kernel_rows import LinkRows, PointRows

__all__ = ["kernel_for", "run_kernel", "kernel_source", "KERNEL_BLOCK"]

#: positions computed at a time (the temporaries of a block stay in the processor's cache)
KERNEL_BLOCK = 8192
EPS = float(np.finfo(float).eps)

# ----------------------------------------------------------------------------------------------
# symbolic arrays: a graph of numpy operations
# ----------------------------------------------------------------------------------------------

_BOOL_OUT = {"less", "less_equal", "greater", "greater_equal", "equal", "not_equal", "isfinite", "isnan",
             "logical_and", "logical_or", "logical_not"}


def _const(value):
    """A constant operand as a plain Python bool, int or float (``None`` when it is not one)."""
    if isinstance(value, np.ndarray):
        if value.ndim:
            return None
        value = value.item()
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    return None


def _kind(value) -> str:
    """``"b"``, ``"i"`` or ``"f"``: the dtype of an operand."""
    if isinstance(value, _Sym):
        return value.dtype
    return "b" if isinstance(value, bool) else "i" if isinstance(value, int) else "f"


def _key(value):
    if isinstance(value, _Sym):
        return ("n", value.uid)
    return ("c", _kind(value), value.hex() if isinstance(value, float) else value)


class _Graph:
    """The operations recorded while tracing, in creation (topological) order, merged by key."""

    def __init__(self):
        self.nodes: list[_Sym] = []
        self.table: dict = {}

    def node(self, op: str, args: tuple, dtype: str) -> "_Sym":
        key = (op, tuple(_key(a) for a in args))
        got = self.table.get(key)
        if got is None:
            got = _Sym(self, op, args, dtype, len(self.nodes))
            self.nodes.append(got)
            self.table[key] = got
        return got


class _Sym:
    """A symbolic ``(n,)`` array: the result of ``op`` on ``args`` (symbols or constants)."""

    __array_priority__ = 1000

    def __init__(self, graph: _Graph, op: str, args: tuple, dtype: str, uid: int):
        self.graph, self.op, self.args, self.dtype, self.uid = graph, op, args, dtype, uid
        self.nonneg = False     # +0.0, positive or NaN everywhere (set by the builder when known)

    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        if method != "__call__" or kwargs or getattr(np, ufunc.__name__, None) is not ufunc:
            raise TypeError(f"kernel tracing: {ufunc.__name__}.{method} {kwargs} is not supported")
        args = tuple(a if isinstance(a, _Sym) else _const(a) for a in inputs)
        if any(a is None for a in args):
            raise TypeError(f"kernel tracing: unsupported operand of {ufunc.__name__}")
        if not any(isinstance(a, _Sym) for a in args):
            return ufunc(*args)
        return _simplified(self.graph, ufunc.__name__, args)

    def __array_function__(self, func, types, args, kwargs):
        if func is np.where and not kwargs and len(args) == 3:
            return _where(self.graph, *args)
        if func is np.clip and not kwargs and len(args) == 3:
            lo, hi = _const(args[1]), _const(args[2])
            if lo is None or hi is None:
                raise TypeError("kernel tracing: clip bounds must be constants")
            return self.graph.node("clip", (args[0], lo, hi), "f")
        raise TypeError(f"kernel tracing: {func.__name__} is not supported")

    def __bool__(self):
        raise TypeError("kernel tracing: a symbolic array has no truth value (data-dependent branch)")

    def __len__(self):
        raise TypeError("kernel tracing: a symbolic array has no length")

    __hash__ = object.__hash__
    __add__ = lambda a, b: np.add(a, b)                 # noqa: E731
    __radd__ = lambda a, b: np.add(b, a)                # noqa: E731
    __sub__ = lambda a, b: np.subtract(a, b)            # noqa: E731
    __rsub__ = lambda a, b: np.subtract(b, a)           # noqa: E731
    __mul__ = lambda a, b: np.multiply(a, b)            # noqa: E731
    __rmul__ = lambda a, b: np.multiply(b, a)           # noqa: E731
    __truediv__ = lambda a, b: np.divide(a, b)          # noqa: E731
    __rtruediv__ = lambda a, b: np.divide(b, a)         # noqa: E731
    __mod__ = lambda a, b: np.remainder(a, b)           # noqa: E731
    __neg__ = lambda a: np.negative(a)                  # noqa: E731
    __abs__ = lambda a: np.absolute(a)                  # noqa: E731
    __invert__ = lambda a: np.invert(a)                 # noqa: E731
    __and__ = __rand__ = lambda a, b: np.bitwise_and(a, b)   # noqa: E731
    __or__ = __ror__ = lambda a, b: np.bitwise_or(a, b)      # noqa: E731
    __lt__ = lambda a, b: np.less(a, b)                 # noqa: E731
    __le__ = lambda a, b: np.less_equal(a, b)           # noqa: E731
    __gt__ = lambda a, b: np.greater(a, b)              # noqa: E731
    __ge__ = lambda a, b: np.greater_equal(a, b)        # noqa: E731
    __eq__ = lambda a, b: np.equal(a, b)                # noqa: E731
    __ne__ = lambda a, b: np.not_equal(a, b)            # noqa: E731

    def __pow__(self, exponent):
        k = _const(exponent)
        if k is None:
            raise TypeError("kernel tracing: the exponent must be a constant")
        base = _negated(self) if k == 2 and _negated(self) is not None else self
        node = self.graph.node("pow", (base, k), "f")   # written as ``a ** k``: numpy's own fast paths
        node.nonneg = node.nonneg or k == 2 or base.nonneg
        return node


def _nonneg(value) -> bool:
    """Whether an operand is +0.0, positive or NaN at every position (never -0.0 or negative)."""
    if isinstance(value, _Sym):
        return value.nonneg
    return not isinstance(value, bool) and (value > 0 or (value == 0 and str(float(value))[0] != "-"))


def _negated(value):
    """``x`` when ``value`` is the node ``-x`` (else None)."""
    return value.args[0] if isinstance(value, _Sym) and value.op == "negative" else None


def _simplified(graph: _Graph, name: str, args: tuple):
    """The node of ufunc ``name`` on ``args``, simplified where the result is the same bit for bit:
    ``x * 1``, ``x / 1``, ``x - 0.0``, ``x + 0.0`` and ``max(0, x)`` (x never -0.0), ``x & True``,
    ``x * -1`` -> ``-x``, and negations absorbed (``x + -y`` -> ``x - y``, ``-x * -y`` -> ``x * y``,
    ``|-x|`` -> ``|x|``, ``-x * c`` -> ``x * -c`` ...)."""
    floats = all(_kind(a) == "f" for a in args)
    if len(args) == 1 and floats:
        (a,) = args
        inner = _negated(a)
        if name == "negative" and inner is not None:
            return inner
        if name == "absolute" and inner is not None:
            return _simplified(graph, "absolute", (inner,))
    if len(args) == 2:
        a, b = args
        na, nb = _negated(a), _negated(b)
        const_a, const_b = not isinstance(a, _Sym), not isinstance(b, _Sym)
        if name == "multiply" and floats or name == "multiply" and (_kind(a), _kind(b)) in (("f", "i"), ("i", "f")):
            for x, y, const_x in ((a, b, const_a), (b, a, const_b)):
                if const_x and x == 1 and _kind(y) == "f":
                    return y
                if const_x and x == -1 and _kind(y) == "f":
                    return _simplified(graph, "negative", (y,))
            if na is not None and nb is not None:
                return _simplified(graph, "multiply", (na, nb))
            if na is not None and const_b:
                return _simplified(graph, "multiply", (na, -b))
            if nb is not None and const_a:
                return _simplified(graph, "multiply", (-a, nb))
        elif name == "divide" and floats:
            if const_b and b == 1:
                return a
            if na is not None and const_b:
                return _simplified(graph, "divide", (na, -b))
        elif name == "subtract" and floats:
            if const_b and b == 0.0 and _nonneg(b):
                return a
            if nb is not None:
                return _simplified(graph, "add", (a, nb))
        elif name == "add" and floats:
            for x, y, const_x in ((a, b, const_a), (b, a, const_b)):
                if const_x and x == 0.0 and (not _nonneg(x) or _nonneg(y)):
                    return y
            if nb is not None:
                return _simplified(graph, "subtract", (a, nb))
            if na is not None:
                return _simplified(graph, "subtract", (b, na))
        elif name == "hypot" and (na is not None or nb is not None):
            return _simplified(graph, "hypot", (a if na is None else na, b if nb is None else nb))
        elif name in ("bitwise_and", "logical_and", "bitwise_or", "logical_or"):
            for x, y in ((a, b), (b, a)):
                if isinstance(y, bool) and _kind(x) == "b":
                    return (x if y else False) if name.endswith("and") else (True if y else x)
            if a is b:
                return a
        elif name in ("maximum", "minimum") and a is b:
            return a
        elif name == "maximum" and floats:
            for x, y, const_x in ((a, b, const_a), (b, a, const_b)):
                if const_x and not np.isnan(x) and x <= 0 and _nonneg(y):
                    return y
    dtype = "b" if name in _BOOL_OUT or (name in ("bitwise_and", "bitwise_or", "invert")
                                         and all(_kind(a) == "b" for a in args)) else "f"
    node = graph.node(name, args, dtype)
    if dtype == "f" and not node.nonneg:
        node.nonneg = (name in ("absolute", "hypot")
                       or (name == "multiply" and args[0] is args[1])
                       or (name in ("multiply", "divide", "add", "maximum", "sqrt") and all(_nonneg(x) for x in args)))
    return node


def _where(graph: _Graph, cond, x, y):
    c = cond if isinstance(cond, _Sym) else _const(cond)
    x = x if isinstance(x, _Sym) else _const(x)
    y = y if isinstance(y, _Sym) else _const(y)
    if c is None or x is None or y is None:
        raise TypeError("kernel tracing: unsupported operand of where")
    if not isinstance(c, _Sym):
        return x if c else y
    if _key(x) == _key(y):
        return x
    if isinstance(y, _Sym) and y.op == "where" and y.args[0] is c and _key(y.args[1]) == _key(x):
        return y                                         # where(c, x, where(c, x, z))
    if isinstance(x, _Sym) and not isinstance(y, _Sym):    # where(~c, const, x): x's buffer can take it
        c = c.args[0] if c.op == "invert" else graph.node("invert", (c,), "b")
        x, y = y, x
    kinds = {_kind(x), _kind(y)}
    dtype = "f" if "f" in kinds else "i" if "i" in kinds else "b"
    node = graph.node("where", (c, x, y), dtype)
    node.nonneg = node.nonneg or (dtype == "f" and _nonneg(x) and _nonneg(y))
    return node


# ----------------------------------------------------------------------------------------------
# tracing the general path
# ----------------------------------------------------------------------------------------------


def supported(mech: Mechanism, structure: Structure | None = None) -> bool:
    """Whether every group of ``mech`` is a closed-form dyad and every input a crank or a slider
    on the frame (what the kernel writes out)."""
    structure = structure_of(mech) if structure is None else structure
    if any(isinstance(j, DrivenPrismaticJoint) for j in structure.input_joints.values()):
        return False
    for g in structure.groups:
        # a dyad solved by the shared closed-form path (its kind only places it): what the trace records
        if not (isinstance(g, Dyad) and type(g).solve is Dyad.solve) or np.ndim(g.size) \
                or any(type(j).rows != 2 for j in g.joints):
            return False
    return True


class _Trace:
    """The graph of a mechanism's kinematics and the outputs to write (name -> node or constant)."""

    def live(self) -> tuple[dict[int, list[int]], set[int]]:
        """The nodes the outputs are (node id -> the outputs' indices) and every node they need:
        what a kernel computes, whichever language it is written in."""
        wanted: dict[int, list[int]] = {}
        for j, (_, value) in enumerate(self.outputs):
            if isinstance(value, _Sym):
                wanted.setdefault(value.uid, []).append(j)
        needed: set[int] = set()
        stack = [self.graph.nodes[uid] for uid in wanted]
        while stack:
            node = stack.pop()
            if node.uid not in needed:
                needed.add(node.uid)
                stack += [a for a in node.args if isinstance(a, _Sym)]
        return wanted, needed

    def __init__(self, mech: Mechanism, structure: Structure, order: int, branches: tuple[int, ...],
                 geometry: Callable | None = None):
        self.graph = g = _Graph()
        self.outputs: list[tuple[str, Any]] = []
        n_inputs = len(structure.inputs)
        params = [g.node("input", (0,), "f")]
        for k in range(1, n_inputs):
            params += [g.node("input", (3 * k - 2 + i,), "f") for i in range(3)]
        if geometry is not None:     # the geometry as further inputs (kernel_variants.py), no named points
            structure = geometry(g, len(params))
        self.n_params = len(params)
        frames, first, second = self._inputs(mech, structure, order, params)
        errors: dict[str, Any] = {k: 0.0 for k in (mech.frame, *structure.inputs)}
        status: Any = OK
        errors.update({k: 0.0 for group in structure.groups for k in group.links})
        for i, (group, branch) in enumerate(zip(structure.groups, branches)):
            incoming = 0.0
            for k in group.known_links:
                incoming = np.maximum(incoming, errors[k])
            got = _solve_dyad(group, frames, first, second, branch, incoming, order)
            for k in group.links:
                errors[k] = got["bound"]
            self.outputs += [(f"conditioning {i}", got["conditioning"]), (f"sign {i}", got["sign"]),
                             (f"scale {i}", got["scale"]), (f"solved {i}", got["status"])]
            for k, pose in got["poses"].items():
                self.outputs += [(f"pose {k} {c}", v) for c, v in enumerate(pose)]
            status = np.where(status == OK, got["status"], status)
        error = 0.0
        for v in errors.values():
            error = np.maximum(error, v)
        self.outputs += [("status", status), ("error", error)]
        bad = status != OK
        masked = {}
        for name, analogs in (("first", first), ("second", second)):
            masked[name] = {k: tuple(np.where(bad, np.nan, v) for v in values) for k, values in (analogs or {}).items()}
            for k, values in masked[name].items():
                self.outputs += [(f"{name} {k} {c}", v) for c, v in enumerate(values)]
        poses = {k: (f[0], f[1], f[4]) for k, f in frames.items() if k != mech.frame}
        for j, (link, local) in enumerate(moving_points(mech) if geometry is None else ()):
            self.outputs += _point(poses[link], masked["first"].get(link), masked["second"].get(link), local, j)

    def _inputs(self, mech, structure, order, params):
        """:func:`linkage.kinematics.inputs.input_state` on symbols: the frames and the analogs
        of the frame and the inputs."""
        g = self.graph
        frames = {mech.frame: (0.0, 0.0, 1.0, 0.0, 0.0)}
        first = {mech.frame: (0.0, 0.0, 0.0)} if order >= 1 else None
        second = {mech.frame: (0.0, 0.0, 0.0)} if order >= 2 else None
        for k, name in enumerate(structure.inputs):
            joint = structure.input_joints[name]
            q, rate, accel = (params[0], 1.0, 0.0) if k == 0 else params[3 * k - 2:3 * k + 1]
            if joint.kind == "P":
                pose, d1, d2 = _slider(joint, name, q, rate, accel)
                theta = g.node("full", (pose[2],), "f")     # cos / sin of an array, as input_state
                frames[name] = (pose[0], pose[1], np.cos(theta), np.sin(theta), theta)
            else:
                p_input, _, p_frame = joint.local(name)
                (px, py), (fx, fy) = xy(p_input), xy(p_frame)
                c, s = np.cos(q), np.sin(q)
                rx, ry = c * px - s * py, s * px + c * py
                pose = (fx - rx, fy - ry, q)
                frames[name] = (pose[0], pose[1], c, s, q)
                d1 = (ry * rate, -rx * rate, rate)
                d2 = (rx * rate**2 + ry * accel, ry * rate**2 - rx * accel, accel)
            self.outputs += [(f"pose {name} {c}", v) for c, v in enumerate(pose)]
            if first is not None:
                first[name] = d1
            if second is not None:
                second[name] = d2
        return frames, first, second


def moving_points(mech: Mechanism) -> list[tuple[str, tuple[float, float]]]:
    """``(link, local point)`` of each named point that a moving link reports
    (:meth:`Mechanism.point_link`) and of each moving link's centre of mass (the kinetostatics'),
    each once."""
    out = [(mech.point_link(p), mech.links[mech.point_link(p)].points[p]) for p in mech.point_names]
    out += [(k, mech.links[k].center_of_mass) for k in mech.moving_links]
    return list(dict.fromkeys((k, tuple(float(c) for c in local)) for k, local in out if k != mech.frame))


def _point(pose, first, second, local, name: int) -> list[tuple[str, Any]]:
    """:meth:`linkage.kinematics.motion.Motion.local_point` on symbols (the link's cosines and sines
    of its angle, as :func:`assur.rows.frame` takes them): the outputs ``point P c``,
    ``point first P c``, ``point second P c`` of the ``P``-th point."""
    x, y, theta = pose
    (px, py), c, s = xy(local), np.cos(theta), np.sin(theta)
    rx, ry = c * px - s * py, s * px + c * py
    out = [(f"point {name} 0", x + rx), (f"point {name} 1", y + ry)]
    if first is not None:
        out += [(f"point first {name} 0", first[0] + (-ry) * first[2]),
                (f"point first {name} 1", first[1] + rx * first[2])]
    if second is not None:
        turn2 = first[2] ** 2
        out += [(f"point second {name} 0", second[0] + (-ry) * second[2] - rx * turn2),
                (f"point second {name} 1", second[1] + rx * second[2] - ry * turn2)]
    return out


def _slider(joint, link, s, rate, accel):
    """:func:`linkage.kinematics.inputs.slider_state` on symbols: pose and analogs (3 each)."""
    if joint.b == link:
        theta, sign = joint.beta, 1.0
        u = np.asarray(joint.u, float)
        start = np.asarray(joint.g, float) - rotate(theta, joint.p)
    else:
        theta, sign = -joint.beta, -1.0
        u = rotate(theta, joint.u)
        start = np.asarray(joint.p, float) - rotate(theta, joint.g)
    along = sign * s
    ux, uy, sx, sy = (float(v) for v in (u[0], u[1], start[0], start[1]))
    pose = (sx + along * ux, sy + along * uy, float(theta))
    d1 = (sign * rate * ux, sign * rate * uy, 0.0)
    d2 = (sign * accel * ux, sign * accel * uy, 0.0)
    return pose, d1, d2


def _solve_dyad(group, frames, first, second, branch, input_error, order) -> dict:
    """:meth:`assur.dyad.Dyad.solve` on symbols (the kind's ``_place``, rows, ``_conditioning``
    and ``_eliminate`` run as they are); updates ``frames``, ``first`` and ``second`` with the
    group's links as later groups see them."""
    l1, l2 = group.links
    placed, ok = group._place(frames, branch)
    frames.update(placed)
    rows = [rows_of(j, frames) for j in group.joints]
    ext1, inner, ext2 = rows
    closure = np.maximum(np.maximum(ext1.residual(frames, group.size), inner.residual(frames, group.size)),
                         ext2.residual(frames, group.size))
    assembled = ok & (closure <= CLOSURE_TOL * group.size)
    c1, c2 = inner.act(l1, ext1.null(l1)), inner.act(l2, ext2.null(l2))
    det = c1[0] * c2[1] - c1[1] * c2[0]
    ratio, scale = group._conditioning(rows, frames, det)
    bound = np.where(assembled, error_bound(ratio, input_error, group.roundoff_factor), np.inf)
    status = np.where(assembled, np.where(bound <= ANALOG_TOL, OK, SINGULAR), CANNOT_ASSEMBLE)
    sign = np.where(assembled, np.sign(det), 0.0)
    conditioning = np.where(assembled, ratio, np.nan)
    placed = {k: tuple(np.where(assembled, c, np.nan) for c in f) for k, f in placed.items()}
    frames.update(placed)
    poses = {k: (f[0], f[1], f[4]) for k, f in placed.items()}
    if order >= 1:
        bad = status != OK
        system = (c1, c2, np.where(bad, 1.0, det))
        known = {k: first[k] for k in group.known_links}
        q1, q2 = group._eliminate(rows, system, known, None)
        solved1 = {**known, l1: q1, l2: q2}
        if order >= 2:
            gammas = [r.quadratic(solved1) for r in rows]
            known2 = {k: second[k] for k in group.known_links}
            a1, a2 = group._eliminate(rows, system, known2, gammas)
            status, bound = second_analog_status(group, status, bound, ratio, input_error, scale, solved1,
                                                 {**known2, l1: a1, l2: a2})
            bad = status != OK      # the solve's NaN where not OK, then where flagged: the same
            second[l1], second[l2] = (tuple(np.where(bad, np.nan, v) for v in a) for a in (a1, a2))
        first[l1], first[l2] = (tuple(np.where(bad, np.nan, v) for v in q) for q in (q1, q2))
    return {"poses": poses, "status": status, "sign": sign, "conditioning": conditioning, "bound": bound,
            "scale": np.where(assembled, scale, np.nan)}


# ----------------------------------------------------------------------------------------------
# writing the graph out as Python source
# ----------------------------------------------------------------------------------------------


def _literal(value) -> str:
    if isinstance(value, (bool, int)):
        return repr(value)
    if np.isnan(value):
        return "NAN"
    if np.isinf(value):
        return "INF" if value > 0 else "(-INF)"
    text = repr(float(value))
    return f"({text})" if text.startswith("-") else text


def _source(trace: _Trace, name: str = "kernel") -> str:
    """The kernel's source: ``def kernel(I, O)`` computing every output of ``trace`` from the input
    arrays ``I`` (the first input's coordinates, then ``q, q', q''`` of each further input) into
    the ``(n,)`` arrays ``O`` (in the order of ``trace.outputs``)."""
    wanted, needed = trace.live()
    nodes = [n for n in trace.graph.nodes if n.uid in needed]
    last: dict[int, int] = {}
    for p, node in enumerate(nodes):
        for a in node.args:
            if isinstance(a, _Sym):
                last[a.uid] = p
    names: dict[int, str] = {}
    owned: set[str] = set()          # variables holding arrays made here (their buffers may be reused)
    free: list[str] = []
    count = 0
    lines = [f"def {name}(I, O):", "    n = I[0].shape[0]", '    with np.errstate(all="ignore"):']

    def arg(a) -> str:
        return names[a.uid] if isinstance(a, _Sym) else _literal(a)

    def reusable(a, p, dtype) -> bool:
        return isinstance(a, _Sym) and last.get(a.uid) == p and names[a.uid] in owned and a.dtype == dtype

    for p, node in enumerate(nodes):
        target = None
        op, args = node.op, node.args
        if op == "input":
            expr = f"I[{args[0]}]"
        elif op == "full":
            expr = f"np.full(n, {arg(args[0])})"
        elif op == "pow":
            expr = f"{arg(args[0])} ** {_literal(args[1])}"
        elif op == "where":
            c, x, y = args
            if reusable(y, p, node.dtype) and x is not y:
                target = names[y.uid]
                expr = f"np.copyto({target}, {arg(x)}, where={arg(c)})"
            else:
                expr = f"np.where({arg(c)}, {arg(x)}, {arg(y)})"
        else:
            call = "clip" if op == "clip" else op
            text = ", ".join(arg(a) for a in args)
            for a in args:
                if reusable(a, p, node.dtype):
                    target = names[a.uid]
                    break
            expr = f"np.{call}({text}" + (f", out={target})" if target else ")")
        if target is not None:
            lines.append(f"        {expr}")
            var = target
        else:
            if free:
                var = free.pop()
            else:
                var = f"t{count}"
                count += 1
            lines.append(f"        {var} = {expr}")
            if op == "input":
                owned.discard(var)
            else:
                owned.add(var)
        names[node.uid] = var
        for j in wanted.get(node.uid, ()):
            lines.append(f"        O[{j}][...] = {var}")
        for a in {a.uid: a for a in args if isinstance(a, _Sym)}.values():
            if last[a.uid] == p and names[a.uid] != var:
                free.append(names[a.uid])
        if node.uid not in last:      # an output only
            free.append(var)
    for j, (_, value) in enumerate(trace.outputs):
        if not isinstance(value, _Sym):
            lines.append(f"        O[{j}][...] = {_literal(_const(value))}")
    return "\n".join(lines) + "\n"


#: compiled kernels by source (mechanisms with the same geometry share one)
_COMPILED: dict[str, Callable] = {}


def _compiled(source: str) -> Callable:
    fn = _COMPILED.get(source)
    if fn is None:
        namespace = {"np": np, "NAN": np.nan, "INF": np.inf}
        exec(compile(source, "<linkage kinematics kernel>", "exec"), namespace)
        fn = namespace["kernel"]
        if len(_COMPILED) >= 256:
            _COMPILED.clear()
        _COMPILED[source] = fn
    return fn


# ----------------------------------------------------------------------------------------------
# the public face
# ----------------------------------------------------------------------------------------------


class Kernel:
    """The kinematics of one mechanism to one analog ``order``, as compiled kernels (one per set of
    assembly branches met). Call it with the input coordinates ``phi`` ``(N,)``: the dict of
    :func:`run_kernel`, or None where a group's branch changes between the positions.

    The results are rows of two arrays allocated per call: one ``(R, N)`` of floats (poses and
    analogs, three rows per link, then each group's conditioning, sign and scale and the error bound)
    and one ``(G + 1, N)`` of ints (the status, each group's own status); the dicts hold views.
    """

    def __init__(self, mech: Mechanism, structure: Structure, order: int, geometry: Callable | None = None):
        self._mech = weakref.ref(mech)     # kept per mechanism in a module dict: no strong reference back
        self.structure, self.order, self.geometry = structure, order, geometry
        self.functions: dict[tuple[int, ...], tuple[Callable, list[int], list[bool]]] = {}
        links = [mech.frame, *structure.inputs, *(k for g in structure.groups for k in g.links)]
        self.links = links
        self._link_index = {k: i for i, k in enumerate(links)}
        rows: dict[str, tuple[bool, int]] = {}
        for kind in ("pose", "first", "second")[:order + 1]:
            for k in links:
                for c in range(3):
                    rows[f"{kind} {k} {c}"] = (True, len(rows))
        self.points = moving_points(mech) if geometry is None else []
        first_point = 3 * len(links) * (order + 1)
        self._point_rows = {point: [first_point + 2 * (j * len(self.points) + i) for j in range(order + 1)]
                            for i, point in enumerate(self.points)}
        for kind in ("point", "point first", "point second")[:order + 1]:
            for point in range(len(self.points)):
                for c in range(2):
                    rows[f"{kind} {point} {c}"] = (True, len(rows))
        n_groups = len(structure.groups)
        self.group_rows = len(rows)         # each group's conditioning, sign and scale rows from here
        self.labels = [repr(g) for g in structure.groups]
        for i in range(n_groups):
            rows[f"conditioning {i}"] = (True, len(rows))
            rows[f"sign {i}"] = (True, len(rows))
            rows[f"scale {i}"] = (True, len(rows))
        rows["error"] = (True, len(rows))
        self.n_float = len(rows)
        rows["status"] = (False, 0)
        for i in range(n_groups):
            rows[f"solved {i}"] = (False, 1 + i)
        self.rows = rows

    @property
    def mech(self) -> Mechanism:
        return self._mech()

    def source(self, branches: tuple[int, ...]) -> str:
        """The Python source of the kernel for the groups' ``branches``."""
        return _source(_Trace(self.mech, self.structure, self.order, branches, self.geometry))

    def function(self, branches: tuple[int, ...]) -> tuple[Callable, list[int], list[bool]]:
        """The compiled kernel for ``branches``, and for each of its outputs in order its row and
        whether it is a float (else an int) row."""
        got = self.functions.get(branches)
        if got is None:
            trace = _Trace(self.mech, self.structure, self.order, branches, self.geometry)
            where = [self.rows[k] for k, _ in trace.outputs]
            at, is_float = [r for _, r in where], [f for f, _ in where]
            fn = numba_kernel(trace, at, is_float, _compiled(_source(trace)))   # numba's where installed
            got = self.functions[branches] = (fn, at, is_float)
        return got

    def branches(self, phi: np.ndarray) -> tuple[int, ...] | None:
        """Each group's branch at every one of ``phi`` (None when one changes among them)."""
        out = []
        for plan in assembly_plans(self.mech):
            if plan.mode == "keep" or not plan.swaps.any():
                out.append(int(plan.branch))
                continue
            per = plan.branches(phi)
            if np.any(per != per[0]):
                return None
            out.append(int(per[0]))
        return tuple(out)

    def __call__(self, phi, branches: tuple[int, ...] | None = None, columns: list = ()) -> dict | None:
        """Kinematics at the input coordinates ``phi`` ``(N,)`` (see :func:`run_kernel`), each group
        on its planned branch or on ``branches`` (one per group) when given; ``columns``: the
        geometry's ``(N,)`` inputs of a kernel of variants (:mod:`.kernel_variants`)."""
        if type(phi) is not np.ndarray or phi.dtype != np.float64 or phi.ndim != 1:
            phi = np.atleast_1d(np.asarray(phi, dtype=float))
        N = len(phi)
        if not N or phi.ndim != 1:
            return None
        if branches is None:
            branches = self.branches(phi)
            if branches is None:
                return None
        else:
            branches = tuple(int(b) for b in branches)
            if len(branches) != len(self.structure.groups) or any(
                    b not in g.branches for b, g in zip(branches, self.structure.groups)):
                raise ValueError(f"branches must be one of each group's {[g.branches for g in self.structure.groups]}, "
                                 f"got {branches!r}")
        fn, at, is_float = self.function(branches)
        structure = self.structure
        floats = np.empty((self.n_float, N))
        ints = np.empty((1 + len(structure.groups), N), dtype=int)
        floats[:3] = 0.0                               # the frame's pose (never written)
        inputs = [phi, *columns]
        if len(structure.inputs) > 1:
            for q in list(input_angles(self.mech, structure, phi).values())[1:]:
                inputs += [np.broadcast_to(np.asarray(v, dtype=float), phi.shape) for v in q]
        whole = getattr(fn, "whole", None)      # the numba kernel (kernel_numba.py): one loop into the rows
        if whole is None or not whole(inputs, floats, ints):
            float_rows, int_rows = list(floats), list(ints)
            out = [float_rows[r] if f else int_rows[r] for r, f in zip(at, is_float)]
            if N <= KERNEL_BLOCK:
                fn(inputs, out)
            else:
                for start in range(0, N, KERNEL_BLOCK):
                    block = slice(start, min(start + KERNEL_BLOCK, N))
                    fn([v[block] for v in inputs], [v[block] for v in out])
        step, rows = 3 * len(self.links), self.group_rows
        result: dict[str, Any] = {name: LinkRows(floats, j * step, self._link_index) if j <= self.order else None
                                  for j, name in enumerate(("poses", "first", "second"))}
        result["points"] = PointRows(floats, self._point_rows, self.order)
        result["conditioning"] = {label: floats[rows + 3 * i] for i, label in enumerate(self.labels)}
        result["signs"] = {i: floats[rows + 3 * i + 1] for i in range(len(self.labels))}
        result["scales"] = {i: floats[rows + 3 * i + 2] for i in range(len(self.labels))}
        result["error_bound"] = floats[-1]
        result["status"] = ints[0]
        result["solved"] = {i: ints[1 + i] for i in range(len(self.labels))}
        result["branches"] = branches
        return result


_KERNELS: dict[int, tuple[weakref.ref, dict[int, Kernel | None]]] = {}


def kernel_for(mech: Mechanism, order: int = 2) -> Kernel | None:
    """The compiled kinematics of ``mech`` to analog ``order`` (0, 1 or 2), or None when the
    kernel does not apply (a group is not a closed-form dyad, or an input is a driven cylinder).

    The kernel is kept per mechanism (while the mechanism lives) and order; calling it with the
    input coordinates ``phi`` ``(N,)`` gives :func:`run_kernel`'s dict."""
    if order not in (0, 1, 2):
        return None
    entry = _KERNELS.get(id(mech))
    if entry is None or entry[0]() is not mech:
        entry = _KERNELS[id(mech)] = (weakref.ref(mech), {})
        weakref.finalize(mech, _KERNELS.pop, id(mech), None)
    kernels = entry[1]
    if order not in kernels:
        structure = structure_of(mech)
        kernels[order] = Kernel(mech, structure, order) if supported(mech, structure) else None
    return kernels[order]


def run_kernel(mech: Mechanism, phi, order: int = 2) -> dict | None:
    """Kinematics of ``mech`` at the input coordinates ``phi`` ``(N,)`` by its compiled kernel: the
    same numbers as ``linkage.analyze(mech, phi, order=order, on_failure="mask")`` holds.

    Returns
    -------
    dict or None
        ``poses``, ``first``, ``second``: link -> ``(N, 3)`` (None above ``order``); ``status``
        ``(N,)`` int; ``conditioning``: group label -> ``(N,)``; ``error_bound`` ``(N,)``;
        ``signs``, ``scales``, ``solved``: group index -> the sign of its Jacobian's determinant,
        its own length scale (m, :meth:`assur.base.Group.scale`; NaN where it is not assembled) and
        its own status ``(N,)``; ``branches``: each group's branch; ``points``: each point that a moving
        link reports -> its position and first and second analogs, each ``(N, 2)`` (None above
        ``order``). None where the kernel does not apply
        (:func:`kernel_for`) or a group's branch changes among ``phi``: run the general path.
    """
    kernel = kernel_for(mech, order)
    return None if kernel is None else kernel(phi)


def kernel_source(mech: Mechanism, order: int = 2, branches: tuple[int, ...] | None = None) -> str | None:
    """The Python source of ``mech``'s kernel (for reading and profiling); ``branches`` default to
    the declared ones."""
    kernel = kernel_for(mech, order)
    if kernel is None:
        return None
    branches = tuple(int(p.branch) for p in assembly_plans(mech)) if branches is None else branches
    return kernel.source(branches)
