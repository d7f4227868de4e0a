"""Loads on a mechanism: gravity, inertia, external forces and moments, force diagrams.

docs/methods.md, "Loads". A :class:`Loads` collects what acts on the links; given a
:class:`~linkage.kinematics.motion.Motion` with real speeds it is evaluated into per-position
:class:`LoadTerm` s (a force at a point of a link and a moment on the link), which the
kinetostatics and the dynamics consume.

Declared in scheme files as::

    [loads]
    gravity = [0.0, -9.81]            # m/s^2 (the default); [0, 0] for a machine lying flat

    [[loads.forces]]                  # a constant force at point E of link 2
    point = "E"
    link = "2"                        # needed only when E is on several moving links
    force = [0.0, -100.0]             # N

    [[loads.forces]]                  # a force diagram over the working stroke of B.x
    point = "B"
    link = "3"
    diagram = { along = "x", working = "+", fractions = [0, 0.5, 1], values = [0, 800, 0] }

    [[loads.forces]]                  # a step diagram: a repeated fraction is a jump
    point = "E"
    link = "2"
    diagram.along = "y"
    diagram.working = "-"
    diagram.fractions = [0, 0.3, 0.3, 0.6, 0.6, 1]
    diagram.values = [0, 0, 2100, 2100, 0, 0]

    [[loads.forces]]                  # a directed force: along the line C -> D (cylinder axis)
    point = "D"
    link = "4"
    between = ["C", "D"]              # positive pushes from C towards D
    magnitude = 1500.0                # N, signed (or diagram = {quantity = ...} / cycle = [...])

    [[loads.moments]]                 # a moment on link 3, N m, CCW positive
    link = "3"
    moment = -5.0

The full format (every key, unit and default) is in ``schemes/README.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike

from assur.base import cross

from ..errors import InputError, LinkageError, SchemeError
from ..kinematics.extremes import extreme_positions, table_angles, wrap_angle
from ..kinematics.full_turn import input_cannot_turn
from ..kinematics.motion import Motion, input_sweep, parse_quantity
from ..model.mechanism import Mechanism
from ..model.numbers import angle_from, check_number, unknown_keys
from ..model.scheme import register_section, section_of

__all__ = [
    "StrokeDiagram",
    "Direction",
    "diagram_value",
    "CycleTable",
    "PointForce",
    "LinkMoment",
    "Loads",
    "LoadTerm",
    "loads_of",
    "evaluate_loads",
    "inertia_terms",
    "generalized_loads",
    "STANDARD_GRAVITY",
]

STANDARD_GRAVITY = (0.0, -9.81)

#: a stroke fraction within this distance of a diagram's fraction is that fraction (so a position
#: placed at a jump of a step diagram is at the jump, whatever the round-off of its geometry)
FRACTION_SNAP = 1e-12


def diagram_value(t, fractions, values, before=False) -> np.ndarray:
    """Value of a piecewise-linear diagram ``(fractions, values)`` at the fractions ``t``.

    ``fractions`` increase from 0 to 1; a fraction given twice is a jump (a step diagram): the
    first of its two values holds just before it, the second just after. At a jump the value is
    the one just after it (the value the motion enters, as time goes on), or the one just before
    it where ``before`` is True (per ``t``: the value the motion arrives with). Between points
    the value is linear; ``t`` is clipped to [0, 1].

    >>> diagram_value([0.25, 0.5, 0.75], [0, 0.5, 0.5, 1], [0, 10, 30, 40]).tolist()
    [5.0, 30.0, 35.0]
    >>> diagram_value([0.5], [0, 0.5, 0.5, 1], [0, 10, 30, 40], before=True).tolist()
    [10.0]
    """
    fr = np.asarray(fractions, dtype=float)
    va = np.asarray(values, dtype=float)
    t = np.clip(np.asarray(t, dtype=float), 0.0, 1.0)
    near = np.abs(t[..., None] - fr) <= FRACTION_SNAP
    t = np.where(near.any(axis=-1), fr[np.argmax(near, axis=-1)], t)
    before = np.broadcast_to(np.asarray(before, bool), t.shape)
    after_index = np.searchsorted(fr, t, side="right") - 1  # fr[i] <= t < fr[i + 1]
    before_index = np.searchsorted(fr, t, side="left") - 1  # fr[i] < t <= fr[i + 1]
    lo = np.clip(np.where(before, before_index, after_index), 0, len(fr) - 2)
    x0, x1 = fr[lo], fr[lo + 1]
    w = np.clip((t - x0) / np.where(x1 > x0, x1 - x0, 1.0), 0.0, 1.0)
    return va[lo] + w * (va[lo + 1] - va[lo])


@dataclass(frozen=True)
class StrokeDiagram:
    """A force (or moment) diagram over the working stroke of an output coordinate (docs/methods.md, "Loads").

    Parameters
    ----------
    quantity : str
        The output coordinate (``"B.x"``, ``"B.y"`` or ``"3.theta"``); the load acts along it.
    working : {1, -1}
        The working stroke is the half-cycle in which the quantity increases (+1) or decreases.
    fractions, values : sequence of float
        Diagram points: fraction of the working stroke, 0 (start) .. 1 (end), nondecreasing; and
        the load's magnitude there (N or N m, >= 0). Linear in between; a fraction given twice
        (inside (0, 1)) is a jump, with the value just before and just after it (see
        :func:`diagram_value`); zero on the idle stroke unless ``idle_fractions`` /
        ``idle_values`` are given.
    opposes : bool
        True (default): the load opposes the working motion (a useful resistance); False: it
        drives it. Not used when ``signed``.
    idle_fractions, idle_values : sequence of float
        The diagram of the idle stroke (fractions of the idle stroke from its start), if any.
    stroke_ends : (float, float) or None
        ``(value_min, value_max)`` of the quantity, its extreme values: found once when a scheme
        is loaded (None: found from the mechanism's extreme positions when needed). Not part of
        the diagram's identity (equality).
    signed : bool
        False (default): the values are magnitudes and the load acts along the quantity, its
        sign from ``opposes``. True: the values are signed magnitudes along a direction declared
        with the force (a :class:`Direction`), returned as they are.
    """

    quantity: str
    working: int
    fractions: tuple[float, ...]
    values: tuple[float, ...]
    opposes: bool = True
    idle_fractions: tuple[float, ...] = ()
    idle_values: tuple[float, ...] = ()
    stroke_ends: tuple[float, float] | None = field(default=None, compare=False)
    signed: bool = False

    def magnitude(self, mech: Mechanism, value, first, second, rotation: float, ends=None):
        """Signed load along the quantity at positions with the given value and analogs (along the
        declared direction when ``signed``).

        At a stroke end the load is two-valued: a position counts in the stroke the mechanism
        enters (the sign of ``q''``, whatever the rotation), or in the one it leaves where ``ends`` is True.
        At a jump of a step diagram likewise: the value just after the jump, or just before it
        where ``ends`` is True.
        """
        if self.stroke_ends is not None:
            value_min, value_max = self.stroke_ends
        else:
            ext = extreme_positions(mech, self.quantity)
            value_min, value_max = ext.value_min, ext.value_max
        stroke = value_max - value_min
        moving = np.sign(first * rotation)  # direction of the output's motion in time
        at_end = np.abs(first) <= 1e-9 * stroke
        leaving = np.zeros(len(value), bool) if ends is None else np.asarray(ends, bool)
        # near an extreme q' ~ q'' (phi - phi_e), so the motion just after it goes along sign(q'')
        entering_dir = np.sign(second) * np.where(leaving, -1.0, 1.0)
        direction = np.where(at_end, entering_dir, moving)
        working = direction == self.working
        start = value_min if self.working > 0 else value_max
        travel = value - start
        if self.quantity.endswith(".theta"):  # a link angle may cross the +-pi cut
            travel = wrap_angle(travel)
        t = np.clip(np.abs(travel) / stroke, 0.0, 1.0)
        work_mag = diagram_value(t, self.fractions, self.values, leaving)
        if self.idle_fractions:
            idle_mag = diagram_value(1.0 - t, self.idle_fractions, self.idle_values, leaving)
        else:
            idle_mag = np.zeros_like(t)
        mag = np.where(working, work_mag, idle_mag)
        if self.signed:
            return mag
        sign = -self.working if self.opposes else self.working
        # on the idle stroke the motion is reversed: an opposing load still opposes the motion
        return np.where(working, sign * mag, -sign * mag)


@dataclass(frozen=True)
class CycleTable:
    """Load values at the positions 1..n+1 of the machine's cycle table (docs/conventions.md, "Table positions").

    Position 1 is the start of the cycle (``start``: "extreme", "max", "min" or degrees) and
    positions follow the rotation; between positions the value is linear in the cycle angle, and
    position n+1 (the cycle's end, same angle as position 1) may carry its own value.
    ``phi0`` is the input angle of position 1 (rad): found once when a scheme is loaded (None:
    found from ``start`` when needed); not part of the table's identity (equality).

    Over an input range ``span = (a, b)`` (rad; a mechanism whose input does not turn fully) the
    positions 1..n+1 run from a to b instead, and the value is linear in the input angle between
    them (``start`` and ``rotation`` are not used).
    """

    quantity: str
    values: tuple[float, ...]
    start: Any = "extreme"
    rotation: int = 1
    phi0: float | None = field(default=None, compare=False)
    span: tuple[float, float] | None = None

    def magnitude(self, mech: Mechanism, phi: np.ndarray, ends=None) -> np.ndarray:
        n = len(self.values) - 1
        if self.span is not None:
            a, b = self.span
            u = np.clip((np.asarray(phi, dtype=float) - a) / (b - a), 0.0, 1.0)
            return np.interp(u, np.linspace(0.0, 1.0, n + 1), self.values)
        phi0 = self.phi0 if self.phi0 is not None else table_angles(mech, 1, self.start, self.rotation)[0]
        psi = np.mod(self.rotation * (phi - phi0), 2 * np.pi)
        psi = np.where(np.isclose(psi, 2 * np.pi, rtol=0, atol=1e-9), 0.0, psi)
        if ends is not None:
            psi = np.where(np.asarray(ends, bool) & (psi < 1e-9), 2 * np.pi, psi)
        return np.interp(psi, np.linspace(0, 2 * np.pi, n + 1), self.values)


@dataclass(frozen=True)
class Direction:
    """The line of action of a directed force: through two named points, or fixed in a link.

    Exactly one of:

    - ``between = (P, Q)``: along the line through the points P and Q (of any links, the frame
      included); a positive magnitude pushes from P towards Q, i.e. acts along ``(Q - P) / |Q - P|``;
    - ``link = L`` with ``angle`` (rad, default 0): along the direction at ``angle``
      counter-clockwise from link L's local x axis (it turns with the link; the frame's is fixed).
    """

    between: tuple[str, str] | None = None
    link: str | None = None
    angle: float = 0.0

    def unit(self, motion: Motion) -> np.ndarray:
        """Global unit vectors ``(N, 2)`` of the direction at the positions of ``motion``."""
        if self.between is not None:
            d = motion.point(self.between[1]) - motion.point(self.between[0])
            length = np.hypot(d[:, 0], d[:, 1])
            with np.errstate(divide="ignore", invalid="ignore"):
                return np.where(length[:, None] > 0, d / length[:, None], np.nan)
        theta = motion.poses[self.link][:, 2] + self.angle
        return np.stack([np.cos(theta), np.sin(theta)], axis=1)

    def describe(self) -> str:
        if self.between is not None:
            return f"between {list(self.between)}"
        return f"along link '{self.link}' at {np.degrees(self.angle):.10g} deg"


@dataclass(frozen=True)
class PointForce:
    """A force at a named point of a link: a constant vector, per-position vectors, or a diagram.

    With a ``direction`` (:class:`Direction`) ``force`` is a signed magnitude along it (N): a
    constant, per-position values ``(N,)``, a signed :class:`StrokeDiagram` or a
    :class:`CycleTable`.
    """

    point: str
    link: str
    force: Any  # (2,), (N, 2), StrokeDiagram or CycleTable; with a direction: float, (N,), ...
    direction: Direction | None = None


@dataclass(frozen=True)
class LinkMoment:
    """A moment on a link (N m, CCW positive): a constant, per-position values, or a diagram."""

    link: str
    moment: Any  # float, (N,) or StrokeDiagram


@dataclass(frozen=True)
class Loads:
    """Everything applied to a mechanism besides inertia.

    Attributes
    ----------
    gravity : (float, float)
        Acceleration of gravity, m/s^2 (zero allowed).
    forces, moments : tuple
        :class:`PointForce` and :class:`LinkMoment` entries.
    notes : tuple of str
        Remarks for reports (e.g. links without a declared mass, treated as massless).
    """

    gravity: tuple[float, float] = STANDARD_GRAVITY
    forces: tuple[PointForce, ...] = ()
    moments: tuple[LinkMoment, ...] = ()
    notes: tuple[str, ...] = ()


@dataclass(frozen=True)
class LoadTerm:
    """One load evaluated at N positions: ``force`` (N, 2) at ``local`` point of ``link`` and a
    ``moment`` (N,) on the link. ``kind`` is "gravity", "external" (resisting or neutral),
    "driving" (a diagram declared with ``opposes = false``), "inertia" or "friction" (a pair's
    Coulomb friction, :mod:`.friction`; ``label`` the pair)."""

    link: str
    local: tuple[float, float]
    force: np.ndarray
    moment: np.ndarray
    kind: str = "external"
    label: str = ""


# ----------------------------------------------------------------------------------------------
# reading [loads] from a scheme
# ----------------------------------------------------------------------------------------------


def _numbers(raw: Any, where: str, what: str, problems: list[str], kind: str, unit: str = "",
             length: int | None = None, at_least: int = 0) -> tuple[float, ...] | None:
    """A list of numbers in the range ``kind`` (of ``length`` items, or ``at_least``); None with
    one problem (naming the first bad item) otherwise."""
    if not (isinstance(raw, list) and (len(raw) == length if length is not None else len(raw) >= at_least)):
        size = f"{length}" if length is not None else f"at least {at_least}"
        problems.append(f"{where}: {what} must be a list of {size} numbers, got {raw!r}")
        return None
    values = []
    for i, x in enumerate(raw):
        v = check_number(x, where, f"{what}[{i}]", problems, kind, unit)
        if v is None:
            return None
        values.append(v)
    return tuple(values)


def _fraction_problem(fr: tuple[float, ...], key: str, raw: Any) -> str | None:
    """Why the fractions ``fr`` of a diagram cannot be meant (None when they can): they must
    start at 0, end at 1 and never decrease; a fraction given twice inside (0, 1) is a jump."""
    if fr[0] != 0 or fr[-1] != 1 or any(b < a for a, b in zip(fr, fr[1:])):
        return (f"diagram '{key}' must increase from 0 to 1 (fractions of the stroke; a fraction given "
                f"twice is a jump), got {raw!r}")
    for a, b, c in zip(fr, fr[1:], fr[2:]):
        if a == b == c:
            return (f"diagram '{key}' gives the fraction {a:g} three times, got {raw!r}: a jump has two "
                    "values, the one just before and the one just after it")
    for end in (0.0, 1.0):
        if fr.count(end) > 1:
            return (f"diagram '{key}' repeats the stroke end {end:g}, got {raw!r}: a jump must lie inside "
                    "the stroke (0 < t < 1); at the stroke ends the load is already two-valued (the end of "
                    "one stroke and the start of the other)")
    return None


def _diagram(mech: Mechanism, raw: Any, quantity: str | None, where: str, problems: list[str],
             signed: bool = False):
    """A :class:`StrokeDiagram` over the stroke of ``quantity``; ``signed`` (a directed force):
    the quantity is the diagram's own ``quantity`` key and the values are signed magnitudes."""
    if not isinstance(raw, Mapping):
        problems.append(f"{where}: diagram must be a table, got {raw!r}")
        return None
    known = {"working", "fractions", "values", "idle_fractions", "idle_values"}
    known |= {"quantity"} if signed else {"along", "opposes"}
    if unknown_keys(raw, known, f"{where} diagram", problems):
        return None
    if signed:
        quantity = raw.get("quantity")
        if not isinstance(quantity, str):
            problems.append(f"{where}: the diagram of a directed force needs quantity = \"P.x\", \"P.y\", "
                            f"\"L.theta\" or \"K.s\": the coordinate whose working stroke its fractions "
                            f"measure, got {quantity!r}")
            return None

        try:
            parse_quantity(mech, quantity)
        except LinkageError as exc:
            problems.append(f"{where}: diagram quantity {quantity!r}: {exc}")
            return None
    raw_working = raw.get("working")
    working = {"+": 1, "-": -1, 1: 1, -1: -1}.get(raw_working) \
        if isinstance(raw_working, (str, int)) and not isinstance(raw_working, bool) else None
    if working is None:
        problems.append(f"{where}: diagram 'working' must be \"+\" or \"-\" (the direction of "
                        f"{quantity} on the working stroke), got {raw_working!r}")
        return None
    curves = []
    for fk, vk in (("fractions", "values"), ("idle_fractions", "idle_values")):
        if fk == "idle_fractions" and fk not in raw and vk not in raw:
            curves.append(((), ()))
            continue
        fr = _numbers(raw.get(fk), where, f"diagram '{fk}'", problems, "fraction", at_least=2)
        if fr is None:
            return None
        if signed:
            vals = _numbers(raw.get(vk), where, f"diagram '{vk}' (signed magnitudes along the force's "
                            "direction, N)", problems, "real", "N", length=len(fr))
        else:
            vals = _numbers(raw.get(vk), where, f"diagram '{vk}' (magnitudes: the sign comes from "
                            "'opposes')", problems, "nonnegative", length=len(fr))
        if vals is None:
            return None
        problem = _fraction_problem(fr, fk, raw.get(fk))
        if problem:
            problems.append(f"{where}: {problem}")
            return None
        curves.append((fr, vals))
    opposes = raw.get("opposes", True)
    if not isinstance(opposes, bool):
        problems.append(f"{where}: diagram 'opposes' must be true or false, got {opposes!r}")
        return None
    try:
        ext = extreme_positions(mech, quantity)
    except LinkageError as exc:
        problems.append(f"{where}: {exc}")
        return None
    if not ext.moves(mech.size):
        problems.append(f"{where}: the working direction {raw_working!r} is never taken: "
                        f"{quantity} does not move (stroke {ext.stroke:.3g})")
        return None
    return StrokeDiagram(quantity, working, *curves[0], opposes, *curves[1],
                         stroke_ends=(ext.value_min, ext.value_max), signed=signed)


#: table positions of a cycle table when the scheme's [dynamics] declares no ``positions``
DEFAULT_POSITIONS = 12


def _cycle_table(mech: Mechanism, spec, quantity: str, where: str, problems: list[str]):
    """A :class:`CycleTable` from ``cycle = [...]``: one value per position 1..n+1 of the cycle's
    table (n: the ``positions`` of ``[dynamics]``, default 12). The cycle (start, rotation) is
    the one the mechanism's ``[dynamics]`` declares; over an input range, positions 1..n+1 run
    over the range and ``[dynamics]`` is not needed."""
    values = _numbers(spec.get("cycle"), where, "cycle (the values, N, at positions 1..n+1)", problems,
                      "real", "N", at_least=2)
    if values is None:
        return None
    try:
        dyn = section_of(mech, "dynamics")
    except SchemeError:  # the [dynamics] section's own problems are reported with it
        return None
    n = dyn.positions if dyn is not None else DEFAULT_POSITIONS
    if len(values) != n + 1:
        declared = (f"[dynamics] positions = {n}" if dyn is not None and "positions" in (mech.extra.get("dynamics")
                                                                                         or {})
                    else f"{n} positions by default; declare [dynamics] positions = N for another table")
        problems.append(f"{where}: cycle has {len(values)} values, expected {n + 1}: one per position 1..{n + 1} "
                        f"of the cycle's table ({declared}), the last one closing the cycle")
        return None
    if mech.input_range is not None:
        return CycleTable(quantity, values, span=tuple(mech.input_range))
    if dyn is None:
        problems.append(f"{where}: a cycle table needs the direction of rotation: declare [dynamics] "
                        "mean_speed (rad/s) or mean_rpm, signed")
        return None
    try:
        phi0 = float(table_angles(mech, 1, dyn.start, dyn.rotation)[0])
    except LinkageError as exc:
        problems.append(f"{where}: the cycle's first position: {exc}")
        return None
    return CycleTable(quantity, values, dyn.start, dyn.rotation, phi0)


def _entries(raw: Mapping[str, Any], key: str, problems: list[str]) -> list:
    """The array of tables ``[[loads.<key>]]`` (empty with a problem when it is not one)."""
    entries = raw.get(key, [])
    if not isinstance(entries, list):
        problems.append(f"{key}: expected an array of tables ([[loads.{key}]]), got {entries!r}")
        return []
    return entries


#: keys of a ``[[loads.forces]]`` entry
FORCE_KEYS = {"point", "link", "force", "diagram", "cycle", "along", "magnitude", "between", "along_link",
              "angle", "angle_deg"}


def _direction(mech: Mechanism, spec: Mapping[str, Any], where: str, problems: list[str]):
    """The :class:`Direction` a force entry declares (``between`` or ``along_link``), None when it
    declares none, or ``False`` (with the problem) when it is declared wrongly."""
    given = [k for k in ("between", "along_link") if k in spec]
    has_angle = "angle" in spec or "angle_deg" in spec
    if not given:
        if has_angle:
            key = "angle_deg" if "angle_deg" in spec else "angle"
            problems.append(f"{where}: {key} = {spec[key]!r} gives the direction of a force in the frame of the "
                            "link named by along_link = \"...\"; declare along_link (or give force = [Fx, Fy])")
            return False
        return None
    if len(given) == 2:
        problems.append(f"{where}: give one direction, between = [\"P\", \"Q\"] or along_link = \"L\", not both")
        return False
    if "between" in spec:
        pts = spec["between"]
        if has_angle:
            key = "angle_deg" if "angle_deg" in spec else "angle"
            problems.append(f"{where}: {key} = {spec[key]!r} goes with along_link, not with between = {pts!r}")
            return False
        if not (isinstance(pts, list) and len(pts) == 2 and all(isinstance(q, str) for q in pts)):
            problems.append(f"{where}: between must name two points [\"P\", \"Q\"] (a positive magnitude "
                            f"pushes from P towards Q), got {pts!r}")
            return False
        unknown = [q for q in pts if not mech.point_links(q)]
        if unknown:
            problems.append(f"{where}: between {pts!r}: unknown point {unknown[0]!r} (points: {mech.point_names})")
            return False
        if pts[0] == pts[1]:
            problems.append(f"{where}: between {pts!r} names one point twice: a line needs two points")
            return False
        direction = Direction(between=(pts[0], pts[1]))
        problem = _coincide(mech, direction)
        if problem:
            problems.append(f"{where}: between {pts!r}: {problem}")
            return False
        return direction
    link = spec["along_link"]
    if not (isinstance(link, str) and link in mech.links):
        problems.append(f"{where}: along_link must name a link (the direction is fixed in its frame), got "
                        f"{link!r} (links: {sorted(mech.links)})")
        return False
    count = len(problems)
    angle = angle_from(spec, "angle", where, problems)
    if len(problems) > count:
        return False
    return Direction(link=link, angle=angle)


def _coincide(mech: Mechanism, direction: Direction) -> str | None:
    """Why the line through the two points of ``direction`` is undefined (they coincide at some
    input angle of the turn or range), or None."""

    motion = input_sweep(mech)
    phi = motion.phi
    p, q = (motion.point(name) for name in direction.between)
    gap = np.hypot(*(q - p).T)
    close = np.flatnonzero(np.isfinite(gap) & (gap <= 1e-9 * mech.size))
    if len(close):
        shown = ", ".join(f"{np.degrees(phi[i]):.4g}" for i in close[:5])
        return (f"the two points coincide at phi = {shown} deg: the direction of the force is undefined "
                "there; choose two points that stay apart")
    return None


def _point_force(mech: Mechanism, spec: Mapping[str, Any], point: str, link: str, where: str,
                 problems: list[str]):
    """The :class:`PointForce` of one ``[[loads.forces]]`` entry (None with the problem)."""
    direction = _direction(mech, spec, where, problems)
    if direction is False:
        return None
    if direction is None:
        if "magnitude" in spec:
            problems.append(f"{where}: magnitude = {spec['magnitude']!r} is a signed value along a direction: "
                            "declare the direction with "
                            "between = [\"P\", \"Q\"] or along_link = \"L\" (or give force = [Fx, Fy])")
            return None
        if sum(k in spec for k in ("force", "diagram", "cycle")) != 1:
            problems.append(f"{where}: give exactly one of 'force' = [Fx, Fy], 'diagram' = {{...}} or "
                            "'cycle' = [values at the cycle's positions]")
            return None
        if "cycle" in spec:
            along = spec.get("along")
            if along not in ("x", "y"):
                problems.append(f"{where}: a cycle table needs along = \"x\" or \"y\", got {along!r}")
                return None
            table = _cycle_table(mech, spec, f"{point}.{along}", where, problems)
            return None if table is None else PointForce(point, link, table)
        if "force" in spec:
            vec = _numbers(spec["force"], where, "force [Fx, Fy]", problems, "real", "N", length=2)
            return None if vec is None else PointForce(point, link, vec)
        along = spec["diagram"].get("along") if isinstance(spec["diagram"], Mapping) else None
        if along not in ("x", "y"):
            problems.append(f"{where}: diagram 'along' must be \"x\" or \"y\", got {along!r}")
            return None
        d = _diagram(mech, spec["diagram"], f"{point}.{along}", where, problems)
        return None if d is None else PointForce(point, link, d)
    told = f"{where} ({direction.describe()})"
    for key, why in (("force", "is a vector [Fx, Fy]; along a declared direction give magnitude = F (N, "
                               "signed)"),
                     ("along", "is the axis of an x / y cycle table or diagram; a directed force acts along "
                               "its declared direction")):
        if key in spec:
            problems.append(f"{told}: {key} = {spec[key]!r} {why}")
            return None
    if sum(k in spec for k in ("magnitude", "diagram", "cycle")) != 1:
        problems.append(f"{told}: give exactly one of 'magnitude' = F (N, signed), 'diagram' = {{quantity, "
                        "working, fractions, values} or 'cycle' = [values at the cycle's positions]")
        return None
    if "magnitude" in spec:
        value = check_number(spec["magnitude"], told, "magnitude", problems, "real", "N")
        return None if value is None else PointForce(point, link, value, direction)
    if "cycle" in spec:
        table = _cycle_table(mech, spec, f"{point}.force", told, problems)
        return None if table is None else PointForce(point, link, table, direction)
    d = _diagram(mech, spec["diagram"], None, told, problems, signed=True)
    return None if d is None else PointForce(point, link, d, direction)


def parse_loads(mech: Mechanism, raw: Mapping[str, Any] | None) -> tuple[Loads, list[str]]:
    """Loads and the list of problems from a scheme's ``[loads]`` table.

    Every number is checked against its range (``schemes/README.md``, "Ranges"); the stroke ends
    of force diagrams and the first position of cycle tables are found here, once: when the input
    cannot turn fully, they are refused first in the words of :func:`~linkage.kinematics.full_turn.input_cannot_turn`.
    """
    problems: list[str] = []
    raw = {} if raw is None else raw
    if not isinstance(raw, Mapping):
        return Loads(), [f"expected a table, got {raw!r}"]
    unknown_keys(raw, {"gravity", "forces", "moments"}, "", problems)
    gravity = STANDARD_GRAVITY
    if "gravity" in raw:
        g = _numbers(raw["gravity"], "gravity", "[gx, gy]", problems, "real", "m/s^2", length=2)
        gravity = g if g is not None else gravity
    # a diagram over the working stroke or a cycle table needs the whole turn: first, can the input make it?
    cyclic = [f"{key}[{i}] ({what} {spec.get(what)!r})" for key, what in (("forces", "point"), ("moments", "link"))
              for i, spec in enumerate(raw[key] if isinstance(raw.get(key), list) else [])
              if isinstance(spec, Mapping) and ("diagram" in spec or "cycle" in spec)]
    why = input_cannot_turn(mech) if cyclic else None
    if why:
        return Loads(gravity), problems + [f"{why}; {', '.join(cyclic)} cannot follow the working cycle: a diagram "
                                           "over the stroke or a cycle table needs the whole travel of the input"]
    forces, moments = [], []
    for i, spec in enumerate(_entries(raw, "forces", problems)):
        where = f"forces[{i}]"
        if not isinstance(spec, Mapping):
            problems.append(f"{where}: expected a table, got {spec!r}")
            continue
        if unknown_keys(spec, FORCE_KEYS, where, problems):
            continue
        point = spec.get("point")
        where = f"forces[{i}] (point {point!r})"
        owners = [k for k in mech.point_links(point) if k != mech.frame] if isinstance(point, str) else []
        link = spec.get("link")
        on_frame = isinstance(point, str) and point in mech.links[mech.frame].points
        if link == mech.frame or (not owners and on_frame):
            moving = f"the moving links with point {point!r}: {owners}" if owners else \
                f"no moving link has point {point!r}"
            problems.append(f"{where}: link {mech.frame!r} is the frame: a force on it moves nothing and loads no "
                            f"pair; apply it to a moving link ({moving})")
            continue
        if not owners:
            problems.append(f"{where}: unknown point {point!r} (points of moving links: "
                            f"{sorted({p for k in mech.moving_links for p in mech.links[k].points})})")
            continue
        if link is None:
            if len(owners) > 1:
                problems.append(f"{where}: point {point!r} is on links {owners}: say which one the force "
                                "acts on with link = \"...\"")
                continue
            link = owners[0]
        elif link not in owners:
            problems.append(f"{where}: link {link!r} has no point {point!r} (links with it: {owners})")
            continue
        force = _point_force(mech, spec, point, link, where, problems)
        if force is not None:
            forces.append(force)
    for i, spec in enumerate(_entries(raw, "moments", problems)):
        where = f"moments[{i}]"
        if not isinstance(spec, Mapping):
            problems.append(f"{where}: expected a table, got {spec!r}")
            continue
        link = spec.get("link")
        where = f"moments[{i}] (link {link!r})"
        if unknown_keys(spec, {"link", "moment", "diagram"}, where, problems):
            continue
        if link not in mech.moving_links:
            problems.append(f"{where}: unknown moving link {link!r} (moving links: {mech.moving_links})")
            continue
        if ("moment" in spec) == ("diagram" in spec):
            problems.append(f"{where}: give exactly one of 'moment' (N m) or 'diagram' = {{...}}")
            continue
        if "moment" in spec:
            value = check_number(spec["moment"], where, "moment", problems, "real", "N m")
            if value is not None:
                moments.append(LinkMoment(link, value))
        else:
            d = _diagram(mech, spec["diagram"], f"{link}.theta", where, problems)
            if d is not None:
                moments.append(LinkMoment(link, d))
    notes = tuple(f"link '{k}' declares no mass: treated as massless" for k in mech.moving_links
                  if not mech.links[k].mass_declared)
    return Loads(gravity, tuple(forces), tuple(moments), notes), problems


def loads_of(mech: Mechanism) -> Loads:
    """The loads a mechanism declares (``[loads]`` of its scheme; gravity alone by default).

    Parsed once (when the scheme is loaded, or on first use) and kept on the mechanism.

    Raises
    ------
    SchemeError
        When the mechanism's ``[loads]`` (or the ``[dynamics]`` it reads) is declared wrongly.
    """
    return section_of(mech, "loads")


register_section("loads", parse_loads, requires=("dynamics",))


# ----------------------------------------------------------------------------------------------
# evaluating loads over a motion
# ----------------------------------------------------------------------------------------------


def _per_position(value: ArrayLike, n: int, shape: tuple[int, ...], what: str) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    try:
        return np.broadcast_to(arr, (n, *shape)).copy()
    except ValueError:
        raise InputError(f"{what}: expected a constant of shape {shape} or per-position values of "
                         f"shape {(n, *shape)}, got shape {arr.shape}") from None


def evaluate_loads(motion: Motion, loads: Loads, ends: ArrayLike | None = None,
                   links: Iterable[str] | None = None) -> list[LoadTerm]:
    """Gravity and external loads at the positions of ``motion`` (inertia not included).

    ``ends`` (bool, per position) marks positions that end a cycle: at a stroke end they take the
    value of the stroke that ends there (docs/methods.md, "Loads"). ``links``: only the loads on
    these links (default: every moving link).
    """
    mech, n = motion.mechanism, len(motion.phi)
    rotation = 1.0 if motion.omega is None else float(np.sign(np.mean(motion.omega)) or 1.0)
    terms = []
    g = np.asarray(loads.gravity, dtype=float)
    zero = np.zeros(n)
    wanted = set(mech.moving_links if links is None else links)
    if np.any(g != 0):
        for k in mech.moving_links:
            if k not in wanted:
                continue
            link = mech.links[k]
            if link.mass > 0:
                terms.append(LoadTerm(k, link.center_of_mass, np.tile(link.mass * g, (n, 1)), zero,
                                      "gravity", f"G{k}"))
    for f in loads.forces:
        if f.link not in wanted:
            continue
        local = mech.links[f.link].points[f.point]
        kind = "external"
        if f.direction is not None:  # a signed magnitude along a direction of the motion
            if isinstance(f.force, StrokeDiagram):
                value, d1, d2 = motion.quantity(f.force.quantity)
                mag = f.force.magnitude(mech, value, d1, d2, rotation, ends)
            elif isinstance(f.force, CycleTable):
                mag = f.force.magnitude(mech, motion.phi, ends)
            else:
                mag = _per_position(f.force, n, (), f"magnitude of the force at point '{f.point}'")
            vec = mag[:, None] * f.direction.unit(motion)
        elif isinstance(f.force, (StrokeDiagram, CycleTable)):
            if isinstance(f.force, StrokeDiagram):
                value, d1, d2 = motion.quantity(f.force.quantity)
                mag = f.force.magnitude(mech, value, d1, d2, rotation, ends)
                kind = "external" if f.force.opposes else "driving"
            else:
                mag = f.force.magnitude(mech, motion.phi, ends)
            axis = np.array([1.0, 0.0]) if f.force.quantity.endswith(".x") else np.array([0.0, 1.0])
            vec = mag[:, None] * axis
        else:
            vec = _per_position(f.force, n, (2,), f"force at point '{f.point}'")
        terms.append(LoadTerm(f.link, local, vec, zero, kind, f"F{f.point}"))
    for m in loads.moments:
        if m.link not in wanted:
            continue
        kind = "external"
        if isinstance(m.moment, StrokeDiagram):
            value, d1, d2 = motion.quantity(m.moment.quantity)
            mom = m.moment.magnitude(mech, value, d1, d2, rotation, ends)
            kind = "external" if m.moment.opposes else "driving"
        else:
            mom = _per_position(m.moment, n, (), f"moment on link '{m.link}'")
        terms.append(LoadTerm(m.link, (0.0, 0.0), np.zeros((n, 2)), mom, kind, f"M{m.link}"))
    return terms


def inertia_terms(motion: Motion, links: Iterable[str] | None = None) -> list[LoadTerm]:
    """Inertia forces ``-m a_S`` at the centres of mass and moments ``-J_S eps_k`` (docs/methods.md, "Kinetostatics").

    Needs a motion analysed with ``omega`` (and ``eps``) and second analogs. ``links``: only
    these links (default: every moving link); links without mass or inertia give no term.
    """
    if motion.omega is None or motion.second is None:
        raise InputError("inertia loads need real accelerations: analyze(..., order=2, omega=..., eps=...)")

    mech = motion.mechanism
    w, e = motion.omega, motion.eps
    terms = []
    wanted = set(mech.moving_links if links is None else links)
    for k in mech.moving_links:
        link = mech.links[k]
        if k not in wanted or link.mass == 0 and link.inertia == 0:
            continue
        _, d1, d2 = motion.local_point(k, link.center_of_mass)
        acc = d2 * (w**2)[:, None] + d1 * e[:, None]
        eps_k = motion.second[k][:, 2] * w**2 + motion.first[k][:, 2] * e
        terms.append(LoadTerm(k, link.center_of_mass, -link.mass * acc, -link.inertia * eps_k,
                              "inertia", f"Fi{k}"))
    return terms


def generalized_loads(motion: Motion, terms: Sequence[LoadTerm]) -> dict[str, np.ndarray]:
    """Sum of terms per link as ``(Fx, Fy, moment about the link's local origin)`` ``(N, 3)``
    (zeros for the drivers of cylinder inputs too, which the groups load)."""

    n = len(motion.phi)
    sums: dict[str, list] = {}
    for t in terms:     # summed per link in contiguous columns, the terms in their order
        force = np.asarray(t.force, dtype=float)
        add = (force[:, 0], force[:, 1], cross(motion.arm(t.link, t.local), force) + t.moment)
        got = sums.get(t.link)
        sums[t.link] = [0.0 + a for a in add] if got is None else [a + b for a, b in zip(got, add)]
    out = {k: np.zeros((n, 3)) for k in [*motion.mechanism.links, *motion.structure.inputs] if k not in sums}
    out.update({k: np.column_stack(v) for k, v in sums.items()})
    return out

